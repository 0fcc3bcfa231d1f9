/* test_linearize.c - eom_linearize against closed forms.
 *
 *   point pendulum   omega = sqrt(g / l) hanging, -sqrt(g / l) inverted;
 *                    M = m l^2, K = m g l, D = c; the signs of K and D
 *                    against the library's own right-hand side.
 *   uniform rod      (eom_models_rod_chain(1), angle from +x) omega =
 *                    +-sqrt(3 g / (2 l)) hanging / upright.
 *   double pendulum  two uniform rods hanging straight down: M and K of
 *                    the closed form (below) and the frequencies of the
 *                    2 x 2 generalized eigenproblem by the quadratic
 *                    formula.
 *   bead on circle   Cartesian (x, y) with one constraint: at the bottom
 *                    K = (m g / l) I comes from the constraint curvature
 *                    alone (d2L/dq2 = 0) and omega = sqrt(g / l).
 *   closed chain     four rods pinned at both ends, at its equilibrium:
 *                    N (4 x 2) and the modes (4 x 2) are not symmetric,
 *                    so a storage-order mistake fails lp_check.
 * Each result passes lp_check (lin_props.h), and the linearized equation
 * M qdd = -K dq is compared with eom_rhs at a small displacement along
 * each mode. Then eom_linear_free and bad input.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom_models.h"
#include "lin_models.h"
#include "lin_props.h"

static const double PI_ = 3.14159265358979323846;
static const double G = 9.81;

static int linearize(eom_system *s, const double *q, eom_linear *lin)
{
    int rc = eom_linearize(s, q, lin);
    if (rc != EOM_OK)
        fprintf(stderr, "eom_linearize: %s\n", eom_system_errmsg(s));
    return rc;
}

/* Along each mode v: project q + eps v onto the constraints at rest, and
 * compare the library's accelerations with the linear prediction
 * qdd = -omega |omega| (dq) for dq = the projected displacement. */
static void check_rhs_along_modes(eom_system *s, const double *q,
                                  const eom_linear *lin, double eps,
                                  double tol)
{
    const int n = lin->n;
    double x[2 * LP_NMAX], xd[2 * LP_NMAX];
    int i, k;
    for (i = 0; i < lin->nr; i++) {
        const double e = lin->omega[i] * fabs(lin->omega[i]);
        double scale = 0.0;
        for (k = 0; k < n; k++) {
            x[k] = q[k] + eps * lin->modes[k * lin->nr + i];
            x[n + k] = 0.0;
        }
        if (eom_system_nconstraints(s) > 0)
            CHECK_INT(eom_project(s, x, 1e-14, NULL), EOM_OK);
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        for (k = 0; k < n; k++)
            scale = fmax(scale, fabs(e * (x[k] - q[k])));
        for (k = 0; k < n; k++)
            CHECK_NEAR(xd[n + k] / scale, -e * (x[k] - q[k]) / scale, tol);
    }
}

static void test_point_pendulum(void)
{
    const double m = 0.7, l = 1.3, c = 0.3, w = sqrt(G / l);
    eom_system *s = lin_models_system(lin_models_pendulum(m, l, G, 0.0, 0.0,
                                                          0, 0.0));
    eom_system *sd = lin_models_system(lin_models_pendulum(m, l, G, 0.0, c,
                                                           1, 0.0));
    eom_linear lin;
    double q, x[2], xd[2];
    CHECK(s && sd);
    if (!s || !sd)
        goto done;

    q = 0.0;
    CHECK_INT(linearize(s, &q, &lin), EOM_OK);
    CHECK_INT(lin.n, 1);
    CHECK_INT(lin.nr, 1);
    CHECK_NEAR(lin.M[0], m * l * l, 1e-14);
    CHECK_NEAR(lin.K[0], m * G * l, 1e-14);
    CHECK(lin.D[0] == 0.0);
    CHECK_NEAR(lin.omega[0], w, 1e-14);
    CHECK_NEAR(fabs(lin.N[0]), 1.0, 0.0);
    lp_check(s, &q, &lin, 1e-12);
    check_rhs_along_modes(s, &q, &lin, 1e-6, 1e-6);
    eom_linear_free(&lin);

    /* inverted: unstable, a negative omega of the same magnitude */
    q = PI_;
    CHECK_INT(linearize(s, &q, &lin), EOM_OK);
    CHECK_NEAR(lin.K[0], -m * G * l, 1e-14);
    CHECK_NEAR(lin.omega[0], -w, 1e-14);
    lp_check(s, &q, &lin, 1e-12);
    check_rhs_along_modes(s, &q, &lin, 1e-6, 1e-6);
    eom_linear_free(&lin);

    /* within the rest tolerance; and clearly out of it */
    q = 1e-9;
    CHECK_INT(linearize(s, &q, &lin), EOM_OK);
    CHECK_NEAR(lin.omega[0], w * sqrt(cos(q)), 1e-14);
    eom_linear_free(&lin);
    q = 0.3;
    CHECK_INT(eom_linearize(s, &q, &lin), EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(s), "not an equilibrium") != NULL);
    CHECK(lin.M == NULL && lin.omega == NULL && lin.nr == 0);

    /* damping: D = d2R/dqd2 = c, and -D qd is the force eom_rhs applies */
    q = 0.0;
    CHECK_INT(linearize(sd, &q, &lin), EOM_OK);
    CHECK_NEAR(lin.D[0], c, 1e-14);
    CHECK_NEAR(lin.Dr[0], c, 1e-14);
    CHECK_NEAR(lin.omega[0], w, 1e-14); /* undamped frequency */
    x[0] = 0.0, x[1] = 1e-3;
    CHECK_INT(eom_rhs(sd, 0.0, x, xd), EOM_OK);
    CHECK_NEAR(xd[1], -lin.D[0] * x[1] / lin.M[0], 1e-12);
    lp_check(sd, &q, &lin, 1e-12);
    eom_linear_free(&lin);
done:
    eom_system_free(&s);
    eom_system_free(&sd);
}

static void test_rod(void)
{
    const double m = 2.0, l = 0.8, w = sqrt(3.0 * G / (2.0 * l));
    double q = -PI_ / 2.0;
    eom_system *s = lin_models_system(
        eom_models_rod_chain(1, &m, &l, &q, G, 0, 0.0));
    eom_linear lin;
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(linearize(s, &q, &lin), EOM_OK);
    CHECK_NEAR(lin.M[0], m * l * l / 3.0, 1e-14);
    CHECK_NEAR(lin.K[0], m * G * l / 2.0, 1e-14);
    CHECK_NEAR(lin.omega[0], w, 1e-14);
    lp_check(s, &q, &lin, 1e-12);
    eom_linear_free(&lin);
    q = PI_ / 2.0;
    CHECK_INT(linearize(s, &q, &lin), EOM_OK);
    CHECK_NEAR(lin.omega[0], -w, 1e-14);
    eom_linear_free(&lin);
    eom_system_free(&s);
}

/* Two uniform rods hanging straight down (angles -pi/2 from +x). With
 * T = qd^T M qd / 2 and V at second order:
 *   M = [[(m1/3 + m2) l1^2, m2 l1 l2 / 2], [m2 l1 l2 / 2, m2 l2^2 / 3]]
 *   K = g diag((m1/2 + m2) l1, m2 l2 / 2)
 * det(K - w^2 M) = 0: a w^4 + b w^2 + c = 0 with a = det M,
 * b = -(K11 M22 + K22 M11), c = K11 K22. */
static void test_double_pendulum(void)
{
    const double m[2] = {1.5, 0.8}, l[2] = {1.2, 0.7};
    const double q[2] = {-PI_ / 2.0, -PI_ / 2.0};
    const double M11 = (m[0] / 3.0 + m[1]) * l[0] * l[0];
    const double M12 = m[1] * l[0] * l[1] / 2.0;
    const double M22 = m[1] * l[1] * l[1] / 3.0;
    const double K11 = G * (m[0] / 2.0 + m[1]) * l[0];
    const double K22 = G * m[1] * l[1] / 2.0;
    const double a = M11 * M22 - M12 * M12, b = -(K11 * M22 + K22 * M11);
    const double c = K11 * K22, disc = sqrt(b * b - 4.0 * a * c);
    /* the smaller root as c / (a x) to avoid cancellation */
    const double w2hi = (-b + disc) / (2.0 * a), w2lo = c / (a * w2hi);
    eom_system *s = lin_models_system(
        eom_models_rod_chain(2, m, l, q, G, 0, 0.0));
    eom_linear lin;
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(linearize(s, q, &lin), EOM_OK);
    CHECK_INT(lin.nr, 2);
    CHECK_NEAR(lin.M[0], M11, 1e-14);
    CHECK_NEAR(lin.M[1], M12, 1e-14);
    CHECK_NEAR(lin.M[3], M22, 1e-14);
    CHECK_NEAR(lin.K[0], K11, 1e-14);
    CHECK_NEAR(lin.K[1], 0.0, 1e-14);
    CHECK_NEAR(lin.K[3], K22, 1e-14);
    CHECK_NEAR(lin.omega[0], sqrt(w2lo), 1e-13);
    CHECK_NEAR(lin.omega[1], sqrt(w2hi), 1e-13);
    /* N is the identity without constraints */
    CHECK(lin.N[0] == 1.0 && lin.N[1] == 0.0 && lin.N[2] == 0.0 &&
          lin.N[3] == 1.0);
    /* the first mode swings both rods the same way, the second opposed */
    CHECK(lin.modes[0] * lin.modes[2] > 0.0);
    CHECK(lin.modes[1] * lin.modes[3] < 0.0);
    lp_check(s, q, &lin, 1e-12);
    check_rhs_along_modes(s, q, &lin, 1e-6, 1e-5);
    eom_linear_free(&lin);
    eom_system_free(&s);
}

/* The bead: V = m g y is linear, so K is the constraint term alone:
 * C^T lambda = -dL/dq = (0, m g) with C = (x, y) = (0, -l) gives lambda =
 * -m g / l and K = -lambda I = (m g / l) I. */
static void test_bead(void)
{
    const double m = 0.5, l = 0.9, w = sqrt(G / l);
    eom_system *s = lin_models_system(eom_models_bead_on_circle(m, l, G));
    eom_linear lin;
    double q[2];
    CHECK(s != NULL);
    if (!s)
        return;
    q[0] = 0.0, q[1] = -l;
    CHECK_INT(linearize(s, q, &lin), EOM_OK);
    CHECK_INT(lin.nr, 1);
    CHECK_NEAR(lin.K[0], m * G / l, 1e-14);
    CHECK_NEAR(lin.K[1], 0.0, 1e-14);
    CHECK_NEAR(lin.K[3], m * G / l, 1e-14);
    CHECK_NEAR(fabs(lin.N[0]), 1.0, 1e-15);
    CHECK_NEAR(lin.N[1], 0.0, 1e-15);
    CHECK_NEAR(lin.Kr[0], m * G / l, 1e-14);
    CHECK_NEAR(lin.Mr[0], m, 1e-14);
    CHECK_NEAR(lin.omega[0], w, 1e-14);
    CHECK(lin.modes[0] > 0.0); /* the largest component is positive */
    lp_check(s, q, &lin, 1e-12);
    check_rhs_along_modes(s, q, &lin, 1e-6, 1e-5);
    eom_linear_free(&lin);

    q[0] = 0.0, q[1] = l; /* on top */
    CHECK_INT(linearize(s, q, &lin), EOM_OK);
    CHECK_NEAR(lin.omega[0], -w, 1e-14);
    check_rhs_along_modes(s, q, &lin, 1e-6, 1e-5);
    eom_linear_free(&lin);

    q[0] = l, q[1] = 0.0; /* on the circle, not at rest */
    CHECK_INT(eom_linearize(s, q, &lin), EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(s), "not an equilibrium") != NULL);
    q[0] = 0.0, q[1] = -1.1 * l; /* off the circle */
    CHECK_INT(eom_linearize(s, q, &lin), EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(s), "constraint 1") != NULL);
    CHECK(lin.M == NULL && lin.nr == 0);
    eom_system_free(&s);
}

/* Four rods pinned at (0, 0) and (D, 0): n = 4, m = 2, nr = 2. */
static void test_closed_chain(void)
{
    const double m[4] = {1.0, 0.6, 0.9, 1.2}, l[4] = {0.8, 1.0, 0.7, 0.9};
    double q[4] = {-1.2, -0.4, 0.4, 1.2};
    eom_system *s = lin_models_system(
        eom_models_rod_chain(4, m, l, q, G, 1, 1.5));
    eom_linear lin;
    int it = 0;
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(eom_equilibrium(s, q, 1e-12, &it), EOM_OK);
    CHECK_INT(linearize(s, q, &lin), EOM_OK);
    CHECK_INT(lin.nr, 2);
    if (lin.nr == 2) {
        CHECK(lin.omega[0] > 0.0); /* hanging: stable */
        CHECK(lin.omega[0] < lin.omega[1]);
        /* N has no symmetric structure to hide a transposition */
        CHECK(fabs(lin.N[1] - lin.N[2]) > 1e-3);
    }
    lp_check(s, q, &lin, 1e-11);
    check_rhs_along_modes(s, q, &lin, 1e-6, 1e-4);
    eom_linear_free(&lin);
    eom_system_free(&s);
}

static void test_free_and_bad_input(void)
{
    eom_system *s = lin_models_system(lin_models_pendulum(1.0, 1.0, G, 0.0,
                                                          0.0, 0, 0.0));
    eom_linear lin;
    double q = 0.0;
    eom_linear_free(NULL);
    memset(&lin, 0, sizeof lin);
    eom_linear_free(&lin);
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(linearize(s, &q, &lin), EOM_OK);
    eom_linear_free(&lin);
    CHECK(lin.M == NULL && lin.K == NULL && lin.D == NULL && lin.N == NULL &&
          lin.Mr == NULL && lin.Kr == NULL && lin.Dr == NULL &&
          lin.omega == NULL && lin.modes == NULL && lin.n == 0 &&
          lin.nr == 0);
    eom_linear_free(&lin); /* twice: harmless */

    CHECK_INT(eom_linearize(NULL, &q, &lin), EOM_ERR_NULL);
    CHECK_INT(eom_linearize(s, NULL, &lin), EOM_ERR_NULL);
    CHECK(eom_system_errmsg(s)[0] != '\0');
    CHECK_INT(eom_linearize(s, &q, NULL), EOM_ERR_NULL);
    q = NAN;
    CHECK_INT(eom_linearize(s, &q, &lin), EOM_ERR_NONFINITE);
    CHECK(lin.M == NULL);
    q = INFINITY;
    CHECK_INT(eom_linearize(s, &q, &lin), EOM_ERR_NONFINITE);
    /* a success clears the message */
    q = 0.0;
    CHECK_INT(linearize(s, &q, &lin), EOM_OK);
    CHECK(eom_system_errmsg(s)[0] == '\0');
    eom_linear_free(&lin);
    eom_system_free(&s);
}

int main(void)
{
    test_point_pendulum();
    test_rod();
    test_double_pendulum();
    test_bead();
    test_closed_chain();
    test_free_and_bad_input();
    CHECK_DONE();
}
