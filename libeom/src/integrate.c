/* integrate.c - the integrator front end: options, method names, the
 * common right-hand side and projection used by every method, and the
 * public eom_integ_* calls that dispatch to a method's ops table. */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "integrate_internal.h"
#include "kkt_sparse.h"
#include "mass_route.h"

static const char *const method_names[] = {"rk4", "erk",    "adams", "bdf",
                                           "ida", "esdirk", "imex"};
#define METHODS (int)(sizeof method_names / sizeof method_names[0])

const char *eom_method_name(eom_method m)
{
    return (unsigned)m < (unsigned)METHODS ? method_names[m] : "unknown";
}

int eom_method_from_name(const char *name)
{
    int i;
    for (i = 0; name && i < METHODS; i++)
        if (strcmp(name, method_names[i]) == 0)
            return i;
    return -1;
}

void eom_opts_default(eom_opts *o)
{
    if (!o)
        return;
    o->method = EOM_RK4;
    o->dt = 1e-3;
    o->rtol = 1e-8;
    o->atol = 1e-10;
    o->max_steps = 10000000L;
    o->project = 1;
    o->proj_tol = 1e-12;
    o->atol_vec = NULL;
    o->erk_table = NULL;
    o->tol_per_step = 0;
    o->max_order = 0;
    o->dq_jacobian = 0;
    o->n_sens = 0;
    o->sens = NULL;
    o->linear_solver = EOM_LINSOL_AUTO;
}

int eom__integ_top_order(eom_method m)
{
    return m == EOM_ADAMS ? 12 : m == EOM_BDF || m == EOM_IDA ? 5 : 0;
}

int eom__integ_max_order(const eom_integ *it)
{
    return it->o.max_order > 0 ? it->o.max_order
                               : eom__integ_top_order(it->o.method);
}

/* CVODE and IDA test the error of each step against rtol |y| + atol, and
 * the global error of a run is the sum of those steps' errors carried
 * forward: on oscillatory motion it grows with the number of steps, as
 * tol^(p/(p+1)) for a method of order p, and lands 1e2 to 1e4 times off
 * the tolerance at t = 10 s on the shipped models (measured: bdf 4.7e4
 * times at 1e-12 on the open chain). As RADAU5 does, each tolerance is
 * therefore mapped to the per-step tolerance c tol^((p+1)/p) that brings
 * the global error back to the order of tol, with p the method's highest
 * order and c measured on the spring pendulum, the double pendulum and
 * the open chain (tests/eom_integrate/test_tolerance.c). The per-step
 * tolerance never goes above tol, nor below the floor that follows (not
 * even for a tol below it: the solvers would refuse it, or fail). erk
 * needs no mapping: its table advances with the higher-order solution of
 * its pair, and its error stays within 100 tol.
 *
 * Below about 2.2e-16 (the unit roundoff) CVODE and IDA refuse a
 * relative tolerance outright (TOO_MUCH_ACC), and near it their error
 * tests judge rounding: the floor is 3e-16. A run that needs 10^5 steps
 * (bdf at 1e-12 on the open chain wants 8e-17 per step) then cannot
 * hold its global error near tol, since the per-step errors it adds up
 * cannot be made small enough in double precision; eom_stats.tol_reachable
 * says so (measured on the open chain at 1e-12: per-step floors of 1e-15,
 * 5e-16, 3e-16 and 2e-16 give 144, 156, 84 and 42 tol: rounding, not
 * the tolerance, decides there).
 * With constraints:
 *   bdf   near a singular position (and throughout with redundant
 *         constraints) the multipliers' filter (docs/theory.md) makes the
 *         accelerations smooth only to about 1e-11, and bdf fails its
 *         error test there with per-step tolerances of 1e-11 and below
 *         (tests/eom_constraints/test_parallelogram.c); there, and only
 *         there, its floor is 1e-10 (it->loose_floor, integrate_cvode.c).
 *   ida   restarts at order 1 from the state projected at output times
 *         (to proj_tol, 1e-12), and its index-1 form lets phi drift
 *         between them, so its accuracy over a long run rests on its
 *         per-step tolerance: 1e-14. With 1e-12, the IFToMM A01 pendulum
 *         (2000 s, an output every 0.5 s) ended 2.3e-5 from its exact
 *         position at rtol = atol = 1e-10 and the same at 1e-12; with
 *         1e-13, 5.5e-6 at 1e-12; with 1e-14, 2.2e-6 at 1e-10 and 6.7e-7
 *         at 1e-12 (tests/eom_constraints/test_a01.c). Restarting only where the
 *         projection's change exceeds the caller's tolerances, not IDA's
 *         per-step ones, restarted 198 times in 4000 outputs instead of
 *         about 3600 and ended 4.5e-5 off: the restarts hold phi. (The
 *         closed chain at 1e-10, which once stopped at t = 4.9 with this
 *         floor, runs its 10 s: 92024 steps.)
 *   adams refuses singular positions; its floor is the unconstrained one.
 * A single floor of 1e-10 for every constrained model held the closed
 * chain's error at 1.8e-6 for bdf at every tol from 1e-8 down. */
static double step_tol_floor(const eom_integ *it)
{
    if (it->s->m > 0 && it->o.method == EOM_IDA)
        return 1e-14;
    if (it->s->m > 0 && it->loose_floor)
        return 1e-10;
    return 3e-16;
}

/* c of the calibration c tol^((p+1)/p), or 0 where there is none */
static double calibration(const eom_integ *it)
{
    if (it->o.tol_per_step)
        return 0.0;
    switch (it->o.method) {
    case EOM_ADAMS:
        return 0.03;
    case EOM_BDF:
        return 0.02;
    case EOM_IDA:
        return 0.05;
    case EOM_ESDIRK:
        return 0.05;
    case EOM_IMEX:
        /* esdirk's: its runs on the four models of test_tolerance.c
         * stay within 100 tol with it (docs/integrators.md) */
        return 0.05;
    default:
        return 0.0;
    }
}

/* the calibration was measured at the methods' own highest orders; a
 * lower max_order keeps it (docs/integrators.md) */
static double exponent(const eom_integ *it)
{
    /* esdirk and imex: order 5, one order */
    const int p = it->o.method == EOM_ESDIRK || it->o.method == EOM_IMEX
                      ? 5
                      : eom__integ_top_order(it->o.method);
    return (p + 1.0) / p;
}

double eom__integ_step_tol(const eom_integ *it, double tol)
{
    const double c = calibration(it);
    if (c == 0.0)
        return tol;
    /* never below the floor, even for a tolerance tighter than it */
    return fmax(step_tol_floor(it), fmin(tol, c * pow(tol, exponent(it))));
}

double eom__integ_tol_reachable(const eom_integ *it)
{
    /* bdf's loose floor counts if it was ever used */
    const double floor = it->was_loose ? 1e-10 : step_tol_floor(it);
    const double c = calibration(it);
    double tol = fmin(it->o.rtol, it->o.atol), reach;
    int i;
    if (c == 0.0)
        return 0.0;
    for (i = 0; it->atolv && i < 2 * it->n; i++)
        tol = fmin(tol, it->atolv[i]);
    /* the tolerance whose per-step tolerance is the floor */
    reach = pow(floor / c, 1.0 / exponent(it));
    return c * pow(tol, exponent(it)) < floor ? reach : 0.0;
}

void eom__integ_atol(const eom_integ *it, double *atol, int len)
{
    int i;
    for (i = 0; i < len; i++)
        atol[i] = eom__integ_step_tol(
            it, it->atolv && i < 2 * it->n ? it->atolv[i] : it->o.atol);
}

int eom__integ_fail(eom_integ *it, int status, const char *fmt, ...)
{
    /* format aside first: the arguments may quote it->msg itself */
    char buf[sizeof it->msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    memcpy(it->msg, buf, sizeof buf);
    it->failed = status;
    return status;
}

void eom__integ_name_rows(eom_integ *it, const double *y)
{
    eom_system *s = it->s;
    char text[sizeof it->msg];
    int rank = 0;
    size_t used;
    /* a diagnostic of n m doubles, once: not for the largest models */
    if (s->m == 0 || (double)s->m * (double)s->n > 4e6)
        return;
    if (eom_constraint_rank(s, y, 0.0, &rank, NULL, text, sizeof text) !=
            EOM_OK ||
        rank >= s->m)
        return;
    used = strlen(it->msg);
    snprintf(it->msg + used, sizeof it->msg - used,
             "; rank %d of %d rows there: %s", rank, s->m, text);
}

/* The sparse path's measure at the positions of y (kkt_integ.c): sets
 * it->kkt_near, and leaves the augmented factor at y. */
static int kkt_measure(eom_integ *it, double t, const double *y)
{
    int poor = 0, rc = eom__kkt_factor_at(it->s, t, y, &poor);
    if (rc != EOM_OK)
        return rc;
    it->kkt_near = poor || eom__kkt_sigma(it->s) < EOM_KKT_SIGMA_NEAR;
    return EOM_OK;
}

int eom__integ_rhs(eom_integ *it, double t, const double *y, double *yd)
{
    eom_system *s = it->s;
    const int n = it->n;
    int rc;
    it->st.rhs_evals++;
    /* the sparse solve, or where its factor is poor the dense route */
    rc = it->kkt && !it->kkt_near ? eom__evaluate_rhs(s, t, y)
                                  : eom__evaluate(s, t, y);
    if (rc != EOM_OK) {
        snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t, s->msg);
        return rc;
    }
    if (it->refuse_singular && s->m > 0 && s->S_pinv) {
        it->t_refused = t;
        snprintf(it->msg, sizeof it->msg,
                 "at t = %.17g the constraint system is singular or nearly "
                 "so (rcond of C M^-1 C^T %.2g): a singular position or "
                 "redundant constraints, which %s cannot pass (it projects "
                 "only at output times); use bdf, erk or rk4 "
                 "(docs/integrators.md)", t, s->rcond_S,
                 eom_method_name(it->o.method));
        return EOM_ERR_RANK_DEFICIENT;
    }
    memmove(yd, y + n, (size_t)n * sizeof(double));
    memcpy(yd + n, s->qdd, (size_t)n * sizeof(double));
    yd[2 * n] = -s->power;
    return EOM_OK;
}

int eom__integ_jacobian(eom_integ *it, double t, const double *y,
                        double *J, int ldj)
{
    const double t0 = eom__integ_now();
    int rc = eom__state_jacobian(it->s, t, y, J, ldj, 1);
    it->st.jac_time += eom__integ_now() - t0;
    if (rc != EOM_OK)
        snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t,
                 it->s->msg);
    return rc;
}

int eom__integ_stretch_done(eom_integ *it, double t)
{
    const double r = it->s->rcond_S;
    if (r < 1e-3)
        it->seen_singular = 1;
    /* past where the method was refused, even if no accepted step of
     * bdf's came as close to the singular position */
    it->stretch_over = (it->seen_singular || t > it->t_refused) && r > 1e-2;
    return it->stretch_over;
}

int eom__integ_branch(eom_integ *it, double t, const double *y)
{
    int rc = EOM_OK;
    if (!it->branch)
        return EOM_OK;
    if (it->kkt) {
        /* far from singular positions (the measure says so) the rank of
         * C is full: the monitor's dense elimination is not run */
        rc = kkt_measure(it, t, y);
        if (rc == EOM_OK && !it->kkt_near &&
            !eom__branch_in_pass(it->branch)) {
            eom__branch_regular(it->branch, t, y);
            return EOM_OK;
        }
    }
    if (rc == EOM_OK || !it->kkt)
        rc = eom__branch_check(it->branch, it->s, t, y,
                               &it->st.rhs_evals);
    if (rc != EOM_OK)
        snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", t,
                 rc == EOM_ERR_NOMEM ? "out of memory" : it->s->msg);
    return rc;
}

/* The position error a step is allowed: what the error test accepts for
 * the largest coordinate of y (the per-step tolerances the method is
 * given), or rk4's atol (it has no error test). The projection may stop
 * once the residual is what such an error leaves and its iteration has
 * stalled (constraints.c, EOM_PROJ_STALL). */
double eom__integ_proj_qtol(const eom_integ *it, const double *y)
{
    double qmax = 0.0;
    int i;
    if (it->o.method == EOM_RK4)
        return it->o.atol;
    for (i = 0; i < it->n; i++)
        qmax = fmax(qmax, fabs(y[i]));
    return eom__integ_step_tol(it, it->o.rtol) * qmax +
           eom__integ_step_tol(it, it->o.atol);
}

int eom__integ_project(eom_integ *it, double *y)
{
    eom_system *s = it->s;
    int rc, iters = 0, j;
    if (s->m == 0)
        return EOM_OK;
    if (it->o.project) {
        int dense = 1;
        rc = EOM_OK;
        if (it->kkt && !it->kkt_near)
            rc = eom__kkt_project(s, it->t, y, it->o.proj_tol, &iters,
                                  &dense);
        if (rc == EOM_OK && dense)
            rc = eom__project_step(s, it->t, y, it->o.proj_tol,
                                   eom__integ_proj_qtol(it, y), &iters);
        if (rc != EOM_OK) {
            snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", it->t,
                     s->msg);
            return rc;
        }
        if (iters > 0)
            it->st.projections++;
    }
    /* s->phi holds phi at the (projected) q */
    if (!it->o.project) {
        rc = eom__constraint_rates(s, it->t, y, s->phi, s->phid, s->gam);
        if (rc != EOM_OK) {
            snprintf(it->msg, sizeof it->msg, "at t = %.17g: %s", it->t,
                     s->msg);
            return rc;
        }
    }
    for (j = 0; j < s->m; j++)
        it->st.max_residual = fmax(it->st.max_residual, fabs(s->phi[j]));
    return EOM_OK;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double eom__integ_now(void)
{
    return now();
}

static const eom_integ_ops *ops_of(eom_method m)
{
    switch (m) {
    case EOM_RK4: return &eom__rk4_ops;
    case EOM_ERK: return &eom__erk_ops;
    case EOM_ADAMS:
    case EOM_BDF: return &eom__cvode_ops;
    case EOM_IDA: return &eom__ida_ops;
    case EOM_ESDIRK: return &eom__esdirk_ops;
    case EOM_IMEX: return &eom__imex_ops;
    default: return NULL;
    }
}

static int check_opts(const eom_opts *o, int n, char *msg, size_t len)
{
    const char *bad = NULL;
    int i;
    if (!ops_of(o->method))
        bad = "unknown integration method";
    else if (o->method == EOM_RK4 && !(o->dt > 0.0 && isfinite(o->dt)))
        bad = "rk4 needs a step dt > 0";
    else if (!(o->dt >= 0.0) || !isfinite(o->dt))
        bad = "the first step dt must be >= 0";
    else if (o->method != EOM_RK4 &&
             !(o->rtol > 0.0 && o->atol > 0.0 && isfinite(o->rtol) &&
               isfinite(o->atol)))
        bad = "tolerances rtol and atol must be > 0";
    else if (o->max_steps < 1)
        bad = "max_steps must be >= 1";
    else if (o->project && !(o->proj_tol > 0.0))
        bad = "the projection tolerance must be > 0";
    else if (o->erk_table && strlen(o->erk_table) >= EOM_TABLE_NAME_LEN)
        bad = "the ERK table name is too long";
    else if (eom__integ_top_order(o->method) > 0 &&
             (o->max_order < 0 ||
              o->max_order > eom__integ_top_order(o->method))) {
        snprintf(msg, len, "max_order %d: %s takes 0 (its own, %d) to %d",
                 o->max_order, eom_method_name(o->method),
                 eom__integ_top_order(o->method),
                 eom__integ_top_order(o->method));
        return EOM_ERR_ARG;
    }
    if (!bad && (o->linear_solver < EOM_LINSOL_AUTO ||
                 o->linear_solver > EOM_LINSOL_SPARSE)) {
        snprintf(msg, len, "linear_solver %d: 0 (auto), 1 (dense) or 2 "
                 "(sparse)", o->linear_solver);
        return EOM_ERR_ARG;
    }
    if (!bad && o->linear_solver == EOM_LINSOL_SPARSE &&
        o->method != EOM_IDA && o->method != EOM_BDF) {
        snprintf(msg, len, "linear_solver 2 (sparse): only ida and bdf "
                 "have a sparse iteration matrix; %s %s "
                 "(docs/integrators.md, \"Sparse iteration matrices\")",
                 eom_method_name(o->method),
                 o->method == EOM_ESDIRK ? "is dense"
                                         : "solves no linear systems");
        return EOM_ERR_ARG;
    }
    if (!bad && o->linear_solver == EOM_LINSOL_SPARSE && o->dq_jacobian)
        bad = "linear_solver 2 (sparse) needs the exact Jacobian: the "
              "difference quotients (dq_jacobian 1) fill dense matrices "
              "only";
    for (i = 0; o->atol_vec && !bad && i < 2 * n; i++)
        if (!(o->atol_vec[i] > 0.0 && isfinite(o->atol_vec[i]))) {
            snprintf(msg, len, "atol_vec[%d] = %g: every absolute "
                     "tolerance must be > 0 and finite", i, o->atol_vec[i]);
            return EOM_ERR_ARG;
        }
    if (bad)
        snprintf(msg, len, "%s", bad);
    return bad ? EOM_ERR_ARG : EOM_OK;
}

/* The sensitivities asked for: methods, models and inputs. */
static int check_sens(const eom_opts *o, const eom_system *s, char *msg,
                      size_t len)
{
    int k;
    if (o->n_sens == 0)
        return EOM_OK;
    if (o->n_sens < 0 || !o->sens) {
        snprintf(msg, len, "n_sens %d with %s sens", o->n_sens,
                 o->sens ? "a" : "a NULL");
        return o->sens ? EOM_ERR_ARG : EOM_ERR_NULL;
    }
    if (o->method != EOM_ADAMS && o->method != EOM_BDF &&
        o->method != EOM_IDA) {
        snprintf(msg, len, "sensitivities are integrated by adams and bdf "
                 "(CVODES) and ida (IDAS), not by %s",
                 eom_method_name(o->method));
        return EOM_ERR_ARG;
    }
    for (k = 0; k < o->n_sens; k++)
        if (o->sens[k] < 0 || o->sens[k] >= s->np + 2 * s->n) {
            snprintf(msg, len, "sens[%d] = %d: an input is a parameter 0 .. "
                     "%d or an initial value %d .. %d", k, o->sens[k],
                     s->np - 1, s->np, s->np + 2 * s->n - 1);
            return EOM_ERR_ARG;
        }
    return EOM_OK;
}

/* With constraints, the sensitivities at t0 are those of the start
 * taken onto the constraints by the least change of the coordinates
 * (eom_project_start; eom-run starts there): the unit vectors of the
 * initial values and the zeros of the parameters, projected with the
 * linearized projection (sensitivity.c), so that a parameter of the
 * constraints moves the start with it. s then forgets the evaluation, so
 * that the run itself is the same as without sensitivities. */
static int sens_start(eom_integ *it)
{
    eom_system *s = it->s;
    const int ns = it->o.n_sens, n2 = 2 * s->n;
    double *cols = malloc((size_t)n2 * (size_t)ns * sizeof *cols);
    double **V = malloc((size_t)ns * sizeof *V);
    double *work = malloc(eom__sens_work(s, ns) * sizeof *work);
    int *par = malloc((size_t)ns * sizeof *par);
    int i, k, rc = EOM_ERR_NOMEM;
    if (cols && V && work && par) {
        for (k = 0; k < ns; k++) {
            V[k] = cols + (size_t)k * n2;
            par[k] = it->sens[k] < s->np ? it->sens[k] : -1;
            for (i = 0; i < n2; i++)
                V[k][i] = it->S[(size_t)i * ns + k];
        }
        rc = eom__sens_project(s, it->t, it->y, 1, ns, par, V, work);
        eom__forget(s);
        for (k = 0; rc == EOM_OK && k < ns; k++)
            for (i = 0; i < n2; i++)
                it->S[(size_t)i * ns + k] = V[k][i];
        if (rc != EOM_OK)
            snprintf(it->msg, sizeof it->msg,
                     "the sensitivities at the start: %s", s->msg);
    } else {
        snprintf(it->msg, sizeof it->msg, "out of memory");
    }
    free(cols);
    free(V);
    free(work);
    free(par);
    return rc;
}

int eom__integ_create(eom_integ **out, eom_system *s, const eom_opts *o,
                      double t0, const double *y0, int fresh)
{
    eom_integ *it;
    int rc;
    *out = NULL;
    if ((rc = check_opts(o, s->n, s->msg, sizeof s->msg)) != EOM_OK)
        return rc;
    if ((rc = check_sens(o, s, s->msg, sizeof s->msg)) != EOM_OK)
        return rc;
    /* velocity constraints: the methods that integrate the accelerations
     * of the range-space solve take them; ida's index-1 form and the
     * projection of the sensitivities are those of holonomic rows */
    if (s->mv > 0 && o->method == EOM_IDA)
        return eom__fail(s, EOM_ERR_MODEL,
                         "ida: the model has velocity (non-holonomic) "
                         "constraints, which ida's index-reduced DAE of "
                         "holonomic constraints does not take; rk4, erk, "
                         "adams, bdf, esdirk and imex do");
    if (s->mv > 0 && o->n_sens > 0)
        return eom__fail(s, EOM_ERR_MODEL,
                         "%s: sensitivities are not integrated for a model "
                         "with velocity (non-holonomic) constraints; rk4, "
                         "erk, adams, bdf, esdirk and imex integrate it "
                         "without them", eom_method_name(o->method));
    it = calloc(1, sizeof *it);
    if (!it)
        return EOM_ERR_NOMEM;
    /* a run's numbers depend on its own inputs, not on what s evaluated
     * before it (an ensemble runs many on one system, in any order) */
    if (fresh)
        eom__forget(s);
    it->s = s;
    it->o = *o;
    /* nothing borrowed outlives this call */
    it->o.atol_vec = NULL;
    it->o.erk_table = NULL;
    it->o.sens = NULL;
    if (o->n_sens > 0) {
        int k;
        it->sens = malloc((size_t)o->n_sens * sizeof *it->sens);
        it->S = calloc(2 * (size_t)s->n * (size_t)o->n_sens, sizeof *it->S);
        if (!it->sens || !it->S) {
            free(it->sens);
            free(it->S);
            free(it);
            return EOM_ERR_NOMEM;
        }
        memcpy(it->sens, o->sens, (size_t)o->n_sens * sizeof *it->sens);
        /* at t0: d x / d x0_i is the unit vector i, d x / dp is 0 */
        for (k = 0; k < o->n_sens; k++)
            if (o->sens[k] >= s->np)
                it->S[(size_t)(o->sens[k] - s->np) * o->n_sens + k] = 1.0;
    }
    if (o->erk_table)
        strcpy(it->erk_table, o->erk_table);
    if (o->atol_vec) {
        it->atolv = malloc(2 * (size_t)s->n * sizeof(double));
        if (!it->atolv) {
            free(it->sens);
            free(it->S);
            free(it);
            return EOM_ERR_NOMEM;
        }
        memcpy(it->atolv, o->atol_vec, 2 * (size_t)s->n * sizeof(double));
    }
    it->n = s->n;
    it->N = 2 * s->n + 1;
    it->t = t0;
    it->ops = ops_of(o->method);
    /* ida's and bdf's init say which they chose */
    it->linsol = o->method == EOM_BDF || o->method == EOM_ESDIRK ||
                         o->method == EOM_IDA
                     ? EOM_LINSOL_DENSE
                     : 0;
    it->y = malloc((size_t)it->N * sizeof(double));
    if (!it->y) {
        free(it->atolv);
        free(it->sens);
        free(it->S);
        free(it);
        return EOM_ERR_NOMEM;
    }
    memcpy(it->y, y0, (size_t)it->N * sizeof(double));
    /* a mass matrix whose smallest relative pivot is below eps / rtol
     * gives accelerations that miss the tolerance: such an evaluation is
     * a singular mass matrix, which stops the integrator at once
     * (rhs.c), where the step would otherwise shrink without end. Below
     * rtol 1e-8 the floor stays at 2.2e-8: well-posed models keep pivots
     * far above it (a spatial model of the tests 0.002, run at rtol
     * 1e-13). From here on eom_integ_free restores the system's own
     * floor. */
    it->pivot_saved = s->mass_pivot_min;
    s->mass_pivot_min = DBL_EPSILON / fmax(o->rtol, 1e-8);
    s->time = t0;
    if (fresh)
        s->rcond_S_min = 1.0;
    it->svd_base = s->n_svd;
    it->refuse_singular =
        s->m > 0 && (o->method == EOM_ADAMS || o->method == EOM_IDA);
    /* the sparse path: methods that need of the constraint system only
     * its solve, the projection and the branch monitor (bdf, ida, esdirk
     * and imex read its dense factors for their Jacobians and error
     * projections; sensitivities are dense) */
    it->kkt = s->m > 0 && o->n_sens == 0 &&
              (o->method == EOM_RK4 || o->method == EOM_ERK ||
               o->method == EOM_ADAMS) &&
              eom__kkt_applies(s);
    rc = EOM_OK;
    if (fresh && s->m > 0 && o->project) {
        /* a start off the constraints is taken onto them here, by the
         * least change of the coordinates, whatever the method: each
         * method's own handling of it differed (rk4, erk, esdirk and imex
         * projected after the first step in the M-norm, adams and ida
         * integrated another motion). A start within proj_tol is left
         * as it is. */
        int iters = 0;
        rc = eom_project_start(s, it->y, o->proj_tol, &iters);
        if (rc != EOM_OK)
            snprintf(it->msg, sizeof it->msg, "the start is off the "
                     "constraints and cannot be projected onto them: %s",
                     s->msg);
        else if (iters > 0)
            it->st.projections++;
    }
    if (rc == EOM_OK && s->m > 0 && o->n_sens > 0)
        rc = sens_start(it);
    if (rc == EOM_OK && it->kkt && (rc = kkt_measure(it, t0, it->y)))
        snprintf(it->msg, sizeof it->msg, "%s", s->msg);
    if (rc == EOM_OK)
        rc = it->ops->init(it);
    if (rc == EOM_OK && fresh && it->refuse_singular) {
        /* refused at setup where the start already shows it */
        double *yd = malloc((size_t)it->N * sizeof(double));
        rc = yd ? eom__integ_rhs(it, t0, it->y, yd) : EOM_ERR_NOMEM;
        if (!yd)
            snprintf(it->msg, sizeof it->msg, "out of memory");
        free(yd);
    }
    /* refused at the start (by init's first evaluation or the one
     * above): which rows, if rows depend on others */
    if (rc == EOM_ERR_RANK_DEFICIENT && fresh && it->refuse_singular)
        eom__integ_name_rows(it, it->y);
    /* a handover borrows the monitor of the integrator it works for */
    if (rc == EOM_OK && fresh && s->m > 0) {
        if (it->kkt && !it->kkt_near) {
            /* the rank is full here: no dense elimination (the factor
             * at the start again: init's evaluations replaced it) */
            double *norm = malloc((size_t)s->m * sizeof *norm);
            rc = EOM_ERR_NOMEM;
            if (norm && (rc = kkt_measure(it, t0, it->y)) == EOM_OK &&
                !it->kkt_near) {
                eom__kkt_row_norms(s, norm);
                rc = eom__branch_new_regular(&it->branch, s, t0, it->y,
                                             norm);
            }
            free(norm);
        }
        if (rc == EOM_OK && !it->branch)
            rc = eom__branch_new(&it->branch, s, t0, it->y);
        if (rc == EOM_OK)
            rc = eom__branch_mark(it->branch);
        if (rc != EOM_OK)
            snprintf(it->msg, sizeof it->msg, "%s",
                     rc == EOM_ERR_NOMEM ? "out of memory" : s->msg);
    }
    if (rc != EOM_OK) {
        eom__fail(s, rc, "%s: %s", eom_method_name(o->method), it->msg);
        eom_integ_free(&it);
        return rc;
    }
    s->msg[0] = '\0';
    *out = it;
    return EOM_OK;
}

int eom_integ_new(eom_integ **out, eom_system *s, const eom_opts *o,
                  double t0, const double *x0)
{
    double *y0;
    int rc;
    if (!out)
        return EOM_ERR_NULL;
    *out = NULL;
    if (!s)
        return EOM_ERR_NULL;
    if (!o || !x0) /* its own message, not the previous call's */
        return eom__fail(s, EOM_ERR_NULL, "eom_integ_new: %s is NULL",
                         !o ? "the options argument" : "the initial state");
    if ((rc = check_opts(o, s->n, s->msg, sizeof s->msg)) != EOM_OK)
        return rc;
    if (!isfinite(t0) || !eom__finite(x0, 2 * (size_t)s->n))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "the initial state is not finite");
    /* W starts at 0 */
    if (!(y0 = calloc(2 * (size_t)s->n + 1, sizeof(double))))
        return eom__fail(s, EOM_ERR_NOMEM, "eom_integ_new: out of memory");
    memcpy(y0, x0, 2 * (size_t)s->n * sizeof(double));
    rc = eom__integ_create(out, s, o, t0, y0, 1);
    free(y0);
    return rc;
}

void eom_integ_free(eom_integ **it)
{
    if (!it || !*it)
        return;
    if ((*it)->ops && (*it)->ops->destroy)
        (*it)->ops->destroy(*it);
    (*it)->s->mass_pivot_min = (*it)->pivot_saved;
    free((*it)->y);
    free((*it)->atolv);
    free((*it)->sens);
    free((*it)->S);
    if (!(*it)->branch_borrowed)
        eom__branch_free(&(*it)->branch);
    eom_integ_free(&(*it)->sub);
    free(*it);
    *it = NULL;
}

int eom_integ_sensitivities(const eom_integ *it, double *S)
{
    if (!it || !S)
        return EOM_ERR_NULL;
    if (it->o.n_sens == 0 || !it->S)
        return EOM_ERR_ARG;
    memcpy(S, it->S, 2 * (size_t)it->n * (size_t)it->o.n_sens * sizeof *S);
    return EOM_OK;
}

const char *eom_integ_errmsg(const eom_integ *it)
{
    return it ? it->msg : "NULL integrator";
}

int eom_integ_advance(eom_integ *it, double tout, double *x, double *W)
{
    double t0;
    int rc;
    if (!it)
        return EOM_ERR_NULL;
    if (!x) {
        snprintf(it->msg, sizeof it->msg, "eom_integ_advance: x is NULL");
        return EOM_ERR_NULL;
    }
    if (it->failed)
        return it->failed;
    if (!isfinite(tout) || !(tout > it->t)) {
        snprintf(it->msg, sizeof it->msg,
                 "eom_integ_advance: tout = %.17g is not after t = %.17g",
                 tout, it->t);
        return EOM_ERR_ARG;
    }
    t0 = now();
    if (it->sub) {
        /* a singular stretch goes on */
        rc = eom__integ_handover(it, tout);
    } else {
        rc = it->ops->advance(it, tout);
        if ((rc == EOM_ERR_RANK_DEFICIENT && it->refuse_singular) ||
            eom__integ_hands_over(it, rc))
            rc = eom__integ_handover(it, tout);
    }
    /* where a handover would begin */
    if (rc == EOM_OK && it->branch && !it->branch_borrowed &&
        eom__branch_mark(it->branch) != EOM_OK)
        rc = eom__integ_fail(it, EOM_ERR_NOMEM, "out of memory");
    it->st.wall_time += now() - t0;
    /* the calls without a t argument now see the state returned */
    it->s->time = it->t;
    if (rc != EOM_OK)
        it->failed = rc;
    memcpy(x, it->y, 2 * (size_t)it->n * sizeof(double));
    if (W)
        *W = it->y[2 * it->n];
    return rc;
}

int eom_integ_stats(const eom_integ *it, eom_stats *st)
{
    if (!it || !st)
        return EOM_ERR_NULL;
    *st = it->st;
    st->min_rcond_S = it->s->rcond_S_min;
    st->svd_solves = it->s->n_svd - it->svd_base;
    st->branch_switches = eom__branch_switches(
        it->branch, &st->first_branch_switch, &st->singular_passes);
    st->step_tol = it->o.method == EOM_RK4
                       ? 0.0
                       : eom__integ_step_tol(it, it->o.rtol);
    st->tol_reachable = eom__integ_tol_reachable(it);
    it->ops->stats(it, st);
    /* what bdf and the method's earlier instances did (handovers) */
    st->steps += it->handed.steps;
    st->failures += it->handed.failures;
    st->jac_evals += it->handed.jac_evals;
    st->linear_solver = it->linsol;
    /* mass_route.h; the sparse path: kkt_integ.c */
    st->mass_route = it->kkt ? EOM_MASS_SPARSE : eom__mass_route(it->s);
    if (it->sub) {
        /* a stretch still under way */
        eom_stats b;
        memset(&b, 0, sizeof b);
        it->sub->ops->stats(it->sub, &b);
        st->steps += b.steps;
        st->failures += b.failures;
        st->jac_evals += b.jac_evals;
        st->jac_time += it->sub->st.jac_time;
        st->rhs_evals += it->sub->st.rhs_evals;
        st->projections += it->sub->st.projections;
        st->max_residual = fmax(st->max_residual, it->sub->st.max_residual);
        st->tol_reachable =
            fmax(st->tol_reachable, eom__integ_tol_reachable(it->sub));
    }
    /* the stretches' bdf may have kept less than the method */
    st->tol_reachable = fmax(st->tol_reachable, it->handed_reach);
    st->singular_handovers = it->handovers;
    st->singular_handovers_erk = it->handovers_erk;
    return EOM_OK;
}
