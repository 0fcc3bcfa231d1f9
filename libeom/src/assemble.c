/* assemble.c - a closed loop assembled from the coordinates the user
 * gives (eom_assemble): the free coordinates by Gauss-Newton steps of
 * least norm on phi(q) = 0, the free rates by one least-norm solve of the
 * velocity constraints. Least norm (LAPACK dgelss, an SVD) because the
 * free coordinates may outnumber the rows and rows may be redundant; run
 * once at a start, so dense. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"

#define ASSEMBLE_ITERS 50

typedef struct assembly {
    eom_system *s;
    const int *held;
    int n, m, mh, nf;
    int *free_of;       /* [nf] the free coordinates */
    double *C, *phi, *A, *b, *sv, *work, *x;
    int lwork;
} assembly;

/* Least-norm solution of A_f d = -r (rows rows of C's free columns):
 * d (nf) in a->b's first nf entries. */
static int least_norm(assembly *a, int rows, const double *r)
{
    const int one = 1, ldb = rows > a->nf ? rows : a->nf;
    const double rcond = 1e-12;
    int i, k, rank = 0, info = 0;
    /* column-major rows x nf */
    for (k = 0; k < a->nf; k++)
        for (i = 0; i < rows; i++)
            a->A[(size_t)k * rows + i] =
                a->C[(size_t)i * a->n + a->free_of[k]];
    for (i = 0; i < ldb; i++)
        a->b[i] = i < rows ? -r[i] : 0.0;
    dgelss_(&rows, &a->nf, &one, a->A, &rows, a->b, &ldb, a->sv, &rcond,
            &rank, a->work, &a->lwork, &info);
    if (info != 0)
        return eom__fail(a->s, EOM_ERR_LINALG, "assembly: dgelss: %s %d",
                         info < 0 ? "argument" : "no convergence, info",
                         info < 0 ? -info : info);
    return EOM_OK;
}

static double maxabs(const double *v, int n, int *at)
{
    double m = 0.0;
    int i;
    *at = 0;
    for (i = 0; i < n; i++)
        if (!(fabs(v[i]) <= m)) { /* NaN wins */
            m = fabs(v[i]);
            *at = i;
        }
    return m;
}

/* "th1, th2" into buf: the held coordinates, for messages. */
static void held_list(const assembly *a, char *buf, size_t len)
{
    size_t used = 0;
    int i;
    buf[0] = '\0';
    for (i = 0; i < a->n && used + 1 < len; i++)
        if (a->held[i]) {
            int k = snprintf(buf + used, len - used, "%s%s", used ? ", " : "",
                             eom_coord_name(a->s, i));
            if (k < 0)
                break;
            used += (size_t)k < len - used ? (size_t)k : len - used - 1;
        }
    if (!buf[0])
        snprintf(buf, len, "none");
}

/* phi = 0 on the free coordinates of a->x. */
static int positions(assembly *a, double tol, int *iters)
{
    double r, trial;
    int it, at, h, i, rc;
    char held[512], row[160];
    if ((rc = eom_constraint_jacobian(a->s, a->x, a->C, a->phi)) != EOM_OK)
        return rc;
    r = maxabs(a->phi, a->mh, &at);
    for (it = 0; it < ASSEMBLE_ITERS && !(r <= tol); it++) {
        double *q = a->x, step = 1.0;
        double *save = a->sv + (a->m < a->nf ? a->m : a->nf); /* scratch */
        if ((rc = least_norm(a, a->mh, a->phi)) != EOM_OK)
            return rc;
        for (i = 0; i < a->nf; i++)
            save[i] = q[a->free_of[i]];
        /* halve the step while it does not reduce max |phi| */
        for (h = 0; h < 30; h++, step *= 0.5) {
            for (i = 0; i < a->nf; i++)
                q[a->free_of[i]] = save[i] + step * a->b[i];
            rc = eom_residuals(a->s, a->x, a->phi, NULL);
            trial = rc == EOM_OK ? maxabs(a->phi, a->mh, &at) : NAN;
            if (trial < r)
                break;
        }
        if (!(trial < r)) {
            for (i = 0; i < a->nf; i++)
                q[a->free_of[i]] = save[i];
            break; /* no step reduces it: the loop cannot close here */
        }
        if ((rc = eom_constraint_jacobian(a->s, a->x, a->C, a->phi)) !=
            EOM_OK)
            return rc;
        r = maxabs(a->phi, a->mh, &at);
        if (iters)
            *iters = it + 1;
    }
    if (r <= tol)
        return EOM_OK;
    eom_residuals(a->s, a->x, a->phi, NULL);
    r = maxabs(a->phi, a->mh, &at);
    held_list(a, held, sizeof held);
    eom__row_label(a->s, at, row, sizeof row);
    return eom__fail(a->s, EOM_ERR_PROJECTION, "the loop cannot close with "
                     "the coordinates held (%s): the constraint %s stays "
                     "open by %.3g after %d iteration%s (tolerance %.3g); "
                     "the held values put the closure out of reach, or the "
                     "start is too far from it", held, row, r, it,
                     it == 1 ? "" : "s", tol);
}

/* C qd + dphi/dt = 0 on the free rates. */
static int rates(assembly *a, double tol)
{
    double *phidot = a->phi, r, scale = 1.0;
    int at, i, rc;
    char held[512], row[160];
    if ((rc = eom_constraint_jacobian(a->s, a->x, a->C, NULL)) != EOM_OK ||
        (rc = eom_residuals(a->s, a->x, NULL, phidot)) != EOM_OK)
        return rc;
    if (maxabs(phidot, a->m, &at) <= tol)
        return EOM_OK;
    if ((rc = least_norm(a, a->m, phidot)) != EOM_OK)
        return rc;
    for (i = 0; i < a->nf; i++)
        a->x[a->n + a->free_of[i]] += a->b[i];
    for (i = 0; i < a->n; i++)
        scale = fmax(scale, fabs(a->x[a->n + i]));
    if ((rc = eom_residuals(a->s, a->x, NULL, phidot)) != EOM_OK)
        return rc;
    r = maxabs(phidot, a->m, &at);
    if (r <= tol * scale)
        return EOM_OK;
    held_list(a, held, sizeof held);
    eom__row_label(a->s, at, row, sizeof row);
    return eom__fail(a->s, EOM_ERR_PROJECTION, "the rates cannot satisfy the "
                     "constraints with the rates of %s held: the velocity "
                     "form of %s stays at %.3g (the held rates contradict "
                     "the constraints)", held, row, r);
}

int eom_assemble(eom_system *s, double *x, const int *held, double tol,
                 int *iters)
{
    assembly a;
    int i, rc, k = 0, big;
    double wq;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (iters)
        *iters = 0;
    if (!x || !held)
        return eom__fail(s, EOM_ERR_NULL, "eom_assemble: NULL argument");
    if (!(tol > 0.0))
        return eom__fail(s, EOM_ERR_ARG, "eom_assemble: tolerance %g", tol);
    if (!eom__finite(x, 2 * (size_t)s->n))
        return eom__fail(s, EOM_ERR_NONFINITE, "eom_assemble: the state is "
                         "not finite");
    if (s->m == 0)
        return EOM_OK;
    memset(&a, 0, sizeof a);
    a.s = s;
    a.held = held;
    a.n = s->n;
    a.m = s->m;
    a.mh = s->mh;
    for (i = 0; i < a.n; i++)
        a.nf += !held[i];
    if (a.nf == 0)
        return eom__fail(s, EOM_ERR_ARG, "eom_assemble: every coordinate is "
                         "held: nothing is left to close the loop");
    big = a.m > a.nf ? a.m : a.nf;
    a.free_of = malloc((size_t)a.nf * sizeof *a.free_of);
    a.C = malloc((size_t)a.m * (size_t)a.n * sizeof *a.C);
    a.phi = malloc((size_t)a.m * sizeof *a.phi);
    a.A = malloc((size_t)a.m * (size_t)a.nf * sizeof *a.A);
    a.b = malloc((size_t)big * sizeof *a.b);
    a.sv = malloc(((size_t)big + (size_t)a.nf) * sizeof *a.sv);
    a.x = malloc(2 * (size_t)a.n * sizeof *a.x);
    if (!a.free_of || !a.C || !a.phi || !a.A || !a.b || !a.sv || !a.x) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "eom_assemble: out of memory");
        goto done;
    }
    for (i = 0; i < a.n; i++)
        if (!held[i])
            a.free_of[k++] = i;
    memcpy(a.x, x, 2 * (size_t)a.n * sizeof *a.x);
    /* dgelss's workspace for the larger of the two systems */
    a.lwork = -1;
    {
        const int one = 1, rows = a.m, ldb = big;
        const double rcond = 1e-12;
        int rank = 0, info = 0;
        dgelss_(&rows, &a.nf, &one, a.A, &rows, a.b, &ldb, a.sv, &rcond,
                &rank, &wq, &a.lwork, &info);
        a.lwork = info == 0 ? (int)wq + 1 : 5 * big + 64;
    }
    if (!(a.work = malloc((size_t)a.lwork * sizeof *a.work))) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "eom_assemble: out of memory");
        goto done;
    }
    if (a.mh > 0 && (rc = positions(&a, tol, iters)) != EOM_OK)
        goto done;
    if ((rc = rates(&a, tol)) != EOM_OK)
        goto done;
    memcpy(x, a.x, 2 * (size_t)a.n * sizeof *x);
    rc = EOM_OK;
done:
    free(a.free_of);
    free(a.C);
    free(a.phi);
    free(a.A);
    free(a.b);
    free(a.sv);
    free(a.x);
    free(a.work);
    return rc;
}
