/* adolc_rhs.h - the right-hand side of the rigid N-link pendulum chain
 * computed with ADOL-C, callable from C, for timing ADOL-C against libtape
 * in the same benchmark process.
 *
 * The model is the chain of eom/chain.h with rigid links only: N uniform
 * rods pinned at the origin, absolute angles theta_j from +x
 * (counter-clockwise), masses m_j, lengths L_j, gravity g along -y. The
 * state is x = (q, qd) = (theta, theta_dot), 2N values. The Lagrangian is
 * recorded once on an ADOL-C tape with adoubles, the kinetic energy
 * accumulated joint by joint as the chain element does; each evaluation
 * replays that tape for dL/dq, M = d2L/dqd2 and h = (d2L/dqd dq) qd and
 * solves M qdd = dL/dq - h by Cholesky (LAPACK).
 *
 * Drivers (what each evaluation calls):
 *   ADOLC_DRIVER_VECTOR   one hov_wk_forward (N directions, the unit
 *                         vectors on qd, keeping the Taylor coefficients)
 *                         and one hos_ov_reverse: the Hessian columns
 *                         d2L/(dx dqd_k) and the gradient in two sweeps;
 *   ADOLC_DRIVER_HESSIAN  hessian() (the full 2N x 2N Hessian, one
 *                         Hessian-vector product per column) and
 *                         gradient().
 *
 * ADOL-C keeps its tapes in process-wide state, so a tag must be unique
 * among the live objects of the process, and an object must be used by
 * one thread at a time (ADOL-C as packaged by Debian is not built for
 * concurrent use). Functions return 0 on success and non-zero on failure;
 * they never abort and never let a C++ exception out. */
#ifndef BENCH_ADOLC_RHS_H
#define BENCH_ADOLC_RHS_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct adolc_rhs adolc_rhs;

enum { ADOLC_DRIVER_VECTOR, ADOLC_DRIVER_HESSIAN };

/* Record the Lagrangian of nlinks rods (masses m[nlinks], lengths
 * L[nlinks], gravity g; read during the call only) on ADOL-C tape tag and
 * allocate every buffer the evaluations need. driver is one of the
 * ADOLC_DRIVER_ values. The tape and the Taylor coefficients the sweeps
 * keep stay in memory (ADOL-C writes no file) up to about 6700 links.
 * On failure *out is NULL and the tape, if recorded, is removed. */
int adolc_rhs_new(adolc_rhs **out, int nlinks, const double *m,
                  const double *L, double g, int driver, short tag);

/* qdd[n] at x = (q, qd) (2n values, borrowed); M (n x n row-major) is
 * written too unless NULL. No heap allocation of its own; ADOL-C's sweeps
 * allocate internally. Non-zero when ADOL-C reports an error or asks for
 * retaping, when M is not positive definite, or on non-finite results. */
int adolc_rhs_eval(adolc_rhs *a, const double *x, double *qdd, double *M);

/* Free the buffers and remove the tape; *a is set to NULL. NULL-safe. */
void adolc_rhs_free(adolc_rhs **a);

#ifdef __cplusplus
}
#endif
#endif /* BENCH_ADOLC_RHS_H */
