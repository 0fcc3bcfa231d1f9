/* pendulum_chain.h - the planar N-link pendulum of uniform rods, pinned at
 * the origin, in absolute angles q_i measured from the downward vertical:
 * the recorded Lagrangian (any libtape backend), the same Lagrangian typed
 * as plain C doubles, and the closed-form mass matrix
 *     M_ij = a_ij cos(q_i - q_j),
 *     a_ii = m_i l_i^2 / 3 + l_i^2 sum_{k>i} m_k,
 *     a_ij = l_i l_j (m_j / 2 + sum_{k>j} m_k)   (i < j).
 * Used by tests, benchmarks and the libtape demo. */
#ifndef PENDULUM_CHAIN_H
#define PENDULUM_CHAIN_H

#include "tape/tape.h"

typedef struct pendulum_chain {
    int n;            /* number of links */
    const double *m;  /* [n] masses; NULL: parameters "m1".. default 1 */
    const double *l;  /* [n] lengths; NULL: parameters "l1".. default 1 */
    double g;         /* default of parameter "g" */
} pendulum_chain;

/* Records output "L" (and "T", "V") from independents (q[n], qd[n]) with
 * parameters m1..mn, l1..ln, g. user is a const pendulum_chain *. */
int pendulum_chain_record(tp_rec *r, void *user);

/* The same L in plain doubles (the compiled baseline). */
double pendulum_chain_L(const pendulum_chain *pc, const double *x);

/* Closed-form M (n x n row-major) at q. */
void pendulum_chain_mass(const pendulum_chain *pc, const double *q,
                         double *M);

/* Mass and length of link i (the defaults when pc->m or pc->l is NULL). */
double pendulum_chain_m(const pendulum_chain *pc, int i);
double pendulum_chain_l(const pendulum_chain *pc, int i);

#endif
