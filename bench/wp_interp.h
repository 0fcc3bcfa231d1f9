/* wp_interp.h - the time a method's sweep needs to reach a given error,
 * read off the sweep by log-log interpolation between the two runs that
 * bracket it (the work-precision summary of bench_wp.c). */
#ifndef BENCH_WP_INTERP_H
#define BENCH_WP_INTERP_H

#include "wp_run.h"

typedef enum wp_reach {
    WP_NOT_REACHED, /* no run of the sweep reached the error */
    WP_INTERPOLATED, /* between the last run above and the first below */
    WP_AT_LOOSEST   /* the first run that counts already reached it: its
                       time is an upper bound */
} wp_reach;

/* The time at which the sweep runs[0 .. nruns-1] (one method, in sweep
 * order from the loosest setting to the tightest) first reaches state
 * error <= target: wall time, or with cpu set CPU time (on a machine
 * that other work shares, the steadier of the two). Failed runs are
 * skipped. *time receives the interpolated time (NAN when not
 * reached). */
wp_reach wp_time_at_error(const wp_run *runs, int nruns, double target,
                          int cpu, double *time);

#endif
