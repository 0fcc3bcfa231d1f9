/* ocea_plain.c - a plain-C embedded-tuple engine for the rigid chain (see
 * ocea_plain.h). A tuple is len = 1 + n + n(n+1)/2 doubles: value,
 * gradient, then the Hessian's lower triangle row by row, n = 2N.
 * Products by the chain's constants (masses, lengths, g) are scalings,
 * sums that start from zero start from their first term, and every
 * operation may write over an operand (Hessian first, then gradient,
 * then value, each entry read before it is written). */
#include "ocea_plain.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { S_PX, S_PY, S_T, S_Y, S_VG, S_SIN, S_COS, S_LTHD, S_A, S_B,
       S_COUNT };

struct ocea_plain {
    int N, n;
    size_t len, nh;
    double *m, *L, g;
    double *pool; /* [S_COUNT + n] tuples: scratch, then the independents */
};

static double *tup(ocea_plain *o, int k) { return o->pool + (size_t)k * o->len; }

/* w = a u */
static void t_scale(const ocea_plain *o, double *w, double a, const double *u)
{
    size_t k;
    for (k = 0; k < o->len; k++)
        w[k] = a * u[k];
}

/* w = u + a v (w may be u or v) */
static void t_axpy(const ocea_plain *o, double *w, const double *u, double a,
                   const double *v)
{
    size_t k;
    for (k = 0; k < o->len; k++)
        w[k] = u[k] + a * v[k];
}

/* w = u v */
static void t_mul(const ocea_plain *o, double *w, const double *u,
                  const double *v)
{
    const size_t n = o->n;
    const double u0 = u[0], v0 = v[0];
    const double *gu = u + 1, *gv = v + 1;
    double *Hw = w + 1 + n;
    const double *Hu = u + 1 + n, *Hv = v + 1 + n;
    size_t i, j, k;
    for (i = 0, k = 0; i < n; i++) {
        const double a = gu[i], b = gv[i];
        for (j = 0; j <= i; j++, k++)
            Hw[k] = v0 * Hu[k] + u0 * Hv[k] + a * gv[j] + b * gu[j];
    }
    for (i = 0; i < n; i++)
        w[1 + i] = v0 * gu[i] + u0 * gv[i];
    w[0] = u0 * v0;
}

/* w = a u^2 */
static void t_sqr(const ocea_plain *o, double *w, double a, const double *u)
{
    const size_t n = o->n;
    const double u0 = u[0], *gu = u + 1, *Hu = u + 1 + n;
    double *Hw = w + 1 + n;
    size_t i, j, k;
    for (i = 0, k = 0; i < n; i++) {
        const double s = 2.0 * a * gu[i];
        for (j = 0; j <= i; j++, k++)
            Hw[k] = 2.0 * a * u0 * Hu[k] + s * gu[j];
    }
    for (i = 0; i < n; i++)
        w[1 + i] = 2.0 * a * u0 * gu[i];
    w[0] = a * u0 * u0;
}

/* w = sin u or cos u (w may be u) */
static void t_sin_or_cos(const ocea_plain *o, double *w, const double *u,
                         int is_cos)
{
    const size_t n = o->n;
    const double sv = sin(u[0]), cv = cos(u[0]);
    const double f1 = is_cos ? -sv : cv, f11 = is_cos ? -cv : -sv;
    const double *gu = u + 1, *Hu = u + 1 + n;
    double *Hw = w + 1 + n;
    size_t i, j, k;
    for (i = 0, k = 0; i < n; i++) {
        const double a = f11 * gu[i];
        for (j = 0; j <= i; j++, k++)
            Hw[k] = f1 * Hu[k] + a * gu[j];
    }
    for (i = 0; i < n; i++)
        w[1 + i] = f1 * gu[i];
    w[0] = is_cos ? cv : sv;
}

ocea_plain *ocea_plain_new(int N, const double *m, const double *L, double g)
{
    ocea_plain *o = calloc(1, sizeof *o);
    if (!o)
        return NULL;
    o->N = N;
    o->n = 2 * N;
    o->nh = (size_t)o->n * (size_t)(o->n + 1) / 2;
    o->len = 1 + (size_t)o->n + o->nh;
    o->g = g;
    o->m = malloc((size_t)N * sizeof(double));
    o->L = malloc((size_t)N * sizeof(double));
    o->pool = calloc((size_t)(S_COUNT + o->n) * o->len, sizeof(double));
    if (!o->m || !o->L || !o->pool) {
        ocea_plain_free(o);
        return NULL;
    }
    memcpy(o->m, m, (size_t)N * sizeof(double));
    memcpy(o->L, L, (size_t)N * sizeof(double));
    return o;
}

void ocea_plain_free(ocea_plain *o)
{
    if (!o)
        return;
    free(o->m);
    free(o->L);
    free(o->pool);
    free(o);
}

void ocea_plain_lagrange(ocea_plain *o, const double *x, double *Lval,
                         double *dLdq, double *M, double *h)
{
    const int N = o->N, n = o->n;
    double *px = tup(o, S_PX), *py = tup(o, S_PY), *T = tup(o, S_T);
    double *y = tup(o, S_Y), *Vg = tup(o, S_VG), *s = tup(o, S_SIN);
    double *co = tup(o, S_COS), *Lthd = tup(o, S_LTHD), *A = tup(o, S_A);
    double *B = tup(o, S_B), *H;
    int j, i, k;

    /* the independents: x_i with gradient e_i and no curvature */
    for (i = 0; i < n; i++) {
        double *v = tup(o, S_COUNT + i);
        memset(v, 0, o->len * sizeof(double));
        v[0] = x[i];
        v[1 + i] = 1.0;
    }
    /* The element's operations in its order (libeom/src/elements/
     * chain.c), one tuple operation each, a product by a constant being
     * a scaling; what differs is only that sums and products starting
     * from the constant 0 of the root are not computed. T, link by link,
     * with the root joint's velocity (px, py): */
    for (j = 0; j < N; j++) {
        const double *th = tup(o, S_COUNT + j), *thd = tup(o, S_COUNT + N + j);
        const double m = o->m[j], L = o->L[j];
        t_sin_or_cos(o, s, th, 0);
        t_sin_or_cos(o, co, th, 1);
        t_scale(o, Lthd, L, thd);
        if (j == 0) {
            /* px = py = 0: t = Lthd^2 / 6 */
            t_sqr(o, A, 1.0, Lthd);
            t_scale(o, A, 1.0 / 6.0, A);
            t_scale(o, T, m, A);
            t_mul(o, px, Lthd, s);
            t_scale(o, px, -1.0, px);
            t_mul(o, py, Lthd, co);
            continue;
        }
        t_mul(o, A, py, co);                /* Sc = py co - px s */
        t_mul(o, B, px, s);
        t_axpy(o, A, A, -1.0, B);
        t_mul(o, A, Lthd, A);               /* Lthd Sc / 2 */
        t_scale(o, A, 0.5, A);
        t_sqr(o, B, 1.0, Lthd);             /* + Lthd^2 / 6 */
        t_scale(o, B, 1.0 / 6.0, B);
        t_axpy(o, A, A, 1.0, B);
        t_sqr(o, B, 1.0, px);               /* + (px^2 + py^2) / 2 */
        t_sqr(o, Vg, 1.0, py);
        t_axpy(o, B, B, 1.0, Vg);
        t_scale(o, B, 0.5, B);
        t_axpy(o, A, B, 1.0, A);
        t_scale(o, A, m, A);                /* trig = m t */
        t_axpy(o, T, T, 1.0, A);
        t_mul(o, B, Lthd, s);               /* the tip's velocity */
        t_axpy(o, px, px, -1.0, B);
        t_mul(o, B, Lthd, co);
        t_axpy(o, py, py, 1.0, B);
    }
    /* V: the heights of the link centres, y the root's */
    for (j = 0; j < N; j++) {
        const double *th = tup(o, S_COUNT + j);
        const double m = o->m[j], L = o->L[j];
        t_sin_or_cos(o, s, th, 0);
        t_scale(o, s, L, s);                /* Ls */
        t_scale(o, A, 0.5, s);              /* h = y + Ls / 2 */
        if (j > 0)
            t_axpy(o, A, y, 1.0, A);
        t_scale(o, A, m, A);                /* Vg += m h */
        if (j > 0) {
            t_axpy(o, Vg, Vg, 1.0, A);
            t_axpy(o, y, y, 1.0, s);        /* y += Ls */
        } else {
            t_scale(o, Vg, 1.0, A);
            t_scale(o, y, 1.0, s);
        }
    }
    t_scale(o, Vg, o->g, Vg);               /* V = g Vg; L = T - V */
    t_axpy(o, T, T, -1.0, Vg);

    H = T + 1 + n;
    *Lval = T[0];
    for (i = 0; i < N; i++) {
        const int qi = N + i;
        double sum = 0.0;
        dLdq[i] = T[1 + i];
        for (k = 0; k < N; k++) {
            const int qk = N + k;
            M[i * N + k] = qi >= qk ? H[qi * (qi + 1) / 2 + qk]
                                    : H[qk * (qk + 1) / 2 + qi];
            sum += H[qi * (qi + 1) / 2 + k] * x[qk];
        }
        h[i] = sum;
    }
}
