/* test_pattern.c - tp_tape_jacobian_pattern, the structural sparsity of a
 * tape's Jacobian.
 *
 *   1. Exact on a function written to know its pattern: 150 independents
 *      (three 64-column blocks and a partial one), outputs that read one,
 *      two, a block-crossing run, none (a parameter only), through every
 *      operand kind (unary, with a constant, integer power, binary);
 *      column ranges that start and end inside a block.
 *   2. A superset of every numerically nonzero entry of tp_jacobian at
 *      random points: the N-link pendulum's Lagrangian and its gradient
 *      tape (a derivative tape: the Hessian's pattern), full range and a
 *      sub-range.
 *   3. Bad input: NULL, a range outside the independents, too small a
 *      cap (rowptr still valid).
 */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "pendulum_chain.h"
#include "support_rng.h"
#include "tape/tape.h"

#define NX 150

/* Outputs and the columns each reads (ascending, -1 ends). */
static const int expect[][8] = {
    {0, 1, -1},           /* x0 * x1 */
    {2, -1},              /* sin(x2) */
    {-1},                 /* 2 p */
    {62, 63, 64, 65, -1}, /* sum across the first block edge */
    {3, 140, -1},         /* (x3 + 0.5)^3 / x140 */
    {149, -1},            /* exp(-x149) */
    {7, 127, 128, -1},    /* atan2(x127, x128) * x7 */
};
#define NOUT ((int)(sizeof expect / sizeof expect[0]))

static int rec_known(tp_rec *r, void *user)
{
    tp_val x[NX], run[4];
    int i;
    (void)user;
    for (i = 0; i < NX; i++)
        x[i] = tp_indep(r, i);
    tp_output(r, "a", tp_mul(r, x[0], x[1]));
    tp_output(r, "b", tp_sin(r, x[2]));
    tp_output(r, "c", tp_mulc(r, tp_param(r, "p", 1.5), 2.0));
    for (i = 0; i < 4; i++)
        run[i] = tp_sqr(r, x[62 + i]);
    tp_output(r, "d", tp_sum(r, 4, run));
    tp_output(r, "e", tp_div(r, tp_powi(r, tp_addc(r, x[3], 0.5), 3),
                             x[140]));
    tp_output(r, "f", tp_exp(r, tp_neg(r, x[149])));
    tp_output(r, "g", tp_mul(r, tp_atan2(r, x[127], x[128]), x[7]));
    return 0;
}

static tp_tape *record(int n, tp_func f, void *user)
{
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    if (tp_recorder_new(&r, n, NULL, NULL) == TP_OK &&
        tp_rec_run(r, NULL, f, user) == TP_OK)
        tp_recorder_finish(r, &t);
    tp_rec_free(&r);
    return t;
}

/* The pattern of t over [first, first + count): rowptr and cols made
 * here (free both), or 0 on failure. */
static int pattern(const tp_tape *t, int first, int count, size_t **rp,
                   int **cols)
{
    const int m = tp_tape_n_outputs(t);
    *rp = malloc(((size_t)m + 1) * sizeof **rp);
    *cols = NULL;
    if (!*rp || tp_tape_jacobian_pattern(t, first, count, *rp, NULL, 0) !=
                    TP_OK)
        return 0;
    *cols = malloc(((*rp)[m] ? (*rp)[m] : 1) * sizeof **cols);
    return *cols && tp_tape_jacobian_pattern(t, first, count, *rp, *cols,
                                             (*rp)[m]) == TP_OK;
}

static void known(void)
{
    tp_tape *t = record(NX, rec_known, NULL);
    size_t *rp = NULL;
    int *cols = NULL, o, k, ranges[][2] = {{0, NX}, {2, 126}, {63, 2},
                                           {128, 22}, {5, 0}};
    size_t r;
    CHECK(t != NULL);
    if (!t)
        return;
    CHECK_INT(tp_tape_n_outputs(t), NOUT);
    for (r = 0; r < sizeof ranges / sizeof ranges[0]; r++) {
        const int first = ranges[r][0], count = ranges[r][1];
        CHECK(pattern(t, first, count, &rp, &cols));
        for (o = 0; o < NOUT && rp && cols; o++) {
            size_t p = rp[o];
            for (k = 0; expect[o][k] >= 0; k++) {
                const int c = expect[o][k] - first;
                if (c < 0 || c >= count)
                    continue;
                CHECK(p < rp[o + 1]);
                if (p < rp[o + 1])
                    CHECK_INT(cols[p], c);
                p++;
            }
            CHECK_INT(p, rp[o + 1]);
        }
        free(rp);
        free(cols);
    }
    tp_tape_free(&t);
}

/* Every entry of tp_jacobian over [first, first + count) that is not
 * zero at npts random points lies in the pattern; returns the number of
 * pattern entries seen nonzero at some point. */
static size_t superset(const tp_tape *t, int first, int count, int npts,
                       uint64_t seed)
{
    const int n = tp_tape_n_indep(t), m = tp_tape_n_outputs(t);
    double *x = malloc((size_t)n * sizeof *x);
    double *J = malloc((size_t)m * (size_t)count * sizeof *J);
    char *in = calloc((size_t)m * (size_t)count, 1);
    char *seen = calloc((size_t)m * (size_t)count, 1);
    size_t *rp = NULL, p, hits = 0;
    int *cols = NULL, i, j, k, bad = 0;
    tp_ws *ws = NULL;
    rng g = rng_seed(seed);
    CHECK(x && J && in && seen && pattern(t, first, count, &rp, &cols));
    CHECK_INT(tp_ws_new(&ws, t, 8, NULL), TP_OK);
    if (!x || !J || !in || !seen || !cols || !ws)
        goto out;
    for (i = 0; i < m; i++)
        for (p = rp[i]; p < rp[i + 1]; p++)
            in[(size_t)i * count + cols[p]] = 1;
    for (k = 0; k < npts; k++) {
        for (j = 0; j < n; j++)
            x[j] = rng_range(&g, -1.5, 1.5);
        CHECK(tp_jacobian(ws, x, first, count, NULL, J) >= TP_OK);
        for (i = 0; i < m * count; i++)
            if (J[i] != 0.0) {
                seen[i] = 1;
                if (!in[i] && bad++ < 5)
                    CHECK_FAIL_("entry (%d, %d) = %g is not in the "
                                "pattern", i / count, first + i % count,
                                J[i]);
            }
    }
    check_count_++;
    for (i = 0; i < m * count; i++)
        hits += seen[i];
out:
    tp_ws_free(&ws);
    free(x);
    free(J);
    free(in);
    free(seen);
    free(rp);
    free(cols);
    return hits;
}

static int rec_gradient(tp_rec *r, void *user)
{
    const tp_tape *L = user;
    tp_val x[40], w[8], g[40];
    char name[16];
    int i, n = tp_tape_n_indep(L);
    for (i = 0; i < n; i++)
        x[i] = tp_indep(r, i);
    for (i = 0; i < tp_tape_n_outputs(L); i++) /* output 0, L */
        w[i] = tp_const(r, i == 0 ? 1.0 : 0.0);
    tp_call_vjp(r, L, x, NULL, w, NULL, g, NULL);
    for (i = 0; i < n; i++) {
        snprintf(name, sizeof name, "g%d", i);
        tp_output(r, name, g[i]);
    }
    return 0;
}

static int rec_chain(tp_rec *r, void *user)
{
    return pendulum_chain_record(r, user);
}

static void chains(void)
{
    pendulum_chain pc = {12, NULL, NULL, 9.81};
    tp_tape *L = record(2 * pc.n, rec_chain, &pc), *G = NULL;
    CHECK(L != NULL);
    if (!L)
        return;
    G = record(2 * pc.n, rec_gradient, L);
    CHECK(G != NULL);
    CHECK(superset(L, 0, 2 * pc.n, 20, 1) > 0);
    if (G) {
        /* the Hessian: q-q full, q-qd and qd-qd through cos(q_i - q_j) */
        size_t hits = superset(G, 0, 2 * pc.n, 20, 2);
        CHECK(hits > (size_t)(2 * pc.n));
        CHECK(superset(G, 3, 17, 20, 3) > 0);
    }
    tp_tape_free(&G);
    tp_tape_free(&L);
}

static void bad_input(void)
{
    tp_tape *t = record(NX, rec_known, NULL);
    size_t rp[NOUT + 1];
    int cols[4];
    CHECK_INT(tp_tape_jacobian_pattern(NULL, 0, 1, rp, NULL, 0),
              TP_ERR_NULL);
    CHECK_INT(tp_tape_jacobian_pattern(t, 0, 1, NULL, NULL, 0), TP_ERR_NULL);
    CHECK_INT(tp_tape_jacobian_pattern(t, -1, 1, rp, NULL, 0), TP_ERR_SIZE);
    CHECK_INT(tp_tape_jacobian_pattern(t, 0, NX + 1, rp, NULL, 0),
              TP_ERR_SIZE);
    CHECK_INT(tp_tape_jacobian_pattern(t, NX, 1, rp, NULL, 0), TP_ERR_SIZE);
    CHECK_INT(tp_tape_jacobian_pattern(t, 0, NX, rp, cols, 4), TP_ERR_SIZE);
    CHECK_INT(rp[NOUT], 13); /* the count is still given */
    tp_tape_free(&t);
}

int main(void)
{
    known();
    chains();
    bad_input();
    CHECK_DONE();
}
