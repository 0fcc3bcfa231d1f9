/* wp_sweep.h - the work-precision sweep of one demo (bench_wp.c): a
 * reference solution, checked by a second method, and every integrator
 * over its range of step sizes or tolerances, with the state error of
 * each run against the reference.
 *
 * Repetitions: every run is timed once in a first round, in sweep order.
 * Up to plan.rounds - 1 further rounds time again each run whose
 * repetitions so far add up to less than plan.repeat_budget seconds (its
 * best time times its repetitions), so that a run of a few milliseconds
 * is timed plan.rounds times and one longer than the budget once. The
 * methods take turns in a rotating order, so that a burst of load on the
 * machine does not fall on one method. The time kept is the minimum over
 * the repetitions: other work can only add to a run's time. */
#ifndef BENCH_WP_SWEEP_H
#define BENCH_WP_SWEEP_H

#include "wp_run.h"

/* rk4, erk, adams, bdf, ida, esdirk, imex: eom_method order */
enum { WP_NMETHODS = 7 };

typedef struct wp_plan {
    double t_end, sample;    /* s: the run, and the interval of samples */
    double rtol_loose, rtol_tight; /* adaptive sweep, one run per decade */
    double atol_per_rtol;    /* atol = atol_per_rtol * rtol */
    const double *dts;       /* rk4 steps, largest first */
    int ndt;
    double rk4_stop;         /* rk4 stops once its error is below this */
    int nmethods;            /* the methods 0 .. nmethods-1 are swept
                                (5: rk4 to ida; WP_NMETHODS: and esdirk
                                and imex) */
    eom_method ref_method, check_method; /* the reference, its check */
    double ref_rtol, check_rtol; /* their tolerances */
    int rounds;              /* timing rounds: the most repetitions */
    double repeat_budget;    /* s: a run is repeated until it has taken
                                about this long in total */
} wp_plan;

typedef struct wp_sweep {
    const char *demo;          /* the demo's name (borrowed) */
    eom_system *s;             /* borrowed */
    int n, m;                  /* coordinates, constraints */
    const double *x0;          /* [2n] the start (borrowed) */
    const wp_plan *plan;       /* borrowed */
    wp_run ref, check;         /* the reference and the second method */
    double floor, floor_angle; /* |ref - check| at t_end: all, angles */
    wp_run *runs;              /* grouped by method, each in sweep order */
    int nruns;
    int first[WP_NMETHODS], count[WP_NMETHODS]; /* method k's runs */
    int rk4_stopped;           /* rk4 steps skipped by plan.rk4_stop */
    double seconds;            /* wall time of the whole sweep */
} wp_sweep;

/* Run the sweep of system s (borrowed) from x0 (2n, borrowed) with plan
 * p (borrowed): fills w. Progress goes to stderr. Returns 0, or -1 when
 * the reference failed or memory ran out (message on stderr); failed
 * runs of the sweep are kept with their status and are not an error. */
int wp_sweep_run(wp_sweep *w, const char *demo, eom_system *s,
                 const double *x0, const wp_plan *p);

/* Free what wp_sweep_run allocated (not the borrowed system). */
void wp_sweep_free(wp_sweep *w);

#endif
