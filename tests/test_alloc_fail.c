/* test_alloc_fail.c - fault injection: fail allocation number N for
 * N = 1, 2, ... until a whole scenario runs without reaching N.
 *
 * The scenario uses every allocating object: a recorder records the
 * 3-link pendulum and finishes a tape; a workspace runs sweeps; the double
 * and tuple evaluators run the same Lagrangian. Every object gets the
 * counting allocator below, which
 *   - fails allocation number N (one-shot mode: later ones succeed, so
 *     error paths that go on allocating are exercised; persistent mode:
 *     every allocation from N on fails);
 *   - tracks every live block with its size, and checks that every free
 *     and every reallocation reports the size the block has (the hook's
 *     contract, tp_allocator in tape.h);
 *   - counts live bytes, which must be zero once everything is freed.
 * A failure must surface as a clean error: TP_ERR_NOMEM from the call
 * that ran out (a constructor also leaves *out NULL), a sticky
 * TP_ERR_NOMEM in the recording context with a message; and whatever did
 * succeed must give the results of an undisturbed run.
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "pendulum_chain.h"
#include "support_num.h"
#include "tape/tape.h"

#define NLINK 3
#define NX (2 * NLINK)

/* ---- the counting allocator ------------------------------------------ */

typedef struct block {
    void *p;
    size_t size;
} block;

typedef struct counter {
    long n_alloc;     /* allocation requests so far (new_size > 0) */
    long fail_at;     /* fail request number fail_at (0: never) */
    bool persistent;  /* also fail every later request */
    long n_failed;    /* requests failed */
    size_t live;      /* bytes in live blocks */
    long bad_size;    /* frees or reallocs that reported a wrong size */
    long bad_ptr;     /* frees or reallocs of unknown pointers */
    block *blocks;    /* live blocks (plain malloc, not counted) */
    size_t n_blocks, cap_blocks;
} counter;

static long find_block(const counter *c, const void *p)
{
    size_t i;
    for (i = 0; i < c->n_blocks; i++)
        if (c->blocks[i].p == p)
            return (long)i;
    return -1;
}

static bool add_block(counter *c, void *p, size_t size)
{
    if (c->n_blocks == c->cap_blocks) {
        size_t ncap = c->cap_blocks ? 2 * c->cap_blocks : 64;
        block *nb = realloc(c->blocks, ncap * sizeof *nb);
        if (!nb)
            return false;
        c->blocks = nb;
        c->cap_blocks = ncap;
    }
    c->blocks[c->n_blocks].p = p;
    c->blocks[c->n_blocks].size = size;
    c->n_blocks++;
    c->live += size;
    return true;
}

static void remove_block(counter *c, long i)
{
    c->live -= c->blocks[i].size;
    c->blocks[i] = c->blocks[--c->n_blocks];
}

static void *counting_alloc(void *ud, void *ptr, size_t old_size,
                            size_t new_size)
{
    counter *c = ud;
    long i = -1;
    void *q;
    if (ptr) {
        i = find_block(c, ptr);
        if (i < 0)
            c->bad_ptr++;
        else if (c->blocks[i].size != old_size)
            c->bad_size++;
    } else if (old_size != 0) {
        c->bad_size++; /* a new block has no old size */
    }
    if (new_size == 0) {
        if (i >= 0)
            remove_block(c, i);
        free(ptr);
        return NULL;
    }
    c->n_alloc++;
    if (c->fail_at > 0 &&
        (c->n_alloc == c->fail_at ||
         (c->persistent && c->n_alloc > c->fail_at))) {
        c->n_failed++;
        return NULL; /* ptr stays valid and owned by the caller */
    }
    q = realloc(ptr, new_size);
    if (!q)
        return NULL;
    if (i >= 0)
        remove_block(c, i);
    if (!add_block(c, q, new_size)) {
        fprintf(stderr, "test_alloc_fail: bookkeeping out of memory\n");
        exit(2);
    }
    return q;
}

/* ---- the scenario ----------------------------------------------------- */

static const double X[NX] = {0.3, -1.2, 2.5, 0.7, -0.4, 1.1};

/* Everything the scenario computes. */
typedef struct results {
    double L, dLdq[NLINK], M[NLINK * NLINK], h[NLINK];
    double H[NX * NX], g[NX], J[3 * NX], y[3];
    double yev[3], Lt, dLdqt[NLINK], Mt[NLINK * NLINK], ht[NLINK];
} results;

/* Did a call fail cleanly? Expects TP_ERR_NOMEM; reports otherwise. */
static bool nomem(int rc, const char *what, long n)
{
    if (rc == TP_OK)
        return false;
    if (rc != TP_ERR_NOMEM)
        CHECK_FAIL_("fail at %ld: %s returned %s, expected TP_ERR_NOMEM", n,
                    what, tp_status_name(rc));
    check_count_++;
    return true;
}

/* A failed run must leave its context in a sticky NOMEM state. */
static void sticky(const tp_rec *r, const char *what, long n)
{
    if (tp_rec_status(r) != TP_ERR_NOMEM || !tp_rec_errmsg(r)[0])
        CHECK_FAIL_("fail at %ld: after %s: status %s, message '%s'", n,
                    what, tp_status_name(tp_rec_status(r)),
                    tp_rec_errmsg(r));
    check_count_++;
}

/* Runs the scenario with allocator al; returns true if it completed,
 * false if it stopped at a (clean) allocation failure. n names the run. */
static bool scenario(const tp_allocator *al, long n, results *R)
{
    static const unsigned char grp[NX] = {0, 0, 0, 1, 1, 1};
    pendulum_chain pc = {NLINK, NULL, NULL, 9.81};
    tp_rec *r = NULL, *ev = NULL, *tu = NULL;
    tp_tape *T = NULL;
    tp_ws *ws = NULL;
    bool done = false;
    int rc;

    rc = tp_recorder_new(&r, NX, grp, al);
    if (nomem(rc, "tp_recorder_new", n)) {
        CHECK(r == NULL);
        goto out;
    }
    rc = tp_rec_run(r, NULL, pendulum_chain_record, &pc);
    if (nomem(rc, "tp_rec_run (recorder)", n)) {
        sticky(r, "tp_rec_run", n);
        /* a failed recording cannot be finished */
        CHECK_INT(tp_recorder_finish(r, &T), TP_ERR_NOMEM);
        CHECK(T == NULL);
        goto out;
    }
    rc = tp_recorder_finish(r, &T);
    if (nomem(rc, "tp_recorder_finish", n)) {
        CHECK(T == NULL);
        sticky(r, "tp_recorder_finish", n);
        goto out;
    }
    rc = tp_ws_new(&ws, T, 2, al);
    if (nomem(rc, "tp_ws_new", n)) {
        CHECK(ws == NULL);
        goto out;
    }
    /* sweeps never allocate */
    CHECK_INT(tp_lagrange(ws, X, 0, &R->L, R->dLdq, R->M, R->h), TP_OK);
    CHECK_INT(tp_hessian(ws, X, 0, R->H), TP_OK);
    CHECK_INT(tp_gradient(ws, X, 1, NULL, R->g), TP_OK);
    CHECK_INT(tp_jacobian(ws, X, 0, NX, R->y, R->J), TP_OK);

    rc = tp_evaluator_new(&ev, NX, al);
    if (nomem(rc, "tp_evaluator_new", n)) {
        CHECK(ev == NULL);
        goto out;
    }
    rc = tp_rec_set_param(ev, "m2", 1.0);
    if (nomem(rc, "tp_rec_set_param", n))
        goto out;
    rc = tp_rec_run(ev, X, pendulum_chain_record, &pc);
    if (nomem(rc, "tp_rec_run (evaluator)", n)) {
        sticky(ev, "tp_rec_run (evaluator)", n);
        goto out;
    }
    CHECK_INT(tp_rec_output_value(ev, 0, &R->yev[0]), TP_OK);
    CHECK_INT(tp_rec_output_value(ev, 1, &R->yev[1]), TP_OK);
    CHECK_INT(tp_rec_output_value(ev, 2, &R->yev[2]), TP_OK);

    rc = tp_tuple_new(&tu, NX, al);
    if (nomem(rc, "tp_tuple_new", n)) {
        CHECK(tu == NULL);
        goto out;
    }
    rc = tp_rec_run(tu, X, pendulum_chain_record, &pc);
    if (nomem(rc, "tp_rec_run (tuple)", n)) {
        sticky(tu, "tp_rec_run (tuple)", n);
        goto out;
    }
    CHECK_INT(tp_tuple_lagrange(tu, 0, &R->Lt, R->dLdqt, R->Mt, R->ht),
              TP_OK);
    /* a second run reuses the buffers; it may still allocate names */
    rc = tp_rec_run(tu, X, pendulum_chain_record, &pc);
    if (nomem(rc, "tp_rec_run (tuple, again)", n)) {
        sticky(tu, "tp_rec_run (tuple, again)", n);
        goto out;
    }
    done = true;
out:
    tp_rec_free(&tu);
    tp_rec_free(&ev);
    tp_ws_free(&ws);
    tp_tape_free(&T);
    tp_rec_free(&r);
    return done;
}

static void compare(const char *ctx, const results *a, const results *b)
{
    CHECK_SAME(ctx, &a->L, &b->L, 1);
    CHECK_SAME(ctx, a->dLdq, b->dLdq, NLINK);
    CHECK_SAME(ctx, a->M, b->M, NLINK * NLINK);
    CHECK_SAME(ctx, a->h, b->h, NLINK);
    CHECK_SAME(ctx, a->H, b->H, NX * NX);
    CHECK_SAME(ctx, a->g, b->g, NX);
    CHECK_SAME(ctx, a->J, b->J, 3 * NX);
    CHECK_SAME(ctx, a->y, b->y, 3);
    CHECK_SAME(ctx, a->yev, b->yev, 3);
    CHECK_SAME(ctx, &a->Lt, &b->Lt, 1);
    CHECK_SAME(ctx, a->dLdqt, b->dLdqt, NLINK);
    CHECK_SAME(ctx, a->Mt, b->Mt, NLINK * NLINK);
    CHECK_SAME(ctx, a->ht, b->ht, NLINK);
}

static void run_mode(bool persistent, const results *ref, long n_total)
{
    long n;
    int n_completed = 0;
    for (n = 1; n <= n_total + 1; n++) {
        counter c;
        tp_allocator al;
        results R;
        bool done;
        char ctx[64];
        memset(&c, 0, sizeof c);
        c.fail_at = n;
        c.persistent = persistent;
        al.fn = counting_alloc;
        al.ud = &c;
        memset(&R, 0, sizeof R);
        done = scenario(&al, n, &R);
        snprintf(ctx, sizeof ctx, "%s fail at %ld",
                 persistent ? "persistent" : "one-shot", n);
        if (c.live != 0 || c.n_blocks != 0)
            CHECK_FAIL_("%s: %zu bytes in %zu blocks leaked", ctx, c.live,
                        c.n_blocks);
        if (c.bad_size || c.bad_ptr)
            CHECK_FAIL_("%s: %ld frees with a wrong size, %ld of unknown "
                        "pointers", ctx, c.bad_size, c.bad_ptr);
        check_count_ += 2;
        /* the run stopped exactly when an allocation failed */
        CHECK_INT(done, c.n_failed == 0);
        if (done) {
            n_completed++;
            compare(ctx, &R, ref);
        }
        free(c.blocks);
    }
    /* only the run past the last allocation completes */
    CHECK_INT(n_completed, 1);
}

int main(void)
{
    counter c;
    tp_allocator al;
    results ref;

    /* an undisturbed run: the reference results and the number of
     * allocations to walk through */
    memset(&c, 0, sizeof c);
    al.fn = counting_alloc;
    al.ud = &c;
    memset(&ref, 0, sizeof ref);
    CHECK(scenario(&al, 0, &ref));
    CHECK_INT(c.live, 0);
    CHECK_INT(c.bad_size + c.bad_ptr, 0);
    CHECK(c.n_alloc > 20);
    printf("scenario: %ld allocations\n", c.n_alloc);
    free(c.blocks);

    run_mode(false, &ref, c.n_alloc);
    run_mode(true, &ref, c.n_alloc);
    CHECK_DONE();
}
