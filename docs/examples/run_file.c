/* run_file.c - the example of docs/run.md: a program of one's own that
 * does what eom-run does for a demo. It loads a model file (given on the
 * command line, or the spring pendulum below), integrates it for 2 s with
 * the run layer into out.csv (the CSV contract of docs/csv.md, with the
 * summary on standard error), reads the CSV back and checks that the
 * energy E + W stayed constant, and draws the standard plots when gnuplot
 * is installed. Built and run by the test suite (suite "docs"). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "eom/model_file.h"
#include "eom/run.h"

static const char spring[] =
    "# spring pendulum\n"
    "param m  = 1    [kg]\n"
    "param k  = 75   [N/m]\n"
    "param r0 = 1    [m]\n"
    "param g  = 9.81 [m/s^2]\n"
    "coord r     = 1.1 [m]\n"
    "coord theta = 0.5 [rad]\n"
    "T = 1/2*m*(r_dot^2 + r^2*theta_dot^2)\n"
    "V = 1/2*k*(r - r0)^2 + m*g*(r0 - r*cos(theta))\n";

int main(int argc, char **argv)
{
    const char *csv = "out.csv";
    char err[2048];
    eom_model *model = NULL;
    eom_system *s = NULL;
    eom_csv_writer *w = NULL;
    eom_csv_table *tab = NULL;
    eom_run_opts o;
    double x0[256];
    int rc, i, E, W;

    rc = argc > 1 ? eom_model_from_file(&model, argv[1], err, sizeof err)
                  : eom_model_from_string(&model, spring, err, sizeof err);
    if (rc != EOM_OK || eom_system_new(&s, model, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    eom_model_free(&model);
    if (2 * eom_system_ncoords(s) > 256)
        return 1;
    eom_initial_state(s, x0);

    eom_run_opts_default(&o);
    o.prog = "run_file";
    o.label = argc > 1 ? argv[1] : "spring pendulum";
    o.t_end = 2.0;
    o.opts.method = EOM_ERK;
    if (eom_run_prepare_start(s, x0, &o.opts, o.prog, o.label) != 0 ||
        eom_csv_writer_open(&w, csv, err, sizeof err) != 0) {
        eom_system_free(&s);
        return 1;
    }
    rc = eom_run(s, x0, &o, w);
    if (eom_csv_writer_close(&w, err, sizeof err) != 0 || rc != 0) {
        eom_system_free(&s);
        return 1;
    }

    /* the file holds what was computed: check the energy balance */
    if (eom_csv_table_read(&tab, csv, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        eom_system_free(&s);
        return 1;
    }
    E = eom_csv_table_col(tab, "E");
    W = eom_csv_table_col(tab, "W");
    for (i = 0; i < tab->nrows && E >= 0 && W >= 0; i++)
        if (fabs(eom_csv_table_at(tab, i, E) + eom_csv_table_at(tab, i, W) -
                 eom_csv_table_at(tab, 0, E)) > 1e-6)
            rc = 1;
    printf("%d rows of %d columns in %s; E + W constant: %s\n", tab->nrows,
           tab->ncols, csv, rc == 0 && E >= 0 ? "yes" : "NO");
    eom_csv_table_free(&tab);

    if (eom_run_plots(o.label, s, csv, err, sizeof err) != 0)
        fprintf(stderr, "no plots: %s\n", err); /* gnuplot is optional */
    eom_system_free(&s);
    return rc == 0 && E >= 0 ? 0 : 1;
}
