/* test_sensitivity.c - forward sensitivities (eom_opts.n_sens,
 * eom_integ_sensitivities) against central differences of whole runs.
 *
 *   1. The shipped spring pendulum and double pendulum, 2 s: the
 *      sensitivities of the state with respect to every parameter and to
 *      two initial values (a coordinate and a rate), by adams, bdf and
 *      ida at rtol 1e-10, against central differences of erk runs at rtol
 *      1e-13 (step 1e-5 relative), to 1e-6 of each input's largest
 *      sensitivity.
 *   2. At t0 the sensitivities are the unit vectors of the initial values
 *      and zero for parameters.
 *   3. Refusals: erk, an input out of range, a NULL list;
 *      eom_integ_sensitivities of a run without them. (Models with
 *      constraints: test_sensitivity_constraints.c.)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"
#include "eom/model_file.h"

#define T_END 2.0

static const char *models_dir = "models";

static eom_system *load(const char *file)
{
    eom_model *md = NULL;
    eom_system *s = NULL;
    char path[1024], err[512];
    snprintf(path, sizeof path, "%s/%s", models_dir, file);
    CHECK_INT(eom_model_from_file(&md, path, err, sizeof err), EOM_OK);
    if (md)
        CHECK_INT(eom_system_new(&s, md, err, sizeof err), EOM_OK);
    eom_model_free(&md);
    return s;
}

/* The state at T_END from x0 (erk, tight). */
static int end_state(eom_system *s, const double *x0, double *x)
{
    eom_opts o;
    eom_integ *it = NULL;
    double W;
    int rc;
    eom_opts_default(&o);
    o.method = EOM_ERK;
    o.rtol = 1e-13;
    o.atol = 1e-15;
    memcpy(x, x0, 2 * (size_t)eom_system_ncoords(s) * sizeof *x);
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    if (rc == EOM_OK)
        rc = eom_integ_advance(it, T_END, x, &W);
    eom_integ_free(&it);
    return rc;
}

static void model(const char *file, int coord, int rate)
{
    eom_system *s = load(file);
    int n, np, ns, k, i, m;
    int sens[32];
    double x0[64], x[64], xp[64], xm[64], S[64 * 32], S0[64 * 32];
    double fd[64 * 32];
    static const eom_method methods[] = {EOM_ADAMS, EOM_BDF, EOM_IDA};
    if (!s)
        return;
    n = eom_system_ncoords(s);
    np = eom_system_nparams(s);
    ns = 0;
    for (k = 0; k < np; k++)
        sens[ns++] = k;
    sens[ns++] = np + coord;
    sens[ns++] = np + n + rate;
    eom_initial_state(s, x0);
    x0[n + rate] += 0.2; /* a moving start for the rate too */

    /* the reference: central differences of whole runs */
    for (k = 0; k < ns; k++) {
        double h;
        if (sens[k] < np) {
            const double p0 = eom_get_param(s, sens[k]);
            h = 1e-5 * fmax(1.0, fabs(p0));
            CHECK_INT(eom_set_param(s, sens[k], p0 + h), EOM_OK);
            CHECK_INT(end_state(s, x0, xp), EOM_OK);
            CHECK_INT(eom_set_param(s, sens[k], p0 - h), EOM_OK);
            CHECK_INT(end_state(s, x0, xm), EOM_OK);
            CHECK_INT(eom_set_param(s, sens[k], p0), EOM_OK);
        } else {
            const int j = sens[k] - np;
            double xs[64];
            h = 1e-5 * fmax(1.0, fabs(x0[j]));
            memcpy(xs, x0, sizeof xs);
            xs[j] = x0[j] + h;
            CHECK_INT(end_state(s, xs, xp), EOM_OK);
            xs[j] = x0[j] - h;
            CHECK_INT(end_state(s, xs, xm), EOM_OK);
        }
        for (i = 0; i < 2 * n; i++)
            fd[i * ns + k] = (xp[i] - xm[i]) / (2.0 * h);
    }

    for (m = 0; m < 3; m++) {
        eom_opts o;
        eom_integ *it = NULL;
        eom_stats st;
        double W, worst = 0.0;
        eom_opts_default(&o);
        o.method = methods[m];
        o.rtol = 1e-10;
        o.atol = 1e-12;
        o.n_sens = ns;
        o.sens = sens;
        memcpy(x, x0, sizeof x);
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
        if (!it)
            continue;
        /* at t0: unit vectors and zeros */
        CHECK_INT(eom_integ_sensitivities(it, S0), EOM_OK);
        for (i = 0; i < 2 * n; i++)
            for (k = 0; k < ns; k++)
                CHECK(S0[i * ns + k] ==
                      (sens[k] >= np && sens[k] - np == i ? 1.0 : 0.0));
        CHECK_INT(eom_integ_advance(it, T_END, x, &W), EOM_OK);
        CHECK_INT(eom_integ_sensitivities(it, S), EOM_OK);
        eom_integ_stats(it, &st);
        for (k = 0; k < ns; k++) {
            double scale = 0.0, err = 0.0;
            for (i = 0; i < 2 * n; i++) {
                scale = fmax(scale, fabs(fd[i * ns + k]));
                err = fmax(err, fabs(S[i * ns + k] - fd[i * ns + k]));
            }
            worst = fmax(worst, err / scale);
            if (!(err <= 1e-6 * scale))
                CHECK_FAIL_("%s %s: d(x)/d(input %d) against differences "
                            "of whole runs: %.3g (scale %.3g)", file,
                            eom_method_name(methods[m]), sens[k], err,
                            scale);
        }
        printf("%-20s %-5s %d sensitivities: worst %.1e of their scale "
               "(%ld steps)\n", file, eom_method_name(methods[m]), ns,
               worst, st.steps);
        eom_integ_free(&it);
    }
    eom_system_free(&s);
}

static void refusals(void)
{
    eom_system *s = load("spring-pendulum.eom");
    eom_system *c = load("four-bar.eom");
    eom_integ *it = NULL;
    eom_opts o;
    double x[64], S[64];
    int sens[2] = {0, 1}, bad[1] = {99};
    if (!s || !c)
        goto done;
    eom_initial_state(s, x);
    eom_opts_default(&o);
    o.method = EOM_ERK;
    o.n_sens = 2;
    o.sens = sens;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(s), "adams and bdf") != NULL);
    o.method = EOM_BDF;
    o.sens = NULL;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_NULL);
    o.sens = bad;
    o.n_sens = 1;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(s), "sens[0] = 99") != NULL);
    o.sens = sens;
    o.method = EOM_ESDIRK;
    o.n_sens = 2;
    eom_initial_state(c, x);
    CHECK_INT(eom_integ_new(&it, c, &o, 0.0, x), EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(c), "not by esdirk") != NULL);
    o.method = EOM_BDF;
    o.n_sens = 0;
    eom_initial_state(s, x);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
    CHECK_INT(eom_integ_sensitivities(it, S), EOM_ERR_ARG);
    CHECK_INT(eom_integ_sensitivities(NULL, S), EOM_ERR_NULL);
    eom_integ_free(&it);
done:
    eom_system_free(&s);
    eom_system_free(&c);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        models_dir = argv[1];
    model("spring-pendulum.eom", 1, 0);
    model("double-pendulum.eom", 0, 1);
    refusals();
    CHECK_DONE();
}
