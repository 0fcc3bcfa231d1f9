/* chain_plot_scripts.h - the gnuplot scripts of the chain plots
 * (chain_plots.c runs them) and the data file of the snapshots. Each
 * script reads the run's CSV by column name, or PREFIX-snapshots.dat,
 * names files without a directory (it runs in their directory) and
 * writes PREFIX-NAME.png and PREFIX-NAME.svg. Text is drawn without
 * gnuplot's "enhanced" markup, so '_' in names stays an underscore. */
#ifndef APPS_CHAIN_PLOT_SCRIPTS_H
#define APPS_CHAIN_PLOT_SCRIPTS_H

#include <stddef.h>

#include "chain_shape.h"
#include "eom/run.h"

/* At most this many links get a panel in the energy plot; the title says
 * when links were left out (the CSV has them all). */
#define CHAIN_PLOT_MAX_PANELS 6
/* Snapshots of the deformed chain, evenly spaced over the rows. */
#define CHAIN_PLOT_SNAPSHOTS 8

/* What every script needs (all borrowed). */
typedef struct plot_job {
    const eom_csv_table *t;    /* the run's rows */
    const chain_shape *c;  /* the chain's geometry */
    const char *csv_name;  /* the CSV's file name, as the scripts read it */
    const char *prefix;    /* output names: PREFIX-NAME.png, .svg */
    double exaggeration;   /* deflection scale of the snapshots */
    int gravity;           /* g != 0 (said in the snapshot title) */
} plot_job;

/* Write PREFIX-snapshots.dat to path: for snapshot k (0-based), data
 * block 2k holds the chain's points (chord x, y, deflection dx, dy; the
 * links one after another) and block 2k+1 its joints (x, y); blocks are
 * separated by two blank lines (gnuplot's `index`). Returns 0, or -1
 * with a message in err (errlen bytes). */
int chain_snapshots_dat(const char *path, const plot_job *j, char *err,
                        size_t errlen);

/* Write the script of plot which ("energy", "snapshots", "total-energy"
 * or "residuals") to path. Returns 0, or -1 with a message. */
int chain_plot_script(const char *path, const char *which,
                      const plot_job *j, char *err, size_t errlen);

#endif /* APPS_CHAIN_PLOT_SCRIPTS_H */
