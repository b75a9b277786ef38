/* test_occmap.c - the evaluation's occupancy mapper (tools/eval/occmap.h)
 * on hand-made scans at 10 cm cells whose log-odds are known exactly: a
 * wall seen along three rows, a slanted beam's cells, a beam without
 * return. Beams run through cell centres or well inside cells, so no ray
 * meets a cell corner. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "near.h"
#include "occmap.h"
#include "pipeline.h"

#define RES 0.1
#define WALL_X 1.05

/* The cell holding world point (x, y): its index, asserted inside. */
static size_t cell_at(const occmap *m, double x, double y)
{
    double gx = floor((x - m->origin_x_m) / m->resolution_m);
    double gy = floor((y - m->origin_y_m) / m->resolution_m);
    assert_true(gx >= 0.0 && gy >= 0.0 && gx < (double)m->width && gy < (double)m->height);
    return (size_t)gy * m->width + (size_t)gx;
}

static polyc_scan one_beam(double x, double y, double angle_rad, const float *range)
{
    polyc_scan s;
    memset(&s, 0, sizeof s);
    s.pose_x_m = x;
    s.pose_y_m = y;
    s.pose_theta_rad = angle_rad;
    s.angle_step_rad = 0.01f;
    s.min_range_m = 0.05f;
    s.max_range_m = 20.0f;
    s.beam_count = 1;
    s.range_m = range;
    return s;
}

static void config(occmap_config *c)
{
    occmap_config_default(c);
    c->resolution_m = RES;
}

static void test_probability(void **state)
{
    occmap_config c;
    (void)state;
    occmap_config_default(&c);
    assert_near(c.resolution_m, 0.05, 0.0);
    assert_near(occmap_probability(0.0), 0.5, 1e-15);
    assert_near(occmap_probability(0.85), 1.0 - 1.0 / (1.0 + exp(0.85)), 1e-15);
    assert_near(occmap_probability(0.85), 0.70057, 1e-5);
    /* one hit is occupied, one miss unknown (p 0.401), four misses free
     * (p 0.168): the free threshold 0.196 is L < -1.41 */
    assert_int_equal(occmap_value(&c, 0.85), 100);
    assert_int_equal(occmap_value(&c, -0.4), -1);
    assert_int_equal(occmap_value(&c, -1.2), -1);
    assert_int_equal(occmap_value(&c, -1.6), 0);
    assert_int_equal(occmap_value(&c, 0.0), -1);
    assert_int_equal(occmap_value(&c, 0.6), -1);   /* p 0.646 */
    assert_int_equal(occmap_value(&c, 0.62), 100); /* p 0.650 2 */
}

/* A wall at x = 1.05 seen from x = 0.05 along the rows y = 0.35, 0.55,
 * 0.75, four beams each (angle 0, range 1 m): ten cells of misses before
 * each hit, nothing behind. */
static void test_wall(void **state)
{
    static const float range[1] = {1.0f};
    const double rows[3] = {0.35, 0.55, 0.75};
    polyc_scan scans[12];
    occmap_config c;
    occmap m;
    (void)state;
    for (int i = 0; i < 12; i++)
        scans[i] = one_beam(0.05, rows[i / 4], 0.0, range);
    config(&c);
    assert_int_equal(occmap_build(&m, &c, scans, 12), 0);
    /* the box of poses and hits, a cell wider on each side */
    assert_near(m.origin_x_m, -0.1, 1e-12);
    assert_near(m.origin_y_m, 0.2, 1e-12);
    assert_int_equal(m.width, 13);
    assert_int_equal(m.height, 7);
    for (int r = 0; r < 3; r++) {
        double y = rows[r];
        for (int k = 0; k < 10; k++) {
            size_t i = cell_at(&m, 0.05 + RES * k, y);
            assert_near(m.logodds[i], -1.6, 1e-6);
            assert_int_equal(m.cells[i], 0);
            assert_int_equal(m.touched[i], 4);
        }
        size_t wall = cell_at(&m, WALL_X, y);
        assert_near(m.logodds[wall], 3.4, 1e-6);
        assert_int_equal(m.cells[wall], 100);
        size_t behind = cell_at(&m, WALL_X + RES, y);
        assert_near(m.logodds[behind], 0.0, 0.0);
        assert_int_equal(m.cells[behind], -1);
        assert_int_equal(m.touched[behind], 0);
        assert_int_equal(m.cells[cell_at(&m, -0.05, y)], -1);   /* behind the robot */
        /* the rows between the beams: unknown */
        assert_int_equal(m.cells[cell_at(&m, 0.55, y + RES)], -1);
    }
    assert_int_equal(m.occupied, 3);
    assert_int_equal(m.free_cells, 30);
    assert_int_equal(m.unknown, 13u * 7u - 33u);

    /* the library's view: the grid and its occupied centres */
    polyc_occupancy_grid g;
    double *xy;
    uint64_t n;
    occmap_grid(&m, &g);
    assert_int_equal(g.width, 13);
    assert_ptr_equal(g.cells, m.cells);
    assert_near(g.resolution_m, 0.1, 1e-7);
    assert_int_equal(occmap_cell_points(&g, 100, &xy, &n), 0);
    assert_int_equal(n, 3);
    for (uint64_t k = 0; k < n; k++) {
        assert_near(xy[2u * k], WALL_X, 1e-6);
        assert_near(xy[2u * k + 1u], rows[k], 1e-6);
    }
    free(xy);
    occmap_free(&m);

    /* one beam per row: the misses are unknown (p 0.401), the hit occupied */
    for (int i = 0; i < 3; i++)
        scans[i] = one_beam(0.05, rows[i], 0.0, range);
    assert_int_equal(occmap_build(&m, &c, scans, 3), 0);
    assert_near(m.logodds[cell_at(&m, 0.55, 0.55)], -0.4, 1e-6);
    assert_int_equal(m.cells[cell_at(&m, 0.55, 0.55)], -1);
    assert_near(m.logodds[cell_at(&m, WALL_X, 0.55)], 0.85, 1e-6);
    assert_int_equal(m.cells[cell_at(&m, WALL_X, 0.55)], 100);
    occmap_free(&m);
}

/* A slanted beam from (0.05, 0.05) to (0.35, 0.13): in cells it crosses
 * x = 0.1 and x = 0.2, then y = 0.1 (at x = 0.2375), then x = 0.3. */
static void test_traversal(void **state)
{
    float range[1] = {(float)hypot(0.3, 0.08)};
    polyc_scan s = one_beam(0.05, 0.05, atan2(0.08, 0.3), range);
    occmap_config c;
    occmap m;
    (void)state;
    config(&c);
    assert_int_equal(occmap_build(&m, &c, &s, 1), 0);
    const double missed[4][2] = {{0.05, 0.05}, {0.15, 0.05}, {0.25, 0.05}, {0.25, 0.15}};
    for (int k = 0; k < 4; k++) {
        size_t i = cell_at(&m, missed[k][0], missed[k][1]);
        assert_near(m.logodds[i], -0.4, 1e-6);
        assert_int_equal(m.touched[i], 1);
    }
    assert_near(m.logodds[cell_at(&m, 0.35, 0.15)], 0.85, 1e-6);
    /* the cells the line passes by */
    assert_int_equal(m.touched[cell_at(&m, 0.15, 0.15)], 0);
    assert_int_equal(m.touched[cell_at(&m, 0.35, 0.05)], 0);
    size_t touched = 0;
    for (size_t i = 0; i < (size_t)m.width * m.height; i++)
        touched += m.touched[i] != 0;
    assert_int_equal(touched, 5);
    occmap_free(&m);
}

/* A beam without return (range = max range) straight up from the pose of
 * the middle row: misses up to free_range_m, where the grid ends first;
 * skipped with free_range_m 0. */
static void test_no_return(void **state)
{
    static const float range[1] = {1.0f}, none[1] = {20.0f};
    polyc_scan scans[5];
    occmap_config c;
    occmap m;
    (void)state;
    for (int i = 0; i < 4; i++)
        scans[i] = one_beam(0.05, 0.55, 0.0, range);
    scans[4] = one_beam(0.05, 0.35, 0.5 * acos(-1.0), none);
    /* the hits' and poses' box: y from 0.25 to 0.65 (cells 2..6) */
    config(&c);
    assert_int_equal(occmap_build(&m, &c, scans, 5), 0);
    assert_int_equal(m.height, 5);
    assert_near(m.logodds[cell_at(&m, 0.05, 0.35)], -0.4, 1e-6);
    assert_near(m.logodds[cell_at(&m, 0.05, 0.45)], -0.4, 1e-6);
    assert_near(m.logodds[cell_at(&m, 0.05, 0.55)], -2.0, 1e-6);
    assert_near(m.logodds[cell_at(&m, 0.05, 0.65)], -0.4, 1e-6);
    assert_int_equal(m.touched[cell_at(&m, 0.05, 0.25)], 0);
    assert_int_equal(m.cells[cell_at(&m, 0.05, 0.55)], 0);
    occmap_free(&m);

    c.free_range_m = 0.0;
    assert_int_equal(occmap_build(&m, &c, scans, 5), 0);
    assert_int_equal(m.touched[cell_at(&m, 0.05, 0.45)], 0);
    assert_near(m.logodds[cell_at(&m, 0.05, 0.55)], -1.6, 1e-6);
    occmap_free(&m);

    /* no scans, no cells */
    assert_int_equal(occmap_build(&m, &c, scans, 0), -1);
    c.resolution_m = 0.0;
    assert_int_equal(occmap_build(&m, &c, scans, 5), -1);
}

/* The grid as the bench feeds it to the library (pipeline_run_grid): a
 * 3 m wall at x = 2.013 seen from 2 m by a fan of beams at 5 cm cells
 * comes out as one polyline along it. */
static void test_library_on_grid(void **state)
{
    enum { SCANS = 8, BEAMS = 181 };
    static float ranges[SCANS][BEAMS];
    polyc_scan scans[SCANS];
    occmap_config c;
    occmap m;
    polyc_occupancy_grid g;
    polyc_config config;
    pipeline p;
    double ms;
    uint32_t count = 0;
    (void)state;
    for (int s = 0; s < SCANS; s++) {
        double py = -0.4 + 0.1 * s;
        for (int i = 0; i < BEAMS; i++) {
            double a = -0.9 + 1.8 * i / (BEAMS - 1), t = cos(a) > 0.0 ? 2.013 / cos(a) : 99.0;
            double y = py + t * sin(a);
            ranges[s][i] = (float)(fabs(y) <= 1.5 ? t : 30.0);  /* no return past the wall */
        }
        scans[s] = one_beam(0.0, py, -0.9, ranges[s]);
        scans[s].angle_step_rad = (float)(1.8 / (BEAMS - 1));
        scans[s].beam_count = BEAMS;
    }
    occmap_config_default(&c);
    assert_int_equal(occmap_build(&m, &c, scans, SCANS), 0);
    assert_true(m.occupied >= 55u && m.occupied <= 130u);   /* 3 m of 5 cm cells, 1-2 deep */
    occmap_grid(&m, &g);
    polyc_config_default(&config);
    assert_int_equal(pipeline_run_grid(&p, &config, &g, &ms), 0);
    polyc_polyline *lines = pipeline_lines(&p, &count);
    assert_non_null(lines);
    assert_int_equal(count, 1);
    assert_int_equal(lines[0].point_count, 2);
    for (uint32_t k = 0; k < lines[0].point_count; k++) {
        assert_near(lines[0].xy_m[2u * k], 2.013, 0.05);
        assert_true(fabs((double)lines[0].xy_m[2u * k + 1u]) <= 1.6);
    }
    free(lines);
    pipeline_close(&p);
    occmap_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_probability),
        cmocka_unit_test(test_wall),
        cmocka_unit_test(test_traversal),
        cmocka_unit_test(test_no_return),
        cmocka_unit_test(test_library_on_grid),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
