/* chain_shape.c - the deformed chain at a CSV row (see chain_shape.h). */
#include "chain_shape.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static const double pi = 3.14159265358979323846;

void chain_shape_free(chain_shape **c)
{
    if (!c || !*c)
        return;
    free((*c)->L);
    free((*c)->modes);
    free((*c)->theta_col);
    free((*c)->q_first);
    free((*c)->q_col);
    free(*c);
    *c = NULL;
}

/* The CSV column called name, or -1 with a message. */
static int column(const eom_csv_table *t, const char *name, char *err,
                  size_t errlen)
{
    int k = eom_csv_table_col(t, name);
    if (k < 0)
        snprintf(err, errlen, "the CSV has no column '%s'", name);
    return k;
}

int chain_shape_new(chain_shape **out, const eom_system *s, int links,
                    const eom_csv_table *t, char *err, size_t errlen)
{
    chain_shape *c = calloc(1, sizeof *c);
    char name[64];
    int j, i, nq = 0, kD;
    *out = NULL;
    if (!c || links < 1)
        goto nomem;
    c->links = links;
    c->L = calloc((size_t)links, sizeof *c->L);
    c->modes = calloc((size_t)links, sizeof *c->modes);
    c->theta_col = calloc((size_t)links, sizeof *c->theta_col);
    c->q_first = calloc((size_t)links, sizeof *c->q_first);
    if (!c->L || !c->modes || !c->theta_col || !c->q_first)
        goto nomem;
    for (j = 0; j < links; j++) {
        int k;
        snprintf(name, sizeof name, "L%d", j + 1);
        if ((k = eom_param_index(s, name)) < 0) {
            snprintf(err, errlen, "the system has no parameter '%s'", name);
            goto fail;
        }
        c->L[j] = eom_get_param(s, k);
        snprintf(name, sizeof name, "theta%d", j + 1);
        if ((c->theta_col[j] = column(t, name, err, errlen)) < 0)
            goto fail;
        /* the modes are the coordinates qJ_1, qJ_2, ... that exist */
        for (i = 1;; i++) {
            snprintf(name, sizeof name, "q%d_%d", j + 1, i);
            if (eom_coord_index(s, name) < 0)
                break;
            c->modes[j]++;
        }
        c->q_first[j] = nq;
        nq += c->modes[j];
    }
    c->q_col = calloc((size_t)nq + 1, sizeof *c->q_col);
    if (!c->q_col)
        goto nomem;
    for (j = 0; j < links; j++)
        for (i = 0; i < c->modes[j]; i++) {
            snprintf(name, sizeof name, "q%d_%d", j + 1, i + 1);
            if ((c->q_col[c->q_first[j] + i] = column(t, name, err,
                                                      errlen)) < 0)
                goto fail;
        }
    kD = eom_param_index(s, "D");
    c->closed = eom_system_nconstraints(s) > 0 && kD >= 0;
    c->D = c->closed ? eom_get_param(s, kD) : 0.0;
    *out = c;
    return 0;
nomem:
    snprintf(err, errlen, "out of memory");
fail:
    chain_shape_free(&c);
    return -1;
}

int chain_shape_npoints(const chain_shape *c, int j)
{
    /* a dozen points per half wave of the highest mode */
    return c->modes[j] > 0 ? 12 * c->modes[j] + 1 : 2;
}

void chain_shape_link(const chain_shape *c, const eom_csv_table *t, int i,
                      int j,
                      double *root, double *pts)
{
    const double th = eom_csv_table_at(t, i, c->theta_col[j]), L = c->L[j];
    const double ex = cos(th), ey = sin(th);
    const int np = chain_shape_npoints(c, j);
    int p, k;
    for (p = 0; pts && p < np; p++) {
        const double x = L * p / (np - 1.0);
        double v = 0.0;
        for (k = 0; k < c->modes[j]; k++)
            v += eom_csv_table_at(t, i, c->q_col[c->q_first[j] + k]) *
                 sin((k + 1) * pi * x / L);
        pts[4 * p + 0] = root[0] + x * ex;
        pts[4 * p + 1] = root[1] + x * ey;
        pts[4 * p + 2] = -v * ey; /* v n, n = (-sin, cos) */
        pts[4 * p + 3] = v * ex;
    }
    root[0] += L * ex;
    root[1] += L * ey;
}

double chain_shape_exaggeration(const chain_shape *c, const eom_csv_table *t)
{
    double vmax = 0.0, Lmax = 0.0, want, p10, f;
    int i, j, k;
    for (j = 0; j < c->links; j++)
        Lmax = fmax(Lmax, c->L[j]);
    for (i = 0; i < t->nrows; i++)
        for (j = 0; j < c->links; j++) {
            double sum = 0.0;
            for (k = 0; k < c->modes[j]; k++)
                sum += fabs(eom_csv_table_at(t, i,
                                             c->q_col[c->q_first[j] + k]));
            vmax = fmax(vmax, sum);
        }
    if (!(vmax > 0.0) || !isfinite(vmax))
        return 1.0;
    want = 0.1 * Lmax / vmax;
    if (!(want > 2.0) || !isfinite(want))
        return 1.0;
    p10 = pow(10.0, floor(log10(want)));
    f = want / p10;
    return (f >= 5.0 ? 5.0 : f >= 2.0 ? 2.0 : 1.0) * p10;
}
