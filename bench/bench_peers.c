/* bench_peers.c - libeom's right-hand side beside the peers a user might
 * pick instead, on the same rigid chain (eom/chain.h: N links of unequal
 * masses and lengths, gravity), at N = 2, 5, 10, 20, 50:
 *
 *   MuJoCo  mj_forward on the chain built as an MJCF model
 *           (bench/mujoco/mujoco_chain.c; option mujoco, Debian
 *           libmujoco-dev); its relative hinge accelerations converted to
 *           the chain's absolute ones.
 *
 * Each peer's accelerations are checked against eom_rhs's before any
 * time is reported, by the backward error of the peer's accelerations in
 * libeom's equations: |M (qdd_peer - qdd)| / (|M| |qdd|), max norms.
 * (The forward difference |qdd_peer - qdd| / |qdd| grows with the mass
 * matrix's condition number, 1e-15 at N = 2 to 1e-9 at N = 50, for any
 * two correct codes.) A peer above 1e-13 gets no ratio. The routes are timed in alternation, R rounds of calibrated
 * batches; the table gives medians. A peer that was not built is named
 * with the option that would build it.
 *
 * usage: bench-peers [--quick] [--reps R] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "eom/chain.h"
#ifdef HAVE_MUJOCO
#include "mujoco_chain.h"
#endif

#ifdef HAVE_MUJOCO
typedef struct ctx {
    int N;
    double *x, *xd;
    eom_system *s;
    mujoco_chain *mj;
} ctx;

static void run_tape(void *p)
{
    ctx *c = p;
    eom_rhs(c->s, 0.0, c->x, c->xd);
}

static void run_mujoco(void *p)
{
    ctx *c = p;
    mujoco_chain_set(c->mj, c->x);
    mujoco_chain_forward(c->mj);
}

static int one(int N, int reps, double min_batch)
{
    ctx c;
    eom_model *md = NULL;
    eom_chain_spec sp = {0};
    double *m = malloc((size_t)N * sizeof(double));
    double *L = malloc((size_t)N * sizeof(double));
    char err[512];
    int i, rc = 0;
    memset(&c, 0, sizeof c);
    c.N = N;
    c.x = malloc(2 * (size_t)N * sizeof(double));
    c.xd = malloc(2 * (size_t)N * sizeof(double));
    for (i = 0; i < N; i++) {
        m[i] = 1.0 + 0.1 * i;
        L[i] = 1.0 - 0.03 * i;
        c.x[i] = 0.3 + 0.7 * sin(1.3 * i);
        c.x[N + i] = 0.5 * cos(0.9 * i);
    }
    sp.links = N;
    sp.m = 1.0;
    sp.L = 1.0;
    sp.m_link = m;
    sp.L_link = L;
    sp.g = 9.81;
    if (eom_model_new(&md) != EOM_OK || eom_chain_add(md, &sp) < 0 ||
        eom_system_new(&c.s, md, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "bench-peers: N = %d: %s\n", N, err);
        exit(1);
    }
    eom_model_free(&md);
    run_tape(&c);
    c.mj = mujoco_chain_new(N, m, L, sp.g, err, (int)sizeof err);
    if (!c.mj) {
        printf("| %d | MuJoCo could not load the chain: %s | | | |\n", N,
               err);
        rc = 1;
    } else {
        double *qdd = malloc((size_t)N * sizeof(double));
        double *M = malloc((size_t)N * (size_t)N * sizeof(double));
        double d = 0.0, Mmax = 0.0, qmax = 0.0;
        int k;
        run_mujoco(&c);
        mujoco_chain_qdd(c.mj, qdd);
        run_tape(&c);
        eom_mass_matrix(c.s, c.x, M);
        for (i = 0; i < N; i++) {
            double r = 0.0;
            for (k = 0; k < N; k++) {
                r += M[i * N + k] * (qdd[k] - c.xd[N + k]);
                Mmax = fmax(Mmax, fabs(M[i * N + k]));
            }
            d = fmax(d, fabs(r));
            qmax = fmax(qmax, fabs(c.xd[N + i]));
        }
        d /= Mmax * qmax > 0.0 ? Mmax * qmax : 1.0;
        free(qdd);
        free(M);
        if (!(d <= 1e-13)) {
            printf("| %d | MuJoCo disagrees with eom_rhs by %.3g | | | |\n",
                   N, d);
            rc = 1;
        } else {
            const long b0 = bench_calibrate(run_tape, &c, min_batch);
            const long b1 = bench_calibrate(run_mujoco, &c, min_batch);
            double t0[64], t1[64], r[64];
            for (i = 0; i < reps && i < 64; i++) {
                if (i % 2) {
                    t1[i] = bench_time(run_mujoco, &c, b1);
                    t0[i] = bench_time(run_tape, &c, b0);
                } else {
                    t0[i] = bench_time(run_tape, &c, b0);
                    t1[i] = bench_time(run_mujoco, &c, b1);
                }
                r[i] = t0[i] / t1[i];
            }
            printf("| %d | %.3g | %.3g | %.2f | %.1e |\n", N,
                   1e6 * bench_median(t0, i), 1e6 * bench_median(t1, i),
                   bench_median(r, i), d);
        }
        mujoco_chain_free(c.mj);
    }
    eom_system_free(&c.s);
    free(c.x);
    free(c.xd);
    free(m);
    free(L);
    return rc;
}

#endif /* HAVE_MUJOCO */

int main(int argc, char **argv)
{
    int reps = 15, quick = 0, i;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) {
            quick = 1;
            reps = 3;
        } else if (!strcmp(argv[i], "--reps") && i + 1 < argc) {
            reps = atoi(argv[++i]);
        } else {
            fprintf(stderr, "usage: bench-peers [--quick] [--reps R]\n");
            return 2;
        }
    }
    if (reps < 1 || reps > 64)
        reps = 15;
#ifndef HAVE_MUJOCO
    printf("mujoco: skipped (libmujoco-dev not found; meson setup "
           "-Dmujoco=enabled to require it)\n");
    (void)quick;
    return 0;
#else
    static const int Ns[] = {2, 5, 10, 20, 50};
    int bad = 0;
    printf("| N | eom_rhs (us) | MuJoCo mj_forward (us) | eom_rhs / "
           "mj_forward | agreement |\n|---|---|---|---|---|\n");
    for (i = 0; i < 5; i++)
        bad |= one(Ns[i], reps, quick ? 0.002 : 0.05);
    return bad;
#endif
}
