/* chain_shape.h - the deformed shape of a chain (eom/chain.h,
 * docs/elements.md) at a row of eom-run's CSV, for the plots and the
 * animation. Link j runs from its root joint R_j along the chord
 * e_j = (cos theta_j, sin theta_j) and is deflected along
 * n_j = (-sin theta_j, cos theta_j):
 *
 *     r_j(x) = R_j + x e_j + v_j(x) n_j,
 *     v_j(x) = sum_i q_{j,i} sin(i pi x / L_j),   R_1 = 0,
 *     R_{j+1} = R_j + L_j e_j.
 *
 * The lengths L_j are the parameters LJ of the system that ran (they may
 * have been set from the command line); the angles and modal amplitudes
 * are the CSV's columns thetaJ and qJ_I. Points are given as the chord
 * point plus the deflection offset, kept apart so that a plot can draw the
 * deflection magnified. */
#ifndef APPS_CHAIN_SHAPE_H
#define APPS_CHAIN_SHAPE_H

#include <stddef.h>

#include "eom/run.h"
#include "eom/eom.h"

typedef struct chain_shape {
    int links;
    int closed;      /* the tip is pinned at (D, 0) */
    double D;        /* the tip pin's x (closed chains) */
    double *L;       /* [links] link lengths */
    int *modes;      /* [links] assumed modes per link (0: rigid) */
    int *theta_col;  /* [links] CSV column of thetaJ */
    int *q_first;    /* [links] index into q_col of link J's first mode */
    int *q_col;      /* [sum of modes] CSV columns of qJ_I, link by link */
} chain_shape;

/* The shape of the links-link chain of s (borrowed) as read from the CSV
 * t (borrowed; its columns are looked up by name). Returns 0 and a new
 * shape in *out, or -1 with a message in err (errlen bytes) naming a
 * missing parameter or column. */
int chain_shape_new(chain_shape **out, const eom_system *s, int links,
                    const eom_csv_table *t, char *err, size_t errlen);
void chain_shape_free(chain_shape **c);

/* Points drawn along link j: 2 for a rigid link, more with modes. */
int chain_shape_npoints(const chain_shape *c, int j);

/* Link j at row i of t: root (2 values, R_j) is read and advanced to
 * R_{j+1}; pts (4 * chain_shape_npoints values) receives, for points
 * evenly spaced from root to tip, the chord point (x, y) and the
 * deflection offset v n (dx, dy). pts may be NULL to advance root
 * only. */
void chain_shape_link(const chain_shape *c, const eom_csv_table *t, int i,
                      int j,
                      double *root, double *pts);

/* A deflection scale for drawing: 1 when the largest deflection over all
 * rows (bounded by sum_i |q_{j,i}|) is already visible, else a round
 * number (1, 2 or 5 times a power of 10) that draws it at about a tenth
 * of the longest link. */
double chain_shape_exaggeration(const chain_shape *c, const eom_csv_table *t);

#endif /* APPS_CHAIN_SHAPE_H */
