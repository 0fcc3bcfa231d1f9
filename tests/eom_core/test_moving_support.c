/* test_moving_support.c - explicit time in T and V: a pendulum (mass m,
 * length l, angle th from the downward vertical) whose pivot is driven up
 * and down as y0(t) = a sin(w t), written with the time in its energies:
 *
 *   bob  (l sin th, y0 - l cos th)
 *   T  = m/2 (l^2 thd^2 + 2 l y0' sin th thd + y0'^2)
 *   V  = m g (y0 - l cos th)
 *
 * Derived by hand: d/dt dL/dthd = m l^2 thdd + m l y0'' sin th
 * + m l y0' cos th thd, dL/dth = m l y0' cos th thd - m g l sin th, so
 *
 *   thdd = -(g + y0'') sin th / l,   y0'' = -a w^2 sin(w t),
 *
 * the pendulum in the pivot's accelerating frame. The explicit-time part
 * of the energy balance: E = thd dL/dthd - L = m/2 l^2 thd^2 - m/2 y0'^2
 * + V and
 *   dL/dt = m (y0'' l sin th thd + y0' y0'') - m g y0'
 * so dE/dt = -dL/dt (eom_energy.Pt).
 *
 * Checked: accelerations at 60 states and times, and the Lagrangian form
 * of the same model, within 1e-13 of the largest term; M; E, T, V and Pt
 * against the formulas; a probe that reads the time, at the system's time
 * (eom_set_time) and at the time the integrator leaves; an RK4 run of 3 s
 * against RK4 of the hand equation with the same steps (a wrong stage time
 * or a sign on d2L/dqd dt shows at once), and E + W over the run. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"
#include "support_rng.h"

typedef struct prm {
    double m, l, g, a, w;
} prm;

static const prm P0 = {0.7, 1.3, 9.81, 0.2, 7.0};

/* y0' and y0'' recorded from the time: the pivot's velocity. */
static tp_val pivot_rate(eom_ctx *c)
{
    tp_rec *r = eom_rec(c);
    tp_val w = eom_param(c, "w");
    return tp_mul(r, tp_mul(r, eom_param(c, "a"), w),
                  tp_cos(r, tp_mul(r, w, eom_time(c))));
}

static int kinetic(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    tp_val m = eom_param(c, "m"), l = eom_param(c, "l");
    tp_val th = eom_q(c, 0), thd = eom_qd(c, 0), yd = pivot_rate(c);
    /* velocity of the bob: (l cos th thd, y0' + l sin th thd) */
    tp_val vx = tp_mul(r, tp_mul(r, l, tp_cos(r, th)), thd);
    tp_val vy = tp_add(r, yd, tp_mul(r, tp_mul(r, l, tp_sin(r, th)), thd));
    (void)user;
    *out = tp_mul(r, tp_mulc(r, m, 0.5),
                  tp_add(r, tp_sqr(r, vx), tp_sqr(r, vy)));
    return 0;
}

static tp_val pivot(eom_ctx *c)
{
    tp_rec *r = eom_rec(c);
    return tp_mul(r, eom_param(c, "a"),
                  tp_sin(r, tp_mul(r, eom_param(c, "w"), eom_time(c))));
}

static int potential(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    tp_val y = tp_sub(r, pivot(c),
                      tp_mul(r, eom_param(c, "l"), tp_cos(r, eom_q(c, 0))));
    (void)user;
    *out = tp_mul(r, tp_mul(r, eom_param(c, "m"), eom_param(c, "g")), y);
    return 0;
}

static int lagrangian(eom_ctx *c, void *user, tp_val *out)
{
    tp_val T, V;
    kinetic(c, user, &T);
    potential(c, user, &V);
    *out = tp_sub(eom_rec(c), T, V);
    return 0;
}

static int pivot_probe(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = pivot(c);
    return 0;
}

static eom_system *build(int whole_L)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    char msg[256];
    eom_model_new(&md);
    eom_model_add_coord(md, "th", "rad", 0.4, 0.0);
    eom_model_add_param(md, "m", "kg", P0.m, NULL);
    eom_model_add_param(md, "l", "m", P0.l, NULL);
    eom_model_add_param(md, "g", "m/s^2", P0.g, NULL);
    eom_model_add_param(md, "a", "m", P0.a, NULL);
    eom_model_add_param(md, "w", "rad/s", P0.w, NULL);
    if (whole_L) {
        eom_model_set_lagrangian(md, lagrangian, NULL);
    } else {
        eom_model_set_kinetic(md, kinetic, NULL);
        eom_model_set_potential(md, potential, NULL);
        eom_model_add_probe(md, "pivot", "m", pivot_probe, NULL);
    }
    if (eom_system_new(&s, md, msg, sizeof msg) != EOM_OK)
        CHECK_FAIL_("eom_system_new: %s", msg);
    eom_model_free(&md);
    return s;
}

/* The hand equation. */
static double hand_thdd(const prm *p, double t, double th)
{
    const double y0dd = -p->a * p->w * p->w * sin(p->w * t);
    return -(p->g + y0dd) * sin(th) / p->l;
}

static void accelerations(eom_system *s, const char *what)
{
    rng g = rng_seed(7001);
    double worst = 0.0;
    int k;
    for (k = 0; k < 60; k++) {
        const double t = rng_range(&g, -3.0, 10.0);
        double x[2], xd[2], ref, scale;
        x[0] = rng_range(&g, -3.0, 3.0);
        x[1] = rng_range(&g, -5.0, 5.0);
        CHECK_INT(eom_rhs(s, t, x, xd), EOM_OK);
        ref = hand_thdd(&P0, t, x[0]);
        scale = (P0.g + P0.a * P0.w * P0.w) / P0.l;
        CHECK(xd[0] == x[1]);
        worst = fmax(worst, fabs(xd[1] - ref) / scale);
    }
    printf("%s: worst relative error of thdd %.2e\n", what, worst);
    CHECK(worst <= 1e-13);
}

/* E, T, V, P and Pt at a few states against the formulas. */
static void energies(eom_system *s)
{
    const prm *p = &P0;
    rng g = rng_seed(7002);
    int k;
    for (k = 0; k < 10; k++) {
        const double t = rng_range(&g, 0.0, 5.0);
        const double th = rng_range(&g, -2.0, 2.0), thd = rng_range(&g, -4, 4);
        const double y0 = p->a * sin(p->w * t);
        const double y1 = p->a * p->w * cos(p->w * t);
        const double y2 = -p->a * p->w * p->w * sin(p->w * t);
        const double T = 0.5 * p->m *
                         (p->l * p->l * thd * thd +
                          2.0 * p->l * y1 * sin(th) * thd + y1 * y1);
        const double V = p->m * p->g * (y0 - p->l * cos(th));
        const double E = 0.5 * p->m * p->l * p->l * thd * thd -
                         0.5 * p->m * y1 * y1 + V;
        const double dLdt = p->m * (y2 * p->l * sin(th) * thd + y1 * y2) -
                            p->m * p->g * y1;
        double x[2] = {th, thd}, M = 0.0, probe = 0.0;
        eom_energy e;
        CHECK_INT(eom_energy_at(s, t, x, &e), EOM_OK);
        CHECK_NEAR(e.T, T, 1e-13);
        CHECK_NEAR(e.V, V, 1e-13);
        CHECK_NEAR(e.L, T - V, 1e-13);
        CHECK_NEAR(e.E, E, 1e-13);
        CHECK_NEAR(e.Pt, -dLdt, 1e-12);
        CHECK_NEAR(e.P, -dLdt, 1e-12); /* no other force */
        CHECK_INT(eom_mass_matrix(s, x, &M), EOM_OK);
        CHECK_NEAR(M, p->m * p->l * p->l, 1e-14);
        /* the probe reads the system's time */
        CHECK_INT(eom_set_time(s, t), EOM_OK);
        CHECK(eom_get_time(s) == t);
        CHECK_INT(eom_probes_at(s, x, &probe), EOM_OK);
        CHECK_NEAR(probe, y0, 1e-15);
    }
    CHECK_INT(eom_set_time(s, NAN), EOM_ERR_NONFINITE);
    CHECK_INT(eom_set_time(s, 0.0), EOM_OK);
}

/* RK4 of the hand equation with the library's steps, y = (th, thd). */
static void hand_rk4(const prm *p, double t, double h, double *y)
{
    double k1[2], k2[2], k3[2], k4[2];
    k1[0] = y[1];
    k1[1] = hand_thdd(p, t, y[0]);
    k2[0] = y[1] + 0.5 * h * k1[1];
    k2[1] = hand_thdd(p, t + 0.5 * h, y[0] + 0.5 * h * k1[0]);
    k3[0] = y[1] + 0.5 * h * k2[1];
    k3[1] = hand_thdd(p, t + 0.5 * h, y[0] + 0.5 * h * k2[0]);
    k4[0] = y[1] + h * k3[1];
    k4[1] = hand_thdd(p, t + h, y[0] + h * k3[0]);
    y[0] += h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]);
    y[1] += h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]);
}

static void trajectory(eom_system *s)
{
    const double h = 1e-3, t0 = 0.25;
    double x[2] = {2.5, -1.0}, y[2] = {2.5, -1.0}, W = 0.0, worst = 0.0;
    double probe = 0.0, drift = 0.0;
    eom_energy e0, e;
    eom_integ *it = NULL;
    eom_opts o;
    int k, j;
    eom_opts_default(&o);
    o.dt = h;
    CHECK_INT(eom_energy_at(s, t0, x, &e0), EOM_OK);
    CHECK_INT(eom_integ_new(&it, s, &o, t0, x), EOM_OK);
    CHECK(eom_get_time(s) == t0);
    for (k = 1; k <= 30 && it; k++) {
        const double t = t0 + 0.1 * k;
        if (eom_integ_advance(it, t, x, &W) != EOM_OK) {
            CHECK_FAIL_("advance: %s", eom_integ_errmsg(it));
            break;
        }
        for (j = 0; j < 100; j++)
            hand_rk4(&P0, t0 + 0.1 * (k - 1) + 1e-3 * j, h, y);
        worst = fmax(worst, fmax(fabs(x[0] - y[0]), fabs(x[1] - y[1])));
        /* the integrator leaves the system at the time it returns */
        CHECK(eom_get_time(s) == t);
        CHECK_INT(eom_probes_at(s, x, &probe), EOM_OK);
        CHECK_NEAR(probe, P0.a * sin(P0.w * t), 1e-15);
        CHECK_INT(eom_energy_at(s, t, x, &e), EOM_OK);
        drift = fmax(drift, fabs(e.E + W - e0.E));
    }
    eom_integ_free(&it);
    printf("rk4 vs hand rk4 over 3 s: max difference %.2e; max |E + W - "
           "E0| %.2e J (E0 %.3f J)\n", worst, drift, e0.E);
    CHECK(worst <= 1e-11);
    /* RK4's own error in E + W at dt = 1e-3 */
    CHECK(drift <= 1e-8);
}

int main(void)
{
    eom_system *s = build(0), *sl = build(1), *c = NULL;
    double x[2] = {0.3, 0.7}, xa[2], xb[2];
    if (!s || !sl) {
        eom_system_free(&s);
        eom_system_free(&sl);
        CHECK_DONE();
    }
    CHECK_INT(eom_system_reads_time(s), 1);
    CHECK_INT(eom_system_reads_time(sl), 1);
    accelerations(s, "T and V");
    accelerations(sl, "L");
    energies(s);
    trajectory(s);
    /* a clone shares the tapes with the time and evaluates alike */
    CHECK_INT(eom_system_clone(&c, s, NULL, 0), EOM_OK);
    if (c) {
        CHECK_INT(eom_rhs(s, 1.7, x, xa), EOM_OK);
        CHECK_INT(eom_rhs(c, 1.7, x, xb), EOM_OK);
        CHECK(memcmp(xa, xb, sizeof xa) == 0);
        CHECK_INT(eom_system_reads_time(c), 1);
    }
    eom_system_free(&c);
    eom_system_free(&s);
    eom_system_free(&sl);
    CHECK_DONE();
}
