/* ensemble_summary.c - eom-ensemble's summary: header, rows, the inputs
 * record beside it, the lock, and --resume's checks
 * (ensemble_summary.h). */
#define _GNU_SOURCE /* flock, getline */
#include "ensemble_summary.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "codegen.h" /* tp__sha256_* (libtape/src/sha256.c) */
#include "eom/run.h"

/* ---- header and rows ----------------------------------------------- */

/* A growing string. */
typedef struct text {
    char *s;
    size_t len, cap;
    int oom;
} text;

static void add(text *t, const char *a, const char *b)
{
    const size_t na = strlen(a), nb = b ? strlen(b) : 0;
    if (t->oom)
        return;
    if (t->len + na + nb + 1 > t->cap) {
        size_t cap = 2 * t->cap + na + nb + 256;
        char *p = realloc(t->s, cap);
        if (!p) {
            t->oom = 1;
            return;
        }
        t->s = p;
        t->cap = cap;
    }
    memcpy(t->s + t->len, a, na);
    if (nb)
        memcpy(t->s + t->len + na, b, nb);
    t->len += na + nb;
    t->s[t->len] = '\0';
}

char *ensemble_summary_header(const ensemble_runs *runs, const eom_system *s)
{
    const int n = eom_system_ncoords(s);
    text t = {NULL, 0, 0, 0};
    int i;
    add(&t, "run", NULL);
    for (i = 0; i < runs->ncols; i++)
        add(&t, ",", runs->names[i]);
    add(&t, ",status", NULL);
    for (i = 0; i < n; i++)
        add(&t, ",final_", eom_coord_name(s, i));
    for (i = 0; i < n; i++) {
        add(&t, ",final_", eom_coord_name(s, i));
        add(&t, "_dot", NULL);
    }
    add(&t, ",E0,energy_error,residual,steps,rhs_evals,wall_time,message\n",
        NULL);
    if (t.oom) {
        free(t.s);
        return NULL;
    }
    return t.s;
}

static void put_num(FILE *f, double v)
{
    char buf[32];
    eom_numtext_format(buf, sizeof buf, v);
    fputs(buf, f);
}

/* The message as a quoted CSV field. */
static void put_text(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"')
            fputc('"', f);
        fputc(*s == '\n' ? ' ' : *s, f);
    }
    fputc('"', f);
}

static void summary_row(FILE *f, const ensemble_runs *runs, long i, int n,
                        const run_result *r)
{
    int k;
    fprintf(f, "%ld", i);
    for (k = 0; k < runs->ncols; k++) {
        fputc(',', f);
        put_num(f, runs->v[i * runs->ncols + k]);
    }
    fputs(r->ok == 1 ? ",ok" : r->ok == 2 ? ",unhealthy" : ",failed", f);
    for (k = 0; k < 2 * n; k++) {
        fputc(',', f);
        put_num(f, r->final ? r->final[k] : NAN);
    }
    fputc(',', f);
    put_num(f, r->E0);
    fputc(',', f);
    put_num(f, r->energy_error);
    fputc(',', f);
    put_num(f, r->residual);
    fprintf(f, ",%ld,%ld,", r->steps, r->rhs);
    put_num(f, r->wall);
    fputc(',', f);
    put_text(f, r->msg);
    fputc('\n', f);
}

/* The row is formatted in memory and written with write(2) straight to
 * the file's descriptor (the stream's buffer is empty since
 * ensemble_summary_open flushed it): a failed write is seen at once,
 * and the file is cut back to its last whole row, which a buffered
 * stream, holding the rest of the row, could not promise. */
int ensemble_summary_put(FILE *f, const char *path, const ensemble_runs *runs,
                         long i, int n, const run_result *r)
{
    const int fd = fileno(f);
    const off_t at = lseek(fd, 0, SEEK_CUR);
    char *buf = NULL;
    size_t len = 0, off = 0;
    FILE *m = open_memstream(&buf, &len);
    int errnum = 0;
    if (!m) {
        fprintf(stderr, "eom-ensemble: cannot write '%s': out of memory\n",
                path);
        return -1;
    }
    summary_row(m, runs, i, n, r);
    if (fclose(m) != 0) {
        free(buf);
        fprintf(stderr, "eom-ensemble: cannot write '%s': out of memory\n",
                path);
        return -1;
    }
    while (off < len) {
        const ssize_t k = write(fd, buf + off, len - off);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            errnum = k < 0 ? errno : EIO;
            break;
        }
        off += (size_t)k;
    }
    free(buf);
    if (errnum == 0)
        return 0;
    fprintf(stderr, "eom-ensemble: cannot write '%s': %s (it keeps the "
            "whole rows before run %ld; the runs not started are not "
            "run)\n", path, strerror(errnum), i);
    if (at >= 0 && ftruncate(fd, at) == 0)
        (void)lseek(fd, at, SEEK_SET);
    return -1;
}

int ensemble_summary_close(FILE **fp, const char *path, int speak)
{
    FILE *f = *fp;
    int errnum = 0;
    if (!f)
        return 0;
    *fp = NULL;
    errno = 0;
    if (fflush(f) != 0 ||
        (fsync(fileno(f)) != 0 && errno != EINVAL && errno != EROFS))
        errnum = errno ? errno : EIO;
    errno = 0;
    if (fclose(f) != 0 && errnum == 0)
        errnum = errno ? errno : EIO;
    if (errnum == 0)
        return 0;
    if (speak)
        fprintf(stderr, "eom-ensemble: cannot write '%s': %s\n", path,
                strerror(errnum));
    return -1;
}

/* ---- the inputs record ------------------------------------------------ */

int ensemble_file_digest(const char *path, char out[72], char *err,
                         size_t errlen)
{
    unsigned char buf[65536];
    char hex[65];
    tp_sha256 h;
    struct stat st;
    ssize_t got;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "cannot read '%s': %s", path,
                 fd < 0 ? strerror(errno) : "not a regular file");
        if (fd >= 0)
            close(fd);
        return -1;
    }
    tp__sha256_init(&h);
    while ((got = read(fd, buf, sizeof buf)) != 0) {
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            snprintf(err, errlen, "cannot read '%s': %s", path,
                     strerror(errno));
            close(fd);
            return -1;
        }
        tp__sha256_update(&h, buf, (size_t)got);
    }
    close(fd);
    tp__sha256_hex(&h, hex);
    snprintf(out, 72, "sha256:%s", hex);
    return 0;
}

/* The whole of a small regular file, NUL-terminated, or NULL (errno
 * set). */
static char *slurp(const char *path)
{
    struct stat st;
    char *buf;
    size_t n = 0;
    ssize_t got;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return NULL;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) ||
        st.st_size > (1 << 24)) {
        close(fd);
        errno = EINVAL;
        return NULL;
    }
    buf = malloc((size_t)st.st_size + 1);
    while (buf && n < (size_t)st.st_size &&
           (got = read(fd, buf + n, (size_t)st.st_size - n)) != 0) {
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            free(buf);
            buf = NULL;
            break;
        }
        n += (size_t)got;
    }
    close(fd);
    if (buf)
        buf[n] = '\0';
    return buf;
}

/* The value of key in a record ("KEY VALUE" lines), as a pointer into
 * it and its length, or NULL. */
static const char *value_of(const char *rec, const char *key, size_t *len)
{
    const size_t kl = strlen(key);
    const char *p = rec;
    while (p && *p) {
        const char *end = strchr(p, '\n');
        if (strncmp(p, key, kl) == 0 && p[kl] == ' ') {
            *len = end ? (size_t)(end - p - (ptrdiff_t)kl - 1)
                       : strlen(p + kl + 1);
            return p + kl + 1;
        }
        p = end ? end + 1 : NULL;
    }
    return NULL;
}

/* What differs between the record there (the summary's) and now (this
 * ensemble's), as "KEY (A there, B now), ..." in out; 0 when nothing. */
static int differences(const char *there, const char *now, char *out,
                       size_t len)
{
    const char *p = now;
    size_t k = 0;
    int count = 0;
    out[0] = '\0';
    while (*p) {
        const char *end = strchr(p, '\n'), *sp = strchr(p, ' ');
        size_t vl_now, vl_there = 0;
        const char *v_there;
        char key[64];
        if (!end)
            end = p + strlen(p);
        if (!sp || sp > end || (size_t)(sp - p) >= sizeof key) {
            p = *end ? end + 1 : end;
            continue;
        }
        memcpy(key, p, (size_t)(sp - p));
        key[sp - p] = '\0';
        vl_now = (size_t)(end - sp - 1);
        v_there = value_of(there, key, &vl_there);
        if (!v_there || vl_there != vl_now ||
            memcmp(v_there, sp + 1, vl_now) != 0) {
            int w;
            if (strncmp(sp + 1, "sha256:", 7) == 0 && v_there &&
                strncmp(v_there, "sha256:", 7) == 0)
                w = snprintf(out + k, k < len ? len - k : 0,
                             "%s%s (its contents differ)", count ? ", " : "",
                             key);
            else
                w = snprintf(out + k, k < len ? len - k : 0,
                             "%s%s (%.*s there, %.*s now)", count ? ", " : "",
                             key, v_there ? (int)(vl_there > 200 ? 200 : vl_there) : 4,
                             v_there ? v_there : "none",
                             (int)(vl_now > 200 ? 200 : vl_now), sp + 1);
            k += w > 0 ? (size_t)w : 0;
            count++;
        }
        p = *end ? end + 1 : end;
    }
    if (k >= len && len > 4)
        memcpy(out + len - 4, "...", 4);
    return count;
}

/* Write the record to path (replacing it in one step): 0 or -1 after a
 * message. */
static int write_record(const char *path, const char *rec)
{
    const size_t n = strlen(path);
    char *tmp = malloc(n + 16);
    int fd = -1, ok = 0, tries;
    for (tries = 0; tmp && tries < 100 && fd < 0; tries++) {
        snprintf(tmp, n + 16, "%s.tmp-%d-%d", path, (int)getpid(), tries);
        fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC,
                  0666);
        if (fd < 0 && errno != EEXIST)
            break;
    }
    if (fd >= 0) {
        const size_t len = strlen(rec);
        size_t done = 0;
        ok = 1;
        while (ok && done < len) {
            const ssize_t w = write(fd, rec + done, len - done);
            if (w < 0 && errno == EINTR)
                continue;
            ok = w > 0;
            done += ok ? (size_t)w : 0;
        }
        ok = close(fd) == 0 && ok && rename(tmp, path) == 0;
        if (!ok)
            unlink(tmp);
    }
    if (!ok)
        fprintf(stderr, "eom-ensemble: cannot write '%s': %s\n", path,
                strerror(errno));
    free(tmp);
    return ok ? 0 : -1;
}

/* ---- --resume's checks of the rows ------------------------------------- */

/* s (len characters) is a number as put_num writes it */
static int is_num(const char *s, size_t len)
{
    char buf[64];
    int rc;
    if (len == 0 || len >= sizeof buf)
        return 0;
    memcpy(buf, s, len);
    buf[len] = '\0';
    rc = eom_numtext_parse_double(buf, &(double){0});
    return rc == EOM_NUMTEXT_OK ||
           (rc == EOM_NUMTEXT_NONFINITE &&
            (strcmp(buf, "nan") == 0 || strcmp(buf, "inf") == 0 ||
             strcmp(buf, "-inf") == 0));
}

static int is_count(const char *s, size_t len)
{
    char buf[32];
    long v;
    if (len == 0 || len >= sizeof buf)
        return 0;
    memcpy(buf, s, len);
    buf[len] = '\0';
    return eom_numtext_parse_long(buf, &v) == EOM_NUMTEXT_OK;
}

/* line (len characters, its '\n' removed) is a row of this ensemble:
 * its run number in *run, or -1 with why. */
static int check_row(const char *line, size_t len, const ensemble_runs *runs,
                     int n, const unsigned char *seen, long *run, char *why,
                     size_t wl)
{
    const long nf = 1 + runs->ncols + 1 + 2L * n + 6; /* before message */
    const char *p = line, *end = line + len;
    long f;
    *run = -1;
    for (f = 0; f < nf; f++) {
        const char *c = memchr(p, ',', (size_t)(end - p));
        const size_t fl = c ? (size_t)(c - p) : 0;
        if (!c) {
            snprintf(why, wl, "%ld fields where %ld are due", f + 1, nf + 1);
            return -1;
        }
        if (f == 0) {
            char buf[32];
            long i;
            if (fl == 0 || fl >= sizeof buf) {
                snprintf(why, wl, "no run number");
                return -1;
            }
            memcpy(buf, p, fl);
            buf[fl] = '\0';
            if (eom_numtext_parse_long(buf, &i) != EOM_NUMTEXT_OK || i < 0 ||
                i >= runs->nruns) {
                snprintf(why, wl, "'%s' is not a run of this ensemble (0 to "
                         "%ld)", buf, runs->nruns - 1);
                return -1;
            }
            if (seen[i]) {
                snprintf(why, wl, "run %ld appears twice", i);
                return -1;
            }
            *run = i;
        } else if (f <= runs->ncols) {
            char want[32];
            eom_numtext_format(want, sizeof want,
                               runs->v[*run * runs->ncols + (f - 1)]);
            if (strlen(want) != fl || memcmp(want, p, fl) != 0) {
                snprintf(why, wl, "run %ld has %s = %.*s, this ensemble's "
                         "run %ld has %s", *run, runs->names[f - 1],
                         (int)(fl > 40 ? 40 : fl), p, *run, want);
                return -1;
            }
        } else if (f == runs->ncols + 1) {
            if (!((fl == 2 && memcmp(p, "ok", 2) == 0) ||
                  (fl == 6 && memcmp(p, "failed", 6) == 0) ||
                  (fl == 9 && memcmp(p, "unhealthy", 9) == 0))) {
                snprintf(why, wl, "the status is not ok, unhealthy or "
                         "failed");
                return -1;
            }
        } else if (f == nf - 3 || f == nf - 2) {
            if (!is_count(p, fl)) {
                snprintf(why, wl, "field %ld is not a whole number", f + 1);
                return -1;
            }
        } else if (!is_num(p, fl)) {
            snprintf(why, wl, "field %ld is not a number", f + 1);
            return -1;
        }
        p = c + 1;
    }
    /* the message: one quoted field, inner quotes doubled */
    if (end - p < 2 || p[0] != '"' || end[-1] != '"') {
        snprintf(why, wl, "the last field is not a quoted message");
        return -1;
    }
    for (p++; p < end - 1; p++)
        if (*p == '"' && (p + 1 >= end - 1 || *++p != '"')) {
            snprintf(why, wl, "the message has a stray quote");
            return -1;
        }
    return 0;
}

/* ---- open, lock, resume -------------------------------------------- */

FILE *ensemble_summary_open(const char *path, int resume, const char *head,
                            const char *inputs, const ensemble_runs *runs,
                            int n, unsigned char *skip, long *ndone)
{
    const size_t pl = strlen(path);
    char *rec_path = malloc(pl + sizeof ".inputs"), *line = NULL;
    size_t cap = 0;
    ssize_t len;
    long keep, lineno = 1;
    struct stat st;
    FILE *f = NULL;
    int fd;
    *ndone = 0;
    if (!rec_path) {
        fprintf(stderr, "eom-ensemble: out of memory\n");
        return NULL;
    }
    memcpy(rec_path, path, pl);
    memcpy(rec_path + pl, ".inputs", sizeof ".inputs");
    /* opened without truncating: the lock comes first. The summary is
     * written in place (so that --resume can continue it), so never
     * through a symbolic link planted at its name (O_NOFOLLOW), and a
     * FIFO there must not block the open (O_NONBLOCK; refused below as
     * not a regular file) */
    fd = open(path, O_RDWR | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC,
              0666);
    if (fd < 0 && errno == ELOOP && lstat(path, &st) == 0 &&
        S_ISLNK(st.st_mode)) {
        fprintf(stderr, "eom-ensemble: '%s' is a symbolic link: the summary "
                "is written in place and never through a link; give the "
                "path of the file itself\n", path);
        goto fail;
    }
    if (fd < 0) {
        fprintf(stderr, "eom-ensemble: cannot write '%s': %s\n", path,
                strerror(errno));
        goto fail;
    }
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        if (errno == EWOULDBLOCK)
            fprintf(stderr, "eom-ensemble: '%s' is being written by another "
                    "eom-ensemble (it holds the file's lock): wait for it "
                    "to end, then --resume\n", path);
        else
            fprintf(stderr, "eom-ensemble: cannot lock '%s': %s\n", path,
                    strerror(errno));
        goto fail;
    }
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        fprintf(stderr, "eom-ensemble: '%s' is not a regular file\n", path);
        goto fail;
    }
    if (!resume || st.st_size == 0) {
        if (ftruncate(fd, 0) != 0) {
            fprintf(stderr, "eom-ensemble: cannot write '%s': %s\n", path,
                    strerror(errno));
            goto fail;
        }
        if (write_record(rec_path, inputs) != 0)
            goto fail;
        f = fdopen(fd, "w");
        if (!f)
            goto fail;
        fd = -1;
        /* on the disk now: the rows are written past the stream */
        errno = 0;
        if (fputs(head, f) == EOF || fflush(f) != 0) {
            fprintf(stderr, "eom-ensemble: cannot write '%s': %s\n", path,
                    strerror(errno ? errno : EIO));
            goto fail;
        }
        free(rec_path);
        return f;
    }
    {
        char *there = slurp(rec_path), diff[2048];
        if (!there) {
            fprintf(stderr, "eom-ensemble: --resume: '%s' is missing or "
                    "unreadable (%s): the inputs that made '%s' are not "
                    "known; run without --resume to start over\n", rec_path,
                    strerror(errno), path);
            goto fail;
        }
        /* the keys of now that differ there, else any key only there */
        if (differences(there, inputs, diff, sizeof diff) > 0 ||
            differences(inputs, there, diff, sizeof diff) > 0) {
            fprintf(stderr, "eom-ensemble: --resume: '%s' was made by "
                    "other inputs: %s\n", path, diff);
            free(there);
            goto fail;
        }
        free(there);
    }
    f = fdopen(fd, "r+");
    if (!f)
        goto fail;
    fd = -1;
    if ((len = getline(&line, &cap, f)) <= 0 || strcmp(line, head) != 0) {
        fprintf(stderr, "eom-ensemble: --resume: '%s' is not the summary "
                "of this ensemble (its header differs)\n", path);
        goto fail;
    }
    keep = (long)len;
    while ((len = getline(&line, &cap, f)) > 0) {
        char why[256];
        long i;
        lineno++;
        if (line[len - 1] != '\n')
            break; /* cut short: rewritten below */
        if (check_row(line, (size_t)len - 1, runs, n, skip, &i, why,
                      sizeof why) != 0) {
            fprintf(stderr, "eom-ensemble: --resume: '%s' line %ld is not a "
                    "row of this ensemble: %s\n", path, lineno, why);
            goto fail;
        }
        skip[i] = 1;
        (*ndone)++;
        keep += (long)len;
    }
    if (fflush(f) != 0 || ftruncate(fileno(f), keep) != 0 ||
        fseek(f, keep, SEEK_SET) != 0) {
        fprintf(stderr, "eom-ensemble: --resume: cannot append to '%s': "
                "%s\n", path, strerror(errno));
        goto fail;
    }
    free(line);
    free(rec_path);
    return f;
fail:
    if (f)
        fclose(f);
    if (fd >= 0)
        close(fd);
    free(line);
    free(rec_path);
    return NULL;
}
