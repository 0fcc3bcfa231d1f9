/* columns.c - CSV column names and row values for a system (see
 * eom/run.h). */
#include "eom/run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A copy of "<a><b>" (b may be ""), or NULL. */
static char *join(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    char *p = malloc(la + lb + 1);
    if (p) {
        memcpy(p, a, la);
        memcpy(p + la, b, lb + 1);
    }
    return p;
}

/* A copy of "<base><k>", k >= 1, or NULL. */
static char *numbered(const char *base, int k)
{
    char num[16];
    snprintf(num, sizeof num, "%d", k);
    return join(base, num);
}

char *eom_run_constraint_column(const eom_system *s, const char *base,
                                int j)
{
    const char *name = eom_constraint_name(s, j);
    char *b, *p;
    if (!name || !base)
        return NULL;
    if (!name[0])
        return numbered(base, j + 1);
    if (!(b = join(base, "_")))
        return NULL;
    p = join(b, name);
    free(b);
    return p;
}

void eom_run_columns_free(eom_run_columns **c)
{
    int i;
    if (!c || !*c)
        return;
    for (i = 0; (*c)->names && i < (*c)->count; i++)
        free((*c)->names[i]);
    free((*c)->names);
    free((*c)->phi);
    free((*c)->phidot);
    free((*c)->xd);
    free(*c);
    *c = NULL;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

int eom_run_columns_new(eom_run_columns **out, const eom_system *s,
                        unsigned extra, char *err, size_t errlen)
{
    static const char *const fixed[] = {"T", "V", "E", "W"};
    eom_run_columns *c = calloc(1, sizeof *c);
    int i, k = 0;
    *out = NULL;
    if (!c)
        goto nomem;
    c->n = eom_system_ncoords(s);
    c->m = eom_system_nconstraints(s);
    c->nprobes = eom_system_nprobes(s);
    c->extra = extra & (EOM_RUN_ACCELERATIONS | EOM_RUN_MULTIPLIERS |
                        EOM_RUN_CONDITION | EOM_RUN_HEALTH);
    eom_run_columns_set_stats(c, NULL);
    c->count = 1 + 2 * c->n + 4 + 2 * c->m + c->nprobes;
    if (c->extra & EOM_RUN_ACCELERATIONS)
        c->count += c->n;
    if (c->extra & EOM_RUN_MULTIPLIERS)
        c->count += c->m;
    if (c->extra & EOM_RUN_CONDITION)
        c->count += 2;
    if (c->extra & EOM_RUN_HEALTH)
        c->count += 4;
    c->names = calloc((size_t)c->count, sizeof *c->names);
    c->phi = calloc((size_t)c->m + 1, sizeof(double));
    c->phidot = calloc((size_t)c->m + 1, sizeof(double));
    c->xd = calloc(2 * (size_t)c->n + 1, sizeof(double));
    if (!c->names || !c->phi || !c->phidot || !c->xd)
        goto nomem;
    c->names[k++] = join("t", "");
    for (i = 0; i < c->n; i++)
        c->names[k++] = join(eom_coord_name(s, i), "");
    for (i = 0; i < c->n; i++)
        c->names[k++] = join(eom_coord_name(s, i), "_dot");
    for (i = 0; i < 4; i++)
        c->names[k++] = join(fixed[i], "");
    for (i = 0; i < c->m; i++)
        c->names[k++] = eom_run_constraint_column(s, "phi", i);
    for (i = 0; i < c->m; i++)
        c->names[k++] = eom_run_constraint_column(s, "phidot", i);
    for (i = 0; i < c->nprobes; i++)
        c->names[k++] = join(eom_probe_name(s, i), "");
    if (c->extra & EOM_RUN_ACCELERATIONS)
        for (i = 0; i < c->n; i++)
            c->names[k++] = join(eom_coord_name(s, i), "_ddot");
    if (c->extra & EOM_RUN_MULTIPLIERS)
        for (i = 0; i < c->m; i++)
            c->names[k++] = eom_run_constraint_column(s, "lambda", i);
    if (c->extra & EOM_RUN_CONDITION) {
        c->names[k++] = join("rcond_M", "");
        c->names[k++] = join("rcond_S", "");
    }
    if (c->extra & EOM_RUN_HEALTH) {
        c->names[k++] = join("projections", "");
        c->names[k++] = join("svd_solves", "");
        c->names[k++] = join("singular_passes", "");
        c->names[k++] = join("branch_switches", "");
    }
    for (i = 0; i < c->count; i++)
        if (!c->names[i])
            goto nomem;
    /* duplicates: neighbours once sorted (n log n: a model may have tens
     * of thousands of columns) */
    if (c->count > 1) {
        char **sorted = malloc((size_t)c->count * sizeof *sorted);
        const char *twice = NULL;
        if (!sorted)
            goto nomem;
        memcpy(sorted, c->names, (size_t)c->count * sizeof *sorted);
        qsort(sorted, (size_t)c->count, sizeof *sorted, by_name);
        for (i = 1; i < c->count && !twice; i++)
            if (strcmp(sorted[i - 1], sorted[i]) == 0)
                twice = sorted[i];
        if (twice) {
            snprintf(err, errlen, "the CSV column name '%s' appears twice "
                     "(a coordinate or probe is named like another column)",
                     twice);
            free(sorted);
            eom_run_columns_free(&c);
            return -1;
        }
        free(sorted);
    }
    *out = c;
    return 0;
nomem:
    snprintf(err, errlen, "out of memory");
    eom_run_columns_free(&c);
    return -1;
}

/* Note the first failure of a row (status rc, message of s). */
static int row_fail(eom_run_columns *c, const eom_system *s, int status, int rc)
{
    if (status != EOM_OK)
        return status;
    snprintf(c->msg, sizeof c->msg, "%s", eom_system_errmsg(s));
    return rc;
}

void eom_run_columns_set_stats(eom_run_columns *c, const eom_stats *st)
{
    if (!c)
        return;
    c->health[0] = st ? (double)st->projections : NAN;
    c->health[1] = st ? (double)st->svd_solves : NAN;
    c->health[2] = st ? (double)st->singular_passes : NAN;
    c->health[3] = st ? (double)st->branch_switches : NAN;
}

int eom_run_columns_fill(eom_run_columns *c, eom_system *s, double t,
                         const double *x, double W, double *row,
                         eom_run_row_info *info)
{
    const int n = c->n, m = c->m;
    double *after = row + 1 + 2 * n; /* T, V, E, W, residuals, probes */
    double *opt = after + 4 + 2 * m + c->nprobes; /* the optional groups */
    int rc, status = EOM_OK, i;
    row[0] = t;
    memcpy(row + 1, x, 2 * (size_t)n * sizeof(double));
    for (i = 0; i < c->count - 1 - 2 * n; i++)
        after[i] = NAN;
    info->e.T = info->e.V = info->e.L = info->e.E = info->e.P = NAN;
    info->phi_max = info->phidot_max = 0.0;
    c->msg[0] = '\0';

    /* the calls below without a t argument evaluate at the row's time (a
     * non-finite t is refused here and reported by eom_energy_at) */
    (void)eom_set_time(s, t);
    rc = eom_energy_at(s, t, x, &info->e);
    if (rc < 0) {
        status = row_fail(c, s, status, rc);
        info->e.T = info->e.V = info->e.L = info->e.E = info->e.P = NAN;
    } else {
        after[0] = info->e.T;
        after[1] = info->e.V;
        after[2] = info->e.E;
    }
    after[3] = W;
    if (m > 0) {
        rc = eom_residuals(s, x, c->phi, c->phidot);
        if (rc < 0) {
            status = row_fail(c, s, status, rc);
            info->phi_max = info->phidot_max = NAN;
        } else {
            for (i = 0; i < m; i++) {
                after[4 + i] = c->phi[i];
                after[4 + m + i] = c->phidot[i];
                info->phi_max = fmax(info->phi_max, fabs(c->phi[i]));
                info->phidot_max = fmax(info->phidot_max, fabs(c->phidot[i]));
            }
        }
    }
    if (c->nprobes > 0) {
        rc = eom_probes_at(s, x, after + 4 + 2 * m);
        if (rc < 0) {
            status = row_fail(c, s, status, rc);
            for (i = 0; i < c->nprobes; i++)
                after[4 + 2 * m + i] = NAN;
        }
    }
    if (c->extra & EOM_RUN_ACCELERATIONS) {
        rc = eom_rhs(s, t, x, c->xd);
        if (rc < 0)
            status = row_fail(c, s, status, rc);
        else
            memcpy(opt, c->xd + n, (size_t)n * sizeof(double));
        opt += n;
    }
    if ((c->extra & EOM_RUN_MULTIPLIERS) && m > 0) {
        rc = eom_multipliers(s, t, x, opt);
        if (rc < 0) {
            status = row_fail(c, s, status, rc);
            for (i = 0; i < m; i++)
                opt[i] = NAN;
        }
        opt += m;
    }
    if (c->extra & EOM_RUN_CONDITION) {
        rc = eom_condition(s, x, &opt[0], &opt[1]);
        if (rc < 0) {
            status = row_fail(c, s, status, rc);
            opt[0] = opt[1] = NAN;
        }
        opt += 2;
    }
    if (c->extra & EOM_RUN_HEALTH)
        memcpy(opt, c->health, sizeof c->health);
    return status;
}
