/* forward.c - forward sweeps: zero order, first order with p directions at
 * once, and univariate second-order Taylor.
 *
 * Values: the leaves are loaded from x and the workspace's parameters; the
 * passive prefix (constants and functions of parameters) is recomputed only
 * after a parameter changed; a sweep runs from first_active to end.
 *
 * Tangents are stored row by row: row i (P doubles, P = max_dirs) holds the
 * p directional derivatives of slot i, so the inner loops run over
 * contiguous directions. An op whose dependency mask misses every seeded
 * group has a structurally zero tangent: the sweep skips it and its row is
 * kept zero (the invariant below), so consumers read zeros without a test.
 *
 * The first-order sweeps (and reverse.c's second-order ones) read each op
 * from the workspace's per-op records (tp_oprec: code, dependency byte
 * and operands side by side) rather than from the tape's four arrays, and keep the
 * tape's first active slot in a local: with fewer base pointers live the
 * loop spills less (7 % fewer instructions per right-hand side at 2 and
 * 10 links).
 *
 * Invariant (ws->tan_mask, ws->tan_cols): every row of an op with
 * (dep & tan_mask) == 0 is zero in its first tan_cols columns and beyond.
 * Changing the mask zeroes the rows that leave the active set.
 */
#include <string.h>

#include "sweep.h"
#include "sweep_one.h"

unsigned tp__seed_mask(const tp_tape *T, int p, const double *S, size_t lds,
                       int first)
{
    unsigned mask = 0;
    uint32_t i;
    int k;
    if (!S)
        return tp__unit_seed_mask(T, p, first);
    for (i = 0; i < T->n_indep; i++) {
        bool seeded = false;
        for (k = 0; k < p && !seeded; k++)
            seeded = S[i * lds + (size_t)k] != 0.0;
        if (seeded)
            mask |= 1u << T->group[i];
    }
    return mask;
}

void tp__ensure_passive(tp_ws *ws)
{
    const tp_tape *T = ws->t;
    const tp_kx kx = tp__kx(ws, 0, 0);
    uint32_t i;
    if (!ws->passive_stale)
        return;
    memcpy(ws->v + T->n_indep, ws->param, T->n_param * sizeof(double));
    for (i = T->n_indep + T->n_param; i < T->first_active; i++)
        tp__k_value(&kx, i, T->opc[i], 0, T->a0[i], T->a1[i]);
    ws->passive_stale = false;
}

/* Establish the invariant for a sweep with this mask and p columns. */
static void prepare_tangents(tp_ws *ws, unsigned mask, int p)
{
    const tp_tape *T = ws->t;
    const size_t P = (size_t)ws->P;
    uint32_t i;
    if (mask != ws->tan_mask && ws->tan_cols > 0) {
        for (i = 0; i < T->n_ops; i++) {
            unsigned d = T->dep[i] & TP_DEP_GROUPS;
            if ((d & ws->tan_mask) && !(d & mask))
                memset(ws->tan + i * P, 0,
                       (size_t)ws->tan_cols * sizeof(double));
        }
    }
    ws->tan_mask = mask;
    if (p > ws->tan_cols)
        ws->tan_cols = p;
    ws->tan_ranged = false; /* a full sweep may write any column */
}

static void load_leaves(tp_ws *ws, const double *x)
{
    memcpy(ws->v, x, ws->t->n_indep * sizeof(double));
    tp__ensure_passive(ws);
}

void tp__fwd0(tp_ws *ws, const double *x, uint32_t end)
{
    const tp_tape *T = ws->t;
    const uint8_t *opc = T->opc;
    const uint32_t *a0 = T->a0, *a1 = T->a1;
    const tp_kx kx = tp__kx(ws, 0, 0);
    uint32_t i;
    load_leaves(ws, x);
    if (ws->cc && ws->cc->fwd0) {
        ws->cc->fwd0(&kx, end);
        return;
    }
    for (i = T->first_active; i < end; i++)
        tp__k_value(&kx, i, opc[i], 0, a0[i], a1[i]);
}

TP_VECTOR_CLONES
void tp__fwd1(tp_ws *ws, const double *x, int p, const double *S, size_t lds,
              int first, unsigned mask, uint32_t end)
{
    const tp_tape *T = ws->t;
    const uint8_t *dep = T->dep;
    const tp_oprec *rec = ws->rec;
    const uint32_t fa = T->first_active;
    const size_t P = (size_t)ws->P;
    const int pr = tp__lanes(p); /* columns swept; those past p stay 0 */
    const tp_kx kx = tp__kx(ws, pr, mask);
    double *tan = ws->tan;
    uint32_t i;

    prepare_tangents(ws, mask, pr);
    load_leaves(ws, x);
    for (i = 0; i < T->n_indep; i++) {
        double *r = tan + i * P;
        if (!(dep[i] & mask))
            continue;
        /* one or two vectors of columns, the common widths: a constant
         * size, so the clearing is a few stores, not a call */
        if (pr == TP_LANES)
            memset(r, 0, TP_LANES * sizeof(double));
        else if (pr == 2 * TP_LANES)
            memset(r, 0, 2 * TP_LANES * sizeof(double));
        else
            memset(r, 0, (size_t)pr * sizeof(double));
        if (S)
            memcpy(r, S + i * lds, (size_t)p * sizeof(double));
        else if ((int)i >= first && (int)i < first + p)
            r[(int)i - first] = 1.0;
    }
    /* One switch per op computes the value and, if the op depends on a
     * seeded group, its tangent row. At one or two vectors of columns (up
     * to eight coordinates, where most models live) the width is a
     * constant of its own loop, which drops the per-row loop control. At
     * one vector the rows are vector operations (sweep_one.h), and with
     * at most four directions in the workspace P is a constant too: no
     * multiplications for the row addresses, and a register freed. */
#if TP_ONE_VECTOR
    if (pr == TP_LANES && P == TP_LANES) {
        tp_kx k1 = kx;
        k1.pr = TP_LANES;
        k1.P = TP_LANES;
        for (i = fa; i < end; i++)
            tp__one_fwd1(&k1, i, rec[i].op, rec[i].fl, rec[i].u, rec[i].t);
        return;
    }
    if (pr == TP_LANES) {
        tp_kx k1 = kx;
        k1.pr = TP_LANES;
        for (i = fa; i < end; i++)
            tp__one_fwd1(&k1, i, rec[i].op, rec[i].fl, rec[i].u, rec[i].t);
        return;
    }
#endif
    if (pr == TP_LANES) {
        tp_kx k1 = kx;
        k1.pr = TP_LANES;
        for (i = fa; i < end; i++)
            tp__k_fwd1(&k1, i, rec[i].op, rec[i].fl, rec[i].u, rec[i].t);
    } else if (pr == 2 * TP_LANES) {
        tp_kx k2 = kx;
        k2.pr = 2 * TP_LANES;
        for (i = fa; i < end; i++)
            tp__k_fwd1(&k2, i, rec[i].op, rec[i].fl, rec[i].u, rec[i].t);
    } else {
        for (i = fa; i < end; i++)
            tp__k_fwd1(&kx, i, rec[i].op, rec[i].fl, rec[i].u, rec[i].t);
    }
}

/* The start of tp__fwd1_ranged, also that of its sweeps in strips of
 * columns (strips.c): the invariant for mask, the rows cleared when
 * tan_ranged does not hold, the unit seeds on independents n .. 2n-1 and
 * the leaves. */
void tp__fwd1_ranged_seed(tp_ws *ws, const double *x, int n, unsigned mask)
{
    const tp_tape *T = ws->t;
    const size_t P = (size_t)ws->P;
    const bool ranged = ws->tan_ranged;
    double *tan = ws->tan;
    uint32_t i;

    prepare_tangents(ws, mask, tp__lanes(n));
    if (!ranged)
        for (i = 0; i < T->n_ops; i++)
            if (T->dep[i] & mask)
                memset(tan + i * P, 0,
                       (size_t)ws->tan_cols * sizeof(double));
    ws->tan_ranged = true;
    load_leaves(ws, x);
    for (i = 0; i < (uint32_t)n; i++)
        tan[((size_t)n + i) * P + i] = 1.0;
}

/* tp__fwd1 with unit directions on independents n .. 2n-1, each op's
 * row swept over its range alone (ranges.c): the columns outside it are
 * zero, kept so by tan_ranged (cleared once when it does not hold). */
TP_VECTOR_CLONES
void tp__fwd1_ranged(tp_ws *ws, const double *x, int n, unsigned mask,
                     uint32_t end)
{
    const tp_tape *T = ws->t;
    const tp_oprec *rec = ws->rec;
    const uint32_t fa = T->first_active;
    const uint32_t *fr = ws->frange;
    tp_kx k = tp__kx(ws, 0, mask);
    double *tan = ws->tan;
    uint32_t i;

    tp__fwd1_ranged_seed(ws, x, n, mask);
    for (i = fa; i < end; i++) {
        k.tan = tan + TP_LANES * (size_t)fr[2 * i];
        k.pr = TP_LANES * (int)(fr[2 * i + 1] - fr[2 * i]);
        tp__k_fwd1(&k, i, rec[i].op, rec[i].fl, rec[i].u, rec[i].t);
    }
}

void tp__lagrange_compiled(tp_ws *ws, const double *x, double *g, double *H)
{
    prepare_tangents(ws, ws->cc->lmask, ws->P);
    load_leaves(ws, x);
    ws->cc->lagrange(ws->v, ws->aux, ws->tan, ws->cat, ws->cadj, g, H);
}

void tp__jacobian_compiled(tp_ws *ws, const double *x)
{
    prepare_tangents(ws, ws->cc->jmask, ws->P);
    load_leaves(ws, x);
    ws->cc->jacobian(ws->v, ws->aux, ws->tan);
}

void tp__taylor2(tp_ws *ws, const double *x, const double *dir, uint32_t end)
{
    const tp_tape *T = ws->t;
    const uint8_t *opc = T->opc;
    const uint32_t *a0 = T->a0, *a1 = T->a1;
    const tp_kx kx = tp__kx(ws, 0, 0);
    double *d1 = ws->d1, *d2 = ws->d2;
    uint32_t i;
    /* d1 and d2 of parameters and passive ops are never written: zero */
    load_leaves(ws, x);
    if (ws->cc && ws->cc->taylor2) {
        ws->cc->taylor2(ws->v, ws->aux, d1, d2, dir);
        return;
    }
    for (i = 0; i < T->n_indep; i++) {
        d1[i] = dir[i];
        d2[i] = 0.0;
    }
    for (i = T->first_active; i < end; i++)
        tp__k_taylor2(&kx, i, opc[i], 0, a0[i], a1[i]);
}
