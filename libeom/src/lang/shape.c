/* shape.c - the shape of every expression: a scalar, a 3-vector or a 3x3
 * matrix. Shapes are fixed when the file is read (a vector is three
 * scalars on the tape, never a run-time object), so every mismatch is
 * an error at its line and column before anything is recorded: a vector
 * where a scalar is needed and the reverse, a product of two vectors, a
 * component that the value does not have. A definition's shape is that
 * of its clauses, which must agree; a recurrence's reference to itself
 * takes the shape of its other clauses (SH_ANY until known). Runs after
 * resolve.c, before units.c, whether or not units are checked. */
#include <stdio.h>
#include <string.h>

#include "lang.h"

typedef struct shaper {
    lang_prog *p;
    int depth;
    char *err;
    size_t len;
} shaper;

const char *lang_shape_name(int shape)
{
    switch (shape) {
    case SH_SCALAR: return "a scalar";
    case SH_VEC: return "a vector";
    case SH_MAT: return "a matrix";
    default: return "a value of unknown shape";
    }
}

static int shape_of(shaper *sh, int n, int *out);

/* Shapes a and b as one (SH_ANY meets anything); -1 when they differ. */
static int meet(int a, int b)
{
    if (a == SH_ANY)
        return b;
    if (b == SH_ANY || a == b)
        return a;
    return -1;
}

static int bad(shaper *sh, int tok, const char *hint, const char *fmt,
               const char *a, const char *b)
{
    char msg[300];
    snprintf(msg, sizeof msg, fmt, a, b);
    lang_diag(sh->p, tok, sh->err, sh->len, hint, "%s", msg);
    return -1;
}

/* The shape of kid k of node n must be want (SH_ANY passes). */
static int want(shaper *sh, int n, int k, int shape, const char *what)
{
    const lang_prog *p = sh->p;
    int kid = p->kids[p->nodes[n].kids + k], s;
    if (shape_of(sh, kid, &s) < 0)
        return -1;
    if (s == SH_ANY || s == shape)
        return 0;
    lang_diag(p, p->nodes[kid].tok, sh->err, sh->len,
              shape == SH_SCALAR
                  ? "take a component (.x, .y, .z), dot() or norm() to get "
                    "a number"
                  : NULL,
              "%s needs %s, not %s", what, lang_shape_name(shape),
              lang_shape_name(s));
    return -1;
}

static int def_shape(shaper *sh, int k, int *out)
{
    lang_prog *p = sh->p;
    sym *s = &p->syms[k];
    int c, acc = SH_ANY, first = -1;
    if (s->shape_state == 2) {
        *out = s->shape;
        return 0;
    }
    if (s->shape_state == 1) { /* a recurrence: its other clauses decide */
        *out = SH_ANY;
        return 0;
    }
    s->shape_state = 1;
    for (c = s->first_clause; c >= 0; c = p->clauses[c].next) {
        int d, m;
        if (shape_of(sh, p->clauses[c].body, &d) < 0)
            return -1;
        if ((m = meet(acc, d)) < 0) {
            char hint[120];
            snprintf(hint, sizeof hint, "on line %d it is %s",
                     p->toks[p->clauses[first].tok].line,
                     lang_shape_name(acc));
            lang_diag(p, p->clauses[c].tok, sh->err, sh->len, hint,
                      "%s is %s here but not on line %d", p->syms[k].name,
                      lang_shape_name(d),
                      p->toks[p->clauses[first].tok].line);
            return -1;
        }
        if (d != SH_ANY || first < 0)
            first = c;
        acc = m;
    }
    s = &p->syms[k];
    if (acc == SH_ANY) {
        /* every clause met a definition still in progress (definitions
         * that refer to each other): decided when that one is */
        s->shape_state = 0;
        *out = SH_ANY;
        return 0;
    }
    s->shape = (uint8_t)acc;
    s->shape_state = 2;
    *out = s->shape;
    return 0;
}

static int binary(shaper *sh, int n, int *out)
{
    lang_prog *p = sh->p;
    const node *nd = &p->nodes[n];
    int a, b, tok = nd->tok;
    char ta[8];
    if (shape_of(sh, p->kids[nd->kids], &a) < 0 ||
        shape_of(sh, p->kids[p->nodes[n].kids + 1], &b) < 0)
        return -1;
    nd = &p->nodes[n];
    lang_tok_text(p, tok, ta, sizeof ta);
    switch (nd->op) {
    case TK_PLUS:
    case TK_MINUS:
        if ((*out = meet(a, b)) < 0)
            return bad(sh, tok,
                       "both sides of + and - have the same shape",
                       "%s plus or minus %s", lang_shape_name(a),
                       lang_shape_name(b));
        return 0;
    case TK_STAR:
        if (a == SH_ANY || b == SH_ANY) {
            /* a recurrence: a scalar factor keeps the other's shape */
            *out = a == SH_SCALAR ? b : b == SH_SCALAR ? a : SH_ANY;
            return 0;
        }
        if (a == SH_SCALAR || b == SH_SCALAR) {
            *out = a == SH_SCALAR ? b : a;
            return 0;
        }
        if (a == SH_MAT) {
            *out = b; /* M*v is a vector, M*N a matrix */
            return 0;
        }
        if (b == SH_VEC)
            return bad(sh, tok,
                       "write dot(a, b) for the scalar product or "
                       "cross(a, b) for the vector product",
                       "%s times %s", lang_shape_name(a),
                       lang_shape_name(b));
        return bad(sh, tok,
                   "a vector is a column: write transpose(M)*v for v^T M",
                   "%s times %s", lang_shape_name(a), lang_shape_name(b));
    case TK_SLASH:
        if (b != SH_SCALAR && b != SH_ANY)
            return bad(sh, p->nodes[p->kids[nd->kids + 1]].tok, NULL,
                       "division by %s%s", lang_shape_name(b), "");
        *out = a;
        return 0;
    default: /* ^ and comparisons: numbers only */
        if ((a != SH_SCALAR && a != SH_ANY) ||
            (b != SH_SCALAR && b != SH_ANY))
            return bad(sh, tok,
                       nd->op == TK_CARET
                           ? "write dot(v, v) or norm(v)^2 for a vector's "
                             "square; M*M for a matrix's"
                           : "compare components (.x) or norms",
                       "'%s' needs numbers, not %s",
                       ta, lang_shape_name(a != SH_SCALAR && a != SH_ANY
                                               ? a
                                               : b));
        *out = SH_SCALAR;
        return 0;
    }
}

/* What each function takes and gives. */
static int call(shaper *sh, int n, int *out)
{
    lang_prog *p = sh->p;
    const node *nd = &p->nodes[n];
    const int fn = nd->op, nk = nd->nkids;
    char what[48];
    int k, s;
    snprintf(what, sizeof what, "%s()", lang_fns[fn].name);
    switch (fn) {
    case F_VEC:
    case F_DIAG:
    case F_QUAT:
    case F_ROTX:
    case F_ROTY:
    case F_ROTZ:
        for (k = 0; k < nk; k++)
            if (want(sh, n, k, SH_SCALAR, what) < 0)
                return -1;
        *out = fn == F_VEC ? SH_VEC : SH_MAT;
        return 0;
    case F_MAT:
        for (k = 0; k < nk; k++)
            if (want(sh, n, k, nk == 9 ? SH_SCALAR : SH_VEC,
                     nk == 9 ? "mat() of 9 numbers" : "mat() of 3 rows") <
                0)
                return -1;
        *out = SH_MAT;
        return 0;
    case F_DOT:
    case F_CROSS:
        for (k = 0; k < 2; k++)
            if (want(sh, n, k, SH_VEC, what) < 0)
                return -1;
        *out = fn == F_DOT ? SH_SCALAR : SH_VEC;
        return 0;
    case F_NORM:
        if (want(sh, n, 0, SH_VEC, what) < 0)
            return -1;
        *out = SH_SCALAR;
        return 0;
    case F_TRANSPOSE:
    case F_ANGVEL_BODY:
    case F_ANGVEL_SPACE:
        if (want(sh, n, 0, SH_MAT, what) < 0)
            return -1;
        *out = fn == F_TRANSPOSE ? SH_MAT : SH_VEC;
        return 0;
    case F_ROT:
        if (want(sh, n, 0, SH_VEC, "rot()'s axis") < 0 ||
            want(sh, n, 1, SH_SCALAR, "rot()'s angle") < 0)
            return -1;
        *out = SH_MAT;
        return 0;
    case F_DER:
        if (shape_of(sh, p->kids[nd->kids], &s) < 0)
            return -1;
        *out = s;
        return 0;
    default: /* the scalar functions */
        for (k = 0; k < nk; k++)
            if (want(sh, n, k, SH_SCALAR, what) < 0)
                return -1;
        *out = SH_SCALAR;
        return 0;
    }
}

static int shape_of(shaper *sh, int n, int *out)
{
    lang_prog *p = sh->p;
    const node *nd = &p->nodes[n];
    int a, b, k, rc = 0;
    if (++sh->depth > LANG_MAX_DEPTH) {
        lang_diag(p, nd->tok, sh->err, sh->len, NULL,
                  "definitions refer to one another more than %d deep",
                  LANG_MAX_DEPTH);
        return -1;
    }
    switch (nd->kind) {
    case N_NAME:
        for (k = 0; k < nd->nkids && rc == 0; k++)
            rc = want(sh, n, k, SH_SCALAR, "an index");
        if (rc == 0 && nd->ref == R_DEF)
            rc = def_shape(sh, nd->sym, out);
        else
            *out = SH_SCALAR;
        break;
    case N_NEG: rc = shape_of(sh, p->kids[nd->kids], out); break;
    case N_BIN: rc = binary(sh, n, out); break;
    case N_CALL: rc = call(sh, n, out); break;
    case N_SUM:
        if ((rc = want(sh, n, 0, SH_SCALAR, "the start of a sum")) == 0 &&
            (rc = want(sh, n, 1, SH_SCALAR, "the end of a sum")) == 0)
            rc = shape_of(sh, p->kids[nd->kids + 2], out);
        break;
    case N_IF:
        if ((rc = want(sh, n, 0, SH_SCALAR, "the condition of if()")) < 0 ||
            (rc = shape_of(sh, p->kids[nd->kids + 1], &a)) < 0 ||
            (rc = shape_of(sh, p->kids[p->nodes[n].kids + 2], &b)) < 0)
            break;
        if ((*out = meet(a, b)) < 0)
            rc = bad(sh, p->nodes[n].tok,
                     "both values of if() have the same shape",
                     "if() gives %s or %s", lang_shape_name(a),
                     lang_shape_name(b));
        break;
    case N_COMP:
        if ((rc = shape_of(sh, p->kids[nd->kids], &a)) < 0)
            break;
        nd = &p->nodes[n];
        if (a == SH_SCALAR ||
            (a == SH_VEC && nd->op >= 16) || (a == SH_MAT && nd->op < 16)) {
            char c[8];
            lang_tok_text(p, nd->tok, c, sizeof c);
            rc = bad(sh, nd->tok,
                     a == SH_SCALAR
                         ? "only vectors and matrices have components"
                         : a == SH_VEC
                               ? "a vector's components are .x .y .z"
                               : "a matrix's components are .xx .xy .xz "
                                 ".yx ... .zz (row, then column)",
                     "%s has no component .%s", lang_shape_name(a), c);
            break;
        }
        *out = SH_SCALAR;
        break;
    default: *out = SH_SCALAR; break;
    }
    sh->depth--;
    if (rc == 0)
        p->nodes[n].shape = (uint8_t)*out;
    return rc;
}

/* Node body must be a scalar: what names it in the message. */
static int scalar_body(shaper *sh, int body, int tok, const char *what)
{
    int s;
    if (body < 0)
        return 0;
    if (shape_of(sh, body, &s) < 0)
        return -1;
    if (s == SH_SCALAR || s == SH_ANY)
        return 0;
    lang_diag(sh->p, tok, sh->err, sh->len,
              "take a component (.x, .y, .z), dot() or norm() to get a "
              "number",
              "%s is %s; it must be a scalar", what, lang_shape_name(s));
    return -1;
}

static int binders(shaper *sh, const binder *b, int nb)
{
    int k;
    for (k = 0; k < nb; k++)
        if (b[k].var < 0 ? scalar_body(sh, b[k].fixed, b[k].tok, "an index")
                         : scalar_body(sh, b[k].lo, b[k].tok, "a range") ||
                               scalar_body(sh, b[k].hi, b[k].tok, "a range"))
            return -1;
    return 0;
}

int lang_shapes(lang_prog *p, char *err, size_t len)
{
    shaper sh;
    int k, s;
    memset(&sh, 0, sizeof sh);
    sh.p = p;
    sh.err = err;
    sh.len = len;
    for (k = 0; k < p->nstmts; k++) {
        const energy_stmt *e = &p->stmts[k];
        static const char *const what[] = {
            "the kinetic energy T", "the potential energy V",
            "the Lagrangian L", "the dissipation function R", "a force"};
        if (binders(&sh, e->idx, e->nidx) < 0 ||
            scalar_body(&sh, e->body, e->tok, what[e->kind]) < 0)
            return -1;
    }
    for (k = 0; k < p->nclauses; k++)
        if (binders(&sh, p->clauses[k].idx, p->clauses[k].nidx) < 0)
            return -1;
    for (k = 0; k < p->nsyms; k++) {
        sym *y = &p->syms[k];
        char what[LANG_MAX_NAME + 40];
        if (y->kind == S_SETTING) {
            if (scalar_body(&sh, y->value, y->tok, "a setting") < 0 ||
                (y->lo >= 0 &&
                 (scalar_body(&sh, y->lo, y->tok, "a setting's range") < 0 ||
                  scalar_body(&sh, p->syms[k].hi, y->tok,
                              "a setting's range") < 0)))
                return -1;
            continue;
        }
        if (y->kind == S_DEF) {
            if (def_shape(&sh, k, &s) < 0)
                return -1;
            y = &p->syms[k];
            if (s == SH_ANY) { /* it only refers to itself: a scalar */
                y->shape = SH_SCALAR;
                y->shape_state = 2;
            }
            continue;
        }
        if (binders(&sh, p->syms[k].idx, p->syms[k].nidx) < 0)
            return -1;
        y = &p->syms[k];
        if (y->kind == S_PROBE || y->kind == S_CONSTRAINT) {
            if (shape_of(&sh, y->value, &s) < 0)
                return -1;
            y = &p->syms[k];
            y->shape = (uint8_t)(s == SH_ANY ? SH_SCALAR : s);
            y->shape_state = 2;
            if (y->kind == S_CONSTRAINT && s == SH_MAT) {
                lang_diag(p, y->tok, err, len,
                          "a vector constraint gives a row per component; "
                          "write the rows of a matrix as vectors",
                          "the constraint %s is a matrix", y->name);
                return -1;
            }
            continue;
        }
        snprintf(what, sizeof what, "the %s of %s",
                 y->kind == S_PARAM
                                               ? "value"
                                               : "initial value",
                 y->name);
        if (scalar_body(&sh, y->value, y->tok, what) < 0 ||
            scalar_body(&sh, p->syms[k].rate, p->syms[k].tok, what) < 0)
            return -1;
    }
    /* every definition's shape is known now: a recurrence's bodies met
     * their own definition before it was, so walk them again to give
     * each node its final shape (the recorder relies on it) */
    for (k = 0; k < p->nclauses; k++)
        if (shape_of(&sh, p->clauses[k].body, &s) < 0)
            return -1;
    return 0;
}
