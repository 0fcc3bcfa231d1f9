/* test_mass_route.c - the mass matrix's route (mass_pattern.c,
 * mass_route.c): M recognised as constant from the tape, formed and
 * factored once, against closed forms and against the dense route.
 *
 * 1. The IFToMM A02 four-bars in natural coordinates (N = 40, the model
 *    file of tests/eom_constraints/models): M is constant. On the
 *    parallelogram branch every crank turns with one angle th,
 *    th'' = -a cos th (test_a02.c), so each tip B_i = (i l + l cos th,
 *    l sin th) has the closed-form acceleration
 *        x'' = -l (sin th th'' + cos th th'^2),
 *        y'' =  l (cos th th'' - sin th th'^2).
 *    The accelerations of both routes are checked against it at two
 *    states, and the routes' accelerations and multipliers against each
 *    other to 1e-12; a parameter changed between evaluations (m) must
 *    refactor M: the multipliers scale with m (the accelerations do not).
 * 2. A pendulum on a spring in polar coordinates (r, th), whose M =
 *    diag(m, m r^2) depends on q, and a rate-dependent one (M depends on
 *    qd), and one whose M depends on q only through a term that vanishes
 *    at the first state: all on the dense route, and evaluated after
 *    another state their accelerations still match the closed form.
 * 3. M's pattern on the A02 model with N = 3: row x_i couples x_{i-1},
 *    x_i, x_{i+1} and nothing else (likewise y), read from the analysis
 *    and compared entry by entry with the structure the file writes.
 * 4. The route reported: eom_system_mass_route, eom_mass_route_name,
 *    eom_stats.mass_route after an integration, the override and its
 *    refusals.
 * The sparse route (kkt_sparse.c: M and C as one augmented system, KLU)
 * is the automatic one at N = 40; it is checked like the others against
 * the closed form and the dense route, and at a flat position (a
 * singular augmented matrix) must give the dense route's filtered
 * numbers. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"
#include "eom/model_file.h"
#include "eom_internal.h"
#include "mass_route.h"

static const double Lr = 1.0, Gr = 9.81;

static eom_system *a02(const char *dir, int N)
{
    char path[1024], err[1024];
    eom_file *f = NULL;
    eom_model *mo = NULL;
    eom_system *s = NULL;
    snprintf(path, sizeof path, "%s/a02-natural.eom", dir);
    if (eom_file_read(&f, path, err, sizeof err) != EOM_OK ||
        eom_file_set_setting(f, "N", N, err, sizeof err) != EOM_OK ||
        eom_file_build(f, &mo, err, sizeof err) != EOM_OK ||
        eom_system_new(&s, mo, err, sizeof err) != EOM_OK)
        fprintf(stderr, "%s: %s\n", path, err);
    eom_file_free(&f);
    eom_model_free(&mo);
    return s;
}

/* The parallelogram state at angle th, rate w, and its exact qdd. */
static void branch_state(int N, double th, double w, double *x, double *qdd)
{
    const int n = 2 * (N + 1);
    const double a = Gr / Lr * ((N + 1) / 2.0 + N) / ((N + 1) / 3.0 + N);
    const double thdd = -a * cos(th);
    int i;
    for (i = 0; i <= N; i++) {
        x[i] = i * Lr + Lr * cos(th);
        x[N + 1 + i] = Lr * sin(th);
        x[n + i] = -Lr * sin(th) * w;
        x[n + N + 1 + i] = Lr * cos(th) * w;
        qdd[i] = -Lr * (sin(th) * thdd + cos(th) * w * w);
        qdd[N + 1 + i] = Lr * (cos(th) * thdd - sin(th) * w * w);
    }
}

static double maxdiff(const double *a, const double *b, int n)
{
    double d = 0.0;
    int i;
    for (i = 0; i < n; i++)
        d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

static double maxabs(const double *a, int n)
{
    double d = 0.0;
    int i;
    for (i = 0; i < n; i++)
        d = fmax(d, fabs(a[i]));
    return d;
}

static void test_a02_constant(const char *dir)
{
    const int N = 40, n = 2 * (N + 1), m = 2 * N + 1;
    eom_system *s = a02(dir, N), *d = a02(dir, N), *c = a02(dir, N);
    double *x = calloc(2 * (size_t)n, sizeof *x);
    double *ex = calloc((size_t)n, sizeof *ex);
    double *xs = calloc(2 * (size_t)n, sizeof *xs);
    double *xd = calloc(2 * (size_t)n, sizeof *xd);
    double *ls = calloc((size_t)m, sizeof *ls);
    double *ld = calloc((size_t)m, sizeof *ld);
    static const double th[3] = {1.5707963267948966, 1.0471975511965976,
                                 0.3};
    static const double w[3] = {-1.0, -2.5, 0.7};
    int k, im;
    long solves, fallbacks;
    if (!s || !d || !c || !x || !ex || !xs || !xd || !ls || !ld) {
        CHECK(0);
        goto done;
    }
    /* automatic: constant M, and at n = 82 the sparse augmented solve */
    CHECK_INT(eom_system_mass_route(s), EOM_MASS_SPARSE);
    CHECK(strcmp(eom_mass_route_name(eom_system_mass_route(s)),
                 "sparse") == 0);
    CHECK_INT(eom_system_set_mass_route(d, EOM_MASS_DENSE), EOM_OK);
    CHECK_INT(eom_system_mass_route(d), EOM_MASS_DENSE);
    CHECK_INT(eom_system_set_mass_route(c, EOM_MASS_CONSTANT), EOM_OK);
    CHECK_INT(eom_system_mass_route(c), EOM_MASS_CONSTANT);
    for (k = 0; k < 3; k++) {
        int r;
        branch_state(N, th[k], w[k], x, ex);
        CHECK_INT(eom_rhs(d, 0.0, x, xd), EOM_OK);
        CHECK_INT(eom_multipliers(d, 0.0, x, ld), EOM_OK);
        CHECK(maxdiff(xd + n, ex, n) < 1e-11 * (1.0 + maxabs(ex, n)));
        for (r = 0; r < 2; r++) {
            eom_system *e = r == 0 ? s : c;
            CHECK_INT(eom_rhs(e, 0.0, x, xs), EOM_OK);
            /* the closed form (the branch's rounding: a few ulps of g) */
            CHECK(maxdiff(xs + n, ex, n) < 1e-11 * (1.0 + maxabs(ex, n)));
            /* against the dense route */
            CHECK(maxdiff(xs + n, xd + n, n) <
                  1e-12 * (1.0 + maxabs(ex, n)));
            CHECK_INT(eom_multipliers(e, 0.0, x, ls), EOM_OK);
            CHECK(maxdiff(ls, ld, m) < 1e-12 * maxabs(ld, m));
        }
    }
    /* every evaluation of s so far was solved sparsely */
    eom__kkt_counts(s, &solves, &fallbacks);
    CHECK_INT(solves, 6);
    CHECK_INT(fallbacks, 0);
    /* a flat position (th = 0: every rod on the x axis, C loses N of
     * its rank): the augmented matrix is singular and the evaluation
     * takes the dense route's filtered solve, giving its numbers */
    branch_state(N, 0.0, -1.0, x, ex);
    CHECK_INT(eom_rhs(s, 0.0, x, xs), EOM_OK);
    CHECK_INT(eom_rhs(d, 0.0, x, xd), EOM_OK);
    CHECK(maxdiff(xs + n, xd + n, n) < 1e-12 * (1.0 + maxabs(xd + n, n)));
    CHECK_INT(eom_multipliers(s, 0.0, x, ls), EOM_OK);
    CHECK_INT(eom_multipliers(d, 0.0, x, ld), EOM_OK);
    CHECK(maxdiff(ls, ld, m) < 1e-12 * (1.0 + maxabs(ld, m)));
    eom__kkt_counts(s, &solves, &fallbacks);
    CHECK_INT(solves, 6);
    CHECK_INT(fallbacks, 2);
    /* a new mass: the constant factor is made again. The motion is the
     * same (every term scales with m), the multipliers scale with it */
    branch_state(N, th[1], w[1], x, ex);
    im = eom_param_index(s, "m");
    CHECK(im >= 0);
    CHECK_INT(eom_set_param(s, im, 3.0), EOM_OK);
    CHECK_INT(eom_set_param(d, im, 3.0), EOM_OK);
    CHECK_INT(eom_multipliers(s, 0.0, x, ls), EOM_OK);
    CHECK_INT(eom_multipliers(d, 0.0, x, ld), EOM_OK);
    CHECK(maxdiff(ls, ld, m) < 1e-12 * maxabs(ld, m));
    CHECK_INT(eom_set_param(d, im, 1.0), EOM_OK);
    CHECK_INT(eom_multipliers(d, 0.0, x, xd), EOM_OK);
    for (k = 0; k < m; k++)
        CHECK_NEAR(ls[k], 3.0 * xd[k], 1e-12 * maxabs(ls, m));
    CHECK_INT(eom_rhs(s, 0.0, x, xs), EOM_OK);
    CHECK(maxdiff(xs + n, ex, n) < 1e-11 * (1.0 + maxabs(ex, n)));
done:
    free(x);
    free(ex);
    free(xs);
    free(xd);
    free(ls);
    free(ld);
    eom_system_free(&s);
    eom_system_free(&d);
    eom_system_free(&c);
}

/* ---- models whose M is not constant ---------------------------------- */

/* polar pendulum on a spring: T = m/2 (rd^2 + r^2 thd^2),
 * V = k/2 (r - r0)^2 - m g r cos th */
static int polar_T(eom_ctx *c, void *u, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    tp_val rr = eom_q(c, 0), rd = eom_qd(c, 0), thd = eom_qd(c, 1);
    (void)u;
    *out = tp_mul(r, tp_const(r, 0.5),
                  tp_add(r, tp_sqr(r, rd),
                         tp_mul(r, tp_sqr(r, rr), tp_sqr(r, thd))));
    return 0;
}

static int polar_V(eom_ctx *c, void *u, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    tp_val rr = eom_q(c, 0), th = eom_q(c, 1);
    (void)u;
    *out = tp_sub(r, tp_mul(r, tp_const(r, 10.0),
                            tp_sqr(r, tp_sub(r, rr, tp_const(r, 1.0)))),
                  tp_mul(r, tp_const(r, Gr), tp_mul(r, rr, tp_cos(r, th))));
    return 0;
}

/* one coordinate, T = 1/2 (1 + q^2) qd^2: M = 1 + q^2, 0 dependence at
 * q = 0 of its derivative, V = 0 */
static int bump_T(eom_ctx *c, void *u, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    tp_val q = eom_q(c, 0), qd = eom_qd(c, 0);
    (void)u;
    *out = tp_mul(r, tp_const(r, 0.5),
                  tp_mul(r, tp_add(r, tp_const(r, 1.0), tp_sqr(r, q)),
                         tp_sqr(r, qd)));
    return 0;
}

/* one coordinate, T = cosh-like in qd: T = qd^2/2 + qd^4/12, M = 1 + qd^2;
 * V = q^2 / 2 */
static int stiff_T(eom_ctx *c, void *u, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    tp_val qd = eom_qd(c, 0), q2 = tp_sqr(r, qd);
    (void)u;
    *out = tp_add(r, tp_mul(r, tp_const(r, 0.5), q2),
                  tp_mul(r, tp_const(r, 1.0 / 12.0), tp_sqr(r, q2)));
    return 0;
}

static int half_q2(eom_ctx *c, void *u, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    (void)u;
    *out = tp_mul(r, tp_const(r, 0.5), tp_sqr(r, eom_q(c, 0)));
    return 0;
}

static int zero_V(eom_ctx *c, void *u, tp_val *out)
{
    (void)u;
    *out = tp_const(eom_rec(c), 0.0);
    return 0;
}

/* a charged particle in a magnetic field B = 2 along z:
 * L = (xd^2 + yd^2) / 2 + (x yd - y xd): M = I, constant, and the
 * gyroscopic h = (d2L/dqd dq) qd = (-yd, xd) nonzero; xdd = 2 yd,
 * ydd = -2 xd */
static int magnetic_L(eom_ctx *c, void *u, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    tp_val x = eom_q(c, 0), y = eom_q(c, 1);
    tp_val xd = eom_qd(c, 0), yd = eom_qd(c, 1);
    (void)u;
    *out = tp_add(r, tp_mul(r, tp_const(r, 0.5),
                            tp_add(r, tp_sqr(r, xd), tp_sqr(r, yd))),
                  tp_sub(r, tp_mul(r, x, yd), tp_mul(r, y, xd)));
    return 0;
}

/* explicit time: L = qd^2 / 2 + qd sin t - q^2 / 2: M = 1 constant,
 * d/dt (qd + sin t) = -q, so qdd = -q - cos t (h holds d2L/dqd dt) */
static int timed_L(eom_ctx *c, void *u, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    tp_val q = eom_q(c, 0), qd = eom_qd(c, 0);
    (void)u;
    *out = tp_sub(r, tp_add(r, tp_mul(r, tp_const(r, 0.5), tp_sqr(r, qd)),
                            tp_mul(r, qd, tp_sin(r, eom_time(c)))),
                  tp_mul(r, tp_const(r, 0.5), tp_sqr(r, q)));
    return 0;
}

static eom_system *build(int n, eom_scalar_fn T, eom_scalar_fn V)
{
    eom_model *mo = NULL;
    eom_system *s = NULL;
    char err[256];
    int i;
    if (eom_model_new(&mo) != EOM_OK)
        return NULL;
    for (i = 0; i < n; i++) {
        char name[8];
        snprintf(name, sizeof name, "q%d", i);
        eom_model_add_coord(mo, name, NULL, 1.0, 0.0);
    }
    if (V) {
        eom_model_set_kinetic(mo, T, NULL);
        eom_model_set_potential(mo, V, NULL);
    } else {
        eom_model_set_lagrangian(mo, T, NULL);
    }
    if (eom_system_new(&s, mo, err, sizeof err) != EOM_OK)
        fprintf(stderr, "build: %s\n", err);
    eom_model_free(&mo);
    return s;
}

static void test_not_constant(void)
{
    eom_system *p = build(2, polar_T, polar_V);
    eom_system *b = build(1, bump_T, zero_V);
    eom_system *q = build(1, stiff_T, half_q2);
    double xd[4];
    if (!p || !b || !q) {
        CHECK(0);
        goto done;
    }
    CHECK_INT(eom_system_mass_route(p), EOM_MASS_DENSE);
    CHECK_INT(eom_system_mass_route(b), EOM_MASS_DENSE);
    CHECK_INT(eom_system_mass_route(q), EOM_MASS_DENSE);
    /* asking for the constant route is refused, with a reason */
    CHECK_INT(eom_system_set_mass_route(p, EOM_MASS_CONSTANT), EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(p), "not constant") != NULL);
    CHECK_INT(eom_system_set_mass_route(p, 7), EOM_ERR_ARG);
    {
        /* polar: rdd = r thd^2 - 20 (r - 1) + g cos th,
         * thdd = (-2 rd thd - g sin th) / r; first at r = 1, then r = 2 */
        const double x1[4] = {1.0, 0.3, 0.0, 0.0};
        const double x2[4] = {2.0, 0.5, 0.4, 1.5};
        CHECK_INT(eom_rhs(p, 0.0, x1, xd), EOM_OK);
        CHECK_NEAR(xd[2], -20.0 * 0.0 + Gr * cos(0.3), 1e-12);
        CHECK_NEAR(xd[3], -Gr * sin(0.3), 1e-12);
        CHECK_INT(eom_rhs(p, 0.0, x2, xd), EOM_OK);
        CHECK_NEAR(xd[2], 2.0 * 1.5 * 1.5 - 20.0 + Gr * cos(0.5), 1e-12);
        CHECK_NEAR(xd[3], (-2.0 * 0.4 * 1.5 - Gr * sin(0.5)) / 2.0, 1e-12);
    }
    {
        /* M = 1 + q^2, from q = 0 (where dM/dq = 0) to q = 1:
         * qdd = -q qd^2 / (1 + q^2) */
        const double x1[2] = {0.0, 1.0}, x2[2] = {1.0, 2.0};
        CHECK_INT(eom_rhs(b, 0.0, x1, xd), EOM_OK);
        CHECK_NEAR(xd[1], 0.0, 1e-15);
        CHECK_INT(eom_rhs(b, 0.0, x2, xd), EOM_OK);
        CHECK_NEAR(xd[1], -1.0 * 4.0 / 2.0, 1e-14);
    }
    {
        /* M = 1 + qd^2: qdd = -q / (1 + qd^2), at qd = 0 then qd = 2 */
        const double x1[2] = {1.0, 0.0}, x2[2] = {1.0, 2.0};
        CHECK_INT(eom_rhs(q, 0.0, x1, xd), EOM_OK);
        CHECK_NEAR(xd[1], -1.0, 1e-14);
        CHECK_INT(eom_rhs(q, 0.0, x2, xd), EOM_OK);
        CHECK_NEAR(xd[1], -1.0 / 5.0, 1e-14);
    }
done:
    eom_system_free(&p);
    eom_system_free(&b);
    eom_system_free(&q);
}

/* Constant M with h != 0: gyroscopic and time terms, on both routes. */
static void test_constant_h(void)
{
    eom_system *g = build(2, magnetic_L, NULL);
    eom_system *t = build(1, timed_L, NULL);
    double xd[4];
    int route;
    if (!g || !t) {
        CHECK(0);
        goto done;
    }
    CHECK_INT(eom_system_mass_route(g), EOM_MASS_CONSTANT);
    CHECK_INT(eom_system_mass_route(t), EOM_MASS_CONSTANT);
    /* no constraints: nothing for the sparse route to solve */
    CHECK_INT(eom_system_set_mass_route(g, EOM_MASS_SPARSE), EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(g), "no constraints") != NULL);
    for (route = 0; route <= EOM_MASS_DENSE; route += EOM_MASS_DENSE) {
        const double x[4] = {0.3, -0.7, 1.25, -0.5};
        const double y[2] = {0.4, 0.9};
        CHECK_INT(eom_system_set_mass_route(g, route), EOM_OK);
        CHECK_INT(eom_system_set_mass_route(t, route), EOM_OK);
        CHECK_INT(eom_rhs(g, 0.0, x, xd), EOM_OK);
        CHECK_NEAR(xd[2], 2.0 * -0.5, 1e-14);
        CHECK_NEAR(xd[3], -2.0 * 1.25, 1e-14);
        CHECK_INT(eom_rhs(t, 0.8, y, xd), EOM_OK);
        CHECK_NEAR(xd[1], -0.4 - cos(0.8), 1e-14);
    }
done:
    eom_system_free(&g);
    eom_system_free(&t);
}

/* ---- the pattern ------------------------------------------------------ */

static void test_pattern(const char *dir)
{
    const int N = 3, n = 2 * (N + 1);
    eom_system *s = a02(dir, N);
    eom_mass *ms;
    int j, i;
    size_t k;
    if (!s) {
        CHECK(0);
        return;
    }
    ms = eom__mass_info(s);
    CHECK(ms && ms->ok && ms->constant);
    if (!ms || !ms->ok)
        goto done;
    /* x_0..x_N then y_0..y_N: each a path of N + 1 (tridiagonal) */
    CHECK_INT((long long)ms->nnz, 2LL * (3 * (N + 1) - 2));
    for (j = 0; j < n; j++) {
        const int blk = j / (N + 1), p = j % (N + 1);
        int expect[3], ne = 0;
        for (i = p - 1; i <= p + 1; i++)
            if (i >= 0 && i <= N)
                expect[ne++] = blk * (N + 1) + i;
        CHECK_INT((long long)(ms->colptr[j + 1] - ms->colptr[j]), ne);
        for (k = (size_t)ms->colptr[j];
             k < (size_t)ms->colptr[j + 1] && (int)(k - ms->colptr[j]) < ne;
             k++)
            CHECK_INT((long long)ms->rowind[k],
                      expect[k - (size_t)ms->colptr[j]]);
    }
done:
    eom_system_free(&s);
}

/* ---- the report ------------------------------------------------------- */

static void test_report(const char *dir)
{
    const int N = 4, n = 2 * (N + 1);
    eom_system *s = a02(dir, N);
    eom_integ *it = NULL;
    eom_opts o;
    eom_stats st;
    double x[20];
    if (!s || eom_initial_state(s, x) != EOM_OK) {
        CHECK(0);
        goto done;
    }
    (void)n;
    eom_opts_default(&o);
    o.method = EOM_RK4;
    o.dt = 1e-3;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    CHECK_INT(eom_integ_advance(it, 0.01, x, NULL), EOM_OK);
    CHECK_INT(eom_integ_stats(it, &st), EOM_OK);
    CHECK_INT(st.mass_route, EOM_MASS_CONSTANT);
    eom_integ_free(&it);
    CHECK_INT(eom_system_set_mass_route(s, EOM_MASS_DENSE), EOM_OK);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    CHECK_INT(eom_integ_advance(it, 0.02, x, NULL), EOM_OK);
    CHECK_INT(eom_integ_stats(it, &st), EOM_OK);
    CHECK_INT(st.mass_route, EOM_MASS_DENSE);
    CHECK_INT(eom_system_set_mass_route(s, 0), EOM_OK);
    CHECK_INT(eom_system_mass_route(s), EOM_MASS_CONSTANT);
    CHECK_INT(eom_system_mass_route(NULL), EOM_ERR_NULL);
    CHECK(strcmp(eom_mass_route_name(EOM_MASS_DENSE), "dense") == 0);
    CHECK(strcmp(eom_mass_route_name(99), "unknown") == 0);
done:
    eom_integ_free(&it);
    eom_system_free(&s);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_mass_route MODELS_DIR\n");
        return 2;
    }
    test_a02_constant(argv[1]);
    test_not_constant();
    test_constant_h();
    test_pattern(argv[1]);
    test_report(argv[1]);
    CHECK_DONE();
}
