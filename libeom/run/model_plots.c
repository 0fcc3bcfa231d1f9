/* model_plots.c - generic plots of any model's run (eom/run.h). The
 * scripts read the CSV itself; its columns are found by name here and
 * written into the scripts by number, as gnuplot counts them (from 1). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom/run.h"

/* Curves in one panel beyond which the key is left out. */
#define MAX_KEY 12

static void begin(FILE *f, const eom_plot_place *p, const char *name,
                  const char *label, const char *what, const char *size)
{
    fprintf(f, "# %s of %s; rerun with: gnuplot %s-%s.gp\n"
               "set datafile separator ','\n"
               "csv = '%s'\n"
               "do for [term in 'pngcairo svg'] {\n"
               "  if (term eq 'svg') { set terminal svg size %s dynamic "
               "noenhanced; set output '%s-%s.svg' }\n"
               "  else { set terminal pngcairo size %s noenhanced; "
               "set output '%s-%s.png' }\n"
               "  set grid; set xlabel 't (s)'\n",
            what, label, p->prefix, name, p->csv_name, size, p->prefix, name,
            size, p->prefix, name);
}

/* The gnuplot title of a name (single quotes doubled). */
static void title(FILE *f, const char *s)
{
    fputc('\'', f);
    for (; *s; s++) {
        if (*s == '\'')
            fputc('\'', f);
        fputc(*s, f);
    }
    fputc('\'', f);
}

/* Open the script PREFIX-name.gp beside the CSV through a text writer
 * (eom_csv_writer_open_text: created exclusively, put in place whole, a
 * symbolic link at its name replaced rather than followed): the stream,
 * or NULL with a message. */
static FILE *open_script(const eom_plot_place *p, const char *name,
                         eom_csv_writer **w, char *err, size_t errlen)
{
    char path[8192], msg[1024];
    if (eom_plot_place_path(p, name, path, sizeof path - 4) != 0) {
        snprintf(err, errlen, "plots: file names too long");
        return NULL;
    }
    strcat(path, ".gp");
    if (eom_csv_writer_open_text(w, path, msg, sizeof msg) != 0) {
        snprintf(err, errlen, "plots: %s", msg);
        return NULL;
    }
    return eom_csv_writer_stream(*w);
}

/* Put the script in place: 0, or -1 with a message. */
static int close_script(eom_csv_writer **w, char *err, size_t errlen)
{
    char msg[1024];
    if (eom_csv_writer_close(w, msg, sizeof msg) != 0) {
        snprintf(err, errlen, "plots: %s", msg);
        return -1;
    }
    return 0;
}

/* Drop a script left unfinished (its temporary file is removed). */
static void drop_script(eom_csv_writer **w)
{
    char msg[1024];
    (void)eom_csv_writer_discard(w, msg, sizeof msg);
}

/* Coordinates, one panel per distinct unit (at most 4; the rest share the
 * last). */
static int coordinates(const eom_plot_place *p, const char *label,
                       const eom_system *s, const eom_csv_table *tab, char *err,
                       size_t errlen)
{
    const int n = eom_system_ncoords(s), t = eom_csv_table_col(tab, "t") + 1;
    const char *units[4];
    int nu = 0, i, u, *group = calloc((size_t)n + 1, sizeof(int));
    eom_csv_writer *w = NULL;
    FILE *f;
    if (!group) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    for (i = 0; i < n; i++) {
        const char *un = eom_coord_unit(s, i);
        for (u = 0; u < nu && strcmp(units[u], un) != 0; u++)
            ;
        if (u == nu && nu < 4)
            units[nu++] = un;
        group[i] = u < nu ? u : nu - 1;
    }
    if (!(f = open_script(p, "coordinates", &w, err, errlen))) {
        free(group);
        return -1;
    }
    begin(f, p, "coordinates", label, "the coordinates over time",
          nu > 1 ? "900,900" : "900,600");
    fprintf(f, "  set multiplot layout %d,1 title ", nu);
    title(f, label);
    fprintf(f, "\n  set key outside right\n");
    for (u = 0; u < nu; u++) {
        int count = 0, first = 1;
        for (i = 0; i < n; i++)
            count += group[i] == u;
        fprintf(f, "  set ylabel '%s'\n  %s\n  plot ",
                units[u][0] ? units[u] : "(no unit)",
                count > MAX_KEY ? "unset key" : "set key outside right");
        for (i = 0; i < n; i++) {
            if (group[i] != u)
                continue;
            fprintf(f, "%scsv every ::1 using %d:%d with lines title ",
                    first ? "" : ", \\\n       ", t,
                    eom_csv_table_col(tab, eom_coord_name(s, i)) + 1);
            title(f, eom_coord_name(s, i));
            first = 0;
        }
        fprintf(f, "\n");
    }
    fprintf(f, "  unset multiplot\n}\n");
    free(group);
    return close_script(&w, err, errlen);
}

static int energy(const eom_plot_place *p, const char *label,
                  const eom_system *s, const eom_csv_table *tab, char *err,
                  size_t errlen)
{
    const int t = eom_csv_table_col(tab, "t") + 1;
    const int T = eom_csv_table_col(tab, "T") + 1;
    const int V = eom_csv_table_col(tab, "V") + 1;
    const int E = eom_csv_table_col(tab, "E") + 1;
    const int W = eom_csv_table_col(tab, "W") + 1;
    eom_csv_writer *w = NULL;
    FILE *f = open_script(p, "energy", &w, err, errlen);
    if (!f)
        return -1;
    begin(f, p, "energy", label, "energies over time", "900,700");
    fprintf(f, "  set multiplot layout 2,1\n  set key outside right\n"
               "  set ylabel 'energy (J)'\n"
               "  set title 'energies (W: work done by dissipation and "
               "forces)'\n  plot ");
    if (eom_system_has_tv(s))
        fprintf(f, "csv every ::1 using %d:%d with lines title 'T', "
                   "'' every ::1 using %d:%d with lines title 'V', ",
                t, T, t, V);
    fprintf(f, "csv every ::1 using %d:%d with lines title 'E', "
               "'' every ::1 using %d:%d with lines title 'W', "
               "'' every ::1 using %d:($%d+$%d) with lines lw 2 "
               "title 'E + W'\n"
               "  set ylabel 'J'; set title 'drift of E + W from its start'\n"
               "  stats csv every ::1::1 using ($%d+$%d) name 'E0' nooutput\n"
               "  plot csv every ::1 using %d:($%d+$%d-E0_mean) with lines "
               "title 'E + W - E(0)'\n"
               "  unset multiplot\n}\n",
            t, E, t, W, t, E, W, E, W, t, E, W);
    return close_script(&w, err, errlen);
}

static int residuals(const eom_plot_place *p, const char *label,
                     const eom_system *s, const eom_csv_table *tab, char *err,
                     size_t errlen)
{
    const int m = eom_system_nconstraints(s);
    const int t = eom_csv_table_col(tab, "t") + 1;
    eom_csv_writer *w = NULL;
    int k, first = 1;
    FILE *f = open_script(p, "residuals", &w, err, errlen);
    if (!f)
        return -1;
    begin(f, p, "residuals", label, "the constraint residuals", "900,600");
    fprintf(f, "  set logscale y; set format y '%%.0e'\n"
               "  set ylabel '|residual| (0 drawn at 1e-17)'\n"
               "  set title 'constraint residuals: phi (position) and "
               "C qd (velocity)'\n  %s\n  plot ",
            2 * m > MAX_KEY ? "unset key" : "set key outside right");
    for (k = 0; k < m; k++) {
        char *phi = eom_run_constraint_column(s, "phi", k);
        char *phidot = eom_run_constraint_column(s, "phidot", k);
        int c;
        if (!phi || !phidot) {
            free(phi);
            free(phidot);
            drop_script(&w);
            snprintf(err, errlen, "plots: out of memory");
            return -1;
        }
        c = eom_csv_table_col(tab, phi) + 1;
        fprintf(f, "%scsv every ::1 using %d:(abs($%d) > 1e-17 ? abs($%d) "
                   ": 1e-17) with lines title ",
                first ? "" : ", \\\n       ", t, c, c);
        title(f, phi);
        first = 0;
        c = eom_csv_table_col(tab, phidot) + 1;
        fprintf(f, ", \\\n       csv every ::1 using %d:(abs($%d) > 1e-17 ? "
                   "abs($%d) : 1e-17) with lines dt 2 title ",
                t, c, c);
        title(f, phidot);
        free(phi);
        free(phidot);
    }
    fprintf(f, "\n}\n");
    return close_script(&w, err, errlen);
}

/* The multipliers, when the CSV has them (--columns multipliers): the
 * constraint forces, each under its constraint's name. */
static int multipliers(const eom_plot_place *p, const char *label,
                       const eom_system *s, const eom_csv_table *tab,
                       char *err, size_t errlen)
{
    const int m = eom_system_nconstraints(s);
    const int t = eom_csv_table_col(tab, "t") + 1;
    eom_csv_writer *w = NULL;
    int k;
    FILE *f = open_script(p, "multipliers", &w, err, errlen);
    if (!f)
        return -1;
    begin(f, p, "multipliers", label, "the Lagrange multipliers",
          "900,600");
    fprintf(f, "  set title 'Lagrange multipliers (constraint force C^T "
               "lambda)'\n  %s\n  plot ",
            m > MAX_KEY ? "unset key" : "set key outside right");
    for (k = 0; k < m; k++) {
        char *col = eom_run_constraint_column(s, "lambda", k);
        if (!col) {
            drop_script(&w);
            snprintf(err, errlen, "plots: out of memory");
            return -1;
        }
        fprintf(f, "%scsv every ::1 using %d:%d with lines title ",
                k ? ", \\\n       " : "", t,
                eom_csv_table_col(tab, col) + 1);
        title(f, col);
        free(col);
    }
    fprintf(f, "\n}\n");
    return close_script(&w, err, errlen);
}

/* 1 if the CSV holds the multipliers' columns. */
static int has_multipliers(const eom_system *s, const eom_csv_table *tab)
{
    char *col;
    int found;
    if (eom_system_nconstraints(s) == 0)
        return 0;
    col = eom_run_constraint_column(s, "lambda", 0);
    found = col && eom_csv_table_col(tab, col) >= 0;
    free(col);
    return found;
}

static int probes(const eom_plot_place *p, const char *label,
                  const eom_system *s, const eom_csv_table *tab, char *err,
                  size_t errlen)
{
    const int np = eom_system_nprobes(s), t = eom_csv_table_col(tab, "t") + 1;
    eom_csv_writer *w = NULL;
    int k;
    FILE *f = open_script(p, "probes", &w, err, errlen);
    if (!f)
        return -1;
    begin(f, p, "probes", label, "the probes over time", "900,600");
    fprintf(f, "  set title 'probes'\n  %s\n  plot ",
            np > MAX_KEY ? "unset key" : "set key outside right");
    for (k = 0; k < np; k++) {
        fprintf(f, "%scsv every ::1 using %d:%d with lines title ",
                k ? ", \\\n       " : "", t,
                eom_csv_table_col(tab, eom_probe_name(s, k)) + 1);
        title(f, eom_probe_name(s, k));
    }
    fprintf(f, "\n}\n");
    return close_script(&w, err, errlen);
}

int eom_run_plots(const char *label, const eom_system *s,
                  const char *csv_path, char *err, size_t errlen)
{
    const char *names[5];
    eom_plot_place p;
    eom_csv_table *tab = NULL;
    char msg[256], script[2048];
    int k, n = 0, rc = 0;
    if (eom_plot_place_of(&p, csv_path, err, errlen) != 0)
        return -1;
    if (eom_csv_table_read(&tab, csv_path, msg, sizeof msg) != 0) {
        snprintf(err, errlen, "plots: reading '%s': %s", csv_path, msg);
        return -1;
    }
    names[n++] = "coordinates";
    names[n++] = "energy";
    rc = coordinates(&p, label, s, tab, err, errlen) ||
         energy(&p, label, s, tab, err, errlen);
    if (rc == 0 && eom_system_nconstraints(s) > 0) {
        names[n++] = "residuals";
        rc = residuals(&p, label, s, tab, err, errlen);
    }
    if (rc == 0 && has_multipliers(s, tab)) {
        names[n++] = "multipliers";
        rc = multipliers(&p, label, s, tab, err, errlen);
    }
    if (rc == 0 && eom_system_nprobes(s) > 0) {
        names[n++] = "probes";
        rc = probes(&p, label, s, tab, err, errlen);
    }
    eom_csv_table_free(&tab);
    /* before gnuplot, which may be missing: the page needs none */
    if (rc == 0)
        rc = eom_run_animation(label, s, csv_path, err, errlen);
    for (k = 0; k < n && rc == 0; k++) {
        snprintf(script, sizeof script, "%s-%s.gp", p.prefix, names[k]);
        rc = eom_gnuplot_run(p.dir, script, err, errlen);
    }
    return rc ? -1 : 0;
}
