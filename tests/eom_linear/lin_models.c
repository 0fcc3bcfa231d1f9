/* lin_models.c - the models of lin_models.h, written against the
 * recording API as a user would. */
#include <stdio.h>

#include "lin_models.h"

static const double PI_ = 3.14159265358979323846;

/* ---- point pendulum ----------------------------------------------------- */

static int pend_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val l = eom_param(c, "l");
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "m"), 0.5),
                  tp_sqr(R, tp_mul(R, l, eom_qd(c, 0))));
    return 0;
}

static int pend_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val th = eom_q(c, 0);
    tp_val mgl = tp_mul(R, tp_mul(R, eom_param(c, "m"), eom_param(c, "g")),
                        eom_param(c, "l"));
    (void)user;
    *out = tp_neg(R, tp_add(R, tp_mul(R, mgl, tp_cos(R, th)),
                            tp_mul(R, eom_param(c, "tau"), th)));
    return 0;
}

static int pend_R(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "c"), 0.5),
                  tp_sqr(R, eom_qd(c, 0)));
    return 0;
}

eom_model *lin_models_pendulum(double m, double l, double g, double tau,
                               double c, int damped, double theta0)
{
    eom_model *md = NULL;
    if (eom_model_new(&md) != EOM_OK)
        return NULL;
    eom_model_add_coord(md, "theta", "rad", theta0, 0.0);
    eom_model_add_param(md, "m", "kg", m, "mass");
    eom_model_add_param(md, "l", "m", l, "length");
    eom_model_add_param(md, "g", "m/s^2", g, "gravity");
    eom_model_add_param(md, "tau", "N m", tau, "constant torque");
    eom_model_add_param(md, "c", "N m s", c, "damping");
    eom_model_set_kinetic(md, pend_T, NULL);
    eom_model_set_potential(md, pend_V, NULL);
    if (damped)
        eom_model_set_dissipation(md, pend_R, NULL);
    if (eom_model_errmsg(md)[0]) {
        eom_model_free(&md);
        return NULL;
    }
    return md;
}

/* ---- flexible link pinned at both ends ---------------------------------- */

static int flex_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val L = eom_param(c, "L"), a1 = eom_q(c, 1), a2 = eom_q(c, 2);
    tp_val thd = eom_qd(c, 0), a1d = eom_qd(c, 1), a2d = eom_qd(c, 2);
    tp_val jth = tp_add(R, tp_mulc(R, tp_sqr(R, L), 1.0 / 3.0),
                        tp_mulc(R, tp_add(R, tp_sqr(R, a1), tp_sqr(R, a2)),
                                0.5));
    tp_val cross = tp_mul(R, tp_mul(R, tp_mulc(R, L, 2.0 / PI_), thd),
                          tp_sub(R, a1d, tp_mulc(R, a2d, 0.5)));
    tp_val modal = tp_mulc(R, tp_add(R, tp_sqr(R, a1d), tp_sqr(R, a2d)), 0.5);
    tp_val sum = tp_add(R, tp_mul(R, jth, tp_sqr(R, thd)),
                        tp_add(R, cross, modal));
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "m"), 0.5), sum);
    return 0;
}

static int flex_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val L = eom_param(c, "L"), th = eom_q(c, 0);
    tp_val a1 = eom_q(c, 1), a2 = eom_q(c, 2);
    tp_val mg = tp_mul(R, eom_param(c, "m"), eom_param(c, "g"));
    tp_val grav = tp_mul(R, mg, tp_add(R, tp_mul(R, tp_mulc(R, L, 0.5),
                                                 tp_sin(R, th)),
                                       tp_mul(R, tp_mulc(R, a1, 2.0 / PI_),
                                              tp_cos(R, th))));
    tp_val a2sq = tp_add(R, tp_sqr(R, a1), tp_mulc(R, tp_sqr(R, a2), 16.0));
    tp_val bend = tp_div(R, tp_mul(R, tp_mulc(R, eom_param(c, "EI"),
                                              PI_ * PI_ * PI_ * PI_ / 4.0),
                                   a2sq),
                         tp_powi(R, L, 3));
    (void)user;
    *out = tp_add(R, grav, bend);
    return 0;
}

static int flex_phi(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val L = eom_param(c, "L"), th = eom_q(c, 0);
    (void)user;
    out[0] = tp_sub(R, tp_mul(R, L, tp_cos(R, th)), L);
    out[1] = tp_mul(R, L, tp_sin(R, th));
    return 0;
}

eom_model *lin_models_flexible_link(double m, double L, double EI, double g)
{
    eom_model *md = NULL;
    if (eom_model_new(&md) != EOM_OK)
        return NULL;
    eom_model_add_coord(md, "th", "rad", 0.0, 0.0);
    eom_model_add_coord(md, "a1", "m", 0.0, 0.0);
    eom_model_add_coord(md, "a2", "m", 0.0, 0.0);
    eom_model_add_param(md, "m", "kg", m, "mass");
    eom_model_add_param(md, "L", "m", L, "length");
    eom_model_add_param(md, "EI", "N m^2", EI, "bending stiffness");
    eom_model_add_param(md, "g", "m/s^2", g, "gravity");
    eom_model_set_kinetic(md, flex_T, NULL);
    eom_model_set_potential(md, flex_V, NULL);
    eom_model_set_constraints(md, 2, flex_phi, NULL);
    if (eom_model_errmsg(md)[0]) {
        eom_model_free(&md);
        return NULL;
    }
    return md;
}

/* ---- point on a sphere, constraint given twice -------------------------- */

static int sph_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val v[3];
    int i;
    (void)user;
    for (i = 0; i < 3; i++)
        v[i] = eom_qd(c, i);
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "m"), 0.5), tp_dot(R, 3, v, v));
    return 0;
}

static int sph_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, tp_mul(R, eom_param(c, "m"), eom_param(c, "g")),
                  eom_q(c, 1));
    return 0;
}

static int sph_phi2(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val p[3], d;
    int i;
    (void)user;
    for (i = 0; i < 3; i++)
        p[i] = eom_q(c, i);
    d = tp_sub(R, tp_dot(R, 3, p, p), tp_sqr(R, eom_param(c, "l")));
    out[0] = tp_mulc(R, d, 0.5);
    out[1] = d;
    return 0;
}

eom_model *lin_models_redundant_sphere(double m, double l, double g)
{
    eom_model *md = NULL;
    if (eom_model_new(&md) != EOM_OK)
        return NULL;
    eom_model_add_coord(md, "x", "m", 0.0, 0.0);
    eom_model_add_coord(md, "y", "m", -l, 0.0);
    eom_model_add_coord(md, "z", "m", 0.0, 0.0);
    eom_model_add_param(md, "m", "kg", m, "mass");
    eom_model_add_param(md, "l", "m", l, "radius");
    eom_model_add_param(md, "g", "m/s^2", g, "gravity");
    eom_model_set_kinetic(md, sph_T, NULL);
    eom_model_set_potential(md, sph_V, NULL);
    eom_model_set_constraints(md, 2, sph_phi2, NULL);
    if (eom_model_errmsg(md)[0]) {
        eom_model_free(&md);
        return NULL;
    }
    return md;
}

eom_system *lin_models_system(eom_model *md)
{
    eom_system *s = NULL;
    char msg[256];
    if (!md) {
        fprintf(stderr, "lin_models_system: no model\n");
        return NULL;
    }
    if (eom_system_new(&s, md, msg, sizeof msg) != EOM_OK)
        fprintf(stderr, "eom_system_new: %s\n", msg);
    eom_model_free(&md);
    return s;
}
