/* test_velocity.c - velocity (non-holonomic) constraints A(q, t) qd +
 * b(q, t) = 0 against closed forms and against holonomic constraints.
 *
 * Skate (a knife edge on a plane): coordinates x, y, th, T = m/2 (xd^2 +
 * yd^2) + I/2 thd^2, the blade's constraint
 *     psi = -sin(th) xd + cos(th) yd = 0.
 * The constraint force lambda (-sin th, cos th, 0) has no moment, so thd
 * = w is constant, and the speed v along the blade too:
 *     th = th0 + w t,  x = x0 + (v/w)(sin th - sin th0),
 *     y = y0 - (v/w)(cos th - cos th0)            (a circle of radius v/w)
 *     xdd = -v w sin th,  ydd = v w cos th,  lambda = m v w.
 * At any state, on the constraint or off it, M qdd = C^T lambda and
 * A qdd = gamma - 2 alpha psi with gamma = -dpsi/ds along (qd, 0) =
 * thd (cos th xd + sin th yd), so lambda = m (gamma - 2 alpha psi).
 *
 * Cart and pendulum, twice: coordinates (x, th), a cart x on a spring
 * and a pendulum th, held together by x = l sin(th) + c sin(W t), written
 * once as the holonomic constraint phi = x - l sin th - c sin(W t) and
 * once as its derivative psi = xd - l cos th thd - c W cos(W t) (a
 * velocity constraint with b(t) != 0). On the constraint both forms must
 * give the same accelerations, multipliers and power (an independent
 * route to gamma, its time terms and the constraint force's work).
 *
 * Checked: the skate's accelerations and multipliers at random states
 * with and without Baumgarte, and a clone's; its trajectory with erk
 * against the closed form, psi and E held; every method that takes
 * velocity rows runs it;
 * the two cart forms at random states and times; a model with both
 * kinds of rows projected (q by the holonomic rows only); the exact
 * Jacobian of the state derivative against differences; compiled tapes
 * beside the interpreted psi tape; the state-space linearization of a
 * velocity constraint against the holonomic one; the refusals
 * (a row not linear in the rates or not reading them, ida, sensitivities,
 * the linearization at rest), bad arguments, a NaN, and redundant velocity
 * rows. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"
#include "support_rng.h"

static const double SM = 1.3, SI = 0.4;

/* ---- the skate -------------------------------------------------------- */

enum skate_kind {
    SKATE,          /* the blade's constraint */
    SKATE_TWICE,    /* the same row twice (redundant) */
    SKATE_SQUARED,  /* a row not linear in the rates */
    SKATE_NO_RATES, /* a row of q alone */
    SKATE_SQRT      /* a row with sqrt(x): NaN for x < 0 */
};

static int skate_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_add(R,
                  tp_mulc(R, tp_add(R, tp_sqr(R, eom_qd(c, 0)),
                                    tp_sqr(R, eom_qd(c, 1))),
                          0.5 * SM),
                  tp_mulc(R, tp_sqr(R, eom_qd(c, 2)), 0.5 * SI));
    return 0;
}

static tp_val blade(eom_ctx *c)
{
    tp_rec *R = eom_rec(c);
    return tp_add(R,
                  tp_neg(R, tp_mul(R, tp_sin(R, eom_q(c, 2)), eom_qd(c, 0))),
                  tp_mul(R, tp_cos(R, eom_q(c, 2)), eom_qd(c, 1)));
}

static int skate_psi(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    const enum skate_kind kind = *(const enum skate_kind *)user;
    out[0] = blade(c);
    switch (kind) {
    case SKATE_TWICE:
        out[1] = tp_mulc(R, blade(c), 2.0);
        break;
    case SKATE_SQUARED:
        out[1] = tp_sub(R, tp_sqr(R, eom_qd(c, 2)), tp_const(R, 1.0));
        break;
    case SKATE_NO_RATES:
        out[1] = tp_sub(R, eom_q(c, 0), eom_q(c, 1));
        break;
    case SKATE_SQRT:
        out[0] = tp_add(R, out[0], tp_mul(R, tp_sqrt(R, eom_q(c, 0)),
                                          eom_qd(c, 2)));
        break;
    default:
        break;
    }
    return 0;
}

static eom_system *skate_new(enum skate_kind *kind, int *status, char *msg,
                             size_t len)
{
    eom_model *m = NULL;
    eom_system *s = NULL;
    const int rows = *kind == SKATE || *kind == SKATE_SQRT ? 1 : 2;
    eom_model_new(&m);
    eom_model_add_coord(m, "x", "m", 0.2, 0.0);
    eom_model_add_coord(m, "y", "m", -0.1, 0.0);
    eom_model_add_coord(m, "th", "rad", 0.3, 0.0);
    eom_model_set_kinetic(m, skate_T, NULL);
    CHECK_INT(eom_model_add_velocity_constraints(m, rows, skate_psi, kind),
              EOM_OK);
    *status = eom_system_new(&s, m, msg, len);
    eom_model_free(&m);
    return s;
}

/* The closed-form state at t from (x0, y0, th0, v, w). */
static void skate_exact(const double *p, double t, double *x)
{
    const double x0 = p[0], y0 = p[1], th0 = p[2], v = p[3], w = p[4];
    const double th = th0 + w * t;
    x[0] = x0 + v / w * (sin(th) - sin(th0));
    x[1] = y0 - v / w * (cos(th) - cos(th0));
    x[2] = th;
    x[3] = v * cos(th);
    x[4] = v * sin(th);
    x[5] = w;
}

static void test_skate_rhs(void)
{
    enum skate_kind kind = SKATE;
    char msg[256];
    int st, k;
    eom_system *s = skate_new(&kind, &st, msg, sizeof msg);
    rng r = rng_seed(12345);
    CHECK_INT(st, EOM_OK);
    if (!s)
        return;
    CHECK_INT(eom_system_nconstraints(s), 1);
    for (k = 0; k < 40; k++) {
        double p[5], x[6], xd[6], lam, phi, psi, C[3];
        const double alpha = k % 2 ? 0.7 : 0.0;
        p[0] = rng_range(&r, -2, 2);
        p[1] = rng_range(&r, -2, 2);
        p[2] = rng_range(&r, -3, 3);
        p[3] = rng_range(&r, -2, 2);
        p[4] = rng_range(&r, -2, 2);
        skate_exact(p, 0.0, x);
        if (k >= 20) { /* off the constraint */
            x[3] += rng_range(&r, -0.5, 0.5);
            x[4] += rng_range(&r, -0.5, 0.5);
        }
        CHECK_INT(eom_set_baumgarte(s, alpha, 0.3), EOM_OK);
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        CHECK_INT(eom_multipliers(s, 0.0, x, &lam), EOM_OK);
        CHECK_INT(eom_residuals(s, x, &phi, &psi), EOM_OK);
        CHECK_INT(eom_constraint_jacobian(s, x, C, &phi), EOM_OK);
        {
            const double sn = sin(x[2]), cs = cos(x[2]);
            const double psi_ex = -sn * x[3] + cs * x[4];
            const double gam = x[5] * (cs * x[3] + sn * x[4]);
            const double lam_ex = SM * (gam - 2.0 * alpha * psi_ex);
            CHECK_NEAR(phi, 0.0, 0.0);
            CHECK_NEAR(psi, psi_ex, 1e-15);
            CHECK_NEAR(C[0], -sn, 1e-15);
            CHECK_NEAR(C[1], cs, 1e-15);
            CHECK_NEAR(C[2], 0.0, 0.0);
            CHECK_NEAR(lam, lam_ex, 1e-13);
            CHECK_NEAR(xd[3], -sn * lam_ex / SM, 1e-13);
            CHECK_NEAR(xd[4], cs * lam_ex / SM, 1e-13);
            CHECK_NEAR(xd[5], 0.0, 1e-15);
            if (k < 20) { /* on it: the closed form's */
                CHECK_NEAR(lam, SM * p[3] * p[4], 1e-13);
                CHECK_NEAR(xd[3], -p[3] * p[4] * sn, 1e-13);
                CHECK_NEAR(xd[4], p[3] * p[4] * cs, 1e-13);
            }
        }
    }
    /* a clone shares the psi tape and gives the same bits; freed in
     * either order */
    {
        eom_system *c = NULL;
        double x[6] = {0.3, -0.4, 1.1, 0.2, 0.5, -0.7}, xa[6], xb[6];
        CHECK_INT(eom_system_clone(&c, s, msg, sizeof msg), EOM_OK);
        if (c) {
            CHECK_INT(eom_rhs(s, 0.0, x, xa), EOM_OK);
            CHECK_INT(eom_rhs(c, 0.0, x, xb), EOM_OK);
            CHECK(memcmp(xa, xb, sizeof xa) == 0);
            eom_system_free(&s);
            CHECK_INT(eom_rhs(c, 0.0, x, xb), EOM_OK);
            CHECK(memcmp(xa, xb, sizeof xa) == 0);
            eom_system_free(&c);
        }
    }
    eom_system_free(&s);
}

/* One run of method from the closed form's start to t = 4; the largest
 * deviation from the closed form, of |psi| and of |E + W - E0| at the
 * output times into err[0..2]; the integrator's status. */
static int skate_run(eom_system *s, eom_method method, double tol,
                     double *err)
{
    const double p[5] = {0.4, -0.3, 0.5, 1.1, 0.8};
    eom_opts o;
    eom_integ *it = NULL;
    eom_energy e;
    double x[6], ex[6], E0, W;
    int rc, k, i;
    err[0] = err[1] = err[2] = 0.0;
    skate_exact(p, 0.0, x);
    eom_opts_default(&o);
    o.method = method;
    o.rtol = o.atol = tol;
    o.dt = 1e-3;
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    if (rc != EOM_OK) {
        fprintf(stderr, "%s: %s\n", eom_method_name(method),
                eom_system_errmsg(s));
        return rc;
    }
    eom_energy_at(s, 0.0, x, &e);
    E0 = e.E;
    for (k = 1; k <= 8 && rc == EOM_OK; k++) {
        double psi;
        const double t = 0.5 * k;
        rc = eom_integ_advance(it, t, x, &W);
        if (rc != EOM_OK) {
            fprintf(stderr, "%s: %s\n", eom_method_name(method),
                    eom_integ_errmsg(it));
            break;
        }
        skate_exact(p, t, ex);
        for (i = 0; i < 6; i++)
            err[0] = fmax(err[0], fabs(x[i] - ex[i]));
        eom_residuals(s, x, NULL, &psi);
        err[1] = fmax(err[1], fabs(psi));
        eom_energy_at(s, t, x, &e);
        err[2] = fmax(err[2], fabs(e.E + W - E0));
    }
    eom_integ_free(&it);
    return rc;
}

static void test_skate_motion(void)
{
    static const eom_method all[] = {EOM_RK4,   EOM_ERK,    EOM_ADAMS,
                                     EOM_BDF,   EOM_ESDIRK, EOM_IMEX};
    enum skate_kind kind = SKATE;
    char msg[256];
    double err[3];
    int st, k;
    eom_system *s = skate_new(&kind, &st, msg, sizeof msg);
    CHECK_INT(st, EOM_OK);
    if (!s)
        return;
    CHECK_INT(skate_run(s, EOM_ERK, 1e-13, err), EOM_OK);
    printf("skate erk 1e-13: state %.3g, |psi| %.3g, |E + W - E0| %.3g\n",
           err[0], err[1], err[2]);
    CHECK(err[0] <= 1e-9);
    CHECK(err[1] <= 1e-12);
    CHECK(err[2] <= 1e-10);
    for (k = 0; k < (int)(sizeof all / sizeof all[0]); k++) {
        CHECK_INT(skate_run(s, all[k], 1e-9, err), EOM_OK);
        printf("skate %-6s 1e-9:  state %.3g, |psi| %.3g, |E + W - E0| "
               "%.3g\n", eom_method_name(all[k]), err[0], err[1], err[2]);
        CHECK(err[0] <= 1e-5);
        CHECK(err[1] <= 1e-11);
        CHECK(err[2] <= 1e-6);
    }
    eom_system_free(&s);
}

/* ---- the cart and pendulum, holonomic and velocity forms ------------- */

static const double CM = 0.9, CI = 0.3, CK = 4.0, CL = 0.7, CG = 9.81,
                    CC = 0.2, CW = 2.5;

static int cart_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_add(R, tp_mulc(R, tp_sqr(R, eom_qd(c, 0)), 0.5 * CM),
                  tp_mulc(R, tp_sqr(R, eom_qd(c, 1)), 0.5 * CI));
    return 0;
}

static int cart_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_add(R, tp_mulc(R, tp_sqr(R, eom_q(c, 0)), 0.5 * CK),
                  tp_mulc(R, tp_cos(R, eom_q(c, 1)), -CI * CG));
    return 0;
}

static tp_val drive(eom_ctx *c, int rate)
{
    tp_rec *R = eom_rec(c);
    tp_val wt = tp_mulc(R, eom_time(c), CW);
    return rate ? tp_mulc(R, tp_cos(R, wt), CC * CW)
                : tp_mulc(R, tp_sin(R, wt), CC);
}

static int cart_phi(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    const int moving = *(const int *)user;
    out[0] = tp_sub(R, eom_q(c, 0), tp_mulc(R, tp_sin(R, eom_q(c, 1)), CL));
    if (moving)
        out[0] = tp_sub(R, out[0], drive(c, 0));
    return 0;
}

static int cart_psi(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    const int moving = *(const int *)user;
    out[0] = tp_sub(R, eom_qd(c, 0),
                    tp_mul(R, tp_mulc(R, tp_cos(R, eom_q(c, 1)), CL),
                           eom_qd(c, 1)));
    if (moving)
        out[0] = tp_sub(R, out[0], drive(c, 1));
    return 0;
}

static eom_system *cart_new(int velocity, int *moving)
{
    eom_model *m = NULL;
    eom_system *s = NULL;
    char msg[256];
    int st;
    eom_model_new(&m);
    eom_model_add_coord(m, "x", "m", 0.0, 0.0);
    eom_model_add_coord(m, "th", "rad", 0.0, 0.0);
    eom_model_set_kinetic(m, cart_T, NULL);
    eom_model_set_potential(m, cart_V, NULL);
    if (velocity)
        eom_model_add_velocity_constraints(m, 1, cart_psi, moving);
    else
        eom_model_add_constraints(m, 1, cart_phi, moving);
    st = eom_system_new(&s, m, msg, sizeof msg);
    CHECK_INT(st, EOM_OK);
    if (st != EOM_OK)
        fprintf(stderr, "cart: %s\n", msg);
    eom_model_free(&m);
    return s;
}

static void test_cart_forms(void)
{
    int moving;
    rng r = rng_seed(777);
    for (moving = 0; moving < 2; moving++) {
        eom_system *h = cart_new(0, &moving), *v = cart_new(1, &moving);
        int k;
        if (!h || !v) {
            eom_system_free(&h);
            eom_system_free(&v);
            continue;
        }
        CHECK_INT(eom_system_reads_time(v), moving);
        for (k = 0; k < 40; k++) {
            const double t = rng_range(&r, -3, 3);
            const double alpha = k % 2 ? 0.9 : 0.0;
            double x[4], xh[4], xv[4], lh, lv;
            eom_energy eh, ev;
            int i;
            x[1] = rng_range(&r, -1.5, 1.5);
            x[3] = rng_range(&r, -2, 2);
            x[0] = CL * sin(x[1]) + (moving ? CC * sin(CW * t) : 0.0);
            x[2] = CL * cos(x[1]) * x[3] +
                   (moving ? CC * CW * cos(CW * t) : 0.0);
            /* the velocity term of Baumgarte's is the same for both
             * (C qd + dphi/dt is psi); the position term is the
             * holonomic form's alone, and phi = 0 here */
            eom_set_baumgarte(h, alpha, 0.5);
            eom_set_baumgarte(v, alpha, 0.5);
            CHECK_INT(eom_rhs(h, t, x, xh), EOM_OK);
            CHECK_INT(eom_rhs(v, t, x, xv), EOM_OK);
            CHECK_INT(eom_multipliers(h, t, x, &lh), EOM_OK);
            CHECK_INT(eom_multipliers(v, t, x, &lv), EOM_OK);
            for (i = 0; i < 4; i++)
                CHECK_NEAR(xv[i], xh[i], 1e-13);
            CHECK_NEAR(lv, lh, 1e-13);
            CHECK_INT(eom_energy_at(h, t, x, &eh), EOM_OK);
            CHECK_INT(eom_energy_at(v, t, x, &ev), EOM_OK);
            CHECK_NEAR(ev.E, eh.E, 1e-14);
            CHECK_NEAR(ev.P, eh.P, 1e-12);
            CHECK_NEAR(ev.Pt, eh.Pt, 1e-12);
        }
        /* a run of the moving velocity form keeps E + W */
        if (moving) {
            eom_opts o;
            eom_integ *it = NULL;
            eom_energy e0, e1;
            double x[4], W = 0.0;
            x[1] = 0.4;
            x[3] = 0.0;
            x[0] = CL * sin(x[1]);
            x[2] = CC * CW;
            eom_opts_default(&o);
            o.method = EOM_ERK;
            o.rtol = o.atol = 1e-12;
            eom_set_baumgarte(v, 0.0, 0.0);
            eom_energy_at(v, 0.0, x, &e0);
            CHECK_INT(eom_integ_new(&it, v, &o, 0.0, x), EOM_OK);
            CHECK_INT(eom_integ_advance(it, 3.0, x, &W), EOM_OK);
            eom_energy_at(v, 3.0, x, &e1);
            printf("cart, moving velocity constraint: E0 %.6f, E %.6f, "
                   "W %.6f, |E + W - E0| %.3g\n", e0.E, e1.E, W,
                   fabs(e1.E + W - e0.E));
            CHECK(fabs(e1.E - e0.E) > 1e-3); /* the drive does work */
            CHECK_NEAR(e1.E + W, e0.E, 1e-9);
            eom_integ_free(&it);
        }
        eom_system_free(&h);
        eom_system_free(&v);
    }
}

/* ---- state-space linearization ---------------------------------------- */

/* The fixed cart at rest, x = th = 0: the holonomic form's reduced
 * eigenvalues are +-i omega (nz = 2n - 2); the velocity form's (nz =
 * 2n - 1) are the same and a zero, for the drift along x - l sin th =
 * const that a velocity constraint does not hold. */
static void test_linearize_state(void)
{
    int moving = 0, k;
    eom_system *h = cart_new(0, &moving), *v = cart_new(1, &moving);
    eom_state_linear lh, lv;
    const double x[4] = {0.0, 0.0, 0.0, 0.0};
    if (!h || !v) {
        eom_system_free(&h);
        eom_system_free(&v);
        return;
    }
    CHECK_INT(eom_linearize_state(h, 0.0, x, &lh), EOM_OK);
    CHECK_INT(eom_linearize_state(v, 0.0, x, &lv), EOM_OK);
    CHECK_INT(lh.nz, 2);
    CHECK_INT(lv.nz, 3);
    if (lh.nz == 2 && lv.nz == 3) {
        /* omega^2 = (k l^2 + I g) / (m l^2 + I), from x = l th */
        const double w =
            sqrt((CK * CL * CL + CI * CG) / (CM * CL * CL + CI));
        printf("cart linearized: holonomic %.15g %+.15gi, %.15g %+.15gi; "
               "velocity", lh.eig_re[0], lh.eig_im[0], lh.eig_re[1],
               lh.eig_im[1]);
        for (k = 0; k < 3; k++)
            printf(" %.3g %+.15gi", lv.eig_re[k], lv.eig_im[k]);
        printf("\n");
        CHECK_NEAR(lh.eig_re[0], 0.0, 1e-12);
        CHECK_NEAR(lh.eig_im[0], -w, 1e-12);
        CHECK_NEAR(lh.eig_im[1], w, 1e-12);
        for (k = 0; k < 3; k++)
            CHECK_NEAR(lv.eig_re[k], 0.0, 1e-12);
        CHECK_NEAR(lv.eig_im[0], -w, 1e-12);
        CHECK_NEAR(lv.eig_im[1], 0.0, 1e-12);
        CHECK_NEAR(lv.eig_im[2], w, 1e-12);
    }
    eom_state_linear_free(&lh);
    eom_state_linear_free(&lv);
    eom_system_free(&h);
    eom_system_free(&v);
}

/* ---- compiled tapes --------------------------------------------------- */

/* The moving cart on compiled tapes (its psi tape stays interpreted)
 * against an interpreted clone, in a cache of the run's own. */
static void test_compiled(void)
{
    char dir[] = "/tmp/test-velocity-XXXXXX", cmd[128], msg[256];
    int moving = 1, st, k;
    eom_system *s, *c = NULL;
    rng r = rng_seed(5);
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        CHECK(0);
        return;
    }
    setenv("AUTOEOM_CACHE_DIR", dir, 1);
    s = cart_new(1, &moving);
    if (s && eom_system_clone(&c, s, msg, sizeof msg) == EOM_OK) {
        st = eom_system_set_compiled(s, 1, NULL);
        CHECK(st == EOM_OK || st == EOM_WARN_INTERPRETED);
        if (st != EOM_OK)
            printf("compiled tapes not in use: %s\n", eom_system_errmsg(s));
        CHECK_INT(eom_system_compiled(s), st == EOM_OK);
        for (k = 0; k < 10; k++) {
            double x[4], xa[4], xb[4], t = rng_range(&r, -2, 2);
            int i;
            for (i = 0; i < 4; i++)
                x[i] = rng_range(&r, -1, 1);
            CHECK_INT(eom_rhs(s, t, x, xa), EOM_OK);
            CHECK_INT(eom_rhs(c, t, x, xb), EOM_OK);
            for (i = 0; i < 4; i++)
                CHECK_NEAR(xa[i], xb[i], 1e-13);
        }
    }
    eom_system_free(&c);
    eom_system_free(&s);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
}

/* ---- exact Jacobians -------------------------------------------------- */

/* eom_state_jacobian against central differences of eom_rhs at (t, x),
 * 2n = n2 states; the largest difference relative to max(1, |entry|). */
static double jacobian_error(eom_system *s, double t, const double *x,
                             int n2)
{
    double A[64], xp[8], fp[8], fm[8], worst = 0.0;
    const double h = 1e-6;
    int i, j;
    CHECK_INT(eom_state_jacobian(s, t, x, A), EOM_OK);
    for (j = 0; j < n2; j++) {
        memcpy(xp, x, (size_t)n2 * sizeof *xp);
        xp[j] = x[j] + h;
        eom_rhs(s, t, xp, fp);
        xp[j] = x[j] - h;
        eom_rhs(s, t, xp, fm);
        for (i = 0; i < n2; i++) {
            const double fd = (fp[i] - fm[i]) / (2 * h);
            const double a = A[i * n2 + j];
            worst = fmax(worst, fabs(a - fd) / fmax(1.0, fabs(a)));
        }
    }
    return worst;
}

static void test_state_jacobian(void)
{
    enum skate_kind kind = SKATE;
    char msg[256];
    int st, k, moving = 1;
    double worst = 0.0;
    rng r = rng_seed(99);
    eom_system *s = skate_new(&kind, &st, msg, sizeof msg);
    eom_system *c = cart_new(1, &moving);
    if (!s || !c) {
        eom_system_free(&s);
        eom_system_free(&c);
        return;
    }
    eom_set_baumgarte(s, 0.7, 0.3);
    eom_set_baumgarte(c, 0.4, 0.0);
    for (k = 0; k < 10; k++) {
        double x[6], t = rng_range(&r, -2, 2);
        int i;
        for (i = 0; i < 6; i++) /* off the constraints too */
            x[i] = rng_range(&r, -1.5, 1.5);
        worst = fmax(worst, jacobian_error(s, 0.0, x, 6));
        worst = fmax(worst, jacobian_error(c, t, x, 4));
    }
    printf("state Jacobian against differences: %.3g\n", worst);
    CHECK(worst <= 1e-7);
    eom_system_free(&s);
    eom_system_free(&c);
}

/* ---- both kinds of rows: projection ----------------------------------- */

/* The skate with a fourth coordinate u held at u = x + y (holonomic). */
static int mixed_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    skate_T(c, user, out);
    *out = tp_add(R, *out, tp_mulc(R, tp_sqr(R, eom_qd(c, 3)), 0.5));
    return 0;
}

static int mixed_phi(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    out[0] = tp_sub(R, eom_q(c, 3), tp_add(R, eom_q(c, 0), eom_q(c, 1)));
    return 0;
}

static void test_mixed_projection(void)
{
    enum skate_kind kind = SKATE;
    eom_model *m = NULL;
    eom_system *s = NULL;
    char msg[256];
    double x[8] = {0.3, -0.2, 0.6, 0.1 + 1e-3, 0.5, -0.4, 0.7, 0.2};
    double x1[8], phi[2], psi[2], C[8], xd[8], xd1[8];
    int iters = 0, i;
    eom_model_new(&m);
    eom_model_add_coord(m, "x", "m", 0.0, 0.0);
    eom_model_add_coord(m, "y", "m", 0.0, 0.0);
    eom_model_add_coord(m, "th", "rad", 0.0, 0.0);
    eom_model_add_coord(m, "u", "m", 0.0, 0.0);
    eom_model_set_kinetic(m, mixed_T, NULL);
    eom_model_add_velocity_constraints(m, 1, skate_psi, &kind);
    eom_model_add_constraints(m, 1, mixed_phi, NULL);
    CHECK_INT(eom_system_new(&s, m, msg, sizeof msg), EOM_OK);
    eom_model_free(&m);
    if (!s) {
        fprintf(stderr, "mixed: %s\n", msg);
        return;
    }
    CHECK_INT(eom_system_nconstraints(s), 2);
    /* rows: the holonomic one first, then the velocity row */
    CHECK_INT(eom_constraint_jacobian(s, x, C, phi), EOM_OK);
    CHECK_NEAR(phi[0], 1e-3 + 0.1 - 0.1, 1e-15);
    CHECK_NEAR(phi[1], 0.0, 0.0);
    CHECK_NEAR(C[4 + 0], -sin(x[2]), 1e-15);
    memcpy(x1, x, sizeof x);
    CHECK_INT(eom_project(s, x1, 1e-13, &iters), EOM_OK);
    CHECK(iters >= 1);
    CHECK_INT(eom_residuals(s, x1, phi, psi), EOM_OK);
    CHECK(fabs(phi[0]) <= 1e-13 && fabs(psi[0]) <= 1e-12 &&
          fabs(psi[1]) <= 1e-12);
    CHECK_NEAR(phi[1], 0.0, 0.0);
    /* q moves along M^-1 C_h^T only (the holonomic row's direction
     * (-1, -1, 0, 1), masses SM, SM, -, 1): th does not move, and x and y
     * by the same amount */
    CHECK_NEAR(x1[2], x[2], 0.0);
    CHECK_NEAR(x1[0] - x[0], x1[1] - x[1], 1e-15);
    CHECK_NEAR((x1[3] - x[3]) / (x1[0] - x[0]), -SM, 1e-9);
    /* and the rates satisfy both rows */
    for (i = 0; i < 8; i++)
        CHECK(isfinite(x1[i]));
    CHECK_INT(eom_rhs(s, 0.0, x1, xd), EOM_OK);
    /* the accelerations keep both rows' rates at 0: A qdd = gamma */
    {
        const double h = 1e-6;
        double x2[8];
        for (i = 0; i < 8; i++)
            x2[i] = x1[i] + h * xd[i];
        CHECK_INT(eom_rhs(s, 0.0, x2, xd1), EOM_OK);
        CHECK_INT(eom_residuals(s, x2, phi, psi), EOM_OK);
        CHECK(fabs(psi[0]) <= 1e-10 && fabs(psi[1]) <= 1e-10);
    }
    eom_system_free(&s);
}

/* ---- refusals and errors ---------------------------------------------- */

static int nothing_psi(eom_ctx *c, void *user, tp_val *out)
{
    (void)c;
    (void)user;
    (void)out;
    return 0;
}

static void test_refusals(void)
{
    enum skate_kind kind;
    char msg[256];
    int st;
    eom_system *s;
    eom_model *m = NULL;

    /* a row not linear in the rates: named */
    kind = SKATE_SQUARED;
    s = skate_new(&kind, &st, msg, sizeof msg);
    CHECK(!s);
    CHECK_INT(st, EOM_ERR_MODEL);
    printf("refused: %s\n", msg);
    CHECK(strstr(msg, "velocity constraint 2") != NULL);
    CHECK(strstr(msg, "not linear in the rates") != NULL);
    CHECK(strstr(msg, "th_dot") != NULL);
    /* a row that does not read the rates */
    kind = SKATE_NO_RATES;
    s = skate_new(&kind, &st, msg, sizeof msg);
    CHECK(!s);
    CHECK_INT(st, EOM_ERR_MODEL);
    printf("refused: %s\n", msg);
    CHECK(strstr(msg, "velocity constraint 2") != NULL);
    CHECK(strstr(msg, "holonomic") != NULL);

    /* bad arguments */
    eom_model_new(&m);
    eom_model_add_coord(m, "x", NULL, 0.0, 0.0);
    CHECK_INT(eom_model_add_velocity_constraints(NULL, 1, skate_psi, NULL),
              EOM_ERR_NULL);
    CHECK_INT(eom_model_add_velocity_constraints(m, 1, NULL, NULL),
              EOM_ERR_NULL);
    CHECK(strstr(eom_model_errmsg(m), "NULL") != NULL);
    eom_model_free(&m);
    eom_model_new(&m);
    CHECK_INT(eom_model_add_velocity_constraints(m, 0, skate_psi, NULL),
              EOM_ERR_ARG);
    CHECK_INT(eom_model_add_velocity_constraints(m, -3, skate_psi, NULL),
              EOM_ERR_ARG);
    eom_model_free(&m);
    /* a callback that sets nothing */
    eom_model_new(&m);
    eom_model_add_coord(m, "x", NULL, 0.0, 0.0);
    eom_model_set_kinetic(m, skate_T, NULL);
    eom_model_add_velocity_constraints(m, 1, nothing_psi, NULL);
    s = NULL;
    st = eom_system_new(&s, m, msg, sizeof msg);
    CHECK(st < 0 && !s);
    eom_model_free(&m);

    /* what does not take them */
    kind = SKATE;
    s = skate_new(&kind, &st, msg, sizeof msg);
    if (s) {
        eom_opts o;
        eom_integ *it = NULL;
        eom_linear lin;
        double x[6] = {0.1, 0.2, 0.3, 0.0, 0.0, 0.5}, A[36], q[3];
        int sens = 0;
        eom_opts_default(&o);
        o.method = EOM_IDA;
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_MODEL);
        CHECK(!it);
        printf("refused: %s\n", eom_system_errmsg(s));
        CHECK(strstr(eom_system_errmsg(s), "rk4, erk, adams, bdf") != NULL);
        o.method = EOM_BDF;
        o.n_sens = 1;
        o.sens = &sens;
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_MODEL);
        CHECK(strstr(eom_system_errmsg(s), "sensitivities") != NULL);
        CHECK_INT(eom_linearize(s, x, &lin), EOM_ERR_MODEL);
        CHECK(strstr(eom_system_errmsg(s), "velocity") != NULL);
        memcpy(q, x, sizeof q);
        CHECK_INT(eom_equilibrium(s, q, 1e-10, NULL), EOM_ERR_MODEL);
        /* a non-finite state */
        x[4] = NAN;
        CHECK_INT(eom_rhs(s, 0.0, x, A), EOM_ERR_NONFINITE);
        eom_system_free(&s);
    }

    /* a NaN from the row itself: sqrt(x) at x < 0 */
    kind = SKATE_SQRT;
    s = skate_new(&kind, &st, msg, sizeof msg);
    CHECK_INT(st, EOM_OK);
    if (s) {
        double x[6] = {-0.5, 0.2, 0.3, 0.1, 0.0, 0.5}, xd[6], phi, psi;
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_ERR_NONFINITE);
        CHECK(strstr(eom_system_errmsg(s), "velocity constraints") != NULL);
        CHECK_INT(eom_residuals(s, x, &phi, &psi), EOM_ERR_NONFINITE);
        CHECK_INT(eom_project(s, x, 1e-12, NULL), EOM_ERR_NONFINITE);
        eom_system_free(&s);
    }

    /* redundant rows: C M^-1 C^T singular, the filtered SVD's solve gives
     * the motion of the single row */
    {
        enum skate_kind k1 = SKATE, k2 = SKATE_TWICE;
        eom_system *s1 = skate_new(&k1, &st, msg, sizeof msg);
        eom_system *s2 = skate_new(&k2, &st, msg, sizeof msg);
        double x[6] = {0.1, 0.2, 0.3, 0.4, -0.2, 0.5}, xd1[6], xd2[6];
        double rs;
        int i;
        CHECK_INT(st, EOM_OK);
        if (s1 && s2) {
            CHECK_INT(eom_rhs(s1, 0.0, x, xd1), EOM_OK);
            CHECK_INT(eom_rhs(s2, 0.0, x, xd2), EOM_OK);
            for (i = 0; i < 6; i++)
                CHECK_NEAR(xd2[i], xd1[i], 1e-9);
            CHECK_INT(eom_condition(s2, x, NULL, &rs), EOM_OK);
            CHECK(rs < 1e-12);
            CHECK_INT(eom_project(s2, x, 1e-12, NULL), EOM_OK);
        }
        eom_system_free(&s1);
        eom_system_free(&s2);
    }
}

int main(void)
{
    test_skate_rhs();
    test_cart_forms();
    test_state_jacobian();
    test_compiled();
    test_linearize_state();
    test_mixed_projection();
    test_refusals();
    test_skate_motion();
    CHECK_DONE();
}
