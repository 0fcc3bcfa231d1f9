/* drivers.c - the public sweep calls: argument checks, splitting p
 * directions into chunks of the workspace's max_dirs, copying results out,
 * and the single check for non-finite results at the end. The kernels are
 * in forward.c and reverse.c. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "codegen.h"
#include "sweep.h" /* TP_VECTOR_CLONES for store_block_n */
#include "tape_internal.h"

static int fail(tp_ws *ws, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static int fail(tp_ws *ws, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(ws->msg, sizeof ws->msg, fmt, ap);
    va_end(ap);
    return status;
}

static bool all_finite(const double *a, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++)
        if (!isfinite(a[i]))
            return false;
    return true;
}

/* Bit 63 set when a is an infinity or a NaN: its exponent field, all
 * ones, carries into bit 63 when one is added to it; no other exponent
 * reaches it. An OR of these over the values written has no branch, so
 * tp_lagrange_t checks its results in the loops that write them (and
 * GCC vectorizes those loops). */
static inline uint64_t nonfinite_bit(double a)
{
    uint64_t u;
    memcpy(&u, &a, sizeof u);
    return (u & UINT64_C(0x7ff0000000000000)) + UINT64_C(0x0010000000000000);
}
#define TP_NONFINITE_OR(acc, a) ((acc) |= nonfinite_bit(a))
#define TP_ALL_FINITE(acc) (((acc) >> 63) == 0)

/* Accumulates the status of a call: TP_WARN_NONFINITE once any requested
 * result is not finite. */
static void check(int *st, const double *a, size_t n)
{
    if (a && *st == TP_OK && !all_finite(a, n))
        *st = TP_WARN_NONFINITE;
}

/* One past the highest output slot with a non-zero weight (w NULL: all
 * outputs), so sweeps stop where nothing needed lies beyond. */
static uint32_t end_of(const tp_tape *T, const double *w)
{
    uint32_t o, end = T->n_indep + T->n_param;
    for (o = 0; o < T->n_out; o++)
        if ((!w || w[o] != 0.0) && T->out_slot[o] + 1 > end)
            end = T->out_slot[o] + 1;
    return end;
}

static int begin(tp_ws *ws, const double *x, const char *fn)
{
    if (!ws)
        return TP_ERR_NULL;
    if (!x && ws->t->n_indep > 0)
        return fail(ws, TP_ERR_NULL, "%s: x is NULL", fn);
    ws->msg[0] = '\0';
    return TP_OK;
}

static void copy_outputs(const tp_ws *ws, double *y)
{
    const tp_tape *T = ws->t;
    uint32_t o;
    if (y)
        for (o = 0; o < T->n_out; o++)
            y[o] = ws->v[T->out_slot[o]];
}

static int check_out(tp_ws *ws, int out, const char *fn)
{
    if (out < 0 || (uint32_t)out >= ws->t->n_out)
        return fail(ws, TP_ERR_SIZE, "%s: output %d outside 0 .. %d", fn,
                    out, (int)ws->t->n_out - 1);
    return TP_OK;
}

/* end_of for unit_weights(ws, out), without the scan of the outputs. */
static uint32_t end_of_unit(const tp_tape *T, int out)
{
    const uint32_t end = T->n_indep + T->n_param;
    return T->out_slot[out] + 1 > end ? T->out_slot[out] + 1 : end;
}

/* Output weights selecting output out, in the workspace's scratch. */
static const double *unit_weights(tp_ws *ws, int out)
{
    memset(ws->wout, 0, ws->t->n_out * sizeof(double));
    ws->wout[out] = 1.0;
    return ws->wout;
}

int tp_eval(tp_ws *ws, const double *x, double *y)
{
    int st = begin(ws, x, "tp_eval");
    if (st)
        return st;
    if (!y)
        return fail(ws, TP_ERR_NULL, "tp_eval: y is NULL");
    tp__fwd0(ws, x, end_of(ws->t, NULL));
    copy_outputs(ws, y);
    check(&st, y, ws->t->n_out);
    return st;
}

/* Forward sweeps over p directions in chunks; S NULL means unit directions
 * on independents first .. first+p-1. Writes Y (m x p) and y. */
static int forward_dirs(tp_ws *ws, const double *x, int p, const double *S,
                        int first, double *y, double *Y)
{
    const tp_tape *T = ws->t;
    const uint32_t end = end_of(T, NULL);
    const size_t P = (size_t)ws->P;
    /* the compiled Jacobian block: every independent's direction in one
     * call (its rows are P >= p wide) */
    const bool block = p > 0 && !S && ws->cc && ws->cc->jacobian &&
                       first == 0 && p == (int)T->n_indep;
    int st = TP_OK, c0, k;
    uint32_t o;
    if (p == 0) {
        tp__fwd0(ws, x, end);
    } else if (block) {
        tp__jacobian_compiled(ws, x);
        for (o = 0; o < T->n_out; o++)
            memcpy(Y + (size_t)o * (size_t)p, ws->tan + T->out_slot[o] * P,
                   (size_t)p * sizeof(double));
    }
    for (c0 = 0; c0 < p && !block; c0 += ws->max_dirs) {
        const int pc = p - c0 < ws->max_dirs ? p - c0 : ws->max_dirs;
        const double *Sc = S ? S + c0 : NULL;
        const unsigned mask =
            tp__seed_mask(T, pc, Sc, (size_t)p, first + c0);
        tp__fwd1(ws, x, pc, Sc, (size_t)p, first + c0, mask, end);
        for (o = 0; o < T->n_out; o++) {
            const double *r = ws->tan + T->out_slot[o] * P;
            for (k = 0; k < pc; k++)
                Y[(size_t)o * (size_t)p + (size_t)(c0 + k)] = r[k];
        }
    }
    copy_outputs(ws, y);
    check(&st, y, T->n_out);
    check(&st, Y, (size_t)T->n_out * (size_t)p);
    return st;
}

int tp_jvp(tp_ws *ws, const double *x, int p, const double *S, double *y,
           double *JS)
{
    int st = begin(ws, x, "tp_jvp");
    if (st)
        return st;
    if (p < 0)
        return fail(ws, TP_ERR_SIZE, "tp_jvp: p = %d", p);
    if (p > 0 && (!S || !JS))
        return fail(ws, TP_ERR_NULL, "tp_jvp: S or JS is NULL");
    return forward_dirs(ws, x, p, S, 0, y, JS);
}

int tp_jacobian(tp_ws *ws, const double *x, int first, int count, double *y,
                double *J)
{
    int st = begin(ws, x, "tp_jacobian");
    if (st)
        return st;
    /* written so that first + count cannot overflow */
    if (first < 0 || count < 0 || first > (int)ws->t->n_indep ||
        count > (int)ws->t->n_indep - first)
        return fail(ws, TP_ERR_SIZE,
                    "tp_jacobian: %d columns from %d outside 0 .. %d", count,
                    first, (int)ws->t->n_indep - 1);
    if (count > 0 && !J)
        return fail(ws, TP_ERR_NULL, "tp_jacobian: J is NULL");
    return forward_dirs(ws, x, count, NULL, first, y, J);
}

int tp_vjp(tp_ws *ws, const double *x, const double *w, double *y, double *g)
{
    int st = begin(ws, x, "tp_vjp");
    const tp_tape *T;
    if (st)
        return st;
    T = ws->t;
    if (!w || !g)
        return fail(ws, TP_ERR_NULL, "tp_vjp: w or g is NULL");
    tp__fwd0(ws, x, end_of(T, y ? NULL : w));
    tp__rev1(ws, w, end_of(T, w), g);
    copy_outputs(ws, y);
    check(&st, y, T->n_out);
    check(&st, g, T->n_indep);
    return st;
}

int tp_gradient(tp_ws *ws, const double *x, int out, double *y, double *g)
{
    int st = begin(ws, x, "tp_gradient");
    const double *w;
    if (st)
        return st;
    if ((st = check_out(ws, out, "tp_gradient")) != TP_OK)
        return st;
    if (!g)
        return fail(ws, TP_ERR_NULL, "tp_gradient: g is NULL");
    w = unit_weights(ws, out);
    tp__fwd0(ws, x, end_of_unit(ws->t, out));
    tp__rev1(ws, w, end_of_unit(ws->t, out), g);
    if (y)
        *y = ws->v[ws->t->out_slot[out]];
    check(&st, y, 1);
    check(&st, g, ws->t->n_indep);
    return st;
}

/* Forward-over-reverse over p directions in chunks (S NULL: unit directions
 * on first .. first+p-1). Writes g (may be NULL) and H (n x p, leading
 * dimension p; may be NULL only if p == 0). */
static int hessian_dirs(tp_ws *ws, const double *x, const double *w, int p,
                        const double *S, int first, double *g, double *H)
{
    const tp_tape *T = ws->t;
    const uint32_t end = end_of(T, w);
    int st = TP_OK, c0;
    double *gg = g ? g : ws->g;
    if (p == 0) {
        tp__fwd0(ws, x, end);
        tp__rev1(ws, w, end, gg);
    }
    for (c0 = 0; c0 < p; c0 += ws->max_dirs) {
        const int pc = p - c0 < ws->max_dirs ? p - c0 : ws->max_dirs;
        const double *Sc = S ? S + c0 : NULL;
        const unsigned mask =
            tp__seed_mask(T, pc, Sc, (size_t)p, first + c0);
        tp__fwd1(ws, x, pc, Sc, (size_t)p, first + c0, mask, end);
        tp__rev2(ws, w, pc, mask, end, c0 == 0 ? gg : NULL, H + c0,
                 (size_t)p);
    }
    check(&st, g, T->n_indep);
    check(&st, H, (size_t)T->n_indep * (size_t)p);
    return st;
}

int tp_hvp(tp_ws *ws, const double *x, const double *w, int p,
           const double *S, double *g, double *HS)
{
    int st = begin(ws, x, "tp_hvp");
    if (st)
        return st;
    if (p < 0)
        return fail(ws, TP_ERR_SIZE, "tp_hvp: p = %d", p);
    if (!w || (p > 0 && (!S || !HS)))
        return fail(ws, TP_ERR_NULL, "tp_hvp: w, S or HS is NULL");
    return hessian_dirs(ws, x, w, p, S, 0, g, HS);
}

int tp_hessian_cols(tp_ws *ws, const double *x, int out, int first,
                    int count, double *g, double *H)
{
    int st = begin(ws, x, "tp_hessian_cols");
    if (st)
        return st;
    if ((st = check_out(ws, out, "tp_hessian_cols")) != TP_OK)
        return st;
    if (first < 0 || count < 0 || first > (int)ws->t->n_indep ||
        count > (int)ws->t->n_indep - first)
        return fail(ws, TP_ERR_SIZE,
                    "tp_hessian_cols: %d columns from %d outside 0 .. %d",
                    count, first, (int)ws->t->n_indep - 1);
    if (count > 0 && !H)
        return fail(ws, TP_ERR_NULL, "tp_hessian_cols: H is NULL");
    return hessian_dirs(ws, x, unit_weights(ws, out), count, NULL, first, g,
                        H);
}

int tp_hessian(tp_ws *ws, const double *x, int out, double *H)
{
    if (!ws)
        return TP_ERR_NULL;
    return tp_hessian_cols(ws, x, out, 0, (int)ws->t->n_indep, NULL, H);
}

int tp_taylor2(tp_ws *ws, const double *x, const double *d, double *y,
               double *y1, double *y2)
{
    int st = begin(ws, x, "tp_taylor2");
    const tp_tape *T;
    uint32_t o;
    if (st)
        return st;
    T = ws->t;
    if (!d || !y2)
        return fail(ws, TP_ERR_NULL, "tp_taylor2: d or y2 is NULL");
    tp__taylor2(ws, x, d, end_of(T, NULL));
    for (o = 0; o < T->n_out; o++) {
        const uint32_t s = T->out_slot[o];
        if (y)
            y[o] = ws->v[s];
        if (y1)
            y1[o] = ws->d1[s];
        y2[o] = ws->d2[s];
    }
    check(&st, y, T->n_out);
    check(&st, y1, T->n_out);
    check(&st, y2, T->n_out);
    return st;
}

/* M's columns c0 .. c0 + pc - 1 and h's entries from H, the Hessian
 * columns of one chunk of rate directions (rows: d/dq (n), then d/dqd
 * (n), then d/dt when timed; pc columns). Returns whether every value
 * written is finite. With all n columns in one chunk (always so for a
 * compiled block) the d/dqd rows are M itself, row-major: one copy.
 * The arrays never overlap (tape.h says so of tp_lagrange's). */
TP_INLINE bool store_block_at(const double *restrict H, int n, int c0,
                              int pc, bool timed,
                              const double *restrict qd, double *restrict M,
                              double *restrict h)
{
    const size_t un = (size_t)n, upc = (size_t)pc;
    uint64_t bad = 0;
    size_t i, k;
    if (M && pc == n) {
        const double *r = H + un * un;
        for (i = 0; i < un * un; i++) {
            M[i] = r[i];
            TP_NONFINITE_OR(bad, r[i]);
        }
    } else if (M) {
        for (i = 0; i < un; i++) {
            const double *r = H + (un + i) * upc;
            double *Mi = M + i * un + (size_t)c0;
            for (k = 0; k < upc; k++) {
                Mi[k] = r[k];
                TP_NONFINITE_OR(bad, r[k]);
            }
        }
    }
    if (h) {
        /* h_c = sum_j d2L/(dq_j dqd_c) qd_j (+ d2L/(dt dqd_c)), summed
         * from 0 over j in order, row by row: contiguous columns */
        double *hc = h + c0;
        for (k = 0; k < upc; k++)
            hc[k] = 0.0;
        for (i = 0; i < un; i++) {
            const double *r = H + i * upc, qi = qd[i];
            for (k = 0; k < upc; k++)
                hc[k] += r[k] * qi;
        }
        if (timed)
            for (k = 0; k < upc; k++)
                hc[k] += H[2 * un * upc + k];
        for (k = 0; k < upc; k++)
            TP_NONFINITE_OR(bad, hc[k]);
    }
    return TP_ALL_FINITE(bad);
}

/* The whole block of a small model (n <= 6, one chunk) with n the
 * constant k, so that the loops above unroll: at n = 2 the general loops
 * took 160 instructions (callgrind) for 4 copies and 2 dot products. The
 * arithmetic is the same, in the same order. One function per size,
 * never inlined, so that each saves only the registers it uses, called
 * through a table. */
#define TP_STORE_BLOCK_OF_SIZE(k)                                           \
    TP_NOINLINE static bool store_block_##k(const double *H, bool timed,   \
                                            const double *qd, double *M,   \
                                            double *h)                      \
    {                                                                       \
        return store_block_at(H, k, 0, k, timed, qd, M, h);                 \
    }
TP_STORE_BLOCK_OF_SIZE(1)
TP_STORE_BLOCK_OF_SIZE(2)
TP_STORE_BLOCK_OF_SIZE(3)
TP_STORE_BLOCK_OF_SIZE(4)
TP_STORE_BLOCK_OF_SIZE(5)
TP_STORE_BLOCK_OF_SIZE(6)

/* The block of larger models (n > TP_SIZES_UNROLLED) and of chunks,
 * with, like the sweeps, an AVX2 clone beside the generic code: 4-wide
 * vectors for the copy of M with its check and for h's sums, which
 * vectorize across columns, so that each column's sum keeps its order
 * (no FMA: both clones round alike). */
TP_VECTOR_CLONES TP_NOINLINE static bool
store_block_n(const double *H, int n, int c0, int pc, bool timed,
              const double *qd, double *M, double *h)
{
    return store_block_at(H, n, c0, pc, timed, qd, M, h);
}

/* The functions of each size, indexed by n. */
static bool (*const store_block_of_size[])(const double *H, bool timed,
                                           const double *qd, double *M,
                                           double *h) = {
    NULL,          store_block_1, store_block_2, store_block_3,
    store_block_4, store_block_5, store_block_6};
#define TP_SIZES_UNROLLED 6

TP_INLINE bool store_block(const double *H, int n, int c0, int pc,
                           bool timed, const double *qd, double *M,
                           double *h)
{
    if (pc == n && n >= 1 && n <= TP_SIZES_UNROLLED)
        return store_block_of_size[n](H, timed, qd, M, h);
    return store_block_n(H, n, c0, pc, timed, qd, M, h);
}

int tp_lagrange(tp_ws *ws, const double *x, int out, double *L, double *dLdq,
                double *M, double *h)
{
    return tp_lagrange_t(ws, x, out, L, dLdq, NULL, M, h);
}

/* With 2n + 1 independents the last is the time t: it is never seeded (the
 * n directions stay on qd), but the reverse sweep reaches it anyway, so
 * row 2n of the Hessian columns holds d2L/(dt dqd_c) and entry 2n of the
 * gradient dL/dt at no extra cost. */
/* L, dL/dq and dL/dt into those of L, dLdq and dLdt that are not NULL,
 * from the last sweeps' values and gradient; the TP_NONFINITE_OR of what
 * was written. */
TP_INLINE uint64_t lagrange_values(const tp_ws *ws, int out, int n,
                                   bool timed, double *L, double *dLdq,
                                   double *dLdt)
{
    const tp_tape *T = ws->t;
    uint64_t bad = 0;
    if (L) {
        *L = ws->v[T->out_slot[out]];
        TP_NONFINITE_OR(bad, *L);
    }
    if (dLdq) {
        int i;
        for (i = 0; i < n; i++) {
            dLdq[i] = ws->g[i];
            TP_NONFINITE_OR(bad, dLdq[i]);
        }
    }
    if (dLdt) {
        *dLdt = timed ? ws->g[2 * n] : 0.0;
        TP_NONFINITE_OR(bad, *dLdt);
    }
    return bad;
}

/* tp_lagrange_t by the interpreter's sweeps (its arguments checked, and
 * n, timed as it found them), out of line: the compiled route's call
 * then saves only the registers it uses itself. */
TP_NOINLINE static int lagrange_swept(tp_ws *ws, const double *x, int out,
                                      int n, bool timed, double *L,
                                      double *dLdq, double *dLdt, double *M,
                                      double *h)
{
    const tp_tape *T = ws->t;
    const double *qd = x + n;
    const double *w = unit_weights(ws, out);
    const uint32_t end = end_of_unit(T, out);
    int c0;
    bool ok = true; /* every result finite */
    /* h is not cleared first: each chunk's store_block sets its entries */
    if (n == 0 || (!M && !h)) {
        tp__fwd0(ws, x, end);
        tp__rev1(ws, w, end, ws->g);
    }
    /* more than one vector of rates in one chunk: each row swept over
     * the columns that can be non-zero in it alone (ranges.c) */
    const bool ranged = n > TP_LANES && n <= ws->max_dirs && (M || h);
    if (ranged) {
        const unsigned mask = tp__unit_seed_mask(T, n, n);
        if (ws->range_out != out || ws->range_n != n)
            tp__lagrange_ranges(ws, out, n, end);
        if (tp__strips_pay(ws, n)) {
            tp__lagrange_strips(ws, x, w, n, mask, end, ws->strip_w, ws->g,
                                ws->hs);
        } else {
            tp__fwd1_ranged(ws, x, n, mask, end);
            tp__rev2_ranged(ws, w, n, mask, end, ws->g, ws->hs);
        }
        ok &= store_block(ws->hs, n, 0, n, timed, qd, M, h);
    }
    for (c0 = 0; c0 < n && (M || h) && !ranged; c0 += ws->max_dirs) {
        const int pc = n - c0 < ws->max_dirs ? n - c0 : ws->max_dirs;
        const unsigned mask = tp__unit_seed_mask(T, pc, n + c0);
        tp__fwd1(ws, x, pc, NULL, 0, n + c0, mask, end);
        tp__rev2(ws, w, pc, mask, end, c0 == 0 ? ws->g : NULL, ws->hs,
                 (size_t)pc);
        ok &= store_block(ws->hs, n, c0, pc, timed, qd, M, h);
    }
    if (!ok || !TP_ALL_FINITE(
                   lagrange_values(ws, out, n, timed, L, dLdq, dLdt)))
        return TP_WARN_NONFINITE;
    return TP_OK;
}

int tp_lagrange_t(tp_ws *ws, const double *x, int out, double *L,
                  double *dLdq, double *dLdt, double *M, double *h)
{
    int st = begin(ws, x, "tp_lagrange");
    const tp_tape *T;
    const tp_compiled *cc;
    int n;
    bool timed;
    if (st)
        return st;
    T = ws->t;
    if ((st = check_out(ws, out, "tp_lagrange")) != TP_OK)
        return st;
    n = (int)T->n_indep / 2;
    timed = T->n_indep % 2 != 0;
    /* compiled: the whole block in one call (lcount = n <= max_dirs), no
     * weights, ends or seed masks to work out */
    cc = ws->cc;
    if (!cc || !cc->lagrange || cc->lout != out || cc->lfirst != n ||
        n > ws->max_dirs || (!M && !h))
        return lagrange_swept(ws, x, out, n, timed, L, dLdq, dLdt, M, h);
    tp__lagrange_compiled(ws, x, ws->g, ws->hs);
    if (!store_block(ws->hs, n, 0, n, timed, x + n, M, h) ||
        !TP_ALL_FINITE(lagrange_values(ws, out, n, timed, L, dLdq, dLdt)))
        return TP_WARN_NONFINITE;
    return TP_OK;
}
