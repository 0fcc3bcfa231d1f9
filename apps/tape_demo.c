/* tape_demo.c - a first look at libtape: the Lagrangian of an N-link
 * pendulum is written once against the recording API, recorded onto a
 * tape, and replayed for what Lagrange's equations need; the same source
 * also runs on the double and embedded-tuple evaluators. The mass matrix is
 * compared with its closed form M_ij = a_ij cos(q_i - q_j).
 *
 * usage: tape-demo [N]   (N links, default 4) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "pendulum_chain.h"
#include "tape/tape.h"

static int fail(const char *what, int rc)
{
    fprintf(stderr, "tape-demo: %s: %s\n", what, tp_strerror(rc));
    return EXIT_FAILURE;
}

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 4, i, j, rc;
    pendulum_chain pc;
    unsigned char *group;
    double *x, *dLdq, *M, *Mc, *h, L, Lt, err = 0.0, scale = 0.0;
    tp_rec *rec = NULL, *tup = NULL;
    tp_tape *tape = NULL;
    tp_ws *ws = NULL;
    tp_tape_stats st;

    if (n < 1 || n > 200) {
        fprintf(stderr, "usage: tape-demo [N], 1 <= N <= 200\n");
        return EXIT_FAILURE;
    }
    pc.n = n;
    pc.m = pc.l = NULL;
    pc.g = 9.81;
    group = malloc((size_t)(2 * n));
    x = malloc(sizeof(double) * (size_t)(2 * n));
    dLdq = malloc(sizeof(double) * (size_t)n);
    h = malloc(sizeof(double) * (size_t)n);
    M = malloc(sizeof(double) * (size_t)(n * n));
    Mc = malloc(sizeof(double) * (size_t)(n * n));
    if (!group || !x || !dLdq || !h || !M || !Mc)
        return fail("allocation", TP_ERR_NOMEM);
    for (i = 0; i < 2 * n; i++) {
        group[i] = i < n ? 0 : 1; /* q in group 0, qd in group 1 */
        x[i] = i < n ? 0.3 * (i + 1) : 0.1 * (i - n) - 0.2;
    }

    /* record once */
    if ((rc = tp_recorder_new(&rec, 2 * n, group, NULL)) != TP_OK)
        return fail("recorder", rc);
    if ((rc = tp_rec_run(rec, NULL, pendulum_chain_record, &pc)) != TP_OK)
        return fail(tp_rec_errmsg(rec), rc);
    if ((rc = tp_recorder_finish(rec, &tape)) != TP_OK)
        return fail(tp_rec_errmsg(rec), rc);
    tp_tape_stats_get(tape, &st);
    printf("%d-link pendulum: tape of %zu ops (%zu recorded, %zu shared by "
           "hash-consing, %zu folded, %zu dead), %.1f bytes/op\n",
           n, st.n_ops, st.n_recorded, st.n_cse_hits, st.n_folded,
           st.n_dead, (double)st.bytes / (double)st.n_ops);

    /* replay: one forward and one reverse sweep with n directions */
    if ((rc = tp_ws_new(&ws, tape, n, NULL)) != TP_OK)
        return fail("workspace", rc);
    rc = tp_lagrange(ws, x, tp_tape_output_index(tape, "L"), &L, dLdq, M, h);
    if (rc != TP_OK)
        return fail(tp_ws_errmsg(ws), rc);
    pendulum_chain_mass(&pc, x, Mc);
    for (i = 0; i < n * n; i++) {
        err = fmax(err, fabs(M[i] - Mc[i]));
        scale = fmax(scale, fabs(Mc[i]));
    }
    printf("L = %.15g (plain C: %.15g)\n", L, pendulum_chain_L(&pc, x));
    printf("mass matrix from the tape:\n");
    for (i = 0; i < n && i < 6; i++) {
        for (j = 0; j < n && j < 6; j++)
            printf(" %10.6f", M[i * n + j]);
        printf(n > 6 ? " ...\n" : "\n");
    }
    printf("largest difference from the closed form: %.2e (relative "
           "%.2e)\n", err, err / scale);

    /* the same source on the embedded-tuple engine */
    if ((rc = tp_tuple_new(&tup, 2 * n, NULL)) != TP_OK ||
        (rc = tp_rec_run(tup, x, pendulum_chain_record, &pc)) != TP_OK ||
        (rc = tp_tuple_lagrange(tup, 0, &Lt, NULL, Mc, NULL)) != TP_OK)
        return fail("tuples", rc);
    err = 0.0;
    for (i = 0; i < n * n; i++)
        err = fmax(err, fabs(M[i] - Mc[i]));
    printf("embedded tuples agree to %.2e\n", err);

    tp_ws_free(&ws);
    tp_tape_free(&tape);
    tp_rec_free(&rec);
    tp_rec_free(&tup);
    free(group);
    free(x);
    free(dLdq);
    free(h);
    free(M);
    free(Mc);
    return EXIT_SUCCESS;
}
