/* support_tape.c - run user functions on the evaluators and collect their
 * outputs (see support_tape.h). */
#include <stdlib.h>

#include "support_tape.h"

static int worse(int st, int rc)
{
    if (rc < 0 || st < 0)
        return rc < st ? rc : st;
    return rc > st ? rc : st;
}

int st_eval(tp_rec *ev, const double *x, tp_func f, void *user, double *y)
{
    int rc = tp_rec_run(ev, x, f, user), st = TP_OK, o, m;
    if (rc < 0)
        return rc;
    m = tp_rec_n_outputs(ev);
    for (o = 0; o < m; o++)
        st = worse(st, tp_rec_output_value(ev, o, &y[o]));
    return st;
}

void st_unpack(int n, const double *packed, double *H)
{
    int i, j;
    for (i = 0; i < n; i++)
        for (j = 0; j <= i; j++) {
            const double v = packed[i * (i + 1) / 2 + j];
            H[i * n + j] = v;
            H[j * n + i] = v;
        }
}

int st_tuple(tp_rec *tu, const double *x, tp_func f, void *user, double *y,
             double *G, double *H)
{
    const int n = tp_rec_n_indep(tu);
    const size_t nn = (size_t)n * (size_t)n;
    double *packed;
    int rc = tp_rec_run(tu, x, f, user), st = TP_OK, o, m;
    if (rc < 0)
        return rc;
    packed = malloc(((size_t)n * (size_t)(n + 1) / 2 + 1) * sizeof(double));
    if (!packed)
        return TP_ERR_NOMEM;
    m = tp_rec_n_outputs(tu);
    for (o = 0; o < m && st >= 0; o++) {
        if (y)
            st = worse(st, tp_rec_output_value(tu, o, &y[o]));
        st = worse(st, tp_tuple_output(tu, o, G ? G + (size_t)o * (size_t)n
                                                : NULL,
                                       packed));
        if (H)
            st_unpack(n, packed, H + (size_t)o * nn);
    }
    free(packed);
    return st;
}
