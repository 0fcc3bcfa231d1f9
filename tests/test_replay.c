/* test_replay.c - one tape, many replays: what a workspace carries from one
 * sweep to the next must never change a result.
 *
 *   1. replay at new points equals the double evaluator and a tape
 *      recorded afresh (bit for bit);
 *   2. a parameter changed in a workspace (tp_ws_set_param) equals a tape
 *      recorded with that default (bit for bit) and the evaluators given
 *      the value by tp_rec_set_param; workspaces do not share parameters;
 *   3. workspaces with max_dirs 1, 2, 3 (chunked sweeps) give the results
 *      of one with max_dirs >= n;
 *   4. an adversarial random sequence of every kind of sweep (Lagrange
 *      blocks, jvp with q-only, group-confined and zero seeds, Hessians,
 *      Hessian columns, hvp with zero weights, gradients of early outputs,
 *      Taylor, eval) on one workspace gives, call by call, exactly the
 *      results of a fresh workspace. This is what the zero-row invariants of
 *      forward.c and reverse.c promise: the dependency mask, the number of
 *      directions and the last swept op change from call to call.
 * Tapes: the pendulum (groups q = 0, qd = 1) and a function of six
 * independents in three groups whose outputs sit at very different places
 * on the tape (an independent, a passive output, a one-group output).
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "pendulum_chain.h"
#include "support_num.h"
#include "support_rng.h"
#include "support_tape.h"

#define NXMAX 12 /* independents at most */
#define NOMAX 6  /* outputs at most */
#define PMAX 6   /* directions per call at most */

static const double PI_ = 3.14159265358979323846;

/* ---- the tapes -------------------------------------------------------- */

/* Six independents in three groups (x0, x1 | x2, x3 | x4, x5), two
 * parameters, outputs in a deliberately scattered order. */
static int mix_record(tp_rec *r, void *user)
{
    tp_val x[6], p, k, a, b, c, d, e;
    int i;
    (void)user;
    for (i = 0; i < 6; i++)
        x[i] = tp_indep(r, i);
    p = tp_param(r, "p", 1.3);
    k = tp_param(r, "k", 0.4);
    a = tp_mul(r, tp_sin(r, x[0]), tp_exp(r, tp_mul(r, k, x[3])));
    tp_output(r, "early", a);
    b = tp_add(r, tp_mul(r, p, tp_sqr(r, x[1])), tp_cos(r, x[4]));
    c = tp_div(r, x[5], tp_addc(r, tp_sqr(r, x[2]), 1.0));
    tp_output(r, "group2", tp_mul(r, x[4], tp_tanh(r, x[5])));
    tp_output(r, "indep", x[3]);
    tp_output(r, "passive", tp_mulc(r, p, 2.0));
    d = tp_add(r, tp_add(r, a, b), c);
    e = tp_add(r, tp_hypot(r, d, x[0]),
               tp_atan2(r, x[2], tp_addc(r, x[1], 3.0)));
    tp_output(r, "main", tp_add(r, tp_mul(r, d, e),
                                tp_log(r, tp_addc(r, tp_sqr(r, x[3]), 1.0))));
    tp_output(r, "group0", tp_mul(r, x[0], x[1]));
    return 0;
}

static const unsigned char mix_groups[6] = {0, 0, 1, 1, 2, 2};

typedef struct chain4 {
    double m[4], l[4];
    pendulum_chain pc;
} chain4;

static void chain4_init(chain4 *c)
{
    static const double m[4] = {1.3, 0.7, 2.1, 0.9};
    static const double l[4] = {0.8, 1.4, 0.5, 1.1};
    memcpy(c->m, m, sizeof m);
    memcpy(c->l, l, sizeof l);
    c->pc.n = 4;
    c->pc.m = c->m;
    c->pc.l = c->l;
    c->pc.g = 9.81;
}

static tp_tape *record(int n, const unsigned char *grp, tp_func f,
                       void *user)
{
    tp_rec *r = NULL;
    tp_tape *T = NULL;
    CHECK_INT(tp_recorder_new(&r, n, grp, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, f, user), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    tp_rec_free(&r);
    return T;
}

static void random_state(rng *g, int n, double *x)
{
    int i;
    for (i = 0; i < n; i++)
        x[i] = i < n / 2 ? rng_range(g, -PI_, PI_) : rng_range(g, -2.0, 2.0);
}

/* ---- 1. replay against the evaluator and re-recording ----------------- */

static void replay_points(void)
{
    static const unsigned char grp[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    chain4 c;
    tp_tape *T, *T2 = NULL;
    tp_ws *ws = NULL, *ws2 = NULL;
    tp_rec *ev = NULL;
    rng g = rng_seed(0x7e91a001u);
    double x[8], y[3], yev[3], y2[3], M[16], M2[16], h[4], h2[4], H[64],
        H2[64];
    int k;

    chain4_init(&c);
    T = record(8, grp, pendulum_chain_record, &c.pc);
    CHECK_INT(tp_ws_new(&ws, T, 2, NULL), TP_OK);
    CHECK_INT(tp_evaluator_new(&ev, 8, NULL), TP_OK);
    if (!ws || !ev)
        goto done;
    for (k = 0; k < 20; k++) {
        char ctx[64];
        snprintf(ctx, sizeof ctx, "replay point %d", k);
        random_state(&g, 8, x);
        CHECK_INT(tp_eval(ws, x, y), TP_OK);
        CHECK_INT(st_eval(ev, x, pendulum_chain_record, &c.pc, yev), TP_OK);
        CHECK_VEC(ctx, y, yev, 3, 1e-14);
        CHECK_INT(tp_lagrange(ws, x, 0, NULL, NULL, M, h), TP_OK);
        CHECK_INT(tp_hessian(ws, x, 0, H), TP_OK);
        if (k % 4 == 0) {
            /* a tape recorded anew, in a new workspace */
            T2 = record(8, grp, pendulum_chain_record, &c.pc);
            CHECK_INT(tp_ws_new(&ws2, T2, 2, NULL), TP_OK);
            if (ws2) {
                CHECK_INT(tp_eval(ws2, x, y2), TP_OK);
                CHECK_INT(tp_lagrange(ws2, x, 0, NULL, NULL, M2, h2), TP_OK);
                CHECK_INT(tp_hessian(ws2, x, 0, H2), TP_OK);
                CHECK_SAME(ctx, y, y2, 3);
                CHECK_SAME(ctx, M, M2, 16);
                CHECK_SAME(ctx, h, h2, 4);
                CHECK_SAME(ctx, H, H2, 64);
            }
            tp_ws_free(&ws2);
            tp_tape_free(&T2);
        }
    }
done:
    tp_rec_free(&ev);
    tp_ws_free(&ws);
    tp_tape_free(&T);
}

/* ---- 2. parameters ---------------------------------------------------- */

typedef struct lag_result {
    double y[3], L, dLdq[4], M[16], h[4], H[64];
} lag_result;

static void lag_all(tp_ws *ws, const double *x, lag_result *R)
{
    CHECK_INT(tp_eval(ws, x, R->y), TP_OK);
    CHECK_INT(tp_lagrange(ws, x, 0, &R->L, R->dLdq, R->M, R->h), TP_OK);
    CHECK_INT(tp_hessian(ws, x, 0, R->H), TP_OK);
}

static void check_same_lag(const char *ctx, const lag_result *a,
                           const lag_result *b)
{
    CHECK_SAME(ctx, a->y, b->y, 3);
    CHECK_SAME(ctx, &a->L, &b->L, 1);
    CHECK_SAME(ctx, a->dLdq, b->dLdq, 4);
    CHECK_SAME(ctx, a->M, b->M, 16);
    CHECK_SAME(ctx, a->h, b->h, 4);
    CHECK_SAME(ctx, a->H, b->H, 64);
}

static void parameters(void)
{
    static const unsigned char grp[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    static const char *const names[3] = {"m2", "g", "l3"};
    static const double values[3] = {2.7, 3.5, 0.35};
    chain4 c, c2;
    tp_tape *T, *T2;
    tp_ws *ws = NULL, *ws_other = NULL, *ws2 = NULL;
    tp_rec *ev = NULL, *tu = NULL;
    rng g = rng_seed(0x7e91a002u);
    lag_result R, R0, R2, Rother;
    double x[8], yev[3], Lt, dLdqt[4], Mt[16], ht[4], v;
    int j, k, idx;

    chain4_init(&c);
    T = record(8, grp, pendulum_chain_record, &c.pc);
    CHECK_INT(tp_tape_n_params(T), 9);
    CHECK_INT(tp_ws_new(&ws, T, 3, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&ws_other, T, 3, NULL), TP_OK);
    CHECK_INT(tp_evaluator_new(&ev, 8, NULL), TP_OK);
    CHECK_INT(tp_tuple_new(&tu, 8, NULL), TP_OK);
    if (!ws || !ws_other || !ev || !tu)
        goto done;
    random_state(&g, 8, x);
    lag_all(ws, x, &R0);

    for (j = 0; j < 3; j++) {
        char ctx[64];
        snprintf(ctx, sizeof ctx, "parameter %s", names[j]);
        idx = tp_tape_param_index(T, names[j]);
        CHECK(idx >= 0);
        if (idx < 0)
            continue;
        /* the tape's default, then a new value in one workspace */
        CHECK_INT(tp_ws_get_param(ws, idx, &v), TP_OK);
        CHECK_VEC(ctx, &v, &(double){tp_tape_param_default(T, idx)}, 1,
                  0.0);
        CHECK_INT(tp_ws_set_param(ws, idx, values[j]), TP_OK);
        CHECK_INT(tp_ws_get_param(ws, idx, &v), TP_OK);
        CHECK_VEC(ctx, &v, &values[j], 1, 0.0);

        /* a tape recorded with that default */
        c2 = c;
        c2.pc.m = c2.m;
        c2.pc.l = c2.l;
        if (j == 0)
            c2.m[1] = values[j];
        else if (j == 1)
            c2.pc.g = values[j];
        else
            c2.l[2] = values[j];
        T2 = record(8, grp, pendulum_chain_record, &c2.pc);
        CHECK_INT(tp_ws_new(&ws2, T2, 3, NULL), TP_OK);
        if (!ws2) {
            tp_tape_free(&T2);
            continue;
        }
        for (k = 0; k < 4; k++) {
            random_state(&g, 8, x);
            lag_all(ws, x, &R);
            lag_all(ws2, x, &R2);
            check_same_lag(ctx, &R, &R2);
            /* the evaluators with the value set by name */
            CHECK_INT(tp_rec_set_param(ev, names[j], values[j]), TP_OK);
            CHECK_INT(tp_rec_set_param(tu, names[j], values[j]), TP_OK);
            CHECK_INT(st_eval(ev, x, pendulum_chain_record, &c.pc, yev),
                      TP_OK);
            CHECK_VEC(ctx, R.y, yev, 3, 1e-14);
            CHECK_INT(tp_rec_run(tu, x, pendulum_chain_record, &c.pc),
                      TP_OK);
            CHECK_INT(tp_tuple_lagrange(tu, 0, &Lt, dLdqt, Mt, ht), TP_OK);
            CHECK_VEC(ctx, &R.L, &Lt, 1, 1e-14);
            CHECK_VEC(ctx, R.dLdq, dLdqt, 4, 1e-13);
            CHECK_VEC(ctx, R.M, Mt, 16, 1e-14);
            CHECK_VEC(ctx, R.h, ht, 4, 1e-13);
            /* a workspace of the same tape keeps its own parameters */
            lag_all(ws_other, x, &Rother);
            lag_all(ws2, x, &R2);
            CHECK(num_count_diff(Rother.y, R2.y, 3) > 0);
        }
        /* back to the default: the first results again */
        CHECK_INT(tp_ws_set_param(ws, idx, tp_tape_param_default(T, idx)),
                  TP_OK);
        CHECK_INT(tp_rec_set_param(ev, names[j],
                                   tp_tape_param_default(T, idx)),
                  TP_OK);
        CHECK_INT(tp_rec_set_param(tu, names[j],
                                   tp_tape_param_default(T, idx)),
                  TP_OK);
        random_state(&g, 8, x);
        lag_all(ws, x, &R);
        lag_all(ws_other, x, &Rother);
        check_same_lag(ctx, &R, &Rother);
        tp_ws_free(&ws2);
        tp_tape_free(&T2);
    }
done:
    tp_rec_free(&ev);
    tp_rec_free(&tu);
    tp_ws_free(&ws);
    tp_ws_free(&ws_other);
    tp_tape_free(&T);
}

/* ---- calls on a workspace, recorded so they can be repeated ----------- */

enum call_kind {
    C_EVAL, C_LAGRANGE, C_JVP_Q, C_JVP_GROUPS, C_HESSIAN, C_HESS_COLS,
    C_HVP, C_GRADIENT, C_VJP, C_TAYLOR, C_JACOBIAN, C_KINDS
};

typedef struct call {
    int kind, out, first, count, p;
    bool want_y;
    double x[NXMAX], S[NXMAX * PMAX], w[NOMAX], d[NXMAX];
} call;

typedef struct shape {
    int n, m;
    const unsigned char *grp;
} shape;

/* Directions on the independents of the groups in mask only. */
static void seed(rng *g, const shape *sh, unsigned mask, int p, double *S)
{
    int i, k;
    for (i = 0; i < sh->n; i++)
        for (k = 0; k < p; k++)
            S[i * p + k] = (mask >> sh->grp[i]) & 1u
                               ? rng_range(g, -1.0, 1.0)
                               : 0.0;
}

static void random_call(rng *g, const shape *sh, call *c)
{
    int o;
    memset(c, 0, sizeof *c);
    c->kind = rng_int(g, C_KINDS);
    c->out = rng_int(g, sh->m);
    c->first = rng_int(g, sh->n);
    c->count = rng_int(g, sh->n - c->first + 1);
    c->p = 1 + rng_int(g, PMAX);
    c->want_y = rng_int(g, 2);
    random_state(g, sh->n, c->x);
    for (o = 0; o < sh->m; o++)
        c->w[o] = rng_int(g, 3) ? 0.0 : rng_range(g, -1.0, 1.0);
    switch (c->kind) {
    case C_JVP_Q:
        seed(g, sh, 1u, c->p, c->S); /* q (group 0) only */
        break;
    case C_JVP_GROUPS:
    case C_HVP:
        /* any set of groups, the empty one (a zero seed) included */
        seed(g, sh, (unsigned)rng_int(g, 8), c->p, c->S);
        break;
    case C_TAYLOR:
        seed(g, sh, (unsigned)rng_int(g, 8), 1, c->d);
        break;
    default: break;
    }
}

#define RESMAX (2 * NXMAX * NXMAX + 4 * NXMAX * PMAX)

/* Run c on ws; writes every result into res[RESMAX] and returns how many
 * entries are meaningful. */
static int do_call(tp_ws *ws, const shape *sh, const call *c, double *res)
{
    const int n = sh->n, m = sh->m;
    double *y = c->want_y ? res : NULL;
    int st = -100, used = 0;
    /* parts a call leaves unwritten (y or g not asked for) compare as 0 */
    memset(res, 0, RESMAX * sizeof(double));
    switch (c->kind) {
    case C_EVAL:
        st = tp_eval(ws, c->x, res);
        used = m;
        break;
    case C_LAGRANGE:
        st = tp_lagrange(ws, c->x, c->out, res, res + 1, res + 1 + n / 2,
                         res + 1 + n / 2 + n * n / 4);
        used = 1 + n + n * n / 4;
        break;
    case C_JVP_Q:
    case C_JVP_GROUPS:
        st = tp_jvp(ws, c->x, c->p, c->S, y, res + m);
        used = m + m * c->p;
        break;
    case C_HESSIAN:
        st = tp_hessian(ws, c->x, c->out, res);
        used = n * n;
        break;
    case C_HESS_COLS:
        st = tp_hessian_cols(ws, c->x, c->out, c->first, c->count, res,
                             res + n);
        used = n + n * c->count;
        break;
    case C_HVP:
        st = tp_hvp(ws, c->x, c->w, c->p, c->S, c->want_y ? res : NULL,
                    res + n);
        used = n + n * c->p;
        break;
    case C_GRADIENT:
        st = tp_gradient(ws, c->x, c->out, res, res + 1);
        used = 1 + n;
        break;
    case C_VJP:
        st = tp_vjp(ws, c->x, c->w, y, res + m);
        used = m + n;
        break;
    case C_TAYLOR:
        st = tp_taylor2(ws, c->x, c->d, y, res + m, res + 2 * m);
        used = 3 * m;
        break;
    case C_JACOBIAN:
        st = tp_jacobian(ws, c->x, c->first, c->count, y, res + m);
        used = m + m * c->count;
        break;
    default: break;
    }
    CHECK_INT(st, TP_OK);
    return used;
}

static const char *const kind_name[C_KINDS] = {
    "eval", "lagrange", "jvp(q only)", "jvp(groups)", "hessian",
    "hessian_cols", "hvp", "gradient", "vjp", "taylor2", "jacobian"};

/* ---- 3. chunking ------------------------------------------------------ */

static void chunking(tp_tape *T, const shape *sh, const char *name)
{
    static const int dirs[3] = {1, 2, 3};
    tp_ws *wide = NULL, *ws = NULL;
    rng g = rng_seed(0x7e91a003u);
    double a[RESMAX], b[RESMAX];
    call c;
    int d, k, kind, na, nb;

    CHECK_INT(tp_ws_new(&wide, T, sh->n, NULL), TP_OK);
    for (d = 0; d < 3 && wide; d++) {
        CHECK_INT(tp_ws_new(&ws, T, dirs[d], NULL), TP_OK);
        if (!ws)
            break;
        for (k = 0; k < 3; k++) {
            for (kind = 0; kind < C_KINDS; kind++) {
                char ctx[96];
                random_call(&g, sh, &c);
                c.kind = kind;
                if (kind == C_JVP_Q || kind == C_JVP_GROUPS ||
                    kind == C_HVP)
                    c.p = PMAX; /* more directions than max_dirs */
                if (kind == C_JVP_GROUPS || kind == C_HVP)
                    seed(&g, sh, 7u, c.p, c.S);
                if (kind == C_HESS_COLS || kind == C_JACOBIAN) {
                    c.first = 1;
                    c.count = sh->n - 1;
                }
                snprintf(ctx, sizeof ctx, "%s max_dirs %d: %s", name,
                         dirs[d], kind_name[kind]);
                na = do_call(ws, sh, &c, a);
                nb = do_call(wide, sh, &c, b);
                CHECK_INT(na, nb);
                CHECK_VEC(ctx, a, b, na, 1e-15);
            }
        }
        tp_ws_free(&ws);
    }
    tp_ws_free(&wide);
}

/* ---- 4. alternating sweeps on one workspace --------------------------- */

static void alternation(tp_tape *T, const shape *sh, int max_dirs,
                        uint64_t seed_, const char *name)
{
    tp_ws *ws = NULL, *fresh = NULL;
    rng g = rng_seed(seed_);
    double a[RESMAX], b[RESMAX];
    call c;
    int k, na, nb;

    CHECK_INT(tp_ws_new(&ws, T, max_dirs, NULL), TP_OK);
    if (!ws)
        return;
    for (k = 0; k < 500; k++) {
        char ctx[96];
        random_call(&g, sh, &c);
        snprintf(ctx, sizeof ctx, "%s max_dirs %d call %d: %s", name,
                 max_dirs, k, kind_name[c.kind]);
        na = do_call(ws, sh, &c, a);
        CHECK_INT(tp_ws_new(&fresh, T, max_dirs, NULL), TP_OK);
        if (!fresh)
            break;
        nb = do_call(fresh, sh, &c, b);
        tp_ws_free(&fresh);
        CHECK_INT(na, nb);
        CHECK_SAME(ctx, a, b, na);
    }
    tp_ws_free(&ws);
}

int main(void)
{
    static const unsigned char pend_groups[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    chain4 c;
    tp_tape *Tp, *Tm;
    shape sp = {8, 3, pend_groups}, sm = {6, 6, mix_groups};

    replay_points();
    parameters();

    chain4_init(&c);
    Tp = record(8, pend_groups, pendulum_chain_record, &c.pc);
    Tm = record(6, mix_groups, mix_record, NULL);
    if (Tp && Tm) {
        CHECK_INT(tp_tape_n_outputs(Tm), sm.m);
        chunking(Tp, &sp, "pendulum");
        chunking(Tm, &sm, "mix");
        alternation(Tp, &sp, 2, 0x7e91a004u, "pendulum");
        alternation(Tp, &sp, 5, 0x7e91a005u, "pendulum");
        alternation(Tm, &sm, 1, 0x7e91a006u, "mix");
        alternation(Tm, &sm, 3, 0x7e91a007u, "mix");
    }
    tp_tape_free(&Tp);
    tp_tape_free(&Tm);
    CHECK_DONE();
}
