/* integrate_ida.c - EOM_IDA: IDA, from IDAS (IDA with forward
 * sensitivities; variable-order BDF for implicit DAEs, Newton iteration,
 * direct linear solver) on the index-1 form of Lagrange's equations, with the exact iteration matrix dG/dY + cj dG/dY'
 * from the residual tape (ida_jac), or with eom_opts.dq_jacobian IDA's
 * difference quotients, kept as a reference. The matrix is dense (dense
 * LU), or sparse (compressed columns, KLU) where its pattern, taken from
 * the tapes, is sparse enough to pay (eom_opts.linear_solver,
 * jacobian_sparse.c).
 *
 * Unknowns Y = (q, v, lambda, W): n + n + m + 1 values. Residuals
 *
 *     q' - v                            = 0   (n)
 *     M(q) v' - F(q, v, t) - C(q)^T lambda = 0   (n)
 *     C(q) v' - gamma(q, v)             = 0   (m)
 *     W' + P(q, v, t)                   = 0   (1)
 *
 * with F = dL/dq - (d2L/dqd dq) v - dR/dqd + Q, gamma = -(d2phi/dq2)[v, v]
 * (minus the Baumgarte terms when they are on) and P = v . (-dR/dqd + Q)
 * (- dL/dt, + lambda . (C v) when the constraints read the time, with
 * this lambda), all from one eom__evaluate at (t, q, v). These are the
 * outputs E, phi2 + 2 alpha phi1 + beta^2 phi0 and P of the residual tape
 * (residual.c) at (q, v, v', lambda, t), whose Jacobian gives ida_jac's. The constraints enter at
 * acceleration level only, so lambda is algebraic and the index is 1
 * (the matrix [M -C^T; C 0] is nonsingular when C has full rank). lambda
 * is flagged algebraic (IDASetId) and left out of the error test
 * (IDASetSuppressAlg): it is a by-product, not part of the state reported.
 * The initial Y' and lambda come from the right-hand side at t0, so the
 * initial values are consistent and IDACalcIC is not needed.
 *
 * Drift: phi = 0 and C v = 0 are not part of the index-1 system and drift
 * like the integration error. At output times the state is projected; the
 * caller receives the projected state, and IDA restarts from it
 * (IDAReInit with a consistent Y', order 1) only when the correction
 * exceeds the local error tolerance (WRMS norm with IDA's weights > 1).
 * IDAReInit zeroes IDA's counters; they are banked first. Baumgarte
 * stabilization (eom_set_baumgarte) is the alternative, the user's choice.
 *
 * Sensitivities (eom_opts.n_sens) are IDAS's: its staggered corrector
 * with the state's linear solver, the state's tolerances scaled by each
 * parameter's size (IDASensEEtolerances, pbar = |p|), and, unlike
 * CVODES's, in the error test (ida_sens_init says why). Their residuals are exact, one
 * forward sweep of the residual tape (ida_sens_res, sensitivity.c),
 * lambda's sensitivities included; their start is consistent: lambda's
 * and Y''s sensitivities from the sensitivities' right-hand sides
 * (ida_sens_consistent), at t0 and after every restart, which restarts
 * them from their projection (IDASensReInit). At output times they are
 * projected with the linearized projection at the projected state
 * (sensitivity.c).
 *
 * Output times: the stop time is tout, so the state returned is a step
 * result. rhs_evals counts residual evaluations (each one evaluation of
 * the model), including those of the difference-quotient Jacobian.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <idas/idas.h>
#include <idas/idas_ls.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include "integrate_internal.h"
/* after eom_internal.h, whose <suitesparse/klu.h> stands for the <klu.h>
 * this header would look for */
#include <sunlinsol/sunlinsol_klu.h>

typedef struct ida {
    SUNContext ctx;
    int NY;                    /* 2n + m + 1 */
    N_Vector yy, yp;           /* [NY] Y and Y' */
    N_Vector id;               /* [NY] 1 differential, 0 algebraic */
    N_Vector ewt;              /* [NY] error weights */
    SUNMatrix A;               /* dense, or sparse (CSC) */
    SUNLinearSolver LS;        /* dense LU, or KLU */
    int sparse;                /* the sparse matrix and KLU */
    void *mem;                 /* IDA memory */
    double *w, *wd;            /* [N] a state (q, v, W) and its rate */
    long banked_steps, banked_fails, banked_jacs; /* before the last
                                                     restart */
    int jacs_stale;            /* IDA keeps its old Jacobian count until
                                  the first solve after a restart */
    int ns;                    /* sensitivities (IDAS) */
    N_Vector *yS, *ypS;        /* [ns] theirs, of Y and Y' */
    int *par;                  /* [ns] parameter index, or -1 */
    double *swork;             /* eom__sens_work doubles */
    double *cols;              /* [ns x (2n + 1)] directions and rates */
    double *dlam;              /* [ns x m] the multipliers' changes */
    double *Wsens;             /* [ns] W's sensitivities at the output */
    const double **Vp, **Pp;   /* [ns] pointers: inputs */
    double **Op;               /* [ns] pointers: outputs */
    eom_sun_report rep;        /* why it stopped */
} ida;

static int ida_cb_result(eom_integ *it, ida *d, int rc)
{
    return eom__sun_cb_result(it, &d->rep, rc);
}

static int ida_res(sunrealtype t, N_Vector yy, N_Vector yp, N_Vector rr,
                   void *user)
{
    eom_integ *it = user;
    ida *d = it->impl;
    eom_system *s = it->s;
    const int n = it->n, m = s->m;
    const double *Y = N_VGetArrayPointer(yy), *P = N_VGetArrayPointer(yp);
    const double *lam = Y + 2 * n, *vd = P + n;
    double *r = N_VGetArrayPointer(rr);
    int i, j, k, rc;
    it->st.rhs_evals++;
    rc = eom__evaluate(s, t, Y);
    if (rc != EOM_OK) {
        snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t, s->msg);
        return ida_cb_result(it, d, rc);
    }
    for (i = 0; i < n; i++) {
        const double *Mi = s->M + (size_t)i * (size_t)n;
        double sum = -s->F[i];
        for (k = 0; k < n; k++)
            sum += Mi[k] * vd[k];
        for (j = 0; j < m; j++)
            sum -= s->C[(size_t)j * (size_t)n + (size_t)i] * lam[j];
        r[i] = P[i] - Y[n + i];
        r[n + i] = sum;
    }
    for (j = 0; j < m; j++) {
        const double *Cj = s->C + (size_t)j * (size_t)n;
        double sum = -s->gam[j];
        for (k = 0; k < n; k++)
            sum += Cj[k] * vd[k];
        r[2 * n + j] = sum;
    }
    r[2 * n + m] = P[2 * n + m] + s->power;
    /* moving constraints: their power with this lambda, not the
     * evaluation's (the two agree on the solution) */
    if (s->tphi.tindex >= 0)
        for (j = 0; j < m; j++) {
            const double *Cj = s->C + (size_t)j * (size_t)n;
            double cv = 0.0;
            for (k = 0; k < n; k++)
                cv += Cj[k] * Y[n + k];
            r[2 * n + m] += (lam[j] - s->lam[j]) * cv;
        }
    if (!eom__finite(r, (size_t)d->NY)) {
        snprintf(it->msg, sizeof it->msg,
                 "at t = %.17g: the DAE residual is not finite", t);
        return ida_cb_result(it, d, EOM_ERR_NONFINITE);
    }
    return ida_cb_result(it, d, EOM_OK);
}

/* The sparse matrix's pattern into A (jacobian_sparse.c); the same at
 * every call, so KLU's symbolic analysis stays valid. */
static int ida_pattern(eom_integ *it, SUNMatrix A)
{
    sunindextype *cp = SM_INDEXPTRS_S(A), *ri = SM_INDEXVALS_S(A);
    eom_dae_pattern p;
    size_t e;
    int c, rc = eom__dae_pattern(it->s, &p);
    if (rc != EOM_OK)
        return rc;
    if ((sunindextype)p.nnz > SM_NNZ_S(A) || p.NY != SM_COLUMNS_S(A))
        return eom__fail(it->s, EOM_ERR_SOLVER, "the sparse matrix holds "
                         "%ld entries of %ld columns, not the pattern's "
                         "%zu of %d", (long)SM_NNZ_S(A),
                         (long)SM_COLUMNS_S(A), p.nnz, p.NY);
    for (c = 0; c <= p.NY; c++)
        cp[c] = (sunindextype)p.colptr[c];
    for (e = 0; e < p.nnz; e++)
        ri[e] = (sunindextype)p.rowind[e];
    return EOM_OK;
}

/* The iteration matrix dG/dY + cj dG/dY' (residual.c). */
static int ida_jac(sunrealtype t, sunrealtype cj, N_Vector yy, N_Vector yp,
                   N_Vector rr, SUNMatrix A, void *user, N_Vector t1,
                   N_Vector t2, N_Vector t3)
{
    eom_integ *it = user;
    ida *d = it->impl;
    const double t0 = eom__integ_now();
    int rc;
    (void)rr;
    (void)t1;
    (void)t2;
    (void)t3;
    if (d->sparse) {
        /* IDA zeroes the matrix, its pattern included, before this call */
        if ((rc = ida_pattern(it, A)) == EOM_OK)
            rc = eom__dae_jacobian_sparse(it->s, t, N_VGetArrayPointer(yy),
                                          N_VGetArrayPointer(yp), cj,
                                          SM_DATA_S(A));
    } else
        rc = eom__dae_jacobian(it->s, t, N_VGetArrayPointer(yy),
                               N_VGetArrayPointer(yp), cj, SM_DATA_D(A),
                               (int)SM_ROWS_D(A));
    it->st.jac_time += eom__integ_now() - t0;
    if (rc != EOM_OK)
        snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t,
                 it->s->msg);
    return ida_cb_result(it, d, rc);
}

/* The sensitivities' residuals dG/dY yS + dG/dY' ypS + dG/dp, exact from
 * the residual tape (sensitivity.c). */
static int ida_sens_res(int ns, sunrealtype t, N_Vector yy, N_Vector yp,
                        N_Vector rr, N_Vector *yS, N_Vector *ypS,
                        N_Vector *rS, void *user, N_Vector t1, N_Vector t2,
                        N_Vector t3)
{
    eom_integ *it = user;
    ida *d = it->impl;
    int k, rc;
    (void)rr;
    (void)t1;
    (void)t2;
    (void)t3;
    for (k = 0; k < ns; k++) {
        d->Vp[k] = N_VGetArrayPointer(yS[k]);
        d->Pp[k] = N_VGetArrayPointer(ypS[k]);
        d->Op[k] = N_VGetArrayPointer(rS[k]);
    }
    rc = eom__sens_dae_res(it->s, t, N_VGetArrayPointer(yy),
                           N_VGetArrayPointer(yp), ns, d->par, d->Vp, d->Pp,
                           d->Op, d->swork);
    if (rc != EOM_OK)
        snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t,
                 it->s->msg);
    return ida_cb_result(it, d, rc);
}

/* A failed setup call: a status and a message naming it. */
static int ida_setup_failed(eom_integ *it, int flag, const char *call)
{
    return eom__sun_setup_failed(it, IDAGetReturnFlagName(flag),
                                 flag == IDA_MEM_FAIL, call);
}

/* Y and a consistent Y' from the state d->w = (q, v, W) at t: lambda and
 * v' from the right-hand side (lambda' is not part of the residual). */
static int ida_consistent(eom_integ *it, ida *d, double t)
{
    const int n = it->n, m = it->s->m;
    double *Y = N_VGetArrayPointer(d->yy), *P = N_VGetArrayPointer(d->yp);
    int rc = eom__integ_rhs(it, t, d->w, d->wd);
    if (rc != EOM_OK)
        return rc;
    memcpy(Y, d->w, 2 * (size_t)n * sizeof(double));
    memcpy(P, d->wd, 2 * (size_t)n * sizeof(double));
    if (m > 0)
        memcpy(Y + 2 * n, it->s->lam, (size_t)m * sizeof(double));
    memset(P + 2 * n, 0, (size_t)m * sizeof(double));
    Y[2 * n + m] = d->w[2 * n];
    P[2 * n + m] = d->wd[2 * n];
    return EOM_OK;
}

/* Consistent sensitivities at the state d->w at t from it->S (their q
 * and v parts) and W's sensitivities in Wsens (ns; NULL: 0): lambda's
 * and the rates' from the right-hand sides of the sensitivities
 * (residual.c), as ida_consistent does for the state. */
static int ida_sens_consistent(eom_integ *it, ida *d, double t,
                               const double *Wsens)
{
    const int n = it->n, m = it->s->m, ns = d->ns, N = it->N;
    int i, k, rc;
    for (k = 0; k < ns; k++) {
        double *v = d->cols + (size_t)k * 2 * N;
        for (i = 0; i < 2 * n; i++)
            v[i] = it->S[(size_t)i * ns + k];
        v[2 * n] = Wsens ? Wsens[k] : 0.0;
        d->Vp[k] = v;
        d->Op[k] = v + N;
    }
    rc = eom__sens_rates(it->s, t, d->w, 0, ns, d->par, d->Vp, d->Op,
                         d->dlam, d->swork);
    if (rc != EOM_OK) {
        snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t,
                 it->s->msg);
        return rc;
    }
    for (k = 0; k < ns; k++) {
        double *Y = N_VGetArrayPointer(d->yS[k]);
        double *P = N_VGetArrayPointer(d->ypS[k]);
        const double *v = d->Vp[k], *r = d->Op[k];
        memcpy(Y, v, 2 * (size_t)n * sizeof(double));
        memcpy(P, r, 2 * (size_t)n * sizeof(double));
        if (m > 0)
            memcpy(Y + 2 * n, d->dlam + (size_t)k * m,
                   (size_t)m * sizeof(double));
        memset(P + 2 * n, 0, (size_t)m * sizeof(double));
        Y[2 * n + m] = v[2 * n];
        P[2 * n + m] = r[2 * n];
    }
    return EOM_OK;
}

static void ida_destroy(eom_integ *it)
{
    ida *d = it->impl;
    if (!d)
        return;
    IDAFree(&d->mem);
    if (d->yS)
        N_VDestroyVectorArray(d->yS, d->ns);
    if (d->ypS)
        N_VDestroyVectorArray(d->ypS, d->ns);
    free(d->par);
    free(d->swork);
    free(d->cols);
    free(d->dlam);
    free(d->Wsens);
    free(d->Vp);
    free(d->Pp);
    free(d->Op);
    if (d->LS)
        SUNLinSolFree(d->LS);
    if (d->A)
        SUNMatDestroy(d->A);
    if (d->yy)
        N_VDestroy(d->yy);
    if (d->yp)
        N_VDestroy(d->yp);
    if (d->id)
        N_VDestroy(d->id);
    if (d->ewt)
        N_VDestroy(d->ewt);
    if (d->ctx)
        SUNContext_Free(&d->ctx);
    free(d->w);
    free(d->wd);
    free(d);
    it->impl = NULL;
}

/* The iteration matrix and its linear solver: dense LU, or KLU on the
 * sparse matrix whose pattern (fixed for the run: KLU's symbolic
 * analysis is done once, each Jacobian refactors) is written here. */
static int ida_matrix(eom_integ *it, ida *d)
{
    eom_dae_pattern p;
    int choice, rc;
    rc = eom__dae_linear_solver(it->s, it->o.linear_solver,
                                it->o.dq_jacobian, &choice);
    if (rc != EOM_OK) {
        snprintf(it->msg, sizeof it->msg, "choosing the linear solver: %s",
                 it->s->msg);
        return rc;
    }
    d->sparse = choice == EOM_LINSOL_SPARSE;
    it->linsol = choice;
    if (!d->sparse) {
        d->A = SUNDenseMatrix(d->NY, d->NY, d->ctx);
        if (!d->A)
            return eom__integ_nomem(it);
        d->LS = SUNLinSol_Dense(d->yy, d->A, d->ctx);
        return d->LS ? EOM_OK : eom__integ_nomem(it);
    }
    if ((rc = eom__dae_pattern(it->s, &p)) != EOM_OK) {
        snprintf(it->msg, sizeof it->msg, "the sparse iteration matrix: %s",
                 it->s->msg);
        return rc;
    }
    d->A = SUNSparseMatrix(d->NY, d->NY, (sunindextype)p.nnz, CSC_MAT,
                           d->ctx);
    if (!d->A)
        return eom__integ_nomem(it);
    if ((rc = ida_pattern(it, d->A)) != EOM_OK) {
        snprintf(it->msg, sizeof it->msg, "the sparse iteration matrix: %s",
                 it->s->msg);
        return rc;
    }
    d->LS = SUNLinSol_KLU(d->yy, d->A, d->ctx);
    return d->LS ? EOM_OK : eom__integ_nomem(it);
}

/* What KLU said, when the sparse path failed in the linear solver: "" or
 * a sentence, into buf. */
static void ida_klu_why(const ida *d, int flag, char *buf, size_t len)
{
    sun_klu_common *k;
    const char *what;
    buf[0] = '\0';
    if (!d->sparse || !d->LS ||
        (flag != IDA_LSETUP_FAIL && flag != IDA_LSOLVE_FAIL))
        return;
    k = SUNLinSol_KLUGetCommon(d->LS);
    if (!k)
        return;
    switch (k->status) {
    case KLU_SINGULAR: what = "the iteration matrix is singular"; break;
    case KLU_OUT_OF_MEMORY: what = "out of memory"; break;
    case KLU_INVALID: what = "the matrix is invalid"; break;
    case KLU_TOO_LARGE: what = "the matrix is too large"; break;
    default: what = NULL; break;
    }
    if (what)
        snprintf(buf, len, "KLU, factoring the sparse iteration matrix "
                 "(%d x %d): %s (status %d); linear_solver 1 (dense) "
                 "takes the dense path", d->NY, d->NY, what,
                 (int)k->status);
    else
        snprintf(buf, len, "KLU, factoring the sparse iteration matrix "
                 "(%d x %d): status %d, rcond %.3g; linear_solver 1 "
                 "(dense) takes the dense path", d->NY, d->NY,
                 (int)k->status, k->rcond);
}

/* IDA's options and linear solver, once IDAInit has run. */
static int ida_setup(eom_integ *it, ida *d)
{
    const int m = it->s->m;
    int flag;
    if ((flag = IDASetUserData(d->mem, it)) < 0)
        return ida_setup_failed(it, flag, "IDASetUserData");
    /* Y = (q, v, lambda, W): atol_vec for q and v, atol after */
    flag = eom__sun_tolerances(it, d->mem, d->ctx, d->NY, IDASStolerances,
                               IDASVtolerances);
    if (flag == 1)
        return eom__integ_nomem(it);
    if (flag < 0)
        return ida_setup_failed(it, flag, it->atolv ? "IDASVtolerances"
                                                 : "IDASStolerances");
    /* explicitly: the default of 500 would stop tight-tolerance runs */
    if ((flag = IDASetMaxNumSteps(d->mem, it->o.max_steps)) < 0)
        return ida_setup_failed(it, flag, "IDASetMaxNumSteps");
    if ((flag = IDASetMaxOrd(d->mem, eom__integ_max_order(it))) < 0)
        return ida_setup_failed(it, flag, "IDASetMaxOrd");
    if (it->o.dt > 0.0 && (flag = IDASetInitStep(d->mem, it->o.dt)) < 0)
        return ida_setup_failed(it, flag, "IDASetInitStep");
    if (m > 0) {
        if ((flag = IDASetId(d->mem, d->id)) < 0)
            return ida_setup_failed(it, flag, "IDASetId");
        if ((flag = IDASetSuppressAlg(d->mem, SUNTRUE)) < 0)
            return ida_setup_failed(it, flag, "IDASetSuppressAlg");
    }
    if ((flag = ida_matrix(it, d)) != EOM_OK)
        return flag;
    if ((flag = IDASetLinearSolver(d->mem, d->LS, d->A)) < 0)
        return ida_setup_failed(it, flag, "IDASetLinearSolver");
    if (!it->o.dq_jacobian && (flag = IDASetJacFn(d->mem, ida_jac)) < 0)
        return ida_setup_failed(it, flag, "IDASetJacFn");
    return EOM_OK;
}

/* IDAS's sensitivities: consistent starts from it->S, the scales of
 * their tolerances (pbar = |p|, 1 for an initial value), and in the
 * error test. */
static int ida_sens_init(eom_integ *it, ida *d)
{
    const int ns = it->o.n_sens, np = it->s->np, m = it->s->m;
    double *pbar;
    int k, flag, rc;
    d->ns = ns;
    d->yS = N_VCloneVectorArray(ns, d->yy);
    d->ypS = N_VCloneVectorArray(ns, d->yy);
    d->par = malloc((size_t)ns * sizeof *d->par);
    d->swork = malloc(eom__sens_work(it->s, ns) * sizeof(double));
    d->cols = malloc((size_t)ns * 2 * (size_t)it->N * sizeof(double));
    d->dlam = malloc((size_t)ns * (size_t)(m > 0 ? m : 1) * sizeof(double));
    d->Wsens = malloc((size_t)ns * sizeof(double));
    d->Vp = malloc((size_t)ns * sizeof *d->Vp);
    d->Pp = malloc((size_t)ns * sizeof *d->Pp);
    d->Op = malloc((size_t)ns * sizeof *d->Op);
    pbar = malloc((size_t)ns * sizeof *pbar);
    if (!d->yS || !d->ypS || !d->par || !d->swork || !d->cols ||
        !d->dlam || !d->Wsens || !d->Vp || !d->Pp || !d->Op || !pbar) {
        free(pbar);
        return eom__integ_nomem(it);
    }
    for (k = 0; k < ns; k++) {
        const int w = it->sens[k];
        d->par[k] = w < np ? w : -1;
        pbar[k] = w < np && it->s->pval[w] != 0.0 ? fabs(it->s->pval[w])
                                                  : 1.0;
    }
    if ((rc = ida_sens_consistent(it, d, it->t, NULL)) != EOM_OK) {
        free(pbar);
        return rc;
    }
    flag = IDASensInit(d->mem, ns, IDA_STAGGERED, ida_sens_res, d->yS,
                       d->ypS);
    if (flag >= 0)
        flag = IDASetSensParams(d->mem, NULL, pbar, NULL);
    free(pbar);
    if (flag < 0)
        return ida_setup_failed(it, flag, "IDASensInit");
    if ((flag = IDASensEEtolerances(d->mem)) < 0)
        return ida_setup_failed(it, flag, "IDASensEEtolerances");
    /* in the error test, unlike CVODES's: left out of it, the
     * sensitivities of the four-bar at rtol 1e-5 grew without bound from
     * t = 2.5 (to 3.5e5 at t = 5, against 24.76), while the state's
     * were accurate */
    if ((flag = IDASetSensErrCon(d->mem, SUNTRUE)) < 0)
        return ida_setup_failed(it, flag, "IDASetSensErrCon");
    return EOM_OK;
}

static int ida_init(eom_integ *it)
{
    ida *d = calloc(1, sizeof *d);
    const int n = it->n, m = it->s->m;
    const size_t N = (size_t)it->N;
    double *id;
    int flag, rc, i;
    if (!d)
        return eom__integ_nomem(it);
    it->impl = d;
    d->NY = 2 * n + m + 1;
    d->w = calloc(N, sizeof(double));
    d->wd = calloc(N, sizeof(double));
    if (!d->w || !d->wd)
        return eom__integ_nomem(it);
    if (SUNContext_Create(NULL, &d->ctx) != 0) {
        d->ctx = NULL;
        return eom__integ_nomem(it);
    }
    d->yy = N_VNew_Serial(d->NY, d->ctx);
    if (!d->yy)
        return eom__integ_nomem(it);
    d->yp = N_VClone(d->yy);
    d->id = N_VClone(d->yy);
    d->ewt = N_VClone(d->yy);
    if (!d->yp || !d->id || !d->ewt)
        return eom__integ_nomem(it);
    id = N_VGetArrayPointer(d->id);
    for (i = 0; i < d->NY; i++)
        id[i] = i >= 2 * n && i < 2 * n + m ? 0.0 : 1.0;
    memcpy(d->w, it->y, N * sizeof(double));
    if ((rc = ida_consistent(it, d, it->t)) != EOM_OK)
        return rc;
    d->mem = IDACreate(d->ctx);
    if (!d->mem)
        return eom__integ_nomem(it);
    if ((flag = IDASetErrHandlerFn(d->mem, eom__sun_error, &d->rep)) < 0)
        return ida_setup_failed(it, flag, "IDASetErrHandlerFn");
    if ((flag = IDAInit(d->mem, ida_res, it->t, d->yy, d->yp)) < 0)
        return ida_setup_failed(it, flag, "IDAInit");
    if ((rc = ida_setup(it, d)) != EOM_OK)
        return rc;
    return it->o.n_sens > 0 ? ida_sens_init(it, d) : EOM_OK;
}

/* Counters that IDAReInit is about to zero. */
static void ida_bank(ida *d)
{
    long nst = 0, netf = 0, ncfn = 0, nje = 0;
    IDAGetNumSteps(d->mem, &nst);
    IDAGetNumErrTestFails(d->mem, &netf);
    IDAGetNumNonlinSolvConvFails(d->mem, &ncfn);
    if (!d->jacs_stale)
        IDAGetNumJacEvals(d->mem, &nje);
    d->banked_steps += nst;
    d->banked_fails += netf + ncfn;
    d->banked_jacs += nje;
    d->jacs_stale = 1;
}

/* The WRMS norm, with IDA's weights, of the change from the solver's
 * (q, v, W) to d->w. */
static double ida_change(eom_integ *it, ida *d)
{
    const int n = it->n, m = it->s->m, N = it->N;
    const double *Y = N_VGetArrayPointer(d->yy);
    const double *ewt = N_VGetArrayPointer(d->ewt);
    double sum = 0.0, e;
    int i;
    IDAGetErrWeights(d->mem, d->ewt);
    for (i = 0; i < 2 * n; i++) {
        e = (d->w[i] - Y[i]) * ewt[i];
        sum += e * e;
    }
    e = (d->w[2 * n] - Y[2 * n + m]) * ewt[2 * n + m];
    sum += e * e;
    return sqrt(sum / N);
}

/* The sensitivities at tout into it->S: IDAS's, with projection on and
 * constraints projected at the projected state d->w (sensitivity.c);
 * W's sensitivities kept in d->Wsens for a restart. A status, with a
 * message in it->msg. */
static int ida_output_sens(eom_integ *it, ida *d, double tout)
{
    const int n = it->n, m = it->s->m, ns = d->ns;
    sunrealtype ts;
    int flag, rc, k, i;
    if ((flag = IDAGetSens(d->mem, &ts, d->yS)) < 0)
        return ida_setup_failed(it, flag, "IDAGetSens");
    for (k = 0; k < ns; k++) {
        double *v = d->cols + (size_t)k * 2 * it->N;
        const double *y = N_VGetArrayPointer(d->yS[k]);
        memcpy(v, y, 2 * (size_t)n * sizeof(double));
        d->Op[k] = v;
    }
    if (m > 0 && it->o.project) {
        rc = eom__sens_project(it->s, tout, d->w, 0, ns, d->par, d->Op,
                               d->swork);
        if (rc != EOM_OK) {
            snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", tout,
                     it->s->msg);
            return rc;
        }
    }
    for (k = 0; k < ns; k++) {
        for (i = 0; i < 2 * n; i++)
            it->S[(size_t)i * ns + k] = d->Op[k][i];
        d->Wsens[k] = N_VGetArrayPointer(d->yS[k])[2 * n + m];
    }
    return EOM_OK;
}

/* At tout, with the solver's state in d->yy: the state for the caller,
 * projected (or only its residual tracked) when the system has
 * constraints, and a restart from it when the drift exceeds the local
 * error tolerance. */
static int ida_output(eom_integ *it, ida *d, double tout)
{
    const int n = it->n, m = it->s->m;
    const double *Y = N_VGetArrayPointer(d->yy);
    int rc, flag;
    it->t = tout;
    memcpy(d->w, Y, 2 * (size_t)n * sizeof(double));
    d->w[2 * n] = Y[2 * n + m];
    if (m > 0 && (rc = eom__integ_project(it, d->w)) != EOM_OK)
        return eom__integ_fail(it, rc, "ida: %s", it->msg);
    if (d->ns > 0 && (rc = ida_output_sens(it, d, tout)) != EOM_OK)
        return eom__integ_fail(it, rc, "ida: %s", it->msg);
    if (m > 0 && it->o.project && ida_change(it, d) > 1.0) {
        if ((rc = ida_consistent(it, d, tout)) != EOM_OK ||
            (d->ns > 0 &&
             (rc = ida_sens_consistent(it, d, tout, d->Wsens)) != EOM_OK))
            return eom__integ_fail(it, rc, "ida: %s", it->msg);
        ida_bank(d);
        flag = IDAReInit(d->mem, tout, d->yy, d->yp);
        if (flag >= 0 && d->ns > 0)
            flag = IDASensReInit(d->mem, IDA_STAGGERED, d->yS, d->ypS);
        if (flag < 0) {
            rc = ida_setup_failed(it, flag, d->ns > 0 ? "IDASensReInit"
                                                      : "IDAReInit");
            return eom__integ_fail(it, rc, "ida: %s", it->msg);
        }
    }
    memcpy(it->y, d->w, (size_t)it->N * sizeof(double));
    return EOM_OK;
}

/* The state of the step just taken, evaluated once: EOM_OK, or the
 * refusal of a singular constraint system (eom__integ_rhs). */
static int ida_regular(eom_integ *it, ida *d, double t)
{
    const int n = it->n, m = it->s->m;
    const double *Y = N_VGetArrayPointer(d->yy);
    memcpy(d->w, Y, 2 * (size_t)n * sizeof(double));
    d->w[2 * n] = Y[2 * n + m];
    return eom__integ_rhs(it, t, d->w, d->wd);
}

static int ida_advance(eom_integ *it, double tout)
{
    ida *d = it->impl;
    const double t_last = it->t;
    sunrealtype tret = it->t, tcur = it->t, hlast = 0.0;
    int flag, status;
    eom__sun_report_reset(&d->rep);
    flag = IDASetMinStep(d->mem, eom__sun_min_step(it->t, tout));
    if (flag >= 0)
        flag = IDASetStopTime(d->mem, tout);
    if (flag >= 0 && it->s->m == 0) {
        flag = IDASolve(d->mem, tout, &tret, d->yy, d->yp, IDA_NORMAL);
        d->jacs_stale = 0;
    } else if (flag >= 0) {
        /* step by step, each step's state checked for a singular
         * constraint system, which the index-1 form cannot pass */
        do {
            flag = IDASolve(d->mem, tout, &tret, d->yy, d->yp,
                            IDA_ONE_STEP);
            d->jacs_stale = 0;
            if (flag >= 0 && ((status = ida_regular(it, d, tret)) != EOM_OK ||
                              (status = eom__integ_branch(it, tret, d->w)) !=
                                  EOM_OK)) {
                IDAGetCurrentTime(d->mem, &tcur);
                return eom__integ_fail(it, status, "ida: %s", it->msg);
            }
        } while (flag == IDA_SUCCESS && tret < tout);
    }
    IDAGetCurrentTime(d->mem, &tcur);
    if (flag >= 0) {
        /* a success that did not reach tout is not one */
        IDAGetLastStep(d->mem, &hlast);
        if (tcur < tout - 100.0 * DBL_EPSILON * (fabs(tout) + fabs(hlast)))
            return eom__integ_fail(it, EOM_ERR_SOLVER,
                                   "ida: stopped at t = %.17g before tout "
                                   "= %.17g (last step %.3g)", tcur, tout,
                                   hlast);
        status = ida_output(it, d, tout);
        if (status != EOM_OK)
            it->t = t_last; /* it->y still holds the state at t_last */
        return status;
    }
    /* it->y keeps the state at the last output time */
    if (it->refuse_singular && it->s->m > 0 && it->s->rcond_S < 1e-2 &&
        (flag == IDA_CONV_FAIL || flag == IDA_ERR_FAIL)) {
        /* failed close to a singular position, before any evaluation
         * there needed the filtered solve: the stretch is bdf's, as at a
         * refusal (integrate_handover.c). Measured: the parallelogram in
         * relative angles at rtol 1e-10 (test_parallelogram.c), Newton
         * failing at t = 19.786 with h = 6.6e-12, rcond 1.1e-5. */
        char *why = IDAGetReturnFlagName(flag); /* malloc'd: ours */
        it->t_refused = tcur;
        status = eom__integ_fail(it, EOM_ERR_RANK_DEFICIENT,
                                 "ida: %s at t = %.17g near a singular "
                                 "position (rcond of C M^-1 C^T %.2g)",
                                 why ? why : "failure", tcur,
                                 it->s->rcond_S);
        free(why);
        return status;
    }
    status = eom__sun_failed(it, &d->rep, "ida", IDAGetReturnFlagName(flag),
                             tcur);
    {
        char klu[256];
        ida_klu_why(d, flag, klu, sizeof klu);
        if (klu[0]) {
            const size_t used = strlen(it->msg);
            snprintf(it->msg + used, sizeof it->msg - used, "; %s", klu);
        }
    }
    return status;
}

static void ida_stats(const eom_integ *it, eom_stats *st)
{
    const ida *d = it->impl;
    long nst = 0, netf = 0, ncfn = 0, nje = 0;
    IDAGetNumSteps(d->mem, &nst);
    IDAGetNumErrTestFails(d->mem, &netf);
    IDAGetNumNonlinSolvConvFails(d->mem, &ncfn);
    if (!d->jacs_stale)
        IDAGetNumJacEvals(d->mem, &nje);
    st->steps = d->banked_steps + nst;
    st->failures = d->banked_fails + netf + ncfn;
    st->jac_evals = d->banked_jacs + nje;
    /* rhs_evals: the common counter, which ida_res also increments */
}

const eom_integ_ops eom__ida_ops = {"ida", ida_init, ida_advance, ida_stats,
                                    ida_destroy};
