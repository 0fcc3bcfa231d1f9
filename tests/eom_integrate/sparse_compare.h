/* sparse_compare.h - a sparse matrix (compressed columns) against the
 * dense matrix it stands for, for test_sparse.c (ida's iteration matrix)
 * and test_sparse_bdf.c (bdf's state Jacobian). Included, not linked, so
 * that its checks count in the including test's check.h counters. */
#ifndef TEST_SPARSE_COMPARE_H
#define TEST_SPARSE_COMPARE_H

#include <math.h>
#include <stdint.h>
#include <stddef.h>

#include "check.h"

/* What the comparisons found so far; start from zeros. */
typedef struct sparse_diff {
    int missing;   /* dense non-zeros outside the pattern */
    int off;       /* entries beyond 1e-14 of their row */
    double worst;  /* largest difference relative to its row */
    long inexact;  /* entries of rows lo .. hi - 1 not equal bit for bit */
} sparse_diff;

/* D (N x N, column-major) against the sparse (colptr, rowind, data);
 * in[c N + r] marks the pattern, rowmax is scratch [N]. Each finding is
 * reported (the first five of a kind) under label. */
static void sparse_compare(const char *label, int N, const double *D,
                           const char *in, const int64_t *colptr,
                           const int64_t *rowind, const double *data,
                           double *rowmax, int lo, int hi, sparse_diff *f)
{
    int c, r;
    size_t e;
    for (r = 0; r < N; r++)
        rowmax[r] = 0.0;
    for (c = 0; c < N; c++)
        for (r = 0; r < N; r++) {
            const double v = D[(size_t)c * N + r];
            rowmax[r] = fmax(rowmax[r], fabs(v));
            if (v != 0.0 && !in[(size_t)c * N + r] && f->missing++ < 5)
                CHECK_FAIL_("%s: dense entry (%d, %d) = %g is not in "
                            "the pattern", label, r, c, v);
        }
    for (c = 0; c < N; c++)
        for (e = (size_t)colptr[c]; e < (size_t)colptr[c + 1]; e++) {
            const int row = (int)rowind[e];
            const double d = D[(size_t)c * N + row];
            const double scale = fmax(fabs(d), rowmax[row]);
            const double rel = scale > 0.0 ? fabs(data[e] - d) / scale
                                           : fabs(data[e]);
            if (fabs(data[e] - d) > 1e-14 * fmax(fabs(d), rowmax[row] * 1e-2) &&
                f->off++ < 5)
                CHECK_FAIL_("%s: entry (%d, %d): sparse %.17g, dense "
                            "%.17g", label, row, c, data[e], d);
            f->worst = fmax(f->worst, rel);
            if (row >= lo && row < hi && data[e] != d)
                f->inexact++;
        }
}

#endif
