/* wp_plot.h - the work-precision plot of one demo (bench_wp.c): wall
 * time against state error, log-log, one series per method, with the
 * reference's own error drawn as a dashed line. Writes DEMO-wp.dat and
 * the gnuplot script DEMO-wp.gp into a directory and runs gnuplot there,
 * which makes DEMO-wp.png and DEMO-wp.svg; the .dat and .gp files stay,
 * so `cd DIR && gnuplot DEMO-wp.gp` redraws the plot. */
#ifndef BENCH_WP_PLOT_H
#define BENCH_WP_PLOT_H

#include <stddef.h>

#include "wp_sweep.h"

/* Write DEMO-wp.dat and DEMO-wp.gp for w into dir (borrowed). Returns 0,
 * or -1 with a message in err (errlen bytes). */
int wp_plot_files(const char *dir, const wp_sweep *w, char *err,
                  size_t errlen);

/* Run gnuplot on DEMO-wp.gp in dir. Returns 0, or -1 with a message in
 * err saying whether gnuplot could not start or failed. */
int wp_plot_draw(const char *dir, const wp_sweep *w, char *err,
                 size_t errlen);

#endif
