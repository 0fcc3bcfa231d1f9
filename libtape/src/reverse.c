/* reverse.c - reverse sweeps: adjoints (gradients) and forward-over-reverse
 * (adjoints and their p directional derivatives: Hessian-vector products).
 *
 * Both run after a forward sweep that left values (and, for the second,
 * tangents) in the workspace. Op i writes slot i, so walking i downwards
 * needs no result array. Only active ops (from first_active) are visited,
 * and no adjoint or adjoint-tangent row of a passive slot is ever written
 * (finalize.c flags the passive operand of an active binary op).
 *
 * Invariant: ws->adj and ws->atan are zero between sweeps. A sweep seeds
 * the outputs, and each op, when visited, consumes its adjoint and adjoint
 * tangent row and zeroes them; at the end the independents' entries are
 * copied out and zeroed, and so are the seeds of passive outputs. No
 * O(n_ops * p) clearing pass is ever needed.
 *
 * Skipping structural zeros: an op whose adjoint is zero propagates no
 * adjoint; an op outside the seeded groups has a zero tangent, so the
 * second-order term of forward-over-reverse vanishes and only the linear
 * part remains; an op whose adjoint-tangent row is still all zero (anz[i]
 * == 0; for a Lagrangian, the chains of the potential energy) and that
 * adds no second-order term propagates only its scalar adjoint.
 */
#include <string.h>

#include "sweep.h"
#include "sweep_one.h"

static void seed_outputs(tp_ws *ws, const double *w)
{
    const tp_tape *T = ws->t;
    uint32_t o;
    for (o = 0; o < T->n_out; o++)
        if (w[o] != 0.0)
            ws->adj[T->out_slot[o]] += w[o];
}

/* Zero the adjoints seeded on outputs that no sweep visits (passive). */
void tp__clear_passive_seeds(tp_ws *ws)
{
    const tp_tape *T = ws->t;
    uint32_t o;
    for (o = 0; o < T->n_out; o++)
        if (T->out_slot[o] >= T->n_indep && T->out_slot[o] < T->first_active)
            ws->adj[T->out_slot[o]] = 0.0;
}

void tp__rev1(tp_ws *ws, const double *w, uint32_t end, double *g)
{
    const tp_tape *T = ws->t;
    const uint8_t *opc = T->opc, *dep = T->dep;
    const uint32_t *a0 = T->a0, *a1 = T->a1;
    const tp_kx kx = tp__kx(ws, 0, 0);
    double *adj = ws->adj;
    uint32_t i;

    seed_outputs(ws, w);
    if (ws->cc && ws->cc->rev1)
        ws->cc->rev1(&kx, end);
    else
        for (i = end; i-- > T->first_active;)
            tp__k_rev1(&kx, i, opc[i], dep[i], a0[i], a1[i]);
    for (i = 0; i < T->n_indep; i++) {
        if (g)
            g[i] = adj[i];
        adj[i] = 0.0;
    }
    tp__clear_passive_seeds(ws);
}

TP_VECTOR_CLONES
void tp__rev2(tp_ws *ws, const double *w, int p, unsigned mask, uint32_t end,
              double *g, double *HS, size_t ldh)
{
    const tp_tape *T = ws->t;
    const tp_oprec *rec = ws->rec;
    /* a local: the kernels' byte stores (anz) could alias T's fields */
    const uint32_t fa = T->first_active;
    const size_t P = (size_t)ws->P;
    const tp_kx kx = tp__kx(ws, tp__lanes(p), mask);
    double *adj = ws->adj, *atan = ws->atan;
    uint8_t *anz = ws->anz;
    uint32_t i;

    seed_outputs(ws, w);
    /* columns swept: p rounded up to TP_LANES; those past p are zero */
#if TP_ONE_VECTOR
    /* as tp__fwd1: rows of one vector, P too, or rows of one vector */
    if (kx.pr == TP_LANES && P == TP_LANES) {
        tp_kx k1 = kx;
        k1.pr = TP_LANES;
        k1.P = TP_LANES;
        for (i = end; i-- > fa;)
            tp__one_rev2(&k1, i, rec[i].op, rec[i].fl, rec[i].u, rec[i].t);
    } else if (kx.pr == TP_LANES) {
        tp_kx k1 = kx;
        k1.pr = TP_LANES;
        for (i = end; i-- > fa;)
            tp__one_rev2(&k1, i, rec[i].op, rec[i].fl, rec[i].u, rec[i].t);
    } else
#endif
        for (i = end; i-- > fa;)
            tp__k_rev2(&kx, i, rec[i].op, rec[i].fl, rec[i].u, rec[i].t);
    for (i = 0; i < T->n_indep; i++) {
        if (g)
            g[i] = adj[i];
        if (HS)
            memcpy(HS + i * ldh, atan + i * P, (size_t)p * sizeof(double));
        adj[i] = 0.0;
        anz[i] = 0;
    }
    memset(atan, 0, T->n_indep * P * sizeof(double));
    tp__clear_passive_seeds(ws);
}

/* The parts of tp__rev2_ranged that its sweeps in strips (strips.c)
 * share: seeding the outputs, and the end (g and HS out, the
 * independents' adjoints and rows zeroed, the passive seeds cleared). */
void tp__rev2_ranged_seed(tp_ws *ws, const double *w)
{
    seed_outputs(ws, w);
}

void tp__rev2_ranged_finish(tp_ws *ws, int n, double *g, double *HS)
{
    const tp_tape *T = ws->t;
    const size_t P = (size_t)ws->P;
    double *adj = ws->adj, *atan = ws->atan;
    uint8_t *anz = ws->anz;
    uint32_t i;

    for (i = 0; i < T->n_indep; i++) {
        if (g)
            g[i] = adj[i];
        if (HS)
            memcpy(HS + i * (size_t)n, atan + i * P,
                   (size_t)n * sizeof(double));
        adj[i] = 0.0;
        anz[i] = 0;
    }
    memset(atan, 0, T->n_indep * P * sizeof(double));
    tp__clear_passive_seeds(ws);
}

/* tp__rev2 after tp__fwd1_ranged, each op's kernels run over its range
 * alone (ranges.c): its own adjoint-tangent row and its operands' rows
 * are zero outside it. HS is n_indep x n (leading dimension n). */
TP_VECTOR_CLONES
void tp__rev2_ranged(tp_ws *ws, const double *w, int n, unsigned mask,
                     uint32_t end, double *g, double *HS)
{
    const tp_tape *T = ws->t;
    const tp_oprec *rec = ws->rec;
    /* a local: the kernels' byte stores (anz) could alias T's fields */
    const uint32_t fa = T->first_active;
    const uint32_t *rr = ws->rrange;
    tp_kx k = tp__kx(ws, 0, mask);
    double *atan = ws->atan, *tan = ws->tan;
    uint32_t i;

    tp__rev2_ranged_seed(ws, w);
    for (i = end; i-- > fa;) {
        const size_t off = TP_LANES * (size_t)rr[2 * i];
        k.tan = tan + off;
        k.atan = atan + off;
        k.pr = TP_LANES * (int)(rr[2 * i + 1] - rr[2 * i]);
        tp__k_rev2(&k, i, rec[i].op, rec[i].fl, rec[i].u, rec[i].t);
    }
    tp__rev2_ranged_finish(ws, n, g, HS);
}
