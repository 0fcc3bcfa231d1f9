/* hard_stiff.c - bench-hard's stiff target (issue 10): the closed
 * five-link chain from the paper's start with EI x 100 (4e6 N m^2) and
 * two modes per link, over 10 s, with the paper's undamped beams and with
 * a modal damping ratio of 2% on every mode. For each, every method's
 * work against precision (wp_sweep.h): rk4 over a sweep of steps, the
 * adaptive methods over a sweep of tolerances (atol = rtol: deflections
 * and angles are held to the same absolute error), each run's state
 * error at t = 10 s against a reference (bdf at rtol 1e-12) that a second
 * method (adams at rtol 1e-12) checks. From each sweep, the CPU time to
 * reach a state error of 1e-6 (log-log between the runs that bracket it,
 * wp_interp.h); the target is the best implicit method reaching it at
 * least 5 times faster than the best explicit one.
 *
 * Classes: rk4 and erk are explicit. So is adams in effect: CVODE's
 * Adams-Moulton corrector is solved by fixed-point iteration
 * (integrate_cvode.c), which converges only for steps below the
 * stiffness limit, as an explicit method's steps are stable only there.
 * bdf, ida and esdirk are implicit: Newton iteration with the exact
 * Jacobian (eom_opts.dq_jacobian = 0, the default, as wp_run.c leaves
 * it). imex is counted implicit too: its elastic and dissipative forces
 * (with q' = qd) are, with Newton iteration on the Hessians of V and R;
 * its inertial terms are explicit (docs/integrators.md, "imex").
 *
 * Time: CPU time of eom_integ_new and every eom_integ_advance (wp_run.h;
 * the program is single-threaded, so the thread's CPU clock is the
 * process's), the minimum over interleaved repetitions of the shorter
 * runs. Other work on the machine inflates wall time, much less CPU
 * time; wall time is printed beside it.
 *
 * Each case first prints the fastest eigenvalue of the linearization at
 * the start (eom_linearize_state): its modulus sets rk4's stability
 * limit, and its damping whether an implicit method can step over the
 * modes or must resolve them like every other method.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_chain.h"
#include "hard_stiff.h"
#include "wp_interp.h"
#include "wp_sweep.h"
#include "wp_table.h"

static const double target_err = 1e-6;

/* From a step beyond rk4's stability limit (about 2.8 / 3200 s on this
 * chain) to steps that resolve the undamped modes' phase over the run;
 * the sweep stops at the first run below the target error. */
static const double full_dts[] = {1e-3, 8e-4, 5e-4, 2e-4, 1e-4,
                                  5e-5, 2e-5, 1e-5, 5e-6};
static const double quick_dts[] = {5e-4, 2e-4};

static void plan_of(wp_plan *p, int quick)
{
    memset(p, 0, sizeof *p);
    p->t_end = quick ? 0.2 : 10.0;
    /* samples only for the energy and residual checks: few, so that
     * adams's and ida's projections at output times and the stops of the
     * one-step methods there do not shape the cost */
    p->sample = quick ? 0.1 : 1.0;
    p->nmethods = WP_NMETHODS;
    p->rtol_loose = 1e-2;
    p->rtol_tight = quick ? 1e-4 : 1e-9;
    p->atol_per_rtol = 1.0;
    p->dts = quick ? quick_dts : full_dts;
    p->ndt = quick ? 2 : (int)(sizeof full_dts / sizeof full_dts[0]);
    p->rk4_stop = target_err;
    /* bdf's per-step tolerance for 1e-12 sits at its floor, where it keeps
     * the error near 3e-12 (docs/integrators.md); adams checks it */
    p->ref_method = EOM_BDF;
    p->ref_rtol = quick ? 1e-10 : 1e-12;
    p->check_method = EOM_ADAMS;
    p->check_rtol = p->ref_rtol;
    p->rounds = quick ? 1 : 3;
    p->repeat_budget = 2.0;
}

static int implicit(int method)
{
    return method == EOM_BDF || method == EOM_IDA || method == EOM_ESDIRK ||
           method == EOM_IMEX;
}

/* The eigenvalue of largest modulus of the constrained linearization at
 * (0, x0), as a frequency and a damping ratio. */
static void print_fastest(eom_system *s, const double *x0)
{
    eom_state_linear lin;
    double wmax = 0.0, zeta = 0.0;
    int i;
    memset(&lin, 0, sizeof lin);
    if (eom_linearize_state(s, 0.0, x0, &lin) != EOM_OK) {
        printf("Linearization at the start failed: %s\n\n",
               eom_system_errmsg(s));
        return;
    }
    for (i = 0; i < lin.nz; i++) {
        const double w = hypot(lin.eig_re[i], lin.eig_im[i]);
        if (w > wmax) {
            wmax = w;
            zeta = -lin.eig_re[i] / w;
        }
    }
    eom_state_linear_free(&lin);
    printf("Fastest eigenvalue of the linearization at the start: |lambda| "
           "= %.0f rad/s, damping ratio %.2g (decay time %.3g s); rk4 is "
           "stable for dt below about 2.8 / |lambda| = %.2e s.\n\n", wmax,
           zeta, zeta > 0.0 ? 1.0 / (zeta * wmax) : INFINITY, 2.8 / wmax);
}

static void print_runs(const wp_sweep *w)
{
    int k, j;
    printf("| method | class | setting | state error | angle error | cpu "
           "(ms) | wall (ms) | steps | rhs | jac | failed steps | note |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (k = 0; k < w->plan->nmethods; k++)
        for (j = 0; j < w->count[k]; j++) {
            const wp_run *r = &w->runs[w->first[k] + j];
            char set[32], cpu[32], wall[32];
            wp_setting_text(&r->set, set, sizeof set);
            wp_ms_text(r->cpu, cpu, sizeof cpu);
            wp_ms_text(r->wall, wall, sizeof wall);
            printf("| %s | %s | %s | ", eom_method_name((eom_method)k),
                   implicit(k) ? "implicit" : "explicit", set);
            if (r->status == EOM_OK)
                printf("%.2e | %.2e | %s | %s | %ld | %ld | %ld | %ld | %s "
                       "|\n", r->err, r->err_angle, cpu, wall, r->steps,
                       r->rhs, r->jacs, r->failures,
                       r->irreproducible ? "repetitions differ" : "");
            else
                printf("- | - | %s | %s | %ld | %ld | %ld | %ld | failed: %s "
                       "|\n", cpu, wall, r->steps, r->rhs, r->jacs,
                       r->failures, eom_status_name(r->status));
        }
    if (w->rk4_stopped > 0)
        printf("\nrk4 stopped at its first step below %.0e: %d smaller "
               "step%s of the plan not run.\n", w->plan->rk4_stop,
               w->rk4_stopped, w->rk4_stopped > 1 ? "s" : "");
    printf("\n");
}

/* Each method's CPU time to the target error; the best of each class and
 * their ratio. Returns that ratio (NAN when a class never reached it). */
static double print_reach(const wp_sweep *w)
{
    double best[2] = {INFINITY, INFINITY}; /* explicit, implicit */
    int kbest[2] = {-1, -1}, k;
    printf("| method | class | cpu to %.0e (ms) |\n|---|---|---|\n",
           target_err);
    for (k = 0; k < w->plan->nmethods; k++) {
        double t;
        char ms[32];
        const wp_reach how = wp_time_at_error(&w->runs[w->first[k]],
                                              w->count[k], target_err, 1,
                                              &t);
        wp_ms_text(t, ms, sizeof ms);
        printf("| %s | %s | %s%s |\n", eom_method_name((eom_method)k),
               implicit(k) ? "implicit" : "explicit",
               how == WP_AT_LOOSEST ? "<= " : "",
               how == WP_NOT_REACHED ? "not reached" : ms);
        if (how != WP_NOT_REACHED && t < best[implicit(k)]) {
            best[implicit(k)] = t;
            kbest[implicit(k)] = k;
        }
    }
    if (kbest[0] < 0 || kbest[1] < 0) {
        printf("\nThe ratio cannot be formed: no %s method reached %.0e."
               "\n\n", kbest[0] < 0 ? "explicit" : "implicit", target_err);
        return NAN;
    }
    printf("\nBest explicit: %s, %.1f ms; best implicit: %s, %.1f ms; "
           "explicit / implicit = %.2f (target >= 5: %s).\n\n",
           eom_method_name((eom_method)kbest[0]), 1e3 * best[0],
           eom_method_name((eom_method)kbest[1]), 1e3 * best[1],
           best[0] / best[1], best[0] / best[1] >= 5.0 ? "met" : "missed");
    return best[0] / best[1];
}

/* One case: the chain with modal damping ratio zeta. *ratio receives the
 * explicit / implicit ratio. Returns 0, or 1 when it could not run. */
static int one_case(double zeta, const wp_plan *p, double *ratio)
{
    chain_cfg cfg = {5, 2, 1, 4e6, 10.0, 9.81, 10.0, 0.0, bench_paper5};
    char name[64], msg[256];
    eom_system *s;
    double x0[64];
    wp_sweep w;
    int rc = 0;
    *ratio = NAN;
    cfg.zeta = zeta;
    if (zeta > 0.0)
        snprintf(name, sizeof name, "%g%% modal damping", 100.0 * zeta);
    else
        snprintf(name, sizeof name, "undamped");
    printf("## Stiff target: closed chain, EI x 100, 2 modes per link, %s, "
           "%g s\n\n", name, p->t_end);
    if (!(s = bench_chain_new(&cfg, msg, sizeof msg))) {
        printf("Set-up failed: %s\n\n", msg);
        return 1;
    }
    /* the paper's start lies on the constraints to round-off: projecting
     * it is what every run's eom_integ_new would do */
    if (2 * eom_system_ncoords(s) > 64 ||
        eom_initial_state(s, x0) != EOM_OK ||
        eom_project(s, x0, 1e-12, NULL) != EOM_OK) {
        printf("No start: %s\n\n", eom_system_errmsg(s));
        eom_system_free(&s);
        return 1;
    }
    print_fastest(s, x0);
    fprintf(stderr, "bench-hard: stiff target, %s\n", name);
    if (wp_sweep_run(&w, name, s, x0, p) != 0) {
        printf("The reference failed (its message is on stderr).\n\n");
        rc = 1;
    } else {
        char ms[32];
        wp_ms_text(w.ref.cpu, ms, sizeof ms);
        printf("Reference: %s at rtol = atol = %.0e, %ld steps, %s ms of "
               "CPU; %s at the same tolerance differs from it by %.1e at "
               "t = %g s: errors below that are not measured.\n\n",
               eom_method_name(w.ref.set.method), p->ref_rtol, w.ref.steps,
               ms, eom_method_name(w.check.set.method), w.floor, p->t_end);
        print_runs(&w);
        *ratio = print_reach(&w);
    }
    wp_sweep_free(&w);
    eom_system_free(&s);
    return rc;
}

int hard_stiff_target(int quick)
{
    static const double zetas[2] = {0.0, 0.02};
    double ratio[2];
    wp_plan p;
    int k, rc = 0;
    plan_of(&p, quick);
    printf("Work against precision, every method (atol = rtol; rk4: step "
           "dt). State error: max abs(x - x_ref) over all coordinates and "
           "rates at t-end; angle error: the same over the angles alone. "
           "CPU time of eom_integ_new and every "
           "eom_integ_advance, the minimum over up to %d interleaved "
           "repetitions of the runs shorter than %g s. Cost to %.0e: "
           "log-log between the two runs of a sweep that bracket it (\"<=\":"
           " the loosest run was already below it).\n\n", p.rounds,
           p.repeat_budget, target_err);
    for (k = 0; k < 2; k++)
        rc |= one_case(zetas[k], &p, &ratio[k]);
    printf("Stiff target, best explicit / best implicit CPU time to %.0e: "
           "undamped %.2f, 2%% modal damping %.2f (target >= 5).\n",
           target_err, ratio[0], ratio[1]);
    return rc;
}
