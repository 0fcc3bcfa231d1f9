/* test_model_large.c - models with very many names build in time linear
 * in them (names are hashed and the CSV's columns checked for duplicates
 * sorted, a tape's parameters searched by bisection): 100,000 probes,
 * 100,000 parameters, and thousands of parameters and outputs, with the
 * duplicates among them still found; and a model whose workspace would
 * exceed the machine's memory refused before it is allocated. The bound is the test's timeout
 * (60 s; the quadratic checks took about 2 minutes for the probes), never
 * a timed assertion.
 *
 * usage: test_model_large MODELS_DIR */
#define _DEFAULT_SOURCE /* _SC_PHYS_PAGES */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "eom/model_file.h"
#include "eom/run.h"

/* A recorder's names past the length where they are hashed: a second
 * output of one name and a parameter declared again with another default
 * are refused, one with the same default gives the same value. */
static int many_names(tp_rec *r, void *user)
{
    char name[32];
    tp_val x = tp_indep(r, 0), p0 = tp_param(r, "p0", 1.0), again;
    int k;
    (void)user;
    for (k = 1; k < 3000; k++) {
        snprintf(name, sizeof name, "p%d", k);
        x = tp_add(r, x, tp_param(r, name, (double)k));
    }
    again = tp_param(r, "p1717", 1717.0);
    CHECK(tp_rec_status(r) == TP_OK);
    (void)again;
    (void)p0;
    for (k = 0; k < 3000; k++) {
        snprintf(name, sizeof name, "y%d", k);
        tp_output(r, name, x);
    }
    CHECK(tp_rec_status(r) == TP_OK);
    tp_output(r, "y2999", x);
    CHECK_INT(tp_rec_status(r), TP_ERR_NAME);
    return 0;
}

static int param_again(tp_rec *r, void *user)
{
    char name[32];
    tp_val x = tp_indep(r, 0);
    int k;
    (void)user;
    for (k = 0; k < 100; k++) {
        snprintf(name, sizeof name, "q%d", k);
        x = tp_add(r, x, tp_param(r, name, 1.0));
    }
    tp_param(r, "q77", 2.0);
    CHECK_INT(tp_rec_status(r), TP_ERR_NAME);
    return tp_output(r, "y", x) == TP_OK ? 0 : 1;
}

static void recorder_names(void)
{
    tp_rec *r = NULL;
    int run;
    /* the evaluator runs twice: the index starts again with each run */
    CHECK_INT(tp_evaluator_new(&r, 1, NULL), TP_OK);
    for (run = 0; run < 2; run++) {
        const double x = 0.5;
        tp_rec_run(r, &x, many_names, NULL);
    }
    tp_rec_free(&r);
    CHECK_INT(tp_recorder_new(&r, 1, NULL, NULL), TP_OK);
    tp_rec_run(r, NULL, param_again, NULL);
    tp_rec_free(&r);
}

static void many_probes(void)
{
    const int n = 100000;
    char *text = malloc(256), err[2048];
    eom_model *m = NULL;
    eom_system *s = NULL;
    eom_run_columns *c = NULL;
    snprintf(text, 256, "units off\nparam m = 1\ncoord x = 0.5\n"
                        "T = 1/2*m*x_dot^2\nprobe p[j in 1..%d] = j*x\n", n);
    if (eom_model_from_string(&m, text, err, sizeof err) != EOM_OK ||
        eom_system_new(&s, m, err, sizeof err) != EOM_OK) {
        CHECK_FAIL_("%s", err);
    } else {
        double xs[2] = {0.5, 0.0}, *p = malloc((size_t)n * sizeof *p);
        CHECK_INT(eom_system_nprobes(s), n);
        CHECK_INT(eom_probes_at(s, xs, p), EOM_OK);
        CHECK(p[n - 1] == n * 0.5);
        free(p);
        CHECK_INT(eom_run_columns_new(&c, s, 0, err, sizeof err), 0);
        eom_run_columns_free(&c);
    }
    eom_system_free(&s);
    eom_model_free(&m);
    free(text);
}

/* 100,000 parameters (the most a model file may declare): each tape's parameters found by name in log time
 * (with a scan of them all, binding them to the tapes and the residual
 * tape took 7.5 s for 30,000 and would take minutes here). The last one
 * set through the API reaches the energy and the exact Jacobian:
 * V = x^2/2 (N - 1 + 3), d(qdd)/dq = -(N + 2) / m. */
static void many_params(void)
{
    const int n = 99999; /* with m, the language's limit of 100,000 */
    char *text = malloc(256), err[2048];
    eom_model *m = NULL;
    eom_system *s = NULL;
    snprintf(text, 256, "units off\nparam m = 1\nparam k[j in 1..%d] = 1\n"
                        "coord x = 0.5\nT = 1/2*m*x_dot^2\n"
                        "V = sum(j in 1..%d, 1/2*k[j]*x^2)\n", n, n);
    if (eom_model_from_string(&m, text, err, sizeof err) != EOM_OK ||
        eom_system_new(&s, m, err, sizeof err) != EOM_OK) {
        CHECK_FAIL_("%s", err);
    } else {
        const double xs[2] = {0.5, 0.0};
        double A[4];
        eom_energy e;
        const int last = eom_system_nparams(s) - 1;
        CHECK_INT(eom_system_nparams(s), n + 1);
        CHECK_INT(eom_param_index(s, eom_param_name(s, last)), last);
        CHECK_INT(eom_set_param(s, last, 3.0), EOM_OK);
        CHECK_INT(eom_energy_at(s, 0.0, xs, &e), EOM_OK);
        CHECK_NEAR(e.V, 0.5 * 0.25 * (n + 2), 1e-12);
        CHECK_INT(eom_state_jacobian(s, 0.0, xs, A), EOM_OK);
        CHECK_NEAR(A[2], -(double)(n + 2), 1e-12);
    }
    eom_system_free(&s);
    eom_model_free(&m);
    free(text);
}

/* A probe named like a coordinate, among thousands: found. */
static void duplicate_among_many(void)
{
    eom_model *m = NULL;
    char name[32];
    int k;
    CHECK_INT(eom_model_new(&m), EOM_OK);
    for (k = 0; k < 5000; k++) {
        snprintf(name, sizeof name, "q%d", k);
        CHECK(eom_model_add_coord(m, name, NULL, 0.0, 0.0) == k);
    }
    CHECK(eom_model_add_param(m, "q4321", NULL, 1.0, NULL) ==
          EOM_ERR_NAME);
    CHECK(strstr(eom_model_errmsg(m), "q4321") != NULL);
    eom_model_free(&m);
}

/* The shipped closed chain at 1000 links of 20 modes, within its
 * settings' ranges: 21000 coordinates, whose Lagrangian workspace (two
 * arrays of operations x 21000 directions of doubles, 48.7 GB each) no
 * machine here holds. eom_system_new refuses it before allocating, with
 * the size and the memory there is. Skipped on a machine of more than
 * 200 GB. */
static void too_big(const char *models_dir)
{
    char path[4096], err[2048];
    eom_file *f = NULL;
    eom_model *m = NULL;
    eom_system *s = NULL;
    const double mem = (double)sysconf(_SC_PHYS_PAGES) *
                       (double)sysconf(_SC_PAGESIZE);
    const char *need;
    if (mem > 200e9) {
        printf("too_big skipped: this machine has %.0f GB\n", mem * 1e-9);
        return;
    }
    snprintf(path, sizeof path, "%s/closed-chain.eom", models_dir);
    CHECK_INT(eom_file_read(&f, path, err, sizeof err), EOM_OK);
    if (!f)
        return;
    CHECK_INT(eom_file_set_setting(f, "links", 1000, err, sizeof err),
              EOM_OK);
    CHECK_INT(eom_file_set_setting(f, "modes", 20, err, sizeof err), EOM_OK);
    CHECK_INT(eom_file_build(f, &m, err, sizeof err), EOM_OK);
    if (m) {
        CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_ERR_NOMEM);
        CHECK(s == NULL);
        need = strstr(err, "would need ");
        CHECK(need != NULL);
        /* at least the two 48.7 GB arrays, in GB */
        CHECK(need && strtod(need + strlen("would need "), NULL) >= 97.4);
        CHECK(strstr(err, "21000 coordinates") != NULL);
        CHECK(strstr(err, "GB of memory") != NULL);
    }
    eom_system_free(&s);
    eom_model_free(&m);
    eom_file_free(&f);
}

int main(int argc, char **argv)
{
    recorder_names();
    many_probes();
    many_params();
    duplicate_among_many();
    if (argc > 1)
        too_big(argv[1]);
    else
        CHECK_FAIL_("usage: test_model_large MODELS_DIR");
    CHECK_DONE();
}
