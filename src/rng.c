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

double polyc__rng_uniform(polyc__rng *r)
{
    return (double)(polyc__rng_next(r) >> 11) * (1.0 / 9007199254740992.0);
}

/* Box-Muller; one value per call keeps the state simple. */
double polyc__rng_normal(polyc__rng *r)
{
    double u1 = polyc__rng_uniform(r);
    double u2 = polyc__rng_uniform(r);
    if (u1 < 1e-300)
        u1 = 1e-300;
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}
