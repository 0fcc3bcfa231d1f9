/* test_lagrange_ranges.c - tp_lagrange's sweeps over each row's column
 * range (libtape/src/ranges.c) against the full sweeps, bit for bit.
 *
 * A workspace of n directions takes the ranged path once the rates fill
 * more than one vector (n > 4). Its L, dL/dq, M and h must equal, bit for
 * bit (a zero's sign aside: == on finite doubles), those of
 *   - a workspace of 3 directions (tp_lagrange in chunks, full rows), and
 *   - tp_hessian_cols over the rates (one full forward-over-reverse sweep
 *     with the same seeds), M its rows of the rates, h summed from its
 *     rows of the coordinates in tp_lagrange's order,
 * for chains of 1 to 13, 16, 17 and 33 links (the vector edges) and for a
 * model whose rates meet in scrambled order through non-linear ops of
 * every kind, with a time argument. Between two calls of tp_lagrange on
 * one workspace a tp_jvp and a tp_hessian_cols write full tangent rows
 * with other seeds: the second call must still give the same bits (the
 * ranged sweep's zero columns are restored when another sweep wrote
 * them). */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "pendulum_chain.h"
#include "support_rng.h"

#define NMAX 40

/* A Lagrangian whose rates are mixed across the vectors: term k couples
 * rates a = perm(k) and b = perm(k + 3) through exp, hypot, powi, div,
 * atan2 and a product with the time (last independent). */
typedef struct scrambled {
    int n;
} scrambled;

static int scrambled_record(tp_rec *r, void *user)
{
    const scrambled *sc = user;
    const int n = sc->n;
    tp_val L = tp_const(r, 0.0), t = tp_indep(r, 2 * n);
    int k;
    for (k = 0; k < n; k++) {
        const int a = (7 * k + 3) % n, b = (5 * k + 1) % n;
        tp_val q = tp_indep(r, k), qa = tp_indep(r, n + a),
               qb = tp_indep(r, n + b), e;
        e = tp_mul(r, tp_exp(r, tp_mulc(r, tp_mul(r, qa, qb), 0.1)),
                   tp_cos(r, q));
        e = tp_add(r, e, tp_div(r, tp_hypot(r, qa, tp_addc(r, qb, 1.0)),
                                tp_addc(r, tp_sqr(r, tp_sin(r, q)), 2.0)));
        e = tp_add(r, e, tp_mul(r, tp_powi(r, qb, 3), tp_mulc(r, q, 0.01)));
        e = tp_add(r, e, tp_mul(r, t, tp_atan2(r, qa, tp_addc(r, q, 3.0))));
        L = tp_add(r, L, tp_add(r, tp_mulc(r, tp_sqr(r, qa), 0.5 + k), e));
    }
    tp_output(r, "L", L);
    return 0;
}

/* tp_lagrange_t's results, in one record for comparing. */
typedef struct block {
    double L, dLdt, dLdq[NMAX], M[NMAX * NMAX], h[NMAX];
} block;

static int lagrange(tp_ws *ws, const double *x, int out, block *b)
{
    return tp_lagrange_t(ws, x, out, &b->L, b->dLdq, &b->dLdt, b->M, b->h);
}

/* == on every entry, all finite; names the first that differs. */
static int same(const char *what, int n, const block *a, const block *b)
{
    int i, bad = 0;
    for (i = 0; i < n * n && !bad; i++)
        bad = !(a->M[i] == b->M[i] && isfinite(a->M[i])) ? 1 + i : 0;
    if (bad) {
        fprintf(stderr, "%s, n = %d: M[%d] %.17g against %.17g\n", what, n,
                bad - 1, a->M[bad - 1], b->M[bad - 1]);
        return 0;
    }
    for (i = 0; i < n; i++)
        if (!(a->h[i] == b->h[i] && isfinite(a->h[i])) ||
            !(a->dLdq[i] == b->dLdq[i])) {
            fprintf(stderr, "%s, n = %d: h[%d] %.17g against %.17g\n", what,
                    n, i, a->h[i], b->h[i]);
            return 0;
        }
    if (!(a->L == b->L) || !(a->dLdt == b->dLdt)) {
        fprintf(stderr, "%s, n = %d: L or dL/dt differ\n", what, n);
        return 0;
    }
    return 1;
}

/* The block from tp_hessian_cols over the rates: one full sweep. */
static void from_hessian(tp_ws *ws, const double *x, int out, int n,
                         bool timed, block *b)
{
    const int ni = timed ? 2 * n + 1 : 2 * n;
    static double H[(2 * NMAX + 1) * NMAX], g[2 * NMAX + 1];
    double y[3];
    int i, k;
    CHECK_INT(tp_hessian_cols(ws, x, out, n, n, g, H), TP_OK);
    CHECK_INT(tp_eval(ws, x, y), TP_OK);
    b->L = y[out];
    b->dLdt = timed ? g[2 * n] : 0.0;
    for (i = 0; i < n; i++) {
        b->dLdq[i] = g[i];
        memcpy(b->M + i * n, H + (n + i) * n, (size_t)n * sizeof(double));
    }
    for (k = 0; k < n; k++) {
        /* tp_lagrange's order: from 0, row by row, then the time row */
        double s = 0.0;
        for (i = 0; i < n; i++)
            s += H[i * n + k] * x[n + i];
        if (timed)
            s += H[2 * n * n + k];
        b->h[k] = s;
    }
    (void)ni;
}

static void check_model(tp_tape *T, int n, bool timed, rng *g)
{
    tp_ws *ws = NULL, *ws3 = NULL, *wsh = NULL;
    const int ni = timed ? 2 * n + 1 : 2 * n;
    static block a, a2, c, hb;
    static double S[(2 * NMAX + 1) * NMAX], JS[3 * NMAX], H[(2 * NMAX + 1) * NMAX];
    double x[2 * NMAX + 1], y[3]; /* a chain's outputs: L, T, V */
    int out, pt, i;
    CHECK_INT(tp_ws_new(&ws, T, n, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&ws3, T, 3, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&wsh, T, n, NULL), TP_OK);
    out = tp_tape_output_index(T, "L");
    CHECK(out >= 0);
    if (!ws || !ws3 || !wsh || out < 0)
        goto done;
    for (pt = 0; pt < 4; pt++) {
        for (i = 0; i < ni; i++)
            x[i] = rng_range(g, -1.5, 1.5);
        for (i = 0; i < ni * n; i++)
            S[i] = rng_range(g, -1.0, 1.0);
        CHECK_INT(lagrange(ws, x, out, &a), TP_OK);
        CHECK_INT(lagrange(ws3, x, out, &c), TP_OK);
        CHECK(same("ranged against chunks of 3", n, &a, &c));
        from_hessian(wsh, x, out, n, timed, &hb);
        CHECK(same("ranged against tp_hessian_cols", n, &a, &hb));
        /* full rows with other seeds in between, then the same call */
        CHECK_INT(tp_jvp(ws, x, n, S, y, JS), TP_OK);
        CHECK_INT(lagrange(ws, x, out, &a2), TP_OK);
        CHECK(same("ranged after tp_jvp", n, &a, &a2));
        CHECK_INT(tp_hessian_cols(ws, x, out, 0, n, NULL, H), TP_OK);
        CHECK_INT(lagrange(ws, x, out, &a2), TP_OK);
        CHECK(same("ranged after tp_hessian_cols", n, &a, &a2));
    }
done:
    tp_ws_free(&ws);
    tp_ws_free(&ws3);
    tp_ws_free(&wsh);
}

static void chain(int n, rng *g)
{
    pendulum_chain pc;
    double m[NMAX], l[NMAX];
    unsigned char grp[2 * NMAX];
    tp_rec *r = NULL;
    tp_tape *T = NULL;
    int i;
    for (i = 0; i < n; i++) {
        m[i] = rng_range(g, 0.5, 2.0);
        l[i] = rng_range(g, 0.3, 1.5);
        grp[i] = 0;
        grp[n + i] = 1;
    }
    pc.n = n;
    pc.m = m;
    pc.l = l;
    pc.g = 9.81;
    CHECK_INT(tp_recorder_new(&r, 2 * n, grp, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, pendulum_chain_record, &pc), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    tp_rec_free(&r);
    if (T)
        check_model(T, n, false, g);
    tp_tape_free(&T);
}

/* One group for every independent: the coordinates' and the time's rows
 * are swept too (ranges empty), the rates' in scrambled order. */
static void scrambled_model(int n, rng *g)
{
    scrambled sc;
    tp_rec *r = NULL;
    tp_tape *T = NULL;
    sc.n = n;
    CHECK_INT(tp_recorder_new(&r, 2 * n + 1, NULL, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, scrambled_record, &sc), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    tp_rec_free(&r);
    if (T)
        check_model(T, n, true, g);
    tp_tape_free(&T);
}

int main(void)
{
    static const int extra[] = {16, 17, 33};
    rng g = rng_seed(20261128);
    int n;
    size_t k;
    for (n = 1; n <= 13; n++) {
        chain(n, &g);
        scrambled_model(n, &g);
    }
    for (k = 0; k < sizeof extra / sizeof extra[0]; k++) {
        chain(extra[k], &g);
        scrambled_model(extra[k], &g);
    }
    CHECK_DONE();
}
