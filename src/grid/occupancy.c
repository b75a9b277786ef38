/* occupancy.c - an occupancy grid as the map's evidence (nav_msgs/OccupancyGrid).
 * Takes: the caller's int8 cells, the thresholds and the origin pose. Gives the
 * grid and contour stages at once, in the grid's own frame (cell (i, j) centred
 * at ((i + 0.5) r, (j + 0.5) r)): occupied cells count a hit and free ones a
 * miss in the tiles that hold an occupied cell or a cell near one,
 * and the contour is every occupied cell that faces free space (faces_free;
 * docs/algorithm.md, "From an occupancy grid"). The caller's cells
 * are read during the call only. */
#include "../context.h"

#include <math.h>
#include <string.h>

enum { CELL_UNKNOWN = 0, CELL_FREE = 1, CELL_OCCUPIED = 2, CELL_BAD = 3 };

/* The class of every int8 value under the thresholds, indexed by value + 128. */
static void classes(const polyc_config *cfg, uint8_t *cls)
{
    float occ = 100.0f * (float)cfg->occupied_thresh, fre = 100.0f * (float)cfg->free_thresh;
    for (int v = -128; v < 128; v++) {
        uint8_t c = CELL_BAD;
        if (v == -1)
            c = CELL_UNKNOWN;
        else if (v >= 0 && v <= 100)
            c = (float)v >= occ ? CELL_OCCUPIED : ((float)v <= fre ? CELL_FREE : CELL_UNKNOWN);
        cls[v + 128] = c;
    }
}

static uint8_t class_of(const uint8_t *cls, int8_t v)
{
    return cls[(int)v + 128];
}

/* The grid's fields (not its values); its tile counts. */
static polyc_status check_grid(const polyc_config *cfg, const polyc_occupancy_grid *grid,
                               const char **why, uint32_t *tiles_x, uint32_t *tiles_y)
{
    const char *w = NULL;
    polyc_status st = POLYC_ERR_CONFIG;
    float r = grid->resolution_m;
    if (!grid->cells) {
        w = "grid.cells is NULL";
        st = POLYC_ERR_NULL;
    } else if (grid->width == 0 || grid->height == 0) {
        w = "grid width and height must be at least 1";
    } else if (!(r >= 1e-4f && r <= 100.0f)) { /* false for NaN */
        w = "grid resolution_m must be in [0.0001, 100]";
    } else if (grid->reserved != 0) {
        w = "grid.reserved must be 0";
    } else if (!polyc__grid_origin_ok(grid)) {
        w = "grid origin is not finite or beyond 1e7 m";
    } else if ((float)grid->width * (float)r > (float)cfg->max_extent_m ||
               (float)grid->height * (float)r > (float)cfg->max_extent_m) {
        w = "the grid spans more than config.max_extent_m";
        st = POLYC_ERR_EXTENT;
    } else {
        uint64_t tx = ((uint64_t)grid->width + POLYC__TILE_SIDE - 1) / POLYC__TILE_SIDE;
        uint64_t ty = ((uint64_t)grid->height + POLYC__TILE_SIDE - 1) / POLYC__TILE_SIDE;
        if (tx * ty * POLYC__TILE_CELLS > 0xffffffffu || grid->width > 0x7fffffe0u ||
            grid->height > 0x7fffffe0u) {
            w = "grid too large for 32-bit cell counts";
            st = POLYC_ERR_EXTENT;
        } else {
            *tiles_x = (uint32_t)tx;
            *tiles_y = (uint32_t)ty;
            st = POLYC_OK;
        }
    }
    *why = w;
    return st;
}

/* Occupied cells, or CELL_BAD's message for a value outside -1..100. */
static polyc_status count_occupied(const uint8_t *cls, const polyc_occupancy_grid *grid,
                                   uint64_t *occupied, const char **why)
{
    uint64_t n = 0, cells = (uint64_t)grid->width * grid->height;
    for (uint64_t k = 0; k < cells; k++) {
        uint8_t c = class_of(cls, grid->cells[k]);
        if (c == CELL_BAD) {
            *why = "grid cell value outside -1..100";
            return POLYC_ERR_CONFIG;
        }
        n += c == CELL_OCCUPIED;
    }
    *occupied = n;
    return POLYC_OK;
}

static uint8_t class_at(const uint8_t *cls, const polyc_occupancy_grid *grid, int64_t ix, int64_t iy);

/* Tiles of 32 x 32 cells that hold a stored cell: an occupied cell in the
 * tile's cross widened by POLYC__FACE_CELLS along rows and along columns. */
static uint64_t occupied_tiles(const uint8_t *cls, const polyc_occupancy_grid *grid)
{
    const int64_t K = POLYC__FACE_CELLS, S = POLYC__TILE_SIDE;
    uint64_t n = 0;
    for (int64_t ty = 0; ty < (int64_t)grid->height; ty += S)
        for (int64_t tx = 0; tx < (int64_t)grid->width; tx += S) {
            int any = 0;
            for (int64_t j = ty; !any && j < ty + S; j++)
                for (int64_t i = tx - K; !any && i < tx + S + K; i++)
                    any = class_at(cls, grid, i, j) == CELL_OCCUPIED;
            for (int64_t j = ty - K; !any && j < ty + S + K; j++)
                for (int64_t i = tx; !any && i < tx + S; i++)
                    any = class_at(cls, grid, i, j) == CELL_OCCUPIED;
            n += (uint64_t)any;
        }
    return n;
}

polyc_status polyc_limits_for_grid(const polyc_config *config, const polyc_occupancy_grid *grid,
                                   polyc_limits *out)
{
    if (!config || !grid || !out)
        return POLYC_ERR_NULL;
    if (polyc_config_check(config, NULL) != POLYC_OK)
        return POLYC_ERR_CONFIG;
    const char *why;
    uint32_t tx, ty;
    polyc_status st = check_grid(config, grid, &why, &tx, &ty);
    if (st != POLYC_OK)
        return st;
    uint8_t cls[256];
    classes(config, cls);
    uint64_t occupied;
    if ((st = count_occupied(cls, grid, &occupied, &why)) != POLYC_OK)
        return st;
    if (occupied > 0xffffffffu - 1024u)
        return POLYC_ERR_LIMIT;
    memset(out, 0, sizeof *out);
    /* an occupied cell plays the part of a beam's endpoint: it is one data
     * point and at most one contour cell; the contour's vertices and the
     * optimiser's additions are bounded as for beams */
    out->max_scans = 0;
    out->max_beams = (uint32_t)occupied;
    /* only the tiles holding an occupied cell are stored; the directory of
     * all tiles must fit the budget too (polyc__grid_dir_cap: 4 entries a
     * tile and 64) */
    uint64_t tiles = occupied_tiles(cls, grid), dir_n = (uint64_t)tx * ty;
    if (tiles * 4 + 64 < dir_n)
        tiles = (dir_n - 64 + 3) / 4;
    out->max_grid_cells = (uint32_t)(tiles * POLYC__TILE_CELLS);
    out->max_vertices = (uint32_t)occupied + POLYC__VERTEX_SPARE;
    out->max_points = (uint32_t)occupied;
    return POLYC_OK;
}

/* The tile of cell (ix, iy), allocated on first use (tiles stay contiguous:
 * nothing else allocates meanwhile); NULL when the budget is spent. */
static polyc__tile *tile_for(polyc_ctx *ctx, int32_t ix, int32_t iy)
{
    polyc__grid *g = &ctx->grid;
    size_t d = (size_t)(iy >> POLYC__TILE_SHIFT) * (size_t)g->tiles_x + (size_t)(ix >> POLYC__TILE_SHIFT);
    if (g->dir[d] == 0) {
        if (g->tile_count >= g->tile_cap)
            return NULL;
        polyc__tile *t = polyc__alloc_zero(&ctx->arena, 1, sizeof(polyc__tile));
        if (!t || t != g->tiles + g->tile_count)
            return NULL;
        g->dir[d] = ++g->tile_count;
    }
    return &g->tiles[g->dir[d] - 1];
}

/* The class of cell (ix, iy), unknown outside the grid. */
static uint8_t class_at(const uint8_t *cls, const polyc_occupancy_grid *grid, int64_t ix, int64_t iy)
{
    if (ix < 0 || iy < 0 || ix >= (int64_t)grid->width || iy >= (int64_t)grid->height)
        return CELL_UNKNOWN;
    return class_of(cls, grid->cells[(size_t)iy * grid->width + (size_t)ix]);
}

/* Contour: along a row or a column, not across a corner. A beam from free
 * space enters a cell through a side; with the 4-neighbourhood the contour
 * of a solid region is one 8-connected cell wide, the chains the trace walks
 * (the 8-neighbourhood adds the cells that touch free space only at a
 * corner, and the thinning then takes them out again). */
/* Contour: an occupied cell that faces free space along a row or a column:
 * a free cell at most POLYC__FACE_CELLS away, only unknown cells between. A
 * log's hit/miss grid leaves the cells just in front of a wall between the
 * thresholds (the beams that graze it count few misses there: in a log's
 * grid of 5 cm cells most occupied cells touch no free cell), and walls
 * seen through a door have such cells for several cells in front of
 * them. Tried on the grid of examples/office.log read back as a ROS map
 * (`polyc map.yaml`), against the log's own map: with 2 or 3 cells a part
 * of its walls had no line within 10 cm, with 4 nearly none. Occupied
 * cells that face only unknown cells or other occupied ones are inside or
 * behind a wall, not its surface (the grid's data points are these cells
 * too: points.c). */
static int faces_free(const uint8_t *cls, const polyc_occupancy_grid *grid, int32_t ix, int32_t iy)
{
    static const int8_t side[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    for (int e = 0; e < 4; e++)
        for (int k = 1; k <= POLYC__FACE_CELLS; k++) {
            uint8_t a = class_at(cls, grid, ix + k * side[e][0], iy + k * side[e][1]);
            if (a == CELL_FREE)
                return 1;
            if (a != CELL_UNKNOWN)
                break;
        }
    return 0;
}

static polyc_status fill(polyc_ctx *ctx, const polyc_occupancy_grid *grid, const uint8_t *cls,
                         uint32_t tiles_x, uint32_t tiles_y)
{
    polyc__grid *g = &ctx->grid;
    g->cell_m = grid->resolution_m;
    g->inv_cell = 1.0f / grid->resolution_m;
    g->width = (int32_t)grid->width;
    g->height = (int32_t)grid->height;
    g->tiles_x = (int32_t)tiles_x;
    g->tiles_y = (int32_t)tiles_y;
    /* the directory and the tile budget as grid.c sizes them */
    size_t budget = polyc__grid_budget_bytes(&ctx->lim);
    size_t dir_n = (size_t)tiles_x * (size_t)tiles_y;
    size_t dir_bytes = polyc__bytes(dir_n, sizeof(uint32_t));
    size_t fixed = polyc__add(dir_bytes, polyc__bytes(1, sizeof(polyc__tile)));
    if (dir_bytes == 0 || fixed >= budget)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "grid extent too large for limits.max_grid_cells");
    g->dir = polyc__alloc_zero(&ctx->arena, dir_n, sizeof(uint32_t));
    if (!g->dir)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the grid directory");
    g->tile_cap = (uint32_t)((budget - fixed) / sizeof(polyc__tile));
    g->tiles = (polyc__tile *)(ctx->arena.base + ctx->arena.used);
    /* the stored tiles: those of every cell within POLYC__FACE_CELLS of an
     * occupied one along a row or a column (their classes tell which
     * occupied cells face free space: points.c), which are the tiles of the
     * two ends of each such run (it is shorter than a tile); a hit in each
     * occupied cell */
    const int8_t *c = grid->cells;
    const int32_t K = POLYC__FACE_CELLS;
    for (int32_t iy = 0; iy < g->height; iy++)
        for (int32_t ix = 0; ix < g->width; ix++, c++) {
            if (class_of(cls, *c) != CELL_OCCUPIED)
                continue;
            const int32_t at[4][2] = {{ix - K < 0 ? 0 : ix - K, iy},
                                      {ix + K >= g->width ? g->width - 1 : ix + K, iy},
                                      {ix, iy - K < 0 ? 0 : iy - K},
                                      {ix, iy + K >= g->height ? g->height - 1 : iy + K}};
            for (int e = 0; e < 4; e++)
                if (!tile_for(ctx, at[e][0], at[e][1]))
                    return polyc__fail(ctx, POLYC_ERR_NOMEM,
                                       "grid needs more cells than limits.max_grid_cells");
            polyc__tile *t = tile_for(ctx, ix, iy);
            if (!t)
                return polyc__fail(ctx, POLYC_ERR_NOMEM,
                                   "grid needs more cells than limits.max_grid_cells");
            t->hits[polyc__cell_index(ix, iy)] = 1;
        }
    /* the contour list after the tiles: each occupied cell labels itself at
     * most once, so limits.max_beams (the occupied cells) bounds it */
    ctx->contour_count = 0;
    ctx->contour_xy = polyc__contour_list(&ctx->arena, &ctx->lim);
    if (!ctx->contour_xy)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the contour");
    /* a miss in each free cell of a stored tile (polyc_grid_cell reads it);
     * the contour */
    c = grid->cells;
    for (int32_t iy = 0; iy < g->height; iy++)
        for (int32_t ix = 0; ix < g->width; ix++, c++) {
            uint8_t k = class_of(cls, *c);
            if (k == CELL_UNKNOWN)
                continue;
            polyc__tile *t = polyc__grid_tile(g, ix, iy);
            if (!t)
                continue;
            if (k == CELL_FREE) {
                t->misses[polyc__cell_index(ix, iy)] = 1;
                continue;
            }
            if (!faces_free(cls, grid, ix, iy))
                continue;
            POLYC_ASSERT(ctx->contour_count < ctx->lim.max_beams);
            t->contour[iy & (POLYC__TILE_SIDE - 1)] |= 1u << (ix & (POLYC__TILE_SIDE - 1));
            ctx->contour_xy[2 * ctx->contour_count] = ix;
            ctx->contour_xy[2 * ctx->contour_count + 1] = iy;
            ctx->contour_count++;
        }
    ctx->stats.grid_width = (uint32_t)g->width;
    ctx->stats.grid_height = (uint32_t)g->height;
    ctx->stats.grid_tiles = g->tile_count;
    ctx->stats.grid_bytes = (uint64_t)dir_bytes + (uint64_t)g->tile_count * sizeof(polyc__tile);
    ctx->stats.contour_cells = ctx->contour_count;
    return POLYC_OK;
}

polyc_status polyc__occ_add(polyc_ctx *ctx, const polyc_occupancy_grid *grid)
{
    if (ctx->from_grid || ctx->scan_count > 0)
        return polyc__fail(ctx, POLYC_ERR_STATE,
                           ctx->from_grid ? "the context holds a grid already (polyc_reset first)"
                                          : "the context holds scans: a grid needs a context of its own");
    const char *why = NULL;
    uint32_t tx = 0, ty = 0;
    polyc_status st = check_grid(&ctx->cfg, grid, &why, &tx, &ty);
    if (st != POLYC_OK)
        return polyc__fail(ctx, st, why);
    uint8_t cls[256];
    classes(&ctx->cfg, cls);
    uint64_t occupied;
    if ((st = count_occupied(cls, grid, &occupied, &why)) != POLYC_OK)
        return polyc__fail(ctx, st, why);
    if (occupied > ctx->lim.max_beams)
        return polyc__fail(ctx, POLYC_ERR_LIMIT,
                           "more occupied cells than limits.max_beams (polyc_limits_for_grid)");
    /* in the block where the scans' grid would start (an empty context may
     * have run its stages: their results go) */
    size_t mark = ctx->scans_mark;
    ctx->arena.used = mark;
    ctx->stage = POLYC__STAGE_SCANS;
    ctx->flat.count = 0;
    memset(&ctx->grid, 0, sizeof ctx->grid);
    st = fill(ctx, grid, cls, tx, ty);
    size_t head = polyc__bytes(1, sizeof(polyc_ctx));
    ctx->stats.memory_used_bytes = (uint64_t)(head + ctx->arena.peak);
    if (st != POLYC_OK) {
        ctx->arena.used = mark;
        memset(&ctx->grid, 0, sizeof ctx->grid);
        ctx->contour_count = 0;
        ctx->stats.contour_cells = 0;
        return st;
    }
    ctx->from_grid = 1;
    polyc__frame_of_grid(ctx, grid);
    /* the grid and its contour are this context's input: stages restart
     * after them */
    ctx->scans_mark = ctx->grid_mark = ctx->contour_mark = ctx->arena.used;
    ctx->stage = POLYC__STAGE_CONTOUR;
    return POLYC_OK;
}

int polyc__occ_free_at(const polyc_ctx *ctx, float x, float y)
{
    const polyc__grid *g = &ctx->grid;
    float fx = ((float)x - g->frame_ox) / (float)g->cell_m;
    float fy = ((float)y - g->frame_oy) / (float)g->cell_m;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < (float)g->width && fy < (float)g->height))
        return 0;
    int32_t ix = (int32_t)fx, iy = (int32_t)fy;
    const polyc__tile *t = polyc__grid_tile(g, ix, iy);
    return t && t->misses[polyc__cell_index(ix, iy)] != 0;
}
