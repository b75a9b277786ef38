/* test_contour_data.c - the contour's data fallback (src/grid/contour.c): a wall
 * whose cells hold data (m >= data_min_m) but never reach the contour
 * threshold, far from any occupied cell, is traced and drawn; below the data
 * rule, or shorter than the trace's minimum for such cells, it is not.
 *
 * The scene: a 6 m x 4 m room and, 1 m in front of eight poses, a free-
 * standing wall `len` long at y = 2 m. Of the eight scans, `seen` are taken
 * with the wall there and the rest without it (a door that stood closed,
 * then open): the wall's cells get hits from the first and misses from the
 * others, m = seen / 8 or so.
 * Needs nothing outside the repository.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "polyc.h"
#include "scansim.h"

#define POSES 8u

/* len > 0: the wall; len < 0: a disc of radius -len at (3, 2) (a person
 * standing still) */
static void scene(scansim_scene *sc, double len, int with_wall)
{
    scansim_scene_init(sc, "door", 5u);
    sc->laser.beam_count = 361u;
    sc->laser.start_angle_rad = (float)(-3.14159265358979 / 2.0);
    sc->laser.angle_step_rad = (float)(3.14159265358979 / 360.0);
    sc->laser.range_sigma_m = 0.005f;
    assert_int_equal(scansim_add_box(sc, 0.0, 0.0, 6.0, 4.0), 0);
    if (with_wall && len > 0.0) {
        const double xy[4] = {3.0 - len / 2.0, 2.0, 3.0 + len / 2.0, 2.0};
        assert_int_equal(scansim_add_wall(sc, xy, 2u, 0), 0);
    } else if (with_wall) {
        assert_int_equal(scansim_add_circle(sc, 3.0, 2.0, -len, 24u), 0);
    }
    for (uint32_t k = 0; k < POSES; k++)
        assert_int_equal(scansim_add_pose(sc, 2.3 + 0.2 * (double)k, 1.0, 1.5707963), 0);
    assert_int_equal(scansim_run(sc), 0);
}

/* The batch map of the scans (the first `seen` with the wall): the
 * length of map within 3 cm of the wall's line y = 2 inside the room's
 * middle (|x - 3| <= len / 2 + 0.1); for a disc (len < 0), the length
 * within its radius + 0.1 m of its centre. */
static double wall_drawn(double len, uint32_t seen)
{
    static scansim_scene with, without;
    scene(&with, len, 1);
    scene(&without, len, 0);
    polyc_scan scans[POSES];
    for (uint32_t k = 0; k < POSES; k++)
        scans[k] = k < seen ? with.scans[k] : without.scans[k];
    polyc_config cfg;
    polyc_config_default(&cfg);
    polyc_limits lim;
    assert_int_equal(polyc_limits_for_scans(&cfg, scans, POSES, &lim), POLYC_OK);
    size_t size = polyc_memory_size(&cfg, &lim);
    void *block = malloc(size);
    assert_non_null(block);
    polyc_ctx *ctx = NULL;
    assert_int_equal(polyc_init(block, size, &cfg, &lim, &ctx), POLYC_OK);
    for (uint32_t k = 0; k < POSES; k++)
        assert_int_equal(polyc_add_scan(ctx, &scans[k]), POLYC_OK);
    assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK);
    double drawn = 0.0;
    for (uint32_t i = 0; i < polyc_polyline_count(ctx); i++) {
        polyc_polyline pl;
        assert_int_equal(polyc_get_polyline(ctx, i, &pl), POLYC_OK);
        uint32_t n = pl.closed ? pl.point_count + 1 : pl.point_count;
        for (uint32_t j = 0; j + 1 < n; j++) {
            const float *p = &pl.xy_m[2 * j], *q = &pl.xy_m[2 * ((j + 1) % pl.point_count)];
            double ax = (double)p[0], ay = (double)p[1], bx = (double)q[0], by = (double)q[1];
            int near_a = len > 0.0 ? fabs(ay - 2.0) <= 0.03 && fabs(ax - 3.0) <= len / 2.0 + 0.1
                                   : hypot(ax - 3.0, ay - 2.0) <= 0.1 - len;
            int near_b = len > 0.0 ? fabs(by - 2.0) <= 0.03 && fabs(bx - 3.0) <= len / 2.0 + 0.1
                                   : hypot(bx - 3.0, by - 2.0) <= 0.1 - len;
            if (near_a && near_b)
                drawn += hypot(bx - ax, by - ay);
        }
    }
    free(block);
    scansim_scene_free(&with);
    scansim_scene_free(&without);
    return drawn;
}

/* Seen by 3 scans of 8 (m about 0.375: data, under the threshold of 0.5),
 * a 2 m wall is drawn over most of its length. */
static void test_data_wall_drawn(void **state)
{
    (void)state;
    assert_true(wall_drawn(2.0, 3u) >= 1.6);
}

/* Seen by 1 scan of 8 (m about 0.125, under data_min_m = 0.2) it is not:
 * a person or a door seen a moment. */
static void test_rare_wall_not_drawn(void **state)
{
    (void)state;
    assert_true(wall_drawn(2.0, 1u) == 0.0);
}

/* Seen by 3 of 8, a piece 30 cm long is not traced: the trace leaves
 * walks on such cells alone that span less than 0.5 m (a chair, a person who
 * stood still). */
static void test_short_data_piece_not_drawn(void **state)
{
    (void)state;
    assert_true(wall_drawn(0.3, 3u) == 0.0);
}

/* Seen by 3 of 8, a disc 0.4 m across (a person who stood still) is not
 * traced: its walk round the disc is 0.6 m long but spans 0.4 m. Seen by
 * all 8 it is occupied and drawn. */
static void test_standing_person_not_drawn(void **state)
{
    (void)state;
    assert_true(wall_drawn(-0.2, 3u) == 0.0);
    assert_true(wall_drawn(-0.2, POSES) >= 0.4);
}

/* Seen by every scan, the wall is occupied and drawn, as always. */
static void test_solid_wall_drawn(void **state)
{
    (void)state;
    assert_true(wall_drawn(2.0, POSES) >= 1.8);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_data_wall_drawn),
        cmocka_unit_test(test_rare_wall_not_drawn),
        cmocka_unit_test(test_short_data_piece_not_drawn),
        cmocka_unit_test(test_standing_person_not_drawn),
        cmocka_unit_test(test_solid_wall_drawn),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
