/* codegen_taylor.c - the univariate second-order Taylor sweep of a
 * compiled tape (tp_taylor2: y, its first and its second derivative along
 * one direction of the independents; for the constraints: phi, the
 * velocity residual and -gamma), as straight-line C specialized to the
 * tape.
 *
 * The interpreter (sweep_ops.h, tp__k_taylor2) takes every op's five
 * partials and combines them in one formula. Here the common ops' partials
 * are written into the formula as the expressions they are (a MUL's fu is
 * its second operand's value, its fuu zero, ...), so the code keeps only
 * the terms that are not structurally zero: a passive operand's
 * coefficients (never written, zero) and a zero second partial drop out.
 * The remaining terms are the interpreter's, in its order, so every
 * finite result is the same to the bit (a dropped term could only have
 * turned a -0 into a +0). The rarer ops take their partials from the one
 * shared function (tpc_partials) and the interpreter's whole formula.
 *
 * The sweep runs the cone of every output (and the partners of paired
 * sine and cosine ops): ops no output needs are not computed.
 */
#include <stdlib.h>
#include <string.h>

#include "codegen.h"

/* The coefficients of op i from its operands': d1[i] and d2[i]. */
static void emit_coefficients(tp_sbuf *b, const tp_tape *T, uint32_t i)
{
    const unsigned op = T->opc[i], fl = T->dep[i];
    const uint32_t u = T->a0[i], t = T->a1[i];
    /* a binary op's passive operand has zero coefficients */
    const bool lu = !(fl & TP_DEP_UPASSIVE), lt = !(fl & TP_DEP_TPASSIVE);
    switch (op) {
    case TP_OP_ADD:
    case TP_OP_SUB: {
        const char sg = op == TP_OP_ADD ? '+' : '-';
        if (lu && lt)
            tp__sbuf_printf(b, "d1[%u] = d1[%u] %c d1[%u];\n"
                               "d2[%u] = d2[%u] %c d2[%u];\n",
                            i, u, sg, t, i, u, sg, t);
        else if (lu)
            tp__sbuf_printf(b, "d1[%u] = d1[%u];\nd2[%u] = d2[%u];\n", i, u,
                            i, u);
        else
            tp__sbuf_printf(b, "d1[%u] = %sd1[%u];\nd2[%u] = %sd2[%u];\n", i,
                            sg == '-' ? "-" : "", t, i, sg == '-' ? "-" : "",
                            t);
        return;
    }
    case TP_OP_MUL: /* fu = v[t], ft = v[u], fut = 1 */
        if (lu && lt)
            tp__sbuf_printf(b,
                            "d1[%u] = v[%u] * d1[%u] + v[%u] * d1[%u];\n"
                            "d2[%u] = v[%u] * d2[%u] + v[%u] * d2[%u] + "
                            "2.0 * d1[%u] * d1[%u];\n",
                            i, t, u, u, t, i, t, u, u, t, u, t);
        else if (lu)
            tp__sbuf_printf(b, "d1[%u] = v[%u] * d1[%u];\n"
                               "d2[%u] = v[%u] * d2[%u];\n",
                            i, t, u, i, t, u);
        else
            tp__sbuf_printf(b, "d1[%u] = v[%u] * d1[%u];\n"
                               "d2[%u] = v[%u] * d2[%u];\n",
                            i, u, t, i, u, t);
        return;
    case TP_OP_NEG:
    case TP_OP_CSUB: /* fu = -1 */
        tp__sbuf_printf(b, "d1[%u] = -d1[%u];\nd2[%u] = -d2[%u];\n", i, u, i,
                        u);
        return;
    case TP_OP_ADDC: /* fu = 1 */
        tp__sbuf_printf(b, "d1[%u] = d1[%u];\nd2[%u] = d2[%u];\n", i, u, i,
                        u);
        return;
    case TP_OP_MULC: /* fu = the constant */
        tp__sbuf_printf(b, "d1[%u] = K[%u] * d1[%u];\nd2[%u] = K[%u] * d2[%u];\n",
                        i, t, u, i, t, u);
        return;
    case TP_OP_SQR: /* fu = 2 u, fuu = 2 */
        tp__sbuf_printf(b,
                        "d1[%u] = 2.0 * v[%u] * d1[%u];\n"
                        "d2[%u] = 2.0 * v[%u] * d2[%u] + 2.0 * d1[%u] * "
                        "d1[%u];\n",
                        i, u, u, i, u, u, u, u);
        return;
    case TP_OP_SIN: /* fu = cos (aux), fuu = -sin (the value) */
    case TP_OP_COS: /* fu = -sin (aux), fuu = -cos (the value) */ {
        const char *sg = op == TP_OP_COS ? "-" : "";
        tp__sbuf_printf(b,
                        "d1[%u] = %saux[%u] * d1[%u];\n"
                        "d2[%u] = %saux[%u] * d2[%u] + -v[%u] * d1[%u] * "
                        "d1[%u];\n",
                        i, sg, i, u, i, sg, i, u, i, u, u);
        return;
    }
    default: break;
    }
    /* the interpreter's formula, partials from the shared function */
    tp__sbuf_printf(b, "tpc_partials(v, aux, %uu, %u, %uu, %uu, &d);\n", i,
                    op, u, t);
    if (tp__op_kind(op) == TP_KIND_BINARY)
        tp__sbuf_printf(b,
                        "d1[%u] = d.fu * d1[%u] + d.ft * d1[%u];\n"
                        "d2[%u] = d.fu * d2[%u] + d.ft * d2[%u] + d.fuu * "
                        "d1[%u] * d1[%u] + 2.0 * d.fut * d1[%u] * d1[%u] + "
                        "d.ftt * d1[%u] * d1[%u];\n",
                        i, u, t, i, u, t, u, u, u, t, t, t);
    else
        tp__sbuf_printf(b,
                        "d1[%u] = d.fu * d1[%u];\n"
                        "d2[%u] = d.fu * d2[%u] + d.fuu * d1[%u] * d1[%u];\n",
                        i, u, i, u, u, u);
}

static void open_chunk(void *ctx, tp_sbuf *b, unsigned c, uint32_t lo,
                       uint32_t hi)
{
    char sig[64];
    (void)ctx;
    (void)lo;
    (void)hi;
    snprintf(sig, sizeof sig, "void ty_%u(TY_ARGS)", c);
    tp__chunk_begin(b, c, sig);
    tp__sbuf_puts(b, "tp_kx y; tp_partials d; memset(&y, 0, sizeof "
                     "y); y.K = K; y.v = v; y.aux = aux; (void)d;\n");
}

int tp__emit_taylor2(const tp_tape *T, bool loops, tp_sbuf *b)
{
    unsigned char *need = calloc((size_t)T->n_ops + 1, 1);
    uint32_t i, end, *clo = NULL;
    unsigned nchunk = 0;
    tp_seq q;
    int st;
    if (!need)
        return TP_ERR_NOMEM;
    end = tp__outputs_cone(T, need);
    tp__sbuf_puts(b, "#define TY_ARGS double *restrict v, double *restrict "
                     "aux, double *restrict d1, double *restrict d2\n");
    memset(&q, 0, sizeof q);
    for (i = T->first_active; i < end; i++) {
        const unsigned op = T->opc[i];
        if (!need[i])
            continue;
        /* the value, as the value sweep computes it */
        if (strcmp(tp__op_fn_name(op), "GEN") == 0)
            tp__sbuf_printf(&q.text,
                            "tpc_value_GEN(v, aux, %uu, %u, %uu, %uu, %uu);\n",
                            i, op, (unsigned)T->dep[i], T->a0[i], T->a1[i]);
        else
            tp__sbuf_printf(&q.text,
                            "tp__value_%s(&y, %uu, %u, %uu, %uu, %uu);\n",
                            tp__op_fn_name(op), i, op, (unsigned)T->dep[i],
                            T->a0[i], T->a1[i]);
        emit_coefficients(&q.text, T, i);
        tp__seq_close(&q, false);
    }
    st = tp__seq_emit(&q, b, loops, open_chunk, NULL, &clo, &nchunk);
    tp__seq_free(&q);
    free(clo);
    if (st != TP_OK) {
        free(need);
        return st;
    }
    /* the entry: the independents' coefficients, then the chunks (those
     * of parameters and passive ops stay zero, as in the interpreter) */
    tp__sbuf_printf(b,
                    "#if TPC_PART == 0\n"
                    "TPC_EXPORT void tpc_taylor2(TY_ARGS, const double "
                    "*restrict dir)\n{\n"
                    "for (int k_ = 0; k_ < %u; k_++) {\n"
                    "    d1[k_] = dir[k_];\n    d2[k_] = 0.0;\n}\n",
                    T->n_indep);
    for (i = 0; i < nchunk; i++)
        tp__sbuf_printf(b, "ty_%u(v, aux, d1, d2);\n", i);
    tp__sbuf_puts(b, "(void)v;\n(void)aux;\n}\n#endif\n");
    free(need);
    return b->failed ? TP_ERR_NOMEM : TP_OK;
}
