/* bench_rhs_loop.c - the C side of bench/bench_python.py: the time of one
 * eom_rhs call in a C loop, over k states of a model file, as the
 * reference the Python calls are measured against. Public headers only.
 *
 * usage: bench-rhs-loop MODEL.eom K REPS
 * prints one line: "ns_per_call N checksum S" (the checksum keeps the
 * loop from being optimised away and lets the script check the states
 * were the same). */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "eom/eom.h"
#include "eom/model_file.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    eom_model *m = NULL;
    eom_system *s = NULL;
    char err[2048];
    double *X, *xd, sum = 0.0, t0, best = 1e300;
    long k, K, reps, r, i;
    int n2, pass;
    if (argc != 4) {
        fprintf(stderr, "usage: bench-rhs-loop MODEL.eom K REPS\n");
        return 2;
    }
    K = atol(argv[2]);
    reps = atol(argv[3]);
    if (K < 1 || reps < 1 ||
        eom_model_from_file(&m, argv[1], err, sizeof err) != EOM_OK ||
        eom_system_new(&s, m, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "bench-rhs-loop: %s\n", K < 1 ? "bad K" : err);
        return 1;
    }
    n2 = 2 * eom_system_ncoords(s);
    X = malloc((size_t)K * (size_t)n2 * sizeof *X);
    xd = malloc((size_t)K * (size_t)n2 * sizeof *xd);
    if (!X || !xd)
        return 1;
    /* the same states as the script: the start, moved by i * 1e-3 */
    eom_initial_state(s, X);
    for (k = 0; k < K; k++)
        for (i = 0; i < n2; i++)
            X[k * n2 + i] = X[i] + 1e-3 * (double)k;
    /* the best of five passes: the least disturbed by the machine */
    for (pass = 0; pass < 5; pass++) {
        t0 = now();
        for (r = 0; r < reps; r++)
            for (k = 0; k < K; k++)
                if (eom_rhs(s, 0.0, X + k * n2, xd + k * n2) < 0)
                    return 1;
        t0 = now() - t0;
        if (t0 < best)
            best = t0;
    }
    for (i = 0; i < K * n2; i++)
        sum += xd[i];
    printf("ns_per_call %.1f checksum %.17g\n",
           1e9 * best / (double)(reps * K), sum);
    free(X);
    free(xd);
    eom_system_free(&s);
    eom_model_free(&m);
    return 0;
}
