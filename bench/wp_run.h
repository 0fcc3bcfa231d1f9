/* wp_run.h - one timed integration of the work-precision benchmark
 * (bench_wp.c): a system from its start to t_end with one integrator
 * setting, sampled at a fixed interval, with the cost, the final state
 * and the conservation and constraint errors seen on the samples.
 *
 * What is timed: eom_integ_new plus every eom_integ_advance, on a
 * monotonic clock (wall time) and on the thread's CPU clock. The samples'
 * energy and residual evaluations are the benchmark's own measuring and
 * are left out. The process is single-threaded, so the two agree on an
 * idle machine; wall well above CPU means that other work took the core.
 * A run can be repeated; it is deterministic, so a repetition only adds
 * a time (the minimum of each clock is kept) and checks that the steps
 * and the final state are the same. */
#ifndef BENCH_WP_RUN_H
#define BENCH_WP_RUN_H

#include "eom/eom.h"

/* One point of a method's sweep. */
typedef struct wp_setting {
    eom_method method;
    double dt;         /* rk4: the step (s) */
    double rtol, atol; /* adaptive methods */
} wp_setting;

/* What a run measured. x is allocated by the caller (2n values). */
typedef struct wp_run {
    wp_setting set;
    int status;          /* EOM_OK, or the status of the failed call */
    char msg[400];       /* the failure's message (the solver's flag) */
    double wall;         /* seconds: the smallest over the repetitions */
    double cpu;          /* seconds of CPU: the smallest likewise */
    int reps;            /* repetitions timed */
    int irreproducible;  /* 1 if a repetition gave other steps or state */
    long steps, rhs, failures, jacs; /* eom_stats of the first repetition */
    double energy_err;   /* max |E + W - E0| / max(|E0|, T0 + |V0|)
                            (infinite if the energy could not be had) */
    double phi_max;      /* max |phi| on the samples (what the caller got) */
    double drift;        /* eom_stats.max_residual: |phi| before projecting */
    double *x;           /* [2n] the state at t_end (valid if status == 0) */
    double err;          /* max |x - x_ref| over all 2n components */
    double err_angle;    /* the same over the angles (unit "rad") only */
} wp_run;

/* Seconds from a monotonic clock. */
double wp_now(void);

/* Seconds of CPU time used by the calling thread. */
double wp_cpu_now(void);

/* Integrate s (borrowed) from x0 (2n) at t = 0 to t_end, advancing to
 * every multiple of sample, with the setting r->set; fill every field of r
 * but err and err_angle (r->x must hold 2n doubles). Returns r->status. */
int wp_run_first(eom_system *s, const double *x0, double t_end,
                 double sample, wp_run *r);

/* Run r's setting again for one more time: keeps the smaller wall time,
 * counts the repetition and sets r->irreproducible if the steps or the
 * final state differ. tmp: scratch of 2n doubles. */
void wp_run_again(eom_system *s, const double *x0, double t_end,
                  double sample, wp_run *r, double *tmp);

/* "dt = 1e-3" or "rtol = 1e-6" into buf. */
void wp_setting_text(const wp_setting *set, char *buf, size_t len);

#endif
