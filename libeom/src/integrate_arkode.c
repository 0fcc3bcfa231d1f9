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
 * (ARK_UNREC_RHSFUNC_ERR); it does not retry with a smaller step. The
 * callbacks, the solver's state, the setup messages and the advance are
 * esdirk's and imex's too (integrate_arkstep.c), through ERKStep's table
 * of functions here.
 */
#include <stdlib.h>
#include <string.h>

#include <arkode/arkode_erkstep.h>
#include <nvector/nvector_serial.h>

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

/* ERKStep's functions for the shared advance and messages. */
const eom_ark_stepper eom__erkstep = EOM_ARK_STEPPER(ERK);

static void erk_destroy(eom_integ *it)
{
    eom_ark *e = it->impl;
    if (!e)
        return;
    eom__ark_free(e);
    free(e);
    it->impl = NULL;
}

static int erk_init(eom_integ *it)
{
    /* the method's impl is the solver alone (integrate_arkstep.c), with
     * no Newton matrix or linear solver */
    eom_ark *e = calloc(1, sizeof *e);
    int flag, rc;
    if (!e)
        return eom__integ_nomem(it);
    it->impl = e;
    if ((rc = eom__ark_start(it, e, &eom__erkstep)) != EOM_OK)
        return rc;
    e->mem = ERKStepCreate(eom__ark_rhs, it->t, e->y, e->ctx);
    if (!e->mem)
        return eom__integ_nomem(it);
    if ((flag = ERKStepSetErrHandlerFn(e->mem, eom__sun_error, &e->rep)) < 0)
        return eom__ark_setup_failed(it, flag, "ERKStepSetErrHandlerFn");
    if ((flag = ERKStepSetUserData(e->mem, it)) < 0)
        return eom__ark_setup_failed(it, flag, "ERKStepSetUserData");
    if (it->erk_table[0]) {
        if (!erk_table_known(it->erk_table))
            return eom__integ_fail(it, EOM_ERR_ARG,
                                   "unknown ERK table '%s' (eom_erk_table_name "
                                   "lists them; docs/integrators.md too)",
                                   it->erk_table);
        if ((flag = ERKStepSetTableName(e->mem, it->erk_table)) < 0)
            return eom__ark_setup_failed(it, flag, "ERKStepSetTableName");
    } else if ((flag = ERKStepSetTableNum(e->mem, ERK_TABLE)) < 0) {
        return eom__ark_setup_failed(it, flag, "ERKStepSetTableNum");
    }
    flag = eom__sun_tolerances(it, e->mem, e->ctx, it->N,
                               ERKStepSStolerances, ERKStepSVtolerances);
    if (flag == 1)
        return eom__integ_nomem(it);
    if (flag < 0)
        return eom__ark_setup_failed(it, flag,
                                     it->atolv ? "ERKStepSVtolerances"
                                               : "ERKStepSStolerances");
    /* explicitly: the default of 500 would stop tight-tolerance runs */
    if ((flag = ERKStepSetMaxNumSteps(e->mem, it->o.max_steps)) < 0)
        return eom__ark_setup_failed(it, flag, "ERKStepSetMaxNumSteps");
    if (it->o.dt > 0.0 &&
        (flag = ERKStepSetInitStep(e->mem, it->o.dt)) < 0)
        return eom__ark_setup_failed(it, flag, "ERKStepSetInitStep");
    /* Installed for every model, constraints or not: ERKStep in SUNDIALS
     * 6.4 takes the last stage of any table whose last node is c = 1 as
     * f at the new step (first-same-as-last), although for Verner 8-5-6
     * the last row of A is not b^T (llnl/sundials issue 311); the method
     * then drops to order 3 (tests/eom_integrate/test_order.c measures it
     * at 3.0, and 6.0 with this). A step postprocessing function tells
     * ERKStep the step may have changed y, so it evaluates f at y_n+1
     * afresh: one right-hand side per step, which a table that is not
     * FSAL needs anyway. Without constraints the function does nothing. */
    if ((flag = ERKStepSetPostprocessStepFn(e->mem,
                                            eom__ark_postprocess)) < 0)
        return eom__ark_setup_failed(it, flag,
                                     "ERKStepSetPostprocessStepFn");
    return EOM_OK;
}

static int erk_advance(eom_integ *it, double tout)
{
    return eom__ark_advance(it, tout, "erk");
}

static void erk_stats(const eom_integ *it, eom_stats *st)
{
    const eom_ark *e = it->impl;
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
