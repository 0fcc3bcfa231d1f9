/* test_sparse_integ.c - the integrators' sparse path (kkt_integ.c): rk4,
 * erk and adams on a system whose eom_rhs takes the augmented sparse
 * solve evaluate, project and watch the assembly branch with sparse
 * factors away from singular positions, and along the dense route near
 * them.
 *
 * 1. The IFToMM A02 four-bars in natural coordinates (N = 40, the model
 *    file of tests/eom_constraints/models), 0.5 s from the model's start
 *    (before the first flat position at 0.72 s) with adams and erk on
 *    the automatic route (sparse) and on the dense route forced by
 *    eom_system_set_mass_route: every crank turns like one pendulum,
 *    th'' = -a cos th, integrated here by RK4 at 1e-5 s (the closed
 *    form's reference); both routes' tips within 1e-7 of it, and within
 *    1e-9 of each other (adams may decide a restart after an output's
 *    projection differently on the two: they then agree to about
 *    1e-10); the stats report the route taken.
 * 2. Through the first flat position (N = 10, rk4 to 0.8 s) with the
 *    sparse route forced: the path hands the neighbourhood to the dense
 *    route and comes back; the run matches the dense route's and the
 *    pendulum, passes one singular position, and switches no branch;
 *    adams hands the neighbourhood to bdf as on the dense route, with
 *    the same outcome.
 * 3. The sparse projection (eom__kkt_project) from a state moved off
 *    the constraints (q and qd) returns to them: |phi| <= tol and |C qd|
 *    to rounding, and it agrees with the dense projection (eom_project,
 *    the same M-norm) to 1e-10.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "support_num.h"
#include "eom/eom.h"
#include "eom/model_file.h"
#include "eom_internal.h"
#include "kkt_sparse.h"
#include "mass_route.h"

static const char *dir;

static eom_system *a02(int N)
{
    char path[1024], err[1024];
    eom_file *f = NULL;
    eom_model *mo = NULL;
    eom_system *s = NULL;
    snprintf(path, sizeof path, "%s/a02-natural.eom", dir);
    if (eom_file_read(&f, path, err, sizeof err) != EOM_OK ||
        eom_file_set_setting(f, "N", N, err, sizeof err) != EOM_OK ||
        eom_file_build(f, &mo, err, sizeof err) != EOM_OK ||
        eom_system_new(&s, mo, err, sizeof err) != EOM_OK)
        fprintf(stderr, "%s: %s\n", path, err);
    eom_file_free(&f);
    eom_model_free(&mo);
    return s;
}


/* The largest distance of a tip from the pendulum's (l = 1): tip i at
 * (i + cos th, sin th). */
static double tip_error(int N, const double *x, double th)
{
    double e = 0.0;
    int i;
    for (i = 0; i <= N; i++)
        e = fmax(e, hypot(x[i] - i - cos(th), x[N + 1 + i] - sin(th)));
    return e;
}

static double maxdiff(const double *a, const double *b, int n)
{
    double d = 0.0;
    int i;
    for (i = 0; i < n; i++)
        d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

/* Integrate to t_end in nout outputs along route (0: automatic) with
 * method; the state at t_end into x, the largest tip error at the
 * outputs into *err, the stats into st. */
static int run(int N, eom_method method, int route, double t_end, int nout,
               double *x, double *err, eom_stats *st)
{
    const double a = 9.81 * ((N + 1) / 2.0 + N) / ((N + 1) / 3.0 + N);
    eom_system *s = a02(N);
    eom_integ *it = NULL;
    eom_opts o;
    double th = 1.5707963267948966, w = -1.0;
    int rc = EOM_ERR_MODEL, k;
    *err = 0.0;
    memset(st, 0, sizeof *st);
    if (!s)
        return rc;
    if (route)
        CHECK_INT(eom_system_set_mass_route(s, route), EOM_OK);
    CHECK_INT(eom_initial_state(s, x), EOM_OK);
    eom_opts_default(&o);
    o.method = method;
    o.rtol = o.atol = 1e-9;
    o.dt = 1e-3;
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    for (k = 1; rc == EOM_OK && k <= nout; k++) {
        rc = eom_integ_advance(it, t_end * k / nout, x, NULL);
        num_rk4_pendulum(a, &th, &w, t_end / nout, 1e-5);
        *err = fmax(*err, tip_error(N, x, th));
    }
    if (rc != EOM_OK)
        fprintf(stderr, "%s: %s\n", eom_method_name(method),
                it ? eom_integ_errmsg(it) : eom_system_errmsg(s));
    if (it)
        eom_integ_stats(it, st);
    eom_integ_free(&it);
    eom_system_free(&s);
    return rc;
}

static void before_flat(void)
{
    /* rk4 is compared through the flat position below (its dense run
     * at N = 40 would be most of this test's time) */
    static const eom_method methods[] = {EOM_ADAMS, EOM_ERK};
    const int N = 40, n = 2 * (N + 1);
    double *xs = malloc(2 * (size_t)n * sizeof *xs);
    double *xd = malloc(2 * (size_t)n * sizeof *xd);
    double es, ed;
    eom_stats ss, sd;
    size_t k;
    if (!xs || !xd) {
        CHECK(0);
        free(xs);
        free(xd);
        return;
    }
    for (k = 0; k < sizeof methods / sizeof methods[0]; k++) {
        CHECK_INT(run(N, methods[k], 0, 0.5, 10, xs, &es, &ss), EOM_OK);
        CHECK_INT(run(N, methods[k], EOM_MASS_DENSE, 0.5, 10, xd, &ed, &sd),
                  EOM_OK);
        printf("N = %d %-5s sparse: error %.2e, %ld steps; dense: error "
               "%.2e, %ld steps; routes differ by %.2e\n", N,
               eom_method_name(methods[k]), es, ss.steps, ed, sd.steps,
               maxdiff(xs, xd, 2 * n));
        CHECK(es < 1e-7);
        CHECK(ed < 1e-7);
        CHECK(maxdiff(xs, xd, 2 * n) < 1e-9);
        CHECK_INT(ss.mass_route, EOM_MASS_SPARSE);
        CHECK_INT(sd.mass_route, EOM_MASS_DENSE);
        CHECK(ss.max_residual <= 1e-12);
        CHECK_INT((int)ss.singular_passes, 0);
    }
    free(xs);
    free(xd);
}

static void through_flat(void)
{
    const int N = 10, n = 2 * (N + 1);
    double xs[44], xd[44], es, ed;
    eom_stats ss, sd;
    int rs, rd;
    CHECK_INT(run(N, EOM_RK4, EOM_MASS_SPARSE, 0.8, 16, xs, &es, &ss),
              EOM_OK);
    CHECK_INT(run(N, EOM_RK4, EOM_MASS_DENSE, 0.8, 16, xd, &ed, &sd),
              EOM_OK);
    printf("N = %d rk4 to 0.8 s: sparse error %.2e, %ld passes, %ld "
           "switches; dense error %.2e; routes differ by %.2e\n", N, es,
           ss.singular_passes, ss.branch_switches, ed,
           maxdiff(xs, xd, 2 * n));
    CHECK(es < 1e-6);
    CHECK(maxdiff(xs, xd, 2 * n) < 1e-9);
    CHECK_INT((int)ss.singular_passes, 1);
    CHECK_INT((int)sd.singular_passes, 1);
    CHECK_INT((int)ss.branch_switches, 0);
    CHECK_INT(ss.mass_route, EOM_MASS_SPARSE);
    /* adams refuses the neighbourhood and hands it to bdf: the same on
     * both routes (whether bdf passes the flat position or stops at it
     * is the dense route's business, integrators.md): the same status
     * and handovers, the same state at the last output reached */
    rs = run(N, EOM_ADAMS, EOM_MASS_SPARSE, 0.8, 16, xs, &es, &ss);
    rd = run(N, EOM_ADAMS, EOM_MASS_DENSE, 0.8, 16, xd, &ed, &sd);
    printf("N = %d adams to 0.8 s: sparse status %d, error %.2e, %ld "
           "handovers; dense status %d, error %.2e, %ld handovers; routes "
           "differ by %.2e\n", N, rs, es, ss.singular_handovers, rd, ed,
           sd.singular_handovers, maxdiff(xs, xd, 2 * n));
    CHECK_INT(rs, rd);
    CHECK_INT((int)ss.singular_handovers, (int)sd.singular_handovers);
    CHECK(ss.singular_handovers >= 1);
    CHECK(maxdiff(xs, xd, 2 * n) < 1e-6);
    CHECK_INT(ss.mass_route, EOM_MASS_SPARSE);
}

static void projection(void)
{
    const int N = 40, n = 2 * (N + 1), m = 2 * N + 1;
    eom_system *s = a02(N);
    double *x = malloc(2 * (size_t)n * sizeof *x);
    double *y = malloc(2 * (size_t)n * sizeof *y);
    double *r = malloc((size_t)m * sizeof *r);
    double th = 0.9, w = -2.0, before = 0.0;
    int i, iters = 0, dense = 1, it2 = 0;
    if (!s || !x || !y || !r) {
        CHECK(0);
        goto done;
    }
    for (i = 0; i <= N; i++) {
        /* on the parallelogram branch, then moved off it */
        x[i] = i + cos(th) + 1e-3 * sin(3.0 * i);
        x[N + 1 + i] = sin(th) - 2e-3 * cos(5.0 * i);
        x[n + i] = -sin(th) * w + 0.01 * cos(i);
        x[n + N + 1 + i] = cos(th) * w - 0.02 * sin(2.0 * i);
    }
    memcpy(y, x, 2 * (size_t)n * sizeof *y);
    CHECK_INT(eom__kkt_applies(s), 1);
    CHECK_INT(eom__constraint_rates(s, 0.0, x, s->phi, s->phid, s->gam),
              EOM_OK);
    for (i = 0; i < m; i++)
        before = fmax(before, fabs(s->phi[i]));
    CHECK(before > 1e-4);
    CHECK_INT(eom__kkt_project(s, 0.0, x, 1e-12, &iters, &dense), EOM_OK);
    CHECK_INT(dense, 0);
    CHECK(iters >= 2);
    /* on the constraints: phi and C qd, measured afresh */
    CHECK_INT(eom__constraint_rates(s, 0.0, x, s->phi, s->phid, s->gam),
              EOM_OK);
    for (i = 0; i < m; i++) {
        CHECK(fabs(s->phi[i]) <= 1e-12);
        CHECK(fabs(s->phid[i]) <= 1e-11);
    }
    /* the dense projection in the same metric, from the same state */
    CHECK_INT(eom_system_set_mass_route(s, EOM_MASS_DENSE), EOM_OK);
    CHECK_INT(eom_project(s, y, 1e-12, &it2), EOM_OK);
    printf("projection from |phi| = %.2e: %d iterations; sparse and dense "
           "differ by %.2e\n", before, iters, maxdiff(x, y, 2 * n));
    CHECK(maxdiff(x, y, 2 * n) < 1e-10);
done:
    eom_system_free(&s);
    free(x);
    free(y);
    free(r);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_sparse_integ MODELS_DIR\n");
        return 2;
    }
    dir = argv[1];
    before_flat();
    through_flat();
    projection();
    CHECK_DONE();
}
