/* bench_util.h - what every benchmark program shares: a monotonic clock,
 * batches calibrated to a minimum duration, medians, and a count of heap
 * allocations made by anything in the process (alloc_count.c interposes
 * malloc and friends). Benchmarks print ratios measured in one run; they
 * never pass or fail on time. */
#ifndef BENCH_UTIL_H
#define BENCH_UTIL_H

#include <stddef.h>

/* Seconds from a monotonic clock. */
double bench_now(void);

/* Seconds of processor time of the calling thread: what a single-threaded
 * computation costs, whatever else the machine runs meanwhile (it still
 * shares the caches). */
double bench_cpu_now(void);

/* Median of v[n] (v is reordered). */
double bench_median(double *v, int n);

/* Calls fn(ctx) reps times; returns seconds per call. */
double bench_time(void (*fn)(void *), void *ctx, long reps);

/* Number of calls so that one batch of fn takes at least min_seconds. */
long bench_calibrate(void (*fn)(void *), void *ctx, double min_seconds);

/* bench_time and bench_calibrate on the calling thread's processor time
 * (bench_cpu_now) instead of the monotonic clock. */
double bench_time_cpu(void (*fn)(void *), void *ctx, long reps);
long bench_calibrate_cpu(void (*fn)(void *), void *ctx, double min_seconds);

/* Heap allocations (malloc, calloc, realloc, aligned variants) made by the
 * whole process since it started. */
unsigned long long bench_alloc_count(void);

/* A list of link counts such as "2,10,50" (each 1 to 100000) into at
 * most max values of out: their count, or -1 when malformed. */
int bench_parse_links(const char *s, int *out, int max);

#endif
