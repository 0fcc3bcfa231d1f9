/* support_tape.h - helpers that run a user function on libtape's
 * evaluators (double and embedded-tuple) and collect all outputs, so the
 * tests compare tape sweeps with the other engines in a line. Uses only
 * the public API. */
#ifndef TESTS_SUPPORT_TAPE_H
#define TESTS_SUPPORT_TAPE_H

#include "tape/tape.h"

/* Run f on the double evaluator ev at x; y[m] receives every output
 * (m = tp_rec_n_outputs after the run). Returns the run's status if it
 * failed, else the worst output status (TP_OK or TP_WARN_NONFINITE). */
int st_eval(tp_rec *ev, const double *x, tp_func f, void *user, double *y);

/* Run f on the tuple evaluator tu at x (n = tp_rec_n_indep): y[m] values,
 * G (m x n) gradients, H (m x n x n) full symmetric Hessians; any of the
 * three may be NULL. Returns like st_eval. */
int st_tuple(tp_rec *tu, const double *x, tp_func f, void *user, double *y,
             double *G, double *H);

/* Expand a packed lower triangle (tp_tuple_output's layout) to a full
 * symmetric n x n matrix. */
void st_unpack(int n, const double *packed, double *H);

/* A tape of 2N independents from f, the first N in group 0 (the
 * coordinates q), the last N in group 1 (the rates qd), the grouping
 * tp_lagrange reads; NULL if recording failed. N <= 64. */
tp_tape *st_record_qqd(tp_func f, int N, void *user);

/* a and b equal bit for bit, but for the sign of a zero: generated code
 * leaves out terms whose row is structurally zero, which can turn the
 * interpreter's -0 into +0 (libtape/src/codegen_lagrange.c). */
int st_same_bits(double a, double b);

#endif
