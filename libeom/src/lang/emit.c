/* emit.c - an expression recorded onto the tape while the model's
 * callbacks run: each operator becomes the matching tp_* call, values
 * known when the file is read (numbers, settings, indices) are folded
 * into constants, and every definition is evaluated once per recording
 * and index (memoized), so a recurrence over the links of a chain records
 * one link's operations per link. The same walker, without a recording,
 * computes defaults, ranges and indices. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"
#include "lang.h"

static const double pi = 3.14159265358979323846;

void lang_fail(lang_inst *in, int tok, const char *hint, const char *fmt,
               ...)
{
    char msg[600];
    va_list ap;
    if (in->failed)
        return;
    in->failed = 1;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    lang_diag(in->p, tok, in->err, sizeof in->err, hint, "%s", msg);
}

static lval konst(double c)
{
    lval v;
    memset(&v, 0, sizeof v);
    v.k = 1;
    v.c = c;
    return v;
}

static lval tape(tp_val t)
{
    lval v;
    memset(&v, 0, sizeof v);
    v.v = t;
    return v;
}

tp_val lang_tape(lang_inst *in, lval v)
{
    return v.k ? tp_const(in->r, v.c) : v.v;
}

void lang_begin(lang_inst *in, eom_ctx *ctx, int role, const char *what)
{
    in->ctx = ctx;
    in->r = ctx ? eom_rec(ctx) : NULL;
    in->role = role;
    in->what = what;
    in->budget = in->p->budget;
    in->depth = 0;
    /* another callback of the recording in progress (the energies and
     * probes of one tape): its definitions are on this tape already */
    if (ctx && ctx->lang_run != 0 && ctx->lang_run == in->epoch)
        return;
    /* a new recording: an earlier one's failure is not this one's (the
     * tuple evaluator repeats a run that failed for want of storage) */
    if (ctx)
        in->failed = 0;
    if (++in->epoch == 0) { /* wrapped: forget everything */
        unsigned k;
        for (k = 0; in->memo && k <= in->memo_mask; k++)
            in->memo[k].epoch = 0;
        for (k = 0; k < (unsigned)in->nparams; k++)
            in->pmemo_epoch[k] = 0;
        in->epoch = 1;
    }
    in->narena = 0; /* the components of the last recording's values */
    if (ctx)
        ctx->lang_run = in->epoch;
}

/* ---- the memo of definitions ------------------------------------------- */

static unsigned memo_hash(int s, const int32_t *idx)
{
    unsigned h = 2166136261u ^ (unsigned)s;
    int k;
    for (k = 0; k < LANG_MAX_IDX; k++)
        h = (h ^ (unsigned)idx[k]) * 16777619u;
    return h ^ (h >> 15);
}

static memo_entry *memo_slot(lang_inst *in, int s, const int32_t *idx)
{
    unsigned h, k;
    if (!in->memo || 2 * (in->memo_used + 1) > in->memo_mask + 1) {
        /* grow: entries of old recordings are dropped */
        unsigned cap = in->memo ? 2 * (in->memo_mask + 1) : 256, j;
        memo_entry *old = in->memo, *nm = calloc(cap, sizeof *nm);
        unsigned old_cap = in->memo ? in->memo_mask + 1 : 0;
        if (!nm)
            return NULL;
        for (j = 0; j < cap; j++)
            nm[j].sym = -1;
        in->memo = nm;
        in->memo_mask = cap - 1;
        in->memo_used = 0;
        for (j = 0; j < old_cap; j++) {
            memo_entry *e;
            if (old[j].sym < 0 || old[j].epoch != in->epoch)
                continue;
            h = memo_hash(old[j].sym, old[j].idx) & in->memo_mask;
            while (nm[h].sym >= 0)
                h = (h + 1) & in->memo_mask;
            e = &nm[h];
            *e = old[j];
            in->memo_used++;
        }
        free(old);
    }
    h = memo_hash(s, idx) & in->memo_mask;
    for (k = 0; k <= in->memo_mask; k++, h = (h + 1) & in->memo_mask) {
        memo_entry *e = &in->memo[h];
        if (e->sym < 0) {
            e->sym = s;
            memcpy(e->idx, idx, sizeof e->idx);
            e->epoch = 0;
            e->state = 0;
            in->memo_used++;
            return e;
        }
        if (e->sym == s && memcmp(e->idx, idx, sizeof e->idx) == 0)
            return e;
    }
    return NULL;
}

/* ---- names ------------------------------------------------------------- */

static int indices(lang_inst *in, const node *nd, long *idx)
{
    const lang_prog *p = in->p;
    int k;
    for (k = 0; k < nd->nkids; k++)
        if (lang_eval_int(in, p->kids[nd->kids + k], "an index", &idx[k]) <
            0)
            return -1;
    return 0;
}

static void idx_text(const long *idx, int n, char *buf, size_t len)
{
    int k;
    buf[0] = '\0';
    for (k = 0; k < n; k++) {
        size_t l = strlen(buf);
        snprintf(buf + l, len - l, "%s%ld", k ? ", " : "", idx[k]);
    }
}

int lang_family_index(lang_inst *in, int s, const long *idx, int tok)
{
    const sym *y = &in->p->syms[s];
    const family *f = &in->fam[s];
    long flat = 0;
    int k;
    for (k = 0; k < y->nidx; k++) {
        if (idx[k] < f->lo[k] || idx[k] >= (long)f->lo[k] + f->cnt[k]) {
            char hint[200], it[80];
            idx_text(idx, y->nidx, it, sizeof it);
            if (f->cnt[k] > 0)
                snprintf(hint, sizeof hint,
                         "%s is declared on line %d with index %d in %d..%d",
                         y->name, in->p->toks[y->tok].line, k + 1, f->lo[k],
                         f->lo[k] + f->cnt[k] - 1);
            else
                snprintf(hint, sizeof hint,
                         "%s is declared on line %d; with these settings "
                         "its index %d has no values",
                         y->name, in->p->toks[y->tok].line, k + 1);
            lang_fail(in, tok, hint, "%s[%s]: index %ld is out of range",
                      y->name, it, idx[k]);
            return -1;
        }
        flat = flat * f->cnt[k] + (idx[k] - f->lo[k]);
    }
    return (int)flat;
}

static int param_ref(lang_inst *in, const node *nd, lval *out)
{
    const sym *y = &in->p->syms[nd->sym];
    long idx[LANG_MAX_IDX];
    int flat;
    if (!in->r && in->pdefault && in->pdefault_on) {
        /* a coordinate's initial value or rate: the parameter's default
         * now, and its value in use when the run starts (the model
         * records its initial state, build.c) */
        if (indices(in, nd, idx) < 0 ||
            (flat = lang_family_index(in, nd->sym, idx, nd->tok)) < 0)
            return -1;
        *out = konst(in->pdefault[flat + in->fam[nd->sym].first]);
        in->init_params = 1;
        return 0;
    }
    if (!in->r) {
        lang_fail(in, nd->tok,
                  "a parameter can change between runs; a value fixed when "
                  "the file is read is a number or a setting",
                  "the parameter %s cannot be used here: %s must be known "
                  "when the file is read", y->name, in->what);
        return -1;
    }
    if (indices(in, nd, idx) < 0 ||
        (flat = lang_family_index(in, nd->sym, idx, nd->tok)) < 0)
        return -1;
    flat += in->fam[nd->sym].first;
    if (in->pmemo_epoch[flat] != in->epoch) {
        in->pmemo[flat] = tape(eom_param(in->ctx, in->pname[flat]));
        in->pmemo_epoch[flat] = in->epoch;
    }
    *out = in->pmemo[flat];
    return 0;
}

static int coord_ref(lang_inst *in, const node *nd, lval *out)
{
    const sym *y = &in->p->syms[nd->sym];
    long idx[LANG_MAX_IDX];
    int flat;
    if (!in->r) {
        lang_fail(in, nd->tok, NULL,
                  "the coordinate %s%s cannot be used here: %s must be "
                  "known when the file is read",
                  y->name, nd->ref == R_RATE ? "_dot" : "", in->what);
        return -1;
    }
    if (nd->ref == R_RATE && in->role == EOM_ROLE_CONSTRAINT) {
        lang_fail(in, nd->tok,
                  "holonomic constraints phi(q, t) = 0 depend on the "
                  "coordinates and the time only",
                  "the rate %s_dot cannot appear in %s", y->name, in->what);
        return -1;
    }
    if (indices(in, nd, idx) < 0 ||
        (flat = lang_family_index(in, nd->sym, idx, nd->tok)) < 0)
        return -1;
    flat += in->fam[nd->sym].first;
    *out = tape(nd->ref == R_RATE ? eom_qd(in->ctx, flat)
                                  : eom_q(in->ctx, flat));
    return 0;
}

/* lambda_NAME: the multiplier of a row of constraint NAME, read by a
 * probe. The rows are stacked as the builder adds them (build.c): every
 * holonomic constraint in the file's order, then every velocity one;
 * each member by member, a vector's components x, y, z in turn. */
static int multiplier_ref(lang_inst *in, const node *nd, lval *out)
{
    const lang_prog *p = in->p;
    const sym *y = &p->syms[nd->sym];
    const int nc = y->shape > SH_SCALAR ? y->shape : 1;
    long idx[LANG_MAX_IDX];
    int k, flat, row = 0;
    if (!in->r || !in->ctx->in_probe) {
        lang_fail(in, nd->tok,
                  "a multiplier is a result of the equations of motion: "
                  "a probe may report it, the model cannot be built on it",
                  "the multiplier lambda_%s can be read by a probe only, "
                  "not by %s", y->name, in->what);
        return -1;
    }
    if (nc > 1 && nd->op == 0) {
        lang_fail(in, nd->tok, NULL, "the constraint %s has a row per "
                  "component: write lambda_%s_x, lambda_%s_y or lambda_%s_z",
                  y->name, y->name, y->name, y->name);
        return -1;
    }
    if (nc == 1 && nd->op != 0) {
        lang_fail(in, nd->tok, NULL, "the constraint %s is a scalar: write "
                  "lambda_%s", y->name, y->name);
        return -1;
    }
    for (k = 0; k < p->nsyms; k++) {
        const sym *z = &p->syms[k];
        const int before = z->velocity == y->velocity ? k < nd->sym
                                                      : !z->velocity;
        if (z->kind == S_CONSTRAINT && before)
            row += in->fam[k].size * (z->shape > SH_SCALAR ? z->shape : 1);
    }
    if (indices(in, nd, idx) < 0 ||
        (flat = lang_family_index(in, nd->sym, idx, nd->tok)) < 0)
        return -1;
    row += flat * nc + (nc > 1 ? nd->op - 1 : 0);
    *out = tape(eom_multiplier(in->ctx, row));
    return 0;
}

/* The clause of definition s that defines index idx, binding its
 * variables (saved in saved[]); -1 if none (message set), -2 if two. */
static int find_clause(lang_inst *in, int s, const long *idx, int tok,
                       long *saved, uint8_t *saved_set)
{
    const lang_prog *p = in->p;
    const sym *y = &p->syms[s];
    int c, found = -1, k;
    char it[80], hint[300];
    for (c = y->first_clause; c >= 0; c = p->clauses[c].next) {
        const clause *cl = &p->clauses[c];
        int match = 1;
        long keep[LANG_MAX_IDX];
        uint8_t keep_set[LANG_MAX_IDX];
        for (k = 0; k < cl->nidx && k < LANG_MAX_IDX; k++)
            if (cl->idx[k].var >= 0) {
                keep[k] = in->ival[cl->idx[k].var];
                keep_set[k] = in->ival_set[cl->idx[k].var];
            }
        for (k = 0; k < cl->nidx && match; k++) {
            const binder *b = &cl->idx[k];
            long v, lo, hi;
            if (b->var < 0) {
                if (lang_eval_int(in, b->fixed, "an index", &v) < 0)
                    return -1;
                match = v == idx[k];
                continue;
            }
            if (lang_eval_int(in, b->lo, "a range", &lo) < 0 ||
                lang_eval_int(in, b->hi, "a range", &hi) < 0)
                return -1;
            match = idx[k] >= lo && idx[k] <= hi;
            in->ival[b->var] = idx[k];
            in->ival_set[b->var] = 1;
        }
        if (match && found >= 0) {
            idx_text(idx, y->nidx, it, sizeof it);
            snprintf(hint, sizeof hint, "both line %d and line %d define "
                     "it: make their index ranges disjoint",
                     p->toks[p->clauses[found].tok].line,
                     p->toks[cl->tok].line);
            lang_fail(in, tok, hint, "%s[%s] is defined twice", y->name, it);
            return -1;
        }
        if (match) {
            found = c;
            for (k = 0; k < cl->nidx; k++)
                if (cl->idx[k].var >= 0) {
                    saved[k] = keep[k];
                    saved_set[k] = keep_set[k];
                }
        } else {
            for (k = 0; k < cl->nidx; k++)
                if (cl->idx[k].var >= 0) {
                    in->ival[cl->idx[k].var] = keep[k];
                    in->ival_set[cl->idx[k].var] = keep_set[k];
                }
        }
    }
    if (found >= 0) {
        /* bind the winner's variables again (a later clause may have
         * overwritten a shared variable) */
        const clause *cl = &p->clauses[found];
        for (k = 0; k < cl->nidx; k++)
            if (cl->idx[k].var >= 0) {
                in->ival[cl->idx[k].var] = idx[k];
                in->ival_set[cl->idx[k].var] = 1;
            }
        return found;
    }
    idx_text(idx, y->nidx, it, sizeof it);
    {
        /* a recurrence one step below its first range: a missing base */
        const clause *cl = &p->clauses[y->first_clause];
        int below = 0;
        long lo;
        if (cl->nidx > 0 && cl->idx[0].var >= 0 &&
            lang_eval_int(in, cl->idx[0].lo, "a range", &lo) == 0 &&
            idx[0] == lo - 1)
            below = 1;
        in->failed = 0;
        if (below) {
            snprintf(hint, sizeof hint,
                     "a recurrence needs a base case: add a line such as "
                     "%s[%ld] = ...",
                     y->name, idx[0]);
            lang_fail(in, tok, hint,
                      "%s[%s] is not defined: %s is defined from index "
                      "%ld on (line %d)",
                      y->name, it, y->name, lo, p->toks[cl->tok].line);
        } else {
            snprintf(hint, sizeof hint, "%s is defined on line %d", y->name,
                     p->toks[y->tok].line);
            lang_fail(in, tok, hint, "%s[%s] is not defined (index out of "
                      "range)", y->name, it);
        }
    }
    return -1;
}

int lang_arena(lang_inst *in, int n)
{
    int at = in->narena;
    if (lang_grow((void **)&in->arena, &in->cap_arena, at + n,
                  sizeof *in->arena, 1 << 28) != 0)
        return -1;
    in->narena += n;
    return at;
}

/* An entry of an earlier recording holds nothing of this one. */
static void memo_fresh(lang_inst *in, memo_entry *e)
{
    if (e->epoch == in->epoch)
        return;
    e->epoch = in->epoch;
    e->state = 0;
    e->dstate = 0;
    e->vslot = -1;
    e->dslot = -1;
}

static int memo_cycle(lang_inst *in, const node *nd, const long *idx)
{
    const lang_prog *p = in->p;
    const sym *y = &p->syms[nd->sym];
    char it[80], hint[400];
    idx_text(idx, y->nidx, it, sizeof it);
    snprintf(hint, sizeof hint,
             "follow the definitions from line %d: one of them uses "
             "%s%s%s%s again; a recurrence must reach a base case",
             p->toks[y->tok].line, y->name, y->nidx ? "[" : "", it,
             y->nidx ? "]" : "");
    lang_fail(in, nd->tok, hint, "%s%s%s%s depends on itself (a cycle "
              "among definitions)", y->name, y->nidx ? "[" : "", it,
              y->nidx ? "]" : "");
    return -1;
}

/* Copy a memoized value (and derivative) of e out. */
static void memo_get(lang_inst *in, const memo_entry *e, int shape,
                     int want_d, lval *sout, ldvec *vout)
{
    int k;
    if (!vout) {
        *sout = e->val;
        return;
    }
    vout->n = shape;
    for (k = 0; k < shape; k++) {
        vout->x[k].v = shape == SH_SCALAR ? e->val : in->arena[e->vslot + k];
        memset(&vout->x[k].d, 0, sizeof vout->x[k].d);
        vout->x[k].d.k = 1;
        if (want_d)
            vout->x[k].d = in->arena[e->dslot + k];
    }
}

int lang_def_ref(lang_inst *in, const node *nd, lval *sout, ldvec *vout,
                 int want_d)
{
    const lang_prog *p = in->p;
    const sym *y = &p->syms[nd->sym];
    const int shape = y->shape ? y->shape : SH_SCALAR;
    long idx[LANG_MAX_IDX], saved[LANG_MAX_IDX];
    uint8_t saved_set[LANG_MAX_IDX];
    int32_t key[LANG_MAX_IDX] = {0};
    memo_entry *e;
    ldvec body;
    lval sval;
    int c, k, rc;
    if (indices(in, nd, idx) < 0)
        return -1;
    for (k = 0; k < y->nidx; k++) {
        if (idx[k] < -(1L << 30) || idx[k] > (1L << 30)) {
            lang_fail(in, nd->tok, NULL, "index %ld is too large", idx[k]);
            return -1;
        }
        key[k] = (int32_t)idx[k];
    }
    e = memo_slot(in, nd->sym, key);
    if (!e) {
        lang_fail(in, nd->tok, NULL, "out of memory");
        return -1;
    }
    memo_fresh(in, e);
    if (want_d ? e->dstate == 2 : e->state == 2) {
        memo_get(in, e, shape, want_d, sout, vout);
        return 0;
    }
    if (want_d ? e->dstate == 1 : e->state == 1)
        return memo_cycle(in, nd, idx);
    if (want_d)
        e->dstate = 1;
    else
        e->state = 1;
    if ((c = find_clause(in, nd->sym, idx, nd->tok, saved, saved_set)) < 0)
        return -1;
    /* a scalar's value alone takes the scalar walker (the path of every
     * planar model, unchanged); the rest the walker of shapes */
    if (!want_d && shape == SH_SCALAR)
        rc = lang_eval(in, p->clauses[c].body, &sval);
    else
        rc = lang_eval_d(in, p->clauses[c].body, &body, want_d);
    for (k = 0; k < p->clauses[c].nidx; k++)
        if (p->clauses[c].idx[k].var >= 0) {
            in->ival[p->clauses[c].idx[k].var] = saved[k];
            in->ival_set[p->clauses[c].idx[k].var] = saved_set[k];
        }
    if (rc < 0)
        return -1;
    /* the table may have grown while evaluating the body */
    e = memo_slot(in, nd->sym, key);
    if (!e) {
        lang_fail(in, nd->tok, NULL, "out of memory");
        return -1;
    }
    memo_fresh(in, e);
    if (!want_d && shape == SH_SCALAR) {
        e->val = sval;
        e->state = 2;
        memo_get(in, e, shape, 0, sout, vout);
        return 0;
    }
    if (e->state != 2) { /* the value, unless known already */
        if (shape == SH_SCALAR)
            e->val = body.x[0].v;
        else if ((e->vslot = lang_arena(in, shape)) < 0) {
            lang_fail(in, nd->tok, NULL, "out of memory");
            return -1;
        }
        for (k = 0; k < shape && shape != SH_SCALAR; k++)
            in->arena[e->vslot + k] = body.x[k].v;
        e->state = 2;
    }
    if (want_d) {
        if ((e->dslot = lang_arena(in, shape)) < 0) {
            lang_fail(in, nd->tok, NULL, "out of memory");
            return -1;
        }
        for (k = 0; k < shape; k++)
            in->arena[e->dslot + k] = body.x[k].d;
        e->dstate = 2;
    }
    memo_get(in, e, shape, want_d, sout, vout);
    return 0;
}

static int name_ref(lang_inst *in, const node *nd, lval *out)
{
    switch (nd->ref) {
    case R_PI: *out = konst(pi); return 0;
    case R_SETTING: *out = konst(in->setting[nd->sym]); return 0;
    case R_IVAR:
        if (!in->ival_set[nd->sym]) {
            lang_fail(in, nd->tok,
                      "a declared family's ranges may use settings and "
                      "numbers only",
                      "this index has no value here");
            return -1;
        }
        *out = konst((double)in->ival[nd->sym]);
        return 0;
    case R_TIME:
        /* T, V, L, R, forces, constraints and probes may all read it;
         * what is fixed when the file is read cannot */
        if (!in->r) {
            lang_fail(in, nd->tok,
                      "the time t may appear in T, V, L, R, forces, "
                      "constraints and probes",
                      "the time t cannot be used here: %s must be known "
                      "when the file is read", in->what);
            return -1;
        }
        *out = tape(eom_time(in->ctx));
        return 0;
    case R_PARAM: return param_ref(in, nd, out);
    case R_COORD:
    case R_RATE: return coord_ref(in, nd, out);
    case R_DEF: return lang_def_ref(in, nd, out, NULL, 0);
    case R_MULT: return multiplier_ref(in, nd, out);
    default:
        lang_fail(in, nd->tok, NULL, "internal error: an unresolved name");
        return -1;
    }
}

/* A name's value and, with want_d, its time derivative: a coordinate's
 * is its rate, the time's 1, the rest's 0. A rate has none here: der()
 * of an expression that holds rates would need accelerations. */
int lang_name_d(lang_inst *in, const node *nd, ldual *out, int want_d)
{
    memset(&out->d, 0, sizeof out->d);
    out->d.k = 1;
    if (want_d && nd->ref == R_MULT) {
        lang_fail(in, nd->tok, NULL, "der() of an expression that holds "
                  "the multiplier lambda_%s (it has no derivative here)",
                  in->p->syms[nd->sym].name);
        return -1;
    }
    if (want_d && nd->ref == R_RATE) {
        lang_fail(in, nd->tok,
                  "der() differentiates positions and angles; the rates "
                  "it gives are their derivatives: write der() of the "
                  "position, not of a velocity",
                  "der() of an expression that holds the rate %s_dot",
                  in->p->syms[nd->sym].name);
        return -1;
    }
    if (name_ref(in, nd, &out->v) < 0)
        return -1;
    if (!want_d)
        return 0;
    if (nd->ref == R_TIME)
        out->d.c = 1.0;
    else if (nd->ref == R_COORD) {
        long idx[LANG_MAX_IDX];
        int flat;
        if (in->role == EOM_ROLE_CONSTRAINT) {
            lang_fail(in, nd->tok,
                      "a holonomic constraint phi(q, t) = 0 reads no rates; "
                      "a constraint on the rates is written `velocity "
                      "constraint NAME = ...`",
                      "der() cannot appear in %s", in->what);
            return -1;
        }
        if (indices(in, nd, idx) < 0 ||
            (flat = lang_family_index(in, nd->sym, idx, nd->tok)) < 0)
            return -1;
        flat += in->fam[nd->sym].first;
        out->d = tape(eom_qd(in->ctx, flat));
    }
    return 0;
}

/* ---- operators --------------------------------------------------------- */

static int need_const(lang_inst *in, int tok, lval a, lval b,
                      const char *what)
{
    if (a.k && b.k)
        return 0;
    lang_fail(in, tok,
              "it decides the model's structure, so it may use numbers, "
              "settings and indices, not coordinates or parameters",
              "%s must be known when the file is read", what);
    return -1;
}

int lang_arith(lang_inst *in, int op, int tok, lval a, lval b, lval *out)
{
    tp_rec *r = in->r;
    switch (op) {
    case TK_PLUS:
        if (a.k && b.k)
            *out = konst(a.c + b.c);
        else if (a.k)
            *out = a.c == 0.0 ? b : tape(tp_addc(r, b.v, a.c));
        else if (b.k)
            *out = b.c == 0.0 ? a : tape(tp_addc(r, a.v, b.c));
        else
            *out = tape(tp_add(r, a.v, b.v));
        return 0;
    case TK_MINUS:
        if (a.k && b.k)
            *out = konst(a.c - b.c);
        else if (a.k)
            *out = tape(a.c == 0.0 ? tp_neg(r, b.v) : tp_csub(r, a.c, b.v));
        else if (b.k)
            *out = b.c == 0.0 ? a : tape(tp_subc(r, a.v, b.c));
        else
            *out = tape(tp_sub(r, a.v, b.v));
        return 0;
    case TK_STAR:
        if (a.k && b.k)
            *out = konst(a.c * b.c);
        else if (a.k || b.k) {
            lval c = a.k ? a : b, v = a.k ? b : a;
            *out = c.c == 0.0   ? konst(0.0)
                   : c.c == 1.0 ? v
                                : tape(tp_mulc(r, v.v, c.c));
        } else
            *out = tape(tp_mul(r, a.v, b.v));
        return 0;
    case TK_SLASH:
        if (b.k && b.c == 0.0) {
            lang_fail(in, tok, NULL, "division by zero");
            return -1;
        }
        if (a.k && b.k)
            *out = konst(a.c / b.c);
        else if (a.k)
            *out = a.c == 0.0 ? konst(0.0) : tape(tp_cdiv(r, a.c, b.v));
        else if (b.k)
            *out = b.c == 1.0 ? a : tape(tp_divc(r, a.v, b.c));
        else
            *out = tape(tp_div(r, a.v, b.v));
        return 0;
    case TK_CARET:
        if (a.k && b.k)
            *out = konst(pow(a.c, b.c));
        else if (b.k) {
            if (b.c == 0.0)
                *out = konst(1.0);
            else if (b.c == 1.0)
                *out = a;
            else if (b.c == 2.0)
                *out = tape(tp_sqr(r, a.v));
            else if (b.c == floor(b.c) && fabs(b.c) <= 1024)
                *out = tape(tp_powi(r, a.v, (int)b.c));
            else
                *out = tape(tp_powc(r, a.v, b.c));
        } else {
            *out = tape(tp_pow(r, lang_tape(in, a), b.v));
        }
        return 0;
    default:
        if (need_const(in, tok, a, b, "a comparison") < 0)
            return -1;
        switch (op) {
        case TK_EQ: *out = konst(a.c == b.c); break;
        case TK_NE: *out = konst(a.c != b.c); break;
        case TK_LT: *out = konst(a.c < b.c); break;
        case TK_LE: *out = konst(a.c <= b.c); break;
        case TK_GT: *out = konst(a.c > b.c); break;
        default: *out = konst(a.c >= b.c); break;
        }
        return 0;
    }
}

int lang_func(lang_inst *in, int fn, lval a, lval b, lval *out)
{
    tp_rec *r = in->r;
    const int two = fn == F_ATAN2 || fn == F_HYPOT;
    if (a.k && (!two || b.k)) {
        double x = a.c, y = b.c, v;
        switch (fn) {
        case F_SQRT: v = sqrt(x); break;
        case F_EXP: v = exp(x); break;
        case F_LOG: v = log(x); break;
        case F_SIN: v = sin(x); break;
        case F_COS: v = cos(x); break;
        case F_TAN: v = tan(x); break;
        case F_ASIN: v = asin(x); break;
        case F_ACOS: v = acos(x); break;
        case F_ATAN: v = atan(x); break;
        case F_SINH: v = sinh(x); break;
        case F_COSH: v = cosh(x); break;
        case F_TANH: v = tanh(x); break;
        case F_ABS: v = fabs(x); break;
        case F_SQR: v = x * x; break;
        case F_ATAN2: v = atan2(x, y); break;
        default: v = hypot(x, y); break;
        }
        *out = konst(v);
        return 0;
    }
    {
        tp_val x = lang_tape(in, a), y;
        switch (fn) {
        case F_SQRT: *out = tape(tp_sqrt(r, x)); break;
        case F_EXP: *out = tape(tp_exp(r, x)); break;
        case F_LOG: *out = tape(tp_log(r, x)); break;
        case F_SIN: *out = tape(tp_sin(r, x)); break;
        case F_COS: *out = tape(tp_cos(r, x)); break;
        case F_TAN: *out = tape(tp_tan(r, x)); break;
        case F_ASIN: *out = tape(tp_asin(r, x)); break;
        case F_ACOS: *out = tape(tp_acos(r, x)); break;
        case F_ATAN: *out = tape(tp_atan(r, x)); break;
        case F_SINH: *out = tape(tp_sinh(r, x)); break;
        case F_COSH: *out = tape(tp_cosh(r, x)); break;
        case F_TANH: *out = tape(tp_tanh(r, x)); break;
        case F_ABS: *out = tape(tp_abs(r, x)); break;
        case F_SQR: *out = tape(tp_sqr(r, x)); break;
        case F_ATAN2:
            y = lang_tape(in, b);
            *out = tape(tp_atan2(r, x, y));
            break;
        default:
            y = lang_tape(in, b);
            *out = tape(tp_hypot(r, x, y));
            break;
        }
    }
    return 0;
}

static int sum(lang_inst *in, const node *nd, lval *out)
{
    const lang_prog *p = in->p;
    long lo, hi, i, keep = in->ival[nd->var];
    uint8_t keep_set = in->ival_set[nd->var];
    double csum = 0.0;
    tp_val acc = {0, 0};
    int have = 0, rc = 0;
    if (lang_eval_int(in, p->kids[nd->kids], "the start of a sum", &lo) < 0 ||
        lang_eval_int(in, p->kids[nd->kids + 1], "the end of a sum", &hi) <
            0)
        return -1;
    for (i = lo; i <= hi && rc == 0; i++) {
        lval t;
        in->ival[nd->var] = i;
        in->ival_set[nd->var] = 1;
        if ((rc = lang_eval(in, p->kids[nd->kids + 2], &t)) < 0)
            break;
        if (t.k)
            csum += t.c;
        else if (!have) {
            acc = t.v;
            have = 1;
        } else
            acc = tp_add(in->r, acc, t.v);
    }
    in->ival[nd->var] = keep;
    in->ival_set[nd->var] = keep_set;
    if (rc < 0)
        return -1;
    if (!have)
        *out = konst(csum);
    else
        *out = tape(csum == 0.0 ? acc : tp_addc(in->r, acc, csum));
    return 0;
}

int lang_enter(lang_inst *in, int tok)
{
    if (--in->budget < 0) {
        lang_fail(in, tok,
                  "check the settings (a number of links or modes?) and "
                  "sums over large ranges",
                  "the model is too large: recording %s takes more than %ld "
                  "steps", in->what, in->p->budget);
        return -1;
    }
    if (++in->depth > LANG_MAX_DEPTH) {
        lang_fail(in, tok,
                  "evaluate a long recurrence in increasing order, for "
                  "example through a sum over its index",
                  "definitions nest more than %d deep", LANG_MAX_DEPTH);
        return -1;
    }
    return 0;
}

/* A scalar made by functions of vectors (dot, norm, a component, der):
 * its own frame, so that the scalar walker's frames stay small. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static int via_vector(lang_inst *in, int n, lval *out)
{
    ldvec v;
    if (lang_eval_d(in, n, &v, 0) < 0)
        return -1;
    *out = v.x[0].v;
    return 0;
}

int lang_eval(lang_inst *in, int n, lval *out)
{
    const lang_prog *p = in->p;
    const node *nd = &p->nodes[n];
    lval a, b;
    int rc = 0;
    if (in->failed)
        return -1;
    if (lang_enter(in, nd->tok) < 0)
        return -1;
    memset(&b, 0, sizeof b);
    switch (nd->kind) {
    case N_NUM: *out = konst(nd->num); break;
    case N_NAME: rc = name_ref(in, nd, out); break;
    case N_NEG:
        if ((rc = lang_eval(in, p->kids[nd->kids], &a)) == 0)
            *out = a.k ? konst(-a.c) : tape(tp_neg(in->r, a.v));
        break;
    case N_BIN:
        if ((rc = lang_eval(in, p->kids[nd->kids], &a)) == 0 &&
            (rc = lang_eval(in, p->kids[nd->kids + 1], &b)) == 0)
            rc = lang_arith(in, nd->op, nd->tok, a, b, out);
        break;
    case N_COMP: rc = via_vector(in, n, out); break;
    case N_CALL:
        if (nd->op >= F_FIRST_SPATIAL) {
            rc = via_vector(in, n, out);
            break;
        }
        if ((rc = lang_eval(in, p->kids[nd->kids], &a)) == 0 &&
            (nd->nkids < 2 ||
             (rc = lang_eval(in, p->kids[nd->kids + 1], &b)) == 0))
            rc = lang_func(in, nd->op, a, b, out);
        break;
    case N_SUM: rc = sum(in, nd, out); break;
    case N_IF:
        if ((rc = lang_eval(in, p->kids[nd->kids], &a)) == 0) {
            memset(&b, 0, sizeof b);
            b.k = 1;
            if ((rc = need_const(in, nd->tok, a, b, "the condition of if()")) ==
                0)
                rc = lang_eval(in, p->kids[nd->kids + (a.c != 0.0 ? 1 : 2)],
                               out);
        }
        break;
    default:
        lang_fail(in, nd->tok, NULL, "internal error: unknown node");
        rc = -1;
    }
    in->depth--;
    if (rc == 0 && in->r && !out->k && tp_rec_status(in->r) != TP_OK) {
        lang_fail(in, nd->tok, NULL, "recording %s failed here: %s",
                  in->what, tp_rec_errmsg(in->r));
        return -1;
    }
    return rc < 0 || in->failed ? -1 : 0;
}

int lang_eval_int(lang_inst *in, int n, const char *what, long *out)
{
    lval v;
    const node *nd = &in->p->nodes[n];
    if (lang_eval(in, n, &v) < 0)
        return -1;
    if (!v.k) {
        lang_fail(in, nd->tok,
                  "indices and ranges may use numbers, settings and other "
                  "indices, not coordinates or parameters",
                  "%s must be known when the file is read", what);
        return -1;
    }
    if (!(v.c == floor(v.c)) || fabs(v.c) > 1e9) {
        lang_fail(in, nd->tok, NULL, "%s must be a whole number, not %g",
                  what, v.c);
        return -1;
    }
    *out = (long)v.c;
    return 0;
}
