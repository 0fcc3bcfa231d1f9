/* test_params.c - probes and parameters.
 *
 *  - Probes on the spring pendulum, "spring" = k/2 (r - r0)^2 and
 *    "swing" = m/2 r^2 thd^2: names, units, count; eom_probes_at equals
 *    those values computed here at random states (1e-14 relative), also
 *    after eom_set_param changes k and m; on a model given by a whole
 *    Lagrangian (no T, V outputs before the probes) as well.
 *  - eom_set_param changes the dynamics exactly like a model built with
 *    that default: the spring pendulum with (m, k, r0, g) changed, and the
 *    four-bar with the ground length D changed (used only by the
 *    constraints), give bit-for-bit the same xd, multipliers, residuals
 *    and energies as systems built with those values; setting a parameter
 *    no callback reads changes nothing.
 *  - Composed models: the spring pendulum from two kinetic and two
 *    potential contributions (eom_model_add_*, after set_ replaced a
 *    first one) and the four-bar as an open chain plus two one-row
 *    constraint blocks give the results of the monolithic models.
 *  - Non-finite values (NaN, +-inf) are rejected with EOM_ERR_NONFINITE and
 *    a message naming the parameter, and leave the value in use unchanged;
 *    an index out of range is EOM_ERR_ARG; accessors out of range give
 *    NULL / NaN / -1.
 */
#include <math.h>
#include <string.h>

#include "check.h"
#include "core_support.h"
#include "eom_models.h"
#include "support_num.h"
#include "support_rng.h"

static int probe_spring(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "k"), 0.5),
                  tp_sqr(R, tp_sub(R, eom_q(c, 0), eom_param(c, "r0"))));
    return 0;
}

static int probe_swing(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "m"), 0.5),
                  tp_sqr(R, tp_mul(R, eom_q(c, 0), eom_qd(c, 1))));
    return 0;
}

/* The spring pendulum as one Lagrangian (no T, V outputs). */
static int sp_L(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val r = eom_q(c, 0), th = eom_q(c, 1), rd = eom_qd(c, 0),
           thd = eom_qd(c, 1);
    tp_val m = eom_param(c, "m"), k = eom_param(c, "k");
    tp_val T = tp_mul(R, tp_mulc(R, m, 0.5),
                      tp_add(R, tp_sqr(R, rd),
                             tp_sqr(R, tp_mul(R, r, thd))));
    tp_val V = tp_add(R, tp_mul(R, tp_mulc(R, k, 0.5),
                                tp_sqr(R, tp_sub(R, r, eom_param(c, "r0")))),
                      tp_mul(R, tp_mul(R, m, eom_param(c, "g")),
                             tp_neg(R, tp_mul(R, r, tp_cos(R, th)))));
    (void)user;
    *out = tp_sub(R, T, V);
    return 0;
}

/* T = p/2 qd^2 */
static int unit_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "p"), 0.5),
                  tp_sqr(R, eom_qd(c, 0)));
    return 0;
}

static eom_model *with_probes(eom_model *md)
{
    if (!md)
        return NULL;
    CHECK_INT(eom_model_add_probe(md, "spring", "J", probe_spring, NULL), 0);
    CHECK_INT(eom_model_add_probe(md, "swing", "J", probe_swing, NULL), 1);
    return md;
}

static void check_probe_values(const char *name, eom_system *s, rng *g)
{
    double m = 1.0, k = 75.0, r0 = 1.0;
    int i, j;
    CHECK_INT(eom_system_nprobes(s), 2);
    CHECK(strcmp(eom_probe_name(s, 0), "spring") == 0);
    CHECK(strcmp(eom_probe_name(s, 1), "swing") == 0);
    CHECK(strcmp(eom_probe_unit(s, 1), "J") == 0);
    CHECK(eom_probe_name(s, 2) == NULL && eom_probe_name(s, -1) == NULL);
    CHECK(eom_probe_unit(s, 2) == NULL);
    for (j = 0; j < 3; j++) {
        if (j > 0) {
            k = 75.0 * (1.0 + j);
            m = 1.0 + 0.5 * j;
            r0 = 1.0 - 0.2 * j;
            CHECK_INT(core_set(s, "k", k), EOM_OK);
            CHECK_INT(core_set(s, "m", m), EOM_OK);
            CHECK_INT(core_set(s, "r0", r0), EOM_OK);
        }
        for (i = 0; i < 20; i++) {
            double x[4], p[2], ref[2];
            x[0] = rng_range(g, 0.2, 3.0);
            x[1] = rng_range(g, -3.0, 3.0);
            x[2] = rng_range(g, -3.0, 3.0);
            x[3] = rng_range(g, -3.0, 3.0);
            ref[0] = 0.5 * k * (x[0] - r0) * (x[0] - r0);
            ref[1] = 0.5 * m * x[0] * x[0] * x[3] * x[3];
            p[0] = p[1] = NAN;
            CHECK_INT(eom_probes_at(s, x, p), EOM_OK);
            CHECK_VEC(name, p, ref, 2, 1e-14);
        }
    }
}

static void probes(rng *g)
{
    eom_system *s = core_system(with_probes(
        eom_models_spring_pendulum(1.0, 75.0, 1.0, 9.81)));
    eom_model *md = NULL;
    CHECK(s != NULL);
    if (s)
        check_probe_values("probes (T, V model)", s, g);
    eom_system_free(&s);

    CHECK_INT(eom_model_new(&md), EOM_OK);
    eom_model_add_coord(md, "r", "m", 1.1, 0.0);
    eom_model_add_coord(md, "theta", "rad", 0.5, 0.0);
    eom_model_add_param(md, "m", "kg", 1.0, NULL);
    eom_model_add_param(md, "k", "N/m", 75.0, NULL);
    eom_model_add_param(md, "r0", "m", 1.0, NULL);
    eom_model_add_param(md, "g", "m/s^2", 9.81, NULL);
    eom_model_set_lagrangian(md, sp_L, NULL);
    s = core_system(with_probes(md));
    CHECK(s != NULL);
    if (s) {
        CHECK_INT(eom_system_has_tv(s), 0);
        check_probe_values("probes (L model)", s, g);
    }
    eom_system_free(&s);
}

/* Two systems give bit-for-bit the same results at random states. */
static void same_results(const char *name, eom_system *a, eom_system *b,
                         rng *g, double qlo, double qhi)
{
    const int n = eom_system_ncoords(a), m = eom_system_nconstraints(a);
    int k, i;
    CHECK_INT(eom_system_ncoords(b), n);
    for (k = 0; k < 20; k++) {
        double x[2 * CORE_NMAX], xa[2 * CORE_NMAX], xb[2 * CORE_NMAX];
        double la[4] = {0}, lb[4] = {0}, pa[4] = {0}, pb[4] = {0};
        eom_energy ea, eb;
        for (i = 0; i < n; i++) {
            x[i] = rng_range(g, qlo, qhi);
            x[n + i] = rng_range(g, -2.0, 2.0);
        }
        CHECK_INT(eom_rhs(a, 0.0, x, xa), EOM_OK);
        CHECK_INT(eom_rhs(b, 0.0, x, xb), EOM_OK);
        CHECK_SAME(name, xa, xb, 2 * n);
        CHECK_INT(eom_energy_at(a, 0.0, x, &ea), EOM_OK);
        CHECK_INT(eom_energy_at(b, 0.0, x, &eb), EOM_OK);
        CHECK_SAME(name, &ea.E, &eb.E, 1);
        CHECK_SAME(name, &ea.T, &eb.T, 1);
        CHECK_SAME(name, &ea.V, &eb.V, 1);
        if (m > 0) {
            CHECK_INT(eom_multipliers(a, 0.0, x, la), EOM_OK);
            CHECK_INT(eom_multipliers(b, 0.0, x, lb), EOM_OK);
            CHECK_SAME(name, la, lb, m);
            CHECK_INT(eom_residuals(a, x, pa, NULL), EOM_OK);
            CHECK_INT(eom_residuals(b, x, pb, NULL), EOM_OK);
            CHECK_SAME(name, pa, pb, m);
        }
    }
}

static void set_param_is_rebuild(rng *g)
{
    eom_system *a = core_system(eom_models_spring_pendulum(1.0, 75.0, 1.0,
                                                           9.81));
    eom_system *b = core_system(eom_models_spring_pendulum(2.5, 120.0, 0.7,
                                                           3.7));
    eom_model *md;
    double x[4] = {1.0, 0.3, 0.2, -0.1}, x1[4], x2[4];
    CHECK(a && b);
    if (a && b) {
        CHECK_INT(core_set(a, "m", 2.5), EOM_OK);
        CHECK_INT(core_set(a, "k", 120.0), EOM_OK);
        CHECK_INT(core_set(a, "r0", 0.7), EOM_OK);
        CHECK_INT(core_set(a, "g", 3.7), EOM_OK);
        /* defaults stay what the model said */
        CHECK(eom_param_default(a, eom_param_index(a, "k")) == 75.0);
        CHECK(eom_get_param(a, eom_param_index(a, "k")) == 120.0);
        same_results("spring pendulum, set vs built", a, b, g, 0.3, 2.0);
    }
    eom_system_free(&a);
    eom_system_free(&b);

    {
        const double th0[3] = {1.5, 0.3, -1.3};
        a = fourbar_system();
        b = core_system(eom_models_rod_chain(3, FB_M, FB_L, th0, FB_G, 1,
                                             2.35));
        CHECK(a && b);
        if (a && b) {
            CHECK_INT(core_set(a, "D", 2.35), EOM_OK);
            same_results("four-bar, D set vs built", a, b, g, -CORE_PI,
                         CORE_PI);
        }
        eom_system_free(&a);
        eom_system_free(&b);
    }

    /* a parameter nobody reads */
    md = eom_models_spring_pendulum(1.0, 75.0, 1.0, 9.81);
    CHECK(md != NULL);
    if (md)
        CHECK_INT(eom_model_add_param(md, "unused", "", 1.0, NULL), 4);
    a = core_system(md);
    CHECK(a != NULL);
    if (a) {
        CHECK_INT(eom_rhs(a, 0.0, x, x1), EOM_OK);
        CHECK_INT(core_set(a, "unused", 42.0), EOM_OK);
        CHECK_INT(eom_rhs(a, 0.0, x, x2), EOM_OK);
        CHECK_SAME("unused parameter", x1, x2, 4);
    }
    eom_system_free(&a);
}

static void rejected_values(void)
{
    eom_system *s = core_system(eom_models_spring_pendulum(1.0, 75.0, 1.0,
                                                           9.81));
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    double x[4] = {1.0, 0.3, 0.2, -0.1}, x1[4], x2[4];
    int k, i;
    CHECK(s != NULL);
    if (!s)
        return;
    k = eom_param_index(s, "k");
    CHECK_INT(core_set(s, "k", 80.0), EOM_OK);
    CHECK_INT(eom_rhs(s, 0.0, x, x1), EOM_OK);
    for (i = 0; i < 3; i++) {
        CHECK_INT(eom_set_param(s, k, bad[i]), EOM_ERR_NONFINITE);
        CHECK(strstr(eom_system_errmsg(s), "'k'") != NULL);
        CHECK(eom_get_param(s, k) == 80.0);
    }
    CHECK_INT(eom_rhs(s, 0.0, x, x2), EOM_OK);
    CHECK_SAME("dynamics after rejected values", x1, x2, 4);
    CHECK_INT(eom_set_param(s, 4, 1.0), EOM_ERR_ARG);
    CHECK_INT(eom_set_param(s, -1, 1.0), EOM_ERR_ARG);
    CHECK(eom_system_errmsg(s)[0] != '\0');
    CHECK_INT(eom_set_param(NULL, 0, 1.0), EOM_ERR_NULL);
    CHECK(isnan(eom_get_param(s, 4)) && isnan(eom_get_param(NULL, 0)));
    CHECK(isnan(eom_param_default(s, -1)));
    CHECK(eom_param_name(s, 4) == NULL && eom_param_unit(s, 4) == NULL);
    CHECK(eom_param_description(s, -1) == NULL);
    CHECK(eom_coord_name(s, 2) == NULL && eom_coord_unit(s, -1) == NULL);
    CHECK_INT(eom_param_index(s, "nosuch"), -1);
    CHECK_INT(eom_param_index(s, NULL), -1);
    CHECK_INT(eom_coord_index(s, NULL), -1);
    eom_system_free(&s);
    /* units and descriptions are "" when the model gave NULL */
    {
        eom_model *md = NULL;
        CHECK_INT(eom_model_new(&md), EOM_OK);
        CHECK_INT(eom_model_add_coord(md, "q", NULL, 0.0, 0.0), 0);
        CHECK_INT(eom_model_add_param(md, "p", NULL, 1.0, NULL), 0);
        CHECK_INT(eom_model_set_kinetic(md, unit_T, NULL), EOM_OK);
        s = core_system(md);
        CHECK(s != NULL);
        if (s) {
            CHECK(strcmp(eom_coord_unit(s, 0), "") == 0);
            CHECK(strcmp(eom_param_unit(s, 0), "") == 0);
            CHECK(strcmp(eom_param_description(s, 0), "") == 0);
        }
        eom_system_free(&s);
    }
}

/* ---- composed models: contributions summed, constraint blocks stacked --- */

static int sp_T_radial(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "m"), 0.5),
                  tp_sqr(R, eom_qd(c, 0)));
    return 0;
}

static int sp_T_swing(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "m"), 0.5),
                  tp_sqr(R, tp_mul(R, eom_q(c, 0), eom_qd(c, 1))));
    return 0;
}

static int sp_V_gravity(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val mg = tp_mul(R, eom_param(c, "m"), eom_param(c, "g"));
    (void)user;
    *out = tp_mul(R, mg, tp_sub(R, eom_param(c, "r0"),
                                tp_mul(R, eom_q(c, 0),
                                       tp_cos(R, eom_q(c, 1)))));
    return 0;
}

/* One coordinate of the tip of the three-rod chain minus the pin (D, 0):
 * x when *(int *)user == 0, else y. */
static int tip_phi(eom_ctx *c, void *user, tp_val *out)
{
    const int which = *(const int *)user;
    tp_rec *R = eom_rec(c);
    tp_val v = which ? tp_const(R, 0.0) : tp_neg(R, eom_param(c, "D"));
    static const char *const l[3] = {"l1", "l2", "l3"};
    int j;
    for (j = 0; j < 3; j++) {
        tp_val th = eom_q(c, j);
        v = tp_add(R, v, tp_mul(R, eom_param(c, l[j]),
                                which ? tp_sin(R, th) : tp_cos(R, th)));
    }
    out[0] = v;
    return 0;
}

static void composed(rng *g)
{
    static int which[2] = {0, 1};
    const double th0[3] = {1.5, 0.3, -1.3};
    eom_model *md = NULL;
    eom_system *a, *b;
    int k, i;

    /* the spring pendulum from four pieces, after a bogus T is replaced */
    CHECK_INT(eom_model_new(&md), EOM_OK);
    eom_model_add_coord(md, "r", "m", 1.1, 0.0);
    eom_model_add_coord(md, "theta", "rad", 0.5, 0.0);
    eom_model_add_param(md, "m", "kg", 1.0, NULL);
    eom_model_add_param(md, "k", "N/m", 75.0, NULL);
    eom_model_add_param(md, "r0", "m", 1.0, NULL);
    eom_model_add_param(md, "g", "m/s^2", 9.81, NULL);
    CHECK_INT(eom_model_add_kinetic(md, sp_T_swing, NULL), EOM_OK);
    CHECK_INT(eom_model_set_kinetic(md, sp_T_radial, NULL), EOM_OK);
    CHECK_INT(eom_model_add_kinetic(md, sp_T_swing, NULL), EOM_OK);
    CHECK_INT(eom_model_add_potential(md, probe_spring, NULL), EOM_OK);
    CHECK_INT(eom_model_add_potential(md, sp_V_gravity, NULL), EOM_OK);
    a = core_system(md);
    b = core_system(eom_models_spring_pendulum(1.0, 75.0, 1.0, 9.81));
    CHECK(a && b);
    for (k = 0; a && b && k < 20; k++) {
        double x[4], xa[4], xb[4];
        eom_energy ea, eb;
        x[0] = rng_range(g, 0.3, 2.0);
        for (i = 1; i < 4; i++)
            x[i] = rng_range(g, -2.0, 2.0);
        CHECK_INT(eom_rhs(a, 0.0, x, xa), EOM_OK);
        CHECK_INT(eom_rhs(b, 0.0, x, xb), EOM_OK);
        CHECK_VEC("composed spring pendulum: xd", xa, xb, 4, 1e-14);
        CHECK_INT(eom_energy_at(a, 0.0, x, &ea), EOM_OK);
        CHECK_INT(eom_energy_at(b, 0.0, x, &eb), EOM_OK);
        CHECK_NEAR(ea.T, eb.T, 1e-14);
        CHECK_NEAR(ea.V, eb.V, 1e-14);
    }
    eom_system_free(&a);
    eom_system_free(&b);

    /* the four-bar: an open chain plus two one-row constraint blocks */
    md = eom_models_rod_chain(3, FB_M, FB_L, th0, FB_G, 0, 0.0);
    CHECK(md != NULL);
    if (!md)
        return;
    eom_model_add_param(md, "D", "m", FB_D, NULL);
    CHECK_INT(eom_model_add_constraints(md, 1, tip_phi, &which[0]), EOM_OK);
    CHECK_INT(eom_model_add_constraints(md, 1, tip_phi, &which[1]), EOM_OK);
    a = core_system(md);
    b = fourbar_system();
    CHECK(a && b);
    if (a)
        CHECK_INT(eom_system_nconstraints(a), 2);
    for (k = 0; a && b && k < 20; k++) {
        double x[6], xa[6], xb[6], la[2], lb[2], pa[2], pb[2];
        for (i = 0; i < 6; i++)
            x[i] = rng_range(g, -2.0, 2.0);
        CHECK_INT(eom_rhs(a, 0.0, x, xa), EOM_OK);
        CHECK_INT(eom_rhs(b, 0.0, x, xb), EOM_OK);
        CHECK_VEC("composed four-bar: xd", xa, xb, 6, 1e-12);
        CHECK_INT(eom_multipliers(a, 0.0, x, la), EOM_OK);
        CHECK_INT(eom_multipliers(b, 0.0, x, lb), EOM_OK);
        CHECK_VEC("composed four-bar: lambda", la, lb, 2, 1e-12);
        CHECK_INT(eom_residuals(a, x, pa, NULL), EOM_OK);
        CHECK_INT(eom_residuals(b, x, pb, NULL), EOM_OK);
        CHECK_VEC("composed four-bar: phi in block order", pa, pb, 2, 1e-15);
    }
    eom_system_free(&a);
    eom_system_free(&b);
}

/* eom_param_at: a parameter by the index eom_model_add_param returned,
 * the same value as by name; an index out of range fails the recording
 * with a message naming it */
static int V_at(eom_ctx *c, void *user, tp_val *out)
{
    const int *k = user;
    tp_rec *R = eom_rec(c);
    *out = tp_mul(R, tp_mulc(R, eom_param_at(c, *k), 0.5),
                  tp_sqr(R, eom_q(c, 0)));
    return 0;
}

static int T_at(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_mulc(eom_rec(c), tp_sqr(eom_rec(c), eom_qd(c, 0)), 0.5);
    return 0;
}

static void by_index(void)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    char msg[256];
    int k, bad = 7;
    double x[2] = {0.3, 0.0}, xd[2];
    CHECK_INT(eom_model_new(&md), EOM_OK);
    eom_model_add_coord(md, "x", "m", 0.3, 0.0);
    eom_model_add_param(md, "unused", "1", 1.0, NULL);
    k = eom_model_add_param(md, "k", "N/m", 40.0, NULL);
    CHECK_INT(k, 1);
    eom_model_set_kinetic(md, T_at, NULL);
    eom_model_set_potential(md, V_at, &k);
    CHECK_INT(eom_system_new(&s, md, msg, sizeof msg), EOM_OK);
    if (s) {
        /* x'' = -k x, with k changed by name afterwards */
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        CHECK_NEAR(xd[1], -40.0 * 0.3, 1e-14);
        CHECK_INT(eom_set_param(s, eom_param_index(s, "k"), 10.0), EOM_OK);
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        CHECK_NEAR(xd[1], -10.0 * 0.3, 1e-14);
        eom_system_free(&s);
    }
    eom_model_set_potential(md, V_at, &bad);
    CHECK(eom_system_new(&s, md, msg, sizeof msg) != EOM_OK);
    CHECK(s == NULL);
    CHECK(strstr(msg, "no parameter of index 7") != NULL);
    eom_model_free(&md);
}

int main(void)
{
    rng g = rng_seed(2718);
    by_index();
    probes(&g);
    set_param_is_rebuild(&g);
    rejected_values();
    composed(&g);
    CHECK_DONE();
}
