/* test_tuple_reuse.c - the tuple evaluator reuses storage from one run to
 * the next (its plan, see libtape/src/tuple.c); no sequence of runs may
 * change a result.
 *
 *   1. one function run many times equals a fresh context's single run,
 *      bit for bit, and the function is called once per run;
 *   2. a function that takes another path when x changes, reading late a
 *      value the previous run's plan had let go: the run is repeated
 *      (the function called twice) and its results are a fresh context's;
 *      the next run with the same path calls it once;
 *   3. the same ops, but an output that the previous run did not keep:
 *      repeated, right results;
 *   4. ops added at the end and taken away again, values never read,
 *      constants where there were values: right results, no repeat;
 *   5. a failing run (an error in the function) leaves nothing behind.
 *   6. parameters declared in another order, fewer, twice, or again with
 *      another default in later runs of one evaluator (plain and tuple):
 *      the same parameter for the same name, the error for the changed
 *      default, whatever the names kept from earlier runs.
 * Values are compared with tp_tuple_output of a context made for the
 * comparison and run once, so every check is against a run that had no
 * plan to follow.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "tape/tape.h"

#define NI 3
#define NH (NI * (NI + 1) / 2)

/* path: which function the run records; calls counts the calls */
typedef struct fn_arg {
    int path;
    int calls;
} fn_arg;

/* A chain of products and sines whose intermediate s is read late only
 * on path 1, and whose output on path 2 is an intermediate (b) that
 * paths 0 and 1 let go early. Path 3 records path 0, then more ops whose
 * results nothing reads (they read only e, which the plan keeps to the
 * end). Path 4 records a constant where path 0 has a value (c). Path 5
 * fails. */
static int fn(tp_rec *R, void *user)
{
    fn_arg *a = user;
    tp_val x = tp_indep(R, 0), y = tp_indep(R, 1), z = tp_indep(R, 2);
    tp_val s = tp_sin(R, x), b = tp_mul(R, s, y);
    tp_val c = a->path == 4 ? tp_const(R, 0.25) : tp_mul(R, b, z);
    tp_val d = tp_add(R, tp_cos(R, c), tp_mul(R, z, z));
    tp_val e = tp_mul(R, d, tp_exp(R, tp_mulc(R, y, 0.5)));
    a->calls++;
    if (a->path == 1)
        e = tp_add(R, e, tp_mul(R, s, s)); /* s read after its last use */
    if (a->path == 3) {
        int k;
        for (k = 0; k < 6; k++)
            (void)tp_mul(R, tp_sin(R, e), tp_addc(R, e, 1.0));
    }
    if (a->path == 5)
        return 7;
    tp_output(R, "e", e);
    if (a->path == 2)
        tp_output(R, "b", b);
    return 0;
}

/* Run path on R at x and compare every output (value, gradient, packed
 * Hessian) with a fresh context's, bit for bit; calls is how many times
 * the function must have been called. */
static void run_and_compare(tp_rec *R, int path, const double *x, int calls,
                            const char *what)
{
    fn_arg a = {path, 0}, b = {path, 0};
    tp_rec *F = NULL;
    int o, m;
    CHECK_INT(tp_rec_run(R, x, fn, &a), TP_OK);
    CHECK_INT(tp_tuple_new(&F, NI, NULL), TP_OK);
    CHECK_INT(tp_rec_run(F, x, fn, &b), TP_OK);
    if (a.calls != calls)
        fprintf(stderr, "%s: the function was called %d times\n", what,
                a.calls);
    CHECK_INT(a.calls, calls);
    m = tp_rec_n_outputs(F);
    CHECK_INT(tp_rec_n_outputs(R), m);
    for (o = 0; o < m; o++) {
        double v1, v2, g1[NI], g2[NI], H1[NH], H2[NH];
        CHECK_INT(tp_rec_output_value(R, o, &v1), TP_OK);
        CHECK_INT(tp_rec_output_value(F, o, &v2), TP_OK);
        CHECK_INT(tp_tuple_output(R, o, g1, H1), TP_OK);
        CHECK_INT(tp_tuple_output(F, o, g2, H2), TP_OK);
        if (v1 != v2 || memcmp(g1, g2, sizeof g1) || memcmp(H1, H2, sizeof H1))
            fprintf(stderr, "%s: output %d differs from a fresh run\n", what,
                    o);
        CHECK(v1 == v2);
        CHECK(memcmp(g1, g2, sizeof g1) == 0);
        CHECK(memcmp(H1, H2, sizeof H1) == 0);
    }
    tp_rec_free(&F);
}

/* Declares one parameter per letter of *user: the name in lower case,
 * default 1 (2 for an upper-case letter); output "s" their sum. */
static int rec_params(tp_rec *R, void *user)
{
    const char *seq = *(const char **)user;
    tp_val s = tp_const(R, 0.0);
    for (; *seq; seq++) {
        const char name[2] = {(char)(*seq | 0x20), '\0'};
        s = tp_add(R, s, tp_param(R, name, *seq & 0x20 ? 1.0 : 2.0));
    }
    tp_output(R, "s", s);
    return 0;
}

/* Runs of rec_params on one evaluator: each sequence's status and sum. */
static void params_across_runs(tp_rec *R)
{
    static const struct {
        const char *seq;
        int status;
        double sum;
    } runs[] = {
        {"ab", TP_OK, 2.0},  {"bB", TP_ERR_NAME, 0.0},
        {"ab", TP_OK, 2.0},  {"b", TP_OK, 1.0},
        {"bb", TP_OK, 2.0},  /* the kept names are now b, b */
        {"bB", TP_ERR_NAME, 0.0}, {"ba", TP_OK, 2.0},
        {"ab", TP_OK, 2.0},  {"abB", TP_ERR_NAME, 0.0},
        {"aab", TP_OK, 3.0}, {"c", TP_OK, 1.0},
        {"cC", TP_ERR_NAME, 0.0}, {"abc", TP_OK, 3.0},
        {"abcA", TP_ERR_NAME, 0.0},
    };
    const double x[NI] = {0.1, 0.2, 0.3};
    size_t k;
    for (k = 0; k < sizeof runs / sizeof runs[0]; k++) {
        double y = -1.0;
        const char *seq = runs[k].seq;
        const int st = tp_rec_run(R, x, rec_params, &seq);
        CHECK_INT(st, runs[k].status);
        if (st == TP_OK) {
            CHECK_INT(tp_rec_output_value(R, 0, &y), TP_OK);
            CHECK_NEAR(y, runs[k].sum, 0.0);
        }
        if (st != runs[k].status)
            fprintf(stderr, "  (parameters %s)\n", runs[k].seq);
    }
}

int main(void)
{
    tp_rec *R = NULL;
    double x[NI] = {0.3, -1.1, 0.7};
    fn_arg a = {5, 0};
    int k;

    CHECK_INT(tp_tuple_new(&R, NI, NULL), TP_OK);
    /* 1. the same ops at new points */
    for (k = 0; k < 5; k++) {
        x[0] = 0.3 + 0.2 * k;
        x[2] = 0.7 - 0.1 * k;
        run_and_compare(R, 0, x, 1, "same ops");
    }
    /* 2. another path: s read after its planned last use */
    run_and_compare(R, 1, x, 2, "late read");
    run_and_compare(R, 1, x, 1, "late read, planned");
    run_and_compare(R, 0, x, 1, "back to path 0");
    /* 3. an output the plan let go */
    run_and_compare(R, 2, x, 2, "new output");
    run_and_compare(R, 2, x, 1, "new output, planned");
    run_and_compare(R, 0, x, 1, "output dropped");
    /* 4. ops added at the end, dropped; a constant for a value */
    run_and_compare(R, 3, x, 1, "ops added");
    run_and_compare(R, 0, x, 1, "ops dropped");
    run_and_compare(R, 4, x, 1, "constant for a value");
    run_and_compare(R, 0, x, 1, "value for a constant");
    /* 5. a failed run, then the plan's path again */
    CHECK_INT(tp_rec_run(R, x, fn, &a), TP_ERR_USER);
    CHECK_INT(a.calls, 1);
    run_and_compare(R, 0, x, 1, "after a failed run");
    run_and_compare(R, 1, x, 2, "late read after a failed run");
    /* 6. parameters from run to run */
    params_across_runs(R);
    tp_rec_free(&R);
    CHECK_INT(tp_evaluator_new(&R, NI, NULL), TP_OK);
    params_across_runs(R);
    tp_rec_free(&R);
    CHECK_DONE();
}
