/* test_model_bicycle.c - models/whipple-bicycle.eom against the benchmark
 * of Meijaard, Papadopoulos, Ruina and Schwab (Proc. R. Soc. A 463, 2007).
 *
 *  - The start follows the forward speed v (an initial rate written as
 *    an expression of a parameter): x_dot = v, the wheels' rates v/rR
 *    and v/rF, after eom_set_param, and upright straight running is
 *    steady (no acceleration).
 *  - The lean and steer equations about upright straight running,
 *    M qdd + v C1 qd + (g K0 + v^2 K2) q = 0 with the benchmark's
 *    published matrices (eq. 5.4, 14 digits): the model's accelerations
 *    of lean and steer, differentiated in lean, steer and their rates at
 *    states made consistent with the constraints (pitch from the ground
 *    contact, the dependent rates from the rolling constraints), by
 *    central differences at two steps combined so that their h^2 errors
 *    cancel (their error is then below the published digits), against
 *    -M^-1 (g K0 + v^2 K2) and -M^-1 v C1 at 0, 2, 5 and 8 m/s; and M,
 *    K0, K2 and C1 themselves (M from the mass matrix and the rolling
 *    constraints), each to 1e-12.
 *  - The eigenvalues of that 4 x 4 system against the published
 *    matrices' at 0 .. 10 m/s to 1e-12, and the
 *    weave and capsize speeds where it loses a root's negative real part
 *    (Routh-Hurwitz, bisection) against the published 4.29238253634111
 *    and 6.02426201538837 m/s to 1e-10.
 *  - eom_linearize_steady (the exact linearization, reduced to lean,
 *    steer and their rates by the library) against the published
 *    matrices' system and against the differences above, at 0 .. 10 m/s.
 *  - The non-linear bicycle released with a small lean at 4.6 m/s (in
 *    the self-stable range 4.29 .. 6.02 m/s) recovers upright; at 3 m/s
 *    it falls; the rolling constraints held to 1e-12 and E + W constant
 *    to 1e-10 over 10 s.
 *  - eom_model_set_initial from C: the start follows a parameter, and an
 *    initial state that reads a coordinate is refused.
 *
 * usage: test_model_bicycle MODELS_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/model_file.h"
#include "eom/steady.h"

/* LAPACK's general eigenvalue solver */
extern void dgeev_(const char *jobvl, const char *jobvr, const int *n,
                   double *a, const int *lda, double *wr, double *wi,
                   double *vl, const int *ldvl, double *vr, const int *ldvr,
                   double *work, const int *lwork, int *info);

enum { X, Y, YAW, LEAN, PITCH, STEER, THR, THF, N = 8 };

#ifndef H_STEP
#define H_STEP 1e-4
#endif

static const double Mb[4] = {80.81722, 2.31941332208709, 2.31941332208709,
                             0.29784188199686};
static const double C1b[4] = {0.0, 33.86641391492494, -0.85035641456978,
                              1.68540397397560};
static const double K0b[4] = {-80.95, -2.59951685249872, -2.59951685249872,
                              -0.80329488458618};
static const double K2b[4] = {0.0, 76.59734589573222, 0.0,
                              2.65431523794604};

/* Solve the 5 x 5 system A z = r in place (partial pivoting). */
static void solve5(double *A, double *r)
{
    int i, j, k;
    for (k = 0; k < 5; k++) {
        int p = k;
        double t;
        for (i = k + 1; i < 5; i++)
            if (fabs(A[5 * i + k]) > fabs(A[5 * p + k]))
                p = i;
        for (j = 0; j < 5; j++) {
            t = A[5 * k + j];
            A[5 * k + j] = A[5 * p + j];
            A[5 * p + j] = t;
        }
        t = r[k];
        r[k] = r[p];
        r[p] = t;
        for (i = k + 1; i < 5; i++) {
            double f = A[5 * i + k] / A[5 * k + k];
            for (j = k; j < 5; j++)
                A[5 * i + j] -= f * A[5 * k + j];
            r[i] -= f * r[k];
        }
    }
    for (k = 4; k >= 0; k--) {
        double t = r[k];
        for (j = k + 1; j < 5; j++)
            t -= A[5 * k + j] * r[j];
        r[k] = t / A[5 * k + k];
    }
}

/* A state on the constraints: lean, steer and their rates, the rear
 * wheel's rate from the start (v / rR); pitch from the ground contact
 * (Newton), the rates of x, y, yaw, pitch and the front wheel from the
 * constraints' velocity rows (linear in the rates). */
static void consistent(eom_system *s, const double *x0, double le,
                       double st, double led, double std_, double *x)
{
    static const int dep[5] = {X, Y, YAW, PITCH, THF};
    double C[5 * N], phi[5], phid[5];
    int it, i, j;
    memset(x, 0, 2 * N * sizeof *x);
    x[LEAN] = le;
    x[STEER] = st;
    x[N + LEAN] = led;
    x[N + STEER] = std_;
    x[N + THR] = x0[N + THR];
    for (it = 0; it < 20; it++) {
        eom_constraint_jacobian(s, x, C, phi);
        x[PITCH] -= phi[0] / C[PITCH];
    }
    for (it = 0; it < 2; it++) {
        double A[25], r[5];
        eom_constraint_jacobian(s, x, C, phi);
        eom_residuals(s, x, phi, phid);
        for (i = 0; i < 5; i++) {
            for (j = 0; j < 5; j++)
                A[5 * i + j] = C[N * i + dep[j]];
            r[i] = -phid[i];
        }
        solve5(A, r);
        for (j = 0; j < 5; j++)
            x[N + dep[j]] += r[j];
    }
}

static void lean_steer_acc(eom_system *s, const double *x0, const double *d,
                           double *out)
{
    double x[2 * N], xd[2 * N];
    consistent(s, x0, d[0], d[1], d[2], d[3], x);
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
    out[0] = xd[N + LEAN];
    out[1] = xd[N + STEER];
}


/* The model's 4 x 4 linearization in (lean, steer, lean rate, steer
 * rate) at speed v: central differences of the lean and steer
 * accelerations (step h, relative to nothing: the state is 0 there). */
static void model_A(eom_system *s, int kv, double v, double A[16])
{
    const double h = H_STEP;
    double x0[2 * N];
    int i, k, r;
    eom_set_param(s, kv, v);
    eom_initial_state(s, x0);
    memset(A, 0, 16 * sizeof *A);
    A[0 * 4 + 2] = 1.0;
    A[1 * 4 + 3] = 1.0;
    for (k = 0; k < 4; k++) {
        /* central differences at h and 2h, combined (Richardson) so that
         * the h^2 error cancels: (4 D(h) - D(2h)) / 3 */
        double D[2][2];
        for (r = 0; r < 2; r++) {
            double d[4] = {0, 0, 0, 0}, p[2], q[2];
            d[k] = (r + 1) * h;
            lean_steer_acc(s, x0, d, p);
            d[k] = -(r + 1) * h;
            lean_steer_acc(s, x0, d, q);
            for (i = 0; i < 2; i++)
                D[r][i] = (p[i] - q[i]) / (2.0 * (r + 1) * h);
        }
        for (i = 0; i < 2; i++)
            A[(2 + i) * 4 + k] = (4.0 * D[0][i] - D[1][i]) / 3.0;
    }
}

/* The same from the published matrices: [0 I; -M^-1 K, -M^-1 v C1]. */
static void bench_A(double v, double A[16])
{
    const double g = 9.81, det = Mb[0] * Mb[3] - Mb[1] * Mb[2];
    const double Mi[4] = {Mb[3] / det, -Mb[1] / det, -Mb[2] / det,
                          Mb[0] / det};
    int i, j;
    memset(A, 0, 16 * sizeof *A);
    A[2] = 1.0;
    A[7] = 1.0;
    for (i = 0; i < 2; i++)
        for (j = 0; j < 2; j++) {
            A[(2 + i) * 4 + j] =
                -(Mi[2 * i] * (g * K0b[j] + v * v * K2b[j]) +
                  Mi[2 * i + 1] * (g * K0b[2 + j] + v * v * K2b[2 + j]));
            A[(2 + i) * 4 + 2 + j] = -(Mi[2 * i] * v * C1b[j] +
                                       Mi[2 * i + 1] * v * C1b[2 + j]);
        }
}

/* Coefficients c[0..4] of det(l I - A) = l^4 + c3 l^3 + ... + c0 (c[4] =
 * 1), by Faddeev-LeVerrier. */
static void charpoly(const double A[16], double c[5])
{
    double Mk[16], AM[16];
    int k, i, j, l;
    memset(Mk, 0, sizeof Mk);
    c[4] = 1.0;
    for (k = 1; k <= 4; k++) {
        double tr = 0.0;
        /* M_k = A M_{k-1} + c_{n-k+1} I, M_0 = 0 */
        for (i = 0; i < 4; i++)
            for (j = 0; j < 4; j++) {
                double t = 0.0;
                for (l = 0; l < 4; l++)
                    t += A[4 * i + l] * Mk[4 * l + j];
                AM[4 * i + j] = t;
            }
        for (i = 0; i < 4; i++)
            for (j = 0; j < 4; j++)
                Mk[4 * i + j] = AM[4 * i + j] + (i == j ? c[5 - k] : 0.0);
        for (i = 0; i < 4; i++)
            for (l = 0; l < 4; l++)
                tr += A[4 * i + l] * Mk[4 * l + i];
        c[4 - k] = -tr / k;
    }
}

/* The start follows v and is steady; the model's 4 x 4 system against
 * the published one at 0, 2, 5 and 8 m/s; and the benchmark's matrices
 * themselves: M = B^T M_full B with B the rates of every coordinate per
 * unit lean and steer rate (from the constraints, exact at the upright
 * state), then K0, K2 and C1 from M and the 4 x 4 systems at 0 and
 * 1 m/s. */
static void linearized(eom_system *s, int kv, int kg)
{
    static const double speeds[] = {0.0, 2.0, 5.0, 8.0};
    double worst = 0.0, worst_m = 0.0, Mf[N * N], B[2][2 * N], Mr[4],
           A0[16], A1[16], x0[2 * N], xd[2 * N];
    int iv, i, j, k, l;
    for (iv = 0; iv < 4; iv++) {
        const double v = speeds[iv];
        double A[16], Ab[16];
        CHECK_INT(eom_set_param(s, kv, v), EOM_OK);
        CHECK_INT(eom_set_param(s, kg, 9.81), EOM_OK);
        CHECK_INT(eom_initial_state(s, x0), EOM_OK);
        CHECK_NEAR(x0[N + X], v, 1e-15);
        CHECK_NEAR(x0[N + THR], v / 0.3, 1e-15);
        CHECK_NEAR(x0[N + THF], v / 0.35, 1e-15);
        /* upright straight running is steady */
        x0[LEAN] = 0.0;
        CHECK_INT(eom_rhs(s, 0.0, x0, xd), EOM_OK);
        for (k = N; k < 2 * N; k++)
            CHECK(fabs(xd[k]) <= 1e-12);
        model_A(s, kv, v, A);
        bench_A(v, Ab);
        for (k = 8; k < 16; k++)
            worst = fmax(worst, fabs(A[k] - Ab[k]) / fmax(1.0, fabs(Ab[k])));
    }
    printf("bicycle: lean and steer accelerations against the benchmark's "
           "M, C1, K0, K2 at 0, 2, 5, 8 m/s: largest relative difference "
           "%.2g\n", worst);
    CHECK(worst <= 1e-12);

    /* M, K0, K2, C1 one by one */
    CHECK_INT(eom_set_param(s, kv, 0.0), EOM_OK);
    CHECK_INT(eom_initial_state(s, x0), EOM_OK);
    x0[LEAN] = 0.0;
    for (k = 0; k < 2; k++)
        consistent(s, x0, 0.0, 0.0, k == 0, k == 1, B[k]);
    CHECK_INT(eom_mass_matrix(s, B[0], Mf), EOM_OK);
    for (i = 0; i < 2; i++)
        for (j = 0; j < 2; j++) {
            double t = 0.0;
            for (k = 0; k < N; k++)
                for (l = 0; l < N; l++)
                    t += B[i][N + k] * Mf[N * k + l] * B[j][N + l];
            Mr[2 * i + j] = t;
        }
    model_A(s, kv, 0.0, A0);
    model_A(s, kv, 1.0, A1);
    for (i = 0; i < 2; i++)
        for (j = 0; j < 2; j++) {
            /* M qdd = -(g K0 + v^2 K2) q - v C1 qd: a row of M times A */
            double k0 = 0.0, k2 = 0.0, c1 = 0.0;
            for (k = 0; k < 2; k++) {
                k0 -= Mr[2 * i + k] * A0[(2 + k) * 4 + j] / 9.81;
                k2 -= Mr[2 * i + k] *
                      (A1[(2 + k) * 4 + j] - A0[(2 + k) * 4 + j]);
                c1 -= Mr[2 * i + k] * A1[(2 + k) * 4 + 2 + j];
            }
            worst_m = fmax(worst_m, fabs(Mr[2 * i + j] - Mb[2 * i + j]) /
                                        fabs(Mb[2 * i + j]));
            worst_m = fmax(worst_m, fabs(k0 - K0b[2 * i + j]) /
                                        fmax(1.0, fabs(K0b[2 * i + j])));
            worst_m = fmax(worst_m, fabs(k2 - K2b[2 * i + j]) /
                                        fmax(1.0, fabs(K2b[2 * i + j])));
            worst_m = fmax(worst_m, fabs(c1 - C1b[2 * i + j]) /
                                        fmax(1.0, fabs(C1b[2 * i + j])));
        }
    printf("bicycle: M = [%.14g %.14g; %.14g %.14g] (the benchmark's to "
           "%.2g); M, K0, K2 and C1 to %.2g\n", Mr[0], Mr[1], Mr[2], Mr[3],
           fmax(fmax(fabs(Mr[0] - Mb[0]) / Mb[0], fabs(Mr[1] - Mb[1]) / Mb[1]),
                fabs(Mr[3] - Mb[3]) / Mb[3]),
           worst_m);
    CHECK(worst_m <= 1e-12);
}

/* The two stability boundaries as functions of v, from the
 * characteristic polynomial (Routh-Hurwitz for a quartic): a real root
 * crosses 0 where c0 = 0 (capsize), a complex pair crosses the
 * imaginary axis where c3 c2 c1 - c1^2 - c3^2 c0 = 0 (weave). */
static double boundary(eom_system *s, int kv, double v, int weave)
{
    double A[16], c[5];
    if (s)
        model_A(s, kv, v, A);
    else
        bench_A(v, A);
    charpoly(A, c);
    return weave ? c[3] * c[2] * c[1] - c[1] * c[1] - c[3] * c[3] * c[0]
                 : c[0];
}

static double crossing(eom_system *s, int kv, double lo, double hi,
                       int weave)
{
    double flo = boundary(s, kv, lo, weave);
    int k;
    for (k = 0; k < 60 && hi - lo > 1e-13; k++) {
        double mid = 0.5 * (lo + hi), fm = boundary(s, kv, mid, weave);
        if ((fm < 0) == (flo < 0)) {
            lo = mid;
            flo = fm;
        } else {
            hi = mid;
        }
    }
    return 0.5 * (lo + hi);
}

/* The eigenvalues of a 4 x 4 row-major A, sorted by real part, then
 * imaginary part. */
static void eig4(const double A[16], double re[4], double im[4])
{
    double a[16], work[64], dummy[1];
    const int n = 4, one = 1, lw = 64;
    int info = 0, i, j;
    for (i = 0; i < 4; i++) /* column-major */
        for (j = 0; j < 4; j++)
            a[4 * j + i] = A[4 * i + j];
    dgeev_("N", "N", &n, a, &n, re, im, dummy, &one, dummy, &one, work, &lw,
           &info);
    CHECK_INT(info, 0);
    for (i = 1; i < 4; i++)
        for (j = i; j > 0 && (re[j] < re[j - 1] ||
                              (re[j] == re[j - 1] && im[j] < im[j - 1]));
             j--) {
            double t = re[j];
            re[j] = re[j - 1];
            re[j - 1] = t;
            t = im[j];
            im[j] = im[j - 1];
            im[j - 1] = t;
        }
}

/* The characteristic polynomials of the model and of the published
 * matrices at 0 .. 10 m/s (the same polynomial: the same eigenvalues),
 * and the weave and capsize speeds against the published ones. */
static void stability(eom_system *s, int kv)
{
    double worst = 0.0, worst_eig = 0.0, vw, vc, vw_b, vc_b, v;
    int k;
    for (v = 0.0; v <= 10.0 + 1e-9; v += 0.5) {
        double A[16], B[16], ca[5], cb[5];
        model_A(s, kv, v, A);
        bench_A(v, B);
        double ra[4], ia[4], rb[4], ib[4];
        charpoly(A, ca);
        charpoly(B, cb);
        for (k = 0; k < 4; k++)
            worst = fmax(worst, fabs(ca[k] - cb[k]) / fmax(1.0, fabs(cb[k])));
        eig4(A, ra, ia);
        eig4(B, rb, ib);
        for (k = 0; k < 4; k++)
            worst_eig = fmax(worst_eig, hypot(ra[k] - rb[k], ia[k] - ib[k]) /
                                            fmax(1.0, hypot(rb[k], ib[k])));
    }
    vw = crossing(s, kv, 3.0, 5.0, 1);
    vc = crossing(s, kv, 5.0, 7.0, 0);
    vw_b = crossing(NULL, kv, 3.0, 5.0, 1);
    vc_b = crossing(NULL, kv, 5.0, 7.0, 0);
    printf("bicycle: eigenvalues at 0 .. 10 m/s against the published "
           "matrices' %.2g\n", worst_eig);
    CHECK(worst_eig <= 1e-12);
    printf("bicycle: characteristic polynomials at 0 .. 10 m/s against the "
           "published matrices' %.2g; weave speed %.14g (published "
           "4.29238253634111, from the published matrices %.14g), capsize "
           "speed %.14g (published 6.02426201538837, %.14g)\n", worst, vw,
           vw_b, vc, vc_b);
    CHECK(worst <= 1e-10);
    CHECK_NEAR(vw_b, 4.29238253634111, 1e-12);
    CHECK_NEAR(vc_b, 6.02426201538837, 1e-12);
    CHECK_NEAR(vw, 4.29238253634111, 1e-10);
    CHECK_NEAR(vc, 6.02426201538837, 1e-10);
}

/* The library's own reduction, exact: eom_linearize_steady keeping lean,
 * steer and their rates. */
static void steady(eom_system *s, int kv)
{
    const int keep[4] = {LEAN, STEER, N + LEAN, N + STEER};
    double worst = 0.0, worst_fd = 0.0, worst_eig = 0.0, v;
    int k;
    for (v = 0.0; v <= 10.0 + 1e-9; v += 0.5) {
        eom_steady_linear lin;
        double x0[2 * N], Ab[16], Af[16], rb[4], ib[4];
        CHECK_INT(eom_set_param(s, kv, v), EOM_OK);
        CHECK_INT(eom_initial_state(s, x0), EOM_OK);
        x0[LEAN] = 0.0;
        if (eom_linearize_steady(s, 0.0, x0, keep, 4, &lin) != EOM_OK) {
            CHECK_FAIL_("eom_linearize_steady at %g m/s: %s", v,
                        eom_system_errmsg(s));
            return;
        }
        CHECK_INT(lin.nr, 4);
        bench_A(v, Ab);
        model_A(s, kv, v, Af);
        eig4(Ab, rb, ib);
        for (k = 0; k < 16 && lin.nr == 4; k++) {
            worst = fmax(worst, fabs(lin.Ar[k] - Ab[k]) /
                                    fmax(1.0, fabs(Ab[k])));
            worst_fd = fmax(worst_fd, fabs(lin.Ar[k] - Af[k]) /
                                          fmax(1.0, fabs(Af[k])));
        }
        for (k = 0; k < 4 && lin.nr == 4; k++)
            worst_eig = fmax(worst_eig,
                             hypot(lin.eig_re[k] - rb[k],
                                   lin.eig_im[k] - ib[k]) /
                                 fmax(1.0, hypot(rb[k], ib[k])));
        eom_steady_linear_free(&lin);
    }
    printf("bicycle, eom_linearize_steady at 0 .. 10 m/s: against the "
           "published matrices %.2g (eigenvalues %.2g), against the "
           "differences %.2g\n", worst, worst_eig, worst_fd);
    CHECK(worst <= 1e-12);
    CHECK(worst_eig <= 1e-12);
    CHECK(worst_fd <= 1e-12);
}

typedef struct run_stats {
    double dE, res, lean_end, lean_max;
} run_stats;

static run_stats ride(eom_system *s, int kv, double v)
{
    eom_integ *it = NULL;
    eom_opts o;
    eom_energy e0, e;
    run_stats st;
    double x[2 * N], x0[2 * N], phi[5], phid[5], t, W = 0.0;
    int k;
    memset(&st, 0, sizeof st);
    CHECK_INT(eom_set_param(s, kv, v), EOM_OK);
    CHECK_INT(eom_initial_state(s, x0), EOM_OK);
    /* leaning 0.01 rad, on the constraints */
    consistent(s, x0, 0.01, 0.0, 0.0, 0.0, x);
    eom_opts_default(&o);
    o.method = EOM_ERK;
    o.rtol = 1e-12;
    o.atol = 1e-12;
    if (eom_integ_new(&it, s, &o, 0.0, x) != EOM_OK) {
        CHECK_FAIL_("bicycle at %g m/s: %s", v, eom_integ_errmsg(it));
        eom_integ_free(&it);
        return st;
    }
    CHECK_INT(eom_energy_at(s, 0.0, x, &e0), EOM_OK);
    for (t = 0.1; t <= 10.0 + 1e-9; t += 0.1) {
        if (eom_integ_advance(it, t, x, &W) != EOM_OK) {
            CHECK_FAIL_("bicycle at %g m/s: %s", v, eom_integ_errmsg(it));
            break;
        }
        CHECK_INT(eom_energy_at(s, t, x, &e), EOM_OK);
        st.dE = fmax(st.dE, fabs(e.E + W - e0.E) / fabs(e0.E));
        CHECK_INT(eom_residuals(s, x, phi, phid), EOM_OK);
        for (k = 0; k < 5; k++)
            st.res = fmax(st.res, fmax(fabs(phi[k]), fabs(phid[k])));
        st.lean_max = fmax(st.lean_max, fabs(x[LEAN]));
        if (t > 9.0)
            st.lean_end = fmax(st.lean_end, fabs(x[LEAN]));
        if (st.lean_max > 1.0) /* fallen: the rider is on the ground */
            break;
    }
    eom_integ_free(&it);
    printf("bicycle at %g m/s, released leaning 0.01 rad: largest lean %.3g "
           "rad (in the last second %.3g rad; t = %.1f s), E + W relative "
           "drift %.2g, constraint residual %.2g\n", v, st.lean_max,
           st.lean_end, t, st.dE, st.res);
    return st;
}

static void bicycle(const char *dir)
{
    char path[1024], err[2048];
    eom_model *m = NULL;
    eom_system *s = NULL;
    run_stats st;
    int kv, kg;
    snprintf(path, sizeof path, "%s/whipple-bicycle.eom", dir);
    if (eom_model_from_file(&m, path, err, sizeof err) != EOM_OK ||
        eom_system_new(&s, m, err, sizeof err) != EOM_OK) {
        CHECK_FAIL_("%s", err);
        eom_model_free(&m);
        return;
    }
    eom_model_free(&m);
    CHECK_INT(eom_system_ncoords(s), N);
    CHECK_INT(eom_system_nconstraints(s), 5);
    kv = eom_param_index(s, "v");
    kg = eom_param_index(s, "g");
    CHECK(kv >= 0 && kg >= 0);
    linearized(s, kv, kg);
    stability(s, kv);
    steady(s, kv);
    st = ride(s, kv, 4.6);
    CHECK(st.lean_end < 1e-3); /* recovered */
    CHECK(st.dE <= 1e-10);
    CHECK(st.res <= 1e-12);
    st = ride(s, kv, 3.0);
    CHECK(st.lean_max > 1.0); /* fell */
    CHECK(st.dE <= 1e-10);
    CHECK(st.res <= 1e-12);
    eom_system_free(&s);
}

/* ---- eom_model_set_initial from C -------------------------------------- */

static int c_T(eom_ctx *c, void *user, tp_val *out)
{
    (void)user;
    *out = tp_mulc(eom_rec(c), tp_sqr(eom_rec(c), eom_qd(c, 0)), 0.5);
    return 0;
}

static int c_x0(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *r = eom_rec(c);
    tp_val a = eom_param(c, "a");
    out[0] = tp_mulc(r, a, 2.0);
    out[1] = user ? eom_q(c, 0) : tp_sin(r, a);
    return 0;
}

static void initial_from_c(void)
{
    eom_model *m = NULL;
    eom_system *s = NULL;
    char err[1024];
    double x[2];
    int bad;
    for (bad = 0; bad < 2; bad++) {
        eom_model_new(&m);
        eom_model_add_coord(m, "q", NULL, 5.0, 6.0);
        eom_model_add_param(m, "a", NULL, 0.5, NULL);
        eom_model_set_kinetic(m, c_T, NULL);
        CHECK_INT(eom_model_set_initial(m, c_x0, bad ? &bad : NULL), EOM_OK);
        if (!bad) {
            CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
            CHECK_INT(eom_initial_state(s, x), EOM_OK);
            CHECK_NEAR(x[0], 1.0, 1e-15);
            CHECK_NEAR(x[1], sin(0.5), 1e-15);
            CHECK_INT(eom_set_param(s, 0, 2.0), EOM_OK);
            CHECK_INT(eom_initial_state(s, x), EOM_OK);
            CHECK_NEAR(x[0], 4.0, 1e-15);
            CHECK_NEAR(x[1], sin(2.0), 1e-15);
        } else {
            CHECK(eom_system_new(&s, m, err, sizeof err) != EOM_OK);
            CHECK(strstr(err, "initial state") != NULL);
        }
        eom_system_free(&s);
        eom_model_free(&m);
    }
    CHECK_INT(eom_model_set_initial(NULL, c_x0, NULL), EOM_ERR_NULL);
}

int main(int argc, char **argv)
{
    bicycle(argc > 1 ? argv[1] : "models");
    initial_from_c();
    CHECK_DONE();
}
