/* test_imex.c - the IMEX integrator (EOM_IMEX, integrate_imex.c), white-
 * box where the split is checked:
 *
 *   1. The split. At random states of a damped, forced two-mass model
 *      with a constant mass matrix, whose parts are known by hand
 *      (T = m1 xd1^2 / 2 + m2 (xd1 + xd2)^2 / 2, V with a quartic spring
 *      and a constant force, R with a damping that depends on x1, Q of
 *      the state), f_I = (qd, M^-1 (-dV/dq - dR/dqd), 0) and
 *      f_E = (0, M^-1 Q, -P), to 1e-14; and f_E + f_I equals the
 *      right-hand side (eom_rhs, and -P from eom_energy_at) to 1e-14 on it,
 *      on the spring pendulum (f_I's accelerations by hand too) and on a
 *      closed four-bar, where the implicit accelerations also satisfy
 *      C a_I = 0 and the explicit ones C a_E = gamma.
 *   2. The Newton matrix's Jacobian: on the constant-mass model J_I is
 *      exact, so it must equal central differences of f_I (1e-7); with
 *      eom_opts.dq_jacobian ARKODE's difference quotient serves as well.
 *   3. Order: error against steps over rtol = atol = 1e-4 .. 1e-8 on the
 *      spring pendulum against the hand-derived reference (nominal 5,
 *      the ARK5(4)8L[2]SA pair), and on the same pendulum with a spring
 *      100 times stiffer against erk at a per-step 1e-13, over
 *      tolerances and with fixed steps halved three times.
 *   4. The stiff part is implicit: a pendulum on a spring of k = 1e8 with
 *      a damper on its length (a fast mode at 1e4 rad/s that decays in a
 *      millisecond) takes imex far fewer steps than erk, which is held
 *      to its stability limit, at the same error.
 *   5. Agreement with a tight reference on every shipped model
 *      (every models/NAME.eom) and on the C models (four-bar, bead on a circle):
 *      imex at rtol = atol = 1e-9 against erk at a per-step 1e-13,
 *      within 100 times the tolerance; and E + W constant on the damped
 *      ones.
 *   6. Refusals: a model that gives a whole Lagrangian (no V apart), and
 *      sensitivities; messages naming what to use instead. A run into a
 *      domain error fails with a message naming imex and the last good
 *      state.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/model_file.h"
#include "eom_models.h"
#include "hand_ref.h"
#include "integrate_internal.h"
#include "support_num.h"

#define NMAX 40

/* ---- the two-mass model -------------------------------------------------- */

static const double M1 = 1.3, M2 = 0.7, K1 = 400.0, K2 = 900.0, K3 = 50.0,
                    C1 = 2.0, C2 = 0.5, FG = 3.0, Q1 = 0.3, Q2 = 0.2;

static int tm_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    tp_val v1 = eom_qd(c, 0), v2 = tp_add(r, eom_qd(c, 0), eom_qd(c, 1));
    (void)user;
    *out = tp_add(r, tp_mulc(r, tp_sqr(r, v1), 0.5 * M1),
                  tp_mulc(r, tp_sqr(r, v2), 0.5 * M2));
    return 0;
}

static int tm_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    tp_val x1 = eom_q(c, 0), x2 = eom_q(c, 1);
    (void)user;
    *out = tp_add(r,
                  tp_add(r, tp_mulc(r, tp_sqr(r, x1), 0.5 * K1),
                         tp_mulc(r, tp_sqr(r, x2), 0.5 * K2)),
                  tp_add(r, tp_mulc(r, tp_powi(r, x2, 4), 0.25 * K3),
                         tp_mulc(r, x1, FG)));
    return 0;
}

static int tm_R(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    tp_val x1 = eom_q(c, 0);
    (void)user;
    *out = tp_add(r,
                  tp_mul(r, tp_mulc(r, tp_addc(r, tp_sqr(r, x1), 1.0),
                                    0.5 * C1),
                         tp_sqr(r, eom_qd(c, 0))),
                  tp_mulc(r, tp_sqr(r, eom_qd(c, 1)), 0.5 * C2));
    return 0;
}

static int tm_Q(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    (void)user;
    out[0] = tp_mulc(r, eom_qd(c, 1), Q1);
    out[1] = tp_mulc(r, eom_q(c, 0), -Q2);
    return 0;
}

static eom_system *two_mass(void)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    char msg[256];
    CHECK_INT(eom_model_new(&md), EOM_OK);
    eom_model_add_coord(md, "x1", "m", 0.1, 0.0);
    eom_model_add_coord(md, "x2", "m", -0.05, 0.3);
    eom_model_set_kinetic(md, tm_T, NULL);
    eom_model_set_potential(md, tm_V, NULL);
    eom_model_set_dissipation(md, tm_R, NULL);
    eom_model_set_forces(md, tm_Q, NULL);
    if (eom_system_new(&s, md, msg, sizeof msg) != EOM_OK)
        CHECK_FAIL_("two-mass model: %s", msg);
    eom_model_free(&md);
    return s;
}

/* The system of *md, which is freed and set to NULL; NULL, with a failed
 * check, when it cannot be made. */
static eom_system *system_of(eom_model **md)
{
    eom_system *s = NULL;
    char msg[256];
    CHECK_INT(eom_system_new(&s, *md, msg, sizeof msg), EOM_OK);
    eom_model_free(md);
    return s;
}

/* M^-1 b for M = [[M1 + M2, M2], [M2, M2]] */
static void tm_solve(const double *b, double *a)
{
    const double det = (M1 + M2) * M2 - M2 * M2;
    a[0] = (M2 * b[0] - M2 * b[1]) / det;
    a[1] = (-M2 * b[0] + (M1 + M2) * b[1]) / det;
}

/* a deterministic pseudo-random number in [-1, 1) */
static double rnd(unsigned *state)
{
    *state = *state * 1664525u + 1013904223u;
    return (double)(*state >> 8) / 8388608.0 - 1.0;
}

/* An imex integrator on s from x (2n) (NULL when it cannot be made). */
static eom_integ *imex_on(eom_system *s, const double *x)
{
    eom_integ *it = NULL;
    eom_opts o;
    eom_opts_default(&o);
    o.method = EOM_IMEX;
    o.rtol = o.atol = 1e-8;
    if (eom_integ_new(&it, s, &o, 0.0, x) != EOM_OK)
        CHECK_FAIL_("imex: %s", eom_system_errmsg(s));
    return it;
}

/* f_E + f_I against the right-hand side and -P at (t, x); the largest
 * difference relative to max(1, |f|) */
static double sum_error(eom_integ *it, eom_system *s, double t,
                        const double *x, double *fe, double *fi)
{
    const int n = eom_system_ncoords(s);
    double y[2 * NMAX + 1], xd[2 * NMAX], worst = 0.0;
    eom_energy e;
    int i;
    memcpy(y, x, 2 * (size_t)n * sizeof(double));
    y[2 * n] = 0.25;
    CHECK_INT(eom__imex_split(it, t, y, fe, fi), EOM_OK);
    CHECK_INT(eom_rhs(s, t, x, xd), EOM_OK);
    CHECK_INT(eom_energy_at(s, t, x, &e), EOM_OK);
    for (i = 0; i <= 2 * n; i++) {
        const double f = i < 2 * n ? xd[i] : -e.P;
        worst = fmax(worst, fabs(fe[i] + fi[i] - f) / fmax(1.0, fabs(f)));
    }
    return worst;
}

static void split_two_mass(void)
{
    eom_system *s = two_mass();
    eom_integ *it;
    double x[4] = {0.1, -0.05, 0.0, 0.3}, fe[5], fi[5], worst = 0.0;
    double hand = 0.0;
    unsigned seed = 12345u;
    int k, i;
    if (!s)
        return;
    if (!(it = imex_on(s, x))) {
        eom_system_free(&s);
        return;
    }
    for (k = 0; k < 50; k++) {
        double b[2], aI[2], aE[2], P;
        const double t = 3.0 * rnd(&seed);
        for (i = 0; i < 4; i++)
            x[i] = (i < 2 ? 0.5 : 3.0) * rnd(&seed);
        worst = fmax(worst, sum_error(it, s, t, x, fe, fi));
        /* by hand: the elastic and dissipative forces, implicit */
        b[0] = -(K1 * x[0] + FG) - C1 * (1.0 + x[0] * x[0]) * x[2];
        b[1] = -(K2 * x[1] + K3 * x[1] * x[1] * x[1]) - C2 * x[3];
        tm_solve(b, aI);
        /* the force Q, explicit; T has no q: no inertial terms */
        b[0] = Q1 * x[3];
        b[1] = -Q2 * x[0];
        tm_solve(b, aE);
        P = x[2] * (-C1 * (1.0 + x[0] * x[0]) * x[2] + Q1 * x[3]) +
            x[3] * (-C2 * x[3] - Q2 * x[0]);
        for (i = 0; i < 2; i++) {
            /* relative to the larger acceleration: M^-1 mixes them, and
             * f_E = f - f_I carries f's rounding */
            const double sc = fmax(1.0, fmax(fabs(aI[0]), fabs(aI[1])));
            hand = fmax(hand, fabs(fi[i] - x[2 + i]) + fabs(fe[i]));
            hand = fmax(hand, fabs(fi[2 + i] - aI[i]) / sc);
            hand = fmax(hand, fabs(fe[2 + i] - aE[i]) / sc);
        }
        hand = fmax(hand, fabs(fi[4]) + fabs(fe[4] + P) / fmax(1.0, fabs(P)));
    }
    printf("two-mass: f_E + f_I against f %.3g, against the hand split "
           "%.3g (50 random states)\n", worst, hand);
    CHECK(worst <= 1e-14);
    CHECK(hand <= 1e-14);

    /* the Newton matrix's Jacobian: exact here (M constant) */
    {
        double y[5], J[25], yp[5], ym[5], fep[5], fem[5], fip[5], fim[5];
        double jerr = 0.0;
        int j;
        for (k = 0; k < 5; k++) {
            for (i = 0; i < 4; i++)
                y[i] = (i < 2 ? 0.5 : 3.0) * rnd(&seed);
            y[4] = 0.0;
            CHECK_INT(eom__imex_jacobian(it, 0.5, y, J), EOM_OK);
            for (j = 0; j < 5; j++) {
                const double h = 1e-5;
                memcpy(yp, y, sizeof y);
                memcpy(ym, y, sizeof y);
                yp[j] += h;
                ym[j] -= h;
                CHECK_INT(eom__imex_split(it, 0.5, yp, fep, fip), EOM_OK);
                CHECK_INT(eom__imex_split(it, 0.5, ym, fem, fim), EOM_OK);
                for (i = 0; i < 5; i++) {
                    const double dq = (fip[i] - fim[i]) / (2.0 * h);
                    jerr = fmax(jerr, fabs(J[j * 5 + i] - dq) /
                                          fmax(1.0, fabs(dq)));
                }
            }
        }
        printf("two-mass: Jacobian of f_I against differences %.3g\n", jerr);
        CHECK(jerr <= 1e-7);
    }
    eom_integ_free(&it);
    eom_system_free(&s);
}

static void split_spring_and_fourbar(void)
{
    eom_model *md = eom_models_spring_pendulum(1.0, 75.0, 1.0, 9.81);
    eom_system *s = NULL;
    eom_integ *it;
    double x[2 * NMAX], fe[2 * NMAX + 1], fi[2 * NMAX + 1], worst = 0.0;
    double hand = 0.0;
    unsigned seed = 777u;
    int k, i;
    s = system_of(&md);
    if (!s)
        return;
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    if ((it = imex_on(s, x))) {
        for (k = 0; k < 50; k++) {
            double r, th, aI[2];
            x[0] = 1.0 + 0.5 * rnd(&seed);
            for (i = 1; i < 4; i++)
                x[i] = 2.0 * rnd(&seed);
            worst = fmax(worst, sum_error(it, s, 0.0, x, fe, fi));
            r = x[0];
            th = x[1];
            /* M = diag(m, m r^2): -dV/dq over it */
            aI[0] = -75.0 * (r - 1.0) + 9.81 * cos(th);
            aI[1] = -9.81 * sin(th) / r;
            for (i = 0; i < 2; i++)
                hand = fmax(hand, fabs(fi[2 + i] - aI[i]) /
                                      fmax(1.0, fabs(aI[i])));
            /* the centrifugal and Coriolis terms, explicit */
            hand = fmax(hand, fabs(fe[2] - r * x[3] * x[3]) /
                                  fmax(1.0, r * x[3] * x[3]));
            hand = fmax(hand, fabs(fe[3] + 2.0 * x[2] * x[3] / r) /
                                  fmax(1.0, fabs(2.0 * x[2] * x[3] / r)));
        }
        eom_integ_free(&it);
    }
    printf("spring pendulum: f_E + f_I against f %.3g, against the hand "
           "split %.3g\n", worst, hand);
    CHECK(worst <= 1e-14);
    CHECK(hand <= 1e-14);
    eom_system_free(&s);

    /* a four-bar: three rods closed at (D, 0) */
    {
        const double m[3] = {1.0, 2.0, 1.5}, l[3] = {1.0, 2.0, 1.5};
        const double th0[3] = {1.2, 0.1, -1.4};
        double C[2 * 3], phi[2], xd[6], lam[2], cI, cE, gam;
        double cworst = 0.0;
        int j;
        worst = 0.0;
        md = eom_models_rod_chain(3, m, l, th0, 9.81, 1, 0.0);
        CHECK(md != NULL);
        s = system_of(&md);
        if (!s)
            return;
        CHECK_INT(eom_initial_state(s, x), EOM_OK);
        CHECK_INT(eom_project_start(s, x, 1e-13, NULL), EOM_OK);
        if ((it = imex_on(s, x))) {
            for (k = 0; k < 20; k++) {
                double xs[6];
                memcpy(xs, x, sizeof xs);
                for (i = 0; i < 6; i++)
                    xs[i] += (i < 3 ? 0.2 : 2.0) * rnd(&seed);
                CHECK_INT(eom_project(s, xs, 1e-13, NULL), EOM_OK);
                worst = fmax(worst, sum_error(it, s, 0.0, xs, fe, fi));
                CHECK_INT(eom_rhs(s, 0.0, xs, xd), EOM_OK);
                CHECK_INT(eom_multipliers(s, 0.0, xs, lam), EOM_OK);
                CHECK_INT(eom_constraint_jacobian(s, xs, C, phi), EOM_OK);
                for (j = 0; j < 2; j++) {
                    cI = cE = gam = 0.0;
                    for (i = 0; i < 3; i++) {
                        cI += C[j * 3 + i] * fi[3 + i];
                        cE += C[j * 3 + i] * fe[3 + i];
                        gam += C[j * 3 + i] * xd[3 + i];
                    }
                    /* the implicit accelerations keep C a = 0; the
                     * explicit ones carry gamma (C qdd) */
                    cworst = fmax(cworst, fabs(cI) + fabs(cE - gam));
                }
            }
            eom_integ_free(&it);
        }
        printf("four-bar: f_E + f_I against f %.3g; |C a_I| + |C a_E - "
               "gamma| %.3g\n", worst, cworst);
        CHECK(worst <= 1e-14);
        CHECK(cworst <= 1e-12);
        eom_system_free(&s);
    }
}

/* ---- runs ------------------------------------------------------------------ */

/* The start of the runs: the model's initial state, or this (2n). */
static const double *start;

/* The state at t_end by method m at rtol = atol = tol (per step as given
 * with per_step), from the start; steps and the last W in *steps, *W
 * (either may be NULL). */
static int run(eom_system *s, eom_method m, double tol, int per_step,
               double t_end, double *x, long *steps, double *W)
{
    eom_integ *it = NULL;
    eom_opts o;
    eom_stats st;
    int rc;
    eom_opts_default(&o);
    o.method = m;
    o.dt = 0.0;
    o.rtol = o.atol = tol;
    o.tol_per_step = per_step;
    o.proj_tol = 1e-13;
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    if (start)
        memcpy(x, start, 2 * (size_t)eom_system_ncoords(s) * sizeof *x);
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    if (rc == EOM_OK)
        rc = eom_integ_advance(it, t_end, x, W);
    if (rc == EOM_OK && eom_integ_stats(it, &st) == EOM_OK && steps)
        *steps = st.steps;
    if (rc != EOM_OK)
        fprintf(stderr, "%s: %s\n", eom_method_name(m),
                it ? eom_integ_errmsg(it) : eom_system_errmsg(s));
    eom_integ_free(&it);
    return rc;
}

/* error against steps of imex over rtol = atol = 10^-top .. 10^-(top+4) */
static double order_on(eom_system *s, const double *ref, int top,
                       const char *what)
{
    double x[4], err[5], steps[5], p;
    long st = 0;
    int i;
    for (i = 0; i < 5; i++) {
        const double tol = pow(10.0, -top - i);
        CHECK_INT(run(s, EOM_IMEX, tol, 0, 10.0, x, &st, NULL), EOM_OK);
        steps[i] = (double)st;
        err[i] = hand_max_diff(4, x, ref);
        printf("%s: imex tol %-6g steps %6ld error %.3g (%.3g x tol)\n",
               what, tol, st, err[i], err[i] / tol);
    }
    p = -num_loglog_slope(5, steps, err);
    printf("%s: imex observed order %.2f (nominal 5)\n", what, p);
    return p;
}

static void order(void)
{
    eom_model *md = eom_models_spring_pendulum(1.0, 75.0, 1.0, 9.81);
    eom_system *s = NULL;
    double ref[4] = {1.1, 0.5, 0.0, 0.0}, ref2[4], p;
    long st;
    s = system_of(&md);
    if (!s)
        return;
    /* the model's start: r = r0 + 0.1, theta = 0.5, at rest */
    CHECK_INT(eom_initial_state(s, ref), EOM_OK);
    memcpy(ref2, ref, sizeof ref);
    hand_rk4(hand_spring, 10.0, 400000, ref);
    hand_rk4(hand_spring, 10.0, 200000, ref2);
    CHECK(hand_max_diff(4, ref, ref2) < 1e-12);
    /* its errors are 1e-3 to 1e-2 of the tolerance: from 1e-4, so that
     * the last stays above the reference's rounding */
    p = order_on(s, ref, 4, "spring pendulum k 75");
    CHECK(p > 4.5 && p < 6.0);
    {
        /* ARKODE's difference quotient of f_I instead of its stiff terms:
         * the same solution to the tolerance */
        eom_integ *it = NULL;
        eom_opts o;
        eom_stats st2;
        double x[4];
        eom_opts_default(&o);
        o.method = EOM_IMEX;
        o.dt = 0.0;
        o.rtol = o.atol = 1e-8;
        o.dq_jacobian = 1;
        CHECK_INT(eom_initial_state(s, x), EOM_OK);
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
        if (it) {
            CHECK_INT(eom_integ_advance(it, 10.0, x, NULL), EOM_OK);
            CHECK_INT(eom_integ_stats(it, &st2), EOM_OK);
            printf("spring pendulum k 75: imex with difference quotients "
                   "at 1e-8: %ld steps, %ld Jacobians, error %.3g\n",
                   st2.steps, st2.jac_evals, hand_max_diff(4, x, ref));
            CHECK(hand_max_diff(4, x, ref) < 1e-6);
            CHECK(st2.jac_evals > 0);
        }
        eom_integ_free(&it);
    }

    /* a spring 100 times stiffer (10 times the frequency) */
    CHECK_INT(eom_set_param(s, eom_param_index(s, "k"), 7500.0), EOM_OK);
    CHECK_INT(run(s, EOM_ERK, 1e-13, 1, 10.0, ref, &st, NULL), EOM_OK);
    CHECK_INT(run(s, EOM_ERK, 1e-12, 1, 10.0, ref2, &st, NULL), EOM_OK);
    printf("stiff spring: erk references at 1e-12 and 1e-13 differ by "
           "%.3g\n", hand_max_diff(4, ref, ref2));
    /* the two differ by rounding carried through 10 s of stiff motion,
     * not by their tolerances: 3.6e-10 here, and 1.1e-9 to 3.8e-9 with
     * h summed in another order and k changed by 1e-15 relative,
     * against the errors of 8e-9 and more that the order below is
     * measured from (the fixed steps: 1.2e-6 and more) */
    CHECK(hand_max_diff(4, ref, ref2) < 1e-8);
    p = order_on(s, ref, 6, "spring pendulum k 7500");
    CHECK(p > 4.5 && p < 6.0);
    {
        /* fixed steps h = 1/100 .. 1/800 s over 1 s (omega h = 0.87 ..
         * 0.11 for the spring's 87 rad/s): the error against halving h */
        double x[4], r1[4], err[4], hs[4];
        eom_integ *it = NULL;
        eom_opts o;
        eom_stats sf;
        int i;
        CHECK_INT(run(s, EOM_ERK, 1e-13, 1, 1.0, r1, &st, NULL), EOM_OK);
        eom_opts_default(&o);
        o.method = EOM_IMEX;
        o.rtol = o.atol = 1e-6; /* the Newton iterations' tolerance */
        for (i = 0; i < 4; i++) {
            hs[i] = 1.0 / (100 << i);
            CHECK_INT(eom_initial_state(s, x), EOM_OK);
            CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
            if (!it)
                break;
            CHECK_INT(eom__imex_fixed_step(it, hs[i]), EOM_OK);
            CHECK_INT(eom_integ_advance(it, 1.0, x, NULL), EOM_OK);
            CHECK_INT(eom_integ_stats(it, &sf), EOM_OK);
            CHECK_INT(sf.steps, 100 << i);
            eom_integ_free(&it);
            err[i] = hand_max_diff(4, x, r1);
            printf("spring pendulum k 7500: imex fixed h 1/%d error %.3g\n",
                   100 << i, err[i]);
        }
        p = num_loglog_slope(4, hs, err);
        printf("spring pendulum k 7500: imex order with fixed steps %.2f "
               "(nominal 5)\n", p);
        CHECK(p > 4.5 && p < 6.0);
    }
    eom_system_free(&s);
}

/* A pendulum on a spring of k = 1e8 with a damper on its length: the
 * implicit part must carry the fast mode. */
static void stiff(void)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    double x[4], xe[4], xr[4];
    long si = 0, se = 0, sr = 0;
    char msg[256];
    if (eom_model_from_string(
            &md,
            "param m = 1 [kg]\nparam k = 1e8 [N/m]\n"
            "param c = 2e3 [N s/m]\nparam r0 = 1 [m]\n"
            "param g = 9.81 [m/s^2]\n"
            "coord r = 1.001 [m]\ncoord th = 0.5 [rad]\n"
            "T = 1/2*m*(r_dot^2 + r^2*th_dot^2)\n"
            "V = 1/2*k*(r - r0)^2 + m*g*(r0 - r*cos(th))\n"
            "R = 1/2*c*r_dot^2\n", msg, sizeof msg) != EOM_OK) {
        CHECK_FAIL_("stiff spring model: %s", msg);
        return;
    }
    s = system_of(&md);
    if (!s)
        return;
    CHECK_INT(run(s, EOM_ERK, 1e-12, 1, 2.0, xr, &sr, NULL), EOM_OK);
    /* at 1e-3: at tight tolerances imex's steps grow as for an order of
     * about 2 here (docs/integrators.md, "imex") */
    CHECK_INT(run(s, EOM_IMEX, 1e-3, 0, 2.0, x, &si, NULL), EOM_OK);
    CHECK_INT(run(s, EOM_ERK, 1e-3, 0, 2.0, xe, &se, NULL), EOM_OK);
    printf("stiff spring (1e4 rad/s, damped): imex %ld steps, error %.3g; "
           "erk %ld steps, error %.3g\n", si, hand_max_diff(4, x, xr), se,
           hand_max_diff(4, xe, xr));
    CHECK(hand_max_diff(4, x, xr) < 1e-3);
    CHECK(10 * si < se);
    eom_system_free(&s);
}

/* imex against erk at a per-step 1e-13 on one model, and E + W */
static void agree(const char *name, eom_system *s)
{
    const int n = eom_system_ncoords(s);
    const double tol = 1e-9, t_end = 5.0;
    double x[2 * NMAX], ref[2 * NMAX], x0[2 * NMAX], W = 0.0, err;
    eom_energy e0, e1;
    long st = 0;
    if (2 * n > 2 * NMAX) {
        CHECK_FAIL_("%s: too many coordinates", name);
        return;
    }
    CHECK_INT(run(s, EOM_ERK, 1e-13, 1, t_end, ref, NULL, NULL), EOM_OK);
    CHECK_INT(run(s, EOM_IMEX, tol, 0, t_end, x, &st, &W), EOM_OK);
    err = hand_max_diff(2 * n, x, ref);
    CHECK_INT(eom_initial_state(s, x0), EOM_OK);
    if (start)
        memcpy(x0, start, 2 * (size_t)n * sizeof *x0);
    CHECK_INT(eom_energy_at(s, 0.0, x0, &e0), EOM_OK);
    CHECK_INT(eom_energy_at(s, t_end, x, &e1), EOM_OK);
    printf("%-16s imex at %g: %6ld steps, error %.3g (%.3g x tol); "
           "|E + W - E0| %.3g (W %.3g)\n", name, tol, st, err, err / tol,
           fabs(e1.E + W - e0.E), W);
    check_count_++;
    if (!(err <= 100.0 * tol))
        CHECK_FAIL_("%s: imex error %.3g is %.3g x tol", name, err,
                    err / tol);
    check_count_++;
    if (!(fabs(e1.E + W - e0.E) <= 1e-7 * fmax(1.0, fabs(e0.E))))
        CHECK_FAIL_("%s: E + W changed by %.3g", name,
                    fabs(e1.E + W - e0.E));
}

static void shipped(const char *dir)
{
    static const char *const names[] = {
        "spring-pendulum", "double-pendulum", "cart-pole", "four-bar",
        "driven-crank",    "open-chain",      "closed-chain"};
    size_t k;
    for (k = 0; k < sizeof names / sizeof names[0]; k++) {
        char path[1024], msg[512];
        eom_model *md = NULL;
        eom_system *s = NULL;
        snprintf(path, sizeof path, "%s/%s.eom", dir, names[k]);
        if (eom_model_from_file(&md, path, msg, sizeof msg) != EOM_OK) {
            CHECK_FAIL_("%s: %s", path, msg);
            continue;
        }
        if (eom_system_new(&s, md, msg, sizeof msg) != EOM_OK)
            CHECK_FAIL_("%s: %s", path, msg);
        eom_model_free(&md);
        if (s)
            agree(names[k], s);
        eom_system_free(&s);
    }
    {
        const double m[3] = {1.0, 2.0, 1.5}, l[3] = {1.0, 2.0, 1.5};
        const double th0[3] = {1.2, 0.1, -1.4};
        eom_model *md = eom_models_rod_chain(3, m, l, th0, 9.81, 1, 0.0);
        eom_system *s = NULL;
        double x[6];
        /* the start on the constraints: the rods' angles as given are
         * not, so the run starts from the projected state */
        s = system_of(&md);
        if (s) {
            CHECK_INT(eom_initial_state(s, x), EOM_OK);
            CHECK_INT(eom_project_start(s, x, 1e-13, NULL), EOM_OK);
            start = x;
            agree("C four-bar", s);
            start = NULL;
        }
        eom_system_free(&s);
        md = eom_models_bead_on_circle(1.0, 1.0, 9.81);
        s = system_of(&md);
        if (s) {
            /* on the circle at 0.7 rad from the bottom, moving along it */
            x[0] = sin(0.7);
            x[1] = -cos(0.7);
            x[2] = 1.5 * cos(0.7);
            x[3] = 1.5 * sin(0.7);
            start = x;
            agree("C bead", s);
            start = NULL;
        }
        eom_system_free(&s);
    }
}

/* ---- refusals ----------------------------------------------------------- */

static int lag_L(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    (void)user;
    *out = tp_sub(r, tp_mulc(r, tp_sqr(r, eom_qd(c, 0)), 0.5),
                  tp_mulc(r, tp_sqr(r, eom_q(c, 0)), 50.0));
    return 0;
}

/* V = sqrt(x): the particle falls towards x = 0, where the force
 * -1 / (2 sqrt(x)) is infinite and beyond which V is not defined */
static int fall_T(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_mulc(eom_rec(c), tp_sqr(eom_rec(c), eom_qd(c, 0)), 0.5);
    return 0;
}

static int fall_V(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_mulc(eom_rec(c), tp_sqrt(eom_rec(c), eom_q(c, 0)), 1.0);
    return 0;
}

/* A run into a domain error fails with a message naming imex, keeps the
 * last good state, and stays failed. */
static void failure(void)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    eom_integ *it = NULL;
    eom_opts o;
    double x[2] = {1.0, -1.0}, W = 0.0;
    int rc = EOM_OK, k, rc2;
    CHECK_INT(eom_model_new(&md), EOM_OK);
    eom_model_add_coord(md, "x", "m", 1.0, -1.0);
    eom_model_set_kinetic(md, fall_T, NULL);
    eom_model_set_potential(md, fall_V, NULL);
    s = system_of(&md);
    if (!s)
        return;
    eom_opts_default(&o);
    o.method = EOM_IMEX;
    o.rtol = o.atol = 1e-8;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    for (k = 1; k <= 20 && it && rc == EOM_OK; k++)
        rc = eom_integ_advance(it, 0.1 * k, x, &W);
    if (!it)
        return;
    printf("into a domain error: %s: %s\n", eom_status_name(rc),
           eom_integ_errmsg(it));
    CHECK(rc < 0);
    CHECK(strncmp(eom_integ_errmsg(it), "imex: ", 6) == 0);
    CHECK(isfinite(x[0]) && isfinite(x[1]) && x[0] > 0.0);
    rc2 = eom_integ_advance(it, 10.0, x, &W);
    CHECK_INT(rc2, rc);
    eom_integ_free(&it);
    eom_system_free(&s);
}

static void refusals(void)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    eom_integ *it = NULL;
    eom_opts o;
    double x[2] = {1.0, 0.0};
    int sens[1] = {0};
    CHECK_INT(eom_method_from_name("imex"), EOM_IMEX);
    CHECK(strcmp(eom_method_name(EOM_IMEX), "imex") == 0);
    /* the values before it are unchanged */
    CHECK_INT(EOM_ESDIRK, 5);
    CHECK_INT(EOM_IMEX, 6);
    CHECK_INT(eom_model_new(&md), EOM_OK);
    eom_model_add_coord(md, "x", "m", 1.0, 0.0);
    eom_model_set_lagrangian(md, lag_L, NULL);
    s = system_of(&md);
    if (!s)
        return;
    eom_opts_default(&o);
    o.method = EOM_IMEX;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_MODEL);
    CHECK(it == NULL);
    printf("refused: %s\n", eom_system_errmsg(s));
    CHECK(strstr(eom_system_errmsg(s), "imex: ") != NULL);
    CHECK(strstr(eom_system_errmsg(s), "whole Lagrangian") != NULL);
    CHECK(strstr(eom_system_errmsg(s), "use esdirk or bdf") != NULL);
    /* esdirk takes it */
    o.method = EOM_ESDIRK;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    eom_integ_free(&it);
    eom_system_free(&s);

    md = eom_models_spring_pendulum(1.0, 75.0, 1.0, 9.81);
    s = system_of(&md);
    if (!s)
        return;
    {
        double xs[4];
        CHECK_INT(eom_initial_state(s, xs), EOM_OK);
        o.method = EOM_IMEX;
        o.n_sens = 1;
        o.sens = sens;
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, xs), EOM_ERR_ARG);
        CHECK(strstr(eom_system_errmsg(s), "adams and bdf") != NULL);
        /* and the white-box calls refuse another method */
        o.n_sens = 0;
        o.sens = NULL;
        o.method = EOM_ESDIRK;
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, xs), EOM_OK);
        if (it) {
            double fe[5], fi[5], y[5] = {1.0, 0.1, 0.0, 0.0, 0.0};
            CHECK_INT(eom__imex_split(it, 0.0, y, fe, fi), EOM_ERR_ARG);
        }
        eom_integ_free(&it);
    }
    eom_system_free(&s);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s MODELS_DIR\n", argv[0]);
        return 2;
    }
    split_two_mass();
    split_spring_and_fourbar();
    refusals();
    failure();
    order();
    stiff();
    shipped(argv[1]);
    CHECK_DONE();
}
