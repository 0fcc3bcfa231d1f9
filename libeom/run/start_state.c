/* start_state.c - projecting the initial state onto the constraints (see
 * eom/run.h). */
#include "eom/run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

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
