/* fmath.c - sine, cosine, arc tangent and logarithm in single precision.
 * Takes: floats (angles in radians within a few thousand turns of 0).
 * Gives: the function to within about an ulp, computed in float only; NaN
 * for an angle that is not finite or past 1e6 rad, and for atan2 of
 * anything not finite.
 * Why not libm's sinf, cosf, atan2f, logf: newlib's (the Cortex-M
 * toolchain's) compute in double, a software call per operation on a
 * single-precision FPU; these keep the target's FPU doing the work, and
 * host and target compute the same bits. */
#include "internal.h"

/* the external definitions of internal.h's and stages.h's inline functions
 * (C99: one copy where a caller does not inline them, as at -Os) */
extern inline int32_t polyc__floori(float x);
extern inline int polyc__cell_index(int32_t ix, int32_t iy);

#include <math.h> /* NAN only */
#include <string.h>

/* pi/2 in three parts (Cody and Waite): k * PIO2_1 is exact for |k| < 2^12 */
#define PIO2_1 1.5703125f
#define PIO2_2 4.8382679233e-04f
#define PIO2_3 2.5632829193e-12f
#define TWO_OVER_PI 6.366197467e-01f

/* Taylor series on |r| <= pi/4: the first term left out is below 2e-9 */
static float sin_kernel(float r)
{
    float z = r * r;
    return r + r * z * (-1.6666667e-1f + z * (8.3333333e-3f + z * (-1.9841270e-4f + z * 2.7557319e-6f)));
}

static float cos_kernel(float r)
{
    float z = r * r;
    return 1.0f + z * (-0.5f + z * (4.1666667e-2f + z * (-1.3888889e-3f + z * (2.4801587e-5f +
                                                                               z * -2.7557319e-7f))));
}

void polyc__sincosf(float a, float *s, float *c)
{
    if (!(a >= -1e6f && a <= 1e6f)) { /* NaN, infinite or past a million radians: NaN */
        *s = *c = NAN;
        return;
    }
    float kf = a * TWO_OVER_PI;
    int32_t k = (int32_t)(kf < 0.0f ? kf - 0.5f : kf + 0.5f);
    float fk = (float)k;
    float r = ((a - fk * PIO2_1) - fk * PIO2_2) - fk * PIO2_3;
    float sr = sin_kernel(r), cr = cos_kernel(r);
    switch (k & 3) {
    case 0: *s = sr; *c = cr; break;
    case 1: *s = cr; *c = -sr; break;
    case 2: *s = -sr; *c = -cr; break;
    default: *s = -cr; *c = sr; break;
    }
}

float polyc__sinf(float a)
{
    float s, c;
    polyc__sincosf(a, &s, &c);
    return s;
}

float polyc__cosf(float a)
{
    float s, c;
    polyc__sincosf(a, &s, &c);
    return c;
}

/* atan(k / 8), k = 0..8 */
static const float atan_eighths[9] = {
    0.0f,         1.243549945e-01f, 2.449786631e-01f, 3.587706703e-01f, 4.636476090e-01f,
    5.585993153e-01f, 6.435011088e-01f, 7.188299996e-01f, 7.853981634e-01f,
};

/* atan(t), 0 <= t <= 1: about the nearest k / 8, where |u| <= 1/16 and the
 * series' first term left out is below 2e-12 */
static float atan_unit(float t)
{
    int32_t k = (int32_t)(t * 8.0f + 0.5f);
    float c = (float)k * 0.125f;
    float u = (t - c) / (1.0f + t * c);
    float z = u * u;
    return atan_eighths[k] + u * (1.0f + z * (-3.3333333e-1f + z * (2.0e-1f + z * -1.4285714e-1f)));
}

float polyc__atan2f(float y, float x)
{
    float ax = x < 0.0f ? -x : x, ay = y < 0.0f ? -y : y;
    if (!(ax <= 3.4e38f && ay <= 3.4e38f))
        return NAN; /* (NaN or infinite: the library's arguments are finite) */
    if (ax == 0.0f && ay == 0.0f)
        return 0.0f;
    float a = ay <= ax ? atan_unit(ay / ax) : 1.5707963268f - atan_unit(ax / ay);
    if (x < 0.0f)
        a = 3.1415926536f - a;
    return y < 0.0f ? -a : a;
}

/* log(x), x > 0 and finite: x = m 2^e with m in [sqrt(1/2), sqrt(2)),
 * log m = 2 atanh(s), s = (m - 1) / (m + 1), |s| < 0.172 */
float polyc__logf(float x)
{
    uint32_t bits;
    memcpy(&bits, &x, sizeof bits);
    int32_t e = (int32_t)((bits >> 23) & 0xffu) - 127;
    bits = (bits & 0x007fffffu) | 0x3f800000u; /* m in [1, 2) */
    float m;
    memcpy(&m, &bits, sizeof m);
    if (m > 1.41421356f) {
        m *= 0.5f;
        e++;
    }
    float s = (m - 1.0f) / (m + 1.0f), z = s * s;
    float lm = 2.0f * s * (1.0f + z * (3.3333333e-1f + z * (2.0e-1f + z * (1.4285714e-1f + z * 1.1111111e-1f))));
    float fe = (float)e;
    return fe * 6.931471825e-01f + (lm + fe * -1.904654323e-09f);
}
