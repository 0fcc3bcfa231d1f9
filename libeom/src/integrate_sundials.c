/* integrate_sundials.c - what the SUNDIALS methods (ERK, Adams/BDF, IDA)
 * share: turning a callback's status into the solver's convention and
 * remembering why, keeping the solver's own error message instead of
 * letting it print, setup failures, and the smallest step of an advance. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "integrate_internal.h"

void eom__sun_report_reset(eom_sun_report *r)
{
    r->cb_status = EOM_OK;
    r->cb_msg[0] = '\0';
    r->sun_msg[0] = '\0';
}

int eom__sun_cb_result(eom_integ *it, eom_sun_report *r, int rc)
{
    r->cb_status = rc;
    if (rc == EOM_OK)
        return 0;
    memcpy(r->cb_msg, it->msg, sizeof r->cb_msg);
    /* a non-finite result may go away with a smaller step: recoverable */
    return rc == EOM_ERR_NONFINITE ? 1 : -1;
}

void eom__sun_error(int code, const char *module, const char *function,
                    char *msg, void *user)
{
    eom_sun_report *r = user;
    (void)module;
    /* warnings describe recoverable events; keep only errors */
    if (code < 0)
        snprintf(r->sun_msg, sizeof r->sun_msg, "%s: %s", function, msg);
}

int eom__sun_tolerances(eom_integ *it, void *mem, SUNContext ctx, int len,
                        eom_sun_ss ss, eom_sun_sv sv)
{
    const double rtol = eom__integ_step_tol(it, it->o.rtol);
    N_Vector a;
    int flag;
    if (!it->atolv) {
        return ss(mem, rtol, eom__integ_step_tol(it, it->o.atol));
    }
    if (!(a = N_VNew_Serial((sunindextype)len, ctx)))
        return 1;
    eom__integ_atol(it, N_VGetArrayPointer(a), len);
    flag = sv(mem, rtol, a); /* copies a */
    N_VDestroy(a);
    return flag;
}

int eom__integ_nomem(eom_integ *it)
{
    snprintf(it->msg, sizeof it->msg, "out of memory");
    return EOM_ERR_NOMEM;
}

int eom__sun_setup_failed(eom_integ *it, char *flag_name, int mem_fail,
                          const char *call)
{
    snprintf(it->msg, sizeof it->msg, "%s failed: %s", call,
             flag_name ? flag_name : "unknown flag");
    free(flag_name);
    return mem_fail ? EOM_ERR_NOMEM : EOM_ERR_SOLVER;
}

int eom__sun_failed(eom_integ *it, const eom_sun_report *r,
                    const char *method, char *flag_name, double t)
{
    /* a failed callback is the cause; otherwise the solver's own error */
    const int status = r->cb_status != EOM_OK ? r->cb_status : EOM_ERR_SOLVER;
    const char *why = r->cb_status != EOM_OK ? r->cb_msg : r->sun_msg;
    char guess[3 * EOM_MSG_LEN], note[400];
    if (!why[0]) {
        /* the solver gave no reason: say what the run's figures suggest */
        if (it->s->m > 0 && it->s->rcond_S_min < 1e-3)
            snprintf(guess, sizeof guess, "the solver gave no reason; the "
                     "constraint system's smallest rcond so far is %.2g, so "
                     "a singular position or redundant constraints are the "
                     "likely cause (docs/integrators.md, \"Singular "
                     "positions\")", it->s->rcond_S_min);
        else
            snprintf(guess, sizeof guess, "the solver gave no reason; a "
                     "point its steps cannot pass (a discontinuity, a "
                     "singularity or a domain edge of the model) is the "
                     "likely cause (docs/troubleshooting.md)");
        why = guess;
    }
    if (why != guess && it->s->m > 0 && status == EOM_ERR_SOLVER) {
        /* the solver's own reason; with constraints the health of their
         * solve says whether a singular position is the likely cause */
        snprintf(guess, sizeof guess, "%s (constraint system's smallest "
                 "rcond so far %.2g%s)", why, it->s->rcond_S_min,
                 it->s->rcond_S_min < 1e-3
                     ? ": a singular position or redundant constraints are "
                       "the likely cause"
                     : "");
        why = guess;
    }
    note[0] = '\0';
    if (status == EOM_ERR_SOLVER && it->s->mf_valid) {
        /* an error test that fails, a step that collapses: a mass matrix
         * close to singular at the last evaluation is the likely cause,
         * named here beside the solver's generic reason */
        int k;
        const double piv = eom__mass_min_pivot(it->s, &k);
        if (piv < 1e-6)
            snprintf(note, sizeof note, "; the mass matrix is nearly "
                     "singular at the last evaluation: the coordinate '%.64s' "
                     "(leading minor of order %d) keeps %.2g of its inertia "
                     "apart from the coordinates before it, a singular "
                     "configuration of the coordinates (such as Euler angles "
                     "at gimbal lock) is the likely cause",
                     it->s->coords[k].name, k + 1, piv);
    }
    if (!note[0] && status == EOM_ERR_SOLVER && it->s->m > 0 &&
        it->s->rcond_S_min < 1e-3 && it->o.method != EOM_ERK)
        /* a method whose error test judges each step's projection did
         * not pass a singular position: name the one that did. Measured
         * on the IFToMM A02 linkage with 40 loops in natural coordinates
         * (tests/eom_constraints/test_a02.c): bdf stopped at the first
         * flat position with steps of 5e-16 s, erk passed all 20 (3.7e-6
         * off the exact motion). Such a failure is handed to erk
         * (integrate_handover.c); this message remains for the runs where
         * it cannot be: with sensitivities, or with projection off */
        snprintf(note, sizeof note, "; %s cannot pass this singular "
                 "position: erk, which projects each accepted step outside "
                 "its error test, passes such positions "
                 "(docs/integrators.md, \"Singular positions\")",
                 eom_method_name(it->o.method));
    eom__integ_fail(it, status, "%s: %s at t = %.17g: %s%s", method,
                    flag_name ? flag_name : "unknown flag", t, why, note);
    free(flag_name);
    return status;
}

/* 4 ulp of tout, but at most 1e-9 of the interval. Without a floor, a
 * solver facing a point it cannot pass shrinks the step until t + h == t
 * and stalls there until max_steps, or, once h is subnormal, mistakes the
 * point for tout (CVODE's test (tn - tout) * h >= 0 underflows to -0.0 >=
 * 0, and it reports success at a time it never reached). */
double eom__sun_min_step(double t, double tout)
{
    return fmin(4.0 * DBL_EPSILON * fabs(tout), 1e-9 * (tout - t));
}
