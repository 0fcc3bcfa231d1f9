/* run_loop.c - integrate and write the rows (see eom/run.h). Every
 * integrator is driven the same way, through eom_integ_advance to each
 * sample time; nothing here depends on the method. */
#include "eom/run.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "csv_writer_internal.h"
#include "progress.h"
#include "run_summary.h"
#include "sens_columns.h"

/* The prefix of every message on standard error, and the model's name. */
#define PROG(p) ((p)->prog ? (p)->prog : "eom_run")
#define LABEL(p) ((p)->label ? (p)->label : "model")

void eom_run_opts_default(eom_run_opts *o)
{
    if (!o)
        return;
    memset(o, 0, sizeof *o);
    o->t_end = 10.0;
    o->sample = 0.01;
    eom_opts_default(&o->opts);
}

void eom_run_grid(double t_end, double sample, long long *K, int *exact)
{
    /* a t_end that is a multiple of sample up to rounding must not get a
     * second row a hair after the last grid point */
    const double tol = fmax(1e-9 * sample, 8.0 * DBL_EPSILON * t_end);
    long long k = (long long)floor(t_end / sample);
    if ((double)(k + 1) * sample - t_end <= tol)
        k++;
    while (k > 0 && (double)k * sample > t_end + tol)
        k--;
    *K = k;
    *exact = fabs(t_end - (double)k * sample) <= tol;
}

typedef struct run_state {
    const eom_run_opts *p;
    eom_system *s;
    eom_integ *it; /* NULL before the integrator starts */
    eom_csv_writer *w;
    eom_run_columns *cols;
    double *row;
    int count;          /* the row: the columns, then the sensitivities */
    char **names;       /* [count] the header (borrowed and owned parts) */
    char **sens_names;  /* the sensitivities' names (owned) */
    int n_sens_names;
    run_summary sum;
    progress prog;
    double last_flush; /* wall clock of the last flush */
    char err[1024];
} run_state;

/* Write the row of (t, x, W). Returns 0, or 1 after a message. */
static int emit(run_state *r, double t, const double *x, double W)
{
    eom_run_row_info info;
    eom_stats st;
    int rc;
    if (r->it && eom_integ_stats(r->it, &st) == EOM_OK) {
        eom_run_columns_set_stats(r->cols, &st);
    } else {
        memset(&st, 0, sizeof st); /* the start row: nothing counted yet */
        eom_run_columns_set_stats(r->cols, &st);
    }
    rc = eom_run_columns_fill(r->cols, r->s, t, x, W, r->row, &info);
    if (r->count > r->cols->count) {
        int rs = sens_columns_fill(r->s, &r->p->opts, r->it,
                                   r->row + r->cols->count);
        if (rs != EOM_OK && rc >= 0) {
            rc = rs;
            snprintf(r->cols->msg, sizeof r->cols->msg,
                     "the sensitivities: %s", eom_status_name(rs));
        }
    }
    /* the state is data even when derived quantities failed: keep it */
    if (eom_csv_writer_row(r->w, r->row, r->count, r->err,
                           sizeof r->err) != 0) {
        progress_clear(&r->prog);
        fprintf(stderr, "%s: %s\n", PROG(r->p), r->err);
        return 1;
    }
    run_summary_add(&r->sum, t, W, &info);
    if (rc < 0) {
        char a[32];
        eom_numtext_format(a, sizeof a, t);
        progress_clear(&r->prog);
        fprintf(stderr, "%s: %s: at t = %s the outputs could not be "
                "evaluated: %s\n", PROG(r->p), LABEL(r->p), a, r->cols->msg);
        return 1;
    }
    if (progress_clock() - r->last_flush >= 1.0) {
        if (eom_csv_writer_flush(r->w, r->err, sizeof r->err) != 0) {
            progress_clear(&r->prog);
            fprintf(stderr, "%s: %s\n", PROG(r->p), r->err);
            return 1;
        }
        r->last_flush = progress_clock();
    }
    progress_update(&r->prog, t);
    return 0;
}

/* Advance to tout and write its row. Returns 0, or 1 after a message. */
static int step_to(run_state *r, eom_integ *it, double tprev, double tout,
                   double *x, double *W)
{
    int rc = eom_integ_advance(it, tout, x, W);
    if (rc < 0) {
        char a[32], b[32];
        eom_numtext_format(a, sizeof a, tprev);
        eom_numtext_format(b, sizeof b, tout);
        progress_clear(&r->prog);
        fprintf(stderr, "%s: %s: integration failed between t = %s "
                "and t = %s: %s\n", PROG(r->p), LABEL(r->p), a, b,
                eom_integ_errmsg(it));
        return 1;
    }
    return emit(r, tout, x, *W);
}

int eom_run(eom_system *s, const double *x0, const eom_run_opts *p,
            eom_csv_writer *w)
{
    const int n = eom_system_ncoords(s);
    const double wall0 = progress_clock();
    run_state r;
    eom_integ *it = NULL;
    eom_stats st;
    double *x = NULL, W = 0.0, tprev = 0.0;
    long long K, k;
    int exact, status = 1, have_stats = 0;
    eom_run_verdict verdict;

    memset(&r, 0, sizeof r);
    r.p = p;
    r.s = s;
    r.w = w;
    run_summary_init(&r.sum);
    progress_start(&r.prog, p->progress && !p->quiet, p->t_end, PROG(p));
    r.last_flush = wall0;
    eom_run_grid(p->t_end, p->sample, &K, &exact);

    if (eom_run_columns_new(&r.cols, s, p->extra, r.err, sizeof r.err) != 0) {
        fprintf(stderr, "%s: %s: %s\n", PROG(p), LABEL(p), r.err);
        return 1;
    }
    r.count = r.cols->count;
    if (p->opts.n_sens > 0 && p->opts.sens) {
        const int ns2 = 2 * n * p->opts.n_sens;
        r.n_sens_names = ns2;
        if (sens_columns_names(s, &p->opts, &r.sens_names) != 0) {
            fprintf(stderr, "%s: out of memory\n", PROG(p));
            goto done;
        }
        r.count += ns2;
    }
    r.row = malloc((size_t)r.count * sizeof(double));
    r.names = malloc((size_t)r.count * sizeof *r.names);
    x = malloc(2 * (size_t)n * sizeof(double) + 1);
    if (!r.row || !r.names || !x) {
        fprintf(stderr, "%s: out of memory\n", PROG(p));
        goto done;
    }
    memcpy(r.names, r.cols->names, (size_t)r.cols->count * sizeof *r.names);
    if (r.count > r.cols->count)
        memcpy(r.names + r.cols->count, r.sens_names,
               (size_t)(r.count - r.cols->count) * sizeof *r.names);
    memcpy(x, x0, 2 * (size_t)n * sizeof(double));
    if (eom_csv_writer_header(w, r.names, r.count, r.err,
                              sizeof r.err) != 0) {
        fprintf(stderr, "%s: %s\n", PROG(p), r.err);
        goto done;
    }
    /* the start's row; with sensitivities after the integrator is made,
     * which gives theirs (with constraints, taken onto the tangent
     * space: not the unit vectors) */
    if (p->opts.n_sens == 0 && emit(&r, 0.0, x, 0.0) != 0)
        goto done;
    if (K > 0 || !exact || p->opts.n_sens > 0) {
        if (eom_integ_new(&it, s, &p->opts, 0.0, x) != EOM_OK) {
            fprintf(stderr, "%s: %s: cannot start the %s integrator: "
                    "%s\n", PROG(p), LABEL(p), eom_method_name(p->opts.method),
                    eom_system_errmsg(s));
            goto done;
        }
        r.it = it;
    }
    if (p->opts.n_sens > 0 && emit(&r, 0.0, x, 0.0) != 0)
        goto done;
    for (k = 1; k <= K + !exact; k++) {
        const double tout = k <= K ? (double)k * p->sample : p->t_end;
        if (p->stop && *p->stop) { /* asked to stop: after a whole row */
            char a[32];
            eom_numtext_format(a, sizeof a, tprev);
            progress_clear(&r.prog);
            fprintf(stderr, "%s: %s: stopped at t = %s (signal %d)\n",
                    PROG(p), LABEL(p), a, (int)*p->stop);
            status = 2;
            goto done;
        }
        if (step_to(&r, it, tprev, tout, x, &W) != 0)
            goto done;
        tprev = tout;
    }
    status = 0;
done:
    if (eom_csv_writer_flush(w, r.err, sizeof r.err) != 0 && status == 0) {
        fprintf(stderr, "%s: %s\n", PROG(p), r.err);
        status = 1;
    }
    if (status != 0)
        csv_writer_mark_failed(w);
    progress_clear(&r.prog);
    memset(&verdict, 0, sizeof verdict);
    if (it)
        have_stats = eom_integ_stats(it, &st) == EOM_OK;
    /* the verdict belongs to a run that reached t_end */
    if (status == 0) {
        eom_run_measures ms;
        run_summary_measures(&r.sum, have_stats ? &st : NULL, &ms);
        eom_run_judge(&p->opts, have_stats ? &st : NULL, &ms, &verdict);
    }
    if (!p->quiet)
        run_summary_print(&r.sum, stderr, PROG(p), LABEL(p),
                          eom_method_name(p->opts.method),
                          have_stats ? &st : NULL,
                          eom_system_reads_time(s) ? "C qd + dphi/dt"
                                                   : "C qd",
                          eom_system_nconstraints(s),
                          progress_clock() - wall0,
                          status == 0 ? &verdict : NULL);
    if (status == 0 && !verdict.healthy) {
        /* said even with quiet: it changes what the run returns */
        fprintf(stderr, "%s: %s: the run is unhealthy: %s%s\n", PROG(p),
                LABEL(p), verdict.text,
                p->accept_unhealthy ? "; accepted as asked" : "");
        if (!p->accept_unhealthy)
            status = 3;
    }
    eom_integ_free(&it);
    sens_columns_free(r.sens_names, r.n_sens_names);
    eom_run_columns_free(&r.cols);
    free(r.names);
    free(r.row);
    free(x);
    return status;
}
