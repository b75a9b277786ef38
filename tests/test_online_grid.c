/* test_online_grid.c - an online grid's misses in tiles it has not stored
 * yet (src/grid/grid.c, "an online grid's misses in tiles not stored"): a person
 * who steps into a round room that the robot has been seeing through is
 * free in the grid once the person's tile is stored, as in a batch grid of
 * the same scans; its tile has the batch's counts, cell by cell; and when
 * the pool of records is spent the context still maps (those misses are
 * lost, as the documented fallback says); and after pose corrections, the
 * counts are those of the true poses and, with every scan kept, the contour
 * is the batch contour of the true poses. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "online.h"

#define BEAMS 360u
#define PI 3.14159265358979323846

typedef struct room {
    double radius_m;           /* a round room around (0, 0) */
    int person;                /* a disc of PERSON_R at (PERSON_X, 0) */
    double turn;               /* the first beam's angle past -pi */
    float range[BEAMS];
    polyc_scan scan;
} room;

#define PERSON_X 2.0
#define PERSON_R 0.2

/* The scan from (0, 0), heading 0: the wall, or the person in front of it. */
static const polyc_scan *room_scan(room *r)
{
    for (uint32_t i = 0; i < BEAMS; i++) {
        double a = r->turn - PI + (double)i * (2.0 * PI / BEAMS);
        double range = r->radius_m;
        /* the ray against the person's disc: |t (cos a, sin a) - (X, 0)| = R */
        double b = PERSON_X * cos(a), c = PERSON_X * PERSON_X - PERSON_R * PERSON_R;
        if (r->person && b * b > c && b - sqrt(b * b - c) > 0.0)
            range = b - sqrt(b * b - c);
        r->range[i] = (float)range;
    }
    memset(&r->scan, 0, sizeof r->scan);
    r->scan.start_angle_rad = (float)(r->turn - PI);
    r->scan.angle_step_rad = (float)(2.0 * PI / BEAMS);
    r->scan.min_range_m = 0.05f;
    r->scan.max_range_m = 30.0f;
    r->scan.beam_count = BEAMS;
    r->scan.range_m = r->range;
    return &r->scan;
}

typedef struct online {
    void *block;
    polyc_ctx *ctx;
} online;

static void open_keeping(online *o, double area_m, uint32_t max_tiles, uint32_t keep)
{
    polyc_config cfg;
    polyc_config_default(&cfg);
    polyc_online_limits lim;
    assert_int_equal(polyc_online_limits_for_area(&cfg, area_m, BEAMS, &lim), POLYC_OK);
    if (max_tiles)
        lim.max_grid_cells = max_tiles * POLYC__TILE_CELLS;
    lim.keep_scans = keep;
    lim.keep_beams = keep * BEAMS;
    size_t n = polyc_online_memory_size(&cfg, &lim);
    assert_true(n > 0);
    o->block = malloc(n);
    assert_non_null(o->block);
    assert_int_equal(polyc_online_init(o->block, n, &cfg, &lim, &o->ctx), POLYC_OK);
}

static void open_online(online *o, double area_m, uint32_t max_tiles)
{
    open_keeping(o, area_m, max_tiles, 0);
}

/* The cell of the online grid at (x, y) metres: its counts; 0 if its tile
 * is not stored. */
static int cell_at(const polyc_ctx *ctx, double x, double y, unsigned *hits, unsigned *misses)
{
    const polyc__grid *g = &ctx->grid;
    int32_t ix = (int32_t)floor((x - g->origin_x_m) / (double)g->cell_m);
    int32_t iy = (int32_t)floor((y - g->origin_y_m) / (double)g->cell_m);
    const polyc__tile *t = polyc__grid_tile(g, ix, iy);
    if (!t)
        return 0;
    *hits = t->hits[polyc__cell_index(ix, iy)];
    *misses = t->misses[polyc__cell_index(ix, iy)];
    return 1;
}

/* The cell with the most hits within 5 cm of (x, y): its counts. */
static void most_hit_near(const polyc_ctx *ctx, double x, double y, unsigned *hits, unsigned *misses)
{
    *hits = *misses = 0;
    for (double dy = -0.05; dy <= 0.05; dy += 0.0125)
        for (double dx = -0.05; dx <= 0.05; dx += 0.0125) {
            unsigned h, m;
            if (cell_at(ctx, x + dx, y + dy, &h, &m) && h > *hits) {
                *hits = h;
                *misses = m;
            }
        }
}

static void test_person_in_a_room_seen_through(void **state)
{
    (void)state;
    room r = {4.0, 0, 0.0, {0}, {0, 0, 0, 0, 0, 0, 0, 0, 0, NULL}};
    online o;
    open_online(&o, 12.0, 0);
    unsigned h = 0, m = 0;
    /* 20 scans through the empty room: the person's tile is not stored */
    for (int k = 0; k < 20; k++)
        assert_int_equal(polyc_online_add_scan(o.ctx, room_scan(&r), 0, NULL), POLYC_OK);
    assert_false(cell_at(o.ctx, PERSON_X - PERSON_R + 0.01, 0.0, &h, &m));
    /* then 3 with the person standing there: the tile is stored, and the
     * cells the person's front lies in keep the 20 scans' misses */
    r.person = 1;
    for (int k = 0; k < 3; k++)
        assert_int_equal(polyc_online_add_scan(o.ctx, room_scan(&r), 0, NULL), POLYC_OK);
    most_hit_near(o.ctx, PERSON_X - PERSON_R, 0.0, &h, &m);
    print_message("the person's front: %u hits, %u misses\n", h, m);
    assert_true(h >= 3);
    assert_true(m >= 20);
    assert_true(m > h); /* free, as in a batch grid of the 23 scans */
    polyc_online_report rep;
    assert_int_equal(polyc_online_update(o.ctx, POLYC_ONLINE_WORK_DEFAULT, &rep), POLYC_OK);
    assert_int_equal(polyc_online_finish(o.ctx, NULL, NULL, &rep), POLYC_OK);
    /* the map is the room's wall: no polyline stands at the person */
    assert_true(polyc_polyline_count(o.ctx) > 0);
    for (uint32_t i = 0; i < polyc_polyline_count(o.ctx); i++) {
        polyc_polyline pl;
        assert_int_equal(polyc_get_polyline(o.ctx, i, &pl), POLYC_OK);
        for (uint32_t j = 0; j < pl.point_count; j++)
            assert_true(hypot((double)pl.xy_m[2 * j], (double)pl.xy_m[2 * j + 1]) > 3.5);
    }
    free(o.block);
}

/* Whether the batch grid stores the tile of its cell (ix, iy): some cell
 * of it has hits (a tile is stored where a beam ends in a hit). */
static int batch_stored(const polyc_ctx *batch, int32_t ix, int32_t iy)
{
    int32_t x0 = ix & ~(POLYC__TILE_SIDE - 1), y0 = iy & ~(POLYC__TILE_SIDE - 1);
    for (int32_t y = y0; y < y0 + POLYC__TILE_SIDE; y++)
        for (int32_t x = x0; x < x0 + POLYC__TILE_SIDE; x++) {
            uint32_t h = 0;
            if (polyc_grid_cell(batch, (uint32_t)x, (uint32_t)y, &h, NULL, NULL) == POLYC_OK && h > 0)
                return 1;
        }
    return 0;
}

/* The person's tile against a batch grid of the same scans (whose cells
 * line up with the online grid's: its origin lies a whole number of cells
 * away): a cell crossed fewer than POLYC__PRE_FULL times before the tile
 * was stored has the batch's counts (so a cell no beam crossed has none: a
 * wall seen for the first time is not put under the misses of the free
 * cells in front of it); one crossed more, at least that many misses. */
static void test_tile_against_batch(void **state)
{
    (void)state;
    room r = {4.0, 0, 0.0, {0}, {0, 0, 0, 0, 0, 0, 0, 0, 0, NULL}};
    online o;
    open_online(&o, 12.0, 0);
    polyc_scan scans[21];
    static float ranges[21][BEAMS];
    polyc_config cfg;
    polyc_config_default(&cfg);
    for (int k = 0; k < 21; k++) {
        r.person = k == 20;
        r.turn = 0.0004 * k; /* (rays on other lines: cells crossed 1 to 20 times) */
        scans[k] = *room_scan(&r);
        memcpy(ranges[k], r.range, sizeof r.range);
        scans[k].range_m = ranges[k];
        assert_int_equal(polyc_online_add_scan(o.ctx, &scans[k], 0, NULL), POLYC_OK);
    }
    polyc_limits lim;
    assert_int_equal(polyc_limits_for_scans(&cfg, scans, 21, &lim), POLYC_OK);
    size_t n = polyc_memory_size(&cfg, &lim);
    void *block = malloc(n);
    assert_non_null(block);
    polyc_ctx *batch;
    assert_int_equal(polyc_init(block, n, &cfg, &lim, &batch), POLYC_OK);
    for (int k = 0; k < 21; k++)
        assert_int_equal(polyc_add_scan(batch, &scans[k]), POLYC_OK);
    assert_int_equal(polyc_build_grid(batch), POLYC_OK);
    double bx, by;
    float cell;
    assert_int_equal(polyc_grid_info(batch, &bx, &by, &cell, NULL, NULL), POLYC_OK);
    const polyc__grid *g = &o.ctx->grid;
    double sx = (bx - g->origin_x_m) / (double)cell, sy = (by - g->origin_y_m) / (double)cell;
    assert_true(fabs(sx - floor(sx + 0.5)) < 1e-3 && fabs(sy - floor(sy + 0.5)) < 1e-3);
    int32_t ox = (int32_t)floor(sx + 0.5), oy = (int32_t)floor(sy + 0.5);
    int32_t ix0 = (int32_t)floor((PERSON_X - g->origin_x_m) / (double)cell) & ~(POLYC__TILE_SIDE - 1);
    int32_t iy0 = (int32_t)floor((0.0 - g->origin_y_m) / (double)cell) & ~(POLYC__TILE_SIDE - 1);
    const polyc__tile *t = polyc__grid_tile(g, ix0, iy0);
    assert_non_null(t);
    uint32_t exact = 0, low = 0, full = 0, full_ok = 0;
    for (int idx = 0; idx < POLYC__TILE_CELLS; idx++) {
        int32_t ix = ix0 + (idx & (POLYC__TILE_SIDE - 1)), iy = iy0 + (idx >> POLYC__TILE_SHIFT);
        uint32_t h, m;
        if (!batch_stored(batch, ix - ox, iy - oy))
            continue; /* (reads 0 there) */
        assert_int_equal(polyc_grid_cell(batch, (uint32_t)(ix - ox), (uint32_t)(iy - oy), &h, &m, NULL),
                         POLYC_OK);
        if (m < POLYC__PRE_FULL) {
            low++;
            exact += t->hits[idx] == h && t->misses[idx] == m;
        } else {
            full++;
            full_ok += t->misses[idx] >= POLYC__PRE_FULL;
        }
    }
    print_message("the person's tile: %u cells with fewer than %u misses (%u exact), %u with "
                  "more (%u at least that many online)\n",
                  low, POLYC__PRE_FULL, exact, full, full_ok);
    assert_true(low > 0 && full > 0);
    assert_true(exact >= low - low / 50); /* (the two grids round a beam's end apart) */
    assert_true(full_ok >= full - full / 50);
    free(block);
    free(o.block);
}

/* A batch context of the scans, its grid and contour built (*block to free). */
static polyc_ctx *batch_contour(const polyc_scan *scans, uint32_t n, void **block)
{
    polyc_config cfg;
    polyc_config_default(&cfg);
    polyc_limits lim;
    assert_int_equal(polyc_limits_for_scans(&cfg, scans, n, &lim), POLYC_OK);
    size_t size = polyc_memory_size(&cfg, &lim);
    *block = malloc(size);
    assert_non_null(*block);
    polyc_ctx *batch;
    assert_int_equal(polyc_init(*block, size, &cfg, &lim, &batch), POLYC_OK);
    for (uint32_t k = 0; k < n; k++)
        assert_int_equal(polyc_add_scan(batch, &scans[k]), POLYC_OK);
    assert_int_equal(polyc_extract_contour(batch), POLYC_OK);
    return batch;
}

/* Every scan kept and added at a drifted pose (up to 0.3 m and 0.05 rad
 * off), then all corrected: the next update casts the contour again on the
 * corrected grid, so the online contour is the batch contour of the true
 * poses, cell by cell, and the drifted poses' contour is gone. (Cast as
 * each correction came, a scan corrected early looked through the walls
 * the scans not yet corrected still held misses on.) */
static void test_corrected_contour_is_batch(void **state)
{
    (void)state;
    enum { N = 24 };
    room r = {4.0, 1, 0.0, {0}, {0, 0, 0, 0, 0, 0, 0, 0, 0, NULL}};
    online o;
    open_keeping(&o, 12.0, 0, N);
    polyc_scan scans[N];
    static float ranges[N][BEAMS];
    polyc_online_report rep;
    for (int k = 0; k < N; k++) {
        r.turn = 0.0004 * k;
        scans[k] = *room_scan(&r);
        memcpy(ranges[k], r.range, sizeof r.range);
        scans[k].range_m = ranges[k];
        polyc_scan drifted = scans[k];
        drifted.pose_x_m = 0.3 * k / (N - 1);
        drifted.pose_theta_rad = 0.05 * k / (N - 1);
        uint32_t id;
        assert_int_equal(polyc_online_add_scan(o.ctx, &drifted, 1, &id), POLYC_OK);
        assert_int_equal(id, (uint32_t)k);
        assert_int_equal(polyc_online_update(o.ctx, POLYC_ONLINE_WORK_DEFAULT, &rep), POLYC_OK);
    }
    for (int k = 0; k < N; k++)
        assert_int_equal(polyc_online_correct(o.ctx, (uint32_t)k, 0.0, 0.0, 0.0), POLYC_OK);
    assert_int_equal(polyc_online_update(o.ctx, POLYC_ONLINE_WORK_DEFAULT, &rep), POLYC_OK);

    void *block;
    polyc_ctx *batch = batch_contour(scans, N, &block);
    double bx, by;
    float cell;
    uint32_t w, h;
    assert_int_equal(polyc_grid_info(batch, &bx, &by, &cell, &w, &h), POLYC_OK);
    const polyc__grid *g = &o.ctx->grid;
    double sx = (bx - g->origin_x_m) / (double)cell, sy = (by - g->origin_y_m) / (double)cell;
    assert_true(fabs(sx - floor(sx + 0.5)) < 1e-3 && fabs(sy - floor(sy + 0.5)) < 1e-3);
    int32_t ox = (int32_t)floor(sx + 0.5), oy = (int32_t)floor(sy + 0.5);
    uint32_t both = 0, batch_only = 0, online_only = 0;
    for (int32_t iy = 0; iy < g->height; iy++)
        for (int32_t ix = 0; ix < g->width; ix++) {
            const polyc__tile *t = polyc__grid_tile(g, ix, iy);
            uint32_t on = t && ((t->contour[iy & (POLYC__TILE_SIDE - 1)] >> (ix & (POLYC__TILE_SIDE - 1))) & 1u);
            uint32_t bc = 0;
            if (ix - ox >= 0 && iy - oy >= 0 && (uint32_t)(ix - ox) < w && (uint32_t)(iy - oy) < h)
                assert_int_equal(polyc_grid_cell(batch, (uint32_t)(ix - ox), (uint32_t)(iy - oy), NULL,
                                                 NULL, &bc),
                                 POLYC_OK);
            both += on && bc;
            batch_only += !on && bc;
            online_only += on && !bc;
        }
    print_message("contour after the corrections: %u cells in both, %u only in the batch's, "
                  "%u only online\n",
                  both, batch_only, online_only);
    assert_true(both > 400); /* the wall's ring and the person's front */
    /* (the two grids may round a beam's end apart) */
    assert_true(batch_only <= both / 50);
    assert_true(online_only <= both / 50);
    free(block);
    free(o.block);
}

/* The cells of the tiles `truth` stores: how many, and how many of them
 * `g` holds with the same counts (with `full_ok`, a cell the truth has
 * POLYC__PRE_FULL misses or more in may hold any count at least that);
 * and the hits `g` holds in the tiles the truth does not store. */
static void compare_counts_in(const polyc_ctx *a_ctx, const polyc_ctx *t_ctx, int full_ok,
                              uint32_t *cells, uint32_t *same, uint32_t *stray)
{
    const polyc__grid *g = &a_ctx->grid, *t = &t_ctx->grid;
    assert_true(g->origin_x_m == t->origin_x_m && g->origin_y_m == t->origin_y_m);
    *cells = *same = *stray = 0;
    for (int32_t iy = 0; iy < g->height; iy++)
        for (int32_t ix = 0; ix < g->width; ix++) {
            const polyc__tile *a = polyc__grid_tile(g, ix, iy), *b = polyc__grid_tile(t, ix, iy);
            int idx = polyc__cell_index(ix, iy);
            if (b) {
                (*cells)++;
                int capped = a && full_ok && b->misses[idx] >= POLYC__PRE_FULL &&
                             a->misses[idx] >= POLYC__PRE_FULL;
                *same += a && a->hits[idx] == b->hits[idx] &&
                         (a->misses[idx] == b->misses[idx] || capped);
            } else if (a) {
                *stray += a->hits[idx] != 0;
            }
        }
}

static void compare_counts(const polyc_ctx *a, const polyc_ctx *t, uint32_t *cells, uint32_t *same,
                           uint32_t *stray)
{
    compare_counts_in(a, t, 0, cells, same, stray);
}

/* Scans 1..N-1 added at drifted poses (scan 0 at its true pose: the frame),
 * the kept ones corrected: the grid then holds, cell by cell, the counts of
 * a context that was given the true poses, in every tile that context
 * stores, and no hit elsewhere. keep_every 1: every scan kept, so the
 * corrections are counted afresh; 4: a quarter kept, each corrected scan
 * taken out and put back. by_add: the corrections are applied by adding
 * one more scan (not kept) instead of by an update. */
static void check_corrected_counts(uint32_t keep_every, int by_add)
{
    enum { N = 16 };
    room r = {4.0, 1, 0.0, {0}, {0, 0, 0, 0, 0, 0, 0, 0, 0, NULL}};
    online fixed, truth;
    open_keeping(&fixed, 12.0, 0, N);
    open_online(&truth, 12.0, 0);
    polyc_online_report rep;
    for (uint32_t k = 0; k < N; k++) {
        r.turn = 0.0004 * k;
        polyc_scan scan = *room_scan(&r);
        int keep = k % keep_every == 0;
        polyc_scan drifted = scan;
        if (keep && k > 0) {
            drifted.pose_x_m = 0.2 * k / (N - 1);
            drifted.pose_theta_rad = 0.04 * k / (N - 1);
        }
        assert_int_equal(polyc_online_add_scan(fixed.ctx, &drifted, keep, NULL), POLYC_OK);
        assert_int_equal(polyc_online_add_scan(truth.ctx, &scan, 0, NULL), POLYC_OK);
        assert_int_equal(polyc_online_update(fixed.ctx, POLYC_ONLINE_WORK_DEFAULT, &rep), POLYC_OK);
    }
    for (uint32_t k = keep_every; k < N; k += keep_every)
        assert_int_equal(polyc_online_correct(fixed.ctx, k, 0.0, 0.0, 0.0), POLYC_OK);
    if (by_add) {
        r.turn = 0.0004 * N;
        const polyc_scan *last = room_scan(&r);
        assert_int_equal(polyc_online_add_scan(fixed.ctx, last, 0, NULL), POLYC_OK);
        assert_int_equal(polyc_online_add_scan(truth.ctx, last, 0, NULL), POLYC_OK);
    } else {
        assert_int_equal(polyc_online_update(fixed.ctx, POLYC_ONLINE_WORK_DEFAULT, &rep), POLYC_OK);
    }
    uint32_t cells, same, stray;
    compare_counts(fixed.ctx, truth.ctx, &cells, &same, &stray);
    print_message("keep every %u%s: %u cells of the true poses' tiles, %u with their counts; "
                  "%u hits left elsewhere\n",
                  keep_every, by_add ? ", applied by an add" : "", cells, same, stray);
    assert_true(cells > 0);
    assert_int_equal(same, cells);
    assert_int_equal(stray, 0);
    assert_int_equal(polyc_online_finish(fixed.ctx, NULL, NULL, &rep), POLYC_OK);
    assert_true(rep.polylines >= 1);
    free(fixed.block);
    free(truth.block);
}

static void test_corrected_counts(void **state)
{
    (void)state;
    check_corrected_counts(1, 0);
    check_corrected_counts(4, 0);
    check_corrected_counts(1, 1);
}

/* Every scan kept, of the empty room, at drifted poses; all corrected, so
 * counted afresh, their misses in the tiles not stored put back into the
 * records by the updates after (grid.c, "the records made again after a
 * recount"); then the person steps in. The person's tile, stored only
 * now, holds the misses of every scan before, as in a context given the
 * true poses from the start:
 * - UPDATE_FIRST: the update makes the records again before the person
 *   comes: cell by cell the same counts;
 * - PERSON_FIRST: the add of the person's scan applies the corrections and
 *   stores the tile before the records are made again: the same counts
 *   below POLYC__PRE_FULL misses (the updates put the rest into its
 *   counts, exactly, where the records cap a cell);
 * - ONE_MORE: one scan is left at its drifted pose, a scan is added (which
 *   applies the corrections), and that one scan is corrected on its own,
 *   taken out and put back, while the records wait: they are made again
 *   first, so it takes its misses out of complete records; the same
 *   counts but in a cell or two whose record reached the cap before the
 *   scan was taken out (a record counts a cell exactly up to
 *   POLYC__PRE_FULL, grid.c; a capped cell keeps its count). Taken out
 *   of the records as they waited, it would take out misses they did not
 *   hold yet and then put them in twice (112 cells off). */
enum { UPDATE_FIRST, PERSON_FIRST, ONE_MORE };

static void check_records_after_recount(int mode)
{
    enum { N = 16, LEFT = 3 };
    static const char *const name[] = {"the update first", "the person first",
                                       "one more correction"};
    room r = {4.0, 0, 0.0, {0}, {0, 0, 0, 0, 0, 0, 0, 0, 0, NULL}};
    online fixed, truth;
    open_keeping(&fixed, 12.0, 0, N + 2);
    open_online(&truth, 12.0, 0);
    polyc_online_report rep;
    polyc_scan drifted[N];
    static float ranges[N][BEAMS];
    for (uint32_t k = 0; k < N; k++) {
        r.turn = 0.0004 * k;
        polyc_scan scan = *room_scan(&r);
        memcpy(ranges[k], r.range, sizeof r.range);
        scan.range_m = ranges[k];
        drifted[k] = scan;
        drifted[k].pose_x_m = 0.2 * k / (N - 1);
        drifted[k].pose_theta_rad = 0.04 * k / (N - 1);
        assert_int_equal(polyc_online_add_scan(fixed.ctx, &drifted[k], 1, NULL), POLYC_OK);
        assert_int_equal(polyc_online_add_scan(truth.ctx, &scan, 0, NULL), POLYC_OK);
        assert_int_equal(polyc_online_update(fixed.ctx, POLYC_ONLINE_WORK_DEFAULT, &rep), POLYC_OK);
    }
    for (uint32_t k = 1; k < N; k++)
        if (mode != ONE_MORE || k != LEFT)
            assert_int_equal(polyc_online_correct(fixed.ctx, k, 0.0, 0.0, 0.0), POLYC_OK);
    if (mode == UPDATE_FIRST)
        assert_int_equal(polyc_online_update(fixed.ctx, POLYC_ONLINE_WORK_DEFAULT, &rep), POLYC_OK);
    if (mode == ONE_MORE) {
        r.turn = 0.0004 * N;
        const polyc_scan *more = room_scan(&r);
        assert_int_equal(polyc_online_add_scan(fixed.ctx, more, 1, NULL), POLYC_OK);
        assert_int_equal(polyc_online_add_scan(truth.ctx, more, 0, NULL), POLYC_OK);
        assert_true(fixed.ctx->online->rec.redo_next < fixed.ctx->online->rec.redo_end); /* waiting */
        assert_int_equal(polyc_online_correct(fixed.ctx, LEFT, 0.0, 0.0, 0.0), POLYC_OK);
        assert_int_equal(polyc_online_update(fixed.ctx, POLYC_ONLINE_WORK_DEFAULT, &rep), POLYC_OK);
    }
    const polyc__grid *g = &fixed.ctx->grid;
    int32_t px = (int32_t)floor((PERSON_X - PERSON_R - g->origin_x_m) / (double)g->cell_m);
    int32_t py = (int32_t)floor((0.0 - g->origin_y_m) / (double)g->cell_m);
    assert_null(polyc__grid_tile(g, px, py));
    r.person = 1;
    r.turn = 0.0004 * (N + 1);
    const polyc_scan *last = room_scan(&r);
    assert_int_equal(polyc_online_add_scan(fixed.ctx, last, 1, NULL), POLYC_OK);
    assert_int_equal(polyc_online_add_scan(truth.ctx, last, 0, NULL), POLYC_OK);
    assert_non_null(polyc__grid_tile(g, px, py));
    if (mode == PERSON_FIRST)
        assert_int_equal(polyc_online_update(fixed.ctx, POLYC_ONLINE_WORK_DEFAULT, &rep), POLYC_OK);
    unsigned h = 0, m = 0, th = 0, tm = 0;
    most_hit_near(fixed.ctx, PERSON_X - PERSON_R, 0.0, &h, &m);
    most_hit_near(truth.ctx, PERSON_X - PERSON_R, 0.0, &th, &tm);
    uint32_t cells, same, stray;
    compare_counts_in(fixed.ctx, truth.ctx, mode == PERSON_FIRST, &cells, &same, &stray);
    print_message("%s: the person's front %u hits, %u misses (true poses: %u, %u); %u cells of "
                  "the true poses' tiles, %u with their counts; %u hits left elsewhere\n",
                  name[mode], h, m, th, tm, cells, same, stray);
    assert_true(m >= N && m > h);
    if (mode == ONE_MORE)
        assert_true(same >= cells - 4);
    else
        assert_int_equal(same, cells);
    assert_int_equal(stray, 0);
    free(fixed.block);
    free(truth.block);
}

static void test_records_after_recount(void **state)
{
    (void)state;
    check_records_after_recount(UPDATE_FIRST);
    check_records_after_recount(PERSON_FIRST);
    check_records_after_recount(ONE_MORE);
}

/* Records for four times as many tiles as stored: a large room seen through
 * from its middle, in a grid of few tiles, spends them. The context maps
 * on (the misses of the tiles past the pool are lost). */
static void test_pool_spent(void **state)
{
    (void)state;
    room r = {12.0, 0, 0.0, {0}, {0, 0, 0, 0, 0, 0, 0, 0, 0, NULL}};
    online o;
    open_online(&o, 30.0, 160);
    polyc_online_report rep;
    for (int k = 0; k < 10; k++) {
        assert_int_equal(polyc_online_add_scan(o.ctx, room_scan(&r), 0, NULL), POLYC_OK);
        assert_int_equal(polyc_online_update(o.ctx, POLYC_ONLINE_WORK_DEFAULT, &rep), POLYC_OK);
    }
    const polyc__records *rec = &o.ctx->online->rec;
    print_message("pool: %u of %u records, %u tiles stored\n", rec->pre_high, rec->pre_cap,
                  o.ctx->grid.tile_count);
    assert_int_equal(rec->pre_high, rec->pre_cap);
    r.person = 1;
    assert_int_equal(polyc_online_add_scan(o.ctx, room_scan(&r), 0, NULL), POLYC_OK);
    assert_int_equal(polyc_online_finish(o.ctx, NULL, NULL, &rep), POLYC_OK);
    assert_true(rep.polylines >= 1);
    free(o.block);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_person_in_a_room_seen_through),
        cmocka_unit_test(test_tile_against_batch),
        cmocka_unit_test(test_pool_spent),
        cmocka_unit_test(test_corrected_contour_is_batch),
        cmocka_unit_test(test_corrected_counts),
        cmocka_unit_test(test_records_after_recount),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
