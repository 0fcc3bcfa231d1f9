/* chains.c - the paper's flexible-chain demos, built with the element
 * library (eom/chain.h):
 *
 *   open-chain    three beams of 1 kg, 10 m, EI = 4e3 N m^2, pinned at the
 *                 origin, no gravity, two modes each. Everything starts at
 *                 rest and undeformed except the last beam: a mid-span
 *                 deflection q3_1 = 0.01 m and theta3_dot = 0.5 rad/s. The
 *                 paper's initial angles were lost; we start from the
 *                 zig-zag theta_j = +pi/6, -pi/6, +pi/6, ... Joint dampers
 *                 (every joint but the base) with c = 0 by default.
 *   closed-chain  five links of 1 kg, 10 m, EI = 4e4 N m^2, pinned at (0, 0)
 *                 and (D, 0) = (10 m, 0), gravity 9.81 m/s^2, released from
 *                 rest and undeformed at theta = (5, 1, 0, 17, 13) pi/12;
 *                 dampers c = 10 N m s/rad at every joint but the base
 *                 joint; one mode per link.
 *
 * Structural settings: links, modes, and the shared m, L, EI, which are
 * the defaults of the per-link parameters mJ, LJ, EIJ (so --set EI=1e5
 * changes every link and --set EI3=1e5 only link 3). With another number
 * of links the closed chain starts from a symmetric arch that closes;
 * --modes looks for its rest state from that arch turned downwards.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "chain_plots.h"
#include "demos.h"
#include "eom/chain.h"

static const double pi = 3.14159265358979323846;

enum { S_LINKS, S_MODES, S_M, S_L, S_EI, S_COUNT };

#define CHAIN_SETTINGS(links, modes, m, L, EI)                               \
    {                                                                        \
        {"links", "", links, 1, 1000, 1, "number of links"},                 \
        {"modes", "", modes, 0, 20, 1,                                       \
         "assumed modes per link (0: rigid links)"},                         \
        {"m", "kg", m, 1e-12, 1e12, 0, "mass of every link (default of mJ)"},\
        {"L", "m", L, 1e-12, 1e12, 0,                                        \
         "length of every link (default of LJ)"},                            \
        {"EI", "N m^2", EI, 0, 1e20, 0,                                      \
         "bending stiffness of every link (default of EIJ)"},                \
    }

static const demo_setting open_settings[S_COUNT] =
    CHAIN_SETTINGS(3, 2, 1.0, 10.0, 4e3);
static const demo_setting closed_settings[S_COUNT] =
    CHAIN_SETTINGS(5, 1, 1.0, 10.0, 4e4);

/* Arrays a chain spec points to, owned by the builder. */
typedef struct chain_init {
    double *theta0, *theta0_dot, *q0;
    unsigned char *damped;
} chain_init;

static void init_free(chain_init *ci)
{
    free(ci->theta0);
    free(ci->theta0_dot);
    free(ci->q0);
    free(ci->damped);
}

static int init_alloc(chain_init *ci, int N, int K)
{
    ci->theta0 = calloc((size_t)N, sizeof(double));
    ci->theta0_dot = calloc((size_t)N, sizeof(double));
    ci->q0 = calloc((size_t)N * (size_t)(K > 0 ? K : 1), sizeof(double));
    ci->damped = calloc((size_t)N + 1, 1);
    return ci->theta0 && ci->theta0_dot && ci->q0 && ci->damped ? 0 : -1;
}

static void spec_from(eom_chain_spec *sp, const double *set,
                      const chain_init *ci)
{
    sp->links = (int)set[S_LINKS];
    sp->modes_all = (int)set[S_MODES];
    sp->m = set[S_M];
    sp->L = set[S_L];
    sp->EI = set[S_EI];
    sp->theta0 = ci->theta0;
    sp->theta0_dot = ci->theta0_dot;
    sp->q0 = ci->q0;
    sp->damped = ci->damped;
}

static int build_chain(const eom_chain_spec *sp, eom_model **out, char *err,
                       size_t errlen)
{
    eom_model *m = NULL;
    int rc = eom_model_new(&m);
    if (rc == EOM_OK && (rc = eom_chain_add(m, sp)) < 0 &&
        !eom_model_errmsg(m)[0]) {
        snprintf(err, errlen, "building the chain: %s", eom_strerror(rc));
        eom_model_free(&m);
        return 1;
    }
    return demo_model_done(&m, out, err, errlen);
}

static int open_build(const demo *d, const double *set, eom_model **out,
                      char *err,
                      size_t errlen)
{
    const int N = (int)set[S_LINKS], K = (int)set[S_MODES];
    eom_chain_spec sp = {0};
    chain_init ci = {0};
    int j, rc;
    (void)d;
    if (init_alloc(&ci, N, K) != 0) {
        init_free(&ci);
        snprintf(err, errlen, "out of memory");
        return 1;
    }
    for (j = 0; j < N; j++)
        ci.theta0[j] = (j % 2 ? -1.0 : 1.0) * pi / 6.0; /* zig-zag */
    ci.theta0_dot[N - 1] = 0.5;   /* the last beam spins ... */
    if (K > 0)
        ci.q0[(size_t)(N - 1) * (size_t)K] = 0.01; /* ... bent mid-span */
    for (j = 1; j <= N - 1; j++)
        ci.damped[j] = 1; /* every joint but the base */
    spec_from(&sp, set, &ci);
    sp.g = 0.0;
    sp.c = 0.0;
    rc = build_chain(&sp, out, err, errlen);
    init_free(&ci);
    return rc;
}

/* A symmetric arch of N equal links that spans D: theta_j =
 * a (1 - 2 j / (N - 1)); sum sin = 0 by symmetry and a is found by
 * bisection so that sum cos theta_j = D / L. */
static int arch(int N, double D, double L, double *theta)
{
    double lo = 0.0, hi = pi, a = 0.0;
    int it, j;
    if (N == 1) {
        theta[0] = 0.0;
        return fabs(D - L) <= 1e-12 * L ? 0 : -1;
    }
    if (!(D < N * L) || D < 0.0)
        return -1;
    for (it = 0; it < 200; it++) {
        double s = 0.0;
        a = 0.5 * (lo + hi);
        for (j = 0; j < N; j++)
            s += cos(a * (1.0 - 2.0 * j / (N - 1.0)));
        if (s > D / L)
            lo = a;
        else
            hi = a;
    }
    for (j = 0; j < N; j++)
        theta[j] = a * (1.0 - 2.0 * j / (N - 1.0));
    return 0;
}

static int closed_build(const demo *d, const double *set, eom_model **out,
                        char *err,
                        size_t errlen)
{
    static const double paper[5] = {5, 1, 0, 17, 13}; /* x pi/12 */
    const int N = (int)set[S_LINKS], K = (int)set[S_MODES];
    const double D = 10.0;
    eom_chain_spec sp = {0};
    chain_init ci = {0};
    int j, rc;
    (void)d;
    if (init_alloc(&ci, N, K) != 0) {
        init_free(&ci);
        snprintf(err, errlen, "out of memory");
        return 1;
    }
    if (N == 5 && set[S_L] == 10.0) {
        for (j = 0; j < 5; j++)
            ci.theta0[j] = paper[j] * pi / 12.0;
    } else if (arch(N, D, set[S_L], ci.theta0) != 0) {
        init_free(&ci);
        snprintf(err, errlen,
                 "%d links of %g m cannot close a gap of D = %g m", N,
                 set[S_L], D);
        return 1;
    }
    for (j = 1; j <= N; j++)
        ci.damped[j] = 1; /* every joint but the base joint */
    spec_from(&sp, set, &ci);
    sp.closed = 1;
    sp.D = D;
    sp.g = 9.81;
    sp.c = 10.0;
    rc = build_chain(&sp, out, err, errlen);
    init_free(&ci);
    return rc;
}

/* The closed chain hangs below its pins at rest: the arch of closed_build
 * turned downwards, with the links straight. */
static int closed_rest_guess(const demo *d, const double *set,
                             const eom_system *s,
                             double *q)
{
    const int N = (int)set[S_LINKS], n = eom_system_ncoords(s);
    int j;
    (void)d;
    if (arch(N, 10.0, set[S_L], q) != 0)
        return 1;
    for (j = 0; j < N; j++)
        q[j] = -q[j];
    for (j = N; j < n; j++)
        q[j] = 0.0;
    return 0;
}

static int chain_after_run(const demo *d, const double *set,
                           const eom_system *s,
                           const char *csv_path, char *err, size_t errlen)
{
    (void)d;
    return chain_plots_write(s, (int)set[S_LINKS], csv_path, err, errlen);
}

const demo demo_open_chain = {
    .name = "open-chain",
    .summary = "three flexible beams pinned at the origin, no gravity "
               "(the paper's open chain)",
    .settings = open_settings,
    .nsettings = S_COUNT,
    .build = open_build,
    .after_run = chain_after_run,
};

const demo demo_closed_chain = {
    .name = "closed-chain",
    .summary = "five flexible links pinned at both ends, gravity and joint "
               "damping (the paper's closed chain)",
    .settings = closed_settings,
    .nsettings = S_COUNT,
    .build = closed_build,
    .after_run = chain_after_run,
    .rest_guess = closed_rest_guess,
};
