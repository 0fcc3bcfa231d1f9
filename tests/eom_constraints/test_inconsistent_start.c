/* test_inconsistent_start.c - a start off the constraints given to
 * eom_integ_new through the C API (no eom_run_prepare_start before it):
 * every method must do the same with it. With projection on (the
 * default) each one starts from the start projected by the least change
 * of the coordinates (eom_project_start) and integrates the same motion:
 * the final states and E + W agree across methods to their tolerances,
 * and match a run started from the projected state by hand. With
 * projection off every method integrates from the start as given, and
 * again they agree.
 *
 * The model: a point mass on a rod of length L in Cartesian coordinates
 * (x, y), constraint x^2 + y^2 - len^2 = 0, started at radius 1.13 L with
 * a velocity that is not tangent. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"
#include "eom/model_file.h"

static const char pendulum[] =
    "param m = 1    [kg]\n"
    "param g = 9.81 [m/s^2]\n"
    "param len = 1  [m]\n"
    "coord x = 0.8  [m] rate 0.5\n"
    "coord y = -0.8 [m] rate 0.4\n"
    "T = 1/2*m*(x_dot^2 + y_dot^2)\n"
    "V = m*g*y\n"
    "constraint rod = x^2 + y^2 - len^2\n";

static const eom_method methods[] = {EOM_RK4, EOM_ERK, EOM_ADAMS, EOM_BDF,
                                     EOM_IDA, EOM_ESDIRK, EOM_IMEX};
enum { NM = sizeof methods / sizeof methods[0] };

/* Integrate from x0 with method to t = 1: the final state in x and
 * E + W there in *ew; the status of eom_integ_new. */
static int run_to_1(eom_system *s, eom_method method, int project,
                    const double *x0, double *x, double *ew)
{
    eom_opts o;
    eom_integ *it = NULL;
    eom_energy e;
    double W = 0.0;
    int rc;
    eom_opts_default(&o);
    o.method = method;
    o.dt = 1e-4;
    o.rtol = 1e-10;
    o.atol = 1e-12;
    o.project = project;
    memcpy(x, x0, 4 * sizeof(double));
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    if (rc != EOM_OK)
        return rc;
    CHECK_INT(eom_integ_advance(it, 1.0, x, &W), EOM_OK);
    CHECK_INT(eom_energy_at(s, 1.0, x, &e), EOM_OK);
    *ew = e.E + W;
    eom_integ_free(&it);
    return rc;
}

int main(void)
{
    char err[1024];
    eom_model *m = NULL;
    eom_system *s = NULL;
    double x0[4], xp[4], x[4], ref[4], ew, ew_ref, phi;
    eom_energy e;
    int k, i;
    CHECK_INT(eom_model_from_string(&m, pendulum, err, sizeof err), EOM_OK);
    CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
    eom_model_free(&m);
    if (!s)
        CHECK_DONE();
    CHECK_INT(eom_initial_state(s, x0), EOM_OK);
    /* the start, projected by hand as eom-run does */
    memcpy(xp, x0, sizeof xp);
    CHECK_INT(eom_project_start(s, xp, 1e-12, NULL), EOM_OK);
    CHECK_INT(eom_energy_at(s, 0.0, xp, &e), EOM_OK);
    /* the reference: rk4 from the projected start */
    CHECK_INT(run_to_1(s, EOM_RK4, 1, xp, ref, &ew_ref), EOM_OK);
    CHECK(fabs(ew_ref - e.E) < 1e-8); /* no dissipation: E + W = E0 */
    for (k = 0; k < NM; k++) {
        const char *name = eom_method_name(methods[k]);
        double d = 0.0;
        int rc = run_to_1(s, methods[k], 1, x0, x, &ew);
        check_count_++;
        if (rc != EOM_OK) {
            CHECK_FAIL_("%s: eom_integ_new %s: %s", name,
                        eom_status_name(rc), eom_system_errmsg(s));
            continue;
        }
        for (i = 0; i < 4; i++)
            d = fmax(d, fabs(x[i] - ref[i]));
        check_count_++;
        if (!(d < 1e-6 && fabs(ew - ew_ref) < 1e-6))
            CHECK_FAIL_("%s: from the inconsistent start: state off by "
                        "%.3g, E + W = %.10g against %.10g", name, d, ew,
                        ew_ref);
        phi = x[0] * x[0] + x[1] * x[1] - 1.0;
        CHECK(fabs(phi) < 1e-8);
    }
    /* projection off: every method integrates from the start as given
     * (the acceleration-level equations keep phi's drift; Baumgarte
     * terms may pull it back), the same motion */
    CHECK_INT(run_to_1(s, EOM_RK4, 0, x0, ref, &ew_ref), EOM_OK);
    CHECK(fabs(ref[0] * ref[0] + ref[1] * ref[1] - 1.0) > 0.1);
    for (k = 0; k < NM; k++) {
        const char *name = eom_method_name(methods[k]);
        double d = 0.0;
        int rc = run_to_1(s, methods[k], 0, x0, x, &ew);
        check_count_++;
        if (rc != EOM_OK) {
            CHECK_FAIL_("%s, projection off: %s: %s", name,
                        eom_status_name(rc), eom_system_errmsg(s));
            continue;
        }
        for (i = 0; i < 4; i++)
            d = fmax(d, fabs(x[i] - ref[i]));
        check_count_++;
        if (!(d < 1e-6 && fabs(ew - ew_ref) < 1e-6))
            CHECK_FAIL_("%s, projection off: state off by %.3g, E + W = "
                        "%.10g against %.10g", name, d, ew, ew_ref);
    }
    eom_system_free(&s);
    CHECK_DONE();
}
