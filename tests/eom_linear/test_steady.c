/* test_steady.c - eom_linearize_steady: the rolling disk about upright
 * straight rolling against its closed form, states of rest against
 * eom_linearize, and the refusals.
 *
 * The rolling disk (models/rolling-disk.eom; argv[1] is the models
 * folder): mass m, radius r, I_a = m r^2 / 2 about the axle, I_d =
 * m r^2 / 4 about a diameter, rolling upright along x at speed v, spin
 * Omega = v / r. Take the frame e1 (forward, horizontal), e2 (the axle),
 * e3 (in the disk's plane, from the contact to the centre G), turned by
 * the lean theta about e1 and the heading psi about the vertical; small
 * theta, theta_dot and psi_dot. The frame turns at w_f = theta_dot e1 +
 * psi_dot e3 (to first order), the disk at w_f + Omega e2. Then
 *   angular momentum about G   H = I_d theta_dot e1 + I_a Omega e2
 *                                  + I_d psi_dot e3,
 *   dH/dt = dH/dt|frame + w_f x H
 *         = (I_d theta_ddot - I_a Omega psi_dot) e1 + I_a Omega_dot e2
 *           + (I_d psi_ddot + I_a Omega theta_dot) e3;
 *   rolling: v_G = w x (r e3) = r Omega e1 - r theta_dot e2, so
 *   a_G = r Omega_dot e1 + (r Omega psi_dot - r theta_ddot) e2;
 *   the contact force F = m a_G + m g z, z = theta e2 + e3, acts at
 *   -r e3 from G, its moment about G is r F2 e1 - r F1 e2.
 * The e1, e3 and e2 components of dH/dt = r F2 e1 - r F1 e2 give
 *   (I_d + m r^2) theta_ddot = m g r theta + (I_a + m r^2) Omega psi_dot
 *   I_d psi_ddot = -I_a Omega theta_dot,    Omega_dot = 0.
 * In the states (theta, psi_dot, theta_dot) the characteristic
 * polynomial is s (s^2 - a + b c) with a = m g r / (I_d + m r^2),
 * b = (I_a + m r^2) Omega / (I_d + m r^2), c = I_a Omega / I_d, so the
 * eigenvalues are 0 and s = +-sqrt(a - b c), for the uniform disk
 *   s^2 = (4/5) (g / r - 3 v^2 / r^2):
 * unstable (real pair) below and oscillating (imaginary pair) above the
 * critical speed v_c = sqrt(g r / 3). The positions x, y, the heading
 * psi, the spin angle phi and the forward speed give zeros that the
 * reduction drops.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom/model_file.h"
#include "eom/steady.h"
#include "eom_models.h"
#include "lin_models.h"

static const double PI_ = 3.14159265358979323846;
static const char *models_dir = ".";

static eom_system *disk_system(void)
{
    char path[1024], err[2048];
    eom_file *f = NULL;
    eom_model *m = NULL;
    eom_system *s = NULL;
    snprintf(path, sizeof path, "%s/rolling-disk.eom", models_dir);
    if (eom_file_read(&f, path, err, sizeof err) != EOM_OK ||
        eom_file_build(f, &m, err, sizeof err) != EOM_OK ||
        eom_system_new(&s, m, err, sizeof err) != EOM_OK)
        CHECK_FAIL_("%s: %s", path, err);
    eom_file_free(&f);
    eom_model_free(&m);
    return s;
}

/* Upright, heading along x, rolling at v: x_dot = v, phi_dot = v / r. */
static void disk_state(const eom_system *s, double v, double *x)
{
    const double r = eom_get_param(s, eom_param_index(s, "r"));
    memset(x, 0, 10 * sizeof *x);
    x[5 + eom_coord_index(s, "x")] = v;
    x[5 + eom_coord_index(s, "phi")] = v / r;
}

/* s^2 of the closed form above. */
static double disk_s2(const eom_system *s, double v)
{
    const double r = eom_get_param(s, eom_param_index(s, "r"));
    const double g = eom_get_param(s, eom_param_index(s, "g"));
    return 0.8 * (g / r - 3.0 * v * v / (r * r));
}

/* re^2 - im^2 of the eigenvalue of largest modulus: s^2 of the closed
 * form, continuous across the critical speed. */
static double largest_s2(const eom_steady_linear *lin)
{
    int i, k = 0;
    for (i = 1; i < lin->nr; i++)
        if (hypot(lin->eig_re[i], lin->eig_im[i]) >
            hypot(lin->eig_re[k], lin->eig_im[k]))
            k = i;
    return lin->eig_re[k] * lin->eig_re[k] - lin->eig_im[k] * lin->eig_im[k];
}

static void test_disk(void)
{
    static const double speeds[] = {0.3, 1.5, 4.0};
    eom_system *s = disk_system();
    eom_steady_linear lin;
    double x[10];
    int k, i;
    if (!s)
        return;
    for (k = 0; k < 3; k++) {
        const double v = speeds[k], s2 = disk_s2(s, v);
        const double mag = sqrt(fabs(s2));
        disk_state(s, v, x);
        CHECK_INT(eom_linearize_steady(s, 0.0, x, NULL, 0, &lin), EOM_OK);
        CHECK_INT(lin.full.nz, 8); /* 10 states, 2 velocity rows */
        CHECK_INT(lin.nr, 3);
        CHECK_INT(lin.ndrop, 5);
        if (lin.nr != 3) {
            fprintf(stderr, "%s\n", eom_system_errmsg(s));
            eom_steady_linear_free(&lin);
            continue;
        }
        CHECK_INT(lin.kept[0], eom_coord_index(s, "theta"));
        CHECK_INT(lin.kept[1], 5 + eom_coord_index(s, "psi"));
        CHECK_INT(lin.kept[2], 5 + eom_coord_index(s, "theta"));
        /* x, y, phi; and psi, whose column is zero heading along x */
        CHECK(lin.cyclic[0] && lin.cyclic[1] && lin.cyclic[2] &&
              !lin.cyclic[3] && lin.cyclic[4]);
        printf("disk v = %g: eigenvalues %.15g%+.15gi, %.15g%+.15gi, "
               "%.15g%+.15gi; closed form 0, +-%s%.15g\n", v, lin.eig_re[0],
               lin.eig_im[0], lin.eig_re[1], lin.eig_im[1], lin.eig_re[2],
               lin.eig_im[2], s2 < 0.0 ? "i " : "", mag);
        if (s2 > 0.0) { /* sorted by real part: -mag, 0, +mag */
            CHECK_NEAR(lin.eig_re[0], -mag, 1e-10);
            CHECK_NEAR(lin.eig_re[1], 0.0, 1e-10);
            CHECK_NEAR(lin.eig_re[2], mag, 1e-10);
            for (i = 0; i < 3; i++)
                CHECK_NEAR(lin.eig_im[i], 0.0, 1e-10);
        } else { /* real parts equal: by imaginary part */
            CHECK_NEAR(lin.eig_im[0], -mag, 1e-10);
            CHECK_NEAR(lin.eig_im[1], 0.0, 1e-10);
            CHECK_NEAR(lin.eig_im[2], mag, 1e-10);
            for (i = 0; i < 3; i++)
                CHECK_NEAR(lin.eig_re[i], 0.0, 1e-10);
        }
        for (i = 0; i < lin.ndrop; i++)
            CHECK_NEAR(hypot(lin.drop_re[i], lin.drop_im[i]), 0.0, 1e-8);
        eom_steady_linear_free(&lin);
    }
    eom_system_free(&s);
}

/* The critical speed: the root of largest_s2 over v, by bisection. */
static void test_disk_critical(void)
{
    eom_system *s = disk_system();
    eom_steady_linear lin;
    double x[10], lo = 0.5, hi = 2.0, vc, r, g;
    int it;
    if (!s)
        return;
    r = eom_get_param(s, eom_param_index(s, "r"));
    g = eom_get_param(s, eom_param_index(s, "g"));
    for (it = 0; it < 60; it++) {
        const double mid = 0.5 * (lo + hi);
        double f;
        disk_state(s, mid, x);
        if (eom_linearize_steady(s, 0.0, x, NULL, 0, &lin) != EOM_OK) {
            CHECK_FAIL_("%s", eom_system_errmsg(s));
            break;
        }
        f = largest_s2(&lin);
        eom_steady_linear_free(&lin);
        if (f > 0.0)
            lo = mid;
        else
            hi = mid;
    }
    vc = 0.5 * (lo + hi);
    printf("disk critical speed %.15g, closed form sqrt(g r / 3) = %.15g\n",
           vc, sqrt(g * r / 3.0));
    CHECK_NEAR(vc, sqrt(g * r / 3.0), 1e-10);
    eom_system_free(&s);
}

/* Named states: the same three give the same eigenvalues; two of them
 * leave the heading rate out, which acts on the lean: refused. A start
 * that leans (the file's own) is not steady: refused with its
 * acceleration. */
static void test_disk_named_and_refused(void)
{
    eom_system *s = disk_system();
    eom_steady_linear lin, named;
    double x[10], acc = 0.0, scale = 0.0;
    int keep[3], at = -1;
    if (!s)
        return;
    keep[0] = 5 + eom_coord_index(s, "theta");
    keep[1] = eom_coord_index(s, "theta");
    keep[2] = 5 + eom_coord_index(s, "psi");
    disk_state(s, 1.5, x);
    CHECK_INT(eom_linearize_steady(s, 0.0, x, NULL, 0, &lin), EOM_OK);
    CHECK_INT(eom_linearize_steady(s, 0.0, x, keep, 3, &named), EOM_OK);
    if (lin.nr == 3 && named.nr == 3) {
        int i;
        CHECK_INT(named.kept[0], keep[1]); /* ascending */
        for (i = 0; i < 3; i++) {
            CHECK_NEAR(named.eig_re[i], lin.eig_re[i], 1e-12);
            CHECK_NEAR(named.eig_im[i], lin.eig_im[i], 1e-12);
        }
    }
    eom_steady_linear_free(&lin);
    eom_steady_linear_free(&named);
    CHECK_INT(eom_linearize_steady(s, 0.0, x, keep, 2, &named),
              EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(s), "not a closed system") != NULL);
    CHECK(named.nr == 0 && named.Ar == NULL && named.full.A == NULL);
    keep[1] = keep[0];
    CHECK_INT(eom_linearize_steady(s, 0.0, x, keep, 2, &named),
              EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(s), "named twice") != NULL);

    CHECK_INT(eom_initial_state(s, x), EOM_OK); /* leaning by 0.05 rad */
    CHECK_INT(eom_steady_check(s, 0.0, x, &acc, &scale, &at), EOM_ERR_ARG);
    CHECK_INT(at, eom_coord_index(s, "theta"));
    CHECK(acc > 1e-3 * scale);
    CHECK_INT(eom_linearize_steady(s, 0.0, x, NULL, 0, &lin), EOM_ERR_ARG);
    printf("refused: %s\n", eom_system_errmsg(s));
    CHECK(strstr(eom_system_errmsg(s), "neither at rest nor a steady "
                                       "motion") != NULL);
    CHECK(strstr(eom_system_errmsg(s), "theta_ddot") != NULL);
    CHECK(lin.nr == 0 && lin.kept == NULL);
    CHECK_INT(eom_linearize_steady(NULL, 0.0, x, NULL, 0, &lin),
              EOM_ERR_NULL);
    CHECK_INT(eom_linearize_steady(s, 0.0, NULL, NULL, 0, &lin),
              EOM_ERR_NULL);
    eom_steady_linear_free(NULL);
    eom_system_free(&s);
}

/* At rest, the eigenvalues are +-i omega of eom_linearize: the double
 * pendulum hanging, and the closed chain of four rods (two holonomic
 * constraints) at its equilibrium. */
static void rest_case(eom_system *s, const double *q, int n, int nr)
{
    eom_linear lin;
    eom_steady_linear st;
    double x[8];
    int i;
    memset(x, 0, sizeof x);
    memcpy(x, q, (size_t)n * sizeof *q);
    CHECK_INT(eom_linearize(s, q, &lin), EOM_OK);
    CHECK_INT(eom_linearize_steady(s, 0.0, x, NULL, 0, &st), EOM_OK);
    CHECK_INT(st.nr, 2 * nr);
    CHECK_INT(st.ndrop, 0);
    if (st.nr == 2 * nr && lin.nr == nr)
        for (i = 0; i < nr; i++) { /* sorted: -i w_max .. -i w_min, ... */
            CHECK_NEAR(st.eig_re[i], 0.0, 1e-10);
            CHECK_NEAR(st.eig_im[i], -lin.omega[nr - 1 - i], 1e-10);
            CHECK_NEAR(st.eig_im[nr + i], lin.omega[i], 1e-10);
        }
    eom_linear_free(&lin);
    eom_steady_linear_free(&st);
}

static void test_rest(void)
{
    const double m2[2] = {1.5, 0.8}, l2[2] = {1.2, 0.7};
    const double q2[2] = {-PI_ / 2.0, -PI_ / 2.0};
    const double m4[4] = {1.0, 0.6, 0.9, 1.2}, l4[4] = {0.8, 1.0, 0.7, 0.9};
    double q4[4] = {-1.2, -0.4, 0.4, 1.2};
    eom_system *s = lin_models_system(
        eom_models_rod_chain(2, m2, l2, q2, 9.81, 0, 0.0));
    int it;
    if (s)
        rest_case(s, q2, 2, 2);
    eom_system_free(&s);
    s = lin_models_system(eom_models_rod_chain(4, m4, l4, q4, 9.81, 1, 1.5));
    if (s) {
        CHECK_INT(eom_equilibrium(s, q4, 1e-12, &it), EOM_OK);
        rest_case(s, q4, 4, 2);
    }
    eom_system_free(&s);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        models_dir = argv[1];
    test_disk();
    test_disk_critical();
    test_disk_named_and_refused();
    test_rest();
    CHECK_DONE();
}
