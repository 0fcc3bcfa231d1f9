/* test_chain_energy.c - the chain element's energies against an
 * independent construction.
 *
 *   - kinetic energy: Gauss-Legendre quadrature of 1/2 rho |rd(x)|^2 along
 *     every link, with the velocity of each point built here from the
 *     kinematics (r_j(x) = sum_{k<j} L_k e_k + x e_j + v_j(x) n_j), at
 *     random states of chains with mixed rigid and flexible links;
 *   - potential: quadrature of the strain energy 1/2 EI v''^2 and of the
 *     gravity potential g rho y(x);
 *   - probes: rigid + flexible parts sum to each link's kinetic energy (the
 *     rigid part is that of the chord as a rigid rod), strain probes sum to
 *     the strain energy;
 *   - the tape of the Lagrangian grows linearly with the number of links;
 *   - the model's Lagrangian run on the embedded-tuple engine
 *     (eom_model_run_lagrangian) gives the tape's mass matrix and forces.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/chain.h"
#include "eom_internal.h"
#include "support_rng.h"

static const double pi = 3.14159265358979323846;

/* Gauss-Legendre nodes and weights on [0, 1] (Newton on P_n). */
static void gauss_legendre(int n, double *x, double *w)
{
    int i, k;
    for (i = 0; i < n; i++) {
        double z = cos(pi * (i + 0.75) / (n + 0.5)), dp = 0.0;
        for (k = 0; k < 100; k++) {
            double p0 = 1.0, p1 = z, z1;
            int l;
            for (l = 2; l <= n; l++) {
                double p2 = ((2.0 * l - 1.0) * z * p1 - (l - 1.0) * p0) / l;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (z * p1 - p0) / (z * z - 1.0);
            z1 = z;
            z -= p1 / dp;
            if (fabs(z - z1) < 1e-16)
                break;
        }
        x[i] = 0.5 * (1.0 - z);
        w[i] = 1.0 / ((1.0 - z * z) * dp * dp);
    }
}

typedef struct chain_case {
    int N;
    int K[6];
    double m[6], L[6], EI[6], g;
} chain_case;

enum { NQ = 24 };

/* Energies by quadrature at state x (theta, then modes link by link). */
static void quadrature(const chain_case *cc, const double *x, int n,
                       double *T, double *Tlink, double *Ustrain,
                       double *Vg)
{
    double gx[NQ], gw[NQ], px = 0.0, py = 0.0, ry = 0.0;
    int j, k, i, qi = cc->N;
    gauss_legendre(NQ, gx, gw);
    *T = *Ustrain = *Vg = 0.0;
    for (j = 0; j < cc->N; j++) {
        const double th = x[j], thd = x[n + j], L = cc->L[j];
        const double rho = cc->m[j] / L;
        const double e[2] = {cos(th), sin(th)}, nn[2] = {-sin(th), cos(th)};
        double tj = 0.0;
        for (k = 0; k < NQ; k++) {
            const double s = gx[k] * L, wk = gw[k] * L;
            double v = 0.0, vd = 0.0, v2 = 0.0, vx, vy;
            for (i = 1; i <= cc->K[j]; i++) {
                const double a = i * pi / L, ph = sin(a * s);
                v += x[qi + i - 1] * ph;
                vd += x[n + qi + i - 1] * ph;
                v2 -= x[qi + i - 1] * a * a * ph;
            }
            /* velocity of the point: root + s thd n + vd n - v thd e */
            vx = px + s * thd * nn[0] + vd * nn[0] - v * thd * e[0];
            vy = py + s * thd * nn[1] + vd * nn[1] - v * thd * e[1];
            tj += wk * 0.5 * rho * (vx * vx + vy * vy);
            *Ustrain += wk * 0.5 * cc->EI[j] * v2 * v2;
            *Vg += wk * cc->g * rho * (ry + s * e[1] + v * nn[1]);
        }
        Tlink[j] = tj;
        *T += tj;
        px += L * thd * nn[0];
        py += L * thd * nn[1];
        ry += L * e[1];
        qi += cc->K[j];
    }
}

static eom_system *build(const chain_case *cc)
{
    eom_chain_spec sp;
    eom_model *md = NULL;
    eom_system *s = NULL;
    char msg[256];
    memset(&sp, 0, sizeof sp);
    sp.links = cc->N;
    sp.modes = cc->K;
    sp.m_link = cc->m;
    sp.L_link = cc->L;
    sp.EI_link = cc->EI;
    sp.g = cc->g;
    if (eom_model_new(&md) != EOM_OK)
        return NULL;
    CHECK(eom_chain_add(md, &sp) == 0);
    CHECK_INT(eom_system_new(&s, md, msg, sizeof msg), EOM_OK);
    eom_model_free(&md);
    return s;
}

static void energies(void)
{
    static const chain_case cases[] = {
        {1, {3}, {1.0}, {10.0}, {4e3}, 9.81},
        {3, {2, 0, 3}, {1.0, 2.0, 0.5}, {10.0, 4.0, 7.0}, {4e3, 1e3, 2e4},
         9.81},
        {5, {1, 2, 3, 1, 0}, {1, 1.5, 0.7, 1.2, 2}, {3, 4, 5, 6, 2},
         {100, 200, 300, 400, 500}, 3.0},
    };
    rng gen = rng_seed(2024);
    size_t c;
    for (c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        const chain_case *cc = &cases[c];
        eom_system *s = build(cc);
        const int n = s ? eom_system_ncoords(s) : 0;
        double x[64], p[32], Tlink[6], T, Us, Vg;
        int trial, j, k;
        if (!s)
            continue;
        for (trial = 0; trial < 20; trial++) {
            eom_energy e;
            double sum_rigid_flex, Ustrain_probe = 0.0;
            for (j = 0; j < 2 * n; j++)
                x[j] = j < cc->N || (j >= n && j < n + cc->N)
                           ? rng_range(&gen, -3.0, 3.0)
                           : rng_range(&gen, -0.3, 0.3);
            quadrature(cc, x, n, &T, Tlink, &Us, &Vg);
            CHECK_INT(eom_energy_at(s, 0.0, x, &e), EOM_OK);
            CHECK_NEAR(e.T, T, 1e-12);
            CHECK_NEAR(e.V, Us + Vg, 1e-12);
            CHECK_INT(eom_probes_at(s, x, p), EOM_OK);
            /* probes: rigid and flexible per link, strain per link */
            for (j = 0, k = 0; j < cc->N; j++) {
                sum_rigid_flex = p[k++];
                if (cc->K[j] > 0) {
                    sum_rigid_flex += p[k++];
                    Ustrain_probe += p[k++];
                }
                CHECK_NEAR(sum_rigid_flex, Tlink[j], 1e-12);
            }
            CHECK_NEAR(Ustrain_probe, Us, 1e-12);
        }
        eom_system_free(&s);
    }
}

/* The rigid probe of a link is the kinetic energy of its chord as a rigid
 * rod: 1/2 m |v_centre|^2 + m L^2 / 24 thd^2. */
static void rigid_probe(void)
{
    const chain_case cc = {2, {2, 2}, {1.0, 3.0}, {2.0, 5.0}, {1e3, 1e3},
                           0.0};
    eom_system *s = build(&cc);
    const int n = s ? eom_system_ncoords(s) : 0;
    double x[16] = {0}, p[8];
    if (!s)
        return;
    x[0] = 0.4;
    x[1] = -1.1;
    x[n + 0] = 0.7;
    x[n + 1] = -0.3;
    x[2] = 0.05;
    x[n + 3] = 0.2; /* flexible motion must not enter the rigid part */
    CHECK_INT(eom_probes_at(s, x, p), EOM_OK);
    {
        /* link 2: root velocity L1 thd1 n1, centre adds L2/2 thd2 n2 */
        const double vx = -2.0 * 0.7 * sin(0.4) - 2.5 * -0.3 * sin(-1.1);
        const double vy = 2.0 * 0.7 * cos(0.4) + 2.5 * -0.3 * cos(-1.1);
        const double t2 = 0.5 * 3.0 * (vx * vx + vy * vy) +
                          3.0 * 25.0 / 24.0 * 0.09;
        CHECK_NEAR(p[3], t2, 1e-13); /* order: T1r, T1f, U1, T2r, ... */
        CHECK_NEAR(p[0], 1.0 * 4.0 / 6.0 * 0.49, 1e-13);
    }
    eom_system_free(&s);
}

static size_t tape_ops(int N, int K)
{
    eom_chain_spec sp;
    eom_model *md = NULL;
    eom_system *s = NULL;
    tp_tape_stats st;
    size_t ops = 0;
    memset(&sp, 0, sizeof sp);
    sp.links = N;
    sp.modes_all = K;
    sp.m = 1.0;
    sp.L = 10.0;
    sp.EI = 4e3;
    sp.g = 9.81;
    sp.closed = 1;
    sp.D = 10.0;
    if (eom_model_new(&md) == EOM_OK && eom_chain_add(md, &sp) >= 0 &&
        eom_system_new(&s, md, NULL, 0) == EOM_OK &&
        tp_tape_stats_get(s->tL.tape, &st) == TP_OK)
        ops = st.n_ops;
    eom_system_free(&s);
    eom_model_free(&md);
    return ops;
}

static void linear_growth(void)
{
    int K;
    for (K = 0; K <= 3; K++) {
        const size_t a = tape_ops(5, K), b = tape_ops(10, K),
                     c = tape_ops(20, K), d = tape_ops(40, K);
        /* equal increments per link once the chain is past its first
         * links (whose zero joint velocity folds away) */
        CHECK(a > 0 && b > a && c > b && d > c);
        CHECK_INT(c - b, 2 * (b - a));
        CHECK_INT(d - c, 2 * (c - b));
    }
}

static void tuples_agree(void)
{
    const chain_case cc = {3, {2, 0, 3}, {1.0, 2.0, 0.5}, {10.0, 4.0, 7.0},
                           {4e3, 1e3, 2e4}, 9.81};
    eom_chain_spec sp;
    eom_model *md = NULL;
    eom_system *s = NULL;
    tp_rec *tu = NULL;
    double x[32], M[256], Mt[256], g[16], h[16], L;
    int n, i, j;
    memset(&sp, 0, sizeof sp);
    sp.links = cc.N;
    sp.modes = cc.K;
    sp.m_link = cc.m;
    sp.L_link = cc.L;
    sp.EI_link = cc.EI;
    sp.g = cc.g;
    if (eom_model_new(&md) != EOM_OK || eom_chain_add(md, &sp) != 0 ||
        eom_system_new(&s, md, NULL, 0) != EOM_OK) {
        CHECK(!"building the chain");
        eom_model_free(&md);
        return;
    }
    n = eom_system_ncoords(s);
    for (i = 0; i < 2 * n; i++)
        x[i] = 0.1 * i - 0.7 + 0.05 * sin(3.0 * i);
    CHECK_INT(tp_tuple_new(&tu, 2 * n, NULL), TP_OK);
    CHECK_INT(eom_model_run_lagrangian(md, tu, x), EOM_OK);
    CHECK_INT(tp_tuple_lagrange(tu, 0, &L, g, Mt, h), TP_OK);
    CHECK_INT(eom_mass_matrix(s, x, M), EOM_OK);
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++)
            CHECK_NEAR(Mt[i * n + j], M[i * n + j], 1e-13);
    /* the right-hand side from the tuples' blocks equals eom_rhs's force:
     * M qdd = dL/dq - h */
    {
        double xd[32], r;
        CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
        for (i = 0; i < n; i++) {
            r = 0.0;
            for (j = 0; j < n; j++)
                r += M[i * n + j] * xd[n + j];
            CHECK_NEAR(r, g[i] - h[i], 1e-11);
        }
    }
    CHECK_INT(eom_model_run_lagrangian(md, NULL, x), EOM_ERR_NULL);
    tp_rec_free(&tu);
    eom_system_free(&s);
    eom_model_free(&md);
}

int main(void)
{
    energies();
    tuples_agree();
    rigid_probe();
    linear_growth();
    CHECK_DONE();
}
