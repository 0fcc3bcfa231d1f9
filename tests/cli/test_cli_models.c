/* test_cli_models.c - eom-run on model files (docs/models.md), from the
 * outside: a shipped model by name and by path, --list, --describe with
 * the file's settings, --set of a setting that reshapes the model, a
 * file with an error (file:line:col on stderr, exit status 1, no CSV),
 * --modes of the double pendulum against its closed-form frequencies,
 * --modes under declared forces (a torque, a follower load; a force
 * that reads the time refused),
 * --plots without --out in a scratch directory, and --compiled (the
 * interpreter's CSV byte for byte, the cache, no compiler).
 *
 * usage: test_cli_models EOM_RUN MODELS_DIR CASE */
#define _XOPEN_SOURCE 700 /* realpath */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "cli_support.h"

static const char *models;

static void model_path(char *buf, size_t len, const char *name)
{
    snprintf(buf, len, "%s/%s.eom", models, name);
}

static void case_list(void)
{
    const char *args[] = {"--list", NULL};
    result r;
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.out, "model files in");
    CHECK_HAS(r.out, "cart-pole");
    CHECK_HAS(r.out, "four-bar");
    CHECK_HAS(r.out, "four-bar linkage");
    CHECK_HAS(r.out, "driven-crank");
    result_free(&r);
}

static void case_describe(void)
{
    char path[1200];
    const char *args[] = {path, "--describe", "--set", "links=2", NULL};
    result r;
    model_path(path, sizeof path, "open-chain");
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.out, "links");
    CHECK_HAS(r.out, "number of links");
    CHECK_HAS(r.out, "theta2");
    CHECK(!has(r.out, "theta3"));
    CHECK_HAS(r.out, "q2_2");
    CHECK_HAS(r.out, "N m^2");
    result_free(&r);
}

/* By name (a shipped model no demo shadows), with a setting and a
 * parameter; the CSV's columns follow the settings. */
static void case_csv(void)
{
    char out[300];
    const char *args[] = {"cart-pole", "--t-end", "0.5", "--set", "F=0",
                          "--set", "theta=0.3", "--out", out, "-q", NULL};
    const char *chain[] = {"open-chain.eom", NULL};
    char *text, msg[256];
    result r;
    csv c;
    scratch(out, sizeof out, "cp.csv");
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    text = read_file(out, NULL);
    CHECK(text != NULL);
    if (!text)
        return;
    if (csv_parse(text, &c, msg, sizeof msg) != 0) {
        CHECK_FAIL_("%s", msg);
    } else {
        int th = csv_col(&c, "theta"), E = csv_col(&c, "E"),
            W = csv_col(&c, "W");
        CHECK_INT(c.nrows, 51);
        CHECK(th >= 0 && E >= 0 && W >= 0 && csv_col(&c, "x_dot") >= 0);
        if (th >= 0 && E >= 0 && W >= 0) {
            CHECK(at(&c, 0, th) == 0.3);
            /* no force: E + W stays */
            CHECK_NEAR(at(&c, 50, E) + at(&c, 50, W), at(&c, 0, E), 1e-6);
        }
        free(c.v);
    }
    free(text);
    /* a path that is not there */
    run(&r, chain);
    CHECK_INT(r.status, 1);
    CHECK_HAS(r.err, "open-chain.eom: cannot open the model file");
    result_free(&r);
}

/* A file with a mistake: the place, the line, the caret and the hint on
 * stderr, status 1, nothing written. */
static void case_error(void)
{
    char file[300], out[300];
    const char *args[] = {file, "--out", out, NULL};
    FILE *f;
    result r;
    struct stat st;
    scratch(file, sizeof file, "bad.eom");
    scratch(out, sizeof out, "bad.csv");
    f = fopen(file, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs("param m = 1 [kg]\ncoord x = 0 [m]\nT = 1/2*m*x_dto^2\n", f);
    fclose(f);
    run(&r, args);
    CHECK_INT(r.status, 1);
    CHECK_HAS(r.err, "bad.eom:3:11: unknown name 'x_dto'");
    CHECK_HAS(r.err, "  T = 1/2*m*x_dto^2\n            ^");
    CHECK_HAS(r.err, "did you mean 'x_dot'?");
    CHECK(stat(out, &st) != 0);
    result_free(&r);
    unlink(file);
}

/* Small oscillations of the double pendulum with equal masses and rods:
 * omega^2 = (2 -+ sqrt 2) g / l. */
static void case_modes(void)
{
    const char *args[] = {"double-pendulum", "--modes", NULL};
    const double g = 9.81;
    result r;
    run(&r, args);
    CHECK_INT(r.status, 0);
    /* the rows of the table: "     1  OMEGA  F" */
    CHECK_NEAR(number_after(r.out, "\n     1  "), sqrt((2 - sqrt(2.0)) * g),
               1e-9);
    CHECK_NEAR(number_after(r.out, "\n     2  "), sqrt((2 + sqrt(2.0)) * g),
               1e-9);
    result_free(&r);
}

/* Writes text to the scratch file name, its path into path. */
static int write_scratch(char *path, size_t len, const char *name,
                         const char *text)
{
    FILE *f;
    scratch(path, len, name);
    f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return -1;
    fputs(text, f);
    fclose(f);
    return 0;
}

/* --modes under the model's force statements. A pendulum (m l^2 thdd =
 * -m g l sin th + tau) with the torque as a force: its equilibrium at
 * asin(tau / (m g l)) and omega = sqrt(g cos(th) / l). A unit mass on
 * springs 4 N/m under the follower load (y, 0.5 - x): the equilibrium
 * (1/34, 2/17), and since no undamped frequencies exist the eigenvalues
 * s^2 = -4 +- i of the state matrix, two of them unstable. The cart-pole,
 * pushed by F cos(w t): refused, naming the force that reads the time. */
static void case_modes_forces(void)
{
    const double m = 1.0, l = 0.5, g = 9.81, tau = 2.0;
    const double th = asin(tau / (m * g * l));
    char file[300], cp[300];
    const char *args[] = {file, "--modes", NULL};
    const char *cart[] = {cp, "--modes", NULL};
    result r;
    if (write_scratch(file, sizeof file, "torque.eom",
                      "param m = 1 [kg]\nparam l = 0.5 [m]\n"
                      "param g = 9.81 [m/s^2]\nparam tau = 2 [N*m]\n"
                      "coord theta = 0 [rad]\n"
                      "T = 1/2*m*l^2*theta_dot^2\n"
                      "V = -m*g*l*cos(theta)\n"
                      "force theta = tau\n") != 0)
        return;
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.out, "every force at rest");
    CHECK_NEAR(number_after(r.out, "\n  theta  "), th, 1e-12);
    CHECK_NEAR(number_after(r.out, "\n     1  "), sqrt(g * cos(th) / l),
               1e-9);
    result_free(&r);

    if (write_scratch(file, sizeof file, "follower.eom",
                      "param m = 1 [kg]\nparam k = 4 [N/m]\n"
                      "param c = 1 [N/m]\nparam f = 0.5 [N]\n"
                      "coord x = 0.1 [m]\ncoord y = 0 [m]\n"
                      "T = 1/2*m*(x_dot^2 + y_dot^2)\n"
                      "V = 1/2*k*(x^2 + y^2)\n"
                      "force x = c*y\nforce y = f - c*x\n") != 0)
        return;
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.out, "the forces' stiffness is unsymmetric");
    CHECK_NEAR(number_after(r.out, "\n  x  "), 1.0 / 34.0, 1e-12);
    CHECK_NEAR(number_after(r.out, "\n  y  "), 2.0 / 17.0, 1e-12);
    /* s = +-(a + i b) with (a + i b)^2 = -4 + i: a = 0.2481 */
    CHECK_NEAR(fabs(number_after(r.out, "\n     1  ")),
               sqrt((sqrt(17.0) - 4.0) / 2.0), 1e-9);
    CHECK_HAS(r.out, "UNSTABLE");
    result_free(&r);

    model_path(cp, sizeof cp, "cart-pole");
    run(&r, cart);
    CHECK_INT(r.status, 1);
    CHECK_HAS(r.err, "the force on x reads the time t");
    CHECK(r.out == NULL || !has(r.out, "equilibrium coordinates"));
    result_free(&r);
}

/* --modes about a steady motion: the rolling disk upright at 1.5 m/s
 * (its lean set to 0) reduced to lean, heading rate and lean rate; its
 * own start leans and is refused with the largest acceleration. --sweep
 * of gravity: the CSV's header, its rows, and the eigenvalues against
 * the closed form s^2 = (4/5) (g / r - 3 v^2 / r^2) (test_steady.c
 * derives it); malformed sweeps are usage errors. */
static void case_modes_steady(void)
{
    const double r0 = 0.3, v = 1.5;
    char path[PATH_MAX];
    const char *upright[] = {"rolling-disk", "--modes", "--set", "theta=0",
                             NULL};
    const char *leaning[] = {"rolling-disk", "--modes", NULL};
    const char *sweep[] = {"rolling-disk", "--modes", "--set", "theta=0",
                           "--sweep", "g=0:30:7", "--out", path, "-q",
                           NULL};
    const char *bad[][6] = {
        {"rolling-disk", "--modes", "--sweep", "g=0:30", NULL},
        {"rolling-disk", "--modes", "--sweep", "g=0:30:1", NULL},
        {"rolling-disk", "--modes", "--sweep", "g=0:x:5", NULL},
        {"rolling-disk", "--modes", "--sweep", "theta=0:1:5", NULL},
        {"rolling-disk", "--sweep", "g=0:30:5", NULL},
    };
    const char *why[] = {"three fields", "N must be", "HI 'x'",
                         "no parameter named 'theta'", "belongs to --modes"};
    result res;
    csv c;
    char msg[256], *text;
    int row, j, k;
    run(&res, upright);
    CHECK_INT(res.status, 0);
    CHECK_HAS(res.out, "a steady motion");
    CHECK_HAS(res.out, "independent states (3 of the 8 on the constraints): "
                       "theta, psi_dot, theta_dot");
    {
        /* the table's row 3: k, re, im; an oscillation above the
         * critical speed */
        const char *p = res.out ? strstr(res.out, "\n     3  ") : NULL;
        char *e = NULL;
        double re = p ? strtod(p + 9, &e) : NAN;
        double im = e ? strtod(e, NULL) : NAN;
        CHECK_NEAR(re, 0.0, 1e-12);
        CHECK_NEAR(im, sqrt(-0.8 * (9.81 / r0 - 3.0 * v * v / (r0 * r0))),
                   1e-12);
    }
    result_free(&res);
    run(&res, leaning);
    CHECK_INT(res.status, 1);
    CHECK_HAS(res.err, "neither at rest nor a steady motion");
    CHECK_HAS(res.err, "theta_ddot");
    result_free(&res);

    scratch(path, sizeof path, "disk-modes.csv");
    run(&res, sweep);
    CHECK_INT(res.status, 0);
    CHECK(res.out && res.out[0] == '\0');
    result_free(&res);
    text = read_file(path, NULL);
    CHECK(text != NULL);
    if (text && csv_parse(text, &c, msg, sizeof msg) == 0) {
        CHECK(strcmp(c.header, "g,re1,im1,re2,im2,re3,im3") == 0);
        CHECK_INT(c.nrows, 7);
        CHECK_INT(c.ncols, 7);
        for (row = 0; row < c.nrows && c.ncols == 7; row++) {
            const double g = 5.0 * row;
            const double s2 = 0.8 * (g / r0 - 3.0 * v * v / (r0 * r0));
            double big = 0.0, sq = 0.0;
            CHECK_NEAR(at(&c, row, 0), g, 1e-15);
            for (j = 0; j < 3; j++) {
                const double re = at(&c, row, 1 + 2 * j);
                const double im = at(&c, row, 2 + 2 * j);
                if (hypot(re, im) > big) {
                    big = hypot(re, im);
                    sq = re * re - im * im;
                }
            }
            CHECK_NEAR(sq, s2, 1e-10);
        }
        /* row 5 (g = 25): a real pair, the unstable one */
        for (j = 0, k = 0; j < 3 && c.nrows == 7 && c.ncols == 7; j++)
            k += at(&c, 5, 1 + 2 * j) > 1.0;
        CHECK_INT(k, 1);
        free(c.v);
    } else {
        CHECK_FAIL_("the sweep's CSV: %s", text ? msg : "missing");
    }
    free(text);
    for (k = 0; k < 5; k++) {
        run(&res, bad[k]);
        CHECK_INT(res.status, 2);
        CHECK_HAS(res.err, why[k]);
        result_free(&res);
    }
}

/* The values of row `row` of block `blk` of --linearize's output (up to
 * max); the number of values, or -1 when the block or row is missing. */
static int block_row(const char *out, const char *blk, const char *row,
                     double *v, int max)
{
    char key[64];
    const char *p, *end;
    int k = 0;
    snprintf(key, sizeof key, "\n%s,", blk);
    p = out ? strstr(out, key) : NULL;
    if (!p)
        return -1;
    p = strchr(p + 1, '\n'); /* past the header */
    snprintf(key, sizeof key, "\n%s,", row);
    while (p && *p) {
        if (strncmp(p, key, strlen(key)) == 0)
            break;
        p = strchr(p + 1, '\n');
        /* a line without a row of this block: a new header follows one
         * whose first field is a block name; stop at the eigenvalues */
        if (p && strncmp(p, "\neigenvalues", 12) == 0 &&
            strcmp(blk, "eigenvalues") != 0)
            return -1;
    }
    if (!p || !*p)
        return -1;
    p += strlen(key);
    end = strchr(p, '\n');
    while (p && p < end && k < max) {
        char *e;
        v[k++] = strtod(p, &e);
        p = strchr(e, ',');
        if (p)
            p++;
    }
    return k;
}

/* --linearize on the spring pendulum against its equations in closed form
 *   rdd  = r thd^2 - k/m (r - r0) + g cos th
 *   thdd = -(g sin th + 2 rd thd) / r
 * at a moving state (gyroscopic terms included), B against the same,
 * the eigenvalues at rest (+-i sqrt(k/m), +-i sqrt(g/r)); the four-bar's
 * reduced blocks; --linearize with --out refused. */
static void case_linearize(void)
{
    const double m = 1.0, k = 75.0, r0 = 1.0, g = 9.81;
    const double r = 1.2, th = 0.4, rd = 0.3, thd = 0.7;
    const double req = r0 + m * g / k;
    char rest_r[64];
    const char *moving[] = {"spring-pendulum", "--linearize", "--set",
                            "r=1.2", "--set", "theta=0.4", "--set",
                            "r_dot=0.3", "--set", "theta_dot=0.7", NULL};
    const char *rest[] = {"spring-pendulum", "--linearize", "--set",
                          rest_r, "--set", "theta=0", NULL};
    const char *bar[] = {"four-bar", "--linearize", NULL};
    const char *bad[] = {"four-bar", "--linearize", "-o", "x.csv", NULL};
    double v[16];
    result res;
    int i;

    run(&res, moving);
    CHECK_INT(res.status, 0);
    CHECK_INT(block_row(res.out, "A", "qd:r", v, 16), 4);
    CHECK_NEAR(v[0], thd * thd - k / m, 1e-12);
    CHECK_NEAR(v[1], -g * sin(th), 1e-12);
    CHECK_NEAR(v[2], 0.0, 1e-12);
    CHECK_NEAR(v[3], 2.0 * r * thd, 1e-12);
    CHECK_INT(block_row(res.out, "A", "qd:theta", v, 16), 4);
    CHECK_NEAR(v[0], (g * sin(th) + 2.0 * rd * thd) / (r * r), 1e-12);
    CHECK_NEAR(v[1], -g * cos(th) / r, 1e-12);
    CHECK_NEAR(v[2], -2.0 * thd / r, 1e-12);
    CHECK_NEAR(v[3], -2.0 * rd / r, 1e-12);
    CHECK_INT(block_row(res.out, "A", "q:theta", v, 16), 4);
    CHECK(v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0 && v[3] == 1.0);
    /* B: columns m, k, r0, g */
    CHECK_INT(block_row(res.out, "B", "qd:r", v, 16), 4);
    CHECK_NEAR(v[0], k * (r - r0) / (m * m), 1e-12);
    CHECK_NEAR(v[1], -(r - r0) / m, 1e-12);
    CHECK_NEAR(v[2], k / m, 1e-12);
    CHECK_NEAR(v[3], cos(th), 1e-12);
    CHECK_INT(block_row(res.out, "B", "qd:theta", v, 16), 4);
    CHECK_NEAR(v[3], -sin(th) / r, 1e-12);
    CHECK_HAS(res.out, "\nB,p:m,p:k,p:r0,p:g\n");
    result_free(&res);

    snprintf(rest_r, sizeof rest_r, "r=%.17g", req);
    run(&res, rest);
    CHECK_INT(res.status, 0);
    {
        const double want[4] = {-sqrt(k / m), -sqrt(g / req), sqrt(g / req),
                                sqrt(k / m)};
        char row[8];
        for (i = 0; i < 4; i++) {
            snprintf(row, sizeof row, "%d", i + 1);
            CHECK_INT(block_row(res.out, "eigenvalues", row, v, 16), 2);
            CHECK_NEAR(v[0], 0.0, 1e-9);
            CHECK_NEAR(v[1], want[i], 1e-9);
        }
    }
    result_free(&res);

    run(&res, bar);
    CHECK_INT(res.status, 0);
    CHECK_HAS(res.out, "\nT,z1,z2\n");
    CHECK_HAS(res.out, "\nAr,z1,z2\n");
    CHECK_INT(block_row(res.out, "T", "qd:th1", v, 16), 2);
    result_free(&res);

    run(&res, bad);
    CHECK_INT(res.status, 2);
    CHECK_HAS(res.err, "--linearize prints to standard output");
    result_free(&res);
}

/* --linearize's output read as docs/csv.md says a script should: a line
 * whose first field is a block name starts that block and names its
 * columns; any other line (not a # comment) is a row of the current
 * block, named by its first field. The entry (row, col) of block blk
 * into *v; 0, or -1 when missing. *nrows receives the block's row count
 * (may be NULL). */
static int lin_entry(const char *out, const char *blk, const char *row,
                     const char *col, double *v, int *nrows)
{
    static const char *const blocks[] = {"x", "A", "B", "T", "Ar", "Br",
                                         "eigenvalues"};
    char line[4096], cur[64] = "", head[4096] = "";
    const char *p = out;
    int found = -1, rows = 0;
    while (p && *p) {
        const char *e = strchr(p, '\n');
        size_t len = e ? (size_t)(e - p) : strlen(p), k, fl;
        int isblock = 0;
        if (len >= sizeof line)
            return -1;
        memcpy(line, p, len);
        line[len] = '\0';
        p = e ? e + 1 : NULL;
        if (line[0] == '#' || line[0] == '\0')
            continue;
        fl = strcspn(line, ",");
        for (k = 0; k < sizeof blocks / sizeof blocks[0]; k++)
            isblock |= strlen(blocks[k]) == fl &&
                       strncmp(line, blocks[k], fl) == 0;
        if (isblock) {
            snprintf(cur, sizeof cur, "%.*s", (int)fl, line);
            snprintf(head, sizeof head, "%s", line);
            continue;
        }
        if (strcmp(cur, blk) != 0)
            continue;
        rows++;
        if (strlen(row) == fl && strncmp(line, row, fl) == 0) {
            /* the column's position in the header, then that field */
            const char *h = head, *f = line;
            size_t cl = strlen(col);
            int j = 0, want = -1;
            while ((h = strchr(h, ',')) != NULL) {
                h++;
                j++;
                if (strncmp(h, col, cl) == 0 && (h[cl] == ',' || !h[cl]))
                    want = j;
            }
            for (j = 0; want > 0 && j < want && f; j++)
                if ((f = strchr(f, ',')) != NULL)
                    f++;
            if (want > 0 && f) {
                *v = strtod(f, NULL);
                found = 0;
            }
        }
    }
    if (nrows)
        *nrows = rows;
    return found;
}

/* --linearize of a model whose coordinates are named like the blocks
 * (x, B): a mass on a spring k and a pendulum of length l, uncoupled, at
 * x = 0.1, B = 0.2. Read by lin_entry: the blocks have their 1 and 4
 * rows, A its closed-form entries, B (the block) its parameter columns. */
static void case_linearize_names(void)
{
    const double m = 2.0, k = 8.0, l = 0.5, g = 9.81, B = 0.2;
    char file[300];
    const char *args[] = {file, "--linearize", NULL};
    double v = NAN;
    int rows = -1;
    result res;
    if (write_scratch(file, sizeof file, "xb.eom",
                      "param m = 2 [kg]\nparam k = 8 [N/m]\n"
                      "param l = 0.5 [m]\nparam g = 9.81 [m/s^2]\n"
                      "coord x = 0.1 [m]\ncoord B = 0.2 [rad]\n"
                      "T = 1/2*m*x_dot^2 + 1/2*m*l^2*B_dot^2\n"
                      "V = 1/2*k*x^2 - m*g*l*cos(B)\n") != 0)
        return;
    run(&res, args);
    CHECK_INT(res.status, 0);
    CHECK_INT(lin_entry(res.out, "x", "value", "q:x", &v, &rows), 0);
    CHECK_NEAR(v, 0.1, 0.0);
    CHECK_INT(rows, 1);
    CHECK_INT(lin_entry(res.out, "x", "value", "q:B", &v, NULL), 0);
    CHECK_NEAR(v, B, 0.0);
    CHECK_INT(lin_entry(res.out, "A", "qd:x", "q:x", &v, &rows), 0);
    CHECK_NEAR(v, -k / m, 1e-14);
    CHECK_INT(rows, 4);
    CHECK_INT(lin_entry(res.out, "A", "q:x", "qd:x", &v, NULL), 0);
    CHECK_NEAR(v, 1.0, 0.0);
    CHECK_INT(lin_entry(res.out, "A", "qd:B", "q:B", &v, NULL), 0);
    CHECK_NEAR(v, -g * cos(B) / l, 1e-13);
    CHECK_INT(lin_entry(res.out, "A", "qd:B", "q:x", &v, NULL), 0);
    CHECK_NEAR(v, 0.0, 0.0);
    CHECK_INT(lin_entry(res.out, "B", "qd:x", "p:k", &v, &rows), 0);
    CHECK_NEAR(v, -0.1 / m, 1e-15);
    CHECK_INT(rows, 4);
    CHECK_INT(lin_entry(res.out, "B", "qd:B", "p:l", &v, NULL), 0);
    CHECK_NEAR(v, g * sin(B) / (l * l), 1e-13);
    CHECK_INT(lin_entry(res.out, "T", "qd:B", "z4", &v, &rows), 0);
    CHECK_INT(rows, 4);
    CHECK_INT(lin_entry(res.out, "eigenvalues", "4", "im", &v, &rows), 0);
    CHECK_NEAR(v, sqrt(g * cos(B) / l), 1e-12);
    CHECK_INT(rows, 4);
    result_free(&res);
}

/* The last row's value of column name in eom-run's CSV on standard out;
 * NaN when missing. */
static double last_value(const result *r, const char *name)
{
    csv c;
    char msg[256];
    double v = NAN;
    if (csv_parse(r->out, &c, msg, sizeof msg) == 0 && c.nrows > 0 &&
        csv_col(&c, name) >= 0)
        v = at(&c, c.nrows - 1, csv_col(&c, name));
    free(c.v);
    return v;
}

/* The derivatives d[i] of the last row's values of the ns states with
 * respect to the input name at base, by central differences of two whole
 * runs of fdargs with --set name=base + h and base - h (setarg, of len
 * bytes, is fdargs's --set value). Checks that both runs succeed. */
static void fd_of_runs(const char *const *fdargs, char *setarg, size_t len,
                       const char *name, double base, double h,
                       const char *const *states, int ns, double *d)
{
    result rp, rm;
    int i;
    snprintf(setarg, len, "%s=%.17g", name, base + h);
    run(&rp, fdargs);
    snprintf(setarg, len, "%s=%.17g", name, base - h);
    run(&rm, fdargs);
    CHECK_INT(rp.status, 0);
    CHECK_INT(rm.status, 0);
    for (i = 0; i < ns; i++)
        d[i] = (last_value(&rp, states[i]) - last_value(&rm, states[i])) /
               (2.0 * h);
    result_free(&rp);
    result_free(&rm);
}

/* --sensitivity: the columns' names and order, their values at the start
 * (unit vectors, zeros), and at t = 1 against central differences of
 * whole runs with --set (a parameter, an initial coordinate and an
 * initial rate); the refusals. */
static void case_sensitivity(void)
{
    static const char *const states[] = {"r", "theta", "r_dot",
                                         "theta_dot"};
    static const char *const inputs[] = {"k", "theta", "r_dot"};
    static const double base[] = {75.0, 0.5, 0.0};
    static const double step[] = {1e-3, 1e-4, 1e-4};
    const char *args[] = {"spring-pendulum", "--integrator", "adams",
                          "--rtol", "1e-11", "--atol", "1e-13", "--t-end",
                          "1", "--sample", "0.5", "--sensitivity",
                          "k,theta,r_dot", "-q", NULL};
    const char *bad_method[] = {"spring-pendulum", "--sensitivity", "k",
                                NULL};
    const char *bad_name[] = {"spring-pendulum", "--integrator", "bdf",
                              "--sensitivity", "k,nope", NULL};
    char setarg[64], col[64];
    const char *fdargs[] = {"spring-pendulum", "--integrator", "adams",
                            "--rtol", "1e-11", "--atol", "1e-13",
                            "--t-end", "1", "--sample", "0.5", "--set",
                            setarg, "-q", NULL};
    result r;
    double fd[4];
    csv c;
    char msg[256];
    int k, i;

    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.out, ",W,d(r)/d(k),d(theta)/d(k),d(r_dot)/d(k),"
                     "d(theta_dot)/d(k),d(r)/d(theta),");
    CHECK(csv_parse(r.out, &c, msg, sizeof msg) == 0);
    CHECK_INT(c.nrows, 3);
    /* at t = 0: d(x)/d(theta) is the unit vector of theta, d(x)/dk = 0 */
    CHECK(at(&c, 0, csv_col(&c, "d(theta)/d(theta)")) == 1.0);
    CHECK(at(&c, 0, csv_col(&c, "d(r)/d(theta)")) == 0.0);
    CHECK(at(&c, 0, csv_col(&c, "d(r_dot)/d(r_dot)")) == 1.0);
    CHECK(at(&c, 0, csv_col(&c, "d(r)/d(k)")) == 0.0);
    free(c.v);
    for (k = 0; k < 3; k++) {
        fd_of_runs(fdargs, setarg, sizeof setarg, inputs[k], base[k],
                   step[k], states, 4, fd);
        for (i = 0; i < 4; i++) {
            snprintf(col, sizeof col, "d(%s)/d(%s)", states[i], inputs[k]);
            /* measured within 2e-8 of each other */
            if (getenv("EOM_TEST_VERBOSE"))
                fprintf(stderr, "%s: %.10g vs %.10g\n", col,
                        last_value(&r, col), fd[i]);
            CHECK_NEAR(last_value(&r, col), fd[i], 2e-7);
        }
    }
    result_free(&r);

    run(&r, bad_method);
    CHECK_INT(r.status, 2);
    CHECK_HAS(r.err, "adams, bdf or ida");
    result_free(&r);
    run(&r, bad_name);
    CHECK_INT(r.status, 2);
    CHECK_HAS(r.err, "'nope' is not a parameter");
    result_free(&r);
}

/* --sensitivity on a model with constraints (the four-bar), by bdf and
 * ida: a length of the loop and the crank's initial angle, both of which
 * move the start (eom-run takes it onto the constraints), at t = 1
 * against central differences of whole runs with --set; at t = 0 the
 * sensitivities are tangent to the constraints, not unit vectors. */
static void case_sensitivity_constraints(void)
{
    static const char *const states[] = {"th1", "th2", "th3", "th1_dot",
                                         "th2_dot", "th3_dot"};
    static const char *const inputs[] = {"l1", "th1"};
    static const double base[] = {1.0, 1.5707963267948966};
    static const char *const methods[] = {"bdf", "ida"};
    char setarg[64], col[64];
    const char *args[] = {"four-bar", "--integrator", "bdf", "--rtol",
                          "1e-11", "--atol", "1e-13", "--t-end", "1",
                          "--sample", "0.5", "--sensitivity", "l1,th1",
                          "-q", NULL};
    const char *fdargs[] = {"four-bar", "--integrator", "erk", "--rtol",
                            "1e-13", "--atol", "1e-15", "--t-end", "1",
                            "--sample", "0.5", "--set", setarg, "-q", NULL};
    result r;
    double fd[6];
    csv c;
    char msg[256];
    int k, i, mi;
    const double h = 1e-4;

    for (mi = 0; mi < 2; mi++) {
        args[2] = methods[mi];
        run(&r, args);
        CHECK_INT(r.status, 0);
        CHECK_HAS(r.out, ",d(th1)/d(l1),d(th2)/d(l1),");
        CHECK(csv_parse(r.out, &c, msg, sizeof msg) == 0);
        CHECK_INT(c.nrows, 3);
        /* at t = 0 the crank's angle takes the loop with it */
        CHECK(fabs(at(&c, 0, csv_col(&c, "d(th1)/d(th1)")) - 1.0) > 0.1);
        CHECK(fabs(at(&c, 0, csv_col(&c, "d(th3)/d(th1)"))) > 0.1);
        free(c.v);
        for (k = 0; k < 2; k++) {
            fd_of_runs(fdargs, setarg, sizeof setarg, inputs[k], base[k], h,
                       states, 6, fd);
            for (i = 0; i < 6; i++) {
                snprintf(col, sizeof col, "d(%s)/d(%s)", states[i],
                         inputs[k]);
                if (getenv("EOM_TEST_VERBOSE"))
                    fprintf(stderr, "%s %s: %.10g vs %.10g\n",
                            methods[mi], col, last_value(&r, col), fd[i]);
                CHECK_NEAR(last_value(&r, col), fd[i], 1e-6);
            }
        }
        result_free(&r);
    }
}

/* The Whipple bicycle as docs/models.md runs it: `--modes --set v=5`
 * prints the benchmark's eigenvalues at 5 m/s (Meijaard et al. 2007:
 * -14.0783896927982, -0.775341882195845 +- 4.46486771378823i,
 * -0.322866429004087), and `--modes --sweep v=0:10:201 --plots`, run as
 * written in a fresh folder, writes 201 rows (the 101st at 5 m/s, the
 * same values) and the plot. */
static void case_bicycle_modes(void)
{
    static const double want[4][2] = {{-14.0783896927982, 0.0},
                                      {-0.775341882195845, -4.46486771378823},
                                      {-0.775341882195845, 4.46486771378823},
                                      {-0.322866429004087, 0.0}};
    const char *at5[] = {"whipple-bicycle", "--modes", "--set", "v=5", NULL};
    const char *sweep[] = {"whipple-bicycle", "--modes", "--sweep",
                           "v=0:10:201", "--plots", NULL};
    char dir[300], file[400], msg[256], *text;
    result res;
    csv c;
    int k;
    run(&res, at5);
    CHECK_INT(res.status, 0);
    CHECK_HAS(res.out, "independent states (4 of the 10 on the "
                       "constraints): lean, steer, lean_dot, steer_dot");
    for (k = 0; k < 4; k++) {
        char row[16];
        const char *p;
        char *e = NULL;
        double re, im;
        snprintf(row, sizeof row, "\n     %d  ", k + 1);
        p = res.out ? strstr(res.out, row) : NULL;
        re = p ? strtod(p + strlen(row), &e) : NAN;
        im = e ? strtod(e, NULL) : NAN;
        CHECK_NEAR(re, want[k][0], 1e-12);
        CHECK_NEAR(im, want[k][1], 1e-12);
    }
    CHECK_HAS(res.out, "the motion is stable");
    result_free(&res);

    scratch(dir, sizeof dir, "bicycle");
    CHECK(mkdir(dir, 0700) == 0);
    run_in(&res, sweep, dir);
    CHECK_INT(res.status, 0);
    result_free(&res);
    snprintf(file, sizeof file, "%s/whipple-bicycle-modes.csv", dir);
    text = read_file(file, NULL);
    CHECK(text != NULL);
    if (text && csv_parse(text, &c, msg, sizeof msg) == 0) {
        CHECK(strcmp(c.header, "v,re1,im1,re2,im2,re3,im3,re4,im4") == 0);
        CHECK_INT(c.nrows, 201);
        if (c.nrows == 201 && c.ncols == 9) {
            const double *r5 = &c.v[100 * 9];
            double got[4][2];
            int i, j;
            CHECK_NEAR(r5[0], 5.0, 1e-15);
            for (k = 0; k < 4; k++) {
                got[k][0] = r5[1 + 2 * k];
                got[k][1] = r5[2 + 2 * k];
            }
            /* columns follow curves: compare as sorted sets */
            for (i = 1; i < 4; i++)
                for (j = i; j > 0 && (got[j][0] < got[j - 1][0] ||
                                      (got[j][0] == got[j - 1][0] &&
                                       got[j][1] < got[j - 1][1]));
                     j--) {
                    double t0 = got[j][0], t1 = got[j][1];
                    got[j][0] = got[j - 1][0];
                    got[j][1] = got[j - 1][1];
                    got[j - 1][0] = t0;
                    got[j - 1][1] = t1;
                }
            for (k = 0; k < 4; k++) {
                CHECK_NEAR(got[k][0], want[k][0], 1e-12);
                CHECK_NEAR(got[k][1], want[k][1], 1e-12);
            }
        }
        free(c.v);
    } else if (text) {
        CHECK_FAIL_("whipple-bicycle-modes.csv: %s", msg);
    }
    free(text);
    if (system("command -v gnuplot > /dev/null 2>&1") == 0) {
        struct stat st;
        snprintf(file, sizeof file, "%s/whipple-bicycle-modes-eigenvalues.png",
                 dir);
        CHECK(stat(file, &st) == 0 && st.st_size > 0);
    }
}

/* --plots alone: NAME.csv and the plots in the current directory. */
static void case_plots(void)
{
    char dir[300], file[400], path[1200];
    const char *args[] = {path, "--t-end", "0.2", "--plots", "-q", NULL};
    static const char *const made[] = {
        "four-bar.csv", "four-bar-coordinates.png", "four-bar-energy.svg",
        "four-bar-residuals.png", "four-bar-probes.gp"};
    size_t k;
    result r;
    if (system("command -v gnuplot > /dev/null 2>&1") != 0) {
        fprintf(stderr, "no gnuplot on PATH: the plots are not tested\n");
        return;
    }
    model_path(path, sizeof path, "four-bar");
    scratch(dir, sizeof dir, "plots");
    CHECK(mkdir(dir, 0700) == 0);
    run_in(&r, args, dir);
    CHECK_INT(r.status, 0);
    result_free(&r);
    for (k = 0; k < sizeof made / sizeof made[0]; k++) {
        struct stat st;
        snprintf(file, sizeof file, "%s/%s", dir, made[k]);
        CHECK(stat(file, &st) == 0 && st.st_size > 0);
    }
}

/* --columns: the accelerations and multipliers of a pendulum in Cartesian
 * coordinates, x^2 + y^2 = l^2, against the closed form from the row's
 * own state: m x'' = 2 lambda x, m y'' = -m g + 2 lambda y with
 * lambda = m (g y - v^2) / (2 l^2), and the rod's pull -2 lambda l read
 * by a probe (lambda_rod); condition estimates in (0, 1]. */
static void case_columns(void)
{
    char file[300], out[300], msg[256], *text;
    const char *args[] = {file, "--columns", "multipliers,accelerations,"
                          "condition", "--t-end", "0.5", "--sample", "0.05",
                          "--integrator", "erk", "-q", "--out", out, NULL};
    const double m = 2.0, l = 1.5, g = 9.81;
    FILE *f;
    result r;
    csv c;
    int i;
    scratch(file, sizeof file, "cartesian.eom");
    scratch(out, sizeof out, "cartesian.csv");
    f = fopen(file, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs("param m = 2 [kg]\nparam l = 1.5 [m]\nparam g = 9.81 [m/s^2]\n"
          "coord x = 1.5*sin(0.7) [m] rate 0.3*cos(0.7)\n"
          "coord y = -1.5*cos(0.7) [m] rate 0.3*sin(0.7)\n"
          "T = 1/2*m*(x_dot^2 + y_dot^2)\nV = m*g*y\n"
          "constraint rod = x^2 + y^2 - l^2\n"
          "probe tension = -2*lambda_rod*l [N]\n", f);
    fclose(f);
    run(&r, args);
    CHECK_INT(r.status, 0);
    result_free(&r);
    text = read_file(out, NULL);
    CHECK(text != NULL);
    if (!text)
        return;
    if (csv_parse(text, &c, msg, sizeof msg) != 0) {
        CHECK_FAIL_("%s", msg);
        free(text);
        return;
    }
    CHECK_INT(c.nrows, 11);
    /* the constraint's columns carry its name from the file */
    CHECK(csv_col(&c, "phi_rod") > csv_col(&c, "W"));
    CHECK(csv_col(&c, "phidot_rod") == csv_col(&c, "phi_rod") + 1);
    CHECK(csv_col(&c, "phi1") < 0 && csv_col(&c, "lambda1") < 0);
    /* the groups come in one order, whatever the order asked for */
    CHECK(csv_col(&c, "x_ddot") < csv_col(&c, "lambda_rod"));
    CHECK(csv_col(&c, "lambda_rod") < csv_col(&c, "rcond_M"));
    CHECK(csv_col(&c, "rcond_S") == c.ncols - 1);
    for (i = 0; i < c.nrows; i++) {
        const double x = at(&c, i, csv_col(&c, "x"));
        const double y = at(&c, i, csv_col(&c, "y"));
        const double vx = at(&c, i, csv_col(&c, "x_dot"));
        const double vy = at(&c, i, csv_col(&c, "y_dot"));
        const double lam = m * (g * y - vx * vx - vy * vy) / (2 * l * l);
        const double rM = at(&c, i, csv_col(&c, "rcond_M"));
        const double rS = at(&c, i, csv_col(&c, "rcond_S"));
        CHECK_NEAR(at(&c, i, csv_col(&c, "lambda_rod")), lam, 1e-9);
        /* the rod's pull read by a probe through lambda_rod */
        CHECK_NEAR(at(&c, i, csv_col(&c, "tension")), -2 * lam * l, 1e-9);
        CHECK_NEAR(at(&c, i, csv_col(&c, "x_ddot")), 2 * lam * x / m, 1e-9);
        CHECK_NEAR(at(&c, i, csv_col(&c, "y_ddot")), -g + 2 * lam * y / m,
                   1e-9);
        CHECK(rM > 0 && rM <= 1 + 1e-12 && rS > 0 && rS <= 1 + 1e-12);
    }
    free(c.v);
    free(text);
    /* a group that does not exist: a usage error that names it */
    args[2] = "multipliers,forces";
    run(&r, args);
    CHECK_INT(r.status, 2);
    CHECK_HAS(r.err, "unknown group 'forces'");
    result_free(&r);
}

/* Constraint names from a file: a family's members (pin1, pin2) and a
 * vector's components (at_x ..) name the CSV's phi, phidot and lambda
 * columns, --describe and the plots' legends; the vector's third row,
 * u - a = (u - x) + (x - a), depends on two others by construction and
 * the warning at the start says so by name. */
static void case_constraint_names(void)
{
    char file[400], out[400], dir[300], msg[256], *text, *gp;
    const char *args[] = {file, "--columns", "multipliers", "--t-end", "0.2",
                          "--out", out, "--plots", NULL};
    const char *describe[] = {file, "--describe", NULL};
    static const char *const cols[] = {
        "phi_pin1", "phi_pin2", "phi_at_x", "phi_at_y", "phi_at_z",
        "phidot_pin1", "phidot_at_z", "lambda_pin1", "lambda_at_z"};
    FILE *f;
    result r;
    csv c;
    size_t k;
    scratch(dir, sizeof dir, "names");
    CHECK(mkdir(dir, 0700) == 0);
    snprintf(file, sizeof file, "%s/named.eom", dir);
    snprintf(out, sizeof out, "%s/named.csv", dir);
    f = fopen(file, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs("param mass = 1 [kg]\nparam a = 1 [m]\nparam b = 2 [m]\n"
          "param h = 0.5 [m]\n"
          "coord x = 1 [m]\ncoord y = 2 [m]\ncoord z = 0.5 [m]\n"
          "coord u = 1 [m]\ncoord w = 0 [m] rate 1\n"
          "param g = 9.81 [m/s^2]\nparam vel = 1 [m/s]\n"
          "T = mass/2*(x_dot^2 + y_dot^2 + z_dot^2 + u_dot^2 + w_dot^2)\n"
          "V = mass*g*(2*x + 3*y + 7*z + 4*u + 5*w)\n"
          "velocity constraint roll = w_dot - vel\n"
          "constraint pin[i in 1..2] = if(i == 1, x - a, y - b)\n"
          "constraint at = vec(z - h, u - x, u - a)\n"
          "probe Lroll = lambda_roll [N]\nprobe Lpin[i in 1..2] = "
          "lambda_pin[i] [N]\nprobe Lz = lambda_at_z [N]\n", f);
    fclose(f);
    run(&r, args);
    CHECK_INT(r.status, 0);
    /* one of pin1, at_y, at_z as a combination of the other two (which
     * one is the pivoting's choice); pin2 and at_x take no part */
    CHECK_HAS(r.err, "rank 5 of 6 rows");
    CHECK_HAS(r.err, "'at_z'");
    CHECK_HAS(r.err, "'at_y'");
    CHECK_HAS(r.err, "'pin1'");
    CHECK(!has(r.err, "'pin2'") && !has(r.err, "'at_x'"));
    result_free(&r);
    text = read_file(out, NULL);
    CHECK(text != NULL);
    if (text && csv_parse(text, &c, msg, sizeof msg) == 0) {
        for (k = 0; k < sizeof cols / sizeof cols[0]; k++)
            if (csv_col(&c, cols[k]) < 0)
                CHECK_FAIL_("no column %s", cols[k]);
        CHECK(csv_col(&c, "phi1") < 0);
        /* the velocity row after every holonomic one, though written
         * first */
        CHECK(csv_col(&c, "phi_roll") == csv_col(&c, "phi_at_z") + 1);
        /* probes read the multipliers of the rows they name: the same
         * numbers as the lambda columns, which are the library's; at
         * rest C^T lambda = dV/dq, so the rows that alone hold a
         * coordinate carry its force: the roll 5 m g (w), pin2 3 m g
         * (y), at_x 7 m g (z) */
        for (k = 0; k < (size_t)c.nrows; k++) {
            CHECK_NEAR(at(&c, (int)k, csv_col(&c, "Lroll")),
                       at(&c, (int)k, csv_col(&c, "lambda_roll")), 1e-12);
            CHECK_NEAR(at(&c, (int)k, csv_col(&c, "Lroll")), 5 * 9.81,
                       1e-9);
            CHECK_NEAR(at(&c, (int)k, csv_col(&c, "Lpin2")),
                       at(&c, (int)k, csv_col(&c, "lambda_pin2")), 1e-12);
            CHECK_NEAR(at(&c, (int)k, csv_col(&c, "Lz")),
                       at(&c, (int)k, csv_col(&c, "lambda_at_z")), 1e-12);
            CHECK_NEAR(at(&c, (int)k, csv_col(&c, "Lpin2")), 3 * 9.81,
                       1e-9);
            CHECK_NEAR(at(&c, (int)k, csv_col(&c, "lambda_at_x")), 7 * 9.81,
                       1e-9);
        }
        free(c.v);
    } else {
        CHECK_FAIL_("%s", text ? msg : "no CSV");
    }
    free(text);
    /* the legends of the residual and multiplier plots */
    snprintf(file + strlen(dir), sizeof file - strlen(dir),
             "/named-residuals.gp");
    gp = read_file(file, NULL);
    CHECK(gp != NULL && has(gp, "'phidot_at_y'") && !has(gp, "'phi1'"));
    free(gp);
    snprintf(file + strlen(dir), sizeof file - strlen(dir),
             "/named-multipliers.gp");
    gp = read_file(file, NULL);
    CHECK(gp != NULL && has(gp, "'lambda_pin2'"));
    free(gp);
    snprintf(file, sizeof file, "%s/named.eom", dir);
    run(&r, describe);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.out, "constraints: 6 (1 of them on the rates); CSV "
                     "columns phi_pin1, phi_pin2, phi_at_x, phi_at_y, "
                     "phi_at_z, phi_roll (rates)");
    result_free(&r);
}

/* The shipped four-bar's joint where the coupler meets the rocker, by
 * circle intersection: the coupler (l2 = 3) from the crank's tip at th1
 * (l1 = 1), the rocker (l3 = 2) from (d, 0) = (3, 0), on the branch with
 * the joint above the line from the crank's tip to the rocker's pivot
 * (the file's own start); th2 and th3 from the joint. */
static void four_bar_closed(double th1, double *th2, double *th3)
{
    const double l2 = 3.0, l3 = 2.0, d = 3.0;
    const double px = cos(th1), py = sin(th1);
    const double ex = d - px, ey = -py, e = hypot(ex, ey);
    const double a = (l2 * l2 - l3 * l3 + e * e) / (2.0 * e);
    const double h = sqrt(l2 * l2 - a * a);
    /* the left normal of the direction from the tip to the pivot */
    const double jx = px + a * ex / e - h * ey / e;
    const double jy = py + a * ey / e + h * ex / e;
    *th2 = atan2(jy - py, jx - px);
    *th3 = atan2(jy, jx - d);
}

/* --assemble: the four-bar's coupler and rocker solved from the crank
 * angle and rate given, against the closed-form geometry (the rates
 * against its central difference in th1); the crank as given, exactly; a
 * ground link too long to close names the open constraint and fails;
 * names that are not coordinates and a model without constraints are
 * usage errors. */
static void case_assemble(void)
{
    char path[1200], out[300], msg[256], *text;
    const char *args[] = {path, "--set", "th1=1.0", "--set", "th1_dot=2",
                          "--assemble", "th1", "--t-end", "0.01", "--out",
                          out, NULL};
    const char *far[] = {path, "--set", "th1=1.0", "--set", "d=10",
                         "--assemble", "th1", "--t-end", "0.01", "-q", NULL};
    const char *bad[] = {path, "--assemble", "th1,phi9", NULL};
    const char *none[] = {"spring-pendulum", "--assemble", "r", NULL};
    double th2, th3, a2, a3, b2, b3;
    const double hh = 1e-6;
    result r;
    csv c;
    model_path(path, sizeof path, "four-bar");
    scratch(out, sizeof out, "assembled.csv");
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "assembled from th1: th2 = ");
    result_free(&r);
    four_bar_closed(1.0, &th2, &th3);
    four_bar_closed(1.0 + hh, &a2, &a3);
    four_bar_closed(1.0 - hh, &b2, &b3);
    text = read_file(out, NULL);
    CHECK(text != NULL);
    if (text && csv_parse(text, &c, msg, sizeof msg) == 0) {
        CHECK(at(&c, 0, csv_col(&c, "th1")) == 1.0);
        CHECK(at(&c, 0, csv_col(&c, "th1_dot")) == 2.0);
        CHECK_NEAR(at(&c, 0, csv_col(&c, "th2")), th2, 1e-12);
        CHECK_NEAR(at(&c, 0, csv_col(&c, "th3")), th3, 1e-12);
        CHECK_NEAR(at(&c, 0, csv_col(&c, "th2_dot")),
                   2.0 * (a2 - b2) / (2 * hh), 1e-7);
        CHECK_NEAR(at(&c, 0, csv_col(&c, "th3_dot")),
                   2.0 * (a3 - b3) / (2 * hh), 1e-7);
        free(c.v);
    } else {
        CHECK_FAIL_("%s", text ? msg : "no CSV");
    }
    free(text);
    run(&r, far);
    CHECK_INT(r.status, 1);
    CHECK_HAS(r.err, "--assemble: the loop cannot close with the "
                     "coordinates held (th1): the constraint 'loop_");
    result_free(&r);
    run(&r, bad);
    CHECK_INT(r.status, 2);
    CHECK_HAS(r.err, "'phi9' is not a coordinate");
    result_free(&r);
    run(&r, none);
    CHECK_INT(r.status, 2);
    CHECK_HAS(r.err, "no constraints");
    result_free(&r);
}

/* --columns health on a parallelogram in point coordinates, whose crank
 * turns over and over (about one flat position every half second, where C
 * loses rank): the counts never decrease, start at 0, end at the
 * summary's figures; every flat position the CSV shows (y1 changes sign)
 * is counted as a singular pass, none as a branch switch, and the run
 * stays on the parallelogram (P2 = P1 + (d, 0)). */
/* The mass matrix's route in the summary (docs/cli.md): a point mass on
 * two springs in Cartesian coordinates (M constant) prints "mass matrix:
 * constant"; the same point in polar coordinates (M = diag(m, m r^2))
 * prints no such line. */
static void case_mass_route(void)
{
    static const char *const text[2] = {
        "param m = 2 [kg]\nparam k = 3 [N/m]\n"
        "coord x = 1 [m] rate 0.5\ncoord y = 0 [m]\n"
        "T = 1/2*m*(x_dot^2 + y_dot^2)\nV = k*(x^2 + y^2)\n",
        "param m = 2 [kg]\nparam k = 3 [N/m]\nparam c = 5 [J]\n"
        "coord r = 1 [m] rate 0.5\ncoord th = 0.2 [1]\n"
        "T = 1/2*m*(r_dot^2 + r^2*th_dot^2)\nV = k*r^2 + c*th^2\n"};
    char file[300], out[300];
    const char *args[] = {file, "--t-end", "0.1", "--out", out, NULL};
    int k;
    for (k = 0; k < 2; k++) {
        FILE *f;
        result r;
        scratch(file, sizeof file, k == 0 ? "cartesian.eom" : "polar.eom");
        scratch(out, sizeof out, k == 0 ? "cartesian.csv" : "polar.csv");
        f = fopen(file, "w");
        CHECK(f != NULL);
        if (!f)
            return;
        fputs(text[k], f);
        fclose(f);
        run(&r, args);
        CHECK_INT(r.status, 0);
        CHECK_INT(has(r.err, "mass matrix: constant"), k == 0);
        result_free(&r);
    }
}

static void case_health(void)
{
    char file[300], out[300], msg[256], *text;
    const char *args[] = {file, "--columns", "health", "--t-end", "5",
                          "--sample", "0.005", "--integrator", "bdf",
                          "--out", out, NULL};
    FILE *f;
    result r;
    csv c;
    long flats = 0;
    int i, j;
    scratch(file, sizeof file, "parallelogram.eom");
    scratch(out, sizeof out, "parallelogram.csv");
    f = fopen(file, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs("param m = 1 [kg]\nparam a = 1 [m]\nparam d = 2 [m]\n"
          "param g = 9.81 [m/s^2]\n"
          "coord x1 = 0 [m] rate 8\ncoord y1 = -1 [m]\n"
          "coord x2 = 2 [m] rate 8\ncoord y2 = -1 [m]\n"
          "T = 1/2*m*(x1_dot^2 + y1_dot^2 + x2_dot^2 + y2_dot^2)\n"
          "V = m*g*(y1 + y2)\n"
          "constraint crank1 = x1^2 + y1^2 - a^2\n"
          "constraint crank2 = (x2 - d)^2 + y2^2 - a^2\n"
          "constraint coupler = (x2 - x1)^2 + (y2 - y1)^2 - d^2\n", f);
    fclose(f);
    run(&r, args);
    CHECK_INT(r.status, 0);
    text = read_file(out, NULL);
    if (!text || csv_parse(text, &c, msg, sizeof msg) != 0) {
        CHECK_FAIL_("%s", text ? msg : "no CSV");
        free(text);
        result_free(&r);
        return;
    }
    CHECK_INT(c.nrows, 1001);
    for (j = 0; j < 4; j++) {
        static const char *const names[] = {"projections", "svd_solves",
                                            "singular_passes",
                                            "branch_switches"};
        const int col = csv_col(&c, names[j]);
        CHECK(col >= 0);
        if (col < 0)
            continue;
        CHECK(at(&c, 0, col) == 0.0);
        for (i = 1; i < c.nrows; i++)
            CHECK(at(&c, i, col) >= at(&c, i - 1, col));
    }
    for (i = 1; i < c.nrows; i++) {
        const double y0 = at(&c, i - 1, csv_col(&c, "y1"));
        const double y1 = at(&c, i, csv_col(&c, "y1"));
        flats += (y0 > 0.0) != (y1 > 0.0);
        CHECK(hypot(at(&c, i, csv_col(&c, "x2")) -
                        at(&c, i, csv_col(&c, "x1")) - 2.0,
                    at(&c, i, csv_col(&c, "y2")) -
                        at(&c, i, csv_col(&c, "y1"))) < 1e-6);
    }
    printf("flat positions in the CSV %ld, singular passes counted %g, "
           "branch switches %g\n", flats,
           at(&c, c.nrows - 1, csv_col(&c, "singular_passes")),
           at(&c, c.nrows - 1, csv_col(&c, "branch_switches")));
    CHECK(flats >= 8);
    CHECK(at(&c, c.nrows - 1, csv_col(&c, "singular_passes")) ==
          (double)flats);
    CHECK(at(&c, c.nrows - 1, csv_col(&c, "branch_switches")) == 0.0);
    CHECK(number_after(r.err, "projections ") ==
          at(&c, c.nrows - 1, csv_col(&c, "projections")));
    CHECK_HAS(r.err, "branch switches 0");
    CHECK(number_after(r.err, "singular positions passed ") ==
          (double)flats);
    CHECK(strstr(r.err, "handed to bdf") == NULL);
    result_free(&r);
    /* adams hands each flat pass to bdf, and the summary counts them */
    args[8] = "adams";
    run(&r, args);
    CHECK_INT(r.status, 0);
    CHECK(number_after(r.err, "singular positions passed ") ==
          (double)flats);
    CHECK(number_after(r.err, "singular stretches handed to bdf ") ==
          (double)flats);
    CHECK_HAS(r.err, "branch switches 0");
    free(c.v);
    free(text);
    result_free(&r);
}

/* Four A02 four-bar loops in natural coordinates (the model of
 * tests/eom_constraints/models/a02-natural.eom with N = 4) through the
 * four flat positions of 3.3 s: bdf's error test fails at them, so it
 * hands those stretches to erk, and adams hands them to bdf, which hands
 * them on; the summary says so, and the motion stays on its branch. */
static void case_singular_erk(void)
{
    char file[300], out[300];
    const char *args[] = {file, "--t-end", "3.3", "--sample", "0.01",
                          "--rtol", "1e-8", "--atol", "1e-8",
                          "--integrator", "bdf", "--out", out, NULL};
    const char *const method[] = {"bdf", "adams"};
    FILE *f;
    result r;
    int k;
    scratch(file, sizeof file, "a02-natural.eom");
    scratch(out, sizeof out, "a02-natural.csv");
    f = fopen(file, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs("setting N = 4 in 1..100\n"
          "param m = 1 [kg]\nparam l = 1 [m]\nparam g = 9.81 [m/s^2]\n"
          "coord x[i in 0..N] = i*l [m] rate 1\n"
          "coord y[i in 0..N] = l [m]\n"
          "T = m/6*sum(i in 0..N, x_dot[i]^2 + y_dot[i]^2) +\n"
          "    m/6*sum(i in 1..N, x_dot[i-1]^2 + x_dot[i-1]*x_dot[i] +\n"
          "        x_dot[i]^2 + y_dot[i-1]^2 + y_dot[i-1]*y_dot[i] +\n"
          "        y_dot[i]^2)\n"
          "V = m*g*(sum(i in 0..N, y[i]/2) + sum(i in 1..N, "
          "(y[i-1] + y[i])/2))\n"
          "constraint crank[i in 0..N] = (x[i] - i*l)^2 + y[i]^2 - l^2\n"
          "constraint coupler[i in 1..N] = (x[i] - x[i-1])^2 + "
          "(y[i] - y[i-1])^2 - l^2\n", f);
    fclose(f);
    for (k = 0; k < 2; k++) {
        char said[128];
        args[10] = method[k];
        run(&r, args);
        CHECK_INT(r.status, 0);
        CHECK(number_after(r.err, "singular positions passed ") == 4.0);
        CHECK_HAS(r.err, "branch switches 0");
        CHECK(number_after(r.err, "singular stretches handed to erk ") >=
              1.0);
        snprintf(said, sizeof said, "(%s could not pass them%s;", method[k],
                 k == 0 ? "" : ", nor bdf");
        CHECK_HAS(r.err, said);
        result_free(&r);
    }
}

/* A tolerance beyond the floor of bdf's error test is named in the
 * summary with what the run keeps instead, (3e-16 / 0.02)^(5/6) = 3.0e-12
 * (docs/integrators.md); a reachable one is not. */
static void case_tolerance(void)
{
    const char *tight[] = {"spring-pendulum", "--integrator", "bdf",
                           "--rtol", "1e-12", "--atol", "1e-12",
                           "--t-end", "0.1", "-o", "/dev/null", NULL};
    const char *loose[] = {"spring-pendulum", "--integrator", "bdf",
                           "--t-end", "0.1", "-o", "/dev/null", NULL};
    result r;
    run(&r, tight);
    CHECK_INT(r.status, 0);
    CHECK_NEAR(number_after(r.err, "keeps the error near "),
               pow(3e-16 / 0.02, 5.0 / 6.0), 1e-13);
    result_free(&r);
    run(&r, loose);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "steps ");
    CHECK(strstr(r.err, "tolerance:") == NULL);
    result_free(&r);
}

/* fc equals the file at path b. */
static int fb_matches(const char *fc, const char *b)
{
    char *fb = read_file(b, NULL);
    const int same = fb && strcmp(fb, fc) == 0;
    free(fb);
    return same;
}

/* --compiled: the interpreter's CSV, byte for byte (the double pendulum,
 * and the closed chain with its constraints); the second run loads from
 * the cache; without a compiler (none on PATH, or CC naming none) a
 * warning and the same CSV. */
static void case_compiled(void)
{
    char cache[512], cache2[512], a[512], b[512], c[512];
    const char *comp[] = {"double-pendulum", "--compiled", "--t-end", "1",
                          "--integrator", "erk", "-o", a, NULL};
    const char *interp[] = {"double-pendulum", "--t-end", "1",
                            "--integrator", "erk", "-o", b, NULL};
    const char *nocc[] = {"double-pendulum", "--compiled", "--t-end", "1",
                          "--integrator", "erk", "-o", c, NULL};
    char *fa, *fb, *fc;
    result r;
    scratch(cache, sizeof cache, "cache");
    scratch(cache2, sizeof cache2, "cache2");
    scratch(a, sizeof a, "compiled.csv");
    scratch(b, sizeof b, "interpreted.csv");
    scratch(c, sizeof c, "nocc.csv");
    setenv("AUTOEOM_CACHE_DIR", cache, 1);
    run(&r, comp);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "compiled tapes in use (0 of ");
    result_free(&r);
    run(&r, interp);
    CHECK_INT(r.status, 0);
    result_free(&r);
    run(&r, comp);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "compiled tapes in use (2 of 2 from the cache");
    result_free(&r);
    /* no compiler on PATH, an empty cache: the run goes on interpreted */
    setenv("AUTOEOM_CACHE_DIR", cache2, 1);
    unsetenv("CC");
    run_path(&r, nocc, "/nonexistent");
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "warning: compiled tapes are not in use");
    CHECK_HAS(r.err, "cannot run the C compiler 'cc'");
    result_free(&r);
    fc = read_file(c, NULL);
    CHECK(fc && fb_matches(fc, b));
    free(fc);
    /* CC naming no compiler */
    setenv("AUTOEOM_CACHE_DIR", cache2, 1);
    setenv("CC", "/nonexistent/bin/cc", 1);
    run(&r, nocc);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "warning: compiled tapes are not in use");
    CHECK_HAS(r.err, "/nonexistent/bin/cc");
    result_free(&r);
    unsetenv("CC");
    fa = read_file(a, NULL);
    fb = read_file(b, NULL);
    fc = read_file(c, NULL);
    CHECK(fa && fb && fc && strlen(fa) > 1000);
    CHECK(fa && fb && strcmp(fa, fb) == 0);
    CHECK(fc && fb && strcmp(fc, fb) == 0);
    free(fa);
    free(fb);
    free(fc);
    /* the closed chain: its constraints' Jacobian and gamma compiled too */
    {
        const char *ccomp[] = {"closed-chain", "--compiled", "--t-end", "0.2",
                               "-o", a, NULL};
        const char *cint[] = {"closed-chain", "--t-end", "0.2", "-o", b,
                              NULL};
        setenv("AUTOEOM_CACHE_DIR", cache, 1);
        run(&r, ccomp);
        CHECK_INT(r.status, 0);
        CHECK_HAS(r.err, "compiled tapes in use (0 of 4");
        result_free(&r);
        run(&r, cint);
        CHECK_INT(r.status, 0);
        result_free(&r);
        fa = read_file(a, NULL);
        fb = read_file(b, NULL);
        CHECK(fa && fb && strlen(fa) > 1000);
        CHECK(fa && fb && strcmp(fa, fb) == 0);
        free(fa);
        free(fb);
    }
}

static const struct {
    const char *name;
    void (*fn)(void);
} cases[] = {
    {"model_compiled", case_compiled},
    {"model_columns", case_columns},
    {"model_constraint_names", case_constraint_names},
    {"model_assemble", case_assemble},
    {"model_linearize", case_linearize},
    {"model_linearize_names", case_linearize_names},
    {"model_sensitivity", case_sensitivity},
    {"model_sensitivity_constraints", case_sensitivity_constraints},
    {"model_health", case_health},
    {"model_mass_route", case_mass_route},
    {"model_tolerance", case_tolerance},
    {"model_singular_erk", case_singular_erk},
    {"model_list", case_list},   {"model_describe", case_describe},
    {"model_csv", case_csv},     {"model_error", case_error},
    {"model_modes", case_modes}, {"model_plots", case_plots},
    {"model_modes_forces", case_modes_forces},
    {"model_modes_steady", case_modes_steady},
    {"model_bicycle_modes", case_bicycle_modes},
};

int main(int argc, char **argv)
{
    static char program[PATH_MAX], models_dir[PATH_MAX];
    size_t i;
    int found = 0;
    if (argc < 4) {
        fprintf(stderr, "usage: test_cli_models EOM_RUN MODELS_DIR CASE\n");
        return EXIT_FAILURE;
    }
    /* absolute: the plots case runs the program in another directory */
    cli_program = realpath(argv[1], program);
    models = realpath(argv[2], models_dir);
    if (!cli_program || !models) {
        fprintf(stderr, "test_cli_models: %s or %s not found\n", argv[1],
                argv[2]);
        return EXIT_FAILURE;
    }
    if (cli_setup() != 0)
        return EXIT_FAILURE;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++)
        if (strcmp(cases[i].name, argv[3]) == 0) {
            cases[i].fn();
            found = 1;
        }
    cli_cleanup();
    if (!found) {
        fprintf(stderr, "test_cli_models: unknown case '%s'\n", argv[3]);
        return EXIT_FAILURE;
    }
    CHECK_DONE();
}
