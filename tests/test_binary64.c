/* test_binary64.c - the boundary's double operations on the bits
 * (binary64.c) against the host's FPU, bit for bit: sums and differences
 * of random doubles over every exponent distance (cancellation, carries,
 * ties, subnormals, overflow), doubles narrowed to float (ties, float
 * subnormals, overflow) and floats widened, and the special values. The
 * FPU rounds to nearest, ties to even, as the library's code does. NaN
 * results are compared as NaN (their payloads are not kept). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <string.h>

#include "internal.h"

static uint64_t state = 0x9e3779b97f4a7c15u;

static uint64_t next64(void)
{
    /* xorshift64*: the test's own stream, the same on every platform */
    state ^= state >> 12;
    state ^= state << 25;
    state ^= state >> 27;
    return state * UINT64_C(2685821657736338717);
}

/* a random double: any sign, an exponent near `center` (within `spread`
 * of it, clamped to the finite range, subnormals included), a random
 * fraction, sometimes with its low bits cleared (exact sums and ties) */
static double random_double(int32_t center, int32_t spread)
{
    uint64_t r = next64();
    int32_t e = center + (int32_t)(next64() % (uint64_t)(2 * spread + 1)) - spread;
    e = e < 0 ? 0 : (e > 0x7fe ? 0x7fe : e);
    uint64_t frac = r & ((UINT64_C(1) << 52) - 1);
    if ((r >> 60) == 0)
        frac &= ~((UINT64_C(1) << (next64() % 52)) - 1);
    return polyc__double_of((r & (UINT64_C(1) << 63)) | ((uint64_t)e << 52) | frac);
}

static void same_double(double got, double want)
{
    if (isnan(want))
        assert_true(isnan(got));
    else
        assert_true(polyc__bits64(got) == polyc__bits64(want));
}

static void same_float(float got, float want)
{
    if (isnan(want))
        assert_true(isnan(got));
    else
        assert_true(polyc__bits32(got) == polyc__bits32(want));
}

static void check_pair(double a, double b)
{
    same_double(polyc__d_add(a, b), a + b);
    same_double(polyc__d_sub(a, b), a - b);
    same_float(polyc__d_to_f(polyc__d_sub(a, b)), (float)(a - b));
}

static void test_sums_every_distance(void **state_unused)
{
    (void)state_unused;
    /* exponent distances 0 .. 70 (beyond 53 one operand only rounds),
     * near 1 m, near the library's coordinates and at the range's ends */
    const int32_t centers[] = {1023, 1023 + 20, 1, 60, 0x7fe - 2, 1023 - 30};
    for (size_t c = 0; c < sizeof centers / sizeof centers[0]; c++)
        for (int32_t spread = 0; spread <= 70; spread += 5)
            for (int i = 0; i < 20000; i++)
                check_pair(random_double(centers[c], spread), random_double(centers[c], spread));
}

static void test_cancellation_and_ties(void **state_unused)
{
    (void)state_unused;
    for (int i = 0; i < 200000; i++) {
        double a = random_double(1023, 40);
        uint64_t u = polyc__bits64(a);
        /* neighbours a few ulps away, either sign: the differences cancel
         * to a few bits */
        double b = polyc__double_of(u + (next64() % 9) - 4);
        check_pair(a, b);
        check_pair(a, -b);
        /* a and half an ulp of it: a tie either way */
        double half = ldexp(1.0, ilogb(a) - 53);
        check_pair(a, half);
        check_pair(a, -half);
        check_pair(a, 3.0 * half);
    }
    check_pair(1.0, -1.0);        /* +0 */
    check_pair(-1.0, 1.0);
    check_pair(-0.0, -0.0);       /* -0 */
    check_pair(0.0, -0.0);
    check_pair(DBL_MAX, DBL_MAX); /* overflow */
    check_pair(-DBL_MAX, -DBL_MAX);
    check_pair(DBL_MIN, -ldexp(1.0, -1074)); /* normal to subnormal */
    check_pair(ldexp(1.0, -1074), ldexp(1.0, -1074));
}

static void test_special_values(void **state_unused)
{
    (void)state_unused;
    const double v[] = {0.0, -0.0, 1.0, -2.5, INFINITY, -INFINITY, NAN, DBL_MAX, ldexp(1.0, -1074)};
    const size_t n = sizeof v / sizeof v[0];
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++)
            check_pair(v[i], v[j]);
}

static void test_narrow_and_widen(void **state_unused)
{
    (void)state_unused;
    /* doubles across float's whole range and beyond it: overflow, float
     * subnormals, underflow to zero */
    for (int i = 0; i < 2000000; i++) {
        double d = random_double(1023, 160);
        same_float(polyc__d_to_f(d), (float)d);
    }
    /* ties: a float and half its ulp, and the float subnormals' */
    for (int i = 0; i < 200000; i++) {
        float f = (float)random_double(1023, 120);
        double half = ldexp(1.0, ilogb((double)f) - 24);
        same_float(polyc__d_to_f((double)f + half), (float)((double)f + half));
        same_float(polyc__d_to_f((double)f - half), (float)((double)f - half));
        double sub = ldexp((double)(next64() % 4096) + 0.5, -149);
        same_float(polyc__d_to_f(sub), (float)sub);
    }
    const double specials[] = {INFINITY, -INFINITY, NAN, 0.0, -0.0, DBL_MAX, -DBL_MAX, (double)FLT_MAX,
                               ldexp(1.0, -1074), (double)FLT_MAX * (1.0 + ldexp(1.0, -25))};
    for (size_t i = 0; i < sizeof specials / sizeof specials[0]; i++)
        same_float(polyc__d_to_f(specials[i]), (float)specials[i]);
    /* every float exponent and its subnormals widen exactly */
    for (int i = 0; i < 2000000; i++) {
        uint32_t u = (uint32_t)next64();
        float f;
        memcpy(&f, &u, sizeof f);
        same_double(polyc__f_to_d(f), (double)f);
    }
    for (uint32_t u = 1; u < 0x800000u; u += 97) { /* positive subnormals */
        float f;
        memcpy(&f, &u, sizeof f);
        same_double(polyc__f_to_d(f), (double)f);
        same_double(polyc__f_to_d(-f), -(double)f);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sums_every_distance),
        cmocka_unit_test(test_cancellation_and_ties),
        cmocka_unit_test(test_special_values),
        cmocka_unit_test(test_narrow_and_widen),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
