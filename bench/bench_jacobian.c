/* bench_jacobian.c - bench-jacobian: the implicit methods with the exact
 * Jacobian of the equations (the residual tape) against the same methods
 * with SUNDIALS' difference quotients, on the same run, with the error
 * each buys against a tight reference.
 *
 *   1. Open chain of N links (default 50, rigid), hanging from a zig-zag,
 *      1 s, rtol 1e-8, atol 1e-11: bdf, ida and esdirk each way; the
 *      reference is adams at rtol 1e-12, atol 1e-14.
 *   2. The cost of one Jacobian by each route at the chain's initial
 *      state: eom_state_jacobian against 2n right-hand sides (what a
 *      difference quotient costs), and their agreement.
 *
 * Usage: bench-jacobian [--links N] [--modes K] [--t-end T]
 * (--modes: flexible links with K assumed modes each, EI 4e4 as in
 * bench-hard; default 0, rigid).
 * Prints a markdown table (docs/benchmarks.md, section "Exact Jacobians").
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_chain.h"
#include "bench_util.h"
#include "eom/eom.h"

static const double pi = 3.14159265358979323846;

typedef struct result {
    int status;
    long steps, rhs, jacs;
    double wall;
    double *x;
    char msg[256];
} result;

static eom_system *chain(int links, int modes, char *msg, size_t len)
{
    chain_cfg cfg = {0, 0, 0, 4e4 /* bench-hard's flexible chains */, 0.0,
                     9.81, 0.0, 0.0, NULL};
    eom_system *s;
    double *th = malloc((size_t)links * sizeof *th);
    int j;
    if (!th)
        return NULL;
    for (j = 0; j < links; j++)
        th[j] = -pi / 2 + (j % 2 ? -0.3 : 0.3);
    cfg.links = links;
    cfg.modes = modes;
    cfg.theta0 = th;
    s = bench_chain_new(&cfg, msg, len);
    free(th);
    return s;
}

static void run(eom_system *s, eom_method method, int dq, double rtol,
                double atol, double t_end, result *r)
{
    eom_opts o;
    eom_integ *it = NULL;
    eom_stats st;
    double W = 0.0;
    eom_opts_default(&o);
    o.method = method;
    o.rtol = rtol;
    o.atol = atol;
    o.dq_jacobian = dq;
    eom_initial_state(s, r->x);
    r->msg[0] = '\0';
    r->status = eom_integ_new(&it, s, &o, 0.0, r->x);
    if (r->status == EOM_OK)
        r->status = eom_integ_advance(it, t_end, r->x, &W);
    if (r->status != EOM_OK)
        snprintf(r->msg, sizeof r->msg, "%s",
                 it ? eom_integ_errmsg(it) : eom_system_errmsg(s));
    if (it) {
        eom_integ_stats(it, &st);
        r->steps = st.steps;
        r->rhs = st.rhs_evals;
        r->jacs = st.jac_evals;
        r->wall = st.wall_time;
    }
    eom_integ_free(&it);
}

static double error_of(const result *a, const result *ref, int n2)
{
    double e = 0.0;
    int i;
    for (i = 0; i < n2; i++)
        e = fmax(e, fabs(a->x[i] - ref->x[i]));
    return e;
}

static void row(const char *method, const char *jac, const result *r,
                double err)
{
    printf("| %s | %s | %s | %ld | %ld | %ld | %.3f | %.1e |%s%s\n", method,
           jac, r->status == EOM_OK ? "ok" : eom_status_name(r->status),
           r->steps, r->rhs, r->jacs, r->wall, err, r->msg[0] ? " " : "",
           r->msg);
    fflush(stdout);
}

typedef struct jac_ctx {
    eom_system *s;
    const double *x;
    double *A, *xd;
} jac_ctx;

static void one_exact(void *p)
{
    jac_ctx *c = p;
    eom_state_jacobian(c->s, 0.0, c->x, c->A);
}

/* What one difference-quotient Jacobian costs: 2n right-hand sides. */
static void one_dq(void *p)
{
    jac_ctx *c = p;
    const int n2 = 2 * eom_system_ncoords(c->s);
    int j;
    for (j = 0; j < n2; j++)
        eom_rhs(c->s, 0.0, c->x, c->xd);
}

int main(int argc, char **argv)
{
    int links = 50, modes = 0, k, n2;
    double t_end = 1.0;
    char msg[256];
    eom_system *s;
    result ref, r;
    static const eom_method methods[] = {EOM_BDF, EOM_IDA, EOM_ESDIRK};
    for (k = 1; k < argc; k++) {
        if (strcmp(argv[k], "--links") == 0 && k + 1 < argc)
            links = atoi(argv[++k]);
        else if (strcmp(argv[k], "--modes") == 0 && k + 1 < argc)
            modes = atoi(argv[++k]);
        else if (strcmp(argv[k], "--t-end") == 0 && k + 1 < argc)
            t_end = atof(argv[++k]);
        else {
            fprintf(stderr, "usage: bench-jacobian [--links N] [--modes K] "
                            "[--t-end T]\n");
            return 2;
        }
    }
    if (links < 1 || links > 500 || modes < 0 || modes > 8 ||
        !(t_end > 0.0)) {
        fprintf(stderr, "bench-jacobian: links 1 .. 500, modes 0 .. 8 and "
                        "t-end > 0\n");
        return 2;
    }
    s = chain(links, modes, msg, sizeof msg);
    if (!s) {
        fprintf(stderr, "bench-jacobian: %s\n", msg);
        return 1;
    }
    n2 = 2 * eom_system_ncoords(s);
    ref.x = malloc((size_t)n2 * sizeof(double));
    r.x = malloc((size_t)n2 * sizeof(double));
    if (!ref.x || !r.x)
        return 1;

    printf("Open chain, %d links, %d modes each, %g s, rtol 1e-8, atol "
           "1e-11; reference adams 1e-12, 1e-14\n\n", links, modes, t_end);
    run(s, EOM_ADAMS, 0, 1e-12, 1e-14, t_end, &ref);
    if (ref.status != EOM_OK) {
        fprintf(stderr, "bench-jacobian: reference failed: %s\n", ref.msg);
        return 1;
    }
    printf("| method | Jacobian | status | steps | rhs | Jacobians | wall (s) "
           "| state error |\n|---|---|---|---|---|---|---|---|\n");
    row("adams 1e-12 (reference)", "none", &ref, 0.0);
    for (k = 0; k < 3; k++) {
        double wall_dq, wall_ex;
        run(s, methods[k], 1, 1e-8, 1e-11, t_end, &r);
        row(eom_method_name(methods[k]), "difference quotients", &r,
            error_of(&r, &ref, n2));
        wall_dq = r.wall;
        run(s, methods[k], 0, 1e-8, 1e-11, t_end, &r);
        row(eom_method_name(methods[k]), "exact", &r, error_of(&r, &ref, n2));
        wall_ex = r.wall;
        printf("| %s | speed-up | %.2fx |||||\n", eom_method_name(methods[k]),
               wall_dq / wall_ex);
    }

    {
        jac_ctx c;
        double *x = malloc((size_t)n2 * sizeof *x), t_ex, t_dq;
        c.s = s;
        c.A = malloc((size_t)n2 * n2 * sizeof *c.A);
        c.xd = malloc((size_t)n2 * sizeof *c.xd);
        if (!x || !c.A || !c.xd)
            return 1;
        eom_initial_state(s, x);
        for (k = 0; k < n2 / 2; k++)
            x[n2 / 2 + k] = 0.1 * sin(k);
        c.x = x;
        t_ex = bench_time(one_exact, &c,
                          bench_calibrate(one_exact, &c, 0.2));
        t_dq = bench_time(one_dq, &c, bench_calibrate(one_dq, &c, 0.2));
        printf("\nOne Jacobian at a state of the chain: exact %.3f ms, "
               "2n = %d right-hand sides %.3f ms (%.1fx)\n", t_ex * 1e3, n2,
               t_dq * 1e3, t_dq / t_ex);
        free(x);
        free(c.A);
        free(c.xd);
    }
    free(ref.x);
    free(r.x);
    eom_system_free(&s);
    return 0;
}
