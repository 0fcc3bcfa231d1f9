/* chain_plain.h - the chain of the element library (eom/chain.h: links
 * from +x, gravity along -y, K assumed modes per link) typed in plain C:
 *   - chain_plain_L: the Lagrangian in doubles, the same algorithm as the
 *     element's recording (the unit "plain L" of the benchmarks);
 *   - chain_hand_*: for rigid links, the equations of motion in closed
 *     form, sum_j a_ij [cos(th_i - th_j) thdd_j + sin(th_i - th_j) thd_j^2]
 *     + g c_i cos th_i = 0, solved by Cholesky (plain loops up to 16
 *     coordinates, LAPACK's above, as libeom does): the hand-coded
 *     limit of a Lagrangian route. */
#ifndef BENCH_CHAIN_PLAIN_H
#define BENCH_CHAIN_PLAIN_H

typedef struct chain_plain {
    int links, modes;          /* N, and K for every link */
    const double *m, *L, *EI;  /* [N] each */
    double g;
} chain_plain;

/* L at x = (q, qd), q = (theta[N], modes link by link). */
double chain_plain_L(const chain_plain *c, const double *x);

typedef struct chain_hand {
    int N;
    double g;
    double *a;  /* N x N coefficients of the mass matrix */
    double *cg; /* N gravity coefficients */
    double *M;  /* N x N scratch */
    double *sc; /* 2N scratch: sines, cosines */
} chain_hand;

/* For rigid links only (modes 0); 0 or -1. */
int chain_plain_hand_new(chain_hand **out, const chain_plain *c);
void chain_plain_hand_free(chain_hand **h);
/* qdd (N) at x = (theta, theta_dot); 0, or non-zero if M is singular. */
int chain_plain_hand_rhs(chain_hand *h, const double *x, double *qdd);
/* Solve M x = b for symmetric positive definite M (n x n, overwritten)
 * with the hand-coded route's Cholesky; b becomes x. 0, or non-zero if M
 * is not positive definite. */
int chain_plain_solve(int n, double *M, double *b);
/* The same by one route at any n, for timing them against each other:
 * CHAIN_SOLVE_COLUMNS (libeom's loops by columns), CHAIN_SOLVE_BLOCKED
 * (its blocked factor, then the columns' solve), CHAIN_SOLVE_LAPACK
 * (dpotrf + dpotrs of the LAPACK the program loaded). 0, or -1. */
enum { CHAIN_SOLVE_COLUMNS, CHAIN_SOLVE_BLOCKED, CHAIN_SOLVE_LAPACK };
int chain_plain_solve_by(int route, int n, double *M, double *b);

#endif
