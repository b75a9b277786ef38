/* test_grid.c - the grid and contour passes (grid.c, contour.c) against a
 * plain re-implementation on polyc__traverse, the generic walk with a
 * callback per cell that keeps every tile a beam crosses: the grid stores
 * exactly the tiles where some beam ends in a hit, in the order beams first
 * reach them, with the same counters in every cell; the contour list is the
 * same, in the same order (with the data fallback, checked by brute force
 * over the cells around each end). Scenes: a room with clutter, no-return, short and
 * NaN ranges at several cell sizes; one pose seen 200 times (the sensor's
 * cell saturates); the contour within its budget; and the walk's skip
 * over tiles against its steps, beam by beam. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "walk.h"

#define PI_D 3.14159265358979323846
#define BEAMS 361
#define MAX_SCANS 200

typedef struct scene {
    polyc_scan scans[MAX_SCANS];
    float ranges[MAX_SCANS][BEAMS];
    uint32_t count;
} scene;

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

/* The room [0, 18] x [0, 12]: wider than the laser's 8 m, so beams cross
 * free space that no beam ends in. */
#define ROOM_W 18.0
#define ROOM_H 12.0

/* distance from (px, py) along (c, s) to the walls of the room */
static double room_range(double px, double py, double c, double s)
{
    double t = 1e30;
    if (c > 1e-12) t = fmin(t, (ROOM_W - px) / c);
    if (c < -1e-12) t = fmin(t, (0.0 - px) / c);
    if (s > 1e-12) t = fmin(t, (ROOM_H - py) / s);
    if (s < -1e-12) t = fmin(t, (0.0 - py) / s);
    return t;
}

/* One scan at (x, y, th); with clutter, some beams end early (people), pass
 * through an open door (no return) or are short or NaN. */
static void add_scan(scene *sc, double x, double y, double th, int clutter, uint32_t *rng)
{
    polyc_scan *s = &sc->scans[sc->count];
    memset(s, 0, sizeof *s);
    s->pose_x_m = x;
    s->pose_y_m = y;
    s->pose_theta_rad = th;
    s->start_angle_rad = (float)(-PI_D / 2.0);
    s->angle_step_rad = (float)(PI_D / (BEAMS - 1));
    s->min_range_m = 0.05f;
    s->max_range_m = 8.0f;
    s->beam_count = BEAMS;
    for (uint32_t i = 0; i < BEAMS; i++) {
        double a = th + (double)s->start_angle_rad + (double)i * (double)s->angle_step_rad;
        float r = (float)room_range(x, y, cos(a), sin(a));
        r += 0.01f * ((float)(lcg(rng) & 1023u) / 512.0f - 1.0f);
        uint32_t u = lcg(rng) % 100u;
        if (clutter && u < 3)
            r *= 0.3f + 0.2f * (float)u;  /* a person */
        else if (clutter && u < 9)
            r = 8.5f;                      /* no return */
        else if (clutter && u == 9)
            r = 0.01f;                     /* too short */
        else if (clutter && u == 10)
            r = NAN;
        else if (r >= 8.0f)
            r = 8.5f;
        sc->ranges[sc->count][i] = r;
    }
    s->range_m = sc->ranges[sc->count];
    sc->count++;
}

static void clutter_scene(scene *sc)
{
    uint32_t rng = 777u;
    memset(sc, 0, sizeof *sc);
    for (int k = 0; k < 40; k++) {
        double x = 0.5 + (ROOM_W - 1.0) * (double)(lcg(&rng) % 1000u) / 1000.0;
        double y = 0.5 + (ROOM_H - 1.0) * (double)(lcg(&rng) % 1000u) / 1000.0;
        double th = 2.0 * PI_D * (double)(lcg(&rng) % 1000u) / 1000.0;
        add_scan(sc, x, y, th, 1, &rng);
    }
}

/* ---- the passes again, on polyc__traverse ---- */

typedef struct oracle {
    const polyc__grid *g;
    polyc__count *hits, *misses;   /* width * height */
    int32_t *tile_rank;            /* per directory entry: 0 untouched, else order + 1 */
    int32_t *touched;              /* directory entries in the order beams reach them */
    uint8_t *wanted;               /* per directory entry: a beam ends in a hit there */
    int32_t tiles;
    const polyc__beam *beam;
    uint8_t *labelled;
    int32_t *list;
    uint32_t count;
    float threshold;
    float data_min;                /* the data rule's m */
    int32_t alone;                 /* the data fallback's square, cells each way */
} oracle;

static void inc(polyc__count *a, polyc__count *b)
{
    if (*a == POLYC__COUNT_MAX) {
        *a = (polyc__count)(*a >> 1);
        *b = (polyc__count)(*b >> 1);
    }
    (*a)++;
}

static int in_grid(const polyc__grid *g, int32_t ix, int32_t iy)
{
    return ix >= 0 && iy >= 0 && ix < g->width && iy < g->height;
}

static size_t tile_of(const polyc__grid *g, int32_t ix, int32_t iy)
{
    return (size_t)(iy >> POLYC__TILE_SHIFT) * (size_t)g->tiles_x +
           (size_t)(ix >> POLYC__TILE_SHIFT);
}

static int count_visit(void *u, int32_t ix, int32_t iy, float t_enter, int last)
{
    oracle *o = u;
    if (!in_grid(o->g, ix, iy))
        return 1;
    size_t d = tile_of(o->g, ix, iy), c = (size_t)iy * (size_t)o->g->width + (size_t)ix;
    if (!o->tile_rank[d]) {
        o->touched[o->tiles] = (int32_t)d;
        o->tile_rank[d] = ++o->tiles;
    }
    if (last && o->beam->hit)
        inc(&o->hits[c], &o->misses[c]);
    else if (t_enter < o->beam->miss_end)
        inc(&o->misses[c], &o->hits[c]);
    return 0;
}

/* The data fallback, brute force: the cell holds data (m >= data_min) and
 * no cell within `alone` of it (a square) is occupied. */
static int data_alone(const oracle *o, int32_t ix, int32_t iy)
{
    size_t c = (size_t)iy * (size_t)o->g->width + (size_t)ix;
    unsigned h = o->hits[c], m = o->misses[c];
    if (h == 0 || (float)h < o->data_min * (float)(h + m))
        return 0;
    for (int32_t y = iy - o->alone; y <= iy + o->alone; y++)
        for (int32_t x = ix - o->alone; x <= ix + o->alone; x++) {
            if (!in_grid(o->g, x, y))
                continue;
            size_t k = (size_t)y * (size_t)o->g->width + (size_t)x;
            unsigned hk = o->hits[k], mk = o->misses[k];
            if (hk > 0 && (float)hk > o->threshold * (float)(hk + mk))
                return 0;
        }
    return 1;
}

static int contour_visit(void *u, int32_t ix, int32_t iy, float t_enter, int last)
{
    (void)t_enter;
    oracle *o = u;
    if (!in_grid(o->g, ix, iy) || !o->tile_rank[tile_of(o->g, ix, iy)])
        return 1;
    size_t c = (size_t)iy * (size_t)o->g->width + (size_t)ix;
    unsigned h = o->hits[c], m = o->misses[c];
    if (!(h > 0 && (float)h > o->threshold * (float)(h + m)) &&
        !(last && o->beam->hit && data_alone(o, ix, iy)))
        return 0;
    if (!o->labelled[c]) {
        o->labelled[c] = 1;
        o->list[2 * o->count] = ix;
        o->list[2 * o->count + 1] = iy;
        o->count++;
    }
    return 1;
}

static void oracle_run(oracle *o, const polyc_ctx *ctx)
{
    const polyc__grid *g = &ctx->grid;
    size_t cells = (size_t)g->width * (size_t)g->height;
    memset(o, 0, sizeof *o);
    o->g = g;
    o->hits = calloc(cells, sizeof *o->hits);
    o->misses = calloc(cells, sizeof *o->misses);
    o->labelled = calloc(cells, 1);
    size_t dir_n = (size_t)g->tiles_x * (size_t)g->tiles_y;
    o->tile_rank = calloc(dir_n, sizeof *o->tile_rank);
    o->touched = calloc(dir_n, sizeof *o->touched);
    o->wanted = calloc(dir_n, 1);
    o->list = calloc((size_t)ctx->lim.max_beams * 2 + 2, sizeof *o->list);
    o->threshold = ctx->cfg.contour_threshold;
    o->data_min = ctx->cfg.data_min_m;
    o->alone = (int32_t)ceilf(2.0f * ctx->cfg.search_radius_m / g->cell_m); /* contour.c */
    assert_true(o->hits && o->misses && o->labelled && o->tile_rank);
    assert_true(o->touched && o->wanted && o->list);
    for (int pass = 0; pass < 2; pass++)
        for (uint32_t si = 0; si < ctx->scan_count; si++)
            for (uint32_t i = 0; i < ctx->scans[si].count; i++) {
                polyc__beam b;
                if (!polyc__beam_get(ctx, &ctx->scans[si], i, &b))
                    continue;
                int32_t ex = (int32_t)floorf(b.ex), ey = (int32_t)floorf(b.ey);
                if (b.hit && in_grid(g, ex, ey))
                    o->wanted[tile_of(g, ex, ey)] = 1;
                o->beam = &b;
                polyc__traverse(&b, pass ? contour_visit : count_visit, o);
            }
}

static void oracle_free(oracle *o)
{
    free(o->hits);
    free(o->misses);
    free(o->labelled);
    free(o->tile_rank);
    free(o->touched);
    free(o->wanted);
    free(o->list);
}

/* Returns how many tiles beams crossed that the grid did not store. */
static uint32_t check_grid(const polyc_ctx *ctx, const oracle *o)
{
    const polyc__grid *g = &ctx->grid;
    size_t dir_n = (size_t)g->tiles_x * (size_t)g->tiles_y;
    uint32_t *want_dir = calloc(dir_n, sizeof *want_dir);
    assert_non_null(want_dir);
    uint32_t stored = 0, skipped = 0;
    for (int32_t k = 0; k < o->tiles; k++) {
        if (o->wanted[o->touched[k]])
            want_dir[o->touched[k]] = ++stored;
        else
            skipped++;
    }
    assert_int_equal(g->tile_count, stored);
    for (size_t d = 0; d < dir_n; d++)
        assert_int_equal(g->dir[d], want_dir[d]);
    free(want_dir);
    for (int32_t y = 0; y < g->height; y++)
        for (int32_t x = 0; x < g->width; x++) {
            const polyc__tile *t = polyc__grid_tile(g, x, y);
            size_t c = (size_t)y * (size_t)g->width + (size_t)x;
            int idx = polyc__cell_index(x, y);
            if (t) {
                assert_int_equal(t->hits[idx], o->hits[c]);
                assert_int_equal(t->misses[idx], o->misses[c]);
            } else {
                assert_int_equal(o->hits[c], 0);
            }
        }
    return skipped;
}

static void check_contour(const polyc_ctx *ctx, const oracle *o)
{
    assert_int_equal(ctx->contour_count, o->count);
    assert_memory_equal(ctx->contour_xy, o->list, (size_t)o->count * 2 * sizeof(int32_t));
}

/* ---- context ---- */

typedef struct fixture {
    void *block;
    polyc_ctx *ctx;
    polyc_limits lim;
} fixture;

static void make_ctx(fixture *f, const scene *sc, float cell_m)
{
    polyc_config cfg;
    polyc_config_default(&cfg);
    cfg.cell_m = cell_m;
    assert_int_equal(polyc_limits_for_scans(&cfg, sc->scans, sc->count, &f->lim), POLYC_OK);
    size_t size = polyc_memory_size(&cfg, &f->lim);
    assert_true(size > 0);
    f->block = malloc(size);
    assert_non_null(f->block);
    assert_int_equal(polyc_init(f->block, size, &cfg, &f->lim, &f->ctx), POLYC_OK);
    for (uint32_t i = 0; i < sc->count; i++)
        assert_int_equal(polyc_add_scan(f->ctx, &sc->scans[i]), POLYC_OK);
    assert_int_equal(polyc_build_grid(f->ctx), POLYC_OK);
}

static void test_passes_match_traversal(void **state)
{
    (void)state;
    static scene sc;
    clutter_scene(&sc);
    static const float cells[] = {0.025f, 0.037f, 0.05f, 0.1f, 0.3f};
    for (size_t k = 0; k < sizeof cells / sizeof cells[0]; k++) {
        fixture f;
        make_ctx(&f, &sc, cells[k]);
        assert_int_equal(polyc_extract_contour(f.ctx), POLYC_OK);
        oracle o;
        oracle_run(&o, f.ctx);
        uint32_t skipped = check_grid(f.ctx, &o);
        check_contour(f.ctx, &o);
        assert_true(o.count > 20);
        if (cells[k] < 0.04f)
            assert_true(skipped > 0);
        oracle_free(&o);
        free(f.block);
    }
}

/* 200 scans from one pose: 72,200 misses in the sensor's cell, past the
 * 16-bit counters' limit, so the counters halve in the order of the beams */
static void test_saturation_matches_traversal(void **state)
{
    (void)state;
    static scene sc;
    uint32_t rng = 99u;
    memset(&sc, 0, sizeof sc);
    for (int k = 0; k < MAX_SCANS; k++)
        add_scan(&sc, 3.3, 2.1, 0.7, k % 2, &rng);
    fixture f;
    make_ctx(&f, &sc, 0.05f);
    assert_int_equal(polyc_extract_contour(f.ctx), POLYC_OK);
    oracle o;
    oracle_run(&o, f.ctx);
    check_grid(f.ctx, &o);
    check_contour(f.ctx, &o);
    oracle_free(&o);
    free(f.block);
}

/* The contour pass takes no more than its budget beyond the grid (its
 * cells and, while it casts, a bit per tile), and its walk, which crosses
 * the tiles without an occupied cell in one move, finds the oracle's
 * contour in a cluttered scene. */
static void test_contour_within_budget(void **state)
{
    (void)state;
    static scene sc;
    clutter_scene(&sc);
    fixture f;
    make_ctx(&f, &sc, 0.04f);
    size_t size = f.ctx->arena.size;
    f.ctx->arena.size = f.ctx->grid_mark + polyc__contour_bytes(&f.lim);
    assert_int_equal(polyc_extract_contour(f.ctx), POLYC_OK);
    f.ctx->arena.size = size;
    assert_true(f.ctx->arena.peak <= f.ctx->grid_mark + polyc__contour_bytes(&f.lim));
    oracle o;
    oracle_run(&o, f.ctx);
    check_contour(f.ctx, &o);
    oracle_free(&o);
    free(f.block);
}

/* A coordinate in [0, w): integers (cell boundaries), halves, and any float. */
static float coord(uint32_t *rng, float w)
{
    *rng = *rng * 1664525u + 1013904223u;
    uint32_t r = *rng >> 8;
    float v = (float)((double)(r % 1000000u) / 1000000.0 * (double)w);
    switch (r % 4u) {
    case 0: return floorf(v);
    case 1: return floorf(v) + 0.5f;
    default: return v;
    }
}

/* polyc__walk_skip_tiles puts a walk where its steps take it into the
 * first stop tile of its path (same cell, keys and steps left), and says
 * when instead its steps end first (the step into a stop tile, or out of
 * the grid, would be the last) or leave the grid: random beams, along the
 * axes and through tile corners too (ties), some ending outside the grid
 * or exactly on cell boundaries, over random stop tiles on a grid whose
 * last row and column of tiles are cut short. */
static void test_tile_skip_matches_steps(void **state)
{
    (void)state;
    enum { W = 300, H = 170, TX = (W + 31) / 32, TY = (H + 31) / 32 };
    uint32_t stop[(TX * TY + 31) / 32];
    uint32_t rng = 777u, count[3] = {0, 0, 0};
    for (int k = 0; k < 30000; k++) {
        if (k % 100 == 0) { /* new stop tiles, one in four */
            memset(stop, 0, sizeof stop);
            for (int32_t d = 0; d < TX * TY; d++) {
                rng = rng * 1664525u + 1013904223u;
                if ((rng >> 28) < 4u)
                    stop[d / 32] |= 1u << (d % 32);
            }
        }
        polyc__beam b;
        b.sx = coord(&rng, (float)W);
        b.sy = coord(&rng, (float)H);
        b.ex = coord(&rng, (float)W + 40.0f) - 20.0f; /* some end outside the grid */
        b.ey = coord(&rng, (float)H + 40.0f) - 20.0f;
        if (k % 10 == 1) b.ey = b.sy; /* along x */
        if (k % 10 == 2) b.ex = b.sx; /* along y */
        if (k % 10 == 3) { /* on y = x: through tile corners */
            b.sy = b.sx = coord(&rng, (float)H);
            b.ey = b.ex = coord(&rng, (float)H + 40.0f) - 20.0f;
        }
        b.hit = 1;
        b.miss_end = 1.0f;
        polyc__walk a;
        polyc__walk_start(&a, &b);
        if (!polyc__walk_enter(&a, W, H))
            continue;
        polyc__walk try = a;
        int got = polyc__walk_skip_tiles(&try, W, H, TX, stop);
        /* the steps: ended (0) when a step leaves none, else out of the
         * grid (-1), or in another tile that is a stop tile (1) */
        int32_t t0 = (a.iy >> 5) * TX + (a.ix >> 5);
        int want = 0;
        while (a.n > 0) {
            polyc__walk_step(&a);
            if (a.n == 0)
                break;
            if (a.ix < 0 || a.iy < 0 || a.ix >= W || a.iy >= H) {
                want = -1;
                break;
            }
            int32_t d = (a.iy >> 5) * TX + (a.ix >> 5);
            if (d != t0 && ((stop[d / 32] >> (d % 32)) & 1u)) {
                want = 1;
                break;
            }
        }
        if (got != want)
            fail_msg("beam %d: (%.3f, %.3f) -> (%.3f, %.3f): skip says %d, the steps %d", k,
                     (double)b.sx, (double)b.sy, (double)b.ex, (double)b.ey, got, want);
        count[want + 1]++;
        if (want != 1)
            continue;
        assert_int_equal(try.ix, a.ix);
        assert_int_equal(try.iy, a.iy);
        assert_int_equal(try.n, a.n);
        assert_true(try.kx == a.kx && try.ky == a.ky);
        assert_true(try.t_key == a.t_key);
    }
    print_message("left the grid %u, ended %u, stopped %u\n", count[0], count[1], count[2]);
    assert_true(count[0] > 1000 && count[1] > 1000 && count[2] > 5000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_passes_match_traversal),
        cmocka_unit_test(test_saturation_matches_traversal),
        cmocka_unit_test(test_contour_within_budget),
        cmocka_unit_test(test_tile_skip_matches_steps),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
