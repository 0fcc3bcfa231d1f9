/* bench_chain.h - the chains the bench programs build from the element
 * library (eom/chain.h): the paper's 1 kg, 10 m links, a damper of c at
 * every joint but the base when c is not 0, optional modal damping, and
 * the paper's start of the closed five-link chain. */
#ifndef BENCH_CHAIN_H
#define BENCH_CHAIN_H

#include <stddef.h>

#include "eom/eom.h"

typedef struct chain_cfg {
    int links, modes, closed;
    double EI, D, g;
    double c;             /* joint dampers (0: none, and no parameter c) */
    double zeta;          /* modal damping ratio of every mode (0: the
                             paper's undamped beams, and no parameters of
                             structural damping) */
    const double *theta0; /* [links] start angles (borrowed) */
} chain_cfg;

/* The closed five-link chain's start in the paper (rad). */
extern const double bench_paper5[5];

/* The system of cfg, or NULL with a message in msg (len bytes). */
eom_system *bench_chain_new(const chain_cfg *cfg, char *msg, size_t len);

#endif
