/* test_branch.c - the assembly-branch monitor (libeom/src/branch.c) fed
 * with motions computed here in closed form, so that the motion and its
 * branch are known exactly:
 *
 *   parallelogram, point coordinates (x1, y1, x2, y2), unit masses at
 *   both points, no gravity: cranks of length a = 1 pinned at (0, 0) and
 *   (d, 0) = (2, 0), coupler of length d. P1 = a (cos th, sin th); on
 *   the parallelogram branch P2 = P1 + (d, 0), on the anti-parallelogram
 *   branch P2 is the other intersection of the circles |P2 - (d, 0)| = a
 *   and |P2 - P1| = d. The branches meet at the flat positions th = 0
 *   and th = pi. On the parallelogram T = a^2 th'^2 and th = w t is an
 *   exact motion.
 *
 *   - th = w t from -pi/2 over two flat passes on the parallelogram: no
 *     switch (the accelerations explain the velocity's change), in fine
 *     and in coarse steps;
 *   - the parallelogram up to th = 0 and the anti-parallelogram after,
 *     with its own velocities: one switch, reported on leaving the pass;
 *   - the same at a tenth of the speed: still one (the test is relative);
 *   - a bead on a circle, two turns: C never loses rank, so nothing is
 *     evaluated and nothing reported.
 */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "integrate_internal.h"

static const double A = 1.0, D = 2.0, PI_ = 3.14159265358979323846;

static int T_points(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val sum = tp_const(R, 0.0);
    int i;
    (void)user;
    for (i = 0; i < eom_ncoords(c); i++)
        sum = tp_add(R, sum, tp_sqr(R, eom_qd(c, i)));
    *out = tp_mulc(R, sum, 0.5);
    return 0;
}

static tp_val half_sq(tp_rec *R, tp_val x, tp_val y, double r)
{
    return tp_mulc(R, tp_subc(R, tp_add(R, tp_sqr(R, x), tp_sqr(R, y)),
                              r * r), 0.5);
}

static int phi_points(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val x1 = eom_q(c, 0), y1 = eom_q(c, 1), x2 = eom_q(c, 2),
           y2 = eom_q(c, 3);
    (void)user;
    out[0] = half_sq(R, x1, y1, A);
    out[1] = half_sq(R, tp_subc(R, x2, D), y2, A);
    out[2] = half_sq(R, tp_sub(R, x2, x1), tp_sub(R, y2, y1), D);
    return 0;
}

static int phi_circle(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    out[0] = half_sq(eom_rec(c), eom_q(c, 0), eom_q(c, 1), A);
    return 0;
}

static eom_system *make(int ncoords, int m, eom_vector_fn phi)
{
    static const char *const names[] = {"x1", "y1", "x2", "y2"};
    eom_model *md = NULL;
    eom_system *s = NULL;
    char msg[256];
    int i;
    CHECK_INT(eom_model_new(&md), EOM_OK);
    for (i = 0; i < ncoords; i++)
        eom_model_add_coord(md, names[i], "m", 0.0, 0.0);
    eom_model_set_kinetic(md, T_points, NULL);
    eom_model_set_constraints(md, m, phi, NULL);
    if (eom_system_new(&s, md, msg, sizeof msg) != EOM_OK)
        CHECK_FAIL_("eom_system_new: %s", msg);
    eom_model_free(&md);
    return s;
}

/* the configuration at th on the parallelogram (anti = 0) or the
 * anti-parallelogram (anti = 1) */
static void config(double th, int anti, double *q)
{
    const double x1 = A * cos(th), y1 = A * sin(th);
    q[0] = x1;
    q[1] = y1;
    if (!anti) {
        q[2] = x1 + D;
        q[3] = y1;
    } else {
        /* circles about c0 = (D, 0), radius A, and P1, radius D */
        const double ux = x1 - D, uy = y1, dist = hypot(ux, uy);
        const double l = (A * A - D * D + dist * dist) / (2.0 * dist);
        const double h = sqrt(fmax(A * A - l * l, 0.0));
        const double px = D + l * ux / dist, py = l * uy / dist;
        const double ax = px - h * uy / dist, ay = py + h * ux / dist;
        const double bx = px + h * uy / dist, by = py - h * ux / dist;
        /* the intersection farther from the parallelogram's P2 */
        const int first = hypot(ax - x1 - D, ay - y1) >
                          hypot(bx - x1 - D, by - y1);
        q[2] = first ? ax : bx;
        q[3] = first ? ay : by;
    }
}

/* the velocity of config at th for th' = w, by central differences */
static void velocity(double th, int anti, double w, double *v)
{
    const double h = 1e-6;
    double qp[4], qm[4];
    int e;
    config(th + h, anti, qp);
    config(th - h, anti, qm);
    for (e = 0; e < 4; e++)
        v[e] = w * (qp[e] - qm[e]) / (2.0 * h);
}

/* th = w t for t = k dt, k = 0 .. K, from th0; the branch is anti_after
 * once th > 0. Returns the switches and their first time. */
static long walk(eom_system *s, double th0, double w, double dt, int K,
                 int anti_after, double *first)
{
    eom_branch *b = NULL;
    double x[8];
    long sw, evals = 0;
    int k;
    for (k = 0; k <= K; k++) {
        const double th = th0 + w * dt * k;
        const int anti = th > 0.0 && th < PI_ / 2 ? anti_after : 0;
        config(th, anti, x);
        velocity(th, anti, w, x + 4);
        if (k == 0)
            CHECK_INT(eom__branch_new(&b, s, 0.0, x), EOM_OK);
        else if (b)
            CHECK_INT(eom__branch_check(b, s, dt * k, x, &evals), EOM_OK);
    }
    sw = eom__branch_switches(b, first, NULL);
    eom__branch_free(&b);
    return sw;
}

int main(void)
{
    eom_system *s = make(4, 3, phi_points), *bead = make(2, 1, phi_circle);
    double first = 0.0, q[4];
    long sw;
    int i;
    if (!s || !bead)
        CHECK_DONE();

    /* the closed-form branches satisfy the constraints */
    for (i = 0; i < 2; i++) {
        config(0.7, i, q);
        CHECK_NEAR(hypot(q[2] - D, q[3]), A, 1e-14);
        CHECK_NEAR(hypot(q[2] - q[0], q[3] - q[1]), D, 1e-14);
    }
    config(0.7, 1, q);
    CHECK(hypot(q[2] - q[0] - D, q[3] - q[1]) > 0.1); /* really the other */

    /* th' = 2: th = -pi/2 + 2 t passes 0 at t = pi/4 and pi at
     * t = 3 pi/4; dt = 1e-3 */
    sw = walk(s, -PI_ / 2 + 1e-4, 2.0, 1e-3, 2000, 0, &first);
    printf("parallelogram, two flat passes: %ld switches\n", sw);
    CHECK_INT(sw, 0);
    /* coarse steps, 0.04 rad each: the velocity turns by about a fifth
     * across the pass, which the accelerations account for */
    sw = walk(s, -PI_ / 2 + 1e-4, 2.0, 2e-2, 100, 0, &first);
    printf("the same in coarse steps: %ld switches\n", sw);
    CHECK_INT(sw, 0);
    sw = walk(s, -PI_ / 2 + 1e-4, 2.0, 1e-3, 2000, 1, &first);
    printf("parallelogram, then the other branch: %ld switch, first at "
           "t = %g\n", sw, first);
    CHECK_INT(sw, 1);
    CHECK(first > PI_ / 4 && first < PI_ / 4 + 0.1);
    sw = walk(s, -PI_ / 2 + 1e-4, 0.2, 1e-2, 2000, 1, &first);
    printf("the same at a tenth of the speed: %ld switch, first at "
           "t = %g\n", sw, first);
    CHECK_INT(sw, 1);

    /* the bead: two full turns, no singular position at all */
    {
        eom_branch *b = NULL;
        double x[4] = {A, 0.0, 0.0, A};
        long evals = 0;
        CHECK_INT(eom__branch_new(&b, bead, 0.0, x), EOM_OK);
        for (i = 1; b && i <= 400; i++) {
            const double th = 4 * PI_ * i / 400;
            x[0] = A * cos(th);
            x[1] = A * sin(th);
            x[2] = -A * sin(th);
            x[3] = A * cos(th);
            CHECK_INT(eom__branch_check(b, bead, 0.01 * i, x, &evals),
                      EOM_OK);
        }
        CHECK_INT(evals, 0); /* never singular: nothing evaluated */
        sw = eom__branch_switches(b, NULL, NULL);
        printf("bead, two turns: %ld switches\n", sw);
        CHECK_INT(sw, 0);
        eom__branch_free(&b);
    }
    eom_system_free(&s);
    eom_system_free(&bead);
    CHECK_DONE();
}
