/* run_loop.c - integrate and write the rows (see run_loop.h). Every
 * integrator is driven the same way, through eom_integ_advance to each
 * sample time; nothing here depends on the method. */
#include "run_loop.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "columns.h"
#include "numtext.h"
#include "progress.h"
#include "run_summary.h"

void run_grid(double t_end, double sample, long long *K, int *exact)
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
    const run_plan *p;
    eom_system *s;
    csv_writer *w;
    columns *cols;
    double *row;
    run_summary sum;
    progress prog;
    double last_flush; /* wall clock of the last flush */
    char err[1024];
} run_state;

/* Write the row of (t, x, W). Returns 0, or 1 after a message. */
static int emit(run_state *r, double t, const double *x, double W)
{
    row_info info;
    int rc = columns_fill(r->cols, r->s, t, x, W, r->row, &info);
    /* the state is data even when derived quantities failed: keep it */
    if (csv_writer_row(r->w, r->row, r->cols->count, r->err,
                       sizeof r->err) != 0) {
        progress_clear(&r->prog);
        fprintf(stderr, "eom-run: %s\n", r->err);
        return 1;
    }
    run_summary_add(&r->sum, t, W, &info);
    if (rc < 0) {
        char a[32];
        numtext_format(a, sizeof a, t);
        progress_clear(&r->prog);
        fprintf(stderr, "eom-run: %s: at t = %s the outputs could not be "
                "evaluated: %s\n", r->p->label, a, r->cols->msg);
        return 1;
    }
    if (progress_clock() - r->last_flush >= 1.0) {
        if (csv_writer_flush(r->w, r->err, sizeof r->err) != 0) {
            progress_clear(&r->prog);
            fprintf(stderr, "eom-run: %s\n", r->err);
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
        numtext_format(a, sizeof a, tprev);
        numtext_format(b, sizeof b, tout);
        progress_clear(&r->prog);
        fprintf(stderr, "eom-run: %s: integration failed between t = %s "
                "and t = %s: %s\n", r->p->label, a, b, eom_integ_errmsg(it));
        return 1;
    }
    return emit(r, tout, x, *W);
}

int run_loop(eom_system *s, const double *x0, const run_plan *p,
             csv_writer *w)
{
    const int n = eom_system_ncoords(s);
    const double wall0 = progress_clock();
    run_state r;
    eom_integ *it = NULL;
    eom_stats st;
    double *x = NULL, W = 0.0, tprev = 0.0;
    long long K, k;
    int exact, status = 1, have_stats = 0;

    memset(&r, 0, sizeof r);
    r.p = p;
    r.s = s;
    r.w = w;
    run_summary_init(&r.sum);
    progress_start(&r.prog, p->progress && !p->quiet, p->t_end);
    r.last_flush = wall0;
    run_grid(p->t_end, p->sample, &K, &exact);

    if (columns_new(&r.cols, s, r.err, sizeof r.err) != 0) {
        fprintf(stderr, "eom-run: %s: %s\n", p->label, r.err);
        return 1;
    }
    r.row = malloc((size_t)r.cols->count * sizeof(double));
    x = malloc(2 * (size_t)n * sizeof(double) + 1);
    if (!r.row || !x) {
        fprintf(stderr, "eom-run: out of memory\n");
        goto done;
    }
    memcpy(x, x0, 2 * (size_t)n * sizeof(double));
    if (csv_writer_header(w, r.cols->names, r.cols->count, r.err,
                          sizeof r.err) != 0) {
        fprintf(stderr, "eom-run: %s\n", r.err);
        goto done;
    }
    if (emit(&r, 0.0, x, 0.0) != 0)
        goto done;
    if (K > 0 || !exact) {
        if (eom_integ_new(&it, s, &p->opts, 0.0, x) != EOM_OK) {
            fprintf(stderr, "eom-run: %s: cannot start the %s integrator: "
                    "%s\n", p->label, eom_method_name(p->opts.method),
                    eom_system_errmsg(s));
            goto done;
        }
    }
    for (k = 1; k <= K; k++) {
        const double tout = (double)k * p->sample;
        if (step_to(&r, it, tprev, tout, x, &W) != 0)
            goto done;
        tprev = tout;
    }
    if (!exact && step_to(&r, it, tprev, p->t_end, x, &W) != 0)
        goto done;
    status = 0;
done:
    if (csv_writer_flush(w, r.err, sizeof r.err) != 0 && status == 0) {
        fprintf(stderr, "eom-run: %s\n", r.err);
        status = 1;
    }
    progress_clear(&r.prog);
    if (it)
        have_stats = eom_integ_stats(it, &st) == EOM_OK;
    if (!p->quiet)
        run_summary_print(&r.sum, stderr, p->label,
                          eom_method_name(p->opts.method),
                          have_stats ? &st : NULL,
                          eom_system_nconstraints(s),
                          progress_clock() - wall0);
    eom_integ_free(&it);
    columns_free(&r.cols);
    free(r.row);
    free(x);
    return status;
}
