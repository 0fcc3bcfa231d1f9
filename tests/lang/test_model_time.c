/* test_model_time.c - model files whose energies and constraints read the
 * time t, against the same models written in C and against closed forms.
 *
 *  - A pendulum on a pivot driven as y0 = a sin(w t) (the model of
 *    tests/eom_core/test_moving_support.c, with units on): the file and
 *    the C callbacks give the same accelerations, energies, explicit-time
 *    power and probe at 20 states and times (to rounding), and both the
 *    hand equation thdd = -(g + y0'') sin th / l.
 *  - models/driven-crank.eom, the shipped slider-crank driven at th = w t
 *    with a pendulum hanging from the slider. The drive fixes the crank,
 *    so by hand
 *        x(t)  = r cos(w t) + sqrt(l^2 - r^2 sin^2(w t))
 *        ph(t) = -asin(r sin(w t) / l)
 *    and the pendulum, in the slider's accelerating frame, obeys
 *        psidd = -(g sin psi + x'' cos psi) / lp
 *        x''   = -r w^2 c - r^2 w^2 (c^2 - s^2) / D - r^4 w^2 s^2 c^2 / D^3
 *    with s = sin(w t), c = cos(w t), D = sqrt(l^2 - r^2 s^2), integrated
 *    here by RK4 at a small step. A 3 s run with erk at rtol 1e-11 agrees
 *    with all four, and E + W (W with the motor's work) stays constant.
 *
 * usage: test_model_time MODELS_DIR */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom/model_file.h"
#include "support_rng.h"

/* ---- the driven pivot -------------------------------------------------- */

static const char *const pivot_file =
    "# a pendulum whose pivot is driven up and down\n"
    "param m = 0.7  [kg]\n"
    "param l = 1.3  [m]\n"
    "param g = 9.81 [m/s^2]\n"
    "param a = 0.2  [m]\n"
    "param w = 7    [rad/s]\n"
    "coord th = 0.4 [rad]\n"
    "y0 = a*sin(w*t)\n"
    "T = 1/2*m*((l*cos(th)*th_dot)^2 + (a*w*cos(w*t) + l*sin(th)*th_dot)^2)\n"
    "V = m*g*(y0 - l*cos(th))\n"
    "probe pivot = y0 [m]\n";

static const double PM = 0.7, PL = 1.3, PG = 9.81, PA = 0.2, PW = 7.0;

static int c_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val th = eom_q(c, 0), thd = eom_qd(c, 0), t = eom_time(c);
    tp_val vx = tp_mulc(R, tp_mul(R, tp_cos(R, th), thd), PL);
    tp_val vy = tp_add(R, tp_mulc(R, tp_cos(R, tp_mulc(R, t, PW)), PA * PW),
                       tp_mulc(R, tp_mul(R, tp_sin(R, th), thd), PL));
    (void)user;
    *out = tp_mulc(R, tp_add(R, tp_sqr(R, vx), tp_sqr(R, vy)), 0.5 * PM);
    return 0;
}

static tp_val c_y0(eom_ctx *c)
{
    tp_rec *R = eom_rec(c);
    return tp_mulc(R, tp_sin(R, tp_mulc(R, eom_time(c), PW)), PA);
}

static int c_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mulc(R, tp_sub(R, c_y0(c),
                             tp_mulc(R, tp_cos(R, eom_q(c, 0)), PL)),
                   PM * PG);
    return 0;
}

static int c_probe(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = c_y0(c);
    return 0;
}

static eom_system *system_of(eom_model *md)
{
    eom_system *s = NULL;
    char msg[512];
    if (!md)
        return NULL;
    if (eom_system_new(&s, md, msg, sizeof msg) != EOM_OK)
        CHECK_FAIL_("eom_system_new: %s", msg);
    eom_model_free(&md);
    return s;
}

static void pivot_agrees(void)
{
    eom_model *fm = NULL, *cm = NULL;
    eom_system *f, *c;
    char err[2048];
    rng g = rng_seed(31337);
    double worst = 0.0;
    int k;
    if (eom_model_from_string(&fm, pivot_file, err, sizeof err) != EOM_OK)
        CHECK_FAIL_("%s", err);
    eom_model_new(&cm);
    eom_model_add_coord(cm, "th", "rad", 0.4, 0.0);
    eom_model_set_kinetic(cm, c_T, NULL);
    eom_model_set_potential(cm, c_V, NULL);
    eom_model_add_probe(cm, "pivot", "m", c_probe, NULL);
    f = system_of(fm);
    c = system_of(cm);
    if (!f || !c) {
        eom_system_free(&f);
        eom_system_free(&c);
        return;
    }
    CHECK_INT(eom_system_reads_time(f), 1);
    for (k = 0; k < 20; k++) {
        const double t = rng_range(&g, 0.0, 5.0);
        const double y0dd = -PA * PW * PW * sin(PW * t);
        double x[2], xf[2], xc[2], pf, pc;
        eom_energy ef, ec;
        x[0] = rng_range(&g, -3.0, 3.0);
        x[1] = rng_range(&g, -4.0, 4.0);
        CHECK_INT(eom_rhs(f, t, x, xf), EOM_OK);
        CHECK_INT(eom_rhs(c, t, x, xc), EOM_OK);
        CHECK_NEAR(xf[1], xc[1], 1e-13);
        CHECK_NEAR(xf[1], -(PG + y0dd) * sin(x[0]) / PL, 1e-13);
        worst = fmax(worst, fabs(xf[1] - xc[1]));
        CHECK_INT(eom_energy_at(f, t, x, &ef), EOM_OK);
        CHECK_INT(eom_energy_at(c, t, x, &ec), EOM_OK);
        CHECK_NEAR(ef.E, ec.E, 1e-13);
        CHECK_NEAR(ef.T, ec.T, 1e-13);
        CHECK_NEAR(ef.Pt, ec.Pt, 1e-12);
        CHECK(fabs(ef.Pt) > 0.0 || fabs(x[1]) < 1e-3);
        CHECK_INT(eom_set_time(f, t), EOM_OK);
        CHECK_INT(eom_set_time(c, t), EOM_OK);
        CHECK_INT(eom_probes_at(f, x, &pf), EOM_OK);
        CHECK_INT(eom_probes_at(c, x, &pc), EOM_OK);
        CHECK_NEAR(pf, PA * sin(PW * t), 1e-15);
        CHECK_NEAR(pc, pf, 1e-15);
    }
    printf("driven pivot: file vs C, worst |thdd difference| %.2e\n", worst);
    eom_system_free(&f);
    eom_system_free(&c);
}

/* ---- the shipped driven crank ------------------------------------------ */

typedef struct crank_prm {
    double r, l, lp, w, g;
} crank_prm;

static double slider_acc(const crank_prm *p, double t)
{
    const double s = sin(p->w * t), c = cos(p->w * t);
    const double D = sqrt(p->l * p->l - p->r * p->r * s * s);
    const double r2 = p->r * p->r, w2 = p->w * p->w;
    return -p->r * w2 * c - r2 * w2 * (c * c - s * s) / D -
           r2 * r2 * w2 * s * s * c * c / (D * D * D);
}

static void psi_rhs(const crank_prm *p, double t, const double *y,
                    double *yd)
{
    yd[0] = y[1];
    yd[1] = -(p->g * sin(y[0]) + slider_acc(p, t) * cos(y[0])) / p->lp;
}

static void psi_rk4(const crank_prm *p, double t, double h, double *y)
{
    double k1[2], k2[2], k3[2], k4[2], z[2];
    int i;
    psi_rhs(p, t, y, k1);
    for (i = 0; i < 2; i++)
        z[i] = y[i] + 0.5 * h * k1[i];
    psi_rhs(p, t + 0.5 * h, z, k2);
    for (i = 0; i < 2; i++)
        z[i] = y[i] + 0.5 * h * k2[i];
    psi_rhs(p, t + 0.5 * h, z, k3);
    for (i = 0; i < 2; i++)
        z[i] = y[i] + h * k3[i];
    psi_rhs(p, t + h, z, k4);
    for (i = 0; i < 2; i++)
        y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

static double param(const eom_system *s, const char *name)
{
    return eom_get_param(s, eom_param_index(s, name));
}

static void driven_crank(const char *dir)
{
    char path[1024], err[2048];
    eom_model *md = NULL;
    eom_system *s;
    eom_integ *it = NULL;
    eom_energy e0, e;
    eom_opts o;
    crank_prm p;
    double x[8], y[2] = {0.0, 0.0}, W = 0.0, wk = 0.0, wp = 0.0, we = 0.0;
    double phi[3], phid[3], wr = 0.0;
    int k, j;
    snprintf(path, sizeof path, "%s/driven-crank.eom", dir);
    if (eom_model_from_file(&md, path, err, sizeof err) != EOM_OK) {
        CHECK_FAIL_("%s", err);
        return;
    }
    s = system_of(md);
    if (!s)
        return;
    CHECK_INT(eom_system_ncoords(s), 4);
    CHECK_INT(eom_system_nconstraints(s), 3);
    CHECK_INT(eom_system_reads_time(s), 1);
    p.r = param(s, "r");
    p.l = param(s, "l");
    p.lp = param(s, "lp");
    p.w = param(s, "w");
    p.g = param(s, "g");
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    /* the file's start is on the constraints and their velocity form */
    CHECK_INT(eom_residuals(s, x, phi, phid), EOM_OK);
    for (j = 0; j < 3; j++)
        CHECK(fabs(phi[j]) < 1e-15 && fabs(phid[j]) < 1e-15);
    CHECK_INT(eom_energy_at(s, 0.0, x, &e0), EOM_OK);
    eom_opts_default(&o);
    o.method = EOM_ERK;
    o.rtol = 1e-11;
    o.atol = 1e-13;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    for (k = 1; k <= 30 && it; k++) {
        const double t = 0.1 * k, sn = sin(p.w * t);
        if (eom_integ_advance(it, t, x, &W) != EOM_OK) {
            CHECK_FAIL_("driven crank: %s", eom_integ_errmsg(it));
            break;
        }
        for (j = 0; j < 1000; j++)
            psi_rk4(&p, t - 0.1 + 1e-4 * j, 1e-4, y);
        wk = fmax(wk, fabs(x[0] - p.w * t));
        wk = fmax(wk, fabs(x[1] + asin(p.r * sn / p.l)));
        wk = fmax(wk, fabs(x[2] - (p.r * cos(p.w * t) +
                                   sqrt(p.l * p.l - p.r * p.r * sn * sn))));
        wp = fmax(wp, fmax(fabs(x[3] - y[0]), fabs(x[7] - y[1])));
        CHECK_INT(eom_energy_at(s, t, x, &e), EOM_OK);
        we = fmax(we, fabs(e.E + W - e0.E));
        CHECK_INT(eom_residuals(s, x, phi, phid), EOM_OK);
        for (j = 0; j < 3; j++)
            wr = fmax(wr, fmax(fabs(phi[j]), fabs(phid[j])));
    }
    eom_integ_free(&it);
    printf("driven crank, erk 3 s: crank, rod and slider against the closed "
           "forms %.2e; pendulum against its own equation %.2e; |E + W - "
           "E0| %.2e J (E0 %.3f J, W %.3f J); residuals %.2e\n", wk, wp, we,
           e0.E, W, wr);
    /* about ten times what the run gets */
    CHECK(wk <= 1e-11);
    CHECK(wp <= 5e-10);
    CHECK(we <= 1e-9);
    CHECK(wr <= 1e-11);
    eom_system_free(&s);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_model_time MODELS_DIR\n");
        return 2;
    }
    pivot_agrees();
    driven_crank(argv[1]);
    CHECK_DONE();
}
