/* test_integrators.c - the six integrators (rk4, erk, adams, bdf, ida,
 * esdirk) through the public API, on mechanisms with known invariants:
 *
 *   - spring pendulum: the energy E is conserved, to a bound stated per
 *     method below (rk4 at a small step, the others at rtol 1e-10);
 *   - double pendulum (two rods, open): erk and bdf at rtol 1e-12 and rk4
 *     at dt 1e-4 agree at several sample times;
 *   - four-bar linkage with damped joints (a dissipation function added
 *     here): E + W is constant, W grows, and with projection the
 *     constraint residuals at the samples and the largest one reported
 *     stay at round-off level; without it they do not;
 *   - sample times: advancing in steps of 0.1 returns the states that a
 *     run advanced directly to k * 0.1 returns, and a reference's;
 *   - failures: a tiny max_steps is EOM_ERR_SOLVER naming the solver's
 *     flag; a model whose right-hand side turns non-finite mid-run is an
 *     error with a finite last state; bad options are EOM_ERR_ARG;
 *   - the statistics are filled.
 *
 * The bounds are about ten times what the methods achieve on this
 * machine's arithmetic, far below what a broken method would give.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom_models.h"

#define NMAX 8
#define NMETHODS 6

static const double PI_ = 3.14159265358979323846;

static const eom_method methods[NMETHODS] = {
    EOM_RK4, EOM_ERK, EOM_ADAMS, EOM_BDF, EOM_IDA, EOM_ESDIRK};

/* ---- helpers ------------------------------------------------------------ */

static eom_system *make_system(eom_model *md)
{
    eom_system *s = NULL;
    char err[256] = "";
    CHECK(md != NULL);
    if (!md)
        return NULL;
    CHECK_INT(eom_system_new(&s, md, err, sizeof err), EOM_OK);
    if (err[0])
        fprintf(stderr, "eom_system_new: %s\n", err);
    eom_model_free(&md);
    return s;
}

/* Options: rk4 at step dt, the adaptive methods at rtol (atol = rtol /
 * 100). */
static eom_opts opts_for(eom_method m, double dt, double rtol)
{
    eom_opts o;
    eom_opts_default(&o);
    o.method = m;
    if (m == EOM_RK4) {
        o.dt = dt;
    } else {
        o.dt = 0.0;
        o.rtol = rtol;
        o.atol = rtol * 1e-2;
    }
    return o;
}

static double maxabs(const double *a, int n)
{
    double m = 0.0;
    int i;
    for (i = 0; i < n; i++)
        m = fmax(m, fabs(a[i]));
    return m;
}

static double maxdiff(const double *a, const double *b, int n)
{
    double m = 0.0;
    int i;
    for (i = 0; i < n; i++)
        m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

static int all_finite(const double *a, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (!isfinite(a[i]))
            return 0;
    return 1;
}

/* What one run saw at its samples t = k * t_end / nsamp, k = 1..nsamp. */
typedef struct run_result {
    int status;          /* first failure, or EOM_OK */
    double E0;           /* E at t = 0 */
    double drift;        /* max |E + W - E0| */
    double phi, phid;    /* max |phi|, |C qd| */
    double W;            /* W at the end */
    double x[2 * NMAX];  /* state at the end */
    eom_stats st;
} run_result;

static void run(eom_system *s, const eom_opts *o, const double *x0,
                double t_end, int nsamp, run_result *r)
{
    const int n = eom_system_ncoords(s), m = eom_system_nconstraints(s);
    eom_integ *it = NULL;
    eom_energy e;
    double x[2 * NMAX], W = 0.0, phi[NMAX], phid[NMAX];
    int k;
    memset(r, 0, sizeof *r);
    eom_energy_at(s, 0.0, x0, &e);
    r->E0 = e.E;
    r->status = eom_integ_new(&it, s, o, 0.0, x0);
    if (r->status != EOM_OK) {
        fprintf(stderr, "%s: eom_integ_new: %s\n", eom_method_name(o->method),
                eom_system_errmsg(s));
        return;
    }
    for (k = 1; k <= nsamp; k++) {
        const double t = t_end * k / nsamp;
        r->status = eom_integ_advance(it, t, x, &W);
        if (r->status != EOM_OK) {
            fprintf(stderr, "%s: %s\n", eom_method_name(o->method),
                    eom_integ_errmsg(it));
            break;
        }
        eom_energy_at(s, t, x, &e);
        r->drift = fmax(r->drift, fabs(e.E + W - r->E0));
        if (m > 0) {
            eom_residuals(s, x, phi, phid);
            r->phi = fmax(r->phi, maxabs(phi, m));
            r->phid = fmax(r->phid, maxabs(phid, m));
        }
    }
    memcpy(r->x, x, 2 * (size_t)n * sizeof(double));
    r->W = W;
    eom_integ_stats(it, &r->st);
    eom_integ_free(&it);
    CHECK(it == NULL);
}

static void check_stats(const run_result *r, eom_method m)
{
    CHECK(r->st.steps > 0);
    CHECK(r->st.rhs_evals > 0);
    CHECK(r->st.wall_time >= 0.0);
    CHECK(r->st.failures >= 0);
    if (m == EOM_RK4)
        CHECK_INT(r->st.rhs_evals, 4 * r->st.steps);
    if (m == EOM_BDF || m == EOM_IDA || m == EOM_ESDIRK)
        CHECK(r->st.jac_evals > 0);
    else
        CHECK_INT(r->st.jac_evals, 0);
}

/* ---- spring pendulum: energy ------------------------------------------- */

static void test_spring_energy(void)
{
    /* bound on max |E - E0| / |E0| over 10 s (about 14 periods of the
     * spring, 5 of the swing), per method */
    static const double bound[NMETHODS] = {
        1e-11, /* rk4, dt 1e-3 */
        3e-6,  /* erk, rtol 1e-10: error per step, 5000 steps */
        3e-8,  /* adams, rtol 1e-10 */
        3e-7,  /* bdf, rtol 1e-10 */
        1e-7,  /* ida, rtol 1e-10 */
        1e-7,  /* esdirk, rtol 1e-10 */
    };
    eom_system *s = make_system(eom_models_spring_pendulum(1, 75, 1, 9.81));
    double x0[4];
    int i;
    if (!s)
        return;
    eom_initial_state(s, x0);
    for (i = 0; i < NMETHODS; i++) {
        const eom_opts o = opts_for(methods[i], 1e-3, 1e-10);
        run_result r;
        run(s, &o, x0, 10.0, 100, &r);
        CHECK_INT(r.status, EOM_OK);
        printf("spring %-5s  |dE|/E0 %.2e (bound %.0e)  steps %ld  rhs %ld"
               "  fails %ld  jac %ld\n",
               eom_method_name(methods[i]), r.drift / fabs(r.E0), bound[i],
               r.st.steps, r.st.rhs_evals, r.st.failures, r.st.jac_evals);
        CHECK(r.drift <= bound[i] * fabs(r.E0));
        CHECK_NEAR(r.W, 0.0, 0.0);
        check_stats(&r, methods[i]);
    }
    eom_system_free(&s);
}

/* ---- double pendulum: methods agree ------------------------------------ */

static void test_double_pendulum(void)
{
    static const double m[2] = {1.0, 0.8}, l[2] = {1.0, 0.7};
    static const double th0[2] = {-PI_ / 2 + 1.0, -PI_ / 2 + 1.6};
    static const double times[4] = {0.5, 1.0, 1.5, 2.0};
    /* agreement of the states (rad, rad/s) at every sample time */
    const double tol = 3e-7;
    const eom_method which[3] = {EOM_ERK, EOM_BDF, EOM_RK4};
    const double rtol[3] = {1e-12, 1e-12, 0.0};
    double xs[3][4][4];
    eom_system *s =
        make_system(eom_models_rod_chain(2, m, l, th0, 9.81, 0, 0.0));
    double x0[4];
    int i, k;
    if (!s)
        return;
    eom_initial_state(s, x0);
    for (i = 0; i < 3; i++) {
        const eom_opts o = opts_for(which[i], 1e-4, rtol[i]);
        eom_integ *it = NULL;
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_OK);
        if (!it)
            return;
        for (k = 0; k < 4; k++)
            CHECK_INT(eom_integ_advance(it, times[k], xs[i][k], NULL),
                      EOM_OK);
        eom_integ_free(&it);
    }
    for (k = 0; k < 4; k++) {
        printf("double pendulum t = %.1f: |erk - bdf| %.2e  |erk - rk4| "
               "%.2e (tol %.0e)\n", times[k],
               maxdiff(xs[0][k], xs[1][k], 4), maxdiff(xs[0][k], xs[2][k], 4),
               tol);
        CHECK(maxdiff(xs[0][k], xs[1][k], 4) <= tol);
        CHECK(maxdiff(xs[0][k], xs[2][k], 4) <= tol);
        CHECK(maxdiff(xs[1][k], xs[2][k], 4) <= tol);
    }
    /* and the motion is not trivial: the angles moved */
    CHECK(fabs(xs[0][3][0] - x0[0]) + fabs(xs[0][3][1] - x0[1]) > 0.1);
    eom_system_free(&s);
}

/* ---- four-bar with damped joints: E + W and residuals ------------------ */

/* R = c/2 sum_j (thd_j - thd_{j-1})^2 with thd_0 = 0: a rotary damper at
 * the base pin and at the two moving joints. */
static int fourbar_R(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val prev = tp_const(R, 0.0), sum = tp_const(R, 0.0);
    int j;
    (void)user;
    for (j = 0; j < 3; j++) {
        tp_val rel = tp_sub(R, eom_qd(c, j), prev);
        sum = tp_add(R, sum, tp_sqr(R, rel));
        prev = eom_qd(c, j);
    }
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "c"), 0.5), sum);
    return 0;
}

/* A crank-rocker (Grashof: 1 + 2 <= 1.5 + 2): the crank turns fully and
 * the linkage meets no singular configuration. */
static eom_system *make_fourbar(double c, double *x0)
{
    static const double m[3] = {1.0, 1.5, 1.2}, l[3] = {1.0, 2.0, 1.5};
    static const double th0[3] = {PI_ / 2, 0.1, -1.6};
    eom_model *md = eom_models_rod_chain(3, m, l, th0, 9.81, 1, 2.0);
    eom_system *s;
    int iters = 0;
    CHECK(md != NULL);
    if (!md)
        return NULL;
    CHECK(eom_model_add_param(md, "c", "N m s", c, "joint damping") >= 0);
    CHECK_INT(eom_model_set_dissipation(md, fourbar_R, NULL), EOM_OK);
    s = make_system(md);
    if (!s)
        return NULL;
    eom_initial_state(s, x0);
    x0[3] = 3.0; /* crank rate before projection, rad/s */
    CHECK_INT(eom_project(s, x0, 1e-14, &iters), EOM_OK);
    return s;
}

static void test_fourbar(void)
{
    /* |E + W - E0| bound (J) over 3 s per method; E0 is about 30 J */
    static const double bound[NMETHODS] = {1e-8, 2e-7, 3e-7, 4e-6, 2e-6,
                                           1e-6};
    double x0[6];
    eom_system *s = make_fourbar(0.4, x0);
    int i;
    if (!s)
        return;
    for (i = 0; i < NMETHODS; i++) {
        eom_opts o = opts_for(methods[i], 1e-3, 1e-10);
        run_result r;
        run(s, &o, x0, 3.0, 30, &r);
        CHECK_INT(r.status, EOM_OK);
        printf("four-bar %-5s  |E+W-E0| %.2e (bound %.0e)  W %.3f  |phi| "
               "%.1e  |Cqd| %.1e  max_residual %.1e  proj %ld  steps %ld  "
               "rhs %ld\n", eom_method_name(methods[i]), r.drift, bound[i],
               r.W, r.phi, r.phid, r.st.max_residual, r.st.projections,
               r.st.steps, r.st.rhs_evals);
        CHECK(r.drift <= bound[i]);
        CHECK(r.W > 1.0);          /* the dampers took energy out */
        CHECK(r.phi <= 1e-12);     /* o.proj_tol */
        CHECK(r.phid <= 1e-11);
        CHECK(r.st.max_residual <= 1e-12);
        /* rk4, erk and bdf project after steps, adams and ida at the 30
         * sample times; esdirk after steps too, but its per-step
         * tolerance (5e-14 for rtol 1e-10) leaves less drift than
         * proj_tol, so it need not (the unprojected run below drifts) */
        if (methods[i] == EOM_ADAMS || methods[i] == EOM_IDA)
            CHECK(r.st.projections <= 30);
        else if (methods[i] != EOM_ESDIRK)
            CHECK(r.st.projections > 60);
        check_stats(&r, methods[i]);

        /* without projection the residuals drift above round-off (at a
         * looser tolerance, so that they surely do) */
        o = opts_for(methods[i], 1e-2, 1e-6);
        o.project = 0;
        run(s, &o, x0, 3.0, 30, &r);
        CHECK_INT(r.status, EOM_OK);
        printf("four-bar %-5s  unprojected: |phi| %.1e  max_residual "
               "%.1e\n", eom_method_name(methods[i]), r.phi,
               r.st.max_residual);
        CHECK(r.phi > 1e-10);
        CHECK(r.st.max_residual >= r.phi);
        CHECK_INT(r.st.projections, 0);
    }
    eom_system_free(&s);
}

/* ---- exact sample times ------------------------------------------------- */

static void test_sample_times(void)
{
    static const int direct[3] = {3, 7, 10};
    eom_system *s = make_system(eom_models_spring_pendulum(1, 75, 1, 9.81));
    double x0[4], ref[11][4], xs[11][4], x[4];
    eom_opts o;
    eom_integ *it = NULL;
    int i, j, k;
    if (!s)
        return;
    eom_initial_state(s, x0);
    /* the reference: erk at rtol 1e-13, advanced directly to each k/10 */
    o = opts_for(EOM_ERK, 0.0, 1e-13);
    for (k = 1; k <= 10; k++) {
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_OK);
        if (!it)
            return;
        CHECK_INT(eom_integ_advance(it, 0.1 * k, ref[k], NULL), EOM_OK);
        eom_integ_free(&it);
    }
    for (i = 0; i < NMETHODS; i++) {
        /* rk4 with a step that does not divide 0.1 evenly */
        o = opts_for(methods[i], 3e-4, 1e-10);
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_OK);
        if (!it)
            return;
        for (k = 1; k <= 10; k++)
            CHECK_INT(eom_integ_advance(it, 0.1 * k, xs[k], NULL), EOM_OK);
        eom_integ_free(&it);
        for (j = 0; j < 3; j++) {
            k = direct[j];
            CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_OK);
            if (!it)
                return;
            CHECK_INT(eom_integ_advance(it, 0.1 * k, x, NULL), EOM_OK);
            eom_integ_free(&it);
            printf("sample %-5s t = %.1f: |sampled - direct| %.1e  "
                   "|sampled - ref| %.1e\n", eom_method_name(methods[i]),
                   0.1 * k, maxdiff(xs[k], x, 4), maxdiff(xs[k], ref[k], 4));
            CHECK(maxdiff(xs[k], x, 4) <= 1e-7);
            CHECK(maxdiff(xs[k], ref[k], 4) <= 1e-7);
        }
    }
    eom_system_free(&s);
}

/* ---- failures ----------------------------------------------------------- */

/* A mass falling onto q = 0 in a potential m g q + k q log q: bounded, so
 * the mass arrives with a finite speed, but undefined for q < 0, where
 * the right-hand side is NaN. */
static int fall_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mulc(R, tp_sqr(R, eom_qd(c, 0)), 0.5);
    return 0;
}

static int fall_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val q = eom_q(c, 0);
    (void)user;
    *out = tp_add(R, tp_mulc(R, q, 9.81), tp_mul(R, q, tp_log(R, q)));
    return 0;
}

static eom_system *make_fall(void)
{
    eom_model *md = NULL;
    CHECK_INT(eom_model_new(&md), EOM_OK);
    if (!md)
        return NULL;
    CHECK(eom_model_add_coord(md, "q", "m", 1.0, -3.0) >= 0);
    CHECK_INT(eom_model_set_kinetic(md, fall_T, NULL), EOM_OK);
    CHECK_INT(eom_model_set_potential(md, fall_V, NULL), EOM_OK);
    return make_system(md);
}

static const char *const too_much_work[NMETHODS] = {
    "max_steps", "ARK_TOO_MUCH_WORK", "CV_TOO_MUCH_WORK", "CV_TOO_MUCH_WORK",
    "IDA_TOO_MUCH_WORK", "ARK_TOO_MUCH_WORK"};

static void test_failures(void)
{
    eom_system *s = make_system(eom_models_spring_pendulum(1, 75, 1, 9.81));
    eom_system *fall = make_fall();
    double x0[4], x[4], W = -1.0;
    eom_opts o;
    eom_integ *it = NULL;
    int i, k, rc = EOM_OK;
    if (!s || !fall)
        return;
    eom_initial_state(s, x0);
    for (i = 0; i < NMETHODS; i++) {
        const char *name = eom_method_name(methods[i]);
        /* max_steps too small to reach t = 10 */
        o = opts_for(methods[i], 1e-3, 1e-10);
        o.max_steps = 5;
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_OK);
        if (!it)
            return;
        memset(x, 0, sizeof x);
        CHECK_INT(eom_integ_advance(it, 10.0, x, &W), EOM_ERR_SOLVER);
        printf("%-5s max_steps 5: %s\n", name, eom_integ_errmsg(it));
        CHECK(strstr(eom_integ_errmsg(it), too_much_work[i]) != NULL);
        CHECK(strstr(eom_integ_errmsg(it), "t = ") != NULL);
        /* the last good state: here the initial one */
        CHECK(maxdiff(x, x0, 4) == 0.0);
        CHECK_NEAR(W, 0.0, 0.0);
        /* a failure is final */
        CHECK_INT(eom_integ_advance(it, 20.0, x, NULL), EOM_ERR_SOLVER);
        eom_integ_free(&it);

        /* a right-hand side that turns NaN at q < 0 (about t = 0.25) */
        o = opts_for(methods[i], 1e-3, 1e-8);
        {
            double xf[2] = {1.0, -3.0}, xl[2] = {1.0, -3.0};
            CHECK_INT(eom_integ_new(&it, fall, &o, 0.0, xf), EOM_OK);
            if (!it)
                return;
            for (k = 1; k <= 10; k++) {
                rc = eom_integ_advance(it, 0.1 * k, xf, NULL);
                CHECK(all_finite(xf, 2));
                if (rc != EOM_OK)
                    break;
                memcpy(xl, xf, sizeof xl);
            }
            printf("%-5s NaN mid-run: %s (%s)\n", name,
                   eom_status_name(rc), eom_integ_errmsg(it));
            CHECK(rc == EOM_ERR_SOLVER || rc == EOM_ERR_NONFINITE);
            CHECK(k >= 2 && k <= 4); /* it failed where q crosses 0 */
            /* the last good state: the last sample (rk4: its last good
             * step, which it also keeps) */
            if (methods[i] != EOM_RK4)
                CHECK(maxdiff(xf, xl, 2) == 0.0);
            CHECK(xf[0] > 0.0);
            CHECK(strlen(eom_integ_errmsg(it)) > 0);
            eom_integ_free(&it);
        }

        /* bad options */
        o = opts_for(methods[i], 1e-3, 1e-8);
        if (methods[i] == EOM_RK4) {
            o.dt = 0.0;
            CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_ERR_ARG);
            o.dt = -1e-3;
            CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_ERR_ARG);
        } else {
            o.rtol = 0.0;
            CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_ERR_ARG);
            o.rtol = -1e-8;
            CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_ERR_ARG);
            o.rtol = 1e-8;
            o.atol = 0.0;
            CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_ERR_ARG);
            o.atol = 1e-10;
            o.dt = -1.0;
            CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_ERR_ARG);
        }
        CHECK(it == NULL);
        o = opts_for(methods[i], 1e-3, 1e-8);
        o.max_steps = 0;
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_ERR_ARG);
        /* tout not after t: an error, but not a failure of the run */
        o = opts_for(methods[i], 1e-3, 1e-8);
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_OK);
        if (!it)
            return;
        CHECK_INT(eom_integ_advance(it, 0.0, x, NULL), EOM_ERR_ARG);
        CHECK_INT(eom_integ_advance(it, -1.0, x, NULL), EOM_ERR_ARG);
        CHECK_INT(eom_integ_advance(it, NAN, x, NULL), EOM_ERR_ARG);
        CHECK_INT(eom_integ_advance(it, 0.1, x, NULL), EOM_OK);
        CHECK_INT(eom_integ_advance(it, 0.1, x, NULL), EOM_ERR_ARG);
        CHECK_INT(eom_integ_advance(it, 0.2, x, NULL), EOM_OK);
        eom_integ_free(&it);
    }
    eom_system_free(&s);
    eom_system_free(&fall);
}

int main(void)
{
    test_spring_energy();
    test_double_pendulum();
    test_fourbar();
    test_sample_times();
    test_failures();
    CHECK_DONE();
}
