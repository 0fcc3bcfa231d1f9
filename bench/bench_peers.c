/* bench_peers.c - libeom's right-hand side beside the peers a user might
 * pick instead, on the same rigid chain (eom/chain.h: N links of unequal
 * masses and lengths, gravity), at N = 2, 5, 10, 20, 50:
 *
 *   MuJoCo  mj_forward on the chain built as an MJCF model
 *           (bench/mujoco/mujoco_chain.c; option mujoco, Debian
 *           libmujoco-dev); its relative hinge accelerations converted to
 *           the chain's absolute ones.
 *   SymPy   C generated at build time by sympy.physics.mechanics'
 *           LagrangesMethod with common subexpressions eliminated
 *           (bench/sympy/chain_sympy.py; option sympy, Debian
 *           python3-sympy; the chains of option sympy_links), M qdd = f
 *           then solved by a plain inline Cholesky, as a user would.
 *
 * Each peer's accelerations are checked against eom_rhs's before any
 * time is reported, by the backward error of the peer's accelerations in
 * libeom's equations: |M (qdd_peer - qdd)| / (|M| |qdd|), max norms.
 * (The forward difference |qdd_peer - qdd| / |qdd| grows with the mass
 * matrix's condition number, 1e-15 at N = 2 to 1e-9 at N = 50, for any
 * two correct codes.) A peer above 1e-13 gets no ratio. The routes are
 * timed in alternation, R rounds of calibrated batches; the tables give
 * medians. A second table sets what building each route took beside each
 * other: libeom's recording (eom_system_new), SymPy's derivation and the
 * C compiler's work on its output.
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
#ifdef HAVE_SYMPY
#include "sympy_chains.h"
#endif

#define NPEERS 2
static const char *const peer_name[NPEERS] = {"MuJoCo", "SymPy"};

typedef struct ctx {
    int N;
    double *x, *xd, *m, *L, g;
    double *M, *f, *qdd; /* a peer's M, f and accelerations */
    eom_system *s;
#ifdef HAVE_MUJOCO
    mujoco_chain *mj;
#endif
#ifdef HAVE_SYMPY
    sympy_chain_fn sym;
#endif
} ctx;

static void run_tape(void *p)
{
    ctx *c = p;
    eom_rhs(c->s, 0.0, c->x, c->xd);
}

#ifdef HAVE_MUJOCO
static void run_mujoco(void *p)
{
    ctx *c = p;
    mujoco_chain_set(c->mj, c->x);
    mujoco_chain_forward(c->mj);
}

static void qdd_mujoco(ctx *c)
{
    mujoco_chain_qdd(c->mj, c->qdd);
}
#endif

#ifdef HAVE_SYMPY
/* M qdd = f by Cholesky in plain loops (M is overwritten) */
static void run_sympy(void *p)
{
    ctx *c = p;
    const int n = c->N;
    double *A = c->M, *b = c->qdd;
    int i, j, k;
    c->sym(c->m, c->L, c->g, c->x, A, c->f);
    for (j = 0; j < n; j++) {
        double d = A[j * n + j];
        for (k = 0; k < j; k++)
            d -= A[j * n + k] * A[j * n + k];
        d = sqrt(d);
        A[j * n + j] = d;
        for (i = j + 1; i < n; i++) {
            double s = A[i * n + j];
            for (k = 0; k < j; k++)
                s -= A[i * n + k] * A[j * n + k];
            A[i * n + j] = s / d;
        }
    }
    for (i = 0; i < n; i++) {
        double s = c->f[i];
        for (k = 0; k < i; k++)
            s -= A[i * n + k] * b[k];
        b[i] = s / A[i * n + i];
    }
    for (i = n; i-- > 0;) {
        double s = b[i];
        for (k = i + 1; k < n; k++)
            s -= A[k * n + i] * b[k];
        b[i] = s / A[i * n + i];
    }
}

static void qdd_sympy(ctx *c)
{
    (void)c; /* run_sympy left them in c->qdd */
}
#endif

/* |M (qdd_peer - qdd)| / (|M| |qdd|) with libeom's M at the state */
static double backward_error(ctx *c)
{
    const int N = c->N;
    double *M = malloc((size_t)N * (size_t)N * sizeof(double));
    double d = 0.0, Mmax = 0.0, qmax = 0.0;
    int i, k;
    if (!M)
        return INFINITY;
    run_tape(c);
    eom_mass_matrix(c->s, c->x, M);
    for (i = 0; i < N; i++) {
        double r = 0.0;
        for (k = 0; k < N; k++) {
            r += M[i * N + k] * (c->qdd[k] - c->xd[N + k]);
            Mmax = fmax(Mmax, fabs(M[i * N + k]));
        }
        d = fmax(d, fabs(r));
        qmax = fmax(qmax, fabs(c->xd[N + i]));
    }
    free(M);
    return d / (Mmax * qmax > 0.0 ? Mmax * qmax : 1.0);
}

/* a peer beside eom_rhs: the time of each and their ratio, or "-" */
static void peer_cell(ctx *c, void (*run)(void *), void (*qdd)(ctx *),
                      int reps, double min_batch, int *bad)
{
    double e, t0[64], t1[64], r[64];
    long b0, b1;
    int i;
    if (!run) {
        printf(" - | - | - |");
        return;
    }
    run(c);
    qdd(c);
    e = backward_error(c);
    if (!(e <= 1e-13)) {
        printf(" disagrees: %.2g | - | - |", e);
        *bad = 1;
        return;
    }
    b0 = bench_calibrate(run_tape, c, min_batch);
    b1 = bench_calibrate(run, c, min_batch);
    for (i = 0; i < reps && i < 64; i++) {
        if (i % 2) {
            t1[i] = bench_time(run, c, b1);
            t0[i] = bench_time(run_tape, c, b0);
        } else {
            t0[i] = bench_time(run_tape, c, b0);
            t1[i] = bench_time(run, c, b1);
        }
        r[i] = t0[i] / t1[i];
    }
    printf(" %.3g | %.2f | %.1e |", 1e6 * bench_median(t1, i),
           bench_median(r, i), e);
}

static int one(int N, int reps, double min_batch, double *record_ms)
{
    ctx c;
    eom_model *md = NULL;
    eom_chain_spec sp = {0};
    char err[512];
    double t;
    int i, bad = 0;
    memset(&c, 0, sizeof c);
    c.N = N;
    c.g = 9.81;
    c.x = malloc(2 * (size_t)N * sizeof(double));
    c.xd = malloc(2 * (size_t)N * sizeof(double));
    c.m = malloc((size_t)N * sizeof(double));
    c.L = malloc((size_t)N * sizeof(double));
    c.M = malloc((size_t)N * (size_t)N * sizeof(double));
    c.f = malloc((size_t)N * sizeof(double));
    c.qdd = malloc((size_t)N * sizeof(double));
    if (!c.x || !c.xd || !c.m || !c.L || !c.M || !c.f || !c.qdd) {
        fprintf(stderr, "bench-peers: out of memory\n");
        exit(1);
    }
    for (i = 0; i < N; i++) {
        c.m[i] = 1.0 + 0.1 * i;
        c.L[i] = 1.0 - 0.03 * i;
        c.x[i] = 0.3 + 0.7 * sin(1.3 * i);
        c.x[N + i] = 0.5 * cos(0.9 * i);
    }
    sp.links = N;
    sp.m = 1.0;
    sp.L = 1.0;
    sp.m_link = c.m;
    sp.L_link = c.L;
    sp.g = c.g;
    t = bench_now();
    if (eom_model_new(&md) != EOM_OK || eom_chain_add(md, &sp) < 0 ||
        eom_system_new(&c.s, md, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "bench-peers: N = %d: %s\n", N, err);
        exit(1);
    }
    *record_ms = 1e3 * (bench_now() - t);
    eom_model_free(&md);
    run_tape(&c);
    printf("| %d | %.3g |", N, 1e6 * bench_time(run_tape, &c,
                                                 bench_calibrate(run_tape,
                                                                 &c,
                                                                 min_batch)));
#ifdef HAVE_MUJOCO
    c.mj = mujoco_chain_new(N, c.m, c.L, c.g, err, (int)sizeof err);
    if (!c.mj) {
        printf(" cannot load: %s | - | - |", err);
        bad = 1;
    } else {
        peer_cell(&c, run_mujoco, qdd_mujoco, reps, min_batch, &bad);
        mujoco_chain_free(c.mj);
    }
#else
    peer_cell(&c, NULL, NULL, reps, min_batch, &bad);
#endif
#ifdef HAVE_SYMPY
    for (i = 0; sympy_chains[i].N && sympy_chains[i].N != N; i++)
        ;
    c.sym = sympy_chains[i].fn;
    peer_cell(&c, c.sym ? run_sympy : NULL, qdd_sympy, reps, min_batch,
              &bad);
#else
    peer_cell(&c, NULL, NULL, reps, min_batch, &bad);
#endif
    printf("\n");
    eom_system_free(&c.s);
    free(c.x);
    free(c.xd);
    free(c.m);
    free(c.L);
    free(c.M);
    free(c.f);
    free(c.qdd);
    return bad;
}

int main(int argc, char **argv)
{
    static const int Ns[] = {2, 5, 10, 20, 50};
    double record_ms[5];
    int reps = 15, quick = 0, i, k, bad = 0;
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
#endif
#ifndef HAVE_SYMPY
    printf("sympy: skipped (python3 cannot import sympy; meson setup "
           "-Dsympy=enabled to require it)\n");
#endif
    printf("\n| N | eom_rhs (us)");
    for (k = 0; k < NPEERS; k++)
        printf(" | %s (us) | eom_rhs / %s | backward error", peer_name[k],
               peer_name[k]);
    printf(" |\n|---|---|");
    for (k = 0; k < NPEERS; k++)
        printf("---|---|---|");
    printf("\n");
    for (i = 0; i < 5; i++)
        bad |= one(Ns[i], reps, quick ? 0.002 : 0.05, &record_ms[i]);
    printf("\n| N | libeom: eom_system_new (ms) | SymPy: derivation (s) | "
           "SymPy: cc -O2 (s) |\n|---|---|---|---|\n");
    for (i = 0; i < 5; i++) {
        printf("| %d | %.3g |", Ns[i], record_ms[i]);
#ifdef HAVE_SYMPY
        for (k = 0; sympy_chains[k].N && sympy_chains[k].N != Ns[i]; k++)
            ;
        if (sympy_chains[k].N)
            printf(" %.3g | %.3g |\n", sympy_chains[k].derive_seconds,
                   sympy_chains[k].compile_seconds);
        else
            printf(" not derived (option sympy_links) | - |\n");
#else
        printf(" - | - |\n");
#endif
    }
    return bad;
}
