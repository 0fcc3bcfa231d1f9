/* cholesky_columns.c - the Cholesky factor and solve of mass matrices of
 * medium size (above the small, fully unrolled path of rhs.c, up to
 * EOM_COLUMN_CHOLESKY), by columns, and the solve with any factor.
 *
 * Debian's reference LAPACK factors these with reference BLAS kernels
 * whose call overhead and non-unit-stride loops cost three to four times
 * the instructions of the loops below (callgrind, factor and solve:
 * 286,000 against 86,000 at n = 50, 1.7 million against 0.39 million at
 * n = 100, with AVX2), and the factor was half of a compiled 50-link
 * chain's right-hand side. Both leave the factor in the lower triangle,
 * column-major, as LAPACK does, so dpocon reads either; the sums run in
 * another order than LAPACK's (the results differ from it in the last
 * bits). Larger matrices go to the blocked factor of cholesky_blocked.c,
 * whose tiles reuse what they load from the cache; the solve here serves
 * every size above the small path.
 *
 * The factor is left-looking: column j is updated by the earlier columns,
 * four at a time, with unit-stride loops over rows j .. n-1, which
 * vectorize; the solve's forward pass is axpys too, its backward pass
 * dot products along the factor's columns. */
#include <math.h>

#include "eom_internal.h"

/* The AVX2 clone as well as the generic code (GCC's function
 * multi-versioning), picked at load time; no FMA, so both round alike.
 * Not under ThreadSanitizer (as libtape's sweep.h says why). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) &&    \
    defined(__linux__) && !defined(__SANITIZE_THREAD__)
#define EOM_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define EOM_VECTOR_CLONES
#endif

EOM_VECTOR_CLONES
int eom__potrf_columns(int n, const double *M, double *A)
{
    int i, j, k;
    for (j = 0; j < n; j++) {
        double *restrict cj = A + (size_t)j * (size_t)n;
        const double *mj = M + (size_t)j * (size_t)n;
        double d;
        for (i = j; i < n; i++)
            cj[i] = mj[i];
        /* four earlier columns at a time: column j is read and written
         * once for four updates */
        for (k = 0; k + 4 <= j; k += 4) {
            const double *restrict c0 = A + (size_t)k * (size_t)n;
            const double *restrict c1 = c0 + n, *restrict c2 = c1 + n;
            const double *restrict c3 = c2 + n;
            const double a0 = c0[j], a1 = c1[j], a2 = c2[j], a3 = c3[j];
            for (i = j; i < n; i++)
                cj[i] -= (a0 * c0[i] + a1 * c1[i]) + (a2 * c2[i] + a3 * c3[i]);
        }
        for (; k < j; k++) {
            const double *restrict ck = A + (size_t)k * (size_t)n;
            const double a = ck[j];
            for (i = j; i < n; i++)
                cj[i] -= a * ck[i];
        }
        d = cj[j];
        if (!(d > 0.0))
            return j + 1;
        d = sqrt(d);
        cj[j] = d;
        for (i = j + 1; i < n; i++)
            cj[i] /= d;
    }
    return 0;
}

EOM_VECTOR_CLONES
void eom__potrs_columns(int n, int nrhs, const double *A, double *B)
{
    int c, i, k;
    for (c = 0; c < nrhs; c++) {
        double *restrict b = B + (size_t)c * (size_t)n;
        /* L y = b: y_k, then its column taken from the rows below */
        for (k = 0; k < n; k++) {
            const double *restrict ck = A + (size_t)k * (size_t)n;
            const double y = b[k] / ck[k];
            b[k] = y;
            for (i = k + 1; i < n; i++)
                b[i] -= y * ck[i];
        }
        /* L^T x = y: row i of L^T is column i of L */
        for (i = n; i-- > 0;) {
            const double *restrict ci = A + (size_t)i * (size_t)n;
            double t = b[i];
            for (k = i + 1; k < n; k++)
                t -= ci[k] * b[k];
            b[i] = t / ci[i];
        }
    }
}
