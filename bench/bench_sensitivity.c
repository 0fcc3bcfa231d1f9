/* bench_sensitivity.c - bench-sensitivity: what forward sensitivities
 * cost beside the nominal run, and how well they agree with central
 * differences of whole runs, with 10 inputs each, on
 *   - the shipped open chain (3 flexible links, 2 modes each: 9
 *     coordinates, 6 parameters): the 6 parameters and 4 initial values;
 *   - the shipped closed chain (5 flexible links, 1 mode each: 10
 *     coordinates, 2 constraints, 7 parameters, two of which, the
 *     links' length and the tip pin's x, move the constraints): the 7
 *     parameters and 3 initial values, perturbed starts taken onto the
 *     constraints by eom_project_start.
 *
 * For adams, bdf and ida at rtol 1e-8, atol 1e-10, over T seconds: the
 * wall time of the nominal run and of the run with 10 sensitivities
 * (median of R repetitions, interleaved: the two runs of a repetition
 * follow each other, so that a machine shared with other jobs slows
 * both alike), their ratio, and the largest error of the sensitivities
 * relative to each input's largest, against central differences of erk
 * runs at rtol 1e-13.
 *
 * Usage: bench-sensitivity [--t-end T] [--reps R] MODELS_DIR
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "eom/eom.h"
#include "eom/model_file.h"

#define NS 10

static double t_end = 2.0;

static long last_steps, last_rhs;

static int run(eom_system *s, const eom_opts *o, const double *x0,
               double *x, double *S, double *wall)
{
    eom_integ *it = NULL;
    eom_stats st;
    double W;
    int rc;
    memcpy(x, x0, 2 * (size_t)eom_system_ncoords(s) * sizeof *x);
    rc = eom_integ_new(&it, s, o, 0.0, x);
    if (rc == EOM_OK)
        rc = eom_integ_advance(it, t_end, x, &W);
    if (rc == EOM_OK && S)
        rc = eom_integ_sensitivities(it, S);
    if (rc != EOM_OK)
        fprintf(stderr, "bench-sensitivity: %s\n",
                it ? eom_integ_errmsg(it) : eom_system_errmsg(s));
    if (it) {
        eom_integ_stats(it, &st);
        *wall = st.wall_time;
        last_steps = st.steps;
        last_rhs = st.rhs_evals;
    }
    eom_integ_free(&it);
    return rc;
}

/* The table of one model: s with its inputs sens and start x0 (on the
 * constraints), the methods, R repetitions. 0, or 1 after a message. */
static int table(eom_system *s, const int *sens, const double *x0, int reps)
{
    static const eom_method methods[] = {EOM_ADAMS, EOM_BDF, EOM_IDA};
    const int n = eom_system_ncoords(s), np = eom_system_nparams(s);
    const int constrained = eom_system_nconstraints(s) > 0;
    eom_opts o, ref;
    int k, i, r, m;
    double x[256], xp[256], xm[256], S[256 * NS], fd[256 * NS], wall;

    /* reference: central differences of erk runs, each start taken onto
     * the constraints as eom-run does */
    eom_opts_default(&ref);
    ref.method = EOM_ERK;
    ref.rtol = 1e-13;
    ref.atol = 1e-15;
    for (k = 0; k < NS; k++) {
        const double v = sens[k] < np ? eom_get_param(s, sens[k])
                                      : x0[sens[k] - np];
        const double h = 1e-5 * fmax(1.0, fabs(v));
        int side;
        for (side = 0; side < 2; side++) {
            const double d = side ? -h : h;
            double xs[256];
            memcpy(xs, x0, 2 * (size_t)n * sizeof *xs);
            if (sens[k] < np)
                eom_set_param(s, sens[k], v + d);
            else
                xs[sens[k] - np] = v + d;
            eom_set_time(s, 0.0);
            if (constrained &&
                eom_project_start(s, xs, 1e-14, NULL) != EOM_OK) {
                fprintf(stderr, "bench-sensitivity: %s\n",
                        eom_system_errmsg(s));
                return 1;
            }
            if (run(s, &ref, xs, side ? xm : xp, NULL, &wall) != EOM_OK)
                return 1;
            if (sens[k] < np)
                eom_set_param(s, sens[k], v);
        }
        for (i = 0; i < 2 * n; i++)
            fd[i * NS + k] = (xp[i] - xm[i]) / (2.0 * h);
    }

    printf("| method | nominal (s) | steps, rhs | with %d sensitivities "
           "(s) | steps, rhs | ratio | worst error / scale |\n"
           "|---|---|---|---|---|---|---|\n", NS);
    for (m = 0; m < 3; m++) {
        double wn[99], ws[99], worst = 0.0;
        long sn = 0, rn = 0;
        eom_opts_default(&o);
        o.method = methods[m];
        o.rtol = 1e-8;
        o.atol = 1e-10;
        for (r = 0; r < reps; r++) {
            eom_opts os = o;
            os.n_sens = NS;
            os.sens = sens;
            if (run(s, &o, x0, x, NULL, &wn[r]) != EOM_OK)
                return 1;
            sn = last_steps;
            rn = last_rhs;
            if (run(s, &os, x0, x, S, &ws[r]) != EOM_OK)
                return 1;
        }
        for (k = 0; k < NS; k++) {
            double scale = 0.0, e = 0.0;
            for (i = 0; i < 2 * n; i++) {
                scale = fmax(scale, fabs(fd[i * NS + k]));
                e = fmax(e, fabs(S[i * NS + k] - fd[i * NS + k]));
            }
            worst = fmax(worst, e / scale);
        }
        {
            const double a = bench_median(wn, reps), b = bench_median(ws, reps);
            printf("| %s | %.4f | %ld, %ld | %.4f | %ld, %ld | %.2f | %.1e "
                   "|\n", eom_method_name(methods[m]), a, sn, rn, b,
                   last_steps, last_rhs, b / a, worst);
        }
    }
    return 0;
}

static eom_system *load(const char *dir, const char *file)
{
    char path[1200], err[512];
    eom_model *md = NULL;
    eom_system *s = NULL;
    snprintf(path, sizeof path, "%s/%s", dir, file);
    if (eom_model_from_file(&md, path, err, sizeof err) != EOM_OK ||
        eom_system_new(&s, md, err, sizeof err) != EOM_OK)
        fprintf(stderr, "bench-sensitivity: %s\n", err);
    eom_model_free(&md);
    return s;
}

int main(int argc, char **argv)
{
    const char *dir = NULL;
    eom_system *s = NULL;
    int reps = 5, k, n, np, sens[NS], rc;
    double x0[256];
    for (k = 1; k < argc; k++) {
        if (strcmp(argv[k], "--t-end") == 0 && k + 1 < argc)
            t_end = atof(argv[++k]);
        else if (strcmp(argv[k], "--reps") == 0 && k + 1 < argc)
            reps = atoi(argv[++k]);
        else if (argv[k][0] != '-' && !dir)
            dir = argv[k];
        else {
            fprintf(stderr, "usage: bench-sensitivity [--t-end T] "
                            "[--reps R] MODELS_DIR\n");
            return 2;
        }
    }
    if (!dir || !(t_end > 0.0) || reps < 1 || reps > 99) {
        fprintf(stderr, "usage: bench-sensitivity [--t-end T] [--reps R] "
                        "MODELS_DIR\n");
        return 2;
    }

    if (!(s = load(dir, "open-chain.eom")))
        return 1;
    n = eom_system_ncoords(s);
    np = eom_system_nparams(s);
    if (2 * n > 256 || np > 6) {
        fprintf(stderr, "bench-sensitivity: unexpected model size\n");
        return 1;
    }
    /* damping and gravity on, so that every parameter acts */
    eom_set_param(s, eom_param_index(s, "g"), 9.81);
    eom_set_param(s, eom_param_index(s, "zeta"), 0.02);
    eom_set_param(s, eom_param_index(s, "c"), 5.0);
    for (k = 0; k < np; k++)
        sens[k] = k;
    for (k = np; k < NS; k++) /* theta[1..] and their rates */
        sens[k] = np + (k - np < 2 ? k - np : n + (k - np - 2));
    eom_initial_state(s, x0);
    printf("Open chain (open-chain.eom: 3 links, 2 modes each, %d "
           "coordinates), %g s, rtol 1e-8, atol 1e-10; %d sensitivities "
           "(%d parameters, 4 initial values); median of %d runs, "
           "interleaved\n\n", n, t_end, NS, np, reps);
    rc = table(s, sens, x0, reps);
    eom_system_free(&s);
    if (rc != 0)
        return rc;

    if (!(s = load(dir, "closed-chain.eom")))
        return 1;
    n = eom_system_ncoords(s);
    np = eom_system_nparams(s);
    if (2 * n > 256 || np != 7) {
        fprintf(stderr, "bench-sensitivity: unexpected model size\n");
        return 1;
    }
    eom_set_param(s, eom_param_index(s, "zeta"), 0.02);
    for (k = 0; k < np; k++)
        sens[k] = k;
    /* theta[2], the first link's mode and theta[3]'s rate */
    sens[np] = np + 1;
    sens[np + 1] = np + 5;
    sens[np + 2] = np + n + 2;
    eom_initial_state(s, x0);
    eom_set_time(s, 0.0);
    if (eom_project_start(s, x0, 1e-14, NULL) != EOM_OK) {
        fprintf(stderr, "bench-sensitivity: %s\n", eom_system_errmsg(s));
        return 1;
    }
    printf("\nClosed chain (closed-chain.eom: 5 links, 1 mode each, %d "
           "coordinates, %d constraints), %g s, rtol 1e-8, atol 1e-10; %d "
           "sensitivities (%d parameters, 3 initial values); median of %d "
           "runs, interleaved\n\n", n, eom_system_nconstraints(s), t_end,
           NS, np, reps);
    rc = table(s, sens, x0, reps);
    eom_system_free(&s);
    return rc;
}
