/* assemble_arg.c - eom-run --assemble: the names read, the assembly run
 * and reported (see assemble_arg.h). */
#include "assemble_arg.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_args.h"

/* held[i] = 1 for each coordinate named in arg; 0, or CLI_EXIT_USAGE. */
static int read_names(const char *arg, const eom_system *s, int *held)
{
    const char *p = arg;
    if (!arg[0])
        return cli_usage_error("--assemble: no coordinate named");
    for (;;) {
        const char *end = strchr(p, ',');
        const size_t len = end ? (size_t)(end - p) : strlen(p);
        char name[160];
        int i;
        if (len == 0 || len >= sizeof name)
            return cli_usage_error("--assemble: an empty or too long name "
                                   "in '%s'", arg);
        memcpy(name, p, len);
        name[len] = '\0';
        if ((i = eom_coord_index(s, name)) < 0)
            return cli_usage_error("--assemble: '%s' is not a coordinate of "
                                   "the model (--describe lists them)",
                                   name);
        held[i] = 1;
        if (!end)
            return 0;
        p = end + 1;
    }
}

int assemble_start(const char *arg, eom_system *s, double *x, double tol,
                   const char *label, int quiet, int run_failure)
{
    const int n = eom_system_ncoords(s);
    int *held = calloc((size_t)n + 1, sizeof *held);
    int rc, iters = 0, i, first = 1;
    if (!held) {
        fprintf(stderr, "eom-run: out of memory\n");
        return run_failure;
    }
    if ((rc = read_names(arg, s, held)) != 0) {
        free(held);
        return rc;
    }
    if (eom_system_nconstraints(s) == 0) {
        fprintf(stderr, "eom-run: %s: --assemble: the model has no "
                "constraints: there is no loop to close\n", label);
        free(held);
        return CLI_EXIT_USAGE;
    }
    eom_set_time(s, 0.0);
    if (eom_assemble(s, x, held, tol, &iters) != EOM_OK) {
        fprintf(stderr, "eom-run: %s: --assemble: %s\n", label,
                eom_system_errmsg(s));
        free(held);
        return run_failure;
    }
    if (!quiet) {
        fprintf(stderr, "eom-run: %s: assembled from %s:", label, arg);
        for (i = 0; i < n; i++)
            if (!held[i]) {
                fprintf(stderr, "%s %s = %.17g", first ? "" : ",",
                        eom_coord_name(s, i), x[i]);
                first = 0;
            }
        fprintf(stderr, " (%d iteration%s)\n", iters, iters == 1 ? "" : "s");
    }
    free(held);
    return 0;
}
