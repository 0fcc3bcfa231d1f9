/* bench_der.c - what der() costs: models/closed-chain.eom as shipped (the
 * joint velocities typed by hand, vx[j] = vx[j-1] - len*theta_dot[j]*...)
 * against the same file with those two lines replaced by der() of the
 * joint positions (vx[j] = der(px[j]), px[j] = px[j-1] + len*cos(...)).
 * For each number of links: the operations of the Lagrangian's tape and
 * the median time of one right-hand side of each, with their ratio (the
 * target is 1.3 at most for both), after checking that the two
 * right-hand sides agree at the start. Measured in one run.
 *
 * usage: bench-der [--quick] MODELS_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "eom/model_file.h"
#include "tape/tape.h"

static char *read_all(const char *path)
{
    FILE *f = fopen(path, "rb");
    long n;
    char *s;
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    s = malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        s = NULL;
    }
    if (s)
        s[n] = '\0';
    fclose(f);
    return s;
}

/* text with from replaced by to, or NULL when from is not there */
static char *replace(const char *text, const char *from, const char *to)
{
    const char *at = text ? strstr(text, from) : NULL;
    size_t a, b, c;
    char *out;
    if (!at)
        return NULL;
    a = (size_t)(at - text);
    b = strlen(to);
    c = strlen(at + strlen(from));
    if (!(out = malloc(a + b + c + 1)))
        return NULL;
    memcpy(out, text, a);
    memcpy(out + a, to, b);
    memcpy(out + a + b, at + strlen(from), c + 1);
    return out;
}

static size_t tape_ops(const eom_model *m)
{
    int n = eom_model_ncoords(m), k;
    unsigned char *group = malloc(2 * (size_t)n);
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    tp_tape_stats st;
    memset(&st, 0, sizeof st);
    for (k = 0; k < 2 * n; k++)
        group[k] = (unsigned char)(k >= n);
    if (tp_recorder_new(&r, 2 * n, group, NULL) == TP_OK &&
        eom_model_run_lagrangian(m, r, NULL) == EOM_OK &&
        tp_recorder_finish(r, &t) == TP_OK)
        tp_tape_stats_get(t, &st);
    tp_tape_free(&t);
    tp_rec_free(&r);
    free(group);
    return st.n_ops;
}

static eom_system *system_of(const char *text, int links, size_t *ops)
{
    eom_file *f = NULL;
    eom_model *m = NULL;
    eom_system *s = NULL;
    char err[2048];
    if (eom_file_parse(&f, text, "closed-chain.eom", err, sizeof err) ||
        eom_file_set_setting(f, "links", links, err, sizeof err) ||
        eom_file_build(f, &m, err, sizeof err) ||
        (*ops = tape_ops(m), eom_system_new(&s, m, err, sizeof err))) {
        fprintf(stderr, "bench-der: %s\n", err);
        s = NULL;
    }
    eom_model_free(&m);
    eom_file_free(&f);
    return s;
}

typedef struct rhs_ctx {
    eom_system *s;
    double *x, *xd;
} rhs_ctx;

static void one_rhs(void *p)
{
    rhs_ctx *c = p;
    c->x[0] += 1e-12;
    eom_rhs(c->s, 0.0, c->x, c->xd);
}

static double rhs_median(eom_system *s, int quick)
{
    int n = eom_system_ncoords(s), k;
    rhs_ctx c;
    double t[7];
    long batch;
    c.s = s;
    c.x = calloc(2 * (size_t)n, sizeof *c.x);
    c.xd = calloc(2 * (size_t)n, sizeof *c.xd);
    eom_initial_state(s, c.x);
    batch = bench_calibrate(one_rhs, &c, quick ? 0.01 : 0.2);
    for (k = 0; k < 7; k++)
        t[k] = bench_time(one_rhs, &c, batch);
    free(c.x);
    free(c.xd);
    return bench_median(t, 7);
}

int main(int argc, char **argv)
{
    static const int sizes[] = {5, 20, 50, 200};
    int quick = argc > 1 && strcmp(argv[1], "--quick") == 0, k, j, bad = 0;
    const char *dir = argc > 1 + quick ? argv[1 + quick] : "models";
    char path[4096], *hand, *step, *der;
    snprintf(path, sizeof path, "%s/closed-chain.eom", dir);
    hand = read_all(path);
    step = replace(hand,
                   "vx[j in 1..links] = vx[j-1] - len*theta_dot[j]*sin(theta[j])",
                   "vx[j in 1..links] = der(px[j])\npx[0] = 0\n"
                   "px[j in 1..links] = px[j-1] + len*cos(theta[j])");
    der = replace(step,
                  "vy[j in 1..links] = vy[j-1] + len*theta_dot[j]*cos(theta[j])",
                  "vy[j in 1..links] = der(py[j])\npy[0] = 0\n"
                  "py[j in 1..links] = py[j-1] + len*sin(theta[j])");
    free(step);
    if (!hand || !der) {
        fprintf(stderr, "bench-der: %s is not the shipped closed chain\n",
                path);
        return 1;
    }
    printf("closed chain (1 mode per link): hand-written velocities "
           "against der() of the positions\n");
    printf("%6s %10s %10s %7s %12s %12s %7s %10s\n", "links", "ops hand",
           "ops der", "ratio", "rhs hand us", "rhs der us", "ratio",
           "rhs diff");
    for (k = 0; k < (int)(sizeof sizes / sizeof sizes[0]); k++) {
        int N = sizes[k], n;
        size_t oh = 0, od = 0;
        eom_system *a, *b;
        double *x, *xa, *xb, diff = 0.0, th, td;
        if (quick && N > 20)
            break;
        a = system_of(hand, N, &oh);
        b = system_of(der, N, &od);
        if (!a || !b) {
            bad = 1;
            eom_system_free(&a);
            eom_system_free(&b);
            break;
        }
        n = eom_system_ncoords(a);
        x = calloc(2 * (size_t)n, sizeof *x);
        xa = calloc(2 * (size_t)n, sizeof *xa);
        xb = calloc(2 * (size_t)n, sizeof *xb);
        eom_initial_state(a, x);
        for (j = n; j < 2 * n; j++)
            x[j] = 0.1 * sin(1.0 + j);
        eom_rhs(a, 0.0, x, xa);
        eom_rhs(b, 0.0, x, xb);
        for (j = 0; j < 2 * n; j++)
            diff = fmax(diff, fabs(xa[j] - xb[j]) / fmax(1.0, fabs(xa[j])));
        th = rhs_median(a, quick);
        td = rhs_median(b, quick);
        printf("%6d %10zu %10zu %7.3f %12.2f %12.2f %7.3f %10.2g\n", N, oh,
               od, (double)od / (double)oh, 1e6 * th, 1e6 * td, td / th,
               diff);
        if (!(diff < 1e-9))
            bad = 1;
        free(x);
        free(xa);
        free(xb);
        eom_system_free(&a);
        eom_system_free(&b);
    }
    free(hand);
    free(der);
    return bad;
}
