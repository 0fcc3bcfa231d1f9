/* cli_args.c - shared command-line pieces of the programs (cli_args.h). */
#define _POSIX_C_SOURCE 200809L
#include "cli_args.h"

#include <stdarg.h>
#include <stdio.h>
#include <sys/stat.h>

#include "eom/run.h"

static const char *program = "eom-run";
static int speaks = 1;

void cli_args_program(const char *name, int speak)
{
    program = name;
    speaks = speak;
}

int cli_out_not_input(const char *out, const char *input, const char *what)
{
    struct stat a, b;
    if (!out || !input || stat(out, &a) != 0 || stat(input, &b) != 0 ||
        a.st_dev != b.st_dev || a.st_ino != b.st_ino)
        return 0;
    return cli_usage_error("--out '%s' is %s ('%s'): the output would "
                           "overwrite it; name another file", out, what,
                           input);
}

int cli_usage_error(const char *fmt, ...)
{
    va_list ap;
    if (!speaks)
        return CLI_EXIT_USAGE;
    fprintf(stderr, "%s: ", program);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\n(%s --help shows the options)\n", program);
    return CLI_EXIT_USAGE;
}

int cli_number_arg(const char *opt, const char *text, int positive,
                   double *out)
{
    double v;
    int rc = eom_numtext_parse_double(text, &v);
    if (rc != EOM_NUMTEXT_OK)
        return cli_usage_error("%s '%s': the value %s", opt, text,
                               eom_numtext_error(rc));
    if (positive ? !(v > 0.0) : !(v >= 0.0))
        return cli_usage_error("%s '%s': the value must be %s", opt, text,
                               positive ? "> 0" : ">= 0");
    *out = v;
    return 0;
}

int cli_integrator_arg(const char *text, eom_method *out)
{
    int m = eom_method_from_name(text);
    if (m < 0)
        return cli_usage_error("--integrator '%s': unknown integrator "
                               "(choose rk4, erk, adams, bdf, ida, esdirk or imex)",
                               text);
    *out = (eom_method)m;
    return 0;
}

void cli_compiled(eom_system *s, const char *label, int quiet)
{
    eom_compiled_info ci;
    quiet = quiet || !speaks;
    if (!quiet)
        fprintf(stderr, "%s: %s: compiling the tapes, or loading them from "
                "the cache\n", program, label);
    if (eom_system_set_compiled(s, 1, &ci) != EOM_OK)
        fprintf(stderr, "%s: %s: warning: %s\n", program, label,
                eom_system_errmsg(s));
    else if (!quiet)
        fprintf(stderr,
                "%s: %s: compiled tapes in use (%d of %d from the cache, "
                "%.2f s)\n",
                program, label, ci.cached, ci.tapes, ci.seconds);
}
