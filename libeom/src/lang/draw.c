/* draw.c - draw statements of the model-file language (docs/models.md,
 * "Drawings"):
 *
 *   draw KIND NAME[binders] = ARG, ARG, ... [color "C"] [trail]
 *
 * parser.c reads the syntax and makes each argument a probe of its own
 * (sym.draw), so that names, index ranges, shapes and units are resolved
 * and checked as for every probe; here, after lang_units, each argument is
 * checked against what its kind needs (a vector of lengths for a point, a
 * matrix for a rotation, a scalar length for a radius), with the place of
 * the argument, and the colour is read. When a model is built each member
 * of a draw statement becomes one drawing of eom/drawing.h, whose callback
 * records its arguments' components in order. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom/drawing.h"
#include "eom_internal.h"
#include "lang.h"

/* What an argument must be: its shape and its unit. */
enum { U_LENGTH, U_PURE, U_ANY };
typedef struct arg_spec {
    const char *what; /* "the centre", for messages */
    int shape;
    int unit;
} arg_spec;

/* Arguments of each kind, in order; the optional ones last. */
typedef struct kind_spec {
    const char *name;
    int kind;
    int nmin, nmax; /* arguments (a polyline: 2 .. any) */
    arg_spec a[3];
    const char *usage;
} kind_spec;

static const kind_spec kinds[] = {
    {"point", EOM_DRAW_POINT, 1, 1,
     {{"the point", SH_VEC, U_LENGTH}},
     "draw point NAME = vec(x, y, 0)"},
    {"segment", EOM_DRAW_SEGMENT, 2, 2,
     {{"the first end", SH_VEC, U_LENGTH},
      {"the second end", SH_VEC, U_LENGTH}},
     "draw segment NAME = A, B (two points)"},
    {"polyline", EOM_DRAW_POLYLINE, 2, 100000,
     {{"a point", SH_VEC, U_LENGTH}},
     "draw polyline NAME = P1, P2, P3, ... (two points or more)"},
    {"circle", EOM_DRAW_CIRCLE, 2, 3,
     {{"the centre", SH_VEC, U_LENGTH},
      {"the radius", SH_SCALAR, U_LENGTH},
      {"the normal", SH_VEC, U_ANY}},
     "draw circle NAME = CENTRE, RADIUS [, NORMAL]"},
    {"disk", EOM_DRAW_DISK, 2, 3,
     {{"the centre", SH_VEC, U_LENGTH},
      {"the radius", SH_SCALAR, U_LENGTH},
      {"the normal", SH_VEC, U_ANY}},
     "draw disk NAME = CENTRE, RADIUS [, NORMAL]"},
    {"box", EOM_DRAW_BOX, 2, 3,
     {{"the centre", SH_VEC, U_LENGTH},
      {"the size", SH_VEC, U_LENGTH},
      {"the rotation", SH_MAT, U_PURE}},
     "draw box NAME = CENTRE, vec(LX, LY, LZ) [, ROTATION]"},
    {"cylinder", EOM_DRAW_CYLINDER, 3, 3,
     {{"the first end", SH_VEC, U_LENGTH},
      {"the second end", SH_VEC, U_LENGTH},
      {"the radius", SH_SCALAR, U_LENGTH}},
     "draw cylinder NAME = END1, END2, RADIUS"},
    {"sphere", EOM_DRAW_SPHERE, 2, 2,
     {{"the centre", SH_VEC, U_LENGTH},
      {"the radius", SH_SCALAR, U_LENGTH}},
     "draw sphere NAME = CENTRE, RADIUS"},
    {"frame", EOM_DRAW_FRAME, 3, 3,
     {{"the origin", SH_VEC, U_LENGTH},
      {"the rotation", SH_MAT, U_PURE},
      {"the length of the axes", SH_SCALAR, U_LENGTH}},
     "draw frame NAME = ORIGIN, ROTATION, LENGTH"},
};
enum { NKINDS = sizeof kinds / sizeof kinds[0] };

/* Named colours; any other is written "#rrggbb". */
static const struct {
    const char *name;
    unsigned rgb;
} colours[] = {
    {"black", 0x000000},  {"white", 0xffffff},  {"gray", 0x808080},
    {"grey", 0x808080},   {"red", 0xe41a1c},    {"green", 0x2ca02c},
    {"blue", 0x1f5fbf},   {"orange", 0xff7f0e}, {"purple", 0x9467bd},
    {"brown", 0x8c564b},  {"pink", 0xe377c2},   {"yellow", 0xf0c800},
    {"cyan", 0x17becf},   {"magenta", 0xd000d0}, {"olive", 0x8a8a1a},
    {"navy", 0x1a237e},   {"teal", 0x00897b},
};

/* The colour of a drawing without one: a drawing of its own colour, in
 * turn (the same list as the page's probe plot, so that it stays apart
 * from the markers the tests look for: none is pure red or green). */
static const unsigned palette[] = {0x1f77b4, 0xff7f0e, 0x2ca02c, 0x9467bd,
                                   0x8c564b, 0x17becf, 0x7f7f7f, 0xbcbd22};

static const kind_spec *kind_of(const lang_prog *p, int tok)
{
    char buf[LANG_MAX_NAME + 1];
    int k;
    lang_tok_text(p, tok, buf, sizeof buf);
    for (k = 0; k < NKINDS; k++)
        if (strcmp(buf, kinds[k].name) == 0)
            return &kinds[k];
    return NULL;
}

static const arg_spec *arg_of(const kind_spec *ks, int a)
{
    /* a polyline's points are all alike */
    return &ks->a[ks->kind == EOM_DRAW_POLYLINE ? 0 : a];
}

static int hexdigit(char c)
{
    return c >= '0' && c <= '9'   ? c - '0'
           : c >= 'a' && c <= 'f' ? c - 'a' + 10
           : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                  : -1;
}

/* The colour of token tok ("red", "#1f77b4"): 0, or -1 with a message. */
static int colour(const lang_prog *p, int tok, unsigned *rgb, char *err,
                  size_t len)
{
    const token *t = &p->toks[tok];
    const char *s = p->text + t->off + 1; /* inside the quotes */
    const int n = t->len - 2;
    int k;
    if (n == 7 && s[0] == '#') {
        unsigned v = 0;
        for (k = 1; k < 7 && hexdigit(s[k]) >= 0; k++)
            v = v * 16 + (unsigned)hexdigit(s[k]);
        if (k == 7) {
            *rgb = v;
            return 0;
        }
    }
    for (k = 0; k < (int)(sizeof colours / sizeof colours[0]); k++)
        if ((int)strlen(colours[k].name) == n &&
            memcmp(colours[k].name, s, (size_t)n) == 0) {
            *rgb = colours[k].rgb;
            return 0;
        }
    lang_diag(p, tok, err, len,
              "write \"#rrggbb\" or one of black white gray red green blue "
              "orange purple brown pink yellow cyan magenta olive navy teal",
              "unknown colour %.*s", t->len, p->text + t->off);
    return -1;
}

/* Argument a (sym k) of drawing d against its spec. */
static int check_arg(lang_prog *p, const lang_draw *d, const kind_spec *ks,
                     int a, int k, char *err, size_t len)
{
    const sym *y = &p->syms[k];
    const arg_spec *as = arg_of(ks, a);
    const char *name = p->syms[d->first_sym].name;
    dim dm, want;
    char dd[80];
    if (y->shape != as->shape) {
        const int rot = as->shape == SH_VEC && y->shape == SH_MAT;
        lang_diag(p, y->draw_tok, err, len,
                  as->shape == SH_VEC
                      ? "a position is a vector: vec(x, y, z) (vec(x, y, 0) "
                        "in a plane)"
                  : as->shape == SH_MAT
                      ? "a rotation is a matrix: rotz(a), rot(axis, a), "
                        "quat(w, x, y, z) or a product of them"
                      : "a radius or a length is a scalar",
                  "%s of the %s %s is %s%s; it must be %s", as->what,
                  ks->name, name, lang_shape_name(y->shape),
                  rot ? " (a rotation?)" : "", lang_shape_name(as->shape));
        return -1;
    }
    if (p->units_off || as->unit == U_ANY)
        return 0;
    if (lang_dim_of(p, y->value, &dm, err, len) < 0)
        return -1;
    memset(&want, 0, sizeof want);
    if (as->unit == U_LENGTH)
        want.e[1] = 2; /* m (exponents are doubled) */
    if (dm.any || lang_dim_equal(dm, want))
        return 0;
    lang_dim_format(dm, dd, sizeof dd);
    lang_diag(p, y->draw_tok, err, len,
              as->unit == U_LENGTH
                  ? "a drawing's positions, sizes and radii are lengths, in m"
                  : "a rotation is a pure number: rotx(a), rot(u, a), "
                    "quat(...)",
              "%s of the %s %s is in %s, not in %s", as->what, ks->name, name,
              dd, as->unit == U_LENGTH ? "m" : "1 (a pure number)");
    return -1;
}

int lang_draws(lang_prog *p, char *err, size_t len)
{
    int k, a;
    for (k = 0; k < p->ndraws; k++) {
        lang_draw *d = &p->draws[k];
        const kind_spec *ks = kind_of(p, d->kind_tok);
        char buf[LANG_MAX_NAME + 1];
        if (!ks) {
            lang_diag(p, d->kind_tok, err, len,
                      "the kinds are point, segment, polyline, circle, "
                      "disk, box, cylinder, sphere and frame",
                      "'%s' is not a kind of drawing",
                      lang_tok_text(p, d->kind_tok, buf, sizeof buf));
            return -1;
        }
        if (d->nargs < ks->nmin || d->nargs > ks->nmax) {
            lang_diag(p, d->kind_tok, err, len, ks->usage,
                      "a %s takes %d%s%s argument%s, not %d", ks->name,
                      ks->nmin,
                      ks->nmax > 3 ? " or more"
                      : ks->nmax > ks->nmin ? " or " : "",
                      ks->nmax > ks->nmin && ks->nmax <= 3
                          ? (ks->nmax == 3 ? "3" : "2")
                          : "",
                      ks->nmax > 1 ? "s" : "", d->nargs);
            return -1;
        }
        if (d->trail_tok >= 0 && ks->kind != EOM_DRAW_POINT) {
            lang_diag(p, d->trail_tok, err, len, NULL,
                      "only a point has a trail, not a %s", ks->name);
            return -1;
        }
        d->kind = ks->kind;
        d->rgb = palette[k % (int)(sizeof palette / sizeof palette[0])];
        if (d->color_tok >= 0 &&
            colour(p, d->color_tok, &d->rgb, err, len) < 0)
            return -1;
        for (a = 0; a < d->nargs; a++)
            if (check_arg(p, d, ks, a, d->first_sym + a, err, len) < 0)
                return -1;
    }
    return 0;
}

/* ---- one build --------------------------------------------------------- */

typedef struct draw_cb {
    lang_inst *in;
    int draw; /* index in p->draws */
    int flat; /* member of the statement's family */
    char what[LANG_MAX_NAME + 72];
} draw_cb;

/* Record the arguments' components in order, then the defaults of the
 * optional ones left out: a circle's normal (0, 0, 1), a box's rotation
 * the identity. */
static int cb_draw(eom_ctx *c, void *user, tp_val *out)
{
    draw_cb *cb = user;
    lang_inst *in = cb->in;
    const lang_draw *d = &in->p->draws[cb->draw];
    long idx[LANG_MAX_IDX];
    lval one, zero;
    int a, j, pos = 0;
    lang_begin(in, c, EOM_ROLE_STATE, cb->what);
    for (a = 0; a < d->nargs; a++) {
        const int k = d->first_sym + a;
        const sym *y = &in->p->syms[k];
        ldvec w;
        int rc;
        lang_bind_member(in, k, cb->flat, idx);
        rc = lang_eval_d(in, y->value, &w, 0);
        lang_unbind(in, k);
        if (rc < 0) {
            if (c->status == EOM_OK) {
                c->status = EOM_ERR_RECORD;
                lang_copy(c->msg, sizeof c->msg, in->err);
            }
            return 1;
        }
        for (j = 0; j < w.n; j++)
            out[pos++] = lang_tape(in, w.x[j].v);
    }
    memset(&one, 0, sizeof one);
    one.k = 1;
    zero = one;
    one.c = 1.0;
    if ((d->kind == EOM_DRAW_CIRCLE || d->kind == EOM_DRAW_DISK) &&
        d->nargs == 2) {
        out[pos++] = lang_tape(in, zero);
        out[pos++] = lang_tape(in, zero);
        out[pos++] = lang_tape(in, one);
    }
    if (d->kind == EOM_DRAW_BOX && d->nargs == 2)
        for (j = 0; j < 9; j++)
            out[pos++] = lang_tape(in, j % 4 == 0 ? one : zero);
    return 0;
}

int lang_draw_callbacks(lang_inst *in, eom_model *m)
{
    const lang_prog *p = in->p;
    draw_cb *cbs;
    long n = 0, idx[LANG_MAX_IDX];
    int k, j, rc;
    char name[LANG_MAX_NAME + 48];
    for (k = 0; k < p->ndraws; k++)
        n += in->fam[p->draws[k].first_sym].size;
    if (n == 0)
        return 0;
    cbs = calloc((size_t)n, sizeof *cbs);
    if (!cbs || eom_model_attach(m, cbs, free) != EOM_OK) {
        lang_fail(in, 0, NULL, "out of memory");
        return -1;
    }
    n = 0;
    for (k = 0; k < p->ndraws; k++) {
        const lang_draw *d = &p->draws[k];
        const sym *y = &p->syms[d->first_sym];
        const int count = d->kind == EOM_DRAW_POLYLINE ? 3 * d->nargs
                          : d->kind == EOM_DRAW_POINT  ? 3
                          : d->kind == EOM_DRAW_SEGMENT ? 6
                          : d->kind == EOM_DRAW_BOX    ? 15
                          : d->kind == EOM_DRAW_SPHERE ? 4
                          : d->kind == EOM_DRAW_FRAME  ? 13
                                                       : 7;
        for (j = 0; j < in->fam[d->first_sym].size; j++) {
            draw_cb *cb = &cbs[n++];
            lang_bind_member(in, d->first_sym, j, idx);
            lang_member_name(y, idx, name, sizeof name);
            lang_unbind(in, d->first_sym);
            cb->in = in;
            cb->draw = k;
            cb->flat = j;
            snprintf(cb->what, sizeof cb->what, "the drawing %s", name);
            rc = eom_model_add_drawing(m, name, d->kind, count, d->rgb,
                                       d->trail_tok >= 0 ? EOM_DRAW_TRAIL
                                                         : 0,
                                       cb_draw, cb);
            if (rc < 0) {
                lang_fail(in, d->tok, NULL, "%s", eom_model_errmsg(m));
                return -1;
            }
        }
    }
    return 0;
}
