/* sweep_one.h - the interpreter's kernels for rows of one vector
 * (TP_LANES columns): the first-order forward op and the
 * forward-over-reverse op of sweep_ops.h, each row a few vector loads,
 * operations and stores instead of a loop over columns, and each
 * reverse op one case of one switch.
 *
 * Why: at up to four rates (tp_lagrange_t below five coordinates) the
 * sweeps run one vector of columns, and there the per-op overhead (the
 * generic kernels' loops, whose trip count the compiler does not know in
 * tp__rev2, and a second dispatch after the common start of every
 * reverse op) costs more than the arithmetic: 10 % of a right-hand side
 * at 2 links. (Used for every op of a ranged sweep whose range is one
 * vector, they saved nothing at 10 links: kept to the full sweeps.)
 * Written with GCC's vector extensions, so only for GCC-compatible
 * compilers and four lanes; elsewhere TP_ONE_VECTOR is 0 and the sweeps
 * use the generic kernels alone.
 *
 * Bit for bit: every lane does what the generic kernel does to that
 * column, the same operations in the same order (no FMA in either; see
 * sweep.h), and in each vector of columns the rows are read and written
 * in the generic kernel's order, so operands that are one slot behave
 * alike. Ops without a kernel of their own here (the generic ones) run
 * sweep_ops.h's kernel. Private to forward.c and reverse.c, not pasted
 * into generated code.
 */
#ifndef TAPE_SWEEP_ONE_H
#define TAPE_SWEEP_ONE_H

#include "sweep.h"

#if defined(__GNUC__) && TP_LANES == 4
#define TP_ONE_VECTOR 1

/* A row of one vector; rows are only 8-byte aligned (P doubles apart). */
typedef double tp_v4 __attribute__((vector_size(4 * sizeof(double))));
typedef double tp_v4u
    __attribute__((vector_size(4 * sizeof(double)), aligned(8), may_alias));

/* Vectors go through macros, never as arguments: passing a 32-byte vector
 * by value changes the ABI between the clones of sweep.h. */
#define V_LD(p) (*(const tp_v4u *)(const void *)(p))
#define V_ST(p, e) (*(tp_v4u *)(void *)(p) = (e))
/* Each row operation runs over the x->pr columns swept, a vector at a
 * time (o_ the first column of one); at x->pr == TP_LANES, a constant of
 * the calling loop, the loop folds away. */
#define V_ROWS(body)                                                       \
    do {                                                                   \
        for (size_t o_ = 0; o_ < (size_t)x->pr; o_ += TP_LANES) {          \
            body;                                                          \
        }                                                                  \
    } while (0)
#define V_SPLAT(s) ((tp_v4){(s), (s), (s), (s)})
#define V_ZERO(p) V_ST(p, V_SPLAT(0.0))

#define R1(s) (x->tan + (size_t)(s) * x->P)
#define A1(s) (x->atan + (size_t)(s) * x->P)

/* ---- first-order forward (tp__fwd1_* of sweep_ops.h) ------------------ */

/* tp__row_copy, tp__row_scale, tp__row_add, tp__row_sub, tp__row_comb */
#define V_COPY(r, a) V_ROWS(V_ST(r + o_, V_LD(a + o_)))
#define V_SCALE(r, a, fa)                                                  \
    do {                                                                   \
        const tp_v4 f_ = V_SPLAT(fa);                                      \
        V_ROWS(V_ST(r + o_, f_ * V_LD(a + o_)));                           \
    } while (0)
#define V_ADD(r, a, b) V_ROWS(V_ST(r + o_, V_LD(a + o_) + V_LD(b + o_)))
#define V_SUB(r, a, b) V_ROWS(V_ST(r + o_, V_LD(a + o_) - V_LD(b + o_)))
#define V_COMB(r, a, b, fa, fb)                                            \
    do {                                                                   \
        const tp_v4 f_ = V_SPLAT(fa), g_ = V_SPLAT(fb);                    \
        V_ROWS(V_ST(r + o_, f_ * V_LD(a + o_) + g_ * V_LD(b + o_)));       \
    } while (0)

/* Op i's value and, if it depends on a seeded group, its tangent row, as
 * tp__k_fwd1. */
TP_KERNEL void tp__one_fwd1(const tp_kx *x, uint32_t i, unsigned op,
                            unsigned fl, uint32_t u, uint32_t t)
{
    const double *v = x->v;
    switch (op) {
    case TP_OP_ADD:
        tp__value_ADD(x, i, op, fl, u, t);
        if (!(fl & x->mask))
            return;
        if (fl & TP_DEP_TPASSIVE)
            V_COPY(R1(i), R1(u));
        else if (fl & TP_DEP_UPASSIVE)
            V_COPY(R1(i), R1(t));
        else
            V_ADD(R1(i), R1(u), R1(t));
        return;
    case TP_OP_SUB:
        tp__value_SUB(x, i, op, fl, u, t);
        if (!(fl & x->mask))
            return;
        if (fl & TP_DEP_TPASSIVE)
            V_COPY(R1(i), R1(u));
        else if (fl & TP_DEP_UPASSIVE)
            V_SCALE(R1(i), R1(t), -1.0);
        else
            V_SUB(R1(i), R1(u), R1(t));
        return;
    case TP_OP_MUL:
        tp__value_MUL(x, i, op, fl, u, t);
        if (!(fl & x->mask))
            return;
        if (fl & TP_DEP_TPASSIVE)
            V_SCALE(R1(i), R1(u), v[t]);
        else if (fl & TP_DEP_UPASSIVE)
            V_SCALE(R1(i), R1(t), v[u]);
        else
            V_COMB(R1(i), R1(u), R1(t), v[t], v[u]);
        return;
/* unary ops: value, then the row f * (row of u), as TP_FWD1_UNARY */
#define ONE_FWD1_UNARY(OP, f)                                              \
    case TP_OP_##OP:                                                       \
        tp__value_##OP(x, i, op, fl, u, t);                                \
        if (fl & x->mask)                                                  \
            V_SCALE(R1(i), R1(u), (f));                                    \
        return;
        ONE_FWD1_UNARY(NEG, -1.0)
        ONE_FWD1_UNARY(ADDC, 1.0)
        ONE_FWD1_UNARY(MULC, x->K[t])
        ONE_FWD1_UNARY(CSUB, -1.0)
        ONE_FWD1_UNARY(SQR, 2.0 * v[u])
        ONE_FWD1_UNARY(SIN, x->aux[i])
        ONE_FWD1_UNARY(COS, -x->aux[i])
#undef ONE_FWD1_UNARY
    default:
        tp__fwd1_GEN(x, i, op, fl, u, t);
        return;
    }
}

/* ---- forward-over-reverse (tp__rev2_* of sweep_ops.h) ----------------- */

/* tp__adj_lin1, tp__adj_acc1, tp__adj_2nd1 (ra consumed and zeroed) */
#define V_LIN1(ru, ra, fu)                                                 \
    do {                                                                   \
        const tp_v4 f_ = V_SPLAT(fu);                                      \
        V_ROWS(V_ST(ru + o_, V_LD(ru + o_) + f_ * V_LD(ra + o_));          \
               V_ZERO(ra + o_));                                           \
    } while (0)
#define V_ACC1(ru, ra)                                                     \
    V_ROWS(V_ST(ru + o_, V_LD(ru + o_) + V_LD(ra + o_)); V_ZERO(ra + o_))
#define V_2ND1(ru, ra, tu, fu, s)                                          \
    do {                                                                   \
        const tp_v4 f_ = V_SPLAT(fu), s_ = V_SPLAT(s);                     \
        V_ROWS(V_ST(ru + o_, V_LD(ru + o_) + (f_ * V_LD(ra + o_) +         \
                                              s_ * V_LD(tu + o_)));        \
               V_ZERO(ra + o_));                                           \
    } while (0)
/* tp__adj_add2, tp__adj_lin2, tp__adj_mul2: in each vector ru is written
 * before rt is read, as the generic kernels' columns are */
#define V_ADD2(ru, rt, ra)                                                 \
    V_ROWS(V_ST(ru + o_, V_LD(ru + o_) + V_LD(ra + o_));                   \
           V_ST(rt + o_, V_LD(rt + o_) + V_LD(ra + o_)); V_ZERO(ra + o_))
#define V_LIN2(ru, rt, ra, fu, ft)                                         \
    do {                                                                   \
        const tp_v4 f_ = V_SPLAT(fu), g_ = V_SPLAT(ft);                    \
        V_ROWS(V_ST(ru + o_, V_LD(ru + o_) + f_ * V_LD(ra + o_));          \
               V_ST(rt + o_, V_LD(rt + o_) + g_ * V_LD(ra + o_));          \
               V_ZERO(ra + o_));                                           \
    } while (0)
#define V_MUL2(ru, rt, ra, tu, tt, fu, ft, a)                              \
    do {                                                                   \
        const tp_v4 f_ = V_SPLAT(fu), g_ = V_SPLAT(ft), a_ = V_SPLAT(a);   \
        V_ROWS(V_ST(ru + o_, V_LD(ru + o_) + (f_ * V_LD(ra + o_) +         \
                                              a_ * V_LD(tt + o_)));        \
               V_ST(rt + o_, V_LD(rt + o_) + (g_ * V_LD(ra + o_) +         \
                                              a_ * V_LD(tu + o_)));        \
               V_ZERO(ra + o_));                                           \
    } while (0)

/* tp__rev2_one: one active operand with partials f, ff */
#define V_REV2_ONE(adj_u, ru, ra, tu, f, ff, a, second)                    \
    do {                                                                   \
        const double fs_ = (f), ffs_ = (ff);                               \
        *(adj_u) += fs_ * (a);                                             \
        if ((second) && ffs_ != 0.0)                                       \
            V_2ND1(ru, ra, tu, fs_, (a) * ffs_);                           \
        else                                                               \
            V_LIN1(ru, ra, fs_);                                           \
    } while (0)

/* TP_REV2_BEGIN for op OP in a case of its own: take the adjoint a; an op
 * whose row is known zero and that adds no second-order term propagates
 * only its scalar adjoint; otherwise flag the operands' rows non-zero. */
#define ONE_BEGIN(OP, binary)                                              \
    a = adj[i];                                                            \
    second = a != 0.0 && (fl & x->mask);                                   \
    adj[i] = 0.0;                                                          \
    if (!x->anz[i] && !second) {                                           \
        if (a != 0.0)                                                      \
            tp__adj1_##OP(x, i, op, fl, u, t, a);                          \
        return;                                                            \
    }                                                                      \
    x->anz[i] = 0;                                                         \
    x->anz[u] = 1;                                                         \
    if (binary)                                                            \
        x->anz[t] = 1

/* Op i's adjoint and adjoint-tangent row, as tp__k_rev2: one switch, each
 * case the whole op (no second dispatch after the common start). */
TP_KERNEL void tp__one_rev2(const tp_kx *x, uint32_t i, unsigned op,
                            unsigned fl, uint32_t u, uint32_t t)
{
    double *adj = x->adj;
    const double *v = x->v;
    double a;
    bool second;
    switch (op) {
    case TP_OP_ADD:
        ONE_BEGIN(ADD, 1);
        if (fl & TP_DEP_TPASSIVE) {
            adj[u] += a;
            V_ACC1(A1(u), A1(i));
        } else if (fl & TP_DEP_UPASSIVE) {
            adj[t] += a;
            V_ACC1(A1(t), A1(i));
        } else {
            adj[u] += a;
            adj[t] += a;
            V_ADD2(A1(u), A1(t), A1(i));
        }
        return;
    case TP_OP_SUB:
        ONE_BEGIN(SUB, 1);
        if (fl & TP_DEP_TPASSIVE) {
            adj[u] += a;
            V_ACC1(A1(u), A1(i));
        } else if (fl & TP_DEP_UPASSIVE) {
            adj[t] -= a;
            V_LIN1(A1(t), A1(i), -1.0);
        } else {
            adj[u] += a;
            adj[t] -= a;
            V_LIN2(A1(u), A1(t), A1(i), 1.0, -1.0);
        }
        return;
    case TP_OP_MUL:
        ONE_BEGIN(MUL, 1);
        if (fl & TP_DEP_TPASSIVE) {
            adj[u] += a * v[t];
            V_LIN1(A1(u), A1(i), v[t]);
        } else if (fl & TP_DEP_UPASSIVE) {
            adj[t] += a * v[u];
            V_LIN1(A1(t), A1(i), v[u]);
        } else {
            adj[u] += a * v[t];
            adj[t] += a * v[u];
            if (second)
                V_MUL2(A1(u), A1(t), A1(i), R1(u), R1(t), v[t], v[u], a);
            else
                V_LIN2(A1(u), A1(t), A1(i), v[t], v[u]);
        }
        return;
/* linear unary ops, as TP_REV2_LIN */
#define ONE_REV2_LIN(OP, f)                                                \
    case TP_OP_##OP:                                                       \
        ONE_BEGIN(OP, 0);                                                  \
        adj[u] += a * (f);                                                 \
        V_LIN1(A1(u), A1(i), (f));                                         \
        return;
        ONE_REV2_LIN(NEG, -1.0)
        ONE_REV2_LIN(CSUB, -1.0)
        ONE_REV2_LIN(ADDC, 1.0)
        ONE_REV2_LIN(MULC, x->K[t])
#undef ONE_REV2_LIN
/* non-linear unary ops, as TP_REV2_UNARY */
#define ONE_REV2_UNARY(OP, f, ff)                                          \
    case TP_OP_##OP:                                                       \
        ONE_BEGIN(OP, 0);                                                  \
        V_REV2_ONE(adj + u, A1(u), A1(i), R1(u), (f), (ff), a, second);    \
        return;
        ONE_REV2_UNARY(SQR, 2.0 * v[u], 2.0)
        ONE_REV2_UNARY(SIN, x->aux[i], -v[i])
        ONE_REV2_UNARY(COS, -x->aux[i], -v[i])
#undef ONE_REV2_UNARY
    default:
        tp__rev2_GEN(x, i, op, fl, u, t);
        return;
    }
}

#undef R1
#undef A1

#else
#define TP_ONE_VECTOR 0
#endif

#endif /* TAPE_SWEEP_ONE_H */
