/* gnuplot_run.c - start gnuplot and wait for it (see eom/run.h).
 *
 * The child reports why it could not start through a pipe that closes
 * on a successful exec (FD_CLOEXEC): the parent reads either nothing (gnuplot
 * is running) or the child's errno, so "gnuplot is not installed" is told
 * apart from "gnuplot ran and failed", which an exit status alone cannot
 * do. */
#define _POSIX_C_SOURCE 200809L
#include "eom/run.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

/* What the child reports on the pipe before it gives up. */
typedef struct child_failure {
    int step; /* 0: chdir, 1: exec */
    int errnum;
} child_failure;

static void child(int fd, const char *dir, const char *script)
{
    child_failure f = {0, 0};
    const char *argv[3];
    int null = open("/dev/null", O_RDONLY);
    if (null >= 0) {
        dup2(null, STDIN_FILENO);
        if (null != STDIN_FILENO)
            close(null);
    }
    /* gnuplot's standard output is not the CSV: keep stdout clean */
    dup2(STDERR_FILENO, STDOUT_FILENO);
    if (chdir(dir) != 0) {
        f.errnum = errno;
    } else {
        argv[0] = "gnuplot";
        argv[1] = script;
        argv[2] = NULL;
        /* execvp takes char *const[]; the strings are not modified */
        execvp(argv[0], (char *const *)(void *)argv);
        f.step = 1;
        f.errnum = errno;
    }
    if (write(fd, &f, sizeof f) < 0) {
        /* nothing more can be reported */
    }
    _exit(127);
}

int eom_gnuplot_run(const char *dir, const char *script, char *err,
                    size_t errlen)
{
    int fds[2], st;
    child_failure f;
    ssize_t got;
    pid_t pid;

    if (pipe(fds) != 0) {
        snprintf(err, errlen, "cannot run gnuplot: pipe: %s",
                 strerror(errno));
        return -1;
    }
    fcntl(fds[1], F_SETFD, FD_CLOEXEC);
    fflush(NULL); /* the child must not flush our buffers a second time */
    pid = fork();
    if (pid < 0) {
        snprintf(err, errlen, "cannot run gnuplot: fork: %s",
                 strerror(errno));
        close(fds[0]);
        close(fds[1]);
        return -1;
    }
    if (pid == 0) {
        close(fds[0]);
        child(fds[1], dir, script);
    }
    close(fds[1]);
    do
        got = read(fds[0], &f, sizeof f);
    while (got < 0 && errno == EINTR);
    close(fds[0]);
    while (waitpid(pid, &st, 0) < 0)
        if (errno != EINTR) {
            snprintf(err, errlen, "gnuplot on '%s': waitpid: %s", script,
                     strerror(errno));
            return -1;
        }
    if (got == (ssize_t)sizeof f) {
        if (f.step == 0)
            snprintf(err, errlen, "cannot run gnuplot in '%s': %s", dir,
                     strerror(f.errnum));
        else if (f.errnum == ENOENT)
            snprintf(err, errlen, "cannot run gnuplot: it is not installed "
                     "or not on PATH (on Debian: apt install gnuplot-nox)");
        else
            snprintf(err, errlen, "cannot run gnuplot: %s",
                     strerror(f.errnum));
        return -1;
    }
    if (WIFSIGNALED(st)) {
        snprintf(err, errlen, "gnuplot on '%s' was killed by signal %d",
                 script, WTERMSIG(st));
        return -1;
    }
    if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        snprintf(err, errlen, "gnuplot failed on '%s' (exit status %d; its "
                 "messages are above)", script,
                 WIFEXITED(st) ? WEXITSTATUS(st) : -1);
        return -1;
    }
    return 0;
}
