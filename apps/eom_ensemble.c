/* eom_ensemble.c - eom-ensemble: many runs of one model (a demo or a
 * model file) on threads, one summary row per run (docs/ensembles.md).
 * The model is built and recorded once; each thread works on a clone
 * that shares its tapes. Runs come from a CSV (--runs) or a grid
 * (--sweep); each row of the summary gives the run's inputs, its status,
 * the final state, the energy balance and constraint residual at t_end,
 * steps, right-hand sides, wall time and, for a failed run, why. Rows
 * are written in run order; --resume skips the runs already in the
 * summary.
 *
 * Exit status: 0 every run succeeded, 1 some run failed (the summary says
 * which), the ensemble could not start or the summary could not be
 * written, 2 the command line is wrong, 3 no run failed but some ended
 * unhealthy (eom_run_judge; not with --accept-unhealthy), 128 + N
 * stopped by signal N
 * (SIGTERM, SIGINT, SIGHUP: the runs under way finish and are written,
 * --resume does the rest). */
#define _GNU_SOURCE /* getopt_long */
#include <getopt.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli_args.h"
#include "cli_stop.h"
#include "demos/demos.h"
#include "demos/file_demo.h"
#include "ensemble_page.h"
#include "ensemble_pool.h"
#include "ensemble_runs.h"
#include "ensemble_summary.h"
#ifdef EOM_ENSEMBLE_MPI
#include "ensemble_mpi.h"
#endif
#include "eom/eom.h"
#include "eom/run.h"
#include "overrides.h"

enum { EXIT_RUN = 1, EXIT_USAGE = CLI_EXIT_USAGE, EXIT_UNHEALTHY = 3 };

/* This process's MPI rank and the number of ranks (0 and 1 without MPI):
 * only rank 0 speaks on the command line's behalf and writes the
 * summary. */
static int g_rank, g_size = 1;

/* Rank 0: the ensemble stops when a rank has not answered for this many
 * seconds (--rank-timeout; read only in an MPI build) */
static double g_rank_timeout = 600.0;

#ifdef EOM_ENSEMBLE_MPI

/* A rank silent for longer than --rank-timeout: say which, and which
 * run it holds. 1 when one is, 0 when none. */
static int rank_stalled(void)
{
    long i;
    double silent;
    const int r = ensemble_mpi_stalled(g_rank_timeout, &i, &silent);
    char held[64] = "no run";
    if (r < 0)
        return 0;
    if (i >= 0)
        snprintf(held, sizeof held, "run %ld", i);
    fprintf(stderr, "eom-ensemble: rank %d has not answered for %.0f s "
            "(--rank-timeout %g; it holds %s): stopping every rank\n", r,
            silent, g_rank_timeout, held);
    return 1;
}
#endif

typedef struct cli {
    const char *model;
    override *sets;
    int nsets;
    char **sweeps;
    int nsweeps;
    char **dists;      /* --random */
    int ndists;
    long count;        /* --count */
    unsigned long long seed;
    const char *runs, *out, *traj;
    double t_end, sample;
    eom_opts opts;
    int threads, resume, quiet, help;
    int compiled; /* --compiled: every run on compiled tapes */
    int accept_unhealthy; /* --accept-unhealthy: exit 0 all the same */
    int plots;    /* --plots: the trajectories drawn in one page */
} cli;

enum { OPT_RUNS = 256, OPT_SWEEP, OPT_THREADS, OPT_TRAJ, OPT_RESUME,
       OPT_INTEGRATOR, OPT_DT, OPT_RTOL, OPT_ATOL, OPT_MAX_STEPS,
       OPT_NO_PROJECT, OPT_SAMPLE, OPT_RANDOM, OPT_COUNT, OPT_SEED,
       OPT_COMPILED, OPT_RANK_TIMEOUT, OPT_ACCEPT_UNHEALTHY, OPT_PLOTS };

static const struct option long_options[] = {
    {"help", no_argument, NULL, 'h'},
    {"set", required_argument, NULL, 's'},
    {"runs", required_argument, NULL, OPT_RUNS},
    {"sweep", required_argument, NULL, OPT_SWEEP},
    {"random", required_argument, NULL, OPT_RANDOM},
    {"count", required_argument, NULL, OPT_COUNT},
    {"seed", required_argument, NULL, OPT_SEED},
    {"out", required_argument, NULL, 'o'},
    {"threads", required_argument, NULL, OPT_THREADS},
    {"trajectories", required_argument, NULL, OPT_TRAJ},
    {"plots", no_argument, NULL, OPT_PLOTS},
    {"resume", no_argument, NULL, OPT_RESUME},
    {"t-end", required_argument, NULL, 't'},
    {"sample", required_argument, NULL, OPT_SAMPLE},
    {"integrator", required_argument, NULL, OPT_INTEGRATOR},
    {"dt", required_argument, NULL, OPT_DT},
    {"rtol", required_argument, NULL, OPT_RTOL},
    {"atol", required_argument, NULL, OPT_ATOL},
    {"max-steps", required_argument, NULL, OPT_MAX_STEPS},
    {"no-project", no_argument, NULL, OPT_NO_PROJECT},
    {"compiled", no_argument, NULL, OPT_COMPILED},
    {"rank-timeout", required_argument, NULL, OPT_RANK_TIMEOUT},
    {"accept-unhealthy", no_argument, NULL, OPT_ACCEPT_UNHEALTHY},
    {"quiet", no_argument, NULL, 'q'},
    {NULL, 0, NULL, 0},
};

static void help(void)
{
    printf(
        "usage: eom-ensemble MODEL (--runs RUNS.csv | --sweep NAME=LO:HI:N..."
        " |\n"
        "                    --random NAME=DIST... [--count N] [--seed S])"
        " --out SUMMARY.csv\n"
        "                    [OPTION]...\n\n"
        "Run MODEL (a demo, a shipped model or a model file PATH.eom) once "
        "per run, on\nthreads, and write one summary row per run.\n\n"
        "  -h, --help            show this help and exit\n"
        "      --runs FILE       the runs: a CSV whose header names what "
        "each run sets\n"
        "                        (parameters, coordinates, rates NAME_dot, "
        "t_end, rtol,\n"
        "                        atol, dt) and whose rows give the values\n"
        "      --sweep NAME=LO:HI:N  a grid of N values from LO to HI; "
        "repeat for a\n"
        "                        product grid (the first varies slowest)\n"
        "      --random NAME=uniform:LO:HI, --random NAME=normal:MEAN:SD\n"
        "                        --count runs drawn at random (repeat for "
        "more names)\n"
        "      --count N         the number of random runs (default 100)\n"
        "      --seed S          the generator's seed (default 1): the same "
        "seed, the\n"
        "                        same runs\n"
        "  -o, --out FILE        the summary CSV (required)\n"
        "      --resume          keep the runs already in the summary and do "
        "the rest\n"
        "      --threads K       K threads (default: the cores available)\n"
        "      --trajectories DIR  also write each run's CSV as "
        "DIR/run-K.csv\n"
        "      --plots           with --trajectories: also write "
        "SUMMARY-animation.html,\n"
        "                        the runs drawn over each other in one "
        "page\n"
        "  -s, --set NAME=VALUE  for every run: a structural setting, a "
        "parameter, an\n"
        "                        initial value or rate (as eom-run)\n"
        "  -t, --t-end T         end time of every run, >= 0 (default 10)\n"
        "      --sample DT       rows of the trajectories (default 0.01)\n"
        "      --integrator M    rk4, erk, adams, bdf, ida, esdirk or imex "
        "(default erk)\n"
        "      --dt H, --rtol R, --atol A, --max-steps N, --no-project\n"
        "                        as for eom-run\n"
        "      --compiled        every run on compiled tapes, compiled once "
        "(as eom-run)\n"
        "      --rank-timeout S  under MPI: stop every rank when one has "
        "not answered\n"
        "                        for S seconds (default 600; longer than "
        "the longest run)\n"
        "      --accept-unhealthy  exit with 0 when runs end unhealthy "
        "(their rows say so)\n"
        "  -q, --quiet           no progress line and no summary line\n"
        "\nExit status: 0 every run succeeded, 1 some run failed (see the "
        "summary's\nstatus and message columns) or the ensemble could not "
        "start, 2 the command\nline is wrong, 3 no run failed but some "
        "ended unhealthy (status unhealthy:\ntheir energy drift, residual "
        "or branch switches exceed what the tolerance\nallows; "
        "docs/run.md), 128 + N stopped by signal N "
        "(SIGTERM, SIGINT, SIGHUP: the runs\nunder way are written, "
        "--resume does the rest). See docs/ensembles.md.\n");
}

static int parse(int argc, char **argv, cli *c)
{
    char err[512];
    double v;
    long l;
    int opt, rc = 0;
    opterr = 0;
    while (rc == 0 && (opt = getopt_long(argc, argv, ":hs:o:t:q",
                                         long_options, NULL)) != -1) {
        switch (opt) {
        case 'h': c->help = 1; break;
        case 's':
            if (override_parse(optarg, &c->sets[c->nsets], err,
                               sizeof err) != 0)
                return cli_usage_error("%s", err);
            c->nsets++;
            break;
        case OPT_RUNS: c->runs = optarg; break;
        case OPT_SWEEP: c->sweeps[c->nsweeps++] = optarg; break;
        case OPT_RANDOM: c->dists[c->ndists++] = optarg; break;
        case OPT_COUNT:
            if (eom_numtext_parse_long(optarg, &l) != EOM_NUMTEXT_OK ||
                l < 1)
                return cli_usage_error("--count '%s': a whole number >= 1",
                                   optarg);
            c->count = l;
            break;
        case OPT_SEED:
            if (eom_numtext_parse_long(optarg, &l) != EOM_NUMTEXT_OK ||
                l < 0)
                return cli_usage_error("--seed '%s': a whole number >= 0",
                                   optarg);
            c->seed = (unsigned long long)l;
            break;
        case 'o': c->out = optarg; break;
        case OPT_THREADS:
            if (eom_numtext_parse_long(optarg, &l) != EOM_NUMTEXT_OK ||
                l < 1 || l > 1024)
                return cli_usage_error("--threads '%s': a whole number from 1 "
                                   "to 1024", optarg);
            c->threads = (int)l;
            break;
        case OPT_TRAJ: c->traj = optarg; break;
        case OPT_PLOTS: c->plots = 1; break;
        case OPT_RESUME: c->resume = 1; break;
        case 't': rc = cli_number_arg("--t-end", optarg, 0, &c->t_end); break;
        case OPT_SAMPLE: rc = cli_number_arg("--sample", optarg, 1, &c->sample); break;
        case OPT_INTEGRATOR:
            rc = cli_integrator_arg(optarg, &c->opts.method);
            break;
        case OPT_DT: rc = cli_number_arg("--dt", optarg, 1, &c->opts.dt); break;
        case OPT_RTOL: rc = cli_number_arg("--rtol", optarg, 1, &c->opts.rtol); break;
        case OPT_ATOL: rc = cli_number_arg("--atol", optarg, 1, &c->opts.atol); break;
        case OPT_MAX_STEPS:
            rc = cli_number_arg("--max-steps", optarg, 1, &v);
            if (rc == 0 && (v != floor(v) || v > 1e15))
                return cli_usage_error("--max-steps '%s': a whole number",
                                   optarg);
            c->opts.max_steps = (long)v;
            break;
        case OPT_NO_PROJECT: c->opts.project = 0; break;
        case OPT_COMPILED: c->compiled = 1; break;
        case OPT_RANK_TIMEOUT:
            rc = cli_number_arg("--rank-timeout", optarg, 1,
                                &g_rank_timeout);
            break;
        case OPT_ACCEPT_UNHEALTHY: c->accept_unhealthy = 1; break;
        case 'q': c->quiet = 1; break;
        case ':':
            return cli_usage_error("option '%s' needs an argument",
                               argv[optind - 1]);
        default:
            return cli_usage_error("unknown option '%s'", argv[optind - 1]);
        }
    }
    if (rc != 0)
        return rc;
    if (optind < argc)
        c->model = argv[optind++];
    if (optind < argc)
        return cli_usage_error("unexpected argument '%s'", argv[optind]);
    return 0;
}

/* ---- the inputs record (ensemble_summary.h) --------------------------- */

/* "KEY VALUE\n" for every input that changes a run's numbers: the model,
 * the runs, --set and the integration options. A new string (the caller
 * frees it), or NULL after a message. */
static char *inputs_record(const cli *c, const demo *d, const char *model)
{
    char digest[72], err[4096], num[32];
    size_t k = 0, cap = 4096;
    char *rec = malloc(cap);
    int i;
#define PUT(...)                                                           \
    do {                                                                   \
        int w_;                                                            \
        while (rec &&                                                      \
               (size_t)(w_ = snprintf(rec + k, cap - k, __VA_ARGS__)) >=   \
                   cap - k) {                                              \
            char *p_ = realloc(rec, 2 * cap + (size_t)w_);                 \
            if (!p_) {                                                     \
                free(rec);                                                 \
                rec = NULL;                                                \
            } else {                                                       \
                rec = p_;                                                  \
                cap = 2 * cap + (size_t)w_;                                \
            }                                                              \
        }                                                                  \
        if (rec)                                                           \
            k += (size_t)w_;                                               \
    } while (0)
#define PUTNUM(key, v)                                                     \
    do {                                                                   \
        eom_numtext_format(num, sizeof num, (v));                          \
        PUT("%s %s\n", (key), num);                                        \
    } while (0)
    PUT("autoeom-ensemble-inputs 1\n");
    if (d->data) { /* a model file: what it holds, wherever it is */
        char shipped[4096];
        const size_t ml = strlen(model);
        /* a shipped model's name, as demo_resolve finds it */
        if (!strchr(model, '/') &&
            !(ml > 4 && strcmp(model + ml - 4, ".eom") == 0) &&
            file_demo_shipped(model, shipped, sizeof shipped) == 0)
            model = shipped;
        if (ensemble_file_digest(model, digest, err, sizeof err) != 0) {
            fprintf(stderr, "eom-ensemble: %s\n", err);
            free(rec);
            return NULL;
        }
        PUT("model %s\n", digest);
    } else {
        PUT("model demo:%s\n", d->name);
    }
    if (c->runs) {
        if (ensemble_file_digest(c->runs, digest, err, sizeof err) != 0) {
            fprintf(stderr, "eom-ensemble: %s\n", err);
            free(rec);
            return NULL;
        }
        PUT("--runs %s\n", digest);
    } else {
        PUT("--runs none\n");
    }
    PUT("--sweep");
    for (i = 0; i < c->nsweeps; i++)
        PUT(" %s", c->sweeps[i]);
    PUT("%s\n", c->nsweeps ? "" : " none");
    PUT("--random");
    for (i = 0; i < c->ndists; i++)
        PUT(" %s", c->dists[i]);
    PUT("%s\n", c->ndists ? "" : " none");
    if (c->ndists) {
        PUT("--count %ld\n", c->count);
        PUT("--seed %llu\n", c->seed);
    }
    PUT("--set");
    for (i = 0; i < c->nsets; i++) {
        eom_numtext_format(num, sizeof num, c->sets[i].value);
        PUT(" %.*s=%s", (int)c->sets[i].namelen, c->sets[i].arg, num);
    }
    PUT("%s\n", c->nsets ? "" : " none");
    PUTNUM("--t-end", c->t_end);
    PUTNUM("--sample", c->sample);
    PUT("--integrator %s\n", eom_method_name(c->opts.method));
    PUTNUM("--dt", c->opts.dt);
    PUTNUM("--rtol", c->opts.rtol);
    PUTNUM("--atol", c->opts.atol);
    PUT("--max-steps %ld\n", c->opts.max_steps);
    PUT("--no-project %s\n", c->opts.project ? "no" : "yes");
    PUT("--compiled %s\n", c->compiled ? "yes" : "no");
#undef PUTNUM
#undef PUT
    if (!rec)
        fprintf(stderr, "eom-ensemble: out of memory\n");
    return rec;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Wait until run i is done (with other ranks, serving them meanwhile):
 * 1, or 0 when it never will be (the job stopped before handing it
 * out), or -1 after a message when a rank stopped answering. */
static int wait_for(ensemble_job *job, long i, int *active)
{
#ifdef EOM_ENSEMBLE_MPI
    if (g_size > 1) {
        const struct timespec nap = {0, 500000}; /* 0.5 ms */
        for (;;) {
            int done, never;
            pthread_mutex_lock(&job->lock);
            done = job->res[i].done;
            never = !done && ensemble_job_stopped(job) && i >= job->next;
            pthread_mutex_unlock(&job->lock);
            if (done || never)
                return done;
            if (!ensemble_mpi_serve(job, active)) {
                if (rank_stalled())
                    return -1;
                nanosleep(&nap, NULL);
            }
        }
    }
#else
    (void)active;
#endif
    return ensemble_pool_wait(job, i);
}

/* Tell every other rank that there is nothing left: 0, or -1 after a
 * message when a rank stopped answering. */
static int finish_ranks(ensemble_job *job, int *active)
{
#ifdef EOM_ENSEMBLE_MPI
    const struct timespec nap = {0, 500000};
    while (*active > 0)
        if (!ensemble_mpi_serve(job, active)) {
            if (rank_stalled())
                return -1;
            nanosleep(&nap, NULL);
        }
#else
    (void)job;
    (void)active;
#endif
    return 0;
}

static int run(cli *c, const demo *d)
{
    eom_model *model = NULL;
    eom_system *s = NULL;
    ensemble_runs runs;
    ensemble_job job;
    pthread_t *th = NULL;
    unsigned char *skip = NULL;
    double *settings = NULL, *x0 = NULL, *p0 = NULL, t0;
    char err[4096], *head = NULL, *inputs = NULL;
    long i, ndone = 0, failed = 0, unhealthy = 0, written = 0;
    int status = EXIT_RUN, n, k, started = 0, tty, active = g_size - 1;
    int wrote = 0; /* 0, or -1 once a row could not be written */
    int stalled = 0; /* an MPI rank stopped answering */
#ifdef EOM_ENSEMBLE_MPI
    int setup_ok = 0;
#endif
    FILE *f = NULL;

    memset(&runs, 0, sizeof runs);
    memset(&job, 0, sizeof job);
    if (!c->out)
        return cli_usage_error("--out SUMMARY.csv is required");
    {
        char shipped[4096];
        if ((k = cli_out_not_input(c->out, c->model, "the model file")) ||
            (file_demo_shipped(c->model, shipped, sizeof shipped) == 0 &&
             (k = cli_out_not_input(c->out, shipped, "the model file"))) ||
            (k = cli_out_not_input(c->out, c->runs, "the runs file")))
            return k;
    }
    if (c->plots && !c->traj)
        return cli_usage_error("--plots draws the trajectories: give "
                               "--trajectories DIR too");
    if (!!c->runs + (c->nsweeps > 0) + (c->ndists > 0) != 1)
        return cli_usage_error("give the runs with one of --runs FILE, --sweep "
                           "NAME=LO:HI:N or --random NAME=...");
    if ((c->runs ? ensemble_runs_read(&runs, c->runs, err, sizeof err)
         : c->nsweeps
             ? ensemble_runs_sweep(&runs, c->sweeps, c->nsweeps, err,
                                   sizeof err)
             : ensemble_runs_random(&runs, c->dists, c->ndists, c->count,
                                    c->seed, err, sizeof err)) != 0) {
        /* a file another machine may lack: every rank must hear of it */
        if (g_rank > 0)
            fprintf(stderr, "eom-ensemble (rank %d): %s\n", g_rank, err);
        status = cli_usage_error("%s", err);
        goto done;
    }
    settings = malloc(((size_t)d->nsettings + 1) * sizeof *settings);
    if (!settings ||
        overrides_settings(c->sets, c->nsets, d, settings, err,
                           sizeof err) != 0) {
        status = cli_usage_error("%s", settings ? err : "out of memory");
        goto done;
    }
    if (d->build(d, settings, &model, err, sizeof err) != 0 ||
        eom_system_new(&s, model, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "eom-ensemble: %s: %s\n", d->name, err);
        goto done;
    }
    eom_model_free(&model);
    /* compiled once here: every thread's clone inherits it */
    if (c->compiled)
        cli_compiled(s, d->name, c->quiet);
    n = eom_system_ncoords(s);
    x0 = malloc(2 * (size_t)n * sizeof *x0);
    p0 = malloc(((size_t)eom_system_nparams(s) + 1) * sizeof *p0);
    skip = calloc((size_t)runs.nruns, 1);
    job.res = calloc((size_t)runs.nruns, sizeof *job.res);
    th = calloc((size_t)c->threads, sizeof *th);
    if (!x0 || !p0 || !skip || !job.res || !th) {
        fprintf(stderr, "eom-ensemble: out of memory\n");
        goto done;
    }
    eom_initial_state(s, x0);
    if (overrides_apply(c->sets, c->nsets, d, s, x0, err, sizeof err) != 0 ||
        ensemble_runs_resolve(&runs, s, err, sizeof err) != 0) {
        status = cli_usage_error("%s", err);
        goto done;
    }
    for (k = 0; k < eom_system_nparams(s); k++)
        p0[k] = eom_get_param(s, k);
    head = ensemble_summary_header(&runs, s);
    if (!head) {
        fprintf(stderr, "eom-ensemble: out of memory\n");
        goto done;
    }
    if (c->traj && mkdir(c->traj, 0777) != 0 && access(c->traj, W_OK) != 0) {
        fprintf(stderr, "eom-ensemble: --trajectories: cannot write to "
                "'%s'\n", c->traj);
        goto done;
    }
    if (g_rank == 0) {
        /* SIGTERM, SIGINT and SIGHUP: no more runs are started, those
         * under way finish and are written (cli_stop.h). Other ranks keep
         * the default: rank 0 tells them when to stop */
        cli_stop_install();
        /* locked until the end; with --resume, checked against this
         * ensemble's inputs and runs */
        inputs = inputs_record(c, d, c->model);
        if (!inputs)
            goto done;
        f = ensemble_summary_open(c->out, c->resume, head, inputs, &runs, n,
                                  skip, &ndone);
        if (!f)
            goto done;
    }

    job.base = s;
    job.runs = &runs;
    job.x0 = x0;
    job.p0 = p0;
    job.opts = c->opts;
    job.t_end = c->t_end;
    job.sample = c->sample;
    job.traj_dir = c->traj;
    job.label = d->name;
    job.skip = skip;
    job.stop = &cli_stop_signal;
    pthread_mutex_init(&job.lock, NULL);
    pthread_cond_init(&job.cond, NULL);
#ifdef EOM_ENSEMBLE_MPI
    /* every rank is ready, or none starts (a rank left waiting would
     * wait for ever) */
    setup_ok = 1;
    if (g_size > 1 && !ensemble_mpi_all_ok(1)) {
        if (g_rank == 0)
            fprintf(stderr, "eom-ensemble: another rank could not set up "
                    "the ensemble (see its message): nothing was run\n");
        status = EXIT_RUN;
        goto destroy;
    }
    if (g_rank > 0) {
        status = ensemble_mpi_work(&job) == 0 ? EXIT_SUCCESS : EXIT_RUN;
        goto destroy;
    }
#endif
    t0 = now();
    started = ensemble_pool_start(&job, c->threads, th);
    if (started == 0 && g_size == 1) {
        fprintf(stderr, "eom-ensemble: no thread could start\n");
        goto destroy;
    }
    tty = !c->quiet && isatty(STDERR_FILENO);
    /* rows in run order, as the runs finish, each on the disk before the
     * next (ensemble_summary_put): the first write that fails stops the
     * ensemble, and so does a signal */
    for (i = 0; i < runs.nruns; i++) {
        if (skip[i])
            continue;
        if ((k = wait_for(&job, i, &active)) <= 0) {
            stalled = k < 0;
            break; /* stopped before run i started, or a rank is lost */
        }
        wrote = ensemble_summary_put(f, c->out, &runs, i, n, &job.res[i]);
        if (wrote != 0) {
            ensemble_job_halt(&job); /* the runs not started are not run */
            break;
        }
        failed += !job.res[i].ok;
        unhealthy += job.res[i].ok == 2;
        written++;
        free(job.res[i].final);
        job.res[i].final = NULL;
        if (tty) {
            const double el = now() - t0;
            const long todo = runs.nruns - ndone - written;
            fprintf(stderr, "\reom-ensemble: %ld/%ld runs, %ld failed, "
                    "%.0f s left    ", ndone + written, runs.nruns, failed,
                    el / (double)written * (double)todo);
        }
    }
    if (stalled) {
        /* the runs on this rank's threads and on the lost rank are not
         * waited for: the summary keeps its whole rows, and MPI_Abort
         * ends every process, the stopped one too */
        ensemble_job_halt(&job);
        ensemble_summary_close(&f, c->out, 1);
        fprintf(stderr, "eom-ensemble: '%s' keeps %ld runs; the same "
                "command with --resume does the rest\n", c->out,
                ndone + written);
#ifdef EOM_ENSEMBLE_MPI
        ensemble_mpi_abort(EXIT_RUN);
#endif
    }
    for (k = 0; k < started; k++)
        pthread_join(th[k], NULL);
    if (finish_ranks(&job, &active) != 0) {
        ensemble_summary_close(&f, c->out, wrote == 0);
        fprintf(stderr, "eom-ensemble: '%s' keeps %ld runs\n", c->out,
                ndone + written);
#ifdef EOM_ENSEMBLE_MPI
        ensemble_mpi_abort(EXIT_RUN);
#endif
    }
    if (tty)
        fprintf(stderr, "\r%70s\r", "");
    if (ensemble_summary_close(&f, c->out, wrote == 0) != 0 || wrote != 0)
        goto destroy;
    if (i < runs.nruns) { /* a signal stopped it */
        const long left = runs.nruns - ndone - written;
        fprintf(stderr, "eom-ensemble: %s: stopped by %s: %ld run%s "
                "written to '%s', %ld not run (the same command with "
                "--resume does them)\n", d->name,
                cli_stop_name(cli_stop_signal), ndone + written,
                ndone + written == 1 ? "" : "s", c->out, left);
        status = 128 + cli_stop_signal;
        goto destroy;
    }
    if (!c->quiet && g_size > 1)
        fprintf(stderr, "eom-ensemble: %s: %ld runs on %d rank%s (%d "
                "thread%s on rank 0) in %.3g s, %ld failed\n", d->name,
                written, g_size, g_size == 1 ? "" : "s", started,
                started == 1 ? "" : "s", now() - t0, failed);
    else if (!c->quiet)
        fprintf(stderr, "eom-ensemble: %s: %ld runs on %d thread%s in %.3g "
                "s, %ld failed%s%s\n", d->name, written, started,
                started == 1 ? "" : "s", now() - t0, failed,
                ndone ? ", kept from before: " : "",
                ndone ? "see the summary" : "");
    if (c->plots) {
        /* every run that reached its end (an unhealthy one too), and
         * those kept from before (--resume) whose trajectory is there */
        unsigned char *drawn = calloc((size_t)runs.nruns, 1);
        long nd = 0;
        if (!drawn) {
            fprintf(stderr, "eom-ensemble: out of memory\n");
            goto destroy;
        }
        for (i = 0; i < runs.nruns; i++) {
            char path[4096];
            snprintf(path, sizeof path, "%s/run-%ld.csv", c->traj, i);
            drawn[i] = skip[i] ? access(path, R_OK) == 0 : job.res[i].ok != 0;
        }
        k = ensemble_page_write(c->out, c->traj, &runs, drawn, s, d->name,
                                &nd);
        free(drawn);
        if (k != 0)
            goto destroy;
        if (!c->quiet && nd > 0)
            fprintf(stderr, "eom-ensemble: %s: %ld run%s drawn in the "
                    "animation page beside '%s'\n", d->name, nd,
                    nd == 1 ? "" : "s", c->out);
    }
    if (unhealthy > 0)
        fprintf(stderr, "eom-ensemble: %s: %ld run%s unhealthy (status "
                "unhealthy in the summary, the measure in its message)%s\n",
                d->name, unhealthy, unhealthy == 1 ? "" : "s",
                c->accept_unhealthy ? ": accepted as asked"
                                    : "; --accept-unhealthy accepts them");
    status = failed                                 ? EXIT_RUN
             : unhealthy > 0 && !c->accept_unhealthy ? EXIT_UNHEALTHY
                                                     : EXIT_SUCCESS;
destroy:
    pthread_mutex_destroy(&job.lock);
    pthread_cond_destroy(&job.cond);
done:
#ifdef EOM_ENSEMBLE_MPI
    /* a failure before every rank said it was ready: tell the others */
    if (g_size > 1 && !setup_ok)
        ensemble_mpi_all_ok(0);
#endif
    if (f)
        fclose(f);
    for (i = 0; job.res && i < runs.nruns; i++)
        free(job.res[i].final);
    free(job.res);
    free(th);
    free(skip);
    free(head);
    free(inputs);
    free(settings);
    free(x0);
    free(p0);
    ensemble_runs_free(&runs);
    eom_model_free(&model);
    eom_system_free(&s);
    return status;
}

int main(int argc, char **argv)
{
    cli c;
    const demo *d = NULL;
    demo *fd = NULL;
    char err[4096];
    int status;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
#ifdef EOM_ENSEMBLE_MPI
    if (ensemble_mpi_init(&argc, &argv, &g_rank, &g_size) != 0) {
        fprintf(stderr, "eom-ensemble: MPI does not start (it needs "
                "MPI_THREAD_FUNNELED)\n");
        return EXIT_RUN;
    }
#endif
    cli_args_program("eom-ensemble", g_rank == 0);
    memset(&c, 0, sizeof c);
    c.t_end = 10.0;
    c.sample = 0.01;
    c.threads = cores > 0 ? (int)(cores > 1024 ? 1024 : cores) : 1;
    eom_opts_default(&c.opts);
    /* erk, as eom-run: its error control holds every run to the
     * tolerances, where rk4's fixed step can be wrong with no sign but
     * the energy (--integrator rk4 still gives it) */
    c.opts.method = EOM_ERK;
    c.opts.dt = 1e-3;
    c.opts.rtol = 1e-8;
    c.opts.atol = 1e-10;
    c.opts.max_steps = 10000000L;
    c.opts.project = 1;
    c.sets = malloc((size_t)argc * sizeof *c.sets);
    c.sweeps = malloc((size_t)argc * sizeof *c.sweeps);
    c.dists = malloc((size_t)argc * sizeof *c.dists);
    c.count = 100;
    c.seed = 1;
    if (!c.sets || !c.sweeps || !c.dists) {
        fprintf(stderr, "eom-ensemble: out of memory\n");
        return EXIT_RUN;
    }
    status = parse(argc, argv, &c);
    if (status == 0 && c.help) {
        help();
    } else if (status == 0 && !c.model) {
        status = cli_usage_error("no model given (eom-run --list shows the "
                             "demos and model files)");
    } else if (status == 0) {
        int rc = demo_resolve(c.model, &d, &fd, err, sizeof err);
        if (rc == 1)
            status = cli_usage_error("unknown demo or model '%s'", c.model);
        else if (rc != 0)
            status = (fprintf(stderr, "eom-ensemble%s: %s\n",
                              g_rank > 0 ? " (another rank)" : "", err),
                      EXIT_RUN);
        else
            status = run(&c, d);
#ifdef EOM_ENSEMBLE_MPI
        /* a rank that found no model releases the others, which wait for
         * every rank to be ready */
        if (rc != 0 && g_size > 1)
            ensemble_mpi_all_ok(0);
#endif
        file_demo_free(&fd);
    }
    free(c.sets);
    free(c.sweeps);
    free(c.dists);
#ifdef EOM_ENSEMBLE_MPI
    ensemble_mpi_finalize();
#endif
    return status;
}
