/* workspace.c - replay buffers for one thread (tp_ws), sized once when the
 * workspace is made so that no sweep allocates. The tape itself is never
 * written by a replay; everything mutable lives here. */
#include <math.h>
#include <stdint.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "tape_internal.h"

/* Doubles of strip_buf: two arrays of n rows w wide and a cache line's
 * room to align them (w 0: none). */
static size_t strip_len(size_t n, int w)
{
    const size_t len = tp__mulsz(tp__mulsz(n, (size_t)w), 2);
    if (!w)
        return 0;
    return len > SIZE_MAX - 8 ? SIZE_MAX : len + 8;
}

static void ws_release(tp_ws *ws)
{
    const tp_allocator al = ws->al;
    const tp_tape *T = ws->t;
    const size_t n = T ? T->n_ops : 0, P = (size_t)ws->P;
    tp__free(&al, ws->v, n * sizeof(double));
    tp__free(&al, ws->aux, n * sizeof(double));
    tp__free(&al, ws->adj, n * sizeof(double));
    tp__free(&al, ws->tan, n * P * sizeof(double));
    tp__free(&al, ws->atan, n * P * sizeof(double));
    tp__free(&al, ws->anz, n);
    tp__free(&al, ws->d1, n * sizeof(double));
    tp__free(&al, ws->d2, n * sizeof(double));
    tp__free(&al, ws->cat, n * P * sizeof(double));
    tp__free(&al, ws->cadj, n * sizeof(double));
    tp__free(&al, ws->frange, 2 * n * sizeof(uint32_t));
    tp__free(&al, ws->rrange, 2 * n * sizeof(uint32_t));
    tp__free(&al, ws->rec, n * sizeof(tp_oprec));
    tp__free(&al, ws->abar, n * sizeof(double));
    tp__free(&al, ws->strip_buf, strip_len(n, ws->strip_w) * sizeof(double));
    if (T) {
        tp__free(&al, ws->param, T->n_param * sizeof(double));
        tp__free(&al, ws->hs, (size_t)T->n_indep * P * sizeof(double));
        tp__free(&al, ws->wout, T->n_out * sizeof(double));
        tp__free(&al, ws->g, T->n_indep * sizeof(double));
    }
    tp__free(&al, ws, sizeof *ws);
}

/* a + b, or SIZE_MAX on overflow. */
static size_t addsz(size_t a, size_t b)
{
    return a > SIZE_MAX - b ? SIZE_MAX : a + b;
}

size_t tp_ws_bytes(const tp_tape *t, int max_dirs)
{
    size_t n, P, b;
    if (!t || max_dirs < 1)
        return 0;
    n = t->n_ops;
    P = ((size_t)max_dirs + TP_LANES - 1) / TP_LANES * TP_LANES;
    /* what tp_ws_new allocates: tan and atan (n x P), hs (n_indep x P),
     * five arrays of n doubles (v, aux, adj, d1, d2), strips.c's abar and
     * anz, the two range arrays (4 x n uint32_t), the op records,
     * strips.c's rows, the parameters, outputs and gradient */
    b = tp__mulsz(tp__mulsz(tp__mulsz(n, P), 2), sizeof(double));
    b = addsz(b, tp__mulsz(tp__mulsz(t->n_indep, P), sizeof(double)));
    b = addsz(b,
              tp__mulsz(n, 6 * sizeof(double) + 1 + 4 * sizeof(uint32_t) +
                               sizeof(tp_oprec)));
    b = addsz(b, tp__mulsz(strip_len(n, tp__strip_width(max_dirs)),
                           sizeof(double)));
    b = addsz(b, ((size_t)t->n_param + t->n_out + t->n_indep) *
                         sizeof(double));
    return addsz(b, sizeof(tp_ws));
}

int tp_ws_new(tp_ws **out, const tp_tape *t, int max_dirs,
              const tp_allocator *al)
{
    tp_allocator a = tp__allocator(al);
    tp_ws *ws;
    size_t n, P, i;
    if (!out)
        return TP_ERR_NULL;
    *out = NULL;
    if (!t)
        return TP_ERR_NULL;
    if (max_dirs < 1)
        return TP_ERR_SIZE;
    if (max_dirs > (1 << 20))
        return TP_ERR_SIZE;
    n = t->n_ops;
    P = ((size_t)max_dirs + TP_LANES - 1) / TP_LANES * TP_LANES;
    if (tp__mulsz(tp__mulsz(n, P), sizeof(double)) == SIZE_MAX)
        return TP_ERR_TOOBIG;
    ws = tp__calloc(&a, 1, sizeof *ws);
    if (!ws)
        return TP_ERR_NOMEM;
    ws->al = a;
    ws->t = t;
    ws->P = (int)P;
    ws->max_dirs = max_dirs;
    ws->v = tp__calloc(&a, n, sizeof(double));
    ws->aux = tp__calloc(&a, n, sizeof(double));
    ws->adj = tp__calloc(&a, n, sizeof(double));
    ws->tan = tp__calloc(&a, n * P, sizeof(double));
    ws->atan = tp__calloc(&a, n * P, sizeof(double));
    ws->anz = tp__calloc(&a, n, 1);
    ws->d1 = tp__calloc(&a, n, sizeof(double));
    ws->d2 = tp__calloc(&a, n, sizeof(double));
    ws->param = tp__calloc(&a, t->n_param, sizeof(double));
    ws->hs = tp__calloc(&a, (size_t)t->n_indep * P, sizeof(double));
    ws->wout = tp__calloc(&a, t->n_out, sizeof(double));
    ws->g = tp__calloc(&a, t->n_indep, sizeof(double));
    ws->frange = tp__calloc(&a, 2 * n, sizeof(uint32_t));
    ws->rrange = tp__calloc(&a, 2 * n, sizeof(uint32_t));
    ws->rec = tp__calloc(&a, n, sizeof(tp_oprec));
    ws->abar = tp__calloc(&a, n, sizeof(double));
    ws->strip_w = tp__strip_width(max_dirs);
    if (ws->strip_w) {
        const size_t len = strip_len(n, ws->strip_w);
        if (len == SIZE_MAX ||
            tp__mulsz(len, sizeof(double)) == SIZE_MAX) {
            ws->strip_w = 0;
            ws_release(ws);
            return TP_ERR_TOOBIG;
        }
        ws->strip_buf = tp__calloc(&a, len, sizeof(double));
        if (ws->strip_buf) {
            /* stan from the first cache line in strip_buf */
            const uintptr_t p = (uintptr_t)ws->strip_buf;
            ws->stan = (double *)((p + 63u) & ~(uintptr_t)63u);
            ws->satan = ws->stan + n * (size_t)ws->strip_w;
        }
    }
    ws->range_out = -1;
    if (!ws->v || !ws->aux || !ws->adj || !ws->tan || !ws->atan || !ws->anz || !ws->d1 ||
        !ws->d2 || !ws->param || !ws->hs || !ws->wout ||
        !ws->g || !ws->frange || !ws->rrange || !ws->rec || !ws->abar ||
        (ws->strip_w && !ws->strip_buf)) {
        ws_release(ws);
        return TP_ERR_NOMEM;
    }
    for (i = 0; i < n; i++) {
        ws->rec[i].op = t->opc[i];
        ws->rec[i].fl = t->dep[i];
        ws->rec[i].u = t->a0[i];
        ws->rec[i].t = t->a1[i];
    }
    if (t->n_param)
        memcpy(ws->param, t->param_dflt, t->n_param * sizeof(double));
    ws->passive_stale = true;
    *out = ws;
    return TP_OK;
}

void tp_ws_free(tp_ws **ws)
{
    if (!ws || !*ws)
        return;
    ws_release(*ws);
    *ws = NULL;
}

const char *tp_ws_errmsg(const tp_ws *ws)
{
    return ws ? ws->msg : "NULL workspace";
}

int tp_ws_set_param(tp_ws *ws, int k, double value)
{
    if (!ws)
        return TP_ERR_NULL;
    if (k < 0 || (uint32_t)k >= ws->t->n_param) {
        snprintf(ws->msg, sizeof ws->msg,
                 "tp_ws_set_param: parameter %d outside 0 .. %d", k,
                 (int)ws->t->n_param - 1);
        return TP_ERR_SIZE;
    }
    ws->param[k] = value;
    ws->passive_stale = true;
    return TP_OK;
}

int tp_ws_get_param(const tp_ws *ws, int k, double *value)
{
    if (!ws || !value)
        return TP_ERR_NULL;
    if (k < 0 || (uint32_t)k >= ws->t->n_param)
        return TP_ERR_SIZE;
    *value = ws->param[k];
    return TP_OK;
}
