/* grid.c - the hit/miss grid (paper section III, eq. 1).
 * Takes: the stored scans. Gives: per cell hits and misses, counted by exact
 * traversal of every beam (Amanatides-Woo), in 32 x 32 tiles over the extent
 * of the data, stored only where some beam ends in a hit. */
#include "walk.h"

#include <math.h>
#include <string.h>

/* A cell's two counters saturate by halving both, which keeps m = h/(h+m). */
static void count_inc(polyc__count *a, polyc__count *b)
{
    if (*a == POLYC__COUNT_MAX) {
        *a = (polyc__count)(*a >> 1);
        *b = (polyc__count)(*b >> 1);
    }
    (*a)++;
}

/* A scan taken back (an online pose correction): exact unless the cell
 * saturated since, then never below 0. */
static void count_dec(polyc__count *a, polyc__count *b)
{
    (void)b;
    if (*a > 0)
        (*a)--;
}

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

/* directory entry of the tile of cell (ix, iy), inside the grid */
static size_t dir_index(const polyc__grid *g, int32_t ix, int32_t iy)
{
    size_t tx = (size_t)(ix >> POLYC__TILE_SHIFT), ty = (size_t)(iy >> POLYC__TILE_SHIFT);
    return ty * (size_t)g->tiles_x + tx;
}

polyc__tile *polyc__grid_tile(const polyc__grid *g, int32_t ix, int32_t iy)
{
    if (ix < 0 || iy < 0 || ix >= g->width || iy >= g->height)
        return NULL;
    uint32_t d = g->dir[dir_index(g, ix, iy)];
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

/* cos and sin of a scan's angular step, for incidence_sin */
typedef struct step_rot {
    float cs, sn;
} step_rot;

/* sin of the incidence angle of beam i on the surface it hit, from the two
 * neighbouring endpoints when the three are nearly collinear (a surface);
 * 1 when unknown. Done in the beam's own frame: the only trigonometry is
 * the scan's step, given by `rot` or computed when rot is NULL. */
static float incidence_sin(const polyc_ctx *ctx, const polyc__scan *s, uint32_t i, float r,
                           const step_rot *rot)
{
    if (i == 0 || i + 1 >= s->count)
        return 1.0f;
    const float *rr = ctx->ranges + s->first;
    float rm = rr[i - 1], rp = rr[i + 1];
    if (!range_is_hit(s, rm) || !range_is_hit(s, rp))
        return 1.0f;
    step_rot own;
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
                     int want_miss_end, const step_rot *rot)
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
    int records;                   /* online: misses in tiles not stored into their records */
} count_pass;

/* ---- an online grid's misses in tiles not stored ----
 *
 * A batch knows every scan before it counts, so it stores each tile some
 * beam ends in and every miss there is counted. An online grid stores a
 * tile when the first beam ends in it; the misses beams made there before
 * would be lost, and a person who stops in a hall that the robot has seen
 * through for minutes would look as solid as a wall (the sweep's
 * thinwalls seed 8 drew one 29.7 mm off the walls against the batch's
 * 2.8; freiburg-campus had 3,340 polylines against the batch's 2,540).
 * So a tile not stored that beams cross takes a record from a pool (548
 * bytes, not a tile's 4 KiB; online.c sizes the pool): its misses at half
 * a byte a cell, exact up to POLYC__PRE_FULL, and per block of 8 x 8 cells
 * their sum. (When the pool is spent, a tile's cells start from the misses
 * counted once it is stored.) A tile stored later takes them: a cell below
 * the cap its own count, a cell at the cap its share of what its block's
 * sum holds beyond the cells below the cap. A cell next
 * to a wall, crossed by a few grazing beams, keeps those few (a block's
 * mean there put a wall first seen late under the free cells' misses: the
 * map of intel's first 100 scans scored 1.19 times the batch's BIC). */

static int pre_block(int idx)
{
    const int per_tile = POLYC__TILE_SHIFT - POLYC__PRE_SHIFT;
    return ((idx >> (POLYC__TILE_SHIFT + POLYC__PRE_SHIFT)) << per_tile) |
           ((idx & (POLYC__TILE_SIDE - 1)) >> POLYC__PRE_SHIFT);
}

static unsigned pre_cell(const uint8_t *nib, int idx)
{
    return (nib[idx >> 1] >> ((idx & 1) * 4)) & 15u;
}

/* The record of the tile not stored at directory entry d: its number,
 * taken from the pool if `take` (-1: none, or the pool is spent). */
static int64_t pre_record(polyc__grid *g, size_t d, int take)
{
    if (g->pre_of[d])
        return (int64_t)g->pre_of[d] - 1;
    if (!take)
        return -1;
    uint32_t r;
    if (g->pre_nfree > 0)
        r = g->pre_free[--g->pre_nfree];
    else if (g->pre_high < g->pre_cap)
        r = g->pre_high++;
    else
        return -1; /* (the pool is spent: those misses are lost) */
    g->pre_of[d] = r + 1;
    return r;
}

/* A tile stored now takes its record, which goes back to the pool. */
static void take_pre_misses(polyc__grid *g, polyc__tile *t, size_t d)
{
    int64_t r = pre_record(g, d, 0);
    if (r < 0)
        return;
    uint8_t *nib = g->pre_cells + (size_t)r * (POLYC__TILE_CELLS / 2);
    uint16_t *sum = g->pre_miss + (size_t)r * POLYC__PRE_BLOCKS;
    unsigned below[POLYC__PRE_BLOCKS] = {0}, full[POLYC__PRE_BLOCKS] = {0};
    for (int idx = 0; idx < POLYC__TILE_CELLS; idx++) {
        unsigned c = pre_cell(nib, idx);
        if (c == POLYC__PRE_FULL)
            full[pre_block(idx)]++;
        else
            below[pre_block(idx)] += c;
    }
    for (int idx = 0; idx < POLYC__TILE_CELLS; idx++) {
        unsigned c = pre_cell(nib, idx);
        if (c == POLYC__PRE_FULL) {
            int k = pre_block(idx);
            unsigned rest = sum[k] > below[k] ? sum[k] - below[k] : 0;
            c = (rest + full[k] / 2) / full[k];
            c = c < POLYC__PRE_FULL ? POLYC__PRE_FULL : c;
        }
        t->misses[idx] = (polyc__count)(c > POLYC__COUNT_MAX ? POLYC__COUNT_MAX : c);
    }
    memset(nib, 0, POLYC__TILE_CELLS / 2);
    memset(sum, 0, POLYC__PRE_BLOCKS * sizeof *sum);
    g->pre_of[d] = 0;
    g->pre_free[g->pre_nfree++] = (uint32_t)r;
}

/* The beam's cells in the tile not stored of entry d, from the walk's
 * cell to the tile's edge or the end cell, into its record (take_back: out
 * again, where the count is exact). As count_beam's loop: a cell counts
 * when the walk enters it before miss_end. Returns polyc__walk_step's
 * last result (1: the walk left the tile). */
static int pre_walk(polyc__grid *g, size_t d, polyc__walk *w, int64_t miss_key, int take_back)
{
    int64_t r = pre_record(g, d, !take_back);
    int left = 0;
    if (r < 0) {
        do
            left = polyc__walk_step(w);
        while (!left && w->n > 0);
        return left;
    }
    uint8_t *nib = g->pre_cells + (size_t)r * (POLYC__TILE_CELLS / 2);
    uint16_t *sum = g->pre_miss + (size_t)r * POLYC__PRE_BLOCKS;
    do {
        if (w->t_key < miss_key) {
            uint16_t *s = &sum[pre_block(w->idx)];
            unsigned c = pre_cell(nib, w->idx), shift = (unsigned)(w->idx & 1) * 4;
            if (take_back) {
                *s = (uint16_t)(*s > 0 ? *s - 1 : 0);
                if (c > 0 && c < POLYC__PRE_FULL)
                    nib[w->idx >> 1] = (uint8_t)(nib[w->idx >> 1] - (1u << shift));
            } else {
                *s = (uint16_t)(*s < 65535u ? *s + 1 : *s);
                if (c < POLYC__PRE_FULL)
                    nib[w->idx >> 1] = (uint8_t)(nib[w->idx >> 1] + (1u << shift));
            }
        }
        left = polyc__walk_step(w);
    } while (!left && w->n > 0);
    return left;
}

/* The tile of cell (ix, iy) inside the grid: stored (allocated on first use
 * if wanted) or the spill tile; NULL when the tile budget is spent
 * (out_of_tiles). Tiles stay contiguous: nothing else allocates meanwhile. */
static polyc__tile *tile_get(const count_pass *p, int32_t ix, int32_t iy)
{
    polyc__grid *g = p->g;
    size_t d = dir_index(g, ix, iy);
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
        if (g->pre_miss)
            take_pre_misses(g, t, d);
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
        count_dec(a, b);
    else
        count_inc(a, b);
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
            /* online: into the record of this tile not stored */
            int left = pre_walk(g, dir_index(g, w.ix, w.iy), &w, miss_key, take_back);
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
            size_t d = dir_index(g, ix, iy);
            g->wanted[d >> 5] |= 1u << (d & 31);
        }
    }
}

/* Counts (or takes back) every beam of the scan; with `records`, an online
 * grid's misses in the tiles not stored too. */
static polyc_status count_scan(polyc_ctx *ctx, const polyc__scan *s, int take_back,
                               uint32_t *on_hits, int records)
{
    polyc__grid *g = &ctx->grid;
    count_pass p;
    p.g = g;
    p.a = &ctx->arena;
    p.wanted = g->wanted;
    p.spill = g->spill;
    p.records = records && g->pre_miss;
    step_rot rot = {polyc__cosf(s->step_rad), polyc__sinf(s->step_rad)};
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

/* ---- the records made again after a recount ----
 * Counting every kept scan again (a pose correction of most of them) as
 * the batch counts, over the tiles not stored in one move, saves walking
 * their cells: on intel, 910 scans in 70 ms instead of 105. The records
 * those misses belong to are made again afterwards, a slice of scans at a
 * time (online.c): each scan's beams walk the tiles that were not stored
 * at the recount (redo_need) and skip the others, whose counts are
 * complete. A tile still not stored takes the misses into its record; one
 * stored since (a later scan's hit) into its counts, which hold the later
 * scans' misses and its record's share already. Until every scan is done
 * a tile stored meanwhile misses the rest's misses for a while; nothing
 * else reads the records. */

void polyc__grid_redo_begin(polyc__grid *g)
{
    size_t dir_n = (size_t)g->tiles_x * (size_t)g->tiles_y;
    memset(g->redo_need, 0, (dir_n / 32 + 1) * sizeof *g->redo_need);
    for (size_t d = 0; d < dir_n; d++)
        if (g->dir[d] == 0)
            g->redo_need[d >> 5] |= 1u << (d & 31);
}

static int redo_needs(const polyc__grid *g, size_t d)
{
    return (g->redo_need[d >> 5] >> (d & 31)) & 1u;
}

static void redo_beam(polyc__grid *g, const polyc__beam *b, uint32_t *on_hits)
{
    polyc__walk w;
    polyc__walk_start(&w, b);
    const int64_t miss_key = polyc__walk_key_at(&w, b->miss_end);
    if (w.n > 0 && !polyc__walk_enter(&w, g->width, g->height))
        return;
    while (w.n > 0) {
        size_t d = dir_index(g, w.ix, w.iy);
        if (!redo_needs(g, d)) {
            int to = polyc__walk_skip_tiles(&w, g->width, g->height, g->tiles_x, g->redo_need);
            if (to < 0)
                return;
            if (to == 0)
                break;
            if (!polyc__walk_enter(&w, g->width, g->height))
                return;
            continue;
        }
        int left;
        if (g->dir[d] == 0) {
            left = pre_walk(g, d, &w, miss_key, 0);
        } else {
            polyc__tile *t = &g->tiles[g->dir[d] - 1];
            do {
                if (w.t_key < miss_key) {
                    count_one(0, &t->misses[w.idx], &t->hits[w.idx]);
                    if (on_hits && t->hits[w.idx])
                        on_hits[t - g->tiles]++;
                }
                left = polyc__walk_step(&w);
            } while (!left && w.n > 0);
        }
        if (left && w.n > 0 && !polyc__walk_enter(&w, g->width, g->height))
            return;
    }
    /* the end cell: a miss past the last reflection's reach, counted only
     * in a stored tile (as count_beam) */
    if (b->hit || w.ex < 0 || w.ey < 0 || w.ex >= g->width || w.ey >= g->height ||
        w.t_key >= miss_key)
        return;
    size_t d = dir_index(g, w.ex, w.ey);
    if (redo_needs(g, d) && g->dir[d] != 0) {
        polyc__tile *t = &g->tiles[g->dir[d] - 1];
        int idx = polyc__cell_index(w.ex, w.ey);
        count_one(0, &t->misses[idx], &t->hits[idx]);
    }
}

void polyc__grid_redo_scan(polyc_ctx *ctx, const polyc__scan *s, uint32_t *on_hits)
{
    step_rot rot = {polyc__cosf(s->step_rad), polyc__sinf(s->step_rad)};
    for (uint32_t i = 0; i < s->count; i++) {
        polyc__beam b;
        if (beam_fill(ctx, s, i, &b, 1, &rot))
            redo_beam(&ctx->grid, &b, on_hits);
    }
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

/* Every count to 0, in the stored tiles and in the records of the tiles
 * not stored, which go back to the pool; the tiles stay stored (their
 * contour bits too: the caller casts the contour again). */
void polyc__grid_clear_counts(polyc__grid *g)
{
    for (uint32_t t = 0; t < g->tile_count; t++) {
        polyc__tile *tile = &g->tiles[t];
        memset(tile->hits, 0, sizeof tile->hits);
        memset(tile->misses, 0, sizeof tile->misses);
    }
    if (!g->pre_miss)
        return;
    memset(g->pre_of, 0, (size_t)g->tiles_x * (size_t)g->tiles_y * sizeof *g->pre_of);
    memset(g->pre_cells, 0, (size_t)g->pre_high * (POLYC__TILE_CELLS / 2));
    memset(g->pre_miss, 0, (size_t)g->pre_high * POLYC__PRE_BLOCKS * sizeof *g->pre_miss);
    g->pre_high = 0;
    g->pre_nfree = 0;
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
