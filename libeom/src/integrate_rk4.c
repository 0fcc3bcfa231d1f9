/* integrate_rk4.c - the classical fixed-step Runge-Kutta method, the
 * paper's choice, kept as a baseline. Steps of at most dt, shortened
 * evenly so that every requested time is hit exactly; a projection onto
 * the constraints after every step. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "integrate_internal.h"

typedef struct rk4 {
    double *k1, *k2, *k3, *k4, *tmp, *ynew; /* [N] each */
    long steps;
} rk4;

static void rk4_destroy(eom_integ *it)
{
    rk4 *r = it->impl;
    if (!r)
        return;
    free(r->k1);
    free(r->k2);
    free(r->k3);
    free(r->k4);
    free(r->tmp);
    free(r->ynew);
    free(r);
    it->impl = NULL;
}

static int rk4_init(eom_integ *it)
{
    rk4 *r = calloc(1, sizeof *r);
    const size_t N = (size_t)it->N;
    if (!r)
        return EOM_ERR_NOMEM;
    it->impl = r;
    r->k1 = calloc(N, sizeof(double));
    r->k2 = calloc(N, sizeof(double));
    r->k3 = calloc(N, sizeof(double));
    r->k4 = calloc(N, sizeof(double));
    r->tmp = calloc(N, sizeof(double));
    r->ynew = calloc(N, sizeof(double));
    if (!r->k1 || !r->k2 || !r->k3 || !r->k4 || !r->tmp || !r->ynew)
        return EOM_ERR_NOMEM;
    return EOM_OK;
}

/* One step of size h from (it->t, it->y) into r->ynew. */
static int rk4_step(eom_integ *it, rk4 *r, double h)
{
    const int N = it->N;
    const double t = it->t, *y = it->y;
    int i, rc;
    if ((rc = eom__integ_rhs(it, t, y, r->k1)))
        return rc;
    for (i = 0; i < N; i++)
        r->tmp[i] = y[i] + 0.5 * h * r->k1[i];
    if ((rc = eom__integ_rhs(it, t + 0.5 * h, r->tmp, r->k2)))
        return rc;
    for (i = 0; i < N; i++)
        r->tmp[i] = y[i] + 0.5 * h * r->k2[i];
    if ((rc = eom__integ_rhs(it, t + 0.5 * h, r->tmp, r->k3)))
        return rc;
    for (i = 0; i < N; i++)
        r->tmp[i] = y[i] + h * r->k3[i];
    if ((rc = eom__integ_rhs(it, t + h, r->tmp, r->k4)))
        return rc;
    for (i = 0; i < N; i++)
        r->ynew[i] = y[i] + h / 6.0 * (r->k1[i] + 2.0 * r->k2[i] +
                                       2.0 * r->k3[i] + r->k4[i]);
    return EOM_OK;
}

static int rk4_advance(eom_integ *it, double tout)
{
    rk4 *r = it->impl;
    const double span = tout - it->t;
    /* the fewest steps of at most dt (with slack for rounding) */
    double ksteps = ceil(span / it->o.dt * (1.0 - 1e-12));
    long k, nsteps;
    int rc;
    if (ksteps < 1.0)
        ksteps = 1.0;
    if (ksteps > (double)it->o.max_steps)
        return eom__integ_fail(it, EOM_ERR_SOLVER,
                               "rk4: reaching t = %.17g takes %.0f steps, "
                               "more than max_steps = %ld", tout, ksteps,
                               it->o.max_steps);
    nsteps = (long)ksteps;
    for (k = 0; k < nsteps; k++) {
        /* the last step lands on tout exactly */
        const double tn = k + 1 == nsteps
                              ? tout
                              : it->t + (tout - it->t) / (double)(nsteps - k);
        const double t_prev = it->t;
        if ((rc = rk4_step(it, r, tn - it->t)) != EOM_OK)
            return eom__integ_fail(it, rc, "rk4: %s", it->msg);
        /* projected at the step's end: constraints that read the time
         * must hold at tn */
        it->t = tn;
        if ((rc = eom__integ_project(it, r->ynew)) != EOM_OK ||
            (rc = eom__integ_branch(it, tn, r->ynew)) != EOM_OK) {
            it->t = t_prev; /* it->y still holds the state at t_prev */
            return eom__integ_fail(it, rc, "rk4: %s", it->msg);
        }
        memcpy(it->y, r->ynew, (size_t)it->N * sizeof(double));
        r->steps++;
    }
    return EOM_OK;
}

static void rk4_stats(const eom_integ *it, eom_stats *st)
{
    const rk4 *r = it->impl;
    st->steps = r->steps;
}

const eom_integ_ops eom__rk4_ops = {"rk4", rk4_init, rk4_advance, rk4_stats,
                                    rk4_destroy};
