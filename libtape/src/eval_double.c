/* eval_double.c - the plain double evaluator backend: runs the user's
 * function on doubles, one value per handle, using the same op values as
 * the tape (op_math.h). Used to check a recording and as the reference
 * value in tests. Buffers persist across runs; a run allocates only while
 * it needs more values than any run before it. */
#include "op_math.h"
#include "tape_internal.h"

typedef struct tp_evaluator {
    tp_rec base;
    double *v; /* [n] values by id */
    size_t n, cap;
} tp_evaluator;

static uint32_t push(tp_evaluator *E, double value)
{
    if (E->n >= TP_MAX_OPS) {
        tp__rec_fail(&E->base, TP_ERR_TOOBIG, "evaluator: too many values");
        return TP_NO_SLOT;
    }
    if (tp__grow(&E->base.al, (void **)&E->v, sizeof(double), &E->cap,
                 E->n + 1)) {
        tp__rec_fail(&E->base, TP_ERR_NOMEM, "evaluator: out of memory");
        return TP_NO_SLOT;
    }
    E->v[E->n] = value;
    E->base.n_ids = (uint32_t)(E->n + 1);
    return (uint32_t)E->n++;
}

static int ev_begin(tp_rec *base, const double *x)
{
    tp_evaluator *E = (tp_evaluator *)base;
    int i;
    E->n = 0;
    base->n_ids = 0;
    for (i = 0; i < base->n_indep; i++)
        if (push(E, x[i]) == TP_NO_SLOT)
            return base->status;
    return TP_OK;
}

static uint32_t ev_param(tp_rec *base, int k, double value)
{
    (void)k;
    return push((tp_evaluator *)base, value);
}

static uint32_t ev_constant(tp_rec *base, double c)
{
    return push((tp_evaluator *)base, c);
}

static uint32_t ev_apply(tp_rec *base, int op, uint32_t u, uint32_t t,
                         double c)
{
    tp_evaluator *E = (tp_evaluator *)base;
    double tv = tp__opinfo[op].kind == TP_KIND_BINARY ? E->v[t] : 0.0;
    return push(E, tp__op_value(op, E->v[u], tv, c));
}

static double ev_value(const tp_rec *base, uint32_t id)
{
    return ((const tp_evaluator *)base)->v[id];
}

static void ev_destroy(tp_rec *base)
{
    tp_evaluator *E = (tp_evaluator *)base;
    const tp_allocator al = base->al;
    tp__free(&al, E->v, E->cap * sizeof(double));
    tp__rec_release(base);
    tp__free(&al, E, sizeof *E);
}

static const tp_backend evaluator_backend = {
    "double evaluator", ev_begin, ev_param, ev_constant, ev_apply, ev_value,
    ev_destroy, NULL,
};

int tp_evaluator_new(tp_rec **out, int n_indep, const tp_allocator *al)
{
    tp_allocator a = tp__allocator(al);
    tp_evaluator *E;
    if (!out)
        return TP_ERR_NULL;
    *out = NULL;
    if (n_indep < 0 || (uint32_t)n_indep >= TP_MAX_OPS)
        return TP_ERR_SIZE;
    E = tp__calloc(&a, 1, sizeof *E);
    if (!E)
        return TP_ERR_NOMEM;
    tp__rec_init(&E->base, &evaluator_backend, n_indep, &a);
    *out = &E->base;
    return TP_OK;
}
