/* chain_plain.c - the chain of the element library typed in plain C (see
 * chain_plain.h): the Lagrangian in doubles, the unit of cost in the
 * benchmarks, and for rigid links the equations of motion in closed form,
 * the hand-coded limit of a Lagrangian route. */
#include "chain_plain.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double pi = 3.14159265358979323846;

void dpotrf_(const char *uplo, const int *n, double *a, const int *lda,
             int *info, size_t uplo_len);
void dpotrs_(const char *uplo, const int *n, const int *nrhs,
             const double *a, const int *lda, double *b, const int *ldb,
             int *info, size_t uplo_len);

/* libeom's blocked factor (libeom/src/cholesky_blocked.c, compiled into
 * the bench: it includes no header of libeom's); in place when A is M. */
int eom__potrf_blocked(int n, const double *M, double *A);

/* The same split as libeom's (libeom/src/rhs.c, cholesky_columns.c,
 * cholesky_blocked.c): up to SMALL_CHOLESKY the Cholesky is plain loops,
 * up to COLUMN_CHOLESKY loops by columns, above it the blocked factor
 * and the column loops' solve, so that "times the hand-coded
 * right-hand side" means times the physical limit of a Lagrangian route,
 * not times LAPACK's call overhead. */
#define SMALL_CHOLESKY 16
#define COLUMN_CHOLESKY 128

/* L L^T = A (column-major lower triangle, n x n), then solve for b. */
static int small_cholesky_solve(int n, double *A, double *b)
{
    int i, j, k;
    for (j = 0; j < n; j++) {
        double d = A[j + j * n];
        for (k = 0; k < j; k++)
            d -= A[j + k * n] * A[j + k * n];
        if (!(d > 0.0))
            return j + 1;
        d = sqrt(d);
        A[j + j * n] = d;
        for (i = j + 1; i < n; i++) {
            double t = A[i + j * n];
            for (k = 0; k < j; k++)
                t -= A[i + k * n] * A[j + k * n];
            A[i + j * n] = t / d;
        }
    }
    for (i = 0; i < n; i++) { /* L y = b */
        double t = b[i];
        for (k = 0; k < i; k++)
            t -= A[i + k * n] * b[k];
        b[i] = t / A[i + i * n];
    }
    for (i = n - 1; i >= 0; i--) { /* L^T x = y */
        double t = b[i];
        for (k = i + 1; k < n; k++)
            t -= A[k + i * n] * b[k];
        b[i] = t / A[i + i * n];
    }
    return 0;
}

/* As libeom's medium path (libeom/src/cholesky_columns.c, typed again
 * here: the bench uses public headers only): the factor left-looking by
 * unit-stride column updates, the solve by columns, the AVX2 clone
 * beside the generic code. With factored set, A holds the factor
 * already (the blocked one) and only the solve runs. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) &&    \
    defined(__linux__) && !defined(__SANITIZE_THREAD__)
__attribute__((target_clones("avx2", "default")))
#endif
static int column_cholesky_solve(int n, double *A, double *b, int factored)
{
    int i, j, k;
    for (j = factored ? n : 0; j < n; j++) {
        double *restrict cj = A + (size_t)j * (size_t)n, d;
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
    for (k = 0; k < n; k++) { /* L y = b */
        const double *restrict ck = A + (size_t)k * (size_t)n;
        const double y = b[k] / ck[k];
        b[k] = y;
        for (i = k + 1; i < n; i++)
            b[i] -= y * ck[i];
    }
    for (i = n - 1; i >= 0; i--) { /* L^T x = y */
        const double *restrict ci = A + (size_t)i * (size_t)n;
        double t = b[i];
        for (k = i + 1; k < n; k++)
            t -= ci[k] * b[k];
        b[i] = t / ci[i];
    }
    return 0;
}

/* The modes of a link enter through these sums (docs/elements.md). */
double chain_plain_L(const chain_plain *c, const double *x)
{
    const int N = c->links, K = c->modes, n = N * (1 + K);
    double px = 0.0, py = 0.0, y = 0.0, T = 0.0, Vg = 0.0, Vs = 0.0;
    int j, i;
    for (j = 0; j < N; j++) {
        const double th = x[j], thd = x[n + j], m = c->m[j], L = c->L[j];
        const double s = sin(th), co = cos(th);
        const double Sc = py * co - px * s, Lthd = L * thd;
        const double *q = x + N + j * K, *qd = x + n + N + j * K;
        T += m * (0.5 * (px * px + py * py) + 0.5 * Lthd * Sc +
                  Lthd * Lthd / 6.0);
        Vg += m * (y + 0.5 * L * s);
        if (K > 0) {
            const double Ss = px * co + py * s;
            double bq = 0.0, bqd = 0.0, aqd = 0.0, qq = 0.0, qdqd = 0.0,
                   strain = 0.0;
            for (i = 1; i <= K; i++) {
                const double b = i % 2 ? 2.0 / (i * pi) : 0.0;
                const double a = (i % 2 ? 1.0 : -1.0) / (i * pi);
                const double ip = i * pi;
                bq += b * q[i - 1];
                bqd += b * qd[i - 1];
                aqd += a * qd[i - 1];
                qq += q[i - 1] * q[i - 1];
                qdqd += qd[i - 1] * qd[i - 1];
                strain += ip * ip * ip * ip / 4.0 * q[i - 1] * q[i - 1];
            }
            T += m * (Sc * bqd - thd * Ss * bq + Lthd * aqd +
                      0.25 * thd * thd * qq + 0.25 * qdqd);
            Vg += m * co * bq;
            Vs += c->EI[j] / (L * L * L) * strain;
        }
        px -= Lthd * s;
        py += Lthd * co;
        y += L * s;
    }
    return T - c->g * Vg - Vs;
}

int chain_plain_hand_new(chain_hand **out, const chain_plain *c)
{
    const int N = c->links;
    chain_hand *h;
    int i, j, k;
    *out = NULL;
    if (c->modes != 0)
        return -1;
    h = calloc(1, sizeof *h);
    if (!h)
        return -1;
    h->N = N;
    h->g = c->g;
    h->a = calloc((size_t)N * (size_t)N, sizeof(double));
    h->cg = calloc((size_t)N, sizeof(double));
    h->M = calloc((size_t)N * (size_t)N, sizeof(double));
    h->sc = calloc(2 * (size_t)N, sizeof(double));
    if (!h->a || !h->cg || !h->M || !h->sc) {
        chain_plain_hand_free(&h);
        return -1;
    }
    /* a_ij: the mass beyond the later joint carried at full speed, the
     * later rod at half (its centre), the rod itself at L^2/3 */
    for (i = 0; i < N; i++) {
        double tail = 0.0;
        for (k = i + 1; k < N; k++)
            tail += c->m[k];
        h->cg[i] = c->L[i] * (c->m[i] / 2.0 + tail);
        for (j = i; j < N; j++) {
            double tj = 0.0, a;
            for (k = j + 1; k < N; k++)
                tj += c->m[k];
            if (i == j)
                a = c->m[i] * c->L[i] * c->L[i] / 3.0 +
                    c->L[i] * c->L[i] * tail;
            else
                a = c->L[i] * c->L[j] * (c->m[j] / 2.0 + tj);
            h->a[i * N + j] = h->a[j * N + i] = a;
        }
    }
    *out = h;
    return 0;
}

void chain_plain_hand_free(chain_hand **h)
{
    if (!h || !*h)
        return;
    free((*h)->a);
    free((*h)->cg);
    free((*h)->M);
    free((*h)->sc);
    free(*h);
    *h = NULL;
}

/* sum_j a_ij [cos(th_i - th_j) thdd_j + sin(th_i - th_j) thd_j^2]
 *     + g c_i cos th_i = 0 */
int chain_plain_hand_rhs(chain_hand *h, const double *x, double *qdd)
{
    const int N = h->N;
    double *s = h->sc, *co = h->sc + N;
    int i, j;
    for (i = 0; i < N; i++) {
        s[i] = sin(x[i]);
        co[i] = cos(x[i]);
    }
    for (i = 0; i < N; i++) {
        double f = -h->g * h->cg[i] * co[i];
        for (j = 0; j < N; j++) {
            const double aij = h->a[i * N + j];
            const double thd = x[N + j];
            h->M[i * N + j] = aij * (co[i] * co[j] + s[i] * s[j]);
            f -= aij * (s[i] * co[j] - co[i] * s[j]) * thd * thd;
        }
        qdd[i] = f;
    }
    return chain_plain_solve(N, h->M, qdd);
}

int chain_plain_solve(int n, double *M, double *b)
{
    if (n <= SMALL_CHOLESKY)
        return small_cholesky_solve(n, M, b) == 0 ? 0 : -1;
    if (n <= COLUMN_CHOLESKY)
        return column_cholesky_solve(n, M, b, 0) == 0 ? 0 : -1;
    return chain_plain_solve_by(CHAIN_SOLVE_BLOCKED, n, M, b);
}

int chain_plain_solve_by(int route, int n, double *M, double *b)
{
    int info = 0, one = 1;
    if (route == CHAIN_SOLVE_COLUMNS)
        return column_cholesky_solve(n, M, b, 0) == 0 ? 0 : -1;
    if (route == CHAIN_SOLVE_BLOCKED)
        return eom__potrf_blocked(n, M, M) == 0 &&
                       column_cholesky_solve(n, M, b, 1) == 0
                   ? 0
                   : -1;
    dpotrf_("L", &n, M, &n, &info, 1);
    if (info == 0)
        dpotrs_("L", &n, &one, M, &n, b, &n, &info, 1);
    return info == 0 ? 0 : -1;
}
