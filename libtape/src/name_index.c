/* name_index.c - a hash index over a recording context's list of names
 * (its parameters, its outputs), so that a model with tens of thousands of
 * them is checked for duplicates and searched in constant time per name,
 * not in time linear in the names declared before (quadratic in all).
 * Short lists keep their linear scan: the index only starts at
 * TP_INDEX_MIN names, so small models run exactly as they did.
 *
 * The index covers the first `count` entries of the list; a lookup adds
 * the entries pushed since (the list only grows within a run), and a new
 * run (the list emptied) resets it. Slots hold entry index + 1 (0 empty),
 * open addressing with linear probing, at most half full. */
#include <stdint.h>
#include <string.h>

#include "tape_internal.h"

static uint32_t hash_name(const char *s)
{
    uint32_t h = 2166136261u;
    while (*s)
        h = (h ^ (unsigned char)*s++) * 16777619u;
    return h ^ (h >> 15);
}

void tp__index_reset(tp_name_index *ix)
{
    if (ix->slot && ix->count > 0)
        memset(ix->slot, 0, ix->cap * sizeof *ix->slot);
    ix->count = 0;
}

void tp__index_free(const tp_allocator *al, tp_name_index *ix)
{
    tp__free(al, ix->slot, ix->cap * sizeof *ix->slot);
    memset(ix, 0, sizeof *ix);
}

static void insert(tp_name_index *ix, const tp_named *v, size_t i)
{
    size_t h = hash_name(v[i].name) & (ix->cap - 1);
    while (ix->slot[h] != 0)
        h = (h + 1) & (ix->cap - 1);
    ix->slot[h] = (uint32_t)(i + 1);
}

/* Room for n entries at most half full: the table rebuilt larger. */
static int reserve(const tp_allocator *al, tp_name_index *ix,
                   const tp_named *v, size_t n)
{
    size_t cap = ix->cap ? ix->cap : 64, i;
    uint32_t *slot;
    if (2 * n <= ix->cap)
        return 0;
    while (2 * n > cap)
        cap *= 2;
    if (cap > UINT32_MAX || !(slot = tp__alloc(al, cap * sizeof *slot)))
        return -1;
    memset(slot, 0, cap * sizeof *slot);
    tp__free(al, ix->slot, ix->cap * sizeof *ix->slot);
    ix->slot = slot;
    ix->cap = cap;
    for (i = 0; i < ix->count; i++)
        insert(ix, v, i);
    return 0;
}

tp_named *tp__index_find(const tp_allocator *al, tp_name_index *ix,
                         tp_named *v, size_t n, const char *name)
{
    size_t i, h;
    if (n < TP_INDEX_MIN || ix->count > n ||
        reserve(al, ix, v, n) != 0) {
        /* short, or (out of memory for the table) the plain scan */
        for (i = 0; i < n; i++)
            if (strcmp(v[i].name, name) == 0)
                return &v[i];
        return NULL;
    }
    for (; ix->count < n; ix->count++)
        insert(ix, v, ix->count);
    for (h = hash_name(name) & (ix->cap - 1); ix->slot[h] != 0;
         h = (h + 1) & (ix->cap - 1))
        if (strcmp(v[ix->slot[h] - 1].name, name) == 0)
            return &v[ix->slot[h] - 1];
    return NULL;
}
