/* test_chain_dynamics.c - the chain element in motion, against analytic
 * results and conservation laws:
 *
 *   - a single flexible link pinned at both ends (a closed chain of one
 *     link with D = L) vibrates at w_i = (i pi / L)^2 sqrt(EI / rho): the
 *     linearization reproduces the first modes to 1e-10 relative;
 *   - the open chain without damping conserves its total energy to 1e-8
 *     relative over 10 s at tight tolerance;
 *   - the damped closed chain conserves E + W to 1e-8 relative over 10 s,
 *     with constraint residuals below 1e-10 (projection on), and W grows;
 *   - the closed chain's trajectory converges as the number of modes per
 *     link goes 1, 2, 3: the distance to a four-mode reference shrinks;
 *   - projecting a start off the constraints by the least change of the
 *     coordinates (eom_project_start) leaves the deflections, which the
 *     constraints do not involve, untouched (the least kinetic-energy
 *     correction of eom_project does not).
 * The chains are the paper's (the demos of apps/demos/chains.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/chain.h"

static const double pi = 3.14159265358979323846;

/* The paper's open chain: three beams, the last spinning and bent. */
static eom_system *open_chain(int K)
{
    const double th[3] = {pi / 6, -pi / 6, pi / 6}, thd[3] = {0, 0, 0.5};
    double q0[3 * 8] = {0};
    const unsigned char damped[4] = {0, 1, 1, 0};
    eom_chain_spec sp;
    eom_model *m = NULL;
    eom_system *s = NULL;
    memset(&sp, 0, sizeof sp);
    q0[2 * K] = 0.01; /* q3_1 */
    sp.links = 3;
    sp.modes_all = K;
    sp.m = 1.0;
    sp.L = 10.0;
    sp.EI = 4e3;
    sp.theta0 = th;
    sp.theta0_dot = thd;
    sp.q0 = q0;
    sp.damped = damped; /* c = 0: the dampers do nothing */
    if (eom_model_new(&m) == EOM_OK && eom_chain_add(m, &sp) == 0)
        CHECK_INT(eom_system_new(&s, m, NULL, 0), EOM_OK);
    eom_model_free(&m);
    return s;
}

/* The paper's closed chain: five links released from rest, damped at
 * every joint but the base. */
static eom_system *closed_chain(int K, double c)
{
    const double th[5] = {5 * pi / 12, pi / 12, 0, 17 * pi / 12,
                          13 * pi / 12};
    const unsigned char damped[6] = {0, 1, 1, 1, 1, 1};
    eom_chain_spec sp;
    eom_model *m = NULL;
    eom_system *s = NULL;
    memset(&sp, 0, sizeof sp);
    sp.links = 5;
    sp.modes_all = K;
    sp.m = 1.0;
    sp.L = 10.0;
    sp.EI = 4e4;
    sp.g = 9.81;
    sp.c = c;
    sp.damped = damped;
    sp.closed = 1;
    sp.D = 10.0;
    sp.theta0 = th;
    if (eom_model_new(&m) == EOM_OK && eom_chain_add(m, &sp) == 0)
        CHECK_INT(eom_system_new(&s, m, NULL, 0), EOM_OK);
    eom_model_free(&m);
    return s;
}

static void pinned_beam(void)
{
    const int K = 4;
    const double L = 10.0, mass = 1.0, EI = 4e4, rho = mass / L;
    eom_chain_spec sp;
    eom_model *m = NULL;
    eom_system *s = NULL;
    eom_linear lin;
    double q[1 + 4] = {0};
    int i;
    memset(&sp, 0, sizeof sp);
    memset(&lin, 0, sizeof lin);
    sp.links = 1;
    sp.modes_all = K;
    sp.m = mass;
    sp.L = L;
    sp.EI = EI;
    sp.closed = 1;
    sp.D = L;
    if (eom_model_new(&m) != EOM_OK || eom_chain_add(m, &sp) != 0 ||
        eom_system_new(&s, m, NULL, 0) != EOM_OK) {
        CHECK(!"building the pinned beam");
        eom_model_free(&m);
        return;
    }
    /* at theta = 0 the constraint Jacobian's x-row vanishes (rank 1) */
    CHECK_INT(eom_linearize(s, q, &lin), EOM_OK);
    CHECK_INT(lin.nr, K);
    for (i = 0; i < K && i < lin.nr; i++) {
        const double w = pow((i + 1) * pi / L, 2) * sqrt(EI / rho);
        CHECK_NEAR(lin.omega[i] / w, 1.0, 1e-10);
    }
    eom_linear_free(&lin);
    eom_system_free(&s);
    eom_model_free(&m);
}

/* Integrate to t_end with Adams at rtol, sampling 50 times; returns the
 * largest |E + W - E0| / |E0| and the largest constraint residual. */
static void run(eom_system *s, double t_end, double rtol, double *drift,
                double *res, double *W_end, double *x)
{
    eom_opts o;
    eom_integ *it = NULL;
    eom_energy e0, e;
    double W = 0.0, phi[2] = {0, 0};
    const int m = eom_system_nconstraints(s);
    int k;
    eom_opts_default(&o);
    o.method = EOM_ADAMS;
    o.rtol = rtol;
    o.atol = 1e-2 * rtol;
    *drift = *res = 0.0;
    eom_initial_state(s, x);
    CHECK_INT(eom_energy_at(s, 0.0, x, &e0), EOM_OK);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    for (k = 1; it && k <= 50; k++) {
        const double t = t_end * k / 50.0;
        if (eom_integ_advance(it, t, x, &W) != EOM_OK) {
            CHECK(!"the run failed");
            break;
        }
        CHECK_INT(eom_energy_at(s, t, x, &e), EOM_OK);
        *drift = fmax(*drift, fabs(e.E + W - e0.E) / fabs(e0.E));
        if (m > 0) {
            CHECK_INT(eom_residuals(s, x, phi, NULL), EOM_OK);
            *res = fmax(*res, fmax(fabs(phi[0]), fabs(phi[1])));
        }
    }
    *W_end = W;
    eom_integ_free(&it);
}

static void conservation(void)
{
    double x[32], drift, res, W;
    eom_system *s = open_chain(2);
    if (s) {
        run(s, 10.0, 1e-12, &drift, &res, &W, x);
        CHECK(drift <= 1e-8);
        CHECK_NEAR(W, 0.0, 1e-14); /* no damping */
        eom_system_free(&s);
    }
    s = closed_chain(1, 10.0);
    if (s) {
        run(s, 10.0, 1e-12, &drift, &res, &W, x);
        CHECK(drift <= 1e-8);
        CHECK(res <= 1e-10);
        CHECK(W > 1.0); /* the dampers took energy out */
        eom_system_free(&s);
    }
}

/* The trajectory with K modes per link, at t = 2 s: the angles. */
static void angles_at(int K, double *th)
{
    double x[64], drift, res, W;
    eom_system *s = closed_chain(K, 10.0);
    int j;
    if (!s)
        return;
    run(s, 2.0, 1e-11, &drift, &res, &W, x);
    for (j = 0; j < 5; j++)
        th[j] = x[j];
    eom_system_free(&s);
}

static double dist(const double *a, const double *b)
{
    double d = 0.0;
    int j;
    for (j = 0; j < 5; j++)
        d = fmax(d, fabs(a[j] - b[j]));
    return d;
}

static void mode_convergence(void)
{
    double th[5][5] = {{0}}, e[4];
    int K;
    for (K = 1; K <= 4; K++)
        angles_at(K, th[K]);
    for (K = 1; K <= 3; K++)
        e[K] = dist(th[K], th[4]);
    /* measured: 8.7e-6, 4.2e-6, 6.3e-7 (the even modes carry no modal
     * momentum b_i, so the second step is the larger one) */
    CHECK(e[1] > e[2] && e[2] > e[3]);
    CHECK(e[3] < e[1] / 5.0);
    CHECK(e[1] < 1e-3); /* and the flexible corrections stay small */
}

static void start_projection(void)
{
    eom_system *s = closed_chain(1, 10.0);
    double x[20], y[20], phi[2], phid[2], dmax = 0.0;
    int i, it = 0;
    if (!s)
        return;
    eom_initial_state(s, x);
    CHECK_INT(eom_set_param(s, eom_param_index(s, "D"), 12.0), EOM_OK);
    x[10 + 1] = 0.3; /* theta2_dot: breaks C qd = 0 too */
    memcpy(y, x, sizeof x);
    CHECK_INT(eom_project_start(s, x, 1e-12, &it), EOM_OK);
    CHECK(it > 0);
    CHECK_INT(eom_residuals(s, x, phi, phid), EOM_OK);
    CHECK(fabs(phi[0]) <= 1e-12 && fabs(phi[1]) <= 1e-12);
    CHECK(fabs(phid[0]) <= 1e-12 && fabs(phid[1]) <= 1e-12);
    for (i = 5; i < 10; i++) { /* q and qd of the five modes */
        CHECK(x[i] == 0.0);
        CHECK(x[10 + i] == 0.0);
    }
    CHECK_INT(eom_project(s, y, 1e-12, NULL), EOM_OK);
    for (i = 5; i < 10; i++)
        dmax = fmax(dmax, fabs(y[i]));
    CHECK(dmax > 1e-3); /* the M-norm correction bends the links */
    eom_system_free(&s);
}

int main(void)
{
    pinned_beam();
    start_projection();
    conservation();
    mode_convergence();
    CHECK_DONE();
}
