/* ensemble_pool.h - the runs of an ensemble on K threads. Each thread
 * works on its own clone of the system (eom_system_clone: the tapes are
 * shared, read-only) and takes the next run as soon as it is free
 * (dynamic scheduling: run times may differ by orders of magnitude). A
 * run's numbers depend only on its inputs, so they are the same whatever
 * the number of threads and the order in which runs finish. */
#ifndef APPS_ENSEMBLE_POOL_H
#define APPS_ENSEMBLE_POOL_H

#include <pthread.h>
#include <signal.h>

#include "ensemble_runs.h"
#include "eom/eom.h"

typedef struct run_result {
    int done;          /* the worker has finished it */
    int ok;            /* 0: failed, see msg; 1: ok; 2: reached t_end
                          but unhealthy (eom_run_judge), msg names the
                          measure */
    double *final;     /* [2n] the state at t_end (NULL when failed early) */
    double E0;         /* E at the start */
    double energy_error; /* E + W - E0 at t_end */
    double residual;   /* max |phi| at t_end (0 without constraints) */
    double wall;       /* seconds */
    long steps, rhs;
    char msg[640];     /* why it failed ("" when it did not) */
} run_result;

typedef struct ensemble_job {
    /* read-only while the pool runs */
    eom_system *base;          /* cloned once per thread */
    const ensemble_runs *runs;
    const double *x0;          /* [2n] the start every run modifies */
    const double *p0;          /* [np] the parameter values it starts from */
    eom_opts opts;
    double t_end, sample;      /* sample: rows of the trajectories */
    const char *traj_dir;      /* write DIR/run-K.csv for each run, or NULL */
    const char *label;
    const unsigned char *skip; /* [nruns] already in the summary */
    const volatile sig_atomic_t *stop; /* NULL, or non-zero when a
                                  signal asked to stop (cli_stop.h) */
    /* shared, under lock */
    run_result *res;           /* [nruns] */
    long next;                 /* runs below it were handed out */
    int halt;                  /* hand out no more runs (a write failed) */
    pthread_mutex_t lock;
    pthread_cond_t cond;
} ensemble_job;

/* One worker: a clone of job->base with its buffers, for one thread or
 * one MPI rank. */
typedef struct ensemble_worker ensemble_worker;
/* NULL after a message on standard error. */
ensemble_worker *ensemble_worker_new(ensemble_job *job);
void ensemble_worker_free(ensemble_worker **w);
/* Run i of job->runs on w into *r (r->done is left to the caller). */
void ensemble_worker_run(ensemble_worker *w, long i, run_result *r);
/* The next run not yet handed out and not skipped, or -1: none left,
 * or the job stopped (ensemble_job_stopped). Takes job->lock. */
long ensemble_job_next(ensemble_job *job);

/* Start threads workers on job (job->res allocated, job->next = 0, the
 * lock and condition initialized by the caller). th receives the thread
 * handles. Returns the number started (each has its own clone; a thread
 * that could not start or clone is reported on standard error and the
 * others carry on), 0 if none. */
int ensemble_pool_start(ensemble_job *job, int threads, pthread_t *th);

/* Whether the job hands out no more runs: *job->stop is set or
 * job->halt (call under job->lock). */
int ensemble_job_stopped(const ensemble_job *job);

/* Stop handing out runs (a write failed): the runs under way finish. */
void ensemble_job_halt(ensemble_job *job);

/* Wait until run i is done: 1, or 0 when it never will be (the job
 * stopped before handing it out). Takes job->lock. */
int ensemble_pool_wait(ensemble_job *job, long i);

#endif /* APPS_ENSEMBLE_POOL_H */
