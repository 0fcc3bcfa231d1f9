/* test_model_tuples.c - model files on one embedded-tuple context, one
 * after another, as a user comparing models would run them. The tuple
 * evaluator reuses storage by the previous run's plan; a model that reads
 * a value the previous model let go makes it repeat the run (tp_tuple_new),
 * and the repeated run must record the file's definitions again rather
 * than reuse the first attempt's handles. Every run's L, dL/dq, M and h
 * are compared bit for bit with a fresh context's.
 */
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom/model_file.h"

/* The same definitions and energies up to V; B adds terms that read s
 * and x after A's last use of them. */
#define COMMON                                                             \
    "units off\n"                                                          \
    "param m = 1.5\n"                                                      \
    "param k = 3\n"                                                        \
    "coord x = 0.1\n"                                                      \
    "coord y = 0.2\n"                                                      \
    "s = sin(x)\n"                                                         \
    "c = cos(y)\n"                                                         \
    "T = 1/2*m*(x_dot^2 + y_dot^2) + s*c*x_dot*y_dot\n"
static const char *model_a = COMMON "V = 1/2*k*(x^2 + y^2) + s*y\n";
static const char *model_b =
    COMMON "V = 1/2*k*(x^2 + y^2) + s*y + s*s*x*c\n";

static void compare(eom_model *m, tp_rec *R, const double *x,
                    const char *what)
{
    double L[2], g[2][2], M[2][4], h[2][2];
    tp_rec *F = NULL;
    int k;
    CHECK_INT(tp_tuple_new(&F, 4, NULL), TP_OK);
    CHECK_INT(eom_model_run_lagrangian(m, R, x), EOM_OK);
    CHECK_INT(tp_tuple_lagrange(R, 0, &L[0], g[0], M[0], h[0]), TP_OK);
    CHECK_INT(eom_model_run_lagrangian(m, F, x), EOM_OK);
    CHECK_INT(tp_tuple_lagrange(F, 0, &L[1], g[1], M[1], h[1]), TP_OK);
    k = L[0] == L[1] && !memcmp(g[0], g[1], sizeof g[0]) &&
        !memcmp(M[0], M[1], sizeof M[0]) && !memcmp(h[0], h[1], sizeof h[0]);
    if (!k)
        fprintf(stderr, "%s: L %.17g against %.17g, M00 %.17g against "
                        "%.17g\n", what, L[0], L[1], M[0][0], M[1][0]);
    CHECK(k);
    tp_rec_free(&F);
}

int main(void)
{
    eom_model *a = NULL, *b = NULL;
    tp_rec *R = NULL;
    char err[512];
    double x[4] = {0.3, -0.4, 0.7, 1.1};
    int k;
    CHECK_INT(eom_model_from_string(&a, model_a, err, sizeof err), EOM_OK);
    CHECK_INT(eom_model_from_string(&b, model_b, err, sizeof err), EOM_OK);
    CHECK_INT(tp_tuple_new(&R, 4, NULL), TP_OK);
    for (k = 0; k < 3; k++) {
        x[0] = 0.3 + 0.1 * k;
        compare(a, R, x, "model A");
        compare(a, R, x, "model A again");
        compare(b, R, x, "model B after A");
        compare(b, R, x, "model B again");
    }
    tp_rec_free(&R);
    eom_model_free(&a);
    eom_model_free(&b);
    CHECK_DONE();
}
