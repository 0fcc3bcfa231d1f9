/* record.c - the recorder backend: appends ops to a growing
 * struct-of-arrays op stream.
 *
 * While recording it
 *   - folds ops whose operands are all constants (parameters are not
 *     constants: they may change between replays);
 *   - simplifies with constants: x + 0 = x, x * 1 = x, x * 0 = 0, x - x = 0,
 *     x + x = 2 x, x * x = x^2, op(x, c) becomes the cheaper one-operand op
 *     with c in the constant pool (MULC, ADDC, CSUB, CDIV, POWC, POWI);
 *   - hash-conses: an op equal to one already recorded (same opcode and
 *     operands, commutative operands sorted) returns the existing slot, so
 *     common subexpressions exist once. Constants are pooled by value.
 * Ids of this backend are slots of the raw op stream; the INDEP ops are the
 * first n_indep slots. finalize.c turns the stream into a tape.
 */
#include <math.h>
#include <string.h>

#include "op_math.h"
#include "tape_internal.h"

typedef struct tp_recorder {
    tp_rec base;
    uint8_t *opc;         /* [n] raw op stream */
    uint32_t *a0, *a1;    /* [n] */
    size_t n, cap_opc, cap_a0, cap_a1;
    double *konst;        /* [nk] constant pool, distinct values */
    uint32_t *kslot;      /* [nk] CONST slot of each pool entry or NO_SLOT */
    size_t nk, cap_k, cap_kslot;
    uint32_t *ohash;      /* open addressing: op slot + 1, 0 empty */
    size_t ohcap, ohn;
    uint32_t *khash;      /* open addressing: pool index + 1, 0 empty */
    size_t khcap, khn;
    unsigned char *group; /* [n_indep] */
    size_t n_cse_hits, n_folded;
} tp_recorder;

static uint64_t mix64(uint64_t h)
{
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ull;
    h ^= h >> 33;
    return h;
}

static uint64_t op_hash(unsigned op, uint32_t a0, uint32_t a1)
{
    return mix64(((uint64_t)a0 << 32 | a1) ^ ((uint64_t)op << 56) ^
                 (uint64_t)op * 0x9e3779b97f4a7c15ull);
}

static uint64_t dbl_bits(double c)
{
    uint64_t b;
    memcpy(&b, &c, sizeof b);
    return b;
}

/* ---- raw stream and hash tables --------------------------------------- */

static uint32_t fail_nomem(tp_recorder *R)
{
    tp__rec_fail(&R->base, TP_ERR_NOMEM, "recorder: out of memory");
    return TP_NO_SLOT;
}

static uint32_t push_op(tp_recorder *R, unsigned op, uint32_t a0, uint32_t a1)
{
    const tp_allocator *al = &R->base.al;
    if (R->n >= TP_MAX_OPS) {
        tp__rec_fail(&R->base, TP_ERR_TOOBIG,
                     "recorder: more than %u ops", (unsigned)TP_MAX_OPS);
        return TP_NO_SLOT;
    }
    if (tp__grow(al, (void **)&R->opc, 1, &R->cap_opc, R->n + 1) ||
        tp__grow(al, (void **)&R->a0, 4, &R->cap_a0, R->n + 1) ||
        tp__grow(al, (void **)&R->a1, 4, &R->cap_a1, R->n + 1))
        return fail_nomem(R);
    R->opc[R->n] = (uint8_t)op;
    R->a0[R->n] = a0;
    R->a1[R->n] = a1;
    R->base.n_ids = (uint32_t)(R->n + 1);
    return (uint32_t)R->n++;
}

/* Rebuild an open-addressing table of size ncap from its old entries. */
static int rehash(tp_recorder *R, uint32_t **tab, size_t *cap, size_t ncap,
                  uint64_t (*key)(const tp_recorder *, uint32_t))
{
    uint32_t *nt = tp__calloc(&R->base.al, ncap, sizeof *nt);
    size_t i;
    if (!nt)
        return -1;
    for (i = 0; i < *cap; i++) {
        uint32_t e = (*tab)[i];
        size_t j;
        if (!e)
            continue;
        j = (size_t)key(R, e - 1) & (ncap - 1);
        while (nt[j])
            j = (j + 1) & (ncap - 1);
        nt[j] = e;
    }
    tp__free(&R->base.al, *tab, *cap * sizeof **tab);
    *tab = nt;
    *cap = ncap;
    return 0;
}

static uint64_t op_key(const tp_recorder *R, uint32_t s)
{
    return op_hash(R->opc[s], R->a0[s], R->a1[s]);
}

static uint64_t k_key(const tp_recorder *R, uint32_t k)
{
    return mix64(dbl_bits(R->konst[k]));
}

/* Keep a table at most half full; false on allocation failure. */
static bool reserve(tp_recorder *R, uint32_t **tab, size_t *cap, size_t used,
                    uint64_t (*key)(const tp_recorder *, uint32_t))
{
    if (2 * (used + 1) <= *cap)
        return true;
    if (*cap > SIZE_MAX / 4)
        return false;
    return rehash(R, tab, cap, *cap ? 2 * *cap : 256, key) == 0;
}

/* Pool index of constant c, adding it if new; UINT32_MAX on failure. */
static uint32_t pool_index(tp_recorder *R, double c)
{
    uint64_t b = dbl_bits(c);
    size_t j;
    if (!reserve(R, &R->khash, &R->khcap, R->khn, k_key)) {
        fail_nomem(R);
        return UINT32_MAX;
    }
    j = (size_t)mix64(b) & (R->khcap - 1);
    while (R->khash[j]) {
        uint32_t k = R->khash[j] - 1;
        if (dbl_bits(R->konst[k]) == b)
            return k;
        j = (j + 1) & (R->khcap - 1);
    }
    if (R->nk >= TP_MAX_OPS ||
        tp__grow(&R->base.al, (void **)&R->konst, sizeof(double), &R->cap_k,
                 R->nk + 1) ||
        tp__grow(&R->base.al, (void **)&R->kslot, 4, &R->cap_kslot,
                 R->nk + 1)) {
        fail_nomem(R);
        return UINT32_MAX;
    }
    R->konst[R->nk] = c;
    R->kslot[R->nk] = TP_NO_SLOT;
    R->khash[j] = (uint32_t)R->nk + 1;
    R->khn++;
    return (uint32_t)R->nk++;
}

/* Emit a non-leaf op, or find the identical op already recorded. */
static uint32_t emit(tp_recorder *R, unsigned op, uint32_t a0, uint32_t a1)
{
    uint64_t h = op_hash(op, a0, a1);
    size_t j;
    uint32_t s;
    if (!reserve(R, &R->ohash, &R->ohcap, R->ohn, op_key))
        return fail_nomem(R);
    j = (size_t)h & (R->ohcap - 1);
    while (R->ohash[j]) {
        s = R->ohash[j] - 1;
        if (R->opc[s] == op && R->a0[s] == a0 && R->a1[s] == a1) {
            R->n_cse_hits++;
            return s;
        }
        j = (j + 1) & (R->ohcap - 1);
    }
    s = push_op(R, op, a0, a1);
    if (s != TP_NO_SLOT) {
        R->ohash[j] = s + 1;
        R->ohn++;
    }
    return s;
}

/* ---- backend functions ------------------------------------------------ */

static uint32_t rec_constant(tp_rec *base, double c)
{
    tp_recorder *R = (tp_recorder *)base;
    uint32_t k = pool_index(R, c);
    if (k == UINT32_MAX)
        return TP_NO_SLOT;
    if (R->kslot[k] == TP_NO_SLOT)
        R->kslot[k] = push_op(R, TP_OP_CONST, k, 0);
    return R->kslot[k];
}

static bool is_const(const tp_recorder *R, uint32_t s, double *c)
{
    if (R->opc[s] != TP_OP_CONST)
        return false;
    *c = R->konst[R->a0[s]];
    return true;
}

static uint32_t fold(tp_recorder *R, int op, double u, double t, double c)
{
    R->n_folded++;
    return rec_constant(&R->base, tp__op_value(op, u, t, c));
}

static bool is_pow2(double c)
{
    int e;
    return isfinite(c) && c != 0.0 && fabs(frexp(c, &e)) == 0.5;
}

static uint32_t rec_apply(tp_rec *base, int op, uint32_t u, uint32_t t,
                          double c);

/* Rewrite as another op, counting the simplification. */
static uint32_t rewrite(tp_recorder *R, int op, uint32_t u, uint32_t t,
                        double c)
{
    R->n_folded++;
    return rec_apply(&R->base, op, u, t, c);
}

static uint32_t apply_uconst(tp_recorder *R, int op, uint32_t u, double c)
{
    uint32_t k;
    switch (op) {
    case TP_OP_ADDC:
        if (c == 0.0) {
            R->n_folded++;
            return u;
        }
        break;
    case TP_OP_MULC:
        if (c == 1.0) {
            R->n_folded++;
            return u;
        }
        if (c == 0.0 && !signbit(c))
            return fold(R, TP_OP_MULC, 0.0, 0.0, 0.0); /* x * 0 = 0 */
        if (c == -1.0)
            return rewrite(R, TP_OP_NEG, u, 0, 0.0);
        break;
    case TP_OP_CSUB:
        if (c == 0.0 && !signbit(c))
            return rewrite(R, TP_OP_NEG, u, 0, 0.0);
        break;
    default: break;
    }
    k = pool_index(R, c);
    return k == UINT32_MAX ? TP_NO_SLOT : emit(R, (unsigned)op, u, k);
}

static uint32_t apply_binary(tp_recorder *R, int op, uint32_t u, uint32_t t)
{
    double cu, ct;
    bool ku = is_const(R, u, &cu), kt = is_const(R, t, &ct);
    if (ku && kt)
        return fold(R, op, cu, ct, 0.0);
    switch (op) {
    case TP_OP_ADD:
        if (kt)
            return rewrite(R, TP_OP_ADDC, u, 0, ct);
        if (ku)
            return rewrite(R, TP_OP_ADDC, t, 0, cu);
        if (u == t)
            return rewrite(R, TP_OP_MULC, u, 0, 2.0);
        break;
    case TP_OP_SUB:
        if (kt)
            return rewrite(R, TP_OP_ADDC, u, 0, -ct);
        if (ku)
            return rewrite(R, TP_OP_CSUB, t, 0, cu);
        if (u == t)
            return fold(R, TP_OP_MULC, 0.0, 0.0, 0.0); /* x - x = 0 */
        break;
    case TP_OP_MUL:
        if (kt)
            return rewrite(R, TP_OP_MULC, u, 0, ct);
        if (ku)
            return rewrite(R, TP_OP_MULC, t, 0, cu);
        if (u == t)
            return rewrite(R, TP_OP_SQR, u, 0, 0.0);
        break;
    case TP_OP_DIV:
        if (ku)
            return rewrite(R, TP_OP_CDIV, t, 0, cu);
        if (kt && is_pow2(ct)) /* exact: x / 2^k = x * 2^-k */
            return rewrite(R, TP_OP_MULC, u, 0, 1.0 / ct);
        break;
    case TP_OP_POW:
        if (kt) {
            if (ct == nearbyint(ct) && fabs(ct) <= 1024.0)
                return rewrite(R, TP_OP_POWI, u, 0, ct);
            return rewrite(R, TP_OP_POWC, u, 0, ct);
        }
        break;
    default: break;
    }
    if ((tp__opinfo[op].flags & TP_FLAG_COMM) && t < u) {
        uint32_t s = u;
        u = t;
        t = s;
    }
    return emit(R, (unsigned)op, u, t);
}

static uint32_t rec_apply(tp_rec *base, int op, uint32_t u, uint32_t t,
                          double c)
{
    tp_recorder *R = (tp_recorder *)base;
    double cu;
    int k;
    switch (tp__opinfo[op].kind) {
    case TP_KIND_UNARY:
        if (is_const(R, u, &cu))
            return fold(R, op, cu, 0.0, 0.0);
        if (op == TP_OP_NEG && R->opc[u] == TP_OP_NEG) {
            R->n_folded++;
            return R->a0[u];
        }
        return emit(R, (unsigned)op, u, 0);
    case TP_KIND_UCONST:
        if (is_const(R, u, &cu))
            return fold(R, op, cu, 0.0, c);
        return apply_uconst(R, op, u, c);
    case TP_KIND_UINT:
        k = (int)c;
        if (k == 0)
            return fold(R, TP_OP_POWI, 1.0, 0.0, 0.0); /* x^0 = 1 */
        if (k == 1) {
            R->n_folded++;
            return u;
        }
        if (is_const(R, u, &cu))
            return fold(R, op, cu, 0.0, c);
        if (k == 2)
            return rewrite(R, TP_OP_SQR, u, 0, 0.0);
        return emit(R, (unsigned)op, u, (uint32_t)k);
    case TP_KIND_BINARY:
        return apply_binary(R, op, u, t);
    default:
        tp__rec_fail(base, TP_ERR_BACKEND, "recorder: leaf op in apply");
        return TP_NO_SLOT;
    }
}

static uint32_t rec_param(tp_rec *base, int k, double value)
{
    (void)value; /* the default is kept by the common layer */
    return push_op((tp_recorder *)base, TP_OP_PARAM, (uint32_t)k, 0);
}

static int rec_begin(tp_rec *base, const double *x)
{
    (void)base;
    (void)x;
    return TP_OK;
}

static void rec_destroy(tp_rec *base)
{
    tp_recorder *R = (tp_recorder *)base;
    const tp_allocator al = base->al;
    tp__free(&al, R->opc, R->cap_opc);
    tp__free(&al, R->a0, R->cap_a0 * 4);
    tp__free(&al, R->a1, R->cap_a1 * 4);
    tp__free(&al, R->konst, R->cap_k * sizeof(double));
    tp__free(&al, R->kslot, R->cap_kslot * 4);
    tp__free(&al, R->ohash, R->ohcap * 4);
    tp__free(&al, R->khash, R->khcap * 4);
    tp__free(&al, R->group, (size_t)base->n_indep);
    tp__rec_release(base);
    tp__free(&al, R, sizeof *R);
}

static const tp_backend recorder_backend = {
    "recorder", rec_begin, rec_param, rec_constant, rec_apply, NULL,
    rec_destroy, NULL,
};

int tp_recorder_new(tp_rec **out, int n_indep, const unsigned char *group,
                    const tp_allocator *al)
{
    tp_allocator a = tp__allocator(al);
    tp_recorder *R;
    int i;
    if (!out)
        return TP_ERR_NULL;
    *out = NULL;
    if (n_indep < 0 || (uint32_t)n_indep >= TP_MAX_OPS / 2)
        return TP_ERR_SIZE;
    if (group)
        for (i = 0; i < n_indep; i++)
            if (group[i] >= TP_MAX_GROUPS)
                return TP_ERR_SIZE;
    R = tp__calloc(&a, 1, sizeof *R);
    if (!R)
        return TP_ERR_NOMEM;
    tp__rec_init(&R->base, &recorder_backend, n_indep, &a);
    R->group = tp__calloc(&a, (size_t)n_indep, 1);
    if (!R->group) {
        rec_destroy(&R->base);
        return TP_ERR_NOMEM;
    }
    if (group)
        memcpy(R->group, group, (size_t)n_indep);
    for (i = 0; i < n_indep; i++) {
        if (push_op(R, TP_OP_INDEP, (uint32_t)i, 0) == TP_NO_SLOT) {
            rec_destroy(&R->base);
            return TP_ERR_NOMEM;
        }
    }
    *out = &R->base;
    return TP_OK;
}

int tp_recorder_finish(tp_rec *base, tp_tape **out)
{
    tp_recorder *R = (tp_recorder *)base;
    tp_rawtape raw;
    int rc;
    if (!out)
        return base ? tp__rec_fail(base, TP_ERR_NULL,
                                   "tp_recorder_finish: out is NULL")
                    : TP_ERR_NULL;
    *out = NULL;
    if (!base)
        return TP_ERR_NULL;
    if (base->be != &recorder_backend)
        return tp__rec_fail(base, TP_ERR_BACKEND,
                            "tp_recorder_finish: not a recorder");
    if (base->finished)
        return tp__rec_fail(base, TP_ERR_FINISHED,
                            "tp_recorder_finish: already finished");
    if (base->status < 0)
        return base->status;
    if (base->n_outs == 0)
        return tp__rec_fail(base, TP_ERR_EMPTY,
                            "tp_recorder_finish: no outputs were declared");
    raw.opc = R->opc;
    raw.a0 = R->a0;
    raw.a1 = R->a1;
    raw.n_ops = R->n;
    raw.konst = R->konst;
    raw.n_const = R->nk;
    raw.group = R->group;
    raw.n_indep = (uint32_t)base->n_indep;
    raw.params = base->params;
    raw.n_params = base->n_params;
    raw.outs = base->outs;
    raw.n_outs = base->n_outs;
    raw.n_cse_hits = R->n_cse_hits;
    raw.n_folded = R->n_folded;
    rc = tp__tape_build(&raw, &base->al, out, base->msg);
    if (rc < 0) {
        base->status = rc;
        return rc;
    }
    base->finished = true;
    return TP_OK;
}
