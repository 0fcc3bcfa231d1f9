/* test_atol_vec.c - per-component absolute tolerances (eom_opts.atol_vec)
 * on a model with constraints, where bdf weighs the error with its own
 * function (integrate_cvode.c's cv_ewt: its per-step floor moves during
 * the run) and ida with its own vector (q, v, then lambda and W); the
 * unconstrained paths are checked in test_order.c.
 *
 * Two equal oscillators held together, x = y (T = (xd^2 + yd^2) / 2,
 * V = w^2 (x^2 + y^2) / 2, phi = x - y): both move as x = A cos(w t),
 * A = 1e4, so with rtol = 1e-12 the absolute tolerances govern the
 * error. For every adaptive method:
 *   - atol_vec equal to atol everywhere gives the scalar run bit for bit;
 *   - loose entries (1e-1) give a looser run than tight ones (1e-5);
 *   - a loose entry for the rates alone, with the coordinates' entries
 *     and the scalar atol tight, still gives a looser run: the rates get
 *     their own entries, not the scalar atol.
 * Errors against the closed form at t = 1, 2, .., 10. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"

static const double A = 1e4, W = 6.283185307179586;

static int kinetic(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    (void)user;
    *out = tp_mulc(r, tp_add(r, tp_sqr(r, eom_qd(c, 0)),
                             tp_sqr(r, eom_qd(c, 1))), 0.5);
    return 0;
}

static int potential(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    (void)user;
    *out = tp_mulc(r, tp_add(r, tp_sqr(r, eom_q(c, 0)),
                             tp_sqr(r, eom_q(c, 1))), 0.5 * W * W);
    return 0;
}

static int tie(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    out[0] = tp_sub(eom_rec(c), eom_q(c, 0), eom_q(c, 1));
    return 0;
}

/* max over t = 1..10 of |x - A cos(w t)| and |y - A cos(w t)| by method
 * m; the final state in xf (may be NULL) */
static double run(eom_system *s, eom_method m, double atol, const double *av,
                  double *xf)
{
    eom_integ *it = NULL;
    eom_opts o;
    double x[4] = {A, A, 0.0, 0.0}, err = 0.0;
    int k, rc;
    eom_opts_default(&o);
    o.method = m;
    o.dt = 0.0;
    o.rtol = 1e-12;
    o.atol = atol;
    o.atol_vec = av;
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    for (k = 1; k <= 10 && rc == EOM_OK; k++) {
        const double want = A * cos(W * k);
        rc = eom_integ_advance(it, (double)k, x, NULL);
        err = fmax(err, fmax(fabs(x[0] - want), fabs(x[1] - want)));
    }
    if (rc != EOM_OK)
        fprintf(stderr, "%s: %s\n", eom_method_name(m),
                it ? eom_integ_errmsg(it) : eom_system_errmsg(s));
    CHECK_INT(rc, EOM_OK);
    if (xf)
        memcpy(xf, x, sizeof x);
    eom_integ_free(&it);
    return err;
}

int main(void)
{
    static const eom_method methods[] = {EOM_ERK, EOM_ADAMS, EOM_BDF,
                                         EOM_IDA, EOM_ESDIRK};
    static const double same[4] = {1e-3, 1e-3, 1e-3, 1e-3};
    static const double loose[4] = {1e-1, 1e-1, 1e-1, 1e-1};
    static const double tight[4] = {1e-5, 1e-5, 1e-5, 1e-5};
    static const double rate_loose[4] = {1e-5, 1e-5, 1e-1, 1e-1};
    eom_model *md = NULL;
    eom_system *s = NULL;
    char msg[256];
    size_t i;
    CHECK_INT(eom_model_new(&md), EOM_OK);
    CHECK_INT(eom_model_add_coord(md, "x", "m", A, 0.0), 0); /* its index */
    CHECK_INT(eom_model_add_coord(md, "y", "m", A, 0.0), 1);
    CHECK_INT(eom_model_set_kinetic(md, kinetic, NULL), EOM_OK);
    CHECK_INT(eom_model_set_potential(md, potential, NULL), EOM_OK);
    CHECK_INT(eom_model_set_constraints(md, 1, tie, NULL), EOM_OK);
    CHECK_INT(eom_system_new(&s, md, msg, sizeof msg), EOM_OK);
    eom_model_free(&md);
    if (!s) {
        fprintf(stderr, "%s\n", msg);
        CHECK_DONE();
    }
    for (i = 0; i < sizeof methods / sizeof methods[0]; i++) {
        const char *name = eom_method_name(methods[i]);
        double xs[4], xv[4], el, et, er;
        run(s, methods[i], 1e-3, NULL, xs);
        run(s, methods[i], 1e-3, same, xv);
        check_count_++;
        if (memcmp(xs, xv, sizeof xs) != 0)
            CHECK_FAIL_("%s: atol_vec equal to atol is not the scalar run",
                        name);
        el = run(s, methods[i], 1e-3, loose, NULL);
        et = run(s, methods[i], 1e-3, tight, NULL);
        er = run(s, methods[i], 1e-5, rate_loose, NULL);
        printf("%-6s: error %.3g with atol_vec 1e-1, %.3g with 1e-5, %.3g "
               "with the rates' 1e-1 alone (the scalar 1e-5)\n", name, el,
               et, er);
        check_count_++;
        if (!(el > 10.0 * et))
            CHECK_FAIL_("%s: loose entries (%.3g) not looser than tight "
                        "(%.3g)", name, el, et);
        check_count_++;
        if (!(er > 3.0 * et))
            CHECK_FAIL_("%s: the rates' own entries not used (%.3g against "
                        "%.3g)", name, er, et);
    }
    eom_system_free(&s);
    CHECK_DONE();
}
