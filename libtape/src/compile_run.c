/* compile_run.c - runs the system's C compiler on a compiled tape's
 * source (compile.c decides what to build and where), and names the
 * compiler that runs for the cache key.
 *
 * A small tape is built by one compiler call. A large one is built in
 * parts at once: the source compiles into part k when TPC_PART = k
 * (codegen.c puts each chunk function in one part and the entry points in
 * part 0), so `parts` compilers run side by side on the same file, each
 * with its share of the chunks, and one link joins their objects. The
 * compiler's time grows with the statements it optimizes, so the parts
 * divide the wall time by up to the number of processors.
 *
 * The compiler. Its command's first word is resolved through PATH to the
 * real path of the file, and that file is what runs (with the command's
 * word as argv[0]): the cache key names the same compiler (its path,
 * size, times and `--version`).
 *
 * The children. Each compiler call runs under a guard: the system's shell
 * (/bin/sh) in a process group of its own, which starts the compiler in
 * it and waits for it. When the thread that started the guard dies (the
 * process is killed mid-compile), the guard is told (Linux:
 * PR_SET_PDEATHSIG) and kills its whole group, so no compiler (nor the
 * compiler's own children) outlives the run; a build abandoned because
 * one part failed kills the other parts' groups. Between fork and exec
 * the child calls only async-signal-safe functions: the caller may have
 * threads.
 *
 * Nothing here can terminate the caller, and every failure is a message.
 */
#define _GNU_SOURCE /* pipe2, prctl */

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#if defined(__linux__)
#include <sys/prctl.h>
#endif

#include "codegen.h"

#define MAX_ARGS 64
#define WORDS_LEN 8192
#define PATH_LEN 4096
/* What `cc --version` may print (the rest is read and dropped), and how
 * long it may take. */
#define VERSION_LEN 2048
#define VERSION_SECONDS 20

/* Split s at blanks into argv (no quoting: a path with blanks cannot be a
 * compiler here). Returns the count, or -1 when there are too many. */
static int split_words(char *s, char **argv, int max)
{
    int n = 0;
    char *save = NULL, *w;
    for (w = strtok_r(s, " \t", &save); w; w = strtok_r(NULL, " \t", &save)) {
        if (n >= max)
            return -1;
        argv[n++] = w;
    }
    return n;
}

/* ---- the compiler that runs --------------------------------------------- */

/* 1 if path is a regular file this user may execute. */
static int runnable(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode) &&
           access(path, X_OK) == 0;
}

int tp__compiler_path(const char *cc, char *exe, size_t len, char *msg,
                      size_t mlen)
{
    char word[PATH_LEN], cand[PATH_LEN], *real = NULL;
    const char *path;
    size_t k = strspn(cc, " \t"), n = strcspn(cc + k, " \t");
    int err = ENOENT;
    if (n == 0 || n >= sizeof word) {
        snprintf(msg, mlen, "the compiler command '%.200s' is empty or too "
                            "long", cc);
        return -1;
    }
    memcpy(word, cc + k, n);
    word[n] = '\0';
    if (strchr(word, '/')) {
        if (runnable(word))
            real = realpath(word, NULL);
        else
            err = errno ? errno : EACCES;
    } else {
        /* PATH as execvp reads it (an empty entry is the current folder) */
        path = getenv("PATH");
        if (!path)
            path = "/usr/local/bin:/usr/bin:/bin";
        while (!real) {
            const size_t d = strcspn(path, ":");
            const int w = d == 0 ? snprintf(cand, sizeof cand, "./%s", word)
                                 : snprintf(cand, sizeof cand, "%.*s/%s",
                                            (int)d, path, word);
            if (w > 0 && (size_t)w < sizeof cand && runnable(cand))
                real = realpath(cand, NULL);
            if (!path[d])
                break;
            path += d + 1;
        }
    }
    if (!real || strlen(real) >= len) {
        snprintf(msg, mlen, "cannot run the C compiler '%.200s': %s%s", word,
                 real ? "its path is too long" : strerror(err),
                 !real && err == ENOENT
                     ? " (set CC or install a C compiler)" : "");
        free(real);
        return -1;
    }
    memcpy(exe, real, strlen(real) + 1);
    free(real);
    return 0;
}

/* ---- children ------------------------------------------------------------ */

/* The guard is the system's shell, run with this script and the compiler
 * as its arguments: it leads a process group of its own, starts the
 * compiler in it, waits for it and exits with its status; told to stop
 * (SIGTERM: the thread that started it died; SIGHUP, SIGINT), it kills its
 * whole group. A program of its own rather than a forked copy of the
 * caller, so that nothing of the caller's state (its heap, its threads'
 * stacks) lives on in it, and a memory checker that follows the caller
 * does not follow the guard. */
static char guard_script[] =
    "trap 'kill -KILL 0' TERM HUP INT; \"$@\" & wait $!";
static char guard_sh[] = "sh", guard_c[] = "-c";
#define GUARD_SHELL "/bin/sh"
/* the longest argv a compiler call has (build_args) */
#define ARGV_CAP (MAX_ARGS + TP_MAX_PARTS + 12)

/* Start exe (argv[0] its name as the command gave it) under a guard,
 * with stdout and stderr to out (an open descriptor): the guard's pid
 * (its process group's id), or -1 with msg. */
static pid_t start(const char *exe, char **argv, int out, char *msg,
                   size_t len)
{
    const pid_t parent = getpid();
    char *gargv[ARGV_CAP + 5];
    union {
        const char *c;
        char *m; /* execv's argv is char *const[]: nothing writes it */
    } path;
    struct sigaction dfl;
    sigset_t none;
    pid_t pid;
    int k, n = 0;
    /* everything exec needs is made before fork: the caller may have
     * threads, so the child calls only async-signal-safe functions */
    path.c = exe;
    gargv[n++] = guard_sh;
    gargv[n++] = guard_c;
    gargv[n++] = guard_script;
    gargv[n++] = guard_sh;
    gargv[n++] = path.m; /* the resolved compiler ("$@" runs it) */
    for (k = 1; argv[k] && n < ARGV_CAP + 4; k++)
        gargv[n++] = argv[k];
    gargv[n] = NULL;
    memset(&dfl, 0, sizeof dfl);
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    sigemptyset(&none);
    pid = fork();
    if (pid == 0) {
        setpgid(0, 0);
        /* a signal ignored when a shell starts cannot be trapped */
        sigaction(SIGTERM, &dfl, NULL);
        sigaction(SIGHUP, &dfl, NULL);
        sigaction(SIGINT, &dfl, NULL);
        sigprocmask(SIG_SETMASK, &none, NULL);
#if defined(__linux__)
        prctl(PR_SET_PDEATHSIG, SIGTERM); /* kept across exec */
#endif
        if (getppid() != parent) /* the caller died before prctl */
            kill(0, SIGKILL);
        if (dup2(out, 1) < 0 || dup2(out, 2) < 0)
            _exit(126);
        execv(GUARD_SHELL, gargv);
        _exit(127);
    }
    if (pid < 0) {
        snprintf(msg, len, "cannot start the C compiler: %s",
                 strerror(errno));
        return -1;
    }
    setpgid(pid, pid); /* as the guard does: no race with a kill below */
    return pid;
}

/* Wait for the guard pid without reaping it, kill whatever is left of
 * its group (if kill_first, before waiting: the build is abandoned), then
 * reap it: its exit status (the compiler's, or 128 + a signal), or -1. */
static int reap(pid_t pid, int kill_first)
{
    siginfo_t si;
    int status;
    if (kill_first)
        kill(-pid, SIGKILL);
    memset(&si, 0, sizeof si);
    while (waitid(P_PID, (id_t)pid, &si, WEXITED | WNOWAIT) < 0)
        if (errno != EINTR)
            break;
    /* the group's id stays reserved while its leader is a zombie */
    kill(-pid, SIGKILL);
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            return -1;
    if (WIFEXITED(status))
        return WEXITSTATUS(status);
    return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

/* ---- the compiler's version ---------------------------------------------- */

/* What `cc --version` printed, per compiler file, for the process's life
 * (a few entries; more compilers are asked each time). */
#define VERSIONS 8
static struct {
    char exe[PATH_LEN];
    struct stat st;
    char text[VERSION_LEN];
} versions[VERSIONS];
static int n_versions;
static pthread_mutex_t versions_lock = PTHREAD_MUTEX_INITIALIZER;

/* Run exe --version as cc: what it printed and its status, into out. */
static void run_version(const char *exe, const char *cc, char *out,
                        size_t len)
{
    char word[PATH_LEN], dash[] = "--version", *argv[3], buf[512];
    size_t k = strspn(cc, " \t"), n = strcspn(cc + k, " \t"), have = 0;
    int fd[2], rc;
    pid_t pid;
    struct timespec t0, t1;
    out[0] = '\0';
    if (n >= sizeof word || pipe2(fd, O_CLOEXEC) != 0)
        return;
    memcpy(word, cc + k, n);
    word[n] = '\0';
    argv[0] = word, argv[1] = dash, argv[2] = NULL;
    pid = start(exe, argv, fd[1], buf, sizeof buf);
    close(fd[1]);
    if (pid < 0) {
        close(fd[0]);
        return;
    }
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (;;) {
        struct pollfd p = {fd[0], POLLIN, 0};
        ssize_t r;
        clock_gettime(CLOCK_MONOTONIC, &t1);
        if (t1.tv_sec - t0.tv_sec > VERSION_SECONDS)
            break;
        if (poll(&p, 1, 1000) < 0 && errno != EINTR)
            break;
        if (!p.revents)
            continue;
        r = read(fd[0], buf, sizeof buf);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        if (have + 1 < len) {
            const size_t take =
                (size_t)r < len - 1 - have ? (size_t)r : len - 1 - have;
            memcpy(out + have, buf, take);
            have += take;
        }
    }
    close(fd[0]);
    rc = reap(pid, 1);
    snprintf(out + have, len - have, "\nstatus %d\n", rc);
}

void tp__compiler_identity(const char *exe, const char *cc, char *out,
                           size_t len)
{
    struct stat st;
    char text[VERSION_LEN];
    int k, n;
    text[0] = '\0';
    if (stat(exe, &st) != 0)
        memset(&st, 0, sizeof st);
    pthread_mutex_lock(&versions_lock);
    for (k = 0; k < n_versions; k++)
        if (strcmp(versions[k].exe, exe) == 0 &&
            versions[k].st.st_size == st.st_size &&
            versions[k].st.st_mtim.tv_sec == st.st_mtim.tv_sec &&
            versions[k].st.st_mtim.tv_nsec == st.st_mtim.tv_nsec &&
            versions[k].st.st_ino == st.st_ino &&
            versions[k].st.st_dev == st.st_dev)
            break;
    if (k < n_versions) {
        memcpy(text, versions[k].text, sizeof text);
    } else {
        /* asked under the lock: threads compiling at once ask once */
        run_version(exe, cc, text, sizeof text);
        if (n_versions < VERSIONS && strlen(exe) < PATH_LEN) {
            memcpy(versions[n_versions].exe, exe, strlen(exe) + 1);
            versions[n_versions].st = st;
            memcpy(versions[n_versions].text, text, sizeof text);
            n_versions++;
        }
    }
    pthread_mutex_unlock(&versions_lock);
    n = snprintf(out, len,
                 "compiler %s\nsize %lld\nmtime %lld.%09ld\nctime "
                 "%lld.%09ld\ninode %llu:%llu\nversion %s",
                 exe, (long long)st.st_size, (long long)st.st_mtim.tv_sec,
                 (long)st.st_mtim.tv_nsec, (long long)st.st_ctim.tv_sec,
                 (long)st.st_ctim.tv_nsec, (unsigned long long)st.st_dev,
                 (unsigned long long)st.st_ino, text);
    (void)n;
}

/* ---- the build ------------------------------------------------------------- */

/* The first line of the compiler's messages, for the caller's message. */
static void first_line(const char *log, char *out, size_t len)
{
    int fd = open(log, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    ssize_t r;
    size_t k;
    out[0] = 0;
    if (fd < 0)
        return;
    r = read(fd, out, len - 1);
    close(fd);
    out[r > 0 ? r : 0] = '\0';
    k = strcspn(out, "\n");
    out[k] = 0;
}

/* The guard pid's status st as a message (once: a message already set is
 * kept, so the first failure is the one reported); 0 if it is 0. */
static int judge(int st, const char *cmd, const char *log,
                 const char *log_name, char *msg, size_t len)
{
    char detail[200];
    if (st == 0)
        return 0;
    if (msg[0])
        return -1;
    first_line(log, detail, sizeof detail);
    if (st < 0)
        snprintf(msg, len, "waiting for the C compiler: %s",
                 strerror(errno));
    else if (st == 127)
        snprintf(msg, len, "cannot run the C compiler '%s' (not found)", cmd);
    else if (st == 126)
        snprintf(msg, len, "cannot start the C compiler '%s'", cmd);
    else if (st > 128)
        snprintf(msg, len, "the C compiler '%s' was stopped by signal %d",
                 cmd, st - 128);
    else
        snprintf(msg, len, "the C compiler '%s' failed (exit %d)%s%.200s; "
                           "see %s",
                 cmd, st, detail[0] ? ": " : "", detail, log_name);
    return -1;
}

int tp__run_build(const char *exe, const char *cc, const char *flags,
                  const char *wd, int parts, const char *log_name,
                  char *msg, size_t len)
{
    static char fpic[] = "-fPIC", shared[] = "-shared",
                contract[] = "-ffp-contract=off", dash_o[] = "-o",
                dash_c[] = "-c", libm[] = "-lm";
    char words[WORDS_LEN], defs[TP_MAX_PARTS][2][32];
    char obj[TP_MAX_PARTS][PATH_LEN], src[PATH_LEN], so[PATH_LEN],
        log[PATH_LEN];
    char *argv[ARGV_CAP];
    pid_t pid[TP_MAX_PARTS];
    int n, m, k, rc = 0, started = 0, out;
    msg[0] = 0;
    if (parts < 1 || parts > TP_MAX_PARTS)
        parts = 1;
    if ((size_t)snprintf(words, sizeof words, "%s", cc) >= sizeof words / 2 ||
        (n = split_words(words, argv, MAX_ARGS / 2)) < 1) {
        snprintf(msg, len, "the compiler command '%s' is empty or too long", cc);
        return -1;
    }
    m = (int)strlen(words) + 1;
    if ((size_t)snprintf(words + m, sizeof words - (size_t)m, "%s", flags) >=
            sizeof words - (size_t)m ||
        (k = split_words(words + m, argv + n, MAX_ARGS / 2)) < 0) {
        snprintf(msg, len, "the compiler flags '%s' are too long", flags);
        return -1;
    }
    n += k;
    if ((size_t)snprintf(src, sizeof src, "%s/src.c", wd) >= sizeof src ||
        (size_t)snprintf(so, sizeof so, "%s/out.so", wd) >= sizeof so ||
        (size_t)snprintf(log, sizeof log, "%s/log", wd) >= sizeof log) {
        snprintf(msg, len, "the cache directory's name is too long");
        return -1;
    }
    /* the log: created here, never an existing file; the parts append */
    out = open(log, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_APPEND |
                        O_CLOEXEC, 0600);
    if (out < 0) {
        snprintf(msg, len, "cannot create %s: %s", log, strerror(errno));
        return -1;
    }
    if (parts == 1) {
        char **a = argv + n;
        *a++ = fpic, *a++ = shared, *a++ = contract, *a++ = dash_o;
        *a++ = so, *a++ = src, *a++ = libm, *a = NULL;
        if ((pid[0] = start(exe, argv, out, msg, len)) < 0)
            rc = -1;
        else
            rc = judge(reap(pid[0], 0), argv[0], log, log_name, msg, len);
        close(out);
        return rc;
    }
    /* the parts, side by side */
    for (k = 0; k < parts; k++) {
        char **a = argv + n;
        snprintf(defs[k][0], sizeof defs[k][0], "-DTPC_NPARTS=%d", parts);
        snprintf(defs[k][1], sizeof defs[k][1], "-DTPC_PART=%d", k);
        if ((size_t)snprintf(obj[k], sizeof obj[k], "%s/p%d.o", wd, k) >=
            sizeof obj[k]) {
            snprintf(msg, len, "the cache directory's name is too long");
            rc = -1;
            break;
        }
        *a++ = fpic, *a++ = contract, *a++ = defs[k][0], *a++ = defs[k][1];
        *a++ = dash_c, *a++ = dash_o, *a++ = obj[k], *a++ = src;
        *a = NULL;
        if ((pid[k] = start(exe, argv, out, msg, len)) < 0) {
            rc = -1;
            break;
        }
        started++;
    }
    /* a failed part abandons the build: the others are killed, not
     * waited for */
    for (k = 0; k < started; k++)
        if (judge(reap(pid[k], rc != 0), argv[0], log, log_name, msg, len) !=
            0)
            rc = -1;
    if (rc == 0) { /* one link of the parts' objects */
        char **a = argv + n;
        *a++ = fpic, *a++ = shared, *a++ = dash_o, *a++ = so;
        for (k = 0; k < parts; k++)
            *a++ = obj[k];
        *a++ = libm, *a = NULL;
        if ((pid[0] = start(exe, argv, out, msg, len)) < 0 ||
            judge(reap(pid[0], 0), argv[0], log, log_name, msg, len) != 0)
            rc = -1;
    }
    close(out);
    return rc;
}
