/* rheonomic.c - explicit time in the energies and the constraints: where
 * the time sits on each tape (eom_internal.h), the inputs of a sweep at
 * (t, x), the constraints' rates along the motion, and the system's time
 * for the calls that take none.
 *
 * With phi(q, t), moving along the motion q(s) = q + s qd, t(s) = t + s is
 * one Taylor sweep of the phi tape in the direction (qd, 1) of its
 * independents (q, t):
 *     d phi/ds   = C qd + phi_t                       (velocity residual)
 *     d2 phi/ds2 = phi_qq[qd, qd] + 2 phi_qt qd + phi_tt = -gamma
 * so the acceleration-level constraint C qdd = gamma has every time term
 * without a sweep of its own. A phi tape without the time is swept along
 * qd alone, as before. */
#include <math.h>
#include <string.h>

#include "eom_internal.h"

const double *eom__tape_input_timed(eom_tape *et, const double *x, double t)
{
    /* a parameter change makes the next sweep recompute the passive ops:
     * only when the time did change */
    if (et->tparam >= 0 && !(et->tset == t)) {
        tp_ws_set_param(et->ws, et->tparam, t);
        et->tset = t;
    }
    if (et->tindex < 0)
        return x;
    memcpy(et->xt, x, (size_t)et->tindex * sizeof(double));
    et->xt[et->tindex] = t;
    return et->xt;
}

int eom__constraint_rates(eom_system *s, double t, const double *x,
                          double *phi, double *phid, double *curv)
{
    const int n = s->n;
    const double *dir = x + n;
    int st;
    if (s->mv > 0) {
        int rc = eom__velocity_rates(s, t, x, phi, phid, curv);
        if (rc != EOM_OK || s->mh == 0)
            return rc;
    }
    if (s->tphi.tindex >= 0) {
        memcpy(s->dir, x + n, (size_t)n * sizeof(double));
        s->dir[n] = 1.0;
        dir = s->dir;
    }
    st = tp_taylor2(s->tphi.ws, eom__tape_input(&s->tphi, x, t), dir, phi,
                    phid, curv);
    return eom__tape_status(s, st, "the constraint residuals or curvature");
}

int eom__refuse_time(eom_system *s, const char *what)
{
    if (s->tL.tindex < 0 && s->tR.tparam < 0 && s->tphi.tindex < 0 &&
        s->tpsi.tindex < 0)
        return EOM_OK;
    return eom__fail(s, EOM_ERR_MODEL,
                     "%s: the time appears in the model's %s (a rheonomic "
                     "model has no state of rest)", what,
                     s->tL.tindex >= 0     ? "Lagrangian"
                     : s->tphi.tindex >= 0 ? "constraints"
                     : s->tpsi.tindex >= 0 ? "velocity constraints"
                                           : "dissipation");
}

int eom_set_time(eom_system *s, double t)
{
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!isfinite(t))
        return eom__fail(s, EOM_ERR_NONFINITE, "eom_set_time: t = %g", t);
    s->time = t;
    return EOM_OK;
}

double eom_get_time(const eom_system *s) { return s ? s->time : NAN; }

int eom_system_reads_time(const eom_system *s)
{
    return s && s->reads_time;
}
