/* test_cli_ensemble.c - eom-ensemble from the outside: the same summary,
 * bit for bit but for the wall times, on 1 and on 3 threads; a failing
 * run in the middle recorded with its message while the others go on;
 * --resume after an interrupted ensemble gives the uninterrupted summary;
 * the trajectories; runs of a model that reads the time, each from t = 0;
 * and the command-line errors.
 *
 * usage: test_cli_ensemble EOM_ENSEMBLE MODELS_DIR CASE */
#define _XOPEN_SOURCE 700 /* realpath, setenv */
#include <dirent.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "cli_support.h"

static char models[PATH_MAX];

/* The summary without its wall_time column (the next to last). */
static char *strip_wall(const char *text)
{
    char *out = malloc(strlen(text) + 1), *o = out;
    const char *line = text;
    while (out && *line) {
        const char *end = strchr(line, '\n'), *p, *wall = NULL, *msg = NULL;
        size_t len = end ? (size_t)(end - line) : strlen(line);
        int commas = 0, total = 0;
        for (p = line; p < line + len && *p != '"'; p++)
            total += *p == ',';
        for (p = line; p < line + len; p++)
            if (*p == ',' && ++commas == total - 1)
                wall = p;
            else if (*p == ',' && commas == total)
                msg = p;
        if (wall && msg) {
            memcpy(o, line, (size_t)(wall - line));
            o += wall - line;
            memcpy(o, msg, (size_t)(line + len - msg));
            o += line + len - msg;
        }
        *o++ = '\n';
        line += len + (end ? 1 : 0);
    }
    if (out)
        *o = '\0';
    return out;
}

static char *summary(const char *path)
{
    char *text = read_file(path, NULL), *s;
    if (!text)
        return NULL;
    s = strip_wall(text);
    free(text);
    return s;
}

static void case_threads(void)
{
    char model[PATH_MAX + 32], out1[300], out3[300], threads[8];
    const char *args[] = {model, "--sweep", "EI=2e4:8e4:3", "--sweep",
                          "c=0:20:3", "--t-end", "0.3", "--integrator",
                          "erk", "--threads", threads, "--out", NULL, "-q",
                          NULL};
    char *a, *b;
    result r;
    snprintf(model, sizeof model, "%s/closed-chain.eom", models);
    scratch(out1, sizeof out1, "one.csv");
    scratch(out3, sizeof out3, "three.csv");
    strcpy(threads, "1");
    args[12] = out1;
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    strcpy(threads, "3");
    args[12] = out3;
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    a = summary(out1);
    b = summary(out3);
    CHECK(a && b);
    if (a && b) {
        CHECK(strcmp(a, b) == 0);
        CHECK_HAS(a, "run,EI,c,status,final_theta1,");
        CHECK_HAS(a, "\n8,80000,20,ok,");
        CHECK(strstr(a, "failed") == NULL);
    }
    free(a);
    free(b);
}

/* --compiled: the interpreter's summary, bit for bit but for wall_time,
 * on two threads (the clones share the compiled tapes). */
static void case_compiled(void)
{
    char model[PATH_MAX + 32], out1[300], out2[300], cache[300];
    const char *args[] = {model, "--sweep", "EI=2e4:8e4:3", "--t-end", "0.3",
                          "--integrator", "erk", "--threads", "2", "--out",
                          NULL, NULL, NULL};
    char *a, *b;
    result r;
    snprintf(model, sizeof model, "%s/closed-chain.eom", models);
    scratch(out1, sizeof out1, "interpreted.csv");
    scratch(out2, sizeof out2, "compiled.csv");
    scratch(cache, sizeof cache, "cache");
    setenv("AUTOEOM_CACHE_DIR", cache, 1);
    args[10] = out1;
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    args[10] = out2;
    args[11] = "--compiled";
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "compiled tapes in use");
    result_free(&r);
    a = summary(out1);
    b = summary(out2);
    CHECK(a && b);
    if (a && b)
        CHECK(strcmp(a, b) == 0);
    free(a);
    free(b);
}

/* The spring pendulum with r = 0 in the middle: a singular mass matrix. */
static void write_runs(const char *path, const char *const *rows)
{
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    for (; *rows; rows++)
        fputs(*rows, f);
    fclose(f);
}

static void case_failure(void)
{
    static const char *const rows[] = {"r,k,theta_dot\n", "1.1,75,0\n",
                                       "1.2,50,0.1\n", "0,75,0\n",
                                       "1.3,60,-0.2\n", NULL};
    char runs[300], out[300], *text;
    const char *args[] = {"spring-pendulum", "--runs", runs, "--t-end", "0.5",
                          "--out", out, "-q", NULL};
    result r;
    scratch(runs, sizeof runs, "runs.csv");
    scratch(out, sizeof out, "sum.csv");
    write_runs(runs, rows);
    run(&r, args);
    CHECK_INT(r.status, 1); /* one run failed */
    result_free(&r);
    text = read_file(out, NULL);
    CHECK(text != NULL);
    if (text) {
        CHECK_HAS(text, "\n0,1.1,75,0,ok,");
        CHECK_HAS(text, "\n2,0,75,0,failed,");
        CHECK_HAS(text, "mass matrix");
        CHECK_HAS(text, "\n3,1.3,60,-0.2,ok,");
    }
    free(text);
}

/* Interrupted after two runs and part of a third line, then resumed. */
static void case_resume(void)
{
    char model[PATH_MAX + 32], full[300], part[300], *a, *b, *text;
    const char *args[] = {model, "--sweep", "m=0.5:2:6", "--t-end", "0.2",
                          "--out", NULL, NULL, NULL};
    FILE *f;
    result r;
    snprintf(model, sizeof model, "%s/double-pendulum.eom", models);
    args[2] = "m1=0.5:2:6";
    scratch(full, sizeof full, "full.csv");
    scratch(part, sizeof part, "part.csv");
    args[6] = full;
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    text = read_file(full, NULL);
    CHECK(text != NULL);
    if (!text)
        return;
    {
        /* header, runs 0 and 1, and half of run 2's line */
        char *p = text;
        int k;
        for (k = 0; k < 3 && p; k++)
            p = strchr(p + 1, '\n');
        f = fopen(part, "w");
        CHECK(f && p);
        if (f && p) {
            fwrite(text, 1, (size_t)(p + 1 - text), f);
            fwrite(p + 1, 1, 10, f);
        }
        if (f)
            fclose(f);
    }
    free(text);
    {
        /* the record of the inputs goes with the summary */
        char from[320], to[320];
        snprintf(from, sizeof from, "%s.inputs", full);
        snprintf(to, sizeof to, "%s.inputs", part);
        text = read_file(from, NULL);
        CHECK(text != NULL);
        f = fopen(to, "w");
        CHECK(f != NULL);
        if (f && text)
            fputs(text, f);
        if (f)
            fclose(f);
        free(text);
    }
    args[6] = part;
    args[7] = "--resume";
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, ": 4 runs on");
    result_free(&r);
    a = summary(full);
    b = summary(part);
    CHECK(a && b && strcmp(a, b) == 0);
    free(a);
    free(b);
    /* another ensemble's summary is not resumed */
    args[2] = "m2=0.5:2:6";
    run(&r, args);
    CHECK_INT(r.status, 1);
    CHECK_HAS(r.err, "other inputs: --sweep (m1=0.5:2:6 there, "
                     "m2=0.5:2:6 now)");
    result_free(&r);
}

/* Killed for real (SIGKILL) after a few rows, then resumed: the summary
 * is that of a run never interrupted. */
static void case_kill(void)
{
    char model[PATH_MAX + 32], full[300], cut[300], *a, *b;
    const char *args[] = {model, "--sweep", "th1=0.5:2.5:40", "--t-end",
                          "10", "--integrator", "erk", "--rtol", "1e-11",
                          "--atol", "1e-13", "--threads", "1", "--out", NULL,
                          "-q", NULL, NULL};
    const char *argv_c[20];
    pid_t pid;
    int k, lines = 0, st;
    result r;
    snprintf(model, sizeof model, "%s/double-pendulum.eom", models);
    scratch(full, sizeof full, "full.csv");
    scratch(cut, sizeof cut, "cut.csv");
    args[14] = full;
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    /* the same ensemble, killed once a few rows are out */
    args[14] = cut;
    argv_c[0] = cli_program;
    for (k = 0; args[k]; k++)
        argv_c[k + 1] = args[k];
    argv_c[k + 1] = NULL;
    fflush(NULL);
    pid = fork();
    if (pid == 0) {
        freopen("/dev/null", "w", stderr);
        execv(cli_program, (char *const *)(void *)argv_c);
        _exit(127);
    }
    CHECK(pid > 0);
    for (k = 0; k < 3000 && lines < 4; k++) { /* at most 30 s */
        char *text = read_file(cut, NULL), *p;
        struct timespec nap = {0, 10000000};
        lines = 0;
        for (p = text; p && *p; p++)
            lines += *p == '\n';
        free(text);
        nanosleep(&nap, NULL);
    }
    kill(pid, SIGKILL);
    waitpid(pid, &st, 0);
    CHECK(WIFSIGNALED(st)); /* it was still running */
    args[16] = "--resume";
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    a = summary(full);
    b = summary(cut);
    CHECK(a && b && strcmp(a, b) == 0);
    free(a);
    free(b);
}

static void case_trajectories(void)
{
    char out[300], dir[300], file[400], *text;
    const char *args[] = {"spring-pendulum", "--sweep", "k=50:100:2",
                          "--t-end", "0.1", "--sample", "0.05",
                          "--trajectories", dir, "--out", out, "-q", NULL};
    result r;
    scratch(out, sizeof out, "sum.csv");
    scratch(dir, sizeof dir, "traj");
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    snprintf(file, sizeof file, "%s/run-1.csv", dir);
    text = read_file(file, NULL);
    CHECK(text != NULL);
    if (text) {
        CHECK(strncmp(text, "t,r,theta,r_dot,theta_dot,T,V,E,W\n", 34) == 0);
        CHECK_HAS(text, "\n0.1,");
    }
    free(text);
    unlink(file);
    snprintf(file, sizeof file, "%s/run-0.csv", dir);
    unlink(file);
    rmdir(dir);
}

/* --plots: one page of the runs drawn over each other beside the
 * summary, a legend entry and a colour per run that reached its end; a
 * usage error without --trajectories. The page's drawing is checked in
 * a browser (tests/browser/test_pages.py). */
static void case_plots(void)
{
    char out[300], dir[300], page[400], model[PATH_MAX + 32], *text;
    const char *args[] = {model, "--sweep", "th1=0.5:1.5:3", "--t-end",
                          "0.2", "--sample", "0.05", "--trajectories", dir,
                          "--plots", "--out", out, "-q", NULL};
    const char *no_traj[] = {model, "--sweep", "th1=0.5:1.5:3", "--plots",
                             "--out", out, NULL};
    result r;
    long k;
    snprintf(model, sizeof model, "%s/double-pendulum.eom", models);
    scratch(out, sizeof out, "swing.csv");
    scratch(dir, sizeof dir, "swing");
    scratch(page, sizeof page, "swing-animation.html");
    run(&r, no_traj);
    CHECK_INT(r.status, 2);
    CHECK_HAS(r.err, "--plots draws the trajectories: give "
                     "--trajectories DIR too");
    result_free(&r);
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    text = read_file(page, NULL);
    CHECK(text != NULL);
    if (text) {
        const char *p = text;
        long n = 0;
        CHECK_HAS(text, "<title>double-pendulum: 3 runs</title>");
        CHECK_HAS(text, "\"label\": \"run 0: th1=0.5\", \"rgb\": 2062260");
        CHECK_HAS(text, "\"label\": \"run 1: th1=1\", \"rgb\": 16744206");
        CHECK_HAS(text, "\"label\": \"run 2: th1=1.5\", \"rgb\": 2924588");
        while ((p = strstr(p, "{\"label\": ")) != NULL) {
            n++;
            p++;
        }
        CHECK_INT(n, 3);
    }
    free(text);
    unlink(page);
    unlink(out);
    for (k = 0; k < 3; k++) {
        char file[400];
        snprintf(file, sizeof file, "%s/run-%ld.csv", dir, k);
        unlink(file);
    }
    rmdir(dir);
}

/* --random: inside its bounds, the right mean and spread, the same runs
 * for the same seed and other runs for another. */
static void case_random(void)
{
    char out1[300], out2[300], *t1, *t2;
    const char *args[] = {"spring-pendulum", "--random", "k=uniform:50:100",
                          "--random", "theta=normal:0.5:0.1", "--count",
                          "2000", "--seed", "42", "--t-end", "0", "--out",
                          out1, "-q", NULL};
    double su = 0, sn = 0, sn2 = 0;
    result r;
    scratch(out1, sizeof out1, "r1.csv");
    scratch(out2, sizeof out2, "r2.csv");
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    args[12] = out2;
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    t1 = read_file(out1, NULL);
    t2 = read_file(out2, NULL);
    CHECK(t1 && t2);
    if (!t1 || !t2) {
        free(t1);
        free(t2);
        return;
    }
    /* the same seed: the same inputs (columns k and theta) */
    {
        char *a = strip_wall(t1), *b = strip_wall(t2);
        CHECK(a && b && strcmp(a, b) == 0);
        free(a);
        free(b);
    }
    /* the inputs are the columns after run: "I,K,THETA,status,..." */
    {
        const char *line = strchr(t1, '\n');
        int rows = 0;
        CHECK(strncmp(t1, "run,k,theta,status,", 19) == 0);
        while (line && line[1]) {
            long run_i;
            double k, th;
            if (sscanf(line + 1, "%ld,%lf,%lf,", &run_i, &k, &th) != 3) {
                CHECK_FAIL_("bad row after %d rows", rows);
                break;
            }
            CHECK(run_i == rows && k >= 50 && k <= 100);
            su += k;
            sn += th;
            sn2 += th * th;
            rows++;
            line = strchr(line + 1, '\n');
        }
        CHECK_INT(rows, 2000);
        if (rows > 0) {
            su /= rows;
            sn /= rows;
            /* within 3 standard errors */
            CHECK(fabs(su - 75.0) < 3 * 50 / sqrt(12.0) / sqrt(2000.0));
            CHECK(fabs(sn - 0.5) < 3 * 0.1 / sqrt(2000.0));
            CHECK(fabs(sqrt(sn2 / rows - sn * sn) - 0.1) < 0.01);
        }
    }
    free(t1);
    free(t2);
    /* every character of MEAN counts: normal:75:0 gives 75 exactly (a
     * reader that skipped its first character would give 5) */
    {
        const char *exact[] = {"spring-pendulum", "--random",
                               "k=normal:75:0", "--count", "3", "--t-end",
                               "0", "--out", out2, "-q", NULL};
        char *t;
        run(&r, exact);
        CHECK_INT(r.status, 0);
        result_free(&r);
        t = read_file(out2, NULL);
        CHECK_HAS(t, "\n0,75,ok,");
        CHECK_HAS(t, "\n2,75,ok,");
        free(t);
    }
    /* another seed: other runs */
    args[8] = "43";
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    t1 = read_file(out2, NULL);
    t2 = read_file(out1, NULL);
    CHECK(t1 && t2 && strncmp(t1 + 200, t2 + 200, 100) != 0);
    free(t1);
    free(t2);
}

/* Built with MPI: 2 and 3 ranks give the summary of one process, and a
 * failing run handed to another rank is recorded there. */
static void case_mpi(void)
{
    static const char *const rows[] = {"r,k\n", "1.1,75\n", "1.2,50\n",
                                       "0,75\n", "1.3,60\n", "1.0,90\n",
                                       NULL};
    char model[PATH_MAX + 32], one[300], two[300], three[300], runs[300];
    char sum[300];
    const char *args[] = {model, "--random", "EI=uniform:2e4:8e4",
                          "--count", "12", "--t-end", "0.3", "--integrator",
                          "erk", "--threads", "1", "--out", NULL, "-q",
                          NULL};
    const char *fail_args[] = {"spring-pendulum", "--runs", runs, "--t-end",
                               "0.2", "--threads", "1", "--out", sum, "-q",
                               NULL};
    char *a, *b, *c3, *text;
    result r;
    snprintf(model, sizeof model, "%s/closed-chain.eom", models);
    scratch(one, sizeof one, "one.csv");
    scratch(two, sizeof two, "two.csv");
    scratch(three, sizeof three, "three.csv");
    scratch(runs, sizeof runs, "runs.csv");
    scratch(sum, sizeof sum, "sum.csv");
    args[12] = one;
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    setenv("EOM_CLI_WRAPPER", "mpirun -np 2 --oversubscribe", 1);
    args[12] = two;
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    setenv("EOM_CLI_WRAPPER", "mpirun -np 3 --oversubscribe", 1);
    args[12] = three;
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    a = summary(one);
    b = summary(two);
    c3 = summary(three);
    CHECK(a && b && c3 && strcmp(a, b) == 0 && strcmp(a, c3) == 0);
    free(a);
    free(b);
    free(c3);
    /* a failing run among ranks */
    write_runs(runs, rows);
    run(&r, fail_args);
    CHECK_INT(r.status, 1);
    result_free(&r);
    unsetenv("EOM_CLI_WRAPPER");
    text = read_file(sum, NULL);
    CHECK(text != NULL);
    if (text) {
        CHECK_HAS(text, "\n2,0,75,failed,");
        CHECK_HAS(text, "mass matrix");
        CHECK_HAS(text, "\n4,1,90,ok,");
    }
    free(text);
}

/* Two ranks, and the model file only where rank 0 runs: the other rank
 * says so and both stop, instead of rank 0 waiting for ever. */
static void case_mpi_setup(void)
{
    char a[300], b[300], model[400], cmd[3000], *err;
    FILE *f;
    int st;
    scratch(a, sizeof a, "wa");
    scratch(b, sizeof b, "wb");
    CHECK(mkdir(a, 0700) == 0 && mkdir(b, 0700) == 0);
    snprintf(model, sizeof model, "%s/m.eom", a);
    f = fopen(model, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs("param m = 1 [kg]\nparam k = 10 [N/m]\ncoord x = 1 [m]\n"
          "T = 1/2*m*x_dot^2\nV = 1/2*k*x^2\n", f);
    fclose(f);
    snprintf(cmd, sizeof cmd,
             "timeout 60 mpirun --oversubscribe -np 1 --wdir %s %s m.eom "
             "--sweep k=1:2:2 --out o.csv : -np 1 --wdir %s %s m.eom "
             "--sweep k=1:2:2 --out o.csv > %s/out.txt 2>&1",
             a, cli_program, b, cli_program, a);
    st = system(cmd);
    CHECK(WIFEXITED(st) && WEXITSTATUS(st) != 0 && WEXITSTATUS(st) != 124);
    snprintf(cmd, sizeof cmd, "%s/out.txt", a);
    err = read_file(cmd, NULL);
    CHECK(err != NULL);
    if (err) {
        CHECK_HAS(err, "cannot open the model file");
        CHECK_HAS(err, "another rank could not set up the ensemble");
    }
    free(err);
    unlink(cmd);
    unlink(model);
    snprintf(cmd, sizeof cmd, "%s/o.csv", a);
    unlink(cmd);
    rmdir(a);
    rmdir(b);
}

/* The pid of the child of parent whose environment says it is MPI rank
 * rank (Open MPI's OMPI_COMM_WORLD_RANK), or -1. */
static pid_t rank_pid(pid_t parent, int rank)
{
    char path[300], want[64], *env, *stat, *p;
    size_t len;
    pid_t pid;
    DIR *d = opendir("/proc");
    struct dirent *e;
    snprintf(want, sizeof want, "OMPI_COMM_WORLD_RANK=%d", rank);
    while (d && (e = readdir(d)) != NULL) {
        pid = (pid_t)atoi(e->d_name);
        if (pid <= 0)
            continue;
        snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
        stat = read_file(path, NULL);
        if (!stat)
            continue;
        p = strrchr(stat, ')'); /* "pid (comm) state ppid ..." */
        if (!p || atoi(p + 4) != (int)parent) {
            free(stat);
            continue;
        }
        free(stat);
        snprintf(path, sizeof path, "/proc/%d/environ", (int)pid);
        env = read_file(path, &len);
        for (p = env; env && p < env + len; p += strlen(p) + 1)
            if (strcmp(p, want) == 0) {
                free(env);
                closedir(d);
                return pid;
            }
        free(env);
    }
    if (d)
        closedir(d);
    return -1;
}

/* pid is a live process (not gone, not a zombie waiting to be reaped). */
static int alive(pid_t pid)
{
    char path[64], *stat, *p;
    int live;
    snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
    stat = read_file(path, NULL);
    p = stat ? strrchr(stat, ')') : NULL;
    live = p && p[1] == ' ' && p[2] != 'Z' && p[2] != 'X';
    free(stat);
    return live;
}

/* Three ranks, one of them stopped (SIGSTOP) mid-ensemble: rank 0 names
 * it and the run it holds after --rank-timeout, keeps the summary whole
 * and ends every rank (the stopped one too); --resume does the rest. */
static void case_mpi_stopped(void)
{
    char model[PATH_MAX + 32], out[300], errp[300], *msg, *text;
    const char *args[] = {"mpirun", "-np", "3", "--oversubscribe",
                          cli_program, model, "--sweep", "th1=0.5:2.5:120",
                          "--t-end", "60", "--integrator", "erk", "--rtol",
                          "1e-10", "--threads", "1", "-q", "--rank-timeout",
                          "2", "--out", out, NULL};
    pid_t pid, victim = -1;
    long lines = 0;
    int k, st = 0;
    snprintf(model, sizeof model, "%s/double-pendulum.eom", models);
    scratch(out, sizeof out, "stopped.csv");
    scratch(errp, sizeof errp, "stopped.txt");
    fflush(NULL);
    pid = fork();
    if (pid == 0) {
        FILE *e = freopen(errp, "w", stderr);
        (void)e;
        execvp(args[0], (char *const *)(void *)args);
        _exit(127);
    }
    CHECK(pid > 0);
    for (k = 0; k < 3000 && lines < 3; k++) { /* rows from every rank */
        const struct timespec nap = {0, 10000000};
        nanosleep(&nap, NULL);
        text = read_file(out, NULL);
        lines = 0;
        for (msg = text; msg && *msg; msg++)
            lines += *msg == '\n';
        free(text);
    }
    CHECK(lines >= 3);
    victim = rank_pid(pid, 1);
    CHECK(victim > 0);
    if (victim > 0)
        kill(victim, SIGSTOP);
    waitpid(pid, &st, 0);
    for (k = 0; k < 500 && victim > 0 && alive(victim); k++) {
        const struct timespec nap = {0, 10000000}; /* being killed */
        nanosleep(&nap, NULL);
    }
    if (victim > 0 && alive(victim)) { /* left behind: a failure */
        CHECK(!"the stopped rank was left running");
        kill(victim, SIGKILL);
    }
    CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 1);
    msg = read_file(errp, NULL);
    CHECK_HAS(msg, "eom-ensemble: rank 1 has not answered for");
    CHECK_HAS(msg, "it holds run ");
    CHECK_HAS(msg, "--resume does the rest");
    free(msg);
    text = read_file(out, NULL);
    CHECK(text && strlen(text) > 0 && text[strlen(text) - 1] == '\n');
    free(text);
    {
        const char *again[] = {model, "--sweep", "th1=0.5:2.5:120",
                               "--t-end", "60", "--integrator", "erk",
                               "--rtol", "1e-10", "-q", "--out", out,
                               "--resume", NULL};
        result r;
        run(&r, again);
        CHECK_INT(r.status, 0);
        result_free(&r);
    }
    text = read_file(out, NULL);
    lines = 0;
    for (msg = text; msg && *msg; msg++)
        lines += *msg == '\n';
    free(text);
    CHECK_INT((int)lines, 121);
    unlink(errp);
}

static void case_usage(void)
{
    const char *no_out[] = {"spring-pendulum", "--sweep", "k=1:2:2", NULL};
    const char *both[] = {"spring-pendulum", "--sweep", "k=1:2:2", "--runs",
                          "x.csv", "--out", "o.csv", NULL};
    const char *unknown[] = {"spring-pendulum", "--sweep", "kk=1:2:2",
                             "--out", "/nonexistent/o.csv", NULL};
    const char *bad[] = {"spring-pendulum", "--sweep", "k=1:2", "--out",
                         "o.csv", NULL};
    result r;
    run(&r, no_out);
    CHECK_INT(r.status, 2);
    CHECK_HAS(r.err, "--out SUMMARY.csv is required");
    result_free(&r);
    run(&r, both);
    CHECK_INT(r.status, 2);
    CHECK_HAS(r.err, "one of --runs FILE, --sweep");
    result_free(&r);
    run(&r, unknown);
    CHECK_INT(r.status, 2);
    CHECK_HAS(r.err, "the runs vary 'kk'");
    result_free(&r);
    run(&r, bad);
    CHECK_INT(r.status, 2);
    CHECK_HAS(r.err, "expected NAME=LO:HI:N");
    result_free(&r);
    /* a runs file naming a column twice, the twins side by side, and
     * apart */
    {
        static const char *const side[] = {"k,k\n", "1,2\n", NULL};
        static const char *const apart[] = {"k,m,k\n", "1,1,2\n", NULL};
        char runs[300];
        const char *dup[] = {"spring-pendulum", "--runs", runs, "--out",
                             "o.csv", NULL};
        scratch(runs, sizeof runs, "dup.csv");
        write_runs(runs, side);
        run(&r, dup);
        CHECK_INT(r.status, 2);
        CHECK_HAS(r.err, "the runs name 'k' twice");
        result_free(&r);
        write_runs(runs, apart);
        run(&r, dup);
        CHECK_INT(r.status, 2);
        CHECK_HAS(r.err, "the runs name 'k' twice");
        result_free(&r);
        unlink(runs);
    }
}

/* The driven crank, whose motor reads the time, three times alike on one
 * thread: each run starts at t = 0, although the worker's system ended
 * the run before at t = 0.5 (a start checked at that time would be off
 * the motor's constraint and projected elsewhere). */
static void case_time(void)
{
    char model[PATH_MAX + 32], out[300], *a, *line[3], *p;
    const char *args[] = {model, "--sweep", "g=9.81:9.81:3", "--t-end",
                          "0.5", "--threads", "1", "--out", out, "-q", NULL};
    result r;
    int k;
    snprintf(model, sizeof model, "%s/driven-crank.eom", models);
    scratch(out, sizeof out, "time.csv");
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    a = summary(out);
    CHECK(a != NULL);
    if (!a)
        return;
    /* the three lines after the header, each without its run number */
    p = strchr(a, '\n');
    for (k = 0; k < 3; k++) {
        char *end = p ? strchr(p + 1, '\n') : NULL;
        line[k] = p ? strchr(p + 1, ',') : NULL;
        if (end)
            *end = '\0';
        p = end;
    }
    CHECK(line[0] && line[1] && line[2]);
    if (line[0] && line[1] && line[2]) {
        CHECK_HAS(line[0], ",ok,2,");
        CHECK(strcmp(line[0], line[1]) == 0);
        CHECK(strcmp(line[0], line[2]) == 0);
    }
    free(a);
}

static const struct {
    const char *name;
    void (*fn)(void);
} cases[] = {
    {"ensemble_threads", case_threads}, {"ensemble_failure", case_failure},
    {"ensemble_resume", case_resume},
    {"ensemble_trajectories", case_trajectories},
    {"ensemble_plots", case_plots},
    {"ensemble_usage", case_usage}, {"ensemble_random", case_random},
    {"ensemble_mpi", case_mpi}, {"ensemble_kill", case_kill},
    {"ensemble_mpi_setup", case_mpi_setup}, {"ensemble_mpi_stopped", case_mpi_stopped}, {"ensemble_time", case_time},
    {"ensemble_compiled", case_compiled},
};

int main(int argc, char **argv)
{
    static char program[PATH_MAX];
    size_t i;
    int found = 0;
    if (argc < 4 || !realpath(argv[1], program) ||
        !realpath(argv[2], models)) {
        fprintf(stderr, "usage: test_cli_ensemble EOM_ENSEMBLE MODELS_DIR "
                "CASE\n");
        return EXIT_FAILURE;
    }
    cli_program = program;
    if (cli_setup() != 0)
        return EXIT_FAILURE;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++)
        if (strcmp(cases[i].name, argv[3]) == 0) {
            cases[i].fn();
            found = 1;
        }
    cli_cleanup();
    if (!found) {
        fprintf(stderr, "test_cli_ensemble: unknown case '%s'\n", argv[3]);
        return EXIT_FAILURE;
    }
    CHECK_DONE();
}
