/* chain.c - chains of rigid and flexible links (see eom/chain.h).
 *
 * Link j, root joint velocity P, chord direction e = (cos th, sin th),
 * normal n = (-sin th, cos th), S_c = P . n, S_s = P . e. With the modal
 * integrals (rho = m / L, phi_i = sin(i pi x / L))
 *     b_i = int rho phi_i      = 2 m / (i pi) for odd i, 0 for even i
 *     a_i = int rho x phi_i    = (-1)^(i+1) m L / (i pi)
 *     int rho phi_i phi_k      = m/2 delta_ik
 *     EI int phi_i'' phi_k''   = EI (i pi)^4 / (2 L^3) delta_ik
 * the kinetic energy of the link is
 *     T_j = 1/2 m |P|^2 + 1/2 m L thd S_c + 1/6 m L^2 thd^2     (rigid)
 *         + S_c (qd . b) - thd S_s (q . b) + thd (qd . a)
 *         + m/4 thd^2 |q|^2 + m/4 |qd|^2                          (flex)
 * and the next joint moves with P + L thd n (the deflection vanishes at
 * the joints). Gravity: g m (y_root + L/2 sin th) + g cos th (q . b).
 * The derivation is in docs/elements.md. Odd-mode sums carry the factors
 * 2/(i pi) as constants, so a mode with b_i = 0 records nothing.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom/chain.h"
#include "eom/drawing.h"

/* strict C11 has no M_PI */
static const double pi = 3.14159265358979323846;

enum probe_kind { PROBE_TRIGID, PROBE_TFLEX, PROBE_USTRAIN };

struct chain;

typedef struct chain_probe {
    const struct chain *ch;
    int link;
    int kind;
} chain_probe;

typedef struct chain {
    int N;
    int closed;
    int structural; /* structural damping of the modes */
    int *K;      /* [N] modes per link */
    int *th;     /* [N] coordinate index of theta_j */
    int *q;      /* [N] coordinate index of mode 1 of link j */
    unsigned char *damped, *sprung; /* [N + 1] */
    char prefix[32];
    chain_probe *probes; /* [3 N] */
    /* parameter indices (eom_param_at), resolved once when added */
    int *p_m, *p_L, *p_EI; /* [N] */
    int p_g, p_c, p_k, p_D, p_zeta, p_ray_a, p_ray_b;
} chain;

static void chain_free(void *p)
{
    chain *ch = p;
    if (!ch)
        return;
    free(ch->K);
    free(ch->th);
    free(ch->q);
    free(ch->damped);
    free(ch->sprung);
    free(ch->probes);
    free(ch->p_m);
    free(ch->p_L);
    free(ch->p_EI);
    free(ch);
}

/* Parameter base (+ link number j + 1 when j >= 0), with the prefix, by
 * the index resolved when the chain was added: callbacks run at every
 * evaluation on the tuple route, where formatting and looking up names
 * cost a third of an evaluation of a short chain. */
static tp_val par(eom_ctx *c, const chain *ch, const char *base, int j)
{
    int k;
    switch (base[0]) {
    case 'm': k = ch->p_m[j]; break;
    case 'L': k = ch->p_L[j]; break;
    case 'E': k = ch->p_EI[j]; break;
    case 'g': k = ch->p_g; break;
    case 'c': k = ch->p_c; break;
    case 'k': k = ch->p_k; break;
    case 'D': k = ch->p_D; break;
    case 'z': k = ch->p_zeta; break;
    default: k = base[4] == 'a' ? ch->p_ray_a : ch->p_ray_b; break;
    }
    return eom_param_at(c, k);
}

/* Sums over the modes of link j: sum w_i x_i with w_i = weight(i). */
static tp_val mode_sum(eom_ctx *c, const chain *ch, int j, int rates,
                       double (*weight)(int))
{
    tp_rec *R = eom_rec(c);
    tp_val s = tp_const(R, 0.0);
    int i;
    for (i = 1; i <= ch->K[j]; i++) {
        const double w = weight(i);
        tp_val x;
        if (w == 0.0)
            continue;
        x = rates ? eom_qd(c, ch->q[j] + i - 1) : eom_q(c, ch->q[j] + i - 1);
        s = tp_add(R, s, tp_mulc(R, x, w));
    }
    return s;
}

static double w_b(int i) { return i % 2 ? 2.0 / (i * pi) : 0.0; }
static double w_a(int i) { return (i % 2 ? 1.0 : -1.0) / (i * pi); }
static double w_one(int i) { return (void)i, 1.0; }
static double w_strain(int i)
{
    const double ip = i * pi;
    return ip * ip * ip * ip / 4.0;
}

/* sum_i w_i x_i^2 */
static tp_val mode_sqsum(eom_ctx *c, const chain *ch, int j, int rates,
                         double (*weight)(int))
{
    tp_rec *R = eom_rec(c);
    tp_val s = tp_const(R, 0.0);
    int i;
    for (i = 1; i <= ch->K[j]; i++) {
        tp_val x = rates ? eom_qd(c, ch->q[j] + i - 1)
                         : eom_q(c, ch->q[j] + i - 1);
        s = tp_add(R, s, tp_mulc(R, tp_sqr(R, x), weight(i)));
    }
    return s;
}

/* The kinetic energy of link j split in its rigid and flexible parts,
 * given the root joint velocity (px, py), which is advanced to the tip. */
static void link_kinetic(eom_ctx *c, const chain *ch, int j, tp_val *px,
                         tp_val *py, tp_val *trig, tp_val *tflex)
{
    tp_rec *R = eom_rec(c);
    tp_val th = eom_q(c, ch->th[j]), thd = eom_qd(c, ch->th[j]);
    tp_val m = par(c, ch, "m", j), L = par(c, ch, "L", j);
    tp_val s = tp_sin(R, th), co = tp_cos(R, th);
    tp_val Sc = tp_sub(R, tp_mul(R, *py, co), tp_mul(R, *px, s));
    tp_val P2 = tp_add(R, tp_sqr(R, *px), tp_sqr(R, *py));
    tp_val Lthd = tp_mul(R, L, thd);
    tp_val t = tp_add(R, tp_mulc(R, P2, 0.5),
                      tp_add(R, tp_mulc(R, tp_mul(R, Lthd, Sc), 0.5),
                             tp_mulc(R, tp_sqr(R, Lthd), 1.0 / 6.0)));
    *trig = tp_mul(R, m, t);
    if (ch->K[j] > 0) {
        tp_val Ss = tp_add(R, tp_mul(R, *px, co), tp_mul(R, *py, s));
        tp_val f = tp_mul(R, Sc, mode_sum(c, ch, j, 1, w_b));
        f = tp_sub(R, f, tp_mul(R, tp_mul(R, thd, Ss),
                                mode_sum(c, ch, j, 0, w_b)));
        f = tp_add(R, f, tp_mul(R, Lthd, mode_sum(c, ch, j, 1, w_a)));
        f = tp_add(R, f, tp_mulc(R, tp_mul(R, tp_sqr(R, thd),
                                           mode_sqsum(c, ch, j, 0, w_one)),
                                 0.25));
        f = tp_add(R, f, tp_mulc(R, mode_sqsum(c, ch, j, 1, w_one), 0.25));
        *tflex = tp_mul(R, m, f);
    } else {
        *tflex = tp_const(R, 0.0);
    }
    *px = tp_sub(R, *px, tp_mul(R, Lthd, s));
    *py = tp_add(R, *py, tp_mul(R, Lthd, co));
}

static tp_val link_strain(eom_ctx *c, const chain *ch, int j)
{
    tp_rec *R = eom_rec(c);
    tp_val L;
    if (ch->K[j] == 0)
        return tp_const(R, 0.0);
    /* 1/2 EI (i pi)^4 / (2 L^3) q_i^2 summed */
    L = par(c, ch, "L", j);
    return tp_mul(R, tp_div(R, par(c, ch, "EI", j), tp_powi(R, L, 3)),
                  mode_sqsum(c, ch, j, 0, w_strain));
}

static int chain_T(eom_ctx *c, void *user, tp_val *out)
{
    const chain *ch = user;
    tp_rec *R = eom_rec(c);
    tp_val px = tp_const(R, 0.0), py = tp_const(R, 0.0);
    tp_val T = tp_const(R, 0.0), tr, tf;
    int j;
    for (j = 0; j < ch->N; j++) {
        link_kinetic(c, ch, j, &px, &py, &tr, &tf);
        T = tp_add(R, T, tp_add(R, tr, tf));
    }
    *out = T;
    return 0;
}

/* Relative angle (rates: rate) across joint j. */
static tp_val joint_rel(eom_ctx *c, const chain *ch, int j, int rates)
{
    tp_rec *R = eom_rec(c);
    tp_val (*get)(eom_ctx *, int) = rates ? eom_qd : eom_q;
    if (j == 0)
        return get(c, ch->th[0]);
    if (j == ch->N)
        return get(c, ch->th[ch->N - 1]);
    return tp_sub(R, get(c, ch->th[j]), get(c, ch->th[j - 1]));
}

static int chain_V(eom_ctx *c, void *user, tp_val *out)
{
    const chain *ch = user;
    tp_rec *R = eom_rec(c);
    tp_val y = tp_const(R, 0.0), Vg = tp_const(R, 0.0);
    tp_val V = tp_const(R, 0.0), g = par(c, ch, "g", -1);
    int j;
    for (j = 0; j < ch->N; j++) {
        tp_val th = eom_q(c, ch->th[j]);
        tp_val m = par(c, ch, "m", j), L = par(c, ch, "L", j);
        tp_val s = tp_sin(R, th), Ls = tp_mul(R, L, s);
        tp_val h = tp_add(R, y, tp_mulc(R, Ls, 0.5)); /* chord centre */
        if (ch->K[j] > 0)
            h = tp_add(R, h, tp_mul(R, tp_cos(R, th),
                                    mode_sum(c, ch, j, 0, w_b)));
        Vg = tp_add(R, Vg, tp_mul(R, m, h));
        y = tp_add(R, y, Ls);
        V = tp_add(R, V, link_strain(c, ch, j));
    }
    V = tp_add(R, V, tp_mul(R, g, Vg));
    for (j = 0; j <= ch->N; j++)
        if (ch->sprung[j])
            V = tp_add(R, V, tp_mul(R, tp_mulc(R, par(c, ch, "k", -1), 0.5),
                                    tp_sqr(R, joint_rel(c, ch, j, 0))));
    *out = V;
    return 0;
}

/* 1/2 sum_i c_ji qd_ji^2 of link j's modes (chain.h): modal and
 * Rayleigh damping of the flexible coordinates. */
static tp_val link_structural(eom_ctx *c, const chain *ch, int j)
{
    tp_rec *R = eom_rec(c);
    tp_val m = par(c, ch, "m", j), L = par(c, ch, "L", j);
    tp_val kmodal = tp_div(R, tp_mulc(R, par(c, ch, "EI", j), 0.5),
                           tp_powi(R, L, 3)); /* k_ji / (i pi)^4 */
    tp_val mmodal = tp_mulc(R, m, 0.5);
    tp_val zeta = par(c, ch, "zeta", -1), a = par(c, ch, "ray_a", -1);
    tp_val b = par(c, ch, "ray_b", -1);
    tp_val sum = tp_const(R, 0.0);
    int i;
    for (i = 1; i <= ch->K[j]; i++) {
        const double ip4 = (i * pi) * (i * pi) * (i * pi) * (i * pi);
        tp_val k = tp_mulc(R, kmodal, ip4);
        tp_val cji = tp_add(R,
                            tp_mulc(R, tp_mul(R, zeta,
                                              tp_sqrt(R, tp_mul(R, k,
                                                                mmodal))),
                                    2.0),
                            tp_add(R, tp_mul(R, a, mmodal), tp_mul(R, b, k)));
        tp_val qd = eom_qd(c, ch->q[j] + i - 1);
        sum = tp_add(R, sum, tp_mul(R, cji, tp_sqr(R, qd)));
    }
    return tp_mulc(R, sum, 0.5);
}

static int chain_R(eom_ctx *c, void *user, tp_val *out)
{
    const chain *ch = user;
    tp_rec *R = eom_rec(c);
    tp_val sum = tp_const(R, 0.0), total;
    int j, any = 0;
    for (j = 0; j <= ch->N; j++)
        if (ch->damped[j]) {
            sum = tp_add(R, sum, tp_sqr(R, joint_rel(c, ch, j, 1)));
            any = 1;
        }
    total = any ? tp_mul(R, tp_mulc(R, par(c, ch, "c", -1), 0.5), sum)
                : tp_const(R, 0.0);
    for (j = 0; ch->structural && j < ch->N; j++)
        if (ch->K[j] > 0)
            total = tp_add(R, total, link_structural(c, ch, j));
    *out = total;
    return 0;
}

static int chain_phi(eom_ctx *c, void *user, tp_val *out)
{
    const chain *ch = user;
    tp_rec *R = eom_rec(c);
    tp_val x = tp_neg(R, par(c, ch, "D", -1)), y = tp_const(R, 0.0);
    int j;
    for (j = 0; j < ch->N; j++) {
        tp_val L = par(c, ch, "L", j), th = eom_q(c, ch->th[j]);
        x = tp_add(R, x, tp_mul(R, L, tp_cos(R, th)));
        y = tp_add(R, y, tp_mul(R, L, tp_sin(R, th)));
    }
    out[0] = x;
    out[1] = y;
    return 0;
}

static int chain_probe_fn(eom_ctx *c, void *user, tp_val *out)
{
    const chain_probe *p = user;
    const chain *ch = p->ch;
    tp_rec *R = eom_rec(c);
    tp_val px = tp_const(R, 0.0), py = tp_const(R, 0.0), tr, tf;
    int j;
    if (p->kind == PROBE_USTRAIN) {
        *out = link_strain(c, ch, p->link);
        return 0;
    }
    /* the joint velocity up to this link (shared with other probes by
     * hash-consing on the tape) */
    for (j = 0; j <= p->link; j++)
        link_kinetic(c, ch, j, &px, &py, &tr, &tf);
    *out = p->kind == PROBE_TRIGID ? tr : tf;
    return 0;
}

/* ---- adding a chain to a model ------------------------------------------ */

static int fail(eom_model *m, int status)
{
    return status < 0 ? status : (m ? EOM_ERR_MODEL : EOM_ERR_NULL);
}

static int add_param(eom_model *m, const chain *ch, const char *base, int j,
                     const char *unit, double dflt, const char *what,
                     int *index)
{
    char name[64], desc[96];
    if (j >= 0) {
        snprintf(name, sizeof name, "%s%s%d", ch->prefix, base, j + 1);
        snprintf(desc, sizeof desc, "%s of link %d", what, j + 1);
    } else {
        snprintf(name, sizeof name, "%s%s", ch->prefix, base);
        snprintf(desc, sizeof desc, "%s", what);
    }
    return *index = eom_model_add_param(m, name, unit, dflt, desc);
}

static double pick(const double *arr, int j, double shared)
{
    return arr ? arr[j] : shared;
}

/* ---- drawings (eom/drawing.h) ----------------------------------------
 * Each link as the deflected beam through five points, x = k/4 of its
 * length along it and sum_i q_i sin(i pi x) across it (the assumed modes
 * of the energies above), its joints and its tip: what the animation page
 * of a run shows. */

/* The joint before link j (j = N: the tip), component 0 (x) or 1 (y). */
static tp_val chain_joint(eom_ctx *c, const chain *ch, int j, int comp)
{
    tp_rec *r = eom_rec(c);
    tp_val v = tp_const(r, 0.0);
    int i;
    for (i = 0; i < j; i++) {
        const tp_val th = eom_q(c, ch->th[i]);
        v = tp_add(r, v, tp_mul(r, eom_param_at(c, ch->p_L[i]),
                                comp ? tp_sin(r, th) : tp_cos(r, th)));
    }
    return v;
}

static int chain_draw_fn(eom_ctx *c, void *user, tp_val *out)
{
    const chain_probe *p = user;
    const chain *ch = p->ch;
    const int j = p->link;
    tp_rec *r = eom_rec(c);
    int k, i;
    if (p->kind != 3) { /* a joint or the tip: a point */
        out[0] = chain_joint(c, ch, j, 0);
        out[1] = chain_joint(c, ch, j, 1);
        out[2] = tp_const(r, 0.0);
        return 0;
    }
    {
        const tp_val x0 = chain_joint(c, ch, j, 0),
                     y0 = chain_joint(c, ch, j, 1),
                     th = eom_q(c, ch->th[j]),
                     L = eom_param_at(c, ch->p_L[j]);
        const tp_val ct = tp_cos(r, th), st = tp_sin(r, th);
        for (k = 0; k <= 4; k++) {
            const double xi = k / 4.0;
            tp_val w = tp_const(r, 0.0), a = tp_mulc(r, L, xi);
            for (i = 1; i <= ch->K[j]; i++)
                w = tp_add(r, w, tp_mulc(r, eom_q(c, ch->q[j] + i - 1),
                                         sin(i * pi * xi)));
            out[3 * k] = tp_sub(r, tp_add(r, x0, tp_mul(r, a, ct)),
                                tp_mul(r, w, st));
            out[3 * k + 1] = tp_add(r, tp_add(r, y0, tp_mul(r, a, st)),
                                    tp_mul(r, w, ct));
            out[3 * k + 2] = tp_const(r, 0.0);
        }
    }
    return 0;
}

static int chain_drawings(eom_model *m, chain *ch)
{
    char name[64];
    int j, rc;
    for (j = 0; j <= 2 * ch->N; j++) {
        chain_probe *p = &ch->probes[3 * ch->N + j];
        p->ch = ch;
        p->link = j < ch->N ? j : j - ch->N;
        p->kind = j < ch->N ? 3 : j < 2 * ch->N ? 4 : 5;
        if (p->kind == 3)
            snprintf(name, sizeof name, "%slink%d", ch->prefix, j + 1);
        else if (p->kind == 4)
            snprintf(name, sizeof name, "%sjoint%d", ch->prefix, p->link);
        else
            snprintf(name, sizeof name, "%stip", ch->prefix);
        rc = eom_model_add_drawing(
            m, name, p->kind == 3 ? EOM_DRAW_POLYLINE : EOM_DRAW_POINT,
            p->kind == 3 ? 15 : 3,
            p->kind == 3 ? 0x1f5fbfu : p->kind == 4 ? 0x000000u : 0xe41a1cu,
            p->kind == 5 ? EOM_DRAW_TRAIL : 0, chain_draw_fn, p);
        if (rc < 0)
            return rc;
    }
    return 0;
}

int eom_chain_add(eom_model *m, const eom_chain_spec *sp)
{
    chain *ch;
    char name[64];
    int N, j, i, rc, first, nq = 0, any_damped = 0, any_sprung = 0;
    if (!m || !sp)
        return EOM_ERR_NULL;
    N = sp->links;
    if (N < 1 || N > 100000 || (sp->prefix && strlen(sp->prefix) > 16))
        return EOM_ERR_ARG;
    ch = calloc(1, sizeof *ch);
    if (!ch)
        return EOM_ERR_NOMEM;
    ch->N = N;
    ch->closed = sp->closed != 0;
    ch->structural = sp->structural != 0;
    snprintf(ch->prefix, sizeof ch->prefix, "%s",
             sp->prefix ? sp->prefix : "");
    ch->K = calloc((size_t)N, sizeof(int));
    ch->th = calloc((size_t)N, sizeof(int));
    ch->q = calloc((size_t)N, sizeof(int));
    ch->damped = calloc((size_t)N + 1, 1);
    ch->sprung = calloc((size_t)N + 1, 1);
    /* the probes, then the drawings: links, joints, the tip */
    ch->probes = calloc(5 * (size_t)N + 1, sizeof *ch->probes);
    ch->p_m = malloc((size_t)N * sizeof(int));
    ch->p_L = malloc((size_t)N * sizeof(int));
    ch->p_EI = malloc((size_t)N * sizeof(int));
    if (!ch->K || !ch->th || !ch->q || !ch->damped || !ch->sprung ||
        !ch->probes || !ch->p_m || !ch->p_L || !ch->p_EI) {
        chain_free(ch);
        return EOM_ERR_NOMEM;
    }
    /* absent parameters: an index no parameter has */
    for (j = 0; j < N; j++)
        ch->p_m[j] = ch->p_L[j] = ch->p_EI[j] = -1;
    ch->p_g = ch->p_c = ch->p_k = ch->p_D = -1;
    ch->p_zeta = ch->p_ray_a = ch->p_ray_b = -1;
    /* the model owns the description from here on */
    if ((rc = eom_model_attach(m, ch, chain_free)) != EOM_OK)
        return rc;
    for (j = 0; j < N; j++) {
        ch->K[j] = sp->modes ? sp->modes[j] : sp->modes_all;
        if (ch->K[j] < 0 || ch->K[j] > 64)
            return EOM_ERR_ARG;
        nq += ch->K[j];
    }
    for (j = 0; j <= N; j++) {
        ch->damped[j] = sp->damped && sp->damped[j];
        ch->sprung[j] = sp->sprung && sp->sprung[j];
        if (j == N && !ch->closed)
            ch->damped[j] = ch->sprung[j] = 0; /* no tip joint */
        any_damped |= ch->damped[j];
        any_sprung |= ch->sprung[j];
    }

    /* coordinates: the angles, then the modes link by link */
    first = eom_model_ncoords(m);
    for (j = 0; j < N; j++) {
        snprintf(name, sizeof name, "%stheta%d", ch->prefix, j + 1);
        rc = eom_model_add_coord(m, name, "rad",
                                 sp->theta0 ? sp->theta0[j] : 0.0,
                                 sp->theta0_dot ? sp->theta0_dot[j] : 0.0);
        if (rc < 0)
            return fail(m, rc);
        ch->th[j] = rc;
    }
    nq = 0;
    for (j = 0; j < N; j++) {
        ch->q[j] = eom_model_ncoords(m);
        for (i = 1; i <= ch->K[j]; i++, nq++) {
            snprintf(name, sizeof name, "%sq%d_%d", ch->prefix, j + 1, i);
            rc = eom_model_add_coord(m, name, "m", sp->q0 ? sp->q0[nq] : 0.0,
                                     sp->q0_dot ? sp->q0_dot[nq] : 0.0);
            if (rc < 0)
                return fail(m, rc);
        }
    }

    /* parameters */
    for (j = 0; j < N; j++) {
        if ((rc = add_param(m, ch, "m", j, "kg", pick(sp->m_link, j, sp->m),
                            "mass", &ch->p_m[j])) < 0 ||
            (rc = add_param(m, ch, "L", j, "m", pick(sp->L_link, j, sp->L),
                            "length", &ch->p_L[j])) < 0)
            return fail(m, rc);
        if (ch->K[j] > 0 &&
            (rc = add_param(m, ch, "EI", j, "N m^2",
                            pick(sp->EI_link, j, sp->EI),
                            "bending stiffness", &ch->p_EI[j])) < 0)
            return fail(m, rc);
    }
    if ((rc = add_param(m, ch, "g", -1, "m/s^2", sp->g,
                        "gravity along -y", &ch->p_g)) < 0)
        return fail(m, rc);
    if (any_damped && (rc = add_param(m, ch, "c", -1, "N m s/rad", sp->c,
                                      "joint damping", &ch->p_c)) < 0)
        return fail(m, rc);
    if (any_sprung && (rc = add_param(m, ch, "k", -1, "N m/rad", sp->k,
                                      "joint stiffness", &ch->p_k)) < 0)
        return fail(m, rc);
    if (ch->closed && (rc = add_param(m, ch, "D", -1, "m", sp->D,
                                      "x of the tip pin", &ch->p_D)) < 0)
        return fail(m, rc);
    if (ch->structural &&
        ((rc = add_param(m, ch, "zeta", -1, NULL, sp->zeta,
                         "modal damping ratio of every mode", &ch->p_zeta)) < 0 ||
         (rc = add_param(m, ch, "ray_a", -1, "1/s", sp->ray_a,
                         "Rayleigh damping of the modes: a of a M + b K",
                         &ch->p_ray_a)) <
             0 ||
         (rc = add_param(m, ch, "ray_b", -1, "s", sp->ray_b,
                         "Rayleigh damping of the modes: b of a M + b K",
                         &ch->p_ray_b)) <
             0))
        return fail(m, rc);

    /* energies, constraints, probes */
    if ((rc = eom_model_add_kinetic(m, chain_T, ch)) < 0 ||
        (rc = eom_model_add_potential(m, chain_V, ch)) < 0)
        return fail(m, rc);
    if ((any_damped || ch->structural) &&
        (rc = eom_model_add_dissipation(m, chain_R, ch)) < 0)
        return fail(m, rc);
    if (ch->closed &&
        (rc = eom_model_add_constraints(m, 2, chain_phi, ch)) < 0)
        return fail(m, rc);
    for (j = 0; j < N; j++) {
        static const char *const fmt[3] = {"%sT%d_rigid", "%sT%d_flex",
                                           "%sU%d_strain"};
        for (i = 0; i < 3; i++) {
            chain_probe *p = &ch->probes[3 * j + i];
            if (i > 0 && ch->K[j] == 0)
                continue; /* a rigid link has no flexible part */
            p->ch = ch;
            p->link = j;
            p->kind = i;
            snprintf(name, sizeof name, fmt[i], ch->prefix, j + 1);
            if ((rc = eom_model_add_probe(m, name, "J", chain_probe_fn,
                                          p)) < 0)
                return fail(m, rc);
        }
    }
    if ((rc = chain_drawings(m, ch)) < 0)
        return fail(m, rc);
    return first;
}
