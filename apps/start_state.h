/* start_state.h - the initial state of a run of a constrained system.
 *
 * The demos' defaults satisfy their constraints, but --set can move a
 * coordinate, a rate or a length so that they no longer do (for the
 * closed chain, --set D=12 moves the far pin). Integrating from there
 * would carry that error along (or, with projection on, remove it only
 * after the first step, so the first CSV row would be off the
 * constraints). So before a run the state is checked: if max |phi| or
 * max |C qd| exceeds the projection tolerance, it is projected onto
 * phi = 0 and C qd = 0 (eom_project, the minimum M-norm correction) and
 * one line on standard error says so with the residuals before; with
 * --no-project it is left alone and a warning says that the run starts
 * off the constraints. */
#ifndef APPS_START_STATE_H
#define APPS_START_STATE_H

#include "eom/eom.h"

/* Check, and project when o->project is set, the state x (2n values,
 * updated in place) of s with tolerance o->proj_tol. label names the
 * demo in messages. Returns 0 (x is the state to start from), or 1 after
 * a message when the residuals cannot be evaluated or the projection
 * fails. Systems without constraints return 0 at once. */
int start_state_prepare(eom_system *s, double *x, const eom_opts *o,
                        const char *label);

#endif /* APPS_START_STATE_H */
