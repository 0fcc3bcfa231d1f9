/* columns.h - the columns of eom-run's CSV for a system, and the values
 * of one row. The order (docs/csv.md is the reference):
 *
 *   t, q_1 .. q_n (coordinate names), NAME_dot for each rate,
 *   T, V, E, W, phi1 .. phiM, phidot1 .. phidotM, probes by name
 *
 * phiK is the residual of constraint K and phidotK the K-th component of
 * the velocity residual C qd; both groups are absent without
 * constraints. */
#ifndef APPS_COLUMNS_H
#define APPS_COLUMNS_H

#include <stddef.h>

#include "eom/eom.h"

typedef struct columns {
    int n, m, nprobes; /* coordinates, constraints, probes */
    int count;         /* columns: 1 + 2n + 4 + 2m + nprobes */
    char **names;      /* [count] column names (owned) */
    double *phi, *phidot; /* [m] scratch */
    char msg[512];     /* why the last columns_fill failed */
} columns;

/* What a row holds besides its values, for the run summary. */
typedef struct row_info {
    eom_energy e;     /* energies at the row's state (NaN if not computed) */
    double phi_max;   /* max |phi_k|, 0 without constraints */
    double phidot_max; /* max |(C qd)_k| */
} row_info;

/* The columns of s (borrowed; only read here). Every name must be unique:
 * a coordinate or probe named like a fixed column is an error. Returns 0
 * and a new layout in *out (free with columns_free), or -1 with a message
 * in err (errlen bytes). */
int columns_new(columns **out, const eom_system *s, char *err,
                size_t errlen);
void columns_free(columns **c);

/* Fill row (c->count values) for time t, state x (2n values) and
 * dissipated work W; *info receives the energies and largest residuals.
 * Returns EOM_OK, or the first failing libeom status with its message in
 * c->msg and the values that could not be computed set to NaN. */
int columns_fill(columns *c, eom_system *s, double t, const double *x,
                 double W, double *row, row_info *info);

#endif /* APPS_COLUMNS_H */
