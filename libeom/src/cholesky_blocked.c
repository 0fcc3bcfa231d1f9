/* cholesky_blocked.c - the Cholesky factor of large mass matrices (above
 * EOM_COLUMN_CHOLESKY), blocked and right-looking, with no BLAS.
 *
 * Column loops (cholesky_columns.c) read every earlier column once for
 * each column they update: at n = 200 that streams about 2.7 million
 * values through the cache for as many multiply-adds, and past a few
 * hundred coordinates the matrix no longer fits in the first levels of
 * cache. Here the matrix is cut into panels of EOM_CHOLESKY_BLOCK
 * columns. Each panel is factored by the column loops restricted to its
 * own columns (its updates from the columns before it have been applied
 * already); then the part of the matrix right of and below it, the
 * trailing matrix, takes the panel's whole update at once, A22 -= L21
 * L21^T, by tiles of 8 rows x 4 columns held in registers: each value
 * loaded from the panel serves four or eight multiply-adds instead of
 * one. This is LAPACK's dpotrf in structure (dpotrf2 on the panel, dsyrk
 * on the rest) with the kernel written for one core.
 *
 * The factor is left where LAPACK leaves it (the lower triangle of A,
 * column-major, leading dimension n), so dpocon and the solves read it;
 * the upper triangle of A is not written. info = j + 1 when the pivot of
 * column j (0-based) is not positive, the order of the leading minor
 * that fails, as dpotrf reports it. No FMA: the AVX2 clone and the
 * generic code round alike. This file includes no header of libeom, so
 * that bench/'s hand-coded chain compiles it too (the physical limit of
 * a Lagrangian route factors as the library does). */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "cholesky_blocked.h"

/* Columns per panel: a panel of n x 48 doubles stays in the second-level
 * cache to n = 800. Panels of 32, 48 and 64 factor n = 129 .. 800 within
 * 10 % of one another, 96 up to 20 % slower (docs/benchmarks.md section
 * 8); -DEOM_CHOLESKY_BLOCK=b builds another for measuring. */
#ifndef EOM_CHOLESKY_BLOCK
#define EOM_CHOLESKY_BLOCK 48
#endif

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) &&    \
    defined(__linux__) && !defined(__SANITIZE_THREAD__)
#define EOM_BLOCKED_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define EOM_BLOCKED_CLONES
#endif
/* The helpers are inlined into eom__potrf_blocked, so that each of its
 * clones has its own copy built for its target. */
#if defined(__GNUC__)
#define EOM_BLOCKED_INLINE static inline __attribute__((always_inline))
#else
#define EOM_BLOCKED_INLINE static
#endif

/* Column j of the panel P (m rows from the panel's diagonal, b columns,
 * leading dimension ld) updated by the panel's columns before it, then
 * scaled by its pivot: 0, or j + 1 at a non-positive pivot. */
EOM_BLOCKED_INLINE int panel_factor(size_t m, int b, double *P, size_t ld)
{
    size_t i;
    int j, k;
    for (j = 0; j < b; j++) {
        double *restrict cj = P + (size_t)j * ld;
        double d;
        for (k = 0; k + 4 <= j; k += 4) {
            const double *restrict c0 = P + (size_t)k * ld;
            const double *restrict c1 = c0 + ld, *restrict c2 = c1 + ld;
            const double *restrict c3 = c2 + ld;
            const double a0 = c0[j], a1 = c1[j], a2 = c2[j], a3 = c3[j];
            for (i = (size_t)j; i < m; i++)
                cj[i] -= (a0 * c0[i] + a1 * c1[i]) + (a2 * c2[i] + a3 * c3[i]);
        }
        for (; k < j; k++) {
            const double *restrict ck = P + (size_t)k * ld;
            const double a = ck[j];
            for (i = (size_t)j; i < m; i++)
                cj[i] -= a * ck[i];
        }
        d = cj[j];
        if (!(d > 0.0))
            return j + 1;
        d = sqrt(d);
        cj[j] = d;
        d = 1.0 / d;
        for (i = (size_t)j + 1; i < m; i++)
            cj[i] *= d;
    }
    return 0;
}

/* C[0..mr, 0..nr) -= A B^T over b terms for a tile at the edge (fewer
 * than 8 rows or 4 columns), or on the diagonal (lower: rows r >= c
 * only, when lower is set). A: rows of the panel at the tile's rows, B:
 * at its columns, both with leading dimension ld; C with ld too. */
EOM_BLOCKED_INLINE void tile_edge(size_t mr, size_t nr, int b, const double *A,
                      const double *B, double *C, size_t ld, int lower)
{
    double acc[8][4] = {{0.0}};
    size_t r, c;
    int k;
    for (k = 0; k < b; k++) {
        const double *a = A + (size_t)k * ld, *bb = B + (size_t)k * ld;
        for (c = 0; c < nr; c++)
            for (r = 0; r < mr; r++)
                acc[r][c] += a[r] * bb[c];
    }
    for (c = 0; c < nr; c++)
        for (r = lower ? c : 0; r < mr; r++)
            C[r + c * ld] -= acc[r][c];
}

#if defined(__GNUC__)
/* Four doubles in a vector register (two SSE registers in the generic
 * clone); loaded and stored through memcpy, unaligned. */
typedef double eom_v4 __attribute__((vector_size(32)));
#define V4_LOAD(v, p) memcpy(&(v), (p), sizeof(eom_v4))
#define V4_STORE(p, v) memcpy((p), &(v), sizeof(eom_v4))

/* A full 8 x 4 tile below the diagonal: C -= A B^T over b terms, the 32
 * sums in eight vector registers. */
EOM_BLOCKED_INLINE void tile_8x4(int b, const double *A, const double *B, double *C,
                     size_t ld)
{
    eom_v4 c00 = {0.0, 0.0, 0.0, 0.0}, c01 = c00, c10 = c00, c11 = c00;
    eom_v4 c20 = c00, c21 = c00, c30 = c00, c31 = c00, a0, a1, t;
    int k;
    for (k = 0; k < b; k++) {
        const double *a = A + (size_t)k * ld, *bb = B + (size_t)k * ld;
        eom_v4 b0 = {bb[0], bb[0], bb[0], bb[0]};
        eom_v4 b1 = {bb[1], bb[1], bb[1], bb[1]};
        eom_v4 b2 = {bb[2], bb[2], bb[2], bb[2]};
        eom_v4 b3 = {bb[3], bb[3], bb[3], bb[3]};
        V4_LOAD(a0, a);
        V4_LOAD(a1, a + 4);
        c00 += a0 * b0;
        c01 += a1 * b0;
        c10 += a0 * b1;
        c11 += a1 * b1;
        c20 += a0 * b2;
        c21 += a1 * b2;
        c30 += a0 * b3;
        c31 += a1 * b3;
    }
#define TILE_COLUMN(col, lo, hi)                                           \
    do {                                                                   \
        double *cc = C + (size_t)(col) * ld;                               \
        V4_LOAD(t, cc);                                                    \
        t -= lo;                                                           \
        V4_STORE(cc, t);                                                   \
        V4_LOAD(t, cc + 4);                                                \
        t -= hi;                                                           \
        V4_STORE(cc + 4, t);                                               \
    } while (0)
    TILE_COLUMN(0, c00, c01);
    TILE_COLUMN(1, c10, c11);
    TILE_COLUMN(2, c20, c21);
    TILE_COLUMN(3, c30, c31);
#undef TILE_COLUMN
}
#else
EOM_BLOCKED_INLINE void tile_8x4(int b, const double *A, const double *B, double *C,
                     size_t ld)
{
    tile_edge(8, 4, b, A, B, C, ld, 0);
}
#endif

/* The trailing matrix C (m x m, lower triangle, leading dimension ld)
 * -= L L^T, L m x b with leading dimension ld: by columns of 4, tiles of
 * 8 rows from the diagonal down. */
EOM_BLOCKED_INLINE void trailing_update(size_t m, int b, const double *L, double *C,
                            size_t ld)
{
    size_t i0, j0;
    for (j0 = 0; j0 < m; j0 += 4) {
        const size_t nr = m - j0 < 4 ? m - j0 : 4;
        double *cj = C + j0 * ld;
        /* the diagonal's 4 x 4 block, lower part */
        tile_edge(nr, nr, b, L + j0, L + j0, cj + j0, ld, 1);
        for (i0 = j0 + nr; i0 < m; i0 += 8) {
            const size_t mr = m - i0 < 8 ? m - i0 : 8;
            if (mr == 8 && nr == 4)
                tile_8x4(b, L + i0, L + j0, cj + i0, ld);
            else
                tile_edge(mr, nr, b, L + i0, L + j0, cj + i0, ld, 0);
        }
    }
}

EOM_BLOCKED_CLONES
int eom__potrf_blocked(int n, const double *M, double *A)
{
    const size_t N = (size_t)n;
    size_t j, kb;
    /* the lower triangle of M, column by column (in place: already) */
    for (j = 0; A != M && j < N; j++)
        memcpy(A + j * N + j, M + j * N + j, (N - j) * sizeof(double));
    for (kb = 0; kb < N; kb += EOM_CHOLESKY_BLOCK) {
        const int b = (int)(N - kb < EOM_CHOLESKY_BLOCK ? N - kb
                                                        : EOM_CHOLESKY_BLOCK);
        double *P = A + kb * N + kb;
        const int info = panel_factor(N - kb, b, P, N);
        if (info != 0)
            return (int)kb + info;
        if (kb + (size_t)b < N)
            trailing_update(N - kb - (size_t)b, b, P + b, P + (size_t)b * N + b,
                            N);
    }
    return 0;
}
