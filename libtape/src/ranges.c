/* ranges.c - the columns of each row that can be non-zero in the Lagrange
 * block's sweeps, worked out once per workspace and output.
 *
 * tp_lagrange_t seeds unit directions on the rates (independent n + c
 * carries column c). An op's tangent row can be non-zero only in the
 * columns of the rates it depends on, and its adjoint-tangent row only in
 * the columns that reach it backwards: from its readers' adjoint-tangent
 * rows, and, at an op with a second derivative, from its operands'
 * tangent rows. On a chain the velocity of link k depends on the first k
 * rates only, so the tangent rows form a triangle: about 40 % of the
 * full rows' vectors, and 70 % for the adjoint-tangent rows (50 links).
 *
 * Each range is the hull of those columns in whole vectors of TP_LANES. The ranged sweeps
 * (forward.c, reverse.c) run every op's row kernels over its range alone;
 * a column skipped is one the full sweep computes as a sum of products
 * with exact zeros, so skipping it changes no finite result (at most the
 * sign of a zero).
 */
#include <stdbool.h>
#include <string.h>

#include "sweep.h"

/* Ranges are pairs (first vector, one past the last); empty: (0, 0).
 * The vectors of a union of columns are the union of their vectors, so
 * hulls are joined in vectors directly. */
static void join(uint32_t *a, const uint32_t *b)
{
    if (b[1] == b[0])
        return;
    if (a[1] == a[0]) {
        a[0] = b[0];
        a[1] = b[1];
        return;
    }
    if (b[0] < a[0])
        a[0] = b[0];
    if (b[1] > a[1])
        a[1] = b[1];
}

/* Ops that add a second-order term (operand tangents) to their operands'
 * adjoint-tangent rows in tp__k_rev2: every op but the linear ones. */
static bool second_order(unsigned op, unsigned fl)
{
    switch (op) {
    case TP_OP_MUL: /* with a passive operand, linear in the other */
        return !TP_UPASSIVE(fl) && !TP_TPASSIVE(fl);
    case TP_OP_ADD:
    case TP_OP_SUB:
    case TP_OP_NEG:
    case TP_OP_ADDC:
    case TP_OP_MULC:
    case TP_OP_CSUB:
        return false;
    default:
        return !tp__op_linear(op);
    }
}

void tp__lagrange_ranges(tp_ws *ws, int out, int n, uint32_t end)
{
    const tp_tape *T = ws->t;
    uint32_t *f = ws->frange, *r = ws->rrange;
    uint32_t i;
    memset(f, 0, 2 * (size_t)T->n_ops * sizeof *f);
    memset(r, 0, 2 * (size_t)T->n_ops * sizeof *r);
    for (i = (uint32_t)n; i < (uint32_t)(2 * n); i++) {
        f[2 * i] = (i - (uint32_t)n) / TP_LANES;
        f[2 * i + 1] = f[2 * i] + 1;
    }
    /* forward: the union of the operands' */
    for (i = T->first_active; i < end; i++) {
        const unsigned op = T->opc[i], fl = T->dep[i];
        if (!TP_UPASSIVE(fl))
            join(f + 2 * i, f + 2 * (size_t)T->a0[i]);
        if (tp__op_kind(op) == TP_KIND_BINARY && !TP_TPASSIVE(fl))
            join(f + 2 * i, f + 2 * (size_t)T->a1[i]);
    }
    /* backward: r[i] gathers the ranges of op i's readers (all visited
     * before it), then becomes the range its kernels run over: its own
     * row's and, with a second-order term, its operands' tangents'; both
     * operands' adjoint-tangent rows receive that range */
    for (i = end; i-- > T->first_active;) {
        const unsigned op = T->opc[i], fl = T->dep[i];
        const bool bin = tp__op_kind(op) == TP_KIND_BINARY;
        uint32_t *u = r + 2 * i;
        if (second_order(op, fl)) {
            join(u, f + 2 * (size_t)T->a0[i]);
            if (bin)
                join(u, f + 2 * (size_t)T->a1[i]);
        }
        if (!TP_UPASSIVE(fl))
            join(r + 2 * (size_t)T->a0[i], u);
        if (bin && !TP_TPASSIVE(fl))
            join(r + 2 * (size_t)T->a1[i], u);
    }
    ws->range_out = out;
    ws->range_n = n;
    ws->tan_ranged = false;
}
