/* ensemble_runs.h - the runs of an ensemble (docs/ensembles.md): a table
 * with one column per varied name and one row per run, read from a CSV
 * (--runs), made as the grid of --sweep NAME=LO:HI:N options (the first
 * sweep varies slowest), or drawn at random (--random). Each name is resolved against the system: a
 * parameter, a coordinate (its initial value), a rate (NAME_dot), or one
 * of the integrator options t_end, rtol, atol and dt. */
#ifndef APPS_ENSEMBLE_RUNS_H
#define APPS_ENSEMBLE_RUNS_H

#include <stddef.h>

#include "eom/eom.h"

enum { RUN_PARAM, RUN_COORD, RUN_RATE, RUN_T_END, RUN_RTOL, RUN_ATOL,
       RUN_DT };

typedef struct ensemble_runs {
    int ncols;
    long nruns;
    char **names; /* [ncols] (owned) */
    int *kind;    /* [ncols] RUN_* */
    int *index;   /* [ncols] parameter or coordinate index */
    double *v;    /* [nruns x ncols] */
} ensemble_runs;

/* From the CSV at path. Returns 0, or -1 with a message. */
int ensemble_runs_read(ensemble_runs *r, const char *path, char *err,
                       size_t errlen);
/* count runs whose values are drawn at random from the texts
 * NAME=uniform:LO:HI or NAME=normal:MEAN:SD (ndist of them), from a
 * generator seeded with seed (xoshiro256** fed by splitmix64; normal
 * values by the Box-Muller transform): the same seed gives the same runs
 * on every machine. */
int ensemble_runs_random(ensemble_runs *r, char *const *specs, int ndist,
                         long count, unsigned long long seed, char *err,
                         size_t errlen);
/* From count texts NAME=LO:HI:N (N >= 1 points, LO and HI included). */
int ensemble_runs_sweep(ensemble_runs *r, char *const *specs, int count,
                        char *err, size_t errlen);
/* Resolve every name against s: 0, or -1 with a message naming the
 * unknown name. */
int ensemble_runs_resolve(ensemble_runs *r, const eom_system *s, char *err,
                          size_t errlen);
void ensemble_runs_free(ensemble_runs *r);

#endif /* APPS_ENSEMBLE_RUNS_H */
