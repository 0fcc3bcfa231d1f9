/* alloc.c - every allocation of libtape goes through one hook that is told
 * the old size (tp_allocator), so a caller can count, limit or fail
 * allocations; tests fail allocation number N for every N. Sizes are
 * checked for overflow before any multiplication reaches the allocator. */
#include <stdlib.h>
#include <string.h>

#include "tape_internal.h"

static void *default_alloc(void *ud, void *ptr, size_t old_size,
                           size_t new_size)
{
    (void)ud;
    (void)old_size;
    if (new_size == 0) {
        free(ptr);
        return NULL;
    }
    return realloc(ptr, new_size);
}

tp_allocator tp__allocator(const tp_allocator *al)
{
    tp_allocator d = {default_alloc, NULL};
    return (al && al->fn) ? *al : d;
}

size_t tp__mulsz(size_t a, size_t b)
{
    if (a != 0 && b > SIZE_MAX / a)
        return SIZE_MAX;
    return a * b;
}

void *tp__alloc(const tp_allocator *al, size_t size)
{
    if (size == 0 || size == SIZE_MAX)
        return NULL;
    return al->fn(al->ud, NULL, 0, size);
}

void *tp__calloc(const tp_allocator *al, size_t n, size_t size)
{
    size_t bytes = tp__mulsz(n, size);
    void *p;
    if (bytes == 0)
        bytes = 1; /* a valid, freeable pointer for empty arrays */
    /* the C library's calloc gets large blocks as fresh zero pages from
     * the system, without writing them (a workspace for n directions is
     * megabytes that a sweep may never touch) */
    if (al->fn == default_alloc && bytes != SIZE_MAX)
        return calloc(1, bytes);
    p = tp__alloc(al, bytes);
    if (p)
        memset(p, 0, bytes);
    return p;
}

void tp__free(const tp_allocator *al, void *p, size_t size)
{
    /* tp__calloc gives empty arrays one byte; report the same size back */
    if (p)
        al->fn(al->ud, p, size ? size : 1, 0);
}

int tp__grow(const tp_allocator *al, void **p, size_t elsize, size_t *cap,
             size_t need)
{
    size_t ncap, bytes;
    void *q;
    if (need <= *cap)
        return 0;
    ncap = *cap ? *cap : 16;
    while (ncap < need) {
        if (ncap > SIZE_MAX / 2)
            return -1;
        ncap *= 2;
    }
    bytes = tp__mulsz(ncap, elsize);
    if (bytes == SIZE_MAX)
        return -1;
    q = al->fn(al->ud, *p, *cap * elsize, bytes);
    if (!q)
        return -1;
    *p = q;
    *cap = ncap;
    return 0;
}

char *tp__strdup(const tp_allocator *al, const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = tp__alloc(al, n);
    if (d)
        memcpy(d, s, n);
    return d;
}

void tp__strfree(const tp_allocator *al, char *s)
{
    if (s)
        tp__free(al, s, strlen(s) + 1);
}
