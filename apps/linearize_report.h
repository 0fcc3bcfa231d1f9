/* linearize_report.h - eom-run --linearize: instead of a run, the
 * state-space linearization about the start state (eom_linearize_state),
 * written as comma-separated blocks on standard output.
 *
 * The format (docs/csv.md, "Linearization"), one block per matrix: a
 * header line whose first field names the block and whose other fields
 * name the columns, then one line per row whose first field names the
 * row. Numbers are written so that they read back exactly. A state is
 * q:NAME (a coordinate) or qd:NAME (its rate), a parameter p:NAME: no
 * row name is a block name, whatever the model's names, so the first
 * field of a line says whether it starts a block.
 *   x,<states>                 the state: one row "value"
 *   A,<states>                 rows: the states; d(xd_i)/dx_j
 *   B,<parameters>             rows: the states; d(xd_i)/dp_k
 *   T,z1..z<nz>                rows: the states; the tangent basis
 *   Ar,z1..z<nz>               rows: z1..; T^T A T
 *   Br,<parameters>            rows: z1..; T^T B
 *   eigenvalues,re,im          rows: 1..nz; the eigenvalues of Ar
 * Lines starting with # are comments. */
#ifndef APPS_LINEARIZE_REPORT_H
#define APPS_LINEARIZE_REPORT_H

#include <stdio.h>

#include "eom/eom.h"

/* Linearize s about (t, x) and print the blocks on f. label names the
 * demo in messages. Returns 0, or 1 after a message on standard error. */
int linearize_report(FILE *f, eom_system *s, double t, const double *x,
                     const char *label);

#endif /* APPS_LINEARIZE_REPORT_H */
