/* chain_unequal.h - the chains of unequal links that bench-rhs and
 * bench-compiled time (docs/benchmarks.md, sections 2 and 13): masses
 * 1 + 0.1 (j mod 7) kg, lengths 10 - 0.3 (j mod 5) m, EI 4e4, gravity
 * 9.81, so that no symmetry helps any method; and the state they are
 * timed at. */
#ifndef BENCH_CHAIN_UNEQUAL_H
#define BENCH_CHAIN_UNEQUAL_H

#include "chain_plain.h"
#include "eom/eom.h"

/* Fill m, L, EI ([links] each) and c (which points at them). */
void chain_unequal(chain_plain *c, int links, int modes, double *m,
                   double *L, double *EI);

/* c as a model of the element library (eom/chain.h); EOM_OK or a status
 * (*out NULL). */
int chain_unequal_model(const chain_plain *c, eom_model **out);

/* The same chain closed: its tip pinned at (D, 0), D 0.9 of the links'
 * total length (bench-compiled's closed chains). */
int chain_unequal_closed_model(const chain_plain *c, eom_model **out);

/* A hanging zig-zag, moving, slightly bent: x = (q, qd) of the chain's
 * n coordinates. */
void chain_unequal_state(const chain_plain *c, int n, double *x);

#endif
