/* integrate_cvode.c - EOM_ADAMS and EOM_BDF: CVODE's variable-order,
 * variable-step multistep methods on y = (q, qd, W), from CVODES (CVODE
 * with forward sensitivities, the same solver otherwise).
 *
 *   Adams  CV_ADAMS (Adams-Moulton, orders 1..12) with the fixed-point
 *          nonlinear solver: no Jacobian, for non-stiff models.
 *   BDF    CV_BDF (orders 1..5) with Newton iteration and a direct
 *          linear solver: dense LU (SUNDenseMatrix + SUNLinSol_Dense), or
 *          on models without constraints whose mass matrix is block
 *          diagonal in small blocks, KLU on a sparse matrix whose pattern
 *          comes from the tapes (eom_opts.linear_solver,
 *          state_jacobian_sparse.c). The Jacobian is exact, from the
 *          residual tape (cv_jac, residual.c), or with
 *          eom_opts.dq_jacobian CVODE's difference quotient (N extra
 *          right-hand sides each, dense only), kept as a reference.
 *
 * Output times: each advance sets the stop time to tout, so the solver
 * never steps past it and the state returned is the step that ends there.
 *
 * Drift. CVODE's projection interface (cvode_proj.h) works with BDF only
 * (CVodeSetProjFn rejects Adams with CV_ILL_INPUT), so:
 *   BDF    CVODE calls cv_project after the corrector of every step
 *          attempt, before the error test; it returns the correction of
 *          least M-norm and projects the error estimate onto the tangent
 *          space (the q and qd parts each M-orthogonally onto the null
 *          space of C at the projected q).
 *   Adams  the state is projected at output times. The caller receives
 *          the projected state; the solver restarts from it (CVodeReInit:
 *          order 1, a new initial step) only when the correction exceeds
 *          the local error tolerance, its WRMS norm with CVODE's error
 *          weights being > 1. Smaller corrections stay out of the solver.
 * CVodeReInit zeroes CVODE's counters; they are banked first.
 *
 * Sensitivities (eom_opts.n_sens): CVODES integrates them beside the
 * state, staggered, with the state's tolerances scaled by each
 * parameter's size (CVodeSensEEtolerances, pbar = |p|, 1 for an initial
 * value) for their corrector, and out of the error test: the steps are
 * the state's. In the error test they doubled the steps of
 * bench-sensitivity's open chain and changed the agreement with
 * differences of whole runs not at all (1.4e-7); their right-hand sides
 * are exact (cv_sens_rhs, residual.c), the multipliers' changes and the
 * Baumgarte terms included. Adams solves them by fixed point as it does
 * the state; BDF by Newton with the same linear solver. With
 * constraints they start tangent to them (integrate.c), CVODES does not
 * project them with the state inside the solver, and at output times
 * they are projected with the linearized projection at the projected
 * state (sensitivity.c), so that the caller's are the derivatives of the
 * projected state; Adams's restart from the projected state restarts
 * them from theirs (CVodeSensReInit), as does BDF's retry with a loose
 * floor from its last step's.
 *
 * Callbacks return 0, +1 for EOM_ERR_NONFINITE (CVODE retries with a
 * smaller step) and -1 otherwise, and keep the status and message of the
 * most recent one: when the solver fails right after a failed callback,
 * that callback's status is the cause.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cvodes/cvodes.h>
#include <cvodes/cvodes_ls.h>
#include <cvodes/cvodes_proj.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include "integrate_internal.h"
/* after eom_internal.h, whose <suitesparse/klu.h> stands for the <klu.h>
 * this header would look for */
#include <sunlinsol/sunlinsol_klu.h>

typedef struct cvode {
    SUNContext ctx;
    N_Vector y;                /* [N] the solver's state */
    N_Vector ewt;              /* [N] error weights (Adams with projection) */
    SUNMatrix A;               /* BDF: Jacobian, dense or sparse (CSC) */
    SUNLinearSolver LS;        /* BDF: dense LU, or KLU */
    int sparse;                /* BDF: the sparse matrix and KLU */
    SUNNonlinearSolver NLS;    /* Adams: fixed point */
    void *mem;                 /* CVODE memory */
    double *w;                 /* [N] a projected copy of a state */
    double *r;                 /* [m] scratch */
    int restart;               /* project at output times, restart on drift */
    long banked_steps, banked_fails; /* counters before the last restart */
    int ns;                    /* sensitivities */
    N_Vector *yS;              /* [ns] their values */
    SUNNonlinearSolver NLSs;   /* Adams: their fixed point */
    int *par;                  /* [ns] parameter index, or -1 */
    double *swork;             /* eom__sens_work doubles */
    const double **Vp;         /* [ns] pointers into yS */
    double **Op;               /* [ns] pointers into their rates */
    double *ylast, tlast;      /* the state of the system's last
                                  evaluation, when have_last */
    int have_last;
    eom_sun_report rep;        /* why it stopped */
} cvode;

static const char *cv_name(const eom_integ *it)
{
    return it->o.method == EOM_BDF ? "bdf" : "adams";
}

static int cv_cb_result(eom_integ *it, cvode *c, int rc)
{
    return eom__sun_cb_result(it, &c->rep, rc);
}

/* With sensitivities: remember where the system was evaluated last, so
 * that their right-hand side at the same state does not evaluate again.
 * Only cv_rhs and cv_sens_rhs evaluate a model without constraints
 * between, and cv_jac, which forgets it; with constraints the
 * projection, the branch check and the output's projection change s's
 * factors too, and forget it as well. */
static void cv_remember(cvode *c, int ok, double t, const double *y, int N)
{
    c->have_last = ok && c->ylast;
    if (c->have_last) {
        memcpy(c->ylast, y, (size_t)N * sizeof(double));
        c->tlast = t;
    }
}

static int cv_rhs(sunrealtype t, N_Vector y, N_Vector yd, void *user)
{
    eom_integ *it = user;
    cvode *c = it->impl;
    int rc = eom__integ_rhs(it, t, N_VGetArrayPointer(y),
                            N_VGetArrayPointer(yd));
    cv_remember(c, rc == EOM_OK, t, N_VGetArrayPointer(y), it->N);
    return cv_cb_result(it, c, rc);
}

/* The sensitivities' right-hand sides: A yS_k + B e_p for each. */
static int cv_sens_rhs(int ns, sunrealtype t, N_Vector y, N_Vector yd,
                       N_Vector *yS, N_Vector *ySd, void *user,
                       N_Vector t1, N_Vector t2)
{
    eom_integ *it = user;
    cvode *c = it->impl;
    const double *yv = N_VGetArrayPointer(y);
    const int same = c->have_last && t == c->tlast &&
                     memcmp(yv, c->ylast, 2 * (size_t)it->n *
                                              sizeof(double)) == 0;
    int k, rc;
    (void)yd;
    (void)t1;
    (void)t2;
    for (k = 0; k < ns; k++) {
        c->Vp[k] = N_VGetArrayPointer(yS[k]);
        c->Op[k] = N_VGetArrayPointer(ySd[k]);
    }
    rc = eom__sens_rhs(it->s, t, yv, same, ns, c->par, c->Vp, c->Op,
                       c->swork);
    cv_remember(c, rc == EOM_OK, t, yv, it->N);
    if (rc != EOM_OK)
        snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t,
                 it->s->msg);
    return cv_cb_result(it, c, rc);
}

/* The sparse matrix's pattern into A (state_jacobian_sparse.c); the
 * same at every call, so KLU's symbolic analysis stays valid. */
static int cv_pattern(eom_integ *it, SUNMatrix A)
{
    sunindextype *cp = SM_INDEXPTRS_S(A), *ri = SM_INDEXVALS_S(A);
    eom_ode_pattern p;
    size_t e;
    int col, rc = eom__ode_pattern(it->s, &p);
    if (rc != EOM_OK)
        return rc;
    if ((sunindextype)p.nnz > SM_NNZ_S(A) || p.N != SM_COLUMNS_S(A))
        return eom__fail(it->s, EOM_ERR_SOLVER, "the sparse matrix holds "
                         "%ld entries of %ld columns, not the pattern's "
                         "%zu of %d", (long)SM_NNZ_S(A),
                         (long)SM_COLUMNS_S(A), p.nnz, p.N);
    for (col = 0; col <= p.N; col++)
        cp[col] = (sunindextype)p.colptr[col];
    for (e = 0; e < p.nnz; e++)
        ri[e] = (sunindextype)p.rowind[e];
    return EOM_OK;
}

/* BDF's Newton matrix: the exact d(yd)/dy, W's row included; CVODE
 * forms I - gamma J from it. */
static int cv_jac(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix J,
                  void *user, N_Vector t1, N_Vector t2, N_Vector t3)
{
    eom_integ *it = user;
    cvode *c = it->impl;
    double t0;
    int rc;
    (void)fy;
    (void)t1;
    (void)t2;
    (void)t3;
    c->have_last = 0; /* it evaluates at its own state */
    if (!c->sparse)
        return cv_cb_result(it, c,
                            eom__integ_jacobian(it, t, N_VGetArrayPointer(y),
                                                SM_DATA_D(J),
                                                (int)SM_ROWS_D(J)));
    t0 = eom__integ_now();
    /* CVODE zeroes the matrix, its pattern included, before this call */
    if ((rc = cv_pattern(it, J)) == EOM_OK)
        rc = eom__state_jacobian_sparse(it->s, t, N_VGetArrayPointer(y),
                                        SM_DATA_S(J));
    it->st.jac_time += eom__integ_now() - t0;
    if (rc != EOM_OK)
        snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t,
                 it->s->msg);
    return cv_cb_result(it, c, rc);
}

/* e[0..n) -= Y S^-1 C e[0..n): the M-orthogonal projection onto the null
 * space of C, with C, Y = M^-1 C^T and the factors of S left by the
 * projection that just ran. */
static int tangent(eom_system *s, double *e, double *r)
{
    const int n = s->n, m = s->m;
    int i, j, rc;
    for (j = 0; j < m; j++) {
        double sum = 0.0;
        for (i = 0; i < n; i++)
            sum += s->C[(size_t)j * (size_t)n + (size_t)i] * e[i];
        r[j] = sum;
    }
    if ((rc = eom__S_solve(s, r)) != EOM_OK)
        return rc;
    for (j = 0; j < m; j++)
        for (i = 0; i < n; i++)
            e[i] -= s->Y[(size_t)j * (size_t)n + (size_t)i] * r[j];
    return EOM_OK;
}

/* CVODE's projection (BDF): corr = P(ycur) - ycur, ycur left alone; err,
 * when CVODE asks for it, projected onto the tangent space (position and
 * velocity parts alike; the dC/dq term of the velocity constraint is
 * neglected, an approximation that affects only the choice of the step,
 * not the solution). epsProj is not used: the projection iterates to
 * o.proj_tol on |phi|. */
static int cv_project(sunrealtype t, N_Vector ycur, N_Vector corr,
                      sunrealtype epsProj, N_Vector err, void *user)
{
    eom_integ *it = user;
    cvode *c = it->impl;
    const double *y = N_VGetArrayPointer(ycur);
    double *dy = N_VGetArrayPointer(corr);
    /* it->t is the last output time; the messages should name this step */
    const double t_out = it->t;
    int i, rc;
    (void)epsProj;
    c->have_last = 0; /* the projection changes s's factors */
    memcpy(c->w, y, (size_t)it->N * sizeof(double));
    it->t = t;
    rc = eom__integ_project(it, c->w);
    it->t = t_out;
    if (rc == EOM_OK) {
        for (i = 0; i < it->N; i++)
            dy[i] = c->w[i] - y[i];
        if (err) {
            double *e = N_VGetArrayPointer(err);
            rc = tangent(it->s, e, c->r);
            if (rc == EOM_OK)
                rc = tangent(it->s, e + it->n, c->r);
            if (rc != EOM_OK)
                snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t,
                         it->s->msg);
        }
    }
    return cv_cb_result(it, c, rc);
}

/* The error weights 1 / (rtol |y_i| + atol_i) with the per-step
 * tolerances of the moment: bdf with constraints changes its floor during
 * the run (cv_floor), which CVODE's own weights cannot follow (in
 * SUNDIALS 6.4, CVodeSStolerances between steps leaves the weight
 * function without its data until the next CVodeReInit). */
static int cv_ewt(N_Vector y, N_Vector ewt, void *user)
{
    eom_integ *it = user;
    const double *Y = N_VGetArrayPointer(y);
    double *w = N_VGetArrayPointer(ewt);
    const double rtol = eom__integ_step_tol(it, it->o.rtol);
    const double atol = eom__integ_step_tol(it, it->o.atol);
    int i;
    for (i = 0; i < it->N; i++) {
        const double a = it->atolv && i < 2 * it->n
                             ? eom__integ_step_tol(it, it->atolv[i])
                             : atol;
        const double d = rtol * fabs(Y[i]) + a;
        if (!(d > 0.0))
            return -1;
        w[i] = 1.0 / d;
    }
    return 0;
}

/* A failed setup call: a status and a message naming it. */
static int cv_setup_failed(eom_integ *it, int flag, const char *call)
{
    return eom__sun_setup_failed(it, CVodeGetReturnFlagName(flag),
                                 flag == CV_MEM_FAIL, call);
}

static void cv_destroy(eom_integ *it)
{
    cvode *c = it->impl;
    if (!c)
        return;
    CVodeFree(&c->mem);
    if (c->NLS)
        SUNNonlinSolFree(c->NLS);
    if (c->NLSs)
        SUNNonlinSolFree(c->NLSs);
    if (c->yS)
        N_VDestroyVectorArray(c->yS, c->ns);
    if (c->LS)
        SUNLinSolFree(c->LS);
    if (c->A)
        SUNMatDestroy(c->A);
    if (c->ewt)
        N_VDestroy(c->ewt);
    if (c->y)
        N_VDestroy(c->y);
    if (c->ctx)
        SUNContext_Free(&c->ctx);
    free(c->w);
    free(c->r);
    free(c->par);
    free(c->swork);
    free(c->Vp);
    free(c->Op);
    free(c->ylast);
    free(c);
    it->impl = NULL;
}

/* BDF's matrix and linear solver: dense LU, or KLU on the sparse matrix
 * whose pattern (fixed for the run: KLU's symbolic analysis is done
 * once, each Jacobian refactors) is written here. */
static int cv_matrix(eom_integ *it, cvode *c)
{
    eom_ode_pattern p;
    int choice, rc;
    rc = eom__ode_linear_solver(it->s, it->o.linear_solver,
                                it->o.dq_jacobian, &choice);
    if (rc != EOM_OK) {
        snprintf(it->msg, sizeof it->msg, "choosing the linear solver: %s",
                 it->s->msg);
        return rc;
    }
    c->sparse = choice == EOM_LINSOL_SPARSE;
    it->linsol = choice;
    if (!c->sparse) {
        c->A = SUNDenseMatrix(it->N, it->N, c->ctx);
        if (!c->A)
            return eom__integ_nomem(it);
        c->LS = SUNLinSol_Dense(c->y, c->A, c->ctx);
        return c->LS ? EOM_OK : eom__integ_nomem(it);
    }
    if ((rc = eom__ode_pattern(it->s, &p)) != EOM_OK) {
        snprintf(it->msg, sizeof it->msg, "the sparse Jacobian: %s",
                 it->s->msg);
        return rc;
    }
    c->A = SUNSparseMatrix(it->N, it->N, (sunindextype)p.nnz, CSC_MAT,
                           c->ctx);
    if (!c->A)
        return eom__integ_nomem(it);
    if ((rc = cv_pattern(it, c->A)) != EOM_OK) {
        snprintf(it->msg, sizeof it->msg, "the sparse Jacobian: %s",
                 it->s->msg);
        return rc;
    }
    c->LS = SUNLinSol_KLU(c->y, c->A, c->ctx);
    return c->LS ? EOM_OK : eom__integ_nomem(it);
}

/* The pieces of one method: nonlinear and linear solvers, projection. */
static int cv_init_method(eom_integ *it, cvode *c)
{
    const int m = it->s->m;
    int flag, rc;
    if (it->o.method == EOM_ADAMS) {
        c->NLS = SUNNonlinSol_FixedPoint(c->y, 0, c->ctx);
        if (!c->NLS)
            return eom__integ_nomem(it);
        if ((flag = CVodeSetNonlinearSolver(c->mem, c->NLS)) < 0)
            return cv_setup_failed(it, flag, "CVodeSetNonlinearSolver");
        c->restart = m > 0 && it->o.project;
        if (c->restart && !(c->ewt = N_VClone(c->y)))
            return eom__integ_nomem(it);
        return EOM_OK;
    }
    if ((rc = cv_matrix(it, c)) != EOM_OK)
        return rc;
    if ((flag = CVodeSetLinearSolver(c->mem, c->LS, c->A)) < 0)
        return cv_setup_failed(it, flag, "CVodeSetLinearSolver");
    if (!it->o.dq_jacobian && (flag = CVodeSetJacFn(c->mem, cv_jac)) < 0)
        return cv_setup_failed(it, flag, "CVodeSetJacFn");
    if (m > 0 && it->o.project &&
        (flag = CVodeSetProjFn(c->mem, cv_project)) < 0)
        return cv_setup_failed(it, flag, "CVodeSetProjFn");
    return EOM_OK;
}

/* Sensitivities: their vectors (unit vectors for initial values), the
 * scales of their tolerances, and for Adams their fixed point. */
static int cv_sens_init(eom_integ *it, cvode *c)
{
    const int ns = it->o.n_sens, np = it->s->np;
    double *pbar;
    int k, flag;
    c->ns = ns;
    c->yS = N_VCloneVectorArray(ns, c->y);
    c->par = malloc((size_t)ns * sizeof *c->par);
    c->swork = malloc(eom__sens_work(it->s, ns) * sizeof(double));
    c->Vp = malloc((size_t)ns * sizeof *c->Vp);
    c->Op = malloc((size_t)ns * sizeof *c->Op);
    c->ylast = malloc((size_t)it->N * sizeof(double));
    pbar = malloc((size_t)ns * sizeof *pbar);
    if (!c->yS || !c->par || !c->swork || !c->Vp || !c->Op || !c->ylast ||
        !pbar) {
        free(pbar);
        return eom__integ_nomem(it);
    }
    for (k = 0; k < ns; k++) {
        const int w = it->sens[k];
        double *v = N_VGetArrayPointer(c->yS[k]);
        int i;
        /* from the sensitivities at it->t (a restart after a singular
         * stretch starts from them too); W's is 0 */
        memset(v, 0, (size_t)it->N * sizeof(double));
        for (i = 0; i < 2 * it->n; i++)
            v[i] = it->S[(size_t)i * ns + k];
        c->par[k] = w < np ? w : -1;
        pbar[k] = w < np && it->s->pval[w] != 0.0 ? fabs(it->s->pval[w])
                                                  : 1.0;
    }
    flag = CVodeSensInit(c->mem, ns, CV_STAGGERED, cv_sens_rhs, c->yS);
    if (flag >= 0)
        flag = CVodeSetSensParams(c->mem, NULL, pbar, NULL);
    free(pbar);
    if (flag < 0)
        return cv_setup_failed(it, flag, "CVodeSensInit");
    if ((flag = CVodeSensEEtolerances(c->mem)) < 0)
        return cv_setup_failed(it, flag, "CVodeSensEEtolerances");
    /* out of the error test (see the top of this file) */
    if ((flag = CVodeSetSensErrCon(c->mem, SUNFALSE)) < 0)
        return cv_setup_failed(it, flag, "CVodeSetSensErrCon");
    if (it->o.method == EOM_ADAMS) {
        c->NLSs = SUNNonlinSol_FixedPointSens(ns, c->y, 0, c->ctx);
        if (!c->NLSs)
            return eom__integ_nomem(it);
        if ((flag = CVodeSetNonlinearSolverSensStg(c->mem, c->NLSs)) < 0)
            return cv_setup_failed(it, flag,
                                   "CVodeSetNonlinearSolverSensStg");
    }
    return EOM_OK;
}

static int cv_init(eom_integ *it)
{
    cvode *c = calloc(1, sizeof *c);
    const size_t N = (size_t)it->N, m = (size_t)it->s->m;
    int flag;
    if (!c)
        return eom__integ_nomem(it);
    it->impl = c;
    c->w = calloc(N, sizeof(double));
    c->r = calloc(m > 0 ? m : 1, sizeof(double));
    if (!c->w || !c->r)
        return eom__integ_nomem(it);
    if (SUNContext_Create(NULL, &c->ctx) != 0) {
        c->ctx = NULL;
        return eom__integ_nomem(it);
    }
    c->y = N_VNew_Serial((sunindextype)N, c->ctx);
    if (!c->y)
        return eom__integ_nomem(it);
    memcpy(N_VGetArrayPointer(c->y), it->y, N * sizeof(double));
    c->mem = CVodeCreate(it->o.method == EOM_BDF ? CV_BDF : CV_ADAMS,
                         c->ctx);
    if (!c->mem)
        return eom__integ_nomem(it);
    if ((flag = CVodeSetErrHandlerFn(c->mem, eom__sun_error, &c->rep)) < 0)
        return cv_setup_failed(it, flag, "CVodeSetErrHandlerFn");
    if ((flag = CVodeInit(c->mem, cv_rhs, it->t, c->y)) < 0)
        return cv_setup_failed(it, flag, "CVodeInit");
    if ((flag = CVodeSetUserData(c->mem, it)) < 0)
        return cv_setup_failed(it, flag, "CVodeSetUserData");
    if (it->o.method == EOM_BDF && it->s->m > 0)
        flag = CVodeWFtolerances(c->mem, cv_ewt);
    else
        flag = eom__sun_tolerances(it, c->mem, c->ctx, N, CVodeSStolerances,
                                   CVodeSVtolerances);
    if (flag == 1)
        return eom__integ_nomem(it);
    if (flag < 0)
        return cv_setup_failed(it, flag, it->atolv ? "CVodeSVtolerances"
                                                 : "CVodeSStolerances");
    /* explicitly: the default of 500 would stop tight-tolerance runs */
    if ((flag = CVodeSetMaxNumSteps(c->mem, it->o.max_steps)) < 0)
        return cv_setup_failed(it, flag, "CVodeSetMaxNumSteps");
    if (it->o.dt > 0.0 && (flag = CVodeSetInitStep(c->mem, it->o.dt)) < 0)
        return cv_setup_failed(it, flag, "CVodeSetInitStep");
    if ((flag = CVodeSetMaxOrd(c->mem, eom__integ_max_order(it))) < 0)
        return cv_setup_failed(it, flag, "CVodeSetMaxOrd");
    if ((flag = cv_init_method(it, c)) != EOM_OK)
        return flag;
    return it->o.n_sens > 0 ? cv_sens_init(it, c) : EOM_OK;
}

/* Counters that CVodeReInit is about to zero. */
static void cv_bank(cvode *c)
{
    long nst = 0, netf = 0, ncfn = 0;
    CVodeGetNumSteps(c->mem, &nst);
    CVodeGetNumErrTestFails(c->mem, &netf);
    CVodeGetNumNonlinSolvConvFails(c->mem, &ncfn);
    c->banked_steps += nst;
    c->banked_fails += netf + ncfn;
}

/* The sensitivities at tout into c->yS and it->S, with projection on
 * and constraints projected at the projected state c->w (their W row
 * untouched). A status, with a message in it->msg. */
static int cv_output_sens(eom_integ *it, cvode *c, double tout)
{
    sunrealtype ts;
    int flag, rc, k, i;
    if ((flag = CVodeGetSens(c->mem, &ts, c->yS)) < 0)
        return cv_setup_failed(it, flag, "CVodeGetSens");
    for (k = 0; k < c->ns; k++)
        c->Op[k] = N_VGetArrayPointer(c->yS[k]);
    if (it->s->m > 0 && it->o.project) {
        c->have_last = 0;
        rc = eom__sens_project(it->s, tout, c->w, 0, c->ns, c->par, c->Op,
                               c->swork);
        if (rc != EOM_OK) {
            snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", tout,
                     it->s->msg);
            return rc;
        }
    }
    for (k = 0; k < c->ns; k++)
        for (i = 0; i < 2 * it->n; i++)
            it->S[(size_t)i * c->ns + k] = c->Op[k][i];
    return EOM_OK;
}

/* At tout, with the solver's state in c->y: the state for the caller,
 * projected (or only its residual tracked) when the system has
 * constraints, and for Adams a restart from it when the drift exceeds the
 * local error tolerance. */
static int cv_output(eom_integ *it, cvode *c, double tout)
{
    const int N = it->N;
    double *y = N_VGetArrayPointer(c->y);
    int rc, flag, i, restart = 0;
    it->t = tout;
    memcpy(c->w, y, (size_t)N * sizeof(double));
    if (it->s->m > 0 && (rc = eom__integ_project(it, c->w)) != EOM_OK)
        return eom__integ_fail(it, rc, "%s: %s", cv_name(it), it->msg);
    if (c->restart) {
        const double *ewt = N_VGetArrayPointer(c->ewt);
        double sum = 0.0;
        CVodeGetErrWeights(c->mem, c->ewt);
        for (i = 0; i < N; i++) {
            const double d = (c->w[i] - y[i]) * ewt[i];
            sum += d * d;
        }
        restart = sqrt(sum / N) > 1.0;
    }
    /* the sensitivities, before a restart replaces them: with projection,
     * the derivative of the projected state (sensitivity.c) */
    if (c->ns > 0 && (rc = cv_output_sens(it, c, tout)) != EOM_OK)
        return eom__integ_fail(it, rc, "%s: %s", cv_name(it), it->msg);
    if (restart) {
        cv_bank(c);
        memcpy(y, c->w, (size_t)N * sizeof(double));
        flag = CVodeReInit(c->mem, tout, c->y);
        if (flag >= 0 && c->ns > 0)
            flag = CVodeSensReInit(c->mem, CV_STAGGERED, c->yS);
        if (flag < 0) {
            rc = cv_setup_failed(it, flag, c->ns > 0 ? "CVodeSensReInit"
                                                     : "CVodeReInit");
            return eom__integ_fail(it, rc, "%s: %s", cv_name(it), it->msg);
        }
    }
    memcpy(it->y, c->w, (size_t)N * sizeof(double));
    return EOM_OK;
}

/* bdf with constraints: the per-step tolerance follows the condition of
 * the constraint system (integrate.c, step_tol_floor): loose from the
 * first accepted step whose last evaluation had rcond of C M^-1 C^T below
 * 1e-2, tight again above 0.1. cv_ewt reads it at every step. */
static void cv_floor(eom_integ *it, int loose)
{
    it->loose_floor = loose;
    it->was_loose |= loose;
}

/* bdf failed a step near a singular position with the tight per-step
 * tolerance: again from the last accepted step (tret, c->y) with the
 * loose one. Returns a status. */
static int cv_retry_loose(eom_integ *it, cvode *c, double tret, double tout)
{
    sunrealtype ts;
    int flag;
    cv_bank(c);
    cv_floor(it, 1);
    /* the sensitivities of the last accepted step go on with it */
    if (c->ns > 0 && (flag = CVodeGetSens(c->mem, &ts, c->yS)) < 0)
        return cv_setup_failed(it, flag, "CVodeGetSens");
    if ((flag = CVodeReInit(c->mem, tret, c->y)) < 0)
        return cv_setup_failed(it, flag, "CVodeReInit");
    if (c->ns > 0 && (flag = CVodeSensReInit(c->mem, CV_STAGGERED, c->yS)) < 0)
        return cv_setup_failed(it, flag, "CVodeSensReInit");
    if ((flag = CVodeSetStopTime(c->mem, tout)) < 0)
        return cv_setup_failed(it, flag, "CVodeSetStopTime");
    eom__sun_report_reset(&c->rep);
    return EOM_OK;
}

/* What KLU said, when the sparse path failed in the linear solver: "" or
 * a sentence, into buf. */
static void cv_klu_why(const cvode *c, int flag, char *buf, size_t len)
{
    sun_klu_common *k;
    const char *what;
    buf[0] = '\0';
    if (!c->sparse || !c->LS ||
        (flag != CV_LSETUP_FAIL && flag != CV_LSOLVE_FAIL))
        return;
    if (!(k = SUNLinSol_KLUGetCommon(c->LS)))
        return;
    switch (k->status) {
    case KLU_SINGULAR: what = "the Newton matrix is singular"; break;
    case KLU_OUT_OF_MEMORY: what = "out of memory"; break;
    case KLU_INVALID: what = "the matrix is invalid"; break;
    case KLU_TOO_LARGE: what = "the matrix is too large"; break;
    default: what = NULL; break;
    }
    if (what)
        snprintf(buf, len, "KLU, factoring the sparse Newton matrix: %s "
                 "(status %d); linear_solver 1 (dense) takes the dense "
                 "path", what, (int)k->status);
    else
        snprintf(buf, len, "KLU, factoring the sparse Newton matrix: "
                 "status %d, rcond %.3g; linear_solver 1 (dense) takes "
                 "the dense path", (int)k->status, k->rcond);
}

static int cv_advance(eom_integ *it, double tout)
{
    cvode *c = it->impl;
    const double t_last = it->t;
    sunrealtype tret = it->t, tcur = it->t, hlast = 0.0;
    int flag, status;
    eom__sun_report_reset(&c->rep);
    flag = CVodeSetMinStep(c->mem, eom__sun_min_step(it->t, tout));
    if (flag >= 0)
        flag = CVodeSetStopTime(c->mem, tout);
    if (flag >= 0 && it->s->m == 0) {
        flag = CVode(c->mem, tout, c->y, &tret, CV_NORMAL);
    } else if (flag >= 0) {
        /* step by step: each accepted step's state is checked for a
         * jump to another assembly branch */
        const int bdf = it->o.method == EOM_BDF;
        do {
            flag = CVode(c->mem, tout, c->y, &tret, CV_ONE_STEP);
            c->have_last = 0; /* the checks below evaluate s */
            if (flag < 0 && bdf && !it->loose_floor &&
                (flag == CV_ERR_FAILURE || flag == CV_CONV_FAILURE) &&
                it->s->rcond_S < 1e-2) {
                if ((status = cv_retry_loose(it, c, tret, tout)) != EOM_OK)
                    return eom__integ_fail(it, status, "%s: %s",
                                           cv_name(it), it->msg);
                flag = CV_SUCCESS;
                continue;
            }
            if (flag >= 0 && (status = eom__integ_branch(
                                  it, tret, N_VGetArrayPointer(c->y))) !=
                                 EOM_OK)
                return eom__integ_fail(it, status, "%s: %s", cv_name(it),
                                       it->msg);
            if (flag >= 0 && bdf)
                cv_floor(it, it->s->rcond_S <
                                 (it->loose_floor ? 0.1 : 1e-2));
            if (flag >= 0 && it->handing && eom__integ_stretch_done(it, tret)) {
                /* the stretch is behind: the method handing over
                 * takes over again here */
                it->t = tret;
                memcpy(it->y, N_VGetArrayPointer(c->y),
                       (size_t)it->N * sizeof(double));
                return EOM_OK;
            }
        } while (flag == CV_SUCCESS && tret < tout);
    }
    CVodeGetCurrentTime(c->mem, &tcur);
    if (flag >= 0) {
        /* a success that did not reach tout is not one */
        CVodeGetLastStep(c->mem, &hlast);
        if (tcur < tout - 100.0 * DBL_EPSILON * (fabs(tout) + fabs(hlast)))
            return eom__integ_fail(it, EOM_ERR_SOLVER,
                                   "%s: stopped at t = %.17g before tout "
                                   "= %.17g (last step %.3g)", cv_name(it),
                                   tcur, tout, hlast);
        status = cv_output(it, c, tout);
        if (status != EOM_OK)
            it->t = t_last; /* it->y still holds the state at t_last */
        return status;
    }
    /* it->y keeps the state at the last output time; where it failed
     * (a singular stretch handed to erk ends after it) */
    it->t_refused = tcur;
    status = eom__sun_failed(it, &c->rep, cv_name(it),
                             CVodeGetReturnFlagName(flag), tcur);
    {
        char klu[256];
        cv_klu_why(c, flag, klu, sizeof klu);
        if (klu[0]) {
            const size_t used = strlen(it->msg);
            snprintf(it->msg + used, sizeof it->msg - used, "; %s", klu);
        }
    }
    return status;
}

static void cv_stats(const eom_integ *it, eom_stats *st)
{
    const cvode *c = it->impl;
    long nst = 0, netf = 0, ncfn = 0, nje = 0;
    CVodeGetNumSteps(c->mem, &nst);
    CVodeGetNumErrTestFails(c->mem, &netf);
    CVodeGetNumNonlinSolvConvFails(c->mem, &ncfn);
    if (c->LS)
        CVodeGetNumJacEvals(c->mem, &nje);
    st->steps = c->banked_steps + nst;
    st->failures = c->banked_fails + netf + ncfn;
    st->jac_evals = nje;
    /* rhs_evals: the common counter, which also sees the difference
     * quotients of the Jacobian (CVODE counts those apart) */
}

const eom_integ_ops eom__cvode_ops = {"cvode", cv_init, cv_advance, cv_stats,
                                      cv_destroy};
