/* jacobian_sparse.c - IDA's iteration matrix dG/dY + cj dG/dY' as a
 * sparse (compressed-column) matrix, for SUNLinSol_KLU, and the rule
 * that chooses between it and the dense matrix (eom_opts.linear_solver).
 *
 * The pattern comes from the residual tape's structure, never from the
 * values at one state: tp_tape_jacobian_pattern gives the pattern of the
 * residual tape's Jacobian over z = (q, qd, qdd, lambda) (a superset of
 * every entry nonzero at any state), and the index-1 residual of
 * integrate_ida.c maps it onto the (2n + m + 1)-square matrix exactly as
 * eom__dae_jacobian (residual.c) maps the dense one:
 *
 *   rows q' - v     (i, i) = cj, (i, n + i) = -1
 *   rows E          dE/dq | dE/dqd + cj dE/dqdd | dE/dlambda
 *   rows K          (K = phi2 + 2 alpha phi1 + beta^2 phi0)
 *                   dK/dq | dK/dqd + cj dphi2/dqdd | 0
 *   row  W' + P     dP/dq | dP/dqd | dP/dlambda, and cj on the diagonal
 *
 * Values: the same forward Jacobian sweep of the residual tape as the
 * dense path, with its columns compressed: columns of z that share no
 * row of the pattern get one direction between them (a greedy colouring,
 * Curtis-Powell-Reid), so the sweep carries as many directions as there
 * are colours (a handful for a line of masses) instead of 3n + m, and
 * each entry is read back from its column's colour exactly: no other
 * column of that colour reaches its row. A few rows much denser than the
 * rest (the power P with dissipation over every rate, a constraint over
 * many coordinates) would force colours on all their columns; they are
 * left out of the colouring and come from one reverse sweep each
 * (tp_gradient; dense_row_bound says which). The entries are summed in the dense path's order, so
 * the two matrices agree to the rounding of those reverse rows (bit for
 * bit elsewhere).
 *
 * The structure is made once per system, on first use, and kept with its
 * own workspace of the residual tape (the dense path's is apart).
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"

/* How a contribution enters its entry: data[tgt] += coef * value. */
enum { C_ONE, C_A2, C_B2, C_CJ, K_CJ, K_MINUS1 };

struct eom_jsparse {
    int NY;           /* 2n + m + 1 */
    int nc;           /* 3n + m: the columns of z in the pattern */
    int nr;           /* n + 3m + 1: the residual tape's outputs */
    int nz;           /* the residual tape's independents */
    size_t *rp;       /* [nr + 1] the residual pattern, rows */
    int *rc;          /* [rp[nr]] its columns */
    int ncolors;
    int *color;       /* [nc] the colour of each column */
    unsigned char *rev; /* [nr] 1: the row comes from a reverse sweep */
    double *seed;     /* [nz x ncolors] the compressed directions */
    double *JS;       /* [nr x ncolors] the compressed Jacobian */
    double *g;        /* [nz] a reverse row */
    double *y;        /* [nr] the outputs */
    double *zv;       /* [nz] the point */
    double *val;      /* [rp[nr]] the residual entries */
    tp_ws *ws;        /* a workspace of the residual tape, this file's */
    size_t nnz;       /* entries of the iteration matrix */
    int64_t *colptr;  /* [NY + 1] */
    int64_t *rowind;  /* [nnz] */
    size_t ncon;      /* contributions, in the order they are summed */
    size_t *ctgt;     /* [ncon] the entry each adds to */
    size_t *csrc;     /* [ncon] the residual entry it reads (constants:
                         unused) */
    unsigned char *ckind; /* [ncon] C_* or K_* */
};

void eom__jsparse_free(eom_jsparse **p)
{
    eom_jsparse *j = p ? *p : NULL;
    if (!j)
        return;
    tp_ws_free(&j->ws);
    free(j->rp);
    free(j->rc);
    free(j->color);
    free(j->rev);
    free(j->seed);
    free(j->JS);
    free(j->g);
    free(j->y);
    free(j->zv);
    free(j->val);
    free(j->colptr);
    free(j->rowind);
    free(j->ctgt);
    free(j->csrc);
    free(j->ckind);
    free(j);
    *p = NULL;
}

/* Rows of more entries than the bound returned come from a reverse
 * sweep each: a row of d entries needs at least d colours, and a reverse
 * sweep (values forward, adjoints back) costs about as much as
 * REVERSE_COST directions of the forward sweep. The bound minimizes
 * bound + REVERSE_COST x (rows above it), the colouring's lower bound
 * plus the reverse sweeps: the damped power P, which reads every rate,
 * goes reverse; rows of a banded pattern, however wide, stay coloured.
 * Returns -1 out of memory. */
#define REVERSE_COST 3
static int dense_row_bound(const eom_jsparse *j)
{
    size_t *hist = calloc((size_t)j->nc + 2, sizeof *hist);
    size_t above = 0, best_cost = (size_t)-1;
    int r, d, best = j->nc;
    if (!hist)
        return -1;
    for (r = 0; r < j->nr; r++)
        hist[j->rp[r + 1] - j->rp[r]]++;
    /* bound d: rows of more than d entries go reverse */
    for (d = j->nc; d >= 0; d--) {
        const size_t cost = (size_t)d + REVERSE_COST * above;
        if (cost <= best_cost) {
            best_cost = cost;
            best = d;
        }
        above += hist[d];
    }
    free(hist);
    return best;
}

/* Greedy colouring of the columns of the rows not in rev: two columns
 * that share such a row get different colours. Returns 0, or -1 out of
 * memory. */
static int colour(eom_jsparse *j)
{
    size_t *cp = NULL, *cr = NULL, e;
    int *mark = NULL, c, k, r, best = 0, rc = -1;
    /* the rows of each column (the pattern transposed) */
    cp = calloc((size_t)j->nc + 1, sizeof *cp);
    cr = malloc((j->rp[j->nr] ? j->rp[j->nr] : 1) * sizeof *cr);
    mark = malloc(((size_t)j->nc + 1) * sizeof *mark);
    j->color = malloc(((size_t)j->nc ? (size_t)j->nc : 1) *
                      sizeof *j->color);
    if (!cp || !cr || !mark || !j->color)
        goto out;
    for (r = 0; r < j->nr; r++)
        for (e = j->rp[r]; !j->rev[r] && e < j->rp[r + 1]; e++)
            cp[j->rc[e] + 1]++;
    for (c = 0; c < j->nc; c++)
        cp[c + 1] += cp[c];
    {
        size_t *next = malloc(((size_t)j->nc + 1) * sizeof *next);
        if (!next)
            goto out;
        memcpy(next, cp, ((size_t)j->nc + 1) * sizeof *next);
        for (r = 0; r < j->nr; r++)
            for (e = j->rp[r]; !j->rev[r] && e < j->rp[r + 1]; e++)
                cr[next[j->rc[e]]++] = (size_t)r;
        free(next);
    }
    for (c = 0; c <= j->nc; c++)
        mark[c] = -1;
    for (c = 0; c < j->nc; c++) {
        for (e = cp[c]; e < cp[c + 1]; e++) {
            const size_t row = cr[e];
            size_t f;
            for (f = j->rp[row]; f < j->rp[row + 1]; f++)
                if (j->rc[f] < c)
                    mark[j->color[j->rc[f]]] = c;
        }
        for (k = 0; mark[k] == c; k++)
            ;
        j->color[c] = k;
        if (k + 1 > best)
            best = k + 1;
    }
    j->ncolors = best;
    rc = 0;
out:
    free(cp);
    free(cr);
    free(mark);
    return rc;
}

static int cmp_i64(const void *a, const void *b)
{
    const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* One contribution: entry (R, C) of the matrix, from residual entry src
 * (or a constant) with coefficient kind. Counted in a first pass (list
 * NULL). */
typedef struct clist {
    size_t n;
    int *R, *C;
    size_t *src;
    unsigned char *kind;
} clist;

static void add(clist *l, int R, int C, size_t src, int kind)
{
    if (l->R) {
        l->R[l->n] = R;
        l->C[l->n] = C;
        l->src[l->n] = src;
        l->kind[l->n] = (unsigned char)kind;
    }
    l->n++;
}

/* The contributions in the dense path's order of summation. */
static void contributions(const eom_jsparse *j, int n, int m, clist *l)
{
    size_t e;
    int i, k;
    for (i = 0; i < n; i++) { /* q' - v */
        add(l, i, i, 0, K_CJ);
        add(l, i, n + i, 0, K_MINUS1);
    }
    for (i = 0; i < n; i++) /* E: qd then qdd, ascending, as dense */
        for (e = j->rp[i]; e < j->rp[i + 1]; e++) {
            const int c = j->rc[e];
            if (c < 2 * n)
                add(l, n + i, c, e, C_ONE);
            else if (c < 3 * n)
                add(l, n + i, c - n, e, C_CJ);
            else
                add(l, n + i, c - n, e, C_ONE); /* lambda */
        }
    for (k = 0; k < m; k++) {
        const int r2 = n + k, r1 = n + m + k, r0 = n + 2 * m + k;
        for (e = j->rp[r2]; e < j->rp[r2 + 1]; e++)
            if (j->rc[e] < 2 * n)
                add(l, 2 * n + k, j->rc[e], e, C_ONE);
        for (e = j->rp[r1]; e < j->rp[r1 + 1]; e++)
            if (j->rc[e] < 2 * n)
                add(l, 2 * n + k, j->rc[e], e, C_A2);
        for (e = j->rp[r0]; e < j->rp[r0 + 1]; e++)
            if (j->rc[e] < 2 * n)
                add(l, 2 * n + k, j->rc[e], e, C_B2);
        for (e = j->rp[r2]; e < j->rp[r2 + 1]; e++)
            if (j->rc[e] >= 2 * n && j->rc[e] < 3 * n)
                add(l, 2 * n + k, j->rc[e] - n, e, C_CJ);
    }
    i = n + 3 * m; /* W' + P */
    for (e = j->rp[i]; e < j->rp[i + 1]; e++) {
        const int c = j->rc[e];
        if (c < 2 * n)
            add(l, 2 * n + m, c, e, C_ONE);
        else if (c >= 3 * n)
            add(l, 2 * n + m, c - n, e, C_ONE);
    }
    add(l, 2 * n + m, 2 * n + m, 0, K_CJ);
}

/* The matrix's pattern (CSC, rows sorted, no duplicates) from the
 * contributions, and each contribution's entry. */
static int assemble(eom_jsparse *j, const clist *l)
{
    const int NY = j->NY;
    int64_t *cnt = calloc((size_t)NY + 1, sizeof *cnt);
    int64_t *rows = malloc((l->n ? l->n : 1) * sizeof *rows);
    size_t e, w;
    int c, rc = -1;
    j->colptr = malloc(((size_t)NY + 1) * sizeof *j->colptr);
    j->ctgt = malloc((l->n ? l->n : 1) * sizeof *j->ctgt);
    if (!cnt || !rows || !j->colptr || !j->ctgt)
        goto out;
    for (e = 0; e < l->n; e++)
        cnt[l->C[e] + 1]++;
    for (c = 0; c < NY; c++)
        cnt[c + 1] += cnt[c];
    memcpy(j->colptr, cnt, ((size_t)NY + 1) * sizeof *cnt);
    for (e = 0; e < l->n; e++)
        rows[cnt[l->C[e]]++] = l->R[e];
    /* sort and compact each column in place */
    w = 0;
    for (c = 0; c < NY; c++) {
        const size_t a = (size_t)j->colptr[c], b = (size_t)j->colptr[c + 1];
        size_t f;
        qsort(rows + a, b - a, sizeof *rows, cmp_i64);
        j->colptr[c] = (int64_t)w;
        for (f = a; f < b; f++)
            if (f == a || rows[f] != rows[f - 1])
                rows[w++] = rows[f];
    }
    j->colptr[NY] = (int64_t)w;
    j->nnz = w;
    j->rowind = malloc((w ? w : 1) * sizeof *j->rowind);
    if (!j->rowind)
        goto out;
    memcpy(j->rowind, rows, w * sizeof *rows);
    for (e = 0; e < l->n; e++) {
        const int64_t *lo = j->rowind + j->colptr[l->C[e]];
        const int64_t key = l->R[e];
        const int64_t *hit = bsearch(&key, lo,
                                     (size_t)(j->colptr[l->C[e] + 1] -
                                              j->colptr[l->C[e]]),
                                     sizeof *lo, cmp_i64);
        j->ctgt[e] = (size_t)(hit - j->rowind);
    }
    rc = 0;
out:
    free(cnt);
    free(rows);
    return rc;
}

/* Build j for s; EOM_OK or a status with a message in s. */
static int build(eom_system *s, eom_jsparse *j)
{
    const int n = s->n, m = s->m;
    const tp_tape *T = s->tRes.tape;
    clist l;
    size_t nres;
    int r, k, st, bound, dirs;
    memset(&l, 0, sizeof l);
    j->NY = 2 * n + m + 1;
    j->nc = 3 * n + m;
    j->nr = n + 3 * m + 1;
    j->nz = tp_tape_n_indep(T);
    if (tp_tape_n_outputs(T) != j->nr || j->nz < j->nc)
        return eom__fail(s, EOM_ERR_MODEL, "the sparse Jacobian: the "
                         "residual tape has %d outputs and %d "
                         "independents, not %d and at least %d",
                         tp_tape_n_outputs(T), j->nz, j->nr, j->nc);
    j->rp = malloc(((size_t)j->nr + 1) * sizeof *j->rp);
    if (!j->rp)
        goto nomem;
    st = tp_tape_jacobian_pattern(T, 0, j->nc, j->rp, NULL, 0);
    nres = j->rp[j->nr];
    if (st == TP_OK) {
        j->rc = malloc((nres ? nres : 1) * sizeof *j->rc);
        if (!j->rc)
            goto nomem;
        st = tp_tape_jacobian_pattern(T, 0, j->nc, j->rp, j->rc, nres);
    }
    if (st != TP_OK)
        return eom__tape_status(s, st, "the sparse Jacobian's pattern");
    j->rev = calloc((size_t)j->nr, 1);
    if (!j->rev)
        goto nomem;
    if ((bound = dense_row_bound(j)) < 0)
        goto nomem;
    for (r = 0; r < j->nr; r++)
        j->rev[r] = j->rp[r + 1] - j->rp[r] > (size_t)bound;
    if (colour(j) != 0)
        goto nomem;
    dirs = j->ncolors ? j->ncolors : 1;
    j->seed = calloc((size_t)j->nz * (size_t)dirs, sizeof *j->seed);
    j->JS = malloc((size_t)j->nr * (size_t)dirs * sizeof *j->JS);
    j->g = malloc((size_t)j->nz * sizeof *j->g);
    j->y = malloc((size_t)j->nr * sizeof *j->y);
    j->zv = malloc((size_t)j->nz * sizeof *j->zv);
    j->val = malloc((nres ? nres : 1) * sizeof *j->val);
    if (!j->seed || !j->JS || !j->g || !j->y || !j->zv || !j->val)
        goto nomem;
    for (k = 0; k < j->nc; k++)
        j->seed[(size_t)k * dirs + j->color[k]] = 1.0;
    if ((st = tp_ws_new(&j->ws, T, dirs, NULL)) != TP_OK)
        return eom__tape_status(s, st, "the sparse Jacobian's workspace");
    contributions(j, n, m, &l); /* count */
    l.R = malloc((l.n ? l.n : 1) * sizeof *l.R);
    l.C = malloc((l.n ? l.n : 1) * sizeof *l.C);
    l.src = malloc((l.n ? l.n : 1) * sizeof *l.src);
    l.kind = malloc((l.n ? l.n : 1) * sizeof *l.kind);
    if (l.R && l.C && l.src && l.kind) {
        l.n = 0;
        contributions(j, n, m, &l);
        if (assemble(j, &l) == 0) {
            j->ncon = l.n;
            j->csrc = l.src;
            j->ckind = l.kind;
            free(l.R);
            free(l.C);
            return EOM_OK;
        }
    }
    free(l.R);
    free(l.C);
    free(l.src);
    free(l.kind);
nomem:
    return eom__fail(s, EOM_ERR_NOMEM,
                     "out of memory for the sparse Jacobian's pattern");
}

static int ready(eom_system *s)
{
    int rc;
    if (s->jsp)
        return EOM_OK;
    if (s->mv > 0) /* ida's matrix: ida does not take them */
        return eom__refuse_velocity(s, "ida's sparse iteration matrix");
    if (!s->tRes.tape)
        return eom__fail(s, EOM_ERR_MODEL,
                         "the system has no residual tape");
    if (!(s->jsp = calloc(1, sizeof *s->jsp)))
        return eom__fail(s, EOM_ERR_NOMEM,
                         "out of memory for the sparse Jacobian");
    if ((rc = build(s, s->jsp)) != EOM_OK)
        eom__jsparse_free(&s->jsp); /* the next call tries again */
    return rc;
}

int eom__dae_pattern(eom_system *s, eom_dae_pattern *p)
{
    int rc = ready(s);
    if (rc != EOM_OK)
        return rc;
    p->NY = s->jsp->NY;
    p->nnz = s->jsp->nnz;
    p->colptr = s->jsp->colptr;
    p->rowind = s->jsp->rowind;
    p->colors = s->jsp->ncolors;
    for (p->reverse_rows = 0, rc = 0; rc < s->jsp->nr; rc++)
        p->reverse_rows += s->jsp->rev[rc];
    return EOM_OK;
}

int eom__dae_jacobian_sparse(eom_system *s, double t, const double *Y,
                             const double *Yp, double cj, double *data)
{
    const int n = s->n, m = s->m;
    const double a2 = 2.0 * s->alpha, b2 = s->beta * s->beta;
    eom_jsparse *j;
    size_t e;
    int r, rc, st;
    if ((rc = ready(s)) != EOM_OK)
        return rc;
    j = s->jsp;
    if (!isfinite(t) || !isfinite(cj) || !eom__finite(Y, 2 * (size_t)n) ||
        !eom__finite(Yp + n, (size_t)n) ||
        !eom__finite(Y + 2 * n, (size_t)m))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "the sparse Jacobian: the state at t = %g is not "
                         "finite", t);
    eom__residual_fill_z(s, t, Y, Yp + n, Y + 2 * n, j->zv);
    /* the coloured rows: one forward sweep over the colours */
    if (j->ncolors > 0) {
        st = tp_jvp(j->ws, j->zv, j->ncolors, j->seed, j->y, j->JS);
        if ((rc = eom__tape_status(s, st, "the sparse Jacobian of the "
                                          "equations")) != EOM_OK)
            return rc;
    }
    for (r = 0; r < j->nr; r++) {
        if (j->rev[r]) { /* a dense row: one reverse sweep */
            st = tp_gradient(j->ws, j->zv, r, NULL, j->g);
            if ((rc = eom__tape_status(s, st, "the sparse Jacobian of the "
                                              "equations")) != EOM_OK)
                return rc;
            for (e = j->rp[r]; e < j->rp[r + 1]; e++)
                j->val[e] = j->g[j->rc[e]];
        } else {
            const double *row = j->JS + (size_t)r * (size_t)j->ncolors;
            for (e = j->rp[r]; e < j->rp[r + 1]; e++)
                j->val[e] = row[j->color[j->rc[e]]];
        }
    }
    memset(data, 0, j->nnz * sizeof *data);
    for (e = 0; e < j->ncon; e++) {
        const double v = j->ckind[e] < K_CJ ? j->val[j->csrc[e]] : 0.0;
        double *d = data + j->ctgt[e];
        switch (j->ckind[e]) {
        case C_ONE: *d += v; break;
        case C_A2: *d += a2 * v; break;
        case C_B2: *d += b2 * v; break;
        case C_CJ: *d += cj * v; break;
        case K_CJ: *d += cj; break;
        default: *d += -1.0; break; /* K_MINUS1 */
        }
    }
    return EOM_OK;
}

/* The automatic choice (docs/integrators.md, "Sparse iteration
 * matrices"; measured by bench-sparse, docs/benchmarks.md section 11):
 * below SPARSE_MIN_NY unknowns dense LU, and the pattern is not even
 * computed (the shipped models, 5 to 23 unknowns, ran as fast either
 * way; the line of masses gained 1.2 times at 45); above, sparse when at
 * most SPARSE_MAX_FILL of the entries can be nonzero (at 405 unknowns
 * sparse gained 1.4 times at 6.5 % of the entries, 1.0 to 1.17 at 8.1 %,
 * 1.03 to 1.09 at 11.2 %: the bound sits where the two are even). */
#define SPARSE_MIN_NY 40
#define SPARSE_MAX_FILL 0.1

int eom__dae_linear_solver(eom_system *s, int requested, int dq,
                           int *choice)
{
    const int NY = 2 * s->n + s->m + 1;
    eom_dae_pattern p;
    int rc;
    *choice = EOM_LINSOL_DENSE;
    if (requested == EOM_LINSOL_DENSE)
        return EOM_OK;
    if (requested == EOM_LINSOL_SPARSE) {
        if (dq)
            return eom__fail(s, EOM_ERR_ARG, "the sparse linear solver "
                             "needs the exact Jacobian (dq_jacobian 0)");
        *choice = EOM_LINSOL_SPARSE;
        return EOM_OK;
    }
    if (dq || NY < SPARSE_MIN_NY)
        return EOM_OK;
    if ((rc = eom__dae_pattern(s, &p)) != EOM_OK)
        return rc;
    if ((double)p.nnz <= SPARSE_MAX_FILL * (double)NY * (double)NY)
        *choice = EOM_LINSOL_SPARSE;
    return EOM_OK;
}

int eom_dae_pattern_size(eom_system *s, int *unknowns, long *entries,
                         int *colors)
{
    eom_dae_pattern p;
    int rc;
    if (!s)
        return EOM_ERR_NULL;
    s->msg[0] = '\0';
    if ((rc = eom__dae_pattern(s, &p)) != EOM_OK)
        return rc;
    if (unknowns)
        *unknowns = p.NY;
    if (entries)
        *entries = (long)p.nnz;
    if (colors)
        *colors = p.colors;
    return EOM_OK;
}
