/* trace.c - initial polylines from the contour (paper section III, step 3).
 * Takes: contour cells (8-connected), thinned to one cell. Gives: polylines
 * in the store, started at contour endpoints, then the remaining cycles; points whose removal
 * leaves the polyline's length unchanged (collinear, in cell units) dropped. */
#include "../context.h"

#include <math.h>
#include <string.h>

static const int32_t NB_X[8] = {1, 0, -1, 0, 1, -1, -1, 1}; /* 4-neighbours first */
static const int32_t NB_Y[8] = {0, 1, 0, -1, 1, 1, -1, -1};

static int unvisited(const polyc__grid *g, int32_t ix, int32_t iy)
{
    const polyc__tile *t = polyc__grid_tile(g, ix, iy);
    return t && ((t->mark[iy & 31] >> (ix & 31)) & 1u);
}

static void set_visited(const polyc__grid *g, int32_t ix, int32_t iy)
{
    polyc__tile *t = polyc__grid_tile(g, ix, iy);
    t->mark[iy & 31] &= ~(1u << (ix & 31));
}

static int contour_degree(const polyc__grid *g, int32_t ix, int32_t iy)
{
    int d = 0;
    for (int k = 0; k < 8; k++) {
        const polyc__tile *t = polyc__grid_tile(g, ix + NB_X[k], iy + NB_Y[k]);
        int32_t x = ix + NB_X[k], y = iy + NB_Y[k];
        d += t && ((t->contour[y & 31] >> (x & 31)) & 1u);
    }
    return d;
}

static int unvisited_degree(const polyc__grid *g, int32_t ix, int32_t iy)
{
    int d = 0;
    for (int k = 0; k < 8; k++)
        d += unvisited(g, ix + NB_X[k], iy + NB_Y[k]);
    return d;
}

/* The next cell of a walk: an unvisited neighbour, 4-neighbours before
 * diagonal ones, and among those the one with the fewest unvisited
 * neighbours of its own (it keeps the walk on the rim of thick contours).
 * From the end of a chain (a contour cell with at most one contour
 * neighbour) the walk continues to the nearest unvisited chain end within
 * link_radius: sparse data (far walls, single scans) leave gaps as wide as
 * the beam spacing there. Cells inside dense chains are never jumped to. */
typedef struct tracer {
    const polyc__grid *g;
    polyc__spacing spacing;
    float ox, oy;                 /* frame-relative grid origin */
    int32_t link;                  /* cells: the merge distance */
    int32_t link_max;              /* cells: the widest gap bridged in sparse data */
} tracer;

/* Gap to bridge from a chain end: 2.5 beam spacings there, at least the
 * merge distance, at most link_max. */
static int32_t link_radius(const tracer *tr, int32_t ix, int32_t iy)
{
    const polyc__grid *g = tr->g;
    float x = (float)(tr->ox + ((float)ix + 0.5f) * (float)g->cell_m);
    float y = (float)(tr->oy + ((float)iy + 0.5f) * (float)g->cell_m);
    float cells = POLYC__GAP_SPACINGS * polyc__spacing_at(&tr->spacing, x, y) * g->inv_cell;
    int32_t r = cells > (float)tr->link_max ? tr->link_max : (int32_t)cells;
    return r > tr->link ? r : tr->link;
}

static int next_cell(const tracer *tr, int32_t ix, int32_t iy, int32_t *nx, int32_t *ny)
{
    const polyc__grid *g = tr->g;
    for (int pass = 0; pass < 2; pass++) {
        int best = 99;
        for (int k = pass * 4; k < pass * 4 + 4; k++) {
            int32_t cx = ix + NB_X[k], cy = iy + NB_Y[k];
            if (!unvisited(g, cx, cy))
                continue;
            int d = unvisited_degree(g, cx, cy);
            if (d < best) {
                best = d;
                *nx = cx;
                *ny = cy;
            }
        }
        if (best < 99)
            return 1;
    }
    if (contour_degree(g, ix, iy) > 1)
        return 0; /* inside a dense contour: no jumps */
    int32_t link = link_radius(tr, ix, iy);
    int32_t best2 = link * link + 1;
    for (int32_t dy = -link; dy <= link; dy++)
        for (int32_t dx = -link; dx <= link; dx++) {
            int32_t d2 = dx * dx + dy * dy;
            if (d2 >= best2 || d2 <= 2 || !unvisited(g, ix + dx, iy + dy) ||
                contour_degree(g, ix + dx, iy + dy) > 1)
                continue;
            best2 = d2;
            *nx = ix + dx;
            *ny = iy + dy;
        }
    return best2 <= link * link;
}

/* ---- thinning (Zhang-Suen) of the cells to trace ----
 * Pose errors and range noise make contours two or three cells thick; a
 * walk along such a band goes back and forth and leaves overlapping
 * pieces. Thinning the band to one cell first gives clean chains. */

static int mark_at(const polyc__grid *g, int32_t ix, int32_t iy)
{
    return unvisited(g, ix, iy);
}

/* p2..p9: N, NE, E, SE, S, SW, W, NW */
static const int32_t ZS_X[8] = {0, 1, 1, 1, 0, -1, -1, -1};
static const int32_t ZS_Y[8] = {1, 1, 0, -1, -1, -1, 0, 1};

static int zs_deletable(const polyc__grid *g, int32_t ix, int32_t iy, int sub)
{
    int p[8], b = 0, a = 0;
    for (int k = 0; k < 8; k++) {
        p[k] = mark_at(g, ix + ZS_X[k], iy + ZS_Y[k]);
        b += p[k];
    }
    for (int k = 0; k < 8; k++)
        a += !p[k] && p[(k + 1) & 7];
    if (b < 2 || b > 6 || a != 1)
        return 0;
    /* p2 = N (0), p4 = E (2), p6 = S (4), p8 = W (6) */
    if (sub == 0)
        return !(p[0] && p[2] && p[4]) && !(p[2] && p[4] && p[6]);
    return !(p[0] && p[2] && p[6]) && !(p[0] && p[4] && p[6]);
}

static void thin(const polyc_ctx *ctx, const int32_t *xy, uint32_t count, int32_t *del, uint32_t cap)
{
    const polyc__grid *g = &ctx->grid;
    for (int changed = 1; changed;) {
        changed = 0;
        for (int sub = 0; sub < 2; sub++) {
            uint32_t n = 0;
            for (uint32_t i = 0; i < count && n < cap; i++) {
                int32_t ix = xy[2 * i], iy = xy[2 * i + 1];
                if (mark_at(g, ix, iy) && zs_deletable(g, ix, iy, sub))
                    del[n++] = (int32_t)i;
            }
            for (uint32_t k = 0; k < n; k++)
                set_visited(g, xy[2 * del[k]], xy[2 * del[k] + 1]);
            changed |= n > 0;
        }
    }
}

typedef struct walk {
    int32_t *xy;     /* scratch: cells of the current walk, 2 per cell */
    uint32_t n, cap;
} walk;

static void walk_from(const tracer *tr, walk *w, int32_t ix, int32_t iy)
{
    while (w->n < w->cap) {
        w->xy[2 * w->n] = ix;
        w->xy[2 * w->n + 1] = iy;
        w->n++;
        set_visited(tr->g, ix, iy);
        if (!next_cell(tr, ix, iy, &ix, &iy))
            break;
    }
}

static void reverse_cells(int32_t *xy, uint32_t n)
{
    for (uint32_t i = 0, j = n - 1; i < j; i++, j--) {
        int32_t tx = xy[2 * i], ty = xy[2 * i + 1];
        xy[2 * i] = xy[2 * j];
        xy[2 * i + 1] = xy[2 * j + 1];
        xy[2 * j] = tx;
        xy[2 * j + 1] = ty;
    }
}

/* b lies on segment a-c: removing it does not change the length. */
static int redundant(const int32_t *a, const int32_t *b, const int32_t *c)
{
    int64_t ux = b[0] - a[0], uy = b[1] - a[1];
    int64_t vx = c[0] - b[0], vy = c[1] - b[1];
    return ux * vy - uy * vx == 0 && ux * vx + uy * vy >= 0;
}

/* Douglas-Peucker with a tolerance of half a cell, in place: on walls that
 * are not grid-aligned the walk is a staircase whose steps are pure
 * discretisation (the paper's length rule removes them only on aligned
 * walls). Explicit stack: no recursion; a full stack keeps the rest. */
#define DP_STACK 48
static uint32_t simplify(int32_t *xy, uint32_t n)
{
    if (n < 3)
        return n;
    uint32_t lo[DP_STACK], hi[DP_STACK];
    int top = 0;
    lo[0] = 0;
    hi[0] = n - 1;
    top = 1;
    /* keep[i]: the x of a dropped point is set to INT32_MIN below */
    while (top > 0) {
        top--;
        uint32_t a = lo[top], b = hi[top];
        if (b <= a + 1)
            continue;
        /* cell steps: integer differences, exact as floats below 2^24 */
        int32_t ax = xy[2 * a], ay = xy[2 * a + 1];
        float dx = (float)(xy[2 * b] - ax), dy = (float)(xy[2 * b + 1] - ay);
        float len = sqrtf(dx * dx + dy * dy);
        float worst = -1.0f;
        uint32_t at = a;
        for (uint32_t i = a + 1; i < b; i++) {
            float px = (float)(xy[2 * i] - ax), py = (float)(xy[2 * i + 1] - ay);
            float d = len > 0.0f ? fabsf(px * dy - py * dx) / len : sqrtf(px * px + py * py);
            if (d > worst) {
                worst = d;
                at = i;
            }
        }
        if (worst <= 0.5f || top + 2 > DP_STACK) {
            if (worst <= 0.5f)
                for (uint32_t i = a + 1; i < b; i++)
                    xy[2 * i] = INT32_MIN;
            continue;
        }
        lo[top] = a;
        hi[top++] = at;
        lo[top] = at;
        hi[top++] = b;
    }
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; i++) {
        if (xy[2 * i] == INT32_MIN)
            continue;
        xy[2 * m] = xy[2 * i];
        xy[2 * m + 1] = xy[2 * i + 1];
        m++;
    }
    return m;
}

/* A walk on none but the contour's data cells (contour.c: returns no
 * occupied cell explains) that spans less than this (the larger side of
 * its cells' bounding box) is not traced: a chair, a person who stood still
 * for a while (a ring round a standing person, 0.4 m across, is a longer
 * walk than that: with the walk's length as the measure it was traced, a
 * line far off every wall). A wall seen at grazing angles is longer. */
#define DATA_ONLY_MIN_M 0.5f

/* Whether the walk holds no occupied cell and spans less than
 * DATA_ONLY_MIN_M. */
static int short_data_only(const polyc_ctx *ctx, const walk *w)
{
    const polyc__grid *g = &ctx->grid;
    int32_t x0 = INT32_MAX, y0 = INT32_MAX, x1 = INT32_MIN, y1 = INT32_MIN;
    for (uint32_t i = 0; i < w->n; i++) {
        int32_t ix = w->xy[2 * i], iy = w->xy[2 * i + 1];
        const polyc__tile *t = polyc__grid_tile(g, ix, iy);
        if (t && polyc__cell_occupied(t, polyc__cell_index(ix, iy), ctx->cfg.contour_threshold))
            return 0;
        x0 = ix < x0 ? ix : x0;
        x1 = ix > x1 ? ix : x1;
        y0 = iy < y0 ? iy : y0;
        y1 = iy > y1 ? iy : y1;
    }
    int32_t span = (x1 - x0 > y1 - y0 ? x1 - x0 : y1 - y0) + 1;
    return (float)span * g->cell_m < DATA_ONLY_MIN_M;
}

static polyc_status emit(polyc_ctx *ctx, walk *w, int closed)
{
    const polyc__grid *g = &ctx->grid;
    polyc__store *s = &ctx->store;
    if (w->n < 2 || short_data_only(ctx, w))
        return POLYC_OK; /* a lone cell gives no segment */
    /* drop redundant points in place */
    uint32_t m = 1;
    for (uint32_t i = 1; i < w->n; i++) {
        int is_last = i + 1 == w->n;
        if (!is_last && redundant(&w->xy[2 * (m - 1)], &w->xy[2 * i], &w->xy[2 * (i + 1)]))
            continue;
        w->xy[2 * m] = w->xy[2 * i];
        w->xy[2 * m + 1] = w->xy[2 * i + 1];
        m++;
    }
    if (closed && m >= 4) {
        /* the joins of a cycle: last-first-second, and second-last-last-first */
        if (redundant(&w->xy[2 * (m - 1)], &w->xy[0], &w->xy[2])) {
            memmove(w->xy, w->xy + 2, (size_t)(m - 1) * 2 * sizeof(int32_t));
            m--;
        }
        if (m >= 4 && redundant(&w->xy[2 * (m - 2)], &w->xy[2 * (m - 1)], &w->xy[0]))
            m--;
    }
    m = simplify(w->xy, m);
    if (closed && m < 3)
        closed = 0;
    int32_t l = polyc__line_new(s);
    if (l == POLYC__NONE)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "too many polylines for limits.max_vertices");
    /* store coordinates relative to the frame (first pose) */
    float ox = g->frame_ox, oy = g->frame_oy;
    for (uint32_t i = 0; i < m; i++) {
        float x = (float)(ox + ((float)w->xy[2 * i] + 0.5f) * (float)g->cell_m);
        float y = (float)(oy + ((float)w->xy[2 * i + 1] + 0.5f) * (float)g->cell_m);
        if (polyc__vertex_append(s, l, x, y) == POLYC__NONE)
            return polyc__fail(ctx, POLYC_ERR_NOMEM, "too many vertices for limits.max_vertices");
    }
    if (closed)
        polyc__line_close(s, l);
    return POLYC_OK;
}

static int adjacent(const int32_t *a, const int32_t *b, int32_t link)
{
    int32_t dx = a[0] - b[0], dy = a[1] - b[1];
    return dx * dx + dy * dy <= (link > 1 ? link * link : 2);
}

/* the walk's cells: the contour's and one more */
static int32_t *walk_cells(polyc__arena *a, uint32_t cap)
{
    return polyc__alloc(a, (size_t)cap * 2, sizeof(int32_t));
}

void polyc__trace_reserve(polyc__arena *a, const polyc_limits *lim)
{
    polyc__store_reserve(a, lim);
    size_t after_store = a->used;
    walk_cells(a, lim->max_beams + 2); /* the contour list holds max_beams + 1 */
    polyc__spacing_reserve(a, lim);
    a->used = after_store;
}

polyc_status polyc__trace_build(polyc_ctx *ctx)
{
    const polyc__grid *g = &ctx->grid;
    if (!polyc__store_init(&ctx->arena, &ctx->store, polyc__max_vertices(&ctx->lim)))
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the polylines");
    for (uint32_t k = 0; k < g->tile_count; k++)
        memcpy(g->tiles[k].mark, g->tiles[k].contour, sizeof g->tiles[k].mark);
    return polyc__trace_cells(ctx, ctx->contour_xy, ctx->contour_count);
}

polyc_status polyc__trace_cells(polyc_ctx *ctx, const int32_t *xy, uint32_t count)
{
    const polyc__grid *g = &ctx->grid;
    polyc_status st;
    size_t after_store = ctx->arena.used; /* the walk scratch is released at the end */
    walk w;
    w.cap = count + 1;
    w.n = 0;
    w.xy = walk_cells(&ctx->arena, w.cap);
    if (!w.xy)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for tracing");
    thin(ctx, xy, count, w.xy, w.cap); /* the walk buffer is free until the walks start */

    tracer tr;
    float link_f = ctx->cfg.merge_dist_m / g->cell_m;
    tr.g = g;
    tr.ox = g->frame_ox;
    tr.oy = g->frame_oy;
    tr.link = link_f < 1.0f ? 1 : (link_f > 8.0f ? 8 : (int32_t)link_f);
    tr.link_max = (int32_t)fminf(fmaxf(0.5f / g->cell_m, (float)tr.link), 32.0f);
    if ((st = polyc__spacing_build(ctx, &tr.spacing)) != POLYC_OK)
        return st;
    /* endpoints first (walking can create new ones: repeat until none), then
     * the rest, which are cycles or knots of them; each walk also goes
     * backwards from its start when cells are left on that side */
    for (int phase = 0; phase < 2; phase++) {
        int found = 1;
        while (found) {
            found = 0;
            for (uint32_t i = 0; i < count; i++) {
                int32_t ix = xy[2 * i], iy = xy[2 * i + 1];
                if (!unvisited(g, ix, iy) || (phase == 0 && unvisited_degree(g, ix, iy) > 1))
                    continue;
                w.n = 0;
                walk_from(&tr, &w, ix, iy);
                int closed = phase == 1 && w.n >= 4 && adjacent(&w.xy[0], &w.xy[2 * (w.n - 1)], tr.link);
                int32_t nx, ny;
                if (!closed && next_cell(&tr, ix, iy, &nx, &ny)) {
                    reverse_cells(w.xy, w.n);
                    walk_from(&tr, &w, nx, ny);
                }
                if ((st = emit(ctx, &w, closed)) != POLYC_OK)
                    return st;
                found = phase == 0;
            }
        }
    }
    ctx->arena.used = after_store;
    return POLYC_OK;
}
