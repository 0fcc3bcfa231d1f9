/* spring_pendulum_tape.c - the README's example: the Lagrangian of a
 * spring pendulum recorded once, then replayed for the blocks of Lagrange's
 * equations M qdd = dL/dq - h. Built and run by the test suite. */
#include <math.h>
#include <stdio.h>

#include "tape/tape.h"

/* x = (r, theta, r_dot, theta_dot); theta from the downward vertical. */
static int spring_pendulum(tp_rec *R, void *user)
{
    tp_val r = tp_indep(R, 0), th = tp_indep(R, 1);
    tp_val rd = tp_indep(R, 2), thd = tp_indep(R, 3);
    tp_val m = tp_param(R, "m", 1.0), k = tp_param(R, "k", 75.0);
    tp_val r0 = tp_param(R, "r0", 1.0), g = tp_param(R, "g", 9.81);
    /* T = 1/2 m (rd^2 + r^2 thd^2) */
    tp_val T = tp_mul(R, tp_mulc(R, m, 0.5),
                      tp_add(R, tp_sqr(R, rd),
                             tp_mul(R, tp_sqr(R, r), tp_sqr(R, thd))));
    /* V = 1/2 k (r - r0)^2 + m g (r0 - r cos th) */
    tp_val V = tp_add(R, tp_mul(R, tp_mulc(R, k, 0.5),
                                tp_sqr(R, tp_sub(R, r, r0))),
                      tp_mul(R, tp_mul(R, m, g),
                             tp_sub(R, r0, tp_mul(R, r, tp_cos(R, th)))));
    (void)user;
    return tp_output(R, "L", tp_sub(R, T, V));
}

/* Report a failed call and say so. */
static int failed(const char *what, int st)
{
    if (st == TP_OK)
        return 0;
    fprintf(stderr, "%s: %s\n", what, tp_strerror(st));
    return 1;
}

int main(void)
{
    const unsigned char group[4] = {0, 0, 1, 1}; /* q, then qd */
    const double x[4] = {1.2, 0.5, 0.1, -0.3};
    const double m = 1.0, k = 75.0, r0 = 1.0, g = 9.81;
    const double r = x[0], th = x[1], rd = x[2], thd = x[3];
    double L, dLdq[2], M[4], h[2], want[9], got[9], err = 0.0;
    tp_rec *rec = NULL;
    tp_tape *tape = NULL;
    tp_ws *ws = NULL;
    int i, bad;

    bad = failed("tp_recorder_new", tp_recorder_new(&rec, 4, group, NULL)) ||
          failed("tp_rec_run", tp_rec_run(rec, NULL, spring_pendulum, NULL)) ||
          failed("tp_recorder_finish", tp_recorder_finish(rec, &tape)) ||
          failed("tp_ws_new", tp_ws_new(&ws, tape, 2, NULL)) ||
          failed("tp_lagrange", tp_lagrange(ws, x, 0, &L, dLdq, M, h));
    if (!bad) {
        /* every block against the hand derivation:
         *   L     = m (rd^2 + r^2 thd^2) / 2 - k (r - r0)^2 / 2
         *           - m g (r0 - r cos th)
         *   dL/dq = (m r thd^2 - k (r - r0) + m g cos th, -m g r sin th)
         *   M     = diag(m, m r^2)
         *   h     = (d2L/dqd dq) qd = (0, 2 m r rd thd) */
        want[0] = 0.5 * m * (rd * rd + r * r * thd * thd) -
                  0.5 * k * (r - r0) * (r - r0) - m * g * (r0 - r * cos(th));
        want[1] = m * r * thd * thd - k * (r - r0) + m * g * cos(th);
        want[2] = -m * g * r * sin(th);
        want[3] = m;
        want[4] = want[5] = 0.0;
        want[6] = m * r * r;
        want[7] = 0.0;
        want[8] = 2.0 * m * r * rd * thd;
        got[0] = L;
        got[1] = dLdq[0];
        got[2] = dLdq[1];
        for (i = 0; i < 4; i++)
            got[3 + i] = M[i];
        got[7] = h[0];
        got[8] = h[1];
        for (i = 0; i < 9; i++)
            err = fmax(err, fabs(got[i] - want[i]) / fmax(1.0, fabs(want[i])));
        printf("L = %.15g, dL/dq = (%.15g, %.15g)\n", L, dLdq[0], dLdq[1]);
        printf("M = [%g %g; %g %g], h = (%g, %g)\n", M[0], M[1], M[2], M[3],
               h[0], h[1]);
        printf("largest difference from the hand derivation: %.3g\n", err);
        bad = !(err <= 1e-14);
    }
    tp_ws_free(&ws);
    tp_tape_free(&tape);
    tp_rec_free(&rec);
    return bad;
}
