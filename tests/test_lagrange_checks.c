/* test_lagrange_checks.c - tp_lagrange's check of the blocks it writes:
 * a non-finite entry of M alone, or of h alone, makes the call return
 * TP_WARN_NONFINITE whenever that block is asked for, on every path that
 * writes them (libtape/src/drivers.c: the unrolled copies for n <= 6, the
 * vectorized one above, whose loops have tails at n = 7, 9 and 13; the
 * ranged sweep, n > 4 in one chunk; chunks of 3 directions), and only
 * the blocks asked for are judged.
 *
 * The model: n rates, K = n - 1, J = n / 2,
 *     L = sum_c (1 + c / 10) qd_c^2 / 2 + pm qd_K^2 / 2 + ph q_J qd_K
 * so that M = diag(1 + c / 10) + pm e_K e_K^T and h = ph qd_J e_K (closed
 * forms, checked at finite pm and ph). With pm = inf, M_KK is not
 * finite and h is (h's rows are those of q, which pm does not touch);
 * with ph = 1e300 and qd_J = 1e10, h_K overflows and M stays finite (an
 * infinite ph would reach M as 0 * inf). L and dL/dq are not asked for
 * in these calls (they overflow too): what is judged is the block's own
 * check. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "tape/tape.h"

#define NMAX 13

static int record(tp_rec *r, void *user)
{
    const int n = *(const int *)user, K = n - 1, J = n / 2;
    tp_val L = tp_const(r, 0.0);
    tp_val pm = tp_param(r, "pm", 0.0), ph = tp_param(r, "ph", 0.0);
    tp_val qdK = tp_indep(r, n + K);
    int c;
    for (c = 0; c < n; c++)
        L = tp_add(r, L, tp_mulc(r, tp_sqr(r, tp_indep(r, n + c)),
                                 0.5 * (1.0 + c / 10.0)));
    L = tp_add(r, L, tp_mul(r, tp_mulc(r, pm, 0.5), tp_sqr(r, qdK)));
    L = tp_add(r, L, tp_mul(r, tp_mul(r, ph, tp_indep(r, J)), qdK));
    tp_output(r, "L", L);
    return 0;
}

/* One workspace of dirs directions: closed forms at finite parameters,
 * then each block made non-finite in turn. */
static void check_ws(tp_tape *T, int n, int dirs)
{
    const int K = n - 1, J = n / 2;
    const int ipm = tp_tape_param_index(T, "pm"),
              iph = tp_tape_param_index(T, "ph");
    tp_ws *ws = NULL;
    double x[2 * NMAX], M[NMAX * NMAX], h[NMAX];
    int i, k, bad = 0;
    CHECK(ipm >= 0 && iph >= 0);
    CHECK_INT(tp_ws_new(&ws, T, dirs, NULL), TP_OK);
    if (!ws || ipm < 0 || iph < 0)
        goto done;
    for (i = 0; i < 2 * n; i++)
        x[i] = 0.25 + 0.125 * i;
    /* finite: M and h as the closed forms say, and TP_OK */
    CHECK_INT(tp_ws_set_param(ws, ipm, 2.0), TP_OK);
    CHECK_INT(tp_ws_set_param(ws, iph, 3.0), TP_OK);
    CHECK_INT(tp_lagrange(ws, x, 0, NULL, NULL, M, h), TP_OK);
    for (i = 0; i < n; i++)
        for (k = 0; k < n; k++) {
            const double want =
                i != k ? 0.0 : 1.0 + i / 10.0 + (i == K ? 2.0 : 0.0);
            bad += M[i * n + k] != want;
        }
    for (k = 0; k < n; k++)
        bad += h[k] != (k == K ? 3.0 * x[n + J] : 0.0);
    if (bad)
        fprintf(stderr, "n = %d, %d directions: M or h off its closed "
                "form in %d entries\n", n, dirs, bad);
    CHECK(bad == 0);
    /* M_KK infinite, h finite */
    CHECK_INT(tp_ws_set_param(ws, ipm, INFINITY), TP_OK);
    CHECK_INT(tp_ws_set_param(ws, iph, 3.0), TP_OK);
    CHECK_INT(tp_lagrange(ws, x, 0, NULL, NULL, M, NULL), TP_WARN_NONFINITE);
    CHECK(!isfinite(M[K * n + K]));
    CHECK_INT(tp_lagrange(ws, x, 0, NULL, NULL, M, h), TP_WARN_NONFINITE);
    CHECK_INT(tp_lagrange(ws, x, 0, NULL, NULL, NULL, h), TP_OK);
    CHECK(h[K] == 3.0 * x[n + J]);
    /* h_K infinite, M finite */
    CHECK_INT(tp_ws_set_param(ws, ipm, 2.0), TP_OK);
    CHECK_INT(tp_ws_set_param(ws, iph, 1e300), TP_OK);
    x[n + J] = 1e10;
    CHECK_INT(tp_lagrange(ws, x, 0, NULL, NULL, NULL, h), TP_WARN_NONFINITE);
    CHECK(isinf(h[K]));
    CHECK_INT(tp_lagrange(ws, x, 0, NULL, NULL, M, h), TP_WARN_NONFINITE);
    CHECK_INT(tp_lagrange(ws, x, 0, NULL, NULL, M, NULL), TP_OK);
    CHECK(M[K * n + K] == 1.0 + K / 10.0 + 2.0);
done:
    tp_ws_free(&ws);
}

int main(void)
{
    static const int sizes[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 13};
    size_t j;
    for (j = 0; j < sizeof sizes / sizeof sizes[0]; j++) {
        int n = sizes[j];
        tp_rec *r = NULL;
        tp_tape *T = NULL;
        CHECK_INT(tp_recorder_new(&r, 2 * n, NULL, NULL), TP_OK);
        CHECK_INT(tp_rec_run(r, NULL, record, &n), TP_OK);
        CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
        tp_rec_free(&r);
        if (T) {
            check_ws(T, n, n); /* one chunk: unrolled, ranged or not */
            if (n > 3)
                check_ws(T, n, 3); /* chunks of 3 and a remainder */
        }
        tp_tape_free(&T);
    }
    CHECK_DONE();
}
