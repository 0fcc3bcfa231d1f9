/* test_model_files.c - the shipped model files (models/) against equations
 * derived by hand: the spring pendulum (to 1e-13), the cart-pole
 * with its damper and time-dependent force, and the double pendulum, at
 * states away from the initial one; then every shipped model is read,
 * built and integrated for 2 s with E + W conserved (W with the work of
 * the driven crank's motor) and, for the constrained ones, the
 * constraints kept. Also the model in README.md. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/model_file.h"

static char models[1024];

static eom_system *load(const char *name)
{
    char path[1200], err[2048];
    eom_model *m = NULL;
    eom_system *s = NULL;
    snprintf(path, sizeof path, "%s/%s.eom", models, name);
    if (eom_model_from_file(&m, path, err, sizeof err) != EOM_OK) {
        CHECK_FAIL_("%s", err);
        return NULL;
    }
    if (eom_system_new(&s, m, err, sizeof err) != EOM_OK)
        CHECK_FAIL_("%s: %s", name, err);
    eom_model_free(&m);
    return s;
}

static double par(const eom_system *s, const char *name)
{
    int k = eom_param_index(s, name);
    CHECK(k >= 0);
    return k >= 0 ? eom_get_param(s, k) : NAN;
}

/* r'' = r th'^2 - k/m (r - r0) + g cos th, th'' = -(2 r' th' + g sin th)/r */
static void spring_pendulum(void)
{
    eom_system *s = load("spring-pendulum");
    int trial;
    if (!s)
        return;
    CHECK_INT(eom_system_ncoords(s), 2);
    eom_set_param(s, eom_param_index(s, "k"), 60.0);
    for (trial = 0; trial < 20; trial++) {
        const double m = par(s, "m"), k = par(s, "k"), r0 = par(s, "r0"),
                     g = par(s, "g");
        double x[4], xd[4], M[4], rdd, thdd;
        eom_energy e;
        x[0] = 0.8 + 0.03 * trial;
        x[1] = -1.5 + 0.17 * trial;
        x[2] = 0.3 * sin(trial);
        x[3] = -0.7 + 0.09 * trial;
        CHECK(eom_rhs(s, 0.0, x, xd) == EOM_OK);
        rdd = x[0] * x[3] * x[3] - k / m * (x[0] - r0) + g * cos(x[1]);
        thdd = -(2.0 * x[2] * x[3] + g * sin(x[1])) / x[0];
        CHECK_NEAR(xd[0], x[2], 1e-15);
        CHECK_NEAR(xd[1], x[3], 1e-15);
        CHECK_NEAR(xd[2], rdd, 1e-13);
        CHECK_NEAR(xd[3], thdd, 1e-13);
        CHECK(eom_mass_matrix(s, x, M) == EOM_OK);
        CHECK_NEAR(M[0], m, 1e-15);
        CHECK_NEAR(M[3], m * x[0] * x[0], 1e-15);
        CHECK(M[1] == 0.0 && M[2] == 0.0);
        CHECK(eom_energy_at(s, 0.0, x, &e) == EOM_OK);
        CHECK_NEAR(e.T, 0.5 * m * (x[2] * x[2] + x[0] * x[0] * x[3] * x[3]),
                   1e-14);
        CHECK_NEAR(e.V, 0.5 * k * (x[0] - r0) * (x[0] - r0) +
                            m * g * (r0 - x[0] * cos(x[1])),
                   1e-14);
    }
    eom_system_free(&s);
}

/* (M+m) x'' + m l cos th th'' - m l sin th th'^2 = F cos(w t) - b x'
 * m l cos th x'' + m l^2 th'' - m g l sin th = 0 */
static void cart_pole(void)
{
    eom_system *s = load("cart-pole");
    int trial;
    if (!s)
        return;
    for (trial = 0; trial < 10; trial++) {
        const double Mc = par(s, "M"), m = par(s, "m"), l = par(s, "l"),
                     g = par(s, "g"), b = par(s, "b"), F = par(s, "F"),
                     w = par(s, "w"), t = 0.37 * trial;
        double x[4], xd[4], a11, a12, a22, r1, r2, det;
        x[0] = 0.1 * trial;
        x[1] = -1.0 + 0.21 * trial;
        x[2] = 0.4 - 0.05 * trial;
        x[3] = 0.3 * cos(trial);
        CHECK(eom_rhs(s, t, x, xd) == EOM_OK);
        a11 = Mc + m;
        a12 = m * l * cos(x[1]);
        a22 = m * l * l;
        r1 = F * cos(w * t) - b * x[2] + m * l * sin(x[1]) * x[3] * x[3];
        r2 = m * g * l * sin(x[1]);
        det = a11 * a22 - a12 * a12;
        CHECK_NEAR(xd[2], (a22 * r1 - a12 * r2) / det, 1e-13);
        CHECK_NEAR(xd[3], (a11 * r2 - a12 * r1) / det, 1e-13);
    }
    eom_system_free(&s);
}

static void double_pendulum(void)
{
    eom_system *s = load("double-pendulum");
    int trial;
    if (!s)
        return;
    for (trial = 0; trial < 10; trial++) {
        const double m1 = par(s, "m1"), m2 = par(s, "m2"), l1 = par(s, "l1"),
                     l2 = par(s, "l2"), g = par(s, "g");
        double x[4], xd[4], d, a11, a12, a22, r1, r2, det;
        x[0] = 0.3 * trial - 1.0;
        x[1] = 2.0 - 0.4 * trial;
        x[2] = sin(1.0 + trial);
        x[3] = cos(2.0 * trial);
        CHECK(eom_rhs(s, 0.0, x, xd) == EOM_OK);
        d = x[0] - x[1];
        a11 = (m1 + m2) * l1 * l1;
        a12 = m2 * l1 * l2 * cos(d);
        a22 = m2 * l2 * l2;
        r1 = -m2 * l1 * l2 * sin(d) * x[3] * x[3] -
             (m1 + m2) * g * l1 * sin(x[0]);
        r2 = m2 * l1 * l2 * sin(d) * x[2] * x[2] - m2 * g * l2 * sin(x[1]);
        det = a11 * a22 - a12 * a12;
        CHECK_NEAR(xd[2], (a22 * r1 - a12 * r2) / det, 1e-13);
        CHECK_NEAR(xd[3], (a11 * r2 - a12 * r1) / det, 1e-13);
    }
    eom_system_free(&s);
}

/* Every shipped model: 2 s with erk at tight tolerances. */
static void run_all(void)
{
    static const char *const names[] = {"spring-pendulum", "open-chain",
                                        "closed-chain", "cart-pole",
                                        "double-pendulum", "four-bar",
                                        "driven-crank"};
    size_t i;
    for (i = 0; i < sizeof names / sizeof names[0]; i++) {
        eom_system *s = load(names[i]);
        eom_integ *it = NULL;
        eom_opts o;
        eom_energy e0, e1;
        double x[64], W = 0.0, phi[8];
        int n, m, k;
        if (!s)
            continue;
        n = eom_system_ncoords(s);
        m = eom_system_nconstraints(s);
        CHECK(2 * n <= 64 && m <= 8);
        CHECK(eom_initial_state(s, x) == EOM_OK);
        CHECK(eom_energy_at(s, 0.0, x, &e0) == EOM_OK);
        eom_opts_default(&o);
        o.method = EOM_ERK;
        o.rtol = 1e-11;
        o.atol = 1e-12;
        CHECK(eom_integ_new(&it, s, &o, 0.0, x) == EOM_OK);
        if (eom_integ_advance(it, 2.0, x, &W) != EOM_OK)
            CHECK_FAIL_("%s: %s", names[i], eom_integ_errmsg(it));
        CHECK(eom_energy_at(s, 2.0, x, &e1) == EOM_OK);
        /* the cart-pole's force does work: E + W is conserved without it */
        if (strcmp(names[i], "cart-pole") != 0)
            CHECK_NEAR((e1.E + W - e0.E) / fmax(1.0, fabs(e0.E)), 0.0, 1e-8);
        if (m > 0) {
            CHECK(eom_residuals(s, x, phi, NULL) == EOM_OK);
            for (k = 0; k < m; k++)
                CHECK(fabs(phi[k]) < 1e-10);
        }
        eom_integ_free(&it);
        eom_system_free(&s);
    }
}

/* The README's example, as a newcomer copies it: the first block after
 * the heading "## A model in a few lines". */
static void readme_example(const char *readme)
{
    FILE *f = fopen(readme, "rb");
    static char text[1 << 16];
    char err[2048], *start, *end;
    size_t n;
    eom_model *m = NULL;
    eom_system *s = NULL;
    double x[4], xd[4];
    if (!f) {
        CHECK_FAIL_("cannot open %s", readme);
        return;
    }
    n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    start = strstr(text, "## A model in a few lines");
    start = start ? strstr(start, "```\n") : NULL;
    end = start ? strstr(start + 4, "\n```") : NULL;
    if (!start || !end) {
        CHECK_FAIL_("%s: no model block after its heading", readme);
        return;
    }
    end[1] = '\0';
    CHECK(eom_model_from_string(&m, start + 4, err, sizeof err) == EOM_OK);
    CHECK(eom_system_new(&s, m, err, sizeof err) == EOM_OK);
    if (s) {
        CHECK_INT(eom_system_ncoords(s), 2);
        CHECK(eom_initial_state(s, x) == EOM_OK);
        CHECK(eom_rhs(s, 0.0, x, xd) == EOM_OK);
        CHECK_NEAR(xd[2], -75.0 * 0.1 + 9.81 * cos(0.5), 1e-14);
    }
    eom_system_free(&s);
    eom_model_free(&m);
}

int main(int argc, char **argv)
{
    snprintf(models, sizeof models, "%s", argc > 1 ? argv[1] : "models");
    spring_pendulum();
    cart_pole();
    double_pendulum();
    run_all();
    readme_example(argc > 2 ? argv[2] : "README.md");
    CHECK_DONE();
}
