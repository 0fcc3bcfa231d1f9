/* constraint_rank.c - which constraint rows depend on others
 * (eom_constraint_rank): a QR factorization with column pivoting of the
 * row-scaled C^T, whose pivot order picks independent rows first; each
 * dependent row's combination of them from the triangular factor. Run
 * once at a start or after a failure, not per step: dense on purpose. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"

#define LABEL_LEN 160

/* Append to text (of len, holding *used) what printf would print. */
static void append(char *text, size_t len, size_t *used, const char *fmt,
                   ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static void append(char *text, size_t len, size_t *used, const char *fmt,
                   ...)
{
    va_list ap;
    int k;
    if (!text || *used + 1 >= len)
        return;
    va_start(ap, fmt);
    k = vsnprintf(text + *used, len - *used, fmt, ap);
    va_end(ap);
    if (k > 0)
        *used = *used + (size_t)k < len ? *used + (size_t)k : len - 1;
}

/* The sentence for dependent pivot column k (of rank r): its row as a
 * combination of the first r pivots, coefficients c (r). */
static void describe(const eom_system *s, const int *piv, int r, int k,
                     const double *c, const double *scale, char *text,
                     size_t len, size_t *used)
{
    char a[LABEL_LEN], b[LABEL_LEN];
    double big = 0.0;
    int i, first = 1;
    for (i = 0; i < r; i++)
        big = fmax(big, fabs(c[i]));
    eom__row_label(s, piv[k], a, sizeof a);
    append(text, len, used, "%s%s =", *used ? "; " : "", a);
    for (i = 0; i < r; i++) {
        /* back to the unscaled rows: row_k / scale_k = sum c_i row_i /
         * scale_i */
        const double ci = c[i] * scale[piv[k]] / scale[piv[i]];
        if (fabs(c[i]) <= 1e-8 * big)
            continue;
        eom__row_label(s, piv[i], b, sizeof b);
        append(text, len, used, "%s%.6g %s", first ? " " : " + ", ci, b);
        first = 0;
    }
    if (first)
        append(text, len, used, " 0 (a row of zeros)");
}

int eom_constraint_rank(eom_system *s, const double *x, double tol,
                        int *rank, int *dependent, char *text,
                        size_t textlen)
{
    double *A = NULL, *tau = NULL, *scale = NULL, *c = NULL, *work = NULL;
    double wq, top;
    int *piv = NULL, n, m, k, i, j, r = 0, lwork = -1, info = 0, rc;
    size_t used = 0;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (text && textlen)
        text[0] = '\0';
    if (!x || !rank)
        return eom__fail(s, EOM_ERR_NULL,
                         "eom_constraint_rank: NULL argument");
    n = s->n;
    m = s->m;
    *rank = 0;
    if (m == 0)
        return EOM_OK;
    if (tol <= 0.0)
        tol = 1e-9;
    A = malloc((size_t)m * (size_t)n * sizeof *A);
    tau = malloc((size_t)(m < n ? m : n) * sizeof *tau);
    scale = malloc((size_t)m * sizeof *scale);
    c = malloc((size_t)m * sizeof *c);
    piv = calloc((size_t)m, sizeof *piv);
    if (!A || !tau || !scale || !c || !piv) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "eom_constraint_rank: out of "
                       "memory (%d x %d)", m, n);
        goto done;
    }
    if ((rc = eom_constraint_jacobian(s, x, A, NULL)) != EOM_OK)
        goto done;
    /* C row-major is C^T column-major (n x m): scale its columns to unit
     * length, so that a row's units do not decide the pivot order */
    for (j = 0; j < m; j++) {
        double nrm = 0.0;
        for (i = 0; i < n; i++)
            nrm = hypot(nrm, A[(size_t)j * n + i]);
        scale[j] = nrm > 0.0 ? nrm : 1.0;
        for (i = 0; i < n; i++)
            A[(size_t)j * n + i] /= scale[j];
    }
    dgeqp3_(&n, &m, A, &n, piv, tau, &wq, &lwork, &info);
    lwork = info == 0 ? (int)wq : 3 * m + 1;
    if (!(work = malloc((size_t)lwork * sizeof *work))) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "eom_constraint_rank: out of "
                       "memory");
        goto done;
    }
    dgeqp3_(&n, &m, A, &n, piv, tau, work, &lwork, &info);
    if (info != 0) {
        rc = eom__fail(s, EOM_ERR_LINALG, "dgeqp3: argument %d", -info);
        goto done;
    }
    for (j = 0; j < m; j++)
        piv[j]--; /* Fortran's 1-based pivots */
    top = fabs(A[0]);
    for (k = 0; k < (m < n ? m : n); k++)
        if (top > 0.0 && fabs(A[(size_t)k * n + k]) > tol * top)
            r++;
    *rank = r;
    if (dependent)
        for (j = 0; j < m; j++)
            dependent[j] = -1;
    for (k = r; k < m; k++) {
        int best = 0;
        /* R11 c = R12's column k, by back substitution */
        for (i = r - 1; i >= 0; i--) {
            double v = A[(size_t)k * n + i];
            for (j = i + 1; j < r; j++)
                v -= A[(size_t)j * n + i] * c[j];
            c[i] = v / A[(size_t)i * n + i];
        }
        for (i = 1; i < r; i++)
            if (fabs(c[i] / scale[piv[i]]) > fabs(c[best] / scale[piv[best]]))
                best = i;
        if (dependent)
            dependent[piv[k]] = r > 0 ? piv[best] : -1;
        describe(s, piv, r, k, c, scale, text, textlen, &used);
    }
    rc = EOM_OK;
done:
    free(A);
    free(tau);
    free(scale);
    free(c);
    free(piv);
    free(work);
    return rc;
}
