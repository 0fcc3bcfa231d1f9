/* units.c - units of measure. A unit is written in brackets after a
 * parameter's or coordinate's value, in SI symbols without prefixes
 * ("kg", "m/s^2", "N m^2", "N m s/rad"); '/' divides by the one symbol
 * after it. Every expression's dimension is inferred from its leaves: a
 * plain number takes the dimension of what it meets, so 1/2*m*v^2 and
 * x - 1 need no annotation. T, V and L must come out in J, R in W, a
 * force on a coordinate in J per unit of that coordinate, and the two
 * sides of + - and of a comparison must agree. "units off" skips all of
 * it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lang.h"

/* Base dimensions kg, m, s, A, K; exponents doubled. */
typedef struct unit_sym {
    const char *name;
    int8_t e[DIM_N];
} unit_sym;

static const unit_sym unit_syms[] = {
    {"kg", {2, 0, 0, 0, 0}},   {"m", {0, 2, 0, 0, 0}},
    {"s", {0, 0, 2, 0, 0}},    {"A", {0, 0, 0, 2, 0}},
    {"K", {0, 0, 0, 0, 2}},    {"N", {2, 2, -4, 0, 0}},
    {"J", {2, 4, -4, 0, 0}},   {"W", {2, 4, -6, 0, 0}},
    {"Pa", {2, -2, -4, 0, 0}}, {"Hz", {0, 0, -2, 0, 0}},
    {"rad", {0, 0, 0, 0, 0}},  {"V", {2, 4, -6, -2, 0}},
    {"C", {0, 0, 2, 2, 0}},    {"1", {0, 0, 0, 0, 0}},
};
#define N_UNIT_SYMS (int)(sizeof unit_syms / sizeof unit_syms[0])

static const dim dim_energy = {{2, 4, -4, 0, 0}, 0};
static const dim dim_power = {{2, 4, -6, 0, 0}, 0};

int lang_dim_equal(dim a, dim b)
{
    int k;
    if (a.any || b.any)
        return 1;
    for (k = 0; k < DIM_N; k++)
        if (a.e[k] != b.e[k])
            return 0;
    return 1;
}

static int dimensionless(dim a)
{
    dim one;
    memset(&one, 0, sizeof one);
    return lang_dim_equal(a, one);
}

void lang_dim_format(dim d, char *buf, size_t len)
{
    static const char *const base[DIM_N] = {"kg", "m", "s", "A", "K"};
    size_t n = 0;
    int k, any = 0;
    buf[0] = '\0';
    if (d.any) {
        snprintf(buf, len, "a plain number");
        return;
    }
    for (k = 0; k < DIM_N; k++) {
        int e = d.e[k];
        if (e == 0)
            continue;
        n = strlen(buf);
        if (e == 2)
            snprintf(buf + n, len - n, "%s%s", any ? " " : "", base[k]);
        else if (e % 2 == 0)
            snprintf(buf + n, len - n, "%s%s^%d", any ? " " : "", base[k],
                     e / 2);
        else
            snprintf(buf + n, len - n, "%s%s^%g", any ? " " : "", base[k],
                     e / 2.0);
        any = 1;
    }
    if (!any)
        snprintf(buf, len, "1 (no unit)");
    else {
        /* name the common derived units */
        static const struct { const char *name; dim d; } named[] = {
            {"J", {{2, 4, -4, 0, 0}, 0}},  {"N", {{2, 2, -4, 0, 0}, 0}},
            {"W", {{2, 4, -6, 0, 0}, 0}},  {"Pa", {{2, -2, -4, 0, 0}, 0}},
        };
        int j;
        for (j = 0; j < 4; j++)
            if (memcmp(named[j].d.e, d.e, sizeof d.e) == 0) {
                n = strlen(buf);
                snprintf(buf + n, len - n, " (%s)", named[j].name);
            }
    }
}

int lang_unit_parse(const char *text, dim *d, char *bad, size_t badlen)
{
    const char *s = text;
    memset(d, 0, sizeof *d);
    if (bad && badlen)
        bad[0] = '\0';
    for (;;) {
        int sign = 1, k, e = 1;
        char word[32];
        size_t n = 0;
        while (*s == ' ' || *s == '\t' || *s == '*')
            s++;
        if (!*s)
            break;
        if (*s == '/') {
            sign = -1;
            s++;
            while (*s == ' ' || *s == '\t')
                s++;
        }
        while ((s[n] >= 'a' && s[n] <= 'z') || (s[n] >= 'A' && s[n] <= 'Z') ||
               (n == 0 && s[n] == '1'))
            n++;
        if (n == 0 || n >= sizeof word) {
            if (bad)
                snprintf(bad, badlen, "%.*s", (int)(n ? n : 1), s);
            return (int)(s - text) + 1;
        }
        memcpy(word, s, n);
        word[n] = '\0';
        for (k = 0; k < N_UNIT_SYMS; k++)
            if (strcmp(word, unit_syms[k].name) == 0)
                break;
        if (k == N_UNIT_SYMS) {
            if (bad)
                snprintf(bad, badlen, "%s", word);
            return (int)(s - text) + 1;
        }
        s += n;
        if (*s == '^') {
            int neg = 0;
            const char *at = s;
            s++;
            if (*s == '-' || *s == '+')
                neg = *s++ == '-';
            if (!(*s >= '0' && *s <= '9')) {
                if (bad)
                    snprintf(bad, badlen, "%.*s", (int)(s - at + 1), at);
                return (int)(at - text) + 1;
            }
            e = 0;
            while (*s >= '0' && *s <= '9' && e < 100)
                e = 10 * e + (*s++ - '0');
            if (neg)
                e = -e;
        }
        {
            const unit_sym *u = &unit_syms[k];
            int j;
            for (j = 0; j < DIM_N; j++) {
                int v = d->e[j] + sign * e * u->e[j];
                if (v > 100 || v < -100) {
                    if (bad)
                        snprintf(bad, badlen, "%s", word);
                    return (int)(s - text);
                }
                d->e[j] = (int8_t)v;
            }
        }
    }
    return 0;
}

/* ---- inference --------------------------------------------------------- */

typedef struct checker {
    lang_prog *p;
    int depth;
    char *err;
    size_t len;
} checker;

static int dim_of(checker *ck, int n, dim *out);

static dim any_dim(void)
{
    dim d;
    memset(&d, 0, sizeof d);
    d.any = 1;
    return d;
}

static dim no_dim(void)
{
    dim d;
    memset(&d, 0, sizeof d);
    return d;
}

static int mismatch(checker *ck, int tok, dim a, dim b, const char *what)
{
    char da[80], db[80];
    lang_dim_format(a, da, sizeof da);
    lang_dim_format(b, db, sizeof db);
    lang_diag(ck->p, tok, ck->err, ck->len,
              "check the units of both sides (or put `units off` at the top "
              "of the file)",
              "units do not agree: %s %s %s", da, what, db);
    return -1;
}

/* The value of an exponent made of numbers only, else NaN. */
static double literal(const lang_prog *p, int n)
{
    const node *nd = &p->nodes[n];
    double a, b;
    switch (nd->kind) {
    case N_NUM: return nd->num;
    case N_NEG: return -literal(p, p->kids[nd->kids]);
    case N_BIN:
        a = literal(p, p->kids[nd->kids]);
        b = literal(p, p->kids[nd->kids + 1]);
        switch (nd->op) {
        case TK_PLUS: return a + b;
        case TK_MINUS: return a - b;
        case TK_STAR: return a * b;
        case TK_SLASH: return a / b;
        default: return NAN;
        }
    default: return NAN;
    }
}

static int def_dim(checker *ck, int k, dim *out)
{
    lang_prog *p = ck->p;
    sym *s = &p->syms[k];
    dim acc = any_dim();
    int c, first = -1;
    if (s->dim_state == 2) {
        *out = s->d;
        return 0;
    }
    if (s->dim_state == 1) { /* a recurrence: its other clauses decide */
        *out = any_dim();
        return 0;
    }
    s->dim_state = 1;
    for (c = s->first_clause; c >= 0; c = p->clauses[c].next) {
        dim d;
        if (dim_of(ck, p->clauses[c].body, &d) < 0)
            return -1;
        if (!lang_dim_equal(acc, d)) {
            char da[80], db[80], hint[200];
            lang_dim_format(d, da, sizeof da);
            lang_dim_format(acc, db, sizeof db);
            snprintf(hint, sizeof hint, "on line %d it is %s",
                     p->toks[p->clauses[first].tok].line, db);
            lang_diag(p, p->clauses[c].tok, ck->err, ck->len, hint,
                      "%s is %s here but not on line %d", s->name, da,
                      p->toks[p->clauses[first].tok].line);
            return -1;
        }
        if (!d.any) {
            acc = d;
            first = c;
        } else if (first < 0) {
            first = c;
        }
    }
    s = &p->syms[k];
    s->d = acc;
    s->dim_state = 2;
    *out = acc;
    return 0;
}

/* a * b (add 1) or a / b (add -1) */
static int dim_mul(checker *ck, int tok, dim a, dim b, int sign, dim *out)
{
    int k;
    if (a.any && b.any) {
        *out = any_dim();
        return 0;
    }
    if (a.any)
        a = no_dim();
    if (b.any)
        b = no_dim();
    for (k = 0; k < DIM_N; k++) {
        int v = a.e[k] + sign * b.e[k];
        if (v > 100 || v < -100) {
            lang_diag(ck->p, tok, ck->err, ck->len, NULL,
                      "a unit power beyond 50");
            return -1;
        }
        a.e[k] = (int8_t)v;
    }
    *out = a;
    return 0;
}

/* Kid k of node n must be a pure number (an angle, a rotation). */
static int pure_kid(checker *ck, int n, int k, dim *d)
{
    const lang_prog *p = ck->p;
    const node *nd = &p->nodes[n];
    int kid = p->kids[nd->kids + k];
    char da[80];
    if (dim_of(ck, kid, d) < 0)
        return -1;
    if (dimensionless(*d))
        return 0;
    lang_dim_format(*d, da, sizeof da);
    lang_diag(p, p->nodes[kid].tok, ck->err, ck->len,
              nd->op == F_ANGVEL_BODY || nd->op == F_ANGVEL_SPACE
                  ? "a rotation matrix is a pure number: build it with "
                    "rotx(), roty(), rotz(), rot() or quat()"
                  : "angles are in rad, quaternions pure numbers",
              "%s() needs a pure number, not %s", lang_fns[nd->op].name,
              da);
    return -1;
}

/* The functions of vectors and matrices: every component of a value has
 * the one unit of the value. */
static int spatial_dim(checker *ck, int n, dim *out)
{
    lang_prog *p = ck->p;
    const node *nd = &p->nodes[n];
    const int nk = nd->nkids, fn = nd->op;
    dim a, b;
    int k;
    switch (fn) {
    case F_VEC:
    case F_MAT:
    case F_DIAG:
        *out = any_dim();
        for (k = 0; k < nk; k++) {
            if (dim_of(ck, p->kids[p->nodes[n].kids + k], &a) < 0)
                return -1;
            if (!lang_dim_equal(*out, a))
                return mismatch(ck, p->nodes[p->kids[p->nodes[n].kids + k]].tok,
                                a, *out,
                                "in one vector or matrix with");
            if (!a.any)
                *out = a;
        }
        return 0;
    case F_DOT:
    case F_CROSS:
        if (dim_of(ck, p->kids[nd->kids], &a) < 0 ||
            dim_of(ck, p->kids[p->nodes[n].kids + 1], &b) < 0)
            return -1;
        return dim_mul(ck, p->nodes[n].tok, a, b, 1, out);
    case F_NORM:
    case F_TRANSPOSE:
        return dim_of(ck, p->kids[nd->kids], out);
    case F_ROT:
        if (dim_of(ck, p->kids[nd->kids], &a) < 0 || pure_kid(ck, n, 1, &b))
            return -1;
        *out = no_dim();
        return 0;
    case F_DER:
        if (dim_of(ck, p->kids[nd->kids], &a) < 0)
            return -1;
        b = no_dim();
        b.e[2] = 2;
        return dim_mul(ck, p->nodes[n].tok, a.any ? no_dim() : a, b, -1,
                       out);
    case F_ANGVEL_BODY:
    case F_ANGVEL_SPACE:
        if (pure_kid(ck, n, 0, &a) < 0)
            return -1;
        *out = no_dim();
        out->e[2] = -2;
        return 0;
    default: /* rotx roty rotz quat: of pure numbers, pure numbers */
        for (k = 0; k < nk; k++)
            if (pure_kid(ck, n, k, &a) < 0)
                return -1;
        *out = no_dim();
        return 0;
    }
}

/* The multiplier of constraint k: C^T lambda is a generalized force
 * (J per unit of q), C = dphi/dq, so lambda is in J per unit of phi; a
 * velocity constraint's C = dpsi/dqd (per unit of q/s), so J per unit
 * of psi per s (a rolling constraint in m/s: N). */
static int mult_dim(checker *ck, int k, dim *out)
{
    const sym *y = &ck->p->syms[k];
    dim d;
    int i;
    if (dim_of(ck, y->value, &d) < 0)
        return -1;
    if (d.any)
        d = no_dim();
    *out = no_dim();
    out->e[0] = 2;  /* kg */
    out->e[1] = 4;  /* m^2 */
    out->e[2] = -4; /* s^-2 */
    for (i = 0; i < DIM_N; i++)
        out->e[i] = (int8_t)(out->e[i] - d.e[i]);
    if (y->velocity)
        out->e[2] = (int8_t)(out->e[2] - 2);
    return 0;
}

static int dim_of(checker *ck, int n, dim *out)
{
    lang_prog *p = ck->p;
    const node *nd = &p->nodes[n];
    dim a, b;
    int k, rc = 0;
    if (++ck->depth > LANG_MAX_DEPTH) {
        lang_diag(p, nd->tok, ck->err, ck->len, NULL,
                  "definitions refer to one another more than %d deep",
                  LANG_MAX_DEPTH);
        return -1;
    }
    switch (nd->kind) {
    case N_NUM:
        *out = any_dim();
        break;
    case N_NAME:
        switch (nd->ref) {
        case R_PARAM:
        case R_COORD: *out = p->syms[nd->sym].unit_dim; break;
        case R_RATE:
            *out = p->syms[nd->sym].unit_dim;
            out->e[2] = (int8_t)(out->e[2] - 2);
            break;
        case R_TIME: *out = no_dim(); out->e[2] = 2; break;
        case R_DEF: rc = def_dim(ck, nd->sym, out); break;
        case R_MULT: rc = mult_dim(ck, nd->sym, out); break;
        default: *out = any_dim(); break;
        }
        break;
    case N_NEG:
        rc = dim_of(ck, p->kids[nd->kids], out);
        break;
    case N_BIN:
        if (dim_of(ck, p->kids[nd->kids], &a) < 0 ||
            dim_of(ck, p->kids[nd->kids + 1], &b) < 0) {
            rc = -1;
            break;
        }
        switch (nd->op) {
        case TK_PLUS:
        case TK_MINUS:
            if (!lang_dim_equal(a, b))
                rc = mismatch(ck, nd->tok, a, b,
                              nd->op == TK_PLUS ? "plus" : "minus");
            *out = a.any ? b : a;
            break;
        case TK_STAR:
        case TK_SLASH:
            if (a.any && b.any) {
                *out = any_dim();
                break;
            }
            if (a.any)
                a = no_dim();
            if (b.any)
                b = no_dim();
            for (k = 0; k < DIM_N; k++) {
                int v = nd->op == TK_STAR ? a.e[k] + b.e[k] : a.e[k] - b.e[k];
                if (v > 100 || v < -100) {
                    lang_diag(p, nd->tok, ck->err, ck->len, NULL,
                              "a unit power beyond 50");
                    return -1;
                }
                a.e[k] = (int8_t)v;
            }
            *out = a;
            break;
        case TK_CARET: {
            double r;
            if (!dimensionless(b)) {
                char db[80];
                lang_dim_format(b, db, sizeof db);
                lang_diag(p, nd->tok, ck->err, ck->len, NULL,
                          "an exponent must be a pure number, not %s", db);
                return -1;
            }
            if (a.any || dimensionless(a)) {
                *out = a;
                break;
            }
            r = literal(p, p->kids[nd->kids + 1]);
            for (k = 0; k < DIM_N && isfinite(r); k++) {
                double v = a.e[k] * r;
                if (v != floor(v) || fabs(v) > 100)
                    r = NAN;
                else
                    a.e[k] = (int8_t)v;
            }
            if (!isfinite(r)) {
                char da[80];
                lang_dim_format(a, da, sizeof da);
                lang_diag(p, nd->tok, ck->err, ck->len,
                          "write the power as a number, as in x^2 or "
                          "x^(1/2)",
                          "a value with units (%s) raised to a power that "
                          "is not a fixed number, or gives a fractional "
                          "unit", da);
                return -1;
            }
            *out = a;
            break;
        }
        default: /* comparisons */
            if (!lang_dim_equal(a, b))
                rc = mismatch(ck, nd->tok, a, b, "compared with");
            *out = any_dim();
            break;
        }
        break;
    case N_COMP:
        rc = dim_of(ck, p->kids[nd->kids], out);
        break;
    case N_CALL:
        if (nd->op >= F_FIRST_SPATIAL) {
            rc = spatial_dim(ck, n, out);
            break;
        }
        if (dim_of(ck, p->kids[nd->kids], &a) < 0) {
            rc = -1;
            break;
        }
        if (nd->nkids == 2 && dim_of(ck, p->kids[nd->kids + 1], &b) < 0) {
            rc = -1;
            break;
        }
        switch (nd->op) {
        case F_SQRT:
            for (k = 0; k < DIM_N && !a.any; k++) {
                if (a.e[k] % 2 != 0) {
                    char da[80];
                    lang_dim_format(a, da, sizeof da);
                    lang_diag(p, nd->tok, ck->err, ck->len, NULL,
                              "the square root of %s has a fractional "
                              "unit", da);
                    return -1;
                }
                a.e[k] = (int8_t)(a.e[k] / 2);
            }
            *out = a;
            break;
        case F_SQR:
            for (k = 0; k < DIM_N && !a.any; k++) {
                if (a.e[k] > 50 || a.e[k] < -50) {
                    lang_diag(p, nd->tok, ck->err, ck->len, NULL,
                              "a unit power beyond 50");
                    return -1;
                }
                a.e[k] = (int8_t)(2 * a.e[k]);
            }
            *out = a;
            break;
        case F_ABS: *out = a; break;
        case F_HYPOT:
        case F_ATAN2:
            if (!lang_dim_equal(a, b))
                return mismatch(ck, nd->tok, a, b, "and");
            *out = nd->op == F_HYPOT ? (a.any ? b : a) : no_dim();
            break;
        default:
            if (!dimensionless(a)) {
                char da[80];
                lang_dim_format(a, da, sizeof da);
                lang_diag(p, nd->tok, ck->err, ck->len,
                          "divide by a reference value to make it a pure "
                          "number",
                          "%s() needs a pure number, not %s",
                          lang_fns[nd->op].name, da);
                return -1;
            }
            *out = a.any ? any_dim() : no_dim();
            break;
        }
        break;
    case N_SUM:
        rc = dim_of(ck, p->kids[nd->kids + 2], out);
        break;
    case N_IF:
        if (dim_of(ck, p->kids[nd->kids + 1], &a) < 0 ||
            dim_of(ck, p->kids[nd->kids + 2], &b) < 0) {
            rc = -1;
            break;
        }
        if (!lang_dim_equal(a, b))
            rc = mismatch(ck, nd->tok, a, b, "or");
        *out = a.any ? b : a;
        break;
    default:
        *out = any_dim();
    }
    ck->depth--;
    return rc;
}

/* The dimension of body must be want (any passes). */
static int expect_dim(checker *ck, int body, int tok, dim want,
                      const char *what, const char *hint)
{
    dim d;
    char dd[80], dw[80];
    if (dim_of(ck, body, &d) < 0)
        return -1;
    if (lang_dim_equal(d, want))
        return 0;
    lang_dim_format(d, dd, sizeof dd);
    lang_dim_format(want, dw, sizeof dw);
    lang_diag(ck->p, tok, ck->err, ck->len, hint, "%s is in %s, not in %s",
              what, dd, dw);
    return -1;
}

int lang_units(lang_prog *p, char *err, size_t len)
{
    checker ck;
    int k;
    memset(&ck, 0, sizeof ck);
    ck.p = p;
    ck.err = err;
    ck.len = len;
    for (k = 0; k < p->nsyms; k++) {
        sym *s = &p->syms[k];
        char bad[40];
        int at;
        if (s->kind != S_PARAM && s->kind != S_COORD && s->kind != S_PROBE)
            continue;
        if (s->unit_tok < 0) {
            if (p->units_off || s->kind == S_PROBE)
                continue;
            lang_diag(p, s->tok, err, len,
                      "write it after the value, as in `param m = 1 [kg]` "
                      "([1] for a pure number), or put `units off` at the "
                      "top of the file",
                      "%s %s has no unit",
                      s->kind == S_PARAM ? "parameter" : "coordinate",
                      s->name);
            return -1;
        }
        at = lang_unit_parse(s->unit, &s->unit_dim, bad, sizeof bad);
        if (at != 0) {
            const token *t = &p->toks[s->unit_tok];
            lang_diag_at(p, t->line, t->col + at, err, len,
                         "units are SI symbols without prefixes: kg m s A K "
                         "N J W Pa Hz rad V C, and 1; powers as m^2 or "
                         "s^-1, '/' divides by the next symbol",
                         "'%s' is not a unit this file can use", bad);
            return -1;
        }
    }
    if (p->units_off)
        return 0;
    for (k = 0; k < p->nstmts; k++) {
        const energy_stmt *e = &p->stmts[k];
        char hint[400];
        switch (e->kind) {
        case ST_T:
        case ST_V:
        case ST_L:
            if (expect_dim(&ck, e->body, e->tok, dim_energy,
                           e->kind == ST_T   ? "the kinetic energy T"
                           : e->kind == ST_V ? "the potential energy V"
                                             : "the Lagrangian L",
                           "an energy is in J = kg m^2 s^-2") < 0)
                return -1;
            break;
        case ST_R:
            if (expect_dim(&ck, e->body, e->tok, dim_power,
                           "the dissipation function R",
                           "R is a power, like 1/2*c*x_dot^2: in W = J/s") <
                0)
                return -1;
            break;
        case ST_FORCE: {
            const sym *q = &p->syms[p->nodes[e->target].sym];
            dim want = dim_energy;
            char du[80];
            int j;
            for (j = 0; j < DIM_N; j++)
                want.e[j] = (int8_t)(want.e[j] - q->unit_dim.e[j]);
            lang_dim_format(want, du, sizeof du);
            snprintf(hint, sizeof hint,
                     "the force conjugate to %s [%s] is in J/(%s) = %s",
                     q->name, q->unit, q->unit, du);
            if (expect_dim(&ck, e->body, e->tok, want, "this force", hint) <
                0)
                return -1;
            break;
        }
        }
    }
    for (k = 0; k < p->nsyms; k++) {
        sym *s = &p->syms[k];
        dim d;
        if (s->kind == S_CONSTRAINT && dim_of(&ck, s->value, &d) < 0)
            return -1;
        if (s->kind == S_PROBE) {
            if (s->unit_tok >= 0) {
                if (expect_dim(&ck, s->value, s->tok, s->unit_dim,
                               "the probe", NULL) < 0)
                    return -1;
            } else if (dim_of(&ck, s->value, &d) < 0) {
                return -1;
            }
        }
        if (s->kind == S_DEF && def_dim(&ck, k, &d) < 0)
            return -1;
    }
    return 0;
}

int lang_dim_of(lang_prog *p, int n, dim *out, char *err, size_t len)
{
    checker ck;
    memset(&ck, 0, sizeof ck);
    ck.p = p;
    ck.err = err;
    ck.len = len;
    return dim_of(&ck, n, out);
}
