/* bench_a02_growth.c - bench-a02-growth: the cost of one right-hand side
 * of the IFToMM A02 four-bars in natural coordinates (N loops in a row,
 * tests/eom_constraints/models/a02-natural.eom: 2N + 2 coordinates,
 * 2N + 1 constraints) as N grows, along each route of the mass matrix
 * (docs/libeom.md, "The mass matrix's route"), with the error of each
 * against the exact motion, and the first 0.5 s of motion (before the
 * first flat position at 0.72 s) integrated with adams.
 *
 * The exact motion keeps every loop a parallelogram: each crank turns
 * with one angle th, th'' = -a cos th, a = g/l ((N+1)/2 + N) / ((N+1)/3
 * + N) (bench/hard_a02.c). At a state on that branch (th = 1.2, th' =
 * -1.5) every tip's acceleration has a closed form; the error columns
 * are the largest difference from it over the coordinates, and "routes"
 * the largest difference between the routes' accelerations and
 * multipliers (relative to the largest multiplier). The run's error is
 * that of B_0 against the pendulum integrated by RK4 at 2e-5 s.
 *
 * Time per right-hand side is processor time over repeated eom_rhs calls
 * (at least 0.3 s of them, 0.05 s with --quick); the growth exponent
 * between two sizes is log(t2 / t1) / log(N2 / N1).
 *
 * The dense route is timed up to N = 400 (DENSE_MAX_N): it costs about
 * N^3 per evaluation.
 *
 * The second table integrates the first 0.5 s (ten outputs, rtol = atol
 * = 1e-8) from the model's start (every crank upright, th = pi/2, th' =
 * -1): adams and erk on the automatic route at every N (the integrators'
 * sparse path, kkt_integ.c), adams on the dense route and bdf (whose
 * iteration matrix is dense) up to N = 100 (RUN_DENSE_MAX_N), with the
 * processor time, the steps and right-hand sides, the largest distance
 * of any tip from the pendulum's at the outputs, and the process's peak
 * resident memory so far (getrusage: sizes run in ascending order).
 *
 * usage: bench-a02-growth [--quick] [N ...]   (default 40 400 4000)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/resource.h>

#include "eom/eom.h"
#include "eom/model_file.h"
#include "hard_a02.h" /* hard_a02_pendulum: the exact motion */

static const double Lr = 1.0, Gr = 9.81;

static double cpu_now(void)
{
    return (double)clock() / CLOCKS_PER_SEC;
}

static double coef(int N)
{
    return Gr / Lr * ((N + 1) / 2.0 + N) / ((N + 1) / 3.0 + N);
}

static eom_system *build(int N, char *err, size_t len)
{
    char path[4096];
    eom_file *f = NULL;
    eom_model *mo = NULL;
    eom_system *s = NULL;
    snprintf(path, sizeof path, "%s/a02-natural.eom", A02_MODELS_DIR);
    if (eom_file_read(&f, path, err, len) == EOM_OK &&
        eom_file_set_setting(f, "N", N, err, len) == EOM_OK &&
        eom_file_build(f, &mo, err, len) == EOM_OK)
        eom_system_new(&s, mo, err, len);
    eom_file_free(&f);
    eom_model_free(&mo);
    return s;
}

static void branch(int N, double th, double w, double *x, double *qdd)
{
    const int n = 2 * (N + 1);
    const double thdd = -coef(N) * cos(th);
    int i;
    for (i = 0; i <= N; i++) {
        x[i] = i * Lr + Lr * cos(th);
        x[N + 1 + i] = Lr * sin(th);
        x[n + i] = -Lr * sin(th) * w;
        x[n + N + 1 + i] = Lr * cos(th) * w;
        qdd[i] = -Lr * (sin(th) * thdd + cos(th) * w * w);
        qdd[N + 1 + i] = Lr * (cos(th) * thdd - sin(th) * w * w);
    }
}

/* The dense route's time grows like N^3 (C M^-1 C^T formed and
 * factored at every evaluation): 3 s per call at N = 400 already. Above
 * this it is not timed, and its accelerations come from one call. */
#define DENSE_MAX_N 400
/* The runs along dense factors (adams forced dense, bdf): up to this
 * size. */
#define RUN_DENSE_MAX_N 100
#define RUNS 4

typedef struct run_row {
    const char *what;
    int done, ok;
    double cpu, err;
    long steps, rhs;
    double rss_mb;
    char why[256];
} run_row;

typedef struct row {
    int N, ok;
    double t_rhs[2];  /* dense, automatic */
    double t_first[2]; /* their first call (analysis, M formed) */
    double err[2];    /* against the closed form */
    double routes;    /* between the routes */
    int route;        /* the automatic route */
    run_row runs[RUNS]; /* 0.5 s of motion (run_motion) */
    char why[512];
} row;

/* processor seconds per eom_rhs at x, at least min_time of calls */
static double time_rhs(eom_system *s, const double *x, double *xd,
                       double min_time)
{
    long reps = 0, k, batch = 1;
    double t0 = cpu_now(), t;
    do {
        for (k = 0; k < batch; k++)
            if (eom_rhs(s, 0.0, x, xd) != EOM_OK)
                return NAN;
        reps += batch;
        batch *= 2;
        t = cpu_now() - t0;
    } while (t < min_time);
    return t / (double)reps;
}

static double maxdiff(const double *a, const double *b, int n)
{
    double d = 0.0;
    int i;
    for (i = 0; i < n; i++)
        d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

static double peak_mb(void)
{
    struct rusage ru;
    return getrusage(RUSAGE_SELF, &ru) == 0 ? ru.ru_maxrss / 1024.0 : NAN;
}

/* 0.5 s from the model's start with method along route (0: automatic):
 * the largest distance of any tip from the pendulum's at ten outputs */
static void run_motion(eom_system *s, int N, eom_method method, int route,
                       run_row *r)
{
    const int n = 2 * (N + 1);
    const double a = coef(N);
    double *x = malloc(2 * (size_t)n * sizeof *x), th = 1.5707963267948966,
           w = -1.0, t0;
    eom_integ *it = NULL;
    eom_stats st;
    eom_opts o;
    int k, i;
    r->done = 1;
    r->ok = 0;
    if (!x || eom_initial_state(s, x) != EOM_OK ||
        eom_system_set_mass_route(s, route) != EOM_OK) {
        snprintf(r->why, sizeof r->why, "%s", eom_system_errmsg(s));
        free(x);
        return;
    }
    eom_opts_default(&o);
    o.method = method;
    o.rtol = o.atol = 1e-8;
    t0 = cpu_now();
    if (eom_integ_new(&it, s, &o, 0.0, x) != EOM_OK) {
        snprintf(r->why, sizeof r->why, "%s", eom_system_errmsg(s));
    } else {
        r->ok = 1;
        for (k = 1; k <= 10; k++) {
            if (eom_integ_advance(it, 0.05 * k, x, NULL) != EOM_OK) {
                snprintf(r->why, sizeof r->why, "%s", eom_integ_errmsg(it));
                r->ok = 0;
                break;
            }
            hard_a02_pendulum(a, &th, &w, 0.05);
            for (i = 0; i <= N; i++)
                r->err = fmax(r->err, hypot(x[i] - i * Lr - Lr * cos(th),
                                            x[N + 1 + i] - Lr * sin(th)));
        }
        eom_integ_stats(it, &st);
        r->steps = st.steps;
        r->rhs = st.rhs_evals;
    }
    r->cpu = cpu_now() - t0;
    r->rss_mb = peak_mb();
    eom_integ_free(&it);
    free(x);
}

static void measure(int N, double min_time, row *r)
{
    const int n = 2 * (N + 1), m = 2 * N + 1;
    eom_system *s;
    double *x = NULL, *ex = NULL, *xd = NULL, *xa = NULL, *ld = NULL,
           *la = NULL, t0;
    int k;
    memset(r, 0, sizeof *r);
    r->N = N;
    s = build(N, r->why, sizeof r->why);
    if (!s)
        return;
    x = malloc(2 * (size_t)n * sizeof *x);
    ex = malloc((size_t)n * sizeof *ex);
    xd = malloc(2 * (size_t)n * sizeof *xd);
    xa = malloc(2 * (size_t)n * sizeof *xa);
    ld = malloc((size_t)m * sizeof *ld);
    la = malloc((size_t)m * sizeof *la);
    if (!x || !ex || !xd || !xa || !ld || !la) {
        snprintf(r->why, sizeof r->why, "out of memory");
        goto done;
    }
    branch(N, 1.2, -1.5, x, ex);
    r->route = eom_system_mass_route(s);
    for (k = 0; k < 2; k++) {
        double *out = k == 0 ? xd : xa;
        if (k == 0 && N > DENSE_MAX_N) {
            r->t_rhs[0] = r->err[0] = r->t_first[0] = NAN;
            continue;
        }
        eom_system_set_mass_route(s, k == 0 ? EOM_MASS_DENSE : 0);
        /* the first call analyses the tapes and forms M: apart */
        t0 = cpu_now();
        eom_rhs(s, 0.0, x, out);
        r->t_first[k] = cpu_now() - t0;
        r->t_rhs[k] = time_rhs(s, x, out, min_time);
        if (eom_rhs(s, 0.0, x, out) != EOM_OK ||
            eom_multipliers(s, 0.0, x, k == 0 ? ld : la) != EOM_OK) {
            snprintf(r->why, sizeof r->why, "%s", eom_system_errmsg(s));
            goto done;
        }
        r->err[k] = maxdiff(out + n, ex, n);
    }
    r->routes = NAN;
    if (N <= DENSE_MAX_N) {
        double lmax = 0.0;
        for (k = 0; k < m; k++)
            lmax = fmax(lmax, fabs(ld[k]));
        r->routes = fmax(maxdiff(xd + n, xa + n, n),
                         maxdiff(ld, la, m) / lmax);
    }
    r->ok = 1;
    r->runs[0].what = "adams, automatic";
    run_motion(s, N, EOM_ADAMS, 0, &r->runs[0]);
    r->runs[1].what = "erk, automatic";
    run_motion(s, N, EOM_ERK, 0, &r->runs[1]);
    r->runs[2].what = "adams, dense";
    r->runs[3].what = "bdf, automatic";
    if (N <= RUN_DENSE_MAX_N) {
        run_motion(s, N, EOM_ADAMS, EOM_MASS_DENSE, &r->runs[2]);
        run_motion(s, N, EOM_BDF, 0, &r->runs[3]);
    }
done:
    free(x);
    free(ex);
    free(xd);
    free(xa);
    free(ld);
    free(la);
    eom_system_free(&s);
}

int main(int argc, char **argv)
{
    int Ns[16], nN = 0, quick = 0, i;
    row rows[16];
    for (i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else if (nN < 16 && atoi(argv[i]) > 0)
            Ns[nN++] = atoi(argv[i]);
        else {
            fprintf(stderr, "usage: bench-a02-growth [--quick] [N ...]\n");
            return 2;
        }
    }
    if (nN == 0) {
        if (quick) {
            Ns[nN++] = 10;
            Ns[nN++] = 40;
        } else {
            Ns[nN++] = 40;
            Ns[nN++] = 400;
            Ns[nN++] = 4000;
        }
    }
    printf("IFToMM A02, natural coordinates: time per right-hand side "
           "(processor time) by the mass matrix's route\n");
    printf("%6s %6s %7s %10s %10s %9s %7s %9s %9s %9s %9s\n", "N",
           "n", "auto", "dense s", "auto s", "dense/au", "growth",
           "1st auto", "err dense", "err auto", "routes");
    for (i = 0; i < nN; i++) {
        row *r = &rows[i];
        measure(Ns[i], quick ? 0.05 : 0.3, r);
        if (!r->ok) {
            printf("%6d  not measured: %s\n", r->N, r->why);
            continue;
        }
        printf("%6d %6d %7s %10.4g %10.4g %9.3g ", r->N, 2 * r->N + 2,
               eom_mass_route_name(r->route), r->t_rhs[0], r->t_rhs[1],
               r->t_rhs[0] / r->t_rhs[1]);
        if (i > 0 && rows[i - 1].ok)
            printf("%7.3f ", log(r->t_rhs[1] / rows[i - 1].t_rhs[1]) /
                                 log((double)r->N / rows[i - 1].N));
        else
            printf("%7s ", "-");
        printf("%8.3gs %9.2e %9.2e %9.2e\n", r->t_first[1], r->err[0],
               r->err[1], r->routes);
        fflush(stdout);
    }
    printf("growth: exponent p in t ~ N^p of the automatic route between "
           "successive sizes; 1st auto: its first call (the tapes "
           "analysed, M formed)\n\n");
    printf("0.5 s of motion from the start (rtol = atol = 1e-8, ten "
           "outputs); error: largest tip distance from the pendulum's\n");
    printf("%6s %-17s %10s %7s %7s %10s %10s\n", "N", "method, route",
           "cpu s", "steps", "rhs", "tip error", "peak MB");
    for (i = 0; i < nN; i++) {
        int k;
        for (k = 0; rows[i].ok && k < RUNS; k++) {
            const run_row *u = &rows[i].runs[k];
            if (!u->done)
                continue;
            if (u->ok)
                printf("%6d %-17s %10.3g %7ld %7ld %10.2e %10.0f\n",
                       rows[i].N, u->what, u->cpu, u->steps, u->rhs, u->err,
                       u->rss_mb);
            else
                printf("%6d %-17s failed: %s\n", rows[i].N, u->what,
                       u->why);
        }
    }
    return 0;
}
