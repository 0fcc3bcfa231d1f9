/* mass_line.h - a model with a sparse iteration matrix, shared by the
 * tests of the sparse path and bench-sparse: a line of N point masses in
 * the plane in Cartesian coordinates (x_i, y_i), neighbours joined by
 * nonlinear springs and dampers, under gravity, optionally constrained.
 *
 *   T = m/2 sum_i (xd_i^2 + yd_i^2)
 *   V = k/2 sum_i sum_s (|r_i+s - r_i| - s a)^2 + m g sum_i y_i
 *   R = c/2 sum_i |v_i+1 - v_i|^2
 *   (s = 1 .. reach: reach 1 joins neighbours only; a larger reach
 *   couples each mass to the next reach masses, to fill the matrices in)
 *   constraints (constrained != 0): the first mass pinned at the origin
 *   (x_0 = 0, y_0 = 0), the last on a vertical rail (x_N-1 = X), and a
 *   rigid link of the initial length d between the two middle masses
 *   (|r_j+1 - r_j|^2 - d^2 = 0, j = N/2 - 1): four constraints, two
 *   linear, one nonlinear in one mass pair. Parameters m, k, a, c, g,
 *   X, d.
 *
 * The masses start slightly compressed (spacing 0.98 a) in a sagging arc,
 * at rest, consistent with the constraints. Each body couples to its
 * neighbours only: M is diagonal, dF/dq and dF/dv tridiagonal by 2 x 2
 * blocks, C has at most four entries a row.
 */
#ifndef MASS_LINE_H
#define MASS_LINE_H

#include "eom/eom.h"

/* A new model of N >= 4 masses, springs reaching 1 <= reach < N masses
 * on (free it with eom_model_free), or NULL. */
eom_model *mass_line_model(int N, int constrained, int reach);

/* The free line of N masses (reach 1) with a mass matrix of blocks: 2,
 * each mass's x and y rates coupled (0.3 m xd_i yd_i); 4, also the
 * masses in pairs (0.2 m v_2i . v_2i+1; N even). NULL otherwise. */
eom_model *mass_line_blocks_model(int N, int blocks);

#endif
