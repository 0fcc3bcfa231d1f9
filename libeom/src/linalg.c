/* linalg.c - LAPACK calls that need more than one line: the full SVD with
 * its workspace query (used by the null-space reduction of the
 * linearization and by the equilibrium solver); and the largest magnitude
 * in a vector, which the projections, the equilibrium solver and the
 * linearizations measure their residuals and scales with. */
#include <math.h>
#include <stdlib.h>

#include "eom_internal.h"

int eom__svd(eom_system *s, int rows, int cols, double *A, double *sv,
             double *U, double *VT, const char *what)
{
    int lwork = -1, info = 0;
    double query = 0.0, *work;
    dgesvd_("A", "A", &rows, &cols, A, &rows, sv, U, &rows, VT, &cols,
            &query, &lwork, &info, 1, 1);
    if (info != 0)
        return eom__fail(s, EOM_ERR_LINALG, "dgesvd: argument %d", -info);
    lwork = (int)query;
    work = malloc((size_t)(lwork > 1 ? lwork : 1) * sizeof(double));
    if (!work)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    dgesvd_("A", "A", &rows, &cols, A, &rows, sv, U, &rows, VT, &cols, work,
            &lwork, &info, 1, 1);
    free(work);
    if (info < 0)
        return eom__fail(s, EOM_ERR_LINALG, "dgesvd: argument %d", -info);
    if (info > 0)
        return eom__fail(s, EOM_ERR_LINALG,
                         "dgesvd: the SVD of %s did not converge (%d "
                         "superdiagonals)", what, info);
    return EOM_OK;
}

double eom__maxabs(const double *a, size_t n)
{
    double m = 0.0;
    size_t i;
    for (i = 0; i < n; i++)
        m = fmax(m, fabs(a[i]));
    return m;
}
