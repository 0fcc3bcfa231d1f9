/* test_compiled_strips.c - the compiled Lagrange block's rows in strips
 * of directions (libtape's codegen_lagrange.c), public API only.
 *
 * The block sweeps values and adjoints once and the direction rows strip
 * by strip, 4 or 8 directions at a time, where the workspace's rows are
 * 12 or more wide; each direction's arithmetic must stay the
 * interpreter's, so every result below is compared bit for bit (a
 * zero's sign aside) with an interpreting workspace of the same tape:
 *
 *   1. A rigid N-link chain (unequal links) at every N from 1 to 17 and
 *      at 50, with max_dirs N (rows 4, 8, 12, 16, 20 and 52 wide: no
 *      strips, strips of 4 ending full and part-full, strips of 8 with
 *      a last strip of one direction) and with max_dirs 2N (strips of 8
 *      from 8 links on): L, dL/dq, M and h of tp_lagrange at several
 *      states, and after it an interpreted Jacobian and gradient on the
 *      same workspace (the block keeps out of the rows the interpreter
 *      uses). Where the rows are 12 or more wide the source must have
 *      the strip loop, where they are 8 or less it must not.
 *   2. A tape of random ops over 2 x 20 independents, among them the
 *      rarer ops whose partials the generated code computes at run time
 *      (division, square root, exponential, arc tangent), so each strip
 *      computes them again: the same checks, 20 directions in strips of
 *      8, 8 and 4.
 *   3. The strips' gates (each row run only in the strips its column
 *      range reaches): a tape whose adjoint-tangent row is first written
 *      by an op reaching fewer strips than a later writer, and rows of
 *      single rates, at 33 and 40 rates (5 strips; fewer are not
 *      gated; the 50-link chain above runs gated too).
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "support_rng.h"
#include "support_tape.h"
#include "tape/tape.h"

#define MAXL 50

/* Rigid links hanging from the origin, absolute angles q[j], rates qd[j];
 * the root velocity accumulated link by link. Outputs: L = T - V and the
 * tip's x. */
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
        const tp_val hw = tp_mulc(r, w, 0.5 * len);
        const tp_val cx = tp_sub(r, vx, tp_mul(r, hw, s));
        const tp_val cy = tp_add(r, vy, tp_mul(r, hw, c));
        const tp_val ke = tp_mulc(
            r, tp_add(r, tp_sqr(r, cx), tp_sqr(r, cy)), 0.5 * m);
        const tp_val rot = tp_mulc(r, tp_sqr(r, w), m * len * len / 24.0);
        const tp_val pe = tp_mulc(r, tp_add(r, py, tp_mulc(r, c, -0.5 * len)),
                                  -9.81 * m);
        L = tp_add(r, L, tp_sub(r, tp_add(r, ke, rot), pe));
        vx = tp_sub(r, vx, tp_mul(r, tp_mulc(r, w, len), s));
        vy = tp_add(r, vy, tp_mul(r, tp_mulc(r, w, len), c));
        px = tp_add(r, px, tp_mulc(r, s, len));
        py = tp_sub(r, py, tp_mulc(r, c, len));
    }
    tp_output(r, "L", L);
    tp_output(r, "x", px);
    return 0;
}

/* Ops and operands drawn from a fixed pseudo-random sequence over 2 NR
 * independents, the rarer ops among them; magnitudes kept near one. */
#define NR 20
static int rec_random(tp_rec *r, void *user)
{
    tp_val pool[600];
    unsigned long long s = 0x2545f4914f6cdd1dull;
    int np = 0, k;
    (void)user;
    for (k = 0; k < 2 * NR; k++)
        pool[np++] = tp_indep(r, k);
    for (k = 0; k < 400; k++) {
        tp_val a, b, v;
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        a = pool[(s >> 33) % (unsigned)np];
        b = pool[(s >> 17) % (unsigned)np];
        switch ((s >> 50) % 10) {
        case 0: v = tp_mul(r, a, b); break;
        case 1: v = tp_add(r, a, b); break;
        case 2: v = tp_sub(r, a, tp_mulc(r, b, 0.75)); break;
        case 3: v = tp_sin(r, a); break;
        case 4: v = tp_cos(r, tp_mulc(r, b, 0.5 + 0.001 * k)); break;
        case 5: v = tp_div(r, a, tp_addc(r, tp_sqr(r, b), 1.0)); break;
        case 6: v = tp_sqrt(r, tp_addc(r, tp_sqr(r, a), 0.5)); break;
        case 7: v = tp_exp(r, tp_mulc(r, tp_sin(r, b), 0.5)); break;
        case 8: v = tp_atan(r, tp_mul(r, a, b)); break;
        default: v = tp_sqr(r, tp_sin(r, a)); break;
        }
        pool[np++] = k % 3 == 0 ? tp_sin(r, v) : v;
    }
    tp_output(r, "L", tp_add(r, pool[np - 1], tp_mul(r, pool[np - 2],
                                                   pool[np - 3])));
    tp_output(r, "y", pool[np - 7]);
    return 0;
}

/* The strips' gates (rows run only in the strips their column ranges
 * reach, from the last strip to the first): an adjoint-tangent row w
 * whose first writer (the last op reading w, y2 = w^2, rate 0 only)
 * reaches fewer strips than an earlier reader (y1 = w a, a of the last
 * rate): where y1 runs, y2 must run too, or y1's row would be added to
 * the previous strip's. Besides, rows of single rates (a ragged set of
 * ranges) and a sum over all rates. */
static int rec_gates(tp_rec *r, void *user)
{
    const int N = *(const int *)user;
    const tp_val q0 = tp_indep(r, 0), r0 = tp_indep(r, N),
                 rl = tp_indep(r, 2 * N - 1);
    const tp_val w = tp_add(r, tp_sin(r, q0), r0);
    const tp_val a = tp_mul(r, rl, rl);
    tp_val L = tp_mul(r, w, a), sum = tp_const(r, 0.0);
    int j;
    L = tp_add(r, L, tp_sqr(r, w));
    for (j = 0; j < N; j++) {
        const tp_val x = tp_mul(r, tp_indep(r, N + j), tp_cos(r, tp_indep(r, j)));
        sum = tp_add(r, sum, x);
        if (j % 3 == 1)
            L = tp_add(r, L, tp_sqr(r, x));
    }
    L = tp_add(r, L, tp_sqr(r, sum));
    tp_output(r, "L", L);
    tp_output(r, "y", w);
    return 0;
}

/* a and b equal bit for bit but for a zero's sign (st_same_bits), n
 * doubles; the first difference named. */
static void bitwise(const double *a, const double *b, int n, const char *what,
                    int N, int dirs)
{
    int k;
    for (k = 0; k < n; k++)
        if (!st_same_bits(a[k], b[k])) {
            CHECK(st_same_bits(a[k], b[k]));
            fprintf(stderr,
                    "  %s, N = %d, max_dirs %d, entry %d: %.17g against "
                    "%.17g\n",
                    what, N, dirs, k, a[k], b[k]);
            return;
        }
}

/* Whether the generated source (info->path with .c) has the strip loop;
 * -1 if it cannot be read. */
static int has_strips(const tp_compile_info *info)
{
    char path[1100], line[512];
    size_t n = strlen(info->path);
    FILE *f;
    int found = 0;
    if (n < 3)
        return -1;
    snprintf(path, sizeof path, "%.*s.c", (int)(n - 3), info->path);
    if (!(f = fopen(path, "rb")))
        return -1;
    while (!found && fgets(line, sizeof line, f))
        found = strstr(line, "const int c_ = s_ * SW;") != NULL;
    fclose(f);
    return found;
}

/* The Lagrange block of t (2N independents, m outputs) compiled with
 * max_dirs dirs against the interpreter at `states` random states. */
static void against_interpreter(tp_tape *t, int N, int m, int dirs,
                                int states, const char *dir,
                                const char *what)
{
    const int n = 2 * N;
    tp_compile_opts o;
    tp_compile_info info;
    tp_compiled *c = NULL;
    tp_ws *w[2] = {NULL, NULL};
    rng g = rng_seed(11 + (unsigned)N + 100u * (unsigned)dirs);
    double *buf, *x, *wt;
    size_t per;
    int s, k, i, strips;
    const int P = (dirs + 3) / 4 * 4;
    memset(&o, 0, sizeof o);
    memset(&info, 0, sizeof info);
    o.cache_dir = dir;
    o.max_dirs = dirs;
    o.lagrange = 1;
    o.lagrange_out = 0;
    o.sweeps = TP_SWEEP_LAGRANGE;
    CHECK_INT(tp_compile(t, &o, &c, &info), TP_OK);
    if (!c) {
        fprintf(stderr, "%s: tp_compile: %s\n", what, info.msg);
        return;
    }
    strips = has_strips(&info);
    if (P >= 12)
        CHECK_INT(strips, 1);
    else
        CHECK_INT(strips, 0);
    CHECK_INT(tp_ws_new(&w[0], t, dirs, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&w[1], t, dirs, NULL), TP_OK);
    CHECK_INT(tp_ws_set_compiled(w[1], c), TP_OK);
    /* per path: L, dL/dq, M, h, then the Jacobian and the gradient of the
     * weighted outputs (interpreted, after the block) */
    per = 1 + (size_t)N + (size_t)N * N + N + (size_t)m * n + n;
    buf = calloc(2 * per + (size_t)n + m, sizeof *buf);
    if (!buf) {
        CHECK(buf != NULL);
        return;
    }
    x = buf + 2 * per;
    wt = x + n;
    for (s = 0; s < states; s++) {
        for (i = 0; i < N; i++) {
            x[i] = -1.5 + 3.0 * rng_unit(&g);
            x[N + i] = -1.0 + 2.0 * rng_unit(&g);
        }
        for (i = 0; i < m; i++)
            wt[i] = 0.5 + rng_unit(&g);
        for (k = 0; k < 2; k++) {
            double *L = buf + k * per, *gq = L + 1, *M = gq + N, *h = M + N * N,
                   *J = h + N, *gr = J + m * n;
            CHECK_INT(tp_lagrange(w[k], x, 0, L, gq, M, h), TP_OK);
            CHECK_INT(tp_jacobian(w[k], x, 0, n, NULL, J), TP_OK);
            CHECK_INT(tp_vjp(w[k], x, wt, NULL, gr), TP_OK);
        }
        bitwise(buf + per, buf, (int)per, what, N, dirs);
    }
    free(buf);
    tp_ws_free(&w[0]);
    tp_ws_free(&w[1]);
    tp_compiled_free(&c);
}

static void chains(const char *dir)
{
    int N;
    for (N = 1; N <= MAXL; N = N < 17 ? N + 1 : MAXL + (N == MAXL)) {
        tp_tape *t = st_record_qqd(rec_chain, N, &N);
        CHECK(t != NULL);
        if (!t)
            continue;
        against_interpreter(t, N, 2, N, N >= 17 ? 2 : 4, dir, "chain");
        if (N >= 4)
            against_interpreter(t, N, 2, 2 * N, 2, dir, "chain");
        tp_tape_free(&t);
    }
}

static void random_tape(const char *dir)
{
    int N = NR;
    tp_tape *t = st_record_qqd(rec_random, N, NULL);
    CHECK(t != NULL);
    if (t)
        against_interpreter(t, N, 2, N, 6, dir, "random tape");
    tp_tape_free(&t);
}

static void gates_tape(const char *dir)
{
    int N;
    for (N = 33; N <= 40; N += 7) { /* 5 strips of 8: gated */
        tp_tape *t = st_record_qqd(rec_gates, N, &N);
        CHECK(t != NULL);
        if (t)
            against_interpreter(t, N, 2, N, 3, dir, "gates tape");
        tp_tape_free(&t);
    }
}

int main(void)
{
    char dir[] = "/tmp/test-compiled-strips-XXXXXX";
    char cmd[128];
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return EXIT_FAILURE;
    }
    chains(dir);
    random_tape(dir);
    gates_tape(dir);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    CHECK_DONE();
}
