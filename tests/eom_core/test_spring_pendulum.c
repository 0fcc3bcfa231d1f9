/* test_spring_pendulum.c - the spring pendulum of tests/models (r, theta
 * from the downward vertical) against its equations of motion derived by
 * hand from T = m/2 (rd^2 + r^2 thd^2), V = k/2 (r - r0)^2
 * + m g (r0 - r cos th):
 *
 *   r_dd  = r thd^2 - (k/m)(r - r0) + g cos th
 *   th_dd = -(2 rd thd + g sin th) / r
 *   M     = diag(m, m r^2)
 *
 * at 200 random states, the parameters changed with eom_set_param every
 * tenth state. Tolerance 1e-13 relative to the largest term of each
 * equation (the library and the formulas round differently, by a few
 * ulps). Also: xd[0..n) = qd exactly, and the system's bookkeeping (names,
 * units, counts, defaults, initial state).
 */
#include <math.h>
#include <string.h>

#include "check.h"
#include "core_support.h"
#include "eom_models.h"
#include "support_rng.h"

#define NSTATES 200

static void check_bookkeeping(eom_system *s)
{
    double x[4];
    CHECK_INT(eom_system_ncoords(s), 2);
    CHECK_INT(eom_system_nconstraints(s), 0);
    CHECK_INT(eom_system_nparams(s), 4);
    CHECK_INT(eom_system_nprobes(s), 0);
    CHECK_INT(eom_system_has_tv(s), 1);
    CHECK_INT(eom_system_has_dissipation(s), 0);
    CHECK(strcmp(eom_coord_name(s, 0), "r") == 0);
    CHECK(strcmp(eom_coord_name(s, 1), "theta") == 0);
    CHECK(strcmp(eom_coord_unit(s, 1), "rad") == 0);
    CHECK_INT(eom_coord_index(s, "theta"), 1);
    CHECK_INT(eom_coord_index(s, "phi"), -1);
    CHECK_INT(eom_param_index(s, "k"), 1);
    CHECK(strcmp(eom_param_unit(s, 1), "N/m") == 0);
    CHECK(strcmp(eom_param_description(s, 1), "spring stiffness") == 0);
    CHECK(eom_param_default(s, 1) == 75.0);
    CHECK(eom_get_param(s, 1) == 75.0);
    /* the model's defaults: r = r0 + 0.1, theta = 0.5, at rest */
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    CHECK(x[0] == 1.0 + 0.1 && x[1] == 0.5 && x[2] == 0.0 && x[3] == 0.0);
}

int main(void)
{
    eom_system *s = core_system(eom_models_spring_pendulum(1.0, 75.0, 1.0,
                                                           9.81));
    rng g = rng_seed(20240601);
    double m = 1.0, k = 75.0, r0 = 1.0, gr = 9.81;
    double worst_r = 0.0, worst_th = 0.0;
    int i;

    CHECK(s != NULL);
    if (!s)
        CHECK_DONE();
    check_bookkeeping(s);

    for (i = 0; i < NSTATES; i++) {
        double x[4], xd[4], M[4], r, th, rd, thd, rdd, thdd, sc_r, sc_th;
        if (i % 10 == 0 && i > 0) {
            m = rng_range(&g, 0.1, 10.0);
            k = rng_range(&g, 1.0, 1000.0);
            r0 = rng_range(&g, 0.2, 3.0);
            gr = rng_range(&g, 0.0, 30.0);
            CHECK_INT(core_set(s, "m", m), EOM_OK);
            CHECK_INT(core_set(s, "k", k), EOM_OK);
            CHECK_INT(core_set(s, "r0", r0), EOM_OK);
            CHECK_INT(core_set(s, "g", gr), EOM_OK);
            CHECK(eom_get_param(s, eom_param_index(s, "k")) == k);
        }
        r = x[0] = rng_range(&g, 0.1, 4.0);
        th = x[1] = rng_range(&g, -CORE_PI, CORE_PI);
        rd = x[2] = rng_range(&g, -5.0, 5.0);
        thd = x[3] = rng_range(&g, -5.0, 5.0);
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        CHECK(xd[0] == rd && xd[1] == thd);

        rdd = r * thd * thd - (k / m) * (r - r0) + gr * cos(th);
        thdd = -(2.0 * rd * thd + gr * sin(th)) / r;
        sc_r = fmax(1.0, fabs(r * thd * thd) + fabs((k / m) * (r - r0)) +
                             fabs(gr));
        sc_th = fmax(1.0, (fabs(2.0 * rd * thd) + fabs(gr)) / r);
        worst_r = fmax(worst_r, fabs(xd[2] - rdd) / sc_r);
        worst_th = fmax(worst_th, fabs(xd[3] - thdd) / sc_th);
        if (!(fabs(xd[2] - rdd) <= 1e-13 * sc_r) ||
            !(fabs(xd[3] - thdd) <= 1e-13 * sc_th))
            CHECK_FAIL_("state %d: (r_dd, th_dd) = (%.17g, %.17g), hand "
                        "(%.17g, %.17g)", i, xd[2], xd[3], rdd, thdd);
        check_count_++;

        CHECK_INT(eom_mass_matrix(s, x, M), EOM_OK);
        CHECK_NEAR(M[0], m, 1e-15);
        CHECK(M[1] == 0.0 && M[2] == 0.0);
        CHECK_NEAR(M[3], m * r * r, 1e-15);
    }
    printf("largest relative error: r_dd %.3g, th_dd %.3g\n", worst_r,
           worst_th);
    eom_system_free(&s);
    CHECK(s == NULL);
    CHECK_DONE();
}
