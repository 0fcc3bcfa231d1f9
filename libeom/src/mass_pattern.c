/* mass_pattern.c - what the L tape says about the mass matrix, found once
 * per system: M's sparsity pattern and whether M is constant.
 *
 * Two derivative tapes (libtape's tp_call_vjp / tp_call_jvp):
 *   G(x)    = dL/dqd                       x = (q, qd [, t]), n outputs
 *   MU(x,u) = (dG/dqd) u = M(x) u          u the n new independents
 * MU is linear in u with the entries of M as coefficients, so the
 * structural Jacobian pattern of MU (libtape's pattern.c, a superset of
 * every entry that can be nonzero, never a subset) gives:
 *   - over u: M's pattern, entry (i, j) when row i of M u reads u_j;
 *   - over x: M's dependence on the state. When no output of MU depends
 *     on any of q, qd or t, M is the same at every state (it may still
 *     depend on the parameters: rhs.c refactors it when one changes).
 * The decision is structural, from the tape's operations, never from
 * values at sample states: a model whose M depends on q only through a
 * term that happens to vanish where it is sampled is still "not
 * constant". It can err only towards "not constant" (a dependence that
 * cancels algebraically, such as sin^2 + cos^2, is still counted), which
 * costs speed, never correctness.
 *
 * The analysis runs at the first evaluation that needs it (eom__mass_at)
 * and its result stays with the system (a clone repeats it). If it
 * cannot be done (out of memory), the system keeps the dense route,
 * which needs none of it.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"
#include "mass_route.h"

void eom__mass_free(eom_mass **p)
{
    eom_mass *ms;
    if (!p || !*p)
        return;
    ms = *p;
    free(ms->colptr);
    free(ms->rowind);
    tp_ws_free(&ms->ws);
    free(ms->work);
    free(ms->w);
    free(ms->y);
    free(ms);
    *p = NULL;
}

/* Record G = dL/dqd from the L tape t (n_indep = ni = 2n or 2n + 1). */
static int record_G(const tp_tape *t, int n, int ni, tp_tape **out)
{
    tp_rec *r = NULL;
    tp_val *x = NULL, *w = NULL, *gx = NULL;
    const int nout = tp_tape_n_outputs(t);
    int i, st;
    char name[32];
    st = tp_recorder_new(&r, ni, NULL, NULL);
    if (st != TP_OK)
        return st;
    x = malloc((size_t)ni * sizeof *x);
    w = malloc((size_t)nout * sizeof *w);
    gx = malloc((size_t)ni * sizeof *gx);
    if (!x || !w || !gx) {
        st = TP_ERR_NOMEM;
        goto done;
    }
    for (i = 0; i < ni; i++)
        x[i] = tp_indep(r, i);
    /* L is output 0 of the L tape (what rhs.c differentiates) */
    for (i = 0; i < nout; i++)
        w[i] = tp_const(r, i == 0 ? 1.0 : 0.0);
    tp_call_vjp(r, t, x, NULL, w, NULL, gx, NULL);
    for (i = 0; i < n; i++) {
        snprintf(name, sizeof name, "p%d", i);
        tp_output(r, name, gx[n + i]);
    }
    st = tp_recorder_finish(r, out);
done:
    free(x);
    free(w);
    free(gx);
    tp_rec_free(&r);
    return st;
}

/* Record MU = (dG/dqd) u from G: independents (x, u), ni + n of them. */
static int record_MU(const tp_tape *G, int n, int ni, tp_tape **out)
{
    tp_rec *r = NULL;
    tp_val *x = NULL, *dx = NULL, *dy = NULL;
    int i, st;
    char name[32];
    st = tp_recorder_new(&r, ni + n, NULL, NULL);
    if (st != TP_OK)
        return st;
    x = malloc((size_t)ni * sizeof *x);
    dx = malloc((size_t)ni * sizeof *dx);
    dy = malloc((size_t)n * sizeof *dy);
    if (!x || !dx || !dy) {
        st = TP_ERR_NOMEM;
        goto done;
    }
    for (i = 0; i < ni; i++) {
        x[i] = tp_indep(r, i);
        /* the direction: u on the rates, 0 on q (and t) */
        dx[i] = i >= n && i < 2 * n ? tp_indep(r, ni + i - n)
                                     : tp_const(r, 0.0);
    }
    tp_call_jvp(r, G, x, NULL, dx, NULL, NULL, dy);
    for (i = 0; i < n; i++) {
        snprintf(name, sizeof name, "mu%d", i);
        tp_output(r, name, dy[i]);
    }
    st = tp_recorder_finish(r, out);
done:
    free(x);
    free(dx);
    free(dy);
    tp_rec_free(&r);
    return st;
}

/* M's pattern as the union of the pattern P read from MU (row i of P:
 * cols[rowptr[i] ..]) and its transpose, in compressed columns with rows
 * ascending and no repeats: M is symmetric, and the sweep that reads its
 * entries (kkt_sparse.c) needs every entry in both triangles, even
 * where the structural analysis found one side alone. pos[n + 1] is
 * scratch; ms->rowind has room for 2 |P| entries. */
static int cmp_i64(const void *x, const void *y)
{
    const int64_t a = *(const int64_t *)x, b = *(const int64_t *)y;
    return (a > b) - (a < b);
}

static void symmetric_union(int n, const size_t *rowptr, const int *cols,
                            eom_mass *ms, size_t *pos)
{
    size_t a, e = 0, k;
    int i, j;
    /* each (i, j) of P puts row i in column j and row j in column i */
    memset(pos, 0, ((size_t)n + 1) * sizeof *pos);
    for (i = 0; i < n; i++)
        for (a = rowptr[i]; a < rowptr[i + 1]; a++) {
            pos[cols[a] + 1]++;
            pos[i + 1]++;
        }
    for (j = 0; j < n; j++)
        pos[j + 1] += pos[j];
    for (j = 0; j <= n; j++)
        ms->colptr[j] = (int64_t)pos[j];
    for (i = 0; i < n; i++)
        for (a = rowptr[i]; a < rowptr[i + 1]; a++) {
            ms->rowind[pos[cols[a]]++] = i;
            ms->rowind[pos[i]++] = cols[a];
        }
    /* sort each column and drop repeats, compacting as we go */
    for (j = 0; j < n; j++) {
        const size_t lo = (size_t)ms->colptr[j], hi = (size_t)ms->colptr[j + 1];
        const size_t start = e;
        qsort(ms->rowind + lo, hi - lo, sizeof *ms->rowind, cmp_i64);
        for (k = lo; k < hi; k++)
            if (e == start || ms->rowind[e - 1] != ms->rowind[k])
                ms->rowind[e++] = ms->rowind[k];
        ms->colptr[j] = (int64_t)start;
    }
    ms->colptr[n] = (int64_t)e;
    ms->nnz = e;
}

/* M's pattern (compressed rows of MU over u, made symmetric) and its
 * dependence on the state, from MU. */
static int read_MU(const tp_tape *MU, int n, int ni, eom_mass *ms)
{
    size_t *rowptr = malloc(((size_t)n + 1) * sizeof *rowptr);
    int *cols = NULL, st;
    size_t *last = NULL;
    if (!rowptr)
        return TP_ERR_NOMEM;
    /* over the state: no entry at all means M is constant */
    st = tp_tape_jacobian_pattern(MU, 0, ni, rowptr, NULL, 0);
    if (st != TP_OK)
        goto done;
    ms->constant = rowptr[n] == 0;
    /* over u: the pattern itself */
    st = tp_tape_jacobian_pattern(MU, ni, n, rowptr, NULL, 0);
    if (st != TP_OK)
        goto done;
    cols = malloc((rowptr[n] ? rowptr[n] : 1) * sizeof *cols);
    ms->colptr = calloc((size_t)n + 1, sizeof *ms->colptr);
    /* room for the union with the transpose: at most twice the entries */
    ms->rowind = malloc((rowptr[n] ? 2 * rowptr[n] : 1) *
                        sizeof *ms->rowind);
    last = malloc(((size_t)n + 1) * sizeof *last);
    if (!cols || !ms->colptr || !ms->rowind || !last) {
        st = TP_ERR_NOMEM;
        goto done;
    }
    st = tp_tape_jacobian_pattern(MU, ni, n, rowptr, cols, rowptr[n]);
    if (st != TP_OK)
        goto done;
    symmetric_union(n, rowptr, cols, ms, last);
done:
    free(rowptr);
    free(cols);
    free(last);
    return st;
}

/* Analyse s's L tape (once). */
static void analyse(eom_system *s, eom_mass *ms)
{
    const tp_tape *t = s->tL.tape;
    const int n = s->n, ni = tp_tape_n_indep(t);
    tp_tape *G = NULL, *MU = NULL;
    int st;
    const int nout = tp_tape_n_outputs(t);
    ms->analysed = true;
    ms->ok = false;
    if (n == 0)
        return;
    ms->work = calloc(3 * (size_t)ni, sizeof *ms->work);
    ms->w = calloc((size_t)nout, sizeof *ms->w);
    ms->y = calloc((size_t)nout, sizeof *ms->y);
    if (!ms->work || !ms->w || !ms->y)
        return;
    ms->w[0] = 1.0;
    st = record_G(t, n, ni, &G);
    if (st == TP_OK)
        st = record_MU(G, n, ni, &MU);
    if (st == TP_OK)
        st = read_MU(MU, n, ni, ms);
    if (st == TP_OK)
        st = tp_ws_new(&ms->ws, t, 1, NULL);
    ms->ok = st == TP_OK;
    if (!ms->ok)
        ms->constant = false;
    tp_tape_free(&G);
    tp_tape_free(&MU);
}

eom_mass *eom__mass_info(eom_system *s)
{
    if (!s->mass) {
        s->mass = calloc(1, sizeof *s->mass);
        if (!s->mass)
            return NULL;
    }
    if (!s->mass->analysed)
        analyse(s, s->mass);
    return s->mass;
}
