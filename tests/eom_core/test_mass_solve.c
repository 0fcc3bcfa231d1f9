/* test_mass_solve.c - the mass matrix's factor and solve at every size:
 * the unrolled small path (n <= 16), the column path (17 .. 128) and
 * the blocked one (above: 300 has panels of 48 and a remainder), on rigid
 * chains with unequal links.
 *
 *   1. eom_rhs's accelerations solve M qdd = dL/dq - h, with M, dL/dq
 *      and h from another evaluation of the same Lagrangian: the
 *      residual is at rounding level, relative to |M| |qdd| + |dL/dq -
 *      h|. Up to n = TUPLE_MAX the embedded-tuple route gives them; above
 *      it a tape recorded afresh from the model (its own recorder and
 *      workspace, no system, tp_lagrange), since a tuple over 2n = 258
 *      independents carries a packed Hessian of 33,000 entries per value:
 *      about 20 s of processor time for n = 128 and 129, which made the
 *      test run past its limit on a loaded machine. The tape's blocks
 *      agree with the tuples' (test_conformance, and this test at
 *      n <= TUPLE_MAX), and the solve this test is about is the same;
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

/* The largest n whose reference blocks come from the embedded tuples. */
#define TUPLE_MAX 40

/* M, dL/dq and h of md at x from a tape recorded afresh (n > TUPLE_MAX). */
static int fresh_tape_blocks(const eom_model *md, int n, const double *x,
                             double *L, double *g, double *M, double *h)
{
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    tp_ws *ws = NULL;
    int rc;
    if ((rc = tp_recorder_new(&r, 2 * n, NULL, NULL)) != TP_OK)
        return rc;
    if ((rc = eom_model_run_lagrangian(md, r, NULL)) == EOM_OK &&
        (rc = tp_recorder_finish(r, &t)) == TP_OK &&
        (rc = tp_ws_new(&ws, t, n, NULL)) == TP_OK)
        rc = tp_lagrange(ws, x, 0, L, g, M, h);
    tp_ws_free(&ws);
    tp_tape_free(&t);
    tp_rec_free(&r);
    return rc;
}

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
    for (i = 0; i < n; i++) {
        x[i] = 0.4 * sin(1.7 * i) - 1.2;
        x[n + i] = 0.3 * cos(0.7 * i);
    }
    CHECK_INT(eom_rhs(s, 0.0, x, xd), EOM_OK);
    if (N <= TUPLE_MAX) {
        CHECK(tp_tuple_new(&tu, 2 * n, NULL) == TP_OK);
        CHECK_INT(eom_model_run_lagrangian(md, tu, x), EOM_OK);
        CHECK_INT(tp_tuple_lagrange(tu, 0, &L, g, M, h), TP_OK);
    } else {
        CHECK_INT(fresh_tape_blocks(md, n, x, &L, g, M, h), TP_OK);
    }
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
    static const int sizes[] = {2, 6, 7, 16, 17, 40, 128, 129, 300};
    size_t k;
    for (k = 0; k < sizeof sizes / sizeof sizes[0]; k++)
        check_solve(sizes[k]);
    check_singular(10, 9);
    check_singular(30, 29);
    check_singular(129, 128);
    check_singular(300, 299);
    CHECK_DONE();
}
