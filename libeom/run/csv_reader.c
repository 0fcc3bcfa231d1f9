/* csv_reader.c - reading eom-run's CSV back (see eom/run.h). The file
 * is read whole, then cut in place into lines and fields. */
#include "eom/run.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void eom_csv_table_free(eom_csv_table **t)
{
    int j;
    if (!t || !*t)
        return;
    for (j = 0; (*t)->names && j < (*t)->ncols; j++)
        free((*t)->names[j]);
    free((*t)->names);
    free((*t)->v);
    free(*t);
    *t = NULL;
}

int eom_csv_table_col(const eom_csv_table *t, const char *name)
{
    int j;
    for (j = 0; j < t->ncols; j++)
        if (strcmp(t->names[j], name) == 0)
            return j;
    return -1;
}

double eom_csv_table_at(const eom_csv_table *t, int i, int j)
{
    return t->v[(size_t)i * (size_t)t->ncols + (size_t)j];
}

/* The whole file as a string (NUL-terminated), or NULL with a message. */
static char *slurp(const char *path, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    size_t cap = 0, n = 0, got;
    if (!f) {
        snprintf(err, errlen, "cannot open '%s': %s", path, strerror(errno));
        return NULL;
    }
    do {
        if (cap - n < 65536 + 1) {
            char *p;
            cap = 2 * cap + 65536 + 1;
            p = realloc(buf, cap);
            if (!p) {
                snprintf(err, errlen, "out of memory reading '%s'", path);
                free(buf);
                fclose(f);
                return NULL;
            }
            buf = p;
        }
        got = fread(buf + n, 1, 65536, f);
        n += got;
    } while (got > 0);
    if (ferror(f)) {
        snprintf(err, errlen, "cannot read '%s'", path);
        free(buf);
        fclose(f);
        return NULL;
    }
    fclose(f);
    buf[n] = '\0';
    return buf;
}

/* Cut the line at *p (ended by '\n', "\r\n" or the end of the text) off
 * in place and move *p past it. NULL at the end of the text. */
static char *next_line(char **p)
{
    char *line = *p, *end;
    size_t len;
    if (!*line)
        return NULL;
    end = strchr(line, '\n');
    if (end) {
        *end = '\0';
        *p = end + 1;
    } else {
        *p = line + strlen(line);
    }
    len = strlen(line);
    if (len > 0 && line[len - 1] == '\r')
        line[len - 1] = '\0';
    return line;
}

/* The next field of the line at *p, cut off in place and trimmed of
 * blanks; *p moves past its ',' (NULL after the last field). */
static char *next_field(char **p)
{
    char *f = *p, *comma = strchr(f, ','), *e;
    if (comma) {
        *comma = '\0';
        *p = comma + 1;
    } else {
        *p = NULL;
    }
    while (*f == ' ' || *f == '\t')
        f++;
    e = f + strlen(f);
    while (e > f && (e[-1] == ' ' || e[-1] == '\t'))
        *--e = '\0';
    return f;
}

static int header(eom_csv_table *t, char *line, char *err, size_t errlen)
{
    const char *c;
    char *p = line;
    int j;
    t->ncols = 1;
    for (c = line; *c; c++)
        t->ncols += *c == ',';
    t->names = calloc((size_t)t->ncols, sizeof *t->names);
    if (!t->names)
        goto nomem;
    for (j = 0; j < t->ncols; j++) {
        const char *name = next_field(&p);
        if (!name[0]) {
            snprintf(err, errlen, "line 1: column %d has no name", j + 1);
            return -1;
        }
        t->names[j] = malloc(strlen(name) + 1);
        if (!t->names[j])
            goto nomem;
        strcpy(t->names[j], name);
    }
    return 0;
nomem:
    snprintf(err, errlen, "out of memory");
    return -1;
}

/* Parse one data line (line number lineno) into row. */
static int row(const eom_csv_table *t, char *line, int lineno, double *out,
               char *err, size_t errlen)
{
    char *p = line;
    int j;
    for (j = 0; j < t->ncols; j++) {
        char *f, *end;
        if (!p) {
            snprintf(err, errlen, "line %d: %d fields, the header has %d",
                     lineno, j, t->ncols);
            return -1;
        }
        f = next_field(&p);
        out[j] = strtod(f, &end);
        if (end == f || *end) {
            snprintf(err, errlen, "line %d, column '%s': '%.40s' is not a "
                     "number", lineno, t->names[j], f);
            return -1;
        }
    }
    if (p) {
        snprintf(err, errlen, "line %d: more fields than the header's %d",
                 lineno, t->ncols);
        return -1;
    }
    return 0;
}

int eom_csv_table_read(eom_csv_table **out, const char *path, char *err,
                       size_t errlen)
{
    char *text, *p, *line;
    eom_csv_table *t;
    size_t cap = 0;
    int lineno = 1;
    *out = NULL;
    if (!(text = slurp(path, err, errlen)))
        return -1;
    p = text;
    t = calloc(1, sizeof *t);
    if (!t) {
        snprintf(err, errlen, "out of memory");
        goto fail;
    }
    line = next_line(&p);
    if (!line || !line[0]) {
        snprintf(err, errlen, "'%s' has no header row", path);
        goto fail;
    }
    if (header(t, line, err, errlen) != 0)
        goto fail;
    while ((line = next_line(&p)) != NULL) {
        lineno++;
        if (!line[0] && !*p)
            break; /* a blank last line */
        if (t->nrows == INT_MAX) {
            snprintf(err, errlen, "'%s' has too many rows", path);
            goto fail;
        }
        if ((size_t)t->nrows == cap) {
            double *v;
            cap = cap ? 2 * cap : 256;
            v = realloc(t->v, cap * (size_t)t->ncols * sizeof(double));
            if (!v) {
                snprintf(err, errlen, "out of memory");
                goto fail;
            }
            t->v = v;
        }
        if (row(t, line, lineno, t->v + (size_t)t->nrows * (size_t)t->ncols,
                err, errlen) != 0)
            goto fail;
        t->nrows++;
    }
    free(text);
    *out = t;
    return 0;
fail:
    free(text);
    eom_csv_table_free(&t);
    return -1;
}
