/* test_tape_opt.c - what recording and finalization do to a tape
 * (white-box: reads the finished tape's arrays).
 *
 *   - hash-consing: an expression recorded twice is one op; a + b and
 *     b + a are one op (likewise *, hypot), a - b and b - a are two (likewise
 *     atan2, pow); equal constants are one pool entry; a large recording
 *     exercises the hash table's growth;
 *   - constant folding: ops on constants become one constant with the
 *     value libm gives; ops on parameters are never folded;
 *   - dead-code elimination: the counters of tp_tape_stats_get and the
 *     tape itself (no op that reaches no output survives);
 *   - the tape's invariants (operands precede their op, leaves first),
 *     and a workspace's per-op records equal to the tape's op arrays;
 *   - dependency analysis: tp_tape_count_dependent agrees with groups
 *     derived here from the tape's structure, the pendulum's sin/cos of q
 *     depend on group 0 only, and an op outside a group does not move when
 *     that group's independents do;
 *   - size: at most 16 bytes per op for the pendulum tape, and op count
 *     and bytes grow linearly with the number of links.
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "pendulum_chain.h"
#include "support_rng.h"
#include "tape_internal.h"

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

static tp_tape_stats stats(const tp_tape *T)
{
    tp_tape_stats st;
    memset(&st, 0, sizeof st);
    CHECK_INT(tp_tape_stats_get(T, &st), TP_OK);
    return st;
}

static int n_slot_operands(unsigned op)
{
    switch (tp__opinfo[op].kind) {
    case TP_KIND_LEAF: return 0;
    case TP_KIND_BINARY: return 2;
    default: return 1;
    }
}

/* Group masks of every op, derived here from the tape's structure:
 * INDEP i has bit group[i], PARAM and CONST none, others the union of
 * their operands'. */
static unsigned char *derive_deps(const tp_tape *T)
{
    unsigned char *d = calloc(T->n_ops ? T->n_ops : 1, 1);
    uint32_t i;
    if (!d)
        return NULL;
    for (i = 0; i < T->n_ops; i++) {
        const unsigned op = T->opc[i];
        const int k = n_slot_operands(op);
        if (op == TP_OP_INDEP)
            d[i] = (unsigned char)(1u << T->group[T->a0[i]]);
        if (k >= 1)
            d[i] |= d[T->a0[i]];
        if (k == 2)
            d[i] |= d[T->a1[i]];
    }
    return d;
}

/* The invariants of a finished tape (tape_internal.h), and the agreement
 * of tp_tape_count_dependent with derive_deps for every group mask. */
static void check_tape(const tp_tape *T, const char *ctx)
{
    unsigned char *d = derive_deps(T), *reach;
    const tp_tape_stats st = stats(T);
    uint32_t i, o;
    unsigned mask;
    int bad_order = 0, bad_leaf = 0, unreached = 0, bad_rec = 0;
    tp_ws *ws = NULL;

    reach = calloc(T->n_ops ? T->n_ops : 1, 1);
    CHECK(d && reach);
    if (!d || !reach)
        goto done;
    CHECK_INT(st.n_ops, T->n_ops);
    CHECK_INT(st.n_consts, T->n_const);
    CHECK_INT(st.n_recorded - st.n_dead, st.n_ops);
    for (i = 0; i < T->n_ops; i++) {
        const unsigned op = T->opc[i];
        const int k = n_slot_operands(op);
        if (op >= TP_OP_COUNT) {
            bad_order++;
            continue;
        }
        if ((k >= 1 && T->a0[i] >= i) || (k == 2 && T->a1[i] >= i))
            bad_order++;
        if ((i < T->n_indep) != (op == TP_OP_INDEP) ||
            ((i >= T->n_indep && i < T->n_indep + T->n_param) !=
             (op == TP_OP_PARAM)) ||
            (op == TP_OP_INDEP && T->a0[i] != i) ||
            (op == TP_OP_CONST && T->a0[i] >= T->n_const) ||
            (tp__opinfo[op].kind == TP_KIND_UCONST &&
             T->a1[i] >= T->n_const))
            bad_leaf++;
    }
    /* every op but INDEP and PARAM reaches an output */
    for (o = 0; o < T->n_out; o++)
        if (T->out_slot[o] < T->n_ops)
            reach[T->out_slot[o]] = 1;
    for (i = T->n_ops; i-- > 0;) {
        const int k = n_slot_operands(T->opc[i]);
        if (!reach[i])
            continue;
        if (k >= 1)
            reach[T->a0[i]] = 1;
        if (k == 2)
            reach[T->a1[i]] = 1;
    }
    for (i = T->n_indep + T->n_param; i < T->n_ops; i++)
        unreached += !reach[i];
    if (bad_order || bad_leaf || unreached)
        CHECK_FAIL_("%s: %d ops out of order, %d misplaced leaves, %d dead "
                    "ops on the tape", ctx, bad_order, bad_leaf, unreached);
    check_count_++;
    /* a workspace's per-op records, which the sweeps read, repeat the
     * tape's arrays exactly (sin and cos pairing and the passive-operand
     * flags included) */
    CHECK_INT(tp_ws_new(&ws, T, 1, NULL), TP_OK);
    for (i = 0; ws && i < T->n_ops; i++)
        if (ws->rec[i].op != T->opc[i] || ws->rec[i].fl != T->dep[i] ||
            ws->rec[i].u != T->a0[i] || ws->rec[i].t != T->a1[i])
            bad_rec++;
    tp_ws_free(&ws);
    if (bad_rec)
        CHECK_FAIL_("%s: %d per-op records differ from the op arrays", ctx,
                    bad_rec);
    check_count_++;
    /* dependency counts */
    for (mask = 0; mask < 8; mask++) {
        size_t c = 0;
        for (i = 0; i < T->n_ops; i++)
            c += mask ? (d[i] & mask) != 0 : d[i] == 0;
        if (tp_tape_count_dependent(T, mask) != c)
            CHECK_FAIL_("%s: tp_tape_count_dependent(mask %u) = %zu, "
                        "derived %zu", ctx, mask,
                        tp_tape_count_dependent(T, mask), c);
        check_count_++;
    }
    CHECK_INT(st.n_passive, tp_tape_count_dependent(T, 0));
done:
    free(d);
    free(reach);
}

/* ---- hash-consing ----------------------------------------------------- */

typedef struct cse_case {
    int twice;   /* record the expression a second time */
    int variant; /* which second expression */
} cse_case;

static int cse_fn(tp_rec *r, void *user)
{
    const cse_case *c = user;
    tp_val a = tp_indep(r, 0), b = tp_indep(r, 1);
    tp_val e1 = tp_mul(r, tp_sin(r, a), tp_addc(r, b, 0.5));
    tp_val e2 = e1;
    tp_output(r, "e1", e1);
    if (!c->twice)
        return 0;
    switch (c->variant) {
    case 0: e2 = tp_mul(r, tp_sin(r, a), tp_addc(r, b, 0.5)); break;
    case 1: e2 = tp_mul(r, tp_addc(r, b, 0.5), tp_sin(r, a)); break;
    case 2: e2 = tp_add(r, a, b); tp_output(r, "x", tp_add(r, b, a)); break;
    case 3: e2 = tp_hypot(r, a, b); tp_output(r, "x", tp_hypot(r, b, a));
        break;
    case 4: e2 = tp_sub(r, a, b); tp_output(r, "x", tp_sub(r, b, a)); break;
    case 5: e2 = tp_atan2(r, a, b); tp_output(r, "x", tp_atan2(r, b, a));
        break;
    case 6: e2 = tp_pow(r, a, b); tp_output(r, "x", tp_pow(r, b, a)); break;
    case 7: /* equal constants share one CONST op and pool entry */
        e2 = tp_mul(r, tp_const(r, 2.5), tp_hypot(r, a, tp_const(r, 2.5)));
        tp_output(r, "x", tp_atan2(r, tp_const(r, 2.5), a));
        break;
    default: e2 = tp_mulc(r, a, 0.5); tp_output(r, "x", tp_mulc(r, a, 0.5));
        break;
    }
    tp_output(r, "e2", e2);
    return 0;
}

/* Many distinct ops, recorded twice: the second pass must find them all. */
static int big_fn(tp_rec *r, void *user)
{
    const int n = *(const int *)user;
    tp_val a = tp_indep(r, 0), b = tp_indep(r, 1), s = a;
    int pass, i;
    for (pass = 0; pass < 2; pass++) {
        s = a;
        for (i = 0; i < n; i++)
            s = tp_add(r, tp_mulc(r, s, 1.0 + i * 1e-3), b);
    }
    tp_output(r, "s", s);
    return 0;
}

static void hash_consing(void)
{
    cse_case c0 = {0, 0}, c;
    tp_tape *T0 = record(2, NULL, cse_fn, &c0), *T;
    tp_tape_stats s0, s;
    int v, n_big = 3000;
    if (!T0)
        return;
    s0 = stats(T0);
    check_tape(T0, "cse base");
    for (v = 0; v <= 8; v++) {
        char ctx[32];
        c.twice = 1;
        c.variant = v;
        T = record(2, NULL, cse_fn, &c);
        if (!T)
            continue;
        snprintf(ctx, sizeof ctx, "cse variant %d", v);
        check_tape(T, ctx);
        s = stats(T);
        switch (v) {
        case 0:
        case 1: /* the same product, in either order: no new op */
            CHECK_INT(s.n_ops, s0.n_ops);
            CHECK_INT(T->out_slot[0], T->out_slot[1]);
            CHECK(s.n_cse_hits >= s0.n_cse_hits + 3);
            break;
        case 2:
        case 3: /* commutative: one new op for both orders */
            CHECK_INT(s.n_ops, s0.n_ops + 1);
            CHECK_INT(T->out_slot[1], T->out_slot[2]);
            break;
        case 4:
        case 5:
        case 6: /* not commutative: two new ops */
            CHECK_INT(s.n_ops, s0.n_ops + 2);
            CHECK(T->out_slot[1] != T->out_slot[2]);
            break;
        case 7: /* one CONST op, one pool entry for 2.5 (and 0.5) */
            CHECK_INT(s.n_consts, 2);
            {
                uint32_t i, n_const_ops = 0;
                for (i = 0; i < T->n_ops; i++)
                    n_const_ops += T->opc[i] == TP_OP_CONST;
                CHECK_INT(n_const_ops, 1);
            }
            break;
        default: /* MULC by the same constant: one op */
            CHECK_INT(s.n_ops, s0.n_ops + 1);
            CHECK_INT(T->out_slot[1], T->out_slot[2]);
            break;
        }
        tp_tape_free(&T);
    }
    tp_tape_free(&T0);

    T = record(2, NULL, big_fn, &n_big);
    if (T) {
        s = stats(T);
        check_tape(T, "cse big");
        /* per pass: s * 1.0 is s itself, then n ADD and n - 1 MULC */
        CHECK_INT(s.n_ops, 2 + 2 * (size_t)n_big - 1);
        CHECK_INT(s.n_cse_hits, 2 * (size_t)n_big - 1);
        CHECK_INT(s.n_consts, (size_t)n_big - 1);
    }
    tp_tape_free(&T);
}

/* ---- constant folding ------------------------------------------------- */

static int fold_fn(tp_rec *r, void *user)
{
    tp_val a = tp_indep(r, 0), p = tp_param(r, "p", 0.25);
    tp_val c1 = tp_const(r, 0.7), c2 = tp_const(r, -1.3);
    (void)user;
    tp_output(r, "folded",
              tp_add(r, tp_mul(r, tp_sin(r, c1), tp_exp(r, c2)),
                     tp_powi(r, tp_atan2(r, c1, c2), 3)));
    tp_output(r, "param", tp_sin(r, tp_mulc(r, p, 3.0)));
    tp_output(r, "mixed", tp_mul(r, a, tp_sqrt(r, tp_hypot(r, c1, c2))));
    return 0;
}

static void folding(void)
{
    tp_tape *T = record(1, NULL, fold_fn, NULL);
    tp_tape_stats s;
    tp_ws *ws = NULL;
    const double folded =
        sin(0.7) * exp(-1.3) + pow(atan2(0.7, -1.3), 3.0);
    double x[1] = {1.5}, y[3];
    uint32_t i;
    int n_sin = 0;
    if (!T)
        return;
    check_tape(T, "folding");
    s = stats(T);
    CHECK(s.n_folded >= 7);
    /* "folded" is a constant with the value of the expression */
    CHECK_INT(T->opc[T->out_slot[0]], TP_OP_CONST);
    /* the parameter's ops stay (they may change between replays), the
     * constant factor of "mixed" is one constant */
    CHECK_INT(T->opc[T->out_slot[1]], TP_OP_SIN);
    CHECK_INT(T->opc[T->out_slot[2]], TP_OP_MULC);
    for (i = 0; i < T->n_ops; i++)
        n_sin += T->opc[i] == TP_OP_SIN;
    CHECK_INT(n_sin, 1);
    /* INDEP, PARAM, CONST, MULC(p), SIN, MULC(a) */
    CHECK_INT(s.n_ops, 6);
    CHECK_INT(s.n_passive, 4);
    CHECK_INT(tp_ws_new(&ws, T, 1, NULL), TP_OK);
    if (ws) {
        CHECK_INT(tp_eval(ws, x, y), TP_OK);
        CHECK_NEAR(y[0], folded, 1e-15);
        CHECK_NEAR(y[1], sin(0.75), 1e-15);
        CHECK_NEAR(y[2], 1.5 * sqrt(hypot(0.7, -1.3)), 1e-15);
        CHECK_INT(tp_ws_set_param(ws, 0, 0.5), TP_OK);
        CHECK_INT(tp_eval(ws, x, y), TP_OK);
        CHECK_NEAR(y[1], sin(1.5), 1e-15);
    }
    tp_ws_free(&ws);
    tp_tape_free(&T);
}

/* ---- dead-code elimination -------------------------------------------- */

static int dead_fn(tp_rec *r, void *user)
{
    tp_val a = tp_indep(r, 0), b = tp_indep(r, 1), d;
    (void)user;
    tp_param(r, "unused", 1.0);             /* kept: parameters stay */
    d = tp_exp(r, a);                       /* dead from here ... */
    d = tp_sin(r, d);
    d = tp_addc(r, d, 7.0);
    d = tp_mul(r, d, b);
    d = tp_add(r, d, tp_const(r, 9.0));     /* ... to here */
    (void)d;
    tp_output(r, "y", tp_mul(r, a, b));
    return 0;
}

static void dead_code(void)
{
    tp_tape *T = record(2, NULL, dead_fn, NULL);
    tp_tape_stats s;
    if (!T)
        return;
    check_tape(T, "dead code");
    s = stats(T);
    /* INDEP x2, PARAM, MUL remain; the chain and its constants are gone */
    CHECK_INT(s.n_ops, 4);
    CHECK_INT(s.n_consts, 0);
    CHECK(s.n_dead >= 6);
    CHECK_INT(s.n_recorded, s.n_ops + s.n_dead);
    CHECK_INT(tp_tape_n_params(T), 1);
    CHECK_INT(T->opc[T->out_slot[0]], TP_OP_MUL);
    tp_tape_free(&T);
}

/* ---- the pendulum: dependencies and size ------------------------------ */

static tp_tape *pendulum(int n, const double *m, const double *l)
{
    unsigned char grp[256];
    pendulum_chain pc;
    int i;
    for (i = 0; i < n; i++) {
        grp[i] = 0;
        grp[n + i] = 1;
    }
    pc.n = n;
    pc.m = m;
    pc.l = l;
    pc.g = 9.81;
    return record(2 * n, grp, pendulum_chain_record, &pc);
}

static void pendulum_deps(void)
{
    const int n = 6;
    tp_tape *T = pendulum(n, NULL, NULL);
    tp_ws *ws = NULL;
    unsigned char *d = NULL;
    rng g = rng_seed(0x0b7a0001u);
    double x[12], x2[12], y[3], *v1 = NULL;
    uint32_t i;
    int k, n_trig = 0, moved_q_only = 0, moved_qd_only = 0;
    if (!T)
        return;
    check_tape(T, "pendulum");
    d = derive_deps(T);
    CHECK_INT(tp_ws_new(&ws, T, 1, NULL), TP_OK);
    v1 = malloc(T->n_ops * sizeof(double));
    if (!d || !ws || !v1)
        goto done;
    /* sin q_i and cos q_i: group 0 only, one of each per link */
    for (i = 0; i < T->n_ops; i++) {
        if (T->opc[i] == TP_OP_SIN || T->opc[i] == TP_OP_COS) {
            n_trig++;
            CHECK_INT(d[i], 1);
            CHECK(T->a0[i] < (uint32_t)n);
        }
    }
    CHECK_INT(n_trig, 2 * n);
    CHECK(tp_tape_count_dependent(T, 1u) > (size_t)(2 * n));
    CHECK(tp_tape_count_dependent(T, 2u) > (size_t)n);
    CHECK(tp_tape_count_dependent(T, 0u) > 0); /* functions of m, l, g */
    /* ops only on q do not move with qd, and vice versa */
    for (k = 0; k < 4; k++) {
        for (i = 0; i < 12; i++)
            x[i] = x2[i] = rng_range(&g, -2.0, 2.0);
        for (i = 0; i < 12; i++)
            if ((k % 2 == 0) == (i >= (uint32_t)n))
                x2[i] += rng_range(&g, 0.1, 1.0);
        CHECK_INT(tp_eval(ws, x, y), TP_OK);
        memcpy(v1, ws->v, T->n_ops * sizeof(double));
        CHECK_INT(tp_eval(ws, x2, y), TP_OK);
        for (i = 0; i < T->n_ops; i++) {
            const unsigned moved = k % 2 == 0 ? 2u : 1u;
            if (!(d[i] & moved) && v1[i] != ws->v[i]) {
                CHECK_FAIL_("pendulum op %u (%s, groups %u) moved with "
                            "group %u", (unsigned)i,
                            tp__opinfo[T->opc[i]].name, d[i], moved - 1);
            }
            check_count_++;
            if (d[i] == 1 && v1[i] != ws->v[i])
                moved_q_only += k % 2;
            if (d[i] == 2 && v1[i] != ws->v[i])
                moved_qd_only += (k + 1) % 2;
        }
    }
    /* and the test is not vacuous */
    CHECK(moved_q_only > 0 && moved_qd_only > 0);
done:
    free(v1);
    free(d);
    tp_ws_free(&ws);
    tp_tape_free(&T);
}

static size_t pendulum_ops(int n, size_t *bytes)
{
    double m[64], l[64];
    tp_tape *T;
    tp_tape_stats s;
    int i;
    for (i = 0; i < n; i++) {
        m[i] = 1.0 + 0.1 * i;
        l[i] = 2.0 - 0.02 * i;
    }
    T = pendulum(n, m, l);
    if (!T)
        return 0;
    s = stats(T);
    tp_tape_free(&T);
    if (bytes)
        *bytes = s.bytes;
    return s.n_ops;
}

static void pendulum_size(void)
{
    size_t ops[17], bytes[17], i;
    for (i = 1; i <= 16; i++) {
        ops[i] = pendulum_ops((int)i, &bytes[i]);
        if (bytes[i] > 16 * ops[i])
            CHECK_FAIL_("pendulum with %zu links: %zu bytes for %zu ops",
                        i, bytes[i], ops[i]);
        check_count_++;
    }
    /* each link after the second adds the same number of ops (the first
     * link's joint-velocity sums start from constant zeros, which the
     * recorder folds away) */
    for (i = 4; i <= 16; i++)
        CHECK_INT(ops[i] - ops[i - 1], ops[3] - ops[2]);
    CHECK(ops[2] - ops[1] <= ops[3] - ops[2]);
    /* and doubling: growth linear, not quadratic (which would give a
     * ratio of about 4 between successive differences) */
    {
        const size_t a = pendulum_ops(8, NULL), b = pendulum_ops(16, NULL),
                     c = pendulum_ops(32, NULL);
        const long d1 = (long)(b - a), d2 = (long)(c - b);
        CHECK(labs(d2 - 2 * d1) <= 2);
    }
}

int main(void)
{
    hash_consing();
    folding();
    dead_code();
    pendulum_deps();
    pendulum_size();
    CHECK_DONE();
}
