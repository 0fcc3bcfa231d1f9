/* bench_util.c - clock, batches and medians for the benchmark programs. */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>
#include <time.h>

#include "bench_util.h"

double bench_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double bench_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double bench_time(void (*fn)(void *), void *ctx, long reps)
{
    double t0 = bench_now();
    long i;
    for (i = 0; i < reps; i++)
        fn(ctx);
    return (bench_now() - t0) / (double)reps;
}

long bench_calibrate(void (*fn)(void *), void *ctx, double min_seconds)
{
    long reps = 1;
    for (;;) {
        double t0 = bench_now(), dt;
        long i;
        for (i = 0; i < reps; i++)
            fn(ctx);
        dt = bench_now() - t0;
        if (dt >= min_seconds || reps > (1L << 40))
            return reps;
        reps = dt > 0 ? (long)(reps * 1.2 * min_seconds / dt) + 1 : reps * 10;
    }
}
