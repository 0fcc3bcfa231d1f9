/* system.c - eom_system_new records every callback of a model once, one
 * tape per purpose (see eom_internal.h), and prepares the solvers; also
 * the system's accessors and parameter handling. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"
#include "mass_route.h"

int eom__fail(eom_system *s, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(s->msg, sizeof s->msg, fmt, ap);
    va_end(ap);
    return status;
}

int eom__tape_status(eom_system *s, int st, const char *what)
{
    if (st == TP_OK)
        return EOM_OK;
    if (st == TP_WARN_NONFINITE)
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "%s is not finite (a domain error in the model, or "
                         "a diverging state)", what);
    if (st == TP_ERR_NOMEM)
        return eom__fail(s, EOM_ERR_NOMEM, "%s: out of memory", what);
    return eom__fail(s, EOM_ERR_ARG, "%s: %s", what, tp_strerror(st));
}

/* ---- recording ---------------------------------------------------------- */

typedef int (*body_fn)(eom_ctx *c);

typedef struct rec_arg {
    eom_ctx *c;
    body_fn body;
} rec_arg;

/* The body of a recording. The tuple evaluator may run it twice in one
 * tp_rec_run (tp_tuple_new): each time starts with a clean context, and
 * the parameters and a model file's definitions are declared again (their
 * handles are the first time's). */
static int run_body(tp_rec *r, void *user)
{
    rec_arg *a = user;
    (void)r;
    a->c->status = EOM_OK;
    a->c->msg[0] = '\0';
    a->c->read_time = false;
    a->c->lang_run = 0;
    memset(a->c->pv, 0, sizeof a->c->pv);
    return a->body(a->c);
}

static const tp_val no_val = {UINT32_MAX, 0};

/* Call a scalar callback; its result (or an error) in *out. */
static int call_scalar(eom_ctx *c, const eom_callback *cb, const char *what,
                       tp_val *out)
{
    int rc;
    *out = no_val;
    rc = cb->fn.scalar(c, cb->user, out);
    if (rc != 0 && c->status == EOM_OK) {
        c->status = EOM_ERR_RECORD;
        snprintf(c->msg, sizeof c->msg, "the %s callback returned %d", what,
                 rc);
    }
    /* returned 0 without setting *out (and no operation failed) */
    if (rc == 0 && out->tag == 0 && c->status == EOM_OK &&
        tp_rec_status(c->r) == TP_OK) {
        c->status = EOM_ERR_RECORD;
        snprintf(c->msg, sizeof c->msg, "the %s callback did not set its "
                 "value", what);
        return 1;
    }
    return rc;
}

/* The sum of a list of scalar contributions (0 for an empty list). */
static int call_sum(eom_ctx *c, const eom_cblist *list, const char *what,
                    tp_val *out)
{
    tp_val v;
    int k;
    *out = tp_const(c->r, 0.0);
    for (k = 0; k < list->n; k++) {
        if (call_scalar(c, &list->v[k], what, &v))
            return 1;
        *out = k == 0 ? v : tp_add(c->r, *out, v);
    }
    return 0;
}

static int body_L(eom_ctx *c)
{
    const eom_model *m = c->m;
    tp_val L, T, V;
    if (m->L.set) {
        if (call_scalar(c, &m->L, "Lagrangian", &L))
            return 1;
    } else {
        if (call_sum(c, &m->T, "kinetic energy", &T) ||
            call_sum(c, &m->V, "potential energy", &V))
            return 1;
        L = m->V.n ? tp_sub(c->r, T, V) : T;
    }
    return tp_output(c->r, "L", L) < 0;
}

static int body_E(eom_ctx *c)
{
    const eom_model *m = c->m;
    char name[32];
    tp_val v;
    int k;
    if (!m->L.set) {
        if (call_sum(c, &m->T, "kinetic energy", &v) ||
            tp_output(c->r, "T", v) < 0)
            return 1;
        if (call_sum(c, &m->V, "potential energy", &v) ||
            tp_output(c->r, "V", v) < 0)
            return 1;
    }
    for (k = 0; k < m->n_probes; k++) {
        eom_callback cb;
        int rc;
        cb.fn.scalar = m->probes[k].fn;
        cb.user = m->probes[k].user;
        c->in_probe = true;
        rc = call_scalar(c, &cb, m->probes[k].name, &v);
        c->in_probe = false;
        if (rc)
            return 1;
        snprintf(name, sizeof name, "probe%d", k);
        if (tp_output(c->r, name, v) < 0)
            return 1;
    }
    return 0;
}

static int body_R(eom_ctx *c)
{
    tp_val R;
    if (call_sum(c, &c->m->R, "dissipation", &R))
        return 1;
    return tp_output(c->r, "R", R) < 0;
}

/* A vector callback fills count values, declared as outputs prefix<k>
 * from number first + 1 on. */
/* Record a vector callback's count values as outputs prefix1, prefix2,
 * ... With zero_fill the entries start as the constant 0, so a callback
 * sets only its nonzero entries (forces); otherwise an entry left unset is
 * an error (a constraint forgotten is a bug, not a zero). */
static int body_vector(eom_ctx *c, const eom_callback *cb, int count,
                       int first, const char *what, const char *prefix,
                       int zero_fill)
{
    tp_val *v = malloc((size_t)count * sizeof *v);
    char name[32];
    int k, rc;
    if (!v) {
        c->status = EOM_ERR_NOMEM;
        snprintf(c->msg, sizeof c->msg, "out of memory");
        return 1;
    }
    for (k = 0; k < count; k++)
        v[k] = zero_fill ? tp_const(c->r, 0.0) : no_val;
    rc = cb->fn.vector(c, cb->user, v);
    if (rc != 0 && c->status == EOM_OK) {
        c->status = EOM_ERR_RECORD;
        snprintf(c->msg, sizeof c->msg, "the %s callback returned %d", what,
                 rc);
    }
    for (k = 0; k < count && rc == 0; k++) {
        snprintf(name, sizeof name, "%s%d", prefix, first + k + 1);
        if (v[k].tag == 0 && c->status == EOM_OK &&
            tp_rec_status(c->r) == TP_OK) {
            c->status = EOM_ERR_RECORD;
            snprintf(c->msg, sizeof c->msg,
                     "the %s callback did not set value %d of %d", what,
                     k + 1, count);
        }
        if (tp_output(c->r, name, v[k]) < 0)
            rc = 1;
    }
    free(v);
    return rc;
}

static int body_Q(eom_ctx *c)
{
    return body_vector(c, &c->m->Q, c->n, 0, "force", "Q", 1);
}

/* The constraint blocks, stacked in the order they were added. */
static int body_phi(eom_ctx *c)
{
    const eom_cblist *list = &c->m->phi;
    int k, first = 0;
    for (k = 0; k < list->n; k++) {
        if (body_vector(c, &list->v[k], list->v[k].count, first,
                        "constraint", "phi", 0))
            return 1;
        first += list->v[k].count;
    }
    return 0;
}

/* The initial state from the parameters: outputs x01 .. x0(2n). */
static int body_x0(eom_ctx *c)
{
    return body_vector(c, &c->m->x0, 2 * c->n, 0, "initial state", "x0", 0);
}

/* The velocity constraint blocks, stacked in the order they were added,
 * as outputs psi1, psi2, ... */
static int body_psi(eom_ctx *c)
{
    const eom_cblist *list = &c->m->psi;
    int k, first = 0;
    for (k = 0; k < list->n; k++) {
        if (body_vector(c, &list->v[k], list->v[k].count, first,
                        "velocity constraint", "psi", 0))
            return 1;
        first += list->v[k].count;
    }
    return 0;
}

int eom_model_run_lagrangian(const eom_model *m, tp_rec *r, const double *x)
{
    eom_ctx c;
    rec_arg arg;
    int rc;
    if (!m || !r)
        return EOM_ERR_NULL;
    if (m->status != EOM_OK)
        return m->status;
    if (m->n_coords < 1 || (!m->L.set && m->T.n == 0))
        return EOM_ERR_MODEL;
    if (tp_rec_n_indep(r) != 2 * m->n_coords &&
        tp_rec_n_indep(r) != 2 * m->n_coords + 1)
        return EOM_ERR_ARG;
    memset(&c, 0, sizeof c);
    c.r = r;
    c.m = m;
    c.role = EOM_ROLE_STATE;
    c.n = m->n_coords;
    if (tp_rec_n_indep(r) > 2 * c.n) {
        c.time_as = EOM_TIME_INDEP;
        c.time_index = 2 * c.n;
    }
    arg.c = &c;
    arg.body = body_L;
    /* x may be NULL for the recorder; the evaluators refuse it */
    rc = tp_rec_run(r, x, run_body, &arg);
    if (c.status != EOM_OK)
        return c.status;
    if (rc == TP_ERR_NOMEM)
        return EOM_ERR_NOMEM;
    if (rc == TP_ERR_NULL)
        return EOM_ERR_NULL;
    return rc < 0 ? EOM_ERR_RECORD : EOM_OK;
}

/* Record one tape and make its workspace and parameter map, with the
 * time (if a callback reads it) as time_as says: the independent after
 * the coordinates (and rates), or the parameter EOM_TIME_NAME. */
static int record_once(eom_system *s, const eom_model *m, eom_tape *et,
                       eom_role role, body_fn body, const char *what,
                       int dirs, eom_time_as time_as, bool *read_time)
{
    const int n = m->n_coords;
    const int base = role == EOM_ROLE_CONSTRAINT ? n : 2 * n;
    const int nind = base + (time_as == EOM_TIME_INDEP);
    unsigned char *group = malloc((size_t)nind);
    eom_ctx c;
    rec_arg arg;
    int rc, k;

    if (!group)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    for (k = 0; k < nind; k++)
        group[k] = (unsigned char)(k < n ? 0 : k < base ? 1 : 2);
    memset(&c, 0, sizeof c);
    c.m = m;
    c.nrows = s->m;
    c.role = role;
    c.n = n;
    c.time_as = time_as;
    c.time_index = base;
    et->dirs = dirs;
    et->tindex = time_as == EOM_TIME_INDEP ? base : -1;
    et->tparam = -1;
    et->tset = NAN;
    rc = tp_recorder_new(&c.r, nind, group, NULL);
    free(group);
    if (rc != TP_OK)
        return eom__fail(s, EOM_ERR_NOMEM, "%s: %s", what, tp_strerror(rc));
    arg.c = &c;
    arg.body = body;
    rc = tp_rec_run(c.r, NULL, run_body, &arg);
    if (c.status != EOM_OK) {
        rc = eom__fail(s, c.status, "recording the %s: %s", what, c.msg);
    } else if (rc != TP_OK) {
        rc = eom__fail(s, rc == TP_ERR_NOMEM ? EOM_ERR_NOMEM : EOM_ERR_RECORD,
                       "recording the %s: %s", what, tp_rec_errmsg(c.r));
    } else if ((rc = tp_recorder_finish(c.r, &et->tape)) != TP_OK) {
        rc = eom__fail(s, rc == TP_ERR_NOMEM ? EOM_ERR_NOMEM : EOM_ERR_RECORD,
                       "recording the %s: %s", what, tp_rec_errmsg(c.r));
    } else if ((rc = eom__workspace_fits(s, et->tape, dirs, what)) !=
               EOM_OK) {
        /* refused before allocating: the message gives the sizes */
    } else if ((rc = tp_ws_new(&et->ws, et->tape, dirs, NULL)) != TP_OK) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "%s workspace: %s", what,
                       tp_strerror(rc));
    } else {
        et->pmap = malloc((size_t)(s->np ? s->np : 1) * sizeof(int));
        et->xt = et->tindex >= 0
                     ? malloc((size_t)(et->tindex + 1) * sizeof(double))
                     : NULL;
        if (!et->pmap || (et->tindex >= 0 && !et->xt)) {
            rc = eom__fail(s, EOM_ERR_NOMEM, "out of memory");
        } else {
            for (k = 0; k < s->np; k++)
                et->pmap[k] = tp_tape_param_index(et->tape, s->params[k].name);
            if (time_as == EOM_TIME_PARAM)
                et->tparam = tp_tape_param_index(et->tape, EOM_TIME_NAME);
            rc = EOM_OK;
        }
    }
    *read_time = c.read_time;
    tp_rec_free(&c.r);
    return rc;
}

static void tape_free(eom_tape *et, bool last);

/* The tapes of a system that has recorded none yet: no time. */
static void tapes_init(eom_system *s)
{
    eom_tape *t[EOM_N_TAPES];
    int k;
    eom__tapes(s, t);
    for (k = 0; k < EOM_N_TAPES; k++) {
        t[k]->tindex = -1;
        t[k]->tparam = -1;
        t[k]->tset = NAN;
    }
}

/* Record one tape. The forces always have the time as an independent. The
 * E and R tapes have it as a parameter: they are evaluated, or
 * differentiated in (q, qd) only. The L and phi tapes are recorded first
 * as the E tape, and recorded again with the time as an independent only
 * if a callback read it: a model without time gets the tapes it always
 * had, op for op, and pays nothing; one with time pays a second
 * recording once. */
static int record(eom_system *s, const eom_model *m, eom_tape *et,
                  eom_role role, body_fn body, const char *what, int dirs,
                  bool differentiate_time)
{
    bool read_time = false;
    int rc;
    if (role == EOM_ROLE_FORCE)
        return record_once(s, m, et, role, body, what, dirs, EOM_TIME_INDEP,
                           &read_time);
    rc = record_once(s, m, et, role, body, what, dirs, EOM_TIME_PARAM,
                     &read_time);
    if (rc != EOM_OK || !differentiate_time || !read_time)
        return rc;
    tape_free(et, true);
    /* one more direction: the constraints' Jacobian includes dphi/dt */
    return record_once(s, m, et, role, body, what,
                       role == EOM_ROLE_CONSTRAINT ? dirs + 1 : dirs,
                       EOM_TIME_INDEP, &read_time);
}

/* The tape itself only when this system is its last owner. */
static void tape_free(eom_tape *et, bool last)
{
    tp_ws_free(&et->ws);
    if (last)
        tp_tape_free(&et->tape);
    et->tape = NULL;
    free(et->pmap);
    et->pmap = NULL;
    free(et->xt);
    et->xt = NULL;
}

/* ---- the system --------------------------------------------------------- */

static void free_named(eom_named *v, int n)
{
    int i;
    if (!v)
        return;
    for (i = 0; i < n; i++) {
        free(v[i].name);
        free(v[i].unit);
        free(v[i].description);
    }
    free(v);
}

void eom_system_free(eom_system **sp)
{
    eom_system *s;
    bool last;
    if (!sp || !*sp)
        return;
    s = *sp;
    /* a system that failed before its tapes existed owns none */
    last = !s->shared || atomic_fetch_sub(&s->shared->refs, 1) == 1;
    /* the mass route's workspaces replay the L and phi tapes: first */
    eom__mass_free(&s->mass);
    eom__kkt_free(&s->kkt);
    tape_free(&s->tL, last);
    tape_free(&s->tE, last);
    tape_free(&s->tR, last);
    tape_free(&s->tQ, last);
    tape_free(&s->tphi, last);
    tape_free(&s->tpsi, last);
    tape_free(&s->tx0, last);
    tape_free(&s->tD, last);
    eom__drawings_free(s);
    /* the sparse Jacobian's workspace replays the residual tape: first */
    eom__jsparse_free(&s->jsp);
    eom__ssparse_free(&s->ssp);
    tape_free(&s->tRes, last);
    if (last && s->shared) {
        int k;
        for (k = 0; k < EOM_N_TAPES; k++)
            tp_compiled_free(&s->shared->cc[k]);
    }
    if (last && s->shared) {
        eom__constraint_names_free(s->shared, s->m);
        free(s->shared);
    }
    free_named(s->coords, s->n);
    free_named(s->params, s->np);
    free_named(s->probes, s->nprobe);
    if (s->knum)
        klu_free_numeric(&s->knum, &s->kc);
    if (s->ksym)
        klu_free_symbolic(&s->ksym, &s->kc);
    free(s->Sa);
    free(s->Su);
    free(s->Svt);
    free(s->Ssv);
    free(s->Swork);
    free(s->pval);
    free(s->M);
    free(s->Mf);
    free(s->g);
    free(s->h);
    free(s->F);
    free(s->qdd);
    free(s->gR);
    free(s->Qv);
    free(s->C);
    free(s->phi);
    free(s->phid);
    free(s->phit);
    free(s->Ct);
    free(s->dir);
    free(s->gam);
    free(s->Y);
    free(s->S);
    free(s->lam);
    free(s->lam_param);
    free(s->wn);
    free(s->wm);
    free(s->wE);
    free(s->Sp);
    free(s->Si);
    free(s->Sx);
    free(s->jz);
    free(s->jres);
    free(s->jB);
    free(s->jy);
    free(s->vx);
    free(s->vdir);
    free(s->ipiv);
    free(s);
    *sp = NULL;
}

static eom_named *copy_named(const eom_named *v, int n)
{
    eom_named *c = calloc((size_t)(n ? n : 1), sizeof *c);
    int i;
    if (!c)
        return NULL;
    for (i = 0; i < n; i++) {
        c[i] = v[i];
        c[i].name = malloc(strlen(v[i].name) + 1);
        c[i].unit = malloc(strlen(v[i].unit) + 1);
        c[i].description = malloc(strlen(v[i].description) + 1);
        if (!c[i].name || !c[i].unit || !c[i].description) {
            free_named(c, i + 1);
            return NULL;
        }
        strcpy(c[i].name, v[i].name);
        strcpy(c[i].unit, v[i].unit);
        strcpy(c[i].description, v[i].description);
    }
    return c;
}

static int alloc_arrays(eom_system *s)
{
    const size_t n = (size_t)s->n, m = (size_t)s->m, mm = m ? m : 1;
    /* the n x n and m x n arrays below, in doubles (those of size n or m
     * are a rounding error beside them) */
    const double dense = 2.0 * (double)n * (double)n +
                         (double)mm * (3.0 * (double)n + (double)mm + 1.0);
    int rc;
    if ((rc = eom__arrays_fit(s, dense * sizeof(double))) != EOM_OK)
        return rc;
    s->pval = calloc(s->np ? (size_t)s->np : 1, sizeof(double));
    s->M = calloc(n * n, sizeof(double));
    s->Mf = calloc(n * n, sizeof(double));
    s->g = calloc(n, sizeof(double));
    s->h = calloc(n, sizeof(double));
    s->F = calloc(n, sizeof(double));
    s->qdd = calloc(n, sizeof(double));
    s->gR = calloc(2 * n, sizeof(double));
    s->Qv = calloc(n, sizeof(double));
    s->C = calloc(mm * n, sizeof(double));
    s->phi = calloc(mm, sizeof(double));
    s->phid = calloc(mm, sizeof(double));
    s->phit = calloc(mm, sizeof(double));
    s->Ct = calloc(mm * (n + 1), sizeof(double));
    s->dir = calloc(n + 1, sizeof(double));
    s->gam = calloc(mm, sizeof(double));
    s->Y = calloc(n * mm, sizeof(double));
    s->S = calloc(mm * mm, sizeof(double));
    s->lam = calloc(mm, sizeof(double));
    s->wn = calloc(2 * n + 1, sizeof(double));
    s->wm = calloc(mm, sizeof(double));
    s->wE = calloc((size_t)s->nprobe + 2, sizeof(double));
    if (s->mv > 0) {
        s->vx = calloc(2 * n + 1, sizeof(double));
        s->vdir = calloc(2 * n + 1, sizeof(double));
        if (!s->vx || !s->vdir)
            return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    }
    if (s->mh > 0 && s->mv > 0 &&
        !(s->ipiv = calloc((size_t)s->mh, sizeof(int))))
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    if (!s->pval || !s->M || !s->Mf || !s->g || !s->h || !s->F || !s->qdd ||
        !s->gR || !s->Qv || !s->C || !s->phi || !s->phid ||
        !s->phit || !s->Ct || !s->dir || !s->gam || !s->Y || !s->S ||
        !s->lam || !s->wn || !s->wm || !s->wE)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    return EOM_OK;
}

/* Free what setup_klu made (after a failure, so that another call
 * starts afresh). */
static void free_klu(eom_system *s)
{
    if (s->ksym)
        klu_free_symbolic(&s->ksym, &s->kc);
    free(s->Sp);
    free(s->Si);
    free(s->Sx);
    free(s->Sa);
    free(s->Su);
    free(s->Svt);
    free(s->Ssv);
    free(s->Swork);
    s->Sp = s->Si = NULL;
    s->Sx = s->Sa = s->Su = s->Svt = s->Ssv = s->Swork = NULL;
}

/* KLU for S: a dense m x m pattern, analyzed once, with the arrays of
 * S's pseudo-inverse; made at the first factorization of S (rhs.c), not
 * with the system: on the sparse route (kkt_sparse.c) S is never formed,
 * and at m = 8001 these take about 0.5 GB and a second of analysis. */
static int setup_klu(eom_system *s)
{
    const int m = s->m;
    int i, j;
    s->Sp = malloc((size_t)(m + 1) * sizeof(int));
    s->Si = malloc((size_t)m * (size_t)m * sizeof(int));
    s->Sx = malloc((size_t)m * (size_t)m * sizeof(double));
    /* the pseudo-inverse's arrays, with dgesvd's workspace queried now so
     * that no evaluation allocates */
    s->Sa = malloc((size_t)m * (size_t)m * sizeof(double));
    s->Su = malloc((size_t)m * (size_t)m * sizeof(double));
    s->Svt = malloc((size_t)m * (size_t)m * sizeof(double));
    s->Ssv = malloc((size_t)m * sizeof(double));
    if (!s->Sp || !s->Si || !s->Sx || !s->Sa || !s->Su || !s->Svt ||
        !s->Ssv) {
        free_klu(s);
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    }
    {
        double query = 0.0;
        int lwork = -1, info = 0;
        dgesvd_("A", "A", &m, &m, s->Sa, &m, s->Ssv, s->Su, &m, s->Svt, &m,
                &query, &lwork, &info, 1, 1);
        s->Slwork = info == 0 && query >= 1.0 ? (int)query : 5 * m;
        s->Swork = malloc((size_t)s->Slwork * sizeof(double));
        if (!s->Swork) {
            free_klu(s);
            return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
        }
    }
    for (j = 0; j <= m; j++)
        s->Sp[j] = j * m;
    for (j = 0; j < m; j++)
        for (i = 0; i < m; i++)
            s->Si[j * m + i] = i;
    klu_defaults(&s->kc);
    s->ksym = klu_analyze(m, s->Sp, s->Si, &s->kc);
    if (!s->ksym) {
        const int st = s->kc.status;
        free_klu(s);
        return eom__fail(s, st == KLU_OUT_OF_MEMORY ? EOM_ERR_NOMEM
                                                    : EOM_ERR_LINALG,
                         "KLU analysis of C M^-1 C^T failed (status %d)",
                         st);
    }
    return EOM_OK;
}

int eom__setup_klu(eom_system *s)
{
    return s->ksym ? EOM_OK : setup_klu(s);
}

static void copy_msg(char *dst, size_t len, const char *src)
{
    if (dst && len) {
        strncpy(dst, src, len - 1);
        dst[len - 1] = '\0';
    }
}

int eom_system_new(eom_system **out, const eom_model *m, char *errmsg,
                   size_t errmsg_len)
{
    eom_system *s;
    int rc, k;
    if (errmsg && errmsg_len)
        errmsg[0] = '\0';
    if (!out)
        return EOM_ERR_NULL;
    *out = NULL;
    if (!m)
        return EOM_ERR_NULL;
    if (m->status != EOM_OK) {
        copy_msg(errmsg, errmsg_len, m->msg);
        return m->status;
    }
    if (m->n_coords < 1 || (!m->L.set && m->T.n == 0) ||
        (m->L.set && (m->T.n > 0 || m->V.n > 0))) {
        copy_msg(errmsg, errmsg_len,
                 m->n_coords < 1 ? "the model has no coordinates"
                 : m->L.set ? "give either T and V, or a Lagrangian L, not "
                              "both"
                            : "the model has no kinetic energy or "
                              "Lagrangian");
        return EOM_ERR_MODEL;
    }
    s = calloc(1, sizeof *s);
    if (!s)
        return EOM_ERR_NOMEM;
    s->n = m->n_coords;
    s->mh = m->phi.n > 0 ? m->n_con : 0;
    s->mv = m->psi.n > 0 ? m->n_vcon : 0;
    s->m = s->mh + s->mv;
    s->np = m->n_params;
    s->nprobe = m->n_probes;
    s->has_tv = !m->L.set;
    s->has_R = m->R.n > 0;
    s->has_Q = m->Q.set;
    s->rcond_S = 1.0;
    s->rcond_S_min = 1.0;
    tapes_init(s);
    s->shared = malloc(sizeof *s->shared);
    if (!s->shared) {
        free(s);
        return EOM_ERR_NOMEM;
    }
    atomic_init(&s->shared->refs, 1);
    memset(s->shared->cc, 0, sizeof s->shared->cc);
    s->shared->con_names = NULL;
    s->shared->con_sorted = NULL;
    s->shared->n_named = 0;
    if ((rc = eom__constraint_names(s, m)) != EOM_OK)
        goto fail;
    s->coords = copy_named(m->coords, s->n);
    s->params = copy_named(m->params, s->np);
    s->probes = copy_named(m->probes, s->nprobe);
    if (!s->coords || !s->params || !s->probes) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "out of memory");
        goto fail;
    }
    /* the Lagrangian's tape, and the size of its workspace checked, before
     * the n x n matrices: a model too large for the machine is refused
     * before anything of its size is allocated (memory_fit.c) */
    if ((rc = record(s, m, &s->tL, EOM_ROLE_STATE, body_L, "Lagrangian",
                     s->n, true)) != EOM_OK)
        goto fail;
    if ((rc = alloc_arrays(s)) != EOM_OK)
        goto fail;
    for (k = 0; k < s->np; k++)
        s->pval[k] = s->params[k].v0;
    if ((s->has_tv || s->nprobe > 0) &&
        ((rc = record(s, m, &s->tE, EOM_ROLE_STATE, body_E, "energies", 1,
                      false)) != EOM_OK ||
         (rc = eom__probe_multipliers(s)) != EOM_OK))
        goto fail;
    if (s->has_R && (rc = record(s, m, &s->tR, EOM_ROLE_STATE, body_R,
                                 "dissipation", 1, false)) != EOM_OK)
        goto fail;
    if (s->has_Q && (rc = record(s, m, &s->tQ, EOM_ROLE_FORCE, body_Q,
                                 "forces", 1, false)) != EOM_OK)
        goto fail;
    if (s->mh > 0 &&
        (rc = record(s, m, &s->tphi, EOM_ROLE_CONSTRAINT, body_phi,
                     "constraints", s->n, true)) != EOM_OK)
        goto fail;
    if (s->mv > 0 &&
        ((rc = record(s, m, &s->tpsi, EOM_ROLE_VCONSTRAINT, body_psi,
                      "velocity constraints", s->n, true)) != EOM_OK ||
         (rc = eom__check_velocity_rows(s)) != EOM_OK))
        goto fail;
    if (m->x0.set && (rc = record(s, m, &s->tx0, EOM_ROLE_INITIAL, body_x0,
                                  "initial state", 1, false)) != EOM_OK)
        goto fail;
    if (m->n_draws > 0 &&
        ((rc = eom__drawings_copy(s, m->draws, m->n_draws)) != EOM_OK ||
         (rc = record(s, m, &s->tD, EOM_ROLE_STATE, eom__body_drawings,
                      "drawings", 1, false)) != EOM_OK))
        goto fail;
    s->reads_time = s->tL.tindex >= 0 || s->tE.tparam >= 0 ||
                    s->tR.tparam >= 0 || s->tphi.tindex >= 0 ||
                    s->tpsi.tindex >= 0;
    if ((rc = eom__record_residual(s)) != EOM_OK)
        goto fail;
    s->msg[0] = '\0';
    *out = s;
    return EOM_OK;
fail:
    copy_msg(errmsg, errmsg_len, s->msg);
    eom_system_free(&s);
    return rc;
}

/* A workspace of the clone c for the tape of src (NULL tape: none). */
static int clone_tape(eom_system *c, eom_tape *dst, const eom_tape *src)
{
    int k;
    if (!src->tape)
        return EOM_OK;
    dst->tape = src->tape;
    dst->dirs = src->dirs;
    dst->tindex = src->tindex;
    dst->tparam = src->tparam;
    dst->tset = NAN;
    if (tp_ws_new(&dst->ws, dst->tape, dst->dirs, NULL) != TP_OK)
        return eom__fail(c, EOM_ERR_NOMEM, "out of memory");
    if (dst->tindex >= 0 &&
        !(dst->xt = malloc((size_t)(dst->tindex + 1) * sizeof(double))))
        return eom__fail(c, EOM_ERR_NOMEM, "out of memory");
    dst->pmap = malloc((size_t)(c->np ? c->np : 1) * sizeof(int));
    if (!dst->pmap)
        return eom__fail(c, EOM_ERR_NOMEM, "out of memory");
    for (k = 0; k < c->np; k++) {
        dst->pmap[k] = src->pmap[k];
        if (dst->pmap[k] >= 0)
            tp_ws_set_param(dst->ws, dst->pmap[k], c->pval[k]);
    }
    return EOM_OK;
}

int eom_system_clone(eom_system **out, const eom_system *s, char *errmsg,
                     size_t errmsg_len)
{
    eom_system *c;
    int rc;
    if (errmsg && errmsg_len)
        errmsg[0] = '\0';
    if (!out)
        return EOM_ERR_NULL;
    *out = NULL;
    if (!s)
        return EOM_ERR_NULL;
    c = calloc(1, sizeof *c);
    if (!c)
        return EOM_ERR_NOMEM;
    c->n = s->n;
    c->m = s->m;
    c->mh = s->mh;
    c->mv = s->mv;
    c->np = s->np;
    c->nprobe = s->nprobe;
    c->has_tv = s->has_tv;
    c->has_R = s->has_R;
    c->has_Q = s->has_Q;
    c->reads_time = s->reads_time;
    c->time = s->time;
    c->alpha = s->alpha;
    c->beta = s->beta;
    c->rcond_S = 1.0;
    c->rcond_S_min = 1.0;
    tapes_init(c);
    /* from here on c owns a share of the tapes, whatever happens */
    c->shared = s->shared;
    atomic_fetch_add(&c->shared->refs, 1);
    c->coords = copy_named(s->coords, c->n);
    c->params = copy_named(s->params, c->np);
    c->probes = copy_named(s->probes, c->nprobe);
    if (!c->coords || !c->params || !c->probes) {
        rc = eom__fail(c, EOM_ERR_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = alloc_arrays(c)) != EOM_OK)
        goto fail;
    memcpy(c->pval, s->pval, (size_t)c->np * sizeof *c->pval);
    if ((rc = clone_tape(c, &c->tL, &s->tL)) != EOM_OK ||
        (rc = clone_tape(c, &c->tE, &s->tE)) != EOM_OK ||
        (rc = clone_tape(c, &c->tR, &s->tR)) != EOM_OK ||
        (rc = clone_tape(c, &c->tQ, &s->tQ)) != EOM_OK ||
        (rc = clone_tape(c, &c->tphi, &s->tphi)) != EOM_OK ||
        (rc = clone_tape(c, &c->tpsi, &s->tpsi)) != EOM_OK ||
        (rc = clone_tape(c, &c->tx0, &s->tx0)) != EOM_OK ||
        (rc = clone_tape(c, &c->tD, &s->tD)) != EOM_OK ||
        (rc = eom__drawings_copy(c, s->draws, s->ndraw)) != EOM_OK)
        goto fail;
    /* the residual tape's workspace is made on first use */
    c->tRes.tape = s->tRes.tape;
    c->tRes.dirs = s->tRes.dirs;
    c->tRes.tindex = -1;
    c->tRes.tparam = -1;
    c->tRes.tset = NAN;
    if (!(c->tRes.pmap = malloc((size_t)(c->np ? c->np : 1) * sizeof(int)))) {
        rc = eom__fail(c, EOM_ERR_NOMEM, "out of memory");
        goto fail;
    }
    memcpy(c->tRes.pmap, s->tRes.pmap, (size_t)c->np * sizeof(int));
    if ((rc = eom__probe_multipliers(c)) != EOM_OK)
        goto fail;
    if (s->compiled &&
        (rc = eom_system_set_compiled(c, 1, NULL)) != EOM_OK) {
        rc = eom__fail(c, EOM_ERR_NOMEM, "out of memory");
        goto fail;
    }
    c->msg[0] = '\0';
    *out = c;
    return EOM_OK;
fail:
    copy_msg(errmsg, errmsg_len, c->msg);
    eom_system_free(&c);
    return rc;
}

const char *eom_system_errmsg(const eom_system *s)
{
    return s ? s->msg : "NULL system";
}

/* ---- accessors ---------------------------------------------------------- */

int eom_system_ncoords(const eom_system *s) { return s ? s->n : 0; }
int eom_system_nconstraints(const eom_system *s) { return s ? s->m : 0; }
int eom_system_nvelocity_constraints(const eom_system *s)
{
    return s ? s->mv : 0;
}
int eom_system_nparams(const eom_system *s) { return s ? s->np : 0; }
int eom_system_nprobes(const eom_system *s) { return s ? s->nprobe : 0; }
int eom_system_has_tv(const eom_system *s) { return s && s->has_tv; }
int eom_system_has_dissipation(const eom_system *s) { return s && s->has_R; }

#define IN_RANGE(k, n) ((k) >= 0 && (k) < (n))

const char *eom_coord_name(const eom_system *s, int i)
{
    return s && IN_RANGE(i, s->n) ? s->coords[i].name : NULL;
}

const char *eom_coord_unit(const eom_system *s, int i)
{
    return s && IN_RANGE(i, s->n) ? s->coords[i].unit : NULL;
}

const char *eom_param_name(const eom_system *s, int k)
{
    return s && IN_RANGE(k, s->np) ? s->params[k].name : NULL;
}

const char *eom_param_unit(const eom_system *s, int k)
{
    return s && IN_RANGE(k, s->np) ? s->params[k].unit : NULL;
}

const char *eom_param_description(const eom_system *s, int k)
{
    return s && IN_RANGE(k, s->np) ? s->params[k].description : NULL;
}

double eom_param_default(const eom_system *s, int k)
{
    return s && IN_RANGE(k, s->np) ? s->params[k].v0 : NAN;
}

const char *eom_probe_name(const eom_system *s, int k)
{
    return s && IN_RANGE(k, s->nprobe) ? s->probes[k].name : NULL;
}

const char *eom_probe_unit(const eom_system *s, int k)
{
    return s && IN_RANGE(k, s->nprobe) ? s->probes[k].unit : NULL;
}

static int index_of(const eom_named *v, int n, const char *name)
{
    int i;
    if (!name)
        return -1;
    for (i = 0; i < n; i++)
        if (strcmp(v[i].name, name) == 0)
            return i;
    return -1;
}

int eom_coord_index(const eom_system *s, const char *name)
{
    return s ? index_of(s->coords, s->n, name) : -1;
}

int eom_param_index(const eom_system *s, const char *name)
{
    return s ? index_of(s->params, s->np, name) : -1;
}

void eom__tapes(eom_system *s, eom_tape *t[EOM_N_TAPES])
{
    t[0] = &s->tL;
    t[1] = &s->tE;
    t[2] = &s->tR;
    t[3] = &s->tQ;
    t[4] = &s->tphi;
    t[5] = &s->tRes;
    t[6] = &s->tpsi;
    t[7] = &s->tx0;
    t[8] = &s->tD;
}

int eom_set_param(eom_system *s, int k, double value)
{
    eom_tape *tapes[EOM_N_TAPES];
    int i;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!IN_RANGE(k, s->np))
        return eom__fail(s, EOM_ERR_ARG, "parameter %d outside 0 .. %d", k,
                         s->np - 1);
    if (!isfinite(value))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "parameter '%s' set to a non-finite value",
                         s->params[k].name);
    eom__tapes(s, tapes);
    for (i = 0; i < EOM_N_TAPES; i++)
        if (tapes[i]->ws && tapes[i]->pmap[k] >= 0)
            tp_ws_set_param(tapes[i]->ws, tapes[i]->pmap[k], value);
    s->pval[k] = value;
    s->param_gen++; /* a constant M's factor is for the old value */
    return EOM_OK;
}

double eom_get_param(const eom_system *s, int k)
{
    return s && IN_RANGE(k, s->np) ? s->pval[k] : NAN;
}

int eom_initial_state(const eom_system *s, double *x)
{
    int i, rc;
    double *in;
    if (!s || !x)
        return EOM_ERR_NULL;
    if (!s->tx0.tape) {
        for (i = 0; i < s->n; i++) {
            x[i] = s->coords[i].v0;
            x[s->n + i] = s->coords[i].v1;
        }
        return EOM_OK;
    }
    /* recorded from the parameters: its workspace follows eom_set_param;
     * the tape reads no independent, but a sweep takes all of them */
    in = calloc((size_t)tp_tape_n_indep(s->tx0.tape) + 1, sizeof *in);
    if (!in)
        return EOM_ERR_NOMEM;
    rc = tp_eval(s->tx0.ws, in, x);
    free(in);
    if (rc == TP_WARN_NONFINITE)
        return EOM_ERR_NONFINITE;
    return rc == TP_OK ? EOM_OK : EOM_ERR_NOMEM;
}

int eom_set_baumgarte(eom_system *s, double alpha, double beta)
{
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!(alpha >= 0.0) || !(beta >= 0.0) || !isfinite(alpha) ||
        !isfinite(beta))
        return eom__fail(s, EOM_ERR_ARG,
                         "Baumgarte parameters must be finite and >= 0");
    s->alpha = alpha;
    s->beta = beta;
    return EOM_OK;
}
