/* strips.c - the Lagrange block's ranged sweeps (forward.c's
 * tp__fwd1_ranged, reverse.c's tp__rev2_ranged) run in strips of columns,
 * so that a strip's tangent and adjoint-tangent rows stay in the caches
 * between its forward and its reverse sweep.
 *
 * With all n directions at once every op's rows are swept over its whole
 * range, rows n doubles apart: at 200 links 5,581 ops, 18 MB of tangent
 * and adjoint-tangent rows through memory per call (50 MB at 400). Here a
 * strip's rows are those of the workspace's strip arrays (ws->stan,
 * ws->satan: one row of strip_w doubles per op, contiguous; rows n apart
 * in the full arrays put every row of a strip on a page of its own).
 * The first strip sweeps every op (values, first-order adjoints and the
 * strip's columns, as the ranged sweeps do), keeping each op's adjoint
 * as it is read (ws->abar); every later strip sweeps only the ops whose
 * range meets it, each reading its recorded adjoint, over the columns its
 * range shares with the strip.
 *
 * Each column's arithmetic is that of the unstripped sweep: the row
 * kernels work column by column, the scalars they use (values, adjoints,
 * the second-order test) are the same, and a skipped op or column is one
 * the ranged sweep leaves alone or adds only exact zeros to an
 * adjoint-tangent entry (entries are +0 or non-zero: unchanged). An op
 * recomputes its value in a later strip from the same operands: the same
 * bits. In a later strip the reverse kernels still accumulate adjoints;
 * each op's slot is overwritten with its recorded adjoint just before it
 * is read, so those sums are discarded (the independents' with them: the
 * gradient is taken after the first strip). Every op a visited op writes
 * into is visited later in the strip (an operand's range holds its
 * readers'), so the slots left non-zero are the independents', zeroed at
 * the end. The strip rows are zero between strips: each op's tangent
 * columns are cleared once its readers have read them, the reverse
 * kernels clear the adjoint-tangent rows they consume, and the
 * independents' rows are cleared after their columns are copied out.
 * The full tangent arrays (ws->tan, ws->atan) are not touched.
 */
#include <string.h>

#include "sweep.h"

/* Columns per strip, and the fewest rates that sweep in strips, as
 * measured (section 1 of docs/benchmarks.md, "Strips at 200 and 400
 * links"). On the sweeps alone (a 400-link pendulum chain, 14,389 ops)
 * strips of 64 were 2x faster than the unstripped sweep, of 32 and 48
 * slower than 64, of 128 slower again (rows of 512 bytes: 8 to a page, a
 * strip's rows of the ops it meets about the second-level cache's size).
 * In bench-rhs strips of 64 paid at 200 links at every load, at 400 on
 * a quiet machine only (at load 11 to 16, the last-level cache shared
 * with the other processes, 400 links were about 15 % slower), and cost
 * 20 to 30 % at 100, where the full rows still fit the caches and each
 * strip's pass over the ops costs more than it saves; sizes from 101 to
 * 199 were not measured and stay unstripped. */
#define STRIP_W 64
#define STRIPS_FROM 200

int tp__strip_width(int max_dirs)
{
    return max_dirs >= STRIPS_FROM ? STRIP_W : 0;
}

bool tp__strips_pay(const tp_ws *ws, int n)
{
    return ws->strip_w > 0 && n >= STRIPS_FROM;
}

/* The vectors [*lo, *hi) range r (a pair) shares with strip [s0, s1);
 * false when none. */
static inline bool meet(const uint32_t *r, uint32_t s0, uint32_t s1,
                        uint32_t *lo, uint32_t *hi)
{
    *lo = r[0] > s0 ? r[0] : s0;
    *hi = r[1] < s1 ? r[1] : s1;
    return *lo < *hi;
}

TP_VECTOR_CLONES
void tp__lagrange_strips(tp_ws *ws, const double *x, const double *w, int n,
                         unsigned mask, uint32_t end, int width, double *g,
                         double *HS)
{
    const tp_tape *T = ws->t;
    const tp_oprec *rec = ws->rec;
    const uint32_t *fr = ws->frange, *rr = ws->rrange;
    const size_t W = (size_t)ws->strip_w; /* row stride of the strips */
    const uint32_t nv = (uint32_t)tp__lanes(n) / TP_LANES;
    /* at least a vector: a narrower width would never end */
    const uint32_t sv = width >= TP_LANES ? (uint32_t)(width / TP_LANES) : 1;
    double *st = ws->stan, *sa = ws->satan, *adj = ws->adj;
    double *abar = ws->abar;
    tp_kx k = tp__kx(ws, 0, mask);
    uint32_t s0, i, lo, hi;
    int c;

    k.P = W;
    memcpy(ws->v, x, T->n_indep * sizeof(double));
    tp__ensure_passive(ws);
    tp__rev2_ranged_seed(ws, w);
    for (s0 = 0; s0 < nv; s0 += sv) {
        const uint32_t s1 = s0 + sv < nv ? s0 + sv : nv;
        const int c0 = TP_LANES * (int)s0;
        const int c1 = TP_LANES * (int)s1 < n ? TP_LANES * (int)s1 : n;
        const bool first = s0 == 0;
        /* column c of the strip is column c - c0 of its rows */
        for (c = c0; c < c1; c++)
            st[(size_t)(n + c) * W + (size_t)(c - c0)] = 1.0;
        for (i = T->first_active; i < end; i++) {
            if (!meet(fr + 2 * i, s0, s1, &lo, &hi)) {
                if (!first) /* its value is there from the first strip */
                    continue;
                lo = hi = s0;
            }
            k.tan = st + TP_LANES * (size_t)(lo - s0);
            k.pr = TP_LANES * (int)(hi - lo);
            tp__k_fwd1(&k, i, rec[i].op, rec[i].fl, rec[i].u, rec[i].t);
        }
        for (i = end; i-- > T->first_active;) {
            uint32_t flo, fhi;
            const bool met = meet(rr + 2 * i, s0, s1, &lo, &hi);
            if (first || met) {
                if (first)
                    abar[i] = adj[i];
                else
                    adj[i] = abar[i];
                if (!met)
                    lo = hi = s0;
                k.tan = st + TP_LANES * (size_t)(lo - s0);
                k.atan = sa + TP_LANES * (size_t)(lo - s0);
                k.pr = TP_LANES * (int)(hi - lo);
                tp__k_rev2(&k, i, rec[i].op, rec[i].fl, rec[i].u, rec[i].t);
            }
            /* its readers (all above it) have read its tangent columns
             * (a loop: most are a vector or two, short for a call) */
            if (meet(fr + 2 * i, s0, s1, &flo, &fhi)) {
                double *r = st + i * W + TP_LANES * (size_t)(flo - s0);
                FOR_LANES(j, TP_LANES * (int)(fhi - flo))
                    r[j] = 0.0;
            }
        }
        if (first && g)
            memcpy(g, adj, T->n_indep * sizeof(double));
        for (c = c0; c < c1; c++)
            st[(size_t)(n + c) * W + (size_t)(c - c0)] = 0.0;
        for (i = 0; i < T->n_indep; i++) {
            if (HS)
                memcpy(HS + i * (size_t)n + c0, sa + i * W,
                       (size_t)(c1 - c0) * sizeof(double));
            memset(sa + i * W, 0,
                   TP_LANES * (size_t)(s1 - s0) * sizeof(double));
        }
    }
    for (i = 0; i < T->n_indep; i++) {
        adj[i] = 0.0;
        ws->anz[i] = 0;
    }
    tp__clear_passive_seeds(ws);
}
