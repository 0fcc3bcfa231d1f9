/* bench_rhs.c - the cost of one right-hand-side evaluation (qdd from the
 * state) of chains of rigid and flexible links, by every route:
 *
 *   tape        libeom's eom_rhs, as users call it;
 *   compiled    eom_rhs on compiled tapes (eom_system_set_compiled, built
 *               into a cache of this run's own);
 *   tuples      the same model source run on the embedded-tuple engine
 *               (eom_model_run_lagrangian), then the same Cholesky solve;
 *   hand-coded  rigid chains: M and the forces typed in closed form, then
 *               Cholesky (chain_plain.c): the limit of a Lagrangian route;
 *   ADOL-C      rigid chains, when built with it (bench/adolc): its vector
 *               forward-over-reverse driver, and hessian();
 *   MuJoCo      rigid chains, when built with it (bench/mujoco): mj_forward
 *               on the chain as a URDF model, with setting its state and
 *               reading its accelerations as absolute angles' (bench-peers
 *               compares it in MuJoCo's own equations too);
 *   SymPy       rigid chains that bench/sympy derived at build time: its
 *               C for M and the forces, then the hand-coded route's
 *               Cholesky;
 * each as a multiple of a plain compiled evaluation of L and of the
 * hand-coded right-hand side, in processor time of the bench's thread
 * (so that other work on the machine does not count). Methods are interleaved in each repetition
 * (rotating order) and the table gives medians of the per-repetition
 * ratios; every method's qdd is checked against the tape's in the run
 * (MuJoCo's, which works in other coordinates, by its backward error in
 * libeom's equations, as bench-peers does).
 * A table times LAPACK's Cholesky against a plain inline one for tiny
 * matrices (is a small-matrix path worth having?), a last one libeom's
 * routes for large ones (its column loops, its blocked factor) against
 * the LAPACK the program loaded (Debian's reference one, or OpenBLAS
 * through LD_LIBRARY_PATH), factor and solve, n = 64 .. 800.
 *
 *   --links N1,N2,...  rigid chains of these links only (no flexible
 *                      ones): the long series, e.g. 2,10,50,100,200,400;
 *   --cholesky         the large-matrix table only;
 *   --count ROUTE N K  no timing: set up the N-link rigid chain and call
 *                      ROUTE (tape, compiled, hand-coded, MuJoCo) K times,
 *                      for counting instructions under callgrind (the
 *                      difference of two K is the cost of the calls).
 *
 * usage: bench-rhs [--quick] [--reps R] [--links LIST] [--cholesky]
 *                  [--count ROUTE N K] */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "chain_plain.h"
#include "chain_unequal.h"
#ifdef HAVE_ADOLC
#include "adolc_rhs.h"
#endif
#ifdef HAVE_MUJOCO
#include "mujoco_chain.h"
#endif
#ifdef HAVE_SYMPY
#include "sympy_chains.h"
#endif

void dpotrf_(const char *uplo, const int *n, double *a, const int *lda,
             int *info, size_t uplo_len);
void dpotrs_(const char *uplo, const int *n, const int *nrhs,
             const double *a, const int *lda, double *b, const int *ldb,
             int *info, size_t uplo_len);

enum { M_PLAIN, M_TAPE, M_COMPILED, M_TUPLE, M_HAND, M_ADOLC_VEC,
       M_ADOLC_HESS, M_MUJOCO, M_SYMPY, M_COUNT };
static const char *const mname[M_COUNT] = {
    "plain L", "tape", "compiled", "tuples", "hand-coded", "ADOL-C vector",
    "ADOL-C hessian", "MuJoCo", "SymPy"};

/* Embedded tuples hold n (2n + 1) doubles per value: beyond this many
 * coordinates a run would need gigabytes, so the route is skipped. */
#define TUPLE_MAX_N 60

typedef struct ctx {
    int n;              /* coordinates */
    double *x, *xd;     /* [2n] state and its derivative */
    double *qdd;        /* = xd + n: every route writes qdd here */
    chain_plain cp;
    eom_model *model;
    eom_system *s;
    eom_system *cs;     /* the same model on compiled tapes */
    tp_rec *tup;
    double *M, *g, *h;  /* tuple blocks */
    chain_hand *hand;
#ifdef HAVE_ADOLC
    adolc_rhs *ad[2];
#endif
#ifdef HAVE_MUJOCO
    mujoco_chain *mj;
#endif
#ifdef HAVE_SYMPY
    sympy_chain_fn sym;
    double *Ms, *fs;    /* SymPy's M and forces */
#endif
    int have[M_COUNT];
    double sink;
} ctx;

static void nudge(ctx *c)
{
    c->x[0] += 1e-9; /* a new point every call: nothing can be reused */
}

static void run_plain(void *p)
{
    ctx *c = p;
    nudge(c);
    c->sink += chain_plain_L(&c->cp, c->x);
}

static void run_tape(void *p)
{
    ctx *c = p;
    nudge(c);
    eom_rhs(c->s, 0.0, c->x, c->xd);
    c->sink += c->qdd[0];
}

static void run_compiled(void *p)
{
    ctx *c = p;
    nudge(c);
    eom_rhs(c->cs, 0.0, c->x, c->xd);
    c->sink += c->qdd[0];
}

/* The tuples' blocks, then the same solve as libeom (LAPACK Cholesky). */
static int tuple_rhs(ctx *c)
{
    const int n = c->n;
    int i, info = 0, one = 1;
    if (eom_model_run_lagrangian(c->model, c->tup, c->x) != EOM_OK ||
        tp_tuple_lagrange(c->tup, 0, NULL, c->g, c->M, c->h) < 0)
        return -1;
    for (i = 0; i < n; i++)
        c->qdd[i] = c->g[i] - c->h[i];
    dpotrf_("L", &n, c->M, &n, &info, 1);
    if (info == 0)
        dpotrs_("L", &n, &one, c->M, &n, c->qdd, &n, &info, 1);
    return info;
}

static void run_tuple(void *p)
{
    ctx *c = p;
    nudge(c);
    tuple_rhs(c);
    c->sink += c->qdd[0];
}

static void run_hand(void *p)
{
    ctx *c = p;
    nudge(c);
    chain_plain_hand_rhs(c->hand, c->x, c->qdd);
    c->sink += c->qdd[0];
}

#ifdef HAVE_ADOLC
static void run_adolc_vec(void *p)
{
    ctx *c = p;
    nudge(c);
    adolc_rhs_eval(c->ad[0], c->x, c->qdd, NULL);
    c->sink += c->qdd[0];
}

static void run_adolc_hess(void *p)
{
    ctx *c = p;
    nudge(c);
    adolc_rhs_eval(c->ad[1], c->x, c->qdd, NULL);
    c->sink += c->qdd[0];
}
#endif

#ifdef HAVE_MUJOCO
static void run_mujoco(void *p)
{
    ctx *c = p;
    nudge(c);
    mujoco_chain_set(c->mj, c->x);
    mujoco_chain_forward(c->mj);
    mujoco_chain_qdd(c->mj, c->qdd);
    c->sink += c->qdd[0];
}
#endif

#ifdef HAVE_SYMPY
static void run_sympy(void *p)
{
    ctx *c = p;
    nudge(c);
    c->sym(c->cp.m, c->cp.L, c->cp.g, c->x, c->Ms, c->qdd);
    chain_plain_solve(c->n, c->Ms, c->qdd);
    c->sink += c->qdd[0];
}
#endif

static void (*const mfn[M_COUNT])(void *) = {
    run_plain, run_tape, run_compiled, run_tuple, run_hand,
#ifdef HAVE_ADOLC
    run_adolc_vec, run_adolc_hess,
#else
    NULL, NULL,
#endif
#ifdef HAVE_MUJOCO
    run_mujoco,
#else
    NULL,
#endif
#ifdef HAVE_SYMPY
    run_sympy,
#else
    NULL,
#endif
};

static int setup(ctx *c, int links, int modes, double *mv, double *Lv,
                 double *EIv, int compiled)
{
    char msg[256] = "";
    memset(c, 0, sizeof *c);
    chain_unequal(&c->cp, links, modes, mv, Lv, EIv);
    if (chain_unequal_model(&c->cp, &c->model) != EOM_OK ||
        eom_system_new(&c->s, c->model, msg, sizeof msg) != EOM_OK) {
        fprintf(stderr, "bench-rhs: set-up failed: %s\n", msg);
        return -1;
    }
    c->n = eom_system_ncoords(c->s);
    c->x = calloc(4 * (size_t)c->n, sizeof(double));
    if (!c->x)
        return -1;
    c->xd = c->x + 2 * c->n;
    c->qdd = c->xd + c->n;
    chain_unequal_state(&c->cp, c->n, c->x);
    c->have[M_PLAIN] = c->have[M_TAPE] = 1;
    if (compiled && eom_system_new(&c->cs, c->model, msg, sizeof msg) ==
                        EOM_OK) {
        if (eom_system_set_compiled(c->cs, 1, NULL) == EOM_OK)
            c->have[M_COMPILED] = 1;
        else
            printf("compiled: not timed at n = %d: %s\n", c->n,
                   eom_system_errmsg(c->cs));
    }
    if (c->n <= TUPLE_MAX_N && tp_tuple_new(&c->tup, 2 * c->n, NULL) == 0) {
        c->M = calloc((size_t)c->n * (size_t)(c->n + 2), sizeof(double));
        c->g = c->M + (size_t)c->n * (size_t)c->n;
        c->h = c->g + c->n;
        c->have[M_TUPLE] = c->M != NULL;
    }
    if (modes == 0 && chain_plain_hand_new(&c->hand, &c->cp) == 0)
        c->have[M_HAND] = 1;
#ifdef HAVE_ADOLC
    if (modes == 0) {
        c->have[M_ADOLC_VEC] =
            adolc_rhs_new(&c->ad[0], links, mv, Lv, 9.81,
                          ADOLC_DRIVER_VECTOR, 1) == 0;
        c->have[M_ADOLC_HESS] =
            adolc_rhs_new(&c->ad[1], links, mv, Lv, 9.81,
                          ADOLC_DRIVER_HESSIAN, 2) == 0;
    }
#endif
#ifdef HAVE_MUJOCO
    if (modes == 0) {
        char err[256];
        c->mj = mujoco_chain_new(links, mv, Lv, c->cp.g, err, (int)sizeof err);
        if (c->mj)
            c->have[M_MUJOCO] = 1;
        else
            printf("MuJoCo: cannot load the %d-link chain: %s\n", links, err);
    }
#endif
#ifdef HAVE_SYMPY
    if (modes == 0) {
        int k;
        for (k = 0; sympy_chains[k].N && sympy_chains[k].N != links; k++)
            ;
        c->sym = sympy_chains[k].fn;
        c->Ms = calloc((size_t)links * (size_t)links, sizeof(double));
        c->have[M_SYMPY] = c->sym != NULL && c->Ms != NULL;
    }
#endif
    return 0;
}

static void teardown(ctx *c)
{
#ifdef HAVE_ADOLC
    adolc_rhs_free(&c->ad[0]);
    adolc_rhs_free(&c->ad[1]);
#endif
#ifdef HAVE_MUJOCO
    mujoco_chain_free(c->mj);
#endif
#ifdef HAVE_SYMPY
    free(c->Ms);
#endif
    chain_plain_hand_free(&c->hand);
    tp_rec_free(&c->tup);
    eom_system_free(&c->cs);
    eom_system_free(&c->s);
    eom_model_free(&c->model);
    free(c->M);
    free(c->x);
}

/* The largest relative difference of each method's qdd from the tape's;
 * for MuJoCo, whose forward difference grows with M's condition number
 * in its other coordinates (docs/benchmarks.md, section 10), the backward
 * error |M (qdd_mujoco - qdd)| / (|M| |qdd|) in libeom's equations. */
static double agreement(ctx *c, int k)
{
    const int n = c->n;
    double e = 0.0, scale = 0.0, Mmax = 0.0;
    double *q = malloc((size_t)n * (size_t)(n + 1) * sizeof(double)),
           *M = q + n;
    int i, j;
    if (!q)
        return INFINITY;
    mfn[k](c); /* writes c->qdd at a nudged point: redo the reference */
    memcpy(q, c->qdd, (size_t)n * sizeof(double));
    c->x[0] -= 1e-9;
    run_tape(c);
    if (k == M_MUJOCO && eom_mass_matrix(c->s, c->x, M) == EOM_OK) {
        for (i = 0; i < n; i++) {
            double r = 0.0;
            for (j = 0; j < n; j++) {
                r += M[i * n + j] * (q[j] - c->qdd[j]);
                Mmax = fmax(Mmax, fabs(M[i * n + j]));
            }
            e = fmax(e, fabs(r));
            scale = fmax(scale, fabs(c->qdd[i]));
        }
        free(q);
        return e / fmax(Mmax * scale, 1e-300);
    }
    for (i = 0; i < n; i++) {
        e = fmax(e, fabs(q[i] - c->qdd[i]));
        scale = fmax(scale, fabs(c->qdd[i]));
    }
    free(q);
    return e / fmax(scale, 1e-300);
}

typedef struct result {
    int n;
    double t_plain;          /* seconds */
    double x_plain[M_COUNT]; /* median ratio to plain L */
    double x_hand[M_COUNT];  /* median ratio to hand-coded */
    double agree[M_COUNT];
} result;

static int measure(int links, int modes, int reps, double min_batch,
                   int compiled, result *r)
{
    double *mv = malloc(3 * (size_t)links * sizeof(double));
    double *rp[M_COUNT], *rh[M_COUNT], *tp = malloc((size_t)reps * 8);
    long batch[M_COUNT];
    ctx c;
    int k, i, rep;
    if (!mv || !tp || setup(&c, links, modes, mv, mv + links,
                            mv + 2 * links, compiled) != 0)
        return -1;
    memset(r, 0, sizeof *r);
    r->n = c.n;
    for (k = 0; k < M_COUNT; k++) {
        rp[k] = malloc((size_t)reps * sizeof(double));
        rh[k] = malloc((size_t)reps * sizeof(double));
        r->agree[k] = NAN;
        r->x_plain[k] = r->x_hand[k] = NAN;
        if (c.have[k] && k != M_PLAIN)
            r->agree[k] = agreement(&c, k);
        batch[k] = c.have[k] ? bench_calibrate_cpu(mfn[k], &c, min_batch) : 0;
    }
    for (rep = 0; rep < reps; rep++) {
        double t[M_COUNT];
        for (i = 0; i < M_COUNT; i++) {
            k = (i + rep) % M_COUNT; /* rotate the order */
            t[k] = c.have[k] ? bench_time_cpu(mfn[k], &c, batch[k]) : NAN;
        }
        tp[rep] = t[M_PLAIN];
        for (k = 0; k < M_COUNT; k++) {
            rp[k][rep] = t[k] / t[M_PLAIN];
            rh[k][rep] = c.have[M_HAND] ? t[k] / t[M_HAND] : NAN;
        }
    }
    r->t_plain = bench_median(tp, reps);
    for (k = 0; k < M_COUNT; k++) {
        if (c.have[k]) {
            r->x_plain[k] = bench_median(rp[k], reps);
            if (c.have[M_HAND])
                r->x_hand[k] = bench_median(rh[k], reps);
        }
        free(rp[k]);
        free(rh[k]);
    }
    if (c.sink == 12345.678)
        puts("");
    teardown(&c);
    free(mv);
    free(tp);
    return 0;
}

/* ---- LAPACK against an inline Cholesky for tiny matrices --------------- */

typedef struct chol_ctx {
    int n;
    double *A, *W, *b, sink;
} chol_ctx;

static void chol_lapack(void *p)
{
    chol_ctx *c = p;
    int info = 0, one = 1;
    memcpy(c->W, c->A, (size_t)c->n * (size_t)c->n * sizeof(double));
    c->b[0] += 1e-12;
    dpotrf_("L", &c->n, c->W, &c->n, &info, 1);
    dpotrs_("L", &c->n, &one, c->W, &c->n, c->b, &c->n, &info, 1);
    c->sink += c->b[0];
}

static void chol_inline(void *p)
{
    chol_ctx *c = p;
    const int n = c->n;
    double *L = c->W, *b = c->b;
    int i, j, k;
    memcpy(L, c->A, (size_t)n * (size_t)n * sizeof(double));
    b[0] += 1e-12;
    for (j = 0; j < n; j++) {
        double d = L[j * n + j];
        for (k = 0; k < j; k++)
            d -= L[j * n + k] * L[j * n + k];
        d = sqrt(d);
        L[j * n + j] = d;
        for (i = j + 1; i < n; i++) {
            double s = L[i * n + j];
            for (k = 0; k < j; k++)
                s -= L[i * n + k] * L[j * n + k];
            L[i * n + j] = s / d;
        }
    }
    for (i = 0; i < n; i++) { /* L y = b */
        for (k = 0; k < i; k++)
            b[i] -= L[i * n + k] * b[k];
        b[i] /= L[i * n + i];
    }
    for (i = n; i-- > 0;) { /* L^T x = y */
        for (k = i + 1; k < n; k++)
            b[i] -= L[k * n + i] * b[k];
        b[i] /= L[i * n + i];
    }
    c->sink += b[0];
}

static void cholesky_table(int reps, double min_batch)
{
    static const int sizes[] = {2, 3, 5, 10, 20};
    size_t s;
    printf("\nCholesky factor and solve of an n x n SPD matrix: time in ns "
           "(median of %d)\n\n| n | LAPACK dpotrf + dpotrs | inline | "
           "LAPACK / inline |\n|---|---|---|---|\n", reps);
    for (s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
        const int n = sizes[s];
        chol_ctx c;
        double *tl = malloc((size_t)reps * 8), *ti = malloc((size_t)reps * 8),
               *rt = malloc((size_t)reps * 8);
        long bl, bi;
        int i, j, rep;
        c.n = n;
        c.sink = 0.0;
        c.A = calloc((size_t)(2 * n * n + n), sizeof(double));
        c.W = c.A + n * n;
        c.b = c.W + n * n;
        for (i = 0; i < n; i++) {
            for (j = 0; j < n; j++)
                c.A[i * n + j] = 1.0 / (1.0 + i + j) + (i == j ? n : 0.0);
            c.b[i] = 1.0;
        }
        bl = bench_calibrate_cpu(chol_lapack, &c, min_batch);
        bi = bench_calibrate_cpu(chol_inline, &c, min_batch);
        for (rep = 0; rep < reps; rep++) {
            tl[rep] = bench_time_cpu(chol_lapack, &c, bl);
            ti[rep] = bench_time_cpu(chol_inline, &c, bi);
            rt[rep] = tl[rep] / ti[rep];
        }
        printf("| %d | %.0f | %.0f | %.1f |\n", n,
               1e9 * bench_median(tl, reps), 1e9 * bench_median(ti, reps),
               bench_median(rt, reps));
        free(c.A);
        free(tl);
        free(ti);
        free(rt);
    }
}

/* ---- libeom's routes against LAPACK for large matrices ---------------- */

typedef struct big_ctx {
    int n, route;
    double *A, *W, *b, sink;
} big_ctx;

static void big_solve(void *p)
{
    big_ctx *c = p;
    memcpy(c->W, c->A, (size_t)c->n * (size_t)c->n * sizeof(double));
    c->b[0] += 1e-12;
    if (chain_plain_solve_by(c->route, c->n, c->W, c->b) != 0)
        c->sink = NAN;
    c->sink += c->b[0];
}

static void large_cholesky_table(int reps, double min_batch, int quick)
{
    static const int sizes[] = {64, 128, 129, 200, 300, 400, 513, 800};
    size_t s;
    printf("\nCholesky factor and solve of a large SPD matrix: time in us "
           "(median of %d interleaved), and as multiples of libeom's "
           "blocked factor; the largest relative difference of the "
           "solutions from the blocked one's\n\n| n | columns | blocked | "
           "LAPACK | columns / blocked | LAPACK / blocked | difference "
           "|\n|---|---|---|---|---|---|---|\n", reps);
    for (s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
        const int n = sizes[s];
        const size_t N = (size_t)n;
        big_ctx c[3];
        double *t[3], *rt[2], *A = malloc((2 * N * N + 4 * N) * 8);
        double diff = 0.0, scale = 0.0;
        long batch[3];
        size_t i, j;
        int k, rep;
        if (quick && n > 129)
            break;
        if (!A)
            return;
        for (i = 0; i < N; i++) /* diagonally dominant, unequal scales */
            for (j = 0; j < N; j++)
                A[i * N + j] = 1.0 / (1.0 + (double)(i + j)) +
                               (i == j ? (double)n + (double)i : 0.0);
        for (k = 0; k < 3; k++) {
            c[k].n = n;
            c[k].route = k == 0   ? CHAIN_SOLVE_COLUMNS
                         : k == 1 ? CHAIN_SOLVE_BLOCKED
                                  : CHAIN_SOLVE_LAPACK;
            c[k].A = A;
            c[k].W = A + N * N;
            c[k].b = A + 2 * N * N + (size_t)k * N;
            c[k].sink = 0.0;
            for (i = 0; i < N; i++)
                c[k].b[i] = sin(0.3 * (double)i);
            big_solve(&c[k]); /* one solve to compare: b = M^-1 (b + e) */
            t[k] = malloc((size_t)reps * sizeof(double));
        }
        for (i = 0; i < N; i++) {
            for (k = 0; k < 3; k += 2)
                diff = fmax(diff, fabs(c[k].b[i] - c[1].b[i]));
            scale = fmax(scale, fabs(c[1].b[i]));
        }
        for (k = 0; k < 3; k++)
            batch[k] = bench_calibrate_cpu(big_solve, &c[k], min_batch);
        rt[0] = malloc((size_t)reps * sizeof(double));
        rt[1] = malloc((size_t)reps * sizeof(double));
        for (rep = 0; rep < reps; rep++) {
            for (k = 0; k < 3; k++) {
                const int r = (k + rep) % 3; /* rotate the order */
                t[r][rep] = bench_time_cpu(big_solve, &c[r], batch[r]);
            }
            rt[0][rep] = t[0][rep] / t[1][rep];
            rt[1][rep] = t[2][rep] / t[1][rep];
        }
        printf("| %d | %.1f | %.1f | %.1f | %.2f | %.2f | %.1e |\n", n,
               1e6 * bench_median(t[0], reps), 1e6 * bench_median(t[1], reps),
               1e6 * bench_median(t[2], reps), bench_median(rt[0], reps),
               bench_median(rt[1], reps), diff / scale);
        for (k = 0; k < 3; k++)
            free(t[k]);
        free(rt[0]);
        free(rt[1]);
        free(A);
    }
}

/* --count: ROUTE called K times on the N-link rigid chain, untimed. */
static int count_calls(const char *route, int links, long K)
{
    ctx c;
    double *mv = malloc(3 * (size_t)links * sizeof(double));
    long i;
    int k;
    for (k = 0; k < M_COUNT && strcmp(mname[k], route); k++)
        ;
    if (k == M_COUNT || !mfn[k] || !mv) {
        fprintf(stderr, "bench-rhs: --count: no route '%s' in this build "
                "(tape, compiled, hand-coded, MuJoCo, ...)\n", route);
        free(mv);
        return 2;
    }
    if (setup(&c, links, 0, mv, mv + links, mv + 2 * links,
              k == M_COMPILED) != 0 || !c.have[k]) {
        fprintf(stderr, "bench-rhs: --count: %s cannot run at %d links\n",
                route, links);
        free(mv);
        return 1;
    }
    for (i = 0; i < K; i++)
        mfn[k](&c);
    printf("%s, %d links: %ld calls (checksum %.17g)\n", route, links, K,
           c.sink);
    teardown(&c);
    free(mv);
    return 0;
}

int main(int argc, char **argv)
{
    static const int rigid_default[] = {2, 5, 10, 20, 50};
    static const int flex[][2] = {{3, 2}, {5, 1}, {10, 2}, {20, 3}, {50, 3}};
    const char *usage = "usage: bench-rhs [--quick] [--reps R] "
                        "[--links N1,N2,...] [--cholesky] "
                        "[--count ROUTE N K]\n";
    char dir[] = "/tmp/bench-rhs-XXXXXX", cmd[128];
    int rigid[32], nrigid = 5, nflex = 5, cholesky_only = 0;
    int reps = 15, quick = 0, i, k, ok = 1, mujoco_bad;
    double min_batch = 5e-3;
    memcpy(rigid, rigid_default, sizeof rigid_default);
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) {
            quick = 1;
            reps = 3;
            min_batch = 2e-4;
        } else if (!strcmp(argv[i], "--reps") && i + 1 < argc) {
            reps = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--links") && i + 1 < argc) {
            if ((nrigid = bench_parse_links(argv[++i], rigid, 32)) < 1) {
                fprintf(stderr, "bench-rhs: --links wants numbers of "
                        "links separated by commas, such as 2,10,50\n");
                return 2;
            }
            nflex = 0;
        } else if (!strcmp(argv[i], "--cholesky")) {
            cholesky_only = 1;
        } else if (!strcmp(argv[i], "--count") && i + 3 < argc) {
            const int links = atoi(argv[i + 2]);
            const long K = atol(argv[i + 3]);
            if (links < 1 || K < 0) {
                fputs(usage, stderr);
                return 2;
            }
            return count_calls(argv[i + 1], links, K);
        } else {
            fputs(usage, stderr);
            return 2;
        }
    }
    if (reps < 1)
        return 2;
    if (cholesky_only) {
        large_cholesky_table(reps, min_batch, quick);
        return 0;
    }
    /* compiled tapes in a cache of this run's own: compiled cold */
    if (mkdtemp(dir))
        setenv("AUTOEOM_CACHE_DIR", dir, 1);
    printf("Right-hand side of chains of links: time as multiples of a "
           "plain compiled evaluation of L (median of %d interleaved "
           "repetitions); in brackets, as multiples of the hand-coded "
           "right-hand side\n\n| chain | n | plain L (us) |", reps);
    for (k = 1; k < M_COUNT; k++)
        printf(" %s |", mname[k]);
    printf(" agreement | MuJoCo: backward |\n|---|---|---|");
    for (k = 1; k < M_COUNT; k++)
        printf("---|");
    printf("---|---|\n");
    for (i = 0; i < nrigid + nflex; i++) {
        const int links = i < nrigid ? rigid[i] : flex[i - nrigid][0];
        const int modes = i < nrigid ? 0 : flex[i - nrigid][1];
        result r;
        double worst = 0.0;
        if (quick && (links > 5))
            continue;
        /* compiled: cold, into this run's cache (--quick: small chains) */
        if (measure(links, modes, reps, min_batch, !quick || links <= 2,
                    &r) != 0)
            return 1;
        if (modes)
            printf("| %d links x %d mode%s | %d | %.2f |", links, modes,
                   modes == 1 ? "" : "s", r.n, 1e6 * r.t_plain);
        else
            printf("| %d rigid links | %d | %.2f |", links, r.n,
                   1e6 * r.t_plain);
        for (k = 1; k < M_COUNT; k++) {
            if (isnan(r.x_plain[k])) {
                printf(" - |");
                continue;
            }
            if (isnan(r.x_hand[k]))
                printf(" %.1f |", r.x_plain[k]);
            else
                printf(" %.1f (%.2f) |", r.x_plain[k], r.x_hand[k]);
            if (k != M_MUJOCO)
                worst = fmax(worst, r.agree[k]);
        }
        printf(" %.1e |", worst);
        if (isnan(r.agree[M_MUJOCO]))
            printf(" - |");
        else
            printf(" %.1e |", r.agree[M_MUJOCO]);
        /* its backward error in absolute angles grows with the chain
         * as n^2: relative angles are a sum away (7e-13 at 50 unequal
         * links, 3e-12 at 100, 6e-11 at 400) */
        mujoco_bad = r.agree[M_MUJOCO] > fmax(1e-12, 1e-15 * r.n * r.n);
        printf("%s\n", worst < 1e-9 && !mujoco_bad ? "" : " DISAGREE");
        ok &= worst < 1e-9 && !mujoco_bad;
        fflush(stdout);
    }
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "bench-rhs: could not remove %s\n", dir);
    cholesky_table(reps, min_batch);
    large_cholesky_table(reps, min_batch, quick);
    return ok ? 0 : 1;
}
