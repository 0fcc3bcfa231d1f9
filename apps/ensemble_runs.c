/* ensemble_runs.c - the runs table of an ensemble (ensemble_runs.h). */
#include "ensemble_runs.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom/run.h"

/* Beyond this many runs a sweep is surely a mistake. */
#define MAX_RUNS 100000000L

void ensemble_runs_free(ensemble_runs *r)
{
    int k;
    for (k = 0; r->names && k < r->ncols; k++)
        free(r->names[k]);
    free(r->names);
    free(r->kind);
    free(r->index);
    free(r->v);
    memset(r, 0, sizeof *r);
}

static char *copy(const char *s, size_t n)
{
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = '\0';
    }
    return d;
}

static int alloc_cols(ensemble_runs *r, int ncols, long nruns)
{
    r->ncols = ncols;
    r->nruns = nruns;
    r->names = calloc((size_t)ncols + 1, sizeof *r->names);
    r->kind = calloc((size_t)ncols + 1, sizeof *r->kind);
    r->index = calloc((size_t)ncols + 1, sizeof *r->index);
    r->v = malloc(((size_t)nruns * (size_t)ncols + 1) * sizeof *r->v);
    return r->names && r->kind && r->index && r->v ? 0 : -1;
}

int ensemble_runs_read(ensemble_runs *r, const char *path, char *err,
                       size_t errlen)
{
    eom_csv_table *t = NULL;
    char msg[512];
    int k;
    memset(r, 0, sizeof *r);
    if (eom_csv_table_read(&t, path, msg, sizeof msg) != 0) {
        snprintf(err, errlen, "--runs: %s", msg);
        return -1;
    }
    if (t->nrows == 0) {
        snprintf(err, errlen, "--runs %s: no runs (a header and no rows)",
                 path);
        eom_csv_table_free(&t);
        return -1;
    }
    if (alloc_cols(r, t->ncols, t->nrows) != 0) {
        eom_csv_table_free(&t);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    for (k = 0; k < t->ncols; k++)
        if (!(r->names[k] = copy(t->names[k], strlen(t->names[k])))) {
            eom_csv_table_free(&t);
            snprintf(err, errlen, "out of memory");
            return -1;
        }
    memcpy(r->v, t->v, (size_t)t->nrows * (size_t)t->ncols * sizeof *r->v);
    eom_csv_table_free(&t);
    return 0;
}

int ensemble_runs_sweep(ensemble_runs *r, char *const *specs, int count,
                        char *err, size_t errlen)
{
    double *lo = calloc((size_t)count + 1, sizeof *lo);
    double *hi = calloc((size_t)count + 1, sizeof *hi);
    long *np = calloc((size_t)count + 1, sizeof *np), total = 1, i;
    int k, rc = -1;
    memset(r, 0, sizeof *r);
    if (!lo || !hi || !np) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    for (k = 0; k < count; k++) {
        const char *eq = strchr(specs[k], '='), *c1, *c2;
        char a[64], b[64];
        if (!eq || eq == specs[k] || !(c1 = strchr(eq + 1, ':')) ||
            !(c2 = strchr(c1 + 1, ':')) || c1 - eq - 1 >= 64 ||
            c2 - c1 - 1 >= 64) {
            snprintf(err, errlen, "--sweep '%s': expected NAME=LO:HI:N",
                     specs[k]);
            goto done;
        }
        snprintf(a, sizeof a, "%.*s", (int)(c1 - eq - 1), eq + 1);
        snprintf(b, sizeof b, "%.*s", (int)(c2 - c1 - 1), c1 + 1);
        if (eom_numtext_parse_double(a, &lo[k]) != EOM_NUMTEXT_OK ||
            eom_numtext_parse_double(b, &hi[k]) != EOM_NUMTEXT_OK ||
            eom_numtext_parse_long(c2 + 1, &np[k]) != EOM_NUMTEXT_OK ||
            np[k] < 1) {
            snprintf(err, errlen, "--sweep '%s': LO and HI must be numbers "
                     "and N a whole number >= 1", specs[k]);
            goto done;
        }
        if (np[k] > MAX_RUNS / total) {
            snprintf(err, errlen, "--sweep: more than %ld runs", MAX_RUNS);
            goto done;
        }
        total *= np[k];
    }
    if (alloc_cols(r, count, total) != 0) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    for (k = 0; k < count; k++) {
        const char *eq = strchr(specs[k], '=');
        if (!(r->names[k] = copy(specs[k], (size_t)(eq - specs[k])))) {
            snprintf(err, errlen, "out of memory");
            goto done;
        }
    }
    /* the grid, the last sweep varying fastest */
    for (i = 0; i < total; i++) {
        long rest = i;
        for (k = count - 1; k >= 0; k--) {
            long j = rest % np[k];
            rest /= np[k];
            r->v[i * count + k] =
                np[k] == 1 ? lo[k]
                           : lo[k] + (hi[k] - lo[k]) * (double)j /
                                         (double)(np[k] - 1);
        }
    }
    rc = 0;
done:
    free(lo);
    free(hi);
    free(np);
    return rc;
}

/* ---- random runs -------------------------------------------------------- */

typedef struct rng {
    unsigned long long s[4];
} rng;

static unsigned long long splitmix(unsigned long long *x)
{
    unsigned long long z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static unsigned long long rotl(unsigned long long x, int k)
{
    return (x << k) | (x >> (64 - k));
}

static unsigned long long next(rng *g)
{
    unsigned long long *s = g->s, r = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return r;
}

/* Uniform in (0, 1), never 0 (the normal draw takes its log). */
static double unit(rng *g)
{
    return ((double)(next(g) >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

int ensemble_runs_random(ensemble_runs *r, char *const *specs, int ndist,
                         long count, unsigned long long seed, char *err,
                         size_t errlen)
{
    static const double two_pi = 6.28318530717958647692;
    double *a = calloc((size_t)ndist + 1, sizeof *a);
    double *b = calloc((size_t)ndist + 1, sizeof *b);
    int *normal = calloc((size_t)ndist + 1, sizeof *normal), k, rc = -1;
    rng g;
    long i;
    memset(r, 0, sizeof *r);
    if (!a || !b || !normal) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    if (count < 1 || count > MAX_RUNS) {
        snprintf(err, errlen, "--count must be from 1 to %ld", MAX_RUNS);
        goto done;
    }
    for (k = 0; k < ndist; k++) {
        const char *eq = strchr(specs[k], '='), *c1, *c2;
        char x[64], y[64];
        int ok = eq && eq > specs[k];
        if (ok && strncmp(eq + 1, "uniform:", 8) == 0)
            c1 = eq + 8;
        else if (ok && strncmp(eq + 1, "normal:", 7) == 0)
            c1 = eq + 7, normal[k] = 1;
        else
            ok = 0;
        if (!ok || !(c2 = strchr(c1 + 1, ':')) || c2 - c1 - 1 >= 64 ||
            strlen(c2 + 1) >= 64) {
            snprintf(err, errlen, "--random '%s': expected "
                     "NAME=uniform:LO:HI or NAME=normal:MEAN:SD", specs[k]);
            goto done;
        }
        snprintf(x, sizeof x, "%.*s", (int)(c2 - c1 - 1), c1 + 1);
        snprintf(y, sizeof y, "%s", c2 + 1);
        if (eom_numtext_parse_double(x, &a[k]) != EOM_NUMTEXT_OK ||
            eom_numtext_parse_double(y, &b[k]) != EOM_NUMTEXT_OK ||
            (normal[k] ? !(b[k] >= 0.0) : !(b[k] >= a[k]))) {
            snprintf(err, errlen, "--random '%s': %s", specs[k],
                     normal[k] ? "MEAN and SD must be numbers, SD >= 0"
                               : "LO and HI must be numbers, LO <= HI");
            goto done;
        }
    }
    if (alloc_cols(r, ndist, count) != 0) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    for (k = 0; k < ndist; k++) {
        const char *eq = strchr(specs[k], '=');
        if (!(r->names[k] = copy(specs[k], (size_t)(eq - specs[k])))) {
            snprintf(err, errlen, "out of memory");
            goto done;
        }
    }
    for (k = 0; k < 4; k++)
        g.s[k] = splitmix(&seed);
    /* run by run, name by name: the draws do not depend on the threads */
    for (i = 0; i < count; i++)
        for (k = 0; k < ndist; k++) {
            double u = unit(&g), v;
            if (normal[k])
                v = a[k] + b[k] * sqrt(-2.0 * log(u)) *
                               cos(two_pi * unit(&g));
            else
                v = a[k] + (b[k] - a[k]) * u;
            r->v[i * ndist + k] = v;
        }
    rc = 0;
done:
    free(a);
    free(b);
    free(normal);
    return rc;
}

int ensemble_runs_resolve(ensemble_runs *r, const eom_system *s, char *err,
                          size_t errlen)
{
    static const char *const integ[] = {"t_end", "rtol", "atol", "dt"};
    int k, j;
    for (k = 0; k < r->ncols; k++) {
        const char *name = r->names[k];
        size_t len = strlen(name);
        for (j = 0; j < k; j++)
            if (strcmp(r->names[j], name) == 0) {
                snprintf(err, errlen, "the runs name '%s' twice", name);
                return -1;
            }
        r->index[k] = -1;
        if ((r->index[k] = eom_param_index(s, name)) >= 0) {
            r->kind[k] = RUN_PARAM;
        } else if ((r->index[k] = eom_coord_index(s, name)) >= 0) {
            r->kind[k] = RUN_COORD;
        } else if (len > 4 && strcmp(name + len - 4, "_dot") == 0) {
            char base[256];
            snprintf(base, sizeof base, "%.*s", (int)(len - 4), name);
            if ((r->index[k] = eom_coord_index(s, base)) >= 0)
                r->kind[k] = RUN_RATE;
        }
        if (r->index[k] >= 0)
            continue;
        for (j = 0; j < 4; j++)
            if (strcmp(name, integ[j]) == 0) {
                r->kind[k] = RUN_T_END + j;
                r->index[k] = 0;
            }
        if (r->index[k] < 0) {
            snprintf(err, errlen, "the runs vary '%s', which is not a "
                     "parameter, a coordinate, a rate (NAME_dot) or one of "
                     "t_end, rtol, atol, dt (eom-run MODEL --describe "
                     "lists the names; structural settings are fixed for "
                     "the whole ensemble with --set)", name);
            return -1;
        }
    }
    return 0;
}
