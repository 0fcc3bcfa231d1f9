/* integrate_arkstep.c - what the ARKODE methods share: erk (ERKStep,
 * integrate_arkode.c), esdirk and imex (ARKStep with a dense Newton
 * solver, integrate_esdirk.c and integrate_imex.c).
 *
 * Each method's impl begins with an eom_ark (integrate_internal.h), so the
 * callbacks here take the integrator as user data and find the solver at
 * it->impl; the solver's stepper table (eom__erkstep, eom__arkstep) names
 * the ERKStep or ARKStep function each call goes to. The ARKStep setup and
 * statistics serve esdirk and imex, which differ only in their right-hand
 * sides, tables and Jacobians; erk sets up its own table and keeps its own
 * counters. Messages name the method, so the ones a run writes are the
 * method's own.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <arkode/arkode_arkstep.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "integrate_internal.h"

int eom__ark_cb_result(eom_integ *it, int rc)
{
    eom_ark *a = it->impl;
    return eom__sun_cb_result(it, &a->rep, rc);
}

int eom__ark_rhs(sunrealtype t, N_Vector y, N_Vector yd, void *user)
{
    eom_integ *it = user;
    int rc = eom__integ_rhs(it, t, N_VGetArrayPointer(y),
                            N_VGetArrayPointer(yd));
    return eom__ark_cb_result(it, rc);
}

int eom__ark_postprocess(sunrealtype t, N_Vector y, void *user)
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
    return eom__ark_cb_result(it, rc);
}

const eom_ark_stepper eom__arkstep = EOM_ARK_STEPPER(ARK);

int eom__ark_start(eom_integ *it, eom_ark *a, const eom_ark_stepper *step)
{
    a->step = step;
    if (SUNContext_Create(NULL, &a->ctx) != 0) {
        a->ctx = NULL;
        return eom__integ_nomem(it);
    }
    a->y = N_VNew_Serial(it->N, a->ctx);
    if (!a->y)
        return eom__integ_nomem(it);
    memcpy(N_VGetArrayPointer(a->y), it->y, (size_t)it->N * sizeof(double));
    return EOM_OK;
}

void eom__ark_free(eom_ark *a)
{
    if (a->step)
        a->step->free_mem(&a->mem);
    if (a->LS)
        SUNLinSolFree(a->LS);
    if (a->A)
        SUNMatDestroy(a->A);
    if (a->y)
        N_VDestroy(a->y);
    if (a->ctx)
        SUNContext_Free(&a->ctx);
}

int eom__ark_setup_failed(eom_integ *it, int flag, const char *call)
{
    const eom_ark *a = it->impl;
    return eom__sun_setup_failed(it, a->step->flag_name(flag),
                                 flag == ARK_MEM_FAIL, call);
}

int eom__ark_advance(eom_integ *it, double tout, const char *method)
{
    eom_ark *a = it->impl;
    const eom_ark_stepper *f = a->step;
    sunrealtype tret = it->t, tcur = it->t, hlast = 0.0;
    int flag;
    eom__sun_report_reset(&a->rep);
    flag = f->set_min_step(a->mem, eom__sun_min_step(it->t, tout));
    if (flag >= 0)
        flag = f->set_stop_time(a->mem, tout);
    if (flag >= 0 && it->handing) {
        /* a singular stretch (integrate_handover.c): step by step, each
         * accepted step's state evaluated for the conditioning of the
         * constraint system, until the stretch is behind */
        do {
            flag = f->evolve(a->mem, tout, a->y, &tret, ARK_ONE_STEP);
            if (flag < 0 || tret >= tout)
                break;
            it->st.rhs_evals++;
            if (eom__evaluate(it->s, tret, N_VGetArrayPointer(a->y)) ==
                    EOM_OK &&
                eom__integ_stretch_done(it, tret)) {
                it->t = tret;
                memcpy(it->y, N_VGetArrayPointer(a->y),
                       (size_t)it->N * sizeof(double));
                return EOM_OK;
            }
        } while (1);
    } else if (flag >= 0) {
        flag = f->evolve(a->mem, tout, a->y, &tret, ARK_NORMAL);
    }
    f->get_current_time(a->mem, &tcur);
    if (flag < 0) {
        /* it->y keeps the state at the last output time; where it failed
         * (a singular stretch handed to erk ends after it) */
        it->t_refused = tcur;
        return eom__sun_failed(it, &a->rep, method, f->flag_name(flag),
                               tcur);
    }
    /* a success that did not reach tout is not one */
    f->get_last_step(a->mem, &hlast);
    if (tcur < tout - 100.0 * DBL_EPSILON * (fabs(tout) + fabs(hlast)))
        return eom__integ_fail(it, EOM_ERR_SOLVER,
                               "%s: stopped at t = %.17g before tout = %.17g "
                               "(last step %.3g)", method, tcur, tout, hlast);
    memcpy(it->y, N_VGetArrayPointer(a->y), (size_t)it->N * sizeof(double));
    it->t = tout;
    return EOM_OK;
}

int eom__ark_implicit_init(eom_integ *it, eom_ark *a, ARKRhsFn fe,
                           ARKRhsFn fi, ARKLsJacFn jac,
                           ARKODE_DIRKTableID itable,
                           ARKODE_ERKTableID etable)
{
    int flag, rc;
    if ((rc = eom__ark_start(it, a, &eom__arkstep)) != EOM_OK)
        return rc;
    a->mem = ARKStepCreate(fe, fi, it->t, a->y, a->ctx);
    if (!a->mem)
        return eom__integ_nomem(it);
    if ((flag = ARKStepSetErrHandlerFn(a->mem, eom__sun_error, &a->rep)) < 0)
        return eom__ark_setup_failed(it, flag, "ARKStepSetErrHandlerFn");
    if ((flag = ARKStepSetUserData(a->mem, it)) < 0)
        return eom__ark_setup_failed(it, flag, "ARKStepSetUserData");
    if ((flag = ARKStepSetTableNum(a->mem, itable, etable)) < 0)
        return eom__ark_setup_failed(it, flag, "ARKStepSetTableNum");
    flag = eom__sun_tolerances(it, a->mem, a->ctx, it->N,
                               ARKStepSStolerances, ARKStepSVtolerances);
    if (flag == 1)
        return eom__integ_nomem(it);
    if (flag < 0)
        return eom__ark_setup_failed(it, flag,
                                     it->atolv ? "ARKStepSVtolerances"
                                               : "ARKStepSStolerances");
    a->A = SUNDenseMatrix(it->N, it->N, a->ctx);
    if (!a->A)
        return eom__integ_nomem(it);
    a->LS = SUNLinSol_Dense(a->y, a->A, a->ctx);
    if (!a->LS)
        return eom__integ_nomem(it);
    if ((flag = ARKStepSetLinearSolver(a->mem, a->LS, a->A)) < 0)
        return eom__ark_setup_failed(it, flag, "ARKStepSetLinearSolver");
    if (!it->o.dq_jacobian && (flag = ARKStepSetJacFn(a->mem, jac)) < 0)
        return eom__ark_setup_failed(it, flag, "ARKStepSetJacFn");
    /* explicitly: the default of 500 would stop tight-tolerance runs */
    if ((flag = ARKStepSetMaxNumSteps(a->mem, it->o.max_steps)) < 0)
        return eom__ark_setup_failed(it, flag, "ARKStepSetMaxNumSteps");
    if (it->o.dt > 0.0 &&
        (flag = ARKStepSetInitStep(a->mem, it->o.dt)) < 0)
        return eom__ark_setup_failed(it, flag, "ARKStepSetInitStep");
    /* the stages' Newton iterations start from the interpolant of the
     * last step at its full order, not from y_n: with the trivial
     * predictor and the Newton matrix kept over steps, the nonlinear
     * solves passed their test with errors the error estimate does not
     * see (esdirk on an oscillator at atol 1e-3 ended 129 off, at 1e-12
     * per step rtol; with this one 0.15) */
    if ((flag = ARKStepSetPredictorMethod(a->mem, 1)) < 0)
        return eom__ark_setup_failed(it, flag, "ARKStepSetPredictorMethod");
    /* without constraints there is nothing to project or watch, and the
     * tables keep their order with the last stage reused (unlike erk's
     * Verner table, integrate_arkode.c) */
    if (it->s->m > 0 &&
        (flag = ARKStepSetPostprocessStepFn(a->mem, eom__ark_postprocess)) <
            0)
        return eom__ark_setup_failed(it, flag, "ARKStepSetPostprocessStepFn");
    return EOM_OK;
}

void eom__ark_stats(const eom_integ *it, eom_stats *st)
{
    const eom_ark *a = it->impl;
    long steps = 0, etf = 0, ncf = 0, nje = 0;
    ARKStepGetNumSteps(a->mem, &steps);
    ARKStepGetNumErrTestFails(a->mem, &etf);
    ARKStepGetNumNonlinSolvConvFails(a->mem, &ncf);
    ARKStepGetNumJacEvals(a->mem, &nje);
    st->steps = steps;
    st->failures = etf + ncf;
    st->jac_evals = nje;
    /* rhs_evals: the common counter, which sees every evaluation of the
     * model, the difference quotients of the Jacobian included (imex: a
     * stage's f_E and f_I share one) */
}
