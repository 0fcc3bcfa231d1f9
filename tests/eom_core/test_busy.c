/* test_busy.c - one system used by two threads at once, which the API
 * forbids (a system is for one thread at a time; eom_system_clone gives
 * each thread its own): eom_rhs must never return a wrong result marked
 * EOM_OK. Each call either computes this thread's right-hand side
 * exactly (the same bits as a call alone) or returns EOM_ERR_BUSY,
 * touching nothing. Two threads, started together, each call eom_rhs at
 * its own state of the spring pendulum until 200000 calls have given a
 * result, trying again after a refusal. */
#define _POSIX_C_SOURCE 200809L /* pthread_barrier_t */
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "eom/eom.h"
#include "eom/model_file.h"

static const char spring[] =
    "param m = 1 [kg]\nparam k = 75 [N/m]\nparam r0 = 1 [m]\n"
    "param g = 9.81 [m/s^2]\ncoord r = 1.1 [m]\ncoord theta = 0.5 [rad]\n"
    "T = 1/2*m*(r_dot^2 + r^2*theta_dot^2)\n"
    "V = 1/2*k*(r - r0)^2 + m*g*(r0 - r*cos(theta))\n";

enum { CALLS = 200000 };

typedef struct job {
    eom_system *s;
    double x[4], want[4];
    long ok, busy, wrong, other;
} job;

static pthread_barrier_t start;

static void *work(void *arg)
{
    job *j = arg;
    double xd[4];
    long i;
    pthread_barrier_wait(&start);
    /* until CALLS results, a refusal counting as none (bounded) */
    for (i = 0; j->ok + j->wrong + j->other < CALLS && i < 100L * CALLS;
         i++) {
        int rc = eom_rhs(j->s, 0.0, j->x, xd);
        if (rc == EOM_ERR_BUSY) {
            j->busy++;
            sched_yield(); /* let the other thread finish its call */
        }
        else if (rc != EOM_OK)
            j->other++;
        else if (memcmp(xd, j->want, sizeof xd) != 0)
            j->wrong++;
        else
            j->ok++;
    }
    return NULL;
}

int main(void)
{
    char err[512];
    eom_model *m = NULL;
    eom_system *s = NULL;
    pthread_t th[2];
    job jobs[2];
    int k;
    CHECK_INT(eom_model_from_string(&m, spring, err, sizeof err), EOM_OK);
    CHECK_INT(eom_system_new(&s, m, err, sizeof err), EOM_OK);
    eom_model_free(&m);
    if (!s)
        CHECK_DONE();
    CHECK(strstr(eom_strerror(EOM_ERR_BUSY), "eom_system_clone") != NULL);
    CHECK(strcmp(eom_status_name(EOM_ERR_BUSY), "EOM_ERR_BUSY") == 0);
    memset(jobs, 0, sizeof jobs);
    for (k = 0; k < 2; k++) {
        jobs[k].s = s;
        jobs[k].x[0] = 1.1 + 0.2 * k;
        jobs[k].x[1] = 0.5 - 0.7 * k;
        jobs[k].x[2] = 0.3 * k;
        jobs[k].x[3] = 1.0 - k;
        CHECK_INT(eom_rhs(s, 0.0, jobs[k].x, jobs[k].want), EOM_OK);
    }
    pthread_barrier_init(&start, NULL, 2);
    for (k = 0; k < 2; k++)
        CHECK(pthread_create(&th[k], NULL, work, &jobs[k]) == 0);
    for (k = 0; k < 2; k++)
        pthread_join(th[k], NULL);
    pthread_barrier_destroy(&start);
    for (k = 0; k < 2; k++) {
        printf("thread %d: %ld right, %ld busy, %ld wrong, %ld other\n", k,
               jobs[k].ok, jobs[k].busy, jobs[k].wrong, jobs[k].other);
        CHECK_INT((int)jobs[k].wrong, 0);
        CHECK_INT((int)jobs[k].other, 0);
        CHECK_INT((int)jobs[k].ok, CALLS);
    }
    /* alone again, the system works as before */
    {
        double xd[4];
        CHECK_INT(eom_rhs(s, 0.0, jobs[0].x, xd), EOM_OK);
        CHECK(memcmp(xd, jobs[0].want, sizeof xd) == 0);
    }
    eom_system_free(&s);
    CHECK_DONE();
}
