/* spacing.c - the expected distance between neighbouring scan endpoints.
 * Takes: the scan poses and the grid's tile layout. Gives: per tile, the
 * distance to the nearest pose (a chamfer distance transform) and from it
 * the beam spacing there (distance x smallest angle step): the scale below
 * which a gap between points is just sampling, not a gap in the wall.
 * With at most DIRECT_POSES poses (a single scan) there is no table: the
 * distance is measured to each pose when asked. The table's two passes
 * over every tile of the extent would cost a single scan with long-range
 * returns (tens of thousands of tiles) a noticeable share of its time, for
 * a handful of queries. */
#include "../context.h"

#include <math.h>

#define DIRECT_POSES 4u

/* a distance per tile of the grid's directory */
static float *dist_table(polyc__arena *a, size_t tiles)
{
    return polyc__alloc(a, tiles, sizeof(float));
}

void polyc__spacing_reserve(polyc__arena *a, const polyc_limits *lim)
{
    dist_table(a, polyc__grid_dir_cap(lim));
}

/* two chamfer passes, weights 1 and sqrt 2 tiles, from the tiles at 0 */
void polyc__spacing_chamfer(polyc__spacing *sp)
{
    const float a = sp->tile_m, b = sp->tile_m * 1.41421356f;
    for (int32_t y = 0; y < sp->h; y++)
        for (int32_t x = 0; x < sp->w; x++) {
            float *d = &sp->dist[(size_t)y * (size_t)sp->w + (size_t)x];
            if (x > 0) *d = polyc__minf(*d, d[-1] + a);
            if (y > 0) {
                const float *up = d - sp->w;
                *d = polyc__minf(*d, up[0] + a);
                if (x > 0) *d = polyc__minf(*d, up[-1] + b);
                if (x + 1 < sp->w) *d = polyc__minf(*d, up[1] + b);
            }
        }
    for (int32_t y = sp->h - 1; y >= 0; y--)
        for (int32_t x = sp->w - 1; x >= 0; x--) {
            float *d = &sp->dist[(size_t)y * (size_t)sp->w + (size_t)x];
            if (x + 1 < sp->w) *d = polyc__minf(*d, d[1] + a);
            if (y + 1 < sp->h) {
                const float *dn = d + sp->w;
                *d = polyc__minf(*d, dn[0] + a);
                if (x + 1 < sp->w) *d = polyc__minf(*d, dn[1] + b);
                if (x > 0) *d = polyc__minf(*d, dn[-1] + b);
            }
        }
}

polyc_status polyc__spacing_build(polyc_ctx *ctx, polyc__spacing *sp)
{
    const polyc__grid *g = &ctx->grid;
    sp->w = g->tiles_x;
    sp->h = g->tiles_y;
    sp->tile_m = g->cell_m * (float)POLYC__TILE_SIDE;
    sp->origin_x = g->frame_ox;
    sp->origin_y = g->frame_oy;
    sp->min_step_rad = 0.0f;
    sp->dist = NULL;
    sp->poses = NULL;
    sp->pose_count = 0;
    size_t n = (size_t)sp->w * (size_t)sp->h;
    if (n == 0)
        return POLYC_OK;
    if (ctx->layer) /* a layer's table (its poses are not kept) */
        return ctx->layer->spacing(ctx, sp, n);
    float step = 1e30f;
    for (uint32_t k = 0; k < ctx->scan_count; k++)
        if (ctx->scans[k].count > 1 && fabsf(ctx->scans[k].step_rad) < step)
            step = fabsf(ctx->scans[k].step_rad);
    sp->min_step_rad = step < 1e29f ? step : 0.0f;
    if (ctx->scan_count <= DIRECT_POSES) {
        sp->poses = ctx->scans;
        sp->pose_count = ctx->scan_count;
        return POLYC_OK;
    }
    sp->dist = dist_table(&ctx->arena, n);
    if (!sp->dist)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the spacing field");
    for (size_t i = 0; i < n; i++)
        sp->dist[i] = 1e30f;
    for (uint32_t k = 0; k < ctx->scan_count; k++) {
        const polyc__scan *s = &ctx->scans[k];
        int32_t tx = (int32_t)floorf((s->x_m - sp->origin_x) / sp->tile_m);
        int32_t ty = (int32_t)floorf((s->y_m - sp->origin_y) / sp->tile_m);
        if (tx >= 0 && ty >= 0 && tx < sp->w && ty < sp->h)
            sp->dist[(size_t)ty * (size_t)sp->w + (size_t)tx] = 0.0f;
    }
    polyc__spacing_chamfer(sp);
    return POLYC_OK;
}

float polyc__spacing_at(const polyc__spacing *sp, float x, float y)
{
    if (sp->poses) {
        float best = 1e30f;
        for (uint32_t k = 0; k < sp->pose_count; k++) {
            float dx = x - sp->poses[k].x_m, dy = y - sp->poses[k].y_m;
            best = polyc__minf(best, dx * dx + dy * dy);
        }
        return sqrtf(best) * sp->min_step_rad;
    }
    if (!sp->dist)
        return 0.0f;
    int32_t tx = (int32_t)floorf((x - sp->origin_x) / sp->tile_m);
    int32_t ty = (int32_t)floorf((y - sp->origin_y) / sp->tile_m);
    tx = tx < 0 ? 0 : (tx >= sp->w ? sp->w - 1 : tx);
    ty = ty < 0 ? 0 : (ty >= sp->h ? sp->h - 1 : ty);
    return sp->dist[(size_t)ty * (size_t)sp->w + (size_t)tx] * sp->min_step_rad;
}
