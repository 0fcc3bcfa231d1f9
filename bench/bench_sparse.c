/* bench_sparse.c - bench-sparse: ida with the sparse iteration matrix
 * (KLU) against ida with the dense one (dense LU), both with the exact
 * Jacobian from the residual tape, on the line of point masses of
 * tests/models/mass_line.h (Cartesian coordinates, neighbour springs and
 * dampers, four constraints): a pattern of a few entries a row.
 *
 *   1. Whole runs at N masses (default 50, 200, 1000), t = 0 .. T
 *      (default 0.1 s), rtol 1e-8, atol 1e-10: steps, Jacobians, wall
 *      time, the time spent forming iteration matrices (eom_stats.
 *      jac_time), and the error against a reference (ida sparse at rtol
 *      1e-12, atol 1e-14) for each; the ratio dense / sparse.
 *   2. Where sparse starts to pay: short runs (T / 4) at small N, ratio
 *      of wall times (the automatic choice's size bound).
 *   3. How sparse a pattern must be: N = 100 with springs reaching 1 .. 48
 *      masses on, which fills the matrix in; ratio of wall times against
 *      the fraction of entries in the pattern (the fill bound).
 *   4. bdf on the free line (no constraints: M diagonal, so bdf's
 *      Jacobian is sparse too, state_jacobian_sparse.c): whole runs at
 *      N = 10, 20, 50, 200, sparse against dense, and bdf's automatic
 *      choice.
 *
 * Each dense / sparse pair runs interleaved, reps times (default 3),
 * and the figures are the medians, in wall and in process CPU seconds:
 * the machine's cores are shared with other jobs, so only ratios
 * measured in one run mean anything, and the CPU ratio is the steadier.
 * Usage: bench-sparse [--quick] [--section 1|2|3|4] [--t-end T] [--reps R]
 *                     [--sizes a,b,..]
 * (--sizes: the N of sections 1 and 2, and the reaches of section 3.)
 * Prints markdown tables (docs/benchmarks.md, section 11).
 */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "eom/eom.h"
#include "mass_line.h"

typedef struct result {
    int status;
    long steps, jacs;
    double wall, cpu, jac_time; /* cpu: this process's seconds */
    int linsol;
    double x[2 * 2000 + 1];
    char msg[256];
} result;

static eom_system *line(int N, int reach, int constrained)
{
    eom_model *md = mass_line_model(N, constrained, reach);
    eom_system *s = NULL;
    char err[512];
    if (!md)
        return NULL;
    if (eom_system_new(&s, md, err, sizeof err) != EOM_OK)
        fprintf(stderr, "bench-sparse: %s\n", err);
    eom_model_free(&md);
    return s;
}

/* The process's CPU seconds: less disturbed than the wall clock by the
 * other jobs of a shared machine (they still share its caches). */
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void run(eom_system *s, eom_method method, int linsol, double rtol,
                double atol, double t_end, result *r)
{
    double c0;
    eom_opts o;
    eom_integ *it = NULL;
    eom_stats st;
    double W = 0.0;
    eom_opts_default(&o);
    o.method = method;
    o.rtol = rtol;
    o.atol = atol;
    o.linear_solver = linsol;
    eom_initial_state(s, r->x);
    r->msg[0] = '\0';
    r->status = eom_integ_new(&it, s, &o, 0.0, r->x);
    c0 = cpu_now();
    if (r->status == EOM_OK)
        r->status = eom_integ_advance(it, t_end, r->x, &W);
    r->cpu = cpu_now() - c0;
    if (r->status != EOM_OK)
        snprintf(r->msg, sizeof r->msg, "%s",
                 it ? eom_integ_errmsg(it) : eom_system_errmsg(s));
    memset(&st, 0, sizeof st);
    if (it)
        eom_integ_stats(it, &st);
    r->steps = st.steps;
    r->jacs = st.jac_evals;
    r->wall = st.wall_time;
    r->jac_time = st.jac_time;
    r->linsol = st.linear_solver;
    eom_integ_free(&it);
}

static double error_of(const result *a, const result *ref, int n2)
{
    double e = 0.0;
    int i;
    for (i = 0; i < n2; i++)
        e = fmax(e, fabs(a->x[i] - ref->x[i]));
    return e;
}

/* reps interleaved dense / sparse runs: medians of wall and Jacobian
 * time into the last of each. */
static void pair(eom_system *s, eom_method method, double t_end, int reps,
                 result *d, result *sp)
{
    double wd[16], ws[16], jd[16], js[16], cd[16], cs[16];
    int k;
    /* a first pair unmeasured: the first run of a process pays for
     * page faults and lazy set-up */
    run(s, method, EOM_LINSOL_DENSE, 1e-8, 1e-10, t_end / 10, d);
    run(s, method, EOM_LINSOL_SPARSE, 1e-8, 1e-10, t_end / 10, sp);
    for (k = 0; k < reps; k++) {
        run(s, method, EOM_LINSOL_DENSE, 1e-8, 1e-10, t_end, d);
        run(s, method, EOM_LINSOL_SPARSE, 1e-8, 1e-10, t_end, sp);
        wd[k] = d->wall;
        ws[k] = sp->wall;
        jd[k] = d->jac_time;
        js[k] = sp->jac_time;
        cd[k] = d->cpu;
        cs[k] = sp->cpu;
    }
    d->cpu = bench_median(cd, reps);
    sp->cpu = bench_median(cs, reps);
    d->wall = bench_median(wd, reps);
    sp->wall = bench_median(ws, reps);
    d->jac_time = bench_median(jd, reps);
    sp->jac_time = bench_median(js, reps);
}

static void whole_runs(const int *sizes, int nsizes, double t_end, int reps)
{
    static result ref, d, sp;
    int k;
    printf("## ida on the line of N masses, t = 0 .. %g s, rtol 1e-8, "
           "atol 1e-10 (medians of %d interleaved pairs)\n\n", t_end, reps);
    printf("| N | unknowns | entries | colours | solver | steps | "
           "Jacobians | wall s | CPU s | Jacobian s | error | dense / sparse "
           "wall | CPU | Jacobian |\n");
    printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (k = 0; k < nsizes; k++) {
        eom_system *s = line(sizes[k], 1, 1);
        const int n2 = 2 * 2 * sizes[k];
        if (!s)
            continue;
        run(s, EOM_IDA, EOM_LINSOL_SPARSE, 1e-12, 1e-14, t_end, &ref);
        if (ref.status != EOM_OK) {
            printf("| %d | reference failed: %s |\n", sizes[k], ref.msg);
            eom_system_free(&s);
            continue;
        }
        long entries = 0;
        int unknowns = 0, colors = 0;
        eom_dae_pattern_size(s, &unknowns, &entries, &colors);
        pair(s, EOM_IDA, t_end, reps, &d, &sp);
        printf("| %d | %d | %ld | %d | dense | %ld | %ld | %.3f | %.3f | "
               "%.3f | %.1e | | | |%s\n", sizes[k], unknowns, entries,
               colors, d.steps, d.jacs, d.wall, d.cpu, d.jac_time,
               error_of(&d, &ref, n2), d.msg);
        printf("| | | | | sparse | %ld | %ld | %.3f | %.3f | %.3f | %.1e | "
               "%.2f | %.2f | %.1f |%s\n", sp.steps, sp.jacs, sp.wall,
               sp.cpu, sp.jac_time, error_of(&sp, &ref, n2),
               d.wall / sp.wall, d.cpu / sp.cpu, d.jac_time / sp.jac_time,
               sp.msg);
        fflush(stdout);
        eom_system_free(&s);
    }
    printf("\n");
}

static void crossover(const int *sizes, int nsizes, double t_end, int reps,
                      int reach_sweep)
{
    static result d, sp, a;
    const int N = 100;
    int k;
    if (!reach_sweep) {
        printf("## Where sparse pays: t = 0 .. %g s\n\n", t_end);
        printf("| N | unknowns | entries | steps dense, sparse | CPU s dense, "
               "sparse | dense / sparse CPU | wall | Jacobian s dense, sparse "
               "| auto |\n|---|---|---|---|---|---|---|---|---|\n");
    } else {
        printf("## How sparse: N = %d, springs reaching r masses on, "
               "t = 0 .. %g s\n\n", N, t_end);
        printf("| r | unknowns | entries | steps dense, sparse | CPU s dense, "
               "sparse | dense / sparse CPU | wall | Jacobian s dense, sparse "
               "| auto |\n|---|---|---|---|---|---|---|---|---|\n");
    }
    for (k = 0; k < nsizes; k++) {
        const int n = reach_sweep ? N : sizes[k];
        const int r = reach_sweep ? sizes[k] : 1;
        eom_system *s = line(n, r, 1);
        if (!s)
            continue;
        long entries = 0;
        int unknowns = 0;
        eom_dae_pattern_size(s, &unknowns, &entries, NULL);
        pair(s, EOM_IDA, t_end, reps, &d, &sp);
        run(s, EOM_IDA, EOM_LINSOL_AUTO, 1e-8, 1e-10, 1e-4, &a);
        printf("| %d | %d | %ld (%.1f%%) | %ld, %ld | %.4f, %.4f | %.2f | "
               "%.2f | %.4f, %.4f | %s |%s%s\n",
               reach_sweep ? r : n, unknowns, entries,
               100.0 * (double)entries / ((double)unknowns * unknowns),
               d.steps, sp.steps, d.cpu, sp.cpu, d.cpu / sp.cpu,
               d.wall / sp.wall, d.jac_time, sp.jac_time,
               a.linsol == EOM_LINSOL_SPARSE ? "sparse" : "dense", d.msg,
               sp.msg);
        fflush(stdout);
        eom_system_free(&s);
    }
    printf("\n");
}

/* Section 4: bdf on the free line (no constraints: its Jacobian is
 * sparse, M being diagonal), dense against sparse, interleaved; the
 * reference is bdf sparse at rtol 1e-12. */
static void bdf_runs(const int *sizes, int nsizes, double t_end, int reps)
{
    static result ref, d, sp, a;
    int k;
    printf("## bdf on the free line of N masses, t = 0 .. %g s, rtol 1e-8, "
           "atol 1e-10 (medians of %d interleaved pairs)\n\n", t_end, reps);
    printf("| N | unknowns | solver | steps | Jacobians | wall s | CPU s | "
           "Jacobian s | error | dense / sparse wall | CPU | Jacobian | "
           "auto |\n");
    printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (k = 0; k < nsizes; k++) {
        eom_system *s = line(sizes[k], 1, 0);
        const int n2 = 2 * 2 * sizes[k];
        if (!s)
            continue;
        run(s, EOM_BDF, EOM_LINSOL_SPARSE, 1e-12, 1e-14, t_end, &ref);
        if (ref.status != EOM_OK) {
            printf("| %d | reference failed: %s |\n", sizes[k], ref.msg);
            eom_system_free(&s);
            continue;
        }
        pair(s, EOM_BDF, t_end, reps, &d, &sp);
        run(s, EOM_BDF, EOM_LINSOL_AUTO, 1e-8, 1e-10, 1e-4, &a);
        printf("| %d | %d | dense | %ld | %ld | %.3f | %.3f | %.4f | %.1e | "
               "| | | |%s\n", sizes[k], n2 + 1, d.steps, d.jacs, d.wall,
               d.cpu, d.jac_time, error_of(&d, &ref, n2), d.msg);
        printf("| | | sparse | %ld | %ld | %.3f | %.3f | %.4f | %.1e | %.2f "
               "| %.2f | %.1f | %s |%s\n", sp.steps, sp.jacs, sp.wall,
               sp.cpu, sp.jac_time, error_of(&sp, &ref, n2),
               d.wall / sp.wall, d.cpu / sp.cpu, d.jac_time / sp.jac_time,
               a.linsol == EOM_LINSOL_SPARSE ? "sparse" : "dense", sp.msg);
        fflush(stdout);
        eom_system_free(&s);
    }
    printf("\n");
}

static int parse_sizes(const char *arg, int *sizes, int cap)
{
    int n = 0;
    char *end;
    while (*arg && n < cap) {
        long v = strtol(arg, &end, 10);
        if (end == arg || v < 4 || v > 2000)
            return 0;
        sizes[n++] = (int)v;
        arg = *end == ',' ? end + 1 : end;
        if (*end && *end != ',')
            return 0;
    }
    return n;
}

int main(int argc, char **argv)
{
    int sizes[16] = {50, 200, 1000}, nsizes = 3, reps = 3, quick = 0, k;
    int section = 0, given = 0; /* given: --sizes also lists the N of
                                    section 2 and the reaches of 3 */
    int small[] = {10, 20, 35, 50, 100};
    int reach[] = {1, 4, 8, 12, 16, 24};
    int bdf_sizes[] = {10, 20, 50, 200};
    double t_end = 0.1;
    for (k = 1; k < argc; k++) {
        if (strcmp(argv[k], "--quick") == 0)
            quick = 1;
        else if (strcmp(argv[k], "--t-end") == 0 && k + 1 < argc)
            t_end = atof(argv[++k]);
        else if (strcmp(argv[k], "--section") == 0 && k + 1 < argc)
            section = atoi(argv[++k]);
        else if (strcmp(argv[k], "--reps") == 0 && k + 1 < argc)
            reps = atoi(argv[++k]);
        else if (strcmp(argv[k], "--sizes") == 0 && k + 1 < argc) {
            given = 1;
            if (!(nsizes = parse_sizes(argv[++k], sizes, 16))) {
                fprintf(stderr, "bench-sparse: --sizes takes N,N,.. "
                        "with 4 <= N <= 2000\n");
                return 2;
            }
        } else {
            fprintf(stderr, "usage: bench-sparse [--quick] [--section 1|2|3|4] "
                    "[--t-end T] [--reps R] [--sizes N,N,..]\n");
            return 2;
        }
    }
    if (reps < 1 || reps > 15 || !(t_end > 0.0)) {
        fprintf(stderr, "bench-sparse: --reps 1 .. 15, --t-end > 0\n");
        return 2;
    }
    if (quick) {
        sizes[0] = 10;
        sizes[1] = 30;
        nsizes = 2;
        reps = 1;
        t_end = 0.01;
    }
    if (section == 0 || section == 1)
        whole_runs(sizes, nsizes, t_end, reps);
    if (!quick && (section == 0 || section == 2))
        crossover(given ? sizes : small,
                  given ? nsizes : (int)(sizeof small / sizeof small[0]),
                  t_end / 4, reps, 0);
    if (!quick && (section == 0 || section == 3))
        crossover(given ? sizes : reach,
                  given ? nsizes : (int)(sizeof reach / sizeof reach[0]),
                  t_end / 4, reps, 1);
    if (section == 4 || (!quick && section == 0))
        bdf_runs(given ? sizes : bdf_sizes,
                 given ? nsizes : (int)(sizeof bdf_sizes / sizeof bdf_sizes[0]),
                 t_end, reps);
    return 0;
}
