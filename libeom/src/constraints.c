/* constraints.c - projection of a state onto the constraint manifold:
 * q onto phi(q, t) = 0 and qd onto C qd + dphi/dt = 0 (dphi/dt = 0 unless
 * the constraints read the time), each by the correction of least W-norm,
 *     dq  = -W^-1 C^T S^-1 phi(q, t)          (Newton, repeated until
 *                                              |phi| <= tol)
 *     dqd = -W^-1 C^T S^-1 (C qd + dphi/dt)   (once, at the corrected q)
 * with S = C W^-1 C^T. eom_project uses the mass matrix, W = M (the
 * correction of least kinetic energy, right for removing the small drift
 * of a step); eom_project_start uses W = I (the least change of the
 * coordinates, right for an initial state a user set off the
 * constraints: M couples angles and deflections, so the M-norm would move
 * deflections the constraints do not involve). W is factored once, at
 * the state given; C and S are recomputed at each iterate.
 *
 * Every projection first measures phi and C qd (one Taylor sweep) and
 * does nothing more when both are within the tolerance. An integrator's
 * projection after each step (eom__project_step) reuses the factor of M
 * from the step's last evaluation, at a nearby state: the correction
 * needs a metric close to M, not M at the corrected point, and this keeps
 * the cost of a step's projection that has work to do at a few small
 * solves.
 *
 * Velocity constraints psi(q, qd, t) = A(q, t) qd + b(q, t) = 0 (the psi
 * tape, eom_internal.h) are rows mh .. m-1 of C: A = dpsi/dqd and b, the
 * value at qd = 0, from one forward Jacobian over the rates at (q, 0, t),
 * so that they need q alone, as the holonomic rows do. Along the motion,
 * with qd held (qdd = 0) and the time running,
 *     d psi/ds = (dA/dq qd) qd + (db/dq) qd + dA/dt qd + db/dt = -gamma
 * is one tangent sweep of the psi tape in the direction (qd, 0, 1). They
 * have no position residual: the Newton iteration on q sees the
 * holonomic rows alone (S's leading mh x mh block, solved densely, when
 * both kinds are present), and the correction of qd all rows. Linearity
 * in qd is checked once, when the system is built (A must not depend on
 * qd: the block d2psi/dqd2 of each row's Hessian is zero). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"

#define EOM_PROJ_MAXIT 20
/* A projection after a step (qtol > 0, eom__project_step) may stop
 * above tol, where the iteration has stalled and the residual is within
 * what the step's own error tolerance makes of it. Near a singular
 * position the Newton step comes from the multipliers' filtered SVD
 * (rhs.c), which damps each direction of S by sv^2 / (sv^2 + mu^2); in
 * the soft directions the iteration then converges linearly, at that
 * rate. Measured on the IFToMM A02 four-bars (N loops in a row, natural
 * coordinates, tests/eom_constraints/test_a02.c): with N = 40 and rk4 at
 * 1e-3 s, at t = 0.721 s (0.6 ms before the first flat position) KLU's
 * estimate was 3.9e-6 and |phi| went from 2.2e-11 to 9.1e-12 in 20
 * iterations, a rate of 0.966 (S's smallest singular value near 2e-8 of
 * its largest: the estimate is a ratio of pivots), each moving q by
 * 4e-10, below the step's error: an absolute 1e-12 cannot be reached
 * there in any reasonable number of iterations, and the soft directions
 * grow with N (the lowest modes of a chain of N loops). KLU's own solve
 * instead reached 7e-15 in one iteration, but its full correction (up to
 * 4e-7 in q, along directions nearly tangent to the motion) broke bdf's
 * error test at the flat position (h down to 4e-16). So the filtered
 * step stays, and the stopping rule follows the step: after two
 * iterations, one under the filter that reduces |phi| by less than
 * EOM_PROJ_STALL stops once |phi| <= qtol |C| (|C| the largest row sum
 * of |dphi/dq|): the residual a position error of qtol, the error the
 * step's own error test allows, leaves. */
#define EOM_PROJ_STALL 0.5

/* ---- velocity constraints ----------------------------------------------- */

int eom__refuse_velocity(eom_system *s, const char *what)
{
    if (s->mv == 0)
        return EOM_OK;
    return eom__fail(s, EOM_ERR_MODEL,
                     "%s: the model has %d velocity (non-holonomic) "
                     "constraint%s, which %s does not take", what, s->mv,
                     s->mv == 1 ? "" : "s", what);
}

int eom__velocity_rows_at(eom_system *s, double t, const double *q)
{
    const int n = s->n, mh = s->mh, mv = s->mv;
    int st, j;
    memcpy(s->vx, q, (size_t)n * sizeof(double));
    memset(s->vx + n, 0, (size_t)n * sizeof(double));
    st = tp_jacobian(s->tpsi.ws, eom__tape_input(&s->tpsi, s->vx, t), n, n,
                     s->phit + mh, s->C + (size_t)mh * (size_t)n);
    for (j = 0; j < mv; j++)
        s->phi[mh + j] = 0.0;
    return eom__tape_status(s, st, "the velocity constraints or their "
                                   "Jacobian");
}

int eom__velocity_rates(eom_system *s, double t, const double *x,
                        double *phi, double *phid, double *curv)
{
    const int n = s->n, mh = s->mh;
    int st, j;
    memcpy(s->vdir, x + n, (size_t)n * sizeof(double));
    memset(s->vdir + n, 0, (size_t)n * sizeof(double));
    s->vdir[2 * n] = 1.0; /* read only by a tape with the time */
    st = tp_jvp(s->tpsi.ws, eom__tape_input(&s->tpsi, x, t), 1, s->vdir,
                phid + mh, curv + mh);
    if (phi)
        for (j = mh; j < s->m; j++)
            phi[j] = 0.0;
    return eom__tape_status(s, st, "the velocity constraints or their "
                                   "rates");
}

/* The states at which linearity is checked: the model's initial state and
 * two others about it (pseudo-random, fixed: the check is reproducible). */
#define EOM_LINEARITY_STATES 3

int eom__check_velocity_rows(eom_system *s)
{
    const int n = s->n, mv = s->mv, ni = tp_tape_n_indep(s->tpsi.tape);
    size_t *rowptr = malloc((size_t)(mv + 1) * sizeof *rowptr);
    double *H = malloc((size_t)ni * (size_t)n * sizeof *H);
    double *x = malloc(2 * (size_t)n * sizeof *x);
    int rc = EOM_OK, st, k, r, i, j;
    if (!rowptr || !H || !x) {
        rc = eom__fail(s, EOM_ERR_NOMEM, "out of memory");
        goto done;
    }
    /* a row that does not read qd at all is a constraint on q */
    st = tp_tape_jacobian_pattern(s->tpsi.tape, n, n, rowptr, NULL, 0);
    if (st != TP_OK && st != TP_ERR_SIZE) {
        rc = eom__tape_status(s, st, "the velocity constraints' pattern");
        goto done;
    }
    for (r = 0; r < mv; r++)
        if (rowptr[r + 1] == rowptr[r]) {
            rc = eom__fail(s, EOM_ERR_MODEL,
                           "velocity constraint %d (constraint row %d) "
                           "does not read the rates qd: a constraint on q "
                           "alone is holonomic (eom_model_add_constraints)",
                           r + 1, s->mh + r + 1);
            goto done;
        }
    /* linear in qd: d2psi/dqd2 = 0, exactly (the sweeps of a product with
     * a factor that does not depend on qd give exact zeros there) */
    for (k = 0; k < EOM_LINEARITY_STATES; k++) {
        for (i = 0; i < n; i++) {
            x[i] = s->coords[i].v0 + (k ? 0.3 * sin(1.7 * i + 2.3 * k) : 0);
            x[n + i] = s->coords[i].v1 + (k ? 0.7 * cos(1.1 * i + k) : 0);
        }
        for (r = 0; r < mv; r++) {
            st = tp_hessian_cols(s->tpsi.ws,
                                 eom__tape_input(&s->tpsi, x, 0.25 * k), r,
                                 n, n, NULL, H);
            if (st != TP_OK && st != TP_WARN_NONFINITE) {
                rc = eom__tape_status(s, st, "the velocity constraints' "
                                             "second derivatives");
                goto done;
            }
            for (i = 0; i < n; i++)
                for (j = 0; j < n; j++) {
                    const double h =
                        H[(size_t)(n + i) * (size_t)n + (size_t)j];
                    if (h == 0.0 || !isfinite(h))
                        continue;
                    rc = eom__fail(
                        s, EOM_ERR_MODEL,
                        "velocity constraint %d (constraint row %d) is not "
                        "linear in the rates: d2/d(%s_dot)d(%s_dot) = %.3g "
                        "at %s state; a velocity constraint is A(q, t) qd + "
                        "b(q, t)", r + 1, s->mh + r + 1, s->coords[i].name,
                        s->coords[j].name, h, k ? "a test" : "the initial");
                    goto done;
                }
        }
    }
done:
    free(rowptr);
    free(H);
    free(x);
    return rc;
}

/* Solve S_h z = r for the holonomic rows (S's leading mh x mh block, of
 * the last eom__factor_S) in place, densely, when velocity rows follow
 * them (the Newton step on q); otherwise with the factor of S. */
static int solve_holonomic(eom_system *s, double *r)
{
    const int mh = s->mh, m = s->m, one = 1;
    int i, j, info = 0;
    if (s->mv == 0)
        return eom__S_solve(s, r);
    for (j = 0; j < mh; j++)
        for (i = 0; i < mh; i++)
            s->Sa[(size_t)j * (size_t)mh + (size_t)i] =
                s->S[(size_t)j * (size_t)m + (size_t)i];
    dgesv_(&mh, &one, s->Sa, &mh, s->ipiv, r, &mh, &info);
    if (info > 0)
        return eom__fail(s, EOM_ERR_RANK_DEFICIENT,
                         "projection onto the holonomic constraints: their "
                         "C W^-1 C^T is singular here (redundant "
                         "constraints or a singular configuration)");
    if (info < 0)
        return eom__fail(s, EOM_ERR_LINALG, "dgesv: argument %d", -info);
    return EOM_OK;
}

/* max_j sum_i |C_ji| over rows 0 .. rows-1 of the rows x n matrix C */
static double row_sum_max(const double *C, int rows, int n)
{
    double m = 0.0;
    int i, j;
    for (j = 0; j < rows; j++) {
        double sum = 0.0;
        for (i = 0; i < n; i++)
            sum += fabs(C[(size_t)j * (size_t)n + (size_t)i]);
        m = fmax(m, sum);
    }
    return m;
}

/* v[0..n) -= Y S^-1 r, r (m) overwritten (eom_internal.h). */
int eom__S_correct(eom_system *s, double *v, double *r)
{
    const int n = s->n, m = s->m;
    int i, j, rc;
    if ((rc = eom__S_solve(s, r)) != EOM_OK)
        return rc;
    for (j = 0; j < m; j++)
        for (i = 0; i < n; i++)
            v[i] -= s->Y[(size_t)j * (size_t)n + (size_t)i] * r[j];
    return EOM_OK;
}

enum metric { METRIC_MASS, METRIC_LAST_MASS, METRIC_IDENTITY };

/* The projection at time t with W = M at x, the M factored last, or I. */
static int project(eom_system *s, double t, double *x, double tol,
                   double qtol, int *iters, enum metric metric,
                   const char *fn)
{
    const int n = s ? s->n : 0, m = s ? s->m : 0, mh = s ? s->mh : 0;
    int it = 0, rc, st, i, j;
    double res, res_prev = 0.0, accept = tol;
    if (iters)
        *iters = 0;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!x)
        return eom__fail(s, EOM_ERR_NULL, "%s: x is NULL", fn);
    if (!(tol > 0.0))
        return eom__fail(s, EOM_ERR_ARG, "%s: tolerance %g", fn, tol);
    if (m == 0)
        return EOM_OK;
    if (!eom__finite(x, 2 * (size_t)n))
        return eom__fail(s, EOM_ERR_NONFINITE, "the state is not finite");
    /* nothing to do when phi and C qd (+ dphi/dt) are within the
     * tolerance */
    if ((rc = eom__constraint_rates(s, t, x, s->phi, s->phid, s->gam)))
        return rc;
    if (eom__maxabs(s->phi, m) <= tol && eom__maxabs(s->phid, m) <= tol)
        return EOM_OK;
    if (metric == METRIC_MASS ||
        (metric == METRIC_LAST_MASS && !s->mf_valid)) {
        double L;
        st = tp_lagrange(s->tL.ws, eom__tape_input(&s->tL, x, t), 0, &L,
                         NULL, s->M, NULL);
        if ((rc = eom__tape_status(s, st,
                                   "the Lagrangian or the mass matrix")))
            return rc;
        if ((rc = eom__factor_mass(s)) != EOM_OK)
            return rc;
    } else if (metric == METRIC_IDENTITY) {
        /* the Cholesky factor of I is I */
        memset(s->Mf, 0, (size_t)n * (size_t)n * sizeof(double));
        for (i = 0; i < n; i++)
            s->Mf[(size_t)i * (size_t)n + (size_t)i] = 1.0;
        s->mf_valid = false; /* no longer M's factor */
    }
    for (;;) {
        if ((rc = eom__constraints_at(s, t, x)) != EOM_OK)
            return rc;
        res = eom__maxabs(s->phi, mh);
        if (qtol > 0.0)
            accept = fmax(tol, qtol * row_sum_max(s->C, mh, n));
        if (res <= tol)
            break;
        /* stalled under the filter, within what the step's error
         * leaves */
        if (it >= 2 && s->S_pinv && res > EOM_PROJ_STALL * res_prev &&
            res <= accept)
            break;
        res_prev = res;
        if (it == EOM_PROJ_MAXIT) {
            /* slow convergence is the mark of a near-singular C: say how
             * near (the estimate of the last factorization) */
            char stalled[64] = "";
            if (accept > tol)
                snprintf(stalled, sizeof stalled,
                         ", or %.3g once the iteration stalls", accept);
            return eom__fail(s, EOM_ERR_PROJECTION,
                             "projection onto the constraints: |phi| = %.3g "
                             "after %d iterations (tolerance %.3g%s); "
                             "C W^-1 C^T has reciprocal condition %.3g "
                             "here%s",
                             res, it, tol, stalled, s->rcond_S,
                             s->rcond_S < 1e-3
                                 ? ": a (nearly) singular configuration"
                                 : "");
        }
        if ((rc = eom__factor_S(s)) != EOM_OK)
            return rc;
        /* x -= Y_h S_h^-1 phi over the holonomic rows (all rows without
         * velocity rows, whose phi is 0 anyway) */
        memcpy(s->wm, s->phi, (size_t)mh * sizeof(double));
        if ((rc = solve_holonomic(s, s->wm)) != EOM_OK)
            return rc;
        for (j = 0; j < mh; j++)
            for (i = 0; i < n; i++)
                x[i] -= s->Y[(size_t)j * (size_t)n + (size_t)i] * s->wm[j];
        it++;
    }
    /* velocities: C qd + dphi/dt = 0, both at the projected q (already in
     * s->C and s->phit), and A qd + b = 0 for the velocity rows */
    if ((rc = eom__factor_S(s)) != EOM_OK)
        return rc;
    for (j = 0; j < m; j++) {
        double sum = s->tphi.tindex >= 0 || j >= mh ? s->phit[j] : 0.0;
        for (i = 0; i < n; i++)
            sum += s->C[(size_t)j * (size_t)n + (size_t)i] * x[n + i];
        s->wm[j] = sum;
    }
    if ((rc = eom__S_correct(s, x + n, s->wm)) != EOM_OK)
        return rc;
    if (iters)
        *iters = it;
    return eom__finite(x, 2 * (size_t)n)
               ? EOM_OK
               : eom__fail(s, EOM_ERR_NONFINITE,
                           "the projected state is not finite");
}

int eom_project(eom_system *s, double *x, double tol, int *iters)
{
    return project(s, s ? s->time : 0.0, x, tol, 0.0, iters, METRIC_MASS,
                   "eom_project");
}

int eom_project_start(eom_system *s, double *x, double tol, int *iters)
{
    return project(s, s ? s->time : 0.0, x, tol, 0.0, iters,
                   METRIC_IDENTITY,
                   "eom_project_start");
}

int eom__project_step(eom_system *s, double t, double *x, double tol,
                      double qtol, int *iters)
{
    return project(s, t, x, tol, qtol, iters, METRIC_LAST_MASS,
                   "projection");
}
