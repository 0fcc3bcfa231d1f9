/* test_mass_pivot.c - the refusals of a singular mass matrix, on both
 * routes of M (constant: formed and factored once; dense: every call),
 * with and without an integrator's pivot floor.
 *
 * The model: T = (qd1^2 + qd2^2) / 2 + c qd1 qd2, V = (q1^2 + q2^2) / 2,
 * so M = [1 c; c 1] (constant) and qdd = -M^-1 q, in closed form
 * qdd1 = -(q1 - c q2) / (1 - c^2), qdd2 = -(q2 - c q1) / (1 - c^2). The
 * relative pivot of q2 (L22^2 / M22) is 1 - c^2.
 *   - c = 0.5: eom_rhs gives the closed form (1e-15), and RK4 steps;
 *   - c = 1 - 1e-14 (pivot 2e-14): eom_rhs still solves (no floor), but
 *     an RK4 run (floor DBL_EPSILON / rtol) stops with
 *     EOM_ERR_SINGULAR_MASS, "singular to working precision", naming q2;
 *     after the run eom_rhs solves again (the floor is the run's own);
 *   - c = 1: M is singular: EOM_ERR_SINGULAR_MASS, "positive definite",
 *     naming q2.
 * Each on the route chosen by the library (constant) and on the dense
 * one (eom_system_set_mass_route between the calls). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"

#define HAS(msg, sub)                                                      \
    do {                                                                   \
        const char *m_ = (msg);                                            \
        check_count_++;                                                    \
        if (!strstr(m_, (sub)))                                            \
            CHECK_FAIL_("message \"%s\" lacks \"%s\"", m_, (sub));         \
    } while (0)

static int kinetic(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val a = eom_qd(c, 0), b = eom_qd(c, 1);
    (void)user;
    *out = tp_add(R, tp_mulc(R, tp_add(R, tp_sqr(R, a), tp_sqr(R, b)), 0.5),
                  tp_mul(R, eom_param(c, "c"), tp_mul(R, a, b)));
    return 0;
}

static int potential(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mulc(R, tp_add(R, tp_sqr(R, eom_q(c, 0)),
                             tp_sqr(R, eom_q(c, 1))), 0.5);
    return 0;
}

static eom_system *coupled(void)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    char msg[256];
    if (eom_model_new(&md) != EOM_OK)
        return NULL;
    eom_model_add_coord(md, "q1", "m", 0.3, 0.0);
    eom_model_add_coord(md, "q2", "m", -0.2, 0.0);
    eom_model_add_param(md, "c", NULL, 0.5, NULL);
    eom_model_set_kinetic(md, kinetic, NULL);
    eom_model_set_potential(md, potential, NULL);
    if (eom_system_new(&s, md, msg, sizeof msg) != EOM_OK)
        fprintf(stderr, "eom_system_new: %s\n", msg);
    eom_model_free(&md);
    return s;
}

/* One RK4 run of a few steps from x: its status, and its message in msg. */
static int rk4_run(eom_system *s, const double *x, char *msg, size_t len)
{
    eom_integ *it = NULL;
    eom_opts o;
    double y[4];
    int rc;
    eom_opts_default(&o);
    o.method = EOM_RK4;
    o.dt = 1e-3;
    memcpy(y, x, sizeof y);
    rc = eom_integ_new(&it, s, &o, 0.0, y);
    if (rc == EOM_OK)
        rc = eom_integ_advance(it, 0.01, y, NULL);
    snprintf(msg, len, "%s", it ? eom_integ_errmsg(it) : "");
    eom_integ_free(&it);
    return rc;
}

static void check_route(eom_system *s, int route)
{
    const double x[4] = {0.3, -0.2, 0.1, 0.05};
    const int k = eom_param_index(s, "c");
    double xd[4], c;
    char msg[1024];
    CHECK(k >= 0);
    CHECK_INT(eom_system_set_mass_route(s, route), EOM_OK);
    CHECK_INT(eom_system_mass_route(s),
              route ? route : EOM_MASS_CONSTANT);
    /* well conditioned: the closed form */
    c = 0.5;
    CHECK_INT(eom_set_param(s, k, c), EOM_OK);
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
    CHECK_NEAR(xd[2], -(x[0] - c * x[1]) / (1.0 - c * c), 1e-15);
    CHECK_NEAR(xd[3], -(x[1] - c * x[0]) / (1.0 - c * c), 1e-15);
    CHECK_INT(rk4_run(s, x, msg, sizeof msg), EOM_OK);
    /* singular to working precision: solved alone, refused in a run */
    c = 1.0 - 1e-14;
    CHECK_INT(eom_set_param(s, k, c), EOM_OK);
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
    CHECK(isfinite(xd[2]) && isfinite(xd[3]));
    CHECK_INT(rk4_run(s, x, msg, sizeof msg), EOM_ERR_SINGULAR_MASS);
    HAS(msg, "singular to working precision");
    HAS(msg, "'q2'");
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
    /* singular */
    CHECK_INT(eom_set_param(s, k, 1.0), EOM_OK);
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_ERR_SINGULAR_MASS);
    HAS(eom_system_errmsg(s), "positive definite");
    HAS(eom_system_errmsg(s), "'q2'");
    CHECK_INT(rk4_run(s, x, msg, sizeof msg), EOM_ERR_SINGULAR_MASS);
    HAS(msg, "positive definite");
}

int main(void)
{
    eom_system *s = coupled();
    CHECK(s != NULL);
    if (s) {
        check_route(s, 0);
        check_route(s, EOM_MASS_DENSE);
        check_route(s, 0);
    }
    eom_system_free(&s);
    CHECK_DONE();
}
