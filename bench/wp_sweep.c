/* wp_sweep.c - the work-precision sweep of one demo (see wp_sweep.h).
 *
 * The state error of a run is the largest absolute difference from the
 * reference over all 2n components at t_end. Angles (rad), deflections
 * (m) and their rates are mixed in it, as a user comparing two CSV rows
 * would mix them; the error of the angles alone is kept beside it. */
#include "wp_sweep.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void errors_of(const wp_sweep *w, const double *ref, wp_run *r)
{
    int i;
    r->err = r->err_angle = NAN;
    if (r->status != EOM_OK)
        return;
    r->err = r->err_angle = 0.0;
    for (i = 0; i < 2 * w->n; i++)
        r->err = fmax(r->err, fabs(r->x[i] - ref[i]));
    for (i = 0; i < w->n; i++)
        if (strcmp(eom_coord_unit(w->s, i), "rad") == 0)
            r->err_angle = fmax(r->err_angle, fabs(r->x[i] - ref[i]));
}

static void progress(const wp_sweep *w, const wp_run *r)
{
    char set[32];
    wp_setting_text(&r->set, set, sizeof set);
    if (r->status == EOM_OK)
        fprintf(stderr, "  %s %-5s %-12s %9.4f s  error %.2e\n", w->demo,
                eom_method_name(r->set.method), set, r->wall, r->err);
    else
        fprintf(stderr, "  %s %-5s %-12s failed: %s\n", w->demo,
                eom_method_name(r->set.method), set, r->msg);
}

static int alloc_run(wp_run *r, int n)
{
    memset(r, 0, sizeof *r);
    r->x = malloc(2 * (size_t)n * sizeof(double));
    return r->x ? 0 : -1;
}

/* The reference and its check: the same tolerance, two methods. */
static int reference(wp_sweep *w)
{
    const wp_plan *p = w->plan;
    wp_run *two[2];
    int k;
    two[0] = &w->ref;
    two[1] = &w->check;
    for (k = 0; k < 2; k++) {
        wp_run *r = two[k];
        r->set.method = k == 0 ? p->ref_method : p->check_method;
        r->set.rtol = k == 0 ? p->ref_rtol : p->check_rtol;
        r->set.atol = r->set.rtol * p->atol_per_rtol;
        if (wp_run_first(w->s, w->x0, p->t_end, p->sample, r) != EOM_OK) {
            fprintf(stderr, "bench-wp: %s: the reference (%s at rtol %g) "
                    "failed: %s\n", w->demo, eom_method_name(r->set.method),
                    r->set.rtol, r->msg);
            return -1;
        }
    }
    errors_of(w, w->ref.x, &w->check);
    w->ref.err = w->ref.err_angle = 0.0;
    w->floor = w->check.err;
    w->floor_angle = w->check.err_angle;
    fprintf(stderr, "  %s reference %s at rtol %.0e, check %s at rtol %.0e: "
            "they differ by %.2e (angles %.2e), %.1f s\n", w->demo,
            eom_method_name(w->ref.set.method), p->ref_rtol,
            eom_method_name(w->check.set.method), p->check_rtol, w->floor,
            w->floor_angle, w->ref.wall + w->check.wall);
    return 0;
}

/* The settings of the sweep, grouped by method, into w->runs. */
static int settings(wp_sweep *w)
{
    const wp_plan *p = w->plan;
    const int ndec =
        (int)floor(log10(p->rtol_loose / p->rtol_tight) + 0.5) + 1;
    const int nruns = p->ndt + (p->nmethods - 1) * ndec;
    int k, j, i = 0;
    w->runs = calloc((size_t)nruns, sizeof(wp_run));
    if (!w->runs)
        return -1;
    w->nruns = nruns; /* zeroed: wp_sweep_free may free all */
    for (k = 0; k < WP_NMETHODS; k++) {
        const int cnt = k >= p->nmethods ? 0 : k == EOM_RK4 ? p->ndt : ndec;
        w->first[k] = i;
        w->count[k] = cnt;
        for (j = 0; j < cnt; j++, i++) {
            wp_run *r = &w->runs[i];
            if (alloc_run(r, w->n) != 0)
                return -1;
            r->set.method = (eom_method)k;
            if (k == EOM_RK4) {
                r->set.dt = p->dts[j];
            } else {
                r->set.rtol = p->rtol_loose * pow(10.0, -j);
                r->set.atol = r->set.rtol * p->atol_per_rtol;
            }
        }
    }
    return 0;
}

int wp_sweep_run(wp_sweep *w, const char *demo, eom_system *s,
                 const double *x0, const wp_plan *p)
{
    const double start = wp_now();
    double *tmp;
    int k, j, round;
    memset(w, 0, sizeof *w);
    w->demo = demo;
    w->s = s;
    w->n = eom_system_ncoords(s);
    w->m = eom_system_nconstraints(s);
    w->x0 = x0;
    w->plan = p;
    tmp = malloc(2 * (size_t)w->n * sizeof(double));
    if (!tmp || alloc_run(&w->ref, w->n) || alloc_run(&w->check, w->n) ||
        settings(w) != 0) {
        free(tmp);
        fprintf(stderr, "bench-wp: out of memory\n");
        return -1;
    }
    if (reference(w) != 0) {
        free(tmp);
        return -1;
    }
    /* round 1, in sweep order. rk4 stops once its error is below rk4_stop
     * (the smallest target error): its smaller steps would cost the most
     * of the whole benchmark and tell nothing the summary uses */
    for (k = 0; k < WP_NMETHODS; k++)
        for (j = 0; j < w->count[k]; j++) {
            wp_run *r = &w->runs[w->first[k] + j];
            wp_run_first(s, x0, p->t_end, p->sample, r);
            errors_of(w, w->ref.x, r);
            progress(w, r);
            if (k == EOM_RK4 && r->status == EOM_OK && r->err < p->rk4_stop) {
                w->rk4_stopped = w->count[k] - j - 1;
                w->count[k] = j + 1;
                break;
            }
        }
    /* further rounds for the short runs, methods in rotating order */
    for (round = 1; round < p->rounds; round++)
        for (k = 0; k < WP_NMETHODS; k++) {
            const int meth = (k + round) % WP_NMETHODS;
            for (j = 0; j < w->count[meth]; j++) {
                wp_run *r = &w->runs[w->first[meth] + j];
                if (r->reps == round &&
                    r->wall * r->reps < p->repeat_budget)
                    wp_run_again(s, x0, p->t_end, p->sample, r, tmp);
            }
        }
    free(tmp);
    w->seconds = wp_now() - start;
    return 0;
}

void wp_sweep_free(wp_sweep *w)
{
    int i;
    if (w->runs)
        for (i = 0; i < w->nruns; i++)
            free(w->runs[i].x);
    free(w->runs);
    free(w->ref.x);
    free(w->check.x);
    memset(w, 0, sizeof *w);
}
