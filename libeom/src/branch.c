/* branch.c - noticing when a run jumps to another assembly branch.
 *
 * A closed mechanism may be assembled in several ways (a four-bar's two
 * modes, a parallelogram and its anti-parallelogram), and the branches
 * meet at singular positions, where C loses rank. The exact motion goes
 * through such a point smoothly, on its own branch; a numerical solution
 * can come out on the other branch and go on as if nothing happened. The
 * branches share the positions there but not the velocities, so a
 * switch shows as a jump of the velocity that no force explains.
 *
 * So the monitor watches the rank of C after each accepted step (complete
 * pivoting, a pivot below RANK_TOL of the largest counts as zero). While the
 * rank is below the rank at the start, the run is passing a singular
 * position: from the last step before the pass to the first step after
 * it, the accelerations are integrated by the trapezoidal rule over the
 * accepted steps (one evaluation of the right-hand side per step of the
 * pass), and the velocity change they explain is compared with the
 * velocity change that happened. A mismatch above a tenth of the speed
 * is a branch switch: counted and reported with its time (eom_stats),
 * not an error. Away from singular positions nothing is evaluated but C.
 *
 * On the integrators' sparse path (kkt_integ.c) the rank is not
 * computed where the sparse measure of singularity says the state is
 * far from a singular position (eom__branch_regular: the rank is full
 * there, and its dense elimination would cost O(m^2 n) per step); the
 * elimination's scratch is allocated at its first use.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "integrate_internal.h"

/* A pivot below RANK_TOL of the largest counts as zero (rank_of): the
 * rank drops within an angle of about RANK_TOL of a singular
 * position, a neighbourhood wide enough that no step that follows the
 * motion's turning (at most a few hundredths of a radian) jumps over it */
#define RANK_TOL 0.05
#define MISMATCH 0.1  /* of the speed: a velocity jump */

struct eom_branch {
    int m, n;
    int rank0;      /* rank of C at the start */
    double *a;      /* [m n] scratch for the elimination */
    double *scale;  /* [m] 1 / the norm of each row of C at the start */
    int *rp, *cp;   /* [m], [n] pivot orders */
    double *prev;   /* [2n] the state of the last accepted step */
    double t_prev;
    int in_pass;    /* inside a singular neighbourhood */
    double *qd0;    /* [n] the velocity before the pass */
    double *acc;    /* [n] the integral of qdd over the pass so far */
    double *qdd;    /* [n] qdd at the pass's latest step */
    long passes;    /* singular neighbourhoods passed */
    long switches;
    double first;
    struct eom_branch *mark; /* a copy at the last output, or NULL */
};

/* the state that a run repeated from the mark must find again */
static void copy_state(eom_branch *to, const eom_branch *from)
{
    const size_t n = (size_t)from->n;
    memcpy(to->prev, from->prev, 2 * n * sizeof(double));
    memcpy(to->qd0, from->qd0, n * sizeof(double));
    memcpy(to->acc, from->acc, n * sizeof(double));
    memcpy(to->qdd, from->qdd, n * sizeof(double));
    to->t_prev = from->t_prev;
    to->in_pass = from->in_pass;
    to->passes = from->passes;
    to->switches = from->switches;
    to->first = from->first;
}

/* The numerical rank of C (m x n, row-major) by complete pivoting, its
 * rows scaled by their length at the start (so that the constraints'
 * units do not matter, while a row that vanishes at a singular position
 * still does), a pivot below RANK_TOL of the largest counting as zero. */
static int rank_of(eom_branch *b, const double *C)
{
    const int m = b->m, n = b->n;
    double *a, big = 0.0;
    int *rp = b->rp, *cp = b->cp;
    int k, i, j;
    if (!b->a &&
        !(b->a = malloc((size_t)m * (size_t)n * sizeof(double))))
        return -1;
    a = b->a;
    for (i = 0; i < m; i++)
        for (j = 0; j < n; j++)
            a[i * n + j] = C[i * n + j] * b->scale[i];
    for (i = 0; i < m; i++)
        rp[i] = i;
    for (j = 0; j < n; j++)
        cp[j] = j;
    for (k = 0; k < m && k < n; k++) {
        int pi = k, pj = k;
        double p = 0.0;
        for (i = k; i < m; i++)
            for (j = k; j < n; j++)
                if (fabs(a[rp[i] * n + cp[j]]) > p) {
                    p = fabs(a[rp[i] * n + cp[j]]);
                    pi = i;
                    pj = j;
                }
        if (k == 0)
            big = p;
        if (!(p > RANK_TOL * big))
            return k;
        i = rp[k]; rp[k] = rp[pi]; rp[pi] = i;
        j = cp[k]; cp[k] = cp[pj]; cp[pj] = j;
        for (i = k + 1; i < m; i++) {
            const double f = a[rp[i] * n + cp[k]] / a[rp[k] * n + cp[k]];
            for (j = k; j < n; j++)
                a[rp[i] * n + cp[j]] -= f * a[rp[k] * n + cp[j]];
        }
    }
    return k;
}

void eom__branch_free(eom_branch **b)
{
    if (!b || !*b)
        return;
    free((*b)->a);
    free((*b)->scale);
    free((*b)->rp);
    free((*b)->cp);
    free((*b)->prev);
    free((*b)->qd0);
    free((*b)->acc);
    free((*b)->qdd);
    eom__branch_free(&(*b)->mark);
    free(*b);
    *b = NULL;
}

/* A monitor for m constraints on n coordinates, its arrays allocated. */
static eom_branch *branch_alloc(int m, int n)
{
    eom_branch *b = calloc(1, sizeof *b);
    if (!b)
        return NULL;
    b->m = m;
    b->n = n;
    b->scale = malloc((size_t)m * sizeof(double));
    b->rp = malloc((size_t)m * sizeof(int));
    b->cp = malloc((size_t)n * sizeof(int));
    b->prev = malloc(2 * (size_t)n * sizeof(double));
    b->qd0 = malloc((size_t)n * sizeof(double));
    b->acc = malloc((size_t)n * sizeof(double));
    b->qdd = malloc((size_t)n * sizeof(double));
    if (!b->scale || !b->rp || !b->cp || !b->prev || !b->qd0 ||
        !b->acc || !b->qdd)
        eom__branch_free(&b);
    return b;
}

int eom__branch_new(eom_branch **out, eom_system *s, double t,
                    const double *x)
{
    const int m = s->m, n = s->n;
    eom_branch *b = branch_alloc(m, n);
    int rc, i, j;
    *out = NULL;
    if (!b)
        return EOM_ERR_NOMEM;
    if ((rc = eom__constraints_at(s, t, x)) != EOM_OK) {
        eom__branch_free(&b);
        return rc;
    }
    for (i = 0; i < m; i++) {
        double norm = 0.0;
        for (j = 0; j < n; j++)
            norm += s->C[i * n + j] * s->C[i * n + j];
        b->scale[i] = norm > 0.0 ? 1.0 / sqrt(norm) : 1.0;
    }
    b->rank0 = rank_of(b, s->C);
    if (b->rank0 < 0) {
        eom__branch_free(&b);
        return EOM_ERR_NOMEM;
    }
    memcpy(b->prev, x, 2 * (size_t)n * sizeof(double));
    b->t_prev = t;
    *out = b;
    return EOM_OK;
}

int eom__branch_new_regular(eom_branch **out, eom_system *s, double t,
                            const double *x, const double *norm)
{
    eom_branch *b = branch_alloc(s->m, s->n);
    int i;
    *out = NULL;
    if (!b)
        return EOM_ERR_NOMEM;
    for (i = 0; i < s->m; i++)
        b->scale[i] = norm[i] > 0.0 ? 1.0 / norm[i] : 1.0;
    b->rank0 = s->m;
    memcpy(b->prev, x, 2 * (size_t)s->n * sizeof(double));
    b->t_prev = t;
    *out = b;
    return EOM_OK;
}

int eom__branch_in_pass(const eom_branch *b)
{
    return b->in_pass;
}

void eom__branch_regular(eom_branch *b, double t, const double *x)
{
    memcpy(b->prev, x, 2 * (size_t)b->n * sizeof(double));
    b->t_prev = t;
}

/* acc += (h / 2) (qdd + qdd at x), and qdd := qdd at x */
static int accumulate(eom_branch *b, eom_system *s, double t,
                      const double *x, double h)
{
    int i, rc = eom__evaluate(s, t, x);
    if (rc != EOM_OK)
        return rc;
    for (i = 0; i < b->n; i++) {
        b->acc[i] += 0.5 * h * (b->qdd[i] + s->qdd[i]);
        b->qdd[i] = s->qdd[i];
    }
    return EOM_OK;
}

int eom__branch_check(eom_branch *b, eom_system *s, double t,
                      const double *x, long *evals)
{
    const int n = b->n;
    const double *qd = x + n;
    int i, singular, rc;
    if ((rc = eom__constraints_at(s, t, x)) != EOM_OK)
        return rc;
    if ((singular = rank_of(b, s->C)) < 0)
        return eom__fail(s, EOM_ERR_NOMEM, "out of memory");
    singular = singular < b->rank0;
    if (singular && !b->in_pass) {
        /* entering: start from the last step before the pass */
        if ((rc = eom__evaluate(s, b->t_prev, b->prev)) != EOM_OK)
            return rc;
        ++*evals;
        memcpy(b->qd0, b->prev + n, (size_t)n * sizeof(double));
        memcpy(b->qdd, s->qdd, (size_t)n * sizeof(double));
        memset(b->acc, 0, (size_t)n * sizeof(double));
        b->in_pass = 1;
    }
    if (b->in_pass) {
        if ((rc = accumulate(b, s, t, x, t - b->t_prev)) != EOM_OK)
            return rc;
        ++*evals;
    }
    if (b->in_pass && !singular) {
        /* out again: the velocity change against what qdd explains */
        double jump = 0.0, speed = 0.0;
        for (i = 0; i < n; i++) {
            jump = fmax(jump, fabs(qd[i] - b->qd0[i] - b->acc[i]));
            speed = fmax(speed, fmax(fabs(qd[i]), fabs(b->qd0[i])));
        }
        if (jump > MISMATCH * speed && b->switches++ == 0)
            b->first = t;
        b->in_pass = 0;
        b->passes++;
    }
    memcpy(b->prev, x, 2 * (size_t)n * sizeof(double));
    b->t_prev = t;
    return EOM_OK;
}

int eom__branch_mark(eom_branch *b)
{
    if (!b->mark && !(b->mark = branch_alloc(b->m, b->n)))
        return EOM_ERR_NOMEM;
    copy_state(b->mark, b);
    return EOM_OK;
}

void eom__branch_rewind(eom_branch *b)
{
    if (b->mark)
        copy_state(b, b->mark);
}

long eom__branch_switches(const eom_branch *b, double *first,
                          long *passes)
{
    if (first)
        *first = b ? b->first : 0.0;
    if (passes)
        *passes = b ? b->passes : 0;
    return b ? b->switches : 0;
}
