/* results.c - the entry points that read a context's results: the
 * polylines, the statistics, the grid and the last error. Takes: a context
 * after its stages. Gives: read-only views and copies (the polylines stay
 * the context's until its next stage or reset). */
#include "context.h"

#include <string.h>

uint32_t polyc_polyline_count(const polyc_ctx *ctx)
{
    if (polyc__check_ctx(ctx) != POLYC_OK || ctx->stage < POLYC__STAGE_TRACE)
        return 0;
    return ctx->flat.count;
}

polyc_status polyc_get_polyline(const polyc_ctx *ctx, uint32_t index, polyc_polyline *out)
{
    polyc_status cst = polyc__check_ctx(ctx);
    if (cst != POLYC_OK || !out)
        return cst != POLYC_OK ? cst : POLYC_ERR_NULL;
    if (ctx->stage < POLYC__STAGE_TRACE)
        return POLYC_ERR_STATE;
    if (index >= ctx->flat.count)
        return POLYC_ERR_RANGE;
    uint32_t a = ctx->flat.start[index];
    out->xy_m = ctx->flat.xy + 2 * a;
    out->point_count = ctx->flat.start[index + 1] - a;
    out->closed = ctx->flat.closed[index];
    return POLYC_OK;
}

polyc_status polyc_copy_polyline(const polyc_ctx *ctx, uint32_t index, float *xy_m,
                                 uint32_t capacity, uint32_t *count, uint32_t *closed)
{
    polyc_polyline pl;
    polyc_status st = polyc_get_polyline(ctx, index, &pl);
    if (st != POLYC_OK)
        return st;
    if (count)
        *count = pl.point_count;
    if (closed)
        *closed = pl.closed;
    if (xy_m) {
        if (capacity < pl.point_count)
            return POLYC_ERR_NOMEM;
        memcpy(xy_m, pl.xy_m, (size_t)pl.point_count * 2 * sizeof(float));
    }
    return POLYC_OK;
}

/* The circle that stands for the result's polyline `index`, or NULL. */
static const polyc__circle *circle_of(const polyc_ctx *ctx, uint32_t index)
{
    for (uint32_t k = 0; k < ctx->flat.circ_n; k++)
        if (ctx->flat.circ[k].line_id == ctx->flat.id[index])
            return &ctx->flat.circ[k];
    return NULL;
}

polyc_status polyc_get_circle(const polyc_ctx *ctx, uint32_t index, polyc_circle *out)
{
    polyc_polyline pl;
    polyc_status st = out ? polyc_get_polyline(ctx, index, &pl) : polyc__check_ctx(ctx);
    if (st != POLYC_OK || !out)
        return st != POLYC_OK ? st : POLYC_ERR_NULL;
    const polyc__circle *c = circle_of(ctx, index);
    memset(out, 0, sizeof *out);
    out->same_as = index;
    if (c) {
        polyc__frame_point_out(ctx, c->cx, c->cy, &out->center_x_m, &out->center_y_m);
        out->radius_m = c->r;
        out->polyline_dev_m = c->dev;
        for (uint32_t i = 0; i < ctx->flat.count; i++)
            if (ctx->flat.id[i] == c->first_id)
                out->same_as = i;
    }
    return POLYC_OK;
}

uint32_t polyc_circle_count(const polyc_ctx *ctx)
{
    uint32_t n = polyc_polyline_count(ctx), k = 0;
    for (uint32_t i = 0; i < n; i++) {
        const polyc__circle *c = circle_of(ctx, i);
        k += c && c->line_id == c->first_id;
    }
    return k;
}

polyc_status polyc_copy_arcs(const polyc_ctx *ctx, uint32_t index, float *xy_m, float *bulges,
                             uint32_t capacity, uint32_t *count, uint32_t *closed)
{
    polyc_polyline pl;
    polyc_status st = polyc_get_polyline(ctx, index, &pl);
    if (st != POLYC_OK)
        return st;
    uint32_t a = ctx->flat.start[index], n = 0;
    int arcs = ctx->flat.arc_n > 0 && ctx->flat.arc_keep;
    for (uint32_t k = 0; k < pl.point_count; k++)
        n += !arcs || ctx->flat.arc_keep[a + k];
    if (count)
        *count = n;
    if (closed)
        *closed = pl.closed;
    if (!xy_m && !bulges)
        return POLYC_OK;
    if (capacity < n)
        return POLYC_ERR_NOMEM;
    for (uint32_t k = 0, j = 0; k < pl.point_count; k++) {
        if (arcs && !ctx->flat.arc_keep[a + k])
            continue;
        if (xy_m) {
            xy_m[2 * j] = pl.xy_m[2 * k];
            xy_m[2 * j + 1] = pl.xy_m[2 * k + 1];
        }
        if (bulges)
            bulges[j] = arcs ? ctx->flat.arc_bulge[a + k] : 0.0f;
        j++;
    }
    return POLYC_OK;
}

uint32_t polyc_arc_count(const polyc_ctx *ctx)
{
    if (polyc__check_ctx(ctx) != POLYC_OK || ctx->stage < POLYC__STAGE_TRACE)
        return 0;
    return ctx->flat.arc_n;
}

polyc_status polyc_get_stats(const polyc_ctx *ctx, polyc_stats *out)
{
    polyc_status cst = polyc__check_ctx(ctx);
    if (cst != POLYC_OK || !out)
        return cst != POLYC_OK ? cst : POLYC_ERR_NULL;
    *out = ctx->stats;
    return POLYC_OK;
}

polyc_status polyc_grid_info(const polyc_ctx *ctx, double *origin_x_m, double *origin_y_m,
                             float *cell_m, uint32_t *width, uint32_t *height)
{
    polyc_status cst = polyc__check_ctx(ctx);
    if (cst != POLYC_OK)
        return cst;
    if (ctx->stage < POLYC__STAGE_GRID)
        return POLYC_ERR_STATE;
    if (origin_x_m) *origin_x_m = ctx->grid.origin_x_m;
    if (origin_y_m) *origin_y_m = ctx->grid.origin_y_m;
    if (cell_m) *cell_m = ctx->grid.cell_m;
    if (width) *width = (uint32_t)ctx->grid.width;
    if (height) *height = (uint32_t)ctx->grid.height;
    return POLYC_OK;
}

polyc_status polyc_grid_cell(const polyc_ctx *ctx, uint32_t ix, uint32_t iy, uint32_t *hits,
                             uint32_t *misses, uint32_t *contour)
{
    polyc_status cst = polyc__check_ctx(ctx);
    if (cst != POLYC_OK)
        return cst;
    if (ctx->stage < POLYC__STAGE_GRID)
        return POLYC_ERR_STATE;
    if (ix >= (uint32_t)ctx->grid.width || iy >= (uint32_t)ctx->grid.height)
        return POLYC_ERR_RANGE;
    const polyc__tile *t = polyc__grid_tile(&ctx->grid, (int32_t)ix, (int32_t)iy);
    int idx = polyc__cell_index((int32_t)ix, (int32_t)iy);
    if (hits) *hits = t ? t->hits[idx] : 0;
    if (misses) *misses = t ? t->misses[idx] : 0;
    if (contour)
        *contour = t && ctx->stage >= POLYC__STAGE_CONTOUR ? (t->contour[iy & 31] >> (ix & 31)) & 1u : 0;
    return POLYC_OK;
}

const char *polyc_last_error(const polyc_ctx *ctx)
{
    polyc_status cst = polyc__check_ctx(ctx);
    if (cst == POLYC_ERR_BUSY)
        return "called from inside the progress callback";
    if (cst != POLYC_OK)
        return "invalid context";
    return ctx->err.msg ? ctx->err.msg : "";
}
