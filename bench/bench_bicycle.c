/* bench_bicycle.c - the Whipple bicycle (models/whipple-bicycle.eom):
 * reading and recording it, and one right-hand side interpreted and
 * compiled (eom_system_set_compiled; the velocity constraints' tape stays
 * interpreted), after checking that both give the same right-hand side
 * at the start. Medians of repeated batches, measured in one run.
 *
 * usage: bench-bicycle [--quick] MODELS_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "eom/model_file.h"

typedef struct rhs_ctx {
    eom_system *s;
    double x[16], xd[16];
} rhs_ctx;

static void one_rhs(void *p)
{
    rhs_ctx *c = p;
    c->x[3] += 1e-12;
    eom_rhs(c->s, 0.0, c->x, c->xd);
}

static double rhs_median(rhs_ctx *c, int quick)
{
    double t[7];
    long batch = bench_calibrate(one_rhs, c, quick ? 0.01 : 0.2);
    int k;
    for (k = 0; k < 7; k++)
        t[k] = bench_time(one_rhs, c, batch);
    return bench_median(t, 7);
}

int main(int argc, char **argv)
{
    int quick = argc > 1 && strcmp(argv[1], "--quick") == 0, k;
    const char *dir = argc > 1 + quick ? argv[1 + quick] : "models";
    char path[4096], err[2048];
    eom_model *m = NULL;
    rhs_ctx c;
    eom_compiled_info info;
    double t0, t_load, t_interp, t_comp, xd[16], diff = 0.0;
    int st;
    snprintf(path, sizeof path, "%s/whipple-bicycle.eom", dir);
    t0 = bench_now();
    if (eom_model_from_file(&m, path, err, sizeof err) != EOM_OK ||
        eom_system_new(&c.s, m, err, sizeof err) != EOM_OK) {
        fprintf(stderr, "bench-bicycle: %s\n", err);
        eom_model_free(&m);
        return 1;
    }
    t_load = bench_now() - t0;
    eom_model_free(&m);
    eom_initial_state(c.s, c.x);
    eom_rhs(c.s, 0.0, c.x, xd);
    t_interp = rhs_median(&c, quick);
    st = eom_system_set_compiled(c.s, 1, &info);
    printf("Whipple bicycle (8 coordinates, 1 holonomic and 4 velocity "
           "constraints)\n");
    printf("  read and record: %.2f ms\n", 1e3 * t_load);
    printf("  right-hand side, interpreted: %.2f us\n", 1e6 * t_interp);
    if (st != EOM_OK) {
        printf("  compiled tapes unavailable here: %s\n",
               eom_system_errmsg(c.s));
        eom_system_free(&c.s);
        return 0;
    }
    eom_initial_state(c.s, c.x);
    eom_rhs(c.s, 0.0, c.x, c.xd);
    for (k = 0; k < 16; k++)
        diff = fmax(diff, fabs(c.xd[k] - xd[k]) / fmax(1.0, fabs(xd[k])));
    t_comp = rhs_median(&c, quick);
    printf("  right-hand side, compiled (%d tapes, %.2f s to build): %.2f "
           "us, %.2f times faster; largest relative difference from the "
           "interpreter %.2g\n", info.tapes, info.seconds, 1e6 * t_comp,
           t_interp / t_comp, diff);
    eom_system_free(&c.s);
    return diff <= 1e-13 ? 0 : 1;
}
