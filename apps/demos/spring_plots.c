/* spring_plots.c - the plots of the spring pendulum (--plots), beside the
 * run's CSV under its name without ".csv" (PREFIX):
 *
 *   PREFIX-energy   T, V, E and E + W over time, and the drift of E + W
 *   PREFIX-path     the bob's path in the plane (theta from the downward
 *                   vertical: x = r sin theta, y = -r cos theta)
 *
 * each as .png and .svg from a kept gnuplot script PREFIX-NAME.gp. The
 * scripts read the CSV itself; its columns are looked up by name here. */
#include <stdio.h>
#include <string.h>

#include "eom/run.h"
#include "demos.h"
#include "spring_plots.h"

/* The column numbers (from 1, as gnuplot counts) of the names needed. */
typedef struct cols {
    int t, r, theta, T, V, E, W;
} cols;

static int find_cols(const char *csv_path, cols *c, char *err,
                     size_t errlen)
{
    eom_csv_table *tab = NULL;
    char msg[256];
    if (eom_csv_table_read(&tab, csv_path, msg, sizeof msg) != 0) {
        snprintf(err, errlen, "plots: reading '%s': %s", csv_path, msg);
        return -1;
    }
    c->t = eom_csv_table_col(tab, "t") + 1;
    c->r = eom_csv_table_col(tab, "r") + 1;
    c->theta = eom_csv_table_col(tab, "theta") + 1;
    c->T = eom_csv_table_col(tab, "T") + 1;
    c->V = eom_csv_table_col(tab, "V") + 1;
    c->E = eom_csv_table_col(tab, "E") + 1;
    c->W = eom_csv_table_col(tab, "W") + 1;
    eom_csv_table_free(&tab);
    if (!c->t || !c->r || !c->theta || !c->T || !c->V || !c->E || !c->W) {
        snprintf(err, errlen, "plots: '%s' lacks a spring-pendulum column",
                 csv_path);
        return -1;
    }
    return 0;
}

/* The frame every script shares: the CSV, a preamble, then the plot for
 * both terminals. */
static void frame_begin(FILE *f, const eom_plot_place *p, const char *name,
                        const char *what, const char *size,
                        const char *preamble)
{
    fprintf(f, "# %s of the spring pendulum; rerun with: gnuplot %s-%s.gp\n"
               "set datafile separator ','\n"
               "csv = '%s'\n"
               "%s"
               "do for [term in 'pngcairo svg'] {\n"
               "  if (term eq 'svg') { set terminal svg size %s "
               "dynamic; set output '%s-%s.svg' }\n"
               "  else { set terminal pngcairo size %s; "
               "set output '%s-%s.png' }\n",
            what, p->prefix, name, p->csv_name, preamble, size, p->prefix,
            name, size, p->prefix, name);
}

static int write_script(const eom_plot_place *p, const char *name,
                        const cols *c, char *err, size_t errlen)
{
    char path[8192], msg[1024];
    eom_csv_writer *w = NULL;
    FILE *f;
    if (eom_plot_place_path(p, name, path, sizeof path - 4) != 0) {
        snprintf(err, errlen, "plots: file names too long");
        return -1;
    }
    strcat(path, ".gp");
    /* created exclusively and put in place whole; a symbolic link at the
     * script's name is replaced, never followed */
    if (eom_csv_writer_open_text(&w, path, msg, sizeof msg) != 0) {
        snprintf(err, errlen, "plots: %s", msg);
        return -1;
    }
    f = eom_csv_writer_stream(w);
    if (strcmp(name, "energy") == 0) {
        frame_begin(f, p, name, "energies over time", "900,700", "");
        fprintf(f,
                "  set multiplot layout 2,1\n"
                "  set grid; set key outside right; set xlabel 't (s)'\n"
                "  set ylabel 'energy (J)'\n"
                "  set title 'kinetic, potential and total energy'\n"
                "  plot csv every ::1 using %d:%d with lines title 'T', "
                "'' every ::1 using %d:%d with lines title 'V', "
                "'' every ::1 using %d:($%d+$%d) with lines lw 2 "
                "title 'E + W'\n"
                "  set ylabel 'J'; set title 'drift of E + W from its start'\n"
                "  stats csv every ::1::1 using ($%d+$%d) name 'E0' nooutput\n"
                "  plot csv every ::1 using %d:($%d+$%d-E0_mean) with lines "
                "title 'E + W - E(0)'\n"
                "  unset multiplot\n}\n",
                c->t, c->T, c->t, c->V, c->t, c->E, c->W, c->E, c->W, c->t,
                c->E, c->W);
    } else {
        char pre[128];
        snprintf(pre, sizeof pre,
                 "stats csv every ::1 using %d name 'R' nooutput\n", c->r);
        frame_begin(f, p, name, "the path of the bob", "700,700", pre);
        fprintf(f,
                "  set xrange [-1.1*R_max:1.1*R_max]\n"
                "  set yrange [-1.1*R_max:0.2*R_max]\n"
                "  set size ratio -1; set grid; set key top right\n"
                "  set xlabel 'x (m)'; set ylabel 'y (m)'\n"
                "  set title 'path of the bob (pivot at the origin)'\n"
                "  set label 1 'pivot' at 0,0 point pointtype 7 "
                "pointsize 2 offset 1,1\n"
                "  plot csv every ::1 using ($%d*sin($%d)):(-$%d*cos($%d)) "
                "with lines title 'bob'\n}\n",
                c->r, c->theta, c->r, c->theta);
    }
    if (eom_csv_writer_close(&w, msg, sizeof msg) != 0) {
        snprintf(err, errlen, "plots: %s", msg);
        return -1;
    }
    return 0;
}

int spring_plots_write(const demo *d, const double *settings,
                       const eom_system *s,
                       const char *csv_path, char *err, size_t errlen)
{
    static const char *const names[2] = {"energy", "path"};
    eom_plot_place p;
    cols c;
    char script[2048];
    int k;
    (void)d;
    (void)settings;
    (void)s;
    if (eom_plot_place_of(&p, csv_path, err, errlen) != 0 ||
        find_cols(csv_path, &c, err, errlen) != 0)
        return -1;
    for (k = 0; k < 2; k++)
        if (write_script(&p, names[k], &c, err, errlen) != 0)
            return -1;
    for (k = 0; k < 2; k++) {
        snprintf(script, sizeof script, "%s-%s.gp", p.prefix, names[k]);
        if (eom_gnuplot_run(p.dir, script, err, errlen) != 0)
            return -1;
    }
    return 0;
}
