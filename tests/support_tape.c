/* support_tape.c - run user functions on the evaluators and collect their
 * outputs, record q/qd tapes, compare doubles bit for bit (see
 * support_tape.h). */
#include <stdlib.h>
#include <string.h>

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

tp_tape *st_record_qqd(tp_func f, int N, void *user)
{
    unsigned char group[128];
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    int i;
    if (N < 0 || N > 64)
        return NULL;
    for (i = 0; i < 2 * N; i++)
        group[i] = (unsigned char)(i < N ? 0 : 1);
    if (tp_recorder_new(&r, 2 * N, group, NULL) != TP_OK ||
        tp_rec_run(r, NULL, f, user) != TP_OK ||
        tp_recorder_finish(r, &t) != TP_OK)
        t = NULL;
    tp_rec_free(&r);
    return t;
}

int st_same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0 || (a == 0.0 && b == 0.0);
}
