/* test_model_spatial.c - der(), vectors, matrices and rotations in model
 * files, each against an independent route:
 *
 *  - every shipped planar model with its hand-written velocities replaced
 *    by der() of the positions gives the same right-hand side (qdd and
 *    the multipliers' effect) to 1e-14 at random states, and a 40-link
 *    closed chain written with der() records within 1.3 times the
 *    operations of the hand-written one;
 *  - models/heavy-top.eom (a rotation matrix, an inertia tensor, the
 *    angular velocity from der()) against the textbook Euler-angle
 *    Lagrangian typed by hand: the same right-hand side at random
 *    states, the same trajectory, the energy and the two conjugate
 *    momenta p_psi, p_phi constant over 100 s, and the shipped start in
 *    steady precession at the closed-form rate;
 *  - models/rolling-disk.eom (two velocity constraints from der() and
 *    the angular velocity): released upright it rolls straight on at
 *    x = r phi_dot t; released leaning its energy stays constant
 *    (rolling does no work) and the constraints hold; and it rolls
 *    steadily on a circle at the closed-form rate derived below;
 *  - models/spherical-double-pendulum.eom (two rods on ball joints):
 *    the angular momentum about the vertical (a probe) and the energy
 *    constant to 1e-10 over 10 s, and swinging in a plane it is the
 *    planar compound double pendulum written with hand-written
 *    velocities (the same accelerations to 1e-12);
 *  - the vector algebra through probes (cross, dot, norm, transpose,
 *    rotations about an axis and from a quaternion, angular velocity in
 *    the body and in space) against the same formulas written in C.
 *
 * usage: test_model_spatial MODELS_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/model_file.h"
#include "support_rng.h"
#include "tape/tape.h"

static const char *models_dir = ".";

static char *dup_text(const char *t)
{
    char *s = t ? malloc(strlen(t) + 1) : NULL;
    if (s)
        memcpy(s, t, strlen(t) + 1);
    return s;
}

static char *read_text(const char *name)
{
    char path[1024];
    FILE *f;
    long n;
    char *s;
    snprintf(path, sizeof path, "%s/%s", models_dir, name);
    f = fopen(path, "rb");
    if (!f) {
        CHECK_FAIL_("cannot open %s", path);
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    s = malloc((size_t)n + 1);
    if (!s || fread(s, 1, (size_t)n, f) != (size_t)n) {
        fclose(f);
        free(s);
        CHECK_FAIL_("cannot read %s", path);
        return NULL;
    }
    s[n] = '\0';
    fclose(f);
    return s;
}

/* text with the first occurrence of from replaced by to (a new string);
 * a from that is not there is a failure: the shipped file changed. */
static char *replace(char *text, const char *from, const char *to)
{
    char *at, *out;
    size_t a, b, c;
    if (!text)
        return NULL;
    at = strstr(text, from);
    if (!at) {
        CHECK_FAIL_("the shipped model no longer holds \"%s\"", from);
        free(text);
        return NULL;
    }
    a = (size_t)(at - text);
    b = strlen(to);
    c = strlen(at + strlen(from));
    out = malloc(a + b + c + 1);
    memcpy(out, text, a);
    memcpy(out + a, to, b);
    memcpy(out + a + b, at + strlen(from), c + 1);
    free(text);
    return out;
}

/* The L tape's operations of a model, as the recorder gives them. */
static size_t lagrangian_ops(const eom_model *m)
{
    int n = eom_model_ncoords(m), k;
    unsigned char *group = malloc(2 * (size_t)n);
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    tp_tape_stats st;
    for (k = 0; k < 2 * n; k++)
        group[k] = (unsigned char)(k >= n);
    memset(&st, 0, sizeof st);
    CHECK(tp_recorder_new(&r, 2 * n, group, NULL) == TP_OK);
    CHECK(eom_model_run_lagrangian(m, r, NULL) == EOM_OK);
    CHECK(tp_recorder_finish(r, &t) == TP_OK);
    tp_tape_stats_get(t, &st);
    tp_tape_free(&t);
    tp_rec_free(&r);
    free(group);
    return st.n_ops;
}

/* The system of a model file's text (links: a setting to change, or 0);
 * ops, when not NULL, gets the L tape's operations. */
static eom_system *build(const char *text, const char *what, int links,
                         size_t *ops)
{
    eom_file *f = NULL;
    eom_model *m = NULL;
    eom_system *s = NULL;
    char err[2048];
    if (!text)
        return NULL;
    if (eom_file_parse(&f, text, what, err, sizeof err) != EOM_OK) {
        CHECK_FAIL_("%s: %s", what, err);
        return NULL;
    }
    if (links > 0 &&
        eom_file_set_setting(f, "links", links, err, sizeof err) != EOM_OK)
        CHECK_FAIL_("%s: %s", what, err);
    if (eom_file_build(f, &m, err, sizeof err) != EOM_OK)
        CHECK_FAIL_("%s: %s", what, err);
    eom_file_free(&f);
    if (m && ops)
        *ops = lagrangian_ops(m);
    if (m && eom_system_new(&s, m, err, sizeof err) != EOM_OK)
        CHECK_FAIL_("%s: %s", what, err);
    eom_model_free(&m);
    return s;
}

/* The right-hand sides of a and b at 20 states around a's start. Two
 * tapes that round differently can agree only as far as the equations'
 * own conditioning allows: that is measured on a alone, at each state
 * moved by 1e-15 (as test_model_chains does), and the tolerance is the
 * larger of tol and 10 times it. */
static void same_rhs(eom_system *a, eom_system *b, const char *what,
                     double tol)
{
    int n, k, j;
    double *x, *xa, *xb, *xp, *x0, worst = 0.0, sens = 0.0;
    rng r = rng_seed(12345u);
    if (!a || !b)
        return;
    n = eom_system_ncoords(a);
    CHECK_INT(eom_system_ncoords(b), n);
    x0 = calloc(2 * (size_t)n, sizeof *x0);
    x = calloc(2 * (size_t)n, sizeof *x);
    xa = calloc(2 * (size_t)n, sizeof *xa);
    xb = calloc(2 * (size_t)n, sizeof *xb);
    xp = calloc(2 * (size_t)n, sizeof *xp);
    eom_initial_state(a, x0);
    for (k = 0; k < 20; k++) {
        for (j = 0; j < 2 * n; j++)
            x[j] = x0[j] + 0.3 * (rng_unit(&r) - 0.5) +
                   (j >= n ? rng_unit(&r) - 0.5 : 0.0);
        CHECK_INT(eom_rhs(a, 0.3, x, xa), EOM_OK);
        CHECK_INT(eom_rhs(b, 0.3, x, xb), EOM_OK);
        for (j = 0; j < 2 * n; j++) {
            double s = fmax(1.0, fabs(xa[j]));
            worst = fmax(worst, fabs(xa[j] - xb[j]) / s);
        }
        for (j = 0; j < 2 * n; j++)
            x[j] += 1e-15 * sin(1.0 + j);
        CHECK_INT(eom_rhs(a, 0.3, x, xp), EOM_OK);
        for (j = 0; j < 2 * n; j++)
            sens = fmax(sens, fabs(xa[j] - xp[j]) / fmax(1.0, fabs(xa[j])));
    }
    printf("%s: max relative difference of the right-hand side %.2g "
           "(the start moved by 1e-15 moves it by %.2g)\n", what, worst,
           sens);
    CHECK(worst <= fmax(tol, 10.0 * sens));
    free(x0);
    free(x);
    free(xa);
    free(xb);
    free(xp);
}

/* ---- planar models rewritten with der() -------------------------------- */

typedef struct rewrite {
    const char *from, *to;
} rewrite;

static void planar(const char *file, const rewrite *rw, int nrw)
{
    char *hand = read_text(file), *der = dup_text(hand);
    eom_system *a, *b;
    int k;
    for (k = 0; k < nrw; k++)
        der = replace(der, rw[k].from, rw[k].to);
    a = build(hand, file, 0, NULL);
    b = build(der, file, 0, NULL);
    same_rhs(a, b, file, 1e-14);
    eom_system_free(&a);
    eom_system_free(&b);
    free(hand);
    free(der);
}

static const rewrite chain_rw[] = {
    {"vx[j in 1..links] = vx[j-1] - len*theta_dot[j]*sin(theta[j])",
     "vx[j in 1..links] = der(px[j])\npx[0] = 0\n"
     "px[j in 1..links] = px[j-1] + len*cos(theta[j])"},
    {"vy[j in 1..links] = vy[j-1] + len*theta_dot[j]*cos(theta[j])",
     "vy[j in 1..links] = der(py[j])\npy[0] = 0\n"
     "py[j in 1..links] = py[j-1] + len*sin(theta[j])"},
};

static void planar_models(void)
{
    static const rewrite dp[] = {
        {"vx1 = l1*cos(th1)*th1_dot", "vx1 = der(x1)"},
        {"vy1 = l1*sin(th1)*th1_dot", "vy1 = der(y1)"},
        {"vx2 = vx1 + l2*cos(th2)*th2_dot", "vx2 = der(x2)"},
        {"vy2 = vy1 + l2*sin(th2)*th2_dot", "vy2 = der(y2)"},
    };
    static const rewrite fb[] = {
        {"vx = -l1*sin(th1)*th1_dot", "vx = der(px)"},
        {"vy = l1*cos(th1)*th1_dot", "vy = der(py)"},
        {"cvx = vx - l2/2*sin(th2)*th2_dot", "cvx = der(cx)"},
        {"cvy = vy + l2/2*cos(th2)*th2_dot", "cvy = der(cy)"},
    };
    static const rewrite cp[] = {
        {"T = 1/2*M*x_dot^2 +\n"
         "    1/2*m*((x_dot + l*cos(theta)*theta_dot)^2 + "
         "(l*sin(theta)*theta_dot)^2)",
         "T = 1/2*M*der(x)^2 +\n"
         "    1/2*m*(der(x + l*sin(theta))^2 + der(l*cos(theta))^2)"},
    };
    static const rewrite sp[] = {
        {"T = 1/2*m*(r_dot^2 + r^2*theta_dot^2)",
         "T = 1/2*m*(der(r*sin(theta))^2 + der(r*cos(theta))^2)"},
    };
    static const rewrite dc[] = {
        {"avx = -r*sin(th)*th_dot", "avx = der(r*cos(th))"},
        {"avy = r*cos(th)*th_dot", "avy = der(r*sin(th))"},
        {"cvx = avx - l/2*sin(ph)*ph_dot",
         "cvx = der(r*cos(th) + l/2*cos(ph))"},
        {"cvy = avy + l/2*cos(ph)*ph_dot",
         "cvy = der(r*sin(th) + l/2*sin(ph))"},
        {"bvx = x_dot + lp*cos(psi)*psi_dot", "bvx = der(x + lp*sin(psi))"},
        {"bvy = lp*sin(psi)*psi_dot", "bvy = der(-lp*cos(psi))"},
    };
    planar("double-pendulum.eom", dp, 4);
    planar("four-bar.eom", fb, 4);
    planar("cart-pole.eom", cp, 1);
    planar("spring-pendulum.eom", sp, 1);
    planar("driven-crank.eom", dc, 6);
    planar("open-chain.eom", chain_rw, 2);
    planar("closed-chain.eom", chain_rw, 2);
}

/* The tape of a chain written with der() stays linear in the links. */
static void chain_ops(void)
{
    char *hand = read_text("closed-chain.eom"), *der = dup_text(hand);
    eom_system *a, *b;
    size_t na, nb;
    der = replace(der, chain_rw[0].from, chain_rw[0].to);
    der = replace(der, chain_rw[1].from, chain_rw[1].to);
    na = nb = 0;
    a = build(hand, "closed-chain.eom", 40, &na);
    b = build(der, "closed-chain.eom (der)", 40, &nb);
    printf("closed chain, 40 links: L tape %zu ops with hand-written "
           "velocities, %zu with der() (ratio %.3f)\n", na, nb,
           (double)nb / (double)na);
    CHECK(na > 0 && (double)nb <= 1.3 * (double)na);
    same_rhs(a, b, "closed chain, 40 links", 1e-12);
    eom_system_free(&a);
    eom_system_free(&b);
    free(hand);
    free(der);
}

/* ---- the heavy top ----------------------------------------------------- */

static const char *const top_textbook =
    "param m  = 1    [kg]\n"
    "param l  = 0.1  [m]\n"
    "param A  = 0.02 [kg m^2]\n"
    "param C  = 0.01 [kg m^2]\n"
    "param g  = 9.81 [m/s^2]\n"
    "coord psi   = 0   [rad] rate 0.49156025789759916\n"
    "coord theta = 0.5 [rad]\n"
    "coord phi   = 0   [rad] rate 200\n"
    "T = 1/2*A*(theta_dot^2 + psi_dot^2*sin(theta)^2) +\n"
    "    1/2*C*(phi_dot + psi_dot*cos(theta))^2\n"
    "V = m*g*l*cos(theta)\n";

static const double TA = 0.02, TC = 0.01, TM = 1.0, TL = 0.1, TG = 9.81;

/* energy, p_psi, p_phi of the textbook Lagrangian at x */
static void top_invariants(const double *x, double *E, double *ppsi,
                           double *pphi)
{
    double th = x[1], psd = x[3], thd = x[4], phd = x[5];
    double w3 = phd + psd * cos(th);
    *E = 0.5 * TA * (thd * thd + psd * psd * sin(th) * sin(th)) +
         0.5 * TC * w3 * w3 + TM * TG * TL * cos(th);
    *ppsi = TA * psd * sin(th) * sin(th) + TC * w3 * cos(th);
    *pphi = TC * w3;
}

static void run(eom_system *s, double *x, double t_end, double dt,
                void (*each)(const double *x, void *u), void *u)
{
    eom_integ *it = NULL;
    eom_opts o;
    double t, W;
    eom_opts_default(&o);
    o.method = EOM_ERK;
    o.rtol = 1e-13;
    o.atol = 1e-13;
    if (eom_integ_new(&it, s, &o, 0.0, x) != EOM_OK) {
        CHECK_FAIL_("eom_integ_new failed");
        return;
    }
    for (t = dt; t <= t_end + 1e-9; t += dt) {
        if (eom_integ_advance(it, t, x, &W) != EOM_OK) {
            CHECK_FAIL_("integration: %s", eom_integ_errmsg(it));
            break;
        }
        if (each)
            each(x, u);
    }
    eom_integ_free(&it);
}

typedef struct drift {
    double E0, p0, q0, dE, dp, dq;
} drift;

static void track(const double *x, void *u)
{
    drift *d = u;
    double E, p, q;
    top_invariants(x, &E, &p, &q);
    d->dE = fmax(d->dE, fabs(E - d->E0) / fabs(d->E0));
    d->dp = fmax(d->dp, fabs(p - d->p0) / fabs(d->p0));
    d->dq = fmax(d->dq, fabs(q - d->q0) / fabs(d->q0));
}

typedef struct steady {
    double th0, psd0, dth, dpsd;
} steady;

static void track_steady(const double *x, void *u)
{
    steady *st = u;
    st->dth = fmax(st->dth, fabs(x[1] - st->th0));
    st->dpsd = fmax(st->dpsd, fabs(x[3] - st->psd0) / st->psd0);
}

static void heavy_top(void)
{
    char *text = read_text("heavy-top.eom");
    eom_system *a = build(text, "heavy-top.eom", 0, NULL);
    eom_system *b = build(top_textbook, "textbook top", 0, NULL);
    double xa[6], xb[6], diff = 0.0, a2, b2, c2, root;
    drift d;
    steady st;
    int k;
    free(text);
    if (!a || !b) {
        eom_system_free(&a);
        eom_system_free(&b);
        return;
    }
    same_rhs(a, b, "heavy top (rotation matrix against Euler-angle "
                   "textbook)", 1e-12);

    /* the shipped start is steady precession: the slow root of
     * (A - C) cos(th) psid^2 - C phid psid + m g l = 0 */
    CHECK_INT(eom_initial_state(a, xa), EOM_OK);
    a2 = (TA - TC) * cos(xa[1]);
    b2 = -TC * xa[5];
    c2 = TM * TG * TL;
    root = 2.0 * c2 / (-b2 + sqrt(b2 * b2 - 4.0 * a2 * c2));
    CHECK_NEAR(xa[3], root, 1e-14);
    {
        /* steady: no acceleration at the start, to the rounding of the
         * terms that balance (m g l / A = 49 rad/s^2) */
        double xd[6];
        CHECK_INT(eom_rhs(a, 0.0, xa, xd), EOM_OK);
        printf("heavy top at the closed-form precession rate: "
               "accelerations %.2g %.2g %.2g rad/s^2\n", xd[3], xd[4],
               xd[5]);
        for (k = 3; k < 6; k++)
            CHECK(fabs(xd[k]) <= 1e-12 * TM * TG * TL / TA);
    }
    st.th0 = xa[1];
    st.psd0 = xa[3];
    st.dth = st.dpsd = 0.0;
    run(a, xa, 10.0, 0.5, track_steady, &st);
    printf("heavy top, steady precession over 10 s: theta moved %.2g rad, "
           "psi_dot by %.2g relative\n", st.dth, st.dpsd);
    CHECK(st.dth <= 1e-12);
    CHECK(st.dpsd <= 1e-10);

    /* a nutating top: both models over 2 s, then 100 s of invariants */
    CHECK_INT(eom_initial_state(a, xa), EOM_OK);
    xa[3] = 0.0; /* released without precession: it nutates */
    xa[5] = 50.0;
    memcpy(xb, xa, sizeof xb);
    run(a, xa, 2.0, 2.0, NULL, NULL);
    run(b, xb, 2.0, 2.0, NULL, NULL);
    for (k = 0; k < 6; k++)
        diff = fmax(diff, fabs(xa[k] - xb[k]) / fmax(1.0, fabs(xb[k])));
    printf("heavy top, nutating, 2 s: rotation-matrix model against the "
           "textbook one %.2g\n", diff);
    CHECK(diff <= 1e-11);

    CHECK_INT(eom_initial_state(a, xa), EOM_OK);
    xa[3] = 0.0;
    xa[5] = 50.0;
    top_invariants(xa, &d.E0, &d.p0, &d.q0);
    d.dE = d.dp = d.dq = 0.0;
    run(a, xa, 100.0, 0.25, track, &d);
    printf("heavy top, 100 s: relative drift of E %.2g, p_psi %.2g, p_phi "
           "%.2g\n", d.dE, d.dp, d.dq);
    CHECK(d.dE <= 1e-10);
    CHECK(d.dp <= 1e-10);
    CHECK(d.dq <= 1e-10);
    eom_system_free(&a);
    eom_system_free(&b);
}

/* Steady rolling on a circle, by hand (Newton and Euler): a thin disk
 * (radius a, I1 = m a^2/4 about a diameter, I3 = m a^2/2 about the axle)
 * leaning by th toward the centre of the circle its contact point runs
 * on (radius rho), its centre on radius Rc = rho - a sin th, the heading
 * turning at W. With e_r outward, the axle n = cos th e_r + sin th e_z,
 * u = -sin th e_r + cos th e_z from the contact to the centre, and the
 * spin s about n: rolling (v_C + w x (P - C) = 0) gives s = -W rho / a;
 * the angular momentum about the centre H = I3 (W sin th + s) n +
 * I1 W cos th u turns with the frame, dH/dt = W e_z x H, and equals the
 * contact force's torque about the centre, with the force
 * F = m g e_z - m W^2 Rc e_r from the centre's circular motion:
 *     W^2 cos th (m a Rc + I3 Rc / a + I1 sin th) = m a g sin th,
 *     W^2 = g tan th / (1.5 Rc + 0.25 a sin th).
 * In the model's coordinates (moving along +x, leaning to the right, so
 * turning right about the centre at y = -rho): x_dot = W rho, psi_dot =
 * -W, phi_dot = W rho / a, and the contact point's acceleration is
 * W^2 rho toward the centre, every other one 0. */
static void disk_circle(eom_system *s)
{
    const double a = 0.3, g = 9.81, th = 0.3, rho = 2.0;
    const double Rc = rho - a * sin(th);
    const double W = sqrt(g * tan(th) / (1.5 * Rc + 0.25 * a * sin(th)));
    double x[10], xd[10], worst = 0.0, off = 0.0;
    int k;
    memset(x, 0, sizeof x);
    x[3] = th;
    x[5] = W * rho;
    x[7] = -W;
    x[9] = W * rho / a;
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
    for (k = 5; k < 10; k++)
        worst = fmax(worst, fabs(xd[k] - (k == 6 ? -W * W * rho : 0.0)));
    run(s, x, 2.0, 2.0, NULL, NULL);
    /* on the circle about (0, -rho), still leaning by th */
    off = fmax(fabs(hypot(x[0], x[1] + rho) - rho), fabs(x[3] - th));
    printf("rolling disk on a circle (lean 0.3 rad, radius 2 m, W = %.12g "
           "rad/s by hand): accelerations off the closed form by %.2g, "
           "after 2 s off the circle by %.2g\n", W, worst, off);
    CHECK(worst <= 1e-12);
    CHECK(off <= 1e-10);
}

/* ---- the rolling disk --------------------------------------------------- */

typedef struct disk_track {
    eom_system *s;
    double E0, dE, res, lean, y;
} disk_track;

static void track_disk(const double *x, void *u)
{
    disk_track *d = u;
    eom_energy e;
    double phi[2], phid[2];
    int k;
    if (eom_energy_at(d->s, 0.0, x, &e) == EOM_OK)
        d->dE = fmax(d->dE, fabs(e.E - d->E0) / fabs(d->E0));
    if (eom_residuals(d->s, x, phi, phid) == EOM_OK)
        for (k = 0; k < 2; k++)
            d->res = fmax(d->res, fabs(phid[k]));
    d->lean = fmax(d->lean, fabs(x[3]));
    d->y = fmax(d->y, fabs(x[1]) + fabs(x[2]));
}

static void rolling_disk(void)
{
    char *text = read_text("rolling-disk.eom");
    eom_system *s = build(text, "rolling-disk.eom", 0, NULL);
    double x[10], x0;
    disk_track d;
    eom_energy e;
    free(text);
    if (!s)
        return;
    CHECK_INT(eom_system_nconstraints(s), 2);
    /* upright, rolling at 1.5 m/s: straight on, and upright */
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    x[3] = 0.0;
    x0 = x[0];
    memset(&d, 0, sizeof d);
    d.s = s;
    CHECK_INT(eom_energy_at(s, 0.0, x, &e), EOM_OK);
    d.E0 = e.E;
    run(s, x, 4.0, 0.25, track_disk, &d);
    printf("rolling disk upright, 4 s: x %.15g (r phi_dot t = %.15g), "
           "lean %.2g, |y| + |psi| %.2g, |C qd| %.2g\n", x[0], 1.5 * 4.0,
           d.lean, d.y, d.res);
    CHECK_NEAR(x[0] - x0, 0.3 * 5.0 * 4.0, 1e-10);
    CHECK(d.lean <= 1e-12 && d.y <= 1e-12);
    CHECK(d.res <= 1e-12);
    /* leaning: it steers; rolling does no work: E stays */
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    memset(&d, 0, sizeof d);
    d.s = s;
    CHECK_INT(eom_energy_at(s, 0.0, x, &e), EOM_OK);
    d.E0 = e.E;
    run(s, x, 10.0, 0.25, track_disk, &d);
    printf("rolling disk leaning, 10 s: relative drift of E %.2g, "
           "|C qd| %.2g, heading %.3g rad\n", d.dE, d.res, x[2]);
    CHECK(d.dE <= 1e-10);
    CHECK(d.res <= 1e-12);
    CHECK(fabs(x[2]) > 0.5); /* it turned */
    disk_circle(s);
    eom_system_free(&s);
}

/* ---- the spherical double pendulum ------------------------------------ */

static const char *const planar_rods =
    "param m = 1    [kg]\n"
    "param l = 1    [m]\n"
    "param r = 0.05 [m]\n"
    "param g = 9.81 [m/s^2]\n"
    "coord b1 = 0.6 [rad]\n"
    "coord b2 = 0.2 [rad]\n"
    "vx1 = -l/2*cos(b1)*b1_dot\n"
    "vz1 = l/2*sin(b1)*b1_dot\n"
    "vx2 = -l*cos(b1)*b1_dot - l/2*cos(b2)*b2_dot\n"
    "vz2 = l*sin(b1)*b1_dot + l/2*sin(b2)*b2_dot\n"
    "Iyy = m*(3*r^2 + l^2)/12\n"
    "T = 1/2*m*(vx1^2 + vz1^2 + vx2^2 + vz2^2) + "
    "1/2*Iyy*(b1_dot^2 + b2_dot^2)\n"
    "V = m*g*(-l/2*cos(b1) - l*cos(b1) - l/2*cos(b2))\n";

typedef struct sdp_track {
    eom_system *s;
    double H0, E0, dH, dE;
} sdp_track;

static void track_sdp(const double *x, void *u)
{
    sdp_track *d = u;
    double p[8];
    eom_energy e;
    if (eom_probes_at(d->s, x, p) == EOM_OK)
        d->dH = fmax(d->dH, fabs(p[0] - d->H0) / fabs(d->H0));
    if (eom_energy_at(d->s, 0.0, x, &e) == EOM_OK)
        d->dE = fmax(d->dE, fabs(e.E - d->E0) / fabs(d->E0));
}

static void spherical_pendulum(void)
{
    char *text = read_text("spherical-double-pendulum.eom");
    eom_system *s = build(text, "spherical-double-pendulum.eom", 0, NULL);
    eom_system *pl = build(planar_rods, "planar rods", 0, NULL);
    double x[12], xd[12], y[4], yd[4], p[8], worst = 0.0;
    sdp_track d;
    eom_energy e;
    rng r = rng_seed(99u);
    int k, j;
    free(text);
    if (!s || !pl) {
        eom_system_free(&s);
        eom_system_free(&pl);
        return;
    }
    /* in the x-z plane: a = c = 0 and no rate of them */
    for (k = 0; k < 20; k++) {
        memset(x, 0, sizeof x);
        x[1] = rng_range(&r, -1.2, 1.2);
        x[4] = rng_range(&r, -1.2, 1.2);
        x[7] = rng_range(&r, -2.0, 2.0);
        x[10] = rng_range(&r, -2.0, 2.0);
        y[0] = x[1];
        y[1] = x[4];
        y[2] = x[7];
        y[3] = x[10];
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        CHECK_INT(eom_rhs(pl, 0.0, y, yd), EOM_OK);
        worst = fmax(worst, fabs(xd[7] - yd[2]) / fmax(1.0, fabs(yd[2])));
        worst = fmax(worst, fabs(xd[10] - yd[3]) / fmax(1.0, fabs(yd[3])));
        for (j = 0; j < 6; j++)
            if (j != 1 && j != 4)
                worst = fmax(worst, fabs(xd[6 + j]));
    }
    printf("spherical double pendulum in a plane against the planar one: "
           "%.2g\n", worst);
    CHECK(worst <= 1e-12);
    /* in space: H_z and E */
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    CHECK_INT(eom_probes_at(s, x, p), EOM_OK);
    CHECK_INT(eom_energy_at(s, 0.0, x, &e), EOM_OK);
    memset(&d, 0, sizeof d);
    d.s = s;
    d.H0 = p[0];
    d.E0 = e.E;
    run(s, x, 10.0, 0.1, track_sdp, &d);
    printf("spherical double pendulum, 10 s: relative drift of H_z %.2g, "
           "of E %.2g\n", d.dH, d.dE);
    CHECK(d.dH <= 1e-10);
    CHECK(d.dE <= 1e-10);
    eom_system_free(&s);
    eom_system_free(&pl);
}

/* ---- vector algebra through probes ------------------------------------- */

static const char *const algebra =
    "units off\n"
    "coord a = 0.7\n"
    "coord b = -0.4\n"
    "coord c = 1.3\n"
    "u = vec(a, b, c)\n"
    "v = vec(c*b, 2, -a)\n"
    "Rx = rotx(a)\n"
    "Rot = rotz(a)*roty(b)*rotx(c)\n"
    "T = 1/2*(a_dot^2 + b_dot^2 + c_dot^2)\n"
    "probe cr = cross(u, v)\n"
    "probe dt = dot(u, v)\n"
    "probe nm = norm(u)\n"
    "probe axis = rot(vec(0, 0, 2), a) - rotz(a)\n"
    "probe q = quat(cos(a/2), sin(a/2), 0, 0) - Rx\n"
    "probe qn = quat(cos(b/2), 0, sin(b/2), 0) - roty(b)\n"
    "probe orth = transpose(Rot)*Rot - diag(1, 1, 1)\n"
    "probe rows = mat(vec(1, 2, 3), u, v) - mat(1, 2, 3, a, b, c, c*b, 2, -a)\n"
    "probe wb = angvel_body(Rot)\n"
    "probe ws = angvel_space(Rot) - Rot*angvel_body(Rot)\n"
    "probe wz = angvel_body(rotz(a)*rotx(c)) - vec(0, sin(c)*a_dot, "
    "cos(c)*a_dot) - vec(c_dot, 0, 0)\n"
    "probe vel = der(Rot*u)\n"
    "probe cmp = Rot.xy + u.z\n";

static void vector_algebra(void)
{
    eom_system *s = build(algebra, "algebra", 0, NULL);
    double x[6] = {0.7, -0.4, 1.3, 0.3, -1.1, 0.6}, p[64];
    double a = x[0], b = x[1], c = x[2];
    double u[3] = {a, b, c}, v[3] = {c * b, 2, -a};
    double ca = cos(a), sa = sin(a), cb = cos(b), sb = sin(b), cc = cos(c),
           sc = sin(c);
    /* Rot = Rz(a) Ry(b) Rx(c) */
    double R[9] = {ca * cb, ca * sb * sc - sa * cc, ca * sb * cc + sa * sc,
                   sa * cb, sa * sb * sc + ca * cc, sa * sb * cc - ca * sc,
                   -sb,     cb * sc,                cb * cc};
    int np, k, at;
    if (!s)
        return;
    np = eom_system_nprobes(s);
    CHECK_INT(np, 3 + 1 + 1 + 9 + 9 + 9 + 9 + 9 + 3 + 3 + 3 + 3 + 1);
    CHECK_INT(eom_probes_at(s, x, p), EOM_OK);
    CHECK_NEAR(p[0], u[1] * v[2] - u[2] * v[1], 1e-15);
    CHECK_NEAR(p[1], u[2] * v[0] - u[0] * v[2], 1e-15);
    CHECK_NEAR(p[2], u[0] * v[1] - u[1] * v[0], 1e-15);
    CHECK_NEAR(p[3], u[0] * v[0] + u[1] * v[1] + u[2] * v[2], 1e-15);
    CHECK_NEAR(p[4], sqrt(a * a + b * b + c * c), 1e-15);
    for (at = 5, k = 0; k < 45; k++) /* axis, q, qn, orth, rows */
        CHECK_NEAR(p[at + k], 0.0, 2e-15);
    at = 50;
    {
        /* body angular velocity of Rz(a) Ry(b) Rx(c), by hand: the rates
         * about the body axes of the three rotations */
        double ad = x[3], bd = x[4], cd = x[5];
        double w[3] = {cd - ad * sb, bd * cc + ad * cb * sc,
                       -bd * sc + ad * cb * cc};
        for (k = 0; k < 3; k++)
            CHECK_NEAR(p[at + k], w[k], 1e-15);
        for (k = 0; k < 3; k++) /* ws, wz */
            CHECK_NEAR(p[at + 3 + k], 0.0, 1e-15);
        for (k = 0; k < 3; k++)
            CHECK_NEAR(p[at + 6 + k], 0.0, 1e-15);
        /* der(Rot u) = dRot/dt u + Rot du/dt, by finite differences of
         * Rot u along the rates */
        {
            double h = 1e-6, xp[3], xm[3], Rp[9], Rm[9];
            for (k = 0; k < 3; k++) {
                xp[k] = x[k] + h * x[3 + k];
                xm[k] = x[k] - h * x[3 + k];
            }
            {
                double A = xp[0], B = xp[1], Cc = xp[2];
                double Rt[9] = {cos(A) * cos(B),
                                cos(A) * sin(B) * sin(Cc) - sin(A) * cos(Cc),
                                cos(A) * sin(B) * cos(Cc) + sin(A) * sin(Cc),
                                sin(A) * cos(B),
                                sin(A) * sin(B) * sin(Cc) + cos(A) * cos(Cc),
                                sin(A) * sin(B) * cos(Cc) - cos(A) * sin(Cc),
                                -sin(B), cos(B) * sin(Cc), cos(B) * cos(Cc)};
                memcpy(Rp, Rt, sizeof Rp);
                A = xm[0];
                B = xm[1];
                Cc = xm[2];
                {
                    double Ru[9] = {
                        cos(A) * cos(B),
                        cos(A) * sin(B) * sin(Cc) - sin(A) * cos(Cc),
                        cos(A) * sin(B) * cos(Cc) + sin(A) * sin(Cc),
                        sin(A) * cos(B),
                        sin(A) * sin(B) * sin(Cc) + cos(A) * cos(Cc),
                        sin(A) * sin(B) * cos(Cc) - cos(A) * sin(Cc),
                        -sin(B), cos(B) * sin(Cc), cos(B) * cos(Cc)};
                    memcpy(Rm, Ru, sizeof Rm);
                }
            }
            for (k = 0; k < 3; k++) {
                double fp = Rp[3 * k] * xp[0] + Rp[3 * k + 1] * xp[1] +
                            Rp[3 * k + 2] * xp[2];
                double fm = Rm[3 * k] * xm[0] + Rm[3 * k + 1] * xm[1] +
                            Rm[3 * k + 2] * xm[2];
                CHECK_NEAR(p[at + 9 + k], (fp - fm) / (2 * h), 1e-8);
            }
        }
        CHECK_NEAR(p[at + 12], R[1] + u[2], 1e-15);
    }
    eom_system_free(&s);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        models_dir = argv[1];
    planar_models();
    chain_ops();
    heavy_top();
    rolling_disk();
    spherical_pendulum();
    vector_algebra();
    CHECK_DONE();
}
