/* test_compiled.c - compiled tapes (tp_compile), public API only.
 *
 *   1. A Lagrangian of (q, qd, t) that uses every op of the op table, in
 *      both operand orders, with passive operands, parameters, paired
 *      sines and cosines and generic ops whose two operands are one slot:
 *      the compiled tape against the interpreter at 40 random states,
 *      each result to 1e-14 relative (they do the same arithmetic):
 *      tp_lagrange_t (L, dL/dq, dL/dt, M, h: the compiled Lagrange
 *      block), tp_eval (the value sweep) and tp_vjp with several weights
 *      (the gradient sweep); sweeps that stay interpreted (tp_jacobian,
 *      tp_hvp, tp_taylor2) on the same workspace. The same with changed
 *      parameters. Then compiled with every sweep on workspaces as wide
 *      as the independents: also tp_jacobian over all of them (the
 *      Jacobian block; other columns after it stay interpreted) and
 *      tp_taylor2 (the Taylor sweep).
 *   2. The cache: a second compile loads without compiling; other flags
 *      give another entry; a corrupt object, a foreign entry and a
 *      truncated checksum are detected and rebuilt, never loaded; a
 *      missing or failing compiler and an unusable cache directory give
 *      TP_ERR_COMPILE with a message that says which.
 *   3. Parts: a tape of about 1400 ops built by three compilers side by
 *      side (tp_compile_opts.jobs) against the interpreter as in 1, one
 *      of about 560 ops by two and by one (straight-line code: the parts
 *      follow the statements written); only
 *      some sweeps compiled (tp_compile_opts.sweeps): the source has those
 *      alone, and the others run interpreted with the same results.
 *   4. Misuse: a compiled tape on a workspace of another tape or width;
 *      sweeps with an unknown bit; a Jacobian block wider than max_dirs.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "support_rng.h"
#include "tape/tape.h"

#define NQ 3
#define NX (2 * NQ + 1)

/* A Lagrangian with every op. q in [-0.5, 0.5], qd in [-1, 1], t in
 * [0, 1]: every op stays inside its domain. Outputs L, then T and V. */
static int rec_every_op(tp_rec *r, void *user)
{
    tp_val q[NQ], qd[NQ], t, m, a, b, c, T, V, e, w, s1, c1;
    int i;
    (void)user;
    for (i = 0; i < NQ; i++) {
        q[i] = tp_indep(r, i);
        qd[i] = tp_indep(r, NQ + i);
    }
    t = tp_indep(r, 2 * NQ);
    m = tp_param(r, "m", 2.0);
    /* a in [1, 2]: the positive operand of sqrt, log, pow, powc, cdiv */
    a = tp_addc(r, tp_mulc(r, tp_sin(r, q[0]), 0.5), 1.5);
    b = tp_cos(r, q[0]); /* paired with sin(q0) */
    c = tp_mul(r, tp_sqrt(r, tp_mul(r, m, m)), tp_log(r, a));
    /* kinetic part: quadratic in qd with configuration-dependent inertia */
    T = tp_mulc(r, tp_mul(r, m, tp_sqr(r, qd[0])), 0.5);
    T = tp_add(r, T, tp_mul(r, tp_mul(r, qd[0], qd[1]), b));
    T = tp_add(r, T, tp_mul(r, tp_sqr(r, qd[1]), tp_hypot(r, a, q[1])));
    T = tp_add(r, T, tp_div(r, tp_sqr(r, qd[2]), a));
    T = tp_add(r, T, tp_mul(r, tp_mul(r, qd[1], qd[2]),
                            tp_atan2(r, q[2], a)));
    T = tp_add(r, T, tp_mul(r, tp_sqr(r, qd[2]), tp_exp(r, tp_mulc(r, q[1],
                                                                   0.3))));
    T = tp_add(r, T, tp_mul(r, tp_sqr(r, qd[0]),
                            tp_cosh(r, tp_mul(r, q[2], t))));
    /* terms of every other op, some in qd alone, some mixed */
    e = tp_pow(r, a, tp_mulc(r, qd[1], 0.2));
    e = tp_add(r, e, tp_pow(r, a, a));              /* POW, one slot */
    e = tp_add(r, e, tp_hypot(r, qd[0], qd[0]));    /* HYPOT, one slot */
    e = tp_add(r, e, tp_atan2(r, a, a));            /* ATAN2, one slot */
    e = tp_add(r, e, tp_div(r, qd[2], a));
    e = tp_add(r, e, tp_powc(r, a, 1.7));
    e = tp_add(r, e, tp_cdiv(r, 2.0, a));
    e = tp_add(r, e, tp_powi(r, qd[1], 3));
    e = tp_add(r, e, tp_powi(r, a, -2));
    e = tp_add(r, e, tp_tan(r, tp_mulc(r, q[0], 0.5)));
    e = tp_add(r, e, tp_asin(r, tp_mulc(r, tp_sin(r, q[1]), 0.5)));
    e = tp_add(r, e, tp_acos(r, tp_mulc(r, tp_cos(r, q[2]), 0.3)));
    e = tp_add(r, e, tp_atan(r, tp_mul(r, qd[0], q[1])));
    e = tp_add(r, e, tp_sinh(r, tp_mulc(r, qd[1], 0.7)));
    e = tp_add(r, e, tp_tanh(r, tp_mul(r, qd[2], q[0])));
    e = tp_add(r, e, tp_abs(r, tp_addc(r, qd[2], 2.0)));
    e = tp_add(r, e, tp_neg(r, tp_mul(r, qd[0], tp_sin(r, t))));
    /* sine and cosine of rates: a pair, and one alone */
    e = tp_add(r, e, tp_mul(r, tp_sin(r, qd[2]), tp_cos(r, qd[2])));
    e = tp_add(r, e, tp_mul(r, tp_sin(r, tp_mul(r, qd[1], q[0])), a));
    e = tp_sub(r, e, tp_csub(r, 1.5, tp_mul(r, qd[1], q[2])));
    e = tp_sub(r, tp_mul(r, c, qd[2]), e);
    T = tp_add(r, T, tp_mul(r, e, tp_addc(r, tp_sqr(r, qd[0]), 1.0)));
    V = tp_mul(r, m, tp_sub(r, tp_mulc(r, b, -9.81), tp_sqr(r, q[2])));
    V = tp_add(r, V, tp_mul(r, tp_mulc(r, q[1], 3.0), t));
    /* ADD and SUB with a passive operand on either side */
    V = tp_add(r, V, tp_mul(r, tp_sub(r, m, tp_mul(r, q[0], q[1])),
                            tp_sub(r, tp_add(r, m, tp_sqr(r, q[2])), m)));
    /* a pair whose first op only the second output reads: L's cone needs
     * the sine for the cosine's value */
    w = tp_mul(r, q[1], qd[0]);
    s1 = tp_sin(r, w);
    c1 = tp_cos(r, w);
    tp_output(r, "L", tp_add(r, tp_sub(r, T, V), tp_mul(r, c1, qd[2])));
    tp_output(r, "T", tp_add(r, T, s1));
    tp_output(r, "V", V);
    return 0;
}

static tp_tape *record_with(tp_func f, void *user)
{
    unsigned char group[NX];
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    int i;
    for (i = 0; i < NX; i++)
        group[i] = (unsigned char)(i < NQ ? 0 : i < 2 * NQ ? 1 : 2);
    if (tp_recorder_new(&r, NX, group, NULL) != TP_OK ||
        tp_rec_run(r, NULL, f, user) != TP_OK ||
        tp_recorder_finish(r, &t) != TP_OK)
        t = NULL;
    tp_rec_free(&r);
    return t;
}

static tp_tape *record(tp_func f)
{
    return record_with(f, NULL);
}

static void random_state(rng *g, double *x)
{
    int i;
    for (i = 0; i < NQ; i++) {
        x[i] = rng_unit(g) - 0.5;
        x[NQ + i] = 2.0 * rng_unit(g) - 1.0;
    }
    x[2 * NQ] = rng_unit(g);
}

/* Every result relative to 1e-14 (CHECK_NEAR scales by max(1, |b|)). */
static void same(const double *a, const double *b, int n)
{
    int k;
    for (k = 0; k < n; k++)
        CHECK_NEAR(a[k], b[k], 1e-14);
}

static void compare_paths(tp_ws *wi, tp_ws *wc, rng *g, int states)
{
    int s, k;
    for (s = 0; s < states; s++) {
        /* L, dL/dt, dL/dq, h, M, y, gradient, Jacobian, Hessian column,
         * Taylor coefficients (y, y1, y2), the Jacobian's rate columns */
        double x[NX], r[2][2 + 2 * NQ + NQ * NQ + 3 + NX + 3 * NX + NX +
                           9 + 3 * NQ];
        double dir[NX];
        tp_ws *w[2];
        memset(r, 0, sizeof r);
        w[0] = wi;
        w[1] = wc;
        random_state(g, x);
        random_state(g, dir);
        for (k = 0; k < 2; k++) {
            double *L = r[k], *dt = L + 1, *gq = dt + 1, *h = gq + NQ,
                   *M = h + NQ, *y = M + NQ * NQ, *gr = y + 3,
                   *J = gr + NX, *HS = J + 3 * NX, *ty = HS + NX,
                   *Jr = ty + 9;
            const double wt[3] = {1.0, -0.5 + s * 0.1, 2.0};
            double S[NX * 1];
            int i;
            for (i = 0; i < NX; i++)
                S[i] = (i % 2) ? 0.5 : -1.0;
            /* the value and gradient sweeps first: nothing computed at
             * this state before them can hide an op they skipped */
            CHECK_INT(tp_eval(w[k], x, y), TP_OK);
            CHECK_INT(tp_vjp(w[k], x, wt, NULL, gr), TP_OK);
            CHECK_INT(tp_lagrange_t(w[k], x, 0, L, gq, dt, M, h), TP_OK);
            CHECK_INT(tp_jacobian(w[k], x, 0, NX, NULL, J), TP_OK);
            /* other columns than the compiled Jacobian block's: the
             * interpreter, on the rows the block left (it must leave the
             * record of which rows may be non-zero right) */
            CHECK_INT(tp_jacobian(w[k], x, NQ, NQ, NULL, Jr), TP_OK);
            CHECK_INT(tp_hvp(w[k], x, wt, 1, S, NULL, HS), TP_OK);
            CHECK_INT(tp_taylor2(w[k], x, dir, ty, ty + 3, ty + 6), TP_OK);
        }
        same(r[1], r[0], (int)(sizeof r[0] / sizeof(double)));
    }
}

/* ---- 1. every op --------------------------------------------------------- */

static void every_op(const char *dir)
{
    tp_tape *t = record(rec_every_op);
    tp_compile_opts o;
    tp_compile_info info;
    tp_compiled *c = NULL;
    tp_ws *wi = NULL, *wc = NULL;
    rng g = rng_seed(7);
    CHECK(t != NULL);
    if (!t)
        return;
    memset(&o, 0, sizeof o);
    o.cache_dir = dir;
    o.max_dirs = NQ;
    o.lagrange = 1;
    o.lagrange_out = 0;
    CHECK_INT(tp_compile(t, &o, &c, &info), TP_OK);
    if (!c) {
        fprintf(stderr, "tp_compile: %s\n", info.msg);
        tp_tape_free(&t);
        return;
    }
    CHECK(info.source_bytes > 0);
    CHECK_INT(tp_ws_new(&wi, t, NQ, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&wc, t, NQ, NULL), TP_OK);
    CHECK_INT(tp_ws_set_compiled(wc, c), TP_OK);
    CHECK_INT(tp_ws_compiled(wc), 1);
    CHECK_INT(tp_ws_compiled(wi), 0);
    compare_paths(wi, wc, &g, 40);
    /* a parameter changed on both: the passive prefix follows */
    CHECK_INT(tp_ws_set_param(wi, 0, 3.25), TP_OK);
    CHECK_INT(tp_ws_set_param(wc, 0, 3.25), TP_OK);
    compare_paths(wi, wc, &g, 10);
    /* back to the interpreter, then compiled again */
    CHECK_INT(tp_ws_set_compiled(wc, NULL), TP_OK);
    CHECK_INT(tp_ws_compiled(wc), 0);
    CHECK_INT(tp_ws_set_compiled(wc, c), TP_OK);
    compare_paths(wi, wc, &g, 5);
    tp_ws_free(&wi);
    tp_ws_free(&wc);
    tp_compiled_free(&c);
    CHECK(c == NULL);
    /* every sweep, on workspaces as wide as the independents: the
     * Jacobian block and the Taylor sweep too */
    o.max_dirs = NX;
    o.sweeps = TP_SWEEP_VALUES | TP_SWEEP_GRADIENTS | TP_SWEEP_LAGRANGE |
               TP_SWEEP_JACOBIAN | TP_SWEEP_TAYLOR2;
    CHECK_INT(tp_compile(t, &o, &c, &info), TP_OK);
    if (!c)
        fprintf(stderr, "tp_compile: %s\n", info.msg);
    CHECK_INT(tp_ws_new(&wi, t, NX, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&wc, t, NX, NULL), TP_OK);
    if (c) {
        CHECK_INT(tp_ws_set_compiled(wc, c), TP_OK);
        compare_paths(wi, wc, &g, 40);
        CHECK_INT(tp_ws_set_param(wi, 0, -1.5), TP_OK);
        CHECK_INT(tp_ws_set_param(wc, 0, -1.5), TP_OK);
        compare_paths(wi, wc, &g, 10);
    }
    tp_ws_free(&wi);
    tp_ws_free(&wc);
    tp_compiled_free(&c);
    tp_tape_free(&t);
}

/* ---- 3. parts and sweeps ----------------------------------------------- */

/* A long Lagrangian: *user (an int) terms of the form of rec_every_op's
 * kinetic and potential parts, about 9 ops each: 150 give about 1400 ops
 * (three parts of a build with jobs 3), 60 about 560 (two parts with
 * jobs 2). */
static int rec_long(tp_rec *r, void *user)
{
    tp_val q[NQ], qd[NQ], t, L, m;
    const int terms = *(const int *)user;
    int i, k;
    for (i = 0; i < NQ; i++) {
        q[i] = tp_indep(r, i);
        qd[i] = tp_indep(r, NQ + i);
    }
    t = tp_indep(r, 2 * NQ);
    m = tp_param(r, "m", 1.5);
    L = tp_mulc(r, tp_mul(r, m, tp_sqr(r, qd[0])), 0.5);
    for (k = 0; k < terms; k++) {
        const int a = k % NQ, b = (k + 1) % NQ;
        tp_val c = tp_cos(r, tp_addc(r, tp_sub(r, q[a], q[b]), 0.01 * k));
        tp_val term = tp_mul(r, tp_mul(r, qd[a], qd[b]), c);
        term = tp_mulc(r, term, 1.0 / (k + 2.0));
        L = tp_add(r, L, term);
        L = tp_sub(r, L, tp_mulc(r, tp_mul(r, tp_sin(r, q[b]), t),
                                 0.5 / (k + 1.0)));
        L = tp_add(r, L, tp_mulc(r, tp_sqr(r, qd[b]), 0.25 / (k + 3.0)));
    }
    tp_output(r, "L", L);
    tp_output(r, "m", m);
    tp_output(r, "L2", tp_mul(r, L, L));
    return 0;
}

/* The generated source of c's cache entry (info->path with .c). */
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

/* Compile t with o, run it against the interpreter, and say whether the
 * source has each sweep's entry point (fwd0, rev1, lagrange). */
static void compiled_against_interpreter(tp_tape *t, const tp_compile_opts *o,
                                         int parts, const char *has,
                                         const char *lacks, int states)
{
    tp_compile_info info;
    tp_compiled *c = NULL;
    tp_ws *wi = NULL, *wc = NULL;
    rng g = rng_seed(11);
    char *src;
    CHECK_INT(tp_compile(t, o, &c, &info), TP_OK);
    if (!c) {
        fprintf(stderr, "tp_compile: %s\n", info.msg);
        return;
    }
    CHECK_INT(info.parts, parts);
    src = source_of(&info);
    CHECK(src != NULL);
    if (src) {
        char name[32];
        const char *p;
        for (p = has; *p; p += strlen(p) + 1) {
            snprintf(name, sizeof name, "void tpc_%s(", p);
            CHECK(strstr(src, name) != NULL);
        }
        for (p = lacks; *p; p += strlen(p) + 1) {
            snprintf(name, sizeof name, "void tpc_%s(", p);
            CHECK(strstr(src, name) == NULL);
        }
        free(src);
    }
    CHECK_INT(tp_ws_new(&wi, t, NQ, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&wc, t, NQ, NULL), TP_OK);
    CHECK_INT(tp_ws_set_compiled(wc, c), TP_OK);
    compare_paths(wi, wc, &g, states);
    tp_ws_free(&wi);
    tp_ws_free(&wc);
    tp_compiled_free(&c);
}

static void parts_and_sweeps(const char *dir)
{
    static int long_terms = 150, mid_terms = 60;
    tp_tape *t = record_with(rec_long, &long_terms);
    tp_tape *tm = record_with(rec_long, &mid_terms);
    tp_tape *t2 = record(rec_every_op);
    tp_compile_opts o;
    CHECK(t && tm && t2);
    if (!t || !tm || !t2) {
        tp_tape_free(&t);
        tp_tape_free(&tm);
        tp_tape_free(&t2);
        return;
    }
    {
        tp_tape_stats st;
        CHECK_INT(tp_tape_stats_get(t, &st), TP_OK);
        CHECK(st.n_ops >= 1000 && st.n_ops < 1500); /* three parts */
        CHECK_INT(tp_tape_stats_get(tm, &st), TP_OK);
        CHECK(st.n_ops >= 500 && st.n_ops < 1000); /* two parts */
    }
    memset(&o, 0, sizeof o);
    o.cache_dir = dir;
    o.max_dirs = NQ;
    o.lagrange = 1;
    o.lagrange_out = 0;
    o.jobs = 3;
    /* straight-line code: the parts follow the statements written, and
     * loops would leave these tapes too few for three parts */
    o.straight = 1;
    compiled_against_interpreter(t, &o, 3, "fwd0\0rev1\0lagrange\0", "",
                                 20);
    /* a shorter source in two parts and in one piece (other flags, so not
     * from the cache; the 1400 ops again cost 8 s of compiler time) */
    o.jobs = 2;
    o.cflags = "-O0 -g0";
    compiled_against_interpreter(tm, &o, 2, "fwd0\0rev1\0lagrange\0", "",
                                 5);
    o.jobs = 1;
    o.cflags = "-O0";
    compiled_against_interpreter(tm, &o, 1, "fwd0\0rev1\0lagrange\0", "",
                                 5);
    /* some sweeps only; the rest run interpreted */
    o.straight = 0;
    o.jobs = 0;
    o.cflags = NULL;
    o.lagrange = 0;
    o.sweeps = TP_SWEEP_VALUES;
    compiled_against_interpreter(t2, &o, 1, "fwd0\0", "rev1\0lagrange\0",
                                 10);
    o.sweeps = TP_SWEEP_GRADIENTS;
    compiled_against_interpreter(t2, &o, 1, "rev1\0", "fwd0\0lagrange\0",
                                 10);
    o.sweeps = TP_SWEEP_LAGRANGE;
    compiled_against_interpreter(t2, &o, 1, "lagrange\0",
                                 "fwd0\0rev1\0jacobian\0taylor2\0", 10);
    o.sweeps = TP_SWEEP_TAYLOR2;
    compiled_against_interpreter(t2, &o, 1, "taylor2\0",
                                 "fwd0\0rev1\0lagrange\0jacobian\0", 10);
    tp_tape_free(&t);
    tp_tape_free(&tm);
    tp_tape_free(&t2);
}

/* ---- 2. the cache ---------------------------------------------------------- */

static int rec_small(tp_rec *r, void *user)
{
    tp_val x[NX];
    int i;
    (void)user;
    for (i = 0; i < NX; i++)
        x[i] = tp_indep(r, i);
    tp_output(r, "L", tp_sub(r, tp_mul(r, tp_sqr(r, x[NQ]), tp_cos(r, x[0])),
                             tp_sin(r, x[1])));
    return 0;
}

static void corrupt(const char *path, long at)
{
    FILE *f = fopen(path, "r+b");
    CHECK(f != NULL);
    if (!f)
        return;
    fseek(f, at, SEEK_SET);
    fputs("corrupted", f);
    fclose(f);
}

static void copy_file(const char *from, const char *to)
{
    char buf[4096];
    size_t n;
    FILE *a = fopen(from, "rb"), *b = fopen(to, "wb");
    CHECK(a != NULL && b != NULL);
    while (a && b && (n = fread(buf, 1, sizeof buf, a)) > 0)
        fwrite(buf, 1, n, b);
    if (a)
        fclose(a);
    if (b)
        fclose(b);
}

/* Compile t with o; the status, and info. The compiled tape, if any, is
 * checked to run and freed. */
static int compile_once(tp_tape *t, const tp_compile_opts *o,
                        tp_compile_info *info)
{
    tp_compiled *c = NULL;
    tp_ws *w = NULL;
    const double x[NX] = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7};
    double y[3];
    int st = tp_compile(t, o, &c, info);
    CHECK(st == TP_OK ? c != NULL : c == NULL);
    if (c) {
        CHECK_INT(tp_ws_new(&w, t, o->max_dirs > 0 ? o->max_dirs : 1, NULL),
                  TP_OK);
        CHECK_INT(tp_ws_set_compiled(w, c), TP_OK);
        CHECK_INT(tp_eval(w, x, y), TP_OK);
        if (tp_tape_n_outputs(t) == 1) /* rec_small */
            CHECK_NEAR(y[0], 0.16 * cos(0.1) - sin(0.2), 1e-15);
        tp_ws_free(&w);
        tp_compiled_free(&c);
    }
    return st;
}

static void cache(const char *dir)
{
    tp_tape *t = record(rec_small), *t2 = record(rec_every_op);
    tp_compile_opts o;
    tp_compile_info a, b;
    char so[1100], sum[1100], other_so[1100], other_sum[1100];
    CHECK(t != NULL && t2 != NULL);
    if (!t || !t2)
        return;
    memset(&o, 0, sizeof o);
    o.cache_dir = dir;
    CHECK_INT(compile_once(t, &o, &a), TP_OK);
    CHECK_INT(a.cached, 0);
    CHECK_INT(a.rebuilt, 0);
    CHECK(access(a.path, R_OK) == 0);
    CHECK_INT(compile_once(t, &o, &b), TP_OK);
    CHECK_INT(b.cached, 1);
    CHECK(strcmp(a.path, b.path) == 0);
    snprintf(so, sizeof so, "%s", a.path);
    snprintf(sum, sizeof sum, "%.*ssum", (int)strlen(so) - 2, so);
    CHECK(access(sum, R_OK) == 0);

    /* another tape: another entry, compiled anew */
    CHECK_INT(compile_once(t2, &o, &b), TP_OK);
    CHECK_INT(b.cached, 0);
    CHECK(strcmp(a.path, b.path) != 0);

    /* other flags: another entry, compiled anew */
    o.cflags = "-O0";
    CHECK_INT(compile_once(t, &o, &b), TP_OK);
    CHECK_INT(b.cached, 0);
    CHECK(strcmp(a.path, b.path) != 0);
    snprintf(other_so, sizeof other_so, "%s", b.path);
    snprintf(other_sum, sizeof other_sum, "%.*ssum",
             (int)strlen(other_so) - 2, other_so);
    o.cflags = NULL;

    /* a corrupt object: rebuilt, not loaded */
    corrupt(so, 200);
    CHECK_INT(compile_once(t, &o, &b), TP_OK);
    CHECK_INT(b.cached, 0);
    CHECK_INT(b.rebuilt, 1);
    CHECK(strstr(b.msg, "corrupt") != NULL);
    CHECK_INT(compile_once(t, &o, &b), TP_OK);
    CHECK_INT(b.cached, 1);

    /* a foreign entry (another tape's object and checksum) */
    copy_file(other_so, so);
    copy_file(other_sum, sum);
    CHECK_INT(compile_once(t, &o, &b), TP_OK);
    CHECK_INT(b.rebuilt, 1);
    CHECK(strstr(b.msg, "another tape") != NULL);

    /* a truncated checksum */
    fclose(fopen(sum, "w"));
    CHECK_INT(compile_once(t, &o, &b), TP_OK);
    CHECK_INT(b.rebuilt, 1);
    /* an object without its checksum */
    CHECK_INT(remove(sum), 0);
    CHECK_INT(compile_once(t, &o, &b), TP_OK);
    CHECK_INT(b.rebuilt, 1);
    CHECK(strstr(b.msg, "checksum file is missing") != NULL);

    /* no compiler, a failing one, an unusable cache: the status and why */
    o.cc = "/nonexistent/bin/cc";
    o.cflags = "-O1 -DNEW_KEY_1";
    CHECK_INT(compile_once(t, &o, &b), TP_ERR_COMPILE);
    CHECK(strstr(b.msg, "cannot run the C compiler") != NULL);
    o.cc = "false";
    o.cflags = "-O1 -DNEW_KEY_2";
    CHECK_INT(compile_once(t, &o, &b), TP_ERR_COMPILE);
    CHECK(strstr(b.msg, "failed (exit 1)") != NULL);
    o.cc = NULL;
    o.cflags = "-O1 -include /nonexistent/header.h";
    CHECK_INT(compile_once(t, &o, &b), TP_ERR_COMPILE);
    CHECK(strstr(b.msg, "failed") != NULL);
    o.cflags = NULL;
    o.cache_dir = "/proc/no/such/dir";
    CHECK_INT(compile_once(t, &o, &b), TP_ERR_COMPILE);
    CHECK(strstr(b.msg, "cache directory") != NULL);
    /* the Lagrange block needs its width */
    o.cache_dir = dir;
    o.lagrange = 1;
    CHECK_INT(compile_once(t, &o, &b), TP_ERR_SIZE);
    CHECK(b.msg[0] != '\0');
    tp_tape_free(&t);
    tp_tape_free(&t2);
}

/* ---- 3. misuse ------------------------------------------------------------- */

static void misuse(const char *dir)
{
    tp_tape *t = record(rec_small), *t2 = record(rec_every_op);
    tp_compile_opts o;
    tp_compile_info info;
    tp_compiled *c = NULL;
    tp_ws *w = NULL;
    CHECK(t && t2);
    if (!t || !t2)
        return;
    memset(&o, 0, sizeof o);
    o.cache_dir = dir;
    o.max_dirs = 4;
    CHECK_INT(tp_compile(t, &o, &c, &info), TP_OK);
    CHECK_INT(tp_ws_new(&w, t2, 4, NULL), TP_OK);
    CHECK_INT(tp_ws_set_compiled(w, c), TP_ERR_FOREIGN);
    CHECK(strstr(tp_ws_errmsg(w), "another tape") != NULL);
    tp_ws_free(&w);
    CHECK_INT(tp_ws_new(&w, t, 9, NULL), TP_OK);
    CHECK_INT(tp_ws_set_compiled(w, c), TP_ERR_SIZE);
    CHECK_INT(tp_ws_compiled(w), 0);
    tp_ws_free(&w);
    CHECK_INT(tp_ws_set_compiled(NULL, c), TP_ERR_NULL);
    tp_compiled_free(&c);
    CHECK(c == NULL);
    {
        tp_compiled *d = (tp_compiled *)&info; /* overwritten with NULL */
        CHECK_INT(tp_compile(NULL, &o, &d, &info), TP_ERR_NULL);
        CHECK(d == NULL);
    }
    CHECK_INT(tp_compile(t, &o, NULL, &info), TP_ERR_NULL);
    o.sweeps = 32u; /* no such sweep */
    CHECK_INT(tp_compile(t, &o, &c, &info), TP_ERR_SIZE);
    CHECK(c == NULL);
    CHECK(strstr(info.msg, "sweeps") != NULL);
    /* the Jacobian block over more independents than directions */
    o.sweeps = TP_SWEEP_JACOBIAN;
    o.max_dirs = 1;
    CHECK_INT(tp_compile(t2, &o, &c, &info), TP_ERR_SIZE);
    CHECK(c == NULL);
    CHECK(strstr(info.msg, "max_dirs") != NULL);
    tp_compiled_free(NULL);
    tp_tape_free(&t);
    tp_tape_free(&t2);
}

int main(void)
{
    char dir[] = "/tmp/test-compiled-XXXXXX";
    char cmd[128];
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return EXIT_FAILURE;
    }
    every_op(dir);
    cache(dir);
    parts_and_sweeps(dir);
    misuse(dir);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    CHECK_DONE();
}
