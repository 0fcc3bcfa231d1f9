/* integrate_arkode.c - EOM_ERK: ARKODE's ERKStep, an adaptive explicit
 * Runge-Kutta method on y = (q, qd, W), with the Verner 8-5-6 table of
 * SUNDIALS 6.4 (8 stages, order 6, embedded order 5 for the error
 * estimate; 6.4 has no 8th-order Verner table).
 *
 * Output times: each advance sets the stop time to tout, so the last step
 * ends on tout and the state returned is a step result, not an
 * interpolant. Drift: a step postprocessing function projects every
 * accepted step onto the constraints (when projection is on and the
 * system has constraints), before ARKODE updates its interpolation data
 * and uses the step as the start of the next one. It is installed for
 * every model, for the method's order (see erk_init).
 *
 * Callbacks return 0, +1 for EOM_ERR_NONFINITE and -1 otherwise, and keep
 * the status and message of the most recent one: when the solver fails
 * right after a failed callback, that callback's status is the cause.
 * ERKStep itself treats +1 from the right-hand side as unrecoverable
 * (ARK_UNREC_RHSFUNC_ERR); it does not retry with a smaller step.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arkode/arkode_erkstep.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include "integrate_internal.h"

#define ERK_TABLE ARKODE_VERNER_8_5_6

/* The ERK tables of SUNDIALS 6.4 (arkode_butcher_erk.h) with an embedded
 * error estimate, by name: checked here so that an unknown name is
 * refused with the list, before ARKODE would print its own error.
 * ARKODE_KNOTH_WOLKE_3_3 has no embedding, so it cannot choose its steps
 * (ARKODE refuses it with ARK_ILL_INPUT) and is left out. */
static const char *const erk_tables[] = {
    "ARKODE_HEUN_EULER_2_1_2",     "ARKODE_BOGACKI_SHAMPINE_4_2_3",
    "ARKODE_ARK324L2SA_ERK_4_2_3", "ARKODE_ZONNEVELD_5_3_4",
    "ARKODE_ARK436L2SA_ERK_6_3_4", "ARKODE_SAYFY_ABURUB_6_3_4",
    "ARKODE_CASH_KARP_6_4_5",      "ARKODE_FEHLBERG_6_4_5",
    "ARKODE_DORMAND_PRINCE_7_4_5", "ARKODE_ARK548L2SA_ERK_8_4_5",
    "ARKODE_VERNER_8_5_6",         "ARKODE_FEHLBERG_13_7_8",
    "ARKODE_ARK437L2SA_ERK_7_3_4", "ARKODE_ARK548L2SAb_ERK_8_4_5",
};

const char *eom_erk_table_name(int k)
{
    const int count = (int)(sizeof erk_tables / sizeof erk_tables[0]);
    return k >= 0 && k < count ? erk_tables[k] : NULL;
}

static int erk_table_known(const char *name)
{
    int k;
    for (k = 0; eom_erk_table_name(k); k++)
        if (strcmp(eom_erk_table_name(k), name) == 0)
            return 1;
    return 0;
}

typedef struct erk {
    SUNContext ctx;
    N_Vector y;                /* [N] the solver's state */
    void *mem;                 /* ERKStep memory */
    eom_sun_report rep;        /* why it stopped */
} erk;

static int erk_cb_result(eom_integ *it, erk *e, int rc)
{
    return eom__sun_cb_result(it, &e->rep, rc);
}

static int erk_rhs(sunrealtype t, N_Vector y, N_Vector yd, void *user)
{
    eom_integ *it = user;
    int rc = eom__integ_rhs(it, t, N_VGetArrayPointer(y),
                            N_VGetArrayPointer(yd));
    return erk_cb_result(it, it->impl, rc);
}

/* After each accepted step: project y in place (or only track the
 * residual when projection is off), and watch the assembly branch. */
static int erk_postprocess(sunrealtype t, N_Vector y, void *user)
{
    eom_integ *it = user;
    /* it->t is the last output time; the messages should name this step */
    const double t_out = it->t;
    int rc;
    it->t = t;
    rc = eom__integ_project(it, N_VGetArrayPointer(y));
    if (rc == EOM_OK)
        rc = eom__integ_branch(it, t, N_VGetArrayPointer(y));
    it->t = t_out;
    return erk_cb_result(it, it->impl, rc);
}

/* A failed setup call: a status and a message naming it. */
static int erk_setup_failed(eom_integ *it, int flag, const char *call)
{
    return eom__sun_setup_failed(it, ERKStepGetReturnFlagName(flag),
                                 flag == ARK_MEM_FAIL, call);
}

static void erk_destroy(eom_integ *it)
{
    erk *e = it->impl;
    if (!e)
        return;
    ERKStepFree(&e->mem);
    if (e->y)
        N_VDestroy(e->y);
    if (e->ctx)
        SUNContext_Free(&e->ctx);
    free(e);
    it->impl = NULL;
}

static int erk_init(eom_integ *it)
{
    erk *e = calloc(1, sizeof *e);
    int flag;
    if (!e)
        return eom__integ_nomem(it);
    it->impl = e;
    if (SUNContext_Create(NULL, &e->ctx) != 0) {
        e->ctx = NULL;
        return eom__integ_nomem(it);
    }
    e->y = N_VNew_Serial(it->N, e->ctx);
    if (!e->y)
        return eom__integ_nomem(it);
    memcpy(N_VGetArrayPointer(e->y), it->y, (size_t)it->N * sizeof(double));
    e->mem = ERKStepCreate(erk_rhs, it->t, e->y, e->ctx);
    if (!e->mem)
        return eom__integ_nomem(it);
    if ((flag = ERKStepSetErrHandlerFn(e->mem, eom__sun_error, &e->rep)) < 0)
        return erk_setup_failed(it, flag, "ERKStepSetErrHandlerFn");
    if ((flag = ERKStepSetUserData(e->mem, it)) < 0)
        return erk_setup_failed(it, flag, "ERKStepSetUserData");
    if (it->erk_table[0]) {
        if (!erk_table_known(it->erk_table))
            return eom__integ_fail(it, EOM_ERR_ARG,
                                   "unknown ERK table '%s' (eom_erk_table_name "
                                   "lists them; docs/integrators.md too)",
                                   it->erk_table);
        if ((flag = ERKStepSetTableName(e->mem, it->erk_table)) < 0)
            return erk_setup_failed(it, flag, "ERKStepSetTableName");
    } else if ((flag = ERKStepSetTableNum(e->mem, ERK_TABLE)) < 0) {
        return erk_setup_failed(it, flag, "ERKStepSetTableNum");
    }
    flag = eom__sun_tolerances(it, e->mem, e->ctx, it->N,
                               ERKStepSStolerances, ERKStepSVtolerances);
    if (flag == 1)
        return eom__integ_nomem(it);
    if (flag < 0)
        return erk_setup_failed(it, flag, it->atolv ? "ERKStepSVtolerances"
                                                 : "ERKStepSStolerances");
    /* explicitly: the default of 500 would stop tight-tolerance runs */
    if ((flag = ERKStepSetMaxNumSteps(e->mem, it->o.max_steps)) < 0)
        return erk_setup_failed(it, flag, "ERKStepSetMaxNumSteps");
    if (it->o.dt > 0.0 &&
        (flag = ERKStepSetInitStep(e->mem, it->o.dt)) < 0)
        return erk_setup_failed(it, flag, "ERKStepSetInitStep");
    /* Installed for every model, constraints or not: ERKStep in SUNDIALS
     * 6.4 takes the last stage of any table whose last node is c = 1 as
     * f at the new step (first-same-as-last), although for Verner 8-5-6
     * the last row of A is not b^T (llnl/sundials issue 311); the method
     * then drops to order 3 (tests/eom_integrate/test_order.c measures it
     * at 3.0, and 6.0 with this). A step postprocessing function tells
     * ERKStep the step may have changed y, so it evaluates f at y_n+1
     * afresh: one right-hand side per step, which a table that is not
     * FSAL needs anyway. Without constraints the function does nothing. */
    if ((flag = ERKStepSetPostprocessStepFn(e->mem, erk_postprocess)) < 0)
        return erk_setup_failed(it, flag, "ERKStepSetPostprocessStepFn");
    return EOM_OK;
}

static int erk_advance(eom_integ *it, double tout)
{
    erk *e = it->impl;
    sunrealtype tret = it->t, tcur = it->t, hlast = 0.0;
    int flag;
    eom__sun_report_reset(&e->rep);
    flag = ERKStepSetMinStep(e->mem, eom__sun_min_step(it->t, tout));
    if (flag >= 0)
        flag = ERKStepSetStopTime(e->mem, tout);
    if (flag >= 0)
        flag = ERKStepEvolve(e->mem, tout, e->y, &tret, ARK_NORMAL);
    ERKStepGetCurrentTime(e->mem, &tcur);
    if (flag >= 0) {
        /* a success that did not reach tout is not one */
        ERKStepGetLastStep(e->mem, &hlast);
        if (tcur < tout - 100.0 * DBL_EPSILON * (fabs(tout) + fabs(hlast)))
            return eom__integ_fail(it, EOM_ERR_SOLVER,
                                   "erk: stopped at t = %.17g before tout "
                                   "= %.17g (last step %.3g)", tcur, tout,
                                   hlast);
        memcpy(it->y, N_VGetArrayPointer(e->y),
               (size_t)it->N * sizeof(double));
        it->t = tout;
        return EOM_OK;
    }
    /* it->y keeps the state at the last output time */
    return eom__sun_failed(it, &e->rep, "erk", ERKStepGetReturnFlagName(flag),
                           tcur);
}

static void erk_stats(const eom_integ *it, eom_stats *st)
{
    const erk *e = it->impl;
    long steps = 0, etf = 0;
    ERKStepGetNumSteps(e->mem, &steps);
    ERKStepGetNumErrTestFails(e->mem, &etf);
    st->steps = steps;
    st->failures = etf;
    st->jac_evals = 0;
    /* rhs_evals: the common counter, which sees every evaluation */
}

const eom_integ_ops eom__erk_ops = {"erk", erk_init, erk_advance, erk_stats,
                                    erk_destroy};
