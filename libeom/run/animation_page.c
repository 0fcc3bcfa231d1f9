/* animation_page.c - the animation page of a run (eom_run_animation in
 * eom/run.h; docs/run.md, "The animation page").
 *
 * The rows of the run's CSV are read back, thinned to the frame budget,
 * and the model's drawings evaluated at each kept row (a clone of the
 * system replays the drawings' tape; nothing else is recomputed). The
 * page is the template animation_page.html (embedded at build time, with
 * three.js when it was found: animation_embed.py) with its markers
 * replaced by the title, the data as one JSON object and, for a spatial
 * model, three.js and its licence. It is written through the CSV writer,
 * so it replaces an older page atomically and never follows a link. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "animation_embed.h"
#include "csv_writer_internal.h"
#include "eom/drawing.h"
#include "eom/run.h"

/* The frame budget (docs/run.md): at most this many frames, and at most
 * ANIM_VALUES drawn values in all frames together. */
#define ANIM_FRAMES 2000
#define ANIM_VALUES 300000

/* The rows kept for nrows rows: every stride-th from the first, and the
 * last. */
static long frames_for(long nrows, int nv, long *stride)
{
    long budget = ANIM_VALUES / (nv > 0 ? nv : 1), n;
    if (budget > ANIM_FRAMES)
        budget = ANIM_FRAMES;
    if (budget < 2)
        budget = 2;
    /* keep = ceil(nrows / stride) + (last not on the stride) <= budget */
    *stride = 1;
    while ((n = (nrows - 1) / *stride + 1 +
                ((nrows - 1) % *stride != 0)) > budget)
        (*stride)++;
    return n;
}

static long row_of(long f, long nframes, long stride, long nrows)
{
    return f == nframes - 1 ? nrows - 1 : f * stride;
}

/* s as a JSON string, with "</" written "<\/" so that nothing closes the
 * script element. */
static void json_str(FILE *f, const char *s)
{
    putc('"', f);
    for (; *s; s++) {
        const unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else if (c == '/' && s[-1] == '<')
            fputs("\\/", f);
        else
            putc(c, f);
    }
    putc('"', f);
}

/* s as HTML text. */
static void html_str(FILE *f, const char *s)
{
    for (; *s; s++)
        switch (*s) {
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '&': fputs("&amp;", f); break;
        case '"': fputs("&quot;", f); break;
        default: putc(*s, f);
        }
}

static void num(FILE *f, double v)
{
    /* 7 digits: far below a pixel, and a page a third the size of
     * 17 */
    if (isfinite(v))
        fprintf(f, "%.7g", v);
    else
        fputs("null", f);
}

/* Planar: only flat kinds, every z 0 and every normal along z. */
static int is_planar(const eom_system *s, const double *v, long nframes,
                     int nv)
{
    long f;
    int k, j;
    for (k = 0; k < eom_system_ndrawings(s); k++) {
        eom_drawing d;
        eom_drawing_get(s, k, &d);
        if (d.kind != EOM_DRAW_POINT && d.kind != EOM_DRAW_SEGMENT &&
            d.kind != EOM_DRAW_POLYLINE && d.kind != EOM_DRAW_CIRCLE &&
            d.kind != EOM_DRAW_DISK)
            return 0;
        for (f = 0; f < nframes; f++) {
            const double *x = v + f * nv + d.offset;
            if (d.kind == EOM_DRAW_CIRCLE || d.kind == EOM_DRAW_DISK) {
                if (x[2] != 0.0 || x[4] != 0.0 || x[5] != 0.0)
                    return 0;
                continue;
            }
            for (j = 2; j < d.count; j += 3)
                if (x[j] != 0.0)
                    return 0;
        }
    }
    return 1;
}

/* The JSON object the page reads (const D). */
static void write_data(FILE *f, const eom_system *s, const eom_csv_table *t,
                       const double *v, long nframes, long stride, int nv,
                       int planar, const char *title)
{
    static const char *const energies[] = {"T", "V", "E"};
    static const unsigned colours[] = {0x1f77b4, 0xff7f0e, 0x333333};
    const int tc = eom_csv_table_col(t, "t");
    char note[512];
    long fr;
    int k, first = 1;
    fputs("{\"title\": ", f);
    json_str(f, title);
    snprintf(note, sizeof note,
             "%ld frames of the CSV's %d rows (%s). %s", nframes, t->nrows,
             stride == 1 ? "every row"
                         : "every few rows and the last: the frame budget",
             planar ? "The x-y plane, y up."
                    : "z is up: drag to turn the view, the wheel zooms.");
    fputs(",\n\"note\": ", f);
    json_str(f, note);
    fprintf(f, ",\n\"planar\": %s,\n\"nv\": %d,\n\"t\": [",
            planar ? "true" : "false", nv);
    for (fr = 0; fr < nframes; fr++) {
        if (fr)
            putc(',', f);
        num(f, eom_csv_table_at(t, (int)row_of(fr, nframes, stride, t->nrows),
                                tc));
    }
    fputs("],\n\"draws\": [", f);
    for (k = 0; k < eom_system_ndrawings(s); k++) {
        eom_drawing d;
        eom_drawing_get(s, k, &d);
        fprintf(f, "%s\n{\"name\": ", k ? "," : "");
        json_str(f, d.name);
        fprintf(f, ", \"kind\": \"%s\", \"count\": %d, \"offset\": %d, "
                   "\"rgb\": %u, \"trail\": %s}",
                eom_draw_kind_name(d.kind), d.count, d.offset, d.rgb,
                (d.flags & EOM_DRAW_TRAIL) ? "true" : "false");
    }
    fputs("],\n\"v\": [", f);
    for (fr = 0; fr < (long)nframes * nv; fr++) {
        if (fr)
            putc(',', f);
        if (fr && fr % nv == 0)
            putc('\n', f); /* a line per frame */
        num(f, v[fr]);
    }
    fputs("],\n\"plot\": [", f);
    for (k = 0; k < 3; k++) {
        const int c = eom_csv_table_col(t, energies[k]);
        if (c < 0)
            continue;
        fprintf(f, "%s{\"name\": \"%s\", \"unit\": \"J\", \"rgb\": %u, "
                   "\"v\": [",
                first ? "" : ",\n", energies[k], colours[k]);
        first = 0;
        for (fr = 0; fr < nframes; fr++) {
            if (fr)
                putc(',', f);
            num(f, eom_csv_table_at(
                       t, (int)row_of(fr, nframes, stride, t->nrows), c));
        }
        fputs("]}", f);
    }
    fputs("]}", f);
}

/* The template with its markers filled. */
static void write_page(FILE *f, const eom_system *s, const eom_csv_table *t,
                       const double *v, long nframes, long stride, int nv,
                       int planar, const char *title)
{
    const char *p = eom__anim_template;
    for (;;) {
        const char *mt = strstr(p, "@TITLE@"), *md = strstr(p, "/*@DATA@*/"),
                   *mh = strstr(p, "/*@THREE@*/"), *next = NULL;
        if (mt && (!next || mt < next))
            next = mt;
        if (md && (!next || md < next))
            next = md;
        if (mh && (!next || mh < next))
            next = mh;
        if (!next)
            break;
        fwrite(p, 1, (size_t)(next - p), f);
        if (next == mt) {
            html_str(f, title);
            p = next + strlen("@TITLE@");
        } else if (next == md) {
            write_data(f, s, t, v, nframes, stride, nv, planar, title);
            p = next + strlen("/*@DATA@*/");
        } else {
            if (!planar && eom__anim_three[0]) {
                fprintf(f, "/* three.js %s (https://threejs.org), under its "
                           "licence:\n\n", eom__anim_three_version);
                fputs(eom__anim_three_license, f);
                fputs("*/\n", f);
                fputs(eom__anim_three, f);
                putc('\n', f);
            }
            p = next + strlen("/*@THREE@*/");
        }
    }
    fputs(p, f);
}

int eom_run_animation(const char *label, const eom_system *s,
                      const char *csv_path, char *err, size_t errlen)
{
    eom_plot_place place;
    eom_csv_table *t = NULL;
    eom_system *c = NULL;
    eom_csv_writer *w = NULL;
    double *v = NULL, *x = NULL;
    int *col = NULL;
    char path[8192], msg[1024], title[1200];
    const int nv = eom_system_ndrawing_values(s), n = eom_system_ncoords(s);
    long nframes, stride, fr;
    int i, rc = -1, planar;
    if (eom_system_ndrawings(s) == 0)
        return 0; /* nothing to draw: no page */
    if (eom_plot_place_of(&place, csv_path, err, errlen) != 0)
        return -1;
    if (eom_plot_place_path(&place, "animation.html", path, sizeof path) !=
        0) {
        snprintf(err, errlen, "animation: file names too long");
        return -1;
    }
    if (eom_csv_table_read(&t, csv_path, msg, sizeof msg) != 0) {
        snprintf(err, errlen, "animation: reading '%s': %s", csv_path, msg);
        return -1;
    }
    if (t->nrows < 1 || eom_csv_table_col(t, "t") < 0) {
        snprintf(err, errlen, "animation: '%s' has %s", csv_path,
                 t->nrows < 1 ? "no rows" : "no column t");
        goto done;
    }
    /* the state's columns: q, then the rates */
    col = malloc(2 * (size_t)n * sizeof *col);
    x = malloc(2 * (size_t)n * sizeof *x);
    if (!col || !x) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    for (i = 0; i < 2 * n; i++) {
        char name[1100];
        snprintf(name, sizeof name, "%s%s", eom_coord_name(s, i % n),
                 i < n ? "" : "_dot");
        if ((col[i] = eom_csv_table_col(t, name)) < 0) {
            snprintf(err, errlen, "animation: '%s' has no column %s",
                     csv_path, name);
            goto done;
        }
    }
    nframes = frames_for(t->nrows, nv, &stride);
    v = malloc((size_t)nframes * (size_t)nv * sizeof *v);
    if (!v) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    /* a clone: the drawings' tape replays into the clone's workspace, the
     * caller's system is left as it was */
    if (eom_system_clone(&c, s, msg, sizeof msg) != EOM_OK) {
        snprintf(err, errlen, "animation: %s", msg);
        goto done;
    }
    for (fr = 0; fr < nframes; fr++) {
        const int row = (int)row_of(fr, nframes, stride, t->nrows);
        for (i = 0; i < 2 * n; i++)
            x[i] = eom_csv_table_at(t, row, col[i]);
        if (eom_drawings_at(c, eom_csv_table_at(t, row, eom_csv_table_col(
                                                            t, "t")),
                            x, v + fr * nv) != EOM_OK) {
            snprintf(err, errlen, "animation: the drawings at row %d: %s",
                     row + 1, eom_system_errmsg(c));
            goto done;
        }
    }
    planar = is_planar(s, v, nframes, nv);
    {
        /* the model's name: a path's last part, without ".eom" */
        const char *base = label ? label : place.prefix, *sl;
        size_t len;
        if ((sl = strrchr(base, '/')) != NULL && sl[1])
            base = sl + 1;
        len = strlen(base);
        if (len > 4 && strcmp(base + len - 4, ".eom") == 0)
            len -= 4;
        snprintf(title, sizeof title, "%.*s", (int)(len > 1000 ? 1000 : len),
                 base);
    }
    if (eom_csv_writer_open(&w, path, err, errlen) != 0)
        goto done;
    write_page(csv_writer_file(w), s, t, v, nframes, stride, nv, planar,
               title);
    rc = eom_csv_writer_close(&w, err, errlen) == 0 ? 0 : -1;
    if (rc != 0)
        snprintf(err + strlen(err), errlen - strlen(err), " (animation)");
done:
    eom_csv_writer_discard(&w, msg, sizeof msg);
    eom_system_free(&c);
    eom_csv_table_free(&t);
    free(v);
    free(x);
    free(col);
    return rc;
}
