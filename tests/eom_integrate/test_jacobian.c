/* test_jacobian.c - the exact Jacobian of the state derivative
 * (eom_state_jacobian, from the residual tape) against two other routes.
 *
 *   1. Fourth-order central differences of eom_rhs, to 1e-7 of the
 *      largest entry, on every shipped model (constraints, moving
 *      constraints, dissipation, forces that read the time, flexible
 *      links) and on inline models for what those lack: a Lagrangian
 *      that reads the time, a force of the rates (qd^3, gyroscopic
 *      coupling), structural damping; at the initial state and at two
 *      states off it, at t = 0.37; with Baumgarte terms on the closed
 *      chain; after a parameter changes; on a clone (equal bit for bit).
 *      eom_param_jacobian against differences in every parameter;
 *      eom_linearize_state's tangent basis T keeping phi and dphi/dt
 *      to first order at moving states.
 *   2. White-box: the row of the dissipated energy W that the implicit
 *      integrators add (eom__state_jacobian with_power) against central
 *      differences of -power.
 *      IDA's iteration matrix dG/dY + cj dG/dY' (eom__dae_jacobian)
 *      against central differences of the index-1 residual G written
 *      out here from the evaluation's M, F, C, gamma and power.
 *   3. At rest, against the linearization's matrices (second derivatives
 *      from separate sweeps): N^T M (dqdd/dq) N = -N^T K N and
 *      N^T M (dqdd/dqd) N = -N^T D N to 1e-11, on the double pendulum,
 *      a damped model and the four-bar at rest; and the eigenvalues of
 *      eom_linearize_state's reduced A equal to those of the damped modal
 *      problem (Mr s^2 + Dr s + Kr) v = 0 to 1e-9, its T orthonormal and
 *      tangent to the constraints.
 *   4. In the integrators: bdf, ida and esdirk with the exact Jacobian
 *      and with difference quotients end 1 s of the double pendulum, the
 *      closed chain and the cart-pole within 1e-6 of each other, the
 *      exact route is the one taken, and on the closed chain bdf's exact
 *      run spends no right-hand sides on Jacobian columns.
 *   5. Bad input: NULL arguments and a non-finite state are errors with a
 *      message, and A is left alone.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"
#include "eom/model_file.h"
#include "eom_internal.h"

#define TJ 0.37

static const char *models_dir = "models";

/* Inline models for what the shipped ones lack. */
static const char *const time_L =
    "units off\nparam m = 1.3\nparam k = 4\nparam w = 3\nparam g = 9.81\n"
    "coord a = 0.4 rate 0.3\ncoord b = -0.2 rate 0.5\n"
    "T = 1/2*m*(a_dot^2 + (1 + 0.2*sin(w*t))*b_dot^2 + a_dot*b_dot*cos(a-b))\n"
    "V = 1/2*k*(1 + 0.3*cos(w*t))*(a^2 + a*b + b^2) + m*g*(1-cos(a))\n";
static const char *const rate_forces =
    "units off\nparam m = 0.7\nparam c = 0.4\nparam G = 1.5\nparam k = 3\n"
    "coord x = 0.3 rate 0.8\ncoord y = -0.4 rate -0.2\n"
    "T = 1/2*m*(x_dot^2 + y_dot^2)\n"
    "V = 1/2*k*(x^2 + y^2) + 1/4*k*x^2*y^2\n"
    "R = 1/2*c*(x_dot^2 + x_dot*y_dot + y_dot^2)\n"
    "force x = -c*x_dot^3 + G*y_dot\n"
    "force y = -G*x_dot + 0.1*sin(t)*x\n";

static const char *const damped =
    "units off\nparam m = 0.7\nparam c = 0.4\nparam k = 3\n"
    "coord x = 0.3\ncoord y = -0.4\n"
    "T = 1/2*m*(x_dot^2 + y_dot^2 + x_dot*y_dot*cos(x))\n"
    "V = 1/2*k*(x^2 + y^2) + 1/4*k*x^2*y^2\n"
    "R = 1/2*c*(x_dot^2 + x_dot*y_dot + y_dot^2)\n";

static eom_system *system_of(const char *what, int is_file)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    char err[512], path[1024];
    int rc;
    if (is_file) {
        snprintf(path, sizeof path, "%s/%s", models_dir, what);
        rc = eom_model_from_file(&md, path, err, sizeof err);
    } else {
        rc = eom_model_from_string(&md, what, err, sizeof err);
    }
    CHECK_INT(rc, EOM_OK);
    if (rc != EOM_OK) {
        fprintf(stderr, "%s: %s\n", is_file ? what : "inline model", err);
        return NULL;
    }
    rc = eom_system_new(&s, md, err, sizeof err);
    CHECK_INT(rc, EOM_OK);
    if (rc != EOM_OK)
        fprintf(stderr, "%s\n", err);
    eom_model_free(&md);
    return s;
}

/* d(xd)/dx by fourth-order central differences of eom_rhs: column j of
 * Afd (row-major 2n x 2n). */
static int fd_jacobian(eom_system *s, double t, const double *x,
                       double *Afd)
{
    static const double step[4] = {1.0, -1.0, 2.0, -2.0};
    static const double coef[4] = {8.0, -8.0, -1.0, 1.0};
    const int n2 = 2 * eom_system_ncoords(s);
    double *xp = malloc((size_t)n2 * sizeof *xp);
    double *f = malloc((size_t)n2 * sizeof *f);
    int i, j, k, rc = 0;
    for (j = 0; j < n2 && rc == 0; j++) {
        const double h = 1e-4 * (1.0 + fabs(x[j]));
        for (i = 0; i < n2; i++)
            Afd[i * n2 + j] = 0.0;
        for (k = 0; k < 4 && rc == 0; k++) {
            memcpy(xp, x, (size_t)n2 * sizeof *xp);
            xp[j] += step[k] * h;
            rc = eom_rhs(s, t, xp, f);
            for (i = 0; i < n2; i++)
                Afd[i * n2 + j] += coef[k] * f[i] / (12.0 * h);
        }
    }
    free(xp);
    free(f);
    return rc;
}

static double max_abs(const double *a, int n)
{
    double m = 0.0;
    int i;
    for (i = 0; i < n; i++)
        m = fmax(m, fabs(a[i]));
    return m;
}

/* eom_state_jacobian against differences at (t, x); returns the relative
 * error. */
static double check_at(eom_system *s, double t, const double *x,
                       const char *ctx)
{
    const int n2 = 2 * eom_system_ncoords(s);
    const size_t nn = (size_t)n2 * (size_t)n2;
    double *A = malloc(nn * sizeof *A), *Afd = malloc(nn * sizeof *Afd);
    double err = INFINITY;
    size_t k;
    CHECK_INT(eom_state_jacobian(s, t, x, A), EOM_OK);
    CHECK_INT(fd_jacobian(s, t, x, Afd), 0);
    err = 0.0;
    for (k = 0; k < nn; k++)
        err = fmax(err, fabs(A[k] - Afd[k]));
    err /= max_abs(Afd, (int)nn);
    if (!(err <= 1e-7))
        CHECK_FAIL_("%s: Jacobian against differences: %.3g > 1e-7", ctx,
                    err);
    free(A);
    free(Afd);
    return err;
}

/* eom_param_jacobian against differences of eom_rhs in each parameter. */
static void check_params(eom_system *s, double t, const double *x,
                         const char *ctx)
{
    static const double step[4] = {1.0, -1.0, 2.0, -2.0};
    static const double coef[4] = {8.0, -8.0, -1.0, 1.0};
    const int n2 = 2 * eom_system_ncoords(s), np = eom_system_nparams(s);
    double *B = malloc((size_t)n2 * (np ? np : 1) * sizeof *B);
    double *fd = calloc((size_t)n2 * (np ? np : 1), sizeof *fd);
    double *f = malloc((size_t)n2 * sizeof *f), err = 0.0, scale;
    int i, k, j;
    CHECK_INT(eom_param_jacobian(s, t, x, B), EOM_OK);
    for (k = 0; k < np; k++) {
        const double p0 = eom_get_param(s, k), h = 1e-4 * (1.0 + fabs(p0));
        for (j = 0; j < 4; j++) {
            CHECK_INT(eom_set_param(s, k, p0 + step[j] * h), EOM_OK);
            CHECK_INT(eom_rhs(s, t, x, f), EOM_OK);
            for (i = 0; i < n2; i++)
                fd[i * np + k] += coef[j] * f[i] / (12.0 * h);
        }
        CHECK_INT(eom_set_param(s, k, p0), EOM_OK);
    }
    scale = max_abs(fd, n2 * np);
    for (i = 0; i < n2 * np; i++)
        err = fmax(err, fabs(B[i] - fd[i]));
    if (!(err <= 1e-7 * scale))
        CHECK_FAIL_("%s: d(xd)/dp against differences: %.3g (scale %.3g)",
                    ctx, err, scale);
    free(B);
    free(fd);
    free(f);
}

/* eom_linearize_state at a moving state: T orthonormal, its columns
 * keep phi and dphi/dt unchanged to first order (central differences of
 * eom_residuals), Ar = T^T A T, and A and B those of the two calls. */
static void check_state_linear(eom_system *s, double t, const double *x,
                               const char *ctx)
{
    const int n2 = 2 * eom_system_ncoords(s), m = eom_system_nconstraints(s);
    const int np = eom_system_nparams(s);
    eom_state_linear sl;
    double xp[256], xm[256], pp[64], pm[64], dp[64], dm[64], err = 0.0;
    double *A = malloc((size_t)n2 * n2 * sizeof *A);
    int i, j, k;
    memset(&sl, 0, sizeof sl);
    CHECK_INT(eom_linearize_state(s, t, x, &sl), EOM_OK);
    CHECK_INT(eom_state_jacobian(s, t, x, A), EOM_OK);
    if (sl.n2 != n2 || !sl.A || m > 64) {
        free(A);
        eom_state_linear_free(&sl);
        return;
    }
    CHECK(memcmp(A, sl.A, (size_t)n2 * n2 * sizeof *A) == 0);
    CHECK_INT(sl.np, np);
    CHECK(m > 0 ? sl.nz <= n2 - 2 * m : sl.nz == n2);
    eom_set_time(s, t);
    for (j = 0; j < sl.nz; j++) {
        const double h = 1e-6;
        for (i = 0; i < n2; i++) {
            xp[i] = x[i] + h * sl.T[i * sl.nz + j];
            xm[i] = x[i] - h * sl.T[i * sl.nz + j];
        }
        CHECK_INT(eom_residuals(s, xp, pp, dp), EOM_OK);
        CHECK_INT(eom_residuals(s, xm, pm, dm), EOM_OK);
        for (k = 0; k < m; k++)
            err = fmax(err, fmax(fabs(pp[k] - pm[k]), fabs(dp[k] - dm[k])) /
                                (2.0 * h));
    }
    if (!(err <= 1e-6))
        CHECK_FAIL_("%s: T leaves the constraints: %.3g", ctx, err);
    /* Ar = T^T A T */
    err = 0.0;
    for (i = 0; i < sl.nz; i++)
        for (j = 0; j < sl.nz; j++) {
            double sum = 0.0;
            int a, b;
            for (a = 0; a < n2; a++)
                for (b = 0; b < n2; b++)
                    sum += sl.T[a * sl.nz + i] * sl.A[a * n2 + b] *
                           sl.T[b * sl.nz + j];
            err = fmax(err, fabs(sum - sl.Ar[i * sl.nz + j]));
        }
    CHECK(err <= 1e-12 * (max_abs(sl.A, n2 * n2) + 1.0));
    free(A);
    eom_state_linear_free(&sl);
}

/* The W row (white-box) against differences of -power. */
static void check_power_row(eom_system *s, double t, const double *x,
                            const char *ctx)
{
    const int n = eom_system_ncoords(s), n2 = 2 * n, N = n2 + 1;
    double *A = calloc((size_t)N * (size_t)N, sizeof *A);
    double *xp = malloc((size_t)n2 * sizeof *xp), fd, scale = 0.0, err = 0.0;
    int j;
    CHECK_INT(eom__state_jacobian(s, t, x, A, N, 1), EOM_OK);
    for (j = 0; j < n2; j++) {
        const double h = 1e-5 * (1.0 + fabs(x[j]));
        double pp, pm;
        memcpy(xp, x, (size_t)n2 * sizeof *xp);
        xp[j] += h;
        CHECK_INT(eom__evaluate(s, t, xp), EOM_OK);
        pp = s->power;
        xp[j] -= 2.0 * h;
        CHECK_INT(eom__evaluate(s, t, xp), EOM_OK);
        pm = s->power;
        fd = -(pp - pm) / (2.0 * h);
        scale = fmax(scale, fabs(fd));
        err = fmax(err, fabs(A[(size_t)j * N + n2] - fd));
        CHECK(A[(size_t)n2 * N + j] == 0.0); /* nothing depends on W */
    }
    if (!(err <= 1e-6 * fmax(scale, 1e-3)))
        CHECK_FAIL_("%s: W row against differences: %.3g (scale %.3g)",
                    ctx, err, scale);
    free(A);
    free(xp);
}

/* IDA's residual G(Y, Yp), Y = (q, v, lambda, W) (integrate_ida.c). */
static int dae_residual(eom_system *s, double t, const double *Y,
                        const double *Yp, double *G)
{
    const int n = s->n, m = s->m;
    const double *lam = Y + 2 * n, *vd = Yp + n;
    int i, j, k;
    if (eom__evaluate(s, t, Y) != EOM_OK)
        return -1;
    for (i = 0; i < n; i++) {
        double sum = -s->F[i];
        for (k = 0; k < n; k++)
            sum += s->M[i * n + k] * vd[k];
        for (j = 0; j < m; j++)
            sum -= s->C[j * n + i] * lam[j];
        G[i] = Yp[i] - Y[n + i];
        G[n + i] = sum;
    }
    for (j = 0; j < m; j++) {
        double sum = -s->gam[j];
        for (k = 0; k < n; k++)
            sum += s->C[j * n + k] * vd[k];
        G[2 * n + j] = sum;
    }
    G[2 * n + m] = Yp[2 * n + m] + s->power;
    if (s->tphi.tindex >= 0)
        for (j = 0; j < m; j++) {
            double cv = 0.0;
            for (k = 0; k < n; k++)
                cv += s->C[j * n + k] * Y[n + k];
            G[2 * n + m] += (lam[j] - s->lam[j]) * cv;
        }
    return 0;
}

static void check_dae(eom_system *s, double t, const double *x,
                      const char *ctx)
{
    const int n = s->n, m = s->m, NY = 2 * n + m + 1;
    const double cj = 37.5;
    double *Y = calloc((size_t)NY, sizeof *Y), *Yp = calloc((size_t)NY,
                                                             sizeof *Yp);
    double *J = calloc((size_t)NY * NY, sizeof *J);
    double *Gp = malloc((size_t)NY * sizeof *Gp);
    double *Gm = malloc((size_t)NY * sizeof *Gm), err = 0.0, scale = 0.0;
    int i, j, side;
    memcpy(Y, x, 2 * (size_t)n * sizeof *Y);
    CHECK_INT(eom_rhs(s, t, x, Yp), EOM_OK);
    for (j = 0; j < m; j++) /* near, not on, the solution */
        Y[2 * n + j] = s->lam[j] * 1.1 + 0.05;
    for (i = 0; i < 2 * n; i++)
        Yp[i] += 0.01 * cos(3.0 * i);
    Y[2 * n + m] = 0.3;
    Yp[2 * n + m] = -0.2;
    CHECK_INT(eom__dae_jacobian(s, t, Y, Yp, cj, J, NY), EOM_OK);
    for (j = 0; j < NY; j++) {
        const double h = 1e-6 * (1.0 + fabs(Y[j]));
        for (side = 0; side < 2; side++) {
            double y0 = Y[j], yp0 = Yp[j], sg = side ? -1.0 : 1.0;
            /* G(Y + s h e_j, Yp + s cj h e_j): the directional derivative
             * along (e_j, cj e_j) is column j of dG/dY + cj dG/dYp */
            Y[j] = y0 + sg * h;
            Yp[j] = yp0 + sg * cj * h;
            CHECK_INT(dae_residual(s, t, Y, Yp, side ? Gm : Gp), 0);
            Y[j] = y0;
            Yp[j] = yp0;
        }
        for (i = 0; i < NY; i++) {
            const double fd = (Gp[i] - Gm[i]) / (2.0 * h);
            scale = fmax(scale, fabs(fd));
            err = fmax(err, fabs(J[(size_t)j * NY + i] - fd));
        }
    }
    if (!(err <= 1e-7 * scale))
        CHECK_FAIL_("%s: DAE iteration matrix against differences: %.3g "
                    "(scale %.3g)", ctx, err, scale);
    free(Y);
    free(Yp);
    free(J);
    free(Gp);
    free(Gm);
}

/* Initial state, and two states off it (not projected: the Jacobian of
 * the stabilized equations is defined off the constraints too). */
static void states(eom_system *s, double *x, int which)
{
    const int n2 = 2 * eom_system_ncoords(s);
    int i;
    eom_initial_state(s, x);
    for (i = 0; i < n2 && which > 0; i++)
        x[i] += (which == 1 ? 0.05 : -0.03) * sin(1.7 * i + which) +
                (i >= n2 / 2 ? 0.2 * which : 0.0);
}

static void one_model(const char *label, const char *what, int is_file)
{
    eom_system *s = system_of(what, is_file), *c = NULL;
    char ctx[256];
    double x[256];
    int k;
    if (!s)
        return;
    for (k = 0; k < 3; k++) {
        double err;
        snprintf(ctx, sizeof ctx, "%s state %d", label, k);
        states(s, x, k);
        err = check_at(s, TJ, x, ctx);
        printf("%-22s state %d: |A - differences| / |A| = %.2e\n", label,
               k, err);
        check_power_row(s, TJ, x, ctx);
        check_dae(s, TJ, x, ctx);
        check_params(s, TJ, x, ctx);
        check_state_linear(s, TJ, x, ctx);
    }
    /* a parameter changed: the Jacobian follows it */
    if (eom_system_nparams(s) > 0) {
        const double p0 = eom_get_param(s, 0);
        CHECK_INT(eom_set_param(s, 0, 1.37 * p0 + 0.1), EOM_OK);
        states(s, x, 1);
        snprintf(ctx, sizeof ctx, "%s, %s changed", label,
                 eom_param_name(s, 0));
        check_at(s, TJ, x, ctx);
    }
    /* a clone gives the same Jacobian, bit for bit */
    CHECK_INT(eom_system_clone(&c, s, NULL, 0), EOM_OK);
    if (c) {
        const int n2 = 2 * eom_system_ncoords(s);
        double *A1 = malloc((size_t)n2 * n2 * sizeof *A1);
        double *A2 = malloc((size_t)n2 * n2 * sizeof *A2);
        states(s, x, 2);
        CHECK_INT(eom_state_jacobian(s, TJ, x, A1), EOM_OK);
        CHECK_INT(eom_state_jacobian(c, TJ, x, A2), EOM_OK);
        CHECK(memcmp(A1, A2, (size_t)n2 * n2 * sizeof *A1) == 0);
        free(A1);
        free(A2);
        eom_system_free(&c);
    }
    eom_system_free(&s);
}

static void baumgarte(void)
{
    eom_system *s = system_of("closed-chain.eom", 1);
    double x[256];
    if (!s)
        return;
    CHECK_INT(eom_set_baumgarte(s, 2.0, 3.0), EOM_OK);
    states(s, x, 1);
    check_at(s, TJ, x, "closed-chain.eom with Baumgarte 2, 3");
    check_dae(s, TJ, x, "closed-chain.eom with Baumgarte 2, 3");
    eom_system_free(&s);
}

/* ---- at rest: the linearization's matrices ----------------------------- */

/* max |a - b| <= tol * scale, or a failure naming the case. */
static void close_scaled(const char *label, const char *what,
                         const double *a, const double *b, int n,
                         double scale, double tol)
{
    double e = 0.0;
    int i;
    for (i = 0; i < n; i++)
        e = fmax(e, fabs(a[i] - b[i]));
    if (!(e <= tol * scale))
        CHECK_FAIL_("%s: %s: %.3g > %.3g", label, what, e, tol * scale);
}

/* P = N^T M Z N (nr x nr) for Z n x n row-major, N n x nr row-major. */
static void project(int n, int nr, const double *N, const double *M,
                    const double *Z, double *P)
{
    double *MZ = calloc((size_t)n * n, sizeof *MZ);
    int i, j, k, l;
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++)
            for (k = 0; k < n; k++)
                MZ[i * n + j] += M[i * n + k] * Z[k * n + j];
    for (i = 0; i < nr; i++)
        for (j = 0; j < nr; j++) {
            double sum = 0.0;
            for (k = 0; k < n; k++)
                for (l = 0; l < n; l++)
                    sum += N[k * nr + i] * MZ[k * n + l] * N[l * nr + j];
            P[i * nr + j] = sum;
        }
    free(MZ);
}

/* The eigenvalues of eom_linearize_state's reduced A at rest against the
 * damped modal problem (Mr s^2 + Dr s + Kr) v = 0 of eom_linearize,
 * written as the companion matrix [0 I; -Mr^-1 Kr, -Mr^-1 Dr]; and T
 * orthonormal with C T_q = 0. */
static void damped_eigenvalues(eom_system *s, const double *x,
                               const eom_linear *lin, const char *label)
{
    const int nr = lin->nr, n = lin->n, N = 2 * nr;
    eom_state_linear sl;
    double *Mi, *P, *comp, *re, *im, *work, C[64 * 64], q;
    int *ipiv, info = 0, lwork = 64 * (N + 1), one = 1, i, j, k;
    memset(&sl, 0, sizeof sl);
    CHECK_INT(eom_linearize_state(s, 0.0, x, &sl), EOM_OK);
    CHECK_INT(sl.nz, N);
    if (sl.nz != N) {
        eom_state_linear_free(&sl);
        return;
    }
    Mi = malloc((size_t)nr * nr * sizeof *Mi);
    P = malloc((size_t)nr * 2 * nr * sizeof *P);
    comp = calloc((size_t)N * N, sizeof *comp);
    re = malloc((size_t)N * sizeof *re);
    im = malloc((size_t)N * sizeof *im);
    work = malloc((size_t)lwork * sizeof *work);
    ipiv = malloc((size_t)nr * sizeof *ipiv);
    /* P = Mr^-1 [Kr Dr], column-major (Mr, Kr, Dr are symmetric) */
    for (i = 0; i < nr * nr; i++)
        Mi[i] = lin->Mr[i];
    for (i = 0; i < nr; i++)
        for (j = 0; j < nr; j++) {
            P[j * nr + i] = lin->Kr[i * nr + j];
            P[(nr + j) * nr + i] = lin->Dr[i * nr + j];
        }
    k = 2 * nr;
    dgesv_(&nr, &k, Mi, &nr, ipiv, P, &nr, &info);
    CHECK_INT(info, 0);
    for (i = 0; i < nr; i++) { /* column-major companion */
        comp[(nr + i) * N + i] = 1.0;
        for (j = 0; j < nr; j++) {
            comp[j * N + nr + i] = -P[j * nr + i];
            comp[(nr + j) * N + nr + i] = -P[(nr + j) * nr + i];
        }
    }
    dgeev_("N", "N", &N, comp, &N, re, im, &q, &one, &q, &one, work, &lwork,
           &info, 1, 1);
    CHECK_INT(info, 0);
    {
        /* as sets: each eigenvalue of the companion matched to the
         * nearest one of Ar not yet taken (equal real parts make any
         * order depend on rounding) */
        double scale = 0.0, err = 0.0;
        int taken[128] = {0};
        for (i = 0; i < N; i++)
            scale = fmax(scale, hypot(re[i], im[i]));
        for (i = 0; i < N && N <= 128; i++) {
            double best = INFINITY;
            int bj = -1;
            for (j = 0; j < N; j++) {
                double d = hypot(re[i] - sl.eig_re[j], im[i] - sl.eig_im[j]);
                if (!taken[j] && d < best) {
                    best = d;
                    bj = j;
                }
            }
            if (bj >= 0)
                taken[bj] = 1;
            err = fmax(err, best);
        }
        if (!(err <= 1e-9 * scale))
            CHECK_FAIL_("%s: eigenvalues of Ar against the damped modal "
                        "problem: %.3g (scale %.3g)", label, err, scale);
        printf("%-22s at rest: %d eigenvalues of Ar = damped modes "
               "(%.1e), e.g. %.6g %+.6gi\n", label, N, err / scale,
               sl.eig_re[N - 1], sl.eig_im[N - 1]);
    }
    /* T orthonormal, its q-part in the null space of C */
    {
        double err = 0.0;
        for (i = 0; i < N; i++)
            for (j = 0; j < N; j++) {
                double d = 0.0;
                for (k = 0; k < 2 * n; k++)
                    d += sl.T[k * N + i] * sl.T[k * N + j];
                err = fmax(err, fabs(d - (i == j)));
            }
        CHECK(err < 1e-12);
        if (eom_system_nconstraints(s) > 0 && n <= 64) {
            const int m = eom_system_nconstraints(s);
            double ct = 0.0;
            CHECK_INT(eom_constraint_jacobian(s, x, C, NULL), EOM_OK);
            for (i = 0; i < m; i++)
                for (j = 0; j < N; j++) {
                    double d = 0.0;
                    for (k = 0; k < n; k++)
                        d += C[i * n + k] * sl.T[k * N + j];
                    ct = fmax(ct, fabs(d));
                }
            CHECK(ct < 1e-12);
        }
    }
    eom_state_linear_free(&sl);
    free(Mi);
    free(P);
    free(comp);
    free(re);
    free(im);
    free(work);
    free(ipiv);
}

static void at_rest(const char *label, const char *what, int is_file,
                    const char *damp_param)
{
    eom_system *s = system_of(what, is_file);
    eom_linear lin;
    double x[256], *A, *Zq, *Zd, *P;
    int n, n2, nr, i, j;
    if (!s)
        return;
    n = eom_system_ncoords(s);
    n2 = 2 * n;
    if (damp_param) /* give the dissipation something to do */
        CHECK_INT(eom_set_param(s, eom_param_index(s, damp_param), 0.35),
                  EOM_OK);
    eom_initial_state(s, x);
    CHECK_INT(eom_equilibrium(s, x, 1e-13, NULL), EOM_OK);
    for (i = 0; i < n; i++)
        x[n + i] = 0.0;
    memset(&lin, 0, sizeof lin);
    CHECK_INT(eom_linearize(s, x, &lin), EOM_OK);
    nr = lin.nr;
    A = malloc((size_t)n2 * n2 * sizeof *A);
    Zq = malloc((size_t)n * n * sizeof *Zq);
    Zd = malloc((size_t)n * n * sizeof *Zd);
    P = malloc((size_t)(nr ? nr : 1) * (nr ? nr : 1) * sizeof *P);
    CHECK_INT(eom_state_jacobian(s, 0.0, x, A), EOM_OK);
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++) {
            Zq[i * n + j] = -A[(n + i) * n2 + j];
            Zd[i * n + j] = -A[(n + i) * n2 + n + j];
        }
    project(n, nr, lin.N, lin.M, Zq, P);
    close_scaled(label, "N'M dqdd/dq N = -Kr", P, lin.Kr, nr * nr,
                 max_abs(lin.Kr, nr * nr), 1e-11);
    project(n, nr, lin.N, lin.M, Zd, P);
    close_scaled(label, "N'M dqdd/dqd N = -Dr", P, lin.Dr, nr * nr,
                 fmax(max_abs(lin.Dr, nr * nr), 1e-12), 1e-11);
    if (damp_param)
        CHECK(max_abs(lin.Dr, nr * nr) > 0.01);
    damped_eigenvalues(s, x, &lin, label);
    printf("%-22s at rest: K and D of the linearization agree\n", label);
    free(A);
    free(Zq);
    free(Zd);
    free(P);
    eom_linear_free(&lin);
    eom_system_free(&s);
}

static void run_to(eom_system *s, eom_method method, int dq, double *x,
                   eom_stats *st)
{
    eom_opts o;
    eom_integ *it = NULL;
    double W = 0.0;
    eom_opts_default(&o);
    o.method = method;
    o.rtol = 1e-9;
    o.atol = 1e-12;
    o.dq_jacobian = dq;
    eom_initial_state(s, x);
    if (eom_system_nconstraints(s) > 0)
        CHECK_INT(eom_project(s, x, 1e-13, NULL), EOM_OK);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    CHECK_INT(eom_integ_advance(it, 1.0, x, &W), EOM_OK);
    eom_integ_stats(it, st);
    eom_integ_free(&it);
}

static void integrators(const char *file)
{
    static const eom_method methods[] = {EOM_BDF, EOM_IDA, EOM_ESDIRK};
    eom_system *s = system_of(file, 1);
    double xe[256], xd[256], d;
    eom_stats se, sd;
    int k, i;
    if (!s)
        return;
    for (k = 0; k < 3; k++) {
        run_to(s, methods[k], 0, xe, &se);
        run_to(s, methods[k], 1, xd, &sd);
        d = 0.0;
        for (i = 0; i < 2 * eom_system_ncoords(s); i++)
            d = fmax(d, fabs(xe[i] - xd[i]));
        printf("%-22s %-6s exact: %ld rhs, %ld Jacobians; differences: "
               "%ld rhs, %ld Jacobians; states %.1e apart\n", file,
               eom_method_name(methods[k]), se.rhs_evals, se.jac_evals,
               sd.rhs_evals, sd.jac_evals, d);
        if (!(d <= 1e-6))
            CHECK_FAIL_("%s %s: exact and difference-quotient runs %.3g "
                        "apart", file, eom_method_name(methods[k]), d);
        CHECK(se.jac_evals > 0);
        /* the exact route was taken: the runs are not the same run */
        CHECK(se.rhs_evals != sd.rhs_evals || d > 0.0);
        /* where Jacobians are frequent, the exact ones save the columns'
         * right-hand sides (a quarter of bdf's on the closed chain) */
        if (methods[k] == EOM_BDF && strcmp(file, "closed-chain.eom") == 0)
            CHECK(se.rhs_evals < 0.9 * sd.rhs_evals);
    }
    eom_system_free(&s);
}

static void bad_input(void)
{
    eom_system *s = system_of("double-pendulum.eom", 1);
    double x[4], A[16];
    int k;
    if (!s)
        return;
    eom_initial_state(s, x);
    CHECK_INT(eom_state_jacobian(NULL, 0.0, x, A), EOM_ERR_NULL);
    CHECK_INT(eom_state_jacobian(s, 0.0, NULL, A), EOM_ERR_NULL);
    CHECK_INT(eom_state_jacobian(s, 0.0, x, NULL), EOM_ERR_NULL);
    CHECK(strstr(eom_system_errmsg(s), "eom_state_jacobian") != NULL);
    for (k = 0; k < 16; k++)
        A[k] = 7.0;
    x[1] = NAN;
    CHECK_INT(eom_state_jacobian(s, 0.0, x, A), EOM_ERR_NONFINITE);
    CHECK(strstr(eom_system_errmsg(s), "not finite") != NULL);
    for (k = 0; k < 16; k++)
        CHECK(A[k] == 7.0);
    eom_system_free(&s);
}

int main(int argc, char **argv)
{
    static const char *const files[] = {
        "spring-pendulum.eom", "double-pendulum.eom", "open-chain.eom",
        "closed-chain.eom", "four-bar.eom", "cart-pole.eom",
        "driven-crank.eom"};
    size_t k;
    if (argc > 1)
        models_dir = argv[1];
    for (k = 0; k < sizeof files / sizeof files[0]; k++)
        one_model(files[k], files[k], 1);
    one_model("L reads the time", time_L, 0);
    one_model("forces of the rates", rate_forces, 0);
    one_model("damped", damped, 0);
    baumgarte();
    at_rest("double-pendulum.eom", "double-pendulum.eom", 1, NULL);
    at_rest("damped", damped, 0, "c");
    at_rest("four-bar.eom", "four-bar.eom", 1, NULL);
    integrators("double-pendulum.eom");
    integrators("closed-chain.eom");
    integrators("cart-pole.eom");
    bad_input();
    CHECK_DONE();
}
