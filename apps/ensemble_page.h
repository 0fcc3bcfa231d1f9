/* ensemble_page.h - eom-ensemble --plots: the runs' trajectories drawn
 * over each other in one animation page (docs/ensembles.md), from the
 * CSVs --trajectories wrote. */
#ifndef APPS_ENSEMBLE_PAGE_H
#define APPS_ENSEMBLE_PAGE_H

#include "ensemble_runs.h"
#include "eom/eom.h"

/* SUMMARY-animation.html beside summary (the --out path) for the runs i
 * with drawn[i] set, each read from traj_dir/run-I.csv and named in the
 * legend by its number and its values ("run 3: th1=0.5"). s: the
 * ensemble's system (its drawings; borrowed), label: the model's name.
 * 0 (also when the model has no drawings or no run is to be drawn), or
 * -1 after a message on standard error. *ndrawn receives the number of
 * runs drawn. */
int ensemble_page_write(const char *summary, const char *traj_dir,
                        const ensemble_runs *runs,
                        const unsigned char *drawn, const eom_system *s,
                        const char *label, long *ndrawn);

#endif /* APPS_ENSEMBLE_PAGE_H */
