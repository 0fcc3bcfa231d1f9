/* test_cholesky.c - the mass matrix's Cholesky routes of libeom on their
 * own (white-box): the column loops (cholesky_columns.c, used for
 * 17 <= n <= 128) and the blocked factor (cholesky_blocked.c, above),
 * each at sizes about every switch and about the blocked factor's panel
 * edges (n = 16, 17, 47 .. 49, 96, 97, 128, 129, 300, 513: remainders of
 * every kind for the panels of 48 columns, the tiles of 8 x 4 and the
 * switch at 128).
 *
 *   1. The factor of M = L L^T, with L a lower triangle drawn at random
 *      (diagonal 1 .. 2), is L itself to rounding: a closed form the
 *      code does not compute. The upper triangle of the output is left
 *      as it was, and M is not written.
 *   2. The solve of M X = B (three right-hand sides) with that factor:
 *      the residual |M x - b| / (|M| |x|) is at rounding level (1e-15
 *      times a small multiple of n), and x agrees with reference
 *      LAPACK's dposv on the same M and B.
 *   3. M made indefinite at coordinate k (M_kk lowered below what the
 *      coordinates before it account for, its leading minors before k
 *      untouched): each route reports k + 1, the order of the leading
 *      minor that fails, at k on either side of each panel edge and at
 *      the last coordinate.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom_internal.h"

void dposv_(const char *uplo, const int *n, const int *nrhs, double *a,
            const int *lda, double *b, const int *ldb, int *info,
            size_t uplo_len);

/* A route: factor, and its name in messages. */
typedef struct {
    int (*potrf)(int n, const double *M, double *A);
    const char *name;
} route;

static const route routes[] = {
    {eom__potrf_columns, "columns"},
    {eom__potrf_blocked, "blocked"},
};

/* Uniform in [0, 1): a small LCG, the same numbers on every machine. */
static double uniform(unsigned long long *state)
{
    *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*state >> 11) / 9007199254740992.0;
}

/* L (n x n, column-major lower triangle, zero above) at random and
 * M = L L^T, both triangles. The entries below the diagonal are at most
 * 0.5 / sqrt(n), so that the part of L below its diagonal has a norm
 * below 1 (about 0.6): L and M stay well conditioned at every n (a
 * random triangle with entries of order 1 has a condition number that
 * grows like 2^n). */
static void draw(int n, unsigned long long seed, double *L, double *M)
{
    const size_t N = (size_t)n;
    size_t i, j, k;
    memset(L, 0, N * N * sizeof *L);
    for (j = 0; j < N; j++) {
        L[j + j * N] = 1.0 + uniform(&seed);
        for (i = j + 1; i < N; i++)
            L[i + j * N] = (uniform(&seed) - 0.5) / sqrt((double)n);
    }
    for (j = 0; j < N; j++)
        for (i = j; i < N; i++) {
            double t = 0.0;
            for (k = 0; k <= j; k++)
                t += L[i + k * N] * L[j + k * N];
            M[i + j * N] = M[j + i * N] = t;
        }
}

static void check_factor_and_solve(const route *r, int n)
{
    const size_t N = (size_t)n;
    const int nrhs = 3;
    double *L = malloc(N * N * sizeof *L), *M = malloc(N * N * sizeof *M);
    double *M0 = malloc(N * N * sizeof *M0), *A = malloc(N * N * sizeof *A);
    double *B = malloc(3 * N * sizeof *B), *X = malloc(3 * N * sizeof *X);
    double *R = malloc(N * N * sizeof *R), *XR = malloc(3 * N * sizeof *XR);
    double ferr = 0.0, res = 0.0, ref = 0.0, mnorm = 0.0, xnorm = 0.0;
    unsigned long long seed = 12345u + (unsigned long long)n;
    size_t i, j;
    int c, info = 0;
    draw(n, (unsigned long long)n, L, M);
    memcpy(M0, M, N * N * sizeof *M);
    for (i = 0; i < N * N; i++)
        A[i] = 7777.0;
    CHECK_INT(r->potrf(n, M, A), 0);
    for (j = 0; j < N; j++)
        for (i = 0; i < N; i++) {
            if (i >= j)
                ferr = fmax(ferr, fabs(A[i + j * N] - L[i + j * N]));
            else if (A[i + j * N] != 7777.0)
                ferr = INFINITY; /* the upper triangle was written */
        }
    if (!(ferr <= 1e-12))
        fprintf(stderr, "%s n = %d: |factor - L| = %.3g\n", r->name, n, ferr);
    CHECK(ferr <= 1e-12);
    CHECK(memcmp(M, M0, N * N * sizeof *M) == 0);

    for (i = 0; i < 3 * N; i++)
        B[i] = 2.0 * uniform(&seed) - 1.0;
    memcpy(X, B, 3 * N * sizeof *X);
    eom__potrs_columns(n, nrhs, A, X);
    memcpy(XR, B, 3 * N * sizeof *XR);
    memcpy(R, M, N * N * sizeof *R);
    dposv_("L", &n, &nrhs, R, &n, XR, &n, &info, 1);
    CHECK_INT(info, 0);
    for (i = 0; i < N; i++) {
        double row = 0.0;
        for (j = 0; j < N; j++)
            row += fabs(M[i + j * N]);
        mnorm = fmax(mnorm, row);
    }
    for (c = 0; c < nrhs; c++) {
        const double *x = X + (size_t)c * N, *b = B + (size_t)c * N;
        const double *xr = XR + (size_t)c * N;
        for (i = 0; i < N; i++) {
            double t = -b[i];
            for (j = 0; j < N; j++)
                t += M[i + j * N] * x[j];
            res = fmax(res, fabs(t));
            xnorm = fmax(xnorm, fabs(x[i]));
            ref = fmax(ref, fabs(x[i] - xr[i]));
        }
    }
    /* |M x - b|_inf / (|M|_inf |x|_inf): backward error of the solve */
    res /= mnorm * xnorm;
    ref /= xnorm;
    if (!(res <= 1e-15 * (1.0 + n / 32.0)) || !(ref <= 1e-10))
        fprintf(stderr,
                "%s n = %d: residual %.3g, against dposv %.3g (relative)\n",
                r->name, n, res, ref);
    CHECK(res <= 1e-15 * (1.0 + n / 32.0));
    CHECK(ref <= 1e-10);
    free(L);
    free(M);
    free(M0);
    free(A);
    free(B);
    free(X);
    free(R);
    free(XR);
}

/* M indefinite at k: the leading minor of order k + 1 fails. */
static void check_indefinite(const route *r, int n, int k)
{
    const size_t N = (size_t)n, K = (size_t)k;
    double *L = malloc(N * N * sizeof *L), *M = malloc(N * N * sizeof *M);
    double *A = malloc(N * N * sizeof *A);
    int info;
    draw(n, 99u + (unsigned long long)k, L, M);
    /* the pivot at k becomes L_kk^2 - 5 <= -1 (L_kk is at most 2); the
     * minors before it keep their pivots */
    M[K + K * N] -= 5.0;
    info = r->potrf(n, M, A);
    if (info != k + 1)
        fprintf(stderr, "%s n = %d, indefinite at %d: info %d\n", r->name,
                n, k, info);
    CHECK_INT(info, k + 1);
    free(L);
    free(M);
    free(A);
}

int main(void)
{
    static const int sizes[] = {1, 2, 16, 17, 47, 48, 49, 96, 97, 128, 129,
                                300, 513};
    static const int at[][2] = {{17, 0},   {17, 16},   {49, 47},
                                {49, 48},  {97, 46},   {97, 95},
                                {97, 96},  {129, 128}, {300, 143},
                                {300, 144}, {300, 250}, {513, 480},
                                {513, 512}};
    size_t r, k;
    for (r = 0; r < sizeof routes / sizeof routes[0]; r++) {
        for (k = 0; k < sizeof sizes / sizeof sizes[0]; k++)
            check_factor_and_solve(&routes[r], sizes[k]);
        for (k = 0; k < sizeof at / sizeof at[0]; k++)
            check_indefinite(&routes[r], at[k][0], at[k][1]);
    }
    CHECK_DONE();
}
