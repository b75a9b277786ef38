/* test_band.c - one wall, one line: hand-made scenes through the public
 * API. A wall seen as a band of points (every scan's pose off by a few
 * centimetres) gives one line through the middle of the band; a thin wall
 * seen from both sides gives one line on each face; a door recess stays; a
 * corner seen from inside has no spur past its points. Scenes come from the
 * simulator (tools/eval/scansim), deterministic by seed. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "polyc.h"
#include "scansim.h"

#define PI 3.14159265358979

/* Builds the scene's scans with the default configuration; the context is
 * returned (free its block with free_map). */
typedef struct built {
    polyc_ctx *ctx;
    void *block;
} built;

static void build(const scansim_scene *sc, built *b)
{
    polyc_config cfg;
    polyc_config_default(&cfg);
    polyc_limits lim;
    assert_int_equal(polyc_limits_for_scans(&cfg, sc->scans, sc->scan_count, &lim), POLYC_OK);
    size_t bytes = polyc_memory_size(&cfg, &lim);
    assert_true(bytes > 0);
    b->block = malloc(bytes);
    assert_non_null(b->block);
    assert_int_equal(polyc_init(b->block, bytes, &cfg, &lim, &b->ctx), POLYC_OK);
    for (uint32_t i = 0; i < sc->scan_count; i++)
        assert_int_equal(polyc_add_scan(b->ctx, &sc->scans[i]), POLYC_OK);
    assert_int_equal(polyc_build(b->ctx, NULL, NULL), POLYC_OK);
}

static void free_map(built *b)
{
    free(b->block);
    b->block = NULL;
}

/* The map's crossings of the vertical line x = x0 (segments that span it),
 * their y in ys (at most cap); returns how many. */
static int crossings_at_x(const polyc_ctx *ctx, double x0, double *ys, int cap)
{
    int n = 0;
    uint32_t count = polyc_polyline_count(ctx);
    for (uint32_t i = 0; i < count; i++) {
        polyc_polyline pl;
        assert_int_equal(polyc_get_polyline(ctx, i, &pl), POLYC_OK);
        uint32_t segs = pl.closed ? pl.point_count : pl.point_count - 1;
        for (uint32_t j = 0; pl.point_count > 1 && j < segs; j++) {
            uint32_t k = (j + 1) % pl.point_count;
            double ax = (double)pl.xy_m[2 * j], ay = (double)pl.xy_m[2 * j + 1];
            double bx = (double)pl.xy_m[2 * k], by = (double)pl.xy_m[2 * k + 1];
            if ((ax - x0) * (bx - x0) > 0.0 || ax == bx)
                continue;
            if (n < cap)
                ys[n] = ay + (by - ay) * (x0 - ax) / (bx - ax);
            n++;
        }
    }
    return n;
}

/* A straight wall along y = 0 from x = 0 to 6 m and poses 1.5 m in front
 * of it, looking at it, spread along it. */
static void wall_scene(scansim_scene *sc, uint64_t seed, uint32_t poses)
{
    scansim_scene_init(sc, "band", seed);
    sc->laser.beam_count = 361u;
    sc->laser.angle_step_rad = (float)(PI / 360.0);
    const double wall[4] = {0.0, 0.0, 6.0, 0.0};
    assert_int_equal(scansim_add_wall(sc, wall, 2, 0), 0);
    for (uint32_t i = 0; i < poses; i++)
        assert_int_equal(scansim_add_pose(sc, 0.5 + 5.0 * (double)i / (double)(poses - 1), 1.5,
                                          -PI / 2.0), 0);
}

/* 200 scans of one 6 m wall, each scan's logged pose off by up to 10 cm
 * across the wall: its points form a 20 cm band. One line, within 2 cm of
 * the band's middle. */
static void test_band_becomes_one_line(void **state)
{
    (void)state;
    scansim_scene sc;
    wall_scene(&sc, 7u, 200u);
    assert_int_equal(scansim_run(&sc), 0);
    scansim_rng rng;
    scansim_rng_seed(&rng, 99u);
    double lo = 1e9, hi = -1e9;
    for (uint32_t i = 0; i < sc.scan_count; i++) {
        double off = 0.2 * scansim_rng_uniform(&rng) - 0.1;
        sc.scans[i].pose_y_m += off;
        lo = fmin(lo, off);
        hi = fmax(hi, off);
    }
    assert_true(hi - lo > 0.18); /* the band is 20 cm wide */
    built b;
    build(&sc, &b);
    for (double x = 0.5; x <= 5.5; x += 0.25) {
        double ys[8];
        int n = crossings_at_x(b.ctx, x, ys, 8);
        assert_int_equal(n, 1);
        assert_true(fabs(ys[0] - 0.5 * (lo + hi)) <= 0.02);
    }
    free_map(&b);
    scansim_scene_free(&sc);
}

/* A 10 cm thin wall seen from both sides: two lines, one on each face. */
static void test_thin_wall_two_faces(void **state)
{
    (void)state;
    scansim_scene sc;
    scansim_scene_init(&sc, "thin", 3u);
    assert_int_equal(scansim_add_box(&sc, 0.0, 0.0, 6.0, 0.1), 0);
    for (uint32_t i = 0; i < 100; i++) {
        double x = 0.5 + 5.0 * (double)i / 99.0;
        assert_int_equal(scansim_add_pose(&sc, x, -1.5, PI / 2.0), 0);
        assert_int_equal(scansim_add_pose(&sc, x, 1.6, -PI / 2.0), 0);
    }
    assert_int_equal(scansim_run(&sc), 0);
    built b;
    build(&sc, &b);
    for (double x = 0.5; x <= 5.5; x += 0.25) {
        double ys[8];
        int n = crossings_at_x(b.ctx, x, ys, 8);
        assert_int_equal(n, 2);
        double y0 = fmin(ys[0], ys[1]), y1 = fmax(ys[0], ys[1]);
        assert_true(fabs(y0) <= 0.02);
        assert_true(fabs(y1 - 0.1) <= 0.02);
    }
    free_map(&b);
    scansim_scene_free(&sc);
}

/* A door recess 10 cm deep and 1 m wide in a wall seen from one side: the
 * recess stays, its back 10 cm behind the wall's line. */
static void test_door_recess_stays(void **state)
{
    (void)state;
    scansim_scene sc;
    scansim_scene_init(&sc, "recess", 5u);
    sc.laser.beam_count = 361u;
    sc.laser.angle_step_rad = (float)(PI / 360.0);
    const double wall[12] = {0.0, 0.0, 2.5, 0.0, 2.5, -0.1, 3.5, -0.1, 3.5, 0.0, 6.0, 0.0};
    assert_int_equal(scansim_add_wall(&sc, wall, 6, 0), 0);
    for (uint32_t i = 0; i < 200; i++)
        assert_int_equal(scansim_add_pose(&sc, 0.5 + 5.0 * (double)i / 199.0, 1.5, -PI / 2.0), 0);
    assert_int_equal(scansim_run(&sc), 0);
    built b;
    build(&sc, &b);
    for (double x = 0.5; x <= 5.5; x += 0.1) {
        double ys[8];
        int n = crossings_at_x(b.ctx, x, ys, 8);
        double want = x > 2.6 && x < 3.4 ? -0.1 : 0.0;
        if (fabs(x - 2.5) < 0.1 || fabs(x - 3.5) < 0.1)
            continue; /* the recess's sides */
        assert_int_equal(n, 1);
        assert_true(fabs(ys[0] - want) <= 0.02);
    }
    free_map(&b);
    scansim_scene_free(&sc);
}

/* An L corner seen from inside: every point of the map within 3 cm of an
 * endpoint (no vertex, spur or hook past the points). */
static void test_corner_without_spur(void **state)
{
    (void)state;
    scansim_scene sc;
    scansim_scene_init(&sc, "corner", 11u);
    sc.laser.beam_count = 361u;
    sc.laser.angle_step_rad = (float)(PI / 360.0);
    const double wall[6] = {4.0, 0.0, 0.0, 0.0, 0.0, 4.0};
    assert_int_equal(scansim_add_wall(&sc, wall, 3, 0), 0);
    scansim_rng rng;
    scansim_rng_seed(&rng, 5u);
    for (uint32_t i = 0; i < 60; i++) {
        double x = 0.8 + 2.2 * scansim_rng_uniform(&rng), y = 0.8 + 2.2 * scansim_rng_uniform(&rng);
        assert_int_equal(scansim_add_pose(&sc, x, y, PI + PI / 4.0), 0);
    }
    assert_int_equal(scansim_run(&sc), 0);
    /* the endpoints, in the logged poses */
    size_t cap = (size_t)sc.scan_count * sc.laser.beam_count;
    double *ep = malloc(cap * 2 * sizeof *ep);
    assert_non_null(ep);
    size_t ne = 0;
    for (uint32_t i = 0; i < sc.scan_count; i++) {
        const polyc_scan *s = &sc.scans[i];
        for (uint32_t k = 0; k < s->beam_count; k++) {
            double r = (double)s->range_m[k];
            if (!(r < (double)s->max_range_m))
                continue;
            double a = s->pose_theta_rad + (double)s->start_angle_rad +
                       (double)k * (double)s->angle_step_rad;
            ep[2 * ne] = s->pose_x_m + r * cos(a);
            ep[2 * ne + 1] = s->pose_y_m + r * sin(a);
            ne++;
        }
    }
    built b;
    build(&sc, &b);
    double worst = 0.0;
    uint32_t count = polyc_polyline_count(b.ctx);
    assert_true(count >= 1);
    for (uint32_t i = 0; i < count; i++) {
        polyc_polyline pl;
        assert_int_equal(polyc_get_polyline(b.ctx, i, &pl), POLYC_OK);
        for (uint32_t j = 0; j + 1 < pl.point_count + (pl.closed ? 1u : 0u); j++) {
            uint32_t k = (j + 1) % pl.point_count;
            double ax = (double)pl.xy_m[2 * j], ay = (double)pl.xy_m[2 * j + 1];
            double dx = (double)pl.xy_m[2 * k] - ax, dy = (double)pl.xy_m[2 * k + 1] - ay;
            int steps = (int)ceil(sqrt(dx * dx + dy * dy) / 0.01);
            for (int q = 0; q <= steps; q++) {
                double x = ax + dx * q / (steps ? steps : 1), y = ay + dy * q / (steps ? steps : 1);
                double best = 1e9;
                for (size_t e = 0; e < ne; e++) {
                    double ex = ep[2 * e] - x, ey = ep[2 * e + 1] - y;
                    best = fmin(best, ex * ex + ey * ey);
                }
                worst = fmax(worst, sqrt(best));
            }
        }
    }
    assert_true(worst <= 0.03);
    free(ep);
    free_map(&b);
    scansim_scene_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_band_becomes_one_line),
        cmocka_unit_test(test_thin_wall_two_faces),
        cmocka_unit_test(test_door_recess_stays),
        cmocka_unit_test(test_corner_without_spur),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
