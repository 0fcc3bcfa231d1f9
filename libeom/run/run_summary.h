/* run_summary.h - what eom-run reports on standard error at the end of a
 * run: counts from the integrator, wall time, energy drift and constraint
 * residuals, gathered from the rows as they are written.
 *
 * Energy drift (docs/cli.md): max over the rows of |E + W - E0|, where E0
 * is E at t = 0, and the same relative to the energy scale
 * max over the rows of max(|E|, |L|), which for a natural system is the
 * largest T + |V| seen: a scale that does not vanish when E happens to be
 * near zero. */
#ifndef APPS_RUN_SUMMARY_H
#define APPS_RUN_SUMMARY_H

#include <stdio.h>

#include "eom/run.h"
#include "eom/eom.h"

typedef struct run_summary {
    long rows;         /* rows written */
    double t_last;     /* time of the last row */
    double E0;         /* E of the first row */
    double drift;      /* max |E + W - E0| */
    double scale;      /* max of max(|E|, |L|) */
    double phi_max;    /* max |phi| over the rows */
    double phidot_max; /* max |C qd| over the rows */
} run_summary;

void run_summary_init(run_summary *r);

/* A row at time t with dissipated work W was written; info as filled by
 * eom_run_columns_fill (NaN values are ignored). */
void run_summary_add(run_summary *r, double t, double W,
                     const eom_run_row_info *info);

/* The measures the verdict judges (eom_run_judge): the relative drift
 * (NaN when the energy scale is 0), max |phi| over the rows and st's
 * steps (st may be NULL), max |C qd| over the rows. */
void run_summary_measures(const run_summary *r, const eom_stats *st,
                          eom_run_measures *m);

/* The report on f: label (the demo) and method name, st (NULL when no
 * integrator was created), nconstraints of the system, vel the name of
 * its velocity residual ("C qd", or "C qd + dphi/dt" for a model that
 * reads the time), wall the total wall time in seconds, v the verdict
 * (NULL for a run that failed before t_end: no verdict line). */
void run_summary_print(const run_summary *r, FILE *f, const char *prog,
                       const char *label,
                       const char *method, const eom_stats *st,
                       const char *vel,
                       int nconstraints, double wall,
                       const eom_run_verdict *v);

#endif /* APPS_RUN_SUMMARY_H */
