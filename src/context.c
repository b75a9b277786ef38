/* context.c - what every entry point does on a context, batch or online:
 * placing it in the caller's block, checking it on entry, taking a scan in
 * (its stored form, its ranges, its beams' tallies) and publishing the
 * store as the result. Takes: the caller's block, context and scans.
 * Gives: the context's header and scan slots filled; api.c (batch) and
 * the online files (online.c, online_scan.c, ...) sit above it, and the
 * batch files call nothing of the online ones. */
#include "context.h"

#include <math.h>
#include <string.h>

extern inline polyc_status polyc__fail(polyc_ctx *ctx, polyc_status st, const char *msg);

polyc_status polyc__check_ctx(const polyc_ctx *ctx)
{
    if (!ctx)
        return POLYC_ERR_NULL;
    if (ctx->magic == POLYC__MAGIC_BUSY)
        return POLYC_ERR_BUSY;
    return ctx->magic == POLYC__MAGIC ? POLYC_OK : POLYC_ERR_NULL;
}

polyc_status polyc__enter(polyc_ctx *ctx, int args_ok)
{
    polyc_status cst = polyc__check_ctx(ctx);
    if (cst != POLYC_OK || !args_ok)
        return cst != POLYC_OK ? cst : POLYC_ERR_NULL;
    ctx->err.msg = NULL;
    return POLYC_OK;
}

polyc_status polyc__init_args(const void *block, const polyc_config *config, const void *limits,
                              polyc_ctx **out)
{
    if (!out)
        return POLYC_ERR_NULL;
    *out = NULL;
    if (!block || !config || !limits)
        return POLYC_ERR_NULL;
    return polyc_config_check(config, NULL) != POLYC_OK ? POLYC_ERR_CONFIG : POLYC_OK;
}

polyc_status polyc__place_ctx(void *block, size_t size, size_t need, size_t head,
                              const polyc_config *config, polyc_ctx **out)
{
    if (need == 0)
        return POLYC_ERR_CONFIG;
    if (size < need)
        return POLYC_ERR_NOMEM;
    uintptr_t p = ((uintptr_t)block + 15u) & ~(uintptr_t)15u;
    size_t skew = (size_t)(p - (uintptr_t)block);
    polyc_ctx *ctx = (polyc_ctx *)p;
    memset(ctx, 0, head);
    ctx->magic = POLYC__MAGIC;
    ctx->cfg = *config;
    ctx->arena.base = (unsigned char *)p + head;
    ctx->arena.size = size - skew - head;
    ctx->frame_dir.cos = 1.0f;
    ctx->stats.memory_size_bytes = size;
    ctx->err.scan = -1;
    *out = ctx;
    return POLYC_OK;
}

const char *polyc__scan_problem(const polyc_scan *s)
{
    if (!polyc__pose_ok(s->pose_x_m, s->pose_y_m, s->pose_theta_rad))
        return "scan pose is not finite, beyond 1e7 m or turned beyond 1e4 rad";
    if (!isfinite(s->start_angle_rad) || !isfinite(s->angle_step_rad) ||
        fabsf(s->angle_step_rad) > 6.2832f || fabsf(s->start_angle_rad) > 100.0f)
        return "scan angles are not finite or out of range";
    if (s->beam_count > 1 && s->angle_step_rad == 0.0f)
        return "scan angle_step_rad is 0";
    if (!(s->min_range_m >= 0.0f) || !(s->max_range_m > s->min_range_m))
        return "scan range interval is empty or negative";
    if (s->reserved != 0)
        return "scan.reserved must be 0";
    return NULL;
}

polyc_status polyc__scan_check(polyc_ctx *ctx, const polyc_scan *s, uint32_t number)
{
    if (s->beam_count && !s->range_m)
        return polyc__fail(ctx, POLYC_ERR_NULL, "scan.range_m is NULL with beams");
    const char *bad = polyc__scan_problem(s);
    if (bad) {
        ctx->err.scan = (int32_t)number;
        return polyc__fail(ctx, POLYC_ERR_SCAN, bad);
    }
    return POLYC_OK;
}

void polyc__store_scan(polyc_ctx *ctx, polyc__scan *d, const polyc_scan *s, uint32_t first)
{
    polyc__frame_scan(ctx, s, d);
    d->start_rad = s->start_angle_rad;
    d->step_rad = s->angle_step_rad;
    d->min_m = s->min_range_m;
    d->max_m = s->max_range_m;
    d->first = first;
    d->count = s->beam_count;
}

void polyc__take_scan(polyc_ctx *ctx, polyc__scan *d, const polyc_scan *s, uint32_t first)
{
    polyc__store_scan(ctx, d, s, first);
    if (s->beam_count)
        memcpy(ctx->ranges + first, s->range_m, (size_t)s->beam_count * sizeof(float));
}

void polyc__tally_beams(polyc_ctx *ctx, const polyc_scan *s)
{
    for (uint32_t i = 0; i < s->beam_count; i++) {
        float r = s->range_m[i];
        if (!(r >= 0.0f)) /* NaN or negative: kept, skipped by every pass */
            ctx->stats.beams_skipped++;
        else if (r >= s->min_range_m && r < s->max_range_m)
            ctx->stats.hits++;
    }
    ctx->stats.beams += s->beam_count;
}

void polyc__export_result(polyc_ctx *ctx)
{
    polyc__flat_from_store(&ctx->flat, &ctx->store);
    polyc__frame_export(ctx);
    ctx->stats.polylines = ctx->flat.count;
    ctx->stats.vertices = ctx->flat.points;
}

/* The caller's callback, with the context marked busy while it runs: a
 * call back into the library on it is refused (POLYC_ERR_BUSY) instead of
 * changing the model under the optimiser. */
int polyc__guarded_progress(void *user, const polyc_iteration *it)
{
    polyc__guarded *g = (polyc__guarded *)user;
    g->ctx->magic = POLYC__MAGIC_BUSY;
    int stop = g->progress(g->user, it);
    g->ctx->magic = POLYC__MAGIC;
    return stop;
}
