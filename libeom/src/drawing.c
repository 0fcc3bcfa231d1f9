/* drawing.c - the drawings of a model (eom/drawing.h): added to a model
 * with their callbacks, recorded by eom_system_new onto a tape of their
 * own (outputs D1, D2, ..., the drawings' values in the order they were
 * added), replayed by eom_drawings_at only. The integrators never see this
 * tape: a model pays for its drawings once, when it is recorded, and then
 * only for the frames that are drawn. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom/drawing.h"
#include "eom_internal.h"

static const char *const kind_names[] = {
    NULL,       "point",    "segment",  "polyline", "circle",
    "disk",     "box",      "cylinder", "sphere",   "frame"};

const char *eom_draw_kind_name(int kind)
{
    return kind >= EOM_DRAW_POINT && kind <= EOM_DRAW_FRAME
               ? kind_names[kind]
               : NULL;
}

/* The number of values of a kind (a polyline: 0, a multiple of 3). */
static int kind_count(int kind)
{
    static const int counts[] = {0, 3, 6, 0, 7, 7, 15, 7, 4, 13};
    return counts[kind];
}

/* A drawing's name: a C identifier (unlike eom__valid_name, a name
 * ending in _dot is allowed: a drawing names no rate). */
static int valid_name(const char *s)
{
    size_t i;
    if (!s || !s[0] || !((s[0] >= 'a' && s[0] <= 'z') ||
                         (s[0] >= 'A' && s[0] <= 'Z') || s[0] == '_'))
        return 0;
    for (i = 1; s[i]; i++)
        if (!((s[i] >= 'a' && s[i] <= 'z') || (s[i] >= 'A' && s[i] <= 'Z') ||
              (s[i] >= '0' && s[i] <= '9') || s[i] == '_'))
            return 0;
    return 1;
}

int eom_model_add_drawing(eom_model *m, const char *name, int kind,
                          int count, unsigned rgb, int flags,
                          eom_vector_fn f, void *user)
{
    eom_drawing_def *d;
    int k;
    if (!m)
        return EOM_ERR_NULL;
    if (!f)
        return eom__model_fail(m, EOM_ERR_NULL,
                               "drawing '%s': function is NULL",
                               name ? name : "(null)");
    if (!valid_name(name))
        return eom__model_fail(m, EOM_ERR_NAME,
                               "drawing name '%s' is not a C identifier",
                               name ? name : "(null)");
    if (!eom_draw_kind_name(kind))
        return eom__model_fail(m, EOM_ERR_ARG, "drawing '%s': unknown kind %d",
                               name, kind);
    if (kind == EOM_DRAW_POLYLINE ? count < 6 || count % 3 != 0
                                  : count != kind_count(kind))
        return eom__model_fail(
            m, EOM_ERR_ARG, "drawing '%s': a %s has %s values, not %d", name,
            eom_draw_kind_name(kind),
            kind == EOM_DRAW_POLYLINE ? "3 per point, at least 6"
            : kind == EOM_DRAW_POINT  ? "3"
                                      : "a fixed number of",
            count);
    if ((flags & ~EOM_DRAW_TRAIL) != 0 ||
        ((flags & EOM_DRAW_TRAIL) && kind != EOM_DRAW_POINT))
        return eom__model_fail(m, EOM_ERR_ARG,
                               "drawing '%s': only a point has a trail", name);
    if (rgb > 0xffffffu || count > 1000000 - m->n_draw_values)
        return eom__model_fail(m, EOM_ERR_ARG, "drawing '%s': %s", name,
                               rgb > 0xffffffu ? "the colour is not 0xRRGGBB"
                                               : "more than 1000000 values");
    /* names are few next to the values they draw; a drawing family of
     * thousands checks each new name against its own kind's list */
    for (k = 0; k < m->n_draws; k++)
        if (strcmp(m->draws[k].name, name) == 0)
            return eom__model_fail(m, EOM_ERR_NAME,
                                   "drawing name '%s' is already used", name);
    if (m->n_draws == m->cap_draws) {
        int nc = m->cap_draws ? 2 * m->cap_draws : 8;
        eom_drawing_def *nv = realloc(m->draws, (size_t)nc * sizeof *nv);
        if (!nv)
            return eom__model_fail(m, EOM_ERR_NOMEM, "out of memory");
        m->draws = nv;
        m->cap_draws = nc;
    }
    d = &m->draws[m->n_draws];
    memset(d, 0, sizeof *d);
    if (!(d->name = malloc(strlen(name) + 1)))
        return eom__model_fail(m, EOM_ERR_NOMEM, "out of memory");
    strcpy(d->name, name);
    d->kind = kind;
    d->count = count;
    d->offset = m->n_draw_values;
    d->rgb = rgb;
    d->flags = flags;
    d->fn = f;
    d->user = user;
    m->n_draw_values += count;
    return m->n_draws++;
}

int eom__body_drawings(eom_ctx *c)
{
    const eom_model *m = c->m;
    tp_val *v = malloc((size_t)m->n_draw_values * sizeof *v);
    char name[32];
    int k, j, rc = 0;
    if (!v) {
        c->status = EOM_ERR_NOMEM;
        snprintf(c->msg, sizeof c->msg, "out of memory");
        return 1;
    }
    for (k = 0; k < m->n_draws && rc == 0; k++) {
        const eom_drawing_def *d = &m->draws[k];
        tp_val *out = v + d->offset;
        for (j = 0; j < d->count; j++) {
            out[j].id = UINT32_MAX; /* unset: an invalid handle */
            out[j].tag = 0;
        }
        rc = d->fn(c, d->user, out);
        if (rc != 0 && c->status == EOM_OK) {
            c->status = EOM_ERR_RECORD;
            snprintf(c->msg, sizeof c->msg,
                     "the callback of the drawing %.64s returned %d", d->name,
                     rc);
        }
        for (j = 0; j < d->count && rc == 0; j++)
            if (out[j].tag == 0 && c->status == EOM_OK &&
                tp_rec_status(c->r) == TP_OK) {
                c->status = EOM_ERR_RECORD;
                snprintf(c->msg, sizeof c->msg,
                         "the callback of the drawing %.64s did not set "
                         "value %d of %d", d->name, j + 1, d->count);
                rc = 1;
            }
    }
    for (k = 0; k < m->n_draw_values && rc == 0; k++) {
        snprintf(name, sizeof name, "D%d", k + 1);
        if (tp_output(c->r, name, v[k]) < 0)
            rc = 1;
    }
    free(v);
    return rc;
}

void eom__drawings_free(eom_system *s)
{
    int k;
    for (k = 0; s->draws && k < s->ndraw; k++)
        free(s->draws[k].name);
    free(s->draws);
    s->draws = NULL;
    s->ndraw = s->ndraw_values = 0;
}

int eom__drawings_copy(eom_system *s, const eom_drawing_def *d, int n)
{
    int k;
    if (n == 0)
        return EOM_OK;
    if (!(s->draws = calloc((size_t)n, sizeof *s->draws)))
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    for (k = 0; k < n; k++) {
        s->draws[k] = d[k];
        s->draws[k].fn = NULL;
        s->draws[k].user = NULL;
        if (!(s->draws[k].name = malloc(strlen(d[k].name) + 1))) {
            s->ndraw = k;
            return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
        }
        strcpy(s->draws[k].name, d[k].name);
        s->ndraw_values += d[k].count;
    }
    s->ndraw = n;
    return EOM_OK;
}

int eom_system_ndrawings(const eom_system *s) { return s ? s->ndraw : 0; }

int eom_system_ndrawing_values(const eom_system *s)
{
    return s ? s->ndraw_values : 0;
}

int eom_drawing_get(const eom_system *s, int k, eom_drawing *out)
{
    const eom_drawing_def *d;
    if (!s || !out)
        return EOM_ERR_NULL;
    if (k < 0 || k >= s->ndraw)
        return EOM_ERR_ARG;
    d = &s->draws[k];
    out->name = d->name;
    out->kind = d->kind;
    out->count = d->count;
    out->offset = d->offset;
    out->rgb = d->rgb;
    out->flags = d->flags;
    return EOM_OK;
}

int eom_drawings_at(eom_system *s, double t, const double *x, double *out)
{
    int st, rc;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (s->ndraw == 0)
        return EOM_OK;
    if (!x || !out)
        return eom__fail(s, EOM_ERR_NULL, "eom_drawings_at: NULL argument");
    if (!isfinite(t) || !eom__finite(x, 2 * (size_t)s->n))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "the state at t = %g is not finite", t);
    st = tp_eval(s->tD.ws, eom__tape_input(&s->tD, x, t), out);
    if ((rc = eom__tape_status(s, st, "a drawing")))
        return rc;
    return EOM_OK;
}
