/* grid.c - the hit/miss grid (paper section III, eq. 1).
 * Takes: the stored scans. Gives: per cell hits and misses, counted by exact
 * traversal of every beam (Amanatides-Woo), in 32 x 32 tiles over the extent
 * of the data, stored only where some beam ends in a hit. */
#include "../walk.h"

/* the external definitions of walk.h's inline functions (C99: one copy
 * where a caller does not inline them, as at -Os) */
extern inline float polyc__max_abs(float a, float b);
extern inline int polyc__walk_step(polyc__walk *w);
extern inline int polyc__walk_enter(polyc__walk *w, int32_t width, int32_t height);

#include <math.h>
#include <string.h>

/* bytes of the bit per directory entry that says a tile is wanted */
static size_t wanted_bytes(size_t dir_n)
{
    return polyc__bytes(dir_n / 32 + 1, sizeof(uint32_t));
}

size_t polyc__grid_dir_cap(const polyc_limits *lim)
{
    size_t tiles = ((size_t)lim->max_grid_cells + POLYC__TILE_CELLS - 1) / POLYC__TILE_CELLS;
    /* one entry per tile of the bounding box; a bounding box up to 4x the
     * tile budget (plus a small fixed part) fits */
    return tiles * 4 + 64;
}

size_t polyc__grid_budget_bytes(const polyc_limits *lim)
{
    size_t tiles = ((size_t)lim->max_grid_cells + POLYC__TILE_CELLS - 1) / POLYC__TILE_CELLS;
    size_t dir_n = polyc__grid_dir_cap(lim);
    size_t dir = polyc__add(polyc__bytes(dir_n, sizeof(uint32_t)), wanted_bytes(dir_n));
    /* the tiles and one more, the spill tile of count_beam */
    return polyc__add(polyc__bytes(tiles + 1, sizeof(polyc__tile)), dir);
}

/* The grid hands out its tiles by data, within its budget (the directory,
 * its bits, the spill tile and the tiles): that budget is its reservation. */
void polyc__grid_reserve(polyc__arena *a, const polyc_limits *lim)
{
    polyc__alloc(a, polyc__grid_budget_bytes(lim), 1);
}

int polyc__cell_occupied(const polyc__tile *t, int idx, float threshold)
{
    unsigned h = t->hits[idx];
    unsigned m = t->misses[idx];
    return h > 0 && (float)h > threshold * (float)(h + m);
}

polyc__tile *polyc__grid_tile(const polyc__grid *g, int32_t ix, int32_t iy)
{
    if (ix < 0 || iy < 0 || ix >= g->width || iy >= g->height)
        return NULL;
    uint32_t d = g->dir[polyc__dir_index(g, ix, iy)];
    return d ? &g->tiles[d - 1] : NULL;
}

/* Distance along the direction (dx, dy) from (sx, sy), inside the box
 * [0, w] x [0, h], before leaving it (sx, sy inside). */
static float exit_distance(float sx, float sy, float dx, float dy, float w, float h)
{
    float t = 1e30f;
    if (dx > 0.0f) t = polyc__minf(t, (w - sx) / dx);
    if (dx < 0.0f) t = polyc__minf(t, -sx / dx);
    if (dy > 0.0f) t = polyc__minf(t, (h - sy) / dy);
    if (dy < 0.0f) t = polyc__minf(t, -sy / dy);
    return t < 0.0f ? 0.0f : t;
}

static int range_is_hit(const polyc__scan *s, float r)
{
    return r >= s->min_m && r < s->max_m;
}

/* sin of the incidence angle of beam i on the surface it hit, from the two
 * neighbouring endpoints when the three are nearly collinear (a surface);
 * 1 when unknown. Done in the beam's own frame: the only trigonometry is
 * the scan's step, given by `rot` or computed when rot is NULL. */
static float incidence_sin(const polyc_ctx *ctx, const polyc__scan *s, uint32_t i, float r,
                           const polyc__step_rot *rot)
{
    if (i == 0 || i + 1 >= s->count)
        return 1.0f;
    const float *rr = ctx->ranges + s->first;
    float rm = rr[i - 1], rp = rr[i + 1];
    if (!range_is_hit(s, rm) || !range_is_hit(s, rp))
        return 1.0f;
    polyc__step_rot own;
    if (!rot) {
        own.cs = polyc__cosf(s->step_rad);
        own.sn = polyc__sinf(s->step_rad);
        rot = &own;
    }
    float cs = rot->cs, sn = rot->sn;
    float ax = rm * cs, ay = -rm * sn; /* neighbour before */
    float cx = rp * cs, cy = rp * sn;  /* neighbour after */
    float tx = cx - ax, ty = cy - ay;
    float len = sqrtf(tx * tx + ty * ty);
    if (len < 1e-6f)
        return 1.0f;
    /* middle point (r, 0) must lie within 3 cm + 2% of the chord */
    float off = fabsf(tx * (0.0f - ay) - ty * (r - ax)) / len;
    if (off > POLYC__SURFACE_OFF_M + POLYC__SURFACE_OFF_REL * r)
        return 1.0f;
    return fabsf(ty) / len;
}

/* Beam i of scan s in grid coordinates; miss_end only when want_miss_end
 * (else 1). Returns 0 for a beam that is skipped. */
static int beam_fill(const polyc_ctx *ctx, const polyc__scan *s, uint32_t i, polyc__beam *b,
                     int want_miss_end, const polyc__step_rot *rot)
{
    const polyc__grid *g = &ctx->grid;
    float r = ctx->ranges[s->first + i];
    if (!(r == r) || r < 0.0f)
        return 0; /* NaN or negative: skipped (counted at add time) */
    float a = s->theta_rad + s->start_rad + (float)i * s->step_rad;
    float dx, dy;
    polyc__sincosf(a, &dy, &dx);
    float ox = s->x_m - g->frame_ox;
    float oy = s->y_m - g->frame_oy;
    b->sx = ox * g->inv_cell;
    b->sy = oy * g->inv_cell;
    float len_m;
    if (range_is_hit(s, r)) {
        b->hit = 1;
        len_m = r;
    } else if (r >= s->max_m && ctx->cfg.free_range_m > 0.0f) {
        b->hit = 0;
        len_m = polyc__minf(ctx->cfg.free_range_m, r < 1e30f ? r : 1e30f);
    } else {
        return 0; /* too short, or no return with free-space marking off */
    }
    float len = len_m * g->inv_cell;
    if (!b->hit) {
        /* no-return beams mark free space only inside the data's extent */
        float w = (float)g->width - 0.001f, h = (float)g->height - 0.001f;
        float t = exit_distance(b->sx, b->sy, dx, dy, w, h);
        if (t < len)
            len = t;
    }
    b->ex = b->sx + dx * len;
    b->ey = b->sy + dy * len;
    b->miss_end = 1.0f;
    if (want_miss_end && b->hit && ctx->cfg.grazing_cells > 0.0f &&
        !(ctx->cfg.flags & POLYC_FLAG_NO_GRAZING)) {
        /* The last cell / sin(incidence) of a beam runs within a cell of the
         * surface it hits: a grazing beam would count misses in the wall's
         * own cells there. Misses stop before that stretch. */
        float sn = polyc__maxf(incidence_sin(ctx, s, i, r, rot), POLYC__INCIDENCE_SIN_MIN);
        float skip = polyc__minf(ctx->cfg.grazing_cells / sn, 0.5f * len);
        b->miss_end = len > 0.0f ? 1.0f - skip / len : 0.0f;
    }
    return 1;
}

int polyc__beam_get(const polyc_ctx *ctx, const polyc__scan *s, uint32_t i, polyc__beam *b)
{
    return beam_fill(ctx, s, i, b, 1, NULL);
}

int polyc__beam_path(const polyc_ctx *ctx, const polyc__scan *s, uint32_t i, polyc__beam *b)
{
    return beam_fill(ctx, s, i, b, 0, NULL);
}

int polyc__beam_turned(const polyc_ctx *ctx, const polyc__scan *s, uint32_t i, polyc__beam *b,
                       const polyc__step_rot *rot)
{
    return beam_fill(ctx, s, i, b, 1, rot);
}

/* The walk's per-beam and per-tile steps out of line, for the records'
 * redo (online_grid.c): one copy of them in the library (at -Os, walk.h's
 * inline steps are a copy per file). */
void polyc__grid_walk_start(struct polyc__walk *w, const polyc__beam *b)
{
    polyc__walk_start(w, b);
}

int64_t polyc__grid_walk_key_at(const struct polyc__walk *w, float t)
{
    return polyc__walk_key_at(w, t);
}

int polyc__grid_walk_skip_tiles(struct polyc__walk *w, int32_t width, int32_t height, int32_t tiles_x,
                                const uint32_t *stop)
{
    return polyc__walk_skip_tiles(w, width, height, tiles_x, stop);
}

/* Exact traversal of the cells from (sx, sy) to (ex, ey); `visit` gets each
 * cell with the beam parameter t at which the beam enters it. Returns early
 * when visit returns non-zero. */
void polyc__traverse(const polyc__beam *b, polyc__cell_fn visit, void *u)
{
    polyc__walk w;
    polyc__walk_start(&w, b);
    while (w.n > 0) {
        if (visit(u, w.ix, w.iy, polyc__walk_t(&w), 0))
            return;
        polyc__walk_step(&w);
    }
    visit(u, w.ex, w.ey, polyc__walk_t(&w), 1);
}

/* The grid pass stores a tile only where some beam ends in a hit (`wanted`,
 * a bit per directory entry from a pass over the endpoints). Elsewhere the
 * misses go to `spill`, a scratch tile that is never read: a tile without a
 * hit holds no occupied cell and no data point, so nothing downstream needs
 * it, and outdoors such free space is most of what the beams cross. */
typedef struct count_pass {
    polyc__grid *g;
    polyc__arena *a;
    const uint32_t *wanted;
    polyc__tile *spill;
    const polyc__layer *layer;     /* g->rec's hooks (NULL: no records) */
    int records;                   /* misses in tiles not stored into their records */
} count_pass;

/* The tile of cell (ix, iy) inside the grid: stored (allocated on first use
 * if wanted) or the spill tile; NULL when the tile budget is spent
 * (out_of_tiles). Tiles stay contiguous: nothing else allocates meanwhile. */
static polyc__tile *tile_get(const count_pass *p, int32_t ix, int32_t iy)
{
    polyc__grid *g = p->g;
    size_t d = polyc__dir_index(g, ix, iy);
    if (g->dir[d] == 0) {
        if (!((p->wanted[d >> 5] >> (d & 31)) & 1u))
            return p->spill;
        if (g->tile_count >= g->tile_cap) {
            g->out_of_tiles = 1;
            return NULL;
        }
        polyc__tile *t = polyc__alloc_zero(p->a, 1, sizeof(polyc__tile));
        if (!t || t != g->tiles + g->tile_count) {
            g->out_of_tiles = 1;
            return NULL;
        }
        g->dir[d] = ++g->tile_count;
        if (p->layer)
            p->layer->rec_take(g->rec, t, d); /* its record's misses */
    }
    return &g->tiles[g->dir[d] - 1];
}

/* One beam into the counters: a miss in every cell the beam enters before
 * miss_end, a hit in the end cell of a reflection; the walk stops at the
 * grid's edge. The tile is looked up only when the walk crosses into
 * another one. */
/* One count: in, or out again (take_back, the constant 0 in a batch
 * build's calls, which the compiler folds away). */
static inline void count_one(int take_back, polyc__count *a, polyc__count *b)
{
    if (take_back)
        polyc__count_dec(a);
    else
        polyc__count_inc(a, b);
}

static inline void count_beam(const count_pass *p, const polyc__beam *b, int take_back,
                              uint32_t *on_hits)
{
    polyc__grid *g = p->g;
    polyc__walk w;
    polyc__walk_start(&w, b);
    const int64_t miss_key = polyc__walk_key_at(&w, b->miss_end);
    polyc__tile *t = NULL;
    if (w.n > 0 && (!polyc__walk_enter(&w, g->width, g->height) || !(t = tile_get(p, w.ix, w.iy))))
        return;
    while (w.n > 0) {
        if (t == p->spill && p->records) {
            /* into the record of this tile not stored */
            size_t d = polyc__dir_index(g, w.ix, w.iy);
            int left = p->layer->rec_walk(g->rec, d, &w, miss_key, take_back);
            if (left && w.n > 0 &&
                (!polyc__walk_enter(&w, g->width, g->height) || !(t = tile_get(p, w.ix, w.iy))))
                return;
            continue;
        }
        if (t == p->spill) {
            /* nothing is counted here or in the tiles after it until one
             * where some beam ends in a hit: the walk goes there in one
             * move, or ends (then its end cell), or leaves the grid */
            int to = polyc__walk_skip_tiles(&w, g->width, g->height, g->tiles_x, p->wanted);
            if (to < 0)
                return;
            if (to == 0)
                break;
            if (!polyc__walk_enter(&w, g->width, g->height) || !(t = tile_get(p, w.ix, w.iy)))
                return;
            continue;
        }
        /* a stored tile: counted up to its edge (or the end cell) */
        int left;
        do {
            if (w.t_key < miss_key) {
                count_one(take_back, &t->misses[w.idx], &t->hits[w.idx]);
                if (on_hits && t->hits[w.idx])
                    on_hits[t - g->tiles]++;
            }
            left = polyc__walk_step(&w);
        } while (!left && w.n > 0);
        if (left && w.n > 0 &&
            (!polyc__walk_enter(&w, g->width, g->height) || !(t = tile_get(p, w.ix, w.iy))))
            return;
    }
    /* the end cell, where the walk is unless rounding took it elsewhere */
    if (w.ex < 0 || w.ey < 0 || w.ex >= g->width || w.ey >= g->height ||
        !(t = tile_get(p, w.ex, w.ey)))
        return;
    int idx = polyc__cell_index(w.ex, w.ey);
    if (b->hit)
        count_one(take_back, &t->hits[idx], &t->misses[idx]);
    else if (w.t_key < miss_key)
        count_one(take_back, &t->misses[idx], &t->hits[idx]);
}

/* The grid's cells over w_m x h_m metres from the frame-relative corner
 * (x0, y0), its directory, wanted bits and spill tile; the tiles follow in
 * the block as beams reach them. */
static polyc_status grid_lay_out(polyc_ctx *ctx, float x0, float y0, float w_m, float h_m,
                                 uint32_t tile_cap)
{
    polyc__grid *g = &ctx->grid;
    float cell = ctx->cfg.cell_m;
    float cell_d = (float)cell;
    g->cell_m = cell;
    g->inv_cell = 1.0f / cell;
    polyc__frame_grid_origin(ctx, g, x0, y0);
    float wc = ceilf(w_m / cell_d), hc = ceilf(h_m / cell_d);
    if (wc > 2147483000.0f || hc > 2147483000.0f)
        return polyc__fail(ctx, POLYC_ERR_EXTENT, "grid too large for 32-bit cell indices");
    g->width = (int32_t)wc;
    g->height = (int32_t)hc;
    g->tiles_x = (g->width + POLYC__TILE_SIDE - 1) / POLYC__TILE_SIDE;
    g->tiles_y = (g->height + POLYC__TILE_SIDE - 1) / POLYC__TILE_SIDE;

    size_t dir_n = (size_t)g->tiles_x * (size_t)g->tiles_y;
    size_t dir_bytes = polyc__bytes(dir_n, sizeof(uint32_t));
    size_t fixed = polyc__add(polyc__add(dir_bytes, wanted_bytes(dir_n)),
                              polyc__bytes(1, sizeof(polyc__tile))); /* + the spill tile */
    size_t budget = tile_cap ? polyc__add(fixed, polyc__bytes(tile_cap, sizeof(polyc__tile)))
                             : polyc__grid_budget_bytes(&ctx->lim);
    if (dir_bytes == 0 || fixed >= budget)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "grid extent too large for limits.max_grid_cells");
    g->dir = polyc__alloc_zero(&ctx->arena, dir_n, sizeof(uint32_t));
    g->wanted = polyc__alloc_zero(&ctx->arena, dir_n / 32 + 1, sizeof(uint32_t));
    g->spill = polyc__alloc_zero(&ctx->arena, 1, sizeof(polyc__tile));
    if (!g->dir || !g->wanted || !g->spill)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the grid directory");
    g->tile_cap = (uint32_t)((budget - fixed) / sizeof(polyc__tile));
    g->tiles = (polyc__tile *)(ctx->arena.base + ctx->arena.used);
    g->fixed_bytes = fixed;
    return POLYC_OK;
}

/* Sets the wanted bit of the tiles where the scan's beams end in a hit. */
static void want_hits(polyc_ctx *ctx, const polyc__scan *s)
{
    polyc__grid *g = &ctx->grid;
    for (uint32_t i = 0; i < s->count; i++) {
        polyc__beam b;
        if (!polyc__beam_path(ctx, s, i, &b) || !b.hit)
            continue;
        int32_t ix = (int32_t)floorf(b.ex), iy = (int32_t)floorf(b.ey);
        if (ix >= 0 && iy >= 0 && ix < g->width && iy < g->height) {
            size_t d = polyc__dir_index(g, ix, iy);
            g->wanted[d >> 5] |= 1u << (d & 31);
        }
    }
}

/* Counts (or takes back) every beam of the scan; with `records`, the
 * misses in the tiles not stored into their records too (a grid with
 * records, g->rec: a layer's). */
static polyc_status count_scan(polyc_ctx *ctx, const polyc__scan *s, int take_back,
                               uint32_t *on_hits, int records)
{
    polyc__grid *g = &ctx->grid;
    count_pass p;
    p.g = g;
    p.a = &ctx->arena;
    p.wanted = g->wanted;
    p.spill = g->spill;
    p.layer = g->rec ? ctx->layer : NULL;
    p.records = records && p.layer;
    polyc__step_rot rot = {polyc__cosf(s->step_rad), polyc__sinf(s->step_rad)};
    for (uint32_t i = 0; i < s->count; i++) {
        polyc__beam b;
        if (!beam_fill(ctx, s, i, &b, 1, &rot))
            continue;
        /* the batch's (and an added scan's) count without the online
         * tests in its inner loop: constants the compiler folds */
        if (!take_back && !on_hits)
            count_beam(&p, &b, 0, NULL);
        else
            count_beam(&p, &b, take_back, on_hits);
        if (g->out_of_tiles)
            return polyc__fail(ctx, POLYC_ERR_NOMEM, "grid needs more cells than limits.max_grid_cells");
    }
    return POLYC_OK;
}

static void grid_stats(polyc_ctx *ctx)
{
    const polyc__grid *g = &ctx->grid;
    ctx->stats.grid_width = (uint32_t)g->width;
    ctx->stats.grid_height = (uint32_t)g->height;
    ctx->stats.grid_tiles = g->tile_count;
    ctx->stats.grid_bytes = (uint64_t)g->fixed_bytes + (uint64_t)g->tile_count * sizeof(polyc__tile);
}

polyc_status polyc__grid_recount_scan(polyc_ctx *ctx, const polyc__scan *s)
{
    polyc_status st = count_scan(ctx, s, 0, NULL, 0);
    grid_stats(ctx);
    return st;
}

polyc_status polyc__grid_build(polyc_ctx *ctx)
{
    polyc__grid *g = &ctx->grid;
    memset(g, 0, sizeof *g);
    if (!ctx->ext.have)
        return POLYC_OK; /* no data: an empty grid */
    float ext = (float)ctx->cfg.max_extent_m, pad = 2.0f * (float)ctx->cfg.cell_m;
    float box[4];
    polyc__frame_box(ctx, box);
    float w_m = box[2] - box[0] + 2.0f * pad;
    float h_m = box[3] - box[1] + 2.0f * pad;
    if (w_m > ext || h_m > ext)
        return polyc__fail(ctx, POLYC_ERR_EXTENT,
                           "the data span more than config.max_extent_m (a far-away scan?)");
    polyc_status st = grid_lay_out(ctx, box[0] - pad, box[1] - pad, w_m, h_m, 0);
    if (st != POLYC_OK)
        return st;
    for (uint32_t si = 0; si < ctx->scan_count; si++)
        want_hits(ctx, &ctx->scans[si]);
    for (uint32_t si = 0; si < ctx->scan_count; si++)
        if ((st = count_scan(ctx, &ctx->scans[si], 0, NULL, 0)) != POLYC_OK)
            return st;
    grid_stats(ctx);
    return POLYC_OK;
}

polyc_status polyc__grid_online_init(polyc_ctx *ctx, float side_m, uint32_t max_cells)
{
    memset(&ctx->grid, 0, sizeof ctx->grid);
    uint32_t tiles = (max_cells + POLYC__TILE_CELLS - 1) / POLYC__TILE_CELLS;
    return grid_lay_out(ctx, -0.5f * side_m, -0.5f * side_m, side_m, side_m, tiles);
}

void polyc__grid_want(polyc_ctx *ctx, const polyc__scan *s)
{
    want_hits(ctx, s);
}

polyc_status polyc__grid_add_scan(polyc_ctx *ctx, const polyc__scan *s, int take_back,
                                  uint32_t *on_hits)
{
    if (!take_back)
        want_hits(ctx, s);
    polyc_status st = count_scan(ctx, s, take_back, on_hits, 1);
    grid_stats(ctx);
    return st;
}
