/* constraints.c - projection of a state onto the constraint manifold:
 * q onto phi(q, t) = 0 and qd onto C qd + dphi/dt = 0 (dphi/dt = 0 unless
 * the constraints read the time), each by the correction of least W-norm,
 *     dq  = -W^-1 C^T S^-1 phi(q, t)          (Newton, repeated until
 *                                              |phi| <= tol)
 *     dqd = -W^-1 C^T S^-1 (C qd + dphi/dt)   (once, at the corrected q)
 * with S = C W^-1 C^T. eom_project uses the mass matrix, W = M (the
 * correction of least kinetic energy, right for removing the small drift
 * of a step); eom_project_start uses W = I (the least change of the
 * coordinates, right for an initial state a user set off the
 * constraints: M couples angles and deflections, so the M-norm would move
 * deflections the constraints do not involve). W is factored once, at
 * the state given; C and S are recomputed at each iterate.
 *
 * Every projection first measures phi and C qd (one Taylor sweep) and
 * does nothing more when both are within the tolerance. An integrator's
 * projection after each step (eom__project_step) reuses the factor of M
 * from the step's last evaluation, at a nearby state: the correction
 * needs a metric close to M, not M at the corrected point, and this keeps
 * the cost of a step's projection that has work to do at a few small
 * solves. */
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

/* v[0..n) -= Y S^-1 r, r (m) overwritten (eom_internal.h). */
int eom__S_correct(eom_system *s, double *v, double *r)
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

enum metric { METRIC_MASS, METRIC_LAST_MASS, METRIC_IDENTITY };

/* The projection at time t with W = M at x, the M factored last, or I. */
static int project(eom_system *s, double t, double *x, double tol,
                   int *iters, enum metric metric, const char *fn)
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
        return eom__fail(s, EOM_ERR_NULL, "%s: x is NULL", fn);
    if (!(tol > 0.0))
        return eom__fail(s, EOM_ERR_ARG, "%s: tolerance %g", fn, tol);
    if (m == 0)
        return EOM_OK;
    if (!eom__finite(x, 2 * (size_t)n))
        return eom__fail(s, EOM_ERR_NONFINITE, "the state is not finite");
    /* nothing to do when phi and C qd (+ dphi/dt) are within the
     * tolerance */
    if ((rc = eom__constraint_rates(s, t, x, s->phi, s->phid, s->gam)))
        return rc;
    if (maxabs(s->phi, m) <= tol && maxabs(s->phid, m) <= tol)
        return EOM_OK;
    if (metric == METRIC_MASS ||
        (metric == METRIC_LAST_MASS && !s->mf_valid)) {
        double L;
        st = tp_lagrange(s->tL.ws, eom__tape_input(&s->tL, x, t), 0, &L,
                         NULL, s->M, NULL);
        if ((rc = eom__tape_status(s, st,
                                   "the Lagrangian or the mass matrix")))
            return rc;
        if ((rc = eom__factor_mass(s)) != EOM_OK)
            return rc;
    } else if (metric == METRIC_IDENTITY) {
        /* the Cholesky factor of I is I */
        memset(s->Mf, 0, (size_t)n * (size_t)n * sizeof(double));
        for (i = 0; i < n; i++)
            s->Mf[(size_t)i * (size_t)n + (size_t)i] = 1.0;
        s->mf_valid = false; /* no longer M's factor */
    }
    for (;;) {
        if ((rc = eom__constraints_at(s, t, x)) != EOM_OK)
            return rc;
        res = maxabs(s->phi, m);
        if (res <= tol)
            break;
        if (it == EOM_PROJ_MAXIT)
            /* slow convergence is the mark of a near-singular C: say how
             * near (the estimate of the last factorization) */
            return eom__fail(s, EOM_ERR_PROJECTION,
                             "projection onto the constraints: |phi| = %.3g "
                             "after %d iterations (tolerance %.3g); "
                             "C W^-1 C^T has reciprocal condition %.3g here%s",
                             res, it, tol, s->rcond_S,
                             s->rcond_S < 1e-3
                                 ? ": a (nearly) singular configuration"
                                 : "");
        if ((rc = eom__factor_S(s)) != EOM_OK)
            return rc;
        memcpy(s->wm, s->phi, (size_t)m * sizeof(double));
        if ((rc = eom__S_correct(s, x, s->wm)) != EOM_OK)
            return rc;
        it++;
    }
    /* velocities: C qd + dphi/dt = 0, both at the projected q (already in
     * s->C and s->phit) */
    if ((rc = eom__factor_S(s)) != EOM_OK)
        return rc;
    for (j = 0; j < m; j++) {
        double sum = s->tphi.tindex >= 0 ? s->phit[j] : 0.0;
        for (i = 0; i < n; i++)
            sum += s->C[(size_t)j * (size_t)n + (size_t)i] * x[n + i];
        s->wm[j] = sum;
    }
    if ((rc = eom__S_correct(s, x + n, s->wm)) != EOM_OK)
        return rc;
    if (iters)
        *iters = it;
    return eom__finite(x, 2 * (size_t)n)
               ? EOM_OK
               : eom__fail(s, EOM_ERR_NONFINITE,
                           "the projected state is not finite");
}

int eom_project(eom_system *s, double *x, double tol, int *iters)
{
    return project(s, s ? s->time : 0.0, x, tol, iters, METRIC_MASS,
                   "eom_project");
}

int eom_project_start(eom_system *s, double *x, double tol, int *iters)
{
    return project(s, s ? s->time : 0.0, x, tol, iters, METRIC_IDENTITY,
                   "eom_project_start");
}

int eom__project_step(eom_system *s, double t, double *x, double tol,
                      int *iters)
{
    return project(s, t, x, tol, iters, METRIC_LAST_MASS, "projection");
}
