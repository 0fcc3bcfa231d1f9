/* integrate_handover.c - adams and ida through singular positions.
 *
 * They cannot pass one themselves: they project onto the constraints only
 * at output times, and near a singular position the multipliers come from
 * a filtered solve that their error control does not survive (adams lost
 * the motion's phase there; ida's index-1 iteration matrix is singular).
 * So when an advance meets one (eom__integ_rhs refuses the evaluation),
 * the stretch around it is integrated by bdf, which projects after every
 * step and loosens its error test there (integrate_cvode.c), from the
 * method's last output; bdf stops once the constraint system is well
 * conditioned again (eom__integ_stretch_done), and the method restarts
 * from bdf's state, as at the start of a run. The branch monitor is the
 * method's own throughout, marked at each output and at each restart and
 * rewound to the mark where bdf begins, so a pass is counted once.
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

/* The bdf for a stretch from (it->t, it->y), in it->sub: a status. */
static int start(eom_integ *it)
{
    eom_integ *b = NULL;
    eom_opts o = it->o;
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
    o.method = EOM_BDF;
    o.n_sens = 0;
    o.max_order = 0;
    o.dt = 0.0;
    o.atol_vec = it->atolv;
    o.erk_table = NULL;
    /* a sparse request was the method's (ida's): with constraints bdf's
     * matrix is dense, and it chooses for itself */
    o.linear_solver = EOM_LINSOL_AUTO;
    rc = eom__integ_create(&b, it->s, &o, it->t, it->y, 0);
    if (rc != EOM_OK)
        return eom__integ_fail(it, rc,
                               "%s: at t = %.17g, handing a singular "
                               "stretch to bdf: %s",
                               eom_method_name(it->o.method), it->t,
                               it->s->msg);
    b->handing = 1;
    b->t_refused = it->t_refused;
    b->branch = it->branch;
    b->branch_borrowed = 1;
    eom__branch_rewind(it->branch);
    it->sub = b;
    it->handovers++;
    return EOM_OK;
}

/* bdf's counts into it's, and bdf gone */
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
    int rc = EOM_ERR_RANK_DEFICIENT;
    while (rc == EOM_ERR_RANK_DEFICIENT) {
        const double t0 = it->t;
        it->failed = 0;
        if (!it->sub && (rc = start(it)) != EOM_OK)
            return rc;
        rc = it->sub->ops->advance(it->sub, tout);
        if (rc == EOM_OK && !(it->sub->t > t0)) {
            rc = EOM_ERR_SOLVER;
            snprintf(it->sub->msg, sizeof it->sub->msg, "no progress");
        }
        if (rc != EOM_OK) {
            rc = eom__integ_fail(it, rc,
                                 "%s: bdf, integrating a singular stretch "
                                 "from t = %.17g: %s", name, t0,
                                 it->sub->msg);
            finish(it);
            return rc;
        }
        it->t = it->sub->t;
        memcpy(it->y, it->sub->y, (size_t)it->N * sizeof(double));
        if (!it->sub->stretch_over) {
            /* at tout inside the stretch: bdf goes on at the next
             * advance */
            it->msg[0] = '\0';
            return EOM_OK;
        }
        finish(it);
        /* the method's next failure repeats from here */
        if (eom__branch_mark(it->branch) != EOM_OK)
            return eom__integ_fail(it, EOM_ERR_NOMEM, "out of memory");
        /* the method again from bdf's state, as at a start */
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
