/* alloc_count.c - counts every heap allocation of the process by
 * interposing malloc, calloc, realloc and the aligned allocators (the
 * executable's definitions take precedence over the C library's for every
 * shared library too, libtape included). The real work is glibc's
 * __libc_* entry points. Linked into benchmarks only: it is how "zero heap
 * allocations per sweep" is measured, independently of libtape's own
 * allocator hook. */
#include <stddef.h>

#include "bench_util.h"

void *__libc_malloc(size_t size);
void *__libc_calloc(size_t n, size_t size);
void *__libc_realloc(void *p, size_t size);
void *__libc_memalign(size_t align, size_t size);
void __libc_free(void *p);

void *malloc(size_t size);
void *calloc(size_t n, size_t size);
void *realloc(void *p, size_t size);
void free(void *p);
int posix_memalign(void **out, size_t align, size_t size);
void *aligned_alloc(size_t align, size_t size);

static unsigned long long n_alloc;

unsigned long long bench_alloc_count(void) { return n_alloc; }

void *malloc(size_t size)
{
    n_alloc++;
    return __libc_malloc(size);
}

void *calloc(size_t n, size_t size)
{
    n_alloc++;
    return __libc_calloc(n, size);
}

void *realloc(void *p, size_t size)
{
    n_alloc++;
    return __libc_realloc(p, size);
}

int posix_memalign(void **out, size_t align, size_t size)
{
    void *p;
    n_alloc++;
    p = __libc_memalign(align, size);
    if (!p)
        return 12; /* ENOMEM */
    *out = p;
    return 0;
}

void *aligned_alloc(size_t align, size_t size)
{
    n_alloc++;
    return __libc_memalign(align, size);
}

void free(void *p) { __libc_free(p); }
