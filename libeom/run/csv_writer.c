/* csv_writer.c - writing eom-run's CSV (see eom/run.h).
 *
 * A file is never written in place. The rows go to a temporary file
 * beside the target, PATH.tmp-XXXXXX, created exclusively (O_CREAT |
 * O_EXCL | O_NOFOLLOW: an existing name, symbolic links included, is
 * never opened) under a name drawn at random; eom_csv_writer_close
 * syncs it and renames it onto PATH in one step. Until then PATH keeps
 * its previous content, whatever happens to the process (SIGKILL, a full
 * disk, a power cut after the sync). A writer whose run failed (a write
 * error, or eom_run's failure, csv_writer_mark_failed) or that is closed
 * by eom_csv_writer_discard renames its file to PATH.partial instead and
 * leaves PATH alone. A path that exists and is not a regular file (a
 * device such as /dev/null, a FIFO) is written directly, as before.
 * A path that is a symbolic link to a regular file is replaced through
 * the link: the file it points to receives the new content.
 *
 * A text writer (eom_csv_writer_open_text: plot scripts and their data)
 * is written the same way with two differences: a symbolic link at PATH
 * is never followed (the rename replaces the link itself, the file it
 * names is untouched), a PATH that is neither a regular file nor a link
 * (a FIFO, a device, a folder) is refused; and after a failure its
 * temporary file is removed, not kept as PATH.partial.
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE
#include "eom/run.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>
#if defined(__linux__)
#include <sys/random.h>
#endif

#include "csv_writer_internal.h"

struct eom_csv_writer {
    FILE *f;
    int owned;    /* 1: opened here, fclose at the end */
    int failed;   /* a write failed or the run did: keep PATH as it was */
    char *target; /* the file replaced at the end (owned; NULL: none) */
    char *tmp;    /* the temporary file the rows go to (owned) */
    char *where;  /* "'PATH'" or "standard output", for messages (owned) */
    int text;     /* opened by eom_csv_writer_open_text: no PATH.partial */
};

static char *dup_str(const char *s)
{
    const size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* a followed by b, freshly allocated, or NULL */
static char *concat(const char *a, const char *b)
{
    const size_t na = strlen(a), nb = strlen(b);
    char *d = malloc(na + nb + 1);
    if (d) {
        memcpy(d, a, na);
        memcpy(d + na, b, nb + 1);
    }
    return d;
}

static int write_fail(eom_csv_writer *w, int errnum, char *err, size_t errlen)
{
    w->failed = 1;
    snprintf(err, errlen, "cannot write to %s: %s", w->where,
             errnum ? strerror(errnum) : "write error");
    return -1;
}

static void free_writer(eom_csv_writer *w)
{
    free(w->target);
    free(w->tmp);
    free(w->where);
    free(w);
}

/* Six characters no one can predict (the name's only defence is O_EXCL:
 * a guessed name costs a retry, never a file). */
static void random_tag(char tag[7])
{
    static const char al[] = "abcdefghijklmnopqrstuvwxyz"
                             "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
    unsigned char b[6];
    int i, got = 0;
#if defined(__linux__)
    got = getrandom(b, sizeof b, GRND_NONBLOCK) == (ssize_t)sizeof b;
#endif
    if (!got) {
        struct timespec ts;
        unsigned long long v;
        clock_gettime(CLOCK_REALTIME, &ts);
        v = (unsigned long long)ts.tv_nsec * 6364136223846793005ULL ^
            (unsigned long long)getpid() * 1442695040888963407ULL ^
            (unsigned long long)(size_t)tag;
        for (i = 0; i < 6; i++, v >>= 8)
            b[i] = (unsigned char)v;
    }
    for (i = 0; i < 6; i++)
        tag[i] = al[b[i] % (sizeof al - 1)];
    tag[6] = '\0';
}

/* Create the temporary file beside w->target: its FILE in w->f, its name
 * in w->tmp. mode: the permissions to give it (-1: those of a new file,
 * 0666 less the umask). 0, or -1 with a message. */
static int open_tmp(eom_csv_writer *w, int mode, const char *path, char *err,
                    size_t errlen)
{
    const size_t n = strlen(w->target);
    int tries, fd = -1;
    w->tmp = malloc(n + sizeof ".tmp-XXXXXX");
    if (!w->tmp) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    for (tries = 0; tries < 100 && fd < 0; tries++) {
        char tag[7];
        random_tag(tag);
        memcpy(w->tmp, w->target, n);
        memcpy(w->tmp + n, ".tmp-", 5);
        memcpy(w->tmp + n + 5, tag, 7);
        fd = open(w->tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC,
                  0666);
        if (fd < 0 && errno != EEXIST)
            break;
    }
    if (fd < 0) {
        snprintf(err, errlen, "cannot open '%s' for writing: %s", path,
                 strerror(errno));
        return -1;
    }
    if (mode >= 0)
        (void)fchmod(fd, (mode_t)mode);
    w->f = fdopen(fd, "w");
    if (!w->f) {
        snprintf(err, errlen, "cannot open '%s' for writing: %s", path,
                 strerror(errno));
        close(fd);
        unlink(w->tmp);
        return -1;
    }
    return 0;
}

int eom_csv_writer_open(eom_csv_writer **out, const char *path, char *err,
                        size_t errlen)
{
    eom_csv_writer *w = calloc(1, sizeof *w);
    struct stat st, lst;
    int mode = -1;
    *out = NULL;
    if (!w) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    if (!path) {
        w->f = stdout;
        w->where = dup_str("standard output");
        if (!w->where) {
            free_writer(w);
            snprintf(err, errlen, "out of memory");
            return -1;
        }
        *out = w;
        return 0;
    }
    w->owned = 1;
    w->where = concat("'", path);
    if (w->where) {
        char *q = concat(w->where, "'");
        free(w->where);
        w->where = q;
    }
    if (!w->where) {
        free_writer(w);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        if (S_ISDIR(st.st_mode)) {
            snprintf(err, errlen, "cannot open '%s' for writing: %s", path,
                     strerror(EISDIR));
            free_writer(w);
            return -1;
        }
        /* a device or a FIFO: nothing to replace, write to it */
        w->f = fopen(path, "w");
        if (!w->f) {
            snprintf(err, errlen, "cannot open '%s' for writing: %s", path,
                     strerror(errno));
            free_writer(w);
            return -1;
        }
        *out = w;
        return 0;
    }
    if (lstat(path, &lst) == 0 && S_ISLNK(lst.st_mode) &&
        stat(path, &st) == 0) {
        w->target = realpath(path, NULL); /* the file the link names */
    } else {
        w->target = dup_str(path);
    }
    if (!w->target) {
        snprintf(err, errlen, "cannot open '%s' for writing: %s", path,
                 strerror(errno ? errno : ENOMEM));
        free_writer(w);
        return -1;
    }
    if (stat(w->target, &st) == 0)
        mode = (int)(st.st_mode & 0777); /* the file keeps its permissions */
    if (open_tmp(w, mode, path, err, errlen) != 0) {
        free_writer(w);
        return -1;
    }
    *out = w;
    return 0;
}

int eom_csv_writer_open_text(eom_csv_writer **out, const char *path,
                             char *err, size_t errlen)
{
    eom_csv_writer *w;
    struct stat lst;
    int mode = -1;
    *out = NULL;
    if (!path) {
        snprintf(err, errlen, "eom_csv_writer_open_text: the path is NULL");
        return -1;
    }
    if (lstat(path, &lst) == 0) {
        if (S_ISREG(lst.st_mode))
            mode = (int)(lst.st_mode & 0777); /* keeps its permissions */
        else if (!S_ISLNK(lst.st_mode)) {
            /* a FIFO would hang the writer, a device is nothing to
             * replace */
            snprintf(err, errlen, "cannot write '%s': it exists and is not "
                     "a regular file", path);
            return -1;
        }
    }
    w = calloc(1, sizeof *w);
    if (!w || !(w->target = dup_str(path)) ||
        !(w->where = concat("'", path))) {
        if (w)
            free_writer(w);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    w->owned = 1;
    w->text = 1;
    {
        char *q = concat(w->where, "'");
        free(w->where);
        w->where = q;
    }
    if (!w->where) {
        free_writer(w);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    if (open_tmp(w, mode, path, err, errlen) != 0) {
        free_writer(w);
        return -1;
    }
    *out = w;
    return 0;
}

FILE *eom_csv_writer_stream(eom_csv_writer *w) { return w ? w->f : NULL; }

int eom_csv_writer_header(eom_csv_writer *w, char *const *names, int count,
                          char *err, size_t errlen)
{
    int i;
    errno = 0;
    for (i = 0; i < count; i++) {
        if (i > 0)
            putc(',', w->f);
        fputs(names[i], w->f);
    }
    putc('\n', w->f);
    return ferror(w->f) ? write_fail(w, errno, err, errlen) : 0;
}

int eom_csv_writer_row(eom_csv_writer *w, const double *v, int count, char *err,
                       size_t errlen)
{
    char num[32];
    int i;
    errno = 0;
    for (i = 0; i < count; i++) {
        eom_numtext_format(num, sizeof num, v[i]);
        if (i > 0)
            putc(',', w->f);
        fputs(num, w->f);
    }
    putc('\n', w->f);
    return ferror(w->f) ? write_fail(w, errno, err, errlen) : 0;
}

int eom_csv_writer_flush(eom_csv_writer *w, char *err, size_t errlen)
{
    errno = 0;
    if (fflush(w->f) != 0 || ferror(w->f))
        return write_fail(w, errno, err, errlen);
    return 0;
}

FILE *csv_writer_file(eom_csv_writer *w) { return w->f; }

void csv_writer_mark_failed(eom_csv_writer *w)
{
    if (w)
        w->failed = 1;
}

/* Close w's file; then rename its temporary file onto the target (keep
 * 1) or to TARGET.partial (keep 0). 0, or -1 with a message (a message
 * that names the partial file when one is kept). */
static int finish(eom_csv_writer **wp, int keep, char *err, size_t errlen)
{
    eom_csv_writer *w = *wp;
    char first[1024] = "";
    int rc = 0;
    rc = eom_csv_writer_flush(w, first, sizeof first);
    if (w->owned) {
        errno = 0;
        if (rc == 0 && w->tmp && fsync(fileno(w->f)) != 0 && errno != EINVAL &&
            errno != EROFS)
            rc = write_fail(w, errno, first, sizeof first);
        errno = 0;
        if (fclose(w->f) != 0 && rc == 0)
            rc = write_fail(w, errno, first, sizeof first);
    }
    if (rc != 0)
        keep = 0;
    if (w->tmp && keep) {
        if (rename(w->tmp, w->target) != 0) {
            snprintf(err, errlen, "cannot put the output in place as %s: %s "
                     "(the rows are in '%s')", w->where, strerror(errno),
                     w->tmp);
            rc = -1;
        }
    } else if (w->tmp && w->text) {
        /* a plot script or its data: nothing worth keeping half-written */
        unlink(w->tmp);
        if (rc != 0)
            snprintf(err, errlen, "%s; %s is unchanged", first, w->where);
        else
            snprintf(err, errlen, "the output was discarded: %s is "
                     "unchanged", w->where);
        rc = -1;
    } else if (w->tmp) {
        char *partial = concat(w->target, ".partial");
        const char *kept = w->tmp;
        if (partial && rename(w->tmp, partial) == 0)
            kept = partial;
        if (rc != 0)
            snprintf(err, errlen, "%s; %s is unchanged, the rows written "
                     "are in '%s'", first, w->where, kept);
        else
            snprintf(err, errlen, "the output is incomplete: %s is "
                     "unchanged, the rows written are in '%s'", w->where,
                     kept);
        free(partial);
        rc = -1;
    } else if (rc != 0) {
        snprintf(err, errlen, "%s", first);
    }
    free_writer(w);
    *wp = NULL;
    return rc;
}

int eom_csv_writer_close(eom_csv_writer **w, char *err, size_t errlen)
{
    if (!w || !*w)
        return 0;
    return finish(w, !(*w)->failed, err, errlen);
}

int eom_csv_writer_discard(eom_csv_writer **w, char *err, size_t errlen)
{
    if (!w || !*w)
        return 0;
    return finish(w, 0, err, errlen);
}
