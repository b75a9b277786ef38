/* angle_prior.c - the angle prior p(turn | x, y) of the paper's eq. (2), section IV.
 * Takes: the stored scans and the grid's extent. Gives: per prior cell (one per
 * 32 x 32 grid tile) a histogram of turn angles between lines fitted in single scans.
 *
 * Learning (polyc__prior_build, the pass in prior_learn.c). For every scan, the hits (min_m <= r < max_m),
 * in beam order, are cut into clusters of consecutive hits; a cluster breaks at a
 * beam that is not a hit or where two consecutive endpoints are more than
 * GAP_M + GAP_STEPS * r * |step| apart (r the larger of the two ranges); the
 * first and last beams of a 360 degree scan are not joined.
 * Each cluster is cut into lines by split-and-merge: iterative end-point fit,
 * splitting an interval at its farthest point when that point is more than
 * TOL_M + TOL_REL * r off the chord (explicit stack, depth <= MAX_DEPTH); an
 * interval still off at that depth is rejected. A line is kept when it has at
 * least MIN_POINTS points and its chord is at least MIN_LEN_M long; adjacent kept
 * lines whose union passes the chord test are merged; each line's direction is
 * refined by a principal-axis (least-squares) fit of its points. Observations:
 *  - corner: two kept lines of a cluster that share their split point give the
 *    turn angle between their directions (0 = straight on, pi = folding back),
 *    recorded at the split point's endpoint with weight CORNER_COUNT = 8;
 *  - straight: every kept line gives turn 0, weight 1, at n = max(1, floor(L /
 *    STRAIGHT_M)) points spread evenly along its fitted extent L.
 * A corner weighs as much as 2 m of straight evidence: a scan that sees a corner
 * also leaves about that much straight evidence of its two walls within reach of
 * the query's 3 x 3 cells, so at a corner its angle holds about half the mass,
 * while along a wall turn 0 holds nearly all of it.
 * Bin b of a cell counts observations whose turn is nearest to b * 10 degrees
 * (b = 0..17; bin 17 takes 165..180 degrees). A counter that would pass 65535
 * halves all 18 counters of its cell first (the shares are kept).
 *
 * Query (polyc__prior_p), the formula:
 *   C_b  = sum_j w_j c_j[b]   over the cell j0 containing (x, y) and its 8
 *          neighbours (cells outside the grid contribute nothing), w = 4 for the
 *          centre, 2 for the 4 edge neighbours, 1 for the 4 corner neighbours;
 *   N    = sum_b C_b          (kept per cell, so no 18-bin loop at query time);
 *   u    = turn / 10 degrees  (turn clamped to [0, pi], u to [0, 17]), k = round(u),
 *          d = u - k in [-0.5, 0.5];
 *   K    = triangular kernel of half-width 1.5 bins: K_{k-1} = 0.5 - d,
 *          K_k = 1.5 - |d|, K_{k+1} = 0.5 + d (terms for bins outside 0..17 dropped),
 *          S = sum of the K used;
 *   p    = (sum_b K_b (C_b + EPS)) / (S * (N + 18 * EPS)),   EPS = 1 (pseudo-count).
 * p is the kernel-weighted average over the bins next to `turn` of the smoothed
 * share (C_b + EPS) / (N + 18 EPS): the share of the observations near (x, y)
 * whose turn angle is within about 10 degrees of `turn`. It lies in (0, 1),
 * is continuous in turn and never 0. Where there is no evidence (no observation
 * within one cell, outside the grid, empty prior, NaN position) every share is
 * 1/18, so p = 1/18 for every angle: a uniform prior, which leaves the choice of
 * angles there to the data term.
 *
 * Memory: per cell a uint32 (row_of: 1 + its row, 0 without evidence); a row
 * of 18 uint16 counters (p->hist) and a uint32 total per cell with evidence,
 * rows handed out in the order cells get their first observation. The budget
 * is a row for every cell; what is not used is given back to the block after
 * learning. (Dense rows for every cell would be zeroed, summed and smoothed
 * cell by cell: a single long-range scan's extent holds a hundred times the
 * cells its returns touch, and those passes were a visible share of its
 * time.) The prior grid is the tile grid; if that grid has more cells than
 * polyc__prior_bytes allows for (a long diagonal extent under a tight
 * limits.max_grid_cells), prior cells are made K x K tiles for the
 * smallest K that fits. */
#include "../context.h"

#include <math.h>
#include <string.h>

#define BINS POLYC__ANGLE_BINS
#define BINS_PER_RAD POLYC__BINS_PER_RAD

#define EPS 1.0f                    /* pseudo-count per bin, in centre-weight / 4 units */

/* Cells the prior may have: the bound grid.c puts on its directory when the
 * extent is within 4x the tile budget. */
static size_t cell_cap(const polyc_limits *lim)
{
    size_t tiles = ((size_t)lim->max_grid_cells + POLYC__TILE_CELLS - 1) / POLYC__TILE_CELLS;
    return tiles * 4 + 64;
}

/* The split-and-merge visits each endpoint several times: a scan of up to
 * this many beams has its endpoints computed once, into a scratch block that
 * is released after learning (a longer scan computes them on every visit,
 * with the same result). */
#define CACHE_BEAMS 1081u

static uint32_t cache_beams(const polyc_limits *lim)
{
    return lim->max_beams < CACHE_BEAMS ? lim->max_beams : CACHE_BEAMS;
}

/* The allocations of polyc__prior_build, in its order: per cell its row;
 * the rows (a budget of one a cell, the unused ones given back after
 * learning); the endpoint cache; per row its total. */
static uint32_t *row_index(polyc__arena *a, size_t cells)
{
    return polyc__alloc_zero(a, cells, sizeof(uint32_t));
}
static uint16_t *row_counts(polyc__arena *a, size_t rows)
{
    return polyc__alloc(a, rows, BINS * sizeof(uint16_t));
}
static float *endpoint_cache(polyc__arena *a, size_t beams)
{
    return polyc__alloc(a, beams, 3 * sizeof(float));
}
static uint32_t *row_totals(polyc__arena *a, size_t rows)
{
    return polyc__alloc(a, rows, sizeof(uint32_t));
}

void polyc__prior_reserve(polyc__arena *a, const polyc_limits *lim)
{
    size_t cells = cell_cap(lim);
    polyc__prior p;
    polyc__acc_learn acc;
    memset(&p, 0, sizeof p);
    p.w = (int32_t)cells;
    p.h = 1;
    row_index(a, cells);
    polyc__accuracy_begin(&acc, &p, a, lim);
    size_t rows_at = a->used;
    row_counts(a, cells);
    endpoint_cache(a, cache_beams(lim));
    polyc__accuracy_scratch(&acc, a, lim);
    polyc__accuracy_reserve_finish(&acc, a);
    a->used = rows_at + polyc__bytes(cells, BINS * sizeof(uint16_t));
    row_totals(a, cells);
}

size_t polyc__prior_bytes(const polyc_limits *lim)
{
    polyc__arena a;
    polyc__arena_counting(&a);
    polyc__prior_reserve(&a, lim);
    return a.peak;
}

/* ---- the table ---- */

/* Neighbour k (0..8) of cell (cx, cy) in the 3 x 3 smoothing: its index
 * and weight (4 itself, 2 beside, 1 diagonal); 0 when outside the cells. */
static int neighbour(const polyc__prior *p, int32_t cx, int32_t cy, int k, size_t *cell,
                     uint32_t *w)
{
    int32_t i = k % 3 - 1, j = k / 3 - 1, ix = cx + i, iy = cy + j;
    if (ix < 0 || iy < 0 || ix >= p->w || iy >= p->h)
        return 0;
    *cell = (size_t)iy * (size_t)p->w + (size_t)ix;
    *w = (uint32_t)(4 >> ((i != 0) + (j != 0)));
    return 1;
}

/* Scatters each cell with evidence into the 3 x 3 cells around it, with the
 * weights smoothed() gathers them with (they are symmetric): the same sums
 * of integers. Rows only for the cells that get some: a first pass hands
 * them out, and the table is built only if they fit in `room` bytes. */
static void smooth_table(polyc__prior *p, polyc__arena *a, size_t room)
{
    size_t cells = (size_t)p->w * (size_t)p->h, mark = a->used;
    if (p->rows == 0 || polyc__bytes(cells, sizeof(uint32_t)) > room)
        return;
    uint32_t *of = polyc__alloc_zero(a, cells, sizeof(uint32_t));
    if (!of)
        return;
    uint32_t n = 0;
    for (int32_t cy = 0; cy < p->h; cy++)
        for (int32_t cx = 0; cx < p->w; cx++) {
            size_t nb;
            uint32_t w;
            if (p->row_of[(size_t)cy * (size_t)p->w + (size_t)cx] == 0)
                continue;
            for (int k = 0; k < 9; k++)
                if (neighbour(p, cx, cy, k, &nb, &w) && of[nb] == 0)
                    of[nb] = ++n;
        }
    size_t need = polyc__add(polyc__bytes(cells, sizeof(uint32_t)),
                             polyc__bytes(n, (BINS + 1) * sizeof(uint32_t)));
    uint32_t *t = need <= room ? polyc__alloc_zero(a, n, (BINS + 1) * sizeof(uint32_t)) : NULL;
    if (!t) {
        a->used = mark; /* no table: queries sum the 3 x 3 cells */
        return;
    }
    for (int32_t cy = 0; cy < p->h; cy++)
        for (int32_t cx = 0; cx < p->w; cx++) {
            size_t c = (size_t)cy * (size_t)p->w + (size_t)cx, nb;
            uint32_t w, r = p->row_of[c];
            if (r == 0)
                continue;
            const uint16_t *h = p->hist + (size_t)(r - 1) * BINS;
            for (int k = 0; k < 9; k++) {
                if (!neighbour(p, cx, cy, k, &nb, &w))
                    continue;
                uint32_t *to = t + (size_t)(of[nb] - 1) * (BINS + 1);
                for (int b = 0; b < BINS; b++)
                    to[b] += w * h[b];
                to[BINS] += w * p->total[r - 1];
            }
        }
    p->smooth_of = of;
    p->smooth = t;
}

/* The prior's cells on the grid: K x K tiles, K = 1 unless the tile grid
 * has more than `cap` tiles. */
static void lay_out(const polyc_ctx *ctx, polyc__prior *p, uint64_t cap)
{
    const polyc__grid *g = &ctx->grid;
    uint64_t tx = (uint64_t)g->tiles_x, ty = (uint64_t)g->tiles_y, k = 1;
    while (((tx + k - 1) / k) * ((ty + k - 1) / k) > cap)
        k++;
    p->w = (int32_t)((tx + k - 1) / k);
    p->h = (int32_t)((ty + k - 1) / k);
    p->cell_m = g->cell_m * (float)POLYC__TILE_SIDE * (float)k;
    p->inv_cell = 1.0f / p->cell_m;
    p->origin_x = g->frame_ox;
    p->origin_y = g->frame_oy;
}

/* per row, the sum of its counts */
static void sum_rows(polyc__prior *p)
{
    for (uint32_t r = 0; r < p->rows; r++) {
        uint32_t n = 0;
        for (int b = 0; b < BINS; b++)
            n += p->hist[(size_t)r * BINS + (size_t)b];
        p->total[r] = n;
    }
}

polyc_status polyc__prior_build(polyc_ctx *ctx, polyc__prior *p, size_t spare)
{
    const polyc__grid *g = &ctx->grid;
    memset(p, 0, sizeof *p);
    if (g->width <= 0 || g->height <= 0 || g->tiles_x <= 0 || g->tiles_y <= 0)
        return POLYC_OK; /* no data: an empty prior, uniform everywhere */
    lay_out(ctx, p, (uint64_t)cell_cap(&ctx->lim));
    size_t cells = (size_t)p->w * (size_t)p->h;
    p->row_of = row_index(&ctx->arena, cells);
    polyc__acc_learn acc;
    if (!p->row_of || !polyc__accuracy_begin(&acc, p, &ctx->arena, &ctx->lim)) {
        memset(p, 0, sizeof *p);
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the angle prior");
    }
    size_t rows_at = ctx->arena.used;
    p->hist = p->row_of ? row_counts(&ctx->arena, cells) : NULL;
    if (!p->hist) {
        memset(p, 0, sizeof *p);
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the angle prior");
    }

    uint32_t cache_cap = cache_beams(&ctx->lim);
    float *cache = endpoint_cache(&ctx->arena, cache_cap);
    polyc__acc_learn *learn_acc =
        polyc__accuracy_scratch(&acc, &ctx->arena, &ctx->lim) && acc.p ? &acc : NULL;
    polyc__prior_learn(ctx, p, cache, cache_cap, learn_acc);
    if (learn_acc)
        polyc__accuracy_finish(&acc, &ctx->arena, ctx->cfg.alpha);
    /* the rows not handed out go back to the block (the cache is gone too) */
    ctx->arena.used = rows_at + polyc__bytes(p->rows, BINS * sizeof(uint16_t));
    p->total = row_totals(&ctx->arena, p->rows);
    if (!p->total && p->rows > 0) { /* cannot happen: the rows' budget held them */
        memset(p, 0, sizeof *p);
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the angle prior");
    }
    sum_rows(p);
    /* the table only where the block has room beyond the budget: the
     * library's footprint stays what polyc_memory_size says */
    size_t free_bytes = ctx->arena.size - ctx->arena.used;
    if (free_bytes > spare)
        smooth_table(p, &ctx->arena, free_bytes - spare);
    return POLYC_OK;
}

/* Online, the prior is laid out once over the grid (the area) with a row
 * for every cell, learned scan by scan (polyc__prior_learn_scan, which
 * keeps the rows' totals) and queried without the smoothed table. */
int polyc__prior_online(const polyc_ctx *ctx, polyc__prior *p, polyc__acc_learn *acc,
                        polyc__arena *a)
{
    memset(p, 0, sizeof *p);
    lay_out(ctx, p, (uint64_t)cell_cap(&ctx->lim));
    size_t cells = (size_t)p->w * (size_t)p->h;
    p->row_of = row_index(a, cells);
    p->hist = row_counts(a, cells);
    p->total = row_totals(a, cells);
    return p->row_of && p->hist && p->total && polyc__accuracy_begin(acc, p, a, &ctx->lim) &&
           polyc__accuracy_online(acc, a, ctx->cfg.alpha);
}

void polyc__prior_forget(polyc__prior *p)
{
    if (p->hist)
        memset(p->hist, 0, (size_t)p->rows * BINS * sizeof(uint16_t));
    if (p->total)
        memset(p->total, 0, (size_t)p->rows * sizeof(uint32_t));
    p->corners = p->straights = 0;
}

/* ---- query (the optimiser's hot loop: no trigonometry, 9 cells x 3 bins) ---- */

/* The cell of (x, y), or 0 if there is no evidence within a cell of it
 * (outside the grid, NaN, no prior): there p is uniform. */
static int cell_of(const polyc__prior *p, float x, float y, int32_t *cx, int32_t *cy)
{
    if (p->w <= 0 || p->h <= 0 || !p->row_of)
        return 0;
    float fx = (x - (float)p->origin_x) * p->inv_cell;
    float fy = (y - (float)p->origin_y) * p->inv_cell;
    /* more than a cell outside (or NaN): no neighbour inside either */
    if (!(fx >= -1.0f && fy >= -1.0f && fx < (float)p->w + 1.0f && fy < (float)p->h + 1.0f))
        return 0;
    *cx = polyc__floori(fx);
    *cy = polyc__floori(fy);
    return 1;
}

/* The kernel around `turn`: bins k-1, k, k+1 and their weights (0 for a
 * bin outside 0..17, which then repeats k). */
static void kernel(float turn_rad, int *b, float *kw)
{
    float u = turn_rad * BINS_PER_RAD;
    if (!(u > 0.0f)) /* also NaN */
        u = 0.0f;
    if (u > (float)(BINS - 1))
        u = (float)(BINS - 1);
    int k = (int)(u + 0.5f);
    float d = u - (float)k;
    b[0] = k > 0 ? k - 1 : k;
    b[1] = k;
    b[2] = k < BINS - 1 ? k + 1 : k;
    kw[0] = k == 0 ? 0.0f : 0.5f - d;
    kw[1] = 1.5f - fabsf(d);
    kw[2] = k == BINS - 1 ? 0.0f : 0.5f + d;
}

/* p from the smoothed counts of the kernel's bins (cnt indexed by bin). */
static float share(const int *b, const float *kw, const uint32_t *cnt, uint32_t n)
{
    float num = kw[0] * ((float)cnt[b[0]] + EPS) + kw[1] * ((float)cnt[b[1]] + EPS) +
                kw[2] * ((float)cnt[b[2]] + EPS);
    float pr = num / ((kw[0] + kw[1] + kw[2]) * ((float)n + (float)BINS * EPS));
    return pr < 1.0f ? pr : 1.0f;
}

/* C_b for the nb bins listed (distinct) and N at cell (cx, cy): 3 x 3
 * cells, weights 4/2/1; cnt is indexed by bin. */
static void smoothed(const polyc__prior *p, int32_t cx, int32_t cy, const int *bins, int nb,
                     uint32_t *cnt, uint32_t *n)
{
    if (p->smooth && cx >= 0 && cy >= 0 && cx < p->w && cy < p->h) {
        uint32_t r = p->smooth_of[(size_t)cy * (size_t)p->w + (size_t)cx];
        const uint32_t *t = p->smooth + (size_t)(r > 0 ? r - 1 : 0) * (BINS + 1);
        for (int k = 0; k < nb; k++)
            cnt[bins[k]] = r > 0 ? t[bins[k]] : 0;
        *n = r > 0 ? t[BINS] : 0;
        return;
    }
    for (int k = 0; k < nb; k++)
        cnt[bins[k]] = 0;
    *n = 0;
    /* the 3 x 3 cells as neighbour() gives them, row by row */
    for (int32_t j = -1; j <= 1; j++) {
        int32_t iy = cy + j;
        if (iy < 0 || iy >= p->h)
            continue;
        const uint32_t *row = p->row_of + (size_t)iy * (size_t)p->w;
        for (int32_t i = -1; i <= 1; i++) {
            int32_t ix = cx + i;
            if (ix < 0 || ix >= p->w || row[ix] == 0)
                continue;
            uint32_t w = (uint32_t)(4 >> ((i != 0) + (j != 0))), r = row[ix] - 1;
            const uint16_t *h = p->hist + (size_t)r * BINS;
            if (nb == BINS) /* all bins, in order: a loop the compiler vectorises */
                for (int b = 0; b < BINS; b++)
                    cnt[b] += w * h[b];
            else
                for (int q = 0; q < nb; q++)
                    cnt[bins[q]] += w * h[bins[q]];
            *n += w * p->total[r];
        }
    }
}

void polyc__prior_at(const polyc__prior *p, float x, float y, polyc__prior_place *at)
{
    static const int ALL[BINS] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17};
    at->valid = cell_of(p, x, y, &at->cx, &at->cy);
    if (at->valid)
        smoothed(p, at->cx, at->cy, ALL, BINS, at->c, &at->n);
}

int polyc__prior_same_place(const polyc__prior *p, const polyc__prior_place *at, float x, float y)
{
    int32_t cx, cy;
    int valid = cell_of(p, x, y, &cx, &cy);
    return valid == at->valid && (!valid || (cx == at->cx && cy == at->cy));
}

const uint16_t *polyc__prior_counts(const polyc__prior *p, int32_t cx, int32_t cy)
{
    if (!p->row_of || cx < 0 || cy < 0 || cx >= p->w || cy >= p->h)
        return NULL;
    uint32_t r = p->row_of[(size_t)cy * (size_t)p->w + (size_t)cx];
    return r > 0 ? p->hist + (size_t)(r - 1) * BINS : NULL;
}

float polyc__prior_p_at(const polyc__prior_place *at, float turn_rad)
{
    int b[3];
    float kw[3];
    if (!at->valid)
        return 1.0f / (float)BINS;
    kernel(turn_rad, b, kw);
    return share(b, kw, at->c, at->n);
}

float polyc__prior_p(const polyc__prior *p, float x, float y, float turn_rad)
{
    int32_t cx, cy;
    int b[3];
    float kw[3];
    if (!cell_of(p, x, y, &cx, &cy))
        return 1.0f / (float)BINS;
    kernel(turn_rad, b, kw);
    /* only the kernel's (distinct) bins */
    int distinct[3], nd = 0;
    for (int k = 0; k < 3; k++)
        if (k == 0 || b[k] != b[k - 1])
            distinct[nd++] = b[k];
    uint32_t cnt[BINS], n;
    smoothed(p, cx, cy, distinct, nd, cnt, &n);
    return share(b, kw, cnt, n);
}
