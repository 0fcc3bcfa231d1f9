/* wp_run.c - one timed integration of the work-precision benchmark (see
 * wp_run.h). The clock runs only inside eom_integ_new and
 * eom_integ_advance, so the energy and residual evaluations on the
 * samples never count as the integrator's time. */
#define _POSIX_C_SOURCE 200809L
#include "wp_run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

double wp_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double wp_cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The two clocks, started together and read together. */
typedef struct stopwatch {
    double wall, cpu;
} stopwatch;

static stopwatch watch_start(void)
{
    stopwatch w;
    w.wall = wp_now();
    w.cpu = wp_cpu_now();
    return w;
}

/* Add the time since w to *acc. */
static void watch_add(stopwatch w, stopwatch *acc)
{
    acc->cpu += wp_cpu_now() - w.cpu;
    acc->wall += wp_now() - w.wall;
}

static void opts_of(const wp_setting *set, eom_opts *o)
{
    eom_opts_default(o);
    o->method = set->method;
    if (set->method == EOM_RK4) {
        o->dt = set->dt;
    } else {
        o->dt = 0.0; /* the solver's own first step */
        o->rtol = set->rtol;
        o->atol = set->atol;
    }
    /* per advance; with samples every 0.1 s never reached, but stated so
     * that a tight tolerance cannot stop a run on SUNDIALS' default 500 */
    o->max_steps = 10000000L;
}

/* The integration itself. measure: evaluate energy and residuals on the
 * samples into r. Writes the final state to x, the times to *spent, the
 * statistics to *st. Returns the status (and the message in r->msg when
 * measure is set). */
static int integrate(eom_system *s, const double *x0, double t_end,
                     double sample, const wp_setting *set, int measure,
                     wp_run *r, double *x, stopwatch *spent, eom_stats *st)
{
    const int m = eom_system_nconstraints(s);
    const long nsamp = (long)ceil(t_end / sample - 1e-9);
    eom_opts o;
    eom_integ *it = NULL;
    eom_energy e0, e;
    double W = 0.0, scale = 1.0, phi[64];
    stopwatch t0;
    int status, i;
    long k;

    opts_of(set, &o);
    memset(st, 0, sizeof *st);
    if (measure && eom_energy_at(s, 0.0, x0, &e0) == EOM_OK)
        scale = fmax(fabs(e0.E), fabs(e0.T) + fabs(e0.V));
    spent->wall = spent->cpu = 0.0;
    t0 = watch_start();
    status = eom_integ_new(&it, s, &o, 0.0, x0);
    watch_add(t0, spent);
    if (status != EOM_OK) {
        if (measure)
            snprintf(r->msg, sizeof r->msg, "%s", eom_system_errmsg(s));
        return status;
    }
    for (k = 1; k <= nsamp; k++) {
        const double t = k == nsamp ? t_end : (double)k * sample;
        t0 = watch_start();
        status = eom_integ_advance(it, t, x, &W);
        watch_add(t0, spent);
        if (status != EOM_OK) {
            if (measure)
                snprintf(r->msg, sizeof r->msg, "%s", eom_integ_errmsg(it));
            break;
        }
        if (!measure)
            continue;
        if (eom_energy_at(s, t, x, &e) == EOM_OK)
            r->energy_err = fmax(r->energy_err, fabs(e.E + W - e0.E) / scale);
        else /* fmax would drop a NaN */
            r->energy_err = INFINITY;
        if (m > 0 && m <= 64 && eom_residuals(s, x, phi, NULL) == EOM_OK)
            for (i = 0; i < m; i++)
                r->phi_max = fmax(r->phi_max, fabs(phi[i]));
    }
    eom_integ_stats(it, st);
    eom_integ_free(&it);
    return status;
}

int wp_run_first(eom_system *s, const double *x0, double t_end,
                 double sample, wp_run *r)
{
    eom_stats st;
    stopwatch spent;
    const int n = eom_system_ncoords(s);
    memcpy(r->x, x0, 2 * (size_t)n * sizeof(double));
    r->msg[0] = '\0';
    r->energy_err = r->phi_max = 0.0;
    r->err = r->err_angle = NAN;
    r->irreproducible = 0;
    r->status = integrate(s, x0, t_end, sample, &r->set, 1, r, r->x, &spent,
                          &st);
    r->wall = spent.wall;
    r->cpu = spent.cpu;
    r->reps = 1;
    r->steps = st.steps;
    r->rhs = st.rhs_evals;
    r->failures = st.failures;
    r->jacs = st.jac_evals;
    r->drift = st.max_residual;
    return r->status;
}

void wp_run_again(eom_system *s, const double *x0, double t_end,
                  double sample, wp_run *r, double *tmp)
{
    eom_stats st;
    stopwatch spent;
    const int n = eom_system_ncoords(s);
    int status;
    memcpy(tmp, x0, 2 * (size_t)n * sizeof(double));
    status = integrate(s, x0, t_end, sample, &r->set, 0, r, tmp, &spent, &st);
    r->reps++;
    r->wall = fmin(r->wall, spent.wall);
    r->cpu = fmin(r->cpu, spent.cpu);
    if (status != r->status || st.steps != r->steps ||
        (status == EOM_OK &&
         memcmp(tmp, r->x, 2 * (size_t)n * sizeof(double)) != 0))
        r->irreproducible = 1;
}

void wp_setting_text(const wp_setting *set, char *buf, size_t len)
{
    if (set->method == EOM_RK4)
        snprintf(buf, len, "dt = %.0e", set->dt);
    else
        snprintf(buf, len, "rtol = %.0e", set->rtol);
}
