/* sensitivity.c - forward sensitivities of constrained models: their
 * linearized projection onto the constraints, and the residuals of IDAS's
 * sensitivity equations; both from forward sweeps of the residual tape
 * (residual.c), exact.
 *
 * Projection. The integrators project a state onto phi(q, t; p) = 0 and
 * phi1 = C qd + dphi/dt = 0 by the correction of least W-norm
 * (constraints.c): q* = q - Y mu with phi(q*) = 0, then
 * qd* = qd - Y S^-1 phi1(q*, qd). Differentiated at a state on the
 * constraints (mu = 0 and phi1 = 0 there, so the derivatives of Y and S
 * drop out), along a direction (dq, dqd, dp):
 *     dq*  = dq  - Y S^-1 (C dq + phi_p dp)
 *     dqd* = dqd - Y S^-1 (G dq* + C dqd + phi1_p dp),  G = d(phi1)/dq
 * so that C dq* + phi_p dp = 0 and G dq* + C dqd* + phi1_p dp = 0: the
 * projected sensitivities are tangent to the constraint manifold of the
 * perturbed parameters, at both levels, the dependence of the velocity
 * constraint on q included. C dq + phi_p dp and G dq + C dqd + phi1_p dp
 * are the outputs phi0 and phi1 of the residual tape along the direction,
 * one forward sweep each (the second after dq* is known).
 *
 * IDAS. The residual G(t, Y, Y') of integrate_ida.c is (q' - v, E,
 * phi2 + 2 alpha phi1 + beta^2 phi0, W' + P) with the residual tape's
 * outputs at z = (q, v, v', lambda, t, p); its sensitivity residual along
 * (YS, YpS, e_p) is one forward sweep seeded with (q, v, v', lambda, p)
 * = (YS_q, YS_v, YpS_v, YS_lambda, e_p), plus YpS_q - YS_v and YpS_W.
 */
#include <string.h>

#include "eom_internal.h"

/* rows of the residual tape's outputs */
#define ROW_PHI1(n, m) ((n) + (m))
#define ROW_PHI0(n, m) ((n) + 2 * (m))
#define ROW_P(n, m) ((n) + 3 * (m))

/* The seed of direction k (of ns) on the parameter par[k]. */
static void seed_params(const eom_system *s, int ns, const int *par,
                        double *seed)
{
    const int first = 3 * s->n + s->m + 1;
    int k;
    for (k = 0; k < ns; k++)
        if (par[k] >= 0)
            seed[(size_t)(first + par[k]) * ns + k] = 1.0;
}

int eom__sens_project(eom_system *s, double t, const double *x, int identity,
                      int ns, const int *par, double *const *V,
                      double *work)
{
    const int n = s->n, m = s->m, nz = 3 * n + m + 1 + s->np;
    double *seed = work, *JS = seed + (size_t)nz * ns;
    int i, j, k, rc, st, pass;
    if (m == 0 || ns == 0)
        return EOM_OK;
    if ((rc = eom__residual_at(s, t, x)) != EOM_OK)
        return rc;
    if (identity) {
        /* W = I: its Cholesky factor is I (as eom_project_start) */
        memset(s->Mf, 0, (size_t)n * (size_t)n * sizeof(double));
        for (i = 0; i < n; i++)
            s->Mf[(size_t)i * (size_t)n + (size_t)i] = 1.0;
        s->mf_valid = false;
        if ((rc = eom__factor_S(s)) != EOM_OK)
            return rc;
    }
    /* pass 0: the positions by phi0; pass 1: the rates by phi1, along
     * the positions' corrected sensitivities */
    for (pass = 0; pass < 2; pass++) {
        const int row = pass == 0 ? ROW_PHI0(n, m) : ROW_PHI1(n, m);
        memset(seed, 0, (size_t)nz * (size_t)ns * sizeof *seed);
        for (k = 0; k < ns; k++)
            for (i = 0; i < 2 * n; i++)
                seed[(size_t)i * ns + k] = V[k][i];
        seed_params(s, ns, par, seed);
        st = tp_jvp(s->tRes.ws, s->jz, ns, seed, s->jy, JS);
        if ((rc = eom__tape_status(s, st, "the sensitivities' projection")))
            return rc;
        for (k = 0; k < ns; k++) {
            for (j = 0; j < m; j++)
                s->wm[j] = JS[(size_t)(row + j) * ns + k];
            rc = eom__S_correct(s, V[k] + pass * n, s->wm);
            if (rc != EOM_OK)
                return rc;
        }
    }
    for (k = 0; k < ns; k++)
        if (!eom__finite(V[k], 2 * (size_t)n))
            return eom__fail(s, EOM_ERR_NONFINITE,
                             "the projected sensitivities at t = %g are "
                             "not finite", t);
    return EOM_OK;
}

int eom__sens_dae_res(eom_system *s, double t, const double *Y,
                      const double *Yp, int ns, const int *par,
                      const double *const *YS, const double *const *YpS,
                      double *const *RS, double *work)
{
    const int n = s->n, m = s->m, nz = 3 * n + m + 1 + s->np;
    const double a2 = 2.0 * s->alpha, b2 = s->beta * s->beta;
    double *seed = work, *JS = seed + (size_t)nz * ns;
    int i, j, k, rc, st;
    if ((rc = eom__residual_z(s, t, Y, Yp + n, Y + 2 * n)) != EOM_OK)
        return rc;
    memset(seed, 0, (size_t)nz * (size_t)ns * sizeof *seed);
    for (k = 0; k < ns; k++) {
        for (i = 0; i < 2 * n; i++) /* q, v */
            seed[(size_t)i * ns + k] = YS[k][i];
        for (i = 0; i < n; i++) /* v' */
            seed[(size_t)(2 * n + i) * ns + k] = YpS[k][n + i];
        for (j = 0; j < m; j++) /* lambda */
            seed[(size_t)(3 * n + j) * ns + k] = YS[k][2 * n + j];
    }
    seed_params(s, ns, par, seed);
    st = tp_jvp(s->tRes.ws, s->jz, ns, seed, s->jy, JS);
    if ((rc = eom__tape_status(s, st, "the sensitivities' residual")))
        return rc;
    for (k = 0; k < ns; k++) {
        double *r = RS[k];
        for (i = 0; i < n; i++) {
            r[i] = YpS[k][i] - YS[k][n + i];
            r[n + i] = JS[(size_t)i * ns + k];
        }
        for (j = 0; j < m; j++)
            r[2 * n + j] = JS[(size_t)(n + j) * ns + k] +
                           a2 * JS[(size_t)(ROW_PHI1(n, m) + j) * ns + k] +
                           b2 * JS[(size_t)(ROW_PHI0(n, m) + j) * ns + k];
        r[2 * n + m] = YpS[k][2 * n + m] +
                       JS[(size_t)ROW_P(n, m) * ns + k];
    }
    return EOM_OK;
}
