/* modes_report.h - eom-run --modes: instead of a run, the static
 * equilibrium nearest the initial state (eom_equilibrium) and the natural
 * frequencies about it (eom_linearize), printed as a table.
 *
 * The equilibrium is solved to MODES_EQ_TOL on max |dL/dq + C^T lambda|
 * (the unbalanced generalized forces, in N or N m) and max |phi| (the
 * constraints' units); that is far below the 1e-6 relative balance that
 * eom_linearize demands, and far above round-off for the demos' forces.
 * Frequencies are undamped and ascending, as eom_linearize gives them: a
 * negative entry -w is an unstable direction growing like exp(w t); an
 * entry within MODES_NEUTRAL of the largest is reported as neutral (a
 * free motion such as a rigid rotation without gravity). */
#ifndef APPS_MODES_REPORT_H
#define APPS_MODES_REPORT_H

#include <stdio.h>

#include "eom/eom.h"

#define MODES_EQ_TOL 1e-9
#define MODES_NEUTRAL 1e-6

/* Start from the coordinates of x0 (2n values; the rates are not used),
 * find the equilibrium of s and print it and the frequencies on f. label
 * names the demo in messages, origin where x0 came from ("the initial
 * state", "the demo's rest guess"). Returns 0, or 1 after a message on standard
 * error (no equilibrium found, or the linearization failed). */
int modes_report(FILE *f, eom_system *s, const double *x0,
                 const char *label, const char *origin);

/* eom-run --modes about a start state x (2n values) that moves: a
 * steady motion (eom_linearize_steady), or one at rest of a model with
 * velocity constraints (no equilibrium search for those). Prints the
 * start, the cyclic coordinates, the independent states (keep: nkeep
 * state indices named by --independent, or NULL to choose them) and the
 * eigenvalues of the reduced state matrix with a verdict on stability.
 * Returns 0, or 1 after a message on standard error (not a steady
 * motion: the message names the largest acceleration). */
int modes_steady_report(FILE *f, eom_system *s, const double *x,
                        const int *keep, int nkeep, const char *label);

#endif /* APPS_MODES_REPORT_H */
