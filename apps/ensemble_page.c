/* ensemble_page.c - eom-ensemble --plots: one animation page of the
 * runs drawn over each other (ensemble_page.h), through the run layer's
 * eom_run_animation_runs. */
#include "ensemble_page.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom/drawing.h"
#include "eom/run.h"

/* "run I: NAME=VALUE, ..." for run i: a new string, or NULL. */
static char *run_label(const ensemble_runs *runs, long i)
{
    size_t cap = 64, k;
    char *s;
    int j;
    for (j = 0; j < runs->ncols; j++)
        cap += strlen(runs->names[j]) + 32;
    if (!(s = malloc(cap)))
        return NULL;
    k = (size_t)snprintf(s, cap, "run %ld", i);
    for (j = 0; j < runs->ncols; j++) {
        /* 6 digits for the eye; the summary has every digit */
        k += (size_t)snprintf(s + k, cap - k, "%s%s=%.6g", j ? ", " : ": ",
                              runs->names[j], runs->v[i * runs->ncols + j]);
    }
    return s;
}

int ensemble_page_write(const char *summary, const char *traj_dir,
                        const ensemble_runs *runs,
                        const unsigned char *drawn, const eom_system *s,
                        const char *label, long *ndrawn)
{
    eom_plot_place place;
    char page[8192], err[4096];
    char **paths = NULL, **labels = NULL;
    long i, n = 0;
    int rc = -1;
    *ndrawn = 0;
    if (eom_system_ndrawings(s) == 0)
        return 0;
    for (i = 0; i < runs->nruns; i++)
        n += drawn[i] != 0;
    if (n == 0)
        return 0;
    if (n > 1000000L) {
        fprintf(stderr, "eom-ensemble: --plots: %ld runs are too many for "
                "one page\n", n);
        return -1;
    }
    if (eom_plot_place_of(&place, summary, err, sizeof err) != 0 ||
        eom_plot_place_path(&place, "animation.html", page, sizeof page) !=
            0) {
        fprintf(stderr, "eom-ensemble: --plots: %s\n",
                err[0] ? err : "file names too long");
        return -1;
    }
    paths = calloc((size_t)n, sizeof *paths);
    labels = calloc((size_t)n, sizeof *labels);
    if (!paths || !labels)
        goto oom;
    n = 0;
    for (i = 0; i < runs->nruns; i++) {
        size_t len;
        if (!drawn[i])
            continue;
        len = strlen(traj_dir) + 32;
        if (!(paths[n] = malloc(len)))
            goto oom;
        snprintf(paths[n], len, "%s/run-%ld.csv", traj_dir, i);
        if (!(labels[n++] = run_label(runs, i)))
            goto oom;
    }
    if (eom_run_animation_runs(label, s, (int)n,
                               (const char *const *)paths,
                               (const char *const *)labels, page, err,
                               sizeof err) != 0) {
        fprintf(stderr, "eom-ensemble: --plots: %s\n", err);
        goto done;
    }
    *ndrawn = n;
    rc = 0;
    goto done;
oom:
    fprintf(stderr, "eom-ensemble: --plots: out of memory\n");
done:
    for (i = 0; i < n; i++) {
        free(paths ? paths[i] : NULL);
        free(labels ? labels[i] : NULL);
    }
    free(paths);
    free(labels);
    return rc;
}
