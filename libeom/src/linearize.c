/* linearize.c - linearization about a static equilibrium (qd = 0) and the
 * natural frequencies of the constrained system (docs/linearization.md).
 *
 * At rest at q the multipliers balance the generalized force,
 * dL/dq + Q + C^T lambda = 0 (Q every force the model declares, at
 * qd = 0: forces_rest.c). Small motions dq = N y, with N an orthonormal
 * basis of the null space of C, obey
 *
 *     Mr ydd + Dr yd + Kr y = 0,   Xr = N^T X N,
 *     M = d2L/dqd2,  K = -(d2L/dq2 + dQ/dq + sum_k lambda_k d2phi_k/dq2),
 *     D = d2R/dqd2 - dQ/dqd,
 *
 * all at (q, 0). The lambda term carries the curvature of the constraint
 * manifold; without it a bead on a circle would have no restoring force.
 * The frequencies solve Kr z = w^2 Mr z (LAPACK dsygv), which needs K
 * symmetric: a force whose dQ/dq is not (a follower load, a circulatory
 * force) is refused with EOM_ERR_MODEL and a message saying so, as no
 * undamped frequencies exist; eom_linearize_state gives the eigenvalues.
 * D keeps the unsymmetric part of -dQ/dqd (a gyroscopic force).
 *
 * A model whose Lagrangian, dissipation, constraints or forces read the
 * time has no state of rest: it is refused (EOM_ERR_MODEL).
 *
 * Rank: N and lambda come from one SVD of C, so a rank-deficient C (a
 * singular configuration, or redundant constraints) gives a larger null
 * space and the minimum-norm multipliers instead of a failure. Singular
 * values at or below EOM_LIN_RANK_RTOL times the largest count as zero.
 *
 * Storage: the library's matrices are row-major, LAPACK's column-major.
 * Symmetric matrices read the same either way. A row-major C (m x n) is a
 * column-major C^T (n x m), so the SVD is taken of C^T = U S V^T: the
 * columns of U beyond the rank span null(C), and lambda = V S^+ U^T (-g).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"
#include "forces_rest.h"

/* Singular values of C at or below this fraction of the largest are zero.
 * AD gives C to rounding, so exact singular configurations land near 1e-16;
 * the margin also catches points that are singular to within the
 * tolerance an equilibrium was solved to. */
#define EOM_LIN_RANK_RTOL 1e-10
/* q must be at rest to this relative tolerance (see check_rest). */
#define EOM_LIN_REST_TOL 1e-6
/* K = -(d2L/dq2 + dQ/dq + ...) counts as symmetric when max |K - K^T| is
 * at most this fraction of max |K|: the sweeps give each entry to
 * rounding, so a conservative model lands near 1e-16. */
#define EOM_LIN_SYM_RTOL 1e-9

void eom_linear_free(eom_linear *lin)
{
    if (!lin)
        return;
    free(lin->M);
    free(lin->K);
    free(lin->D);
    free(lin->N);
    free(lin->Mr);
    free(lin->Kr);
    free(lin->Dr);
    free(lin->omega);
    free(lin->modes);
    memset(lin, 0, sizeof *lin);
}

/* Scratch of one call, carved from one allocation. */
typedef struct lin_work {
    double *x;    /* 2n  (q, 0) */
    double *g;    /* 2n  gradient of L at x; g[0..n) = dL/dq + Q */
    double *Q;    /* n  the forces at rest Q(q, 0) */
    double *P;    /* n x n  dQ/dq at (q, 0) */
    double *Pd;   /* n x n  dQ/dqd at (q, 0) */
    double *xq;   /* 2n  scratch of the force sweeps */
    double *H;    /* 2n x n  Hessian columns of L on q; rows 0..n) d2L/dq2 */
    double *HR;   /* 2n x n  Hessian columns of R on qd */
    double *eye;  /* n x n  identity: directions for the constraint term */
    double *Hphi; /* n x n  sum_k lambda_k d2phi_k/dq2 */
    double *a;    /* n x m  C^T column-major; destroyed by the SVD */
    double *sv;   /* min(n, m) singular values, descending */
    double *u;    /* n x n  left singular vectors of C^T, column-major */
    double *vt;   /* m x m  V^T, column-major */
    double *lam;  /* m */
    double *t;    /* n x n  products; eigenproblem copies */
    double *t2;   /* n x n */
} lin_work;

static double *work_new(lin_work *w, int n, int m)
{
    const size_t N = (size_t)n, M = (size_t)m, k = N < M ? N : M;
    const size_t total = 7 * N + 4 * N * N + 7 * N * N + N * M + k + M * M +
                         M;
    double *p = calloc(total ? total : 1, sizeof(double)), *c = p;
    if (!p)
        return NULL;
    w->x = c, c += 2 * N;
    w->g = c, c += 2 * N;
    w->Q = c, c += N;
    w->xq = c, c += 2 * N;
    w->P = c, c += N * N;
    w->Pd = c, c += N * N;
    w->H = c, c += 2 * N * N;
    w->HR = c, c += 2 * N * N;
    w->eye = c, c += N * N;
    w->Hphi = c, c += N * N;
    w->u = c, c += N * N;
    w->t = c, c += N * N;
    w->t2 = c, c += N * N;
    w->a = c, c += N * M;
    w->sv = c, c += k;
    w->vt = c, c += M * M;
    w->lam = c;
    return p;
}

/* X := (X + X^T) / 2 for X n x n: removes the rounding asymmetry of the
 * sweeps, so LAPACK's choice of triangle does not matter. */
static void symmetrize(double *X, int n)
{
    int i, j;
    for (i = 0; i < n; i++)
        for (j = 0; j < i; j++) {
            double v = 0.5 * (X[i * n + j] + X[j * n + i]);
            X[i * n + j] = X[j * n + i] = v;
        }
}

/* The SVD of C^T (n x m, column-major in w->a, destroyed): w->sv, all of
 * U (w->u) and V^T (w->vt). */
static int svd_ct(eom_system *s, lin_work *w)
{
    return eom__svd(s, s->n, s->m, w->a, w->sv, w->u, w->vt,
                    "the constraint Jacobian");
}

/* q must lie on the constraints: each |phi_k|, divided by the length of
 * its row of C (a distance in q, whatever the scale of phi_k), at most
 * EOM_LIN_REST_TOL max(1, |q|). A zero row (a singular configuration) is
 * measured with the largest row instead. */
static int check_on_manifold(eom_system *s, const double *q)
{
    const int n = s->n, m = s->m;
    const double qs = fmax(1.0, eom__maxabs(q, (size_t)n));
    double cmax = 0.0;
    int i, k;
    for (k = 0; k < m; k++) {
        double r = 0.0;
        for (i = 0; i < n; i++)
            r = hypot(r, s->C[k * n + i]);
        cmax = fmax(cmax, r);
    }
    for (k = 0; k < m; k++) {
        double r = 0.0, d;
        for (i = 0; i < n; i++)
            r = hypot(r, s->C[k * n + i]);
        if (r == 0.0)
            r = cmax > 0.0 ? cmax : 1.0;
        d = fabs(s->phi[k]) / r;
        if (!(d <= EOM_LIN_REST_TOL * qs))
            return eom__fail(s, EOM_ERR_ARG,
                             "eom_linearize: q does not satisfy constraint "
                             "%d (phi = %.3g, a distance of %.3g); project "
                             "it with eom_project or solve for it with "
                             "eom_equilibrium", k + 1, s->phi[k], d);
    }
    return EOM_OK;
}

/* The system must be at rest at q: the unbalanced generalized force
 * r = dL/dq + Q + C^T lambda (w->g holds dL/dq + Q; lambda the least-squares multipliers, so r is
 * what no constraint force can cancel) must satisfy
 *     max |r| <= EOM_LIN_REST_TOL (max |dL/dq| + max |K| max(1, |q|)).
 * The K term is the force of a unit displacement: near an unconstrained
 * equilibrium dL/dq itself is small, and this keeps the test relative. */
static int check_rest(eom_system *s, const double *q, const lin_work *w,
                      const double *K)
{
    const int n = s->n, m = s->m;
    const double scale = eom__maxabs(w->g, (size_t)n) +
                         eom__maxabs(K, (size_t)n * (size_t)n) *
                             fmax(1.0, eom__maxabs(q, (size_t)n));
    double worst = 0.0;
    int i, k, at = 0;
    for (i = 0; i < n; i++) {
        double r = w->g[i];
        for (k = 0; k < m; k++)
            r += s->C[k * n + i] * w->lam[k];
        if (!(fabs(r) <= worst)) {
            worst = fabs(r);
            at = i;
        }
    }
    if (!(worst <= EOM_LIN_REST_TOL * scale))
        return eom__fail(s, EOM_ERR_ARG,
                         "eom_linearize: q is not an equilibrium: the "
                         "generalized force on %s is unbalanced by %.3g "
                         "(relative %.3g); solve for q with eom_equilibrium",
                         s->coords[at].name, worst,
                         scale > 0.0 ? worst / scale : INFINITY);
    return EOM_OK;
}

/* Constraints at q: C, phi, the rank, the null-space basis in w->u
 * (columns rank .. n-1) and the minimum-norm multipliers of C^T lambda =
 * -(dL/dq + Q) in w->lam. */
static int constraint_part(eom_system *s, const double *q, lin_work *w,
                           int *rank)
{
    const int n = s->n, m = s->m, kmin = n < m ? n : m;
    int rc, i, j, r = 0;
    *rank = 0;
    if ((rc = eom__constraints_at(s, s->time, q)) != EOM_OK)
        return rc;
    if ((rc = check_on_manifold(s, q)) != EOM_OK)
        return rc;
    memcpy(w->a, s->C, (size_t)m * (size_t)n * sizeof(double));
    if ((rc = svd_ct(s, w)) != EOM_OK)
        return rc;
    while (r < kmin && w->sv[r] > EOM_LIN_RANK_RTOL * w->sv[0])
        r++;
    /* lambda = sum over i < rank of v_i (u_i . (-g)) / s_i, with v_i the
     * i-th column of V: component j at vt[i + j m] */
    for (j = 0; j < m; j++)
        w->lam[j] = 0.0;
    for (i = 0; i < r; i++) {
        double c = 0.0;
        for (j = 0; j < n; j++)
            c -= w->u[(size_t)i * (size_t)n + (size_t)j] * w->g[j];
        c /= w->sv[i];
        for (j = 0; j < m; j++)
            w->lam[j] += w->vt[i + j * m] * c;
    }
    *rank = r;
    return EOM_OK;
}

/* Xr = N^T X N (nr x nr) with N n x nr and X n x n, all row-major; t is
 * n x nr scratch. sym: symmetrize Xr (X is symmetric but for rounding). */
static void reduce(int n, int nr, const double *N, const double *X,
                   double *t, double *Xr, bool sym)
{
    int i, j, k;
    for (i = 0; i < n; i++)
        for (j = 0; j < nr; j++) {
            double v = 0.0;
            for (k = 0; k < n; k++)
                v += X[i * n + k] * N[k * nr + j];
            t[i * nr + j] = v;
        }
    for (i = 0; i < nr; i++)
        for (j = 0; j < nr; j++) {
            double v = 0.0;
            for (k = 0; k < n; k++)
                v += N[k * nr + i] * t[k * nr + j];
            Xr[i * nr + j] = v;
        }
    if (sym)
        symmetrize(Xr, nr);
}

/* EOM_ERR_MODEL when the forces leave K unsymmetric beyond
 * EOM_LIN_SYM_RTOL, naming the pair of coordinates with the largest
 * difference. */
static int check_symmetric(eom_system *s, const double *K)
{
    const int n = s->n;
    const double big = eom__maxabs(K, (size_t)n * (size_t)n);
    double worst = 0.0;
    int i, j, wi = 0, wj = 0;
    for (i = 0; i < n; i++)
        for (j = 0; j < i; j++) {
            const double d = fabs(K[i * n + j] - K[j * n + i]);
            if (d > worst) {
                worst = d;
                wi = i;
                wj = j;
            }
        }
    if (worst <= EOM_LIN_SYM_RTOL * big)
        return EOM_OK;
    return eom__fail(s, EOM_ERR_MODEL,
                     "eom_linearize: the forces make the stiffness "
                     "unsymmetric: dQ/dq couples %s and %s unequally "
                     "(K differs from its transpose by %.3g, relative "
                     "%.3g; a follower or circulatory force); there are no "
                     "undamped natural frequencies, the eigenvalues of "
                     "eom_linearize_state describe the motion",
                     s->coords[wi].name, s->coords[wj].name, worst,
                     worst / big);
}

/* Kr z = e Mr z by dsygv: omega from e, modes = N Z (n x nr), each mode
 * with its largest component positive. a and b are nr x nr scratch. */
static int eigen(eom_system *s, eom_linear *lin, double *a, double *b)
{
    const int n = lin->n, nr = lin->nr, itype = 1;
    int lwork = -1, info = 0, i, j, k;
    double query = 0.0, *work;
    memcpy(a, lin->Kr, (size_t)nr * (size_t)nr * sizeof(double));
    memcpy(b, lin->Mr, (size_t)nr * (size_t)nr * sizeof(double));
    dsygv_(&itype, "V", "L", &nr, a, &nr, b, &nr, lin->omega, &query, &lwork,
           &info, 1, 1);
    if (info != 0)
        return eom__fail(s, EOM_ERR_LINALG, "dsygv: argument %d", -info);
    lwork = (int)query;
    work = malloc((size_t)(lwork > 1 ? lwork : 1) * sizeof(double));
    if (!work)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    dsygv_(&itype, "V", "L", &nr, a, &nr, b, &nr, lin->omega, work, &lwork,
           &info, 1, 1);
    free(work);
    if (info < 0)
        return eom__fail(s, EOM_ERR_LINALG, "dsygv: argument %d", -info);
    if (info > nr)
        return eom__fail(s, EOM_ERR_SINGULAR_MASS,
                         "the reduced mass matrix is not positive definite "
                         "(leading minor of order %d)", info - nr);
    if (info > 0)
        return eom__fail(s, EOM_ERR_LINALG,
                         "dsygv: the eigenproblem did not converge (%d)",
                         info);
    for (i = 0; i < nr; i++) {
        const double e = lin->omega[i];
        double big = 0.0;
        lin->omega[i] = e >= 0.0 ? sqrt(e) : -sqrt(-e);
        /* eigenvector i is column i of the column-major a */
        for (k = 0; k < n; k++) {
            double v = 0.0;
            for (j = 0; j < nr; j++)
                v += lin->N[k * nr + j] * a[j + i * nr];
            lin->modes[k * nr + i] = v;
            if (fabs(v) > fabs(big))
                big = v;
        }
        if (big < 0.0)
            for (k = 0; k < n; k++)
                lin->modes[k * nr + i] = -lin->modes[k * nr + i];
    }
    return EOM_OK;
}

static int alloc_reduced(eom_system *s, eom_linear *lin)
{
    const size_t n = (size_t)lin->n, r = (size_t)lin->nr;
    const size_t nr1 = r ? r : 1, rr1 = r ? r * r : 1;
    lin->N = calloc(n * nr1, sizeof(double));
    lin->Mr = calloc(rr1, sizeof(double));
    lin->Kr = calloc(rr1, sizeof(double));
    lin->Dr = calloc(rr1, sizeof(double));
    lin->omega = calloc(nr1, sizeof(double));
    lin->modes = calloc(n * nr1, sizeof(double));
    if (!lin->N || !lin->Mr || !lin->Kr || !lin->Dr || !lin->omega ||
        !lin->modes)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    return EOM_OK;
}

static int linearize(eom_system *s, const double *q, eom_linear *lin,
                     lin_work *w)
{
    const int n = s->n, m = s->m;
    int rc, st, i, j, rank = 0;
    double L;

    memcpy(w->x, q, (size_t)n * sizeof(double));
    st = tp_hessian_cols(s->tL.ws, w->x, 0, 0, n, w->g, w->H);
    if ((rc = eom__tape_status(s, st, "the Hessian of the Lagrangian")))
        return rc;
    st = tp_lagrange(s->tL.ws, w->x, 0, &L, NULL, lin->M, NULL);
    if ((rc = eom__tape_status(s, st, "the Lagrangian or the mass matrix")))
        return rc;
    symmetrize(lin->M, n);
    if ((rc = eom__forces_at_rest(s, q, w->xq, w->Q, w->P, w->Pd)) !=
        EOM_OK)
        return rc;
    for (i = 0; i < n; i++)
        w->g[i] += w->Q[i];
    if (m > 0) {
        if ((rc = constraint_part(s, q, w, &rank)) != EOM_OK)
            return rc;
        for (i = 0; i < n; i++)
            w->eye[i * n + i] = 1.0;
        st = tp_hvp(s->tphi.ws, q, w->lam, n, w->eye, NULL, w->Hphi);
        if ((rc = eom__tape_status(s, st, "the constraint curvature")))
            return rc;
    }
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++)
            lin->K[i * n + j] =
                -(w->H[i * n + j] + w->P[i * n + j] + w->Hphi[i * n + j]);
    if ((rc = check_symmetric(s, lin->K)) != EOM_OK)
        return rc;
    symmetrize(lin->K, n);
    if ((rc = check_rest(s, q, w, lin->K)) != EOM_OK)
        return rc;
    if (s->has_R) {
        st = tp_hessian_cols(s->tR.ws, w->x, 0, n, n, NULL, w->HR);
        if ((rc = eom__tape_status(s, st, "the Hessian of the dissipation")))
            return rc;
        /* rows n .. 2n-1 of the qd columns: d2R/dqd2 */
        memcpy(lin->D, w->HR + (size_t)n * (size_t)n,
               (size_t)n * (size_t)n * sizeof(double));
        symmetrize(lin->D, n);
    }
    for (i = 0; i < n * n; i++)
        lin->D[i] -= w->Pd[i];

    lin->nr = n - rank;
    if ((rc = alloc_reduced(s, lin)) != EOM_OK)
        return rc;
    for (i = 0; i < n; i++)
        for (j = 0; j < lin->nr; j++)
            lin->N[i * lin->nr + j] =
                m > 0 ? w->u[(size_t)(rank + j) * (size_t)n + (size_t)i]
                      : (double)(i == j);
    if (lin->nr == 0)
        return EOM_OK;
    reduce(n, lin->nr, lin->N, lin->M, w->t, lin->Mr, true);
    reduce(n, lin->nr, lin->N, lin->K, w->t, lin->Kr, true);
    reduce(n, lin->nr, lin->N, lin->D, w->t, lin->Dr, !s->has_Q);
    if ((rc = eigen(s, lin, w->t, w->t2)) != EOM_OK)
        return rc;
    if (!eom__finite(lin->omega, (size_t)lin->nr) ||
        !eom__finite(lin->modes, (size_t)n * (size_t)lin->nr))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "the frequencies or mode shapes are not finite");
    return EOM_OK;
}

/* lin's previous contents are not freed: pass a zeroed or freed struct.
 * On failure lin is left zeroed (nothing to free). */
int eom_linearize(eom_system *s, const double *q, eom_linear *lin)
{
    lin_work w;
    double *block;
    int rc;
    if (lin)
        memset(lin, 0, sizeof *lin);
    if (!s)
        return EOM_ERR_NULL;
    if (!q || !lin)
        return eom__fail(s, EOM_ERR_NULL, "eom_linearize: q or lin is NULL");
    if (!eom__finite(q, (size_t)s->n))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "eom_linearize: q is not finite");
    if ((rc = eom__refuse_time(s, "eom_linearize")) != EOM_OK ||
        (rc = eom__refuse_velocity(s, "eom_linearize")) != EOM_OK ||
        (rc = eom__refuse_forces_time(s, "eom_linearize")) != EOM_OK)
        return rc;
    lin->n = s->n;
    lin->M = calloc((size_t)s->n * (size_t)s->n, sizeof(double));
    lin->K = calloc((size_t)s->n * (size_t)s->n, sizeof(double));
    lin->D = calloc((size_t)s->n * (size_t)s->n, sizeof(double));
    block = work_new(&w, s->n, s->m);
    if (!lin->M || !lin->K || !lin->D || !block)
        rc = eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    else
        rc = linearize(s, q, lin, &w);
    free(block);
    if (rc != EOM_OK)
        eom_linear_free(lin);
    else
        s->msg[0] = '\0';
    return rc;
}
