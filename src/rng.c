/* rng.c - the library's own PRNG: splitmix64, so that the same seed gives
 * the same map on every platform (no rand(), no global state). */
#include "internal.h"

#include <math.h>

uint64_t polyc__rng_next(polyc__rng *r)
{
    uint64_t z = (r->state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

float polyc__rng_uniform(polyc__rng *r)
{
    /* 24 bits, a float's mantissa: exact, and a 32-bit conversion (one
     * instruction on an FPU; a 64-bit one is a software call) */
    return (float)(uint32_t)(polyc__rng_next(r) >> 40) * (1.0f / 16777216.0f);
}

/* Box-Muller; one value per call keeps the state simple. */
float polyc__rng_normal(polyc__rng *r)
{
    float u1 = polyc__rng_uniform(r);
    float u2 = polyc__rng_uniform(r);
    if (u1 <= 0.0f)
        u1 = 1.0f / 33554432.0f; /* 2^-25: half the smallest step */
    return sqrtf(-2.0f * polyc__logf(u1)) * polyc__cosf(6.283185307179586f * u2);
}
