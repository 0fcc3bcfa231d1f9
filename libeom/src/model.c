/* model.c - building a model (coordinates, parameters, callbacks, probes)
 * and the recording context handed to callbacks (eom_ctx). A model is a
 * plain description: nothing is recorded until eom_system_new. */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"

const char *eom_strerror(int status)
{
    switch (status) {
#define EOM_TEXT_(name, value, text) \
    case value: return text;
        EOM_STATUS_LIST(EOM_TEXT_)
#undef EOM_TEXT_
    default: return "unknown status";
    }
}

const char *eom_status_name(int status)
{
    switch (status) {
#define EOM_NAME_(name, value, text) \
    case value: return #name;
        EOM_STATUS_LIST(EOM_NAME_)
#undef EOM_NAME_
    default: return "EOM_UNKNOWN";
    }
}

int eom__model_fail(eom_model *m, int status, const char *fmt, ...)
{
    if (m->status == EOM_OK) {
        va_list ap;
        m->status = status;
        va_start(ap, fmt);
        vsnprintf(m->msg, sizeof m->msg, fmt, ap);
        va_end(ap);
    }
    return status;
}

int eom_model_new(eom_model **out)
{
    if (!out)
        return EOM_ERR_NULL;
    *out = calloc(1, sizeof **out);
    return *out ? EOM_OK : EOM_ERR_NOMEM;
}

static void free_named(eom_named *v, int n)
{
    int i;
    for (i = 0; i < n; i++) {
        free(v[i].name);
        free(v[i].unit);
        free(v[i].description);
    }
    free(v);
}

void eom_model_free(eom_model **m)
{
    int i;
    if (!m || !*m)
        return;
    free_named((*m)->coords, (*m)->n_coords);
    free_named((*m)->params, (*m)->n_params);
    free_named((*m)->probes, (*m)->n_probes);
    free((*m)->names);
    free((*m)->T.v);
    free((*m)->V.v);
    free((*m)->R.v);
    for (i = 0; i < (*m)->phi.n; i++)
        eom__free_names((*m)->phi.v[i].names, (*m)->phi.v[i].count);
    for (i = 0; i < (*m)->psi.n; i++)
        eom__free_names((*m)->psi.v[i].names, (*m)->psi.v[i].count);
    free((*m)->phi.v);
    free((*m)->psi.v);
    for (i = 0; i < (*m)->n_att; i++)
        (*m)->att[i].free_fn((*m)->att[i].data);
    free((*m)->att);
    for (i = 0; i < (*m)->n_draws; i++)
        free((*m)->draws[i].name);
    free((*m)->draws);
    free(*m);
    *m = NULL;
}

int eom_model_attach(eom_model *m, void *data, void (*free_fn)(void *))
{
    if (!m || !free_fn) {
        if (free_fn)
            free_fn(data);
        return EOM_ERR_NULL;
    }
    if (m->n_att == m->cap_att) {
        int nc = m->cap_att ? 2 * m->cap_att : 4;
        eom_attached *na = realloc(m->att, (size_t)nc * sizeof *na);
        if (!na) {
            free_fn(data);
            return eom__model_fail(m, EOM_ERR_NOMEM, "out of memory");
        }
        m->att = na;
        m->cap_att = nc;
    }
    m->att[m->n_att].data = data;
    m->att[m->n_att].free_fn = free_fn;
    m->n_att++;
    return EOM_OK;
}

int eom_model_ncoords(const eom_model *m) { return m ? m->n_coords : 0; }

const char *eom_model_errmsg(const eom_model *m)
{
    return m ? m->msg : "NULL model";
}

static char *dup_or_empty(const char *s)
{
    size_t n = s ? strlen(s) : 0;
    char *d = malloc(n + 1);
    if (d) {
        if (n)
            memcpy(d, s, n);
        d[n] = '\0';
    }
    return d;
}

/* A C identifier that does not end in "_dot" (reserved for rates). */
bool eom__valid_name(const char *s)
{
    size_t i, n;
    if (!s || !s[0] || !(isalpha((unsigned char)s[0]) || s[0] == '_'))
        return false;
    for (i = 1; s[i]; i++)
        if (!(isalnum((unsigned char)s[i]) || s[i] == '_'))
            return false;
    n = i;
    return !(n >= 4 && strcmp(s + n - 4, "_dot") == 0);
}

static unsigned name_hash(const char *s)
{
    unsigned h = 2166136261u;
    while (*s)
        h = (h ^ (unsigned char)*s++) * 16777619u;
    return h ^ (h >> 15);
}

/* The slot of name in m's index, or NULL. */
static const eom_name_slot *name_find(const eom_model *m, const char *name)
{
    unsigned h;
    if (!m->names)
        return NULL;
    for (h = name_hash(name) & (unsigned)(m->names_cap - 1);
         m->names[h].name; h = (h + 1) & (unsigned)(m->names_cap - 1))
        if (strcmp(m->names[h].name, name) == 0)
            return &m->names[h];
    return NULL;
}

static void name_put(eom_name_slot *t, int cap, eom_name_slot e)
{
    unsigned h = name_hash(e.name) & (unsigned)(cap - 1);
    while (t[h].name)
        h = (h + 1) & (unsigned)(cap - 1);
    t[h] = e;
}

/* Index name (the entry's copy) as entry index of list; 0 or -1. */
static int name_add(eom_model *m, const char *name, int list, int index)
{
    eom_name_slot e;
    if (2 * (m->names_used + 1) > m->names_cap) {
        int cap = m->names_cap ? 2 * m->names_cap : 64, k;
        eom_name_slot *t = calloc((size_t)cap, sizeof *t);
        if (!t)
            return -1;
        for (k = 0; k < m->names_cap; k++)
            if (m->names[k].name)
                name_put(t, cap, m->names[k]);
        free(m->names);
        m->names = t;
        m->names_cap = cap;
    }
    e.name = name;
    e.list = list;
    e.index = index;
    name_put(m->names, m->names_cap, e);
    m->names_used++;
    return 0;
}

/* Append an entry to one of the model's lists; its index or a status. */
static int add_named(eom_model *m, eom_named **v, int *n, int *cap,
                     const char *kind, const char *name, const char *unit,
                     const char *desc)
{
    eom_named e;
    if (!eom__valid_name(name))
        return eom__model_fail(m, EOM_ERR_NAME,
                          "%s name '%s' is not a C identifier (or ends in "
                          "_dot)", kind, name ? name : "(null)");
    if (name_find(m, name))
        return eom__model_fail(m, EOM_ERR_NAME, "%s name '%s' is already used",
                          kind, name);
    if (*n == *cap) {
        int nc = *cap ? 2 * *cap : 8;
        eom_named *nv = realloc(*v, (size_t)nc * sizeof *nv);
        if (!nv)
            return eom__model_fail(m, EOM_ERR_NOMEM, "out of memory");
        *v = nv;
        *cap = nc;
    }
    memset(&e, 0, sizeof e);
    e.name = dup_or_empty(name);
    e.unit = dup_or_empty(unit);
    e.description = dup_or_empty(desc);
    if (!e.name || !e.unit || !e.description ||
        name_add(m, e.name, v == &m->coords ? 0 : v == &m->params ? 1 : 2,
                 *n) != 0) {
        free(e.name);
        free(e.unit);
        free(e.description);
        return eom__model_fail(m, EOM_ERR_NOMEM, "out of memory");
    }
    (*v)[*n] = e;
    return (*n)++;
}

int eom_model_add_coord(eom_model *m, const char *name, const char *unit,
                        double q0, double qd0)
{
    int k;
    if (!m)
        return EOM_ERR_NULL;
    if (!isfinite(q0) || !isfinite(qd0))
        return eom__model_fail(m, EOM_ERR_NONFINITE,
                          "coordinate '%s': initial value or rate is not "
                          "finite", name ? name : "(null)");
    k = add_named(m, &m->coords, &m->n_coords, &m->cap_coords, "coordinate",
                  name, unit, NULL);
    if (k >= 0) {
        m->coords[k].v0 = q0;
        m->coords[k].v1 = qd0;
    }
    return k;
}

int eom_model_add_param(eom_model *m, const char *name, const char *unit,
                        double dflt, const char *description)
{
    int k;
    if (!m)
        return EOM_ERR_NULL;
    if (!isfinite(dflt))
        return eom__model_fail(m, EOM_ERR_NONFINITE,
                          "parameter '%s': default is not finite",
                          name ? name : "(null)");
    k = add_named(m, &m->params, &m->n_params, &m->cap_params, "parameter",
                  name, unit, description);
    if (k >= 0)
        m->params[k].v0 = dflt;
    return k;
}

int eom_model_add_probe(eom_model *m, const char *name, const char *unit,
                        eom_scalar_fn f, void *user)
{
    int k;
    if (!m)
        return EOM_ERR_NULL;
    if (!f)
        return eom__model_fail(m, EOM_ERR_NULL, "probe '%s': function is NULL",
                          name ? name : "(null)");
    k = add_named(m, &m->probes, &m->n_probes, &m->cap_probes, "probe",
                  name, unit, NULL);
    if (k >= 0) {
        m->probes[k].fn = f;
        m->probes[k].user = user;
    }
    return k;
}

/* Append a contribution to a list (after clearing it when replace). */
static int push_cb(eom_model *m, eom_cblist *list, eom_callback cb,
                   bool replace, const char *what)
{
    if (!cb.fn.scalar && !cb.fn.vector)
        return eom__model_fail(m, EOM_ERR_NULL, "%s function is NULL", what);
    if (replace)
        list->n = 0;
    if (list->n == list->cap) {
        int nc = list->cap ? 2 * list->cap : 4;
        eom_callback *nv = realloc(list->v, (size_t)nc * sizeof *nv);
        if (!nv)
            return eom__model_fail(m, EOM_ERR_NOMEM, "out of memory");
        list->v = nv;
        list->cap = nc;
    }
    cb.set = true;
    list->v[list->n++] = cb;
    return EOM_OK;
}

static int scalar_cb(eom_model *m, eom_cblist *list, eom_scalar_fn f,
                     void *user, bool replace, const char *what)
{
    eom_callback cb;
    if (!m)
        return EOM_ERR_NULL;
    memset(&cb, 0, sizeof cb);
    cb.fn.scalar = f;
    cb.user = user;
    return push_cb(m, list, cb, replace, what);
}

int eom_model_set_kinetic(eom_model *m, eom_scalar_fn T, void *user)
{
    return scalar_cb(m, m ? &m->T : NULL, T, user, true, "kinetic energy");
}

int eom_model_add_kinetic(eom_model *m, eom_scalar_fn T, void *user)
{
    return scalar_cb(m, m ? &m->T : NULL, T, user, false, "kinetic energy");
}

int eom_model_set_potential(eom_model *m, eom_scalar_fn V, void *user)
{
    return scalar_cb(m, m ? &m->V : NULL, V, user, true, "potential energy");
}

int eom_model_add_potential(eom_model *m, eom_scalar_fn V, void *user)
{
    return scalar_cb(m, m ? &m->V : NULL, V, user, false,
                     "potential energy");
}

int eom_model_set_dissipation(eom_model *m, eom_scalar_fn R, void *user)
{
    return scalar_cb(m, m ? &m->R : NULL, R, user, true, "dissipation");
}

int eom_model_add_dissipation(eom_model *m, eom_scalar_fn R, void *user)
{
    return scalar_cb(m, m ? &m->R : NULL, R, user, false, "dissipation");
}

int eom_model_set_lagrangian(eom_model *m, eom_scalar_fn L, void *user)
{
    if (!m)
        return EOM_ERR_NULL;
    if (!L)
        return eom__model_fail(m, EOM_ERR_NULL, "Lagrangian function is NULL");
    m->L.fn.scalar = L;
    m->L.user = user;
    m->L.set = true;
    return EOM_OK;
}

int eom_model_set_forces(eom_model *m, eom_vector_fn Q, void *user)
{
    if (!m)
        return EOM_ERR_NULL;
    if (!Q)
        return eom__model_fail(m, EOM_ERR_NULL, "force function is NULL");
    m->Q.fn.vector = Q;
    m->Q.user = user;
    m->Q.set = true;
    return EOM_OK;
}

static int constraint_cb(eom_model *m, int count, eom_vector_fn phi,
                         void *user, bool replace)
{
    eom_callback cb;
    int rc;
    if (!m)
        return EOM_ERR_NULL;
    if (!phi)
        return eom__model_fail(m, EOM_ERR_NULL, "constraint function is NULL");
    if (count < 1 || count > 100000)
        return eom__model_fail(m, EOM_ERR_ARG, "constraint count %d", count);
    memset(&cb, 0, sizeof cb);
    cb.fn.vector = phi;
    cb.user = user;
    cb.count = count;
    if (replace) {
        int i;
        for (i = 0; i < m->phi.n; i++) {
            eom__free_names(m->phi.v[i].names, m->phi.v[i].count);
            m->phi.v[i].names = NULL;
        }
        m->n_con = 0;
    }
    rc = push_cb(m, &m->phi, cb, replace, "constraint");
    if (rc == EOM_OK) {
        m->n_con += count;
        m->last_con = &m->phi;
    }
    return rc;
}

int eom_model_set_constraints(eom_model *m, int count, eom_vector_fn phi,
                              void *user)
{
    return constraint_cb(m, count, phi, user, true);
}

int eom_model_add_constraints(eom_model *m, int count, eom_vector_fn phi,
                              void *user)
{
    return constraint_cb(m, count, phi, user, false);
}

int eom_model_set_initial(eom_model *m, eom_vector_fn x0, void *user)
{
    if (!m)
        return EOM_ERR_NULL;
    if (!x0)
        return eom__model_fail(m, EOM_ERR_NULL, "initial state function is NULL");
    memset(&m->x0, 0, sizeof m->x0);
    m->x0.fn.vector = x0;
    m->x0.user = user;
    m->x0.set = true;
    return EOM_OK;
}

int eom_model_add_velocity_constraints(eom_model *m, int count,
                                       eom_vector_fn psi, void *user)
{
    eom_callback cb;
    int rc;
    if (!m)
        return EOM_ERR_NULL;
    if (!psi)
        return eom__model_fail(m, EOM_ERR_NULL,
                          "velocity constraint function is NULL");
    if (count < 1 || count > 100000)
        return eom__model_fail(m, EOM_ERR_ARG, "velocity constraint count %d",
                          count);
    memset(&cb, 0, sizeof cb);
    cb.fn.vector = psi;
    cb.user = user;
    cb.count = count;
    rc = push_cb(m, &m->psi, cb, false, "velocity constraint");
    if (rc == EOM_OK) {
        m->n_vcon += count;
        m->last_con = &m->psi;
    }
    return rc;
}

/* ---- the recording context -------------------------------------------- */

static tp_val ctx_bad(eom_ctx *c, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static tp_val ctx_bad(eom_ctx *c, const char *fmt, ...)
{
    static const tp_val bad = {UINT32_MAX, 0};
    if (c && c->status == EOM_OK) {
        va_list ap;
        c->status = EOM_ERR_RECORD;
        va_start(ap, fmt);
        vsnprintf(c->msg, sizeof c->msg, fmt, ap);
        va_end(ap);
    }
    return bad;
}

tp_rec *eom_rec(eom_ctx *c) { return c ? c->r : NULL; }

int eom_ncoords(const eom_ctx *c) { return c ? c->n : 0; }

tp_val eom_q(eom_ctx *c, int i)
{
    if (!c)
        return ctx_bad(c, "eom_q: NULL context");
    if (c->role == EOM_ROLE_INITIAL)
        return ctx_bad(c, "eom_q: the initial state depends on the "
                          "parameters only");
    if (i < 0 || i >= c->n)
        return ctx_bad(c, "eom_q: coordinate %d outside 0 .. %d", i,
                       c->n - 1);
    return tp_indep(c->r, i);
}

tp_val eom_qd(eom_ctx *c, int i)
{
    if (!c)
        return ctx_bad(c, "eom_qd: NULL context");
    if (c->role == EOM_ROLE_CONSTRAINT)
        return ctx_bad(c, "eom_qd: constraints may depend on q only");
    if (c->role == EOM_ROLE_INITIAL)
        return ctx_bad(c, "eom_qd: the initial state depends on the "
                          "parameters only");
    if (i < 0 || i >= c->n)
        return ctx_bad(c, "eom_qd: coordinate %d outside 0 .. %d", i,
                       c->n - 1);
    return tp_indep(c->r, c->n + i);
}

tp_val eom_time(eom_ctx *c)
{
    if (!c)
        return ctx_bad(c, "eom_time: NULL context");
    if (c->role == EOM_ROLE_INITIAL)
        return ctx_bad(c, "eom_time: the initial state depends on the "
                          "parameters only");
    switch (c->time_as) {
    case EOM_TIME_INDEP:
        c->read_time = true;
        return tp_indep(c->r, c->time_index);
    case EOM_TIME_PARAM:
        c->read_time = true;
        return tp_param(c->r, EOM_TIME_NAME, 0.0);
    default:
        return ctx_bad(c, "eom_time: this recording has no time (give "
                          "eom_model_run_lagrangian a context of 2n + 1 "
                          "independents, the time last)");
    }
}

tp_val eom_multiplier(eom_ctx *c, int j)
{
    char name[32];
    if (!c)
        return ctx_bad(c, "eom_multiplier: NULL context");
    if (!c->in_probe)
        return ctx_bad(c, "eom_multiplier: a multiplier may be read by a "
                          "probe only (the energies, forces and constraints "
                          "determine it)");
    if (j < 0 || j >= c->nrows)
        return ctx_bad(c, "eom_multiplier: constraint row %d outside 0 .. "
                       "%d", j, c->nrows - 1);
    snprintf(name, sizeof name, EOM_LAMBDA_FMT, j);
    return tp_param(c->r, name, 0.0);
}

/* Parameter k's handle in this recording, declared at its first use. */
static tp_val param_handle(eom_ctx *c, int k)
{
    tp_val v;
    if (k < EOM_CTX_PARAMS && c->pv[k].tag != 0)
        return c->pv[k];
    v = tp_param(c->r, c->m->params[k].name, c->m->params[k].v0);
    if (k < EOM_CTX_PARAMS)
        c->pv[k] = v;
    return v;
}

tp_val eom_param_at(eom_ctx *c, int k)
{
    if (!c)
        return ctx_bad(c, "eom_param_at: NULL context");
    if (k < 0 || k >= c->m->n_params)
        return ctx_bad(c, "eom_param_at: no parameter of index %d (the "
                       "model has %d)", k, c->m->n_params);
    return param_handle(c, k);
}

tp_val eom_param(eom_ctx *c, const char *name)
{
    int k;
    if (!c)
        return ctx_bad(c, "eom_param: NULL context");
    {
        const eom_name_slot *e = name ? name_find(c->m, name) : NULL;
        k = e && e->list == 1 ? e->index : -1;
    }
    if (k < 0)
        return ctx_bad(c, "eom_param: no parameter named '%s'",
                       name ? name : "(null)");
    return param_handle(c, k);
}
