/* hand_ref.h - references for the integrator tests computed without
 * libeom: equations of motion derived by hand, for a state of 4 values
 * (two coordinates and their rates), integrated by classical RK4. */
#ifndef TESTS_HAND_REF_H
#define TESTS_HAND_REF_H

typedef void (*hand_f)(const double *y, double *f);

/* The spring pendulum with m = 1, k = 75, r0 = 1, g = 9.81 (the shipped
 * model's and eom_models_spring_pendulum's defaults), y = (r, th, r',
 * th'), th from the downward vertical:
 *     r''  = r th'^2 - (k/m)(r - r0) + g cos th,
 *     th'' = -(2 r' th' + g sin th) / r. */
void hand_spring(const double *y, double *f);

/* y(t_end) from y(0) by classical RK4 of f in the given steps. */
void hand_rk4(hand_f f, double t_end, long steps, double *y);

/* max_e |a_e - b_e| over len values */
double hand_max_diff(int len, const double *a, const double *b);

#endif
