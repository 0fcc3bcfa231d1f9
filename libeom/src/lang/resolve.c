/* resolve.c - every name in the file bound to what it means: a setting,
 * parameter, coordinate, rate (NAME_dot), definition, index variable,
 * pi, or the time t; every function call checked against its arity.
 * Names may be used before the line that declares them. A name that
 * means nothing gets the nearest known name as a suggestion. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lang.h"

int lang_is_keyword(const char *s);

const fn_info lang_fns[F_COUNT] = {
    [F_SQRT] = {"sqrt", 1},   [F_EXP] = {"exp", 1},
    [F_LOG] = {"log", 1},     [F_SIN] = {"sin", 1},
    [F_COS] = {"cos", 1},     [F_TAN] = {"tan", 1},
    [F_ASIN] = {"asin", 1},   [F_ACOS] = {"acos", 1},
    [F_ATAN] = {"atan", 1},   [F_SINH] = {"sinh", 1},
    [F_COSH] = {"cosh", 1},   [F_TANH] = {"tanh", 1},
    [F_ABS] = {"abs", 1},     [F_SQR] = {"sqr", 1},
    [F_ATAN2] = {"atan2", 2}, [F_HYPOT] = {"hypot", 2},
    [F_VEC] = {"vec", 3},     [F_MAT] = {"mat", -1},
    [F_DIAG] = {"diag", 3},   [F_DOT] = {"dot", 2},
    [F_CROSS] = {"cross", 2}, [F_NORM] = {"norm", 1},
    [F_TRANSPOSE] = {"transpose", 1},
    [F_ROTX] = {"rotx", 1},   [F_ROTY] = {"roty", 1},
    [F_ROTZ] = {"rotz", 1},   [F_ROT] = {"rot", 2},
    [F_QUAT] = {"quat", 4},   [F_DER] = {"der", 1},
    [F_ANGVEL_BODY] = {"angvel_body", 1},
    [F_ANGVEL_SPACE] = {"angvel_space", 1},
};

/* ---- a name table (open addressing) ------------------------------------ */

typedef struct names {
    int32_t *slot; /* symbol index + 1, 0 empty */
    unsigned mask;
} names;

static unsigned hash_str(const char *s)
{
    unsigned h = 2166136261u;
    while (*s)
        h = (h ^ (unsigned char)*s++) * 16777619u;
    return h;
}

static int names_init(names *t, int n)
{
    unsigned cap = 64;
    while (cap < 2u * (unsigned)n + 2u)
        cap *= 2;
    t->slot = calloc(cap, sizeof *t->slot);
    t->mask = cap - 1;
    return t->slot ? 0 : -1;
}

/* The symbol named s in t, or -1. */
static int names_find(const names *t, const lang_prog *p, const char *s)
{
    unsigned h = hash_str(s) & t->mask;
    while (t->slot[h]) {
        if (strcmp(p->syms[t->slot[h] - 1].name, s) == 0)
            return t->slot[h] - 1;
        h = (h + 1) & t->mask;
    }
    return -1;
}

static void names_add(names *t, const lang_prog *p, int k)
{
    unsigned h = hash_str(p->syms[k].name) & t->mask;
    while (t->slot[h])
        h = (h + 1) & t->mask;
    t->slot[h] = k + 1;
}

/* ---- the resolver ------------------------------------------------------ */

typedef struct scope_var {
    const char *name;
    int len;
    int var;
} scope_var;

typedef struct resolver {
    lang_prog *p;
    names values;  /* settings, params, coords, definitions */
    names outputs; /* probes and constraints */
    scope_var scope[64];
    int nscope;
    char *err;
    size_t len;
} resolver;

static const char *sym_what(int kind)
{
    switch (kind) {
    case S_SETTING: return "a setting";
    case S_PARAM: return "a parameter";
    case S_COORD: return "a coordinate";
    case S_DEF: return "a definition";
    case S_PROBE: return "a probe";
    default: return "a constraint";
    }
}

static int reserved(const char *s)
{
    static const char *const words[] = {"T", "V", "L", "R", "t", "pi", NULL};
    int k;
    for (k = 0; words[k]; k++)
        if (strcmp(s, words[k]) == 0)
            return 1;
    return 0;
}

static int check_new_name(resolver *rs, int k)
{
    const sym *s = &rs->p->syms[k];
    size_t n = strlen(s->name);
    int f;
    if (reserved(s->name)) {
        lang_diag(rs->p, s->tok, rs->err, rs->len,
                  strcmp(s->name, "L") == 0
                      ? "choose another name, such as len or L1"
                      : "choose another name",
                  "'%s' is reserved (%s)", s->name,
                  strcmp(s->name, "t") == 0    ? "the time"
                  : strcmp(s->name, "pi") == 0 ? "the number pi"
                  : strcmp(s->name, "T") == 0  ? "the kinetic energy"
                  : strcmp(s->name, "V") == 0  ? "the potential energy"
                  : strcmp(s->name, "L") == 0  ? "the Lagrangian"
                                               : "the dissipation function");
        return -1;
    }
    if (n > 4 && strcmp(s->name + n - 4, "_dot") == 0) {
        lang_diag(rs->p, s->tok, rs->err, rs->len,
                  "NAME_dot is the rate of the coordinate NAME, made for "
                  "you: declare `coord NAME`",
                  "a name cannot end in _dot");
        return -1;
    }
    /* the functions of vectors came later: files that name a value
     * norm or dot keep working (a call is still the function) */
    for (f = 0; f < F_FIRST_SPATIAL; f++)
        if (strcmp(s->name, lang_fns[f].name) == 0 ||
            strcmp(s->name, "sum") == 0) {
            lang_diag(rs->p, s->tok, rs->err, rs->len, "choose another name",
                      "'%s' is a function", s->name);
            return -1;
        }
    return 0;
}

static int twice(resolver *rs, int tok, int first_tok, const char *name,
                 const char *what)
{
    char hint[160];
    snprintf(hint, sizeof hint, "the first definition is on line %d; "
             "remove one or rename it",
             rs->p->toks[first_tok].line);
    lang_diag(rs->p, tok, rs->err, rs->len, hint, "%s is defined twice (%s)",
              name, what);
    return -1;
}

/* Gather the definition clauses into symbols and fill the tables. */
static int declare(resolver *rs)
{
    lang_prog *p = rs->p;
    int k, c, nsyms_decl = p->nsyms;
    if (names_init(&rs->values, p->nsyms + p->nclauses) != 0 ||
        names_init(&rs->outputs, p->nsyms) != 0)
        return -2;
    for (k = 0; k < nsyms_decl; k++) {
        sym *s = &p->syms[k];
        names *t = s->kind == S_PROBE || s->kind == S_CONSTRAINT
                       ? &rs->outputs
                       : &rs->values;
        int old = names_find(t, p, s->name);
        if (check_new_name(rs, k) != 0)
            return -1;
        if (old >= 0)
            return twice(rs, s->tok, p->syms[old].tok, s->name,
                         sym_what(p->syms[old].kind));
        names_add(t, p, k);
    }
    for (c = 0; c < p->nclauses; c++) {
        clause *cl = &p->clauses[c];
        char name[LANG_MAX_NAME + 1];
        int old;
        lang_tok_text(p, cl->tok, name, sizeof name);
        old = names_find(&rs->values, p, name);
        if (old >= 0 && p->syms[old].kind != S_DEF)
            return twice(rs, cl->tok, p->syms[old].tok, name,
                         sym_what(p->syms[old].kind));
        if (old >= 0) {
            sym *s = &p->syms[old];
            if (s->nidx == 0 || cl->nidx == 0)
                return twice(rs, cl->tok, s->tok, name, "a definition");
            if (s->nidx != cl->nidx) {
                lang_diag(p, cl->tok, rs->err, rs->len, NULL,
                          "%s has %d ind%s here but %d on line %d", name,
                          cl->nidx, cl->nidx == 1 ? "ex" : "ices", s->nidx,
                          p->toks[s->tok].line);
                return -1;
            }
            p->clauses[s->last_clause].next = c;
            s->last_clause = c;
            s->nclauses++;
            cl->sym = old;
            continue;
        }
        if (lang_grow((void **)&p->syms, &p->cap_syms, p->nsyms + 1,
                      sizeof *p->syms, 2 * LANG_MAX_COUNT) != 0)
            return -2;
        k = p->nsyms++;
        memset(&p->syms[k], 0, sizeof p->syms[k]);
        p->syms[k].kind = S_DEF;
        p->syms[k].tok = cl->tok;
        p->syms[k].nidx = cl->nidx;
        snprintf(p->syms[k].name, sizeof p->syms[k].name, "%s", name);
        p->syms[k].value = p->syms[k].rate = -1;
        p->syms[k].unit_tok = p->syms[k].desc_tok = -1;
        p->syms[k].first_clause = p->syms[k].last_clause = c;
        p->syms[k].nclauses = 1;
        cl->sym = k;
        if (check_new_name(rs, k) != 0)
            return -1;
        names_add(&rs->values, p, k);
    }
    return 0;
}

/* The nearest known name to s (values, rates, functions, index variables
 * in scope), or NULL when none is close. */
static const char *nearest(resolver *rs, const char *s, char *buf,
                           size_t len, int functions)
{
    const lang_prog *p = rs->p;
    int best = (int)strlen(s) <= 3 ? 1 : 2, k, d;
    const char *found = NULL;
    buf[0] = '\0';
    for (k = 0; k < p->nsyms && !functions; k++) {
        const sym *y = &p->syms[k];
        if (y->kind == S_PROBE || y->kind == S_CONSTRAINT)
            continue;
        if ((d = lang_edit_distance(s, y->name, best)) <= best &&
            (d < best || !found)) {
            best = d;
            snprintf(buf, len, "%s", y->name);
            found = buf;
        }
        if (y->kind == S_COORD) {
            char rate[LANG_MAX_NAME + 8];
            snprintf(rate, sizeof rate, "%s_dot", y->name);
            if ((d = lang_edit_distance(s, rate, best)) <= best &&
                (d < best || !found)) {
                best = d;
                snprintf(buf, len, "%s", rate);
                found = buf;
            }
        }
    }
    for (k = 0; k < rs->nscope && !functions; k++) {
        char v[LANG_MAX_NAME + 1];
        snprintf(v, sizeof v, "%.*s", rs->scope[k].len, rs->scope[k].name);
        if ((d = lang_edit_distance(s, v, best)) < best ||
            (d == best && !found)) {
            best = d;
            snprintf(buf, len, "%s", v);
            found = buf;
        }
    }
    for (k = 0; k <= F_COUNT; k++) {
        const char *f = k < F_COUNT ? lang_fns[k].name : "sum";
        if (!functions && strcmp(s, f) != 0)
            continue;
        if ((d = lang_edit_distance(s, f, best)) < best ||
            (d == best && !found)) {
            best = d;
            snprintf(buf, len, "%s", f);
            found = buf;
        }
    }
    if (!functions && !found) {
        static const char *const words[] = {"pi", "t", NULL};
        for (k = 0; words[k]; k++)
            if (lang_edit_distance(s, words[k], 1) <= 1 && strlen(s) > 1) {
                snprintf(buf, len, "%s", words[k]);
                found = buf;
            }
    }
    return found;
}

static int push_var(resolver *rs, int tok)
{
    lang_prog *p = rs->p;
    const token *t = &p->toks[tok];
    int v;
    if (rs->nscope == (int)(sizeof rs->scope / sizeof rs->scope[0])) {
        lang_diag(p, tok, rs->err, rs->len, NULL,
                  "index variables nest deeper than %d",
                  (int)(sizeof rs->scope / sizeof rs->scope[0]));
        return -1;
    }
    if (lang_grow((void **)&p->var_tok, &p->cap_vars, p->nvars + 1,
                  sizeof *p->var_tok, 1 << 28) != 0)
        return -2;
    v = p->nvars++;
    p->var_tok[v] = tok;
    rs->scope[rs->nscope].name = p->text + t->off;
    rs->scope[rs->nscope].len = t->len;
    rs->scope[rs->nscope].var = v;
    rs->nscope++;
    return v;
}

static int find_var(const resolver *rs, const char *name)
{
    int k;
    for (k = rs->nscope - 1; k >= 0; k--)
        if ((int)strlen(name) == rs->scope[k].len &&
            memcmp(name, rs->scope[k].name, (size_t)rs->scope[k].len) == 0)
            return rs->scope[k].var;
    return -1;
}

static int expr(resolver *rs, int n);

static int index_count(resolver *rs, const node *nd, const char *name,
                       int want)
{
    if (nd->nkids == want)
        return 0;
    if (want == 0) {
        lang_diag(rs->p, nd->tok, rs->err, rs->len, NULL,
                  "%s has no index: write %s alone", name, name);
    } else {
        char hint[160];
        snprintf(hint, sizeof hint, "write %s[%s]", name,
                 want == 1 ? "j" : want == 2 ? "j, i" : "j, i, k");
        lang_diag(rs->p, nd->tok, rs->err, rs->len, hint,
                  "%s has %d ind%s, not %d", name, want,
                  want == 1 ? "ex" : "ices", (int)nd->nkids);
    }
    return -1;
}

/* lambda_NAME, lambda_NAME_x ..: the multiplier of constraint NAME (of
 * its component x, y or z). 1 when name is one (nd resolved), 0 when it
 * is not, -1 on an error (reported). */
static int multiplier_ref(resolver *rs, node *nd, const char *name)
{
    lang_prog *p = rs->p;
    char base[LANG_MAX_NAME + 1];
    size_t len;
    int k, comp = 0;
    if (strncmp(name, "lambda_", 7) != 0 || !name[7])
        return 0;
    snprintf(base, sizeof base, "%s", name + 7);
    k = names_find(&rs->outputs, p, base);
    len = strlen(base);
    if ((k < 0 || p->syms[k].kind != S_CONSTRAINT) && len > 2 &&
        base[len - 2] == '_' && base[len - 1] >= 'x' && base[len - 1] <= 'z') {
        comp = 1 + (base[len - 1] - 'x');
        base[len - 2] = '\0';
        k = names_find(&rs->outputs, p, base);
    }
    if (k < 0 || p->syms[k].kind != S_CONSTRAINT)
        return 0;
    nd->ref = R_MULT;
    nd->sym = k;
    nd->op = (uint8_t)comp;
    return index_count(rs, nd, name, p->syms[k].nidx) < 0 ? -1 : 1;
}

static int name_ref(resolver *rs, int n)
{
    lang_prog *p = rs->p;
    node *nd = &p->nodes[n];
    char name[LANG_MAX_NAME + 1], sugg[LANG_MAX_NAME + 8], hint[400];
    size_t len;
    int k, v;
    lang_tok_text(p, nd->tok, name, sizeof name);
    for (k = 0; k < nd->nkids; k++)
        if (expr(rs, p->kids[nd->kids + k]) < 0)
            return -1;
    nd = &p->nodes[n];
    if ((v = find_var(rs, name)) >= 0) {
        nd->ref = R_IVAR;
        nd->sym = v;
        return index_count(rs, nd, name, 0);
    }
    if (strcmp(name, "pi") == 0 || strcmp(name, "t") == 0) {
        nd->ref = name[0] == 'p' ? R_PI : R_TIME;
        return index_count(rs, nd, name, 0);
    }
    if ((k = names_find(&rs->values, p, name)) >= 0) {
        const sym *s = &p->syms[k];
        nd->ref = s->kind == S_SETTING ? R_SETTING
                  : s->kind == S_PARAM ? R_PARAM
                  : s->kind == S_COORD ? R_COORD
                                       : R_DEF;
        nd->sym = k;
        return index_count(rs, nd, name, s->nidx);
    }
    len = strlen(name);
    if (len > 4 && strcmp(name + len - 4, "_dot") == 0) {
        char base[LANG_MAX_NAME + 1];
        snprintf(base, sizeof base, "%.*s", (int)(len - 4), name);
        k = names_find(&rs->values, p, base);
        if (k >= 0 && p->syms[k].kind == S_COORD) {
            nd->ref = R_RATE;
            nd->sym = k;
            return index_count(rs, nd, name, p->syms[k].nidx);
        }
        if (k >= 0) {
            lang_diag(p, nd->tok, rs->err, rs->len,
                      "only coordinates have rates",
                      "%s is %s, not a coordinate: %s has no meaning",
                      base, sym_what(p->syms[k].kind), name);
            return -1;
        }
    }
    if ((k = multiplier_ref(rs, nd, name)) != 0)
        return k > 0 ? 0 : -1;
    if (names_find(&rs->outputs, p, name) >= 0) {
        lang_diag(p, nd->tok, rs->err, rs->len,
                  "give the value a name with a definition (NAME = ...) "
                  "and use it in both places",
                  "%s is a probe or constraint: its value cannot be used "
                  "in an expression", name);
        return -1;
    }
    if (lang_is_keyword(name)) {
        lang_diag(p, nd->tok, rs->err, rs->len, NULL,
                  "'%s' is a reserved word, not a value", name);
        return -1;
    }
    if (strcmp(name, "T") == 0 || strcmp(name, "V") == 0 ||
        strcmp(name, "L") == 0 || strcmp(name, "R") == 0) {
        lang_diag(p, nd->tok, rs->err, rs->len,
                  "give the part a name (a definition) and use it here "
                  "and in the energy",
                  "%s names an energy of the model and cannot be used in "
                  "an expression", name);
        return -1;
    }
    for (k = 0; k < F_COUNT; k++)
        if (strcmp(name, lang_fns[k].name) == 0) {
            lang_diag(p, nd->tok, rs->err, rs->len, NULL,
                      "%s is a function: write %s(...)", name, name);
            return -1;
        }
    if (nearest(rs, name, sugg, sizeof sugg, 0))
        snprintf(hint, sizeof hint, "did you mean '%s'?", sugg);
    else
        snprintf(hint, sizeof hint,
                 "declare it with param, coord or setting, or define it "
                 "with %s = ...", name);
    lang_diag(p, nd->tok, rs->err, rs->len, hint, "unknown name '%s'", name);
    return -1;
}

static int call(resolver *rs, int n)
{
    lang_prog *p = rs->p;
    node *nd = &p->nodes[n];
    char name[LANG_MAX_NAME + 1], sugg[LANG_MAX_NAME + 8], hint[400];
    int k;
    lang_tok_text(p, nd->tok, name, sizeof name);
    for (k = 0; k < nd->nkids; k++)
        if (expr(rs, p->kids[nd->kids + k]) < 0)
            return -1;
    nd = &p->nodes[n];
    for (k = 0; k < F_COUNT; k++)
        if (strcmp(name, lang_fns[k].name) == 0) {
            nd->op = (uint8_t)k;
            if (k == F_MAT && nd->nkids != 9 && nd->nkids != 3) {
                lang_diag(p, nd->tok, rs->err, rs->len,
                          "write mat(a11, a12, a13, a21, ..., a33) or "
                          "mat(row1, row2, row3) with three vectors",
                          "mat takes 9 numbers or 3 rows, not %d "
                          "argument%s", (int)nd->nkids,
                          nd->nkids == 1 ? "" : "s");
                return -1;
            }
            if (k != F_MAT && nd->nkids != lang_fns[k].arity) {
                lang_diag(p, nd->tok, rs->err, rs->len, NULL,
                          "%s takes %d argument%s, not %d", name,
                          lang_fns[k].arity,
                          lang_fns[k].arity == 1 ? "" : "s", (int)nd->nkids);
                return -1;
            }
            return 0;
        }
    if (names_find(&rs->values, p, name) >= 0 || find_var(rs, name) >= 0) {
        lang_diag(p, nd->tok, rs->err, rs->len,
                  "write a product with '*', as in m*(a + b)",
                  "%s is not a function", name);
        return -1;
    }
    if (nearest(rs, name, sugg, sizeof sugg, 1))
        snprintf(hint, sizeof hint, "did you mean '%s'?", sugg);
    else
        snprintf(hint, sizeof hint,
                 "the functions are sqrt exp log sin cos tan asin acos atan "
                 "sinh cosh tanh abs sqr atan2 hypot, sum and if, der, and "
                 "vec mat diag dot cross norm transpose rotx roty rotz rot "
                 "quat angvel_body angvel_space");
    lang_diag(p, nd->tok, rs->err, rs->len, hint, "unknown function '%s'",
              name);
    return -1;
}

static int expr(resolver *rs, int n)
{
    lang_prog *p = rs->p;
    node *nd = &p->nodes[n];
    int k, v;
    switch (nd->kind) {
    case N_NUM: return 0;
    case N_NAME: return name_ref(rs, n);
    case N_CALL: return call(rs, n);
    case N_SUM:
        if (expr(rs, p->kids[nd->kids]) < 0 ||
            expr(rs, p->kids[nd->kids + 1]) < 0)
            return -1;
        if ((v = push_var(rs, p->nodes[n].var)) < 0)
            return v;
        p->nodes[n].var = v;
        k = expr(rs, p->kids[p->nodes[n].kids + 2]);
        rs->nscope--;
        return k;
    default:
        for (k = 0; k < nd->nkids; k++)
            if (expr(rs, p->kids[nd->kids + k]) < 0)
                return -1;
        return 0;
    }
}

/* Binders of a declaration or clause, then body nodes, in their scope.
 * The scope is left pushed; the caller pops nb variables. */
static int bind(resolver *rs, binder *b, int nb)
{
    int k, v;
    for (k = 0; k < nb; k++) {
        if (b[k].var < 0) {
            if (expr(rs, b[k].fixed) < 0)
                return -1;
            continue;
        }
        if (expr(rs, b[k].lo) < 0 || expr(rs, b[k].hi) < 0)
            return -1;
        if ((v = push_var(rs, b[k].var)) < 0)
            return v;
        b[k].var = v;
    }
    return 0;
}

static int count_vars(const binder *b, int nb)
{
    int k, n = 0;
    for (k = 0; k < nb; k++)
        n += b[k].var >= 0;
    return n;
}

/* Settings' defaults and ranges are numbers: no name may appear. */
static int plain_number(resolver *rs, int n, const char *what)
{
    const lang_prog *p = rs->p;
    const node *nd = &p->nodes[n];
    int k;
    if (nd->kind == N_NAME || nd->kind == N_SUM) {
        lang_diag(p, nd->tok, rs->err, rs->len, NULL,
                  "%s is a plain whole number (no names)", what);
        return -1;
    }
    for (k = 0; k < nd->nkids; k++)
        if (plain_number(rs, p->kids[nd->kids + k], what) < 0)
            return -1;
    return 0;
}

static int resolve_all(resolver *rs)
{
    lang_prog *p = rs->p;
    int k, rc, T = -1, V = -1, L = -1, R = -1;
    for (k = 0; k < p->nsyms; k++) {
        sym *s = &p->syms[k];
        if (s->kind == S_DEF)
            continue;
        if (s->kind == S_SETTING) {
            if (plain_number(rs, s->value, "a setting's default") < 0 ||
                (s->lo >= 0 &&
                 (plain_number(rs, s->lo, "a setting's range") < 0 ||
                  plain_number(rs, s->hi, "a setting's range") < 0)))
                return -1;
            continue;
        }
        if ((rc = bind(rs, s->idx, s->nidx)) < 0)
            return rc;
        s = &p->syms[k];
        if ((rc = expr(rs, s->value)) < 0 ||
            (s->rate >= 0 && (rc = expr(rs, p->syms[k].rate)) < 0))
            return rc;
        rs->nscope -= count_vars(p->syms[k].idx, p->syms[k].nidx);
    }
    for (k = 0; k < p->nclauses; k++) {
        if ((rc = bind(rs, p->clauses[k].idx, p->clauses[k].nidx)) < 0)
            return rc;
        if ((rc = expr(rs, p->clauses[k].body)) < 0)
            return rc;
        rs->nscope -= count_vars(p->clauses[k].idx, p->clauses[k].nidx);
    }
    for (k = 0; k < p->nstmts; k++) {
        energy_stmt *e = &p->stmts[k];
        int *slot = e->kind == ST_T   ? &T
                    : e->kind == ST_V ? &V
                    : e->kind == ST_L ? &L
                    : e->kind == ST_R ? &R
                                      : NULL;
        if (slot && *slot >= 0) {
            char name[4];
            lang_tok_text(p, e->tok, name, sizeof name);
            return twice(rs, e->tok, p->stmts[*slot].tok, name,
                         "an energy");
        }
        if (slot)
            *slot = k;
        if ((rc = bind(rs, e->idx, e->nidx)) < 0)
            return rc;
        e = &p->stmts[k];
        if (e->target >= 0) {
            node *t;
            if ((rc = expr(rs, e->target)) < 0)
                return rc;
            t = &p->nodes[p->stmts[k].target];
            if (t->ref != R_COORD) {
                char name[LANG_MAX_NAME + 1];
                lang_diag(p, t->tok, rs->err, rs->len,
                          "write force COORD = ..., the generalized force "
                          "conjugate to the coordinate COORD",
                          "%s is not a coordinate",
                          lang_tok_text(p, t->tok, name, sizeof name));
                return -1;
            }
        }
        if ((rc = expr(rs, p->stmts[k].body)) < 0)
            return rc;
        rs->nscope -= count_vars(p->stmts[k].idx, p->stmts[k].nidx);
    }
    if (L >= 0 && (T >= 0 || V >= 0)) {
        lang_diag(p, p->stmts[L].tok, rs->err, rs->len,
                  "give either T and V, or L = T - V alone",
                  "a Lagrangian L together with %s", T >= 0 ? "T" : "V");
        return -1;
    }
    if (L < 0 && T < 0) {
        lang_diag_at(p, 1, 1, rs->err, rs->len,
                     "write the kinetic energy as T = ..., for example "
                     "T = 1/2*m*x_dot^2 (or a Lagrangian L = ...)",
                     "the model has no kinetic energy T");
        return -1;
    }
    for (k = 0; k < p->nsyms && p->syms[k].kind != S_COORD; k++)
        ;
    if (k == p->nsyms) {
        lang_diag_at(p, 1, 1, rs->err, rs->len,
                     "declare one with: coord x = 0 [m]",
                     "the model has no coordinates");
        return -1;
    }
    return 0;
}

int lang_resolve(lang_prog *p, char *err, size_t len)
{
    resolver rs;
    int rc;
    memset(&rs, 0, sizeof rs);
    rs.p = p;
    rs.err = err;
    rs.len = len;
    rc = declare(&rs);
    if (rc == 0)
        rc = resolve_all(&rs);
    if (rc == -2)
        snprintf(err, len, "%s: out of memory while reading the file",
                 p->path ? p->path : "<string>");
    free(rs.values.slot);
    free(rs.outputs.slot);
    return rc < 0 ? -1 : 0;
}
