/* eom_models.h - small mechanisms built as libeom models, shared by the
 * libeom tests. Each builder returns a new model (free it with
 * eom_model_free) or NULL on failure; parameters are named as below and
 * start at the values given. Angles of chains are absolute.
 *
 *   spring pendulum   coordinates r, theta (theta from the downward
 *                     vertical); parameters m, k, r0, g.
 *                     T = m/2 (rd^2 + r^2 thd^2),
 *                     V = k/2 (r - r0)^2 + m g (r0 - r cos theta).
 *   rod chain         n uniform rods pinned at the origin, angles th1..thn
 *                     from +x (counter-clockwise), gravity along -y;
 *                     parameters m1.., l1.., g. With closed != 0 the tip is
 *                     pinned at (D, 0): constraints sum l cos th = D,
 *                     sum l sin th = 0 (parameter D). Three rods closed
 *                     make a four-bar linkage (the ground is the fourth).
 *   bead on a circle  a point mass (x, y) with phi = (x^2 + y^2 - l^2)/2
 *                     = 0, gravity along -y; parameters m, l, g. Its
 *                     generalized constraint force at rest at the bottom
 *                     is C^T lambda = (0, m g).
 */
#ifndef EOM_MODELS_H
#define EOM_MODELS_H

#include "eom/eom.h"

eom_model *eom_models_spring_pendulum(double m, double k, double r0,
                                      double g);

/* n rods of masses m[i] and lengths l[i] at initial angles th0[i] (rates
 * zero); closed: pinned at (D, 0) too. */
eom_model *eom_models_rod_chain(int n, const double *m, const double *l,
                                const double *th0, double g, int closed,
                                double D);

eom_model *eom_models_bead_on_circle(double m, double l, double g);

#endif
