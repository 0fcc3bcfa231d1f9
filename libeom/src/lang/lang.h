/* lang.h - internal structures of the model-file language (docs/models.md).
 *
 * A file goes through four stages, one file each:
 *   lexer.c    text -> tokens (with line, column and spacing)
 *   parser.c   tokens -> declarations, definitions and an expression pool
 *   resolve.c  names -> symbols, index variables bound, arities checked,
 *              nearest-name suggestions
 *   units.c    unit strings and the dimension of every expression
 * and then, per set of structural settings:
 *   build.c    the eom_model: coordinates, parameters and callbacks
 *   emit.c     an expression recorded onto the tape (tp_* calls), with
 *              definitions memoized per recording
 * diag.c formats every message as file:line:col, the line and a caret.
 *
 * The expression pool is only walked while recording: a replay of the
 * tapes never sees it.
 */
#ifndef EOM_LANG_H
#define EOM_LANG_H

#include <stddef.h>
#include <stdint.h>

#include "eom/eom.h"

/* Documented limits (docs/models.md, "Limits"). */
#define LANG_MAX_FILE (1L << 20)  /* bytes of a file */
#define LANG_MAX_NEST 200         /* nesting of parentheses and operators */
#define LANG_MAX_NAME 64          /* characters of a name */
#define LANG_MAX_IDX 4            /* indices of a family */
#define LANG_MAX_DEPTH 5000       /* definitions evaluated inside another */
#define LANG_MAX_COUNT 100000     /* coordinates, parameters, probes,
                                     constraints or forces of one model */
#define LANG_MAX_SETTING 100000   /* largest value of a setting */
#define LANG_BUDGET 20000000L     /* expression nodes walked per recording
                                     (no input makes the loader hang) */

/* ---- tokens ------------------------------------------------------------ */

typedef enum tok_kind {
    TK_EOF,
    TK_NL,
    TK_NUM,
    TK_ID,
    TK_STR,
    TK_PLUS,
    TK_MINUS,
    TK_STAR,
    TK_SLASH,
    TK_CARET,
    TK_LPAR,
    TK_RPAR,
    TK_LBRK,
    TK_RBRK,
    TK_COMMA,
    TK_ASSIGN,
    TK_DOTDOT,
    TK_EQ,
    TK_NE,
    TK_LT,
    TK_LE,
    TK_GT,
    TK_GE,
    TK_DOT /* '.' before a letter: a component, as in r.x or I.xy */
} tok_kind;

typedef struct token {
    uint8_t kind;
    uint8_t space_before; /* whitespace (or line start) right before it */
    int32_t line, col;    /* 1-based; col counts bytes */
    int32_t off, len;     /* in the source text */
    double num;           /* TK_NUM */
} token;

/* ---- expressions ------------------------------------------------------- */

typedef enum node_kind {
    N_NUM,   /* num */
    N_NAME,  /* a name, possibly indexed: kids = index expressions */
    N_NEG,   /* -a */
    N_BIN,   /* a op b (op: a tok_kind of + - * / ^ or a comparison) */
    N_CALL,  /* function op (a lang_fn), kids = arguments */
    N_SUM,   /* sum(var in a..b, body): kids = {a, b, body} */
    N_IF,    /* if(cond, a, b): kids = {cond, a, b} */
    N_COMP   /* a component of a vector or matrix: kids = {value}, op =
                the component (0..2 of a vector, 3*row+col of a matrix) */
} node_kind;

/* The shape of a value (shape.c): a scalar, a 3-vector or a 3x3 matrix
 * (row-major). SH_ANY: not known yet (a recurrence's own reference). */
enum { SH_SCALAR = 1, SH_VEC = 3, SH_MAT = 9, SH_ANY = 0 };

/* What a resolved name refers to. */
typedef enum ref_kind {
    R_NONE,
    R_SETTING,
    R_PARAM,
    R_COORD,
    R_RATE,
    R_DEF,
    R_IVAR, /* an index variable */
    R_PI,
    R_TIME,
    R_MULT /* lambda_NAME: constraint NAME's multiplier (probes only);
              node op = 1 + the component of a vector constraint
              (lambda_NAME_x), else 0 */
} ref_kind;

typedef struct node {
    uint8_t kind;
    uint8_t op;
    uint8_t ref;    /* ref_kind, for N_NAME */
    uint8_t nkids;
    uint8_t shape;  /* SH_*, set by shape.c */
    int32_t tok;    /* token that places it in the file */
    int32_t kids;   /* first index in prog.kids */
    int32_t sym;    /* N_NAME: symbol (or index variable) */
    int32_t var;    /* N_SUM: its index variable */
    double num;
} node;

/* Built-in functions (N_CALL op). */
typedef enum lang_fn {
    F_SQRT, F_EXP, F_LOG, F_SIN, F_COS, F_TAN, F_ASIN, F_ACOS, F_ATAN,
    F_SINH, F_COSH, F_TANH, F_ABS, F_SQR, F_ATAN2, F_HYPOT,
    /* vectors, matrices, rotations and time derivatives (vector.c,
     * tangent.c); not reserved names: a value may be called norm */
    F_VEC, F_MAT, F_DIAG, F_DOT, F_CROSS, F_NORM, F_TRANSPOSE, F_ROTX,
    F_ROTY, F_ROTZ, F_ROT, F_QUAT, F_DER, F_ANGVEL_BODY, F_ANGVEL_SPACE,
    F_COUNT
} lang_fn;
#define F_FIRST_SPATIAL F_VEC

typedef struct fn_info {
    const char *name;
    int arity; /* -1: mat(), which takes 9 scalars or 3 rows */
} fn_info;
extern const fn_info lang_fns[F_COUNT];

/* ---- dimensions -------------------------------------------------------- */

/* Exponents of kg, m, s, A, K, doubled (so sqrt of m^2 is exact). any:
 * a plain number, which takes the dimension of what it meets. */
#define DIM_N 5
typedef struct dim {
    int8_t e[DIM_N];
    uint8_t any;
} dim;

/* ---- declarations ------------------------------------------------------ */

/* One index of a family's declaration or of a definition clause: either
 * a range "var in lo..hi" or a fixed index expression "fixed". */
typedef struct binder {
    int32_t var;    /* index variable, or -1 for a fixed index */
    int32_t lo, hi; /* range nodes (var >= 0) */
    int32_t fixed;  /* node (var < 0) */
    int32_t tok;
} binder;

typedef enum sym_kind {
    S_SETTING,
    S_PARAM,
    S_COORD,
    S_DEF,
    S_PROBE,
    S_CONSTRAINT
} sym_kind;

/* A declared name. Settings, parameters, coordinates and definitions
 * share one namespace; probes and constraints have their own (they name
 * outputs and cannot be used in expressions). */
typedef struct sym {
    uint8_t kind;
    uint8_t nidx;          /* 0: a scalar; else a family */
    int32_t tok;           /* the name's token in its first declaration */
    char name[LANG_MAX_NAME + 1];
    binder idx[LANG_MAX_IDX]; /* families of params, coords, probes,
                                 constraints: their ranges */
    int32_t value;         /* default / initial value node (-1: 0) */
    int32_t rate;          /* coord: initial rate node (-1: 0) */
    int32_t unit_tok;      /* token of '[' of the unit, or -1 */
    char unit[64];         /* the unit as written ("" when none) */
    dim unit_dim;
    int32_t desc_tok;      /* TK_STR of the description, or -1 */
    int32_t lo, hi;        /* settings: allowed range */
    int32_t first_clause;  /* definitions: clauses in prog.clauses ... */
    int32_t nclauses;      /* ... in a chain through clause.next */
    int32_t last_clause;
    dim d;                 /* definitions: dimension (units.c) */
    uint8_t dim_state;     /* 0 not computed, 1 in progress, 2 done */
    uint8_t velocity;      /* constraints: on the rates (velocity
                              constraint NAME = ...) */
    uint8_t shape;         /* definitions, probes, constraints: SH_* */
    uint8_t shape_state;   /* 0 not computed, 1 in progress, 2 done */
    int32_t draw;          /* probes: 0, or 1 + the drawing (lang_draw)
                              this is an argument of: a value of the
                              drawing's tape, in no CSV */
    int32_t draw_tok;      /* a drawing's argument: its first token */
} sym;

/* A draw statement (draw.c): draw KIND NAME[binders] = ARG, ARG, ...
 * [color "C"] [trail]. Its arguments are the probes first_sym ..
 * first_sym + nargs - 1, with the statement's binders each; the first is
 * named NAME, the others '#' and numbers (no name a file can write). */
typedef struct lang_draw {
    int32_t tok;        /* 'draw' */
    int32_t kind_tok;   /* the kind's word */
    int32_t first_sym, nargs;
    int32_t color_tok;  /* TK_STR after 'color', or -1 */
    int32_t trail_tok;  /* 'trail', or -1 */
    int kind;           /* eom_draw_kind, set by lang_draws */
    unsigned rgb;       /* set by lang_draws */
} lang_draw;

/* One defining equation of a definition: NAME[binders] = body. */
typedef struct clause {
    int32_t sym;
    uint8_t nidx;
    int32_t body;
    int32_t tok;
    int32_t next;
    binder idx[LANG_MAX_IDX];
} clause;

/* T, V, L, R, a force or a probe/constraint body: an expression that
 * becomes an output. */
typedef enum stmt_kind { ST_T, ST_V, ST_L, ST_R, ST_FORCE } stmt_kind;

typedef struct energy_stmt {
    uint8_t kind;
    int32_t tok;
    int32_t body;
    /* forces: the coordinate it acts on, as a name node (maybe indexed)
     * and the binders that range over it */
    int32_t target;
    uint8_t nidx;
    binder idx[LANG_MAX_IDX];
} energy_stmt;

/* ---- the parsed program ------------------------------------------------ */

typedef struct lang_prog {
    int refs;             /* shared by the file handle and built models */
    char *path;           /* as given, for messages */
    char *text;           /* the source (NUL-terminated) */
    long text_len;
    token *toks;
    int ntoks;
    node *nodes;
    int nnodes, cap_nodes;
    int32_t *kids;
    int nkids, cap_kids;
    sym *syms;
    int nsyms, cap_syms;
    clause *clauses;
    int nclauses, cap_clauses;
    energy_stmt *stmts;
    int nstmts, cap_stmts;
    int nvars, cap_vars;  /* index variables */
    int32_t *var_tok;     /* [nvars] where each is bound */
    long budget;          /* LANG_BUDGET, or lower (lang_file_limits) */
    int max_count;        /* LANG_MAX_COUNT, or lower */
    lang_draw *draws;     /* draw statements (draw.c) */
    int ndraws, cap_draws;
    int units_off;        /* "units off" */
    int32_t units_off_tok;
} lang_prog;

/* A message about the file: "path:line:col: text", the source line and
 * a caret under col; hint (may be NULL) is added as a last line. Writes
 * at most len bytes to out. */
void lang_diag(const lang_prog *p, int tok, char *out, size_t len,
               const char *hint, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 6, 7)))
#endif
    ;
/* The same at a line and column (lexer errors, before tokens exist). */
void lang_diag_at(const lang_prog *p, int line, int col, char *out,
                  size_t len, const char *hint, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 7, 8)))
#endif
    ;

/* The text of token t as a NUL-terminated copy in buf (truncated). */
const char *lang_tok_text(const lang_prog *p, int t, char *buf, size_t len);

/* Edit distance of a and b, capped at cap + 1. */
int lang_edit_distance(const char *a, const char *b, int cap);

/* Stages; each returns 0, or -1 with a message in err. */
int lang_lex(lang_prog *p, char *err, size_t len);
int lang_parse(lang_prog *p, char *err, size_t len);
int lang_resolve(lang_prog *p, char *err, size_t len);
int lang_units(lang_prog *p, char *err, size_t len);
int lang_shapes(lang_prog *p, char *err, size_t len);
int lang_rates(lang_prog *p, char *err, size_t len);
/* draw.c: the kinds, arguments, shapes, units and colours of the draw
 * statements (after lang_units). */
int lang_draws(lang_prog *p, char *err, size_t len);
/* units.c: the dimension of node n (0, or -1 with a message in err). */
int lang_dim_of(lang_prog *p, int n, dim *out, char *err, size_t len);
/* "a scalar", "a vector", "a matrix" */
const char *lang_shape_name(int shape);

/* Units: parse a unit string (as written between brackets). Returns 0, or
 * -1 with the offending symbol copied to bad. */
int lang_unit_parse(const char *text, dim *d, char *bad, size_t badlen);
/* The dimension written in base units ("kg m^2 s^-2"; "1" when none). */
void lang_dim_format(dim d, char *buf, size_t len);
int lang_dim_equal(dim a, dim b);

/* Lower the limits of f (for the fuzzer, which must not spend its time
 * on legitimately large models): steps per recording and members of a
 * family, coordinates or parameters. */
struct eom_file;
void lang_file_limits(struct eom_file *f, long budget, int max_count);

/* Growable arrays. Return 0, or -1 when out of memory or beyond limit. */
int lang_grow(void **v, int *cap, int need, size_t elem, int limit);

void lang_prog_release(lang_prog *p);

/* A malloc'd copy of s (NULL when out of memory). */
char *lang_strdup(const char *s);
/* Copy src into dst (len bytes), truncated when it does not fit. */
void lang_copy(char *dst, size_t len, const char *src);

/* ---- one build: the model for fixed settings --------------------------- */

/* A value while recording: a constant known when the file is read (k =
 * 1, value c), or a value on the tape (v). */
typedef struct lval {
    double c;
    tp_val v;
    int k;
} lval;

/* A value and its total time derivative (konst 0 when not asked for). */
typedef struct ldual {
    lval v, d;
} ldual;

/* A value of any shape: n = 1, 3 or 9 components (a matrix row-major). */
typedef struct ldvec {
    int n;
    ldual x[9];
} ldvec;

typedef struct memo_entry {
    int32_t sym; /* -1: empty */
    int32_t idx[LANG_MAX_IDX];
    uint32_t epoch;
    uint8_t state;  /* 1 being evaluated, 2 done */
    uint8_t dstate; /* the same for the time derivative (der()) */
    lval val;       /* a scalar's value */
    int32_t vslot;  /* a vector's or matrix's components in inst->arena */
    int32_t dslot;  /* the time derivative's components in inst->arena */
} memo_entry;

/* What a declared family became: its index ranges and the model index of
 * its first member (coordinates, parameters). */
typedef struct family {
    int lo[LANG_MAX_IDX], cnt[LANG_MAX_IDX];
    int size;
    int first;
} family;

typedef struct lang_inst {
    lang_prog *p;           /* a reference (released with the inst) */
    double *setting;        /* [nsyms]: value of each setting symbol */
    family *fam;            /* [nsyms]: params, coords, probes, constraints */
    char **pname;           /* [nparams] generated parameter names */
    int nparams, ncoords;
    long *ival;             /* [nvars] index variables' values */
    uint8_t *ival_set;      /* [nvars] */
    memo_entry *memo;
    unsigned memo_mask, memo_used;
    uint32_t epoch;
    lval *arena;            /* components of memoized vectors and time
                               derivatives, this recording's only */
    int narena, cap_arena;
    double *pdefault;       /* [nparams] parameters' defaults, while the
                               coordinates' initial values are read (they
                               may use parameters), else NULL */
    int pdefault_on;        /* reading a coordinate's initial value */
    int quat_check;         /* the checks' run at the start (build.c):
                               each quat() outputs its squared length */
    int32_t *quat_tok;      /* [nquat] where each of those is written */
    int nquat, cap_quat;
    int init_params;        /* an initial value used a parameter: the
                               model records its initial state */
    lval *pmemo;            /* [nparams] parameter values this recording */
    uint32_t *pmemo_epoch;
    /* the recording in progress (r == NULL: constants only) */
    eom_ctx *ctx;
    tp_rec *r;
    int role;               /* an eom_role */
    const char *what;       /* "the kinetic energy T", for messages */
    long budget;
    int depth;
    int failed;
    char err[2048];
    /* callback arguments, owned here */
    struct lang_cb *cbs;
    int ncbs;
} lang_inst;

/* One step of a walk at token tok: counts it against the budget and the
 * depth (lang_eval and lang_eval_d undo the depth). 0, or -1 failed. */
int lang_enter(lang_inst *in, int tok);
/* Evaluate node n (in constants-only mode when inst->r is NULL). Returns
 * 0, or -1 with inst->failed set and the message in inst->err. */
int lang_eval(lang_inst *in, int n, lval *out);
/* Node n of any shape (tangent.c). With want_d, also its total time
 * derivative sum_i dv/dq_i qd_i + dv/dt, recorded as a forward tangent
 * of the recorded value (the rates are the coordinates' tangents, 1 the
 * time's); without, the derivatives are konst 0 and record nothing. */
int lang_eval_d(lang_inst *in, int n, ldvec *out, int want_d);
/* A name that is not a definition, with its derivative (emit.c). */
int lang_name_d(lang_inst *in, const struct node *nd, ldual *out,
                int want_d);
/* Arithmetic of two scalars with constants folded (emit.c): op is a
 * tok_kind of + - * / ^; tok places an error. */
int lang_arith(lang_inst *in, int op, int tok, lval a, lval b, lval *out);
/* A scalar function of one or two scalars (F_SQRT .. F_HYPOT). */
int lang_func(lang_inst *in, int fn, lval a, lval b, lval *out);
/* The same on values with derivatives (tangent.c): the chain rule, with
 * nothing recorded for a derivative that is konst 0. */
int lang_darith(lang_inst *in, int op, int tok, ldual a, ldual b,
                ldual *out);
int lang_dfunc(lang_inst *in, int fn, int tok, ldual a, ldual b,
               ldual *out);
/* Functions of vectors and matrices on evaluated arguments (vector.c):
 * args[k] is argument k; out gets the node's shape. */
int lang_spatial(lang_inst *in, const struct node *nd, const ldvec *args,
                 ldvec *out);
/* Products and sums of values of any shape (vector.c), by shape. */
int lang_vbinary(lang_inst *in, int op, int tok, const ldvec *a,
                 const ldvec *b, ldvec *out);
/* A definition's value (sout for a scalar without want_d, else vout),
 * memoized per recording and index; its derivative is memoized apart. */
int lang_def_ref(lang_inst *in, const struct node *nd, lval *sout,
                 ldvec *vout, int want_d);
/* Room for n components in inst->arena: the offset, or -1. */
int lang_arena(lang_inst *in, int n);
/* A constant, integral value of node n (an index, a range end). */
int lang_eval_int(lang_inst *in, int n, const char *what, long *out);
/* v on the tape (a constant becomes tp_const). */
tp_val lang_tape(lang_inst *in, lval v);
/* Start a recording on ctx (NULL: constants only): clears the memo. */
void lang_begin(lang_inst *in, eom_ctx *ctx, int role, const char *what);
/* The flat index of a family member from its index values, or -1 with a
 * message at tok. */
int lang_family_index(lang_inst *in, int sym, const long *idx, int tok);
/* build.c: bind the index variables of family s to its member flat (the
 * index values into idx), unbind them, and a member's name (theta3). */
void lang_bind_member(lang_inst *in, int s, int flat, long *idx);
void lang_unbind(lang_inst *in, int s);
void lang_member_name(const sym *y, const long *idx, char *buf, size_t len);
/* draw.c: a drawing per member of each draw statement, added to m. */
int lang_draw_callbacks(lang_inst *in, eom_model *m);
void lang_fail(lang_inst *in, int tok, const char *hint, const char *fmt,
               ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

#endif /* EOM_LANG_H */
