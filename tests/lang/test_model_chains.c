/* test_model_chains.c - the flexible chains written in the model language
 * (models/open-chain.eom, models/closed-chain.eom) against the same chains
 * from the C element library (eom/chain.h), as the demos build them: the
 * mass matrix and the accelerations at two states, the state after 2 s of
 * RK4, and the size of the Lagrangian's tape. Also a chain of 7 links and
 * 3 modes, to see that the settings reach the file. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/chain.h"
#include "eom/model_file.h"

static const double pi = 3.14159265358979323846;
static char models[1024];

/* The C chain of the demos (apps/demos/chains.c). */
static eom_model *c_chain(int closed, int N, int K)
{
    double *th = calloc((size_t)N, sizeof *th);
    double *thd = calloc((size_t)N, sizeof *thd);
    double *q0 = calloc((size_t)(N * K + 1), sizeof *q0);
    unsigned char *damped = calloc((size_t)N + 1, 1);
    static const double paper[5] = {5, 1, 0, 17, 13};
    eom_chain_spec sp;
    eom_model *m = NULL;
    int j;
    memset(&sp, 0, sizeof sp);
    for (j = 0; j < N; j++)
        th[j] = closed ? paper[j] * pi / 12 : (j % 2 ? -1.0 : 1.0) * pi / 6;
    if (!closed) {
        thd[N - 1] = 0.5;
        if (K > 0)
            q0[(N - 1) * K] = 0.01;
    }
    for (j = 1; j <= (closed ? N : N - 1); j++)
        damped[j] = 1;
    sp.links = N;
    sp.modes_all = K;
    sp.closed = closed;
    sp.m = 1.0;
    sp.L = 10.0;
    sp.EI = closed ? 4e4 : 4e3;
    sp.g = closed ? 9.81 : 0.0;
    sp.c = closed ? 10.0 : 0.0;
    sp.D = 10.0;
    sp.structural = 1; /* as the files: zeta, 0 by default */
    sp.theta0 = th;
    sp.theta0_dot = thd;
    sp.q0 = q0;
    sp.damped = damped;
    CHECK(eom_model_new(&m) == EOM_OK);
    CHECK(eom_chain_add(m, &sp) >= 0);
    free(th);
    free(thd);
    free(q0);
    free(damped);
    return m;
}

static eom_model *file_chain(const char *name, int N, int K)
{
    char path[1200], err[2048];
    eom_file *f = NULL;
    eom_model *m = NULL;
    snprintf(path, sizeof path, "%s/%s", models, name);
    if (eom_file_read(&f, path, err, sizeof err) != EOM_OK) {
        CHECK_FAIL_("%s", err);
        return NULL;
    }
    CHECK(eom_file_set_setting(f, "links", N, err, sizeof err) == EOM_OK);
    CHECK(eom_file_set_setting(f, "modes", K, err, sizeof err) == EOM_OK);
    if (eom_file_build(f, &m, err, sizeof err) != EOM_OK)
        CHECK_FAIL_("%s", err);
    eom_file_free(&f);
    return m;
}

static size_t lagrangian_ops(const eom_model *m, int n)
{
    unsigned char *group = malloc(2 * (size_t)n);
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    tp_tape_stats st;
    int k;
    for (k = 0; k < 2 * n; k++)
        group[k] = (unsigned char)(k >= n);
    CHECK(tp_recorder_new(&r, 2 * n, group, NULL) == TP_OK);
    CHECK(eom_model_run_lagrangian(m, r, NULL) == EOM_OK);
    CHECK(tp_recorder_finish(r, &t) == TP_OK);
    memset(&st, 0, sizeof st);
    tp_tape_stats_get(t, &st);
    tp_tape_free(&t);
    tp_rec_free(&r);
    free(group);
    return st.n_ops;
}

static double max_abs(const double *v, size_t n)
{
    double m = 0.0;
    size_t k;
    for (k = 0; k < n; k++)
        m = fmax(m, fabs(v[k]));
    return m;
}

static void integrate_2s(eom_system *s, double *x)
{
    eom_opts o;
    eom_integ *it = NULL;
    eom_opts_default(&o);
    o.method = EOM_RK4;
    o.dt = 1e-3;
    CHECK(eom_integ_new(&it, s, &o, 0.0, x) == EOM_OK);
    CHECK(eom_integ_advance(it, 2.0, x, NULL) == EOM_OK);
    eom_integ_free(&it);
}

/* M and qdd at the initial state and at a state moved off it. */
static void compare_chain(int closed, int N, int K, int integrate)
{
    eom_model *mc = c_chain(closed, N, K);
    eom_model *mf = file_chain(closed ? "closed-chain.eom" : "open-chain.eom",
                               N, K);
    eom_system *sc = NULL, *sf = NULL;
    char err[512];
    int n, k, pass;
    size_t ops_c, ops_f;
    double *x, *xc, *xf, *Mc, *Mf, *dc, *df;
    if (!mc || !mf)
        return;
    CHECK(eom_system_new(&sc, mc, err, sizeof err) == EOM_OK);
    CHECK(eom_system_new(&sf, mf, err, sizeof err) == EOM_OK);
    if (!sc || !sf)
        return;
    n = eom_system_ncoords(sc);
    CHECK_INT(eom_system_ncoords(sf), n);
    CHECK_INT(eom_system_nconstraints(sf), eom_system_nconstraints(sc));
    for (k = 0; k < n; k++)
        CHECK(strcmp(eom_coord_name(sc, k), eom_coord_name(sf, k)) == 0);
    x = calloc(2 * (size_t)n, sizeof *x);
    xc = calloc(2 * (size_t)n, sizeof *xc);
    xf = calloc(2 * (size_t)n, sizeof *xf);
    Mc = calloc((size_t)n * n, sizeof *Mc);
    Mf = calloc((size_t)n * n, sizeof *Mf);
    dc = calloc(2 * (size_t)n, sizeof *dc);
    df = calloc(2 * (size_t)n, sizeof *df);
    CHECK(eom_initial_state(sc, xc) == EOM_OK);
    CHECK(eom_initial_state(sf, xf) == EOM_OK);
    for (k = 0; k < 2 * n; k++)
        CHECK(xc[k] == xf[k]);
    for (pass = 0; pass < 2; pass++) {
        double scale;
        for (k = 0; k < 2 * n; k++)
            x[k] = xc[k] + (pass ? 0.05 * sin(1.0 + k) : 0.0);
        CHECK(eom_mass_matrix(sc, x, Mc) == EOM_OK);
        CHECK(eom_mass_matrix(sf, x, Mf) == EOM_OK);
        scale = max_abs(Mc, (size_t)n * n);
        for (k = 0; k < n * n; k++)
            CHECK_NEAR(Mf[k] / scale, Mc[k] / scale, 1e-12);
        CHECK(eom_rhs(sc, 0.0, x, dc) == EOM_OK);
        CHECK(eom_rhs(sf, 0.0, x, df) == EOM_OK);
        scale = fmax(1.0, max_abs(dc + n, (size_t)n));
        for (k = n; k < 2 * n; k++)
            CHECK_NEAR(df[k] / scale, dc[k] / scale, 1e-12);
    }
    /* structural damping: the same forces from the file's R and the
     * element's */
    if (K > 0) {
        double scale;
        CHECK(eom_set_param(sc, eom_param_index(sc, "zeta"), 0.03) == EOM_OK);
        CHECK(eom_set_param(sf, eom_param_index(sf, "zeta"), 0.03) == EOM_OK);
        CHECK(eom_rhs(sc, 0.0, x, dc) == EOM_OK);
        CHECK(eom_rhs(sf, 0.0, x, df) == EOM_OK);
        scale = fmax(1.0, max_abs(dc + n, (size_t)n));
        for (k = n; k < 2 * n; k++)
            CHECK_NEAR(df[k] / scale, dc[k] / scale, 1e-12);
        CHECK(eom_set_param(sc, eom_param_index(sc, "zeta"), 0.0) == EOM_OK);
        CHECK(eom_set_param(sf, eom_param_index(sf, "zeta"), 0.0) == EOM_OK);
    }
    if (integrate) {
        /* RK4 for 2 s from the same start; the tapes differ in the order
         * of their operations, so the reverse sweeps add the same terms
         * in another order. The chain's own sensitivity bounds what can
         * agree: the C chain is run a third time from a start moved by
         * 1e-15, and the file may differ from C by no more than 10 times
         * that (and never by more than 1e-12 where that is larger). */
        double diff = 0.0, sens = 0.0;
        for (k = 0; k < 2 * n; k++)
            x[k] = xc[k] + 1e-15 * sin(1.0 + k);
        integrate_2s(sc, xc);
        integrate_2s(sf, xf);
        integrate_2s(sc, x);
        for (k = 0; k < 2 * n; k++) {
            diff = fmax(diff, fabs(xf[k] - xc[k]));
            sens = fmax(sens, fabs(x[k] - xc[k]));
        }
        printf("%s chain at t = 2 s: file - C %.2g, C moved by 1e-15 at the "
               "start - C %.2g\n", closed ? "closed" : "open", diff, sens);
        CHECK(diff <= fmax(1e-12, 10.0 * sens));
    }
    ops_c = lagrangian_ops(mc, n);
    ops_f = lagrangian_ops(mf, n);
    printf("%s chain, %d links, %d modes: L tape %zu ops from C, %zu from "
           "the file (%+.1f%%)\n", closed ? "closed" : "open", N, K, ops_c,
           ops_f, 100.0 * ((double)ops_f - (double)ops_c) / (double)ops_c);
    CHECK(fabs((double)ops_f - (double)ops_c) <= 0.10 * (double)ops_c);
    free(x);
    free(xc);
    free(xf);
    free(Mc);
    free(Mf);
    free(dc);
    free(df);
    eom_system_free(&sc);
    eom_system_free(&sf);
    eom_model_free(&mc);
    eom_model_free(&mf);
}

int main(int argc, char **argv)
{
    snprintf(models, sizeof models, "%s", argc > 1 ? argv[1] : "models");
    compare_chain(0, 3, 2, 1); /* the demos' defaults */
    compare_chain(1, 5, 1, 1);
    compare_chain(0, 7, 3, 0);
    compare_chain(0, 2, 0, 0); /* rigid links */
    CHECK_DONE();
}
