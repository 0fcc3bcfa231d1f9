/* tape.h - public API of libtape, the operation-tape automatic differentiation
 * engine.
 *
 * A user writes a function of n independent variables as ordinary C code
 * against the recording API below (one handle type, tp_val, for every value).
 * The same function runs unchanged against three backends:
 *
 *   - the recorder, which writes an operation tape once; the finished tape is
 *     then replayed by sweeps for values, first and second derivatives;
 *   - the plain double evaluator, which just computes the values;
 *   - the embedded-tuple evaluator, which carries (value, gradient, packed
 *     Hessian) over all independents through every operation.
 *
 * Conventions
 *   - Status codes: 0 success, > 0 a warning with valid output (for example
 *     TP_WARN_NONFINITE: some requested result is NaN or infinite), < 0 an
 *     error with nothing written. tp_strerror() describes each code and each
 *     handle keeps a detailed message of its last error.
 *   - Constructors write through T **out and return a status; destructors
 *     take T ** and set it to NULL; both accept NULL.
 *   - Matrices are dense, row-major, with the leading dimension stated.
 *   - A finished tape is immutable and may be shared by threads; everything a
 *     sweep writes lives in a tp_ws workspace, one per thread. Sweeps do not
 *     allocate.
 *   - The library never aborts and keeps no process-wide state.
 */
#ifndef TAPE_TAPE_H
#define TAPE_TAPE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#if defined(_WIN32)
#define TP_API
#elif defined(__GNUC__)
#define TP_API __attribute__((visibility("default")))
#else
#define TP_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- status codes ----------------------------------------------------- */

/* X(name, value, description): one list generates the enum, tp_strerror()
 * and tp_status_name(), and the error table in docs/. */
#define TP_STATUS_LIST(X)                                                      \
    X(TP_OK, 0, "success")                                                     \
    X(TP_WARN_NONFINITE, 1,                                                    \
      "a result is NaN or infinite (domain error such as log of a negative, "  \
      "division by zero, or a non-finite input)")                              \
    X(TP_ERR_NULL, -1, "a required pointer argument is NULL")                  \
    X(TP_ERR_NOMEM, -2, "out of memory")                                       \
    X(TP_ERR_SIZE, -3, "a size or index is out of range")                      \
    X(TP_ERR_FOREIGN, -4, "a value handle belongs to another recording")       \
    X(TP_ERR_FINISHED, -5, "the recording is already finished")                \
    X(TP_ERR_HANDLE, -6, "a value handle is invalid (uninitialized, or the "   \
                         "result of an earlier failed operation)")             \
    X(TP_ERR_NAME, -7, "a name is unknown, empty, or declared twice")          \
    X(TP_ERR_BACKEND, -8, "the operation is not available on this backend")    \
    X(TP_ERR_USER, -9, "a user callback returned an error")                    \
    X(TP_ERR_TOOBIG, -10, "the tape or a buffer would exceed its size limit")  \
    X(TP_ERR_EMPTY, -11, "nothing to do: the recording has no outputs, or "    \
                         "no result is available yet")                         \
    X(TP_ERR_COMPILE, -12, "the tape could not be compiled to machine code "   \
                           "(no C compiler, a compiler error, or a check "     \
                           "against the interpreter failed)")

typedef enum tp_status {
#define TP_STATUS_ENUM_(name, value, text) name = value,
    TP_STATUS_LIST(TP_STATUS_ENUM_)
#undef TP_STATUS_ENUM_
} tp_status;

/* A static description of a status code ("unknown status" for others). */
TP_API const char *tp_strerror(int status);
/* The enum name of a status code, such as "TP_ERR_NOMEM". */
TP_API const char *tp_status_name(int status);

/* ---- allocation hook -------------------------------------------------- */

/* One function does all allocation, told the old size (Lua's convention):
 * new_size == 0 frees ptr and returns NULL; otherwise behaves like realloc
 * and returns NULL on failure, leaving ptr untouched. ud is passed through.
 * Every constructor takes a const tp_allocator * (NULL: the C library's). */
typedef struct tp_allocator {
    void *(*fn)(void *ud, void *ptr, size_t old_size, size_t new_size);
    void *ud;
} tp_allocator;

/* ---- recording contexts ----------------------------------------------- */

/* A recording context: the recorder, the double evaluator or the tuple
 * evaluator. The recording API below is the same for all three. */
typedef struct tp_rec tp_rec;

/* A value handle, valid only inside the context that made it. Pass it by
 * value; never build one by hand. A failed operation returns an invalid
 * handle and puts its context into a sticky error state, so a sequence of
 * operations may be written without checking each result: the first error
 * is reported by tp_rec_status() and by the call that ends the run. */
typedef struct tp_val {
    uint32_t id;  /* index in the context */
    uint32_t tag; /* identifies the context; 0 in an invalid handle */
} tp_val;

/* The user's function: records outputs from independents and parameters.
 * Returns 0 on success; any other value stops the run with TP_ERR_USER. */
typedef int (*tp_func)(tp_rec *r, void *user);

/* Create a recorder for a function of n_indep independent variables.
 * group[i] in 0..5 assigns independent i to a dependency group (NULL: all in
 * group 0). Sweeps use the groups to skip derivative work that is
 * structurally zero: for a Lagrangian, put q in group 0 and qd in group 1. */
TP_API int tp_recorder_new(tp_rec **out, int n_indep,
                           const unsigned char *group,
                           const tp_allocator *al);

/* Create the plain double evaluator for n_indep independents. */
TP_API int tp_evaluator_new(tp_rec **out, int n_indep,
                            const tp_allocator *al);

/* Create the embedded-tuple evaluator for n_indep independents: every value
 * carries its gradient and packed Hessian over all n_indep independents.
 * From one run to the next it reuses the storage of values the previous
 * run no longer read, so a function that records the same operations at
 * every run needs only the tuples alive at once. A run whose function
 * takes another path and reads a value that storage was given to is made
 * again from the start, without reuse: f is then called twice in that
 * tp_rec_run (its results are those of a single run). */
TP_API int tp_tuple_new(tp_rec **out, int n_indep, const tp_allocator *al);

/* Free any context; *r is set to NULL. Handles it made become invalid. */
TP_API void tp_rec_free(tp_rec **r);

/* Run f once on r. For the recorder, x may be NULL (values are not needed
 * to record) and the run appends to the recording. For the evaluators, x
 * holds n_indep values; each run starts afresh (outputs and intermediate
 * values of the previous run are discarded, buffers are kept; the tuple
 * evaluator may call f a second time, see tp_tuple_new). Returns the
 * first error of the run, or TP_ERR_USER if f returned non-zero. */
TP_API int tp_rec_run(tp_rec *r, const double *x, tp_func f, void *user);

/* Override the value a parameter takes in the evaluators (the recorder keeps
 * the default given at recording, which a workspace may change). */
TP_API int tp_rec_set_param(tp_rec *r, const char *name, double value);

/* The sticky status of r (TP_OK while no error happened), and a message
 * describing the first error ("" if none). The message is owned by r. */
TP_API int tp_rec_status(const tp_rec *r);
TP_API const char *tp_rec_errmsg(const tp_rec *r);

/* Number of independents of r. */
TP_API int tp_rec_n_indep(const tp_rec *r);

/* Results of an evaluator run, by output index (order of tp_output calls)
 * or name. tp_rec_output_index returns -1 for an unknown name. */
TP_API int tp_rec_n_outputs(const tp_rec *r);
TP_API int tp_rec_output_index(const tp_rec *r, const char *name);
TP_API int tp_rec_output_value(const tp_rec *r, int out, double *value);

/* Tuple evaluator only: gradient (n_indep) and packed Hessian of output
 * out. The packed Hessian holds the lower triangle row by row: entry (i, j)
 * with i >= j is at i * (i + 1) / 2 + j; n_indep (n_indep + 1) / 2 values.
 * Either pointer may be NULL. */
TP_API int tp_tuple_output(const tp_rec *r, int out, double *grad,
                           double *hess_packed);

/* ---- recording API (all backends) ------------------------------------- */

/* Independent variable i, 0 <= i < n_indep. */
TP_API tp_val tp_indep(tp_rec *r, int i);
/* A named parameter with a default value: a value that may change between
 * replays without re-recording (a mass, a stiffness). Declaring the same
 * name again returns the same value; a different default is an error. */
TP_API tp_val tp_param(tp_rec *r, const char *name, double dflt);
/* A constant. */
TP_API tp_val tp_const(tp_rec *r, double c);
/* Declare v as the output called name (names are unique in a run).
 * Returns a status; errors are also sticky. */
TP_API int tp_output(tp_rec *r, const char *name, tp_val v);

TP_API tp_val tp_add(tp_rec *r, tp_val a, tp_val b);   /* a + b */
TP_API tp_val tp_sub(tp_rec *r, tp_val a, tp_val b);   /* a - b */
TP_API tp_val tp_mul(tp_rec *r, tp_val a, tp_val b);   /* a * b */
TP_API tp_val tp_div(tp_rec *r, tp_val a, tp_val b);   /* a / b */
TP_API tp_val tp_pow(tp_rec *r, tp_val a, tp_val b);   /* a ^ b, a > 0 */
TP_API tp_val tp_atan2(tp_rec *r, tp_val y, tp_val x); /* angle of (x, y) */
TP_API tp_val tp_hypot(tp_rec *r, tp_val a, tp_val b); /* sqrt(a^2+b^2) */

TP_API tp_val tp_neg(tp_rec *r, tp_val a);
TP_API tp_val tp_sqr(tp_rec *r, tp_val a);
TP_API tp_val tp_sqrt(tp_rec *r, tp_val a);
TP_API tp_val tp_exp(tp_rec *r, tp_val a);
TP_API tp_val tp_log(tp_rec *r, tp_val a);
TP_API tp_val tp_sin(tp_rec *r, tp_val a);
TP_API tp_val tp_cos(tp_rec *r, tp_val a);
TP_API tp_val tp_tan(tp_rec *r, tp_val a);
TP_API tp_val tp_asin(tp_rec *r, tp_val a);
TP_API tp_val tp_acos(tp_rec *r, tp_val a);
TP_API tp_val tp_atan(tp_rec *r, tp_val a);
TP_API tp_val tp_sinh(tp_rec *r, tp_val a);
TP_API tp_val tp_cosh(tp_rec *r, tp_val a);
TP_API tp_val tp_tanh(tp_rec *r, tp_val a);
/* |a|; its derivative is taken as sign(a), 0 at a == 0. */
TP_API tp_val tp_abs(tp_rec *r, tp_val a);

/* Constant operands. One naming rule: a trailing c (tp_addc) means the
 * constant is the right operand and comes last, a leading c (tp_csub)
 * means it is the left operand and comes first; the arguments are in the
 * order of the operands. */
TP_API tp_val tp_powi(tp_rec *r, tp_val a, int k);      /* a ^ k */
TP_API tp_val tp_powc(tp_rec *r, tp_val a, double c);   /* a ^ c */
TP_API tp_val tp_addc(tp_rec *r, tp_val a, double c);   /* a + c */
TP_API tp_val tp_subc(tp_rec *r, tp_val a, double c);   /* a - c */
TP_API tp_val tp_mulc(tp_rec *r, tp_val a, double c);   /* a * c */
TP_API tp_val tp_divc(tp_rec *r, tp_val a, double c);   /* a / c */
TP_API tp_val tp_csub(tp_rec *r, double c, tp_val a);   /* c - a */
TP_API tp_val tp_cdiv(tp_rec *r, double c, tp_val a);   /* c / a */

/* sum of n values (0 for n == 0) and dot product of two arrays of n. */
TP_API tp_val tp_sum(tp_rec *r, int n, const tp_val *a);
TP_API tp_val tp_dot(tp_rec *r, int n, const tp_val *a, const tp_val *b);

/* ---- the tape --------------------------------------------------------- */

typedef struct tp_tape tp_tape;

/* Finish the recording and build the tape: dead-code elimination, constant
 * pool compaction and dependency analysis (constant folding and common
 * subexpression elimination happen while recording). On success *out owns
 * a new tape and r is finished: recording into it afterwards is an error
 * (TP_ERR_FINISHED); free it with tp_rec_free. */
TP_API int tp_recorder_finish(tp_rec *r, tp_tape **out);

TP_API void tp_tape_free(tp_tape **t);

TP_API int tp_tape_n_indep(const tp_tape *t);
TP_API int tp_tape_n_outputs(const tp_tape *t);
TP_API int tp_tape_n_params(const tp_tape *t);
/* Index of a named output or parameter, or -1. */
TP_API int tp_tape_output_index(const tp_tape *t, const char *name);
TP_API int tp_tape_param_index(const tp_tape *t, const char *name);
/* Names and defaults by index (NULL / NaN when out of range). */
TP_API const char *tp_tape_output_name(const tp_tape *t, int out);
TP_API const char *tp_tape_param_name(const tp_tape *t, int k);
TP_API double tp_tape_param_default(const tp_tape *t, int k);

/* Size and shape of a tape, and what finalization did. */
typedef struct tp_tape_stats {
    size_t n_ops;       /* operations, leaves (independents, parameters and
                           constants) included */
    size_t n_consts;    /* entries of the constant pool */
    size_t bytes;       /* tape storage: op stream, operands, pool */
    size_t n_passive;   /* ops that depend on no independent */
    size_t n_recorded;  /* ops appended while recording */
    size_t n_cse_hits;  /* ops found already on the tape (hash-consing) */
    size_t n_folded;    /* ops folded to constants or simplified away */
    size_t n_dead;      /* ops removed by dead-code elimination */
} tp_tape_stats;
TP_API int tp_tape_stats_get(const tp_tape *t, tp_tape_stats *st);

/* 1 if a and b are the same tape op for op (opcodes, operands, constant
 * pool, parameters, outputs and groups), else 0; *first_diff (may be
 * NULL) receives the index of the first op that differs (the length of
 * the shorter when one is a prefix of the other). */
TP_API int tp_tape_equal(const tp_tape *a, const tp_tape *b,
                         size_t *first_diff);

/* Number of ops that depend on the independents of the groups in mask
 * (bit g for group g); with mask 0, the number of passive ops. */
TP_API size_t tp_tape_count_dependent(const tp_tape *t, unsigned mask);

/* The structural pattern of the Jacobian of t's outputs with respect to
 * independents first .. first+count-1: entry (o, j) is in it when output
 * o depends on independent first + j through some chain of ops (forward
 * propagation of index sets), whatever the values of the independents
 * and parameters. A superset of the entries that are nonzero at any
 * point, never a subset: a partial that vanishes at some point, or
 * everywhere, is still counted. Compressed rows: row o's columns
 * (relative to first, ascending) are cols[rowptr[o] .. rowptr[o+1]-1].
 * rowptr (n_out + 1 entries) is always written; rowptr[n_out] is the
 * number of entries. cols may be NULL (count only: call again with cols
 * of that many entries); cap is the number of entries cols holds.
 * Returns TP_OK; TP_ERR_NULL (t or rowptr NULL); TP_ERR_SIZE (the range
 * leaves the independents, or cap is too small: rowptr is then valid);
 * TP_ERR_NOMEM (scratch of one word per op from the tape's allocator).
 * Costs one pass over the tape per 64 columns. */
TP_API int tp_tape_jacobian_pattern(const tp_tape *t, int first, int count,
                                    size_t *rowptr, int *cols, size_t cap);

/* ---- workspaces and sweeps -------------------------------------------- */

/* Replay buffers for one thread. max_dirs >= 1 is the largest number of
 * directions a single sweep carries; calls asking for more are split into
 * chunks of max_dirs. The workspace keeps a pointer to t, which must
 * outlive it. Parameters start at their defaults. */
typedef struct tp_ws tp_ws;
TP_API int tp_ws_new(tp_ws **out, const tp_tape *t, int max_dirs,
                     const tp_allocator *al);
/* The bytes tp_ws_new(t, max_dirs) would allocate (SIZE_MAX when that
 * overflows, 0 for a NULL t or max_dirs < 1): for a caller that refuses,
 * before allocating, a workspace larger than the machine's memory. */
TP_API size_t tp_ws_bytes(const tp_tape *t, int max_dirs);
TP_API void tp_ws_free(tp_ws **ws);
TP_API const char *tp_ws_errmsg(const tp_ws *ws);

/* Parameter values used by this workspace's replays. */
TP_API int tp_ws_set_param(tp_ws *ws, int k, double value);
TP_API int tp_ws_get_param(const tp_ws *ws, int k, double *value);

/* All sweeps take x (n_indep values) and check every requested result:
 * TP_WARN_NONFINITE when one is NaN or infinite. n = n_indep, m = n_out. */

/* Zero-order forward: y[m] = outputs at x. */
TP_API int tp_eval(tp_ws *ws, const double *x, double *y);

/* First-order forward with p directions: y[m] (may be NULL) and
 * JS = J S (m x p), where S is n x p (row-major, leading dimension p). */
TP_API int tp_jvp(tp_ws *ws, const double *x, int p, const double *S,
                  double *y, double *JS);

/* Forward Jacobian with respect to independents first .. first+count-1:
 * J (m x count). */
TP_API int tp_jacobian(tp_ws *ws, const double *x, int first, int count,
                       double *y, double *J);

/* Reverse: g[n] = w^T J for output weights w[m]; y[m] may be NULL. */
TP_API int tp_vjp(tp_ws *ws, const double *x, const double *w, double *y,
                  double *g);

/* Reverse: gradient g[n] of output out; *y its value (y may be NULL). */
TP_API int tp_gradient(tp_ws *ws, const double *x, int out, double *y,
                       double *g);

/* Forward-over-reverse with p directions: with f = w^T y, g[n] = grad f and
 * HS = (d2f/dx2) S, n x p. g may be NULL. */
TP_API int tp_hvp(tp_ws *ws, const double *x, const double *w, int p,
                  const double *S, double *g, double *HS);

/* Columns first .. first+count-1 of the Hessian of output out:
 * H (n x count); g[n] may be NULL. */
TP_API int tp_hessian_cols(tp_ws *ws, const double *x, int out, int first,
                           int count, double *g, double *H);

/* Full Hessian of output out, H (n x n). */
TP_API int tp_hessian(tp_ws *ws, const double *x, int out, double *H);

/* Univariate second-order Taylor: for x(s) = x + s d, y[m] = outputs,
 * y1 = dy/ds and y2 = d2y/ds2 at s = 0 (each m; y and y1 may be NULL). */
TP_API int tp_taylor2(tp_ws *ws, const double *x, const double *d, double *y,
                      double *y1, double *y2);

/* What Lagrange's equations need, for a tape whose 2n independents are
 * x = (q, qd) and whose output out is L: the value *L, dLdq[n], the mass
 * matrix M = d2L/dqd2 (n x n) and h = (d2L/dqd dq) qd [n]. One forward
 * sweep and one reverse sweep carrying n directions seeded on qd (chunked
 * if max_dirs < n). Any of L, dLdq, M, h may be NULL; none may overlap
 * x or another. A tape of 2n + 1 independents is read as in
 * tp_lagrange_t. */
TP_API int tp_lagrange(tp_ws *ws, const double *x, int out, double *L,
                       double *dLdq, double *M, double *h);

/* The same for a Lagrangian that depends on the time explicitly: a tape
 * of 2n + 1 independents x = (q, qd, t), the time last. Then
 * h = (d2L/dqd dq) qd + d2L/dqd dt, the part of d/dt (dL/dqd) that does
 * not involve the accelerations, and *dLdt = dL/dt at fixed (q, qd). The
 * same two sweeps as tp_lagrange: the time is not a direction. For a
 * tape of 2n independents this is tp_lagrange with *dLdt = 0. dLdt may
 * be NULL. */
TP_API int tp_lagrange_t(tp_ws *ws, const double *x, int out, double *L,
                         double *dLdq, double *dLdt, double *M, double *h);

/* The same blocks from an evaluated tuple context (for comparison). */
TP_API int tp_tuple_lagrange(const tp_rec *r, int out, double *L,
                             double *dLdq, double *M, double *h);

/* ---- a tape called from a recording (derivative tapes) ---------------- */

/* Record, inside a run of r (any backend), what the finished tape t
 * computes, as if its user function were called there: x[n_indep] are
 * values of r standing for t's independents; par[n_param] those for its
 * parameters, or NULL to declare t's parameters in r by name with their
 * defaults (tp_param), so that they stay parameters of a tape recorded by
 * r. y[n_out] receives t's outputs. The same call on the evaluators
 * computes the values directly.
 *
 * tp_call_jvp also records the directional derivative dy = J dx + Jp dpar
 * for a direction given as values dx[n_indep] and dpar[n_param] (either
 * may be NULL: zero); y may be NULL.
 *
 * tp_call_vjp also records the reverse sweep: gx[n_indep] = w^T J and
 * gpar[n_param] = w^T dy/dpar for output weights w[n_out] (values of r);
 * y, and one of gx and gpar, may be NULL.
 *
 * Recorded by the recorder, these are derivative tapes: the gradient of a
 * Lagrangian as a tape of its own, whose sweeps give third derivatives.
 * Each op of t adds a bounded number of ops (derivatives known to be zero
 * are not recorded), so a derivative tape grows linearly with t. The
 * derivative of |u| is recorded as u / |u| (NaN at u = 0, where the
 * sweeps take 0). Errors are r's sticky errors; the return value is r's
 * status after the call. */
TP_API int tp_call(tp_rec *r, const tp_tape *t, const tp_val *x,
                   const tp_val *par, tp_val *y);
TP_API int tp_call_jvp(tp_rec *r, const tp_tape *t, const tp_val *x,
                       const tp_val *par, const tp_val *dx,
                       const tp_val *dpar, tp_val *y, tp_val *dy);
TP_API int tp_call_vjp(tp_rec *r, const tp_tape *t, const tp_val *x,
                       const tp_val *par, const tp_val *w, tp_val *y,
                       tp_val *gx, tp_val *gpar);

/* ---- compiled tapes ---------------------------------------------------- */

/* A tape as machine code: emitted as C, built by the system's C compiler
 * into a shared object, kept in a per-user cache and loaded. A workspace
 * given one runs its value sweeps (tp_eval, and the forward part of the
 * other calls), its gradient sweeps (tp_vjp, tp_gradient) and, if it was
 * compiled, the Lagrange block (tp_lagrange, tp_lagrange_t) through it;
 * the sweeps over many directions (tp_jvp, tp_jacobian, tp_hvp,
 * tp_hessian_cols) and tp_taylor2 stay interpreted. The results are the
 * interpreter's: the per-op arithmetic is the same text, compiled without
 * contraction of multiply-adds, and every object is compared with the
 * interpreter at one state when it is loaded (docs/libtape.md, "Compiled
 * tapes"). Immutable once made: workspaces of any thread may share one.
 * Free it after the workspaces that use it, and before its tape. */
typedef struct tp_compiled tp_compiled;

typedef struct tp_compile_opts {
    /* The compiler command, words separated by blanks (NULL or "": the
     * environment's CC, else "cc"). */
    const char *cc;
    /* Its flags (NULL: the environment's AUTOEOM_CFLAGS, else "-O1", and
     * for a tape of 500 ops or more "-O1 -fno-dse -fno-tree-dse"); -fPIC
     * -shared -ffp-contract=off are always added. Flags that change
     * rounding (-ffast-math) fail the check. */
    const char *cflags;
    /* The cache (NULL: $AUTOEOM_CACHE_DIR, else $XDG_CACHE_HOME/autoeom,
     * else $HOME/.cache/autoeom); created with mode 0700. */
    const char *cache_dir;
    /* The state [n_indep] at which the loaded object is checked against
     * the interpreter (NULL: a fixed point with entries in 0.3 .. 0.85).
     * Give a state inside the model's domain. */
    const double *x;
    /* The max_dirs of the workspaces that will use it (0: any). The
     * Lagrange block needs it (its rows then have a fixed width); a
     * compiled tape made with it serves only workspaces of that max_dirs
     * (tp_ws_set_compiled checks). */
    int max_dirs;
    /* 1: also compile the Lagrange block of output lagrange_out, which
     * tp_lagrange and tp_lagrange_t then run in one call: the tape's
     * independents must be (q, qd) or (q, qd, t) with the rates a
     * dependency group of their own, and max_dirs >= n (TP_ERR_SIZE
     * otherwise). */
    int lagrange;
    int lagrange_out;
    /* Which sweeps to compile, an or of TP_SWEEP_VALUES (every sweep of
     * values alone: tp_eval and the first half of tp_gradient),
     * TP_SWEEP_GRADIENTS (the reverse sweep of tp_gradient and tp_vjp),
     * TP_SWEEP_LAGRANGE (the Lagrange block, as lagrange = 1),
     * TP_SWEEP_JACOBIAN (tp_jacobian over all the independents, first 0
     * and count n_indep; needs max_dirs >= n_indep) and TP_SWEEP_TAYLOR2
     * (tp_taylor2); 0 (the default): values and gradients, and the
     * Lagrange block if lagrange is set. The sweeps left out stay on the
     * interpreter. Each costs
     * compile time (for a 50-link chain's Lagrangian, the values and
     * gradients were 40 % of it), so compile only what is called often:
     * a tape whose gradient is never taken needs TP_SWEEP_VALUES, one
     * used through tp_lagrange only TP_SWEEP_LAGRANGE. */
    unsigned sweeps;
    /* How many compilers may build the tape at once (0: the processors
     * online, at most 8). A large tape is built in parts side by side,
     * about one for every 500 statements of its source, and linked; 1:
     * in one piece. */
    int jobs;
    /* 1: write every sweep straight-line, one statement per op, as
     * libtape did before repeated runs became loops (for comparison: the
     * source grows with the tape; also set by the environment's
     * AUTOEOM_CODEGEN=straight). 0 (the default): runs of statements that
     * repeat with shifted slots (a chain's links) are written once, as
     * loops. Both give the same results bit for bit. */
    int straight;
} tp_compile_opts;
#define TP_SWEEP_VALUES 1u
#define TP_SWEEP_GRADIENTS 2u
#define TP_SWEEP_LAGRANGE 4u
#define TP_SWEEP_JACOBIAN 8u
#define TP_SWEEP_TAYLOR2 16u

typedef struct tp_compile_info {
    int cached;   /* 1: loaded from the cache, nothing was compiled */
    int rebuilt;  /* 1: a cache entry failed its checks and was rebuilt */
    double t_emit, t_compile, t_load, t_check; /* seconds */
    size_t source_bytes; /* size of the generated C source */
    int parts;    /* compilers that built it side by side (0: not built) */
    char path[1024];     /* the shared object */
    char msg[512];       /* why it failed, or what was rebuilt and why */
} tp_compile_info;

/* Compile t (or load it from the cache). On success *out is the compiled
 * tape and info (may be NULL) says how it was obtained; on failure *out
 * is NULL, the status is TP_ERR_COMPILE (or TP_ERR_NOMEM, TP_ERR_NULL,
 * TP_ERR_SIZE) and
 * info->msg says why: the tape still runs on the interpreter. Never
 * terminates the caller: the compiler runs as a child process. The
 * compiler's messages of a failed build stay in the cache as NAME.log;
 * the generated source of each entry as NAME.c. */
TP_API int tp_compile(const tp_tape *t, const tp_compile_opts *o,
                      tp_compiled **out, tp_compile_info *info);
TP_API void tp_compiled_free(tp_compiled **c);
/* Run ws's sweeps through c (NULL: back to the interpreter). c must have
 * been made from ws's tape (TP_ERR_FOREIGN otherwise) and for its
 * max_dirs, if with one (TP_ERR_SIZE otherwise). */
TP_API int tp_ws_set_compiled(tp_ws *ws, const tp_compiled *c);
/* 1 if ws runs compiled code, else 0. */
TP_API int tp_ws_compiled(const tp_ws *ws);
/* Write the C source that tp_compile builds for t (without its cache
 * key) to out. */
TP_API int tp_tape_emit_c(const tp_tape *t, FILE *out);

#ifdef __cplusplus
}
#endif
#endif /* TAPE_TAPE_H */
