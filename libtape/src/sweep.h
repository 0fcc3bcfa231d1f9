/* sweep.h - inline helpers shared by the sweep kernels (forward.c,
 * reverse.c): an op's constant, its value, and its partials read from the
 * values a forward sweep stored. Private to the sweep files. */
#ifndef TAPE_SWEEP_H
#define TAPE_SWEEP_H

#include <stdint.h>

#include "op_math.h"
#include "tape_internal.h"

/* Direction rows are swept in whole groups of TP_LANES columns (the row
 * stride P is a multiple of it); the padding columns hold zeros. A fixed
 * inner trip count lets the compiler emit straight vector code with no
 * remainder loop, which matters for the few directions of small systems. */
#define FOR_LANES(k, pr)                                                   \
    for (int k##4_ = 0; k##4_ < (pr); k##4_ += TP_LANES)                   \
        for (int k = k##4_; k < k##4_ + TP_LANES; k++)

/* The row-heavy kernels are also compiled for AVX2 and picked at load time
 * (GCC's function multi-versioning), so a generic build uses 4-wide
 * vectors where the machine has them. No FMA: both versions round alike. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) &&    \
    defined(__linux__)
#define TP_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define TP_VECTOR_CLONES
#endif

static inline int tp__lanes(int p)
{
    return (p + TP_LANES - 1) / TP_LANES * TP_LANES;
}

/* For small per-op bodies that must be inlined into a sweep loop. */
#if defined(__GNUC__)
#define TP_INLINE inline __attribute__((always_inline))
#else
#define TP_INLINE inline
#endif

/* a1 of a UINT op holds the exponent in two's complement. */
static inline int tp__u2i(uint32_t t)
{
    return t <= (uint32_t)INT32_MAX ? (int)t : -(int)(UINT32_MAX - t) - 1;
}

/* The constant operand of op i: pool entry (UCONST), exponent (UINT) or 0. */
static inline double tp__op_c(const tp_tape *T, uint32_t i, unsigned op)
{
    switch (tp__opinfo[op].kind) {
    case TP_KIND_UCONST: return T->konst[T->a1[i]];
    case TP_KIND_UINT: return (double)tp__u2i(T->a1[i]);
    default: return 0.0;
    }
}

/* Value of non-leaf op i (CONST included) from the values v of its
 * operands; stores its auxiliary value in aux[i] where it has one. */
static TP_INLINE double tp__value_at(const tp_tape *T, const double *v,
                                     double *aux, uint32_t i, unsigned op)
{
    const uint32_t u = T->a0[i], t = T->a1[i];
    switch (op) {
    case TP_OP_CONST: return T->konst[u];
    case TP_OP_ADD: return v[u] + v[t];
    case TP_OP_SUB: return v[u] - v[t];
    case TP_OP_MUL: return v[u] * v[t];
    case TP_OP_DIV: return v[u] / v[t];
    case TP_OP_NEG: return -v[u];
    case TP_OP_ADDC: return v[u] + T->konst[t];
    case TP_OP_MULC: return T->konst[t] * v[u];
    case TP_OP_CSUB: return T->konst[t] - v[u];
    case TP_OP_SQR: return v[u] * v[u];
    case TP_OP_SIN:
    case TP_OP_COS:
        if (t) { /* paired: the partner's aux is this value and vice versa */
            aux[i] = v[t - 1];
            return aux[t - 1];
        }
        return tp__op_value_aux((int)op, v[u], 0.0, 0.0, &aux[i]);
    default:
        return tp__op_value_aux(
            (int)op, v[u],
            tp__opinfo[op].kind == TP_KIND_BINARY ? v[t] : 0.0,
            tp__op_c(T, i, op), &aux[i]);
    }
}

/* Partials of non-leaf op i from stored values. */
static inline void tp__partials_at(const tp_tape *T, const double *v,
                                   const double *aux, uint32_t i, unsigned op,
                                   tp_partials *d)
{
    const uint32_t u = T->a0[i], t = T->a1[i];
    switch (op) {
    case TP_OP_ADD: *d = (tp_partials){1.0, 1.0, 0.0, 0.0, 0.0}; return;
    case TP_OP_SUB: *d = (tp_partials){1.0, -1.0, 0.0, 0.0, 0.0}; return;
    case TP_OP_MUL: *d = (tp_partials){v[t], v[u], 0.0, 1.0, 0.0}; return;
    case TP_OP_NEG: *d = (tp_partials){-1.0, 0.0, 0.0, 0.0, 0.0}; return;
    case TP_OP_ADDC: *d = (tp_partials){1.0, 0.0, 0.0, 0.0, 0.0}; return;
    case TP_OP_MULC:
        *d = (tp_partials){T->konst[t], 0.0, 0.0, 0.0, 0.0};
        return;
    case TP_OP_CSUB: *d = (tp_partials){-1.0, 0.0, 0.0, 0.0, 0.0}; return;
    case TP_OP_SQR: *d = (tp_partials){2.0 * v[u], 0.0, 2.0, 0.0, 0.0}; return;
    default:
        tp__op_partials((int)op, v[u],
                        tp__opinfo[op].kind == TP_KIND_BINARY ? v[t] : 0.0,
                        tp__op_c(T, i, op), v[i], aux[i], d);
    }
}

#endif /* TAPE_SWEEP_H */
