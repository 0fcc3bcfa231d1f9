/* test_cli_output.c - what eom-run and eom-ensemble do to the files they
 * write and read, when things go wrong: an output replaced only by a
 * finished run (a SIGKILL, a failed run leave the old file as it was),
 * --out naming an input, --resume of another ensemble's summary or of
 * garbage, two resumes at once, a summary header far wider than 64 KiB.
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
    free(orig);
    cli_program = eom_run_path;
}

static const struct {
    const char *name;
    void (*fn)(void);
} cases[] = {
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
