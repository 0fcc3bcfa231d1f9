/* rates.c - a velocity constraint must be linear in the rates, A(q, t) qd
 * + b(q, t) = 0. Checked on the expression, when the file is read, so
 * the error points at the term that is not: every node gets its degree
 * in the rates (0: none, 1: linear, 2: more), from the rules of algebra
 * (a product adds degrees, a function of a rate or a division by one is
 * not linear, der() of a position is linear). The check is structural:
 * x_dot*x_dot/x_dot is refused although it is linear. libeom checks the
 * recorded rows again when the system is built. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lang.h"

typedef struct rater {
    lang_prog *p;
    int depth;
    int bad; /* node where the degree first passed 1, or -1 */
    uint8_t *def_deg; /* [nsyms]: degree + 1 of a definition, 0 unknown */
} rater;

static int degree(rater *ra, int n);

static int at_most_one(rater *ra, int n, int d)
{
    if (d > 1 && ra->bad < 0)
        ra->bad = n;
    return d > 1 ? 2 : d;
}

static int def_degree(rater *ra, int k)
{
    const lang_prog *p = ra->p;
    int c, d = 0;
    if (ra->def_deg[k])
        return ra->def_deg[k] - 1;
    ra->def_deg[k] = 1; /* a recurrence's own reference: its other clauses */
    for (c = p->syms[k].first_clause; c >= 0; c = p->clauses[c].next) {
        int e = degree(ra, p->clauses[c].body);
        d = e > d ? e : d;
    }
    ra->def_deg[k] = (uint8_t)(d + 1);
    return d;
}

static int degree(rater *ra, int n)
{
    const lang_prog *p = ra->p;
    const node *nd = &p->nodes[n];
    int a = 0, b = 0, k, d = 0;
    if (++ra->depth > LANG_MAX_DEPTH) {
        ra->depth--;
        return 0; /* reported by the other passes */
    }
    switch (nd->kind) {
    case N_NAME:
        d = nd->ref == R_RATE ? 1
            : nd->ref == R_DEF ? def_degree(ra, nd->sym)
                               : 0;
        break;
    case N_NEG:
    case N_COMP: d = degree(ra, p->kids[nd->kids]); break;
    case N_BIN:
        a = degree(ra, p->kids[nd->kids]);
        b = degree(ra, p->kids[nd->kids + 1]);
        switch (nd->op) {
        case TK_PLUS:
        case TK_MINUS: d = a > b ? a : b; break;
        case TK_STAR: d = a + b; break;
        case TK_SLASH: d = b > 0 ? 2 : a; break;
        default: { /* ^: a rate to the power 1 only */
            const node *e = &p->nodes[p->kids[nd->kids + 1]];
            if (b > 0)
                d = 2;
            else if (a == 0 || (e->kind == N_NUM && e->num == 1.0))
                d = a;
            else
                d = 2;
            break;
        }
        }
        break;
    case N_CALL:
        for (k = 0; k < nd->nkids; k++) {
            int e = degree(ra, p->kids[nd->kids + k]);
            a = e > a ? e : a;
            if (k == 0)
                b = e;
            else if (e + b > d)
                d = e + b; /* products of two arguments */
        }
        switch (nd->op) {
        case F_DER:
        case F_ANGVEL_BODY:
        case F_ANGVEL_SPACE: d = a > 0 ? 2 : 1; break;
        case F_VEC:
        case F_MAT:
        case F_DIAG:
        case F_TRANSPOSE: d = a; break;
        case F_DOT:
        case F_CROSS: break; /* d: the two arguments' sum */
        default: d = a > 0 ? 2 : 0; break; /* a function of a rate */
        }
        break;
    case N_SUM: d = degree(ra, p->kids[nd->kids + 2]); break;
    case N_IF:
        a = degree(ra, p->kids[nd->kids + 1]);
        b = degree(ra, p->kids[nd->kids + 2]);
        d = a > b ? a : b;
        break;
    default: d = 0; break;
    }
    ra->depth--;
    return at_most_one(ra, n, d);
}

int lang_rates(lang_prog *p, char *err, size_t len)
{
    rater ra;
    int k;
    memset(&ra, 0, sizeof ra);
    ra.p = p;
    for (k = 0; k < p->nsyms; k++) {
        const sym *y = &p->syms[k];
        int d;
        if (y->kind != S_CONSTRAINT || !y->velocity)
            continue;
        if (!ra.def_deg &&
            !(ra.def_deg = calloc((size_t)p->nsyms, sizeof *ra.def_deg))) {
            snprintf(err, len, "%s: out of memory while reading the file",
                     p->path ? p->path : "<string>");
            return -1;
        }
        ra.bad = -1;
        d = degree(&ra, y->value);
        if (d > 1) {
            lang_diag(p, p->nodes[ra.bad].tok, err, len,
                      "a velocity constraint is A(q, t) qd + b(q, t) = 0: "
                      "each term holds at most one rate, as a factor",
                      "the velocity constraint %s is not linear in the "
                      "rates here", y->name);
            free(ra.def_deg);
            return -1;
        }
        if (d == 0) {
            lang_diag(p, y->tok, err, len,
                      "a constraint on the coordinates alone is written "
                      "`constraint NAME = ...`",
                      "the velocity constraint %s reads no rates",
                      y->name);
            free(ra.def_deg);
            return -1;
        }
    }
    free(ra.def_deg);
    return 0;
}
