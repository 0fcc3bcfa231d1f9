/* support_rng.h - a small deterministic PRNG for the tests (splitmix64), so
 * every run samples the same points on every platform; rand() is neither
 * portable in its sequence nor good enough. Header-only. */
#ifndef TESTS_SUPPORT_RNG_H
#define TESTS_SUPPORT_RNG_H

#include <stdint.h>

typedef struct rng {
    uint64_t s;
} rng;

static inline rng rng_seed(uint64_t seed)
{
    rng g;
    g.s = seed;
    return g;
}

static inline uint64_t rng_next(rng *g)
{
    uint64_t z = (g->s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1), 53 random bits. */
static inline double rng_unit(rng *g)
{
    return (double)(rng_next(g) >> 11) * (1.0 / 9007199254740992.0);
}

/* Uniform in [lo, hi). */
static inline double rng_range(rng *g, double lo, double hi)
{
    return lo + (hi - lo) * rng_unit(g);
}

/* Uniform integer in 0 .. n-1 (n > 0; the modulo bias is irrelevant here). */
static inline int rng_int(rng *g, int n)
{
    return (int)(rng_next(g) % (uint64_t)n);
}

#endif
