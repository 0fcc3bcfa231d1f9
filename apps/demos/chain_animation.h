/* chain_animation.h - a self-contained HTML page that plays a chain's
 * motion: one canvas, inline JavaScript, the frames embedded as data, no
 * network resources, so the file can be opened offline or mailed.
 *
 * Each frame is one line `[t, theta1, .., thetaN, q1_1, .., qN_K],` in
 * the array `frames`; the page computes the deformed links from them with
 * the same formula as the plots (chain_shape.h), so the file stays small.
 * Controls: play/pause (also the space bar), a time slider, the playback
 * speed and the deflection scale. */
#ifndef APPS_CHAIN_ANIMATION_H
#define APPS_CHAIN_ANIMATION_H

#include <stddef.h>

#include "chain_shape.h"
#include "eom/run.h"

/* The most frames embedded: longer runs are thinned evenly (the last row
 * is always kept). */
#define CHAIN_ANIMATION_MAX_FRAMES 5000

/* Write the page to path for chain c and the rows of t (both borrowed).
 * title is shown on the page (escaped here); exaggeration is the initial
 * deflection scale; gravity 1 adds a note that gravity acts along -y.
 * Returns 0, or -1 with a message in err (errlen bytes). */
int chain_animation_write(const char *path, const chain_shape *c,
                          const eom_csv_table *t, const char *title,
                          double exaggeration, int gravity, char *err,
                          size_t errlen);

#endif /* APPS_CHAIN_ANIMATION_H */
