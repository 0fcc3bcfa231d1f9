/* eom.hpp - C++ operators for the recording API (optional; C programs
 * never need it).
 *
 * eom::val wraps a recorded value (tp_val) with the context that made it,
 * so that a Lagrangian reads as its formula:
 *
 *     eom::model_ctx c(ctx);                       // inside a callback
 *     eom::val r = c.q(0), th = c.q(1), rd = c.qd(0), thd = c.qd(1);
 *     eom::val m = c.param("m");
 *     *out = (0.5*m*(rd*rd + r*r*thd*thd)).raw();
 *
 * Every operator is one call of the C API, chosen by the operand types,
 * so an expression records exactly the ops of the same C calls nested
 * the same way (tests/cpp shows the tapes identical with tp_tape_equal):
 *
 *     a + b  tp_add     a + c  tp_addc(a, c)   c + a  tp_addc(a, c)
 *     a - b  tp_sub     a - c  tp_subc(a, c)   c - a  tp_csub(c, a)
 *     a * b  tp_mul     a * c  tp_mulc(a, c)   c * a  tp_mulc(a, c)
 *     a / b  tp_div     a / c  tp_divc(a, c)   c / a  tp_cdiv(c, a)
 *     -a     tp_neg     pow(a, int) tp_powi    pow(a, double) tp_powc
 *
 * with a, b values and c a double. Both operands of a binary operator
 * must come from the same context (else the context records the error,
 * as the C API does). Where both operands of an operator record ops of
 * their own, C++ leaves the order in which they are evaluated to the
 * compiler, as C does for the arguments of the nested calls: the tape
 * then holds the same ops, possibly in another order (same values,
 * derivatives and size). Header-only; needs C++11. */
#ifndef EOM_EOM_HPP
#define EOM_EOM_HPP

#include "eom/eom.h"

namespace eom {

class val {
public:
    val() : r_(nullptr), v_{0, 0} {}
    val(tp_rec *r, tp_val v) : r_(r), v_(v) {}
    tp_rec *rec() const { return r_; }
    tp_val raw() const { return v_; }

    val &operator+=(const val &b) { return *this = val(r_, tp_add(r_, v_, b.v_)); }
    val &operator-=(const val &b) { return *this = val(r_, tp_sub(r_, v_, b.v_)); }
    val &operator*=(const val &b) { return *this = val(r_, tp_mul(r_, v_, b.v_)); }
    val &operator/=(const val &b) { return *this = val(r_, tp_div(r_, v_, b.v_)); }
    val &operator+=(double c) { return *this = val(r_, tp_addc(r_, v_, c)); }
    val &operator-=(double c) { return *this = val(r_, tp_subc(r_, v_, c)); }
    val &operator*=(double c) { return *this = val(r_, tp_mulc(r_, v_, c)); }
    val &operator/=(double c) { return *this = val(r_, tp_divc(r_, v_, c)); }

private:
    tp_rec *r_;
    tp_val v_;
};

inline val operator+(const val &a, const val &b) { return val(a.rec(), tp_add(a.rec(), a.raw(), b.raw())); }
inline val operator-(const val &a, const val &b) { return val(a.rec(), tp_sub(a.rec(), a.raw(), b.raw())); }
inline val operator*(const val &a, const val &b) { return val(a.rec(), tp_mul(a.rec(), a.raw(), b.raw())); }
inline val operator/(const val &a, const val &b) { return val(a.rec(), tp_div(a.rec(), a.raw(), b.raw())); }
inline val operator+(const val &a, double c) { return val(a.rec(), tp_addc(a.rec(), a.raw(), c)); }
inline val operator-(const val &a, double c) { return val(a.rec(), tp_subc(a.rec(), a.raw(), c)); }
inline val operator*(const val &a, double c) { return val(a.rec(), tp_mulc(a.rec(), a.raw(), c)); }
inline val operator/(const val &a, double c) { return val(a.rec(), tp_divc(a.rec(), a.raw(), c)); }
inline val operator+(double c, const val &a) { return val(a.rec(), tp_addc(a.rec(), a.raw(), c)); }
inline val operator-(double c, const val &a) { return val(a.rec(), tp_csub(a.rec(), c, a.raw())); }
inline val operator*(double c, const val &a) { return val(a.rec(), tp_mulc(a.rec(), a.raw(), c)); }
inline val operator/(double c, const val &a) { return val(a.rec(), tp_cdiv(a.rec(), c, a.raw())); }
inline val operator-(const val &a) { return val(a.rec(), tp_neg(a.rec(), a.raw())); }
inline val operator+(const val &a) { return a; }

#define EOM_HPP_UNARY_(name)                                                   \
    inline val name(const val &a) { return val(a.rec(), tp_##name(a.rec(), a.raw())); }
EOM_HPP_UNARY_(sqr)
EOM_HPP_UNARY_(sqrt)
EOM_HPP_UNARY_(exp)
EOM_HPP_UNARY_(log)
EOM_HPP_UNARY_(sin)
EOM_HPP_UNARY_(cos)
EOM_HPP_UNARY_(tan)
EOM_HPP_UNARY_(asin)
EOM_HPP_UNARY_(acos)
EOM_HPP_UNARY_(atan)
EOM_HPP_UNARY_(sinh)
EOM_HPP_UNARY_(cosh)
EOM_HPP_UNARY_(tanh)
EOM_HPP_UNARY_(abs)
#undef EOM_HPP_UNARY_

inline val pow(const val &a, const val &b) { return val(a.rec(), tp_pow(a.rec(), a.raw(), b.raw())); }
inline val pow(const val &a, int k) { return val(a.rec(), tp_powi(a.rec(), a.raw(), k)); }
inline val pow(const val &a, double c) { return val(a.rec(), tp_powc(a.rec(), a.raw(), c)); }
inline val atan2(const val &y, const val &x) { return val(y.rec(), tp_atan2(y.rec(), y.raw(), x.raw())); }
inline val hypot(const val &a, const val &b) { return val(a.rec(), tp_hypot(a.rec(), a.raw(), b.raw())); }

/* The values a recording context offers, as eom::val. */
class rec_ctx {
public:
    explicit rec_ctx(tp_rec *r) : r_(r) {}
    val indep(int i) const { return val(r_, tp_indep(r_, i)); }
    val param(const char *name, double dflt) const { return val(r_, tp_param(r_, name, dflt)); }
    val constant(double c) const { return val(r_, tp_const(r_, c)); }
    tp_rec *rec() const { return r_; }

private:
    tp_rec *r_;
};

/* The same inside a libeom model callback: coordinates, rates, time and
 * the model's parameters. */
class model_ctx {
public:
    explicit model_ctx(eom_ctx *c) : c_(c) {}
    val q(int i) const { return val(eom_rec(c_), eom_q(c_, i)); }
    val qd(int i) const { return val(eom_rec(c_), eom_qd(c_, i)); }
    val t() const { return val(eom_rec(c_), eom_time(c_)); }
    val param(const char *name) const { return val(eom_rec(c_), eom_param(c_, name)); }
    val constant(double c) const { return val(eom_rec(c_), tp_const(eom_rec(c_), c)); }
    tp_rec *rec() const { return eom_rec(c_); }

private:
    eom_ctx *c_;
};

} /* namespace eom */

#endif /* EOM_EOM_HPP */
