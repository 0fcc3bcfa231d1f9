/* test_lagrange_strips.c - the Lagrange block's ranged sweeps run in
 * strips of columns (libtape/src/strips.c) against the same sweeps
 * unstripped and against tp_hessian_cols.
 *
 * For chains of 1 to 17 and 33 links, one of 90 (two strips of 64, twelve
 * of 8) and a model whose rates meet in scrambled order through
 * non-linear ops, with a time argument: tp__lagrange_strips at widths 8,
 * 16 and 64 must give the gradient and the Hessian columns of the rates
 * of tp__fwd1_ranged then tp__rev2_ranged bit for bit (memcmp), and equal
 * (==, a zero's sign aside) those of tp_hessian_cols, one full sweep. The
 * unstripped sweep runs again after the strips on the same workspace (the
 * strips leave its rows alone) and must repeat its bits. A 200-link chain
 * goes through tp_lagrange_t's own switch to strips: its mass matrix must
 * equal the one from tp_hessian_cols. */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "pendulum_chain.h"
#include "support_rng.h"
#include "tape_internal.h"

/* Rates a = perm(k) and b = perm'(k) coupled through mul, exp, sin, div,
 * atan2 and a product with the time (last independent). */
static int scrambled_record(tp_rec *r, void *user)
{
    const int n = *(const int *)user;
    tp_val L = tp_const(r, 0.0), t = tp_indep(r, 2 * n);
    int k;
    for (k = 0; k < n; k++) {
        const int a = (11 * k + 5) % n, b = (3 * k + 2) % n;
        tp_val q = tp_indep(r, k), qa = tp_indep(r, n + a),
               qb = tp_indep(r, n + b), e;
        e = tp_mul(r, tp_exp(r, tp_mulc(r, tp_mul(r, qa, qb), 0.2)),
                   tp_sin(r, q));
        e = tp_add(r, e, tp_div(r, tp_sqr(r, qb),
                                tp_addc(r, tp_sqr(r, tp_cos(r, q)), 1.5)));
        e = tp_add(r, e, tp_mul(r, t, tp_atan2(r, qa, tp_addc(r, q, 2.0))));
        L = tp_add(r, L, tp_add(r, tp_mulc(r, tp_sqr(r, qa), 1.0 + k), e));
    }
    tp_output(r, "L", L);
    return 0;
}

/* == on every entry, all finite; names the first that differs. */
static int same_values(const char *what, int n, size_t len, const double *a,
                       const double *b)
{
    size_t i;
    for (i = 0; i < len; i++)
        if (!(a[i] == b[i]) || !isfinite(a[i])) {
            fprintf(stderr, "%s, n = %d: entry %zu %.17g against %.17g\n",
                    what, n, i, a[i], b[i]);
            return 0;
        }
    return 1;
}

static int same_bits(const char *what, int n, size_t len, const double *a,
                     const double *b)
{
    if (memcmp(a, b, len * sizeof(double)) == 0)
        return 1;
    return same_values(what, n, len, a, b) &&
           (fprintf(stderr, "%s, n = %d: a zero's sign differs\n", what,
                    n),
            0);
}

static void check_tape(const tp_tape *T, int n, rng *g)
{
    static const int widths[] = {8, 16, 64};
    const int ni = (int)T->n_indep;
    const size_t len = (size_t)ni * (size_t)n;
    tp_ws *ws = NULL, *wsh = NULL;
    double *x = malloc((size_t)ni * sizeof(double));
    double *w = calloc(T->n_out, sizeof(double));
    double *H0 = malloc(len * sizeof(double)), *H1 = malloc(len * sizeof(double));
    double *Hh = malloc(len * sizeof(double));
    double *g0 = malloc((size_t)ni * sizeof(double));
    double *g1 = malloc((size_t)ni * sizeof(double));
    double *gh = malloc((size_t)ni * sizeof(double));
    const int out = tp_tape_output_index(T, "L");
    size_t k;
    int pt, i;
    /* max_dirs 200: the workspace has strip rows at any n <= 200 */
    CHECK_INT(tp_ws_new(&ws, T, 200, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&wsh, T, n, NULL), TP_OK);
    CHECK(out >= 0);
    if (!ws || !wsh || out < 0 || !x || !w || !H0 || !H1 || !Hh || !g0 ||
        !g1 || !gh)
        goto done;
    CHECK(ws->strip_w >= 64);
    w[out] = 1.0;
    for (pt = 0; pt < 2; pt++) {
        const uint32_t end = T->out_slot[out] + 1;
        const unsigned mask = tp__unit_seed_mask(T, n, n);
        for (i = 0; i < ni; i++)
            x[i] = rng_range(g, -1.5, 1.5);
        tp__lagrange_ranges(ws, out, n, end);
        tp__fwd1_ranged(ws, x, n, mask, end);
        tp__rev2_ranged(ws, w, n, mask, end, g0, H0);
        CHECK_INT(tp_hessian_cols(wsh, x, out, n, n, gh, Hh), TP_OK);
        CHECK(same_values("ranged against tp_hessian_cols", n, len, H0, Hh));
        CHECK(same_values("gradient against tp_hessian_cols", n,
                          (size_t)ni, g0, gh));
        for (k = 0; k < sizeof widths / sizeof widths[0]; k++) {
            memset(H1, 0xff, len * sizeof(double)); /* NaN: must be set */
            memset(g1, 0xff, (size_t)ni * sizeof(double));
            tp__lagrange_strips(ws, x, w, n, mask, end, widths[k], g1, H1);
            CHECK(same_bits("strips against ranged", n, len, H1, H0));
            CHECK(same_bits("strips' gradient against ranged", n,
                            (size_t)ni, g1, g0));
        }
        /* the unstripped sweep after the strips: the same bits */
        tp__fwd1_ranged(ws, x, n, mask, end);
        tp__rev2_ranged(ws, w, n, mask, end, g1, H1);
        CHECK(same_bits("ranged after strips", n, len, H1, H0));
        CHECK(same_bits("ranged gradient after strips", n, (size_t)ni, g1,
                        g0));
    }
done:
    tp_ws_free(&ws);
    tp_ws_free(&wsh);
    free(x);
    free(w);
    free(H0);
    free(H1);
    free(Hh);
    free(g0);
    free(g1);
    free(gh);
}

static tp_tape *chain_tape(int n, rng *g, pendulum_chain *pc, double *m,
                           double *l)
{
    unsigned char *grp = malloc(2 * (size_t)n);
    tp_rec *r = NULL;
    tp_tape *T = NULL;
    int i;
    if (!grp)
        return NULL;
    for (i = 0; i < n; i++) {
        m[i] = rng_range(g, 0.5, 2.0);
        l[i] = rng_range(g, 0.3, 1.5);
        grp[i] = 0;
        grp[n + i] = 1;
    }
    pc->n = n;
    pc->m = m;
    pc->l = l;
    pc->g = 9.81;
    CHECK_INT(tp_recorder_new(&r, 2 * n, grp, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, pendulum_chain_record, pc), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    tp_rec_free(&r);
    free(grp);
    return T;
}

static void chain(int n, rng *g)
{
    pendulum_chain pc;
    double m[100], l[100];
    tp_tape *T = chain_tape(n, g, &pc, m, l);
    if (T)
        check_tape(T, n, g);
    tp_tape_free(&T);
}

static void scrambled_model(int n, rng *g)
{
    tp_rec *r = NULL;
    tp_tape *T = NULL;
    CHECK_INT(tp_recorder_new(&r, 2 * n + 1, NULL, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, scrambled_record, &n), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    tp_rec_free(&r);
    if (T)
        check_tape(T, n, g);
    tp_tape_free(&T);
}

/* 200 links: tp_lagrange_t itself sweeps in strips; its M against the
 * rates' rows of tp_hessian_cols. */
static void chain_200(rng *g)
{
    enum { N = 200 };
    pendulum_chain pc;
    static double m[N], l[N], x[2 * N], M[N * N], h[N], H[2 * N * N],
        gr[2 * N];
    tp_tape *T = chain_tape(N, g, &pc, m, l);
    tp_ws *ws = NULL, *wsh = NULL;
    int i, out;
    if (!T)
        return;
    out = tp_tape_output_index(T, "L");
    CHECK_INT(tp_ws_new(&ws, T, N, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&wsh, T, N, NULL), TP_OK);
    if (ws && wsh && out >= 0) {
        CHECK(tp__strips_pay(ws, N));
        for (i = 0; i < 2 * N; i++)
            x[i] = rng_range(g, -1.5, 1.5);
        CHECK_INT(tp_lagrange_t(ws, x, out, NULL, NULL, NULL, M, h), TP_OK);
        CHECK_INT(tp_hessian_cols(wsh, x, out, N, N, gr, H), TP_OK);
        for (i = 0; i < N; i++)
            CHECK(same_values("tp_lagrange_t in strips against "
                              "tp_hessian_cols",
                              N, N, M + (size_t)i * N,
                              H + (size_t)(N + i) * N));
    }
    tp_ws_free(&ws);
    tp_ws_free(&wsh);
    tp_tape_free(&T);
}

int main(void)
{
    rng g = rng_seed(20261128);
    int n;
    for (n = 1; n <= 17; n++) {
        chain(n, &g);
        scrambled_model(n, &g);
    }
    chain(33, &g);
    scrambled_model(33, &g);
    chain(90, &g);
    scrambled_model(90, &g);
    chain_200(&g);
    CHECK_DONE();
}
