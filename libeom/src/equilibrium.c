/* equilibrium.c - static equilibrium: q and multipliers lambda with
 *
 *     r_q   = dL/dq(q, 0) + Q(q, 0) + C(q)^T lambda = 0      (n)
 *     r_phi = phi(q)                               = 0      (m)
 *
 * (for L = T - V, dV/dq - Q - C^T lambda = 0), by Newton's method on the
 * KKT system, with H = d2L/dq2 at qd = 0 and P = dQ/dq(q, 0) (so H + P +
 * sum lambda Hphi = -K of linearize.c):
 *
 *     [ H + P + sum_k lambda_k d2phi_k/dq2   C^T ] [dq     ]     [r_q  ]
 *     [ C                                    0   ] [dlambda] = - [r_phi]
 *
 * Q is every generalized force the model declares, at qd = 0
 * (forces_rest.c); P may be unsymmetric (a follower load), which the SVD
 * solve below does not mind.
 *
 * Robustness, in order of use:
 *   - the first lambda is the least-squares balance of dL/dq at the guess,
 *     so the first step already sees the constraint curvature;
 *   - the KKT matrix is scaled symmetrically (rows and columns by
 *     1/sqrt of the row's largest entry) and solved by SVD in the
 *     minimum-norm sense, dropping singular values below EOM_EQ_RCOND of
 *     the largest: a rank-deficient C (redundant constraints, a singular
 *     configuration) or a neutral direction does not stop the iteration;
 *   - the q part of a step is at most EOM_EQ_MAXSTEP max(1, max |q|);
 *   - a backtracking line search on the scaled residual |S r|^2 (S the
 *     scaling above, for which the step is a descent direction) accepts
 *     only a sufficient decrease (Armijo), halving up to EOM_EQ_MAXHALF
 *     times; a trial point where the model is not finite is rejected.
 * The iteration stops when max |r| <= tol (r_q and r_phi in their own
 * units), and fails with EOM_ERR_NOT_CONVERGED after EOM_EQ_MAXIT steps or
 * when no step decreases the residual. Any equilibrium may be found,
 * stable or not; eom_linearize tells which. The dissipation plays no
 * part (R's gradient vanishes at rest). A model whose Lagrangian,
 * dissipation, constraints or forces read the time has no state of rest
 * and is refused (EOM_ERR_MODEL). See docs/linearization.md.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"
#include "forces_rest.h"

#define EOM_EQ_MAXIT 50
#define EOM_EQ_MAXHALF 40
#define EOM_EQ_MAXSTEP 0.5
#define EOM_EQ_RCOND 1e-12
#define EOM_EQ_ARMIJO 1e-4

/* Scratch of one call, carved from one allocation; k = n + m. */
typedef struct eq_work {
    int k;
    double *x;    /* 2n  (q, 0) */
    double *g;    /* 2n  gradient of L at x */
    double *H;    /* 2n x n  Hessian columns of L on q */
    double *Q;    /* n  the forces at rest, Q(q, 0) */
    double *P;    /* n x n  dQ/dq at (q, 0) */
    double *xq;   /* 2n  scratch of the force sweeps */
    double *eye;  /* n x n  identity */
    double *Hphi; /* n x n  sum_k lambda_k d2phi_k/dq2 */
    double *lam;  /* m */
    double *r;    /* k  residual at the iterate */
    double *J;    /* k x k  KKT matrix, row-major */
    double *A;    /* k x k  scaled copy, column-major; destroyed by SVD */
    double *sc;   /* k  symmetric scaling */
    double *sv;   /* k  singular values */
    double *U;    /* k x k */
    double *VT;   /* k x k */
    double *b;    /* k  right-hand side */
    double *dz;   /* k  step (dq, dlambda) */
    double *Jdz;  /* k  J dz */
    double *q0;   /* n  the guess, restored on failure */
    double *qt;   /* n  trial point */
    double *lt;   /* m */
    double *rt;   /* k  residual at the trial point */
} eq_work;

static double *work_new(eq_work *w, int n, int m)
{
    const size_t N = (size_t)n, M = (size_t)m, K = N + M;
    const size_t total = 9 * N + 5 * N * N + 2 * M + 4 * K * K + 7 * K;
    double *p = calloc(total, sizeof(double)), *c = p;
    if (!p)
        return NULL;
    w->k = n + m;
    w->x = c, c += 2 * N;
    w->g = c, c += 2 * N;
    w->H = c, c += 2 * N * N;
    w->P = c, c += N * N;
    w->Q = c, c += N;
    w->xq = c, c += 2 * N;
    w->eye = c, c += N * N;
    w->Hphi = c, c += N * N;
    w->lam = c, c += M;
    w->J = c, c += K * K;
    w->A = c, c += K * K;
    w->U = c, c += K * K;
    w->VT = c, c += K * K;
    w->r = c, c += K;
    w->sc = c, c += K;
    w->sv = c, c += K;
    w->b = c, c += K;
    w->dz = c, c += K;
    w->Jdz = c, c += K;
    w->rt = c, c += K;
    w->q0 = c, c += N;
    w->qt = c, c += N;
    w->lt = c;
    return p;
}

/* r (n + m) at (q, lam), the forces Q(q, 0) included; leaves C and phi
 * at q in s. */
static int residual(eom_system *s, eq_work *w, const double *q,
                    const double *lam, double *r)
{
    const int n = s->n, m = s->m;
    int st, rc, i, j;
    memcpy(w->x, q, (size_t)n * sizeof(double));
    st = tp_gradient(s->tL.ws, w->x, 0, NULL, w->g);
    if ((rc = eom__tape_status(s, st, "the gradient of the Lagrangian")))
        return rc;
    if ((rc = eom__forces_at_rest(s, q, w->xq, w->Q, NULL, NULL)) != EOM_OK)
        return rc;
    for (i = 0; i < n; i++)
        r[i] = w->g[i] + w->Q[i];
    if (m == 0)
        return EOM_OK;
    if ((rc = eom__constraints_at(s, s->time, q)) != EOM_OK)
        return rc;
    for (j = 0; j < m; j++) {
        for (i = 0; i < n; i++)
            r[i] += s->C[j * n + i] * lam[j];
        r[n + j] = s->phi[j];
    }
    return eom__finite(r, (size_t)(n + m))
               ? EOM_OK
               : eom__fail(s, EOM_ERR_NONFINITE, "the residual is not finite");
}

/* The KKT matrix at (q, lam) into w->J; C at q must be in s (residual). */
static int kkt(eom_system *s, eq_work *w, const double *q, const double *lam)
{
    const int n = s->n, m = s->m, k = w->k;
    int st, rc, i, j;
    memcpy(w->x, q, (size_t)n * sizeof(double));
    st = tp_hessian_cols(s->tL.ws, w->x, 0, 0, n, NULL, w->H);
    if ((rc = eom__tape_status(s, st, "the Hessian of the Lagrangian")))
        return rc;
    if (m > 0) {
        st = tp_hvp(s->tphi.ws, q, lam, n, w->eye, NULL, w->Hphi);
        if ((rc = eom__tape_status(s, st, "the constraint curvature")))
            return rc;
    }
    if ((rc = eom__forces_at_rest(s, q, w->xq, w->Q, w->P, NULL)) != EOM_OK)
        return rc;
    memset(w->J, 0, (size_t)k * (size_t)k * sizeof(double));
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++)
            w->J[i * k + j] =
                w->H[i * n + j] + w->P[i * n + j] + w->Hphi[i * n + j];
    for (j = 0; j < m; j++)
        for (i = 0; i < n; i++) {
            w->J[i * k + n + j] = s->C[j * n + i];   /* C^T */
            w->J[(n + j) * k + i] = s->C[j * n + i]; /* C */
        }
    return EOM_OK;
}

/* Minimum-norm solution x of the scaled system: with S = diag(w->sc),
 * x = S (S J S)^+ S b, where the pseudo-inverse drops singular values at
 * or below EOM_EQ_RCOND of the largest. J is row-major dim x dim; uses
 * w->A, U, VT, sv. */
static int pinv_solve(eom_system *s, eq_work *w, int dim, const double *J,
                      const double *b, double *x)
{
    int i, j, l, rc;
    for (i = 0; i < dim; i++) {
        double big = 0.0;
        for (j = 0; j < dim; j++)
            big = fmax(big, fabs(J[i * dim + j]));
        w->sc[i] = big > 0.0 ? 1.0 / sqrt(big) : 1.0;
    }
    for (i = 0; i < dim; i++)
        for (j = 0; j < dim; j++)
            w->A[i + j * dim] = w->sc[i] * J[i * dim + j] * w->sc[j];
    if ((rc = eom__svd(s, dim, dim, w->A, w->sv, w->U, w->VT,
                       "the equilibrium system")) != EOM_OK)
        return rc;
    for (j = 0; j < dim; j++)
        x[j] = 0.0;
    for (l = 0; l < dim && w->sv[l] > EOM_EQ_RCOND * w->sv[0]; l++) {
        double c = 0.0;
        for (i = 0; i < dim; i++)
            c += w->U[i + l * dim] * w->sc[i] * b[i];
        c /= w->sv[l];
        for (j = 0; j < dim; j++)
            x[j] += w->VT[l + j * dim] * c; /* row l of V^T */
    }
    for (j = 0; j < dim; j++)
        x[j] *= w->sc[j];
    return EOM_OK;
}

/* The least-squares multipliers of C^T lambda = -(dL/dq + Q) at the
 * point whose residual (lam = 0) is in w->r and whose C is in s: the
 * minimum-norm solution of C C^T lambda = -C r. */
static int first_multipliers(eom_system *s, eq_work *w)
{
    const int n = s->n, m = s->m;
    int i, j, l;
    for (i = 0; i < m; i++) {
        double v = 0.0;
        for (l = 0; l < n; l++)
            v -= s->C[i * n + l] * w->r[l];
        w->b[i] = v;
        for (j = 0; j < m; j++) {
            double c = 0.0;
            for (l = 0; l < n; l++)
                c += s->C[i * n + l] * s->C[j * n + l];
            w->J[i * m + j] = c;
        }
    }
    return pinv_solve(s, w, m, w->J, w->b, w->lam);
}

static double scaled_norm2(const eq_work *w, const double *r)
{
    double f = 0.0;
    int i;
    for (i = 0; i < w->k; i++)
        f += (w->sc[i] * r[i]) * (w->sc[i] * r[i]);
    return f;
}

/* Backtracking from the limited step along w->dz; on success q, lam and
 * w->r hold the accepted point. *stalled is set when no trial decreases
 * the residual enough. */
static int line_search(eom_system *s, eq_work *w, double *q, bool *stalled)
{
    const int n = s->n, m = s->m, k = w->k;
    const double f0 = scaled_norm2(w, w->r);
    const double big = eom__maxabs(w->dz, n);
    const double limit = EOM_EQ_MAXSTEP * fmax(1.0, eom__maxabs(q, n));
    double slope = 0.0, alpha = 1.0;
    int i, j, tries, rc;

    *stalled = false;
    for (i = 0; i < k; i++) {
        double v = 0.0;
        for (j = 0; j < k; j++)
            v += w->J[i * k + j] * w->dz[j];
        slope += 2.0 * (w->sc[i] * w->r[i]) * (w->sc[i] * v);
    }
    if (!(slope < 0.0)) {
        *stalled = true;
        return EOM_OK;
    }
    if (big > limit)
        alpha = limit / big;
    for (tries = 0; tries < EOM_EQ_MAXHALF; tries++, alpha *= 0.5) {
        for (i = 0; i < n; i++)
            w->qt[i] = q[i] + alpha * w->dz[i];
        for (j = 0; j < m; j++)
            w->lt[j] = w->lam[j] + alpha * w->dz[n + j];
        rc = residual(s, w, w->qt, w->lt, w->rt);
        if (rc == EOM_ERR_NONFINITE)
            continue; /* outside the model's domain: shorter step */
        if (rc != EOM_OK)
            return rc;
        if (scaled_norm2(w, w->rt) <= f0 + EOM_EQ_ARMIJO * alpha * slope) {
            memcpy(q, w->qt, (size_t)n * sizeof(double));
            memcpy(w->lam, w->lt, (size_t)m * sizeof(double));
            memcpy(w->r, w->rt, (size_t)k * sizeof(double));
            return EOM_OK;
        }
    }
    *stalled = true;
    return EOM_OK;
}

static int solve(eom_system *s, eq_work *w, double *q, double tol,
                 int *iters)
{
    const int n = s->n, m = s->m, k = w->k;
    double res;
    bool stalled;
    int rc, i;

    for (i = 0; i < n; i++)
        w->eye[i * n + i] = 1.0;
    if ((rc = residual(s, w, q, w->lam, w->r)) != EOM_OK)
        return rc;
    if (m > 0) {
        if ((rc = first_multipliers(s, w)) != EOM_OK)
            return rc;
        if ((rc = residual(s, w, q, w->lam, w->r)) != EOM_OK)
            return rc;
    }
    for (*iters = 0;; ++*iters) {
        res = eom__maxabs(w->r, k);
        if (res <= tol)
            return EOM_OK;
        if (*iters == EOM_EQ_MAXIT)
            return eom__fail(s, EOM_ERR_NOT_CONVERGED,
                             "eom_equilibrium: max |residual| = %.3g after "
                             "%d iterations (tolerance %.3g)", res, *iters,
                             tol);
        /* C at q is in s: residual was last evaluated at the iterate */
        if ((rc = kkt(s, w, q, w->lam)) != EOM_OK)
            return rc;
        for (i = 0; i < k; i++)
            w->rt[i] = -w->r[i];
        if ((rc = pinv_solve(s, w, k, w->J, w->rt, w->dz)) != EOM_OK)
            return rc;
        if ((rc = line_search(s, w, q, &stalled)) != EOM_OK)
            return rc;
        if (stalled)
            return eom__fail(s, EOM_ERR_NOT_CONVERGED,
                             "eom_equilibrium: no step reduces the residual "
                             "(max |residual| = %.3g after %d iterations); "
                             "there may be no equilibrium near the guess",
                             res, *iters);
    }
}

/* q is restored to the guess on failure; *iters (may be NULL) receives
 * the number of Newton steps taken, also on failure. */
int eom_equilibrium(eom_system *s, double *q, double tol, int *iters)
{
    eq_work w;
    double *block;
    int rc, it = 0;
    if (iters)
        *iters = 0;
    if (!s)
        return EOM_ERR_NULL;
    if (!q)
        return eom__fail(s, EOM_ERR_NULL, "eom_equilibrium: q is NULL");
    if (!(tol > 0.0))
        return eom__fail(s, EOM_ERR_ARG, "eom_equilibrium: tolerance %g",
                         tol);
    if (!eom__finite(q, (size_t)s->n))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "eom_equilibrium: q is not finite");
    if ((rc = eom__refuse_time(s, "eom_equilibrium")) != EOM_OK ||
        (rc = eom__refuse_velocity(s, "eom_equilibrium")) != EOM_OK ||
        (rc = eom__refuse_forces_time(s, "eom_equilibrium")) != EOM_OK)
        return rc;
    block = work_new(&w, s->n, s->m);
    if (!block)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    memcpy(w.q0, q, (size_t)s->n * sizeof(double));
    rc = solve(s, &w, q, tol, &it);
    if (rc != EOM_OK)
        memcpy(q, w.q0, (size_t)s->n * sizeof(double));
    else
        s->msg[0] = '\0';
    free(block);
    if (iters)
        *iters = it;
    return rc;
}
