/* bench_peers.c - libeom's right-hand side beside the peers a user might
 * pick instead, on the same rigid chain (eom/chain.h: N links of unequal
 * masses and lengths, gravity, absolute angles), at N = 2, 5, 10, 20,
 * 50 (or those of --links):
 *
 *   MuJoCo  mj_forward on the chain built as a URDF model
 *           (bench/mujoco/mujoco_chain.c; option mujoco, Debian
 *           libmujoco-dev); its relative hinge accelerations converted to
 *           the chain's absolute ones. Its time includes setting qpos and
 *           qvel from the absolute state, as a caller of eom_rhs would.
 *   SymPy   C generated at build time by sympy.physics.mechanics'
 *           LagrangesMethod with common subexpressions eliminated
 *           (bench/sympy/chain_sympy.py; option sympy, Debian
 *           python3-sympy; the chains of option sympy_links), M qdd = f
 *           then solved by a plain inline Cholesky, as a user would.
 *
 * Each peer's accelerations are checked against eom_rhs's before any
 * time is reported. The gate is the backward error of the peer's
 * accelerations in libeom's equations, |M (qdd_peer - qdd)| / (|M| |qdd|)
 * in max norms: a peer above GATE(N) gets no ratio. The forward difference
 * |qdd_peer - qdd| / |qdd| is printed beside it, with the mass matrix's
 * condition number (eom_condition) and the forward difference of the
 * hand-coded equations (bench/chain_plain.c, the same coordinates and
 * formulas) as yardsticks: it may reach cond(M) times the rounding unit
 * for a code that works in other coordinates, and does for MuJoCo. For
 * MuJoCo the backward error is also taken the other way round, of
 * eom_rhs's accelerations in MuJoCo's own equations (hinge angles, its
 * mass matrix): each code's answer is then judged where the other code
 * rounds.
 *
 * The routes are timed in alternation with eom_rhs, R rounds of
 * calibrated batches, in processor time of the bench's thread; the tables give medians (eom_rhs's over every
 * round). A last table sets what building each route took beside each
 * other: libeom's recording (eom_system_new), SymPy's derivation and the
 * C compiler's work on its output.
 *
 * --links N1,N2,... measures chains of these links instead (the long
 * series: 2,10,50,100,200,400).
 *
 * usage: bench-peers [--quick] [--reps R] [--links N1,N2,...] */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "chain_plain.h"
#include "eom/chain.h"
#ifdef HAVE_MUJOCO
#include "mujoco_chain.h"
#endif
#ifdef HAVE_SYMPY
#include "sympy_chains.h"
#endif

#define NPEERS 2
#define MAX_REPS 64
/* The largest backward error a timed peer may have at N links: 1e-13,
 * and 1e-15 N^2 above 10 links, where MuJoCo's, taken in absolute angles
 * that are sums of its relative ones, grows as N^2 (7e-14 at 50 links,
 * 3e-13 at 100, 8e-12 at 200, 7e-11 at 400; eom_rhs's in MuJoCo's
 * equations stays below 1e-15), as bench-rhs's gate does */
#define GATE(N) fmax(1e-13, 1e-15 * (double)(N) * (double)(N))
enum { P_MUJOCO, P_SYMPY };
static const char *const peer_name[NPEERS] = {"MuJoCo", "SymPy"};

typedef struct ctx {
    int N;
    double *x, *xd, *m, *L, g;
    double *M, *f, *qdd; /* a peer's M, f and accelerations */
    eom_system *s;
    eom_system *cs;      /* the same model on compiled tapes, or NULL */
#ifdef HAVE_MUJOCO
    mujoco_chain *mj;
#endif
#ifdef HAVE_SYMPY
    sympy_chain_fn sym;
#endif
} ctx;

/* One N: what the tables print, filled by measure(). */
typedef struct row {
    double record_ms;      /* eom_system_new */
    double rhs_us;         /* eom_rhs, median over every round */
    double cond;           /* 1-norm condition estimate of M */
    double hand_fwd;       /* hand-coded equations' forward difference */
    int have[NPEERS];      /* 1: built for this N */
    double fwd[NPEERS];    /* forward difference from eom_rhs */
    double bwd[NPEERS];    /* backward error in libeom's equations */
    double mj_bwd;         /* eom_rhs's backward error in MuJoCo's */
    double us[NPEERS];     /* median time (NAN: not timed) */
    double ratio[NPEERS];  /* median of eom_rhs / peer per round */
    double crhs_us;        /* compiled eom_rhs (NAN: none) */
    double cratio[NPEERS]; /* median of compiled eom_rhs / peer */
    double cdiff;          /* compiled qdd against interpreted, relative */
    double compile_s;      /* eom_system_set_compiled, cold cache */
} row;

static void run_tape(void *p)
{
    ctx *c = p;
    eom_rhs(c->s, 0.0, c->x, c->xd);
}

static void run_ctape(void *p)
{
    ctx *c = p;
    eom_rhs(c->cs, 0.0, c->x, c->xd);
}

#ifdef HAVE_MUJOCO
static void run_mujoco(void *p)
{
    ctx *c = p;
    mujoco_chain_set(c->mj, c->x);
    mujoco_chain_forward(c->mj);
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
#endif

/* Peer k's right-hand side for this N, or NULL when it was not built. */
static void (*peer_run(ctx *c, int k))(void *)
{
    (void)c;
#ifdef HAVE_MUJOCO
    if (k == P_MUJOCO && c->mj)
        return run_mujoco;
#endif
#ifdef HAVE_SYMPY
    if (k == P_SYMPY && c->sym)
        return run_sympy;
#endif
    (void)k;
    return NULL;
}

/* Peer k's accelerations (absolute angles) into c->qdd, after its run. */
static void peer_qdd(ctx *c, int k)
{
#ifdef HAVE_MUJOCO
    if (k == P_MUJOCO)
        mujoco_chain_qdd(c->mj, c->qdd);
#endif
    (void)c; /* run_sympy left them in c->qdd */
    (void)k;
}

/* |q - qdd| / |qdd| in max norms, qdd eom_rhs's in c->xd + N */
static double forward_diff(const ctx *c, const double *q)
{
    double d = 0.0, qmax = 0.0;
    int i;
    for (i = 0; i < c->N; i++) {
        d = fmax(d, fabs(q[i] - c->xd[c->N + i]));
        qmax = fmax(qmax, fabs(c->xd[c->N + i]));
    }
    return d / (qmax > 0.0 ? qmax : 1.0);
}

/* |M (q - qdd)| / (|M| |qdd|) with libeom's M and qdd at the state */
static double backward_error(const ctx *c, const double *M, const double *q)
{
    const int N = c->N;
    double d = 0.0, Mmax = 0.0, qmax = 0.0;
    int i, k;
    for (i = 0; i < N; i++) {
        double r = 0.0;
        for (k = 0; k < N; k++) {
            r += M[i * N + k] * (q[k] - c->xd[N + k]);
            Mmax = fmax(Mmax, fabs(M[i * N + k]));
        }
        d = fmax(d, fabs(r));
        qmax = fmax(qmax, fabs(c->xd[N + i]));
    }
    return d / (Mmax * qmax > 0.0 ? Mmax * qmax : 1.0);
}

/* The agreement columns of r: M's condition, the hand-coded equations'
 * forward difference, and each built peer's. 0, or -1 out of memory. */
static int compare(ctx *c, row *r)
{
    const int N = c->N;
    double *M = malloc((size_t)N * (size_t)N * sizeof(double));
    double *q = malloc((size_t)N * sizeof(double));
    double rcond_M = 0.0, rcond_S;
    chain_plain cp = {N, 0, c->m, c->L, NULL, c->g};
    chain_hand *h = NULL;
    int k, ok = M && q;
    if (ok) {
        run_tape(c);
        eom_mass_matrix(c->s, c->x, M);
        eom_condition(c->s, c->x, &rcond_M, &rcond_S);
        r->cond = rcond_M > 0.0 ? 1.0 / rcond_M : INFINITY;
        ok = chain_plain_hand_new(&h, &cp) == 0 &&
             chain_plain_hand_rhs(h, c->x, q) == 0;
        r->hand_fwd = ok ? forward_diff(c, q) : NAN;
        chain_plain_hand_free(&h);
    }
    for (k = 0; ok && k < NPEERS; k++) {
        void (*run)(void *) = peer_run(c, k);
        r->have[k] = run != NULL;
        r->fwd[k] = r->bwd[k] = NAN;
        if (!run)
            continue;
        run(c);
        peer_qdd(c, k);
        r->fwd[k] = forward_diff(c, c->qdd);
        r->bwd[k] = backward_error(c, M, c->qdd);
#ifdef HAVE_MUJOCO
        if (k == P_MUJOCO)
            r->mj_bwd = mujoco_chain_backward_error(c->mj, c->xd + N);
#endif
    }
    free(M);
    free(q);
    return ok ? 0 : -1;
}

/* The timing columns of r: each peer that passed the gate in alternation
 * with eom_rhs (the order flipped every round), reps rounds of batches
 * of at least min_batch seconds. */
static void time_routes(ctx *c, int reps, double min_batch, row *r)
{
    double tape[NPEERS * MAX_REPS], ctape[NPEERS * MAX_REPS], t0, t1, t2;
    double rt[MAX_REPS], ct[MAX_REPS], tp[MAX_REPS];
    long b0 = bench_calibrate_cpu(run_tape, c, min_batch), b1, b2;
    int k, i, ntape = 0;
    b2 = c->cs ? bench_calibrate_cpu(run_ctape, c, min_batch) : 0;
    for (k = 0; k < NPEERS; k++) {
        void (*run)(void *) = peer_run(c, k);
        r->us[k] = r->ratio[k] = r->cratio[k] = NAN;
        if (!run || !(r->bwd[k] <= GATE(c->N)))
            continue;
        b1 = bench_calibrate_cpu(run, c, min_batch);
        for (i = 0; i < reps; i++) {
            /* the three routes in a rotating order */
            t2 = NAN;
            if (i % 2) {
                t1 = bench_time_cpu(run, c, b1);
                if (c->cs)
                    t2 = bench_time_cpu(run_ctape, c, b2);
                t0 = bench_time_cpu(run_tape, c, b0);
            } else {
                t0 = bench_time_cpu(run_tape, c, b0);
                if (c->cs)
                    t2 = bench_time_cpu(run_ctape, c, b2);
                t1 = bench_time_cpu(run, c, b1);
            }
            tape[ntape] = t0;
            ctape[ntape++] = t2;
            tp[i] = t1;
            rt[i] = t0 / t1;
            ct[i] = t2 / t1;
        }
        r->us[k] = 1e6 * bench_median(tp, reps);
        r->ratio[k] = bench_median(rt, reps);
        r->cratio[k] = c->cs ? bench_median(ct, reps) : NAN;
    }
    if (!ntape) /* no peer to alternate with: eom_rhs alone */
        for (i = 0; i < reps; i++) {
            tape[ntape] = bench_time_cpu(run_tape, c, b0);
            ctape[ntape++] = c->cs ? bench_time_cpu(run_ctape, c, b2) : NAN;
        }
    r->rhs_us = 1e6 * bench_median(tape, ntape);
    r->crhs_us = c->cs ? 1e6 * bench_median(ctape, ntape) : NAN;
}

/* The same chain on compiled tapes (c->cs), its set-up time and its
 * difference from the interpreter's accelerations. */
static void compile_route(ctx *c, const eom_model *md, row *r)
{
    double *xd = malloc(2 * (size_t)c->N * sizeof(double)), t;
    char err[256];
    int i;
    r->crhs_us = NAN;
    r->cdiff = NAN;
    if (!xd || eom_system_new(&c->cs, md, err, sizeof err) != EOM_OK) {
        free(xd);
        return;
    }
    t = bench_now();
    if (eom_system_set_compiled(c->cs, 1, NULL) != EOM_OK) {
        printf("compiled tapes: not in use for N = %d: %s\n", c->N,
               eom_system_errmsg(c->cs));
        eom_system_free(&c->cs);
        free(xd);
        return;
    }
    r->compile_s = bench_now() - t;
    eom_rhs(c->s, 0.0, c->x, c->xd);
    eom_rhs(c->cs, 0.0, c->x, xd);
    r->cdiff = 0.0;
    for (i = c->N; i < 2 * c->N; i++)
        r->cdiff = fmax(r->cdiff, fabs(xd[i] - c->xd[i]) / fabs(c->xd[i]));
    free(xd);
}

/* Build every route for N links, compare and time them into r; 0, or 1
 * when a peer disagrees (it is then not timed). */
static int measure(int N, int reps, double min_batch, row *r)
{
    ctx c;
    eom_model *md = NULL;
    eom_chain_spec sp = {0};
    char err[512];
    double t;
    int i, k, bad = 0;
    memset(&c, 0, sizeof c);
    memset(r, 0, sizeof *r);
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
    r->record_ms = 1e3 * (bench_now() - t);
    compile_route(&c, md, r);
    eom_model_free(&md);
#ifdef HAVE_MUJOCO
    c.mj = mujoco_chain_new(N, c.m, c.L, c.g, err, (int)sizeof err);
    if (!c.mj) {
        fprintf(stderr, "bench-peers: MuJoCo cannot load the %d-link "
                "chain: %s\n", N, err);
        bad = 1;
    }
#endif
#ifdef HAVE_SYMPY
    for (i = 0; sympy_chains[i].N && sympy_chains[i].N != N; i++)
        ;
    c.sym = sympy_chains[i].fn;
#endif
    if (compare(&c, r) != 0) {
        fprintf(stderr, "bench-peers: N = %d: the comparison failed\n", N);
        exit(1);
    }
    for (k = 0; k < NPEERS; k++)
        if (r->have[k] && !(r->bwd[k] <= GATE(N)))
            bad = 1;
    time_routes(&c, reps, min_batch, r);
#ifdef HAVE_MUJOCO
    mujoco_chain_free(c.mj);
#endif
    eom_system_free(&c.s);
    eom_system_free(&c.cs);
    free(c.x);
    free(c.xd);
    free(c.m);
    free(c.L);
    free(c.M);
    free(c.f);
    free(c.qdd);
    return bad;
}

static void print_times(const int *Ns, const row *r, int n)
{
    int i, k;
    printf("| N | eom_rhs (us) | compiled (us)");
    for (k = 0; k < NPEERS; k++)
        printf(" | %s (us) | eom_rhs / %s | compiled / %s", peer_name[k],
               peer_name[k], peer_name[k]);
    printf(" |\n|---|---|---|");
    for (k = 0; k < NPEERS; k++)
        printf("---|---|---|");
    printf("\n");
    for (i = 0; i < n; i++) {
        printf("| %d | %.3g | %.3g |", Ns[i], r[i].rhs_us, r[i].crhs_us);
        for (k = 0; k < NPEERS; k++) {
            if (!r[i].have[k])
                printf(" - | - | - |");
            else if (!(r[i].bwd[k] <= GATE(Ns[i])))
                printf(" disagrees | - | - |");
            else
                printf(" %.3g | %.2f | %.2f |", r[i].us[k], r[i].ratio[k],
                       r[i].cratio[k]);
        }
        printf("\n");
    }
    printf("\nCompiled tapes (eom_system_set_compiled, cold cache; the "
           "accelerations' largest relative difference from the "
           "interpreter's):\n\n| N | compile (s) | difference |\n"
           "|---|---|---|\n");
    for (i = 0; i < n; i++)
        printf("| %d | %.3g | %.1e |\n", Ns[i], r[i].compile_s,
               r[i].cdiff);
}

static void print_agreement(const int *Ns, const row *r, int n)
{
    int i, k;
    printf("| N | cond(M) | hand-coded: forward");
    for (k = 0; k < NPEERS; k++) {
        printf(" | %s: forward | %s: backward", peer_name[k], peer_name[k]);
        if (k == P_MUJOCO)
            printf(" | eom_rhs: backward in MuJoCo's");
    }
    printf(" |\n|---|---|---|");
    for (k = 0; k < NPEERS; k++)
        printf(k == P_MUJOCO ? "---|---|---|" : "---|---|");
    printf("\n");
    for (i = 0; i < n; i++) {
        printf("| %d | %.2g | %.1e |", Ns[i], r[i].cond, r[i].hand_fwd);
        for (k = 0; k < NPEERS; k++) {
            if (r[i].have[k])
                printf(" %.1e | %.1e%s |", r[i].fwd[k], r[i].bwd[k],
                       r[i].bwd[k] <= GATE(Ns[i]) ? "" : " DISAGREES");
            else
                printf(" - | - |");
            if (k == P_MUJOCO && r[i].have[k])
                printf(" %.1e |", r[i].mj_bwd);
            else if (k == P_MUJOCO)
                printf(" - |");
        }
        printf("\n");
    }
}

static void print_build(const int *Ns, const row *r, int n)
{
    const char *v = "";
    int i;
#ifdef HAVE_SYMPY
    v = sympy_version;
#endif
    printf("| N | libeom: eom_system_new (ms) | SymPy %s: derivation (CPU s) | "
           "SymPy: cc -O2 (CPU s) |\n|---|---|---|---|\n", v);
    for (i = 0; i < n; i++) {
        printf("| %d | %.3g |", Ns[i], r[i].record_ms);
#ifdef HAVE_SYMPY
        {
            int k;
            for (k = 0; sympy_chains[k].N && sympy_chains[k].N != Ns[i];
                 k++)
                ;
            if (sympy_chains[k].N)
                printf(" %.3g | %.3g |\n", sympy_chains[k].derive_seconds,
                       sympy_chains[k].compile_seconds);
            else
                printf(" not derived (option sympy_links) | - |\n");
        }
#else
        printf(" - | - |\n");
#endif
    }
}

int main(int argc, char **argv)
{
    static const int Ns_default[] = {2, 5, 10, 20, 50};
    char dir[] = "/tmp/bench-peers-XXXXXX", cmd[128];
    int Ns[32], n = (int)(sizeof Ns_default / sizeof Ns_default[0]);
    row r[32];
    int reps = 15, quick = 0, i, bad = 0;
    memcpy(Ns, Ns_default, sizeof Ns_default);
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) {
            quick = 1;
            reps = 3;
        } else if (!strcmp(argv[i], "--reps") && i + 1 < argc) {
            reps = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--links") && i + 1 < argc &&
                   (n = bench_parse_links(argv[i + 1], Ns, 32)) >= 1) {
            i++;
        } else {
            fprintf(stderr, "usage: bench-peers [--quick] [--reps R] "
                    "[--links N1,N2,...]\n");
            return 2;
        }
    }
    if (reps < 1 || reps > MAX_REPS)
        reps = 15;
#if !defined HAVE_MUJOCO && defined MUJOCO_DISABLED
    printf("mujoco: skipped (option mujoco is disabled; meson setup "
           "-Dmujoco=enabled to build it)\n");
#elif !defined HAVE_MUJOCO
    printf("mujoco: skipped (libmujoco-dev not found; meson setup "
           "-Dmujoco=enabled to require it)\n");
#endif
#if !defined HAVE_SYMPY && defined SYMPY_DISABLED
    printf("sympy: skipped (option sympy is disabled; meson setup "
           "-Dsympy=enabled to build it)\n");
#elif !defined HAVE_SYMPY
    printf("sympy: skipped (python3 cannot import sympy.physics.mechanics; "
           "meson setup -Dsympy=enabled to require it)\n");
#endif
    /* compiled tapes in a cache of this run's own: compiled cold */
    if (mkdtemp(dir))
        setenv("AUTOEOM_CACHE_DIR", dir, 1);
    for (i = 0; i < n; i++)
        bad |= measure(Ns[i], reps, quick ? 0.002 : 0.05, &r[i]);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "bench-peers: could not remove %s\n", dir);
    printf("\nOne right-hand side, medians of %d alternating rounds:\n\n",
           reps);
    print_times(Ns, r, n);
    printf("\nAgreement with eom_rhs (max norms; a peer whose backward "
           "error exceeds max(1e-13, 1e-15 N^2) is not timed):\n\n");
    print_agreement(Ns, r, n);
    printf("\nWhat building each route took:\n\n");
    print_build(Ns, r, n);
    return bad;
}
