/* test_fmath.c - the library's float sine, cosine, arc tangent and
 * logarithm (fmath.c) against libm's double functions over the ranges the
 * library uses them in: angles of a few turns (scan and beam angles, noise
 * directions), arc tangents of line fits, logarithms of point counts and
 * of the PRNG's uniform draws. Bounds: a few float ulps of the result. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>

#include "internal.h"

/* float's ulp at 1 is 1.19e-7; these results are at most about 1 */
#define ABS_BOUND 3e-7

static void test_sin_cos_over_turns(void **state)
{
    (void)state;
    double worst = 0.0;
    for (int32_t i = -2000000; i <= 2000000; i += 7) {
        float a = (float)i * 2.5e-5f; /* -50 .. 50 rad */
        float s, c;
        polyc__sincosf(a, &s, &c);
        double es = fabs((double)s - sin((double)a)), ec = fabs((double)c - cos((double)a));
        worst = fmax(worst, fmax(es, ec));
        assert_true(polyc__sinf(a) == s && polyc__cosf(a) == c);
    }
    print_message("sin, cos on [-50, 50] rad: worst error %.3g\n", worst);
    assert_true(worst < ABS_BOUND);
    float s, c;
    polyc__sincosf(0.0f, &s, &c);
    assert_true(s == 0.0f && c == 1.0f);
}

static void test_atan2_every_quadrant(void **state)
{
    (void)state;
    double worst = 0.0;
    for (int i = 0; i < 20000; i++) {
        double t = -3.14159 + 6.28318 * (double)i / 20000.0;
        for (int k = 0; k < 4; k++) {
            double r = k == 0 ? 1e-3 : (k == 1 ? 0.5 : (k == 2 ? 7.0 : 3e4));
            float y = (float)(r * sin(t)), x = (float)(r * cos(t));
            double e = fabs((double)polyc__atan2f(y, x) - atan2((double)y, (double)x));
            worst = fmax(worst, e);
        }
    }
    print_message("atan2 over every direction: worst error %.3g rad\n", worst);
    assert_true(worst < 5e-7); /* two ulps of a result near pi */
    assert_true(polyc__atan2f(0.0f, 0.0f) == 0.0f);
    assert_true(polyc__atan2f(0.0f, 1.0f) == 0.0f);
    assert_true(fabs((double)polyc__atan2f(1.0f, 0.0f) - 1.5707963267948966) < ABS_BOUND);
    assert_true(fabs((double)polyc__atan2f(0.0f, -1.0f) - 3.141592653589793) < ABS_BOUND);
}

static void test_log_relative(void **state)
{
    (void)state;
    double worst = 0.0;
    for (int i = 0; i < 200000; i++) {
        float x = ldexpf(1.0f + (float)i / 200000.0f, (i % 60) - 30); /* 2^-30 .. 2^30 */
        double ref = log((double)x);
        double e = fabs((double)polyc__logf(x) - ref) / fmax(1.0, fabs(ref));
        worst = fmax(worst, e);
    }
    print_message("log over 2^-30 .. 2^30: worst error %.3g (relative above 1)\n", worst);
    assert_true(worst < ABS_BOUND);
    assert_true(polyc__logf(1.0f) == 0.0f);
}

static void test_not_finite(void **state)
{
    (void)state;
    float s, c;
    polyc__sincosf(INFINITY, &s, &c);
    assert_true(isnan(s) && isnan(c));
    polyc__sincosf(-INFINITY, &s, &c);
    assert_true(isnan(s) && isnan(c));
    polyc__sincosf(NAN, &s, &c);
    assert_true(isnan(s) && isnan(c));
    polyc__sincosf(3e6f, &s, &c);
    assert_true(isnan(s) && isnan(c));
    assert_true(isnan(polyc__atan2f(INFINITY, 1.0f)) && isnan(polyc__atan2f(1.0f, NAN)));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sin_cos_over_turns),
        cmocka_unit_test(test_atan2_every_quadrant),
        cmocka_unit_test(test_log_relative),
        cmocka_unit_test(test_not_finite),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
