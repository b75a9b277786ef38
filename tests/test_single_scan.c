/* test_single_scan.c - maps from one scan: initial polylines from the beam
 * order (src/trace/scan_chains.c) and the beams as constraints on the optimiser
 * (src/search/ray_check.c). Scenes come from tools/eval/scansim, scored along the beams
 * by tools/eval/gtscore (f and ray RMSE, as docs/evaluation.md defines them).
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gtscore.h"
#include "optimize.h"
#include "polyc.h"
#include "scansim.h"

#define PI 3.14159265358979
#define PIF 3.14159265f

typedef struct one_map {
    scansim_scene scene;
    void *block;
    polyc_ctx *ctx;
    polyc_stats stats;
    gtscore_scan_score score;
    double worst_short_m;      /* largest (map range - measured range) < 0 ... */
    double worst_long_m;       /* ... and > 0, over the hits */
} one_map;

/* A 6 m x 4 m room with a 40 cm box in it, seen once from (1, 2). */
static void room_with_box(scansim_scene *sc)
{
    scansim_scene_init(sc, "room", 5u);
    assert_int_equal(scansim_add_box(sc, 0.0, 0.0, 6.0, 4.0), 0);
    assert_int_equal(scansim_add_box(sc, 2.6, 1.4, 3.0, 1.8), 0);
    assert_int_equal(scansim_add_pose(sc, 1.0, 2.0, 0.1), 0);
    scansim_transform(sc, 0.4, 3.0, -1.0);
}

/* A scanner over a full turn (720 beams), the beam list starting and
 * ending in the middle of a wall: in the room with its box (whose shadow
 * cuts the wall behind it), and in the room alone. */
static void laser_full_turn(scansim_scene *sc)
{
    sc->laser.beam_count = 720u;
    sc->laser.start_angle_rad = (float)-PI;
    sc->laser.angle_step_rad = (float)(PI / 360.0);
}

static void room_full_turn(scansim_scene *sc)
{
    room_with_box(sc);
    laser_full_turn(sc);
}

static void empty_room_full_turn(scansim_scene *sc)
{
    scansim_scene_init(sc, "empty room", 5u);
    assert_int_equal(scansim_add_box(sc, 0.0, 0.0, 6.0, 4.0), 0);
    assert_int_equal(scansim_add_pose(sc, 1.0, 2.0, 0.1), 0);
    scansim_transform(sc, 0.4, 3.0, -1.0);
    laser_full_turn(sc);
}

/* A 1.6 m wide corridor, 30 m long, seen once from near one end along it. */
static void corridor(scansim_scene *sc)
{
    scansim_scene_init(sc, "corridor", 9u);
    const double left[4] = {-1.0, 1.6, 29.0, 1.6}, right[4] = {-1.0, 0.0, 29.0, 0.0};
    assert_int_equal(scansim_add_wall(sc, left, 2, 0), 0);
    assert_int_equal(scansim_add_wall(sc, right, 2, 0), 0);
    sc->laser.max_range_m = 20.0f;
    assert_int_equal(scansim_add_pose(sc, 0.0, 0.8, 0.0), 0);
}

/* Thin posts (2 cm, 6 cm apart) 60 cm in front of a 0.5-degree scanner, a
 * wall 5 m behind them: at that range a grid cell spans almost three beams,
 * and most beams pass between the posts to the wall. */
static void posts(scansim_scene *sc)
{
    scansim_scene_init(sc, "posts", 11u);
    sc->laser.beam_count = 361u;
    sc->laser.angle_step_rad = (float)(PI / 360.0);
    const double wall[4] = {-6.0, 5.6, 6.0, 5.6};
    assert_int_equal(scansim_add_wall(sc, wall, 2, 0), 0);
    for (int k = 0; k < 8; k++)
        assert_int_equal(scansim_add_box(sc, -0.25 + 0.06 * k, 0.6, -0.23 + 0.06 * k, 0.62), 0);
    assert_int_equal(scansim_add_pose(sc, 0.0, 0.0, PI / 2.0), 0);
}

static void build(one_map *m, const polyc_config *config)
{
    polyc_limits lim;
    assert_int_equal(scansim_run(&m->scene), 0);
    assert_int_equal(m->scene.scan_count, 1);
    const polyc_scan *scan = &m->scene.scans[0];
    assert_int_equal(polyc_limits_for_scans(config, scan, 1, &lim), POLYC_OK);
    size_t size = polyc_memory_size(config, &lim);
    assert_true(size > 0);
    m->block = malloc(size);
    assert_non_null(m->block);
    assert_int_equal(polyc_init(m->block, size, config, &lim, &m->ctx), POLYC_OK);
    assert_int_equal(polyc_add_scan(m->ctx, scan), POLYC_OK);
    polyc_status st = polyc_build(m->ctx, NULL, NULL);
    if (st != POLYC_OK)
        fail_msg("polyc_build: %s (%s)", polyc_status_str(st), polyc_last_error(m->ctx));
    assert_int_equal(polyc_get_stats(m->ctx, &m->stats), POLYC_OK);

    /* score along the beams */
    uint32_t n = polyc_polyline_count(m->ctx);
    polyc_polyline *lines = calloc(n ? n : 1u, sizeof *lines);
    assert_non_null(lines);
    for (uint32_t i = 0; i < n; i++)
        assert_int_equal(polyc_get_polyline(m->ctx, i, &lines[i]), POLYC_OK);
    gtscore_index map;
    gtscore_index_init(&map);
    assert_int_equal(gtscore_index_add_polylines(&map, lines, n), 0);
    assert_int_equal(gtscore_index_build(&map, 0.1), 0);
    memset(&m->score, 0, sizeof m->score);
    gtscore_score_scan(&map, scan, &m->score);
    m->worst_short_m = m->worst_long_m = 0.0;
    for (uint32_t i = 0; i < scan->beam_count; i++) {
        if (!gtscore_beam_reflected(scan, i))
            continue;
        double a = scan->pose_theta_rad + (double)scan->start_angle_rad +
                   (double)i * (double)scan->angle_step_rad;
        double r = gtscore_index_ray(&map, scan->pose_x_m, scan->pose_y_m, a,
                                     (double)scan->max_range_m);
        if (!isfinite(r))
            continue;
        double e = r - (double)scan->range_m[i];
        if (e < m->worst_short_m)
            m->worst_short_m = e;
        if (e > m->worst_long_m)
            m->worst_long_m = e;
    }
    gtscore_index_free(&map);
    free(lines);
    print_message("%s: %u polylines, %u vertices (initial %u/%u), f %.4f, ray RMSE %.1f mm, "
                  "worst %.0f / +%.0f mm\n",
                  m->scene.name, m->stats.polylines, m->stats.vertices,
                  m->stats.initial_polylines, m->stats.initial_vertices, m->score.f,
                  1e3 * m->score.ray_rmse_m, 1e3 * m->worst_short_m, 1e3 * m->worst_long_m);
}

/* Simulates `scene` into m and builds its map: defaults, with `iterations`
 * (UINT32_MAX: the default) and `flags`. */
static void scene_map(one_map *m, void (*scene)(scansim_scene *), uint32_t iterations,
                      uint32_t flags)
{
    memset(m, 0, sizeof *m);
    scene(&m->scene);
    polyc_config c;
    polyc_config_default(&c);
    if (iterations != UINT32_MAX)
        c.max_iterations = iterations;
    c.flags = flags;
    build(m, &c);
}

static void done(one_map *m)
{
    free(m->block);
    scansim_scene_free(&m->scene);
}

/* Initial polylines: every return is on the map, within the range noise
 * along its beam, and the box is not joined to the wall behind it (such a
 * segment would stop the beams that pass beside the box). The contour is
 * not computed for them. */
static void test_chains_follow_the_beams(void **state)
{
    (void)state;
    one_map m;
    scene_map(&m, room_with_box, 0, 0);
    assert_true(m.score.f >= 0.99);
    assert_true(m.score.ray_rmse_m <= 0.02);
    assert_true(m.worst_short_m > -0.05);
    assert_int_equal(m.stats.contour_cells, 0);
    assert_true(m.stats.polylines >= 2); /* the box apart from the room */
    done(&m);
}

/* Near returns do not stop the beams beside them: a chain's end, or a lone
 * return's segment, reaches half a beam spacing past its return, never a
 * neighbouring beam (it reached half a cell: at 60 cm, over two beams). */
static void test_near_returns_leave_gaps(void **state)
{
    (void)state;
    one_map m;
    scene_map(&m, posts, 0, 0);
    assert_true(m.score.f >= 0.99);
    assert_true(m.worst_short_m > -0.05);
    assert_true(m.score.ray_rmse_m <= 0.02);
    done(&m);
    scene_map(&m, posts, UINT32_MAX, 0);
    assert_true(m.score.f >= 0.95);
    assert_true(m.worst_short_m > -(double)POLYC__RAY_TOLERANCE_M - 0.03);
    assert_true(m.score.ray_rmse_m <= 0.04);
    done(&m);
}

/* The initial polylines of `scene`: `chains` of them, every beam on the map. */
static void check_chains(void (*scene)(scansim_scene *), uint32_t chains)
{
    one_map m;
    scene_map(&m, scene, 0, 0);
    assert_int_equal(m.stats.polylines, chains);
    assert_true(m.score.f >= 0.99);
    done(&m);
}

/* Beams whose return lies in front (the posts) do not break the chain of
 * the wall behind them: 8 posts and one wall. */
static void test_occluders_do_not_break_chains(void **state)
{
    (void)state;
    check_chains(posts, 9);
}

/* A context for one hand-made scan with config c, the scan added; the
 * caller frees *block. */
static polyc_ctx *open_one_scan(const polyc_scan *scan, const polyc_config *c, void **block)
{
    polyc_limits lim;
    polyc_ctx *ctx;
    assert_int_equal(polyc_limits_for_scans(c, scan, 1, &lim), POLYC_OK);
    size_t size = polyc_memory_size(c, &lim);
    *block = malloc(size);
    assert_non_null(*block);
    assert_int_equal(polyc_init(*block, size, c, &lim, &ctx), POLYC_OK);
    assert_int_equal(polyc_add_scan(ctx, scan), POLYC_OK);
    return ctx;
}

/* Hits receding along the beams behind a near object are not a wall seen at
 * a grazing angle: a 0.5-degree scan whose beam 79 returns at 2.4 m, beams
 * 80-86 at 0.9 m (the object), and beams 87 and 88 on the line from beam
 * 79's return to a point 1 m out on beam 89. Beam 79 stays out of their
 * chain. */
static void test_no_grazing_link_behind_occluders(void **state)
{
    (void)state;
    enum { N = 361 };
    float range[N];
    const double step = PI / 360.0, start = -PI / 2.0;
    double ax = 2.4 * cos(start + 79 * step), ay = 2.4 * sin(start + 79 * step);
    double qx = 1.0 * cos(start + 89 * step), qy = 1.0 * sin(start + 89 * step);
    for (int i = 0; i < N; i++)
        range[i] = 5.0f;
    range[79] = 2.4f;
    for (int i = 80; i <= 86; i++)
        range[i] = 0.9f;
    for (int i = 87; i <= 88; i++) {
        /* where beam i meets the line a-q */
        double c = cos(start + i * step), sn = sin(start + i * step);
        double ex = qx - ax, ey = qy - ay;
        range[i] = (float)((ax * ey - ay * ex) / (c * ey - sn * ex));
    }
    polyc_scan scan;
    memset(&scan, 0, sizeof scan);
    scan.start_angle_rad = (float)start;
    scan.angle_step_rad = (float)step;
    scan.min_range_m = 0.05f;
    scan.max_range_m = 30.0f;
    scan.beam_count = N;
    scan.range_m = range;
    polyc_config c;
    void *block;
    polyc_config_default(&c);
    polyc_ctx *ctx = open_one_scan(&scan, &c, &block);
    assert_int_equal(polyc_build_grid(ctx), POLYC_OK);
    assert_int_equal(polyc_trace(ctx), POLYC_OK);
    double bx = (double)range[88] * cos(start + 88 * step), by = (double)range[88] * sin(start + 88 * step);
    int found88 = 0;
    for (uint32_t l = 0; l < polyc_polyline_count(ctx); l++) {
        polyc_polyline pl;
        assert_int_equal(polyc_get_polyline(ctx, l, &pl), POLYC_OK);
        int near79 = 0, near88 = 0;
        for (uint32_t k = 0; k < pl.point_count; k++) {
            double x = pl.xy_m[2 * k], y = pl.xy_m[2 * k + 1];
            near79 |= hypot(x - ax, y - ay) < 0.05;
            near88 |= hypot(x - bx, y - by) < 0.05;
        }
        found88 |= near88;
        assert_false(near79 && near88);
    }
    assert_true(found88);
    free(block);
}

/* A wall seen at grazing angles is one chain, not a string of single hits. */
static void test_grazing_wall_is_one_chain(void **state)
{
    (void)state;
    check_chains(corridor, 2);
}

/* A chain that runs outwards along the beams (returns at 0.55 m on four
 * beams, then 0.95 and 1.25 m on the next two, 1 degree apart, as a chair
 * or a door leaf seen edge-on): its fitted line runs within 3 degrees of
 * the last beam, which crosses it far past the return. The chain ends in a
 * stub across that beam through its return, so the beam meets the map
 * there, before and after the optimiser (on edmonton's scan 283 that beam
 * met the map 13.5 m behind its return). */
static void test_chain_end_along_beams(void **state)
{
    (void)state;
    enum { N = 180 };
    float range[N];
    const float near[6] = {0.55f, 0.55f, 0.55f, 0.55f, 0.95f, 1.25f};
    for (int i = 0; i < N; i++)
        range[i] = 50.0f;
    for (int i = 0; i < 6; i++)
        range[12 + i] = near[i];
    polyc_scan scan;
    memset(&scan, 0, sizeof scan);
    scan.pose_theta_rad = 0.3;
    scan.start_angle_rad = (float)(-PI / 2.0);
    scan.angle_step_rad = (float)(PI / 180.0);
    scan.min_range_m = 0.05f;
    scan.max_range_m = 50.0f;
    scan.beam_count = N;
    scan.range_m = range;
    for (int pass = 0; pass < 2; pass++) {
        polyc_config c;
        void *block;
        polyc_config_default(&c);
        if (pass == 0)
            c.max_iterations = 0; /* the chains as traced */
        polyc_ctx *ctx = open_one_scan(&scan, &c, &block);
        assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK);
        uint32_t n = polyc_polyline_count(ctx);
        polyc_polyline *lines = calloc(n ? n : 1u, sizeof *lines);
        assert_non_null(lines);
        for (uint32_t l = 0; l < n; l++)
            assert_int_equal(polyc_get_polyline(ctx, l, &lines[l]), POLYC_OK);
        gtscore_index map;
        gtscore_index_init(&map);
        assert_int_equal(gtscore_index_add_polylines(&map, lines, n), 0);
        assert_int_equal(gtscore_index_build(&map, 0.1), 0);
        for (int i = 12; i < 18; i++) {
            double a = scan.pose_theta_rad + (double)scan.start_angle_rad +
                       (double)i * (double)scan.angle_step_rad;
            double r = gtscore_index_ray(&map, 0.0, 0.0, a, 50.0);
            if (!(fabs(r - (double)range[i]) <= (double)POLYC__RAY_TOLERANCE_M))
                fail_msg("%s: beam %d meets the map at %.3f m, its return at %.3f m",
                         pass ? "optimised" : "traced", i, r, (double)range[i]);
        }
        gtscore_index_free(&map);
        free(lines);
        free(block);
    }
}

/* Initial chains drop the vertices Douglas-Peucker keeps on range noise:
 * each corridor wall (1 cm noise, seen along 15 m) is one segment
 * (Douglas-Peucker alone keeps 10 vertices a wall), and the room keeps its
 * corners: two pieces of wall around the box's shadow with a corner each
 * (6 vertices), the box's near face (2), and its other face, seen edge-on,
 * as 3 cm of a chain of its own (2; 1 if the faces come as one chain).
 * Every return stays on the map. */
static void test_chains_drop_noise_vertices(void **state)
{
    (void)state;
    one_map m;
    scene_map(&m, corridor, 0, 0);
    assert_int_equal(m.stats.initial_polylines, 2);
    assert_int_equal(m.stats.initial_vertices, 4);
    assert_true(m.score.f >= 0.99);
    assert_true(m.worst_short_m > -(double)POLYC__RAY_TOLERANCE_M);
    done(&m);
    scene_map(&m, room_with_box, 0, 0);
    assert_in_range(m.stats.initial_vertices, 9, 10);
    assert_true(m.score.f >= 0.99);
    assert_true(m.worst_short_m > -(double)POLYC__RAY_TOLERANCE_M);
    done(&m);
}

/* The optimised map of one scan: compact (at most `most` vertices, and no
 * more than it started with), and still true along the beams: no segment
 * in front of a return, f and ray RMSE at the project's targets (f >= 0.95,
 * RMSE <= 4 cm); and since no edit may lose a return, f >= 0.99 and no beam
 * passing its return to meet the map behind it. */
static void check_optimised(void (*scene)(scansim_scene *), uint32_t most)
{
    one_map m;
    scene_map(&m, scene, UINT32_MAX, 0);
    assert_true(m.stats.iterations > 0);
    assert_true(m.stats.vertices <= m.stats.initial_vertices);
    assert_true(m.stats.vertices <= most);
    assert_true(m.score.f >= 0.95);
    assert_true(m.score.ray_rmse_m <= 0.04);
    assert_true(m.worst_short_m > -(double)POLYC__RAY_TOLERANCE_M - 0.03);
    /* nor does any beam pass its return to meet the map farther on */
    assert_true(m.worst_long_m < (double)POLYC__RAY_TOLERANCE_M + 0.03);
    assert_true(m.score.f >= 0.99);
    done(&m);
}

static void test_optimised_room(void **state)
{
    (void)state;
    check_optimised(room_with_box, 10);
}

/* A full turn has no seam where the beam list wraps: the empty room's
 * walls are one closed ring (they were an open polyline whose two ends met
 * behind the scanner), and in the room with the box no open polyline's
 * ends meet. */
static void check_full_turn(void (*scene)(scansim_scene *), uint32_t rings)
{
    one_map m;
    scene_map(&m, scene, UINT32_MAX, 0);
    uint32_t n = polyc_polyline_count(m.ctx), closed = 0, ring_vertices = 0;
    for (uint32_t i = 0; i < n; i++) {
        polyc_polyline pl;
        assert_int_equal(polyc_get_polyline(m.ctx, i, &pl), POLYC_OK);
        if (pl.closed) {
            closed++;
            ring_vertices = pl.point_count;
        } else {
            /* an open polyline's ends do not meet (a ring cut open) */
            float dx = pl.xy_m[0] - pl.xy_m[2 * pl.point_count - 2];
            float dy = pl.xy_m[1] - pl.xy_m[2 * pl.point_count - 1];
            assert_true(dx * dx + dy * dy > 0.05f * 0.05f);
        }
    }
    print_message("%s over a full turn: %u polylines, %u closed (%u vertices), f %.4f\n",
                  m.scene.name, n, closed, ring_vertices, m.score.f);
    assert_int_equal(closed, rings);
    assert_true(rings == 0 || (ring_vertices >= 4 && ring_vertices <= 8));
    assert_true(m.score.f >= 0.99);
    done(&m);
}

static void test_full_turn_is_one_ring(void **state)
{
    (void)state;
    check_full_turn(empty_room_full_turn, 1);
    check_full_turn(room_full_turn, 0);
}

static void test_optimised_corridor(void **state)
{
    (void)state;
    check_optimised(corridor, 4);
}

/* POLYC_FLAG_GRID_TRACE keeps the paper's contour trace for one scan. */
static void test_grid_trace_flag(void **state)
{
    (void)state;
    one_map m;
    scene_map(&m, room_with_box, 0, POLYC_FLAG_GRID_TRACE);
    assert_true(m.stats.contour_cells > 0);
    /* and the contour is there on request in the default mode too */
    assert_int_equal(polyc_extract_contour(m.ctx), POLYC_OK);
    done(&m);

    scene_map(&m, room_with_box, 0, 0);
    assert_int_equal(m.stats.contour_cells, 0);
    assert_int_equal(polyc_extract_contour(m.ctx), POLYC_OK);
    assert_int_equal(polyc_get_stats(m.ctx, &m.stats), POLYC_OK);
    assert_true(m.stats.contour_cells > 0);
    done(&m);
}

/* A contour asked for in a one-scan context is released by the trace: the
 * chains take its room (polyc_memory_size charges the larger of the two,
 * not both), so the block's high-water mark is the map's own, the grid
 * keeps its contour bits, and the map is the one built without it. */
static void test_chains_take_the_contour_room(void **state)
{
    (void)state;
    one_map m;
    scene_map(&m, room_with_box, UINT32_MAX, 0);
    uint32_t vertices = m.stats.vertices;
    uint64_t used = m.stats.memory_used_bytes;
    assert_int_equal(polyc_extract_contour(m.ctx), POLYC_OK);
    uint32_t w = 0, h = 0, cx = 0, cy = 0, found = 0;
    assert_int_equal(polyc_grid_info(m.ctx, NULL, NULL, NULL, &w, &h), POLYC_OK);
    for (uint32_t y = 0; y < h && !found; y++)
        for (uint32_t x = 0; x < w && !found; x++) {
            uint32_t hits, misses, contour;
            assert_int_equal(polyc_grid_cell(m.ctx, x, y, &hits, &misses, &contour), POLYC_OK);
            if (contour) {
                cx = x;
                cy = y;
                found = 1;
            }
        }
    assert_true(found);
    assert_int_equal(polyc_trace(m.ctx), POLYC_OK);
    uint32_t hits, misses, contour = 0;
    assert_int_equal(polyc_grid_cell(m.ctx, cx, cy, &hits, &misses, &contour), POLYC_OK);
    assert_int_equal(contour, 1);
    assert_int_equal(polyc_optimize(m.ctx, NULL, NULL), POLYC_OK);
    assert_int_equal(polyc_get_stats(m.ctx, &m.stats), POLYC_OK);
    assert_int_equal(m.stats.vertices, vertices);
    assert_int_equal(m.stats.memory_used_bytes, used);
    done(&m);
}

/* polyc__blocks_beams on hand cases: a scan whose every return is at 2 m. */
/* A full turn of 360 beams from the origin, every return at 2 m but for
 * what the caller changes in `range`. */
static void full_turn(polyc__rays *r, float *range)
{
    for (int i = 0; i < 360; i++)
        range[i] = 2.0f;
    memset(r, 0, sizeof *r);
    r->on = 1;
    r->base = 0.0;
    r->step = 2.0f * PIF / 360.0f;
    r->step_cos = cosf(r->step);
    r->step_sin = sinf(r->step);
    r->count = 360;
    r->turn = 360;
    r->range = range;
    r->min_m = 0.1f;
    r->max_m = 30.0f;
    r->tol_m = POLYC__RAY_TOLERANCE_M;
    r->own_m = 0.15f;
}

static void test_blocks_beams(void **state)
{
    (void)state;
    float range[360];
    polyc__rays r;
    full_turn(&r, range);
    range[10] = 50.0f; /* no return (>= max) */
    /* in front of the returns: blocks */
    assert_true(polyc__blocks_beams(&r, 1.0f, -0.2f, 1.0f, 0.2f, NULL, 0));
    /* on them, or within the tolerance: fine */
    assert_false(polyc__blocks_beams(&r, 2.0f, -0.2f, 2.0f, 0.2f, NULL, 0));
    assert_false(polyc__blocks_beams(&r, 1.95f, -0.2f, 1.95f, 0.2f, NULL, 0));
    /* behind its own returns by more than the tolerance: a misfit */
    assert_true(polyc__blocks_beams(&r, 2.13f, -0.2f, 2.13f, 0.2f, NULL, 0));
    /* far behind: some other returns' business */
    assert_false(polyc__blocks_beams(&r, 3.0f, -0.2f, 3.0f, 0.2f, NULL, 0));
    /* unless a segment the edit replaces met those returns: they would lose
     * their wall (as on a wall seen at a grazing angle, where a return can
     * lie beyond the search radius of the new line and metres before it
     * along its beam) */
    const float own_xy[8] = {5.0f, 5.0f, 5.0f, 6.0f, 2.0f, -0.2f, 2.0f, 0.2f};
    assert_true(polyc__blocks_beams(&r, 3.0f, -0.2f, 3.0f, 0.2f, own_xy, 2));
    assert_false(polyc__blocks_beams(&r, 3.0f, -0.2f, 3.0f, 0.2f, own_xy, 1));
    const float far_xy[4] = {3.5f, -0.2f, 3.5f, 0.2f};
    assert_false(polyc__blocks_beams(&r, 3.0f, -0.2f, 3.0f, 0.2f, far_xy, 1));
    /* across the seam of the turn (beams 359 and 0) and at 180 degrees */
    assert_true(polyc__blocks_beams(&r, 1.0f, 0.05f, 1.0f, -0.05f, NULL, 0));
    assert_true(polyc__blocks_beams(&r, -1.0f, 0.1f, -1.0f, -0.1f, NULL, 0));
    /* only the no-return beam crosses it: nothing proven */
    float a = 10.0f * r.step;
    assert_false(polyc__blocks_beams(&r, cosf(a) - 0.01f * sinf(a), sinf(a) + 0.01f * cosf(a),
                                     cosf(a) + 0.01f * sinf(a), sinf(a) - 0.01f * cosf(a), NULL, 0));
    /* a 180-degree scan sees nothing behind it */
    r.base = -0.5f * PIF;
    r.count = 181;
    r.step = PIF / 180.0f;
    r.step_cos = cosf(r.step);
    r.step_sin = sinf(r.step);
    assert_false(polyc__blocks_beams(&r, -1.0f, 0.1f, -1.0f, -0.1f, NULL, 0));
    assert_true(polyc__blocks_beams(&r, 1.0f, -0.2f, 1.0f, 0.2f, NULL, 0));
    r.on = 0;
    assert_false(polyc__blocks_beams(&r, 1.0f, -0.2f, 1.0f, 0.2f, NULL, 0));
}

/* Which segments hold a return (an end segment that does may not go). */
static void test_holds_returns(void **state)
{
    (void)state;
    float range[360];
    polyc__rays r;
    full_turn(&r, range);
    range[5] = 50.0f;  /* no return */
    range[90] = 25.0f; /* far: held all the same */
    /* across the beams at their returns, or within the tolerance */
    assert_true(polyc__holds_returns(&r, 2.0f, -0.05f, 2.0f, 0.05f));
    assert_true(polyc__holds_returns(&r, 2.08f, -0.05f, 2.08f, 0.05f));
    /* in front of them or behind them: not theirs */
    assert_false(polyc__holds_returns(&r, 1.5f, -0.05f, 1.5f, 0.05f));
    assert_false(polyc__holds_returns(&r, 2.5f, -0.05f, 2.5f, 0.05f));
    /* along a beam through its return: held too */
    assert_true(polyc__holds_returns(&r, 1.95f, 0.0f, 2.05f, 0.0001f));
    /* a no-return beam holds nothing; a far return is held */
    float a = 5.0f * r.step, e = 90.0f * r.step;
    assert_false(polyc__holds_returns(&r, 2.0f * cosf(a) - 0.005f * sinf(a),
                                      2.0f * sinf(a) + 0.005f * cosf(a),
                                      2.0f * cosf(a) + 0.005f * sinf(a),
                                      2.0f * sinf(a) - 0.005f * cosf(a)));
    assert_true(polyc__holds_returns(&r, 25.0f * cosf(e) - 0.05f * sinf(e),
                                     25.0f * sinf(e) + 0.05f * cosf(e),
                                     25.0f * cosf(e) + 0.05f * sinf(e),
                                     25.0f * sinf(e) - 0.05f * cosf(e)));
    r.on = 0;
    assert_false(polyc__holds_returns(&r, 2.0f, -0.05f, 2.0f, 0.05f));
}

/* An edit may not leave a return its old segments held without a new
 * segment that meets its beam within the tolerance. */
static void test_loses_returns(void **state)
{
    (void)state;
    float range[360];
    polyc__rays r;
    full_turn(&r, range);
    const float old_xy[4] = {2.0f, -0.05f, 2.0f, 0.05f};
    const float same[4] = {2.0f, -0.05f, 2.0f, 0.05f};
    const float near[4] = {2.05f, -0.06f, 1.98f, 0.06f}; /* within the tolerance */
    const float short_xy[4] = {2.0f, 0.01f, 2.0f, 0.05f};  /* beam 0 passes below it */
    const float behind[4] = {2.5f, -0.06f, 2.5f, 0.06f};
    assert_false(polyc__loses_returns(&r, old_xy, 1, same, 1));
    assert_false(polyc__loses_returns(&r, old_xy, 1, near, 1));
    assert_true(polyc__loses_returns(&r, old_xy, 1, short_xy, 1));
    assert_true(polyc__loses_returns(&r, old_xy, 1, behind, 1));
    assert_true(polyc__loses_returns(&r, old_xy, 1, NULL, 0));
    /* two new segments sharing the returns */
    const float split[8] = {2.0f, -0.05f, 2.0f, 0.0f, 2.0f, 0.0f, 2.0f, 0.05f};
    assert_false(polyc__loses_returns(&r, old_xy, 1, split, 2));
    r.on = 0;
    assert_false(polyc__loses_returns(&r, old_xy, 1, NULL, 0));
}

/* One dense scan close to its walls: 100,000 beams over a full turn, every
 * range the same (a robot in a round tank of 1 m and of 2 m radius): more
 * returns than the grid has cells, so the one-scan path sums them by cell.
 * With the limits polyc_limits_for_scans gives, the map is made (it ran out
 * of points at any block size) and lies on the circle. */
static void test_dense_scan_maps(void **state)
{
    (void)state;
    const uint32_t n = 100000;
    float *r = malloc(n * sizeof *r);
    assert_non_null(r);
    for (int k = 0; k < 2; k++) {
        float radius = k == 0 ? 1.0f : 2.0f;
        for (uint32_t i = 0; i < n; i++)
            r[i] = radius;
        polyc_scan s;
        memset(&s, 0, sizeof s);
        s.start_angle_rad = -PIF;
        s.angle_step_rad = 2.0f * PIF / (float)n;
        s.min_range_m = 0.02f;
        s.max_range_m = 30.0f;
        s.beam_count = n;
        s.range_m = r;
        polyc_config c;
        polyc_limits lim;
        polyc_config_default(&c);
        assert_int_equal(polyc_limits_for_scans(&c, &s, 1, &lim), POLYC_OK);
        size_t size = polyc_memory_size(&c, &lim);
        void *block = malloc(size);
        assert_non_null(block);
        polyc_ctx *ctx;
        assert_int_equal(polyc_init(block, size, &c, &lim, &ctx), POLYC_OK);
        assert_int_equal(polyc_add_scan(ctx, &s), POLYC_OK);
        polyc_status st = polyc_build(ctx, NULL, NULL);
        if (st != POLYC_OK)
            fail_msg("radius %.0f m: %s (%s)", (double)radius, polyc_status_str(st),
                     polyc_last_error(ctx));
        uint32_t lines = polyc_polyline_count(ctx), verts = 0, closed = 0;
        double worst = 0.0;
        for (uint32_t l = 0; l < lines; l++) {
            polyc_polyline pl;
            assert_int_equal(polyc_get_polyline(ctx, l, &pl), POLYC_OK);
            closed += pl.closed != 0;
            for (uint32_t v = 0; v < pl.point_count; v++) {
                double d = fabs(hypot((double)pl.xy_m[2 * v], (double)pl.xy_m[2 * v + 1]) - (double)radius);
                worst = d > worst ? d : worst;
                verts++;
            }
        }
        print_message("radius %.0f m, 100,000 beams: %u polylines (%u closed), %u vertices, "
                      "within %.1f mm of the circle\n",
                      (double)radius, lines, closed, verts, 1e3 * worst);
        /* a full turn round one wall: one ring, no seam where the beams wrap */
        assert_true(lines == 1 && closed == 1 && verts >= 8);
        /* vertices outside the circle by the chords' sag: a 16-gon's at 1 m
         * is 19 mm; the wall's cells are 2.5 cm */
        assert_true(worst < 0.025);
        free(block);
    }
    free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_blocks_beams),
        cmocka_unit_test(test_holds_returns),
        cmocka_unit_test(test_loses_returns),
        cmocka_unit_test(test_occluders_do_not_break_chains),
        cmocka_unit_test(test_no_grazing_link_behind_occluders),
        cmocka_unit_test(test_chains_follow_the_beams),
        cmocka_unit_test(test_grazing_wall_is_one_chain),
        cmocka_unit_test(test_chain_end_along_beams),
        cmocka_unit_test(test_chains_drop_noise_vertices),
        cmocka_unit_test(test_near_returns_leave_gaps),
        cmocka_unit_test(test_optimised_room),
        cmocka_unit_test(test_optimised_corridor),
        cmocka_unit_test(test_grid_trace_flag),
        cmocka_unit_test(test_chains_take_the_contour_room),
        cmocka_unit_test(test_dense_scan_maps),
        cmocka_unit_test(test_full_turn_is_one_ring),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
