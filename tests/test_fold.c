/* test_fold.c - the recorder's constant folding and record-time rewrites
 * (record.c) against unfolded recording, over every op that takes a
 * constant and constants of every sign.
 *
 * One function records, for each binary op (+ - * / pow atan2 hypot),
 * each constant c in {-3, -2, -1, -1/2, -0, +0, 1/2, 1, 2, 3} and each
 * variable v in {e, -e} (e = x0 x1 + x1 > 0): op(c, v), op(v, c) and
 * op(c, d) for two constants d; each constant-operand call (addc, subc,
 * mulc, divc, csub, cdiv, powc) with every c on v and on a constant;
 * powi with k = -3..3; every unary op on each constant inside its domain;
 * and the double negation. The tape recorder folds and rewrites these
 * (x*1 -> x, x*-1 -> -x, x*0 -> 0, 0-x -> -x, x/2^k -> x*2^-k, x^k ->
 * powi, ops on constants -> one constant, ...); the double evaluator
 * and the embedded-tuple engine run the same function with nothing
 * folded. At random points the tape's values must equal the
 * evaluator's to 1e-14 (relative), its gradients (tp_jacobian) and
 * Hessians (tp_hessian) the tuples' to 1e-13. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "support_rng.h"
#include "support_tape.h"

static const double consts[] = {-3.0, -2.0, -1.0, -0.5, -0.0,
                                0.0,  0.5,  1.0,  2.0,  3.0};
#define NC ((int)(sizeof consts / sizeof consts[0]))
static const double others[] = {0.75, -1.25}; /* the second constant */

typedef tp_val (*binop)(tp_rec *, tp_val, tp_val);
typedef tp_val (*unop)(tp_rec *, tp_val);
typedef tp_val (*cop)(tp_rec *, tp_val, double);

enum { B_ADD, B_SUB, B_MUL, B_DIV, B_POW, B_ATAN2, B_HYPOT, B_COUNT };
static const binop binops[B_COUNT] = {tp_add, tp_sub, tp_mul, tp_div,
                                      tp_pow, tp_atan2, tp_hypot};
static const char *const binop_name[B_COUNT] = {"+", "-", "*", "/", "pow",
                                                "atan2", "hypot"};

/* Whether op(a, b) is inside the op's domain; a variable operand is
 * marked by its sign only (sa, sb: +1 or -1 for e or -e, 0 for a
 * constant, whose value is then a or b). */
static int defined(int op, double a, int sa, double b, int sb)
{
    switch (op) {
    case B_DIV: return sb != 0 || b != 0.0;
    case B_POW: return sa > 0 || (sa == 0 && a > 0.0);
    case B_ATAN2: return sa != 0 || sb != 0 || a != 0.0 || b != 0.0;
    default: return 1;
    }
}

static tp_val cop_csub(tp_rec *r, tp_val a, double c)
{
    return tp_csub(r, c, a);
}
static tp_val cop_cdiv(tp_rec *r, tp_val a, double c)
{
    return tp_cdiv(r, c, a);
}
enum { C_ADDC, C_SUBC, C_MULC, C_DIVC, C_CSUB, C_CDIV, C_POWC, C_COUNT };
static const cop cops[C_COUNT] = {tp_addc, tp_subc, tp_mulc, tp_divc,
                                  cop_csub, cop_cdiv, tp_powc};
static const char *const cop_name[C_COUNT] = {"addc", "subc", "mulc",
                                              "divc", "csub", "cdiv",
                                              "powc"};

static const unop unops[] = {tp_neg,  tp_sqr,  tp_sqrt, tp_exp,  tp_log,
                             tp_sin,  tp_cos,  tp_tan,  tp_asin, tp_acos,
                             tp_atan, tp_sinh, tp_cosh, tp_tanh, tp_abs};
static const char *const unop_name[] = {
    "neg",  "sqr",  "sqrt", "exp",  "log",  "sin",  "cos", "tan",
    "asin", "acos", "atan", "sinh", "cosh", "tanh", "abs"};
#define NU ((int)(sizeof unops / sizeof unops[0]))

/* Whether unary op k is defined (and smooth enough to fold) at c. */
static int unary_defined(int k, double c)
{
    const char *n = unop_name[k];
    if (!strcmp(n, "sqrt") || !strcmp(n, "log"))
        return c > 0.0;
    if (!strcmp(n, "asin") || !strcmp(n, "acos"))
        return fabs(c) < 1.0;
    return 1;
}

/* What each output is, for messages (filled by the first recording). */
static char (*labels)[48];
static int nlabels;

/* Output number *k (then *k + 1) is v, described by fmt. */
static void out(tp_rec *r, int *k, tp_val v, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void out(tp_rec *r, int *k, tp_val v, const char *fmt, ...)
{
    char name[32];
    snprintf(name, sizeof name, "o%d", *k);
    tp_output(r, name, v);
    if (labels && *k < nlabels) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(labels[*k], sizeof labels[*k], fmt, ap);
        va_end(ap);
    }
    (*k)++;
}

static int record(tp_rec *r, void *user)
{
    const tp_val x0 = tp_indep(r, 0), x1 = tp_indep(r, 1);
    const tp_val e = tp_add(r, tp_mul(r, x0, x1), x1); /* > 0 */
    const tp_val vars[2] = {e, tp_neg(r, e)};
    const int sign[2] = {1, -1};
    int o, c, v, d, k = 0;
    (void)user;
    for (o = 0; o < B_COUNT; o++)
        for (c = 0; c < NC; c++) {
            const double cv = consts[c];
            for (v = 0; v < 2; v++) {
                if (defined(o, cv, 0, 0.0, sign[v]))
                    out(r, &k, binops[o](r, tp_const(r, cv), vars[v]),
                        "%g %s %se", cv, binop_name[o], v ? "-" : "");
                if (defined(o, 0.0, sign[v], cv, 0))
                    out(r, &k, binops[o](r, vars[v], tp_const(r, cv)),
                        "%se %s %g", v ? "-" : "", binop_name[o], cv);
            }
            for (d = 0; d < 2; d++) {
                if (defined(o, cv, 0, others[d], 0))
                    out(r, &k, binops[o](r, tp_const(r, cv),
                                         tp_const(r, others[d])),
                        "%g %s %g", cv, binop_name[o], others[d]);
                if (defined(o, others[d], 0, cv, 0))
                    out(r, &k, binops[o](r, tp_const(r, others[d]),
                                         tp_const(r, cv)),
                        "%g %s %g", others[d], binop_name[o], cv);
            }
        }
    for (o = 0; o < C_COUNT; o++)
        for (c = 0; c < NC; c++) {
            const double cv = consts[c];
            if (o == C_DIVC && cv == 0.0)
                continue;
            for (v = 0; v < 2; v++) {
                if (o == C_POWC && v == 1)
                    continue; /* u^c needs u > 0 */
                out(r, &k, cops[o](r, vars[v], cv), "%s(%se, %g)",
                    cop_name[o], v ? "-" : "", cv);
            }
            for (d = 0; d < 2; d++) {
                if ((o == C_CDIV && others[d] == 0.0) ||
                    (o == C_POWC && others[d] <= 0.0))
                    continue;
                out(r, &k, cops[o](r, tp_const(r, others[d]), cv),
                    "%s(%g, %g)", cop_name[o], others[d], cv);
            }
        }
    for (c = -3; c <= 3; c++) {
        for (v = 0; v < 2; v++)
            out(r, &k, tp_powi(r, vars[v], c), "powi(%se, %d)",
                v ? "-" : "", c);
        out(r, &k, tp_powi(r, tp_const(r, others[1]), c), "powi(%g, %d)",
            others[1], c);
    }
    for (o = 0; o < NU; o++)
        for (c = 0; c < NC; c++)
            if (unary_defined(o, consts[c]))
                out(r, &k, unops[o](r, tp_const(r, consts[c])), "%s(%g)",
                    unop_name[o], consts[c]);
    for (v = 0; v < 2; v++)
        out(r, &k, tp_neg(r, tp_neg(r, vars[v])), "neg(neg(%se))",
            v ? "-" : "");
    return 0;
}

static int close_to(double a, double b, double tol)
{
    if (a == b)
        return 1;
    return fabs(a - b) <= tol * fmax(1.0, fmax(fabs(a), fabs(b)));
}

int main(void)
{
    static const unsigned char grp[2] = {0, 1};
    tp_rec *r = NULL, *ev = NULL, *tu = NULL;
    tp_tape *T = NULL;
    tp_ws *ws = NULL;
    tp_tape_stats st;
    rng g = rng_seed(0xf01d0001u);
    double *y, *yev, *ytu, *J, *G, *Htu, H[4];
    int m, o, p, i;

    labels = calloc(4096, sizeof *labels);
    nlabels = labels ? 4096 : 0;
    CHECK_INT(tp_recorder_new(&r, 2, grp, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, record, NULL), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    tp_rec_free(&r);
    if (!T)
        CHECK_DONE();
    m = tp_tape_n_outputs(T);
    CHECK(m > 500 && m <= nlabels);
    CHECK_INT(tp_tape_stats_get(T, &st), TP_OK);
    /* the recorder did fold and rewrite: the test reaches those paths */
    CHECK(st.n_folded > (size_t)m / 2);
    printf("%d outputs, %zu folds and rewrites\n", m, st.n_folded);
    nlabels = 0; /* the other engines leave the labels alone */

    y = calloc((size_t)m, sizeof *y);
    yev = calloc((size_t)m, sizeof *yev);
    ytu = calloc((size_t)m, sizeof *ytu);
    J = calloc(2 * (size_t)m, sizeof *J);
    G = calloc(2 * (size_t)m, sizeof *G);
    Htu = calloc(4 * (size_t)m, sizeof *Htu);
    CHECK_INT(tp_ws_new(&ws, T, 2, NULL), TP_OK);
    CHECK_INT(tp_evaluator_new(&ev, 2, NULL), TP_OK);
    CHECK_INT(tp_tuple_new(&tu, 2, NULL), TP_OK);
    if (!y || !yev || !ytu || !J || !G || !Htu || !ws || !ev || !tu)
        goto done;
    for (p = 0; p < 5; p++) {
        double x[2];
        x[0] = rng_range(&g, 0.5, 1.5);
        x[1] = rng_range(&g, 0.5, 1.5);
        CHECK(tp_eval(ws, x, y) >= 0);
        CHECK(st_eval(ev, x, record, NULL, yev) >= 0);
        CHECK(st_tuple(tu, x, record, NULL, ytu, G, Htu) >= 0);
        CHECK_INT(tp_rec_n_outputs(ev), m);
        CHECK(tp_jacobian(ws, x, 0, 2, NULL, J) >= 0);
        for (o = 0; o < m; o++) {
            int bad = !close_to(y[o], yev[o], 1e-14) ||
                      !close_to(y[o], ytu[o], 1e-14);
            check_count_++;
            if (bad)
                CHECK_FAIL_("%s at (%.3f, %.3f): tape %.17g, evaluator "
                            "%.17g, tuples %.17g", labels[o], x[0], x[1],
                            y[o], yev[o], ytu[o]);
            CHECK(tp_hessian(ws, x, o, H) >= 0);
            for (i = 0; i < 2 && !bad; i++)
                if (!close_to(J[2 * o + i], G[2 * o + i], 1e-13)) {
                    CHECK_FAIL_("%s: d/dx%d: tape %.17g, tuples %.17g",
                                labels[o], i, J[2 * o + i], G[2 * o + i]);
                    bad = 1;
                }
            for (i = 0; i < 4 && !bad; i++)
                if (!close_to(H[i], Htu[4 * o + i], 1e-13)) {
                    CHECK_FAIL_("%s: Hessian entry %d: tape %.17g, tuples "
                                "%.17g", labels[o], i, H[i], Htu[4 * o + i]);
                    bad = 1;
                }
        }
    }
done:
    free(y);
    free(yev);
    free(ytu);
    free(J);
    free(G);
    free(Htu);
    free(labels);
    tp_ws_free(&ws);
    tp_rec_free(&ev);
    tp_rec_free(&tu);
    tp_tape_free(&T);
    CHECK_DONE();
}
