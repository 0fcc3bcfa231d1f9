/* test_equilibrium.c - eom_equilibrium, checked independently of the
 * linearization code:
 *
 *   four-bar         three rods pinned at (0, 0) and (D, 0) with gravity,
 *                    from a start off the constraints: phi = 0
 *                    (eom_residuals), the system stays at rest (eom_rhs
 *                    gives qdd = 0), and -dV/dq + C^T lambda = 0 with
 *                    dV/dq by central differences of V (eom_energy_at)
 *                    and lambda from eom_multipliers. Its frequency from
 *                    eom_linearize against the second variation of V
 *                    along the mode: V(c(e)) for the curve c(e) =
 *                    eom_project(q + e v) on the constraints,
 *                      omega^2 = (d2/de2 V(c(e))) / (v^T M v),
 *                    by central differences. The inverted four-bar:
 *                    found from a start above, with omega < 0.
 *   pendulum         to theta = 0 and theta = pi; with a constant torque
 *                    tau < m g l to sin theta = tau / (m g l), where
 *                    omega^2 = g cos(theta) / l.
 *   forces           the pendulum with its torque as a declared force
 *                    Q = tq (not a potential): the same sin theta =
 *                    tq / (m g l) and omega; a force that reads theta
 *                    (Q = tq - k theta) stiffens K by k, one that reads
 *                    theta_dot (Q = -b theta_dot) adds b to D; a force
 *                    that reads the time is refused by both calls with
 *                    a message naming the coordinate; a circulatory
 *                    force (x, y on springs, Q = (c y, -c x)) has its
 *                    equilibrium found and eom_linearize refused with a
 *                    message (K is not symmetric).
 *   double pendulum  unconstrained Newton to the hanging state.
 *   failures         no equilibrium (tau > m g l; rods too short to
 *                    reach the far pin): EOM_ERR_NOT_CONVERGED with a
 *                    message and the guess restored; bad arguments.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom_models.h"
#include "lin_models.h"

static const double PI_ = 3.14159265358979323846;
static const double G = 9.81;

static int equilibrium(eom_system *s, double *q, double tol, int *it)
{
    int rc = eom_equilibrium(s, q, tol, it);
    if (rc != EOM_OK)
        fprintf(stderr, "eom_equilibrium: %s\n", eom_system_errmsg(s));
    return rc;
}

static int linearize(eom_system *s, const double *q, eom_linear *lin)
{
    int rc = eom_linearize(s, q, lin);
    if (rc != EOM_OK)
        fprintf(stderr, "eom_linearize: %s\n", eom_system_errmsg(s));
    return rc;
}

/* V at q (at rest). */
static double V_at(eom_system *s, const double *q, int n)
{
    double x[8] = {0};
    eom_energy e;
    memcpy(x, q, (size_t)n * sizeof(double));
    if (eom_energy_at(s, 0.0, x, &e) != EOM_OK)
        return NAN;
    return e.V;
}

/* The equilibrium conditions at q, from the library's other routines. */
static void check_at_rest(eom_system *s, const double *q, int n)
{
    const int m = eom_system_nconstraints(s);
    const double h = 1e-6;
    double x[8] = {0}, xd[8], C[8], phi[2], lam[2], qh[4];
    int i, k;
    memcpy(x, q, (size_t)n * sizeof(double));
    CHECK_INT(eom_residuals(s, x, phi, NULL), EOM_OK);
    for (k = 0; k < m; k++)
        CHECK_NEAR(phi[k], 0.0, 1e-12);
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
    for (i = 0; i < n; i++)
        CHECK_NEAR(xd[n + i], 0.0, 1e-9);
    CHECK_INT(eom_multipliers(s, 0.0, x, lam), EOM_OK);
    CHECK_INT(eom_constraint_jacobian(s, x, C, NULL), EOM_OK);
    for (i = 0; i < n; i++) {
        double dV, f = 0.0;
        memcpy(qh, q, (size_t)n * sizeof(double));
        qh[i] = q[i] + h;
        dV = V_at(s, qh, n);
        qh[i] = q[i] - h;
        dV = (dV - V_at(s, qh, n)) / (2.0 * h);
        for (k = 0; k < m; k++)
            f += C[k * n + i] * lam[k];
        CHECK_NEAR(-dV + f, 0.0, 1e-7 * fmax(1.0, fabs(dV)));
    }
}

/* omega^2 against the second variation of V along mode 0, on the
 * constraint manifold. */
static void check_second_variation(eom_system *s, const double *q,
                                   const eom_linear *lin)
{
    const int n = lin->n;
    const double e = 1e-3;
    double x[8], M[16], Vp = NAN, Vm = NAN, V0, vMv = 0.0, d2V;
    int i, j, sign;
    for (sign = -1; sign <= 1; sign += 2) {
        for (i = 0; i < n; i++) {
            x[i] = q[i] + sign * e * lin->modes[i * lin->nr];
            x[n + i] = 0.0;
        }
        CHECK_INT(eom_project(s, x, 1e-15, NULL), EOM_OK);
        if (sign < 0)
            Vm = V_at(s, x, n);
        else
            Vp = V_at(s, x, n);
    }
    V0 = V_at(s, q, n);
    for (i = 0; i < n; i++)
        x[i] = q[i], x[n + i] = 0.0;
    CHECK_INT(eom_mass_matrix(s, x, M), EOM_OK);
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++)
            vMv += lin->modes[i * lin->nr] * M[i * n + j] *
                   lin->modes[j * lin->nr];
    d2V = (Vp - 2.0 * V0 + Vm) / (e * e);
    CHECK_NEAR(lin->omega[0] * fabs(lin->omega[0]), d2V / vMv,
               1e-6 * fabs(d2V / vMv));
}

static void test_four_bar(void)
{
    const double m[3] = {1.0, 1.4, 0.8}, l[3] = {1.0, 1.5, 1.2};
    double q[3] = {-1.3, 0.2, 1.2};
    eom_system *s = lin_models_system(
        eom_models_rod_chain(3, m, l, q, G, 1, 1.6));
    eom_linear lin;
    int it = -1;
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(equilibrium(s, q, 1e-12, &it), EOM_OK);
    CHECK(it > 0 && it <= 50);
    CHECK(q[0] < 0.0 && q[2] > 0.0); /* hanging below the pins */
    check_at_rest(s, q, 3);
    CHECK_INT(linearize(s, q, &lin), EOM_OK);
    CHECK_INT(lin.nr, 1);
    if (lin.nr == 1) {
        CHECK(lin.omega[0] > 0.0);
        check_second_variation(s, q, &lin);
    }
    eom_linear_free(&lin);

    /* from the mirror image above the pins: the inverted equilibrium */
    q[0] = 1.3, q[1] = -0.2, q[2] = -1.2;
    CHECK_INT(equilibrium(s, q, 1e-12, &it), EOM_OK);
    CHECK(q[0] > 0.0 && q[2] < 0.0);
    check_at_rest(s, q, 3);
    CHECK_INT(linearize(s, q, &lin), EOM_OK);
    CHECK_INT(lin.nr, 1);
    if (lin.nr == 1) {
        CHECK(lin.omega[0] < 0.0);
        check_second_variation(s, q, &lin);
    }
    eom_linear_free(&lin);

    /* already at rest: no step */
    CHECK_INT(equilibrium(s, q, 1e-9, &it), EOM_OK);
    CHECK_INT(it, 0);

    /* the far pin out of reach: no configuration satisfies phi = 0 */
    CHECK_INT(eom_set_param(s, eom_param_index(s, "D"), 5.0), EOM_OK);
    q[0] = -1.3, q[1] = 0.2, q[2] = 1.2;
    CHECK_INT(eom_equilibrium(s, q, 1e-10, &it), EOM_ERR_NOT_CONVERGED);
    CHECK(strstr(eom_system_errmsg(s), "eom_equilibrium") != NULL);
    CHECK(q[0] == -1.3 && q[1] == 0.2 && q[2] == 1.2);
    eom_system_free(&s);
}

static void test_pendulum(void)
{
    const double m = 0.7, l = 1.3, mgl = m * G * l;
    eom_system *s = lin_models_system(lin_models_pendulum(m, l, G, 0.0, 0.0,
                                                          0, 0.0));
    eom_linear lin;
    double q;
    int it = 0, ktau;
    CHECK(s != NULL);
    if (!s)
        return;
    q = 0.3;
    CHECK_INT(equilibrium(s, &q, 1e-12, &it), EOM_OK);
    CHECK(fabs(mgl * sin(q)) <= 1e-12);
    CHECK_NEAR(q, 0.0, 1e-12);
    CHECK(it > 0 && it < 10);
    q = 3.0;
    CHECK_INT(equilibrium(s, &q, 1e-12, &it), EOM_OK);
    CHECK_NEAR(q, PI_, 1e-12);

    /* a constant torque shifts the equilibrium to sin theta = tau / mgl */
    ktau = eom_param_index(s, "tau");
    CHECK_INT(eom_set_param(s, ktau, 0.5 * mgl), EOM_OK);
    q = 0.0;
    CHECK_INT(equilibrium(s, &q, 1e-12, &it), EOM_OK);
    CHECK_NEAR(q, PI_ / 6.0, 1e-12);
    CHECK_INT(linearize(s, &q, &lin), EOM_OK);
    if (lin.nr == 1)
        CHECK_NEAR(lin.omega[0], sqrt(G * cos(PI_ / 6.0) / l), 1e-12);
    eom_linear_free(&lin);

    /* tau > m g l: no equilibrium at all */
    CHECK_INT(eom_set_param(s, ktau, 2.0 * mgl), EOM_OK);
    q = 0.3;
    CHECK_INT(eom_equilibrium(s, &q, 1e-10, &it), EOM_ERR_NOT_CONVERGED);
    CHECK(strlen(eom_system_errmsg(s)) > 0);
    CHECK(q == 0.3);
    eom_system_free(&s);
}

/* The pendulum's declared force, by *mode: 0 Q = tq, 1 Q = tq - k theta,
 * 2 Q = tq - b theta_dot, 3 Q = tq cos(t). */
static int pend_force(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    const int mode = *(const int *)user;
    tp_val tq = eom_param(c, "tq");
    if (mode == 1)
        tq = tp_sub(R, tq, tp_mul(R, eom_param(c, "k"), eom_q(c, 0)));
    else if (mode == 2)
        tq = tp_sub(R, tq, tp_mul(R, eom_param(c, "b"), eom_qd(c, 0)));
    else if (mode == 3)
        tq = tp_mul(R, tq, tp_cos(R, eom_time(c)));
    out[0] = tq;
    return 0;
}

static eom_system *forced_pendulum(double m, double l, double tq,
                                   int *mode)
{
    eom_model *md = lin_models_pendulum(m, l, G, 0.0, 0.3, 1, 0.0);
    if (!md)
        return NULL;
    eom_model_add_param(md, "tq", "N m", tq, "torque (a force)");
    eom_model_add_param(md, "k", "N m", 2.0, "torsion spring (a force)");
    eom_model_add_param(md, "b", "N m s", 0.4, "damper (a force)");
    eom_model_set_forces(md, pend_force, mode);
    return lin_models_system(md);
}

static int plane_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mulc(R, tp_add(R, tp_sqr(R, eom_qd(c, 0)),
                             tp_sqr(R, eom_qd(c, 1))), 0.5);
    return 0;
}

static int plane_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mulc(R, tp_add(R, tp_sqr(R, eom_q(c, 0)),
                             tp_sqr(R, eom_q(c, 1))), 2.0);
    return 0;
}

/* A follower load on a unit mass held by springs 4 N/m: Q = (y, 0.5 - x). */
static int plane_Q(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    out[0] = eom_q(c, 1);
    out[1] = tp_csub(R, 0.5, eom_q(c, 0));
    return 0;
}

static void test_forces(void)
{
    const double m = 0.7, l = 1.3, mgl = m * G * l, tq = 0.4 * mgl;
    const double th = asin(0.4);
    static int modes[4] = {0, 1, 2, 3};
    eom_linear lin;
    eom_model *md = NULL;
    eom_system *s;
    double q, xy[2];
    int it = 0;

    /* a constant torque declared as a force */
    s = forced_pendulum(m, l, tq, &modes[0]);
    CHECK(s != NULL);
    if (s) {
        q = 0.0;
        CHECK_INT(equilibrium(s, &q, 1e-12, &it), EOM_OK);
        CHECK_NEAR(q, th, 1e-12);
        CHECK_INT(linearize(s, &q, &lin), EOM_OK);
        if (lin.nr == 1) {
            CHECK_NEAR(lin.omega[0], sqrt(G * cos(th) / l), 1e-12);
            CHECK_NEAR(lin.D[0], 0.3, 1e-14);
        }
        eom_linear_free(&lin);
        /* the hanging state is not at rest under the torque */
        q = 0.0;
        CHECK_INT(eom_linearize(s, &q, &lin), EOM_ERR_ARG);
        eom_system_free(&s);
    }

    /* a force that reads theta: balance mgl sin q + k q = tq, K + k */
    s = forced_pendulum(m, l, tq, &modes[1]);
    CHECK(s != NULL);
    if (s) {
        q = 0.0;
        CHECK_INT(equilibrium(s, &q, 1e-12, &it), EOM_OK);
        CHECK_NEAR(mgl * sin(q) + 2.0 * q, tq, 1e-12);
        CHECK_INT(linearize(s, &q, &lin), EOM_OK);
        if (lin.nr == 1)
            CHECK_NEAR(lin.omega[0],
                       sqrt((mgl * cos(q) + 2.0) / (m * l * l)), 1e-12);
        eom_linear_free(&lin);
        eom_system_free(&s);
    }

    /* a force that reads theta_dot: no part in the balance, b in D */
    s = forced_pendulum(m, l, tq, &modes[2]);
    CHECK(s != NULL);
    if (s) {
        q = 0.0;
        CHECK_INT(equilibrium(s, &q, 1e-12, &it), EOM_OK);
        CHECK_NEAR(q, th, 1e-12);
        CHECK_INT(linearize(s, &q, &lin), EOM_OK);
        if (lin.nr == 1) {
            CHECK_NEAR(lin.omega[0], sqrt(G * cos(th) / l), 1e-12);
            CHECK_NEAR(lin.D[0], 0.3 + 0.4, 1e-14);
        }
        eom_linear_free(&lin);
        eom_system_free(&s);
    }

    /* a force that reads the time: refused, the coordinate named */
    s = forced_pendulum(m, l, tq, &modes[3]);
    CHECK(s != NULL);
    if (s) {
        q = 0.1;
        CHECK_INT(eom_equilibrium(s, &q, 1e-12, &it), EOM_ERR_MODEL);
        CHECK(strstr(eom_system_errmsg(s), "force on theta reads the "
                                           "time") != NULL);
        CHECK(q == 0.1);
        CHECK_INT(eom_linearize(s, &q, &lin), EOM_ERR_MODEL);
        CHECK(strstr(eom_system_errmsg(s), "reads the time") != NULL);
        eom_system_free(&s);
    }

    /* a circulatory force: the equilibrium, and no undamped frequencies */
    CHECK_INT(eom_model_new(&md), EOM_OK);
    eom_model_add_coord(md, "x", "m", 0.1, 0.0);
    eom_model_add_coord(md, "y", "m", 0.0, 0.0);
    eom_model_set_kinetic(md, plane_T, NULL);
    eom_model_set_potential(md, plane_V, NULL);
    eom_model_set_forces(md, plane_Q, NULL);
    s = lin_models_system(md);
    CHECK(s != NULL);
    if (s) {
        xy[0] = 0.1;
        xy[1] = 0.0;
        CHECK_INT(equilibrium(s, xy, 1e-13, &it), EOM_OK);
        /* 4 x = y, 4 y = 0.5 - x */
        CHECK_NEAR(xy[0], 0.5 / 17.0, 1e-13);
        CHECK_NEAR(xy[1], 2.0 / 17.0, 1e-13);
        CHECK_INT(eom_linearize(s, xy, &lin), EOM_ERR_MODEL);
        CHECK(strstr(eom_system_errmsg(s), "unsymmetric") != NULL);
        eom_system_free(&s);
    }
}

static void test_double_pendulum(void)
{
    const double m[2] = {1.5, 0.8}, l[2] = {1.2, 0.7};
    double q[2] = {-1.2, -2.0};
    eom_system *s = lin_models_system(
        eom_models_rod_chain(2, m, l, q, G, 0, 0.0));
    int it = 0;
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(equilibrium(s, q, 1e-12, &it), EOM_OK);
    CHECK_NEAR(q[0], -PI_ / 2.0, 1e-12);
    CHECK_NEAR(q[1], -PI_ / 2.0, 1e-12);
    check_at_rest(s, q, 2);
    eom_system_free(&s);
}

static void test_bad_input(void)
{
    eom_system *s = lin_models_system(lin_models_pendulum(1.0, 1.0, G, 0.0,
                                                          0.0, 0, 0.0));
    double q = 0.3;
    int it = 7;
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK_INT(eom_equilibrium(NULL, &q, 1e-9, &it), EOM_ERR_NULL);
    CHECK_INT(it, 0);
    CHECK_INT(eom_equilibrium(s, NULL, 1e-9, &it), EOM_ERR_NULL);
    CHECK(eom_system_errmsg(s)[0] != '\0');
    CHECK_INT(eom_equilibrium(s, &q, 0.0, &it), EOM_ERR_ARG);
    CHECK_INT(eom_equilibrium(s, &q, -1.0, NULL), EOM_ERR_ARG);
    CHECK_INT(eom_equilibrium(s, &q, NAN, NULL), EOM_ERR_ARG);
    CHECK(q == 0.3);
    q = NAN;
    CHECK_INT(eom_equilibrium(s, &q, 1e-9, &it), EOM_ERR_NONFINITE);
    q = -INFINITY;
    CHECK_INT(eom_equilibrium(s, &q, 1e-9, &it), EOM_ERR_NONFINITE);
    q = 0.3;
    CHECK_INT(equilibrium(s, &q, 1e-9, NULL), EOM_OK);
    CHECK(eom_system_errmsg(s)[0] == '\0');
    eom_system_free(&s);
}

int main(void)
{
    test_four_bar();
    test_pendulum();
    test_forces();
    test_double_pendulum();
    test_bad_input();
    CHECK_DONE();
}
