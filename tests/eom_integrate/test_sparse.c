/* test_sparse.c - IDA's sparse iteration matrix (jacobian_sparse.c) and
 * the choice between it and the dense one (eom_opts.linear_solver).
 *
 *   1. The pattern (from the residual tape's structure) holds every
 *      entry of the dense matrix (eom__dae_jacobian) that is nonzero at
 *      many random states, rates, multipliers and cj, on the line of
 *      masses with and without constraints, and on the shipped models
 *      with constraints (closed chain, four-bar, driven crank).
 *   2. The sparse values equal the dense ones entry by entry, to 1e-14
 *      of the entry (with a floor of 1e-14 of its row's largest), the
 *      constraint rows and the W row included, with and without
 *      Baumgarte terms.
 *   3. Whole runs: ida sparse and dense end 1 s of the constrained line
 *      of 30 masses within 1e-7 of each other, and eom_stats says which
 *      solver each used.
 *   4. The automatic choice: dense for the shipped models as shipped
 *      (below the size bound) and as chains of 30 and 40 links (full M:
 *      above the fill bound), sparse for a line of 100 masses.
 *   5. Bad input: a sparse request to esdirk, adams or rk4, with
 *      difference quotients, or out of range, is refused with a message.
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

static eom_system *file_system(const char *file)
{
    eom_model *md = NULL;
    char err[512], path[1024];
    snprintf(path, sizeof path, "%s/%s", models_dir, file);
    if (eom_model_from_file(&md, path, err, sizeof err) != EOM_OK) {
        CHECK_FAIL_("%s: %s", file, err);
        return NULL;
    }
    return system_of(md);
}

/* A random (Y, Yp, cj) around the initial state: Y = (q, v, lambda, W). */
static void random_point(eom_system *s, rng *g, double *Y, double *Yp,
                         double *cj)
{
    const int n = eom_system_ncoords(s), m = eom_system_nconstraints(s);
    const int NY = 2 * n + m + 1;
    int i;
    eom_initial_state(s, Y);
    for (i = 0; i < n; i++)
        Y[i] += rng_range(g, -0.02, 0.02);
    for (i = n; i < 2 * n; i++)
        Y[i] = rng_range(g, -1.0, 1.0);
    for (i = 2 * n; i < NY; i++)
        Y[i] = rng_range(g, -2.0, 2.0);
    for (i = 0; i < NY; i++)
        Yp[i] = rng_range(g, -3.0, 3.0);
    *cj = pow(10.0, rng_range(g, -1.0, 5.0));
}

/* Sections 1 and 2 on s at npts random points: returns the largest
 * relative difference of sparse and dense. */
static double compare(const char *label, eom_system *s, int npts,
                      uint64_t seed)
{
    const int n = eom_system_ncoords(s), m = eom_system_nconstraints(s);
    const int NY = 2 * n + m + 1;
    double *Y = malloc((size_t)NY * sizeof *Y);
    double *Yp = malloc((size_t)NY * sizeof *Yp);
    double *D = malloc((size_t)NY * (size_t)NY * sizeof *D);
    double *rowmax = malloc((size_t)NY * sizeof *rowmax);
    double *data = NULL, cj;
    sparse_diff f = {0, 0, 0.0, 0};
    char *in = calloc((size_t)NY * (size_t)NY, 1);
    eom_dae_pattern p;
    rng g = rng_seed(seed);
    int k, c;
    size_t e;
    CHECK(Y && Yp && D && rowmax && in);
    CHECK_INT(eom__dae_pattern(s, &p), EOM_OK);
    CHECK_INT(p.NY, NY);
    if (!Y || !Yp || !D || !rowmax || !in || p.NY != NY)
        goto out;
    data = malloc((p.nnz ? p.nnz : 1) * sizeof *data);
    for (c = 0; c < NY; c++) {
        CHECK(p.colptr[c] <= p.colptr[c + 1]);
        for (e = (size_t)p.colptr[c]; e < (size_t)p.colptr[c + 1]; e++) {
            CHECK(p.rowind[e] >= 0 && p.rowind[e] < NY);
            if (e > (size_t)p.colptr[c])
                CHECK(p.rowind[e] > p.rowind[e - 1]);
            in[(size_t)c * NY + (size_t)p.rowind[e]] = 1;
        }
    }
    CHECK_INT(p.colptr[NY], (int64_t)p.nnz);
    for (k = 0; k < npts && data; k++) {
        random_point(s, &g, Y, Yp, &cj);
        CHECK_INT(eom__dae_jacobian(s, 0.3, Y, Yp, cj, D, NY), EOM_OK);
        CHECK_INT(eom__dae_jacobian_sparse(s, 0.3, Y, Yp, cj, data),
                  EOM_OK);
        sparse_compare(label, NY, D, in, p.colptr, p.rowind, data, rowmax,
                       0, 0, &f);
    }
    check_count_ += 2;
    printf("%-22s NY %4d, %6zu entries (%.1f%%), %d colours, %d reverse "
           "rows; sparse - dense <= %.1e of the row\n", label, NY, p.nnz,
           100.0 * (double)p.nnz / ((double)NY * NY), p.colors,
           p.reverse_rows, f.worst);
out:
    free(Y);
    free(Yp);
    free(D);
    free(rowmax);
    free(data);
    free(in);
    return f.worst;
}

static void patterns(void)
{
    static const char *const files[] = {"closed-chain.eom", "four-bar.eom",
                                        "driven-crank.eom",
                                        "double-pendulum.eom"};
    eom_system *s;
    size_t k;
    s = system_of(mass_line_model(12, 1, 1));
    if (s) {
        compare("line of 12, 4 constraints", s, 25, 1);
        CHECK_INT(eom_set_baumgarte(s, 3.0, 5.0), EOM_OK);
        compare("  with Baumgarte", s, 25, 2);
        eom_system_free(&s);
    }
    s = system_of(mass_line_model(20, 1, 3));
    if (s) {
        compare("line of 20, reach 3", s, 10, 4);
        eom_system_free(&s);
    }
    s = system_of(mass_line_model(40, 0, 1));
    if (s) {
        compare("line of 40, free", s, 10, 3);
        eom_system_free(&s);
    }
    for (k = 0; k < sizeof files / sizeof files[0]; k++) {
        s = file_system(files[k]);
        if (s) {
            compare(files[k], s, 20, 10 + k);
            eom_system_free(&s);
        }
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
    o.method = EOM_IDA;
    o.rtol = 1e-8;
    o.atol = 1e-10;
    o.linear_solver = linsol;
    eom_initial_state(s, x);
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    if (rc == EOM_OK)
        rc = eom_integ_advance(it, t_end, x, &W);
    if (rc != EOM_OK && msg)
        snprintf(msg, len, "%s", it ? eom_integ_errmsg(it) : "");
    memset(st, 0, sizeof *st);
    if (it)
        eom_integ_stats(it, st);
    eom_integ_free(&it);
    return rc;
}

static void whole_runs(void)
{
    eom_system *s = system_of(mass_line_model(30, 1, 1));
    double xs[128], xd[128], d = 0.0;
    eom_stats ss, sd;
    char msg[1024] = "";
    int i;
    if (!s)
        return;
    CHECK_INT(run(s, EOM_LINSOL_SPARSE, 1.0, xs, &ss, msg, sizeof msg),
              EOM_OK);
    if (msg[0])
        fprintf(stderr, "%s\n", msg);
    CHECK_INT(run(s, EOM_LINSOL_DENSE, 1.0, xd, &sd, NULL, 0), EOM_OK);
    CHECK_INT(ss.linear_solver, EOM_LINSOL_SPARSE);
    CHECK_INT(sd.linear_solver, EOM_LINSOL_DENSE);
    CHECK(ss.jac_evals > 0 && sd.jac_evals > 0);
    CHECK(ss.jac_time > 0.0 && sd.jac_time > 0.0);
    for (i = 0; i < 120; i++)
        d = fmax(d, fabs(xs[i] - xd[i]));
    printf("ida 1 s, line of 30: sparse %ld steps %ld Jacobians, dense %ld "
           "steps %ld Jacobians; states %.1e apart\n", ss.steps,
           ss.jac_evals, sd.steps, sd.jac_evals, d);
    if (!(d <= 1e-7))
        CHECK_FAIL_("sparse and dense runs %.3g apart", d);
    eom_system_free(&s);
}

/* A shipped model file with its structural setting name = value. */
static eom_system *file_system_set(const char *file, const char *name,
                                   long value)
{
    eom_file *f = NULL;
    eom_model *md = NULL;
    char err[512], path[1024];
    snprintf(path, sizeof path, "%s/%s", models_dir, file);
    if (eom_file_read(&f, path, err, sizeof err) != EOM_OK ||
        eom_file_set_setting(f, name, value, err, sizeof err) != EOM_OK ||
        eom_file_build(f, &md, err, sizeof err) != EOM_OK) {
        CHECK_FAIL_("%s with %s = %ld: %s", file, name, value, err);
        eom_file_free(&f);
        return NULL;
    }
    eom_file_free(&f);
    return system_of(md);
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
        s = file_system(files[k]);
        if (!s)
            continue;
        CHECK_INT(run(s, EOM_LINSOL_AUTO, 1e-3, x, &st, msg, sizeof msg),
                  EOM_OK);
        if (st.linear_solver != EOM_LINSOL_DENSE)
            CHECK_FAIL_("%s: the automatic choice is %d, not dense",
                        files[k], st.linear_solver);
        /* below the size bound the pattern is not even computed */
        if (s->jsp != NULL)
            CHECK_FAIL_("%s: the pattern was computed for %d unknowns",
                        files[k], 2 * s->n + s->m + 1);
        eom_system_free(&s);
    }
    /* chains of many links, large enough for the size bound: their mass
     * matrix is full, the iteration matrix dense by the fill bound */
    s = file_system_set("open-chain.eom", "links", 40);
    if (s) {
        long entries = 0;
        int unknowns = 0;
        CHECK_INT(eom_dae_pattern_size(s, &unknowns, &entries, NULL),
                  EOM_OK);
        printf("open chain of 40 links: %d unknowns, %ld entries "
               "(%.0f%%)\n", unknowns, entries,
               100.0 * (double)entries / ((double)unknowns * unknowns));
        CHECK(unknowns >= 100);
        CHECK_INT(eom__dae_linear_solver(s, EOM_LINSOL_AUTO, 0, &choice),
                  EOM_OK);
        CHECK_INT(choice, EOM_LINSOL_DENSE);
        eom_system_free(&s);
    }
    s = file_system_set("closed-chain.eom", "links", 30);
    if (s) {
        CHECK_INT(eom__dae_linear_solver(s, EOM_LINSOL_AUTO, 0, &choice),
                  EOM_OK);
        CHECK_INT(choice, EOM_LINSOL_DENSE);
        eom_system_free(&s);
    }
    s = system_of(mass_line_model(100, 1, 1));
    if (s) {
        CHECK_INT(eom__dae_linear_solver(s, EOM_LINSOL_AUTO, 0, &choice),
                  EOM_OK);
        CHECK_INT(choice, EOM_LINSOL_SPARSE);
        /* difference quotients: dense whatever the pattern */
        CHECK_INT(eom__dae_linear_solver(s, EOM_LINSOL_AUTO, 1, &choice),
                  EOM_OK);
        CHECK_INT(choice, EOM_LINSOL_DENSE);
        CHECK_INT(run(s, EOM_LINSOL_AUTO, 1e-3, x, &st, msg, sizeof msg),
                  EOM_OK);
        CHECK_INT(st.linear_solver, EOM_LINSOL_SPARSE);
        eom_system_free(&s);
    }
    /* rk4 has no linear solver; bdf is dense on a small model */
    s = file_system("double-pendulum.eom");
    if (s) {
        eom_opts o;
        eom_integ *it = NULL;
        eom_opts_default(&o);
        eom_initial_state(s, x);
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
        eom_integ_stats(it, &st);
        CHECK_INT(st.linear_solver, 0);
        eom_integ_free(&it);
        o.method = EOM_BDF;
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_OK);
        eom_integ_stats(it, &st);
        CHECK_INT(st.linear_solver, EOM_LINSOL_DENSE);
        eom_integ_free(&it);
        eom_system_free(&s);
    }
}

static void bad_input(void)
{
    /* bdf's sparse path and its refusals: test_sparse_bdf.c */
    static const eom_method refuse[] = {EOM_ESDIRK, EOM_ADAMS, EOM_RK4};
    eom_system *s = system_of(mass_line_model(8, 1, 1));
    eom_integ *it = NULL;
    eom_opts o;
    double x[64];
    char err[512];
    size_t k;
    if (!s)
        return;
    eom_initial_state(s, x);
    for (k = 0; k < sizeof refuse / sizeof refuse[0]; k++) {
        eom_opts_default(&o);
        o.method = refuse[k];
        o.linear_solver = EOM_LINSOL_SPARSE;
        CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
        snprintf(err, sizeof err, "%s", eom_system_errmsg(s));
        if (!strstr(err, "only ida and bdf"))
            CHECK_FAIL_("%s: message \"%s\"", eom_method_name(refuse[k]),
                        err);
        CHECK(it == NULL);
    }
    eom_opts_default(&o);
    o.method = EOM_IDA;
    o.linear_solver = EOM_LINSOL_SPARSE;
    o.dq_jacobian = 1;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(s), "exact Jacobian") != NULL);
    o.dq_jacobian = 0;
    o.linear_solver = 3;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
    CHECK(strstr(eom_system_errmsg(s), "linear_solver 3") != NULL);
    o.linear_solver = -1;
    CHECK_INT(eom_integ_new(&it, s, &o, 0.0, x), EOM_ERR_ARG);
    eom_system_free(&s);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        models_dir = argv[1];
    patterns();
    whole_runs();
    automatic();
    bad_input();
    CHECK_DONE();
}
