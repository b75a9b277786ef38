/* blocks.c - the weighted points' blocks of 2 x 2 grid cells (points.c's
 * and the online layer's): which blocks of a tile hold data, their numbers
 * in storage order, and each block's mean and central moments from its
 * sums. Takes: the grid's counters, the points' sums. Gives: the blocks'
 * numbering and the finished points. */
#include "../context.h"

#include <string.h>

static float block_centre(float origin, int32_t i, float cell)
{
    return (float)(origin + ((float)i + 0.5f * POLYC__BLOCK_SIDE) * (float)cell);
}

/* Marks the blocks of tile t that hold data, from the counters (the grid
 * counts a hit only in the end cell of a reflection, the cell endpoint_of
 * finds, so a cell with hits that passes the data rule holds an endpoint
 * that endpoint_of accepts, and only such cells do: the same marks as a
 * pass over the beams, without computing every endpoint once more). */
void polyc__block_mark_tile(const polyc_ctx *ctx, polyc__tile *t)
{
    const int32_t side = POLYC__TILE_SIDE, block = ~(int32_t)(POLYC__BLOCK_SIDE - 1);
    memset(t->mark, 0, sizeof t->mark);
    for (int32_t r = 0; r < side; r++) {
        /* most rows have no hit at all: one test for the row first */
        uint64_t any = 0, word;
        for (size_t at = 0; at < sizeof t->hits / POLYC__TILE_SIDE; at += sizeof word) {
            memcpy(&word, (const char *)(t->hits + r * side) + at, sizeof word);
            any |= word;
        }
        for (int32_t c = 0; any != 0 && c < side; c++)
            if (t->hits[r * side + c] != 0 &&
                polyc__cell_holds_data(t, r * side + c, ctx->cfg.data_min_m))
                t->mark[r & block] |= 1u << (c & block);
    }
}

/* Numbers tile t's marked blocks from n; returns the next number. */
uint32_t polyc__block_number_tile(polyc__tile *t, uint32_t n)
{
    t->mark_base = n;
    uint32_t in_tile = 0;
    for (int r = 0; r < POLYC__TILE_SIDE; r++) {
        t->mark_row[r] = (uint16_t)in_tile;
        uint32_t bits = t->mark[r];
        while (bits) {
            bits &= bits - 1;
            in_tile++;
        }
    }
    return n + in_tile;
}

/* Every tile's blocks marked and numbered in storage order; their count. */
static uint32_t mark_blocks(polyc_ctx *ctx)
{
    polyc__grid *g = &ctx->grid;
    uint32_t n = 0;
    for (uint32_t k = 0; k < g->tile_count; k++)
        polyc__block_mark_tile(ctx, &g->tiles[k]);
    for (uint32_t k = 0; k < g->tile_count; k++)
        n = polyc__block_number_tile(&g->tiles[k], n);
    return n;
}

/* Means and central moments from the sums of the points of the tile at
 * directory entry d, in the numbering order of its marks. */
void polyc__block_finish_tile(const polyc_ctx *ctx, int32_t d, polyc__point *tmp)
{
    const polyc__grid *g = &ctx->grid;
    float ox = g->frame_ox, oy = g->frame_oy;
    const polyc__tile *t = &g->tiles[g->dir[d] - 1];
    int32_t tx = (d % g->tiles_x) << POLYC__TILE_SHIFT, ty = (d / g->tiles_x) << POLYC__TILE_SHIFT;
    uint32_t k = t->mark_base;
    for (int r = 0; r < POLYC__TILE_SIDE; r++)
        for (int c = 0; t->mark[r] != 0 && c < POLYC__TILE_SIDE; c++) { /* most rows: none */
            if (!((t->mark[r] >> c) & 1u))
                continue;
            polyc__point *p = &tmp[k++];
            if (p->w <= 0.0f)
                continue; /* (a layer's: cells with hits but no sums) */
            float mx = p->x / p->w, my = p->y / p->w;
            p->cxx -= p->w * mx * mx;
            p->cxy -= p->w * mx * my;
            p->cyy -= p->w * my * my;
            if (p->cxx < 0.0f) p->cxx = 0.0f;
            if (p->cyy < 0.0f) p->cyy = 0.0f;
            p->x = block_centre(ox, tx + c, g->cell_m) + mx;
            p->y = block_centre(oy, ty + r, g->cell_m) + my;
        }
}

void polyc__blocks_finish(polyc_ctx *ctx, polyc__point *tmp)
{
    const polyc__grid *g = &ctx->grid;
    int32_t dir_n = g->tiles_x * g->tiles_y;
    for (int32_t d = 0; d < dir_n; d++)
        if (g->dir[d])
            polyc__block_finish_tile(ctx, d, tmp);
}

/* Every tile's blocks marked and numbered, and that many points (and
 * views, if any) zeroed; POLYC_ERR_NOMEM past cap. */
polyc_status polyc__blocks_begin(polyc_ctx *ctx, polyc__point *tmp, float *view, int32_t cap,
                                 uint32_t *n)
{
    *n = mark_blocks(ctx);
    if (*n > (uint32_t)cap)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "more weighted data points than limits.max_points");
    memset(tmp, 0, (size_t)*n * sizeof *tmp);
    if (view)
        memset(view, 0, (size_t)*n * 2 * sizeof *view);
    return POLYC_OK;
}

