/* kkt_sparse.c - the constrained solve of eom_rhs as one sparse system,
 * for models whose mass matrix is constant (mass_route.c):
 *
 *     [ M  C^T ] [ qdd ]   [ F   ]
 *     [ C  0   ] [ -lam] = [ gam ]          (n + m square, KLU)
 *
 * which is the range-space method's M qdd = F + C^T lambda, C qdd = gam
 * (rhs.c) written as one matrix. Why not C M^-1 C^T: M^-1 of a banded M
 * (a chain of bodies in natural coordinates couples each point with its
 * neighbours) is full, so C M^-1 C^T is a full m x m matrix, its forming
 * O(n m^2) and its factor O(m^3) at every evaluation, whereas the
 * augmented matrix keeps the sparsity of M and C and KLU (its fill-
 * reducing order chosen once, klu_analyze) factors it in time about
 * linear in n for such chains.
 *
 * Its pieces, all found once per system and linear in the tape:
 *   M        the constant mass matrix: its pattern from mass_pattern.c's
 *            structural analysis, its entries from one Hessian sweep
 *            with as many directions as the pattern has colours (three
 *            for a chain), once per set of parameter values; no dense
 *            n x n matrix is formed or factored;
 *   C        from a forward sweep of the constraints' tape with p
 *            directions, p the colours of C's columns (two columns share
 *            a colour when no row reads both, a greedy colouring of the
 *            pattern from libtape's tp_tape_jacobian_pattern): each
 *            column's entries are read from its colour's direction;
 *   gam      one Taylor sweep (eom__constraint_rates, as rhs.c).
 *
 * When it applies (eom__kkt_applies): holonomic constraints only, which
 * do not read the time, a constant M (structurally, mass_pattern.c), and
 * on the automatic route n >= EOM_KKT_MIN_N (and, for a system running
 * compiled tapes, n > 64, as the constant route); otherwise, and at every evaluation whose KLU factor
 * is poorly conditioned (a singular position, where the range-space
 * method's filtered solve is the one to use: rhs.c, EOM_RCOND_PINV), the
 * dense range-space evaluation runs instead. eom_rhs and
 * eom_multipliers take this route, and so do rk4, erk and adams away
 * from singular positions (kkt_integ.c: the augmented factor is also
 * their projection's, and eom__kkt_factor_at / eom__kkt_solve its
 * pieces); the other integrators evaluate through eom__evaluate, whose
 * factors of C M^-1 C^T their Jacobians and error projections read.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "eom_internal.h"
#include "kkt_sparse.h"
#include "mass_route.h"

/* Below this many coordinates the dense range-space solve is as fast
 * (bench-a02-growth: at N = 10, n = 22, the two are within 10 %). */
#define EOM_KKT_MIN_N 32


void eom__kkt_free(eom_kkt **p)
{
    eom_kkt *k;
    if (!p || !*p)
        return;
    k = *p;
    if (k->num)
        klu_free_numeric(&k->num, &k->kc);
    if (k->sym)
        klu_free_symbolic(&k->sym, &k->kc);
    eom__kkt_integ_free(k);
    tp_ws_free(&k->wsL);
    tp_ws_free(&k->wsphi);
    free(k->color);
    free(k->mcolor);
    free(k->mseed);
    free(k->mhs);
    free(k->mg);
    free(k->mvals);
    free(k->seed);
    free(k->JS);
    free(k->Kp);
    free(k->Ki);
    free(k->Kx);
    free(k->src);
    free(k->b);
    free(k);
    *p = NULL;
}

/* Greedy colouring of C's columns: j takes the smallest colour no
 * column sharing a row with it has. rowptr/cols: C by rows; cp/ri: by
 * columns. */
static int colour(int n, const size_t *rowptr, const int *cols,
                  const size_t *cp, const int *ri, int *color, int *p)
{
    int *mark = malloc(((size_t)n + 1) * sizeof *mark);
    int j, c;
    size_t a, b;
    if (!mark)
        return -1;
    for (j = 0; j <= n; j++)
        mark[j] = -1;
    *p = 0;
    for (j = 0; j < n; j++) {
        for (a = cp[j]; a < cp[j + 1]; a++)
            for (b = rowptr[ri[a]]; b < rowptr[ri[a] + 1]; b++)
                if (cols[b] < j)
                    mark[color[cols[b]]] = j;
        for (c = 0; mark[c] == j; c++)
            ;
        color[j] = c;
        if (c + 1 > *p)
            *p = c + 1;
    }
    free(mark);
    if (*p == 0)
        *p = 1;
    return 0;
}

/* M's colours (its pattern is symmetric: rows and columns alike) and
 * the seeds of the Hessian sweep that gives its entries. */
static int colour_M(eom_kkt *k, const eom_mass *ms, int ni)
{
    const int n = k->n;
    size_t *ptr = malloc(((size_t)n + 1) * sizeof *ptr);
    int *idx = malloc((ms->nnz ? ms->nnz : 1) * sizeof *idx);
    size_t a;
    int j, rc = -1;
    k->mcolor = calloc((size_t)n, sizeof *k->mcolor);
    k->mvals = calloc(ms->nnz ? ms->nnz : 1, sizeof *k->mvals);
    k->mg = calloc((size_t)ni, sizeof *k->mg);
    if (!ptr || !idx || !k->mcolor || !k->mvals || !k->mg)
        goto done;
    for (j = 0; j <= n; j++)
        ptr[j] = (size_t)ms->colptr[j];
    for (a = 0; a < ms->nnz; a++)
        idx[a] = (int)ms->rowind[a];
    if (colour(n, ptr, idx, ptr, idx, k->mcolor, &k->pm) != 0)
        goto done;
    k->mseed = calloc((size_t)ni * (size_t)k->pm, sizeof *k->mseed);
    k->mhs = calloc((size_t)ni * (size_t)k->pm, sizeof *k->mhs);
    if (!k->mseed || !k->mhs)
        goto done;
    for (j = 0; j < n; j++)
        k->mseed[(size_t)(n + j) * (size_t)k->pm + (size_t)k->mcolor[j]] =
            1.0;
    rc = 0;
done:
    free(ptr);
    free(idx);
    return rc;
}

/* The parameters of the route's own workspaces: the system's values,
 * set again after each eom_set_param. */
static void sync_params(eom_system *s, eom_kkt *k)
{
    int i;
    if (k->wset && k->wgen == s->param_gen)
        return;
    for (i = 0; i < s->np; i++) {
        if (s->tL.pmap[i] >= 0)
            tp_ws_set_param(k->wsL, s->tL.pmap[i], s->pval[i]);
        if (s->tphi.pmap[i] >= 0)
            tp_ws_set_param(k->wsphi, s->tphi.pmap[i], s->pval[i]);
    }
    k->wset = true;
    k->wgen = s->param_gen;
}

/* The constant M's entries, in the order of its pattern, from one
 * Hessian sweep with pm directions (once per set of parameters): entry
 * (i, j) is row n + i of H times the seed of j's colour. */
static int mass_values(eom_system *s, eom_kkt *k, double t, const double *x)
{
    const eom_mass *ms = s->mass;
    const int n = k->n;
    int st, rc, j;
    size_t a;
    if (k->mheld && k->mgen == s->param_gen)
        return EOM_OK;
    st = tp_hvp(k->wsL, eom__tape_input(&s->tL, x, t), ms->w, k->pm,
                k->mseed, k->mg, k->mhs);
    if ((rc = eom__tape_status(s, st, "the Lagrangian or the mass matrix")))
        return rc;
    for (j = 0; j < n; j++)
        for (a = (size_t)ms->colptr[j]; a < (size_t)ms->colptr[j + 1]; a++)
            k->mvals[a] = k->mhs[(size_t)(n + ms->rowind[a]) *
                                     (size_t)k->pm +
                                 (size_t)k->mcolor[j]];
    k->mheld = true;
    k->mgen = s->param_gen;
    return EOM_OK;
}

/* The augmented matrix's pattern and the source of each entry. */
static int assemble_pattern(eom_kkt *k, const eom_mass *ms,
                            const size_t *rowptr, const int *cols,
                            const size_t *cp, const int *ri)
{
    const int n = k->n, m = k->m;
    const size_t nnz = ms->nnz + 2 * rowptr[m];
    size_t e = 0, a;
    int j, i;
    k->Kp = malloc(((size_t)k->N + 1) * sizeof *k->Kp);
    k->Ki = malloc((nnz ? nnz : 1) * sizeof *k->Ki);
    k->Kx = malloc((nnz ? nnz : 1) * sizeof *k->Kx);
    k->src = malloc((nnz ? nnz : 1) * sizeof *k->src);
    if (!k->Kp || !k->Ki || !k->Kx || !k->src || nnz > (size_t)INT32_MAX)
        return -1;
    for (j = 0; j < n; j++) {
        k->Kp[j] = (int)e;
        for (a = (size_t)ms->colptr[j]; a < (size_t)ms->colptr[j + 1];
             a++) {
            k->Ki[e] = (int)ms->rowind[a];
            k->src[e++] = (long)a;
        }
        for (a = cp[j]; a < cp[j + 1]; a++) {
            k->Ki[e] = n + ri[a];
            k->src[e++] = -1 - ((long)ri[a] * k->p + k->color[j]);
        }
    }
    for (i = 0; i < m; i++) {
        k->Kp[n + i] = (int)e;
        for (a = rowptr[i]; a < rowptr[i + 1]; a++) {
            k->Ki[e] = cols[a];
            k->src[e++] = -1 - ((long)i * k->p + k->color[cols[a]]);
        }
    }
    k->Kp[k->N] = (int)e;
    return 0;
}

static void analyse(eom_system *s, eom_kkt *k, const eom_mass *ms)
{
    const int n = s->n, m = s->m;
    size_t *rowptr = NULL, *cp = NULL, a;
    int *cols = NULL, *ri = NULL, i, j;
    size_t *fill = NULL;
    k->analysed = true;
    k->n = n;
    k->m = m;
    k->N = n + m;
    rowptr = malloc(((size_t)m + 1) * sizeof *rowptr);
    if (!rowptr ||
        tp_tape_jacobian_pattern(s->tphi.tape, 0, n, rowptr, NULL, 0) !=
            TP_OK)
        goto done;
    cols = malloc((rowptr[m] ? rowptr[m] : 1) * sizeof *cols);
    ri = malloc((rowptr[m] ? rowptr[m] : 1) * sizeof *ri);
    cp = calloc((size_t)n + 1, sizeof *cp);
    fill = calloc((size_t)n + 1, sizeof *fill);
    k->color = calloc((size_t)n, sizeof *k->color);
    if (!cols || !ri || !cp || !fill || !k->color ||
        tp_tape_jacobian_pattern(s->tphi.tape, 0, n, rowptr, cols,
                                 rowptr[m]) != TP_OK)
        goto done;
    /* by columns too (rows ascending in each) */
    for (a = 0; a < rowptr[m]; a++)
        cp[cols[a] + 1]++;
    for (j = 0; j < n; j++)
        cp[j + 1] += cp[j];
    memcpy(fill, cp, ((size_t)n + 1) * sizeof *fill);
    for (i = 0; i < m; i++)
        for (a = rowptr[i]; a < rowptr[i + 1]; a++)
            ri[fill[cols[a]]++] = i;
    if (colour(n, rowptr, cols, cp, ri, k->color, &k->p) != 0 ||
        colour_M(k, ms, tp_tape_n_indep(s->tL.tape)) != 0 ||
        assemble_pattern(k, ms, rowptr, cols, cp, ri) != 0)
        goto done;
    k->seed = calloc((size_t)n * (size_t)k->p, sizeof *k->seed);
    k->JS = calloc((size_t)m * (size_t)k->p, sizeof *k->JS);
    k->b = calloc((size_t)k->N, sizeof *k->b);
    if (!k->seed || !k->JS || !k->b)
        goto done;
    for (j = 0; j < n; j++)
        k->seed[(size_t)j * (size_t)k->p + (size_t)k->color[j]] = 1.0;
    if (tp_ws_new(&k->wsL, s->tL.tape, k->pm, NULL) != TP_OK ||
        tp_ws_new(&k->wsphi, s->tphi.tape, k->p, NULL) != TP_OK)
        goto done;
    klu_defaults(&k->kc);
    k->sym = klu_analyze(k->N, k->Kp, k->Ki, &k->kc);
    k->ok = k->sym != NULL;
done:
    free(rowptr);
    free(cols);
    free(ri);
    free(cp);
    free(fill);
}

int eom__kkt_possible(eom_system *s)
{
    eom_kkt *k;
    eom_mass *ms = eom__mass_info(s);
    if (s->m == 0 || s->mv > 0 || s->tphi.tindex >= 0 ||
        s->tphi.tparam >= 0 || !ms || !ms->ok || !ms->constant)
        return 0;
    if (!s->kkt) {
        s->kkt = calloc(1, sizeof *s->kkt);
        if (!s->kkt)
            return 0;
    }
    k = s->kkt;
    if (!k->analysed)
        analyse(s, k, ms);
    return k->ok;
}

int eom__kkt_applies(eom_system *s)
{
    const int req = eom__mass_info(s) ? s->mass->requested : 0;
    if (req == EOM_MASS_SPARSE)
        return eom__kkt_possible(s);
    if (req != 0 || s->n < EOM_KKT_MIN_N || (s->compiled && s->n <= 64))
        return 0;
    return eom__kkt_possible(s);
}

/* Factor the augmented matrix (values in Kx); 0 when factored well
 * enough, 1 when this evaluation should take the dense route. */
static int factor(eom_kkt *k)
{
    if (k->num && !klu_refactor(k->Kp, k->Ki, k->Kx, k->sym, k->num,
                                &k->kc))
        klu_free_numeric(&k->num, &k->kc);
    if (k->num && klu_rcond(k->sym, k->num, &k->kc) &&
        k->kc.rcond >= EOM_KKT_RCOND)
        return 0;
    /* new pivots: the first time, after a failed refactorization, or
     * when the old ones have become poor */
    if (k->num)
        klu_free_numeric(&k->num, &k->kc);
    k->num = klu_factor(k->Kp, k->Ki, k->Kx, k->sym, &k->kc);
    if (!k->num)
        return 1;
    if (!klu_rcond(k->sym, k->num, &k->kc) || k->kc.rcond < EOM_KKT_RCOND)
        return 1;
    return 0;
}

int eom__kkt_factor_at(eom_system *s, double t, const double *x, int *poor)
{
    eom_kkt *k = s->kkt;
    const int nnz = k->Kp[k->N];
    int st, rc, e;
    *poor = 0;
    sync_params(s, k);
    if ((rc = mass_values(s, k, t, x)) != EOM_OK)
        return rc;
    st = tp_jvp(k->wsphi, x, k->p, k->seed, s->phi, k->JS);
    if ((rc = eom__tape_status(s, st, "the constraints or their Jacobian")))
        return rc;
    for (e = 0; e < nnz; e++)
        k->Kx[e] = k->src[e] >= 0 ? k->mvals[k->src[e]]
                                  : k->JS[-1 - k->src[e]];
    *poor = factor(k);
    return EOM_OK;
}

int eom__kkt_solve(eom_system *s, double *b)
{
    eom_kkt *k = s->kkt;
    if (!klu_solve(k->sym, k->num, k->N, 1, b, &k->kc))
        return eom__fail(s, EOM_ERR_LINALG, "KLU solve failed (status %d)",
                         k->kc.status);
    return EOM_OK;
}

void eom__kkt_C_times(const eom_system *s, const double *v, double *out)
{
    const eom_kkt *k = s->kkt;
    const int n = k->n, m = k->m;
    int i, e;
    /* row i of C is column n + i of K above its diagonal block */
    for (i = 0; i < m; i++) {
        double sum = 0.0;
        for (e = k->Kp[n + i]; e < k->Kp[n + i + 1]; e++)
            sum += k->Kx[e] * v[k->Ki[e]];
        out[i] = sum;
    }
}

/* After eom__evaluate_free (F in s->F): M's entries (once), C, gam, the
 * augmented solve; qdd and lam into s. *dense set to 1 when this
 * evaluation should take the dense route instead. */
static int solve(eom_system *s, double t, const double *x, int *dense)
{
    eom_kkt *k = s->kkt;
    const int n = s->n, m = s->m;
    int rc, j;
    if ((rc = eom__kkt_factor_at(s, t, x, dense)) != EOM_OK)
        return rc;
    if (*dense)
        return EOM_OK;
    if ((rc = eom__constraint_rates(s, t, x, NULL, s->phid, s->gam)))
        return rc;
    memcpy(k->b, s->F, (size_t)n * sizeof(double));
    for (j = 0; j < m; j++)
        k->b[n + j] = -s->gam[j] - 2.0 * s->alpha * s->phid[j] -
                      s->beta * s->beta * s->phi[j];
    memcpy(s->gam, k->b + n, (size_t)m * sizeof(double));
    if ((rc = eom__kkt_solve(s, k->b)) != EOM_OK)
        return rc;
    memcpy(s->qdd, k->b, (size_t)n * sizeof(double));
    for (j = 0; j < m; j++)
        s->lam[j] = -k->b[n + j];
    return EOM_OK;
}

int eom__evaluate_rhs(eom_system *s, double t, const double *x)
{
    int rc, dense = 0;
    if (!eom__kkt_applies(s))
        return eom__evaluate(s, t, x);
    if ((rc = eom__evaluate_free(s, t, x, 0)) != EOM_OK)
        return rc;
    rc = solve(s, t, x, &dense);
    if (rc == EOM_OK && dense) {
        s->kkt->fallbacks++;
        return eom__evaluate(s, t, x);
    }
    if (rc != EOM_OK)
        return rc;
    s->kkt->solves++;
    /* no filtered pseudo-inverse in this evaluation (an integrator's
     * refusal of singular positions reads it) */
    s->S_pinv = false;
    /* fixed holonomic constraints do no work: power_t is -dL/dt alone */
    s->power += s->power_t;
    if (!eom__finite(s->qdd, (size_t)s->n))
        return eom__fail(s, EOM_ERR_NONFINITE,
                         "the accelerations at t = %g are not finite", t);
    return EOM_OK;
}

void eom__kkt_counts(const eom_system *s, long *solves, long *fallbacks)
{
    *solves = s->kkt ? s->kkt->solves : 0;
    *fallbacks = s->kkt ? s->kkt->fallbacks : 0;
}
