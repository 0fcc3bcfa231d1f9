/* build.c - the eom_model of a parsed file for one set of structural
 * settings: families expanded into numbered coordinates and parameters
 * (theta[3] is theta3, q[2,1] is q2_1), one callback per energy, force
 * block, constraint family and probe, all recording through emit.c. Before
 * the model is handed out every callback is run once, so that an index
 * out of range, a recurrence without its base case or a cycle is reported
 * with its place in the file, and the mass matrix is checked for a rate
 * that T does not depend on. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"
#include "lang.h"

typedef struct lang_cb {
    lang_inst *in;
    int sym;  /* constraint or probe symbol, or -1 */
    int stmt; /* energy statement, or -1 */
    int flat; /* probe: member of the family */
    int comp; /* probe: component of a vector or matrix (0: a scalar's) */
    int initial; /* the initial state's callback */
} lang_cb;

/* The suffix of component k of a value of n components: a vector's
 * x y z, a matrix's xx xy .. zz (row, then column). */
static const char *comp_suffix(int n, int k)
{
    static const char *const vs[3] = {"x", "y", "z"};
    static const char *const ms[9] = {"xx", "xy", "xz", "yx", "yy",
                                      "yz", "zx", "zy", "zz"};
    return n == SH_VEC ? vs[k] : ms[k];
}

static void inst_free(void *v)
{
    lang_inst *in = v;
    int k;
    if (!in)
        return;
    for (k = 0; k < in->nparams; k++)
        free(in->pname[k]);
    free(in->pname);
    free(in->setting);
    free(in->fam);
    free(in->ival);
    free(in->ival_set);
    free(in->memo);
    free(in->arena);
    free(in->pmemo);
    free(in->pdefault);
    free(in->quat_tok);
    free(in->pmemo_epoch);
    free(in->cbs);
    lang_prog_release(in->p);
    free(in);
}

/* ---- families ---------------------------------------------------------- */

/* Evaluate the ranges of a declared family. */
static int family_ranges(lang_inst *in, int s)
{
    const sym *y = &in->p->syms[s];
    family *f = &in->fam[s];
    long size = 1;
    int k;
    lang_begin(in, NULL, EOM_ROLE_STATE, "the range of a declared family");
    for (k = 0; k < y->nidx; k++) {
        long lo, hi;
        if (lang_eval_int(in, y->idx[k].lo, "the start of a range", &lo) < 0 ||
            lang_eval_int(in, y->idx[k].hi, "the end of a range", &hi) < 0)
            return -1;
        if (lo < 0 && (y->kind == S_PARAM || y->kind == S_COORD ||
                       y->kind == S_PROBE)) {
            lang_fail(in, y->idx[k].tok,
                      "the members are named after their indices (theta1, "
                      "q2_1): start at 0 or 1",
                      "the indices of %s start at %ld", y->name, lo);
            return -1;
        }
        f->lo[k] = (int)lo;
        f->cnt[k] = hi >= lo ? (int)(hi - lo + 1 > in->p->max_count
                                         ? in->p->max_count + 1
                                         : hi - lo + 1)
                             : 0;
        size *= f->cnt[k];
        if (size > in->p->max_count) {
            lang_fail(in, y->tok, NULL,
                      "%s has more than %d members", y->name,
                      in->p->max_count);
            return -1;
        }
    }
    f->size = (int)size;
    return 0;
}

/* Bind the index variables of family s to member flat; idx receives the
 * index values. */
static void bind_member(lang_inst *in, int s, int flat, long *idx)
{
    const sym *y = &in->p->syms[s];
    const family *f = &in->fam[s];
    int k;
    for (k = y->nidx - 1; k >= 0; k--) {
        idx[k] = f->lo[k] + flat % f->cnt[k];
        flat /= f->cnt[k];
        in->ival[y->idx[k].var] = idx[k];
        in->ival_set[y->idx[k].var] = 1;
    }
}

static void unbind(lang_inst *in, int s)
{
    const sym *y = &in->p->syms[s];
    int k;
    for (k = 0; k < y->nidx; k++)
        in->ival_set[y->idx[k].var] = 0;
}

/* theta + (3) -> theta3; q + (2, 1) -> q2_1; x1 + (2) -> x1_2 */
static void member_name(const sym *y, const long *idx, char *buf, size_t len)
{
    size_t n;
    int k, digit_end;
    snprintf(buf, len, "%s", y->name);
    n = strlen(buf);
    digit_end = n > 0 && buf[n - 1] >= '0' && buf[n - 1] <= '9';
    for (k = 0; k < y->nidx; k++) {
        n = strlen(buf);
        snprintf(buf + n, len - n, "%s%ld", k > 0 || digit_end ? "_" : "",
                 idx[k]);
    }
}

static int const_value(lang_inst *in, int nd, const char *what,
                       const char *name, double *out)
{
    lval v;
    if (nd < 0) {
        *out = 0.0;
        return 0;
    }
    lang_begin(in, NULL, EOM_ROLE_STATE, what);
    if (lang_eval(in, nd, &v) < 0)
        return -1;
    if (!isfinite(v.c)) {
        lang_fail(in, in->p->nodes[nd].tok, NULL, "%s of %s is %g", what,
                  name, v.c);
        return -1;
    }
    *out = v.c;
    return 0;
}

static const char *desc_text(const lang_prog *p, const sym *y, char *buf,
                             size_t len)
{
    const token *t;
    if (y->desc_tok < 0)
        return NULL;
    t = &p->toks[y->desc_tok];
    snprintf(buf, len, "%.*s", t->len - 2, p->text + t->off + 1);
    return buf;
}

/* Coordinates and parameters, family by family in the order of the
 * file. */
static int declare(lang_inst *in, eom_model *m)
{
    const lang_prog *p = in->p;
    int s, j, rc, np = 0, nc = 0, pass;
    char name[LANG_MAX_NAME + 48], desc[256], what[LANG_MAX_NAME + 64];
    for (s = 0; s < p->nsyms; s++) {
        const sym *y = &p->syms[s];
        if (y->kind == S_SETTING || y->kind == S_DEF)
            continue;
        if (family_ranges(in, s) < 0)
            return -1;
        if (y->kind == S_PARAM)
            np += in->fam[s].size;
        if (y->kind == S_COORD)
            nc += in->fam[s].size;
        if (np > in->p->max_count || nc > in->p->max_count) {
            lang_fail(in, y->tok, NULL, "more than %d %s",
                      in->p->max_count,
                      np > in->p->max_count ? "parameters" : "coordinates");
            return -1;
        }
    }
    in->pname = calloc((size_t)np + 1, sizeof *in->pname);
    in->pdefault = calloc((size_t)np + 1, sizeof *in->pdefault);
    in->pmemo = calloc((size_t)np + 1, sizeof *in->pmemo);
    in->pmemo_epoch = calloc((size_t)np + 1, sizeof *in->pmemo_epoch);
    if (!in->pname || !in->pdefault || !in->pmemo || !in->pmemo_epoch)
        goto nomem;
    /* the parameters first: a coordinate's initial value may use them */
    for (pass = 0; pass < 2 * p->nsyms; pass++) {
        const sym *y;
        family *f;
        s = pass % p->nsyms;
        y = &p->syms[s];
        f = &in->fam[s];
        if (y->kind != (pass < p->nsyms ? S_PARAM : S_COORD))
            continue;
        f->first = y->kind == S_PARAM ? in->nparams : eom_model_ncoords(m);
        for (j = 0; j < f->size; j++) {
            long idx[LANG_MAX_IDX];
            double v0, v1 = 0.0;
            bind_member(in, s, j, idx);
            member_name(y, idx, name, sizeof name);
            snprintf(what, sizeof what, "the %s",
                     y->kind == S_PARAM ? "default" : "initial value");
            if (y->kind == S_COORD)
                in->pdefault_on = 1;
            rc = const_value(in, y->value, what, name, &v0);
            if (rc == 0 && y->kind == S_COORD)
                rc = const_value(in, y->rate, "the initial rate", name, &v1);
            in->pdefault_on = 0;
            if (rc < 0)
                return -1;
            if (y->kind == S_COORD) {
                rc = eom_model_add_coord(m, name, p->units_off && !y->unit[0]
                                                      ? NULL
                                                      : y->unit,
                                         v0, v1);
            } else {
                rc = eom_model_add_param(m, name, y->unit[0] ? y->unit : NULL,
                                         v0, desc_text(p, y, desc,
                                                       sizeof desc));
                if (rc >= 0) {
                    in->pdefault[in->nparams] = v0;
                    if (!(in->pname[in->nparams++] = lang_strdup(name)))
                        goto nomem;
                }
            }
            if (rc == EOM_ERR_NOMEM)
                goto nomem;
            if (rc < 0) {
                lang_fail(in, y->tok,
                          "members of a family are named NAME and their "
                          "indices (theta1, q2_1): rename one of the two",
                          "%s%s is already the name of another parameter "
                          "or coordinate", name,
                          y->nidx ? " (a member of this family)" : "");
                return -1;
            }
        }
        unbind(in, s);
    }
    in->ncoords = eom_model_ncoords(m);
    return 0;
nomem:
    lang_fail(in, 0, NULL, "out of memory");
    return -1;
}

/* ---- callbacks --------------------------------------------------------- */

static const char *stmt_what(int kind)
{
    switch (kind) {
    case ST_T: return "the kinetic energy T";
    case ST_V: return "the potential energy V";
    case ST_L: return "the Lagrangian L";
    case ST_R: return "the dissipation function R";
    default: return "a force";
    }
}

/* Report a failure to libeom as well (its message is shorter). */
static int cb_fail(eom_ctx *c, lang_inst *in)
{
    if (c->status == EOM_OK) {
        c->status = EOM_ERR_RECORD;
        lang_copy(c->msg, sizeof c->msg, in->err);
    }
    return 1;
}

static int cb_energy(eom_ctx *c, void *user, tp_val *out)
{
    lang_cb *cb = user;
    lang_inst *in = cb->in;
    const energy_stmt *e = &in->p->stmts[cb->stmt];
    lval v;
    lang_begin(in, c, EOM_ROLE_STATE, stmt_what(e->kind));
    if (lang_eval(in, e->body, &v) < 0)
        return cb_fail(c, in);
    *out = lang_tape(in, v);
    return 0;
}

/* Run one force statement for every tuple of its binders from k on. */
static int force_tuples(lang_inst *in, const energy_stmt *e, int k,
                        tp_val *out)
{
    const lang_prog *p = in->p;
    if (k == e->nidx) {
        const node *t = &p->nodes[e->target];
        long idx[LANG_MAX_IDX];
        int j, flat;
        lval v;
        for (j = 0; j < t->nkids; j++)
            if (lang_eval_int(in, p->kids[t->kids + j], "an index",
                              &idx[j]) < 0)
                return -1;
        if ((flat = lang_family_index(in, t->sym, idx, t->tok)) < 0)
            return -1;
        flat += in->fam[t->sym].first;
        if (lang_eval(in, e->body, &v) < 0)
            return -1;
        if (!(v.k && v.c == 0.0))
            out[flat] = tp_add(in->r, out[flat], lang_tape(in, v));
        return 0;
    }
    if (e->idx[k].var < 0) /* a fixed index: evaluated with the target */
        return force_tuples(in, e, k + 1, out);
    {
        long lo, hi, i;
        const int var = e->idx[k].var;
        if (lang_eval_int(in, e->idx[k].lo, "the start of a range", &lo) < 0 ||
            lang_eval_int(in, e->idx[k].hi, "the end of a range", &hi) < 0)
            return -1;
        for (i = lo; i <= hi; i++) {
            in->ival[var] = i;
            in->ival_set[var] = 1;
            if (force_tuples(in, e, k + 1, out) < 0)
                return -1;
            if (--in->budget < 0) {
                lang_fail(in, e->tok, NULL,
                          "the model is too large: this force ranges over "
                          "too many indices");
                return -1;
            }
        }
        in->ival_set[var] = 0;
    }
    return 0;
}

static int cb_forces(eom_ctx *c, void *user, tp_val *out)
{
    lang_cb *cb = user;
    lang_inst *in = cb->in;
    int k;
    lang_begin(in, c, EOM_ROLE_FORCE, "a force");
    for (k = 0; k < in->p->nstmts; k++)
        if (in->p->stmts[k].kind == ST_FORCE &&
            force_tuples(in, &in->p->stmts[k], 0, out) < 0)
            return cb_fail(c, in);
    return 0;
}

/* Every member of a constraint family, a row per component of a vector
 * constraint (NAME_x, NAME_y, NAME_z, member by member). */
static int cb_constraint(eom_ctx *c, void *user, tp_val *out)
{
    lang_cb *cb = user;
    lang_inst *in = cb->in;
    const sym *y = &in->p->syms[cb->sym];
    const int nc = y->shape > SH_SCALAR ? y->shape : 1;
    char what[LANG_MAX_NAME + 40];
    int j, k;
    snprintf(what, sizeof what, "the %sconstraint %s",
             y->velocity ? "velocity " : "", y->name);
    lang_begin(in, c, y->velocity ? EOM_ROLE_VCONSTRAINT
                                  : EOM_ROLE_CONSTRAINT, what);
    for (j = 0; j < in->fam[cb->sym].size; j++) {
        long idx[LANG_MAX_IDX];
        lval v;
        bind_member(in, cb->sym, j, idx);
        if (nc > 1) {
            ldvec w;
            if (lang_eval_d(in, y->value, &w, 0) < 0)
                return cb_fail(c, in);
            for (k = 0; k < nc; k++)
                out[j * nc + k] = lang_tape(in, w.x[k].v);
            continue;
        }
        if (lang_eval(in, y->value, &v) < 0)
            return cb_fail(c, in);
        out[j] = lang_tape(in, v);
    }
    unbind(in, cb->sym);
    return 0;
}

/* The rows of constraint s by name, as cb_constraint stacks them: a
 * family member as its probe would be named (NAME_1_2), a vector's
 * components NAME_x .. (a member's NAME_1_x). */
static int name_rows(lang_inst *in, eom_model *m, int s, int rows)
{
    const sym *y = &in->p->syms[s];
    const int nc = y->shape > SH_SCALAR ? y->shape : 1;
    char **names = calloc((size_t)rows, sizeof *names);
    int j, k, rc = 0;
    if (!names) {
        lang_fail(in, 0, NULL, "out of memory");
        return -1;
    }
    for (j = 0; j < in->fam[s].size && rc == 0; j++) {
        long idx[LANG_MAX_IDX];
        char name[LANG_MAX_NAME + 48];
        bind_member(in, s, j, idx);
        member_name(y, idx, name, sizeof name);
        for (k = 0; k < nc && rc == 0; k++) {
            const size_t len = strlen(name) + 8;
            char *row = malloc(len);
            if (!row) {
                lang_fail(in, 0, NULL, "out of memory");
                rc = -1;
                break;
            }
            if (nc > 1)
                snprintf(row, len, "%s_%s", name, comp_suffix(nc, k));
            else
                snprintf(row, len, "%s", name);
            names[j * nc + k] = row;
        }
    }
    unbind(in, s);
    if (rc == 0)
        rc = eom_model_name_constraints(m, rows,
                                        (const char *const *)names);
    for (j = 0; j < rows; j++)
        free(names[j]);
    free(names);
    return rc;
}

static int cb_probe(eom_ctx *c, void *user, tp_val *out)
{
    lang_cb *cb = user;
    lang_inst *in = cb->in;
    const sym *y = &in->p->syms[cb->sym];
    char what[LANG_MAX_NAME + 32];
    long idx[LANG_MAX_IDX];
    lval v;
    snprintf(what, sizeof what, "the probe %s", y->name);
    lang_begin(in, c, EOM_ROLE_STATE, what);
    bind_member(in, cb->sym, cb->flat, idx);
    if (y->shape > SH_SCALAR) {
        ldvec w;
        if (lang_eval_d(in, y->value, &w, 0) < 0)
            return cb_fail(c, in);
        v = w.x[cb->comp].v;
    } else if (lang_eval(in, y->value, &v) < 0)
        return cb_fail(c, in);
    unbind(in, cb->sym);
    *out = lang_tape(in, v);
    return 0;
}

/* The initial state, recorded from the parameters: every coordinate's
 * initial value, then every initial rate, as declared (a number where
 * none is written). Used when an initial value reads a parameter, so
 * that the start follows --set and eom_set_param. */
static int cb_initial(eom_ctx *c, void *user, tp_val *out)
{
    lang_cb *cb = user;
    lang_inst *in = cb->in;
    const lang_prog *p = in->p;
    const int n = in->ncoords;
    int s, j, k;
    lang_begin(in, c, EOM_ROLE_INITIAL, "the initial state");
    for (s = 0; s < p->nsyms; s++) {
        const sym *y = &p->syms[s];
        if (y->kind != S_COORD)
            continue;
        for (j = 0; j < in->fam[s].size; j++) {
            long idx[LANG_MAX_IDX];
            const int flat = in->fam[s].first + j;
            bind_member(in, s, j, idx);
            for (k = 0; k < 2; k++) {
                const int nd = k == 0 ? y->value : y->rate;
                lval v;
                memset(&v, 0, sizeof v);
                v.k = 1;
                if (nd >= 0 && lang_eval(in, nd, &v) < 0)
                    return cb_fail(c, in);
                out[k * n + flat] = lang_tape(in, v);
            }
        }
        unbind(in, s);
    }
    return 0;
}

static lang_cb *new_cb(lang_inst *in, int s, int stmt, int flat)
{
    lang_cb *cb = &in->cbs[in->ncbs++];
    cb->in = in;
    cb->sym = s;
    cb->stmt = stmt;
    cb->flat = flat;
    cb->comp = 0;
    cb->initial = 0;
    return cb;
}

static int add_callbacks(lang_inst *in, eom_model *m)
{
    const lang_prog *p = in->p;
    int k, j, rc = 0, nforce = 0, ncb = 1;
    char name[LANG_MAX_NAME + 48];
    for (k = 0; k < p->nstmts; k++)
        ncb++;
    ncb++; /* the initial state */
    for (k = 0; k < p->nsyms; k++)
        if (p->syms[k].kind == S_PROBE && p->syms[k].draw)
            continue; /* a drawing's: lang_draw_callbacks */
        else if (p->syms[k].kind == S_PROBE)
            ncb += in->fam[k].size * (p->syms[k].shape > SH_SCALAR
                                          ? p->syms[k].shape
                                          : 1);
        else if (p->syms[k].kind == S_CONSTRAINT)
            ncb++;
    in->cbs = calloc((size_t)ncb, sizeof *in->cbs);
    if (!in->cbs) {
        lang_fail(in, 0, NULL, "out of memory");
        return -1;
    }
    for (k = 0; k < p->nstmts && rc >= 0; k++) {
        const energy_stmt *e = &p->stmts[k];
        switch (e->kind) {
        case ST_T:
            rc = eom_model_add_kinetic(m, cb_energy, new_cb(in, -1, k, 0));
            break;
        case ST_V:
            rc = eom_model_add_potential(m, cb_energy, new_cb(in, -1, k, 0));
            break;
        case ST_L:
            rc = eom_model_set_lagrangian(m, cb_energy,
                                          new_cb(in, -1, k, 0));
            break;
        case ST_R:
            rc = eom_model_add_dissipation(m, cb_energy,
                                           new_cb(in, -1, k, 0));
            break;
        default: nforce++; break;
        }
    }
    if (rc >= 0 && nforce > 0)
        rc = eom_model_set_forces(m, cb_forces, new_cb(in, -1, -1, 0));
    if (rc >= 0 && in->init_params) {
        lang_cb *cb = new_cb(in, -1, -1, 0);
        cb->initial = 1;
        rc = eom_model_set_initial(m, cb_initial, cb);
    }
    for (k = 0; k < p->nsyms && rc >= 0; k++) {
        const sym *y = &p->syms[k];
        if (y->kind == S_CONSTRAINT && in->fam[k].size > 0) {
            const int rows = in->fam[k].size *
                             (y->shape > SH_SCALAR ? y->shape : 1);
            rc = y->velocity
                     ? eom_model_add_velocity_constraints(
                           m, rows, cb_constraint, new_cb(in, k, -1, 0))
                     : eom_model_add_constraints(m, rows, cb_constraint,
                                                 new_cb(in, k, -1, 0));
            if (rc >= 0)
                rc = name_rows(in, m, k, rows);
        }
        if (y->kind != S_PROBE || y->draw)
            continue;
        for (j = 0; j < in->fam[k].size && rc >= 0; j++) {
            long idx[LANG_MAX_IDX];
            const int nc = y->shape > SH_SCALAR ? y->shape : 1;
            int comp;
            bind_member(in, k, j, idx);
            member_name(y, idx, name, sizeof name);
            /* a vector or matrix probe: a column per component, NAME_x */
            for (comp = 0; comp < nc && rc >= 0; comp++) {
                char cname[LANG_MAX_NAME + 56];
                lang_cb *cb = new_cb(in, k, -1, j);
                cb->comp = comp;
                if (nc > 1)
                    snprintf(cname, sizeof cname, "%s_%s", name,
                             comp_suffix(nc, comp));
                else
                    snprintf(cname, sizeof cname, "%s", name);
                rc = eom_model_add_probe(m, cname,
                                         y->unit[0] ? y->unit : NULL,
                                         cb_probe, cb);
            }
        }
        unbind(in, k);
    }
    if (rc >= 0 && p->ndraws > 0 && lang_draw_callbacks(in, m) < 0)
        return -1;
    if (rc < 0) {
        lang_fail(in, 0, NULL, "%s", eom_model_errmsg(m)[0]
                                         ? eom_model_errmsg(m)
                                         : eom_strerror(rc));
        return -1;
    }
    return 0;
}

/* ---- checks before the model is handed out ----------------------------- */

/* One run of the double evaluator over every callback of one role (the
 * callbacks of a role share definitions, as they do on the tapes). */
typedef struct check_arg {
    eom_ctx *c;
    lang_inst *in;
    int role;
    tp_val *out;
} check_arg;

static int check_body(tp_rec *r, void *user)
{
    check_arg *a = user;
    lang_inst *in = a->in;
    tp_val one;
    int k, j, rc = 0;
    (void)r;
    for (k = 0; k < in->ncbs && rc == 0; k++) {
        lang_cb *cb = &in->cbs[k];
        int kind = cb->stmt >= 0 ? in->p->stmts[cb->stmt].kind : -1;
        int sk = cb->sym >= 0 ? in->p->syms[cb->sym].kind : -1;
        switch (a->role) {
        case EOM_ROLE_STATE:
            /* R is checked here; T, V and L (checked on their tapes) only
             * for the lengths of their quaternions */
            if (kind == ST_R || (in->quat_check && kind >= 0 &&
                                 kind != ST_FORCE))
                rc = cb_energy(a->c, cb, &one);
            else if (sk == S_PROBE) {
                /* a multiplier a probe reads is 0 here: what is checked
                 * is the probe's domain at the start, not its value */
                a->c->in_probe = true;
                rc = cb_probe(a->c, cb, &one);
                a->c->in_probe = false;
            }
            break;
        case EOM_ROLE_FORCE:
            if (cb->stmt < 0 && cb->sym < 0 && !cb->initial) {
                for (j = 0; j < a->c->n; j++)
                    a->out[j] = tp_const(a->c->r, 0.0);
                rc = cb_forces(a->c, cb, a->out);
            }
            break;
        default: /* holonomic, then velocity constraints */
            if (sk == S_CONSTRAINT &&
                in->p->syms[cb->sym].velocity ==
                    (a->role == EOM_ROLE_VCONSTRAINT))
                rc = cb_constraint(a->c, cb, a->out);
            break;
        }
    }
    return rc;
}

/* Run every callback but T, V and L once on the double evaluator at x
 * (2n + 1 values: q, qd, t). */
/* A rotation from a quaternion that is not of unit length at the start
 * is an error where quat() is written: its components are mistyped, or
 * not those of a rotation (quat() divides by the length, so the motion
 * would go on quietly with another rotation than the one meant). */
static void check_quaternions(lang_inst *in, tp_rec *r)
{
    int k;
    for (k = 0; k < in->nquat && !in->failed; k++) {
        double n2;
        if (tp_rec_output_value(r, k, &n2) != TP_OK)
            continue;
        if (!(fabs(n2 - 1.0) <= 1e-9))
            lang_fail(in, in->quat_tok[k],
                      "a rotation's quaternion (w, x, y, z) has w^2 + x^2 "
                      "+ y^2 + z^2 = 1, as cos(a/2), sin(a/2)*axis does",
                      "the quaternion of quat() has length %.17g at the "
                      "start, not 1", sqrt(n2));
    }
}

static int run_others(lang_inst *in, const eom_model *m, const double *x)
{
    static const int roles[4] = {EOM_ROLE_STATE, EOM_ROLE_FORCE,
                                 EOM_ROLE_CONSTRAINT, EOM_ROLE_VCONSTRAINT};
    const int n = m->n_coords;
    eom_ctx c;
    tp_rec *r = NULL;
    tp_val *out = NULL;
    int k, most = n;
    for (k = 0; k < in->ncbs; k++)
        if (in->cbs[k].sym >= 0 &&
            in->p->syms[in->cbs[k].sym].kind == S_CONSTRAINT &&
            in->fam[in->cbs[k].sym].size * 3 > most)
            most = in->fam[in->cbs[k].sym].size * 3; /* a vector's rows */
    if (tp_evaluator_new(&r, 2 * n + 1, NULL) != TP_OK ||
        !(out = calloc((size_t)most + 1, sizeof *out))) {
        tp_rec_free(&r);
        lang_fail(in, 0, NULL, "out of memory");
        return -1;
    }
    for (k = 0; k < 4 && !in->failed; k++) {
        check_arg a;
        memset(&c, 0, sizeof c);
        c.r = r;
        c.m = m;
        c.n = n;
        c.role = (eom_role)roles[k];
        c.nrows = m->n_con + m->n_vcon;
        c.time_as = EOM_TIME_INDEP;
        c.time_index = 2 * n;
        a.c = &c;
        a.in = in;
        a.role = roles[k];
        a.out = out;
        in->nquat = 0;
        if (tp_rec_run(r, x, check_body, &a) != TP_OK && !in->failed)
            lang_fail(in, 0, NULL, "%s",
                      c.msg[0] ? c.msg : tp_rec_errmsg(r));
        check_quaternions(in, r);
    }
    free(out);
    tp_rec_free(&r);
    return in->failed ? -1 : 0;
}

/* The Lagrangian recorded alone. A coordinate whose row of the mass matrix
 * M = d2L/dqd2 vanishes has a rate T does not depend on; M v for one
 * direction v with no zero entries finds such rows (a row that is not
 * zero gives (M v)_i = 0 only by accident), at two unrelated states, with
 * one Hessian-vector product each. */
static int check_mass(lang_inst *in, const eom_model *m, const double *x0)
{
    const int n = m->n_coords, nx = 2 * n + 1; /* (q, qd, t) */
    unsigned char *group = malloc((size_t)nx);
    double *x = malloc((size_t)nx * sizeof *x);
    double *S = calloc((size_t)nx, sizeof *S);
    double *HS = malloc((size_t)nx * sizeof *HS);
    unsigned char *zero = malloc((size_t)n);
    const double w = 1.0;
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    tp_ws *ws = NULL;
    int rc = -1, k, i, pass;
    if (!group || !x || !S || !HS || !zero) {
        lang_fail(in, 0, NULL, "out of memory");
        goto done;
    }
    for (k = 0; k < nx; k++)
        group[k] = (unsigned char)(k < n ? 0 : k < 2 * n ? 1 : 2);
    for (i = 0; i < n; i++) {
        S[n + i] = 1.0 + 0.618 * (double)((i * 7919) % 97) / 97.0;
        zero[i] = 1;
    }
    if (tp_recorder_new(&r, nx, group, NULL) != TP_OK) {
        lang_fail(in, 0, NULL, "out of memory");
        goto done;
    }
    k = eom_model_run_lagrangian(m, r, NULL);
    if (k != EOM_OK) {
        if (!in->failed)
            lang_fail(in, 0, NULL, "recording the Lagrangian: %s",
                      eom_strerror(k));
        goto done;
    }
    if (tp_recorder_finish(r, &t) != TP_OK ||
        tp_ws_new(&ws, t, 1, NULL) != TP_OK) {
        lang_fail(in, 0, NULL, "recording the Lagrangian: %s",
                  tp_rec_errmsg(r));
        goto done;
    }
    for (pass = 0; pass < 2; pass++) {
        for (k = 0; k < nx; k++)
            x[k] = x0[k] + (pass ? 0.137 + 0.071 * (k % 11) : 0.0);
        /* a non-finite value is a question for the run, not for here */
        if (tp_hvp(ws, x, &w, 1, S, NULL, HS) < 0) {
            lang_fail(in, 0, NULL, "evaluating the Lagrangian: %s",
                      tp_ws_errmsg(ws));
            goto done;
        }
        for (i = 0; i < n; i++)
            if (HS[n + i] != 0.0)
                zero[i] = 0;
    }
    for (i = 0; i < n; i++)
        if (zero[i]) {
            int st;
            char hint[300];
            for (st = 0; st < in->p->nstmts; st++)
                if (in->p->stmts[st].kind == ST_T ||
                    in->p->stmts[st].kind == ST_L)
                    break;
            snprintf(hint, sizeof hint,
                     "every coordinate needs inertia: add its kinetic "
                     "energy, such as 1/2*m*%s_dot^2", m->coords[i].name);
            lang_fail(in, in->p->stmts[st].tok, hint,
                      "%s does not depend on %s_dot: the mass matrix would "
                      "be singular",
                      in->p->stmts[st].kind == ST_T ? "T" : "L",
                      m->coords[i].name);
            goto done;
        }
    rc = 0;
done:
    tp_ws_free(&ws);
    tp_tape_free(&t);
    tp_rec_free(&r);
    free(group);
    free(x);
    free(S);
    free(HS);
    free(zero);
    return rc;
}

/* ---- the build --------------------------------------------------------- */

int lang_build(lang_prog *p, const double *setting, eom_model **out,
               char *err, size_t len);
int lang_build(lang_prog *p, const double *setting, eom_model **out,
               char *err, size_t len)
{
    lang_inst *in = calloc(1, sizeof *in);
    eom_model *m = NULL;
    double *x0 = NULL;
    int rc, k, has_quat = 0;
    *out = NULL;
    if (!in || eom_model_new(&m) != EOM_OK) {
        free(in);
        snprintf(err, len, "out of memory");
        return EOM_ERR_NOMEM;
    }
    in->p = p;
    p->refs++;
    in->setting = calloc((size_t)p->nsyms + 1, sizeof *in->setting);
    in->fam = calloc((size_t)p->nsyms + 1, sizeof *in->fam);
    in->ival = calloc((size_t)p->nvars + 1, sizeof *in->ival);
    in->ival_set = calloc((size_t)p->nvars + 1, 1);
    if (!in->setting || !in->fam || !in->ival || !in->ival_set ||
        eom_model_attach(m, in, inst_free) != EOM_OK) {
        eom_model_free(&m);
        snprintf(err, len, "out of memory");
        return EOM_ERR_NOMEM;
    }
    memcpy(in->setting, setting, (size_t)p->nsyms * sizeof *setting);
    rc = declare(in, m) == 0 && add_callbacks(in, m) == 0 ? 0 : -1;
    for (k = 0; k < p->nnodes && rc == 0 && !has_quat; k++)
        has_quat = p->nodes[k].kind == N_CALL && p->nodes[k].op == F_QUAT;
    if (rc == 0) {
        const int n = eom_model_ncoords(m);
        /* (q, qd, t): the forces' recording reads the time too */
        x0 = malloc((2 * (size_t)n + 1) * sizeof *x0);
        if (!x0) {
            lang_fail(in, 0, NULL, "out of memory");
            rc = -1;
        } else {
            for (k = 0; k < n; k++) {
                x0[k] = m->coords[k].v0;
                x0[n + k] = m->coords[k].v1;
            }
            x0[2 * n] = 0.0;
            /* the quaternions' lengths only in the run of the double
             * evaluator (their outputs would join the Lagrangian's tape) */
            rc = check_mass(in, m, x0);
            in->quat_check = has_quat;
            if (rc == 0)
                rc = run_others(in, m, x0);
            in->quat_check = 0;
        }
    }
    free(x0);
    if (rc != 0) {
        lang_copy(err, len, in->err);
        eom_model_free(&m);
        return EOM_ERR_FILE;
    }
    *out = m;
    return EOM_OK;
}

void lang_bind_member(lang_inst *in, int s, int flat, long *idx)
{
    bind_member(in, s, flat, idx);
}

void lang_unbind(lang_inst *in, int s) { unbind(in, s); }

void lang_member_name(const sym *y, const long *idx, char *buf, size_t len)
{
    member_name(y, idx, buf, len);
}
