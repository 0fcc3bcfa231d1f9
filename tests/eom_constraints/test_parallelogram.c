/* test_parallelogram.c - a parallelogram linkage whose crank turns over
 * and over, through the flat position (constraint Jacobian losing rank)
 * twice a revolution, with every integrator, in three formulations:
 *
 *   angles   three cranks (length a, pins at (0,0), (d,0), (2d,0),
 *            absolute angles th1, th2, th3) and one coupler (length 2d,
 *            angle ph) joined to the three crank tips: 4 coordinates, 4
 *            loop-closure equations of rank 3 (one exactly redundant),
 *            rank 2 when flat;
 *   points   two cranks, tips P1 = (x1, y1), P2 = (x2, y2) as coordinates,
 *            |P1| = a, |P2 - (d,0)| = a, |P2 - P1| = d: 4 coordinates, 3
 *            constraints of rank 3, rank 2 when flat.
 *   relative two cranks and a coupler of length d as a chain of relative
 *            (joint) angles: crank 1 at th1 = a, the coupler at a + b,
 *            crank 2 at a + b + c from the pin at (d,0); the chain's
 *            end on the second pin: 3 coordinates, 2 constraints of rank
 *            2, rank 1 when flat.
 * Cranks and coupler are uniform rods (crank mass mc, coupler mass mb),
 * gravity g along -y. On the parallelogram branch every crank has the
 * angle th and the coupler translates, so th obeys the pendulum
 *     I th'' = -g G cos th,  I = k mc a^2 / 3 + mb a^2,
 *     G = (k mc / 2 + mb) a,  k = number of cranks,
 * integrated here by a fine RK4 of its own as the reference. Started
 * hanging (th = -pi/2) with th' = 8 rad/s, the crank turns over about once
 * a second: 40 flat passes in 20 s. A switch to the other assembly branch
 * (the anti-parallelogram) would show as a coupler that turns.
 *
 * rk4, erk, bdf, esdirk and imex pass. adams and ida cannot by
 * themselves (they project only at output times: adams drifted off the
 * phase, ida's index-1 iteration matrix is singular there and it picked
 * the other branch): they hand each flat pass of the points and relative
 * forms to bdf and restart after it, and refuse the angles form's
 * redundant loop at setup, with a message that says why. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"

static const double A = 1.0, D = 2.0, MC = 1.0, MB = 2.0, G = 9.81;
static const double W0 = 8.0, T_END = 20.0;
#define PI_ 3.14159265358979323846

/* ---- angles: three cranks, a coupler, a redundant loop ----------------- */

static tp_val rod_pin_T(tp_rec *R, tp_val thd)
{
    /* a crank about its pin: (mc a^2 / 3) thd^2 / 2 */
    return tp_mulc(R, tp_sqr(R, thd), MC * A * A / 6.0);
}

static int ang_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val th1 = eom_q(c, 0), ph = eom_q(c, 3);
    tp_val w1 = eom_qd(c, 0), wp = eom_qd(c, 3);
    /* coupler centre: a e(th1) + d e(ph); velocity a w1 n(th1) + d wp n(ph) */
    tp_val vx = tp_sub(R, tp_neg(R, tp_mulc(R, tp_mul(R, w1, tp_sin(R, th1)), A)),
                       tp_mulc(R, tp_mul(R, wp, tp_sin(R, ph)), D));
    tp_val vy = tp_add(R, tp_mulc(R, tp_mul(R, w1, tp_cos(R, th1)), A),
                       tp_mulc(R, tp_mul(R, wp, tp_cos(R, ph)), D));
    tp_val Tc = tp_add(R, tp_mulc(R, tp_add(R, tp_sqr(R, vx), tp_sqr(R, vy)),
                                  0.5 * MB),
                       tp_mulc(R, tp_sqr(R, wp), 0.5 * MB * 4.0 * D * D / 12));
    (void)user;
    *out = tp_add(R, Tc, tp_add(R, rod_pin_T(R, w1),
                                tp_add(R, rod_pin_T(R, eom_qd(c, 1)),
                                       rod_pin_T(R, eom_qd(c, 2)))));
    return 0;
}

static int ang_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val s1 = tp_sin(R, eom_q(c, 0)), s2 = tp_sin(R, eom_q(c, 1));
    tp_val s3 = tp_sin(R, eom_q(c, 2)), sp = tp_sin(R, eom_q(c, 3));
    tp_val cranks = tp_mulc(R, tp_add(R, s1, tp_add(R, s2, s3)),
                            G * MC * A / 2);
    tp_val coupler = tp_mulc(R, tp_add(R, tp_mulc(R, s1, A),
                                       tp_mulc(R, sp, D)), G * MB);
    (void)user;
    *out = tp_add(R, cranks, coupler);
    return 0;
}

static int ang_phi(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val th1 = eom_q(c, 0), ph = eom_q(c, 3);
    tp_val x1 = tp_mulc(R, tp_cos(R, th1), A), y1 = tp_mulc(R, tp_sin(R, th1), A);
    tp_val cp = tp_cos(R, ph), sp = tp_sin(R, ph);
    int k;
    (void)user;
    /* tip 1 + k d e(ph) = pin k + a e(th_k+1), k = 1, 2 */
    for (k = 1; k <= 2; k++) {
        tp_val th = eom_q(c, k);
        out[2 * (k - 1)] = tp_sub(R, tp_add(R, x1, tp_mulc(R, cp, k * D)),
                                  tp_addc(R, tp_mulc(R, tp_cos(R, th), A),
                                          k * D));
        out[2 * (k - 1) + 1] = tp_sub(R, tp_add(R, y1, tp_mulc(R, sp, k * D)),
                                      tp_mulc(R, tp_sin(R, th), A));
    }
    return 0;
}

/* ---- points: two crank tips ------------------------------------------- */

static int pt_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val u1 = eom_qd(c, 0), v1 = eom_qd(c, 1);
    tp_val u2 = eom_qd(c, 2), v2 = eom_qd(c, 3);
    tp_val s11 = tp_add(R, tp_sqr(R, u1), tp_sqr(R, v1));
    tp_val s22 = tp_add(R, tp_sqr(R, u2), tp_sqr(R, v2));
    tp_val s12 = tp_add(R, tp_mul(R, u1, u2), tp_mul(R, v1, v2));
    (void)user;
    /* cranks about their pins: (mc / 3) |P'|^2 / 2; the coupler rod
     * between P1 and P2: (mb / 6) (|P1'|^2 + P1'.P2' + |P2'|^2) */
    *out = tp_add(R, tp_mulc(R, tp_add(R, s11, s22), MC / 6.0),
                  tp_mulc(R, tp_add(R, s11, tp_add(R, s12, s22)), MB / 6.0));
    return 0;
}

static int pt_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mulc(R, tp_add(R, eom_q(c, 1), eom_q(c, 3)),
                   G * (MC + MB) / 2.0);
    return 0;
}

static int pt_phi(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val x1 = eom_q(c, 0), y1 = eom_q(c, 1);
    tp_val x2 = eom_q(c, 2), y2 = eom_q(c, 3);
    (void)user;
    out[0] = tp_addc(R, tp_add(R, tp_sqr(R, x1), tp_sqr(R, y1)), -A * A);
    out[1] = tp_addc(R, tp_add(R, tp_sqr(R, tp_addc(R, x2, -D)),
                               tp_sqr(R, y2)), -A * A);
    out[2] = tp_addc(R, tp_add(R, tp_sqr(R, tp_sub(R, x2, x1)),
                               tp_sqr(R, tp_sub(R, y2, y1))), -D * D);
    return 0;
}

/* ---- relative: a chain of joint angles closed on the second pin ------- */

static int rel_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val a = eom_q(c, 0), ph = tp_add(R, a, eom_q(c, 1));
    tp_val wa = eom_qd(c, 0), wp = tp_add(R, wa, eom_qd(c, 1));
    tp_val w2 = tp_add(R, wp, eom_qd(c, 2));
    /* coupler centre: a e(th1) + (d / 2) e(ph) */
    tp_val vx = tp_neg(R, tp_add(R, tp_mulc(R, tp_mul(R, wa, tp_sin(R, a)), A),
                                 tp_mulc(R, tp_mul(R, wp, tp_sin(R, ph)),
                                         D / 2)));
    tp_val vy = tp_add(R, tp_mulc(R, tp_mul(R, wa, tp_cos(R, a)), A),
                       tp_mulc(R, tp_mul(R, wp, tp_cos(R, ph)), D / 2));
    tp_val Tc = tp_add(R, tp_mulc(R, tp_add(R, tp_sqr(R, vx), tp_sqr(R, vy)),
                                  0.5 * MB),
                       tp_mulc(R, tp_sqr(R, wp), 0.5 * MB * D * D / 12));
    (void)user;
    *out = tp_add(R, Tc, tp_add(R, rod_pin_T(R, wa), rod_pin_T(R, w2)));
    return 0;
}

static int rel_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val a = eom_q(c, 0), ph = tp_add(R, a, eom_q(c, 1));
    tp_val th2 = tp_add(R, ph, eom_q(c, 2));
    tp_val cranks = tp_mulc(R, tp_add(R, tp_sin(R, a), tp_sin(R, th2)),
                            G * MC * A / 2);
    tp_val coupler = tp_mulc(R, tp_add(R, tp_mulc(R, tp_sin(R, a), A),
                                       tp_mulc(R, tp_sin(R, ph), D / 2)),
                             G * MB);
    (void)user;
    *out = tp_add(R, cranks, coupler);
    return 0;
}

static int rel_phi(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val a = eom_q(c, 0), ph = tp_add(R, a, eom_q(c, 1));
    tp_val th2 = tp_add(R, ph, eom_q(c, 2));
    (void)user;
    /* a e(th1) + d e(ph) - a e(th2) = (d, 0) */
    out[0] = tp_addc(R, tp_add(R, tp_mulc(R, tp_sub(R, tp_cos(R, a),
                                                    tp_cos(R, th2)), A),
                               tp_mulc(R, tp_cos(R, ph), D)), -D);
    out[1] = tp_add(R, tp_mulc(R, tp_sub(R, tp_sin(R, a), tp_sin(R, th2)), A),
                    tp_mulc(R, tp_sin(R, ph), D));
    return 0;
}

/* ---- the reference ----------------------------------------------------- */

static void pendulum_f(double I, double Gm, const double *y, double *f)
{
    f[0] = y[1];
    f[1] = -G * Gm * cos(y[0]) / I;
}

/* th and th' at each of the nt times t_k = k T_END / nt, k = 1..nt, for
 * k cranks: RK4 with 2e5 steps (error far below the checks). */
static void reference(int k, int nt, double *th, double *thd)
{
    const double I = k * MC * A * A / 3.0 + MB * A * A;
    const double Gm = (k * MC / 2.0 + MB) * A;
    const long steps = 200000;
    const double h = T_END / (double)steps;
    double y[2] = {-PI_ / 2, W0};
    long i;
    int j = 0;
    for (i = 1; i <= steps; i++) {
        double k1[2], k2[2], k3[2], k4[2], z[2];
        int e;
        pendulum_f(I, Gm, y, k1);
        for (e = 0; e < 2; e++) z[e] = y[e] + 0.5 * h * k1[e];
        pendulum_f(I, Gm, z, k2);
        for (e = 0; e < 2; e++) z[e] = y[e] + 0.5 * h * k2[e];
        pendulum_f(I, Gm, z, k3);
        for (e = 0; e < 2; e++) z[e] = y[e] + h * k3[e];
        pendulum_f(I, Gm, z, k4);
        for (e = 0; e < 2; e++)
            y[e] += h / 6.0 * (k1[e] + 2 * k2[e] + 2 * k3[e] + k4[e]);
        if (i % (steps / nt) == 0 && j < nt) {
            th[j] = y[0];
            thd[j] = y[1];
            j++;
        }
    }
}

/* ---- runs -------------------------------------------------------------- */

enum { NT = 20 };

enum form { ANGLES, POINTS, RELATIVE };
static const char *const form_names[] = {"angles", "points", "relative"};

static eom_system *make(enum form form)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    char msg[256];
    if (eom_model_new(&md) != EOM_OK)
        return NULL;
    if (form == RELATIVE) {
        /* on the branch: b = -th1, c = th1 */
        eom_model_add_coord(md, "a", "rad", -PI_ / 2, W0);
        eom_model_add_coord(md, "b", "rad", PI_ / 2, -W0);
        eom_model_add_coord(md, "c", "rad", -PI_ / 2, W0);
        eom_model_set_kinetic(md, rel_T, NULL);
        eom_model_set_potential(md, rel_V, NULL);
        eom_model_set_constraints(md, 2, rel_phi, NULL);
    } else if (form == POINTS) {
        eom_model_add_coord(md, "x1", "m", 0.0, A * W0);
        eom_model_add_coord(md, "y1", "m", -A, 0.0);
        eom_model_add_coord(md, "x2", "m", D, A * W0);
        eom_model_add_coord(md, "y2", "m", -A, 0.0);
        eom_model_set_kinetic(md, pt_T, NULL);
        eom_model_set_potential(md, pt_V, NULL);
        eom_model_set_constraints(md, 3, pt_phi, NULL);
    } else {
        eom_model_add_coord(md, "th1", "rad", -PI_ / 2, W0);
        eom_model_add_coord(md, "th2", "rad", -PI_ / 2, W0);
        eom_model_add_coord(md, "th3", "rad", -PI_ / 2, W0);
        eom_model_add_coord(md, "ph", "rad", 0.0, 0.0);
        eom_model_set_kinetic(md, ang_T, NULL);
        eom_model_set_potential(md, ang_V, NULL);
        eom_model_set_constraints(md, 4, ang_phi, NULL);
    }
    if (eom_system_new(&s, md, msg, sizeof msg) != EOM_OK)
        fprintf(stderr, "eom_system_new: %s\n", msg);
    eom_model_free(&md);
    return s;
}

/* The crank angle and rate of a state, and how far it is from the
 * parallelogram branch (other cranks at the same angle, coupler level). */
static void read_state(enum form form, const double *x, double *th,
                       double *thd, double *off)
{
    if (form == RELATIVE) {
        *th = x[0];
        *thd = x[3];
        *off = fmax(fabs(remainder(x[0] + x[1], 2 * PI_)),
                    fabs(remainder(x[1] + x[2], 2 * PI_)));
    } else if (form == POINTS) {
        *th = atan2(x[1], x[0]);
        *thd = (x[0] * x[5] - x[1] * x[4]) / (A * A);
        *off = hypot(x[2] - D - x[0], x[3] - x[1]);
    } else {
        *th = x[0];
        *thd = x[4];
        *off = fmax(fabs(x[1] - x[0]), fmax(fabs(x[2] - x[0]), fabs(x[3])));
    }
}

/* the difference of two angles, reduced to (-pi, pi] */
static double angle_diff(double a, double b)
{
    return remainder(a - b, 2 * PI_);
}

/* the flat positions (th = 0, pi, 2 pi, ...) the reference passes: th
 * grows from -pi/2 (the crank turns over and over) */
static long flat_passes(const double *th_ref, int nt)
{
    return (long)floor(th_ref[nt - 1] / PI_) + 1;
}

static double run_tol = 1e-10; /* rtol = atol of run() */

/* method on the linkage with nt output times over T_END */
static void run(enum form form, eom_method method, int nt)
{
    const int k = form == ANGLES ? 3 : 2;
    double *th_ref = malloc((size_t)nt * sizeof(double));
    double *thd_ref = malloc((size_t)nt * sizeof(double));
    double x[8], err = 0.0, off_max = 0.0;
    eom_system *s = make(form);
    eom_integ *it = NULL;
    eom_opts o;
    int j, rc = EOM_OK;
    const char *name = eom_method_name(method);
    CHECK(s != NULL && th_ref && thd_ref);
    if (!s || !th_ref || !thd_ref) {
        free(th_ref);
        free(thd_ref);
        eom_system_free(&s);
        return;
    }
    reference(k, nt, th_ref, thd_ref);
    eom_opts_default(&o);
    o.method = method;
    o.dt = 1e-3;
    o.rtol = o.atol = run_tol;
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    for (j = 0; j < nt && rc == EOM_OK; j++) {
        double th, thd, off;
        rc = eom_integ_advance(it, (j + 1) * T_END / nt, x, NULL);
        if (rc != EOM_OK)
            break;
        read_state(form, x, &th, &thd, &off);
        err = fmax(err, fmax(fabs(angle_diff(th, th_ref[j])),
                             fabs(thd - thd_ref[j]) / W0));
        off_max = fmax(off_max, off);
    }
    if (rc != EOM_OK)
        fprintf(stderr, "%s %s: %s: %s\n", form_names[form],
                name, eom_status_name(rc),
                it ? eom_integ_errmsg(it) : eom_system_errmsg(s));
    /* the health figures: the redundant loop makes every solve an SVD
     * one; the flat passes drive the condition of C M^-1 C^T to 0 */
    if (it) {
        eom_stats st;
        CHECK_INT(eom_integ_stats(it, &st), EOM_OK);
        /* in joint angles the steps come less close: measured 2.5e-4
         * (adams) to 3e-6 (erk) */
        CHECK(st.min_rcond_S < (form == RELATIVE ? 1e-3 : 1e-6));
        CHECK(st.svd_solves > 0);
        /* on the branch through every pass: the monitor agrees */
        printf("%-6s %-5s: %d outputs, %ld singular passes seen, %ld branch "
               "switches\n", form_names[form], name, nt,
               st.singular_passes, st.branch_switches);
        if (form == RELATIVE) {
            /* here a step of erk's can carry it across the narrower
             * neighbourhood where C loses rank: 37 of 39 seen, 35 since
             * the projection stops once stalled within the step's error
             * (constraints.c; its error against the pendulum is the same,
             * 1.9e-8) */
            CHECK(st.singular_passes <= flat_passes(th_ref, nt) &&
                  st.singular_passes >= flat_passes(th_ref, nt) - 5);
        } else {
            CHECK_INT(st.singular_passes, flat_passes(th_ref, nt));
        }
        CHECK_INT(st.branch_switches, 0);
        /* adams and ida hand each flat pass to bdf, once */
        printf("%-6s %-5s: %ld singular stretches handed to bdf\n",
               form_names[form], name, st.singular_handovers);
        if (method != EOM_ADAMS && method != EOM_IDA)
            CHECK_INT(st.singular_handovers, 0);
        else if (form == POINTS || method == EOM_ADAMS)
            CHECK_INT(st.singular_handovers, flat_passes(th_ref, nt));
        else /* ida's steps pass some by themselves: 32 of 39; the
              * method takes over again after each (one handover that
              * never ends would count 1) */
            CHECK(st.singular_handovers >= flat_passes(th_ref, nt) / 2 &&
                  st.singular_handovers <= flat_passes(th_ref, nt));
        if (form == ANGLES)
            CHECK(st.svd_solves >= st.steps);
        /* near the flat positions bdf's per-step tolerance is 1e-10,
         * which keeps 1.2e-7 (docs/integrators.md): the tolerances here,
         * below that, are reported so by bdf and by the methods handing
         * to it */
        if (method == EOM_BDF ||
            (st.singular_handovers > 0 &&
             (method == EOM_ADAMS || method == EOM_IDA)))
            CHECK(st.tol_reachable >= 1e-7);
    }
    printf("%-6s %-5s: max error against the pendulum %.3g, off the "
           "branch %.3g\n", form_names[form], name, err, off_max);
    /* at rtol = atol = 1e-10 the passes cost accuracy: measured 1.3e-9
     * (rk4, dt 1e-3) to 3.8e-6 (bdf, points: its per-step tolerance is
     * 1e-10 near each pass, 3e-16 between them) */
    CHECK_INT(rc, EOM_OK);
    CHECK(err < 1e-5);
    CHECK(off_max < 1e-9);
    eom_integ_free(&it);
    eom_system_free(&s);
    free(th_ref);
    free(thd_ref);
}

/* Before the first flat pass (0.05 s from hanging) the points form is
 * well conditioned: no SVD solve, and the smallest rcond says so; the
 * figures are the integrator's own, not what an earlier run of the same
 * system met (it passes flat within its first second). */
static void health_regular(void)
{
    eom_system *s = make(POINTS);
    eom_integ *it = NULL;
    eom_opts o;
    eom_stats st;
    double x[8];
    CHECK(s != NULL);
    if (!s)
        return;
    eom_opts_default(&o);
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    CHECK_INT(eom_integ_advance(it, 1.0, x, NULL), EOM_OK);
    CHECK_INT(eom_integ_stats(it, &st), EOM_OK);
    CHECK(st.svd_solves > 0);
    eom_integ_free(&it);
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    CHECK_INT(eom_integ_advance(it, 0.05, x, NULL), EOM_OK);
    CHECK_INT(eom_integ_stats(it, &st), EOM_OK);
    printf("points, 0.05 s: smallest rcond %.3g, %ld SVD solves\n",
           st.min_rcond_S, st.svd_solves);
    CHECK(st.min_rcond_S > 1e-3 && st.min_rcond_S <= 1.0);
    CHECK_INT(st.svd_solves, 0);
    eom_integ_free(&it);
    eom_system_free(&s);
}

/* adams and ida refuse what they cannot pass at setup: the redundant
 * loop of the angles form; the message names the time, the condition
 * estimate, the cause and the methods that can go on */
static void refused(eom_method method)
{
    eom_system *s = make(ANGLES);
    eom_integ *it = NULL;
    eom_opts o;
    double x[8];
    const char *msg;
    int rc;
    CHECK(s != NULL);
    if (!s)
        return;
    eom_opts_default(&o);
    o.method = method;
    o.rtol = o.atol = 1e-10;
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    CHECK_INT(rc, EOM_ERR_RANK_DEFICIENT);
    CHECK(it == NULL);
    msg = eom_system_errmsg(s);
    printf("angles %s refused: %s\n", eom_method_name(method), msg);
    CHECK(strstr(msg, "at t = 0 ") != NULL);
    CHECK(strstr(msg, "rcond of C M^-1 C^T") != NULL);
    CHECK(strstr(msg, "singular position") != NULL);
    CHECK(strstr(msg, "redundant") != NULL);
    CHECK(strstr(msg, "use bdf, erk or rk4") != NULL);
    CHECK(strstr(msg, eom_method_name(method)) != NULL);
    eom_integ_free(&it);
    eom_system_free(&s);
}

int main(void)
{
    /* the methods that pass through the flat positions; adams and ida
     * hand them to bdf, and refuse the redundant loop */
    static const eom_method passing[] = {EOM_RK4, EOM_ERK, EOM_BDF,
                                         EOM_ESDIRK, EOM_IMEX};
    int m;
    health_regular();
    for (m = 0; m < 5; m++) {
        run(ANGLES, passing[m], NT);
        run(POINTS, passing[m], NT);
        run(RELATIVE, passing[m], NT);
    }
    for (m = 0; m < 2; m++) {
        const eom_method hands = m ? EOM_IDA : EOM_ADAMS;
        refused(hands);
        run(POINTS, hands, NT);
        run(RELATIVE, hands, NT);
        /* outputs every 2 ms: a stretch goes on across several */
        run(POINTS, hands, 10000);
    }
    /* tighter than the floor near the flat positions: it holds, and says
     * what it keeps */
    run_tol = 1e-12;
    run(POINTS, EOM_BDF, NT);
    run(POINTS, EOM_ADAMS, NT);
    run(RELATIVE, EOM_IDA, NT);
    CHECK_DONE();
}
