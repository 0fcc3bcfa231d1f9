/* ocea_plain.h - the paper's embedded tuples written as a careful plain-C
 * engine, the reference that tp_tuple is measured against: every value
 * is (value, gradient, packed Hessian) over the 2n independents, tuples
 * live in one pool made once, and each operation writes its result in
 * place with unit-stride loops and no temporaries. Only what the rigid
 * chain's Lagrangian needs is here: it evaluates the same L as the
 * element library's chain (eom/chain.h, rigid links, gravity), in the
 * same order of operations, and returns the Lagrange blocks. */
#ifndef BENCH_OCEA_PLAIN_H
#define BENCH_OCEA_PLAIN_H

typedef struct ocea_plain ocea_plain;

/* An engine for the rigid chain of N links of masses m[j] and lengths
 * L[j] (copied), gravity g; NULL when out of memory. */
ocea_plain *ocea_plain_new(int N, const double *m, const double *L,
                           double g);
void ocea_plain_free(ocea_plain *o);

/* At x = (theta, theta_dot): L, dL/dq, M = d2L/dqd2 (N x N, row-major)
 * and h = (d2L/dqd dq) qd, like tp_tuple_lagrange. */
void ocea_plain_lagrange(ocea_plain *o, const double *x, double *L,
                         double *dLdq, double *M, double *h);

#endif
