/* eom_internal.h - structures and internal prototypes of libeom. Not
 * installed; white-box tests may include it.
 *
 * A system owns one tape per purpose, each with its own workspace, so an
 * evaluation replays only what it needs:
 *   L tape     x = (q, qd), groups q = 0, qd = 1; output "L" (T - V, or
 *              the user's L). Lagrange blocks, energy.
 *   E tape     x = (q, qd); outputs "T", "V" (when given separately) and
 *              one per probe. Only for reporting.
 *   R tape     x = (q, qd); output "R". dR/dqd by a reverse sweep.
 *   Q tape     (q, qd, t), groups 0, 1, 2; n outputs. Zero-order sweep.
 *   phi tape   q; mh outputs. C by a forward Jacobian, gamma by one
 *              second-order Taylor sweep along qd.
 *   psi tape   (q, qd), groups 0, 1; mv outputs, the velocity
 *              constraints A(q) qd + b(q), each linear in qd (checked
 *              when the system is built). A = dpsi/dqd and b = psi at
 *              qd = 0 by one forward Jacobian; psi and dpsi/ds along
 *              (qd, 0) by one tangent sweep (constraints.c).
 *
 * The constraint rows of a system are the mh holonomic rows of the phi
 * tape followed by the mv velocity rows of the psi tape, m = mh + mv in
 * all: C (m x n) is [dphi/dq; A], and every array of the range-space
 * solve has the m rows. A velocity row has no position residual: its
 * phi entry is 0, its phit entry is b (so that C qd + phit is psi, the
 * velocity residual of every row), and its curvature entry is
 * dpsi/ds (gamma = -dpsi/ds).
 *
 * Explicit time (rheonomic models, rheonomic.c). A tape whose callbacks
 * never call eom_time is recorded exactly as above. Otherwise the time
 * takes the place its derivatives need: on the L and phi tapes it is one
 * more independent, last, in group 2 (x = (q, qd, t) and (q, t)), since
 * the equations need d2L/dqd dt, dL/dt, dphi/dt and d2phi/dt2 (and on
 * the psi tape, x = (q, qd, t), for dpsi/dt); on the E
 * and R tapes, which are only evaluated or differentiated in (q, qd), it
 * is a parameter named EOM_TIME_NAME, set before each sweep.
 */
#ifndef EOM_INTERNAL_H
#define EOM_INTERNAL_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <suitesparse/klu.h>

#include "cholesky_blocked.h"
#include "eom/eom.h"

/* room for a sentence that names constraint rows (eom_constraint_rank) */
#define EOM_MSG_LEN 1024
/* The tape parameter that carries the time on the E and R tapes (and,
 * while it is first recorded, on the L and phi tapes): not a C
 * identifier, so no model parameter can take its name. */
#define EOM_TIME_NAME "(time)"
/* The E tape's parameter of constraint row j's multiplier: "(lambda j)"
 * (not an identifier, so no model parameter can take it). */
#define EOM_LAMBDA_FMT "(lambda %d)"

/* ---- model ------------------------------------------------------------ */

typedef struct eom_named {
    char *name;
    char *unit;
    char *description;
    double v0, v1; /* coordinate: q0, qd0; parameter: default */
    eom_scalar_fn fn; /* probes */
    void *user;
} eom_named;

typedef struct eom_callback {
    union {
        eom_scalar_fn scalar;
        eom_vector_fn vector;
    } fn;
    void *user;
    int count;  /* vector callbacks: number of values */
    char **names; /* constraint blocks: count row names (an entry NULL:
                     unnamed), or NULL (eom_model_name_constraints) */
    bool set;
} eom_callback;

/* The contributions of one kind, summed (energies) or stacked
 * (constraint blocks). */
typedef struct eom_cblist {
    eom_callback *v;
    int n, cap;
} eom_cblist;

typedef struct eom_attached {
    void *data;
    void (*free_fn)(void *);
} eom_attached;

/* One name of a model in its hash index: which list holds it and where
 * (name NULL: an empty slot). */
typedef struct eom_name_slot {
    const char *name; /* the entry's own copy */
    int list;         /* 0 coordinates, 1 parameters, 2 probes */
    int index;
} eom_name_slot;

/* A drawing (drawing.c, eom/drawing.h): in a model with its callback,
 * in a system a copy without it. */
typedef struct eom_drawing_def {
    char *name;
    int kind, count, offset, flags;
    unsigned rgb;
    eom_vector_fn fn;
    void *user;
} eom_drawing_def;

struct eom_model {
    eom_named *coords, *params, *probes;
    eom_name_slot *names; /* every name above, hashed: a model with tens
                             of thousands checks each new one in constant
                             time; at most half full */
    int names_cap, names_used;
    int n_coords, n_params, n_probes;
    int cap_coords, cap_params, cap_probes;
    eom_cblist T, V, R, phi;
    eom_cblist psi; /* velocity constraint blocks */
    eom_callback L, Q;
    eom_callback x0; /* the initial state from the parameters, or unset */
    int n_con;      /* total over the constraint blocks */
    int n_vcon;     /* total over the velocity constraint blocks */
    eom_cblist *last_con; /* the list (phi or psi) that took the last
                             constraint block, or NULL */
    eom_attached *att;
    int n_att, cap_att;
    eom_drawing_def *draws; /* drawings (drawing.c) */
    int n_draws, cap_draws, n_draw_values;
    int status;
    char msg[EOM_MSG_LEN];
};

/* Which callback a context is recording: decides the leaves it offers. */
typedef enum eom_role {
    EOM_ROLE_STATE, /* q, qd: T, V, L, R, probes */
    EOM_ROLE_FORCE, /* q, qd, t */
    EOM_ROLE_CONSTRAINT, /* q only */
    EOM_ROLE_VCONSTRAINT, /* q, qd, t: velocity constraints, linear in qd */
    EOM_ROLE_INITIAL /* parameters only: the initial state */
} eom_role;

/* What eom_time gives in a recording. */
typedef enum eom_time_as {
    EOM_TIME_NONE,  /* nothing: reading the time is an error */
    EOM_TIME_INDEP, /* the independent time_index */
    EOM_TIME_PARAM  /* the tape parameter EOM_TIME_NAME */
} eom_time_as;

#define EOM_CTX_PARAMS 64

struct eom_ctx {
    tp_rec *r;
    const eom_model *m;
    eom_role role;
    int n;
    eom_time_as time_as;
    int time_index;   /* the time's independent (EOM_TIME_INDEP) */
    bool read_time;   /* eom_time was called */
    bool in_probe;    /* recording a probe: eom_multiplier is allowed */
    int nrows;        /* the model's constraint rows (holonomic and
                         velocity), for eom_multiplier's range */
    int status;       /* first error of this recording */
    char msg[EOM_MSG_LEN];
    unsigned lang_run; /* 0 when the recording starts; the model-file
                          language marks it to share its definitions
                          among the callbacks of one recording */
    /* the handles of the first EOM_CTX_PARAMS parameters in this
     * recording (tag 0: not yet asked for): elements ask for the same
     * parameter at every link, and declaring it again means a search of
     * the recording's parameters by name */
    tp_val pv[EOM_CTX_PARAMS];
};

/* ---- system ----------------------------------------------------------- */

/* A tape, its workspace, and the workspace index of every system
 * parameter (-1 when the tape does not use it). The tape may be shared
 * with clones of the system (eom_system_clone); the workspace is the
 * system's own. */
typedef struct eom_tape {
    tp_tape *tape;
    tp_ws *ws;
    int *pmap;
    int dirs; /* the workspace's largest number of directions */
    int tindex;   /* the time's independent, or -1 */
    int tparam;   /* the workspace parameter of the time, or -1 */
    double tset;  /* the time last given to tparam (NaN: none yet) */
    double *xt;   /* [tindex + 1] a sweep's input with the time (tindex
                     >= 0), the system's own */
} eom_tape;

/* How many systems share one set of tapes: the last one frees them.
 * Clones may be freed by different threads, hence atomic. */
#define EOM_N_TAPES 9 /* L, E, R, Q, phi, residual, psi, initial state,
                         drawings: eom__tapes */
typedef struct eom_shared {
    atomic_int refs;
    tp_compiled *cc[EOM_N_TAPES]; /* compiled tapes, or NULL */
    char **con_names; /* [m] the constraint rows' names (NULL: unnamed),
                         or NULL when no row has one; shared by clones */
    int *con_sorted;  /* [m] the named rows by name, for lookups */
    int n_named;      /* entries of con_sorted */
} eom_shared;

struct eom_system {
    atomic_int busy;  /* 1 while eom_rhs runs on it: a second thread that
                         enters meanwhile gets EOM_ERR_BUSY (a system is
                         for one thread at a time) */
    int n, m, np, nprobe;
    int mh, mv;       /* holonomic and velocity rows, m = mh + mv */
    size_t ws_bytes;  /* the tape workspaces made so far (memory_fit.c) */
    bool has_tv, has_R, has_Q;
    bool reads_time;  /* the L, E, R, phi or psi tape reads the time */
    double time;      /* the time of the calls that take no t */
    eom_named *coords, *params, *probes; /* copies (fn unused) */
    double *pval;                        /* parameter values in use */
    eom_tape tL, tE, tR, tQ, tphi;
    eom_tape tpsi;    /* velocity constraints (mv > 0), interpreted */
    eom_tape tx0;     /* the initial state from the parameters, or none
                         (initial.c), interpreted */
    eom_tape tD;      /* the drawings (drawing.c), or none; replayed only
                         by eom_drawings_at */
    eom_drawing_def *draws; /* copies of the model's drawings (fn unused) */
    int ndraw, ndraw_values;
    double *vx;       /* 2n + 1: a sweep's input (q, qd) of the psi tape */
    double *vdir;     /* 2n + 1: its direction (qd, 0, 1) */
    int *ipiv;        /* mh: pivots of the holonomic block's solve */
    /* the residual tape (residual.c): z = (q, qd, qdd, lambda, t, p); its
     * workspace and the Jacobian's scratch are made on first use */
    eom_tape tRes;
    double *jz, *jres, *jB, *jy;
    struct eom_jsparse *jsp; /* the sparse iteration matrix's structure
                                (jacobian_sparse.c), made on first use */
    struct eom_ssparse *ssp; /* bdf's sparse Jacobian's structure
                                (state_jacobian_sparse.c), likewise */
    struct eom_mass *mass; /* what the L tape says about M and the
                              route it takes (mass_route.h), made on
                              first use */
    int route;      /* eom__mass_route's answer, kept while route_key is
                       1 + compiled (0: not known; the analysis not made
                       yet, or eom_system_set_mass_route since) */
    int route_key;
    struct eom_kkt *kkt; /* eom_rhs's augmented sparse solve
                            (kkt_sparse.c), made on first use */
    unsigned long param_gen; /* advanced by every eom_set_param: a factor
                                kept for constant M is for one value */
    eom_shared *shared;                  /* the tapes' owners */
    bool compiled;   /* the workspaces run the shared compiled tapes */
    double alpha, beta;                  /* Baumgarte */
    char msg[EOM_MSG_LEN];

    /* results of the last evaluation (rhs.c) */
    double *M;     /* n x n mass matrix */
    double *Mf;    /* n x n Cholesky factor (its lower triangle; the
                      upper one is never read) */
    bool mf_valid; /* Mf holds the factor of a mass matrix */
    double mass_pivot_min; /* an integrator's floor on each coordinate's
                              relative pivot L_ii^2 / M_ii (rhs.c,
                              eom__factor_mass); 0: only a factor that
                              fails is singular */
    double *g;     /* n  dL/dq */
    double *h;     /* n  (d2L/dqd dq) qd */
    double *F;     /* n  g - h - dR/dqd + Q */
    double *qdd;   /* n */
    double *gR;    /* 2n gradient of R */
    double *Qv;    /* n  non-conservative forces -dR/dqd + Q */
    double *C;     /* m x n */
    double *phi;   /* m */
    double *phid;  /* m  C qd (+ dphi/dt); psi for velocity rows */
    double *phit;  /* m  dphi/dt at fixed q (0 unless phi reads time);
                      b for velocity rows */
    double *Ct;    /* m x (n + 1) scratch: C and dphi/dt in one Jacobian */
    double *dir;   /* n + 1: the Taylor direction (qd, 1) in (q, t) */
    double dLdt;   /* dL/dt at fixed (q, qd), last evaluation */
    double *gam;   /* m  right side of C qdd = gam */
    double *Y;     /* n x m  M^-1 C^T */
    double *S;     /* m x m  C M^-1 C^T */
    double *lam;   /* m */
    int *lam_param; /* [m] the E tape's parameter of each multiplier a
                       probe reads (eom_multiplier), or -1; NULL when no
                       probe reads one */
    double *wn, *wm; /* scratch n and m */
    double *wE;      /* scratch for energy tape outputs */
    double power;  /* dE/dt at the last evaluation: qd . Qv, and for a
                      model that reads time also -dL/dt and, when the
                      constraints read it, lambda . (C qd) */
    double power_t; /* the part of power due to the explicit time and
                       the velocity constraints' forces */

    /* KLU for S: dense pattern in compressed columns, analyzed once */
    int *Sp, *Si;
    double *Sx;
    klu_common kc;
    klu_symbolic *ksym;
    klu_numeric *knum;
    double rcond_S;   /* KLU's estimate at the last factorization */

    /* S's filtered pseudo-inverse where KLU's factor is too poorly
     * conditioned (redundant constraints, near a singular configuration):
     * S = U diag(sv) V^T, m x m column-major (rhs.c, EOM_PINV_MU). Work
     * arrays allocated with the KLU ones. */
    bool S_pinv;      /* the last factorization is the pseudo-inverse */
    int S_rank;       /* directions it keeps */
    double S_mu;      /* its filter parameter */
    double rcond_S_min; /* smallest rcond_S since the last reset (an
                           integrator resets it when it starts) */
    long n_svd;       /* factorizations that took the SVD path */
    double *Sa, *Su, *Svt, *Ssv, *Swork;
    int Slwork;
};

/* residual.c: record the residual tape from the system's tapes (at the
 * end of eom_system_new). */
int eom__record_residual(eom_system *s);
/* Eigenvalues (re, im; n) sorted by real part, then imaginary part; real
 * parts within 1e-12 of the largest modulus count as equal, so rounding
 * does not decide the order of a conjugate pair (linearize_state.c). */
void eom__sort_eig(int n, double *re, double *im);
/* residual.c: the exact Jacobian of the state derivative at (t, x), the
 * columns of A (leading dimension lda) for x = (q, qd): 2n rows, and with
 * with_power a row 2n for the dissipated energy W and a zero column 2n
 * (A is then (2n + 1) square). Leaves s evaluated at (t, x). */
int eom__state_jacobian(eom_system *s, double t, const double *x,
                        double *A, int lda, int with_power);
/* residual.c: d(xd)/dp for the system's parameters at (t, x): 2n rows,
 * np columns, column-major with leading dimension ldb. */
int eom__param_jacobian(eom_system *s, double t, const double *x,
                        double *B, int ldb);
/* residual.c: the right-hand sides of ns forward sensitivities at
 * (t, x): out[k] = A V_k + (B e_par[k] when par[k] >= 0) for the
 * (2n + 1)-vectors V_k (q, qd, W; W enters nothing), W's row included;
 * one forward sweep of the residual tape with ns directions. With
 * evaluated, s already holds the evaluation at (t, x) (eom__evaluate
 * was its last evaluation), which is then not repeated. work holds
 * eom__sens_work(s, ns) doubles. */
int eom__sens_rhs(eom_system *s, double t, const double *x, int evaluated,
                  int ns, const int *par, const double *const *V,
                  double *const *out, double *work);
size_t eom__sens_work(const eom_system *s, int ns);
/* residual.c: eom__sens_rhs, and with dlam (m x ns, column k at
 * dlam + k m; may be NULL) the multipliers' changes d lambda along each
 * direction too (IDAS's consistent starts, integrate_ida.c). */
int eom__sens_rates(eom_system *s, double t, const double *x, int evaluated,
                    int ns, const int *par, const double *const *V,
                    double *const *out, double *dlam, double *work);
/* residual.c: the residual tape's workspace made and its independents z
 * = (x, qdd, lambda, t, p) in s->jz, for sweeps of s->tRes.ws at z:
 * eom__residual_z at the given qdd and lambda, without evaluating the
 * model; eom__residual_at after an evaluation at (t, x), whose qdd and
 * lambda it takes (s then holds that evaluation's factors). */
int eom__residual_z(eom_system *s, double t, const double *x,
                    const double *qdd, const double *lam);
int eom__residual_at(eom_system *s, double t, const double *x);
/* sensitivity.c: the linearized projection of ns sensitivities V_k
 * (2n values for (q, qd) each, changed in place; par[k] the parameter of
 * direction k or -1) at a state x = (q, qd) on the constraints at t:
 *     V_q <- V_q - Y S^-1 (C V_q + dphi/dp e),
 *     V_v <- V_v - Y S^-1 (d(phi1)/dq V_q + C V_v + d(phi1)/dp e)
 * with phi1 = C qd + dphi/dt, Y = W^-1 C^T, S = C W^-1 C^T: the
 * derivative of the projection of least W-norm, W = M at x (identity 0:
 * after the integrators' projections) or I (identity 1: the start's,
 * eom_project_start). Leaves s evaluated at (t, x) (with identity, its
 * factor of M replaced). work: eom__sens_work(s, ns) doubles. */
int eom__sens_project(eom_system *s, double t, const double *x, int identity,
                      int ns, const int *par, double *const *V,
                      double *work);
/* sensitivity.c: the residuals of IDAS's sensitivity equations at
 * (t, Y, Y') for Y = (q, v, lambda, W) (integrate_ida.c): for each
 * direction k, RS_k = dG/dY YS_k + dG/dY' YpS_k + dG/dp e_par[k], exact
 * from one forward sweep of the residual tape with ns directions. work:
 * eom__sens_work(s, ns) doubles. */
int eom__sens_dae_res(eom_system *s, double t, const double *Y,
                      const double *Yp, int ns, const int *par,
                      const double *const *YS, const double *const *YpS,
                      double *const *RS, double *work);
/* residual.c: the residual tape's Jacobian at z = (x, qdd, lambda, t) over
 * (q, qd, qdd, lambda): J row-major, n + 3m + 1 rows (E, phi2, phi1,
 * phi0, P) by 3n + m columns. */
int eom__residual_jacobian(eom_system *s, double t, const double *x,
                           const double *qdd, const double *lam,
                           double *J);
/* residual.c: IDA's iteration matrix dG/dY + cj dG/dY' for the index-1
 * residual G of integrate_ida.c at (Y, Yp), Y = (q, v, lambda, W):
 * (2n + m + 1) square, column-major with leading dimension ldj. */
int eom__dae_jacobian(eom_system *s, double t, const double *Y,
                      const double *Yp, double cj, double *J, int ldj);
/* residual.c: z = (x, qdd, lambda, t, p) for the residual tape, into
 * z[3n + m + 1 + np]. */
void eom__residual_fill_z(const eom_system *s, double t, const double *x,
                          const double *qdd, const double *lam, double *z);

/* jacobian_sparse.c: IDA's iteration matrix as a sparse matrix. */
typedef struct eom_jsparse eom_jsparse;
void eom__jsparse_free(eom_jsparse **p);
/* The structure of the sparse iteration matrix, owned by s (made on
 * first use, from the residual tape's pattern): */
typedef struct eom_dae_pattern {
    int NY;                /* 2n + m + 1 */
    size_t nnz;            /* entries */
    const int64_t *colptr; /* [NY + 1] compressed columns */
    const int64_t *rowind; /* [nnz] rows, ascending in each column */
    int colors;            /* directions of the forward sweep */
    int reverse_rows;      /* residual rows from a reverse sweep each */
} eom_dae_pattern;
int eom__dae_pattern(eom_system *s, eom_dae_pattern *p);
/* The values of the iteration matrix dG/dY + cj dG/dY' (the dense one is
 * eom__dae_jacobian) in the order of p's entries, into data[nnz]. */
int eom__dae_jacobian_sparse(eom_system *s, double t, const double *Y,
                             const double *Yp, double cj, double *data);
/* The linear solver ida uses for s: requested (eom_opts.linear_solver)
 * unless EOM_LINSOL_AUTO, then the rule of docs/integrators.md ("Sparse
 * iteration matrices"); into *choice (EOM_LINSOL_DENSE or
 * EOM_LINSOL_SPARSE). dq: difference quotients (dense only). */
int eom__dae_linear_solver(eom_system *s, int requested, int dq,
                           int *choice);

/* state_jacobian_sparse.c: bdf's d(yd)/dy, y = (q, qd, W), as a sparse
 * matrix, for models without constraints. */
typedef struct eom_ssparse eom_ssparse;
void eom__ssparse_free(eom_ssparse **p);
/* Its structure, owned by s (made on first use from the residual tape's
 * pattern; EOM_ERR_ARG when s has constraints): */
typedef struct eom_ode_pattern {
    int N;                 /* 2n + 1 */
    size_t nnz;            /* entries, the whole diagonal included */
    const int64_t *colptr; /* [N + 1] compressed columns */
    const int64_t *rowind; /* [nnz] rows, ascending in each column */
    int colors;            /* directions of the forward sweep */
    int reverse_rows;      /* 1 when the power row is a reverse sweep */
    int blocks;            /* connected components of M's pattern */
    int largest_block;     /* coordinates in the largest */
} eom_ode_pattern;
int eom__ode_pattern(eom_system *s, eom_ode_pattern *p);
/* The values of d(yd)/dy at (t, y) (the dense one is eom__state_jacobian
 * with its power row) in the order of p's entries, into data[nnz];
 * evaluates s at (t, y). */
int eom__state_jacobian_sparse(eom_system *s, double t, const double *y,
                               double *data);
/* The linear solver bdf uses for s: requested (eom_opts.linear_solver)
 * unless EOM_LINSOL_AUTO, then ida's rule on bdf's matrix; into *choice.
 * A sparse request is refused (EOM_ERR_ARG, with the reason in s) with
 * constraints, difference quotients, or one block of M over more than
 * half the coordinates. */
int eom__ode_linear_solver(eom_system *s, int requested, int dq,
                           int *choice);

/* rhs.c: the non-conservative generalized forces at (t, x), -dR/dqd + Q,
 * into s->Qv, and their power qd . Qv into s->power (uses s->wn). */
int eom__nonconservative(eom_system *s, double t, const double *x);

/* rheonomic.c: the input of a sweep of et at (t, x): x itself when the
 * tape has no time independent (after giving the time to its parameter,
 * if it has one), else a copy of x's first tindex values followed by t in
 * et->xt. */
const double *eom__tape_input_timed(eom_tape *et, const double *x,
                                    double t);
/* The same, inline for the tapes without the time (every tape of most
 * models): they cost one test. */
static inline const double *eom__tape_input(eom_tape *et, const double *x,
                                            double t)
{
    if (et->tindex < 0 && et->tparam < 0)
        return x;
    return eom__tape_input_timed(et, x, t);
}
/* rheonomic.c: phi, C qd + dphi/dt and -gamma's curvature part
 * d2phi/ds2 along (q + s qd, t + s) at (t, x) into phi (may be NULL),
 * phid and curv (m each): one Taylor sweep. */
int eom__constraint_rates(eom_system *s, double t, const double *x,
                          double *phi, double *phid, double *curv);
/* constraints.c: EOM_ERR_MODEL with a message naming what (a call or a
 * method) when s has velocity constraints, which what does not take. */
int eom__refuse_velocity(eom_system *s, const char *what);
/* constraints.c: the velocity rows at (t, q): A into rows mh .. m-1 of
 * s->C, b into s->phit's, 0 into s->phi's. */
int eom__velocity_rows_at(eom_system *s, double t, const double *q);
/* constraints.c: the velocity rows' residual psi into phid[mh ..] and its
 * rate along (qd, 0, 1) into curv[mh ..]; phi[mh ..] = 0 (phi may be
 * NULL). */
int eom__velocity_rates(eom_system *s, double t, const double *x,
                        double *phi, double *phid, double *curv);
/* constraints.c: the linearity of the velocity constraints in qd
 * (EOM_ERR_MODEL naming the first row that is not, or that does not read
 * qd at all). */
int eom__check_velocity_rows(eom_system *s);
/* model.c: record a model's first error (kept; later ones are not) and
 * return status; names the model accepts (C identifiers not ending in
 * "_dot"). */
int eom__model_fail(eom_model *m, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
bool eom__valid_name(const char *s);
/* constraint_names.c: the rows' names gathered from m's blocks into s's
 * shared part, checked unique (EOM_ERR_MODEL naming both rows); freed
 * with the last system that shares them. */
int eom__constraint_names(eom_system *s, const eom_model *m);
void eom__constraint_names_free(eom_shared *sh, int m);
void eom__free_names(char **names, int count);
/* Constraint row j for a message: 'NAME' when named, else "row K"
 * (from 1). */
void eom__row_label(const eom_system *s, int j, char *buf, size_t len);
/* energy.c: s->lam_param from the E tape (after it is recorded or
 * cloned). */
int eom__probe_multipliers(eom_system *s);
/* rheonomic.c: EOM_ERR_MODEL with a message naming what when the
 * Lagrangian, the dissipation or the constraints read the time. */
int eom__refuse_time(eom_system *s, const char *what);
/* rhs.c: evaluate everything the right-hand side needs at (t, x) and
 * solve; leaves M, Mf, F, C, lam, qdd, power in s. */
int eom__evaluate(eom_system *s, double t, const double *x);
/* Factor s->M into s->Mf (Cholesky); EOM_ERR_SINGULAR_MASS on failure. */
/* The smallest relative pivot L_kk^2 / M_kk of the factor in s->Mf (of
 * s->M): the part of coordinate k's inertia not shared with the
 * coordinates before it (1 for a coordinate independent of them, 0 when
 * it moves only with them); its index into *k. */
double eom__mass_min_pivot(const eom_system *s, int *k);
int eom__factor_mass(eom_system *s);
/* cholesky_columns.c: the Cholesky factor of mass matrices of medium
 * size, up to this n (cholesky_blocked.h's above): the lower triangle of
 * M (n x n, column-major) read, the factor's written to A's; info = j + 1 at a
 * non-positive pivot j, else 0. And the solve of A A^T X = B for nrhs
 * columns of n in place. */
#define EOM_COLUMN_CHOLESKY 128
int eom__potrf_columns(int n, const double *M, double *A);
void eom__potrs_columns(int n, int nrhs, const double *A, double *B);
/* Forget the factorizations kept from earlier evaluations (KLU's pivot
 * order, the factor of M the projection reuses), so that what follows
 * depends on its inputs alone, not on what s evaluated before. */
void eom__forget(eom_system *s);
/* Projection after an integrator's step at time t: as eom_project, with
 * the factor of M from the last evaluation when there is one
 * (constraints.c). */
int eom__project_step(eom_system *s, double t, double *x, double tol,
                      double qtol, int *iters);
/* Solve Mf Mf^T X = B in place, B n x nrhs column-major (a column is n
 * contiguous values). */
int eom__mass_solve(eom_system *s, double *B, int nrhs);
/* Constraint Jacobian and values at (t, q) into s->C, s->phi, and, when
 * the constraints read the time, dphi/dt into s->phit. */
int eom__constraints_at(eom_system *s, double t, const double *q);
/* Form S = C M^-1 C^T (also Y = M^-1 C^T) and factor it with KLU. */
int eom__factor_S(eom_system *s);
/* S's KLU analysis and pseudo-inverse arrays, made on the first call
 * (system.c; eom__factor_S calls it). */
int eom__setup_klu(eom_system *s);
/* Solve S z = b in place (m values). */
int eom__S_solve(eom_system *s, double *b);
/* The correction of least W-norm with the factors of S and Y = W^-1 C^T
 * held: v[0..n) -= Y S^-1 r, r (m values) overwritten with S^-1 r. A
 * status (constraints.c; the projections, their sensitivities, imex's
 * split). */
int eom__S_correct(eom_system *s, double *v, double *r);

/* Full SVD of the rows x cols column-major A (destroyed): singular values
 * sv, all of U (rows x rows) and V^T (cols x cols), column-major (linalg.c).
 * what names the matrix in a failure message. */
int eom__svd(eom_system *s, int rows, int cols, double *A, double *sv,
             double *U, double *VT, const char *what);

/* max_i |a_i| over n values, 0 for none; a NaN entry is passed over, as
 * fmax does (linalg.c). */
double eom__maxabs(const double *a, size_t n);

/* The system's tapes in a fixed order: L, E, R, Q, phi, residual, psi
 * (the order of eom_shared.cc). */
void eom__tapes(eom_system *s, eom_tape *t[EOM_N_TAPES]);
/* drawing.c: record every drawing of c->m as outputs D1, D2, ... (the
 * body of the drawings' tape); copy n drawings into s (names copied, no
 * callbacks); free s's copies. */
int eom__body_drawings(eom_ctx *c);
int eom__drawings_copy(eom_system *s, const eom_drawing_def *d, int n);
void eom__drawings_free(eom_system *s);

/* Status with a message in s (first argument printf-style). */
int eom__fail(eom_system *s, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Map a libtape status to libeom's, with a message naming what. */
int eom__tape_status(eom_system *s, int tp_status, const char *what);
/* EOM_OK when a workspace of tape t for dirs directions fits, with the
 * system's workspaces made before, in the machine's memory (and counts
 * it); else EOM_ERR_NOMEM with a message giving the size it needs and the
 * memory there is (memory_fit.c). Call it before tp_ws_new. */
int eom__workspace_fits(eom_system *s, const tp_tape *t, int dirs,
                        const char *what);
/* The same for bytes of the system's own arrays (alloc_arrays). */
int eom__arrays_fit(eom_system *s, double bytes);
/* Every value finite? Inline: every evaluation checks its state and its
 * accelerations, a few values each, where a call cost as much as the
 * test. The exponent field of an infinity or a NaN, all ones, carries
 * into bit 63 when one is added to it (no other exponent does): an OR
 * of these over the values, with no branch per value, vectorizes. */
static inline bool eom__finite(const double *a, size_t n)
{
    uint64_t bad = 0;
    size_t i;
    for (i = 0; i < n; i++) {
        uint64_t u;
        memcpy(&u, a + i, sizeof u);
        bad |= (u & UINT64_C(0x7ff0000000000000)) +
               UINT64_C(0x0010000000000000);
    }
    return (bad >> 63) == 0;
}

/* ---- LAPACK (Fortran interface; hidden string lengths last) ----------- */

void dpotrf_(const char *uplo, const int *n, double *a, const int *lda,
             int *info, size_t uplo_len);
void dpotrs_(const char *uplo, const int *n, const int *nrhs,
             const double *a, const int *lda, double *b, const int *ldb,
             int *info, size_t uplo_len);
void dpocon_(const char *uplo, const int *n, const double *a,
             const int *lda, const double *anorm, double *rcond,
             double *work, int *iwork, int *info, size_t uplo_len);
double dlansy_(const char *norm, const char *uplo, const int *n,
               const double *a, const int *lda, double *work,
               size_t norm_len, size_t uplo_len);
void dsygv_(const int *itype, const char *jobz, const char *uplo,
            const int *n, double *a, const int *lda, double *b,
            const int *ldb, double *w, double *work, const int *lwork,
            int *info, size_t jobz_len, size_t uplo_len);
void dgesvd_(const char *jobu, const char *jobvt, const int *m,
             const int *n, double *a, const int *lda, double *s, double *u,
             const int *ldu, double *vt, const int *ldvt, double *work,
             const int *lwork, int *info, size_t jobu_len, size_t jobvt_len);
void dgeev_(const char *jobvl, const char *jobvr, const int *n, double *a,
            const int *lda, double *wr, double *wi, double *vl,
            const int *ldvl, double *vr, const int *ldvr, double *work,
            const int *lwork, int *info, size_t jobvl_len, size_t jobvr_len);
void dgesv_(const int *n, const int *nrhs, double *a, const int *lda,
            int *ipiv, double *b, const int *ldb, int *info);
void dgelss_(const int *m, const int *n, const int *nrhs, double *a,
             const int *lda, double *b, const int *ldb, double *s,
             const double *rcond, int *rank, double *work, const int *lwork,
             int *info);
void dgeqp3_(const int *m, const int *n, double *a, const int *lda,
             int *jpvt, double *tau, double *work, const int *lwork,
             int *info);

#endif /* EOM_INTERNAL_H */
