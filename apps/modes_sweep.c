/* modes_sweep.c - eom-run --modes --sweep (see modes_sweep.h). */
#define _POSIX_C_SOURCE 200809L /* strdup */
#include "modes_sweep.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom/run.h"
#include "eom/steady.h"

#define MAX_COUNT 1000000

/* Copy text[0 .. len) into buf (size size); -1 if it does not fit. */
static int piece(char *buf, size_t size, const char *text, size_t len)
{
    if (len >= size)
        return -1;
    memcpy(buf, text, len);
    buf[len] = '\0';
    return 0;
}

int modes_sweep_parse(const char *arg, modes_sweep *sw, char *err,
                      size_t errlen)
{
    const char *eq = strchr(arg, '='), *c1, *c2;
    char lo[64], hi[64];
    long count;
    int rc;
    memset(sw, 0, sizeof *sw);
    sw->arg = arg;
    if (!eq || eq == arg) {
        snprintf(err, errlen, "--sweep '%s': expected NAME=LO:HI:N (a "
                 "parameter, its first and last value and the number of "
                 "values, for example v=0:10:201)", arg);
        return -1;
    }
    c1 = strchr(eq + 1, ':');
    c2 = c1 ? strchr(c1 + 1, ':') : NULL;
    if (!c1 || !c2 || strchr(c2 + 1, ':')) {
        snprintf(err, errlen, "--sweep '%s': expected NAME=LO:HI:N with "
                 "three fields after '=', separated by ':'", arg);
        return -1;
    }
    if (piece(sw->name, sizeof sw->name, arg, (size_t)(eq - arg)) ||
        piece(lo, sizeof lo, eq + 1, (size_t)(c1 - eq - 1)) ||
        piece(hi, sizeof hi, c1 + 1, (size_t)(c2 - c1 - 1))) {
        snprintf(err, errlen, "--sweep '%s': a field is too long", arg);
        return -1;
    }
    if ((rc = eom_numtext_parse_double(lo, &sw->lo)) != EOM_NUMTEXT_OK) {
        snprintf(err, errlen, "--sweep '%s': LO '%s' %s", arg, lo,
                 eom_numtext_error(rc));
        return -1;
    }
    if ((rc = eom_numtext_parse_double(hi, &sw->hi)) != EOM_NUMTEXT_OK) {
        snprintf(err, errlen, "--sweep '%s': HI '%s' %s", arg, hi,
                 eom_numtext_error(rc));
        return -1;
    }
    if ((rc = eom_numtext_parse_long(c2 + 1, &count)) != EOM_NUMTEXT_OK) {
        snprintf(err, errlen, "--sweep '%s': N '%s' %s", arg, c2 + 1,
                 eom_numtext_error(rc));
        return -1;
    }
    if (count < 2 || count > MAX_COUNT) {
        snprintf(err, errlen, "--sweep '%s': N must be 2 to %d", arg,
                 MAX_COUNT);
        return -1;
    }
    if (sw->lo == sw->hi) {
        snprintf(err, errlen, "--sweep '%s': LO and HI are the same", arg);
        return -1;
    }
    sw->count = (int)count;
    return 0;
}

static double value_at(const modes_sweep *sw, int i)
{
    if (i == sw->count - 1)
        return sw->hi;
    /* weights of the ends, so that round steps print round */
    return (sw->lo * (double)(sw->count - 1 - i) + sw->hi * (double)i) /
           (double)(sw->count - 1);
}

/* Set the parameter to value i, take the start and linearize: into lin.
 * Returns 0, or 1 after a message. */
static int point(eom_system *s, int k, const modes_sweep *sw, int i,
                 modes_start_fn start, void *user, double *x,
                 const int *keep, int nkeep, const char *label,
                 eom_steady_linear *lin)
{
    const double v = value_at(sw, i);
    if (eom_set_param(s, k, v) != EOM_OK) {
        fprintf(stderr, "eom-run: %s: --sweep %s = %g: %s\n", label,
                sw->name, v, eom_system_errmsg(s));
        return 1;
    }
    if (start(user, s, x) != 0)
        return 1;
    if (eom_linearize_steady(s, 0.0, x, keep, nkeep, lin) != EOM_OK) {
        fprintf(stderr, "eom-run: %s: --sweep at %s = %g: cannot "
                "linearize about the start state: %s\n", label, sw->name, v,
                eom_system_errmsg(s));
        return 1;
    }
    return 0;
}

/* Order the eigenvalues re, im (nr) of one row to follow prev (nr, the
 * previous row in column order): the closest pair first. out receives
 * them in column order; used is nr scratch flags. */
static void follow(int nr, const double *pre, const double *pim,
                   const double *re, const double *im, double *ore,
                   double *oim, unsigned char *used)
{
    unsigned char *taken = used + nr;
    int step, i, j;
    memset(used, 0, 2 * (size_t)nr);
    for (step = 0; step < nr; step++) {
        double best = INFINITY;
        int bi = -1, bj = -1;
        for (i = 0; i < nr; i++) {
            if (taken[i])
                continue;
            for (j = 0; j < nr; j++) {
                double d;
                if (used[j])
                    continue;
                d = hypot(re[j] - pre[i], im[j] - pim[i]);
                if (bi < 0 || d < best) {
                    best = d;
                    bi = i;
                    bj = j;
                }
            }
        }
        taken[bi] = 1;
        used[bj] = 1;
        ore[bi] = re[bj];
        oim[bi] = im[bj];
    }
}

/* The gnuplot title text of s (single quotes doubled) in quotes. */
static void quoted(FILE *f, const char *s)
{
    fputc('\'', f);
    for (; *s; s++) {
        if (*s == '\'')
            fputc('\'', f);
        fputc(*s, f);
    }
    fputc('\'', f);
}

/* PREFIX-eigenvalues.gp beside the CSV, run by gnuplot: PNG and SVG. */
static int plot(const eom_system *s, int k, const char *csv, int nr,
                const char *label)
{
    eom_plot_place p;
    char err[4096], path[8192], script[2048];
    const char *unit = eom_param_unit(s, k);
    eom_csv_writer *w = NULL;
    FILE *f;
    if (eom_plot_place_of(&p, csv, err, sizeof err) != 0 ||
        eom_plot_place_path(&p, "eigenvalues.gp", path, sizeof path) != 0) {
        fprintf(stderr, "eom-run: %s: plots: %s\n", label,
                err[0] ? err : "file names too long");
        return 1;
    }
    /* created exclusively and put in place whole; a symbolic link at the
     * script's name is replaced, never followed */
    if (eom_csv_writer_open_text(&w, path, err, sizeof err) != 0) {
        fprintf(stderr, "eom-run: %s: plots: %s\n", label, err);
        return 1;
    }
    f = eom_csv_writer_stream(w);
    fprintf(f, "# eigenvalues of %s against %s; rerun with: gnuplot "
               "%s-eigenvalues.gp\n"
               "set datafile separator ','\n"
               "csv = '%s'\n"
               "nr = %d\n"
               "do for [term in 'pngcairo svg'] {\n"
               "  if (term eq 'svg') { set terminal svg size 900,600 "
               "dynamic noenhanced; set output '%s-eigenvalues.svg' }\n"
               "  else { set terminal pngcairo size 900,600 noenhanced; "
               "set output '%s-eigenvalues.png' }\n"
               "  set grid; set key outside right\n"
               "  set xlabel '%s%s%s%s'\n"
               "  set ylabel 'eigenvalue (1/s)'\n"
               "  set title ",
            label, eom_param_name(s, k), p.prefix, p.csv_name, nr, p.prefix,
            p.prefix, eom_param_name(s, k), unit[0] ? " (" : "", unit,
            unit[0] ? ")" : "");
    quoted(f, label);
    fprintf(f, "\n"
               "  set xzeroaxis lt -1\n"
               "  plot for [j=1:nr] csv every ::1 using 1:(column(2*j)) "
               "with points pt 7 ps 0.5 lc rgb '#1f77b4' "
               "title (j == 1 ? 'real part' : ''), \\\n"
               "       for [j=1:nr] csv every ::1 using 1:(column(2*j+1) > "
               "0 ? column(2*j+1) : NaN) with points pt 6 ps 0.5 "
               "lc rgb '#d62728' title (j == 1 ? 'imaginary part (> 0)' "
               ": '')\n"
               "}\n");
    if (eom_csv_writer_close(&w, err, sizeof err) != 0) {
        fprintf(stderr, "eom-run: %s: plots: %s\n", label, err);
        return 1;
    }
    snprintf(script, sizeof script, "%s-eigenvalues.gp", p.prefix);
    if (eom_gnuplot_run(p.dir, script, err, sizeof err) != 0) {
        fprintf(stderr, "eom-run: %s: %s\n", label, err);
        return 1;
    }
    return 0;
}

int modes_sweep_run(eom_system *s, int k, const modes_sweep *sw,
                    modes_start_fn start, void *user, const int *keep,
                    int nkeep, const char *label, const char *out, int plots,
                    int quiet)
{
    const int n = eom_system_ncoords(s), n2 = 2 * n, N = sw->count;
    eom_steady_linear lin;
    double *x = malloc(((size_t)n2 + 1) * sizeof *x);
    double *vals = NULL; /* N rows of nr (re, im) pairs, column order */
    double *ore = NULL;
    int *ukeep = NULL, nu = 0, nr = -1, i, j, status = 1;
    unsigned char *flags = calloc((size_t)n2 + 1, 1);
    eom_csv_writer *w = NULL;
    char **names = NULL, err[4096];
    double *row_out = NULL;
    memset(&lin, 0, sizeof lin);
    if (!x || !flags) {
        fprintf(stderr, "eom-run: out of memory\n");
        goto done;
    }
    if (!keep) {
        /* the union of the states chosen at each value */
        for (i = 0; i < N; i++) {
            if (point(s, k, sw, i, start, user, x, NULL, 0, label, &lin))
                goto done;
            for (j = 0; j < lin.nr; j++)
                flags[lin.kept[j]] = 1;
            eom_steady_linear_free(&lin);
        }
        ukeep = malloc(((size_t)n2 + 1) * sizeof *ukeep);
        if (!ukeep) {
            fprintf(stderr, "eom-run: out of memory\n");
            goto done;
        }
        for (j = 0; j < n2; j++)
            if (flags[j])
                ukeep[nu++] = j;
        keep = ukeep;
        nkeep = nu;
    }
    for (i = 0; i < N; i++) {
        if (point(s, k, sw, i, start, user, x, keep, nkeep, label, &lin))
            goto done;
        if (nr < 0) {
            nr = lin.nr;
            vals = malloc(((size_t)N * 2 * (size_t)nr + 1) * sizeof *vals);
            ore = malloc((4 * (size_t)nr + 1) * sizeof *ore);
            if (!vals || !ore) {
                fprintf(stderr, "eom-run: out of memory\n");
                goto done;
            }
        }
        if (i == 0) {
            memcpy(vals, lin.eig_re, (size_t)nr * sizeof *vals);
            memcpy(vals + nr, lin.eig_im, (size_t)nr * sizeof *vals);
        } else {
            double *prev = vals + (size_t)(i - 1) * 2 * nr;
            double *row = vals + (size_t)i * 2 * nr;
            follow(nr, prev, prev + nr, lin.eig_re, lin.eig_im, row,
                   row + nr, (unsigned char *)ore);
        }
        eom_steady_linear_free(&lin);
    }
    /* through the run layer's writer: OUT.tmp-XXXXXX renamed onto OUT
     * when whole, so a sweep that fails or is killed leaves OUT as it
     * was */
    names = calloc(2 * (size_t)nr + 1, sizeof *names);
    row_out = malloc((2 * (size_t)nr + 1) * sizeof *row_out);
    if (!names || !row_out) {
        fprintf(stderr, "eom-run: out of memory\n");
        goto done;
    }
    names[0] = (char *)(uintptr_t)sw->name; /* read only */
    for (j = 0; j < 2 * nr; j++) {
        char b[32];
        snprintf(b, sizeof b, "%s%d", j % 2 ? "im" : "re", j / 2 + 1);
        if (!(names[1 + j] = strdup(b))) {
            fprintf(stderr, "eom-run: out of memory\n");
            goto done;
        }
    }
    if (eom_csv_writer_open(&w, out, err, sizeof err) != 0 ||
        eom_csv_writer_header(w, names, 2 * nr + 1, err, sizeof err) != 0) {
        fprintf(stderr, "eom-run: %s\n", err);
        goto done;
    }
    for (i = 0; i < N; i++) {
        const double *row = vals + (size_t)i * 2 * nr;
        row_out[0] = value_at(sw, i);
        for (j = 0; j < nr; j++) {
            row_out[1 + 2 * j] = row[j];
            row_out[2 + 2 * j] = row[nr + j];
        }
        for (j = 0; j <= 2 * nr; j++) /* no "-0" in the file */
            row_out[j] = row_out[j] == 0.0 ? 0.0 : row_out[j];
        if (eom_csv_writer_row(w, row_out, 2 * nr + 1, err,
                               sizeof err) != 0) {
            fprintf(stderr, "eom-run: %s\n", err);
            goto done;
        }
    }
    if (eom_csv_writer_close(&w, err, sizeof err) != 0) {
        fprintf(stderr, "eom-run: %s\n", err);
        goto done;
    }
    if (!quiet)
        fprintf(stderr, "eom-run: %s: the eigenvalues of %d states at %d "
                "values of %s written to '%s'\n", label, nr, N, sw->name,
                out);
    if (plots) {
        if (plot(s, k, out, nr, label) != 0)
            goto done;
        if (!quiet)
            fprintf(stderr, "eom-run: %s: plots written beside '%s'\n",
                    label, out);
    }
    status = 0;
done:
    if (w) { /* failed part-way: OUT stays as it was */
        eom_csv_writer_discard(&w, err, sizeof err);
        fprintf(stderr, "eom-run: %s\n", err);
    }
    if (names)
        for (j = 1; j <= 2 * nr; j++)
            free(names[j]);
    free(names);
    free(row_out);
    eom_steady_linear_free(&lin);
    free(x);
    free(vals);
    free(ore);
    free(ukeep);
    free(flags);
    return status;
}
