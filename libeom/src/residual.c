/* residual.c - Lagrange's equations as a tape of their own, and from it
 * the exact Jacobian of the state derivative.
 *
 * The residual tape is recorded once per system from the system's tapes
 * with libtape's derivative calls (tp_call, tp_call_jvp, tp_call_vjp).
 * Its independents are z = (q, qd, qdd, lambda, t, p), p the system's
 * parameters (so that the equations can be differentiated with respect
 * to them too), and its outputs
 *
 *   E     = d/dt (dL/dqd) - dL/dq + dR/dqd - Q - C^T lambda      (n)
 *   phi2  = d2phi/dt2 = C qdd + (d2phi/dq2)[qd, qd] + time terms  (m)
 *   phi1  = dphi/dt = C qd + dphi/dt|q                            (m)
 *   phi0  = phi                                                   (m)
 *   P     = qd . (Q - dR/dqd) - dL/dt|(q,qd) [+ lambda . (C qd)]  (1)
 *
 * For the velocity rows (mh .. m-1, after the holonomic ones) of
 * psi(q, qd, t) = A qd + b: C^T lambda takes A^T lambda (a reverse sweep
 * of the psi tape, whose qd part is A^T lambda), phi2 = dpsi/dt along
 * (qd, qdd, 1) = A qdd - gamma, phi1 = psi, phi0 = 0, and P always
 * takes lambda . (A qd) (= qd . A^T lambda).
 *
 * so that E = 0 and phi2 + 2 alpha phi1 + beta^2 phi0 = 0 are the
 * equations the right-hand side solves (rhs.c) and P is the power whose
 * negative the integrators integrate as the dissipated energy W (the
 * last term only when the constraints read the time: then they do work).
 * d/dt (dL/dqd) is the gradient tape of L differentiated along
 * (qd, qdd, 1); phi1 and phi2 are the constraint tape differentiated
 * along the motion once and twice.
 *
 * Differentiating the equations along a change of the state x = (q, qd)
 * at fixed t, with X = d qdd/dx and Lam = d lambda/dx:
 *   M X - C^T Lam = -dE/dx,   C X = -dK/dx   (K = phi2 + 2a phi1 + b^2 phi0)
 * solved by the range-space method with the factors of the last
 * evaluation: Lam = S^-1 (C M^-1 dE/dx - dK/dx), X = M^-1 (C^T Lam - dE/dx).
 * dE/dx and dK/dx are one forward Jacobian sweep of the residual tape
 * with 2n directions, which holds third derivatives of L; no difference
 * quotient is taken anywhere.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"

typedef struct res_rec {
    const eom_system *s;
    const tp_tape *G;    /* gradient of L over its independents */
    const tp_tape *Phi1; /* (phi, dphi/dt[, C qd]) over (q, qd[, t]) */
    int status;
} res_rec;

/* Values for the parameters of tape t in r: the time parameter of the E
 * and R tapes is bound to the time independent; a system parameter to
 * its independent p[k] when p is given (the residual tape), else declared
 * in r by name (the intermediate tapes, whose parameters the residual
 * tape binds in turn). */
static int bind_params(tp_rec *r, const eom_system *s, const tp_tape *t,
                       tp_val time, const tp_val *p, tp_val *par)
{
    int k, j, np = tp_tape_n_params(t);
    for (k = 0; k < np; k++) {
        const char *name = tp_tape_param_name(t, k);
        par[k] = strcmp(name, EOM_TIME_NAME) == 0
                     ? time
                     : tp_param(r, name, tp_tape_param_default(t, k));
    }
    /* the system's parameters found on t by name (a bisection each, not
     * a scan of all: tens of thousands of parameters bind in n log n) */
    for (j = 0; p && j < s->np; j++)
        if ((k = tp_tape_param_index(t, s->params[j].name)) >= 0 &&
            strcmp(s->params[j].name, EOM_TIME_NAME) != 0)
            par[k] = p[j];
    return tp_rec_status(r);
}

/* Weights selecting output out of tape t. */
static void select_output(tp_rec *r, const tp_tape *t, int out, tp_val *w)
{
    int o;
    for (o = 0; o < tp_tape_n_outputs(t); o++)
        w[o] = tp_const(r, o == out ? 1.0 : 0.0);
}

/* One scratch array of handles for everything a recording below needs:
 * sized by the largest count of independents, parameters and outputs. */
static tp_val *handles(const eom_system *s, size_t *count)
{
    const size_t n = (size_t)s->n, m = (size_t)s->m;
    const tp_tape *tapes[6];
    size_t most = 3 * n + m + 2 + (size_t)s->np, k;
    tapes[0] = s->tL.tape;
    tapes[1] = s->tR.tape;
    tapes[2] = s->tQ.tape;
    tapes[3] = s->tphi.tape;
    tapes[4] = s->tE.tape;
    tapes[5] = s->tpsi.tape;
    for (k = 0; k < 6; k++)
        if (tapes[k]) {
            size_t c = (size_t)tp_tape_n_params(tapes[k]) +
                       (size_t)tp_tape_n_outputs(tapes[k]) +
                       (size_t)tp_tape_n_indep(tapes[k]);
            if (c > most)
                most = c;
        }
    *count = most;
    return malloc(8 * most * sizeof(tp_val)); /* 8 slices at most */
}

/* The gradient tape of L: the same independents, every partial an
 * output (dL/dq, dL/dqd, and dL/dt last when L reads the time). */
static int rec_gradient(tp_rec *r, void *user)
{
    res_rec *a = user;
    const tp_tape *L = a->s->tL.tape;
    const int ni = tp_tape_n_indep(L);
    size_t cnt;
    tp_val *h = handles(a->s, &cnt), *x, *w, *g;
    char name[24];
    int i;
    if (!h)
        return a->status = EOM_ERR_NOMEM, 1;
    x = h;
    w = h + cnt;
    g = h + 2 * cnt;
    for (i = 0; i < ni; i++)
        x[i] = tp_indep(r, i);
    select_output(r, L, 0, w);
    tp_call_vjp(r, L, x, NULL, w, NULL, g, NULL);
    for (i = 0; i < ni; i++) {
        snprintf(name, sizeof name, "dL%d", i);
        tp_output(r, name, g[i]);
    }
    free(h);
    return 0;
}

/* phi, its rate along the motion (qd, 1) and, when the constraints read
 * the time, C qd alone: independents (q, qd[, t]). */
static int rec_phi1(tp_rec *r, void *user)
{
    res_rec *a = user;
    const eom_system *s = a->s;
    const tp_tape *P = s->tphi.tape;
    const int n = s->n, m = s->mh, timed = s->tphi.tindex >= 0;
    size_t cnt;
    tp_val *h = handles(s, &cnt), *x, *d, *y, *dy, *cq;
    char name[24];
    int i;
    if (!h)
        return a->status = EOM_ERR_NOMEM, 1;
    x = h;
    d = h + cnt;
    y = h + 2 * cnt;
    dy = h + 3 * cnt;
    cq = h + 4 * cnt;
    for (i = 0; i < n; i++) {
        x[i] = tp_indep(r, i);
        d[i] = tp_indep(r, n + i);
    }
    if (timed) {
        x[n] = tp_indep(r, 2 * n);
        d[n] = tp_const(r, 0.0);
        tp_call_jvp(r, P, x, NULL, d, NULL, NULL, cq);
        d[n] = tp_const(r, 1.0);
    }
    tp_call_jvp(r, P, x, NULL, d, NULL, y, dy);
    for (i = 0; i < m; i++) {
        snprintf(name, sizeof name, "phi%d", i);
        tp_output(r, name, y[i]);
    }
    for (i = 0; i < m; i++) {
        snprintf(name, sizeof name, "phid%d", i);
        tp_output(r, name, dy[i]);
    }
    for (i = 0; timed && i < m; i++) {
        snprintf(name, sizeof name, "Cqd%d", i);
        tp_output(r, name, cq[i]);
    }
    free(h);
    return 0;
}

/* The residual tape over z = (q, qd, qdd, lambda, t). */
static int rec_residual(tp_rec *r, void *user)
{
    res_rec *a = user;
    const eom_system *s = a->s;
    const int n = s->n, m = s->m, mh = s->mh, mv = s->mv;
    const int L_timed = s->tL.tindex >= 0, phi_timed = s->tphi.tindex >= 0;
    size_t cnt;
    tp_val *h = handles(s, &cnt), *z, *x, *d, *y, *dy, *w, *par, *E, *p;
    tp_val *v = handles(s, &cnt), *dv;
    tp_val t, one, P, zero;
    char name[24];
    int i;
    if (!h || !v) {
        free(h);
        free(v);
        return a->status = EOM_ERR_NOMEM, 1;
    }
    dv = v + cnt;
    z = h;
    x = h + cnt;
    d = h + 2 * cnt;
    y = h + 3 * cnt;
    dy = h + 4 * cnt;
    w = h + 5 * cnt;
    par = h + 6 * cnt;
    E = h + 7 * cnt;
    for (i = 0; i < 3 * n + m + 1 + s->np; i++)
        z[i] = tp_indep(r, i);
    t = z[3 * n + m];
    p = z + 3 * n + m + 1;
    one = tp_const(r, 1.0);
    zero = tp_const(r, 0.0);

    /* d/dt (dL/dqd) - dL/dq: the gradient tape along (qd, qdd, 1) */
    for (i = 0; i < 2 * n; i++) {
        x[i] = z[i];
        d[i] = z[n + i];
    }
    x[2 * n] = t;
    d[2 * n] = one;
    bind_params(r, s, a->G, t, p, par);
    tp_call_jvp(r, a->G, x, par, d, NULL, y, dy);
    for (i = 0; i < n; i++)
        E[i] = tp_sub(r, dy[n + i], y[i]);
    P = L_timed ? tp_neg(r, y[2 * n]) : tp_const(r, 0.0);

    if (s->has_R) { /* + dR/dqd; the power qd . (-dR/dqd) */
        bind_params(r, s, s->tR.tape, t, p, par);
        select_output(r, s->tR.tape, 0, w);
        tp_call_vjp(r, s->tR.tape, x, par, w, NULL, dy, NULL);
        for (i = 0; i < n; i++) {
            E[i] = tp_add(r, E[i], dy[n + i]);
            P = tp_sub(r, P, tp_mul(r, z[n + i], dy[n + i]));
        }
    }
    if (s->has_Q) { /* - Q; the power qd . Q */
        bind_params(r, s, s->tQ.tape, t, p, par);
        tp_call(r, s->tQ.tape, x, par, y);
        for (i = 0; i < n; i++) {
            E[i] = tp_sub(r, E[i], y[i]);
            P = tp_add(r, P, tp_mul(r, z[n + i], y[i]));
        }
    }
    if (mh > 0) {
        /* - C^T lambda: the constraint tape's reverse sweep weighted by
         * lambda */
        for (i = 0; i < n; i++)
            x[i] = z[i];
        x[n] = t;
        bind_params(r, s, s->tphi.tape, t, p, par);
        tp_call_vjp(r, s->tphi.tape, x, par, z + 3 * n, NULL, dy, NULL);
        for (i = 0; i < n; i++)
            E[i] = tp_sub(r, E[i], dy[i]);
    }
    if (mv > 0) {
        /* - A^T lambda: the qd part of the velocity constraints' reverse
         * sweep; their force's power qd . A^T lambda */
        for (i = 0; i < 2 * n; i++)
            x[i] = z[i];
        x[2 * n] = t;
        bind_params(r, s, s->tpsi.tape, t, p, par);
        tp_call_vjp(r, s->tpsi.tape, x, par, z + 3 * n + mh, NULL, dy,
                    NULL);
        for (i = 0; i < n; i++) {
            E[i] = tp_sub(r, E[i], dy[n + i]);
            P = tp_add(r, P, tp_mul(r, z[n + i], dy[n + i]));
        }
        /* psi and its rate along (qd, qdd, 1) */
        for (i = 0; i < 2 * n; i++)
            d[i] = z[n + i];
        d[2 * n] = one;
        tp_call_jvp(r, s->tpsi.tape, x, par, d, NULL, v, dv);
    }
    for (i = 0; i < n; i++) {
        snprintf(name, sizeof name, "E%d", i);
        tp_output(r, name, E[i]);
    }
    if (mh > 0) {
        /* (phi, phi1[, C qd]) and their rates along (qd, qdd, 1) */
        for (i = 0; i < 2 * n; i++) {
            x[i] = z[i];
            d[i] = z[n + i];
        }
        x[2 * n] = t;
        d[2 * n] = one;
        bind_params(r, s, a->Phi1, t, p, par);
        tp_call_jvp(r, a->Phi1, x, par, d, NULL, y, dy);
        /* moving constraints do work: + lambda . (C qd) */
        for (i = 0; phi_timed && i < mh; i++)
            P = tp_add(r, P, tp_mul(r, z[3 * n + i], y[2 * mh + i]));
    }
    /* the rows: holonomic (phi2, phi1, phi0 from the Phi1 tape: its
     * outputs phi, then phid), then velocity (dpsi/dt, psi, 0) */
    for (i = 0; i < m; i++) {
        snprintf(name, sizeof name, "phi2_%d", i);
        tp_output(r, name, i < mh ? dy[mh + i] : dv[i - mh]);
    }
    for (i = 0; i < m; i++) {
        snprintf(name, sizeof name, "phi1_%d", i);
        tp_output(r, name, i < mh ? y[mh + i] : v[i - mh]);
    }
    for (i = 0; i < m; i++) {
        snprintf(name, sizeof name, "phi0_%d", i);
        tp_output(r, name, i < mh ? y[i] : zero);
    }
    tp_output(r, "P", P);
    free(h);
    free(v);
    return 0;
}

/* Record one tape of n_indep independents in the given group layout. */
static int record_tape(eom_system *s, int n_indep, const int *group_ends,
                       tp_func f, res_rec *a, const char *what,
                       tp_tape **out)
{
    unsigned char *grp = malloc((size_t)n_indep);
    tp_rec *r = NULL;
    int i, g = 0, rc;
    if (!grp)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    for (i = 0; i < n_indep; i++) {
        while (i >= group_ends[g])
            g++;
        grp[i] = (unsigned char)g;
    }
    rc = tp_recorder_new(&r, n_indep, grp, NULL);
    free(grp);
    if (rc == TP_OK)
        rc = tp_rec_run(r, NULL, f, a);
    if (rc == TP_OK)
        rc = tp_recorder_finish(r, out);
    if (a->status != EOM_OK)
        rc = eom__fail(s, a->status, "recording the %s: out of memory",
                       what);
    else if (rc != TP_OK)
        rc = eom__fail(s, rc == TP_ERR_NOMEM ? EOM_ERR_NOMEM
                                             : EOM_ERR_RECORD,
                       "recording the %s: %s", what,
                       r ? tp_rec_errmsg(r) : tp_strerror(rc));
    else
        rc = EOM_OK;
    tp_rec_free(&r);
    return rc;
}

int eom__record_residual(eom_system *s)
{
    const int n = s->n, m = s->m;
    const int nL = tp_tape_n_indep(s->tL.tape);
    tp_tape *G = NULL, *Phi1 = NULL;
    res_rec a;
    int ends[6], rc, k;

    memset(&a, 0, sizeof a);
    a.s = s;
    ends[0] = n;
    ends[1] = 2 * n;
    ends[2] = 2 * n + 1;
    rc = record_tape(s, nL, ends, rec_gradient, &a,
                     "gradient of the Lagrangian", &G);
    if (rc == EOM_OK && s->mh > 0) {
        a.G = G;
        rc = record_tape(s, 2 * n + (s->tphi.tindex >= 0), ends, rec_phi1,
                         &a, "rates of the constraints", &Phi1);
    }
    if (rc == EOM_OK) {
        a.G = G;
        a.Phi1 = Phi1;
        ends[0] = n;
        ends[1] = 2 * n;
        ends[2] = 3 * n;
        ends[3] = 3 * n + m;
        ends[4] = 3 * n + m + 1;
        ends[5] = 3 * n + m + 1 + s->np;
        rc = record_tape(s, 3 * n + m + 1 + s->np, ends, rec_residual, &a,
                         "residual of the equations of motion",
                         &s->tRes.tape);
    }
    tp_tape_free(&G);
    tp_tape_free(&Phi1);
    if (rc != EOM_OK)
        return rc;
    s->tRes.dirs = 2 * n;
    s->tRes.tindex = -1;
    s->tRes.tparam = -1;
    s->tRes.tset = NAN;
    /* the system's parameters are independents of this tape: none of
     * its own */
    s->tRes.pmap = malloc((size_t)(s->np ? s->np : 1) * sizeof(int));
    if (!s->tRes.pmap)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    for (k = 0; k < s->np; k++)
        s->tRes.pmap[k] = -1;
    return EOM_OK;
}

/* The residual tape's workspace and the Jacobian's scratch, made on
 * first use (most runs never ask for a Jacobian). */
static int jac_ready(eom_system *s)
{
    const size_t n = (size_t)s->n, m = (size_t)s->m;
    const size_t rows = n + 3 * m + 1;
    if (s->tRes.ws)
        return EOM_OK;
    if (!s->tRes.tape)
        return eom__fail(s, EOM_ERR_MODEL,
                         "the system has no residual tape");
    /* after a failure here, what was made is kept for the next try */
    if (!s->jz)
        s->jz = malloc((3 * n + m + 1 + (size_t)s->np) * sizeof(double));
    /* wide enough for every column of z but the time */
    if (!s->jres)
        s->jres = malloc(rows * (3 * n + m + (size_t)s->np + 1) *
                         sizeof(double));
    if (!s->jB)
        s->jB = malloc(n * (2 * n + (size_t)s->np + 1) * sizeof(double));
    if (!s->jy)
        s->jy = malloc(rows * sizeof(double));
    if (!s->jz || !s->jres || !s->jB || !s->jy ||
        tp_ws_new(&s->tRes.ws, s->tRes.tape, s->tRes.dirs, NULL) != TP_OK)
        return eom__fail(s, EOM_ERR_NOMEM,
                         "out of memory for the Jacobian of the state "
                         "derivative");
    return EOM_OK;
}

void eom__residual_fill_z(const eom_system *s, double t, const double *x,
                          const double *qdd, const double *lam, double *z)
{
    const int n = s->n, m = s->m;
    memcpy(z, x, 2 * (size_t)n * sizeof(double));
    memcpy(z + 2 * n, qdd, (size_t)n * sizeof(double));
    if (m > 0)
        memcpy(z + 3 * n, lam, (size_t)m * sizeof(double));
    z[3 * n + m] = t;
    if (s->np > 0)
        memcpy(z + 3 * n + m + 1, s->pval, (size_t)s->np * sizeof(double));
}

/* z = (x, qdd, lambda, t, p) into s->jz. */
static void fill_z(eom_system *s, double t, const double *x,
                   const double *qdd, const double *lam)
{
    eom__residual_fill_z(s, t, x, qdd, lam, s->jz);
}

int eom__residual_jacobian(eom_system *s, double t, const double *x,
                           const double *qdd, const double *lam,
                           double *J)
{
    const int n = s->n, m = s->m;
    int rc, st;
    if ((rc = jac_ready(s)) != EOM_OK)
        return rc;
    if (!isfinite(t) || !eom__finite(x, 2 * (size_t)n) ||
        !eom__finite(qdd, (size_t)n) || !eom__finite(lam, (size_t)m))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "the state at t = %g is not finite", t);
    fill_z(s, t, x, qdd, lam);
    st = tp_jacobian(s->tRes.ws, s->jz, 0, 3 * n + m, s->jy, J);
    return eom__tape_status(s, st, "the Jacobian of the equations");
}

int eom__dae_jacobian(eom_system *s, double t, const double *Y,
                      const double *Yp, double cj, double *J, int ldj)
{
    const int n = s->n, m = s->m, nc = 3 * n + m;
    const double a2 = 2.0 * s->alpha, b2 = s->beta * s->beta;
    const double *Jt, *Er, *K2, *K1, *K0, *Pr;
    int i, j, k, rc;
    if ((rc = jac_ready(s)) != EOM_OK)
        return rc;
    rc = eom__residual_jacobian(s, t, Y, Yp + n, Y + 2 * n, s->jres);
    if (rc != EOM_OK)
        return rc;
    Jt = s->jres;
#define AT(i, j) J[(size_t)(j) * (size_t)ldj + (size_t)(i)]
    for (j = 0; j <= 2 * n + m; j++)
        for (i = 0; i <= 2 * n + m; i++)
            AT(i, j) = 0.0;
    for (i = 0; i < n; i++) { /* q' - v */
        AT(i, i) = cj;
        AT(i, n + i) = -1.0;
    }
    for (i = 0; i < n; i++) { /* E, with v' entering through M */
        Er = Jt + (size_t)i * nc;
        for (j = 0; j < n; j++) {
            AT(n + i, j) = Er[j];
            AT(n + i, n + j) = Er[n + j] + cj * Er[2 * n + j];
        }
        for (k = 0; k < m; k++)
            AT(n + i, 2 * n + k) = Er[3 * n + k];
    }
    for (k = 0; k < m; k++) { /* phi2 + 2 alpha phi1 + beta^2 phi0 */
        K2 = Jt + (size_t)(n + k) * nc;
        K1 = K2 + (size_t)m * nc;
        K0 = K1 + (size_t)m * nc;
        for (j = 0; j < 2 * n; j++)
            AT(2 * n + k, j) = K2[j] + a2 * K1[j] + b2 * K0[j];
        for (j = 0; j < n; j++)
            AT(2 * n + k, n + j) += cj * K2[2 * n + j];
    }
    Pr = Jt + (size_t)(n + 3 * m) * nc; /* W' + P */
    for (j = 0; j < 2 * n; j++)
        AT(2 * n + m, j) = Pr[j];
    for (k = 0; k < m; k++)
        AT(2 * n + m, 2 * n + k) = Pr[3 * n + k];
    AT(2 * n + m, 2 * n + m) = cj;
#undef AT
    return EOM_OK;
}

/* From the residual tape's derivatives along count directions (Jr,
 * row-major (n + 3m + 1) x count, at fixed qdd and lambda), the changes
 * of the accelerations X = M^-1 (C^T Lam - dE) with
 * Lam = S^-1 (C M^-1 dE - dK), into rows n .. 2n-1 of column j of out
 * (out + j * ldo), and with with_power -dP into row 2n; Lam_j into
 * Lam + j * m when Lam is not NULL. Bw: n x count scratch. Uses the
 * factors of the evaluation at x. */
static int finish_columns(eom_system *s, const double *x, const double *Jr,
                          int count, double *Bw, double *out, int ldo,
                          int with_power, double *Lam)
{
    const int n = s->n, m = s->m;
    const double *qd = x + n;
    int i, j, k, rc;
    for (j = 0; j < count; j++)
        for (i = 0; i < n; i++)
            Bw[(size_t)j * n + i] = Jr[(size_t)i * count + j];
    if ((rc = eom__mass_solve(s, Bw, count)) != EOM_OK)
        return rc;
    for (j = 0; j < count; j++) {
        double *col = out + (size_t)j * (size_t)ldo;
        const double *Bj = Bw + (size_t)j * n;
        double *lam = s->wm;
        for (i = 0; i < n; i++)
            col[n + i] = -Bj[i];
        if (m > 0) {
            /* Lam_j = S^-1 (C B_j - dK_j) */
            for (k = 0; k < m; k++) {
                const double *Ck = s->C + (size_t)k * n;
                double cb = 0.0;
                const size_t r2 = (size_t)(n + k), r1 = r2 + (size_t)m,
                             r0 = r1 + (size_t)m;
                for (i = 0; i < n; i++)
                    cb += Ck[i] * Bj[i];
                lam[k] = cb - (Jr[r2 * count + j] +
                               2.0 * s->alpha * Jr[r1 * count + j] +
                               s->beta * s->beta * Jr[r0 * count + j]);
            }
            if ((rc = eom__S_solve(s, lam)) != EOM_OK)
                return rc;
            for (k = 0; k < m; k++)
                for (i = 0; i < n; i++)
                    col[n + i] += s->Y[(size_t)k * n + i] * lam[k];
            if (Lam)
                memcpy(Lam + (size_t)j * m, lam, (size_t)m * sizeof *lam);
        }
        if (with_power) {
            double dP = Jr[(size_t)(n + 3 * m) * count + j];
            /* moving constraints and velocity rows: P holds lambda .
             * (C qd) at fixed lambda; add its change through lambda,
             * (C qd) . Lam_j */
            if (m > 0) {
                for (k = s->tphi.tindex >= 0 ? 0 : s->mh; k < m; k++) {
                    const double *Ck = s->C + (size_t)k * n;
                    double cqd = 0.0;
                    for (i = 0; i < n; i++)
                        cqd += Ck[i] * qd[i];
                    dP += cqd * lam[k];
                }
            }
            col[2 * n] = -dP;
        }
    }
    return EOM_OK;
}

size_t eom__sens_work(const eom_system *s, int ns)
{
    const size_t n = (size_t)s->n, m = (size_t)s->m, k = (size_t)ns;
    return ((3 * n + m + 1 + (size_t)s->np) + (n + 3 * m + 1) + n +
            (2 * n + 1)) * k;
}

/* Evaluate at (t, x) and fill z. */
static int evaluate_z(eom_system *s, double t, const double *x)
{
    int rc;
    if ((rc = jac_ready(s)) != EOM_OK)
        return rc;
    if ((rc = eom__evaluate(s, t, x)) != EOM_OK)
        return rc;
    fill_z(s, t, x, s->qdd, s->lam);
    return EOM_OK;
}

/* Columns first .. first + count - 1 of z (the state x = (q, qd) when
 * first is 0, the parameters when it is 3n + m + 1): d(xd)/d(column)
 * into the columns of A (leading dimension lda), and with with_power
 * -dP/d(column) in row 2n. */
static int xd_columns(eom_system *s, double t, const double *x, int first,
                      int count, double *A, int lda, int with_power)
{
    const int n = s->n;
    int i, j, rc, st;
    if ((rc = evaluate_z(s, t, x)) != EOM_OK)
        return rc;
    if (count == 0)
        return EOM_OK;
    st = tp_jacobian(s->tRes.ws, s->jz, first, count, s->jy, s->jres);
    if ((rc = eom__tape_status(s, st, "the Jacobian of the equations")))
        return rc;
    /* dq/dx = [0 I], 0 for a parameter */
    for (j = 0; j < count; j++)
        for (i = 0; i < n; i++)
            A[(size_t)j * (size_t)lda + (size_t)i] =
                first == 0 && i + n == j ? 1.0 : 0.0;
    return finish_columns(s, x, s->jres, count, s->jB, A, lda, with_power,
                          NULL);
}

int eom__residual_z(eom_system *s, double t, const double *x,
                    const double *qdd, const double *lam)
{
    int rc;
    if ((rc = jac_ready(s)) != EOM_OK)
        return rc;
    if (!isfinite(t) || !eom__finite(x, 2 * (size_t)s->n) ||
        !eom__finite(qdd, (size_t)s->n) ||
        !eom__finite(lam, (size_t)s->m))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "the state at t = %g is not finite", t);
    fill_z(s, t, x, qdd, lam);
    return EOM_OK;
}

int eom__residual_at(eom_system *s, double t, const double *x)
{
    return evaluate_z(s, t, x);
}

int eom__sens_rhs(eom_system *s, double t, const double *x, int evaluated,
                  int ns, const int *par, const double *const *V,
                  double *const *out, double *work)
{
    return eom__sens_rates(s, t, x, evaluated, ns, par, V, out, NULL,
                           work);
}

int eom__sens_rates(eom_system *s, double t, const double *x, int evaluated,
                    int ns, const int *par, const double *const *V,
                    double *const *out, double *dlam, double *work)
{
    const int n = s->n, m = s->m, nz = 3 * n + m + 1 + s->np;
    const int N = 2 * n + 1;
    double *seed = work, *JS = seed + (size_t)nz * ns;
    double *Bw = JS + (size_t)(n + 3 * m + 1) * ns, *cols = Bw + (size_t)n * ns;
    int i, k, rc, st;
    if (evaluated) { /* s holds the evaluation at (t, x): z from it */
        if ((rc = jac_ready(s)) != EOM_OK)
            return rc;
        fill_z(s, t, x, s->qdd, s->lam);
    } else if ((rc = evaluate_z(s, t, x)) != EOM_OK) {
        return rc;
    }
    /* direction k: (q, qd) by V_k, parameter par[k] by 1 */
    memset(seed, 0, (size_t)nz * (size_t)ns * sizeof *seed);
    for (k = 0; k < ns; k++) {
        for (i = 0; i < 2 * n; i++)
            seed[(size_t)i * ns + k] = V[k][i];
        if (par[k] >= 0)
            seed[(size_t)(3 * n + m + 1 + par[k]) * ns + k] = 1.0;
    }
    st = tp_jvp(s->tRes.ws, s->jz, ns, seed, s->jy, JS);
    if ((rc = eom__tape_status(s, st, "the sensitivities' right-hand side")))
        return rc;
    if ((rc = finish_columns(s, x, JS, ns, Bw, cols, N, 1, dlam)) != EOM_OK)
        return rc;
    for (k = 0; k < ns; k++) {
        memcpy(out[k], V[k] + n, (size_t)n * sizeof(double));
        memcpy(out[k] + n, cols + (size_t)k * N + n,
               (size_t)(n + 1) * sizeof(double));
    }
    return EOM_OK;
}

int eom__state_jacobian(eom_system *s, double t, const double *x,
                        double *A, int lda, int with_power)
{
    const int n2 = 2 * s->n;
    int i, rc = xd_columns(s, t, x, 0, n2, A, lda, with_power);
    if (rc == EOM_OK && with_power)
        for (i = 0; i <= n2; i++)
            A[(size_t)n2 * (size_t)lda + (size_t)i] = 0.0;
    return rc;
}

int eom__param_jacobian(eom_system *s, double t, const double *x,
                        double *B, int ldb)
{
    return xd_columns(s, t, x, 3 * s->n + s->m + 1, s->np, B, ldb, 0);
}

/* The public form of d(xd)/dx (params 0) or d(xd)/dp (params 1): 2n
 * rows, row-major, from the column-major internal one. */
static int xd_rows(eom_system *s, double t, const double *x, int params,
                   double *out, const char *fn)
{
    const int n2 = s ? 2 * s->n : 0;
    const int count = s ? (params ? s->np : n2) : 0;
    double *cols;
    int i, j, rc;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!x || (!out && count > 0))
        return eom__fail(s, EOM_ERR_NULL, "%s: x or %s is NULL", fn,
                         params ? "B" : "A");
    cols = malloc((size_t)n2 * (size_t)(count ? count : 1) *
                  sizeof(double));
    if (!cols)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    rc = params ? eom__param_jacobian(s, t, x, cols, n2)
                : eom__state_jacobian(s, t, x, cols, n2, 0);
    if (rc == EOM_OK)
        for (i = 0; i < n2; i++)
            for (j = 0; j < count; j++)
                out[(size_t)i * count + j] = cols[(size_t)j * n2 + i];
    free(cols);
    if (rc == EOM_OK)
        s->msg[0] = '\0';
    return rc;
}

int eom_state_jacobian(eom_system *s, double t, const double *x, double *A)
{
    return xd_rows(s, t, x, 0, A, "eom_state_jacobian");
}

int eom_param_jacobian(eom_system *s, double t, const double *x, double *B)
{
    return xd_rows(s, t, x, 1, B, "eom_param_jacobian");
}
