/* bench_hard.c - the hard cases of the chain demos: each either runs with
 * its accuracy reported or fails with a clear diagnosis.
 *
 *   stiff     the closed chain with EI x 100 and x 10^4 and three modes per
 *             link (the highest modal frequencies grow like EI^(1/2) i^2),
 *             with BDF and IDA, and Adams for contrast; state error at
 *             t-end against a tight BDF reference;
 *   singular  the closed chain stretched almost straight (D close to the
 *             total length: S = C M^-1 C^T nearly singular), and exactly
 *             straight; the condition estimate of S is reported;
 *   long      a 50-link chain, and the paper's closed chain for 1000 s;
 *   stiff-target  issue 10's stiff case, every method's work against
 *             precision on the closed chain with EI x 100 and two modes
 *             per link, undamped and with 2% modal damping (hard_stiff.c);
 *   a02       the IFToMM benchmark A02, 40 four-bar loops through 20 flat
 *             singular positions, in natural coordinates and in angles,
 *             every method against the exact motion (hard_a02.c).
 * Stiff runs use two tolerance pairs: one that resolves the vibration
 * of the beams, one loose enough for an implicit method to step over it.
 * Energy: max |E + W - E0| relative to max(|E0|, T0 + |V0|); residual:
 * max |phi| over the samples; rcond S: the smallest KLU estimate seen.
 *
 * usage: bench-hard [--quick] [SECTION...]   (no SECTION: all of them) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_chain.h"
#include "hard_a02.h"
#include "hard_stiff.h"

static const double pi = 3.14159265358979323846;

typedef struct outcome {
    int status;
    char msg[512];
    long steps, rhs;
    double wall, drift, residual, rcond_S, t_reached;
    double x[512]; /* state at the end (or at the failure) */
} outcome;

/* Run s from its initial state (projected onto the constraints) to t_end
 * with method, sampling nsamp times. */
static void run(eom_system *s, eom_method method, double rtol, double atol,
                double dt, double t_end, int nsamp, outcome *o)
{
    const int n = eom_system_ncoords(s), m = eom_system_nconstraints(s);
    eom_opts opts;
    eom_integ *it = NULL;
    eom_energy e0, e;
    eom_stats st;
    double W = 0.0, scale, phi[2], rm, rs;
    int k;
    memset(o, 0, sizeof *o);
    o->rcond_S = 1.0;
    eom_initial_state(s, o->x);
    if (m > 0 && (o->status = eom_project(s, o->x, 1e-12, NULL))) {
        snprintf(o->msg, sizeof o->msg, "%s", eom_system_errmsg(s));
        return;
    }
    if ((o->status = eom_energy_at(s, 0.0, o->x, &e0))) {
        snprintf(o->msg, sizeof o->msg, "%s", eom_system_errmsg(s));
        return;
    }
    scale = fmax(fabs(e0.E), fabs(e0.T) + fabs(e0.V));
    eom_opts_default(&opts);
    opts.method = method;
    opts.rtol = rtol;
    opts.atol = atol;
    opts.dt = dt;
    if ((o->status = eom_integ_new(&it, s, &opts, 0.0, o->x))) {
        snprintf(o->msg, sizeof o->msg, "%s", eom_system_errmsg(s));
        return;
    }
    for (k = 1; k <= nsamp; k++) {
        const double t = t_end * k / nsamp;
        o->status = eom_integ_advance(it, t, o->x, &W);
        if (o->status != EOM_OK) {
            snprintf(o->msg, sizeof o->msg, "%s", eom_integ_errmsg(it));
            break;
        }
        o->t_reached = t;
        if (eom_energy_at(s, t, o->x, &e) == EOM_OK)
            o->drift = fmax(o->drift, fabs(e.E + W - e0.E) / scale);
        if (m > 0 && eom_residuals(s, o->x, phi, NULL) == EOM_OK)
            o->residual = fmax(o->residual, fmax(fabs(phi[0]), fabs(phi[1])));
        if (m > 0 && eom_condition(s, o->x, &rm, &rs) == EOM_OK)
            o->rcond_S = fmin(o->rcond_S, rs);
    }
    eom_integ_stats(it, &st);
    o->steps = st.steps;
    o->rhs = st.rhs_evals;
    o->wall = st.wall_time;
    eom_integ_free(&it);
    (void)n;
}

static double state_error(const outcome *a, const outcome *ref, int n)
{
    double e = 0.0;
    int i;
    for (i = 0; i < 2 * n; i++)
        e = fmax(e, fabs(a->x[i] - ref->x[i]));
    return e;
}

static void row(const char *name, const char *method, const outcome *o,
                double err)
{
    printf("| %s | %s | %s | %.3g | %ld | %ld | %.3f | %.1e | %.1e | %.1e | ",
           name, method, o->status == EOM_OK ? "ok" : eom_status_name(o->status),
           o->t_reached, o->steps, o->rhs, o->wall, o->drift, o->residual,
           o->rcond_S);
    if (err >= 0)
        printf("%.1e |", err);
    else
        printf(" |");
    if (o->status != EOM_OK) { /* a message may hold |phi|: escape it */
        const char *c;
        putchar(' ');
        for (c = o->msg; *c; c++) {
            if (*c == '|')
                putchar('\\');
            putchar(*c);
        }
    }
    printf("\n");
    fflush(stdout);
}

/* rtol, and atol on every component: tight enough to resolve the beams'
 * vibration, or loose enough to let an implicit method step over it */
static const double tols[2][2] = {{1e-7, 1e-10}, {1e-6, 1e-6}};

static void stiff(int quick)
{
    static const double factors[2] = {1e2, 1e4};
    static const eom_method methods[4] = {EOM_BDF, EOM_IDA, EOM_ESDIRK,
                                          EOM_ADAMS};
    const double t_end = quick ? 0.1 : 2.0;
    int f, k, tl;
    for (f = 0; f < 2; f++) {
        chain_cfg cfg = {5, 3, 1, 4e4 * factors[f], 10.0, 9.81, 10.0, 0.0,
                         bench_paper5};
        char name[64], msg[256];
        eom_system *s = bench_chain_new(&cfg, msg, sizeof msg);
        outcome ref, o;
        if (!s) {
            printf("| stiff | set-up failed: %s |\n", msg);
            continue;
        }
        /* bdf's tolerances are targets for the run's error
         * (docs/integrators.md): 1e-10 keeps it far below the errors of
         * the runs measured */
        run(s, EOM_BDF, 1e-10, 1e-13, 0.0, t_end, 20, &ref);
        snprintf(name, sizeof name, "closed chain, EI x %g, 3 modes",
                 factors[f]);
        row(name, "bdf 1e-10, 1e-13 (reference)", &ref, -1);
        for (tl = 0; tl < 2; tl++)
            for (k = 0; k < 4; k++) {
                char meth[48];
                snprintf(meth, sizeof meth, "%s %g, %g",
                         eom_method_name(methods[k]), tols[tl][0],
                         tols[tl][1]);
                run(s, methods[k], tols[tl][0], tols[tl][1], 0.0, t_end, 20,
                    &o);
                row(name, meth, &o,
                    o.status == EOM_OK && ref.status == EOM_OK
                        ? state_error(&o, &ref, eom_system_ncoords(s))
                        : -1);
            }
        eom_system_free(&s);
    }
}

/* A chain of 5 links stretched to D of its total length 50. */
static void singular(int quick)
{
    static const double gaps[3] = {49.0, 49.99, 50.0};
    const double t_end = quick ? 0.5 : 5.0;
    int k;
    for (k = 0; k < 3; k++) {
        double th[5];
        chain_cfg cfg = {5, 1, 1, 4e4, gaps[k], 9.81, 10.0, 0.0, th};
        char name[64], msg[256];
        eom_system *s;
        outcome o;
        int j;
        /* a shallow symmetric arch that nearly spans D; projection closes
         * it exactly */
        for (j = 0; j < 5; j++)
            th[j] = 0.02 * (1.0 - j / 2.0);
        s = bench_chain_new(&cfg, msg, sizeof msg);
        snprintf(name, sizeof name, "closed chain, D = %g of 50", gaps[k]);
        if (!s) {
            printf("| %s | set-up failed: %s |\n", name, msg);
            continue;
        }
        run(s, EOM_ADAMS, 1e-9, 1e-12, 0.0, t_end, 50, &o);
        row(name, "adams 1e-9, 1e-12", &o, -1);
        eom_system_free(&s);
    }
}

static void long_runs(int quick)
{
    char msg[256];
    double th[50];
    outcome o;
    int j;
    /* 50 links, 2 modes each, open, gravity: a hanging chain let go from
     * a zig-zag */
    for (j = 0; j < 50; j++)
        th[j] = -pi / 2 + (j % 2 ? -0.3 : 0.3);
    {
        chain_cfg cfg = {50, 2, 0, 4e4, 0.0, 9.81, 0.0, 0.0, th};
        eom_system *s = bench_chain_new(&cfg, msg, sizeof msg);
        if (s) {
            run(s, EOM_ADAMS, 1e-8, 1e-11, 0.0, quick ? 0.05 : 1.0, 10, &o);
            row("open chain, 50 links x 2 modes", "adams 1e-8, 1e-11", &o,
                -1);
            run(s, EOM_BDF, 1e-8, 1e-11, 0.0, quick ? 0.05 : 1.0, 10, &o);
            row("open chain, 50 links x 2 modes", "bdf 1e-8, 1e-11", &o,
                -1);
            eom_system_free(&s);
        } else {
            printf("| 50 links | set-up failed: %s |\n", msg);
        }
    }
    {
        chain_cfg cfg = {5, 1, 1, 4e4, 10.0, 9.81, 10.0, 0.0,
                         bench_paper5};
        eom_system *s = bench_chain_new(&cfg, msg, sizeof msg);
        if (s) {
            run(s, EOM_ADAMS, 1e-8, 1e-11, 0.0, quick ? 10.0 : 1000.0, 100,
                &o);
            row(quick ? "closed chain, 10 s" : "closed chain, 1000 s",
                "adams 1e-8, 1e-11", &o, -1);
            eom_system_free(&s);
        }
    }
}

/* The sections, in the order they run: the first three share one
 * table, the stiff target prints its own. */
static const char *const sections[5] = {"stiff", "singular", "long",
                                        "stiff-target", "a02"};

static int usage(void)
{
    fprintf(stderr, "usage: bench-hard [--quick] [stiff] [singular] [long] "
            "[stiff-target] [a02]\n  (no section: all five)\n");
    return 2;
}

int main(int argc, char **argv)
{
    int quick = 0, chosen[5] = {0, 0, 0, 0, 0}, any = 0, i, k, rc = 0;
    for (i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
            continue;
        }
        for (k = 0; k < 5 && strcmp(argv[i], sections[k]) != 0; k++)
            ;
        if (k == 5)
            return usage();
        chosen[k] = any = 1;
    }
    for (k = 0; !any && k < 5; k++)
        chosen[k] = 1;
    if (chosen[0] || chosen[1] || chosen[2])
        printf("| case | method, rtol, atol | status | t reached | steps | "
               "rhs | wall (s) | energy drift | residual | rcond S | state "
               "error |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|\n");
    if (chosen[0])
        stiff(quick);
    if (chosen[1])
        singular(quick);
    if (chosen[2])
        long_runs(quick);
    if (chosen[3]) {
        if (chosen[0] || chosen[1] || chosen[2])
            printf("\n");
        rc = hard_stiff_target(quick);
    }
    if (chosen[4]) {
        if (chosen[0] || chosen[1] || chosen[2] || chosen[3])
            printf("\n");
        rc |= hard_a02(A02_MODELS_DIR, quick);
    }
    return rc;
}
