/* kkt_integ.c - the integrators' sparse path for models whose eom_rhs
 * takes the augmented sparse solve (kkt_sparse.c): a measure of how near
 * a singular position the state is, and the projection onto the
 * constraints, both from sparse factors, so that a step away from
 * singular positions costs about linear time in n.
 *
 * The measure. The dense route's handling of singular positions reads
 * KLU's pivot ratio of S = C M^-1 C^T (rhs.c: below EOM_RCOND_PINV the
 * filtered pseudo-inverse; adams refuses it and hands over to bdf). S is
 * full (M^-1 of a banded M is), so it is not formed here; the augmented
 * matrix's own pivot ratio is no substitute (KLU's threshold pivoting
 * makes it jump by decades between nearby states, and its condition
 * grows like N^2 on a chain of N loops where S's pivot ratio does not).
 * Instead: G = C D^-1 C^T, D the diagonal of M, is sparse (two rows of
 * C share an entry only where a coordinate appears in both), and its
 * pivot ratio behaves like S's: it falls like the square of the distance
 * to a singular position and does not grow with N (measured on the A02
 * four-bars, docs/libeom.md). An integrator on the sparse path measures
 * it after each accepted step (eom__kkt_sigma) and evaluates along the
 * dense route, with all of its handling of singular positions, while it
 * is below EOM_KKT_SIGMA_NEAR (integrate.c).
 *
 * The projection. The correction of least M-norm of constraints.c,
 *     dq = -M^-1 C^T (C M^-1 C^T)^-1 phi,
 * is the first block of the solution of
 *     [ M  C^T ] [ dq ]   [  0   ]
 *     [ C  0   ] [ mu ] = [ -phi ],
 * so each Newton iterate is one sparse factor and solve of the augmented
 * matrix at q, and the velocities' correction (C qd -> 0) one more solve
 * with the factor at the projected q. No filter: near a singular position
 * the caller projects along the dense route instead.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kkt_sparse.h"
#include "mass_route.h"

#define EOM_PROJ_MAXIT 20

typedef struct trip {
    int a, b;     /* G's entry (a, b) */
    int ea, eb;   /* entries C_aj, C_bj of Kx */
    int ed;       /* entry M_jj of Kx */
} trip;

static int trip_cmp(const void *x, const void *y)
{
    const trip *p = x, *q = y;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return (p->a > q->a) - (p->a < q->a);
}

/* G's pattern: for each coordinate j, every pair of rows that read it.
 * 0 when made, -1 when it cannot be (M without its diagonal in the
 * pattern, out of memory, KLU's analysis failed). */
static int g_pattern(eom_kkt *k)
{
    const int n = k->n, m = k->m;
    size_t cnt = 0, t, g;
    trip *tr = NULL;
    int j, ea, eb, ed, b;
    for (j = 0; j < n; j++) {
        size_t c = 0;
        for (ea = k->Kp[j]; ea < k->Kp[j + 1]; ea++)
            c += k->Ki[ea] >= n;
        cnt += c * c;
    }
    tr = malloc((cnt ? cnt : 1) * sizeof *tr);
    k->gtrip = malloc((cnt ? 4 * cnt : 1) * sizeof *k->gtrip);
    k->gp = malloc(((size_t)m + 1) * sizeof *k->gp);
    k->gi = malloc((cnt ? cnt : 1) * sizeof *k->gi);
    k->gx = malloc((cnt ? cnt : 1) * sizeof *k->gx);
    if (!tr || !k->gtrip || !k->gp || !k->gi || !k->gx ||
        cnt > (size_t)INT32_MAX) {
        free(tr);
        return -1;
    }
    t = 0;
    for (j = 0; j < n; j++) {
        ed = -1;
        for (ea = k->Kp[j]; ea < k->Kp[j + 1]; ea++)
            if (k->Ki[ea] == j)
                ed = ea;
        if (ed < 0) {
            free(tr);
            return -1;
        }
        for (ea = k->Kp[j]; ea < k->Kp[j + 1]; ea++)
            for (eb = k->Kp[j]; eb < k->Kp[j + 1]; eb++)
                if (k->Ki[ea] >= n && k->Ki[eb] >= n) {
                    tr[t].a = k->Ki[ea] - n;
                    tr[t].b = k->Ki[eb] - n;
                    tr[t].ea = ea;
                    tr[t].eb = eb;
                    tr[t++].ed = ed;
                }
    }
    qsort(tr, cnt, sizeof *tr, trip_cmp);
    g = 0;
    b = 0;
    k->gp[0] = 0;
    for (t = 0; t < cnt; t++) {
        if (t == 0 || tr[t].a != tr[t - 1].a || tr[t].b != tr[t - 1].b) {
            while (b < tr[t].b)
                k->gp[++b] = (int)g;
            k->gi[g++] = tr[t].a;
        }
        k->gtrip[4 * t] = (int)g - 1;
        k->gtrip[4 * t + 1] = tr[t].ea;
        k->gtrip[4 * t + 2] = tr[t].eb;
        k->gtrip[4 * t + 3] = tr[t].ed;
    }
    while (b < m)
        k->gp[++b] = (int)g;
    k->ntrip = cnt;
    free(tr);
    klu_defaults(&k->gc);
    k->gsym = klu_analyze(m, k->gp, k->gi, &k->gc);
    return k->gsym ? 0 : -1;
}

double eom__kkt_sigma(eom_system *s)
{
    eom_kkt *k = s->kkt;
    size_t t;
    if (!k->gok) {
        k->gok = true;
        if (g_pattern(k) != 0) {
            if (k->gsym)
                klu_free_symbolic(&k->gsym, &k->gc);
            return -1.0;
        }
    }
    if (!k->gsym)
        return -1.0;
    memset(k->gx, 0, (size_t)k->gp[k->m] * sizeof *k->gx);
    for (t = 0; t < k->ntrip; t++) {
        const int *q = k->gtrip + 4 * t;
        k->gx[q[0]] += k->Kx[q[1]] * k->Kx[q[2]] / k->Kx[q[3]];
    }
    if (k->gnum)
        klu_free_numeric(&k->gnum, &k->gc);
    k->gnum = klu_factor(k->gp, k->gi, k->gx, k->gsym, &k->gc);
    if (!k->gnum)
        return 0.0;
    if (!klu_rcond(k->gsym, k->gnum, &k->gc))
        return 0.0;
    return k->gc.rcond;
}

void eom__kkt_integ_free(eom_kkt *k)
{
    if (k->gnum)
        klu_free_numeric(&k->gnum, &k->gc);
    if (k->gsym)
        klu_free_symbolic(&k->gsym, &k->gc);
    free(k->gp);
    free(k->gi);
    free(k->gx);
    free(k->gtrip);
}

void eom__kkt_row_norms(const eom_system *s, double *norm)
{
    const eom_kkt *k = s->kkt;
    int i, e;
    for (i = 0; i < k->m; i++) {
        double sum = 0.0;
        for (e = k->Kp[k->n + i]; e < k->Kp[k->n + i + 1]; e++)
            sum += k->Kx[e] * k->Kx[e];
        norm[i] = sqrt(sum);
    }
}

int eom__kkt_project(eom_system *s, double t, double *x, double tol,
                     int *iters, int *dense)
{
    eom_kkt *k = s->kkt;
    const int n = s->n, m = s->m;
    double *b = k->b, res;
    int it = 0, rc, poor, i;
    *iters = 0;
    *dense = 0;
    if (!eom__finite(x, 2 * (size_t)n))
        return eom__fail(s, EOM_ERR_NONFINITE, "the state is not finite");
    /* nothing to do when phi and C qd are within the tolerance */
    if ((rc = eom__constraint_rates(s, t, x, s->phi, s->phid, s->gam)))
        return rc;
    if (eom__maxabs(s->phi, m) <= tol && eom__maxabs(s->phid, m) <= tol)
        return EOM_OK;
    for (;;) {
        if ((rc = eom__kkt_factor_at(s, t, x, &poor)) != EOM_OK)
            return rc;
        if (poor) {
            *dense = 1;
            return EOM_OK;
        }
        res = eom__maxabs(s->phi, m);
        if (res <= tol)
            break;
        if (it == EOM_PROJ_MAXIT)
            return eom__fail(s, EOM_ERR_PROJECTION,
                             "projection onto the constraints: |phi| = "
                             "%.3g after %d iterations (tolerance %.3g) "
                             "of the sparse augmented solve", res, it, tol);
        memset(b, 0, (size_t)n * sizeof *b);
        for (i = 0; i < m; i++)
            b[n + i] = -s->phi[i];
        if ((rc = eom__kkt_solve(s, b)) != EOM_OK)
            return rc;
        for (i = 0; i < n; i++)
            x[i] += b[i];
        it++;
    }
    /* velocities: C qd = 0 at the projected q, whose factor is held */
    eom__kkt_C_times(s, x + n, b + n);
    memset(b, 0, (size_t)n * sizeof *b);
    for (i = 0; i < m; i++)
        b[n + i] = -b[n + i];
    if ((rc = eom__kkt_solve(s, b)) != EOM_OK)
        return rc;
    for (i = 0; i < n; i++)
        x[n + i] += b[i];
    *iters = it;
    return eom__finite(x, 2 * (size_t)n)
               ? EOM_OK
               : eom__fail(s, EOM_ERR_NONFINITE,
                           "the projected state is not finite");
}
