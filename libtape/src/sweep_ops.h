/* sweep_ops.h - what one op does in each sweep: its value, its tangent
 * row, its adjoint and its adjoint-tangent row, its Taylor coefficients.
 *
 * The single source of every sweep's per-op work. The interpreter
 * (forward.c, reverse.c) calls these functions in a loop over the tape;
 * a compiled tape (codegen.c) calls them once per op with the op's code,
 * dependency byte and operands as constants, so the compiler folds the
 * dispatch away and both paths do the same arithmetic in the same order.
 * For that reason this header is also pasted, as text, into every
 * generated source: it must depend on nothing but the C library, op_math.h
 * and tape_ops.h, and it must not change the arithmetic of an op without
 * the compiled tapes' checks noticing (they compare the two paths).
 *
 * Conventions: a sweep's arrays and sizes travel in a tp_kx; op i writes
 * slot i, u and t are its operand slots (or constant index / exponent, see
 * tape_ops.h); fl is its dependency byte. Rows are P doubles apart and pr
 * (a multiple of TP_LANES) columns are swept.
 */
#ifndef TAPE_SWEEP_OPS_H
#define TAPE_SWEEP_OPS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "op_math.h"

#ifndef TP_KERNEL
#if defined(__GNUC__)
#define TP_KERNEL static inline __attribute__((always_inline))
#else
#define TP_KERNEL static inline
#endif
#endif
/* The row kernels (loops over the directions). A compiled tape of wide
 * rows makes them functions of their own: inlined, every op's loops
 * would be compiled again (the compiler's time grows with the loops). */
#ifndef TP_ROW
#define TP_ROW TP_KERNEL
#endif

/* Direction rows are swept in whole groups of TP_LANES columns (the row
 * stride P is a multiple of it); the padding columns hold zeros. A fixed
 * inner trip count lets the compiler emit straight vector code with no
 * remainder loop, which matters for the few directions of small systems. */
#define FOR_LANES(k, pr)                                                   \
    for (int k##4_ = 0; k##4_ < (pr); k##4_ += TP_LANES)                   \
        for (int k = k##4_; k < k##4_ + TP_LANES; k++)

#define TP_UPASSIVE(fl) ((fl) & TP_DEP_UPASSIVE)
#define TP_TPASSIVE(fl) ((fl) & TP_DEP_TPASSIVE)

/* The arrays and sizes of one sweep over a workspace. */
typedef struct tp_kx {
    const double *K;     /* constant pool */
    double *v, *aux;     /* values and auxiliary values */
    double *adj;         /* adjoints */
    double *tan, *atan;  /* tangent and adjoint-tangent rows */
    uint8_t *anz;        /* 0: that adjoint-tangent row is known zero */
    double *d1, *d2;     /* Taylor coefficients */
    size_t P;            /* row stride */
    int pr;              /* columns swept, a multiple of TP_LANES */
    unsigned mask;       /* the seeded groups */
} tp_kx;

static inline int tp__lanes(int p)
{
    return (p + TP_LANES - 1) / TP_LANES * TP_LANES;
}

/* An op's operand kind and linearity, from the op table (a read of a
 * constant table at a constant index folds to a constant). */
enum { TP_COMM_ = TP_FLAG_COMM, TP_LIN_ = TP_FLAG_LIN, TP_KINK_ = TP_FLAG_KINK };
static const unsigned char tp__kind_of[TP_OP_COUNT] = {
#define TP_OP_KIND_(name, kind, flags, dom, text) TP_KIND_##kind,
    TP_OP_TABLE(TP_OP_KIND_)
#undef TP_OP_KIND_
};
static const unsigned char tp__linear_of[TP_OP_COUNT] = {
#define COMM TP_COMM_
#define LIN TP_LIN_
#define KINK TP_KINK_
#define TP_OP_LIN_(name, kind, flags, dom, text) ((flags) & TP_LIN_) != 0,
    TP_OP_TABLE(TP_OP_LIN_)
#undef TP_OP_LIN_
#undef COMM
#undef LIN
#undef KINK
};

TP_KERNEL int tp__op_kind(unsigned op) { return tp__kind_of[op]; }
TP_KERNEL bool tp__op_linear(unsigned op) { return tp__linear_of[op]; }

/* a1 of a UINT op holds the exponent in two's complement. */
static inline int tp__u2i(uint32_t t)
{
    return t <= (uint32_t)INT32_MAX ? (int)t : -(int)(UINT32_MAX - t) - 1;
}

/* The constant operand of an op: pool entry (UCONST), exponent (UINT) or 0. */
TP_KERNEL double tp__op_cval(const double *K, unsigned op, uint32_t t)
{
    switch (tp__op_kind(op)) {
    case TP_KIND_UCONST: return K[t];
    case TP_KIND_UINT: return (double)tp__u2i(t);
    default: return 0.0;
    }
}

/* ---- per-op functions ---------------------------------------------------
 *
 * Each kernel (value, fwd1, adj1, rev2, taylor2) has one function per
 * common op, named tp__<kernel>_<OP>, and one generic function
 * tp__<kernel>_GEN for the others, all with the signature
 * (x, i, op, fl, u, t); tp__k_<kernel> dispatches on op. A compiled tape
 * calls the op's own function directly, so the compiler sees only that
 * op's few lines, never a whole switch (which made compiling grow with
 * the kernel's size times the ops). TP_COMMON_OPS lists the ops that have
 * functions of their own, for the dispatchers here and for codegen.c. */
#define TP_COMMON_OPS(X)                                                   \
    X(ADD) X(SUB) X(MUL) X(NEG) X(ADDC) X(MULC) X(CSUB) X(SQR) X(SIN) X(COS)

#define TP_OPFN(kern, OP)                                                  \
    TP_KERNEL void tp__##kern##_##OP(const tp_kx *x, uint32_t i,           \
                                     unsigned op, unsigned fl, uint32_t u, \
                                     uint32_t t)
#define TP_UNUSED4 (void)x, (void)op, (void)fl, (void)u, (void)t

/* The dispatcher of kernel kern. */
#define TP_DISPATCH(kern)                                                  \
    TP_KERNEL void tp__k_##kern(const tp_kx *x, uint32_t i, unsigned op,   \
                                unsigned fl, uint32_t u, uint32_t t)       \
    {                                                                      \
        switch (op) {                                                      \
            TP_COMMON_OPS(TP_CASE_##kern)                                  \
        default: tp__##kern##_GEN(x, i, op, fl, u, t); break;              \
        }                                                                  \
    }
#define TP_CASE_value(OP) case TP_OP_##OP: tp__value_##OP(x, i, op, fl, u, t); break;
#define TP_CASE_fwd1(OP) case TP_OP_##OP: tp__fwd1_##OP(x, i, op, fl, u, t); break;
#define TP_CASE_rev1(OP) case TP_OP_##OP: tp__rev1_##OP(x, i, op, fl, u, t); break;
#define TP_CASE_rev2(OP) case TP_OP_##OP: tp__rev2_##OP(x, i, op, fl, u, t); break;

/* ---- values ------------------------------------------------------------ */

/* Value of a generic op from its operands' values (and aux). */
TP_KERNEL double tp__gen_value(const double *K, const double *v, double *aux,
                               uint32_t i, unsigned op, uint32_t u,
                               uint32_t t)
{
    if (op == TP_OP_CONST)
        return K[u];
    return tp__op_value_aux(
        (int)op, v[u], tp__op_kind(op) == TP_KIND_BINARY ? v[t] : 0.0,
        tp__op_cval(K, op, t), &aux[i]);
}

/* sin and cos: a paired op (t != 0) reads its partner's results (the
 * partner's aux is this value and vice versa). */
TP_KERNEL double tp__trig_value(double *v, double *aux, uint32_t i,
                                unsigned op, uint32_t u, uint32_t t)
{
    if (t) {
        aux[i] = v[t - 1];
        return aux[t - 1];
    }
    return tp__op_value_aux((int)op, v[u], 0.0, 0.0, &aux[i]);
}

TP_OPFN(value, ADD) { TP_UNUSED4; x->v[i] = x->v[u] + x->v[t]; }
TP_OPFN(value, SUB) { TP_UNUSED4; x->v[i] = x->v[u] - x->v[t]; }
TP_OPFN(value, MUL) { TP_UNUSED4; x->v[i] = x->v[u] * x->v[t]; }
TP_OPFN(value, NEG) { TP_UNUSED4; x->v[i] = -x->v[u]; }
TP_OPFN(value, ADDC) { TP_UNUSED4; x->v[i] = x->v[u] + x->K[t]; }
TP_OPFN(value, MULC) { TP_UNUSED4; x->v[i] = x->K[t] * x->v[u]; }
TP_OPFN(value, CSUB) { TP_UNUSED4; x->v[i] = x->K[t] - x->v[u]; }
TP_OPFN(value, SQR) { TP_UNUSED4; x->v[i] = x->v[u] * x->v[u]; }
TP_OPFN(value, SIN) { TP_UNUSED4; x->v[i] = tp__trig_value(x->v, x->aux, i, TP_OP_SIN, u, t); }
TP_OPFN(value, COS) { TP_UNUSED4; x->v[i] = tp__trig_value(x->v, x->aux, i, TP_OP_COS, u, t); }
TP_OPFN(value, GEN) { TP_UNUSED4; x->v[i] = tp__gen_value(x->K, x->v, x->aux, i, op, u, t); }
TP_DISPATCH(value)

/* Partials of a generic op from stored values. */
TP_KERNEL void tp__gen_partials(const double *K, const double *v,
                                const double *aux, uint32_t i, unsigned op,
                                uint32_t u, uint32_t t, tp_partials *d)
{
    tp__op_partials((int)op, v[u],
                    tp__op_kind(op) == TP_KIND_BINARY ? v[t] : 0.0,
                    tp__op_cval(K, op, t), v[i], aux[i], d);
}

/* ---- first-order forward ---------------------------------------------- */

/* Row kernels: r is the row being written, a and b rows of operands (which
 * precede r, so never alias it; a and b may be the same row). */
TP_ROW void tp__row_copy(double *restrict r, const double *restrict a,
                            int pr)
{
    FOR_LANES(k, pr) r[k] = a[k];
}

TP_ROW void tp__row_scale(double *restrict r, const double *restrict a,
                             double fa, int pr)
{
    FOR_LANES(k, pr) r[k] = fa * a[k];
}

TP_ROW void tp__row_add(double *restrict r, const double *restrict a,
                           const double *restrict b, int pr)
{
    FOR_LANES(k, pr) r[k] = a[k] + b[k];
}

TP_ROW void tp__row_sub(double *restrict r, const double *restrict a,
                           const double *restrict b, int pr)
{
    FOR_LANES(k, pr) r[k] = a[k] - b[k];
}

TP_ROW void tp__row_comb(double *restrict r, const double *restrict a,
                            const double *restrict b, double fa, double fb,
                            int pr)
{
    FOR_LANES(k, pr) r[k] = fa * a[k] + fb * b[k];
}

/* Each computes op i's value and, if the op depends on a seeded group, its
 * tangent row; an op outside the seeded groups keeps a zero row
 * (forward.c's invariant). R(s) is the tangent row of slot s. */
#define R(s) (x->tan + (size_t)(s) * x->P)
#define ACTIVE (fl & x->mask)

TP_OPFN(fwd1, ADD)
{
    tp__value_ADD(x, i, op, fl, u, t);
    if (!ACTIVE)
        return;
    if (fl & TP_DEP_TPASSIVE)
        tp__row_copy(R(i), R(u), x->pr);
    else if (fl & TP_DEP_UPASSIVE)
        tp__row_copy(R(i), R(t), x->pr);
    else
        tp__row_add(R(i), R(u), R(t), x->pr);
}

TP_OPFN(fwd1, SUB)
{
    tp__value_SUB(x, i, op, fl, u, t);
    if (!ACTIVE)
        return;
    if (fl & TP_DEP_TPASSIVE)
        tp__row_copy(R(i), R(u), x->pr);
    else if (fl & TP_DEP_UPASSIVE)
        tp__row_scale(R(i), R(t), -1.0, x->pr);
    else
        tp__row_sub(R(i), R(u), R(t), x->pr);
}

TP_OPFN(fwd1, MUL)
{
    const double *v = x->v;
    tp__value_MUL(x, i, op, fl, u, t);
    if (!ACTIVE)
        return;
    if (fl & TP_DEP_TPASSIVE)
        tp__row_scale(R(i), R(u), v[t], x->pr);
    else if (fl & TP_DEP_UPASSIVE)
        tp__row_scale(R(i), R(t), v[u], x->pr);
    else
        tp__row_comb(R(i), R(u), R(t), v[t], v[u], x->pr);
}

/* Unary ops with first partial f: value, then the row f * (row of u). */
#define TP_FWD1_UNARY(OP, f)                                               \
    TP_OPFN(fwd1, OP)                                                      \
    {                                                                      \
        tp__value_##OP(x, i, op, fl, u, t);                                \
        if (ACTIVE)                                                        \
            tp__row_scale(R(i), R(u), (f), x->pr);                         \
    }
TP_FWD1_UNARY(NEG, -1.0)
TP_FWD1_UNARY(ADDC, 1.0) /* 1 * row: the row itself, exactly */
TP_FWD1_UNARY(MULC, x->K[t])
TP_FWD1_UNARY(CSUB, -1.0)
TP_FWD1_UNARY(SQR, 2.0 * x->v[u])
TP_FWD1_UNARY(SIN, x->aux[i])  /* fu = cos u, left in aux */
TP_FWD1_UNARY(COS, -x->aux[i]) /* fu = -sin u */

TP_OPFN(fwd1, GEN)
{
    tp_partials d;
    tp__value_GEN(x, i, op, fl, u, t);
    if (!ACTIVE)
        return; /* structurally zero tangent; row stays zero */
    tp__gen_partials(x->K, x->v, x->aux, i, op, u, t, &d);
    if (tp__op_kind(op) == TP_KIND_BINARY)
        tp__row_comb(R(i), R(u), R(t), d.fu, d.ft, x->pr);
    else
        tp__row_scale(R(i), R(u), d.fu, x->pr);
}
TP_DISPATCH(fwd1)

/* ---- adjoints --------------------------------------------------------- */

/* The adjoint update of op i, whose adjoint a is non-zero: adjoint
 * functions take a instead of consuming adj[i] (tp__rev1_* do that). */
#define TP_ADJFN(OP)                                                       \
    TP_KERNEL void tp__adj1_##OP(const tp_kx *x, uint32_t i, unsigned op,  \
                                 unsigned fl, uint32_t u, uint32_t t,      \
                                 double a)
#define ADJ x->adj
TP_ADJFN(ADD)
{
    TP_UNUSED4, (void)i;
    if (!TP_UPASSIVE(fl))
        ADJ[u] += a;
    if (!TP_TPASSIVE(fl))
        ADJ[t] += a;
}
TP_ADJFN(SUB)
{
    TP_UNUSED4, (void)i;
    if (!TP_UPASSIVE(fl))
        ADJ[u] += a;
    if (!TP_TPASSIVE(fl))
        ADJ[t] -= a;
}
TP_ADJFN(MUL)
{
    TP_UNUSED4, (void)i;
    if (!TP_UPASSIVE(fl))
        ADJ[u] += a * x->v[t];
    if (!TP_TPASSIVE(fl))
        ADJ[t] += a * x->v[u];
}
TP_ADJFN(NEG) { TP_UNUSED4, (void)i; ADJ[u] -= a; }
TP_ADJFN(ADDC) { TP_UNUSED4, (void)i; ADJ[u] += a; }
TP_ADJFN(MULC) { TP_UNUSED4, (void)i; ADJ[u] += a * x->K[t]; }
TP_ADJFN(CSUB) { TP_UNUSED4, (void)i; ADJ[u] -= a; }
TP_ADJFN(SQR) { TP_UNUSED4, (void)i; ADJ[u] += 2.0 * a * x->v[u]; }
TP_ADJFN(SIN) { TP_UNUSED4; ADJ[u] += a * x->aux[i]; }
TP_ADJFN(COS) { TP_UNUSED4; ADJ[u] -= a * x->aux[i]; }
TP_ADJFN(GEN)
{
    tp_partials d;
    tp__gen_partials(x->K, x->v, x->aux, i, op, u, t, &d);
    if (!TP_UPASSIVE(fl))
        ADJ[u] += d.fu * a;
    if (tp__op_kind(op) == TP_KIND_BINARY && !TP_TPASSIVE(fl))
        ADJ[t] += d.ft * a;
}

/* Reverse sweep, op i: consume its adjoint (an op with a zero adjoint
 * propagates nothing, and its partials are never formed). */
#define TP_REV1(OP)                                                        \
    TP_OPFN(rev1, OP)                                                      \
    {                                                                      \
        const double a = ADJ[i];                                           \
        if (a == 0.0)                                                      \
            return;                                                        \
        ADJ[i] = 0.0;                                                      \
        tp__adj1_##OP(x, i, op, fl, u, t, a);                              \
    }
TP_COMMON_OPS(TP_REV1)
TP_REV1(GEN)
TP_DISPATCH(rev1)

/* Adjoint-tangent row kernels: ra is the row of the op being visited
 * (consumed and zeroed), ru and rt the rows of its operands (distinct rows
 * that precede ra), tu and tt their tangent rows. */
TP_ROW void tp__adj_lin1(double *restrict ru, double *restrict ra,
                            double fu, int p)
{
    FOR_LANES(k, p) {
        ru[k] += fu * ra[k];
        ra[k] = 0.0;
    }
}

TP_ROW void tp__adj_acc1(double *restrict ru, double *restrict ra, int p)
{
    FOR_LANES(k, p) {
        ru[k] += ra[k];
        ra[k] = 0.0;
    }
}

TP_ROW void tp__adj_2nd1(double *restrict ru, double *restrict ra,
                            const double *restrict tu, double fu, double s,
                            int p)
{
    FOR_LANES(k, p) {
        ru[k] += fu * ra[k] + s * tu[k];
        ra[k] = 0.0;
    }
}

TP_ROW void tp__adj_add2(double *restrict ru, double *restrict rt,
                            double *restrict ra, int p)
{
    FOR_LANES(k, p) {
        ru[k] += ra[k];
        rt[k] += ra[k];
        ra[k] = 0.0;
    }
}

TP_ROW void tp__adj_lin2(double *restrict ru, double *restrict rt,
                            double *restrict ra, double fu, double ft, int p)
{
    FOR_LANES(k, p) {
        ru[k] += fu * ra[k];
        rt[k] += ft * ra[k];
        ra[k] = 0.0;
    }
}

TP_ROW void tp__adj_mul2(double *restrict ru, double *restrict rt,
                            double *restrict ra, const double *restrict tu,
                            const double *restrict tt, double fu, double ft,
                            double a, int p)
{
    FOR_LANES(k, p) {
        ru[k] += fu * ra[k] + a * tt[k];
        rt[k] += ft * ra[k] + a * tu[k];
        ra[k] = 0.0;
    }
}

TP_ROW void tp__adj_2nd2(double *restrict ru, double *restrict rt,
                            double *restrict ra, const double *restrict tu,
                            const double *restrict tt, const tp_partials *d,
                            double a, int p)
{
    const double fu = d->fu, ft = d->ft, suu = a * d->fuu, sut = a * d->fut,
                 stt = a * d->ftt;
    FOR_LANES(k, p) {
        const double r = ra[k], x = tu[k], y = tt[k];
        ru[k] += fu * r + suu * x + sut * y;
        rt[k] += ft * r + sut * x + stt * y;
        ra[k] = 0.0;
    }
}

/* One active operand with partials f, ff (its first and second): the
 * update of that operand's adjoint and row. */
TP_KERNEL void tp__rev2_one(double *adj_u, double *ru, double *ra,
                            const double *tu, double f, double ff, double a,
                            bool second, int p)
{
    *adj_u += f * a;
    if (second && ff != 0.0)
        tp__adj_2nd1(ru, ra, tu, f, a * ff, p);
    else
        tp__adj_lin1(ru, ra, f, p);
}

/* Forward-over-reverse, op i: its adjoint and adjoint-tangent row. The
 * common start: take the adjoint a; an op whose row is still known zero
 * and that adds no second-order term (zero adjoint, or no seeded tangent)
 * propagates only its scalar adjoint, and the function returns. Otherwise
 * the operands' rows are flagged non-zero and the op's own code (after
 * the macro) runs with a and second. A(s) is the adjoint-tangent row of
 * slot s, T(s) the tangent row. */
#define A(s) (x->atan + (size_t)(s) * x->P)
#define TP_REV2_BEGIN(OP, OPV)                                             \
    const double a = ADJ[i];                                               \
    const bool second = a != 0.0 && (fl & x->mask);                        \
    const int p = x->pr;                                                   \
    (void)second, (void)p, (void)op;                                       \
    ADJ[i] = 0.0;                                                          \
    if (!x->anz[i] && !second) {                                           \
        if (a != 0.0)                                                      \
            tp__adj1_##OP(x, i, op, fl, u, t, a);                          \
        return;                                                            \
    }                                                                      \
    x->anz[i] = 0;                                                         \
    x->anz[u] = 1;                                                         \
    if (tp__op_kind(OPV) == TP_KIND_BINARY)                                \
        x->anz[t] = 1 /* a passive operand's flag is never read */

TP_OPFN(rev2, ADD)
{
    TP_REV2_BEGIN(ADD, TP_OP_ADD);
    if (TP_TPASSIVE(fl)) {
        ADJ[u] += a;
        tp__adj_acc1(A(u), A(i), p);
    } else if (TP_UPASSIVE(fl)) {
        ADJ[t] += a;
        tp__adj_acc1(A(t), A(i), p);
    } else {
        ADJ[u] += a;
        ADJ[t] += a;
        tp__adj_add2(A(u), A(t), A(i), p);
    }
}

TP_OPFN(rev2, SUB)
{
    TP_REV2_BEGIN(SUB, TP_OP_SUB);
    if (TP_TPASSIVE(fl)) {
        ADJ[u] += a;
        tp__adj_acc1(A(u), A(i), p);
    } else if (TP_UPASSIVE(fl)) {
        ADJ[t] -= a;
        tp__adj_lin1(A(t), A(i), -1.0, p);
    } else {
        ADJ[u] += a;
        ADJ[t] -= a;
        tp__adj_lin2(A(u), A(t), A(i), 1.0, -1.0, p);
    }
}

TP_OPFN(rev2, MUL)
{
    const double *v = x->v;
    TP_REV2_BEGIN(MUL, TP_OP_MUL);
    if (TP_TPASSIVE(fl)) { /* fuu = 0 and t has no tangent */
        ADJ[u] += a * v[t];
        tp__adj_lin1(A(u), A(i), v[t], p);
    } else if (TP_UPASSIVE(fl)) {
        ADJ[t] += a * v[u];
        tp__adj_lin1(A(t), A(i), v[u], p);
    } else {
        ADJ[u] += a * v[t];
        ADJ[t] += a * v[u];
        if (second)
            tp__adj_mul2(A(u), A(t), A(i), R(u), R(t), v[t], v[u], a, p);
        else
            tp__adj_lin2(A(u), A(t), A(i), v[t], v[u], p);
    }
}

/* Linear unary ops with partial f (+-1 multiplies exactly: these are
 * the interpreter's adj -= a, ru -= ra, ru += ra). */
#define TP_REV2_LIN(OP, f)                                                 \
    TP_OPFN(rev2, OP)                                                      \
    {                                                                      \
        TP_REV2_BEGIN(OP, TP_OP_##OP);                                     \
        ADJ[u] += a * (f);                                                 \
        tp__adj_lin1(A(u), A(i), (f), p);                                  \
    }
TP_REV2_LIN(NEG, -1.0)
TP_REV2_LIN(CSUB, -1.0)
TP_REV2_LIN(ADDC, 1.0)
TP_REV2_LIN(MULC, x->K[t])

/* Non-linear unary ops with first and second partials f, ff. */
#define TP_REV2_UNARY(OP, f, ff)                                           \
    TP_OPFN(rev2, OP)                                                      \
    {                                                                      \
        TP_REV2_BEGIN(OP, TP_OP_##OP);                                     \
        tp__rev2_one(ADJ + u, A(u), A(i), R(u), (f), (ff), a, second, p);  \
    }
TP_REV2_UNARY(SQR, 2.0 * x->v[u], 2.0)
TP_REV2_UNARY(SIN, x->aux[i], -x->v[i])  /* fu = cos u, fuu = -w */
TP_REV2_UNARY(COS, -x->aux[i], -x->v[i]) /* fu = -sin u, fuu = -w */

TP_OPFN(rev2, GEN)
{
    tp_partials d;
    bool sec;
    TP_REV2_BEGIN(GEN, op);
    tp__gen_partials(x->K, x->v, x->aux, i, op, u, t, &d);
    sec = second && !tp__op_linear(op);
    if (tp__op_kind(op) != TP_KIND_BINARY || TP_TPASSIVE(fl)) {
        tp__rev2_one(ADJ + u, A(u), A(i), R(u), d.fu, d.fuu, a, sec, p);
    } else if (TP_UPASSIVE(fl)) {
        tp__rev2_one(ADJ + t, A(t), A(i), R(t), d.ft, d.ftt, a, sec, p);
    } else if (u == t) { /* both operands one slot: combine the partials */
        tp__rev2_one(ADJ + u, A(u), A(i), R(u), d.fu + d.ft,
                     d.fuu + 2.0 * d.fut + d.ftt, a, sec, p);
    } else {
        ADJ[u] += d.fu * a;
        ADJ[t] += d.ft * a;
        if (sec)
            tp__adj_2nd2(A(u), A(t), A(i), R(u), R(t), &d, a, p);
        else
            tp__adj_lin2(A(u), A(t), A(i), d.fu, d.ft, p);
    }
}
TP_DISPATCH(rev2)

#undef A
#undef R
#undef ACTIVE
#undef ADJ

/* ---- univariate second-order Taylor ------------------------------------ */

TP_KERNEL void tp__k_taylor2(const tp_kx *x, uint32_t i, unsigned op,
                             unsigned fl, uint32_t u, uint32_t t)
{
    double *v = x->v, *d1 = x->d1, *d2 = x->d2;
    tp_partials d;
    tp__k_value(x, i, op, fl, u, t);
    tp__gen_partials(x->K, v, x->aux, i, op, u, t, &d);
    if (tp__op_kind(op) == TP_KIND_BINARY) {
        d1[i] = d.fu * d1[u] + d.ft * d1[t];
        d2[i] = d.fu * d2[u] + d.ft * d2[t] + d.fuu * d1[u] * d1[u] +
                2.0 * d.fut * d1[u] * d1[t] + d.ftt * d1[t] * d1[t];
    } else {
        d1[i] = d.fu * d1[u];
        d2[i] = d.fu * d2[u] + d.fuu * d1[u] * d1[u];
    }
}

#endif /* TAPE_SWEEP_OPS_H */
