/* online_grid.c - an online grid's records of the misses in tiles not
 * stored (a pool of them, sized and carved here, handed to the grid's
 * count as hooks), and their redo after every kept scan was counted again.
 * Takes: the grid (grid.c) and the kept scans. Gives: the misses a batch
 * count of the same scans would have in every tile stored. */
#include "../online.h"
#include "../walk.h"

#include <string.h>

/* A batch knows every scan before it counts, so it stores each tile some
 * beam ends in and every miss there is counted. An online grid stores a
 * tile when the first beam ends in it; the misses beams made there before
 * would be lost, and a person who stops in a hall that the robot has seen
 * through for minutes would look as solid as a wall (online maps drew
 * lines through open halls that the batch map leaves empty, and a campus
 * log's map kept far more polylines than the batch's).
 * So a tile not stored that beams cross takes a record from a pool (548
 * bytes, not a tile's 4 KiB; sized below): its misses at half
 * a byte a cell, exact up to POLYC__PRE_FULL, and per block of 8 x 8 cells
 * their sum. (When the pool is spent, a tile's cells start from the misses
 * counted once it is stored.) A tile stored later takes them: a cell below
 * the cap its own count, a cell at the cap its share of what its block's
 * sum holds beyond the cells below the cap. A cell next
 * to a wall, crossed by a few grazing beams, keeps those few (a block's
 * mean there put a wall first seen late under the free cells' misses, and
 * the early map lost walls that the batch map of the same scans has). */

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
static int64_t pre_record(polyc__records *rec, size_t d, int take)
{
    if (rec->pre_of[d])
        return (int64_t)rec->pre_of[d] - 1;
    if (!take)
        return -1;
    uint32_t r;
    if (rec->pre_nfree > 0)
        r = rec->pre_free[--rec->pre_nfree];
    else if (rec->pre_high < rec->pre_cap)
        r = rec->pre_high++;
    else
        return -1; /* (the pool is spent: those misses are lost) */
    rec->pre_of[d] = r + 1;
    return r;
}

/* A tile stored now takes its record, which goes back to the pool. */
void polyc__records_take(polyc__records *rec, polyc__tile *t, size_t d)
{
    int64_t r = pre_record(rec, d, 0);
    if (r < 0)
        return;
    uint8_t *nib = rec->pre_cells + (size_t)r * (POLYC__TILE_CELLS / 2);
    uint16_t *sum = rec->pre_miss + (size_t)r * POLYC__PRE_BLOCKS;
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
    rec->pre_of[d] = 0;
    rec->pre_free[rec->pre_nfree++] = (uint32_t)r;
}

/* The walk's cells from where it is to its tile's edge or the end cell
 * into a record (nib, sum), as count_beam's loop counts a stored tile: a
 * cell counts when the walk enters it before miss_key. The steps are
 * polyc__walk_step's, on the walk's fields held in locals: the byte stores
 * may alias anything, and through the walk's pointer each step would load
 * them again (half of an online add's time on a long-range log is this
 * loop). take_back: out again, where the count is exact (a constant in
 * each call below, which the compiler folds). Returns the last step's
 * result (1: the walk left the tile). */
static inline int record_cells(polyc__walk *w, uint8_t *nib, uint16_t *sum, int64_t miss_key,
                               int take_back)
{
    int64_t kx = w->kx, ky = w->ky, t = w->t_key;
    const int64_t inc_x = w->inc_x, inc_y = w->inc_y;
    int32_t idx = w->idx, n = w->n, lx = w->left_x, ly = w->left_y;
    const int32_t sx = w->stx, sy = w->sty, lx0 = lx, ly0 = ly;
    int left;
    do {
        if (t < miss_key) {
            uint16_t *s = &sum[pre_block(idx)];
            uint8_t *p = &nib[idx >> 1];
            unsigned shift = (unsigned)(idx & 1) * 4, c = (unsigned)(*p >> shift) & 15u;
            if (take_back) {
                *s = (uint16_t)(*s > 0 ? *s - 1 : 0);
                if (c > 0 && c < POLYC__PRE_FULL)
                    *p = (uint8_t)(*p - (1u << shift));
            } else {
                *s = (uint16_t)(*s < 65535u ? *s + 1 : *s);
                if (c < POLYC__PRE_FULL)
                    *p = (uint8_t)(*p + (1u << shift));
            }
        }
        n--;
        if (kx < ky) {
            t = kx;
            kx += inc_x;
            idx += sx;
            left = --lx < 0;
        } else {
            t = ky;
            ky += inc_y;
            idx += sy * POLYC__TILE_SIDE;
            left = --ly < 0;
        }
    } while (!left && n > 0);
    w->kx = kx;
    w->ky = ky;
    w->t_key = t;
    w->idx = idx;
    w->n = n;
    w->ix += sx * (lx0 - lx); /* a step each time left_x went down */
    w->iy += sy * (ly0 - ly);
    w->left_x = lx;
    w->left_y = ly;
    return left;
}

/* The beam's cells in the tile not stored of entry d, from the walk's
 * cell to the tile's edge or the end cell, into its record (take_back: out
 * again). Returns polyc__walk_step's last result (1: the walk left the
 * tile). */
int polyc__records_walk(polyc__records *rec, size_t d, polyc__walk *w, int64_t miss_key, int take_back)
{
    int64_t r = pre_record(rec, d, !take_back);
    int left = 0;
    if (r < 0) {
        do
            left = polyc__walk_step(w);
        while (!left && w->n > 0);
        return left;
    }
    uint8_t *nib = rec->pre_cells + (size_t)r * (POLYC__TILE_CELLS / 2);
    uint16_t *sum = rec->pre_miss + (size_t)r * POLYC__PRE_BLOCKS;
    return take_back ? record_cells(w, nib, sum, miss_key, 1) : record_cells(w, nib, sum, miss_key, 0);
}


/* The pool: for four times as many tiles as the grid stores, and no more
 * than the area holds. On a large log the beams cross about four times
 * the tiles that end up stored; a hall seen with a long-range scanner
 * spent a pool of twice the tiles, and its map lost precision against one
 * with every record it needed, but not a pool of four. */
static size_t pool_records(uint32_t tile_cap, size_t dir_n)
{
    size_t n = 4 * (size_t)tile_cap;
    return n < dir_n ? n : dir_n;
}

int polyc__records_carve(polyc__arena *a, polyc__records *r, uint32_t tile_cap, size_t dir_n)
{
    int ok = 1;
    size_t cap = pool_records(tile_cap, dir_n);
    memset(r, 0, sizeof *r);
    POLYC__CARVE_ZERO(ok, a, r->pre_of, dir_n);
    POLYC__CARVE_ZERO(ok, a, r->pre_miss, cap * POLYC__PRE_BLOCKS);
    POLYC__CARVE_ZERO(ok, a, r->pre_cells, cap * (POLYC__TILE_CELLS / 2));
    POLYC__CARVE(ok, a, r->pre_free, cap);
    POLYC__CARVE_ZERO(ok, a, r->redo_need, dir_n / 32 + 1);
    r->pre_cap = (uint32_t)cap;
    return ok;
}

/* ---- the records made again after a recount ----
 * Counting every kept scan again (a pose correction of most of them) as
 * the batch counts, over the tiles not stored in one move, saves walking
 * their cells one by one, the larger part of a recount's time. The records
 * those misses belong to are made again afterwards, a slice of scans at a
 * time (polyc__online_redo_records): each scan's beams walk the tiles that were not stored
 * at the recount (redo_need) and skip the others, whose counts are
 * complete. A tile still not stored takes the misses into its record; one
 * stored since (a later scan's hit) into its counts, which hold the later
 * scans' misses and its record's share already. Until every scan is done
 * a tile stored meanwhile misses the rest's misses for a while; nothing
 * else reads the records. */

static void redo_begin(const polyc__grid *g, polyc__records *r)
{
    size_t dir_n = (size_t)g->tiles_x * (size_t)g->tiles_y;
    memset(r->redo_need, 0, (dir_n / 32 + 1) * sizeof *r->redo_need);
    for (size_t d = 0; d < dir_n; d++)
        if (g->dir[d] == 0)
            r->redo_need[d >> 5] |= 1u << (d & 31);
}

static int redo_needs(const polyc__records *r, size_t d)
{
    return (r->redo_need[d >> 5] >> (d & 31)) & 1u;
}

static void redo_beam(const polyc__grid *g, polyc__records *r, const polyc__beam *b, uint32_t *on_hits)
{
    polyc__walk w;
    polyc__grid_walk_start(&w, b);
    const int64_t miss_key = polyc__grid_walk_key_at(&w, b->miss_end);
    if (w.n > 0 && !polyc__walk_enter(&w, g->width, g->height))
        return;
    while (w.n > 0) {
        size_t d = polyc__dir_index(g, w.ix, w.iy);
        if (!redo_needs(r, d)) {
            int to = polyc__grid_walk_skip_tiles(&w, g->width, g->height, g->tiles_x, r->redo_need);
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
            left = polyc__records_walk(r, d, &w, miss_key, 0);
        } else {
            polyc__tile *t = &g->tiles[g->dir[d] - 1];
            do {
                if (w.t_key < miss_key) {
                    polyc__count_inc(&t->misses[w.idx], &t->hits[w.idx]);
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
    size_t d = polyc__dir_index(g, w.ex, w.ey);
    if (redo_needs(r, d) && g->dir[d] != 0) {
        polyc__tile *t = &g->tiles[g->dir[d] - 1];
        int idx = polyc__cell_index(w.ex, w.ey);
        polyc__count_inc(&t->misses[idx], &t->hits[idx]);
    }
}

static void redo_scan(polyc_ctx *ctx, polyc__records *r, const polyc__scan *s, uint32_t *on_hits)
{
    polyc__step_rot rot = {polyc__cosf(s->step_rad), polyc__sinf(s->step_rad)};
    for (uint32_t i = 0; i < s->count; i++) {
        polyc__beam b;
        if (polyc__beam_turned(ctx, s, i, &b, &rot))
            redo_beam(&ctx->grid, r, &b, on_hits);
    }
}

void polyc__records_redo_begin(polyc_ctx *ctx, polyc__records *r, uint32_t kept_n)
{
    redo_begin(&ctx->grid, r);
    r->redo_next = 0;
    r->redo_end = kept_n;
}

void polyc__online_redo_records(polyc_ctx *ctx, uint32_t beams)
{
    polyc__online *on = ctx->online;
    polyc__records *r = &on->rec;
    uint32_t done = 0;
    while (r->redo_next < r->redo_end && done < beams) {
        const polyc__scan *s = &ctx->scans[1 + r->redo_next++];
        redo_scan(ctx, r, s, on->backlog.tile_miss);
        done += s->count > 0 ? s->count : 1;
    }
}

/* Every count to 0, in the stored tiles and in the records of the tiles
 * not stored, which go back to the pool; the tiles stay stored (their
 * contour bits too: the caller casts the contour again). */
void polyc__records_clear_counts(polyc__grid *g, polyc__records *r)
{
    for (uint32_t t = 0; t < g->tile_count; t++) {
        polyc__tile *tile = &g->tiles[t];
        memset(tile->hits, 0, sizeof tile->hits);
        memset(tile->misses, 0, sizeof tile->misses);
    }
    memset(r->pre_of, 0, (size_t)g->tiles_x * (size_t)g->tiles_y * sizeof *r->pre_of);
    memset(r->pre_cells, 0, (size_t)r->pre_high * (POLYC__TILE_CELLS / 2));
    memset(r->pre_miss, 0, (size_t)r->pre_high * POLYC__PRE_BLOCKS * sizeof *r->pre_miss);
    r->pre_high = 0;
    r->pre_nfree = 0;
}

