/* test_cli_chains.c - eom-run's chain demos (open-chain, closed-chain)
 * and the options that came with them, seen from outside: --describe,
 * the CSV checked against the chain's geometry and energies computed
 * here from the row's own state, --plots (the files, the animation's
 * data, the errors), --modes against frequencies known in closed form,
 * and the projection of an initial state that is off the constraints.
 *
 * usage: test_cli_chains EOM_RUN CASE
 * Runs are short (tenths of a second of simulated time): the suite also
 * runs under valgrind. No check depends on timing. Without gnuplot on
 * PATH the plots case tests only the errors (it says so on stderr). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "cli_support.h"

static const double pi = 3.14159265358979323846;

/* ---- --describe ------------------------------------------------------- */

/* The line of out whose first word is name, into buf; 0 if found. */
static int find_line(const char *out, const char *name, char *buf,
                     size_t len)
{
    const char *line = out;
    const size_t nl = strlen(name);
    while (line && *line) {
        const char *end = strchr(line, '\n'), *p = line;
        size_t ll = end ? (size_t)(end - line) : strlen(line);
        while (*p == ' ')
            p++;
        if (strncmp(p, name, nl) == 0 && p[nl] == ' ') {
            snprintf(buf, len, "%.*s", (int)ll, line);
            return 0;
        }
        line = end ? end + 1 : NULL;
    }
    return -1;
}

/* The line of name exists and contains each of texts (NULL-ended). */
static void check_line(const char *out, const char *name,
                       const char *const *texts)
{
    char buf[512];
    int k;
    check_count_++;
    if (find_line(out, name, buf, sizeof buf) != 0) {
        CHECK_FAIL_("--describe: no line for %s", name);
        return;
    }
    for (k = 0; texts[k]; k++) {
        check_count_++;
        if (!strstr(buf, texts[k]))
            CHECK_FAIL_("--describe: '%s' missing on the line '%s'",
                        texts[k], buf);
    }
}

/* The second word of the line of name as a number (NaN if missing). */
static double line_value(const char *out, const char *name)
{
    char buf[512];
    const char *p;
    if (find_line(out, name, buf, sizeof buf) != 0)
        return NAN;
    p = buf;
    while (*p == ' ')
        p++;
    p += strlen(name);
    return strtod(p, NULL);
}

static void case_list(void)
{
    const char *args[] = {"--list", NULL};
    result r;
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.out, "\nopen-chain ");
    CHECK_HAS(r.out, "\nclosed-chain ");
    result_free(&r);
}

static void case_describe(void)
{
    const char *open_args[] = {"open-chain", "--describe", NULL};
    const char *closed_args[] = {"closed-chain", "--describe", NULL};
    const char *small_args[] = {"closed-chain", "--set", "links=4", "--set",
                                "modes=1", "--describe", NULL};
    const char *ei_args[] = {"closed-chain", "--set", "EI=1e5", "--set",
                             "EI3=2e5", "--describe", NULL};
    static const char *const closed_angles[5] = {"theta1", "theta2",
                                                 "theta3", "theta4",
                                                 "theta5"};
    static const double paper[5] = {5, 1, 0, 17, 13};
    const char *links3[] = {"3", "integer", NULL};
    const char *links5[] = {"5", "integer", NULL};
    const char *modes2[] = {"2", "integer", NULL};
    const char *modes1[] = {"1", "integer", NULL};
    const char *m_set[] = {"1", "kg", NULL};
    const char *L_set[] = {"10", " m ", NULL};
    const char *EI_open[] = {"4000", "N m^2", NULL};
    const char *EI_closed[] = {"40000", "N m^2", NULL};
    const char *kg[] = {"1", "kg", NULL}, *len[] = {"10", " m ", NULL};
    const char *g0[] = {"0", "m/s^2", NULL}, *g981[] = {"9.81", "m/s^2",
                                                        NULL};
    const char *c0[] = {"0", "N m s/rad", NULL};
    const char *c10[] = {"10", "N m s/rad", NULL};
    const char *D10[] = {"10", " m ", NULL};
    const char *rad[] = {"rad", "rad/s", NULL}, *metre[] = {" m ", "m/s",
                                                           NULL};
    const char *links4[] = {"5 (set: 4)", NULL};
    /* the setting EI is the default of EIJ in the model it builds, so
     * EI1 shows the new default; EI3 is set on top of it */
    const char *ei_all[] = {"40000 (set: 100000)", NULL};
    const char *ei_link[] = {" 100000 ", NULL};
    const char *ei3[] = {"100000 (set: 200000)", NULL};
    char name[32];
    result r;
    int j, i;

    run(&r, open_args);
    CHECK_INT(r.status, 0);
    check_line(r.out, "links", links3);
    check_line(r.out, "modes", modes2);
    check_line(r.out, "m", m_set);
    check_line(r.out, "L", L_set);
    check_line(r.out, "EI", EI_open);
    for (j = 1; j <= 3; j++) {
        snprintf(name, sizeof name, "m%d", j);
        check_line(r.out, name, kg);
        snprintf(name, sizeof name, "L%d", j);
        check_line(r.out, name, len);
        snprintf(name, sizeof name, "EI%d", j);
        check_line(r.out, name, EI_open);
        snprintf(name, sizeof name, "theta%d", j);
        check_line(r.out, name, rad);
        for (i = 1; i <= 2; i++) {
            snprintf(name, sizeof name, "q%d_%d", j, i);
            check_line(r.out, name, metre);
        }
    }
    check_line(r.out, "g", g0);
    check_line(r.out, "c", c0);
    /* the zig-zag start and the spinning, bent last beam */
    CHECK_NEAR(line_value(r.out, "theta1"), pi / 6, 1e-15);
    CHECK_NEAR(line_value(r.out, "theta2"), -pi / 6, 1e-15);
    CHECK_NEAR(line_value(r.out, "theta3"), pi / 6, 1e-15);
    CHECK_NEAR(line_value(r.out, "q3_1"), 0.01, 1e-15);
    CHECK_HAS(r.out, "T3_rigid");
    CHECK_HAS(r.out, "T3_flex");
    CHECK_HAS(r.out, "U3_strain");
    CHECK(find_line(r.out, "D", name, sizeof name) != 0);
    CHECK(find_line(r.out, "theta4", name, sizeof name) != 0);
    result_free(&r);

    run(&r, closed_args);
    CHECK_INT(r.status, 0);
    check_line(r.out, "links", links5);
    check_line(r.out, "modes", modes1);
    check_line(r.out, "EI", EI_closed);
    for (j = 1; j <= 5; j++) {
        snprintf(name, sizeof name, "m%d", j);
        check_line(r.out, name, kg);
        snprintf(name, sizeof name, "L%d", j);
        check_line(r.out, name, len);
        snprintf(name, sizeof name, "EI%d", j);
        check_line(r.out, name, EI_closed);
        snprintf(name, sizeof name, "q%d_1", j);
        check_line(r.out, name, metre);
        check_line(r.out, closed_angles[j - 1], rad);
        CHECK_NEAR(line_value(r.out, closed_angles[j - 1]),
                   paper[j - 1] * pi / 12, 1e-15);
    }
    check_line(r.out, "g", g981);
    check_line(r.out, "c", c10);
    check_line(r.out, "D", D10);
    CHECK(find_line(r.out, "q1_2", name, sizeof name) != 0);
    CHECK_HAS(r.out, "constraints: 2");
    result_free(&r);

    /* a smaller chain: four links of one mode each */
    run(&r, small_args);
    CHECK_INT(r.status, 0);
    check_line(r.out, "links", links4);
    for (j = 1; j <= 4; j++) {
        snprintf(name, sizeof name, "theta%d", j);
        check_line(r.out, name, rad);
        snprintf(name, sizeof name, "q%d_1", j);
        check_line(r.out, name, metre);
        snprintf(name, sizeof name, "EI%d", j);
        check_line(r.out, name, EI_closed);
    }
    CHECK(find_line(r.out, "theta5", name, sizeof name) != 0);
    CHECK(find_line(r.out, "q1_2", name, sizeof name) != 0);
    CHECK(find_line(r.out, "EI5", name, sizeof name) != 0);
    result_free(&r);

    /* EI is the shared default of every EIJ; EI3 is link 3's own */
    run(&r, ei_args);
    CHECK_INT(r.status, 0);
    check_line(r.out, "EI", ei_all);
    check_line(r.out, "EI1", ei_link);
    check_line(r.out, "EI3", ei3);
    check_line(r.out, "EI5", ei_link);
    result_free(&r);
}

/* ---- the CSV ------------------------------------------------------------ */

/* Run (args must write the scratch file out.csv) and parse the CSV. */
static int run_csv(csv *c, const char *const *args, result *r)
{
    char path[300], msg[512];
    char *text;
    scratch(path, sizeof path, "out.csv");
    run(r, args);
    text = read_file(path, NULL);
    memset(c, 0, sizeof *c);
    if (!text) {
        CHECK_FAIL_("no CSV written (status %d):\n%s", r->status, r->err);
        return r->status;
    }
    check_count_++;
    if (csv_parse(text, c, msg, sizeof msg) != 0)
        CHECK_FAIL_("%s", msg);
    free(text);
    unlink(path);
    return r->status;
}

/* The expected header of a chain of N links with K modes each. */
static void chain_header(char *buf, size_t len, int N, int K, int closed)
{
    size_t n = 0;
    int j, i, pass;
#define ADD(...) n += (size_t)snprintf(buf + n, n < len ? len - n : 0, \
                                       __VA_ARGS__)
    ADD("t");
    for (pass = 0; pass < 2; pass++) {
        const char *dot = pass ? "_dot" : "";
        for (j = 1; j <= N; j++)
            ADD(",theta%d%s", j, dot);
        for (j = 1; j <= N; j++)
            for (i = 1; i <= K; i++)
                ADD(",q%d_%d%s", j, i, dot);
    }
    ADD(",T,V,E,W");
    if (closed)
        ADD(",phi1,phi2,phidot1,phidot2");
    for (j = 1; j <= N; j++) {
        ADD(",T%d_rigid", j);
        if (K > 0)
            ADD(",T%d_flex,U%d_strain", j, j);
    }
#undef ADD
}

/* Check a chain CSV (N links, one mode each, all 1 kg and 10 m) against
 * what the row's own state gives: the constraints, the kinetic energy
 * as the sum of its probes, the potential as strain plus gravity
 * (docs/elements.md), E = T + V, and E + W constant to drift. */
static void check_chain_rows(const csv *c, int N, int closed, double g,
                             double D, double drift)
{
    const double m = 1.0, L = 10.0, b1 = 2.0 * m / pi;
    const int cT = csv_col(c, "T"), cV = csv_col(c, "V");
    const int cE = csv_col(c, "E"), cW = csv_col(c, "W");
    int i, j;
    CHECK(cT > 0 && cV > 0 && cE > 0 && cW > 0);
    if (cT <= 0 || cV <= 0 || cE <= 0 || cW <= 0 || c->nrows < 1)
        return;
    for (i = 0; i < c->nrows; i++) {
        double x = 0.0, y = 0.0, T = 0.0, U = 0.0, Vg = 0.0;
        char name[32];
        for (j = 1; j <= N; j++) {
            double th, q;
            snprintf(name, sizeof name, "theta%d", j);
            th = at(c, i, csv_col(c, name));
            snprintf(name, sizeof name, "q%d_1", j);
            q = at(c, i, csv_col(c, name));
            Vg += g * (m * y + 0.5 * m * L * sin(th) + cos(th) * q * b1);
            x += L * cos(th);
            y += L * sin(th);
            snprintf(name, sizeof name, "T%d_rigid", j);
            T += at(c, i, csv_col(c, name));
            snprintf(name, sizeof name, "T%d_flex", j);
            T += at(c, i, csv_col(c, name));
            snprintf(name, sizeof name, "U%d_strain", j);
            U += at(c, i, csv_col(c, name));
        }
        CHECK_NEAR(at(c, i, cT), T, 1e-9);
        CHECK_NEAR(at(c, i, cV), U + Vg, 1e-9);
        CHECK_NEAR(at(c, i, cE), at(c, i, cT) + at(c, i, cV), 1e-9);
        CHECK_NEAR(at(c, i, cE) + at(c, i, cW), at(c, 0, cE), drift);
        if (closed) {
            CHECK_NEAR(at(c, i, csv_col(c, "phi1")), x - D, 1e-12);
            CHECK_NEAR(at(c, i, csv_col(c, "phi2")), y, 1e-12);
            CHECK(fabs(at(c, i, csv_col(c, "phi1"))) <= 1e-10);
            CHECK(fabs(at(c, i, csv_col(c, "phi2"))) <= 1e-10);
            CHECK(fabs(at(c, i, csv_col(c, "phidot1"))) <= 1e-10);
            CHECK(fabs(at(c, i, csv_col(c, "phidot2"))) <= 1e-10);
        }
    }
}

static void case_csv(void)
{
    char path[300], want[4096];
    const char *closed[] = {"closed-chain", "--t-end", "0.2", "--sample",
                            "0.05", "-q", "--out", path, NULL};
    const char *open_args[] = {"open-chain", "--t-end", "0.2", "--sample",
                               "0.05", "--set", "modes=1", "-q", "--out",
                               path, NULL};
    const char *rigid[] = {"closed-chain", "--set", "modes=0", "--t-end",
                           "0", "-q", "--out", path, NULL};
    static const double paper[5] = {5, 1, 0, 17, 13};
    result r;
    csv c;
    int j;
    scratch(path, sizeof path, "out.csv");

    CHECK_INT(run_csv(&c, closed, &r), 0);
    CHECK(r.err[0] == '\0'); /* the default start needs no projection */
    chain_header(want, sizeof want, 5, 1, 1);
    check_count_++;
    if (strcmp(c.header, want) != 0)
        CHECK_FAIL_("header\n  %s\nwanted\n  %s", c.header, want);
    CHECK_INT(c.nrows, 5);
    if (c.nrows > 0 && strcmp(c.header, want) == 0) {
        for (j = 0; j < 5; j++) {
            CHECK_NEAR(at(&c, 0, 1 + j), paper[j] * pi / 12, 1e-15);
            CHECK(at(&c, 0, 6 + j) == 0.0);  /* undeformed */
            CHECK(at(&c, 0, 11 + j) == 0.0); /* at rest */
        }
        check_chain_rows(&c, 5, 1, 9.81, 10.0, 1e-8);
        /* the dampers have started to work */
        CHECK(at(&c, c.nrows - 1, csv_col(&c, "W")) > 0.0);
    }
    free(c.v);
    result_free(&r);

    /* the same run with its summary: each figure against the CSV's rows
     * (energy drift, |C qd|), the counts (rk4: four right-hand sides a
     * step, 0.2 s / 1e-3) and the projection's tolerance (|phi| after a
     * step, which no row shows, is at most 1e-12) */
    {
        const char *loud[] = {"closed-chain", "--integrator", "rk4",
                              "--t-end", "0.2", "--sample", "0.05", "--out",
                              path, NULL};
        double drift = 0.0, phi = 0.0, phid = 0.0, summ;
        int i, cE, cW, cp, cd;
        CHECK_INT(run_csv(&c, loud, &r), 0);
        cE = csv_col(&c, "E");
        cW = csv_col(&c, "W");
        cp = csv_col(&c, "phi1");
        cd = csv_col(&c, "phidot1");
        CHECK(cE > 0 && cW > 0 && cp > 0 && cd > 0);
        for (i = 0; i < c.nrows && cE > 0 && cW > 0 && cp > 0 && cd > 0;
             i++) {
            drift = fmax(drift, fabs(at(&c, i, cE) + at(&c, i, cW) -
                                     at(&c, 0, cE)));
            phi = fmax(phi, fmax(fabs(at(&c, i, cp)), fabs(at(&c, i, cp + 1))));
            phid = fmax(phid,
                        fmax(fabs(at(&c, i, cd)), fabs(at(&c, i, cd + 1))));
        }
        CHECK_INT(number_after(r.err, "with rk4: "), 5);
        CHECK_INT(number_after(r.err, "steps "), 200);
        CHECK_INT(number_after(r.err, "right-hand sides "), 800);
        CHECK(drift > 0.0 && phid > 0.0);
        CHECK_REL(number_after(r.err, "max |E + W - E0| = "), drift, 5e-3);
        CHECK_REL(number_after(r.err, "max |C qd| = "), phid, 5e-3);
        /* a regular closed chain: no SVD solve, a sound condition */
        CHECK(number_after(r.err, "smallest rcond ") > 1e-3);
        CHECK_HAS(r.err, ", 0 SVD solves");
        CHECK_HAS(r.err, "singular positions passed 0, branch switches 0");
        summ = number_after(r.err, "max |phi| = ");
        CHECK(summ >= phi * (1.0 - 5e-3) && summ <= 1e-12);
        free(c.v);
        result_free(&r);
    }

    CHECK_INT(run_csv(&c, open_args, &r), 0);
    chain_header(want, sizeof want, 3, 1, 0);
    check_count_++;
    if (strcmp(c.header, want) != 0)
        CHECK_FAIL_("header\n  %s\nwanted\n  %s", c.header, want);
    if (c.nrows > 0 && strcmp(c.header, want) == 0) {
        CHECK_NEAR(at(&c, 0, csv_col(&c, "theta1")), pi / 6, 1e-15);
        CHECK_NEAR(at(&c, 0, csv_col(&c, "theta2")), -pi / 6, 1e-15);
        CHECK_NEAR(at(&c, 0, csv_col(&c, "theta3")), pi / 6, 1e-15);
        CHECK(at(&c, 0, csv_col(&c, "q3_1")) == 0.01);
        CHECK(at(&c, 0, csv_col(&c, "theta3_dot")) == 0.5);
        /* no gravity, c = 0: conservative, W stays 0 */
        check_chain_rows(&c, 3, 0, 0.0, 0.0, 1e-9);
        CHECK(at(&c, c.nrows - 1, csv_col(&c, "W")) == 0.0);
    }
    free(c.v);
    result_free(&r);

    /* rigid links have only the rigid part of the kinetic energy */
    CHECK_INT(run_csv(&c, rigid, &r), 0);
    chain_header(want, sizeof want, 5, 0, 1);
    check_count_++;
    if (strcmp(c.header, want) != 0)
        CHECK_FAIL_("header\n  %s\nwanted\n  %s", c.header, want);
    free(c.v);
    result_free(&r);
}

/* ---- --plots ------------------------------------------------------------ */

/* The file exists, is not empty and starts with magic (may be NULL). */
static void check_file(const char *dir_file, const char *magic)
{
    size_t len = 0;
    char *text = read_file(dir_file, &len);
    check_count_++;
    if (!text || len == 0) {
        CHECK_FAIL_("missing or empty: %s", dir_file);
    } else if (magic && memcmp(text, magic, strlen(magic)) != 0) {
        CHECK_FAIL_("%s does not start with '%s'", dir_file, magic);
    }
    free(text);
}

/* The page (eom_run_animation) embeds one frame per row, its times the
 * CSV's, and loads nothing from the network; its first drawing is link 1,
 * from the pin at the origin along the paper's first angle, 5 pi/12: its
 * second point a quarter of the 10 m link along it (no deflection at the
 * start). */
static void check_animation(const char *path, int rows, int N)
{
    char *html = read_file(path, NULL);
    const char *p;
    char *end = NULL;
    int frames = 0;
    double v[6];
    CHECK(html != NULL);
    if (!html)
        return;
    CHECK_HAS(html, "<canvas");
    CHECK_HAS(html, "Pause");
    CHECK(!has(html, "http:") && !has(html, "https:") &&
          !has(html, " src="));
    p = strstr(html, "\"t\": [");
    CHECK(p != NULL);
    if (p) {
        p += 6;
        CHECK(strtod(p, &end) == 0.0);
        for (frames = 1; *end == ','; frames++)
            strtod(end + 1, &end);
    }
    CHECK_INT(frames, rows);
    CHECK(strstr(html, "{\"name\": \"link1\", \"kind\": \"polyline\"") !=
          NULL);
    {
        char want[32];
        snprintf(want, sizeof want, "\"link%d\"", N);
        CHECK_HAS(html, want);
    }
    p = strstr(html, "\"v\": [");
    CHECK(p != NULL);
    if (p) {
        int k;
        for (k = 0; k < 6; k++)
            v[k] = strtod(k == 0 ? p + 6 : end + 1, &end);
        CHECK_NEAR(v[0], 0.0, 1e-12);
        CHECK_NEAR(v[1], 0.0, 1e-12);
        CHECK_NEAR(v[3], 2.5 * cos(5 * pi / 12), 1e-6);
        CHECK_NEAR(v[4], 2.5 * sin(5 * pi / 12), 1e-6);
    }
    free(html);
}

/* The first snapshot of the closed chain's .dat (t = 0): its points lie
 * on the chords (no deflection at the start) and its joints are where
 * the documented angles put them, ending at the far pin (10, 0). */
static void check_closed_snapshot(const char *path)
{
    static const double paper[5] = {5, 1, 0, 17, 13};
    char *text = read_file(path, NULL), *p;
    double x = 0.0, y = 0.0;
    int j, points = 0;
    CHECK(text != NULL);
    if (!text)
        return;
    /* block 0: x y dx dy, after the comment lines */
    for (p = text; *p == '#'; p = strchr(p, '\n') + 1)
        ;
    while (*p && *p != '\n') {
        double v[4];
        int k;
        for (k = 0; k < 4; k++)
            v[k] = strtod(p, &p);
        CHECK(v[2] == 0.0 && v[3] == 0.0);
        points++;
        p = strchr(p, '\n') + 1;
    }
    CHECK(points > 5);
    p = strstr(text, "# joints at t = 0 s\n");
    CHECK(p != NULL);
    if (p) {
        p = strchr(p, '\n') + 1;
        CHECK(strtod(p, &p) == 0.0 && strtod(p, &p) == 0.0);
        for (j = 0; j < 5; j++) {
            double jx, jy;
            x += 10.0 * cos(paper[j] * pi / 12);
            y += 10.0 * sin(paper[j] * pi / 12);
            jx = strtod(p, &p);
            jy = strtod(p, &p);
            CHECK_NEAR(jx, x, 1e-8);
            CHECK_NEAR(jy, y, 1e-8);
        }
        CHECK_NEAR(x, 10.0, 1e-12);
    }
    free(text);
}

/* The open chain's first snapshot: only link 3 is bent, by its first
 * mode, 0.01 m at mid-span along n3 = (-sin, cos)(pi/6). */
static void check_open_snapshot(const char *path)
{
    char *text = read_file(path, NULL), *p;
    double best = 0.0, bx = 0.0, by = 0.0;
    CHECK(text != NULL);
    if (!text)
        return;
    for (p = text; *p == '#'; p = strchr(p, '\n') + 1)
        ;
    while (*p && *p != '\n') {
        double v[4], d;
        int k;
        for (k = 0; k < 4; k++)
            v[k] = strtod(p, &p);
        d = hypot(v[2], v[3]);
        if (d > best) {
            best = d;
            bx = v[2];
            by = v[3];
        }
        p = strchr(p, '\n') + 1;
    }
    CHECK_NEAR(best, 0.01, 1e-9);
    CHECK_NEAR(bx, -0.01 * sin(pi / 6), 1e-9);
    CHECK_NEAR(by, 0.01 * cos(pi / 6), 1e-9);
    free(text);
}

static int gnuplot_installed(void)
{
    const char *path = getenv("PATH"), *p;
    char buf[4096];
    for (p = path; p && *p;) {
        const char *colon = strchr(p, ':');
        size_t dl = colon ? (size_t)(colon - p) : strlen(p);
        snprintf(buf, sizeof buf, "%.*s/gnuplot", (int)dl, p);
        if (dl > 0 && access(buf, X_OK) == 0)
            return 1;
        p += dl + (colon ? 1 : 0);
    }
    return 0;
}

static void case_plots(void)
{
    static const char *const made[] = {
        "energy.png", "energy.svg", "energy.gp", "snapshots.png",
        "snapshots.svg", "snapshots.gp", "snapshots.dat",
        "total-energy.png", "total-energy.svg", "total-energy.gp",
        "residuals.png", "residuals.svg", "residuals.gp",
        "animation.html"};
    char path[300], file[400], empty[300], msg[512];
    const char *args[] = {"closed-chain", "--t-end", "0.2", "--sample",
                          "0.02", "--plots", "--out", path, NULL};
    const char *open_args[] = {"open-chain", "--t-end", "0.1", "--plots",
                               "-q", "--out", path, NULL};
    const char *no_out[] = {"closed-chain", "--plots", "--modes", NULL};
    const char *sp[] = {"spring-pendulum", "--plots", "--out", path, NULL};
    size_t k;
    char *text;
    result r;
    csv c;

    /* usage errors first: they need no gnuplot, and create nothing */
    run(&r, no_out);
    CHECK_INT(r.status, 2);
    CHECK_HAS(r.err, "--out and --plots belong to a run");
    CHECK(r.out[0] == '\0');
    result_free(&r);
    /* the spring pendulum's plots: energies and the bob's path */
    scratch(path, sizeof path, "sp.csv");
    run(&r, sp);
    CHECK_INT(r.status, 0);
    result_free(&r);
    for (k = 0; k < 2; k++) {
        static const char *const sp_files[2] = {"sp-energy.png",
                                                "sp-path.svg"};
        struct stat st;
        scratch(file, sizeof file, sp_files[k]);
        CHECK(stat(file, &st) == 0 && st.st_size > 0);
    }

    /* gnuplot missing: a clear message, status 1, the CSV and the
     * animation kept */
    scratch(empty, sizeof empty, "empty-bin");
    CHECK(mkdir(empty, 0700) == 0);
    scratch(path, sizeof path, "cc.csv");
    run_path(&r, args, empty);
    CHECK_INT(r.status, 1);
    CHECK_HAS(r.err, "gnuplot");
    CHECK_HAS(r.err, "not installed");
    CHECK_HAS(r.err, "energy drift"); /* the run itself went through */
    text = read_file(path, NULL);
    CHECK(text != NULL);
    if (text) {
        check_count_++;
        if (csv_parse(text, &c, msg, sizeof msg) != 0)
            CHECK_FAIL_("%s", msg);
        CHECK_INT(c.nrows, 11);
        free(c.v);
        free(text);
    }
    scratch(file, sizeof file, "cc-animation.html");
    check_file(file, "<!DOCTYPE html>");
    scratch(file, sizeof file, "cc-energy.png");
    CHECK(access(file, F_OK) != 0);
    result_free(&r);
    rmdir(empty);

    if (!gnuplot_installed()) {
        fprintf(stderr, "gnuplot is not installed: the plots are not "
                "tested\n");
        return;
    }
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "plots written");
    for (k = 0; k < sizeof made / sizeof made[0]; k++) {
        char name[64];
        const char *ext = strrchr(made[k], '.');
        snprintf(name, sizeof name, "cc-%s", made[k]);
        scratch(file, sizeof file, name);
        check_file(file, strcmp(ext, ".png") == 0   ? "\x89PNG"
                         : strcmp(ext, ".svg") == 0 ? "<?xml"
                                                    : NULL);
    }
    scratch(file, sizeof file, "cc-animation.html");
    check_animation(file, 11, 5);
    scratch(file, sizeof file, "cc-snapshots.dat");
    check_closed_snapshot(file);
    /* the scripts name their files relative to their directory */
    scratch(file, sizeof file, "cc-energy.gp");
    text = read_file(file, NULL);
    CHECK(text && has(text, "csv = 'cc.csv'") && !has(text, "/"));
    free(text);
    result_free(&r);

    /* an open chain has no constraints, so no residual plot */
    scratch(path, sizeof path, "oc.csv");
    run(&r, open_args);
    CHECK_INT(r.status, 0);
    scratch(file, sizeof file, "oc-snapshots.png");
    check_file(file, "\x89PNG");
    scratch(file, sizeof file, "oc-residuals.png");
    CHECK(access(file, F_OK) != 0);
    scratch(file, sizeof file, "oc-snapshots.dat");
    check_open_snapshot(file);
    result_free(&r);
}

/* ---- --modes ------------------------------------------------------------ */

/* The frequencies of a --modes table: omega[k] for rows "  N  omega ..."
 * after the "mode" header, hz[k] the f (Hz) column (NaN when not a
 * number). Returns their number. */
static int parse_modes(const char *out, double *omega, double *hz, int max)
{
    const char *p = strstr(out, "  mode  ");
    int n = 0;
    if (!p)
        return 0;
    p = strchr(p, '\n');
    while (p && n < max) {
        char *end;
        long k = strtol(p + 1, &end, 10);
        if (end == p + 1 || k != n + 1)
            break;
        omega[n] = strtod(end, &end);
        hz[n] = strtod(end, &end);
        if (*end != ' ' && *end != '\n')
            hz[n] = NAN;
        n++;
        p = strchr(end, '\n');
    }
    return n;
}

static void case_modes(void)
{
    const char *sp[] = {"spring-pendulum", "--modes", NULL};
    const char *sp_set[] = {"spring-pendulum", "--modes", "--set", "k=100",
                            "--set", "m=2", NULL};
    const char *beam[] = {"closed-chain", "--modes", "--set", "links=1",
                          "--set", "modes=2", "--set", "g=0", NULL};
    const char *beam_one[] = {"closed-chain", "--modes", "--set", "links=1",
                              "--set", "modes=1", "--set", "g=0", NULL};
    const char *beam_ei[] = {"closed-chain", "--modes", "--set", "links=1",
                             "--set", "modes=2", "--set", "g=0", "--set",
                             "EI1=1e5", "--set", "m1=2", NULL};
    const char *open_args[] = {"open-chain", "--modes", NULL};
    const char *one_beam[] = {"open-chain", "--modes", "--set", "links=1",
                              "--set", "modes=2", NULL};
    const char *far[] = {"closed-chain", "--modes", "--set", "D=60", NULL};
    char path[300];
    const char *with_out[] = {"spring-pendulum", "--modes", "--out", path,
                              NULL};
    const char *with_describe[] = {"spring-pendulum", "--modes",
                                   "--describe", NULL};
    double w[16], f[16];
    result r;
    int n, i;

    /* the spring pendulum at rest hangs at r = r0 + m g / k */
    run(&r, sp);
    CHECK_INT(r.status, 0);
    n = parse_modes(r.out, w, f, 16);
    CHECK_INT(n, 2);
    if (n == 2) {
        CHECK_NEAR(w[0], sqrt(9.81 / (1.0 + 9.81 / 75.0)), 1e-6);
        CHECK_NEAR(w[1], sqrt(75.0), 1e-6);
        for (i = 0; i < 2; i++)
            CHECK_NEAR(f[i], w[i] / (2 * pi), 1e-9);
    }
    CHECK_NEAR(line_value(r.out, "r"), 1.0 + 9.81 / 75.0, 1e-9);
    CHECK_NEAR(line_value(r.out, "theta"), 0.0, 1e-9);
    CHECK_HAS(r.out, "tolerance");
    CHECK_HAS(r.out, "stable");
    CHECK_HAS(r.out, "found from the initial state"); /* no rest guess */
    CHECK(r.err[0] == '\0');
    result_free(&r);

    /* --set applies first */
    run(&r, sp_set);
    CHECK_INT(r.status, 0);
    n = parse_modes(r.out, w, f, 16);
    CHECK_INT(n, 2);
    if (n == 2) {
        CHECK_NEAR(w[0], sqrt(9.81 / (1.0 + 2.0 * 9.81 / 100.0)), 1e-6);
        CHECK_NEAR(w[1], sqrt(50.0), 1e-6);
    }
    result_free(&r);

    /* one link from (0, 0) to (D, 0) = (L, 0) is a pinned-pinned beam:
     * omega_i = (i pi / L)^2 sqrt(EI / rho), rho = m / L. Without
     * gravity it stays straight; with it, it would sag. */
    run(&r, beam);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.out, "found from the demo's rest guess");
    n = parse_modes(r.out, w, f, 16);
    CHECK_INT(n, 2);
    for (i = 0; i < n && i < 2; i++)
        CHECK_NEAR(w[i], pow((i + 1) * pi / 10.0, 2) * sqrt(4e4 / 0.1),
                   1e-6);
    result_free(&r);
    /* one mode: two coordinates, two constraints of rank 1 (the x row
     * of C vanishes on the straight link); one degree of freedom */
    run(&r, beam_one);
    CHECK_INT(r.status, 0);
    n = parse_modes(r.out, w, f, 16);
    CHECK_INT(n, 1);
    if (n == 1)
        CHECK_NEAR(w[0], pow(pi / 10.0, 2) * sqrt(4e4 / 0.1), 1e-6);
    result_free(&r);
    run(&r, beam_ei);
    CHECK_INT(r.status, 0);
    n = parse_modes(r.out, w, f, 16);
    CHECK_INT(n, 2);
    for (i = 0; i < n && i < 2; i++)
        CHECK_NEAR(w[i], pow((i + 1) * pi / 10.0, 2) * sqrt(1e5 / 0.2),
                   1e-6);
    result_free(&r);

    /* one free beam pinned at the origin, two modes, no gravity: at rest
     * T = 1/2 (M_rr thd^2 + 2 thd sum_i M_ri qd_i + m/2 sum_i qd_i^2) with
     * M_rr = m L^2 / 3 and M_ri = int rho x sin(i pi x / L) dx =
     * m L (-1)^(i+1) / (i pi); V = sum_i EI (i pi / L)^4 L / 4 q_i^2.
     * The rotation is free (omega 0); condensing it out leaves
     * det(K - w^2 (m/2 I - 3 m a a')) = 0 with a_i = (-1)^(i+1) / (i pi),
     * a quadratic in w^2. */
    run(&r, one_beam);
    CHECK_INT(r.status, 0);
    n = parse_modes(r.out, w, f, 16);
    CHECK_INT(n, 3);
    if (n == 3) {
        const double m = 1.0, L = 10.0, EI = 4e3;
        const double a0 = 1.0 / pi, a1 = -1.0 / (2.0 * pi);
        const double M00 = m / 2 - 3 * m * a0 * a0, M11 = m / 2 - 3 * m * a1 * a1;
        const double M01 = -3 * m * a0 * a1;
        const double k0 = EI * pow(pi / L, 4) * L / 2;
        const double k1 = EI * pow(2 * pi / L, 4) * L / 2;
        const double A = M00 * M11 - M01 * M01, B = -(k0 * M11 + k1 * M00);
        const double D = sqrt(B * B - 4 * A * k0 * k1);
        CHECK(fabs(w[0]) < 1e-6);
        CHECK_NEAR(w[1], sqrt((-B - D) / (2 * A)), 1e-9);
        CHECK_NEAR(w[2], sqrt((-B + D) / (2 * A)), 1e-9);
    }
    result_free(&r);

    /* no gravity, no springs: the three rigid rotations are neutral */
    run(&r, open_args);
    CHECK_INT(r.status, 0);
    n = parse_modes(r.out, w, f, 16);
    CHECK_INT(n, 9);
    for (i = 0; i < n; i++)
        CHECK(i < 3 ? fabs(w[i]) < 1e-6 : w[i] > 1.0);
    CHECK_HAS(r.out, "neutral");
    result_free(&r);

    /* five 10 m links cannot reach a pin 60 m away */
    run(&r, far);
    CHECK_INT(r.status, 1);
    CHECK_HAS(r.err, "no static equilibrium found from the demo's rest "
                     "guess");
    CHECK(r.out[0] == '\0');
    result_free(&r);

    scratch(path, sizeof path, "modes.csv");
    run(&r, with_out);
    CHECK_INT(r.status, 2);
    CHECK_HAS(r.err, "--modes");
    CHECK(access(path, F_OK) != 0);
    result_free(&r);
    run(&r, with_describe);
    CHECK_INT(r.status, 2);
    result_free(&r);
}

/* ---- the initial projection -------------------------------------------- */

static void case_project(void)
{
    char path[300];
    const char *far[] = {"closed-chain", "--set", "D=12", "--t-end", "0.1",
                         "--sample", "0.05", "-q", "--out", path, NULL};
    const char *far_np[] = {"closed-chain", "--set", "D=12", "--no-project",
                            "--t-end", "0", "-q", "--out", path, NULL};
    const char *six[] = {"closed-chain", "--set", "links=6", "--t-end",
                         "0.1", "--sample", "0.05", "-q", "--out", path,
                         NULL};
    const char *spin[] = {"closed-chain", "--set", "theta1_dot=1",
                          "--t-end", "0", "-q", "--out", path, NULL};
    result r;
    csv c;
    scratch(path, sizeof path, "out.csv");

    /* the far pin moved: the first row is already on the constraints */
    CHECK_INT(run_csv(&c, far, &r), 0);
    CHECK_HAS(r.err, "off the constraints");
    CHECK_HAS(r.err, "max |phi| = 2,");
    CHECK_HAS(r.err, "projected");
    CHECK(strchr(r.err, '\n') == r.err + strlen(r.err) - 1); /* one line */
    if (c.nrows > 0 && csv_col(&c, "phi1") > 0) {
        double x = 0.0;
        int j;
        for (j = 1; j <= 5; j++) {
            char name[16];
            snprintf(name, sizeof name, "theta%d", j);
            x += 10.0 * cos(at(&c, 0, csv_col(&c, name)));
        }
        CHECK_NEAR(x, 12.0, 1e-10);
        CHECK(fabs(at(&c, 0, csv_col(&c, "phi1"))) <= 1e-10);
        CHECK(fabs(at(&c, 0, csv_col(&c, "phi2"))) <= 1e-10);
        CHECK(fabs(at(&c, c.nrows - 1, csv_col(&c, "phi1"))) <= 1e-10);
    }
    free(c.v);
    result_free(&r);

    /* --no-project: a warning, and the run starts where it was told;
     * its verdict fails on the residual (2 m), exit status 3, and the
     * rows are written whole */
    CHECK_INT(run_csv(&c, far_np, &r), 3);
    CHECK_HAS(r.err, "warning");
    CHECK_HAS(r.err, "--no-project");
    CHECK_HAS(r.err, "unhealthy: constraint residual max |phi| 2 exceeds");
    if (c.nrows > 0 && csv_col(&c, "phi1") > 0)
        CHECK_NEAR(at(&c, 0, csv_col(&c, "phi1")), -2.0, 1e-12);
    free(c.v);
    result_free(&r);

    /* six links start from an arch that closes: nothing to project */
    CHECK_INT(run_csv(&c, six, &r), 0);
    CHECK(!has(r.err, "off the constraints"));
    if (c.nrows > 0 && csv_col(&c, "phi1") > 0) {
        CHECK(csv_col(&c, "theta6") > 0);
        CHECK(fabs(at(&c, 0, csv_col(&c, "phi1"))) <= 1e-10);
        CHECK(fabs(at(&c, 0, csv_col(&c, "phi2"))) <= 1e-10);
    }
    free(c.v);
    result_free(&r);

    /* a rate that breaks C qd = 0 is projected too */
    CHECK_INT(run_csv(&c, spin, &r), 0);
    CHECK_HAS(r.err, "projected");
    if (c.nrows > 0 && csv_col(&c, "phidot1") > 0) {
        CHECK(fabs(at(&c, 0, csv_col(&c, "phidot1"))) <= 1e-10);
        CHECK(fabs(at(&c, 0, csv_col(&c, "phidot2"))) <= 1e-10);
        CHECK(at(&c, 0, csv_col(&c, "theta1_dot")) != 0.0);
    }
    free(c.v);
    result_free(&r);
}

static const struct {
    const char *name;
    void (*fn)(void);
} cases[] = {
    {"chain_list", case_list},   {"chain_describe", case_describe},
    {"chain_csv", case_csv},     {"chain_plots", case_plots},
    {"chain_modes", case_modes}, {"chain_project", case_project},
};

int main(int argc, char **argv)
{
    size_t i;
    int found = 0;
    if (argc < 3) {
        fprintf(stderr, "usage: test_cli_chains EOM_RUN CASE\n");
        return EXIT_FAILURE;
    }
    cli_program = argv[1];
    if (cli_setup() != 0)
        return EXIT_FAILURE;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++)
        if (strcmp(cases[i].name, argv[2]) == 0) {
            cases[i].fn();
            found = 1;
        }
    cli_cleanup();
    if (!found) {
        fprintf(stderr, "test_cli_chains: unknown case '%s'\n", argv[2]);
        return EXIT_FAILURE;
    }
    CHECK_DONE();
}
