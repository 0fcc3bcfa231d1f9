/* pattern.c - the structural sparsity pattern of a tape's Jacobian:
 * which outputs depend on which independents, whatever the values.
 *
 * Forward propagation of index sets: the set of an INDEP op is its own
 * index, of a PARAM or CONST op empty, of any other op the union of its
 * operands' sets. An output's set is the set of its slot. The result is
 * a superset of the entries that are nonzero at any point (a partial
 * that happens to vanish, such as d(u*t)/du at t = 0, or that vanishes
 * identically, is still counted), and never a subset: every derivative
 * the sweeps can produce flows along an operand edge.
 *
 * The sets are bit words over blocks of 64 independents: one sweep of
 * the tape per block, one word per op, so the scratch is n_ops words and
 * the cost n_ops x ceil(count / 64) word operations, with no sets that
 * grow along a long sum.
 */
#include <stdint.h>
#include <string.h>

#include "tape_internal.h"

/* Words of the columns first + 64 b .. first + 64 b + 63 (< first +
 * count) for every op of t, into w[n_ops]. */
static void sweep_block(const tp_tape *t, int first, int count, int b,
                        uint64_t *w)
{
    const uint32_t lo = (uint32_t)first + 64u * (uint32_t)b;
    const uint32_t hi = (uint32_t)first + (uint32_t)count;
    uint32_t i;
    for (i = 0; i < t->n_ops; i++) {
        switch (tp__opinfo[t->opc[i]].kind) {
        case TP_KIND_LEAF:
            w[i] = t->opc[i] == TP_OP_INDEP && t->a0[i] >= lo &&
                           t->a0[i] < hi && t->a0[i] - lo < 64u
                       ? (uint64_t)1 << (t->a0[i] - lo)
                       : 0;
            break;
        case TP_KIND_BINARY:
            w[i] = w[t->a0[i]] | w[t->a1[i]];
            break;
        default: /* UNARY, UCONST, UINT: a1 is not a slot */
            w[i] = w[t->a0[i]];
            break;
        }
    }
}

static size_t popcount64(uint64_t x)
{
    size_t c = 0;
    for (; x; x &= x - 1)
        c++;
    return c;
}

int tp_tape_jacobian_pattern(const tp_tape *t, int first, int count,
                             size_t *rowptr, int *cols, size_t cap)
{
    uint64_t *w;
    size_t *next = NULL, nnz;
    int blocks, b;
    uint32_t o;
    if (!t || !rowptr)
        return TP_ERR_NULL;
    if (first < 0 || count < 0 || (uint32_t)first > t->n_indep ||
        (uint32_t)count > t->n_indep - (uint32_t)first)
        return TP_ERR_SIZE;
    blocks = (count + 63) / 64;
    w = tp__alloc(&t->al, tp__mulsz(t->n_ops ? t->n_ops : 1,
                                    sizeof *w));
    if (!w)
        return TP_ERR_NOMEM;
    /* counts per row */
    memset(rowptr, 0, ((size_t)t->n_out + 1) * sizeof *rowptr);
    for (b = 0; b < blocks; b++) {
        sweep_block(t, first, count, b, w);
        for (o = 0; o < t->n_out; o++)
            rowptr[o + 1] += popcount64(w[t->out_slot[o]]);
    }
    for (o = 0; o < t->n_out; o++)
        rowptr[o + 1] += rowptr[o];
    nnz = rowptr[t->n_out];
    if (!cols) {
        tp__free(&t->al, w, (size_t)(t->n_ops ? t->n_ops : 1) * sizeof *w);
        return TP_OK;
    }
    if (cap < nnz) {
        tp__free(&t->al, w, (size_t)(t->n_ops ? t->n_ops : 1) * sizeof *w);
        return TP_ERR_SIZE;
    }
    next = tp__alloc(&t->al, tp__mulsz((size_t)t->n_out + 1,
                                       sizeof *next));
    if (!next) {
        tp__free(&t->al, w, (size_t)(t->n_ops ? t->n_ops : 1) * sizeof *w);
        return TP_ERR_NOMEM;
    }
    memcpy(next, rowptr, ((size_t)t->n_out + 1) * sizeof *next);
    /* the blocks in ascending order, bits low to high: rows come out
     * sorted */
    for (b = 0; b < blocks; b++) {
        sweep_block(t, first, count, b, w);
        for (o = 0; o < t->n_out; o++) {
            uint64_t x = w[t->out_slot[o]];
            int k;
            for (k = 0; x; k++, x >>= 1)
                if (x & 1u)
                    cols[next[o]++] = 64 * b + k;
        }
    }
    tp__free(&t->al, next, ((size_t)t->n_out + 1) * sizeof *next);
    tp__free(&t->al, w, (size_t)(t->n_ops ? t->n_ops : 1) * sizeof *w);
    return TP_OK;
}
