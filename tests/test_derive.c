/* test_derive.c - derivative tapes of a Lagrangian (tp_call, tp_call_jvp,
 * tp_call_vjp), public API only. The op-by-op checks are in
 * test_conformance.c (g); this file checks what libeom builds from them.
 *
 *   1. For the N-link pendulum chain (N = 3, 8, 16), the gradient tape
 *      of L (tp_call_vjp) and from it the Lagrange residual tape
 *          r(q, qd, qdd) = d/dt (dL/dqd) - dL/dq
 *                        = M qdd + (d2L/dqd dq) qd - dL/dq
 *      (tp_call_jvp of the gradient tape along (qd, qdd)):
 *        - r against M qdd + h - g from tp_lagrange (a second route);
 *        - its Jacobian over (q, qd, qdd), third derivatives of L,
 *          against central differences of that route (1e-7) and
 *          against the tuple engine running the same calls (1e-12);
 *        - its qdd block equal to the closed-form mass matrix;
 *        - the derivative tapes grow linearly: their size over L's is
 *          bounded and no larger at N = 16 than at N = 3 (+20 %).
 *   2. Misuse: NULL tape, inputs, weights and results; handles of another
 *      context and invalid ones; an evaluator outside a run; each named
 *      in the context's message, nothing recorded.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "pendulum_chain.h"
#include "support_num.h"
#include "support_rng.h"
#include "support_tape.h"

#define NMAX 16

typedef struct chain_tapes {
    pendulum_chain pc;
    tp_tape *L, *G, *R; /* Lagrangian, its gradient, the residual */
} chain_tapes;

/* Gradient tape: x = (q, qd), outputs dL/dq then dL/dqd. */
static int rec_gradient(tp_rec *r, void *user)
{
    const chain_tapes *c = user;
    const int n2 = 2 * c->pc.n;
    tp_val x[2 * NMAX], w, g[2 * NMAX];
    char name[16];
    int i;
    for (i = 0; i < n2; i++)
        x[i] = tp_indep(r, i);
    w = tp_const(r, 1.0);
    /* the L tape has outputs L, T, V: weight L alone */
    {
        tp_val wv[3];
        int o, nout = tp_tape_n_outputs(c->L);
        for (o = 0; o < nout; o++)
            wv[o] = o == tp_tape_output_index(c->L, "L") ? w
                                                          : tp_const(r, 0.0);
        if (tp_call_vjp(r, c->L, x, NULL, wv, NULL, g, NULL) != TP_OK)
            return 1;
    }
    for (i = 0; i < n2; i++) {
        snprintf(name, sizeof name, "g%d", i);
        tp_output(r, name, g[i]);
    }
    return 0;
}

/* Residual tape: x = (q, qd, qdd), outputs r_i. */
static int rec_residual(tp_rec *r, void *user)
{
    const chain_tapes *c = user;
    const int n = c->pc.n;
    tp_val x[3 * NMAX] = {{0, 0}}, g[2 * NMAX], dg[2 * NMAX];
    char name[16];
    int i;
    for (i = 0; i < 3 * n; i++)
        x[i] = tp_indep(r, i);
    /* d/dt of (dL/dq, dL/dqd) along qdot = qd, qddot = qdd */
    if (tp_call_jvp(r, c->G, x, NULL, x + n, NULL, g, dg) != TP_OK)
        return 1;
    for (i = 0; i < n; i++) {
        snprintf(name, sizeof name, "r%d", i);
        tp_output(r, name, tp_sub(r, dg[n + i], g[i]));
    }
    return 0;
}

static tp_tape *record(int n_indep, const unsigned char *groups, tp_func f,
                       void *user)
{
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    CHECK_INT(tp_recorder_new(&r, n_indep, groups, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, f, user), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &t), TP_OK);
    tp_rec_free(&r);
    return t;
}

/* The second route: r = M qdd + h - g from tp_lagrange. */
typedef struct route {
    tp_ws *ws;
    int n, outL;
} route;

static int residual_by_blocks(void *ctx, const double *x, double *res)
{
    const route *rt = ctx;
    double g[NMAX], M[NMAX * NMAX], h[NMAX];
    int i, j, n = rt->n;
    if (tp_lagrange(rt->ws, x, rt->outL, NULL, g, M, h) != TP_OK)
        return -1;
    for (i = 0; i < n; i++) {
        res[i] = h[i] - g[i];
        for (j = 0; j < n; j++)
            res[i] += M[i * n + j] * x[2 * n + j];
    }
    return 0;
}

static size_t ops(const tp_tape *t)
{
    tp_tape_stats st;
    CHECK_INT(tp_tape_stats_get(t, &st), TP_OK);
    return st.n_ops;
}

static void chain(int n, double *grow_g, double *grow_r)
{
    unsigned char grp[3 * NMAX];
    chain_tapes c;
    route rt;
    tp_ws *wr = NULL;
    tp_rec *tu = NULL;
    rng gen = rng_seed(0xde41u + (unsigned)n);
    double x[3 * NMAX], res[NMAX], ref[NMAX], J[NMAX * 3 * NMAX];
    double Jfd[NMAX * 3 * NMAX], Jtu[NMAX * 3 * NMAX], M[NMAX * NMAX];
    double Mt[NMAX * NMAX], ytu[NMAX];
    char ctx[64];
    int i, j;

    memset(&c, 0, sizeof c);
    c.pc.n = n;
    c.pc.g = 9.81;
    for (i = 0; i < 3 * n; i++)
        grp[i] = (unsigned char)(i / n);
    c.L = record(2 * n, grp, pendulum_chain_record, &c.pc);
    c.G = c.L ? record(2 * n, grp, rec_gradient, &c) : NULL;
    c.R = c.G ? record(3 * n, grp, rec_residual, &c) : NULL;
    if (!c.R)
        goto done;
    snprintf(ctx, sizeof ctx, "chain N=%d", n);
    *grow_g = (double)ops(c.G) / (double)ops(c.L);
    *grow_r = (double)ops(c.R) / (double)ops(c.L);
    printf("%s: ops L %zu, gradient %zu (%.2fx), residual %zu (%.2fx)\n",
           ctx, ops(c.L), ops(c.G), *grow_g, ops(c.R), *grow_r);

    CHECK_INT(tp_ws_new(&rt.ws, c.L, n, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&wr, c.R, 3 * n, NULL), TP_OK);
    CHECK_INT(tp_tuple_new(&tu, 3 * n, NULL), TP_OK);
    rt.n = n;
    rt.outL = tp_tape_output_index(c.L, "L");
    for (i = 0; i < 3 * n; i++)
        x[i] = rng_range(&gen, -1.5, 1.5);

    CHECK_INT(tp_eval(wr, x, res), TP_OK);
    CHECK_INT(residual_by_blocks(&rt, x, ref), 0);
    CHECK_VEC_SCALED(ctx, res, ref, n, num_max_abs(ref, n) + 1.0, 1e-13);

    CHECK_INT(tp_jacobian(wr, x, 0, 3 * n, NULL, J), TP_OK);
    CHECK_INT(num_fd_jac(residual_by_blocks, &rt, 3 * n, n, x, 1e-4, Jfd),
              0);
    CHECK_VEC(ctx, J, Jfd, n * 3 * n, 1e-7);
    CHECK_INT(st_tuple(tu, x, rec_residual, &c, ytu, Jtu, NULL), TP_OK);
    CHECK_VEC_SCALED(ctx, J, Jtu, n * 3 * n,
                     num_max_abs(Jtu, n * 3 * n) + 1.0, 1e-12);
    pendulum_chain_mass(&c.pc, x, M);
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++)
            Mt[i * n + j] = J[i * 3 * n + 2 * n + j];
    CHECK_VEC_SCALED(ctx, Mt, M, n * n, num_max_abs(M, n * n), 1e-13);

    tp_rec_free(&tu);
    tp_ws_free(&wr);
    tp_ws_free(&rt.ws);
done:
    tp_tape_free(&c.R);
    tp_tape_free(&c.G);
    tp_tape_free(&c.L);
}

/* ---- misuse ------------------------------------------------------------ */

typedef struct misuse {
    const tp_tape *t;
    int which;
    int rc;
} misuse;

static int simple(tp_rec *r, void *user)
{
    (void)user;
    tp_output(r, "f", tp_mul(r, tp_sin(r, tp_indep(r, 0)),
                             tp_param(r, "k", 2.0)));
    return 0;
}

static int misuse_fn(tp_rec *r, void *user)
{
    misuse *m = user;
    tp_val x[1], bad[1], y[1], g[1], zero = {0, 0};
    x[0] = tp_indep(r, 0);
    bad[0] = zero;
    switch (m->which) {
    case 0: m->rc = tp_call(r, NULL, x, NULL, y); break;
    case 1: m->rc = tp_call(r, m->t, NULL, NULL, y); break;
    case 2: m->rc = tp_call(r, m->t, x, NULL, NULL); break;
    case 3: m->rc = tp_call(r, m->t, bad, NULL, y); break;
    case 4: m->rc = tp_call_jvp(r, m->t, x, NULL, bad, NULL, y, g); break;
    case 5: m->rc = tp_call_jvp(r, m->t, x, NULL, x, NULL, y, NULL); break;
    case 6: m->rc = tp_call_vjp(r, m->t, x, NULL, NULL, y, g, NULL); break;
    case 7: m->rc = tp_call_vjp(r, m->t, x, NULL, x, y, NULL, NULL); break;
    case 8: m->rc = tp_call_vjp(r, m->t, x, bad, x, y, g, NULL); break;
    default: break;
    }
    tp_output(r, "out", x[0]);
    return 0;
}

static int foreign_fn(tp_rec *r, void *user)
{
    misuse *m = user;
    tp_rec *other = NULL;
    tp_val x[1], y[1];
    tp_recorder_new(&other, 1, NULL, NULL);
    x[0] = tp_indep(other, 0);
    m->rc = tp_call(r, m->t, x, NULL, y);
    tp_rec_free(&other);
    return 0;
}

static void misuse_checks(void)
{
    static const int expect[] = {TP_ERR_NULL, TP_ERR_NULL, TP_ERR_NULL,
                                 TP_ERR_HANDLE, TP_ERR_HANDLE, TP_ERR_NULL,
                                 TP_ERR_NULL, TP_ERR_NULL, TP_ERR_HANDLE};
    static const char *const fn[] = {"tp_call", "tp_call", "tp_call",
                                     "tp_call", "tp_call_jvp",
                                     "tp_call_jvp", "tp_call_vjp",
                                     "tp_call_vjp", "tp_call_vjp"};
    tp_rec *r = NULL, *ev = NULL;
    tp_tape *t = NULL;
    tp_val x[1], y[1];
    misuse m;
    double one = 1.0;
    int k;

    CHECK_INT(tp_recorder_new(&r, 1, NULL, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, simple, NULL), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &t), TP_OK);
    tp_rec_free(&r);
    if (!t)
        return;
    m.t = t;
    for (k = 0; k < (int)(sizeof expect / sizeof expect[0]); k++) {
        m.which = k;
        m.rc = TP_OK;
        CHECK_INT(tp_recorder_new(&r, 1, NULL, NULL), TP_OK);
        CHECK_INT(tp_rec_run(r, NULL, misuse_fn, &m), expect[k]);
        CHECK_INT(m.rc, expect[k]);
        CHECK_INT(tp_rec_status(r), expect[k]);
        if (!strstr(tp_rec_errmsg(r), fn[k]))
            CHECK_FAIL_("case %d: message '%s' does not name %s", k,
                        tp_rec_errmsg(r), fn[k]);
        tp_rec_free(&r);
    }
    /* a handle of another context */
    CHECK_INT(tp_recorder_new(&r, 1, NULL, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, foreign_fn, &m), TP_ERR_FOREIGN);
    CHECK_INT(m.rc, TP_ERR_FOREIGN);
    tp_rec_free(&r);
    /* an evaluator outside a run, and a NULL context */
    CHECK_INT(tp_evaluator_new(&ev, 1, NULL), TP_OK);
    CHECK_INT(tp_rec_run(ev, &one, simple, NULL), TP_OK);
    x[0] = tp_indep(ev, 0);
    CHECK(tp_call(ev, t, x, NULL, y) < 0);
    tp_rec_free(&ev);
    CHECK_INT(tp_call(NULL, t, x, NULL, y), TP_ERR_NULL);
    tp_tape_free(&t);
}

int main(void)
{
    double g3 = 0, r3 = 0, g8 = 0, r8 = 0, g16 = 0, r16 = 0;
    chain(3, &g3, &r3);
    chain(8, &g8, &r8);
    chain(16, &g16, &r16);
    /* linear growth: a bounded factor, not rising with the model */
    CHECK(g3 > 1.0 && g3 < 6.0 && r3 > 1.0 && r3 < 20.0);
    CHECK(g16 <= 1.2 * g3 && r16 <= 1.2 * r3);
    CHECK(g8 <= 1.2 * g3 && r8 <= 1.2 * r3);
    misuse_checks();
    CHECK_DONE();
}
