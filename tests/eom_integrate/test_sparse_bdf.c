/* test_sparse_bdf.c - bdf's sparse Jacobian (state_jacobian_sparse.c)
 * and the choice between it and the dense one (eom_opts.linear_solver).
 *
 *   1. The pattern (from the residual tape's structure and the blocks of
 *      M) holds the whole diagonal and every entry of the dense
 *      d(yd)/dy (eom__state_jacobian with its power row) that is
 *      nonzero at many random states, on free lines of masses with a
 *      diagonal M, with 2 x 2 and with 4 x 4 blocks of M, and with
 *      springs of reach 3; its blocks are the ones built in.
 *   2. The sparse values equal the dense ones entry by entry, to 1e-14
 *      of the entry (with a floor of 1e-16 of its row's largest), the
 *      power row included.
 *   3. Whole runs: bdf sparse and dense end 1 s of the free line of 30
 *      masses (also stiffly damped) and of the 4 x 4 blocks line within
 *      1e-7 of each other, in steps within 10 % of each other, and
 *      eom_stats says which solver each used.
 *      Sensitivities (to a parameter and an initial value) agree too.
 *   4. The automatic choice: dense for the shipped models (below the
 *      size bound, the pattern not even computed), for an open chain of
 *      40 links (full M: above the fill bound) and for constrained
 *      lines; sparse for a free line of 100 masses.
 *   5. Refusals: a sparse request with constraints, with difference
 *      quotients, or with M coupling most coordinates, each with a
 *      message saying why and what goes on instead.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"
#include "eom/model_file.h"
#include "eom_internal.h"
#include "mass_line.h"
#include "sparse_compare.h"
#include "support_rng.h"

static const char *models_dir = "models";

static eom_system *system_of(eom_model *md)
{
    eom_system *s = NULL;
    char err[512];
    int rc;
    CHECK(md != NULL);
    if (!md)
        return NULL;
    rc = eom_system_new(&s, md, err, sizeof err);
    CHECK_INT(rc, EOM_OK);
    if (rc != EOM_OK)
        fprintf(stderr, "%s\n", err);
    eom_model_free(&md);
    return s;
}

static eom_system *file_system_set(const char *file, const char *name,
                                   long value)
{
    eom_file *f = NULL;
    eom_model *md = NULL;
    char err[512], path[1024];
    snprintf(path, sizeof path, "%s/%s", models_dir, file);
    if (eom_file_read(&f, path, err, sizeof err) != EOM_OK ||
        (name && eom_file_set_setting(f, name, value, err, sizeof err) !=
                     EOM_OK) ||
        eom_file_build(f, &md, err, sizeof err) != EOM_OK) {
        CHECK_FAIL_("%s: %s", file, err);
        eom_file_free(&f);
        return NULL;
    }
    eom_file_free(&f);
    return system_of(md);
}

/* Sections 1 and 2 on s at npts random states y = (q, qd, W); blocks:
 * the number of blocks of M expected, largest their size. Returns the
 * largest relative difference of sparse and dense. */
static double compare(const char *label, eom_system *s, int npts,
                      uint64_t seed, int blocks, int largest)
{
    const int n = eom_system_ncoords(s), N = 2 * n + 1;
    double *y = malloc((size_t)N * sizeof *y);
    double *D = malloc((size_t)N * (size_t)N * sizeof *D);
    double *rowmax = malloc((size_t)N * sizeof *rowmax);
    double *data = NULL;
    sparse_diff f = {0, 0, 0.0, 0};
    char *in = calloc((size_t)N * (size_t)N, 1);
    eom_ode_pattern p;
    rng g = rng_seed(seed);
    int k, c, i;
    size_t e;
    CHECK(y && D && rowmax && in);
    CHECK_INT(eom__ode_pattern(s, &p), EOM_OK);
    CHECK_INT(p.N, N);
    CHECK_INT(p.blocks, blocks);
    CHECK_INT(p.largest_block, largest);
    if (!y || !D || !rowmax || !in || p.N != N)
        goto out;
    data = malloc((p.nnz ? p.nnz : 1) * sizeof *data);
    for (c = 0; c < N; c++) {
        CHECK(p.colptr[c] <= p.colptr[c + 1]);
        for (e = (size_t)p.colptr[c]; e < (size_t)p.colptr[c + 1]; e++) {
            CHECK(p.rowind[e] >= 0 && p.rowind[e] < N);
            if (e > (size_t)p.colptr[c])
                CHECK(p.rowind[e] > p.rowind[e - 1]);
            in[(size_t)c * N + (size_t)p.rowind[e]] = 1;
        }
        /* CVODE adds the identity in place only where the diagonal is */
        if (!in[(size_t)c * N + (size_t)c])
            CHECK_FAIL_("%s: diagonal entry %d is not in the pattern",
                        label, c);
    }
    CHECK_INT(p.colptr[N], (int64_t)p.nnz);
    for (k = 0; k < npts && data; k++) {
        eom_initial_state(s, y);
        for (i = 0; i < n; i++)
            y[i] += rng_range(&g, -0.02, 0.02);
        for (i = n; i < 2 * n; i++)
            y[i] = rng_range(&g, -1.0, 1.0);
        y[2 * n] = rng_range(&g, -2.0, 2.0);
        CHECK_INT(eom__state_jacobian(s, 0.3, y, D, N, 1), EOM_OK);
        CHECK_INT(eom__state_jacobian_sparse(s, 0.3, y, data), EOM_OK);
        sparse_compare(label, N, D, in, p.colptr, p.rowind, data, rowmax,
                       n, 2 * n, &f);
    }
    check_count_ += 2;
    printf("%-24s N %4d, %6zu entries (%.1f%%), %d blocks (largest %d), "
           "%d colours, %d reverse rows; sparse - dense <= %.1e of the "
           "row, %ld entries of X not bit for bit\n", label, N, p.nnz,
           100.0 * (double)p.nnz / ((double)N * N), p.blocks,
           p.largest_block, p.colors, p.reverse_rows, f.worst, f.inexact);
out:
    free(y);
    free(D);
    free(rowmax);
    free(data);
    free(in);
    return f.worst;
}

static void patterns(void)
{
    eom_system *s;
    s = system_of(mass_line_model(12, 0, 1));
    if (s) {
        compare("line of 12, diagonal M", s, 25, 1, 24, 1);
        eom_system_free(&s);
    }
    s = system_of(mass_line_model(20, 0, 3));
    if (s) {
        compare("line of 20, reach 3", s, 10, 2, 40, 1);
        eom_system_free(&s);
    }
    s = system_of(mass_line_blocks_model(16, 2));
    if (s) {
        compare("line of 16, 2 x 2 blocks", s, 20, 3, 16, 2);
        eom_system_free(&s);
    }
    s = system_of(mass_line_blocks_model(16, 4));
    if (s) {
        compare("line of 16, 4 x 4 blocks", s, 20, 4, 8, 4);
        eom_system_free(&s);
    }
    s = system_of(mass_line_model(40, 0, 1));
    if (s) {
        compare("line of 40, diagonal M", s, 10, 5, 80, 1);
        eom_system_free(&s);
    }
}

static int run(eom_system *s, int linsol, double t_end, double *x,
               eom_stats *st, char *msg, size_t len)
{
    eom_opts o;
    eom_integ *it = NULL;
    double W = 0.0;
    int rc;
    eom_opts_default(&o);
    o.method = EOM_BDF;
    o.rtol = 1e-8;
    o.atol = 1e-10;
    o.linear_solver = linsol;
    eom_initial_state(s, x);
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    if (rc == EOM_OK)
        rc = eom_integ_advance(it, t_end, x, &W);
    if (rc != EOM_OK && msg)
        snprintf(msg, len, "%s", it ? eom_integ_errmsg(it)
                                    : eom_system_errmsg(s));
    memset(st, 0, sizeof *st);
    if (it)
        eom_integ_stats(it, st);
    eom_integ_free(&it);
    return rc;
}

static void whole_run(const char *label, eom_system *s)
{
    const int N = 2 * eom_system_ncoords(s) + 1;
    double *xs = calloc((size_t)N, sizeof *xs);
    double *xd = calloc((size_t)N, sizeof *xd), d = 0.0;
    eom_stats ss, sd;
    char msg[1024] = "";
    int i;
    if (!xs || !xd) {
        CHECK_FAIL_("out of memory");
        free(xs);
        free(xd);
        return;
    }
    CHECK_INT(run(s, EOM_LINSOL_SPARSE, 1.0, xs, &ss, msg, sizeof msg),
              EOM_OK);
    if (msg[0])
        fprintf(stderr, "%s\n", msg);
    CHECK_INT(run(s, EOM_LINSOL_DENSE, 1.0, xd, &sd, NULL, 0), EOM_OK);
    CHECK_INT(ss.linear_solver, EOM_LINSOL_SPARSE);
    CHECK_INT(sd.linear_solver, EOM_LINSOL_DENSE);
    CHECK(ss.jac_evals > 0 && sd.jac_evals > 0);
    CHECK(ss.jac_time > 0.0 && sd.jac_time > 0.0);
    for (i = 0; i < N - 1; i++)
        d = fmax(d, fabs(xs[i] - xd[i]));
    printf("bdf 1 s, %s: sparse %ld steps %ld Jacobians, dense %ld steps "
           "%ld Jacobians; states %.1e apart\n", label, ss.steps,
           ss.jac_evals, sd.steps, sd.jac_evals, d);
    if (!(d <= 1e-7))
        CHECK_FAIL_("%s: sparse and dense runs %.3g apart", label, d);
    /* the same Newton matrix up to rounding: the same steps, nearly (a
     * wrong matrix still converges, with more and shorter steps where
     * the model is stiff) */
    if (!(labs(ss.steps - sd.steps) <= sd.steps / 10))
        CHECK_FAIL_("%s: %ld steps sparse, %ld dense", label, ss.steps,
                    sd.steps);
    free(xs);
    free(xd);
}

static void whole_runs(void)
{
    eom_system *s = system_of(mass_line_model(30, 0, 1));
    if (s) {
        whole_run("line of 30", s);
        eom_system_free(&s);
    }
    s = system_of(mass_line_blocks_model(16, 4));
    if (s) {
        whole_run("line of 16, 4 x 4 blocks", s);
        eom_system_free(&s);
    }
    /* stiff: dampers 1000 times stronger (rates decaying at ~ 2e3 / s),
     * where bdf's steps depend on its Newton matrix being right */
    s = system_of(mass_line_model(30, 0, 1));
    if (s) {
        CHECK_INT(eom_set_param(s, eom_param_index(s, "c"), 50.0), EOM_OK);
        whole_run("line of 30, stiff", s);
        eom_system_free(&s);
    }
}

/* Sensitivities (CVODES's staggered corrector with the same linear
 * solver): to the stiffness k and to x_0's initial value, over 0.2 s of
 * the free line of 20, sparse against dense. */
static void sensitivities(void)
{
    eom_system *s = system_of(mass_line_model(20, 0, 1));
    double S[2][80 * 2], x[81], W = 0.0, d = 0.0, big = 0.0;
    int which[2], k, i;
    if (!s)
        return;
    which[0] = eom_param_index(s, "k");
    which[1] = eom_system_nparams(s); /* x_0's initial value */
    for (k = 0; k < 2; k++) {
        eom_opts o;
        eom_integ *it = NULL;
        eom_stats st;
        eom_opts_default(&o);
        o.method = EOM_BDF;
        o.rtol = 1e-8;
        o.atol = 1e-10;
        o.n_sens = 2;
        o.sens = which;
        o.linear_solver = k == 0 ? EOM_LINSOL_SPARSE : EOM_LINSOL_DENSE;
        eom_initial_state(s, x);
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
        if (!it)
            continue;
        CHECK_INT(eom_integ_advance(it, 0.2, x, &W), EOM_OK);
        CHECK_INT(eom_integ_sensitivities(it, S[k]), EOM_OK);
        eom_integ_stats(it, &st);
        CHECK_INT(st.linear_solver, o.linear_solver);
        eom_integ_free(&it);
    }
    for (i = 0; i < 80 * 2; i++) {
        d = fmax(d, fabs(S[0][i] - S[1][i]));
        big = fmax(big, fabs(S[1][i]));
    }
    printf("bdf sensitivities, line of 20: sparse - dense %.1e of %.1e\n",
           d, big);
    if (!(big > 0.0 && d <= 1e-6 * big))
        CHECK_FAIL_("sensitivities: sparse and dense %.3g apart (largest "
                    "%.3g)", d, big);
    eom_system_free(&s);
}

static void automatic(void)
{
    static const char *const files[] = {
        "open-chain.eom", "closed-chain.eom", "double-pendulum.eom",
        "four-bar.eom", "driven-crank.eom", "spring-pendulum.eom",
        "cart-pole.eom"};
    eom_system *s;
    eom_stats st;
    double x[512];
    char msg[1024] = "";
    size_t k;
    int choice;
    for (k = 0; k < sizeof files / sizeof files[0]; k++) {
        s = file_system_set(files[k], NULL, 0);
        if (!s)
            continue;
        CHECK_INT(run(s, EOM_LINSOL_AUTO, 1e-3, x, &st, msg, sizeof msg),
                  EOM_OK);
        if (st.linear_solver != EOM_LINSOL_DENSE)
            CHECK_FAIL_("%s: bdf's automatic choice is %d, not dense",
                        files[k], st.linear_solver);
        if (s->ssp != NULL)
            CHECK_FAIL_("%s: the pattern was computed for %d unknowns",
                        files[k], 2 * s->n + 1);
        eom_system_free(&s);
    }
    /* a chain of 40 links: M full, dense by the fill bound */
    s = file_system_set("open-chain.eom", "links", 40);
    if (s) {
        eom_ode_pattern p;
        CHECK_INT(eom__ode_linear_solver(s, EOM_LINSOL_AUTO, 0, &choice),
                  EOM_OK);
        CHECK_INT(choice, EOM_LINSOL_DENSE);
        CHECK_INT(eom__ode_pattern(s, &p), EOM_OK);
        printf("open chain of 40 links: N %d, %zu entries (%.0f%%), "
               "largest block %d\n", p.N, p.nnz,
               100.0 * (double)p.nnz / ((double)p.N * p.N),
               p.largest_block);
        CHECK_INT(p.largest_block, s->n);
        eom_system_free(&s);
    }
    /* constraints: dense, the pattern never asked for */
    s = file_system_set("closed-chain.eom", "links", 30);
    if (s) {
        CHECK_INT(eom__ode_linear_solver(s, EOM_LINSOL_AUTO, 0, &choice),
                  EOM_OK);
        CHECK_INT(choice, EOM_LINSOL_DENSE);
        CHECK(s->ssp == NULL);
        eom_system_free(&s);
    }
    s = system_of(mass_line_model(100, 1, 1));
    if (s) {
        CHECK_INT(run(s, EOM_LINSOL_AUTO, 1e-3, x, &st, msg, sizeof msg),
                  EOM_OK);
        CHECK_INT(st.linear_solver, EOM_LINSOL_DENSE);
        eom_system_free(&s);
    }
    s = system_of(mass_line_model(100, 0, 1));
    if (s) {
        CHECK_INT(eom__ode_linear_solver(s, EOM_LINSOL_AUTO, 0, &choice),
                  EOM_OK);
        CHECK_INT(choice, EOM_LINSOL_SPARSE);
        CHECK_INT(eom__ode_linear_solver(s, EOM_LINSOL_AUTO, 1, &choice),
                  EOM_OK);
        CHECK_INT(choice, EOM_LINSOL_DENSE);
        CHECK_INT(run(s, EOM_LINSOL_AUTO, 1e-3, x, &st, msg, sizeof msg),
                  EOM_OK);
        CHECK_INT(st.linear_solver, EOM_LINSOL_SPARSE);
        eom_system_free(&s);
    }
}

/* bdf with a sparse request on s: refused, the message holding want. */
static void refused(eom_system *s, int dq, const char *want)
{
    eom_integ *it = NULL;
    eom_opts o;
    double x[512];
    eom_opts_default(&o);
    o.method = EOM_BDF;
    o.linear_solver = EOM_LINSOL_SPARSE;
    o.dq_jacobian = dq;
    eom_initial_state(s, x);
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
    CHECK(it == NULL);
    if (!strstr(eom_system_errmsg(s), want))
        CHECK_FAIL_("message \"%s\" lacks \"%s\"", eom_system_errmsg(s),
                    want);
    eom_integ_free(&it);
}

static void bad_input(void)
{
    eom_system *s = system_of(mass_line_model(8, 1, 1));
    if (s) {
        refused(s, 0, "dense with constraints");
        refused(s, 0, "or ida");
        eom_system_free(&s);
    }
    s = system_of(mass_line_model(8, 0, 1));
    if (s) {
        refused(s, 1, "exact Jacobian");
        eom_system_free(&s);
    }
    s = file_system_set("open-chain.eom", NULL, 0);
    if (s) {
        refused(s, 0, "mass matrix couples");
        refused(s, 0, "dense linear solver");
        eom_system_free(&s);
    }
}

int main(int argc, char **argv)
{
    if (argc > 1)
        models_dir = argv[1];
    patterns();
    whole_runs();
    sensitivities();
    automatic();
    bad_input();
    CHECK_DONE();
}
