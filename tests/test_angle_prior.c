/* test_angle_prior.c - the angle prior (angle_prior.c) on synthetic scans with
 * known geometry: a rectangular room (corners of 90 degrees, straight walls),
 * a single straight wall, an empty context, a thin diagonal extent that makes
 * the prior coarsen, running out of memory, determinism. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "context.h"

#define PI_D 3.14159265358979323846
#define BEAMS 180

/* ---- scene: axis-aligned boxes (rooms) seen from inside ---- */

typedef struct room {
    double x0, y0, x1, y1;
} room;

/* distance from (px, py) inside the room along (c, s) to its wall */
static double room_range(const room *r, double px, double py, double c, double s)
{
    double t = 1e30;
    if (c > 1e-12) t = fmin(t, (r->x1 - px) / c);
    if (c < -1e-12) t = fmin(t, (r->x0 - px) / c);
    if (s > 1e-12) t = fmin(t, (r->y1 - py) / s);
    if (s < -1e-12) t = fmin(t, (r->y0 - py) / s);
    return t;
}

/* deterministic noise in [-amp, amp] (an LCG: the test needs no libm randomness) */
static float noise(uint32_t *state, float amp)
{
    *state = *state * 1664525u + 1013904223u;
    return amp * ((float)(*state >> 8) / 8388608.0f - 1.0f);
}

typedef struct scene {
    polyc_scan scans[64];
    float ranges[64][BEAMS];
    uint32_t count;
} scene;

/* one 180-beam scan over 180 degrees (1 degree steps) at pose (x, y, th) */
static void add_room_scan(scene *sc, const room *r, double x, double y, double th,
                          float noise_m, uint32_t *rng)
{
    polyc_scan *s = &sc->scans[sc->count];
    memset(s, 0, sizeof *s);
    s->pose_x_m = x;
    s->pose_y_m = y;
    s->pose_theta_rad = th;
    s->start_angle_rad = (float)(-PI_D / 2.0);
    s->angle_step_rad = (float)(PI_D / BEAMS);
    s->min_range_m = 0.05f;
    s->max_range_m = 30.0f;
    s->beam_count = BEAMS;
    for (uint32_t i = 0; i < BEAMS; i++) {
        double a = th + (double)s->start_angle_rad + (double)i * (double)s->angle_step_rad;
        float rr = (float)room_range(r, x, y, cos(a), sin(a));
        sc->ranges[sc->count][i] = rr + noise(rng, noise_m);
    }
    s->range_m = sc->ranges[sc->count];
    sc->count++;
}

/* The room [0, 6] x [0, 4] (absolute metres, far from the frame origin to
 * exercise frame-relative coordinates), seen from 12 poses facing its four
 * sides. */
static const room ROOM = {100.0, 50.0, 106.0, 54.0};

static void room_scene(scene *sc, float noise_m)
{
    uint32_t rng = 12345u;
    memset(sc, 0, sizeof *sc);
    static const double px[3] = {101.5, 103.0, 104.5};
    for (int k = 0; k < 3; k++)
        for (int h = 0; h < 4; h++)
            add_room_scan(sc, &ROOM, px[k], 51.0 + 0.6 * k, h * PI_D / 2.0 + 0.1 * k, noise_m, &rng);
}

/* ---- context through the public API ---- */

typedef struct fixture {
    void *block;
    polyc_ctx *ctx;
    polyc__prior prior;
} fixture;

static void make_ctx(fixture *f, const scene *sc, const polyc_config *cfg_in,
                     const polyc_limits *lim_in)
{
    polyc_config cfg;
    if (cfg_in)
        cfg = *cfg_in;
    else
        polyc_config_default(&cfg);
    polyc_limits lim;
    if (lim_in)
        lim = *lim_in;
    else
        assert_int_equal(polyc_limits_for_scans(&cfg, sc ? sc->scans : NULL,
                                                sc ? sc->count : 0, &lim), POLYC_OK);
    size_t size = polyc_memory_size(&cfg, &lim);
    assert_true(size > 0);
    f->block = malloc(size);
    assert_non_null(f->block);
    assert_int_equal(polyc_init(f->block, size, &cfg, &lim, &f->ctx), POLYC_OK);
    for (uint32_t i = 0; sc && i < sc->count; i++)
        assert_int_equal(polyc_add_scan(f->ctx, &sc->scans[i]), POLYC_OK);
    assert_int_equal(polyc_build_grid(f->ctx), POLYC_OK);
}

/* make_ctx on the room scene with range noise noise_m (the scans are
 * copied into the context, so one scene serves every test in turn) */
static void make_room_ctx(fixture *f, float noise_m)
{
    static scene sc;
    room_scene(&sc, noise_m);
    make_ctx(f, &sc, NULL, NULL);
}

static void free_ctx(fixture *f)
{
    free(f->block);
    f->block = NULL;
}

/* frame-relative from absolute */
static float fx(const fixture *f, double x)
{
    return (float)(x - f->ctx->frame_x);
}
static float fy(const fixture *f, double y)
{
    return (float)(y - f->ctx->frame_y);
}

static const float DEG = (float)(PI_D / 180.0);

/* p in (0, 1] everywhere, and the same from polyc__prior_at's counts */
static void check_all_in_unit_interval(const polyc__prior *p, float x0, float y0, float x1, float y1)
{
    for (int iy = 0; iy <= 40; iy++)
        for (int ix = 0; ix <= 40; ix++) {
            float x = x0 + (x1 - x0) * (float)ix / 40.0f, y = y0 + (y1 - y0) * (float)iy / 40.0f;
            polyc__prior_place at;
            polyc__prior_at(p, x, y, &at);
            assert_true(polyc__prior_same_place(p, &at, x, y));
            for (int a = -5; a <= 185; a += 1) {
                float v = polyc__prior_p(p, x, y, (float)a * DEG);
                assert_true(v > 0.0f && v <= 1.0f);
                /* the per-place form gives the same value */
                assert_true(v == polyc__prior_p_at(&at, (float)a * DEG));
            }
        }
}

/* ---- tests ---- */

static void test_room_corners_and_walls(void **state)
{
    (void)state;
    fixture f;
    make_room_ctx(&f, 0.01f);
    polyc_ctx *ctx = f.ctx;
    size_t before = ctx->arena.used;
    assert_int_equal(polyc__prior_build(ctx, &f.prior, SIZE_MAX), POLYC_OK);
    const polyc__prior *p = &f.prior;

    /* the tile grid, frame-relative, and within the size query's bound */
    assert_int_equal(p->w, ctx->grid.tiles_x);
    assert_int_equal(p->h, ctx->grid.tiles_y);
    assert_float_equal(p->cell_m, ctx->grid.cell_m * 32.0f, 1e-6f);
    assert_true(p->origin_x == ctx->grid.frame_ox && p->origin_y == ctx->grid.frame_oy);
    assert_true(ctx->arena.used - before <= polyc__prior_bytes(&ctx->lim));
    assert_true(p->corners >= 12);  /* every scan sees at least one corner */
    assert_true(p->straights > 100);

    float corner[4][2] = {{fx(&f, ROOM.x0), fy(&f, ROOM.y0)}, {fx(&f, ROOM.x1), fy(&f, ROOM.y0)},
                          {fx(&f, ROOM.x1), fy(&f, ROOM.y1)}, {fx(&f, ROOM.x0), fy(&f, ROOM.y1)}};
    float wall[4][2] = {{fx(&f, 103.0), fy(&f, ROOM.y0)}, {fx(&f, ROOM.x1), fy(&f, 52.0)},
                        {fx(&f, 103.0), fy(&f, ROOM.y1)}, {fx(&f, ROOM.x0), fy(&f, 52.0)}};
    for (int c = 0; c < 4; c++) {
        float pc90 = polyc__prior_p(p, corner[c][0], corner[c][1], 90.0f * DEG);
        float pw90 = polyc__prior_p(p, wall[c][0], wall[c][1], 90.0f * DEG);
        float pw0 = polyc__prior_p(p, wall[c][0], wall[c][1], 0.0f);
        float pc45 = polyc__prior_p(p, corner[c][0], corner[c][1], 45.0f * DEG);
        print_message("corner %d: p(90)=%.4f p(45)=%.4f  wall: p(90)=%.4f p(0)=%.4f\n", c,
                      (double)pc90, (double)pc45, (double)pw90, (double)pw0);
        assert_true(pc90 > 5.0f * pw90);     /* a corner is cheap where corners were seen */
        assert_true(pc90 > 4.0f * pc45);     /* ... at the angle they were seen at */
        assert_true(pw0 > 0.5f);             /* a straight continuation in a wall */
        assert_true(pw90 < 0.02f);           /* a corner in the middle of a wall */
    }
    check_all_in_unit_interval(p, fx(&f, 97.0), fy(&f, 47.0), fx(&f, 109.0), fy(&f, 57.0));
    free_ctx(&f);
}

/* The smoothed table (built when the block has room to spare) holds the
 * sums the queries would make: every value, bit for bit, is the same,
 * inside the grid, on its border and a cell outside it. */
static void test_smoothed_table_same_values(void **state)
{
    (void)state;
    fixture f;
    make_room_ctx(&f, 0.01f);
    polyc_ctx *ctx = f.ctx;
    assert_int_equal(polyc__prior_build(ctx, &f.prior, 0), POLYC_OK);
    polyc__prior *p = &f.prior;
    assert_non_null(p->smooth); /* the test block has room */
    uint32_t *table = p->smooth;
    size_t checked = 0;
    for (int32_t cy = -1; cy <= p->h; cy++)
        for (int32_t cx = -1; cx <= p->w; cx++) {
            float x = p->origin_x + ((float)cx + 0.5f) * p->cell_m;
            float y = p->origin_y + ((float)cy + 0.5f) * p->cell_m;
            for (int a = 0; a <= 180; a += 5) {
                p->smooth = table;
                float with = polyc__prior_p(p, x, y, (float)a * DEG);
                polyc__prior_place at;
                polyc__prior_at(p, x, y, &at);
                float with_at = polyc__prior_p_at(&at, (float)a * DEG);
                p->smooth = NULL;
                float without = polyc__prior_p(p, x, y, (float)a * DEG);
                polyc__prior_at(p, x, y, &at);
                assert_true(with == without);
                assert_true(with_at == polyc__prior_p_at(&at, (float)a * DEG));
                checked++;
            }
        }
    assert_true(checked > 100);
    /* a budget that leaves no room: no table */
    assert_int_equal(polyc__prior_build(ctx, p, SIZE_MAX), POLYC_OK);
    assert_null(p->smooth);
    free_ctx(&f);
}

static void test_histogram_bins(void **state)
{
    (void)state;
    fixture f;
    make_room_ctx(&f, 0.0f);
    assert_int_equal(polyc__prior_build(f.ctx, &f.prior, SIZE_MAX), POLYC_OK);
    const polyc__prior *p = &f.prior;
    /* the cell of the lower-left corner: 90 degree turns in bin 9 only */
    int32_t ix = (int32_t)floorf((fx(&f, ROOM.x0) - p->origin_x) / p->cell_m);
    int32_t iy = (int32_t)floorf((fy(&f, ROOM.y0) - p->origin_y) / p->cell_m);
    const uint16_t *h = polyc__prior_counts(p, ix, iy);
    assert_non_null(h);
    assert_true(h[9] > 0);
    assert_true(h[0] > 0);
    for (int b = 1; b < POLYC__ANGLE_BINS; b++)
        if (b != 9)
            assert_int_equal(h[b], 0);
    /* every recorded observation is in the histogram, in the row of its
     * cell: the rows are those of the cells with evidence, each once */
    uint64_t sum = 0;
    uint32_t cells_with = 0;
    for (int32_t cy = 0; cy < p->h; cy++)
        for (int32_t cx = 0; cx < p->w; cx++) {
            const uint16_t *c = polyc__prior_counts(p, cx, cy);
            if (!c)
                continue;
            cells_with++;
            uint32_t n = 0;
            for (int b = 0; b < POLYC__ANGLE_BINS; b++)
                n += c[b];
            assert_true(n > 0);
            sum += n;
        }
    assert_int_equal(cells_with, p->rows);
    assert_int_equal(sum, (uint64_t)p->corners * 8u + p->straights); /* corners weigh 8 */
    free_ctx(&f);
}

static void test_straight_wall_has_no_corners(void **state)
{
    (void)state;
    /* a wall y = 2 seen from below, scans 0.5 m apart, range noise 1 cm */
    static scene sc;
    memset(&sc, 0, sizeof sc);
    uint32_t rng = 7u;
    room wide = {-100.0, 0.0, 100.0, 2.0};
    for (int k = 0; k < 10; k++) {
        add_room_scan(&sc, &wide, 0.5 * k, 0.5, PI_D / 2.0, 0.01f, &rng);
        /* keep only the upper wall: beams towards the other walls do not return */
        for (uint32_t i = 0; i < BEAMS; i++)
            if (sc.ranges[k][i] > 6.0f)
                sc.ranges[k][i] = 40.0f;
    }
    fixture f;
    make_ctx(&f, &sc, NULL, NULL);
    assert_int_equal(polyc__prior_build(f.ctx, &f.prior, SIZE_MAX), POLYC_OK);
    const polyc__prior *p = &f.prior;
    print_message("wall: corners %u straights %u\n", p->corners, p->straights);
    assert_int_equal(p->corners, 0);
    assert_true(p->straights > 50);
    for (int k = 0; k <= 10; k++) {
        float x = fx(&f, 0.5 * k - 0.5), y = fy(&f, 2.0);
        assert_true(polyc__prior_p(p, x, y, 0.0f) > 0.7f);
        assert_true(polyc__prior_p(p, x, y, 90.0f * DEG) < 0.01f);
    }
    free_ctx(&f);
}

static void test_empty_context(void **state)
{
    (void)state;
    fixture f;
    polyc_limits lim = {4, 1000, 1 << 16, 0, 0};
    make_ctx(&f, NULL, NULL, &lim);
    memset(&f.prior, 0xab, sizeof f.prior);
    assert_int_equal(polyc__prior_build(f.ctx, &f.prior, SIZE_MAX), POLYC_OK);
    assert_int_equal(f.prior.w, 0);
    assert_int_equal(f.prior.h, 0);
    assert_null(f.prior.hist);
    assert_int_equal(f.prior.corners, 0);
    const float u = 1.0f / (float)POLYC__ANGLE_BINS;
    for (int a = 0; a <= 180; a += 10)
        assert_float_equal(polyc__prior_p(&f.prior, 0.0f, 0.0f, (float)a * DEG), u, 1e-6f);
    free_ctx(&f);

    /* a zeroed prior is valid too */
    polyc__prior z;
    memset(&z, 0, sizeof z);
    assert_float_equal(polyc__prior_p(&z, 1.0f, 2.0f, 1.0f), u, 1e-6f);
}

static void test_outside_and_bad_arguments(void **state)
{
    (void)state;
    fixture f;
    make_room_ctx(&f, 0.01f);
    assert_int_equal(polyc__prior_build(f.ctx, &f.prior, SIZE_MAX), POLYC_OK);
    const polyc__prior *p = &f.prior;
    const float u = 1.0f / (float)POLYC__ANGLE_BINS;
    /* far outside the grid, NaN position: no evidence, uniform */
    assert_float_equal(polyc__prior_p(p, 1e6f, 0.0f, 1.0f), u, 1e-6f);
    assert_float_equal(polyc__prior_p(p, -1e30f, 1e30f, 1.0f), u, 1e-6f);
    assert_float_equal(polyc__prior_p(p, NAN, 0.0f, 1.0f), u, 1e-6f);
    assert_float_equal(polyc__prior_p(p, INFINITY, 0.0f, 1.0f), u, 1e-6f);
    /* turn clamped to [0, pi]; NaN turn treated as 0 */
    float x = fx(&f, 103.0), y = fy(&f, ROOM.y0);
    assert_float_equal(polyc__prior_p(p, x, y, -1.0f), polyc__prior_p(p, x, y, 0.0f), 1e-7f);
    assert_float_equal(polyc__prior_p(p, x, y, NAN), polyc__prior_p(p, x, y, 0.0f), 1e-7f);
    assert_float_equal(polyc__prior_p(p, x, y, 10.0f), polyc__prior_p(p, x, y, (float)PI_D), 1e-7f);
    /* continuous in the turn angle */
    for (int a = 0; a < 1800; a++) {
        float t0 = (float)a * 0.1f * DEG, t1 = (float)(a + 1) * 0.1f * DEG;
        float c0 = polyc__prior_p(p, fx(&f, ROOM.x0), fy(&f, ROOM.y0), t0);
        float c1 = polyc__prior_p(p, fx(&f, ROOM.x0), fy(&f, ROOM.y0), t1);
        assert_true(fabsf(c1 - c0) < 0.02f);
    }
    free_ctx(&f);
}

static void test_deterministic(void **state)
{
    (void)state;
    static scene sc;
    room_scene(&sc, 0.02f);
    fixture a, b;
    make_ctx(&a, &sc, NULL, NULL);
    make_ctx(&b, &sc, NULL, NULL);
    assert_int_equal(polyc__prior_build(a.ctx, &a.prior, SIZE_MAX), POLYC_OK);
    assert_int_equal(polyc__prior_build(b.ctx, &b.prior, SIZE_MAX), POLYC_OK);
    assert_int_equal(a.prior.w, b.prior.w);
    assert_int_equal(a.prior.h, b.prior.h);
    assert_int_equal(a.prior.corners, b.prior.corners);
    assert_int_equal(a.prior.straights, b.prior.straights);
    /* the same rows, handed out in the same order */
    size_t cells = (size_t)a.prior.w * (size_t)a.prior.h * sizeof(uint32_t);
    size_t n = (size_t)a.prior.rows * POLYC__ANGLE_BINS * sizeof(uint16_t);
    assert_int_equal(a.prior.rows, b.prior.rows);
    assert_true(a.prior.rows > 0);
    assert_memory_equal(a.prior.row_of, b.prior.row_of, cells);
    assert_memory_equal(a.prior.hist, b.prior.hist, n);
    /* building again in the same context gives the same prior */
    polyc__prior again;
    assert_int_equal(polyc__prior_build(a.ctx, &again, SIZE_MAX), POLYC_OK);
    assert_int_equal(again.rows, a.prior.rows);
    assert_memory_equal(a.prior.row_of, again.row_of, cells);
    assert_memory_equal(a.prior.hist, again.hist, n);
    free_ctx(&a);
    free_ctx(&b);
}

static void test_out_of_memory(void **state)
{
    (void)state;
    fixture f;
    make_room_ctx(&f, 0.01f);
    polyc_ctx *ctx = f.ctx;
    size_t size = ctx->arena.size;
    ctx->arena.size = ctx->arena.used + 64; /* room for almost nothing */
    assert_int_equal(polyc__prior_build(ctx, &f.prior, SIZE_MAX), POLYC_ERR_NOMEM);
    assert_int_equal(f.prior.w, 0);
    assert_null(f.prior.hist);
    assert_string_equal(polyc_last_error(ctx), "no room for the angle prior");
    /* the prior is still usable (uniform), and a retry with room succeeds */
    assert_float_equal(polyc__prior_p(&f.prior, 0.0f, 0.0f, 1.0f),
                       1.0f / (float)POLYC__ANGLE_BINS, 1e-6f);
    ctx->arena.size = size;
    assert_int_equal(polyc__prior_build(ctx, &f.prior, SIZE_MAX), POLYC_OK);
    assert_true(f.prior.w > 0);
    free_ctx(&f);
}

/* Two small rooms 25 m apart on a diagonal with a tight tile budget: the
 * tile grid has more cells than polyc__prior_bytes allows, so prior cells
 * cover 2 x 2 (or more) tiles; the corners are still found. */
static void test_coarse_prior_for_thin_extent(void **state)
{
    (void)state;
    static scene sc;
    memset(&sc, 0, sizeof sc);
    uint32_t rng = 99u;
    room r0 = {0.0, 0.0, 1.0, 1.0}, r1 = {25.0, 25.0, 26.0, 26.0};
    for (int h = 0; h < 4; h++) {
        add_room_scan(&sc, &r0, 0.5, 0.5, h * PI_D / 2.0, 0.005f, &rng);
        add_room_scan(&sc, &r1, 25.5, 25.5, h * PI_D / 2.0, 0.005f, &rng);
    }
    polyc_config cfg;
    polyc_config_default(&cfg);
    cfg.cell_m = 0.05f; /* tiles of 1.6 m: a 26 m box is 17 x 17 tiles */
    polyc_limits lim;
    assert_int_equal(polyc_limits_for_scans(&cfg, sc.scans, sc.count, &lim), POLYC_OK);
    lim.max_grid_cells = 16 * POLYC__TILE_CELLS; /* 16 tiles: room for 128 prior cells */
    fixture f;
    make_ctx(&f, &sc, &cfg, &lim);
    polyc_ctx *ctx = f.ctx;
    assert_true(ctx->grid.tiles_x * ctx->grid.tiles_y > 16 * 4 + 64);
    size_t before = ctx->arena.used;
    assert_int_equal(polyc__prior_build(ctx, &f.prior, SIZE_MAX), POLYC_OK);
    const polyc__prior *p = &f.prior;
    assert_true(ctx->arena.used - before <= polyc__prior_bytes(&ctx->lim));
    assert_true(p->w * p->h <= 16 * 4 + 64);
    assert_true(p->cell_m >= 2.0f * 32.0f * cfg.cell_m - 1e-6f);
    print_message("coarse: %d x %d cells of %.2f m (tiles %d x %d)\n", p->w, p->h,
                  (double)p->cell_m, ctx->grid.tiles_x, ctx->grid.tiles_y);
    float c90 = polyc__prior_p(p, fx(&f, 1.0), fy(&f, 1.0), 90.0f * DEG);
    float c45 = polyc__prior_p(p, fx(&f, 1.0), fy(&f, 1.0), 45.0f * DEG);
    float mid = polyc__prior_p(p, fx(&f, 13.0), fy(&f, 13.0), 90.0f * DEG);
    assert_true(c90 > 4.0f * c45);
    assert_float_equal(mid, 1.0f / (float)POLYC__ANGLE_BINS, 1e-6f); /* no data there */
    free_ctx(&f);
}

static void test_size_query(void **state)
{
    (void)state;
    polyc_limits lim = {1, 1, 0, 0, 0};
    /* per cell: its row index, a row of counters and a total */
    size_t cell = sizeof(uint32_t) + POLYC__ANGLE_BINS * sizeof(uint16_t) + sizeof(uint32_t);
    assert_true(polyc__prior_bytes(&lim) >= 64 * cell);
    lim.max_grid_cells = 1u << 20; /* 1024 tiles */
    assert_true(polyc__prior_bytes(&lim) >= (1024 * 4 + 64) * cell);
    /* and a scratch row for one beam's endpoint (x, y, range), each of the
     * four arrays aligned */
    assert_true(polyc__prior_bytes(&lim) < (1024 * 4 + 64) * cell + 3 * 16 + 3 * sizeof(float) + 16);
    lim.max_grid_cells = UINT32_MAX;
    assert_true(polyc__prior_bytes(&lim) > 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_room_corners_and_walls),
        cmocka_unit_test(test_histogram_bins),
        cmocka_unit_test(test_smoothed_table_same_values),
        cmocka_unit_test(test_straight_wall_has_no_corners),
        cmocka_unit_test(test_empty_context),
        cmocka_unit_test(test_outside_and_bad_arguments),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_out_of_memory),
        cmocka_unit_test(test_coarse_prior_for_thin_extent),
        cmocka_unit_test(test_size_query),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
