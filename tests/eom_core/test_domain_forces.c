/* test_domain_forces.c - a state outside the model's domain is an error,
 * the generalized forces add to the dissipation force (and need set only
 * their nonzero entries), and eom_model_run_lagrangian keeps its contract
 * on x.
 *
 * Domain: T = xd^2 / 2, V = log(x). At x = -1, L is NaN although every
 * derivative the equations use (dV/dx = 1/x) is finite: only a check of L
 * itself tells.
 *
 * Forces: a free point mass (x, y) with Rayleigh dissipation
 * R = c (xd^2 + yd^2) / 2 and a force Q that sets only its y entry,
 * Q = (unset, F sin(w t)). By hand:
 *   m xdd = -c xd,  m ydd = -c yd + F sin(w t),
 *   P = xd (-c xd) + yd (-c yd + F sin(w t)). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"

/* ---- domain ------------------------------------------------------------ */

static int dom_T(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_mulc(eom_rec(c), tp_sqr(eom_rec(c), eom_qd(c, 0)), 0.5);
    return 0;
}

static int dom_V(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_log(eom_rec(c), eom_q(c, 0));
    return 0;
}

static eom_system *domain_system(void)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    char msg[256];
    if (eom_model_new(&md) != EOM_OK)
        return NULL;
    eom_model_add_coord(md, "x", "m", 2.0, 0.0);
    eom_model_set_kinetic(md, dom_T, NULL);
    eom_model_set_potential(md, dom_V, NULL);
    if (eom_system_new(&s, md, msg, sizeof msg) != EOM_OK)
        fprintf(stderr, "eom_system_new: %s\n", msg);
    eom_model_free(&md);
    return s;
}

static void test_domain(void)
{
    eom_system *s = domain_system();
    double inside[2] = {2.0, 0.3}, outside[2] = {-1.0, 0.3}, xd[2], M[1];
    eom_energy e;
    CHECK(s != NULL);
    if (!s)
        return;
    /* inside: qdd = -dV/dx = -1/x */
    CHECK_INT(eom_rhs(s, 0.0, inside, xd), EOM_OK);
    CHECK_NEAR(xd[1], -0.5, 1e-15);
    /* outside: every evaluation says so, with a message */
    CHECK_INT(eom_rhs(s, 0.0, outside, xd), EOM_ERR_NONFINITE);
    CHECK(strstr(eom_system_errmsg(s), "not finite") != NULL);
    CHECK_INT(eom_mass_matrix(s, outside, M), EOM_ERR_NONFINITE);
    CHECK_INT(eom_energy_at(s, 0.0, outside, &e), EOM_ERR_NONFINITE);
    eom_system_free(&s);
}

/* An integrator started outside the domain fails at once and says why;
 * it never returns a trajectory. */
static void test_domain_integrator(void)
{
    eom_system *s = domain_system();
    eom_integ *it = NULL;
    eom_opts o;
    double x0[2] = {-1.0, 0.0}, x[2];
    int rc, m;
    CHECK(s != NULL);
    if (!s)
        return;
    for (m = EOM_RK4; m <= EOM_IDA; m++) {
        eom_opts_default(&o);
        o.method = (eom_method)m;
        rc = eom_integ_new(&it, s, &o, 0.0, x0);
        if (rc == EOM_OK)
            rc = eom_integ_advance(it, 0.1, x, NULL);
        if (rc == EOM_OK)
            fprintf(stderr, "%s integrated outside the domain\n",
                    eom_method_name((eom_method)m));
        CHECK(rc < 0);
        eom_integ_free(&it);
    }
    eom_system_free(&s);
}

/* ---- forces ------------------------------------------------------------ */

enum { FM = 0, FC, FF, FW }; /* parameter order below */
static const double fpar[4] = {2.0, 0.7, 3.0, 5.0};

static int f_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "m"), 0.5),
                  tp_add(R, tp_sqr(R, eom_qd(c, 0)),
                         tp_sqr(R, eom_qd(c, 1))));
    return 0;
}

static int f_R(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "c"), 0.5),
                  tp_add(R, tp_sqr(R, eom_qd(c, 0)),
                         tp_sqr(R, eom_qd(c, 1))));
    return 0;
}

/* sets only Q[1]: Q[0] must come out as 0 */
static int f_Q(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    out[1] = tp_mul(R, eom_param(c, "F"),
                    tp_sin(R, tp_mul(R, eom_param(c, "w"), eom_time(c))));
    return 0;
}

static void test_forces(void)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    char msg[256];
    const double m = fpar[FM], c = fpar[FC], F = fpar[FF], w = fpar[FW];
    const double t = 0.37, x[4] = {0.1, -0.2, 1.3, -0.4};
    double xd[4], f, P;
    eom_energy e;
    CHECK_INT(eom_model_new(&md), EOM_OK);
    eom_model_add_coord(md, "x", "m", 0.0, 0.0);
    eom_model_add_coord(md, "y", "m", 0.0, 0.0);
    eom_model_add_param(md, "m", "kg", m, NULL);
    eom_model_add_param(md, "c", "N s/m", c, NULL);
    eom_model_add_param(md, "F", "N", F, NULL);
    eom_model_add_param(md, "w", "1/s", w, NULL);
    eom_model_set_kinetic(md, f_T, NULL);
    eom_model_set_dissipation(md, f_R, NULL);
    eom_model_set_forces(md, f_Q, NULL);
    CHECK_INT(eom_system_new(&s, md, msg, sizeof msg), EOM_OK);
    eom_model_free(&md);
    if (!s) {
        fprintf(stderr, "eom_system_new: %s\n", msg);
        return;
    }
    f = F * sin(w * t);
    CHECK_INT(eom_rhs(s, t, x, xd), EOM_OK);
    CHECK_NEAR(xd[0], x[2], 0.0);
    CHECK_NEAR(xd[1], x[3], 0.0);
    CHECK_NEAR(xd[2], -c * x[2] / m, 1e-15);
    CHECK_NEAR(xd[3], (-c * x[3] + f) / m, 1e-15);
    P = x[2] * (-c * x[2]) + x[3] * (-c * x[3] + f);
    CHECK_INT(eom_energy_at(s, t, x, &e), EOM_OK);
    CHECK_NEAR(e.P, P, 1e-15);
    CHECK_NEAR(e.T, 0.5 * m * (x[2] * x[2] + x[3] * x[3]), 1e-15);
    eom_system_free(&s);
}

/* ---- eom_model_run_lagrangian and x ------------------------------------ */

static void test_run_lagrangian_x(void)
{
    eom_model *md = NULL;
    tp_rec *rec = NULL, *ev = NULL;
    tp_tape *tape = NULL;
    const double x[2] = {2.0, 0.5};
    double y;
    CHECK_INT(eom_model_new(&md), EOM_OK);
    eom_model_add_coord(md, "x", "m", 2.0, 0.0);
    eom_model_set_kinetic(md, dom_T, NULL);
    eom_model_set_potential(md, dom_V, NULL);
    /* the recorder needs no values: NULL x is documented as accepted */
    CHECK_INT(tp_recorder_new(&rec, 2, NULL, NULL), TP_OK);
    CHECK_INT(eom_model_run_lagrangian(md, rec, NULL), EOM_OK);
    CHECK_INT(tp_recorder_finish(rec, &tape), TP_OK);
    CHECK_INT(tp_tape_n_outputs(tape), 1);
    /* an evaluator needs them */
    CHECK_INT(tp_evaluator_new(&ev, 2, NULL), TP_OK);
    CHECK_INT(eom_model_run_lagrangian(md, ev, NULL), EOM_ERR_NULL);
    CHECK_INT(eom_model_run_lagrangian(md, ev, x), EOM_OK);
    CHECK_INT(tp_rec_output_value(ev, 0, &y), TP_OK);
    CHECK_NEAR(y, 0.5 * 0.25 - log(2.0), 1e-15);
    tp_tape_free(&tape);
    tp_rec_free(&rec);
    tp_rec_free(&ev);
    eom_model_free(&md);
}

int main(void)
{
    test_domain();
    test_domain_integrator();
    test_forces();
    test_run_lagrangian_x();
    CHECK_DONE();
}
