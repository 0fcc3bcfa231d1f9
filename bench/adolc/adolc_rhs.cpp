/* adolc_rhs.cpp - the rigid pendulum chain's right-hand side with ADOL-C
 * (see adolc_rhs.h): the Lagrangian recorded once with adoubles, two ways
 * of getting its second derivatives from the tape, and the Cholesky solve.
 *
 * Index conventions: x = (q, qd), independents 0 .. n-1 are the angles and
 * n .. 2n-1 the rates, in the order of the <<= assignments. Everything an
 * evaluation writes is allocated in adolc_rhs_new; the three-index arrays
 * ADOL-C's vector sweeps take are pointer tables over one contiguous
 * block each. ADOL-C reports errors by throwing; every entry point catches
 * them so that nothing crosses the C interface. */
#include <climits>
#include <cmath>
#include <cstdlib>
#include <vector>

#include <adolc/adouble.h>
#include <adolc/drivers/drivers.h>
#include <adolc/interfaces.h>
#include <adolc/taping.h>

#include "adolc_rhs.h"

/* LAPACK (Fortran interface; gfortran passes string lengths last). */
extern "C" {
void dpotrf_(const char *uplo, const int *n, double *a, const int *lda,
             int *info, size_t uplo_len);
void dpotrs_(const char *uplo, const int *n, const int *nrhs,
             const double *a, const int *lda, double *b, const int *ldb,
             int *info, size_t uplo_len);
}

struct adolc_rhs {
    int n;          /* links; the tape has 2n independents, 1 dependent */
    int driver;     /* ADOLC_DRIVER_* */
    short tag;      /* ADOL-C tape */
    double *x;      /* [2n] copy of the state (hessian() takes non-const) */
    /* ADOLC_DRIVER_VECTOR */
    double ***X;    /* [2n][n][1] seeds: X[n + k][k][0] = 1, else 0 */
    double ***Y;    /* [1][n][1] first-order Taylor coefficients of L */
    double **U;     /* [1][2] adjoint weights {1, 0}: L itself */
    double ***Z;    /* [n][2n][2] Z[k][i][0] = dL/dx_i,
                       Z[k][i][1] = d2L/(dx_i dqd_k) */
    /* ADOLC_DRIVER_HESSIAN */
    double **H;     /* [2n][2n] Hessian, lower triangle filled */
    double *grad;   /* [2n] gradient */
    /* the solve */
    double *A;      /* [n * n] M, then its Cholesky factor */
    double *b;      /* [n] dL/dq - h, then qdd */
};

/* ---- buffers ------------------------------------------------------------ */

/* An [a][b] array: a row table over one zeroed block (a, b >= 1). */
static double **alloc2(size_t a, size_t b)
{
    double **p = static_cast<double **>(std::malloc(a * sizeof *p));
    double *v = static_cast<double *>(std::calloc(a * b, sizeof *v));
    if (!p || !v) {
        std::free(p);
        std::free(v);
        return nullptr;
    }
    for (size_t i = 0; i < a; i++)
        p[i] = v + i * b;
    return p;
}

static void free2(double **p)
{
    if (p)
        std::free(p[0]);
    std::free(p);
}

/* An [a][b][c] array: two pointer tables over one zeroed block. */
static double ***alloc3(size_t a, size_t b, size_t c)
{
    double ***p = static_cast<double ***>(std::malloc(a * sizeof *p));
    double **rows = alloc2(a * b, c);
    if (!p || !rows) {
        std::free(p);
        free2(rows);
        return nullptr;
    }
    for (size_t i = 0; i < a; i++)
        p[i] = rows + i * b;
    return p;
}

static void free3(double ***p)
{
    if (p)
        free2(p[0]);
    std::free(p);
}

static void release(adolc_rhs *a)
{
    std::free(a->x);
    free3(a->X);
    free3(a->Y);
    free2(a->U);
    free3(a->Z);
    free2(a->H);
    std::free(a->grad);
    std::free(a->A);
    std::free(a->b);
    std::free(a);
}

/* ---- the Lagrangian ------------------------------------------------------ */

/* Record L(q, qd) at x0 between trace_on and trace_off. The root joint
 * velocity P is advanced link by link; for the first link P = 0, and the
 * terms that vanish with it are left out rather than recorded as
 * operations on zero (libtape folds them away when it records).
 *
 * P is advanced with p = p - a * b, not p -= a * b: ADOL-C records the
 * latter as one fused operation (eq_min_prod, eq_plus_prod for +=), and
 * ADOL-C 2.7.2's hos_ov_reverse gets the second-order adjoints wrong when
 * such an operation overwrites a value that was used before, as P is:
 * the Hessian columns of the vector driver (and of hess_mat) were then
 * off by O(1) with two or more directions. test_adolc_rhs catches it. */
static void record_lagrangian(int n, const double *mass, const double *len,
                              double g, const double *x0)
{
    std::vector<adouble> x(2 * static_cast<size_t>(n));
    adouble T, Vg, y, px, py;
    double out;
    for (int i = 0; i < 2 * n; i++)
        x[i] <<= x0[i];
    for (int j = 0; j < n; j++) {
        const adouble &th = x[j], &thd = x[n + j];
        adouble s = sin(th), c = cos(th);
        adouble Lthd = len[j] * thd;
        adouble t = Lthd * Lthd / 6.0;
        if (j > 0) {
            adouble Sc = py * c - px * s; /* P . n_j */
            t += 0.5 * (px * px + py * py) + 0.5 * Lthd * Sc;
            T += mass[j] * t;
            Vg += mass[j] * (y + 0.5 * len[j] * s);
            y += len[j] * s;
            px = px - Lthd * s;
            py = py + Lthd * c;
        } else {
            T = mass[j] * t;
            Vg = mass[j] * (0.5 * len[j] * s);
            y = len[j] * s;
            px = -(Lthd * s);
            py = Lthd * c;
        }
    }
    adouble lag = T - g * Vg;
    lag >>= out;
}

/* Record the tape of a (tag, n). The reverse sweeps read the Taylor
 * coefficients the forward sweep keeps: 1 + n values per overwritten
 * location with n directions (the vector driver), 2 in hessian()'s scalar
 * sweeps. ADOL-C keeps them in a buffer of TBUFSIZE values by default,
 * enough for the vector driver up to about 115 links, and spills them to
 * a file in the current directory when the buffer fills (even when the
 * last record just fits, hence one record of slack). A tape that needs
 * more is recorded again with a buffer that holds them all. The tape
 * itself stays in memory up to about 6700 links (ADOL-C's location
 * buffer). Returns 0 or -1, with no tape left behind on failure. */
static int record(adolc_rhs *a, const double *m, const double *L, double g)
{
    const size_t per = a->driver == ADOLC_DRIVER_VECTOR
                           ? static_cast<size_t>(a->n) + 1 : 2;
    size_t st[STAT_SIZE];
    try {
        /* a generic point: the tape has no branches, so any point does */
        for (int i = 0; i < 2 * a->n; i++)
            a->x[i] = 0.1 + 0.01 * i;
        trace_on(a->tag);
        record_lagrangian(a->n, m, L, g, a->x);
        trace_off();
        tapestats(a->tag, st);
        if ((st[TAY_STACK_SIZE] + 1) * per > st[TAY_BUFFER_SIZE]) {
            const size_t need = (st[TAY_STACK_SIZE] + 1) * per;
            removeTape(a->tag, ADOLC_REMOVE_COMPLETELY);
            if (need > UINT_MAX)
                return -1;
            trace_on(a->tag, 0, static_cast<uint>(st[OP_BUFFER_SIZE]),
                     static_cast<uint>(st[LOC_BUFFER_SIZE]),
                     static_cast<uint>(st[VAL_BUFFER_SIZE]),
                     static_cast<uint>(need));
            record_lagrangian(a->n, m, L, g, a->x);
            trace_off();
        }
    } catch (...) {
        try {
            if (isTaping())
                trace_off();
            removeTape(a->tag, ADOLC_REMOVE_COMPLETELY);
        } catch (...) {
        }
        return -1;
    }
    return 0;
}

/* ---- construction ------------------------------------------------------- */

int adolc_rhs_new(adolc_rhs **out, int nlinks, const double *m,
                  const double *L, double g, int driver, short tag)
{
    adolc_rhs *a;
    size_t n, n2;
    if (!out)
        return -1;
    *out = nullptr;
    if (nlinks < 1 || nlinks > 10000 || !m || !L ||
        (driver != ADOLC_DRIVER_VECTOR && driver != ADOLC_DRIVER_HESSIAN))
        return -1;
    a = static_cast<adolc_rhs *>(std::calloc(1, sizeof *a));
    if (!a)
        return -1;
    a->n = nlinks;
    a->driver = driver;
    a->tag = tag;
    n = static_cast<size_t>(nlinks);
    n2 = 2 * n;
    a->x = static_cast<double *>(std::calloc(n2, sizeof(double)));
    a->A = static_cast<double *>(std::calloc(n * n, sizeof(double)));
    a->b = static_cast<double *>(std::calloc(n, sizeof(double)));
    if (driver == ADOLC_DRIVER_VECTOR) {
        a->X = alloc3(n2, n, 1);
        a->Y = alloc3(1, n, 1);
        a->U = alloc2(1, 2);
        a->Z = alloc3(n, n2, 2);
    } else {
        a->H = alloc2(n2, n2);
        a->grad = static_cast<double *>(std::calloc(n2, sizeof(double)));
    }
    if (!a->x || !a->A || !a->b ||
        (driver == ADOLC_DRIVER_VECTOR && (!a->X || !a->Y || !a->U || !a->Z)) ||
        (driver == ADOLC_DRIVER_HESSIAN && (!a->H || !a->grad))) {
        release(a);
        return -1;
    }
    if (driver == ADOLC_DRIVER_VECTOR) {
        for (size_t k = 0; k < n; k++)
            a->X[n + k][k][0] = 1.0;
        a->U[0][0] = 1.0;
    }
    if (record(a, m, L, g) != 0) {
        release(a);
        return -1;
    }
    *out = a;
    return 0;
}

void adolc_rhs_free(adolc_rhs **ap)
{
    if (!ap || !*ap)
        return;
    try {
        removeTape((*ap)->tag, ADOLC_REMOVE_COMPLETELY);
    } catch (...) {
    }
    release(*ap);
    *ap = nullptr;
}

/* ---- evaluation ---------------------------------------------------------- */

/* dL/dq into b, M into A and b -= h, from one vector forward sweep over
 * the n unit directions on qd and one reverse sweep over all of them.
 * Direction k gives the column d2L/(dx dqd_k): its qd rows are column k
 * of M, and its q rows are row k of d2L/(dq dqd), which by symmetry is
 * column k of d2L/(dqd dq), so h_i = sum_k Z[i][k][1] qd_k. */
static int blocks_vector(adolc_rhs *a, const double *x)
{
    const int n = a->n, n2 = 2 * n;
    double lag;
    if (hov_wk_forward(a->tag, 1, n2, 1, 2, n, x, a->X, &lag, a->Y) < 0 ||
        hos_ov_reverse(a->tag, 1, n2, 1, n, a->U, a->Z) < 0)
        return -1;
    for (int i = 0; i < n; i++) {
        double r = a->Z[0][i][0];
        for (int k = 0; k < n; k++) {
            a->A[i * n + k] = a->Z[k][n + i][1];
            r -= a->Z[i][k][1] * x[n + k];
        }
        a->b[i] = r;
    }
    return 0;
}

/* The same from the full Hessian (lower triangle: H[r][c] with c <= r)
 * and the gradient. */
static int blocks_hessian(adolc_rhs *a, const double *x)
{
    const int n = a->n, n2 = 2 * n;
    for (int i = 0; i < n2; i++)
        a->x[i] = x[i];
    if (hessian(a->tag, n2, a->x, a->H) < 0 ||
        gradient(a->tag, n2, a->x, a->grad) < 0)
        return -1;
    for (int i = 0; i < n; i++) {
        double r = a->grad[i];
        for (int k = 0; k < n; k++) {
            a->A[i * n + k] = i >= k ? a->H[n + i][n + k] : a->H[n + k][n + i];
            r -= a->H[n + i][k] * x[n + k]; /* row n + i > k: filled */
        }
        a->b[i] = r;
    }
    return 0;
}

int adolc_rhs_eval(adolc_rhs *a, const double *x, double *qdd, double *M)
{
    int n, one = 1, info = 0, rc;
    if (!a || !x || !qdd)
        return -1;
    n = a->n;
    try {
        rc = a->driver == ADOLC_DRIVER_VECTOR ? blocks_vector(a, x)
                                              : blocks_hessian(a, x);
    } catch (...) {
        return -1;
    }
    if (rc != 0)
        return -1;
    if (M)
        for (int i = 0; i < n * n; i++)
            M[i] = a->A[i];
    /* M is symmetric, so the row-major array is its own transpose */
    dpotrf_("L", &n, a->A, &n, &info, 1);
    if (info != 0)
        return -1;
    dpotrs_("L", &n, &one, a->A, &n, a->b, &n, &info, 1);
    if (info != 0)
        return -1;
    rc = 0;
    for (int i = 0; i < n; i++) {
        qdd[i] = a->b[i];
        if (!std::isfinite(qdd[i]))
            rc = -1;
    }
    return rc;
}
