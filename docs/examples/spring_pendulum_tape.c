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

int main(void)
{
    const unsigned char group[4] = {0, 0, 1, 1}; /* q, then qd */
    const double x[4] = {1.2, 0.5, 0.1, -0.3};
    double L, dLdq[2], M[4], h[2];
    tp_rec *rec;
    tp_tape *tape;
    tp_ws *ws;

    tp_recorder_new(&rec, 4, group, NULL);
    tp_rec_run(rec, NULL, spring_pendulum, NULL);
    if (tp_recorder_finish(rec, &tape) != TP_OK) {
        fprintf(stderr, "%s\n", tp_rec_errmsg(rec));
        return 1;
    }
    tp_ws_new(&ws, tape, 2, NULL);
    tp_lagrange(ws, x, 0, &L, dLdq, M, h);
    /* M = diag(m, m r^2); check against the hand derivation */
    printf("M = [%g %g; %g %g], expected diag(1, %g)\n", M[0], M[1], M[2],
           M[3], x[0] * x[0]);
    tp_ws_free(&ws);
    tp_tape_free(&tape);
    tp_rec_free(&rec);
    return fabs(M[3] - x[0] * x[0]) < 1e-15 && M[1] == 0.0 ? 0 : 1;
}
