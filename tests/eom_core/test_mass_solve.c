/* test_mass_solve.c - the mass matrix's factor and solve at every size:
 * the unrolled small path (n <= 16), the column path (17 .. 128) and
 * LAPACK's (above), on rigid chains with unequal links.
 *
 *   1. eom_rhs's accelerations solve M qdd = dL/dq - h, with M, dL/dq
 *      and h from the embedded-tuple route (another evaluation of the
 *      same Lagrangian): the residual is at rounding level, relative to
 *      |M| |qdd| + |dL/dq - h|;
 *   2. accelerations of the same chain at sizes either side of each
 *      switch of path are continuous in the sense that each passes (1);
 *   3. a link of zero mass makes M singular: every path reports
 *      EOM_ERR_SINGULAR_MASS and names the leading minor that fails.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/chain.h"

/* A rigid chain of N links, link `massless` (0-based, or -1) without
 * mass. */
static eom_model *chain(int N, int massless)
{
    double *m = malloc((size_t)N * sizeof *m), *L = malloc((size_t)N * sizeof *L);
    eom_chain_spec sp;
    eom_model *md = NULL;
    int j;
    for (j = 0; j < N; j++) {
        m[j] = j == massless ? 0.0 : 1.0 + 0.1 * (j % 7);
        L[j] = 1.0 - 0.003 * j;
    }
    memset(&sp, 0, sizeof sp);
    sp.links = N;
    sp.m_link = m;
    sp.L_link = L;
    sp.g = 9.81;
    CHECK(eom_model_new(&md) == EOM_OK);
    CHECK(eom_chain_add(md, &sp) >= 0);
    free(m);
    free(L);
    return md;
}

static void check_solve(int N)
{
    const int n = N;
    eom_model *md = chain(N, -1);
    eom_system *s = NULL;
    tp_rec *tu = NULL;
    char msg[256];
    double *x = malloc(4 * (size_t)n * sizeof *x), *xd = x + 2 * n;
    double *M = malloc((size_t)n * (size_t)n * sizeof *M);
    double *g = malloc(2 * (size_t)n * sizeof *g), *h = g + n, L;
    double res = 0.0, scale = 0.0;
    int i, k;
    CHECK(eom_system_new(&s, md, msg, sizeof msg) == EOM_OK);
    CHECK(tp_tuple_new(&tu, 2 * n, NULL) == TP_OK);
    for (i = 0; i < n; i++) {
        x[i] = 0.4 * sin(1.7 * i) - 1.2;
        x[n + i] = 0.3 * cos(0.7 * i);
    }
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
    CHECK_INT(eom_model_run_lagrangian(md, tu, x), EOM_OK);
    CHECK_INT(tp_tuple_lagrange(tu, 0, &L, g, M, h), TP_OK);
    for (i = 0; i < n; i++) {
        double r = g[i] - h[i], a = fabs(g[i] - h[i]);
        for (k = 0; k < n; k++) {
            r -= M[i * n + k] * xd[n + k];
            a += fabs(M[i * n + k] * xd[n + k]);
        }
        res = fmax(res, fabs(r));
        scale = fmax(scale, a);
    }
    if (!(res <= 1e-13 * scale))
        fprintf(stderr, "n = %d: |M qdd - (dL/dq - h)| = %.3g (scale %.3g)\n",
                n, res, scale);
    CHECK(res <= 1e-13 * scale);
    tp_rec_free(&tu);
    eom_system_free(&s);
    eom_model_free(&md);
    free(x);
    free(M);
    free(g);
}

/* Link j massless: M's leading minor of order j + 1 vanishes. */
static void check_singular(int N, int j)
{
    eom_model *md = chain(N, j);
    eom_system *s = NULL;
    char msg[256], want[64];
    double *x = calloc(4 * (size_t)N, sizeof *x);
    int i;
    CHECK(eom_system_new(&s, md, msg, sizeof msg) == EOM_OK);
    for (i = 0; i < N; i++)
        x[i] = 0.1 * i;
    CHECK_INT(eom_rhs(s, 0.0, x, x + 2 * N), EOM_ERR_SINGULAR_MASS);
    snprintf(want, sizeof want, "leading minor of order %d ", j + 1);
    if (!strstr(eom_system_errmsg(s), want))
        fprintf(stderr, "N = %d: '%s' does not name the minor %d\n", N,
                eom_system_errmsg(s), j + 1);
    CHECK(strstr(eom_system_errmsg(s), want) != NULL);
    eom_system_free(&s);
    eom_model_free(&md);
    free(x);
}

int main(void)
{
    static const int sizes[] = {2, 6, 7, 16, 17, 40, 128, 129};
    size_t k;
    for (k = 0; k < sizeof sizes / sizeof sizes[0]; k++)
        check_solve(sizes[k]);
    check_singular(10, 9);
    check_singular(30, 29);
    check_singular(129, 128);
    CHECK_DONE();
}
