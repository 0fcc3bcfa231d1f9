/* eom_run.c - eom-run, the scene runner: pick a demo or a model file
 * (.eom, docs/models.md), override its
 * settings, parameters and initial state by name, integrate it with any
 * of libeom's methods and write the trajectory as CSV (docs/cli.md,
 * docs/csv.md), optionally with plots beside it (--plots), or print its
 * equilibrium and natural frequencies instead (--modes). This file reads
 * the command line and puts the pieces together; the demos live in
 * demos/, the run itself, the start of a constrained run, the CSV and the
 * generic plots in the run layer (eom/run.h, libeom/run/), --modes in
 * modes_report.c (an equilibrium, or the start when it moves steadily)
 * and --modes --sweep in modes_sweep.c.
 *
 * Exit status: 0 success, 1 the run failed (model, initial projection,
 * integrator, output file, plots; with --modes: no equilibrium, or a
 * start that is not a steady motion), 2 the
 * command line is wrong (nothing was run or written), 3 the run reached
 * t_end but its health verdict failed (eom_run_judge; not with
 * --accept-unhealthy), 128 + N stopped by
 * signal N (SIGTERM, SIGINT, SIGHUP: the rows up to the stop are in
 * FILE.partial, cli_stop.h). */
#define _GNU_SOURCE /* getopt_long */
#include <getopt.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "eom/run.h"
#include "cli_args.h"
#include "cli_stop.h"
#include "demos/demos.h"
#include "demos/file_demo.h"
#include "describe.h"
#include "eom/eom.h"
#include "eom/steady.h"
#include "assemble_arg.h"
#include "linearize_report.h"
#include "modes_report.h"
#include "modes_sweep.h"
#include "overrides.h"

enum { EXIT_RUN = 1, EXIT_USAGE = CLI_EXIT_USAGE, EXIT_UNHEALTHY = 3 };

/* The largest t_end / sample accepted: beyond it the sample times k *
 * sample lose too much precision to be told apart reliably. */
#define MAX_ROWS 1e12

typedef struct cli {
    const char *demo_name; /* the positional argument, or NULL */
    override *sets;        /* nsets --set options, in order */
    int nsets;
    double t_end, sample;
    eom_opts opts;
    int baumgarte;         /* --baumgarte given */
    double alpha, beta;
    const char *out;       /* --out, or NULL for standard output */
    int quiet, list, describe, help;
    int plots;             /* --plots: the demo's after_run hook */
    int modes;             /* --modes: equilibrium and frequencies */
    int linearize;         /* --linearize: A, B about the start state */
    const char *sweep_arg; /* --sweep NAME=LO:HI:N (with --modes) */
    modes_sweep sweep;     /* its fields */
    const char *assemble_arg; /* --assemble NAME[,NAME...] */
    const char *indep_arg; /* --independent NAME[,NAME...] */
    int *indep;            /* their state indices */
    int nindep;
    const char *sens_arg;  /* --sensitivity NAME[,NAME...] */
    int *sens;             /* their inputs (eom_opts.sens) */
    unsigned extra;        /* --columns: optional CSV columns */
    int compiled;          /* --compiled: run compiled tapes */
    int accept_unhealthy;  /* --accept-unhealthy: exit 0 all the same */
} cli;

/* Long-only options get codes outside the range of characters. */
enum {
    OPT_LIST = 256,
    OPT_DESCRIBE,
    OPT_SAMPLE,
    OPT_INTEGRATOR,
    OPT_ERK_TABLE,
    OPT_DT,
    OPT_RTOL,
    OPT_ATOL,
    OPT_MAX_STEPS,
    OPT_MAX_ORDER,
    OPT_LINEAR_SOLVER,
    OPT_TOL_PER_STEP,
    OPT_NO_PROJECT,
    OPT_BAUMGARTE,
    OPT_PLOTS,
    OPT_MODES,
    OPT_LINEARIZE,
    OPT_SENSITIVITY,
    OPT_COLUMNS,
    OPT_COMPILED,
    OPT_SWEEP,
    OPT_INDEPENDENT,
    OPT_ASSEMBLE,
    OPT_ACCEPT_UNHEALTHY
};

static const struct option long_options[] = {
    {"help", no_argument, NULL, 'h'},
    {"list", no_argument, NULL, OPT_LIST},
    {"describe", no_argument, NULL, OPT_DESCRIBE},
    {"set", required_argument, NULL, 's'},
    {"t-end", required_argument, NULL, 't'},
    {"sample", required_argument, NULL, OPT_SAMPLE},
    {"integrator", required_argument, NULL, OPT_INTEGRATOR},
    {"erk-table", required_argument, NULL, OPT_ERK_TABLE},
    {"dt", required_argument, NULL, OPT_DT},
    {"rtol", required_argument, NULL, OPT_RTOL},
    {"atol", required_argument, NULL, OPT_ATOL},
    {"max-steps", required_argument, NULL, OPT_MAX_STEPS},
    {"max-order", required_argument, NULL, OPT_MAX_ORDER},
    {"linear-solver", required_argument, NULL, OPT_LINEAR_SOLVER},
    {"tol-per-step", no_argument, NULL, OPT_TOL_PER_STEP},
    {"no-project", no_argument, NULL, OPT_NO_PROJECT},
    {"baumgarte", required_argument, NULL, OPT_BAUMGARTE},
    {"out", required_argument, NULL, 'o'},
    {"plots", no_argument, NULL, OPT_PLOTS},
    {"modes", no_argument, NULL, OPT_MODES},
    {"linearize", no_argument, NULL, OPT_LINEARIZE},
    {"sweep", required_argument, NULL, OPT_SWEEP},
    {"independent", required_argument, NULL, OPT_INDEPENDENT},
    {"assemble", required_argument, NULL, OPT_ASSEMBLE},
    {"sensitivity", required_argument, NULL, OPT_SENSITIVITY},
    {"columns", required_argument, NULL, OPT_COLUMNS},
    {"compiled", no_argument, NULL, OPT_COMPILED},
    {"accept-unhealthy", no_argument, NULL, OPT_ACCEPT_UNHEALTHY},
    {"quiet", no_argument, NULL, 'q'},
    {NULL, 0, NULL, 0},
};

static void usage_line(FILE *f)
{
    fprintf(f, "usage: eom-run --list\n"
               "       eom-run DEMO --describe [--set NAME=VALUE]...\n"
               "       eom-run DEMO --modes [--set NAME=VALUE]...\n"
               "       eom-run DEMO --modes --sweep NAME=LO:HI:N [--out FILE] "
               "[--plots]\n"
               "       eom-run DEMO --linearize [--set NAME=VALUE]...\n"
               "       eom-run DEMO [OPTION]...\n"
               "DEMO is a demo or shipped model by name, or a model file "
               "PATH.eom.\n");
}

static void help(void)
{
    usage_line(stdout);
    printf(
        "\nIntegrate a demo's or a model file's equations of motion and "
        "write the\ntrajectory as CSV.\n\n"
        "  -h, --help            show this help and exit\n"
        "      --list            list the demos and shipped model files, "
        "and exit\n"
        "      --describe        list the demo's settings, parameters and "
        "coordinates\n"
        "                        with defaults and units, and exit\n"
        "  -s, --set NAME=VALUE  set a structural setting, a parameter, a "
        "coordinate's\n"
        "                        initial value (NAME) or initial rate "
        "(NAME_dot);\n"
        "                        repeatable, the last value of a name wins\n"
        "  -t, --t-end T         end time, >= 0 (default 10)\n"
        "      --sample DT       interval between CSV rows, > 0 (default "
        "0.01)\n"
        "      --integrator M    rk4, erk, adams, bdf, ida, esdirk or imex "
        "(default erk)\n"
        "      --erk-table NAME  erk: an ARKODE ERK table (default "
        "ARKODE_VERNER_8_5_6;\n"
        "                        docs/integrators.md lists them)\n"
        "      --dt H            rk4: the step; other methods: the first "
        "step tried,\n"
        "                        > 0 (default 0.001)\n"
        "      --rtol R          relative tolerance of adaptive methods, > 0 "
        "(default 1e-8)\n"
        "      --atol A          absolute tolerance of adaptive methods, > 0 "
        "(default 1e-10)\n"
        "      --max-steps N     at most N steps between two rows, >= 1 "
        "(default 10000000)\n"
        "      --max-order K     adams, bdf, ida: the highest order used "
        "(adams 1..12,\n"
        "                        bdf and ida 1..5; default: the highest)\n"
        "      --linear-solver S ida, bdf: auto, dense or sparse (KLU) for "
        "the Newton\n"
        "                        iteration (default auto: by the model's "
        "structure)\n"
        "      --tol-per-step    hand adams, bdf, ida, esdirk and imex rtol "
        "and atol as given, for\n"
        "                        each"
        " step's error test (default: tighter "
        "per-step tolerances\n"
        "                        that keep the run's error near rtol and "
        "atol)\n"
        "      --no-project      do not project the state onto the "
        "constraints, neither\n"
        "                        the initial state nor after each step\n"
        "      --baumgarte A,B   Baumgarte stabilization of the constraints, "
        "A, B >= 0\n"
        "                        in 1/s (default 0,0: off)\n"
        );
    printf(
        "      --compiled        run the model's tapes as machine code: "
        "emitted as C,\n"
        "                        built with the C compiler (CC, else cc) "
        "into a cache\n"
        "                        (AUTOEOM_CACHE_DIR, else ~/.cache/autoeom) "
        "and checked\n"
        "                        against the interpreter; without a "
        "compiler the run goes\n"
        "                        on interpreted and says so (docs/cli.md)\n"
        "      --columns LIST    add optional CSV columns: accelerations "
        "(NAME_ddot),\n"
        "                        multipliers (lambdaK), condition (rcond_M, "
        "rcond_S),\n"
        "                        health (projections, svd_solves, "
        "singular_passes,\n"
        "                        branch_switches: counts so far); "
        "comma-separated,\n"
        "                        after the probes\n"
        "  -o, --out FILE        write the CSV to FILE (default: standard "
        "output, or\n"
        "                        NAME.csv in the current directory with "
        "--plots)\n"
        "      --plots           after the run, write the demo's plots "
        "beside the CSV\n"
        "                        (PNG, SVG, gnuplot scripts; for the "
        "chains an HTML\n"
        "                        animation); needs gnuplot\n"
        "      --modes           do not integrate: find the static "
        "equilibrium from the\n"
        "                        initial state and print it with the "
        "natural frequencies;\n"
        "                        about a start that moves steadily "
        "(accelerations 0,\n"
        "                        cyclic coordinates at constant rates) or "
        "a model with\n"
        "                        velocity constraints: the eigenvalues "
        "about the start,\n"
        "                        reduced to independent coordinates and "
        "speeds\n"
        "      --assemble NAME[,NAME...]\n"
        "                        close the start's loops from these "
        "coordinates and their\n"
        "                        rates, as given: the others are solved "
        "(an error when\n"
        "                        the loop cannot close)\n"
        "      --independent NAME[,NAME...]\n"
        "                        with --modes about a steady motion: the "
        "coordinates and\n"
        "                        rates (NAME_dot) to reduce to (default: "
        "chosen)\n"
        "      --sweep NAME=LO:HI:N\n"
        "                        with --modes: the eigenvalues at N values "
        "of the parameter\n"
        "                        NAME from LO to HI, as CSV to --out "
        "(default\n"
        "                        MODEL-modes.csv); with --plots also their "
        "plot\n"
        "      --linearize       do not integrate: print the state-space "
        "matrices A = d(xd)/dx\n"
        "                        and B = d(xd)/dp about the start state, "
        "reduced to the\n"
        "                        constraints, and their eigenvalues "
        "(docs/cli.md)\n"
        "      --sensitivity NAME[,NAME...]\n"
        "                        with adams, bdf or ida: also the columns "
        "d(x)/d(NAME) of\n"
        "                        the sensitivities of every state x to "
        "each parameter, or\n"
        "                        initial coordinate or rate (NAME_dot), "
        "named\n"
        "      --accept-unhealthy\n"
        "                        exit with 0 after a run whose health "
        "verdict fails\n"
        "                        (the verdict is still printed)\n"
        "  -q, --quiet           no summary, no progress line and no note "
        "about the plots\n"
        "                        on standard error\n"
        "\nA summary (steps, right-hand sides, wall time, energy drift, "
        "constraint\n"
        "residual, and the run's health verdict) ends every run on standard "
        "error;\na progress line is drawn "
        "there during long runs when it is a terminal.\n"
        "\nExit status: 0 success, 1 the run failed (rows written so far are "
        "kept),\n"
        "2 the command line is wrong, 3 the run ended but is unhealthy: its "
        "energy\ndrift, constraint residual or branch switches exceed what "
        "its tolerance allows\n(docs/run.md, \"The verdict\"; the CSV is "
        "written whole), 128 + N stopped by signal N\n(SIGTERM, "
        "SIGINT, SIGHUP: the rows so far are kept in FILE.partial).\n"
        "\nExample: eom-run spring-pendulum --set k=100 --set theta_dot=0.3 "
        "--t-end 5 --out sp.csv\n"
        "See docs/cli.md, docs/csv.md, docs/demos.md and docs/models.md.\n");
}

/* --sensitivity NAME[,NAME...]: each a parameter, or a coordinate or
 * rate (NAME_dot) whose initial value it is; into c->sens and the
 * integrator's options. Returns 0, or a usage error. */
static int sensitivity_arg(cli *c, const eom_system *s)
{
    const int n = eom_system_ncoords(s), np = eom_system_nparams(s);
    const char *p = c->sens_arg;
    int count = 1, k = 0;
    for (; *p; p++)
        count += *p == ',';
    c->sens = malloc((size_t)count * sizeof *c->sens);
    if (!c->sens) {
        fprintf(stderr, "eom-run: out of memory\n");
        return EXIT_RUN;
    }
    for (p = c->sens_arg; k < count; k++) {
        const char *end = strchr(p, ',');
        const size_t len = end ? (size_t)(end - p) : strlen(p);
        char name[160];
        int i, w = -1;
        if (len == 0 || len >= sizeof name)
            return cli_usage_error("--sensitivity: an empty or too long "
                                   "name in '%s'", c->sens_arg);
        memcpy(name, p, len);
        name[len] = '\0';
        if ((i = eom_param_index(s, name)) >= 0) {
            w = i;
        } else if ((i = eom_coord_index(s, name)) >= 0) {
            w = np + i;
        } else if (len > 4 && strcmp(name + len - 4, "_dot") == 0) {
            name[len - 4] = '\0';
            if ((i = eom_coord_index(s, name)) >= 0)
                w = np + n + i;
            name[len - 4] = '_';
        }
        if (w < 0)
            return cli_usage_error("--sensitivity: '%s' is not a parameter, "
                                   "a coordinate or a rate (NAME_dot) of "
                                   "the model (--describe lists them)",
                                   name);
        c->sens[k] = w;
        p = end ? end + 1 : p + len;
    }
    c->opts.n_sens = count;
    c->opts.sens = c->sens;
    return 0;
}

/* --independent NAME[,NAME...]: coordinates and rates (NAME_dot) into
 * c->indep as state indices (i, or n + i). Returns 0, or a usage
 * error. */
static int independent_arg(cli *c, const eom_system *s)
{
    const int n = eom_system_ncoords(s);
    const char *p = c->indep_arg;
    int count = 1, k = 0;
    for (; *p; p++)
        count += *p == ',';
    c->indep = malloc((size_t)count * sizeof *c->indep);
    if (!c->indep) {
        fprintf(stderr, "eom-run: out of memory\n");
        return EXIT_RUN;
    }
    for (p = c->indep_arg; k < count; k++) {
        const char *end = strchr(p, ',');
        const size_t len = end ? (size_t)(end - p) : strlen(p);
        char name[160];
        int i, w = -1;
        if (len == 0 || len >= sizeof name)
            return cli_usage_error("--independent: an empty or too long "
                                   "name in '%s'", c->indep_arg);
        memcpy(name, p, len);
        name[len] = '\0';
        if ((i = eom_coord_index(s, name)) >= 0) {
            w = i;
        } else if (len > 4 && strcmp(name + len - 4, "_dot") == 0) {
            name[len - 4] = '\0';
            if ((i = eom_coord_index(s, name)) >= 0)
                w = n + i;
            name[len - 4] = '_';
        }
        if (w < 0)
            return cli_usage_error("--independent: '%s' is not a coordinate "
                                   "or a rate (NAME_dot) of the model "
                                   "(--describe lists them)", name);
        c->indep[k] = w;
        p = end ? end + 1 : p + len;
    }
    c->nindep = count;
    return 0;
}

/* The start of a --modes run about a steady motion, again for each
 * value of a --sweep: the model's initial state for the parameters now
 * set, the --set coordinates and rates, and the projection onto the
 * constraints. */
typedef struct start_ctx {
    cli *c;
    const demo *d;
} start_ctx;

static int steady_start(void *user, eom_system *s, double *x)
{
    start_ctx *sc = user;
    char err[4096];
    if (eom_initial_state(s, x) != EOM_OK) {
        fprintf(stderr, "eom-run: %s: %s\n", sc->d->name,
                eom_system_errmsg(s));
        return 1;
    }
    if (overrides_apply_state(sc->c->sets, sc->c->nsets, sc->d, s, x, err,
                              sizeof err) != 0) {
        fprintf(stderr, "eom-run: %s\n", err);
        return 1;
    }
    return eom_run_prepare_start(s, x, &sc->c->opts, "eom-run",
                                 sc->d->name) != 0;
}

/* --modes about the start state when it moves steadily, or for
 * --sweep; else the equilibrium search as before. */
static int modes(cli *c, const demo *d, const double *settings,
                 eom_system *s, double *x0)
{
    const int n = eom_system_ncoords(s);
    start_ctx sc;
    double *x;
    int moving = 0, k, status;
    sc.c = c;
    sc.d = d;
    if (c->sweep_arg) {
        char def[1100];
        const char *out = c->out;
        if ((k = eom_param_index(s, c->sweep.name)) < 0)
            return cli_usage_error("--sweep '%s': %s has no parameter named "
                                   "'%s' (see: eom-run %s --describe)",
                                   c->sweep_arg, d->name, c->sweep.name,
                                   d->name);
        if (!out) {
            const char *base = strrchr(d->name, '/');
            size_t len;
            base = base ? base + 1 : d->name;
            len = strlen(base);
            if (len > 4 && strcmp(base + len - 4, ".eom") == 0)
                len -= 4;
            snprintf(def, sizeof def, "%.*s-modes.csv", (int)len, base);
            out = def;
        }
        return modes_sweep_run(s, k, &c->sweep, steady_start, &sc, c->indep,
                               c->nindep, d->name, out, c->plots, c->quiet)
                   ? EXIT_RUN
                   : EXIT_SUCCESS;
    }
    for (k = 0; k < n; k++)
        moving |= x0[n + k] != 0.0;
    if (moving || c->indep) {
        x = malloc(2 * (size_t)n * sizeof *x + 1);
        if (!x) {
            fprintf(stderr, "eom-run: out of memory\n");
            return EXIT_RUN;
        }
        memcpy(x, x0, 2 * (size_t)n * sizeof *x);
        if (eom_run_prepare_start(s, x, &c->opts, "eom-run", d->name) != 0) {
            free(x);
            return EXIT_RUN;
        }
        /* moving but not steady: the equilibrium search, as before */
        if (c->indep || eom_steady_check(s, 0.0, x, NULL, NULL, NULL) ==
                            EOM_OK) {
            status = modes_steady_report(stdout, s, x, c->indep, c->nindep,
                                         d->name) == 0
                         ? EXIT_SUCCESS
                         : EXIT_RUN;
            free(x);
            return status;
        }
        free(x);
    }
    {
        /* the demo's rest guess, unless the user placed the coordinates */
        const char *origin = "the initial state";
        int placed = 0;
        for (k = 0; k < c->nsets; k++) {
            char name[128];
            snprintf(name, sizeof name, "%.*s", (int)c->sets[k].namelen,
                     c->sets[k].arg);
            placed |= eom_coord_index(s, name) >= 0;
        }
        if (!placed && d->rest_guess &&
            d->rest_guess(d, settings, s, x0) == 0)
            origin = "the demo's rest guess";
        return modes_report(stdout, s, x0, d->name, origin) == 0
                   ? EXIT_SUCCESS
                   : EXIT_RUN;
    }
}

/* --erk-table: one of the names libeom knows, else the list. */
static int erk_table_arg(const char *text, const char **out)
{
    char list[1024] = "";
    int k;
    for (k = 0; eom_erk_table_name(k); k++) {
        if (strcmp(text, eom_erk_table_name(k)) == 0) {
            *out = text;
            return 0;
        }
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s",
                 k ? ", " : "", eom_erk_table_name(k));
    }
    return cli_usage_error("--erk-table '%s': unknown table (choose one of %s)",
                       text, list);
}

static int max_steps_arg(const char *text, long *out)
{
    long v;
    int rc = eom_numtext_parse_long(text, &v);
    if (rc != EOM_NUMTEXT_OK)
        return cli_usage_error("--max-steps '%s': the value %s", text,
                           eom_numtext_error(rc));
    if (v < 1)
        return cli_usage_error("--max-steps '%s': the value must be >= 1", text);
    *out = v;
    return 0;
}

static int max_order_arg(const char *text, int *out)
{
    long v;
    int rc = eom_numtext_parse_long(text, &v);
    if (rc != EOM_NUMTEXT_OK)
        return cli_usage_error("--max-order '%s': the value %s", text,
                               eom_numtext_error(rc));
    if (v < 1 || v > 12)
        return cli_usage_error("--max-order '%s': the value must be 1 to 12 "
                               "(adams) or 1 to 5 (bdf, ida)", text);
    *out = (int)v;
    return 0;
}

static int linear_solver_arg(const char *text, int *out)
{
    if (strcmp(text, "auto") == 0)
        *out = EOM_LINSOL_AUTO;
    else if (strcmp(text, "dense") == 0)
        *out = EOM_LINSOL_DENSE;
    else if (strcmp(text, "sparse") == 0)
        *out = EOM_LINSOL_SPARSE;
    else
        return cli_usage_error("--linear-solver '%s': choose auto, dense or "
                               "sparse", text);
    return 0;
}

static int baumgarte_arg(const char *text, double *alpha, double *beta)
{
    const char *comma = strchr(text, ',');
    char a[64];
    size_t la;
    if (!comma)
        return cli_usage_error("--baumgarte '%s': expected ALPHA,BETA", text);
    la = (size_t)(comma - text);
    if (la >= sizeof a)
        return cli_usage_error("--baumgarte '%s': ALPHA is too long", text);
    memcpy(a, text, la);
    a[la] = '\0';
    if (cli_number_arg("--baumgarte (ALPHA)", a, 0, alpha) ||
        cli_number_arg("--baumgarte (BETA)", comma + 1, 0, beta))
        return EXIT_USAGE;
    return 0;
}

/* --columns: a comma-separated list of optional column groups. */
static int columns_arg(const char *text, unsigned *out)
{
    static const struct {
        const char *name;
        unsigned flag;
    } groups[] = {{"accelerations", EOM_RUN_ACCELERATIONS},
                  {"multipliers", EOM_RUN_MULTIPLIERS},
                  {"condition", EOM_RUN_CONDITION},
                  {"health", EOM_RUN_HEALTH}};
    const char *p = text;
    unsigned flags = 0;
    if (!*p)
        return cli_usage_error("--columns: empty list (choose from "
                           "accelerations, multipliers, condition, "
                           "health)");
    while (*p) {
        size_t len = strcspn(p, ","), k;
        for (k = 0; k < sizeof groups / sizeof groups[0]; k++)
            if (strlen(groups[k].name) == len &&
                strncmp(groups[k].name, p, len) == 0)
                break;
        if (k == sizeof groups / sizeof groups[0])
            return cli_usage_error("--columns '%s': unknown group '%.*s' (choose "
                               "from accelerations, multipliers, "
                               "condition, health)", text, (int)len, p);
        flags |= groups[k].flag;
        p += len;
        if (*p == ',')
            p++;
    }
    *out = flags;
    return 0;
}

/* Message for getopt's '?' (unknown option, or an argument given to an
 * option that takes none). */
static int bad_option(char **argv)
{
    const char *arg = argv[optind - 1];
    if (strncmp(arg, "--", 2) == 0) {
        if (optopt != 0)
            return cli_usage_error("option '%s' does not take an argument", arg);
        return cli_usage_error("unknown or ambiguous option '%s'", arg);
    }
    return cli_usage_error("unknown option '-%c'", optopt);
}

/* Read the command line into *c. Returns 0, or EXIT_USAGE after a
 * message. */
static int parse(int argc, char **argv, cli *c)
{
    char err[512];
    int opt, rc = 0;
    opterr = 0; /* our messages, not getopt's */
    while (rc == 0 &&
           (opt = getopt_long(argc, argv, ":hs:t:o:q", long_options,
                              NULL)) != -1) {
        switch (opt) {
        case 'h': c->help = 1; break;
        case OPT_LIST: c->list = 1; break;
        case OPT_DESCRIBE: c->describe = 1; break;
        case 's':
            if (override_parse(optarg, &c->sets[c->nsets], err,
                               sizeof err) != 0)
                return cli_usage_error("%s", err);
            c->nsets++;
            break;
        case 't': rc = cli_number_arg("--t-end", optarg, 0, &c->t_end); break;
        case OPT_SAMPLE:
            rc = cli_number_arg("--sample", optarg, 1, &c->sample);
            break;
        case OPT_INTEGRATOR:
            rc = cli_integrator_arg(optarg, &c->opts.method);
            break;
        case OPT_ERK_TABLE:
            rc = erk_table_arg(optarg, &c->opts.erk_table);
            break;
        case OPT_DT: rc = cli_number_arg("--dt", optarg, 1, &c->opts.dt); break;
        case OPT_RTOL:
            rc = cli_number_arg("--rtol", optarg, 1, &c->opts.rtol);
            break;
        case OPT_ATOL:
            rc = cli_number_arg("--atol", optarg, 1, &c->opts.atol);
            break;
        case OPT_MAX_STEPS:
            rc = max_steps_arg(optarg, &c->opts.max_steps);
            break;
        case OPT_MAX_ORDER:
            rc = max_order_arg(optarg, &c->opts.max_order);
            break;
        case OPT_LINEAR_SOLVER:
            rc = linear_solver_arg(optarg, &c->opts.linear_solver);
            break;
        case OPT_TOL_PER_STEP: c->opts.tol_per_step = 1; break;
        case OPT_NO_PROJECT: c->opts.project = 0; break;
        case OPT_PLOTS: c->plots = 1; break;
        case OPT_MODES: c->modes = 1; break;
        case OPT_LINEARIZE: c->linearize = 1; break;
        case OPT_SWEEP:
            if (modes_sweep_parse(optarg, &c->sweep, err, sizeof err) != 0)
                return cli_usage_error("%s", err);
            c->sweep_arg = optarg;
            break;
        case OPT_INDEPENDENT:
            if (!optarg[0])
                return cli_usage_error("--independent: no name");
            c->indep_arg = optarg;
            break;
        case OPT_ASSEMBLE: c->assemble_arg = optarg; break;
        case OPT_COMPILED: c->compiled = 1; break;
        case OPT_ACCEPT_UNHEALTHY: c->accept_unhealthy = 1; break;
        case OPT_SENSITIVITY:
            if (!optarg[0])
                return cli_usage_error("--sensitivity: no name");
            c->sens_arg = optarg;
            break;
        case OPT_COLUMNS: rc = columns_arg(optarg, &c->extra); break;
        case OPT_BAUMGARTE:
            rc = baumgarte_arg(optarg, &c->alpha, &c->beta);
            c->baumgarte = 1;
            break;
        case 'o':
            if (!optarg[0])
                return cli_usage_error("--out: empty file name");
            c->out = optarg;
            break;
        case 'q': c->quiet = 1; break;
        case ':':
            return cli_usage_error("option '%s' needs an argument",
                               argv[optind - 1]);
        default: return bad_option(argv);
        }
    }
    if (rc != 0)
        return rc;
    if (optind < argc)
        c->demo_name = argv[optind++];
    if (optind < argc)
        return cli_usage_error("unexpected argument '%s' (one demo at a time)",
                           argv[optind]);
    return 0;
}

/* The demo or model file called name: a built-in demo, a path to a model
 * file (it ends in .eom or has a '/'), or a shipped model by name. *fd
 * receives a file's demo for the caller to free. Returns 0, or an exit
 * status after a message. */
static int find_demo(const char *name, const demo **d, demo **fd)
{
    char err[4096];
    int rc = demo_resolve(name, d, fd, err, sizeof err);
    if (rc == 1)
        return cli_usage_error("unknown demo '%s' (eom-run --list shows the "
                           "demos and model files; a model file's name "
                           "ends in .eom)", name);
    if (rc != 0) {
        fprintf(stderr, "eom-run: %s\n", err);
        return EXIT_RUN;
    }
    return 0;
}

/* The rest of main once the command line is read: returns the exit
 * status. */
static int run(cli *c, const demo *d)
{
    eom_model *model = NULL;
    eom_system *s = NULL;
    eom_csv_writer *w = NULL;
    double *settings = NULL, *x0 = NULL;
    char err[4096], default_out[1100];
    int status = EXIT_RUN, n, rc;
    eom_run_opts plan;

    if (c->modes + c->describe + c->linearize > 1)
        return cli_usage_error("--modes, --linearize and --describe: give "
                               "one of them");
    if (c->sens_arg && (c->modes || c->linearize || c->describe))
        return cli_usage_error("--sensitivity belongs to a run: not with "
                               "--modes, --linearize or --describe");
    if (c->sens_arg && c->opts.method != EOM_ADAMS &&
        c->opts.method != EOM_BDF && c->opts.method != EOM_IDA)
        return cli_usage_error("--sensitivity: the sensitivities are "
                               "integrated by --integrator adams, bdf or "
                               "ida, not %s",
                               eom_method_name(c->opts.method));
    if (c->sweep_arg && !c->modes)
        return cli_usage_error("--sweep belongs to --modes");
    if (c->indep_arg && !c->modes)
        return cli_usage_error("--independent belongs to --modes");
    if (((c->modes && !c->sweep_arg) || c->linearize) &&
        (c->plots || c->out))
        return cli_usage_error("--%s prints to standard output and runs "
                               "nothing: --out and --plots belong to a run "
                               "(or to --modes --sweep)",
                               c->modes ? "modes" : "linearize");
    if (c->out) {
        /* the model file, whether named by its path or a shipped one */
        char shipped[4096];
        if ((rc = cli_out_not_input(c->out, c->demo_name,
                                    "the model file")) != 0)
            return rc;
        if (file_demo_shipped(c->demo_name, shipped, sizeof shipped) == 0 &&
            (rc = cli_out_not_input(c->out, shipped, "the model file")) != 0)
            return rc;
    }
    if (c->plots && !d->after_run && !c->sweep_arg)
        return cli_usage_error("--plots: the demo %s has no plots", d->name);
    if (c->t_end / c->sample > MAX_ROWS)
        return cli_usage_error("--t-end / --sample = %g: more than %g rows",
                           c->t_end / c->sample, MAX_ROWS);
    settings = malloc(((size_t)d->nsettings + 1) * sizeof(double));
    if (!settings) {
        fprintf(stderr, "eom-run: out of memory\n");
        return EXIT_RUN;
    }
    if (overrides_settings(c->sets, c->nsets, d, settings, err,
                           sizeof err) != 0) {
        free(settings);
        return cli_usage_error("%s", err);
    }

    if (d->build(d, settings, &model, err, sizeof err) != 0) {
        fprintf(stderr, "eom-run: %s: cannot build the model: %s\n", d->name,
                err);
        goto done;
    }
    if (eom_system_new(&s, model, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "eom-run: %s: cannot set up the system: %s\n",
                d->name, err);
        goto done;
    }
    eom_model_free(&model);
    if (demo_check_names(d, s, err, sizeof err) != 0) {
        fprintf(stderr, "eom-run: %s\n", err);
        goto done;
    }
    n = eom_system_ncoords(s);
    x0 = malloc(2 * (size_t)n * sizeof(double) + 1);
    if (!x0 || eom_initial_state(s, x0) != EOM_OK) {
        fprintf(stderr, "eom-run: out of memory\n");
        goto done;
    }
    if (overrides_apply(c->sets, c->nsets, d, s, x0, err, sizeof err) != 0) {
        status = cli_usage_error("%s", err);
        goto done;
    }
    if (c->assemble_arg &&
        (rc = assemble_start(c->assemble_arg, s, x0, c->opts.proj_tol,
                             d->name, c->quiet, EXIT_RUN)) != 0) {
        status = rc;
        goto done;
    }
    if (c->indep_arg && (rc = independent_arg(c, s)) != 0) {
        status = rc;
        goto done;
    }
    if (c->sens_arg && (rc = sensitivity_arg(c, s)) != 0) {
        status = rc;
        goto done;
    }
    if (c->compiled)
        cli_compiled(s, d->name, c->quiet);
    if (c->baumgarte && eom_set_baumgarte(s, c->alpha, c->beta) != EOM_OK) {
        fprintf(stderr, "eom-run: %s\n", eom_system_errmsg(s));
        goto done;
    }

    if (c->describe) {
        if (describe_demo(stdout, d, settings, s, x0, c->extra) != 0) {
            fprintf(stderr, "eom-run: out of memory\n");
            goto done;
        }
        if (fflush(stdout) != 0 || ferror(stdout)) {
            fprintf(stderr, "eom-run: cannot write to standard output\n");
            goto done;
        }
        status = EXIT_SUCCESS;
        goto done;
    }
    if (c->modes) {
        status = modes(c, d, settings, s, x0);
        goto done;
    }
    if (eom_run_prepare_start(s, x0, &c->opts, "eom-run", d->name) != 0)
        goto done;
    if (c->linearize) {
        status = linearize_report(stdout, s, 0.0, x0, d->name) == 0
                     ? EXIT_SUCCESS
                     : EXIT_RUN;
        if (status == EXIT_SUCCESS &&
            (fflush(stdout) != 0 || ferror(stdout))) {
            fprintf(stderr, "eom-run: cannot write to standard output\n");
            status = EXIT_RUN;
        }
        goto done;
    }

    /* --plots needs a CSV file to read back: NAME.csv here by default */
    if (c->plots && !c->out) {
        const char *base = strrchr(d->name, '/');
        size_t len;
        base = base ? base + 1 : d->name;
        len = strlen(base);
        if (len > 4 && strcmp(base + len - 4, ".eom") == 0)
            len -= 4;
        snprintf(default_out, sizeof default_out, "%.*s.csv", (int)len,
                 base);
        c->out = default_out;
    }
    /* every check is done: only now create or truncate the output; from
     * here SIGTERM, SIGINT and SIGHUP stop the run after a whole row */
    cli_stop_install();
    if (eom_csv_writer_open(&w, c->out, err, sizeof err) != 0) {
        fprintf(stderr, "eom-run: %s\n", err);
        goto done;
    }
    eom_run_opts_default(&plan);
    plan.prog = "eom-run";
    plan.label = d->name;
    plan.t_end = c->t_end;
    plan.sample = c->sample;
    plan.opts = c->opts;
    plan.quiet = c->quiet;
    plan.extra = c->extra;
    plan.progress = isatty(STDERR_FILENO);
    plan.stop = &cli_stop_signal;
    plan.accept_unhealthy = c->accept_unhealthy;
    rc = eom_run(s, x0, &plan, w);
    status = rc == 0   ? EXIT_SUCCESS
             : rc == 2 ? 128 + cli_stop_signal
             : rc == 3 ? EXIT_UNHEALTHY
                       : EXIT_RUN;
    if (status == EXIT_UNHEALTHY)
        fprintf(stderr, "eom-run: exit status 3 (an unhealthy run); "
                "--accept-unhealthy accepts it\n");
    /* after a failure or a stop eom_run has said why; the writer says
     * where the rows are (FILE.partial, FILE unchanged) */
    if (eom_csv_writer_close(&w, err, sizeof err) != 0) {
        fprintf(stderr, "eom-run: %s\n", err);
        if (rc != 2)
            status = EXIT_RUN;
    }
    /* an unhealthy run's rows are whole: its plots show what went wrong */
    if ((status == EXIT_SUCCESS || status == EXIT_UNHEALTHY) && c->plots) {
        /* gnuplot takes a while on long runs: say what is going on, on a
         * terminal, and erase it after (like the progress line) */
        const int tty = plan.progress && !c->quiet;
        if (tty) {
            fprintf(stderr, "eom-run: %s: making the plots ...", d->name);
            fflush(stderr);
        }
        /* the CSV is closed: the plots read it back from the file */
        rc = d->after_run(d, settings, s, c->out, err, sizeof err);
        if (tty)
            fprintf(stderr, "\r%60s\r", "");
        if (rc != 0) {
            fprintf(stderr, "eom-run: %s: %s\n", d->name, err);
            status = EXIT_RUN;
        } else if (!c->quiet) {
            fprintf(stderr, "eom-run: %s: plots written beside '%s'\n",
                    d->name, c->out);
        }
    }
done:
    eom_csv_writer_close(&w, err, sizeof err);
    eom_model_free(&model);
    eom_system_free(&s);
    free(settings);
    free(x0);
    free(c->sens);
    c->sens = NULL;
    free(c->indep);
    c->indep = NULL;
    return status;
}

int main(int argc, char **argv)
{
    cli c;
    int status;

    memset(&c, 0, sizeof c);
    cli_args_program("eom-run", 1);
    c.t_end = 10.0;
    c.sample = 0.01;
    /* the defaults documented in --help and docs/cli.md, stated here so
     * that they stay true if libeom's own defaults change. The method is
     * erk, whose error control holds the run to the tolerances: rk4's
     * fixed step (libeom's default) can be wrong by far more with no sign
     * but the energy drift (--integrator rk4 still gives it) */
    eom_opts_default(&c.opts);
    c.opts.method = EOM_ERK;
    c.opts.dt = 1e-3;
    c.opts.rtol = 1e-8;
    c.opts.atol = 1e-10;
    c.opts.max_steps = 10000000L;
    c.opts.project = 1;
    /* at most one --set per argument */
    c.sets = malloc((size_t)argc * sizeof *c.sets);
    if (!c.sets) {
        fprintf(stderr, "eom-run: out of memory\n");
        return EXIT_RUN;
    }

    status = parse(argc, argv, &c);
    if (status == 0) {
        if (c.help) {
            help();
        } else if (c.list) {
            describe_list(stdout);
            file_demo_list(stdout);
        } else if (!c.demo_name) {
            usage_line(stderr);
            status = cli_usage_error("no demo given (eom-run --list shows the "
                                 "demos)");
        } else {
            const demo *d = NULL;
            demo *fd = NULL;
            status = find_demo(c.demo_name, &d, &fd);
            if (status == 0)
                status = run(&c, d);
            file_demo_free(&fd);
        }
    }
    free(c.sets);
    if (status == 0 && (fflush(stdout) != 0 || ferror(stdout))) {
        fprintf(stderr, "eom-run: cannot write to standard output\n");
        status = EXIT_RUN;
    }
    return status;
}
