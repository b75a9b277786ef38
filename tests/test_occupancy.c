/* test_occupancy.c - maps from an occupancy grid (polyc_add_grid).
 * A 6 m x 4 m room with a 1 m box inside, rasterised here into 5 cm cells of
 * a grid whose origin is turned by 0.3 rad (and other yaws), with unknown
 * cells outside the walls and inside the box: every wall is found, with a
 * vertex within a cell of each true corner, about one vertex per corner, in
 * the map frame. Then the thresholds, the grid queries, bad grids, grids and
 * scans mixed, too small blocks and limits, and the exhaustion sweep of
 * test_exhaustion.c on the grid route. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "polyc.h"

#define RES 0.05
#define GUARD 64
#define GUARD_BYTE 0xa5

/* ---- the scene -------------------------------------------------------- */

typedef struct wall {
    double x0, y0, x1, y1;
} wall;

static const wall WALLS[8] = {
    {0, 0, 6, 0}, {6, 0, 6, 4}, {6, 4, 0, 4}, {0, 4, 0, 0},                      /* room */
    {3.5, 1.5, 4.5, 1.5}, {4.5, 1.5, 4.5, 2.5}, {4.5, 2.5, 3.5, 2.5}, {3.5, 2.5, 3.5, 1.5}, /* box */
};
static const double CORNERS[8][2] = {{0, 0}, {6, 0}, {6, 4}, {0, 4},
                                     {3.5, 1.5}, {4.5, 1.5}, {4.5, 2.5}, {3.5, 2.5}};

static double wall_dist(const wall *w, double x, double y)
{
    double dx = w->x1 - w->x0, dy = w->y1 - w->y0;
    double t = ((x - w->x0) * dx + (y - w->y0) * dy) / (dx * dx + dy * dy);
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    return hypot(w->x0 + t * dx - x, w->y0 + t * dy - y);
}

static double scene_dist(double x, double y)
{
    double best = 1e9;
    for (int i = 0; i < 8; i++) {
        double d = wall_dist(&WALLS[i], x, y);
        best = d < best ? d : best;
    }
    return best;
}

/* A grid whose cells are `res` wide, turned by `yaw`, holding the room (in
 * the map frame) with 0.5 m to spare: a cell whose centre lies within
 * `thick_cells` cells of a wall is occupied (0.6: walls 1-2 cells thick, as
 * maps from SLAM draw them; 1.1: 2-3 cells), the room's other cells free,
 * all others unknown (-1). */
typedef struct scene {
    polyc_occupancy_grid grid;
    int8_t *cells;
    uint32_t occupied;
    uint32_t facing;           /* occupied cells that face free space (the data) */
} scene;

static int8_t cell_at(const scene *s, int64_t i, int64_t j)
{
    if (i < 0 || j < 0 || i >= (int64_t)s->grid.width || j >= (int64_t)s->grid.height)
        return -1;
    return s->cells[(size_t)j * s->grid.width + (size_t)i];
}

/* Occupied cells with a free cell at most 4 cells away along a row or a
 * column, only unknown cells between: the data points and the contour of a
 * grid (POLYC__FACE_CELLS). */
static uint32_t count_facing(const scene *s)
{
    static const int side[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    uint32_t n = 0;
    for (uint32_t j = 0; j < s->grid.height; j++)
        for (uint32_t i = 0; i < s->grid.width; i++) {
            if (cell_at(s, i, j) != 100)
                continue;
            int faces = 0;
            for (int e = 0; e < 4 && !faces; e++)
                for (int k = 1; k <= 4; k++) {
                    int8_t a = cell_at(s, (int64_t)i + k * side[e][0], (int64_t)j + k * side[e][1]);
                    faces = a == 0;
                    if (a != -1)
                        break;
                }
            n += (uint32_t)faces;
        }
    return n;
}

static void scene_make_thick(scene *s, double yaw, double res, double thick_cells)
{
    double c = cos(yaw), sn = sin(yaw), lo_x = 1e9, lo_y = 1e9, hi_x = -1e9, hi_y = -1e9;
    for (int k = 0; k < 4; k++) {
        double gx = c * CORNERS[k][0] + sn * CORNERS[k][1], gy = -sn * CORNERS[k][0] + c * CORNERS[k][1];
        lo_x = fmin(lo_x, gx);
        lo_y = fmin(lo_y, gy);
        hi_x = fmax(hi_x, gx);
        hi_y = fmax(hi_y, gy);
    }
    memset(s, 0, sizeof *s);
    double ax = lo_x - 0.5, ay = lo_y - 0.5; /* the corner in the grid's axes */
    s->grid.origin_x_m = c * ax - sn * ay;
    s->grid.origin_y_m = sn * ax + c * ay;
    s->grid.origin_yaw_rad = yaw;
    s->grid.resolution_m = (float)res;
    s->grid.width = (uint32_t)ceil((hi_x - lo_x + 1.0) / res);
    s->grid.height = (uint32_t)ceil((hi_y - lo_y + 1.0) / res);
    s->cells = malloc((size_t)s->grid.width * s->grid.height);
    assert_non_null(s->cells);
    for (uint32_t j = 0; j < s->grid.height; j++)
        for (uint32_t i = 0; i < s->grid.width; i++) {
            double gx = (i + 0.5) * res, gy = (j + 0.5) * res;
            double x = s->grid.origin_x_m + c * gx - sn * gy, y = s->grid.origin_y_m + sn * gx + c * gy;
            int8_t v = -1;
            if (scene_dist(x, y) <= thick_cells * res)
                v = 100;
            else if (x > 0 && x < 6 && y > 0 && y < 4 && !(x > 3.5 && x < 4.5 && y > 1.5 && y < 2.5))
                v = 0;
            s->occupied += v == 100;
            s->cells[(size_t)j * s->grid.width + i] = v;
        }
    s->grid.cells = s->cells;
    s->facing = count_facing(s);
}

static void scene_make(scene *s, double yaw, double res)
{
    scene_make_thick(s, yaw, res, 0.6);
}

static void scene_free(scene *s)
{
    free(s->cells);
    s->cells = NULL;
}

/* A context sized by polyc_limits_for_grid for `grid`. */
typedef struct opened {
    polyc_config cfg;
    polyc_limits lim;
    void *block;
    size_t size;
    polyc_ctx *ctx;
} opened;

static void open_for(opened *o, const polyc_occupancy_grid *grid)
{
    polyc_config_default(&o->cfg);
    assert_int_equal(polyc_limits_for_grid(&o->cfg, grid, &o->lim), POLYC_OK);
    o->size = polyc_memory_size(&o->cfg, &o->lim);
    assert_true(o->size > 0);
    o->block = malloc(o->size);
    assert_non_null(o->block);
    assert_int_equal(polyc_init(o->block, o->size, &o->cfg, &o->lim, &o->ctx), POLYC_OK);
}

static void close_opened(opened *o)
{
    free(o->block);
}

/* Distance from (x, y) to the nearest vertex of the map. */
static double nearest_vertex(const polyc_ctx *ctx, double x, double y)
{
    double best = 1e9;
    for (uint32_t i = 0; i < polyc_polyline_count(ctx); i++) {
        polyc_polyline pl;
        assert_int_equal(polyc_get_polyline(ctx, i, &pl), POLYC_OK);
        for (uint32_t k = 0; k < pl.point_count; k++) {
            double d = hypot((double)pl.xy_m[2 * k] - x, (double)pl.xy_m[2 * k + 1] - y);
            best = d < best ? d : best;
        }
    }
    return best;
}

/* Distance from (x, y) to the nearest segment of the map. */
static double nearest_segment(const polyc_ctx *ctx, double x, double y)
{
    double best = 1e9;
    for (uint32_t i = 0; i < polyc_polyline_count(ctx); i++) {
        polyc_polyline pl;
        assert_int_equal(polyc_get_polyline(ctx, i, &pl), POLYC_OK);
        uint32_t n = pl.point_count, segs = pl.closed ? n : n - 1;
        for (uint32_t k = 0; k < segs; k++) {
            wall w = {pl.xy_m[2 * k], pl.xy_m[2 * k + 1], pl.xy_m[2 * ((k + 1) % n)],
                      pl.xy_m[2 * ((k + 1) % n) + 1]};
            double d = (w.x0 == w.x1 && w.y0 == w.y1) ? hypot(w.x0 - x, w.y0 - y) : wall_dist(&w, x, y);
            best = d < best ? d : best;
        }
    }
    return best;
}

/* The room's corners and walls moved `face` towards the room's free space:
 * into the room, out of the box. */
static void faces_of(double face, wall *walls, double corners[8][2])
{
    for (int k = 0; k < 8; k++) {
        double side = k < 4 ? 1.0 : -1.0; /* into the room, or out of the box */
        double cx = k < 4 ? 3.0 : 4.0, cy = 2.0;
        corners[k][0] = CORNERS[k][0] + side * face * (CORNERS[k][0] < cx ? 1.0 : -1.0);
        corners[k][1] = CORNERS[k][1] + side * face * (CORNERS[k][1] < cy ? 1.0 : -1.0);
    }
    /* wall i runs from corner i to the next corner of its square */
    for (int i = 0; i < 8; i++) {
        int a = i, b = (i & ~3) + ((i + 1) & 3);
        walls[i] = (wall){corners[a][0], corners[a][1], corners[b][0], corners[b][1]};
    }
}

/* The map of the room: every wall face found (each point of it, every 5 cm,
 * within `res` of the map), a vertex within `res` of every corner, every
 * vertex within `res` of a wall face, 8 to 12 vertices in all. The faces lie
 * `face` from the walls' centre lines towards free space: the map follows
 * the occupied cells that face free space. */
static void check_room_faces(const polyc_ctx *ctx, double res, double face, const char *what)
{
    wall walls[8];
    double corners[8][2];
    faces_of(face, walls, corners);
    for (int i = 0; i < 8; i++) {
        const wall *w = &walls[i];
        double len = hypot(w->x1 - w->x0, w->y1 - w->y0);
        for (double t = 0.0; t <= len + 1e-9; t += 0.05) {
            double x = w->x0 + (w->x1 - w->x0) * t / len, y = w->y0 + (w->y1 - w->y0) * t / len;
            double d = nearest_segment(ctx, x, y);
            if (d > res)
                fail_msg("%s: wall %d at %.2f m: the map is %.1f mm away", what, i, t, d * 1e3);
        }
    }
    for (int k = 0; k < 8; k++) {
        double d = nearest_vertex(ctx, corners[k][0], corners[k][1]);
        if (d > res)
            fail_msg("%s: corner (%.1f, %.1f): nearest vertex %.1f mm away", what, CORNERS[k][0],
                     CORNERS[k][1], d * 1e3);
    }
    uint32_t vertices = 0;
    for (uint32_t i = 0; i < polyc_polyline_count(ctx); i++) {
        polyc_polyline pl;
        assert_int_equal(polyc_get_polyline(ctx, i, &pl), POLYC_OK);
        for (uint32_t k = 0; k < pl.point_count; k++) {
            double d = 1e9, x = pl.xy_m[2 * k], y = pl.xy_m[2 * k + 1];
            for (int w = 0; w < 8; w++)
                d = fmin(d, wall_dist(&walls[w], x, y));
            if (d > res)
                fail_msg("%s: vertex (%.3f, %.3f) is %.1f mm off every wall face", what, x, y,
                         d * 1e3);
        }
        vertices += pl.point_count;
    }
    if (vertices < 8 || vertices > 12)
        fail_msg("%s: %u vertices for 8 corners", what, vertices);
}

/* Walls 1-2 cells thick, their faces within a cell of the centre lines. */
static void check_room_map(const polyc_ctx *ctx, double res, const char *what)
{
    check_room_faces(ctx, res, 0.0, what);
}

/* ---- the room ------------------------------------------------------------ */

static void test_room_rotated_grid(void **state)
{
    (void)state;
    const double yaws[] = {0.3, 0.0, -2.0, 1.5707963267948966};
    for (size_t k = 0; k < sizeof yaws / sizeof yaws[0]; k++) {
        scene s;
        opened o;
        char what[48];
        snprintf(what, sizeof what, "yaw %.2f", yaws[k]);
        scene_make(&s, yaws[k], RES);
        open_for(&o, &s.grid);
        assert_int_equal(polyc_add_grid(o.ctx, &s.grid), POLYC_OK);
        polyc_status st = polyc_build(o.ctx, NULL, NULL);
        if (st != POLYC_OK)
            fail_msg("%s: %s (%s)", what, polyc_status_str(st), polyc_last_error(o.ctx));
        check_room_map(o.ctx, RES, what);
        polyc_stats stats;
        assert_int_equal(polyc_get_stats(o.ctx, &stats), POLYC_OK);
        assert_int_equal(stats.data_points, s.facing);
        assert_int_equal(stats.weighted_points, s.facing);
        assert_true(s.facing > 0 && s.facing < s.occupied);
        assert_int_equal(stats.scans, 0);
        assert_int_equal(stats.beams, 0);
        assert_int_equal(stats.grid_width, s.grid.width);
        assert_int_equal(stats.grid_height, s.grid.height);
        assert_true(stats.contour_cells > 0 && stats.contour_cells <= s.occupied);
        assert_true(stats.initial_vertices >= stats.vertices);
        assert_true(stats.iterations > 0);
        assert_true(stats.memory_used_bytes <= stats.memory_size_bytes);
        assert_true(isfinite(stats.bic));
        /* two closed polylines: the room and the box */
        assert_int_equal(polyc_polyline_count(o.ctx), 2);
        for (uint32_t i = 0; i < 2; i++) {
            polyc_polyline pl;
            assert_int_equal(polyc_get_polyline(o.ctx, i, &pl), POLYC_OK);
            assert_int_equal(pl.closed, 1);
        }
        close_opened(&o);
        scene_free(&s);
    }
}

/* The same room at other resolutions and with thicker walls: the same
 * corners (alpha is weighed by the resolution, docs/algorithm.md). */
static void test_room_resolutions(void **state)
{
    (void)state;
    const double res[] = {0.025, 0.1, 0.15, 0.05};
    for (size_t k = 0; k < sizeof res / sizeof res[0]; k++)
        for (int thick = 0; thick < 2; thick++) {
            scene s;
            opened o;
            char what[64];
            snprintf(what, sizeof what, "%.3f m cells, walls %s", res[k], thick ? "2-3 cells" : "1-2 cells");
            scene_make_thick(&s, 0.7, res[k], thick ? 1.1 : 0.6);
            open_for(&o, &s.grid);
            assert_int_equal(polyc_add_grid(o.ctx, &s.grid), POLYC_OK);
            polyc_status st = polyc_build(o.ctx, NULL, NULL);
            if (st != POLYC_OK)
                fail_msg("%s: %s (%s)", what, polyc_status_str(st), polyc_last_error(o.ctx));
            /* walls 2-3 cells thick (cells within 1.1 cells of the centre
             * line occupied): the cells facing free space lie about 0.6 of a
             * cell from the centre line, and the map on them within a cell */
            check_room_faces(o.ctx, res[k], thick ? 0.6 * res[k] : 0.0, what);
            close_opened(&o);
            scene_free(&s);
        }
}

/* The same grid twice gives the same map; the stages can be rerun. */
static void test_stages_and_determinism(void **state)
{
    (void)state;
    scene s;
    opened a, b;
    scene_make(&s, 0.3, RES);
    open_for(&a, &s.grid);
    open_for(&b, &s.grid);
    assert_int_equal(polyc_add_grid(a.ctx, &s.grid), POLYC_OK);
    assert_int_equal(polyc_add_grid(b.ctx, &s.grid), POLYC_OK);
    /* the caller's cells are not needed after the call */
    memset(s.cells, 0x7f, (size_t)s.grid.width * s.grid.height);
    assert_int_equal(polyc_build(a.ctx, NULL, NULL), POLYC_OK);
    assert_int_equal(polyc_trace(b.ctx), POLYC_OK);
    polyc_stats traced;
    assert_int_equal(polyc_get_stats(b.ctx, &traced), POLYC_OK);
    double bic0, err0;
    assert_int_equal(polyc_score(b.ctx, &bic0, &err0), POLYC_OK);
    assert_true(polyc_polyline_count(b.ctx) >= 2);
    assert_int_equal(polyc_optimize(b.ctx, NULL, NULL), POLYC_OK);
    uint32_t n = polyc_polyline_count(a.ctx);
    assert_int_equal(polyc_polyline_count(b.ctx), n);
    for (uint32_t i = 0; i < n; i++) {
        polyc_polyline pa, pb;
        assert_int_equal(polyc_get_polyline(a.ctx, i, &pa), POLYC_OK);
        assert_int_equal(polyc_get_polyline(b.ctx, i, &pb), POLYC_OK);
        assert_int_equal(pa.point_count, pb.point_count);
        assert_memory_equal(pa.xy_m, pb.xy_m, (size_t)pa.point_count * 2 * sizeof(float));
    }
    double bic1, err1;
    assert_int_equal(polyc_score(b.ctx, &bic1, &err1), POLYC_OK);
    assert_true(bic1 < bic0);
    /* polyc_build_grid drops the results; the grid is still there */
    assert_int_equal(polyc_build_grid(b.ctx), POLYC_OK);
    assert_int_equal(polyc_polyline_count(b.ctx), 0);
    assert_int_equal(polyc_extract_contour(b.ctx), POLYC_OK);
    assert_int_equal(polyc_trace(b.ctx), POLYC_OK);
    polyc_stats again;
    assert_int_equal(polyc_get_stats(b.ctx, &again), POLYC_OK);
    assert_int_equal(again.initial_vertices, traced.initial_vertices);
    assert_int_equal(again.contour_cells, traced.contour_cells);
    assert_int_equal(polyc_build(b.ctx, NULL, NULL), POLYC_OK);
    check_room_map(b.ctx, RES, "rebuilt");
    close_opened(&a);
    close_opened(&b);
    scene_free(&s);
}

/* ---- thresholds and the grid queries ------------------------------------ */

/* A 40 x 40 grid at 0.1 m, origin (2, 3), yaw 0: unknown but for a free
 * square (cells 5..34) holding an occupied block of 3 x 10 cells (10..12,
 * 15..24) and, in row 30, values 64 and 65 and a cell of 65 beside 20. */
static int8_t small_cells[40 * 40];

static polyc_occupancy_grid small_grid(void)
{
    for (int j = 0; j < 40; j++)
        for (int i = 0; i < 40; i++) {
            int8_t v = -1;
            if (i >= 5 && i < 35 && j >= 5 && j < 35)
                v = 0;
            if (i >= 10 && i <= 12 && j >= 15 && j <= 24)
                v = 100;
            small_cells[j * 40 + i] = v;
        }
    small_cells[30 * 40 + 20] = 64;
    small_cells[30 * 40 + 22] = 65;
    /* a cell of 65 whose every neighbour is 20 (unknown), free beyond them:
     * occupied, and contour (it faces free space through the unknown ring,
     * as a wall in a log's hit/miss grid does through the cells its grazing
     * beams leave between the thresholds) */
    for (int k = 0; k < 9; k++)
        small_cells[(32 + k / 3 - 1) * 40 + 30 + k % 3 - 1] = 20;
    small_cells[32 * 40 + 30] = 65;
    polyc_occupancy_grid g;
    memset(&g, 0, sizeof g);
    g.width = g.height = 40;
    g.resolution_m = 0.1f;
    g.origin_x_m = 2.0;
    g.origin_y_m = 3.0;
    g.cells = small_cells;
    return g;
}

static void cell(const polyc_ctx *ctx, uint32_t i, uint32_t j, uint32_t hits, uint32_t misses,
                 uint32_t contour)
{
    uint32_t h = 9, m = 9, c = 9;
    assert_int_equal(polyc_grid_cell(ctx, i, j, &h, &m, &c), POLYC_OK);
    if (h != hits || m != misses || c != contour)
        fail_msg("cell (%u, %u): hits %u misses %u contour %u, expected %u %u %u", i, j, h, m, c,
                 hits, misses, contour);
}

static void test_thresholds_and_queries(void **state)
{
    (void)state;
    polyc_occupancy_grid g = small_grid();
    opened o;
    open_for(&o, &g);
    assert_int_equal(o.lim.max_beams, 30 + 2);  /* the block, 65 twice */
    assert_int_equal(o.lim.max_scans, 0);
    assert_int_equal(polyc_add_grid(o.ctx, &g), POLYC_OK);
    double ox, oy;
    float cm;
    uint32_t w, h;
    assert_int_equal(polyc_grid_info(o.ctx, &ox, &oy, &cm, &w, &h), POLYC_OK);
    assert_true(ox == 2.0 && oy == 3.0 && cm == 0.1f && w == 40 && h == 40);
    cell(o.ctx, 10, 15, 1, 0, 1);   /* the block's corner */
    cell(o.ctx, 11, 20, 1, 0, 0);   /* its middle column: no free side */
    cell(o.ctx, 12, 20, 1, 0, 1);
    cell(o.ctx, 13, 20, 0, 1, 0);   /* free */
    cell(o.ctx, 20, 30, 0, 0, 0);   /* 64: neither free nor occupied */
    cell(o.ctx, 22, 30, 1, 0, 1);   /* 65: occupied, free beside it */
    cell(o.ctx, 30, 32, 1, 0, 1);   /* 65 among 20s, free beyond: contour */
    cell(o.ctx, 1, 1, 0, 0, 0);     /* unknown, in a tile with occupied cells */
    uint32_t u;
    assert_int_equal(polyc_grid_cell(o.ctx, 40, 0, &u, &u, &u), POLYC_ERR_RANGE);
    polyc_stats st;
    assert_int_equal(polyc_build(o.ctx, NULL, NULL), POLYC_OK);
    assert_int_equal(polyc_get_stats(o.ctx, &st), POLYC_OK);
    /* the occupied cells that face free space: the 3 x 10 box but the 8
     * cells inside it, the cell of 65 in row 30 and the one in the ring */
    assert_int_equal(st.data_points, 24);
    assert_int_equal(st.contour_cells, 2 * 10 + 2 + 1 + 1);
    /* the block's polyline lies on it, in the map frame: x 3.0..3.3, y 4.5..5.5 */
    assert_true(polyc_polyline_count(o.ctx) >= 1);
    double block = nearest_vertex(o.ctx, 3.15, 5.0);
    assert_true(block < 0.6);
    close_opened(&o);

    /* occupied from 50 on, free up to 30: the 64 is occupied, the 20s free */
    polyc_config cfg;
    polyc_config_default(&cfg);
    cfg.occupied_thresh = 0.5f;
    cfg.free_thresh = 0.3f;
    polyc_limits lim;
    assert_int_equal(polyc_limits_for_grid(&cfg, &g, &lim), POLYC_OK);
    assert_int_equal(lim.max_beams, 30 + 3);
    size_t size = polyc_memory_size(&cfg, &lim);
    void *block_mem = malloc(size);
    polyc_ctx *ctx;
    assert_int_equal(polyc_init(block_mem, size, &cfg, &lim, &ctx), POLYC_OK);
    assert_int_equal(polyc_add_grid(ctx, &g), POLYC_OK);
    cell(ctx, 20, 30, 1, 0, 1);
    cell(ctx, 30, 32, 1, 0, 1);
    cell(ctx, 29, 32, 0, 1, 0);
    free(block_mem);

    /* thresholds out of range */
    const float bad[][2] = {{0.0f, 0.0f}, {1.5f, 0.1f}, {NAN, 0.1f}, {0.5f, 0.5f}, {0.5f, 0.7f},
                            {0.5f, -0.1f}, {0.5f, NAN}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        polyc_config_default(&cfg);
        cfg.occupied_thresh = bad[k][0];
        cfg.free_thresh = bad[k][1];
        const char *why = NULL;
        assert_int_equal(polyc_config_check(&cfg, &why), POLYC_ERR_CONFIG);
        assert_non_null(why);
        assert_true(strstr(why, "thresh") != NULL);
        assert_int_equal(polyc_limits_for_grid(&cfg, &g, &lim), POLYC_ERR_CONFIG);
    }
    polyc_config_default(&cfg);
    assert_true(cfg.occupied_thresh == 0.65f && cfg.free_thresh == 0.196f);
}

/* ---- bad grids ----------------------------------------------------------- */

typedef struct bad_case {
    const char *what;
    polyc_status status;
    int field;
} bad_case;

enum { B_RES_ZERO, B_RES_NEG, B_RES_NAN, B_RES_INF, B_WIDTH0, B_HEIGHT0, B_V101, B_VM2, B_V127,
       B_VM128, B_NULL, B_RESERVED, B_ORIGIN_NAN, B_YAW_INF, B_EXTENT, B_CASES };

static polyc_occupancy_grid spoil(polyc_occupancy_grid g, int k, int8_t *cells, size_t n)
{
    memcpy(cells, g.cells, n);
    g.cells = cells;
    switch (k) {
    case B_RES_ZERO: g.resolution_m = 0.0f; break;
    case B_RES_NEG: g.resolution_m = -0.05f; break;
    case B_RES_NAN: g.resolution_m = NAN; break;
    case B_RES_INF: g.resolution_m = INFINITY; break;
    case B_WIDTH0: g.width = 0; break;
    case B_HEIGHT0: g.height = 0; break;
    case B_V101: cells[n / 2] = 101; break;
    case B_VM2: cells[n - 1] = -2; break;
    case B_V127: cells[0] = 127; break;
    case B_VM128: cells[7] = -128; break;
    case B_NULL: g.cells = NULL; break;
    case B_RESERVED: g.reserved = 1; break;
    case B_ORIGIN_NAN: g.origin_y_m = NAN; break;
    case B_YAW_INF: g.origin_yaw_rad = INFINITY; break;
    default: g.resolution_m = 60.0f; break; /* 40 cells of 60 m: over max_extent_m */
    }
    return g;
}

static void test_bad_grids(void **state)
{
    (void)state;
    polyc_occupancy_grid good = small_grid();
    opened o;
    open_for(&o, &good);
    int8_t cells[40 * 40];
    for (int k = 0; k < B_CASES; k++) {
        polyc_occupancy_grid g = spoil(good, k, cells, sizeof cells);
        polyc_status want = k == B_NULL ? POLYC_ERR_NULL : k == B_EXTENT ? POLYC_ERR_EXTENT
                                                                         : POLYC_ERR_CONFIG;
        polyc_limits lim;
        polyc_status st = polyc_limits_for_grid(&o.cfg, &g, &lim);
        if (st != want)
            fail_msg("case %d: polyc_limits_for_grid gave %s", k, polyc_status_str(st));
        st = polyc_add_grid(o.ctx, &g);
        if (st != want)
            fail_msg("case %d: polyc_add_grid gave %s", k, polyc_status_str(st));
        const char *msg = polyc_last_error(o.ctx);
        if (strlen(msg) == 0)
            fail_msg("case %d: no message", k);
        if ((k <= B_RES_INF && !strstr(msg, "resolution")) ||
            (k >= B_V101 && k <= B_VM128 && !strstr(msg, "-1..100")) ||
            (k == B_NULL && !strstr(msg, "NULL")) || (k == B_RESERVED && !strstr(msg, "reserved")))
            fail_msg("case %d: message '%s'", k, msg);
        /* refused, nothing added: the context takes the good grid after it */
        polyc_stats st0;
        assert_int_equal(polyc_get_stats(o.ctx, &st0), POLYC_OK);
        assert_int_equal(st0.contour_cells, 0);
    }
    assert_int_equal(polyc_add_grid(o.ctx, NULL), POLYC_ERR_NULL);
    assert_int_equal(polyc_add_grid(NULL, &good), POLYC_ERR_NULL);
    polyc_limits lim;
    assert_int_equal(polyc_limits_for_grid(NULL, &good, &lim), POLYC_ERR_NULL);
    assert_int_equal(polyc_limits_for_grid(&o.cfg, NULL, &lim), POLYC_ERR_NULL);
    assert_int_equal(polyc_limits_for_grid(&o.cfg, &good, NULL), POLYC_ERR_NULL);
    assert_int_equal(polyc_add_grid(o.ctx, &good), POLYC_OK);
    assert_int_equal(polyc_build(o.ctx, NULL, NULL), POLYC_OK);
    assert_true(polyc_polyline_count(o.ctx) >= 1);
    close_opened(&o);
}

/* ---- one kind of input per context --------------------------------------- */

static polyc_scan wall_scan(float *ranges, uint32_t n)
{
    polyc_scan s;
    memset(&s, 0, sizeof s);
    s.pose_x_m = 3.0;
    s.pose_y_m = 4.0;
    s.start_angle_rad = -0.6f;
    s.angle_step_rad = 1.2f / (float)(n - 1);
    s.min_range_m = 0.02f;
    s.max_range_m = 30.0f;
    s.beam_count = n;
    s.range_m = ranges;
    for (uint32_t i = 0; i < n; i++)
        ranges[i] = (float)(1.5 / cos(-0.6 + 1.2 * i / (n - 1)));
    return s;
}

static void test_one_kind_of_input(void **state)
{
    (void)state;
    polyc_occupancy_grid g = small_grid();
    float ranges[61];
    polyc_scan scan = wall_scan(ranges, 61);
    /* limits for both, one block */
    polyc_config cfg;
    polyc_config_default(&cfg);
    polyc_limits lg, ls;
    assert_int_equal(polyc_limits_for_grid(&cfg, &g, &lg), POLYC_OK);
    assert_int_equal(polyc_limits_for_scans(&cfg, &scan, 1, &ls), POLYC_OK);
    polyc_limits lim = ls;
    lim.max_beams = ls.max_beams > lg.max_beams ? ls.max_beams : lg.max_beams;
    lim.max_grid_cells = ls.max_grid_cells > lg.max_grid_cells ? ls.max_grid_cells : lg.max_grid_cells;
    lim.max_vertices = lim.max_points = 0;
    size_t size = polyc_memory_size(&cfg, &lim);
    void *block = malloc(size);
    polyc_ctx *ctx;
    assert_int_equal(polyc_init(block, size, &cfg, &lim, &ctx), POLYC_OK);

    /* scans, then a grid */
    assert_int_equal(polyc_add_scan(ctx, &scan), POLYC_OK);
    assert_int_equal(polyc_add_grid(ctx, &g), POLYC_ERR_STATE);
    assert_true(strstr(polyc_last_error(ctx), "scans") != NULL);
    assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK);
    assert_int_equal(polyc_add_grid(ctx, &g), POLYC_ERR_STATE);
    assert_true(polyc_polyline_count(ctx) >= 1); /* the scan's map is kept */

    /* a grid, then a scan, then a second grid */
    assert_int_equal(polyc_reset(ctx), POLYC_OK);
    assert_int_equal(polyc_add_grid(ctx, &g), POLYC_OK);
    assert_int_equal(polyc_add_scan(ctx, &scan), POLYC_ERR_STATE);
    assert_true(strstr(polyc_last_error(ctx), "grid") != NULL);
    assert_int_equal(polyc_add_grid(ctx, &g), POLYC_ERR_STATE);
    assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK);
    polyc_stats st;
    assert_int_equal(polyc_get_stats(ctx, &st), POLYC_OK);
    assert_int_equal(st.data_points, 24); /* as in test_thresholds_and_queries */
    assert_int_equal(st.scans, 0);
    assert_int_equal(polyc_add_grid(ctx, &g), POLYC_ERR_STATE);

    /* after a reset, scans again: the grid's frame is gone */
    assert_int_equal(polyc_reset(ctx), POLYC_OK);
    assert_int_equal(polyc_add_scan(ctx, &scan), POLYC_OK);
    assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK);
    /* the wall 1.5 m ahead of (3, 4): x = 4.5 */
    polyc_polyline pl;
    assert_int_equal(polyc_get_polyline(ctx, 0, &pl), POLYC_OK);
    assert_true(fabsf(pl.xy_m[0] - 4.5f) < 0.05f);
    free(block);
}

/* ---- too small ------------------------------------------------------------ */

static void test_too_small(void **state)
{
    (void)state;
    scene s;
    scene_make(&s, 0.3, RES);
    polyc_config cfg;
    polyc_config_default(&cfg);
    polyc_limits full;
    assert_int_equal(polyc_limits_for_grid(&cfg, &s.grid, &full), POLYC_OK);
    assert_int_equal(full.max_beams, s.occupied);
    size_t need = polyc_memory_size(&cfg, &full);
    void *block = malloc(need);
    polyc_ctx *ctx = NULL;
    /* a block too small */
    assert_int_equal(polyc_init(block, need - 1, &cfg, &full, &ctx), POLYC_ERR_NOMEM);
    assert_null(ctx);
    /* fewer beams (occupied cells) than the grid has: LIMIT, at add time */
    polyc_limits lim = full;
    lim.max_beams = s.occupied - 1;
    size_t size = polyc_memory_size(&cfg, &lim);
    assert_int_equal(polyc_init(block, size, &cfg, &lim, &ctx), POLYC_OK);
    assert_int_equal(polyc_add_grid(ctx, &s.grid), POLYC_ERR_LIMIT);
    assert_true(strstr(polyc_last_error(ctx), "max_beams") != NULL);
    assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK); /* empty */
    assert_int_equal(polyc_polyline_count(ctx), 0);
    /* too few grid cells: NOMEM, as for scans */
    lim = full;
    lim.max_grid_cells = 4 * 1024;
    size = polyc_memory_size(&cfg, &lim);
    assert_int_equal(polyc_init(block, size, &cfg, &lim, &ctx), POLYC_OK);
    assert_int_equal(polyc_add_grid(ctx, &s.grid), POLYC_ERR_NOMEM);
    assert_true(strstr(polyc_last_error(ctx), "max_grid_cells") != NULL);
    /* too few vertices: the trace runs out; too few points: the optimiser */
    for (int k = 0; k < 2; k++) {
        lim = full;
        if (k == 0)
            lim.max_vertices = 6;
        else
            lim.max_points = 100;
        size = polyc_memory_size(&cfg, &lim);
        assert_int_equal(polyc_init(block, size, &cfg, &lim, &ctx), POLYC_OK);
        assert_int_equal(polyc_add_grid(ctx, &s.grid), POLYC_OK);
        assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_ERR_NOMEM);
        assert_true(strlen(polyc_last_error(ctx)) > 0);
        if (k == 1) /* the traced map is the result */
            assert_true(polyc_polyline_count(ctx) >= 2);
    }
    /* the full limits build in exactly the queried size, also after the
     * empty context has been built and a grid refused */
    assert_int_equal(polyc_init(block, need, &cfg, &full, &ctx), POLYC_OK);
    assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK);
    polyc_occupancy_grid bad = s.grid;
    bad.reserved = 7;
    assert_int_equal(polyc_add_grid(ctx, &bad), POLYC_ERR_CONFIG);
    assert_int_equal(polyc_add_grid(ctx, &s.grid), POLYC_OK);
    assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK);
    check_room_map(ctx, RES, "exact block");
    free(block);
    scene_free(&s);
}

/* ---- exhaustion (as tests/test_exhaustion.c) ------------------------------ */

/* The room in a block of `size` bytes at offset `skew`, guard bytes on both
 * sides; returns the first status that is not OK. */
static polyc_status run_guarded(const polyc_occupancy_grid *grid, const polyc_config *cfg,
                                const polyc_limits *lim, size_t size, size_t skew, const char *what)
{
    unsigned char *raw = malloc(size + skew + 2 * GUARD);
    assert_non_null(raw);
    memset(raw, GUARD_BYTE, size + skew + 2 * GUARD);
    unsigned char *blk = raw + GUARD + skew;
    polyc_ctx *ctx = NULL;
    polyc_status st = polyc_init(blk, size, cfg, lim, &ctx);
    if (st == POLYC_OK) {
        st = polyc_add_grid(ctx, grid);
        if (st == POLYC_OK)
            st = polyc_build(ctx, NULL, NULL);
        if (st != POLYC_OK && st != POLYC_ERR_NOMEM && st != POLYC_ERR_LIMIT)
            fail_msg("%s: %s (%s)", what, polyc_status_str(st), polyc_last_error(ctx));
        if (st != POLYC_OK && polyc_last_error(ctx)[0] == '\0')
            fail_msg("%s: %s without a message", what, polyc_status_str(st));
        polyc_stats stats;
        memset(&stats, 0, sizeof stats);
        assert_int_equal(polyc_get_stats(ctx, &stats), POLYC_OK);
        assert_true(stats.memory_used_bytes <= stats.memory_size_bytes);
        for (uint32_t i = 0; i < polyc_polyline_count(ctx); i++) {
            polyc_polyline pl;
            assert_int_equal(polyc_get_polyline(ctx, i, &pl), POLYC_OK);
        }
        if (st != POLYC_OK) {
            /* still usable: empty, then the small grid if it fits */
            assert_int_equal(polyc_reset(ctx), POLYC_OK);
            assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK);
            assert_int_equal(polyc_polyline_count(ctx), 0);
        }
    } else if (st != POLYC_ERR_NOMEM || ctx != NULL) {
        fail_msg("%s: polyc_init gave %s", what, polyc_status_str(st));
    }
    for (size_t i = 0; i < GUARD + skew; i++)
        if (raw[i] != GUARD_BYTE)
            fail_msg("%s: byte %zu before the block written", what, GUARD + skew - i);
    for (size_t i = 0; i < GUARD; i++)
        if (blk[size + i] != GUARD_BYTE)
            fail_msg("%s: byte %zu after the block written", what, i);
    free(raw);
    return st;
}

static void test_exhaustion(void **state)
{
    (void)state;
    scene s;
    scene_make(&s, 0.3, 0.1); /* 10 cm cells: a smaller grid, the same rules */
    polyc_config cfg;
    polyc_config_default(&cfg);
    cfg.max_iterations = 3;
    polyc_limits full;
    assert_int_equal(polyc_limits_for_grid(&cfg, &s.grid, &full), POLYC_OK);
    size_t need = polyc_memory_size(&cfg, &full);
    char what[96];
    uint32_t ok = 0, runs = 0;
    for (uint32_t k = 0; k <= 120; k++, runs++) {
        size_t size = k == 120 ? need : (size_t)((double)need * k / 120.0);
        snprintf(what, sizeof what, "block %zu of %zu", size, need);
        polyc_status st = run_guarded(&s.grid, &cfg, &full, size, k % 16, what);
        if (size >= need && st != POLYC_OK)
            fail_msg("%s: the queried size is not enough", what);
        ok += st == POLYC_OK;
    }
    assert_int_equal(ok, 1);
    /* each limit from nothing to enough */
    uint32_t nomem = 0, limit = 0;
    for (int f = 0; f < 5; f++) {
        for (uint32_t k = 0; k <= 24; k++, runs++) {
            polyc_limits lim = full;
            uint32_t *field = f == 0 ? &lim.max_scans : f == 1 ? &lim.max_beams
                            : f == 2 ? &lim.max_grid_cells : f == 3 ? &lim.max_vertices
                                                                   : &lim.max_points;
            uint32_t top = *field;
            *field = k < 4 ? k : (uint32_t)((uint64_t)top * (k - 3) / 21);
            snprintf(what, sizeof what, "limit %d = %u of %u", f, *field, top);
            size_t size = polyc_memory_size(&cfg, &lim);
            assert_true(size > 0);
            polyc_status st = run_guarded(&s.grid, &cfg, &lim, size, 0, what);
            nomem += st == POLYC_ERR_NOMEM;
            limit += st == POLYC_ERR_LIMIT;
            if (*field >= top && st != POLYC_OK)
                fail_msg("%s: the full limits fail: %s", what, polyc_status_str(st));
        }
    }
    assert_true(nomem > 0 && limit > 0);
    print_message("%u runs: %u out of memory, %u over a limit\n", runs, nomem, limit);
    scene_free(&s);
}

/* The room in a corner of a 80 m x 80 m grid that is unknown elsewhere:
 * the limits store the tiles that hold occupied cells (and the directory of
 * all tiles), not the whole grid, and the map is the same room. */
static void test_sparse_grid(void **state)
{
    (void)state;
    scene s;
    scene_make(&s, 0.3, RES);
    const uint32_t side = 1600, at_x = 700, at_y = 900;
    int8_t *big = malloc((size_t)side * side);
    assert_non_null(big);
    memset(big, -1, (size_t)side * side);
    for (uint32_t j = 0; j < s.grid.height; j++)
        memcpy(big + (size_t)(j + at_y) * side + at_x, s.cells + (size_t)j * s.grid.width, s.grid.width);
    polyc_occupancy_grid g = s.grid;
    double c = cos(0.3), sn = sin(0.3), dx = at_x * RES, dy = at_y * RES;
    g.origin_x_m -= c * dx - sn * dy;
    g.origin_y_m -= sn * dx + c * dy;
    g.width = g.height = side;
    g.cells = big;
    opened o;
    open_for(&o, &g);
    uint32_t all_tiles = (side / 32) * (side / 32);
    assert_true(o.lim.max_grid_cells / 1024 < all_tiles / 2);
    assert_int_equal(polyc_add_grid(o.ctx, &g), POLYC_OK);
    assert_int_equal(polyc_build(o.ctx, NULL, NULL), POLYC_OK);
    check_room_map(o.ctx, RES, "sparse grid");
    polyc_stats st;
    assert_int_equal(polyc_get_stats(o.ctx, &st), POLYC_OK);
    assert_int_equal(st.grid_width, side);
    assert_true(st.grid_tiles < 64);
    close_opened(&o);
    free(big);
    scene_free(&s);
}

/* A grid with nothing occupied: no polylines, no error. */
static void test_empty_grid(void **state)
{
    (void)state;
    int8_t cells[64 * 48];
    memset(cells, 0, sizeof cells);
    cells[5] = -1;
    polyc_occupancy_grid g;
    memset(&g, 0, sizeof g);
    g.width = 64;
    g.height = 48;
    g.resolution_m = 0.05f;
    g.cells = cells;
    opened o;
    open_for(&o, &g);
    assert_int_equal(o.lim.max_beams, 0);
    assert_int_equal(polyc_add_grid(o.ctx, &g), POLYC_OK);
    assert_int_equal(polyc_build(o.ctx, NULL, NULL), POLYC_OK);
    assert_int_equal(polyc_polyline_count(o.ctx), 0);
    polyc_stats st;
    assert_int_equal(polyc_get_stats(o.ctx, &st), POLYC_OK);
    assert_int_equal(st.data_points, 0);
    assert_int_equal(st.grid_tiles, 0);
    close_opened(&o);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_room_rotated_grid),
        cmocka_unit_test(test_room_resolutions),
        cmocka_unit_test(test_stages_and_determinism),
        cmocka_unit_test(test_thresholds_and_queries),
        cmocka_unit_test(test_bad_grids),
        cmocka_unit_test(test_one_kind_of_input),
        cmocka_unit_test(test_too_small),
        cmocka_unit_test(test_exhaustion),
        cmocka_unit_test(test_sparse_grid),
        cmocka_unit_test(test_empty_grid),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
