/* tuple.c - the embedded-tuple evaluator backend (OCEA style).
 *
 * Every value carries the tuple (value, gradient, packed Hessian) over all
 * n independents; every op propagates the whole tuple by the chain rule:
 *     g_w = fu g_u + ft g_t
 *     H_w = fu H_u + ft H_t + fuu g_u g_u' + fut (g_u g_t' + g_t g_u')
 *           + ftt g_t g_t'
 * so one op costs O(n^2). Constants and parameters carry no derivative
 * part (as a mixed real/embedded operation would), which keeps a product
 * with a constant at the cost of a scaling.
 *
 * Storage: each id has its value in val[id] and, unless it is a constant,
 * a derivative part of nd = n + n(n+1)/2 doubles in slot slot[id] of the
 * pool: the gradient, then the Hessian's lower triangle row by row (entry
 * (i, j), i >= j, at n + i(i+1)/2 + j).
 *
 * Slots are reused by a plan. A run that ends well leaves, for each id,
 * the slot it gets in the next run, made from the ids' last uses in this
 * run: a slot is free once the last op reading its id is made (outputs
 * live to the end). A function that records the same ops at every run (a
 * model's energies) then needs as many slots as it has values alive at
 * once, a few tuples that stay in cache, where one new tuple per op would
 * stream megabytes through memory at 20 links. Nothing is assumed: an op
 * follows the plan only while the run has made the same ops with the same
 * operands as the planned one, every read checks that the operand's slot
 * still holds it (owner), and a run that finds one overwritten (the
 * function took another path this time) is repeated without a plan, each
 * id in a slot of its own (tp_rec_run asks the end hook). A run that
 * departs from the plan without harm makes a new plan.
 */
#include <string.h>

#include "op_math.h"
#include "sweep.h"
#include "tape_internal.h"

#define NO_DERIV UINT32_MAX /* slot of an id whose derivatives are zero */
#define NO_ID UINT32_MAX    /* operand of a leaf */
#define LIVE_TO_END (UINT32_MAX - 1u) /* last use of an output */

/* The per-id arrays share one block: val, then six uint32 arrays. */
#define ID_BYTES (sizeof(double) + 6 * sizeof(uint32_t))
/* A slot: its derivative part and its owner. */
#define SLOT_BYTES(nd) ((nd) * sizeof(double) + sizeof(uint32_t))

typedef struct tp_tuple {
    tp_rec base;
    size_t n;  /* independents */
    size_t nd; /* doubles in a derivative part */
    /* per id, [cap_ids], in one block at val */
    double *val;
    uint32_t *slot;     /* derivative slot, or NO_DERIV */
    uint32_t *plan;     /* the slot the plan gives the id in the next run */
    uint32_t *opu, *opt; /* operands of the op that made the id, or NO_ID */
    uint32_t *last;     /* the planner's: last op reading the id */
    uint32_t *stack;    /* the planner's: free slots */
    size_t cap_ids;     /* (this run's ids: base.n_ids) */
    /* derivative parts, [cap_slots * nd], then owner [cap_slots] */
    double *pool;
    uint32_t *owner; /* the id whose derivatives a slot holds */
    size_t cap_slots;
    size_t next_fresh; /* the next slot no id of this run has had */
    size_t plan_len;   /* ids covered by the plan (0: no plan) */
    size_t plan_slots; /* slots the plan uses */
    bool diverged;     /* this run has left the plan (or had none) */
    bool conflict;     /* an operand's slot was overwritten: run again */
} tp_tuple;

static double *deriv(const tp_tuple *U, uint32_t s)
{
    return U->pool + (size_t)s * U->nd;
}

/* Point the per-id arrays into a block of cap ids. */
static void id_arrays(tp_tuple *U, void *block, size_t cap)
{
    uint32_t *w = (uint32_t *)((double *)block + cap);
    U->val = block;
    U->slot = w;
    U->plan = w + cap;
    U->opu = w + 2 * cap;
    U->opt = w + 3 * cap;
    U->last = w + 4 * cap;
    U->stack = w + 5 * cap;
}

/* Grow the per-id block to hold at least need ids, keeping every entry
 * (the plan's reach beyond this run's ids). */
static bool grow_ids(tp_tuple *U, size_t need)
{
    const tp_allocator *al = &U->base.al;
    size_t ncap = U->cap_ids ? U->cap_ids : 64, bytes;
    const size_t ocap = U->cap_ids;
    double *oval = U->val;
    uint32_t *oslot = U->slot, *oplan = U->plan, *oopu = U->opu;
    uint32_t *oopt = U->opt;
    void *q;
    while (ncap < need)
        ncap *= 2;
    bytes = tp__mulsz(ncap, ID_BYTES);
    if (bytes == SIZE_MAX || !(q = tp__alloc(al, bytes))) {
        tp__rec_fail(&U->base, TP_ERR_NOMEM, "tuples: out of memory");
        return false;
    }
    id_arrays(U, q, ncap);
    if (ocap) {
        memcpy(U->val, oval, ocap * sizeof(double));
        memcpy(U->slot, oslot, ocap * sizeof(uint32_t));
        memcpy(U->plan, oplan, ocap * sizeof(uint32_t));
        memcpy(U->opu, oopu, ocap * sizeof(uint32_t));
        memcpy(U->opt, oopt, ocap * sizeof(uint32_t));
        tp__free(al, oval, ocap * ID_BYTES);
    }
    U->cap_ids = ncap;
    return true;
}

/* Grow the pool to hold at least need slots, keeping their contents. */
static bool grow_slots(tp_tuple *U, size_t need)
{
    const tp_allocator *al = &U->base.al;
    size_t ncap = U->cap_slots ? U->cap_slots : 16, bytes;
    double *q;
    while (ncap < need)
        ncap *= 2;
    bytes = tp__mulsz(ncap, SLOT_BYTES(U->nd));
    if (bytes == SIZE_MAX || !(q = tp__alloc(al, bytes))) {
        tp__rec_fail(&U->base, TP_ERR_NOMEM, "tuples: out of memory");
        return false;
    }
    if (U->cap_slots) {
        memcpy(q, U->pool, U->cap_slots * U->nd * sizeof(double));
        memcpy(q + ncap * U->nd, U->owner,
               U->cap_slots * sizeof(uint32_t));
        tp__free(al, U->pool, U->cap_slots * SLOT_BYTES(U->nd));
    }
    U->pool = q;
    U->owner = (uint32_t *)(q + ncap * U->nd);
    U->cap_slots = ncap;
    return true;
}

/* new_id when the plan does not hold: a slot no id of this run has had
 * (growing the arrays as needed), and the op's operands written down for
 * the next plan. */
static uint32_t new_id_off_plan(tp_tuple *U, uint32_t u, uint32_t t,
                                bool has_deriv)
{
    const size_t k = U->base.n_ids;
    uint32_t s = NO_DERIV;
    if (k >= U->cap_ids) {
        if (k >= TP_MAX_OPS) {
            tp__rec_fail(&U->base, TP_ERR_TOOBIG, "tuples: too many values");
            return TP_NO_SLOT;
        }
        if (!grow_ids(U, k + 1))
            return TP_NO_SLOT;
    }
    U->diverged = true;
    U->opu[k] = u;
    U->opt[k] = t;
    if (has_deriv) {
        if (U->next_fresh >= U->cap_slots &&
            !grow_slots(U, U->next_fresh + 1))
            return TP_NO_SLOT;
        s = (uint32_t)U->next_fresh++;
        U->owner[s] = (uint32_t)k;
    }
    U->slot[k] = s;
    U->base.n_ids = (uint32_t)(k + 1);
    return (uint32_t)k;
}

/* A new id, made by an op of operands u and t (NO_ID: a leaf), with a
 * derivative part or not; its contents are for the caller to fill. Its
 * slot is the plan's while this run has made the planned ops (the plan
 * never covers more ids than the arrays hold). */
static inline uint32_t new_id(tp_tuple *U, uint32_t u, uint32_t t,
                              bool has_deriv)
{
    const size_t k = U->base.n_ids;
    uint32_t s;
    if (U->diverged || k >= U->plan_len || U->opu[k] != u ||
        U->opt[k] != t || ((s = U->plan[k]) != NO_DERIV) != has_deriv)
        return new_id_off_plan(U, u, t, has_deriv);
    U->slot[k] = s;
    if (s != NO_DERIV)
        U->owner[s] = (uint32_t)k;
    U->base.n_ids = (uint32_t)(k + 1);
    return (uint32_t)k;
}

static uint32_t const_id(tp_tuple *U, double value)
{
    uint32_t id = new_id(U, NO_ID, NO_ID, false);
    if (id != TP_NO_SLOT)
        U->val[id] = value;
    return id;
}

static int tu_begin(tp_rec *base, const double *x)
{
    tp_tuple *U = (tp_tuple *)base;
    size_t i;
    base->n_ids = 0;
    U->diverged = U->plan_len == 0;
    U->conflict = false;
    U->next_fresh = U->plan_len ? U->plan_slots : 0;
    /* a plan uses no more slots than the run it came from had (it frees
     * only what that run no longer read); checked all the same, as
     * new_id writes into the plan's slots unchecked */
    if (U->next_fresh > U->cap_slots && !grow_slots(U, U->next_fresh))
        return base->status;
    for (i = 0; i < U->n; i++) {
        uint32_t id = new_id(U, NO_ID, NO_ID, true);
        double *d;
        if (id == TP_NO_SLOT)
            return base->status;
        U->val[id] = x[i];
        d = deriv(U, U->slot[id]);
        memset(d, 0, U->nd * sizeof(double));
        d[i] = 1.0;
    }
    return TP_OK;
}

static uint32_t tu_param(tp_rec *base, int k, double value)
{
    (void)k;
    return const_id((tp_tuple *)base, value);
}

static uint32_t tu_constant(tp_rec *base, double c)
{
    return const_id((tp_tuple *)base, c);
}

/* w = fu u + ft t + second-order terms, over gradient and Hessian, for n
 * independents; an operand may be NULL (constant). One pass over the
 * packed Hessian, with unit stride and no temporaries: per row i the
 * second-order terms fold into two scalars, a = fuu gu_i + fut gt_i and
 * b = ftt gt_i + fut gu_i, so that H_w(i, j) = fu H_u + ft H_t + a gu_j +
 * b gt_j. Inlined with n a constant for small n (below). */
#if defined(__GNUC__) && !defined(__clang__)
#define TP_UNROLL _Pragma("GCC unroll 10")
#else
#define TP_UNROLL
#endif
TP_KERNEL void propagate_n(const size_t n, double *restrict w,
                           const double *restrict u,
                           const double *restrict t, const tp_partials *d)
{
    double *restrict gw = w, *restrict Hw = w + n;
    const size_t nd = n + n * (n + 1) / 2;
    size_t i, j, k;

    if (u && t) {
        const double *gu = u, *gt = t, *Hu = u + n, *Ht = t + n;
        const double fu = d->fu, ft = d->ft;
        if (d->fuu == 0.0 && d->ftt == 0.0 && d->fut == 0.0) {
            /* linear: gradient and Hessian in one pass */
            for (k = 0; k < nd; k++)
                w[k] = fu * u[k] + ft * t[k];
            return;
        }
        for (i = 0; i < n; i++)
            gw[i] = fu * gu[i] + ft * gt[i];
        TP_UNROLL
        for (i = 0, k = 0; i < n; i++) {
            const double a = d->fuu * gu[i] + d->fut * gt[i];
            const double b = d->ftt * gt[i] + d->fut * gu[i];
            TP_UNROLL
            for (j = 0; j <= i; j++, k++)
                Hw[k] = fu * Hu[k] + ft * Ht[k] + a * gu[j] + b * gt[j];
        }
        return;
    }
    {
        /* one operand carries derivatives: v, with f1 and f11 its own */
        const double *v = u ? u : t, *gv = v, *Hv = v + n;
        const double f1 = u ? d->fu : d->ft, f11 = u ? d->fuu : d->ftt;
        if (f11 == 0.0) {
            for (k = 0; k < nd; k++)
                w[k] = f1 * v[k];
            return;
        }
        for (i = 0; i < n; i++)
            gw[i] = f1 * gv[i];
        TP_UNROLL
        for (i = 0, k = 0; i < n; i++) {
            const double a = f11 * gv[i];
            TP_UNROLL
            for (j = 0; j <= i; j++, k++)
                Hw[k] = f1 * Hv[k] + a * gv[j];
        }
    }
}

/* Models of a few links (2n of 2 to 10 independents) spend most of an op
 * in loop control of rows of one to ten entries: with n a constant the
 * compiler unrolls them. This and the general version below are also
 * compiled for AVX2, picked at load time where the machine has it (no
 * FMA: every version rounds alike). */
TP_VECTOR_CLONES
static void propagate_small(size_t n, double *w, const double *u,
                            const double *t, const tp_partials *d)
{
    switch (n) {
    case 2: propagate_n(2, w, u, t, d); break;
    case 4: propagate_n(4, w, u, t, d); break;
    case 6: propagate_n(6, w, u, t, d); break;
    case 8: propagate_n(8, w, u, t, d); break;
    default: propagate_n(10, w, u, t, d); break; /* n = 10 */
    }
}

TP_VECTOR_CLONES
static void propagate_large(size_t n, double *w, const double *u,
                            const double *t, const tp_partials *d)
{
    propagate_n(n, w, u, t, d);
}

static void propagate(size_t n, double *w, const double *u, const double *t,
                      const tp_partials *d)
{
    if (n <= 10 && n % 2 == 0 && n > 0)
        propagate_small(n, w, u, t, d);
    else
        propagate_large(n, w, u, t, d);
}

/* An operand's slot holds another id: the run is made again. */
TP_COLD static uint32_t overwritten(tp_tuple *U, uint32_t id)
{
    U->conflict = true;
    tp__rec_fail(&U->base, TP_ERR_BACKEND,
                 "tuples: value %u was overwritten after this run took "
                 "another path than the last one (the run is repeated "
                 "without reusing storage)",
                 (unsigned)id);
    return TP_NO_SLOT;
}

static uint32_t tu_apply(tp_rec *base, int op, uint32_t u, uint32_t t,
                         double c)
{
    tp_tuple *U = (tp_tuple *)base;
    const bool binary = tp__opinfo[op].kind == TP_KIND_BINARY;
    const uint32_t su = U->slot[u], st = binary ? U->slot[t] : NO_DERIV;
    const bool cu = su == NO_DERIV, ct = st == NO_DERIV;
    const double uv = U->val[u], tv = binary ? U->val[t] : 0.0;
    double aux, w;
    tp_partials d;
    uint32_t id;

    if (!cu && U->owner[su] != u)
        return overwritten(U, u);
    if (!ct && U->owner[st] != t)
        return overwritten(U, t);
    /* identities: the operand's tuple is the result (tuples never change
     * while their ids are alive), which spares a pass over it; sums that
     * start from a constant 0 are how models accumulate terms */
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
    id = new_id(U, u, binary ? t : NO_ID, !(cu && ct));
    if (id == TP_NO_SLOT)
        return id;
    U->val[id] = w;
    if (cu && ct)
        return id;
    tp__op_partials(op, uv, tv, c, w, aux, &d);
    /* the pool may have moved: take operand pointers after new_id */
    propagate(U->n, deriv(U, U->slot[id]), cu ? NULL : deriv(U, su),
              ct ? NULL : deriv(U, st), &d);
    return id;
}

static double tu_value(const tp_rec *base, uint32_t id)
{
    return ((const tp_tuple *)base)->val[id];
}

/* The plan for the next run, from this run's ops and outputs: ids in
 * order, each takes a free slot (or a new one), and the slots of its
 * operands whose last reader it is are freed after it (never before: an
 * op's result must not overwrite its operands); an id nothing reads
 * frees its slot at once. */
static void make_plan(tp_tuple *U)
{
    const size_t cnt = U->base.n_ids;
    uint32_t *last = U->last, *stack = U->stack, *plan = U->plan;
    size_t k, top = 0, used = 0;
    for (k = 0; k < cnt; k++)
        last[k] = NO_ID;
    for (k = 0; k < cnt; k++) {
        if (U->opu[k] != NO_ID)
            last[U->opu[k]] = (uint32_t)k;
        if (U->opt[k] != NO_ID)
            last[U->opt[k]] = (uint32_t)k;
    }
    for (k = 0; k < U->base.n_outs; k++)
        last[U->base.outs[k].id] = LIVE_TO_END;
    for (k = 0; k < cnt; k++) {
        const uint32_t u = U->opu[k], t = U->opt[k];
        if (U->slot[k] == NO_DERIV) {
            plan[k] = NO_DERIV;
            continue;
        }
        plan[k] = top ? stack[--top] : (uint32_t)used++;
        if (last[k] == NO_ID)
            stack[top++] = plan[k];
        if (u != NO_ID && last[u] == k && plan[u] != NO_DERIV)
            stack[top++] = plan[u];
        if (t != NO_ID && t != u && last[t] == k && plan[t] != NO_DERIV)
            stack[top++] = plan[t];
    }
    U->plan_len = cnt;
    U->plan_slots = used;
}

/* After the user's function: 1 to have the run made again without a
 * plan (an operand or an output was overwritten), else 0, with the plan
 * for the next run made new if this one left it. */
static int tu_end(tp_rec *base)
{
    tp_tuple *U = (tp_tuple *)base;
    size_t k;
    if (U->conflict) {
        U->plan_len = 0;
        return 1;
    }
    if (base->status < 0) {
        U->plan_len = 0;
        return 0;
    }
    for (k = 0; k < base->n_outs; k++) {
        const uint32_t id = base->outs[k].id, s = U->slot[id];
        if (s != NO_DERIV && U->owner[s] != id) {
            U->plan_len = 0;
            return 1;
        }
    }
    if (U->diverged || base->n_ids != U->plan_len)
        make_plan(U);
    return 0;
}

static void tu_destroy(tp_rec *base)
{
    tp_tuple *U = (tp_tuple *)base;
    const tp_allocator al = base->al;
    if (U->cap_slots)
        tp__free(&al, U->pool, U->cap_slots * SLOT_BYTES(U->nd));
    if (U->cap_ids)
        tp__free(&al, U->val, U->cap_ids * ID_BYTES);
    tp__rec_release(base);
    tp__free(&al, U, sizeof *U);
}

static const tp_backend tuple_backend = {
    "tuple evaluator", tu_begin, tu_param, tu_constant, tu_apply, tu_value,
    tu_destroy, tu_end,
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
    U->nd = n + n * (n + 1) / 2;
    *out = &U->base;
    return TP_OK;
}

/* Output out's value and derivative part (NULL: zero). */
static int tuple_of(const tp_rec *r, int out, double *v, const double **d)
{
    const tp_tuple *U = (const tp_tuple *)r;
    uint32_t id;
    if (!r)
        return TP_ERR_NULL;
    if (r->be != &tuple_backend)
        return TP_ERR_BACKEND;
    if (r->status < 0)
        return r->status;
    if (out < 0 || (size_t)out >= r->n_outs)
        return r->n_outs ? TP_ERR_SIZE : TP_ERR_EMPTY;
    id = r->outs[out].id;
    *v = U->val[id];
    *d = U->slot[id] == NO_DERIV ? NULL : deriv(U, U->slot[id]);
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
    const double *d;
    double v;
    const tp_tuple *U = (const tp_tuple *)r;
    int st = tuple_of(r, out, &v, &d);
    size_t nh;
    if (st)
        return st;
    nh = U->n * (U->n + 1) / 2;
    if (grad) {
        if (!d)
            memset(grad, 0, U->n * sizeof(double));
        else
            memcpy(grad, d, U->n * sizeof(double));
    }
    if (hess_packed) {
        if (!d)
            memset(hess_packed, 0, nh * sizeof(double));
        else
            memcpy(hess_packed, d + U->n, nh * sizeof(double));
    }
    st = finite_status(&v, 1, TP_OK);
    st = finite_status(grad, U->n, st);
    return finite_status(hess_packed, nh, st);
}

int tp_tuple_lagrange(const tp_rec *r, int out, double *L, double *dLdq,
                      double *M, double *h)
{
    const double *d, *H;
    double v;
    const tp_tuple *U = (const tp_tuple *)r;
    int st = tuple_of(r, out, &v, &d);
    size_t n, i, j;
    if (st)
        return st;
    if (U->n % 2)
        return TP_ERR_SIZE;
    n = U->n / 2;
    H = d ? d + U->n : NULL;
    if (L)
        *L = v;
    for (i = 0; i < n; i++) {
        const size_t qi = n + i; /* row of qd_i */
        double s = 0.0;
        if (dLdq)
            dLdq[i] = d ? d[i] : 0.0;
        for (j = 0; j < n; j++) {
            const size_t qj = n + j;
            /* M_ij = H(qd_i, qd_j); mixed term H(qd_i, q_j), qi > j */
            const double mij =
                !H ? 0.0
                   : (qi >= qj ? H[qi * (qi + 1) / 2 + qj]
                               : H[qj * (qj + 1) / 2 + qi]);
            if (M)
                M[i * n + j] = mij;
            if (H)
                s += H[qi * (qi + 1) / 2 + j] * U->val[qj];
        }
        if (h)
            h[i] = s;
    }
    st = finite_status(L, 1, TP_OK);
    st = finite_status(dLdq, n, st);
    st = finite_status(M, n * n, st);
    return finite_status(h, n, st);
}
