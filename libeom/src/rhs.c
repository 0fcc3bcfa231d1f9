/* rhs.c - the right-hand side: Lagrange's equations solved for the
 * accelerations (and the multipliers of the constraints) by the
 * range-space method, and the accessors that read one evaluation.
 *
 *   F   = dL/dq - (d2L/dqd dq) qd - d2L/dqd dt - dR/dqd + Q
 *   M   = LL^T                  (Cholesky: loops of our own at every n)
 *   Y   = M^-1 C^T,  S = C Y                     (S: KLU, analyzed once,
 *                                                 refactored per call)
 *   S lambda = gamma - C M^-1 F,
 *   gamma = -(d2phi/dq2)[qd, qd] - 2 (d2phi/dq dt) qd - d2phi/dt2
 *           - 2 alpha (C qd + dphi/dt) - beta^2 phi  (Baumgarte, if enabled)
 *   qdd = M^-1 F + Y lambda
 *
 * The time terms are there only when the Lagrangian or the constraints
 * read the time (rheonomic.c); otherwise the sweeps are those of a tape
 * without time, and cost what they always did. The power s->power = dE/dt
 * of the Jacobi integral E = qd . dL/dqd - L follows from the equations:
 *   dE/dt = qd . (-dR/dqd + Q) - dL/dt + lambda . (C qd)
 * (the last term, the power of the constraint forces, is
 * -lambda . dphi/dt on the constraints; it is counted only when they read
 * the time: a fixed constraint does no work; for velocity rows, -lambda .
 * b on them, it is always counted). Velocity rows (constraints.c) enter
 * C as A = dpsi/dqd with gamma = -dpsi/ds along (qd, 0, 1) and, having no
 * position residual, phi = 0 in the Baumgarte term.
 *
 * Storage: M is symmetric, so its row-major array is also LAPACK's
 * column-major one. C (m x n, row-major) read column-major is C^T, so
 * Y = M^-1 C^T is one dpotrs with m right-hand sides on a copy of C.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"
#include "mass_route.h"

/* Below this reciprocal condition estimate of KLU's factor of S, the
 * multipliers come from a filtered SVD of S instead: redundant
 * constraints (S exactly singular) and the neighbourhood of singular
 * configurations, where the range-space solve would amplify rounding and
 * the drift of phi and C qd by 1/rcond into the accelerations. */
#define EOM_RCOND_PINV 1e-3
/* The filter: with S = U diag(sv) V^T, lambda = sum_k v_k sv_k / (sv_k^2 +
 * mu^2) u_k' b, mu = EOM_PINV_MU sv_max (Tikhonov). Directions well
 * above mu are solved exactly; those far below it are dropped; in between
 * the weight varies smoothly with the state, which the adaptive methods'
 * error control needs at a singular pass (a hard cut-off makes the
 * accelerations jump and their steps collapse). Measured on
 * tests/eom_constraints/test_parallelogram.c: 1e-7 keeps rk4, erk and bdf
 * on the branch through 40 flat passes in both formulations; 1e-9 and
 * 3e-7 each lose one of them. At the switch from KLU, a direction at
 * rcond 1e-3 is weighted by 1 - 1e-8. */
#define EOM_PINV_MU 1e-7
/* After a refactorization (fixed pivots) below this, factor afresh. */
#define EOM_RCOND_REFACTOR 1e-6

/* Up to this size a Cholesky of our own replaces LAPACK's: bench-rhs
 * measures Debian's reference dpotrf + dpotrs at 3.8 times the cost of the
 * loops below for n = 2 (123 ns against 32 ns), 2.7 times for n = 10 and
 * 2.2 times for n = 20 (docs/benchmarks.md): its call overhead dominates
 * these sizes (a fifth of a small system's whole right-hand side). Larger
 * ones go to the loops of cholesky_columns.c up to EOM_COLUMN_CHOLESKY and
 * to the blocked factor of cholesky_blocked.c above (reference LAPACK's
 * dpotrf took 5 times as long at n = 200, OpenBLAS's 0.9 times:
 * docs/benchmarks.md section 8); every solve is the column loops'. All
 * leave the factor in the same place and layout (the lower triangle,
 * column-major), so dpocon reads any of them. */
#define EOM_SMALL_CHOLESKY 16

/* The loops of the small path run a few times each: vectorized, their
 * set-up cost more than the work (a 2 x 2 solve took 312 instructions);
 * GCC keeps them plain here. */
#if defined(__GNUC__) && !defined(__clang__)
#define EOM_SCALAR_LOOPS __attribute__((optimize("no-tree-vectorize")))
#else
#define EOM_SCALAR_LOOPS
#endif
#if defined(__GNUC__)
#define EOM_INLINE_BODY static inline __attribute__((always_inline))
#define EOM_NOINLINE __attribute__((noinline))
#else
#define EOM_INLINE_BODY static inline
#define EOM_NOINLINE
#endif

/* LAPACK's dpotrf for small n, reading the lower triangle of M and
 * writing the factor's into A (the upper triangle of A is not touched:
 * nothing reads it), so no copy of M comes first: info = j + 1 at a
 * non-positive pivot. The sums run in a local, in the order of the
 * in-place loops they replace (the same roundings). */
EOM_INLINE_BODY int potrf_body(int n, const double *M, double *A)
{
    int i, j, k;
    for (j = 0; j < n; j++) {
        double d = M[j + j * n];
        for (k = 0; k < j; k++)
            d -= A[j + k * n] * A[j + k * n];
        if (!(d > 0.0))
            return j + 1;
        d = sqrt(d);
        A[j + j * n] = d;
        for (i = j + 1; i < n; i++) {
            double t = M[i + j * n];
            for (k = 0; k < j; k++)
                t -= A[i + k * n] * A[j + k * n];
            A[i + j * n] = t / d;
        }
    }
    return 0;
}

/* Solve L L^T X = B for nrhs columns of n (column-major) in place; each
 * entry is accumulated in a local and stored once. */
EOM_INLINE_BODY void potrs_body(int n, int nrhs, const double *A, double *B)
{
    int c, i, k;
    for (c = 0; c < nrhs; c++) {
        double *b = B + (size_t)c * (size_t)n;
        for (i = 0; i < n; i++) {
            double t = b[i];
            for (k = 0; k < i; k++)
                t -= A[i + k * n] * b[k];
            b[i] = t / A[i + i * n];
        }
        for (i = n; i-- > 0;) {
            double t = b[i];
            for (k = i + 1; k < n; k++)
                t -= A[k + i * n] * b[k];
            b[i] = t / A[i + i * n];
        }
    }
}

/* The factor and the solve of one size k: the bodies above with n the
 * constant k, where their loops unroll (callgrind: the general loops
 * took 206 instructions to factor and solve at n = 2, mostly loop
 * control, these 49; at n = 5, 723 and 319). One function per size,
 * never inlined, so that each saves only the registers it uses;
 * small_potrf and small_potrs call them through a table. */
#define EOM_CHOLESKY_OF_SIZE(k)                                             \
    EOM_SCALAR_LOOPS EOM_NOINLINE static int potrf_##k(const double *M,    \
                                                        double *A)          \
    {                                                                       \
        return potrf_body(k, M, A);                                         \
    }                                                                       \
    EOM_SCALAR_LOOPS EOM_NOINLINE static void potrs_##k(                   \
        int nrhs, const double *A, double *B)                               \
    {                                                                       \
        potrs_body(k, nrhs, A, B);                                          \
    }
EOM_CHOLESKY_OF_SIZE(1)
EOM_CHOLESKY_OF_SIZE(2)
EOM_CHOLESKY_OF_SIZE(3)
EOM_CHOLESKY_OF_SIZE(4)
EOM_CHOLESKY_OF_SIZE(5)
EOM_CHOLESKY_OF_SIZE(6)

EOM_SCALAR_LOOPS EOM_NOINLINE static int potrf_n(int n, const double *M,
                                                  double *A)
{
    return potrf_body(n, M, A);
}

EOM_SCALAR_LOOPS EOM_NOINLINE static void potrs_n(int n, int nrhs,
                                                   const double *A, double *B)
{
    potrs_body(n, nrhs, A, B);
}

/* The functions of each size, indexed by n. */
static int (*const potrf_of_size[])(const double *M, double *A) = {
    NULL, potrf_1, potrf_2, potrf_3, potrf_4, potrf_5, potrf_6};
static void (*const potrs_of_size[])(int nrhs, const double *A,
                                     double *B) = {
    NULL, potrs_1, potrs_2, potrs_3, potrs_4, potrs_5, potrs_6};
#define EOM_SIZES_UNROLLED 6

static int small_potrf(int n, const double *M, double *A)
{
    if (n >= 1 && n <= EOM_SIZES_UNROLLED)
        return potrf_of_size[n](M, A);
    return potrf_n(n, M, A);
}

static void small_potrs(int n, int nrhs, const double *A, double *B)
{
    if (n >= 1 && n <= EOM_SIZES_UNROLLED)
        potrs_of_size[n](nrhs, A, B);
    else
        potrs_n(n, nrhs, A, B);
}

double eom__mass_min_pivot(const eom_system *s, int *k)
{
    const size_t n = (size_t)s->n;
    double best = INFINITY;
    size_t i;
    *k = 0;
    for (i = 0; i < n; i++) {
        const double l = s->Mf[i * n + i], m = s->M[i * n + i];
        const double r = m > 0.0 ? l * l / m : 0.0;
        if (r < best) {
            best = r;
            *k = (int)i;
        }
    }
    return best;
}

/* eom__factor_mass's verdict on a factor that failed (info > 0: the
 * leading minor of that order is not positive; < 0: an argument) or,
 * when it succeeded, on its smallest pivot against the integrator's
 * floor, out of the common path (no floor, no failure). */
EOM_NOINLINE static int factor_verdict(eom_system *s, int info)
{
    int k;
    double r;
    if (info > 0)
        return eom__fail(s, EOM_ERR_SINGULAR_MASS,
                         "the mass matrix is not positive definite: the "
                         "coordinate '%s' (its leading minor of order %d "
                         "is not positive) moves only with the "
                         "coordinates before it, or has no inertia",
                         s->coords[info - 1].name, info);
    if (info < 0)
        return eom__fail(s, EOM_ERR_LINALG, "dpotrf: argument %d", -info);
    r = eom__mass_min_pivot(s, &k);
    if (r < s->mass_pivot_min) {
        s->mf_valid = false;
        return eom__fail(s, EOM_ERR_SINGULAR_MASS,
                         "the mass matrix is singular to working precision: "
                         "the coordinate '%s' (leading minor of order %d) "
                         "keeps %.2g of its inertia apart from the "
                         "coordinates before it, below %.2g (the machine's "
                         "precision over the tolerance), so its "
                         "acceleration cannot be computed to the "
                         "tolerance: a singular configuration of the "
                         "coordinates (such as Euler angles at gimbal "
                         "lock)", s->coords[k].name, k + 1, r,
                         s->mass_pivot_min);
    }
    return EOM_OK;
}

/* eom__factor_mass, inline for the evaluations of this file. */
EOM_INLINE_BODY int factor_mass(eom_system *s)
{
    const int n = s->n;
    const int info = n <= EOM_SMALL_CHOLESKY ? small_potrf(n, s->M, s->Mf)
                     : n <= EOM_COLUMN_CHOLESKY
                         ? eom__potrf_columns(n, s->M, s->Mf)
                         : eom__potrf_blocked(n, s->M, s->Mf);
    s->mf_valid = info == 0;
    /* nearly singular: the accelerations lose a digit for each decade of
     * the pivot, and past the integrator's floor they cannot be computed
     * to its tolerance (the step would shrink towards zero) */
    if (info != 0 || s->mass_pivot_min > 0.0)
        return factor_verdict(s, info);
    return EOM_OK;
}

int eom__factor_mass(eom_system *s)
{
    return factor_mass(s);
}

EOM_INLINE_BODY void mass_solve(const eom_system *s, double *B, int nrhs)
{
    if (s->n > EOM_SMALL_CHOLESKY)
        eom__potrs_columns(s->n, nrhs, s->Mf, B);
    else
        small_potrs(s->n, nrhs, s->Mf, B);
}

int eom__mass_solve(eom_system *s, double *B, int nrhs)
{
    mass_solve(s, B, nrhs);
    return EOM_OK;
}

int eom__constraints_at(eom_system *s, double t, const double *q)
{
    const int n = s->n, m = s->mh;
    int st, j;
    if (s->mv > 0) {
        int rc = eom__velocity_rows_at(s, t, q);
        if (rc != EOM_OK || m == 0)
            return rc;
    }
    if (s->tphi.tindex < 0) {
        st = tp_jacobian(s->tphi.ws, q, 0, n, s->phi, s->C);
        return eom__tape_status(s, st, "the constraints or their Jacobian");
    }
    /* the time's column too: dphi/dt, for the velocity constraint */
    st = tp_jacobian(s->tphi.ws, eom__tape_input(&s->tphi, q, t), 0, n + 1,
                     s->phi, s->Ct);
    for (j = 0; j < m; j++) {
        const double *row = s->Ct + (size_t)j * (size_t)(n + 1);
        memcpy(s->C + (size_t)j * (size_t)n, row, (size_t)n * sizeof(double));
        s->phit[j] = row[n];
    }
    return eom__tape_status(s, st, "the constraints or their Jacobian");
}

/* Factor S (Sx holds it) with KLU: the first time with pivoting, then by
 * refactorization with the same pivots, factoring afresh when those pivots
 * have become poor. */
void eom__forget(eom_system *s)
{
    if (s->knum)
        klu_free_numeric(&s->knum, &s->kc);
    s->mf_valid = false;
}

static int klu_factor_S(eom_system *s, bool fresh)
{
    if (fresh && s->knum)
        klu_free_numeric(&s->knum, &s->kc);
    if (!s->knum) {
        s->knum = klu_factor(s->Sp, s->Si, s->Sx, s->ksym, &s->kc);
        if (!s->knum) {
            s->rcond_S = 0.0; /* no estimate of a failed factorization */
            return s->kc.status == KLU_OUT_OF_MEMORY ? EOM_ERR_NOMEM
                                                     : EOM_ERR_RANK_DEFICIENT;
        }
    } else if (!klu_refactor(s->Sp, s->Si, s->Sx, s->ksym, s->knum,
                             &s->kc)) {
        s->rcond_S = 0.0;
        return s->kc.status == KLU_OUT_OF_MEMORY ? EOM_ERR_NOMEM
                                                 : EOM_ERR_RANK_DEFICIENT;
    }
    if (!klu_rcond(s->ksym, s->knum, &s->kc))
        return EOM_ERR_LINALG;
    s->rcond_S = s->kc.rcond;
    return EOM_OK;
}

/* S = U diag(sv) V^T by LAPACK's SVD (into the arrays setup_klu
 * made), and the filter's mu (see EOM_PINV_MU). */
static int factor_S_pinv(eom_system *s)
{
    const int m = s->m;
    int info = 0, k;
    memcpy(s->Sa, s->S, (size_t)m * (size_t)m * sizeof(double));
    dgesvd_("A", "A", &m, &m, s->Sa, &m, s->Ssv, s->Su, &m, s->Svt, &m,
            s->Swork, &s->Slwork, &info, 1, 1);
    if (info != 0)
        return eom__fail(s, EOM_ERR_LINALG,
                         "dgesvd of C M^-1 C^T failed (info %d)", info);
    s->S_mu = EOM_PINV_MU * s->Ssv[0];
    /* beyond these the filter's weight is below 1e-6: skip them */
    for (k = 0; k < m && s->Ssv[k] > 1e-3 * s->S_mu; k++)
        ;
    if (k == 0)
        return eom__fail(s, EOM_ERR_RANK_DEFICIENT,
                         "the constraint Jacobian is zero here: C M^-1 C^T "
                         "has no nonzero singular value");
    s->S_rank = k;
    s->S_pinv = true;
    s->n_svd++;
    return EOM_OK;
}

int eom__factor_S(eom_system *s)
{
    const int n = s->n, m = s->m;
    int i, j, k, rc;
    if ((rc = eom__setup_klu(s)) != EOM_OK)
        return rc;
    memcpy(s->Y, s->C, (size_t)m * (size_t)n * sizeof(double));
    if ((rc = eom__mass_solve(s, s->Y, m)) != EOM_OK)
        return rc;
    for (i = 0; i < m; i++) {
        for (j = 0; j <= i; j++) {
            double a = 0.0, b = 0.0;
            for (k = 0; k < n; k++) {
                a += s->C[i * n + k] * s->Y[j * n + k];
                b += s->C[j * n + k] * s->Y[i * n + k];
            }
            /* symmetric in exact arithmetic; keep it so in rounding */
            s->S[i * m + j] = s->S[j * m + i] = 0.5 * (a + b);
        }
    }
    if (!eom__finite(s->S, (size_t)m * (size_t)m))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "C M^-1 C^T is not finite");
    memcpy(s->Sx, s->S, (size_t)m * (size_t)m * sizeof(double));
    s->S_pinv = false;
    rc = klu_factor_S(s, false);
    /* old pivots that fail or have degraded: factor afresh, with pivoting,
     * before judging the conditioning */
    if ((rc == EOM_OK && s->rcond_S < EOM_RCOND_REFACTOR) ||
        rc == EOM_ERR_RANK_DEFICIENT)
        rc = klu_factor_S(s, true);
    if (rc == EOM_ERR_NOMEM)
        return eom__fail(s, rc, "KLU: out of memory");
    if (rc == EOM_ERR_LINALG)
        return eom__fail(s, rc, "KLU: rcond failed (status %d)",
                         s->kc.status);
    if (rc != EOM_OK)
        s->rcond_S = 0.0;
    if (s->rcond_S < s->rcond_S_min)
        s->rcond_S_min = s->rcond_S;
    if (rc != EOM_OK || s->rcond_S < EOM_RCOND_PINV)
        return factor_S_pinv(s);
    return EOM_OK;
}

int eom__S_solve(eom_system *s, double *b)
{
    if (s->S_pinv) {
        /* b := V diag(sv / (sv^2 + mu^2)) U^T b over the kept directions:
         * for consistent b and sv >> mu, the least-norm solution */
        const int m = s->m;
        int i, k;
        for (k = 0; k < s->S_rank; k++) {
            double t = 0.0;
            for (i = 0; i < m; i++)
                t += s->Su[(size_t)k * (size_t)m + (size_t)i] * b[i];
            s->Sa[k] = t * s->Ssv[k] / (s->Ssv[k] * s->Ssv[k] +
                                        s->S_mu * s->S_mu);
        }
        for (i = 0; i < m; i++) {
            double t = 0.0;
            for (k = 0; k < s->S_rank; k++)
                t += s->Svt[(size_t)i * (size_t)m + (size_t)k] * s->Sa[k];
            b[i] = t;
        }
        return EOM_OK;
    }
    if (!klu_solve(s->ksym, s->knum, s->m, 1, b, &s->kc))
        return eom__fail(s, EOM_ERR_LINALG, "KLU solve failed (status %d)",
                         s->kc.status);
    return EOM_OK;
}

static double dot(const double *a, const double *b, int n)
{
    double sum = 0.0;
    int i;
    for (i = 0; i < n; i++)
        sum += a[i] * b[i];
    return sum;
}

/* The forces of a model with dissipation or forces: Qv and its power.
 * Apart from eom__nonconservative, whose common case (neither) then
 * saves no registers and inlines. */
EOM_NOINLINE static int forces_at(eom_system *s, double t, const double *x)
{
    const int n = s->n;
    int i, st, rc;
    memset(s->Qv, 0, (size_t)n * sizeof(double));
    if (s->has_R) {
        st = tp_gradient(s->tR.ws, eom__tape_input(&s->tR, x, t), 0, NULL,
                         s->gR);
        if ((rc = eom__tape_status(s, st, "the gradient of the dissipation")))
            return rc;
        for (i = 0; i < n; i++)
            s->Qv[i] = -s->gR[n + i];
    }
    if (s->has_Q) {
        st = tp_eval(s->tQ.ws, eom__tape_input(&s->tQ, x, t), s->wn);
        if ((rc = eom__tape_status(s, st, "a generalized force")))
            return rc;
        for (i = 0; i < n; i++)
            s->Qv[i] += s->wn[i];
    }
    s->power = dot(x + n, s->Qv, n);
    return EOM_OK;
}

int eom__nonconservative(eom_system *s, double t, const double *x)
{
    s->power = 0.0;
    /* neither: Qv stays as alloc_arrays made it, all +0, and its power
     * qd . Qv, a sum of signed zeros from +0, is +0 at any finite qd (the
     * callers have checked x) */
    if (!s->has_R && !s->has_Q)
        return EOM_OK;
    return forces_at(s, t, x);
}

/* eom__evaluate_free, inline for eom__evaluate. The route is asked once
 * (kept in s: mass_route.h), and on the dense one the Lagrange block and
 * the factor are called directly. */
EOM_INLINE_BODY int evaluate_free(eom_system *s, double t, const double *x,
                                  int factor)
{
    const int n = s->n;
    const bool dense = eom__mass_route(s) == EOM_MASS_DENSE;
    int i, rc;

    if (!isfinite(t) || !eom__finite(x, 2 * (size_t)n))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "the state at t = %g is not finite", t);
    /* L itself is asked for so that a state outside the model's domain
     * is an error even where the derivatives happen to stay finite; h
     * includes d2L/dqd dt; M is formed and factored each time, or once
     * when it is constant (the route: mass_route.c) */
    rc = dense ? eom__block_dense(s, t, x) : eom__lagrange_block(s, t, x);
    if (rc != EOM_OK)
        return rc;
    if ((rc = eom__nonconservative(s, t, x)) != EOM_OK)
        return rc;
    /* F = (g - h) + Qv, rounded as two steps were (Qv is +0 without
     * forces: -0 becomes +0 as before), and qdd = F, solved in place */
    for (i = 0; i < n; i++)
        s->qdd[i] = s->F[i] = s->g[i] - s->h[i] + s->Qv[i];
    s->power_t = -s->dLdt;
    if (!factor)
        return EOM_OK;
    return dense ? factor_mass(s) : eom__mass_factor(s, t, x);
}

int eom__evaluate_free(eom_system *s, double t, const double *x,
                       int factor)
{
    return evaluate_free(s, t, x, factor);
}

/* The range-space solve of a model with constraints, after
 * evaluate_free and M^-1 F in s->qdd. */
static int constrained(eom_system *s, double t, const double *x)
{
    const int n = s->n, m = s->m;
    const double *qd = x + n;
    int i, j, rc;
    /* C and phi, then C qd (+ dphi/dt) and the curvature along the
     * motion in one sweep */
    if ((rc = eom__constraints_at(s, t, x)) != EOM_OK)
        return rc;
    if ((rc = eom__constraint_rates(s, t, x, NULL, s->phid, s->gam)))
        return rc;
    for (j = 0; j < m; j++)
        s->gam[j] = -s->gam[j] - 2.0 * s->alpha * s->phid[j] -
                    s->beta * s->beta * s->phi[j];
    if ((rc = eom__factor_S(s)) != EOM_OK)
        return rc;
    for (j = 0; j < m; j++)
        s->lam[j] = s->gam[j] - dot(s->C + (size_t)j * (size_t)n,
                                    s->qdd, n);
    if ((rc = eom__S_solve(s, s->lam)) != EOM_OK)
        return rc;
    for (j = 0; j < m; j++)
        for (i = 0; i < n; i++)
            s->qdd[i] += s->Y[(size_t)j * (size_t)n + (size_t)i] *
                         s->lam[j];
    /* moving constraints do work: lambda . (C qd), the power of the
     * constraint force C^T lambda; so do velocity constraints with b
     * != 0 (lambda . (A qd) = -lambda . b on them, 0 for b = 0) */
    for (j = s->tphi.tindex >= 0 ? 0 : s->mh; j < m; j++)
        s->power_t += s->lam[j] * dot(s->C + (size_t)j * (size_t)n,
                                      qd, n);
    return EOM_OK;
}

int eom__evaluate(eom_system *s, double t, const double *x)
{
    int rc;
    if ((rc = evaluate_free(s, t, x, 1)) != EOM_OK)
        return rc;
    mass_solve(s, s->qdd, 1);
    if (s->m > 0 && (rc = constrained(s, t, x)) != EOM_OK)
        return rc;
    s->power += s->power_t;
    if (!eom__finite(s->qdd, (size_t)s->n))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "the accelerations at t = %g are not finite", t);
    return EOM_OK;
}

/* Without constraints eom__evaluate_rhs is eom__evaluate (its augmented
 * sparse solve needs constraints, kkt_sparse.c), so eom_rhs calls that
 * directly. One thread at a time: eom_rhs marks s busy for the duration of the
 * call (one uncontended atomic exchange and one store, about 4
 * instructions against 3000 for the smallest model: docs/libeom.md). A
 * second thread that enters meanwhile touches nothing of s, not even its
 * message (which the first thread owns): it returns EOM_ERR_BUSY, whose
 * text (eom_strerror) says what to do. */
int eom_rhs(eom_system *s, double t, const double *x, double *xd)
{
    int rc;
    if (!s)
        return EOM_ERR_NULL;
    if (atomic_exchange_explicit(&s->busy, 1, memory_order_acquire))
        return EOM_ERR_BUSY;
    if (!x || !xd) {
        rc = eom__fail(s, EOM_ERR_NULL, "eom_rhs: x or xd is NULL");
    } else if ((rc = s->m == 0 ? eom__evaluate(s, t, x)
                               : eom__evaluate_rhs(s, t, x)) == EOM_OK) {
        memmove(xd, x + s->n, (size_t)s->n * sizeof(double));
        memcpy(xd + s->n, s->qdd, (size_t)s->n * sizeof(double));
        s->msg[0] = '\0';
    }
    atomic_store_explicit(&s->busy, 0, memory_order_release);
    return rc;
}

int eom_mass_matrix(eom_system *s, const double *x, double *M)
{
    int st;
    double L;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!x || !M)
        return eom__fail(s, EOM_ERR_NULL, "eom_mass_matrix: NULL argument");
    if (!eom__finite(x, 2 * (size_t)s->n))
        return eom__fail(s, EOM_ERR_NONFINITE, "the state is not finite");
    st = tp_lagrange(s->tL.ws, eom__tape_input(&s->tL, x, s->time), 0, &L,
                     NULL, M, NULL);
    return eom__tape_status(s, st, "the Lagrangian or the mass matrix");
}

int eom_constraint_jacobian(eom_system *s, const double *x, double *C,
                            double *phi)
{
    int rc;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!x || !C)
        return eom__fail(s, EOM_ERR_NULL,
                         "eom_constraint_jacobian: NULL argument");
    if (s->m == 0)
        return EOM_OK;
    if (!eom__finite(x, (size_t)s->n))
        return eom__fail(s, EOM_ERR_NONFINITE, "q is not finite");
    if ((rc = eom__constraints_at(s, s->time, x)) != EOM_OK)
        return rc;
    memcpy(C, s->C, (size_t)s->m * (size_t)s->n * sizeof(double));
    if (phi)
        memcpy(phi, s->phi, (size_t)s->m * sizeof(double));
    return EOM_OK;
}

int eom_multipliers(eom_system *s, double t, const double *x,
                    double *lambda)
{
    int rc;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!x || (!lambda && s->m > 0))
        return eom__fail(s, EOM_ERR_NULL, "eom_multipliers: NULL argument");
    if ((rc = eom__evaluate_rhs(s, t, x)) != EOM_OK)
        return rc;
    if (s->m > 0)
        memcpy(lambda, s->lam, (size_t)s->m * sizeof(double));
    return EOM_OK;
}

int eom_residuals(eom_system *s, const double *x, double *phi,
                  double *phidot)
{
    int rc;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!x)
        return eom__fail(s, EOM_ERR_NULL, "eom_residuals: x is NULL");
    if (s->m == 0)
        return EOM_OK;
    if (!eom__finite(x, 2 * (size_t)s->n))
        return eom__fail(s, EOM_ERR_NONFINITE, "the state is not finite");
    if ((rc = eom__constraint_rates(s, s->time, x, s->phi, s->phid,
                                    s->gam)) != EOM_OK)
        return rc;
    if (phi)
        memcpy(phi, s->phi, (size_t)s->m * sizeof(double));
    if (phidot)
        memcpy(phidot, s->phid, (size_t)s->m * sizeof(double));
    return EOM_OK;
}

int eom_condition(eom_system *s, const double *x, double *rcond_M,
                  double *rcond_S)
{
    const int n = s ? s->n : 0;
    double anorm, *work;
    int *iwork, info = 0, rc;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!x)
        return eom__fail(s, EOM_ERR_NULL, "eom_condition: x is NULL");
    if ((rc = eom_mass_matrix(s, x, s->M)) != EOM_OK)
        return rc;
    work = malloc(3 * (size_t)n * sizeof(double));
    iwork = malloc((size_t)n * sizeof(int));
    if (!work || !iwork) {
        free(work);
        free(iwork);
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    }
    anorm = dlansy_("1", "L", &n, s->M, &n, work, 1, 1);
    rc = eom__factor_mass(s);
    if (rc == EOM_OK && rcond_M) {
        dpocon_("L", &n, s->Mf, &n, &anorm, rcond_M, work, iwork, &info, 1);
        if (info != 0)
            rc = eom__fail(s, EOM_ERR_LINALG, "dpocon: argument %d", -info);
    } else if (rc == EOM_ERR_SINGULAR_MASS && rcond_M) {
        *rcond_M = 0.0;
    }
    free(work);
    free(iwork);
    if (rc != EOM_OK)
        return rc;
    if (rcond_S) {
        *rcond_S = 1.0;
        if (s->m > 0) {
            if ((rc = eom__constraints_at(s, s->time, x)) != EOM_OK)
                return rc;
            rc = eom__factor_S(s);
            if (rc == EOM_OK && s->S_pinv && s->rcond_S == 0.0) {
                *rcond_S = 0.0; /* KLU could not factor S at all */
            } else if (rc == EOM_OK) {
                /* KLU's 1-norm condition estimate (more than the pivot
                 * ratio used to screen each step) */
                if (!klu_condest(s->Sp, s->Sx, s->ksym, s->knum, &s->kc))
                    return eom__fail(s, EOM_ERR_LINALG,
                                     "klu_condest failed");
                *rcond_S = 1.0 / s->kc.condest;
            } else if (rc == EOM_ERR_RANK_DEFICIENT) {
                *rcond_S = s->rcond_S;
            }
            return rc;
        }
    }
    return EOM_OK;
}
