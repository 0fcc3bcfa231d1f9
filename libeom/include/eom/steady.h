/* steady.h - linearization about steady motions (part of libeom's public
 * API; see eom.h and docs/linearization.md). */
#ifndef EOM_STEADY_H
#define EOM_STEADY_H

#include "eom/eom.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Linearization about a steady motion: a state x where the
 * accelerations vanish (max |qdd| <= 1e-8 times the size of its terms,
 * M^-1 of dL/dq, of the velocity terms, of the forces, and the
 * constraint forces) while cyclic coordinates (the right-hand side does
 * not read them) move at constant rates, such as a disk or a bicycle
 * rolling straight on, or a state of rest. eom_steady_check returns
 * EOM_OK there, else EOM_ERR_ARG with a message that names the largest
 * acceleration and its coordinate; *acc (max |qdd|), *scale (the size of
 * the terms) and *at (its coordinate) may be NULL.
 *
 * eom_linearize_steady checks the start so, then linearizes about it
 * (eom_linearize_state: holonomic and velocity constraints restrict the
 * perturbations, full holds that result) and reduces the result to
 * independent coordinates and speeds y (nr states, indices kept: i for
 * q_i, n + i for qd_i): y' = Ar y, with eigenvalues eig_re, eig_im
 * sorted by real, then imaginary part. keep (nkeep state indices,
 * borrowed) names them; NULL (nkeep 0) chooses them: the coordinates
 * that are not cyclic and not dependent, and the speeds that are
 * independent, with the directions of zero eigenvalue that nothing kept
 * depends on (positions on the plane, a heading, wheel angles, a forward
 * speed) left out: for the Whipple bicycle lean, steer and their rates,
 * for the rolling disk its lean, heading rate and lean rate. The ndrop eigenvalues of what was left out are in
 * drop_re, drop_im (all about zero when chosen). A named set must be
 * independent on the constraints and closed (what it leaves out must not
 * act on it): EOM_ERR_ARG otherwise. On failure *lin is zeroed. Free
 * with eom_steady_linear_free. docs/linearization.md has the details. */
typedef struct eom_steady_linear {
    eom_state_linear full;   /* about x, on the constraints (nz states) */
    int n;                   /* coordinates */
    int *cyclic;             /* n flags: the column of A is zero */
    double acc, acc_scale;   /* max |qdd| at x, the size of its terms */
    int acc_at;              /* the coordinate of acc */
    int nr;                  /* independent states */
    int *kept;               /* nr state indices, ascending */
    double *Ar;              /* nr x nr, row-major */
    double *eig_re, *eig_im; /* nr */
    int ndrop;               /* nz - nr directions left out */
    double *drop_re, *drop_im; /* ndrop: their eigenvalues */
} eom_steady_linear;
EOM_API int eom_steady_check(eom_system *s, double t, const double *x,
                             double *acc, double *scale, int *at);
EOM_API int eom_linearize_steady(eom_system *s, double t, const double *x,
                                 const int *keep, int nkeep,
                                 eom_steady_linear *lin);
EOM_API void eom_steady_linear_free(eom_steady_linear *lin);

#ifdef __cplusplus
}
#endif

#endif /* EOM_STEADY_H */
