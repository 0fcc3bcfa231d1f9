/* forward.c - forward sweeps: zero order, first order with p directions at
 * once, and univariate second-order Taylor.
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

/* Establish the invariant for a sweep with this mask and p columns. */
static void prepare_tangents(tp_ws *ws, unsigned mask, int p)
{
    const tp_tape *T = ws->t;
    const size_t P = (size_t)ws->P;
    uint32_t i;
    if (mask != ws->tan_mask && ws->tan_cols > 0) {
        for (i = 0; i < T->n_ops; i++) {
            unsigned d = T->dep[i];
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
    const tp_tape *T = ws->t;
    memcpy(ws->v, x, T->n_indep * sizeof(double));
    memcpy(ws->v + T->n_indep, ws->param, T->n_param * sizeof(double));
}

void tp__fwd0(tp_ws *ws, const double *x, uint32_t end)
{
    const tp_tape *T = ws->t;
    const uint8_t *opc = T->opc;
    double *v = ws->v, *aux = ws->aux;
    uint32_t i;
    load_leaves(ws, x);
    for (i = T->n_indep + T->n_param; i < end; i++)
        v[i] = tp__value_at(T, v, aux, i, opc[i]);
}

void tp__fwd1(tp_ws *ws, const double *x, int p, const double *S, size_t lds,
              int first, unsigned mask, uint32_t end)
{
    const tp_tape *T = ws->t;
    const uint8_t *opc = T->opc, *dep = T->dep;
    const uint32_t *a0 = T->a0, *a1 = T->a1;
    const size_t P = (size_t)ws->P;
    double *v = ws->v, *aux = ws->aux, *tan = ws->tan;
    uint32_t i;
    int k;

    prepare_tangents(ws, mask, p);
    load_leaves(ws, x);
    for (i = 0; i < T->n_indep; i++) {
        double *r = tan + i * P;
        if (!(dep[i] & mask))
            continue;
        if (S) {
            memcpy(r, S + i * lds, (size_t)p * sizeof(double));
        } else {
            memset(r, 0, (size_t)p * sizeof(double));
            if ((int)i >= first && (int)i < first + p)
                r[(int)i - first] = 1.0;
        }
    }
    for (i = T->n_indep + T->n_param; i < end; i++) {
        const unsigned op = opc[i];
        double *r, *ru, *rt;
        tp_partials d;
        v[i] = tp__value_at(T, v, aux, i, op);
        if (!(dep[i] & mask))
            continue; /* structurally zero tangent; row stays zero */
        r = tan + i * P;
        ru = tan + a0[i] * P;
        switch (op) {
        case TP_OP_ADD:
            rt = tan + a1[i] * P;
            for (k = 0; k < p; k++)
                r[k] = ru[k] + rt[k];
            break;
        case TP_OP_SUB:
            rt = tan + a1[i] * P;
            for (k = 0; k < p; k++)
                r[k] = ru[k] - rt[k];
            break;
        case TP_OP_MUL: {
            const double vu = v[a0[i]], vt = v[a1[i]];
            rt = tan + a1[i] * P;
            for (k = 0; k < p; k++)
                r[k] = vt * ru[k] + vu * rt[k];
            break;
        }
        case TP_OP_NEG:
            for (k = 0; k < p; k++)
                r[k] = -ru[k];
            break;
        case TP_OP_ADDC:
            memcpy(r, ru, (size_t)p * sizeof(double));
            break;
        default:
            tp__partials_at(T, v, aux, i, op, &d);
            if (tp__opinfo[op].kind == TP_KIND_BINARY) {
                rt = tan + a1[i] * P;
                for (k = 0; k < p; k++)
                    r[k] = d.fu * ru[k] + d.ft * rt[k];
            } else {
                for (k = 0; k < p; k++)
                    r[k] = d.fu * ru[k];
            }
            break;
        }
    }
}

void tp__taylor2(tp_ws *ws, const double *x, const double *dir, uint32_t end)
{
    const tp_tape *T = ws->t;
    const uint8_t *opc = T->opc;
    const uint32_t *a0 = T->a0, *a1 = T->a1;
    const uint32_t n_in = T->n_indep + T->n_param;
    double *v = ws->v, *aux = ws->aux, *d1 = ws->d1, *d2 = ws->d2;
    uint32_t i;
    load_leaves(ws, x);
    for (i = 0; i < n_in; i++) {
        d1[i] = i < T->n_indep ? dir[i] : 0.0;
        d2[i] = 0.0;
    }
    for (i = n_in; i < end; i++) {
        const unsigned op = opc[i];
        const uint32_t u = a0[i];
        tp_partials d;
        v[i] = tp__value_at(T, v, aux, i, op);
        if (op == TP_OP_CONST || !T->dep[i]) {
            d1[i] = d2[i] = 0.0;
            continue;
        }
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
