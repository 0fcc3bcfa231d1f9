/* codegen_lagrange.c - the direction blocks of a compiled tape, as
 * straight-line C specialized to the tape:
 *   - the Lagrange block: one output's gradient and its Hessian columns
 *     for unit directions on a block of independents (for a Lagrangian:
 *     dL/dx and d2L/dx dqd, from which tp_lagrange forms M and h);
 *   - the Jacobian block: every output's value and tangent row for unit
 *     directions on a block of independents (tp_jacobian; for the
 *     constraints: phi and C, with dphi/dt when the time is one).
 *
 * What the interpreter decides while sweeping, this decides once while
 * writing the code: which ops the outputs need (their cone), which tangent
 * rows are structurally zero (the op depends on no seeded group), which
 * adjoint-tangent rows have been reached (the interpreter's anz flags),
 * and where each adjoint and row is first written, so the code assigns
 * instead of accumulating into zeroed memory and never clears anything.
 * The per-op arithmetic is the interpreter's (sweep_ops.h), term for term
 * and in the same order; terms whose row is structurally zero are left
 * out, which changes no finite result.
 *
 * The code reads the leaves' and passive ops' values from v (the caller
 * loads them), writes values of the cone into v and aux, tangent rows
 * into tan (only rows of ops depending on a seeded group, as a forward
 * sweep with that mask would), and uses at and adj as scratch of its own.
 * Rows are P (a multiple of TP_LANES) wide: up to ROWS_UNROLL written out
 * element by element, wider ones through small row functions.
 *
 * Strips (the Lagrange block, P of 8 and more): n_ops rows P wide are
 * hundreds of kilobytes at 50 links and megabytes at 200, more than the
 * caches hold, and a sweep streamed them all. Instead the values and
 * adjoints are swept once, and the rows then strip by strip, W
 * directions at a time (4 or 8), in W-wide rows of the block's own
 * scratch (at: the tangent rows, then the adjoint-tangent rows, each
 * half starting on a cache line; tan is not touched). Every row
 * statement runs once per strip with the coefficients the scalar sweeps
 * left (an op's adjoint is final once its reverse statement ran; a GEN
 * op's partials are computed again, the same function of the same
 * values), so each direction's arithmetic is what it was, term for
 * term and in the same order. A strip's row statements are macros
 * (emit_strip_macros): 4-wide vectors where the code is built with AVX,
 * 2-wide ones otherwise. With 4 strips or more a row statement runs
 * only in the strips its row's column range reaches (lagrange_gates).
 */
#include <stdlib.h>
#include <string.h>

#include "codegen.h"

#define ROWS_UNROLL 4

typedef struct lg {
    const tp_tape *T;
    tp_sbuf *b;
    int P;
    unsigned mask;
    unsigned char *need; /* in the output's cone */
    unsigned char *an;   /* the interpreter's anz: row path taken above */
    unsigned char *rw;   /* the adjoint-tangent row holds data */
    unsigned char *aw;   /* the adjoint holds data */
    const char *prefix;  /* of the block's chunk functions: lg_0, ... */
    tp_sbuf *br;         /* where row statements go (b, or the strips') */
    int W;               /* a row's width: P, or the strip's */
    bool strips;         /* rows in strips of W directions (U_, B_) */
    /* Strips gated by the rows' column ranges (lagrange_gates): op i's
     * forward row statement runs in strips below fh[i], its reverse one
     * below rh[i]; setter[w]: the statement of rs that assigns w's
     * adjoint-tangent row (later writers add to it, so run only where it
     * does). fh NULL: no gates. */
    uint32_t *fh, *rh, *setter, *first_w; /* first_w: its op */
    tp_seq *rs;
    uint32_t cur; /* the op being written */
} lg;

/* One term of a row update: coef * (row src). */
typedef struct term {
    const char *coef; /* a C expression, evaluated once */
    char src[40];     /* a row expression */
} term;

static bool tn(const lg *g, uint32_t s)
{
    return (g->T->dep[s] & g->mask) != 0;
}

static void trm(term *t, const char *coef, char kind, uint32_t slot)
{
    t->coef = coef;
    snprintf(t->src, sizeof t->src, "%c_(%u)", kind, slot);
}

/* dst (= or +=) sum of terms, dst the row of slot d in T_ or A_: as
 * 2-wide vectors (the width every x86-64 and AArch64 has in registers;
 * wider generic vectors without the instructions for them go through
 * memory), written out for narrow rows, through a row function
 * (a loop, compiled once) for wide ones. The sum is formed first and then
 * added, as the interpreter does. */
static void emit_row(lg *g, char kind, uint32_t d, bool set, int nt,
                     const term *t)
{
    tp_sbuf *b = g->br;
    int k, j;
    if (nt == 0)
        return;
    if (g->strips) /* the strip's rows: U_ for T_, B_ for A_ */
        kind = kind == 'T' ? 'U' : 'B';
    tp__sbuf_puts(b, "{\n");
    for (j = 0; j < nt; j++)
        tp__sbuf_printf(b, "const double c%d = %s; const double *s%d = %c%s;\n",
                        j, t[j].coef, j,
                        g->strips ? (t[j].src[0] == 'T' ? 'U' : 'B')
                                  : t[j].src[0],
                        t[j].src + 1);
    tp__sbuf_printf(b, "double *d_ = %c_(%u);\n", kind, d);
    if (g->strips && g->fh && kind == 'B') {
        if (set) {
            g->setter[d] = g->rs->n;
            g->first_w[d] = g->cur;
        }
        else
            tp__seq_pair(g->rs, g->setter[d], g->rs->n);
    }
    if (g->strips) {
        tp__sbuf_printf(b, "TPC_R%d%s(d_", nt, set ? "s" : "a");
        for (j = 0; j < nt; j++)
            tp__sbuf_printf(b, ", c%d, s%d", j, j);
        tp__sbuf_puts(b, ");\n");
    } else if (g->W <= ROWS_UNROLL) {
        for (k = 0; k < g->W; k += 2) {
            tp__sbuf_printf(b, "tpc_st(d_ + %d, ", k);
            if (!set)
                tp__sbuf_printf(b, "tpc_ld(d_ + %d) + (", k);
            for (j = 0; j < nt; j++)
                tp__sbuf_printf(b, "%sc%d * tpc_ld(s%d + %d)", j ? " + " : "",
                                j, j, k);
            tp__sbuf_puts(b, set ? ");\n" : "));\n");
        }
    } else {
        tp__sbuf_printf(b, "tpr_%d%s(d_", nt, set ? "s" : "a");
        for (j = 0; j < nt; j++)
            tp__sbuf_printf(b, ", c%d, s%d", j, j);
        tp__sbuf_puts(b, ");\n");
    }
    tp__sbuf_puts(b, "}\n");
}

/* A strip's row statements, d (= or +=) c0 s0 (+ c1 s1 (+ c2 s2)) over
 * W directions, as macros TPC_R<terms><s|a>: 4-wide vectors where the
 * code is built with AVX (compile.c adds -mavx2 where the processor has
 * it), 2-wide ones otherwise (generic 4-wide vectors without AVX are
 * taken apart element by element: 5 times slower). The same sums in the
 * same order either way. */
static void emit_strip_macros(tp_sbuf *b, int W)
{
    int br, n, set, j, k;
    for (br = 0; br < 2; br++) {
        const int vl = br == 0 ? 4 : 2;
        if (br == 0)
            tp__sbuf_puts(
                b, "#ifdef __AVX__\n"
                   "typedef double tpc_v4 __attribute__((vector_size(32)));\n"
                   "#define tpc_ldv(p) __extension__({ tpc_v4 r4_; "
                   "memcpy(&r4_, (p), sizeof r4_); r4_; })\n"
                   "#define tpc_stv(p, x) do { tpc_v4 w4_ = (x); "
                   "memcpy((p), &w4_, sizeof w4_); } while (0)\n");
        else
            tp__sbuf_puts(b, "#else\n#define tpc_ldv(p) tpc_ld(p)\n"
                             "#define tpc_stv(p, x) tpc_st((p), (x))\n");
        for (n = 1; n <= 3; n++)
            for (set = 0; set < 2; set++) {
                tp__sbuf_printf(b, "#define TPC_R%d%s(d", n, set ? "s" : "a");
                for (j = 0; j < n; j++)
                    tp__sbuf_printf(b, ", c%d, s%d", j, j);
                tp__sbuf_puts(b, ") do {");
                for (k = 0; k < W; k += vl) {
                    tp__sbuf_printf(b, " tpc_stv((d) + %d, ", k);
                    if (!set)
                        tp__sbuf_printf(b, "tpc_ldv((d) + %d) + (", k);
                    for (j = 0; j < n; j++)
                        tp__sbuf_printf(b, "%s(c%d) * tpc_ldv((s%d) + %d)",
                                        j ? " + " : "", j, j, k);
                    tp__sbuf_puts(b, set ? ");" : "));");
                }
                tp__sbuf_puts(b, " } while (0)\n");
            }
    }
    tp__sbuf_puts(b, "#endif\n");
}

/* The vector type, and the row functions for wide rows: d (= or +=) c0 s0
 * (+ c1 s1 (+ c2 s2)), plain loops of a fixed length that GCC compiles
 * vectorized, also for AVX2 where the machine has it (picked at load
 * time, as the interpreter's kernels are; no FMA either way). */
static void emit_row_functions(tp_sbuf *b)
{
    static const char *const args[3] = {
        "double c0, const double *restrict s0",
        "double c0, const double *restrict s0, double c1, "
        "const double *restrict s1",
        "double c0, const double *restrict s0, double c1, "
        "const double *restrict s1, double c2, const double *restrict s2"};
    static const char *const sum[3] = {
        "c0 * s0[k]", "c0 * s0[k] + c1 * s1[k]",
        "c0 * s0[k] + c1 * s1[k] + c2 * s2[k]"};
    int n, set;
    tp__sbuf_puts(b,
                  "#if defined(__GNUC__) && !defined(__clang__) && "
                  "defined(__x86_64__) && defined(__linux__)\n"
                  "#define TPC_ROWFN __attribute__((noinline, unused, "
                  "optimize(\"O3\"), target_clones(\"avx2\", "
                  "\"default\")))\n"
                  "#else\n"
                  "#define TPC_ROWFN __attribute__((noinline, unused))\n"
                  "#endif\n"
                  "typedef double tpc_v2 __attribute__((vector_size(16)));\n"
                  "static inline tpc_v2 tpc_ld(const double *p)\n"
                  "{\n    tpc_v2 r;\n    memcpy(&r, p, sizeof r);\n"
                  "    return r;\n}\n"
                  "static inline void tpc_st(double *p, tpc_v2 r)\n"
                  "{\n    memcpy(p, &r, sizeof r);\n}\n");
    for (n = 1; n <= 3; n++)
        for (set = 0; set < 2; set++)
            tp__sbuf_printf(b,
                            "static TPC_ROWFN void tpr_%d%s(double *restrict "
                            "d, %s)\n"
                            "{\n    for (int k = 0; k < PW; k++)\n"
                            "        d[k] %s %s%s%s;\n}\n",
                            n, set ? "s" : "a", args[n - 1], set ? "=" : "+=",
                            set ? "" : "(", sum[n - 1], set ? "" : ")");
}

/* Adjoint contribution: adj[s] (op) expr, with op "+" or "-". */
static void emit_adj(lg *g, uint32_t s, char op, const char *expr)
{
    if (g->aw[s])
        tp__sbuf_printf(g->b, "adj[%u] %c= %s;\n", s, op, expr);
    else if (op == '-')
        tp__sbuf_printf(g->b, "adj[%u] = -(%s);\n", s, expr);
    else
        tp__sbuf_printf(g->b, "adj[%u] = %s;\n", s, expr);
    g->aw[s] = 1;
}

/* Row update of operand w of op i on the row path: terms (ra first, where
 * the op's own row holds data), and w's flags afterwards. */
static void row_to(lg *g, uint32_t w, int nt, const term *t)
{
    emit_row(g, 'A', w, !g->rw[w], nt, t);
    if (nt > 0)
        g->rw[w] = 1;
    g->an[w] = 1;
}

/* ---- forward ----------------------------------------------------------- */

static void emit_forward(lg *g, uint32_t i)
{
    const tp_tape *T = g->T;
    const unsigned op = T->opc[i], fl = T->dep[i];
    const uint32_t u = T->a0[i], t = T->a1[i];
    const bool up = fl & TP_DEP_UPASSIVE, tpas = fl & TP_DEP_TPASSIVE;
    const bool bin = tp__op_kind(op) == TP_KIND_BINARY;
    term tt[2];
    int nt = 0;
    char cu[48], ct[48];
    if (strcmp(tp__op_fn_name(op), "GEN") == 0)
        tp__sbuf_printf(g->b, "tpc_value_GEN(v, aux, %uu, %u, %uu, %uu, %uu);\n",
                        i, op, fl, u, t);
    else
        tp__sbuf_printf(g->b, "tp__value_%s(&y, %uu, %u, %uu, %uu, %uu);\n",
                        tp__op_fn_name(op), i, op, fl, u, t);
    if (!tn(g, i))
        return;
    /* the first partials as expressions */
    switch (op) {
    case TP_OP_ADD: strcpy(cu, "1.0"); strcpy(ct, "1.0"); break;
    case TP_OP_SUB: strcpy(cu, "1.0"); strcpy(ct, "-1.0"); break;
    case TP_OP_MUL:
        snprintf(cu, sizeof cu, "v[%u]", t);
        snprintf(ct, sizeof ct, "v[%u]", u);
        break;
    case TP_OP_NEG:
    case TP_OP_CSUB: strcpy(cu, "-1.0"); break;
    case TP_OP_ADDC: strcpy(cu, "1.0"); break;
    case TP_OP_MULC: snprintf(cu, sizeof cu, "K[%u]", t); break;
    case TP_OP_SQR: snprintf(cu, sizeof cu, "2.0 * v[%u]", u); break;
    case TP_OP_SIN: snprintf(cu, sizeof cu, "aux[%u]", i); break;
    case TP_OP_COS: snprintf(cu, sizeof cu, "-aux[%u]", i); break;
    default:
        tp__sbuf_printf(g->br, "tpc_partials(v, aux, %uu, %u, %uu, %uu, &d);\n",
                        i, op, u, t);
        strcpy(cu, "d.fu");
        strcpy(ct, "d.ft");
        break;
    }
    if (!up && tn(g, u))
        trm(&tt[nt++], cu, 'T', u);
    if (bin && !tpas && tn(g, t))
        trm(&tt[nt++], ct, 'T', t);
    /* an op depending on a seeded group has an operand that does */
    emit_row(g, 'T', i, true, nt, tt);
}

/* ---- reverse ----------------------------------------------------------- */

/* The scalar adjoint of op i when its row path is not taken (the
 * interpreter's tp__adj1_*), or the row path's (tp__rev2_*): they differ
 * only where two operands are one slot. */
static void emit_adjoint(lg *g, uint32_t i, bool rowpath)
{
    const tp_tape *T = g->T;
    const unsigned op = T->opc[i], fl = T->dep[i];
    const uint32_t u = T->a0[i], t = T->a1[i];
    const bool up = fl & TP_DEP_UPASSIVE, tpas = fl & TP_DEP_TPASSIVE;
    char e[64];
    switch (op) {
    case TP_OP_ADD:
        if (!up)
            emit_adj(g, u, '+', "a");
        if (!tpas)
            emit_adj(g, t, '+', "a");
        return;
    case TP_OP_SUB:
        if (!up)
            emit_adj(g, u, '+', "a");
        if (!tpas)
            emit_adj(g, t, '-', "a");
        return;
    case TP_OP_MUL:
        if (!up) {
            snprintf(e, sizeof e, "a * v[%u]", t);
            emit_adj(g, u, '+', e);
        }
        if (!tpas) {
            snprintf(e, sizeof e, "a * v[%u]", u);
            emit_adj(g, t, '+', e);
        }
        return;
    case TP_OP_NEG:
    case TP_OP_CSUB: emit_adj(g, u, '-', "a"); return;
    case TP_OP_ADDC: emit_adj(g, u, '+', "a"); return;
    case TP_OP_MULC:
        snprintf(e, sizeof e, "a * K[%u]", t);
        emit_adj(g, u, '+', e);
        return;
    case TP_OP_SQR:
        snprintf(e, sizeof e, "2.0 * a * v[%u]", u);
        emit_adj(g, u, '+', e);
        return;
    case TP_OP_SIN:
        snprintf(e, sizeof e, "a * aux[%u]", i);
        emit_adj(g, u, '+', e);
        return;
    case TP_OP_COS:
        snprintf(e, sizeof e, "a * aux[%u]", i);
        emit_adj(g, u, '-', e);
        return;
    default: break;
    }
    /* generic: d holds the partials */
    if (rowpath && tp__op_kind(op) == TP_KIND_BINARY && !up && !tpas &&
        u == t) {
        emit_adj(g, u, '+', "(d.fu + d.ft) * a");
        return;
    }
    if (tp__op_kind(op) != TP_KIND_BINARY || !up)
        emit_adj(g, u, '+', "d.fu * a");
    if (tp__op_kind(op) == TP_KIND_BINARY && !tpas)
        emit_adj(g, t, '+', "d.ft * a");
}

/* rev2_one: operand w with first partial f and second ff (expressions). */
static void one_row(lg *g, uint32_t i, uint32_t w, const char *f,
                    const char *ss, bool second)
{
    term t[2];
    int nt = 0;
    if (g->rw[i])
        trm(&t[nt++], f, 'A', i);
    if (second && tn(g, w))
        trm(&t[nt++], ss, 'T', w);
    row_to(g, w, nt, t);
}

static void emit_rows(lg *g, uint32_t i, bool second)
{
    const tp_tape *T = g->T;
    const unsigned op = T->opc[i], fl = T->dep[i];
    const uint32_t u = T->a0[i], t = T->a1[i];
    const bool up = fl & TP_DEP_UPASSIVE, tpas = fl & TP_DEP_TPASSIVE;
    char fu[48], ft[48], s[64];
    term tt[3];
    int nt;
    switch (op) {
    case TP_OP_ADD:
    case TP_OP_SUB:
        if (!up)
            one_row(g, i, u, "1.0", "", false);
        if (!tpas)
            one_row(g, i, t, op == TP_OP_ADD ? "1.0" : "-1.0", "", false);
        return;
    case TP_OP_MUL:
        snprintf(fu, sizeof fu, "v[%u]", t);
        snprintf(ft, sizeof ft, "v[%u]", u);
        if (up || tpas) { /* fuu = 0, the passive one has no tangent */
            one_row(g, i, up ? t : u, up ? ft : fu, "", false);
            return;
        }
        /* adj_mul2: ru += fu ra + a tt; rt += ft ra + a tu */
        nt = 0;
        if (g->rw[i])
            trm(&tt[nt++], fu, 'A', i);
        if (second && tn(g, t))
            trm(&tt[nt++], "a", 'T', t);
        row_to(g, u, nt, tt);
        nt = 0;
        if (g->rw[i])
            trm(&tt[nt++], ft, 'A', i);
        if (second && tn(g, u))
            trm(&tt[nt++], "a", 'T', u);
        row_to(g, t, nt, tt);
        return;
    case TP_OP_NEG:
    case TP_OP_CSUB: one_row(g, i, u, "-1.0", "", false); return;
    case TP_OP_ADDC: one_row(g, i, u, "1.0", "", false); return;
    case TP_OP_MULC:
        snprintf(fu, sizeof fu, "K[%u]", t);
        one_row(g, i, u, fu, "", false);
        return;
    case TP_OP_SQR:
        snprintf(fu, sizeof fu, "2.0 * v[%u]", u);
        one_row(g, i, u, fu, "a * 2.0", second);
        return;
    case TP_OP_SIN:
    case TP_OP_COS:
        snprintf(fu, sizeof fu, "%saux[%u]", op == TP_OP_COS ? "-" : "", i);
        snprintf(s, sizeof s, "a * -v[%u]", i);
        one_row(g, i, u, fu, s, second);
        return;
    default: break;
    }
    second = second && !tp__op_linear(op);
    if (tp__op_kind(op) != TP_KIND_BINARY || tpas) {
        one_row(g, i, u, "d.fu", "a * d.fuu", second);
    } else if (up) {
        one_row(g, i, t, "d.ft", "a * d.ftt", second);
    } else if (u == t) {
        one_row(g, i, u, "d.fu + d.ft",
                "a * (d.fuu + 2.0 * d.fut + d.ftt)", second);
    } else {
        /* adj_2nd2: ru += fu r + suu x + sut y; rt += ft r + sut x + stt y */
        nt = 0;
        if (g->rw[i])
            trm(&tt[nt++], "d.fu", 'A', i);
        if (second && tn(g, u))
            trm(&tt[nt++], "a * d.fuu", 'T', u);
        if (second && tn(g, t))
            trm(&tt[nt++], "a * d.fut", 'T', t);
        row_to(g, u, nt, tt);
        nt = 0;
        if (g->rw[i])
            trm(&tt[nt++], "d.ft", 'A', i);
        if (second && tn(g, u))
            trm(&tt[nt++], "a * d.fut", 'T', u);
        if (second && tn(g, t))
            trm(&tt[nt++], "a * d.ftt", 'T', t);
        row_to(g, t, nt, tt);
    }
}

static void emit_reverse(lg *g, uint32_t i)
{
    const tp_tape *T = g->T;
    const unsigned op = T->opc[i];
    const bool second = tn(g, i); /* the adjoint is taken as non-zero */
    const bool rowpath = g->an[i] || second;
    const bool gen = !strcmp(tp__op_fn_name(op), "GEN");
    size_t at0;
    if (!g->aw[i])
        return; /* nothing reached it */
    tp__sbuf_printf(g->b, "{\nconst double a = adj[%u];\n", i);
    if (gen)
        tp__sbuf_printf(g->b, "tpc_partials(v, aux, %uu, %u, %uu, %uu, &d);\n",
                        i, op, T->a0[i], T->a1[i]);
    emit_adjoint(g, i, rowpath);
    if (g->br != g->b) {
        /* strips: the rows in a statement of their own, run once per
         * strip after the whole scalar sweep, when adj[i] is what it was
         * here (no later op writes it) and d the same partials again */
        tp__sbuf_puts(g->b, "}\n");
        if (!rowpath)
            return;
        at0 = g->br->len;
        tp__sbuf_printf(g->br, "{\nconst double a = adj[%u];\n", i);
        if (gen)
            tp__sbuf_printf(g->br,
                            "tpc_partials(v, aux, %uu, %u, %uu, %uu, &d);\n",
                            i, op, T->a0[i], T->a1[i]);
        {
            const size_t head = g->br->len;
            emit_rows(g, i, second);
            if (g->br->len == head && !g->br->failed) {
                g->br->len = at0; /* no row written: no statement */
                g->br->p[at0] = '\0';
                return;
            }
        }
        tp__sbuf_puts(g->br, "}\n");
        return;
    }
    if (rowpath)
        emit_rows(g, i, second);
    tp__sbuf_puts(g->b, "}\n");
}

/* ---- the functions ----------------------------------------------------- */

/* The ops of one phase: each op's statement (its forward or its reverse
 * code) collected, then written as chunk functions <prefix>_<k>, k from
 * *nchunk on, repeated runs as loops (codegen_loops.c). */
typedef struct phase_ctx {
    const char *prefix;
    int base; /* the first chunk's number */
} phase_ctx;

static void open_phase_chunk(void *ctx, tp_sbuf *b, unsigned c, uint32_t lo,
                             uint32_t hi)
{
    const phase_ctx *x = ctx;
    char sig[64];
    (void)lo;
    (void)hi;
    snprintf(sig, sizeof sig, "void %s_%d(LG_ARGS)", x->prefix,
             x->base + (int)c);
    tp__chunk_begin(b, (unsigned)x->base + c, sig);
    tp__sbuf_puts(b, "LG_BEGIN\n");
}

/* Op i's statements: into q (its value or adjoint, and its rows unless
 * in strips), its rows into r (strips; NULL otherwise). A statement is
 * closed where text was written. */
static void phase_op(lg *g, tp_seq *q, tp_seq *r, bool reverse, uint32_t i)
{
    const size_t l0 = q->text.len, r0 = r ? r->text.len : 0;
    g->b = &q->text;
    g->br = r ? &r->text : g->b;
    g->rs = r;
    g->cur = i;
    if (r && g->fh)
        r->next_hi = reverse ? g->rh[i] : g->fh[i];
    if (reverse)
        emit_reverse(g, i);
    else
        emit_forward(g, i);
    if (q->text.len != l0 || !r)
        tp__seq_close(q, false);
    if (r && r->text.len != r0)
        tp__seq_close(r, false);
}

static int phase_end(lg *g, tp_seq *q, tp_sbuf *b, bool loops, int *nchunk)
{
    phase_ctx x = {g->prefix, *nchunk};
    uint32_t *clo = NULL;
    unsigned nc = 0;
    const int st = tp__seq_emit(q, b, loops, open_phase_chunk, &x, &clo, &nc);
    free(clo);
    tp__seq_free(q);
    g->b = g->br = b;
    *nchunk += (int)nc;
    return st;
}

/* The seeded groups of unit directions on independents first .. first +
 * count - 1 into *mask: TP_ERR_SIZE unless they are whole groups (rows of
 * other independents of a seeded group would have to be zero rows). */
static int block_mask(const tp_tape *T, int first, int count, unsigned *mask)
{
    uint32_t i;
    int k;
    *mask = 0;
    for (k = first; k < first + count; k++)
        *mask |= 1u << T->group[k];
    for (i = 0; i < T->n_indep; i++)
        if ((*mask >> T->group[i] & 1u) &&
            ((int)i < first || (int)i >= first + count))
            return TP_ERR_SIZE;
    return TP_OK;
}

/* A block's state for tape T, P wide, seeding independents first ..
 * first + count - 1: TP_OK, TP_ERR_SIZE or TP_ERR_NOMEM. */
static int lg_init(lg *g, const tp_tape *T, int first, int count, int P,
                   const char *prefix, tp_sbuf *b)
{
    int st;
    memset(g, 0, sizeof *g);
    g->T = T;
    g->b = g->br = b;
    g->P = P;
    g->W = P;
    g->prefix = prefix;
    if ((st = block_mask(T, first, count, &g->mask)) != TP_OK)
        return st;
    g->need = calloc(T->n_ops, 4);
    if (!g->need)
        return TP_ERR_NOMEM;
    g->an = g->need + T->n_ops;
    g->rw = g->an + T->n_ops;
    g->aw = g->rw + T->n_ops;
    return TP_OK;
}

/* Gates for the strips from the rows' column ranges (ranges.c, as the
 * interpreter's ranged sweeps use them): a tangent row of op i can be
 * non-zero only in its forward range's columns, an adjoint-tangent row
 * and what op i's reverse statement adds to its operands' only in its
 * reverse range's. A chain's link k has rates 0 .. k in its rows, so
 * most ranges start at column 0: each statement runs in the strips
 * below the end of its range only (fh, rh: that end in strips), and the
 * strips run from the last to the first. Then a row a statement reads
 * was either written in this strip or not yet in this call (its
 * statement runs in no strip at or above this one), and the block
 * clears every row once per call, so a row not written reads as the
 * zeros the full sweep computes there; a statement running outside its
 * own range (a loop member runs where any of its statements must)
 * computes those zeros too. An adjoint-tangent row is assigned by its
 * first writer and added to by the others: codegen_loops.c runs the
 * first wherever another runs (the pairs recorded in emit_row). Each
 * column a statement computes is computed as in the full sweep, so the
 * results are unchanged (a zero's sign aside, as the interpreter's
 * ranged sweeps).
 *
 * Only for the block ranges.c works out (unit directions on the second
 * half of the independents), strips of whole vectors and MIN_GATED
 * strips or more;
 * AUTOEOM_CODEGEN=noranges leaves the gates out (for benchmarks comparing
 * the two). TP_OK (with or without gates) or TP_ERR_NOMEM. */
#define MIN_GATED 4 /* strips; with 3 (10 links, strips of 4) the gates
                       * were 7 % slower in two runs (bench-rhs) */

static int lagrange_gates(lg *g, int out, uint32_t o, int first, int count)
{
    const tp_tape *T = g->T;
    const uint32_t vps = (uint32_t)g->W / TP_LANES, n = T->n_ops;
    const uint32_t lv = T->n_indep + T->n_param;
    const char *cg = getenv("AUTOEOM_CODEGEN");
    tp_ws *ws = NULL;
    uint32_t i;
    if ((cg && strcmp(cg, "noranges") == 0) || first != count ||
        (uint32_t)first * 2 > T->n_indep || g->W % TP_LANES != 0 ||
        (count + g->W - 1) / g->W < MIN_GATED)
        return TP_OK;
    if (tp_ws_new(&ws, T, 1, NULL) != TP_OK)
        return TP_ERR_NOMEM;
    g->fh = malloc(4 * (size_t)n * sizeof *g->fh);
    if (!g->fh) {
        tp_ws_free(&ws);
        return TP_ERR_NOMEM;
    }
    g->rh = g->fh + n;
    g->setter = g->rh + n;
    g->first_w = g->setter + n;
    tp__lagrange_ranges(ws, out, count, o + 1 > lv ? o + 1 : lv);
    for (i = 0; i < n; i++) {
        const uint32_t *f = ws->frange + 2 * (size_t)i,
                       *r = ws->rrange + 2 * (size_t)i;
        g->fh[i] = f[1] > f[0] ? (f[1] + vps - 1) / vps : 0;
        g->rh[i] = r[1] > r[0] ? (r[1] + vps - 1) / vps : 0;
        g->setter[i] = g->first_w[i] = 0;
    }
    tp_ws_free(&ws);
    return TP_OK;
}

/* Unit seeds on the rows of independents first .. first + count - 1 (a
 * loop: written out, they were a tenth of the source). */
static void emit_seeds(tp_sbuf *b, int first, int count, int P)
{
    tp__sbuf_printf(b,
                    "for (int k_ = 0; k_ < %d; k_++) {\n"
                    "    memset(T_(%d + k_), 0, %d * sizeof(double));\n"
                    "    T_(%d + k_)[k_] = 1.0;\n}\n",
                    count, first, P, first);
}

void tp__emit_blocks_common(int P, tp_sbuf *b)
{
    tp__sbuf_printf(b, "#define PW %d\n", P);
    emit_row_functions(b);
    tp__sbuf_puts(b,
                  "#define T_(s) (tan + (size_t)(s) * PW)\n"
                  "#define A_(s) (at + (size_t)(s) * PW)\n"
                  "#define U_(s) (tan + (size_t)(s) * SW)\n"
                  "static inline double *tpc_line(double *p)\n"
                  "{\n    return (double *)(((uintptr_t)p + 63u) & "
                  "~(uintptr_t)63u);\n}\n"
                  "#define B_(s) (at + (size_t)(s) * SW)\n"
                  "#define LG_ARGS double *restrict v, double *restrict aux, "
                  "double *restrict tan, double *restrict at, "
                  "double *restrict adj, int s_\n"
                  "#define LG_BEGIN tp_kx y; tp_partials d; "
                  "memset(&y, 0, sizeof y); y.K = K; y.v = v; y.aux = aux; "
                  "(void)d; (void)tan; (void)at; (void)adj; (void)s_;\n");
}

/* The strip's width for rows P wide, 0 for no strips. A strip's rows
 * are written out as 2-wide vectors (a few statements per row at these
 * widths, no call); strips need 2 n_ops W doubles of at, which holds
 * n_ops P, and 14 more to start both halves on a cache line. Measured
 * (section 13 of docs/benchmarks.md): 8 directions where there are 16
 * or more (and room for them), 4 below; wider strips, through the row
 * functions or written out, were slower at every N. */
static int strip_width(int P, uint32_t n_ops)
{
    int W;
    for (W = P >= 16 ? 8 : 4; W >= 4; W -= 4)
        if (P >= 2 * W && (size_t)n_ops * (size_t)(P - 2 * W) >= 14)
            return W;
    return 0;
}

/* The copy-out of the independents' rows (strips: this strip's columns
 * c_ .. c_ + w_ - 1 of them) and, once, their adjoints: a statement
 * each, repeated runs as loops. */
static int emit_results(lg *g, int count, bool rows, bool grads, bool loops,
                        tp_sbuf *b)
{
    tp_seq q;
    uint32_t i, *clo = NULL;
    unsigned nc = 0;
    int st;
    memset(&q, 0, sizeof q);
    for (i = 0; i < g->T->n_indep; i++) {
        if (grads) {
            if (g->aw[i])
                tp__sbuf_printf(&q.text, "gr[%u] = adj[%u];\n", i, i);
            else
                tp__sbuf_printf(&q.text, "gr[%u] = 0.0;\n", i);
        }
        if (rows && g->strips) {
            if (g->rw[i])
                tp__sbuf_printf(&q.text,
                                "tpc_out(H + %u + c_, sb_ + (size_t)%u * SW, "
                                "w_);\n",
                                i * (uint32_t)count, i);
            else
                tp__sbuf_printf(&q.text, "tpc_out0(H + %u + c_, w_);\n",
                                i * (uint32_t)count);
        } else if (rows) {
            if (g->rw[i])
                tp__sbuf_printf(&q.text,
                                "memcpy(H + %u, A_(%u), %d * sizeof(double));\n",
                                i * (uint32_t)count, i, count);
            else
                tp__sbuf_printf(&q.text,
                                "memset(H + %u, 0, %d * sizeof(double));\n",
                                i * (uint32_t)count, count);
        }
        tp__seq_close(&q, false);
    }
    st = tp__seq_emit(&q, b, loops, NULL, NULL, &clo, &nc);
    free(clo);
    tp__seq_free(&q);
    return st;
}

/* Gated strips: the rows a strip may read without having written them
 * zero at the start of a call (lagrange_gates): the tangent rows of ops
 * whose forward statement does not run in every strip, and the
 * adjoint-tangent rows whose first writer does not (the seeds' rows are
 * cleared apart). A statement each, repeated runs as loops. */
static int emit_zeros(lg *g, uint32_t ns, bool loops, tp_sbuf *b)
{
    const tp_tape *T = g->T;
    tp_seq q;
    uint32_t i, *clo = NULL;
    unsigned nc = 0;
    int st;
    int half;
    memset(&q, 0, sizeof q);
    for (half = 0; half < 2; half++) {
        uint32_t a = 0, len = 0;
        for (i = 0; i <= T->n_ops; i++) {
            const bool z =
                i < T->n_ops &&
                (half == 0 ? i >= T->first_active && g->need[i] &&
                                 tn(g, i) && g->fh[i] < ns
                           : g->rw[i] && g->rh[g->first_w[i]] < ns);
            if (z && len++ == 0)
                a = i;
            if (z || len == 0)
                continue;
            /* a run of consecutive rows: one memset */
            tp__sbuf_printf(&q.text,
                            "memset(%s + (size_t)%uu * SW, 0, (size_t)%uu * "
                            "SW * sizeof(double));\n",
                            half ? "sb_" : "su_", a, len);
            tp__seq_close(&q, false);
            len = 0;
        }
    }
    st = tp__seq_emit(&q, b, loops, NULL, NULL, &clo, &nc);
    free(clo);
    tp__seq_free(&q);
    return st;
}

static void emit_calls(tp_sbuf *b, int k0, int k1, const char *args)
{
    int k;
    for (k = k0; k < k1; k++)
        tp__sbuf_printf(b, "lg_%d(%s);\n", k, args);
}

int tp__emit_lagrange(const tp_tape *T, int out, int first, int count,
                      int P, bool loops, tp_sbuf *b)
{
    const uint32_t o = T->out_slot[out];
    const bool any = o >= T->first_active;
    lg g;
    tp_seq q, r;
    uint32_t i;
    int nchunk = 0, k[5] = {0, 0, 0, 0, 0};
    int st = lg_init(&g, T, first, count, P, "lg", b);
    if (st != TP_OK)
        return st;
    g.W = strip_width(P, T->n_ops);
    g.strips = g.W > 0;
    if (!g.strips)
        g.W = P;
    else {
        tp__sbuf_printf(b, "#define SW %d\n", g.W);
        emit_strip_macros(b, g.W);
        /* the copy-out of a strip's w_ columns: a constant size (a few
         * vector moves, no call) where the strip is full */
        tp__sbuf_puts(
            b, "static inline void tpc_out(double *restrict d, "
               "const double *restrict s, int w)\n"
               "{\n    if (w == SW)\n"
               "        memcpy(d, s, SW * sizeof(double));\n"
               "    else\n"
               "        memcpy(d, s, (size_t)w * sizeof(double));\n}\n"
               "static inline void tpc_out0(double *d, int w)\n"
               "{\n    if (w == SW)\n"
               "        memset(d, 0, SW * sizeof(double));\n"
               "    else\n"
               "        memset(d, 0, (size_t)w * sizeof(double));\n}\n");
    }
    if (any) {
        g.need[o] = 1;
        tp__cone(T, o, g.need);
    }
    if (g.strips && any &&
        (st = lagrange_gates(&g, out, o, first, count)) != TP_OK) {
        free(g.need);
        return st;
    }
    /* forward over the cone, then reverse from the output; in strips,
     * the values and adjoints (chunks k0 .. k1, k2 .. k3) apart from
     * the rows (k1 .. k2, k3 .. k4), which run once per strip */
    memset(&q, 0, sizeof q);
    memset(&r, 0, sizeof r);
    if (g.fh)
        r.nstrips = (uint32_t)((count + g.W - 1) / g.W);
    for (i = T->first_active; any && i <= o; i++)
        if (g.need[i])
            phase_op(&g, &q, g.strips ? &r : NULL, false, i);
    st = phase_end(&g, &q, b, loops, &nchunk);
    k[1] = nchunk;
    if (st == TP_OK && g.strips)
        st = phase_end(&g, &r, b, loops, &nchunk);
    k[2] = nchunk;
    if (g.fh) /* phase_end cleared r */
        r.nstrips = (uint32_t)((count + g.W - 1) / g.W);
    g.aw[o] = 1; /* seeded by the entry function */
    for (i = o + 1; st == TP_OK && any && i-- > T->first_active;)
        if (g.need[i] && g.aw[i])
            phase_op(&g, &q, g.strips ? &r : NULL, true, i);
    if (st == TP_OK)
        st = phase_end(&g, &q, b, loops, &nchunk);
    k[3] = nchunk;
    if (st == TP_OK && g.strips)
        st = phase_end(&g, &r, b, loops, &nchunk);
    k[4] = nchunk;
    tp__seq_free(&q);
    tp__seq_free(&r);
    if (st != TP_OK) {
        free(g.need);
        free(g.fh);
        return st;
    }
    tp__sbuf_puts(b, "#if TPC_PART == 0\n"
                     "TPC_EXPORT void tpc_lagrange(double *restrict v, "
                     "double *restrict aux, double *restrict tan, "
                     "double *restrict at, double *restrict adj, "
                     "double *restrict gr, double *restrict H)\n{\n");
    if (!g.strips) {
        emit_seeds(b, first, count, P);
        tp__sbuf_printf(b, "adj[%u] = 1.0;\n", o);
        emit_calls(b, 0, k[4], "v, aux, tan, at, adj, 0");
        st = emit_results(&g, count, true, true, loops, b);
    } else {
        tp__sbuf_printf(b, "adj[%u] = 1.0;\n", o);
        emit_calls(b, k[0], k[1], "v, aux, tan, at, adj, 0");
        emit_calls(b, k[2], k[3], "v, aux, tan, at, adj, 0");
        st = emit_results(&g, count, false, true, loops, b);
        tp__sbuf_printf(b,
                        "double *restrict su_ = tpc_line(at), *restrict sb_ "
                        "= tpc_line(su_ + (size_t)%uu * SW);\n"
                        "(void)tan;\n",
                        T->n_ops);
        tp__sbuf_printf(b,
                        "memset(su_ + (size_t)%d * SW, 0, (size_t)%d * "
                        "SW * sizeof(double));\n",
                        first, count);
        if (g.fh && st == TP_OK) /* gated: rows zero until written */
            st = emit_zeros(&g, (uint32_t)((count + g.W - 1) / g.W), loops,
                            b);
        tp__sbuf_printf(
            b,
            "for (int s_ = %d; s_-- > 0;) {\n"
            "const int c_ = s_ * SW;\n"
            "const int w_ = %d - c_ < SW ? %d - c_ : SW;\n"
            "for (int k_ = c_; k_ < c_ + w_; k_++)\n"
            "    su_[(size_t)(%d + k_) * SW + (size_t)(k_ - c_)] = 1.0;\n",
            (count + g.W - 1) / g.W, count, count, first);
        emit_calls(b, k[1], k[2], "v, aux, su_, sb_, adj, s_");
        emit_calls(b, k[3], k[4], "v, aux, su_, sb_, adj, s_");
        if (st == TP_OK)
            st = emit_results(&g, count, true, false, loops, b);
        /* the seed rows zero again for the next strip's */
        tp__sbuf_printf(
            b,
            "for (int k_ = c_; k_ < c_ + w_; k_++)\n"
            "    su_[(size_t)(%d + k_) * SW + (size_t)(k_ - c_)] = 0.0;\n"
            "}\n",
            first);
    }
    if (st != TP_OK) {
        free(g.need);
        free(g.fh);
        return st;
    }
    tp__sbuf_printf(b,
                    "(void)v;\n(void)aux;\n}\n"
                    "TPC_EXPORT const int tpc_lagrange_shape[4] = "
                    "{%d, %d, %d, %d};\n#endif\n",
                    out, first, count, P);
    free(g.need);
        free(g.fh);
    return b->failed ? TP_ERR_NOMEM : TP_OK;
}

int tp__emit_jacobian(const tp_tape *T, int P, bool loops, tp_sbuf *b)
{
    const int count = (int)T->n_indep;
    lg g;
    tp_seq q;
    uint32_t i, top;
    int k, nchunk = 0;
    int st = lg_init(&g, T, 0, count, P, "jc", b);
    if (st != TP_OK)
        return st;
    /* the cone of every output, forward once */
    top = tp__outputs_cone(T, g.need);
    memset(&q, 0, sizeof q);
    for (i = T->first_active; i < top; i++)
        if (g.need[i])
            phase_op(&g, &q, NULL, false, i);
    if ((st = phase_end(&g, &q, b, loops, &nchunk)) != TP_OK) {
        free(g.need);
        free(g.fh);
        return st;
    }
    tp__sbuf_puts(b, "#if TPC_PART == 0\n"
                     "TPC_EXPORT void tpc_jacobian(double *restrict v, "
                     "double *restrict aux, double *restrict tan)\n{\n");
    emit_seeds(b, 0, count, P);
    for (k = 0; k < nchunk; k++)
        tp__sbuf_printf(b, "jc_%d(v, aux, tan, NULL, NULL, 0);\n", k);
    tp__sbuf_printf(b,
                    "(void)v;\n(void)aux;\n}\n"
                    "TPC_EXPORT const int tpc_jacobian_shape[2] = "
                    "{%d, %d};\n#endif\n",
                    count, P);
    free(g.need);
        free(g.fh);
    return b->failed ? TP_ERR_NOMEM : TP_OK;
}
