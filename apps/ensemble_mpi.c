/* ensemble_mpi.c - the runs of an ensemble over MPI ranks
 * (ensemble_mpi.h). Three messages: a request for a run (worker to rank
 * 0), a run's number or -1 for "stop" (rank 0 to the worker), and a run's
 * result (worker to rank 0) as bytes: a header, the final state and the
 * message. Every rank runs the same program, so the layout agrees. */
#include "ensemble_mpi.h"

#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { TAG_REQ = 1, TAG_RUN = 2, TAG_RES = 3 };

/* Rank 0's view of every other rank, for ensemble_mpi_stalled: when it
 * was last heard from, the runs handed to it whose results have not come
 * back (at most two: a worker asks one run ahead), and whether it was
 * told to stop. Allocated at the first ensemble_mpi_serve. */
typedef struct rank_view {
    double heard;
    long held[2];
    int nheld, done;
} rank_view;
static rank_view *g_view;
static int g_nview;

static rank_view *view_of(int rank)
{
    if (!g_view) {
        int size = 1, r;
        MPI_Comm_size(MPI_COMM_WORLD, &size);
        g_view = calloc((size_t)size, sizeof *g_view);
        if (!g_view)
            return NULL;
        g_nview = size;
        for (r = 0; r < size; r++)
            g_view[r].heard = MPI_Wtime();
        g_view[0].done = 1; /* rank 0 is this one */
    }
    return rank >= 0 && rank < g_nview ? &g_view[rank] : NULL;
}

typedef struct wire {
    long i;
    int ok, has_final;
    double E0, energy_error, residual, wall;
    long steps, rhs;
    char msg[640];
} wire;

int ensemble_mpi_init(int *argc, char ***argv, int *rank, int *size)
{
    int provided;
    if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) !=
        MPI_SUCCESS)
        return -1;
    MPI_Comm_rank(MPI_COMM_WORLD, rank);
    MPI_Comm_size(MPI_COMM_WORLD, size);
    return provided >= MPI_THREAD_FUNNELED ? 0 : -1;
}

void ensemble_mpi_finalize(void)
{
    free(g_view);
    g_view = NULL;
    MPI_Finalize();
}

int ensemble_mpi_all_ok(int ok)
{
    int all = 0;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return all != 0;
}

static size_t wire_size(const ensemble_job *job)
{
    return sizeof(wire) +
           2 * (size_t)eom_system_ncoords(job->base) * sizeof(double);
}

int ensemble_mpi_work(ensemble_job *job)
{
    const int n = eom_system_ncoords(job->base);
    ensemble_worker *w = ensemble_worker_new(job);
    unsigned char *buf = malloc(wire_size(job));
    int dummy = 0, rc = w && buf ? 0 : -1;
    long i;
    /* always one request ahead: the next run's number arrives while this
     * one runs, so no rank waits for rank 0 between runs */
    MPI_Send(&dummy, 1, MPI_INT, 0, TAG_REQ, MPI_COMM_WORLD);
    MPI_Recv(&i, 1, MPI_LONG, 0, TAG_RUN, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    while (i >= 0) {
        long next;
        run_result r;
        wire h;
        MPI_Request req;
        /* even a worker that could not start asks, to be told to stop */
        MPI_Send(&dummy, 1, MPI_INT, 0, TAG_REQ, MPI_COMM_WORLD);
        MPI_Irecv(&next, 1, MPI_LONG, 0, TAG_RUN, MPI_COMM_WORLD, &req);
        memset(&r, 0, sizeof r);
        if (rc == 0)
            ensemble_worker_run(w, i, &r);
        else
            snprintf(r.msg, sizeof r.msg, "the worker on this rank could "
                     "not start");
        memset(&h, 0, sizeof h);
        h.i = i;
        h.ok = r.ok;
        h.has_final = r.final != NULL;
        h.E0 = r.E0;
        h.energy_error = r.energy_error;
        h.residual = r.residual;
        h.wall = r.wall;
        h.steps = r.steps;
        h.rhs = r.rhs;
        memcpy(h.msg, r.msg, sizeof h.msg);
        if (buf) {
            memcpy(buf, &h, sizeof h);
            if (r.final)
                memcpy(buf + sizeof h, r.final,
                       2 * (size_t)n * sizeof(double));
            MPI_Send(buf, (int)wire_size(job), MPI_BYTE, 0, TAG_RES,
                     MPI_COMM_WORLD);
        } else {
            MPI_Send(&h, (int)sizeof h, MPI_BYTE, 0, TAG_RES,
                     MPI_COMM_WORLD);
        }
        free(r.final);
        MPI_Wait(&req, MPI_STATUS_IGNORE);
        i = next;
    }
    ensemble_worker_free(&w);
    free(buf);
    return rc;
}

/* Not to be: the ranks run one program. Stop them all. */
static int malformed(int source, unsigned char *buf)
{
    fprintf(stderr, "eom-ensemble: a result from rank %d is malformed\n",
            source);
    free(buf);
    MPI_Abort(MPI_COMM_WORLD, 1);
    return 1;
}

int ensemble_mpi_serve(ensemble_job *job, int *active)
{
    const int n = eom_system_ncoords(job->base);
    MPI_Status st;
    int flag = 0;
    rank_view *v;
    (void)view_of(0); /* every rank's clock starts at the first call */
    MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
    if (!flag)
        return 0;
    v = view_of(st.MPI_SOURCE);
    if (v)
        v->heard = MPI_Wtime();
    if (st.MPI_TAG == TAG_REQ) {
        int dummy;
        long i;
        MPI_Recv(&dummy, 1, MPI_INT, st.MPI_SOURCE, TAG_REQ, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
        i = ensemble_job_next(job);
        if (i < 0)
            (*active)--;
        if (v && i < 0)
            v->done = 1;
        else if (v && v->nheld < 2)
            v->held[v->nheld++] = i;
        MPI_Send(&i, 1, MPI_LONG, st.MPI_SOURCE, TAG_RUN, MPI_COMM_WORLD);
        return 1;
    }
    if (st.MPI_TAG == TAG_RES) {
        int count = 0;
        unsigned char *buf;
        wire h;
        MPI_Get_count(&st, MPI_BYTE, &count);
        buf = malloc(count > 0 ? (size_t)count : 1);
        MPI_Recv(buf, count, MPI_BYTE, st.MPI_SOURCE, TAG_RES, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
        if (!buf || (size_t)count < sizeof h)
            return malformed(st.MPI_SOURCE, buf);
        memcpy(&h, buf, sizeof h);
        if (h.i < 0 || h.i >= job->runs->nruns)
            return malformed(st.MPI_SOURCE, buf);
        if (v && v->nheld > 0 && v->held[0] == h.i) /* results in order */
            v->held[0] = v->held[--v->nheld];
        {
            run_result *r = &job->res[h.i];
            r->ok = h.ok;
            r->E0 = h.E0;
            r->energy_error = h.energy_error;
            r->residual = h.residual;
            r->wall = h.wall;
            r->steps = h.steps;
            r->rhs = h.rhs;
            memcpy(r->msg, h.msg, sizeof r->msg);
            r->msg[sizeof r->msg - 1] = '\0';
            r->final = NULL;
            if (h.has_final &&
                (size_t)count >= sizeof h + 2 * (size_t)n * sizeof(double) &&
                (r->final = malloc(2 * (size_t)n * sizeof(double))))
                memcpy(r->final, buf + sizeof h,
                       2 * (size_t)n * sizeof(double));
            if (h.has_final && !r->final)
                r->ok = 0;
            free(buf);
            pthread_mutex_lock(&job->lock);
            r->done = 1;
            pthread_cond_broadcast(&job->cond);
            pthread_mutex_unlock(&job->lock);
        }
        return 1;
    }
    return 0;
}

int ensemble_mpi_stalled(double timeout, long *run, double *silent)
{
    const double now = MPI_Wtime();
    int r;
    *run = -1;
    *silent = 0.0;
    if (!view_of(0))
        return -1;
    for (r = 1; r < g_nview; r++) {
        const rank_view *v = &g_view[r];
        if (!v->done && now - v->heard > timeout) {
            *run = v->nheld > 0 ? v->held[0] : -1;
            *silent = now - v->heard;
            return r;
        }
    }
    return -1;
}

void ensemble_mpi_abort(int status)
{
    MPI_Abort(MPI_COMM_WORLD, status);
}
