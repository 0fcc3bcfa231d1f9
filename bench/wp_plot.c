/* wp_plot.c - the work-precision plot files (see wp_plot.h).
 *
 * DEMO-wp.dat holds one block per method that has at least one finished
 * run, in eom_method order, blocks separated by two blank lines (gnuplot's
 * `index`); a block's first line names the method. Failed runs and
 * methods without a finished run appear only as comments, so the block
 * numbers the script uses are those of the methods that can be drawn. */
#include "wp_plot.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "eom/run.h"

static int path_of(char *buf, size_t len, const char *dir, const char *demo,
                   const char *suffix, char *err, size_t errlen)
{
    const int n = snprintf(buf, len, "%s/%s-wp%s", dir, demo, suffix);
    if (n < 0 || (size_t)n >= len) {
        snprintf(err, errlen, "the path '%s/%s-wp%s' is too long", dir,
                 demo, suffix);
        return -1;
    }
    return 0;
}

/* The file at path through the run layer's text writer: created
 * exclusively beside it and renamed onto it whole, a symbolic link at
 * path replaced, never followed. Its stream, or NULL with a message. */
static FILE *open_out(const char *path, eom_csv_writer **w, char *err,
                      size_t errlen)
{
    if (eom_csv_writer_open_text(w, path, err, errlen) != 0)
        return NULL;
    return eom_csv_writer_stream(*w);
}

/* Put the file in place: 0, or -1 with a message. */
static int close_out(eom_csv_writer **w, char *err, size_t errlen)
{
    return eom_csv_writer_close(w, err, errlen) != 0 ? -1 : 0;
}

static int finished(const wp_run *r)
{
    return r->status == EOM_OK && isfinite(r->err);
}

/* How many runs of method k can be drawn. */
static int drawable(const wp_sweep *w, int k)
{
    int j, c = 0;
    for (j = 0; j < w->count[k]; j++)
        c += finished(&w->runs[w->first[k] + j]);
    return c;
}

static void write_dat(FILE *f, const wp_sweep *w)
{
    int k, j, blocks = 0;
    fprintf(f, "# %s: work against precision over t = 0 .. %g s.\n"
            "# columns: state error, wall time (s), angle error, energy "
            "error, steps, rhs,\n# setting (rk4: dt; others: rtol). Errors "
            "of exactly 0 are written as 1e-18.\n", w->demo, w->plan->t_end);
    for (k = 0; k < w->plan->nmethods; k++)
        if (!drawable(w, k))
            fprintf(f, "# %s: no finished run\n",
                    eom_method_name((eom_method)k));
    for (k = 0; k < WP_NMETHODS; k++) {
        if (!drawable(w, k))
            continue;
        if (blocks++)
            fputs("\n\n", f);
        fprintf(f, "# %s\n", eom_method_name((eom_method)k));
        for (j = 0; j < w->count[k]; j++) {
            const wp_run *r = &w->runs[w->first[k] + j];
            const double setting = k == EOM_RK4 ? r->set.dt : r->set.rtol;
            if (!finished(r)) {
                fprintf(f, "# setting %.0e failed: %s\n", setting,
                        eom_status_name(r->status));
                continue;
            }
            fprintf(f, "%.6e %.6e %.6e %.6e %ld %ld %.0e\n",
                    fmax(r->err, 1e-18), r->wall, fmax(r->err_angle, 1e-18),
                    fmax(r->energy_err, 1e-18), r->steps, r->rhs, setting);
        }
    }
}

static void write_gp(FILE *f, const wp_sweep *w)
{
    static const char *const style[WP_NMETHODS] = {
        "lc rgb '#000000' pt 5", "lc rgb '#1f77b4' pt 7",
        "lc rgb '#2ca02c' pt 9", "lc rgb '#d62728' pt 13",
        "lc rgb '#9467bd' pt 11", "lc rgb '#ff7f0e' pt 15",
        "lc rgb '#8c564b' pt 3"};
    int k, block = 0, first = 1;
    fprintf(f, "# %s-wp.gp - %s: wall time against the state error at "
            "t = %g s,\n# one series per integrator, from %s-wp.dat. "
            "Written by bench-wp; to redraw\n# %s-wp.png and %s-wp.svg, "
            "run `gnuplot %s-wp.gp` in this directory.\n", w->demo,
            w->demo, w->plan->t_end, w->demo, w->demo, w->demo, w->demo);
    fprintf(f, "dat = '%s-wp.dat'\nout = '%s-wp'\n", w->demo, w->demo);
    fprintf(f, "floor = %.6e  # reference against its check: errors below "
            "are not measurable\n", fmax(w->floor, 1e-18));
    fputs("do for [fmt in 'png svg'] {\n"
          "reset\n"
          "if (fmt eq 'png') {\n"
          "  set terminal pngcairo noenhanced size 900,600 font 'Sans,10'\n"
          "} else {\n"
          "  set terminal svg noenhanced size 900,600 dynamic font "
          "'Sans,10'\n"
          "}\n"
          "set output out.'.'.fmt\n"
          "set grid lc rgb '#e0e0e0'\n"
          "set logscale xy\n"
          "set format x '%.0e'\n"
          "set format y '%g'\n", f);
    fprintf(f, "set title '%s: work against precision, t = 0 .. %g s'\n",
            w->demo, w->plan->t_end);
    fputs("set xlabel 'state error at t-end: max abs(x - x_ref) over all "
          "coordinates and rates'\n"
          "set ylabel 'wall time (s)'\n"
          "set key outside right top\n"
          "set arrow 1 from floor, graph 0 to floor, graph 1 nohead "
          "dt 2 lc rgb '#888888'\n"
          "set label 1 'reference' at floor, graph 0.97 left offset 0.5,0 "
          "tc rgb '#888888'\n", f);
    for (k = 0; k < WP_NMETHODS; k++) {
        if (!drawable(w, k))
            continue;
        fprintf(f, "%s dat index %d using 1:2 with linespoints %s ps 1 "
                "lw 1.5 title '%s'", first ? "plot" : ", \\\n    ", block,
                style[k], eom_method_name((eom_method)k));
        block++;
        first = 0;
    }
    if (first) /* nothing finished: an empty frame that says so */
        fputs("set label 2 'no run finished' at graph 0.5, graph 0.5 "
              "center\nplot [1e-12:1] [1e-3:1] NaN notitle", f);
    fputs("\nset output\n}\n", f);
}

int wp_plot_files(const char *dir, const wp_sweep *w, char *err,
                  size_t errlen)
{
    char path[4096];
    eom_csv_writer *cw = NULL;
    FILE *f;
    if (path_of(path, sizeof path, dir, w->demo, ".dat", err, errlen) != 0 ||
        !(f = open_out(path, &cw, err, errlen)))
        return -1;
    write_dat(f, w);
    if (close_out(&cw, err, errlen) != 0)
        return -1;
    if (path_of(path, sizeof path, dir, w->demo, ".gp", err, errlen) != 0 ||
        !(f = open_out(path, &cw, err, errlen)))
        return -1;
    write_gp(f, w);
    return close_out(&cw, err, errlen);
}

int wp_plot_draw(const char *dir, const wp_sweep *w, char *err,
                 size_t errlen)
{
    char script[512];
    snprintf(script, sizeof script, "%s-wp.gp", w->demo);
    return eom_gnuplot_run(dir, script, err, errlen);
}
