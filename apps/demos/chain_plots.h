/* chain_plots.h - the plots of the chain demos: kinetic energy per link
 * split into its rigid and flexible parts, snapshots of the deformed
 * chain, total energy and E + W, the constraint residuals of a closed
 * chain, and an animation, written beside the run's CSV. */
#ifndef APPS_CHAIN_PLOTS_H
#define APPS_CHAIN_PLOTS_H

#include <stddef.h>

#include "eom/eom.h"

/* Write the plots of a chain of links links (system s, which ran and
 * wrote csv_path) beside csv_path. Returns 0, or non-zero with a message
 * in err (errlen bytes). */
int chain_plots_write(const eom_system *s, int links, const char *csv_path,
                      char *err, size_t errlen);

#endif
