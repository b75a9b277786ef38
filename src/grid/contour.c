/* contour.c - the contour (paper section III, second ray casting).
 * Takes: the hit/miss grid and the scans. Gives: the cells where a beam
 * first meets a cell with m > contour_threshold, or, for a reflection that
 * meets none, its end cell when the data fallback takes it (below); as bits
 * in the tiles and as a list (each beam labels at most one cell, so the
 * list is bounded). */
#include "../walk.h"

#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>

/* The list: each beam labels at most one cell (and an occupancy grid's
 * occupied cells, limits.max_beams of them, one each). */
int32_t *polyc__contour_list(polyc__arena *a, const polyc_limits *lim)
{
    return polyc__alloc(a, (size_t)lim->max_beams * 2 + 2, sizeof(int32_t));
}

/* while the beams are cast: a bit per directory entry */
static uint32_t *busy_bits(polyc__arena *a, size_t dir_n)
{
    return polyc__alloc_zero(a, dir_n / 32 + 1, sizeof(uint32_t));
}

void polyc__contour_reserve(polyc__arena *a, const polyc_limits *lim)
{
    polyc__contour_list(a, lim);
    size_t mark = a->used;
    busy_bits(a, polyc__grid_dir_cap(lim));
    a->used = mark;
}

size_t polyc__contour_bytes(const polyc_limits *lim)
{
    polyc__arena a;
    polyc__arena_counting(&a);
    polyc__contour_reserve(&a, lim);
    return a.peak;
}

/* Labels cell (ix, iy) once; 0 when the list is full. An online context
 * keeps no list (contour_xy NULL): the bits alone. */
static int label(polyc_ctx *ctx, int32_t ix, int32_t iy)
{
    polyc__tile *t = polyc__grid_tile(&ctx->grid, ix, iy);
    uint32_t bit = 1u << (ix & (POLYC__TILE_SIDE - 1));
    uint32_t *row = &t->contour[iy & (POLYC__TILE_SIDE - 1)];
    if (*row & bit)
        return 1;
    if (!ctx->contour_xy) {
        *row |= bit;
        return 1;
    }
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

/* The data fallback (ours). A reflection that met no occupied cell on its
 * way labels its end cell too when that cell holds data (m >= data_min_m,
 * points.c's rule) and no occupied cell lies within DATA_ALONE_RADII
 * search radii of it (a square). A wall seen only at grazing angles, or
 * through a band of pose error, has cells that the beams running along it
 * cross more often than they end in: none reaches the threshold, and its
 * returns are data that no contour cell explains. Such a wall, metres long
 * with a thousand returns yet free in the grid, was drawn only when the
 * search happened to lay a segment along it, so the map (and its BIC)
 * depended on the seed: the same log gave maps with and without the wall.
 * Within one search radius (15 cm at the defaults) the edges of wide bands
 * beside occupied cells were labelled too and traced as a second line
 * beside the wall's; two (30 cm) leave bands to their walls. The trace
 * drops short walks on such cells alone (trace.c). */
#define DATA_ALONE_RADII 2.0f

/* Whether an occupied cell lies in columns c0..c1 (within one tile) of row
 * r of tile t: from the tile's marks (`bits`, as the contour pass sets
 * them) or from its counts. */
static int occupied_in_row(const polyc_ctx *ctx, const polyc__tile *t, int r, int c0, int c1,
                           int bits)
{
    if (bits) {
        uint32_t below_c1 = c1 == POLYC__TILE_SIDE - 1 ? ~0u : (1u << (c1 + 1)) - 1u;
        uint32_t mask = below_c1 & ~((1u << c0) - 1u);
        return (t->mark[r] & mask) != 0;
    }
    for (int c = c0; c <= c1; c++)
        if (polyc__cell_occupied(t, (r << POLYC__TILE_SHIFT) | c, ctx->cfg.contour_threshold))
            return 1;
    return 0;
}

int polyc__contour_data_alone(const polyc_ctx *ctx, int32_t ix, int32_t iy, int bits)
{
    const polyc__grid *g = &ctx->grid;
    const polyc__tile *t = polyc__grid_tile(g, ix, iy);
    if (!t)
        return 0;
    if (!polyc__cell_holds_data(t, polyc__cell_index(ix, iy), ctx->cfg.data_min_m))
        return 0;
    int32_t r = (int32_t)ceilf(DATA_ALONE_RADII * ctx->cfg.search_radius_m / g->cell_m);
    int32_t x_lo = ix - r > 0 ? ix - r : 0, x_hi = ix + r < g->width - 1 ? ix + r : g->width - 1;
    int32_t y_lo = iy - r > 0 ? iy - r : 0, y_hi = iy + r < g->height - 1 ? iy + r : g->height - 1;
    for (int32_t y = y_lo; y <= y_hi; y++)
        for (int32_t x = x_lo; x <= x_hi; x = (x | (POLYC__TILE_SIDE - 1)) + 1) {
            /* the row's cells in one tile at a time (none where no tile
             * is stored: no beam ended in a hit there) */
            int32_t end = x | (POLYC__TILE_SIDE - 1);
            const polyc__tile *u = polyc__grid_tile(g, x, y);
            if (u && occupied_in_row(ctx, u, y & (POLYC__TILE_SIDE - 1), x & (POLYC__TILE_SIDE - 1),
                                     (end < x_hi ? end : x_hi) & (POLYC__TILE_SIDE - 1), bits))
                return 0;
        }
    return 1;
}

/* The end cell, visited last whatever the rounding: labelled when it is
 * occupied, or by the data fallback (a reflection: `hit`). */
static int end_cell(polyc_ctx *ctx, const polyc__walk *w, int hit)
{
    const polyc__tile *t = polyc__grid_tile(&ctx->grid, w->ex, w->ey);
    if (!t)
        return 1;
    if (occupied(t, polyc__cell_index(w->ex, w->ey)) ||
        (hit && polyc__contour_data_alone(ctx, w->ex, w->ey, 1)))
        return label(ctx, w->ex, w->ey);
    return 1;
}

/* The walk on the tiles' marks: from a tile without an occupied cell
 * (`busy`, a bit per directory entry, clear) to the next one with some in
 * one move (polyc__walk_skip_tiles), cell by cell in those. */
static int walk_tiles(polyc_ctx *ctx, const uint32_t *busy, polyc__walk *w, int hit)
{
    const polyc__grid *g = &ctx->grid;
    /* the walk has steps left and is in the grid, idx and counts set */
    for (;;) {
        size_t d = (size_t)(w->iy >> POLYC__TILE_SHIFT) * (size_t)g->tiles_x +
                   (size_t)(w->ix >> POLYC__TILE_SHIFT);
        if (!((busy[d >> 5] >> (d & 31)) & 1u)) {
            int to = polyc__walk_skip_tiles(w, g->width, g->height, g->tiles_x, busy);
            if (to < 0)
                return 1; /* out of the grid: unlabelled */
            if (to == 0)
                return end_cell(ctx, w, hit);
            polyc__walk_enter(w, g->width, g->height); /* (in the grid) */
        }
        const polyc__tile *t = polyc__grid_tile(g, w->ix, w->iy);
        /* the steps in this tile, in locals (the compiler cannot tell that
         * label's stores miss *w) */
        int64_t kx = w->kx, ky = w->ky, t_key = w->t_key;
        const int64_t inc_x = w->inc_x, inc_y = w->inc_y;
        int32_t ix = w->ix, iy = w->iy, idx = w->idx, lx = w->left_x, ly = w->left_y, n = w->n;
        const int32_t stx = w->stx, sty = w->sty, row = w->sty * POLYC__TILE_SIDE;
        int left = 0;
        while (!left && n > 0) {
            if (occupied(t, idx))
                return label(ctx, ix, iy);
            n--;
            if (kx < ky) {
                t_key = kx;
                kx += inc_x;
                ix += stx;
                idx += stx;
                left = --lx < 0;
            } else {
                t_key = ky;
                ky += inc_y;
                iy += sty;
                idx += row;
                left = --ly < 0;
            }
        }
        w->kx = kx;
        w->ky = ky;
        w->t_key = t_key;
        w->ix = ix;
        w->iy = iy;
        w->n = n;
        if (n == 0)
            return end_cell(ctx, w, hit);
        if (!polyc__walk_enter(w, g->width, g->height))
            return 1;
    }
}

/* Walks the beam to its first occupied cell and labels it; 0 when the list
 * is full. */
static int contour_beam(polyc_ctx *ctx, const uint32_t *busy, const polyc__beam *b)
{
    polyc__walk w;
    polyc__walk_start(&w, b);
    if (w.n == 0)
        return end_cell(ctx, &w, b->hit);
    if (!polyc__walk_enter(&w, ctx->grid.width, ctx->grid.height))
        return 1;
    return walk_tiles(ctx, busy, &w, b->hit);
}

/* The tiles' marks (m > threshold, once per cell), their contour bits
 * cleared if `clear`, and the busy bits: a directory entry's tile holds an
 * occupied cell. */
static void mark_occupied(polyc__grid *g, float threshold, int clear, uint32_t *busy)
{
    for (uint32_t k = 0; k < g->tile_count; k++) {
        polyc__tile *t = &g->tiles[k];
        if (clear)
            memset(t->contour, 0, sizeof t->contour);
        for (int r = 0; r < POLYC__TILE_SIDE; r++) {
            uint32_t bits = 0;
            for (int c = 0; c < POLYC__TILE_SIDE; c++)
                if (polyc__cell_occupied(t, (r << POLYC__TILE_SHIFT) | c, threshold))
                    bits |= 1u << c;
            t->mark[r] = bits;
        }
    }
    size_t dir_n = (size_t)g->tiles_x * (size_t)g->tiles_y;
    for (size_t d = 0; g->dir && d < dir_n; d++)
        if (g->dir[d] != 0) {
            const polyc__tile *t = &g->tiles[g->dir[d] - 1];
            uint32_t any = 0;
            for (int r = 0; r < POLYC__TILE_SIDE; r++)
                any |= t->mark[r];
            if (any)
                busy[d >> 5] |= 1u << (d & 31);
        }
}

size_t polyc__contour_cast_bytes(size_t dir_n)
{
    return polyc__bytes(dir_n / 32 + 1, sizeof(uint32_t));
}

/* Marks the grid and casts scans[0 .. n-1] (only those whose bit is set
 * in `only`, if given); the busy bits are scratch on the arena. Returns 1,
 * 0 when there is no room for them, -1 when the list is full. */
static int cast(polyc_ctx *ctx, const polyc__scan *scans, uint32_t n, int clear,
                const uint32_t *only)
{
    polyc__grid *g = &ctx->grid;
    size_t mark = ctx->arena.used;
    uint32_t *busy = busy_bits(&ctx->arena, (size_t)g->tiles_x * (size_t)g->tiles_y);
    if (!busy)
        return 0;
    mark_occupied(g, ctx->cfg.contour_threshold, clear, busy);
    int full = 0;
    for (uint32_t si = 0; si < n; si++) {
        if (only && !((only[si >> 5] >> (si & 31)) & 1u))
            continue;
        const polyc__scan *s = &scans[si];
        for (uint32_t i = 0; i < s->count; i++) {
            polyc__beam b;
            if (polyc__beam_path(ctx, s, i, &b) && !contour_beam(ctx, busy, &b))
                full = 1;
        }
    }
    ctx->arena.used = mark;
    return full ? -1 : 1;
}

int polyc__contour_cast(polyc_ctx *ctx, const polyc__scan *scans, uint32_t n, int clear,
                        const uint32_t *only)
{
    return cast(ctx, scans, n, clear, only) > 0;
}

polyc_status polyc__contour_build(polyc_ctx *ctx)
{
    ctx->contour_count = 0;
    ctx->contour_xy = polyc__contour_list(&ctx->arena, &ctx->lim);
    if (!ctx->contour_xy)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the contour");
    int r = cast(ctx, ctx->scans, ctx->scan_count, 1, NULL);
    if (r == 0)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the contour");
    POLYC_ASSERT(r > 0);
    ctx->stats.contour_cells = ctx->contour_count;
    return POLYC_OK;
}
