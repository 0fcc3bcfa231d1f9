/* check.h - minimal assertion macros for the test programs. Each test is
 * its own executable (its own process, with a meson timeout); a failed check
 * prints both operands with the file and line, counts, and the test goes
 * on, so one run shows every failure. main() ends with CHECK_DONE(). */
#ifndef TESTS_CHECK_H
#define TESTS_CHECK_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static int check_failures_;
static int check_count_;

#define CHECK_FAIL_(...)                                                   \
    do {                                                                   \
        check_failures_++;                                                 \
        fprintf(stderr, "%s:%d: ", __FILE__, __LINE__);                    \
        fprintf(stderr, __VA_ARGS__);                                      \
        fputc('\n', stderr);                                               \
    } while (0)

/* A condition. */
#define CHECK(cond)                                                        \
    do {                                                                   \
        check_count_++;                                                    \
        if (!(cond))                                                       \
            CHECK_FAIL_("check failed: %s", #cond);                        \
    } while (0)

/* Two integers are equal. */
#define CHECK_INT(a, b)                                                    \
    do {                                                                   \
        long long a_ = (long long)(a), b_ = (long long)(b);                \
        check_count_++;                                                    \
        if (a_ != b_)                                                      \
            CHECK_FAIL_("%s == %s failed: %lld != %lld", #a, #b, a_, b_);  \
    } while (0)

/* |a - b| <= tol * max(1, |b|): relative for large b, absolute near 0. */
#define CHECK_NEAR(a, b, tol)                                              \
    do {                                                                   \
        double a_ = (a), b_ = (b), t_ = (tol);                             \
        double s_ = fabs(b_) > 1.0 ? fabs(b_) : 1.0;                       \
        check_count_++;                                                    \
        if (!(fabs(a_ - b_) <= t_ * s_))                                   \
            CHECK_FAIL_("%s ~ %s failed: %.17g vs %.17g (diff %.3g, "      \
                        "tol %.3g)", #a, #b, a_, b_, fabs(a_ - b_),        \
                        t_ * s_);                                          \
    } while (0)

/* End of main: report and return the exit status. */
#define CHECK_DONE()                                                       \
    do {                                                                   \
        printf("%d checks, %d failed\n", check_count_, check_failures_);   \
        return check_failures_ ? EXIT_FAILURE : EXIT_SUCCESS;              \
    } while (0)

#endif
