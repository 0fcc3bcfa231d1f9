/* linearize_steady.c - linearization about a steady motion
 * (eom_linearize_steady, eom_steady_check; docs/linearization.md).
 *
 * A steady motion is a state x = (q, qd) where the accelerations vanish
 * while cyclic coordinates (those the right-hand side does not read: the
 * state Jacobian's column is zero) move at constant rates: a disk or a
 * bicycle rolling straight on, a top in steady precession. The state
 * Jacobian A and the constraint rows do not change along such a motion,
 * so the perturbations (dq, dqd) obey d(dx)/dt = A dx on the invariant
 * null space of the linearized constraints, dx = T z, d(z)/dt = Ar z with
 * Ar = T^T A T (eom_linearize_state: one SVD of the rows phi0, phi1 of the
 * residual tape, holonomic and velocity rows alike).
 *
 * Reduction to independent coordinates and speeds. Let K be a set of
 * states (coordinates q_i, speeds qd_i) and P its selection: y = P T z.
 * When W = null(P T) is invariant under Ar (P T Ar w = 0 for w in W: the
 * directions K does not see never act on what it does), y obeys the
 * closed system y' = Ary y, Ary = (P T) Ar (P T)^+, whose eigenvalues are
 * those of Ar with the ones of Ar on W taken out. Chosen automatically,
 * K starts from every coordinate that is not cyclic and every speed; a
 * speed alone, then a coordinate with its speed or a coordinate alone (in
 * the model's order) is dropped when W stays invariant and every
 * eigenvalue of Ar on W is zero (|e| <= ZERO_TOL times the largest entry
 * of Ar): a heading, a position on the plane, a wheel angle, a forward
 * speed or a rate the constraints determine. What is left keeps its
 * states that are independent on the null space (Gram-Schmidt on the rows
 * of P T, coordinates first, then speeds, in the model's order). For the
 * Whipple bicycle that is lean, steer and their rates. A set named by
 * the caller is checked (independent, W invariant) and taken as given;
 * the eigenvalues of Ar on W are reported as dropped either way.
 *
 * Tolerances: a row of P T is independent of the rows before it when its
 * remainder has a norm above INDEP_TOL (the rows of T are at most of unit
 * length); W is invariant when max |P T Ar N_W| <= CLOSE_TOL max |Ar|.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"
#include "eom/steady.h"

#define STEADY_RTOL 1e-8 /* max |qdd| against the size of its terms */
#define CYCLIC_TOL 1e-12 /* a zero column of A, relative to max |A| */
#define INDEP_TOL 1e-8
#define CLOSE_TOL 1e-9
#define ZERO_TOL 1e-6

void eom_steady_linear_free(eom_steady_linear *lin)
{
    if (!lin)
        return;
    eom_state_linear_free(&lin->full);
    free(lin->kept);
    free(lin->cyclic);
    free(lin->Ar);
    free(lin->eig_re);
    free(lin->eig_im);
    free(lin->drop_re);
    free(lin->drop_im);
    memset(lin, 0, sizeof *lin);
}

int eom_steady_check(eom_system *s, double t, const double *x, double *acc,
                     double *scale, int *at)
{
    const int n = s ? s->n : 0, m = s ? s->m : 0;
    double *xd = NULL, *w = NULL, worst = 0.0, big = 0.0;
    int i, j, k, rc, where = 0;
    if (acc)
        *acc = 0.0;
    if (scale)
        *scale = 0.0;
    if (at)
        *at = 0;
    if (!s)
        return EOM_ERR_NULL;
    if (!x)
        return eom__fail(s, EOM_ERR_NULL, "eom_steady_check: x is NULL");
    xd = malloc((2 * (size_t)n + 1) * sizeof *xd);
    w = malloc((4 * (size_t)n * (size_t)n + 1) * sizeof *w);
    if (!xd || !w) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "out of memory");
        goto done;
    }
    /* the acceleration of a unit change of the state (near an
     * equilibrium of forces that vanish there, dL/dq itself is small):
     * max |d(qdd)/dx| max(1, max |x|), as eom_linearize's rest test */
    if ((rc = eom_state_jacobian(s, t, x, w)) != EOM_OK)
        goto done;
    big = eom__maxabs(w + 2 * (size_t)n * (size_t)n, 2 * (size_t)n * (size_t)n) *
          fmax(1.0, eom__maxabs(x, 2 * (size_t)n));
    if ((rc = eom_rhs(s, t, x, xd)) != EOM_OK)
        goto done;
    /* the size of the terms: each of M^-1 dL/dq, M^-1 h, M^-1 Qv and the
     * constraint forces' M^-1 C^T lambda, by its absolute values */
    memcpy(w, s->g, (size_t)n * sizeof *w);
    memcpy(w + n, s->h, (size_t)n * sizeof *w);
    memcpy(w + 2 * (size_t)n, s->Qv, (size_t)n * sizeof *w);
    if ((rc = eom__mass_solve(s, w, 3)) != EOM_OK)
        goto done;
    for (i = 0; i < n; i++) {
        double sz = 0.0;
        for (k = 0; k < 3; k++)
            sz += fabs(w[(size_t)k * n + i]);
        for (j = 0; j < m; j++)
            sz += fabs(s->Y[(size_t)j * n + i] * s->lam[j]);
        big = fmax(big, sz);
        if (fabs(xd[n + i]) > worst) {
            worst = fabs(xd[n + i]);
            where = i;
        }
    }
    if (acc)
        *acc = worst;
    if (scale)
        *scale = big;
    if (at)
        *at = where;
    if (!(worst <= STEADY_RTOL * big))
        rc = eom__fail(s, EOM_ERR_ARG,
                       "the start is neither at rest nor a steady motion: "
                       "the largest acceleration is %s_ddot = %.6g "
                       "(relative to its terms %.3g, more than %g)",
                       s->coords[where].name, xd[n + where],
                       big > 0.0 ? worst / big : INFINITY, STEADY_RTOL);
    else
        s->msg[0] = '\0';
done:
    free(xd);
    free(w);
    return rc;
}

/* Eigenvalues of the row-major k x k A into re, im, sorted by real part,
 * then imaginary part (real parts within 1e-12 of the largest modulus
 * count as equal, as in eom_linearize_state). */
static int eig(eom_system *s, int k, const double *A, double *re, double *im)
{
    int lwork = -1, info = 0, one = 1, i, j;
    double query = 0.0, dummy = 0.0, *a, *work;
    if (k == 0)
        return EOM_OK;
    a = malloc((size_t)k * k * sizeof *a);
    if (!a)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    for (i = 0; i < k; i++)
        for (j = 0; j < k; j++)
            a[(size_t)j * k + i] = A[(size_t)i * k + j];
    dgeev_("N", "N", &k, a, &k, re, im, &dummy, &one, &dummy, &one, &query,
           &lwork, &info, 1, 1);
    lwork = info == 0 ? (int)query : 1;
    work = malloc((size_t)(lwork > 1 ? lwork : 1) * sizeof *work);
    if (!work) {
        free(a);
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    }
    if (info == 0)
        dgeev_("N", "N", &k, a, &k, re, im, &dummy, &one, &dummy, &one,
               work, &lwork, &info, 1, 1);
    free(work);
    free(a);
    if (info != 0)
        return eom__fail(s, EOM_ERR_LINALG,
                         "dgeev: the eigenvalues of the steady motion's "
                         "reduced matrix did not converge (info %d)", info);
    eom__sort_eig(k, re, im);
    return EOM_OK;
}

/* Scratch of one call; nz the reduced states, n2 = 2n. */
typedef struct st_work {
    int n2, nz;
    const double *T, *Ar; /* 2n x nz, nz x nz (borrowed from full) */
    double scale;         /* max |Ar| */
    double *PT;   /* n2 x nz  the rows of T in the set */
    double *a;    /* n2 x nz  column-major copy for the SVD */
    double *sv;   /* nz */
    double *U;    /* n2 x n2 */
    double *VT;   /* nz x nz */
    double *NW;   /* nz x nz  basis of W, row-major nz x dim */
    double *X;    /* nz x nz  products */
    double *Y;    /* nz x nz */
    double *re, *im; /* nz */
} st_work;

/* The rows of T for the states flagged in keep (n2 flags) into w->PT;
 * returns their count. */
static int rows_of(st_work *w, const unsigned char *keep)
{
    int i, j, c = 0;
    for (i = 0; i < w->n2; i++)
        if (keep[i]) {
            for (j = 0; j < w->nz; j++)
                w->PT[(size_t)c * w->nz + j] = w->T[(size_t)i * w->nz + j];
            c++;
        }
    return c;
}

/* W = null(P T) for the set keep: its basis (nz x *dim, row-major) in
 * w->NW. */
static int null_space(eom_system *s, st_work *w, const unsigned char *keep,
                      int *dim)
{
    const int nz = w->nz, c = rows_of(w, keep);
    int i, j, r = 0, rc;
    if (c == 0) {
        memset(w->NW, 0, (size_t)nz * nz * sizeof *w->NW);
        for (i = 0; i < nz; i++)
            w->NW[(size_t)i * nz + i] = 1.0;
        *dim = nz;
        return EOM_OK;
    }
    for (i = 0; i < c; i++)
        for (j = 0; j < nz; j++)
            w->a[(size_t)j * c + i] = w->PT[(size_t)i * nz + j];
    if ((rc = eom__svd(s, c, nz, w->a, w->sv, w->U, w->VT,
                       "the kept states")) != EOM_OK)
        return rc;
    for (i = 0; i < (c < nz ? c : nz); i++)
        if (w->sv[i] > INDEP_TOL)
            r++;
    *dim = nz - r;
    for (i = 0; i < nz; i++)
        for (j = 0; j < *dim; j++)
            w->NW[(size_t)i * *dim + j] = w->VT[(size_t)(r + j) + (size_t)i * nz];
    return EOM_OK;
}

/* The largest entry of P T Ar N_W for the set keep (W from null_space,
 * dim columns), and the row (state index) where it is. */
static double leak(st_work *w, const unsigned char *keep, int dim, int *at)
{
    const int nz = w->nz;
    double worst = 0.0;
    int i, j, k;
    /* X = Ar N_W (nz x dim) */
    for (i = 0; i < nz; i++)
        for (j = 0; j < dim; j++) {
            double v = 0.0;
            for (k = 0; k < nz; k++)
                v += w->Ar[(size_t)i * nz + k] * w->NW[(size_t)k * dim + j];
            w->X[(size_t)i * dim + j] = v;
        }
    for (i = 0; i < w->n2; i++) {
        if (!keep[i])
            continue;
        for (j = 0; j < dim; j++) {
            double v = 0.0;
            for (k = 0; k < nz; k++)
                v += w->T[(size_t)i * nz + k] * w->X[(size_t)k * dim + j];
            if (fabs(v) > worst) {
                worst = fabs(v);
                if (at)
                    *at = i;
            }
        }
    }
    return worst;
}

/* The eigenvalues of Ar on W (N_W^T Ar N_W, after leak filled X = Ar N_W)
 * into w->re, w->im. */
static int eig_on_w(eom_system *s, st_work *w, int dim)
{
    const int nz = w->nz;
    int i, j, k;
    for (i = 0; i < dim; i++)
        for (j = 0; j < dim; j++) {
            double v = 0.0;
            for (k = 0; k < nz; k++)
                v += w->NW[(size_t)k * dim + i] * w->X[(size_t)k * dim + j];
            w->Y[(size_t)i * dim + j] = v;
        }
    return eig(s, dim, w->Y, w->re, w->im);
}

/* May the set keep stand: W invariant and, when zero is set, every
 * eigenvalue on it zero. *ok receives the answer. */
static int droppable(eom_system *s, st_work *w, const unsigned char *keep,
                     int zero, int *ok)
{
    int dim, rc, i;
    *ok = 0;
    if ((rc = null_space(s, w, keep, &dim)) != EOM_OK)
        return rc;
    if (leak(w, keep, dim, NULL) > CLOSE_TOL * w->scale)
        return EOM_OK;
    if (zero) {
        if ((rc = eig_on_w(s, w, dim)) != EOM_OK)
            return rc;
        for (i = 0; i < dim; i++)
            if (hypot(w->re[i], w->im[i]) > ZERO_TOL * w->scale)
                return EOM_OK;
    }
    *ok = 1;
    return EOM_OK;
}

/* Drop what the automatic choice drops from keep (see the top): each
 * speed alone first (a rate the others determine, a forward speed), then
 * each coordinate with its speed, or alone. Speeds go first so that a
 * coordinate is not dropped for a speed it determines (a bicycle's steer
 * angle for its yaw rate). */
static int choose(eom_system *s, st_work *w, unsigned char *keep)
{
    const int n = s->n;
    int i, ok, rc;
    for (i = 0; i < n; i++) {
        if (!keep[n + i])
            continue;
        keep[n + i] = 0;
        if ((rc = droppable(s, w, keep, 1, &ok)) != EOM_OK)
            return rc;
        if (!ok)
            keep[n + i] = 1;
    }
    for (i = 0; i < n; i++) {
        if (!keep[i])
            continue;
        keep[i] = 0;
        if (keep[n + i]) {
            keep[n + i] = 0;
            if ((rc = droppable(s, w, keep, 1, &ok)) != EOM_OK)
                return rc;
            if (ok)
                continue;
            keep[n + i] = 1;
        }
        if ((rc = droppable(s, w, keep, 1, &ok)) != EOM_OK)
            return rc;
        if (!ok)
            keep[i] = 1;
    }
    return EOM_OK;
}

/* The states of keep whose rows of T are independent of the rows before
 * them, in state order (coordinates, then speeds), into lin->kept;
 * flags the others off in keep. Modified Gram-Schmidt, twice. */
static int independent(eom_system *s, st_work *w, unsigned char *keep,
                       eom_steady_linear *lin)
{
    const int nz = w->nz;
    double *basis = w->X, *v = w->re;
    int i, j, k, pass, c = 0;
    lin->kept = malloc((size_t)(w->n2 ? w->n2 : 1) * sizeof *lin->kept);
    if (!lin->kept)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    for (i = 0; i < w->n2; i++) {
        double norm = 0.0;
        if (!keep[i])
            continue;
        memcpy(v, w->T + (size_t)i * nz, (size_t)nz * sizeof *v);
        for (pass = 0; pass < 2; pass++)
            for (k = 0; k < c; k++) {
                double d = 0.0;
                for (j = 0; j < nz; j++)
                    d += basis[(size_t)k * nz + j] * v[j];
                for (j = 0; j < nz; j++)
                    v[j] -= d * basis[(size_t)k * nz + j];
            }
        for (j = 0; j < nz; j++)
            norm = hypot(norm, v[j]);
        if (norm <= INDEP_TOL) {
            keep[i] = 0;
            continue;
        }
        for (j = 0; j < nz; j++)
            basis[(size_t)c * nz + j] = v[j] / norm;
        lin->kept[c++] = i;
    }
    lin->nr = c;
    return EOM_OK;
}

/* Ary = (P T) Ar (P T)^+ = B G^-1 with B = (P T) Ar (P T)^T and
 * G = (P T)(P T)^T (nr x nr, invertible: the rows are independent). */
static int reduced(eom_system *s, st_work *w, const unsigned char *keep,
                   eom_steady_linear *lin)
{
    const int nz = w->nz, nr = lin->nr, nr1 = nr ? nr : 1;
    double *B = NULL, *G = NULL;
    int *ipiv = NULL, i, j, k, info = 0, rc = EOM_OK;
    lin->Ar = malloc((size_t)nr1 * nr1 * sizeof *lin->Ar);
    lin->eig_re = malloc((size_t)nr1 * sizeof *lin->eig_re);
    lin->eig_im = malloc((size_t)nr1 * sizeof *lin->eig_im);
    B = malloc((size_t)nr1 * nr1 * sizeof *B);
    G = malloc((size_t)nr1 * nr1 * sizeof *G);
    ipiv = malloc((size_t)nr1 * sizeof *ipiv);
    if (!lin->Ar || !lin->eig_re || !lin->eig_im || !B || !G || !ipiv) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "out of memory");
        goto done;
    }
    if (nr == 0)
        goto done;
    rows_of(w, keep);
    /* X = Ar (P T)^T (nz x nr) */
    for (i = 0; i < nz; i++)
        for (j = 0; j < nr; j++) {
            double v = 0.0;
            for (k = 0; k < nz; k++)
                v += w->Ar[(size_t)i * nz + k] * w->PT[(size_t)j * nz + k];
            w->X[(size_t)i * nr + j] = v;
        }
    /* B^T and G, column-major for dgesv: solve G Ary^T = B^T */
    for (i = 0; i < nr; i++)
        for (j = 0; j < nr; j++) {
            double b = 0.0, g = 0.0;
            for (k = 0; k < nz; k++) {
                b += w->PT[(size_t)i * nz + k] * w->X[(size_t)k * nr + j];
                g += w->PT[(size_t)i * nz + k] * w->PT[(size_t)j * nz + k];
            }
            B[(size_t)i * nr + j] = b; /* row-major B = column-major B^T */
            G[(size_t)i * nr + j] = g; /* symmetric */
        }
    dgesv_(&nr, &nr, G, &nr, ipiv, B, &nr, &info);
    if (info != 0) {
        rc = eom__fail(s, EOM_ERR_LINALG,
                       "dgesv: the kept states' Gram matrix is singular "
                       "(info %d)", info);
        goto done;
    }
    /* column-major Ary^T is row-major Ary */
    memcpy(lin->Ar, B, (size_t)nr * nr * sizeof *B);
    rc = eig(s, nr, lin->Ar, lin->eig_re, lin->eig_im);
done:
    free(B);
    free(G);
    free(ipiv);
    return rc;
}

static void state_name(const eom_system *s, int i, char *buf, size_t len)
{
    if (i < s->n)
        snprintf(buf, len, "%s", s->coords[i].name);
    else
        snprintf(buf, len, "%s_dot", s->coords[i - s->n].name);
}

static int steady(eom_system *s, double t, const double *x, const int *names,
                  int nnames, eom_steady_linear *lin, st_work *w,
                  unsigned char *keep)
{
    const int n = s->n, n2 = 2 * n;
    double acc = 0.0, sc = 0.0, cmax;
    int i, j, rc, dim, at = 0;

    if ((rc = eom_steady_check(s, t, x, &acc, &sc, &at)) != EOM_OK)
        return rc;
    lin->acc = acc;
    lin->acc_scale = sc;
    lin->acc_at = at;
    if ((rc = eom_linearize_state(s, t, x, &lin->full)) != EOM_OK)
        return rc;
    w->n2 = n2;
    w->nz = lin->full.nz;
    w->T = lin->full.T;
    w->Ar = lin->full.Ar;
    w->scale = eom__maxabs(lin->full.Ar, (size_t)w->nz * (size_t)w->nz);
    /* cyclic coordinates: a zero column of A */
    cmax = eom__maxabs(lin->full.A, (size_t)n2 * (size_t)n2);
    for (i = 0; i < n; i++) {
        double c = 0.0;
        for (j = 0; j < n2; j++)
            c = fmax(c, fabs(lin->full.A[(size_t)j * n2 + i]));
        lin->cyclic[i] = c <= CYCLIC_TOL * cmax;
    }
    if (names) {
        for (i = 0; i < nnames; i++) {
            if (names[i] < 0 || names[i] >= n2)
                return eom__fail(s, EOM_ERR_ARG,
                                 "eom_linearize_steady: state %d is not "
                                 "one of the %d states", names[i], n2);
            if (keep[names[i]]) {
                char nm[160];
                state_name(s, names[i], nm, sizeof nm);
                return eom__fail(s, EOM_ERR_ARG,
                                 "eom_linearize_steady: %s is named twice",
                                 nm);
            }
            keep[names[i]] = 1;
        }
    } else {
        for (i = 0; i < n; i++) {
            keep[i] = !lin->cyclic[i];
            keep[n + i] = 1;
        }
        if ((rc = choose(s, w, keep)) != EOM_OK)
            return rc;
    }
    if ((rc = independent(s, w, keep, lin)) != EOM_OK)
        return rc;
    if (names && lin->nr < nnames) {
        char nm[160];
        for (i = 0; i < nnames && keep[names[i]]; i++)
            ;
        state_name(s, names[i < nnames ? i : 0], nm, sizeof nm);
        return eom__fail(s, EOM_ERR_ARG,
                         "eom_linearize_steady: %s is not independent of "
                         "the states named before it, on the constraints",
                         nm);
    }
    if ((rc = null_space(s, w, keep, &dim)) != EOM_OK)
        return rc;
    {
        double l = leak(w, keep, dim, &at);
        if (l > CLOSE_TOL * w->scale) {
            char nm[160];
            state_name(s, at, nm, sizeof nm);
            return eom__fail(s, EOM_ERR_ARG,
                             "eom_linearize_steady: the kept states are "
                             "not a closed system: the directions left "
                             "out act on %s (by %.3g against max |A| = "
                             "%.3g); keep more states", nm, l, w->scale);
        }
    }
    lin->ndrop = dim;
    lin->drop_re = malloc((size_t)(dim ? dim : 1) * sizeof *lin->drop_re);
    lin->drop_im = malloc((size_t)(dim ? dim : 1) * sizeof *lin->drop_im);
    if (!lin->drop_re || !lin->drop_im)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    if ((rc = eig_on_w(s, w, dim)) != EOM_OK)
        return rc;
    memcpy(lin->drop_re, w->re, (size_t)dim * sizeof *w->re);
    memcpy(lin->drop_im, w->im, (size_t)dim * sizeof *w->im);
    return reduced(s, w, keep, lin);
}

int eom_linearize_steady(eom_system *s, double t, const double *x,
                         const int *keep, int nkeep, eom_steady_linear *lin)
{
    const size_t n2 = s ? 2 * (size_t)s->n : 0, N = n2 ? n2 : 1;
    st_work w;
    double *block = NULL;
    unsigned char *flags = NULL;
    int rc;
    if (lin)
        memset(lin, 0, sizeof *lin);
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!x || !lin)
        return eom__fail(s, EOM_ERR_NULL,
                         "eom_linearize_steady: x or lin is NULL");
    if (keep ? nkeep < 0 : nkeep != 0)
        return eom__fail(s, EOM_ERR_ARG,
                         "eom_linearize_steady: %d states named, keep %s",
                         nkeep, keep ? "given" : "NULL");
    memset(&w, 0, sizeof w);
    lin->n = s->n;
    lin->cyclic = calloc(N, sizeof *lin->cyclic);
    flags = calloc(N, 1);
    /* PT, a: n2 x nz; U: n2 x n2; VT, NW, X, Y: nz x nz; sv, re, im */
    block = malloc((2 * N * N + N * N + 4 * N * N + 3 * N) * sizeof *block);
    if (!lin->cyclic || !flags || !block) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "out of memory");
        goto done;
    }
    w.PT = block;
    w.a = w.PT + N * N;
    w.U = w.a + N * N;
    w.VT = w.U + N * N;
    w.NW = w.VT + N * N;
    w.X = w.NW + N * N;
    w.Y = w.X + N * N;
    w.sv = w.Y + N * N;
    w.re = w.sv + N;
    w.im = w.re + N;
    rc = steady(s, t, x, keep, nkeep, lin, &w, flags);
done:
    free(block);
    free(flags);
    if (rc != EOM_OK) {
        char msg[EOM_MSG_LEN];
        memcpy(msg, s->msg, sizeof msg);
        eom_steady_linear_free(lin);
        memcpy(s->msg, msg, sizeof msg);
    } else {
        s->msg[0] = '\0';
    }
    return rc;
}
