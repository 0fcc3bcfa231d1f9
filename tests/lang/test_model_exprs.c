/* test_model_exprs.c - every operator and function of the language, with
 * constants on either side, precedence and associativity, sums, if(),
 * comparisons and recurrences: each expression becomes a probe of a small
 * model, and its value at a state is compared with the same expression
 * written in C. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/model_file.h"

#define X 0.7
#define Y -1.3
#define A 2.5 /* parameter a */
#define N 4   /* setting n */

typedef struct expr_case {
    const char *text;
    double value;
} expr_case;

static double fact_sum(void)
{
    /* f[0] = 1, f[j] = j f[j-1] x; sum j = 1..n of f[j] */
    double f = 1.0, s = 0.0;
    int j;
    for (j = 1; j <= N; j++) {
        f = j * f * X;
        s += f;
    }
    return s;
}

int main(void)
{
    const expr_case cases[] = {
        {"x + y", X + Y},
        {"2 + x", 2 + X},
        {"x + 2", X + 2},
        {"x - y", X - Y},
        {"2 - x", 2 - X},
        {"x - 2", X - 2},
        {"0 - x", -X},
        {"x*y", X * Y},
        {"3*x", 3 * X},
        {"x*3", X * 3},
        {"x/y", X / Y},
        {"3/x", 3 / X},
        {"x/3", X / 3},
        {"x^2", X * X},
        {"x^3", X * X * X},
        {"x^-2", 1 / (X * X)},
        {"x^0.5", sqrt(X)},
        {"a^x", pow(A, X)},
        {"x^a", pow(X, A)},
        {"2^x", pow(2, X)},
        {"-x^2", -(X * X)},
        {"-x*y", -X * Y},
        {"x - y - a", X - Y - A},
        {"x/y/a", X / Y / A},
        {"2^3^2", 512.0},
        {"(x + y)*a", (X + Y) * A},
        {"x + y*a", X + Y * A},
        {"1.5e-1*x + 2E2", 0.15 * X + 200.0},
        {".5*x", 0.5 * X},
        {"sqrt(a)", sqrt(A)},
        {"exp(x)", exp(X)},
        {"log(a)", log(A)},
        {"sin(x)", sin(X)},
        {"cos(x)", cos(X)},
        {"tan(x)", tan(X)},
        {"asin(x)", asin(X)},
        {"acos(x)", acos(X)},
        {"atan(y)", atan(Y)},
        {"sinh(y)", sinh(Y)},
        {"cosh(y)", cosh(Y)},
        {"tanh(y)", tanh(Y)},
        {"abs(y)", fabs(Y)},
        {"sqr(y)", Y * Y},
        {"atan2(y, x)", atan2(Y, X)},
        {"hypot(x, y)", hypot(X, Y)},
        {"pi*x", 3.14159265358979323846 * X},
        {"sum(i in 1..n, i*x)", 10 * X},
        {"sum(i in 1..n, sum(k in i..n, x))", 10 * X},
        {"sum(i in 3..1, x)", 0.0},
        {"if(n > 3, x, y)", X},
        {"if(n <= 3, x, y)", Y},
        {"(n <= 4)*x + (n > 4)*y + (n < 5)*a + (n >= 5)", X + A},
        {"(n == 4) + (n != 4)*x + (n >= 4)*y + (n < 4)*a", 1 + Y},
        {"f_sum", fact_sum()},
        {"sq[n]", (double)(N * N) * X},
        {"w[2, 3]", 6.0 * Y},
    };
    const size_t nfixed = sizeof cases / sizeof cases[0];
    /* constant folding against the plain operation: every binary
     * operator with a constant of either sign on either side, written
     * as a number, in parentheses, and after a unary minus */
    static const double consts[] = {-2, -1, -0.5, 0, 0.5, 1, 2};
    static const char ops[] = "+-*/^";
    char (*ftext)[48] = malloc(400 * sizeof *ftext);
    double *fval = malloc(400 * sizeof *fval);
    size_t nc = nfixed;
    char *text = malloc(96 * 1024), err[4096];
    eom_model *m = NULL;
    eom_system *s = NULL;
    double x[4], *p;
    size_t k;
    int rc;
    strcpy(text, "units off\nsetting n = 4\nparam a = 2.5\n"
                 "coord x = 0.7\ncoord y = -1.3\n"
                 "T = 1/2*(x_dot^2 + y_dot^2)\n"
                 "f[0] = 1\nf[j in 1..n] = j*f[j-1]*x\n"
                 "f_sum = sum(j in 1..n, f[j])\n"
                 "sq[j in 1..n] = j^2*x\n"
                 "w[i in 1..3, k in 1..3] = i*k*y\n");
    for (k = 0; k < nfixed; k++)
        sprintf(text + strlen(text), "probe p%zu = %s\n", k, cases[k].text);
    {
        size_t o, c, side, form, nf = 0;
        for (o = 0; o < 5; o++)
            for (c = 0; c < sizeof consts / sizeof consts[0]; c++)
                for (side = 0; side < 2; side++)
                    for (form = 0; form < 3; form++) {
                        const double cv = consts[c];
                        const char op = ops[o];
                        double a = side ? X : cv, b = side ? cv : X, v;
                        char ct[16];
                        if ((op == '/' && b == 0.0) ||
                            (op == '^' && a <= 0.0) ||
                            (form == 2 && cv >= 0.0))
                            continue; /* undefined, or no unary form */
                        if (form == 0)
                            snprintf(ct, sizeof ct, "%g", cv);
                        else if (form == 1)
                            snprintf(ct, sizeof ct, "(%g)", cv);
                        else /* a unary minus before the number */
                            snprintf(ct, sizeof ct, "-%g", -cv);
                        if (form == 0 && cv < 0.0 && !side)
                            snprintf(ct, sizeof ct, "(%g)", cv);
                        v = op == '+'   ? a + b
                            : op == '-' ? a - b
                            : op == '*' ? a * b
                            : op == '/' ? a / b
                                        : pow(a, b);
                        /* -2^x is -(2^x): the unary form's own meaning */
                        if (form == 2 && !side && op == '^')
                            v = -pow(-cv, X);
                        snprintf(ftext[nf], sizeof ftext[nf], "%s %c %s",
                                 side ? "x" : ct, op, side ? ct : "x");
                        fval[nf] = v;
                        sprintf(text + strlen(text), "probe p%zu = %s\n", nc,
                                ftext[nf]);
                        nf++;
                        nc++;
                    }
    }
    rc = eom_model_from_string(&m, text, err, sizeof err);
    if (rc != EOM_OK) {
        CHECK_FAIL_("%s", err);
        CHECK_DONE();
    }
    CHECK(eom_system_new(&s, m, err, sizeof err) == EOM_OK);
    p = calloc(nc, sizeof *p);
    CHECK(eom_initial_state(s, x) == EOM_OK);
    CHECK(eom_probes_at(s, x, p) == EOM_OK);
    for (k = 0; k < nc; k++) {
        const char *t = k < nfixed ? cases[k].text : ftext[k - nfixed];
        double want = k < nfixed ? cases[k].value : fval[k - nfixed];
        if (!(fabs(p[k] - want) <= 1e-14 * fmax(1.0, fabs(want))))
            CHECK_FAIL_("%s = %.17g, expected %.17g", t, p[k], want);
        else
            check_count_++;
    }
    printf("%zu expressions, %zu of them constant folding\n", nc,
           nc - nfixed);
    free(p);
    free(ftext);
    free(fval);
    free(text);
    eom_system_free(&s);
    eom_model_free(&m);
    CHECK_DONE();
}
