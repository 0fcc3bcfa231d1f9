/* codegen_loops.c - a sweep's statements, collected one per op, written
 * as chunk functions in which repeated runs become loops.
 *
 * A chain's links, the members of an indexed family and whatever else a
 * recording repeats give runs of statements that are the same text but
 * for their integer literals (slots, constants' indices, ends), which
 * shift by a constant stride from one repetition to the next. Each
 * statement is split into its template (the text with every integer
 * literal taken out) and its integers. A run of R repetitions of a body
 * of p statements whose templates repeat statement for statement is
 * written once as
 *
 *     for (long k_ = 0; k_ < R; k_++) { body }
 *
 * where each integer of the body is a literal (the same in every
 * repetition), base + stride * k_ (an arithmetic sequence), or an entry
 * of a table of R values (anything else; a body needing more than a
 * quarter of its integers from tables stays straight-line). The loop
 * runs the same statements, with the same values, in the same order as
 * the straight-line code: results are equal bit for bit.
 *
 * The search is greedy, left to right: at each statement the candidate
 * periods are the distances to the next few statements that start the
 * same window of templates, and the one covering the most statements
 * wins. Statements marked fixed (labels a switch jumps to) stay outside
 * loops.
 *
 * The chunks: as codegen.c's, functions of about CHUNK statements of
 * text; a loop counts as its body, a body larger than a chunk is a
 * chunk of its own. */
#include <stdlib.h>
#include <string.h>

#include "codegen.h"

#define CHUNK 256u
#define WINDOW 8u          /* templates that must match to propose a period */
#define CANDIDATES 12      /* periods tried at one statement */
#define MAX_PERIOD 8192u   /* longest body */
#define MIN_COVER 16u      /* fewest statements a loop replaces */

/* A literal starts at p (a digit): not part of a name or a floating
 * literal. Its length, the 'u' suffix included, in *len. */
static bool int_at(const char *s, size_t p, size_t n, size_t *len)
{
    size_t q = p;
    if (p > 0) {
        const char c = s[p - 1];
        if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
            (c >= '0' && c <= '9') || c == '_' || c == '.')
            return false;
    }
    while (q < n && s[q] >= '0' && s[q] <= '9')
        q++;
    if (q < n && (s[q] == '.' || s[q] == 'x' || s[q] == 'X' ||
                  s[q] == 'e' || s[q] == 'E' || s[q] == 'p'))
        return false;
    if (q < n && s[q] == 'u')
        q++;
    if (q < n && ((s[q] >= 'a' && s[q] <= 'z') ||
                  (s[q] >= 'A' && s[q] <= 'Z') || s[q] == '_'))
        return false;
    if (q - p > 9) /* beyond what a slot can be: keep as text */
        return false;
    *len = q - p;
    return true;
}

void tp__seq_close(tp_seq *s, bool fixed)
{
    if (s->failed || s->text.failed)
        return;
    if (s->n == s->cap) {
        const uint32_t cap = s->cap ? 2 * s->cap : 256;
        size_t *e = realloc(s->end, cap * sizeof *e);
        unsigned char *f;
        if (!e) {
            s->failed = true;
            return;
        }
        s->end = e;
        f = realloc(s->fixed, cap);
        if (!f) {
            s->failed = true;
            return;
        }
        s->fixed = f;
        if (s->nstrips) {
            uint32_t *h = realloc(s->hi, cap * sizeof *h);
            if (!h) {
                s->failed = true;
                return;
            }
            s->hi = h;
        }
        s->cap = cap;
    }
    s->end[s->n] = s->text.len;
    s->fixed[s->n] = fixed;
    if (s->nstrips)
        s->hi[s->n] = s->next_hi;
    s->n++;
}

void tp__seq_pair(tp_seq *s, uint32_t a, uint32_t b)
{
    if (s->failed)
        return;
    if (s->npairs == s->pcap) {
        const size_t cap = s->pcap ? 2 * s->pcap : 256;
        uint32_t *p = realloc(s->pairs, 2 * cap * sizeof *p);
        if (!p) {
            s->failed = true;
            return;
        }
        s->pairs = p;
        s->pcap = cap;
    }
    s->pairs[2 * s->npairs] = a;
    s->pairs[2 * s->npairs + 1] = b;
    s->npairs++;
}

void tp__seq_free(tp_seq *s)
{
    tp__sbuf_free(&s->text);
    free(s->end);
    free(s->fixed);
    free(s->hi);
    free(s->pairs);
    memset(s, 0, sizeof *s);
}

/* ---- templates --------------------------------------------------------- */

typedef struct parsed {
    const tp_seq *s;
    uint32_t *tid;    /* template id of each statement */
    size_t *ioff;     /* first integer of statement k in ints */
    long *ints;       /* the integers of every statement, in order */
    size_t nints;
} parsed;

static size_t stmt_start(const tp_seq *s, uint32_t k)
{
    return k ? s->end[k - 1] : 0;
}

static uint64_t hash_bytes(uint64_t h, const void *p, size_t n)
{
    const unsigned char *c = p;
    size_t i;
    for (i = 0; i < n; i++)
        h = (h ^ c[i]) * 1099511628211ull;
    return h;
}

/* Split every statement; templates get ids by hashing (a 64-bit hash of
 * the template text, then the exact text compared on collision). */
static int parse(const tp_seq *s, parsed *P)
{
    const uint32_t n = s->n;
    size_t cap = 1024, k, hcap = 64;
    uint64_t *hh = NULL;
    uint32_t *hid = NULL, *rep = NULL, nt = 0;
    int st = TP_OK;
    memset(P, 0, sizeof *P);
    P->s = s;
    while (hcap < 2 * (size_t)n + 2)
        hcap *= 2;
    P->tid = malloc(((size_t)n + 1) * sizeof *P->tid);
    P->ioff = malloc(((size_t)n + 1) * sizeof *P->ioff);
    P->ints = malloc(cap * sizeof *P->ints);
    hh = malloc(hcap * sizeof *hh);
    hid = malloc(hcap * sizeof *hid);
    rep = malloc(((size_t)n + 1) * sizeof *rep);
    if (!P->tid || !P->ioff || !P->ints || !hh || !hid || !rep) {
        st = TP_ERR_NOMEM;
        goto done;
    }
    for (k = 0; k < hcap; k++)
        hid[k] = UINT32_MAX;
    for (k = 0; k < n; k++) {
        const char *t = s->text.p;
        const size_t a = stmt_start(s, (uint32_t)k), e = s->end[k];
        size_t p = a, len, slot;
        uint64_t h = 1469598103934665603ull;
        P->ioff[k] = P->nints;
        while (p < e) {
            if (t[p] >= '0' && t[p] <= '9' && int_at(t, p, e, &len)) {
                if (P->nints == cap) {
                    long *ni = realloc(P->ints, 2 * cap * sizeof *ni);
                    if (!ni) {
                        st = TP_ERR_NOMEM;
                        goto done;
                    }
                    P->ints = ni;
                    cap *= 2;
                }
                P->ints[P->nints++] = strtol(t + p, NULL, 10);
                h = hash_bytes(h, t[p + len - 1] == 'u' ? "\1u" : "\1",
                               t[p + len - 1] == 'u' ? 2 : 1);
                p += len;
            } else {
                const size_t q = p;
                while (p < e && !(t[p] >= '0' && t[p] <= '9'))
                    p++;
                if (p == q) { /* a digit inside a name or literal */
                    while (p < e && t[p] >= '0' && t[p] <= '9')
                        p++;
                }
                h = hash_bytes(h, t + q, p - q);
            }
        }
        /* intern h: the same hash is taken as the same template (a
         * statement's template is checked against its id's first
         * statement below) */
        for (slot = (size_t)(h & (hcap - 1));; slot = (slot + 1) & (hcap - 1)) {
            if (hid[slot] == UINT32_MAX) {
                hid[slot] = nt;
                hh[slot] = h;
                rep[nt] = (uint32_t)k;
                P->tid[k] = nt++;
                break;
            }
            if (hh[slot] == h) {
                P->tid[k] = hid[slot];
                break;
            }
        }
    }
    P->ioff[n] = P->nints;
done:
    free(hh);
    free(hid);
    free(rep);
    return st;
}

/* Statements a and b are the same template: same id and same integer
 * count, and the same text outside the integers (a hash collision would
 * show here). */
static bool same_template(const parsed *P, uint32_t a, uint32_t b)
{
    const tp_seq *s = P->s;
    const char *t = s->text.p;
    size_t pa = stmt_start(s, a), pb = stmt_start(s, b);
    const size_t ea = s->end[a], eb = s->end[b];
    size_t la, lb;
    if (P->tid[a] != P->tid[b] ||
        P->ioff[a + 1] - P->ioff[a] != P->ioff[b + 1] - P->ioff[b])
        return false;
    while (pa < ea && pb < eb) {
        const bool ia = t[pa] >= '0' && t[pa] <= '9' && int_at(t, pa, ea, &la);
        const bool ib = t[pb] >= '0' && t[pb] <= '9' && int_at(t, pb, eb, &lb);
        if (ia != ib)
            return false;
        if (ia) {
            if ((t[pa + la - 1] == 'u') != (t[pb + lb - 1] == 'u'))
                return false;
            pa += la;
            pb += lb;
        } else {
            if (t[pa] != t[pb])
                return false;
            pa++;
            pb++;
        }
    }
    return pa == ea && pb == eb;
}

/* ---- the plan ---------------------------------------------------------- */

typedef struct item {
    uint32_t at, p, reps; /* statements at .. at + p * reps - 1; p = 0 or
                             reps = 1: one statement */
} item;

/* How many repetitions of the body at i, p long, follow: templates equal
 * statement for statement, no fixed statement. */
static uint32_t count_reps(const parsed *P, uint32_t i, uint32_t p,
                           uint32_t n)
{
    uint32_t r = 1, j;
    for (j = 0; j < p; j++)
        if (P->s->fixed[i + j])
            return 1;
    while (i + (r + 1) * (uint64_t)p <= n) {
        const uint32_t b = i + r * p;
        for (j = 0; j < p; j++)
            if (P->tid[b + j] != P->tid[i + j] || P->s->fixed[b + j])
                return r;
        r++;
    }
    return r;
}

/* The integers of the loop at i (body p, reps r) needing a table, or
 * UINT32_MAX when the body's templates differ after all. */
static size_t tables_needed(const parsed *P, uint32_t i, uint32_t p,
                            uint32_t r, size_t *total)
{
    size_t need = 0, q;
    uint32_t j, k;
    for (j = 0; j < p; j++)
        for (k = 1; k < r; k++)
            if (!same_template(P, i + j, i + k * p + j))
                return SIZE_MAX;
    *total = P->ioff[i + p] - P->ioff[i];
    for (q = 0; q < *total; q++) {
        const long x0 = P->ints[P->ioff[i] + q];
        const long d = r > 1 ? P->ints[P->ioff[i + p] + q] - x0 : 0;
        for (k = 2; k < r; k++)
            if (P->ints[P->ioff[i + k * p] + q] != x0 + (long)k * d)
                break;
        if (k < r)
            need++;
    }
    return need;
}

/* The plan: items covering the statements in order. */
static int plan(const parsed *P, item **out, uint32_t *nout)
{
    const uint32_t n = P->s->n;
    uint64_t *wh = NULL;
    uint32_t *nxt = NULL, *head = NULL, i, ni = 0;
    size_t hcap = 64, k;
    item *it = NULL;
    int st = TP_OK;
    while (hcap < 2 * (size_t)n + 2)
        hcap *= 2;
    wh = malloc(((size_t)n + 1) * sizeof *wh);
    nxt = malloc(((size_t)n + 1) * sizeof *nxt);
    head = malloc(hcap * 2 * sizeof *head);
    it = malloc(((size_t)n + 1) * sizeof *it);
    if (!wh || !nxt || !head || !it) {
        st = TP_ERR_NOMEM;
        goto done;
    }
    /* the window of templates starting at each statement */
    for (i = 0; i < n; i++) {
        uint64_t h = 1469598103934665603ull;
        uint32_t j;
        for (j = i; j < i + WINDOW && j < n; j++)
            h = hash_bytes(h, &P->tid[j], sizeof P->tid[j]);
        wh[i] = h;
    }
    /* nxt[i]: the next statement with the same window (hash table of the
     * last position seen, filled from the end) */
    for (k = 0; k < 2 * hcap; k++)
        head[k] = UINT32_MAX;
    for (i = n; i-- > 0;) {
        size_t slot = (size_t)(wh[i] & (hcap - 1));
        for (;; slot = (slot + 1) & (hcap - 1)) {
            const uint32_t pos = head[2 * slot];
            if (pos == UINT32_MAX) {
                nxt[i] = UINT32_MAX;
                head[2 * slot] = i;
                head[2 * slot + 1] = i;
                break;
            }
            if (wh[pos] == wh[i]) {
                nxt[i] = head[2 * slot + 1];
                head[2 * slot + 1] = i;
                break;
            }
        }
    }
    for (i = 0; i < n;) {
        uint32_t best_p = 0, best_r = 1, best_skip = 0, j = nxt[i], m;
        int c;
        for (c = 0; c < CANDIDATES && j != UINT32_MAX && j - i <= MAX_PERIOD;
             c++, j = nxt[j]) {
            const uint32_t p = j - i, r = count_reps(P, i, p, n);
            size_t total = 0, tab;
            uint32_t skip = 0;
            if (r < 2 || (uint64_t)p * r < MIN_COVER ||
                (uint64_t)p * r <= (uint64_t)best_p * best_r)
                continue;
            tab = tables_needed(P, i, p, r, &total);
            if (tab == SIZE_MAX)
                continue;
            /* the first repetition often differs (a chain's first link
             * hangs from the ground): without it, strides may do where
             * it needed tables */
            if (tab > 0 && r >= 3 && (uint64_t)p * (r - 1) >= MIN_COVER) {
                size_t t2 = 0, tab2 = tables_needed(P, i + p, p, r - 1, &t2);
                if (tab2 == 0) {
                    tab = 0;
                    skip = 1;
                }
            }
            if (4 * tab > total)
                continue;
            best_p = p;
            best_r = r;
            best_skip = skip;
        }
        /* statements before the loop (a skipped repetition) one by one */
        for (m = 0; m < (best_p ? best_skip * best_p : 1); m++) {
            it[ni].at = i + m;
            it[ni].p = 1;
            it[ni].reps = 1;
            ni++;
        }
        if (!best_p) {
            i++;
            continue;
        }
        it[ni].at = i + best_skip * best_p;
        it[ni].p = best_p;
        it[ni].reps = best_r - best_skip;
        ni++;
        i += best_p * best_r;
    }
    *out = it;
    *nout = ni;
    it = NULL;
done:
    free(wh);
    free(nxt);
    free(head);
    free(it);
    return st;
}

/* ---- writing ----------------------------------------------------------- */

/* Statement k with its integers replaced by expr(q) for integer q of the
 * body (loop) or copied (straight). */
static void write_stmt(const parsed *P, tp_sbuf *b, uint32_t k,
                       const item *it, uint32_t j, const unsigned *tab_id)
{
    const tp_seq *s = P->s;
    const char *t = s->text.p;
    const size_t a = stmt_start(s, k), e = s->end[k];
    size_t p = a, q = 0, len;
    if (it->reps < 2) {
        tp__sbuf_putn(b, t + a, e - a);
        return;
    }
    while (p < e) {
        if (t[p] >= '0' && t[p] <= '9' && int_at(t, p, e, &len)) {
            const size_t idx = P->ioff[k] + q;
            const long x0 = P->ints[idx];
            const long d =
                P->ints[P->ioff[it->at + it->p + j] + q] - x0;
            const unsigned tb = tab_id[P->ioff[k] - P->ioff[it->at] + q];
            if (tb)
                tp__sbuf_printf(b, "tb%u_[k_]", tb - 1);
            else if (d == 0)
                tp__sbuf_printf(b, "%ld", x0);
            else
                tp__sbuf_printf(b, "(%ld %c %ld * k_)", x0, d < 0 ? '-' : '+',
                                d < 0 ? -d : d);
            p += len;
            q++;
        } else {
            const size_t r = p;
            while (p < e && !(t[p] >= '0' && t[p] <= '9' && int_at(t, p, e, &len)))
                p++;
            tp__sbuf_putn(b, t + r, p - r);
        }
    }
}

/* Gates (tp_seq's hi): each unit (a loop's member, or a statement
 * outside loops) runs in strips s_ < uh[its first statement], the
 * largest bound of its statements, raised until every pair holds. */
static int gates(const tp_seq *s, const item *it, uint32_t ni, uint32_t **out)
{
    uint32_t *unit = malloc(((size_t)s->n + 1) * sizeof *unit);
    uint32_t *uh = calloc((size_t)s->n + 1, sizeof *uh);
    uint32_t k, m, j;
    size_t q;
    bool changed = true;
    if (!unit || !uh) {
        free(unit);
        free(uh);
        return TP_ERR_NOMEM;
    }
    for (k = 0; k < ni; k++)
        for (m = 0; m < (it[k].reps < 2 ? 1 : it[k].reps); m++)
            for (j = 0; j < it[k].p; j++) {
                const uint32_t st = it[k].at + m * it[k].p + j;
                unit[st] = it[k].reps < 2 ? st : it[k].at + m * it[k].p;
                if (s->hi[st] > uh[unit[st]])
                    uh[unit[st]] = s->hi[st];
            }
    while (changed) {
        changed = false;
        for (q = 0; q < s->npairs; q++) {
            const uint32_t a = unit[s->pairs[2 * q]],
                           b = unit[s->pairs[2 * q + 1]];
            if (uh[a] < uh[b]) {
                uh[a] = uh[b];
                changed = true;
            }
        }
    }
    free(unit);
    *out = uh;
    return TP_OK;
}

/* A statement outside loops, behind its gate (none where it runs in
 * every strip; nothing where it runs in none). */
static void write_single(const parsed *P, tp_sbuf *b, const item *it,
                         const uint32_t *uh)
{
    if (uh && uh[it->at] == 0)
        return;
    if (uh && uh[it->at] < P->s->nstrips)
        tp__sbuf_printf(b, "if (s_ < %u)\n", uh[it->at]);
    write_stmt(P, b, it->at, it, 0, NULL);
}

static int write_loop(const parsed *P, tp_sbuf *b, const item *it,
                      unsigned *ntab, const uint32_t *uh)
{
    const size_t i0 = P->ioff[it->at], total = P->ioff[it->at + it->p] - i0;
    unsigned *tab_id = calloc(total + 1, sizeof *tab_id);
    uint32_t j, k;
    size_t q, q2;
    if (!tab_id)
        return TP_ERR_NOMEM;
    tp__sbuf_puts(b, "{\n");
    for (q = 0; q < total; q++) {
        const long x0 = P->ints[i0 + q];
        const long d = P->ints[P->ioff[it->at + it->p] + q] - x0;
        for (k = 2; k < it->reps; k++)
            if (P->ints[P->ioff[it->at + k * it->p] + q] != x0 + (long)k * d)
                break;
        if (k == it->reps)
            continue;
        /* the same sequence as an earlier table of this loop: that one */
        for (q2 = 0; q2 < q; q2++) {
            if (!tab_id[q2])
                continue;
            for (k = 0; k < it->reps; k++)
                if (P->ints[P->ioff[it->at + k * it->p] + q2] !=
                    P->ints[P->ioff[it->at + k * it->p] + q])
                    break;
            if (k == it->reps)
                break;
        }
        if (q2 < q) {
            tab_id[q] = tab_id[q2];
            continue;
        }
        tab_id[q] = ++*ntab;
        tp__sbuf_printf(b, "static const unsigned tb%u_[%u] = {", *ntab - 1,
                        it->reps);
        for (k = 0; k < it->reps; k++)
            tp__sbuf_printf(b, "%ld%s", P->ints[P->ioff[it->at + k * it->p] + q],
                            k + 1 < it->reps ? ", " : "};\n");
    }
    if (uh) { /* the members' gates: a table where one does not run
               * in every strip */
        for (k = 0; k < it->reps; k++)
            if (uh[it->at + k * it->p] < P->s->nstrips)
                break;
        if (k < it->reps) {
            tp__sbuf_printf(b, "static const unsigned short tb%u_[%u] = {",
                            (*ntab)++, it->reps);
            for (k = 0; k < it->reps; k++)
                tp__sbuf_printf(b, "%u%s", uh[it->at + k * it->p],
                                k + 1 < it->reps ? ", " : "};\n");
            tp__sbuf_printf(b,
                            "for (long k_ = 0; k_ < %u; k_++) {\n"
                            "if (s_ >= tb%u_[k_])\n    continue;\n",
                            it->reps, *ntab - 1);
        } else
            tp__sbuf_printf(b, "for (long k_ = 0; k_ < %u; k_++) {\n",
                            it->reps);
    } else
        tp__sbuf_printf(b, "for (long k_ = 0; k_ < %u; k_++) {\n",
                        it->reps);
    for (j = 0; j < it->p; j++)
        write_stmt(P, b, it->at + j, it, j, tab_id);
    tp__sbuf_puts(b, "}\n}\n");
    free(tab_id);
    return TP_OK;
}

int tp__seq_emit(const tp_seq *s, tp_sbuf *b, bool loops, tp_seq_open open,
                 void *ctx, uint32_t **chunk_lo, unsigned *nchunks)
{
    parsed P;
    item *it = NULL;
    uint32_t ni = 0, k, *lo = NULL, *uh = NULL;
    unsigned nc = 0, ntab = 0;
    int st;
    *chunk_lo = NULL;
    *nchunks = 0;
    if (s->failed || s->text.failed)
        return TP_ERR_NOMEM;
    if ((st = parse(s, &P)) != TP_OK)
        goto done;
    if (loops) {
        if ((st = plan(&P, &it, &ni)) != TP_OK)
            goto done;
    } else {
        it = malloc(((size_t)s->n + 1) * sizeof *it);
        if (!it) {
            st = TP_ERR_NOMEM;
            goto done;
        }
        for (k = 0; k < s->n; k++) {
            it[k].at = k;
            it[k].p = 1;
            it[k].reps = 1;
        }
        ni = s->n;
    }
    if (s->nstrips && (st = gates(s, it, ni, &uh)) != TP_OK)
        goto done;
    lo = malloc(((size_t)ni + 1) * sizeof *lo);
    if (!lo) {
        st = TP_ERR_NOMEM;
        goto done;
    }
    if (!open) { /* inside the function being written */
        for (k = 0; k < ni; k++) {
            b->stmts += it[k].p;
            if (it[k].reps < 2)
                write_single(&P, b, &it[k], uh);
            else if ((st = write_loop(&P, b, &it[k], &ntab, uh)) != TP_OK)
                goto done;
        }
        st = b->failed ? TP_ERR_NOMEM : TP_OK;
        goto done;
    }
    for (k = 0; k < ni;) {
        /* a chunk: items while their bodies fit, at least one */
        uint32_t e = k, cost = 0, hi;
        while (e < ni && (e == k || cost + it[e].p <= CHUNK)) {
            cost += it[e].p;
            e++;
        }
        hi = e < ni ? it[e].at : s->n;
        lo[nc] = it[k].at;
        open(ctx, b, nc, it[k].at, hi);
        for (; k < e; k++) {
            b->stmts += it[k].p;
            if (it[k].reps < 2)
                write_single(&P, b, &it[k], uh);
            else if ((st = write_loop(&P, b, &it[k], &ntab, uh)) != TP_OK)
                goto done;
        }
        tp__sbuf_puts(b, TP_CHUNK_END);
        nc++;
    }
    *chunk_lo = lo;
    *nchunks = nc;
    lo = NULL;
    st = b->failed ? TP_ERR_NOMEM : TP_OK;
done:
    free(P.tid);
    free(P.ioff);
    free(P.ints);
    free(it);
    free(lo);
    free(uh);
    return st;
}
