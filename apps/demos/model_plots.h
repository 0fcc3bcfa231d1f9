/* model_plots.h - the plots eom-run draws for any model (--plots on a
 * model file), beside the run's CSV under its name without ".csv"
 * (PREFIX), each as .png and .svg from a kept gnuplot script:
 *
 *   PREFIX-coordinates  every coordinate over time, one panel per unit
 *   PREFIX-energy       T, V, E and E + W over time, and the drift of E + W
 *   PREFIX-residuals    |phi| and |C qd| of every constraint (log scale),
 *                       when the model has constraints
 *   PREFIX-probes       every probe over time, when the model has probes
 */
#ifndef APPS_MODEL_PLOTS_H
#define APPS_MODEL_PLOTS_H

#include <stddef.h>

#include "eom/eom.h"

/* Write and run the scripts for the system s (which wrote csv_path);
 * label names the model in titles. Returns 0, or -1 with a message. */
int model_plots_write(const char *label, const eom_system *s,
                      const char *csv_path, char *err, size_t errlen);

#endif /* APPS_MODEL_PLOTS_H */
