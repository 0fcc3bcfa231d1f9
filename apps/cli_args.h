/* cli_args.h - what eom-run and eom-ensemble share on their command
 * lines: the message of a usage error (exit status 2), the checked
 * reading of number and integrator options, and --compiled. */
#ifndef APPS_CLI_ARGS_H
#define APPS_CLI_ARGS_H

#include "eom/eom.h"

enum { CLI_EXIT_USAGE = 2 };

/* The program's name in messages ("eom-run"), and whether this process
 * speaks (an MPI rank other than 0 does not: rank 0 says it once). */
void cli_args_program(const char *name, int speak);

/* "PROGRAM: <message>" and a pointer to --help on standard error;
 * returns CLI_EXIT_USAGE. */
int cli_usage_error(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* A number option: finite, and > 0 (positive) or >= 0. Returns 0, or
 * CLI_EXIT_USAGE after a message. */
int cli_number_arg(const char *opt, const char *text, int positive,
                   double *out);

/* --integrator: rk4, erk, adams, bdf, ida, esdirk or imex. */
int cli_integrator_arg(const char *text, eom_method *out);

/* --out names the file input (both borrowed; input may be NULL): the same
 * file by device and inode, through any spelling, symbolic or hard link.
 * Returns 0 when it does not (or when either does not exist), or
 * CLI_EXIT_USAGE after a message that calls input what (e.g. "the model
 * file"). */
int cli_out_not_input(const char *out, const char *input, const char *what);

/* --compiled: s on compiled tapes, saying so on standard error first
 * (a first run waits for the compiler) and after, unless quiet; without
 * them a warning, and s stays on the interpreter (never an error). label
 * names the model in the messages. */
void cli_compiled(eom_system *s, const char *label, int quiet);

#endif /* APPS_CLI_ARGS_H */
