/* run_verdict.c - the health verdict of a finished run (eom/run.h,
 * docs/run.md "The verdict"): what the run measured of itself, each
 * measure against a threshold scaled by the run's own tolerance.
 *
 * The tolerance tau is max(rtol, tol_reachable): the one the run was
 * asked for, or the looser one its method could actually be held to
 * (eom_stats.tol_reachable). rk4 has no error control; it is judged
 * against the rtol it was given like any other method, so a fixed step
 * too long for the motion shows. The thresholds, in this order:
 *
 *   relative energy drift   max |E + W - E0| / energy scale
 *                           <= clamp(1000 tau, 1e-8, 1e-2)
 *   constraint residual     max |phi| <= clamp(1000 max(tau, atol),
 *                           1e-8, 1e-2), and at least 10 proj_tol
 *   velocity residual       max |C qd (+ dphi/dt)|, the same threshold
 *   branch switches         0
 *
 * 1000 tau leaves room for the global error to grow over a run (every
 * shipped model with every method at the default tolerances drifts by
 * less than 9e-9 relative: 1100 times below); the floor 1e-8 keeps
 * rounding over millions of steps from failing a run asked for a
 * tolerance near the machine's precision, and the cap 1e-2 keeps a run
 * asked for a loose tolerance from passing with its energy off by
 * percents. A branch switch is a jump to another assembly of the
 * mechanism: a different motion, whatever its energy says. */
#include "eom/run.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define FACTOR 1e3  /* threshold / tolerance */
#define FLOOR 1e-8
#define CAP 1e-2

static double clamp_thr(double v)
{
    return fmin(fmax(v, FLOOR), CAP);
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
    const double thr_e = clamp_thr(FACTOR * tau);
    const double thr_c = fmax(clamp_thr(FACTOR * fmax(tau, o->atol)),
                              10.0 * o->proj_tol);
    const long switches = st ? st->branch_switches : 0;
    char why[128];

    memset(v, 0, sizeof *v);
    v->healthy = 1;
    v->tol = tau;
    v->energy_threshold = thr_e;
    v->residual_threshold = thr_c;
    snprintf(why, sizeof why, "%g x the run's tolerance %.3g", FACTOR, tau);
    /* NaN measures (not computed: a failed row) are not judged here: the
     * run has already failed for them */
    if (m->drift_rel > thr_e)
        fail(v, "relative energy drift", m->drift_rel, thr_e,
             thr_e == FACTOR * tau ? why
             : thr_e == CAP        ? "the largest threshold, 1e-2"
                                   : "the smallest threshold, 1e-8");
    snprintf(why, sizeof why, "%g x the run's tolerance %.3g", FACTOR,
             fmax(tau, o->atol));
    if (m->phi_max > thr_c)
        fail(v, "constraint residual max |phi|", m->phi_max, thr_c, why);
    if (m->phidot_max > thr_c)
        fail(v, "velocity constraint residual max |C qd|", m->phidot_max,
             thr_c, why);
    if (switches > 0) {
        snprintf(why, sizeof why, "the first at t = %.6g: the motion "
                 "jumped to another assembly of the mechanism",
                 st->first_branch_switch);
        fail(v, "branch switches", (double)switches, 0.0, why);
    }
}
