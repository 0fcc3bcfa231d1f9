/* pendulum_chain.c - the N-link pendulum, written once against the
 * recording API and once in plain doubles (see pendulum_chain.h). The
 * kinetic energy is accumulated link by link through the joint velocity,
 * so the tape grows linearly with n. */
#include <math.h>
#include <stdio.h>

#include "pendulum_chain.h"

double pendulum_chain_m(const pendulum_chain *pc, int i)
{
    return pc->m ? pc->m[i] : 1.0;
}

double pendulum_chain_l(const pendulum_chain *pc, int i)
{
    return pc->l ? pc->l[i] : 1.0;
}

int pendulum_chain_record(tp_rec *r, void *user)
{
    const pendulum_chain *pc = user;
    const int n = pc->n;
    tp_val px = tp_const(r, 0.0), py = tp_const(r, 0.0); /* joint velocity */
    tp_val y = tp_const(r, 0.0);                          /* joint height */
    tp_val T = tp_const(r, 0.0), V = tp_const(r, 0.0);
    tp_val g = tp_param(r, "g", pc->g);
    char name[32];
    int i;
    for (i = 0; i < n; i++) {
        tp_val q = tp_indep(r, i), qd = tp_indep(r, n + i);
        tp_val m, l, c, s, hl, vx, vy, yc, lqd;
        snprintf(name, sizeof name, "m%d", i + 1);
        m = tp_param(r, name, pendulum_chain_m(pc, i));
        snprintf(name, sizeof name, "l%d", i + 1);
        l = tp_param(r, name, pendulum_chain_l(pc, i));
        c = tp_cos(r, q);
        s = tp_sin(r, q);
        hl = tp_mulc(r, l, 0.5);
        /* centre velocity: joint velocity + (l/2) qd (cos q, sin q) */
        lqd = tp_mul(r, hl, qd);
        vx = tp_add(r, px, tp_mul(r, lqd, c));
        vy = tp_add(r, py, tp_mul(r, lqd, s));
        T = tp_add(r, T, tp_mul(r, tp_mulc(r, m, 0.5),
                                tp_add(r, tp_sqr(r, vx), tp_sqr(r, vy))));
        /* rotation about the centre: m l^2 / 24 qd^2 */
        T = tp_add(r, T, tp_mul(r, tp_mulc(r, tp_mul(r, m, tp_sqr(r, l)),
                                           1.0 / 24.0),
                                tp_sqr(r, qd)));
        yc = tp_sub(r, y, tp_mul(r, hl, c));
        V = tp_add(r, V, tp_mul(r, tp_mul(r, m, g), yc));
        /* next joint */
        lqd = tp_mul(r, l, qd);
        px = tp_add(r, px, tp_mul(r, lqd, c));
        py = tp_add(r, py, tp_mul(r, lqd, s));
        y = tp_sub(r, y, tp_mul(r, l, c));
    }
    tp_output(r, "L", tp_sub(r, T, V));
    tp_output(r, "T", T);
    tp_output(r, "V", V);
    return 0;
}

double pendulum_chain_L(const pendulum_chain *pc, const double *x)
{
    const int n = pc->n;
    double px = 0.0, py = 0.0, y = 0.0, T = 0.0, V = 0.0;
    int i;
    for (i = 0; i < n; i++) {
        const double q = x[i], qd = x[n + i];
        const double m = pendulum_chain_m(pc, i), l = pendulum_chain_l(pc, i);
        const double c = cos(q), s = sin(q), hl = 0.5 * l;
        const double vx = px + hl * qd * c, vy = py + hl * qd * s;
        T += 0.5 * m * (vx * vx + vy * vy) + m * l * l / 24.0 * qd * qd;
        V += m * pc->g * (y - hl * c);
        px += l * qd * c;
        py += l * qd * s;
        y -= l * c;
    }
    return T - V;
}

void pendulum_chain_mass(const pendulum_chain *pc, const double *q, double *M)
{
    const int n = pc->n;
    int i, j, k;
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) {
            const int lo = i < j ? i : j, hi = i < j ? j : i;
            const double li = pendulum_chain_l(pc, lo);
            const double lj = pendulum_chain_l(pc, hi);
            double tail = 0.0, a;
            for (k = hi + 1; k < n; k++)
                tail += pendulum_chain_m(pc, k);
            if (lo == hi)
                a = pendulum_chain_m(pc, lo) * li * li / 3.0 + li * li * tail;
            else
                a = li * lj * (pendulum_chain_m(pc, hi) / 2.0 + tail);
            M[i * n + j] = a * cos(q[i] - q[j]);
        }
    }
}
