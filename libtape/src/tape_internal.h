/* tape_internal.h - structures and internal prototypes shared by the files
 * of libtape. Not installed.
 *
 * Three levels of visibility: tape.h is the public API; this header is
 * library-internal (used by libtape's files and by its white-box tests);
 * each .c file keeps its own helpers static.
 *
 * Invariants of a finished tape (see finalize.c):
 *   - op i writes slot i; every operand slot of op i is < i;
 *   - slots 0 .. n_indep-1 are the INDEP ops in order, then the n_param
 *     PARAM ops in order, then the passive ops (dep == 0: constants and
 *     functions of parameters only), then from first_active the ops that
 *     depend on some independent;
 *   - a1 of a SIN or COS op is 0, or 1 + the slot of an earlier COS or SIN
 *     op of the same operand, whose auxiliary value is this op's value;
 *   - every non-leaf op and every CONST reaches some output (dead code is
 *     gone); INDEP and PARAM ops are kept whether used or not;
 *   - dep[i] & TP_DEP_GROUPS has bit g set iff op i depends on an
 *     independent of group g; an active binary op flags a passive operand
 *     with TP_DEP_UPASSIVE or TP_DEP_TPASSIVE;
 *   - ADD, SUB and MUL never have both operands in one slot (the recorder
 *     records 2x, 0 and x^2 instead), so their operand rows are distinct.
 */
#ifndef TAPE_INTERNAL_H
#define TAPE_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "tape/tape.h"
#include "tape_ops.h"

#define TP_MAX_GROUPS 6
#define TP_MSG_LEN 256
/* Slot indices are 32-bit; leave room for "no slot". */
#define TP_MAX_OPS (UINT32_MAX / 2u)
#define TP_NO_SLOT UINT32_MAX

/* ---- the op table as data --------------------------------------------- */

typedef struct tp_opinfo {
    const char *name;    /* "ADD" */
    unsigned char kind;  /* enum tp_op_kind */
    unsigned char flags; /* enum tp_op_flag */
    unsigned char domain; /* enum tp_op_domain */
    const char *meaning;
} tp_opinfo;

extern const tp_opinfo tp__opinfo[TP_OP_COUNT];

/* ---- allocation (alloc.c) --------------------------------------------- */

/* The allocator to use: *al, or the C library's when al is NULL. */
tp_allocator tp__allocator(const tp_allocator *al);
void *tp__alloc(const tp_allocator *al, size_t size);
void *tp__calloc(const tp_allocator *al, size_t n, size_t size);
void tp__free(const tp_allocator *al, void *p, size_t size);
/* Grow *p (elements of elsize, capacity *cap) to hold at least need
 * elements, doubling. Returns 0, or -1 on overflow or allocation failure
 * with *p and *cap unchanged. */
int tp__grow(const tp_allocator *al, void **p, size_t elsize, size_t *cap,
             size_t need);
char *tp__strdup(const tp_allocator *al, const char *s);
void tp__strfree(const tp_allocator *al, char *s);
/* a * b, or SIZE_MAX on overflow. */
size_t tp__mulsz(size_t a, size_t b);

/* ---- recording contexts (rec.c) --------------------------------------- */

/* Inlining where it decides speed: TP_COLD for the error path of a
 * function called for every op (kept out of line, so that the common
 * path saves no registers for it); TP_INLINE for a body specialized by
 * its callers' constants; TP_NOINLINE for a function that must save only
 * the registers it uses itself. */
#if defined(__GNUC__)
#define TP_COLD __attribute__((noinline, cold))
#define TP_INLINE static inline __attribute__((always_inline))
#define TP_NOINLINE __attribute__((noinline))
#else
#define TP_COLD
#define TP_INLINE static inline
#define TP_NOINLINE
#endif

/* What a backend implements. Ids are the backend's indices of values; the
 * common layer (rec.c) has already checked every operand id. */
typedef struct tp_backend {
    const char *name;
    /* Start a run: evaluators discard the previous run's values and make
     * the n_indep independents ids 0 .. n_indep-1 from x. */
    int (*begin)(tp_rec *r, const double *x);
    /* A parameter (k-th declared in this run) with the value it takes. */
    uint32_t (*param)(tp_rec *r, int k, double value);
    uint32_t (*constant)(tp_rec *r, double c);
    /* A non-leaf op; c is the constant (UCONST) or exponent (UINT). */
    uint32_t (*apply)(tp_rec *r, int op, uint32_t u, uint32_t t, double c);
    /* The value of an id (evaluators); NULL for the recorder. */
    double (*value)(const tp_rec *r, uint32_t id);
    void (*destroy)(tp_rec *r);
    /* Evaluators, optional: called when the user's function has returned;
     * non-zero asks tp_rec_run to make the run once more from the start
     * (the tuple evaluator, when its reuse of storage did not hold). */
    int (*end)(tp_rec *r);
} tp_backend;

typedef struct tp_named {
    char *name;
    double value; /* parameter: default (recorder) or value in use */
    uint32_t id;  /* backend id */
} tp_named;

/* A hash index over a list of names (name_index.c). */
#define TP_INDEX_MIN 32 /* shorter lists are scanned */
typedef struct tp_name_index {
    uint32_t *slot; /* entry index + 1, 0 empty; cap entries */
    size_t cap;     /* a power of 2, or 0 */
    size_t count;   /* the list's first count entries are in it */
} tp_name_index;
/* The entry of v[0 .. n) named name, or NULL. */
tp_named *tp__index_find(const tp_allocator *al, tp_name_index *ix,
                         tp_named *v, size_t n, const char *name);
/* Forget the entries (the list was emptied); free the table. */
void tp__index_reset(tp_name_index *ix);
void tp__index_free(const tp_allocator *al, tp_name_index *ix);

/* The common part of every context; backends embed it first. */
struct tp_rec {
    const tp_backend *be;
    tp_allocator al;
    int n_indep;
    uint32_t tag;    /* stamped in every handle of this context */
    uint32_t n_ids;  /* ids below this are valid (set by the backend) */
    int status;      /* sticky: first error of the current run */
    bool finished;   /* recorder only: tp_recorder_finish succeeded */
    bool running;    /* inside tp_rec_run */
    char msg[TP_MSG_LEN];
    tp_named *params; /* declared parameters, in declaration order */
    size_t n_params, cap_params;
    tp_named *outs; /* outputs, in declaration order */
    size_t n_outs, cap_outs;
    /* evaluators: entries whose names are kept from earlier runs */
    size_t kept_params, kept_outs;
    /* evaluators: the parameters the previous run declared, and whether
     * this run has declared the same ones in the same order so far (then
     * the next of them needs no search among this run's names) */
    size_t prev_params;
    bool params_in_order;
    tp_named *over; /* evaluators: parameter overrides by name */
    size_t n_over, cap_over;
    tp_name_index param_index, out_index; /* over params, outs */
};

/* Initialize / release the common part. */
int tp__rec_init(tp_rec *r, const tp_backend *be, int n_indep,
                 const tp_allocator *al);
void tp__rec_release(tp_rec *r);
/* Record an error in r if none is recorded yet; returns status. */
int tp__rec_fail(tp_rec *r, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Apply op through the common checks (for the op-table-driven tests):
 * a, b are operands (b ignored for unary kinds), c the constant or the
 * integer exponent. */
tp_val tp__rec_op(tp_rec *r, int op, tp_val a, tp_val b, double c);

/* ---- the tape --------------------------------------------------------- */

/* One op as the interpreter's first- and second-order sweeps read it:
 * the tape's opc, dep, a0 and a1 of that op side by side, one load base
 * instead of four (workspace.c fills a workspace's copy; the tape itself
 * stays the arrays, about 10 bytes an op). */
typedef struct tp_oprec {
    uint32_t u, t;
    uint8_t op, fl;
} tp_oprec;

struct tp_tape {
    tp_allocator al;
    uint32_t n_ops;    /* total, leaves included */
    uint32_t n_indep;
    uint32_t n_param;
    uint32_t n_out;
    uint32_t n_const;
    uint32_t first_active; /* slots below hold leaves and passive ops */
    uint8_t *opc;      /* [n_ops] opcode */
    uint8_t *dep;      /* [n_ops] group mask */
    uint32_t *a0;      /* [n_ops] first operand / leaf index */
    uint32_t *a1;      /* [n_ops] second operand / const index / exponent */
    double *konst;     /* [n_const] constant pool */
    uint32_t *out_slot; /* [n_out] */
    char **out_name;    /* [n_out] */
    char **param_name;  /* [n_param] */
    double *param_dflt; /* [n_param] */
    uint32_t *out_order;   /* [n_out] output indices, names ascending */
    uint32_t *param_order; /* [n_param] parameter indices, names ascending
                              (tp_tape_*_index search them by bisection) */
    unsigned char *group; /* [n_indep] */
    tp_tape_stats stats;
};

/* Build a tape from a recorder's op stream (finalize.c). */
typedef struct tp_rawtape {
    const uint8_t *opc;
    const uint32_t *a0, *a1;
    size_t n_ops;
    const double *konst;
    size_t n_const;
    const unsigned char *group;
    uint32_t n_indep;
    const tp_named *params; /* id = slot */
    size_t n_params;
    const tp_named *outs;   /* id = slot */
    size_t n_outs;
    size_t n_cse_hits, n_folded;
} tp_rawtape;
int tp__tape_build(const tp_rawtape *raw, const tp_allocator *al,
                   tp_tape **out, char *msg);

/* ---- workspaces and sweeps -------------------------------------------- */

struct tp_ws {
    const tp_tape *t;
    tp_allocator al;
    int P;            /* row stride: max_dirs rounded up to TP_LANES */
    int max_dirs;     /* directions per sweep (chunk size) */
    double *v;        /* [n_ops] values */
    double *aux;      /* [n_ops] auxiliary values (op_math.h) */
    double *adj;      /* [n_ops] adjoints; all zero between sweeps */
    double *tan;      /* [n_ops * P] tangents, row i = slot i */
    double *atan;     /* [n_ops * P] adjoint tangents; zero between sweeps */
    uint8_t *anz;     /* [n_ops] 0: that atan row is known to be zero */
    double *d1, *d2;  /* [n_ops] Taylor coefficients */
    double *param;    /* [n_param] parameter values in use */
    double *hs;       /* [n_indep * P] scratch for Hessian columns */
    double *g;        /* [n_indep] scratch for gradients */
    double *wout;     /* [n_out] scratch for output weights */
    bool passive_stale; /* v of the passive ops needs recomputing */
    unsigned tan_mask; /* rows of ops outside this dependency mask are zero */
    int tan_cols;      /* columns of active rows that may be non-zero */
    const tp_compiled *cc; /* compiled sweeps in use, or NULL */
    double *cat, *cadj;    /* [n_ops * P], [n_ops]: scratch of its Lagrange
                              block (made with the first such cc) */
    /* The Lagrange block's column ranges (ranges.c), in vectors of
     * TP_LANES, (first, one past the last) per op: frange of its tangent
     * row, rrange of its reverse kernels; for output range_out (-1: not
     * worked out yet) and range_n rates. While tan_ranged holds, every
     * tangent row is zero outside its frange (the ranged sweeps keep it;
     * any other sweep writing tangents ends it). */
    uint32_t *frange, *rrange; /* [2 * n_ops] each */
    tp_oprec *rec;             /* [n_ops] the tape's ops as records */
    int range_out, range_n;
    bool tan_ranged;
    /* strips.c's scratch: each op's adjoint as the first strip read it
     * [n_ops], and strip_w wide tangent and adjoint-tangent rows [n_ops
     * strip_w] each, from stan (strip_w 0: no strips; strip_buf holds
     * them with room to start stan on a cache line) */
    double *abar, *strip_buf, *stan, *satan;
    int strip_w;
    char msg[TP_MSG_LEN];
};

/* Sweeps (forward.c, reverse.c). Ops in slots end and above are not swept. A seed is
 * either S (n_indep x p, leading dimension lds) or, when S is NULL, unit
 * directions on independents first .. first+p-1. */
void tp__fwd0(tp_ws *ws, const double *x, uint32_t end);
void tp__fwd1(tp_ws *ws, const double *x, int p, const double *S, size_t lds,
              int first, unsigned mask, uint32_t end);
void tp__rev1(tp_ws *ws, const double *w, uint32_t end, double *g);
/* Adjoints and adjoint tangents; results: g[n] (may be NULL) and HS (n x p,
 * leading dimension ldh) (may be NULL). */
void tp__rev2(tp_ws *ws, const double *w, int p, unsigned mask, uint32_t end,
              double *g, double *HS, size_t ldh);
void tp__taylor2(tp_ws *ws, const double *x, const double *d, uint32_t end);
/* The compiled Lagrange block of ws->cc at x: g[n_indep] and H (n_indep x
 * lcount), keeping the tangent rows to fwd1's invariant (forward.c). */
void tp__lagrange_compiled(tp_ws *ws, const double *x, double *g,
                           double *H);
/* The compiled Jacobian block of ws->cc at x: the values and tangent rows
 * of every output's cone in ws, as tp__fwd1 with unit directions on
 * every independent leaves them for the outputs (forward.c). */
void tp__jacobian_compiled(tp_ws *ws, const double *x);
/* The Lagrange block's sweeps with every row swept over its range alone
 * (ranges.c): unit directions on independents n .. 2n-1, n <= max_dirs,
 * for output ws->range_out, after tp__lagrange_ranges(ws, out, n, end). */
void tp__lagrange_ranges(tp_ws *ws, int out, int n, uint32_t end);
void tp__fwd1_ranged(tp_ws *ws, const double *x, int n, unsigned mask,
                     uint32_t end);
void tp__rev2_ranged(tp_ws *ws, const double *w, int n, unsigned mask,
                     uint32_t end, double *g, double *HS);
/* Their parts, for the same sweeps in strips of columns (strips.c):
 * tp__fwd1_ranged up to its loop over the ops (the seeds and leaves),
 * tp__rev2_ranged's seeding of the outputs w, and its end (g and HS out
 * of the independents' adjoints and rows, which it zeroes). */
void tp__fwd1_ranged_seed(tp_ws *ws, const double *x, int n, unsigned mask);
void tp__rev2_ranged_seed(tp_ws *ws, const double *w);
void tp__rev2_ranged_finish(tp_ws *ws, int n, double *g, double *HS);
/* Zero the adjoints seeded on outputs no sweep visits (reverse.c). */
void tp__clear_passive_seeds(tp_ws *ws);
/* Strips (strips.c): the width of a workspace of max_dirs directions (0:
 * it never sweeps in strips), whether tp_lagrange_t of n rates sweeps in
 * strips, and tp__fwd1_ranged then tp__rev2_ranged (output weights w, g
 * and HS as there), the same results bit for bit, with the rows swept in
 * strips of width columns (a multiple of 2 TP_LANES, at most
 * ws->strip_w). */
int tp__strip_width(int max_dirs);
bool tp__strips_pay(const tp_ws *ws, int n);
void tp__lagrange_strips(tp_ws *ws, const double *x, const double *w, int n,
                         unsigned mask, uint32_t end, int width, double *g,
                         double *HS);
/* Recompute the passive prefix of v if a parameter changed (forward.c). */
void tp__ensure_passive(tp_ws *ws);
/* The dependency mask of a seed (groups of independents it touches). */
unsigned tp__seed_mask(const tp_tape *t, int p, const double *S, size_t lds,
                       int first);
/* The same for unit directions on the independents first .. first+p-1
 * (S NULL), inline: tp_lagrange_t asks for it on every call. */
static inline unsigned tp__unit_seed_mask(const tp_tape *t, int p, int first)
{
    unsigned mask = 0;
    int k;
    for (k = first < 0 ? 0 : first; k < first + p && k < (int)t->n_indep;
         k++)
        mask |= 1u << t->group[k];
    return mask;
}

/* Reference interpreter (reference.c): the same results as the sweeps,
 * computed one direction at a time with the generic partials, no skipping
 * and no reuse of buffers. For tests of the fast paths. Each allocates with
 * malloc and returns 0 or TP_ERR_NOMEM. */
int tp__ref_eval(const tp_tape *t, const double *param, const double *x,
                 double *y);
int tp__ref_jvp(const tp_tape *t, const double *param, const double *x,
                const double *s, double *y, double *ys);
int tp__ref_vjp(const tp_tape *t, const double *param, const double *x,
                const double *w, double *g);
int tp__ref_hvp(const tp_tape *t, const double *param, const double *x,
                const double *w, const double *s, double *hs);

#endif /* TAPE_INTERNAL_H */
