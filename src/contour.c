/* contour.c - the contour (paper section III, second ray casting).
 * Takes: the hit/miss grid and the scans. Gives: the cells where a beam
 * first meets a cell with m > contour_threshold, as bits in the tiles and as
 * a list (each beam labels at most one cell, so the list is bounded). */
#include "walk.h"

#include <string.h>

size_t polyc__contour_bytes(const polyc_limits *lim)
{
    /* each beam labels at most one cell */
    return polyc__bytes((size_t)lim->max_beams * 2 + 2, sizeof(int32_t));
}

static int occupied(const polyc__tile *t, int idx)
{
    return (t->mark[idx >> POLYC__TILE_SHIFT] >> (idx & (POLYC__TILE_SIDE - 1))) & 1u;
}

/* Labels cell (ix, iy) of tile t once; 0 when the list is full. */
static int label(polyc_ctx *ctx, polyc__tile *t, int32_t ix, int32_t iy)
{
    uint32_t bit = 1u << (ix & (POLYC__TILE_SIDE - 1));
    uint32_t *row = &t->contour[iy & (POLYC__TILE_SIDE - 1)];
    if (*row & bit)
        return 1;
    if (ctx->contour_count >= ctx->lim.max_beams)
        return 0;
    *row |= bit;
    ctx->contour_xy[2 * ctx->contour_count] = ix;
    ctx->contour_xy[2 * ctx->contour_count + 1] = iy;
    ctx->contour_count++;
    return 1;
}

/* Walks the beam to its first occupied cell and labels it; the walk stops
 * at the grid's edge. 0 when the list is full. */
static int contour_beam(polyc_ctx *ctx, const polyc__beam *b)
{
    polyc__grid *g = &ctx->grid;
    polyc__walk w;
    polyc__walk_start(&w, b);
    polyc__tile *t = NULL;
    if (w.n > 0 && (!polyc__walk_enter(&w, g->width, g->height) || !(t = polyc__grid_tile(g, w.ix, w.iy))))
        return 1;
    while (w.n > 0) {
        if (occupied(t, w.idx))
            return label(ctx, t, w.ix, w.iy);
        if (polyc__walk_step(&w) && w.n > 0 &&
            (!polyc__walk_enter(&w, g->width, g->height) || !(t = polyc__grid_tile(g, w.ix, w.iy))))
            return 1;
    }
    t = polyc__grid_tile(g, w.ex, w.ey);
    if (t && occupied(t, polyc__cell_index(w.ex, w.ey)))
        return label(ctx, t, w.ex, w.ey);
    return 1;
}

polyc_status polyc__contour_build(polyc_ctx *ctx)
{
    polyc__grid *g = &ctx->grid;
    ctx->contour_count = 0;
    ctx->contour_xy = polyc__alloc(&ctx->arena, (size_t)ctx->lim.max_beams * 2 + 2, sizeof(int32_t));
    if (!ctx->contour_xy)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the contour");
    /* m > threshold once per cell, as bits in the scratch marks: the walk
     * then tests a bit instead of two counters */
    float threshold = ctx->cfg.contour_threshold;
    for (uint32_t k = 0; k < g->tile_count; k++) {
        polyc__tile *t = &g->tiles[k];
        memset(t->contour, 0, sizeof t->contour);
        for (int r = 0; r < POLYC__TILE_SIDE; r++) {
            uint32_t bits = 0;
            for (int c = 0; c < POLYC__TILE_SIDE; c++)
                if (polyc__cell_occupied(t, (r << POLYC__TILE_SHIFT) | c, threshold))
                    bits |= 1u << c;
            t->mark[r] = bits;
        }
    }
    int full = 0;
    for (uint32_t si = 0; si < ctx->scan_count; si++) {
        const polyc__scan *s = &ctx->scans[si];
        for (uint32_t i = 0; i < s->count; i++) {
            polyc__beam b;
            if (polyc__beam_path(ctx, s, i, &b) && !contour_beam(ctx, &b))
                full = 1;
        }
    }
    POLYC_ASSERT(!full);
    ctx->stats.contour_cells = ctx->contour_count;
    return POLYC_OK;
}
