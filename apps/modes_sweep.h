/* modes_sweep.h - eom-run --modes --sweep NAME=LO:HI:N: the eigenvalues
 * of the steady motion (eom_linearize_steady) at N values of a parameter
 * from LO to HI, as CSV (docs/csv.md, "Eigenvalues against a parameter")
 * and, with --plots, the classic plot of their real and imaginary parts
 * against it.
 *
 * The independent states are the same at every value, so that the CSV
 * has the same columns on every row: those named (--independent), or
 * else the union of the ones chosen at each value (a first pass). The
 * columns follow curves: the first row's eigenvalues are in the order of
 * eom_linearize_steady (real part, then imaginary part, ascending); on
 * each later row, the eigenvalues are matched to the previous row's
 * columns closest pair first (by the distance in the complex plane). */
#ifndef APPS_MODES_SWEEP_H
#define APPS_MODES_SWEEP_H

#include <stdio.h>

#include "eom/eom.h"

typedef struct modes_sweep {
    const char *arg; /* the option's text (borrowed: from argv) */
    char name[128];  /* NAME */
    double lo, hi;   /* the first and last value */
    int count;       /* N >= 2 values, evenly spaced */
} modes_sweep;

/* Parse NAME=LO:HI:N (LO and HI finite numbers, N an integer from 2 to
 * 1000000). Returns 0, or -1 with a message in err. */
int modes_sweep_parse(const char *arg, modes_sweep *sw, char *err,
                      size_t errlen);

/* The start state x (2n values) of s for the parameters now set:
 * eom_initial_state, the --set coordinate overrides and the projection
 * onto the constraints. Returns 0, or 1 after a message. */
typedef int (*modes_start_fn)(void *user, eom_system *s, double *x);

/* Run the sweep of sw's parameter (index k of s) and write the CSV to
 * out; with plots the plots beside it (gnuplot). keep: nkeep state
 * indices named by --independent, or NULL. label names the model in
 * messages and titles. Returns 0, or 1 after a message on standard
 * error. */
int modes_sweep_run(eom_system *s, int k, const modes_sweep *sw,
                    modes_start_fn start, void *user, const int *keep,
                    int nkeep, const char *label, const char *out, int plots,
                    int quiet);

#endif /* APPS_MODES_SWEEP_H */
