/* test_exhaustion.c - running out of memory, the way Lua's test allocator
 * does it: the small scene (tests/small_scene.h) with every block size from
 * 0 up to what polyc_memory_size asked for (every 16 bytes at the start, a
 * few hundred sizes spread over the rest, the exact size and the size - 1),
 * the block at every alignment, with guard bytes on both sides. Then each
 * limit of polyc_limits swept from nothing up to enough, so that the later
 * stages run out, not polyc_init. Every run either succeeds or fails with
 * POLYC_ERR_NOMEM (or POLYC_ERR_LIMIT for too few scans or beams), never
 * writes outside its block, and the queried size is always enough. */
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
#include "scansim.h"
#include "small_scene.h"

#define GUARD 64
#define GUARD_BYTE 0xa5

/* A block of `size` bytes at offset `skew` of a buffer with guard bytes
 * before (GUARD + skew) and after (GUARD). */
typedef struct guarded {
    unsigned char *raw;
    unsigned char *block;
    size_t size, skew;
} guarded;

static void guarded_alloc(guarded *g, size_t size, size_t skew)
{
    g->raw = malloc(size + skew + 2 * GUARD);
    assert_non_null(g->raw);
    memset(g->raw, GUARD_BYTE, size + skew + 2 * GUARD);
    g->block = g->raw + GUARD + skew;
    g->size = size;
    g->skew = skew;
}

/* Fails the test if any byte outside the block changed. */
static void guarded_check(const guarded *g, const char *what)
{
    for (size_t i = 0; i < GUARD + g->skew; i++)
        if (g->raw[i] != GUARD_BYTE)
            fail_msg("%s: block of %zu bytes: byte %zu before it written", what, g->size,
                     GUARD + g->skew - i);
    for (size_t i = 0; i < GUARD; i++)
        if (g->block[g->size + i] != GUARD_BYTE)
            fail_msg("%s: block of %zu bytes: byte %zu after it written", what, g->size, i);
}

static void guarded_free(guarded *g)
{
    free(g->raw);
    g->raw = g->block = NULL;
}

/* Adds the scans and builds. Returns the first status that is not OK (or
 * OK); checks that it is one an exhausted budget may give and that the
 * context can still be read. */
static polyc_status build_scene(polyc_ctx *ctx, const scansim_scene *sc, const char *what)
{
    polyc_status st = POLYC_OK;
    for (uint32_t i = 0; st == POLYC_OK && i < sc->scan_count; i++)
        st = polyc_add_scan(ctx, &sc->scans[i]);
    if (st == POLYC_OK)
        st = polyc_build(ctx, NULL, NULL);
    if (st != POLYC_OK && st != POLYC_ERR_NOMEM && st != POLYC_ERR_LIMIT)
        fail_msg("%s: %s (%s)", what, polyc_status_str(st), polyc_last_error(ctx));
    if (st != POLYC_OK && polyc_last_error(ctx)[0] == '\0')
        fail_msg("%s: %s without a message", what, polyc_status_str(st));
    polyc_stats stats;
    memset(&stats, 0, sizeof stats); /* -Os -flto cannot see that the call fills it */
    assert_int_equal(polyc_get_stats(ctx, &stats), POLYC_OK);
    assert_true(stats.memory_used_bytes <= stats.memory_size_bytes);
    if (st == POLYC_OK && map_is_valid(ctx, 11.5, -2.0, 4.0) != 0)
        fail_msg("%s: invalid map", what);
    /* after a failure the results read as empty or as the last good stage */
    uint32_t n = polyc_polyline_count(ctx);
    for (uint32_t i = 0; i < n; i++) {
        polyc_polyline pl;
        assert_int_equal(polyc_get_polyline(ctx, i, &pl), POLYC_OK);
    }
    return st;
}

/* The small scene, its configuration (3 iterations) and its limits. */
static void open_small(scansim_scene *sc, polyc_config *cfg, polyc_limits *lim)
{
    assert_int_equal(small_scene(sc), 0);
    small_config(cfg);
    cfg->max_iterations = 3;
    assert_int_equal(polyc_limits_for_scans(cfg, sc->scans, sc->scan_count, lim), POLYC_OK);
}

/* The small scene in a block of `size` bytes. */
static polyc_status run_block(const scansim_scene *sc, const polyc_config *cfg,
                              const polyc_limits *lim, size_t size, size_t skew, size_t need)
{
    guarded g;
    polyc_ctx *ctx = (polyc_ctx *)&g;
    char what[96];
    snprintf(what, sizeof what, "block %zu of %zu bytes, skew %zu", size, need, skew);
    guarded_alloc(&g, size, skew);
    polyc_status st = polyc_init(g.block, size, cfg, lim, &ctx);
    if (size < need) {
        if (st != POLYC_ERR_NOMEM || ctx != NULL)
            fail_msg("%s: polyc_init gave %s", what, polyc_status_str(st));
    } else {
        if (st != POLYC_OK)
            fail_msg("%s: polyc_init gave %s", what, polyc_status_str(st));
        st = build_scene(ctx, sc, what);
        if (st != POLYC_OK)
            fail_msg("%s: the queried size is not enough: %s (%s)", what,
                     polyc_status_str(st), polyc_last_error(ctx));
    }
    guarded_check(&g, what);
    guarded_free(&g);
    return st;
}

static void test_every_block_size(void **state)
{
    (void)state;
    scansim_scene sc;
    polyc_config cfg;
    polyc_limits lim;
    open_small(&sc, &cfg, &lim);
    size_t need = polyc_memory_size(&cfg, &lim);
    assert_true(need > 4096);
    uint32_t runs = 0, ok = 0;
    /* every 16 bytes over the first 4 KiB, where the context header lives */
    for (size_t size = 0; size <= 4096; size += 16, runs++)
        ok += run_block(&sc, &cfg, &lim, size, size % 16, need) == POLYC_OK;
    /* 300 sizes spread over the rest, then the edge */
    for (uint32_t k = 1; k <= 300; k++, runs++) {
        size_t size = 4096 + (size_t)((double)(need - 4096) * k / 301.0);
        ok += run_block(&sc, &cfg, &lim, size, k % 16, need) == POLYC_OK;
    }
    for (size_t skew = 0; skew < 16; skew++, runs += 3) {
        ok += run_block(&sc, &cfg, &lim, need - 1, skew, need) == POLYC_OK;
        ok += run_block(&sc, &cfg, &lim, need, skew, need) == POLYC_OK;
        ok += run_block(&sc, &cfg, &lim, need + 1, skew, need) == POLYC_OK;
    }
    assert_int_equal(ok, 32);
    print_message("%u block sizes from 0 to %zu bytes, %u built\n", runs, need, ok);
    scansim_scene_free(&sc);
}

/* ---- limits too small: the later stages run out ------------------------ */

enum { L_SCANS, L_BEAMS, L_CELLS, L_VERTICES, L_POINTS, L_FIELDS };
static const char *const field_name[L_FIELDS] = {"max_scans", "max_beams", "max_grid_cells",
                                                 "max_vertices", "max_points"};

static uint32_t *field(polyc_limits *lim, int f)
{
    switch (f) {
    case L_SCANS: return &lim->max_scans;
    case L_BEAMS: return &lim->max_beams;
    case L_CELLS: return &lim->max_grid_cells;
    case L_VERTICES: return &lim->max_vertices;
    default: return &lim->max_points;
    }
}

/* The small scene with `lim`, in a block of exactly the queried size. On a
 * failure the context must still work: after polyc_reset an empty context
 * builds, and after another reset one of the scene's scans builds a map (or
 * the budget is too small even for it: NOMEM or LIMIT again). */
static polyc_status run_limits(const scansim_scene *sc, const polyc_config *cfg,
                               const polyc_limits *lim, const char *what)
{
    size_t size = polyc_memory_size(cfg, lim);
    assert_true(size > 0);
    guarded g;
    polyc_ctx *ctx = NULL;
    guarded_alloc(&g, size, 0);
    assert_int_equal(polyc_init(g.block, size, cfg, lim, &ctx), POLYC_OK);
    polyc_status st = build_scene(ctx, sc, what);
    if (st != POLYC_OK) {
        assert_int_equal(polyc_reset(ctx), POLYC_OK);
        assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK);
        assert_int_equal(polyc_polyline_count(ctx), 0);
        assert_int_equal(polyc_reset(ctx), POLYC_OK);
        scansim_scene part = *sc;
        part.scan_count = 1;
        polyc_status again = build_scene(ctx, &part, what);
        assert_true(again == POLYC_OK || again == POLYC_ERR_NOMEM || again == POLYC_ERR_LIMIT);
    }
    guarded_check(&g, what);
    guarded_free(&g);
    return st;
}

static void test_limits_too_small(void **state)
{
    (void)state;
    scansim_scene sc;
    polyc_config cfg;
    polyc_limits full;
    open_small(&sc, &cfg, &full);
    /* vertices and points as the scene needs at most: all beams */
    full.max_vertices = full.max_beams + 1024;
    full.max_points = full.max_beams;
    uint32_t runs = 0, nomem = 0, limit = 0;
    for (int f = 0; f < L_FIELDS; f++) {
        uint32_t top = *field(&full, f);
        /* 0 (derived), 1, 2, 3, ... then 40 steps up to the full value */
        for (uint32_t k = 0; k < 48; k++) {
            polyc_limits lim = full;
            uint32_t v = k < 8 ? k : (uint32_t)((uint64_t)top * (k - 7) / 40);
            if (v > top)
                break;
            *field(&lim, f) = v;
            char what[64];
            snprintf(what, sizeof what, "%s = %u of %u", field_name[f], v, top);
            polyc_status st = run_limits(&sc, &cfg, &lim, what);
            runs++;
            nomem += st == POLYC_ERR_NOMEM;
            limit += st == POLYC_ERR_LIMIT;
            if (v == top && st != POLYC_OK)
                fail_msg("%s: the full limits fail: %s", what, polyc_status_str(st));
        }
    }
    /* a few hundred random mixes of smaller limits */
    uint64_t seed = 12345;
    for (int i = 0; i < 200; i++, runs++) {
        polyc_limits lim = full;
        for (int f = i % 4 ? L_CELLS : 0; f < L_FIELDS; f++) {  /* mostly all scans */
            seed = seed * 6364136223846793005u + 1442695040888963407u;
            uint32_t top = *field(&full, f);
            *field(&lim, f) = (uint32_t)((double)(seed >> 40) / 16777216.0 * 1.2 * top);
            if (*field(&lim, f) > top)
                *field(&lim, f) = top;
        }
        char what[128];
        snprintf(what, sizeof what, "mix %d: %u scans %u beams %u cells %u vertices %u points", i,
                 lim.max_scans, lim.max_beams, lim.max_grid_cells, lim.max_vertices,
                 lim.max_points);
        polyc_status st = run_limits(&sc, &cfg, &lim, what);
        nomem += st == POLYC_ERR_NOMEM;
        limit += st == POLYC_ERR_LIMIT;
    }
    assert_true(nomem > 0 && limit > 0);
    print_message("%u limit sets: %u out of memory, %u over a limit\n", runs, nomem, limit);
    scansim_scene_free(&sc);
}

/* The brief's two cases by name: a grid budget far too small and a tiny
 * vertex budget fail with NOMEM; after polyc_reset the context builds a
 * scene that fits. */
static void test_named_cases(void **state)
{
    (void)state;
    scansim_scene sc;
    polyc_config cfg;
    polyc_limits lim;
    assert_int_equal(small_scene(&sc), 0);
    small_config(&cfg);
    assert_int_equal(polyc_limits_for_scans(&cfg, sc.scans, sc.scan_count, &lim), POLYC_OK);
    for (int c = 0; c < 2; c++) {
        polyc_limits small = lim;
        if (c == 0)
            small.max_grid_cells = 2048;    /* two tiles */
        else
            small.max_vertices = 4;
        size_t size = polyc_memory_size(&cfg, &small);
        guarded g;
        polyc_ctx *ctx = NULL;
        guarded_alloc(&g, size, 3);
        assert_int_equal(polyc_init(g.block, size, &cfg, &small, &ctx), POLYC_OK);
        polyc_status st = build_scene(ctx, &sc, c == 0 ? "tiny grid" : "tiny vertices");
        assert_int_equal(st, POLYC_ERR_NOMEM);
        assert_true(strlen(polyc_last_error(ctx)) > 0);
        /* a second try without reset fails the same way, nothing breaks */
        assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_ERR_NOMEM);
        assert_int_equal(polyc_reset(ctx), POLYC_OK);
        if (c == 0) {
            /* one beam fits in two tiles */
            float r = 0.5f;
            polyc_scan s = sc.scans[0];
            s.beam_count = 1;
            s.range_m = &r;
            assert_int_equal(polyc_add_scan(ctx, &s), POLYC_OK);
            assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK);
        } else {
            assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK);
        }
        guarded_check(&g, "named case");
        guarded_free(&g);
    }
    scansim_scene_free(&sc);
}

/* The queried size suffices for the simulator's scenes, built whole. */
static void test_query_enough_for_scenes(void **state)
{
    (void)state;
    const char *const names[] = {"square", "angled", "circle"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        scansim_scene sc;
        polyc_config cfg;
        polyc_limits lim;
        assert_int_equal(scansim_scene_builtin(&sc, names[i], 3u), 0);
        assert_int_equal(scansim_run(&sc), 0);
        polyc_config_default(&cfg);
        cfg.max_iterations = 2;
        assert_int_equal(polyc_limits_for_scans(&cfg, sc.scans, sc.scan_count, &lim), POLYC_OK);
        size_t size = polyc_memory_size(&cfg, &lim);
        guarded g;
        polyc_ctx *ctx = NULL;
        guarded_alloc(&g, size, 5);
        assert_int_equal(polyc_init(g.block, size, &cfg, &lim, &ctx), POLYC_OK);
        polyc_status st = POLYC_OK;
        for (uint32_t k = 0; st == POLYC_OK && k < sc.scan_count; k++)
            st = polyc_add_scan(ctx, &sc.scans[k]);
        if (st == POLYC_OK)
            st = polyc_build(ctx, NULL, NULL);
        if (st != POLYC_OK)
            fail_msg("%s: %s (%s)", names[i], polyc_status_str(st), polyc_last_error(ctx));
        guarded_check(&g, names[i]);
        guarded_free(&g);
        scansim_scene_free(&sc);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_block_size),
        cmocka_unit_test(test_limits_too_small),
        cmocka_unit_test(test_named_cases),
        cmocka_unit_test(test_query_enough_for_scenes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
