/* run_loop.h - one run of eom-run: integrate a system from t = 0 and
 * write a CSV row at every sample time, then the summary.
 *
 * Sample times (docs/cli.md): t_k = k * sample for k = 0, 1, .., K, each
 * computed as that product in double precision, where K is the largest k
 * with t_k <= t_end. t_end counts as a multiple of sample when it is
 * within 1e-9 sample intervals (or a few rounding errors of t_end) of
 * one; the last row is then t_K, which may differ from the typed t_end in
 * the last digit. Otherwise one more row follows at t_end exactly. */
#ifndef APPS_RUN_LOOP_H
#define APPS_RUN_LOOP_H

#include "csv_writer.h"
#include "eom/eom.h"

typedef struct run_plan {
    const char *label; /* the demo's name, for messages */
    double t_end;      /* >= 0 */
    double sample;     /* > 0 */
    eom_opts opts;     /* passed to eom_integ_new as they are */
    int quiet;         /* no summary */
    int progress;      /* draw the progress line (see progress.h) */
} run_plan;

/* The sample grid: *K as above, *exact 1 when t_end is on the grid.
 * Valid for t_end / sample <= 1e12 (eom-run refuses larger ratios). */
void run_grid(double t_end, double sample, long long *K, int *exact);

/* Integrate s (borrowed) from (0, x0) as planned, writing the header and
 * the rows to w (borrowed; flushed at least once a second and before
 * returning, not closed). Messages and the summary go to standard
 * error. Returns 0 on success, 1 on a failure (integrator, evaluation or
 * write): the rows before the failure are in w. */
int run_loop(eom_system *s, const double *x0, const run_plan *p,
             csv_writer *w);

#endif /* APPS_RUN_LOOP_H */
