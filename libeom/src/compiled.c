/* compiled.c - a system's tapes as machine code (libtape's compiled
 * tapes): eom_system_set_compiled compiles the tapes the system has (or
 * finds them in the cache), checks each at the model's initial state and
 * points the system's workspaces at them. The tapes are compiled side by
 * side, one thread each (every compiler call is its own process, so the
 * threads only wait; the compilers' start-up times overlap instead of
 * adding up tape by tape). The compiled tapes belong to the set
 * of tapes a system shares with its clones; clones made later inherit
 * them. Any failure leaves the system on the interpreter, with the
 * reason in its message: a run never fails for it. */
#define _POSIX_C_SOURCE 200809L

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "eom_internal.h"

/* Where a tape is checked against the interpreter: the initial state
 * (q, qd, t = 0; the constraints' tape has (q) or (q, t)). */
static void check_point(const eom_system *s, const eom_tape *et, double *x)
{
    const int ni = tp_tape_n_indep(et->tape), n = s->n;
    int i;
    for (i = 0; i < ni; i++)
        x[i] = i == et->tindex ? 0.0
               : i < n         ? s->coords[i].v0
               : i < 2 * n     ? s->coords[i - n].v1
                               : 0.0;
}

/* Point s's workspaces at the shared compiled tapes (on) or back to the
 * interpreter; 0, or -1 (all back on the interpreter) if a workspace
 * refuses (out of memory for its scratch). */
static int attach(eom_system *s, bool on)
{
    eom_tape *t[EOM_N_TAPES];
    int k;
    eom__tapes(s, t);
    for (k = 0; k < EOM_N_TAPES; k++)
        if (t[k]->ws && (!on || s->shared->cc[k]) &&
            tp_ws_set_compiled(t[k]->ws, on ? s->shared->cc[k] : NULL) !=
                TP_OK) {
            eom__fail(s, EOM_WARN_INTERPRETED,
                      "compiled tapes are not in use, the interpreter runs "
                      "the model: %s",
                      tp_ws_errmsg(t[k]->ws));
            attach(s, false);
            return -1;
        }
    s->compiled = on;
    return 0;
}

/* One tape to compile: its options (and the state of its check) in, the
 * compiled tape and its status and account out. */
typedef struct compile_job {
    const tp_tape *tape;
    tp_compile_opts o;
    double *x;
    tp_compiled *out;
    tp_compile_info ci;
    int st;
    pthread_t thread;
    bool started;
} compile_job;

static void *compile_one(void *p)
{
    compile_job *j = p;
    j->st = tp_compile(j->tape, &j->o, &j->out, &j->ci);
    return NULL;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The options for tape k of s (et), the check at x. */
static void options_for(const eom_system *s, int k, const eom_tape *et,
                        double *x, tp_compile_opts *o)
{
    memset(o, 0, sizeof *o);
    check_point(s, et, x);
    o->x = x;
    o->max_dirs = et->dirs;
    /* the L tape's Lagrange block: its output 0 is L, its rates a group
     * of their own, its workspace n directions wide */
    o->lagrange = k == 0 && et->dirs >= s->n;
    /* only the sweeps the evaluations run (each costs compile time): L
     * through tp_lagrange, R's gradient, the values of E (with the
     * probes) and Q, the constraints' Jacobian (C, with dphi/dt when the
     * time is an independent: its workspace is as wide as its
     * independents) and their Taylor sweep (the velocity residual and
     * gamma); the rarer calls (a gradient of L for the power of a
     * rheonomic model, the linearization's Hessians) interpret */
    o->sweeps = o->lagrange         ? TP_SWEEP_LAGRANGE
                : k == 4            ? TP_SWEEP_JACOBIAN | TP_SWEEP_TAYLOR2
                : k == 1 || k == 3  ? TP_SWEEP_VALUES
                                    : TP_SWEEP_VALUES | TP_SWEEP_GRADIENTS;
}

int eom_system_set_compiled(eom_system *s, int on,
                            eom_compiled_info *info)
{
    eom_tape *t[EOM_N_TAPES];
    compile_job job[EOM_N_TAPES];
    eom_compiled_info local;
    double *x = NULL, t0;
    int k, ni_max = 1, failed = -1;
    if (!info)
        info = &local;
    memset(info, 0, sizeof *info);
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if (!on) {
        attach(s, false);
        return EOM_OK;
    }
    eom__tapes(s, t);
    for (k = 0; k < EOM_N_TAPES; k++)
        if (t[k]->tape && tp_tape_n_indep(t[k]->tape) > ni_max)
            ni_max = tp_tape_n_indep(t[k]->tape);
    /* a check state per tape: the jobs run at once */
    x = malloc((size_t)EOM_N_TAPES * (size_t)ni_max * sizeof(double));
    if (!x)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    memset(job, 0, sizeof job);
    t0 = now();
    for (k = 0; k < EOM_N_TAPES; k++) {
        compile_job *j = &job[k];
        /* the residual tape serves the implicit integrators' Jacobians
         * (seeded directions over every op, a few calls per step): it
         * stays on the interpreter; so does the velocity constraints'
         * tape (two sweeps per evaluation, docs/libeom.md), and the
         * initial state's (evaluated once a run) and the drawings'
         * (the frames of an animation only) */
        if (!t[k]->tape || k == 5 || k == 6 || k == 7 || k == 8)
            continue;
        info->tapes++;
        if (s->shared->cc[k]) {
            info->cached++;
            continue;
        }
        j->tape = t[k]->tape;
        options_for(s, k, t[k], x + (size_t)k * (size_t)ni_max, &j->o);
        j->st = TP_ERR_COMPILE;
        j->started = pthread_create(&j->thread, NULL, compile_one, j) == 0;
        if (!j->started) /* no thread to be had: compile here */
            compile_one(j);
    }
    for (k = 0; k < EOM_N_TAPES; k++) {
        compile_job *j = &job[k];
        if (!j->tape)
            continue;
        if (j->started)
            pthread_join(j->thread, NULL);
        info->source_bytes += j->ci.source_bytes;
        info->cached += j->ci.cached;
        info->rebuilt += j->ci.rebuilt;
        if (j->st == TP_OK)
            s->shared->cc[k] = j->out;
        else if (failed < 0)
            failed = k;
    }
    info->seconds = now() - t0;
    free(x);
    if (failed >= 0) {
        attach(s, false);
        eom__fail(s, EOM_WARN_INTERPRETED,
                  "compiled tapes are not in use, the interpreter runs the "
                  "model: %s",
                  job[failed].ci.msg);
        return EOM_WARN_INTERPRETED;
    }
    return attach(s, true) == 0 ? EOM_OK : EOM_WARN_INTERPRETED;
}

int eom_system_compiled(const eom_system *s)
{
    return s && s->compiled;
}
