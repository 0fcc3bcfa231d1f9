/* test_rank_deficient.c - linearization and equilibrium where the
 * constraint Jacobian C has deficient rank (docs/linearization.md):
 *
 *   redundant sphere a point mass on a sphere with the constraint given
 *                    twice (C: 2 rows of rank 1 everywhere): nr = 2 and
 *                    omega = sqrt(g / l) twice, as with one constraint;
 *                    eom_equilibrium still converges (its KKT matrix is
 *                    singular throughout).
 *   straight chain   three rods pinned at (0, 0) and (l1 + l2 + l3, 0),
 *                    lying straight along x: the x-row of C is zero
 *                    (a singular configuration), nr = 2, and without
 *                    gravity K = 0 so omega = 0, finite. With gravity
 *                    the straight chain is not at rest: EOM_ERR_ARG.
 *   flexible link    paper/NOTES.md: one flexible link pinned at both
 *                    ends; at th = 0 the x-row of C is identically zero
 *                    (and C has rank 1 at every th, since phi does not
 *                    depend on the modes). The bending modes of a
 *                    pinned-pinned beam, omega_i = (i pi)^2 sqrt(EI /
 *                    (m L^3)), with and without gravity, and the sag
 *                    a1 = -4 m g L^3 / (pi^5 EI) from eom_equilibrium.
 */
#include <math.h>
#include <stdbool.h>
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

static int equilibrium(eom_system *s, double *q, double tol, int *it)
{
    int rc = eom_equilibrium(s, q, tol, it);
    if (rc != EOM_OK)
        fprintf(stderr, "eom_equilibrium: %s\n", eom_system_errmsg(s));
    return rc;
}

static bool all_finite(const eom_linear *lin)
{
    int i, n = lin->n, nr = lin->nr;
    for (i = 0; i < n * n; i++)
        if (!isfinite(lin->M[i]) || !isfinite(lin->K[i]) ||
            !isfinite(lin->D[i]))
            return false;
    for (i = 0; i < n * nr; i++)
        if (!isfinite(lin->N[i]) || !isfinite(lin->modes[i]))
            return false;
    for (i = 0; i < nr; i++)
        if (!isfinite(lin->omega[i]))
            return false;
    return true;
}

static void test_redundant_sphere(void)
{
    const double m = 0.5, l = 0.9;
    eom_system *s = lin_models_system(lin_models_redundant_sphere(m, l, G));
    eom_linear lin;
    double q[3] = {0.0, -l, 0.0};
    int it = 0, i;
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(linearize(s, q, &lin), EOM_OK);
    CHECK_INT(lin.nr, 2);
    CHECK(all_finite(&lin));
    /* the minimum-norm multipliers (1, 2) lambda / 5 give the same
     * curvature term, (m g / l) I, as the single constraint's lambda */
    for (i = 0; i < 9; i++)
        CHECK_NEAR(lin.K[i], i % 4 == 0 ? m * G / l : 0.0, 1e-14);
    for (i = 0; i < lin.nr; i++)
        CHECK_NEAR(lin.omega[i], sqrt(G / l), 1e-14);
    lp_check(s, q, &lin, 1e-12);
    eom_linear_free(&lin);

    q[0] = 0.3, q[1] = -0.7, q[2] = 0.2;
    CHECK_INT(equilibrium(s, q, 1e-12, &it), EOM_OK);
    CHECK_NEAR(q[0], 0.0, 1e-11);
    CHECK_NEAR(q[1], -l, 1e-11);
    CHECK_NEAR(q[2], 0.0, 1e-11);
    CHECK(it > 0);
    eom_system_free(&s);
}

static void test_straight_chain(void)
{
    const double m[3] = {1.0, 0.7, 1.3}, l[3] = {1.0, 1.5, 0.7};
    const double q[3] = {0.0, 0.0, 0.0};
    eom_system *s = lin_models_system(
        eom_models_rod_chain(3, m, l, q, 0.0, 1, l[0] + l[1] + l[2]));
    double x[6] = {0}, C[6], phi[2];
    eom_linear lin;
    int i;
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(eom_constraint_jacobian(s, x, C, phi), EOM_OK);
    CHECK(C[0] == 0.0 && C[1] == 0.0 && C[2] == 0.0); /* the x-row */
    CHECK(fabs(phi[0]) < 1e-15 && phi[1] == 0.0);

    CHECK_INT(linearize(s, q, &lin), EOM_OK);
    CHECK_INT(lin.nr, 2);
    CHECK(all_finite(&lin));
    for (i = 0; i < lin.nr; i++) {
        CHECK_NEAR(lin.omega[i], 0.0, 1e-6);
        /* N is orthogonal to the y-row (l1, l2, l3) */
        CHECK_NEAR(l[0] * lin.N[i] + l[1] * lin.N[2 + i] +
                       l[2] * lin.N[4 + i], 0.0, 1e-14);
    }
    lp_check(s, q, &lin, 1e-12);
    eom_linear_free(&lin);

    /* with gravity the straight chain is not at rest (the rods' weights
     * are not proportional to the y-row of C) */
    CHECK_INT(eom_set_param(s, eom_param_index(s, "g"), G), EOM_OK);
    CHECK_INT(eom_linearize(s, q, &lin), EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(s), "not an equilibrium") != NULL);
    CHECK(lin.M == NULL);
    eom_system_free(&s);
}

static void test_flexible_link(void)
{
    const double m = 0.9, L = 1.1, EI = 35.0;
    const double w = PI_ * PI_ * sqrt(EI / (m * L * L * L));
    const double sag = -4.0 * m * G * L * L * L / (pow(PI_, 5) * EI);
    eom_system *s = lin_models_system(lin_models_flexible_link(m, L, EI, G));
    double x[6] = {0}, C[6], q[3];
    eom_linear lin;
    int it = 0, i, j;
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(eom_constraint_jacobian(s, x, C, NULL), EOM_OK);
    CHECK(C[0] == 0.0 && C[1] == 0.0 && C[2] == 0.0); /* x-row at th = 0 */

    /* the equilibrium from a start off the constraints */
    q[0] = 0.05, q[1] = 0.0, q[2] = 0.01;
    CHECK_INT(equilibrium(s, q, 1e-12, &it), EOM_OK);
    CHECK_NEAR(q[0], 0.0, 1e-12);
    CHECK_NEAR(q[1], sag, 1e-12);
    CHECK_NEAR(q[2], 0.0, 1e-12);
    CHECK(it > 0);

    CHECK_INT(linearize(s, q, &lin), EOM_OK);
    CHECK_INT(lin.nr, 2);
    CHECK(all_finite(&lin));
    if (lin.nr == 2) {
        /* N spans the two modes (any orthonormal basis of them) */
        for (j = 0; j < 2; j++)
            CHECK_NEAR(lin.N[j], 0.0, 1e-12);
        for (i = 0; i < 2; i++)
            for (j = 0; j < 2; j++)
                CHECK_NEAR(lin.Mr[i * 2 + j], i == j ? m / 2.0 : 0.0, 1e-13);
        CHECK_NEAR(lin.omega[0], w, 1e-12);
        CHECK_NEAR(lin.omega[1], 4.0 * w, 1e-12);
        /* mode i moves a_i alone, mass-normalized: |a_i| = sqrt(2 / m) */
        CHECK_NEAR(lin.modes[1 * 2 + 0], sqrt(2.0 / m), 1e-12);
        CHECK_NEAR(lin.modes[2 * 2 + 0], 0.0, 1e-12);
        CHECK_NEAR(lin.modes[1 * 2 + 1], 0.0, 1e-12);
        CHECK_NEAR(lin.modes[2 * 2 + 1], sqrt(2.0 / m), 1e-12);
    }
    lp_check(s, q, &lin, 1e-12);
    eom_linear_free(&lin);

    /* without gravity: straight, the same frequencies */
    CHECK_INT(eom_set_param(s, eom_param_index(s, "g"), 0.0), EOM_OK);
    q[0] = q[1] = q[2] = 0.0;
    CHECK_INT(linearize(s, q, &lin), EOM_OK);
    CHECK_INT(lin.nr, 2);
    if (lin.nr == 2) {
        CHECK_NEAR(lin.omega[0], w, 1e-12);
        CHECK_NEAR(lin.omega[1], 4.0 * w, 1e-12);
    }
    eom_linear_free(&lin);
    eom_system_free(&s);
}

int main(void)
{
    test_redundant_sphere();
    test_straight_chain();
    test_flexible_link();
    CHECK_DONE();
}
