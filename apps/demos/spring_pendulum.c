/* spring_pendulum.c - the spring pendulum demo: a bob of mass m on a
 * massless spring (stiffness k, unstretched length r0) that swings in a
 * vertical plane. Coordinates: the spring length r and the angle theta
 * from the downward vertical.
 *
 *     T = 1/2 m (r_dot^2 + r^2 theta_dot^2)
 *     V = 1/2 k (r - r0)^2 + m g (r0 - r cos theta)
 *
 * T and V are given separately so that both are reported. The default
 * start (r = 1.1 m, theta = 0.5 rad, at rest) couples the stretching and
 * swinging motions, so energy moves between them in a non-trivial way. */
#include "demos.h"
#include "spring_plots.h"

static int sp_kinetic(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val r = eom_q(c, 0), rd = eom_qd(c, 0), thd = eom_qd(c, 1);
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "m"), 0.5),
                  tp_add(R, tp_sqr(R, rd),
                         tp_mul(R, tp_sqr(R, r), tp_sqr(R, thd))));
    return 0;
}

static int sp_potential(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val r = eom_q(c, 0), th = eom_q(c, 1);
    tp_val m = eom_param(c, "m"), k = eom_param(c, "k");
    tp_val r0 = eom_param(c, "r0"), g = eom_param(c, "g");
    tp_val spring = tp_mul(R, tp_mulc(R, k, 0.5), tp_sqr(R, tp_sub(R, r, r0)));
    /* height measured down from the pivot, zero at r = r0, theta = 0 */
    tp_val gravity = tp_mul(R, tp_mul(R, m, g),
                            tp_sub(R, r0, tp_mul(R, r, tp_cos(R, th))));
    (void)user;
    *out = tp_add(R, spring, gravity);
    return 0;
}

static int sp_build(const demo *d, const double *settings, eom_model **out,
                    char *err, size_t errlen)
{
    eom_model *m = NULL;
    (void)d;
    (void)settings;
    if (eom_model_new(&m) == EOM_OK) {
        /* failures are sticky: demo_model_done reports the first one */
        eom_model_add_coord(m, "r", "m", 1.1, 0.0);
        eom_model_add_coord(m, "theta", "rad", 0.5, 0.0);
        eom_model_add_param(m, "m", "kg", 1.0, "mass of the bob");
        eom_model_add_param(m, "k", "N/m", 75.0, "spring stiffness");
        eom_model_add_param(m, "r0", "m", 1.0,
                            "unstretched length of the spring");
        eom_model_add_param(m, "g", "m/s^2", 9.81,
                            "gravitational acceleration");
        eom_model_set_kinetic(m, sp_kinetic, NULL);
        eom_model_set_potential(m, sp_potential, NULL);
    }
    return demo_model_done(&m, out, err, errlen);
}

const demo demo_spring_pendulum = {
    .name = "spring-pendulum",
    .summary = "a mass on a spring swinging in a vertical plane (r, theta)",
    .settings = NULL, /* no structural settings */
    .nsettings = 0,
    .build = sp_build,
    .after_run = spring_plots_write,
};
