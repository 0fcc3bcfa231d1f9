/* integrate_handover.c - the implicit and multistep methods through
 * singular positions.
 *
 * adams and ida cannot pass one themselves: they project onto the
 * constraints only at output times, and near a singular position the
 * multipliers come from a filtered solve that their error control does
 * not survive (adams lost the motion's phase there; ida's index-1
 * iteration matrix is singular). So when an advance meets one
 * (eom__integ_rhs refuses the evaluation), the stretch around it is
 * integrated by bdf, which projects after every step and loosens its
 * error test there (integrate_cvode.c), from the method's last output.
 *
 * bdf, esdirk and imex project every step, but their error tests can
 * still fail at a singular position where the filtered accelerations are
 * not smooth: bdf on the IFToMM A02 linkage in natural coordinates
 * (tests/eom_constraints/test_a02.c) failed its error test at the first
 * flat position with steps of 5e-16 s, whatever its projection's error
 * estimate (CVodeSetProjErrEst off failed the same way). Such a failure
 * (EOM_ERR_SOLVER with the constraint system's rcond below 1e-2 at the
 * last evaluation, eom__integ_hands_over) hands the stretch from the last
 * output to erk, which projects each accepted step outside its error test
 * and passed all 20 flat positions there; when the stretch's bdf of adams
 * or ida fails so, erk takes the stretch over and, for that run, the
 * stretches after it.
 *
 * The stretch's integrator stops once the constraint system is well
 * conditioned again (eom__integ_stretch_done), and the method restarts
 * from its state, as at the start of a run. The branch monitor is the
 * method's own throughout, marked at each output and at each restart and
 * rewound to the mark where a stretch begins, so a pass is counted once.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "integrate_internal.h"

/* The counts that ops->stats gives for one instance, into acc. */
static void bank(eom_integ *it, eom_stats *acc)
{
    eom_stats st;
    memset(&st, 0, sizeof st);
    it->ops->stats(it, &st);
    acc->steps += st.steps;
    acc->failures += st.failures;
    acc->jac_evals += st.jac_evals;
}

int eom__integ_hands_over(const eom_integ *it, int rc)
{
    const eom_method m = it->o.method;
    return rc == EOM_ERR_SOLVER && it->s->m > 0 && it->o.project &&
           it->o.n_sens == 0 &&
           (m == EOM_BDF || m == EOM_ESDIRK || m == EOM_IMEX) &&
           it->s->rcond_S < 1e-2;
}

/* the method that integrates the stretches of it: bdf for adams and ida
 * until bdf failed one, erk otherwise */
static eom_method stretch_method(const eom_integ *it)
{
    return it->refuse_singular && !it->stretch_erk ? EOM_BDF : EOM_ERK;
}

/* The integrator for a stretch from (it->t, it->y), in it->sub: a
 * status. count: a new stretch (not erk taking over bdf's). */
static int start(eom_integ *it, int count)
{
    eom_integ *b = NULL;
    eom_opts o = it->o;
    const char *to;
    int rc;
    if (it->o.n_sens > 0)
        /* the sensitivities grow without bound at a singular position;
         * the stretch's bdf would have to take them over and hand them
         * back, which is not done */
        return eom__integ_fail(it, EOM_ERR_RANK_DEFICIENT,
                               "%s: at t = %.17g the constraint system is "
                               "singular or nearly so (rcond of C M^-1 C^T "
                               "%.2g), where sensitivities grow without "
                               "bound: %s hands such a stretch to bdf, but "
                               "not with sensitivities; use bdf, which "
                               "integrates them through it "
                               "(docs/integrators.md, \"Sensitivities\")",
                               eom_method_name(it->o.method), it->t_refused,
                               it->s->rcond_S, eom_method_name(it->o.method));
    o.method = stretch_method(it);
    to = eom_method_name(o.method);
    o.n_sens = 0;
    o.max_order = 0;
    o.dt = 0.0;
    o.atol_vec = it->atolv;
    o.erk_table = NULL;
    /* a sparse request was the method's (ida's): with constraints bdf's
     * matrix is dense, and it chooses for itself (erk has none) */
    o.linear_solver = EOM_LINSOL_AUTO;
    rc = eom__integ_create(&b, it->s, &o, it->t, it->y, 0);
    if (rc != EOM_OK)
        return eom__integ_fail(it, rc,
                               "%s: at t = %.17g, handing a singular "
                               "stretch to %s: %s",
                               eom_method_name(it->o.method), it->t, to,
                               it->s->msg);
    b->handing = 1;
    b->t_refused = it->t_refused;
    b->branch = it->branch;
    b->branch_borrowed = 1;
    eom__branch_rewind(it->branch);
    it->sub = b;
    if (count)
        it->handovers++;
    if (count && o.method == EOM_ERK)
        it->handovers_erk++;
    return EOM_OK;
}

/* the stretch integrator's counts into it's, and the stretch integrator
 * gone */
static void finish(eom_integ *it)
{
    eom_integ *b = it->sub;
    bank(b, &it->handed);
    it->handed_reach = fmax(it->handed_reach, eom__integ_tol_reachable(b));
    it->st.rhs_evals += b->st.rhs_evals;
    it->st.jac_time += b->st.jac_time;
    it->st.projections += b->st.projections;
    it->st.max_residual = fmax(it->st.max_residual, b->st.max_residual);
    eom_integ_free(&it->sub);
}

int eom__integ_handover(eom_integ *it, double tout)
{
    const char *name = eom_method_name(it->o.method);
    int rc = EOM_ERR_RANK_DEFICIENT, count = 1;
    while (rc == EOM_ERR_RANK_DEFICIENT) {
        const double t0 = it->t;
        it->failed = 0;
        if (!it->sub && (rc = start(it, count)) != EOM_OK)
            return rc;
        count = 1;
        rc = it->sub->ops->advance(it->sub, tout);
        if (rc == EOM_OK && !(it->sub->t > t0)) {
            rc = EOM_ERR_SOLVER;
            snprintf(it->sub->msg, sizeof it->sub->msg, "no progress");
        }
        if (rc != EOM_OK && it->sub->o.method == EOM_BDF &&
            eom__integ_hands_over(it->sub, rc) && !it->stretch_erk) {
            /* bdf could not pass it either: erk takes the stretch over
             * from the last output (the branch monitor rewound to its
             * mark in start), and the stretches after it */
            it->t_refused = fmax(it->t_refused, it->sub->t_refused);
            finish(it);
            it->stretch_erk = 1;
            it->handovers_erk++;
            count = 0;
            rc = EOM_ERR_RANK_DEFICIENT;
            continue;
        }
        if (rc != EOM_OK) {
            rc = eom__integ_fail(it, rc,
                                 "%s: %s, integrating a singular stretch "
                                 "from t = %.17g: %s", name,
                                 eom_method_name(it->sub->o.method), t0,
                                 it->sub->msg);
            finish(it);
            return rc;
        }
        it->t = it->sub->t;
        memcpy(it->y, it->sub->y, (size_t)it->N * sizeof(double));
        if (!it->sub->stretch_over) {
            /* at tout inside the stretch: it goes on at the next
             * advance */
            it->msg[0] = '\0';
            return EOM_OK;
        }
        finish(it);
        /* the method's next failure repeats from here */
        if (eom__branch_mark(it->branch) != EOM_OK)
            return eom__integ_fail(it, EOM_ERR_NOMEM, "out of memory");
        /* the method again from the stretch's end, as at a start */
        bank(it, &it->handed);
        it->ops->destroy(it);
        if ((rc = it->ops->init(it)) != EOM_OK)
            return eom__integ_fail(it, rc, "%s: restarting at t = %.17g "
                                   "after a singular stretch: %s", name,
                                   it->t, it->msg);
        if (it->t >= tout) {
            it->msg[0] = '\0';
            return EOM_OK;
        }
        rc = it->ops->advance(it, tout);
    }
    if (rc == EOM_OK)
        it->msg[0] = '\0';
    return rc;
}
