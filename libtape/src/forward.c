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
 * Invariant (ws->tan_mask, ws->tan_cols): every row of an op with
 * (dep & tan_mask) == 0 is zero in its first tan_cols columns and beyond.
 * Changing the mask zeroes the rows that leave the active set.
 */
#include <string.h>

#include "sweep.h"

unsigned tp__seed_mask(const tp_tape *T, int p, const double *S, size_t lds,
                       int first)
{
    unsigned mask = 0;
    uint32_t i;
    int k;
    for (i = 0; i < T->n_indep; i++) {
        bool seeded = false;
        if (S) {
            for (k = 0; k < p && !seeded; k++)
                seeded = S[i * lds + (size_t)k] != 0.0;
        } else {
            seeded = (int)i >= first && (int)i < first + p;
        }
        if (seeded)
            mask |= 1u << T->group[i];
    }
    return mask;
}

void tp__ensure_passive(tp_ws *ws)
{
    const tp_tape *T = ws->t;
    uint32_t i;
    if (!ws->passive_stale)
        return;
    memcpy(ws->v + T->n_indep, ws->param, T->n_param * sizeof(double));
    for (i = T->n_indep + T->n_param; i < T->first_active; i++)
        ws->v[i] = tp__value_at(T, ws->v, ws->aux, i, T->opc[i]);
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
    double *v = ws->v, *aux = ws->aux;
    uint32_t i;
    load_leaves(ws, x);
    for (i = T->first_active; i < end; i++)
        v[i] = tp__value_at(T, v, aux, i, opc[i]);
}

/* Row kernels: r is the row being written, a and b rows of operands (which
 * precede r, so never alias it; a and b may be the same row). pr is a
 * multiple of TP_LANES, so FOR_LANES compiles to straight vector code. */
static inline void row_copy(double *restrict r, const double *restrict a,
                            int pr)
{
    FOR_LANES(k, pr) r[k] = a[k];
}

static inline void row_scale(double *restrict r, const double *restrict a,
                             double fa, int pr)
{
    FOR_LANES(k, pr) r[k] = fa * a[k];
}

static inline void row_add(double *restrict r, const double *restrict a,
                           const double *restrict b, int pr)
{
    FOR_LANES(k, pr) r[k] = a[k] + b[k];
}

static inline void row_sub(double *restrict r, const double *restrict a,
                           const double *restrict b, int pr)
{
    FOR_LANES(k, pr) r[k] = a[k] - b[k];
}

static inline void row_comb(double *restrict r, const double *restrict a,
                            const double *restrict b, double fa, double fb,
                            int pr)
{
    FOR_LANES(k, pr) r[k] = fa * a[k] + fb * b[k];
}

TP_VECTOR_CLONES
void tp__fwd1(tp_ws *ws, const double *x, int p, const double *S, size_t lds,
              int first, unsigned mask, uint32_t end)
{
    const tp_tape *T = ws->t;
    const uint8_t *opc = T->opc, *dep = T->dep;
    const uint32_t *a0 = T->a0, *a1 = T->a1;
    const size_t P = (size_t)ws->P;
    const int pr = tp__lanes(p); /* columns swept; those past p stay 0 */
    double *v = ws->v, *aux = ws->aux, *tan = ws->tan;
    uint32_t i;

    prepare_tangents(ws, mask, pr);
    load_leaves(ws, x);
    for (i = 0; i < T->n_indep; i++) {
        double *r = tan + i * P;
        if (!(dep[i] & mask))
            continue;
        memset(r, 0, (size_t)pr * sizeof(double));
        if (S)
            memcpy(r, S + i * lds, (size_t)p * sizeof(double));
        else if ((int)i >= first && (int)i < first + p)
            r[(int)i - first] = 1.0;
    }
    /* One switch per op computes the value and, if the op depends on a
     * seeded group, its tangent row; common ops are written out. */
    for (i = T->first_active; i < end; i++) {
        const unsigned op = opc[i], fl = dep[i];
        const uint32_t u = a0[i], t = a1[i];
        const bool active = fl & mask;
        double *r = tan + i * P;
        const double *ru = tan + u * P;
        tp_partials d;
        switch (op) {
        case TP_OP_ADD:
            v[i] = v[u] + v[t];
            if (!active)
                break;
            if (fl & TP_DEP_TPASSIVE)
                row_copy(r, ru, pr);
            else if (fl & TP_DEP_UPASSIVE)
                row_copy(r, tan + t * P, pr);
            else
                row_add(r, ru, tan + t * P, pr);
            break;
        case TP_OP_SUB:
            v[i] = v[u] - v[t];
            if (!active)
                break;
            if (fl & TP_DEP_TPASSIVE)
                row_copy(r, ru, pr);
            else if (fl & TP_DEP_UPASSIVE)
                row_scale(r, tan + t * P, -1.0, pr);
            else
                row_sub(r, ru, tan + t * P, pr);
            break;
        case TP_OP_MUL:
            v[i] = v[u] * v[t];
            if (!active)
                break;
            if (fl & TP_DEP_TPASSIVE)
                row_scale(r, ru, v[t], pr);
            else if (fl & TP_DEP_UPASSIVE)
                row_scale(r, tan + t * P, v[u], pr);
            else
                row_comb(r, ru, tan + t * P, v[t], v[u], pr);
            break;
        case TP_OP_NEG:
            v[i] = -v[u];
            if (active)
                row_scale(r, ru, -1.0, pr);
            break;
        case TP_OP_ADDC:
            v[i] = v[u] + T->konst[t];
            if (active)
                row_copy(r, ru, pr);
            break;
        case TP_OP_MULC:
            v[i] = T->konst[t] * v[u];
            if (active)
                row_scale(r, ru, T->konst[t], pr);
            break;
        case TP_OP_SQR:
            v[i] = v[u] * v[u];
            if (active)
                row_scale(r, ru, 2.0 * v[u], pr);
            break;
        case TP_OP_SIN: /* fu = cos u, left in aux */
            v[i] = tp__value_at(T, v, aux, i, op);
            if (active)
                row_scale(r, ru, aux[i], pr);
            break;
        case TP_OP_COS: /* fu = -sin u */
            v[i] = tp__value_at(T, v, aux, i, op);
            if (active)
                row_scale(r, ru, -aux[i], pr);
            break;
        default:
            v[i] = tp__value_at(T, v, aux, i, op);
            if (!active)
                break; /* structurally zero tangent; row stays zero */
            tp__partials_at(T, v, aux, i, op, &d);
            if (tp__opinfo[op].kind == TP_KIND_BINARY)
                row_comb(r, ru, tan + t * P, d.fu, d.ft, pr);
            else
                row_scale(r, ru, d.fu, pr);
            break;
        }
    }
}

void tp__taylor2(tp_ws *ws, const double *x, const double *dir, uint32_t end)
{
    const tp_tape *T = ws->t;
    const uint8_t *opc = T->opc;
    const uint32_t *a0 = T->a0, *a1 = T->a1;
    double *v = ws->v, *aux = ws->aux, *d1 = ws->d1, *d2 = ws->d2;
    uint32_t i;
    /* d1 and d2 of parameters and passive ops are never written: zero */
    load_leaves(ws, x);
    for (i = 0; i < T->n_indep; i++) {
        d1[i] = dir[i];
        d2[i] = 0.0;
    }
    for (i = T->first_active; i < end; i++) {
        const unsigned op = opc[i];
        const uint32_t u = a0[i];
        tp_partials d;
        v[i] = tp__value_at(T, v, aux, i, op);
        tp__partials_at(T, v, aux, i, op, &d);
        if (tp__opinfo[op].kind == TP_KIND_BINARY) {
            const uint32_t t = a1[i];
            d1[i] = d.fu * d1[u] + d.ft * d1[t];
            d2[i] = d.fu * d2[u] + d.ft * d2[t] +
                    d.fuu * d1[u] * d1[u] + 2.0 * d.fut * d1[u] * d1[t] +
                    d.ftt * d1[t] * d1[t];
        } else {
            d1[i] = d.fu * d1[u];
            d2[i] = d.fu * d2[u] + d.fuu * d1[u] * d1[u];
        }
    }
}
