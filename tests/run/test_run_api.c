/* test_run_api.c - the run layer's public API (eom/run.h) on its own:
 * number text round trips and refusals, the sample grid, the CSV columns
 * of a system, a run of the spring pendulum written by eom_run and read
 * back with eom_csv_table_read, row for row equal to the same RK4 steps
 * taken here with eom_integ_advance and with energies equal to the
 * hand-written T and V, and the errors of the writer and the reader; a
 * model that reads the time checked at the start of a run (t = 0) and
 * in a row (the row's time), whatever time its system was left at; the
 * text writer for plot scripts (eom_csv_writer_open_text). */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "eom/model_file.h"
#include "eom/run.h"

static const char spring[] =
    "param m = 1 [kg]\nparam k = 75 [N/m]\nparam r0 = 1 [m]\n"
    "param g = 9.81 [m/s^2]\ncoord r = 1.1 [m] rate 0.2\n"
    "coord theta = 0.5 [rad]\n"
    "T = 1/2*m*(r_dot^2 + r^2*theta_dot^2)\n"
    "V = 1/2*k*(r - r0)^2 + m*g*(r0 - r*cos(theta))\n";

/* The whole of a small text file, or NULL. */
static char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    char *buf = calloc(4096, 1);
    if (f && buf)
        buf[fread(buf, 1, 4095, f)] = '\0';
    if (f)
        fclose(f);
    if (!f) {
        free(buf);
        return NULL;
    }
    return buf;
}

/* The entries of dir other than . and .. */
static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int n = 0;
    while (d && (e = readdir(d)) != NULL)
        n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    if (d)
        closedir(d);
    return n;
}

static void numbers(void)
{
    char buf[32];
    double v, back;
    long l;
    int k;
    for (k = 0; k < 1000; k++) {
        v = sin(k * 12.9898) * pow(10.0, (k % 41) - 20);
        eom_numtext_format(buf, sizeof buf, v);
        CHECK_INT(eom_numtext_parse_double(buf, &back), EOM_NUMTEXT_OK);
        if (back != v)
            CHECK_FAIL_("%.17g formats as %s", v, buf);
    }
    CHECK_INT(eom_numtext_parse_double("", &v), EOM_NUMTEXT_EMPTY);
    CHECK_INT(eom_numtext_parse_double(" 1", &v), EOM_NUMTEXT_NOT_NUMBER);
    CHECK_INT(eom_numtext_parse_double("1x", &v), EOM_NUMTEXT_TRAILING);
    CHECK_INT(eom_numtext_parse_double("inf", &v), EOM_NUMTEXT_NONFINITE);
    CHECK_INT(eom_numtext_parse_double("1e999", &v), EOM_NUMTEXT_RANGE);
    CHECK_INT(eom_numtext_parse_long("2.5", &l), EOM_NUMTEXT_NOT_INTEGER);
    CHECK_INT(eom_numtext_parse_long("-42", &l), EOM_NUMTEXT_OK);
    CHECK_INT(l, -42);
    CHECK(strlen(eom_numtext_error(EOM_NUMTEXT_TRAILING)) > 0);
}

static void grid(void)
{
    long long K;
    int exact;
    eom_run_grid(1.0, 0.1, &K, &exact);
    CHECK(K == 10 && exact);
    eom_run_grid(1.05, 0.1, &K, &exact);
    CHECK(K == 10 && !exact);
    eom_run_grid(0.0, 0.1, &K, &exact);
    CHECK(K == 0 && exact);
}

/* The run: rows against our own RK4 steps; T and V by hand. */
static void run_spring(const char *dir)
{
    char err[2048], csv[1100];
    eom_model *m = NULL;
    eom_system *s = NULL;
    eom_run_columns *cols = NULL;
    eom_csv_writer *w = NULL;
    eom_csv_table *tab = NULL;
    eom_integ *it = NULL;
    eom_run_opts o;
    double x[4], y[4];
    int i, k, rc;

    CHECK(eom_model_from_string(&m, spring, err, sizeof err) == EOM_OK);
    CHECK(eom_system_new(&s, m, err, sizeof err) == EOM_OK);
    eom_model_free(&m);
    if (!s)
        return;
    CHECK(eom_run_columns_new(&cols, s, 0, err, sizeof err) == 0);
    if (cols) {
        static const char *const want[] = {"t", "r", "theta", "r_dot",
                                           "theta_dot", "T", "V", "E", "W"};
        CHECK_INT(cols->count, 9);
        for (k = 0; k < 9 && k < cols->count; k++)
            CHECK(strcmp(cols->names[k], want[k]) == 0);
    }
    eom_run_columns_free(&cols);

    eom_run_opts_default(&o);
    CHECK(o.t_end == 10.0 && o.sample == 0.01 && o.opts.method == EOM_RK4);
    o.t_end = 0.5;
    o.sample = 0.05;
    o.quiet = 1;
    o.opts.dt = 1e-3;
    snprintf(csv, sizeof csv, "%s/spring.csv", dir);
    CHECK(eom_initial_state(s, x) == EOM_OK);
    CHECK(eom_csv_writer_open(&w, csv, err, sizeof err) == 0);
    CHECK_INT(eom_run(s, x, &o, w), 0);
    CHECK(eom_csv_writer_close(&w, err, sizeof err) == 0);
    if (eom_csv_table_read(&tab, csv, err, sizeof err) != 0) {
        CHECK_FAIL_("%s", err);
        eom_system_free(&s);
        return;
    }
    CHECK_INT(tab->nrows, 11);
    CHECK(eom_integ_new(&it, s, &o.opts, 0.0, x) == EOM_OK);
    for (i = 0; i < tab->nrows; i++) {
        const double t = 0.05 * i;
        if (i > 0)
            CHECK(eom_integ_advance(it, t, x, NULL) == EOM_OK);
        for (k = 0; k < 4; k++)
            y[k] = eom_csv_table_at(tab, i, 1 + k);
        CHECK(eom_csv_table_at(tab, i, 0) == t);
        for (k = 0; k < 4; k++)
            CHECK(y[k] == x[k]); /* the same steps, read back exactly */
        CHECK_NEAR(eom_csv_table_at(tab, i, eom_csv_table_col(tab, "T")),
                   0.5 * (y[2] * y[2] + y[0] * y[0] * y[3] * y[3]), 1e-14);
        CHECK_NEAR(eom_csv_table_at(tab, i, eom_csv_table_col(tab, "V")),
                   0.5 * 75.0 * (y[0] - 1.0) * (y[0] - 1.0) +
                       9.81 * (1.0 - y[0] * cos(y[1])),
                   1e-14);
    }
    eom_integ_free(&it);
    eom_csv_table_free(&tab);

    /* errors: a folder that is not there, a malformed CSV */
    snprintf(csv, sizeof csv, "%s/no/such/dir.csv", dir);
    CHECK(eom_csv_writer_open(&w, csv, err, sizeof err) == -1 && !w);
    CHECK(strstr(err, "dir.csv") != NULL);
    snprintf(csv, sizeof csv, "%s/bad.csv", dir);
    {
        FILE *f = fopen(csv, "w");
        CHECK(f != NULL);
        if (f) {
            fputs("a,b\n1,2\n3\n", f);
            fclose(f);
        }
    }
    rc = eom_csv_table_read(&tab, csv, err, sizeof err);
    CHECK(rc == -1 && !tab);
    CHECK(strstr(err, "line 3") != NULL);
    unlink(csv);
    snprintf(csv, sizeof csv, "%s/spring.csv", dir);
    unlink(csv);
    eom_system_free(&s);
}

/* A bead on a rod turned at w: the constraint th - w t reads the time, and
 * a probe is the time itself. */
static const char rod[] =
    "units off\nparam m = 0.5\nparam w = 2\ncoord r = 1 rate 0.1\n"
    "coord th = 0 rate 2\nT = 1/2*m*(r_dot^2 + r^2*th_dot^2)\n"
    "constraint drive = th - w*t\nprobe clock = t\n";

static void timed_rows(void)
{
    char err[2048];
    eom_model *m = NULL;
    eom_system *s = NULL;
    eom_run_columns *cols = NULL;
    eom_run_opts o;
    eom_run_row_info info;
    double x[4], x0[4], row[16];
    int k;
    CHECK(eom_model_from_string(&m, rod, err, sizeof err) == EOM_OK);
    CHECK(eom_system_new(&s, m, err, sizeof err) == EOM_OK);
    eom_model_free(&m);
    if (!s)
        return;
    eom_run_opts_default(&o);
    /* the start is on the constraint at t = 0, not at the 5 s where the
     * system was left: nothing to project */
    CHECK(eom_initial_state(s, x) == EOM_OK);
    memcpy(x0, x, sizeof x);
    CHECK(eom_set_time(s, 5.0) == EOM_OK);
    CHECK_INT(eom_run_prepare_start(s, x, &o.opts, "test", "rod"), 0);
    for (k = 0; k < 4; k++)
        CHECK(x[k] == x0[k]);
    /* a row at t = 0.5 of the state on the rod then, with the system left
     * at 7 s: residuals and the probe at the row's time */
    CHECK(eom_run_columns_new(&cols, s, 0, err, sizeof err) == 0);
    if (cols && cols->count <= 16) {
        x[1] = 2.0 * 0.5;
        CHECK(eom_set_time(s, 7.0) == EOM_OK);
        CHECK_INT(eom_run_columns_fill(cols, s, 0.5, x, 0.0, row, &info),
                  EOM_OK);
        /* t, r, th, r_dot, th_dot, T, V, E, W, phi1, phidot1, clock */
        CHECK_INT(cols->count, 12);
        CHECK(strcmp(cols->names[11], "clock") == 0);
        CHECK_NEAR(row[9], 0.0, 1e-15);
        CHECK_NEAR(row[10], 0.0, 1e-15);
        CHECK_NEAR(row[11], 0.5, 1e-15);
    }
    eom_run_columns_free(&cols);
    eom_system_free(&s);
}

/* eom_run_judge: each measure against its threshold (docs/run.md, "The
 * verdict"): 1000 x max(rtol, tol_reachable) within [1e-8, 1e-2], the
 * residuals also against atol, any branch switch. */
static void verdict(void)
{
    eom_opts o;
    eom_stats st;
    eom_run_measures m = {1e-9, 1e-13, 1e-13};
    eom_run_verdict v;
    eom_opts_default(&o);
    o.rtol = 1e-8;
    o.atol = 1e-10;
    memset(&st, 0, sizeof st);
    eom_run_judge(&o, &st, &m, &v);
    CHECK_INT(v.healthy, 1);
    CHECK(v.measure == NULL);
    CHECK_NEAR(v.energy_threshold, 1e-5, 1e-20);
    CHECK_NEAR(v.residual_threshold, 1e-5, 1e-20);
    m.drift_rel = 2e-5;
    eom_run_judge(&o, &st, &m, &v);
    CHECK_INT(v.healthy, 0);
    CHECK(v.measure && strcmp(v.measure, "relative energy drift") == 0);
    CHECK(strstr(v.text, "relative energy drift 2e-05 exceeds 1e-05") != NULL);
    /* a long run: 10 x the tolerance for each step */
    st.steps = 5000;
    eom_run_judge(&o, &st, &m, &v);
    CHECK_INT(v.healthy, 1);
    CHECK_NEAR(v.energy_threshold, 5e-4, 1e-18);
    m.drift_rel = 6e-4;
    eom_run_judge(&o, &st, &m, &v);
    CHECK_INT(v.healthy, 0);
    CHECK(strstr(v.text, "for each of its 5000 steps") != NULL);
    st.steps = 0;
    m.drift_rel = 2e-5;
    /* a method held to a looser tolerance is judged against it */
    st.tol_reachable = 1e-7;
    eom_run_judge(&o, &st, &m, &v);
    CHECK_INT(v.healthy, 1);
    CHECK_NEAR(v.tol, 1e-7, 1e-22);
    /* the floor and the cap */
    st.tol_reachable = 0.0;
    o.rtol = 1e-15;
    m.drift_rel = 5e-9;
    eom_run_judge(&o, &st, &m, &v);
    CHECK_INT(v.healthy, 1);
    o.rtol = 1e-3;
    m.drift_rel = 0.02;
    eom_run_judge(&o, &st, &m, &v);
    CHECK_INT(v.healthy, 0);
    CHECK_NEAR(v.threshold, 1e-2, 1e-17);
    /* residuals: atol counts for them, not for the energy */
    o.rtol = 1e-8;
    o.atol = 1e-6;
    m.drift_rel = NAN; /* not measured: not judged */
    m.phi_max = 5e-4;
    eom_run_judge(&o, &st, &m, &v);
    CHECK_INT(v.healthy, 1);
    m.phi_max = 2e-3;
    eom_run_judge(&o, &st, &m, &v);
    CHECK(v.measure && strcmp(v.measure,
                              "constraint residual max |phi|") == 0);
    m.phi_max = 0.0;
    m.phidot_max = 2e-3;
    eom_run_judge(&o, &st, &m, &v);
    CHECK(v.measure && strncmp(v.measure, "velocity", 8) == 0);
    /* a branch switch fails whatever else holds */
    m.phidot_max = 0.0;
    st.branch_switches = 1;
    st.first_branch_switch = 0.5;
    eom_run_judge(&o, &st, &m, &v);
    CHECK_INT(v.healthy, 0);
    CHECK(strstr(v.text, "branch switches 1 exceeds 0 (the first at t = "
                         "0.5") != NULL);
    /* no integrator: nothing counted */
    eom_run_judge(&o, NULL, &m, &v);
    CHECK_INT(v.healthy, 1);
}

/* The text writer (eom_csv_writer_open_text): a new file, an existing
 * one replaced with its permissions kept, a discarded one left as it was
 * with no PATH.partial and no temporary, a link replaced and its target
 * untouched, a folder and NULL refused. */
static void text_writer(const char *dir)
{
    char path[256], link[256], partial[300], msg[512], *text;
    eom_csv_writer *w = NULL;
    struct stat st;
    snprintf(path, sizeof path, "%s/script.gp", dir);
    snprintf(link, sizeof link, "%s/link.gp", dir);
    snprintf(partial, sizeof partial, "%s.partial", path);
    CHECK(eom_csv_writer_open_text(&w, path, msg, sizeof msg) == 0);
    CHECK(access(path, F_OK) != 0); /* nothing at PATH until the close */
    fprintf(eom_csv_writer_stream(w), "first %d\n", 1);
    CHECK(eom_csv_writer_close(&w, msg, sizeof msg) == 0 && w == NULL);
    text = read_text(path);
    CHECK(text && strcmp(text, "first 1\n") == 0);
    free(text);
    CHECK(chmod(path, 0640) == 0);
    CHECK(eom_csv_writer_open_text(&w, path, msg, sizeof msg) == 0);
    fputs("second\n", eom_csv_writer_stream(w));
    CHECK(eom_csv_writer_close(&w, msg, sizeof msg) == 0);
    text = read_text(path);
    CHECK(text && strcmp(text, "second\n") == 0);
    free(text);
    CHECK(stat(path, &st) == 0 && (st.st_mode & 0777) == 0640);
    /* discarded: PATH as it was, nothing else left */
    CHECK(eom_csv_writer_open_text(&w, path, msg, sizeof msg) == 0);
    fputs("never\n", eom_csv_writer_stream(w));
    CHECK(eom_csv_writer_discard(&w, msg, sizeof msg) == -1 && w == NULL);
    CHECK(strstr(msg, "is unchanged") != NULL);
    text = read_text(path);
    CHECK(text && strcmp(text, "second\n") == 0);
    free(text);
    CHECK(access(partial, F_OK) != 0);
    CHECK(count_entries(dir) == 1);
    /* a link: replaced by the file, the file it named untouched */
    CHECK(symlink(path, link) == 0);
    CHECK(eom_csv_writer_open_text(&w, link, msg, sizeof msg) == 0);
    fputs("through\n", eom_csv_writer_stream(w));
    CHECK(eom_csv_writer_close(&w, msg, sizeof msg) == 0);
    CHECK(lstat(link, &st) == 0 && S_ISREG(st.st_mode));
    text = read_text(path);
    CHECK(text && strcmp(text, "second\n") == 0);
    free(text);
    /* not files */
    CHECK(eom_csv_writer_open_text(&w, dir, msg, sizeof msg) == -1 &&
          w == NULL);
    CHECK(strstr(msg, "not a regular file") != NULL);
    CHECK(eom_csv_writer_open_text(&w, NULL, msg, sizeof msg) == -1);
    CHECK(eom_csv_writer_stream(NULL) == NULL);
    CHECK(count_entries(dir) == 2);
    unlink(link);
    unlink(path);
}

int main(void)
{
    char dir[] = "/tmp/test_run_api.XXXXXX";
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return EXIT_FAILURE;
    }
    numbers();
    grid();
    run_spring(dir);
    timed_rows();
    verdict();
    text_writer(dir);
    rmdir(dir);
    CHECK_DONE();
}
