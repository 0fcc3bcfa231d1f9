/* core_support.h - helpers shared by the eom_core tests (header-only):
 * making a system from a model, setting a parameter by name, the closed
 * forms of the uniform-rod chain of tests/models/eom_models.c derived by
 * hand (not from the model's code), and a dense solver for the augmented
 * (KKT) system used as an independent reference for the range-space solve.
 *
 * Rod chain, angles th_i from +x, gravity g along -y, rod i of mass m_i and
 * length l_i (centre of mass at mid-length, inertia m l^2 / 12):
 *   M_ii = l_i^2 (m_i / 3 + sum_{k>i} m_k)
 *   M_ij = l_i l_j cos(th_i - th_j) (m_j / 2 + sum_{k>j} m_k),  i < j
 *   V    = g sum_i m_i (sum_{k<i} l_k sin th_k + l_i / 2 sin th_i)
 *   dV/dth_i = g l_i cos th_i (m_i / 2 + sum_{k>i} m_k)
 * With M_ij = a_ij cos(th_i - th_j), Lagrange's equations read
 *   M qdd = -sum_j a_ij sin(th_i - th_j) thd_j^2 - dV/dth_i + C^T lambda.
 * Closed chain (tip pinned at (D, 0)):
 *   phi = (sum l cos th - D, sum l sin th),
 *   C   = [-l_j sin th_j ; l_j cos th_j],
 *   gamma = -(d2phi/dq2)[qd, qd] = (sum l cos th thd^2, sum l sin th thd^2).
 * The four-bar of the tests (three rods closed, FB_* below) and
 * fourbar_assemble, which builds its consistent states by intersecting
 * circles, are at the end.
 */
#ifndef TESTS_EOM_CORE_SUPPORT_H
#define TESTS_EOM_CORE_SUPPORT_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "eom/eom.h"
#include "eom_models.h"

#define CORE_NMAX 8
#define CORE_PI 3.14159265358979323846

/* A system from a model; the model is freed. NULL (with the message on
 * stderr) on failure. */
static inline eom_system *core_system(eom_model *md)
{
    char msg[256];
    eom_system *s = NULL;
    int rc;
    if (!md) {
        fprintf(stderr, "core_system: no model\n");
        return NULL;
    }
    rc = eom_system_new(&s, md, msg, sizeof msg);
    if (rc != EOM_OK)
        fprintf(stderr, "eom_system_new: %s: %s\n", eom_status_name(rc), msg);
    eom_model_free(&md);
    return s;
}

/* Set a parameter by name; the status (EOM_ERR_NAME if unknown). */
static inline int core_set(eom_system *s, const char *name, double v)
{
    int k = eom_param_index(s, name);
    return k < 0 ? EOM_ERR_NAME : eom_set_param(s, k, v);
}

/* Closed forms of the rod chain (see the top of this file). */
typedef struct core_chain {
    int n;
    double m[CORE_NMAX], l[CORE_NMAX], g, D;
} core_chain;

/* The tail masses m_i / 2 + sum_{k>i} m_k and m_i / 3 + sum_{k>i} m_k. */
static inline double core_tail(const core_chain *c, int i, double self)
{
    double t = self * c->m[i];
    int k;
    for (k = i + 1; k < c->n; k++)
        t += c->m[k];
    return t;
}

static inline void core_chain_mass(const core_chain *c, const double *q,
                                   double *M)
{
    const int n = c->n;
    int i, j;
    for (i = 0; i < n; i++) {
        M[i * n + i] = c->l[i] * c->l[i] * core_tail(c, i, 1.0 / 3.0);
        for (j = i + 1; j < n; j++)
            M[i * n + j] = M[j * n + i] = c->l[i] * c->l[j] *
                                          cos(q[i] - q[j]) *
                                          core_tail(c, j, 0.5);
    }
}

static inline double core_chain_V(const core_chain *c, const double *q)
{
    double V = 0.0, y = 0.0;
    int i;
    for (i = 0; i < c->n; i++) {
        V += c->g * c->m[i] * (y + 0.5 * c->l[i] * sin(q[i]));
        y += c->l[i] * sin(q[i]);
    }
    return V;
}

static inline double core_chain_T(const core_chain *c, const double *x)
{
    double M[CORE_NMAX * CORE_NMAX], T = 0.0;
    const int n = c->n;
    int i, j;
    core_chain_mass(c, x, M);
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++)
            T += 0.5 * x[n + i] * M[i * n + j] * x[n + j];
    return T;
}

/* F = -sum_j a_ij sin(th_i - th_j) thd_j^2 - dV/dth_i (n), the applied
 * generalized force of the unconstrained chain, and optionally the scale
 * of its terms (for relative error measures). */
static inline void core_chain_force(const core_chain *c, const double *x,
                                    double *F, double *scale)
{
    const int n = c->n;
    double M[CORE_NMAX * CORE_NMAX], sc = 0.0;
    double a;
    int i, j;
    core_chain_mass(c, x, M);
    for (i = 0; i < n; i++) {
        double dV = c->g * c->l[i] * cos(x[i]) * core_tail(c, i, 0.5);
        F[i] = -dV;
        sc += fabs(dV);
        for (j = 0; j < n; j++) {
            if (j == i)
                continue;
            a = c->l[i] * c->l[j] * core_tail(c, i > j ? i : j, 0.5);
            F[i] -= a * sin(x[i] - x[j]) * x[n + j] * x[n + j];
            sc += fabs(a * x[n + j] * x[n + j]);
        }
    }
    if (scale)
        *scale = sc;
}

/* Closed chain: phi (2), C (2 x n) and gamma (2). */
static inline void core_chain_constraints(const core_chain *c,
                                          const double *x, double *phi,
                                          double *C, double *gam)
{
    const int n = c->n;
    int j;
    if (phi) {
        phi[0] = -c->D;
        phi[1] = 0.0;
    }
    if (gam)
        gam[0] = gam[1] = 0.0;
    for (j = 0; j < n; j++) {
        const double co = cos(x[j]), si = sin(x[j]);
        if (phi) {
            phi[0] += c->l[j] * co;
            phi[1] += c->l[j] * si;
        }
        if (C) {
            C[j] = -c->l[j] * si;
            C[n + j] = c->l[j] * co;
        }
        if (gam) {
            gam[0] += c->l[j] * co * x[n + j] * x[n + j];
            gam[1] += c->l[j] * si * x[n + j] * x[n + j];
        }
    }
}

/* Solve A z = b (k x k, row-major, overwritten) by Gaussian elimination
 * with partial pivoting; z overwrites b. 0, or -1 if singular. */
static inline int core_dense_solve(int k, double *A, double *b)
{
    int i, j, r, p;
    for (j = 0; j < k; j++) {
        p = j;
        for (i = j + 1; i < k; i++)
            if (fabs(A[i * k + j]) > fabs(A[p * k + j]))
                p = i;
        if (A[p * k + j] == 0.0)
            return -1;
        if (p != j) {
            double t;
            for (r = 0; r < k; r++) {
                t = A[j * k + r];
                A[j * k + r] = A[p * k + r];
                A[p * k + r] = t;
            }
            t = b[j];
            b[j] = b[p];
            b[p] = t;
        }
        for (i = j + 1; i < k; i++) {
            const double f = A[i * k + j] / A[j * k + j];
            for (r = j; r < k; r++)
                A[i * k + r] -= f * A[j * k + r];
            b[i] -= f * b[j];
        }
    }
    for (j = k - 1; j >= 0; j--) {
        for (r = j + 1; r < k; r++)
            b[j] -= A[j * k + r] * b[r];
        b[j] /= A[j * k + j];
    }
    return 0;
}

/* The augmented system [M -C^T; C 0] (qdd, lambda) = (F, gam), solved
 * densely: qdd (n) and lambda (m). 0, or -1 if singular. */
static inline int core_kkt(int n, int m, const double *M, const double *C,
                           const double *F, const double *gam, double *qdd,
                           double *lam)
{
    double A[(CORE_NMAX + 4) * (CORE_NMAX + 4)], b[CORE_NMAX + 4];
    const int k = n + m;
    int i, j;
    memset(A, 0, sizeof A);
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++)
            A[i * k + j] = M[i * n + j];
        for (j = 0; j < m; j++) {
            A[i * k + n + j] = -C[j * n + i];
            A[(n + j) * k + i] = C[j * n + i];
        }
        b[i] = F[i];
    }
    for (j = 0; j < m; j++)
        b[n + j] = gam[j];
    if (core_dense_solve(k, A, b))
        return -1;
    memcpy(qdd, b, (size_t)n * sizeof(double));
    if (m)
        memcpy(lam, b + n, (size_t)m * sizeof(double));
    return 0;
}

/* y = A x, A rows x cols. */
static inline void core_matvec(int rows, int cols, const double *A,
                               const double *x, double *y)
{
    int i, j;
    for (i = 0; i < rows; i++) {
        y[i] = 0.0;
        for (j = 0; j < cols; j++)
            y[i] += A[i * cols + j] * x[j];
    }
}

static inline double core_maxabs(const double *a, int n)
{
    double m = 0.0;
    int i;
    for (i = 0; i < n; i++)
        m = fabs(a[i]) > m ? fabs(a[i]) : m;
    return m;
}

/* ---- the four-bar ------------------------------------------------------- */

/* The four-bar of the tests: rods l = (1, 2, 1.5) m, masses (1, 2, 1.5)
 * kg, ground D = 2.2 m, g = 9.81: a Grashof crank-rocker (s + l = 3.2 <
 * p + q = 3.5) whose crank turns fully and which never reaches a singular
 * configuration. (D = 2.5 would make s + l = p + q, a change-point
 * linkage that passes through a flat, singular configuration.) */
static const double FB_M[3] = {1.0, 2.0, 1.5}, FB_L[3] = {1.0, 2.0, 1.5};
#define FB_D 2.2
#define FB_G 9.81

static inline core_chain fourbar_closed_form(void)
{
    core_chain c;
    int i;
    memset(&c, 0, sizeof c);
    c.n = 3;
    for (i = 0; i < 3; i++) {
        c.m[i] = FB_M[i];
        c.l[i] = FB_L[i];
    }
    c.g = FB_G;
    c.D = FB_D;
    return c;
}

static inline eom_system *fourbar_system(void)
{
    const double th0[3] = {1.5, 0.3, -1.3};
    return core_system(eom_models_rod_chain(3, FB_M, FB_L, th0, FB_G, 1,
                                            FB_D));
}

/* A consistent state: crank angle th1, the assembly branch (+1: the
 * coupler-rocker joint to the left of the line from the crank tip to the
 * pin (D, 0), looking along it; -1: to the right), crank rate w1; th2, th3
 * by intersecting circles, their rates from C qd = 0. */
static inline void fourbar_assemble(const core_chain *c, double th1,
                                    int branch, double w1, double *x)
{
    const double ax = c->l[0] * cos(th1), ay = c->l[0] * sin(th1);
    const double dx = c->D - ax, dy = -ay, d = hypot(dx, dy);
    const double a = (c->l[1] * c->l[1] - c->l[2] * c->l[2] + d * d) /
                     (2.0 * d);
    const double h = sqrt(c->l[1] * c->l[1] - a * a);
    const double ux = dx / d, uy = dy / d;
    const double px = ax + a * ux - branch * h * uy;
    const double py = ay + a * uy + branch * h * ux;
    double Cm[6], det;
    x[0] = th1;
    x[1] = atan2(py - ay, px - ax);
    x[2] = atan2(-py, c->D - px);
    x[3] = w1;
    /* columns 2, 3 of C times (w2, w3) = -column 1 times w1 */
    core_chain_constraints(c, x, NULL, Cm, NULL);
    det = Cm[1] * Cm[5] - Cm[2] * Cm[4];
    x[4] = (-Cm[0] * w1 * Cm[5] + Cm[2] * Cm[3] * w1) / det;
    x[5] = (-Cm[1] * Cm[3] * w1 + Cm[4] * Cm[0] * w1) / det;
}

#endif
