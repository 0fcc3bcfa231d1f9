/* test_baumgarte.c - Baumgarte stabilization, projection off.
 *
 * With C qdd = gamma - 2 alpha (C qd) - beta^2 phi, the residual of each
 * constraint obeys the linear equation
 *     phi'' + 2 alpha phi' + beta^2 phi = 0,   phi' = C qd,
 * whatever the mechanism. So, from a perturbed four-bar state (phi0 and
 * phid0 of order 1e-3, computed here by hand), integrating with RK4 (dt
 * 1e-3, eom_opts.project = 0) must give phi(t) equal to the solution of
 * that equation:
 *   alpha = beta = 0 (off): phi0 + phid0 t       (drift: grows linearly)
 *   alpha = beta = a:       (phi0 + (phid0 + a phi0) t) e^{-a t}
 *   alpha < beta:           e^{-alpha t} (phi0 cos wt
 *                           + (phid0 + alpha phi0)/w sin wt),
 *                           w = sqrt(beta^2 - alpha^2)
 * checked every 0.05 s over 3 s to 1e-8 absolute (3e-6 of the initial
 * residual, 3.6e-3; what is left is RK4's truncation error, 3e-9 at
 * most; a wrong factor or sign in the stabilization term would show as
 * 1e-3). With alpha = beta = 5 the residual at 3 s is below 1e-4 of
 * its start; without stabilization it is larger than at the start. No
 * projection is counted, and eom_integ_stats' max_residual reports the
 * drift. Bad arguments (negative, NaN, infinite) are EOM_ERR_ARG.
 */
#include <math.h>
#include <string.h>

#include "check.h"
#include "core_support.h"
#include "eom_models.h"
#include "support_num.h"

/* The residual predicted at t for one constraint. */
static double predicted(double alpha, double beta, double p0, double v0,
                        double t)
{
    if (alpha == 0.0 && beta == 0.0)
        return p0 + v0 * t;
    if (alpha == beta)
        return (p0 + (v0 + alpha * p0) * t) * exp(-alpha * t);
    {
        const double w = sqrt(beta * beta - alpha * alpha);
        return exp(-alpha * t) *
               (p0 * cos(w * t) + (v0 + alpha * p0) / w * sin(w * t));
    }
}

/* Run from x0 with (alpha, beta); the largest deviation from the
 * prediction and the final |phi|. */
static void run(eom_system *s, const core_chain *c, const double *x0,
                double alpha, double beta, double *dev, double *phi_end,
                double *max_res)
{
    double x[6], phi0[2], v0[2], phi[2] = {0.0, 0.0}, Cm[6];
    eom_opts o;
    eom_integ *it = NULL;
    eom_stats st;
    int k, j;
    *dev = INFINITY;
    *phi_end = INFINITY;
    *max_res = INFINITY;
    CHECK_INT(eom_set_baumgarte(s, alpha, beta), EOM_OK);
    core_chain_constraints(c, x0, phi0, Cm, NULL);
    core_matvec(2, 3, Cm, x0 + 3, v0);
    eom_opts_default(&o);
    o.dt = 1e-3;
    o.project = 0;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_OK);
    if (!it)
        return;
    *dev = 0.0;
    for (k = 1; k <= 60; k++) {
        const double t = 0.05 * k;
        if (eom_integ_advance(it, t, x, NULL) != EOM_OK) {
            CHECK_FAIL_("alpha %g beta %g: %s", alpha, beta,
                        eom_integ_errmsg(it));
            *dev = INFINITY;
            break;
        }
        core_chain_constraints(c, x, phi, NULL, NULL);
        for (j = 0; j < 2; j++)
            *dev = fmax(*dev, fabs(phi[j] - predicted(alpha, beta, phi0[j],
                                                      v0[j], t)));
    }
    *phi_end = core_maxabs(phi, 2);
    CHECK_INT(eom_integ_stats(it, &st), EOM_OK);
    CHECK_INT(st.projections, 0);
    *max_res = st.max_residual;
    eom_integ_free(&it);
}

int main(void)
{
    const core_chain c = fourbar_closed_form();
    eom_system *s = fourbar_system();
    double x0[6], phi0[2], dev, pend, mres, start;
    CHECK(s != NULL);
    if (!s)
        CHECK_DONE();

    /* bad arguments */
    CHECK_INT(eom_set_baumgarte(s, -1.0, 0.0), EOM_ERR_ARG);
    CHECK_INT(eom_set_baumgarte(s, 0.0, -1.0), EOM_ERR_ARG);
    CHECK_INT(eom_set_baumgarte(s, NAN, 1.0), EOM_ERR_ARG);
    CHECK_INT(eom_set_baumgarte(s, 1.0, INFINITY), EOM_ERR_ARG);
    CHECK(eom_system_errmsg(s)[0] != '\0');
    CHECK_INT(eom_set_baumgarte(NULL, 1.0, 1.0), EOM_ERR_NULL);

    /* a consistent state, then perturbed: phi ~ 1e-3, C qd ~ 1e-3 */
    fourbar_assemble(&c, 0.8, 1, 2.0, x0);
    x0[0] += 1e-3;
    x0[2] -= 2e-3;
    x0[4] += 1e-3;
    core_chain_constraints(&c, x0, phi0, NULL, NULL);
    start = core_maxabs(phi0, 2);
    printf("initial |phi| %.3g\n", start);
    CHECK(start > 5e-4);

    run(s, &c, x0, 0.0, 0.0, &dev, &pend, &mres);
    printf("off:          deviation %.3g, |phi(3 s)| %.3g, max residual "
           "%.3g\n", dev, pend, mres);
    CHECK(dev <= 1e-8);
    CHECK(pend > start);
    CHECK(mres >= pend);

    run(s, &c, x0, 5.0, 5.0, &dev, &pend, &mres);
    printf("alpha=beta=5: deviation %.3g, |phi(3 s)| %.3g\n", dev, pend);
    CHECK(dev <= 1e-8);
    CHECK(pend <= 1e-4 * start);

    run(s, &c, x0, 2.0, 6.0, &dev, &pend, &mres);
    printf("alpha 2 beta 6: deviation %.3g, |phi(3 s)| %.3g\n", dev, pend);
    CHECK(dev <= 1e-8);
    CHECK(pend <= 1e-2 * start);

    /* back off: the equations are the plain ones again (a rhs equal to
     * that of a fresh system) */
    {
        eom_system *f = fourbar_system();
        double xa[6], xb[6];
        CHECK_INT(eom_set_baumgarte(s, 0.0, 0.0), EOM_OK);
        CHECK(f != NULL);
        if (f) {
            CHECK_INT(eom_rhs(s, 0.0, x0, xa), EOM_OK);
            CHECK_INT(eom_rhs(f, 0.0, x0, xb), EOM_OK);
            CHECK_SAME("Baumgarte off", xa, xb, 6);
        }
        eom_system_free(&f);
    }
    eom_system_free(&s);
    CHECK_DONE();
}
