/* test_projection.c - eom_project: onto phi(q) = 0 and C qd = 0 with the
 * correction of least M-norm.
 *
 * Four-bar (core_support.h), consistent states assembled in the test,
 * q perturbed by eps = 1e-3 and 1e-4 (random direction, each component
 * within +-eps), qd by O(1):
 *  - |phi(q)| <= tol = 1e-12 and |C qd| <= 1e-14 |C| |qd| afterwards (phi,
 *    C by hand), in at most 6 Newton iterations;
 *  - the position correction dq is the least M-norm one to first order
 *    (the Newton iterates move C by O(eps)): with N spanning the null
 *    space of C (for a 2 x 3 C, the cross product of its rows),
 *    |N^T M dq| / (|N| max|M_ij|) <= 10 eps^2 (M dq is in the range of
 *    C^T up to second order), and dq equals the linearized least-M-norm
 *    step -M^-1 C^T (C M^-1 C^T)^-1 phi (at the perturbed q) to within
 *    20 eps^2; the first measure is over 100 times larger for the
 *    Euclidean least-norm step -C^T (C C^T)^-1 phi (it is O(eps)), so the
 *    check tells the two apart;
 *  - the velocity correction is exact: |N^T M dqd| / (|N| max|M_ij|)
 *    <= 1e-14 |dqd| (M at the state given, which is where eom_project
 *    factors it), and C qd = 0;
 *  - a consistent state: q unchanged bit for bit, 0 iterations;
 *  - a large perturbation (0.3 rad) still converges.
 * Bead on a circle (M = m I): the projection is the radial one, exactly,
 * for any perturbation: q -> l q / |q|, qd -> its tangential part.
 * Errors: tol <= 0 is EOM_ERR_ARG; an unreachable ground length (D = 10 m
 * > the sum of the rods) fails with EOM_ERR_PROJECTION or
 * EOM_ERR_RANK_DEFICIENT and a message.
 */
#include <math.h>
#include <string.h>

#include "check.h"
#include "core_support.h"
#include "eom_models.h"
#include "support_num.h"
#include "support_rng.h"

static void cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static double norm3(const double *a)
{
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* |N^T M d| / (|N| max|M_ij|) with N the null vector of C (2 x 3): the
 * part of M d outside the range of C^T. */
static double off_range(const double *C, const double *M, const double *d)
{
    double N[3], Md[3];
    cross(C, C + 3, N);
    core_matvec(3, 3, M, d, Md);
    return fabs(dot3(N, Md)) / (norm3(N) * core_maxabs(M, 9));
}

/* The step -W^-1 C^T (C W^-1 C^T)^-1 phi for a metric W (3 x 3). */
static void linear_step(const double *W, const double *C, const double *phi,
                        double *dq)
{
    double Y[6], S[4], z[2], A[9];
    int j, i;
    for (j = 0; j < 2; j++) {
        memcpy(A, W, sizeof A);
        for (i = 0; i < 3; i++)
            Y[j * 3 + i] = C[j * 3 + i];
        core_dense_solve(3, A, Y + j * 3); /* Y row j = W^-1 C_j^T */
    }
    for (i = 0; i < 2; i++)
        for (j = 0; j < 2; j++)
            S[i * 2 + j] = dot3(C + i * 3, Y + j * 3);
    z[0] = phi[0];
    z[1] = phi[1];
    core_dense_solve(2, S, z);
    for (i = 0; i < 3; i++)
        dq[i] = -(Y[i] * z[0] + Y[3 + i] * z[1]);
}

static void fourbar_cases(eom_system *s, const core_chain *c, rng *g)
{
    const double eps_list[2] = {1e-3, 1e-4};
    int e, k, i;
    for (e = 0; e < 2; e++) {
        const double eps = eps_list[e];
        double worst_off = 0.0, worst_lin = 0.0, worst_E = 0.0;
        for (k = 0; k < 20; k++) {
            double x0[6], xp[6], x[6], phi[2], phip[2], C[6], Cp[6], M[9];
            double Mh[9], dq[3], dqd[3], dq_lin[3], dq_E[3], r[2], I3[9];
            double o, lin, sc;
            int iters = -1;
            fourbar_assemble(c, rng_range(g, -CORE_PI, CORE_PI),
                             k % 2 ? 1 : -1, rng_range(g, -3.0, 3.0), x0);
            memcpy(xp, x0, sizeof xp);
            for (i = 0; i < 3; i++) {
                xp[i] += rng_range(g, -eps, eps);
                xp[3 + i] += rng_range(g, -1.0, 1.0);
            }
            memcpy(x, xp, sizeof x);
            CHECK_INT(eom_project(s, x, 1e-12, &iters), EOM_OK);
            CHECK(iters >= 1 && iters <= 6);

            core_chain_constraints(c, x, phi, C, NULL);
            CHECK(core_maxabs(phi, 2) <= 1e-12);
            core_matvec(2, 3, C, x + 3, r);
            /* round-off scale: the correction is computed from the rates
             * before the projection, which may be the larger */
            sc = core_maxabs(C, 6) *
                 fmax(core_maxabs(x + 3, 3), core_maxabs(xp + 3, 3));
            CHECK(core_maxabs(r, 2) <= 1e-14 * sc);

            for (i = 0; i < 3; i++) {
                dq[i] = x[i] - xp[i];
                dqd[i] = x[3 + i] - xp[3 + i];
            }
            /* positions: least M-norm to first order */
            CHECK_INT(eom_mass_matrix(s, xp, M), EOM_OK);
            core_chain_mass(c, xp, Mh);
            CHECK_VEC_SCALED("mass matrix", M, Mh, 9, core_maxabs(Mh, 9),
                             1e-14);
            o = off_range(C, Mh, dq) / (eps * eps);
            worst_off = fmax(worst_off, o);
            CHECK(o <= 10.0);
            core_chain_constraints(c, xp, phip, Cp, NULL);
            linear_step(Mh, Cp, phip, dq_lin);
            for (i = 0; i < 3; i++)
                dq_lin[i] -= dq[i];
            lin = norm3(dq_lin) / (eps * eps);
            worst_lin = fmax(worst_lin, lin);
            CHECK(lin <= 20.0);
            /* the Euclidean least-norm step is measurably different */
            memset(I3, 0, sizeof I3);
            I3[0] = I3[4] = I3[8] = 1.0;
            linear_step(I3, Cp, phip, dq_E);
            worst_E = fmax(worst_E, off_range(Cp, Mh, dq_E) / (eps * eps));

            /* velocities: exactly least M-norm (M at the given state) */
            o = off_range(C, Mh, dqd);
            CHECK(o <= 1e-14 * norm3(dqd));
        }
        printf("eps %g, in units of eps^2: |N^T M dq| / (|N| max|M|) up to "
               "%.3g, |dq - linearized step| up to %.3g; Euclidean step: "
               "%.3g\n", eps, worst_off, worst_lin, worst_E);
        CHECK(worst_E > 100.0 * worst_off);
    }

    /* a consistent state: q untouched, no iteration */
    {
        double x0[6], x[6];
        int iters = -1;
        fourbar_assemble(c, 0.7, 1, 2.0, x0);
        memcpy(x, x0, sizeof x);
        CHECK_INT(eom_project(s, x, 1e-12, &iters), EOM_OK);
        CHECK_INT(iters, 0);
        CHECK_SAME("consistent q", x, x0, 3);
        CHECK_VEC("consistent qd", x + 3, x0 + 3, 3, 1e-14);
    }
    /* a large perturbation */
    {
        double x[6], phi[2];
        int iters = -1;
        fourbar_assemble(c, -2.0, 1, 0.0, x);
        x[0] += 0.3;
        x[1] -= 0.3;
        x[2] += 0.3;
        CHECK_INT(eom_project(s, x, 1e-12, &iters), EOM_OK);
        core_chain_constraints(c, x, phi, NULL, NULL);
        CHECK(core_maxabs(phi, 2) <= 1e-12);
        printf("large perturbation: %d iterations\n", iters);
    }
}

static void bead_cases(rng *g)
{
    const double m = 2.0, l = 0.8;
    eom_system *s = core_system(eom_models_bead_on_circle(m, l, 9.81));
    int k;
    CHECK(s != NULL);
    if (!s)
        return;
    for (k = 0; k < 20; k++) {
        double x[4], ref[4], rr, vr;
        int iters = -1;
        x[0] = rng_range(g, -2.0, 2.0);
        x[1] = rng_range(g, -2.0, 2.0);
        x[2] = rng_range(g, -3.0, 3.0);
        x[3] = rng_range(g, -3.0, 3.0);
        rr = hypot(x[0], x[1]);
        if (rr < 0.05)
            continue;
        ref[0] = l * x[0] / rr;
        ref[1] = l * x[1] / rr;
        vr = (x[2] * x[0] + x[3] * x[1]) / rr;
        ref[2] = x[2] - vr * x[0] / rr;
        ref[3] = x[3] - vr * x[1] / rr;
        CHECK_INT(eom_project(s, x, 1e-13, &iters), EOM_OK);
        CHECK_VEC("bead: radial projection", x, ref, 4, 1e-12);
    }
    eom_system_free(&s);
}

static void error_cases(eom_system *s, const core_chain *c)
{
    double x[6], x0[6];
    int rc, iters = -1;
    fourbar_assemble(c, 0.3, 1, 0.0, x0);
    memcpy(x, x0, sizeof x);
    CHECK_INT(eom_project(s, x, 0.0, NULL), EOM_ERR_ARG);
    CHECK_INT(eom_project(s, x, -1.0, NULL), EOM_ERR_ARG);
    CHECK_INT(eom_project(s, x, NAN, NULL), EOM_ERR_ARG);
    CHECK_SAME("rejected call leaves x", x, x0, 6);
    CHECK_INT(core_set(s, "D", 10.0), EOM_OK);
    rc = eom_project(s, x, 1e-12, &iters);
    CHECK(rc == EOM_ERR_PROJECTION || rc == EOM_ERR_RANK_DEFICIENT);
    CHECK(eom_system_errmsg(s)[0] != '\0');
    printf("unreachable D: %s after %d iterations: %s\n",
           eom_status_name(rc), iters, eom_system_errmsg(s));
    CHECK_INT(core_set(s, "D", FB_D), EOM_OK);
}

int main(void)
{
    core_chain c = fourbar_closed_form();
    eom_system *s = fourbar_system();
    rng g = rng_seed(99);
    CHECK(s != NULL);
    if (!s)
        CHECK_DONE();
    fourbar_cases(s, &c, &g);
    bead_cases(&g);
    error_cases(s, &c);
    eom_system_free(&s);
    CHECK_DONE();
}
