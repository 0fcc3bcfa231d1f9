/* animation_page.c - the animation page of a run, or of several runs of
 * one system drawn over each other (eom_run_animation and
 * eom_run_animation_runs in eom/run.h; docs/run.md, "The animation page",
 * and docs/ensembles.md).
 *
 * The rows of each run's CSV are read back, thinned to the frame budget
 * (shared by the runs: one stride for all, from the longest run), and
 * the model's drawings evaluated at each kept row (a clone of the system
 * replays the drawings' tape; nothing else is recomputed). The page is
 * the template animation_page.html (embedded at build time, with three.js
 * when it was found: animation_embed.py) with its markers replaced by the
 * title, the data as one JSON object and, for a spatial model, three.js
 * and its licence. It is written through the CSV writer, so it replaces
 * an older page atomically and never follows a link. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "animation_embed.h"
#include "csv_writer_internal.h"
#include "eom/drawing.h"
#include "eom/run.h"

/* The frame budget (docs/run.md): at most this many frames per run, and
 * at most ANIM_VALUES drawn values in all frames of all runs together. */
#define ANIM_FRAMES 2000
#define ANIM_VALUES 300000

/* The colours of the runs of an ensemble's page, in turn (docs/run.md):
 * ten that stay apart on white. */
static const unsigned run_colours[] = {0x1f77b4, 0xff7f0e, 0x2ca02c,
                                       0xd62728, 0x9467bd, 0x8c564b,
                                       0xe377c2, 0x7f7f7f, 0xbcbd22,
                                       0x17becf};

/* The energies plotted below the drawing (the single run's page: all
 * three; an ensemble's: E of each run). */
static const char *const energies[] = {"T", "V", "E"};
static const unsigned energy_colours[] = {0x1f77b4, 0xff7f0e, 0x333333};

/* One run's frames: its kept rows' times, drawn values and energies. */
typedef struct anim_run {
    long nrows, nframes;
    double *t;     /* [nframes] */
    double *v;     /* [nframes x nv] */
    double *e[3];  /* [nframes] T, V, E, or NULL without the column */
} anim_run;

/* The number of frames for nrows rows at stride: every stride-th row
 * from the first, and the last. */
static long frames_at(long nrows, long stride)
{
    return (nrows - 1) / stride + 1 + ((nrows - 1) % stride != 0);
}

/* The smallest stride that keeps nrows rows within budget frames. */
static long stride_for(long nrows, long budget)
{
    long stride = 1;
    while (frames_at(nrows, stride) > budget)
        stride++;
    return stride;
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

static void nums(FILE *f, const double *v, long n)
{
    long i;
    putc('[', f);
    for (i = 0; i < n; i++) {
        if (i)
            putc(',', f);
        num(f, v[i]);
    }
    putc(']', f);
}

/* Planar: only flat kinds, every z 0 and every normal along z, in every
 * frame of every run. */
static int is_planar(const eom_system *s, const anim_run *runs, int nruns,
                     int nv)
{
    long f;
    int k, j, r;
    for (k = 0; k < eom_system_ndrawings(s); k++) {
        eom_drawing d;
        eom_drawing_get(s, k, &d);
        if (d.kind != EOM_DRAW_POINT && d.kind != EOM_DRAW_SEGMENT &&
            d.kind != EOM_DRAW_POLYLINE && d.kind != EOM_DRAW_CIRCLE &&
            d.kind != EOM_DRAW_DISK)
            return 0;
        for (r = 0; r < nruns; r++)
            for (f = 0; f < runs[r].nframes; f++) {
                const double *x = runs[r].v + f * nv + d.offset;
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

/* What the page needs to know of the runs as a whole. */
typedef struct anim_page {
    const eom_system *s;
    const anim_run *runs;
    const char *const *labels; /* [nruns] or NULL (a single run) */
    int nruns, nv, planar, longest; /* longest: the slider's run */
    long stride;
    const char *title;
} anim_page;

/* The JSON object the page reads (const D): the slider's times (the
 * longest run's frames), the drawings, and per run its label, colour,
 * times (an ensemble's page only) and drawn values; the plot's series. */
static void write_data(FILE *f, const anim_page *p)
{
    const anim_run *lr = &p->runs[p->longest];
    const int multi = p->labels != NULL;
    char note[768];
    int k, r, first = 1;
    fputs("{\"title\": ", f);
    json_str(f, p->title);
    if (multi)
        snprintf(note, sizeof note,
                 "%d runs drawn over each other, each in its colour; the "
                 "slider goes through the %ld frames of the longest run's "
                 "%ld rows (%s), each run shown at its last frame at or "
                 "before the slider's time. %s",
                 p->nruns, lr->nframes, lr->nrows,
                 p->stride == 1 ? "every row"
                                : "every few rows and the last: the frame "
                                  "budget, shared by the runs",
                 p->planar ? "The x-y plane, y up."
                           : "z is up: drag to turn the view, the wheel "
                             "zooms.");
    else
        snprintf(note, sizeof note,
                 "%ld frames of the CSV's %ld rows (%s). %s", lr->nframes,
                 lr->nrows,
                 p->stride == 1 ? "every row"
                                : "every few rows and the last: the frame "
                                  "budget",
                 p->planar ? "The x-y plane, y up."
                           : "z is up: drag to turn the view, the wheel "
                             "zooms.");
    fputs(",\n\"note\": ", f);
    json_str(f, note);
    fprintf(f, ",\n\"planar\": %s,\n\"nv\": %d,\n\"t\": ",
            p->planar ? "true" : "false", p->nv);
    nums(f, lr->t, lr->nframes);
    fputs(",\n\"draws\": [", f);
    for (k = 0; k < eom_system_ndrawings(p->s); k++) {
        eom_drawing d;
        eom_drawing_get(p->s, k, &d);
        fprintf(f, "%s\n{\"name\": ", k ? "," : "");
        json_str(f, d.name);
        fprintf(f, ", \"kind\": \"%s\", \"count\": %d, \"offset\": %d, "
                   "\"rgb\": %u, \"trail\": %s}",
                eom_draw_kind_name(d.kind), d.count, d.offset, d.rgb,
                (d.flags & EOM_DRAW_TRAIL) ? "true" : "false");
    }
    fputs("],\n\"runs\": [", f);
    for (r = 0; r < p->nruns; r++) {
        const anim_run *a = &p->runs[r];
        long i;
        fprintf(f, "%s\n{", r ? "," : "");
        if (multi) {
            fputs("\"label\": ", f);
            json_str(f, p->labels[r] ? p->labels[r] : "");
            fprintf(f, ", \"rgb\": %u, \"t\": ",
                    run_colours[r % (int)(sizeof run_colours /
                                          sizeof *run_colours)]);
            nums(f, a->t, a->nframes);
            fputs(", ", f);
        }
        fputs("\"v\": [", f);
        for (i = 0; i < a->nframes * p->nv; i++) {
            if (i)
                putc(',', f);
            if (i && i % p->nv == 0)
                putc('\n', f); /* a line per frame */
            num(f, a->v[i]);
        }
        fputs("]}", f);
    }
    fputs("],\n\"plot\": [", f);
    if (multi) {
        /* E of each run, in the run's colour */
        for (r = 0; r < p->nruns; r++) {
            if (!p->runs[r].e[2])
                continue;
            fprintf(f, "%s{\"name\": \"E\", \"unit\": \"J\", \"run\": %d, "
                       "\"rgb\": %u, \"v\": ",
                    first ? "" : ",\n", r,
                    run_colours[r % (int)(sizeof run_colours /
                                          sizeof *run_colours)]);
            first = 0;
            nums(f, p->runs[r].e[2], p->runs[r].nframes);
            putc('}', f);
        }
    } else {
        for (k = 0; k < 3; k++) {
            if (!lr->e[k])
                continue;
            fprintf(f, "%s{\"name\": \"%s\", \"unit\": \"J\", \"rgb\": %u, "
                       "\"v\": ",
                    first ? "" : ",\n", energies[k], energy_colours[k]);
            first = 0;
            nums(f, lr->e[k], lr->nframes);
            putc('}', f);
        }
    }
    fputs("]}", f);
}

/* The template with its markers filled. */
static void write_page(FILE *f, const anim_page *pg)
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
            html_str(f, pg->title);
            p = next + strlen("@TITLE@");
        } else if (next == md) {
            write_data(f, pg);
            p = next + strlen("/*@DATA@*/");
        } else {
            if (!pg->planar && eom__anim_three[0]) {
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

/* Read csv_path whole into *t and check that it has rows, a column t and
 * every coordinate and rate of s (their columns into col[2n]). */
static int read_table(eom_csv_table **t, const eom_system *s,
                      const char *csv_path, int *col, char *err,
                      size_t errlen)
{
    const int n = eom_system_ncoords(s);
    char msg[1024];
    int i;
    if (eom_csv_table_read(t, csv_path, msg, sizeof msg) != 0) {
        snprintf(err, errlen, "animation: reading '%s': %s", csv_path, msg);
        return -1;
    }
    if ((*t)->nrows < 1 || eom_csv_table_col(*t, "t") < 0) {
        snprintf(err, errlen, "animation: '%s' has %s", csv_path,
                 (*t)->nrows < 1 ? "no rows" : "no column t");
        eom_csv_table_free(t);
        return -1;
    }
    /* the state's columns: q, then the rates */
    for (i = 0; i < 2 * n; i++) {
        char name[1100];
        snprintf(name, sizeof name, "%s%s", eom_coord_name(s, i % n),
                 i < n ? "" : "_dot");
        if ((col[i] = eom_csv_table_col(*t, name)) < 0) {
            snprintf(err, errlen, "animation: '%s' has no column %s",
                     csv_path, name);
            eom_csv_table_free(t);
            return -1;
        }
    }
    return 0;
}

/* Run a's frames from its table at stride: times, the drawings of the
 * clone c at each kept row (x: [2n] scratch), the energies. */
static int fill_run(anim_run *a, eom_system *c, const eom_csv_table *t,
                    const int *col, long stride, int nv, double *x,
                    const char *csv_path, char *err, size_t errlen)
{
    const int n = eom_system_ncoords(c), tc = eom_csv_table_col(t, "t");
    long fr;
    int i, k;
    a->nrows = t->nrows;
    a->nframes = frames_at(t->nrows, stride);
    a->t = malloc((size_t)a->nframes * sizeof *a->t);
    a->v = malloc(((size_t)a->nframes * (size_t)nv + 1) * sizeof *a->v);
    if (!a->t || !a->v) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    for (k = 0; k < 3; k++)
        if (eom_csv_table_col(t, energies[k]) >= 0 &&
            !(a->e[k] = malloc((size_t)a->nframes * sizeof *a->e[k]))) {
            snprintf(err, errlen, "out of memory");
            return -1;
        }
    for (fr = 0; fr < a->nframes; fr++) {
        const int row = (int)row_of(fr, a->nframes, stride, t->nrows);
        a->t[fr] = eom_csv_table_at(t, row, tc);
        for (k = 0; k < 3; k++)
            if (a->e[k])
                a->e[k][fr] = eom_csv_table_at(
                    t, row, eom_csv_table_col(t, energies[k]));
        for (i = 0; i < 2 * n; i++)
            x[i] = eom_csv_table_at(t, row, col[i]);
        if (eom_drawings_at(c, a->t[fr], x, a->v + fr * nv) != EOM_OK) {
            snprintf(err, errlen, "animation: the drawings at row %d of "
                     "'%s': %s", row + 1, csv_path, eom_system_errmsg(c));
            return -1;
        }
    }
    return 0;
}

/* The page of nruns runs (labels NULL: a single run's page) at
 * page_path; title already made. */
static int animation(const char *title, const eom_system *s, int nruns,
                     const char *const *csv_paths,
                     const char *const *labels, const char *page_path,
                     char *err, size_t errlen)
{
    const int nv = eom_system_ndrawing_values(s), n = eom_system_ncoords(s);
    eom_csv_table *t = NULL;
    eom_system *c = NULL;
    eom_csv_writer *w = NULL;
    anim_run *runs = NULL;
    anim_page pg;
    double *x = NULL;
    int *col = NULL;
    char msg[1024];
    long budget, maxrows = 0;
    int r, k, rc = -1;
    memset(&pg, 0, sizeof pg);
    runs = calloc((size_t)nruns, sizeof *runs);
    col = malloc((2 * (size_t)n + 1) * sizeof *col);
    x = malloc((2 * (size_t)n + 1) * sizeof *x);
    if (!runs || !col || !x) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    /* the longest run sets the stride of all (the budget is shared):
     * each table is read twice rather than all held at once */
    for (r = 0; r < nruns; r++) {
        if (read_table(&t, s, csv_paths[r], col, err, errlen) != 0)
            goto done;
        runs[r].nrows = t->nrows;
        if (t->nrows > maxrows) {
            maxrows = t->nrows;
            pg.longest = r;
        }
        if (nruns > 1)
            eom_csv_table_free(&t);
    }
    budget = ANIM_VALUES / ((long)(nv > 0 ? nv : 1) * nruns);
    if (budget > ANIM_FRAMES)
        budget = ANIM_FRAMES;
    if (budget < 2)
        budget = 2;
    pg.stride = stride_for(maxrows, budget);
    /* a clone: the drawings' tape replays into the clone's workspace, the
     * caller's system is left as it was */
    if (eom_system_clone(&c, s, msg, sizeof msg) != EOM_OK) {
        snprintf(err, errlen, "animation: %s", msg);
        goto done;
    }
    for (r = 0; r < nruns; r++) {
        if (!t && read_table(&t, s, csv_paths[r], col, err, errlen) != 0)
            goto done;
        if (fill_run(&runs[r], c, t, col, pg.stride, nv, x, csv_paths[r],
                     err, errlen) != 0)
            goto done;
        eom_csv_table_free(&t);
    }
    pg.s = s;
    pg.runs = runs;
    pg.labels = labels;
    pg.nruns = nruns;
    pg.nv = nv;
    pg.title = title;
    pg.planar = is_planar(s, runs, nruns, nv);
    if (eom_csv_writer_open(&w, page_path, err, errlen) != 0)
        goto done;
    write_page(csv_writer_file(w), &pg);
    rc = eom_csv_writer_close(&w, err, errlen) == 0 ? 0 : -1;
    if (rc != 0)
        snprintf(err + strlen(err), errlen - strlen(err), " (animation)");
done:
    eom_csv_writer_discard(&w, msg, sizeof msg);
    eom_system_free(&c);
    eom_csv_table_free(&t);
    for (r = 0; runs && r < nruns; r++) {
        free(runs[r].t);
        free(runs[r].v);
        for (k = 0; k < 3; k++)
            free(runs[r].e[k]);
    }
    free(runs);
    free(x);
    free(col);
    return rc;
}

/* The model's name for a title: a path's last part, without ".eom". */
static void model_title(char *title, size_t len, const char *label,
                        const char *fallback, const char *suffix)
{
    const char *base = label ? label : fallback, *sl;
    size_t l;
    if ((sl = strrchr(base, '/')) != NULL && sl[1])
        base = sl + 1;
    l = strlen(base);
    if (l > 4 && strcmp(base + l - 4, ".eom") == 0)
        l -= 4;
    snprintf(title, len, "%.*s%s", (int)(l > 1000 ? 1000 : l), base, suffix);
}

int eom_run_animation(const char *label, const eom_system *s,
                      const char *csv_path, char *err, size_t errlen)
{
    eom_plot_place place;
    char path[8192], title[1200];
    if (eom_system_ndrawings(s) == 0)
        return 0; /* nothing to draw: no page */
    if (eom_plot_place_of(&place, csv_path, err, errlen) != 0)
        return -1;
    if (eom_plot_place_path(&place, "animation.html", path, sizeof path) !=
        0) {
        snprintf(err, errlen, "animation: file names too long");
        return -1;
    }
    model_title(title, sizeof title, label, place.prefix, "");
    return animation(title, s, 1, &csv_path, NULL, path, err, errlen);
}

int eom_run_animation_runs(const char *label, const eom_system *s,
                           int nruns, const char *const *csv_paths,
                           const char *const *run_labels,
                           const char *page_path, char *err, size_t errlen)
{
    char title[1200], suffix[64];
    if (!s || !csv_paths || !page_path || nruns < 1) {
        snprintf(err, errlen, "animation: %s",
                 nruns < 1 ? "no run to draw" : "a NULL argument");
        return -1;
    }
    if (eom_system_ndrawings(s) == 0)
        return 0; /* nothing to draw: no page */
    snprintf(suffix, sizeof suffix, ": %d run%s", nruns,
             nruns == 1 ? "" : "s");
    model_title(title, sizeof title, label, "runs", suffix);
    if (!run_labels) {
        /* every run gets a label (and a colour): "run K" */
        char **made = calloc((size_t)nruns, sizeof *made);
        int r, rc = -1;
        if (made) {
            for (r = 0; r < nruns; r++)
                if (!(made[r] = malloc(32)))
                    break;
                else
                    snprintf(made[r], 32, "run %d", r);
            if (r == nruns)
                rc = animation(title, s, nruns, csv_paths,
                               (const char *const *)made, page_path, err,
                               errlen);
            else
                snprintf(err, errlen, "out of memory");
            for (r = 0; r < nruns; r++)
                free(made[r]);
            free(made);
        } else {
            snprintf(err, errlen, "out of memory");
        }
        return rc;
    }
    return animation(title, s, nruns, csv_paths, run_labels, page_path,
                     err, errlen);
}
