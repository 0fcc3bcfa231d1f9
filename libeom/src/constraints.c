/* constraints.c - projection of a state onto the constraint manifold:
 * q onto phi(q) = 0 and qd onto C qd = 0, each by the correction of least
 * M-norm,
 *     dq  = -M^-1 C^T S^-1 phi(q)   (Newton, repeated until |phi| <= tol)
 *     dqd = -M^-1 C^T S^-1 C qd     (once, at the corrected q)
 * with S = C M^-1 C^T. M is factored once, at the state given (the metric
 * of the correction need not be exact for the iteration to converge);
 * C and S are recomputed at each iterate. */
#include <math.h>
#include <string.h>

#include "eom_internal.h"

#define EOM_PROJ_MAXIT 20

static double maxabs(const double *a, int n)
{
    double m = 0.0;
    int i;
    for (i = 0; i < n; i++)
        m = fmax(m, fabs(a[i]));
    return m;
}

/* x[0..n) -= Y S^-1 r, with r (m) overwritten. */
static int correct(eom_system *s, double *v, double *r)
{
    const int n = s->n, m = s->m;
    int i, j, rc;
    if ((rc = eom__S_solve(s, r)) != EOM_OK)
        return rc;
    for (j = 0; j < m; j++)
        for (i = 0; i < n; i++)
            v[i] -= s->Y[(size_t)j * (size_t)n + (size_t)i] * r[j];
    return EOM_OK;
}

int eom_project(eom_system *s, double *x, double tol, int *iters)
{
    const int n = s ? s->n : 0, m = s ? s->m : 0;
    int it = 0, rc, st, i, j;
    double res;
    if (iters)
        *iters = 0;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!x)
        return eom__fail(s, EOM_ERR_NULL, "eom_project: x is NULL");
    if (!(tol > 0.0))
        return eom__fail(s, EOM_ERR_ARG, "eom_project: tolerance %g", tol);
    if (m == 0)
        return EOM_OK;
    if (!eom__finite(x, 2 * (size_t)n))
        return eom__fail(s, EOM_ERR_NONFINITE, "the state is not finite");
    st = tp_lagrange(s->tL.ws, x, 0, NULL, NULL, s->M, NULL);
    if ((rc = eom__tape_status(s, st, "the mass matrix")))
        return rc;
    if ((rc = eom__factor_mass(s)) != EOM_OK)
        return rc;
    for (;;) {
        if ((rc = eom__constraints_at(s, x)) != EOM_OK)
            return rc;
        res = maxabs(s->phi, m);
        if (res <= tol)
            break;
        if (it == EOM_PROJ_MAXIT)
            return eom__fail(s, EOM_ERR_PROJECTION,
                             "projection onto the constraints: |phi| = %.3g "
                             "after %d iterations (tolerance %.3g)", res, it,
                             tol);
        if ((rc = eom__factor_S(s)) != EOM_OK)
            return rc;
        memcpy(s->wm, s->phi, (size_t)m * sizeof(double));
        if ((rc = correct(s, x, s->wm)) != EOM_OK)
            return rc;
        it++;
    }
    /* velocities: C (at the projected q, already in s->C) qd = 0 */
    if ((rc = eom__factor_S(s)) != EOM_OK)
        return rc;
    for (j = 0; j < m; j++) {
        double sum = 0.0;
        for (i = 0; i < n; i++)
            sum += s->C[(size_t)j * (size_t)n + (size_t)i] * x[n + i];
        s->wm[j] = sum;
    }
    if ((rc = correct(s, x + n, s->wm)) != EOM_OK)
        return rc;
    if (iters)
        *iters = it;
    return eom__finite(x, 2 * (size_t)n)
               ? EOM_OK
               : eom__fail(s, EOM_ERR_NONFINITE,
                           "the projected state is not finite");
}
