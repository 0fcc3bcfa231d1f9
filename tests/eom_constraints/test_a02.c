/* test_a02.c - the IFToMM benchmark A02 (N four-bar loops in a row) at
 * the benchmark's size, N = 40, through its flat singular positions, in
 * natural coordinates and in absolute angles (the model files in
 * models/ beside this file), against the exact motion.
 *
 * On the parallelogram branch every crank has one angle th(t) and the
 * couplers translate, so th obeys one pendulum equation,
 *     I th'' = -G cos th,   I = m l^2 ((N + 1) / 3 + N),
 *                           G = m g l ((N + 1) / 2 + N),
 * from th = pi/2, th' = -1 rad/s (B_0 along +x at 1 m/s). The reference
 * is that equation integrated by a classical RK4 of this file's own at
 * 2e-5 s (its energy checked constant to 1e-11), not by libeom. The
 * cranks lie flat each time th crosses a multiple of pi: 20 times in the
 * benchmark's 20 s, the first at t = 0.7216 s.
 *
 * Each run is checked against it at 400 outputs (the benchmark's
 * sampling, every 0.05 s): the largest distance of B_0 from its exact
 * place (the benchmark's tolerances on B_0: 1e-1 and, for high
 * precision, 1e-3), of every crank tip (a run that came out on another
 * assembly branch at a flat position has cranks that differ), and the
 * branch monitor's count of switches (none) and passes.
 *
 * usage: test_a02 MODELS_DIR [quick|full]
 *   quick  the default suite: the natural form with erk, the angle form
 *          with bdf and with adams (which hands each flat position to
 *          bdf), to t = 3.3 s (four flat positions; about 10 s of
 *          processor time)
 *          and, with 4 loops in natural coordinates, bdf's and adams'
 *          stop at a flat position, whose message names erk
 *   full   the methods that pass, on both forms, to 20 s (bench-hard's
 *          a02 section runs every method and reports the others) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"
#include "eom/model_file.h"

#define PI_ 3.14159265358979323846
#define NLOOPS 40
#define NOUT_PER_S 20 /* the benchmark's 400 outputs in 20 s */

static const double L = 1.0, G = 9.81;

/* th'' = -a cos th for the parallelogram branch */
static double accel_coef(int N)
{
    return G / L * ((N + 1) / 2.0 + N) / ((N + 1) / 3.0 + N);
}

/* Advance (th, w) by dt with RK4 steps of at most 2e-5 s. */
static void pendulum(double a, double *th, double *w, double dt)
{
    const long k = (long)ceil(dt / 2e-5);
    const double h = dt / (double)k;
    long i;
    for (i = 0; i < k; i++) {
        const double t0 = *th, w0 = *w;
        const double k1t = w0, k1w = -a * cos(t0);
        const double k2t = w0 + h / 2 * k1w, k2w = -a * cos(t0 + h / 2 * k1t);
        const double k3t = w0 + h / 2 * k2w, k3w = -a * cos(t0 + h / 2 * k2t);
        const double k4t = w0 + h * k3w, k4w = -a * cos(t0 + h * k3t);
        *th = t0 + h / 6 * (k1t + 2 * k2t + 2 * k3t + k4t);
        *w = w0 + h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
    }
}

typedef struct result {
    int status;
    double t_reached, err_b0, err_all, wall;
    long passes, switches, steps;
} result;

/* Run the model at path (N loops) with method to t_end. */
static void run(const char *path, int natural, eom_method method,
                double t_end, result *r)
{
    const int N = NLOOPS, nout = (int)lround(t_end * NOUT_PER_S);
    const double a = accel_coef(N);
    char err[1024];
    eom_file *f = NULL;
    eom_model *mo = NULL;
    eom_system *s = NULL;
    eom_integ *it = NULL;
    eom_opts o;
    eom_stats st;
    double *x = NULL, th = PI_ / 2, w = -1.0, tprev = 0.0, e0;
    int n = 0, k, i;
    memset(r, 0, sizeof *r);
    r->status = -1;
    if (eom_file_read(&f, path, err, sizeof err) != EOM_OK ||
        eom_file_set_setting(f, "N", N, err, sizeof err) != EOM_OK ||
        eom_file_build(f, &mo, err, sizeof err) != EOM_OK ||
        eom_system_new(&s, mo, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "%s: %s\n", path, err);
        goto done;
    }
    n = eom_system_ncoords(s);
    CHECK_INT(n, natural ? 2 * (N + 1) : 2 * N + 1);
    CHECK_INT(eom_system_nconstraints(s), natural ? 2 * N + 1 : 2 * N);
    x = malloc(2 * (size_t)n * sizeof *x);
    if (!x || eom_initial_state(s, x) != EOM_OK)
        goto done;
    eom_opts_default(&o);
    o.method = method;
    o.rtol = o.atol = 1e-8;
    o.dt = 1e-3;
    if ((r->status = eom_integ_new(&it, s, &o, 0.0, x)) != EOM_OK) {
        fprintf(stderr, "%s %s: %s\n", path, eom_method_name(method),
                eom_system_errmsg(s));
        goto done;
    }
    e0 = 0.5 * w * w + a * sin(th);
    for (k = 1; k <= nout; k++) {
        const double t = t_end * k / nout;
        double bx, by;
        r->status = eom_integ_advance(it, t, x, NULL);
        if (r->status != EOM_OK) {
            fprintf(stderr, "%s %s: %s\n", path, eom_method_name(method),
                    eom_integ_errmsg(it));
            break;
        }
        r->t_reached = t;
        pendulum(a, &th, &w, t - tprev);
        tprev = t;
        /* the reference keeps its own first integral */
        CHECK(fabs(0.5 * w * w + a * sin(th) - e0) < 1e-11 * fabs(e0));
        bx = natural ? x[0] : L * cos(x[0]);
        by = natural ? x[N + 1] : L * sin(x[0]);
        r->err_b0 = fmax(r->err_b0, hypot(bx - L * cos(th), by - L * sin(th)));
        for (i = 0; i <= N; i++)
            r->err_all = fmax(
                r->err_all,
                natural ? hypot(x[i] - i * L - L * cos(th),
                                x[N + 1 + i] - L * sin(th))
                        : L * fabs(x[i] - th));
        /* the couplers stay level */
        for (i = N + 1; !natural && i < n; i++)
            r->err_all = fmax(r->err_all, L * fabs(x[i]));
    }
    if (eom_integ_stats(it, &st) == EOM_OK) {
        r->passes = st.singular_passes;
        r->switches = st.branch_switches;
        r->steps = st.steps;
        r->wall = st.wall_time;
    }
done:
    eom_integ_free(&it);
    eom_system_free(&s);
    eom_model_free(&mo);
    eom_file_free(&f);
    free(x);
}

/* flat positions of the exact motion in (0, t_end] */
static int flats_until(double t_end)
{
    const double a = accel_coef(NLOOPS);
    double th = PI_ / 2, w = -1.0, t = 0.0;
    int count = 0;
    while (t < t_end) {
        const double before = floor(th / PI_);
        pendulum(a, &th, &w, 1e-3);
        t += 1e-3;
        count += floor(th / PI_) != before;
    }
    return count;
}

/* bdf cannot pass the flat positions in natural coordinates (its error
 * test fails with steps of 5e-16 s; adams and ida hand them to bdf): with
 * 4 loops it stops at the second, t = 1.236 s, and the message names the
 * method that passes them. */
static void bdf_refusal(const char *dir)
{
    static const eom_method methods[] = {EOM_BDF, EOM_ADAMS};
    char err[1024], path[4096];
    int k;
    snprintf(path, sizeof path, "%s/a02-natural.eom", dir);
    for (k = 0; k < 2; k++) {
        eom_file *f = NULL;
        eom_model *mo = NULL;
        eom_system *s = NULL;
        eom_integ *it = NULL;
        eom_opts o;
        double x[64];
        int rc = EOM_OK, i;
        if (eom_file_read(&f, path, err, sizeof err) != EOM_OK ||
            eom_file_set_setting(f, "N", 4, err, sizeof err) != EOM_OK ||
            eom_file_build(f, &mo, err, sizeof err) != EOM_OK ||
            eom_system_new(&s, mo, err, sizeof err) != EOM_OK) {
            CHECK_FAIL_("%s: %s", path, err);
            eom_model_free(&mo);
            eom_file_free(&f);
            return;
        }
        CHECK_INT(eom_initial_state(s, x), EOM_OK);
        eom_opts_default(&o);
        o.method = methods[k];
        o.rtol = o.atol = 1e-8;
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
        for (i = 1; i <= 40 && rc == EOM_OK && it; i++)
            rc = eom_integ_advance(it, 0.05 * i, x, NULL);
        printf("A02 N = 4 natural %s: %s\n", eom_method_name(methods[k]),
               rc == EOM_OK ? "passed" : eom_integ_errmsg(it));
        CHECK_INT(rc, EOM_ERR_SOLVER);
        CHECK(i - 1 <= 26); /* stopped by t = 1.3 s */
        CHECK(it && strstr(eom_integ_errmsg(it), "bdf cannot pass this "
                           "singular position: erk") != NULL);
        eom_integ_free(&it);
        eom_system_free(&s);
        eom_model_free(&mo);
        eom_file_free(&f);
    }
}

typedef struct spec {
    const char *file;
    int natural;
    eom_method method;
    double bound; /* on the error of every crank tip, m */
} spec;

int main(int argc, char **argv)
{
    /* bounds, at rtol = atol = 1e-8, all well inside the benchmark's
     * 1e-3 (a run on the other branch is off by the rods' length):
     * quick, measured 2.9e-7 (erk), 3.6e-8 (bdf) and 4.8e-8 (adams); full,
     * 3.7e-6 (erk, natural), 8.2e-5 (erk, angles), 5.5e-6 (adams),
     * 1.8e-6 (bdf), 4.8e-6 (ida) */
    static const spec quick[] = {
        {"a02-natural.eom", 1, EOM_ERK, 1e-5},
        {"a02-angles.eom", 0, EOM_BDF, 1e-5},
        {"a02-angles.eom", 0, EOM_ADAMS, 1e-5},
    };
    static const spec full[] = {
        {"a02-natural.eom", 1, EOM_ERK, 1e-5},
        {"a02-angles.eom", 0, EOM_ERK, 3e-4},
        {"a02-angles.eom", 0, EOM_ADAMS, 3e-5},
        {"a02-angles.eom", 0, EOM_BDF, 1e-5},
        {"a02-angles.eom", 0, EOM_IDA, 3e-5},
    };
    const int is_full = argc > 2 && strcmp(argv[2], "full") == 0;
    const spec *cases = is_full ? full : quick;
    const int ncases = is_full ? (int)(sizeof full / sizeof *full)
                               : (int)(sizeof quick / sizeof *quick);
    const double t_end = is_full ? 20.0 : 3.3;
    const int flats = flats_until(t_end);
    char path[4096];
    int c;
    if (argc < 2) {
        fprintf(stderr, "usage: %s MODELS_DIR [quick|full]\n", argv[0]);
        return 2;
    }
    if (!is_full)
        bdf_refusal(argv[1]);
    /* the benchmark's own count, and four in the quick case */
    CHECK_INT(flats, is_full ? 20 : 4);
    for (c = 0; c < ncases; c++) {
        result r;
        snprintf(path, sizeof path, "%s/%s", argv[1], cases[c].file);
        run(path, cases[c].natural, cases[c].method, t_end, &r);
        printf("A02 N = %d %-8s %-6s to %4.1f s: %s at t = %5.2f, B0 error "
               "%.2e, every tip %.2e (bound %.0e), %ld steps, %.1f s, flat "
               "passes %ld of %d, branch switches %ld\n",
               NLOOPS, cases[c].natural ? "natural" : "angles",
               eom_method_name(cases[c].method), t_end,
               r.status == EOM_OK ? "ok" : "STOPPED", r.t_reached, r.err_b0,
               r.err_all, cases[c].bound, r.steps, r.wall, r.passes, flats,
               r.switches);
        CHECK_INT(r.status, EOM_OK);
        CHECK(r.t_reached >= t_end - 1e-9);
        CHECK(r.err_all <= cases[c].bound);
        CHECK_INT(r.switches, 0);
        /* the monitor sees a pass when a step lands close enough to the
         * flat position; a step may straddle one */
        CHECK(r.passes >= flats / 2 && r.passes <= flats);
    }
    CHECK_DONE();
}
