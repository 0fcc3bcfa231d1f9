/* test_compiled_loops.c - compiled tapes whose repeated runs are written
 * as loops (libtape's codegen_loops.c), public API only.
 *
 *   1. A rigid N-link chain recorded here (unequal links: masses and
 *      lengths constants that repeat every 7 and 5 links, so some of a
 *      loop's integers come from tables and some from strides; outputs
 *      L and the tip's position) at N = 1, 2, 3, 7, 20 and 50, every
 *      sweep compiled (values, gradients, the Lagrange block, the
 *      Jacobian block, the Taylor sweep): the compiled results equal the
 *      interpreter's bit for bit at several states (a zero's sign aside,
 *      see same_bits). From 7 links on the
 *      source has loops.
 *   2. Size: the Lagrange block of the 50-link chain stays below the
 *      10-link chain's source plus 512 bytes per further link; the
 *      straight-line code of the same tape (tp_compile_opts.straight)
 *      exceeds that bound (it grows about 9 kB per link).
 *   3. A tape without repetition (ops and operands drawn at random):
 *      every sweep equal to the interpreter's bit for bit.
 *   4. The closed chain of flexible links of the element library (5 links
 *      x 3 modes: the Lagrangian's block and the constraints' Jacobian
 *      block and Taylor sweep) and the open rigid chain at 12 links: the
 *      compiled system's right-hand sides equal an interpreted clone's
 *      bit for bit.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/chain.h"
#include "eom/eom.h"
#include "support_rng.h"
#include "support_tape.h"
#include "tape/tape.h"

#define MAXL 50
#define ALL_SWEEPS                                                         \
    (TP_SWEEP_VALUES | TP_SWEEP_GRADIENTS | TP_SWEEP_LAGRANGE |            \
     TP_SWEEP_JACOBIAN | TP_SWEEP_TAYLOR2)

/* ---- the chain --------------------------------------------------------- */

/* Rigid links hanging from the origin, absolute angles q[j], rates qd[j];
 * the root velocity accumulated link by link (the tape grows linearly).
 * Outputs: L = T - V, the tip's x and y. */
static int rec_chain(tp_rec *r, void *user)
{
    const int N = *(const int *)user;
    tp_val vx = tp_const(r, 0.0), vy = tp_const(r, 0.0);
    tp_val px = tp_const(r, 0.0), py = tp_const(r, 0.0);
    tp_val L = tp_const(r, 0.0);
    int j;
    for (j = 0; j < N; j++) {
        const double m = 1.0 + 0.1 * (j % 7), len = 10.0 - 0.3 * (j % 5);
        const tp_val th = tp_indep(r, j), w = tp_indep(r, N + j);
        const tp_val s = tp_sin(r, th), c = tp_cos(r, th);
        /* the centre's velocity: root + (len / 2) w (-sin, cos) */
        const tp_val hw = tp_mulc(r, w, 0.5 * len);
        const tp_val cx = tp_sub(r, vx, tp_mul(r, hw, s));
        const tp_val cy = tp_add(r, vy, tp_mul(r, hw, c));
        tp_val T = tp_mulc(r, tp_add(r, tp_sqr(r, cx), tp_sqr(r, cy)),
                           0.5 * m);
        T = tp_add(r, T, tp_mulc(r, tp_sqr(r, w), m * len * len / 24.0));
        /* gravity on the centre: V = m g (py + len / 2 sin) */
        L = tp_add(r, L, T);
        L = tp_sub(r, L, tp_mulc(r, tp_add(r, py, tp_mulc(r, s, 0.5 * len)),
                                 9.81 * m));
        vx = tp_sub(r, vx, tp_mul(r, tp_mulc(r, w, len), s));
        vy = tp_add(r, vy, tp_mul(r, tp_mulc(r, w, len), c));
        px = tp_add(r, px, tp_mulc(r, c, len));
        py = tp_add(r, py, tp_mulc(r, s, len));
    }
    tp_output(r, "L", L);
    tp_output(r, "x", px);
    tp_output(r, "y", py);
    return 0;
}

/* a and b equal bit for bit but for a zero's sign (st_same_bits), n
 * doubles; the first difference named. */
static void bitwise(const double *a, const double *b, int n, const char *what,
                    int N)
{
    int k;
    for (k = 0; k < n; k++)
        if (!st_same_bits(a[k], b[k])) {
            CHECK(st_same_bits(a[k], b[k]));
            fprintf(stderr, "  %s, N = %d, entry %d: %.17g against %.17g\n",
                    what, N, k, a[k], b[k]);
            return;
        }
}

/* The generated source of a compile (info->path with .c), or NULL. */
static char *source_of(const tp_compile_info *info)
{
    char path[1100];
    size_t n = strlen(info->path);
    FILE *f;
    char *p;
    long len;
    if (n < 3)
        return NULL;
    snprintf(path, sizeof path, "%.*s.c", (int)(n - 3), info->path);
    if (!(f = fopen(path, "rb")))
        return NULL;
    fseek(f, 0, SEEK_END);
    len = ftell(f);
    rewind(f);
    p = calloc((size_t)len + 1, 1);
    if (p && fread(p, 1, (size_t)len, f) != (size_t)len) {
        free(p);
        p = NULL;
    }
    fclose(f);
    return p;
}

/* Every sweep of t (2N independents, outputs m) compiled against the
 * interpreter at `states` random states, bit for bit. *loops: whether
 * the source has a loop. */
static void every_sweep(tp_tape *t, int N, int m, int states, const char *dir,
                        const char *what, int *loops)
{
    const int n = 2 * N;
    tp_compile_opts o;
    tp_compile_info info;
    tp_compiled *c = NULL;
    tp_ws *w[2] = {NULL, NULL};
    rng g = rng_seed(7 + (unsigned)N);
    double *buf, *x, *d, *wt;
    size_t per;
    int s, k, i;
    char *src;
    memset(&o, 0, sizeof o);
    o.cache_dir = dir;
    o.max_dirs = n;
    o.lagrange = 1;
    o.lagrange_out = 0;
    o.sweeps = ALL_SWEEPS;
    CHECK_INT(tp_compile(t, &o, &c, &info), TP_OK);
    if (!c) {
        fprintf(stderr, "%s: tp_compile: %s\n", what, info.msg);
        return;
    }
    src = source_of(&info);
    CHECK(src != NULL);
    *loops = src && strstr(src, "for (long k_ = 0;") != NULL;
    free(src);
    CHECK_INT(tp_ws_new(&w[0], t, n, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&w[1], t, n, NULL), TP_OK);
    CHECK_INT(tp_ws_set_compiled(w[1], c), TP_OK);
    /* per path: y, gradient of the weighted outputs, L, dL/dq, M, h,
     * Jacobian, Taylor y, y1, y2 */
    per = (size_t)m + n + 1 + N + (size_t)N * N + N + (size_t)m * n + 3 * m;
    buf = calloc(2 * per + 3 * (size_t)n + m, sizeof *buf);
    if (!buf) {
        CHECK(buf != NULL);
        return;
    }
    x = buf + 2 * per;
    d = x + n;
    wt = d + n;
    for (s = 0; s < states; s++) {
        for (i = 0; i < N; i++) {
            x[i] = -1.5 + 3.0 * rng_unit(&g);
            x[N + i] = -1.0 + 2.0 * rng_unit(&g);
        }
        for (i = 0; i < n; i++)
            d[i] = -1.0 + 2.0 * rng_unit(&g);
        for (i = 0; i < m; i++)
            wt[i] = 0.5 + rng_unit(&g);
        for (k = 0; k < 2; k++) {
            double *y = buf + k * per, *gr = y + m, *L = gr + n, *gq = L + 1,
                   *M = gq + N, *h = M + N * N, *J = h + N, *ty = J + m * n;
            CHECK_INT(tp_eval(w[k], x, y), TP_OK);
            CHECK_INT(tp_vjp(w[k], x, wt, NULL, gr), TP_OK);
            CHECK_INT(tp_lagrange(w[k], x, 0, L, gq, M, h), TP_OK);
            CHECK_INT(tp_jacobian(w[k], x, 0, n, NULL, J), TP_OK);
            CHECK_INT(tp_taylor2(w[k], x, d, ty, ty + m, ty + 2 * m), TP_OK);
        }
        bitwise(buf + per, buf, (int)per, what, N);
    }
    free(buf);
    tp_ws_free(&w[0]);
    tp_ws_free(&w[1]);
    tp_compiled_free(&c);
}

static void chains(const char *dir)
{
    static const int sizes[] = {1, 2, 3, 7, 20, 50};
    size_t k;
    for (k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        int N = sizes[k], loops = 0;
        tp_tape *t = st_record_qqd(rec_chain, N, &N);
        CHECK(t != NULL);
        if (!t)
            continue;
        every_sweep(t, N, 3, N >= 20 ? 3 : 6, dir, "chain", &loops);
        if (N >= 7)
            CHECK(loops);
        tp_tape_free(&t);
    }
}

/* ---- 2. size ------------------------------------------------------------ */

/* The source bytes of the chain's Lagrange block alone. */
static size_t lagrange_source(int N, int straight, const char *dir)
{
    tp_tape *t = st_record_qqd(rec_chain, N, &N);
    tp_compile_opts o;
    tp_compile_info info;
    tp_compiled *c = NULL;
    memset(&o, 0, sizeof o);
    memset(&info, 0, sizeof info);
    o.cache_dir = dir;
    o.max_dirs = N;
    o.lagrange = 1;
    o.lagrange_out = 0;
    o.sweeps = TP_SWEEP_LAGRANGE;
    o.cflags = "-O0"; /* the size does not depend on it; quicker */
    o.straight = straight;
    CHECK(t != NULL);
    if (t)
        CHECK_INT(tp_compile(t, &o, &c, &info), TP_OK);
    tp_compiled_free(&c);
    tp_tape_free(&t);
    return info.source_bytes;
}

static void size_bound(const char *dir)
{
    const size_t s10 = lagrange_source(10, 0, dir);
    const size_t bound = s10 + 40 * 512;
    const size_t s50 = lagrange_source(50, 0, dir);
    const size_t s50s = lagrange_source(50, 1, dir);
    printf("Lagrange block source: 10 links %zu bytes, 50 links %zu "
           "(straight-line %zu), bound %zu\n",
           s10, s50, s50s, bound);
    CHECK(s10 > 0);
    CHECK(s50 < bound);
    CHECK(s50s > bound);
}

/* ---- 3. no repetition --------------------------------------------------- */

/* Ops and operands drawn from a fixed pseudo-random sequence over NR
 * independents; values kept in range by sines. */
#define NR 4
static int rec_random(tp_rec *r, void *user)
{
    tp_val pool[400];
    unsigned long long s = 0x9e3779b97f4a7c15ull;
    int np = 0, k;
    (void)user;
    for (k = 0; k < 2 * NR; k++)
        pool[np++] = tp_indep(r, k);
    for (k = 0; k < 300; k++) {
        tp_val a, b, v;
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        a = pool[(s >> 33) % (unsigned)np];
        b = pool[(s >> 17) % (unsigned)np];
        switch ((s >> 50) % 7) {
        case 0: v = tp_mul(r, a, b); break;
        case 1: v = tp_add(r, a, b); break;
        case 2: v = tp_sub(r, a, b); break;
        case 3: v = tp_sin(r, a); break;
        case 4: v = tp_cos(r, tp_mulc(r, b, 0.5 + 0.001 * k)); break;
        case 5: v = tp_sqr(r, tp_sin(r, a)); break;
        default: v = tp_mulc(r, tp_add(r, a, tp_sqr(r, b)), 0.25); break;
        }
        /* keep magnitudes near one */
        pool[np++] = k % 3 == 0 ? tp_sin(r, v) : v;
    }
    tp_output(r, "L", tp_add(r, pool[np - 1], tp_mul(r, pool[np - 2],
                                                   pool[np - 3])));
    tp_output(r, "y", pool[np - 7]);
    return 0;
}

static void no_repetition(const char *dir)
{
    int N = NR, loops = 0;
    tp_tape *t = st_record_qqd(rec_random, N, NULL);
    CHECK(t != NULL);
    if (t)
        every_sweep(t, N, 2, 10, dir, "random tape", &loops);
    tp_tape_free(&t);
}

/* ---- 4. the element library's chains ----------------------------------- */

static void system_bitwise(int links, int modes, int closed)
{
    eom_chain_spec sp;
    eom_model *m = NULL;
    eom_system *s = NULL, *c = NULL;
    eom_compiled_info info;
    char msg[256] = "";
    double x[2 * 64], a[2 * 64], b[2 * 64], x0[2 * 64];
    rng g = rng_seed(5);
    int n, k, i, st;
    memset(&sp, 0, sizeof sp);
    sp.links = links;
    sp.modes_all = modes;
    sp.m = 1.0;
    sp.L = 10.0;
    sp.EI = 4e4;
    sp.g = 9.81;
    sp.c = closed ? 0.5 : 0.0;
    sp.closed = closed;
    sp.D = closed ? 0.8 * 10.0 * links : 0.0;
    CHECK_INT(eom_model_new(&m), EOM_OK);
    CHECK(eom_chain_add(m, &sp) >= 0);
    CHECK_INT(eom_system_new(&s, m, msg, sizeof msg), EOM_OK);
    eom_model_free(&m);
    if (!s) {
        fprintf(stderr, "chain %d x %d: %s\n", links, modes, msg);
        return;
    }
    n = eom_system_ncoords(s);
    CHECK(n <= 64);
    CHECK_INT(eom_system_clone(&c, s, NULL, 0), EOM_OK);
    st = eom_system_set_compiled(s, 1, &info);
    CHECK_INT(st, EOM_OK);
    if (st != EOM_OK || !c || n > 64) {
        fprintf(stderr, "chain %d x %d: %s\n", links, modes,
                eom_system_errmsg(s));
        eom_system_free(&s);
        eom_system_free(&c);
        return;
    }
    eom_initial_state(s, x0);
    for (k = 0; k < 8; k++) {
        for (i = 0; i < 2 * n; i++)
            x[i] = x0[i] + (k ? 0.1 * (rng_unit(&g) - 0.5) : 0.0);
        CHECK_INT(eom_rhs(s, 0.0, x, a), eom_rhs(c, 0.0, x, b));
        bitwise(a, b, 2 * n, closed ? "closed chain" : "open chain", links);
    }
    eom_system_free(&s);
    eom_system_free(&c);
}

int main(void)
{
    char dir[] = "/tmp/test-compiled-loops-XXXXXX";
    char cmd[128];
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return EXIT_FAILURE;
    }
    setenv("AUTOEOM_CACHE_DIR", dir, 1); /* the systems' compiles */
    chains(dir);
    size_bound(dir);
    no_repetition(dir);
    system_bitwise(5, 3, 1);
    system_bitwise(12, 0, 0);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    CHECK_DONE();
}
