/* tuple.c - the embedded-tuple evaluator backend (OCEA style).
 *
 * Every value carries the tuple (value, gradient, packed Hessian) over all
 * n independents; every op propagates the whole tuple by the chain rule:
 *     g_w = fu g_u + ft g_t
 *     H_w = fu H_u + ft H_t + fuu g_u g_u' + fut (g_u g_t' + g_t g_u')
 *           + ftt g_t g_t'
 * so one op costs O(n^2). Constants and parameters carry no derivative
 * part (a flag, as a mixed real/embedded operation would), which keeps a
 * product with a constant at the cost of a scaling.
 *
 * Layout: tuple k is len = 1 + n + n(n+1)/2 doubles at pool + k len:
 * value, gradient, then the Hessian's lower triangle row by row (entry
 * (i, j), i >= j, at i(i+1)/2 + j). The pool grows by doubling and is kept
 * between runs, so repeated runs of one function do not allocate.
 */
#include <string.h>

#include "op_math.h"
#include "tape_internal.h"

typedef struct tp_tuple {
    tp_rec base;
    size_t n;      /* independents */
    size_t len;    /* doubles per tuple */
    double *pool;  /* [cap * len] */
    uint8_t *cst;  /* [cap] 1: derivative part is zero and not stored */
    size_t count, cap, cap_cst;
} tp_tuple;

static double *tup(const tp_tuple *U, uint32_t id)
{
    return U->pool + (size_t)id * U->len;
}

/* A new tuple slot; its contents are for the caller to fill. */
static uint32_t new_tuple(tp_tuple *U, bool cst)
{
    size_t ncap = U->cap;
    if (U->count >= TP_MAX_OPS) {
        tp__rec_fail(&U->base, TP_ERR_TOOBIG, "tuples: too many values");
        return TP_NO_SLOT;
    }
    if (U->count + 1 > U->cap) {
        /* grow the pool in whole tuples, telling the hook both sizes */
        size_t oldb = U->cap * U->len * sizeof(double), newb;
        void *q;
        ncap = U->cap ? 2 * U->cap : 16;
        newb = tp__mulsz(tp__mulsz(ncap, U->len), sizeof(double));
        if (newb == SIZE_MAX)
            goto nomem;
        q = U->base.al.fn(U->base.al.ud, U->pool, oldb, newb);
        if (!q)
            goto nomem;
        U->pool = q;
        U->cap = ncap;
    }
    if (U->count + 1 > U->cap_cst &&
        tp__grow(&U->base.al, (void **)&U->cst, 1, &U->cap_cst,
                 U->count + 1))
        goto nomem;
    U->cst[U->count] = cst;
    U->base.n_ids = (uint32_t)(U->count + 1);
    return (uint32_t)U->count++;
nomem:
    tp__rec_fail(&U->base, TP_ERR_NOMEM, "tuples: out of memory");
    return TP_NO_SLOT;
}

static uint32_t const_tuple(tp_tuple *U, double value)
{
    uint32_t id = new_tuple(U, true);
    if (id != TP_NO_SLOT)
        tup(U, id)[0] = value;
    return id;
}

static int tu_begin(tp_rec *base, const double *x)
{
    tp_tuple *U = (tp_tuple *)base;
    size_t i;
    U->count = 0;
    base->n_ids = 0;
    for (i = 0; i < U->n; i++) {
        uint32_t id = new_tuple(U, false);
        double *w;
        if (id == TP_NO_SLOT)
            return base->status;
        w = tup(U, id);
        memset(w, 0, U->len * sizeof(double));
        w[0] = x[i];
        w[1 + i] = 1.0;
    }
    return TP_OK;
}

static uint32_t tu_param(tp_rec *base, int k, double value)
{
    (void)k;
    return const_tuple((tp_tuple *)base, value);
}

static uint32_t tu_constant(tp_rec *base, double c)
{
    return const_tuple((tp_tuple *)base, c);
}

/* w = fu u + ft t + second-order terms, over gradient and Hessian; an
 * operand may be NULL (constant). One pass over the packed Hessian, with
 * unit stride and no temporaries: per row i the second-order terms fold
 * into two scalars, a = fuu gu_i + fut gt_i and b = ftt gt_i + fut gu_i,
 * so that H_w(i, j) = fu H_u + ft H_t + a gu_j + b gt_j. */
static void propagate(const tp_tuple *U, double *restrict w,
                      const double *u, const double *t, const tp_partials *d)
{
    const size_t n = U->n;
    double *restrict gw = w + 1, *restrict Hw = w + 1 + n;
    size_t i, j, k;

    if (u && t) {
        const double *gu = u + 1, *gt = t + 1, *Hu = u + 1 + n,
                     *Ht = t + 1 + n;
        const double fu = d->fu, ft = d->ft;
        for (i = 0; i < n; i++)
            gw[i] = fu * gu[i] + ft * gt[i];
        if (d->fuu == 0.0 && d->ftt == 0.0 && d->fut == 0.0) {
            const size_t nh = n * (n + 1) / 2;
            for (k = 0; k < nh; k++)
                Hw[k] = fu * Hu[k] + ft * Ht[k];
            return;
        }
        for (i = 0, k = 0; i < n; i++) {
            const double a = d->fuu * gu[i] + d->fut * gt[i];
            const double b = d->ftt * gt[i] + d->fut * gu[i];
            for (j = 0; j <= i; j++, k++)
                Hw[k] = fu * Hu[k] + ft * Ht[k] + a * gu[j] + b * gt[j];
        }
        return;
    }
    {
        /* one operand carries derivatives: v, with f1 and f11 its own */
        const double *v = u ? u : t, *gv = v + 1, *Hv = v + 1 + n;
        const double f1 = u ? d->fu : d->ft, f11 = u ? d->fuu : d->ftt;
        for (i = 0; i < n; i++)
            gw[i] = f1 * gv[i];
        if (f11 == 0.0) {
            const size_t nh = n * (n + 1) / 2;
            for (k = 0; k < nh; k++)
                Hw[k] = f1 * Hv[k];
            return;
        }
        for (i = 0, k = 0; i < n; i++) {
            const double a = f11 * gv[i];
            for (j = 0; j <= i; j++, k++)
                Hw[k] = f1 * Hv[k] + a * gv[j];
        }
    }
}

static uint32_t tu_apply(tp_rec *base, int op, uint32_t u, uint32_t t,
                         double c)
{
    tp_tuple *U = (tp_tuple *)base;
    const bool binary = tp__opinfo[op].kind == TP_KIND_BINARY;
    const bool cu = U->cst[u], ct = binary ? U->cst[t] : true;
    double uv = tup(U, u)[0], tv = binary ? tup(U, t)[0] : 0.0, aux, w;
    tp_partials d;
    uint32_t id;

    /* identities: the operand's tuple is the result (tuples never change
     * once made), which spares a pass over it; sums that start from a
     * constant 0 are how models accumulate terms */
    if (binary) {
        if ((op == TP_OP_ADD && cu && uv == 0.0) ||
            (op == TP_OP_MUL && cu && uv == 1.0))
            return t;
        if (((op == TP_OP_ADD || op == TP_OP_SUB) && ct && tv == 0.0) ||
            (op == TP_OP_MUL && ct && tv == 1.0))
            return u;
    } else if ((op == TP_OP_ADDC && c == 0.0) ||
               (op == TP_OP_MULC && c == 1.0)) {
        return u;
    }
    w = tp__op_value_aux(op, uv, tv, c, &aux);
    id = new_tuple(U, cu && ct);
    if (id == TP_NO_SLOT)
        return id;
    tup(U, id)[0] = w;
    if (cu && ct)
        return id;
    tp__op_partials(op, uv, tv, c, w, aux, &d);
    /* the pool may have moved: take operand pointers after new_tuple */
    propagate(U, tup(U, id), cu ? NULL : tup(U, u),
              ct ? NULL : tup(U, t), &d);
    return id;
}

static double tu_value(const tp_rec *base, uint32_t id)
{
    return tup((const tp_tuple *)base, id)[0];
}

static void tu_destroy(tp_rec *base)
{
    tp_tuple *U = (tp_tuple *)base;
    const tp_allocator al = base->al;
    tp__free(&al, U->pool, U->cap * U->len * sizeof(double));
    tp__free(&al, U->cst, U->cap_cst);
    tp__rec_release(base);
    tp__free(&al, U, sizeof *U);
}

static const tp_backend tuple_backend = {
    "tuple evaluator", tu_begin, tu_param, tu_constant, tu_apply, tu_value,
    tu_destroy,
};

int tp_tuple_new(tp_rec **out, int n_indep, const tp_allocator *al)
{
    tp_allocator a = tp__allocator(al);
    tp_tuple *U;
    size_t n;
    if (!out)
        return TP_ERR_NULL;
    *out = NULL;
    if (n_indep < 0 || n_indep > 65535)
        return TP_ERR_SIZE;
    n = (size_t)n_indep;
    U = tp__calloc(&a, 1, sizeof *U);
    if (!U)
        return TP_ERR_NOMEM;
    tp__rec_init(&U->base, &tuple_backend, n_indep, &a);
    U->n = n;
    U->len = 1 + n + n * (n + 1) / 2;
    *out = &U->base;
    return TP_OK;
}

static int tuple_of(const tp_rec *r, int out, const double **w, bool *cst)
{
    const tp_tuple *U = (const tp_tuple *)r;
    if (!r)
        return TP_ERR_NULL;
    if (r->be != &tuple_backend)
        return TP_ERR_BACKEND;
    if (r->status < 0)
        return r->status;
    if (out < 0 || (size_t)out >= r->n_outs)
        return r->n_outs ? TP_ERR_SIZE : TP_ERR_EMPTY;
    *w = tup(U, r->outs[out].id);
    *cst = U->cst[r->outs[out].id];
    return TP_OK;
}

static int finite_status(const double *a, size_t n, int st)
{
    size_t i;
    for (i = 0; a && i < n; i++)
        if (!isfinite(a[i]))
            return st == TP_OK ? TP_WARN_NONFINITE : st;
    return st;
}

int tp_tuple_output(const tp_rec *r, int out, double *grad,
                    double *hess_packed)
{
    const double *w;
    bool cst;
    const tp_tuple *U = (const tp_tuple *)r;
    int st = tuple_of(r, out, &w, &cst);
    size_t nh;
    if (st)
        return st;
    nh = U->n * (U->n + 1) / 2;
    if (grad) {
        if (cst)
            memset(grad, 0, U->n * sizeof(double));
        else
            memcpy(grad, w + 1, U->n * sizeof(double));
    }
    if (hess_packed) {
        if (cst)
            memset(hess_packed, 0, nh * sizeof(double));
        else
            memcpy(hess_packed, w + 1 + U->n, nh * sizeof(double));
    }
    st = finite_status(w, 1, TP_OK);
    st = finite_status(grad, U->n, st);
    return finite_status(hess_packed, nh, st);
}

int tp_tuple_lagrange(const tp_rec *r, int out, double *L, double *dLdq,
                      double *M, double *h)
{
    const double *w, *H;
    bool cst;
    const tp_tuple *U = (const tp_tuple *)r;
    int st = tuple_of(r, out, &w, &cst);
    size_t n, i, j;
    if (st)
        return st;
    if (U->n % 2)
        return TP_ERR_SIZE;
    n = U->n / 2;
    H = w + 1 + U->n;
    if (L)
        *L = w[0];
    for (i = 0; i < n; i++) {
        const size_t qi = n + i; /* row of qd_i */
        double s = 0.0;
        if (dLdq)
            dLdq[i] = cst ? 0.0 : w[1 + i];
        for (j = 0; j < n; j++) {
            const size_t qj = n + j;
            /* M_ij = H(qd_i, qd_j); mixed term H(qd_i, q_j), qi > j */
            const double mij =
                cst ? 0.0
                    : (qi >= qj ? H[qi * (qi + 1) / 2 + qj]
                                : H[qj * (qj + 1) / 2 + qi]);
            if (M)
                M[i * n + j] = mij;
            if (!cst)
                s += H[qi * (qi + 1) / 2 + j] * tup(U, (uint32_t)qj)[0];
        }
        if (h)
            h[i] = s;
    }
    st = finite_status(L, 1, TP_OK);
    st = finite_status(dLdq, n, st);
    st = finite_status(M, n * n, st);
    return finite_status(h, n, st);
}
