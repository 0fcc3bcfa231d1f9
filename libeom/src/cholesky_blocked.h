/* cholesky_blocked.h - the blocked Cholesky factor of large mass matrices
 * (cholesky_blocked.c). Apart from eom_internal.h so that the source
 * compiles alone (bench/'s hand-coded chain builds it too). */
#ifndef EOM_CHOLESKY_BLOCKED_H
#define EOM_CHOLESKY_BLOCKED_H

/* The Cholesky factor L L^T = M of the n x n symmetric M (its lower
 * triangle read, column-major) into the lower triangle of A (n x n,
 * column-major; its upper triangle not written; A may be M, in place).
 * Returns 0, or j + 1 when the leading minor of order j + 1 is not
 * positive (A's columns from j on are then partial). */
int eom__potrf_blocked(int n, const double *M, double *A);

#endif /* EOM_CHOLESKY_BLOCKED_H */
