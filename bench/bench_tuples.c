/* bench_tuples.c - libtape's embedded-tuple engine (tp_tuple, running the
 * element library's rigid chain through eom_model_run_lagrangian, then
 * tp_tuple_lagrange) against a careful plain-C engine of the same method
 * (ocea_plain.c) on the same Lagrangian: N = 2, 5, 10, 20 links of
 * different masses and lengths, one state. Both give L, dL/dq, M and h,
 * checked against each other to 1e-13 relative before any time is
 * reported. The two are timed in alternation, R rounds of calibrated
 * batches; the table gives the median time of each and the median of the
 * per-round ratios.
 *
 * usage: bench-tuples [--quick] [--reps R] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "eom/chain.h"
#include "ocea_plain.h"

typedef struct route {
    int N;
    double *x, *L2, *M, *g, *h; /* results of the route timed last */
    eom_model *md;
    tp_rec *tu;
    ocea_plain *op;
} route;

static void run_tuple(void *p)
{
    route *r = p;
    eom_model_run_lagrangian(r->md, r->tu, r->x);
    tp_tuple_lagrange(r->tu, 0, r->L2, r->g, r->M, r->h);
}

static void run_plain(void *p)
{
    route *r = p;
    ocea_plain_lagrange(r->op, r->x, r->L2, r->g, r->M, r->h);
}

/* max |a - b| over max |a| (1 if a is all zero) */
static double rel_diff(const double *a, const double *b, int n)
{
    double d = 0.0, s = 0.0;
    int i;
    for (i = 0; i < n; i++) {
        d = fmax(d, fabs(a[i] - b[i]));
        s = fmax(s, fabs(a[i]));
    }
    return d / (s > 0.0 ? s : 1.0);
}

/* One N: agreement, then times. Returns 0, or 1 if the routes disagree. */
static int one(int N, int reps, double min_batch)
{
    route r;
    eom_chain_spec sp = {0};
    double *m = malloc((size_t)N * sizeof(double));
    double *Ls = malloc((size_t)N * sizeof(double));
    double *res[2][4], t[2], *tt[2], ratio[64], d = 0.0;
    long batch[2];
    int i, k, rc = 0;
    memset(&r, 0, sizeof r);
    r.N = N;
    r.x = malloc(2 * (size_t)N * sizeof(double));
    for (i = 0; i < N; i++) {
        m[i] = 1.0 + 0.1 * i;
        Ls[i] = 1.0 - 0.03 * i;
        r.x[i] = 0.3 + 0.7 * sin(1.3 * i);
        r.x[N + i] = 0.5 * cos(0.9 * i);
    }
    sp.links = N;
    sp.m = 1.0;
    sp.L = 1.0;
    sp.m_link = m;
    sp.L_link = Ls;
    sp.g = 9.81;
    if (eom_model_new(&r.md) != EOM_OK || eom_chain_add(r.md, &sp) < 0 ||
        tp_tuple_new(&r.tu, 2 * N, NULL) != 0 ||
        !(r.op = ocea_plain_new(N, m, Ls, sp.g))) {
        fprintf(stderr, "bench-tuples: N = %d: setup failed\n", N);
        exit(1);
    }
    for (k = 0; k < 2; k++) {
        res[k][0] = calloc(1, sizeof(double));
        res[k][1] = calloc((size_t)N, sizeof(double));
        res[k][2] = calloc((size_t)N * (size_t)N, sizeof(double));
        res[k][3] = calloc((size_t)N, sizeof(double));
        r.L2 = res[k][0];
        r.g = res[k][1];
        r.M = res[k][2];
        r.h = res[k][3];
        (k ? run_plain : run_tuple)(&r);
    }
    d = fmax(fmax(rel_diff(res[0][0], res[1][0], 1),
                  rel_diff(res[0][1], res[1][1], N)),
             fmax(rel_diff(res[0][2], res[1][2], N * N),
                  rel_diff(res[0][3], res[1][3], N)));
    if (!(d <= 1e-13)) {
        printf("| %d | routes disagree: %.3g | | | |\n", N, d);
        rc = 1;
    } else {
        batch[0] = bench_calibrate(run_tuple, &r, min_batch);
        batch[1] = bench_calibrate(run_plain, &r, min_batch);
        tt[0] = malloc((size_t)reps * sizeof(double));
        tt[1] = malloc((size_t)reps * sizeof(double));
        for (i = 0; i < reps && i < 64; i++) {
            /* alternate which goes first */
            const int first = i % 2;
            for (k = 0; k < 2; k++) {
                const int w = (first + k) % 2;
                tt[w][i] = bench_time(w ? run_plain : run_tuple, &r,
                                      batch[w]);
            }
            ratio[i] = tt[0][i] / tt[1][i];
        }
        t[0] = bench_median(tt[0], i);
        t[1] = bench_median(tt[1], i);
        printf("| %d | %.3g | %.3g | %.2f | %.1e |\n", N, 1e6 * t[0],
               1e6 * t[1], bench_median(ratio, i), d);
        free(tt[0]);
        free(tt[1]);
    }
    for (k = 0; k < 2; k++)
        for (i = 0; i < 4; i++)
            free(res[k][i]);
    ocea_plain_free(r.op);
    tp_rec_free(&r.tu);
    eom_model_free(&r.md);
    free(r.x);
    free(m);
    free(Ls);
    return rc;
}

int main(int argc, char **argv)
{
    static const int Ns[] = {2, 5, 10, 20};
    int reps = 15, quick = 0, i, bad = 0;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) {
            quick = 1;
            reps = 3;
        } else if (!strcmp(argv[i], "--reps") && i + 1 < argc) {
            reps = atoi(argv[++i]);
        } else {
            fprintf(stderr, "usage: bench-tuples [--quick] [--reps R]\n");
            return 2;
        }
    }
    if (reps < 1 || reps > 64)
        reps = 15;
    printf("| N | tp_tuple (us) | plain engine (us) | tp_tuple / plain | "
           "agreement |\n|---|---|---|---|---|\n");
    for (i = 0; i < 4; i++)
        bad |= one(Ns[i], reps, quick ? 0.002 : 0.05);
    return bad;
}
