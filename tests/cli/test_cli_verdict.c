/* test_cli_verdict.c - the health verdict of eom-run (docs/run.md, "The
 * verdict"): a run that ends wrong exits with status 3 and names the
 * measure; a healthy run of every shipped model exits 0.
 *
 *   verdict_andrews    Andrews' squeezing mechanism (Hairer and Wanner,
 *                      Solving ODEs II, VII.7: the seven-body benchmark,
 *                      its data, mass matrix and constraints as published)
 *                      to t = 0.03: rk4 at its fixed step 1e-3 ends far
 *                      from the published reference solution with no error,
 *                      and its verdict names the energy drift; erk ends on
 *                      the reference, healthy
 *   verdict_baumgarte  two four-bar loops of the IFToMM A02 benchmark in
 *                      angles, through their flat positions, with
 *                      projection off and Baumgarte's terms instead: E + W
 *                      drifts by percents, status 3; projected, healthy
 *   verdict_shipped    every model in models/ with its defaults: status 0,
 *                      "verdict: healthy"
 *   verdict_ensemble   eom-ensemble's runs of the squeezer: rk4's rows
 *                      unhealthy, status 3; erk, its default, healthy
 *   singular_top       a heavy top in Euler angles through the vertical,
 *                      where its mass matrix is singular: every method
 *                      stops within a few hundred steps naming the
 *                      coordinate (phi) and the time
 *
 * usage: test_cli_verdict EOM_RUN MODELS_DIR CASE (EOM_ENSEMBLE for
 * verdict_ensemble) */
#define _XOPEN_SOURCE 700 /* realpath */
#include <dirent.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "cli_support.h"

static const char *models;

static const char andrews[] =
    "# Andrews' squeezing mechanism (Hairer & Wanner, Solving ODEs II, VII.7; Schiehlen's benchmark)\n"
    "units off\n"
    "param m1 = .04325\n"
    "param m2 = .00365\n"
    "param m3 = .02373\n"
    "param m4 = .00706\n"
    "param m5 = .07050\n"
    "param m6 = .00706\n"
    "param m7 = .05498\n"
    "param i1 = 2.194e-6\n"
    "param i2 = 4.410e-7\n"
    "param i3 = 5.255e-6\n"
    "param i4 = 5.667e-7\n"
    "param i5 = 1.169e-5\n"
    "param i6 = 5.667e-7\n"
    "param i7 = 1.912e-5\n"
    "param xa = -.06934\n"
    "param ya = -.00227\n"
    "param xb = -.03635\n"
    "param yb = .03273\n"
    "param xc = .014\n"
    "param yc = .072\n"
    "param d = 28e-3\n"
    "param da = 115e-4\n"
    "param e = 2e-2\n"
    "param ea = 1421e-5\n"
    "param rr = 7e-3\n"
    "param ra = 92e-5\n"
    "param ss = 35e-3\n"
    "param sa = 1874e-5\n"
    "param sb = 1043e-5\n"
    "param sc = 18e-3\n"
    "param sd = 2e-2\n"
    "param ta = 2308e-5\n"
    "param tb = 916e-5\n"
    "param u = 4e-2\n"
    "param ua = 1228e-5\n"
    "param ub = 449e-5\n"
    "param zf = 2e-2\n"
    "param zt = 4e-2\n"
    "param fa = 1421e-5\n"
    "param mom = 33e-3\n"
    "param c0 = 4530\n"
    "param lo = 0.07785\n"
    "\n"
    "coord beta = -0.0617138900142764496358948458001\n"
    "coord Theta = 0\n"
    "coord gamma = 0.455279819163070380255912382449\n"
    "coord Phi = 0.222668390165885884674473185609\n"
    "coord delta = 0.487364979543842550225598953530\n"
    "coord Omega = -0.222668390165885884674473185609\n"
    "coord epsilon = 1.23054744454982119249735015568\n"
    "\n"
    "# the mass matrix of the reference, as a quadratic form in the rates\n"
    "T = 1/2*(m1*ra^2 + m2*(rr^2 - 2*da*rr*cos(Theta) + da^2) + i1 + i2)*beta_dot^2 +\n"
    "    (m2*(da^2 - da*rr*cos(Theta)) + i2)*beta_dot*Theta_dot +\n"
    "    1/2*(m2*da^2 + i2)*Theta_dot^2 +\n"
    "    1/2*(m3*(sa^2 + sb^2) + i3)*gamma_dot^2 +\n"
    "    1/2*(m4*(e - ea)^2 + i4)*Phi_dot^2 +\n"
    "    (m4*((e - ea)^2 + zt*(e - ea)*sin(Phi)) + i4)*Phi_dot*delta_dot +\n"
    "    1/2*(m4*(zt^2 + 2*zt*(e - ea)*sin(Phi) + (e - ea)^2) + m5*(ta^2 + tb^2) + i4 + i5)*delta_dot^2 +\n"
    "    1/2*(m6*(zf - fa)^2 + i6)*Omega_dot^2 +\n"
    "    (m6*((zf - fa)^2 - u*(zf - fa)*sin(Omega)) + i6)*Omega_dot*epsilon_dot +\n"
    "    1/2*(m6*((zf - fa)^2 - 2*u*(zf - fa)*sin(Omega) + u^2) + m7*(ua^2 + ub^2) + i6 + i7)*epsilon_dot^2\n"
    "\n"
    "# the spring from (xc, yc) to its point on body 3\n"
    "xd = sd*cos(gamma) + sc*sin(gamma) + xb\n"
    "yd = sd*sin(gamma) - sc*cos(gamma) + yb\n"
    "V = 1/2*c0*(sqrt((xd - xc)^2 + (yd - yc)^2) - lo)^2\n"
    "\n"
    "force beta = mom\n"
    "\n"
    "constraint g1 = rr*cos(beta) - d*cos(beta + Theta) - ss*sin(gamma) - xb\n"
    "constraint g2 = rr*sin(beta) - d*sin(beta + Theta) + ss*cos(gamma) - yb\n"
    "constraint g3 = rr*cos(beta) - d*cos(beta + Theta) - e*sin(Phi + delta) - zt*cos(delta) - xa\n"
    "constraint g4 = rr*sin(beta) - d*sin(beta + Theta) + e*cos(Phi + delta) - zt*sin(delta) - ya\n"
    "constraint g5 = rr*cos(beta) - d*cos(beta + Theta) - zf*cos(Omega + epsilon) - u*sin(epsilon) - xa\n"
    "constraint g6 = rr*sin(beta) - d*sin(beta + Theta) - zf*sin(Omega + epsilon) + u*cos(epsilon) - ya\n";

/* Two loops of A02 (IFToMM's N four-bar benchmark) in absolute angles:
 * N + 1 cranks of length l pinned at (i l, 0), N couplers, started upright
 * with the cranks turning at 1 rad/s; the flat positions come once a
 * half turn. */
static const char a02[] =
    "setting N = 2 in 1..10\n"
    "param m = 1 [kg]\n"
    "param l = 1 [m]\n"
    "param g = 9.81 [m/s^2]\n"
    "coord th[i in 0..N] = pi/2 [rad] rate -1\n"
    "coord ph[i in 1..N] = 0 [rad]\n"
    "bx[i in 0..N] = i*l + l*cos(th[i])\n"
    "by[i in 0..N] = l*sin(th[i])\n"
    "vx[i in 0..N] = -l*sin(th[i])*th_dot[i]\n"
    "vy[i in 0..N] = l*cos(th[i])*th_dot[i]\n"
    "cy[i in 1..N] = by[i-1] + l/2*sin(ph[i])\n"
    "cvx[i in 1..N] = vx[i-1] - l/2*sin(ph[i])*ph_dot[i]\n"
    "cvy[i in 1..N] = vy[i-1] + l/2*cos(ph[i])*ph_dot[i]\n"
    "T = m*l^2/6*sum(i in 0..N, th_dot[i]^2) +\n"
    "    sum(i in 1..N, m/2*(cvx[i]^2 + cvy[i]^2) + m*l^2/24*ph_dot[i]^2)\n"
    "V = m*g*(sum(i in 0..N, by[i]/2) + sum(i in 1..N, cy[i]))\n"
    "constraint loop_x[i in 1..N] = bx[i-1] + l*cos(ph[i]) - bx[i]\n"
    "constraint loop_y[i in 1..N] = by[i-1] + l*sin(ph[i]) - by[i]\n";

/* A heavy top in Euler angles (z-x-z: precession psi, nutation theta,
 * spin phi), its centre of mass above the pivot, started at theta = 0.3
 * falling towards the vertical with p_psi = p_phi, so that it passes
 * through theta = 0 (psi's rate from C phi_dot (1 - cos) / (A sin^2 + C
 * cos (cos - 1))). There psi and phi turn about one axis: the mass matrix
 * is singular, phi's leading minor of order 3 vanishing, at t = 0.06367. */
static const char top[] =
    "param m = 1 [kg]\n"
    "param l = 0.1 [m]\n"
    "param A = 0.02 [kg m^2]\n"
    "param C = 0.01 [kg m^2]\n"
    "param g = 9.81 [m/s^2]\n"
    "coord psi = 0 [rad] rate 1.691854723953737\n"
    "coord theta = 0.3 [rad] rate -5\n"
    "coord phi = 0 [rad] rate 5\n"
    "Rot = rotz(psi)*rotx(theta)*rotz(phi)\n"
    "w = angvel_body(Rot)\n"
    "T = 1/2*dot(w, diag(A, A, C)*w)\n"
    "V = m*g*(Rot*vec(0, 0, l)).z\n";

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

/* The last row of the CSV at path into *c (freed by the caller). */
static int read_csv(const char *path, csv *c)
{
    char msg[512], *text = read_file(path, NULL);
    memset(c, 0, sizeof *c);
    check_count_++;
    if (!text) {
        CHECK_FAIL_("no CSV at %s", path);
        return -1;
    }
    if (csv_parse(text, c, msg, sizeof msg) != 0) {
        CHECK_FAIL_("%s", msg);
        free(text);
        return -1;
    }
    free(text);
    return c->nrows > 0 ? 0 : -1;
}

static void case_andrews(void)
{
    /* the reference solution at t = 0.03 (Hairer and Wanner; the test set
     * for IVP solvers of Bari, problem "andrews"): beta, Theta */
    const double beta_ref = 15.81077119629904, theta_ref = -15.75637105984298;
    char file[300], out[300];
    const char *rk4[] = {file, "--integrator", "rk4", "--t-end", "0.03",
                         "--out", out, NULL};
    const char *rk4_ok[] = {file, "--integrator", "rk4", "--t-end", "0.03",
                            "--accept-unhealthy", "-q", "--out", out, NULL};
    const char *erk[] = {file, "--t-end", "0.03", "--out", out, NULL};
    result r;
    csv c;
    if (write_scratch(file, sizeof file, "andrews.eom", andrews) != 0)
        return;
    scratch(out, sizeof out, "andrews.csv");

    /* rk4: wrong by most of a radian, and the verdict says so */
    run(&r, rk4);
    CHECK_INT(r.status, 3);
    CHECK_HAS(r.err, "verdict: unhealthy: relative energy drift");
    CHECK_HAS(r.err, "the run is unhealthy: relative energy drift");
    CHECK_HAS(r.err, "exceeds 1e-05 (1000 x the run's tolerance 1e-08)");
    CHECK_HAS(r.err, "--accept-unhealthy");
    CHECK(number_after(r.err, "the run is unhealthy: relative energy "
                              "drift") > 0.01);
    /* the rows are whole and in place, not FILE.partial */
    if (read_csv(out, &c) == 0) {
        const int b = csv_col(&c, "beta"), th = csv_col(&c, "Theta");
        CHECK_NEAR(at(&c, c.nrows - 1, 0), 0.03, 1e-15);
        CHECK(fabs(at(&c, c.nrows - 1, th) - theta_ref) > 0.5);
        CHECK(fabs(at(&c, c.nrows - 1, b) - beta_ref) > 0.5);
    }
    free(c.v);
    result_free(&r);

    run(&r, rk4_ok);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "the run is unhealthy: relative energy drift");
    CHECK_HAS(r.err, "accepted as asked");
    result_free(&r);

    /* erk, eom-run's default, on the reference and healthy */
    run(&r, erk);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "verdict: healthy");
    if (read_csv(out, &c) == 0) {
        CHECK_NEAR(at(&c, c.nrows - 1, csv_col(&c, "beta")), beta_ref, 1e-6);
        CHECK_NEAR(at(&c, c.nrows - 1, csv_col(&c, "Theta")), theta_ref,
                   1e-6);
    }
    free(c.v);
    result_free(&r);
    unlink(out);
    unlink(file);
}

static void case_baumgarte(void)
{
    char file[300], out[300];
    const char *baum[] = {file, "--integrator", "erk", "--no-project",
                          "--baumgarte", "10,10", "--t-end", "20",
                          "--sample", "0.1", "--out", out, NULL};
    /* projected, to 10 s: past six flat positions */
    const char *proj[] = {file, "--t-end", "10", "--sample", "0.1",
                          "--out", out, NULL};
    result r;
    if (write_scratch(file, sizeof file, "a02.eom", a02) != 0)
        return;
    scratch(out, sizeof out, "a02.csv");
    run(&r, baum);
    CHECK_INT(r.status, 3);
    CHECK_HAS(r.err, "the run is unhealthy: relative energy drift");
    /* E + W off by percents */
    CHECK(number_after(r.err, "the run is unhealthy: relative energy "
                              "drift") > 0.005);
    result_free(&r);
    run(&r, proj);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "verdict: healthy");
    CHECK_HAS(r.err, "branch switches 0");
    result_free(&r);
    unlink(out);
    unlink(file);
}

static void case_shipped(void)
{
    DIR *dir = opendir(models);
    struct dirent *e;
    int count = 0;
    CHECK(dir != NULL);
    if (!dir)
        return;
    while ((e = readdir(dir)) != NULL) {
        const size_t len = strlen(e->d_name);
        char file[PATH_MAX + 300], out[300];
        const char *args[] = {file, "--out", out, NULL};
        result r;
        if (len < 5 || strcmp(e->d_name + len - 4, ".eom") != 0)
            continue;
        snprintf(file, sizeof file, "%s/%s", models, e->d_name);
        scratch(out, sizeof out, "shipped.csv");
        run(&r, args);
        check_count_++;
        if (r.status != 0 || !has(r.err, "verdict: healthy"))
            CHECK_FAIL_("%s: status %d:\n%s", e->d_name, r.status, r.err);
        result_free(&r);
        unlink(out);
        count++;
    }
    closedir(dir);
    CHECK(count >= 11);
}

/* eom-ensemble (the program under test for this case): each run judged
 * as eom-run judges it, status unhealthy in its row with the measure in
 * its message, exit status 3; erk, the default, healthy; a summary with
 * unhealthy rows resumed. */
static void case_ensemble(void)
{
    char file[300], out[300], *text;
    const char *rk4[] = {file, "--sweep", "mom=0.03:0.033:2", "--t-end",
                         "0.03", "--integrator", "rk4", "--threads", "1",
                         "--out", out, NULL, NULL};
    const char *dflt[] = {file, "--sweep", "mom=0.03:0.033:2", "--t-end",
                          "0.03", "--threads", "1", "--out", out, NULL};
    result r;
    if (write_scratch(file, sizeof file, "andrews.eom", andrews) != 0)
        return;
    scratch(out, sizeof out, "sum.csv");
    run(&r, rk4);
    CHECK_INT(r.status, 3);
    CHECK_HAS(r.err, "2 runs unhealthy");
    text = read_file(out, NULL);
    CHECK_HAS(text, ",unhealthy,");
    CHECK_HAS(text, "\"unhealthy: relative energy drift 0.0");
    CHECK(!has(text, ",ok,"));
    free(text);
    result_free(&r);
    /* resumed: the unhealthy rows are rows of this ensemble */
    rk4[11] = "--resume";
    run(&r, rk4);
    CHECK_INT(r.status, 0);
    result_free(&r);
    rk4[11] = "--accept-unhealthy";
    run(&r, rk4);
    CHECK_INT(r.status, 0);
    CHECK_HAS(r.err, "accepted as asked");
    result_free(&r);
    run(&r, dflt);
    CHECK_INT(r.status, 0);
    text = read_file(out, NULL);
    CHECK_HAS(text, ",ok,");
    CHECK(!has(text, "unhealthy"));
    free(text);
    text = read_file(strcat(out, ".inputs"), NULL);
    CHECK_HAS(text, "--integrator erk\n");
    free(text);
    result_free(&r);
}

/* The top through the vertical with every method: a prompt stop (a few
 * hundred steps, where bdf took 10^7 and erk 1.8 million) whose message
 * names the coordinate and the time. rk4 steps over the vertical unless
 * a step ends on it: its step here divides the time of the vertical. */
static void case_singular(void)
{
    static const char *methods[] = {"erk", "adams", "bdf", "esdirk", "imex",
                                    "ida", "rk4"};
    char file[300], out[300];
    size_t k;
    if (write_scratch(file, sizeof file, "top.eom", top) != 0)
        return;
    scratch(out, sizeof out, "top.csv");
    for (k = 0; k < sizeof methods / sizeof methods[0]; k++) {
        const int rk4 = strcmp(methods[k], "rk4") == 0;
        const char *args[] = {file, "--integrator", methods[k], "--t-end",
                              "1", "--max-steps", "100000", "--sample",
                              rk4 ? "0.0636704" : "0.01", "--dt",
                              rk4 ? "0.00099485" : "0.001", "--out", out,
                              NULL};
        double steps;
        result r;
        run(&r, args);
        check_count_++;
        steps = number_after(r.err, "  steps ");
        if (r.status != 1 || !has(r.err, "singular") ||
            !has(r.err, "the coordinate 'phi' (leading minor of order 3)") ||
            !has(r.err, "at t = 0.0636") || !(steps < 2000))
            CHECK_FAIL_("%s: status %d, %g steps:\n%s", methods[k],
                        r.status, steps, r.err);
        result_free(&r);
    }
    {
        /* started on the vertical: refused at once, by name */
        char file0[300];
        const char *args[] = {file0, "--out", out, NULL};
        result r;
        char text[sizeof top];
        strcpy(text, top);
        memcpy(strstr(text, "theta = 0.3"), "theta = 0  ", 11);
        if (write_scratch(file0, sizeof file0, "top0.eom", text) != 0)
            return;
        run(&r, args);
        CHECK_INT(r.status, 1);
        CHECK_HAS(r.err, "at t = 0: the mass matrix is singular to working "
                         "precision: the coordinate 'phi' (leading minor of "
                         "order 3)");
        result_free(&r);
        unlink(file0);
    }
    unlink(out);
    unlink(file);
}

static const struct {
    const char *name;
    void (*fn)(void);
} cases[] = {
    {"singular_top", case_singular},
    {"verdict_ensemble", case_ensemble},
    {"verdict_andrews", case_andrews},
    {"verdict_baumgarte", case_baumgarte},
    {"verdict_shipped", case_shipped},
};

int main(int argc, char **argv)
{
    static char program[PATH_MAX], models_dir[PATH_MAX];
    size_t i;
    int found = 0;
    if (argc < 4) {
        fprintf(stderr, "usage: test_cli_verdict EOM_RUN MODELS_DIR CASE\n");
        return EXIT_FAILURE;
    }
    cli_program = realpath(argv[1], program);
    models = realpath(argv[2], models_dir);
    if (!cli_program || !models) {
        fprintf(stderr, "test_cli_verdict: %s or %s not found\n", argv[1],
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
        fprintf(stderr, "test_cli_verdict: unknown case '%s'\n", argv[3]);
        return EXIT_FAILURE;
    }
    CHECK_DONE();
}
