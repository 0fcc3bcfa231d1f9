/* test_conformance.c - the op-table conformance suite (white-box).
 *
 * It loops over THE op table (tape_ops.h), so an op added there is tested
 * without touching this file. For every non-leaf op, every constant (UCONST
 * kind) or exponent (UINT kind) of a small list, and several operand shapes,
 * it records through tp__rec_op
 *     f = op(u, t),   g = f (1.5 + x1 / 4) + u x2
 * from four independents in two groups (x0, x1 in group 0; x2, x3 in
 * group 1). The operands u, t are a parameter plus a bilinear function of
 * the independents, so the Hessians have off-diagonal and mixed-group
 * entries; the parameters move the operands onto chosen values in the op's
 * domain (tp__opinfo[op].domain) without re-recording, including points at
 * the domain's edge. At every point:
 *   (a) first-order forward (tp_jacobian, tp_jvp) against central finite
 *       differences of the double evaluator;
 *   (b) reverse against forward, the dot-product test w'(J s) = (w'J) s;
 *   (c) tp_hvp against finite differences of the reverse gradient and
 *       against the embedded-tuple engine's Hessian;
 *   (d) tp_hessian symmetric and equal to the tuple Hessian;
 *   (e) every fast sweep against the reference interpreter tp__ref_*;
 *   (f) tp_taylor2's coefficients against J d and d' H d;
 *   (g) derivative tapes: T's reverse sweep recorded by tp_call_vjp and
 *       its tangent sweep by tp_call_jvp, finalized and swept: values
 *       against (b) and (a), Jacobians against the Hessians of (c), (d),
 *       parameter gradients against central differences; the same calls
 *       run on the double and tuple evaluators;
 * on workspaces with max_dirs 1, 3 and 4 (= n), so chunking is exercised.
 * Seeds include directions confined to one group, which exercises the
 * sweeps' dependency skipping.
 *
 * A second part runs every case on the compiled backend: all of them on
 * one tape (each with its own parameters, output 0 their sum), compiled
 * once with every sweep it has, against the interpreter at random points
 * inside each op's domain: values, gradients, the Lagrange block, the
 * Jacobian block and the Taylor sweep to 1e-14 relative.
 *
 * A third part checks the record-time rewrites (an op with a constant
 * operand becomes ADDC, MULC, CSUB, CDIV, POWC or POWI; x*0, x+0, x-x, x*x,
 * x+x, POWI with k = 0, 1, 2; constant folding): the opcode that lands on
 * the tape, and values and derivatives against the evaluators.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "support_num.h"
#include "support_rng.h"
#include "support_tape.h"
#include "tape_internal.h"

#define NI 4 /* independents */
#define NO 2 /* outputs: f, g */
#define NS 3 /* directions in the jvp, hvp and taylor tests */
#define NW 3 /* workspaces: max_dirs 1, 3, NI */
#define NRAND 10 /* random points per case, besides the edge points */

static const double PI_ = 3.14159265358979323846;
static const unsigned char groups[NI] = {0, 0, 1, 1};
static const int ws_dirs[NW] = {1, 3, NI};

/* Operand shapes: both operands on both groups; u on group 0 and t on
 * group 1 (a unary op then reads a group-1 operand); one operand a bare
 * parameter, i.e. passive (binary ops only); both operands the same slot
 * (binary ops only: op(u, u), which hash-consing produces whenever a
 * model writes the same expression twice; a sweep that treats the two
 * operands as distinct values gets its second derivatives wrong). */
enum shape { SH_MIXED, SH_SPLIT, SH_UPARAM, SH_TPARAM, SH_ALIAS, SH_COUNT };
static const char *const shape_name[SH_COUNT] = {"mixed", "split",
                                                 "u-param", "t-param",
                                                 "alias"};

/* Constants for UCONST ops and exponents for UINT ops; the special values
 * (0, 1, -1, 2) also reach the recorder's rewrites. */
static const double uconst_list[] = {0.0, 1.0, -1.0, 2.5, -0.75,
                                     1.0 / 3.0, 12.5};
static const int uint_list[] = {-3, -2, -1, 0, 1, 2, 3, 7};

typedef struct conf_case {
    int op;
    double c; /* constant (UCONST) or exponent (UINT) */
    int shape;
} conf_case;

/* ---- the recorded function ------------------------------------------- */

/* Bilinear operand functions; |gradient|_1 <= 3.5 on [-0.5, 0.5]^4 (used
 * to size finite-difference steps). Each has a plain double twin. */
static tp_val rec_g1(tp_rec *r, const tp_val *x)
{
    /* x0 + 0.7 x1 - 0.4 x2 + 0.3 x3 + 0.5 x0 x3 - 0.3 x1 x2 */
    tp_val s = tp_add(r, x[0], tp_mulc(r, x[1], 0.7));
    s = tp_add(r, s, tp_mulc(r, x[2], -0.4));
    s = tp_add(r, s, tp_mulc(r, x[3], 0.3));
    s = tp_add(r, s, tp_mulc(r, tp_mul(r, x[0], x[3]), 0.5));
    return tp_add(r, s, tp_mulc(r, tp_mul(r, x[1], x[2]), -0.3));
}

static double g1(const double *x)
{
    return x[0] + 0.7 * x[1] - 0.4 * x[2] + 0.3 * x[3] + 0.5 * x[0] * x[3] -
           0.3 * x[1] * x[2];
}

static tp_val rec_g2(tp_rec *r, const tp_val *x)
{
    /* -0.3 x0 + 0.6 x1 + 0.8 x2 - 0.5 x3 + 0.4 x0 x2 + 0.2 x1 x3 */
    tp_val s = tp_add(r, tp_mulc(r, x[0], -0.3), tp_mulc(r, x[1], 0.6));
    s = tp_add(r, s, tp_mulc(r, x[2], 0.8));
    s = tp_sub(r, s, tp_mulc(r, x[3], 0.5));
    s = tp_add(r, s, tp_mulc(r, tp_mul(r, x[0], x[2]), 0.4));
    return tp_add(r, s, tp_mulc(r, tp_mul(r, x[1], x[3]), 0.2));
}

static double g2(const double *x)
{
    return -0.3 * x[0] + 0.6 * x[1] + 0.8 * x[2] - 0.5 * x[3] +
           0.4 * x[0] * x[2] + 0.2 * x[1] * x[3];
}

/* group 0 only */
static tp_val rec_ga(tp_rec *r, const tp_val *x)
{
    /* 0.8 x0 - 0.5 x1 + 0.6 x0 x1 */
    return tp_add(r, tp_sub(r, tp_mulc(r, x[0], 0.8), tp_mulc(r, x[1], 0.5)),
                  tp_mulc(r, tp_mul(r, x[0], x[1]), 0.6));
}

static double ga(const double *x)
{
    return 0.8 * x[0] - 0.5 * x[1] + 0.6 * x[0] * x[1];
}

/* group 1 only */
static tp_val rec_gb(tp_rec *r, const tp_val *x)
{
    /* 0.5 x2 + 0.9 x3 - 0.4 x2 x3 */
    return tp_sub(r, tp_add(r, tp_mulc(r, x[2], 0.5), tp_mulc(r, x[3], 0.9)),
                  tp_mulc(r, tp_mul(r, x[2], x[3]), 0.4));
}

static double gb(const double *x)
{
    return 0.5 * x[2] + 0.9 * x[3] - 0.4 * x[2] * x[3];
}

static bool is_binary(int op)
{
    return tp__opinfo[op].kind == TP_KIND_BINARY;
}

/* Case cc's f and g at x, its operands offset by the parameters pu, pt. */
static void record_case(tp_rec *r, const tp_val *x, const conf_case *cc,
                        tp_val pu, tp_val pt, tp_val *f, tp_val *gout)
{
    tp_val u, t;
    switch (cc->shape) {
    case SH_SPLIT:
        u = tp_add(r, pu, is_binary(cc->op) ? rec_ga(r, x) : rec_gb(r, x));
        t = tp_add(r, pt, rec_gb(r, x));
        break;
    case SH_UPARAM:
        u = pu;
        t = tp_add(r, pt, rec_g2(r, x));
        break;
    case SH_TPARAM:
        u = tp_add(r, pu, rec_g1(r, x));
        t = pt;
        break;
    case SH_ALIAS:
        u = tp_add(r, pu, rec_g1(r, x));
        t = u;
        break;
    default:
        u = tp_add(r, pu, rec_g1(r, x));
        t = tp_add(r, pt, rec_g2(r, x));
        break;
    }
    *f = tp__rec_op(r, cc->op, u, t, cc->c);
    *gout = tp_add(r, tp_mul(r, *f, tp_addc(r, tp_mulc(r, x[1], 0.25), 1.5)),
                   tp_mul(r, u, x[2]));
}

static int conf_record(tp_rec *r, void *user)
{
    const conf_case *cc = user;
    tp_val x[NI], pu, pt, f, gout;
    int i;
    for (i = 0; i < NI; i++)
        x[i] = tp_indep(r, i);
    /* in this order: the parameters' indices on the tape */
    pu = tp_param(r, "cu", 0.5);
    pt = tp_param(r, "ct", 0.5);
    record_case(r, x, cc, pu, pt, &f, &gout);
    tp_output(r, "f", f);
    tp_output(r, "g", gout);
    return 0;
}

/* ---- sampling --------------------------------------------------------- */

/* Number of fixed edge points of a domain. */
static int n_edge(int dom)
{
    switch (dom) {
    case TP_DOM_UPOS: return 1;
    case TP_DOM_PAIR: return 1;
    default: return 2;
    }
}

/* Sample k of the operand values (u, t) in domain dom: the first n_edge
 * samples sit at the domain's edge, the rest are random. Returns the
 * distance to the nearest place where the op may stop being smooth, which
 * sizes the finite-difference step.
 * PAIR domains include atan2, whose value jumps across the negative t axis,
 * so angles stay 0.3 away from it and the distance accounts for it. */
static double sample(int dom, int k, rng *g, double *u, double *t)
{
    const bool edge = k < n_edge(dom);
    const double sgn = (k % 2) ? -1.0 : 1.0;
    double r, a;
    *u = rng_range(g, -2.0, 2.0);
    *t = rng_range(g, -2.0, 2.0);
    switch (dom) {
    case TP_DOM_UPOS:
        *u = edge ? 1e-3 : exp(rng_range(g, log(1e-3), log(5.0)));
        return *u;
    case TP_DOM_UNZ:
        *u = sgn * (edge ? 1e-3 : exp(rng_range(g, log(1e-2), log(3.0))));
        return fabs(*u);
    case TP_DOM_TNZ:
        *t = sgn * (edge ? 1e-3 : exp(rng_range(g, log(1e-2), log(3.0))));
        return fabs(*t);
    case TP_DOM_UNIT:
        *u = edge ? sgn * 0.99 : rng_range(g, -0.98, 0.98);
        return 1.0 - fabs(*u);
    case TP_DOM_TAN:
        *u = edge ? sgn * (PI_ / 2 - 0.05)
                  : rng_range(g, -(PI_ / 2 - 0.06), PI_ / 2 - 0.06);
        return PI_ / 2 - fabs(*u);
    case TP_DOM_PAIR:
        r = edge ? 1e-3 : exp(rng_range(g, log(1e-2), log(2.5)));
        a = rng_range(g, -PI_ + 0.3, PI_ - 0.3);
        *u = r * sin(a);
        *t = r * cos(a);
        return *t < 0.0 ? fmin(r, fabs(*u)) : r;
    default: /* ANY: the edge points are exact zeros */
        if (edge) {
            *u = 0.0;
            *t = k ? 0.0 : *t;
        }
        return 1.0;
    }
}

/* Sample k of case cc's operand values (u, t), as sample() draws them,
 * and the parameters pu, pt that put its operands there at x. Returns
 * the distance to the nearest place where the op may stop being smooth. */
static double place(const conf_case *cc, int k, rng *g, const double *x,
                    double *u, double *t, double *pu, double *pt)
{
    const int dom = tp__opinfo[cc->op].domain;
    double dist = sample(dom, k, g, u, t);
    switch (cc->shape) {
    case SH_SPLIT:
        *pu = *u - (is_binary(cc->op) ? ga(x) : gb(x));
        *pt = *t - gb(x);
        break;
    case SH_UPARAM:
        *pu = *u;
        *pt = *t - g2(x);
        break;
    case SH_TPARAM:
        *pu = *u - g1(x);
        *pt = *t;
        break;
    case SH_ALIAS:
        /* one value a for both operands, in every alias domain (nonzero,
         * and positive for a base) and not small: ops such as a/a and
         * atan2(a, a) are constant, so their derivatives are sums of
         * terms of size 1/a that cancel, and rounding in them must stay
         * below the checks' tolerances */
        *u = *t = (dom == TP_DOM_UPOS || k % 2 == 0 ? 1.0 : -1.0) *
                  rng_range(g, 0.5, 2.0);
        dist = 0.5;
        *pu = *u - g1(x);
        *pt = 0.5;
        break;
    default:
        *pu = *u - g1(x);
        *pt = *t - g2(x);
        break;
    }
    return dist;
}

/* ---- engines and finite-difference callbacks -------------------------- */

typedef struct engines {
    conf_case *cc;
    tp_tape *T;
    tp_tape *Tg, *Tt; /* derivative tapes of T (record_derived) */
    tp_ws *wg, *wt;
    tp_ws *ws[NW];
    tp_rec *ev, *tu;
    int kcu, kct;        /* parameter indices on the tape */
    double param[2];     /* parameter values by tape index */
    double w[NO];        /* output weights (fd_grad differentiates w'y) */
} engines;

static int fd_value(void *ctx, const double *x, double *y)
{
    engines *E = ctx;
    return st_eval(E->ev, x, conf_record, E->cc, y) == TP_OK ? 0
                                                                     : -1;
}

static int fd_grad(void *ctx, const double *x, double *g)
{
    engines *E = ctx;
    return tp_vjp(E->ws[NW - 1], x, E->w, NULL, g) == TP_OK ? 0 : -1;
}

static void set_params(engines *E, double pu, double pt)
{
    int k;
    for (k = 0; k < NW; k++) {
        CHECK_INT(tp_ws_set_param(E->ws[k], E->kcu, pu), TP_OK);
        CHECK_INT(tp_ws_set_param(E->ws[k], E->kct, pt), TP_OK);
    }
    CHECK_INT(tp_rec_set_param(E->ev, "cu", pu), TP_OK);
    CHECK_INT(tp_rec_set_param(E->ev, "ct", pt), TP_OK);
    CHECK_INT(tp_rec_set_param(E->tu, "cu", pu), TP_OK);
    CHECK_INT(tp_rec_set_param(E->tu, "ct", pt), TP_OK);
    CHECK_INT(tp_ws_set_param(E->wg, tp_tape_param_index(E->Tg, "cu"), pu),
              TP_OK);
    CHECK_INT(tp_ws_set_param(E->wg, tp_tape_param_index(E->Tg, "ct"), pt),
              TP_OK);
    CHECK_INT(tp_ws_set_param(E->wt, tp_tape_param_index(E->Tt, "cu"), pu),
              TP_OK);
    CHECK_INT(tp_ws_set_param(E->wt, tp_tape_param_index(E->Tt, "ct"), pt),
              TP_OK);
    E->param[E->kcu] = pu;
    E->param[E->kct] = pt;
}

/* sum_j |A_ij| |s_j| summed over i: the scale of the terms of A s. */
static double term_scale(int m, int n, const double *A, const double *s,
                         int lds)
{
    double sc = 0.0;
    int i, j;
    for (i = 0; i < m; i++)
        for (j = 0; j < n; j++)
            sc += fabs(A[i * n + j]) * fabs(s[j * lds]);
    return sc;
}

/* ---- derivative tapes (g) --------------------------------------------- */

/* The gradient tape of T: independents (x, w), outputs y (NO), w'J over x
 * (NI) and over the two parameters, recorded by tp_call_vjp. */
static int rec_gradient_tape(tp_rec *r, void *user)
{
    const tp_tape *T = user;
    tp_val x[NI], w[NO], y[NO], gx[NI], gp[2];
    char name[16];
    int i;
    for (i = 0; i < NI; i++)
        x[i] = tp_indep(r, i);
    for (i = 0; i < NO; i++)
        w[i] = tp_indep(r, NI + i);
    if (tp_call_vjp(r, T, x, NULL, w, y, gx, gp) != TP_OK)
        return 1;
    for (i = 0; i < NO; i++) {
        snprintf(name, sizeof name, "y%d", i);
        tp_output(r, name, y[i]);
    }
    for (i = 0; i < NI; i++) {
        snprintf(name, sizeof name, "gx%d", i);
        tp_output(r, name, gx[i]);
    }
    tp_output(r, "gp0", gp[0]);
    tp_output(r, "gp1", gp[1]);
    return 0;
}

/* The tangent tape of T: independents (x, s), outputs y (NO) and J s
 * (NO), recorded by tp_call_jvp. */
static int rec_tangent_tape(tp_rec *r, void *user)
{
    const tp_tape *T = user;
    tp_val x[NI], s[NI], y[NO], dy[NO];
    char name[16];
    int i;
    for (i = 0; i < NI; i++) {
        x[i] = tp_indep(r, i);
        s[i] = tp_indep(r, NI + i);
    }
    if (tp_call_jvp(r, T, x, NULL, s, NULL, y, dy) != TP_OK)
        return 1;
    for (i = 0; i < NO; i++) {
        snprintf(name, sizeof name, "y%d", i);
        tp_output(r, name, y[i]);
        snprintf(name, sizeof name, "dy%d", i);
        tp_output(r, name, dy[i]);
    }
    return 0;
}

static int record_derived(engines *E)
{
    static const unsigned char gg[NI + NO] = {0, 0, 1, 1, 2, 2};
    static const unsigned char gt[2 * NI] = {0, 0, 1, 1, 2, 2, 2, 2};
    tp_rec *r = NULL;
    int rc = tp_recorder_new(&r, NI + NO, gg, NULL);
    if (rc == TP_OK)
        rc = tp_rec_run(r, NULL, rec_gradient_tape, E->T);
    if (rc == TP_OK)
        rc = tp_recorder_finish(r, &E->Tg);
    tp_rec_free(&r);
    if (rc == TP_OK)
        rc = tp_recorder_new(&r, 2 * NI, gt, NULL);
    if (rc == TP_OK)
        rc = tp_rec_run(r, NULL, rec_tangent_tape, E->T);
    if (rc == TP_OK)
        rc = tp_recorder_finish(r, &E->Tt);
    tp_rec_free(&r);
    if (rc == TP_OK)
        rc = tp_ws_new(&E->wg, E->Tg, NI + NO, NULL);
    if (rc == TP_OK)
        rc = tp_ws_new(&E->wt, E->Tt, 2 * NI, NULL);
    return rc;
}

/* tp_call_vjp run on an evaluator: x independents, constant weights. */
typedef struct call_args {
    const tp_tape *T;
    const double *w;
} call_args;

static int rec_call_vjp(tp_rec *r, void *user)
{
    const call_args *a = user;
    tp_val x[NI], w[NO], gx[NI];
    char name[16];
    int i;
    for (i = 0; i < NI; i++)
        x[i] = tp_indep(r, i);
    for (i = 0; i < NO; i++)
        w[i] = tp_const(r, a->w[i]);
    if (tp_call_vjp(r, a->T, x, NULL, w, NULL, gx, NULL) != TP_OK)
        return 1;
    for (i = 0; i < NI; i++) {
        snprintf(name, sizeof name, "gx%d", i);
        tp_output(r, name, gx[i]);
    }
    return 0;
}

/* (g) The derivative tapes against the sweeps of T: the gradient tape's
 * values are w'J, its Jacobian over x is the weighted Hessian Hw (the
 * tuple engine's) and over w is J'; its parameter gradient matches
 * central differences in the parameters; the tangent tape's values are
 * J s and its Jacobian is H s for each output. The same replay run on the
 * double and tuple evaluators gives w'J and (through the tuples) Hw
 * again. */
static void check_derived(engines *E, const double *x, const double *w,
                          const double *gv, const double *J,
                          const double *S, const double *Hw,
                          const double *Hall, double h, const char *ctx)
{
    enum { NG = NO + NI + 2, NT = 2 * NO };
    double z[NI + NO], yg[NG], Jg[NG * (NI + NO)], a[NI * NI], b[NI * NI];
    double zt[2 * NI], yt[NT], Jt[NT * 2 * NI], gtu[NI * NI], gev[NI];
    double y0[NO], yp[NO], fd[2];
    call_args ca;
    int i, j, o, k, kp[2];

    for (i = 0; i < NI; i++)
        z[i] = x[i];
    for (o = 0; o < NO; o++)
        z[NI + o] = w[o];
    CHECK_INT(tp_eval(E->wg, z, yg), TP_OK);
    CHECK_INT(tp_eval(E->ws[NW - 1], x, y0), TP_OK);
    CHECK_VEC(ctx, yg, y0, NO, 1e-14);
    CHECK_VEC_SCALED(ctx, yg + NO, gv, NI, num_max_abs(gv, NI) + 1.0,
                     1e-13);
    CHECK_INT(tp_jacobian(E->wg, z, 0, NI + NO, NULL, Jg), TP_OK);
    for (i = 0; i < NI; i++)
        for (j = 0; j < NI; j++)
            a[i * NI + j] = Jg[(NO + i) * (NI + NO) + j];
    CHECK_VEC_SCALED(ctx, a, Hw, NI * NI, num_max_abs(Hw, NI * NI) + 1.0,
                     1e-12);
    for (i = 0; i < NI; i++)
        for (o = 0; o < NO; o++) {
            a[i * NO + o] = Jg[(NO + i) * (NI + NO) + NI + o];
            b[i * NO + o] = J[o * NI + i];
        }
    CHECK_VEC_SCALED(ctx, a, b, NI * NO, num_max_abs(J, NO * NI) + 1.0,
                     1e-13);
    /* the parameter gradient against central differences of w'y */
    kp[0] = E->kcu;
    kp[1] = E->kct;
    for (k = 0; k < 2; k++) {
        /* fourth-order central differences: steps h and 2 h */
        static const double step[4] = {1.0, -1.0, 2.0, -2.0};
        static const double coef[4] = {8.0, -8.0, -1.0, 1.0};
        const double p0 = E->param[kp[k]];
        int m;
        fd[k] = 0.0;
        for (m = 0; m < 4; m++) {
            double sw = 0.0;
            CHECK_INT(tp_ws_set_param(E->ws[NW - 1], kp[k],
                                      p0 + step[m] * h), TP_OK);
            CHECK_INT(tp_eval(E->ws[NW - 1], x, yp), TP_OK);
            for (o = 0; o < NO; o++)
                sw += w[o] * yp[o];
            fd[k] += coef[m] * sw / (12.0 * h);
        }
        CHECK_INT(tp_ws_set_param(E->ws[NW - 1], kp[k], p0), TP_OK);
    }
    /* the tape lists cu and ct in the order they were declared */
    {
        double gp[2];
        gp[0] = yg[NO + NI + (tp_tape_param_index(E->Tg, "cu") == E->kcu
                                  ? 0 : 1)];
        gp[1] = yg[NO + NI + (tp_tape_param_index(E->Tg, "cu") == E->kcu
                                  ? 1 : 0)];
        CHECK_VEC_SCALED(ctx, gp, fd, 2, num_max_abs(fd, 2) + 1.0, 1e-6);
    }

    /* the tangent tape along the first direction of S */
    for (i = 0; i < NI; i++) {
        zt[i] = x[i];
        zt[NI + i] = S[i * NS];
    }
    CHECK_INT(tp_eval(E->wt, zt, yt), TP_OK);
    CHECK_INT(tp_jacobian(E->wt, zt, 0, NI, NULL, Jt), TP_OK);
    for (o = 0; o < NO; o++) {
        const double *H = Hall + o * NI * NI;
        double js = 0.0, sc = 0.0, hs[NI];
        for (i = 0; i < NI; i++) {
            js += J[o * NI + i] * zt[NI + i];
            sc += fabs(J[o * NI + i] * zt[NI + i]);
        }
        CHECK_VEC(ctx, &yt[2 * o], &y0[o], 1, 1e-14);
        CHECK_VEC_SCALED(ctx, &yt[2 * o + 1], &js, 1, sc + 1.0, 1e-13);
        for (i = 0; i < NI; i++) {
            hs[i] = 0.0;
            for (j = 0; j < NI; j++)
                hs[i] += H[i * NI + j] * zt[NI + j];
            a[i] = Jt[(2 * o + 1) * NI + i];
        }
        CHECK_VEC_SCALED(ctx, a, hs, NI, num_max_abs(H, NI * NI) + 1.0,
                         1e-12);
    }

    /* the replay on the evaluators: w'J by doubles, Hw by tuples */
    ca.T = E->T;
    ca.w = w;
    CHECK_INT(st_eval(E->ev, x, rec_call_vjp, &ca, gev), TP_OK);
    CHECK_VEC_SCALED(ctx, gev, gv, NI, num_max_abs(gv, NI) + 1.0, 1e-13);
    CHECK_INT(st_tuple(E->tu, x, rec_call_vjp, &ca, NULL, gtu, NULL),
              TP_OK);
    CHECK_VEC_SCALED(ctx, gtu, Hw, NI * NI, num_max_abs(Hw, NI * NI) + 1.0,
                     1e-12);
}

/* ---- the checks at one point ------------------------------------------ */

static void check_point(engines *E, const double *x, double h,
                        const char *ctx, rng *g)
{
    tp_ws *big = E->ws[NW - 1];
    double y[NO], yev[NO], yref[NO], ytu[NO], yo;
    double J[NO * NI], Jfd[NO * NI], Jc[NO * NI], Jp[NO * 2];
    double G[NO * NI], Htu[NO * NI * NI];
    double S[NI * NS], JS[NO * NS], JSc[NO * NS], JSm[NO * NS], ys[NO];
    double *w = E->w, gv[NI], gref[NI], gh[NI], go[NI];
    double HS[NI * NS], HSc[NI * NS], Hw[NI * NI], hcol[NI], hfd[NI];
    double Hall[NO * NI * NI], Hc[NI * NI], Hcols[NI * 2], sk[NI];
    double yt[NO], y1[NO], y2[NO];
    int i, j, k, o, q;

    /* values: tape, reference interpreter, both evaluators */
    CHECK_INT(tp_eval(big, x, y), TP_OK);
    CHECK_INT(st_eval(E->ev, x, conf_record, E->cc, yev), TP_OK);
    CHECK_INT(tp__ref_eval(E->T, E->param, x, yref), TP_OK);
    CHECK_INT(st_tuple(E->tu, x, conf_record, E->cc, ytu, G, Htu),
              TP_OK);
    CHECK_VEC(ctx, y, yev, NO, 1e-13);
    CHECK_VEC(ctx, yref, y, NO, 1e-14);
    CHECK_VEC(ctx, ytu, yev, NO, 1e-14);

    /* (a) Jacobian against finite differences and the tuple gradients */
    CHECK_INT(tp_jacobian(big, x, 0, NI, NULL, J), TP_OK);
    CHECK_INT(num_fd_jac(fd_value, E, NI, NO, x, h, Jfd), 0);
    CHECK_VEC(ctx, J, Jfd, NO * NI, 1e-7);
    CHECK_VEC(ctx, J, G, NO * NI, 1e-13);
    for (q = 0; q < NW - 1; q++) {
        CHECK_INT(tp_jacobian(E->ws[q], x, 0, NI, NULL, Jc), TP_OK);
        CHECK_VEC(ctx, Jc, J, NO * NI, 1e-15);
        CHECK_INT(tp_jacobian(E->ws[q], x, 1, 2, NULL, Jp), TP_OK);
        for (o = 0; o < NO; o++)
            for (j = 0; j < 2; j++)
                Jc[o * 2 + j] = J[o * NI + 1 + j];
        CHECK_VEC(ctx, Jp, Jc, NO * 2, 1e-15);
    }

    /* directions: one general, one on group 0 only, one on group 1 only */
    for (i = 0; i < NI; i++) {
        S[i * NS + 0] = rng_range(g, -1.0, 1.0);
        S[i * NS + 1] = groups[i] == 0 ? rng_range(g, -1.0, 1.0) : 0.0;
        S[i * NS + 2] = groups[i] == 1 ? rng_range(g, -1.0, 1.0) : 0.0;
    }
    CHECK_INT(tp_jvp(big, x, NS, S, yt, JS), TP_OK);
    CHECK_VEC(ctx, yt, y, NO, 0.0);
    for (o = 0; o < NO; o++)
        for (k = 0; k < NS; k++) {
            double s = 0.0;
            for (i = 0; i < NI; i++)
                s += J[o * NI + i] * S[i * NS + k];
            JSm[o * NS + k] = s;
        }
    for (k = 0; k < NS; k++) {
        const double sc = term_scale(NO, NI, J, S + k, NS);
        double a[NO], b[NO];
        for (i = 0; i < NI; i++)
            sk[i] = S[i * NS + k];
        CHECK_INT(tp__ref_jvp(E->T, E->param, x, sk, NULL, ys), TP_OK);
        for (o = 0; o < NO; o++) {
            a[o] = JS[o * NS + k];
            b[o] = JSm[o * NS + k];
        }
        CHECK_VEC_SCALED(ctx, a, b, NO, sc, 1e-13);
        CHECK_VEC_SCALED(ctx, a, ys, NO, sc, 1e-13);
    }
    for (q = 0; q < NW - 1; q++) {
        CHECK_INT(tp_jvp(E->ws[q], x, NS, S, NULL, JSc), TP_OK);
        CHECK_VEC(ctx, JSc, JS, NO * NS, 1e-15);
    }

    /* (b) reverse: dot-product test, reference, single-output gradients */
    for (o = 0; o < NO; o++)
        w[o] = rng_range(g, -1.0, 1.0);
    CHECK_INT(tp_vjp(big, x, w, NULL, gv), TP_OK);
    CHECK_INT(tp__ref_vjp(E->T, E->param, x, w, gref), TP_OK);
    {
        double sc = 0.0;
        for (o = 0; o < NO; o++)
            for (i = 0; i < NI; i++)
                sc += fabs(w[o] * J[o * NI + i]);
        CHECK_VEC_SCALED(ctx, gv, gref, NI, sc, 1e-13);
    }
    for (k = 0; k < NS; k++) {
        double lhs = 0.0, rhs = 0.0, sc = 0.0;
        for (o = 0; o < NO; o++)
            lhs += w[o] * JS[o * NS + k];
        for (i = 0; i < NI; i++)
            rhs += gv[i] * S[i * NS + k];
        for (o = 0; o < NO; o++)
            for (i = 0; i < NI; i++)
                sc += fabs(w[o] * J[o * NI + i] * S[i * NS + k]);
        CHECK_VEC_SCALED(ctx, &lhs, &rhs, 1, sc, 1e-13);
    }
    for (o = 0; o < NO; o++) {
        CHECK_INT(tp_gradient(E->ws[o % NW], x, o, &yo, go), TP_OK);
        CHECK_VEC(ctx, &yo, &y[o], 1, 0.0);
        CHECK_VEC(ctx, go, J + o * NI, NI, 1e-13);
    }

    /* (c) Hessian-vector products: finite differences of the reverse
     * gradient, the tuple Hessian, the reference, the chunked workspaces */
    CHECK_INT(tp_hvp(big, x, w, NS, S, gh, HS), TP_OK);
    CHECK_VEC(ctx, gh, gv, NI, 1e-15);
    for (i = 0; i < NI * NI; i++)
        Hw[i] = w[0] * Htu[i] + w[1] * Htu[NI * NI + i];
    for (k = 0; k < NS; k++) {
        const double sc = term_scale(NI, NI, Hw, S + k, NS);
        double a[NI], b[NI];
        for (i = 0; i < NI; i++)
            sk[i] = S[i * NS + k];
        for (i = 0; i < NI; i++) {
            a[i] = HS[i * NS + k];
            b[i] = 0.0;
            for (j = 0; j < NI; j++)
                b[i] += Hw[i * NI + j] * sk[j];
        }
        CHECK_INT(num_fd_dir(fd_grad, E, NI, NI, x, sk, h, hfd), 0);
        CHECK_VEC(ctx, a, hfd, NI, 1e-6);
        CHECK_VEC_SCALED(ctx, a, b, NI, sc, 1e-12);
        CHECK_INT(tp__ref_hvp(E->T, E->param, x, w, sk, hcol), TP_OK);
        CHECK_VEC_SCALED(ctx, a, hcol, NI, sc, 1e-13);
    }
    for (q = 0; q < NW - 1; q++) {
        CHECK_INT(tp_hvp(E->ws[q], x, w, NS, S, NULL, HSc), TP_OK);
        CHECK_VEC(ctx, HSc, HS, NI * NS, 1e-15);
    }

    /* (d) full Hessians: symmetric, equal to the tuple's, chunk-invariant;
     * (f) Taylor coefficients against J d and d' H d */
    for (o = 0; o < NO; o++) {
        const double *Ht = Htu + o * NI * NI;
        double *H = Hall + o * NI * NI, Htr[NI * NI];
        CHECK_INT(tp_hessian(big, x, o, H), TP_OK);
        for (i = 0; i < NI; i++)
            for (j = 0; j < NI; j++)
                Htr[i * NI + j] = H[j * NI + i];
        CHECK_VEC_SCALED(ctx, H, Htr, NI * NI, num_max_abs(H, NI * NI),
                         1e-13);
        CHECK_VEC_SCALED(ctx, H, Ht, NI * NI, num_max_abs(Ht, NI * NI),
                         1e-12);
        for (q = 0; q < NW - 1; q++) {
            CHECK_INT(tp_hessian(E->ws[q], x, o, Hc), TP_OK);
            CHECK_VEC(ctx, Hc, H, NI * NI, 1e-15);
        }
        CHECK_INT(tp_hessian_cols(E->ws[0], x, o, 1, 2, go, Hcols), TP_OK);
        CHECK_VEC(ctx, go, J + o * NI, NI, 1e-13);
        for (i = 0; i < NI; i++)
            for (j = 0; j < 2; j++)
                Hc[i * 2 + j] = H[i * NI + 1 + j];
        CHECK_VEC(ctx, Hcols, Hc, NI * 2, 1e-15);
    }
    for (k = 0; k < NS; k++) {
        for (i = 0; i < NI; i++)
            sk[i] = S[i * NS + k];
        CHECK_INT(tp_taylor2(E->ws[k % NW], x, sk, yt, y1, y2), TP_OK);
        CHECK_VEC(ctx, yt, y, NO, 0.0);
        for (o = 0; o < NO; o++) {
            const double *H = Hall + o * NI * NI;
            double dHd = 0.0, sc = 0.0, a = JS[o * NS + k];
            for (i = 0; i < NI; i++)
                for (j = 0; j < NI; j++) {
                    dHd += sk[i] * H[i * NI + j] * sk[j];
                    sc += fabs(sk[i] * H[i * NI + j] * sk[j]);
                }
            CHECK_VEC_SCALED(ctx, &y2[o], &dHd, 1, sc, 1e-12);
            CHECK_VEC_SCALED(ctx, &y1[o], &a, 1,
                             term_scale(1, NI, J + o * NI, sk, 1), 1e-13);
        }
    }
    check_derived(E, x, w, gv, J, S, Hw, Hall, h, ctx);
}

/* ---- one case: record, then sample points ----------------------------- */

static void run_case(conf_case *cc, tp_rec *ev, tp_rec *tu,
                     rng *g)
{
    const int dom = tp__opinfo[cc->op].domain;
    engines E;
    tp_rec *r = NULL;
    char ctx[160];
    int k, q, rc;

    memset(&E, 0, sizeof E);
    E.cc = cc;
    E.ev = ev;
    E.tu = tu;
    snprintf(ctx, sizeof ctx, "%s c=%g %s", tp__opinfo[cc->op].name, cc->c,
             shape_name[cc->shape]);
    rc = tp_recorder_new(&r, NI, groups, NULL);
    CHECK_INT(rc, TP_OK);
    if (rc != TP_OK)
        return;
    CHECK_INT(tp_rec_run(r, NULL, conf_record, cc), TP_OK);
    rc = tp_recorder_finish(r, &E.T);
    CHECK_INT(rc, TP_OK);
    tp_rec_free(&r);
    if (rc != TP_OK) {
        fprintf(stderr, "%s: recording failed\n", ctx);
        return;
    }
    E.kcu = tp_tape_param_index(E.T, "cu");
    E.kct = tp_tape_param_index(E.T, "ct");
    CHECK(E.kcu >= 0 && E.kcu < 2 && E.kct >= 0 && E.kct < 2);
    CHECK_INT(record_derived(&E), TP_OK);
    for (q = 0; q < NW; q++)
        CHECK_INT(tp_ws_new(&E.ws[q], E.T, ws_dirs[q], NULL), TP_OK);

    for (k = 0; k < n_edge(dom) + NRAND; k++) {
        double x[NI], u, t, pu, pt, dist, h;
        char pctx[400];
        int i;
        for (i = 0; i < NI; i++)
            x[i] = rng_range(g, -0.5, 0.5);
        dist = place(cc, k, g, x, &u, &t, &pu, &pt);
        /* an operand moves by at most 3.5 h per unit step in x; keep the
         * difference stencil 1000 times closer to the operand than any
         * non-smooth place */
        h = 1e-3 * fmin(1.0, dist / 3.5);
        snprintf(pctx, sizeof pctx, "%s point %d (u=%.17g t=%.17g)", ctx, k,
                 u, t);
        set_params(&E, pu, pt);
        check_point(&E, x, h, pctx, g);
    }
    for (q = 0; q < NW; q++)
        tp_ws_free(&E.ws[q]);
    tp_ws_free(&E.wg);
    tp_ws_free(&E.wt);
    tp_tape_free(&E.Tg);
    tp_tape_free(&E.Tt);
    tp_tape_free(&E.T);
}

/* Every case: each non-leaf op of the table, with each constant of its
 * kind's list and each operand shape it takes. Fills out (up to max) and
 * returns the count. */
#define MAX_CASES 512
static int list_cases(conf_case *out, int max)
{
    int op, s, kc, n = 0;
    for (op = 0; op < TP_OP_COUNT; op++) {
        const int kind = tp__opinfo[op].kind;
        const int n_shapes = kind == TP_KIND_BINARY ? SH_COUNT : 2;
        int n_consts = 1;
        if (kind == TP_KIND_LEAF)
            continue;
        if (kind == TP_KIND_UCONST)
            n_consts = (int)(sizeof uconst_list / sizeof uconst_list[0]);
        else if (kind == TP_KIND_UINT)
            n_consts = (int)(sizeof uint_list / sizeof uint_list[0]);
        for (kc = 0; kc < n_consts; kc++)
            for (s = 0; s < n_shapes && n < max; s++) {
                out[n].op = op;
                out[n].c = kind == TP_KIND_UCONST ? uconst_list[kc]
                         : kind == TP_KIND_UINT  ? (double)uint_list[kc]
                                                 : 0.0;
                out[n].shape = s;
                n++;
            }
    }
    return n;
}

static void conformance(void)
{
    static conf_case cases[MAX_CASES];
    tp_rec *ev = NULL, *tu = NULL;
    rng g = rng_seed(0x5eed0001u);
    const int n_cases = list_cases(cases, MAX_CASES);
    int op, k, covered[TP_OP_COUNT] = {0};

    CHECK(n_cases < MAX_CASES);
    CHECK_INT(tp_evaluator_new(&ev, NI, NULL), TP_OK);
    CHECK_INT(tp_tuple_new(&tu, NI, NULL), TP_OK);
    if (!ev || !tu)
        goto done;
    for (k = 0; k < n_cases; k++) {
        run_case(&cases[k], ev, tu, &g);
        covered[cases[k].op]++;
    }
    /* every non-leaf op of the table was exercised */
    for (op = 0; op < TP_OP_COUNT; op++)
        if (tp__opinfo[op].kind != TP_KIND_LEAF)
            CHECK(covered[op] > 0);
    printf("conformance: %d cases over %d ops\n", n_cases, TP_OP_COUNT);
done:
    tp_rec_free(&ev);
    tp_rec_free(&tu);
}

/* ---- the compiled backend ---------------------------------------------- */

/* Every case on one tape: case k's f and g with its own parameters cuK
 * and ctK; output 0 is the sum of the g's (a Lagrangian of q = (x0, x1),
 * qd = (x2, x3): every op's second derivatives reach its Lagrange block),
 * then each case's f and g. */
typedef struct all_cases {
    const conf_case *c;
    int n;
} all_cases;

static int all_record(tp_rec *r, void *user)
{
    const all_cases *a = user;
    static tp_val f[MAX_CASES], gout[MAX_CASES];
    tp_val x[NI], sum;
    char name[32];
    int i, k;
    for (i = 0; i < NI; i++)
        x[i] = tp_indep(r, i);
    for (k = 0; k < a->n; k++) {
        tp_val pu, pt;
        snprintf(name, sizeof name, "cu%d", k);
        pu = tp_param(r, name, 0.5);
        snprintf(name, sizeof name, "ct%d", k);
        pt = tp_param(r, name, 0.5);
        record_case(r, x, &a->c[k], pu, pt, &f[k], &gout[k]);
    }
    sum = gout[0];
    for (k = 1; k < a->n; k++)
        sum = tp_add(r, sum, gout[k]);
    tp_output(r, "L", sum);
    for (k = 0; k < a->n; k++) {
        snprintf(name, sizeof name, "f%d", k);
        tp_output(r, name, f[k]);
        snprintf(name, sizeof name, "g%d", k);
        tp_output(r, name, gout[k]);
    }
    return 0;
}

/* Every sweep the compiled backend has, on both paths at x: values, a
 * weighted gradient, the Lagrange block of output 0, the Jacobian over
 * every independent, the Taylor coefficients along dir; into r. */
static void all_sweeps(tp_ws *w, const double *x, const double *wt,
                       const double *dir, int m, double *r)
{
    double *y = r, *gr = y + m, *L = gr + NI, *gq = L + 1, *M = gq + 2,
           *h = M + 4, *J = h + 2, *ty = J + (size_t)m * NI;
    CHECK_INT(tp_eval(w, x, y), TP_OK);
    CHECK_INT(tp_vjp(w, x, wt, NULL, gr), TP_OK);
    CHECK_INT(tp_lagrange(w, x, 0, L, gq, M, h), TP_OK);
    CHECK_INT(tp_jacobian(w, x, 0, NI, NULL, J), TP_OK);
    CHECK_INT(tp_taylor2(w, x, dir, ty, ty + m, ty + 2 * m), TP_OK);
}

/* The cases of conformance() at random points of their domains (no edge
 * points: there a NaN or an infinity may propagate differently where the
 * compiled code leaves out a structurally zero term), compiled against
 * interpreted, every result to 1e-14 relative: they do the same
 * arithmetic. One tape, so one compilation. */
static void compiled_backend(void)
{
    static conf_case cases[MAX_CASES];
    char dir[] = "/tmp/test-conformance-XXXXXX", cmd[128];
    all_cases a;
    tp_rec *r = NULL;
    tp_tape *T = NULL;
    tp_ws *w[2] = {NULL, NULL};
    tp_compiled *c = NULL;
    tp_compile_opts o;
    tp_compile_info info;
    rng g = rng_seed(0x5eed0002u);
    double *res[2] = {NULL, NULL}, *par = NULL;
    static int pidx[2 * MAX_CASES];
    size_t per;
    int m, k, p, i, q;

    a.c = cases;
    a.n = list_cases(cases, MAX_CASES);
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        CHECK(0);
        return;
    }
    CHECK_INT(tp_recorder_new(&r, NI, groups, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, all_record, &a), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    tp_rec_free(&r);
    if (!T)
        goto done;
    memset(&o, 0, sizeof o);
    o.cache_dir = dir;
    o.max_dirs = NI;
    o.lagrange = 1;
    o.lagrange_out = 0;
    o.sweeps = TP_SWEEP_VALUES | TP_SWEEP_GRADIENTS | TP_SWEEP_LAGRANGE |
               TP_SWEEP_JACOBIAN | TP_SWEEP_TAYLOR2;
    CHECK_INT(tp_compile(T, &o, &c, &info), TP_OK);
    if (!c) {
        fprintf(stderr, "compiled backend: %s\n", info.msg);
        goto done;
    }
    m = (int)tp_tape_n_outputs(T);
    CHECK_INT(m, 1 + 2 * a.n);
    per = (size_t)m + NI + 1 + 2 + 4 + 2 + (size_t)m * NI + 3 * (size_t)m;
    res[0] = calloc(2 * per, sizeof(double));
    res[1] = res[0] ? res[0] + per : NULL;
    par = calloc((size_t)m, sizeof(double)); /* output weights */
    for (q = 0; q < 2; q++)
        CHECK_INT(tp_ws_new(&w[q], T, NI, NULL), TP_OK);
    if (!res[0] || !par || !w[0] || !w[1])
        goto out;
    CHECK_INT(tp_ws_set_compiled(w[1], c), TP_OK);
    for (k = 0; k < 2 * a.n; k++) {
        char name[32];
        snprintf(name, sizeof name, "c%c%d", k % 2 ? 't' : 'u', k / 2);
        pidx[k] = tp_tape_param_index(T, name);
        CHECK(pidx[k] >= 0);
    }
    for (p = 0; p < NRAND; p++) {
        double x[NI], d[NI];
        for (i = 0; i < NI; i++) {
            x[i] = rng_range(&g, -0.5, 0.5);
            d[i] = rng_range(&g, -1.0, 1.0);
        }
        /* each case's operands somewhere inside its op's domain */
        for (k = 0; k < a.n; k++) {
            const int dom = tp__opinfo[cases[k].op].domain;
            double u, t, pu, pt;
            place(&cases[k], n_edge(dom) + p, &g, x, &u, &t, &pu, &pt);
            for (q = 0; q < 2; q++) {
                CHECK_INT(tp_ws_set_param(w[q], pidx[2 * k], pu), TP_OK);
                CHECK_INT(tp_ws_set_param(w[q], pidx[2 * k + 1], pt), TP_OK);
            }
        }
        for (i = 0; i < m; i++)
            par[i] = rng_range(&g, -1.0, 1.0);
        for (q = 0; q < 2; q++)
            all_sweeps(w[q], x, par, d, m, res[q]);
        for (i = 0; i < (int)per; i++)
            CHECK_NEAR(res[1][i], res[0][i], 1e-14);
    }
    printf("compiled backend: %d cases on one tape of %d outputs\n", a.n, m);
out:
    free(res[0]);
    free(par);
done:
    tp_ws_free(&w[0]);
    tp_ws_free(&w[1]);
    tp_compiled_free(&c);
    tp_tape_free(&T);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
}

/* ---- record-time rewrites --------------------------------------------- */

enum { SAME_AS_E = -1 }; /* the output is the operand e itself */

typedef struct rw_case {
    const char *name;
    int expect; /* opcode of the output's op on the tape, or SAME_AS_E */
} rw_case;

/* Expected tape op of each output of rw_record, in output order. */
static const rw_case rw_cases[] = {
    {"e", TP_OP_ADD},
    {"e+c", TP_OP_ADDC},
    {"c+e", TP_OP_ADDC},
    {"e-c", TP_OP_ADDC},
    {"c-e", TP_OP_CSUB},
    {"e*c", TP_OP_MULC},
    {"c*e", TP_OP_MULC},
    {"c/e", TP_OP_CDIV},
    {"e/4", TP_OP_MULC},
    {"e/3", TP_OP_DIV},
    {"e^2.5", TP_OP_POWC},
    {"e^3.0", TP_OP_POWI},
    {"e^-2.0", TP_OP_POWI},
    {"2^e", TP_OP_POW},
    {"powc(e,3)", TP_OP_POWI},
    {"powc(e,0.5)", TP_OP_POWC},
    {"e*0", TP_OP_CONST},
    {"0*e", TP_OP_CONST},
    {"e+0", SAME_AS_E},
    {"e-0", SAME_AS_E},
    {"e-e", TP_OP_CONST},
    {"e*e", TP_OP_SQR},
    {"e+e", TP_OP_MULC},
    {"powi(e,0)", TP_OP_CONST},
    {"powi(e,1)", SAME_AS_E},
    {"powi(e,2)", TP_OP_SQR},
    {"powi(e,-3)", TP_OP_POWI},
    {"mulc(e,1)", SAME_AS_E},
    {"mulc(e,-1)", TP_OP_NEG},
    {"neg(neg(e))", SAME_AS_E},
    {"0-e", TP_OP_NEG},
    {"addc(e,0)", SAME_AS_E},
    {"sin(c)", TP_OP_CONST},
    {"c+c", TP_OP_CONST},
    {"powi(c,3)", TP_OP_CONST},
    {"atan2(c,c)", TP_OP_CONST},
    {"x0x1-x1x0", TP_OP_CONST},
    {"c*p", TP_OP_MULC},
    {"subc(e,2.5)", TP_OP_ADDC},
    {"divc(e,4)", TP_OP_MULC},
    {"divc(e,3)", TP_OP_DIV},
};
/* The constant-operand calls and the binary ops they stand for record the
 * same op (hash-consing makes it the same slot): output index pairs. */
static const int rw_same[][2] = {{38, 3}, {39, 8}, {40, 9}};
#define N_RW ((int)(sizeof rw_cases / sizeof rw_cases[0]))

static int rw_record(tp_rec *r, void *user)
{
    tp_val x0 = tp_indep(r, 0), x1 = tp_indep(r, 1);
    tp_val e = tp_add(r, tp_mul(r, x0, x1), x1); /* in [0.75, 3.75] */
    tp_val c25 = tp_const(r, 2.5), c0 = tp_const(r, 0.0);
    tp_val p = tp_param(r, "p", 1.75);
    tp_val v[N_RW];
    int i = 0;
    (void)user;
    v[i++] = e;
    v[i++] = tp_add(r, e, c25);
    v[i++] = tp_add(r, c25, e);
    v[i++] = tp_sub(r, e, c25);
    v[i++] = tp_sub(r, c25, e);
    v[i++] = tp_mul(r, e, tp_const(r, 3.0));
    v[i++] = tp_mul(r, tp_const(r, 3.0), e);
    v[i++] = tp_div(r, tp_const(r, 2.0), e);
    v[i++] = tp_div(r, e, tp_const(r, 4.0));
    v[i++] = tp_div(r, e, tp_const(r, 3.0));
    v[i++] = tp_pow(r, e, c25);
    v[i++] = tp_pow(r, e, tp_const(r, 3.0));
    v[i++] = tp_pow(r, e, tp_const(r, -2.0));
    v[i++] = tp_pow(r, tp_const(r, 2.0), e);
    v[i++] = tp_powc(r, e, 3.0);
    v[i++] = tp_powc(r, e, 0.5);
    v[i++] = tp_mul(r, e, c0);
    v[i++] = tp_mul(r, c0, e);
    v[i++] = tp_add(r, e, c0);
    v[i++] = tp_sub(r, e, c0);
    v[i++] = tp_sub(r, e, e);
    v[i++] = tp_mul(r, e, e);
    v[i++] = tp_add(r, e, e);
    v[i++] = tp_powi(r, e, 0);
    v[i++] = tp_powi(r, e, 1);
    v[i++] = tp_powi(r, e, 2);
    v[i++] = tp_powi(r, e, -3);
    v[i++] = tp_mulc(r, e, 1.0);
    v[i++] = tp_mulc(r, e, -1.0);
    v[i++] = tp_neg(r, tp_neg(r, e));
    v[i++] = tp_sub(r, c0, e);
    v[i++] = tp_addc(r, e, 0.0);
    v[i++] = tp_sin(r, tp_const(r, 0.7));
    v[i++] = tp_add(r, tp_const(r, 1.25), c25);
    v[i++] = tp_powi(r, tp_const(r, 1.5), 3);
    v[i++] = tp_atan2(r, tp_const(r, 0.5), tp_const(r, -2.0));
    v[i++] = tp_sub(r, tp_mul(r, x0, x1), tp_mul(r, x1, x0));
    /* a parameter is not a constant: never folded, but MUL by a constant
     * still becomes MULC */
    v[i++] = tp_mul(r, tp_const(r, 3.0), p);
    v[i++] = tp_subc(r, e, 2.5);
    v[i++] = tp_divc(r, e, 4.0);
    v[i++] = tp_divc(r, e, 3.0);
    for (i = 0; i < N_RW; i++)
        tp_output(r, rw_cases[i].name, v[i]);
    return 0;
}

static void rewrites(void)
{
    static const unsigned char grp[2] = {0, 1};
    tp_rec *r = NULL, *ev = NULL, *tu = NULL;
    tp_tape *T = NULL;
    tp_ws *ws = NULL;
    rng g = rng_seed(0x5eed0002u);
    double y[N_RW], yev[N_RW], yref[N_RW], J[N_RW * 2], G[N_RW * 2];
    double Htu[N_RW * 4], H[4], param[1];
    int o, k;

    CHECK_INT(tp_recorder_new(&r, 2, grp, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, rw_record, NULL), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    tp_rec_free(&r);
    if (!T)
        return;
    CHECK_INT(tp_tape_n_outputs(T), N_RW);
    for (o = 0; o < N_RW; o++) {
        const uint32_t s = T->out_slot[o];
        if (rw_cases[o].expect == SAME_AS_E) {
            if (s != T->out_slot[0])
                CHECK_FAIL_("rewrite %s: not the operand's slot (op %s)",
                            rw_cases[o].name, tp__opinfo[T->opc[s]].name);
            check_count_++;
        } else {
            if (T->opc[s] != rw_cases[o].expect)
                CHECK_FAIL_("rewrite %s: tape op %s, expected %s",
                            rw_cases[o].name, tp__opinfo[T->opc[s]].name,
                            tp__opinfo[rw_cases[o].expect].name);
            check_count_++;
        }
    }
    for (k = 0; k < (int)(sizeof rw_same / sizeof rw_same[0]); k++)
        if (T->out_slot[rw_same[k][0]] != T->out_slot[rw_same[k][1]])
            CHECK_FAIL_("%s records another op than %s",
                        rw_cases[rw_same[k][0]].name,
                        rw_cases[rw_same[k][1]].name);
    /* a + b and b + a are one op */
    CHECK_INT(T->out_slot[1], T->out_slot[2]);
    CHECK_INT(T->out_slot[5], T->out_slot[6]);

    CHECK_INT(tp_ws_new(&ws, T, 1, NULL), TP_OK);
    CHECK_INT(tp_evaluator_new(&ev, 2, NULL), TP_OK);
    CHECK_INT(tp_tuple_new(&tu, 2, NULL), TP_OK);
    if (!ws || !ev || !tu)
        goto done;
    param[0] = 1.75;
    for (k = 0; k < 10; k++) {
        double x[2];
        char ctx[64];
        x[0] = rng_range(&g, 0.5, 1.5);
        x[1] = rng_range(&g, 0.5, 1.5);
        CHECK_INT(tp_eval(ws, x, y), TP_OK);
        CHECK_INT(st_eval(ev, x, rw_record, NULL, yev), TP_OK);
        CHECK_INT(tp__ref_eval(T, param, x, yref), TP_OK);
        CHECK_INT(st_tuple(tu, x, rw_record, NULL, NULL, G, Htu), TP_OK);
        CHECK_INT(tp_jacobian(ws, x, 0, 2, NULL, J), TP_OK);
        for (o = 0; o < N_RW; o++) {
            snprintf(ctx, sizeof ctx, "rewrite %s at point %d",
                     rw_cases[o].name, k);
            CHECK_VEC(ctx, &y[o], &yev[o], 1, 1e-14);
            CHECK_VEC(ctx, &yref[o], &y[o], 1, 0.0);
            CHECK_VEC(ctx, J + 2 * o, G + 2 * o, 2, 1e-13);
            CHECK_INT(tp_hessian(ws, x, o, H), TP_OK);
            CHECK_VEC(ctx, H, Htu + 4 * o, 4, 1e-13);
        }
    }
done:
    tp_ws_free(&ws);
    tp_rec_free(&ev);
    tp_rec_free(&tu);
    tp_tape_free(&T);
}

int main(void)
{
    conformance();
    compiled_backend();
    rewrites();
    CHECK_DONE();
}
