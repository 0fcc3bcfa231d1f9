/* op_math.h - value and partial derivatives of every op, the single source
 * of the calculus used by all backends (tape sweeps, reference interpreter,
 * double evaluator, embedded tuples).
 *
 * An op computes w = f(u) or w = f(u, t); c is its constant (UCONST) or its
 * integer exponent (UINT, as a double). Alongside w an op may leave one
 * auxiliary value that its partials reuse, so that a reverse sweep need not
 * call libm again (cos u beside sin u, u^(k-1) beside u^k, ...). The
 * partials are functions of (u, t, c, w, aux) only.
 *
 * Outside an op's domain the results are NaN or infinite, as libm gives
 * them; callers check for non-finite results once, at the end.
 */
#ifndef TAPE_OP_MATH_H
#define TAPE_OP_MATH_H

#include <math.h>

#include "tape_ops.h"

/* First and second partials of w = f(u, t); unary ops use u only. */
typedef struct tp_partials {
    double fu, ft;       /* df/du, df/dt */
    double fuu, fut, ftt; /* second partials */
} tp_partials;

/* u ^ k by repeated squaring: exact for small integers, the same in every
 * backend. */
static inline double tp__powi(double u, int k)
{
    unsigned long long e = k < 0 ? -(unsigned long long)k : (unsigned long long)k;
    double r = 1.0, b = u;
    while (e) {
        if (e & 1u)
            r *= b;
        e >>= 1;
        if (e)
            b *= b;
    }
    return k < 0 ? 1.0 / r : r;
}

/* sin and cos of one angle in one libm call where the compiler offers it
 * (compilers do not always merge separate sin and cos calls; clang, which
 * defines __GNUC__ too, has no __builtin_sincos but merges them itself
 * with -fno-math-errno). */
static inline double tp__sin_cos(double u, double *c)
{
#if defined(__GNUC__) && !defined(__clang__)
    double s;
    __builtin_sincos(u, &s, c);
    return s;
#else
    *c = cos(u);
    return sin(u);
#endif
}

/* Value of a non-leaf op, and its auxiliary value in *aux. */
static inline double tp__op_value_aux(int op, double u, double t, double c,
                                      double *aux)
{
    double w;
    *aux = 0.0;
    switch (op) {
    case TP_OP_ADD: return u + t;
    case TP_OP_SUB: return u - t;
    case TP_OP_MUL: return u * t;
    case TP_OP_DIV: return u / t;
    case TP_OP_POW:
        *aux = log(u);
        return pow(u, t);
    case TP_OP_ATAN2: return atan2(u, t);
    case TP_OP_HYPOT: return hypot(u, t);
    case TP_OP_NEG: return -u;
    case TP_OP_ADDC: return u + c;
    case TP_OP_MULC: return c * u;
    case TP_OP_CSUB: return c - u;
    case TP_OP_CDIV: return c / u;
    case TP_OP_POWC:
        *aux = pow(u, c - 1.0);
        return pow(u, c);
    case TP_OP_POWI: {
        int k = (int)c;
        *aux = tp__powi(u, k - 1);
        return tp__powi(u, k);
    }
    case TP_OP_SQR: return u * u;
    case TP_OP_SQRT: return sqrt(u);
    case TP_OP_EXP: return exp(u);
    case TP_OP_LOG: return log(u);
    case TP_OP_SIN:
        return tp__sin_cos(u, aux);
    case TP_OP_COS:
        *aux = tp__sin_cos(u, &w);
        return w;
    case TP_OP_TAN: return tan(u);
    case TP_OP_ASIN:
        *aux = 1.0 / sqrt(1.0 - u * u);
        return asin(u);
    case TP_OP_ACOS:
        *aux = 1.0 / sqrt(1.0 - u * u);
        return acos(u);
    case TP_OP_ATAN: return atan(u);
    case TP_OP_SINH:
        *aux = cosh(u);
        return sinh(u);
    case TP_OP_COSH:
        *aux = sinh(u);
        return cosh(u);
    case TP_OP_TANH: return tanh(u);
    case TP_OP_ABS: return fabs(u);
    default: break;
    }
    w = NAN; /* leaves are not computed here */
    return w;
}

static inline double tp__op_value(int op, double u, double t, double c)
{
    double aux;
    return tp__op_value_aux(op, u, t, c, &aux);
}

/* Partials of a non-leaf op from its operands, constant, value and aux. */
static inline void tp__op_partials(int op, double u, double t, double c,
                                   double w, double aux, tp_partials *d)
{
    d->fu = d->ft = d->fuu = d->fut = d->ftt = 0.0;
    switch (op) {
    case TP_OP_ADD: d->fu = 1.0; d->ft = 1.0; break;
    case TP_OP_SUB: d->fu = 1.0; d->ft = -1.0; break;
    case TP_OP_MUL: d->fu = t; d->ft = u; d->fut = 1.0; break;
    case TP_OP_DIV: {
        double r = 1.0 / t;
        d->fu = r;
        d->ft = -w * r;
        d->fut = -r * r;
        d->ftt = 2.0 * w * r * r;
        break;
    }
    case TP_OP_POW: {
        double pm1 = pow(u, t - 1.0); /* u^(t-1) */
        d->fu = t * pm1;
        d->ft = w * aux;
        d->fuu = t * (t - 1.0) * pow(u, t - 2.0);
        d->fut = pm1 * (1.0 + t * aux);
        d->ftt = w * aux * aux;
        break;
    }
    case TP_OP_ATAN2: {
        double r2 = u * u + t * t, q = 1.0 / (r2 * r2);
        d->fu = t / r2;
        d->ft = -u / r2;
        d->fuu = -2.0 * u * t * q;
        d->ftt = 2.0 * u * t * q;
        d->fut = (u * u - t * t) * q;
        break;
    }
    case TP_OP_HYPOT: {
        double r = 1.0 / w, r3 = r * r * r;
        d->fu = u * r;
        d->ft = t * r;
        d->fuu = t * t * r3;
        d->ftt = u * u * r3;
        d->fut = -u * t * r3;
        break;
    }
    case TP_OP_NEG: d->fu = -1.0; break;
    case TP_OP_ADDC: d->fu = 1.0; break;
    case TP_OP_MULC: d->fu = c; break;
    case TP_OP_CSUB: d->fu = -1.0; break;
    case TP_OP_CDIV: {
        double r = 1.0 / u;
        d->fu = -w * r;
        d->fuu = 2.0 * w * r * r;
        break;
    }
    case TP_OP_POWC:
        d->fu = c * aux;
        d->fuu = c * (c - 1.0) * pow(u, c - 2.0);
        break;
    case TP_OP_POWI: {
        int k = (int)c;
        d->fu = c * aux;
        d->fuu = c * (c - 1.0) * tp__powi(u, k - 2);
        break;
    }
    case TP_OP_SQR: d->fu = 2.0 * u; d->fuu = 2.0; break;
    case TP_OP_SQRT:
        d->fu = 0.5 / w;
        d->fuu = -0.25 / (w * u);
        break;
    case TP_OP_EXP: d->fu = w; d->fuu = w; break;
    case TP_OP_LOG: d->fu = 1.0 / u; d->fuu = -d->fu * d->fu; break;
    case TP_OP_SIN: d->fu = aux; d->fuu = -w; break;
    case TP_OP_COS: d->fu = -aux; d->fuu = -w; break;
    case TP_OP_TAN: {
        double s = 1.0 + w * w;
        d->fu = s;
        d->fuu = 2.0 * w * s;
        break;
    }
    case TP_OP_ASIN:
        d->fu = aux;
        d->fuu = u * aux * aux * aux;
        break;
    case TP_OP_ACOS:
        d->fu = -aux;
        d->fuu = -u * aux * aux * aux;
        break;
    case TP_OP_ATAN: {
        double s = 1.0 / (1.0 + u * u);
        d->fu = s;
        d->fuu = -2.0 * u * s * s;
        break;
    }
    case TP_OP_SINH: d->fu = aux; d->fuu = w; break;
    case TP_OP_COSH: d->fu = aux; d->fuu = w; break;
    case TP_OP_TANH: {
        double s = 1.0 - w * w;
        d->fu = s;
        d->fuu = -2.0 * w * s;
        break;
    }
    case TP_OP_ABS: d->fu = (double)((u > 0.0) - (u < 0.0)); break;
    default: break;
    }
}

#endif /* TAPE_OP_MATH_H */
