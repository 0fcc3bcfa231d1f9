/* compile_run.c - runs the system's C compiler on a compiled tape's
 * source (compile.c decides what to build and where).
 *
 * A small tape is built by one compiler call. A large one is built in
 * parts at once: the source compiles into part k when TPC_PART = k
 * (codegen.c puts each chunk function in one part and the entry points in
 * part 0), so `parts` compilers run side by side on the same file, each
 * with its share of the chunks, and one link joins their objects. The
 * compiler's time grows with the statements it optimizes, so the parts
 * divide the wall time by up to the number of processors.
 *
 * The compilers run as child processes: nothing here can terminate the
 * caller, and every failure is a message.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <fcntl.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "codegen.h"

extern char **environ;

#define MAX_ARGS 64
#define WORDS_LEN 8192

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

/* The first line of the compiler's messages, for the caller's message. */
static void first_line(const char *log, char *out, size_t len)
{
    FILE *f = fopen(log, "r");
    size_t k;
    out[0] = 0;
    if (!f)
        return;
    if (!fgets(out, (int)len, f))
        out[0] = 0;
    fclose(f);
    k = strcspn(out, "\n");
    out[k] = 0;
}

/* Start argv with its output appended to log: its pid, or -1 with msg. */
static pid_t start(char **argv, const char *log, char *msg, size_t len)
{
    posix_spawn_file_actions_t fa;
    pid_t pid;
    int rc;
    if (posix_spawn_file_actions_init(&fa) != 0) {
        snprintf(msg, len, "cannot start the compiler: out of memory");
        return -1;
    }
    posix_spawn_file_actions_addopen(&fa, 1, log,
                                     O_WRONLY | O_CREAT | O_APPEND, 0600);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    rc = posix_spawnp(&pid, argv[0], &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) {
        snprintf(msg, len, "cannot run the C compiler '%s': %s%s", argv[0],
                 strerror(rc),
                 rc == ENOENT ? " (set CC or install a C compiler)" : "");
        return -1;
    }
    return pid;
}

/* Wait for pid; 0 if it exited with 0, else -1 with msg (once: a message
 * already set is kept, so the first failure is the one reported). */
static int finish(pid_t pid, const char *cmd, const char *log, char *msg,
                  size_t len)
{
    char detail[200];
    int status;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) {
            if (!msg[0])
                snprintf(msg, len, "waiting for the C compiler: %s",
                         strerror(errno));
            return -1;
        }
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0)
        return 0;
    if (msg[0])
        return -1;
    first_line(log, detail, sizeof detail);
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
        snprintf(msg, len, "cannot run the C compiler '%s' (not found)", cmd);
    else if (WIFEXITED(status))
        snprintf(msg, len, "the C compiler '%s' failed (exit %d)%s%.200s; see %s",
                 cmd, WEXITSTATUS(status), detail[0] ? ": " : "", detail, log);
    else
        snprintf(msg, len, "the C compiler '%s' was stopped by signal %d", cmd,
                 WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    return -1;
}

int tp__run_build(const char *cc, const char *flags, char *src, char *so,
                  const char *tmp_base, int parts,
                  const char *log, char *msg, size_t len)
{
    static char fpic[] = "-fPIC", shared[] = "-shared",
                contract[] = "-ffp-contract=off", dash_o[] = "-o",
                dash_c[] = "-c", libm[] = "-lm";
    char words[WORDS_LEN], defs[TP_MAX_PARTS][2][32];
    char obj[TP_MAX_PARTS][4096];
    char *argv[MAX_ARGS + TP_MAX_PARTS + 12];
    pid_t pid[TP_MAX_PARTS];
    int n, m, k, rc = 0, started = 0;
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
    /* a fresh log: the parts append to it */
    if (unlink(log) != 0 && errno != ENOENT) {
        snprintf(msg, len, "cannot replace %s: %s", log, strerror(errno));
        return -1;
    }
    if (parts == 1) {
        char **a = argv + n;
        *a++ = fpic, *a++ = shared, *a++ = contract, *a++ = dash_o;
        *a++ = so, *a++ = src, *a++ = libm, *a = NULL;
        if ((pid[0] = start(argv, log, msg, len)) < 0)
            return -1;
        return finish(pid[0], argv[0], log, msg, len);
    }
    /* the parts, side by side */
    for (k = 0; k < parts; k++) {
        char **a = argv + n;
        snprintf(defs[k][0], sizeof defs[k][0], "-DTPC_NPARTS=%d", parts);
        snprintf(defs[k][1], sizeof defs[k][1], "-DTPC_PART=%d", k);
        if ((size_t)snprintf(obj[k], sizeof obj[k], "%s.p%d.o", tmp_base, k) >=
            sizeof obj[k]) {
            snprintf(msg, len, "the cache directory's name is too long");
            rc = -1;
            break;
        }
        *a++ = fpic, *a++ = contract, *a++ = defs[k][0], *a++ = defs[k][1];
        *a++ = dash_c, *a++ = dash_o, *a++ = obj[k], *a++ = src;
        *a = NULL;
        if ((pid[k] = start(argv, log, msg, len)) < 0) {
            rc = -1;
            break;
        }
        started++;
    }
    for (k = 0; k < started; k++)
        if (finish(pid[k], argv[0], log, msg, len) != 0)
            rc = -1;
    if (rc == 0) { /* one link of the parts' objects */
        char **a = argv + n;
        *a++ = fpic, *a++ = shared, *a++ = dash_o, *a++ = so;
        for (k = 0; k < parts; k++)
            *a++ = obj[k];
        *a++ = libm, *a = NULL;
        if ((pid[0] = start(argv, log, msg, len)) < 0 ||
            finish(pid[0], argv[0], log, msg, len) != 0)
            rc = -1;
    }
    for (k = 0; k < started; k++)
        unlink(obj[k]);
    return rc;
}
