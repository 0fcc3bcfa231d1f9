/* eom_models.c - the test mechanisms of eom_models.h, written against the
 * recording API as a user would. */
#include <stdio.h>
#include <stdlib.h>

#include "eom_models.h"

/* ---- spring pendulum ---------------------------------------------------- */

static int sp_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val r = eom_q(c, 0), rd = eom_qd(c, 0), thd = eom_qd(c, 1);
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "m"), 0.5),
                  tp_add(R, tp_sqr(R, rd),
                         tp_mul(R, tp_sqr(R, r), tp_sqr(R, thd))));
    return 0;
}

static int sp_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val r = eom_q(c, 0), th = eom_q(c, 1);
    tp_val m = eom_param(c, "m"), k = eom_param(c, "k");
    tp_val r0 = eom_param(c, "r0"), g = eom_param(c, "g");
    (void)user;
    *out = tp_add(R, tp_mul(R, tp_mulc(R, k, 0.5), tp_sqr(R, tp_sub(R, r, r0))),
                  tp_mul(R, tp_mul(R, m, g),
                         tp_sub(R, r0, tp_mul(R, r, tp_cos(R, th)))));
    return 0;
}

eom_model *eom_models_spring_pendulum(double m, double k, double r0, double g)
{
    eom_model *md = NULL;
    if (eom_model_new(&md) != EOM_OK)
        return NULL;
    eom_model_add_coord(md, "r", "m", r0 + 0.1, 0.0);
    eom_model_add_coord(md, "theta", "rad", 0.5, 0.0);
    eom_model_add_param(md, "m", "kg", m, "mass");
    eom_model_add_param(md, "k", "N/m", k, "spring stiffness");
    eom_model_add_param(md, "r0", "m", r0, "unstretched length");
    eom_model_add_param(md, "g", "m/s^2", g, "gravity");
    eom_model_set_kinetic(md, sp_T, NULL);
    eom_model_set_potential(md, sp_V, NULL);
    if (eom_model_errmsg(md)[0]) {
        eom_model_free(&md);
        return NULL;
    }
    return md;
}

/* ---- chains of uniform rods --------------------------------------------- */

typedef struct chain {
    int n;
} chain;

static tp_val pnamed(eom_ctx *c, const char *base, int i)
{
    char name[32];
    snprintf(name, sizeof name, "%s%d", base, i + 1);
    return eom_param(c, name);
}

/* T: the joint velocity is accumulated link by link. */
static int chain_T(eom_ctx *c, void *user, tp_val *out)
{
    const chain *ch = user;
    tp_rec *R = eom_rec(c);
    tp_val px = tp_const(R, 0.0), py = tp_const(R, 0.0);
    tp_val T = tp_const(R, 0.0);
    int j;
    for (j = 0; j < ch->n; j++) {
        tp_val th = eom_q(c, j), thd = eom_qd(c, j);
        tp_val m = pnamed(c, "m", j), l = pnamed(c, "l", j);
        tp_val s = tp_sin(R, th), co = tp_cos(R, th);
        tp_val w = tp_mul(R, l, thd); /* speed of the tip relative to root */
        /* centre: root velocity + (l/2) thd (-sin, cos) */
        tp_val vx = tp_sub(R, px, tp_mul(R, tp_mulc(R, w, 0.5), s));
        tp_val vy = tp_add(R, py, tp_mul(R, tp_mulc(R, w, 0.5), co));
        T = tp_add(R, T, tp_mul(R, tp_mulc(R, m, 0.5),
                                tp_add(R, tp_sqr(R, vx), tp_sqr(R, vy))));
        T = tp_add(R, T, tp_mul(R, tp_mulc(R, m, 1.0 / 24.0), tp_sqr(R, w)));
        px = tp_sub(R, px, tp_mul(R, w, s));
        py = tp_add(R, py, tp_mul(R, w, co));
    }
    *out = T;
    return 0;
}

static int chain_V(eom_ctx *c, void *user, tp_val *out)
{
    const chain *ch = user;
    tp_rec *R = eom_rec(c);
    tp_val y = tp_const(R, 0.0), V = tp_const(R, 0.0), g = eom_param(c, "g");
    int j;
    for (j = 0; j < ch->n; j++) {
        tp_val m = pnamed(c, "m", j), l = pnamed(c, "l", j);
        tp_val ly = tp_mul(R, l, tp_sin(R, eom_q(c, j)));
        V = tp_add(R, V, tp_mul(R, tp_mul(R, m, g),
                                tp_add(R, y, tp_mulc(R, ly, 0.5))));
        y = tp_add(R, y, ly);
    }
    *out = V;
    return 0;
}

static int chain_phi(eom_ctx *c, void *user, tp_val *out)
{
    const chain *ch = user;
    tp_rec *R = eom_rec(c);
    tp_val x = tp_neg(R, eom_param(c, "D")), y = tp_const(R, 0.0);
    int j;
    for (j = 0; j < ch->n; j++) {
        tp_val l = pnamed(c, "l", j), th = eom_q(c, j);
        x = tp_add(R, x, tp_mul(R, l, tp_cos(R, th)));
        y = tp_add(R, y, tp_mul(R, l, tp_sin(R, th)));
    }
    out[0] = x;
    out[1] = y;
    return 0;
}

/* The chain descriptions live as long as the process: a model keeps the
 * user pointer, and tests make few models. */
static chain chains[64];
static int n_chains;

eom_model *eom_models_rod_chain(int n, const double *m, const double *l,
                                const double *th0, double g, int closed,
                                double D)
{
    eom_model *md = NULL;
    char name[32];
    chain *ch;
    int j;
    if (n < 1 || n_chains == 64 || eom_model_new(&md) != EOM_OK)
        return NULL;
    ch = &chains[n_chains++];
    ch->n = n;
    for (j = 0; j < n; j++) {
        snprintf(name, sizeof name, "th%d", j + 1);
        eom_model_add_coord(md, name, "rad", th0[j], 0.0);
    }
    for (j = 0; j < n; j++) {
        snprintf(name, sizeof name, "m%d", j + 1);
        eom_model_add_param(md, name, "kg", m[j], "mass of a rod");
        snprintf(name, sizeof name, "l%d", j + 1);
        eom_model_add_param(md, name, "m", l[j], "length of a rod");
    }
    eom_model_add_param(md, "g", "m/s^2", g, "gravity");
    eom_model_set_kinetic(md, chain_T, ch);
    eom_model_set_potential(md, chain_V, ch);
    if (closed) {
        eom_model_add_param(md, "D", "m", D, "distance of the pins");
        eom_model_set_constraints(md, 2, chain_phi, ch);
    }
    if (eom_model_errmsg(md)[0]) {
        eom_model_free(&md);
        return NULL;
    }
    return md;
}

/* ---- bead on a circle --------------------------------------------------- */

static int bead_T(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, tp_mulc(R, eom_param(c, "m"), 0.5),
                  tp_add(R, tp_sqr(R, eom_qd(c, 0)), tp_sqr(R, eom_qd(c, 1))));
    return 0;
}

static int bead_V(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    (void)user;
    *out = tp_mul(R, tp_mul(R, eom_param(c, "m"), eom_param(c, "g")),
                  eom_q(c, 1));
    return 0;
}

static int bead_phi(eom_ctx *c, void *user, tp_val *out)
{
    tp_rec *R = eom_rec(c);
    tp_val r2 = tp_add(R, tp_sqr(R, eom_q(c, 0)), tp_sqr(R, eom_q(c, 1)));
    (void)user;
    out[0] = tp_mulc(R, tp_sub(R, r2, tp_sqr(R, eom_param(c, "l"))), 0.5);
    return 0;
}

eom_model *eom_models_bead_on_circle(double m, double l, double g)
{
    eom_model *md = NULL;
    if (eom_model_new(&md) != EOM_OK)
        return NULL;
    eom_model_add_coord(md, "x", "m", 0.0, 0.0);
    eom_model_add_coord(md, "y", "m", -l, 0.0);
    eom_model_add_param(md, "m", "kg", m, "mass");
    eom_model_add_param(md, "l", "m", l, "radius");
    eom_model_add_param(md, "g", "m/s^2", g, "gravity");
    eom_model_set_kinetic(md, bead_T, NULL);
    eom_model_set_potential(md, bead_V, NULL);
    eom_model_set_constraints(md, 1, bead_phi, NULL);
    if (eom_model_errmsg(md)[0]) {
        eom_model_free(&md);
        return NULL;
    }
    return md;
}
