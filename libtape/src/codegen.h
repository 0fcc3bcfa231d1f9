/* codegen.h - what the compiled-tape files share (codegen.c emits the
 * source, compile.c builds, caches and loads it, textbuf.c holds the text
 * while it grows). Not installed. */
#ifndef TAPE_CODEGEN_H
#define TAPE_CODEGEN_H

#include <stdbool.h>
#include <stddef.h>

#include "sweep_ops.h"
#include "tape_internal.h"

/* Bumped whenever the generated source's interface or the generator's
 * way of writing it changes (the entry points, tp_kx; 4: repeated runs
 * as loops, codegen_loops.c; 5: the Lagrange block's rows in strips in
 * its own scratch, codegen_lagrange.c; 6: the strips' seeds and
 * copy-out; 7: the strips gated by the rows' column ranges, run from the
 * last to the first); part of the cache key (beside the source itself)
 * and checked on load, so that no object a former generator built is
 * loaded. */
#define TP_CODEGEN_FORMAT 7

/* A growing string; after a failed allocation `failed` is set and further
 * appends do nothing. */
typedef struct tp_sbuf {
    char *p;
    size_t len, cap;
    bool failed;
    size_t stmts; /* statements tp__seq_emit wrote into it (a loop's body
                     once): what the compiler's time grows with */
} tp_sbuf;

void tp__sbuf_puts(tp_sbuf *b, const char *s);
void tp__sbuf_putn(tp_sbuf *b, const char *s, size_t n); /* n bytes of s */
void tp__sbuf_printf(tp_sbuf *b, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
void tp__sbuf_free(tp_sbuf *b);

/* The per-op kernels as text, NULL-terminated (made at build time from
 * tape_ops.h, op_math.h and sweep_ops.h). */
extern const char *const tp__kernel_text[];

/* The C source of tape T, appended to b: TP_OK or TP_ERR_NOMEM (or the
 * blocks' TP_ERR_SIZE). P is the row width the workspaces will have (a
 * multiple of TP_LANES, 0: unknown); sweeps says which of the value
 * (tpc_fwd0) and gradient (tpc_rev1) sweeps, the Jacobian block over
 * every independent (tpc_jacobian, it needs P) and the Taylor sweep
 * (tpc_taylor2) to include (TP_SWEEP_VALUES, _GRADIENTS, _JACOBIAN,
 * _TAYLOR2); with lagrange_out >= 0 the Lagrange block of that output is
 * included too (it needs P). loops: repeated runs of statements as loops
 * (codegen_loops.c), else straight-line code. */
int tp__emit_c(const tp_tape *T, int P, int lagrange_out, unsigned sweeps,
               bool loops, tp_sbuf *b);

/* What the blocks below share (the row width PW, the row functions, the
 * row macros and chunk arguments), emitted once before them. */
void tp__emit_blocks_common(int P, tp_sbuf *b);

/* The Lagrange block of output out (codegen_lagrange.c): the function
 * tpc_lagrange(v, aux, tan, at, adj, g, H) giving the output's gradient g
 * and its Hessian columns H (n_indep x count) for unit directions on the
 * independents first .. first + count - 1, rows P wide. TP_ERR_SIZE when
 * the block is not made of whole dependency groups. */
int tp__emit_lagrange(const tp_tape *T, int out, int first, int count,
                      int P, bool loops, tp_sbuf *b);

/* The Jacobian block (codegen_lagrange.c): the function
 * tpc_jacobian(v, aux, tan) giving the values of every output's cone and
 * their tangent rows for unit directions on every independent, rows P
 * wide. */
int tp__emit_jacobian(const tp_tape *T, int P, bool loops, tp_sbuf *b);

/* The Taylor sweep (codegen_taylor.c): the function
 * tpc_taylor2(v, aux, d1, d2, dir) giving the values and the first and
 * second Taylor coefficients along dir of every output's cone, as
 * tp__taylor2 does. */
int tp__emit_taylor2(const tp_tape *T, bool loops, tp_sbuf *b);

/* A chunk function (a run of a sweep's ops) opens with its prototype sig
 * ("void lg_3(LG_ARGS)") and its definition, compiled only in part
 * c % TPC_NPARTS: a large tape is built in TPC_NPARTS parts at once, each
 * part the same source with its own TPC_PART (compile.c), part 0 holding
 * the entry points and exported data. TP_CHUNK_END closes it. */
void tp__chunk_begin(tp_sbuf *b, unsigned c, const char *sig);
#define TP_CHUNK_END "}\n#endif\n"

/* A sweep's statements, one per op, before they are written
 * (codegen_loops.c): append a statement's text to text, then close it. */
typedef struct tp_seq {
    tp_sbuf text;         /* the statements, one after another */
    size_t *end;          /* end[k]: one past statement k in text */
    unsigned char *fixed; /* statement k stays out of loops (a label) */
    uint32_t n, cap;      /* statements, room */
    bool failed;          /* out of memory */
    /* Gated statements (the Lagrange block's strips, nstrips > 0): a
     * statement runs in strips s_ < hi[k] only (next_hi: the bound of
     * the statement being written, taken by tp__seq_close), and a loop
     * member runs where any of its statements must; pairs (a, b): where
     * statement b runs, a must run too (tp__seq_pair). */
    uint32_t nstrips, next_hi;
    uint32_t *hi;
    uint32_t *pairs;
    size_t npairs, pcap;
} tp_seq;
void tp__seq_close(tp_seq *s, bool fixed);
void tp__seq_free(tp_seq *s);
void tp__seq_pair(tp_seq *s, uint32_t a, uint32_t b);
/* Writes chunk c's opening for statements lo .. hi - 1 (tp__chunk_begin
 * and what the chunk declares). */
typedef void (*tp_seq_open)(void *ctx, tp_sbuf *b, unsigned c, uint32_t lo,
                            uint32_t hi);
/* The statements of s into b as chunk functions (each opened by open,
 * closed by TP_CHUNK_END; open NULL: no chunks, the statements go into
 * the function being written), repeated runs as loops unless loops is false
 * (then straight-line, one statement after another). *chunk_lo (malloc'd,
 * the caller frees) gets each chunk's first statement, *nchunks their
 * count. TP_OK or TP_ERR_NOMEM. */
int tp__seq_emit(const tp_seq *s, tp_sbuf *b, bool loops, tp_seq_open open,
                 void *ctx, uint32_t **chunk_lo, unsigned *nchunks);

/* The compiler (compile_run.c). The command cc's first word is resolved
 * through PATH to the real path of the file that runs (exe, at most len
 * bytes); 0, or -1 with msg. */
#define TP_MAX_PARTS 8
int tp__compiler_path(const char *cc, char *exe, size_t len, char *msg,
                      size_t mlen);
/* The identity of the compiler exe run as cc: its path, size, times and
 * inode, and what `cc --version` prints (run once per process and
 * compiler, under a lock), into out (NUL-terminated, cut at len). */
void tp__compiler_identity(const char *exe, const char *cc, char *out,
                           size_t len);
/* Build wd/src.c into wd/out.so with exe run as cc and flags: in one
 * compiler call, or with parts > 1 in that many side by side (objects
 * wd/pK.o, linked). wd is a private directory of this build; the
 * compilers' messages go to wd/log, which messages call log_name. Each
 * compiler runs in a process group of its own, killed whole when the
 * build is abandoned or the calling thread dies. 0, or -1 with msg. */
int tp__run_build(const char *exe, const char *cc, const char *flags,
                  const char *wd, int parts, const char *log_name,
                  char *msg, size_t len);

/* SHA-256 (sha256.c): init, update any number of times, then the digest
 * as 64 hex digits (the state is spent). */
typedef struct tp_sha256 {
    uint32_t h[8];
    uint64_t bytes;
    unsigned char buf[64];
    size_t fill;
} tp_sha256;
void tp__sha256_init(tp_sha256 *s);
void tp__sha256_update(tp_sha256 *s, const void *data, size_t n);
void tp__sha256_hex(tp_sha256 *s, char out[65]);

/* The cone of the ops marked in need at or below top: every op whose
 * value they need (and the partners whose sine or cosine a paired op
 * reads), marked in need too (codegen.c). */
void tp__cone(const tp_tape *T, uint32_t top, unsigned char *need);
/* The same for every output's op: need (n_ops entries, zeroed) marks the
 * cone; returns one past the highest op marked (first_active if none). */
uint32_t tp__outputs_cone(const tp_tape *T, unsigned char *need);

/* The name of op's own function in sweep_ops.h ("MUL"), or "GEN". */
const char *tp__op_fn_name(unsigned op);

typedef void (*tp_lagrange_fn)(double *v, double *aux, double *tan,
                               double *at, double *adj, double *g,
                               double *H);
typedef void (*tp_jacobian_fn)(double *v, double *aux, double *tan);
typedef void (*tp_taylor2_fn)(double *v, double *aux, double *d1,
                              double *d2, const double *dir);

/* The entry points of a loaded compiled tape: each runs one sweep's ops
 * from first_active up to end (forward) or from end - 1 down (reverse). */
typedef void (*tp_kernel_fn)(const tp_kx *x, uint32_t end);

struct tp_compiled {
    const tp_tape *t; /* the tape it was made from */
    void *dl;         /* dlopen handle */
    int P;            /* row width it was made for, 0: any */
    unsigned sweeps;  /* TP_SWEEP_VALUES, _GRADIENTS, _JACOBIAN, _TAYLOR2 */
    tp_kernel_fn fwd0, rev1; /* NULL for a sweep it does not have */
    /* the Lagrange block, or NULL: output lout, unit directions on the
     * independents lfirst .. lfirst + lcount - 1, seeded groups lmask */
    tp_lagrange_fn lagrange;
    int lout, lfirst, lcount;
    unsigned lmask;
    /* the Jacobian block, or NULL: unit directions on every independent,
     * seeded groups jmask */
    tp_jacobian_fn jacobian;
    unsigned jmask;
    tp_taylor2_fn taylor2; /* the Taylor sweep, or NULL */
};

#endif /* TAPE_CODEGEN_H */
