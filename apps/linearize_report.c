/* linearize_report.c - eom-run --linearize (see linearize_report.h). */
#include "linearize_report.h"

#include <stdlib.h>

#include "eom/run.h"

/* The name of state i: q:NAME for a coordinate, qd:NAME for its rate.
 * The prefix keeps every row name apart from the block names (a
 * coordinate may be called x, A or T). */
static void state_name(const eom_system *s, int i, char *buf, size_t len)
{
    const int n = eom_system_ncoords(s);
    if (i < n)
        snprintf(buf, len, "q:%s", eom_coord_name(s, i));
    else
        snprintf(buf, len, "qd:%s", eom_coord_name(s, i - n));
}

static void number(FILE *f, double v)
{
    char b[40];
    /* -0 (a zero times a negative) printed as 0 */
    eom_numtext_format(b, sizeof b, v == 0.0 ? 0.0 : v);
    fprintf(f, ",%s", b);
}

/* Header "what,<columns>": states, parameters, or z1..z<count>. */
enum cols { COLS_STATES, COLS_PARAMS, COLS_Z };

static void header(FILE *f, const eom_system *s, const char *what,
                   enum cols kind, int count)
{
    char name[160];
    int j;
    fputs(what, f);
    for (j = 0; j < count; j++) {
        if (kind == COLS_STATES)
            state_name(s, j, name, sizeof name);
        else if (kind == COLS_PARAMS)
            snprintf(name, sizeof name, "p:%s", eom_param_name(s, j));
        else
            snprintf(name, sizeof name, "z%d", j + 1);
        fprintf(f, ",%s", name);
    }
    fputc('\n', f);
}

/* rows x cols row-major M, the rows named as states or z. */
static void block(FILE *f, const eom_system *s, const char *what,
                  enum cols rows_kind, int rows, enum cols cols_kind,
                  int cols, const double *M)
{
    char name[160];
    int i, j;
    header(f, s, what, cols_kind, cols);
    for (i = 0; i < rows; i++) {
        if (rows_kind == COLS_STATES)
            state_name(s, i, name, sizeof name);
        else
            snprintf(name, sizeof name, "z%d", i + 1);
        fputs(name, f);
        for (j = 0; j < cols; j++)
            number(f, M[(size_t)i * (size_t)cols + (size_t)j]);
        fputc('\n', f);
    }
}

int linearize_report(FILE *f, eom_system *s, double t, const double *x,
                     const char *label)
{
    eom_state_linear lin;
    int i, rc = eom_linearize_state(s, t, x, &lin);
    if (rc != EOM_OK) {
        fprintf(stderr, "eom-run: %s: cannot linearize about the start "
                "state: %s\n", label, eom_system_errmsg(s));
        return 1;
    }
    fprintf(f, "# eom-run --linearize: %s about its start state at t = %g\n"
            "# d(dx)/dt = A dx + B dp; with constraints dx = T z, "
            "d(z)/dt = Ar z + Br dp\n"
            "# (docs/cli.md, \"Linearization\"; docs/csv.md; "
            "docs/linearization.md)\n",
            label, t);
    header(f, s, "x", COLS_STATES, lin.n2);
    fputs("value", f);
    for (i = 0; i < lin.n2; i++)
        number(f, lin.x[i]);
    fputc('\n', f);
    block(f, s, "A", COLS_STATES, lin.n2, COLS_STATES, lin.n2, lin.A);
    block(f, s, "B", COLS_STATES, lin.n2, COLS_PARAMS, lin.np, lin.B);
    block(f, s, "T", COLS_STATES, lin.n2, COLS_Z, lin.nz, lin.T);
    block(f, s, "Ar", COLS_Z, lin.nz, COLS_Z, lin.nz, lin.Ar);
    block(f, s, "Br", COLS_Z, lin.nz, COLS_PARAMS, lin.np, lin.Br);
    fputs("eigenvalues,re,im\n", f);
    for (i = 0; i < lin.nz; i++) {
        fprintf(f, "%d", i + 1);
        number(f, lin.eig_re[i]);
        number(f, lin.eig_im[i]);
        fputc('\n', f);
    }
    eom_state_linear_free(&lin);
    return 0;
}
