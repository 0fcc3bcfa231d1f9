/* integrate_imex.c - EOM_IMEX: ARKODE's ARKStep as an additive
 * (implicit-explicit) Runge-Kutta method on y = (q, qd, W), the stiff part
 * of the motion implicit and the rest explicit, with the ARK5(4)8L[2]SA
 * pair of SUNDIALS 6.4 (ARKODE_ARK548L2SA_DIRK_8_4_5 with
 * ARKODE_ARK548L2SA_ERK_8_4_5: 8 stages, order 5, embedded order 4; the
 * implicit table is esdirk's, L-stable and stiffly accurate).
 *
 * The split (docs/integrators.md, "imex"). With F_s = -dV/dq - dR/dqd the
 * elastic and dissipative forces (V the potential, R the dissipation) and
 * G = M^-1 - Y S^-1 Y^T (Y = M^-1 C^T, S = C Y; G = M^-1 without
 * constraints) the M-orthogonal projection of M^-1 onto the motions the
 * constraints allow:
 *
 *   f_I(y) = (qd, G F_s, 0)      implicit: the stiff oscillators
 *   f_E(y) = f(y) - f_I(y)       explicit: (0, the rest of qdd, -P)
 *
 * The kinematic part q' = qd is implicit with the forces: a spring's
 * stiffness makes the pair (q' = qd, qd' = -k q / m) stiff, not the second
 * equation alone; with q' = qd explicit every stage's q would be explicit
 * data and the spring would be integrated explicitly whatever the Newton
 * matrix. The multipliers split as the forces do (lambda is linear in
 * them): the implicit acceleration G F_s satisfies C a = 0, the explicit
 * one carries gamma (and the Baumgarte terms). The inertial forces (the
 * gyroscopic and centrifugal terms, dT/dq - (d2T/dqd dq) qd), the user's
 * forces Q and the power P of W are explicit. Gravity is part of V and so
 * implicit: the tapes do not tell a beam's strain energy from its weight,
 * and an implicit non-stiff term costs nothing more.
 *
 * V is the "V" output of the system's energy tape, which exists when the
 * model gives T and V apart; a potential tape of its own (2n independents,
 * the output V alone: dead-code elimination drops T and the probes) is
 * recorded from it here with tp_call, so the integrator replays only V.
 * A model that gives a whole Lagrangian L is refused at setup.
 *
 * Newton matrix: I - gamma h J_I with the stiff terms of f_I's Jacobian,
 *
 *   J_I = [[0, I, 0], [-G (K + B), -G D, 0], [0, 0, 0]],
 *   K = d2V/dq2, B = d2R/dqd dq, D = d2R/dqd2,
 *
 * from Hessians of the potential and dissipation tapes. It leaves out the
 * derivatives of G (of M(q) and C(q)) times F_s: terms of the size of the
 * forces, not of the stiffness, which ARKODE's modified Newton iteration
 * absorbs. eom_opts.dq_jacobian = 1 gives ARKODE's difference quotient of
 * f_I instead (exact up to differencing; N more evaluations each).
 *
 * f_E and f_I at one state come from one evaluation of the model: the last
 * state's split is kept, and ARKODE asks for both parts of each stage.
 * Output times, drift and callbacks as for esdirk (integrate_esdirk.c),
 * whose setup, advance and statistics it shares (integrate_arkstep.c):
 * with constraints, a step postprocessing function projects every
 * accepted step and watches the assembly branch. Unlike erk's Verner
 * table (integrate_arkode.c, upstream llnl/sundials issue 311), this pair
 * keeps its order when ARKODE reuses the last stage's f_E and f_I as the
 * new step's: measured on the spring pendulum, 5.3 with or without a
 * postprocessing function that forces fresh ones.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arkode/arkode_arkstep.h>
#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "integrate_internal.h"

#define IMEX_DIRK ARKODE_ARK548L2SA_DIRK_8_4_5
#define IMEX_ERK ARKODE_ARK548L2SA_ERK_8_4_5

typedef struct imex {
    eom_ark ark;               /* the solver (first: integrate_arkstep.c) */
    /* the potential tape: x = (q, qd), output V */
    tp_tape *tV;
    tp_ws *wV;
    int *pmap;                 /* [np] its parameter of each system one */
    int tparam;                /* its time parameter, or -1 */
    /* the split at the last state asked for */
    double tkey, *ykey;        /* [N] that state */
    int valid;                 /* ykey, f and fi hold an evaluation */
    double *f, *fi;            /* [N] f and f_I there */
    /* scratch */
    double *gV;                /* [2n] gradient of V */
    double *HV;                /* [2n x n] d2V/dx dq */
    double *HR;                /* [2n x 2n] Hessian of R */
    double *Kc;                /* [n x 2n] column-major: K + B, then D */
    double *wm;                /* [m] */
} imex;

/* ---- the potential tape ------------------------------------------------ */

typedef struct vrec {
    const tp_tape *tE;
    int vout;
} vrec;

static int rec_potential(tp_rec *r, void *user)
{
    const vrec *a = user;
    const int ni = tp_tape_n_indep(a->tE), no = tp_tape_n_outputs(a->tE);
    tp_val *x = malloc((size_t)ni * sizeof *x);
    tp_val *y = malloc((size_t)no * sizeof *y);
    int i, rc = 1;
    if (x && y) {
        for (i = 0; i < ni; i++)
            x[i] = tp_indep(r, i);
        /* the energy tape's parameters (the time among them) become this
         * tape's, by name */
        if (tp_call(r, a->tE, x, NULL, y) == TP_OK)
            rc = tp_output(r, "V", y[a->vout]) < 0;
    }
    free(x);
    free(y);
    return rc;
}

/* Record the potential tape and its workspace. A status; a model without
 * V apart is refused with a message naming the methods that can go on. */
static int make_potential(eom_integ *it, imex *d)
{
    eom_system *s = it->s;
    const int n = s->n;
    unsigned char *grp;
    tp_rec *r = NULL;
    vrec a;
    int rc, k;
    if (!s->has_tv || !s->tE.tape ||
        (a.vout = tp_tape_output_index(s->tE.tape, "V")) < 0)
        return eom__integ_fail(
            it, EOM_ERR_MODEL,
            "the model gives a whole Lagrangian, not T and V apart: the "
            "implicit part needs V; give T and V, or use esdirk or bdf "
            "(docs/integrators.md)");
    a.tE = s->tE.tape;
    if (!(grp = malloc(2 * (size_t)n)))
        return eom__integ_nomem(it);
    for (k = 0; k < 2 * n; k++)
        grp[k] = k >= n;
    rc = tp_recorder_new(&r, 2 * n, grp, NULL);
    free(grp);
    if (rc == TP_OK)
        rc = tp_rec_run(r, NULL, rec_potential, &a);
    if (rc == TP_OK)
        rc = tp_recorder_finish(r, &d->tV);
    tp_rec_free(&r);
    if (rc == TP_OK)
        rc = tp_ws_new(&d->wV, d->tV, n, NULL);
    if (rc == TP_ERR_NOMEM)
        return eom__integ_nomem(it);
    if (rc != TP_OK)
        return eom__integ_fail(it, EOM_ERR_RECORD,
                               "recording the potential tape: %s",
                               tp_strerror(rc));
    if (!(d->pmap = malloc((size_t)(s->np ? s->np : 1) * sizeof(int))))
        return eom__integ_nomem(it);
    for (k = 0; k < s->np; k++)
        d->pmap[k] = tp_tape_param_index(d->tV, s->params[k].name);
    d->tparam = tp_tape_param_index(d->tV, EOM_TIME_NAME);
    return EOM_OK;
}

/* The potential tape's workspace at the system's parameters and time t. */
static void potential_params(const eom_integ *it, imex *d, double t)
{
    const eom_system *s = it->s;
    int k;
    for (k = 0; k < s->np; k++)
        if (d->pmap[k] >= 0)
            tp_ws_set_param(d->wV, d->pmap[k], s->pval[k]);
    if (d->tparam >= 0)
        tp_ws_set_param(d->wV, d->tparam, t);
}

/* A libtape status of a potential sweep: EOM_OK, or the system's status
 * with a message in it->msg naming the time. */
static int potential_status(eom_integ *it, double t, int st,
                            const char *what)
{
    int rc = eom__tape_status(it->s, st, what);
    if (rc != EOM_OK)
        snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t, it->s->msg);
    return rc;
}

/* ---- the split ---------------------------------------------------------- */

/* v := G v = M^-1 v - Y S^-1 C M^-1 v, with the factors of the system's
 * last evaluation (the M-orthogonal projection onto C a = 0). */
static int apply_G(eom_integ *it, imex *d, double *v)
{
    eom_system *s = it->s;
    const int n = s->n, m = s->m;
    int i, j, rc;
    if ((rc = eom__mass_solve(s, v, 1)) != EOM_OK)
        return rc;
    if (m == 0)
        return EOM_OK;
    for (j = 0; j < m; j++) {
        double c = 0.0;
        for (i = 0; i < n; i++)
            c += s->C[(size_t)j * (size_t)n + (size_t)i] * v[i];
        d->wm[j] = c;
    }
    return eom__S_correct(s, v, d->wm);
}

/* Evaluate the model at (t, y) and split its right-hand side into d->f and
 * d->fi, unless that state's split is the one kept. A status with a
 * message in it->msg. */
static int split_at(eom_integ *it, imex *d, double t, const double *y)
{
    eom_system *s = it->s;
    const int n = s->n, N = it->N;
    double *a = d->fi + n;
    int i, rc, st;
    if (d->valid && t == d->tkey &&
        memcmp(y, d->ykey, (size_t)N * sizeof(double)) == 0)
        return EOM_OK;
    d->valid = 0;
    if ((rc = eom__integ_rhs(it, t, y, d->f)) != EOM_OK)
        return rc;
    potential_params(it, d, t);
    st = tp_gradient(d->wV, y, 0, NULL, d->gV);
    if ((rc = potential_status(it, t, st, "the gradient of the potential")))
        return rc;
    /* F_s = -dV/dq - dR/dqd (s->gR: the dissipation's gradient of this
     * evaluation) */
    for (i = 0; i < n; i++)
        a[i] = -d->gV[i] - (s->has_R ? s->gR[n + i] : 0.0);
    if ((rc = apply_G(it, d, a)) != EOM_OK) {
        snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t, s->msg);
        return rc;
    }
    memcpy(d->fi, y + n, (size_t)n * sizeof(double));
    d->fi[2 * n] = 0.0;
    memcpy(d->ykey, y, (size_t)N * sizeof(double));
    d->tkey = t;
    d->valid = 1;
    return EOM_OK;
}

int eom__imex_split(eom_integ *it, double t, const double *y, double *fe,
                    double *fi)
{
    imex *d = it->impl;
    int rc, i;
    if (!it->ops || strcmp(it->ops->name, "imex") != 0 || !d)
        return EOM_ERR_ARG;
    d->valid = 0;
    if ((rc = split_at(it, d, t, y)) != EOM_OK)
        return rc;
    for (i = 0; i < it->N; i++) {
        fe[i] = d->f[i] - d->fi[i];
        fi[i] = d->fi[i];
    }
    return EOM_OK;
}

/* ---- ARKODE callbacks --------------------------------------------------- */

static int ix_fi(sunrealtype t, N_Vector y, N_Vector yd, void *user)
{
    eom_integ *it = user;
    imex *d = it->impl;
    int rc = split_at(it, d, t, N_VGetArrayPointer(y));
    if (rc == EOM_OK)
        memcpy(N_VGetArrayPointer(yd), d->fi, (size_t)it->N * sizeof(double));
    return eom__ark_cb_result(it, rc);
}

static int ix_fe(sunrealtype t, N_Vector y, N_Vector yd, void *user)
{
    eom_integ *it = user;
    imex *d = it->impl;
    int rc = split_at(it, d, t, N_VGetArrayPointer(y)), i;
    double *out = N_VGetArrayPointer(yd);
    if (rc == EOM_OK)
        for (i = 0; i < it->N; i++)
            out[i] = d->f[i] - d->fi[i];
    return eom__ark_cb_result(it, rc);
}

/* J_I at (t, y), column-major with leading dimension ldj = N (see the top
 * of the file): the model is evaluated at y for G's factors. */
static int imex_jacobian(eom_integ *it, imex *d, double t, const double *y,
                         double *J, int ldj)
{
    eom_system *s = it->s;
    const int n = s->n, N = it->N;
    int i, j, rc, st;
    d->valid = 0;
    if ((rc = split_at(it, d, t, y)) != EOM_OK)
        return rc;
    potential_params(it, d, t);
    st = tp_hessian_cols(d->wV, y, 0, 0, n, NULL, d->HV);
    if ((rc = potential_status(it, t, st, "the Hessian of the potential")))
        return rc;
    if (s->has_R) {
        st = tp_hessian(s->tR.ws, eom__tape_input(&s->tR, y, t), 0, d->HR);
        if ((rc = potential_status(it, t, st,
                                   "the Hessian of the dissipation")))
            return rc;
    }
    /* columns j < n: K + B (d/dq_j of dV/dq and dR/dqd); n <= j < 2n: D */
    for (j = 0; j < 2 * n; j++)
        for (i = 0; i < n; i++) {
            double v = j < n ? d->HV[(size_t)i * (size_t)n + (size_t)j] : 0.0;
            if (s->has_R)
                v += d->HR[(size_t)(n + i) * (size_t)(2 * n) + (size_t)j];
            d->Kc[(size_t)j * (size_t)n + (size_t)i] = v;
        }
    for (j = 0; j < 2 * n; j++)
        if ((rc = apply_G(it, d, d->Kc + (size_t)j * (size_t)n)) != EOM_OK) {
            snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t, s->msg);
            return rc;
        }
    for (j = 0; j < N; j++)
        memset(J + (size_t)j * (size_t)ldj, 0, (size_t)N * sizeof(double));
    for (i = 0; i < n; i++)
        J[(size_t)(n + i) * (size_t)ldj + (size_t)i] = 1.0;
    for (j = 0; j < 2 * n; j++)
        for (i = 0; i < n; i++)
            J[(size_t)j * (size_t)ldj + (size_t)(n + i)] =
                -d->Kc[(size_t)j * (size_t)n + (size_t)i];
    return EOM_OK;
}

static int ix_jac(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix J,
                  void *user, N_Vector t1, N_Vector t2, N_Vector t3)
{
    eom_integ *it = user;
    (void)fy;
    (void)t1;
    (void)t2;
    (void)t3;
    return eom__ark_cb_result(it, imex_jacobian(it, it->impl, t,
                                                N_VGetArrayPointer(y),
                                                SM_DATA_D(J),
                                                (int)SM_ROWS_D(J)));
}

int eom__imex_jacobian(eom_integ *it, double t, const double *y, double *J)
{
    if (!it->ops || strcmp(it->ops->name, "imex") != 0 || !it->impl)
        return EOM_ERR_ARG;
    return imex_jacobian(it, it->impl, t, y, J, it->N);
}

/* Tests: fixed steps of h (ARKStepSetFixedStep), for the table's order
 * measured by halving the step. */
int eom__imex_fixed_step(eom_integ *it, double h)
{
    imex *d = it->impl;
    if (!it->ops || strcmp(it->ops->name, "imex") != 0 || !d || !(h > 0.0))
        return EOM_ERR_ARG;
    return ARKStepSetFixedStep(d->ark.mem, h) == ARK_SUCCESS ? EOM_OK
                                                         : EOM_ERR_SOLVER;
}

/* ---- the method --------------------------------------------------------- */

static void ix_destroy(eom_integ *it)
{
    imex *d = it->impl;
    if (!d)
        return;
    eom__ark_free(&d->ark);
    tp_ws_free(&d->wV);
    tp_tape_free(&d->tV);
    free(d->pmap);
    free(d->ykey);
    free(d->f);
    free(d->fi);
    free(d->gV);
    free(d->HV);
    free(d->HR);
    free(d->Kc);
    free(d->wm);
    free(d);
    it->impl = NULL;
}

static int ix_init(eom_integ *it)
{
    const int n = it->n, N = it->N, m = it->s->m;
    imex *d = calloc(1, sizeof *d);
    int rc;
    if (!d)
        return eom__integ_nomem(it);
    it->impl = d;
    if ((rc = make_potential(it, d)) != EOM_OK)
        return rc;
    d->ykey = malloc((size_t)N * sizeof(double));
    d->f = malloc((size_t)N * sizeof(double));
    d->fi = malloc((size_t)N * sizeof(double));
    d->gV = malloc(2 * (size_t)n * sizeof(double));
    d->HV = malloc(2 * (size_t)n * (size_t)n * sizeof(double));
    d->HR = malloc(4 * (size_t)n * (size_t)n * sizeof(double));
    d->Kc = malloc(2 * (size_t)n * (size_t)n * sizeof(double));
    d->wm = malloc((size_t)(m ? m : 1) * sizeof(double));
    if (!d->ykey || !d->f || !d->fi || !d->gV || !d->HV || !d->HR ||
        !d->Kc || !d->wm)
        return eom__integ_nomem(it);
    return eom__ark_implicit_init(it, &d->ark, ix_fe, ix_fi, ix_jac,
                                  IMEX_DIRK, IMEX_ERK);
}

static int ix_advance(eom_integ *it, double tout)
{
    return eom__ark_advance(it, tout, "imex");
}

const eom_integ_ops eom__imex_ops = {"imex", ix_init, ix_advance,
                                     eom__ark_stats, ix_destroy};
