/* mass_route.c - the route of the mass matrix in the right-hand side, and
 * the Lagrange block evaluated along it.
 *
 * Dense (EOM_MASS_DENSE): every evaluation forms M with n directions
 * (tp_lagrange_t: one forward and one reverse sweep carrying n tangents)
 * and factors it (eom__factor_mass).
 *
 * Constant (EOM_MASS_CONSTANT), when mass_pattern.c finds from the tape
 * that M depends on none of q, qd and t: M is formed and factored once
 * per set of parameter values, and an evaluation needs of the Lagrangian
 * only L, g = dL/dq, dL/dt and
 *     h = (d2L/dqd dq) qd + d2L/dqd dt,
 * the rate rows of ONE Hessian-vector product along (qd, 0 [, 1]) (the
 * q rows of H (qd, 0, 1) are not used): a sweep with one direction
 * instead of n, so its cost no longer grows with n times the tape. The
 * factor is kept in s->Mf and reused while s->mf_valid holds (anything
 * that puts another matrix there, the projection's identity metric, or
 * eom__forget, clears it) and the parameters are those it was made for
 * (s->param_gen, advanced by eom_set_param). Each reuse still checks the
 * integrator's pivot floor (s->mass_pivot_min), which may have been set
 * after the factor was made.
 *
 * The rule: the constant route whenever M is constant, except for a
 * system running compiled tapes with n <= EOM_MASS_CONST_COMPILED_N,
 * whose whole Lagrange block is one call of generated code (the one
 * direction of the constant route is an interpreted sweep). The route is
 * reported by eom_system_mass_route and in eom_stats.mass_route;
 * eom_system_set_mass_route overrides it (the dense route for any
 * model, the constant one only for a constant M).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"
#include "mass_route.h"

#define EOM_MASS_CONST_COMPILED_N 64

/* The rule, kept in s once the analysis exists (not when it could not
 * be allocated: the next call tries again). */
int eom__mass_route_find(eom_system *s)
{
    eom_mass *ms = eom__mass_info(s);
    int route = EOM_MASS_CONSTANT;
    if (!ms)
        return EOM_MASS_DENSE;
    if (!ms->ok || !ms->constant || ms->requested == EOM_MASS_DENSE ||
        (s->compiled && s->n <= EOM_MASS_CONST_COMPILED_N))
        route = EOM_MASS_DENSE;
    s->route = route;
    s->route_key = 1 + (int)s->compiled;
    return route;
}

int eom_system_mass_route(eom_system *s)
{
    if (!s)
        return EOM_ERR_NULL;
    if (eom__kkt_applies(s))
        return EOM_MASS_SPARSE;
    return eom__mass_route(s);
}

int eom_system_set_mass_route(eom_system *s, int route)
{
    eom_mass *ms;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (route != 0 && route != EOM_MASS_DENSE &&
        route != EOM_MASS_CONSTANT && route != EOM_MASS_SPARSE)
        return eom__fail(s, EOM_ERR_ARG,
                         "eom_system_set_mass_route: route %d: 0 (auto), "
                         "%d (dense), %d (constant) or %d (sparse)", route,
                         EOM_MASS_DENSE, EOM_MASS_CONSTANT, EOM_MASS_SPARSE);
    if (!(ms = eom__mass_info(s)))
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    if ((route == EOM_MASS_CONSTANT || route == EOM_MASS_SPARSE) &&
        !(ms->ok && ms->constant))
        return eom__fail(s, EOM_ERR_ARG,
                         "eom_system_set_mass_route: the mass matrix is "
                         "not constant: the Lagrangian's tape makes "
                         "d2L/dqd2 depend on the coordinates, the rates "
                         "or the time");
    if (route == EOM_MASS_SPARSE && !eom__kkt_possible(s))
        return eom__fail(s, EOM_ERR_ARG,
                         "eom_system_set_mass_route: the sparse route "
                         "needs holonomic constraints that do not read "
                         "the time (this model has %s)",
                         s->m == 0    ? "no constraints"
                         : s->mv > 0 ? "velocity constraints"
                                     : "constraints that read the time");
    ms->requested = route;
    ms->held = false;
    s->route_key = 0; /* eom__mass_route finds it again */
    return EOM_OK;
}

const char *eom_mass_route_name(int route)
{
    switch (route) {
    case EOM_MASS_DENSE:
        return "dense";
    case EOM_MASS_CONSTANT:
        return "constant";
    case EOM_MASS_SPARSE:
        return "sparse";
    default:
        return "unknown";
    }
}

/* The constant route's factor: made when not held for these parameters,
 * else the pivot floor checked (eom__factor_mass gives the message). */
static int constant_factor(eom_system *s, eom_mass *ms, double t,
                           const double *x)
{
    int st, rc, k;
    double L;
    if (ms->held && s->mf_valid && ms->gen == s->param_gen) {
        if (s->mass_pivot_min > 0.0 &&
            eom__mass_min_pivot(s, &k) < s->mass_pivot_min)
            return eom__factor_mass(s);
        return EOM_OK;
    }
    ms->held = false;
    st = tp_lagrange_t(s->tL.ws, eom__tape_input(&s->tL, x, t), 0, &L,
                       NULL, NULL, s->M, NULL);
    if ((rc = eom__tape_status(s, st, "the Lagrangian or the mass matrix")))
        return rc;
    if ((rc = eom__factor_mass(s)) != EOM_OK)
        return rc;
    ms->held = true;
    ms->gen = s->param_gen;
    return EOM_OK;
}

int eom__lagrange_block(eom_system *s, double t, const double *x)
{
    const int n = s->n;
    const double *xin;
    double *d, *hs;
    int st, rc, i, ni;
    eom_mass *ms;
    if (eom__mass_route(s) != EOM_MASS_CONSTANT)
        return eom__block_dense(s, t, x);
    ms = s->mass;
    xin = eom__tape_input(&s->tL, x, t);
    ni = tp_tape_n_indep(s->tL.tape);
    /* L itself, so that a state outside the model's domain is an error
     * even where the derivatives happen to stay finite (as on the dense
     * route, whose forward sweep computes it) */
    if (!ms->wset || ms->wgen != s->param_gen) {
        for (i = 0; i < s->np; i++)
            if (s->tL.pmap[i] >= 0)
                tp_ws_set_param(ms->ws, s->tL.pmap[i], s->pval[i]);
        ms->wset = true;
        ms->wgen = s->param_gen;
    }
    st = tp_eval(ms->ws, xin, ms->y);
    if ((rc = eom__tape_status(s, st, "the Lagrangian or a derivative")))
        return rc;
    /* the direction (qd, 0 [, 1]), then H times it, then the gradient */
    d = ms->work;
    hs = d + ni;
    for (i = 0; i < n; i++) {
        d[i] = x[n + i];
        d[n + i] = 0.0;
    }
    if (ni > 2 * n)
        d[2 * n] = 1.0;
    st = tp_hvp(ms->ws, xin, ms->w, 1, d, hs + ni, hs);
    if ((rc = eom__tape_status(s, st, "the Lagrangian or a derivative")))
        return rc;
    memcpy(s->g, hs + ni, (size_t)n * sizeof(double));
    s->dLdt = ni > 2 * n ? hs[ni + 2 * n] : 0.0;
    memcpy(s->h, hs + n, (size_t)n * sizeof(double));
    return EOM_OK;
}

int eom__mass_factor(eom_system *s, double t, const double *x)
{
    if (eom__mass_route(s) != EOM_MASS_CONSTANT)
        return eom__factor_mass(s);
    return constant_factor(s, s->mass, t, x);
}
