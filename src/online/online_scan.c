/* online_scan.c - one scan into an online context (or out again, for a
 * pose correction): its beams into the grid's counts, its endpoints into
 * their cells' sums, its first occupied cells into the contour, its lines
 * into the angle prior and the accuracy, its pose into the tiles that held
 * one (and the spacing table made from them), and the tiles it changed
 * into the backlog. Takes: a scan. Gives: the state online_round.c
 * re-optimises the map from. */
#include "../online.h"
#include "../walk.h"

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
 * finishing call, and the map between updates lacked walls that a batch
 * map of the same scans has (its BIC on the batch's data far above the
 * batch map's, tools/eval/fairbic.h; level with it with this rule). */
#define SPARSE_MIN 4u

/* Endpoints and poses must stay this far inside the area: vertices may
 * wander a little past the data (the spatial hash's own margin is 2 m). */
#define AREA_MARGIN_M 1.0f

/* The layer's spacing table (polyc__layer): from the tiles where some pose
 * was (the poses are not kept);
 * made again when a pose fell in a new tile, at most once in this many
 * scans (a pass over the area's tiles: on a large square, made at every
 * new pose tile, it took a large share of the updates' time): meanwhile a
 * new tile's spacing is measured from the poses before it. */
#define REMAKE_SCANS 32u

polyc_status polyc__online_spacing(polyc_ctx *ctx, polyc__spacing *sp, size_t n)
{
    polyc__online *on = ctx->online;
    sp->min_step_rad = on->poses.min_step_rad;
    sp->dist = on->poses.spacing_dist;
    if (!on->poses.spacing_stale || (!on->poses.spacing_now && on->poses.spacing_scans != 0 &&
                               on->scans - on->poses.spacing_scans < REMAKE_SCANS))
        return POLYC_OK;
    for (size_t i = 0; i < n; i++)
        sp->dist[i] = (on->poses.pose_bits[i >> 5] >> (i & 31)) & 1u ? 0.0f : 1e30f;
    polyc__spacing_chamfer(sp);
    on->poses.spacing_stale = 0;
    on->poses.spacing_scans = on->scans;
    return POLYC_OK;
}

static void mark_dirty(polyc__online *on, size_t d)
{
    if (on->backlog.dirty_since[d] == 0) {
        on->backlog.dirty_since[d] = on->scans + 1;
        on->backlog.dirty[on->backlog.dirty_n++] = (uint32_t)d;
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
        if (on->backlog.tile_miss[k] >= CHANGE_MIN && (float)on->backlog.tile_miss[k] >= on->backlog.tile_raw[k])
            mark_dirty(on, d);
        else if (on->backlog.tile_new[k] >= SPARSE_MIN && on->backlog.tile_new[k] >= on->backlog.tile_raw[k])
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
    uint32_t e = polyc__cell_find(&on->tab, polyc__cell_key(g->dir[d] - 1, polyc__cell_index(ix, iy)));
    if (e == 0)
        return;
    *vx = on->tab.sums[e - 1].vx;
    *vy = on->tab.sums[e - 1].vy;
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
        if (++on->backlog.tile_new[k] >= CHANGE_MIN && (float)on->backlog.tile_new[k] >= CHANGE_SHARE * on->backlog.tile_raw[k])
            mark_dirty(on, (size_t)d);
        uint32_t key = polyc__cell_key(k, polyc__cell_index(ix, iy));
        uint32_t e = sign < 0.0f ? polyc__cell_find(&on->tab, key) : polyc__cell_add(&on->tab, key);
        if (e == 0) { /* the entries are used up (or a cell without sums taken back) */
            if (sign > 0.0f)
                ok = 0;
            continue;
        }
        polyc__cell_sums *c = &on->tab.sums[e - 1];
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
            polyc__cell_drop(&on->tab, e);
    }
    return ok;
}

/* Labels the first occupied cell along each beam as contour, or a
 * reflection's end cell by the data fallback (contour.c), on the grid as it
 * stands with this scan counted (the batch casts once more on the final
 * grid). */
void polyc__online_label_contour(polyc_ctx *ctx, const polyc__scan *s)
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


/* The scan's beams into the grid and its endpoints into the sums; a new
 * scan's first occupied cells into the contour and its lines into the
 * prior. POLYC__SCAN_OUT takes its counts and sums out again (the prior and the
 * contour keep what it gave: see docs/algorithm.md, "Online"). A corrected
 * scan's contour is cast once every waiting correction is in the grid
 * (polyc__online_apply_corrections). */
polyc_status polyc__online_accumulate(polyc_ctx *ctx, const polyc__scan *s, uint32_t number, int how)
{
    polyc__online *on = ctx->online;
    const polyc__grid *g = &ctx->grid;
    int take_back = how == POLYC__SCAN_OUT;
    polyc_status st = how == POLYC__SCAN_RECOUNT ? polyc__grid_recount_scan(ctx, s)
                                          : polyc__grid_add_scan(ctx, s, take_back, on->backlog.tile_miss);
    int sums_ok = sum_endpoints(ctx, s, take_back ? -1.0f : 1.0f);
    if (take_back)
        return st;
    /* A new scan whose endpoints outgrow the data cells, or the weighted
     * points an update collects from them (their 2 x 2 blocks), goes out
     * again: an update after an accepted add can always run (with blocks
     * of one or two cells on average, limits.max_points / 2 points filled
     * long before the cells did, and every update and the finish failed) */
    if (how == POLYC__SCAN_NEW && st == POLYC_OK &&
        (!sums_ok || on->tab.blocks_n > (uint32_t)polyc__points_bound(&ctx->cfg, &ctx->lim))) {
        polyc__grid_add_scan(ctx, s, 1, on->backlog.tile_miss);
        sum_endpoints(ctx, s, -1.0f);
        on->refused = 1;
        return polyc__fail(ctx, POLYC_ERR_NOMEM,
                           "no room for the scan's endpoints (limits.max_points): not added");
    }
    if (how == POLYC__SCAN_NEW) {
        polyc__online_label_contour(ctx, s);
        /* (the block is sized for it; without it, NULL: the same lines,
         * the endpoints computed twice) */
        size_t mark = ctx->arena.used;
        polyc__online_scratch(&ctx->arena, on, 0, POLYC__STEP_LEARN);
        polyc__prior_learn_scan(ctx, &on->prior, s, number, on->scr.learn_cache, on->lim.max_scan_beams,
                                &on->acc);
        ctx->arena.used = mark;
        on->scr.learn_cache = NULL;
    }
    int64_t d = tile_of(g, (int32_t)floorf((s->x_m - g->frame_ox) * g->inv_cell),
                        (int32_t)floorf((s->y_m - g->frame_oy) * g->inv_cell));
    if (d >= 0 && !((on->poses.pose_bits[d >> 5] >> (d & 31)) & 1u)) {
        on->poses.pose_bits[d >> 5] |= 1u << (d & 31);
        on->poses.spacing_stale = 1;
    }
    if (s->count > 1 && (on->poses.min_step_rad == 0.0f || fabsf(s->step_rad) < on->poses.min_step_rad))
        on->poses.min_step_rad = fabsf(s->step_rad);
    on->poses.last_x = s->x_m;
    on->poses.last_y = s->y_m;
    if (st == POLYC_OK && !sums_ok)
        st = polyc__fail(ctx, POLYC_ERR_NOMEM, "more cells with endpoints than limits.max_points");
    return st;
}

polyc_status polyc__online_inside_area(polyc_ctx *ctx, const polyc_scan *s)
{
    if (polyc__frame_inside(ctx, s, 0.5f * polyc__narrow(ctx->online->lim.area_m) - AREA_MARGIN_M))
        return POLYC_OK;
    return polyc__fail(ctx, POLYC_ERR_EXTENT, "the scan reaches outside limits.area_m around the first pose");
}

polyc_status polyc__online_enter(polyc_ctx *ctx, int args_ok)
{
    polyc_status st = polyc__enter(ctx, args_ok);
    if (st == POLYC_OK && !ctx->online)
        st = polyc__fail(ctx, POLYC_ERR_STATE, "not an online context (polyc_online_init)");
    return st;
}

polyc_status polyc_online_add_scan(polyc_ctx *ctx, const polyc_scan *s, int keep, uint32_t *scan_id)
{
    polyc_status cst = polyc__online_enter(ctx, s != NULL);
    if (cst != POLYC_OK)
        return cst;
    polyc__online *on = ctx->online;
    if ((cst = polyc__scan_check(ctx, s, on->scans)) != POLYC_OK)
        return cst;
    if (s->beam_count > on->lim.max_scan_beams)
        return polyc__fail(ctx, POLYC_ERR_LIMIT, "a scan with more beams than limits.max_scan_beams");
    if (keep && (on->kept.n >= on->lim.keep_scans || s->beam_count > on->lim.keep_beams - on->kept.beams))
        return polyc__fail(ctx, POLYC_ERR_LIMIT, "no room to keep the scan (limits.keep_scans, keep_beams)");
    if (on->kept.moved_n > 0) { /* the waiting corrections go in first */
        polyc_status cst2 = polyc__online_apply_corrections(ctx, NULL);
        if (cst2 != POLYC_OK)
            return cst2;
    }
    polyc__online_learn_due(ctx); /* (before this scan's lines join the prior) */
    if (!ctx->have_frame) { /* the grid was laid out around (0, 0) */
        polyc__frame_set(ctx, s->pose_x_m, s->pose_y_m);
        polyc__frame_grid_origin(ctx, &ctx->grid, ctx->grid.frame_ox, ctx->grid.frame_oy);
    }
    if ((cst = polyc__online_inside_area(ctx, s)) != POLYC_OK)
        return cst;
    /* the current scan is slot 0; a kept one has its own slot and ranges */
    polyc__scan *d = &ctx->scans[0];
    uint32_t first = 0;
    if (keep) {
        d = &ctx->scans[1 + on->kept.n];
        first = on->lim.max_scan_beams + on->kept.beams;
    }
    polyc__take_scan(ctx, d, s, first);
    on->refused = 0;
    polyc_status st = polyc__online_accumulate(ctx, d, on->scans, POLYC__SCAN_NEW);
    if (on->refused)
        return st; /* (nothing of it stays: not counted, not kept) */
    polyc__tally_beams(ctx, s);
    if (keep) {
        on->kept.id[on->kept.n++] = on->scans;
        on->kept.beams += s->beam_count;
    }
    if (scan_id)
        *scan_id = on->scans;
    on->scans++;
    on->pending++;
    ctx->stats.scans = on->scans;
    return st;
}

