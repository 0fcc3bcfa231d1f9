/* wp_table.h - the markdown reports of the work-precision benchmark
 * (bench_wp.c): one table per demo with every run, and the summary that
 * names the fastest method at each target error. Both are written to any
 * stream, so the same text goes to the terminal and to the files. */
#ifndef BENCH_WP_TABLE_H
#define BENCH_WP_TABLE_H

#include <stdio.h>

#include "wp_sweep.h"

/* The demo's section: its reference, then one row per run (failed runs
 * too, with their status and the solver's message). */
void wp_table_write(FILE *f, const wp_sweep *w);

/* The summary over the demos w[0 .. nw-1]: for each target error
 * (targets[0 .. nt-1]), the time each method needs to reach it (log-log
 * interpolation in its sweep: wp_interp.h), the fastest method and how
 * many times faster the fastest adaptive method is than rk4. */
void wp_summary_write(FILE *f, const wp_sweep *w, int nw,
                      const double *targets, int nt);

/* Format a time in seconds as milliseconds with 3 significant digits
 * (at least the integral part) into buf. */
void wp_ms_text(double seconds, char *buf, size_t len);

#endif
