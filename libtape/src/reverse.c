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

#define UPASSIVE(fl) ((fl) & TP_DEP_UPASSIVE)
#define TPASSIVE(fl) ((fl) & TP_DEP_TPASSIVE)

static void seed_outputs(tp_ws *ws, const double *w)
{
    const tp_tape *T = ws->t;
    uint32_t o;
    for (o = 0; o < T->n_out; o++)
        if (w[o] != 0.0)
            ws->adj[T->out_slot[o]] += w[o];
}

/* Zero the adjoints seeded on outputs that no sweep visits (passive). */
static void clear_passive_seeds(tp_ws *ws)
{
    const tp_tape *T = ws->t;
    uint32_t o;
    for (o = 0; o < T->n_out; o++)
        if (T->out_slot[o] >= T->n_indep && T->out_slot[o] < T->first_active)
            ws->adj[T->out_slot[o]] = 0.0;
}

/* The arrays a reverse sweep reads, held in locals by the caller so that
 * the inlined per-op code keeps them in registers. */
typedef struct rev_view {
    const uint8_t *opc, *dep;
    const uint32_t *a0, *a1;
    const double *K, *v, *aux;
} rev_view;

static rev_view view_of(const tp_ws *ws)
{
    const tp_tape *T = ws->t;
    rev_view r = {T->opc, T->dep, T->a0, T->a1, T->konst, ws->v, ws->aux};
    return r;
}

/* The adjoint update of op i, whose adjoint a is non-zero. */
static TP_INLINE void rev1_op(const tp_tape *T, rev_view V, double *adj,
                              uint32_t i, double a)
{
    const unsigned fl = V.dep[i], op = V.opc[i];
    const uint32_t u = V.a0[i], t = V.a1[i];
    tp_partials d;
    switch (op) {
    case TP_OP_ADD:
        if (!UPASSIVE(fl))
            adj[u] += a;
        if (!TPASSIVE(fl))
            adj[t] += a;
        break;
    case TP_OP_SUB:
        if (!UPASSIVE(fl))
            adj[u] += a;
        if (!TPASSIVE(fl))
            adj[t] -= a;
        break;
    case TP_OP_MUL:
        if (!UPASSIVE(fl))
            adj[u] += a * V.v[t];
        if (!TPASSIVE(fl))
            adj[t] += a * V.v[u];
        break;
    case TP_OP_NEG: adj[u] -= a; break;
    case TP_OP_ADDC: adj[u] += a; break;
    case TP_OP_MULC: adj[u] += a * V.K[t]; break;
    case TP_OP_SQR: adj[u] += 2.0 * a * V.v[u]; break;
    case TP_OP_SIN: adj[u] += a * V.aux[i]; break;
    case TP_OP_COS: adj[u] -= a * V.aux[i]; break;
    default:
        tp__partials_at(T, V.v, V.aux, i, op, &d);
        if (!UPASSIVE(fl))
            adj[u] += d.fu * a;
        if (tp__opinfo[op].kind == TP_KIND_BINARY && !TPASSIVE(fl))
            adj[t] += d.ft * a;
        break;
    }
}

void tp__rev1(tp_ws *ws, const double *w, uint32_t end, double *g)
{
    const tp_tape *T = ws->t;
    const rev_view V = view_of(ws);
    double *adj = ws->adj;
    uint32_t i;

    seed_outputs(ws, w);
    for (i = end; i-- > T->first_active;) {
        const double a = adj[i];
        if (a == 0.0)
            continue;
        adj[i] = 0.0;
        rev1_op(T, V, adj, i, a);
    }
    for (i = 0; i < T->n_indep; i++) {
        if (g)
            g[i] = adj[i];
        adj[i] = 0.0;
    }
    clear_passive_seeds(ws);
}

/* Adjoint-tangent row kernels: ra is the row of the op being visited
 * (consumed and zeroed), ru and rt the rows of its operands (distinct rows
 * that precede ra), tu and tt their tangent rows. p is the padded column
 * count, a multiple of TP_LANES. */
static inline void adj_lin1(double *restrict ru, double *restrict ra,
                            double fu, int p)
{
    FOR_LANES(k, p) {
        ru[k] += fu * ra[k];
        ra[k] = 0.0;
    }
}

static inline void adj_acc1(double *restrict ru, double *restrict ra, int p)
{
    FOR_LANES(k, p) {
        ru[k] += ra[k];
        ra[k] = 0.0;
    }
}

static inline void adj_2nd1(double *restrict ru, double *restrict ra,
                            const double *restrict tu, double fu, double s,
                            int p)
{
    FOR_LANES(k, p) {
        ru[k] += fu * ra[k] + s * tu[k];
        ra[k] = 0.0;
    }
}

static inline void adj_add2(double *restrict ru, double *restrict rt,
                            double *restrict ra, int p)
{
    FOR_LANES(k, p) {
        ru[k] += ra[k];
        rt[k] += ra[k];
        ra[k] = 0.0;
    }
}

static inline void adj_lin2(double *restrict ru, double *restrict rt,
                            double *restrict ra, double fu, double ft, int p)
{
    FOR_LANES(k, p) {
        ru[k] += fu * ra[k];
        rt[k] += ft * ra[k];
        ra[k] = 0.0;
    }
}

static inline void adj_mul2(double *restrict ru, double *restrict rt,
                            double *restrict ra, const double *restrict tu,
                            const double *restrict tt, double fu, double ft,
                            double a, int p)
{
    FOR_LANES(k, p) {
        ru[k] += fu * ra[k] + a * tt[k];
        rt[k] += ft * ra[k] + a * tu[k];
        ra[k] = 0.0;
    }
}

static inline void adj_2nd2(double *restrict ru, double *restrict rt,
                            double *restrict ra, const double *restrict tu,
                            const double *restrict tt, const tp_partials *d,
                            double a, int p)
{
    const double fu = d->fu, ft = d->ft, suu = a * d->fuu, sut = a * d->fut,
                 stt = a * d->ftt;
    FOR_LANES(k, p) {
        const double r = ra[k], x = tu[k], y = tt[k];
        ru[k] += fu * r + suu * x + sut * y;
        rt[k] += ft * r + sut * x + stt * y;
        ra[k] = 0.0;
    }
}

/* One active operand with partials f, ff (its first and second): the
 * update of that operand's adjoint and row. */
static inline void rev2_one(double *adj_u, double *ru, double *ra,
                            const double *tu, double f, double ff, double a,
                            bool second, int p)
{
    *adj_u += f * a;
    if (second && ff != 0.0)
        adj_2nd1(ru, ra, tu, f, a * ff, p);
    else
        adj_lin1(ru, ra, f, p);
}

/* The generic path of forward-over-reverse for op i with adjoint a. */
TP_VECTOR_CLONES
static void rev2_generic(tp_ws *ws, uint32_t i, double a, bool second, int p)
{
    const tp_tape *T = ws->t;
    const size_t P = (size_t)ws->P;
    const unsigned op = T->opc[i], fl = T->dep[i];
    const uint32_t u = T->a0[i], t = T->a1[i];
    const double *tan = ws->tan;
    double *atan = ws->atan, *adj = ws->adj;
    double *ra = atan + i * P;
    tp_partials d;
    tp__partials_at(T, ws->v, ws->aux, i, op, &d);
    second = second && !(tp__opinfo[op].flags & TP_FLAG_LIN);
    if (tp__opinfo[op].kind != TP_KIND_BINARY) {
        rev2_one(adj + u, atan + u * P, ra, tan + u * P, d.fu, d.fuu, a,
                 second, p);
    } else if (TPASSIVE(fl)) {
        rev2_one(adj + u, atan + u * P, ra, tan + u * P, d.fu, d.fuu, a,
                 second, p);
    } else if (UPASSIVE(fl)) {
        rev2_one(adj + t, atan + t * P, ra, tan + t * P, d.ft, d.ftt, a,
                 second, p);
    } else if (u == t) { /* both operands one slot: combine the partials */
        rev2_one(adj + u, atan + u * P, ra, tan + u * P, d.fu + d.ft,
                 d.fuu + 2.0 * d.fut + d.ftt, a, second, p);
    } else {
        adj[u] += d.fu * a;
        adj[t] += d.ft * a;
        if (second)
            adj_2nd2(atan + u * P, atan + t * P, ra, tan + u * P,
                     tan + t * P, &d, a, p);
        else
            adj_lin2(atan + u * P, atan + t * P, ra, d.fu, d.ft, p);
    }
}

TP_VECTOR_CLONES
void tp__rev2(tp_ws *ws, const double *w, int p, unsigned mask, uint32_t end,
              double *g, double *HS, size_t ldh)
{
    const tp_tape *T = ws->t;
    const uint8_t *opc = T->opc, *dep = T->dep;
    const uint32_t *a0 = T->a0, *a1 = T->a1;
    const double *K = T->konst;
    const size_t P = (size_t)ws->P;
    const double *v = ws->v, *aux = ws->aux, *tan = ws->tan;
    double *adj = ws->adj, *atan = ws->atan;
    uint8_t *anz = ws->anz;
    const rev_view V = view_of(ws);
    const int pc = p; /* columns the caller asked for */
    uint32_t i;

    p = tp__lanes(p); /* columns swept; those past pc are zero */
    seed_outputs(ws, w);
    /* One switch per op; the common ops have their partials inline. */
    for (i = end; i-- > T->first_active;) {
        const double a = adj[i];
        const unsigned fl = dep[i];
        const uint32_t u = a0[i];
        /* the second-order term needs a non-zero adjoint and tangent */
        const bool second = a != 0.0 && (fl & mask);
        double *ra = atan + i * P, *ru = atan + u * P;
        adj[i] = 0.0;
        if (!anz[i] && !second) {
            if (a != 0.0)
                rev1_op(T, V, adj, i, a);
            continue;
        }
        anz[i] = 0;
        anz[u] = 1;
        if (tp__opinfo[opc[i]].kind == TP_KIND_BINARY)
            anz[a1[i]] = 1; /* a passive operand's flag is never read */
        switch (opc[i]) {
        case TP_OP_ADD: {
            const uint32_t t = a1[i];
            if (TPASSIVE(fl)) {
                adj[u] += a;
                adj_acc1(ru, ra, p);
            } else if (UPASSIVE(fl)) {
                adj[t] += a;
                adj_acc1(atan + t * P, ra, p);
            } else {
                adj[u] += a;
                adj[t] += a;
                adj_add2(ru, atan + t * P, ra, p);
            }
            break;
        }
        case TP_OP_SUB: {
            const uint32_t t = a1[i];
            if (TPASSIVE(fl)) {
                adj[u] += a;
                adj_acc1(ru, ra, p);
            } else if (UPASSIVE(fl)) {
                adj[t] -= a;
                adj_lin1(atan + t * P, ra, -1.0, p);
            } else {
                adj[u] += a;
                adj[t] -= a;
                adj_lin2(ru, atan + t * P, ra, 1.0, -1.0, p);
            }
            break;
        }
        case TP_OP_MUL: {
            const uint32_t t = a1[i];
            if (TPASSIVE(fl)) { /* fuu = 0 and t has no tangent */
                adj[u] += a * v[t];
                adj_lin1(ru, ra, v[t], p);
            } else if (UPASSIVE(fl)) {
                adj[t] += a * v[u];
                adj_lin1(atan + t * P, ra, v[u], p);
            } else {
                adj[u] += a * v[t];
                adj[t] += a * v[u];
                if (second)
                    adj_mul2(ru, atan + t * P, ra, tan + u * P, tan + t * P,
                             v[t], v[u], a, p);
                else
                    adj_lin2(ru, atan + t * P, ra, v[t], v[u], p);
            }
            break;
        }
        case TP_OP_NEG:
        case TP_OP_CSUB:
            adj[u] -= a;
            adj_lin1(ru, ra, -1.0, p);
            break;
        case TP_OP_ADDC:
            adj[u] += a;
            adj_acc1(ru, ra, p);
            break;
        case TP_OP_MULC: {
            const double c = K[a1[i]];
            adj[u] += a * c;
            adj_lin1(ru, ra, c, p);
            break;
        }
        case TP_OP_SQR:
            rev2_one(adj + u, ru, ra, tan + u * P, 2.0 * v[u], 2.0, a,
                     second, p);
            break;
        case TP_OP_SIN: /* fu = cos u, fuu = -w */
            rev2_one(adj + u, ru, ra, tan + u * P, aux[i], -v[i], a, second,
                     p);
            break;
        case TP_OP_COS: /* fu = -sin u, fuu = -w */
            rev2_one(adj + u, ru, ra, tan + u * P, -aux[i], -v[i], a, second,
                     p);
            break;
        default:
            rev2_generic(ws, i, a, second, p);
            break;
        }
    }
    for (i = 0; i < T->n_indep; i++) {
        if (g)
            g[i] = adj[i];
        if (HS)
            memcpy(HS + i * ldh, atan + i * P, (size_t)pc * sizeof(double));
        adj[i] = 0.0;
        anz[i] = 0;
    }
    memset(atan, 0, T->n_indep * P * sizeof(double));
    clear_passive_seeds(ws);
}
