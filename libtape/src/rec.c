/* rec.c - the backend-neutral recording API.
 *
 * Every public recording call lands here first: the context and operand
 * handles are checked (NULL, another context's handle, an invalid handle,
 * a finished recording), errors become sticky in the context, names of
 * parameters and outputs are managed, and only then the backend's apply()
 * runs. Backends therefore see only valid ids.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "tape_internal.h"

static const tp_val invalid_val = {UINT32_MAX, 0};

/* A tag that differs between contexts with high probability: the address
 * of the context mixed with the creation time (no process-wide counter). */
static uint32_t make_tag(const void *p)
{
    struct timespec ts = {0, 0};
    uint64_t h;
    (void)timespec_get(&ts, TIME_UTC);
    h = (uint64_t)(uintptr_t)p ^ ((uint64_t)ts.tv_nsec << 20) ^
        (uint64_t)ts.tv_sec;
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ull;
    h ^= h >> 33;
    return (uint32_t)h | 1u; /* never 0: 0 marks an invalid handle */
}

int tp__rec_init(tp_rec *r, const tp_backend *be, int n_indep,
                 const tp_allocator *al)
{
    memset(r, 0, sizeof *r);
    r->be = be;
    r->al = tp__allocator(al);
    r->n_indep = n_indep;
    r->tag = make_tag(r);
    return TP_OK;
}

/* A list of names: entries below *n are this run's; the names of entries
 * below *kept (NULL: none) are allocated still, kept from earlier runs of
 * an evaluator, which declare the same names run after run. */
static void free_named(tp_rec *r, tp_named **v, size_t *n, size_t *cap,
                       size_t *kept)
{
    size_t i, m = kept && *kept > *n ? *kept : *n;
    for (i = 0; i < m; i++)
        tp__strfree(&r->al, (*v)[i].name);
    tp__free(&r->al, *v, *cap * sizeof **v);
    *v = NULL;
    *n = *cap = 0;
    if (kept)
        *kept = 0;
}

/* Empty the list for a new run, keeping its names for the next. */
static void clear_named(size_t *n, size_t *kept)
{
    if (*n > *kept)
        *kept = *n;
    *n = 0;
}

void tp__rec_release(tp_rec *r)
{
    free_named(r, &r->params, &r->n_params, &r->cap_params,
               &r->kept_params);
    free_named(r, &r->outs, &r->n_outs, &r->cap_outs, &r->kept_outs);
    free_named(r, &r->over, &r->n_over, &r->cap_over, NULL);
    tp__index_free(&r->al, &r->param_index);
    tp__index_free(&r->al, &r->out_index);
}

int tp__rec_fail(tp_rec *r, int status, const char *fmt, ...)
{
    if (r->status >= 0) {
        va_list ap;
        r->status = status;
        va_start(ap, fmt);
        vsnprintf(r->msg, sizeof r->msg, fmt, ap);
        va_end(ap);
    }
    return status;
}

static bool is_evaluator(const tp_rec *r) { return r->be->value != NULL; }

/* May ops be recorded into r now? */
static bool writable(tp_rec *r, const char *fn)
{
    if (r->status < 0)
        return false;
    if (r->finished) {
        tp__rec_fail(r, TP_ERR_FINISHED, "%s: the recording is finished", fn);
        return false;
    }
    if (is_evaluator(r) && !r->running) {
        tp__rec_fail(r, TP_ERR_BACKEND,
                     "%s: an evaluator computes only inside tp_rec_run", fn);
        return false;
    }
    return true;
}

static bool check_val(tp_rec *r, tp_val a, const char *fn, int argno)
{
    if (a.tag == 0) {
        tp__rec_fail(r, TP_ERR_HANDLE, "%s: operand %d is an invalid handle",
                     fn, argno);
        return false;
    }
    if (a.tag != r->tag) {
        tp__rec_fail(r, TP_ERR_FOREIGN,
                     "%s: operand %d belongs to another recording", fn, argno);
        return false;
    }
    if (a.id >= r->n_ids) {
        tp__rec_fail(r, TP_ERR_HANDLE,
                     "%s: operand %d is not a value of this run", fn, argno);
        return false;
    }
    return true;
}

static tp_val make_val(tp_rec *r, uint32_t id)
{
    tp_val v;
    if (id == TP_NO_SLOT) /* the backend failed and said why */
        return invalid_val;
    v.id = id;
    v.tag = r->tag;
    return v;
}

/* An op's public name, tp_ + its table name in lower case: for messages
 * only, so it is built only when a check fails. */
static const char *op_fn_name(int op, char *fn, size_t len)
{
    const char *name = tp__opinfo[op].name;
    size_t k;
    fn[0] = 't';
    fn[1] = 'p';
    fn[2] = '_';
    for (k = 0; name[k] && k + 4 < len; k++)
        fn[3 + k] = (char)(name[k] >= 'A' && name[k] <= 'Z'
                               ? name[k] - 'A' + 'a' : name[k]);
    fn[3 + k] = '\0';
    return fn;
}

/* Does a hold a value of this run? (the test of check_val, silently) */
static bool val_ok(const tp_rec *r, tp_val a)
{
    return a.tag != 0 && a.tag == r->tag && a.id < r->n_ids;
}

/* Why op may not be recorded now (the message, with the op's name, and
 * the status); false if it may after all. */
TP_COLD static bool op_refused(tp_rec *r, int op, tp_val a, tp_val b,
                               int binary)
{
    char fn[24];
    op_fn_name(op, fn, sizeof fn);
    return !writable(r, fn) || !check_val(r, a, fn, 1) ||
           (binary && !check_val(r, b, fn, 2));
}

tp_val tp__rec_op(tp_rec *r, int op, tp_val a, tp_val b, double c)
{
    const int binary = tp__opinfo[op].kind == TP_KIND_BINARY;
    if (!r)
        return invalid_val;
    /* every op of every run passes here: the common case checks without
     * formatting the op's name, which only a message needs */
    if ((r->status < 0 || r->finished || (is_evaluator(r) && !r->running) ||
         !val_ok(r, a) || (binary && !val_ok(r, b))) &&
        op_refused(r, op, a, b, binary))
        return invalid_val;
    if (!binary)
        b.id = 0;
    return make_val(r, r->be->apply(r, op, a.id, b.id, c));
}

/* ---- leaves, parameters, outputs -------------------------------------- */

tp_val tp_indep(tp_rec *r, int i)
{
    if (!r || !writable(r, "tp_indep"))
        return invalid_val;
    if (i < 0 || i >= r->n_indep) {
        tp__rec_fail(r, TP_ERR_SIZE,
                     "tp_indep: index %d outside 0 .. %d", i, r->n_indep - 1);
        return invalid_val;
    }
    return make_val(r, (uint32_t)i); /* backends make indeps ids 0..n-1 */
}

tp_val tp_const(tp_rec *r, double c)
{
    if (!r || !writable(r, "tp_const"))
        return invalid_val;
    return make_val(r, r->be->constant(r, c));
}

static bool valid_name(tp_rec *r, const char *name, const char *fn)
{
    if (!name || !name[0]) {
        tp__rec_fail(r, name ? TP_ERR_NAME : TP_ERR_NULL,
                     "%s: the name is %s", fn, name ? "empty" : "NULL");
        return false;
    }
    return true;
}

static tp_named *find_named(tp_named *v, size_t n, const char *name)
{
    size_t i;
    for (i = 0; i < n; i++)
        if (strcmp(v[i].name, name) == 0)
            return &v[i];
    return NULL;
}

/* Append (name, value, id) to a list owned by r, reusing the name kept
 * at that place if it is the same; false on failure. */
static bool push_named(tp_rec *r, tp_named **v, size_t *n, size_t *cap,
                       size_t *kept, const char *name, double value,
                       uint32_t id)
{
    const bool reuse = kept && *n < *kept;
    char *copy;
    if (tp__grow(&r->al, (void **)v, sizeof **v, cap, *n + 1) != 0)
        return false;
    if (!reuse || strcmp((*v)[*n].name, name) != 0) {
        copy = tp__strdup(&r->al, name);
        if (!copy)
            return false;
        if (reuse)
            tp__strfree(&r->al, (*v)[*n].name);
        else if (kept)
            *kept = *n + 1;
        (*v)[*n].name = copy;
    }
    (*v)[*n].value = value;
    (*v)[*n].id = id;
    (*n)++;
    return true;
}

tp_val tp_param(tp_rec *r, const char *name, double dflt)
{
    tp_named *p, *o;
    double value = dflt;
    uint32_t id;
    if (!r || !writable(r, "tp_param") || !valid_name(r, name, "tp_param"))
        return invalid_val;
    /* A function declares its parameters in the same order at every run:
     * the previous run's next name (they were distinct, and this run's so
     * far are the ones before it) is a new one without a search. Only
     * otherwise a search among this run's names (a model with hundreds of
     * parameters searched them all at every run). */
    if (r->params_in_order && r->n_params < r->prev_params &&
        strcmp(r->params[r->n_params].name, name) == 0)
        p = NULL;
    else if ((p = tp__index_find(&r->al, &r->param_index, r->params,
                                 r->n_params, name)) == NULL)
        r->params_in_order = false;
    if (p) {
        /* NaN defaults compare unequal; treat identical bits as equal. */
        if (!(p->value == dflt) && memcmp(&p->value, &dflt, sizeof dflt)) {
            tp__rec_fail(r, TP_ERR_NAME,
                         "tp_param: '%s' declared again with default %g "
                         "(first %g)", name, dflt, p->value);
            return invalid_val;
        }
        return make_val(r, p->id);
    }
    if (is_evaluator(r)) {
        o = find_named(r->over, r->n_over, name);
        if (o)
            value = o->value;
    }
    id = r->be->param(r, (int)r->n_params, value);
    if (id == TP_NO_SLOT)
        return invalid_val;
    if (!push_named(r, &r->params, &r->n_params, &r->cap_params,
                    &r->kept_params, name, dflt, id)) {
        tp__rec_fail(r, TP_ERR_NOMEM, "tp_param: out of memory");
        return invalid_val;
    }
    return make_val(r, id);
}

int tp_output(tp_rec *r, const char *name, tp_val v)
{
    if (!r)
        return TP_ERR_NULL;
    if (!writable(r, "tp_output") || !valid_name(r, name, "tp_output") ||
        !check_val(r, v, "tp_output", 1))
        return r->status;
    if (tp__index_find(&r->al, &r->out_index, r->outs, r->n_outs, name))
        return tp__rec_fail(r, TP_ERR_NAME,
                            "tp_output: output '%s' declared twice", name);
    if (!push_named(r, &r->outs, &r->n_outs, &r->cap_outs, &r->kept_outs,
                    name, 0.0, v.id))
        return tp__rec_fail(r, TP_ERR_NOMEM, "tp_output: out of memory");
    return TP_OK;
}

/* ---- running a function ----------------------------------------------- */

/* An evaluator's new run forgets the previous one (keeps overrides). */
static void fresh_run(tp_rec *r)
{
    r->status = TP_OK;
    r->msg[0] = '\0';
    r->prev_params = r->n_params;
    r->params_in_order = true;
    clear_named(&r->n_params, &r->kept_params);
    clear_named(&r->n_outs, &r->kept_outs);
    tp__index_reset(&r->param_index);
    tp__index_reset(&r->out_index);
}

int tp_rec_run(tp_rec *r, const double *x, tp_func f, void *user)
{
    int rc, attempt;
    if (!r)
        return TP_ERR_NULL;
    if (!f || (is_evaluator(r) && !x && r->n_indep > 0))
        return tp__rec_fail(r, TP_ERR_NULL, "tp_rec_run: %s is NULL",
                            f ? "x" : "the function");
    if (r->finished)
        return tp__rec_fail(r, TP_ERR_FINISHED,
                            "tp_rec_run: the recording is finished");
    if (r->running)
        return tp__rec_fail(r, TP_ERR_BACKEND,
                            "tp_rec_run: called from inside a run");
    if (is_evaluator(r))
        fresh_run(r);
    else if (r->status < 0)
        return r->status; /* a failed recording cannot be continued */
    for (attempt = 0;; attempt++) {
        rc = r->be->begin(r, x);
        if (rc < 0)
            return tp__rec_fail(r, rc, "tp_rec_run: %s", tp_strerror(rc));
        r->running = true;
        rc = f(r, user);
        r->running = false;
        /* once more if the backend asks (it runs the second time in a way
         * that cannot ask again) */
        if (!r->be->end || !r->be->end(r) || attempt > 0)
            break;
        fresh_run(r);
    }
    if (r->status < 0)
        return r->status;
    if (rc != 0)
        return tp__rec_fail(r, TP_ERR_USER,
                            "tp_rec_run: the user function returned %d", rc);
    return TP_OK;
}

int tp_rec_set_param(tp_rec *r, const char *name, double value)
{
    tp_named *o;
    if (!r || !name)
        return TP_ERR_NULL;
    if (!is_evaluator(r))
        return TP_ERR_BACKEND; /* a tape's parameters live in a workspace */
    if (!name[0])
        return TP_ERR_NAME;
    o = find_named(r->over, r->n_over, name);
    if (o) {
        o->value = value;
        return TP_OK;
    }
    return push_named(r, &r->over, &r->n_over, &r->cap_over, NULL, name,
                      value, 0)
               ? TP_OK
               : TP_ERR_NOMEM;
}

int tp_rec_status(const tp_rec *r) { return r ? r->status : TP_ERR_NULL; }

const char *tp_rec_errmsg(const tp_rec *r)
{
    return r ? r->msg : "NULL context";
}

int tp_rec_n_indep(const tp_rec *r) { return r ? r->n_indep : 0; }

int tp_rec_n_outputs(const tp_rec *r) { return r ? (int)r->n_outs : 0; }

int tp_rec_output_index(const tp_rec *r, const char *name)
{
    size_t i;
    if (!r || !name)
        return -1;
    for (i = 0; i < r->n_outs; i++)
        if (strcmp(r->outs[i].name, name) == 0)
            return (int)i;
    return -1;
}

int tp_rec_output_value(const tp_rec *r, int out, double *value)
{
    if (!r || !value)
        return TP_ERR_NULL;
    if (!is_evaluator(r))
        return TP_ERR_BACKEND;
    if (r->status < 0)
        return r->status;
    if (out < 0 || (size_t)out >= r->n_outs)
        return r->n_outs ? TP_ERR_SIZE : TP_ERR_EMPTY;
    *value = r->be->value(r, r->outs[out].id);
    return isfinite(*value) ? TP_OK : TP_WARN_NONFINITE;
}

void tp_rec_free(tp_rec **r)
{
    if (!r || !*r)
        return;
    (*r)->be->destroy(*r); /* releases the common part too */
    *r = NULL;
}

/* ---- the operations --------------------------------------------------- */

static const tp_val zero_b = {0, 0};

#define TP_BINARY_(fn, OP)                                                 \
    tp_val fn(tp_rec *r, tp_val a, tp_val b)                               \
    {                                                                      \
        return tp__rec_op(r, TP_OP_##OP, a, b, 0.0);                       \
    }
#define TP_UNARY_(fn, OP)                                                  \
    tp_val fn(tp_rec *r, tp_val a)                                         \
    {                                                                      \
        return tp__rec_op(r, TP_OP_##OP, a, zero_b, 0.0);                  \
    }

TP_BINARY_(tp_add, ADD)
TP_BINARY_(tp_sub, SUB)
TP_BINARY_(tp_mul, MUL)
TP_BINARY_(tp_div, DIV)
TP_BINARY_(tp_pow, POW)
TP_BINARY_(tp_atan2, ATAN2)
TP_BINARY_(tp_hypot, HYPOT)
TP_UNARY_(tp_neg, NEG)
TP_UNARY_(tp_sqr, SQR)
TP_UNARY_(tp_sqrt, SQRT)
TP_UNARY_(tp_exp, EXP)
TP_UNARY_(tp_log, LOG)
TP_UNARY_(tp_sin, SIN)
TP_UNARY_(tp_cos, COS)
TP_UNARY_(tp_tan, TAN)
TP_UNARY_(tp_asin, ASIN)
TP_UNARY_(tp_acos, ACOS)
TP_UNARY_(tp_atan, ATAN)
TP_UNARY_(tp_sinh, SINH)
TP_UNARY_(tp_cosh, COSH)
TP_UNARY_(tp_tanh, TANH)
TP_UNARY_(tp_abs, ABS)

tp_val tp_powi(tp_rec *r, tp_val a, int k)
{
    return tp__rec_op(r, TP_OP_POWI, a, zero_b, (double)k);
}

tp_val tp_powc(tp_rec *r, tp_val a, double c)
{
    /* An integral exponent is the exact integer power. */
    if (c == nearbyint(c) && fabs(c) <= 1024.0)
        return tp__rec_op(r, TP_OP_POWI, a, zero_b, c);
    return tp__rec_op(r, TP_OP_POWC, a, zero_b, c);
}

tp_val tp_addc(tp_rec *r, tp_val a, double c)
{
    return tp__rec_op(r, TP_OP_ADDC, a, zero_b, c);
}

tp_val tp_mulc(tp_rec *r, tp_val a, double c)
{
    return tp__rec_op(r, TP_OP_MULC, a, zero_b, c);
}

/* a - c and a / c go through the binary ops with a constant leaf, so
 * they record exactly what tp_sub and tp_div with tp_const would (ADDC of
 * -c; MULC of 1 / c when that is exact, else DIV). */
tp_val tp_subc(tp_rec *r, tp_val a, double c)
{
    return tp_sub(r, a, tp_const(r, c));
}

tp_val tp_divc(tp_rec *r, tp_val a, double c)
{
    return tp_div(r, a, tp_const(r, c));
}

tp_val tp_csub(tp_rec *r, double c, tp_val a)
{
    return tp__rec_op(r, TP_OP_CSUB, a, zero_b, c);
}

tp_val tp_cdiv(tp_rec *r, double c, tp_val a)
{
    return tp__rec_op(r, TP_OP_CDIV, a, zero_b, c);
}

tp_val tp_sum(tp_rec *r, int n, const tp_val *a)
{
    tp_val s;
    int i;
    if (!r)
        return invalid_val;
    if (n < 0 || (n > 0 && !a)) {
        tp__rec_fail(r, n < 0 ? TP_ERR_SIZE : TP_ERR_NULL,
                     "tp_sum: bad array (n = %d)", n);
        return invalid_val;
    }
    if (n == 0)
        return tp_const(r, 0.0);
    s = a[0];
    if (n == 1 && !check_val(r, s, "tp_sum", 1))
        return invalid_val;
    for (i = 1; i < n; i++)
        s = tp_add(r, s, a[i]);
    return s;
}

tp_val tp_dot(tp_rec *r, int n, const tp_val *a, const tp_val *b)
{
    tp_val s;
    int i;
    if (!r)
        return invalid_val;
    if (n < 0 || (n > 0 && (!a || !b))) {
        tp__rec_fail(r, n < 0 ? TP_ERR_SIZE : TP_ERR_NULL,
                     "tp_dot: bad arrays (n = %d)", n);
        return invalid_val;
    }
    if (n == 0)
        return tp_const(r, 0.0);
    s = tp_mul(r, a[0], b[0]);
    for (i = 1; i < n; i++)
        s = tp_add(r, s, tp_mul(r, a[i], b[i]));
    return s;
}
