/* sens_columns.h - the CSV columns of forward sensitivities in a run
 * (eom_opts.n_sens): for each input in the order given, for each state x
 * (the coordinates, then their rates NAME_dot), the column
 * "d(x)/d(INPUT)", INPUT a parameter's name or the name of the
 * coordinate or rate whose initial value it is. Private to the run
 * layer. */
#ifndef EOM_RUN_SENS_COLUMNS_H
#define EOM_RUN_SENS_COLUMNS_H

#include "eom/eom.h"

/* The names of the 2n * o->n_sens columns (owned by *names, freed with
 * sens_columns_free). Returns 0, or -1 (out of memory). */
int sens_columns_names(const eom_system *s, const eom_opts *o,
                       char ***names);
void sens_columns_free(char **names, int count);
/* Their values at the integrator's time; it NULL: at the start (unit
 * vectors for initial values, zero for parameters). Returns EOM_OK or
 * the status of eom_integ_sensitivities. */
int sens_columns_fill(const eom_system *s, const eom_opts *o,
                      const eom_integ *it, double *row);

#endif
