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

double bench_cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
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

static double time_with(double (*clk)(void), void (*fn)(void *), void *ctx,
                        long reps)
{
    double t0 = clk();
    long i;
    for (i = 0; i < reps; i++)
        fn(ctx);
    return (clk() - t0) / (double)reps;
}

double bench_time(void (*fn)(void *), void *ctx, long reps)
{
    return time_with(bench_now, fn, ctx, reps);
}

double bench_time_cpu(void (*fn)(void *), void *ctx, long reps)
{
    return time_with(bench_cpu_now, fn, ctx, reps);
}

static long calibrate_with(double (*clk)(void), void (*fn)(void *),
                           void *ctx, double min_seconds)
{
    long reps = 1;
    for (;;) {
        double t0 = clk(), dt;
        long i;
        for (i = 0; i < reps; i++)
            fn(ctx);
        dt = clk() - t0;
        if (dt >= min_seconds || reps > (1L << 40))
            return reps;
        reps = dt > 0 ? (long)(reps * 1.2 * min_seconds / dt) + 1 : reps * 10;
    }
}

long bench_calibrate(void (*fn)(void *), void *ctx, double min_seconds)
{
    return calibrate_with(bench_now, fn, ctx, min_seconds);
}

long bench_calibrate_cpu(void (*fn)(void *), void *ctx, double min_seconds)
{
    return calibrate_with(bench_cpu_now, fn, ctx, min_seconds);
}

int bench_parse_links(const char *s, int *out, int max)
{
    int n = 0;
    while (*s) {
        char *end;
        const long v = strtol(s, &end, 10);
        if (end == s || v < 1 || v > 100000 || n == max ||
            (*end && *end != ','))
            return -1;
        out[n++] = (int)v;
        s = *end ? end + 1 : end;
    }
    return n;
}
