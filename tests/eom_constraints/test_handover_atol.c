/* test_handover_atol.c - adams and ida hand each singular stretch to bdf
 * (integrate_handover.c); bdf must take the run's per-component absolute
 * tolerances (eom_opts.atol_vec) with it.
 *
 * The IFToMM A02 linkage with N = 2 loops in angles (models/
 * a02-angles.eom) to t = 3.3 s passes four flat positions; adams hands
 * the stretch around some of them to bdf. Two runs of adams at rtol
 * 1e-10 that differ only in how a loose absolute tolerance is given:
 * (a) atol_vec = 1e-7 on every coordinate and rate, with the scalar atol
 * 1e-11; (b) the scalar atol 1e-7. The model has no dissipation, so the
 * dissipated work W (the one component atol_vec does not cover) stays 0
 * and its tolerance does not matter: the two runs must hand over the
 * same stretches and take the same steps (within 2 %: the scalar atol
 * also sets the projection's stopping rule where it stalls). Measured
 * from the initial state: 650 steps and 2 stretches each. With the
 * handover dropping atol_vec (its bdf at the scalar 1e-11), (a) took 593
 * steps and 1 stretch. Which flat positions adams hands over depends on
 * the last bits (NSTARTS below), so the pair runs from twelve starts.
 * (ida is left out: its Newton test weighs the multipliers with the
 * scalar atol, so its two runs differ anyway.)
 *
 * usage: test_handover_atol MODELS_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"
#include "eom/model_file.h"

#define NLOOPS 2
#define LOOSE 1e-7
#define TIGHT 1e-11
#define NMAX (2 * NLOOPS + 1)

/* Runs method to 3.3 s from the initial state with the first rate times
 * 1 + pert; its stats into st, the final state into x. */
static int run(const char *path, eom_method method, int use_vec,
               double pert, eom_stats *st, double *x)
{
    char err[1024];
    eom_file *f = NULL;
    eom_model *mo = NULL;
    eom_system *s = NULL;
    eom_integ *it = NULL;
    eom_opts o;
    double atolv[2 * NMAX];
    int rc = -1, n, i, k;
    memset(st, 0, sizeof *st);
    if (eom_file_read(&f, path, err, sizeof err) != EOM_OK ||
        eom_file_set_setting(f, "N", NLOOPS, err, sizeof err) != EOM_OK ||
        eom_file_build(f, &mo, err, sizeof err) != EOM_OK ||
        eom_system_new(&s, mo, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "%s: %s\n", path, err);
        goto done;
    }
    n = eom_system_ncoords(s);
    CHECK(n <= NMAX);
    if (n > NMAX || eom_initial_state(s, x) != EOM_OK)
        goto done;
    x[n] *= 1.0 + pert;
    for (i = 0; i < 2 * n; i++)
        atolv[i] = LOOSE;
    eom_opts_default(&o);
    o.method = method;
    o.rtol = 1e-10;
    o.atol = use_vec ? TIGHT : LOOSE;
    o.atol_vec = use_vec ? atolv : NULL;
    if ((rc = eom_integ_new(&it, s, &o, 0.0, x)) != EOM_OK) {
        fprintf(stderr, "%s: %s\n", eom_method_name(method),
                eom_system_errmsg(s));
        goto done;
    }
    for (k = 1; k <= 66 && rc == EOM_OK; k++)
        rc = eom_integ_advance(it, 0.05 * k, x, NULL);
    if (rc != EOM_OK)
        fprintf(stderr, "%s: %s\n", eom_method_name(method),
                eom_integ_errmsg(it));
    eom_integ_stats(it, st);
done:
    eom_integ_free(&it);
    eom_system_free(&s);
    eom_model_free(&mo);
    eom_file_free(&f);
    return rc;
}

/* Whether adams meets a flat position closely enough to hand it over
 * is a matter of the last bits: the same build handed over 2, 1, 0 and
 * 0 stretches from first rates 1e-15 apart. So the pair of runs starts
 * from twelve first rates 1e-14 apart, and together they must hand over
 * at least two stretches (measured: 7 on one build, and 2, 0, 0, 1, 0,
 * 0 over the first six; 6 over the first six with h summed in another
 * order). */
#define NSTARTS 12
static const double pert[NSTARTS] = {0.0,    1e-14, -1e-14, 2e-14,
                                     -2e-14, 3e-14, -3e-14, 4e-14,
                                     -4e-14, 5e-14, -5e-14, 6e-14};

int main(int argc, char **argv)
{
    static const eom_method methods[] = {EOM_ADAMS};
    char path[4096];
    int k;
    if (argc < 2) {
        fprintf(stderr, "usage: %s MODELS_DIR\n", argv[0]);
        return 2;
    }
    snprintf(path, sizeof path, "%s/a02-angles.eom", argv[1]);
    for (k = 0; k < (int)(sizeof methods / sizeof *methods); k++) {
        long stretches = 0;
        int j;
        for (j = 0; j < NSTARTS; j++) {
            eom_stats va, sc;
            double xa[2 * NMAX], xs[2 * NMAX];
            CHECK_INT(run(path, methods[k], 1, pert[j], &va, xa), EOM_OK);
            CHECK_INT(run(path, methods[k], 0, pert[j], &sc, xs), EOM_OK);
            printf("%s, first rate x (1 %+g): atol_vec %g: %ld steps, %ld "
                   "stretches handed to bdf; scalar atol %g: %ld steps, "
                   "%ld stretches\n",
                   eom_method_name(methods[k]), pert[j], LOOSE, va.steps,
                   va.singular_handovers, LOOSE, sc.steps,
                   sc.singular_handovers);
            stretches += sc.singular_handovers;
            CHECK_INT(va.singular_handovers, sc.singular_handovers);
            CHECK(fabs((double)(va.steps - sc.steps)) <=
                  0.02 * (double)sc.steps);
            CHECK(fabs(xa[0] - xs[0]) < 1e-6);
        }
        CHECK(stretches >= 2);
    }
    CHECK_DONE();
}
