/* energy.c - the energies of a state: the Jacobi integral E = qd . dL/dqd
 * - L from the Lagrangian's tape (no user help needed: it equals T + V for
 * a natural system), T and V separately when the model gave them, the
 * rate dE/dt (the power of the non-conservative forces, and for a model
 * that reads the time -dL/dt and the power of moving constraints: see
 * rhs.c), and the probes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"

int eom_energy_at(eom_system *s, double t, const double *x, eom_energy *e)
{
    const int n = s ? s->n : 0;
    double L, dLdt;
    int st, rc, i;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!x || !e)
        return eom__fail(s, EOM_ERR_NULL, "eom_energy_at: NULL argument");
    if (!isfinite(t) || !eom__finite(x, 2 * (size_t)n))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "the state at t = %g is not finite", t);
    /* T and V first: a domain error in one of them is named as its own,
     * not as the Lagrangian's */
    e->T = e->V = NAN;
    if (s->has_tv) {
        /* the tape holds the probes after T and V: a probe's domain error
         * is eom_probes_at's to report, not a fault of T or V */
        st = tp_eval(s->tE.ws, eom__tape_input(&s->tE, x, t), s->wE);
        if (st == TP_WARN_NONFINITE && isfinite(s->wE[0]) &&
            isfinite(s->wE[1]))
            st = TP_OK;
        if ((rc = eom__tape_status(s, st,
                                   !isfinite(s->wE[0])
                                       ? "the kinetic energy T"
                                       : "the potential energy V")))
            return rc;
        e->T = s->wE[0];
        e->V = s->wE[1];
    }
    st = tp_gradient(s->tL.ws, eom__tape_input(&s->tL, x, t), 0, &L, s->wn);
    if ((rc = eom__tape_status(s, st, "the Lagrangian or its gradient")))
        return rc;
    e->L = L;
    e->E = -L;
    for (i = 0; i < n; i++)
        e->E += x[n + i] * s->wn[n + i];
    /* the gradient's last entry, on a tape with the time */
    dLdt = s->tL.tindex >= 0 ? s->wn[2 * n] : 0.0;
    if (s->tphi.tindex >= 0 || s->mv > 0) {
        /* the constraint forces' power needs the multipliers: the whole
         * evaluation */
        if ((rc = eom__evaluate(s, t, x)) != EOM_OK)
            return rc;
        e->P = s->power;
        e->Pt = s->power_t;
        return EOM_OK;
    }
    /* after the Lagrangian's gradient: this reuses the scratch s->wn */
    if ((rc = eom__nonconservative(s, t, x)) != EOM_OK)
        return rc;
    e->Pt = -dLdt;
    e->P = s->power + e->Pt;
    return EOM_OK;
}

int eom__probe_multipliers(eom_system *s)
{
    char name[32];
    int j, any = 0;
    free(s->lam_param);
    s->lam_param = NULL;
    if (!s->tE.tape || s->m == 0)
        return EOM_OK;
    s->lam_param = malloc((size_t)s->m * sizeof *s->lam_param);
    if (!s->lam_param)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    for (j = 0; j < s->m; j++) {
        snprintf(name, sizeof name, EOM_LAMBDA_FMT, j);
        s->lam_param[j] = tp_tape_param_index(s->tE.tape, name);
        any |= s->lam_param[j] >= 0;
    }
    if (!any) {
        free(s->lam_param);
        s->lam_param = NULL;
    }
    return EOM_OK;
}

/* The multipliers the probes read, into the E tape's parameters: the
 * equations of motion solved at (s->time, x). */
static int probe_multipliers_at(eom_system *s, const double *x)
{
    int j, rc;
    if (!s->lam_param)
        return EOM_OK;
    if ((rc = eom__evaluate(s, s->time, x)) != EOM_OK)
        return rc;
    for (j = 0; j < s->m; j++)
        if (s->lam_param[j] >= 0)
            tp_ws_set_param(s->tE.ws, s->lam_param[j], s->lam[j]);
    return EOM_OK;
}

int eom_probes_at(eom_system *s, const double *x, double *p)
{
    int st, rc, first;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (s->nprobe == 0)
        return EOM_OK;
    if (!x || !p)
        return eom__fail(s, EOM_ERR_NULL, "eom_probes_at: NULL argument");
    if (!eom__finite(x, 2 * (size_t)s->n))
        return eom__fail(s, EOM_ERR_NONFINITE, "the state is not finite");
    if ((rc = probe_multipliers_at(s, x)) != EOM_OK)
        return rc;
    st = tp_eval(s->tE.ws, eom__tape_input(&s->tE, x, s->time), s->wE);
    /* the E tape holds T and V first when the model gave them: a non-finite
     * one of those is not a probe's fault */
    first = s->has_tv ? 2 : 0;
    if (st == TP_WARN_NONFINITE) {
        int k, bad = -1, nbad = 0;
        for (k = 0; k < s->nprobe; k++)
            if (!isfinite(s->wE[first + k]) && nbad++ == 0)
                bad = k;
        if (bad < 0) /* only T or V: the probes themselves are fine */
            st = TP_OK;
        else {
            memcpy(p, s->wE + first, (size_t)s->nprobe * sizeof(double));
            return eom__fail(s, EOM_ERR_NONFINITE,
                             "the probe '%s' is not finite (a domain error "
                             "in its expression, or a diverging state)%s",
                             s->probes[bad].name,
                             nbad > 1 ? ", and others after it" : "");
        }
    }
    if ((rc = eom__tape_status(s, st, "a probe")))
        return rc;
    memcpy(p, s->wE + first, (size_t)s->nprobe * sizeof(double));
    return EOM_OK;
}
