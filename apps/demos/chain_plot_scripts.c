/* chain_plot_scripts.c - writing the gnuplot scripts and the snapshot data
 * of the chain plots (see chain_plot_scripts.h). Every script has the same
 * frame: a comment saying what it draws and how to rerun it, the names of
 * its input and outputs as variables, then one loop over the two
 * terminals (pngcairo, svg) around the plot itself. */
#include "chain_plot_scripts.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Write s as a gnuplot single-quoted string (a quote is doubled). */
static void gp_str(FILE *f, const char *s)
{
    fputc('\'', f);
    for (; *s; s++) {
        if (*s == '\'')
            fputc('\'', f);
        if (*s != '\n')
            fputc(*s, f);
    }
    fputc('\'', f);
}

/* The rows shown as snapshots: up to CHAIN_PLOT_SNAPSHOTS, evenly spaced
 * from the first to the last. Returns their number. */
static int snapshot_rows(int nrows, int *rows)
{
    int k, n = 0;
    const int want = nrows < CHAIN_PLOT_SNAPSHOTS ? nrows
                                                  : CHAIN_PLOT_SNAPSHOTS;
    for (k = 0; k < want; k++) {
        int r = want > 1 ? (int)((double)k * (nrows - 1) / (want - 1) + 0.5)
                         : 0;
        if (n == 0 || r != rows[n - 1])
            rows[n++] = r;
    }
    return n;
}

/* A script or data file through a text writer (eom_csv_writer_open_text:
 * created exclusively beside path and renamed onto it whole; a symbolic
 * link at path is replaced, never followed): its stream, or NULL with a
 * message. */
static FILE *open_out(const char *path, eom_csv_writer **w, char *err,
                      size_t errlen)
{
    if (eom_csv_writer_open_text(w, path, err, errlen) != 0)
        return NULL;
    return eom_csv_writer_stream(*w);
}

/* Put the file in place: 0, or -1 with a message (a write that failed
 * leaves path as it was). */
static int close_out(eom_csv_writer **w, char *err, size_t errlen)
{
    return eom_csv_writer_close(w, err, errlen) != 0 ? -1 : 0;
}

int chain_snapshots_dat(const char *path, const plot_job *j, char *err,
                        size_t errlen)
{
    const chain_shape *c = j->c;
    const int tcol = eom_csv_table_col(j->t, "t");
    int rows[CHAIN_PLOT_SNAPSHOTS], nsnap, k, l, p, maxnp = 2;
    double *pts, root[2];
    eom_csv_writer *w = NULL;
    FILE *f;
    for (l = 0; l < c->links; l++)
        if (chain_shape_npoints(c, l) > maxnp)
            maxnp = chain_shape_npoints(c, l);
    pts = malloc(4 * (size_t)maxnp * sizeof(double));
    if (!pts) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    if (!(f = open_out(path, &w, err, errlen))) {
        free(pts);
        return -1;
    }
    nsnap = snapshot_rows(j->t->nrows, rows);
    fprintf(f, "# The deformed chain of %s at %d times, for "
            "%s-snapshots.gp.\n# Block 2k: chord x, y (m) and deflection "
            "dx, dy (m) of points along the links;\n# block 2k+1: the "
            "joints x, y (m). The drawn point is (x + s dx, y + s dy).\n",
            j->csv_name, nsnap, j->prefix);
    for (k = 0; k < nsnap; k++) {
        const int i = rows[k];
        fprintf(f, "%s# t = %.9g s\n", k ? "\n\n" : "",
                tcol >= 0 ? eom_csv_table_at(j->t, i, tcol) : 0.0);
        root[0] = root[1] = 0.0;
        for (l = 0; l < c->links; l++) {
            const int np = chain_shape_npoints(c, l);
            chain_shape_link(c, j->t, i, l, root, pts);
            /* a link's first point is the previous link's last */
            for (p = l ? 1 : 0; p < np; p++)
                fprintf(f, "%.9g %.9g %.9g %.9g\n", pts[4 * p],
                        pts[4 * p + 1], pts[4 * p + 2], pts[4 * p + 3]);
        }
        fprintf(f, "\n\n# joints at t = %.9g s\n0 0\n",
                tcol >= 0 ? eom_csv_table_at(j->t, i, tcol) : 0.0);
        root[0] = root[1] = 0.0;
        for (l = 0; l < c->links; l++) {
            chain_shape_link(c, j->t, i, l, root, NULL);
            fprintf(f, "%.9g %.9g\n", root[0], root[1]);
        }
    }
    free(pts);
    return close_out(&w, err, errlen);
}

/* The frame of every script up to the plot: what it is, its input and
 * outputs, the terminal loop. w, h: the image size in pixels. */
static void head(FILE *f, const plot_job *j, const char *which,
                 const char *what, int w, int h)
{
    fprintf(f, "# %s-%s.gp - %s.\n", j->prefix, which, what);
    fprintf(f, "# Written by eom-run --plots from the CSV below. To change "
            "the plot, edit this\n# file and run `gnuplot %s-%s.gp` in its "
            "directory: it rewrites\n# %s-%s.png and %s-%s.svg.\n",
            j->prefix, which, j->prefix, which, j->prefix, which);
    fputs("csv = ", f);
    gp_str(f, j->csv_name);
    fputs("\nout = ", f);
    gp_str(f, j->prefix);
    fprintf(f, ".'-%s'\n", which);
    fputs("do for [fmt in 'png svg'] {\n"
          "reset\n"
          "if (fmt eq 'png') {\n", f);
    fprintf(f, "  set terminal pngcairo noenhanced size %d,%d font "
            "'Sans,10'\n} else {\n  set terminal svg noenhanced size %d,%d "
            "dynamic font 'Sans,10'\n}\n", w, h, w, h);
    fputs("set output out.'.'.fmt\n"
          "set datafile separator ','\n"
          "set grid lc rgb '#e0e0e0'\n", f);
}

static void tail(FILE *f)
{
    fputs("set output\n}\n", f);
}

/* Kinetic energy per link: one panel per link (at most
 * CHAIN_PLOT_MAX_PANELS), rigid part solid on the left axis, flexible
 * part dashed on the right axis (it is often a hundred times smaller).
 * The flexible part is the link's T less the rigid part, so it holds the
 * terms that couple the deflection with the chord's motion, which take
 * either sign: it can be negative (-3.6 J on the closed chain, whose
 * links' T stay positive), and the title says so. */
static void energy(FILE *f, const plot_job *j)
{
    const int links = j->c->links;
    const int np = links < CHAIN_PLOT_MAX_PANELS ? links
                                                 : CHAIN_PLOT_MAX_PANELS;
    const int cols = np > 3 ? 2 : 1, rows = (np + cols - 1) / cols;
    int l, flexible = 0;
    for (l = 0; l < links; l++)
        flexible |= j->c->modes[l] > 0;
    head(f, j, "energy", "kinetic energy per link, rigid and flexible "
         "parts", cols == 2 ? 1100 : 800,
         280 * rows + (flexible ? 90 : 70));
    fputs("set multiplot layout ", f);
    fprintf(f, "%d,%d title csv.': kinetic energy per link'.\"\\n\".'%s",
            rows, cols, flexible ? "solid: rigid part (the chord as a rigid "
            "rod), left axis; dashed: flexible part, right axis'.\"\\n\"."
            "'(the flexible part is T less the rigid part: it holds the "
            "coupling of deflection and chord motion, so it can be "
            "negative)"
                               : "rigid links: all of it is the rigid part");
    if (np < links)
        fprintf(f, "'.\"\\n\".'links 1 to %d of %d shown: the CSV has "
                "TJ_rigid and TJ_flex of every link", np, links);
    fputs("'\n", f);
    fputs("unset key\n"
          "set xlabel 't (s)'\n"
          "set ylabel 'rigid (J)'\n"
          "set ytics nomirror\n", f);
    for (l = 1; l <= np; l++) {
        char flex[64];
        snprintf(flex, sizeof flex, "T%d_flex", l);
        const int has_flex = eom_csv_table_col(j->t, flex) >= 0;
        fprintf(f, "set title 'link %d%s'\n", l,
                j->c->modes[l - 1] ? "" : " (rigid)");
        fputs(has_flex ? "set y2tics; set y2label 'flexible (J)'\n"
                       : "unset y2tics; unset y2label\n", f);
        fprintf(f, "plot csv using 't':'T%d_rigid' with lines lw 1.5 "
                "lc rgb '#1f77b4'", l);
        if (has_flex) {
            fputs(", \\\n     csv using 't':", f);
            gp_str(f, flex);
            fputs(" axes x1y2 with lines dt 2 lw 1 lc rgb '#d62728'", f);
        }
        fputs("\n", f);
    }
    fputs("unset multiplot\n", f);
}

static void snapshots(FILE *f, const plot_job *j)
{
    static const char *const colors = "#1f77b4 #d62728 #2ca02c #9467bd "
                                      "#ff7f0e #8c564b #e377c2 #17becf";
    const int tcol = eom_csv_table_col(j->t, "t");
    int rows[CHAIN_PLOT_SNAPSHOTS], n = snapshot_rows(j->t->nrows, rows), k;
    head(f, j, "snapshots", "the deformed chain at several times", 1000,
         760);
    fprintf(f, "# deflections are drawn this many times larger (1: true "
            "scale)\nexaggeration = %.6g\n", j->exaggeration);
    fputs("dat = ", f);
    gp_str(f, j->prefix);
    fputs(".'-snapshots.dat'\n", f);
    fprintf(f, "colors = '%s'\ntimes = '", colors);
    for (k = 0; k < n; k++)
        fprintf(f, "%s%.6g", k ? " " : "",
                tcol >= 0 ? eom_csv_table_at(j->t, rows[k], tcol) : 0.0);
    fputs("'\n", f);
    fprintf(f, "set title csv.sprintf(': the chain at %d times, deflection "
            "magnified %%g times', exaggeration)%s\n", n,
            j->gravity ? ".'; gravity along -y'" : "");
    fputs("set datafile separator whitespace\n"
          "set size ratio -1\n"
          "set xlabel 'x (m)'\n"
          "set ylabel 'y (m)'\n"
          "set key outside right top title 'time'\n"
          "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n"
          "set label 1 '' at 0,0 point pt 9 ps 2.5 lc rgb 'black' front\n",
          f);
    if (j->c->closed)
        fprintf(f, "set label 2 '' at %.9g,0 point pt 9 ps 2.5 lc rgb "
                "'black' front\n", j->c->D);
    fprintf(f, "plot for [k=1:%d] dat index (2*k-2) using "
            "($1+exaggeration*$3):($2+exaggeration*$4) \\\n"
            "       with lines lw 2 lc rgb word(colors, k) title "
            "sprintf('t = %%s s', word(times, k)), \\\n"
            "     for [k=1:%d] dat index (2*k-1) using 1:2 with points pt 7 "
            "ps 0.8 \\\n"
            "       lc rgb word(colors, k) notitle\n", n, n);
}

static void total_energy(FILE *f, const plot_job *j)
{
    const int cE = eom_csv_table_col(j->t, "E");
    const double E0 = cE >= 0 ? eom_csv_table_at(j->t, 0, cE) : 0.0;
    head(f, j, "total-energy", "total energy E, dissipated work W and "
         "E + W", 1000, 760);
    fprintf(f, "# E at t = 0\nE0 = %.17g\n", E0);
    fputs("set multiplot layout 2,1 title csv.': energy'\n"
          "set xlabel 't (s)'\n"
          "set ylabel 'J'\n"
          "set key outside right top\n"
          "# the same margins in both panels, so that their t axes line up\n"
          "set lmargin at screen 0.1\n"
          "set rmargin at screen 0.8\n"
          "set title 'E (the Jacobi integral; T + V here), W (work "
          "dissipated since t = 0) and E + W'\n"
          "plot csv using 't':'E' with lines lw 1.5 lc rgb '#1f77b4' "
          "title 'E', \\\n"
          "     csv using 't':'W' with lines lw 1.5 lc rgb '#2ca02c' "
          "title 'W', \\\n"
          "     csv using 't':(column('E')+column('W')) with lines lw 2 "
          "dt 2 lc rgb '#d62728' title 'E + W'\n"
          "set title 'E + W - E(0): zero in exact arithmetic, so this is "
          "the integration error'\n"
          "plot csv using 't':(column('E')+column('W')-E0) with lines "
          "lw 1.5 lc rgb '#d62728' title 'E + W - E(0)'\n"
          "unset multiplot\n", f);
}

static void residuals(FILE *f, const plot_job *j)
{
    char name[32];
    int m = 0;
    for (;;) {
        snprintf(name, sizeof name, "phi%d", m + 1);
        if (eom_csv_table_col(j->t, name) < 0)
            break;
        m++;
    }
    /* a point per pixel column or so is enough for a scatter of
     * round-off, and keeps the SVG of a long run small */
    const int every = j->t->nrows > 4000 ? (j->t->nrows + 3999) / 4000 : 1;
    head(f, j, "residuals", "constraint residuals |phi| and |C qd|", 1000,
         600);
    fputs("# residuals below floor (exact zeros too) are drawn at floor\n"
          "floor = 1e-18\n"
          "mag(x) = abs(x) > floor ? abs(x) : floor\n"
          "set title csv.': constraint residuals (values below 1e-18 are "
          "drawn at 1e-18)'\n"
          "set logscale y\n"
          "set format y '%.0e'\n"
          "set xlabel 't (s)'\n"
          "set ylabel 'residual'\n"
          "set key outside right top\n", f);
    /* points, not lines: residuals at round-off jump by decades from
     * row to row, and lines would fill the plot */
    fprintf(f, "# every: draw every this many rows (the CSV has %d)\n"
            "every = %d\n", j->t->nrows, every);
    if (every > 1)
        fputs("set label 1 sprintf('every %d-th row', every) at graph 0.01, "
              "graph 0.97\n", f);
    fprintf(f, "plot for [k=1:%d] csv every every using 't':"
            "(mag(column(sprintf('phi%%d', k)))) \\\n"
            "       with points pt 7 ps 0.4 title sprintf('|phi%%d| (m)', "
            "k), \\\n"
            "     for [k=1:%d] csv every every using 't':"
            "(mag(column(sprintf('phidot%%d', k)))) \\\n"
            "       with points pt 6 ps 0.4 title sprintf('|phidot%%d| "
            "(m/s)', k)\n", m, m);
}

int chain_plot_script(const char *path, const char *which,
                      const plot_job *j, char *err, size_t errlen)
{
    eom_csv_writer *w = NULL;
    FILE *f = open_out(path, &w, err, errlen);
    if (!f)
        return -1;
    if (strcmp(which, "energy") == 0)
        energy(f, j);
    else if (strcmp(which, "snapshots") == 0)
        snapshots(f, j);
    else if (strcmp(which, "total-energy") == 0)
        total_energy(f, j);
    else
        residuals(f, j);
    tail(f);
    return close_out(&w, err, errlen);
}
