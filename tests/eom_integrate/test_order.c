/* test_order.c - integrators checked by their order and their tolerance,
 * on the spring pendulum (no constraints) over 10 s, against a reference
 * computed here from the equations derived by hand,
 *     r''  = r th'^2 - (k / m) (r - r0) + g cos th,
 *     th'' = -(2 r' th' + g sin th) / r,
 * by classical RK4 at h and h/2 (their difference bounds its error).
 *
 *   - rk4: the observed order over dt = 1e-2 .. 2.5e-3 (nominal 4);
 *   - erk: the observed order from error against steps over rtol = atol =
 *     1e-6 .. 1e-10 (nominal 6, the Verner 6(5) pair): fails more than
 *     0.5 below it (an effective order of 3 is what a table reusing its
 *     last stage as if first-same-as-last gives);
 *   - erk: the global error stays within 100 times rtol = atol from 1e-6
 *     to 1e-12.
 *   - every adaptive method honours rtol and atol as given, each for its
 *     part: a harmonic oscillator of amplitude 1e4, x = A cos(w t), run
 *     with (rtol, atol) = (1e-12, 1e-3), where atol governs, and swapped,
 *     where rtol does and allows errors of order A rtol = 10: the first
 *     must be far more accurate than the second (a swap in the solver
 *     setup turns that around).
 *   - erk with another table by name (Dormand-Prince 5(4)): its order;
 *     an unknown name is an error naming it;
 *   - per-coordinate absolute tolerances (atol_vec): equal entries give
 *     the scalar atol's run bit for bit, loose ones a looser result (a
 *     loose entry for the rate alone too: the rates get their own
 *     entries, not the scalar atol), a bad entry an error.
 * adams, bdf and ida (order at each highest order, and the global error
 * against the tolerance on three models) are test_tolerance.c's.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom_models.h"
#include "hand_ref.h"
#include "support_num.h"

/* the spring pendulum of hand_ref.h */
static const double M_ = 1.0, K_ = 75.0, R0_ = 1.0, G_ = 9.81, T_END = 10.0;

static double max_diff(const double *a, const double *b)
{
    return hand_max_diff(4, a, b);
}

/* the state at T_END by method m; steps taken in *steps */
static int run(eom_system *s, eom_method m, double dt, double tol, double *x,
               long *steps)
{
    eom_integ *it = NULL;
    eom_opts o;
    eom_stats st;
    int rc;
    eom_opts_default(&o);
    o.method = m;
    o.dt = dt;
    o.rtol = o.atol = tol;
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    if (rc == EOM_OK)
        rc = eom_integ_advance(it, T_END, x, NULL);
    if (rc == EOM_OK && eom_integ_stats(it, &st) == EOM_OK)
        *steps = st.steps;
    if (rc != EOM_OK)
        fprintf(stderr, "%s: %s\n", eom_method_name(m), eom_integ_errmsg(it));
    eom_integ_free(&it);
    return rc;
}

/* ---- the oscillator: T = xd^2 / 2, V = w^2 x^2 / 2 ------------------------ */

static const double OSC_A = 1e4, OSC_W = 6.283185307179586;

static int osc_T(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_mulc(eom_rec(c), tp_sqr(eom_rec(c), eom_qd(c, 0)), 0.5);
    return 0;
}

static int osc_V(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_mulc(eom_rec(c), tp_sqr(eom_rec(c), eom_q(c, 0)),
                   0.5 * OSC_W * OSC_W);
    return 0;
}

/* max |x - A cos(w t)| at t = 1, 2, .. 10 by method m, with atol_vec
 * when av is not NULL; the final state in xf (may be NULL) */
static double osc_run(eom_system *s, eom_method m, double rtol, double atol,
                      const double *av, double *xf)
{
    eom_integ *it = NULL;
    eom_opts o;
    double x[2] = {OSC_A, 0.0}, err = 0.0;
    int k, rc;
    eom_opts_default(&o);
    o.method = m;
    o.dt = 0.0;
    o.rtol = rtol;
    o.atol = atol;
    o.atol_vec = av;
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    for (k = 1; k <= 10 && rc == EOM_OK; k++) {
        rc = eom_integ_advance(it, (double)k, x, NULL);
        err = fmax(err, fabs(x[0] - OSC_A * cos(OSC_W * k)));
    }
    CHECK_INT(rc, EOM_OK);
    if (xf) {
        xf[0] = x[0];
        xf[1] = x[1];
    }
    eom_integ_free(&it);
    return err;
}

static double osc_error(eom_system *s, eom_method m, double rtol,
                        double atol)
{
    return osc_run(s, m, rtol, atol, NULL, NULL);
}

static void tolerances(void)
{
    static const eom_method adaptive[] = {EOM_ERK, EOM_ADAMS, EOM_BDF,
                                          EOM_IDA, EOM_ESDIRK};
    eom_model *md = NULL;
    eom_system *s = NULL;
    char msg[256];
    int i;
    CHECK_INT(eom_model_new(&md), EOM_OK);
    eom_model_add_coord(md, "x", "m", OSC_A, 0.0);
    eom_model_set_kinetic(md, osc_T, NULL);
    eom_model_set_potential(md, osc_V, NULL);
    CHECK_INT(eom_system_new(&s, md, msg, sizeof msg), EOM_OK);
    eom_model_free(&md);
    if (!s)
        return;
    for (i = 0; i < 5; i++) {
        const double ea = osc_error(s, adaptive[i], 1e-12, 1e-3);
        const double er = osc_error(s, adaptive[i], 1e-3, 1e-12);
        printf("%-5s: error %.3g with atol 1e-3 governing, %.3g with rtol "
               "1e-3 governing\n", eom_method_name(adaptive[i]), ea, er);
        check_count_++;
        if (!(ea < 1.0 && er > 5.0 * ea))
            CHECK_FAIL_("%s: rtol and atol not honoured as given (errors "
                        "%.3g and %.3g)", eom_method_name(adaptive[i]), ea,
                        er);
    }
    /* atol_vec: equal to atol everywhere is the scalar run; loose for x
     * and its rate is a looser run than tight */
    for (i = 0; i < 5; i++) {
        const double same[2] = {1e-3, 1e-3}, loose[2] = {1e-1, 1e-1};
        const double tight[2] = {1e-5, 1e-5}, rate_loose[2] = {1e-5, 1e-1};
        double xs[2], xv[2], el, et;
        osc_run(s, adaptive[i], 1e-12, 1e-3, NULL, xs);
        osc_run(s, adaptive[i], 1e-12, 1e-3, same, xv);
        CHECK(xs[0] == xv[0] && xs[1] == xv[1]);
        el = osc_run(s, adaptive[i], 1e-12, 1e-3, loose, NULL);
        et = osc_run(s, adaptive[i], 1e-12, 1e-3, tight, NULL);
        printf("%-5s: error %.3g with atol_vec 1e-1, %.3g with 1e-5\n",
               eom_method_name(adaptive[i]), el, et);
        CHECK(el > 10.0 * et);
        /* the rate's own entry counts, not the scalar atol: loose for
         * the rate alone, the scalar tight */
        el = osc_run(s, adaptive[i], 1e-12, 1e-5, rate_loose, NULL);
        printf("%-5s: error %.3g with the rate's atol 1e-1 (the "
               "coordinate's and the scalar 1e-5)\n",
               eom_method_name(adaptive[i]), el);
        CHECK(el > 3.0 * et); /* 6.5 to 13 times; the scalar's: 1 */
    }
    {
        const double bad[2] = {1e-3, -1.0};
        eom_integ *it = NULL;
        eom_opts o;
        double x[2] = {OSC_A, 0.0};
        eom_opts_default(&o);
        o.method = EOM_BDF;
        o.atol_vec = bad;
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
        CHECK(strstr(eom_system_errmsg(s), "atol_vec[1]") != NULL);
        CHECK(it == NULL);
    }
    eom_system_free(&s);
}

int main(void)
{
    eom_system *s = NULL;
    eom_model *md = eom_models_spring_pendulum(M_, K_, R0_, G_);
    double ref[4] = {R0_ + 0.1, 0.5, 0.0, 0.0}, ref2[4], x[4];
    double err[8], xs[8], p, verner_steps;
    char msg[256];
    long steps = 0;
    int i;

    /* the reference, and a bound on its own error */
    for (i = 0; i < 4; i++)
        ref2[i] = ref[i];
    hand_rk4(hand_spring, T_END, 400000, ref);
    hand_rk4(hand_spring, T_END, 800000, ref2);
    printf("reference: h and h/2 differ by %.3g\n", max_diff(ref, ref2));
    CHECK(max_diff(ref, ref2) < 1e-12);

    CHECK_INT(eom_system_new(&s, md, msg, sizeof msg), EOM_OK);
    eom_model_free(&md);
    if (!s)
        CHECK_DONE();

    /* rk4: dt = 1e-2, 5e-3, 2.5e-3 */
    for (i = 0; i < 3; i++) {
        const double dt = 1e-2 / (1 << i);
        CHECK_INT(run(s, EOM_RK4, dt, 1e-8, x, &steps), EOM_OK);
        xs[i] = dt;
        err[i] = max_diff(x, ref2);
        printf("rk4 dt %-8g error %.3g\n", dt, err[i]);
    }
    p = num_loglog_slope(3, xs, err);
    printf("rk4: observed order %.2f (nominal 4)\n", p);
    CHECK(p > 3.5 && p < 4.5);

    /* erk: error against steps */
    for (i = 0; i < 5; i++) {
        const double tol = pow(10.0, -6 - i);
        CHECK_INT(run(s, EOM_ERK, 0.0, tol, x, &steps), EOM_OK);
        xs[i] = (double)steps;
        err[i] = max_diff(x, ref2);
        printf("erk tol %-6g steps %6ld error %.3g (%.3g x tol)\n", tol,
               steps, err[i], err[i] / tol);
    }
    p = -num_loglog_slope(5, xs, err);
    printf("erk: observed order %.2f (nominal 6)\n", p);
    CHECK(p > 5.5);
    verner_steps = xs[4];

    /* esdirk: error against steps (nominal 5, the ARK5(4)8L[2]SA DIRK) */
    for (i = 0; i < 5; i++) {
        const double tol = pow(10.0, -6 - i);
        CHECK_INT(run(s, EOM_ESDIRK, 0.0, tol, x, &steps), EOM_OK);
        xs[i] = (double)steps;
        err[i] = max_diff(x, ref2);
        printf("esdirk tol %-6g steps %6ld error %.3g (%.3g x tol)\n", tol,
               steps, err[i], err[i] / tol);
    }
    p = -num_loglog_slope(5, xs, err);
    printf("esdirk: observed order %.2f (nominal 5)\n", p);
    CHECK(p > 4.5);

    /* erk: tolerance proportionality down to 1e-12 */
    for (i = 0; i < 4; i++) {
        const double tol = pow(10.0, -6 - 2 * i);
        CHECK_INT(run(s, EOM_ERK, 0.0, tol, x, &steps), EOM_OK);
        check_count_++;
        if (!(max_diff(x, ref2) <= 100.0 * tol))
            CHECK_FAIL_("erk at tol %g: error %.3g is %.3g x tol", tol,
                        max_diff(x, ref2), max_diff(x, ref2) / tol);
    }
    /* erk with the Dormand-Prince 5(4) table, by name */
    for (i = 0; i < 5; i++) {
        const double tol = pow(10.0, -6 - i);
        eom_integ *it = NULL;
        eom_opts o;
        eom_stats st;
        eom_opts_default(&o);
        o.method = EOM_ERK;
        o.dt = 0.0;
        o.rtol = o.atol = tol;
        o.erk_table = "ARKODE_DORMAND_PRINCE_7_4_5";
        CHECK_INT(eom_initial_state(s, x), EOM_OK);
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
        CHECK_INT(eom_integ_advance(it, T_END, x, NULL), EOM_OK);
        CHECK_INT(eom_integ_stats(it, &st), EOM_OK);
        eom_integ_free(&it);
        xs[i] = (double)st.steps;
        err[i] = max_diff(x, ref2);
    }
    p = -num_loglog_slope(5, xs, err);
    printf("erk, Dormand-Prince 5(4): observed order %.2f (nominal 5), "
           "%g steps at 1e-10 against Verner's %g\n", p, xs[4],
           verner_steps);
    CHECK(p > 4.5);
    CHECK(xs[4] > 1.3 * verner_steps); /* the lower order shows */
    /* every name listed is one ARKODE takes, and runs */
    for (i = 0; eom_erk_table_name(i); i++) {
        eom_integ *it = NULL;
        eom_opts o;
        eom_opts_default(&o);
        o.method = EOM_ERK;
        o.erk_table = eom_erk_table_name(i);
        CHECK_INT(eom_initial_state(s, x), EOM_OK);
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
        CHECK_INT(eom_integ_advance(it, 0.5, x, NULL), EOM_OK);
        eom_integ_free(&it);
    }
    CHECK_INT(i, 14);
    {
        eom_integ *it = NULL;
        eom_opts o;
        eom_opts_default(&o);
        o.method = EOM_ERK;
        o.erk_table = "ARKODE_NO_SUCH_TABLE";
        CHECK_INT(eom_initial_state(s, x), EOM_OK);
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
        CHECK(strstr(eom_system_errmsg(s), "ARKODE_NO_SUCH_TABLE") != NULL);
        CHECK(it == NULL);
    }
    {
        /* max_order: within the method's own orders */
        static const eom_method m[] = {EOM_ADAMS, EOM_BDF, EOM_IDA};
        static const int top[] = {12, 5, 5};
        eom_integ *it = NULL;
        eom_opts o;
        eom_opts_default(&o);
        CHECK_INT(eom_initial_state(s, x), EOM_OK);
        for (i = 0; i < 3; i++) {
            o.method = m[i];
            o.max_order = top[i] + 1;
            CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
            CHECK(strstr(eom_system_errmsg(s), "max_order") != NULL);
            o.max_order = -1;
            CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
            o.max_order = top[i];
            CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
            eom_integ_free(&it);
        }
        o.method = EOM_ERK; /* ignored */
        o.max_order = 99;
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
        eom_integ_free(&it);
    }
    eom_system_free(&s);
    tolerances();
    CHECK_DONE();
}
