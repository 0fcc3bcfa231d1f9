/* spring_pendulum_eom.c - the example of docs/libeom.md: a spring pendulum
 * described by its energies, compiled into a system, checked against the
 * hand-derived equations of motion and integrated with RK4 for 5 s.
 * Built and run by the test suite (suite "docs"); exits non-zero if a
 * check fails.
 *
 *   coordinates r (spring length) and theta (from the downward vertical)
 *   T = m/2 (rd^2 + r^2 thd^2)
 *   V = k/2 (r - r0)^2 + m g (r0 - r cos theta)
 */
#include <math.h>
#include <stdio.h>

#include "eom/eom.h"

/* T(q, qd): read coordinates, rates and parameters from the context and
 * combine them with libtape's recording operations. */
static int kinetic(eom_ctx *c, void *user, tp_val *T)
{
    tp_rec *R = eom_rec(c);
    tp_val r = eom_q(c, 0), rd = eom_qd(c, 0), thd = eom_qd(c, 1);
    tp_val m = eom_param(c, "m");
    (void)user;
    *T = tp_mul(R, tp_mulc(R, m, 0.5),
                tp_add(R, tp_sqr(R, rd), tp_sqr(R, tp_mul(R, r, thd))));
    return 0;
}

/* V(q) */
static int potential(eom_ctx *c, void *user, tp_val *V)
{
    tp_rec *R = eom_rec(c);
    tp_val r = eom_q(c, 0), th = eom_q(c, 1);
    tp_val m = eom_param(c, "m"), k = eom_param(c, "k");
    tp_val r0 = eom_param(c, "r0"), g = eom_param(c, "g");
    tp_val spring = tp_mul(R, tp_mulc(R, k, 0.5), tp_sqr(R, tp_sub(R, r, r0)));
    tp_val height = tp_sub(R, r0, tp_mul(R, r, tp_cos(R, th)));
    (void)user;
    *V = tp_add(R, spring, tp_mul(R, tp_mul(R, m, g), height));
    return 0;
}

/* The spring's share of the energy, reported beside T and V. */
static int spring_energy(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val stretch = tp_sub(R, eom_q(c, 0), eom_param(c, "r0"));
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "k"), 0.5), tp_sqr(R, stretch));
    return 0;
}

int main(void)
{
    char msg[256];
    eom_model *model = NULL;
    eom_system *sys = NULL;
    eom_integ *integ = NULL;
    eom_opts opts;
    eom_energy en;
    eom_stats st;
    double x[4], xd[4], W, E0, drift = 0.0, spring;
    int rc, i, failures = 0;

    /* 1. the model: coordinates, parameters, energies */
    eom_model_new(&model);
    eom_model_add_coord(model, "r", "m", 1.1, 0.0);       /* q0, qd0 */
    eom_model_add_coord(model, "theta", "rad", 0.5, 0.0);
    eom_model_add_param(model, "m", "kg", 1.0, "bob mass");
    eom_model_add_param(model, "k", "N/m", 75.0, "spring stiffness");
    eom_model_add_param(model, "r0", "m", 1.0, "unstretched length");
    eom_model_add_param(model, "g", "m/s^2", 9.81, "gravity");
    eom_model_set_kinetic(model, kinetic, NULL);
    eom_model_set_potential(model, potential, NULL);
    eom_model_add_probe(model, "spring", "J", spring_energy, NULL);

    /* 2. the system: every callback is recorded once, here */
    rc = eom_system_new(&sys, model, msg, sizeof msg);
    eom_model_free(&model);
    if (rc != EOM_OK) {
        fprintf(stderr, "eom_system_new: %s: %s\n", eom_status_name(rc), msg);
        return 1;
    }

    /* 3. one evaluation, compared with the equations derived by hand:
     *    r_dd = r thd^2 - (k/m)(r - r0) + g cos th
     *    th_dd = -(2 rd thd + g sin th) / r          (with k = 120) */
    eom_set_param(sys, eom_param_index(sys, "k"), 120.0);
    x[0] = 1.2;  /* r */
    x[1] = 0.4;  /* theta */
    x[2] = -0.3; /* r_dot */
    x[3] = 1.5;  /* theta_dot */
    if ((rc = eom_rhs(sys, 0.0, x, xd)) != EOM_OK) {
        fprintf(stderr, "eom_rhs: %s\n", eom_system_errmsg(sys));
        eom_system_free(&sys);
        return 1;
    }
    {
        const double rdd = x[0] * x[3] * x[3] - 120.0 * (x[0] - 1.0) +
                           9.81 * cos(x[1]);
        const double thdd = -(2.0 * x[2] * x[3] + 9.81 * sin(x[1])) / x[0];
        printf("r_dd  = %.15g (by hand %.15g)\n", xd[2], rdd);
        printf("th_dd = %.15g (by hand %.15g)\n", xd[3], thdd);
        if (fabs(xd[2] - rdd) > 1e-12 * fabs(rdd) ||
            fabs(xd[3] - thdd) > 1e-12 * fabs(thdd))
            failures++;
    }

    /* 4. integrate 5 s with RK4 from the model's initial state (k stays
     *    at 120) */
    eom_initial_state(sys, x);
    eom_energy_at(sys, 0.0, x, &en);
    E0 = en.E;
    eom_opts_default(&opts); /* RK4, dt = 1e-3 */
    rc = eom_integ_new(&integ, sys, &opts, 0.0, x);
    if (rc != EOM_OK) {
        fprintf(stderr, "eom_integ_new: %s\n", eom_system_errmsg(sys));
        eom_system_free(&sys);
        return 1;
    }
    printf("%5s %10s %10s %10s %10s\n", "t", "r", "theta", "E", "spring");
    for (i = 1; i <= 50; i++) {
        const double t = 0.1 * i;
        rc = eom_integ_advance(integ, t, x, &W);
        if (rc != EOM_OK) {
            fprintf(stderr, "%s\n", eom_integ_errmsg(integ));
            failures++;
            break;
        }
        eom_energy_at(sys, t, x, &en);
        eom_probes_at(sys, x, &spring);
        drift = fmax(drift, fabs(en.E - E0));
        if (i % 10 == 0)
            printf("%5.1f %10.6f %10.6f %10.6f %10.6f\n", t, x[0], x[1], en.E,
                   spring);
    }
    eom_integ_stats(integ, &st);
    printf("%ld steps, %ld evaluations, max |E - E0| = %.2e J\n", st.steps,
           st.rhs_evals, drift);
    /* no dissipation: the energy is conserved up to RK4's error */
    if (!(drift < 1e-8 * fabs(E0)) || W != 0.0)
        failures++;

    eom_integ_free(&integ);
    eom_system_free(&sys);
    return failures ? 1 : 0;
}
