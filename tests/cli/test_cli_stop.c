/* test_cli_stop.c - eom-run and eom-ensemble stopped part-way: by
 * SIGTERM, SIGINT or SIGHUP sent from here to a child run (it stops after
 * a whole row and exits with 128 + the signal; an ensemble's summary
 * resumes to what an uninterrupted ensemble writes; a SIGHUP ignored at
 * the start, as under nohup, stays ignored), and by a write that
 * fails (a file size limit, RLIMIT_FSIZE, makes the summary's writes fail
 * with EFBIG part-way as a full disk does with ENOSPC: the failure is
 * said once with its reason, the summary keeps whole rows and the runs
 * not started are not run; eom-run --modes --sweep keeps the old CSV).
 * One case per meson test:
 *   test_cli_stop EOM_RUN EOM_ENSEMBLE MODELS_DIR CASE */
#define _XOPEN_SOURCE 700 /* realpath */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "cli_support.h"

static char eom_run_path[PATH_MAX], ensemble_path[PATH_MAX];
static char models[PATH_MAX];

static void nap_ms(long ms)
{
    struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

static long long size_of(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long long)st.st_size : -1;
}

/* The number of '\n' in path (-1: unreadable). */
static long lines_of(const char *path)
{
    char *text = read_file(path, NULL);
    long k = 0;
    const char *p;
    if (!text)
        return -1;
    for (p = text; *p; p++)
        k += *p == '\n';
    free(text);
    return k;
}

/* How many times word occurs in s (0 when s is NULL). */
static int occurrences(const char *s, const char *word)
{
    int k = 0;
    while (s && (s = strstr(s, word)) != NULL) {
        k++;
        s += strlen(word);
    }
    return k;
}

/* The files in dir whose names start with prefix. */
static int count_prefix(const char *dir, const char *prefix)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int k = 0;
    while (d && (e = readdir(d)) != NULL)
        k += strncmp(e->d_name, prefix, strlen(prefix)) == 0;
    if (d)
        closedir(d);
    return k;
}

/* The size of the first file of the scratch directory whose name starts
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
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            size = size_of(path);
            break;
        }
    if (d)
        closedir(d);
    return size;
}

/* SIGHUP ignored in the next child spawn starts (as nohup starts it),
 * else every stop signal in its default action. */
static int spawn_ignoring_hup;

/* Start prog with args (NULL-terminated, args[0] the program), its
 * standard error into err_path, with a file size limit of fsize bytes
 * (0: none; SIGXFSZ ignored, so that a write past it fails with EFBIG as
 * one to a full disk fails with ENOSPC). The stop signals start in their
 * default action whatever this test inherited (a test run under nohup
 * inherits SIGHUP ignored, which the child would keep ignoring by
 * design), unless spawn_ignoring_hup. The child's pid. */
static pid_t spawn(const char **args, const char *err_path,
                   long long fsize)
{
    pid_t pid;
    fflush(NULL);
    pid = fork();
    if (pid == 0) {
        int fd;
        signal(SIGTERM, SIG_DFL);
        signal(SIGINT, SIG_DFL);
        signal(SIGHUP, spawn_ignoring_hup ? SIG_IGN : SIG_DFL);
        fd = open(err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            dup2(fd, STDERR_FILENO);
            close(fd);
        }
        fd = open("/dev/null", O_WRONLY);
        if (fd >= 0) {
            dup2(fd, STDOUT_FILENO);
            close(fd);
        }
        if (fsize > 0) {
            struct rlimit rl;
            rl.rlim_cur = rl.rlim_max = (rlim_t)fsize;
            signal(SIGXFSZ, SIG_IGN);
            if (setrlimit(RLIMIT_FSIZE, &rl) != 0)
                _exit(126);
        }
        execv(args[0], (char *const *)(void *)args);
        _exit(127);
    }
    CHECK(pid > 0);
    return pid;
}

/* The child's exit status (128 + N when a signal N killed it). */
static int reap(pid_t pid)
{
    int st = 0;
    if (waitpid(pid, &st, 0) != pid)
        return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st) + 1000;
}

/* eom-run sent sig in the middle of a long run: it exits with 128 + sig
 * (not killed by it), says at which time it stopped, leaves FILE as it
 * was and FILE.partial of whole rows whose last row is at that time. */
static void run_signal(int sig)
{
    char out[300], partial[320], errp[300], *text, *msg;
    const char *args[] = {eom_run_path, "spring-pendulum", "--t-end",
                          "100000", "-q", "--out", out, NULL};
    long long size = -1;
    pid_t pid;
    csv c;
    char why[256];
    int k;
    scratch(out, sizeof out, "out.csv");
    scratch(errp, sizeof errp, "err.txt");
    snprintf(partial, sizeof partial, "%s.partial", out);
    unlink(partial);
    {
        FILE *f = fopen(out, "w");
        CHECK(f != NULL);
        if (f) {
            fputs("t,x\n0,1\n", f);
            fclose(f);
        }
    }
    pid = spawn(args, errp, 0);
    /* until rows are on the disk (at most 20 s) */
    for (k = 0; k < 2000 && size < 20000; k++) {
        nap_ms(10);
        size = first_with_prefix("out.csv.tmp-");
    }
    CHECK(size >= 20000);
    kill(pid, sig);
    CHECK_INT(reap(pid), 128 + sig);
    msg = read_file(errp, NULL);
    CHECK_HAS(msg, "stopped at t = ");
    CHECK_HAS(msg, "out.csv.partial");
    CHECK_HAS(msg, "unchanged");
    text = read_file(out, NULL);
    CHECK(text && strcmp(text, "t,x\n0,1\n") == 0);
    free(text);
    CHECK_INT(first_with_prefix("out.csv.tmp-") >= 0, 0);
    text = read_file(partial, NULL);
    CHECK(text != NULL);
    if (text && msg) {
        /* whole rows: parsed without a ragged or broken row, the last
         * one ending the file and at the time the message gives */
        const double t_stop = number_after(msg, "stopped at t = ");
        const size_t len = strlen(text);
        CHECK(len > 0 && text[len - 1] == '\n');
        CHECK_INT(csv_parse(text, &c, why, sizeof why), 0);
        CHECK(c.nrows > 100);
        if (c.nrows > 100) {
            CHECK(at(&c, c.nrows - 1, 0) == t_stop);
            /* t = k / 100: no row lost or repeated */
            CHECK(fabs(at(&c, c.nrows - 1, 0) - 0.01 * (c.nrows - 1)) <
                  1e-9 * c.nrows);
        }
        free(c.v);
    }
    free(text);
    free(msg);
    unlink(partial);
}

/* eom-run started with SIGHUP ignored (nohup) keeps ignoring it: still
 * running well after a SIGHUP, then stopped by SIGTERM as usual. */
static void run_nohup(void)
{
    char out[300], partial[320], errp[300];
    const char *args[] = {eom_run_path, "spring-pendulum", "--t-end",
                          "100000", "-q", "--out", out, NULL};
    long long size = -1;
    pid_t pid;
    int k, st = 0;
    scratch(out, sizeof out, "nohup.csv");
    scratch(errp, sizeof errp, "err.txt");
    snprintf(partial, sizeof partial, "%s.partial", out);
    spawn_ignoring_hup = 1;
    pid = spawn(args, errp, 0);
    spawn_ignoring_hup = 0;
    for (k = 0; k < 2000 && size < 20000; k++) {
        nap_ms(10);
        size = first_with_prefix("nohup.csv.tmp-");
    }
    CHECK(size >= 20000);
    kill(pid, SIGHUP);
    /* a run that obeyed it would have ended within these 0.5 s: it
     * stops after the row under way */
    nap_ms(500);
    CHECK_INT((int)waitpid(pid, &st, WNOHANG), 0);
    kill(pid, SIGTERM);
    CHECK_INT(reap(pid), 128 + SIGTERM);
    unlink(partial);
}

static void case_run_signals(void)
{
    run_signal(SIGTERM);
    run_signal(SIGINT);
    run_signal(SIGHUP);
    run_nohup();
}

/* The summary's text without the wall time (the second-last field of
 * each row; the message is "" in these runs), for comparing two
 * ensembles. */
static char *without_wall(const char *text)
{
    char *out = malloc(strlen(text) + 1), *o = out;
    const char *line = text;
    int first = 1;
    while (out && *line) {
        const char *end = strchr(line, '\n');
        const char *last, *prev;
        size_t n = end ? (size_t)(end - line) : strlen(line);
        if (first) { /* the header as it is */
            memcpy(o, line, n);
            o += n;
            first = 0;
        } else {
            last = line + n;
            while (last > line && last[-1] != ',')
                last--;
            prev = last > line ? last - 1 : line;
            while (prev > line && prev[-1] != ',')
                prev--;
            memcpy(o, line, (size_t)(prev - line));
            o += prev - line;
            memcpy(o, last, (size_t)(line + n - last));
            o += line + n - last;
        }
        *o++ = '\n';
        line += n + (end != NULL);
    }
    if (out)
        *o = '\0';
    return out;
}

/* eom-ensemble sent SIGTERM mid-way: it exits with 143, its summary
 * holds whole rows, and --resume completes it to what an ensemble never
 * stopped writes (every field but the wall time). */
static void case_ensemble_signal(void)
{
    char model[PATH_MAX + 32], out[300], ref[300], errp[300];
    char *a_text, *b_text, *msg;
    const char *args[] = {ensemble_path, model, "--sweep", "th1=0.5:2.5:30",
                          "--t-end", "60", "--integrator", "erk", "--rtol",
                          "1e-10", "--threads", "1", "-q", "--out", out,
                          NULL, NULL};
    long rows = 0;
    pid_t pid;
    int k, status;
    snprintf(model, sizeof model, "%s/double-pendulum.eom", models);
    scratch(out, sizeof out, "sum.csv");
    scratch(ref, sizeof ref, "ref.csv");
    scratch(errp, sizeof errp, "err.txt");
    pid = spawn(args, errp, 0);
    for (k = 0; k < 3000 && rows < 3; k++) { /* two rows out */
        nap_ms(10);
        rows = lines_of(out);
    }
    CHECK(rows >= 3);
    kill(pid, SIGTERM);
    status = reap(pid);
    msg = read_file(errp, NULL);
    CHECK_INT(status, 128 + SIGTERM);
    CHECK_HAS(msg, "stopped by SIGTERM");
    CHECK_HAS(msg, "--resume");
    rows = lines_of(out);
    CHECK(rows >= 3 && rows < 31); /* stopped before the end */
    a_text = read_file(out, NULL);
    CHECK(a_text && a_text[strlen(a_text) - 1] == '\n');
    free(a_text);
    free(msg);
    /* the rest */
    args[15] = "--resume";
    pid = spawn(args, errp, 0);
    CHECK_INT(reap(pid), 0);
    CHECK_INT((int)lines_of(out), 31);
    /* an ensemble never stopped */
    args[14] = ref;
    args[15] = NULL;
    pid = spawn(args, errp, 0);
    CHECK_INT(reap(pid), 0);
    a_text = read_file(out, NULL);
    b_text = read_file(ref, NULL);
    CHECK(a_text && b_text);
    if (a_text && b_text) {
        char *a = without_wall(a_text), *b = without_wall(b_text);
        CHECK(a && b && strcmp(a, b) == 0);
        free(a);
        free(b);
    }
    free(a_text);
    free(b_text);
}

/* A summary whose writes fail part-way (EFBIG past a file size limit):
 * the failure is said once, with its reason; the summary keeps whole
 * rows; the runs not yet started are not run (each run computed leaves
 * its trajectory file); --resume then does the rest. */
static void case_ensemble_full(void)
{
    char model[PATH_MAX + 32], out[300], errp[300], traj[300], *msg, *text;
    const char *args[] = {ensemble_path, model, "--sweep", "th1=0.5:2.5:200",
                          "--t-end", "0.01", "--sample", "0.01",
                          "--threads", "1", "-q", "--trajectories", traj,
                          "--out", out, NULL, NULL};
    const long long limit = 3000;
    long rows;
    int files;
    snprintf(model, sizeof model, "%s/double-pendulum.eom", models);
    scratch(out, sizeof out, "full.csv");
    scratch(errp, sizeof errp, "err.txt");
    scratch(traj, sizeof traj, "traj");
    CHECK_INT(reap(spawn(args, errp, limit)), 1);
    msg = read_file(errp, NULL);
    CHECK_HAS(msg, "cannot write");
    CHECK_HAS(msg, strerror(EFBIG));
    CHECK_INT(occurrences(msg, "cannot write"), 1); /* said once */
    free(msg);
    text = read_file(out, NULL);
    CHECK(text != NULL);
    rows = lines_of(out) - 1;
    CHECK(text && strlen(text) > 0 && text[strlen(text) - 1] == '\n');
    CHECK(size_of(out) <= limit);
    CHECK(rows >= 2 && rows < 200);
    free(text);
    /* the rows written, the run whose row failed, at most one begun
     * meanwhile: nothing more was computed */
    files = count_prefix(traj, "run-");
    CHECK(files >= rows + 1);
    CHECK(files <= rows + 2);
    /* with room again, --resume does the rest */
    args[15] = "--resume";
    CHECK_INT(reap(spawn(args, errp, 0)), 0);
    CHECK_INT((int)lines_of(out), 201);
    CHECK_INT(count_prefix(traj, "run-"), 200);
}

/* eom-run --modes --sweep whose CSV cannot be written whole (EFBIG past
 * a file size limit): the old file stays as it was, the rows written are
 * in FILE.partial, no temporary file is left, and the reason is given;
 * without the limit the file is replaced. */
static void case_sweep_full(void)
{
    char out[300], partial[320], errp[300], *text, *msg;
    const char *args[] = {eom_run_path, "rolling-disk", "--modes", "--set",
                          "theta=0", "--sweep", "g=0:30:400", "-q", "--out",
                          out, NULL};
    FILE *f;
    scratch(out, sizeof out, "sweep.csv");
    scratch(errp, sizeof errp, "err.txt");
    snprintf(partial, sizeof partial, "%s.partial", out);
    f = fopen(out, "w");
    CHECK(f != NULL);
    if (f) {
        fputs("g,re1\n0,1\n", f);
        fclose(f);
    }
    CHECK_INT(reap(spawn(args, errp, 3000)), 1);
    msg = read_file(errp, NULL);
    CHECK_HAS(msg, strerror(EFBIG));
    CHECK_HAS(msg, "sweep.csv.partial");
    free(msg);
    text = read_file(out, NULL);
    CHECK(text && strcmp(text, "g,re1\n0,1\n") == 0);
    free(text);
    CHECK(size_of(partial) > 0);
    CHECK_INT(first_with_prefix("sweep.csv.tmp-") >= 0, 0);
    CHECK_INT(reap(spawn(args, errp, 0)), 0);
    CHECK_INT((int)lines_of(out), 401);
    unlink(partial);
}

static const struct {
    const char *name;
    void (*fn)(void);
} cases[] = {
    {"sweep_full", case_sweep_full},
    {"run_signals", case_run_signals},
    {"ensemble_signal", case_ensemble_signal},
    {"ensemble_full", case_ensemble_full},
};

int main(int argc, char **argv)
{
    size_t i;
    int found = 0;
    if (argc < 5 || !realpath(argv[1], eom_run_path) ||
        !realpath(argv[2], ensemble_path) || !realpath(argv[3], models)) {
        fprintf(stderr, "usage: test_cli_stop EOM_RUN EOM_ENSEMBLE "
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
        fprintf(stderr, "test_cli_stop: unknown case '%s'\n", argv[4]);
        return EXIT_FAILURE;
    }
    CHECK_DONE();
}
