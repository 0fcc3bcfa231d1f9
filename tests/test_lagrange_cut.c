/* test_lagrange_cut.c - tp_lagrange_t's h, gathered at the ops on no
 * rate (sweep_ops.h, tp__tau; ranges.c), against a closed form.
 *
 * The Lagrangian, with q grouped 0, qd 1 and t 2 as libeom records:
 *   L = sum_k (1/2 qd_a qd_b c_k(q, t) + 1/2 qd_b q_k t + cos q_k),
 *   a = (7k + 3) mod n, b = (5k + 1) mod n (rates met in scrambled order),
 *   c_k = w_k cos s_k, s_k = sin(q_k - q_{k+1}/2) + 0.3 t, w_k = 2 + q_k^2:
 * c_k is a chain of ops on no rate five deep, driven by q and by the time.
 * Then dL/dqd_c = 1/2 sum_k (c_k ([a = c] qd_b + [b = c] qd_a)
 * + [b = c] q_k t), and
 * h_c = d/de dL/dqd_c (q + e qd, qd, t + e) takes dc_k = grad c_k . (qd, 1)
 * in place of c_k and qd_k t + q_k in place of q_k t, written out below
 * by hand. Every interpreter path of tp_lagrange_t runs: one vector
 * (n <= 4), the ranged sweeps (n > 4), strips (n = 200, a workspace of
 * 200 directions), and chunks (workspaces of 3 directions: one vector,
 * and of 8: the general kernels over full rows). h must agree with the
 * closed form to rounding on each, L, dL/dq, dL/dt and M bit for bit
 * between them, and every sweep must leave its adjoint-tangent rows and
 * flags zero (the next sweep relies on it).
 *
 * White-box: the reverse ranges of the ops on no rate that no op on a
 * rate reads must be empty (a rate-free op passes its row to no operand). */
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "support_rng.h"
#include "sweep.h"

#define NMAX 200

typedef struct model {
    int n;
} model;

static int pair_a(int k, int n)
{
    return (7 * k + 3) % n;
}
static int pair_b(int k, int n)
{
    return (5 * k + 1) % n;
}

static int record(tp_rec *r, void *user)
{
    const model *md = user;
    const int n = md->n;
    tp_val L = tp_const(r, 0.0), t = tp_indep(r, 2 * n);
    int k;
    for (k = 0; k < n; k++) {
        const int k1 = (k + 1) % n;
        tp_val q = tp_indep(r, k), q1 = tp_indep(r, k1);
        tp_val s = tp_add(r, tp_sin(r, tp_sub(r, q, tp_mulc(r, q1, 0.5))),
                          tp_mulc(r, t, 0.3));
        tp_val c = tp_mul(r, tp_addc(r, tp_sqr(r, q), 2.0), tp_cos(r, s));
        tp_val e = tp_mul(r,
                          tp_mul(r, tp_indep(r, n + pair_a(k, n)),
                                 tp_indep(r, n + pair_b(k, n))),
                          tp_mulc(r, c, 0.5));
        /* ops on a rate that read q and t themselves: their rows reach
         * q and t, summed into h at the end of the sweep */
        e = tp_add(
            r, e,
            tp_mulc(r,
                    tp_mul(r, tp_mul(r, tp_indep(r, n + pair_b(k, n)), q), t),
                    0.5));
        L = tp_add(r, L, tp_add(r, e, tp_cos(r, q)));
    }
    tp_output(r, "L", L);
    return 0;
}

/* h by hand; bound[c]: 1e-13 times the terms' magnitudes plus one. */
static void closed_form(int n, const double *x, double *h, double *bound)
{
    const double *q = x, *qd = x + n;
    int k, c;
    for (c = 0; c < n; c++)
        h[c] = bound[c] = 0.0;
    for (k = 0; k < n; k++) {
        const int k1 = (k + 1) % n, a = pair_a(k, n), b = pair_b(k, n);
        const double ak = q[k] - 0.5 * q[k1], dak = qd[k] - 0.5 * qd[k1];
        const double sk = sin(ak) + 0.3 * x[2 * n];
        const double dsk = cos(ak) * dak + 0.3;
        const double wk = 2.0 + q[k] * q[k];
        const double dck = -sin(sk) * dsk * wk + cos(sk) * 2.0 * q[k] * qd[k];
        h[b] += 0.5 * (qd[k] * x[2 * n] + q[k]);
        bound[b] += 0.5 * (fabs(qd[k] * x[2 * n]) + fabs(q[k]));
        h[a] += 0.5 * dck * qd[b];
        h[b] += 0.5 * dck * qd[a];
        /* the products' magnitudes, each rounded a few times */
        const double mag = wk * (fabs(dak) + 0.3) + 2.0 * fabs(q[k] * qd[k]);
        bound[a] += 0.5 * mag * fabs(qd[b]);
        bound[b] += 0.5 * mag * fabs(qd[a]);
    }
    for (c = 0; c < n; c++)
        bound[c] = 1e-13 * (1.0 + bound[c]);
}

/* The ops on no rate that no op on a rate reads have empty reverse
 * ranges; returns how many such ops there are (the check's reach). */
static int check_cut(tp_ws *ws, int out, int n)
{
    const tp_tape *T = ws->t;
    const uint32_t end = T->out_slot[out] + 1;
    const unsigned mask = tp__unit_seed_mask(T, n, n);
    bool *read = calloc(T->n_ops, sizeof *read);
    uint32_t i;
    int below = 0;
    CHECK(read != NULL);
    if (!read)
        return 0;
    tp__lagrange_ranges(ws, out, n, end);
    for (i = T->first_active; i < end; i++) {
        const unsigned fl = T->dep[i];
        if (!(fl & mask))
            continue;
        if (!TP_UPASSIVE(fl))
            read[T->a0[i]] = true;
        if (tp__op_kind(T->opc[i]) == TP_KIND_BINARY && !TP_TPASSIVE(fl))
            read[T->a1[i]] = true;
    }
    for (i = T->first_active; i < end; i++)
        if (!(T->dep[i] & mask) && !read[i]) {
            below++;
            if (ws->rrange[2 * i] != ws->rrange[2 * i + 1]) {
                fprintf(stderr,
                        "n = %d: op %u on no rate, read by none on "
                        "a rate, has reverse range [%u, %u)\n",
                        n, i, ws->rrange[2 * i], ws->rrange[2 * i + 1]);
                CHECK(0);
                break;
            }
        }
    /* the ranged sweeps' ranges were replaced: have them made again */
    ws->range_out = -1;
    free(read);
    return below;
}

/* The sweeps leave every adjoint-tangent row zero (anz too), the strips'
 * as well: an op on no rate that passed its row on below the cut would
 * leave rows there that nothing consumes. */
static void check_clean(const tp_ws *ws, int n)
{
    const size_t no = ws->t->n_ops, P = (size_t)ws->P;
    const size_t ns = ws->strip_w > 0 ? no * (size_t)ws->strip_w : 0;
    size_t i, bad = 0;
    for (i = 0; i < no * P; i++)
        bad += ws->atan[i] != 0.0;
    for (i = 0; i < ns; i++)
        bad += ws->satan[i] != 0.0;
    for (i = 0; i < no; i++)
        bad += ws->anz[i] != 0;
    if (bad) {
        fprintf(stderr,
                "n = %d: %zu adjoint-tangent entries or flags left "
                "non-zero\n",
                n, bad);
        CHECK(0);
    }
}

static void check_n(int n, rng *g)
{
    static double x[2 * NMAX + 1], M[NMAX * NMAX], M3[NMAX * NMAX];
    static double M8[NMAX * NMAX], h8[NMAX], dq8[NMAX];
    static double h[NMAX], h3[NMAX], hc[NMAX], bound[NMAX], dq[NMAX], dq3[NMAX];
    model md;
    tp_rec *r = NULL;
    tp_tape *T = NULL;
    tp_ws *ws = NULL, *ws3 = NULL, *ws8 = NULL;
    unsigned char grp[2 * NMAX + 1];
    double L, L3, L8, dt, dt3, dt8;
    int i, pt, out;
    for (i = 0; i <= 2 * n; i++)
        grp[i] = (unsigned char)(i < n ? 0 : i < 2 * n ? 1 : 2);
    md.n = n;
    CHECK_INT(tp_recorder_new(&r, 2 * n + 1, grp, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, record, &md), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    tp_rec_free(&r);
    if (!T)
        return;
    CHECK_INT(tp_ws_new(&ws, T, n, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&ws3, T, 3, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&ws8, T, 8, NULL), TP_OK);
    out = tp_tape_output_index(T, "L");
    CHECK(out >= 0);
    if (!ws || !ws3 || !ws8 || out < 0)
        goto done;
    for (pt = 0; pt < 3; pt++) {
        for (i = 0; i <= 2 * n; i++)
            x[i] = rng_range(g, -1.5, 1.5);
        CHECK_INT(tp_lagrange_t(ws, x, out, &L, dq, &dt, M, h), TP_OK);
        check_clean(ws, n);
        CHECK_INT(tp_lagrange_t(ws3, x, out, &L3, dq3, &dt3, M3, h3), TP_OK);
        check_clean(ws3, n);
        /* chunks of 8: the general (not one-vector) kernels over full rows */
        CHECK_INT(tp_lagrange_t(ws8, x, out, &L8, dq8, &dt8, M8, h8), TP_OK);
        check_clean(ws8, n);
        closed_form(n, x, hc, bound);
        for (i = 0; i < n; i++)
            if (!(fabs(h[i] - hc[i]) <= bound[i]) ||
                !(fabs(h3[i] - hc[i]) <= bound[i]) ||
                !(fabs(h8[i] - hc[i]) <= bound[i])) {
                fprintf(stderr,
                        "n = %d: h[%d] %.17g, in chunks of 3 %.17g, "
                        "of 8 %.17g, closed form %.17g\n",
                        n, i, h[i], h3[i], h8[i], hc[i]);
                CHECK(0);
                break;
            }
        /* chunks of 3 against one sweep: L, dL/dq, dL/dt and M bit for
         * bit (h is checked against the closed form above) */
        CHECK(L == L3 && dt == dt3 && L == L8 && dt == dt8);
        for (i = 0; i < n * n; i++)
            if (!(M[i] == M3[i]) || !(M[i] == M8[i])) {
                fprintf(stderr, "n = %d: M[%d] %.17g, in chunks %.17g\n", n, i,
                        M[i], M3[i]);
                CHECK(0);
                break;
            }
        for (i = 0; i < n; i++)
            CHECK(dq[i] == dq3[i] && dq[i] == dq8[i]);
    }
    if (n > TP_LANES)
        CHECK(check_cut(ws, out, n) > 0);
done:
    tp_ws_free(&ws);
    tp_ws_free(&ws3);
    tp_ws_free(&ws8);
    tp_tape_free(&T);
}

int main(void)
{
    static const int extra[] = {33, 90, 200};
    rng g = rng_seed(26);
    int n;
    size_t k;
    for (n = 1; n <= 17; n++)
        check_n(n, &g);
    for (k = 0; k < sizeof extra / sizeof extra[0]; k++)
        check_n(extra[k], &g);
    CHECK_DONE();
}
