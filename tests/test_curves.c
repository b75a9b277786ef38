/* test_curves.c - round things as circles and arcs (polyc_find_curves): a
 * room with round pillars of known centre and radius, seen all round by a
 * robot driving a loop (tools/eval/scansim), mapped in batch and online;
 * each pillar must come out as one circle near the truth, the room's walls
 * and a square box as polylines, and nothing with POLYC_FLAG_NO_ARCS; a
 * room with a curved side whose arcs lie on it; straight rooms without
 * either. The calls' errors and when the curves are forgotten. Needs
 * nothing outside the repository. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "curves.h"
#include "polyc.h"
#include "scansim.h"

#define PI 3.14159265358979323846
#define PILLARS 3
/* the truth: centres and radii (metres), and a square box */
static const double pillar[PILLARS][3] = {{2.0, 2.0, 0.30}, {6.0, 1.6, 0.15}, {4.2, 3.4, 0.45}};

/* A 9 m x 5.5 m room, the pillars and a box, a loop round them. */
static void pillar_scene(scansim_scene *sc, double turn)
{
    static const double loop[] = {0.8, 0.8, 8.2, 0.8, 8.2, 4.7, 0.8, 4.7, 0.8, 1.0};
    scansim_scene_init(sc, "pillars-test", 5u);
    sc->laser.beam_count = 361u;
    sc->laser.angle_step_rad = (float)(PI / 360.0);
    sc->laser.max_range_m = 12.0f;
    assert_int_equal(scansim_add_box(sc, 0.0, 0.0, 9.0, 5.5), 0);
    for (int k = 0; k < PILLARS; k++)
        assert_int_equal(scansim_add_circle(sc, pillar[k][0], pillar[k][1], pillar[k][2],
                                            (uint32_t)(2.0 * PI * pillar[k][2] / 0.005)),
                         0);
    assert_int_equal(scansim_add_box(sc, 6.9, 3.0, 7.5, 3.6), 0);
    assert_int_equal(scansim_add_path(sc, loop, 5u, 0.1), 0);
    scansim_transform(sc, turn, 0.0, 0.0);
    assert_int_equal(scansim_run(sc), 0);
}

static void check(polyc_status st, const polyc_ctx *ctx, const char *what)
{
    if (st != POLYC_OK)
        fail_msg("%s: %s (%s)", what, polyc_status_str(st), ctx ? polyc_last_error(ctx) : "");
}

/* Each pillar one circle within 1 cm (centre) and 1 cm (radius) of the
 * truth (turned by `turn` as the scene was); no other circle. */
static void check_circles(const polyc_ctx *ctx, double turn)
{
    uint32_t n = polyc_polyline_count(ctx), found = 0;
    int seen[PILLARS] = {0};
    double c = cos(turn), s = sin(turn);
    for (uint32_t i = 0; i < n; i++) {
        polyc_circle ci;
        check(polyc_get_circle(ctx, i, &ci), ctx, "polyc_get_circle");
        if (!(ci.radius_m > 0.0f) || ci.same_as != i)
            continue;
        found++;
        int match = -1;
        for (int k = 0; k < PILLARS; k++) {
            double x = c * pillar[k][0] - s * pillar[k][1], y = s * pillar[k][0] + c * pillar[k][1];
            if (hypot((double)ci.center_x_m - x, (double)ci.center_y_m - y) < 0.01 &&
                fabs((double)ci.radius_m - pillar[k][2]) < 0.01)
                match = k;
        }
        if (match < 0)
            fail_msg("circle %u at (%.3f, %.3f) r %.3f is no pillar", i, (double)ci.center_x_m,
                     (double)ci.center_y_m, (double)ci.radius_m);
        seen[match]++;
        /* the polyline callers that know only vertices read stays near it */
        polyc_polyline pl;
        check(polyc_get_polyline(ctx, i, &pl), ctx, "polyc_get_polyline");
        assert_true(pl.point_count >= 3);
        assert_true(ci.polyline_dev_m >= 0.0f && ci.polyline_dev_m < 0.05f);
    }
    for (int k = 0; k < PILLARS; k++)
        if (seen[k] != 1)
            fail_msg("pillar %d: %d circles", k, seen[k]);
    assert_int_equal(found, PILLARS);
    assert_int_equal(polyc_circle_count(ctx), PILLARS);
}

static polyc_ctx *batch_map(const scansim_scene *sc, const polyc_config *cfg, void **block)
{
    polyc_limits lim;
    polyc_ctx *ctx = NULL;
    check(polyc_limits_for_scans(cfg, sc->scans, sc->scan_count, &lim), NULL, "limits");
    size_t size = polyc_memory_size(cfg, &lim);
    *block = malloc(size);
    assert_non_null(*block);
    check(polyc_init(*block, size, cfg, &lim, &ctx), NULL, "polyc_init");
    for (uint32_t i = 0; i < sc->scan_count; i++)
        check(polyc_add_scan(ctx, &sc->scans[i]), ctx, "polyc_add_scan");
    check(polyc_build(ctx, NULL, NULL), ctx, "polyc_build");
    return ctx;
}

static void test_batch_pillars(void **state)
{
    (void)state;
    for (int t = 0; t < 2; t++) {
        double turn = t ? 0.7 : 0.0;
        scansim_scene sc;
        polyc_config cfg;
        void *block;
        pillar_scene(&sc, turn);
        polyc_config_default(&cfg);
        polyc_ctx *ctx = batch_map(&sc, &cfg, &block);
        assert_int_equal(polyc_circle_count(ctx), 0); /* not looked for yet */
        check(polyc_find_curves(ctx), ctx, "polyc_find_curves");
        check_circles(ctx, turn);
        /* a call that changes the map forgets them */
        check(polyc_optimize(ctx, NULL, NULL), ctx, "polyc_optimize");
        assert_int_equal(polyc_circle_count(ctx), 0);
        check(polyc_find_curves(ctx), ctx, "polyc_find_curves again");
        check_circles(ctx, turn);
        free(block);

        /* switched off: polylines only */
        cfg.flags |= POLYC_FLAG_NO_ARCS;
        ctx = batch_map(&sc, &cfg, &block);
        check(polyc_find_curves(ctx), ctx, "polyc_find_curves, no arcs");
        assert_int_equal(polyc_circle_count(ctx), 0);
        free(block);
        scansim_scene_free(&sc);
    }
}

static void test_online_pillars(void **state)
{
    scansim_scene sc;
    polyc_config cfg;
    polyc_online_limits lim;
    polyc_ctx *ctx = NULL;
    uint32_t beams = 0;
    (void)state;
    pillar_scene(&sc, 0.0);
    polyc_config_default(&cfg);
    for (uint32_t i = 0; i < sc.scan_count; i++)
        beams = sc.scans[i].beam_count > beams ? sc.scans[i].beam_count : beams;
    check(polyc_online_limits_for_area(&cfg, 30.0, beams, &lim), NULL, "online limits");
    size_t size = polyc_online_memory_size(&cfg, &lim);
    void *block = malloc(size);
    assert_non_null(block);
    check(polyc_online_init(block, size, &cfg, &lim, &ctx), NULL, "polyc_online_init");
    for (uint32_t i = 0; i < sc.scan_count; i++) {
        check(polyc_online_add_scan(ctx, &sc.scans[i], 0, NULL), ctx, "add");
        check(polyc_online_update(ctx, POLYC_ONLINE_WORK_DEFAULT, NULL), ctx, "update");
    }
    check(polyc_online_finish(ctx, NULL, NULL, NULL), ctx, "finish");
    check(polyc_find_curves(ctx), ctx, "polyc_find_curves");
    check_circles(ctx, 0.0);
    free(block);
    scansim_scene_free(&sc);
}

/* On the simulator's round kinds, every circle is held all round by the
 * scans: no stretch of it longer than the split gap (plus a bin) without
 * an endpoint within 5 cm (a circle over a pillar's unseen back would be a
 * run without data). */
static void test_held_all_round(void **state)
{
    static const char *const kinds[] = {"roundmix", "pillars"};
    (void)state;
    for (int kk = 0; kk < 2; kk++)
        for (uint64_t seed = 1; seed <= 6; seed++) {
            scansim_scene sc;
            polyc_config cfg;
            void *block;
            assert_int_equal(scansim_scene_builtin(&sc, kinds[kk], seed), 0);
            assert_int_equal(scansim_keep_every(&sc, 2u), 0);
            assert_int_equal(scansim_run(&sc), 0);
            polyc_config_default(&cfg);
            polyc_ctx *ctx = batch_map(&sc, &cfg, &block);
            check(polyc_find_curves(ctx), ctx, "polyc_find_curves");
            for (uint32_t i = 0; i < polyc_polyline_count(ctx); i++) {
                polyc_circle c;
                check(polyc_get_circle(ctx, i, &c), ctx, "polyc_get_circle");
                if (!(c.radius_m > 0.0f))
                    continue;
                enum { BINS = 720 };
                unsigned char hit[BINS] = {0};
                for (uint32_t k = 0; k < sc.scan_count; k++) {
                    const polyc_scan *scan = &sc.scans[k];
                    for (uint32_t j = 0; j < scan->beam_count; j++) {
                        float r = scan->range_m[j];
                        if (!(r >= scan->min_range_m && r < scan->max_range_m))
                            continue;
                        double a = scan->pose_theta_rad + (double)scan->start_angle_rad +
                                   (double)j * (double)scan->angle_step_rad;
                        double x = scan->pose_x_m + (double)r * cos(a) - (double)c.center_x_m;
                        double y = scan->pose_y_m + (double)r * sin(a) - (double)c.center_y_m;
                        if (fabs(hypot(x, y) - (double)c.radius_m) > 0.05)
                            continue;
                        int b = (int)((atan2(y, x) + PI) / (2.0 * PI) * BINS);
                        hit[b < 0 ? 0 : (b >= BINS ? BINS - 1 : b)] = 1;
                    }
                }
                int run = 0, longest = 0;
                for (int b = 0; b < 2 * BINS; b++) {
                    run = hit[b % BINS] ? 0 : run + 1;
                    longest = run > longest ? run : longest;
                }
                double bin_m = 2.0 * PI * (double)c.radius_m / BINS;
                if ((double)longest * bin_m > (double)cfg.split_gap_m + 2.0 * bin_m)
                    fail_msg("%s seed %u: circle %u (r %.3f) has %.3f m without data", kinds[kk],
                             (unsigned)seed, i, (double)c.radius_m, (double)longest * bin_m);
            }
            free(block);
            scansim_scene_free(&sc);
        }
}

/* A 9 m x 6 m room whose north side is an arc of radius 7 m through its
 * corners, bulging out; a loop inside. The arc comes out as arcs of about
 * that circle (polyc_copy_arcs), the straight sides without one; with
 * POLYC_FLAG_NO_ARCS none, and the arc form is the polyline itself. */
static void test_arc_room(void **state)
{
    static const double loop[] = {1.2, 1.2, 7.8, 1.2, 7.8, 5.2, 1.2, 5.2, 1.2, 1.4};
    const double R = 7.0, w = 9.0, h = 6.0;
    double xy[2 * 4096], cy = h - sqrt(R * R - 0.25 * w * w);
    uint8_t smooth[4096];
    uint32_t n = 0;
    scansim_scene sc;
    (void)state;
    scansim_scene_init(&sc, "arc-room", 3u);
    sc.laser.beam_count = 361u;
    sc.laser.angle_step_rad = (float)(PI / 360.0);
    sc.laser.max_range_m = 15.0f;
    xy[0] = 0.0, xy[1] = 0.0, xy[2] = w, xy[3] = 0.0;
    smooth[0] = smooth[1] = 0;
    n = 2;
    /* from (w, h) round to (0, h) counter-clockwise about (w / 2, cy) */
    uint32_t m = scansim_arc_points(&xy[2 * n], 4000u, w / 2, cy, R, atan2(h - cy, w / 2),
                                    PI - atan2(h - cy, w / 2));
    for (uint32_t k = 0; k < m; k++)
        smooth[n + k] = k > 0 && k + 1 < m;
    n += m;
    assert_int_equal(scansim_add_wall_smooth(&sc, xy, n, 1, smooth), 0);
    assert_int_equal(scansim_add_path(&sc, loop, 5u, 0.1), 0);
    assert_int_equal(scansim_run(&sc), 0);
    for (int off = 0; off < 2; off++) {
        polyc_config cfg;
        void *block;
        polyc_config_default(&cfg);
        if (off)
            cfg.flags |= POLYC_FLAG_NO_ARCS;
        polyc_ctx *ctx = batch_map(&sc, &cfg, &block);
        check(polyc_find_curves(ctx), ctx, "polyc_find_curves");
        uint32_t arcs = 0, on_circle = 0;
        for (uint32_t i = 0; i < polyc_polyline_count(ctx); i++) {
            float pts[2 * 512], bul[512];
            uint32_t cnt = 0, closed = 0, full = 0;
            check(polyc_copy_arcs(ctx, i, NULL, NULL, 0, &cnt, NULL), ctx, "count");
            assert_int_equal(polyc_copy_arcs(ctx, i, pts, bul, cnt ? cnt - 1 : 0, &cnt, &closed),
                             cnt ? POLYC_ERR_NOMEM : POLYC_OK);
            check(polyc_copy_arcs(ctx, i, pts, bul, 512, &cnt, &closed), ctx, "polyc_copy_arcs");
            check(polyc_copy_polyline(ctx, i, NULL, 0, &full, NULL), ctx, "polyc_copy_polyline");
            assert_true(cnt <= full);
            if (off)
                assert_int_equal(cnt, full);
            for (uint32_t k = 0; k < cnt; k++) {
                if (bul[k] == 0.0f)
                    continue;
                assert_true(k + 1 < cnt || closed);
                double ccx, ccy, r, a0, sweep;
                curves_arc(&pts[2 * k], &pts[2 * ((k + 1) % cnt)], (double)bul[k], &ccx, &ccy, &r,
                           &a0, &sweep);
                arcs++;
                /* the room's arc: every point of it within 1 cm of the true
                 * circle (a short arc's radius is loose, its place is not) */
                double worst = 0.0;
                for (int q = 0; q <= 8; q++) {
                    double ang = a0 + sweep * q / 8.0;
                    double px = ccx + r * cos(ang), py = ccy + r * sin(ang);
                    worst = fmax(worst, fabs(hypot(px - w / 2, py - cy) - R));
                }
                on_circle += worst < 0.01;
            }
        }
        if (off) {
            assert_int_equal(arcs, 0);
            assert_int_equal(polyc_arc_count(ctx), 0);
        } else {
            assert_true(arcs >= 1);
            assert_int_equal(polyc_arc_count(ctx), arcs);
            if (on_circle != arcs)
                fail_msg("%u of %u arcs within 1 cm of the room's circle", on_circle, arcs);
        }
        free(block);
    }
    scansim_scene_free(&sc);
}

/* Straight rooms: no arc, no circle. */
static void test_straight_scenes(void **state)
{
    static const char *const kinds[] = {"square", "office", "angled"};
    (void)state;
    for (int kk = 0; kk < 3; kk++)
        for (uint64_t seed = 1; seed <= 3; seed++) {
            scansim_scene sc;
            polyc_config cfg;
            void *block;
            assert_int_equal(scansim_scene_builtin(&sc, kinds[kk], seed), 0);
            assert_int_equal(scansim_run(&sc), 0);
            polyc_config_default(&cfg);
            polyc_ctx *ctx = batch_map(&sc, &cfg, &block);
            check(polyc_find_curves(ctx), ctx, "polyc_find_curves");
            if (polyc_arc_count(ctx) || polyc_circle_count(ctx))
                fail_msg("%s seed %u: %u arcs, %u circles", kinds[kk], (unsigned)seed,
                         polyc_arc_count(ctx), polyc_circle_count(ctx));
            free(block);
            scansim_scene_free(&sc);
        }
}

static void test_errors(void **state)
{
    scansim_scene sc;
    polyc_config cfg;
    polyc_limits lim;
    polyc_ctx *ctx = NULL;
    polyc_circle c;
    (void)state;
    assert_int_equal(polyc_struct_size("polyc_circle"), sizeof(polyc_circle));
    assert_int_equal(polyc_find_curves(NULL), POLYC_ERR_NULL);
    pillar_scene(&sc, 0.0);
    polyc_config_default(&cfg);
    check(polyc_limits_for_scans(&cfg, sc.scans, sc.scan_count, &lim), NULL, "limits");
    size_t size = polyc_memory_size(&cfg, &lim);
    void *block = malloc(size);
    assert_non_null(block);
    check(polyc_init(block, size, &cfg, &lim, &ctx), NULL, "polyc_init");
    assert_int_equal(polyc_find_curves(ctx), POLYC_ERR_STATE); /* no polylines yet */
    assert_int_equal(polyc_get_circle(ctx, 0, &c), POLYC_ERR_STATE);
    assert_int_equal(polyc_circle_count(ctx), 0);
    for (uint32_t i = 0; i < sc.scan_count; i++)
        check(polyc_add_scan(ctx, &sc.scans[i]), ctx, "polyc_add_scan");
    check(polyc_build(ctx, NULL, NULL), ctx, "polyc_build");
    check(polyc_find_curves(ctx), ctx, "polyc_find_curves");
    assert_int_equal(polyc_get_circle(ctx, 0, NULL), POLYC_ERR_NULL);
    assert_int_equal(polyc_get_circle(ctx, polyc_polyline_count(ctx), &c), POLYC_ERR_RANGE);
    assert_int_equal(polyc_get_circle(NULL, 0, &c), POLYC_ERR_NULL);
    assert_int_equal(polyc_copy_arcs(ctx, polyc_polyline_count(ctx), NULL, NULL, 0, NULL, NULL),
                     POLYC_ERR_RANGE);
    assert_int_equal(polyc_copy_arcs(NULL, 0, NULL, NULL, 0, NULL, NULL), POLYC_ERR_NULL);
    /* the config check knows the flag */
    cfg.flags = POLYC_FLAG_NO_ARCS;
    assert_int_equal(polyc_config_check(&cfg, NULL), POLYC_OK);
    free(block);
    scansim_scene_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_batch_pillars),
        cmocka_unit_test(test_online_pillars),
        cmocka_unit_test(test_held_all_round),
        cmocka_unit_test(test_arc_room),
        cmocka_unit_test(test_straight_scenes),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
