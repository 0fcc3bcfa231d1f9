/* support_num.c - error measures, the slope of a convergence study and
 * finite differences for the tests (see support_num.h). */
#include <math.h>
#include <stdlib.h>

#include "support_num.h"

double num_max_abs(const double *a, size_t n)
{
    double m = 0.0;
    size_t i;
    for (i = 0; i < n; i++)
        if (fabs(a[i]) > m)
            m = fabs(a[i]);
    return m;
}

double num_vec_err(const double *a, const double *b, size_t n)
{
    double scale = 1.0, err = 0.0;
    size_t i;
    for (i = 0; i < n; i++) {
        if (!isfinite(a[i]) || !isfinite(b[i]))
            return INFINITY;
        if (fabs(b[i]) > scale)
            scale = fabs(b[i]);
        if (fabs(a[i] - b[i]) > err)
            err = fabs(a[i] - b[i]);
    }
    return err / scale;
}

double num_vec_err_scaled(const double *a, const double *b, size_t n,
                          double scale)
{
    double err = 0.0;
    size_t i;
    if (!isfinite(scale))
        return INFINITY;
    if (scale < 1.0)
        scale = 1.0;
    for (i = 0; i < n; i++) {
        if (!isfinite(a[i]) || !isfinite(b[i]))
            return INFINITY;
        if (fabs(a[i] - b[i]) > err)
            err = fabs(a[i] - b[i]);
    }
    return err / scale;
}

size_t num_count_diff(const double *a, const double *b, size_t n)
{
    size_t i, d = 0;
    for (i = 0; i < n; i++)
        if (isnan(a[i]) ? !isnan(b[i]) : !(a[i] == b[i]))
            d++;
    return d;
}

/* (f(x + h s) - f(x - h s)) / 2h into d[m]; xs and yp, ym are scratch. */
static int central(num_vfunc f, void *ctx, int n, int m, const double *x,
                   const double *s, double h, double *xs, double *yp,
                   double *ym, double *d)
{
    int i;
    for (i = 0; i < n; i++)
        xs[i] = x[i] + h * s[i];
    if (f(ctx, xs, yp))
        return -1;
    for (i = 0; i < n; i++)
        xs[i] = x[i] - h * s[i];
    if (f(ctx, xs, ym))
        return -1;
    for (i = 0; i < m; i++)
        d[i] = (yp[i] - ym[i]) / (2.0 * h);
    return 0;
}

int num_fd_dir(num_vfunc f, void *ctx, int n, int m, const double *x,
               const double *s, double h, double *dy)
{
    double *buf = malloc(((size_t)n + 3 * (size_t)m + 1) * sizeof(double));
    double *xs, *yp, *ym, *dh;
    int i, rc = -1;
    if (!buf)
        return -1;
    xs = buf;
    yp = xs + n;
    ym = yp + m;
    dh = ym + m;
    if (central(f, ctx, n, m, x, s, h, xs, yp, ym, dh) == 0 &&
        central(f, ctx, n, m, x, s, 0.5 * h, xs, yp, ym, dy) == 0) {
        /* D(h) = D + c h^2 + O(h^4): eliminate the h^2 term */
        for (i = 0; i < m; i++)
            dy[i] = (4.0 * dy[i] - dh[i]) / 3.0;
        rc = 0;
    }
    free(buf);
    return rc;
}

int num_fd_jac(num_vfunc f, void *ctx, int n, int m, const double *x,
               double h, double *J)
{
    double *e = calloc((size_t)n + (size_t)m + 1, sizeof(double));
    double *col;
    int i, j, rc = 0;
    if (!e)
        return -1;
    col = e + n;
    for (j = 0; j < n && rc == 0; j++) {
        e[j] = 1.0;
        rc = num_fd_dir(f, ctx, n, m, x, e, h, col);
        e[j] = 0.0;
        for (i = 0; i < m; i++)
            J[(size_t)i * (size_t)n + (size_t)j] = col[i];
    }
    free(e);
    return rc;
}

double num_loglog_slope(int n, const double *x, const double *y)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int i;
    for (i = 0; i < n; i++) {
        const double a = log(x[i]), b = log(y[i]);
        sx += a;
        sy += b;
        sxx += a * a;
        sxy += a * b;
    }
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

void num_rk4_pendulum(double a, double *th, double *w, double dt,
                      double hmax)
{
    const long k = (long)ceil(dt / hmax);
    const double h = dt / (double)k;
    long i;
    for (i = 0; i < k; i++) {
        const double t0 = *th, w0 = *w;
        const double k1t = w0, k1w = -a * cos(t0);
        const double k2t = w0 + h / 2 * k1w, k2w = -a * cos(t0 + h / 2 * k1t);
        const double k3t = w0 + h / 2 * k2w, k3w = -a * cos(t0 + h / 2 * k2t);
        const double k4t = w0 + h * k3w, k4w = -a * cos(t0 + h * k3t);
        *th = t0 + h / 6 * (k1t + 2 * k2t + 2 * k3t + k4t);
        *w = w0 + h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
    }
}
