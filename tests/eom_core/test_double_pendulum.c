/* test_double_pendulum.c - two uniform rods (eom_models_rod_chain(2, ..)),
 * angles th1, th2 from +x, gravity g along -y, against the closed form
 * derived by hand. With c = cos(th1 - th2), s = sin(th1 - th2) and
 * a = m2 l1 l2 / 2:
 *
 *   T = 1/2 M11 thd1^2 + a c thd1 thd2 + 1/2 M22 thd2^2,
 *   M11 = (m1/3 + m2) l1^2,  M12 = a c,  M22 = m2 l2^2 / 3
 *   V = m1 g l1/2 sin th1 + m2 g (l1 sin th1 + l2/2 sin th2)
 *
 * and Lagrange's equations d/dt dT/dthd - dT/dth + dV/dth = 0:
 *
 *   M11 thdd1 + a c thdd2 = -a s thd2^2 - (m1/2 + m2) g l1 cos th1
 *   a c thdd1 + M22 thdd2 =  a s thd1^2 - m2 g l2/2 cos th2
 *
 * solved here by Cramer's rule. At 200 random states, with masses,
 * lengths and g changed by eom_set_param every tenth state: M to 1e-14 of
 * max |M|, the accelerations to 1e-13 relative to the scale of the terms
 * (|F| (M11 + M22) / det M; the parameter ranges keep det M away from 0).
 */
#include <math.h>

#include "check.h"
#include "core_support.h"
#include "eom_models.h"
#include "support_rng.h"

#define NSTATES 200

int main(void)
{
    const double m0[2] = {1.0, 2.0}, l0[2] = {1.0, 0.5}, th0[2] = {0.1, 0.2};
    eom_system *s = core_system(eom_models_rod_chain(2, m0, l0, th0, 9.81,
                                                     0, 0.0));
    rng g = rng_seed(77);
    double m1 = m0[0], m2 = m0[1], l1 = l0[0], l2 = l0[1], gr = 9.81;
    double worst_M = 0.0, worst_a = 0.0;
    int i;

    CHECK(s != NULL);
    if (!s)
        CHECK_DONE();
    CHECK_INT(eom_system_ncoords(s), 2);
    CHECK_INT(eom_system_nconstraints(s), 0);

    for (i = 0; i < NSTATES; i++) {
        double x[4], xd[4], M[4], Mh[4], rhs[2], qdd[2];
        double th1, th2, w1, w2, a, c, sn, det, Mmax, sc, e;
        if (i % 10 == 0 && i > 0) {
            m1 = rng_range(&g, 0.2, 5.0);
            m2 = rng_range(&g, 0.2, 5.0);
            l1 = rng_range(&g, 0.3, 3.0);
            l2 = rng_range(&g, 0.3, 3.0);
            gr = rng_range(&g, 0.0, 20.0);
            CHECK_INT(core_set(s, "m1", m1), EOM_OK);
            CHECK_INT(core_set(s, "m2", m2), EOM_OK);
            CHECK_INT(core_set(s, "l1", l1), EOM_OK);
            CHECK_INT(core_set(s, "l2", l2), EOM_OK);
            CHECK_INT(core_set(s, "g", gr), EOM_OK);
        }
        th1 = x[0] = rng_range(&g, -CORE_PI, CORE_PI);
        th2 = x[1] = rng_range(&g, -CORE_PI, CORE_PI);
        w1 = x[2] = rng_range(&g, -4.0, 4.0);
        w2 = x[3] = rng_range(&g, -4.0, 4.0);

        a = 0.5 * m2 * l1 * l2;
        c = cos(th1 - th2);
        sn = sin(th1 - th2);
        Mh[0] = (m1 / 3.0 + m2) * l1 * l1;
        Mh[1] = Mh[2] = a * c;
        Mh[3] = m2 * l2 * l2 / 3.0;

        CHECK_INT(eom_mass_matrix(s, x, M), EOM_OK);
        Mmax = fmax(Mh[0], Mh[3]);
        e = core_maxabs((double[4]){M[0] - Mh[0], M[1] - Mh[1],
                                    M[2] - Mh[2], M[3] - Mh[3]}, 4) / Mmax;
        worst_M = fmax(worst_M, e);
        check_count_++;
        if (!(e <= 1e-14))
            CHECK_FAIL_("state %d: M error %.3g", i, e);
        CHECK_NEAR(M[1], M[2], 1e-15 * Mmax); /* symmetric */

        rhs[0] = -a * sn * w2 * w2 - (0.5 * m1 + m2) * gr * l1 * cos(th1);
        rhs[1] = a * sn * w1 * w1 - 0.5 * m2 * gr * l2 * cos(th2);
        det = Mh[0] * Mh[3] - Mh[1] * Mh[2];
        qdd[0] = (rhs[0] * Mh[3] - Mh[1] * rhs[1]) / det;
        qdd[1] = (Mh[0] * rhs[1] - Mh[2] * rhs[0]) / det;

        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        CHECK(xd[0] == w1 && xd[1] == w2);
        /* scale: the accelerations the largest force terms would give */
        sc = fmax(1.0, (fabs(a) * (w1 * w1 + w2 * w2) +
                        (m1 + m2) * gr * (l1 + l2)) *
                           (Mh[0] + Mh[3]) / det);
        e = fmax(fabs(xd[2] - qdd[0]), fabs(xd[3] - qdd[1])) / sc;
        worst_a = fmax(worst_a, e);
        check_count_++;
        if (!(e <= 1e-13))
            CHECK_FAIL_("state %d: qdd = (%.17g, %.17g), hand (%.17g, "
                        "%.17g), error %.3g", i, xd[2], xd[3], qdd[0],
                        qdd[1], e);
    }
    printf("largest relative error: M %.3g, accelerations %.3g\n", worst_M,
           worst_a);
    eom_system_free(&s);
    CHECK_DONE();
}
