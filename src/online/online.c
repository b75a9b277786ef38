/* online.c - an online context: its limits and size from an area, its
 * block's layout (everything the online files carve, in one order, and the
 * scratch the steps share above the tiles), and the layer table that lends
 * the batch stages the online data. Takes: the caller's block, config and
 * online limits. Gives: a context that online_scan.c takes scans into,
 * online_correct.c corrects and online_update.c maps. */
#include "../online.h"

#include <math.h>
#include <string.h>

/* The hash's bound, in beams of 16 buckets: 69,632 buckets. */
#define ONLINE_HASH_BEAMS 4096u

void polyc__online_stage_limits(const polyc_online_limits *ol, polyc_limits *lim)
{
    memset(lim, 0, sizeof *lim);
    /* the current scan's slot and the kept ones' (at least two: the stages
     * size for scans, not for a single scan's chains) */
    lim->max_scans = 2 + ol->keep_scans;
    /* the spatial hash takes at most 16 buckets a beam of max_beams (and
     * fewer for a small grid): an update's pass over the points' order
     * walks every bucket, so their count stays bounded whatever the area
     * (buckets sized by the area made the same building's updates several
     * times slower in a large square than in one that just holds it) */
    lim->max_beams = ONLINE_HASH_BEAMS;
    lim->max_grid_cells = ol->max_grid_cells;
    lim->max_vertices = ol->max_vertices;
    /* a weighted point gathers the data cells of a 2 x 2 block: half of
     * them is room for blocks of under two cells on average (a wall's
     * blocks usually hold more, long-range data many more) */
    lim->max_points = ol->max_points / 2 > 16 ? ol->max_points / 2 : 16;
}

/* The limits' ranges; the square's side at most twice config.max_extent_m
 * (the data may lie on one side of the first pose), as a batch context
 * refuses data spanning more than it. */
static int limits_ok(const polyc_config *cfg, const polyc_online_limits *ol)
{
    float area = polyc__narrow(ol->area_m);
    return area > 1.0f && area <= 1e5f && area <= 2.0f * cfg->max_extent_m &&
           ol->max_grid_cells >= POLYC__TILE_CELLS &&
           ol->max_grid_cells <= 0x40000000u && ol->max_vertices >= 16 &&
           ol->max_vertices <= 0x10000000u && ol->max_points >= 16 && ol->max_points <= 0x10000000u &&
           ol->max_scan_beams > 0 && ol->max_scan_beams <= 0x1000000u &&
           ol->keep_beams <= 0x10000000u && ol->keep_scans <= 0x1000000u && ol->reserved == 0;
}

polyc_status polyc_online_limits_for_area(const polyc_config *config, double area_m,
                                          uint32_t max_scan_beams, polyc_online_limits *out)
{
    if (!config || !out)
        return POLYC_ERR_NULL;
    if (polyc_config_check(config, NULL) != POLYC_OK)
        return POLYC_ERR_CONFIG;
    memset(out, 0, sizeof *out);
    float area = polyc__narrow(area_m);
    /* a side too wide for the grid is the data's extent (any side over 1e5
     * is: max_extent_m is at most 1e4), not a bad argument */
    if (area > 2.0f * config->max_extent_m)
        return POLYC_ERR_EXTENT;
    if (!(area > 1.0f && area <= 1e5f) || max_scan_beams == 0)
        return POLYC_ERR_CONFIG;
    float side = ceilf(area / config->cell_m / POLYC__TILE_SIDE);
    float tiles = side * side;
    /* the tiles a building's walls reach: a share of its square's tiles,
     * a few percent of a campus's where most of the square is open ground
     * or never seen; a small square is taken whole, a large one for a
     * sixteenth (at least 1,024) */
    float stored = tiles <= 1024.0f ? tiles : fmaxf(1024.0f, ceilf(tiles / 16.0f));
    float cells = fminf(stored * POLYC__TILE_CELLS, 0x40000000);
    /* endpoints fall in a small share of a stored tile's cells (those
     * along its walls; more where long-range returns spread them in a small
     * building): room for one in 4 (the tool doubles the limits of a map
     * that needs more) */
    float points = fminf(fmaxf(cells / 4.0f, 4096.0f), 0x10000000);
    out->area_m = area_m;
    out->max_grid_cells = (uint32_t)cells;
    out->max_points = (uint32_t)points;
    /* vertices: the map and what the rounds and the finishing call trace
     * into it, a vertex per 16 data cells (room for a whole contour traced
     * at once, as the batch traces it) */
    out->max_vertices = (uint32_t)(points / 16.0f) + 4096;
    out->max_scan_beams = max_scan_beams;
    return POLYC_OK;
}

/* Everything an online context carves, in the block's order, on the block
 * or on the size query's counting arena (nothing is written then); the
 * grid's tiles come last, as beams reach them. ctx->cfg and ctx->lim are set. */
static int lay_out(polyc_ctx *ctx, polyc__online *on, polyc__arena *a)
{
    const polyc_online_limits *ol = &on->lim;
    int ok = 1;
    uint32_t slots = ctx->lim.max_scans;
    POLYC__CARVE(ok, a, ctx->scans, slots);
    POLYC__CARVE(ok, a, ctx->ranges, (size_t)ol->max_scan_beams + ol->keep_beams);
    POLYC__CARVE(ok, a, on->kept.id, ol->keep_scans + 1);
    POLYC__CARVE_ZERO(ok, a, on->kept.moved, ol->keep_scans / 32u + 1u);
    POLYC__CARVE(ok, a, on->kept.new_pose, 3 * (size_t)ol->keep_scans + 1u);
    int32_t V = polyc__max_vertices(&ctx->lim);
    if (!ok || !polyc__store_init(a, &ctx->store, V))
        return 0;
    int32_t lines = polyc__line_cap(V);
    if (a->base)
        ok &= polyc__flat_result(a, &ctx->flat, (uint32_t)lines, (uint32_t)V);
    else
        polyc__flat_reserve(a, V, 1);
    polyc__online_pub_carve(a, on, lines);
    ok &= on->pubs.pub && on->pubs.pub_next && on->pubs.gone;
    /* the grid's geometry first (its directory is carved last) */
    polyc__arena probe;
    polyc__arena_counting(&probe);
    polyc__arena saved = ctx->arena;
    ctx->arena = probe;
    polyc_status st = polyc__grid_online_init(ctx, polyc__narrow(ol->area_m), ol->max_grid_cells);
    ctx->arena = saved;
    if (st != POLYC_OK)
        return 0;
    size_t dir_n = (size_t)ctx->grid.tiles_x * (size_t)ctx->grid.tiles_y;
    uint32_t tile_cap = ctx->grid.tile_cap;
    ok &= polyc__prior_online(ctx, &on->prior, &on->acc, a);
    ok = ok && polyc__cells_carve(a, &on->tab, ol->max_points, tile_cap);
    POLYC__CARVE_ZERO(ok, a, on->poses.pose_bits, dir_n / 32 + 1);
    POLYC__CARVE(ok, a, on->poses.spacing_dist, dir_n);
    POLYC__CARVE_ZERO(ok, a, on->backlog.dirty_since, dir_n);
    POLYC__CARVE(ok, a, on->backlog.dirty, dir_n);
    /* buckets as narrow as a batch's over the same area (the search walks
     * 3 x 3 of them around every point it scores): an update moves the
     * other buckets' points and starts as whole blocks (online_data.c), so
     * their number costs memory more than time */
    int32_t bucket_cap = polyc__hash_bucket_cap(&ctx->lim), by_area = polyc__hash_bucket_cap_tiles(dir_n);
    ok = ok && polyc__opt_carve_lasting(ctx, a, &on->opt, bucket_cap > by_area ? bucket_cap : by_area);
    if (!ok)
        return 0;
    size_t P = (size_t)polyc__points_bound(&ctx->cfg, &ctx->lim), nb = (size_t)on->opt.h.bx * (size_t)on->opt.h.by;
    POLYC__CARVE(ok, a, on->pt_tile, P);
    POLYC__CARVE(ok, a, on->bucket_fill, nb);
    POLYC__CARVE_ZERO(ok, a, on->backlog.tile_raw, tile_cap);
    POLYC__CARVE_ZERO(ok, a, on->backlog.tile_new, tile_cap);
    POLYC__CARVE_ZERO(ok, a, on->backlog.tile_miss, tile_cap);
    /* the grid's records of misses in tiles not stored: carved here, handed
     * to the grid below (its layout clears the grid) */
    ok = ok && polyc__records_carve(a, &on->rec, tile_cap, dir_n);
    if (!ok)
        return 0;
    saved = ctx->arena;
    ctx->arena = *a;
    st = polyc__grid_online_init(ctx, polyc__narrow(ol->area_m), ol->max_grid_cells);
    *a = ctx->arena;
    ctx->arena = saved;
    if (st != POLYC_OK)
        return 0;
    ctx->grid.rec = &on->rec;
    /* the tiles, and above them the largest step's scratch */
    size_t scratch = 0;
    for (int step = POLYC__STEP_TRACE; step <= POLYC__STEP_LEARN; step++) {
        polyc__arena c;
        polyc__arena_counting(&c);
        polyc__online_scratch(&c, on, (int32_t)P, (polyc__online_step)step);
        if (step == POLYC__STEP_TRACE) { /* and the trace's walk, which trace.c carves, or after it
                                          * the round's flags */
            size_t walk = polyc__bytes(2 * (size_t)polyc__online_cells_cap(on) + 2, sizeof(int32_t));
            size_t flags = polyc__bytes((size_t)polyc__max_vertices(&ctx->lim), 1);
            c.peak = polyc__add(c.peak, walk > flags ? walk : flags);
        }
        scratch = c.peak > scratch ? c.peak : scratch;
    }
    size_t cast = polyc__contour_cast_bytes(dir_n); /* relabel's */
    scratch = cast > scratch ? cast : scratch;
    on->scr.cells = NULL;
    on->scr.pts_tmp = NULL;
    on->scr.view_tmp = NULL;
    on->scr.fresh_tile = NULL;
    on->scr.fresh_bucket = NULL;
    on->scr.learn_cache = NULL;
    on->scr.seg_data = NULL;
    a->peak = polyc__add(a->used, polyc__add(polyc__bytes(tile_cap, sizeof(polyc__tile)), scratch));
    return 1;
}



/* The online map's optimiser, kept between the calls. */
static polyc__opt *live_opt(polyc_ctx *ctx)
{
    return &ctx->online->opt;
}

/* What the online layer lends the batch stages it runs on its own data. */
static const polyc__layer online_layer = {
    polyc__online_spacing, polyc__online_points_scratch, polyc__online_collect, polyc__records_walk,
    polyc__records_take, live_opt,
};

static size_t header_bytes(void)
{
    return polyc__bytes(1, sizeof(polyc__online_head));
}

size_t polyc_online_memory_size(const polyc_config *config, const polyc_online_limits *limits)
{
    if (!config || !limits || polyc_config_check(config, NULL) != POLYC_OK || !limits_ok(config, limits))
        return 0;
    polyc_ctx ctx;
    polyc__online on;
    memset(&ctx, 0, sizeof ctx);
    memset(&on, 0, sizeof on);
    ctx.cfg = *config;
    on.lim = *limits;
    ctx.online = &on;
    polyc__online_stage_limits(limits, &ctx.lim);
    polyc__arena_counting(&ctx.arena);
    polyc__arena a;
    polyc__arena_counting(&a);
    if (!lay_out(&ctx, &on, &a))
        return 0;
    size_t n = polyc__add(polyc__add(header_bytes(), 32), a.peak);
    return n == SIZE_MAX ? 0 : n;
}

polyc_status polyc_online_init(void *block, size_t size, const polyc_config *config,
                               const polyc_online_limits *limits, polyc_ctx **out)
{
    polyc_status st = polyc__init_args(block, config, limits, out);
    if (st == POLYC_OK && !limits_ok(config, limits))
        st = POLYC_ERR_CONFIG;
    /* the context's header, then the online state's, then the arena */
    polyc_ctx *ctx;
    if (st == POLYC_OK)
        st = polyc__place_ctx(block, size, polyc_online_memory_size(config, limits), header_bytes(),
                              config, &ctx);
    if (st != POLYC_OK)
        return st;
    polyc__online *on = &((polyc__online_head *)(void *)ctx)->on;
    ctx->online = on;
    ctx->layer = &online_layer;
    on->lim = *limits;
    polyc__online_stage_limits(limits, &ctx->lim);
    polyc__arena a = ctx->arena;
    if (!lay_out(ctx, on, &a))
        return POLYC_ERR_NOMEM;
    ctx->arena = a;
    ctx->arena.peak = ctx->arena.used;
    ctx->flat.count = 0;
    ctx->stage = POLYC__STAGE_SCANS;
    *out = ctx;
    return POLYC_OK;
}

uint64_t polyc_online_version(const polyc_ctx *ctx)
{
    return polyc__check_ctx(ctx) == POLYC_OK && ctx->online ? ctx->online->pubs.version : 0;
}
