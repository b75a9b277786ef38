/* contour.c - the contour (paper section III, second ray casting).
 * Takes: the hit/miss grid and the scans. Gives: the cells where a beam
 * first meets a cell with m > contour_threshold, as bits in the tiles and as
 * a list (each beam labels at most one cell, so the list is bounded). */
#include "walk.h"

#include <stddef.h>
#include <stdint.h>
#include <string.h>

size_t polyc__contour_bytes(const polyc_limits *lim)
{
    /* each beam labels at most one cell */
    return polyc__bytes((size_t)lim->max_beams * 2 + 2, sizeof(int32_t));
}

/* Labels cell (ix, iy) once; 0 when the list is full. */
static int label(polyc_ctx *ctx, int32_t ix, int32_t iy)
{
    polyc__tile *t = polyc__grid_tile(&ctx->grid, ix, iy);
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

static int occupied(const polyc__tile *t, int idx)
{
    return (t->mark[idx >> POLYC__TILE_SHIFT] >> (idx & (POLYC__TILE_SIDE - 1))) & 1u;
}

/* The end cell, visited last whatever the rounding. */
static int end_cell(polyc_ctx *ctx, const polyc__walk *w)
{
    const polyc__tile *t = polyc__grid_tile(&ctx->grid, w->ex, w->ey);
    return t && occupied(t, polyc__cell_index(w->ex, w->ey)) ? label(ctx, w->ex, w->ey) : 1;
}

/* Occupancy of the grid's whole box, one bit per cell, row after row, with a
 * border of set bits. A set bit stops the walk: an occupied cell, or the
 * edge of the grid, where it stops unlabelled. (Tiles the grid did not store
 * hold no hit, so no occupied cell.) */
typedef struct occ_map {
    uint32_t *bits;
    ptrdiff_t stride;              /* width + 2 */
} occ_map;

static int occ_bit(const occ_map *m, ptrdiff_t p)
{
    return (m->bits[p >> 5] >> (p & 31)) & 1u;
}

static void occ_set_bits(occ_map *m, ptrdiff_t p, uint32_t bits)
{
    uint32_t s = (uint32_t)(p & 31);
    m->bits[p >> 5] |= bits << s;
    if (s)
        m->bits[(p >> 5) + 1] |= bits >> (32 - s);
}

/* 0 when the bit positions do not fit a ptrdiff_t */
static size_t occ_words(const polyc__grid *g)
{
    ptrdiff_t w = (ptrdiff_t)g->width + 2, h = (ptrdiff_t)g->height + 2;
    if (h > (PTRDIFF_MAX - 64) / w)
        return 0;
    return (size_t)(w * h / 32 + 2);
}

static void occ_fill(occ_map *m, const polyc__grid *g)
{
    memset(m->bits, 0, occ_words(g) * sizeof(uint32_t));
    m->stride = (ptrdiff_t)g->width + 2;
    for (int32_t ty = 0; ty < g->tiles_y; ty++)
        for (int32_t tx = 0; tx < g->tiles_x; tx++) {
            int32_t x0 = tx << POLYC__TILE_SHIFT, y0 = ty << POLYC__TILE_SHIFT;
            const polyc__tile *t = polyc__grid_tile(g, x0, y0);
            int32_t cols = g->width - x0 < POLYC__TILE_SIDE ? g->width - x0 : POLYC__TILE_SIDE;
            uint32_t in_grid = cols == POLYC__TILE_SIDE ? ~0u : (1u << cols) - 1u;
            for (int32_t r = 0; t && r < POLYC__TILE_SIDE && y0 + r < g->height; r++)
                occ_set_bits(m, (ptrdiff_t)(y0 + r + 1) * m->stride + x0 + 1, t->mark[r] & in_grid);
        }
    for (ptrdiff_t x = 0; x < m->stride; x++) {
        occ_set_bits(m, x, 1u);
        occ_set_bits(m, ((ptrdiff_t)g->height + 1) * m->stride + x, 1u);
    }
    for (ptrdiff_t y = 1; y <= g->height; y++) {
        occ_set_bits(m, y * m->stride, 1u);
        occ_set_bits(m, y * m->stride + m->stride - 1, 1u);
    }
}

/* The walk on the map: one bit per cell, no tiles, no bounds. */
static int walk_map(polyc_ctx *ctx, const occ_map *m, polyc__walk *w)
{
    const polyc__grid *g = &ctx->grid;
    ptrdiff_t p = ((ptrdiff_t)w->iy + 1) * m->stride + w->ix + 1;
    const ptrdiff_t step_y = w->sty > 0 ? m->stride : -m->stride;
    /* (in locals: the compiler cannot tell that label's stores miss *w) */
    int64_t kx = w->kx, ky = w->ky;
    const int64_t inc_x = w->inc_x, inc_y = w->inc_y;
    const ptrdiff_t step_x = w->stx;
    for (int32_t n = w->n; n > 0; n--) {
        if (occ_bit(m, p)) {
            int32_t ix = (int32_t)(p % m->stride) - 1, iy = (int32_t)(p / m->stride) - 1;
            if (ix < 0 || iy < 0 || ix >= g->width || iy >= g->height)
                return 1;
            return label(ctx, ix, iy);
        }
        if (kx < ky) {
            kx += inc_x;
            p += step_x;
        } else {
            ky += inc_y;
            p += step_y;
        }
    }
    return end_cell(ctx, w);
}

/* No occupied cell in the tile (or no tile stored there). */
static int tile_empty(const polyc__tile *t)
{
    uint32_t any = 0;
    for (int r = 0; t && r < POLYC__TILE_SIDE; r++)
        any |= t->mark[r];
    return any == 0;
}

/* The walk on the tiles' marks, when there is no room for the map; a tile
 * without an occupied cell is left in one move. */
static int walk_tiles(polyc_ctx *ctx, polyc__walk *w)
{
    const polyc__grid *g = &ctx->grid;
    const polyc__tile *t = polyc__grid_tile(g, w->ix, w->iy);
    int empty = tile_empty(t);
    while (w->n > 0) {
        int left;
        if (empty) {
            left = polyc__walk_leave_tile(w);
            while (!left && w->n > 0)
                left = polyc__walk_step(w);
        } else {
            if (occupied(t, w->idx))
                return label(ctx, w->ix, w->iy);
            left = polyc__walk_step(w);
        }
        if (left && w->n > 0) {
            if (!polyc__walk_enter(w, g->width, g->height))
                return 1;
            t = polyc__grid_tile(g, w->ix, w->iy);
            empty = tile_empty(t);
        }
    }
    return end_cell(ctx, w);
}

/* Walks the beam to its first occupied cell and labels it; 0 when the list
 * is full. */
static int contour_beam(polyc_ctx *ctx, const occ_map *m, const polyc__beam *b)
{
    polyc__walk w;
    polyc__walk_start(&w, b);
    if (w.n == 0)
        return end_cell(ctx, &w);
    if (!polyc__walk_enter(&w, ctx->grid.width, ctx->grid.height))
        return 1;
    return m ? walk_map(ctx, m, &w) : walk_tiles(ctx, &w);
}

polyc_status polyc__contour_build(polyc_ctx *ctx)
{
    polyc__grid *g = &ctx->grid;
    ctx->contour_count = 0;
    ctx->contour_xy = polyc__alloc(&ctx->arena, (size_t)ctx->lim.max_beams * 2 + 2,
                                   sizeof(int32_t));
    if (!ctx->contour_xy)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the contour");
    /* m > threshold once per cell, as bits in the scratch marks */
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
    /* The map of the whole box is scratch in memory budgeted for the later
     * stages, so it is there unless the limits are tight; it saves the walk
     * the tile bookkeeping, which costs about as much as the walk itself. */
    size_t mark = ctx->arena.used;
    occ_map map = {NULL, 0};
    size_t words = occ_words(g);
    if (g->tile_count > 0 && words > 0)
        map.bits = polyc__alloc(&ctx->arena, words, sizeof(uint32_t));
    if (map.bits)
        occ_fill(&map, g);
    int full = 0;
    for (uint32_t si = 0; si < ctx->scan_count; si++) {
        const polyc__scan *s = &ctx->scans[si];
        for (uint32_t i = 0; i < s->count; i++) {
            polyc__beam b;
            if (polyc__beam_path(ctx, s, i, &b) && !contour_beam(ctx, map.bits ? &map : NULL, &b))
                full = 1;
        }
    }
    ctx->arena.used = mark;
    POLYC_ASSERT(!full);
    (void)full;
    ctx->stats.contour_cells = ctx->contour_count;
    return POLYC_OK;
}
