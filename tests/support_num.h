/* support_num.h - numerical helpers shared by the tests: error measures
 * for comparing vectors, and central finite differences with one Richardson
 * step, the independent derivation the AD results are checked against.
 *
 * Error measure: num_vec_err(a, b, n) = max_i |a_i - b_i| / max(1, max_i
 * |b_i|), relative to the largest entry of the reference b (so a tiny entry
 * beside a large one is judged on the scale of the vector), absolute below
 * 1. Any NaN or infinity in a or b gives +infinity: a test never passes on
 * a non-finite number by accident. */
#ifndef TESTS_SUPPORT_NUM_H
#define TESTS_SUPPORT_NUM_H

#include <stddef.h>

double num_max_abs(const double *a, size_t n);
double num_vec_err(const double *a, const double *b, size_t n);
/* max_i |a_i - b_i| / max(1, scale), +infinity on non-finite entries: for
 * results that may cancel, judged on the scale of their terms. */
double num_vec_err_scaled(const double *a, const double *b, size_t n,
                          double scale);
/* Number of entries where a and b differ as doubles (a_i != b_i, or one
 * is NaN and the other not): 0 means equal entry by entry. */
size_t num_count_diff(const double *a, const double *b, size_t n);

/* The least-squares slope of log(y) against log(x) over n points (x, y
 * > 0): the order a convergence study observes. */
double num_loglog_slope(int n, const double *x, const double *y);

/* Advance th'' = -a cos th (the IFToMM A02 four-bars' exact motion: every
 * crank turns like this pendulum) by dt with classical RK4 steps of at
 * most hmax: the reference the A02 tests compare crank tips with. */
void num_rk4_pendulum(double a, double *th, double *w, double dt,
                      double hmax);

/* A vector function y[m] = f(x[n]) for finite differences; returns 0, or
 * non-zero when it cannot be evaluated (the difference then fails). */
typedef int (*num_vfunc)(void *ctx, const double *x, double *y);

/* Directional derivative dy[m] of f at x along s[n], by central differences
 * with steps h and h/2 combined by Richardson extrapolation (error O(h^4)).
 * Returns 0, or -1 if f failed or memory ran out. */
int num_fd_dir(num_vfunc f, void *ctx, int n, int m, const double *x,
               const double *s, double h, double *dy);

/* Jacobian J (m x n, row-major) of f at x by num_fd_dir on unit vectors. */
int num_fd_jac(num_vfunc f, void *ctx, int n, int m, const double *x,
               double h, double *J);

/* Mark a check with its vector error; the macro lives with check.h's
 * counters in each test file. ctx is a string naming the case. */
#define CHECK_VEC(ctx, a, b, n, tol)                                       \
    do {                                                                   \
        double e_ = num_vec_err((a), (b), (size_t)(n));                    \
        check_count_++;                                                    \
        if (!(e_ <= (tol)))                                                \
            CHECK_FAIL_("%s: %s ~ %s failed: error %.3g > %.3g", (ctx),    \
                        #a, #b, e_, (double)(tol));                        \
    } while (0)

/* The same with an explicit scale (see num_vec_err_scaled). */
#define CHECK_VEC_SCALED(ctx, a, b, n, scale, tol)                         \
    do {                                                                   \
        double e_ = num_vec_err_scaled((a), (b), (size_t)(n), (scale));    \
        check_count_++;                                                    \
        if (!(e_ <= (tol)))                                                \
            CHECK_FAIL_("%s: %s ~ %s failed: error %.3g > %.3g", (ctx),    \
                        #a, #b, e_, (double)(tol));                        \
    } while (0)

/* a and b equal entry by entry (exact doubles). */
#define CHECK_SAME(ctx, a, b, n)                                           \
    do {                                                                   \
        size_t d_ = num_count_diff((a), (b), (size_t)(n));                 \
        check_count_++;                                                    \
        if (d_ != 0)                                                       \
            CHECK_FAIL_("%s: %s == %s failed: %zu of %zu entries differ",  \
                        (ctx), #a, #b, d_, (size_t)(n));                   \
    } while (0)

#endif
