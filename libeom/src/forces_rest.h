/* forces_rest.h - the generalized forces Q(q, qd, t) at rest, for the
 * static analysis (equilibrium.c, linearize.c): library-internal. */
#ifndef EOM_FORCES_REST_H
#define EOM_FORCES_REST_H

#include "eom_internal.h"

/* EOM_ERR_MODEL, with a message that starts with what and names the
 * first coordinate whose force reads the time, when one of the model's
 * forces depends on the time (structurally: through any chain of ops of
 * the force tape); a force that changes with time has no state of rest.
 * EOM_OK for a model without forces or whose forces read (q, qd) only. */
int eom__refuse_forces_time(eom_system *s, const char *what);

/* The forces at rest at q (n): Q(q, 0) into Q (n), and when dq (n x n)
 * and dqd (n x n) are not NULL the Jacobians dQ/dq and dQ/dqd there
 * (row i: the force on coordinate i), all row-major. Without forces
 * every output is zero. x (2n) is the caller's scratch. Call after
 * eom__refuse_forces_time: the time is taken as 0. */
int eom__forces_at_rest(eom_system *s, const double *q, double *x,
                        double *Q, double *dq, double *dqd);

#endif
