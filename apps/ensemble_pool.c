/* ensemble_pool.c - running an ensemble's runs on threads
 * (ensemble_pool.h). */
#define _POSIX_C_SOURCE 200809L
#include "ensemble_pool.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "eom/run.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct ensemble_worker {
    ensemble_job *job;
    eom_system *s; /* this thread's clone */
    double *x, *phi, *row;
    eom_run_columns *cols;
} worker;

/* The run's trajectory, a row at every sample time, into DIR/run-I.csv. */
static int trajectory(worker *w, long i, eom_integ *it, double *W,
                      run_result *r)
{
    ensemble_job *job = w->job;
    char path[4096], err[512];
    eom_csv_writer *cw = NULL;
    eom_run_row_info info;
    long long K, k;
    int exact, rc = 0;
    snprintf(path, sizeof path, "%s/run-%ld.csv", job->traj_dir, i);
    if (eom_csv_writer_open(&cw, path, err, sizeof err) != 0 ||
        eom_csv_writer_header(cw, w->cols->names, w->cols->count, err,
                              sizeof err) != 0) {
        snprintf(r->msg, sizeof r->msg, "%s", err);
        eom_csv_writer_close(&cw, err, sizeof err);
        return -1;
    }
    eom_run_grid(job->t_end, job->sample, &K, &exact);
    for (k = 0; k <= K + !exact && rc == 0; k++) {
        const double t = k <= K ? (double)k * job->sample : job->t_end;
        if (k > 0 && eom_integ_advance(it, t, w->x, W) != EOM_OK) {
            snprintf(r->msg, sizeof r->msg, "%s", eom_integ_errmsg(it));
            rc = -1;
            break;
        }
        eom_run_columns_fill(w->cols, w->s, t, w->x, *W, w->row, &info);
        if (eom_csv_writer_row(cw, w->row, w->cols->count, err,
                               sizeof err) != 0) {
            snprintf(r->msg, sizeof r->msg, "%s", err);
            rc = -1;
        }
    }
    if (eom_csv_writer_close(&cw, err, sizeof err) != 0 && rc == 0) {
        snprintf(r->msg, sizeof r->msg, "%s", err);
        rc = -1;
    }
    return rc;
}

/* Run i on this worker's system. */
void ensemble_worker_run(worker *w, long i, run_result *r)
{
    ensemble_job *job = w->job;
    const ensemble_runs *runs = job->runs;
    const int n = eom_system_ncoords(w->s), m = eom_system_nconstraints(w->s);
    const int np = eom_system_nparams(w->s);
    eom_opts o = job->opts;
    double t_end = job->t_end, W = 0.0, t0 = now(), scale = 0.0;
    eom_run_measures ms = {NAN, NAN, NAN};
    eom_integ *it = NULL;
    eom_energy e;
    eom_stats st;
    int k;

    r->ok = 0;
    r->final = NULL;
    r->E0 = r->energy_error = r->residual = NAN;
    r->steps = r->rhs = 0;
    r->msg[0] = '\0';
    memcpy(w->x, job->x0, 2 * (size_t)n * sizeof *w->x);
    for (k = 0; k < np; k++)
        eom_set_param(w->s, k, job->p0[k]);
    for (k = 0; k < runs->ncols; k++) {
        const double v = runs->v[i * runs->ncols + k];
        const int j = runs->index[k];
        switch (runs->kind[k]) {
        case RUN_PARAM:
            if (eom_set_param(w->s, j, v) != EOM_OK) {
                snprintf(r->msg, sizeof r->msg, "%s = %g: %s",
                         runs->names[k], v, eom_system_errmsg(w->s));
                goto out;
            }
            break;
        case RUN_COORD: w->x[j] = v; break;
        case RUN_RATE: w->x[n + j] = v; break;
        case RUN_T_END: t_end = v; break;
        case RUN_RTOL: o.rtol = v; break;
        case RUN_ATOL: o.atol = v; break;
        default: o.dt = v; break;
        }
    }
    if (!(t_end >= 0.0) || !isfinite(t_end)) {
        snprintf(r->msg, sizeof r->msg, "t_end = %g is not >= 0", t_end);
        goto out;
    }
    /* every run starts at t = 0: the worker's system was left at the end
     * of its previous run (a model that reads the time sees it) */
    eom_set_time(w->s, 0.0);
    /* a start off the constraints is projected, as eom-run does */
    if (m > 0 && o.project) {
        double pmax = 0.0, vmax = 0.0;
        if (eom_residuals(w->s, w->x, w->phi, w->phi + m) == EOM_OK)
            for (k = 0; k < m; k++) {
                pmax = fmax(pmax, fabs(w->phi[k]));
                vmax = fmax(vmax, fabs(w->phi[m + k]));
            }
        if ((pmax > o.proj_tol || vmax > o.proj_tol) &&
            eom_project_start(w->s, w->x, o.proj_tol, NULL) != EOM_OK) {
            snprintf(r->msg, sizeof r->msg, "the start cannot be projected "
                     "onto the constraints: %s", eom_system_errmsg(w->s));
            goto out;
        }
    }
    if (eom_energy_at(w->s, 0.0, w->x, &e) == EOM_OK) {
        r->E0 = e.E;
        scale = fmax(fabs(e.E), fabs(e.L));
    }
    if (eom_integ_new(&it, w->s, &o, 0.0, w->x) != EOM_OK) {
        snprintf(r->msg, sizeof r->msg, "%s", eom_system_errmsg(w->s));
        goto out;
    }
    if (job->traj_dir) {
        if (trajectory(w, i, it, &W, r) != 0)
            goto stats;
    } else if (t_end > 0.0 &&
               eom_integ_advance(it, t_end, w->x, &W) != EOM_OK) {
        snprintf(r->msg, sizeof r->msg, "%s", eom_integ_errmsg(it));
        goto stats;
    }
    ms.drift_rel = ms.phidot_max = NAN;
    if (eom_energy_at(w->s, t_end, w->x, &e) == EOM_OK) {
        r->energy_error = e.E + W - r->E0;
        scale = fmax(scale, fmax(fabs(e.E), fabs(e.L)));
        if (scale > 0.0)
            ms.drift_rel = fabs(r->energy_error) / scale;
    }
    r->residual = 0.0;
    if (m > 0 && eom_residuals(w->s, w->x, w->phi, w->phi + m) == EOM_OK) {
        ms.phidot_max = 0.0;
        for (k = 0; k < m; k++) {
            r->residual = fmax(r->residual, fabs(w->phi[k]));
            ms.phidot_max = fmax(ms.phidot_max, fabs(w->phi[m + k]));
        }
    }
    r->final = malloc(2 * (size_t)n * sizeof *r->final);
    if (!r->final) {
        snprintf(r->msg, sizeof r->msg, "out of memory");
        goto stats;
    }
    memcpy(r->final, w->x, 2 * (size_t)n * sizeof *r->final);
    r->ok = 1;
stats:
    if (eom_integ_stats(it, &st) == EOM_OK) {
        r->steps = st.steps;
        r->rhs = st.rhs_evals;
        if (r->ok) {
            /* the verdict of eom-run, from the ends of the run: its
             * drift at t_end, its residual there and after every step */
            eom_run_verdict v;
            ms.phi_max = fmax(r->residual, st.max_residual);
            eom_run_judge(&o, &st, &ms, &v);
            if (!v.healthy) {
                r->ok = 2;
                snprintf(r->msg, sizeof r->msg, "unhealthy: %s", v.text);
            }
        }
    }
out:
    eom_integ_free(&it);
    r->wall = now() - t0;
}

int ensemble_job_stopped(const ensemble_job *job)
{
    return job->halt || (job->stop && *job->stop);
}

void ensemble_job_halt(ensemble_job *job)
{
    pthread_mutex_lock(&job->lock);
    job->halt = 1;
    pthread_mutex_unlock(&job->lock);
}

long ensemble_job_next(ensemble_job *job)
{
    long i;
    pthread_mutex_lock(&job->lock);
    if (ensemble_job_stopped(job)) {
        pthread_mutex_unlock(&job->lock);
        return -1;
    }
    while (job->next < job->runs->nruns && job->skip &&
           job->skip[job->next])
        job->next++;
    i = job->next < job->runs->nruns ? job->next++ : -1;
    pthread_mutex_unlock(&job->lock);
    return i;
}

void ensemble_worker_free(worker **wp)
{
    worker *w = wp ? *wp : NULL;
    if (!w)
        return;
    eom_run_columns_free(&w->cols);
    eom_system_free(&w->s);
    free(w->x);
    free(w->phi);
    free(w->row);
    free(w);
    *wp = NULL;
}

worker *ensemble_worker_new(ensemble_job *job)
{
    const int n = eom_system_ncoords(job->base);
    const int m = eom_system_nconstraints(job->base);
    worker *w = calloc(1, sizeof *w);
    char err[512] = "out of memory";
    if (!w) {
        fprintf(stderr, "eom-ensemble: out of memory\n");
        return NULL;
    }
    w->job = job;
    w->x = malloc((2 * (size_t)n + 1) * sizeof *w->x);
    w->phi = malloc((2 * (size_t)m + 1) * sizeof *w->phi);
    if (!w->x || !w->phi ||
        eom_system_clone(&w->s, job->base, err, sizeof err) != EOM_OK ||
        (job->traj_dir &&
         (eom_run_columns_new(&w->cols, w->s, 0, err, sizeof err) != 0 ||
          !(w->row = malloc((size_t)w->cols->count * sizeof *w->row))))) {
        fprintf(stderr, "eom-ensemble: a worker cannot start: %s\n", err);
        ensemble_worker_free(&w);
        return NULL;
    }
    return w;
}

static void *work(void *p)
{
    worker *w = p;
    ensemble_job *job = w->job;
    long i;
    while ((i = ensemble_job_next(job)) >= 0) {
        ensemble_worker_run(w, i, &job->res[i]);
        pthread_mutex_lock(&job->lock);
        job->res[i].done = 1;
        pthread_cond_broadcast(&job->cond);
        pthread_mutex_unlock(&job->lock);
    }
    ensemble_worker_free(&w);
    return NULL;
}

int ensemble_pool_start(ensemble_job *job, int threads, pthread_t *th)
{
    int k, started = 0;
    for (k = 0; k < threads; k++) {
        worker *w = ensemble_worker_new(job);
        if (!w)
            continue;
        if (pthread_create(&th[started], NULL, work, w) != 0) {
            fprintf(stderr, "eom-ensemble: thread %d cannot start\n", k);
            ensemble_worker_free(&w);
            continue;
        }
        started++;
    }
    return started;
}

int ensemble_pool_wait(ensemble_job *job, long i)
{
    int done;
    pthread_mutex_lock(&job->lock);
    while (!job->res[i].done &&
           !(ensemble_job_stopped(job) && i >= job->next)) {
        /* a signal cannot wake a condition (a handler may not broadcast):
         * look at the flag ten times a second */
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        ts.tv_nsec += 100000000L;
        if (ts.tv_nsec >= 1000000000L) {
            ts.tv_sec++;
            ts.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&job->cond, &job->lock, &ts);
    }
    done = job->res[i].done;
    pthread_mutex_unlock(&job->lock);
    return done;
}
