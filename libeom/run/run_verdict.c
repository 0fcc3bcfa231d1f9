/* run_verdict.c - the health verdict of a finished run (eom/run.h,
 * docs/run.md "The verdict"): what the run measured of itself, each
 * measure against a threshold scaled by the run's own tolerance.
 *
 * The tolerance tau is max(rtol, tol_reachable): the one the run was
 * asked for, or the looser one its method could actually be held to
 * (eom_stats.tol_reachable). rk4 has no error control; it is judged
 * against the rtol it was given like any other method, so a fixed step
 * too long for the motion shows. With k the run's steps and
 * allow(x) = clamp(x max(1000, 10 k), 1e-8, 1e-2), the thresholds, in
 * this order:
 *
 *   relative energy drift   max |E + W - E0| / energy scale <= allow(tau)
 *   constraint residual     max |phi| <= allow(max(tau, atol)), and at
 *                           least 10 proj_tol
 *   velocity residual       max |C qd (+ dphi/dt)|, the same threshold
 *   branch switches         0
 *
 * An error-controlled method keeps each step's error near tau, so the
 * drift of a method that does not conserve energy grows with the steps:
 * 10 tau a step leaves room for it (erk at rtol 1e-10 on the double
 * pendulum's wildest swings drifted by 0.71 tau a step over 60 s), 1000
 * tau for short runs. Every shipped model with every method at the
 * default tolerances drifts by less than 9e-9 relative over its 10 s.
 * The floor 1e-8 keeps rounding over millions of steps from failing a
 * run asked for a tolerance near the machine's precision, and the cap
 * 1e-2 keeps a run asked for a loose tolerance, or a very long one, from
 * passing with its energy off by percents. A branch switch is a jump to
 * another assembly of the mechanism: a different motion, whatever its
 * energy says. */
#include "eom/run.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define FACTOR 1e3   /* threshold / tolerance, at least */
#define PER_STEP 10.0 /* threshold / tolerance, per step */
#define FLOOR 1e-8
#define CAP 1e-2

/* The threshold for a measure held to tolerance tol over steps steps. */
static double allow(double tol, long steps)
{
    const double k = fmax(FACTOR, PER_STEP * (double)steps);
    return fmin(fmax(tol * k, FLOOR), CAP);
}

/* Where the threshold thr for tolerance tol came from, into why. */
static void explain(char *why, size_t len, double tol, double thr,
                    long steps)
{
    if (thr == CAP)
        snprintf(why, len, "the largest threshold, 1e-2");
    else if (thr == FLOOR)
        snprintf(why, len, "the smallest threshold, 1e-8");
    else if (PER_STEP * (double)steps > FACTOR)
        snprintf(why, len, "%g x the run's tolerance %.3g for each of its "
                 "%ld steps", PER_STEP, tol, steps);
    else
        snprintf(why, len, "%g x the run's tolerance %.3g", FACTOR, tol);
}

/* Record the first failing measure in v. */
static void fail(eom_run_verdict *v, const char *measure, double value,
                 double threshold, const char *why)
{
    if (!v->healthy)
        return;
    v->healthy = 0;
    v->measure = measure;
    v->value = value;
    v->threshold = threshold;
    snprintf(v->text, sizeof v->text, "%s %.3g exceeds %.3g (%s)", measure,
             value, threshold, why);
}

void eom_run_judge(const eom_opts *o, const eom_stats *st,
                   const eom_run_measures *m, eom_run_verdict *v)
{
    const double reach = st ? st->tol_reachable : 0.0;
    const double tau = fmax(o->rtol, reach);
    const long steps = st ? st->steps : 0;
    const double thr_e = allow(tau, steps);
    const double thr_c = fmax(allow(fmax(tau, o->atol), steps),
                              10.0 * o->proj_tol);
    const long switches = st ? st->branch_switches : 0;
    char why[160];

    memset(v, 0, sizeof *v);
    v->healthy = 1;
    v->tol = tau;
    v->energy_threshold = thr_e;
    v->residual_threshold = thr_c;
    /* NaN measures (not computed: a failed row) are not judged here: the
     * run has already failed for them */
    if (m->drift_rel > thr_e) {
        explain(why, sizeof why, tau, thr_e, steps);
        fail(v, "relative energy drift", m->drift_rel, thr_e, why);
    }
    if (m->phi_max > thr_c) {
        explain(why, sizeof why, fmax(tau, o->atol), thr_c, steps);
        fail(v, "constraint residual max |phi|", m->phi_max, thr_c, why);
    }
    if (m->phidot_max > thr_c) {
        explain(why, sizeof why, fmax(tau, o->atol), thr_c, steps);
        fail(v, "velocity constraint residual max |C qd|", m->phidot_max,
             thr_c, why);
    }
    if (switches > 0) {
        snprintf(why, sizeof why, "the first at t = %.6g: the motion "
                 "jumped to another assembly of the mechanism",
                 st->first_branch_switch);
        fail(v, "branch switches", (double)switches, 0.0, why);
    }
}
