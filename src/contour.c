/* contour.c - the contour (paper section III, second ray casting).
 * Takes: the hit/miss grid and the scans. Gives: the cells where a beam
 * first meets a cell with m > contour_threshold, as bits in the tiles and as
 * a list (each beam labels at most one cell, so the list is bounded). */
#include "internal.h"

#include <string.h>

typedef struct contour_pass {
    polyc_ctx *ctx;
    float threshold;
    int overflow;
} contour_pass;

static int contour_cell(void *u, int32_t ix, int32_t iy, float t_enter, int last)
{
    (void)t_enter;
    (void)last;
    contour_pass *p = u;
    polyc_ctx *ctx = p->ctx;
    polyc__tile *t = polyc__grid_tile(&ctx->grid, ix, iy);
    if (!t)
        return 1;
    int idx = polyc__cell_index(ix, iy);
    if (!polyc__cell_occupied(t, idx, p->threshold))
        return 0;
    uint32_t bit = 1u << (ix & 31);
    uint32_t *row = &t->contour[iy & 31];
    if (!(*row & bit)) {
        if (ctx->contour_count >= ctx->lim.max_beams) {
            p->overflow = 1;
            return 1;
        }
        *row |= bit;
        ctx->contour_xy[2 * ctx->contour_count] = ix;
        ctx->contour_xy[2 * ctx->contour_count + 1] = iy;
        ctx->contour_count++;
    }
    return 1;
}

size_t polyc__contour_bytes(const polyc_limits *lim)
{
    /* each beam labels at most one cell */
    return polyc__bytes((size_t)lim->max_beams * 2 + 2, sizeof(int32_t));
}

polyc_status polyc__contour_build(polyc_ctx *ctx)
{
    polyc__grid *g = &ctx->grid;
    ctx->contour_count = 0;
    ctx->contour_xy = polyc__alloc(&ctx->arena, (size_t)ctx->lim.max_beams * 2 + 2, sizeof(int32_t));
    if (!ctx->contour_xy)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the contour");
    for (uint32_t k = 0; k < g->tile_count; k++)
        memset(g->tiles[k].contour, 0, sizeof g->tiles[k].contour);
    contour_pass p = {ctx, ctx->cfg.contour_threshold, 0};
    for (uint32_t si = 0; si < ctx->scan_count; si++) {
        const polyc__scan *s = &ctx->scans[si];
        for (uint32_t i = 0; i < s->count; i++) {
            polyc__beam b;
            if (!polyc__beam_get(ctx, s, i, &b))
                continue;
            polyc__traverse(&b, contour_cell, &p);
        }
    }
    POLYC_ASSERT(!p.overflow);
    ctx->stats.contour_cells = ctx->contour_count;
    return POLYC_OK;
}
