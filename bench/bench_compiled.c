/* bench_compiled.c - compiled tapes (eom_system_set_compiled) against the
 * interpreter and the hand-coded equations, on the chains of the element
 * library (the same chains as bench-rhs: unequal links, gravity, open;
 * and closed, the tip pinned at 0.9 of the chain's length, so that the
 * constraints' Jacobian and gamma run compiled too):
 *
 *   - set-up: recording (eom_system_new), then compiling every tape into a
 *     fresh cache (emit + compile + load + check, cold), and again from
 *     the cache (warm), with the generated source's size;
 *   - one right-hand side: interpreted, compiled and, for rigid chains,
 *     hand-coded (chain_plain.c, the limit of a Lagrangian route), timed
 *     interleaved in processor time of the thread; medians of the
 *     per-repetition ratios; the largest
 *     relative difference of the compiled qdd from the interpreted one.
 *
 * The cache is a temporary directory of this run; CC and AUTOEOM_CFLAGS
 * choose the compiler and flags as for any user (default cc -O1).
 *
 * --compare runs every row twice, with the straight-line code of
 * libtape's former generator (AUTOEOM_CODEGEN=straight) and with the
 * default (repeated runs as loops); --chain L, LxM or L[xM]c (closed)
 * picks rows (any number; default: the table of docs/benchmarks.md).
 * The processor time of the set-up (record, emit, compile, load, check)
 * counts the compilers, which run as children.
 *
 * --calls K runs K compiled right-hand sides of each --chain and
 * nothing else (the cache as the environment says; for callgrind: run
 * with K and with 0 and divide the difference by K).
 *
 * usage: bench-compiled [--quick] [--reps R] [--compare]
 *                       [--chain L[xM][c]]... [--calls K] */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <sys/resource.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "chain_unequal.h"

typedef struct ctx {
    eom_system *s;
    double *x, *xd;
    chain_hand *hand;
    double *qdd;
} ctx;

static void call_rhs(void *p)
{
    ctx *c = p;
    eom_rhs(c->s, 0.0, c->x, c->xd);
}

static void call_hand(void *p)
{
    ctx *c = p;
    chain_plain_hand_rhs(c->hand, c->x, c->qdd);
}

/* Processor time (user + system) of this process and its waited-for
 * children, in seconds: the compilers run as children. */
static double cpu_now(void)
{
    struct rusage a, b;
    getrusage(RUSAGE_SELF, &a);
    getrusage(RUSAGE_CHILDREN, &b);
    return (double)(a.ru_utime.tv_sec + a.ru_stime.tv_sec + b.ru_utime.tv_sec +
                    b.ru_stime.tv_sec) +
           1e-6 * (double)(a.ru_utime.tv_usec + a.ru_stime.tv_usec +
                           b.ru_utime.tv_usec + b.ru_stime.tv_usec);
}

static eom_system *make(chain_plain *cp, int links, int modes, int closed,
                        double *mv, double *Lv, double *EIv)
{
    eom_model *m = NULL;
    eom_system *s = NULL;
    char msg[256] = "";
    chain_unequal(cp, links, modes, mv, Lv, EIv);
    if ((closed ? chain_unequal_closed_model(cp, &m)
                : chain_unequal_model(cp, &m)) != EOM_OK ||
        eom_system_new(&s, m, msg, sizeof msg) != EOM_OK)
        fprintf(stderr, "bench-compiled: set-up failed: %s\n", msg);
    eom_model_free(&m);
    return s;
}

static void row(int links, int modes, int closed, int reps)
{
    double mv[512], Lv[512], EIv[512], t0, c0, t_rec, t_cold, c_cold,
        t_warm;
    double rc[64], rh[64], ti[64], tc[64], th[64], diff = 0.0;
    eom_compiled_info cold, warm;
    eom_system *s, *s2;
    ctx ci, cc, ch;
    chain_plain cp;
    int n, k, i, st;
    char label[48], hand[32];
    double *xdi;

    t0 = bench_now();
    c0 = cpu_now();
    s = make(&cp, links, modes, closed, mv, Lv, EIv);
    t_rec = bench_now() - t0;
    if (!s)
        return;
    n = eom_system_ncoords(s);
    t0 = bench_now();
    st = eom_system_set_compiled(s, 1, &cold);
    t_cold = bench_now() - t0;
    c_cold = cpu_now() - c0; /* record + emit + compile + load + check */
    if (st != EOM_OK) {
        printf("| %d x %d%s | compiled tapes unavailable: %s |\n", links,
               modes, closed ? ", closed" : "", eom_system_errmsg(s));
        eom_system_free(&s);
        return;
    }
    /* a second system: its tapes are found in the cache */
    s2 = make(&cp, links, modes, closed, mv, Lv, EIv);
    t0 = bench_now();
    eom_system_set_compiled(s2, 1, &warm);
    t_warm = bench_now() - t0;

    memset(&ci, 0, sizeof ci);
    ci.x = calloc(4 * (size_t)n + (size_t)n, sizeof(double));
    ci.xd = ci.x + 2 * n;
    chain_unequal_state(&cp, n, ci.x);
    ci.s = s2;
    eom_system_set_compiled(s2, 0, NULL); /* s2: the interpreter */
    cc = ci;
    cc.s = s;
    xdi = malloc(2 * (size_t)n * sizeof(double));
    eom_rhs(s2, 0.0, ci.x, xdi);
    eom_rhs(s, 0.0, ci.x, ci.xd);
    for (i = 0; i < n; i++)
        diff = fmax(diff, fabs(ci.xd[n + i] - xdi[n + i]) /
                              fmax(1.0, fabs(xdi[n + i])));
    ch = ci;
    ch.hand = NULL;
    ch.qdd = ci.x + 4 * n;
    if (modes == 0 && !closed && chain_plain_hand_new(&ch.hand, &cp) != 0)
        ch.hand = NULL;
    {
        /* processor time of this thread: the machine may be shared */
        const long bi = bench_calibrate_cpu(call_rhs, &ci, 0.01);
        const long bh =
            ch.hand ? bench_calibrate_cpu(call_hand, &ch, 0.01) : 0;
        for (k = 0; k < reps; k++) {
            ti[k] = bench_time_cpu(call_rhs, &ci, bi);
            tc[k] = bench_time_cpu(call_rhs, &cc, bi);
            th[k] = ch.hand ? bench_time_cpu(call_hand, &ch, bh) : NAN;
            rc[k] = ti[k] / tc[k];
            rh[k] = tc[k] / th[k];
        }
    }
    if (modes)
        snprintf(label, sizeof label, "%d links x %d modes%s", links, modes,
                 closed ? ", closed" : "");
    else
        snprintf(label, sizeof label, "%d rigid links%s", links,
                 closed ? ", closed" : "");
    printf("| %s | %d | %.3g | %.3g | %.3g | %.3g | %zu | %.3g | %.3g | %.2f | "
           "%s | %.1e |\n",
           label, n, 1e3 * t_rec, t_cold, c_cold, 1e3 * t_warm,
           cold.source_bytes,
           1e6 * bench_median(ti, reps), 1e6 * bench_median(tc, reps),
           bench_median(rc, reps),
           ch.hand ? (snprintf(hand, sizeof hand, "%.2f",
                               bench_median(rh, reps)),
                      hand)
                   : "-",
           diff);
    (void)warm;
    chain_plain_hand_free(&ch.hand);
    free(ci.x);
    free(xdi);
    eom_system_free(&s);
    eom_system_free(&s2);
}

/* K compiled right-hand sides of one chain and nothing else, for
 * instruction counts and cache misses (callgrind: run with K and with 0
 * and take the difference); prints a checksum of the accelerations. */
static int calls_only(int links, int modes, int closed, long K)
{
    double mv[512], Lv[512], EIv[512], sum = 0.0, *x;
    chain_plain cp;
    eom_system *s = make(&cp, links, modes, closed, mv, Lv, EIv);
    long k;
    int n, i;
    if (!s)
        return 1;
    if (eom_system_set_compiled(s, 1, NULL) != EOM_OK) {
        fprintf(stderr, "bench-compiled: %s\n", eom_system_errmsg(s));
        eom_system_free(&s);
        return 1;
    }
    n = eom_system_ncoords(s);
    x = calloc(4 * (size_t)n, sizeof(double));
    chain_unequal_state(&cp, n, x);
    for (k = 0; k < K; k++) {
        eom_rhs(s, 0.0, x, x + 2 * n);
        for (i = 0; i < n; i++)
            sum += x[3 * n + i];
    }
    printf("%d x %d%s: %ld calls, checksum %.17g\n", links, modes,
           closed ? " closed" : "", K, sum);
    free(x);
    eom_system_free(&s);
    return 0;
}

/* One row, or with compare two: the straight-line code first (libtape's
 * generator before loops, AUTOEOM_CODEGEN=straight), then the default. */
static void rows(int links, int modes, int closed, int reps, int compare)
{
    if (compare) {
        setenv("AUTOEOM_CODEGEN", "straight", 1);
        printf("| straight-line: ");
        row(links, modes, closed, reps);
        unsetenv("AUTOEOM_CODEGEN");
        printf("| loops: ");
    }
    row(links, modes, closed, reps);
}

int main(int argc, char **argv)
{
    static const int rigid[] = {2, 5, 10, 20, 50};
    static const int flex[][2] = {{3, 2}, {10, 2}, {20, 3}, {50, 3}};
    static const int closed[][2] = {{5, 0}, {5, 3}, {20, 0}};
    int chosen[32][3], nchosen = 0;
    char dir[] = "/tmp/bench-compiled-XXXXXX", cmd[128];
    int quick = 0, reps = 15, compare = 0, k;
    long calls = -1;
    for (k = 1; k < argc; k++) {
        int l = 0, m = 0;
        char c = 0;
        if (!strcmp(argv[k], "--quick"))
            quick = 1;
        else if (!strcmp(argv[k], "--reps") && k + 1 < argc)
            reps = atoi(argv[++k]);
        else if (!strcmp(argv[k], "--compare"))
            compare = 1;
        else if (!strcmp(argv[k], "--calls") && k + 1 < argc)
            calls = atol(argv[++k]);
        else if (!strcmp(argv[k], "--chain") && k + 1 < argc && nchosen < 32 &&
                 sscanf(argv[k + 1], "%d%c%d", &l, &c, &m) >= 1 && l >= 1 &&
                 l <= 400 && m >= 0 && m <= 8) {
            chosen[nchosen][0] = l;
            chosen[nchosen][1] = c == 'x' ? m : 0;
            chosen[nchosen][2] = strchr(argv[k + 1], 'c') != NULL;
            nchosen++;
            k++;
        } else {
            fprintf(stderr, "usage: bench-compiled [--quick] [--reps R] "
                            "[--compare] [--chain L[xM][c]]... "
                            "[--calls K]\n");
            return 2;
        }
    }
    if (calls >= 0) { /* the cache as the environment says */
        int rc = 0;
        for (k = 0; k < nchosen; k++)
            rc |= calls_only(chosen[k][0], chosen[k][1], chosen[k][2], calls);
        return rc;
    }
    if (quick)
        reps = 3;
    if (reps < 1 || reps > 64)
        reps = 15;
    if (!mkdtemp(dir)) {
        perror("bench-compiled: mkdtemp");
        return 1;
    }
    setenv("AUTOEOM_CACHE_DIR", dir, 1);
    printf("compiler: %s, flags: %s\n\n",
           getenv("CC") ? getenv("CC") : "cc",
           getenv("AUTOEOM_CFLAGS") ? getenv("AUTOEOM_CFLAGS") : "-O1");
    printf("| chain | n | record (ms) | compile, cold (s) | "
           "record + compile, cold, processor (s) | from cache (ms) | "
           "source (bytes) | interpreted (us) | compiled (us) | "
           "interpreted / compiled | compiled / hand-coded | difference |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    if (nchosen) {
        for (k = 0; k < nchosen; k++)
            rows(chosen[k][0], chosen[k][1], chosen[k][2], reps, compare);
    } else {
        for (k = 0; k < (quick ? 2 : 5); k++)
            rows(rigid[k], 0, 0, reps, compare);
        for (k = 0; k < (quick ? 1 : 4); k++)
            rows(flex[k][0], flex[k][1], 0, reps, compare);
        for (k = 0; k < (quick ? 1 : 3); k++)
            rows(closed[k][0], closed[k][1], 1, reps, compare);
    }
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "bench-compiled: could not remove %s\n", dir);
    return 0;
}
