/* cli_support.c - running eom-run and reading its output for the
 * command-line tests (see cli_support.h). */
#define _POSIX_C_SOURCE 200809L
#include "cli_support.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

const char *cli_program;
static char tmpdir[256]; /* scratch directory of this process */

int cli_setup(void)
{
    const char *base = getenv("TMPDIR");
    snprintf(tmpdir, sizeof tmpdir, "%s/eom-cli-XXXXXX",
             base && *base ? base : "/tmp");
    if (!mkdtemp(tmpdir)) {
        fprintf(stderr, "mkdtemp %s: %s\n", tmpdir, strerror(errno));
        return -1;
    }
    return 0;
}

/* Remove the files of dir and, depth levels down, of its directories,
 * then dir itself; 0 if dir is gone. */
static int remove_tree(const char *dir, int depth)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char path[1024];
    while (d && (e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        /* a name too long for path is left, and dir's rmdir says so */
        if ((size_t)snprintf(path, sizeof path, "%s/%s", dir, e->d_name) >=
            sizeof path)
            continue;
        if (unlink(path) != 0 && depth > 0)
            remove_tree(path, depth - 1);
    }
    if (d)
        closedir(d);
    return rmdir(dir);
}

void cli_cleanup(void)
{
    /* what a case left behind: files, and directories of files (the
     * compiled tapes' caches) */
    if (remove_tree(tmpdir, 1) != 0)
        fprintf(stderr, "warning: cannot remove %s: %s\n", tmpdir,
                strerror(errno));
}

void scratch(char *buf, size_t len, const char *name)
{
    snprintf(buf, len, "%s/%s", tmpdir, name);
}

char *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    size_t cap = 0, n = 0, got;
    if (!f)
        return NULL;
    do {
        if (n + 4096 + 1 > cap) {
            char *p;
            cap = 2 * cap + 4096 + 1;
            p = realloc(buf, cap);
            if (!p) {
                free(buf);
                fclose(f);
                return NULL;
            }
            buf = p;
        }
        got = fread(buf + n, 1, 4096, f);
        n += got;
    } while (got > 0);
    fclose(f);
    buf[n] = '\0';
    if (len)
        *len = n;
    return buf;
}

void result_free(result *r)
{
    free(r->out);
    free(r->err);
    r->out = r->err = NULL;
}

/* The file name prog found on the current PATH (into buf), or prog as it
 * is when it has a '/' or is not found. */
static const char *on_path(const char *prog, char *buf, size_t len)
{
    const char *path = getenv("PATH"), *p;
    if (strchr(prog, '/') || !path)
        return prog;
    for (p = path; *p;) {
        const char *colon = strchr(p, ':');
        size_t dl = colon ? (size_t)(colon - p) : strlen(p);
        snprintf(buf, len, "%.*s/%s", (int)dl, p, prog);
        if (dl > 0 && access(buf, X_OK) == 0)
            return buf;
        p += dl + (colon ? 1 : 0);
    }
    return prog;
}

static void run_full(result *r, const char *const *args, const char *path,
                     const char *dir);

void run_path(result *r, const char *const *args, const char *path)
{
    run_full(r, args, path, NULL);
}

void run_in(result *r, const char *const *args, const char *dir)
{
    run_full(r, args, NULL, dir);
}

static void run_full(result *r, const char *const *args, const char *path,
                     const char *dir)
{
    char out_path[300], err_path[300], wrap[1024], found[4096];
    const char *argv[64];
    const char *w = getenv("EOM_CLI_WRAPPER");
    int argc = 0, st;
    pid_t pid;

    if (w && *w) {
        char *tok;
        snprintf(wrap, sizeof wrap, "%s", w);
        for (tok = strtok(wrap, " "); tok && argc < 16;
             tok = strtok(NULL, " "))
            argv[argc++] = tok;
    }
    argv[argc++] = cli_program;
    while (*args && argc < 63)
        argv[argc++] = *args++;
    argv[argc] = NULL;
    /* with PATH changed for the child, find the first word now */
    argv[0] = on_path(argv[0], found, sizeof found);

    scratch(out_path, sizeof out_path, "stdout.txt");
    scratch(err_path, sizeof err_path, "stderr.txt");
    fflush(NULL);
    pid = fork();
    if (pid == 0) {
        int fo = open(out_path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
        int fe = open(err_path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
        if (fo < 0 || fe < 0 || dup2(fo, 1) < 0 || dup2(fe, 2) < 0)
            _exit(126);
        if (path && setenv("PATH", path, 1) != 0)
            _exit(126);
        if (dir && chdir(dir) != 0)
            _exit(126);
        /* execvp's argv is char *const[]: the strings are not modified */
        execvp(argv[0], (char *const *)(void *)argv);
        _exit(127);
    }
    r->status = -1;
    if (pid > 0 && waitpid(pid, &st, 0) == pid)
        r->status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    r->out = read_file(out_path, NULL);
    r->err = read_file(err_path, NULL);
    if (!r->out || !r->err) {
        fprintf(stderr, "cannot read the output of eom-run\n");
        exit(EXIT_FAILURE);
    }
    unlink(out_path);
    unlink(err_path);
}

void run(result *r, const char *const *args)
{
    run_path(r, args, NULL);
}

int has(const char *s, const char *word)
{
    return s && strstr(s, word) != NULL;
}

double number_after(const char *s, const char *label)
{
    const char *p = s ? strstr(s, label) : NULL;
    char *end;
    double v;
    if (!p)
        return NAN;
    p += strlen(label);
    v = strtod(p, &end);
    return end == p ? NAN : v;
}

int csv_parse(const char *text, csv *c, char *msg, size_t msglen)
{
    const char *p = strchr(text, '\n'), *line;
    int cap = 0;
    memset(c, 0, sizeof *c);
    if (!p || (size_t)(p - text) >= sizeof c->header) {
        snprintf(msg, msglen, "CSV without a header row:\n%.200s", text);
        return -1;
    }
    memcpy(c->header, text, (size_t)(p - text));
    c->ncols = 1;
    for (line = c->header; *line; line++)
        c->ncols += *line == ',';
    for (line = p + 1; *line;) {
        int j;
        if (c->nrows == cap) {
            cap = cap ? 2 * cap : 64;
            c->v = realloc(c->v, (size_t)cap * (size_t)c->ncols *
                                     sizeof(double));
            if (!c->v)
                exit(EXIT_FAILURE);
        }
        for (j = 0; j < c->ncols; j++) {
            char *end;
            double x = strtod(line, &end);
            char want = j + 1 < c->ncols ? ',' : '\n';
            if (end == line || *end != want) {
                snprintf(msg, msglen, "CSV row %d, column %d is malformed: "
                         "%.60s", c->nrows + 1, j + 1, line);
                return -1;
            }
            c->v[c->nrows * c->ncols + j] = x;
            line = end + 1;
        }
        c->nrows++;
    }
    return 0;
}

double at(const csv *c, int row, int col)
{
    return c->v[row * c->ncols + col];
}

int csv_col(const csv *c, const char *name)
{
    const char *p = c->header;
    size_t nl = strlen(name);
    int k = 0;
    for (;;) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        if (len == nl && strncmp(p, name, nl) == 0)
            return k;
        if (!comma)
            return -1;
        p = comma + 1;
        k++;
    }
}
