/* mass_line.c - the line of point masses of mass_line.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "mass_line.h"

typedef struct line {
    int N;
    int reach; /* springs from each mass to the next reach masses */
    int blocks; /* mass_line_blocks_model's mass blocks: 0 (diagonal),
                   2 or 4 */
} line;

static int line_T(eom_ctx *c, void *user, tp_val *out)
{
    const line *ln = user;
    tp_rec *R = eom_rec(c);
    tp_val *v = malloc(2 * (size_t)ln->N * sizeof *v);
    int i;
    if (!v)
        return 1;
    for (i = 0; i < 2 * ln->N; i++)
        v[i] = eom_qd(c, i);
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "m"), 0.5),
                  tp_dot(R, 2 * ln->N, v, v));
    free(v);
    return 0;
}

/* mass_line_blocks_model's T: line_T's plus 0.3 m xd_i yd_i for each
 * mass (2 x 2 blocks), and with blocks 4 0.2 m v_2i . v_2i+1 for each
 * pair of masses (4 x 4 blocks); diagonally dominant, so M stays
 * positive definite. */
static int line_T_blocks(eom_ctx *c, void *user, tp_val *out)
{
    const line *ln = user;
    tp_rec *R = eom_rec(c);
    tp_val *t = malloc(2 * (size_t)ln->N * sizeof *t), T0, m;
    int i, cnt = 0;
    if (!t || line_T(c, user, &T0) != 0) {
        free(t);
        return 1;
    }
    m = eom_param(c, "m");
    for (i = 0; i < ln->N; i++)
        t[cnt++] = tp_mul(R, eom_qd(c, 2 * i), eom_qd(c, 2 * i + 1));
    *out = tp_add(R, T0, tp_mul(R, tp_mulc(R, m, 0.3), tp_sum(R, cnt, t)));
    if (ln->blocks == 4) {
        cnt = 0;
        for (i = 0; i + 1 < ln->N; i += 2)
            t[cnt++] = tp_add(R, tp_mul(R, eom_qd(c, 2 * i),
                                        eom_qd(c, 2 * i + 2)),
                              tp_mul(R, eom_qd(c, 2 * i + 1),
                                     eom_qd(c, 2 * i + 3)));
        *out = tp_add(R, *out,
                      tp_mul(R, tp_mulc(R, m, 0.2), tp_sum(R, cnt, t)));
    }
    free(t);
    return 0;
}

/* |r_j - r_i| */
static tp_val gap(eom_ctx *c, int i, int j)
{
    tp_rec *R = eom_rec(c);
    return tp_hypot(R, tp_sub(R, eom_q(c, 2 * j), eom_q(c, 2 * i)),
                    tp_sub(R, eom_q(c, 2 * j + 1), eom_q(c, 2 * i + 1)));
}

static int line_V(eom_ctx *c, void *user, tp_val *out)
{
    const line *ln = user;
    tp_rec *R = eom_rec(c);
    tp_val *t = malloc((size_t)ln->N * (size_t)ln->reach * sizeof *t);
    tp_val a = eom_param(c, "a"), springs, heights;
    int i, k, cnt = 0;
    if (!t)
        return 1;
    for (i = 0; i + 1 < ln->N; i++)
        for (k = 1; k <= ln->reach && i + k < ln->N; k++)
            t[cnt++] = tp_sqr(R, tp_sub(R, gap(c, i, i + k),
                                        tp_mulc(R, a, (double)k)));
    springs = tp_sum(R, cnt, t);
    for (i = 0; i < ln->N; i++)
        t[i] = eom_q(c, 2 * i + 1);
    heights = tp_sum(R, ln->N, t);
    *out = tp_add(R, tp_mul(R, tp_mulc(R, eom_param(c, "k"), 0.5), springs),
                  tp_mul(R, tp_mul(R, eom_param(c, "m"), eom_param(c, "g")),
                         heights));
    free(t);
    return 0;
}

static int line_R(eom_ctx *c, void *user, tp_val *out)
{
    const line *ln = user;
    tp_rec *R = eom_rec(c);
    tp_val *t = malloc(2 * (size_t)ln->N * sizeof *t);
    int i;
    if (!t)
        return 1;
    for (i = 0; i + 1 < ln->N; i++)
        t[i] = tp_add(R, tp_sqr(R, tp_sub(R, eom_qd(c, 2 * i + 2),
                                          eom_qd(c, 2 * i))),
                      tp_sqr(R, tp_sub(R, eom_qd(c, 2 * i + 3),
                                       eom_qd(c, 2 * i + 1))));
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "c"), 0.5),
                  tp_sum(R, ln->N - 1, t));
    free(t);
    return 0;
}

static int line_phi(eom_ctx *c, void *user, tp_val *out)
{
    const line *ln = user;
    tp_rec *R = eom_rec(c);
    const int N = ln->N, j = N / 2 - 1;
    tp_val d = eom_param(c, "d");
    out[0] = eom_q(c, 0);
    out[1] = eom_q(c, 1);
    out[2] = tp_sub(R, eom_q(c, 2 * N - 2), eom_param(c, "X"));
    out[3] = tp_sub(R, tp_sqr(R, gap(c, j, j + 1)), tp_sqr(R, d));
    return 0;
}

/* The initial position of mass i. */
static void start(int N, double a, int i, double *x, double *y)
{
    *x = 0.98 * a * i;
    *y = -0.05 * a * (N - 1) * sin(3.14159265358979323846 * i / (N - 1));
}

static eom_model *line_model(int N, int constrained, int reach,
                             int blocks)
{
    const double a = 0.1;
    eom_model *md = NULL;
    line *ln;
    char name[32];
    double x, y, x1, y1;
    int i, j = N / 2 - 1;
    if (N < 4 || reach < 1 || reach >= N || eom_model_new(&md) != EOM_OK)
        return NULL;
    ln = malloc(sizeof *ln);
    if (!ln || eom_model_attach(md, ln, free) != EOM_OK) {
        eom_model_free(&md);
        return NULL;
    }
    ln->N = N;
    ln->reach = reach;
    ln->blocks = blocks;
    for (i = 0; i < N; i++) {
        start(N, a, i, &x, &y);
        snprintf(name, sizeof name, "x%d", i);
        eom_model_add_coord(md, name, "m", x, 0.0);
        snprintf(name, sizeof name, "y%d", i);
        eom_model_add_coord(md, name, "m", y, 0.0);
    }
    eom_model_add_param(md, "m", "kg", 0.1, "mass of each body");
    eom_model_add_param(md, "k", "N/m", 1e3, "stiffness of each spring");
    eom_model_add_param(md, "a", "m", a, "rest length of each spring");
    eom_model_add_param(md, "c", "N s/m", 0.05, "damping of each spring");
    eom_model_add_param(md, "g", "m/s^2", 9.81, "gravity");
    eom_model_set_kinetic(md, blocks ? line_T_blocks : line_T, ln);
    eom_model_set_potential(md, line_V, ln);
    eom_model_set_dissipation(md, line_R, ln);
    if (constrained) {
        start(N, a, N - 1, &x, &y);
        eom_model_add_param(md, "X", "m", x, "x of the rail");
        start(N, a, j, &x, &y);
        start(N, a, j + 1, &x1, &y1);
        eom_model_add_param(md, "d", "m", hypot(x1 - x, y1 - y),
                            "length of the rigid link");
        eom_model_set_constraints(md, 4, line_phi, ln);
    }
    if (eom_model_errmsg(md)[0]) {
        eom_model_free(&md);
        return NULL;
    }
    return md;
}

eom_model *mass_line_model(int N, int constrained, int reach)
{
    return line_model(N, constrained, reach, 0);
}

eom_model *mass_line_blocks_model(int N, int blocks)
{
    return blocks == 2 || blocks == 4 ? line_model(N, 0, 1, blocks) : NULL;
}
