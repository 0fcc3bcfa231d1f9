/* test_clone.c - systems that share their tapes (eom_system_clone): two
 * threads integrate the closed chain for different stiffnesses on two
 * clones at the same time, and every final state equals, bit for bit,
 * the same run made alone on the original system; a clone keeps working
 * after the original is freed; parameters set on one system do not
 * reach another; bad arguments are refused. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "eom/chain.h"

#define RUNS 6
#define NX 20 /* 5 links, 1 mode: 10 coordinates */

static const double pi = 3.14159265358979323846;

static eom_system *closed_chain(void)
{
    static const double paper[5] = {5, 1, 0, 17, 13};
    unsigned char damped[6] = {0, 1, 1, 1, 1, 1};
    double th[5];
    eom_chain_spec sp;
    eom_model *m = NULL;
    eom_system *s = NULL;
    char err[256];
    int j;
    for (j = 0; j < 5; j++)
        th[j] = paper[j] * pi / 12.0;
    memset(&sp, 0, sizeof sp);
    sp.links = 5;
    sp.modes_all = 1;
    sp.closed = 1;
    sp.m = 1.0;
    sp.L = 10.0;
    sp.EI = 4e4;
    sp.g = 9.81;
    sp.c = 10.0;
    sp.D = 10.0;
    sp.theta0 = th;
    sp.damped = damped;
    if (eom_model_new(&m) == EOM_OK && eom_chain_add(m, &sp) >= 0)
        eom_system_new(&s, m, err, sizeof err);
    eom_model_free(&m);
    return s;
}

/* One run: EI of every link for run k, 0.3 s of erk; the final state. */
static int run(eom_system *s, int k, double *x)
{
    eom_opts o;
    eom_integ *it = NULL;
    char name[8];
    int j, rc;
    for (j = 1; j <= 5; j++) {
        snprintf(name, sizeof name, "EI%d", j);
        if (eom_set_param(s, eom_param_index(s, name), 2e4 + 1e4 * k) !=
            EOM_OK)
            return -1;
    }
    eom_opts_default(&o);
    o.method = EOM_ERK;
    o.rtol = 1e-9;
    o.atol = 1e-11;
    eom_initial_state(s, x);
    rc = eom_integ_new(&it, s, &o, 0.0, x);
    if (rc == EOM_OK)
        rc = eom_integ_advance(it, 0.3, x, NULL);
    eom_integ_free(&it);
    return rc;
}

typedef struct job {
    eom_system *s;
    int first;          /* runs first, first + 2, ... */
    double x[RUNS][NX];
    int rc;
} job;

static void *worker(void *p)
{
    job *j = p;
    int k;
    j->rc = 0;
    for (k = j->first; k < RUNS; k += 2)
        j->rc |= run(j->s, k, j->x[k]);
    return NULL;
}

int main(void)
{
    eom_system *s = closed_chain(), *c1 = NULL, *c2 = NULL, *c3 = NULL;
    static double ref[RUNS][NX];
    static job jobs[2];
    pthread_t th[2];
    double x[NX];
    char err[256];
    int k, i;

    CHECK(s != NULL);
    if (!s)
        CHECK_DONE();
    CHECK_INT(eom_system_ncoords(s), NX / 2);
    for (k = 0; k < RUNS; k++)
        CHECK_INT(run(s, k, ref[k]), EOM_OK);

    /* the clones start with the original's parameter values */
    CHECK(eom_set_param(s, eom_param_index(s, "c"), 7.5) == EOM_OK);
    CHECK_INT(eom_system_clone(&c1, s, err, sizeof err), EOM_OK);
    CHECK_INT(eom_system_clone(&c2, s, err, sizeof err), EOM_OK);
    CHECK(c1 && c2);
    if (!c1 || !c2)
        CHECK_DONE();
    CHECK(eom_get_param(c1, eom_param_index(c1, "c")) == 7.5);
    CHECK_INT(eom_system_nconstraints(c1), 2);
    CHECK(strcmp(eom_coord_name(c2, 5), "q1_1") == 0);
    CHECK(eom_set_param(s, eom_param_index(s, "c"), 10.0) == EOM_OK);
    CHECK(eom_set_param(c1, eom_param_index(c1, "c"), 10.0) == EOM_OK);
    CHECK(eom_set_param(c2, eom_param_index(c2, "c"), 10.0) == EOM_OK);

    /* the values reach the clone's tapes: a clone of a system with g = 5
     * runs as that system does */
    {
        eom_system *c4 = NULL;
        double xs[NX], xc[NX];
        CHECK(eom_set_param(s, eom_param_index(s, "g"), 5.0) == EOM_OK);
        CHECK_INT(eom_system_clone(&c4, s, err, sizeof err), EOM_OK);
        CHECK_INT(run(s, 2, xs), EOM_OK);
        CHECK_INT(run(c4, 2, xc), EOM_OK);
        CHECK(memcmp(xs, xc, sizeof xs) == 0);
        CHECK(memcmp(xs, ref[2], sizeof xs) != 0); /* g mattered */
        CHECK(eom_set_param(s, eom_param_index(s, "g"), 9.81) == EOM_OK);
        eom_system_free(&c4);
    }

    /* two threads at once, one clone each */
    jobs[0].s = c1;
    jobs[0].first = 0;
    jobs[1].s = c2;
    jobs[1].first = 1;
    for (i = 0; i < 2; i++)
        CHECK(pthread_create(&th[i], NULL, worker, &jobs[i]) == 0);
    for (i = 0; i < 2; i++)
        pthread_join(th[i], NULL);
    for (i = 0; i < 2; i++) {
        CHECK_INT(jobs[i].rc, 0);
        for (k = i; k < RUNS; k += 2)
            CHECK(memcmp(jobs[i].x[k], ref[k], sizeof ref[k]) == 0);
    }

    /* a parameter set on a clone stays there */
    CHECK(eom_set_param(c1, eom_param_index(c1, "g"), 1.0) == EOM_OK);
    CHECK(eom_get_param(s, eom_param_index(s, "g")) == 9.81);
    CHECK(eom_get_param(c2, eom_param_index(c2, "g")) == 9.81);

    /* the original freed first: the clones keep their tapes */
    CHECK_INT(eom_system_clone(&c3, c2, err, sizeof err), EOM_OK);
    eom_system_free(&s);
    CHECK_INT(run(c2, 3, x), EOM_OK);
    CHECK(memcmp(x, ref[3], sizeof x) == 0);
    eom_system_free(&c2);
    CHECK_INT(run(c3, 4, x), EOM_OK);
    CHECK(memcmp(x, ref[4], sizeof x) == 0);
    eom_system_free(&c3);
    eom_system_free(&c1);

    /* bad arguments */
    CHECK_INT(eom_system_clone(NULL, c1, err, sizeof err), EOM_ERR_NULL);
    CHECK_INT(eom_system_clone(&c1, NULL, err, sizeof err), EOM_ERR_NULL);
    CHECK(c1 == NULL);
    CHECK_DONE();
}
