/* online_points.c - the weighted points of an online context, made from
 * the cells' sums (the scans are not kept): a tile's blocks' sums, and
 * every stored tile's points for the layer's collect (polyc__layer, read
 * by points.c). Takes: the cell table and the grid. Gives: unsorted
 * points. */
#include "../online.h"

#include <string.h>

/* The sums of the cells of the tile at directory entry d (the scans are
 * not kept) into its marked blocks' points. A cell's offsets
 * move to its block's centre by (dx, dy): the sums of products gain the
 * cross terms. Returns the endpoints taken. */
float polyc__online_sum_tile(const polyc_ctx *ctx, int32_t d, polyc__point *tmp, float *view)
{
    const polyc__online *on = ctx->online;
    const polyc__grid *g = &ctx->grid;
    const float half = 0.5f * (float)(POLYC__BLOCK_SIDE - 1);
    uint32_t k = g->dir[d] - 1;
    const polyc__tile *t = &g->tiles[k];
    float raw = 0.0f;
    for (int idx = 0; idx < POLYC__TILE_CELLS; idx++) {
        if (!t->hits[idx] || !polyc__cell_holds_data(t, idx, ctx->cfg.data_min_m))
            continue;
        uint32_t e = polyc__cell_find(&on->tab, polyc__cell_key(k, idx));
        if (!e)
            continue;
        const polyc__cell_sums *c = &on->tab.sums[e - 1];
        int32_t ix = idx & (POLYC__TILE_SIDE - 1), iy = idx >> POLYC__TILE_SHIFT;
        int32_t bx = ix & ~(int32_t)(POLYC__BLOCK_SIDE - 1), by = iy & ~(int32_t)(POLYC__BLOCK_SIDE - 1);
        float dx = ((float)(ix - bx) - half) * g->cell_m, dy = ((float)(iy - by) - half) * g->cell_m;
        float w = (float)c->n;
        uint32_t at = polyc__block_number(t, bx, by);
        polyc__point *p = &tmp[at];
        view[2 * at] += c->vx;
        view[2 * at + 1] += c->vy;
        p->w += w;
        p->x += c->fx + w * dx;
        p->y += c->fy + w * dy;
        p->cxx += c->fxx + 2.0f * dx * c->fx + w * dx * dx;
        p->cxy += c->fxy + dx * c->fy + dy * c->fx + w * dx * dy;
        p->cyy += c->fyy + 2.0f * dy * c->fy + w * dy * dy;
        raw += (float)w;
    }
    return raw;
}

/* Online, a block whose cells hold hits but no sums (limits.max_points ran
 * out as they came) has no point: the others move up. */
uint32_t polyc__online_drop_empty(polyc__point *pts, float *view, uint32_t *tile, uint32_t n)
{
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; i++) {
        if (pts[i].w <= 0.0f)
            continue;
        pts[m] = pts[i];
        view[2 * m] = view[2 * i];
        view[2 * m + 1] = view[2 * i + 1];
        tile[m++] = tile[i];
    }
    return m;
}

/* The layer's collect (polyc__layer, for polyc__opt_refresh): every
 * stored tile's points from its cells' sums, into the update's scratch
 * (polyc__online_points_scratch); the sort by bucket carries each point's
 * tile (its directory entry) into pt_tile. */
polyc_status polyc__online_collect(polyc__opt *o, int32_t cap, polyc__points_in *in, int32_t *n_out)
{
    polyc_ctx *ctx = o->ctx;
    polyc__online *on = ctx->online;
    in->pts = on->scr.pts_tmp;
    in->view = on->scr.view_tmp;
    in->tag = on->scr.fresh_tile;
    in->tag_out = on->pt_tile;
    uint32_t n;
    polyc_status st = polyc__blocks_begin(ctx, in->pts, in->view, cap, &n);
    if (st != POLYC_OK)
        return st;
    const polyc__grid *g = &ctx->grid;
    for (int32_t d = 0; d < g->tiles_x * g->tiles_y; d++) {
        if (!g->dir[d])
            continue;
        /* tile k's points are numbered up to tile k + 1's first */
        uint32_t k = g->dir[d] - 1;
        uint32_t end = k + 1 < g->tile_count ? g->tiles[k + 1].mark_base : n;
        for (uint32_t i = g->tiles[k].mark_base; i < end; i++)
            on->scr.fresh_tile[i] = (uint32_t)d;
        on->backlog.tile_raw[k] = polyc__online_sum_tile(ctx, d, in->pts, in->view);
    }
    polyc__blocks_finish(ctx, in->pts);
    *n_out = (int32_t)polyc__online_drop_empty(in->pts, in->view, on->scr.fresh_tile, n);
    return POLYC_OK;
}

