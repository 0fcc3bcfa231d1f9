/* chain_plots.c - the plots of the chain demos (see chain_plots.h),
 * written beside the run's CSV under its name without ".csv" (PREFIX):
 *
 *   PREFIX-energy      kinetic energy per link, rigid and flexible parts
 *   PREFIX-snapshots   the deformed chain at 8 times (+ PREFIX-snapshots.dat)
 *   PREFIX-total-energy  E, W and E + W, and the drift E + W - E(0)
 *   PREFIX-residuals   |phi| and |C qd| on a log scale (closed chains)
 *
 * each as .png and .svg, made by gnuplot from a script PREFIX-NAME.gp
 * that is kept (rerun it with `cd DIR && gnuplot PREFIX-NAME.gp`), and
 * PREFIX-animation.html (eom_run_animation: the chain element draws
 * its links, joints and tip). Everything is read back from the CSV file, so the
 * plots show what the file holds. The scripts and the page are written
 * first and gnuplot runs last: when gnuplot is missing, the user still has
 * the CSV, the scripts and the animation. */
#include "chain_plots.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "chain_shape.h"
#include "chain_plot_scripts.h"
#include "eom/run.h"

/* The plots, in the order they are made. */
static const struct {
    const char *name;
    int closed_only; /* residuals: only a closed chain has constraints */
} plots[] = {
    {"energy", 0},
    {"snapshots", 0},
    {"total-energy", 0},
    {"residuals", 1},
};
enum { NPLOTS = sizeof plots / sizeof plots[0] };

int chain_plots_write(const eom_system *s, int links, const char *csv_path,
                      char *err, size_t errlen)
{
    eom_csv_table *t = NULL;
    chain_shape *c = NULL;
    plot_job job;
    eom_plot_place p;
    char path[8192], name[2048], msg[1024];
    int rc = -1, k, kg;

    if (eom_plot_place_of(&p, csv_path, err, errlen) != 0)
        return -1;
    if (eom_csv_table_read(&t, csv_path, msg, sizeof msg) != 0) {
        snprintf(err, errlen, "plots: reading '%s': %s", csv_path, msg);
        return -1;
    }
    if (t->nrows < 1) {
        snprintf(err, errlen, "plots: '%s' has no rows", csv_path);
        goto done;
    }
    if (chain_shape_new(&c, s, links, t, msg, sizeof msg) != 0) {
        snprintf(err, errlen, "plots: %s", msg);
        goto done;
    }
    memset(&job, 0, sizeof job);
    job.t = t;
    job.c = c;
    job.csv_name = p.csv_name;
    job.prefix = p.prefix;
    job.exaggeration = chain_shape_exaggeration(c, t);
    kg = eom_param_index(s, "g");
    job.gravity = kg >= 0 && eom_get_param(s, kg) != 0.0;

    /* everything that does not need gnuplot first; path always fits
     * (dir and prefix are bounded), but say so if it ever does not */
    /* the animation page of every model with drawings (the chain element
     * draws its links, joints and tip) */
    if (eom_run_animation(NULL, s, csv_path, err, errlen) != 0)
        goto done;
    if (eom_plot_place_path(&p, "snapshots.dat", path, sizeof path) != 0)
        goto too_long;
    if (chain_snapshots_dat(path, &job, err, errlen) != 0)
        goto done;
    for (k = 0; k < NPLOTS; k++) {
        if (plots[k].closed_only && !c->closed)
            continue;
        snprintf(name, sizeof name, "%s.gp", plots[k].name);
        if (eom_plot_place_path(&p, name, path, sizeof path) != 0)
            goto too_long;
        if (chain_plot_script(path, plots[k].name, &job, err, errlen) != 0)
            goto done;
    }
    for (k = 0; k < NPLOTS; k++) {
        if (plots[k].closed_only && !c->closed)
            continue;
        snprintf(name, sizeof name, "%s-%s.gp", p.prefix, plots[k].name);
        if (eom_gnuplot_run(p.dir, name, msg, sizeof msg) != 0) {
            snprintf(err, errlen, "plots: %s; the CSV, the gnuplot scripts "
                     "and the animation are written", msg);
            goto done;
        }
    }
    rc = 0;
    goto done;
too_long:
    snprintf(err, errlen, "plots: the path '%s' is too long", csv_path);
done:
    chain_shape_free(&c);
    eom_csv_table_free(&t);
    return rc;
}
