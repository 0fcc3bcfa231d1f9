/* bench_tape.c - libtape on the N-link pendulum Lagrangian: the cost of
 * each derivative product as a multiple of a plain compiled evaluation of
 * L, against the same blocks from embedded tuples, with heap allocations
 * per sweep, tape bytes per op, and the agreement of every method checked
 * in the same run.
 *
 * Methods are interleaved within each repetition (in rotating order); each
 * repetition gives one ratio per method, and the table reports the median
 * of those ratios, which is robust to the machine's other load.
 *
 * usage: bench-tape [--quick] [--reps R] [--sizes 2,5,10,20,50] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "pendulum_chain.h"
#include "tape/tape.h"

enum { M_PLAIN, M_EVAL, M_GRAD, M_HVP, M_BLOCK, M_TUPLE, M_COUNT };
static const char *method_name[M_COUNT] = {
    "plain L", "tape L", "gradient", "Hv", "Lagrange block", "tuples"};

typedef struct ctx {
    pendulum_chain pc;
    int n;           /* links; 2n independents */
    double *x;       /* [2n] state, nudged every call */
    double *w1;      /* [n_out] weights selecting L */
    double *dir;     /* [2n] direction for Hv */
    double *g, *Hv, *y, *dLdq, *M, *h; /* results */
    tp_tape *tape;
    tp_ws *ws;
    tp_rec *tup;
    double sink;
} ctx;

static void nudge(ctx *c)
{
    /* a new point each call, so no result can be reused */
    c->x[0] += 1e-9;
    if (c->x[0] > 2.0)
        c->x[0] = 0.3;
}

static void run_plain(void *p)
{
    ctx *c = p;
    nudge(c);
    c->sink += pendulum_chain_L(&c->pc, c->x);
}

static void run_eval(void *p)
{
    ctx *c = p;
    nudge(c);
    tp_eval(c->ws, c->x, c->y);
    c->sink += c->y[0];
}

static void run_grad(void *p)
{
    ctx *c = p;
    nudge(c);
    tp_gradient(c->ws, c->x, 0, NULL, c->g);
    c->sink += c->g[0];
}

static void run_hvp(void *p)
{
    ctx *c = p;
    nudge(c);
    tp_hvp(c->ws, c->x, c->w1, 1, c->dir, c->g, c->Hv);
    c->sink += c->Hv[0];
}

static void run_block(void *p)
{
    ctx *c = p;
    double L;
    nudge(c);
    tp_lagrange(c->ws, c->x, 0, &L, c->dLdq, c->M, c->h);
    c->sink += c->M[0] + c->h[0];
}

static void run_tuple(void *p)
{
    ctx *c = p;
    double L;
    nudge(c);
    tp_rec_run(c->tup, c->x, pendulum_chain_record, &c->pc);
    tp_tuple_lagrange(c->tup, 0, &L, c->dLdq, c->M, c->h);
    c->sink += c->M[0] + c->h[0];
}

static void (*const method_fn[M_COUNT])(void *) = {
    run_plain, run_eval, run_grad, run_hvp, run_block, run_tuple};

static double maxabs(const double *a, int n)
{
    double m = 0.0;
    int i;
    for (i = 0; i < n; i++)
        m = fmax(m, fabs(a[i]));
    return m;
}

static double maxdiff(const double *a, const double *b, int n)
{
    double m = 0.0;
    int i;
    for (i = 0; i < n; i++)
        m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

/* Agreement of the methods at the current point: the largest relative
 * difference of the tape's blocks from the tuples' and of M from its closed
 * form. Returns 0 when every check holds. */
static int check_agreement(ctx *c, double *err_closed, double *err_tuples)
{
    const int n = c->n;
    double L1, L2, *d2 = malloc(sizeof(double) * (size_t)n),
                   *M2 = malloc(sizeof(double) * (size_t)(n * n)),
                   *h2 = malloc(sizeof(double) * (size_t)n);
    double sM, e;
    int rc = 0;
    if (!d2 || !M2 || !h2) {
        free(d2);
        free(M2);
        free(h2);
        return 1;
    }
    rc |= tp_lagrange(c->ws, c->x, 0, &L1, c->dLdq, c->M, c->h) != TP_OK;
    pendulum_chain_mass(&c->pc, c->x, M2);
    sM = maxabs(M2, n * n);
    *err_closed = maxdiff(c->M, M2, n * n) / sM;
    rc |= tp_rec_run(c->tup, c->x, pendulum_chain_record, &c->pc) != TP_OK;
    rc |= tp_tuple_lagrange(c->tup, 0, &L2, d2, M2, h2) != TP_OK;
    e = fabs(L1 - L2) / fmax(1.0, fabs(L2));
    e = fmax(e, maxdiff(c->dLdq, d2, n) / fmax(1.0, maxabs(d2, n)));
    e = fmax(e, maxdiff(c->M, M2, n * n) / sM);
    e = fmax(e, maxdiff(c->h, h2, n) / fmax(1.0, maxabs(h2, n)));
    *err_tuples = e;
    rc |= fabs(pendulum_chain_L(&c->pc, c->x) - L1) > 1e-12 * fmax(1, fabs(L1));
    rc |= *err_closed > 1e-13 || *err_tuples > 1e-12;
    free(d2);
    free(M2);
    free(h2);
    return rc;
}

typedef struct row {
    int n;
    size_t ops;
    double bytes_per_op;
    double t_plain;            /* seconds, median */
    double ratio[M_COUNT];     /* median of per-repetition ratios to plain */
    double per_dir;            /* (block - gradient) / n, in plain L */
    double block_vs_tuples;    /* median of tuples / block */
    double allocs_per_sweep;
    double err_closed, err_tuples;
    int ok;
} row;

static int bench_size(int n, int reps, double min_batch, row *out)
{
    ctx c;
    unsigned char *group = malloc((size_t)(2 * n));
    double *ratio[M_COUNT], *perdir = malloc(sizeof(double) * (size_t)reps),
                            *bvt = malloc(sizeof(double) * (size_t)reps),
                            *tplain = malloc(sizeof(double) * (size_t)reps);
    long batch[M_COUNT];
    tp_rec *rec = NULL;
    tp_tape_stats st;
    int i, r, k, rc = 0;
    unsigned long long a0;

    memset(&c, 0, sizeof c);
    c.n = n;
    c.pc.n = n;
    c.pc.g = 9.81;
    c.x = calloc((size_t)(2 * n), sizeof(double));
    c.w1 = calloc(3, sizeof(double));
    c.dir = calloc((size_t)(2 * n), sizeof(double));
    c.g = calloc((size_t)(2 * n), sizeof(double));
    c.Hv = calloc((size_t)(2 * n), sizeof(double));
    c.y = calloc(3, sizeof(double));
    c.dLdq = calloc((size_t)n, sizeof(double));
    c.M = calloc((size_t)(n * n), sizeof(double));
    c.h = calloc((size_t)n, sizeof(double));
    for (k = 0; k < M_COUNT; k++)
        ratio[k] = malloc(sizeof(double) * (size_t)reps);
    for (i = 0; i < 2 * n; i++) {
        group[i] = i < n ? 0 : 1;
        c.x[i] = i < n ? 0.3 + 0.1 * i : 0.2 - 0.05 * (i - n);
        c.dir[i] = 1.0 / (1.0 + i);
    }
    c.w1[0] = 1.0;
    if (tp_recorder_new(&rec, 2 * n, group, NULL) ||
        tp_rec_run(rec, NULL, pendulum_chain_record, &c.pc) ||
        tp_recorder_finish(rec, &c.tape) || tp_ws_new(&c.ws, c.tape, n, NULL) ||
        tp_tuple_new(&c.tup, 2 * n, NULL)) {
        fprintf(stderr, "bench-tape: set-up failed for N = %d: %s\n", n,
                rec ? tp_rec_errmsg(rec) : "");
        return 1;
    }
    tp_tape_stats_get(c.tape, &st);
    out->n = n;
    out->ops = st.n_ops;
    out->bytes_per_op = (double)st.bytes / (double)st.n_ops;
    out->ok = check_agreement(&c, &out->err_closed, &out->err_tuples) == 0;

    /* heap allocations during sweeps (the tuples' pool is warm too) */
    for (k = 0; k < M_COUNT; k++)
        method_fn[k](&c);
    a0 = bench_alloc_count();
    for (i = 0; i < 100; i++)
        for (k = M_EVAL; k <= M_BLOCK; k++)
            method_fn[k](&c);
    out->allocs_per_sweep = (double)(bench_alloc_count() - a0) / 400.0;

    for (k = 0; k < M_COUNT; k++)
        batch[k] = bench_calibrate(method_fn[k], &c, min_batch);
    for (r = 0; r < reps; r++) {
        double t[M_COUNT];
        for (i = 0; i < M_COUNT; i++) {
            k = (i + r) % M_COUNT; /* rotate the order */
            t[k] = bench_time(method_fn[k], &c, batch[k]);
        }
        for (k = 0; k < M_COUNT; k++)
            ratio[k][r] = t[k] / t[M_PLAIN];
        tplain[r] = t[M_PLAIN];
        perdir[r] = (t[M_BLOCK] - t[M_GRAD]) / n / t[M_PLAIN];
        bvt[r] = t[M_TUPLE] / t[M_BLOCK];
    }
    for (k = 0; k < M_COUNT; k++)
        out->ratio[k] = bench_median(ratio[k], reps);
    out->t_plain = bench_median(tplain, reps);
    out->per_dir = bench_median(perdir, reps);
    out->block_vs_tuples = bench_median(bvt, reps);
    /* check again after all the nudging */
    out->ok &= check_agreement(&c, &out->err_closed, &out->err_tuples) == 0;

    if (c.sink == 12345.678)
        puts(""); /* keep the results observable */
    tp_ws_free(&c.ws);
    tp_tape_free(&c.tape);
    tp_rec_free(&rec);
    tp_rec_free(&c.tup);
    for (k = 0; k < M_COUNT; k++)
        free(ratio[k]);
    free(perdir);
    free(bvt);
    free(tplain);
    free(group);
    free(c.x);
    free(c.w1);
    free(c.dir);
    free(c.g);
    free(c.Hv);
    free(c.y);
    free(c.dLdq);
    free(c.M);
    free(c.h);
    return rc;
}

int main(int argc, char **argv)
{
    int sizes[16] = {2, 5, 10, 20, 50}, n_sizes = 5, reps = 21, i, k;
    double min_batch = 5e-3;
    int all_ok = 1;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) {
            reps = 3;
            min_batch = 2e-4;
            n_sizes = 2;
        } else if (!strcmp(argv[i], "--reps") && i + 1 < argc) {
            reps = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--sizes") && i + 1 < argc) {
            char *s = argv[++i], *end;
            n_sizes = 0;
            while (*s && n_sizes < 16) {
                sizes[n_sizes++] = (int)strtol(s, &end, 10);
                s = *end ? end + 1 : end;
            }
        } else {
            fprintf(stderr, "usage: bench-tape [--quick] [--reps R] "
                            "[--sizes 2,5,10]\n");
            return 2;
        }
    }
    if (reps < 1) {
        fprintf(stderr, "bench-tape: --reps must be >= 1\n");
        return 2;
    }
    printf("N-link pendulum; times as multiples of a plain compiled "
           "evaluation of L (median of %d interleaved repetitions)\n\n",
           reps);
    printf("| N | tape ops | bytes/op | plain L (ns) |");
    for (k = 1; k < M_COUNT; k++)
        printf(" %s |", method_name[k]);
    printf(" per direction | tuples / block | allocs/sweep | M vs closed "
           "form | tape vs tuples |\n|");
    for (k = 0; k < M_COUNT + 9; k++)
        printf("---|");
    printf("\n");
    for (i = 0; i < n_sizes; i++) {
        row rw;
        if (sizes[i] < 1 || bench_size(sizes[i], reps, min_batch, &rw))
            return 1;
        printf("| %d | %zu | %.1f | %.0f |", rw.n, rw.ops, rw.bytes_per_op,
               rw.t_plain * 1e9);
        for (k = 1; k < M_COUNT; k++)
            printf(" %.2f |", rw.ratio[k]);
        printf(" %.2f | %.1f | %.0f | %.1e | %.1e |%s\n", rw.per_dir,
               rw.block_vs_tuples, rw.allocs_per_sweep, rw.err_closed,
               rw.err_tuples, rw.ok ? "" : " DISAGREE");
        fflush(stdout);
        all_ok &= rw.ok;
    }
    return all_ok ? 0 : 1;
}
