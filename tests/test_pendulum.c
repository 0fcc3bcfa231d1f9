/* test_pendulum.c - the N-link pendulum (tests/models/pendulum_chain), a
 * problem with a known answer, through tp_lagrange.
 *
 * For N = 1, 2, 3, 5, 10, 20 links with unequal masses and lengths, a tape
 * recorded with groups q = 0, qd = 1 is replayed at random states and
 * compared with
 *   - the closed-form mass matrix (pendulum_chain_mass): M to 1e-14
 *     relative to max |M|;
 *   - the plain-double Lagrangian (pendulum_chain_L): L;
 *   - the embedded-tuple engine (tp_tuple_lagrange): L, dLdq, M, h;
 *   - central finite differences of the plain-double L (dLdq) and of
 *     dL/dqd = M(q) qd built from the closed-form M (h = d/ds dL/dqd along
 *     q' = qd);
 *   - closed forms derived by hand from M_ij = a_ij cos(q_i - q_j):
 *       dL/dq_k = -qd_k sum_j a_kj sin(q_k - q_j) qd_j
 *                 - g l_k sin(q_k) (m_k / 2 + sum_{i>k} m_i)
 *       h_i     = -sum_j a_ij sin(q_i - q_j) (qd_i - qd_j) qd_j
 *       T = qd' M qd / 2,  V = -g sum_i m_i (sum_{k<i} l_k cos q_k
 *                                            + l_i cos(q_i) / 2).
 * A workspace with max_dirs 3 (chunked) must agree with one of max_dirs N.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "pendulum_chain.h"
#include "support_num.h"
#include "support_rng.h"
#include "support_tape.h"

#define NMAX 20
#define NPOINTS 5

static const double PI_ = 3.14159265358979323846;

typedef struct fd_ctx {
    const pendulum_chain *pc;
    const double *x; /* the state (q, qd) the differences start from */
} fd_ctx;

/* L as a function of q alone (qd fixed), for dL/dq. */
static int fd_L_of_q(void *ctx, const double *q, double *y)
{
    const fd_ctx *c = ctx;
    double x[2 * NMAX];
    const int n = c->pc->n;
    memcpy(x, q, (size_t)n * sizeof(double));
    memcpy(x + n, c->x + n, (size_t)n * sizeof(double));
    *y = pendulum_chain_L(c->pc, x);
    return 0;
}

/* dL/dqd = M(q) qd from the closed-form M, as a function of q. */
static int fd_p_of_q(void *ctx, const double *q, double *p)
{
    const fd_ctx *c = ctx;
    const int n = c->pc->n;
    const double *qd = c->x + n;
    double M[NMAX * NMAX];
    int i, j;
    pendulum_chain_mass(c->pc, q, M);
    for (i = 0; i < n; i++) {
        p[i] = 0.0;
        for (j = 0; j < n; j++)
            p[i] += M[i * n + j] * qd[j];
    }
    return 0;
}

/* L as a function of qd alone (q fixed at c->x). */
static int fd_L_of_qd(void *ctx, const double *qd, double *y)
{
    const fd_ctx *c = ctx;
    double x[2 * NMAX];
    const int n = c->pc->n;
    memcpy(x, c->x, (size_t)n * sizeof(double));
    memcpy(x + n, qd, (size_t)n * sizeof(double));
    *y = pendulum_chain_L(c->pc, x);
    return 0;
}

/* dL/dqd by finite differences of the plain-double L, as a function of q
 * (qd fixed): differences of differences, no closed form involved. */
static int fd_p_of_q_nested(void *ctx, const double *q, double *p)
{
    const fd_ctx *c = ctx;
    double x[2 * NMAX];
    fd_ctx inner;
    const int n = c->pc->n;
    memcpy(x, q, (size_t)n * sizeof(double));
    memcpy(x + n, c->x + n, (size_t)n * sizeof(double));
    inner.pc = c->pc;
    inner.x = x;
    return num_fd_jac(fd_L_of_qd, &inner, n, 1, x + n, 1e-2, p);
}

/* The hand-derived closed forms of the header comment. a (n x n) holds
 * the coefficients a_ij (M at q = 0). */
static void closed_forms(const pendulum_chain *pc, const double *a,
                         const double *x, double *dLdq, double *h, double *T,
                         double *V)
{
    const int n = pc->n;
    const double *q = x, *qd = x + n;
    double y = 0.0;
    int i, j, k;
    *T = 0.0;
    *V = 0.0;
    for (i = 0; i < n; i++) {
        double tail = 0.0, s = 0.0, hs = 0.0;
        const double mi = pendulum_chain_m(pc, i), li = pendulum_chain_l(pc, i);
        for (k = i + 1; k < n; k++)
            tail += pendulum_chain_m(pc, k);
        for (j = 0; j < n; j++) {
            const double sij = sin(q[i] - q[j]);
            s += a[i * n + j] * sij * qd[j];
            hs += a[i * n + j] * sij * (qd[i] - qd[j]) * qd[j];
            *T += 0.5 * qd[i] * a[i * n + j] * cos(q[i] - q[j]) * qd[j];
        }
        dLdq[i] = -qd[i] * s - pc->g * li * sin(q[i]) * (0.5 * mi + tail);
        h[i] = -hs;
        *V -= pc->g * mi * (y + 0.5 * li * cos(q[i]));
        y += li * cos(q[i]);
    }
}

static void one_size(int n, rng *g)
{
    double m[NMAX], l[NMAX], a[NMAX * NMAX], zero[NMAX];
    unsigned char grp[2 * NMAX];
    pendulum_chain pc;
    tp_rec *r = NULL, *tu = NULL;
    tp_tape *T = NULL;
    tp_ws *ws = NULL, *ws3 = NULL;
    int i, k, iL, iT, iV;
    char ctx[80];

    for (i = 0; i < n; i++) {
        m[i] = rng_range(g, 0.5, 2.0);
        l[i] = rng_range(g, 0.3, 1.5);
        zero[i] = 0.0;
        grp[i] = 0;
        grp[n + i] = 1;
    }
    pc.n = n;
    pc.m = m;
    pc.l = l;
    pc.g = 9.81;
    pendulum_chain_mass(&pc, zero, a); /* cos 0 = 1: the a_ij */

    CHECK_INT(tp_recorder_new(&r, 2 * n, grp, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, pendulum_chain_record, &pc), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    tp_rec_free(&r);
    CHECK_INT(tp_ws_new(&ws, T, n, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&ws3, T, 3, NULL), TP_OK);
    CHECK_INT(tp_tuple_new(&tu, 2 * n, NULL), TP_OK);
    if (!T || !ws || !ws3 || !tu)
        goto done;
    iL = tp_tape_output_index(T, "L");
    iT = tp_tape_output_index(T, "T");
    iV = tp_tape_output_index(T, "V");
    CHECK(iL >= 0 && iT >= 0 && iV >= 0);

    for (k = 0; k < NPOINTS; k++) {
        double x[2 * NMAX], M[NMAX * NMAX], Mc[NMAX * NMAX], M3[NMAX * NMAX];
        double Mt[NMAX * NMAX], dLdq[NMAX], h[NMAX], dLdq_t[NMAX], h_t[NMAX];
        double dLdq_a[NMAX], h_a[NMAX], dLdq_fd[NMAX], h_fd[NMAX];
        double dLdq3[NMAX], h3[NMAX], hM[NMAX], y[3];
        double L, L_t, L3, Lp, Ta, Va, Mmax, sc;
        fd_ctx fc;
        for (i = 0; i < n; i++) {
            x[i] = rng_range(g, -PI_, PI_);
            x[n + i] = rng_range(g, -2.0, 2.0);
        }
        snprintf(ctx, sizeof ctx, "N=%d point %d", n, k);

        CHECK_INT(tp_lagrange(ws, x, iL, &L, dLdq, M, h), TP_OK);
        pendulum_chain_mass(&pc, x, Mc);
        Mmax = num_max_abs(Mc, (size_t)n * (size_t)n);
        CHECK_VEC_SCALED(ctx, M, Mc, n * n, Mmax, 1e-14);

        /* L, T, V against the plain doubles and the closed forms */
        closed_forms(&pc, a, x, dLdq_a, h_a, &Ta, &Va);
        Lp = pendulum_chain_L(&pc, x);
        sc = fabs(Ta) + fabs(Va);
        CHECK_VEC_SCALED(ctx, &L, &Lp, 1, sc, 1e-14);
        CHECK_INT(tp_eval(ws, x, y), TP_OK);
        CHECK_VEC(ctx, &y[iL], &L, 1, 0.0);
        /* (the closed forms sum n^2 terms in another order) */
        CHECK_VEC_SCALED(ctx, &y[iT], &Ta, 1, sc, 1e-13);
        CHECK_VEC_SCALED(ctx, &y[iV], &Va, 1, sc, 1e-13);

        /* scale of the generalized forces: the largest term of dL/dq */
        sc = Mmax * num_max_abs(x + n, (size_t)n) *
                 num_max_abs(x + n, (size_t)n) * n +
             pc.g * 2.0 * n * 1.5;
        CHECK_VEC_SCALED(ctx, dLdq, dLdq_a, n, sc, 1e-13);
        CHECK_VEC_SCALED(ctx, h, h_a, n, sc, 1e-13);

        /* the embedded-tuple engine on the same Lagrangian */
        CHECK_INT(tp_rec_run(tu, x, pendulum_chain_record, &pc), TP_OK);
        CHECK_INT(tp_tuple_lagrange(tu, iL, &L_t, dLdq_t, Mt, h_t), TP_OK);
        CHECK_VEC_SCALED(ctx, &L, &L_t, 1, fabs(Ta) + fabs(Va), 1e-14);
        CHECK_VEC_SCALED(ctx, M, Mt, n * n, Mmax, 1e-14);
        CHECK_VEC_SCALED(ctx, dLdq, dLdq_t, n, sc, 1e-13);
        CHECK_VEC_SCALED(ctx, h, h_t, n, sc, 1e-13);

        /* finite differences of plain-double code */
        fc.pc = &pc;
        fc.x = x;
        CHECK_INT(num_fd_jac(fd_L_of_q, &fc, n, 1, x, 1e-3, dLdq_fd), 0);
        CHECK_INT(num_fd_dir(fd_p_of_q, &fc, n, n, x, x + n, 1e-3, h_fd),
                  0);
        CHECK_VEC_SCALED(ctx, dLdq, dLdq_fd, n, sc, 1e-9);
        CHECK_VEC_SCALED(ctx, h, h_fd, n, sc, 1e-9);
        /* h once more, from differences of differences of plain-double L
         * (L is quadratic in qd, so the inner differences are exact up to
         * rounding; the outer step is larger to tame that rounding) */
        CHECK_INT(num_fd_dir(fd_p_of_q_nested, &fc, n, n, x, x + n, 1e-2,
                             h_fd),
                  0);
        CHECK_VEC_SCALED(ctx, h, h_fd, n, sc, 1e-7);

        /* chunked workspace, and partial requests */
        CHECK_INT(tp_lagrange(ws3, x, iL, &L3, dLdq3, M3, h3), TP_OK);
        CHECK_VEC(ctx, &L3, &L, 1, 0.0);
        CHECK_VEC(ctx, dLdq3, dLdq, n, 1e-15);
        CHECK_VEC(ctx, M3, M, n * n, 1e-15);
        CHECK_VEC(ctx, h3, h, n, 1e-15);
        CHECK_INT(tp_lagrange(ws3, x, iL, NULL, dLdq3, NULL, NULL), TP_OK);
        CHECK_VEC(ctx, dLdq3, dLdq, n, 1e-15);
        CHECK_INT(tp_lagrange(ws3, x, iL, NULL, NULL, NULL, h3), TP_OK);
        CHECK_VEC(ctx, h3, h, n, 1e-15);
        CHECK_INT(tp_lagrange(ws3, x, iL, NULL, NULL, M3, NULL), TP_OK);
        CHECK_VEC(ctx, M3, M, n * n, 1e-15);
        CHECK_INT(tp_lagrange(ws, x, iL, &L3, NULL, NULL, NULL), TP_OK);
        CHECK_VEC(ctx, &L3, &L, 1, 0.0);

        /* M is the Hessian block of T over qd: the same from tp_hessian */
        {
            double Hf[4 * NMAX * NMAX];
            int j;
            CHECK_INT(tp_hessian(ws3, x, iT, Hf), TP_OK);
            for (i = 0; i < n; i++)
                for (j = 0; j < n; j++)
                    Mc[i * n + j] = Hf[(n + i) * 2 * n + n + j];
            CHECK_VEC_SCALED(ctx, Mc, M, n * n, Mmax, 1e-14);
            /* and M qd = dL/dqd from the gradient */
            CHECK_INT(tp_gradient(ws, x, iL, NULL, Hf), TP_OK);
            for (i = 0; i < n; i++) {
                hM[i] = 0.0;
                for (j = 0; j < n; j++)
                    hM[i] += M[i * n + j] * x[n + j];
            }
            CHECK_VEC_SCALED(ctx, Hf + n, hM, n,
                             Mmax * n * num_max_abs(x + n, (size_t)n),
                             1e-14);
        }
    }
done:
    tp_rec_free(&tu);
    tp_ws_free(&ws);
    tp_ws_free(&ws3);
    tp_tape_free(&T);
}

int main(void)
{
    static const int sizes[] = {1, 2, 3, 5, 10, 20};
    rng g = rng_seed(0x9e4d0001u);
    size_t i;
    for (i = 0; i < sizeof sizes / sizeof sizes[0]; i++)
        one_size(sizes[i], &g);
    CHECK_DONE();
}
