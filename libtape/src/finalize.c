/* finalize.c - turns a recorder's raw op stream into an immutable tape.
 *
 *   1. dead-code elimination: only ops that reach an output survive
 *      (INDEP and PARAM ops always survive, so their slots are fixed);
 *   2. dependency analysis: dep[i] is the set of independent groups op i
 *      depends on, so sweeps can skip structurally zero derivative work,
 *      plus a flag on an active binary op with a passive operand;
 *   3. renumbering: INDEP ops, then PARAM ops, then the passive ops (those
 *      that depend on no independent: constants and functions of
 *      parameters), then the active ops, each in recording order. Passive
 *      ops depend only on passive ops, so this is still a topological
 *      order; a workspace computes the passive prefix once per parameter
 *      change and sweeps start at first_active;
 *   4. the constant pool keeps only entries that live ops use;
 *   5. sin/cos pairing: when sin(u) and cos(u) are both on the tape, the
 *      later one takes its value from the earlier one's auxiliary value
 *      (a1 = earlier slot + 1), so an angle costs one sincos per sweep.
 * Also tape queries and destruction (the tape's other public functions).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "tape_internal.h"

static void tape_release(tp_tape *t)
{
    const tp_allocator al = t->al;
    uint32_t i;
    tp__free(&al, t->opc, t->n_ops);
    tp__free(&al, t->dep, t->n_ops);
    tp__free(&al, t->a0, (size_t)t->n_ops * 4);
    tp__free(&al, t->a1, (size_t)t->n_ops * 4);
    tp__free(&al, t->konst, (size_t)t->n_const * sizeof(double));
    tp__free(&al, t->out_slot, (size_t)t->n_out * 4);
    if (t->out_name)
        for (i = 0; i < t->n_out; i++)
            tp__strfree(&al, t->out_name[i]);
    tp__free(&al, t->out_name, (size_t)t->n_out * sizeof(char *));
    if (t->param_name)
        for (i = 0; i < t->n_param; i++)
            tp__strfree(&al, t->param_name[i]);
    tp__free(&al, t->param_name, (size_t)t->n_param * sizeof(char *));
    tp__free(&al, t->param_dflt, (size_t)t->n_param * sizeof(double));
    tp__free(&al, t->out_order, (size_t)t->n_out * 4);
    tp__free(&al, t->param_order, (size_t)t->n_param * 4);
    tp__free(&al, t->group, t->n_indep);
    tp__free(&al, t, sizeof *t);
}

void tp_tape_free(tp_tape **t)
{
    if (!t || !*t)
        return;
    tape_release(*t);
    *t = NULL;
}

static int has_slot_operands(unsigned op, int *nops)
{
    switch (tp__opinfo[op].kind) {
    case TP_KIND_LEAF: *nops = 0; break;
    case TP_KIND_BINARY: *nops = 2; break;
    default: *nops = 1; break;
    }
    return *nops;
}

/* order[0..n) = 0..n-1 sorted by names[] ascending (strcmp): a bottom-up
 * merge sort, n log n comparisons and one scratch array. A tape's names
 * are unique (the recorder refuses a name given twice). 0, or -1 out of
 * memory. */
static int name_order(const tp_allocator *al, char *const *names, uint32_t n,
                      uint32_t *order)
{
    uint32_t *tmp, *a = order, *b, i;
    uint64_t w;
    for (i = 0; i < n; i++)
        order[i] = i;
    if (n < 2)
        return 0;
    tmp = tp__calloc(al, n, 4);
    if (!tmp)
        return -1;
    b = tmp;
    for (w = 1; w < n; w *= 2) {
        for (i = 0; i < n; i = (uint32_t)(i + 2 * w < n ? i + 2 * w : n)) {
            const uint32_t mid = (uint32_t)(i + w < n ? i + w : n);
            const uint32_t end = (uint32_t)(i + 2 * w < n ? i + 2 * w : n);
            uint32_t p = i, q = mid, k = i;
            while (p < mid && q < end)
                b[k++] = strcmp(names[a[q]], names[a[p]]) < 0 ? a[q++]
                                                              : a[p++];
            while (p < mid)
                b[k++] = a[p++];
            while (q < end)
                b[k++] = a[q++];
        }
        {
            uint32_t *s = a;
            a = b;
            b = s;
        }
    }
    if (a != order)
        memcpy(order, a, (size_t)n * 4);
    tp__free(al, tmp, (size_t)n * 4);
    return 0;
}

/* Allocate every array of t (counts already set); 0 or -1. */
static int tape_alloc(tp_tape *t)
{
    const tp_allocator *al = &t->al;
    t->opc = tp__calloc(al, t->n_ops, 1);
    t->dep = tp__calloc(al, t->n_ops, 1);
    t->a0 = tp__calloc(al, t->n_ops, 4);
    t->a1 = tp__calloc(al, t->n_ops, 4);
    t->konst = tp__calloc(al, t->n_const, sizeof(double));
    t->out_slot = tp__calloc(al, t->n_out, 4);
    t->out_name = tp__calloc(al, t->n_out, sizeof(char *));
    t->param_name = tp__calloc(al, t->n_param, sizeof(char *));
    t->param_dflt = tp__calloc(al, t->n_param, sizeof(double));
    t->out_order = tp__calloc(al, t->n_out, 4);
    t->param_order = tp__calloc(al, t->n_param, 4);
    t->group = tp__calloc(al, t->n_indep, 1);
    if (!t->opc || !t->dep || !t->a0 || !t->a1 || !t->konst ||
        !t->out_slot || !t->out_name || !t->param_name || !t->param_dflt ||
        !t->out_order || !t->param_order || !t->group)
        return -1;
    return 0;
}

/* For each live SIN or COS op, link it to an earlier COS or SIN op of the
 * same operand: a1 = partner slot + 1 (0 when unpaired). */
static int pair_sincos(tp_tape *t, const tp_allocator *al)
{
    uint32_t *seen = tp__calloc(al, t->n_ops, 4); /* operand -> slot + 1 */
    uint32_t i;
    if (!seen)
        return -1;
    for (int pass = 0; pass < 2; pass++) {
        const unsigned first = pass ? TP_OP_COS : TP_OP_SIN;
        const unsigned other = pass ? TP_OP_SIN : TP_OP_COS;
        memset(seen, 0, (size_t)t->n_ops * 4);
        for (i = t->first_active; i < t->n_ops; i++) {
            if (t->opc[i] == first && !seen[t->a0[i]])
                seen[t->a0[i]] = i + 1;
            else if (t->opc[i] == other && seen[t->a0[i]] &&
                     seen[t->a0[i]] - 1 < i && t->a1[i] == 0)
                t->a1[i] = seen[t->a0[i]];
        }
    }
    tp__free(al, seen, (size_t)t->n_ops * 4);
    return 0;
}

int tp__tape_build(const tp_rawtape *raw, const tp_allocator *al,
                   tp_tape **out, char *msg)
{
    size_t n = raw->n_ops, i, n_live = 0, n_kept_k = 0;
    uint8_t *live = NULL, *rdep = NULL;
    uint32_t *map = NULL, *kmap = NULL, next;
    tp_tape *t = NULL;
    int rc = TP_ERR_NOMEM, nops, pass;

    live = tp__calloc(al, n, 1);
    rdep = tp__calloc(al, n, 1);
    map = tp__calloc(al, n, 4);
    kmap = tp__calloc(al, raw->n_const, 4);
    t = tp__calloc(al, 1, sizeof *t);
    if (t)
        t->al = *al; /* before any goto fail: tape_release frees with it */
    if (!live || !rdep || !map || !kmap || !t)
        goto fail;

    /* 1. liveness, walking backwards from the outputs */
    for (i = 0; i < raw->n_outs; i++)
        live[raw->outs[i].id] = 1;
    for (i = n; i-- > 0;) {
        unsigned op = raw->opc[i];
        if (op == TP_OP_INDEP || op == TP_OP_PARAM)
            live[i] = 1;
        if (!live[i])
            continue;
        if (has_slot_operands(op, &nops)) {
            live[raw->a0[i]] = 1;
            if (nops == 2)
                live[raw->a1[i]] = 1;
        }
        if (op == TP_OP_CONST)
            kmap[raw->a0[i]] = 1;
        else if (tp__opinfo[op].kind == TP_KIND_UCONST)
            kmap[raw->a1[i]] = 1;
    }
    for (i = 0; i < n; i++)
        n_live += live[i];
    for (i = 0; i < raw->n_const; i++)
        kmap[i] = kmap[i] ? (uint32_t)n_kept_k++ : UINT32_MAX;

    /* 2. dependency groups, in recording (topological) order */
    for (i = 0; i < n; i++) {
        unsigned op = raw->opc[i];
        if (op == TP_OP_INDEP)
            rdep[i] = (uint8_t)(1u << raw->group[raw->a0[i]]);
        else if (has_slot_operands(op, &nops))
            rdep[i] = (uint8_t)(rdep[raw->a0[i]] |
                                (nops == 2 ? rdep[raw->a1[i]] : 0));
    }

    /* counts, then arrays */
    t->n_ops = (uint32_t)n_live;
    t->n_indep = raw->n_indep;
    t->n_param = (uint32_t)raw->n_params;
    t->n_out = (uint32_t)raw->n_outs;
    t->n_const = (uint32_t)n_kept_k;
    if (tape_alloc(t) != 0)
        goto fail;

    /* 3. renumber: INDEP, PARAM (by parameter index), passive, active */
    for (i = 0; i < raw->n_indep; i++)
        map[i] = (uint32_t)i;
    for (i = 0; i < raw->n_params; i++)
        map[raw->params[i].id] = raw->n_indep + (uint32_t)i;
    next = raw->n_indep + (uint32_t)raw->n_params;
    for (pass = 0; pass < 2; pass++) {
        if (pass == 1)
            t->first_active = next;
        for (i = raw->n_indep; i < n; i++)
            if (live[i] && raw->opc[i] != TP_OP_PARAM &&
                (rdep[i] != 0) == (pass == 1))
                map[i] = next++;
    }

    for (i = 0; i < n; i++) {
        unsigned op = raw->opc[i];
        uint32_t s, b0 = raw->a0[i], b1 = raw->a1[i];
        if (!live[i])
            continue;
        s = map[i];
        switch (tp__opinfo[op].kind) {
        case TP_KIND_LEAF:
            if (op == TP_OP_CONST)
                b0 = kmap[b0];
            else if (op == TP_OP_PARAM) /* its index among parameters */
                b0 = s - raw->n_indep;
            break;
        case TP_KIND_BINARY:
            b0 = map[b0];
            b1 = map[b1];
            break;
        case TP_KIND_UCONST:
            b0 = map[b0];
            b1 = kmap[b1];
            break;
        case TP_KIND_UNARY:
            b0 = map[b0];
            b1 = 0; /* SIN/COS pairing below may set it */
            break;
        default: /* UINT */
            b0 = map[b0];
            break;
        }
        t->opc[s] = (uint8_t)op;
        t->a0[s] = b0;
        t->a1[s] = b1;
        t->dep[s] = rdep[i];
        if (rdep[i] && tp__opinfo[op].kind == TP_KIND_BINARY)
            t->dep[s] |= (uint8_t)((rdep[raw->a0[i]] ? 0u : TP_DEP_UPASSIVE) |
                                   (rdep[raw->a1[i]] ? 0u : TP_DEP_TPASSIVE));
    }
    for (i = 0; i < raw->n_const; i++)
        if (kmap[i] != UINT32_MAX)
            t->konst[kmap[i]] = raw->konst[i];
    memcpy(t->group, raw->group, raw->n_indep);
    for (i = 0; i < raw->n_outs; i++) {
        t->out_slot[i] = map[raw->outs[i].id];
        t->out_name[i] = tp__strdup(al, raw->outs[i].name);
        if (!t->out_name[i])
            goto fail;
    }
    for (i = 0; i < raw->n_params; i++) {
        t->param_dflt[i] = raw->params[i].value;
        t->param_name[i] = tp__strdup(al, raw->params[i].name);
        if (!t->param_name[i])
            goto fail;
    }
    if (name_order(al, t->out_name, t->n_out, t->out_order) != 0 ||
        name_order(al, t->param_name, t->n_param, t->param_order) != 0)
        goto fail;
    if (pair_sincos(t, al) != 0)
        goto fail;

    /* statistics */
    t->stats.n_ops = t->n_ops;
    t->stats.n_consts = t->n_const;
    t->stats.bytes = (size_t)t->n_ops * (1 + 1 + 4 + 4) +
                     (size_t)t->n_const * sizeof(double);
    for (i = 0; i < t->n_ops; i++)
        t->stats.n_passive += (t->dep[i] & TP_DEP_GROUPS) == 0;
    t->stats.n_recorded = n;
    t->stats.n_cse_hits = raw->n_cse_hits;
    t->stats.n_folded = raw->n_folded;
    t->stats.n_dead = n - n_live;

    rc = TP_OK;
    *out = t;
    t = NULL;
fail:
    if (rc != TP_OK && msg)
        snprintf(msg, TP_MSG_LEN, "tp_recorder_finish: out of memory");
    if (t)
        tape_release(t);
    tp__free(al, live, n);
    tp__free(al, rdep, n);
    tp__free(al, map, n * 4);
    tp__free(al, kmap, raw->n_const * 4);
    return rc;
}

/* ---- queries ---------------------------------------------------------- */

int tp_tape_n_indep(const tp_tape *t) { return t ? (int)t->n_indep : 0; }
int tp_tape_n_outputs(const tp_tape *t) { return t ? (int)t->n_out : 0; }
int tp_tape_n_params(const tp_tape *t) { return t ? (int)t->n_param : 0; }

/* The index of name among names[0..n) by bisection of order (the
 * indices sorted by name), or -1: a model with tens of thousands of
 * parameters maps them to its tapes in O(n log n), not O(n^2). */
static int find_name(char *const *names, const uint32_t *order, uint32_t n,
                     const char *name)
{
    uint32_t lo = 0, hi = n;
    if (!name)
        return -1;
    while (lo < hi) {
        const uint32_t mid = lo + (hi - lo) / 2;
        const int c = strcmp(names[order[mid]], name);
        if (c == 0)
            return (int)order[mid];
        if (c < 0)
            lo = mid + 1;
        else
            hi = mid;
    }
    return -1;
}

int tp_tape_output_index(const tp_tape *t, const char *name)
{
    return t ? find_name(t->out_name, t->out_order, t->n_out, name) : -1;
}

int tp_tape_param_index(const tp_tape *t, const char *name)
{
    return t ? find_name(t->param_name, t->param_order, t->n_param, name)
             : -1;
}

const char *tp_tape_output_name(const tp_tape *t, int out)
{
    if (!t || out < 0 || (uint32_t)out >= t->n_out)
        return NULL;
    return t->out_name[out];
}

const char *tp_tape_param_name(const tp_tape *t, int k)
{
    if (!t || k < 0 || (uint32_t)k >= t->n_param)
        return NULL;
    return t->param_name[k];
}

double tp_tape_param_default(const tp_tape *t, int k)
{
    if (!t || k < 0 || (uint32_t)k >= t->n_param)
        return NAN;
    return t->param_dflt[k];
}

int tp_tape_stats_get(const tp_tape *t, tp_tape_stats *st)
{
    if (!t || !st)
        return TP_ERR_NULL;
    *st = t->stats;
    return TP_OK;
}

size_t tp_tape_count_dependent(const tp_tape *t, unsigned mask)
{
    size_t i, c = 0;
    if (!t)
        return 0;
    for (i = 0; i < t->n_ops; i++)
        c += mask ? (t->dep[i] & mask & TP_DEP_GROUPS) != 0
                  : (t->dep[i] & TP_DEP_GROUPS) == 0;
    return c;
}
