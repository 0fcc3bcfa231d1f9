/* eom.h - public API of libeom, the Lagrangian compiler.
 *
 * A model names its generalized coordinates and parameters and gives its
 * energies as recording callbacks: the kinetic energy T(q, qd, t) and the
 * potential V(q, t) (or a whole Lagrangian L(q, qd, t)), optionally a
 * Rayleigh dissipation function R(q, qd, t), generalized forces
 * Q(q, qd, t), holonomic constraints phi(q, t) = 0 and named probes. Any
 * callback may read the time (eom_time): a driven crank, a prescribed
 * coordinate, a moving support. eom_system_new records every callback
 * once onto tapes; from then on each evaluation replays the tapes and
 * solves Lagrange's equations
 *
 *     M qdd = dL/dq - (d2L/dqd dq) qd - d2L/dqd dt - dR/dqd + Q
 *             + C^T lambda
 *     C qdd = -(d2phi/dq2)[qd, qd] - 2 (d2phi/dq dt) qd - d2phi/dt2
 *             (+ Baumgarte terms if enabled)
 *
 * with M = d2L/dqd2 and C = dphi/dq, by the range-space method (Cholesky
 * of M, KLU of S = C M^-1 C^T); the terms in t vanish for a model that
 * does not read the time, and cost nothing then. The velocities satisfy
 * C qd + dphi/dt = 0. Sign convention: the generalized constraint force is
 * C^T lambda, added to the applied forces. Velocity constraints
 * A(q, t) qd + b(q, t) = 0 add rows A to C (after the holonomic ones) with
 * gamma = -(d/ds) psi(q + s qd, qd, t + s).
 *
 * State vectors are x = (q, qd), 2n values. Conventions as in libtape:
 * status 0 success, > 0 warning, < 0 error; constructors write through
 * T **out; destructors take T ** and set it to NULL; matrices are dense
 * row-major; the library never aborts and keeps no process-wide state.
 * A system and its integrators belong to one thread at a time.
 */
#ifndef EOM_EOM_H
#define EOM_EOM_H

#include <stddef.h>

#include "tape/tape.h"

#if defined(__GNUC__) && !defined(_WIN32)
#define EOM_API __attribute__((visibility("default")))
#else
#define EOM_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- status codes ----------------------------------------------------- */

#define EOM_STATUS_LIST(X)                                                     \
    X(EOM_OK, 0, "success")                                                    \
    X(EOM_ERR_NULL, -1, "a required pointer argument is NULL")                 \
    X(EOM_ERR_NOMEM, -2, "out of memory")                                      \
    X(EOM_ERR_ARG, -3, "an argument is out of range or malformed")             \
    X(EOM_ERR_NAME, -4, "a name is unknown, empty, malformed or declared "     \
                        "twice")                                               \
    X(EOM_ERR_MODEL, -5, "the model is incomplete or inconsistent")            \
    X(EOM_ERR_RECORD, -6, "recording a model callback failed")                 \
    X(EOM_ERR_NONFINITE, -7, "a state, parameter or computed quantity is "     \
                             "NaN or infinite")                                \
    X(EOM_ERR_SINGULAR_MASS, -8, "the mass matrix is not positive definite")   \
    X(EOM_ERR_RANK_DEFICIENT, -9, "the constraint Jacobian is rank "           \
                                  "deficient: C M^-1 C^T is singular")         \
    X(EOM_ERR_PROJECTION, -10, "projection onto the constraints did not "      \
                               "converge")                                     \
    X(EOM_ERR_SOLVER, -11, "the integrator failed (the message names the "     \
                           "solver's flag)")                                   \
    X(EOM_ERR_LINALG, -12, "a linear-algebra routine failed")                  \
    X(EOM_ERR_NOT_CONVERGED, -13, "an iteration did not converge")            \
    X(EOM_ERR_FILE, -14, "a model file cannot be read or is not valid (the "   \
                         "message gives file:line:col)")                       \
    X(EOM_ERR_BUSY, -15, "the system is in use by another thread at the same " \
                         "time: give each thread its own (eom_system_clone)")  \
    X(EOM_WARN_INTERPRETED, 1, "compiled tapes are not in use: the "           \
                               "interpreter runs the model (the message says " \
                               "why)")

typedef enum eom_status {
#define EOM_STATUS_ENUM_(name, value, text) name = value,
    EOM_STATUS_LIST(EOM_STATUS_ENUM_)
#undef EOM_STATUS_ENUM_
} eom_status;

EOM_API const char *eom_strerror(int status);
EOM_API const char *eom_status_name(int status);

/* ---- models ----------------------------------------------------------- */

typedef struct eom_model eom_model;

/* While a callback records, it receives the recording context: */
typedef struct eom_ctx eom_ctx;

/* A scalar energy (T, V, L, R or a probe): set *out. A vector callback
 * (constraints, forces) sets out[0 .. count-1]. Return 0, or non-zero to
 * abort recording (EOM_ERR_RECORD). */
typedef int (*eom_scalar_fn)(eom_ctx *c, void *user, tp_val *out);
typedef int (*eom_vector_fn)(eom_ctx *c, void *user, tp_val *out);

EOM_API int eom_model_new(eom_model **out);
EOM_API void eom_model_free(eom_model **m);
/* The model's message about its first error ("" if none). */
EOM_API const char *eom_model_errmsg(const eom_model *m);

/* Names are C identifiers (letters, digits, '_', not starting with a
 * digit), unique among coordinates and parameters, and not ending in
 * "_dot". unit may be NULL. q0 and qd0 are the default initial value and
 * rate. Returns the new coordinate's index, or a negative status. */
EOM_API int eom_model_add_coord(eom_model *m, const char *name,
                                const char *unit, double q0, double qd0);
/* A parameter: a value that may change without re-recording. Returns its
 * index, or a negative status. description may be NULL. */
EOM_API int eom_model_add_param(eom_model *m, const char *name,
                                const char *unit, double dflt,
                                const char *description);

/* Energies: either T and V (V may be omitted: zero), or a Lagrangian L.
 * Each callback is kept by pointer with its user pointer (borrowed until
 * eom_system_new returns). set_* makes f the only contribution of its
 * kind; add_* adds one more, and the contributions are summed: this is
 * how elements of a scene each record only their own terms. */
EOM_API int eom_model_set_kinetic(eom_model *m, eom_scalar_fn T, void *user);
EOM_API int eom_model_set_potential(eom_model *m, eom_scalar_fn V,
                                    void *user);
EOM_API int eom_model_add_kinetic(eom_model *m, eom_scalar_fn T, void *user);
EOM_API int eom_model_add_potential(eom_model *m, eom_scalar_fn V,
                                    void *user);
EOM_API int eom_model_set_lagrangian(eom_model *m, eom_scalar_fn L,
                                     void *user);
/* Rayleigh dissipation R(q, qd, t): generalized force -dR/dqd. */
EOM_API int eom_model_set_dissipation(eom_model *m, eom_scalar_fn R,
                                      void *user);
EOM_API int eom_model_add_dissipation(eom_model *m, eom_scalar_fn R,
                                      void *user);
/* Generalized forces Q(q, qd, t): n values (eom_time is available). The
 * n outputs start as the constant 0: the callback sets only the nonzero
 * entries. */
EOM_API int eom_model_set_forces(eom_model *m, eom_vector_fn Q, void *user);
/* Holonomic constraints phi(q, t) = 0: count values of q and the time
 * (reading qd in this callback is an error). A constraint that reads the
 * time moves (a prescribed coordinate: q_k - f(t)); its velocity form is
 * C qd + dphi/dt = 0. set_ makes phi the only block of constraints; add_
 * appends a block (the blocks are stacked in the order added). */
EOM_API int eom_model_set_constraints(eom_model *m, int count,
                                      eom_vector_fn phi, void *user);
EOM_API int eom_model_add_constraints(eom_model *m, int count,
                                      eom_vector_fn phi, void *user);
/* Velocity constraints A(q, t) qd + b(q, t) = 0 (non-holonomic: a wheel
 * that rolls without slipping, a knife edge): count values of q, qd and
 * the time, each linear in qd (checked when the system is built: a row
 * that is not linear in the rates, or does not read them, is refused
 * with EOM_ERR_MODEL and a message naming the row). add_ appends a block
 * after any earlier block; rows are stacked after every holonomic row.
 * Their rows of C are A = dpsi/dqd, their gamma is -dpsi/ds along (qd,
 * qdd = 0, t-rate 1), their Baumgarte term -2 alpha psi; they have no
 * position residual (phi = 0) and are projected at the velocity level
 * only. The exact Jacobians (eom_state_jacobian, eom_param_jacobian) and
 * eom_linearize_state include them; eom_linearize, eom_equilibrium, ida
 * and sensitivities refuse a model with them (EOM_ERR_MODEL). The psi
 * tape is never compiled (eom_system_set_compiled). */
EOM_API int eom_model_add_velocity_constraints(eom_model *m, int count,
                                               eom_vector_fn psi,
                                               void *user);
/* Names for the rows of the constraint block added last (holonomic or
 * velocity): count names, the block's count, in its row order; a NULL
 * entry leaves its row unnamed. Names are C identifiers, unique among all
 * constraint rows of the model (checked by eom_system_new). A named row's
 * columns in eom-run's CSV are phi_NAME, phidot_NAME and lambda_NAME; an
 * unnamed row k's (from 1) are phiK, phidotK and lambdaK. */
EOM_API int eom_model_name_constraints(eom_model *m, int count,
                                       const char *const *names);
/* The default initial state as a function of the parameters: x0 sets
 * out[0 .. 2n-1], the coordinates then the rates, from eom_param values
 * and constants only (eom_q, eom_qd and eom_time are errors in it). It
 * is recorded once with the system; eom_initial_state then gives it at
 * the parameters in use, so that a start can follow a parameter (a
 * vehicle's wheel rates from its speed). Without it, eom_initial_state
 * gives the values passed to eom_model_add_coord. */
EOM_API int eom_model_set_initial(eom_model *m, eom_vector_fn x0,
                                  void *user);
/* Give the model data to free with it (for example an element's
 * description that its callbacks read). free_fn(data) is called by
 * eom_model_free; on failure it is called at once. */
EOM_API int eom_model_attach(eom_model *m, void *data,
                             void (*free_fn)(void *));
/* Number of coordinates added so far (the index the next one gets). */
EOM_API int eom_model_ncoords(const eom_model *m);
/* A named scalar of (q, qd, t) reported beside the energies (for example
 * the flexible part of a link's kinetic energy). */
EOM_API int eom_model_add_probe(eom_model *m, const char *name,
                                const char *unit, eom_scalar_fn f,
                                void *user);

/* Inside a callback: the recording context (for tp_* operations), the
 * coordinates, rates, time and parameters as recorded values. A bad index
 * or unknown parameter name gives an invalid value and makes recording
 * fail with a message naming it. eom_time may be read by every callback;
 * a tape whose callbacks never read it is recorded without it (the
 * derivatives in t of the equations above are then not computed at all),
 * one that reads it is recorded a second time with the time as an
 * independent variable where the equations need its derivatives (the
 * Lagrangian and the constraints). */
EOM_API tp_rec *eom_rec(eom_ctx *c);
EOM_API int eom_ncoords(const eom_ctx *c);
EOM_API tp_val eom_q(eom_ctx *c, int i);
EOM_API tp_val eom_qd(eom_ctx *c, int i);
EOM_API tp_val eom_time(eom_ctx *c);
/* In a probe's callback only: the multiplier of constraint row j
 * (holonomic rows, then velocity rows, from 0) at the state the probe is
 * evaluated at (so that a probe can report a constraint force: a motor's
 * torque, a wheel's contact force). eom_probes_at then solves the
 * equations of motion at that state first. Anywhere else, or j out of
 * range, recording fails with a message. */
EOM_API tp_val eom_multiplier(eom_ctx *c, int j);
EOM_API tp_val eom_param(eom_ctx *c, const char *name);
/* The parameter of index k, as eom_model_add_param returned it: the same
 * value as eom_param by name, without the name's lookup, for callbacks
 * that run at every evaluation (the embedded-tuple route of
 * eom_model_run_lagrangian runs them all each time). */
EOM_API tp_val eom_param_at(eom_ctx *c, int k);

/* Run the model's Lagrangian (T - V, or L) once on any libtape context r
 * made for 2n independents, at x = (q, qd) (x may be NULL for the
 * recorder): with the embedded-tuple evaluator (tp_tuple_new) this gives
 * the same derivative blocks as the tape from the same source
 * (tp_tuple_lagrange), with the double evaluator its value. Parameters
 * take their defaults (tp_rec_set_param overrides them in evaluators).
 * The output is named "L". A context of 2n + 1 independents gives the
 * time as the last one, x = (q, qd, t); with 2n, a Lagrangian that reads
 * the time fails (EOM_ERR_RECORD). Returns a status. */
EOM_API int eom_model_run_lagrangian(const eom_model *m, tp_rec *r,
                                     const double *x);

/* ---- systems ---------------------------------------------------------- */

typedef struct eom_system eom_system;

/* Record every callback of m once and prepare the solvers. The system
 * keeps its own copy of names, units and defaults; m may be freed after.
 * On failure *out is NULL and, if errmsg is not NULL, a description is
 * written to errmsg (errmsg_len bytes). */
EOM_API int eom_system_new(eom_system **out, const eom_model *m,
                           char *errmsg, size_t errmsg_len);
EOM_API void eom_system_free(eom_system **s);
/* A second system that shares the recorded tapes of s (read-only) and has
 * its own workspaces, factorizations and results, for another thread:
 * s and its clones may evaluate and integrate at the same time, each in
 * one thread. The clone starts with the parameter values and Baumgarte
 * settings s has now; later changes to either do not reach the other.
 * The tapes live until the last system sharing them is freed, so s and
 * its clones may be freed in any order. Cloning reads s (call it while s
 * is not in use by another thread); nothing is recorded again. On
 * failure *out is NULL and errmsg (may be NULL) says why. */
EOM_API int eom_system_clone(eom_system **out, const eom_system *s,
                             char *errmsg, size_t errmsg_len);
/* Message about the last error of a call on s ("" after a success). */
EOM_API const char *eom_system_errmsg(const eom_system *s);

/* Compiled tapes (docs/libeom.md, "Compiled tapes"). With on = 1 the
 * tapes of s are emitted as C, in the sweeps its evaluations call, built
 * by the system's C compiler (CC, else cc; flags -O1, libtape.md) into a
 * per-user cache ($AUTOEOM_CACHE_DIR, else $XDG_CACHE_HOME/autoeom, else
 * ~/.cache/autoeom), loaded, and checked against the interpreter at the
 * model's initial state; from then on the right-hand sides, energies and
 * probes of s run the compiled code, with the interpreter's results (the
 * constraints' Jacobian and gamma, and the exact Jacobians of the
 * implicit methods, stay interpreted). A second call,
 * or another process, finds the objects in the cache. When anything
 * fails (no compiler, a compiler error, a failed check) s stays on the
 * interpreter and the call returns EOM_WARN_INTERPRETED with the reason
 * in eom_system_errmsg: a warning, s remains fully usable. on = 0 returns
 * s to the interpreter. Clones made afterwards inherit the setting; call
 * it while no system sharing s's tapes is in use by another thread.
 * info (may be NULL) receives what it took. */
typedef struct eom_compiled_info {
    int tapes;      /* tapes of the system that are compiled */
    int cached;     /* of them found in the cache or already compiled */
    int rebuilt;    /* cache entries that failed their checks and were
                       built again */
    double seconds; /* generating, compiling, loading and checking
                       (wall time: the tapes are built side by side) */
    size_t source_bytes; /* generated C source of the tapes compiled now */
} eom_compiled_info;
EOM_API int eom_system_set_compiled(eom_system *s, int on,
                                    eom_compiled_info *info);
/* 1 if s runs compiled tapes, else 0. */
EOM_API int eom_system_compiled(const eom_system *s);

/* How the right-hand side forms and factors the mass matrix M = d2L/dqd2,
 * chosen automatically from the Lagrangian's tape (docs/libeom.md, "The
 * mass matrix's route"). */
typedef enum eom_mass_route {
    EOM_MASS_DENSE = 1,   /* formed with n directions and factored at
                             every evaluation */
    EOM_MASS_CONSTANT = 2, /* M depends on none of q, qd, t (decided
                              from the tape's operations, not from
                              samples): formed and factored once per set
                              of parameter values; an evaluation sweeps
                              the Lagrangian with one direction */
    EOM_MASS_SPARSE = 3   /* constant M, and eom_rhs and eom_multipliers
                             solve M and the (holonomic, fixed)
                             constraints as one sparse system with KLU,
                             with C from a coloured sweep: a cost about
                             linear in n on chains; the integrators keep
                             the constant route */
} eom_mass_route;
/* s's route in eom_rhs (an eom_mass_route value; the tapes are analysed
 * on the first call or evaluation), or EOM_ERR_NULL. */
EOM_API int eom_system_mass_route(eom_system *s);
/* Override the automatic choice: route 0 (auto, the default),
 * EOM_MASS_DENSE (any model), EOM_MASS_CONSTANT (refused with
 * EOM_ERR_ARG, and a message in s, when M is not constant) or
 * EOM_MASS_SPARSE (refused likewise when M is not constant or the model
 * has no constraints, velocity constraints, or constraints that read the
 * time). For comparisons of the routes; all give the same results to
 * rounding. */
EOM_API int eom_system_set_mass_route(eom_system *s, int route);
/* "dense", "constant", "sparse", or "unknown". */
EOM_API const char *eom_mass_route_name(int route);

EOM_API int eom_system_ncoords(const eom_system *s);
/* Constraint rows m: the holonomic ones, then the velocity ones. */
EOM_API int eom_system_nconstraints(const eom_system *s);
/* Of them, the velocity (non-holonomic) rows, the last ones. */
EOM_API int eom_system_nvelocity_constraints(const eom_system *s);
/* Constraint row j's name ("" when unnamed; NULL when j is out of
 * range), and the row of a name (-1 when no row has it). */
EOM_API const char *eom_constraint_name(const eom_system *s, int j);
EOM_API int eom_constraint_index(const eom_system *s, const char *name);
EOM_API int eom_system_nparams(const eom_system *s);
EOM_API int eom_system_nprobes(const eom_system *s);
/* 1 if T and V were given separately (so both are reported), else 0. */
EOM_API int eom_system_has_tv(const eom_system *s);
EOM_API int eom_system_has_dissipation(const eom_system *s);
/* 1 if the energies, the dissipation, the constraints or a probe read the
 * time (a rheonomic model: the calls without a t argument then depend on
 * eom_set_time), else 0. Forces that read the time do not count. */
EOM_API int eom_system_reads_time(const eom_system *s);

/* Names, units (never NULL: "" when none), defaults. NULL / NaN when the
 * index is out of range. */
EOM_API const char *eom_coord_name(const eom_system *s, int i);
EOM_API const char *eom_coord_unit(const eom_system *s, int i);
EOM_API const char *eom_param_name(const eom_system *s, int k);
EOM_API const char *eom_param_unit(const eom_system *s, int k);
EOM_API const char *eom_param_description(const eom_system *s, int k);
EOM_API double eom_param_default(const eom_system *s, int k);
EOM_API const char *eom_probe_name(const eom_system *s, int k);
EOM_API const char *eom_probe_unit(const eom_system *s, int k);
/* Index by name, or -1. */
EOM_API int eom_coord_index(const eom_system *s, const char *name);
EOM_API int eom_param_index(const eom_system *s, const char *name);

/* Parameter values in use (they start at their defaults). Non-finite
 * values are rejected (EOM_ERR_NONFINITE). */
EOM_API int eom_set_param(eom_system *s, int k, double value);
EOM_API double eom_get_param(const eom_system *s, int k);

/* The default initial state x0 = (q0, qd0) of the model (2n values): at
 * the parameters in use when the model set one with eom_model_set_initial
 * (EOM_ERR_NONFINITE when it is not finite there). */
EOM_API int eom_initial_state(const eom_system *s, double *x);

/* Baumgarte stabilization of the constraints at acceleration level:
 * C qdd = gamma - 2 alpha (C qd + dphi/dt) - beta^2 phi (for velocity
 * constraints, A qdd = gamma - 2 alpha psi). Both 0 (the default) turns
 * it off. alpha, beta >= 0, in 1/s. */
EOM_API int eom_set_baumgarte(eom_system *s, double alpha, double beta);

/* The time at which the calls that take no t argument (eom_mass_matrix,
 * eom_constraint_jacobian, eom_residuals, eom_condition, eom_probes_at,
 * eom_project, eom_project_start) evaluate a model that reads the time.
 * It is 0 when the system is made (a clone starts with the time of s);
 * eom_integ_new sets it to t0 and eom_integ_advance to the time it
 * returns at, so the state an integrator hands back is evaluated at its
 * own time. The calls that take t use theirs and leave this time alone.
 * Models that do not read the time ignore it. A non-finite t is refused
 * (EOM_ERR_NONFINITE). */
EOM_API int eom_set_time(eom_system *s, double t);
EOM_API double eom_get_time(const eom_system *s);

/* ---- evaluation at a state -------------------------------------------- */

/* The right-hand side: xd = (qd, qdd) at time t and state x (2n). Any of
 * the results of the same evaluation may then be read with the accessors
 * below at no extra cost. Errors: EOM_ERR_NONFINITE (non-finite x or
 * result, or a Lagrangian that is NaN or infinite at x: a state outside
 * the model's domain), EOM_ERR_SINGULAR_MASS, EOM_ERR_RANK_DEFICIENT. */
EOM_API int eom_rhs(eom_system *s, double t, const double *x, double *xd);

/* The exact Jacobian of the state derivative, A = d(xd)/dx (2n x 2n,
 * row-major) at (t, x): the accelerations differentiated through the
 * Lagrangian's third derivatives, the dissipation, the forces, the
 * constraint forces and multipliers and the Baumgarte terms, from a
 * forward sweep of the system's residual tape (docs/integrators.md). The
 * implicit integrators use it for their Newton iterations. */
EOM_API int eom_state_jacobian(eom_system *s, double t, const double *x,
                               double *A);
/* The Jacobian of the state derivative with respect to the system's
 * parameters, B = d(xd)/dp (2n x np, row-major, parameters in index
 * order) at (t, x), from the same tape: a force or a stiffness that is a
 * parameter is an input of the linearized model. */
EOM_API int eom_param_jacobian(eom_system *s, double t, const double *x,
                               double *B);

/* The structure of ida's sparse iteration matrix dG/dY + cj dG/dY'
 * (docs/integrators.md, "Sparse iteration matrices"), from the system's
 * tapes and valid at every state: *unknowns = 2n + m + 1 (its size),
 * *entries the entries that can be nonzero, *colors the directions of
 * the forward sweep that fills it. Any output may be NULL. Computed on
 * the first call (or ida's first sparse run) and kept. */
EOM_API int eom_dae_pattern_size(eom_system *s, int *unknowns,
                                 long *entries, int *colors);

/* Quantities at a state; each evaluates what it needs. */
EOM_API int eom_mass_matrix(eom_system *s, const double *x, double *M);
/* C = dphi/dq (m x n) and phi (m, may be NULL) at q = x[0..n); for a
 * velocity row, A and phi = 0. */
EOM_API int eom_constraint_jacobian(eom_system *s, const double *x,
                                    double *C, double *phi);
/* The multipliers lambda (m) at (t, x): the generalized constraint force
 * is C^T lambda. */
EOM_API int eom_multipliers(eom_system *s, double t, const double *x,
                            double *lambda);
/* Constraint residuals: phi (m) and the velocity residual C qd +
 * dphi/dt (m; C qd for constraints that do not read the time); either
 * may be NULL. A velocity row has phi = 0 and velocity residual psi =
 * A qd + b. */
EOM_API int eom_residuals(eom_system *s, const double *x, double *phi,
                          double *phidot);
/* Reciprocal condition estimates (1-norm, LAPACK dpocon and KLU's rcond)
 * of M and of S = C M^-1 C^T at x; rcond_S is 1 without constraints. */
EOM_API int eom_condition(eom_system *s, const double *x, double *rcond_M,
                          double *rcond_S);

/* Which constraint rows depend on others at q = x[0..n): the rows of C,
 * each scaled to unit length, by a QR factorization with column pivoting
 * of C^T (LAPACK dgeqp3; a diagnostic: O(n m min(n, m)) operations and
 * n m doubles). A row is dependent when its part outside the span of
 * the rows chosen before it is below tol (<= 0: 1e-9) relative to the
 * largest. *rank receives the rank; dependent (m, may be NULL) receives
 * for each row -1 when it is independent, else the independent row with
 * the largest coefficient in its combination; text (may be NULL) a
 * sentence naming each dependent row and the rows it combines, by the
 * names of eom_constraint_name ("row K" for an unnamed one), e.g.
 * "'drive2' = 1 'drive'". Velocity rows count like holonomic ones. */
EOM_API int eom_constraint_rank(eom_system *s, const double *x, double tol,
                                int *rank, int *dependent, char *text,
                                size_t textlen);

typedef struct eom_energy {
    double T, V;  /* NaN when the model gave a whole Lagrangian */
    double L;     /* the Lagrangian */
    double E;     /* Jacobi integral qd . dL/dqd - L (= T + V for natural
                     systems) */
    double P;     /* dE/dt: the power of the non-conservative forces
                     qd . (-dR/dqd + Q) (<= 0 when only dissipating),
                     plus Pt */
    double Pt;    /* the part of P due to the explicit time: -dL/dt (at
                     fixed q, qd), plus lambda . (C qd), the power of the
                     constraint forces, when the constraints read the
                     time (= -lambda . dphi/dt on them), and lambda .
                     (A qd) for velocity constraints (= -lambda . b on
                     them: 0 when b = 0); 0 for a model that does not
                     read the time and has no velocity constraints */
} eom_energy;
EOM_API int eom_energy_at(eom_system *s, double t, const double *x,
                          eom_energy *e);
/* Values of the probes (nprobes values). A probe that is not finite
 * there (a domain error such as the square root of a negative) gives
 * EOM_ERR_NONFINITE with a message naming it ("the probe 'NAME' is not
 * finite ..."); p still receives every value, that one NaN or infinite.
 * eom_energy_at does not fail for a probe: it reports T, V and E. */
EOM_API int eom_probes_at(eom_system *s, const double *x, double *p);

/* Project x onto phi(q) = 0 and C qd = 0 (C qd + dphi/dt = 0 for
 * constraints that read the time, at the system's time: eom_set_time)
 * with the minimum M-norm correction (Newton iteration on q, until max
 * |phi| <= tol; then one linear correction of qd). A state with max |phi|
 * <= tol and max |C qd| <= tol is left as it is. *iters (may be NULL) receives the number of
 * iterations. EOM_ERR_PROJECTION if it does not converge in 20. During
 * integration the projection after each step uses the factor of M from
 * the step's last evaluation instead of factoring M again. */
EOM_API int eom_project(eom_system *s, double *x, double tol, int *iters);
/* The same with the correction of least Euclidean norm in q and in qd:
 * the smallest change of the coordinates, for an initial state set off
 * the constraints (the M-norm correction moves every coordinate coupled
 * through M, such as the deflections of a flexible link). */
EOM_API int eom_project_start(eom_system *s, double *x, double tol,
                              int *iters);
/* Assembly of a closed loop from the coordinates the user gives: the
 * coordinates with held[i] != 0 and their rates keep their values in x;
 * the others are solved so that max |phi| <= tol (Gauss-Newton steps of
 * least norm on the free coordinates, halved while they do not reduce
 * |phi|, at most 50) and then C qd + dphi/dt = 0 (one least-norm
 * correction of the free rates), at the system's time. *iters (may be
 * NULL) receives the iterations on q. EOM_ERR_PROJECTION with a message
 * naming the constraint that stays open and the held coordinates when
 * the loop cannot close (a linkage that cannot reach the given input, a
 * start too far from any closure) or when the held rates contradict the
 * constraints; x is then left as given. */
EOM_API int eom_assemble(eom_system *s, double *x, const int *held,
                         double tol, int *iters);

/* ---- linearization ---------------------------------------------------- */

/* Linearization about an equilibrium q (qd = 0): M, the stiffness
 * K = -d2L/dq2 - dQ/dq - sum_k lambda_k d2phi_k/dq2 and the damping
 * D = d2R/dqd2 - dQ/dqd (each n x n; Q the declared forces at qd = 0),
 * reduced to the null space of C (nr = n - rank C coordinates; a
 * rank-deficient C is allowed), and the natural
 * frequencies omega (rad/s, ascending) of K v = omega^2 M v on that null
 * space. The multipliers are those that hold the system at rest at q; if
 * q is not at rest (off the constraints, or an unbalanced force beyond a
 * relative 1e-6) the call fails with EOM_ERR_ARG: find the rest state
 * with eom_equilibrium first. A force whose dQ/dq is not symmetric (a
 * follower load) leaves no undamped frequencies: EOM_ERR_MODEL, with a
 * message saying so. eom_linearize overwrites *lin without freeing it (free an earlier
 * result with eom_linear_free first) and leaves it zeroed on failure.
 * A model whose Lagrangian, dissipation, constraints or forces read the
 * time has no state of rest: EOM_ERR_MODEL. docs/linearization.md has
 * the details. */
typedef struct eom_linear {
    int n, nr;       /* coordinates, and independent ones */
    double *M, *K, *D; /* n x n */
    double *N;       /* n x nr: orthonormal basis of the null space of C */
    double *Mr, *Kr, *Dr; /* nr x nr reduced matrices */
    double *omega;   /* nr natural frequencies; a negative value -w means
                        an unstable direction with K v = -w^2 M v */
    double *modes;   /* n x nr mode shapes in the full coordinates */
} eom_linear;
EOM_API int eom_linearize(eom_system *s, const double *q, eom_linear *lin);
EOM_API void eom_linear_free(eom_linear *lin);

/* The state-space linearization about any state (t, x), moving or at
 * rest:  d(dx)/dt = A dx + B dp,  A = d(xd)/dx (2n x 2n) and B = d(xd)/dp
 * (2n x np, every parameter in index order), exact, with the forces Q,
 * the gyroscopic, dissipation and constraint forces and the Baumgarte
 * terms (eom_state_jacobian, eom_param_jacobian). With constraints the
 * perturbations that keep phi = 0 and dphi/dt = 0 (and psi = 0 for
 * velocity constraints, which remove one dimension each, not two) are
 * dx = T z, T (2n x nz) an orthonormal basis (from one SVD; redundant
 * constraints are allowed); Ar = T^T A T (nz x nz) and Br = T^T B (nz x np) are the
 * reduced matrices, and eig_re, eig_im the eigenvalues of Ar sorted by
 * real, then imaginary part. Without constraints T is the identity and
 * Ar = A. All matrices row-major. On failure *lin is zeroed. Free with
 * eom_state_linear_free. docs/linearization.md has the details. */
typedef struct eom_state_linear {
    int n2, np, nz;   /* states 2n, parameters, reduced states */
    double t;
    double *x;        /* 2n: the state linearized about */
    double *A, *B;    /* 2n x 2n, 2n x np */
    double *T;        /* 2n x nz */
    double *Ar, *Br;  /* nz x nz, nz x np */
    double *eig_re, *eig_im; /* nz */
} eom_state_linear;
EOM_API int eom_linearize_state(eom_system *s, double t, const double *x,
                                eom_state_linear *lin);
EOM_API void eom_state_linear_free(eom_state_linear *lin);

/* Static equilibrium: from q (n, updated in place), Newton iteration
 * (with a line search) on dL/dq(q, 0) + Q(q, 0) + C^T lambda = 0,
 * phi(q) = 0 (Q every declared force at qd = 0) with the tape's second
 * derivatives, to max |residual| <= tol. A model whose Lagrangian,
 * dissipation, constraints or forces read the time is refused
 * (EOM_ERR_MODEL, naming what reads it). On failure
 * (EOM_ERR_NOT_CONVERGED after 50 steps, or another error) q is restored
 * to the guess. *iters (may be NULL)
 * receives the number of Newton steps. */
EOM_API int eom_equilibrium(eom_system *s, double *q, double tol,
                            int *iters);

/* ---- integration ------------------------------------------------------ */

typedef enum eom_method {
    EOM_RK4,   /* fixed-step classical Runge-Kutta (the paper's) */
    EOM_ERK,   /* ARKODE ERKStep, adaptive explicit, Verner 6(5), 8 stages */
    EOM_ADAMS, /* CVODE Adams-Moulton, fixed-point iteration */
    EOM_BDF,   /* CVODE BDF, Newton iteration with a dense Jacobian */
    EOM_IDA,   /* IDA on the index-1 form (see docs/integrators.md) */
    EOM_ESDIRK, /* ARKODE ARKStep, an implicit, L-stable ESDIRK 5(4) for
                   stiff models (see docs/integrators.md) */
    EOM_IMEX    /* ARKODE ARKStep, an additive (IMEX) ARK 5(4): the elastic
                   and dissipative forces (-dV/dq - dR/dqd) with q' = qd
                   implicit, the inertial terms, Q and the constraints'
                   gamma explicit; needs T and V given apart (see
                   docs/integrators.md, "imex") */
} eom_method;

/* Name as used on the command line ("rk4", "erk", "adams", "bdf", "ida",
 * "esdirk", "imex") and back (-1 for an unknown name). */
EOM_API const char *eom_method_name(eom_method m);
EOM_API int eom_method_from_name(const char *name);

typedef struct eom_opts {
    eom_method method; /* eom_opts_default: EOM_RK4, the paper's fixed
                          step dt with no error control: a step too long
                          for the motion gives a wrong run whose only
                          sign is the energy drift (eom_run_judge in
                          eom/run.h judges it). eom-run and eom-ensemble
                          use EOM_ERK, error-controlled, by default */
    double dt;        /* RK4: the step; others: the first step (0: auto) */
    double rtol, atol; /* adaptive methods */
    long max_steps;   /* per call of eom_integ_advance (default 1e7) */
    int project;      /* project onto the constraints (default 1; ignored
                         without constraints): the start, when it is off
                         them by more than proj_tol, by eom_integ_new with
                         every method (eom_project_start); then after each
                         step with rk4, erk and bdf, at each requested
                         time with adams and ida (docs/integrators.md) */
    double proj_tol;  /* projection tolerance on |phi| (default 1e-12) */
    const double *atol_vec; /* adaptive methods: NULL (default) for atol on
                               every component, or 2n absolute tolerances
                               for (q, qd), each > 0 and finite, for
                               coordinates of different scales (angles
                               and deflections); copied by eom_integ_new.
                               W and IDA's multipliers keep atol */
    const char *erk_table;  /* erk: the name of an ARKODE ERK table, such
                               as "ARKODE_DORMAND_PRINCE_7_4_5" (docs/
                               integrators.md lists them); NULL (default):
                               "ARKODE_VERNER_8_5_6"; copied */
    int tol_per_step; /* 0 (default): rtol and atol are targets for the
                         global error, and adams, bdf, ida, esdirk and
                         imex are handed the tighter per-step tolerances
                         calibrated to meet them (docs/integrators.md, "What the
                         tolerances mean"); 1: every method gets rtol and
                         atol as given, for its own per-step error test */
    int max_order;    /* adams, bdf, ida: the highest order used, 1 to
                         12 (adams) or 5 (bdf, ida); 0 (default): 12 or
                         5. bdf at order 2 or less is A-stable, for stiff
                         oscillatory motion. Ignored by rk4 and erk. */
    int dq_jacobian;  /* bdf, ida, esdirk: 0 (default) for the exact
                         Jacobian of the equations (eom_state_jacobian);
                         1 for SUNDIALS' difference quotients, kept as a
                         reference for tests and benchmarks. imex: 0 for
                         the stiff terms of its implicit part's Jacobian
                         (Hessians of V and R), 1 for ARKODE's difference
                         quotient of the implicit part */
    int n_sens;       /* adams, bdf and ida: forward sensitivities of
                         the trajectory with respect to n_sens inputs (0,
                         default: none), for models with or without
                         constraints; read them with
                         eom_integ_sensitivities. Other methods refuse
                         them (EOM_ERR_ARG) */
    const int *sens;  /* [n_sens] the inputs: a parameter index k
                         (0 .. np-1), or np + i for the initial value of
                         state i (coordinate i for i < n, the rate of
                         coordinate i - n otherwise); copied. With
                         constraints, a start moved along an input is
                         taken back onto them by the least change of the
                         coordinates (eom_project_start): the
                         sensitivities at t0 are tangent to the
                         constraints, not unit vectors */
    int linear_solver; /* ida and bdf: the linear solver of their Newton
                          iteration: EOM_LINSOL_AUTO (0, default) chooses
                          by the structure of the iteration matrix, which
                          comes from the model's tapes (docs/integrators.md,
                          "Sparse iteration matrices"); EOM_LINSOL_DENSE
                          (1) dense LU; EOM_LINSOL_SPARSE (2) KLU on a
                          compressed-column matrix (not with
                          dq_jacobian; bdf refuses it with constraints or
                          when the mass matrix couples most coordinates).
                          esdirk is dense whatever is asked but
                          EOM_LINSOL_SPARSE, which it refuses; methods
                          without a Newton iteration ignore it.
                          eom_stats.linear_solver says which was used */
} eom_opts;

/* eom_opts.linear_solver and eom_stats.linear_solver. */
enum {
    EOM_LINSOL_AUTO = 0,   /* options: choose; stats: no linear solver */
    EOM_LINSOL_DENSE = 1,  /* dense LU (SUNLinSol_Dense) */
    EOM_LINSOL_SPARSE = 2  /* KLU on a sparse matrix (SUNLinSol_KLU) */
};

/* The names eom_opts.erk_table accepts: the k-th for k = 0, 1, ..., then
 * NULL. */
EOM_API const char *eom_erk_table_name(int k);


/* Defaults: RK4 with dt = 1e-3 (a fixed step, no error control: set
 * method = EOM_ERK for a run held to rtol and atol, as eom-run and
 * eom-ensemble do), rtol = 1e-8, atol = 1e-10, no atol_vec, the default
 * ERK table. */
EOM_API void eom_opts_default(eom_opts *o);

typedef struct eom_stats {
    long steps;          /* accepted steps */
    long rhs_evals;      /* right-hand-side evaluations, all causes */
    long failures;       /* error-test and convergence failures */
    long jac_evals;      /* Jacobian evaluations (bdf, ida, esdirk,
                            imex) */
    long projections;    /* projections applied */
    double wall_time;    /* seconds spent in eom_integ_advance */
    double max_residual; /* largest |phi| seen after a step */
    /* the health of the constraint solve, without failing the run: */
    double min_rcond_S;  /* smallest reciprocal condition estimate of
                            C M^-1 C^T met by an evaluation (KLU's pivot
                            estimate, 0 where KLU could not factor it; 1
                            without constraints) */
    long svd_solves;     /* evaluations whose multipliers came from the
                            filtered SVD (redundant constraints, or near a
                            singular configuration: docs/theory.md) */
    long singular_passes;  /* singular positions passed (the rank of C
                              below its rank at the start, after a step) */
    long branch_switches;  /* of those, passes that came out on another
                              assembly branch: a velocity jump that the
                              accelerations do not explain (docs/
                              integrators.md, "Singular positions"); the
                              run goes on */
    double first_branch_switch; /* the time of the first (0 if none) */
    long singular_handovers; /* singular stretches that another method
                                integrated, the method restarting after
                                each: adams's and ida's to bdf, bdf's,
                                esdirk's and imex's (and adams's and
                                ida's where bdf failed) to erk
                                (docs/integrators.md, "Singular
                                positions"); the counts above include
                                theirs */
    long singular_handovers_erk; /* of those, the ones erk integrated */
    /* what the error test was given (docs/integrators.md, "What the
     * tolerances mean"): */
    double step_tol;     /* the per-step relative tolerance for rtol:
                            calibrated for adams, bdf, ida, esdirk and
                            imex, rtol itself for erk (and with
                            tol_per_step), 0 for rk4 */
    double tol_reachable; /* 0, or the tolerance the method keeps
                            instead of a tighter one asked for: its
                            calibration wanted a per-step tolerance below
                            what double precision allows (3e-16; with
                            constraints 1e-14 for ida, 1e-10 for bdf near
                            singular positions) and held it at that floor,
                            which keeps the global error near this value
                            rather than near rtol and atol */
    int linear_solver;   /* the Newton iteration's linear solver:
                            EOM_LINSOL_DENSE, EOM_LINSOL_SPARSE, or 0 for
                            methods without one (rk4, erk, adams) */
    double jac_time;     /* seconds spent forming Jacobians or iteration
                            matrices (bdf, ida, esdirk with the exact
                            Jacobian; 0 otherwise), part of wall_time */
    int mass_route;      /* the mass matrix's route in the right-hand
                            side (eom_system_mass_route) */
} eom_stats;

typedef struct eom_integ eom_integ;

/* An integrator for s from (t0, x0); W, the work done on the system by
 * its non-conservative forces with the sign that makes E + W constant
 * (W >= 0 is the energy dissipated), starts at 0 and is integrated beside
 * the state: dW/dt = -P (eom_energy). For a model that reads the time, W
 * also holds the energy taken out by the explicit time dependence and
 * the moving constraints (-Pt), so E + W stays constant, but W may then
 * have either sign. The integrator borrows s. A run's numbers depend only on its
 * inputs (s's parameters, the options, t0, x0), not on what s evaluated
 * before: the same run on s or on a clone of it gives the same bits. */
EOM_API int eom_integ_new(eom_integ **out, eom_system *s, const eom_opts *o,
                          double t0, const double *x0);
EOM_API void eom_integ_free(eom_integ **it);
EOM_API const char *eom_integ_errmsg(const eom_integ *it);

/* Advance to exactly tout > current time; x (2n) and W receive the state
 * there (W may be NULL). On a solver failure, returns EOM_ERR_SOLVER with
 * the solver's flag name and time in the message, and x holds the last
 * good state. */
EOM_API int eom_integ_advance(eom_integ *it, double tout, double *x,
                              double *W);
EOM_API int eom_integ_stats(const eom_integ *it, eom_stats *st);

/* The sensitivities at the time of the last eom_integ_advance (at t0
 * before the first): S[i * n_sens + k] = d x_i / d(input k) for the 2n
 * states x = (q, qd) and the inputs of eom_opts.sens, row-major 2n x
 * n_sens. CVODES (adams, bdf) integrates them beside the state
 * (staggered, on the state's steps, their corrector with the state's
 * tolerances scaled by each parameter's size) with right-hand sides
 * A S + B from the residual tape, exact, the constraint forces' and
 * multipliers' changes included; IDAS (ida) the same with exact
 * residuals of the DAE's sensitivities and in its error test. With
 * constraints and eom_opts.project they are the derivatives of the
 * projected state x returned: projected with the linearized projection,
 * so that C S_q + dphi/dp = 0 and d(C qd + dphi/dt)/d(q, qd, p) along
 * them is 0 (docs/integrators.md, "Sensitivities"). A run with
 * sensitivities that adams or ida would hand to bdf at a singular
 * position stops there (EOM_ERR_RANK_DEFICIENT). EOM_ERR_ARG when the
 * integrator computes none. */
EOM_API int eom_integ_sensitivities(const eom_integ *it, double *S);

#ifdef __cplusplus
}
#endif
#endif /* EOM_EOM_H */
