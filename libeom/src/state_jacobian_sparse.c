/* state_jacobian_sparse.c - bdf's Jacobian d(yd)/dy of y = (q, qd, W) as
 * a sparse (compressed-column) matrix, for SUNLinSol_KLU, and the rule
 * that chooses between it and the dense matrix (eom_opts.linear_solver).
 *
 * Without constraints the Jacobian is (integrate_cvode.c, residual.c)
 *
 *         q     qd    W
 *   q'  [ 0     I     0 ]      X = d qdd/dx = -M^-1 dE/dx
 *   qd' [ X_q   X_qd  0 ]      (E the residual tape's first n outputs,
 *   W'  [-P_q  -P_qd  0 ]       P its power output)
 *
 * X is sparse exactly when M^-1 is: M^-1 is block diagonal on the
 * connected components of M's graph (coordinates i and j joined when
 * M_ij can be nonzero), so the pattern of column c of X is the union of
 * the components that the rows of column c of dE/dx touch. All of it
 * comes from the residual tape's structure (tp_tape_jacobian_pattern,
 * dE/dqdd being M), never from values at one state, so it holds every
 * entry that is nonzero at any state. With constraints the
 * multipliers' term M^-1 C^T S^-1 C M^-1 fills X in; this file is for
 * models without them (eom__ode_linear_solver refuses otherwise).
 *
 * The pattern holds the whole diagonal, explicit zeros included:
 * CVODE forms I - gamma J in place (SUNMatScaleAddI), which for a sparse
 * matrix missing a diagonal entry reallocates it, and KLU's symbolic
 * analysis, done once, needs the same pattern at every factorization.
 *
 * Values: one forward sweep of the residual tape over the columns of x
 * compressed by colour (two columns share a colour when no component of
 * M is in both their X patterns), then M^-1 by the system's own factors
 * of M (eom__mass_solve) on the compressed columns: the columns of a
 * colour reach disjoint components, so the solve keeps them apart and
 * each entry is read back from its column's colour. The power row P
 * joins the colouring when that costs at most REVERSE_COST colours, else
 * it is one reverse sweep (with dissipation it reads every rate). The
 * entries of X equal the dense path's bit for bit (same sweep, zeros
 * added exactly); P's to rounding when it comes from the reverse sweep.
 *
 * The structure is made once per system, on first use, and kept with its
 * own workspace of the residual tape.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"

/* How an entry gets its value. */
enum { E_ZERO, E_ONE, E_X, E_P };

/* A reverse sweep costs about as many forward directions (as in
 * jacobian_sparse.c). */
#define REVERSE_COST 3

struct eom_ssparse {
    int n, N;          /* coordinates; N = 2n + 1 */
    int nz;            /* the residual tape's independents */
    int nr;            /* its outputs: n + 1 */
    int nblocks;       /* components of M's graph */
    int largest;       /* coordinates in the largest */
    int ncolors;       /* directions of the forward sweep */
    int *color;        /* [2n] the colour of each column of x */
    int p_rev;         /* 1: P from a reverse sweep */
    double *seed;      /* [nz x ncolors] the compressed directions */
    double *JS;        /* [nr x ncolors] the compressed Jacobian */
    double *B;         /* [n x ncolors] column-major: M^-1 dE/dx S */
    double *g;         /* [nz] the reverse row */
    double *yv;        /* [nr] the outputs */
    double *zv;        /* [nz] the point */
    tp_ws *ws;         /* a workspace of the residual tape, this file's */
    size_t nnz;
    int64_t *colptr;   /* [N + 1] */
    int64_t *rowind;   /* [nnz] rows ascending in each column */
    unsigned char *kind; /* [nnz] E_* */
};

void eom__ssparse_free(eom_ssparse **p)
{
    eom_ssparse *j = p ? *p : NULL;
    if (!j)
        return;
    tp_ws_free(&j->ws);
    free(j->color);
    free(j->seed);
    free(j->JS);
    free(j->B);
    free(j->g);
    free(j->yv);
    free(j->zv);
    free(j->colptr);
    free(j->rowind);
    free(j->kind);
    free(j);
    *p = NULL;
}

static int find(int *parent, int i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* Greedy colouring of the 2n columns of x: columns that share a
 * component (cb/cbl: the components of each column, CSR) conflict, and
 * with prow also every two columns that P reads (inp[c]). The colours
 * into color; returns their number, or -1 out of memory. */
static int colour(int n2, int nb, const size_t *cbp, const int *cbl,
                  const unsigned char *inp, int prow, int *color)
{
    size_t *bcp = calloc((size_t)nb + 1, sizeof *bcp), *bcl = NULL, e;
    int *mark = malloc(((size_t)n2 + 2) * sizeof *mark);
    int c, b, k, best = 0;
    unsigned char *pused = calloc((size_t)n2 + 2, 1);
    if (!bcp || !mark || !pused)
        goto fail;
    /* the columns of each component */
    for (e = 0; e < cbp[n2]; e++)
        bcp[cbl[e] + 1]++;
    for (b = 0; b < nb; b++)
        bcp[b + 1] += bcp[b];
    bcl = malloc((cbp[n2] ? cbp[n2] : 1) * sizeof *bcl);
    if (!bcl)
        goto fail;
    {
        size_t *next = malloc(((size_t)nb + 1) * sizeof *next);
        if (!next)
            goto fail;
        memcpy(next, bcp, ((size_t)nb + 1) * sizeof *next);
        for (c = 0; c < n2; c++)
            for (e = cbp[c]; e < cbp[c + 1]; e++)
                bcl[next[cbl[e]]++] = (size_t)c;
        free(next);
    }
    for (c = 0; c <= n2 + 1; c++)
        mark[c] = -1;
    for (c = 0; c < n2; c++) {
        for (e = cbp[c]; e < cbp[c + 1]; e++) {
            size_t f;
            b = cbl[e];
            for (f = bcp[b]; f < bcp[b + 1]; f++)
                if ((int)bcl[f] < c)
                    mark[color[bcl[f]]] = c;
        }
        for (k = 0; mark[k] == c || (prow && inp[c] && pused[k]); k++)
            ;
        color[c] = k;
        if (prow && inp[c])
            pused[k] = 1;
        if (k + 1 > best)
            best = k + 1;
    }
    free(bcp);
    free(bcl);
    free(mark);
    free(pused);
    return best;
fail:
    free(bcp);
    free(bcl);
    free(mark);
    free(pused);
    return -1;
}

/* Build j for s (m = 0); EOM_OK or a status with a message in s. */
static int build(eom_system *s, eom_ssparse *j)
{
    const int n = s->n, n2 = 2 * s->n, N = 2 * s->n + 1;
    const tp_tape *T = s->tRes.tape;
    size_t *rp = NULL, *cbp = NULL, *cxp = NULL, nres, e;
    int *rc = NULL, *parent = NULL, *comp = NULL, *cbl = NULL, *stamp = NULL;
    int *cnt = NULL, *cstart = NULL, *members = NULL;
    int *color2 = NULL;
    unsigned char *inp = NULL;
    int64_t *rows = NULL;
    unsigned char *kinds = NULL;
    int i, c, b, k, st, status = EOM_ERR_NOMEM, k0, k1, np = 0;
    j->n = n;
    j->N = N;
    j->nr = n + 1;
    j->nz = tp_tape_n_indep(T);
    if (tp_tape_n_outputs(T) != j->nr || j->nz < 3 * n)
        return eom__fail(s, EOM_ERR_MODEL, "the sparse Jacobian: the "
                         "residual tape has %d outputs and %d "
                         "independents, not %d and at least %d",
                         tp_tape_n_outputs(T), j->nz, j->nr, 3 * n);
    /* the residual's pattern over (q, qd, qdd) */
    rp = malloc(((size_t)j->nr + 1) * sizeof *rp);
    if (!rp)
        goto out;
    st = tp_tape_jacobian_pattern(T, 0, 3 * n, rp, NULL, 0);
    nres = rp[j->nr];
    if (st == TP_OK) {
        rc = malloc((nres ? nres : 1) * sizeof *rc);
        if (!rc)
            goto out;
        st = tp_tape_jacobian_pattern(T, 0, 3 * n, rp, rc, nres);
    }
    if (st != TP_OK) {
        status = eom__tape_status(s, st, "the sparse Jacobian's pattern");
        goto out;
    }
    /* M's components: dE_i/dqdd_k joins i and k */
    parent = malloc((size_t)n * sizeof *parent);
    comp = malloc((size_t)n * sizeof *comp);
    cnt = calloc((size_t)n + 1, sizeof *cnt);
    if (!parent || !comp || !cnt)
        goto out;
    for (i = 0; i < n; i++)
        parent[i] = i;
    for (i = 0; i < n; i++)
        for (e = rp[i]; e < rp[i + 1]; e++)
            if (rc[e] >= n2) {
                const int a = find(parent, i), z = find(parent, rc[e] - n2);
                if (a != z)
                    parent[a] = z;
            }
    j->nblocks = 0;
    for (i = 0; i < n; i++)
        comp[i] = -1;
    for (i = 0; i < n; i++) {
        const int r = find(parent, i);
        if (comp[r] < 0)
            comp[r] = j->nblocks++;
        comp[i] = comp[r];
    }
    /* the coordinates of each component (ascending) */
    cstart = calloc((size_t)j->nblocks + 1, sizeof *cstart);
    members = malloc((size_t)(n ? n : 1) * sizeof *members);
    if (!cstart || !members)
        goto out;
    for (i = 0; i < n; i++)
        cstart[comp[i] + 1]++;
    j->largest = 0;
    for (b = 0; b < j->nblocks; b++) {
        if (cstart[b + 1] > j->largest)
            j->largest = cstart[b + 1];
        cstart[b + 1] += cstart[b];
    }
    memcpy(cnt, cstart, (size_t)j->nblocks * sizeof *cnt);
    for (i = 0; i < n; i++)
        members[cnt[comp[i]]++] = i;
    /* the components each column of x reaches through the rows of dE/dx
     * (cbp/cbl, no repeats), and the columns P reads */
    cbp = calloc((size_t)n2 + 1, sizeof *cbp);
    stamp = malloc(((size_t)j->nblocks + 1) * sizeof *stamp);
    inp = calloc((size_t)n2 + 1, 1);
    cxp = calloc((size_t)n2 + 1, sizeof *cxp);
    if (!cbp || !stamp || !inp || !cxp)
        goto out;
    for (e = rp[n]; e < rp[n + 1]; e++)
        if (rc[e] < n2 && !inp[rc[e]]) {
            inp[rc[e]] = 1;
            np++;
        }
    {
        /* the rows of each column of dE/dx (the pattern transposed) */
        size_t *tp = calloc((size_t)n2 + 1, sizeof *tp), *next;
        int *tr = malloc((rp[n] ? rp[n] : 1) * sizeof *tr);
        size_t total = 0;
        next = malloc(((size_t)n2 + 1) * sizeof *next);
        if (!tp || !tr || !next) {
            free(tp);
            free(tr);
            free(next);
            goto out;
        }
        for (e = 0; e < rp[n]; e++)
            if (rc[e] < n2)
                tp[rc[e] + 1]++;
        for (c = 0; c < n2; c++)
            tp[c + 1] += tp[c];
        memcpy(next, tp, ((size_t)n2 + 1) * sizeof *next);
        for (i = 0; i < n; i++)
            for (e = rp[i]; e < rp[i + 1]; e++)
                if (rc[e] < n2)
                    tr[next[rc[e]]++] = i;
        free(next);
        /* two passes: count, then fill */
        for (k = 0; k < 2; k++) {
            for (b = 0; b < j->nblocks; b++)
                stamp[b] = -1;
            total = 0;
            for (c = 0; c < n2; c++) {
                size_t f, rows_c = 0;
                if (k == 1)
                    cbp[c] = total;
                for (f = tp[c]; f < tp[c + 1]; f++) {
                    b = comp[tr[f]];
                    if (stamp[b] == c)
                        continue;
                    stamp[b] = c;
                    if (k == 1)
                        cbl[total] = b;
                    total++;
                    rows_c += (size_t)(cstart[b + 1] - cstart[b]);
                }
                if (k == 0)
                    cxp[c + 1] = cxp[c] + rows_c;
            }
            if (k == 0 && !(cbl = malloc((total ? total : 1) * sizeof *cbl))) {
                free(tp);
                free(tr);
                goto out;
            }
        }
        cbp[n2] = total;
        free(tp);
        free(tr);
    }
    /* colours: without P, and with P if that costs little */
    j->color = malloc(((size_t)n2 + 1) * sizeof *j->color);
    color2 = malloc(((size_t)n2 + 1) * sizeof *color2);
    if (!j->color || !color2)
        goto out;
    k0 = colour(n2, j->nblocks, cbp, cbl, inp, 0, j->color);
    k1 = np > 0 ? colour(n2, j->nblocks, cbp, cbl, inp, 1, color2) : k0;
    if (k0 < 0 || k1 < 0)
        goto out;
    j->p_rev = np > 0 && k1 > k0 + REVERSE_COST;
    if (np > 0 && !j->p_rev)
        memcpy(j->color, color2, (size_t)n2 * sizeof *color2);
    j->ncolors = j->p_rev || np == 0 ? k0 : k1;
    /* the matrix's pattern, column by column: (c, c) always; column
     * q_c: X's rows; column qd_c: row c (the identity) and X's rows; P's
     * row where P reads the column; column W: its diagonal only */
    {
        size_t cap = (size_t)N + (size_t)n + cxp[n2] + (size_t)np, w = 0;
        rows = malloc(cap * sizeof *rows);
        kinds = malloc(cap * sizeof *kinds);
        j->colptr = malloc(((size_t)N + 1) * sizeof *j->colptr);
        if (!rows || !kinds || !j->colptr)
            goto out;
        for (c = 0; c < N; c++) {
            const size_t a = w;
            size_t f, g;
            j->colptr[c] = (int64_t)w;
            rows[w] = c;
            kinds[w++] = E_ZERO;
            if (c >= n && c < n2) {
                rows[w] = c - n;
                kinds[w++] = E_ONE;
            }
            for (f = c < n2 ? cbp[c] : 0; c < n2 && f < cbp[c + 1]; f++) {
                b = cbl[f];
                for (k = cstart[b]; k < cstart[b + 1]; k++) {
                    rows[w] = n + members[k];
                    kinds[w++] = E_X;
                }
            }
            if (c < n2 && inp[c]) {
                rows[w] = n2;
                kinds[w++] = E_P;
            }
            /* sort by row (a few entries: insertion), and merge the
             * diagonal's explicit zero into an entry of the same row */
            for (f = a + 1; f < w; f++) {
                const int64_t r = rows[f];
                const unsigned char kd = kinds[f];
                for (g = f; g > a && (rows[g - 1] > r ||
                                      (rows[g - 1] == r &&
                                       kinds[g - 1] < kd)); g--) {
                    rows[g] = rows[g - 1];
                    kinds[g] = kinds[g - 1];
                }
                rows[g] = r;
                kinds[g] = kd;
            }
            for (f = g = a; f < w; f++)
                if (f == a || rows[f] != rows[g - 1]) {
                    rows[g] = rows[f];
                    kinds[g++] = kinds[f];
                }
            w = g;
        }
        j->colptr[N] = (int64_t)w;
        j->nnz = w;
        j->rowind = malloc((w ? w : 1) * sizeof *j->rowind);
        j->kind = malloc(w ? w : 1);
        if (!j->rowind || !j->kind)
            goto out;
        memcpy(j->rowind, rows, w * sizeof *rows);
        memcpy(j->kind, kinds, w);
    }
    {
        const int dirs = j->ncolors ? j->ncolors : 1;
        j->seed = calloc((size_t)j->nz * (size_t)dirs, sizeof *j->seed);
        j->JS = malloc((size_t)j->nr * (size_t)dirs * sizeof *j->JS);
        j->B = malloc((size_t)(n ? n : 1) * (size_t)dirs * sizeof *j->B);
        j->g = malloc((size_t)j->nz * sizeof *j->g);
        j->yv = malloc((size_t)j->nr * sizeof *j->yv);
        j->zv = malloc((size_t)j->nz * sizeof *j->zv);
        if (!j->seed || !j->JS || !j->B || !j->g || !j->yv || !j->zv)
            goto out;
        for (c = 0; c < n2; c++)
            j->seed[(size_t)c * dirs + j->color[c]] = 1.0;
        if ((st = tp_ws_new(&j->ws, T, dirs, NULL)) != TP_OK) {
            status = eom__tape_status(s, st,
                                      "the sparse Jacobian's workspace");
            goto out;
        }
    }
    status = EOM_OK;
out:
    if (status == EOM_ERR_NOMEM)
        eom__fail(s, status, "out of memory for the sparse Jacobian's "
                  "pattern");
    free(rp);
    free(rc);
    free(parent);
    free(comp);
    free(cnt);
    free(cstart);
    free(members);
    free(cbp);
    free(cbl);
    free(cxp);
    free(stamp);
    free(inp);
    free(color2);
    free(rows);
    free(kinds);
    return status;
}

static int ready(eom_system *s)
{
    int rc;
    if (s->ssp)
        return EOM_OK;
    if (s->m > 0)
        return eom__fail(s, EOM_ERR_ARG, "the sparse Jacobian of the "
                         "state derivative is for models without "
                         "constraints");
    if (!s->tRes.tape)
        return eom__fail(s, EOM_ERR_MODEL,
                         "the system has no residual tape");
    if (!(s->ssp = calloc(1, sizeof *s->ssp)))
        return eom__fail(s, EOM_ERR_NOMEM,
                         "out of memory for the sparse Jacobian");
    if ((rc = build(s, s->ssp)) != EOM_OK)
        eom__ssparse_free(&s->ssp); /* the next call tries again */
    return rc;
}

int eom__ode_pattern(eom_system *s, eom_ode_pattern *p)
{
    int rc = ready(s);
    if (rc != EOM_OK)
        return rc;
    p->N = s->ssp->N;
    p->nnz = s->ssp->nnz;
    p->colptr = s->ssp->colptr;
    p->rowind = s->ssp->rowind;
    p->colors = s->ssp->ncolors;
    p->reverse_rows = s->ssp->p_rev;
    p->blocks = s->ssp->nblocks;
    p->largest_block = s->ssp->largest;
    return EOM_OK;
}

int eom__state_jacobian_sparse(eom_system *s, double t, const double *y,
                               double *data)
{
    eom_ssparse *j;
    const double *JS;
    size_t e;
    int n, c, i, k, rc, st, dirs;
    if ((rc = ready(s)) != EOM_OK)
        return rc;
    j = s->ssp;
    n = j->n;
    dirs = j->ncolors;
    /* the evaluation at (t, x) leaves qdd and M's factors */
    if ((rc = eom__evaluate(s, t, y)) != EOM_OK)
        return rc;
    eom__residual_fill_z(s, t, y, s->qdd, s->lam, j->zv);
    if (dirs > 0) {
        st = tp_jvp(j->ws, j->zv, dirs, j->seed, j->yv, j->JS);
        if ((rc = eom__tape_status(s, st, "the sparse Jacobian of the "
                                          "equations")) != EOM_OK)
            return rc;
        for (k = 0; k < dirs; k++)
            for (i = 0; i < n; i++)
                j->B[(size_t)k * n + i] = j->JS[(size_t)i * dirs + k];
        if ((rc = eom__mass_solve(s, j->B, dirs)) != EOM_OK)
            return rc;
    }
    if (j->p_rev) {
        st = tp_gradient(j->ws, j->zv, n, NULL, j->g);
        if ((rc = eom__tape_status(s, st, "the sparse Jacobian's power "
                                          "row")) != EOM_OK)
            return rc;
    }
    JS = j->JS + (size_t)n * (size_t)dirs; /* the P row */
    for (c = 0; c < j->N; c++)
        for (e = (size_t)j->colptr[c]; e < (size_t)j->colptr[c + 1]; e++) {
            const int r = (int)j->rowind[e];
            switch (j->kind[e]) {
            case E_ONE: data[e] = 1.0; break;
            case E_X:
                data[e] = -j->B[(size_t)j->color[c] * n + (size_t)(r - n)];
                break;
            case E_P:
                data[e] = -(j->p_rev ? j->g[c] : JS[j->color[c]]);
                break;
            default: data[e] = 0.0; break;
            }
        }
    if (!eom__finite(data, j->nnz))
        return eom__fail(s, EOM_ERR_NONFINITE, "the sparse Jacobian at "
                         "t = %g is not finite", t);
    return EOM_OK;
}

/* The automatic choice: ida's rule and bounds (jacobian_sparse.c,
 * docs/integrators.md "Sparse iteration matrices"), on the N = 2n + 1
 * unknowns of bdf's state. Refusals name why and what goes on instead. */
#define SPARSE_MIN_N 40
#define SPARSE_MAX_FILL 0.1

int eom__ode_linear_solver(eom_system *s, int requested, int dq,
                           int *choice)
{
    const int N = 2 * s->n + 1;
    eom_ode_pattern p;
    int rc;
    *choice = EOM_LINSOL_DENSE;
    if (requested == EOM_LINSOL_DENSE)
        return EOM_OK;
    if (requested == EOM_LINSOL_SPARSE) {
        if (dq)
            return eom__fail(s, EOM_ERR_ARG, "the sparse linear solver "
                             "needs the exact Jacobian (dq_jacobian 0)");
        if (s->m > 0)
            return eom__fail(s, EOM_ERR_ARG, "bdf's Jacobian is dense "
                             "with constraints (M^-1 C^T S^-1 C M^-1 fills "
                             "it in): use bdf with the dense linear solver, "
                             "or ida, whose iteration matrix stays sparse");
        if ((rc = eom__ode_pattern(s, &p)) != EOM_OK)
            return rc;
        /* one block of M over most coordinates: M^-1 is full there */
        if (s->n >= 2 && 2 * p.largest_block > s->n)
            return eom__fail(s, EOM_ERR_ARG, "bdf's Jacobian is dense: "
                             "the mass matrix couples %d of the %d "
                             "coordinates, and its inverse fills them in; "
                             "use bdf with the dense linear solver",
                             p.largest_block, s->n);
        *choice = EOM_LINSOL_SPARSE;
        return EOM_OK;
    }
    if (dq || s->m > 0 || N < SPARSE_MIN_N)
        return EOM_OK;
    if ((rc = eom__ode_pattern(s, &p)) != EOM_OK)
        return rc;
    if ((double)p.nnz <= SPARSE_MAX_FILL * (double)N * (double)N)
        *choice = EOM_LINSOL_SPARSE;
    return EOM_OK;
}
