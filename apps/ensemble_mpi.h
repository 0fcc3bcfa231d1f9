/* ensemble_mpi.h - eom-ensemble over several processes, on one machine or
 * many (meson -Dmpi=enabled; docs/ensembles.md). Rank 0 reads the runs,
 * works on them with its own threads like a plain eom-ensemble, and also
 * hands runs out, one at a time on request, to the other ranks (dynamic
 * load balancing: a rank that finishes asks for the next), collects their
 * results and writes the summary; the other ranks only run. Results are
 * the same as on one process, bit for bit. All MPI calls are made by each
 * process's main thread (MPI_THREAD_FUNNELED). */
#ifndef APPS_ENSEMBLE_MPI_H
#define APPS_ENSEMBLE_MPI_H

#include "ensemble_pool.h"

/* MPI_Init_thread; *rank and *size of MPI_COMM_WORLD. 0, or -1. */
int ensemble_mpi_init(int *argc, char ***argv, int *rank, int *size);
void ensemble_mpi_finalize(void);
/* Every rank says whether it is ready (ok != 0); 1 when all are. */
int ensemble_mpi_all_ok(int ok);
/* Rank > 0: ask rank 0 for runs and send back their results until it
 * says there are none left. Returns 0, or -1 without a worker. */
int ensemble_mpi_work(ensemble_job *job);
/* Rank 0: answer the other ranks' requests and take in their results
 * (marking them done under job->lock); *active counts the ranks not yet
 * told to stop. Returns 1 when it handled a message, 0 when none was
 * waiting. */
int ensemble_mpi_serve(ensemble_job *job, int *active);

/* Rank 0: a rank not yet told to stop that has sent nothing for more
 * than timeout seconds (stopped, SIGSTOP, or lost): its number, with the
 * run it holds in *run (-1: none) and the seconds since it was last
 * heard from in *silent; or -1 when every rank has answered in time.
 * A rank working on a run is silent for the whole run: timeout must be
 * longer than the longest run (docs/ensembles.md). */
int ensemble_mpi_stalled(double timeout, long *run, double *silent);

/* End every rank at once (MPI_Abort) with status. */
void ensemble_mpi_abort(int status);

#endif /* APPS_ENSEMBLE_MPI_H */
