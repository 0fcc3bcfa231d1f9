/* assemble_arg.h - eom-run --assemble NAME[,NAME...]: the start's loop
 * closed from the coordinates named (held with their rates), the others
 * solved (eom_assemble). */
#ifndef APPS_ASSEMBLE_ARG_H
#define APPS_ASSEMBLE_ARG_H

#include "eom/eom.h"

/* Assemble x (2n) of s, at time 0, holding the coordinates listed in arg
 * (comma-separated names); label names the model in messages. Returns 0,
 * CLI_EXIT_USAGE for a name that is not a coordinate, or run_failure
 * when the loop cannot close (after a message on standard error). A note
 * of what was solved goes to standard error unless quiet. */
int assemble_start(const char *arg, eom_system *s, double *x, double tol,
                   const char *label, int quiet, int run_failure);

#endif
