/* test_ensemble_mpi_serve.c - rank 0's bookkeeping in eom-ensemble over
 * MPI (apps/ensemble_mpi.c), driven directly under `mpirun -np 3`.
 *
 * In eom-ensemble rank 0's own threads nearly always take run 0 before a
 * worker's request is served, so a rank 0 that miscounted the workers
 * still running when it hands run 0 to one of them went unseen. Here rank
 * 0 runs no threads: it only serves, as ensemble_mpi_serve does inside
 * eom-ensemble's wait_for and finish_ranks. Rank 1 works from the start
 * and so takes every run, run 0 first; rank 2 starts only when rank 0
 * has every result (told so on a communicator of the test's own), so its
 * first request reaches rank 0 after the runs are out. Rank 0 must then
 * still count rank 2 as waiting (active > 0), serve its request and tell
 * it to stop. A rank 0 that counted rank 1 as stopped when it handed out
 * run 0 leaves rank 2 waiting for ever: rank 0 notices (rank 2 never says
 * goodbye within a minute, where it takes milliseconds), says so and
 * aborts, and the test fails instead of hanging.
 *
 * Checked as well: every run's result arrived whole, bit for bit the
 * result of the same run done on rank 0 itself (final state, E0, steps,
 * evaluations), and active ends at 0 exactly.
 *
 * usage: mpirun -np 3 test_ensemble_mpi_serve */
#define _POSIX_C_SOURCE 200809L
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "ensemble_mpi.h"
#include "eom/eom.h"
#include "eom/model_file.h"

#define NRUNS 3

static const char spring[] =
    "param m = 1 [kg]\nparam k = 75 [N/m]\nparam r0 = 1 [m]\n"
    "param g = 9.81 [m/s^2]\ncoord r = 1.1 [m] rate 0.2\n"
    "coord theta = 0.5 [rad]\n"
    "T = 1/2*m*(r_dot^2 + r^2*theta_dot^2)\n"
    "V = 1/2*k*(r - r0)^2 + m*g*(r0 - r*cos(theta))\n";

enum { TAG_GO = 11, TAG_BYE = 12 };

static void nap(void)
{
    const struct timespec t = {0, 500000}; /* 0.5 ms */
    nanosleep(&t, NULL);
}

static int all_done(ensemble_job *job)
{
    long i;
    int done = 1;
    pthread_mutex_lock(&job->lock);
    for (i = 0; i < job->runs->nruns; i++)
        done = done && job->res[i].done;
    pthread_mutex_unlock(&job->lock);
    return done;
}

/* Rank 0: wait for a goodbye from every worker on ctl, for at most a
 * minute (each comes milliseconds after its rank is told to stop); 0, or
 * the first rank that never said it. */
static int goodbyes(MPI_Comm ctl, int size)
{
    const double until = MPI_Wtime() + 60.0;
    int r, got = 0, flag, seen[64] = {0};
    while (got < size - 1 && MPI_Wtime() < until) {
        MPI_Status st;
        MPI_Iprobe(MPI_ANY_SOURCE, TAG_BYE, ctl, &flag, &st);
        if (!flag) {
            nap();
            continue;
        }
        MPI_Recv(&r, 1, MPI_INT, st.MPI_SOURCE, TAG_BYE, ctl,
                 MPI_STATUS_IGNORE);
        seen[st.MPI_SOURCE] = 1;
        got++;
    }
    for (r = 1; r < size; r++)
        if (!seen[r])
            return r;
    return 0;
}

int main(int argc, char **argv)
{
    char err[2048], spec[] = "k=50:100:3";
    char *specs[1] = {spec};
    eom_model *m = NULL;
    eom_system *s = NULL;
    ensemble_runs runs;
    ensemble_job job;
    MPI_Comm ctl;
    double *x0 = NULL, *p0 = NULL;
    int rank = 0, size = 0, n = 0, k, one = 1;

    if (ensemble_mpi_init(&argc, &argv, &rank, &size) != 0) {
        fprintf(stderr, "MPI without MPI_THREAD_FUNNELED\n");
        return EXIT_FAILURE;
    }
    if (size != 3) {
        if (rank == 0)
            fprintf(stderr, "run with mpirun -np 3 (not %d)\n", size);
        ensemble_mpi_finalize();
        return EXIT_FAILURE;
    }
    MPI_Comm_dup(MPI_COMM_WORLD, &ctl);
    memset(&runs, 0, sizeof runs);
    memset(&job, 0, sizeof job);
    CHECK(eom_model_from_string(&m, spring, err, sizeof err) == EOM_OK);
    CHECK(m && eom_system_new(&s, m, err, sizeof err) == EOM_OK);
    eom_model_free(&m);
    CHECK(s && ensemble_runs_sweep(&runs, specs, 1, err, sizeof err) == 0);
    CHECK(s && ensemble_runs_resolve(&runs, s, err, sizeof err) == 0);
    CHECK_INT(runs.nruns, NRUNS);
    if (!s || runs.nruns != NRUNS) {
        fprintf(stderr, "rank %d: setup: %s\n", rank, err);
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    n = eom_system_ncoords(s);
    x0 = malloc(2 * (size_t)n * sizeof *x0);
    p0 = malloc(((size_t)eom_system_nparams(s) + 1) * sizeof *p0);
    job.res = calloc(NRUNS, sizeof *job.res);
    if (!x0 || !p0 || !job.res)
        MPI_Abort(MPI_COMM_WORLD, 1);
    eom_initial_state(s, x0);
    for (k = 0; k < eom_system_nparams(s); k++)
        p0[k] = eom_get_param(s, k);
    job.base = s;
    job.runs = &runs;
    job.x0 = x0;
    job.p0 = p0;
    eom_opts_default(&job.opts);
    job.opts.method = EOM_ERK;
    job.t_end = 0.05;
    job.sample = 0.01;
    job.label = "spring";
    pthread_mutex_init(&job.lock, NULL);
    pthread_cond_init(&job.cond, NULL);

    if (rank == 0) {
        int active = size - 1, lost;
        long i;
        /* the runs, all on rank 1 (rank 2 has not asked yet) */
        while (!all_done(&job))
            if (!ensemble_mpi_serve(&job, &active))
                nap();
        /* rank 1 was told to stop with its last request; rank 2 waits */
        CHECK_INT(active, 1);
        if (active != 1) { /* rank 2 would never be told to stop */
            fprintf(stderr, "rank 0 counts %d ranks as waiting, not 1 "
                    "(rank 2 has not asked yet)\n", active);
            fflush(stderr);
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
        MPI_Send(&one, 1, MPI_INT, 2, TAG_GO, ctl);
        /* eom-ensemble's finish_ranks: serve until no rank waits */
        while (active > 0)
            if (!ensemble_mpi_serve(&job, &active))
                nap();
        CHECK_INT(active, 0);
        lost = goodbyes(ctl, size);
        if (lost) {
            fprintf(stderr, "rank %d was never told to stop: rank 0 "
                    "counted it out too early\n", lost);
            CHECK(!"every rank told to stop");
            fflush(stderr);
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
        /* every result whole: the same run done here, bit for bit */
        for (i = 0; i < NRUNS; i++) {
            ensemble_worker *w = ensemble_worker_new(&job);
            run_result here;
            memset(&here, 0, sizeof here);
            CHECK(w != NULL);
            if (!w)
                break;
            ensemble_worker_run(w, i, &here);
            ensemble_worker_free(&w);
            CHECK_INT(job.res[i].ok, 1);
            CHECK_INT(here.ok, 1);
            CHECK(job.res[i].final != NULL && here.final != NULL);
            if (job.res[i].final && here.final)
                CHECK(memcmp(job.res[i].final, here.final,
                             2 * (size_t)n * sizeof(double)) == 0);
            CHECK(job.res[i].E0 == here.E0);
            CHECK_INT(job.res[i].steps, here.steps);
            CHECK_INT(job.res[i].rhs, here.rhs);
            free(here.final);
            free(job.res[i].final);
        }
        /* the runs differ (k from 50 to 100): not one result thrice */
        CHECK(job.res[0].E0 != job.res[2].E0);
    } else {
        if (rank == 2)
            MPI_Recv(&one, 1, MPI_INT, 0, TAG_GO, ctl, MPI_STATUS_IGNORE);
        CHECK_INT(ensemble_mpi_work(&job), 0);
        MPI_Send(&one, 1, MPI_INT, 0, TAG_BYE, ctl);
    }
    pthread_mutex_destroy(&job.lock);
    pthread_cond_destroy(&job.cond);
    free(job.res);
    free(x0);
    free(p0);
    ensemble_runs_free(&runs);
    eom_system_free(&s);
    MPI_Comm_free(&ctl);
    ensemble_mpi_finalize();
    if (rank != 0) { /* rank 0 alone reports */
        return check_failures_ ? EXIT_FAILURE : EXIT_SUCCESS;
    }
    CHECK_DONE();
}
