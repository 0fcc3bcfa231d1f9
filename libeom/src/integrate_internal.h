/* integrate_internal.h - what the integrator backends share. An eom_integ
 * holds the common state; each method (RK4, ERK, Adams/BDF, IDA) supplies
 * an ops table and keeps its own data behind impl.
 *
 * The integrated vector is y = (q, qd, W), N = 2n + 1 values: W, the work
 * done against the non-conservative forces, rides along so that E + W is
 * conserved (dW/dt = -qd . (-dR/dqd + Q)).
 */
#ifndef EOM_INTEGRATE_INTERNAL_H
#define EOM_INTEGRATE_INTERNAL_H

#include <arkode/arkode_arkstep.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>

#include "eom_internal.h"

typedef struct eom_integ_ops {
    const char *name;
    /* Set up the method from it->t, it->y; a status. */
    int (*init)(eom_integ *it);
    /* Advance it->t, it->y to exactly tout; a status with a message in
     * it->msg on failure (it->y then holds the last good state). */
    int (*advance)(eom_integ *it, double tout);
    /* Add the method's own counters to it->st (steps, evaluations, ...). */
    void (*stats)(const eom_integ *it, eom_stats *st);
    void (*destroy)(eom_integ *it);
} eom_integ_ops;

#define EOM_TABLE_NAME_LEN 64

struct eom_integ {
    eom_system *s;
    eom_opts o;
    int n;          /* coordinates */
    int N;          /* length of y: 2n + 1 */
    double t;       /* time of y */
    double *y;      /* [N] current state */
    eom_stats st;   /* common counters: rhs_evals, projections, wall time,
                       max_residual (methods add theirs in stats()) */
    int failed;     /* a failure is final: later advances return it */
    char msg[2 * EOM_MSG_LEN]; /* room to quote the system's message */
    const eom_integ_ops *ops;
    void *impl;
    double *atolv;  /* [2n] per-component atol (o.atol_vec), or NULL */
    long svd_base;  /* the system's SVD count when this integrator began */
    char erk_table[EOM_TABLE_NAME_LEN]; /* o.erk_table, or "" */
    struct eom_branch *branch; /* with constraints: the assembly branch
                                  (branch.c) */
    double pivot_saved;  /* the system's mass_pivot_min before this
                            integrator set its own (restored by
                            eom_integ_free) */
    int refuse_singular; /* adams, ida with constraints: an evaluation at
                            a singular or redundant constraint system is
                            an error (eom__integ_rhs) */
    int loose_floor;     /* bdf with constraints, near a singular position:
                            the per-step tolerance floor is 1e-10
                            (integrate.c) */
    int was_loose;       /* loose_floor was set at some time */
    /* adams and ida hand a singular stretch to a bdf integrator, bdf,
     * esdirk and imex (and adams and ida once bdf failed one) to an erk
     * integrator (integrate_handover.c): */
    int handing;         /* this is that integrator: stop after the
                            stretch */
    int seen_singular;   /* handing: the stretch's singular part met */
    int stretch_over;    /* handing: stopped after it */
    double t_refused;    /* the time of the evaluation refused last (adams,
                            ida) or of the last failure (the others),
                            and handing: the method's */
    struct eom_integ *sub; /* that integrator, while a stretch goes on
                              across output times */
    int branch_borrowed; /* branch belongs to the integrator handing over */
    long handovers;      /* stretches handed over */
    long handovers_erk;  /* of those, the ones erk integrated */
    int stretch_erk;     /* adams, ida: a stretch's bdf failed, erk
                            integrates the later ones */
    eom_stats handed;    /* counts of the stretches' runs and of the method's
                            instances before each restart */
    double handed_reach; /* the largest tol_reachable of those bdf runs */
    int *sens;           /* [o.n_sens] the inputs of the sensitivities */
    double *S;           /* [2n x o.n_sens] row-major: the sensitivities at
                            t (integrate_cvode.c) */
    int kkt;             /* rk4, erk, adams on a system whose eom_rhs is
                            sparse (kkt_sparse.c): evaluations, the
                            projection and the branch monitor take the
                            sparse path (kkt_integ.c) while not kkt_near */
    int kkt_near;        /* the last measure said: near a singular
                            position, along the dense route */
    int linsol;          /* eom_stats.linear_solver: EOM_LINSOL_DENSE for
                            bdf and esdirk, ida's choice, 0 otherwise */
};

/* Seconds on a monotonic clock (eom_stats.wall_time, jac_time). */
double eom__integ_now(void);

/* The highest order of a variable-order method (adams 12, bdf and ida
 * 5; 0 for the others), and the one an integrator uses (o.max_order, or
 * the method's own). */
int eom__integ_top_order(eom_method m);
int eom__integ_max_order(const eom_integ *it);

/* The per-step tolerance a solver's error test is given for a tolerance
 * tol of the caller's: tol itself with o.tol_per_step and for rk4 and
 * erk; for adams, bdf and ida the tighter tolerance calibrated to keep
 * the global error near tol (docs/integrators.md). */
double eom__integ_step_tol(const eom_integ *it, double tol);
/* eom_stats.tol_reachable: where a calibrated tolerance (rtol, atol or
 * an atol_vec entry) wanted a per-step tolerance below the floor, the
 * tolerance that the floor is calibrated for; else 0. */
double eom__integ_tol_reachable(const eom_integ *it);

/* The per-step absolute tolerance of each of the len components of a
 * solver's unknowns: from atol_vec for the first 2n (q, qd) when given,
 * from atol for the rest and otherwise. */
void eom__integ_atol(const eom_integ *it, double *atol, int len);

/* yd = dy/dt at (t, y): (qd, qdd, dW/dt). Counts the evaluation. Returns
 * the status of eom__evaluate (message in it->msg on failure), or, with
 * it->refuse_singular, EOM_ERR_RANK_DEFICIENT where the multipliers
 * needed the filtered SVD (a singular position or redundant
 * constraints), with a message naming the time, the condition estimate,
 * the likely cause and the methods that can go on. */
int eom__integ_rhs(eom_integ *it, double t, const double *y, double *yd);
/* Appends to it->msg the constraint rows that depend on others at the
 * state y (eom_constraint_rank's sentence: "rank 1 of 2 rows there:
 * 'rod2' = 1 'rod'"), when there are any; nothing for a model whose
 * n x m Jacobian is too large for a dense diagnostic (over 4e6 values).
 * Changes the system's evaluation buffers. */
void eom__integ_name_rows(eom_integ *it, const double *y);

/* J = d(yd)/dy at (t, y), (2n + 1) square, column-major with leading
 * dimension ldj: the exact Jacobian from the residual tape, W's row
 * included (residual.c). Returns like eom__integ_rhs (message in
 * it->msg); not counted as a right-hand side. */
int eom__integ_jacobian(eom_integ *it, double t, const double *y,
                        double *J, int ldj);

/* The assembly-branch monitor (branch.c): made at the start (t, x),
 * checked after each accepted step (t, x = (q, qd)); a switch is
 * counted, not an error. The calls evaluate C at q, and inside a singular
 * passage the right-hand side (counted in *evals): s's results change. */
typedef struct eom_branch eom_branch;
int eom__branch_new(eom_branch **out, eom_system *s, double t,
                    const double *x);
int eom__branch_check(eom_branch *b, eom_system *s, double t,
                      const double *x, long *evals);
/* The integrators' sparse path (kkt_integ.c), away from singular
 * positions: a monitor made from the row lengths of C (norm, m) with
 * the full rank m at the start, and a step at (t, x) known to be away
 * from any singular position (nothing evaluated; a pass under way is
 * ended by eom__branch_check instead). */
int eom__branch_new_regular(eom_branch **out, eom_system *s, double t,
                            const double *x, const double *norm);
int eom__branch_in_pass(const eom_branch *b);
void eom__branch_regular(eom_branch *b, double t, const double *x);
/* switches seen, the time of the first, and the singular neighbourhoods
 * passed (any of b, first, passes may be NULL) */
long eom__branch_switches(const eom_branch *b, double *first,
                          long *passes);
void eom__branch_free(eom_branch **b);

/* Remember the monitor as it is (at an output time), and go back to what
 * was remembered: a run repeated from there (a handover, integrate_
 * handover.c) counts its passes once. */
int eom__branch_mark(eom_branch *b);
void eom__branch_rewind(eom_branch *b);

/* After an accepted step at (t, y): the branch check, with a message in
 * it->msg on failure. A no-op without constraints. */
int eom__integ_branch(eom_integ *it, double t, const double *y);

/* After an accepted step: project y onto the constraints when the system
 * has them and projection is on, and track the largest residual. */
int eom__integ_project(eom_integ *it, double *y);
double eom__integ_proj_qtol(const eom_integ *it, const double *y);

/* A failure with a message (the arguments may quote it->msg); marks the
 * integrator failed. */
int eom__integ_fail(eom_integ *it, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* An integrator from (t0, y0), y0 holding q, qd and W (N values). With
 * fresh, s forgets its earlier evaluations and its run counters start
 * over (eom_integ_new); without, they go on (a handover). */
int eom__integ_create(eom_integ **out, eom_system *s, const eom_opts *o,
                      double t0, const double *y0, int fresh);

/* handing: after an accepted step at t, 1 when the singular stretch is
 * behind: rcond of C M^-1 C^T is above 1e-2, and it has been below 1e-3
 * at an accepted step or t is past it->t_refused. */
int eom__integ_stretch_done(eom_integ *it, double t);

/* adams, ida: the advance to tout failed with EOM_ERR_RANK_DEFICIENT at
 * a singular position after setup; bdf, esdirk, imex: it failed so that
 * eom__integ_hands_over says yes; or a stretch handed over earlier goes
 * on (it->sub): integrate the stretch with bdf (adams, ida) or erk from
 * (it->t, it->y), and after it restart the method and go on to tout. A
 * status (integrate_handover.c). */
int eom__integ_handover(eom_integ *it, double tout);
/* 1 when bdf, esdirk or imex failed with status rc at a singular
 * position that erk may pass: a solver failure with projection on, no
 * sensitivities, and rcond of C M^-1 C^T below 1e-2 at the last
 * evaluation. */
int eom__integ_hands_over(const eom_integ *it, int rc);

/* ---- what the SUNDIALS methods share (integrate_sundials.c) ---------- */

/* Why a SUNDIALS method stopped: the status and message of its most
 * recent callback, and the solver's own message about its last error. */
typedef struct eom_sun_report {
    int cb_status;
    char cb_msg[2 * EOM_MSG_LEN];
    char sun_msg[EOM_MSG_LEN];
} eom_sun_report;

/* A solver's scalar and vector tolerance setters (CVodeSStolerances,
 * IDASVtolerances, ...). */
typedef int (*eom_sun_ss)(void *mem, double rtol, double atol);
typedef int (*eom_sun_sv)(void *mem, double rtol, N_Vector atol);
/* Give the solver mem the per-step tolerances of it for len unknowns:
 * scalar ones, or a vector with atol_vec. Returns the setter's flag, or
 * 1 when out of memory. */
int eom__sun_tolerances(eom_integ *it, void *mem, SUNContext ctx, int len,
                        eom_sun_ss ss, eom_sun_sv sv);

/* Forget the previous advance's callback status and messages. */
void eom__sun_report_reset(eom_sun_report *r);
/* The solver's return value for a callback status: 0, +1 (recoverable:
 * EOM_ERR_NONFINITE, the solver retries with a smaller step) or -1;
 * remembers the status and it->msg in r. */
int eom__sun_cb_result(eom_integ *it, eom_sun_report *r, int rc);
/* A SUNDIALS error handler (user data: an eom_sun_report) that keeps the
 * solver's last error message instead of printing it. */
void eom__sun_error(int code, const char *module, const char *function,
                    char *msg, void *user);
/* An allocation during setup failed: EOM_ERR_NOMEM with a message. */
int eom__integ_nomem(eom_integ *it);
/* A failed setup call: a message naming the call and the flag (flag_name
 * as allocated by SUNDIALS' GetReturnFlagName; freed here); the status
 * is EOM_ERR_NOMEM when mem_fail, else EOM_ERR_SOLVER. */
int eom__sun_setup_failed(eom_integ *it, char *flag_name, int mem_fail,
                          const char *call);
/* A solver's failure at time t: the status (the failed callback's, or
 * EOM_ERR_SOLVER) with a message naming the method, the flag (flag_name
 * as allocated by SUNDIALS; freed here), the time and the cause. */
int eom__sun_failed(eom_integ *it, const eom_sun_report *r,
                    const char *method, char *flag_name, double t);
/* The smallest step to allow while advancing from t to tout. */
double eom__sun_min_step(double t, double tout);

/* ---- what the ARKODE methods share (integrate_arkstep.c) ------------- */

/* The functions of an ARKODE stepper that the shared code calls: ERKStep's
 * and ARKStep's have the same signatures under their own prefixes. */
typedef struct eom_ark_stepper {
    void (*free_mem)(void **mem);
    int (*set_min_step)(void *mem, sunrealtype hmin);
    int (*set_stop_time)(void *mem, sunrealtype tstop);
    int (*evolve)(void *mem, sunrealtype tout, N_Vector yout,
                  sunrealtype *tret, int itask);
    int (*get_current_time)(void *mem, sunrealtype *tcur);
    int (*get_last_step)(void *mem, sunrealtype *hlast);
    char *(*flag_name)(long flag); /* allocated, as GetReturnFlagName */
} eom_ark_stepper;
/* The table of the stepper whose functions begin with P (ERK, ARK). */
#define EOM_ARK_STEPPER(P)                                                 \
    {                                                                      \
        .free_mem = P##StepFree, .set_min_step = P##StepSetMinStep,        \
        .set_stop_time = P##StepSetStopTime, .evolve = P##StepEvolve,      \
        .get_current_time = P##StepGetCurrentTime,                         \
        .get_last_step = P##StepGetLastStep,                               \
        .flag_name = P##StepGetReturnFlagName,                             \
    }
extern const eom_ark_stepper eom__erkstep; /* integrate_arkode.c */
extern const eom_ark_stepper eom__arkstep; /* integrate_arkstep.c */

/* The solver of an ARKODE method (erk, esdirk, imex). It is the first
 * member of each method's impl, so that the functions below, given the
 * integrator (as a callback's user data), find it at it->impl. */
typedef struct eom_ark {
    const eom_ark_stepper *step; /* NULL before eom__ark_start */
    SUNContext ctx;
    N_Vector y;                /* [N] the solver's state */
    SUNMatrix A;               /* dense Newton matrix (ARKStep), or NULL */
    SUNLinearSolver LS;        /* dense LU (ARKStep), or NULL */
    void *mem;                 /* ERKStep or ARKStep memory */
    eom_sun_report rep;        /* why it stopped */
} eom_ark;

/* The solver's return value for a callback status (eom__sun_cb_result
 * with it->impl's report). */
int eom__ark_cb_result(eom_integ *it, int rc);
/* The right-hand side as an ARKRhsFn (user data: the integrator). */
int eom__ark_rhs(sunrealtype t, N_Vector y, N_Vector yd, void *user);
/* After each accepted step, an ARKPostProcessFn (user data: the
 * integrator): project y in place (or only track the residual when
 * projection is off), and watch the assembly branch. */
int eom__ark_postprocess(sunrealtype t, N_Vector y, void *user);
/* Start a with the stepper step: the context, and the state vector
 * holding it->y; a status. */
int eom__ark_start(eom_integ *it, eom_ark *a, const eom_ark_stepper *step);
/* Free what a holds; NULL members are skipped. */
void eom__ark_free(eom_ark *a);
/* A failed setup call of it->impl's stepper: a status and a message
 * naming the call and the flag. */
int eom__ark_setup_failed(eom_integ *it, int flag, const char *call);
/* Advance it->impl's solver to exactly tout (the stop time); messages
 * name method. A status (it->y keeps the last output state on
 * failure). */
int eom__ark_advance(eom_integ *it, double tout, const char *method);

/* ARKStep with a dense Newton solver (esdirk, imex): start a
 * (eom__ark_start) and create its solver from the parts fe and fi
 * (fe NULL: all implicit), with the implicit and explicit tables itable
 * and etable (ARKODE_ERK_NONE: none) and the Jacobian jac of fi (unused
 * with o.dq_jacobian); the tolerances, step limits and, with
 * constraints, eom__ark_postprocess. A status with a message. */
int eom__ark_implicit_init(eom_integ *it, eom_ark *a, ARKRhsFn fe,
                           ARKRhsFn fi, ARKLsJacFn jac,
                           ARKODE_DIRKTableID itable,
                           ARKODE_ERKTableID etable);
/* Steps, failed steps (error test and Newton) and Jacobians of an ARKStep
 * solver (it->impl). */
void eom__ark_stats(const eom_integ *it, eom_stats *st);

/* The methods. */
extern const eom_integ_ops eom__rk4_ops;
extern const eom_integ_ops eom__erk_ops;
extern const eom_integ_ops eom__cvode_ops; /* Adams and BDF */
extern const eom_integ_ops eom__ida_ops;
extern const eom_integ_ops eom__esdirk_ops;
extern const eom_integ_ops eom__imex_ops;

/* imex (integrate_imex.c), for white-box tests: the split of the
 * right-hand side at (t, y) into its explicit part fe and implicit part fi
 * (N values each; fe + fi is eom__integ_rhs's yd), and the Jacobian of the
 * implicit part that its Newton matrix uses (N x N, column-major, leading
 * dimension N). EOM_ERR_ARG when it is not an imex integrator; otherwise
 * a status with a message in it->msg. */
int eom__imex_split(eom_integ *it, double t, const double *y, double *fe,
                    double *fi);
int eom__imex_jacobian(eom_integ *it, double t, const double *y, double *J);
/* imex, for tests: take fixed steps of h > 0 from now on (no error
 * control); EOM_ERR_ARG as above or for a bad h. */
int eom__imex_fixed_step(eom_integ *it, double h);

#endif /* EOM_INTEGRATE_INTERNAL_H */
