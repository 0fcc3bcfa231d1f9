/* lin_props.h - properties every eom_linear result must have, checked
 * against quantities the test computes itself from the public API (so a
 * transposed N, Z or C in linearize.c shows up). Header-only: the CHECK
 * counters of check.h are per translation unit. Systems up to LP_NMAX
 * coordinates. Include after check.h. */
#ifndef LIN_PROPS_H
#define LIN_PROPS_H

#include <math.h>
#include <string.h>

#include "eom/eom.h"

#define LP_NMAX 8

static double lp_maxabs(const double *a, int n)
{
    double r = 0.0;
    int i;
    for (i = 0; i < n; i++)
        r = fmax(r, fabs(a[i]));
    return r;
}

/* (A^T B)_{ij} for A n x p, B n x p' (row-major), entry i, j. */
static double lp_tdot(const double *A, int pa, int i, const double *B, int pb,
                      int j, int n)
{
    double v = 0.0;
    int k;
    for (k = 0; k < n; k++)
        v += A[k * pa + i] * B[k * pb + j];
    return v;
}

/* N orthonormal and in null(C); M the library's mass matrix; Xr = N^T X
 * N; omega ascending; every mode v in range(N), C v = 0, v^T M v = 1 and
 * N^T (K - omega|omega| M) v = 0. tol is relative. */
static void lp_check(eom_system *s, const double *q, const eom_linear *lin,
                     double tol)
{
    const int n = lin->n, nr = lin->nr, m = eom_system_nconstraints(s);
    double x[2 * LP_NMAX], M[LP_NMAX * LP_NMAX], C[2 * LP_NMAX * LP_NMAX];
    double XN[LP_NMAX * LP_NMAX], v[LP_NMAX], Kv[LP_NMAX], Mv[LP_NMAX];
    const double *X[3], *Xr[3];
    double sK, sM;
    int i, j, k, t;

    CHECK_INT(n, eom_system_ncoords(s));
    if (n > LP_NMAX || nr < 0 || nr > n || m > 2 * LP_NMAX) {
        CHECK(!"lp_check: sizes out of range");
        return;
    }
    memcpy(x, q, (size_t)n * sizeof(double));
    memset(x + n, 0, (size_t)n * sizeof(double));
    CHECK_INT(eom_mass_matrix(s, x, M), EOM_OK);
    for (i = 0; i < n * n; i++)
        CHECK_NEAR(lin->M[i], M[i], tol * lp_maxabs(M, n * n));
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++) {
            CHECK(lin->K[i * n + j] == lin->K[j * n + i]);
            CHECK(lin->D[i * n + j] == lin->D[j * n + i]);
        }
    /* N: orthonormal columns, in null(C) */
    for (i = 0; i < nr; i++)
        for (j = 0; j < nr; j++)
            CHECK_NEAR(lp_tdot(lin->N, nr, i, lin->N, nr, j, n),
                       i == j ? 1.0 : 0.0, tol);
    if (m > 0) {
        CHECK_INT(eom_constraint_jacobian(s, x, C, NULL), EOM_OK);
        for (k = 0; k < m; k++)
            for (j = 0; j < nr; j++) {
                double c = 0.0;
                for (i = 0; i < n; i++)
                    c += C[k * n + i] * lin->N[i * nr + j];
                CHECK_NEAR(c, 0.0, tol * fmax(1.0, lp_maxabs(C, m * n)));
            }
    }
    /* reduced matrices */
    X[0] = lin->M, X[1] = lin->K, X[2] = lin->D;
    Xr[0] = lin->Mr, Xr[1] = lin->Kr, Xr[2] = lin->Dr;
    for (t = 0; t < 3; t++) {
        const double sc = fmax(1.0, lp_maxabs(X[t], n * n));
        for (i = 0; i < n; i++)
            for (j = 0; j < nr; j++) {
                double c = 0.0;
                for (k = 0; k < n; k++)
                    c += X[t][i * n + k] * lin->N[k * nr + j];
                XN[i * nr + j] = c;
            }
        for (i = 0; i < nr; i++)
            for (j = 0; j < nr; j++)
                CHECK_NEAR(Xr[t][i * nr + j],
                           lp_tdot(lin->N, nr, i, XN, nr, j, n), tol * sc);
    }
    /* frequencies and modes */
    sK = fmax(1.0, lp_maxabs(lin->K, n * n));
    sM = fmax(1.0, lp_maxabs(lin->M, n * n));
    for (i = 0; i < nr; i++) {
        const double w = lin->omega[i], e = w * fabs(w);
        CHECK(isfinite(w));
        if (i > 0)
            CHECK(lin->omega[i - 1] <= w);
        for (k = 0; k < n; k++)
            v[k] = lin->modes[k * nr + i];
        for (k = 0; k < n; k++) {
            Kv[k] = Mv[k] = 0.0;
            for (j = 0; j < n; j++) {
                Kv[k] += lin->K[k * n + j] * v[j];
                Mv[k] += lin->M[k * n + j] * v[j];
            }
        }
        {
            double vMv = 0.0;
            for (k = 0; k < n; k++)
                vMv += v[k] * Mv[k];
            CHECK_NEAR(vMv, 1.0, tol);
        }
        for (j = 0; j < nr; j++) {
            double a = 0.0, b = 0.0;
            for (k = 0; k < n; k++) {
                a += lin->N[k * nr + j] * Kv[k];
                b += lin->N[k * nr + j] * Mv[k];
            }
            CHECK_NEAR(a - e * b, 0.0, tol * (sK + fabs(e) * sM));
        }
        /* v = N N^T v */
        for (k = 0; k < n; k++) {
            double p = 0.0;
            for (j = 0; j < nr; j++)
                p += lin->N[k * nr + j] * lp_tdot(lin->N, nr, j, v, 1, 0, n);
            CHECK_NEAR(p, v[k], tol * fmax(1.0, lp_maxabs(v, n)));
        }
        if (m > 0)
            for (k = 0; k < m; k++) {
                double c = 0.0;
                for (j = 0; j < n; j++)
                    c += C[k * n + j] * v[j];
                CHECK_NEAR(c, 0.0, tol * fmax(1.0, lp_maxabs(C, m * n)));
            }
    }
}

#endif
