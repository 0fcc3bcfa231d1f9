/* test_threads.c - one finished tape shared by four POSIX threads.
 *
 * A finished tape is immutable and everything a sweep writes lives in a
 * workspace, so threads replaying one tape, each with its own workspace,
 * must get exactly (bit for bit) what a serial run gets. Each thread sweeps
 * all points, starting at a different one so that the threads work on
 * different points at the same time, with its own max_dirs (chunked and
 * not); each also runs its own double evaluator, since the library keeps
 * no process-wide state. The serial reference repeats every thread's work
 * in the main thread with the same workspace shape.
 */
#define _POSIX_C_SOURCE 200809L

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "pendulum_chain.h"
#include "support_num.h"
#include "support_rng.h"
#include "support_tape.h"

#define NLINK 10
#define NX (2 * NLINK)
#define NTHREADS 4
#define NPTS 96
/* per point: L, dLdq, M, h, the Hessian of T, the outputs, the evaluator's
 * outputs */
#define PER_PT (1 + NLINK + NLINK * NLINK + NLINK + NX * NX + 3 + 3)

static const double PI_ = 3.14159265358979323846;

typedef struct job {
    const tp_tape *T;
    pendulum_chain *pc;
    const double *pts; /* NPTS x NX */
    int max_dirs;
    int start;      /* first point this job visits */
    double *out;    /* NPTS x PER_PT, by point */
    int status;     /* worst status seen; TP_OK when all went well */
} job;

static void note(job *j, int st)
{
    if (st != TP_OK && j->status == TP_OK)
        j->status = st;
}

static void *run_job(void *arg)
{
    job *j = arg;
    tp_ws *ws = NULL;
    tp_rec *ev = NULL;
    int k;
    note(j, tp_ws_new(&ws, j->T, j->max_dirs, NULL));
    note(j, tp_evaluator_new(&ev, NX, NULL));
    if (!ws || !ev)
        goto done;
    for (k = 0; k < NPTS; k++) {
        const int p = (j->start + k) % NPTS;
        const double *x = j->pts + p * NX;
        double *o = j->out + (size_t)p * PER_PT;
        note(j, tp_lagrange(ws, x, 0, o, o + 1, o + 1 + NLINK,
                            o + 1 + NLINK + NLINK * NLINK));
        o += 1 + 2 * NLINK + NLINK * NLINK;
        note(j, tp_hessian(ws, x, 1, o));
        o += NX * NX;
        note(j, tp_eval(ws, x, o));
        note(j, st_eval(ev, x, pendulum_chain_record, j->pc, o + 3));
    }
done:
    tp_rec_free(&ev);
    tp_ws_free(&ws);
    return NULL;
}

int main(void)
{
    static const int dirs[NTHREADS] = {1, 3, NLINK, NX};
    double m[NLINK], l[NLINK], *pts, *par, *ser;
    unsigned char grp[NX];
    pendulum_chain pc;
    tp_rec *r = NULL;
    tp_tape *T = NULL;
    pthread_t th[NTHREADS];
    job jobs[NTHREADS], serial;
    rng g = rng_seed(0x74ead001u);
    int i, t, started[NTHREADS];

    for (i = 0; i < NLINK; i++) {
        m[i] = rng_range(&g, 0.5, 2.0);
        l[i] = rng_range(&g, 0.3, 1.5);
        grp[i] = 0;
        grp[NLINK + i] = 1;
    }
    pc.n = NLINK;
    pc.m = m;
    pc.l = l;
    pc.g = 9.81;
    CHECK_INT(tp_recorder_new(&r, NX, grp, NULL), TP_OK);
    CHECK_INT(tp_rec_run(r, NULL, pendulum_chain_record, &pc), TP_OK);
    CHECK_INT(tp_recorder_finish(r, &T), TP_OK);
    tp_rec_free(&r);

    pts = malloc(NPTS * NX * sizeof(double));
    par = calloc((size_t)NTHREADS * NPTS * PER_PT, sizeof(double));
    ser = calloc((size_t)NPTS * PER_PT, sizeof(double));
    CHECK(T && pts && par && ser);
    if (!T || !pts || !par || !ser)
        goto done;
    for (i = 0; i < NPTS * NX; i++)
        pts[i] = (i % NX) < NLINK ? rng_range(&g, -PI_, PI_)
                                  : rng_range(&g, -2.0, 2.0);

    for (t = 0; t < NTHREADS; t++) {
        jobs[t].T = T;
        jobs[t].pc = &pc;
        jobs[t].pts = pts;
        jobs[t].max_dirs = dirs[t];
        jobs[t].start = t * NPTS / NTHREADS;
        jobs[t].out = par + (size_t)t * NPTS * PER_PT;
        jobs[t].status = TP_OK;
        started[t] = pthread_create(&th[t], NULL, run_job, &jobs[t]) == 0;
        CHECK(started[t]);
    }
    for (t = 0; t < NTHREADS; t++)
        if (started[t])
            CHECK_INT(pthread_join(th[t], NULL), 0);

    /* the same work, serially, compared bit for bit */
    for (t = 0; t < NTHREADS; t++) {
        char ctx[64];
        snprintf(ctx, sizeof ctx, "thread %d (max_dirs %d)", t, dirs[t]);
        CHECK_INT(jobs[t].status, TP_OK);
        serial = jobs[t];
        serial.start = 0;
        serial.out = ser;
        serial.status = TP_OK;
        memset(ser, 0, (size_t)NPTS * PER_PT * sizeof(double));
        run_job(&serial);
        CHECK_INT(serial.status, TP_OK);
        CHECK(memcmp(jobs[t].out, ser,
                     (size_t)NPTS * PER_PT * sizeof(double)) == 0);
        CHECK_SAME(ctx, jobs[t].out, ser, NPTS * PER_PT);
    }
done:
    free(pts);
    free(par);
    free(ser);
    tp_tape_free(&T);
    CHECK_DONE();
}
