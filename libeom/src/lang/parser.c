/* parser.c - tokens to declarations, definition clauses, energy
 * statements and an expression pool (docs/models.md has the grammar).
 * Recursive descent; a binary operator at the end of a line continues
 * the statement on the next one. Names are resolved later (resolve.c),
 * so a file may use a definition before the line that defines it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lang.h"

/* Deepest expression tree (operators inside operators): the walkers that
 * record and check an expression recurse this deep. */
#define MAX_TREE 2000
#define MAX_ARGS 9

typedef struct parser {
    lang_prog *p;
    int pos;
    int nest;
    char *err;
    size_t len;
} parser;

static const token *cur(parser *ps) { return &ps->p->toks[ps->pos]; }
static int kind(parser *ps) { return ps->p->toks[ps->pos].kind; }

static int is_word(parser *ps, int t, const char *w)
{
    const token *k = &ps->p->toks[t];
    return k->kind == TK_ID && (size_t)k->len == strlen(w) &&
           memcmp(ps->p->text + k->off, w, (size_t)k->len) == 0;
}

static const char *const keywords[] = {
    "setting", "param", "coord", "probe", "constraint", "force", "units",
    "sum", "if", "in", "rate", NULL};

int lang_is_keyword(const char *s);
int lang_is_keyword(const char *s)
{
    int k;
    for (k = 0; keywords[k]; k++)
        if (strcmp(s, keywords[k]) == 0)
            return 1;
    return 0;
}

static int fail(parser *ps, int tok, const char *hint, const char *what)
{
    char buf[80];
    lang_diag(ps->p, tok, ps->err, ps->len, hint, "%s, found '%s'", what,
              lang_tok_text(ps->p, tok, buf, sizeof buf));
    return -1;
}

static int nomem(parser *ps)
{
    snprintf(ps->err, ps->len, "%s: out of memory while reading the file",
             ps->p->path ? ps->p->path : "<string>");
    return -1;
}

/* ---- the node pool ----------------------------------------------------- */

static int depth_of(const lang_prog *p, int k);

static int new_node(parser *ps, int kind_, int tok, const int *kids, int nk)
{
    lang_prog *p = ps->p;
    node *nd;
    int k, depth = 1;
    if (lang_grow((void **)&p->nodes, &p->cap_nodes, p->nnodes + 1,
                  sizeof *p->nodes, 1 << 28) != 0 ||
        lang_grow((void **)&p->kids, &p->cap_kids, p->nkids + nk,
                  sizeof *p->kids, 1 << 28) != 0)
        return nomem(ps);
    nd = &p->nodes[p->nnodes];
    memset(nd, 0, sizeof *nd);
    nd->kind = (uint8_t)kind_;
    nd->tok = tok;
    nd->kids = p->nkids;
    nd->nkids = (uint8_t)nk;
    nd->sym = -1;
    nd->var = -1;
    for (k = 0; k < nk; k++) {
        int d = depth_of(p, kids[k]) + 1;
        p->kids[p->nkids++] = kids[k];
        if (d > depth)
            depth = d;
    }
    /* the depth rides in num for the moment of parsing; N_NUM keeps its
     * value (depth 1) */
    if (kind_ != N_NUM)
        nd->num = depth;
    if (depth > MAX_TREE) {
        lang_diag(p, tok, ps->err, ps->len,
                  "split it with named definitions (a = ..., then use a)",
                  "this expression is more than %d operations deep",
                  MAX_TREE);
        return -1;
    }
    return p->nnodes++;
}

static int depth_of(const lang_prog *p, int k)
{
    return p->nodes[k].kind == N_NUM ? 1 : (int)p->nodes[k].num;
}

/* ---- expressions ------------------------------------------------------- */

static int expr(parser *ps);
static int unary(parser *ps);

static void skip_nl(parser *ps)
{
    while (kind(ps) == TK_NL && ps->p->toks[ps->pos + 1].kind != TK_EOF)
        ps->pos++;
}

static int expect(parser *ps, int k, const char *what)
{
    if (kind(ps) != k)
        return fail(ps, ps->pos, NULL, what);
    ps->pos++;
    return 0;
}

static int enter(parser *ps)
{
    if (++ps->nest > LANG_MAX_NEST) {
        lang_diag(ps->p, ps->pos, ps->err, ps->len, NULL,
                  "expressions nest deeper than %d", LANG_MAX_NEST);
        return -1;
    }
    return 0;
}

/* "(" args ")" after a function name: up to MAX_ARGS expressions. */
static int call_args(parser *ps, int *args, int *nargs)
{
    int n = 0, a;
    ps->pos++; /* ( */
    if (kind(ps) == TK_RPAR) {
        ps->pos++;
        *nargs = 0;
        return 0;
    }
    for (;;) {
        if ((a = expr(ps)) < 0)
            return -1;
        if (n == MAX_ARGS)
            return fail(ps, ps->pos, NULL, "too many arguments");
        args[n++] = a;
        if (kind(ps) == TK_COMMA) {
            ps->pos++;
            continue;
        }
        if (expect(ps, TK_RPAR, "expected ',' or ')' in the arguments") < 0)
            return -1;
        break;
    }
    *nargs = n;
    return 0;
}

/* sum(VAR in LO..HI, BODY) */
static int sum_expr(parser *ps, int tok)
{
    int kids[3], var_tok, nd;
    ps->pos++; /* ( */
    if (kind(ps) != TK_ID)
        return fail(ps, ps->pos, "write sum(i in 1..n, x[i])",
                    "expected an index name after 'sum('");
    var_tok = ps->pos++;
    if (!is_word(ps, ps->pos, "in"))
        return fail(ps, ps->pos, "write sum(i in 1..n, x[i])",
                    "expected 'in' after the index name");
    ps->pos++;
    if ((kids[0] = expr(ps)) < 0)
        return -1;
    if (expect(ps, TK_DOTDOT, "expected '..' in the range of the sum") < 0)
        return -1;
    if ((kids[1] = expr(ps)) < 0)
        return -1;
    if (expect(ps, TK_COMMA, "expected ',' after the range of the sum") < 0)
        return -1;
    if ((kids[2] = expr(ps)) < 0)
        return -1;
    if (expect(ps, TK_RPAR, "expected ')' to close the sum") < 0)
        return -1;
    if ((nd = new_node(ps, N_SUM, tok, kids, 3)) < 0)
        return -1;
    /* the variable's token, for the resolver */
    ps->p->nodes[nd].var = var_tok;
    return nd;
}

static int primary(parser *ps)
{
    const int tok = ps->pos;
    const token *t = cur(ps);
    int nd, args[MAX_ARGS], nargs;
    if (t->kind == TK_NUM) {
        ps->pos++;
        if ((nd = new_node(ps, N_NUM, tok, NULL, 0)) < 0)
            return -1;
        ps->p->nodes[nd].num = t->num;
        return nd;
    }
    if (t->kind == TK_LPAR) {
        ps->pos++;
        if ((nd = expr(ps)) < 0)
            return -1;
        if (expect(ps, TK_RPAR, "expected ')'") < 0)
            return -1;
        return nd;
    }
    if (t->kind != TK_ID)
        return fail(ps, tok, NULL, "expected a number, a name or '('");
    ps->pos++;
    if (kind(ps) == TK_LPAR) {
        if (is_word(ps, tok, "sum"))
            return sum_expr(ps, tok);
        if (call_args(ps, args, &nargs) < 0)
            return -1;
        if (is_word(ps, tok, "if")) {
            if (nargs != 3) {
                lang_diag(ps->p, tok, ps->err, ps->len,
                          "write if(condition, value if true, value if "
                          "false)",
                          "if() takes 3 arguments, not %d", nargs);
                return -1;
            }
            return new_node(ps, N_IF, tok, args, 3);
        }
        return new_node(ps, N_CALL, tok, args, nargs);
    }
    if (kind(ps) == TK_LBRK && !cur(ps)->space_before) {
        ps->pos++;
        nargs = 0;
        for (;;) {
            int a = expr(ps);
            if (a < 0)
                return -1;
            if (nargs == LANG_MAX_IDX)
                return fail(ps, ps->pos, NULL, "too many indices");
            args[nargs++] = a;
            if (kind(ps) == TK_COMMA) {
                ps->pos++;
                continue;
            }
            if (expect(ps, TK_RBRK, "expected ',' or ']' after an index") < 0)
                return -1;
            break;
        }
        return new_node(ps, N_NAME, tok, args, nargs);
    }
    return new_node(ps, N_NAME, tok, NULL, 0);
}

/* The component letters after '.': x, y, z of a vector, xx .. zz of a
 * matrix (row, then column); the index (3*row + col for a matrix, plus
 * 16 to mark two letters), or -1. */
static int component(const char *s, int len)
{
    int k, v = 0;
    if (len < 1 || len > 2)
        return -1;
    for (k = 0; k < len; k++) {
        if (s[k] < 'x' || s[k] > 'z')
            return -1;
        v = 3 * v + (s[k] - 'x');
    }
    return len == 2 ? v + 16 : v;
}

/* primary {'.' component}: r.x, I.xy, p[j].z */
static int postfix(parser *ps)
{
    int a = primary(ps);
    while (a >= 0 && kind(ps) == TK_DOT) {
        const token *t;
        int c;
        ps->pos++;
        t = cur(ps);
        c = t->kind == TK_ID ? component(ps->p->text + t->off, t->len) : -1;
        if (c < 0)
            return fail(ps, ps->pos,
                        "a vector's components are .x .y .z; a matrix's "
                        ".xx .xy .xz .yx ... .zz (row, then column)",
                        "expected a component after '.'");
        if ((a = new_node(ps, N_COMP, ps->pos, &a, 1)) < 0)
            return -1;
        ps->p->nodes[a].op = (uint8_t)c;
        ps->pos++;
    }
    return a;
}

/* postfix ['^' unary]: right-associative, binds tighter than unary minus
 * on its left (-x^2 is -(x^2)) and accepts one on its right (x^-2). */
static int power(parser *ps)
{
    int a = postfix(ps), b, kids[2], op;
    if (a < 0)
        return -1;
    if (kind(ps) != TK_CARET)
        return a;
    op = ps->pos++;
    skip_nl(ps);
    if (enter(ps) < 0 || (b = unary(ps)) < 0)
        return -1;
    ps->nest--;
    kids[0] = a;
    kids[1] = b;
    if ((a = new_node(ps, N_BIN, op, kids, 2)) >= 0)
        ps->p->nodes[a].op = TK_CARET;
    return a;
}

static int unary(parser *ps)
{
    int tok = ps->pos, a;
    if (kind(ps) == TK_MINUS || kind(ps) == TK_PLUS) {
        int neg = kind(ps) == TK_MINUS;
        ps->pos++;
        if (enter(ps) < 0 || (a = unary(ps)) < 0)
            return -1;
        ps->nest--;
        return neg ? new_node(ps, N_NEG, tok, &a, 1) : a;
    }
    return power(ps);
}

static int binary_level(parser *ps, int level);

/* level 0: comparison (one at most), 1: + -, 2: * / */
static int binary_level(parser *ps, int level)
{
    int a = level == 2 ? unary(ps) : binary_level(ps, level + 1);
    if (a < 0)
        return -1;
    for (;;) {
        int k = kind(ps), op, b, kids[2];
        int match = level == 2   ? (k == TK_STAR || k == TK_SLASH)
                    : level == 1 ? (k == TK_PLUS || k == TK_MINUS)
                                 : (k >= TK_EQ && k <= TK_GE);
        if (!match)
            return a;
        op = ps->pos++;
        skip_nl(ps);
        b = level == 2 ? unary(ps) : binary_level(ps, level + 1);
        if (b < 0)
            return -1;
        kids[0] = a;
        kids[1] = b;
        if ((a = new_node(ps, N_BIN, op, kids, 2)) < 0)
            return -1;
        ps->p->nodes[a].op = (uint8_t)k;
        if (level == 0 && kind(ps) >= TK_EQ && kind(ps) <= TK_GE)
            return fail(ps, ps->pos, "write (a < b)*(b < c) for both",
                        "comparisons do not chain");
    }
}

static int expr(parser *ps)
{
    int a;
    if (enter(ps) < 0)
        return -1;
    a = binary_level(ps, 0);
    ps->nest--;
    return a;
}

/* ---- statements -------------------------------------------------------- */

/* '[' binder {',' binder} ']' right after a declared name; binder is
 * "VAR in LO..HI", or (fixed_ok) an expression for one index. */
static int binders(parser *ps, binder *b, uint8_t *nb, int fixed_ok)
{
    int n = 0;
    ps->pos++; /* [ */
    for (;;) {
        binder *x;
        if (n == LANG_MAX_IDX)
            return fail(ps, ps->pos, NULL, "too many indices");
        x = &b[n++];
        x->tok = ps->pos;
        x->var = x->lo = x->hi = x->fixed = -1;
        if (kind(ps) == TK_ID && is_word(ps, ps->pos + 1, "in")) {
            x->var = ps->pos; /* the token; resolve.c makes it a variable */
            ps->pos += 2;
            if ((x->lo = expr(ps)) < 0)
                return -1;
            if (expect(ps, TK_DOTDOT, "expected '..' in the index range") < 0)
                return -1;
            if ((x->hi = expr(ps)) < 0)
                return -1;
        } else if (fixed_ok) {
            if ((x->fixed = expr(ps)) < 0)
                return -1;
        } else {
            return fail(ps, ps->pos, "write NAME[i in 1..n]",
                        "expected an index range 'i in LO..HI'");
        }
        if (kind(ps) == TK_COMMA) {
            ps->pos++;
            continue;
        }
        if (expect(ps, TK_RBRK, "expected ',' or ']' after an index") < 0)
            return -1;
        break;
    }
    *nb = (uint8_t)n;
    return 0;
}

static int new_sym(parser *ps, int kind_, int name_tok)
{
    lang_prog *p = ps->p;
    sym *s;
    const token *t = &p->toks[name_tok];
    if (lang_grow((void **)&p->syms, &p->cap_syms, p->nsyms + 1,
                  sizeof *p->syms, LANG_MAX_COUNT) != 0) {
        if (p->nsyms >= LANG_MAX_COUNT) {
            lang_diag(p, name_tok, ps->err, ps->len, NULL,
                      "more than %d declarations", LANG_MAX_COUNT);
            return -1;
        }
        return nomem(ps);
    }
    s = &p->syms[p->nsyms];
    memset(s, 0, sizeof *s);
    s->kind = (uint8_t)kind_;
    s->tok = name_tok;
    memcpy(s->name, p->text + t->off, (size_t)t->len);
    s->name[t->len] = '\0';
    s->value = s->rate = s->unit_tok = s->desc_tok = -1;
    s->lo = s->hi = -1;
    s->first_clause = s->last_clause = -1;
    return p->nsyms++;
}

/* '[' unit text ']' with whitespace before it: the raw text */
static int unit_part(parser *ps, sym *s)
{
    const lang_prog *p = ps->p;
    int open = ps->pos, close = open + 1;
    long from, to;
    while (p->toks[close].kind != TK_RBRK && p->toks[close].kind != TK_EOF)
        close++;
    if (p->toks[close].kind != TK_RBRK)
        return fail(ps, open, NULL, "a unit in brackets is not closed");
    from = p->toks[open].off + 1;
    to = p->toks[close].off;
    if (to - from >= (long)sizeof s->unit) {
        lang_diag(p, open, ps->err, ps->len, NULL,
                  "a unit longer than %d characters",
                  (int)sizeof s->unit - 1);
        return -1;
    }
    memcpy(s->unit, p->text + from, (size_t)(to - from));
    s->unit[to - from] = '\0';
    s->unit_tok = open;
    ps->pos = close + 1;
    return 0;
}

static int end_of_stmt(parser *ps)
{
    if (kind(ps) == TK_LBRK)
        return fail(ps, ps->pos,
                    "an index follows its name without a space "
                    "(theta[j]); a unit in brackets ends a param, coord "
                    "or probe line",
                    "unexpected '['");
    if (kind(ps) != TK_NL)
        return fail(ps, ps->pos, NULL, "expected the end of the line");
    ps->pos++;
    return 0;
}

static int optional_desc(parser *ps, sym *s)
{
    if (kind(ps) == TK_STR)
        s->desc_tok = ps->pos++;
    return 0;
}

static int expect_name(parser *ps, const char *what)
{
    char buf[80];
    if (kind(ps) != TK_ID)
        return fail(ps, ps->pos, NULL, what);
    if (lang_is_keyword(lang_tok_text(ps->p, ps->pos, buf, sizeof buf))) {
        lang_diag(ps->p, ps->pos, ps->err, ps->len, NULL,
                  "'%s' is a reserved word and cannot name a value", buf);
        return -1;
    }
    return ps->pos++;
}

/* setting NAME = VALUE [in LO..HI] ["description"] */
static int setting_stmt(parser *ps)
{
    int name = expect_name(ps, "expected the setting's name"), k;
    sym *s;
    if (name < 0 || (k = new_sym(ps, S_SETTING, name)) < 0)
        return -1;
    if (expect(ps, TK_ASSIGN, "expected '=' and the setting's default") < 0)
        return -1;
    if ((ps->p->syms[k].value = expr(ps)) < 0)
        return -1;
    s = &ps->p->syms[k];
    if (is_word(ps, ps->pos, "in")) {
        ps->pos++;
        if ((s->lo = expr(ps)) < 0)
            return -1;
        s = &ps->p->syms[k];
        if (expect(ps, TK_DOTDOT, "expected '..' in the setting's range") < 0)
            return -1;
        if ((s->hi = expr(ps)) < 0)
            return -1;
        s = &ps->p->syms[k];
    }
    optional_desc(ps, s);
    return end_of_stmt(ps);
}

/* param|coord|probe|constraint NAME[binders] = EXPR [unit] [rate EXPR]
 * ["description"] */
static int decl_stmt(parser *ps, int kind_)
{
    int name = expect_name(ps, "expected a name"), k, v;
    sym *s;
    if (name < 0 || (k = new_sym(ps, kind_, name)) < 0)
        return -1;
    if (kind(ps) == TK_LBRK) {
        if (cur(ps)->space_before)
            return fail(ps, ps->pos, "write NAME[i in 1..n] with no space",
                        "a space between a name and its indices");
        if (binders(ps, ps->p->syms[k].idx, &ps->p->syms[k].nidx, 0) < 0)
            return -1;
    }
    if (expect(ps, TK_ASSIGN, "expected '='") < 0)
        return -1;
    if ((v = expr(ps)) < 0)
        return -1;
    s = &ps->p->syms[k];
    s->value = v;
    if (kind(ps) == TK_LBRK && kind_ != S_CONSTRAINT) {
        if (unit_part(ps, s) < 0)
            return -1;
    }
    if (kind_ == S_COORD && is_word(ps, ps->pos, "rate")) {
        ps->pos++;
        if ((v = expr(ps)) < 0)
            return -1;
        s = &ps->p->syms[k];
        s->rate = v;
    }
    optional_desc(ps, s);
    return end_of_stmt(ps);
}

static int new_stmt(parser *ps, int kind_, int tok)
{
    lang_prog *p = ps->p;
    energy_stmt *e;
    if (lang_grow((void **)&p->stmts, &p->cap_stmts, p->nstmts + 1,
                  sizeof *p->stmts, LANG_MAX_COUNT) != 0) {
        lang_diag(p, tok, ps->err, ps->len, NULL,
                  "more than %d energy and force statements",
                  LANG_MAX_COUNT);
        return -1;
    }
    e = &p->stmts[p->nstmts];
    memset(e, 0, sizeof *e);
    e->kind = (uint8_t)kind_;
    e->tok = tok;
    e->target = -1;
    return p->nstmts++;
}

/* force COORD[binders or indices] = EXPR */
static int force_stmt(parser *ps, int tok)
{
    int k = new_stmt(ps, ST_FORCE, tok), name, b, kids[LANG_MAX_IDX], nk, i;
    energy_stmt *e;
    if (k < 0)
        return -1;
    if ((name = expect_name(ps, "expected the coordinate the force acts "
                                "on")) < 0)
        return -1;
    e = &ps->p->stmts[k];
    if (kind(ps) == TK_LBRK && !cur(ps)->space_before) {
        if (binders(ps, e->idx, &e->nidx, 1) < 0)
            return -1;
    }
    e = &ps->p->stmts[k];
    /* the target as a name node whose indices are the binders' variables
     * or fixed expressions: resolve.c fills the variable references */
    nk = e->nidx;
    for (i = 0; i < nk; i++) {
        if (e->idx[i].var >= 0) {
            if ((b = new_node(ps, N_NAME, e->idx[i].var, NULL, 0)) < 0)
                return -1;
        } else {
            b = e->idx[i].fixed;
        }
        kids[i] = b;
        e = &ps->p->stmts[k];
    }
    if ((b = new_node(ps, N_NAME, name, kids, nk)) < 0)
        return -1;
    ps->p->stmts[k].target = b;
    if (expect(ps, TK_ASSIGN, "expected '='") < 0)
        return -1;
    if ((b = expr(ps)) < 0)
        return -1;
    ps->p->stmts[k].body = b;
    return end_of_stmt(ps);
}

/* NAME[binders] = EXPR: a definition clause, or T/V/L/R = EXPR */
static int def_stmt(parser *ps)
{
    lang_prog *p = ps->p;
    const int name = ps->pos;
    static const char *const energies[4] = {"T", "V", "L", "R"};
    clause c;
    int k, e;
    char buf[LANG_MAX_NAME + 1];
    lang_tok_text(p, name, buf, sizeof buf);
    for (e = 0; e < 4; e++)
        if (strcmp(buf, energies[e]) == 0) {
            int st;
            ps->pos++;
            if (kind(ps) != TK_ASSIGN)
                return fail(ps, ps->pos, NULL,
                            e == 0   ? "expected '=' after T (kinetic energy)"
                            : e == 1 ? "expected '=' after V (potential "
                                       "energy)"
                            : e == 2 ? "expected '=' after L (Lagrangian)"
                                     : "expected '=' after R (dissipation)");
            ps->pos++;
            if ((st = new_stmt(ps, e, name)) < 0 || (k = expr(ps)) < 0)
                return -1;
            p->stmts[st].body = k;
            return end_of_stmt(ps);
        }
    if (expect_name(ps, "expected a statement") < 0)
        return -1;
    memset(&c, 0, sizeof c);
    c.tok = name;
    c.next = -1;
    c.sym = -1;
    if (kind(ps) == TK_LBRK) {
        uint8_t nb;
        if (cur(ps)->space_before)
            return fail(ps, ps->pos, "write NAME[i in 1..n] with no space",
                        "a space between a name and its indices");
        if (binders(ps, c.idx, &nb, 1) < 0)
            return -1;
        c.nidx = nb;
    }
    if (kind(ps) != TK_ASSIGN) {
        if (kind(ps) == TK_ID || kind(ps) == TK_NUM)
            return fail(ps, ps->pos,
                        "statements start with setting, param, coord, "
                        "probe, constraint, force, units, T, V, L, R or a "
                        "definition NAME = ...",
                        "expected '='");
        return fail(ps, ps->pos, NULL, "expected '='");
    }
    ps->pos++;
    if ((c.body = expr(ps)) < 0)
        return -1;
    if (lang_grow((void **)&p->clauses, &p->cap_clauses, p->nclauses + 1,
                  sizeof c, LANG_MAX_COUNT) != 0) {
        lang_diag(p, name, ps->err, ps->len, NULL,
                  "more than %d definitions", LANG_MAX_COUNT);
        return -1;
    }
    p->clauses[p->nclauses++] = c;
    return end_of_stmt(ps);
}

/* draw KIND NAME[binders] = ARG {, ARG} {color "C" | trail}: the syntax
 * only; draw.c checks the kind, the arguments and the colour. */
static int draw_stmt(parser *ps, int tok)
{
    lang_prog *p = ps->p;
    lang_draw *d;
    int name, first, k, v;
    if (kind(ps) != TK_ID)
        return fail(ps, ps->pos, "write draw point NAME = vec(x, y, 0)",
                    "expected the kind of drawing after 'draw'");
    ps->pos++;
    if ((name = expect_name(ps, "expected the drawing's name")) < 0 ||
        (first = new_sym(ps, S_PROBE, name)) < 0)
        return -1;
    if (lang_grow((void **)&p->draws, &p->cap_draws, p->ndraws + 1,
                  sizeof *p->draws, LANG_MAX_COUNT) != 0)
        return nomem(ps);
    d = &p->draws[p->ndraws++];
    memset(d, 0, sizeof *d);
    d->tok = tok;
    d->kind_tok = tok + 1;
    d->first_sym = first;
    d->color_tok = d->trail_tok = -1;
    if (kind(ps) == TK_LBRK) {
        if (cur(ps)->space_before)
            return fail(ps, ps->pos, "write NAME[i in 1..n] with no space",
                        "a space between a name and its indices");
        if (binders(ps, p->syms[first].idx, &p->syms[first].nidx, 0) < 0)
            return -1;
    }
    if (expect(ps, TK_ASSIGN, "expected '='") < 0)
        return -1;
    for (k = first;; ) {
        const int at = ps->pos;
        if ((v = expr(ps)) < 0)
            return -1;
        p->syms[k].value = v;
        p->syms[k].draw = p->ndraws;
        p->syms[k].draw_tok = at;
        p->draws[p->ndraws - 1].nargs++;
        if (kind(ps) != TK_COMMA)
            break;
        ps->pos++;
        skip_nl(ps); /* a line that ends with a comma goes on */
        if ((k = new_sym(ps, S_PROBE, name)) < 0)
            return -1;
        snprintf(p->syms[k].name, sizeof p->syms[k].name, "#%d.%d",
                 p->ndraws, p->draws[p->ndraws - 1].nargs + 1);
        memcpy(p->syms[k].idx, p->syms[first].idx, sizeof p->syms[k].idx);
        p->syms[k].nidx = p->syms[first].nidx;
    }
    d = &p->draws[p->ndraws - 1];
    while (kind(ps) == TK_ID) {
        if (is_word(ps, ps->pos, "color") && ps->p->toks[ps->pos + 1].kind ==
                                                 TK_STR) {
            d->color_tok = ps->pos + 1;
            ps->pos += 2;
        } else if (is_word(ps, ps->pos, "trail")) {
            d->trail_tok = ps->pos++;
        } else {
            return fail(ps, ps->pos,
                        "a drawing ends with color \"NAME\" or "
                        "color \"#rrggbb\", and trail for a point",
                        "expected color \"...\" or trail");
        }
    }
    return end_of_stmt(ps);
}

static int statement(parser *ps)
{
    const int tok = ps->pos;
    if (kind(ps) == TK_NL) {
        ps->pos++;
        return 0;
    }
    if (kind(ps) != TK_ID) {
        if (kind(ps) == TK_PLUS || kind(ps) == TK_MINUS ||
            kind(ps) == TK_STAR || kind(ps) == TK_SLASH)
            return fail(ps, tok,
                        "to continue an expression on the next line, end "
                        "the line before with the operator",
                        "a line cannot start with an operator");
        return fail(ps, tok, NULL, "expected a statement");
    }
    if (is_word(ps, tok, "setting")) {
        ps->pos++;
        return setting_stmt(ps);
    }
    if (is_word(ps, tok, "velocity") && is_word(ps, tok + 1, "constraint")) {
        /* a constraint on the rates: A(q, t) qd + b(q, t) = 0 */
        int first = ps->p->nsyms, rc;
        ps->pos += 2;
        rc = decl_stmt(ps, S_CONSTRAINT);
        if (ps->p->nsyms > first)
            ps->p->syms[first].velocity = 1;
        return rc;
    }
    if (is_word(ps, tok, "param") || is_word(ps, tok, "coord") ||
        is_word(ps, tok, "probe") || is_word(ps, tok, "constraint")) {
        int k = is_word(ps, tok, "param")   ? S_PARAM
                : is_word(ps, tok, "coord") ? S_COORD
                : is_word(ps, tok, "probe") ? S_PROBE
                                            : S_CONSTRAINT;
        ps->pos++;
        return decl_stmt(ps, k);
    }
    /* not a reserved word: a value named draw keeps working */
    if (is_word(ps, tok, "draw") && ps->p->toks[tok + 1].kind == TK_ID) {
        ps->pos++;
        return draw_stmt(ps, tok);
    }
    if (is_word(ps, tok, "force")) {
        ps->pos++;
        return force_stmt(ps, tok);
    }
    if (is_word(ps, tok, "units")) {
        ps->pos++;
        if (!is_word(ps, ps->pos, "off"))
            return fail(ps, ps->pos, "the only form is: units off",
                        "expected 'off' after 'units'");
        ps->p->units_off = 1;
        ps->p->units_off_tok = tok;
        ps->pos++;
        return end_of_stmt(ps);
    }
    return def_stmt(ps);
}

int lang_parse(lang_prog *p, char *err, size_t len)
{
    parser ps;
    memset(&ps, 0, sizeof ps);
    ps.p = p;
    ps.err = err;
    ps.len = len;
    while (kind(&ps) != TK_EOF)
        if (statement(&ps) < 0)
            return -1;
    return 0;
}
