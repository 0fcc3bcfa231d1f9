/* test_adolc_rhs.c - the ADOL-C right-hand side (adolc_rhs.h) agrees with
 * the exact equations of the rigid pendulum chain and with libeom's chain
 * element, so that the benchmark times methods that compute the same
 * thing.
 *
 * For N = 1, 2, 5, 10 links of unequal masses and lengths, at random
 * states, both ADOL-C drivers must give, to 1e-12 relative (largest
 * difference over largest reference entry):
 *   - M equal to the closed form M_ij = a_ij cos(th_i - th_j),
 *       a_ii = m_i L_i^2 / 3 + L_i^2 sum_{k>i} m_k,
 *       a_ij = L_i L_j (m_j / 2 + sum_{k>j} m_k)   (i < j);
 *   - qdd equal to the solution of the hand-derived equations
 *       sum_j M_ij qdd_j = -sum_j a_ij sin(th_i - th_j) thd_j^2
 *                          - g c_i cos th_i,
 *       c_i = L_i (m_i / 2 + sum_{k>i} m_k),
 *     solved here by a Cholesky factorization of our own (not LAPACK);
 *   - qdd equal to eom_rhs of a model built with eom_chain_add.
 * The equations follow from T = 1/2 sum_ij a_ij cos(th_i - th_j) thd_i
 * thd_j and V = g sum_i c_i sin th_i: d/dt dT/dthd_i - dT/dth_i gives
 * sum_j a_ij [cos(th_i - th_j) qdd_j + sin(th_i - th_j) thd_j^2].
 *
 * A chain of 120 links checks the same at one state: its Taylor
 * coefficients overflow ADOL-C's default buffer, so adolc_rhs records the
 * tape with a larger one, and no ADOL-C file may appear in the current
 * directory. Its M is far worse conditioned (1-norm condition about 3e5
 * against 2e3 for 10 links, from eom_condition), and three Cholesky
 * solves of it differ by about 1e-12 relative, so qdd is held to 1e-10
 * there. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "adolc_rhs.h"
#include "check.h"
#include "eom/chain.h"
#include "support_rng.h"

static const double pi = 3.14159265358979323846;

/* The coefficients a (n x n, symmetric) and c (n) of the chain. */
static void chain_coeffs(int n, const double *m, const double *L, double *a,
                         double *c)
{
    int i, j, k;
    for (i = 0; i < n; i++) {
        double below = 0.0; /* sum_{k>i} m_k */
        for (k = i + 1; k < n; k++)
            below += m[k];
        a[i * n + i] = m[i] * L[i] * L[i] / 3.0 + L[i] * L[i] * below;
        c[i] = L[i] * (m[i] / 2.0 + below);
        for (j = i + 1; j < n; j++) {
            double below_j = 0.0;
            for (k = j + 1; k < n; k++)
                below_j += m[k];
            a[i * n + j] = a[j * n + i] = L[i] * L[j] * (m[j] / 2.0 + below_j);
        }
    }
}

/* Closed-form M and the hand-derived qdd at x = (q, qd); work holds
 * n * n + n values. */
static void hand_eom(int n, const double *a, const double *c, double g,
                     const double *x, double *M, double *qdd, double *work)
{
    double *Lf = work, *r = work + n * n;
    int i, j, k;
    for (i = 0; i < n; i++) {
        r[i] = -g * c[i] * cos(x[i]);
        for (j = 0; j < n; j++) {
            M[i * n + j] = a[i * n + j] * cos(x[i] - x[j]);
            r[i] -= a[i * n + j] * sin(x[i] - x[j]) * x[n + j] * x[n + j];
            Lf[i * n + j] = 0.0;
        }
    }
    /* M = Lf Lf^T, then two triangular solves */
    for (j = 0; j < n; j++) {
        double d = M[j * n + j];
        for (k = 0; k < j; k++)
            d -= Lf[j * n + k] * Lf[j * n + k];
        Lf[j * n + j] = sqrt(d);
        for (i = j + 1; i < n; i++) {
            double t = M[i * n + j];
            for (k = 0; k < j; k++)
                t -= Lf[i * n + k] * Lf[j * n + k];
            Lf[i * n + j] = t / Lf[j * n + j];
        }
    }
    for (i = 0; i < n; i++) {
        for (k = 0; k < i; k++)
            r[i] -= Lf[i * n + k] * r[k];
        r[i] /= Lf[i * n + i];
    }
    for (i = n - 1; i >= 0; i--) {
        for (k = i + 1; k < n; k++)
            r[i] -= Lf[k * n + i] * r[k];
        r[i] /= Lf[i * n + i];
    }
    memcpy(qdd, r, sizeof(double) * (size_t)n);
}

/* max |u - v| / max |v| over len entries */
static double rel_err(const double *u, const double *v, int len)
{
    double d = 0.0, s = 0.0;
    int i;
    for (i = 0; i < len; i++) {
        d = fmax(d, fabs(u[i] - v[i]));
        s = fmax(s, fabs(v[i]));
    }
    return d / (s > 0.0 ? s : 1.0);
}

/* The same chain as a libeom model (rigid links only). */
static eom_system *eom_chain(int n, const double *m, const double *L,
                             double g)
{
    eom_chain_spec sp;
    eom_model *md = NULL;
    eom_system *s = NULL;
    memset(&sp, 0, sizeof sp);
    sp.links = n;
    sp.modes_all = 0;
    sp.m_link = m;
    sp.L_link = L;
    sp.g = g;
    if (eom_model_new(&md) == EOM_OK && eom_chain_add(md, &sp) == 0)
        CHECK_INT(eom_system_new(&s, md, NULL, 0), EOM_OK);
    eom_model_free(&md);
    return s;
}

static const int drivers[2] = {ADOLC_DRIVER_VECTOR, ADOLC_DRIVER_HESSIAN};
static short next_tag = 1;

/* 1 if an ADOL-C Taylor file of tape tag is in the current directory */
static int taylor_file_exists(short tag)
{
    char name[64];
    FILE *f;
    snprintf(name, sizeof name, "ADOLC-Taylors_%d.tap", tag);
    f = fopen(name, "rb");
    if (f)
        fclose(f);
    return f != NULL;
}

/* Both drivers against the closed form, the hand-derived equations and
 * libeom for a chain of n links at the given number of random states;
 * M to 1e-12 relative, qdd to tol. */
static void check_chain(int n, int states, double tol, rng *r)
{
    const size_t n1 = (size_t)n, nn = n1 * n1;
    double *m = malloc(n1 * sizeof *m), *L = malloc(n1 * sizeof *L),
           *a = malloc(nn * sizeof *a), *c = malloc(n1 * sizeof *c),
           *x = malloc(2 * n1 * sizeof *x), *xd = malloc(2 * n1 * sizeof *xd),
           *M0 = malloc(nn * sizeof *M0), *M1 = malloc(nn * sizeof *M1),
           *q0 = malloc(n1 * sizeof *q0), *q1 = malloc(n1 * sizeof *q1),
           *work = malloc((nn + n1) * sizeof *work);
    const double g = 9.81;
    adolc_rhs *ad[2] = {NULL, NULL};
    eom_system *s = NULL;
    /* M, qdd vs hand, qdd vs libeom; condition of M */
    double worst[4] = {0.0, 0.0, 0.0, 0.0}, rcond = 0.0;
    short tag[2];
    int i, d, st;
    CHECK(m && L && a && c && x && xd && M0 && M1 && q0 && q1 && work);
    if (!(m && L && a && c && x && xd && M0 && M1 && q0 && q1 && work))
        goto done;
    for (i = 0; i < n; i++) {
        m[i] = rng_range(r, 0.5, 2.0);
        L[i] = rng_range(r, 0.4, 1.6);
    }
    chain_coeffs(n, m, L, a, c);
    s = eom_chain(n, m, L, g);
    CHECK(s != NULL);
    for (d = 0; d < 2; d++) {
        tag[d] = next_tag++;
        CHECK_INT(adolc_rhs_new(&ad[d], n, m, L, g, drivers[d], tag[d]), 0);
    }
    if (!s || !ad[0] || !ad[1])
        goto done;
    for (st = 0; st < states; st++) {
        for (i = 0; i < n; i++) {
            x[i] = rng_range(r, -pi, pi);
            x[n + i] = rng_range(r, -2.0, 2.0);
        }
        hand_eom(n, a, c, g, x, M0, q0, work);
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        CHECK(rel_err(xd + n, q0, n) <= tol);
        CHECK_INT(eom_condition(s, x, &rcond, NULL), EOM_OK);
        worst[3] = fmax(worst[3], 1.0 / rcond);
        for (d = 0; d < 2; d++) {
            double eM, eq, ee;
            CHECK_INT(adolc_rhs_eval(ad[d], x, q1, M1), 0);
            eM = rel_err(M1, M0, n * n);
            eq = rel_err(q1, q0, n);
            ee = rel_err(q1, xd + n, n);
            worst[0] = fmax(worst[0], eM);
            worst[1] = fmax(worst[1], eq);
            worst[2] = fmax(worst[2], ee);
            CHECK(eM <= 1e-12);
            CHECK(eq <= tol);
            CHECK(ee <= tol);
            /* M is optional */
            CHECK_INT(adolc_rhs_eval(ad[d], x, q1, NULL), 0);
            CHECK(rel_err(q1, q0, n) <= tol);
            CHECK(!taylor_file_exists(tag[d]));
        }
    }
    printf("N = %3d: largest relative differences %.1e (M), %.1e (qdd "
           "vs hand), %.1e (qdd vs libeom); cond(M) up to %.0e\n", n,
           worst[0], worst[1], worst[2], worst[3]);
done:
    for (d = 0; d < 2; d++) {
        adolc_rhs_free(&ad[d]);
        CHECK(ad[d] == NULL);
    }
    eom_system_free(&s);
    free(m);
    free(L);
    free(a);
    free(c);
    free(x);
    free(xd);
    free(M0);
    free(M1);
    free(q0);
    free(q1);
    free(work);
}

/* Bad arguments and a non-finite state fail cleanly; the destructor is
 * NULL-safe. */
static void check_misuse(void)
{
    const double m = 1.0, L = 1.0;
    double x[2] = {0.0, 0.0}, qdd[1];
    static int junk;
    int d;
    adolc_rhs *a = (adolc_rhs *)&junk; /* must be overwritten with NULL */
    CHECK(adolc_rhs_new(&a, 0, &m, &L, 9.81, ADOLC_DRIVER_VECTOR, 99) != 0);
    CHECK(a == NULL);
    CHECK(adolc_rhs_new(&a, 1, NULL, &L, 9.81, ADOLC_DRIVER_VECTOR, 99) != 0);
    CHECK(adolc_rhs_new(&a, 1, &m, &L, 9.81, 7, 99) != 0);
    CHECK(a == NULL);
    CHECK(adolc_rhs_new(NULL, 1, &m, &L, 9.81, ADOLC_DRIVER_VECTOR, 99) != 0);
    CHECK(adolc_rhs_eval(NULL, x, qdd, NULL) != 0);
    adolc_rhs_free(NULL);
    adolc_rhs_free(&a);
    for (d = 0; d < 2; d++) {
        CHECK_INT(adolc_rhs_new(&a, 1, &m, &L, 9.81, drivers[d], next_tag++),
                  0);
        x[0] = NAN;
        CHECK(adolc_rhs_eval(a, x, qdd, NULL) != 0);
        x[0] = 0.5;
        CHECK_INT(adolc_rhs_eval(a, x, qdd, NULL), 0);
        adolc_rhs_free(&a);
    }
}

int main(void)
{
    static const int sizes[] = {1, 2, 5, 10};
    rng r = rng_seed(7);
    size_t i;
    for (i = 0; i < sizeof sizes / sizeof sizes[0]; i++)
        check_chain(sizes[i], 6, 1e-12, &r);
    check_chain(120, 1, 1e-10, &r);
    check_misuse();
    CHECK_DONE();
}
