/* kkt_sparse.h - the augmented sparse system [M C^T; C 0] of models
 * with a constant mass matrix (kkt_sparse.c), shared with the
 * integrators' sparse path (kkt_integ.c). Private to libeom. */
#ifndef EOM_KKT_SPARSE_H
#define EOM_KKT_SPARSE_H

#include <stdbool.h>
#include <stddef.h>

#include "eom_internal.h"
#include "mass_route.h"

/* KLU's reciprocal pivot ratio of the augmented matrix below which an
 * evaluation goes to the dense route (its filtered solve near a
 * singular position). */
#define EOM_KKT_RCOND 1e-10
/* The sparse path's measure (eom__kkt_sigma) below which an integrator
 * evaluates, projects and watches the rank along the dense route.
 * Measured on the A02 four-bars (N = 40 and 400 alike): the measure is
 * 0.31 th^2 near the flat position at crank angle th, S's pivot ratio
 * 0.49 th^2 (the dense route's filter starts below 1e-3, at th = 0.045),
 * and the branch monitor's rank drops below 1.5e-3 (th = 0.07); 1e-2
 * (th = 0.18) leaves room for steps of 0.1 rad. */
#define EOM_KKT_SIGMA_NEAR 1e-2

struct eom_kkt {
    bool analysed, ok;
    int n, m, p;         /* coordinates, rows, colours of C's columns */
    int *color;          /* [n] each column's colour */
    double *seed;        /* [n p] the directions, row-major */
    double *JS;          /* [m p] C times them */
    int N;               /* n + m */
    int *Kp, *Ki;        /* the augmented matrix, compressed columns */
    double *Kx;
    long *src;           /* [nnz] >= 0: entry of mvals; < 0: -1 - entry
                            of JS */
    double *b;           /* [N] right side, then solution */
    int pm;              /* colours of M's columns */
    int *mcolor;         /* [n] each column's colour */
    double *mseed;       /* [ni pm] directions on the rates, row-major */
    double *mhs;         /* [ni pm] H times them */
    double *mg;          /* [ni] gradient (not used) */
    double *mvals;       /* [M's nnz] the constant M's entries */
    bool mheld;          /* mvals is M for parameters of generation mgen */
    unsigned long mgen;
    /* workspaces of the L and phi tapes of their own, as wide as the
     * colours: the system's are n wide, and a sweep clears (and strides
     * through) tangents of that width, which would cost O(n) per op */
    tp_ws *wsL, *wsphi;
    unsigned long wgen;  /* s->param_gen their parameters were set at */
    bool wset;
    long solves;         /* evaluations solved here */
    long fallbacks;      /* evaluations handed to the dense route */
    /* kkt_integ.c: the singularity measure's G = C D^-1 C^T (D the
     * diagonal of M), m x m, its pattern and KLU factor */
    bool gok;            /* G's pattern made (gp non-NULL) */
    int *gp, *gi;        /* G in compressed columns */
    double *gx;
    int *gtrip;          /* [4 ntrip] the entry of gx, and the entries
                            C_aj, C_bj, M_jj of Kx, of each term
                            C_aj C_bj / M_jj */
    size_t ntrip;
    klu_common gc;
    klu_symbolic *gsym;
    klu_numeric *gnum;
    klu_common kc;
    klu_symbolic *sym;
    klu_numeric *num;
};

/* The augmented matrix at the positions of x (C and phi, into s->phi,
 * from one forward sweep; M's entries once per set of parameters) and
 * its KLU factor. *poor set to 1 when the factor failed or its pivot
 * ratio is below EOM_KKT_RCOND (nothing should be solved with it).
 * eom__kkt_applies(s) must have returned 1. */
int eom__kkt_factor_at(eom_system *s, double t, const double *x, int *poor);
/* b (n + m) := K^-1 b with the last factor. */
int eom__kkt_solve(eom_system *s, double *b);
/* out (m) = C v (v: n), C from the last eom__kkt_factor_at. */
void eom__kkt_C_times(const eom_system *s, const double *v, double *out);

/* kkt_integ.c. The pivot ratio of G = C D^-1 C^T (D: M's diagonal) with
 * C from the last eom__kkt_factor_at: near a singular position it falls
 * as S's does; -1 when it cannot be had (M's pattern without its
 * diagonal), 0 when G's factor failed. */
double eom__kkt_sigma(eom_system *s);
/* norm (m): the length of each row of C, from the last factor. */
void eom__kkt_row_norms(const eom_system *s, double *norm);
/* Project x = (q, qd) onto phi = 0 (Newton to |phi| <= tol) and C qd =
 * 0 in the M-norm, with the augmented matrix; *dense set to 1 (x maybe
 * partly corrected, still on the way) when a factor was poor: then the
 * dense projection should take over. */
int eom__kkt_project(eom_system *s, double t, double *x, double tol,
                     int *iters, int *dense);
/* G's arrays (eom__kkt_free calls it). */
void eom__kkt_integ_free(eom_kkt *k);

#endif /* EOM_KKT_SPARSE_H */
