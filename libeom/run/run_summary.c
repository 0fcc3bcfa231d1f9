/* run_summary.c - the end-of-run report (see run_summary.h). */
#include "run_summary.h"

#include <math.h>
#include <string.h>

void run_summary_init(run_summary *r)
{
    r->rows = 0;
    r->t_last = 0.0;
    r->E0 = NAN;
    r->drift = 0.0;
    r->scale = 0.0;
    r->phi_max = 0.0;
    r->phidot_max = 0.0;
}

void run_summary_add(run_summary *r, double t, double W,
                     const eom_run_row_info *info)
{
    /* fmax ignores a NaN operand, so a row whose energies could not be
     * computed leaves the maxima alone */
    if (r->rows == 0)
        r->E0 = info->e.E;
    r->rows++;
    r->t_last = t;
    r->drift = fmax(r->drift, fabs(info->e.E + W - r->E0));
    r->scale = fmax(r->scale, fmax(fabs(info->e.E), fabs(info->e.L)));
    r->phi_max = fmax(r->phi_max, info->phi_max);
    r->phidot_max = fmax(r->phidot_max, info->phidot_max);
}

void run_summary_measures(const run_summary *r, const eom_stats *st,
                          eom_run_measures *m)
{
    m->drift_rel = r->scale > 0.0 ? r->drift / r->scale : NAN;
    m->phi_max = st ? fmax(r->phi_max, st->max_residual) : r->phi_max;
    m->phidot_max = r->phidot_max;
}

void run_summary_print(const run_summary *r, FILE *f, const char *prog,
                       const char *label,
                       const char *method, const eom_stats *st,
                       const char *vel,
                       int nconstraints, double wall,
                       const eom_run_verdict *v)
{
    eom_stats zero;
    memset(&zero, 0, sizeof zero);
    zero.min_rcond_S = 1.0;
    if (!st)
        st = &zero;
    fprintf(f, "%s: %s with %s: %ld row%s, t = 0 .. %.10g\n", prog, label,
            method, r->rows, r->rows == 1 ? "" : "s", r->t_last);
    fprintf(f, "  steps %ld, right-hand sides %ld, failed steps %ld, "
            "Jacobians %ld%s\n", st->steps, st->rhs_evals, st->failures,
            st->jac_evals,
            st->linear_solver == EOM_LINSOL_SPARSE  ? " (sparse, KLU)"
            : st->linear_solver == EOM_LINSOL_DENSE ? " (dense LU)"
                                                    : "");
    fprintf(f, "  wall time %.3g s (integrator %.3g s)\n", wall,
            st->wall_time);
    if (st->mass_route == EOM_MASS_CONSTANT)
        fprintf(f, "  mass matrix: constant, formed and factored once "
                "(docs/libeom.md, \"The mass matrix's route\")\n");
    if (st->mass_route == EOM_MASS_SPARSE)
        fprintf(f, "  mass matrix: constant, with the constraints one "
                "sparse system (KLU) away from singular positions "
                "(docs/libeom.md, \"The mass matrix's route\")\n");
    if (st->tol_reachable > 0.0)
        fprintf(f, "  tolerance: tighter than %s allows this method's error "
                "test; it keeps the error near %.2g instead (docs/"
                "integrators.md, \"What the tolerances mean\")\n",
                nconstraints > 0 ? "a model with constraints"
                                 : "double precision",
                st->tol_reachable);
    if (r->scale > 0.0)
        fprintf(f, "  energy drift max |E + W - E0| = %.3g, relative %.3g "
                "(scale %.6g)\n", r->drift, r->drift / r->scale, r->scale);
    else
        fprintf(f, "  energy drift max |E + W - E0| = %.3g (energy scale "
                "zero: no relative drift)\n", r->drift);
    if (nconstraints > 0) {
        fprintf(f, "  constraint residual max |phi| = %.3g, max |%s| = "
                "%.3g, projections %ld\n",
                fmax(r->phi_max, st->max_residual), vel, r->phidot_max,
                st->projections);
        fprintf(f, "  constraint system: smallest rcond %.3g, %ld SVD "
                "solve%s%s\n", st->min_rcond_S, st->svd_solves,
                st->svd_solves == 1 ? "" : "s",
                st->svd_solves ? " (redundant constraints or a near-singular "
                                 "configuration)" : "");
        if (st->branch_switches > 0)
            fprintf(f, "  singular positions passed %ld, branch switches %ld "
                    "(the first at t = %.6g: the motion jumped to another "
                    "assembly of the mechanism; check it, or use bdf, erk "
                    "or rk4 with a tighter tolerance)\n", st->singular_passes,
                    st->branch_switches, st->first_branch_switch);
        else
            fprintf(f, "  singular positions passed %ld, branch switches 0\n",
                    st->singular_passes);
        if (st->singular_handovers > st->singular_handovers_erk)
            fprintf(f, "  singular stretches handed to bdf %ld (%s cannot "
                    "pass them; it restarts after each)\n",
                    st->singular_handovers - st->singular_handovers_erk,
                    method);
        if (st->singular_handovers_erk > 0)
            fprintf(f, "  singular stretches handed to erk %ld (%s could "
                    "not pass them%s; it restarts after each)\n",
                    st->singular_handovers_erk, method,
                    strcmp(method, "adams") == 0 || strcmp(method, "ida") == 0
                        ? ", nor bdf"
                        : "");
    } else {
        fprintf(f, "  constraint residual: none (no constraints)\n");
    }
    if (v && v->healthy && nconstraints > 0)
        fprintf(f, "  verdict: healthy (relative energy drift within "
                "%.3g, constraint residuals within %.3g, no branch "
                "switch)\n", v->energy_threshold, v->residual_threshold);
    else if (v && v->healthy)
        fprintf(f, "  verdict: healthy (relative energy drift within "
                "%.3g)\n", v->energy_threshold);
    else if (v)
        fprintf(f, "  verdict: unhealthy: %s\n", v->text);
}
