/* integrate_esdirk.c - EOM_ESDIRK: ARKODE's ARKStep with the whole right-
 * hand side implicit, an adaptive, L-stable, stiffly accurate ESDIRK
 * method on y = (q, qd, W): the ARK5(4)8L[2]SA table of SUNDIALS 6.4
 * (ARKODE_ARK548L2SA_DIRK_8_4_5: 8 stages, order 5, embedded order 4),
 * for stiff models (stiff springs and beams, strong damping) where the
 * explicit methods' steps are bound by stability, not accuracy.
 *
 * Each stage is solved by Newton's method with a dense direct linear
 * solver; the Jacobian of the right-hand side is exact, from the residual
 * tape (dk_jac, residual.c), or with eom_opts.dq_jacobian ARKODE's
 * difference quotient (N extra right-hand sides each), as for bdf. The
 * method
 * advances with its order-5 solution: like erk, its global error stays
 * near the tolerance without the multistep methods' calibration.
 *
 * Output times, drift and callbacks as for erk (integrate_arkode.c): the
 * stop time is tout; with constraints, a step postprocessing function
 * projects every accepted step and watches the assembly branch. The
 * setup, the advance and the statistics are imex's too
 * (integrate_arkstep.c).
 */
#include <stdlib.h>

#include <arkode/arkode_arkstep.h>
#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "integrate_internal.h"

#define DIRK_TABLE ARKODE_ARK548L2SA_DIRK_8_4_5

/* The Newton matrix's Jacobian: the exact d(yd)/dy, W's row included. */
static int dk_jac(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix J,
                  void *user, N_Vector t1, N_Vector t2, N_Vector t3)
{
    eom_integ *it = user;
    int rc = eom__integ_jacobian(it, t, N_VGetArrayPointer(y), SM_DATA_D(J),
                                 (int)SM_ROWS_D(J));
    (void)fy;
    (void)t1;
    (void)t2;
    (void)t3;
    return eom__ark_cb_result(it, rc);
}

static void dk_destroy(eom_integ *it)
{
    eom_ark *d = it->impl;
    if (!d)
        return;
    eom__ark_free(d);
    free(d);
    it->impl = NULL;
}

static int dk_init(eom_integ *it)
{
    /* the method's impl is the solver alone */
    eom_ark *d = calloc(1, sizeof *d);
    if (!d)
        return eom__integ_nomem(it);
    it->impl = d;
    /* everything implicit: fe = NULL, fi = the right-hand side */
    return eom__ark_implicit_init(it, d, NULL, eom__ark_rhs, dk_jac,
                                  DIRK_TABLE, ARKODE_ERK_NONE);
}

static int dk_advance(eom_integ *it, double tout)
{
    return eom__ark_advance(it, tout, "esdirk");
}

const eom_integ_ops eom__esdirk_ops = {"esdirk", dk_init, dk_advance,
                                       eom__ark_stats, dk_destroy};
