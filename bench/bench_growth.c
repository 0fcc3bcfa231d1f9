/* bench_growth.c - how the cost of a chain grows with its number of links
 * and of modes per link: the size of the Lagrangian's tape (ops, bytes),
 * the time to record every tape of the system (eom_system_new), and the
 * time of one right-hand side (eom_rhs), for open chains with gravity.
 * With an output directory it also writes the table and a plot (gnuplot:
 * PNG and SVG, with the .dat and .gp beside them).
 *
 * The kinetic energy is accumulated joint by joint, so the tape grows
 * linearly with the links; one right-hand side carries n directions
 * through it and then factors M, so its time grows like n^2 (sweeps) plus
 * n^3 / 3 (Cholesky), the latter dominating only for large n.
 *
 * usage: bench-growth [--quick] [OUTDIR] */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bench_util.h"
#include "eom/chain.h"
#include "eom_internal.h"
#include "eom/run.h"

static const double pi = 3.14159265358979323846;

typedef struct point {
    int links, modes, n;
    size_t ops, bytes;
    double t_record, t_rhs; /* seconds */
} point;

typedef struct rhs_ctx {
    eom_system *s;
    double *x, *xd;
} rhs_ctx;

static void one_rhs(void *p)
{
    rhs_ctx *c = p;
    c->x[0] += 1e-12;
    eom_rhs(c->s, 0.0, c->x, c->xd);
}

static int measure(int links, int modes, double min_batch, int reps,
                   point *pt)
{
    eom_chain_spec sp;
    eom_model *m = NULL;
    tp_tape_stats st;
    rhs_ctx c = {NULL, NULL, NULL};
    double *t = malloc((size_t)reps * sizeof(double)), t0;
    long batch;
    int i, r;
    memset(&sp, 0, sizeof sp);
    sp.links = links;
    sp.modes_all = modes;
    sp.m = 1.0;
    sp.L = 10.0;
    sp.EI = 4e4;
    sp.g = 9.81;
    if (!t || eom_model_new(&m) != EOM_OK || eom_chain_add(m, &sp) < 0)
        return -1;
    /* recording: every tape of the system, its workspaces and solvers */
    for (r = 0; r < reps; r++) {
        t0 = bench_now();
        if (eom_system_new(&c.s, m, NULL, 0) != EOM_OK)
            return -1;
        t[r] = bench_now() - t0;
        if (r + 1 < reps)
            eom_system_free(&c.s);
    }
    pt->t_record = bench_median(t, reps);
    tp_tape_stats_get(c.s->tL.tape, &st);
    pt->links = links;
    pt->modes = modes;
    pt->n = eom_system_ncoords(c.s);
    pt->ops = st.n_ops;
    pt->bytes = st.bytes;
    c.x = calloc(4 * (size_t)pt->n, sizeof(double));
    if (!c.x)
        return -1;
    c.xd = c.x + 2 * pt->n;
    for (i = 0; i < links; i++) {
        c.x[i] = -pi / 2 + (i % 2 ? -0.3 : 0.3);
        c.x[pt->n + i] = 0.1 * sin(i);
    }
    batch = bench_calibrate(one_rhs, &c, min_batch);
    for (r = 0; r < reps; r++)
        t[r] = bench_time(one_rhs, &c, batch);
    pt->t_rhs = bench_median(t, reps);
    eom_system_free(&c.s);
    eom_model_free(&m);
    free(c.x);
    free(t);
    return 0;
}

static int write_plot(const char *dir, const point *p, int np)
{
    char path[512], err[1024];
    eom_csv_writer *w = NULL;
    FILE *f;
    int k, i, kmax = 0;
    for (i = 0; i < np; i++)
        kmax = p[i].modes > kmax ? p[i].modes : kmax;
    /* both files through the run layer's text writer: created beside
     * their names and renamed onto them whole, a symbolic link at a name
     * replaced, never followed */
    snprintf(path, sizeof path, "%s/growth.dat", dir);
    if (eom_csv_writer_open_text(&w, path, err, sizeof err) != 0) {
        fprintf(stderr, "bench-growth: %s\n", err);
        return -1;
    }
    f = eom_csv_writer_stream(w);
    for (k = 0; k <= kmax; k++) {
        fprintf(f, "# modes %d: links n ops record_s rhs_s\n", k);
        for (i = 0; i < np; i++)
            if (p[i].modes == k)
                fprintf(f, "%d %d %zu %.6g %.6g\n", p[i].links, p[i].n,
                        p[i].ops, p[i].t_record, p[i].t_rhs);
        fprintf(f, "\n\n");
    }
    if (eom_csv_writer_close(&w, err, sizeof err) != 0) {
        fprintf(stderr, "bench-growth: %s\n", err);
        return -1;
    }
    snprintf(path, sizeof path, "%s/growth.gp", dir);
    if (eom_csv_writer_open_text(&w, path, err, sizeof err) != 0) {
        fprintf(stderr, "bench-growth: %s\n", err);
        return -1;
    }
    f = eom_csv_writer_stream(w);
    fprintf(f,
            "# growth of a chain's cost with links and modes "
            "(bench-growth)\n"
            "do for [term in 'pngcairo svg'] {\n"
            "  if (term eq 'svg') { set terminal svg size 1100,420; "
            "set output 'growth.svg' } "
            "else { set terminal pngcairo size 1100,420; "
            "set output 'growth.png' }\n"
            "  set multiplot layout 1,2\n"
            "  set logscale xy; set grid; set key left top\n"
            "  set xlabel 'links'; set ylabel 'ops on the tape of L'\n"
            "  set title 'tape size: linear in the links'\n"
            "  plot for [k=0:%d] 'growth.dat' index k using 1:3 with "
            "linespoints title sprintf('%%d modes', k)\n"
            "  set xlabel 'coordinates n'; set ylabel 'seconds'\n"
            "  set title 'one right-hand side (eom\\_rhs)'\n"
            "  plot for [k=0:%d] 'growth.dat' index k using 2:5 with "
            "linespoints title sprintf('%%d modes', k), "
            "1e-8*x**2 dashtype 2 title 'n^2'\n"
            "  unset multiplot\n"
            "}\n", kmax, kmax);
    if (eom_csv_writer_close(&w, err, sizeof err) != 0) {
        fprintf(stderr, "bench-growth: %s\n", err);
        return -1;
    }
    if (eom_gnuplot_run(dir, "growth.gp", err, sizeof err) != 0) {
        fprintf(stderr, "bench-growth: %s\n", err);
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    static const int links_full[] = {5, 10, 20, 50, 100};
    static const int links_quick[] = {2, 4};
    const char *dir = NULL;
    int quick = 0, reps = 7, i, k, np = 0;
    double min_batch = 0.02;
    point pts[32];
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) {
            quick = 1;
            reps = 3;
            min_batch = 1e-3;
        } else if (argv[i][0] != '-' && !dir) {
            dir = argv[i];
        } else {
            fprintf(stderr, "usage: bench-growth [--quick] [OUTDIR]\n");
            return 2;
        }
    }
    printf("Growth of an open chain with gravity: the tape of L, recording "
           "every tape (eom_system_new) and one right-hand side (eom_rhs); "
           "medians of %d\n\n| links | modes | n | ops of L | bytes of L | "
           "record (ms) | rhs (us) | rhs / n^2 (ns) |\n"
           "|---|---|---|---|---|---|---|---|\n", reps);
    for (k = 0; k <= 3; k++) {
        const int *lv = quick ? links_quick : links_full;
        const int nl = quick ? 2 : 5;
        for (i = 0; i < nl; i++) {
            point *p = &pts[np];
            if (quick && k > 1)
                break;
            if (measure(lv[i], k, min_batch, reps, p) != 0) {
                fprintf(stderr, "bench-growth: %d links, %d modes failed\n",
                        lv[i], k);
                return 1;
            }
            printf("| %d | %d | %d | %zu | %zu | %.2f | %.1f | %.2f |\n",
                   p->links, p->modes, p->n, p->ops, p->bytes,
                   1e3 * p->t_record, 1e6 * p->t_rhs,
                   1e9 * p->t_rhs / ((double)p->n * p->n));
            fflush(stdout);
            np++;
        }
    }
    if (dir) {
        mkdir(dir, 0777);
        if (write_plot(dir, pts, np) != 0)
            return 1;
    }
    return 0;
}
