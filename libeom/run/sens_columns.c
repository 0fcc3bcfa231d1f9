/* sens_columns.c - the sensitivities' CSV columns (see sens_columns.h). */
#include "sens_columns.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The name of state i (a coordinate, or a rate NAME_dot) into buf. */
static void state_name(const eom_system *s, int i, char *buf, size_t len)
{
    const int n = eom_system_ncoords(s);
    snprintf(buf, len, "%s%s", eom_coord_name(s, i < n ? i : i - n),
             i < n ? "" : "_dot");
}

/* The name of input w: a parameter, or the state whose initial value. */
static void input_name(const eom_system *s, int w, char *buf, size_t len)
{
    const int np = eom_system_nparams(s);
    if (w < np)
        snprintf(buf, len, "%s", eom_param_name(s, w));
    else
        state_name(s, w - np, buf, len);
}

int sens_columns_names(const eom_system *s, const eom_opts *o,
                       char ***names)
{
    const int n2 = 2 * eom_system_ncoords(s), ns = o->n_sens;
    char **v = calloc((size_t)(n2 * ns) + 1, sizeof *v);
    char a[256], b[256];
    int i, k;
    *names = v;
    if (!v)
        return -1;
    for (k = 0; k < ns; k++) {
        input_name(s, o->sens[k], b, sizeof b);
        for (i = 0; i < n2; i++) {
            size_t len;
            state_name(s, i, a, sizeof a);
            len = strlen(a) + strlen(b) + 8;
            v[k * n2 + i] = malloc(len);
            if (!v[k * n2 + i])
                return -1;
            snprintf(v[k * n2 + i], len, "d(%s)/d(%s)", a, b);
        }
    }
    return 0;
}

void sens_columns_free(char **names, int count)
{
    int i;
    if (!names)
        return;
    for (i = 0; i < count; i++)
        free(names[i]);
    free(names);
}

int sens_columns_fill(const eom_system *s, const eom_opts *o,
                      const eom_integ *it, double *row)
{
    const int n2 = 2 * eom_system_ncoords(s), ns = o->n_sens;
    const int np = eom_system_nparams(s);
    double *S;
    int i, k, rc = EOM_OK;
    if (!it) {
        for (k = 0; k < ns; k++)
            for (i = 0; i < n2; i++)
                row[k * n2 + i] = o->sens[k] - np == i ? 1.0 : 0.0;
        return EOM_OK;
    }
    S = malloc((size_t)n2 * (size_t)ns * sizeof *S);
    if (!S)
        return EOM_ERR_NOMEM;
    rc = eom_integ_sensitivities(it, S);
    for (k = 0; rc == EOM_OK && k < ns; k++)
        for (i = 0; i < n2; i++)
            row[k * n2 + i] = S[i * ns + k];
    free(S);
    return rc;
}
