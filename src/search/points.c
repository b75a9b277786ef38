/* points.c - the data points d_i of the BIC (paper eq. 2).
 * Takes: the grid and the scans. Gives: the reflected endpoints that fall in
 * a cell the grid judges not free, i.e. m >= data_min_m, as one weighted point
 * per block of 2 x 2 grid cells (count, mean, second moments: squared distances to a line
 * stay exact) or, with POLYC_FLAG_EXACT_POINTS, one point per endpoint;
 * sorted by spatial-hash bucket. */
#include "../optimize.h"

#include <math.h>
#include <string.h>

typedef struct endpoint {
    int32_t ix, iy;
    float fx, fy;                  /* offset from the cell centre, metres */
    float vx, vy;                  /* from the endpoint to its sensor, metres */
} endpoint;

static int endpoint_of(const polyc_ctx *ctx, const polyc__scan *s, uint32_t i, endpoint *e)
{
    polyc__beam b;
    if (!polyc__beam_path(ctx, s, i, &b) || !b.hit)
        return 0;
    float fx = floorf(b.ex), fy = floorf(b.ey);
    e->ix = (int32_t)fx;
    e->iy = (int32_t)fy;
    e->fx = (b.ex - fx - 0.5f) * ctx->grid.cell_m;
    e->fy = (b.ey - fy - 0.5f) * ctx->grid.cell_m;
    e->vx = (b.sx - b.ex) * ctx->grid.cell_m;
    e->vy = (b.sy - b.ey) * ctx->grid.cell_m;
    /* Data if the endpoint's own cell is not judged free. (A looser rule,
     * accepting points next to solid cells, lets people walking along walls
     * in: on a corridor their tracks became lines of their own, several
     * times the vertices the walls need.) */
    const polyc__tile *t = polyc__grid_tile(&ctx->grid, e->ix, e->iy);
    return t && polyc__cell_holds_data(t, polyc__cell_index(e->ix, e->iy), ctx->cfg.data_min_m);
}

static float cell_centre(float origin, int32_t i, float cell)
{
    return (float)(origin + ((float)i + 0.5f) * (float)cell);
}

/* The block of an endpoint (its lower-left cell) and the offset from the
 * block's centre. */
static void to_block(const endpoint *e, float cell, int32_t *bx, int32_t *by, float *fx, float *fy)
{
    const int32_t mask = ~(int32_t)(POLYC__BLOCK_SIDE - 1);
    const float half = 0.5f * (float)(POLYC__BLOCK_SIDE - 1);
    *bx = e->ix & mask;
    *by = e->iy & mask;
    *fx = e->fx + ((float)(e->ix - *bx) - half) * cell;
    *fy = e->fy + ((float)(e->iy - *by) - half) * cell;
}

/* One weighted point per marked block, from the endpoints. */
static polyc_status collect_cells(polyc__opt *o, polyc__point *tmp, float *view, int32_t cap,
                                  int32_t *n_out)
{
    polyc_ctx *ctx = o->ctx;
    polyc__grid *g = &ctx->grid;
    uint32_t n;
    polyc_status st = polyc__blocks_begin(ctx, tmp, view, cap, &n);
    if (st != POLYC_OK)
        return st;
    endpoint e;
    for (uint32_t si = 0; si < ctx->scan_count; si++)
        for (uint32_t i = 0; i < ctx->scans[si].count; i++) {
            if (!endpoint_of(ctx, &ctx->scans[si], i, &e))
                continue;
            int32_t bx, by;
            float fx, fy;
            to_block(&e, g->cell_m, &bx, &by, &fx, &fy);
            uint32_t at = polyc__block_number(polyc__grid_tile(g, e.ix, e.iy), bx, by); /* the block's tile too */
            polyc__point *p = &tmp[at];
            if (view) {
                view[2 * at] += e.vx;
                view[2 * at + 1] += e.vy;
            }
            /* sums of offsets from the block centre: small numbers, float is exact enough */
            p->w += 1.0f;
            p->x += fx;
            p->y += fy;
            p->cxx += fx * fx;
            p->cxy += fx * fy;
            p->cyy += fy * fy;
        }
    polyc__blocks_finish(ctx, tmp);
    *n_out = (int32_t)n;
    return POLYC_OK;
}

static polyc_status collect_raw(polyc__opt *o, polyc__point *tmp, float *view, int32_t cap,
                                int32_t *n_out)
{
    polyc_ctx *ctx = o->ctx;
    polyc__grid *g = &ctx->grid;
    float ox = g->frame_ox, oy = g->frame_oy;
    int32_t n = 0;
    endpoint e;
    for (uint32_t si = 0; si < ctx->scan_count; si++)
        for (uint32_t i = 0; i < ctx->scans[si].count; i++) {
            if (!endpoint_of(ctx, &ctx->scans[si], i, &e))
                continue;
            if (n >= cap)
                return polyc__fail(ctx, POLYC_ERR_NOMEM, "more data points than limits.max_points");
            polyc__point *p = &tmp[n++];
            memset(p, 0, sizeof *p);
            p->x = cell_centre(ox, e.ix, g->cell_m) + e.fx;
            p->y = cell_centre(oy, e.iy, g->cell_m) + e.fy;
            p->w = 1.0f;
            if (view) {
                view[2 * (n - 1)] = e.vx;
                view[2 * (n - 1) + 1] = e.vy;
            }
        }
    *n_out = n;
    return POLYC_OK;
}

/* An occupancy grid's data: one point at the centre of each occupied cell
 * that faces free space (a free cell at most POLYC__FACE_CELLS away along a
 * row or a column, only unknown cells between, as occupancy.c's contour),
 * weight 1. The other occupied
 * cells are inside a wall or behind one, not its surface: with them the
 * lines lie in the middle of the occupied bands a mapper leaves (1-3 cells),
 * half a cell or more behind the walls. The centre, not the side facing free
 * space: a hit's cell holds the wall anywhere across it, and its free side
 * lies half a cell in front of the wall on average. */
#define OCC_WEIGHT 1.0f

static int cell_class(const polyc__grid *g, int32_t ix, int32_t iy)
{
    const polyc__tile *t = polyc__grid_tile(g, ix, iy);
    if (!t)
        return 0; /* unknown */
    int k = polyc__cell_index(ix, iy);
    return t->hits[k] ? 2 : (t->misses[k] ? 1 : 0);
}

static polyc_status collect_occupied(polyc__opt *o, polyc__point *tmp, int32_t cap, int32_t *n_out)
{
    static const int8_t side[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    polyc_ctx *ctx = o->ctx;
    const polyc__grid *g = &ctx->grid;
    int32_t n = 0, dir_n = g->tiles_x * g->tiles_y;
    for (int32_t d = 0; d < dir_n; d++) {
        if (!g->dir[d])
            continue;
        const polyc__tile *t = &g->tiles[g->dir[d] - 1];
        int32_t tx = (d % g->tiles_x) << POLYC__TILE_SHIFT, ty = (d / g->tiles_x) << POLYC__TILE_SHIFT;
        for (int32_t k = 0; k < POLYC__TILE_CELLS; k++) {
            if (!t->hits[k])
                continue;
            int32_t ix = tx + (k & (POLYC__TILE_SIDE - 1)), iy = ty + (k >> POLYC__TILE_SHIFT);
            int faces = 0;
            for (int e = 0; e < 4 && !faces; e++)
                for (int step = 1; step <= POLYC__FACE_CELLS; step++) {
                    int a = cell_class(g, ix + step * side[e][0], iy + step * side[e][1]);
                    faces = a == 1;
                    if (a != 0)
                        break;
                }
            if (!faces)
                continue; /* inside or behind a wall */
            if (n >= cap)
                return polyc__fail(ctx, POLYC_ERR_NOMEM, "more data points than limits.max_points");
            polyc__point *p = &tmp[n++];
            memset(p, 0, sizeof *p);
            p->x = cell_centre(0.0f, ix, g->cell_m);
            p->y = cell_centre(0.0f, iy, g->cell_m);
            p->w = OCC_WEIGHT;
        }
    }
    *n_out = n;
    return POLYC_OK;
}

/* Where the scans disagree beyond the sensor's accuracy, their points
 * weigh less (accuracy.c); the BIC's n stays the count of endpoints. */
void polyc__point_weigh(const polyc__prior *prior, polyc__point *p)
{
    float f = polyc__accuracy_weight(prior, p->x, p->y);
    if (f < 1.0f) {
        p->w *= f;
        p->cxx *= f;
        p->cxy *= f;
        p->cyy *= f;
    }
}

int polyc__points_viewed(const polyc_ctx *ctx)
{
    return !ctx->from_grid && ctx->lim.max_scans > 1;
}

int32_t polyc__points_bound(const polyc_config *cfg, const polyc_limits *lim)
{
    uint32_t b = lim->max_points ? lim->max_points : lim->max_beams;
    if (!(cfg->flags & POLYC_FLAG_EXACT_POINTS) && lim->max_grid_cells < b)
        b = lim->max_grid_cells;
    return b > 0x3fffffffu ? 0x3fffffff : (int32_t)b;
}

/* The points and, with `viewed`, where they were seen from: a pair of
 * arrays of cap entries (the sorted ones first, the unsorted after them). */
static int points_carve(polyc__arena *a, int32_t cap, int viewed, polyc__point **pts, float **view)
{
    *pts = polyc__alloc(a, (size_t)cap, sizeof(polyc__point));
    *view = viewed ? polyc__alloc(a, (size_t)cap, 2 * sizeof(float)) : NULL;
    return *pts && (!viewed || *view);
}

/* The span of one weighted point: gaps between points shorter than it say
 * nothing (split); and how near a point supports the map. */
void polyc__points_spans(polyc__opt *o, int exact)
{
    const polyc_ctx *ctx = o->ctx;
    o->d.point_span_m = ctx->from_grid ? ctx->grid.cell_m
                      : exact        ? 0.0f
                                     : ctx->grid.cell_m * (float)POLYC__BLOCK_SIDE;
    o->d.support_m = polyc__maxf(POLYC__SUPPORT_M, o->d.point_span_m);
}

/* the points and their views carved once, for an optimiser that lives
 * across updates (a layer's, whose collect fills them) */
int polyc__points_carve_online(polyc__arena *a, polyc__opt *o)
{
    int32_t cap = polyc__points_bound(o->cfg, &o->ctx->lim);
    return points_carve(a, cap, 1, &o->d.pts, &o->d.pt_view);
}

void polyc__points_reserve(polyc__arena *a, const polyc_config *cfg, const polyc_limits *lim)
{
    polyc__point *pts;
    float *view;
    int32_t cap = polyc__points_bound(cfg, lim);
    points_carve(a, cap, lim->max_scans > 1, &pts, &view);
    size_t mark = a->used;
    points_carve(a, cap, lim->max_scans > 1, &pts, &view);
    a->used = mark;
}

polyc_status polyc__points_collect(polyc__opt *o)
{
    polyc_ctx *ctx = o->ctx;
    int32_t cap = polyc__points_bound(o->cfg, &ctx->lim);
    /* final array first, the unsorted one after it (released at the end);
     * where the endpoints were seen from: scans (more than one) only */
    int viewed = polyc__points_viewed(ctx);
    size_t mark = ctx->arena.used;
    polyc__points_in in = {NULL, NULL, NULL, NULL};
    int32_t n = 0;
    /* one scan: a point per return, whose beam the ends are set by (a
     * weighted point of several near returns would set them by their mean);
     * but a scan with more returns than the points bound (a dense scan
     * close to its walls: 100,000 beams round a full turn are 0.06 mm apart
     * at 1 m, hundreds of returns in a 2.5 cm cell) has its returns summed
     * by cell, as many scans' are */
    int exact = !ctx->layer && ((o->cfg->flags & POLYC_FLAG_EXACT_POINTS) ||
                                (o->rays.on && ctx->stats.hits <= (uint64_t)cap));
    polyc_status st;
    if (ctx->layer) { /* a layer's points: its data, its scratch (the points carved once) */
        st = ctx->layer->collect(o, cap, &in, &n);
    } else {
        int ok = points_carve(&ctx->arena, cap, viewed, &o->d.pts, &o->d.pt_view);
        mark = ctx->arena.used;
        if (!ok || !points_carve(&ctx->arena, cap, viewed, &in.pts, &in.view))
            return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the data points");
        st = ctx->from_grid ? collect_occupied(o, in.pts, cap, &n)
             : exact        ? collect_raw(o, in.pts, in.view, cap, &n)
                            : collect_cells(o, in.pts, in.view, cap, &n);
    }
    if (st != POLYC_OK)
        return st;
    polyc__point *tmp = in.pts;
    const float *tmp_view = in.view;
    /* counting sort by bucket: points of one bucket are contiguous */
    polyc__hash *h = &o->h;
    int32_t nb = h->bx * h->by;
    memset(h->pt_start, 0, ((size_t)nb + 1) * sizeof(uint32_t));
    float total = 0.0f;
    for (int32_t i = 0; i < n; i++) {
        h->pt_start[polyc__bucket_of(h, tmp[i].x, tmp[i].y) + 1]++;
        total += (float)tmp[i].w;
        polyc__point_weigh(&o->prior, &tmp[i]);
    }
    for (int32_t b = 0; b < nb; b++)
        h->pt_start[b + 1] += h->pt_start[b];
    for (int32_t i = 0; i < n; i++) {
        int32_t b = polyc__bucket_of(h, tmp[i].x, tmp[i].y);
        uint32_t at = h->pt_start[b]++;
        o->d.pts[at] = tmp[i];
        if (in.tag)
            in.tag_out[at] = in.tag[i];
        if (tmp_view) {
            o->d.pt_view[2 * at] = tmp_view[2 * i];
            o->d.pt_view[2 * at + 1] = tmp_view[2 * i + 1];
        }
    }
    for (int32_t b = nb; b > 0; b--)
        h->pt_start[b] = h->pt_start[b - 1];
    h->pt_start[0] = 0;
    ctx->arena.used = mark;
    o->d.np = n;
    o->d.n = total;
    polyc__points_spans(o, exact);
    ctx->stats.data_points = (uint32_t)total; /* (a count of returns, < 2^32) */
    ctx->stats.weighted_points = (uint32_t)n;
    return POLYC_OK;
}
