/* start_state.c - projecting the initial state onto the constraints (see
 * eom/run.h). */
#include "eom/run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* Redundant constraints at the start, named: a warning (the run goes on:
 * the multipliers take a filtered SVD, at a cost in accuracy). Only when
 * C M^-1 C^T is nearly singular, and only at a size where the dense
 * rank-revealing factorization takes well under a second. */
static void warn_redundant(eom_system *s, const double *x, const char *prog,
                           const char *label)
{
    const int m = eom_system_nconstraints(s), n = eom_system_ncoords(s);
    double rcM = 1.0, rcS = 1.0;
    char text[1024];
    int rank = m;
    if (eom_condition(s, x, &rcM, &rcS) != EOM_OK || !(rcS < 1e-8))
        return;
    if ((double)m * (double)n * (double)(m < n ? m : n) > 2e9) {
        fprintf(stderr, "%s: %s: warning: C M^-1 C^T is singular or nearly "
                "so at the start (rcond %.2g): redundant constraints or a "
                "singular position (too many rows to name the dependent "
                "ones)\n", prog, label, rcS);
        return;
    }
    if (eom_constraint_rank(s, x, 0.0, &rank, NULL, text, sizeof text) !=
            EOM_OK ||
        rank == m)
        return;
    fprintf(stderr, "%s: %s: warning: the constraints are redundant at the "
            "start (rank %d of %d rows): %s. A redundant row costs accuracy "
            "(each step's multipliers then come from a filtered SVD); leave "
            "it out (docs/integrators.md, \"Redundant constraints\")\n",
            prog, label, rank, m, text);
}

int eom_run_prepare_start(eom_system *s, double *x, const eom_opts *o,
                          const char *prog, const char *label)
{
    const int m = eom_system_nconstraints(s);
    if (!prog)
        prog = "eom_run";
    if (!label)
        label = "model";
    const char *vel = eom_system_reads_time(s) ? "C qd + dphi/dt" : "C qd";
    double *phi, *phidot, pmax = 0.0, vmax = 0.0;
    int k, iters = 0, rc;
    if (m == 0)
        return 0;
    /* a run starts at t = 0: constraints that read the time are checked
     * there */
    eom_set_time(s, 0.0);
    phi = malloc(2 * (size_t)m * sizeof(double));
    if (!phi) {
        fprintf(stderr, "%s: out of memory\n", prog);
        return 1;
    }
    phidot = phi + m;
    if (eom_residuals(s, x, phi, phidot) != EOM_OK) {
        fprintf(stderr, "%s: %s: cannot evaluate the constraints at "
                "the initial state: %s\n", prog, label, eom_system_errmsg(s));
        free(phi);
        return 1;
    }
    for (k = 0; k < m; k++) {
        pmax = fmax(pmax, fabs(phi[k]));
        vmax = fmax(vmax, fabs(phidot[k]));
    }
    free(phi);
    warn_redundant(s, x, prog, label);
    if (pmax <= o->proj_tol && vmax <= o->proj_tol)
        return 0;
    if (!o->project) {
        fprintf(stderr, "%s: %s: warning: the initial state is off the "
                "constraints (max |phi| = %.3g, max |%s| = %.3g, tolerance "
                "%.3g) and --no-project is given: the run starts off the "
                "constraints\n", prog, label, pmax, vel, vmax, o->proj_tol);
        return 0;
    }
    /* the least change of the coordinates the user gave (not the least
     * kinetic energy: that would move coordinates the constraints do not
     * involve, such as the deflections of flexible links) */
    rc = eom_project_start(s, x, o->proj_tol, &iters);
    if (rc != EOM_OK) {
        fprintf(stderr, "%s: %s: the initial state is off the "
                "constraints (max |phi| = %.3g, max |%s| = %.3g) and "
                "cannot be projected onto them: %s\n", prog, label, pmax, vel,
                vmax, eom_system_errmsg(s));
        return 1;
    }
    fprintf(stderr, "%s: %s: the initial state is off the constraints "
            "(max |phi| = %.3g, max |%s| = %.3g, tolerance %.3g): "
            "projected onto phi = 0 and %s = 0 by the least change of the "
            "coordinates (%d iteration%s on q)\n", prog, label, pmax, vel,
            vmax, o->proj_tol, vel, iters, iters == 1 ? "" : "s");
    return 0;
}
