/* csv_writer.c - writing eom-run's CSV (see eom/run.h). */
#include "eom/run.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


struct eom_csv_writer {
    FILE *f;
    int owned;        /* 1: opened here, fclose at the end */
    char where[4096]; /* "file 'PATH'" or "standard output", for messages */
};

static int write_fail(const eom_csv_writer *w, int errnum, char *err,
                      size_t errlen)
{
    snprintf(err, errlen, "cannot write to %s: %s", w->where,
             errnum ? strerror(errnum) : "write error");
    return -1;
}

int eom_csv_writer_open(eom_csv_writer **out, const char *path, char *err,
                        size_t errlen)
{
    eom_csv_writer *w = calloc(1, sizeof *w);
    *out = NULL;
    if (!w) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    if (path) {
        w->f = fopen(path, "w");
        if (!w->f) {
            snprintf(err, errlen, "cannot open '%s' for writing: %s", path,
                     strerror(errno));
            free(w);
            return -1;
        }
        w->owned = 1;
        snprintf(w->where, sizeof w->where, "'%s'", path);
    } else {
        w->f = stdout;
        snprintf(w->where, sizeof w->where, "standard output");
    }
    *out = w;
    return 0;
}

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

int eom_csv_writer_close(eom_csv_writer **w, char *err, size_t errlen)
{
    int rc;
    if (!w || !*w)
        return 0;
    rc = eom_csv_writer_flush(*w, err, errlen);
    if ((*w)->owned) {
        errno = 0;
        if (fclose((*w)->f) != 0 && rc == 0)
            rc = write_fail(*w, errno, err, errlen);
    }
    free(*w);
    *w = NULL;
    return rc;
}
