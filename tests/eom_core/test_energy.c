/* test_energy.c - eom_energy_at and the work W integrated beside the
 * state.
 *
 *  1. Natural systems (spring pendulum, open double pendulum, four-bar,
 *     bead on a circle): at 50 random states each, T, V, L = T - V and the
 *     Jacobi integral E = T + V equal the hand-written energies (1e-13
 *     relative to |T| + |V|); P = 0.
 *  2. A model given as a whole Lagrangian with a gyroscopic term, a
 *     charged particle in a magnetic field B on a spring:
 *        L = m/2 (xd^2 + yd^2) + B/2 (x yd - y xd) - k/2 (x^2 + y^2)
 *     E = qd . dL/dqd - L = m/2 |v|^2 + k/2 |r|^2 (the linear term drops
 *     out; E is not T - L for any split the library could guess), T and V
 *     are NaN, and the accelerations are m xdd = B yd - k x, m ydd = -B xd
 *     - k y (1e-14). Along a 5 s RK4 run E stays within 1e-11 relative.
 *  3. Damping: the open double pendulum with R = c/2 (thd1^2 + thd2^2)
 *     (parameter c added to the shared model): P = -c (thd1^2 + thd2^2) at
 *     random states; along a 5 s RK4 run (dt 1e-3) E + W stays within 1e-8
 *     J of E0 while E drops by more than 1 J (20 J) and W never decreases.
 *     The same for the damped four-bar within 2e-8 J (E drops by 40 J):
 *     constraint forces do no work, and projection (on) removes no
 *     measurable energy.
 *  4. Forcing: the spring pendulum with Q = (A sin(w t) - b rd, B0 cos(w
 *     t)): P = rd Q_r + thd Q_th at random (t, x); along a 5 s run E + W
 *     stays constant (1e-9 relative to the range of E, 6.5 J) while E
 *     changes.
 */
#include <math.h>
#include <string.h>

#include "check.h"
#include "core_support.h"
#include "eom_models.h"
#include "support_num.h"
#include "support_rng.h"

/* ---- 1: natural systems ------------------------------------------------- */

typedef void (*energy_fn)(const double *x, double *T, double *V);

static double sp_m = 1.3, sp_k = 40.0, sp_r0 = 0.9, sp_g = 9.81;

static void sp_energy(const double *x, double *T, double *V)
{
    *T = 0.5 * sp_m * (x[2] * x[2] + x[0] * x[0] * x[3] * x[3]);
    *V = 0.5 * sp_k * (x[0] - sp_r0) * (x[0] - sp_r0) +
         sp_m * sp_g * (sp_r0 - x[0] * cos(x[1]));
}

static core_chain dp_chain;

static void dp_energy(const double *x, double *T, double *V)
{
    *T = core_chain_T(&dp_chain, x);
    *V = core_chain_V(&dp_chain, x);
}

static core_chain fb_chain;

static void fb_energy(const double *x, double *T, double *V)
{
    *T = core_chain_T(&fb_chain, x);
    *V = core_chain_V(&fb_chain, x);
}

static const double bead_m = 0.4, bead_l = 1.1, bead_g = 9.81;

static void bead_energy(const double *x, double *T, double *V)
{
    *T = 0.5 * bead_m * (x[2] * x[2] + x[3] * x[3]);
    *V = bead_m * bead_g * x[1];
}

static void check_natural(const char *name, eom_system *s, energy_fn f,
                          double qrange, rng *g)
{
    const int n = eom_system_ncoords(s);
    double worst = 0.0;
    int k, i;
    CHECK(n <= CORE_NMAX);
    CHECK_INT(eom_system_has_tv(s), 1);
    for (k = 0; k < 50; k++) {
        double x[2 * CORE_NMAX], T, V, sc, e;
        eom_energy en;
        for (i = 0; i < n; i++) {
            x[i] = rng_range(g, -qrange, qrange);
            x[n + i] = rng_range(g, -3.0, 3.0);
        }
        if (f == sp_energy)
            x[0] = rng_range(g, 0.2, 2.0); /* r > 0 */
        f(x, &T, &V);
        sc = fmax(1.0, fabs(T) + fabs(V));
        CHECK_INT(eom_energy_at(s, 0.0, x, &en), EOM_OK);
        e = fmax(fmax(fabs(en.T - T), fabs(en.V - V)),
                 fmax(fabs(en.L - (T - V)), fabs(en.E - (T + V)))) / sc;
        worst = fmax(worst, e);
        check_count_++;
        if (!(e <= 1e-13))
            CHECK_FAIL_("%s, state %d: T %.17g V %.17g L %.17g E %.17g vs "
                        "T %.17g V %.17g", name, k, en.T, en.V, en.L, en.E,
                        T, V);
        CHECK(en.P == 0.0);
    }
    printf("%s: T, V, L, E within %.3g of the hand energies\n", name, worst);
}

static void natural_systems(rng *g)
{
    const double m2[2] = {1.2, 0.7}, l2[2] = {0.9, 1.4}, z[3] = {0, 0, 0};
    eom_system *s;
    int i;

    s = core_system(eom_models_spring_pendulum(sp_m, sp_k, sp_r0, sp_g));
    if (s)
        check_natural("spring pendulum", s, sp_energy, CORE_PI, g);
    eom_system_free(&s);

    memset(&dp_chain, 0, sizeof dp_chain);
    dp_chain.n = 2;
    for (i = 0; i < 2; i++) {
        dp_chain.m[i] = m2[i];
        dp_chain.l[i] = l2[i];
    }
    dp_chain.g = 9.81;
    s = core_system(eom_models_rod_chain(2, m2, l2, z, 9.81, 0, 0.0));
    if (s)
        check_natural("double pendulum", s, dp_energy, CORE_PI, g);
    eom_system_free(&s);

    /* the energies need not be consistent states */
    fb_chain = fourbar_closed_form();
    s = fourbar_system();
    if (s)
        check_natural("four-bar", s, fb_energy, CORE_PI, g);
    eom_system_free(&s);

    s = core_system(eom_models_bead_on_circle(bead_m, bead_l, bead_g));
    if (s)
        check_natural("bead", s, bead_energy, 2.0, g);
    eom_system_free(&s);
}

/* ---- 2: a gyroscopic Lagrangian ----------------------------------------- */

static int mag_L(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val x = eom_q(c, 0), y = eom_q(c, 1);
    tp_val xd = eom_qd(c, 0), yd = eom_qd(c, 1);
    tp_val m = eom_param(c, "m"), B = eom_param(c, "B"), k = eom_param(c, "k");
    tp_val v2 = tp_add(R, tp_sqr(R, xd), tp_sqr(R, yd));
    tp_val r2 = tp_add(R, tp_sqr(R, x), tp_sqr(R, y));
    tp_val gyro = tp_sub(R, tp_mul(R, x, yd), tp_mul(R, y, xd));
    (void)user;
    *out = tp_sub(R, tp_add(R, tp_mul(R, tp_mulc(R, m, 0.5), v2),
                            tp_mul(R, tp_mulc(R, B, 0.5), gyro)),
                  tp_mul(R, tp_mulc(R, k, 0.5), r2));
    return 0;
}

static void gyroscopic(rng *g)
{
    const double m = 0.8, B = 3.0, k = 5.0;
    eom_model *md = NULL;
    eom_system *s;
    eom_integ *it = NULL;
    eom_opts o;
    double x[4], xd[4], E0, Emax = 0.0;
    int kk;

    CHECK_INT(eom_model_new(&md), EOM_OK);
    eom_model_add_coord(md, "x", "m", 1.0, 0.0);
    eom_model_add_coord(md, "y", "m", 0.0, 0.5);
    eom_model_add_param(md, "m", "kg", m, NULL);
    eom_model_add_param(md, "B", "kg/s", B, "charge times field");
    eom_model_add_param(md, "k", "N/m", k, NULL);
    CHECK_INT(eom_model_set_lagrangian(md, mag_L, NULL), EOM_OK);
    s = core_system(md);
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(eom_system_has_tv(s), 0);
    for (kk = 0; kk < 50; kk++) {
        eom_energy en;
        double E, L, ax, ay, sc;
        int i;
        for (i = 0; i < 4; i++)
            x[i] = rng_range(g, -2.0, 2.0);
        E = 0.5 * m * (x[2] * x[2] + x[3] * x[3]) +
            0.5 * k * (x[0] * x[0] + x[1] * x[1]);
        L = 0.5 * m * (x[2] * x[2] + x[3] * x[3]) +
            0.5 * B * (x[0] * x[3] - x[1] * x[2]) -
            0.5 * k * (x[0] * x[0] + x[1] * x[1]);
        CHECK_INT(eom_energy_at(s, 0.0, x, &en), EOM_OK);
        CHECK(isnan(en.T) && isnan(en.V));
        CHECK_NEAR(en.E, E, 1e-14 * fmax(1.0, E));
        CHECK_NEAR(en.L, L, 1e-14 * fmax(1.0, fabs(L) + E));
        CHECK(en.P == 0.0);
        ax = (B * x[3] - k * x[0]) / m;
        ay = (-B * x[2] - k * x[1]) / m;
        sc = (fabs(B) * 4.0 + k * 4.0) / m;
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        CHECK_NEAR(xd[2], ax, 1e-14 * sc);
        CHECK_NEAR(xd[3], ay, 1e-14 * sc);
    }
    /* E is conserved along the motion */
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    E0 = 0.5 * m * (x[2] * x[2] + x[3] * x[3]) +
         0.5 * k * (x[0] * x[0] + x[1] * x[1]);
    eom_opts_default(&o);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    for (kk = 1; it && kk <= 50; kk++) {
        eom_energy en;
        CHECK_INT(eom_integ_advance(it, 0.1 * kk, x, NULL), EOM_OK);
        CHECK_INT(eom_energy_at(s, 0.1 * kk, x, &en), EOM_OK);
        Emax = fmax(Emax, fabs(en.E - E0));
    }
    printf("gyroscopic: max |E - E0| = %.3g (E0 = %.3g)\n", Emax, E0);
    CHECK(Emax <= 1e-11 * E0);
    eom_integ_free(&it);
    eom_system_free(&s);
}

/* ---- 3: damping --------------------------------------------------------- */

static int damp_R(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val sum = tp_const(R, 0.0);
    int i;
    (void)user;
    for (i = 0; i < eom_ncoords(c); i++)
        sum = tp_add(R, sum, tp_sqr(R, eom_qd(c, i)));
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "c"), 0.5), sum);
    return 0;
}

/* Add R = c/2 sum qd^2 to a model, with parameter c. */
static eom_model *damped(eom_model *md, double c)
{
    if (!md)
        return NULL;
    eom_model_add_param(md, "c", "N m s", c, "joint damping");
    eom_model_set_dissipation(md, damp_R, NULL);
    return md;
}

/* Run from x0 for tend seconds; E + W against E0, W monotone. */
static void damped_run(const char *name, eom_system *s, const double *x0,
                       double tend, double tol)
{
    eom_integ *it = NULL;
    eom_opts o;
    eom_energy en;
    double x[2 * CORE_NMAX], W, Wprev = 0.0, E0, drift = 0.0;
    int k, monotone = 1;
    const int nsamples = (int)lround(tend / 0.05);

    CHECK_INT(eom_energy_at(s, 0.0, x0, &en), EOM_OK);
    E0 = en.E;
    eom_opts_default(&o);
    o.dt = 1e-3;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_OK);
    if (!it)
        return;
    for (k = 1; k <= nsamples; k++) {
        if (eom_integ_advance(it, 0.05 * k, x, &W) != EOM_OK) {
            CHECK_FAIL_("%s: %s", name, eom_integ_errmsg(it));
            break;
        }
        CHECK_INT(eom_energy_at(s, 0.05 * k, x, &en), EOM_OK);
        drift = fmax(drift, fabs(en.E + W - E0));
        if (W < Wprev)
            monotone = 0;
        Wprev = W;
    }
    printf("%s: E0 %.6g, E %.6g, W %.6g, max |E + W - E0| %.3g\n", name, E0,
           en.E, Wprev, drift);
    CHECK(monotone);
    CHECK(Wprev > 1.0);
    CHECK(E0 - en.E > 1.0);
    CHECK(drift <= tol);
    eom_integ_free(&it);
}

static void damping(rng *g)
{
    const double m2[2] = {1.2, 0.7}, l2[2] = {0.9, 1.4}, th0[2] = {0.0, 0.5};
    const double c = 0.4;
    eom_system *s = core_system(damped(
        eom_models_rod_chain(2, m2, l2, th0, 9.81, 0, 0.0), c));
    double x[6];
    int k;
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(eom_system_has_dissipation(s), 1);
    for (k = 0; k < 50; k++) {
        eom_energy en;
        double P;
        int i;
        for (i = 0; i < 4; i++)
            x[i] = rng_range(g, -3.0, 3.0);
        P = -c * (x[2] * x[2] + x[3] * x[3]);
        CHECK_INT(eom_energy_at(s, 0.0, x, &en), EOM_OK);
        CHECK_NEAR(en.P, P, 1e-15 * fabs(P));
    }
    /* P follows the parameter */
    CHECK_INT(core_set(s, "c", 2.0 * c), EOM_OK);
    {
        eom_energy en;
        const double xs[4] = {0.1, 0.2, 1.0, -2.0};
        CHECK_INT(eom_energy_at(s, 0.0, xs, &en), EOM_OK);
        CHECK_NEAR(en.P, -2.0 * c * 5.0, 1e-15);
    }
    CHECK_INT(core_set(s, "c", c), EOM_OK);
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    x[2] = 3.0; /* start with some speed */
    damped_run("damped double pendulum", s, x, 5.0, 1e-8);
    eom_system_free(&s);

    /* the damped four-bar: constraint forces do no work */
    {
        core_chain fb = fourbar_closed_form();
        const double th0f[3] = {1.5, 0.3, -1.3};
        double xf[6];
        s = core_system(damped(eom_models_rod_chain(3, FB_M, FB_L, th0f,
                                                    FB_G, 1, FB_D),
                               c));
        CHECK(s != NULL);
        if (!s)
            return;
        fourbar_assemble(&fb, 1.5, 1, 3.0, xf);
        damped_run("damped four-bar", s, xf, 5.0, 2e-8);
        eom_system_free(&s);
    }
}

/* ---- 4: forcing --------------------------------------------------------- */

typedef struct forcing {
    double A, B0, w, b;
} forcing;

static int force_Q(eom_ctx *c, void *user, tp_val *out)
{
    const forcing *f = user;
    tp_rec *R = eom_rec(c);
    tp_val wt = tp_mulc(R, eom_time(c), f->w);
    out[0] = tp_sub(R, tp_mulc(R, tp_sin(R, wt), f->A),
                    tp_mulc(R, eom_qd(c, 0), f->b));
    out[1] = tp_mulc(R, tp_cos(R, wt), f->B0);
    return 0;
}

static void forcing_case(rng *g)
{
    static forcing f = {3.0, 1.5, 4.0, 0.3};
    eom_model *md = eom_models_spring_pendulum(1.0, 30.0, 1.0, 9.81);
    eom_system *s;
    eom_integ *it = NULL;
    eom_opts o;
    eom_energy en;
    double x[4], W, E0, drift = 0.0, Emin = INFINITY, Emax = -INFINITY;
    int k;

    CHECK(md != NULL);
    if (!md)
        return;
    CHECK_INT(eom_model_set_forces(md, force_Q, &f), EOM_OK);
    s = core_system(md);
    CHECK(s != NULL);
    if (!s)
        return;
    for (k = 0; k < 50; k++) {
        const double t = rng_range(g, 0.0, 10.0);
        double P;
        x[0] = rng_range(g, 0.5, 2.0);
        x[1] = rng_range(g, -3.0, 3.0);
        x[2] = rng_range(g, -3.0, 3.0);
        x[3] = rng_range(g, -3.0, 3.0);
        P = x[2] * (f.A * sin(f.w * t) - f.b * x[2]) +
            x[3] * f.B0 * cos(f.w * t);
        CHECK_INT(eom_energy_at(s, t, x, &en), EOM_OK);
        CHECK_NEAR(en.P, P, 1e-14 * (fabs(f.A) + fabs(f.B0) + 10.0) * 3.0);
    }
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    CHECK_INT(eom_energy_at(s, 0.0, x, &en), EOM_OK);
    E0 = en.E;
    eom_opts_default(&o);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    for (k = 1; it && k <= 100; k++) {
        CHECK_INT(eom_integ_advance(it, 0.05 * k, x, &W), EOM_OK);
        CHECK_INT(eom_energy_at(s, 0.05 * k, x, &en), EOM_OK);
        drift = fmax(drift, fabs(en.E + W - E0));
        Emin = fmin(Emin, en.E);
        Emax = fmax(Emax, en.E);
    }
    printf("forced spring pendulum: E in [%.6g, %.6g], max |E + W - E0| "
           "%.3g\n", Emin, Emax, drift);
    CHECK(Emax - Emin > 0.5);
    CHECK(drift <= 1e-9 * (Emax - Emin));
    eom_integ_free(&it);
    eom_system_free(&s);
}

int main(void)
{
    rng g = rng_seed(31337);
    natural_systems(&g);
    gyroscopic(&g);
    damping(&g);
    forcing_case(&g);
    CHECK_DONE();
}
