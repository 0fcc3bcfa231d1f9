/* hand_ref.c - see hand_ref.h. */
#include "hand_ref.h"

#include <math.h>

void hand_spring(const double *y, double *f)
{
    const double k = 75.0, r0 = 1.0, g = 9.81; /* m = 1 */
    const double r = y[0], th = y[1], rd = y[2], thd = y[3];
    f[0] = rd;
    f[1] = thd;
    f[2] = r * thd * thd - k * (r - r0) + g * cos(th);
    f[3] = -(2.0 * rd * thd + g * sin(th)) / r;
}

void hand_rk4(hand_f fn, double t_end, long steps, double *y)
{
    const double h = t_end / (double)steps;
    long i;
    int e;
    for (i = 0; i < steps; i++) {
        double k1[4], k2[4], k3[4], k4[4], z[4];
        fn(y, k1);
        for (e = 0; e < 4; e++) z[e] = y[e] + 0.5 * h * k1[e];
        fn(z, k2);
        for (e = 0; e < 4; e++) z[e] = y[e] + 0.5 * h * k2[e];
        fn(z, k3);
        for (e = 0; e < 4; e++) z[e] = y[e] + h * k3[e];
        fn(z, k4);
        for (e = 0; e < 4; e++)
            y[e] += h / 6.0 * (k1[e] + 2 * k2[e] + 2 * k3[e] + k4[e]);
    }
}

double hand_max_diff(int len, const double *a, const double *b)
{
    double d = 0.0;
    int e;
    for (e = 0; e < len; e++)
        d = fmax(d, fabs(a[e] - b[e]));
    return d;
}
