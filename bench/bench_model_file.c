/* bench_model_file.c - what a model file costs against the same model in
 * C: the time to read and record a flexible chain from models/open-chain.eom
 * (read and check the file, build the model for the settings, which
 * records every part once to check it, then eom_system_new, which records
 * the tapes the run uses), and the time of one right-hand side of that
 * system against the same chain from the C element library (eom/chain.h).
 * The two right-hand sides are compared for equality at the same state
 * before anything is timed. Medians of repeated batches, measured in one
 * run.
 *
 * usage: bench-model-file [--quick] MODELS_DIR [LINKS MODES] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "eom/chain.h"
#include "eom/model_file.h"

static const double pi = 3.14159265358979323846;

typedef struct load_ctx {
    const char *path;
    int links, modes;
    double t_read, t_build, t_system; /* of the last call */
    int failed;
} load_ctx;

static void load_once(void *p)
{
    load_ctx *c = p;
    char err[2048];
    eom_file *f = NULL;
    eom_model *m = NULL;
    eom_system *s = NULL;
    double t0 = bench_now(), t1, t2, t3;
    if (eom_file_read(&f, c->path, err, sizeof err) != EOM_OK ||
        eom_file_set_setting(f, "links", c->links, err, sizeof err) ||
        eom_file_set_setting(f, "modes", c->modes, err, sizeof err)) {
        fprintf(stderr, "bench-model-file: %s\n", err);
        c->failed = 1;
    }
    t1 = bench_now();
    if (!c->failed && eom_file_build(f, &m, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "bench-model-file: %s\n", err);
        c->failed = 1;
    }
    t2 = bench_now();
    if (!c->failed && eom_system_new(&s, m, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "bench-model-file: %s\n", err);
        c->failed = 1;
    }
    t3 = bench_now();
    c->t_read = t1 - t0;
    c->t_build = t2 - t1;
    c->t_system = t3 - t2;
    eom_system_free(&s);
    eom_model_free(&m);
    eom_file_free(&f);
}

typedef struct rhs_ctx {
    eom_system *s;
    double *x, *xd;
} rhs_ctx;

static void one_rhs(void *p)
{
    rhs_ctx *c = p;
    c->x[0] += 1e-12;
    eom_rhs(c->s, 0.0, c->x, c->xd);
}

static eom_system *c_chain(int N, int K)
{
    double *th = calloc((size_t)N, sizeof *th);
    double *thd = calloc((size_t)N, sizeof *thd);
    double *q0 = calloc((size_t)(N * K + 1), sizeof *q0);
    unsigned char *damped = calloc((size_t)N + 1, 1);
    eom_chain_spec sp;
    eom_model *m = NULL;
    eom_system *s = NULL;
    char err[512];
    int j;
    memset(&sp, 0, sizeof sp);
    for (j = 0; j < N; j++)
        th[j] = (j % 2 ? -1.0 : 1.0) * pi / 6;
    thd[N - 1] = 0.5;
    if (K > 0)
        q0[(N - 1) * K] = 0.01;
    for (j = 1; j < N; j++)
        damped[j] = 1;
    sp.links = N;
    sp.modes_all = K;
    sp.m = 1.0;
    sp.L = 10.0;
    sp.EI = 4e3;
    sp.theta0 = th;
    sp.theta0_dot = thd;
    sp.q0 = q0;
    sp.damped = damped;
    if (eom_model_new(&m) != EOM_OK || eom_chain_add(m, &sp) < 0 ||
        eom_system_new(&s, m, err, sizeof err) != EOM_OK)
        s = NULL;
    eom_model_free(&m);
    free(th);
    free(thd);
    free(q0);
    free(damped);
    return s;
}

static eom_system *file_chain(const char *path, int N, int K)
{
    char err[2048];
    eom_file *f = NULL;
    eom_model *m = NULL;
    eom_system *s = NULL;
    if (eom_file_read(&f, path, err, sizeof err) == EOM_OK &&
        eom_file_set_setting(f, "links", N, err, sizeof err) == EOM_OK &&
        eom_file_set_setting(f, "modes", K, err, sizeof err) == EOM_OK &&
        eom_file_build(f, &m, err, sizeof err) == EOM_OK)
        eom_system_new(&s, m, err, sizeof err);
    if (!s)
        fprintf(stderr, "bench-model-file: %s\n", err);
    eom_model_free(&m);
    eom_file_free(&f);
    return s;
}

int main(int argc, char **argv)
{
    int quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
    const char *dir = argc > 1 + quick ? argv[1 + quick] : "models";
    int links = argc > 3 + quick ? atoi(argv[2 + quick]) : 50;
    int modes = argc > 3 + quick ? atoi(argv[3 + quick]) : 3;
    const int reps = quick ? 3 : 21;
    char path[2048];
    load_ctx lc;
    double tr[64], tb[64], ts[64], tt[64], rc_t[64], rf_t[64], diff = 0.0;
    eom_system *sc, *sf;
    rhs_ctx c1, c2;
    long batch;
    int k, n;

    snprintf(path, sizeof path, "%s/open-chain.eom", dir);
    memset(&lc, 0, sizeof lc);
    lc.path = path;
    lc.links = links;
    lc.modes = modes;
    load_once(&lc); /* warm up */
    for (k = 0; k < reps && !lc.failed; k++) {
        double t0 = bench_now();
        load_once(&lc);
        tt[k] = bench_now() - t0;
        tr[k] = lc.t_read;
        tb[k] = lc.t_build;
        ts[k] = lc.t_system;
    }
    if (lc.failed)
        return 1;
    printf("open chain from %s, %d links, %d modes:\n", path, links, modes);
    printf("  read and record: %.3f ms (read %.3f, build and check %.3f, "
           "eom_system_new %.3f; target < 5 ms)\n",
           1e3 * bench_median(tt, reps), 1e3 * bench_median(tr, reps),
           1e3 * bench_median(tb, reps), 1e3 * bench_median(ts, reps));

    /* the same recording for the C element, for scale */
    for (k = 0; k < reps; k++) {
        double t0 = bench_now();
        sc = c_chain(links, modes);
        tt[k] = bench_now() - t0;
        eom_system_free(&sc);
    }
    printf("  the same chain from the C element: eom_model_new, "
           "eom_chain_add and eom_system_new %.3f ms\n",
           1e3 * bench_median(tt, reps));
    sc = c_chain(links, modes);
    sf = file_chain(path, links, modes);
    if (!sc || !sf)
        return 1;
    n = eom_system_ncoords(sc);
    c1.s = sc;
    c2.s = sf;
    c1.x = calloc(2 * (size_t)n, sizeof(double));
    c2.x = calloc(2 * (size_t)n, sizeof(double));
    c1.xd = calloc(2 * (size_t)n, sizeof(double));
    c2.xd = calloc(2 * (size_t)n, sizeof(double));
    eom_initial_state(sc, c1.x);
    eom_initial_state(sf, c2.x);
    eom_rhs(sc, 0.0, c1.x, c1.xd);
    eom_rhs(sf, 0.0, c2.x, c2.xd);
    for (k = 0; k < 2 * n; k++)
        diff = fmax(diff, fabs(c1.xd[k] - c2.xd[k]) /
                              fmax(1.0, fabs(c1.xd[k])));
    batch = bench_calibrate(one_rhs, &c1, quick ? 0.01 : 0.2);
    /* alternate the two so that both see the same machine */
    for (k = 0; k < reps; k++) {
        rc_t[k] = bench_time(one_rhs, &c1, batch);
        rf_t[k] = bench_time(one_rhs, &c2, batch);
    }
    printf("  right-hand side: C element %.1f us, file %.1f us, file / C = "
           "%.3f (target within 10%%); largest relative difference of the "
           "two at the start %.1e\n",
           1e6 * bench_median(rc_t, reps), 1e6 * bench_median(rf_t, reps),
           bench_median(rf_t, reps) / bench_median(rc_t, reps), diff);
    free(c1.x);
    free(c2.x);
    free(c1.xd);
    free(c2.xd);
    eom_system_free(&sc);
    eom_system_free(&sf);
    return diff < 1e-12 ? 0 : 1;
}
