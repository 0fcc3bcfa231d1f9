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
 * In natural coordinates bdf's error test fails at a flat position, and
 * so does that of the bdf to which adams and ida hand such stretches:
 * the stretch goes to erk (integrate_handover.c), counted in
 * eom_stats.singular_handovers_erk, which is checked here to be at least
 * one for them.
 *
 * usage: test_a02 MODELS_DIR [small|quick|full]
 *   small  the default suite: 4 loops in natural coordinates to 3.3 s
 *          (four flat positions) with bdf, adams, ida, esdirk and imex
 *          (about 2 s of processor time in a debug build)
 *   quick  the accuracy suite: 40 loops to 3.3 s, the natural form with
 *          erk and adams (whose bdf fails at the first flat position and
 *          hands to erk), the angle form with bdf and adams (bdf and ida
 *          in natural coordinates cost 7 and 2 times adams': full)
 *   full   every method that passes, on both forms, to 20 s (bench-hard's
 *          a02 section runs every method and reports the others) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "support_num.h"
#include "eom/eom.h"
#include "eom/model_file.h"

#define PI_ 3.14159265358979323846
#define NLOOPS 40 /* the benchmark's size */
#define NOUT_PER_S 20 /* the benchmark's 400 outputs in 20 s */

static const double L = 1.0, G = 9.81;

/* th'' = -a cos th for the parallelogram branch */
static double accel_coef(int N)
{
    return G / L * ((N + 1) / 2.0 + N) / ((N + 1) / 3.0 + N);
}


typedef struct result {
    int status;
    double t_reached, err_b0, err_all, wall;
    long passes, switches, steps, handovers, handovers_erk;
} result;

/* Run the model at path with N loops with method to t_end. */
static void run(const char *path, int N, int natural, eom_method method,
                double t_end, result *r)
{
    const int nout = (int)lround(t_end * NOUT_PER_S);
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
        num_rk4_pendulum(a, &th, &w, t - tprev, 2e-5);
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
        r->handovers = st.singular_handovers;
        r->handovers_erk = st.singular_handovers_erk;
    }
done:
    eom_integ_free(&it);
    eom_system_free(&s);
    eom_model_free(&mo);
    eom_file_free(&f);
    free(x);
}

/* flat positions of the exact motion with N loops in (0, t_end] */
static int flats_until(int N, double t_end)
{
    const double a = accel_coef(N);
    double th = PI_ / 2, w = -1.0, t = 0.0;
    int count = 0;
    while (t < t_end) {
        const double before = floor(th / PI_);
        num_rk4_pendulum(a, &th, &w, 1e-3, 2e-5);
        t += 1e-3;
        count += floor(th / PI_) != before;
    }
    return count;
}

typedef struct spec {
    const char *file;
    int natural;
    eom_method method;
    double bound; /* on the error of every crank tip, m */
    int handed_to_erk; /* 1: at least one stretch went to erk */
} spec;

int main(int argc, char **argv)
{
    /* bounds, at rtol = atol = 1e-8, all well inside the benchmark's
     * 1e-3 (a run on the other branch is off by the rods' length):
     * small (release build), measured 3.7e-7 (bdf), 1.8e-8 (adams),
     * 1.1e-7 (ida), 1.2e-7 (esdirk), 7.7e-8 (imex); quick, 2.9e-7 (erk)
     * and 1.6e-7 (adams) on the natural form, 3.6e-8 (bdf) and 4.8e-8
     * (adams) on the angles; full, on the natural form 8.4e-7 (erk),
     * 3.5e-6 (bdf), 5.5e-6 (adams), 6.9e-6 (ida), 3.6e-6 (esdirk), 2.1e-6
     * (imex), on the angles 8.2e-5 (erk), 5.5e-6 (adams), 1.8e-6 (bdf),
     * 4.8e-6 (ida), 1.5e-6 (esdirk), 2.2e-6 (imex) */
    static const spec small[] = {
        {"a02-natural.eom", 1, EOM_BDF, 1e-5, 1},
        {"a02-natural.eom", 1, EOM_ADAMS, 1e-5, 1},
        {"a02-natural.eom", 1, EOM_IDA, 1e-5, 1},
        {"a02-natural.eom", 1, EOM_ESDIRK, 1e-5, 0},
        {"a02-natural.eom", 1, EOM_IMEX, 1e-5, 0},
    };
    static const spec quick[] = {
        {"a02-natural.eom", 1, EOM_ERK, 1e-5, 0},
        {"a02-natural.eom", 1, EOM_ADAMS, 1e-5, 1},
        {"a02-angles.eom", 0, EOM_BDF, 1e-5, 0},
        {"a02-angles.eom", 0, EOM_ADAMS, 1e-5, 0},
    };
    static const spec full[] = {
        {"a02-natural.eom", 1, EOM_ERK, 1e-5, 0},
        {"a02-natural.eom", 1, EOM_BDF, 1e-5, 1},
        {"a02-natural.eom", 1, EOM_ADAMS, 1e-5, 1},
        {"a02-natural.eom", 1, EOM_IDA, 1e-5, 1},
        {"a02-natural.eom", 1, EOM_ESDIRK, 1e-5, 0},
        {"a02-natural.eom", 1, EOM_IMEX, 1e-5, 0},
        {"a02-angles.eom", 0, EOM_ERK, 3e-4, 0},
        {"a02-angles.eom", 0, EOM_ADAMS, 3e-5, 0},
        {"a02-angles.eom", 0, EOM_BDF, 1e-5, 0},
        {"a02-angles.eom", 0, EOM_IDA, 3e-5, 0},
        {"a02-angles.eom", 0, EOM_ESDIRK, 1e-5, 0},
        {"a02-angles.eom", 0, EOM_IMEX, 1e-5, 0},
    };
    const char *mode = argc > 2 ? argv[2] : "quick";
    const int is_full = strcmp(mode, "full") == 0,
              is_small = strcmp(mode, "small") == 0;
    const spec *cases = is_full ? full : is_small ? small : quick;
    const int ncases =
        is_full    ? (int)(sizeof full / sizeof *full)
        : is_small ? (int)(sizeof small / sizeof *small)
                   : (int)(sizeof quick / sizeof *quick);
    const int N = is_small ? 4 : NLOOPS;
    const double t_end = is_full ? 20.0 : 3.3;
    const int flats = flats_until(N, t_end);
    char path[4096];
    int c;
    if (argc < 2 || (!is_full && !is_small && strcmp(mode, "quick") != 0)) {
        fprintf(stderr, "usage: %s MODELS_DIR [small|quick|full]\n",
                argv[0]);
        return 2;
    }
    /* the benchmark's own count, and four in the shorter cases */
    CHECK_INT(flats, is_full ? 20 : 4);
    for (c = 0; c < ncases; c++) {
        result r;
        snprintf(path, sizeof path, "%s/%s", argv[1], cases[c].file);
        run(path, N, cases[c].natural, cases[c].method, t_end, &r);
        printf("A02 N = %d %-8s %-6s to %4.1f s: %s at t = %5.2f, B0 error "
               "%.2e, every tip %.2e (bound %.0e), %ld steps, %.1f s, flat "
               "passes %ld of %d, branch switches %ld, stretches handed "
               "over %ld (to erk %ld)\n",
               N, cases[c].natural ? "natural" : "angles",
               eom_method_name(cases[c].method), t_end,
               r.status == EOM_OK ? "ok" : "STOPPED", r.t_reached, r.err_b0,
               r.err_all, cases[c].bound, r.steps, r.wall, r.passes, flats,
               r.switches, r.handovers, r.handovers_erk);
        CHECK_INT(r.status, EOM_OK);
        CHECK(r.t_reached >= t_end - 1e-9);
        CHECK(r.err_all <= cases[c].bound);
        CHECK_INT(r.switches, 0);
        /* the monitor sees a pass when a step lands close enough to the
         * flat position; a step may straddle one */
        CHECK(r.passes >= flats / 2 && r.passes <= flats);
        /* the stretches erk integrated are counted among the handovers */
        CHECK(r.handovers_erk <= r.handovers);
        if (cases[c].handed_to_erk)
            CHECK(r.handovers_erk >= 1 && r.handovers_erk <= flats);
    }
    CHECK_DONE();
}
