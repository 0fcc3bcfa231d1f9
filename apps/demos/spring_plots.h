/* spring_plots.h - the plots of the spring-pendulum demo (the after_run
 * hook of demo_spring_pendulum): its energies and the bob's path,
 * written beside the CSV. */
#ifndef APPS_SPRING_PLOTS_H
#define APPS_SPRING_PLOTS_H

#include <stddef.h>

#include "demos.h"
#include "eom/eom.h"

int spring_plots_write(const demo *d, const double *settings,
                       const eom_system *s,
                       const char *csv_path, char *err, size_t errlen);

#endif
