/* tangent.c - the walker of values of any shape, and der(): the total
 * time derivative of an expression, recorded as a forward tangent of the
 * recorded expression along (qd, 1).
 *
 * Every value here is an ldual: its recorded value and its derivative.
 * A coordinate's derivative is its rate, the time's is 1, a parameter's
 * and a number's 0; each operation applies the chain rule (tangent of a
 * product: da*b + a*db) through the same folding arithmetic as the
 * scalar walker (emit.c), so a derivative that is the constant 0 records
 * nothing. Outside der() every derivative is that constant 0: the walker
 * then records exactly what the operations themselves need. Definitions
 * are memoized with their derivatives (emit.c, lang_def_ref), so der()
 * of the tip of a chain records each link's tangent once: the tape stays
 * linear in the links. No expression is ever expanded symbolically.
 *
 * der() of something that already holds rates would need the
 * accelerations; it is refused where a rate or a der() is met. */
#include <math.h>
#include <string.h>

#include "lang.h"

static lval zero(void)
{
    lval z;
    memset(&z, 0, sizeof z);
    z.k = 1;
    return z;
}

static lval num(double c)
{
    lval z = zero();
    z.c = c;
    return z;
}

static int is_zero(lval a) { return a.k && a.c == 0.0; }

/* out = a op b on plain values (no derivatives) */
static int ar(lang_inst *in, int op, int tok, lval a, lval b, lval *out)
{
    return lang_arith(in, op, tok, a, b, out);
}

int lang_darith(lang_inst *in, int op, int tok, ldual a, ldual b,
                ldual *out)
{
    lval t1, t2, v;
    if (ar(in, op, tok, a.v, b.v, &v) < 0)
        return -1;
    out->d = zero();
    switch (op) {
    case TK_PLUS:
    case TK_MINUS:
        if (ar(in, op, tok, a.d, b.d, &out->d) < 0)
            return -1;
        break;
    case TK_STAR: /* da*b + a*db */
        if (ar(in, TK_STAR, tok, a.d, b.v, &t1) < 0 ||
            ar(in, TK_STAR, tok, a.v, b.d, &t2) < 0 ||
            ar(in, TK_PLUS, tok, t1, t2, &out->d) < 0)
            return -1;
        break;
    case TK_SLASH: /* (da - v*db)/b */
        if (is_zero(a.d) && is_zero(b.d))
            break;
        if (ar(in, TK_STAR, tok, v, b.d, &t1) < 0 ||
            ar(in, TK_MINUS, tok, a.d, t1, &t2) < 0 ||
            ar(in, TK_SLASH, tok, t2, b.v, &out->d) < 0)
            return -1;
        break;
    case TK_CARET:
        if (!is_zero(b.d)) { /* v*(db*log(a) + b*da/a) */
            lval la, s1, s2, s3;
            if (lang_func(in, F_LOG, a.v, zero(), &la) < 0 ||
                ar(in, TK_STAR, tok, b.d, la, &s1) < 0 ||
                ar(in, TK_STAR, tok, b.v, a.d, &s2) < 0 ||
                ar(in, TK_SLASH, tok, s2, a.v, &s3) < 0 ||
                ar(in, TK_PLUS, tok, s1, s3, &t1) < 0 ||
                ar(in, TK_STAR, tok, v, t1, &out->d) < 0)
                return -1;
        } else if (!is_zero(a.d)) { /* b*a^(b-1)*da */
            if (b.v.k && b.v.c == 2.0) {
                if (ar(in, TK_STAR, tok, a.v, a.d, &t1) < 0 ||
                    ar(in, TK_STAR, tok, num(2.0), t1, &out->d) < 0)
                    return -1;
            } else if (ar(in, TK_MINUS, tok, b.v, num(1.0), &t1) < 0 ||
                       ar(in, TK_CARET, tok, a.v, t1, &t2) < 0 ||
                       ar(in, TK_STAR, tok, b.v, t2, &t1) < 0 ||
                       ar(in, TK_STAR, tok, t1, a.d, &out->d) < 0)
                return -1;
        }
        break;
    default: /* comparisons: of constants only, derivative 0 */
        break;
    }
    out->v = v;
    return 0;
}

int lang_dfunc(lang_inst *in, int fn, int tok, ldual a, ldual b,
               ldual *out)
{
    lval v, f, g, h;
    const int two = fn == F_ATAN2 || fn == F_HYPOT;
    if (lang_func(in, fn, a.v, b.v, &v) < 0)
        return -1;
    out->v = v;
    out->d = zero();
    if (is_zero(a.d) && (!two || is_zero(b.d)))
        return 0;
    switch (fn) {
    case F_SQRT: /* da/(2v) */
        if (ar(in, TK_STAR, tok, num(2.0), v, &f) < 0 ||
            ar(in, TK_SLASH, tok, a.d, f, &out->d) < 0)
            return -1;
        return 0;
    case F_EXP: return ar(in, TK_STAR, tok, v, a.d, &out->d);
    case F_LOG: return ar(in, TK_SLASH, tok, a.d, a.v, &out->d);
    case F_SIN:
        if (lang_func(in, F_COS, a.v, zero(), &f) < 0)
            return -1;
        return ar(in, TK_STAR, tok, f, a.d, &out->d);
    case F_COS: /* -sin(a)*da, the sign folded into a subtraction */
        if (lang_func(in, F_SIN, a.v, zero(), &f) < 0 ||
            ar(in, TK_STAR, tok, f, a.d, &g) < 0)
            return -1;
        return ar(in, TK_MINUS, tok, zero(), g, &out->d);
    case F_TAN: /* (1 + v^2) da */
    case F_TANH: /* (1 - v^2) da */
        if (lang_func(in, F_SQR, v, zero(), &f) < 0 ||
            ar(in, fn == F_TAN ? TK_PLUS : TK_MINUS, tok, num(1.0), f, &g) <
                0)
            return -1;
        return ar(in, TK_STAR, tok, g, a.d, &out->d);
    case F_ASIN: /* +-da/sqrt(1 - a^2) */
    case F_ACOS:
        if (lang_func(in, F_SQR, a.v, zero(), &f) < 0 ||
            ar(in, TK_MINUS, tok, num(1.0), f, &g) < 0 ||
            lang_func(in, F_SQRT, g, zero(), &h) < 0 ||
            ar(in, TK_SLASH, tok, a.d, h, &f) < 0)
            return -1;
        if (fn == F_ASIN) {
            out->d = f;
            return 0;
        }
        return ar(in, TK_MINUS, tok, zero(), f, &out->d);
    case F_ATAN: /* da/(1 + a^2) */
        if (lang_func(in, F_SQR, a.v, zero(), &f) < 0 ||
            ar(in, TK_PLUS, tok, num(1.0), f, &g) < 0)
            return -1;
        return ar(in, TK_SLASH, tok, a.d, g, &out->d);
    case F_SINH:
    case F_COSH:
        if (lang_func(in, fn == F_SINH ? F_COSH : F_SINH, a.v, zero(), &f) <
            0)
            return -1;
        return ar(in, TK_STAR, tok, f, a.d, &out->d);
    case F_ABS: /* da*a/|a| */
        if (ar(in, TK_STAR, tok, a.d, a.v, &f) < 0)
            return -1;
        return ar(in, TK_SLASH, tok, f, v, &out->d);
    case F_SQR: /* 2 a da */
        if (ar(in, TK_STAR, tok, a.v, a.d, &f) < 0)
            return -1;
        return ar(in, TK_STAR, tok, num(2.0), f, &out->d);
    case F_ATAN2: { /* atan2(y, x): (x dy - y dx)/(x^2 + y^2) */
        lval p, q, s;
        if (ar(in, TK_STAR, tok, b.v, a.d, &p) < 0 ||
            ar(in, TK_STAR, tok, a.v, b.d, &q) < 0 ||
            ar(in, TK_MINUS, tok, p, q, &f) < 0 ||
            lang_func(in, F_SQR, a.v, zero(), &p) < 0 ||
            lang_func(in, F_SQR, b.v, zero(), &q) < 0 ||
            ar(in, TK_PLUS, tok, p, q, &s) < 0)
            return -1;
        return ar(in, TK_SLASH, tok, f, s, &out->d);
    }
    default: { /* hypot(a, b): (a da + b db)/v */
        lval p, q;
        if (ar(in, TK_STAR, tok, a.v, a.d, &p) < 0 ||
            ar(in, TK_STAR, tok, b.v, b.d, &q) < 0 ||
            ar(in, TK_PLUS, tok, p, q, &f) < 0)
            return -1;
        return ar(in, TK_SLASH, tok, f, v, &out->d);
    }
    }
}

static void scalar(ldvec *out, lval v)
{
    out->n = 1;
    out->x[0].v = v;
    out->x[0].d = zero();
}

/* sum(i in lo..hi, body) of any shape */
static int dsum(lang_inst *in, const node *nd, ldvec *out, int want_d)
{
    const lang_prog *p = in->p;
    long lo, hi, i, keep = in->ival[nd->var];
    uint8_t keep_set = in->ival_set[nd->var];
    int rc = 0, k, first = 1;
    ldvec t;
    if (lang_eval_int(in, p->kids[nd->kids], "the start of a sum", &lo) < 0 ||
        lang_eval_int(in, p->kids[nd->kids + 1], "the end of a sum", &hi) <
            0)
        return -1;
    out->n = nd->shape;
    for (k = 0; k < out->n; k++) {
        out->x[k].v = zero();
        out->x[k].d = zero();
    }
    for (i = lo; i <= hi && rc == 0; i++) {
        in->ival[nd->var] = i;
        in->ival_set[nd->var] = 1;
        if ((rc = lang_eval_d(in, p->kids[nd->kids + 2], &t, want_d)) < 0)
            break;
        if (first) {
            *out = t;
            first = 0;
            continue;
        }
        for (k = 0; k < t.n && rc == 0; k++)
            rc = lang_darith(in, TK_PLUS, nd->tok, out->x[k], t.x[k],
                             &out->x[k]);
    }
    in->ival[nd->var] = keep;
    in->ival_set[nd->var] = keep_set;
    return rc;
}

/* der(e) and the angular velocities, which differentiate their
 * argument: their own derivative would need second derivatives. */
static int differentiating(lang_inst *in, const node *nd, ldvec *out,
                           int want_d)
{
    const lang_prog *p = in->p;
    ldvec a;
    int k;
    if (want_d) {
        lang_fail(in, nd->tok,
                  "der() gives rates; differentiating again would need "
                  "the accelerations, which the equations of motion "
                  "solve for",
                  "der() of an expression that already holds rates (%s() "
                  "inside der())", lang_fns[nd->op].name);
        return -1;
    }
    if (lang_eval_d(in, p->kids[nd->kids], &a, 1) < 0)
        return -1;
    if (nd->op == F_DER) {
        out->n = a.n;
        for (k = 0; k < a.n; k++) {
            out->x[k].v = a.x[k].d;
            out->x[k].d = zero();
        }
        return 0;
    }
    return lang_spatial(in, nd, &a, out);
}

/* Each kind of node in a function of its own: the walker recurses once
 * per level of an expression and of a recurrence among definitions, so
 * its own frame holds no value (a value of 9 components is 0.4 kB). */
#if defined(__GNUC__)
#define NOINLINE __attribute__((noinline))
#else
#define NOINLINE
#endif

static NOINLINE int d_unary(lang_inst *in, const node *nd, ldvec *out,
                            int want_d)
{
    ldvec a;
    int k, rc;
    if ((rc = lang_eval_d(in, in->p->kids[nd->kids], &a, want_d)) < 0)
        return rc;
    if (nd->kind == N_COMP) {
        out->n = 1;
        out->x[0] = a.x[nd->op & 15];
        return 0;
    }
    out->n = a.n;
    for (k = 0; k < a.n && rc == 0; k++) {
        ldual z;
        z.v = zero();
        z.d = zero();
        rc = lang_darith(in, TK_MINUS, nd->tok, z, a.x[k], &out->x[k]);
    }
    return rc;
}

static NOINLINE int d_binary(lang_inst *in, const node *nd, ldvec *out,
                             int want_d)
{
    const lang_prog *p = in->p;
    ldvec a, b;
    if (lang_eval_d(in, p->kids[nd->kids], &a, want_d) < 0 ||
        lang_eval_d(in, p->kids[nd->kids + 1], &b, want_d) < 0)
        return -1;
    return lang_vbinary(in, nd->op, nd->tok, &a, &b, out);
}

static NOINLINE int d_call(lang_inst *in, const node *nd, ldvec *out,
                           int want_d)
{
    const lang_prog *p = in->p;
    ldvec args[3], a;
    int k, rc = 0, gather;
    if (nd->op == F_DER || nd->op == F_ANGVEL_BODY ||
        nd->op == F_ANGVEL_SPACE)
        return differentiating(in, nd, out, want_d);
    if (nd->op < F_FIRST_SPATIAL) { /* a scalar function */
        ldual y;
        y.v = zero();
        y.d = zero();
        if (lang_eval_d(in, p->kids[nd->kids], &args[0], want_d) < 0 ||
            (nd->nkids == 2 &&
             lang_eval_d(in, p->kids[nd->kids + 1], &args[1], want_d) < 0))
            return -1;
        out->n = 1;
        return lang_dfunc(in, nd->op, nd->tok, args[0].x[0],
                          nd->nkids == 2 ? args[1].x[0] : y, &out->x[0]);
    }
    /* at most 3 arguments of any shape; numbers (vec(), diag(), quat(),
     * mat() of 9) are gathered into one value */
    gather = nd->nkids > 3 || nd->op == F_VEC || nd->op == F_DIAG;
    if (gather)
        args[0].n = nd->nkids;
    for (k = 0; k < nd->nkids && rc == 0; k++) {
        if ((rc = lang_eval_d(in, p->kids[nd->kids + k],
                              gather ? &a : &args[k], want_d)) < 0)
            break;
        if (gather)
            args[0].x[k] = a.x[0];
    }
    return rc < 0 ? -1 : lang_spatial(in, nd, args, out);
}

int lang_eval_d(lang_inst *in, int n, ldvec *out, int want_d)
{
    const lang_prog *p = in->p;
    const node *nd = &p->nodes[n];
    int rc = 0;
    if (in->failed)
        return -1;
    /* a scalar's value alone: the scalar walker (its memo, its folding) */
    if (!want_d && nd->shape == SH_SCALAR && nd->kind != N_COMP &&
        !(nd->kind == N_CALL && nd->op >= F_FIRST_SPATIAL)) {
        lval v;
        if (lang_eval(in, n, &v) < 0)
            return -1;
        scalar(out, v);
        return 0;
    }
    if (lang_enter(in, nd->tok) < 0)
        return -1;
    switch (nd->kind) {
    case N_NUM: scalar(out, num(nd->num)); break;
    case N_NAME:
        if (nd->ref == R_DEF)
            rc = lang_def_ref(in, nd, NULL, out, want_d);
        else {
            out->n = 1;
            rc = lang_name_d(in, nd, &out->x[0], want_d);
        }
        break;
    case N_NEG:
    case N_COMP: rc = d_unary(in, nd, out, want_d); break;
    case N_BIN: rc = d_binary(in, nd, out, want_d); break;
    case N_CALL: rc = d_call(in, nd, out, want_d); break;
    case N_SUM: rc = dsum(in, nd, out, want_d); break;
    case N_IF: {
        lval c;
        if ((rc = lang_eval(in, p->kids[nd->kids], &c)) == 0) {
            if (!c.k) {
                lang_fail(in, nd->tok,
                          "it decides the model's structure, so it may use "
                          "numbers, settings and indices, not coordinates "
                          "or parameters",
                          "the condition of if() must be known when the "
                          "file is read");
                rc = -1;
                break;
            }
            rc = lang_eval_d(in,
                             p->kids[nd->kids + (c.c != 0.0 ? 1 : 2)],
                             out, want_d);
        }
        break;
    }
    default:
        lang_fail(in, nd->tok, NULL, "internal error: unknown node");
        rc = -1;
    }
    in->depth--;
    if (rc == 0 && in->r && tp_rec_status(in->r) != TP_OK) {
        lang_fail(in, nd->tok, NULL, "recording %s failed here: %s",
                  in->what, tp_rec_errmsg(in->r));
        return -1;
    }
    return rc < 0 || in->failed ? -1 : 0;
}
