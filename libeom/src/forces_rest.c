/* forces_rest.c - the generalized forces Q at rest for eom_equilibrium
 * and eom_linearize (forces_rest.h). The force tape has 2n + 1
 * independents (q, qd, t) and n outputs, row i the force on coordinate
 * i. At rest qd = 0; a force that reads qd contributes its value there
 * (usually 0) to the balance and its dQ/dqd to the damping. A force
 * that reads the time is refused: it has no static value. */
#include "forces_rest.h"

#include <stdlib.h>
#include <string.h>

int eom__refuse_forces_time(eom_system *s, const char *what)
{
    const int n = s->n;
    size_t *rowptr;
    int rc, i;
    if (!s->has_Q)
        return EOM_OK;
    rowptr = malloc(((size_t)n + 1) * sizeof *rowptr);
    if (!rowptr)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    /* the pattern of the time's column (count only: cols NULL) */
    rc = tp_tape_jacobian_pattern(s->tQ.tape, 2 * n, 1, rowptr, NULL, 0);
    if (rc != TP_OK && rc != TP_ERR_SIZE) {
        free(rowptr);
        return eom__tape_status(s, rc, "the forces' dependence on time");
    }
    for (i = 0; i < n && rowptr[i + 1] == rowptr[i]; i++)
        ;
    free(rowptr);
    if (i == n)
        return EOM_OK;
    return eom__fail(s, EOM_ERR_MODEL,
                     "%s: the force on %s reads the time t (a force that "
                     "changes with time has no state of rest; "
                     "eom_linearize_state linearizes about a state at a "
                     "given time)", what, s->coords[i].name);
}

int eom__forces_at_rest(eom_system *s, const double *q, double *x,
                        double *Q, double *dq, double *dqd)
{
    const int n = s->n;
    const size_t nn = (size_t)n * (size_t)n;
    const double *in;
    double *J;
    int st, rc, i, j;
    memset(Q, 0, (size_t)n * sizeof(double));
    if (dq)
        memset(dq, 0, nn * sizeof(double));
    if (dqd)
        memset(dqd, 0, nn * sizeof(double));
    if (!s->has_Q)
        return EOM_OK;
    memcpy(x, q, (size_t)n * sizeof(double));
    memset(x + n, 0, (size_t)n * sizeof(double));
    in = eom__tape_input(&s->tQ, x, 0.0);
    if (!dq && !dqd) {
        st = tp_eval(s->tQ.ws, in, Q);
        return eom__tape_status(s, st, "a generalized force at rest");
    }
    /* one forward Jacobian over (q, qd): n x 2n */
    J = malloc(2 * nn * sizeof(double) + 1);
    if (!J)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    st = tp_jacobian(s->tQ.ws, in, 0, 2 * n, Q, J);
    if ((rc = eom__tape_status(s, st, "the Jacobian of the forces at rest"))
        == EOM_OK)
        for (i = 0; i < n; i++)
            for (j = 0; j < n; j++) {
                if (dq)
                    dq[i * n + j] = J[(size_t)i * 2 * n + j];
                if (dqd)
                    dqd[i * n + j] = J[(size_t)i * 2 * n + n + j];
            }
    free(J);
    return rc;
}
