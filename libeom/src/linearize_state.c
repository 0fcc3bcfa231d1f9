/* linearize_state.c - the state-space linearization about any state
 * (eom_linearize_state): A = d(xd)/dx and B = d(xd)/dp from the residual
 * tape (residual.c), reduced to the tangent space of the constraints, and
 * the eigenvalues of the reduced A.
 *
 * With constraints, a motion that starts on phi = 0 and dphi/dt = 0 stays
 * there, so its perturbations dx = (dq, dqd) satisfy
 *     C dq = 0,   (d phidot/dq) dq + C dqd = 0,
 * the rows phi0 and phi1 of the residual tape's Jacobian over (q, qd).
 * T is an orthonormal basis of the null space of those 2m rows (from one
 * SVD: a rank-deficient C is allowed, the numerical rank is counted with
 * a relative threshold of 1e-10). Ar = T^T A T and Br = T^T B. At rest,
 * T is diag(N, N) with N the null space of C, and the eigenvalues of Ar
 * are those of the damped modal problem (Mr s^2 + Dr s + Kr) v = 0 of
 * eom_linearize (tests/eom_integrate/test_jacobian.c checks it).
 *
 * A velocity constraint psi = A qd + b has the row phi1 = psi, (dpsi/dq,
 * A), and a phi0 row of zeros: it removes one dimension (a speed) from
 * the tangent space where a holonomic constraint removes two, so nz =
 * 2n - 2 mh - mv for independent rows (tests/eom_constraints/
 * test_velocity.c: the velocity form of a holonomic constraint keeps its
 * eigenvalues and adds a zero, the drift along the constraint's level
 * sets).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"

/* Relative threshold on the singular values of the constraint rows. */
#define RANK_TOL 1e-10

void eom_state_linear_free(eom_state_linear *lin)
{
    if (!lin)
        return;
    free(lin->x);
    free(lin->A);
    free(lin->B);
    free(lin->T);
    free(lin->Ar);
    free(lin->Br);
    free(lin->eig_re);
    free(lin->eig_im);
    memset(lin, 0, sizeof *lin);
}

/* C = A^T B for A (rows x ca) and B (rows x cb), all row-major. */
static void at_b(int rows, int ca, int cb, const double *A, const double *B,
                 double *C)
{
    int i, j, k;
    for (i = 0; i < ca; i++)
        for (j = 0; j < cb; j++) {
            double sum = 0.0;
            for (k = 0; k < rows; k++)
                sum += A[(size_t)k * ca + i] * B[(size_t)k * cb + j];
            C[(size_t)i * cb + j] = sum;
        }
}

/* Eigenvalues sorted by real part, then imaginary part; real parts
 * within 1e-12 of the largest modulus count as equal, so that rounding
 * does not decide the order of a conjugate pair. */
void eom__sort_eig(int n, double *re, double *im)
{
    double scale = 0.0, tol;
    int i, j;
    for (i = 0; i < n; i++)
        scale = fmax(scale, hypot(re[i], im[i]));
    tol = 1e-12 * scale;
    for (i = 1; i < n; i++)
        for (j = i; j > 0 && (re[j] < re[j - 1] - tol ||
                              (fabs(re[j] - re[j - 1]) <= tol &&
                               im[j] < im[j - 1]));
             j--) {
            double a = re[j], b = im[j];
            re[j] = re[j - 1];
            im[j] = im[j - 1];
            re[j - 1] = a;
            im[j - 1] = b;
        }
}

/* The tangent basis T (row-major 2n x nz) from the SVD of the 2m rows
 * G = [phi0; phi1] over (q, qd). */
static int tangent_basis(eom_system *s, const double *G, eom_state_linear *lin)
{
    const int n2 = 2 * s->n, m2 = 2 * s->m;
    const int ns = m2 < n2 ? m2 : n2;
    double *a = malloc((size_t)m2 * n2 * sizeof *a);
    double *sv = malloc((size_t)(ns ? ns : 1) * sizeof *sv);
    double *U = malloc((size_t)m2 * m2 * sizeof *U);
    double *VT = malloc((size_t)n2 * n2 * sizeof *VT);
    int i, j, r = 0, rc = EOM_OK;
    if (!a || !sv || !U || !VT) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (i = 0; i < m2; i++) /* to column-major */
        for (j = 0; j < n2; j++)
            a[(size_t)j * m2 + i] = G[(size_t)i * n2 + j];
    rc = eom__svd(s, m2, n2, a, sv, U, VT, "the constraints' rates");
    if (rc != EOM_OK)
        goto done;
    for (i = 0; i < ns; i++)
        if (sv[i] > RANK_TOL * sv[0])
            r++;
    lin->nz = n2 - r;
    lin->T = malloc((size_t)n2 * (size_t)(lin->nz ? lin->nz : 1) *
                    sizeof *lin->T);
    if (!lin->T) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "out of memory");
        goto done;
    }
    /* the rows r .. 2n-1 of V^T span the null space */
    for (i = 0; i < n2; i++)
        for (j = 0; j < lin->nz; j++)
            lin->T[(size_t)i * lin->nz + j] =
                VT[(size_t)i * n2 + (size_t)(r + j)];
done:
    free(a);
    free(sv);
    free(U);
    free(VT);
    return rc;
}

static int eigenvalues(eom_system *s, eom_state_linear *lin)
{
    const int nz = lin->nz;
    int lwork = -1, info = 0, one = 1, i, j;
    double query = 0.0, dummy = 0.0, *a, *work;
    if (nz == 0)
        return EOM_OK;
    a = malloc((size_t)nz * nz * sizeof *a);
    if (!a)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    for (i = 0; i < nz; i++)
        for (j = 0; j < nz; j++)
            a[(size_t)j * nz + i] = lin->Ar[(size_t)i * nz + j];
    dgeev_("N", "N", &nz, a, &nz, lin->eig_re, lin->eig_im, &dummy, &one,
           &dummy, &one, &query, &lwork, &info, 1, 1);
    lwork = info == 0 ? (int)query : 1;
    work = malloc((size_t)(lwork > 1 ? lwork : 1) * sizeof *work);
    if (!work) {
        free(a);
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    }
    if (info == 0)
        dgeev_("N", "N", &nz, a, &nz, lin->eig_re, lin->eig_im, &dummy,
               &one, &dummy, &one, work, &lwork, &info, 1, 1);
    free(work);
    free(a);
    if (info != 0)
        return eom__fail(s, EOM_ERR_LINALG,
                         "dgeev: the eigenvalues of the reduced state "
                         "matrix did not converge (info %d)", info);
    eom__sort_eig(nz, lin->eig_re, lin->eig_im);
    return EOM_OK;
}

int eom_linearize_state(eom_system *s, double t, const double *x,
                        eom_state_linear *lin)
{
    int n2, np, m, i, j, rc;
    double *G = NULL, *TA = NULL;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!x || !lin)
        return eom__fail(s, EOM_ERR_NULL,
                         "eom_linearize_state: x or lin is NULL");
    memset(lin, 0, sizeof *lin);
    n2 = 2 * s->n;
    np = s->np;
    m = s->m;
    lin->n2 = n2;
    lin->np = np;
    lin->t = t;
    lin->x = malloc((size_t)n2 * sizeof *lin->x);
    lin->A = malloc((size_t)n2 * n2 * sizeof *lin->A);
    lin->B = malloc((size_t)n2 * (np ? np : 1) * sizeof *lin->B);
    G = malloc((size_t)(m > 0 ? 2 * m : 1) * n2 * sizeof *G);
    if (!lin->x || !lin->A || !lin->B || !G) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "out of memory");
        goto done;
    }
    memcpy(lin->x, x, (size_t)n2 * sizeof *x);
    if ((rc = eom_state_jacobian(s, t, x, lin->A)) != EOM_OK)
        goto done;
    /* phi0 and phi1 rows over (q, qd), left in s->jres by that sweep
     * (rows E, phi2, phi1, phi0, P; stride 2n) */
    for (i = 0; i < m; i++)
        for (j = 0; j < n2; j++) {
            G[(size_t)i * n2 + j] =
                s->jres[(size_t)(s->n + 2 * m + i) * n2 + j];
            G[(size_t)(m + i) * n2 + j] =
                s->jres[(size_t)(s->n + m + i) * n2 + j];
        }
    if ((rc = eom_param_jacobian(s, t, x, lin->B)) != EOM_OK)
        goto done;
    if (m > 0) {
        if ((rc = tangent_basis(s, G, lin)) != EOM_OK)
            goto done;
    } else {
        lin->nz = n2;
        lin->T = calloc((size_t)n2 * n2, sizeof *lin->T);
        if (!lin->T) {
            rc = eom__fail(s, EOM_ERR_NOMEM, "out of memory");
            goto done;
        }
        for (i = 0; i < n2; i++)
            lin->T[(size_t)i * n2 + i] = 1.0;
    }
    {
        const int nz = lin->nz, nzz = nz ? nz : 1;
        lin->Ar = malloc((size_t)nzz * nzz * sizeof *lin->Ar);
        lin->Br = malloc((size_t)nzz * (np ? np : 1) * sizeof *lin->Br);
        lin->eig_re = malloc((size_t)nzz * sizeof *lin->eig_re);
        lin->eig_im = malloc((size_t)nzz * sizeof *lin->eig_im);
        TA = malloc((size_t)n2 * nzz * sizeof *TA);
        if (!lin->Ar || !lin->Br || !lin->eig_re || !lin->eig_im || !TA) {
            rc = eom__fail(s, EOM_ERR_NOMEM, "out of memory");
            goto done;
        }
        /* TA = A T (2n x nz), Ar = T^T (A T), Br = T^T B */
        for (i = 0; i < n2; i++)
            for (j = 0; j < nz; j++) {
                double sum = 0.0;
                int k;
                for (k = 0; k < n2; k++)
                    sum += lin->A[(size_t)i * n2 + k] *
                           lin->T[(size_t)k * nz + j];
                TA[(size_t)i * nz + j] = sum;
            }
        at_b(n2, nz, nz, lin->T, TA, lin->Ar);
        at_b(n2, nz, np, lin->T, lin->B, lin->Br);
        rc = eigenvalues(s, lin);
    }
done:
    free(G);
    free(TA);
    if (rc != EOM_OK) {
        char msg[EOM_MSG_LEN];
        memcpy(msg, s->msg, sizeof msg);
        eom_state_linear_free(lin);
        memcpy(s->msg, msg, sizeof msg);
    } else {
        s->msg[0] = '\0';
    }
    return rc;
}
