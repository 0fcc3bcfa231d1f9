/* test_chain_structural.c - structural damping of flexible links
 * (eom/chain.h): a link pinned at both ends, with one mode, is a single
 * damped oscillator (its angle is held by the pins), so
 *   - the linearization's reduced damping is 2 zeta sqrt(k m_modal) with
 *     m_modal = m/2 and k = EI pi^4 / (2 L^3), or a m_modal + b k for
 *     Rayleigh damping: closed forms;
 *   - the mode's motion from a released deflection is
 *     q0 e^(-zeta w t) (cos w_d t + zeta w / w_d sin w_d t),
 *     w = sqrt(k / m_modal), w_d = w sqrt(1 - zeta^2): integrated and
 *     compared at several times;
 *   - E + W stays constant, and the angles are never damped (a free
 *     rigid rotation of an open link keeps its speed). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom/chain.h"

static const double pi = 3.14159265358979323846;
static const double m = 2.0, L = 3.0, EI = 50.0;

static eom_system *link(int closed, double zeta, double a, double b,
                        double q0, double thd0)
{
    eom_chain_spec sp;
    eom_model *mo = NULL;
    eom_system *s = NULL;
    char err[256];
    double th = 0.0;
    memset(&sp, 0, sizeof sp);
    sp.links = 1;
    sp.modes_all = 1;
    sp.closed = closed;
    sp.m = m;
    sp.L = L;
    sp.EI = EI;
    sp.D = L;
    sp.structural = 1;
    sp.zeta = zeta;
    sp.ray_a = a;
    sp.ray_b = b;
    sp.theta0 = &th;
    sp.theta0_dot = &thd0;
    sp.q0 = &q0;
    if (eom_model_new(&mo) == EOM_OK && eom_chain_add(mo, &sp) >= 0 &&
        eom_system_new(&s, mo, err, sizeof err) != EOM_OK)
        CHECK_FAIL_("%s", err);
    eom_model_free(&mo);
    return s;
}

static void linearized(double zeta, double a, double b)
{
    const double mm = m / 2, k = EI * pi * pi * pi * pi / (2 * L * L * L);
    eom_system *s = link(1, zeta, a, b, 0.0, 0.0);
    eom_linear lin;
    double q[2] = {0.0, 0.0};
    if (!s)
        return;
    memset(&lin, 0, sizeof lin);
    CHECK_INT(eom_linearize(s, q, &lin), EOM_OK);
    CHECK_INT(lin.nr, 1);
    if (lin.nr == 1) {
        CHECK_NEAR(lin.Mr[0], mm, 1e-12);
        CHECK_NEAR(lin.Kr[0], k, 1e-12);
        CHECK_NEAR(lin.Dr[0], 2 * zeta * sqrt(k * mm) + a * mm + b * k,
                   1e-12);
    }
    eom_linear_free(&lin);
    eom_system_free(&s);
}

static void released(double zeta)
{
    const double mm = m / 2, k = EI * pi * pi * pi * pi / (2 * L * L * L);
    const double w = sqrt(k / mm), wd = w * sqrt(1 - zeta * zeta);
    const double q0 = 0.01;
    eom_system *s = link(1, zeta, 0.0, 0.0, q0, 0.0);
    eom_integ *it = NULL;
    eom_opts o;
    eom_energy e0, e;
    double x[4], W = 0.0;
    int k2;
    if (!s)
        return;
    eom_opts_default(&o);
    o.method = EOM_ERK;
    o.rtol = 1e-11;
    o.atol = 1e-13;
    CHECK(eom_initial_state(s, x) == EOM_OK);
    CHECK(eom_energy_at(s, 0.0, x, &e0) == EOM_OK);
    CHECK(eom_integ_new(&it, s, &o, 0.0, x) == EOM_OK);
    for (k2 = 1; k2 <= 8; k2++) {
        const double t = 0.25 * k2;
        const double env = q0 * exp(-zeta * w * t);
        CHECK(eom_integ_advance(it, t, x, &W) == EOM_OK);
        CHECK_NEAR(x[1], env * (cos(wd * t) + zeta * w / wd * sin(wd * t)),
                   1e-9);
        CHECK(fabs(x[0]) < 1e-12); /* the pins hold the angle */
        CHECK(eom_energy_at(s, t, x, &e) == EOM_OK);
        CHECK_NEAR(e.E + W, e0.E, 1e-9);
    }
    CHECK(zeta == 0.0 || W > 0.5 * e0.E); /* most of it dissipated */
    eom_integ_free(&it);
    eom_system_free(&s);
}

/* An open link spinning undeformed: structural damping leaves the angle
 * alone, so nothing is dissipated. */
static void rigid_spin(void)
{
    eom_system *s = link(0, 0.1, 0.5, 1e-3, 0.0, 2.0);
    eom_integ *it = NULL;
    eom_opts o;
    double x[4], W = 0.0;
    if (!s)
        return;
    eom_opts_default(&o);
    o.method = EOM_ERK;
    o.rtol = 1e-11;
    o.atol = 1e-13;
    CHECK(eom_initial_state(s, x) == EOM_OK);
    CHECK(eom_integ_new(&it, s, &o, 0.0, x) == EOM_OK);
    CHECK(eom_integ_advance(it, 3.0, x, &W) == EOM_OK);
    CHECK_NEAR(x[2], 2.0, 1e-9);
    CHECK(fabs(W) < 1e-12);
    eom_integ_free(&it);
    eom_system_free(&s);
}

int main(void)
{
    linearized(0.05, 0.0, 0.0);
    linearized(0.0, 0.3, 1e-4);
    linearized(0.02, 0.1, 2e-4);
    released(0.02);
    released(0.3);
    released(0.0);
    rigid_spin();
    CHECK_DONE();
}
