/* test_a01.c - the IFToMM benchmark A01 (a pendulum in Cartesian
 * coordinates with one constraint, released level) over 2000 s against
 * its exact motion, with the benchmark's tolerance on the final position
 * (1e-5 m).
 *
 * The exact motion: th'' = -(g/l) sin th from th = pi/2 at rest (th from
 * the downward vertical), periodic with period P = 4 K(k) / sqrt(g/l),
 * k = sin(pi/4), K by the arithmetic-geometric mean (K = pi / (2
 * agm(1, sqrt(1 - k^2)))). The state at t is the state at t mod P,
 * integrated from the release by a classical RK4 of this file's own with
 * steps of at most 1e-5 s; both routes are independent of libeom.
 *
 * The run outputs every 0.5 s (4000 outputs) at rtol = atol = 1e-10.
 * ida projects at output times and restarts from the projected state;
 * between them its index-1 form lets phi drift, so its per-step
 * tolerance decides its accuracy: with its floor at 1e-12 (integrate.c)
 * it ended 2.3e-5 off, with 1e-14 2.2e-6. Measured with the other
 * methods by the same program: adams 5.4e-6, bdf 4.6e-6, erk 1.7e-4
 * (erk's error is not calibrated to the tolerance over 843 periods).
 *
 * usage: test_a01 MODELS_DIR [METHOD [RTOL ATOL [DT [BOUND]]]]
 *        (default: ida 1e-10 1e-10 0.5 1e-5) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"
#include "eom/model_file.h"

#define PI_ 3.14159265358979323846

static const double L = 1.0, G = 9.81;

static double agm(double a, double b)
{
    int i;
    for (i = 0; i < 60 && fabs(a - b) > 1e-16 * a; i++) {
        const double c = 0.5 * (a + b);
        b = sqrt(a * b);
        a = c;
    }
    return a;
}

/* the angle from the downward vertical at t */
static double exact_angle(double t)
{
    const double k = sin(PI_ / 4), w0 = sqrt(G / L);
    const double K = PI_ / (2 * agm(1.0, sqrt(1 - k * k)));
    const double P = 4 * K / w0;
    const double r = t - P * floor(t / P);
    const long steps = (long)ceil(r / 1e-5);
    const double h = steps > 0 ? r / (double)steps : 0.0;
    double th = PI_ / 2, w = 0.0;
    long i;
    for (i = 0; i < steps; i++) {
        const double k1t = w, k1w = -w0 * w0 * sin(th);
        const double k2t = w + h / 2 * k1w,
                     k2w = -w0 * w0 * sin(th + h / 2 * k1t);
        const double k3t = w + h / 2 * k2w,
                     k3w = -w0 * w0 * sin(th + h / 2 * k2t);
        const double k4t = w + h * k3w, k4w = -w0 * w0 * sin(th + h * k3t);
        th += h / 6 * (k1t + 2 * k2t + 2 * k3t + k4t);
        w += h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
    }
    return th;
}

/* Runs the model with method to t_end, output every dt; the distance of
 * the final position from the exact one, or -1 if the run failed. */
static double run(const char *path, eom_method method, double rtol,
                  double atol, double t_end, double dt, eom_stats *st)
{
    char err[1024];
    eom_file *f = NULL;
    eom_model *mo = NULL;
    eom_system *s = NULL;
    eom_integ *it = NULL;
    eom_opts o;
    double x[4], th, dist = -1.0;
    long k, nout = lround(t_end / dt);
    memset(st, 0, sizeof *st);
    if (eom_file_read(&f, path, err, sizeof err) != EOM_OK ||
        eom_file_build(f, &mo, err, sizeof err) != EOM_OK ||
        eom_system_new(&s, mo, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "%s: %s\n", path, err);
        goto done;
    }
    CHECK_INT(eom_system_ncoords(s), 2);
    CHECK_INT(eom_system_nconstraints(s), 1);
    if (eom_initial_state(s, x) != EOM_OK)
        goto done;
    eom_opts_default(&o);
    o.method = method;
    o.rtol = rtol;
    o.atol = atol;
    o.dt = 1e-3;
    if (eom_integ_new(&it, s, &o, 0.0, x) != EOM_OK) {
        fprintf(stderr, "%s: %s\n", eom_method_name(method),
                eom_system_errmsg(s));
        goto done;
    }
    for (k = 1; k <= nout; k++)
        if (eom_integ_advance(it, t_end * (double)k / (double)nout, x,
                              NULL) != EOM_OK) {
            fprintf(stderr, "%s: %s\n", eom_method_name(method),
                    eom_integ_errmsg(it));
            goto done;
        }
    eom_integ_stats(it, st);
    th = exact_angle(t_end);
    dist = hypot(x[0] - L * sin(th), x[1] + L * cos(th));
done:
    eom_integ_free(&it);
    eom_system_free(&s);
    eom_model_free(&mo);
    eom_file_free(&f);
    return dist;
}

int main(int argc, char **argv)
{
    const double t_end = 2000.0;
    char path[4096];
    const char *name = argc > 2 ? argv[2] : "ida";
    const double rtol = argc > 3 ? atof(argv[3]) : 1e-10;
    const double atol = argc > 4 ? atof(argv[4]) : 1e-10;
    const double dt = argc > 5 ? atof(argv[5]) : 0.5;
    const double bound = argc > 6 ? atof(argv[6]) : 1e-5;
    const int method = eom_method_from_name(name);
    eom_stats st;
    double dist;
    if (argc < 2 || method < 0 || !(rtol > 0) || !(atol > 0) || !(dt > 0)) {
        fprintf(stderr, "usage: %s MODELS_DIR [METHOD [RTOL ATOL [DT "
                "[BOUND]]]]\n", argv[0]);
        return 2;
    }
    /* the reference: a quarter period is the bottom (th = 0), half a
     * period the other end */
    {
        const double k = sin(PI_ / 4);
        const double P = 4 * PI_ / (2 * agm(1.0, sqrt(1 - k * k))) /
                         sqrt(G / L);
        CHECK(fabs(exact_angle(P / 4)) < 1e-12);
        CHECK(fabs(exact_angle(P / 2) + PI_ / 2) < 1e-12);
    }
    snprintf(path, sizeof path, "%s/a01-cartesian.eom", argv[1]);
    dist = run(path, (eom_method)method, rtol, atol, t_end, dt, &st);
    printf("A01 %-6s rtol %.0e atol %.0e to %.0f s, output every %g s: "
           "final position %.2e from the exact one (bound %.0e), %ld "
           "steps, %ld projections, %.1f s\n",
           name, rtol, atol, t_end, dt, dist, bound, st.steps,
           st.projections, st.wall_time);
    CHECK(dist >= 0.0);
    CHECK(dist < bound);
    CHECK_DONE();
}
