/* codegen.c - a finished tape as C source: one statement per live op
 * with the op's code, dependency byte, slots and constants as literals,
 * runs of statements that repeat with shifted slots (a chain's links)
 * written once as loops (codegen_loops.c).
 *
 * The per-op kernels are pasted in as text (kernel_text.c, made at build
 * time from sweep_ops.h and the headers it needs), so the compiled sweeps
 * do exactly the interpreter's arithmetic and a change to an op's calculus
 * reaches both. Each op calls its own small function (tp__value_MUL, ...);
 * the ops without one (GEN: the transcendental and rarer ops) go through
 * one shared function, compiled once, that dispatches at run time as the
 * interpreter does: inlining their whole calculus at every op made the
 * compiler's time grow with the kernel's size times the ops.
 *
 * Layout of the generated source (format TP_CODEGEN_FORMAT):
 *   - the kernels, the constant pool K as exact hexadecimal literals;
 *   - the value sweep (fwd0) and the gradient sweep (rev1): chunk
 *     functions of about 256 statements (the compiler's time grows
 *     faster than linearly in a function's size) and an exported entry
 *     tpc_<sweep>(kx, end);
 *   - optionally the direction blocks (codegen_lagrange.c: the Lagrange
 *     block, the Jacobian block), where the direction rows are: sweeps
 *     with rows compiled op by op through the generic kernels were no
 *     faster than the interpreter;
 *   - optionally the Taylor sweep (codegen_taylor.c);
 *   - tpc_format, tpc_nops, tpc_kx_size, tpc_P and tpc_sweeps, read back
 *     on load.
 * A sweep may stop at `end` (one past the last slot a caller needs):
 * forward chunks return where end can fall (past an output), reverse
 * chunks jump to where it starts. Ops above end have zero adjoints, so a
 * reverse sweep that started higher would still be right, only slower.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codegen.h"
#include "sweep_ops.h"

enum sweep { SW_FWD0, SW_REV1, SW_COUNT };
static const char *const sweep_name[SW_COUNT] = {"fwd0", "rev1"};
/* the kernel of each sweep (sweep_ops.h) */
static const char *const sweep_fn[SW_COUNT] = {"value", "rev1"};
/* the bit of tp_compile_opts.sweeps that asks for it */
static const unsigned sweep_bit[SW_COUNT] = {TP_SWEEP_VALUES,
                                             TP_SWEEP_GRADIENTS};

/* The slots where a sweep may end: end is one past an output's slot, or
 * the leaves' end when no output is needed (drivers.c, end_of). */
static unsigned char *end_points(const tp_tape *T)
{
    unsigned char *e = calloc((size_t)T->n_ops + 1, 1);
    uint32_t o;
    if (!e)
        return NULL;
    e[T->n_indep + T->n_param] = 1;
    for (o = 0; o < T->n_out; o++)
        e[T->out_slot[o] + 1] = 1;
    return e;
}

static void emit_op(tp_sbuf *b, const tp_tape *T, enum sweep s, uint32_t i)
{
    const unsigned op = T->opc[i];
    const char *f = tp__op_fn_name(op);
    if (strcmp(f, "GEN") == 0)
        tp__sbuf_printf(b, "tpc_%s_GEN(y.v, y.aux,%s %uu,%u,%uu,%uu,%uu);\n",
                        sweep_fn[s], s == SW_REV1 ? " y.adj," : "", i, op,
                        (unsigned)T->dep[i], T->a0[i], T->a1[i]);
    else
        tp__sbuf_printf(b, "tp__%s_%s(&y,%uu,%u,%uu,%uu,%uu);\n",
                        sweep_fn[s], f, i, op, (unsigned)T->dep[i], T->a0[i],
                        T->a1[i]);
}

void tp__cone(const tp_tape *T, uint32_t top, unsigned char *need)
{
    uint32_t i;
    for (i = top + 1; i-- > T->first_active;) {
        const unsigned op = T->opc[i];
        if (!need[i])
            continue;
        need[T->a0[i]] = 1;
        if (tp__op_kind(op) == TP_KIND_BINARY)
            need[T->a1[i]] = 1;
        if ((op == TP_OP_SIN || op == TP_OP_COS) && T->a1[i])
            need[T->a1[i] - 1] = 1;
    }
}

uint32_t tp__outputs_cone(const tp_tape *T, unsigned char *need)
{
    uint32_t o, end = T->first_active;
    for (o = 0; o < T->n_out; o++)
        if (T->out_slot[o] >= T->first_active) {
            need[T->out_slot[o]] = 1;
            if (T->out_slot[o] + 1 > end)
                end = T->out_slot[o] + 1;
        }
    if (end > T->first_active)
        tp__cone(T, end - 1, need);
    return end;
}

const char *tp__op_fn_name(unsigned op)
{
    switch (op) {
#define TP_NAME_(OP)                                                       \
    case TP_OP_##OP: return #OP;
        TP_COMMON_OPS(TP_NAME_)
#undef TP_NAME_
    default: return "GEN";
    }
}

/* What a sweep's chunk openings need. Statement k is op lo + k (value
 * sweep) or op n - 1 - k (gradient sweep, which runs backwards). */
typedef struct sweep_ctx {
    const tp_tape *T;
    const unsigned char *ep;
    enum sweep s;
} sweep_ctx;

static uint32_t stmt_op(const sweep_ctx *x, uint32_t k)
{
    return x->s == SW_REV1 ? x->T->n_ops - 1 - k : x->T->first_active + k;
}

static void open_chunk(void *ctx, tp_sbuf *b, unsigned c, uint32_t lo,
                       uint32_t hi)
{
    const sweep_ctx *x = ctx;
    char sig[96];
    uint32_t k;
    bool any = false;
    snprintf(sig, sizeof sig, "void %s_%u(const tp_kx *x, uint32_t end)",
             sweep_name[x->s], c);
    tp__chunk_begin(b, c, sig);
    tp__sbuf_puts(b, "    tp_kx y = *x;\n    y.K = K;\n    (void)end;\n");
    if (x->s != SW_REV1)
        return;
    /* entry points: end == i + 1 starts at op i, where label e(i+1) is */
    for (k = lo; k < hi; k++) {
        const uint32_t i = stmt_op(x, k);
        if (i + 1 < x->T->n_ops && x->ep[i + 1]) {
            if (!any)
                tp__sbuf_puts(b, "switch (end) {\n");
            any = true;
            tp__sbuf_printf(b, "case %uu: goto e%u;\n", i + 1, i + 1);
        }
    }
    if (any)
        tp__sbuf_puts(b, "default: break;\n}\n");
}

/* A sweep's statements: an op each; the value sweep returns before op i
 * where end can fall, the gradient sweep's entry labels stay out of
 * loops. */
static int emit_sweep(tp_sbuf *b, const tp_tape *T, const unsigned char *ep,
                      enum sweep s, bool loops)
{
    const uint32_t lo = T->first_active, n = T->n_ops;
    sweep_ctx x = {T, ep, s};
    tp_seq q;
    uint32_t k, *clo = NULL;
    unsigned nc = 0, c;
    int st;
    memset(&q, 0, sizeof q);
    for (k = 0; k < n - lo; k++) {
        const uint32_t i = stmt_op(&x, k);
        bool fixed = false;
        if (s != SW_REV1 && i > lo && ep[i])
            tp__sbuf_printf(&q.text, "if (end <= %uu) return;\n", i);
        if (s == SW_REV1 && i + 1 < n && ep[i + 1]) {
            tp__sbuf_printf(&q.text, "e%u:\n", i + 1);
            fixed = true;
        }
        emit_op(&q.text, T, s, i);
        tp__seq_close(&q, fixed);
    }
    st = tp__seq_emit(&q, b, loops, open_chunk, &x, &clo, &nc);
    tp__seq_free(&q);
    if (st != TP_OK) {
        free(clo);
        return st;
    }
    tp__sbuf_printf(b, "#if TPC_PART == 0\n"
                       "TPC_EXPORT void tpc_%s(const tp_kx *x, uint32_t end)\n{\n",
                    sweep_name[s]);
    if (s == SW_REV1) {
        /* chunk c holds ops down to the one of its last statement; chunk
         * 0 the highest (the sweep runs backwards) */
        for (c = 0; c < nc; c++) {
            const uint32_t last = c + 1 < nc ? clo[c + 1] - 1 : n - lo - 1;
            tp__sbuf_printf(b, "    if (end > %uu) %s_%u(x, end);\n",
                            stmt_op(&x, last), sweep_name[s], c);
        }
    } else {
        for (c = 0; c < nc; c++)
            tp__sbuf_printf(b, "    if (end <= %uu) return;\n    %s_%u(x, end);\n",
                            stmt_op(&x, clo[c]), sweep_name[s], c);
    }
    tp__sbuf_puts(b, "    (void)x;\n    (void)end;\n}\n#endif\n");
    free(clo);
    return b->failed ? TP_ERR_NOMEM : TP_OK;
}

void tp__chunk_begin(tp_sbuf *b, unsigned c, const char *sig)
{
    tp__sbuf_printf(b, "%s;\n#if TPC_PART == %u %% TPC_NPARTS\nTPC_CHUNK %s\n{\n",
                    sig, c, sig);
}

/* A double as an exact C literal. */
static void emit_double(tp_sbuf *b, double c)
{
    if (isnan(c))
        tp__sbuf_puts(b, "__builtin_nan(\"\")");
    else if (isinf(c))
        tp__sbuf_puts(b, c > 0 ? "__builtin_inf()" : "-__builtin_inf()");
    else
        tp__sbuf_printf(b, "%a", c);
}

int tp__emit_c(const tp_tape *T, int P, int lagrange_out, unsigned sweeps,
               bool loops, tp_sbuf *b)
{
    unsigned char *ep = end_points(T);
    const char *const *line;
    uint32_t k;
    int s, st = TP_OK;
    if (!ep)
        return TP_ERR_NOMEM;
    tp__sbuf_printf(b,
                    "/* A compiled tape: %u ops (%u independents, %u "
                    "parameters, %u outputs), format %d.\n"
                    " * Generated by libtape from the tape; not meant to be "
                    "edited. */\n",
                    T->n_ops, T->n_indep, T->n_param, T->n_out,
                    TP_CODEGEN_FORMAT);
    tp__sbuf_puts(b, "#define TP_KERNEL static inline "
                     "__attribute__((always_inline))\n"
                     "#ifndef TPC_NPARTS /* built in one piece */\n"
                     "#define TPC_NPARTS 1\n#define TPC_PART 0\n#endif\n"
                     "#define TPC_CHUNK __attribute__((noinline, "
                     "visibility(\"hidden\")))\n"
                     "#define TPC_LOCAL static __attribute__((noinline))\n"
                     "#define TPC_EXPORT __attribute__((visibility(\"default\")))\n"
                     "#include <math.h>\n#include <string.h>\n");
    for (line = tp__kernel_text; *line; line++)
        tp__sbuf_puts(b, *line);
    tp__sbuf_puts(b, "static const double K[] = {");
    for (k = 0; k < T->n_const; k++) {
        emit_double(b, T->konst[k]);
        tp__sbuf_puts(b, k % 4 == 3 ? ",\n" : ", ");
    }
    tp__sbuf_puts(b, "0.0};\n");
    /* the ops without functions of their own: one copy each, compiled
     * once, dispatching at run time */
    /* (their arguments are the arrays, not the sweep's tp_kx: a tp_kx
     * whose address leaves a chunk stays in memory there, and the
     * compiler's alias analysis of every op then costs most of its time) */
    tp__sbuf_puts(b,
                  "TPC_LOCAL void tpc_value_GEN(double *v, double *aux, "
                  "uint32_t i, unsigned op, unsigned fl, uint32_t u, "
                  "uint32_t t)\n"
                  "{\n    tp_kx x;\n    memset(&x, 0, sizeof x);\n"
                  "    x.K = K;\n    x.v = v;\n    x.aux = aux;\n"
                  "    tp__value_GEN(&x, i, op, fl, u, t);\n}\n"
                  "TPC_LOCAL void tpc_rev1_GEN(double *v, double *aux, "
                  "double *adj, uint32_t i, unsigned op, unsigned fl, "
                  "uint32_t u, uint32_t t)\n"
                  "{\n    tp_kx x;\n    memset(&x, 0, sizeof x);\n"
                  "    x.K = K;\n    x.v = v;\n    x.aux = aux;\n"
                  "    x.adj = adj;\n"
                  "    tp__rev1_GEN(&x, i, op, fl, u, t);\n}\n"
                  "TPC_LOCAL void tpc_partials(const double *v, "
                  "const double *aux, uint32_t i, unsigned op, uint32_t u, "
                  "uint32_t t, tp_partials *d)\n"
                  "{\n    tp__gen_partials(K, v, aux, i, op, u, t, d);\n}\n");
    for (s = 0; s < SW_COUNT && st == TP_OK; s++)
        if (sweeps & sweep_bit[s])
            st = emit_sweep(b, T, ep, (enum sweep)s, loops);
    if (lagrange_out >= 0 || (sweeps & TP_SWEEP_JACOBIAN))
        tp__emit_blocks_common(P, b);
    if (st == TP_OK && lagrange_out >= 0)
        st = tp__emit_lagrange(T, lagrange_out, (int)T->n_indep / 2,
                               (int)T->n_indep / 2, P, loops, b);
    if (st == TP_OK && (sweeps & TP_SWEEP_JACOBIAN))
        st = tp__emit_jacobian(T, P, loops, b);
    if (st == TP_OK && (sweeps & TP_SWEEP_TAYLOR2))
        st = tp__emit_taylor2(T, loops, b);
    tp__sbuf_printf(b,
                    "#if TPC_PART == 0\n"
                    "TPC_EXPORT const int tpc_format = %d;\n"
                    "TPC_EXPORT const uint32_t tpc_nops = %uu;\n"
                    "TPC_EXPORT const size_t tpc_kx_size = sizeof(tp_kx);\n"
                    "TPC_EXPORT const int tpc_P = %d;\n"
                    "TPC_EXPORT const unsigned tpc_sweeps = %uu;\n"
                    "#endif\n",
                    TP_CODEGEN_FORMAT, T->n_ops, P,
                    sweeps & (TP_SWEEP_VALUES | TP_SWEEP_GRADIENTS |
                              TP_SWEEP_JACOBIAN | TP_SWEEP_TAYLOR2));
    free(ep);
    return b->failed ? TP_ERR_NOMEM : st;
}

int tp_tape_emit_c(const tp_tape *t, FILE *out)
{
    tp_sbuf b = {0};
    int st;
    if (!t || !out)
        return TP_ERR_NULL;
    st = tp__emit_c(t, 0, -1, TP_SWEEP_VALUES | TP_SWEEP_GRADIENTS, true,
                    &b);
    if (st == TP_OK && fwrite(b.p, 1, b.len, out) != b.len)
        st = TP_ERR_SIZE;
    tp__sbuf_free(&b);
    return st;
}
