/* bench_wp.c - work against precision: for each demo (spring-pendulum,
 * open-chain, closed-chain; default settings and start), every integrator
 * over a sweep of step sizes (rk4) or tolerances (erk, adams, bdf, ida),
 * with the wall time of each run beside the error it reached against a
 * tight-tolerance reference computed in the same run.
 *
 * Error measures, all at or up to t-end:
 *   state error   max |x - x_ref| over all 2n components at t-end (angles
 *                 in rad, deflections in m and their rates mixed), and
 *                 the same over the angles alone;
 *   energy error  max over the samples of |E + W - E0| / max(|E0|,
 *                 T0 + |V0|), W being the work of the dampers;
 *   residual      max |phi| on the samples, and eom_stats' max_residual
 *                 (the drift the projection removed), for the closed chain.
 * The reference is adams at rtol 1e-14: of the five methods it came
 * closest to converged rk4 runs (dt = 2e-5) at the least cost. ida at
 * rtol 1e-13 checks it, and their difference is the floor of measurable
 * error. (At rtol 1e-14 both bdf and ida fail on the closed chain, and
 * erk's error, controlled per step, grows with its many steps.)
 *
 * Writes into OUTDIR (default bench-results/): DEMO.md (the table),
 * DEMO-wp.{dat,gp,png,svg} (the plot) and summary.md (the fastest method
 * at state errors 1e-3, 1e-6, 1e-9), and prints the same text. Prints,
 * never asserts, the closed chain's target: an adaptive method reaching
 * 1e-6 at least 20 times faster than rk4. --quick: the spring pendulum
 * over 1 s with a few settings, checked only for sane numbers (finite
 * errors that shrink with the tolerance for at least one method).
 *
 * usage: bench-wp [--quick] [--no-plots] [--demo NAME]... [OUTDIR] */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "demos.h"
#include "eom/run.h"
#include "wp_interp.h"
#include "wp_plot.h"
#include "wp_sweep.h"
#include "wp_table.h"

enum { MAX_DEMOS = 3 };

/* From a step beyond rk4's stability limit on the chains (h omega <= 2.8
 * with bending modes up to 105 rad/s: dt < 0.027 s) down to steps the
 * sweep does not reach, since it stops below the smallest target error
 * (rk4_stop). */
static const double full_dts[] = {5e-2, 2e-2, 1e-2, 5e-3, 2e-3, 1e-3,
                                  5e-4, 2e-4, 1e-4, 5e-5, 2e-5};
static const double quick_dts[] = {1e-2, 1e-3, 1e-4};
static const double targets[] = {1e-3, 1e-6, 1e-9};

static void plan_full(wp_plan *p)
{
    memset(p, 0, sizeof *p);
    p->t_end = 10.0;
    p->sample = 0.1;
    p->nmethods = 5; /* rk4 to ida */
    p->rtol_loose = 1e-3;
    p->rtol_tight = 1e-12;
    p->atol_per_rtol = 1e-2;
    p->dts = full_dts;
    p->ndt = (int)(sizeof full_dts / sizeof full_dts[0]);
    p->rk4_stop = 1e-9;
    p->ref_method = EOM_ADAMS;
    p->ref_rtol = 1e-14;
    p->check_method = EOM_IDA;
    p->check_rtol = 1e-13;
    p->rounds = 7;
    p->repeat_budget = 1.0;
}

static void plan_quick(wp_plan *p)
{
    plan_full(p);
    p->t_end = 1.0;
    p->rtol_tight = 1e-9;
    p->dts = quick_dts;
    p->ndt = (int)(sizeof quick_dts / sizeof quick_dts[0]);
    p->rounds = 1;
}

/* mkdir -p: make dir and its parents (an existing directory is fine). */
static int make_dir(const char *dir)
{
    char buf[4096];
    size_t i, len = strlen(dir);
    if (len == 0 || len >= sizeof buf)
        return -1;
    memcpy(buf, dir, len + 1);
    for (i = 1; i <= len; i++)
        if (buf[i] == '/' || buf[i] == '\0') {
            const char c = buf[i];
            buf[i] = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return -1;
            buf[i] = c;
        }
    return 0;
}

/* Build demo name with its default settings; the system and its default
 * start go to *s and *x0 (freed by the caller). Returns 0 or -1. */
static int build_demo(const char *name, eom_system **s, double **x0)
{
    const demo *d = demo_find(name);
    double settings[16];
    eom_model *model = NULL;
    char err[1024];
    int k, n;
    *s = NULL;
    *x0 = NULL;
    if (!d || d->nsettings > 16) {
        fprintf(stderr, "bench-wp: unknown demo '%s'\n", name);
        return -1;
    }
    for (k = 0; k < d->nsettings; k++)
        settings[k] = d->settings[k].dflt;
    if (d->build(d, settings, &model, err, sizeof err) != 0 ||
        eom_system_new(s, model, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "bench-wp: %s: %s\n", name, err);
        eom_model_free(&model);
        return -1;
    }
    eom_model_free(&model);
    n = eom_system_ncoords(*s);
    *x0 = malloc(2 * (size_t)n * sizeof(double));
    if (!*x0 || eom_initial_state(*s, *x0) != EOM_OK) {
        fprintf(stderr, "bench-wp: %s: no initial state\n", name);
        eom_system_free(s);
        free(*x0);
        *x0 = NULL;
        return -1;
    }
    return 0;
}

/* How far the start is from the constraints: the demos' defaults lie on
 * them, as they should, since the benchmark compares the methods and not
 * their handling of a start off the constraints. */
static void report_start(const char *name, eom_system *s, const double *x0)
{
    double phi[64], phid[64], r = 0.0, rd = 0.0;
    const int m = eom_system_nconstraints(s);
    int i;
    if (m == 0 || m > 64 || eom_residuals(s, x0, phi, phid) != EOM_OK)
        return;
    for (i = 0; i < m; i++) {
        r = fmax(r, fabs(phi[i]));
        rd = fmax(rd, fabs(phid[i]));
    }
    fprintf(stderr, "  %s start: max |phi| = %.1e, max |C qd| = %.1e\n",
            name, r, rd);
}

/* Open dir/name for writing through the run layer's text writer
 * (created exclusively beside it, renamed onto it whole, a symbolic link
 * at the name replaced, never followed), or say why not. */
static FILE *open_in(const char *dir, const char *name, char *path,
                     size_t len, eom_csv_writer **w)
{
    char err[1024];
    const int n = snprintf(path, len, "%s/%s", dir, name);
    if (n < 0 || (size_t)n >= len) {
        fprintf(stderr, "bench-wp: the path '%s/%s' is too long\n", dir,
                name);
        return NULL;
    }
    if (eom_csv_writer_open_text(w, path, err, sizeof err) != 0) {
        fprintf(stderr, "bench-wp: %s\n", err);
        return NULL;
    }
    return eom_csv_writer_stream(*w);
}

static int close_in(eom_csv_writer **w)
{
    char err[1024];
    if (eom_csv_writer_close(w, err, sizeof err) != 0) {
        fprintf(stderr, "bench-wp: %s\n", err);
        return -1;
    }
    return 0;
}

/* DEMO.md, then the plot's files, then the images: a failing gnuplot
 * loses only the images. Returns 0, 1 when only the images are missing
 * (a warning), -1 when a file could not be written. */
static int write_outputs(const char *dir, const wp_sweep *w, int plots)
{
    char err[1024], name[256], path[4096];
    eom_csv_writer *cw = NULL;
    FILE *f;
    snprintf(name, sizeof name, "%s.md", w->demo);
    if (!(f = open_in(dir, name, path, sizeof path, &cw)))
        return -1;
    wp_table_write(f, w);
    if (close_in(&cw) != 0)
        return -1;
    if (wp_plot_files(dir, w, err, sizeof err) != 0) {
        fprintf(stderr, "bench-wp: %s\n", err);
        return -1;
    }
    if (plots && wp_plot_draw(dir, w, err, sizeof err) != 0) {
        fprintf(stderr, "bench-wp: %s: no plot images: %s (the tables, "
                "the .dat and the .gp files are written)\n", w->demo, err);
        return 1;
    }
    return 0;
}

static int write_summary_file(const char *dir, const wp_sweep *w, int nw)
{
    char path[4096];
    eom_csv_writer *cw = NULL;
    FILE *f = open_in(dir, "summary.md", path, sizeof path, &cw);
    if (!f)
        return -1;
    wp_summary_write(f, w, nw, targets,
                     (int)(sizeof targets / sizeof targets[0]));
    return close_in(&cw);
}

/* The closed chain's target, printed and never asserted: an adaptive
 * method reaches a state error of 1e-6 at t-end at least 20 times
 * faster than rk4 does. */
static void print_target(const wp_sweep *w)
{
    const double target = 1e-6;
    double t_rk4, t, best = INFINITY;
    int k, kbest = -1;
    char ms[32];
    wp_time_at_error(&w->runs[w->first[EOM_RK4]], w->count[EOM_RK4], target,
                     0, &t_rk4);
    printf("## Target: %s, state error %.0e at t = %g s\n\n", w->demo,
           target, w->plan->t_end);
    wp_ms_text(t_rk4, ms, sizeof ms);
    printf("- rk4: %s ms\n", isfinite(t_rk4) ? ms : "not reached");
    for (k = EOM_ERK; k < w->plan->nmethods; k++) {
        const wp_reach how = wp_time_at_error(&w->runs[w->first[k]],
                                              w->count[k], target, 0,
                                              &t);
        wp_ms_text(t, ms, sizeof ms);
        if (how == WP_NOT_REACHED) {
            printf("- %s: not reached\n", eom_method_name((eom_method)k));
            continue;
        }
        printf("- %s: %s%s ms, rk4 / %s = %.1f\n",
               eom_method_name((eom_method)k),
               how == WP_AT_LOOSEST ? "<= " : "", ms,
               eom_method_name((eom_method)k), t_rk4 / t);
        if (t < best) {
            best = t;
            kbest = k;
        }
    }
    if (kbest >= 0 && isfinite(t_rk4))
        printf("\nFastest adaptive: %s, %.1f times faster than rk4 (target "
               ">= 20: %s).\n\n", eom_method_name((eom_method)kbest),
               t_rk4 / best, t_rk4 / best >= 20.0 ? "met" : "missed");
    else
        printf("\nThe ratio cannot be formed: a method did not reach "
               "%.0e.\n\n", target);
}

/* --quick: finite errors for every finished run, and for at least one
 * method an error at its tightest setting below that at its loosest.
 * Returns 0 when sane. */
static int sane(const wp_sweep *w)
{
    int k, j, shrinks = 0, ok = 1;
    for (k = 0; k < WP_NMETHODS; k++) {
        const wp_run *r = &w->runs[w->first[k]];
        const int c = w->count[k];
        for (j = 0; j < c; j++)
            if (r[j].status == EOM_OK &&
                (!isfinite(r[j].err) || !isfinite(r[j].energy_err))) {
                fprintf(stderr, "bench-wp: %s %s: non-finite error\n",
                        w->demo, eom_method_name((eom_method)k));
                ok = 0;
            }
        if (c >= 2 && r[0].status == EOM_OK && r[c - 1].status == EOM_OK &&
            r[c - 1].err < r[0].err)
            shrinks = 1;
    }
    if (!shrinks)
        fprintf(stderr, "bench-wp: %s: no method's error shrinks with its "
                "tolerance or step\n", w->demo);
    if (!(isfinite(w->floor) && w->floor < 1e-6)) {
        fprintf(stderr, "bench-wp: %s: the reference and its check differ "
                "by %g\n", w->demo, w->floor);
        ok = 0;
    }
    return ok && shrinks ? 0 : 1;
}

static int usage(void)
{
    fprintf(stderr, "usage: bench-wp [--quick] [--no-plots] [--demo NAME]"
            "... [OUTDIR]\n");
    return 2;
}

int main(int argc, char **argv)
{
    static const char *const all[MAX_DEMOS] = {
        "spring-pendulum", "open-chain", "closed-chain"};
    const char *names[MAX_DEMOS], *dir = "bench-results";
    wp_sweep sweeps[MAX_DEMOS];
    eom_system *systems[MAX_DEMOS] = {NULL, NULL, NULL};
    double *starts[MAX_DEMOS] = {NULL, NULL, NULL};
    int ndemo = 0, nw = 0, quick = 0, plots = 1, i, rc = 0, plot_fail = 0;
    double t0 = wp_now();
    wp_plan plan;

    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick"))
            quick = 1;
        else if (!strcmp(argv[i], "--no-plots"))
            plots = 0;
        else if (!strcmp(argv[i], "--demo") && i + 1 < argc &&
                 ndemo < MAX_DEMOS)
            names[ndemo++] = argv[++i];
        else if (argv[i][0] == '-')
            return usage();
        else
            dir = argv[i];
    }
    if (quick)
        plan_quick(&plan);
    else
        plan_full(&plan);
    if (ndemo == 0) {
        names[ndemo++] = all[0];
        for (i = 1; !quick && i < MAX_DEMOS; i++)
            names[ndemo++] = all[i];
    }
    if (make_dir(dir) != 0) {
        fprintf(stderr, "bench-wp: cannot make the directory '%s': %s\n",
                dir, strerror(errno));
        return 1;
    }
    printf("# Work against precision\n\n"
           "Wall time: eom_integ_new plus every eom_integ_advance. ");
    if (plan.rounds > 1)
        printf("The minimum over interleaved repetitions: up to %d, until "
               "a run's repetitions add up to about %g s (longer runs are "
               "timed once). ", plan.rounds, plan.repeat_budget);
    else
        printf("Each run is timed once. ");
    printf("CPU time likewise, from the thread's CPU clock. Adaptive "
           "methods: atol = %g rtol. Samples every %g s.\n\n",
           plan.atol_per_rtol, plan.sample);
    fflush(stdout);
    for (i = 0; i < ndemo; i++) {
        wp_sweep *w = &sweeps[nw];
        int out;
        fprintf(stderr, "bench-wp: %s\n", names[i]);
        if (build_demo(names[i], &systems[i], &starts[i]) != 0) {
            rc = 1;
            continue;
        }
        report_start(names[i], systems[i], starts[i]);
        if (wp_sweep_run(w, names[i], systems[i], starts[i], &plan) != 0) {
            wp_sweep_free(w);
            rc = 1;
            continue;
        }
        nw++;
        wp_table_write(stdout, w);
        fflush(stdout);
        out = write_outputs(dir, w, plots);
        if (out < 0)
            rc = 1;
        else if (out > 0)
            plot_fail = 1;
        if (quick && sane(w) != 0)
            rc = 1;
        fprintf(stderr, "  %s: %.1f s\n", names[i], w->seconds);
    }
    wp_summary_write(stdout, sweeps, nw, targets,
                     (int)(sizeof targets / sizeof targets[0]));
    if (write_summary_file(dir, sweeps, nw) != 0)
        rc = 1;
    for (i = 0; i < nw; i++)
        if (!strcmp(sweeps[i].demo, "closed-chain"))
            print_target(&sweeps[i]);
    printf("Total wall time of the benchmark: %.1f s. Results in %s/%s\n",
           wp_now() - t0, dir,
           plot_fail ? " (without some plot images: see above)" : "");
    for (i = 0; i < nw; i++)
        wp_sweep_free(&sweeps[i]);
    for (i = 0; i < MAX_DEMOS; i++) {
        eom_system_free(&systems[i]);
        free(starts[i]);
    }
    return rc;
}
