/* test_cli.c - eom-run seen from outside: each case runs the built
 * program in a child process with its output captured (cli_support.h),
 * and checks the exit status, words of its messages and the CSV it
 * writes (parsed back and compared with the spring pendulum's formulas,
 * computed here). The chain demos have their own cases in
 * test_cli_chains.c.
 *
 * usage: test_cli EOM_RUN CASE [DOCS_CLI_MD]
 * EOM_CLI_WRAPPER runs eom-run under a wrapper such as valgrind
 * (cli_support.h). No check depends on timing. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "cli_support.h"

static const char *docs_cli; /* docs/cli.md, for the "help" case */

/* Run eom-run (args NULL-terminated, which must write the CSV to the
 * scratch file out.csv) and parse the file. Returns the exit status. */
/* Run args and read the CSV written to name in the scratch directory. */
static int run_csv_in(csv *c, const char *const *args, result *r,
                      const char *name)
{
    char path[300];
    char *text;
    scratch(path, sizeof path, name);
    run(r, args);
    text = read_file(path, NULL);
    memset(c, 0, sizeof *c);
    if (!text) {
        CHECK_FAIL_("no CSV file written (status %d):\n%s", r->status,
                    r->err);
        return r->status;
    }
    {
        char msg[512];
        int ok = csv_parse(text, c, msg, sizeof msg) == 0;
        check_count_++;
        if (!ok)
            CHECK_FAIL_("%s", msg);
    }
    free(text);
    unlink(path);
    return r->status;
}

static int run_csv(csv *c, const char *const *args, result *r)
{
    return run_csv_in(c, args, r, "out.csv");
}

/* ---- the spring pendulum, independently -------------------------------- */

enum { C_T, C_R, C_TH, C_RD, C_THD, C_KE, C_PE, C_E, C_W, NCOLS };
static const char header[] = "t,r,theta,r_dot,theta_dot,T,V,E,W";

typedef struct sp {
    double m, k, r0, g;
} sp;

static double sp_T(const sp *p, const double *row)
{
    return 0.5 * p->m * (row[C_RD] * row[C_RD] +
                         row[C_R] * row[C_R] * row[C_THD] * row[C_THD]);
}

static double sp_V(const sp *p, const double *row)
{
    double s = row[C_R] - p->r0;
    return 0.5 * p->k * s * s + p->m * p->g * (p->r0 - row[C_R] *
                                               cos(row[C_TH]));
}

/* Accelerations from Lagrange's equations, derived by hand. */
static void sp_acc(const sp *p, const double *row, double *rdd, double *thdd)
{
    double r = row[C_R], th = row[C_TH], rd = row[C_RD], thd = row[C_THD];
    *rdd = r * thd * thd - p->k / p->m * (r - p->r0) + p->g * cos(th);
    *thdd = -(p->g * sin(th) + 2.0 * rd * thd) / r;
}

/* The checks every spring-pendulum CSV must pass: header, rows exactly
 * at k * sample (and at t_end when it is off the grid), finite values,
 * T and V from the row's own state, E = T + V, W = 0, E conserved to
 * drift_tol relative, and accelerations from central differences of the
 * rates that match the hand-derived equations of motion. */
static void check_sp_csv(const csv *c, const sp *p, double sample,
                         double t_end, int off_grid, double drift_tol)
{
    const int K = off_grid ? c->nrows - 2 : c->nrows - 1;
    int i, j;
    double E0;
    CHECK(strcmp(c->header, header) == 0);
    if (strcmp(c->header, header) != 0)
        fprintf(stderr, "header: '%s'\n", c->header);
    CHECK_INT(c->ncols, NCOLS);
    if (c->ncols != NCOLS || c->nrows < 1)
        return;
    for (i = 0; i <= K; i++)
        CHECK(at(c, i, C_T) == (double)i * sample);
    if (off_grid)
        CHECK(at(c, c->nrows - 1, C_T) == t_end);
    else
        CHECK_NEAR(at(c, c->nrows - 1, C_T), t_end, 1e-12);
    E0 = at(c, 0, C_E);
    for (i = 0; i < c->nrows; i++) {
        const double *row = c->v + i * c->ncols;
        int finite = 1;
        for (j = 0; j < c->ncols; j++)
            finite &= isfinite(row[j]) != 0;
        CHECK(finite);
        CHECK_NEAR(row[C_KE], sp_T(p, row), 1e-12);
        CHECK_NEAR(row[C_PE], sp_V(p, row), 1e-12);
        CHECK_NEAR(row[C_E], row[C_KE] + row[C_PE], 1e-12);
        CHECK(row[C_W] == 0.0);
        CHECK_NEAR(row[C_E] + row[C_W], E0, drift_tol);
    }
    /* central differences over the on-grid rows: error O(sample^2) */
    for (i = 1; i + 1 <= K; i++) {
        const double *row = c->v + i * c->ncols;
        double rdd, thdd;
        sp_acc(p, row, &rdd, &thdd);
        CHECK_NEAR((at(c, i + 1, C_RD) - at(c, i - 1, C_RD)) / (2 * sample),
                   rdd, 2e-2);
        CHECK_NEAR((at(c, i + 1, C_THD) - at(c, i - 1, C_THD)) /
                       (2 * sample), thdd, 2e-2);
    }
}

static const sp sp_default = {1.0, 75.0, 1.0, 9.81};

/* ---- cases -------------------------------------------------------------- */

static void case_list(void)
{
    const char *args[] = {"--list", NULL};
    result r;
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.out, "spring-pendulum");
    CHECK_HAS(r.out, "spring");
    CHECK(r.err[0] == '\0');
    result_free(&r);
}

/* The line of out whose first word is name contains every word of
 * words (NULL-terminated) as a whole word. */
static void check_describe_line(const char *out, const char *name,
                                const char *const *words)
{
    const char *line = out;
    while (line && *line) {
        const char *end = strchr(line, '\n'), *p = line;
        size_t len = end ? (size_t)(end - line) : strlen(line), nl;
        char buf[512];
        while (*p == ' ')
            p++;
        nl = strlen(name);
        if (strncmp(p, name, nl) == 0 && p[nl] == ' ' &&
            len < sizeof buf) {
            int k;
            memcpy(buf, line, len);
            buf[len] = '\0';
            for (k = 0; words[k]; k++) {
                /* a whole word: bounded by blanks or the line's ends */
                const char *q = buf;
                size_t wl = strlen(words[k]);
                int found = 0;
                while ((q = strstr(q, words[k])) != NULL) {
                    if ((q == buf || q[-1] == ' ') &&
                        (q[wl] == ' ' || q[wl] == '\0')) {
                        found = 1;
                        break;
                    }
                    q++;
                }
                check_count_++;
                if (!found)
                    CHECK_FAIL_("--describe: '%s' missing on the line of "
                                "%s: '%s'", words[k], name, buf);
            }
            return;
        }
        line = end ? end + 1 : NULL;
    }
    CHECK_FAIL_("--describe: no line for %s:\n%s", name, out);
}

static void case_describe(void)
{
    const char *args[] = {"spring-pendulum", "--describe", NULL};
    const char *set_args[] = {"spring-pendulum", "--describe", "--set",
                              "k=100", "--set", "theta_dot=0.3", NULL};
    const char *m[] = {"1", "kg", NULL}, *k[] = {"75", "N/m", NULL};
    const char *r0[] = {"1", "m", NULL}, *g[] = {"9.81", "m/s^2", NULL};
    const char *rr[] = {"1.1", "0", "m", "m/s", NULL};
    const char *th[] = {"0.5", "0", "rad", "rad/s", NULL};
    const char *k100[] = {"75", "(set:", "100)", NULL};
    result r;
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK(r.err[0] == '\0');
    check_describe_line(r.out, "m", m);
    check_describe_line(r.out, "k", k);
    check_describe_line(r.out, "r0", r0);
    check_describe_line(r.out, "g", g);
    check_describe_line(r.out, "r", rr);
    check_describe_line(r.out, "theta", th);
    CHECK_HAS(r.out, "structural settings: none");
    CHECK_HAS(r.out, header);
    result_free(&r);

    /* --set values in use appear beside the defaults */
    run(&r, set_args);
    CHECK_INT(r.status, 0);
    check_describe_line(r.out, "k", k100);
    result_free(&r);
}

/* --help names every option, and docs/cli.md documents each of them. */
static void case_help(void)
{
    static const char *const options[] = {
        "--help", "--list", "--describe", "--set", "--t-end", "--sample",
        "--integrator", "--dt", "--rtol", "--atol", "--max-steps",
        "--max-order", "--tol-per-step", "--no-project", "--baumgarte", "--out", "--quiet", NULL};
    const char *args[] = {"--help", NULL};
    char *doc = docs_cli ? read_file(docs_cli, NULL) : NULL;
    const char *p;
    result r;
    int k;
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.out, "usage:");
    for (k = 0; options[k]; k++)
        CHECK_HAS(r.out, options[k]);
    CHECK(doc != NULL);
    /* every long option the help shows is in the document */
    for (p = r.out; doc && (p = strstr(p, "--")) != NULL; ) {
        char opt[64];
        size_t n = 2;
        while (n < sizeof opt - 1 &&
               ((p[n] >= 'a' && p[n] <= 'z') || p[n] == '-'))
            n++;
        memcpy(opt, p, n);
        opt[n] = '\0';
        if (n > 2)
            CHECK_HAS(doc, opt);
        p += n;
    }
    free(doc);
    result_free(&r);
}

static void case_csv(void)
{
    char path[300];
    const char *args[] = {"spring-pendulum", "--integrator", "rk4",
                          "--t-end", "0.5", "--out", path, NULL};
    const char *args_stdout[] = {"spring-pendulum", "--integrator", "rk4",
                                 "--t-end", "0.5", "-q", NULL};
    char *file;
    result r, r2;
    csv c;
    scratch(path, sizeof path, "out.csv");

    CHECK_INT(run_csv(&c, args, &r), 0);
    CHECK_INT(c.nrows, 51);
    check_sp_csv(&c, &sp_default, 0.01, 0.5, 0, 1e-9);
    if (c.nrows > 0 && c.ncols == NCOLS) {
        /* the documented default start */
        CHECK(at(&c, 0, C_R) == 1.1);
        CHECK(at(&c, 0, C_TH) == 0.5);
        CHECK(at(&c, 0, C_RD) == 0.0);
        CHECK(at(&c, 0, C_THD) == 0.0);
    }
    /* the summary: its figures against what they count or measure, taken
     * from the rows of the CSV and from rk4's four stages per step */
    CHECK_INT(number_after(r.err, "with rk4: "), 51);
    CHECK_NEAR(number_after(r.err, "t = 0 .. "), 0.5, 1e-15);
    CHECK_INT(number_after(r.err, "steps "), 500);
    CHECK_INT(number_after(r.err, "right-hand sides "), 2000);
    CHECK_INT(number_after(r.err, "failed steps "), 0);
    CHECK(number_after(r.err, "wall time ") >= 0.0);
    if (c.nrows > 0 && c.ncols == NCOLS) {
        double drift = 0.0, scale = 0.0;
        int i;
        for (i = 0; i < c.nrows; i++) {
            const double E = at(&c, i, C_E), L = at(&c, i, C_KE) -
                                                  at(&c, i, C_PE);
            drift = fmax(drift, fabs(E + at(&c, i, C_W) - at(&c, 0, C_E)));
            scale = fmax(scale, fmax(fabs(E), fabs(L)));
        }
        CHECK(drift > 0.0);
        CHECK_REL(number_after(r.err, "max |E + W - E0| = "), drift, 5e-3);
        CHECK_REL(number_after(r.err, "(scale "), scale, 5e-6);
        CHECK_REL(number_after(r.err, ", relative "), drift / scale, 5e-3);
    }
    CHECK_HAS(r.err, "constraint residual: none");
    CHECK(r.out[0] == '\0');
    free(c.v);
    result_free(&r);

    /* without --out the same bytes go to stdout; --quiet: nothing else */
    run(&r, args);
    file = read_file(path, NULL);
    run(&r2, args_stdout);
    CHECK_INT(r2.status, 0);
    CHECK(file && strcmp(file, r2.out) == 0);
    CHECK(r2.err[0] == '\0');
    free(file);
    unlink(path);
    result_free(&r);
    result_free(&r2);
}

/* Sample grids: off-grid t_end, t_end = 0, and a t_end that is a multiple
 * only up to rounding (0.3 / 0.1). */
static void case_grid(void)
{
    char path[300];
    const char *off[] = {"spring-pendulum", "--t-end", "0.025", "-q",
                         "--out", path, NULL};
    const char *zero[] = {"spring-pendulum", "--t-end", "0", "-q", "--out",
                          path, NULL};
    const char *round[] = {"spring-pendulum", "--t-end", "0.3", "--sample",
                           "0.1", "--dt", "1e-4", "-q", "--out", path,
                           NULL};
    result r;
    csv c;
    scratch(path, sizeof path, "out.csv");

    CHECK_INT(run_csv(&c, off, &r), 0);
    CHECK_INT(c.nrows, 4);
    check_sp_csv(&c, &sp_default, 0.01, 0.025, 1, 1e-9);
    free(c.v);
    result_free(&r);

    CHECK_INT(run_csv(&c, zero, &r), 0);
    CHECK_INT(c.nrows, 1);
    check_sp_csv(&c, &sp_default, 0.01, 0.0, 0, 1e-9);
    free(c.v);
    result_free(&r);

    CHECK_INT(run_csv(&c, round, &r), 0);
    CHECK_INT(c.nrows, 4);
    if (c.nrows == 4 && c.ncols == NCOLS)
        CHECK(at(&c, 3, C_T) == 3 * 0.1);
    free(c.v);
    result_free(&r);
}

/* --set changes the initial state and the parameters; the last value of
 * a name wins. */
static void case_set(void)
{
    char path[300];
    const char *args[] = {"spring-pendulum", "--set", "k=50", "--set",
                          "k=100", "--set", "r=1.2", "-s", "theta_dot=0.3",
                          "--set", "m=2", "--t-end", "0.2", "-q", "--out",
                          path, NULL};
    const sp p = {2.0, 100.0, 1.0, 9.81};
    result r;
    csv c;
    scratch(path, sizeof path, "out.csv");
    CHECK_INT(run_csv(&c, args, &r), 0);
    CHECK_INT(c.nrows, 21);
    check_sp_csv(&c, &p, 0.01, 0.2, 0, 1e-9);
    if (c.nrows > 0 && c.ncols == NCOLS) {
        const double *row = c.v;
        CHECK(row[C_R] == 1.2);
        CHECK(row[C_TH] == 0.5);
        CHECK(row[C_RD] == 0.0);
        CHECK(row[C_THD] == 0.3);
        /* the spring with k = 100, m = 2: not the defaults */
        CHECK_NEAR(row[C_PE], 0.5 * 100.0 * 0.2 * 0.2 +
                                  2.0 * 9.81 * (1.0 - 1.2 * cos(0.5)), 1e-14);
        CHECK_NEAR(row[C_KE], 0.5 * 2.0 * 1.44 * 0.09, 1e-14);
    }
    free(c.v);
    result_free(&r);
}

typedef struct bad_case {
    const char *args[8];
    int status;          /* expected exit status */
    const char *word;    /* expected in stderr */
} bad_case;

/* Each bad command line: the documented status, a message naming the
 * problem, nothing on stdout. */
static void case_usage(void)
{
    static const bad_case cases[] = {
        {{NULL}, 2, "no demo"},
        {{"no-such-demo"}, 2, "unknown demo 'no-such-demo'"},
        {{"--describe"}, 2, "no demo"},
        {{"spring-pendulum", "--bogus"}, 2, "unknown or ambiguous option "
                                            "'--bogus'"},
        {{"spring-pendulum", "-x"}, 2, "unknown option '-x'"},
        {{"spring-pendulum", "--quiet=1"}, 2, "does not take an argument"},
        {{"spring-pendulum", "--t-end"}, 2, "'--t-end' needs an argument"},
        {{"spring-pendulum", "--set"}, 2, "'--set' needs an argument"},
        {{"spring-pendulum", "--set", "k"}, 2, "NAME=VALUE"},
        {{"spring-pendulum", "--set", "=5"}, 2, "empty name"},
        {{"spring-pendulum", "--set", "k="}, 2, "is empty"},
        {{"spring-pendulum", "--set", "k=abc"}, 2, "not a number"},
        {{"spring-pendulum", "--set", "k= 5"}, 2, "not a number"},
        {{"spring-pendulum", "--set", "k=inf"}, 2, "not finite"},
        {{"spring-pendulum", "--set", "k=nan"}, 2, "not finite"},
        {{"spring-pendulum", "--set", "k=1e999"}, 2, "out of range"},
        {{"spring-pendulum", "--set", "k=5x"}, 2, "trailing"},
        {{"spring-pendulum", "--set", "kk=5"}, 2, "named 'kk'"},
        {{"spring-pendulum", "--set", "kk=5"}, 2, "--describe"},
        {{"spring-pendulum", "--set", "r_dott=5"}, 2, "named 'r_dott'"},
        {{"spring-pendulum", "--set", "_dot=5"}, 2, "named '_dot'"},
        {{"spring-pendulum", "--sample", "0"}, 2, "--sample '0'"},
        {{"spring-pendulum", "--sample", "-0.1"}, 2, "must be > 0"},
        {{"spring-pendulum", "--dt", "0"}, 2, "--dt '0'"},
        {{"spring-pendulum", "--dt", "-1e-3"}, 2, "must be > 0"},
        {{"spring-pendulum", "--t-end", "-1"}, 2, "must be >= 0"},
        {{"spring-pendulum", "--t-end", "nan"}, 2, "not finite"},
        {{"spring-pendulum", "--rtol", "0"}, 2, "--rtol"},
        {{"spring-pendulum", "--atol", "-1"}, 2, "--atol"},
        {{"spring-pendulum", "--max-steps", "0"}, 2, "must be >= 1"},
        {{"spring-pendulum", "--max-steps", "2.5"}, 2, "not an integer"},
        {{"spring-pendulum", "--max-order", "0"}, 2, "1 to 12"},
        {{"spring-pendulum", "--max-order", "2.5"}, 2, "not an integer"},
        {{"spring-pendulum", "--max-order", "13"}, 2, "1 to 12"},
        {{"spring-pendulum", "--linear-solver", "klu"}, 2,
         "choose auto, dense or sparse"},
        {{"spring-pendulum", "--baumgarte", "1"}, 2, "ALPHA,BETA"},
        {{"spring-pendulum", "--baumgarte", "1,-2"}, 2, "must be >= 0"},
        {{"spring-pendulum", "--integrator", "euler"}, 2,
         "unknown integrator"},
        {{"spring-pendulum", "--erk-table", "ARKODE_NOPE"}, 2,
         "ARKODE_DORMAND_PRINCE_7_4_5"},
        {{"spring-pendulum", "--t-end", "1e9", "--sample", "1e-9"}, 2,
         "rows"},
        {{"spring-pendulum", "extra"}, 2, "unexpected argument 'extra'"},
        {{"spring-pendulum", "--out", "/nonexistent-dir/x/out.csv"}, 1,
         "cannot open"},
        {{"spring-pendulum", "--out", ""}, 2, "empty file name"},
    };
    char path[300];
    const char *keep[] = {"spring-pendulum", "--set", "kk=1", "--out", path,
                          NULL};
    size_t i;
    char *text;
    FILE *f;
    result r;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        run(&r, cases[i].args);
        check_count_++;
        if (r.status != cases[i].status || !has(r.err, cases[i].word) ||
            r.out[0] != '\0')
            CHECK_FAIL_("eom-run %s %s %s %s: status %d (want %d), stderr "
                        "'%s' (want '%s'), stdout '%.80s'",
                        cases[i].args[0] ? cases[i].args[0] : "",
                        cases[i].args[0] && cases[i].args[1]
                            ? cases[i].args[1] : "",
                        cases[i].args[0] && cases[i].args[1] &&
                                cases[i].args[2] ? cases[i].args[2] : "",
                        cases[i].args[0] && cases[i].args[1] &&
                                cases[i].args[2] && cases[i].args[3]
                            ? cases[i].args[3] : "",
                        r.status, cases[i].status, r.err, cases[i].word,
                        r.out);
        result_free(&r);
    }

    /* a bad command line leaves an existing output file alone */
    scratch(path, sizeof path, "keep.csv");
    f = fopen(path, "w");
    CHECK(f != NULL);
    if (f) {
        fputs("keep\n", f);
        fclose(f);
    }
    run(&r, keep);
    CHECK_INT(r.status, 2);
    text = read_file(path, NULL);
    CHECK(text && strcmp(text, "keep\n") == 0);
    free(text);
    unlink(path);
    result_free(&r);
}

/* Integrator failures: status 1, libeom's message, and the rows written
 * before the failure kept in the file. */
static void case_failure(void)
{
    char path[300];
    const char *steps[] = {"spring-pendulum", "--integrator", "rk4",
                           "--max-steps", "1", "--out", path, NULL};
    /* RK4 far beyond its stability limit (h w = 17): the state grows by
     * orders of magnitude each step until it overflows */
    const char *diverge[] = {"spring-pendulum", "--integrator", "rk4",
                             "--dt", "2", "--sample", "2", "--t-end",
                             "1000", "-q", "--out", path, NULL};
    result r;
    csv c;
    int i, j;
    scratch(path, sizeof path, "out.csv");

    /* a failed run leaves its rows in out.csv.partial, no out.csv */
    CHECK_INT(run_csv_in(&c, steps, &r, "out.csv.partial"), 1);
    CHECK(access(path, F_OK) != 0);
    CHECK_HAS(r.err, "out.csv.partial");
    CHECK_HAS(r.err, "integration failed");
    CHECK_HAS(r.err, "rk4");
    CHECK_HAS(r.err, "max_steps");
    CHECK_HAS(r.err, "energy drift"); /* the summary still comes */
    CHECK(strcmp(c.header, header) == 0);
    CHECK_INT(c.nrows, 1);
    free(c.v);
    result_free(&r);

    CHECK_INT(run_csv_in(&c, diverge, &r, "out.csv.partial"), 1);
    CHECK_HAS(r.err, "spring-pendulum");
    CHECK_HAS(r.err, "not finite");
    CHECK(strcmp(c.header, header) == 0);
    CHECK(c.nrows >= 2 && c.nrows < 500);
    for (i = 0; i < c.nrows; i++)
        CHECK(at(&c, i, C_T) == 2.0 * i);
    /* the rows before the blow-up are complete */
    for (i = 0; i + 1 < c.nrows; i++)
        for (j = 0; j < c.ncols; j++)
            CHECK(isfinite(at(&c, i, j)));
    free(c.v);
    result_free(&r);

    /* a full disk is a run failure with a message, not a short file */
    if (access("/dev/full", W_OK) == 0) {
        const char *full[] = {"spring-pendulum", "-q", "--out", "/dev/full",
                              NULL};
        run(&r, full);
        CHECK_INT(r.status, 1);
        CHECK_HAS(r.err, "cannot write");
        result_free(&r);
    }
}

/* Every method through the same options gives a correct CSV. */
static void case_methods(void)
{
    static const char *const methods[] = {"rk4", "erk", "adams", "bdf",
                                          "ida", "imex"};
    char path[300];
    const char *args[] = {"spring-pendulum", "--integrator", NULL,
                          "--t-end", "0.2", "-q", "--out", path, NULL};
    size_t i;
    result r;
    csv c;
    scratch(path, sizeof path, "out.csv");
    for (i = 0; i < sizeof methods / sizeof methods[0]; i++) {
        args[2] = methods[i];
        run_csv(&c, args, &r);
        check_count_++;
        if (r.status != 0)
            CHECK_FAIL_("method %s: status %d: %s", methods[i], r.status,
                        r.err);
        CHECK_INT(c.nrows, 21);
        check_sp_csv(&c, &sp_default, 0.01, 0.2, 0, 1e-6);
        free(c.v);
        result_free(&r);
    }
}

/* With no --integrator the method is erk, error-controlled: the summary
 * names it, its steps are its own (not t-end / dt), and the rows match
 * the closed-form checks of check_sp_csv; --integrator rk4 still takes
 * its fixed steps of --dt. */
static void case_default_method(void)
{
    char path[300];
    const char *dflt[] = {"spring-pendulum", "--t-end", "2", "--out", path,
                          NULL};
    const char *rk4[] = {"spring-pendulum", "--t-end", "2", "--integrator",
                         "rk4", "--out", path, NULL};
    result r;
    csv c;
    scratch(path, sizeof path, "out.csv");
    CHECK_INT(run_csv(&c, dflt, &r), 0);
    CHECK_HAS(r.err, "spring-pendulum with erk: ");
    CHECK_INT(number_after(r.err, "with erk: "), 201);
    CHECK(number_after(r.err, "steps ") > 0 &&
          number_after(r.err, "steps ") < 2000);
    CHECK_INT(c.nrows, 201);
    check_sp_csv(&c, &sp_default, 0.01, 2.0, 0, 1e-6);
    free(c.v);
    result_free(&r);
    CHECK_INT(run_csv(&c, rk4, &r), 0);
    CHECK_HAS(r.err, "spring-pendulum with rk4: ");
    CHECK_INT(number_after(r.err, "steps "), 2000);
    free(c.v);
    result_free(&r);
}

/* bdf's steps over 1 s from the summary, with extra options */
static double bdf_steps(const char *rtol, const char *opt, const char *val)
{
    char path[300];
    const char *args[] = {"spring-pendulum", "--integrator", "bdf",
                          "--t-end", "1", "--rtol", rtol, "--atol", rtol,
                          "--out", path, opt, val, NULL};
    double steps;
    result r;
    scratch(path, sizeof path, "out.csv");
    run(&r, args);
    CHECK_INT(r.status, 0);
    steps = number_after(r.err, "steps ");
    result_free(&r);
    return steps;
}

/* --tol-per-step hands bdf the tolerance as given: fewer steps than the
 * default's tighter per-step tolerance; --max-order 1 (backward Euler)
 * takes more steps than order 5 */
static void case_tolerances(void)
{
    const double dflt = bdf_steps("1e-8", NULL, NULL);
    const double given = bdf_steps("1e-8", "--tol-per-step", NULL);
    const double five = bdf_steps("1e-4", NULL, NULL);
    const double euler = bdf_steps("1e-4", "--max-order", "1");
    printf("bdf steps over 1 s at 1e-8: %g by default, %g with "
           "--tol-per-step; at 1e-4: %g, %g with --max-order 1\n", dflt,
           given, five, euler);
    CHECK(given > 0 && dflt > 1.5 * given);
    CHECK(five > 0 && euler > 3.0 * five);
}

/* --linear-solver: ida's and bdf's choice in the summary; sparse refused
 * by bdf where the mass matrix couples the coordinates, and by adams */
static void case_linear_solver(void)
{
    char path[300];
    const char *args[] = {"spring-pendulum", "--integrator", "ida",
                          "--t-end", "0.2", "--out", path,
                          "--linear-solver", NULL, NULL};
    result r;
    scratch(path, sizeof path, "out.csv");
    args[8] = "sparse";
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "(sparse, KLU)");
    result_free(&r);
    args[8] = "auto"; /* a small model: dense */
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "(dense LU)");
    result_free(&r);
    args[2] = "bdf"; /* M diagonal in (r, theta): bdf's sparse path */
    args[8] = "sparse";
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "(sparse, KLU)");
    result_free(&r);
    args[0] = "double-pendulum"; /* M couples the two angles */
    run(&r, args);
    CHECK(r.status != 0);
    CHECK_HAS(r.err, "the mass matrix couples");
    result_free(&r);
    args[2] = "adams";
    run(&r, args);
    CHECK(r.status != 0);
    CHECK_HAS(r.err, "only ida and bdf have a sparse iteration matrix");
    result_free(&r);
}

static const struct {
    const char *name;
    void (*fn)(void);
} cases[] = {
    {"linear-solver", case_linear_solver},
    {"list", case_list},       {"describe", case_describe},
    {"help", case_help},       {"csv", case_csv},
    {"grid", case_grid},       {"set", case_set},
    {"usage", case_usage},     {"failure", case_failure},
    {"methods", case_methods}, {"tolerances", case_tolerances},
    {"default-method", case_default_method},
};

int main(int argc, char **argv)
{
    size_t i;
    int found = 0;
    if (argc < 3) {
        fprintf(stderr, "usage: test_cli EOM_RUN CASE [DOCS_CLI_MD]\n");
        return EXIT_FAILURE;
    }
    cli_program = argv[1];
    docs_cli = argc > 3 ? argv[3] : NULL;
    if (cli_setup() != 0)
        return EXIT_FAILURE;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++)
        if (strcmp(cases[i].name, argv[2]) == 0) {
            cases[i].fn();
            found = 1;
        }
    cli_cleanup();
    if (!found) {
        fprintf(stderr, "test_cli: unknown case '%s'\n", argv[2]);
        return EXIT_FAILURE;
    }
    CHECK_DONE();
}
