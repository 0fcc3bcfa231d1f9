/* reference.c - a plain reference interpreter of a tape, for tests of the
 * fast sweeps: one direction at a time, the generic partials of every op,
 * no dependency skipping, no buffer reuse and no zero invariants. Slow and
 * simple on purpose; it allocates its own buffers with malloc. */
#include <stdlib.h>
#include <string.h>

#include "op_math.h"
#include "tape_internal.h"

typedef struct ref_bufs {
    double *v, *aux, *dv, *a, *da;
} ref_bufs;

static void ref_free(ref_bufs *b)
{
    free(b->v);
    free(b->aux);
    free(b->dv);
    free(b->a);
    free(b->da);
}

static int ref_alloc(const tp_tape *T, ref_bufs *b)
{
    size_t n = T->n_ops ? T->n_ops : 1;
    b->v = calloc(n, sizeof(double));
    b->aux = calloc(n, sizeof(double));
    b->dv = calloc(n, sizeof(double));
    b->a = calloc(n, sizeof(double));
    b->da = calloc(n, sizeof(double));
    if (!b->v || !b->aux || !b->dv || !b->a || !b->da) {
        ref_free(b);
        return TP_ERR_NOMEM;
    }
    return TP_OK;
}

static double op_c(const tp_tape *T, uint32_t i)
{
    unsigned op = T->opc[i];
    if (tp__opinfo[op].kind == TP_KIND_UCONST)
        return T->konst[T->a1[i]];
    if (tp__opinfo[op].kind == TP_KIND_UINT) {
        int32_t k;
        memcpy(&k, &T->a1[i], sizeof k);
        return (double)k;
    }
    return 0.0;
}

static bool is_binary(const tp_tape *T, uint32_t i)
{
    return tp__opinfo[T->opc[i]].kind == TP_KIND_BINARY;
}

/* Values, and first-order tangents in direction s (s may be NULL). */
static void ref_forward(const tp_tape *T, const double *param,
                        const double *x, const double *s, ref_bufs *b)
{
    uint32_t i;
    for (i = 0; i < T->n_ops; i++) {
        const unsigned op = T->opc[i];
        const uint32_t u = T->a0[i], t = T->a1[i];
        tp_partials d;
        double tv;
        switch (op) {
        case TP_OP_INDEP:
            b->v[i] = x[u];
            b->dv[i] = s ? s[u] : 0.0;
            continue;
        case TP_OP_PARAM:
            b->v[i] = param[u];
            b->dv[i] = 0.0;
            continue;
        case TP_OP_CONST:
            b->v[i] = T->konst[u];
            b->dv[i] = 0.0;
            continue;
        default: break;
        }
        tv = is_binary(T, i) ? b->v[t] : 0.0;
        b->v[i] = tp__op_value_aux(op, b->v[u], tv, op_c(T, i), &b->aux[i]);
        tp__op_partials(op, b->v[u], tv, op_c(T, i), b->v[i], b->aux[i], &d);
        b->dv[i] = d.fu * b->dv[u] + (is_binary(T, i) ? d.ft * b->dv[t] : 0.0);
    }
}

/* Adjoints for output weights w and, with second, their tangents. */
static void ref_reverse(const tp_tape *T, const double *w, bool second,
                        ref_bufs *b)
{
    uint32_t i, o;
    memset(b->a, 0, T->n_ops * sizeof(double));
    memset(b->da, 0, T->n_ops * sizeof(double));
    for (o = 0; o < T->n_out; o++)
        b->a[T->out_slot[o]] += w[o];
    for (i = T->n_ops; i-- > 0;) {
        const unsigned op = T->opc[i];
        const uint32_t u = T->a0[i], t = T->a1[i];
        const bool bin = is_binary(T, i);
        const double tv = bin ? b->v[t] : 0.0, dt = bin ? b->dv[t] : 0.0;
        tp_partials d;
        if (tp__opinfo[op].kind == TP_KIND_LEAF)
            continue;
        tp__op_partials(op, b->v[u], tv, op_c(T, i), b->v[i], b->aux[i], &d);
        b->a[u] += d.fu * b->a[i];
        if (bin)
            b->a[t] += d.ft * b->a[i];
        if (!second)
            continue;
        b->da[u] += d.fu * b->da[i] +
                    b->a[i] * (d.fuu * b->dv[u] + d.fut * dt);
        if (bin)
            b->da[t] += d.ft * b->da[i] +
                        b->a[i] * (d.fut * b->dv[u] + d.ftt * dt);
    }
}

int tp__ref_eval(const tp_tape *T, const double *param, const double *x,
                 double *y)
{
    return tp__ref_jvp(T, param, x, NULL, y, NULL);
}

int tp__ref_jvp(const tp_tape *T, const double *param, const double *x,
                const double *s, double *y, double *ys)
{
    ref_bufs b;
    uint32_t o;
    if (ref_alloc(T, &b))
        return TP_ERR_NOMEM;
    ref_forward(T, param, x, s, &b);
    for (o = 0; o < T->n_out; o++) {
        if (y)
            y[o] = b.v[T->out_slot[o]];
        if (ys)
            ys[o] = b.dv[T->out_slot[o]];
    }
    ref_free(&b);
    return TP_OK;
}

int tp__ref_vjp(const tp_tape *T, const double *param, const double *x,
                const double *w, double *g)
{
    ref_bufs b;
    uint32_t i;
    if (ref_alloc(T, &b))
        return TP_ERR_NOMEM;
    ref_forward(T, param, x, NULL, &b);
    ref_reverse(T, w, false, &b);
    for (i = 0; i < T->n_indep; i++)
        g[i] = b.a[i];
    ref_free(&b);
    return TP_OK;
}

int tp__ref_hvp(const tp_tape *T, const double *param, const double *x,
                const double *w, const double *s, double *hs)
{
    ref_bufs b;
    uint32_t i;
    if (ref_alloc(T, &b))
        return TP_ERR_NOMEM;
    ref_forward(T, param, x, s, &b);
    ref_reverse(T, w, true, &b);
    for (i = 0; i < T->n_indep; i++)
        hs[i] = b.da[i];
    ref_free(&b);
    return TP_OK;
}
