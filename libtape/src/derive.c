/* derive.c - a finished tape replayed onto a recording context, with its
 * first derivatives: the derivatives of a recorded computation become a
 * recorded computation.
 *
 * Replayed onto the recorder, a tape's forward tangent sweep or reverse
 * sweep becomes a new tape, finalized and optimized like any other; its
 * own sweeps then give the derivatives of those derivatives (a gradient
 * tape's Jacobian is the Hessian, a residual tape's Jacobian holds third
 * derivatives of a Lagrangian). Replayed onto the double or the tuple
 * evaluator, the same code computes the derivatives directly, which is how
 * the tests check it against the tape's own sweeps.
 *
 * Each op's derivative rule is written with the recording API from its
 * operands and its value, the calculus of op_math.h in recorded form.
 * A derivative known to be zero is not recorded at all (a handle with tag
 * 0 stands for it here), so a replay adds a bounded number of ops per op
 * of t: a derivative tape grows linearly with its tape.
 */
#include <stdint.h>
#include <string.h>

#include "tape_internal.h"

/* A partial derivative: k * v, or the constant k when v is zero-tagged. */
typedef struct part {
    tp_val v;
    double k;
} part;

static const tp_val zero_val = {0, 0};

static bool is_zero(tp_val a) { return a.tag == 0; }

static part cpart(double k)
{
    part p;
    p.v = zero_val;
    p.k = k;
    return p;
}

static part vpart(tp_val v, double k)
{
    part p;
    p.v = v;
    p.k = k;
    return p;
}

/* The partials of w = op(u, t) (t unused for unary kinds) as recorded
 * values; c is the op's constant or integer exponent. */
static void partials(tp_rec *r, int op, tp_val u, tp_val t, double c,
                     tp_val w, part *pu, part *pt)
{
    *pt = cpart(0.0);
    switch (op) {
    case TP_OP_ADD: *pu = cpart(1.0); *pt = cpart(1.0); break;
    case TP_OP_SUB: *pu = cpart(1.0); *pt = cpart(-1.0); break;
    case TP_OP_MUL: *pu = vpart(t, 1.0); *pt = vpart(u, 1.0); break;
    case TP_OP_DIV:
        *pu = vpart(tp_cdiv(r, 1.0, t), 1.0);
        *pt = vpart(tp_mul(r, w, pu->v), -1.0);
        break;
    case TP_OP_POW: /* t u^(t-1) = t w / u; w log u */
        *pu = vpart(tp_div(r, tp_mul(r, t, w), u), 1.0);
        *pt = vpart(tp_mul(r, w, tp_log(r, u)), 1.0);
        break;
    case TP_OP_ATAN2: {
        tp_val r2 = tp_add(r, tp_sqr(r, u), tp_sqr(r, t));
        *pu = vpart(tp_div(r, t, r2), 1.0);
        *pt = vpart(tp_div(r, u, r2), -1.0);
        break;
    }
    case TP_OP_HYPOT:
        *pu = vpart(tp_div(r, u, w), 1.0);
        *pt = vpart(tp_div(r, t, w), 1.0);
        break;
    case TP_OP_NEG: *pu = cpart(-1.0); break;
    case TP_OP_ADDC: *pu = cpart(1.0); break;
    case TP_OP_MULC: *pu = cpart(c); break;
    case TP_OP_CSUB: *pu = cpart(-1.0); break;
    case TP_OP_CDIV: *pu = vpart(tp_div(r, w, u), -1.0); break;
    case TP_OP_POWC: *pu = vpart(tp_powc(r, u, c - 1.0), c); break;
    case TP_OP_POWI:
        *pu = c == 1.0 ? cpart(1.0)
                       : vpart(tp_powi(r, u, (int)c - 1), c);
        break;
    case TP_OP_SQR: *pu = vpart(u, 2.0); break;
    case TP_OP_SQRT: *pu = vpart(tp_cdiv(r, 1.0, w), 0.5); break;
    case TP_OP_EXP: *pu = vpart(w, 1.0); break;
    case TP_OP_LOG: *pu = vpart(tp_cdiv(r, 1.0, u), 1.0); break;
    case TP_OP_SIN: *pu = vpart(tp_cos(r, u), 1.0); break;
    case TP_OP_COS: *pu = vpart(tp_sin(r, u), -1.0); break;
    case TP_OP_TAN: *pu = vpart(tp_addc(r, tp_sqr(r, w), 1.0), 1.0); break;
    case TP_OP_ASIN:
    case TP_OP_ACOS:
        *pu = vpart(tp_cdiv(r, 1.0, tp_sqrt(r, tp_csub(r, 1.0,
                                                         tp_sqr(r, u)))),
                    op == TP_OP_ASIN ? 1.0 : -1.0);
        break;
    case TP_OP_ATAN:
        *pu = vpart(tp_cdiv(r, 1.0, tp_addc(r, tp_sqr(r, u), 1.0)), 1.0);
        break;
    case TP_OP_SINH: *pu = vpart(tp_cosh(r, u), 1.0); break;
    case TP_OP_COSH: *pu = vpart(tp_sinh(r, u), 1.0); break;
    case TP_OP_TANH: *pu = vpart(tp_csub(r, 1.0, tp_sqr(r, w)), 1.0); break;
    /* sign(u) as u / |u|: outside ABS's domain (u = 0) this is NaN where
     * the sweeps take 0 */
    case TP_OP_ABS: *pu = vpart(tp_div(r, u, w), 1.0); break;
    default: *pu = cpart(0.0); break;
    }
}

/* d * p, or zero when d is. */
static tp_val times(tp_rec *r, tp_val d, part p)
{
    tp_val m;
    if (is_zero(d) || (is_zero(p.v) && p.k == 0.0))
        return zero_val;
    if (is_zero(p.v)) {
        if (p.k == 1.0)
            return d;
        if (p.k == -1.0)
            return tp_neg(r, d);
        return tp_mulc(r, d, p.k);
    }
    m = tp_mul(r, d, p.v);
    if (p.k == -1.0)
        return tp_neg(r, m);
    return p.k == 1.0 ? m : tp_mulc(r, m, p.k);
}

/* acc + term, either of them possibly zero. */
static tp_val plus(tp_rec *r, tp_val acc, tp_val term)
{
    if (is_zero(term))
        return acc;
    if (is_zero(acc))
        return term;
    return tp_add(r, acc, term);
}

typedef struct replay_args {
    const tp_val *x, *par;   /* inputs */
    const tp_val *dx, *dpar; /* tangent seed (jvp); NULL: zero */
    const tp_val *w;         /* output weights (vjp) */
    tp_val *y, *dy, *gx, *gpar;
    bool tangent, adjoint;
} replay_args;

/* The handle of an input array entry, checked against r. */
static bool input_ok(tp_rec *r, const tp_val *a, uint32_t k,
                     const char *fn, const char *what)
{
    if (a[k].tag == 0 || a[k].tag != r->tag || a[k].id >= r->n_ids) {
        tp__rec_fail(r, a[k].tag == r->tag || a[k].tag == 0
                            ? TP_ERR_HANDLE : TP_ERR_FOREIGN,
                     "%s: %s[%u] is not a valid handle of this context",
                     fn, what, (unsigned)k);
        return false;
    }
    return true;
}

static int check_inputs(tp_rec *r, const tp_tape *t, const replay_args *a,
                        const char *fn)
{
    uint32_t k;
    if (t->n_indep > 0 && !a->x)
        return tp__rec_fail(r, TP_ERR_NULL, "%s: x is NULL", fn);
    for (k = 0; k < t->n_indep; k++)
        if (!input_ok(r, a->x, k, fn, "x") ||
            (a->dx && !input_ok(r, a->dx, k, fn, "dx")))
            return r->status;
    for (k = 0; k < t->n_param; k++)
        if ((a->par && !input_ok(r, a->par, k, fn, "par")) ||
            (a->dpar && !input_ok(r, a->dpar, k, fn, "dpar")))
            return r->status;
    if (a->adjoint) {
        if (!a->w)
            return tp__rec_fail(r, TP_ERR_NULL, "%s: w is NULL", fn);
        for (k = 0; k < t->n_out; k++)
            if (!input_ok(r, a->w, k, fn, "w"))
                return r->status;
    }
    return TP_OK;
}

static tp_val leaf_value(tp_rec *r, const tp_tape *t, uint32_t i,
                         const replay_args *a)
{
    uint32_t k = t->a0[i];
    switch (t->opc[i]) {
    case TP_OP_INDEP: return a->x[k];
    case TP_OP_PARAM:
        return a->par ? a->par[k]
                      : tp_param(r, t->param_name[k], t->param_dflt[k]);
    default: return tp_const(r, t->konst[k]);
    }
}

static tp_val leaf_tangent(const tp_tape *t, uint32_t i,
                           const replay_args *a)
{
    uint32_t k = t->a0[i];
    if (t->opc[i] == TP_OP_INDEP && a->dx)
        return a->dx[k];
    if (t->opc[i] == TP_OP_PARAM && a->dpar)
        return a->dpar[k];
    return zero_val;
}

/* The constant an op carries (UCONST) or its exponent (UINT). */
static double op_const(const tp_tape *t, uint32_t i)
{
    switch (tp__opinfo[t->opc[i]].kind) {
    case TP_KIND_UCONST: return t->konst[t->a1[i]];
    case TP_KIND_UINT: return (double)(int32_t)t->a1[i];
    default: return 0.0;
    }
}

static bool is_binary(const tp_tape *t, uint32_t i)
{
    return tp__opinfo[t->opc[i]].kind == TP_KIND_BINARY;
}

static void forward(tp_rec *r, const tp_tape *t, const replay_args *a,
                    tp_val *v, tp_val *d)
{
    uint32_t i;
    for (i = 0; i < t->n_ops && r->status >= 0; i++) {
        int op = t->opc[i];
        tp_val u, tv;
        part pu, pt;
        if (tp__opinfo[op].kind == TP_KIND_LEAF) {
            v[i] = leaf_value(r, t, i, a);
            if (d)
                d[i] = leaf_tangent(t, i, a);
            continue;
        }
        u = v[t->a0[i]];
        tv = is_binary(t, i) ? v[t->a1[i]] : u;
        v[i] = tp__rec_op(r, op, u, tv, op_const(t, i));
        if (!d)
            continue;
        if (is_zero(d[t->a0[i]]) && (!is_binary(t, i) ||
                                     is_zero(d[t->a1[i]]))) {
            d[i] = zero_val;
            continue;
        }
        partials(r, op, u, tv, op_const(t, i), v[i], &pu, &pt);
        d[i] = times(r, d[t->a0[i]], pu);
        if (is_binary(t, i))
            d[i] = plus(r, d[i], times(r, d[t->a1[i]], pt));
    }
}

/* Adjoints from the output weights back to the leaves. */
static void reverse(tp_rec *r, const tp_tape *t, const replay_args *a,
                    const tp_val *v, tp_val *adj)
{
    uint32_t o, i;
    for (o = 0; o < t->n_out; o++)
        adj[t->out_slot[o]] = plus(r, adj[t->out_slot[o]], a->w[o]);
    for (i = t->n_ops; i-- > 0 && r->status >= 0;) {
        int op = t->opc[i];
        part pu, pt;
        tp_val u, tv;
        if (is_zero(adj[i]) || tp__opinfo[op].kind == TP_KIND_LEAF)
            continue;
        u = v[t->a0[i]];
        tv = is_binary(t, i) ? v[t->a1[i]] : u;
        partials(r, op, u, tv, op_const(t, i), v[i], &pu, &pt);
        adj[t->a0[i]] = plus(r, adj[t->a0[i]], times(r, adj[i], pu));
        if (is_binary(t, i))
            adj[t->a1[i]] = plus(r, adj[t->a1[i]], times(r, adj[i], pt));
    }
}

/* A result handle: zero-tagged values become the constant 0. */
static tp_val result(tp_rec *r, tp_val a)
{
    return is_zero(a) ? tp_const(r, 0.0) : a;
}

static int replay(tp_rec *r, const tp_tape *t, replay_args *a,
                  const char *fn)
{
    tp_val *v, *d = NULL;
    size_t bytes;
    uint32_t k, i;
    int st;
    if (!r)
        return TP_ERR_NULL;
    if (r->status < 0)
        return r->status;
    if (!t)
        return tp__rec_fail(r, TP_ERR_NULL, "%s: the tape is NULL", fn);
    if ((a->tangent && !a->dy) || (a->adjoint && !a->gx && !a->gpar))
        return tp__rec_fail(r, TP_ERR_NULL, "%s: no result array", fn);
    st = check_inputs(r, t, a, fn);
    if (st < 0)
        return st;
    bytes = tp__mulsz(t->n_ops, sizeof *v);
    v = tp__calloc(&r->al, t->n_ops, sizeof *v);
    if (v && (a->tangent || a->adjoint)) {
        d = tp__calloc(&r->al, t->n_ops, sizeof *d);
        if (!d) {
            tp__free(&r->al, v, bytes);
            v = NULL;
        }
    }
    if (!v)
        return tp__rec_fail(r, TP_ERR_NOMEM,
                            "%s: out of memory for a tape of %u ops", fn,
                            (unsigned)t->n_ops);
    forward(r, t, a, v, a->tangent ? d : NULL);
    if (a->adjoint && r->status >= 0)
        reverse(r, t, a, v, d);
    if (r->status >= 0) {
        for (k = 0; k < t->n_out; k++) {
            if (a->y)
                a->y[k] = v[t->out_slot[k]];
            if (a->tangent)
                a->dy[k] = result(r, d[t->out_slot[k]]);
        }
        /* the leaves' adjoints: independents are slots 0 .. n_indep-1,
         * parameters the next n_param slots */
        for (i = 0; a->adjoint && i < t->n_indep + t->n_param; i++) {
            tp_val g = result(r, d[i]);
            if (i < t->n_indep && a->gx)
                a->gx[i] = g;
            else if (i >= t->n_indep && a->gpar)
                a->gpar[i - t->n_indep] = g;
        }
    }
    tp__free(&r->al, v, bytes);
    if (d)
        tp__free(&r->al, d, bytes);
    return r->status;
}

int tp_call(tp_rec *r, const tp_tape *t, const tp_val *x,
              const tp_val *par, tp_val *y)
{
    replay_args a;
    memset(&a, 0, sizeof a);
    a.x = x;
    a.par = par;
    a.y = y;
    if (r && !y)
        return tp__rec_fail(r, TP_ERR_NULL, "tp_call: y is NULL");
    return replay(r, t, &a, "tp_call");
}

int tp_call_jvp(tp_rec *r, const tp_tape *t, const tp_val *x,
                  const tp_val *par, const tp_val *dx, const tp_val *dpar,
                  tp_val *y, tp_val *dy)
{
    replay_args a;
    memset(&a, 0, sizeof a);
    a.x = x;
    a.par = par;
    a.dx = dx;
    a.dpar = dpar;
    a.y = y;
    a.dy = dy;
    a.tangent = true;
    return replay(r, t, &a, "tp_call_jvp");
}

int tp_call_vjp(tp_rec *r, const tp_tape *t, const tp_val *x,
                  const tp_val *par, const tp_val *w, tp_val *y, tp_val *gx,
                  tp_val *gpar)
{
    replay_args a;
    memset(&a, 0, sizeof a);
    a.x = x;
    a.par = par;
    a.w = w;
    a.y = y;
    a.gx = gx;
    a.gpar = gpar;
    a.adjoint = true;
    return replay(r, t, &a, "tp_call_vjp");
}
