/* wp_table.c - the markdown tables of the work-precision benchmark (see
 * wp_table.h). Every speed figure is printed beside the error it was
 * bought with; a failed run keeps its row, with the solver's message in
 * place of the errors. */
#include "wp_table.h"

#include <math.h>
#include <string.h>

#include "wp_interp.h"

void wp_ms_text(double seconds, char *buf, size_t len)
{
    const double ms = 1e3 * seconds;
    if (!isfinite(ms))
        snprintf(buf, len, "-");
    else if (ms >= 100.0)
        snprintf(buf, len, "%.0f", ms);
    else if (ms >= 10.0)
        snprintf(buf, len, "%.1f", ms);
    else if (ms >= 1.0)
        snprintf(buf, len, "%.2f", ms);
    else
        snprintf(buf, len, "%.3f", ms);
}

/* A message in a table cell: '|' would end the cell unescaped, a newline
 * the row. */
static void cell_text(FILE *f, const char *s)
{
    for (; *s; s++) {
        if (*s == '|')
            fputc('\\', f);
        fputc(*s == '\n' ? ' ' : *s, f);
    }
}

static void err_cell(FILE *f, double e)
{
    if (isfinite(e))
        fprintf(f, " %.2e |", e);
    else
        fputs(" - |", f);
}

static void row(FILE *f, const wp_sweep *w, const wp_run *r)
{
    char set[32], ms[32], cpu[32];
    wp_setting_text(&r->set, set, sizeof set);
    wp_ms_text(r->wall, ms, sizeof ms);
    wp_ms_text(r->cpu, cpu, sizeof cpu);
    fprintf(f, "| %s | %s | %s | %s | %d | %ld | %ld | %ld |",
            eom_method_name(r->set.method), set, ms, cpu, r->reps, r->steps,
            r->rhs, r->failures);
    err_cell(f, r->err);
    err_cell(f, r->err_angle);
    err_cell(f, r->status == EOM_OK ? r->energy_err : NAN);
    if (w->m > 0) {
        err_cell(f, r->status == EOM_OK ? r->phi_max : NAN);
        err_cell(f, r->drift);
    }
    fputc(' ', f);
    if (r->status != EOM_OK) {
        fprintf(f, "failed: %s: ", eom_status_name(r->status));
        cell_text(f, r->msg);
    }
    if (r->irreproducible)
        fputs(" repetitions differ", f);
    fputs(" |\n", f);
}

/* Sum of the best wall times over the sum of the best CPU times of the
 * sweep's runs: about 1 when the benchmark had a core to itself. */
static double load_ratio(const wp_sweep *w)
{
    double wall = 0.0, cpu = 0.0;
    int k, j;
    for (k = 0; k < WP_NMETHODS; k++)
        for (j = 0; j < w->count[k]; j++) {
            wall += w->runs[w->first[k] + j].wall;
            cpu += w->runs[w->first[k] + j].cpu;
        }
    return cpu > 0.0 ? wall / cpu : NAN;
}

void wp_table_write(FILE *f, const wp_sweep *w)
{
    const wp_plan *p = w->plan;
    char ms[32];
    int k, j;
    wp_ms_text(w->ref.wall, ms, sizeof ms);
    fprintf(f, "## %s\n\n", w->demo);
    fprintf(f, "t = 0 .. %g s from the default start; %d coordinates, %d "
            "constraints; samples every %g s.\n\n", p->t_end, w->n, w->m,
            p->sample);
    fprintf(f, "Reference: %s at rtol %.0e, atol %.0e (%ld steps, %s ms). "
            "Its check, %s at rtol %.0e, atol %.0e, differs from it by %.2e "
            "at t = %g (angles: %.2e): errors below that are not "
            "measurable.\n\n", eom_method_name(w->ref.set.method),
            w->ref.set.rtol, w->ref.set.atol, w->ref.steps, ms,
            eom_method_name(w->check.set.method), w->check.set.rtol,
            w->check.set.atol, w->floor, p->t_end, w->floor_angle);
    fprintf(f, "Wall time over CPU time, summed over the runs: %.2f (1 when "
            "the benchmark had a core to itself).\n\n", load_ratio(w));
    fprintf(f, "Columns: **error** max abs(x - x_ref) over all %d "
            "coordinates and rates at t = %g; **angle error** the same over "
            "the angles only; **energy error** max abs(E + W - E0) / "
            "max(abs(E0), T0 + abs(V0)) over the samples; **steps**, "
            "**rhs** (model evaluations, all causes) and **failed steps** "
            "from eom_stats.", 2 * w->n, p->t_end);
    if (w->m > 0)
        fputs(" **max abs(phi)**: the constraint residual on the samples, "
              "as the caller gets the state; **drift abs(phi)**: the "
              "largest residual found before a projection (eom_stats' "
              "max_residual).", f);
    fputs("\n\n", f);
    fprintf(f, "| method | setting | wall time (ms) | cpu (ms) | reps | "
            "steps | rhs | failed steps | error | angle error | energy "
            "error |%s note |\n",
            w->m > 0 ? " max abs(phi) | drift abs(phi) |" : "");
    fprintf(f, "|---|---|---|---|---|---|---|---|---|---|---|%s---|\n",
            w->m > 0 ? "---|---|" : "");
    for (k = 0; k < WP_NMETHODS; k++)
        for (j = 0; j < w->count[k]; j++)
            row(f, w, &w->runs[w->first[k] + j]);
    if (w->rk4_stopped > 0)
        fprintf(f, "\nrk4 stopped after its error fell below %.0e: the %d "
                "smaller steps of the plan were not run.\n", p->rk4_stop,
                w->rk4_stopped);
    fputc('\n', f);
}

/* The time method k needs for target, as table text; *t receives it
 * (NAN when not reached). */
static void reach_cell(const wp_sweep *w, int k, double target, double *t,
                       char *buf, size_t len)
{
    char ms[32];
    const wp_reach how = wp_time_at_error(&w->runs[w->first[k]], w->count[k],
                                          target, 0, t);
    wp_ms_text(*t, ms, sizeof ms);
    if (how == WP_NOT_REACHED)
        snprintf(buf, len, "not reached");
    else if (how == WP_AT_LOOSEST)
        snprintf(buf, len, "<= %s", ms);
    else
        snprintf(buf, len, "%s", ms);
}

void wp_summary_write(FILE *f, const wp_sweep *w, int nw,
                      const double *targets, int nt)
{
    /* the columns: every demo's plan sweeps the same methods */
    const int nmeth = nw > 0 ? w[0].plan->nmethods : 0;
    int d, i, k;
    fputs("## Summary: time to reach a state error\n\n"
          "Wall time in ms to reach the state error at t-end, interpolated "
          "log-log between the two runs of a method's sweep that bracket "
          "it. \"<=\" : the method's loosest setting was already that "
          "accurate, so its time is an upper bound. The last column is "
          "rk4's time over the fastest adaptive method's.\n\n", f);
    fputs("| demo | error |", f);
    for (k = 0; k < nmeth; k++)
        fprintf(f, " %s |", eom_method_name((eom_method)k));
    fputs(" fastest | rk4 / best adaptive |\n|---|---|", f);
    for (k = 0; k < nmeth; k++)
        fputs("---|", f);
    fputs("---|---|\n", f);
    for (d = 0; d < nw; d++)
        for (i = 0; i < nt; i++) {
            double t[WP_NMETHODS], best = INFINITY, best_ad = INFINITY;
            int kbest = -1;
            char buf[64];
            fprintf(f, "| %s | %.0e |", w[d].demo, targets[i]);
            for (k = 0; k < nmeth; k++) {
                reach_cell(&w[d], k, targets[i], &t[k], buf, sizeof buf);
                fprintf(f, " %s |", buf);
                if (isfinite(t[k]) && t[k] < best) {
                    best = t[k];
                    kbest = k;
                }
                if (k != EOM_RK4 && isfinite(t[k]) && t[k] < best_ad)
                    best_ad = t[k];
            }
            fprintf(f, " %s |", kbest >= 0 ? eom_method_name((eom_method)kbest)
                                            : "none");
            if (isfinite(t[EOM_RK4]) && isfinite(best_ad))
                fprintf(f, " %.1f |\n", t[EOM_RK4] / best_ad);
            else
                fputs(" - |\n", f);
        }
    fputc('\n', f);
}
