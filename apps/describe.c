/* describe.c - --list and --describe (see describe.h). Tables are
 * aligned: each is gathered as strings first, then printed with the
 * widest cell of each column. */
#include "describe.h"

#include <stdlib.h>
#include <string.h>

#include "eom/run.h"

enum { CELL = 96 };

typedef struct table {
    int ncols, nrows, cap;
    char (*cells)[CELL]; /* row-major, ncols per row */
} table;

static int table_add(table *t, const char *const *row)
{
    int j;
    if (t->nrows == t->cap) {
        int cap = t->cap ? 2 * t->cap : 8;
        void *p = realloc(t->cells, (size_t)cap * (size_t)t->ncols * CELL);
        if (!p)
            return -1;
        t->cells = p;
        t->cap = cap;
    }
    for (j = 0; j < t->ncols; j++)
        snprintf(t->cells[t->nrows * t->ncols + j], CELL, "%s", row[j]);
    t->nrows++;
    return 0;
}

static void table_print(FILE *f, const table *t)
{
    int i, j, w[8] = {0};
    for (i = 0; i < t->nrows; i++)
        for (j = 0; j < t->ncols; j++) {
            int len = (int)strlen(t->cells[i * t->ncols + j]);
            w[j] = len > w[j] ? len : w[j];
        }
    for (i = 0; i < t->nrows; i++) {
        fputs("  ", f);
        for (j = 0; j < t->ncols; j++) {
            const char *c = t->cells[i * t->ncols + j];
            if (j + 1 < t->ncols)
                fprintf(f, "%-*s  ", w[j], c);
            else
                fprintf(f, "%s\n", c);
        }
    }
}

/* The number as text; with " (set: X)" when the value in use differs. */
static void value_text(char *buf, size_t len, double dflt, double used)
{
    char a[32], b[32];
    eom_numtext_format(a, sizeof a, dflt);
    if (used == dflt) {
        snprintf(buf, len, "%s", a);
        return;
    }
    eom_numtext_format(b, sizeof b, used);
    snprintf(buf, len, "%s (set: %s)", a, b);
}

void describe_list(FILE *f)
{
    int i, n, w = 0;
    const demo *const *all = demos_all(&n);
    for (i = 0; i < n; i++) {
        int len = (int)strlen(all[i]->name);
        w = len > w ? len : w;
    }
    for (i = 0; i < n; i++)
        fprintf(f, "%-*s  %s\n", w, all[i]->name, all[i]->summary);
}

static int describe_settings(FILE *f, const demo *d, const double *settings)
{
    table t = {6, 0, 0, NULL};
    const char *head[6] = {"name", "default", "unit", "range", "kind",
                           "description"};
    int k, rc = 0;
    if (d->nsettings == 0) {
        fprintf(f, "structural settings: none\n");
        return 0;
    }
    fprintf(f, "structural settings (--set NAME=VALUE; they change the "
            "model's size and are read before it is built):\n");
    rc |= table_add(&t, head);
    for (k = 0; k < d->nsettings; k++) {
        const demo_setting *st = &d->settings[k];
        char val[CELL], lo[32], hi[32], range[CELL];
        const char *row[6];
        value_text(val, sizeof val, st->dflt, settings[k]);
        eom_numtext_format(lo, sizeof lo, st->min);
        eom_numtext_format(hi, sizeof hi, st->max);
        snprintf(range, sizeof range, "%s .. %s", lo, hi);
        row[0] = st->name;
        row[1] = val;
        row[2] = st->unit[0] ? st->unit : "-";
        row[3] = range;
        row[4] = st->integer ? "integer" : "real";
        row[5] = st->description;
        rc |= table_add(&t, row);
    }
    if (rc == 0)
        table_print(f, &t);
    free(t.cells);
    return rc;
}

static int describe_params(FILE *f, const eom_system *s)
{
    table t = {4, 0, 0, NULL};
    const char *head[4] = {"name", "default", "unit", "description"};
    int k, rc = 0, np = eom_system_nparams(s);
    if (np == 0) {
        fprintf(f, "parameters: none\n");
        return 0;
    }
    fprintf(f, "parameters (--set NAME=VALUE):\n");
    rc |= table_add(&t, head);
    for (k = 0; k < np; k++) {
        char val[CELL];
        const char *row[4];
        const char *desc = eom_param_description(s, k);
        value_text(val, sizeof val, eom_param_default(s, k),
                   eom_get_param(s, k));
        row[0] = eom_param_name(s, k);
        row[1] = val;
        row[2] = eom_param_unit(s, k)[0] ? eom_param_unit(s, k) : "-";
        row[3] = desc && desc[0] ? desc : "-";
        rc |= table_add(&t, row);
    }
    if (rc == 0)
        table_print(f, &t);
    free(t.cells);
    return rc;
}

static int describe_coords(FILE *f, const eom_system *s, const double *x0)
{
    table t = {5, 0, 0, NULL};
    const char *head[5] = {"name", "initial", "initial rate (NAME_dot)",
                           "unit", "rate unit"};
    const int n = eom_system_ncoords(s);
    double *dflt = malloc(2 * (size_t)n * sizeof(double) + 1);
    int i, rc = 0;
    if (!dflt || eom_initial_state(s, dflt) != EOM_OK) {
        free(dflt);
        return -1;
    }
    fprintf(f, "coordinates (--set NAME=VALUE for the initial value, "
            "--set NAME_dot=VALUE for the initial rate):\n");
    rc |= table_add(&t, head);
    for (i = 0; i < n; i++) {
        char q[CELL], qd[CELL], rate_unit[CELL];
        const char *unit = eom_coord_unit(s, i);
        const char *row[5];
        value_text(q, sizeof q, dflt[i], x0[i]);
        value_text(qd, sizeof qd, dflt[n + i], x0[n + i]);
        snprintf(rate_unit, sizeof rate_unit, "%s/s", unit[0] ? unit : "1");
        row[0] = eom_coord_name(s, i);
        row[1] = q;
        row[2] = qd;
        row[3] = unit[0] ? unit : "-";
        row[4] = rate_unit;
        rc |= table_add(&t, row);
    }
    if (rc == 0)
        table_print(f, &t);
    free(t.cells);
    free(dflt);
    return rc;
}

/* The constraint rows by their CSV names (phi_NAME for a named row,
 * phiK otherwise), the velocity rows marked. */
static void describe_constraints(FILE *f, const eom_system *s)
{
    const int m = eom_system_nconstraints(s);
    const int mv = eom_system_nvelocity_constraints(s);
    int k;
    fprintf(f, "constraints: %d", m);
    if (mv > 0)
        fprintf(f, " (%d of them on the rates)", mv);
    fprintf(f, "; CSV columns");
    for (k = 0; k < m; k++) {
        char *col = eom_run_constraint_column(s, "phi", k);
        fprintf(f, "%s%s%s", k ? ", " : " ", col ? col : "?",
                k >= m - mv ? " (rates)" : "");
        free(col);
        if (k == 19 && m > 24) {
            fprintf(f, ", ... (%d more)", m - 20);
            break;
        }
    }
    fprintf(f, " and their phidot and lambda columns\n");
}

static void describe_outputs(FILE *f, const eom_system *s)
{
    const int m = eom_system_nconstraints(s), np = eom_system_nprobes(s);
    int k;
    if (m > 0)
        describe_constraints(f, s);
    else
        fprintf(f, "constraints: none\n");
    fprintf(f, "energies: %s\n", eom_system_has_tv(s)
            ? "T and V given separately"
            : "a whole Lagrangian (the CSV's T and V are nan)");
    if (np == 0) {
        fprintf(f, "probes: none\n");
        return;
    }
    fprintf(f, "probes:");
    for (k = 0; k < np; k++)
        fprintf(f, " %s%s%s%s", eom_probe_name(s, k),
                eom_probe_unit(s, k)[0] ? " (" : "", eom_probe_unit(s, k),
                eom_probe_unit(s, k)[0] ? ")" : "");
    fputc('\n', f);
}

int describe_demo(FILE *f, const demo *d, const double *settings,
                  const eom_system *s, const double *x0, unsigned extra)
{
    eom_run_columns *c = NULL;
    char err[256];
    int i;
    fprintf(f, "%s: %s\n\n", d->name, d->summary);
    if (describe_settings(f, d, settings) != 0)
        return -1;
    fputc('\n', f);
    if (describe_params(f, s) != 0)
        return -1;
    fputc('\n', f);
    if (describe_coords(f, s, x0) != 0)
        return -1;
    fputc('\n', f);
    describe_outputs(f, s);
    if (eom_run_columns_new(&c, s, extra, err, sizeof err) != 0) {
        fprintf(f, "CSV columns: (%s)\n", err);
        return 0;
    }
    fprintf(f, "CSV columns: ");
    for (i = 0; i < c->count; i++)
        fprintf(f, "%s%s", i ? "," : "", c->names[i]);
    fputc('\n', f);
    eom_run_columns_free(&c);
    return 0;
}
