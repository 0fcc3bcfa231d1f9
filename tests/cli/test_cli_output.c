/* test_cli_output.c - what eom-run and eom-ensemble do to the files they
 * write and read, when things go wrong: an output replaced only by a
 * finished run (a SIGKILL, a failed run leave the old file as it was),
 * --out naming an input or a symbolic link, --resume of another
 * ensemble's summary or of garbage, two resumes at once, a summary header
 * far wider than 64 KiB.
 * One case per meson test:
 *   test_cli_output EOM_RUN EOM_ENSEMBLE MODELS_DIR CASE */
#define _XOPEN_SOURCE 700 /* realpath, symlink */
#include <dirent.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "cli_support.h"

static char eom_run_path[PATH_MAX], ensemble_path[PATH_MAX];
static char models[PATH_MAX];
static const char old_text[] = "t,x\n0,1\n";

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (f) {
        fputs(text, f);
        CHECK(fclose(f) == 0);
    }
}

/* path holds exactly text */
static int holds(const char *path, const char *text)
{
    char *got = read_file(path, NULL);
    int same = got && strcmp(got, text) == 0;
    free(got);
    return same;
}

/* The size of the first file in the scratch directory whose name starts
 * with prefix, or -1. */
static long long first_with_prefix(const char *prefix)
{
    char dir[300], path[700];
    DIR *d;
    struct dirent *e;
    long long size = -1;
    scratch(dir, sizeof dir, "");
    d = opendir(dir);
    while (d && (e = readdir(d)) != NULL)
        if (strncmp(e->d_name, prefix, strlen(prefix)) == 0) {
            struct stat st;
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            if (stat(path, &st) == 0)
                size = (long long)st.st_size;
            break;
        }
    if (d)
        closedir(d);
    return size;
}

static void nap_ms(long ms)
{
    struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* eom-run killed by SIGKILL in the middle of a long run: the previous
 * output is still there, whole. */
static void case_out_kill(void)
{
    char out[300];
    const char *argv_c[] = {eom_run_path, "spring-pendulum", "--t-end",
                            "100000", "-q", "--out", out, NULL};
    pid_t pid;
    int k, st;
    long long size = -1;
    scratch(out, sizeof out, "out.csv");
    write_text(out, old_text);
    fflush(NULL);
    pid = fork();
    if (pid == 0) {
        execv(eom_run_path, (char *const *)(void *)argv_c);
        _exit(127);
    }
    CHECK(pid > 0);
    /* until some rows are on the disk (at most 10 s), wherever they go */
    for (k = 0; k < 1000 && size < 100000; k++) {
        nap_ms(10);
        size = first_with_prefix("out.csv");
        if (size < 100000)
            size = first_with_prefix("out.csv.tmp-");
    }
    CHECK(size >= 100000);
    kill(pid, SIGKILL);
    waitpid(pid, &st, 0);
    CHECK(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL); /* still running */
    CHECK(holds(out, old_text));
}

/* A run that fails part-way keeps the old file and leaves its rows in
 * FILE.partial, which the message names; a finished run replaces the
 * file and keeps its permissions. */
static void case_out_failure(void)
{
    char out[300], partial[320];
    const char *fail[] = {"spring-pendulum", "--max-steps", "1", "-q",
                          "--out", out, NULL};
    const char *good[] = {"spring-pendulum", "--t-end", "0.02", "-q",
                          "--out", out, NULL};
    struct stat st;
    char *text;
    result r;
    scratch(out, sizeof out, "out.csv");
    snprintf(partial, sizeof partial, "%s.partial", out);
    write_text(out, old_text);
    CHECK(chmod(out, 0640) == 0);
    run(&r, fail);
    CHECK_INT(r.status, 1);
    CHECK_HAS(r.err, "integration failed");
    CHECK_HAS(r.err, "out.csv.partial");
    CHECK_HAS(r.err, "unchanged");
    result_free(&r);
    CHECK(holds(out, old_text));
    text = read_file(partial, NULL);
    CHECK(text != NULL && strncmp(text, "t,r,theta,", 10) == 0);
    free(text);
    CHECK_INT((int)(first_with_prefix("out.csv.tmp-") >= 0), 0);

    run(&r, good);
    CHECK_INT(r.status, 0);
    result_free(&r);
    text = read_file(out, NULL);
    CHECK(text != NULL && strncmp(text, "t,r,theta,", 10) == 0);
    free(text);
    CHECK(stat(out, &st) == 0 && (st.st_mode & 0777) == 0640);
    CHECK_INT((int)(first_with_prefix("out.csv.tmp-") >= 0), 0);
}

/* --out naming the model file or the runs file is refused before
 * anything is written, through any spelling of the name. */
static void case_out_input(void)
{
    char model[300], link[300], runs[300], src[PATH_MAX + 40];
    char *text, *orig;
    result r;
    snprintf(src, sizeof src, "%s/spring-pendulum.eom", models);
    orig = read_file(src, NULL);
    CHECK(orig != NULL);
    if (!orig)
        return;
    scratch(model, sizeof model, "m.eom");
    scratch(link, sizeof link, "link.csv");
    scratch(runs, sizeof runs, "runs.csv");
    write_text(model, orig);
    CHECK(symlink(model, link) == 0);
    {
        const char *a[] = {model, "--t-end", "0.01", "-q", "--out", model,
                           NULL};
        run(&r, a);
        CHECK_INT(r.status, 2);
        CHECK_HAS(r.err, "the model file");
        result_free(&r);
    }
    {
        const char *a[] = {model, "--t-end", "0.01", "-q", "--out", link,
                           NULL};
        run(&r, a);
        CHECK_INT(r.status, 2);
        CHECK_HAS(r.err, "the model file");
        result_free(&r);
    }
    text = read_file(model, NULL);
    CHECK(text && strcmp(text, orig) == 0);
    free(text);

    cli_program = ensemble_path;
    write_text(runs, "m\n1\n2\n");
    {
        const char *a[] = {model, "--runs", runs, "--t-end", "0.01", "-q",
                           "--out", runs, NULL};
        run(&r, a);
        CHECK_INT(r.status, 2);
        CHECK_HAS(r.err, "the runs file");
        result_free(&r);
        CHECK(holds(runs, "m\n1\n2\n"));
    }
    {
        const char *a[] = {model, "--runs", runs, "--t-end", "0.01", "-q",
                           "--out", link, NULL};
        run(&r, a);
        CHECK_INT(r.status, 2);
        CHECK_HAS(r.err, "the model file");
        result_free(&r);
    }
    text = read_file(model, NULL);
    CHECK(text && strcmp(text, orig) == 0);
    free(text);
    /* a link at --out to a file that is no input: the summary is written
     * in place, so never through the link (its target keeps its text) */
    {
        char victim[300], vlink[300];
        const char *a[] = {model, "--runs", runs, "--t-end", "0.01", "-q",
                           "--out", vlink, NULL};
        scratch(victim, sizeof victim, "victim.csv");
        scratch(vlink, sizeof vlink, "victim-link.csv");
        write_text(victim, old_text);
        CHECK(symlink(victim, vlink) == 0);
        run(&r, a);
        CHECK(r.status != 0);
        CHECK_HAS(r.err, "is a symbolic link");
        result_free(&r);
        CHECK(holds(victim, old_text));
    }
    free(orig);
    cli_program = eom_run_path;
}

/* ---- eom-ensemble's summary ------------------------------------------ */

/* Run eom-ensemble with args; its exit status, r kept for the caller. */
static int ensemble(result *r, const char *const *args)
{
    cli_program = ensemble_path;
    run(r, args);
    cli_program = eom_run_path;
    return r->status;
}

/* --resume with an option, the model or the seed changed is refused with
 * a message naming what changed, and the summary is left alone. */
static void case_resume_inputs(void)
{
    char model[300], out[300], src[PATH_MAX + 40], *orig, *before;
    const char *base[] = {model, "--sweep", "k=50:100:3", "--t-end", "0.2",
                          "-q", "--out", out, NULL};
    result r;
    snprintf(src, sizeof src, "%s/spring-pendulum.eom", models);
    orig = read_file(src, NULL);
    CHECK(orig != NULL);
    if (!orig)
        return;
    scratch(model, sizeof model, "m.eom");
    scratch(out, sizeof out, "sum.csv");
    write_text(model, orig);
    CHECK_INT(ensemble(&r, base), 0);
    result_free(&r);
    before = read_file(out, NULL);
    {
        const char *a[] = {model, "--sweep", "k=50:100:3", "--t-end", "0.3",
                           "-q", "--out", out, "--resume", NULL};
        CHECK_INT(ensemble(&r, a), 1);
        CHECK_HAS(r.err, "was made by other inputs: --t-end (0.2 there, "
                         "0.3 now)");
        result_free(&r);
    }
    {
        const char *a[] = {model, "--sweep", "k=50:100:3", "--t-end", "0.2",
                           "--integrator", "rk4", "-q", "--out", out,
                           "--resume", NULL};
        CHECK_INT(ensemble(&r, a), 1);
        CHECK_HAS(r.err, "--integrator (erk there, rk4 now)");
        result_free(&r);
    }
    {
        const char *a[] = {model, "--sweep", "k=50:100:3", "--t-end", "0.2",
                           "--set", "m=2", "-q", "--out", out, "--resume",
                           NULL};
        CHECK_INT(ensemble(&r, a), 1);
        CHECK_HAS(r.err, "--set (none there, m=2 now)");
        result_free(&r);
    }
    /* the same file name, other contents */
    {
        FILE *f = fopen(model, "a");
        CHECK(f != NULL);
        if (f) {
            fputs("# edited\n", f);
            fclose(f);
        }
    }
    {
        const char *a[] = {model, "--sweep", "k=50:100:3", "--t-end", "0.2",
                           "-q", "--out", out, "--resume", NULL};
        CHECK_INT(ensemble(&r, a), 1);
        CHECK_HAS(r.err, "model (its contents differ)");
        result_free(&r);
    }
    {
        char *now = read_file(out, NULL);
        CHECK(before && now && strcmp(before, now) == 0);
        free(now);
    }
    free(before);
    /* random runs: another seed */
    {
        const char *a[] = {"spring-pendulum", "--random", "k=uniform:50:100",
                           "--count", "3", "--seed", "1", "--t-end", "0.1",
                           "-q", "--out", out, NULL, NULL};
        CHECK_INT(ensemble(&r, a), 0);
        result_free(&r);
        a[6] = "2";
        a[12] = "--resume";
        CHECK_INT(ensemble(&r, a), 1);
        CHECK_HAS(r.err, "--seed (1 there, 2 now)");
        result_free(&r);
    }
    free(orig);
}

/* Replace line k (from 1) of path by repl. */
static void replace_line(const char *path, int k, const char *repl)
{
    char *text = read_file(path, NULL), *p, *e;
    int i;
    FILE *f;
    CHECK(text != NULL);
    if (!text)
        return;
    for (p = text, i = 1; i < k && p; i++) {
        p = strchr(p, '\n');
        p = p ? p + 1 : NULL;
    }
    e = p ? strchr(p, '\n') : NULL;
    CHECK(p && e);
    f = fopen(path, "w");
    if (f && p && e) {
        fwrite(text, 1, (size_t)(p - text), f);
        fputs(repl, f);
        fputs(e, f);
    }
    if (f)
        fclose(f);
    free(text);
}

/* Rows already in the summary that are not this ensemble's rows are
 * refused, naming the line; the valid summary resumes. */
static void case_resume_garbage(void)
{
    char out[300], *good, line2[4096];
    const char *a[] = {"spring-pendulum", "--sweep", "k=50:100:3", "--t-end",
                       "0.1", "-q", "--out", out, NULL, NULL};
    static const char *const bad[] = {
        "garbage",
        "7,50,ok,1,2,3,4,5,6,7,8,9,10,\"\"",
        "0,51,ok,1,2,3,4,5,6,7,8,9,10,\"\"",
        "0,50,maybe,1,2,3,4,5,6,7,8,9,10,\"\"",
        "0,50,ok,1,2,x,4,5,6,7,8,9,10,\"\"",
        "0,50,ok,1,2,3,4,5,6,7,8.5,9,10,\"\"",
        "0,50,ok,1,2,3,4,5,6,7,8,9,10,\"a\"b\"",
        "0,50,ok,1,2,3,4,5,6,7,8,9,10",
        "0,50,ok,1,2,3,4,5,6,7,8,9,10,\"\",extra",
    };
    size_t k;
    result r;
    scratch(out, sizeof out, "sum.csv");
    CHECK_INT(ensemble(&r, a), 0);
    result_free(&r);
    good = read_file(out, NULL);
    CHECK(good != NULL);
    if (!good)
        return;
    {
        const char *p = strchr(good, '\n');
        const char *e = p ? strchr(p + 1, '\n') : NULL;
        CHECK(p && e && (size_t)(e - p) < sizeof line2);
        if (!p || !e)
            return;
        memcpy(line2, p + 1, (size_t)(e - p - 1));
        line2[e - p - 1] = '\0';
    }
    a[8] = "--resume";
    for (k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        write_text(out, good);
        replace_line(out, 2, bad[k]);
        CHECK_INT(ensemble(&r, a), 1);
        check_count_++;
        if (!has(r.err, "line 2 is not a row of this ensemble"))
            CHECK_FAIL_("bad row '%s' not refused:\n%s", bad[k], r.err);
        result_free(&r);
    }
    /* run 1's row twice */
    write_text(out, good);
    replace_line(out, 3, line2);
    CHECK_INT(ensemble(&r, a), 1);
    CHECK_HAS(r.err, "line 3 is not a row of this ensemble: run 0 appears "
                     "twice");
    result_free(&r);
    /* the summary as written resumes, with nothing to do */
    write_text(out, good);
    CHECK_INT(ensemble(&r, a), 0);
    result_free(&r);
    CHECK(holds(out, good));
    free(good);
}

/* Two ensembles on one summary: the second is refused at once while the
 * first holds the summary's lock. The first is given far more work than
 * the checks take (it is killed at the end): with 10 s of motion a run it
 * once finished before the checks while this test ran under valgrind. */
static void case_resume_lock(void)
{
    char model[PATH_MAX + 32], out[300];
    const char *args[] = {ensemble_path, model, "--sweep", "th1=0.5:2.5:40",
                          "--t-end", "10000", "--integrator", "erk", "--rtol",
                          "1e-11", "--atol", "1e-13", "--threads", "1",
                          "-q", "--out", out, NULL};
    pid_t pid;
    int k, st;
    long long size = -1;
    result r;
    snprintf(model, sizeof model, "%s/double-pendulum.eom", models);
    scratch(out, sizeof out, "sum.csv");
    fflush(NULL);
    pid = fork();
    if (pid == 0) {
        execv(ensemble_path, (char *const *)(void *)args);
        _exit(127);
    }
    CHECK(pid > 0);
    for (k = 0; k < 500 && size <= 0; k++) { /* the header is out */
        nap_ms(10);
        size = first_with_prefix("sum.csv");
    }
    CHECK(size > 0);
    {
        const char *a[] = {model, "--sweep", "th1=0.5:2.5:40", "--t-end",
                           "10", "--integrator", "erk", "--rtol", "1e-11",
                           "--atol", "1e-13", "--threads", "1", "-q",
                           "--out", out, "--resume", NULL};
        CHECK_INT(ensemble(&r, a), 1);
        CHECK_HAS(r.err, "is being written by another eom-ensemble");
        result_free(&r);
        a[16] = NULL; /* nor a fresh ensemble on the same file */
        CHECK_INT(ensemble(&r, a), 1);
        CHECK_HAS(r.err, "is being written by another eom-ensemble");
        result_free(&r);
    }
    CHECK(waitpid(pid, &st, WNOHANG) == 0); /* the first still runs */
    kill(pid, SIGKILL);
    waitpid(pid, &st, 0);
}

/* A summary header far beyond 64 KiB (2000 coordinates with long names)
 * is written whole, and the summary resumes. */
static void case_summary_wide(void)
{
    static const char name[] =
        "a_coordinate_with_a_rather_long_name_for_the_summary_header";
    char model[300], out[300], *text, *first;
    const char *a[] = {model, "--sweep", "k=1:2:2", "--t-end", "0", "-q",
                       "--threads", "1", "--out", out, NULL, NULL};
    FILE *f;
    result r;
    int cols = 1, lines = 0;
    const char *p;
    scratch(model, sizeof model, "wide.eom");
    scratch(out, sizeof out, "wide.csv");
    /* the system's workspaces for 2000 coordinates come to about 1.4 GB
     * of allocations it never touches at t_end = 0 (one system per
     * thread: one thread); meson's MALLOC_PERTURB_ would fill them all
     * (4 s a run) */
    unsetenv("MALLOC_PERTURB_");
    f = fopen(model, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fprintf(f, "param k = 1 [N/m]\nparam m = 1 [kg]\n"
               "coord %s[j in 1..2000] = 0.001*j [m]\n"
               "T = sum(j in 1..2000, 1/2*m*%s_dot[j]^2)\n"
               "V = sum(j in 1..2000, 1/2*k*%s[j]^2)\n",
            name, name, name);
    fclose(f);
    CHECK_INT(ensemble(&r, a), 0);
    result_free(&r);
    text = read_file(out, NULL);
    CHECK(text != NULL);
    if (!text)
        return;
    for (p = text; *p && *p != '\n'; p++)
        cols += *p == ',';
    for (p = text; *p; p++)
        lines += *p == '\n';
    CHECK_INT(cols, 1 + 1 + 1 + 4000 + 7);
    CHECK_INT(lines, 3);
    first = strchr(text, '\n');
    CHECK(first && strncmp(first + 1, "0,1,ok,", 7) == 0);
    CHECK(strlen(text) > 4 * 65536);
    a[10] = "--resume";
    CHECK_INT(ensemble(&r, a), 0);
    result_free(&r);
    CHECK(holds(out, text));
    free(text);
}

static const struct {
    const char *name;
    void (*fn)(void);
} cases[] = {
    {"resume_inputs", case_resume_inputs},
    {"resume_garbage", case_resume_garbage},
    {"resume_lock", case_resume_lock},
    {"summary_wide", case_summary_wide},
    {"out_kill", case_out_kill},
    {"out_failure", case_out_failure},
    {"out_input", case_out_input},
};

int main(int argc, char **argv)
{
    size_t i;
    int found = 0;
    if (argc < 5 || !realpath(argv[1], eom_run_path) ||
        !realpath(argv[2], ensemble_path) || !realpath(argv[3], models)) {
        fprintf(stderr, "usage: test_cli_output EOM_RUN EOM_ENSEMBLE "
                "MODELS_DIR CASE\n");
        return EXIT_FAILURE;
    }
    cli_program = eom_run_path;
    if (cli_setup() != 0)
        return EXIT_FAILURE;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++)
        if (strcmp(cases[i].name, argv[4]) == 0) {
            cases[i].fn();
            found = 1;
        }
    cli_cleanup();
    if (!found) {
        fprintf(stderr, "test_cli_output: unknown case '%s'\n", argv[4]);
        return EXIT_FAILURE;
    }
    CHECK_DONE();
}
