/* lin_models.h - models written for the linearization tests, beside the
 * shared ones of tests/models/eom_models.h. Each builder returns a new
 * model (free it with eom_model_free) or NULL.
 *
 *   point pendulum    a point mass m on a massless rod of length l;
 *                     theta from the downward vertical (q0 = theta0).
 *                     T = m l^2 thd^2 / 2, V = -m g l cos theta - tau theta
 *                     (tau: a constant torque, written as its potential);
 *                     with damped != 0 also R = c thd^2 / 2.
 *                     Parameters m, l, g, tau, c.
 *   flexible link     one uniform Euler-Bernoulli link (mass m, length L)
 *                     with two assumed modes v(x) = a1 sin(pi x / L) +
 *                     a2 sin(2 pi x / L), angle th from +x, pinned at the
 *                     origin and at (L, 0), gravity along -y: the case of
 *                     paper/NOTES.md, where at th = 0 the x-row of C is
 *                     identically zero. Coordinates th, a1, a2;
 *                     parameters m, L, EI, g. With the integrals over the
 *                     link of x sin(i pi x / L) (L^2 (-1)^(i+1) / (i pi))
 *                     and of sin(i pi x / L) (2L / pi, then 0):
 *                       T = m/2 [(L^2/3 + (a1^2 + a2^2)/2) thd^2
 *                                + (2L/pi) thd (a1d - a2d / 2)
 *                                + (a1d^2 + a2d^2)/2]
 *                       V = m g [(L/2) sin th + (2 a1 / pi) cos th]
 *                           + EI pi^4 (a1^2 + 16 a2^2) / (4 L^3)
 *                       phi = (L cos th - L, L sin th)
 *   redundant sphere  a point mass (x, y, z) on a sphere of radius l,
 *                     gravity along -y, with its constraint given twice:
 *                     phi1 = (x^2 + y^2 + z^2 - l^2) / 2, phi2 = 2 phi1,
 *                     so C has rank 1 everywhere. Parameters m, l, g.
 * (eom_system_new needs fewer constraints than coordinates, hence the
 * second mode and the third dimension.)
 */
#ifndef LIN_MODELS_H
#define LIN_MODELS_H

#include "eom/eom.h"

eom_model *lin_models_pendulum(double m, double l, double g, double tau,
                               double c, int damped, double theta0);
eom_model *lin_models_flexible_link(double m, double L, double EI, double g);
eom_model *lin_models_redundant_sphere(double m, double l, double g);

/* A system from a model (the model is freed); NULL with a message on
 * stderr on failure. */
eom_system *lin_models_system(eom_model *md);

#endif
