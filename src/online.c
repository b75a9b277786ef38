/* online.c - an online context: sized from an area, it takes scans one at
 * a time into what the batch stages would compute from all of them (the
 * grid's counts, each cell's endpoint sums, the contour, the angle prior
 * and the accuracy), remembers the tiles they changed (the backlog), and
 * keeps the scans the caller asks it to, so that their poses can be
 * corrected. Takes: scans, corrections. Gives: the state online_round.c
 * re-optimises the map from. */
#include "online.h"
#include "walk.h"

#include <math.h>
#include <string.h>

/* A tile joins the backlog when the endpoints that came in (or went out)
 * since its points were last made reach this share of those it held then:
 * where the map is seen again and again, a scan changes a tile's data by a
 * few per cent, too little to move a vertex, and the update leaves it;
 * where the robot sees something new, the first endpoints count whole. */
#define CHANGE_SHARE 0.25f
/* and at least this many endpoints: a few far returns a scan (a sparse
 * tile) wait for the next */
#define CHANGE_MIN 16u
/* A sparse tile (far walls seen through a door, a few returns a scan)
 * never gains CHANGE_MIN endpoints at once: it joins the backlog at the
 * periodic check once it holds SPARSE_MIN new endpoints and at least as
 * many as it held when last made. Without this such walls waited for the
 * finishing call: on intel the map of the first 100 scans scored 1.66
 * times the BIC of the batch map of those scans on the batch's data
 * (tools/eval/fairbic.h), 0.995 with it. */
#define SPARSE_MIN 4u

/* The hash's bound, in beams of 16 buckets: 69,632 buckets. */
#define ONLINE_HASH_BEAMS 4096u

/* Endpoints and poses must stay this far inside the area: vertices may
 * wander a little past the data (the spatial hash's own margin is 2 m). */
#define AREA_MARGIN_M 1.0f

/* relabel: the marks pay when the scans' beams times this reach the
 * stored cells (a beam walks some tens of cells in the tiles it does not
 * skip) */
#define RELABEL_CELLS_PER_BEAM 32u

void polyc__online_stage_limits(const polyc_online_limits *ol, polyc_limits *lim)
{
    memset(lim, 0, sizeof *lim);
    /* the current scan's slot and the kept ones' (at least two: the stages
     * size for scans, not for a single scan's chains) */
    lim->max_scans = 2 + ol->keep_scans;
    /* the spatial hash takes at most 16 buckets a beam of max_beams (and
     * fewer for a small grid): an update's pass over the points' order
     * walks every bucket, so their count stays bounded whatever the area
     * (on a 500 m square, a bucket per 0.4 m made intel's updates 7 times
     * slower than on its 50 m one) */
    lim->max_beams = ONLINE_HASH_BEAMS;
    lim->max_grid_cells = ol->max_grid_cells;
    lim->max_vertices = ol->max_vertices;
    /* a weighted point gathers the data cells of a 2 x 2 block: half of
     * them is room for blocks of under two cells on average (intel's hold
     * 2.5, freiburg-079's 7) */
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
    /* the tiles a building's walls reach: intel 851 of its 50 m square's
     * 3,906, freiburg-campus 15,399 of its 524 m square's 429,025; a small
     * square is taken whole, a large one for a sixteenth (at least 1,024) */
    float stored = tiles <= 1024.0f ? tiles : fmaxf(1024.0f, ceilf(tiles / 16.0f));
    float cells = fminf(stored * POLYC__TILE_CELLS, 0x40000000);
    /* endpoints fall in one cell in 15 of a stored tile on intel (57,712
     * cells in 851 tiles), one in 5 on freiburg-079 (143,127 in 720, long
     * range in a small building): room for one in 4 (the tool doubles the
     * limits of a map that needs more) */
    float points = fminf(fmaxf(cells / 4.0f, 4096.0f), 0x10000000);
    out->area_m = area_m;
    out->max_grid_cells = (uint32_t)cells;
    out->max_points = (uint32_t)points;
    /* vertices: the map and what the rounds and the finishing call trace
     * into it, a vertex per 16 data cells (room for a whole contour traced
     * at once: intel's batch trace is 15,000 of them) */
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
    POLYC__CARVE(ok, a, on->kept_id, ol->keep_scans + 1);
    POLYC__CARVE_ZERO(ok, a, on->moved, ol->keep_scans / 32u + 1u);
    POLYC__CARVE(ok, a, on->new_pose, 3 * (size_t)ol->keep_scans + 1u);
    int32_t V = polyc__max_vertices(&ctx->lim);
    if (!ok || !polyc__store_init(a, &ctx->store, V))
        return 0;
    int32_t lines = polyc__line_cap(V);
    if (a->base)
        ok &= polyc__flat_init(a, &ctx->flat, (uint32_t)lines, (uint32_t)V);
    else
        polyc__flat_reserve(a, V);
    polyc__online_pub_carve(a, on, lines);
    ok &= on->pub && on->pub_next && on->gone;
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
    ok = ok && polyc__cells_carve(a, on, tile_cap);
    POLYC__CARVE_ZERO(ok, a, on->pose_bits, dir_n / 32 + 1);
    POLYC__CARVE(ok, a, on->spacing_dist, dir_n);
    POLYC__CARVE_ZERO(ok, a, on->dirty_since, dir_n);
    POLYC__CARVE(ok, a, on->dirty, dir_n);
    on->cells_cap = ol->max_points + 1;
    ok = ok && polyc__opt_carve_online(ctx, a, &on->opt);
    if (!ok)
        return 0;
    size_t P = (size_t)polyc__points_bound(&ctx->cfg, &ctx->lim), nb = (size_t)on->opt.h.bx * (size_t)on->opt.h.by;
    POLYC__CARVE(ok, a, on->pt_tile, P);
    POLYC__CARVE(ok, a, on->bucket_fill, nb);
    POLYC__CARVE_ZERO(ok, a, on->tile_raw, tile_cap);
    POLYC__CARVE_ZERO(ok, a, on->tile_new, tile_cap);
    POLYC__CARVE_ZERO(ok, a, on->tile_miss, tile_cap);
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
            size_t walk = polyc__bytes(2 * (size_t)on->cells_cap + 2, sizeof(int32_t));
            size_t flags = polyc__bytes((size_t)polyc__max_vertices(&ctx->lim), 1);
            c.peak = polyc__add(c.peak, walk > flags ? walk : flags);
        }
        scratch = c.peak > scratch ? c.peak : scratch;
    }
    size_t cast = polyc__contour_cast_bytes(dir_n); /* relabel's */
    scratch = cast > scratch ? cast : scratch;
    on->cells = NULL;
    on->pts_tmp = NULL;
    on->view_tmp = NULL;
    on->fresh_tile = NULL;
    on->fresh_bucket = NULL;
    on->learn_cache = NULL;
    on->seg_data = NULL;
    a->peak = polyc__add(a->used, polyc__add(polyc__bytes(tile_cap, sizeof(polyc__tile)), scratch));
    return 1;
}

/* A step's scratch lives only while the step runs, so the steps share one
 * region above the tiles: the block holds the largest, not their sum. */
int polyc__online_scratch(polyc__arena *a, polyc__online *on, int32_t points, polyc__online_step step)
{
    int ok = 1;
    size_t P = (size_t)points;
    switch (step) {
    case POLYC__STEP_TRACE:
        POLYC__CARVE(ok, a, on->cells, 2 * (size_t)on->cells_cap);
        break;
    case POLYC__STEP_POINTS:
        POLYC__CARVE(ok, a, on->pts_tmp, P);
        POLYC__CARVE(ok, a, on->view_tmp, 2 * P);
        POLYC__CARVE(ok, a, on->fresh_tile, P);
        POLYC__CARVE(ok, a, on->fresh_bucket, P);
        break;
    case POLYC__STEP_LEARN:
        POLYC__CARVE(ok, a, on->learn_cache, 3 * (size_t)on->lim.max_scan_beams);
        break;
    case POLYC__STEP_DATALESS:
        POLYC__CARVE(ok, a, on->seg_data, (size_t)on->opt.s->v_cap);
        break;
    }
    return ok;
}

/* The layer's spacing table (polyc__layer): from the tiles where some pose
 * was (the poses are not kept);
 * made again when a pose fell in a new tile, at most once in this many
 * scans (a pass over the area's tiles: on freiburg-campus's 300 m square,
 * at every new pose tile, 30 % of the updates' time): meanwhile a new
 * tile's spacing is measured from the poses before it. */
#define REMAKE_SCANS 32u

static polyc_status online_spacing(polyc_ctx *ctx, polyc__spacing *sp, size_t n)
{
    polyc__online *on = ctx->online;
    sp->min_step_rad = on->min_step_rad;
    sp->dist = on->spacing_dist;
    if (!on->spacing_stale || (!on->spacing_now && on->spacing_scans != 0 &&
                               on->scans - on->spacing_scans < REMAKE_SCANS))
        return POLYC_OK;
    for (size_t i = 0; i < n; i++)
        sp->dist[i] = (on->pose_bits[i >> 5] >> (i & 31)) & 1u ? 0.0f : 1e30f;
    polyc__spacing_chamfer(sp);
    on->spacing_stale = 0;
    on->spacing_scans = on->scans;
    return POLYC_OK;
}

/* The layer's points' scratch (polyc__layer, for polyc__opt_refresh). */
static int points_scratch(polyc_ctx *ctx, int32_t points)
{
    return polyc__online_scratch(&ctx->arena, ctx->online, points, POLYC__STEP_POINTS);
}

/* What the online layer lends the batch stages it runs on its own data. */
static const polyc__layer online_layer = {
    online_spacing, points_scratch, polyc__online_collect, polyc__records_walk, polyc__records_take,
};

static size_t header_bytes(void)
{
    return polyc__add(polyc__bytes(1, sizeof(polyc_ctx)), polyc__bytes(1, sizeof(polyc__online)));
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
    if (!out)
        return POLYC_ERR_NULL;
    *out = NULL;
    if (!block || !config || !limits)
        return POLYC_ERR_NULL;
    if (polyc_config_check(config, NULL) != POLYC_OK || !limits_ok(config, limits))
        return POLYC_ERR_CONFIG;
    /* the context's header, then the online state's, then the arena */
    polyc_ctx *ctx;
    polyc_status st = polyc__place_ctx(block, size, polyc_online_memory_size(config, limits),
                                       header_bytes(), config, &ctx);
    if (st != POLYC_OK)
        return st;
    polyc__online *on = (polyc__online *)((unsigned char *)ctx + polyc__bytes(1, sizeof(polyc_ctx)));
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

/* ---- one scan in (or out) ---- */

static void mark_dirty(polyc__online *on, size_t d)
{
    if (on->dirty_since[d] == 0) {
        on->dirty_since[d] = on->scans + 1;
        on->dirty[on->dirty_n++] = (uint32_t)d;
    }
}

/* A tile also joins the backlog when beams have passed through its cells
 * with hits as often as it held endpoints at its last update: then the
 * data rule may drop them (a person who walked by); and a sparse tile by
 * SPARSE_MIN. Both looked at every MISS_CHECK_SCANS scans (a pass over the
 * directory). */
#define MISS_CHECK_SCANS 8u

void polyc__online_backlog_misses(polyc_ctx *ctx)
{
    polyc__online *on = ctx->online;
    if (on->scans % MISS_CHECK_SCANS != 0)
        return;
    const polyc__grid *g = &ctx->grid;
    size_t dir_n = (size_t)g->tiles_x * (size_t)g->tiles_y;
    for (size_t d = 0; d < dir_n; d++) {
        if (!g->dir[d])
            continue;
        uint32_t k = g->dir[d] - 1;
        if (on->tile_miss[k] >= CHANGE_MIN && (float)on->tile_miss[k] >= on->tile_raw[k])
            mark_dirty(on, d);
        else if (on->tile_new[k] >= SPARSE_MIN && on->tile_new[k] >= on->tile_raw[k])
            mark_dirty(on, d);
    }
}

void polyc__online_backlog_all(polyc_ctx *ctx)
{
    const polyc__grid *g = &ctx->grid;
    size_t dir_n = (size_t)g->tiles_x * (size_t)g->tiles_y;
    for (size_t d = 0; d < dir_n; d++)
        if (g->dir[d])
            mark_dirty(ctx->online, d);
}

/* The tile index of cell (ix, iy) inside the grid, or -1. */
static int64_t tile_of(const polyc__grid *g, int32_t ix, int32_t iy)
{
    if (ix < 0 || iy < 0 || ix >= g->width || iy >= g->height)
        return -1;
    return (int64_t)(iy >> POLYC__TILE_SHIFT) * g->tiles_x + (ix >> POLYC__TILE_SHIFT);
}

/* The sum of the view vectors of cell (ix, iy)'s endpoints (towards their
 * sensors); 0, 0 for a cell without endpoints. */
void polyc__online_cell_view(const polyc_ctx *ctx, int32_t ix, int32_t iy, float *vx, float *vy)
{
    const polyc__online *on = ctx->online;
    const polyc__grid *g = &ctx->grid;
    int64_t d = tile_of(g, ix, iy);
    *vx = *vy = 0.0f;
    if (d < 0 || g->dir[d] == 0)
        return;
    uint32_t e = polyc__cell_find(on, polyc__cell_key(g->dir[d] - 1, polyc__cell_index(ix, iy)));
    if (e == 0)
        return;
    *vx = on->sums[e - 1].vx;
    *vy = on->sums[e - 1].vy;
}

/* Each endpoint into its cell's sums (sign -1: out again); the tiles they
 * fall in join the backlog. 0 when the sums are used up. */
static int sum_endpoints(polyc_ctx *ctx, const polyc__scan *s, float sign)
{
    polyc__online *on = ctx->online;
    const polyc__grid *g = &ctx->grid;
    int ok = 1;
    for (uint32_t i = 0; i < s->count; i++) {
        polyc__beam b;
        if (!polyc__beam_path(ctx, s, i, &b) || !b.hit)
            continue;
        float fx = floorf(b.ex), fy = floorf(b.ey);
        int32_t ix = (int32_t)fx, iy = (int32_t)fy;
        int64_t d = tile_of(g, ix, iy);
        if (d < 0 || g->dir[d] == 0)
            continue;
        uint32_t k = g->dir[d] - 1;
        if (++on->tile_new[k] >= CHANGE_MIN && (float)on->tile_new[k] >= CHANGE_SHARE * on->tile_raw[k])
            mark_dirty(on, (size_t)d);
        uint32_t key = polyc__cell_key(k, polyc__cell_index(ix, iy));
        uint32_t e = sign < 0.0f ? polyc__cell_find(on, key) : polyc__cell_add(on, key);
        if (e == 0) { /* the entries are used up (or a cell without sums taken back) */
            if (sign > 0.0f)
                ok = 0;
            continue;
        }
        polyc__cell_sums *c = &on->sums[e - 1];
        float ox = (b.ex - fx - 0.5f) * g->cell_m, oy = (b.ey - fy - 0.5f) * g->cell_m;
        c->fx += sign * ox;
        c->fy += sign * oy;
        c->fxx += sign * ox * ox;
        c->fxy += sign * ox * oy;
        c->fyy += sign * oy * oy;
        c->vx += sign * (b.sx - b.ex) * g->cell_m;
        c->vy += sign * (b.sy - b.ey) * g->cell_m;
        c->n = sign > 0.0f ? c->n + 1 : (c->n > 0 ? c->n - 1 : 0);
        if (c->n == 0) /* its last endpoint went (a correction): the entry is free */
            polyc__cell_drop(on, e);
    }
    return ok;
}

/* Labels the first occupied cell along each beam as contour, or a
 * reflection's end cell by the data fallback (contour.c), on the grid as it
 * stands with this scan counted (the batch casts once more on the final
 * grid). */
static void label_contour(polyc_ctx *ctx, const polyc__scan *s)
{
    const polyc__grid *g = &ctx->grid;
    float thr = ctx->cfg.contour_threshold;
    for (uint32_t i = 0; i < s->count; i++) {
        polyc__beam b;
        if (!polyc__beam_path(ctx, s, i, &b))
            continue;
        polyc__walk w;
        polyc__walk_start(&w, &b);
        int32_t cx = w.ex, cy = w.ey;
        /* tile by tile: over tiles no beam wanted (no hit, so no occupied
         * cell) in one move, as the grid's count does */
        const polyc__tile *t = NULL;
        int in = w.n > 0 && polyc__walk_enter(&w, g->width, g->height);
        while (in && w.n > 0) {
            if (!(t = polyc__grid_tile(g, w.ix, w.iy))) {
                int to = polyc__walk_skip_tiles(&w, g->width, g->height, g->tiles_x, g->wanted);
                if (to <= 0)
                    break; /* the end cell next, or out of the grid */
                in = polyc__walk_enter(&w, g->width, g->height);
                continue;
            }
            int left = 0, found = 0;
            do {
                if (polyc__cell_occupied(t, w.idx, thr)) {
                    found = 1;
                    break;
                }
                left = polyc__walk_step(&w);
            } while (!left && w.n > 0);
            if (found) {
                cx = w.ix;
                cy = w.iy;
                break;
            }
            if (left && w.n > 0)
                in = polyc__walk_enter(&w, g->width, g->height);
        }
        polyc__tile *e = polyc__grid_tile(g, cx, cy);
        if (e && (polyc__cell_occupied(e, polyc__cell_index(cx, cy), thr) ||
                  (b.hit && polyc__contour_data_alone(ctx, cx, cy, 0))))
            e->contour[cy & (POLYC__TILE_SIDE - 1)] |= 1u << (cx & (POLYC__TILE_SIDE - 1));
    }
}

/* How a scan goes into the grid (accumulate): */
enum {
    SCAN_NEW,      /* a new scan: its contour and its lines too */
    SCAN_MOVED,    /* a corrected scan, in again at its new pose */
    SCAN_OUT,      /* its counts and sums out again */
    SCAN_RECOUNT   /* in again on cleared counts, as a batch counts it (its
                    * records later: polyc__online_redo_records); the misses
                    * on hit cells, which put a tile in the backlog, are
                    * not tallied (every tile joins it: polyc__online_apply_corrections) */
};

/* The scan's beams into the grid and its endpoints into the sums; a new
 * scan's first occupied cells into the contour and its lines into the
 * prior. SCAN_OUT takes its counts and sums out again (the prior and the
 * contour keep what it gave: see docs/algorithm.md, "Online"). A corrected
 * scan's contour is cast once every waiting correction is in the grid
 * (polyc__online_apply_corrections). */
static polyc_status accumulate(polyc_ctx *ctx, const polyc__scan *s, uint32_t number, int how)
{
    polyc__online *on = ctx->online;
    const polyc__grid *g = &ctx->grid;
    int take_back = how == SCAN_OUT;
    polyc_status st = how == SCAN_RECOUNT ? polyc__grid_recount_scan(ctx, s)
                                          : polyc__grid_add_scan(ctx, s, take_back, on->tile_miss);
    int sums_ok = sum_endpoints(ctx, s, take_back ? -1.0f : 1.0f);
    if (take_back)
        return st;
    /* A new scan whose endpoints outgrow the data cells, or the weighted
     * points an update collects from them (their 2 x 2 blocks), goes out
     * again: an update after an accepted add can always run (with blocks
     * of one or two cells on average, limits.max_points / 2 points filled
     * long before the cells did, and every update and the finish failed) */
    if (how == SCAN_NEW && st == POLYC_OK &&
        (!sums_ok || on->blocks_n > (uint32_t)polyc__points_bound(&ctx->cfg, &ctx->lim))) {
        polyc__grid_add_scan(ctx, s, 1, on->tile_miss);
        sum_endpoints(ctx, s, -1.0f);
        on->refused = 1;
        return polyc__fail(ctx, POLYC_ERR_NOMEM,
                           "no room for the scan's endpoints (limits.max_points): not added");
    }
    if (how == SCAN_NEW) {
        label_contour(ctx, s);
        /* (the block is sized for it; without it, NULL: the same lines,
         * the endpoints computed twice) */
        size_t mark = ctx->arena.used;
        polyc__online_scratch(&ctx->arena, on, 0, POLYC__STEP_LEARN);
        polyc__prior_learn_scan(ctx, &on->prior, s, number, on->learn_cache, on->lim.max_scan_beams,
                                &on->acc);
        ctx->arena.used = mark;
        on->learn_cache = NULL;
    }
    int64_t d = tile_of(g, (int32_t)floorf((s->x_m - g->frame_ox) * g->inv_cell),
                        (int32_t)floorf((s->y_m - g->frame_oy) * g->inv_cell));
    if (d >= 0 && !((on->pose_bits[d >> 5] >> (d & 31)) & 1u)) {
        on->pose_bits[d >> 5] |= 1u << (d & 31);
        on->spacing_stale = 1;
    }
    if (s->count > 1 && (on->min_step_rad == 0.0f || fabsf(s->step_rad) < on->min_step_rad))
        on->min_step_rad = fabsf(s->step_rad);
    on->last_x = s->x_m;
    on->last_y = s->y_m;
    if (st == POLYC_OK && !sums_ok)
        st = polyc__fail(ctx, POLYC_ERR_NOMEM, "more cells with endpoints than limits.max_points");
    return st;
}

/* Whether the scan at its pose lies inside the area (frame metres). */
static int inside_area(const polyc_ctx *ctx, const polyc_scan *s)
{
    return polyc__frame_inside(ctx, s, 0.5f * polyc__narrow(ctx->online->lim.area_m) - AREA_MARGIN_M);
}

/* Kept scan k as the caller gave it, at another pose (frame-free metres). */
static void moved_scan(const polyc_ctx *ctx, uint32_t k, double x, double y, double theta,
                       polyc_scan *out)
{
    const polyc__scan *d = &ctx->scans[1 + k];
    memset(out, 0, sizeof *out);
    out->pose_x_m = x;
    out->pose_y_m = y;
    out->pose_theta_rad = theta;
    out->start_angle_rad = d->start_rad;
    out->angle_step_rad = d->step_rad;
    out->min_range_m = d->min_m;
    out->max_range_m = d->max_m;
    out->beam_count = d->count;
    out->range_m = ctx->ranges + d->first;
}

polyc_status polyc_online_add_scan(polyc_ctx *ctx, const polyc_scan *s, int keep, uint32_t *scan_id)
{
    polyc_status cst = polyc__enter(ctx, s != NULL);
    if (cst != POLYC_OK)
        return cst;
    polyc__online *on = ctx->online;
    if (!on)
        return polyc__fail(ctx, POLYC_ERR_STATE, "not an online context (polyc_online_init)");
    if ((cst = polyc__scan_check(ctx, s, on->scans)) != POLYC_OK)
        return cst;
    if (s->beam_count > on->lim.max_scan_beams)
        return polyc__fail(ctx, POLYC_ERR_LIMIT, "a scan with more beams than limits.max_scan_beams");
    if (keep && (on->kept_n >= on->lim.keep_scans || s->beam_count > on->lim.keep_beams - on->kept_beams))
        return polyc__fail(ctx, POLYC_ERR_LIMIT, "no room to keep the scan (limits.keep_scans, keep_beams)");
    if (on->moved_n > 0) { /* the waiting corrections go in first */
        polyc_status cst2 = polyc__online_apply_corrections(ctx, NULL);
        if (cst2 != POLYC_OK)
            return cst2;
    }
    polyc__online_learn_due(ctx); /* (before this scan's lines join the prior) */
    if (!ctx->have_frame) { /* the grid was laid out around (0, 0) */
        polyc__frame_set(ctx, s->pose_x_m, s->pose_y_m);
        polyc__frame_grid_origin(ctx, &ctx->grid, ctx->grid.frame_ox, ctx->grid.frame_oy);
    }
    if (!inside_area(ctx, s))
        return polyc__fail(ctx, POLYC_ERR_EXTENT, "the scan reaches outside limits.area_m around the first pose");
    /* the current scan is slot 0; a kept one has its own slot and ranges */
    polyc__scan *d = &ctx->scans[0];
    uint32_t first = 0;
    if (keep) {
        d = &ctx->scans[1 + on->kept_n];
        first = on->lim.max_scan_beams + on->kept_beams;
    }
    polyc__take_scan(ctx, d, s, first);
    on->refused = 0;
    polyc_status st = accumulate(ctx, d, on->scans, SCAN_NEW);
    if (on->refused)
        return st; /* (nothing of it stays: not counted, not kept) */
    polyc__tally_beams(ctx, s);
    if (keep) {
        on->kept_id[on->kept_n++] = on->scans;
        on->kept_beams += s->beam_count;
    }
    if (scan_id)
        *scan_id = on->scans;
    on->scans++;
    on->pending++;
    ctx->stats.scans = on->scans;
    return st;
}

/* ---- pose corrections ----
 * polyc_online_correct only notes the new pose; the next update, finish or
 * add applies every correction waiting, in one of two ways:
 * - when every scan is kept and at least half of them moved, the grid's
 *   counts and the cells' sums are cleared and every kept scan counted
 *   again, as a batch build counts them: the tiles of all their hits
 *   wanted first, then one cast each, over the tiles not stored in one
 *   move; the records of those the updates make again after (online_grid.c).
 *   Taking each scan out and in again costs two casts a scan (intel: 910
 *   corrections in 288 ms, against 130 counted afresh), and the float sums
 *   come out exact;
 * - otherwise each moved scan's counts and sums are taken out exactly (the
 *   counters are integers; one that saturated is not taken below 0) and
 *   added back at the new pose.
 * Then the contour is cast, on the grid with every correction in it: a
 * scan cast as its correction came would meet, at its new pose, cells that
 * still held the misses of the scans not corrected yet, and see through
 * walls those scans saw (intel's drift row: 1.056 times the batch map's
 * BIC that way, 0.986 cast after all). When every scan is kept, the
 * contour is cleared and cast from all of them: the batch's contour, with
 * the old poses' gone; otherwise the old poses' contour stays (it only
 * seeds the trace). */

polyc_status polyc_online_correct(polyc_ctx *ctx, uint32_t scan_id, double pose_x_m,
                                  double pose_y_m, double pose_theta_rad)
{
    polyc_status cst = polyc__enter(ctx, 1);
    if (cst != POLYC_OK)
        return cst;
    polyc__online *on = ctx->online;
    if (!on)
        return polyc__fail(ctx, POLYC_ERR_STATE, "not an online context (polyc_online_init)");
    uint32_t lo = 0, hi = on->kept_n;
    while (lo < hi) { /* kept_id ascends */
        uint32_t mid = lo + (hi - lo) / 2;
        if (on->kept_id[mid] < scan_id)
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo >= on->kept_n || on->kept_id[lo] != scan_id)
        return polyc__fail(ctx, POLYC_ERR_RANGE, "the scan was not kept (polyc_online_add_scan's keep)");
    if (!polyc__pose_ok(pose_x_m, pose_y_m, pose_theta_rad))
        return polyc__fail(ctx, POLYC_ERR_SCAN, "scan pose is not finite or beyond 1e7 m");
    polyc_scan moved;
    moved_scan(ctx, lo, pose_x_m, pose_y_m, pose_theta_rad, &moved);
    if (!inside_area(ctx, &moved))
        return polyc__fail(ctx, POLYC_ERR_EXTENT, "the scan reaches outside limits.area_m around the first pose");
    on->new_pose[3 * (size_t)lo] = pose_x_m;
    on->new_pose[3 * (size_t)lo + 1] = pose_y_m;
    on->new_pose[3 * (size_t)lo + 2] = pose_theta_rad;
    if (!((on->moved[lo >> 5] >> (lo & 31)) & 1u)) {
        on->moved[lo >> 5] |= 1u << (lo & 31);
        on->moved_n++;
    }
    on->pending++;
    return POLYC_OK;
}

static int is_moved(const polyc__online *on, uint32_t k)
{
    return (on->moved[k >> 5] >> (k & 31)) & 1u;
}

/* Kept scan k at its waiting pose. */
static void take_new_pose(polyc_ctx *ctx, uint32_t k)
{
    polyc__online *on = ctx->online;
    polyc__scan *d = &ctx->scans[1 + k];
    const double *p = &on->new_pose[3 * (size_t)k];
    polyc_scan moved;
    moved_scan(ctx, k, p[0], p[1], p[2], &moved);
    polyc__store_scan(ctx, d, &moved, d->first);
}

/* Every kept scan counted afresh (every scan is kept); the records after. */
static polyc_status count_afresh(polyc_ctx *ctx)
{
    polyc__online *on = ctx->online;
    polyc__grid *g = &ctx->grid;
    for (uint32_t k = 0; k < on->kept_n; k++)
        if (is_moved(on, k))
            take_new_pose(ctx, k);
    polyc__records_clear_counts(g, &on->rec);
    polyc__cells_clear(on, g->tile_count);
    memset(on->tile_new, 0, (size_t)g->tile_count * sizeof *on->tile_new);
    memset(on->tile_miss, 0, (size_t)g->tile_count * sizeof *on->tile_miss);
    for (uint32_t k = 0; k < on->kept_n; k++)
        polyc__grid_want(ctx, &ctx->scans[1 + k]);
    polyc_status st = POLYC_OK;
    for (uint32_t k = 0; k < on->kept_n && st == POLYC_OK; k++)
        st = accumulate(ctx, &ctx->scans[1 + k], on->kept_id[k], SCAN_RECOUNT);
    polyc__records_redo_begin(ctx, &on->rec, on->kept_n);
    return st;
}

/* Each moved scan out at its old pose and in at its new one. */
static polyc_status move_each(polyc_ctx *ctx)
{
    polyc__online *on = ctx->online;
    polyc_status st = POLYC_OK;
    for (uint32_t k = 0; k < on->kept_n && st == POLYC_OK; k++) {
        if (!is_moved(on, k))
            continue;
        polyc__scan *d = &ctx->scans[1 + k];
        st = accumulate(ctx, d, on->kept_id[k], SCAN_OUT);
        take_new_pose(ctx, k);
        if (st == POLYC_OK)
            st = accumulate(ctx, d, on->kept_id[k], SCAN_MOVED); /* (the prior has its lines) */
    }
    return st;
}

/* The contour of the moved scans (all: cleared, and every kept scan's).
 * Many scans are cast as the batch casts, on the tiles' marks (contour.c),
 * which pass over the tiles without an occupied cell in one move: for
 * intel's 910 scans 75 -> 35 ms. The marks cost a test per stored cell,
 * so a few scans are labelled one by one on the counts; the bits are the
 * same either way. */
static void relabel(polyc_ctx *ctx, int all)
{
    polyc__online *on = ctx->online;
    polyc__grid *g = &ctx->grid;
    const uint32_t *only = all ? NULL : on->moved;
    uint64_t beams = (uint64_t)(all ? on->kept_n : on->moved_n) * on->lim.max_scan_beams;
    if (beams * RELABEL_CELLS_PER_BEAM >= (uint64_t)g->tile_count * POLYC__TILE_CELLS &&
        polyc__contour_cast(ctx, &ctx->scans[1], on->kept_n, all, only))
        return;
    if (all)
        for (uint32_t t = 0; t < g->tile_count; t++)
            memset(g->tiles[t].contour, 0, sizeof g->tiles[t].contour);
    for (uint32_t k = 0; k < on->kept_n; k++)
        if (all || is_moved(on, k))
            label_contour(ctx, &ctx->scans[1 + k]);
}

/* The angle prior's counts and the accuracy's pairs cannot be taken out
 * one scan at a time (a pair's offset is not kept). When every scan is
 * kept, both are forgotten and learned again from all of them at their
 * poses now, and every tile joins the backlog: its points' weights change.
 * Without it the drifted scans' pairs stay, and the weights they give (a
 * band's, where the drift spread a wall) fit the corrected map loosely:
 * intel's drift experiment came out at 1.23 times the batch map's BIC on
 * the true poses' data. The learning waits for the next round or scan
 * (polyc__online_learn_due): nothing reads the two before, and the update
 * that applies the corrections does nothing else. */
void polyc__online_learn_due(polyc_ctx *ctx)
{
    polyc__online *on = ctx->online;
    if (!on->learn_due)
        return;
    on->learn_due = 0;
    polyc__prior_forget(&on->prior);
    polyc__accuracy_forget(&on->acc);
    for (uint32_t k = 0; k < on->kept_n; k++) {
        size_t mark = ctx->arena.used;
        polyc__online_scratch(&ctx->arena, on, 0, POLYC__STEP_LEARN);
        polyc__prior_learn_scan(ctx, &on->prior, &ctx->scans[1 + k], on->kept_id[k], on->learn_cache,
                                on->lim.max_scan_beams, &on->acc);
        ctx->arena.used = mark;
        on->learn_cache = NULL;
    }
}

polyc_status polyc__online_apply_corrections(polyc_ctx *ctx, uint64_t *beams_cast)
{
    polyc__online *on = ctx->online;
    if (beams_cast)
        *beams_cast = 0;
    if (on->moved_n == 0)
        return POLYC_OK;
    int all = on->kept_n == on->scans;
    float lx = on->last_x, ly = on->last_y;
    int afresh = all && 2u * on->moved_n >= on->kept_n;
    if (beams_cast) {
        uint64_t moved_beams = 0;
        for (uint32_t k = 0; k < on->kept_n; k++)
            if (is_moved(on, k))
                moved_beams += ctx->scans[1 + k].count;
        /* counted (afresh: every kept scan once; else each moved one out
         * and in), then their contour cast */
        *beams_cast = (afresh ? on->kept_beams : 2u * moved_beams) +
                      (all ? on->kept_beams : moved_beams);
    }
    if (!afresh) /* (a scan taken out takes its misses out of the records) */
        polyc__online_redo_records(ctx, UINT32_MAX);
    polyc_status st = afresh ? count_afresh(ctx) : move_each(ctx);
    on->last_x = lx; /* the robot is where the latest scan was */
    on->last_y = ly;
    relabel(ctx, all);
    memset(on->moved, 0, (on->lim.keep_scans / 32u + 1u) * sizeof *on->moved);
    on->moved_n = 0;
    if (all) {
        polyc__online_backlog_all(ctx);
        on->learn_due = 1;
    }
    return st;
}

uint64_t polyc_online_version(const polyc_ctx *ctx)
{
    return polyc__check_ctx(ctx) == POLYC_OK && ctx->online ? ctx->online->version : 0;
}
