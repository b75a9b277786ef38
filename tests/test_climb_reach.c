/* test_climb_reach.c - polyc_config_check refuses a hill-climbing step the
 * climb cannot take: a climb stays within POLYC__CLIMB_REACH_M - step_m of
 * where it started (the spatial hash's reach), so a step longer than half
 * the reach would never move a vertex (src/tunables.h). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "polyc.h"
#include "tunables.h"

static void test_step_within_reach(void **state)
{
    (void)state;
    polyc_config c;
    const char *why = NULL;
    polyc_config_default(&c);
    c.step_m = POLYC__STEP_MAX_M;
    assert_int_equal(polyc_config_check(&c, &why), POLYC_OK);
    assert_true(POLYC__STEP_MAX_M <= POLYC__CLIMB_REACH_M - POLYC__STEP_MAX_M);
}

static void test_step_beyond_reach(void **state)
{
    (void)state;
    const float steps[] = {0.026f, 0.05f, 0.1f, 10.0f};
    polyc_limits lim = {1, 360, 1u << 20, 0, 0};
    for (size_t i = 0; i < sizeof steps / sizeof steps[0]; i++) {
        polyc_config c;
        const char *why = NULL;
        polyc_config_default(&c);
        c.step_m = steps[i];
        assert_int_equal(polyc_config_check(&c, &why), POLYC_ERR_CONFIG);
        assert_non_null(why);
        assert_non_null(strstr(why, "step_m"));
        assert_int_equal(polyc_memory_size(&c, &lim), 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_step_within_reach),
        cmocka_unit_test(test_step_beyond_reach),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
