/* test_closed_chain.c - constrained systems: the rigid four-bar (three
 * uniform rods pinned at (0, 0) and (D, 0)) and the bead on a circle.
 *
 * Four-bar: rods l = (1, 2, 1.5) m, masses (1, 2, 1.5) kg, ground D = 2.2
 * m: a Grashof crank-rocker (s + l = 3.2 < p + q = 3.5), so the crank turns
 * fully and the mechanism never reaches a singular configuration. (With
 * D = 2.5, s + l = p + q: a change-point linkage that passes through a
 * flat, singular configuration.)
 *
 *  1. At 50 consistent states, assembled in the test by intersecting
 *     circles, and at 50 random inconsistent ones, the accelerations and
 *     multipliers of eom_rhs / eom_multipliers equal those of the augmented
 *     system [M -C^T; C 0] (qdd, lambda) = (F, gamma) built from the
 *     closed forms of core_support.h and solved densely (1e-12 relative).
 *     This checks M, F, C, gamma = -(d2phi/dq2)[qd, qd] and the sign
 *     convention (C^T lambda added to the applied forces) at once.
 *  2. At rest, M qdd = F + C^T lambda with F = -dV/dq by central
 *     differences of eom_energy_at's V (no closed form involved).
 *  3. RK4 with projection, dt = 1e-3, 20 s from a projected initial guess
 *     with the crank turning: every 0.05 s, |phi| <= 1e-11 and |C qd| <=
 *     1e-11 (phi and C by hand); E = T + V (by hand, E0 = 55.2 J) stays
 *     within 1e-6 J of its start while T varies by more than 10 J and the
 *     crank turns round; W stays 0; the statistics count the steps and
 *     4 evaluations per step. The drift of E is RK4's truncation error:
 *     halving dt divides it by at least 10 (16 in theory).
 *  Bead on a circle of radius l, angle a from the downward vertical, speed
 *  v along the tangent: the constraint force is
 *     C^T lambda = -(m v^2 / l + m g cos a) (sin a, -cos a),
 *  (0, m g) at rest at the bottom, and the acceleration is
 *     -v^2/l (sin a, -cos a) - g sin a (cos a, sin a).
 */
#include <math.h>
#include <string.h>

#include "check.h"
#include "core_support.h"
#include "eom_models.h"
#include "support_num.h"
#include "support_rng.h"

/* 1: eom_rhs and eom_multipliers against the dense augmented system. */
static void check_kkt(eom_system *s, const core_chain *c, rng *g)
{
    double worst_a = 0.0, worst_l = 0.0;
    int k;
    for (k = 0; k < 100; k++) {
        double x[6], xd[6], M[9], C[6], F[3], gam[2], qdd[3], lam[2];
        double lam_lib[2], sc, e_a, e_l;
        int i;
        if (k < 50) {
            fourbar_assemble(c, rng_range(g, -CORE_PI, CORE_PI),
                             k % 2 ? 1 : -1, rng_range(g, -4.0, 4.0), x);
        } else {
            /* near the mechanism, not on it: the equations hold anywhere */
            fourbar_assemble(c, rng_range(g, -CORE_PI, CORE_PI), 1, 0.0, x);
            for (i = 0; i < 3; i++) {
                x[i] += rng_range(g, -0.2, 0.2);
                x[3 + i] = rng_range(g, -3.0, 3.0);
            }
        }
        core_chain_mass(c, x, M);
        core_chain_force(c, x, F, &sc);
        core_chain_constraints(c, x, NULL, C, gam);
        sc += fabs(gam[0]) + fabs(gam[1]) + 1.0;
        if (core_kkt(3, 2, M, C, F, gam, qdd, lam)) {
            CHECK_FAIL_("state %d: the reference KKT system is singular", k);
            continue;
        }
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        CHECK_INT(eom_multipliers(s, 0.0, x, lam_lib), EOM_OK);
        e_a = num_vec_err_scaled(xd + 3, qdd, 3, sc);
        e_l = num_vec_err_scaled(lam_lib, lam, 2, sc);
        worst_a = fmax(worst_a, e_a);
        worst_l = fmax(worst_l, e_l);
        check_count_++;
        if (!(e_a <= 1e-12 && e_l <= 1e-12))
            CHECK_FAIL_("state %d: qdd error %.3g, lambda error %.3g "
                        "(lambda %.17g %.17g, reference %.17g %.17g)", k,
                        e_a, e_l, lam_lib[0], lam_lib[1], lam[0], lam[1]);
    }
    printf("four-bar vs augmented system: qdd %.3g, lambda %.3g\n", worst_a,
           worst_l);
}

/* 2: at rest, M qdd - C^T lambda = -dV/dq by differences of eom_energy_at's
 * V. */
typedef struct v_ctx {
    eom_system *s;
} v_ctx;

static int V_of_q(void *ctx, const double *q, double *V)
{
    v_ctx *v = ctx;
    double x[6] = {0};
    eom_energy e;
    memcpy(x, q, 3 * sizeof(double));
    if (eom_energy_at(v->s, 0.0, x, &e) != EOM_OK)
        return -1;
    *V = e.V;
    return 0;
}

static void check_rest(eom_system *s, const core_chain *c, rng *g)
{
    int k;
    for (k = 0; k < 10; k++) {
        double x[6], xd[6], M[9], C[6], lam[2], dV[3], F[3], Mq[3];
        double Fh[3], r[3], sc;
        v_ctx vc;
        int i;
        fourbar_assemble(c, rng_range(g, -CORE_PI, CORE_PI), k % 2 ? 1 : -1,
                         0.0, x);
        vc.s = s;
        CHECK_INT(num_fd_jac(V_of_q, &vc, 3, 1, x, 1e-3, dV), 0);
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        CHECK_INT(eom_multipliers(s, 0.0, x, lam), EOM_OK);
        CHECK_INT(eom_mass_matrix(s, x, M), EOM_OK);
        CHECK_INT(eom_constraint_jacobian(s, x, C, NULL), EOM_OK);
        core_matvec(3, 3, M, xd + 3, Mq);
        core_chain_force(c, x, Fh, &sc);
        for (i = 0; i < 3; i++) {
            F[i] = -dV[i];
            r[i] = Mq[i] - C[i] * lam[0] - C[3 + i] * lam[1];
        }
        /* the differences agree with the hand-derived -dV/dq */
        CHECK_VEC_SCALED("rest: -dV/dq by differences vs by hand", F, Fh, 3,
                         sc, 1e-9);
        CHECK_VEC_SCALED("rest: M qdd - C^T lambda = F", r, F, 3,
                         sc + fabs(lam[0]) + fabs(lam[1]), 1e-9);
        /* and the tip is held: at rest gamma = 0, so C qdd = 0 */
        core_matvec(2, 3, C, xd + 3, r);
        CHECK(core_maxabs(r, 2) <=
              1e-13 * fmax(1.0, 2.0 * core_maxabs(xd + 3, 3)));
    }
}

/* 3: a run with projection from the projected guess x0, to tend with
 * steps dt, sampled every 0.05 s; returns max |E - E0|. */
static double run(eom_system *s, const core_chain *c, const double *x0,
                  double dt, double tend, int verbose)
{
    double x[6], phi[2], phidot[2], Cm[6], W, E0, T, V;
    double Tmin = INFINITY, Tmax = -INFINITY, dE = 0.0, res = 0.0;
    double th1min = INFINITY, th1max = -INFINITY, Vmin = INFINITY,
           Vmax = -INFINITY;
    const long nsteps = lround(tend / dt);
    const int nsamples = (int)lround(tend / 0.05);
    eom_opts o;
    eom_integ *it = NULL;
    eom_stats st;
    int k;

    E0 = core_chain_T(c, x0) + core_chain_V(c, x0);
    eom_opts_default(&o);
    o.method = EOM_RK4;
    o.dt = dt;
    CHECK(o.project == 1);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x0), EOM_OK);
    if (!it)
        return INFINITY;
    for (k = 1; k <= nsamples; k++) {
        if (eom_integ_advance(it, 0.05 * k, x, &W) != EOM_OK) {
            CHECK_FAIL_("advance to %g: %s", 0.05 * k,
                        eom_integ_errmsg(it));
            dE = INFINITY;
            break;
        }
        core_chain_constraints(c, x, phi, Cm, NULL);
        core_matvec(2, 3, Cm, x + 3, phidot);
        res = fmax(res, fmax(core_maxabs(phi, 2), core_maxabs(phidot, 2)));
        T = core_chain_T(c, x);
        V = core_chain_V(c, x);
        dE = fmax(dE, fabs(T + V - E0));
        Tmin = fmin(Tmin, T);
        Tmax = fmax(Tmax, T);
        Vmin = fmin(Vmin, V);
        Vmax = fmax(Vmax, V);
        th1min = fmin(th1min, x[0]);
        th1max = fmax(th1max, x[0]);
        CHECK(W == 0.0);
    }
    if (verbose)
        printf("four-bar run, dt %g, %g s: max residual %.3g, max |E - E0| "
               "%.3g (E0 %.3g, T in [%.3g, %.3g], V in [%.3g, %.3g], crank "
               "over %.3g rad)\n", dt, tend, res, dE, E0, Tmin, Tmax, Vmin,
               Vmax, th1max - th1min);
    CHECK(res <= 1e-11);
    CHECK(Tmax - Tmin > 10.0); /* energy really is exchanged */
    CHECK(th1max - th1min > 2.0 * CORE_PI); /* the crank turns round */
    CHECK_INT(eom_integ_stats(it, &st), EOM_OK);
    CHECK_INT(st.steps, nsteps);
    CHECK_INT(st.rhs_evals, 4 * nsteps);
    CHECK(st.max_residual <= 1e-12);
    CHECK(st.projections > 0);
    eom_integ_free(&it);
    CHECK(it == NULL);
    return dE;
}

static void check_run(eom_system *s, const core_chain *c)
{
    double x0[6], phi[2], phidot[2], Cm[6], E0, dE1, dE2;
    eom_energy e;
    int iters = -1;

    /* a rough guess of the assembly (upper branch, crank up), crank
     * turning at 3 rad/s; projection makes it consistent */
    x0[0] = 1.5;
    x0[1] = 0.3;
    x0[2] = -1.3;
    x0[3] = 3.0;
    x0[4] = x0[5] = 0.0;
    CHECK_INT(eom_project(s, x0, 1e-14, &iters), EOM_OK);
    CHECK(iters >= 1 && iters <= 8);
    core_chain_constraints(c, x0, phi, Cm, NULL);
    CHECK(core_maxabs(phi, 2) <= 1e-14);
    core_matvec(2, 3, Cm, x0 + 3, phidot);
    CHECK(core_maxabs(phidot, 2) <= 1e-14);
    CHECK(fabs(x0[3]) > 0.5); /* still turning */

    E0 = core_chain_T(c, x0) + core_chain_V(c, x0);
    CHECK_INT(eom_energy_at(s, 0.0, x0, &e), EOM_OK);
    CHECK_NEAR(e.E, E0, 1e-13 * fmax(1.0, fabs(E0)));

    /* 20 s at dt = 1e-3: the drift of E is RK4's truncation error, 4.7e-7
     * J here against E0 = 55.2 J; the bound is 1e-6 J. */
    dE1 = run(s, c, x0, 1e-3, 20.0, 1);
    CHECK(dE1 <= 1e-6);
    /* and it is a fourth-order error: halving dt over 5 s divides it by
     * about 16 (at least 10 is required) */
    dE1 = run(s, c, x0, 2e-3, 5.0, 1);
    dE2 = run(s, c, x0, 1e-3, 5.0, 1);
    CHECK(dE2 > 0.0 && dE1 / dE2 >= 10.0);
}

static void check_bead(rng *g)
{
    const double m = 0.7, l = 1.3, gr = 9.81;
    eom_system *s = core_system(eom_models_bead_on_circle(m, l, gr));
    double x[4], xd[4], lam, C[2], Fc[2], ref[2];
    int k;
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(eom_system_nconstraints(s), 1);
    /* at rest at the bottom: the model's default state */
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    CHECK(x[0] == 0.0 && x[1] == -l && x[2] == 0.0 && x[3] == 0.0);
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
    CHECK_INT(eom_multipliers(s, 0.0, x, &lam), EOM_OK);
    CHECK_INT(eom_constraint_jacobian(s, x, C, NULL), EOM_OK);
    CHECK_NEAR(C[0] * lam, 0.0, 1e-15);
    CHECK_NEAR(C[1] * lam, m * gr, 1e-15);
    CHECK_NEAR(lam, -m * gr / l, 1e-15);
    CHECK(fabs(xd[2]) <= 1e-15 && fabs(xd[3]) <= 1e-15);

    for (k = 0; k < 50; k++) {
        const double a = rng_range(g, -CORE_PI, CORE_PI);
        const double v = k < 10 ? 0.0 : rng_range(g, -5.0, 5.0);
        const double rx = sin(a), ry = -cos(a), tx = cos(a), ty = sin(a);
        const double N = m * v * v / l + m * gr * cos(a);
        const double sc = m * v * v / l + m * gr;
        x[0] = l * rx;
        x[1] = l * ry;
        x[2] = v * tx;
        x[3] = v * ty;
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        CHECK_INT(eom_multipliers(s, 0.0, x, &lam), EOM_OK);
        CHECK_INT(eom_constraint_jacobian(s, x, C, NULL), EOM_OK);
        Fc[0] = C[0] * lam;
        Fc[1] = C[1] * lam;
        ref[0] = -N * rx;
        ref[1] = -N * ry;
        CHECK_VEC_SCALED("bead: C^T lambda", Fc, ref, 2, sc, 1e-14);
        ref[0] = -v * v / l * rx - gr * sin(a) * tx;
        ref[1] = -v * v / l * ry - gr * sin(a) * ty;
        CHECK_VEC_SCALED("bead: acceleration", xd + 2, ref, 2, sc / m,
                         1e-14);
    }
    eom_system_free(&s);
}

int main(void)
{
    core_chain c = fourbar_closed_form();
    eom_system *s = fourbar_system();
    rng g = rng_seed(4242);
    CHECK(s != NULL);
    if (!s)
        CHECK_DONE();
    CHECK_INT(eom_system_nconstraints(s), 2);
    check_kkt(s, &c, &g);
    check_rest(s, &c, &g);
    check_run(s, &c);
    check_bead(&g);
    eom_system_free(&s);
    CHECK_DONE();
}
