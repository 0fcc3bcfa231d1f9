/* reverse.c - reverse sweeps: adjoints (gradients) and forward-over-reverse
 * (adjoints and their p directional derivatives: Hessian-vector products).
 *
 * Both run after a forward sweep that left values (and, for the second,
 * tangents) in the workspace. Op i writes slot i, so walking i downwards
 * needs no result array.
 *
 * Invariant: ws->adj and ws->atan are zero between sweeps. A sweep seeds
 * the outputs, and each op, when visited, consumes its adjoint and adjoint
 * tangent row and zeroes them; the independents' entries are copied out and
 * zeroed at the end. So no O(n_ops * p) clearing pass is ever needed.
 *
 * Skipping structural zeros: a passive op (depends on no independent)
 * propagates nothing; an op whose adjoint is zero propagates no adjoint; an
 * op outside the seeded groups has a zero tangent, so the second-order term
 * of forward-over-reverse vanishes and only the linear part remains.
 */
#include <string.h>

#include "sweep.h"

static void seed_outputs(tp_ws *ws, const double *w)
{
    const tp_tape *T = ws->t;
    uint32_t o;
    for (o = 0; o < T->n_out; o++)
        if (w[o] != 0.0)
            ws->adj[T->out_slot[o]] += w[o];
}

void tp__rev1(tp_ws *ws, const double *w, uint32_t end, double *g)
{
    const tp_tape *T = ws->t;
    const uint8_t *opc = T->opc, *dep = T->dep;
    const uint32_t *a0 = T->a0, *a1 = T->a1;
    const uint32_t n_in = T->n_indep + T->n_param;
    const double *v = ws->v, *aux = ws->aux;
    double *adj = ws->adj;
    uint32_t i;

    seed_outputs(ws, w);
    for (i = end; i-- > n_in;) {
        const double a = adj[i];
        const unsigned op = opc[i];
        tp_partials d;
        if (a == 0.0)
            continue;
        adj[i] = 0.0;
        if (!dep[i])
            continue; /* passive: its operands are passive too */
        switch (op) {
        case TP_OP_ADD:
            adj[a0[i]] += a;
            adj[a1[i]] += a;
            break;
        case TP_OP_SUB:
            adj[a0[i]] += a;
            adj[a1[i]] -= a;
            break;
        case TP_OP_MUL:
            adj[a0[i]] += a * v[a1[i]];
            adj[a1[i]] += a * v[a0[i]];
            break;
        case TP_OP_NEG: adj[a0[i]] -= a; break;
        case TP_OP_ADDC: adj[a0[i]] += a; break;
        case TP_OP_MULC: adj[a0[i]] += a * T->konst[a1[i]]; break;
        default:
            tp__partials_at(T, v, aux, i, op, &d);
            adj[a0[i]] += d.fu * a;
            if (tp__opinfo[op].kind == TP_KIND_BINARY)
                adj[a1[i]] += d.ft * a;
            break;
        }
    }
    for (i = 0; i < n_in; i++) {
        if (g && i < T->n_indep)
            g[i] = adj[i];
        adj[i] = 0.0;
    }
}

void tp__rev2(tp_ws *ws, const double *w, int p, unsigned mask, uint32_t end,
              double *g, double *HS, size_t ldh)
{
    const tp_tape *T = ws->t;
    const uint8_t *opc = T->opc, *dep = T->dep;
    const uint32_t *a0 = T->a0, *a1 = T->a1;
    const uint32_t n_in = T->n_indep + T->n_param;
    const size_t P = (size_t)ws->P;
    const double *v = ws->v, *aux = ws->aux, *tan = ws->tan;
    double *adj = ws->adj, *atan = ws->atan;
    const size_t rowbytes = (size_t)p * sizeof(double);
    uint32_t i;
    int k;

    seed_outputs(ws, w);
    for (i = end; i-- > n_in;) {
        const double a = adj[i];
        const unsigned op = opc[i];
        double *ra = atan + i * P;
        double *ru, *rt;
        const double *tu, *tt;
        tp_partials d;
        adj[i] = 0.0;
        if (!dep[i]) {
            memset(ra, 0, rowbytes);
            continue;
        }
        ru = atan + a0[i] * P;
        tp__partials_at(T, v, aux, i, op, &d);
        adj[a0[i]] += d.fu * a;
        if (tp__opinfo[op].kind != TP_KIND_BINARY) {
            if ((dep[i] & mask) && a != 0.0 && d.fuu != 0.0) {
                const double s = a * d.fuu;
                tu = tan + a0[i] * P;
                for (k = 0; k < p; k++)
                    ru[k] += d.fu * ra[k] + s * tu[k];
            } else if (op == TP_OP_ADDC) {
                for (k = 0; k < p; k++)
                    ru[k] += ra[k];
            } else {
                for (k = 0; k < p; k++)
                    ru[k] += d.fu * ra[k];
            }
        } else {
            adj[a1[i]] += d.ft * a;
            rt = atan + a1[i] * P;
            if ((dep[i] & mask) && a != 0.0 &&
                !(tp__opinfo[op].flags & TP_FLAG_LIN)) {
                tu = tan + a0[i] * P;
                tt = tan + a1[i] * P;
                if (op == TP_OP_MUL) { /* fuu = ftt = 0, fut = 1 */
                    for (k = 0; k < p; k++) {
                        const double r = ra[k];
                        ru[k] += d.fu * r + a * tt[k];
                        rt[k] += d.ft * r + a * tu[k];
                    }
                } else {
                    const double suu = a * d.fuu, sut = a * d.fut,
                                 stt = a * d.ftt;
                    for (k = 0; k < p; k++) {
                        const double r = ra[k], x = tu[k], y = tt[k];
                        ru[k] += d.fu * r + suu * x + sut * y;
                        rt[k] += d.ft * r + sut * x + stt * y;
                    }
                }
            } else if (op == TP_OP_ADD) {
                for (k = 0; k < p; k++) {
                    ru[k] += ra[k];
                    rt[k] += ra[k];
                }
            } else {
                for (k = 0; k < p; k++) {
                    const double r = ra[k];
                    ru[k] += d.fu * r;
                    rt[k] += d.ft * r;
                }
            }
        }
        memset(ra, 0, rowbytes);
    }
    for (i = 0; i < n_in; i++) {
        double *ra = atan + i * P;
        if (i < T->n_indep) {
            if (g)
                g[i] = adj[i];
            if (HS)
                memcpy(HS + i * ldh, ra, rowbytes);
        }
        adj[i] = 0.0;
        memset(ra, 0, rowbytes);
    }
}
