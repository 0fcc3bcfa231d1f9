/* mass_route.h - how the right-hand side forms and factors the mass
 * matrix (mass_pattern.c: what the L tape says about M; mass_route.c:
 * the route chosen and the evaluation along it). Private to libeom. */
#ifndef EOM_MASS_ROUTE_H
#define EOM_MASS_ROUTE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "eom/eom.h"
#include "eom_internal.h"

/* What the L tape says about M, found once per system. */
typedef struct eom_mass {
    bool analysed;     /* the analysis has run (ok or not) */
    bool ok;           /* it succeeded: the fields below are valid */
    bool constant;     /* M depends on none of q, qd, t (structurally) */
    int requested;     /* eom_system_set_mass_route: 0 (auto) or a route */
    size_t nnz;        /* entries of M's pattern, both triangles */
    int64_t *colptr;   /* [n + 1] M's pattern in compressed columns */
    int64_t *rowind;   /* [nnz] rows, ascending in each column */
    /* the constant route's factor: s->Mf holds the factor of the
     * constant M for the parameters of generation gen when held is
     * true and s->mf_valid */
    bool held;
    unsigned long gen;
    double *work;      /* [3 ni] the direction, H d and the gradient
                          (ni: the L tape's independents) */
    double *w, *y;     /* [the L tape's outputs] weights (1 on L), values */
    tp_ws *ws;         /* the L tape's workspace of one direction for the
                          constant route's sweep (the system's is n wide:
                          a sweep clears tangents of that width) */
    unsigned long wgen; /* s->param_gen its parameters were set at */
    bool wset;
} eom_mass;

/* The analysis of s's L tape (run on the first call), or NULL when out of
 * memory for the record itself; ok false when it could not be done. */
eom_mass *eom__mass_info(eom_system *s);
void eom__mass_free(eom_mass **p);

/* The route of s's mass matrix in eom__evaluate (EOM_MASS_DENSE or
 * EOM_MASS_CONSTANT), analysing the L tape on the first call; eom_rhs's
 * may be EOM_MASS_SPARSE (eom_system_mass_route). Every evaluation asks
 * for it, twice: after the first call it is the answer kept in s
 * (eom__mass_route_find keeps it; it depends only on the analysis, made
 * once, on the route requested, whose setter forgets it, and on whether
 * s runs compiled tapes, part of the key). */
int eom__mass_route_find(eom_system *s);
static inline int eom__mass_route(eom_system *s)
{
    if (s->route_key == 1 + (int)s->compiled)
        return s->route;
    return eom__mass_route_find(s);
}

/* The dense route's Lagrange block at (t, x): L (checked), g, dL/dt, M
 * and h from one tp_lagrange_t (eom__lagrange_block on that route;
 * inline, so that an evaluation makes the call directly). */
static inline int eom__block_dense(eom_system *s, double t, const double *x)
{
    double L;
    const int st = tp_lagrange_t(s->tL.ws, eom__tape_input(&s->tL, x, t), 0,
                                 &L, s->g, &s->dLdt, s->M, s->h);
    return st == TP_OK ? EOM_OK
                       : eom__tape_status(s, st,
                                          "the Lagrangian or a derivative");
}

/* rhs.c's Lagrange block along the route at (t, x): g = dL/dq, h and
 * dL/dt into s (as tp_lagrange_t gives them; L itself is checked), and
 * on the dense route M into s->M. On the constant route the sweep
 * carries one direction instead of n and M is not formed. */
int eom__lagrange_block(eom_system *s, double t, const double *x);
/* Then M's factor in s->Mf (eom__factor_mass's statuses and messages):
 * on the constant route formed and factored only when not held for the
 * current parameters. */
int eom__mass_factor(eom_system *s, double t, const double *x);

/* rhs.c: the unconstrained part of an evaluation at (t, x): state
 * checked, the Lagrange block, forces, F into s->F and s->qdd, power,
 * and with factor M factored (eom__evaluate is this, then the
 * range-space solve; the sparse route needs no factor of M alone). */
int eom__evaluate_free(eom_system *s, double t, const double *x,
                       int factor);

/* kkt_sparse.c: the augmented sparse solve of eom_rhs and
 * eom_multipliers. */
typedef struct eom_kkt eom_kkt;
void eom__kkt_free(eom_kkt **p);
/* 1 when s's eom_rhs takes the augmented sparse solve (analysing the
 * constraints' pattern on the first call), else 0; _possible: when s's
 * model allows it at all (what EOM_MASS_SPARSE asks for). */
int eom__kkt_applies(eom_system *s);
int eom__kkt_possible(eom_system *s);
/* eom_rhs's evaluation: the augmented sparse solve when it applies and
 * is well conditioned here, else eom__evaluate. Leaves qdd, lam, F,
 * power in s (C, Y, S only from eom__evaluate). */
int eom__evaluate_rhs(eom_system *s, double t, const double *x);
/* The evaluations eom__evaluate_rhs solved sparsely, and those it handed
 * to the dense route (a poorly conditioned augmented matrix). */
void eom__kkt_counts(const eom_system *s, long *solves, long *fallbacks);

#endif /* EOM_MASS_ROUTE_H */
