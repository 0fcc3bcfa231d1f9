/* test_condition.c - eom_condition and the factorization of S.
 *
 *  - M = diag(a, b) (T = (a xd^2 + b yd^2)/2): rcond_M = min(a, b) /
 *    max(a, b), the reciprocal 1-norm condition number computed here;
 *    rcond_S = 1 without constraints.
 *  - The four-bar (core_support.h): at regular configurations, rcond_M and
 *    rcond_S are estimates of 1 / (|A|_1 |A^-1|_1) for the closed-form M
 *    and S = C M^-1 C^T: never below the true value (an estimate of the
 *    condition number is a lower bound) and within a factor 3 of it.
 *  - Approaching a singular configuration, the chain stretched straight
 *    (angles (e, -e, e), e -> 0, where the row dphi_y/dq vanishes):
 *    rcond_S falls like e^2, strictly decreasing, below 1e-9 at e = 1e-5;
 *    at e = 0, EOM_ERR_RANK_DEFICIENT, and
 *    rcond_S is 0 there (not the estimate of an earlier factorization).
 *  - S refactored after a parameter change (the same pattern, new values,
 *    the pivots of the first factorization): with constraints phi1 = A x,
 *    phi2 = B x + z on a free unit point mass (in either order), S =
 *    [[A^2, A B], [A B, B^2 + 1]], strongly coupled for A = 0.01, B = 100;
 *    with B then set to 0, S = diag(1e-4, 1): the evaluation succeeds,
 *    rcond_S = 1e-4, qdd = lambda = 0 (no forces, linear constraints), and
 *    a projection sends x and z, and only them, to 0.
 */
#include <math.h>
#include <string.h>

#include "check.h"
#include "core_support.h"
#include "eom_models.h"
#include "support_num.h"

static int diag_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mulc(R, tp_add(R, tp_mul(R, eom_param(c, "a"),
                                       tp_sqr(R, eom_qd(c, 0))),
                             tp_mul(R, eom_param(c, "b"),
                                    tp_sqr(R, eom_qd(c, 1)))),
                   0.5);
    return 0;
}

static int unit_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val s = tp_const(R, 0.0);
    int i;
    (void)user;
    for (i = 0; i < eom_ncoords(c); i++)
        s = tp_add(R, s, tp_sqr(R, eom_qd(c, i)));
    *out = tp_mulc(R, s, 0.5);
    return 0;
}

/* phi1 = A x, phi2 = B x + z (a gravity-free point mass in 3-D), or the
 * other way round when *(int *)user. */
static int ab_phi(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    const int swap = *(const int *)user;
    out[swap] = tp_mul(R, eom_param(c, "A"), eom_q(c, 0));
    out[1 - swap] = tp_add(R, tp_mul(R, eom_param(c, "B"), eom_q(c, 0)),
                           eom_q(c, 2));
    return 0;
}

/* 1-norm condition number of a k x k matrix (k <= 3) from its inverse. */
static double cond1(int k, const double *A)
{
    double inv[9], work[9], e[3], na = 0.0, ni = 0.0;
    int i, j;
    for (j = 0; j < k; j++) {
        memcpy(work, A, sizeof(double) * (size_t)(k * k));
        for (i = 0; i < k; i++)
            e[i] = i == j ? 1.0 : 0.0;
        if (core_dense_solve(k, work, e))
            return INFINITY;
        for (i = 0; i < k; i++)
            inv[i * k + j] = e[i];
    }
    for (j = 0; j < k; j++) {
        double sa = 0.0, si = 0.0;
        for (i = 0; i < k; i++) {
            sa += fabs(A[i * k + j]);
            si += fabs(inv[i * k + j]);
        }
        na = fmax(na, sa);
        ni = fmax(ni, si);
    }
    return na * ni;
}

/* S = C M^-1 C^T (2 x 2) for the chain at q. */
static void chain_S(const core_chain *c, const double *x, double *S)
{
    double M[9], C[6], Y[6], A[9];
    int i, j;
    core_chain_mass(c, x, M);
    core_chain_constraints(c, x, NULL, C, NULL);
    for (j = 0; j < 2; j++) {
        memcpy(A, M, sizeof A);
        memcpy(Y + 3 * j, C + 3 * j, 3 * sizeof(double));
        core_dense_solve(3, A, Y + 3 * j);
    }
    for (i = 0; i < 2; i++)
        for (j = 0; j < 2; j++)
            S[i * 2 + j] = C[3 * i] * Y[3 * j] + C[3 * i + 1] * Y[3 * j + 1] +
                           C[3 * i + 2] * Y[3 * j + 2];
}

static void diagonal(void)
{
    static const double ab[3][2] = {{2.0, 8.0}, {5.0, 0.5}, {1.0, 1e-6}};
    eom_model *md = NULL;
    eom_system *s;
    double x[4] = {0.1, 0.2, 0.3, 0.4}, rM = -1.0, rS = -1.0;
    int k;
    eom_model_new(&md);
    eom_model_add_coord(md, "x", "m", 0.0, 0.0);
    eom_model_add_coord(md, "y", "m", 0.0, 0.0);
    eom_model_add_param(md, "a", "kg", 1.0, NULL);
    eom_model_add_param(md, "b", "kg", 1.0, NULL);
    eom_model_set_kinetic(md, diag_T, NULL);
    s = core_system(md);
    CHECK(s != NULL);
    if (!s)
        return;
    for (k = 0; k < 3; k++) {
        const double a = ab[k][0], b = ab[k][1];
        CHECK_INT(core_set(s, "a", a), EOM_OK);
        CHECK_INT(core_set(s, "b", b), EOM_OK);
        CHECK_INT(eom_condition(s, x, &rM, &rS), EOM_OK);
        CHECK_NEAR(rM, fmin(a, b) / fmax(a, b), 1e-15);
        CHECK(rS == 1.0);
    }
    /* either output may be NULL */
    CHECK_INT(eom_condition(s, x, NULL, &rS), EOM_OK);
    CHECK_INT(eom_condition(s, x, &rM, NULL), EOM_OK);
    eom_system_free(&s);
}

static void fourbar(void)
{
    core_chain c = fourbar_closed_form();
    eom_system *s = fourbar_system();
    double prev = INFINITY;
    int k;
    CHECK(s != NULL);
    if (!s)
        return;
    for (k = 0; k < 8; k++) {
        double x[6], M[9], S[4], rM, rS, tM, tS;
        fourbar_assemble(&c, -3.0 + 0.8 * k, k % 2 ? 1 : -1, 0.0, x);
        core_chain_mass(&c, x, M);
        chain_S(&c, x, S);
        tM = 1.0 / cond1(3, M);
        tS = 1.0 / cond1(2, S);
        CHECK_INT(eom_condition(s, x, &rM, &rS), EOM_OK);
        check_count_++;
        if (!(rM >= tM * (1.0 - 1e-12) && rM <= 3.0 * tM &&
              rS >= tS * (1.0 - 1e-12) && rS <= 3.0 * tS))
            CHECK_FAIL_("state %d: rcond_M %.6g (true %.6g), rcond_S %.6g "
                        "(true %.6g)", k, rM, tM, rS, tS);
    }
    /* towards the straight chain (D = sum of the rods: the configurations
     * below are near-consistent) */
    CHECK_INT(core_set(s, "D", FB_L[0] + FB_L[1] + FB_L[2]), EOM_OK);
    c.D = FB_L[0] + FB_L[1] + FB_L[2];
    for (k = 0; k <= 5; k++) {
        const double e = 0.3 * pow(0.1, k);
        double x[6] = {e, -e, e, 0.0, 0.0, 0.0}, S[4], rM, rS, tS;
        chain_S(&c, x, S);
        tS = 1.0 / cond1(2, S);
        CHECK_INT(eom_condition(s, x, &rM, &rS), EOM_OK);
        printf("e = %.1e: rcond_S %.3g (true %.3g)\n", e, rS, tS);
        CHECK(rS < prev);
        CHECK(rS >= tS * (1.0 - 1e-9) && rS <= 3.0 * tS);
        prev = rS;
    }
    CHECK(prev < 1e-9);
    {
        double x[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}, rM, rS = -1.0;
        /* exactly singular: no error (the pseudo-inverse serves it), an
         * estimate of 0 or at round-off */
        CHECK_INT(eom_condition(s, x, &rM, &rS), EOM_OK);
        CHECK(rS >= 0.0 && rS < 1e-15);
    }
    eom_system_free(&s);
}

static void stale_pivots(int *swap)
{
    eom_model *md = NULL;
    eom_system *s;
    double x[6] = {0.3, -0.2, 0.1, 0.5, 0.7, -0.4}, xd[6], lam[2];
    double rM, rS;
    eom_model_new(&md);
    eom_model_add_coord(md, "x", "m", 0.0, 0.0);
    eom_model_add_coord(md, "y", "m", 0.0, 0.0);
    eom_model_add_coord(md, "z", "m", 0.0, 0.0);
    eom_model_add_param(md, "A", "", 0.01, NULL);
    eom_model_add_param(md, "B", "", 100.0, NULL);
    eom_model_set_kinetic(md, unit_T, NULL);
    eom_model_set_constraints(md, 2, ab_phi, swap);
    s = core_system(md);
    CHECK(s != NULL);
    if (!s)
        return;
    /* A = 0.01, B = 100: fine, if poorly scaled */
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
    /* no force, so qdd = 0 and lambda = 0 (gamma = 0: linear constraints) */
    CHECK(core_maxabs(xd + 3, 3) <= 1e-12);
    /* B = 0: S = diag(1e-4, 1) */
    CHECK_INT(core_set(s, "B", 0.0), EOM_OK);
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
    if (eom_system_errmsg(s)[0])
        printf("B = 0: %s\n", eom_system_errmsg(s));
    CHECK(core_maxabs(xd + 3, 3) <= 1e-12);
    CHECK_INT(eom_multipliers(s, 0.0, x, lam), EOM_OK);
    CHECK(core_maxabs(lam, 2) <= 1e-12);
    CHECK_INT(eom_condition(s, x, &rM, &rS), EOM_OK);
    CHECK_NEAR(rS, 1e-4, 1e-12);
    /* and a projection there: x -> 0 and z -> 0 (phi = (A x, z)) */
    CHECK_INT(eom_project(s, x, 1e-14, NULL), EOM_OK);
    CHECK(fabs(x[0]) <= 1e-12 && fabs(x[2]) <= 1e-14);
    CHECK(x[1] == -0.2);
    eom_system_free(&s);
}

int main(void)
{
    diagonal();
    fourbar();
    {
        static int order[2] = {0, 1};
        stale_pivots(&order[0]);
        stale_pivots(&order[1]);
    }
    CHECK_DONE();
}
