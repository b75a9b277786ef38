/* boundary.c - where the API's doubles meet the library's floats.
 * Takes: poses and origins in the caller's frame (double, polyc.h).
 * Gives: float coordinates relative to the frame (the first pose, or an
 * occupancy grid's origin), the map back in the caller's frame, and the
 * BIC and error figures as the API's doubles.
 * Everything else computes in float: on a Cortex-M4F (a single-precision
 * FPU) each double operation is a software call. The calls here run a few
 * times per scan, per grid or per result (the Makefile's cold list). */
#include "context.h"

#include <math.h>

#define TWO_PI 6.283185307179586
#define PI 3.141592653589793

float polyc__narrow(double v)
{
    return (float)v;
}

void polyc__frame_set(polyc_ctx *ctx, double x_m, double y_m)
{
    ctx->frame_x = x_m;
    ctx->frame_y = y_m;
    ctx->have_frame = 1;
}

float polyc__heading(double theta_rad)
{
    /* whole turns off, by additions (|theta| <= 1e4 rad, polyc__pose_ok:
     * at most 1,592 of them): libm's remainder() and a multiply would
     * bring a kilobyte and more of software double into every firmware */
    while (theta_rad > PI)
        theta_rad -= TWO_PI;
    while (theta_rad < -PI)
        theta_rad += TWO_PI;
    return (float)theta_rad;
}

void polyc__frame_scan(const polyc_ctx *ctx, const polyc_scan *s, polyc__scan *d)
{
    d->x_m = (float)(s->pose_x_m - ctx->frame_x);
    d->y_m = (float)(s->pose_y_m - ctx->frame_y);
    d->theta_rad = polyc__heading(s->pose_theta_rad);
}

void polyc__frame_grid_origin(const polyc_ctx *ctx, polyc__grid *g, float x0_m, float y0_m)
{
    g->frame_ox = x0_m;
    g->frame_oy = y0_m;
    g->origin_x_m = ctx->frame_x + (double)x0_m;
    g->origin_y_m = ctx->frame_y + (double)y0_m;
}

int polyc__frame_inside(const polyc_ctx *ctx, const polyc_scan *s, float half_m)
{
    double box[4] = {0.0, 0.0, 0.0, 0.0};
    int have = 0;
    polyc__extent_add(s, ctx->frame_x, ctx->frame_y, box, &have);
    double h = (double)half_m;
    return !have || (box[0] > -h && box[1] > -h && box[2] < h && box[3] < h);
}

void polyc__frame_box(const polyc_ctx *ctx, float box[4])
{
    box[0] = (float)ctx->ext.min_x;
    box[1] = (float)ctx->ext.min_y;
    box[2] = (float)ctx->ext.max_x;
    box[3] = (float)ctx->ext.max_y;
}

void polyc__frame_export(polyc_ctx *ctx)
{
    for (uint32_t i = 0; ctx->from_grid && i < ctx->flat.points; i++) {
        /* turned in float (offsets from the grid's corner), placed in double */
        float x = ctx->flat.xy[2 * i], y = ctx->flat.xy[2 * i + 1];
        float c = ctx->frame_dir.cos, s = ctx->frame_dir.sin;
        ctx->flat.xy[2 * i] = (float)(ctx->frame_x + (double)(c * x - s * y));
        ctx->flat.xy[2 * i + 1] = (float)(ctx->frame_y + (double)(s * x + c * y));
    }
    for (uint32_t i = 0; !ctx->from_grid && i < ctx->flat.points; i++) {
        ctx->flat.xy[2 * i] = (float)((double)ctx->flat.xy[2 * i] + ctx->frame_x);
        ctx->flat.xy[2 * i + 1] = (float)((double)ctx->flat.xy[2 * i + 1] + ctx->frame_y);
    }
}

void polyc__frame_of_grid(polyc_ctx *ctx, const polyc_occupancy_grid *grid)
{
    polyc__frame_set(ctx, grid->origin_x_m, grid->origin_y_m);
    ctx->frame_dir.cos = (float)cos(grid->origin_yaw_rad);
    ctx->frame_dir.sin = (float)sin(grid->origin_yaw_rad);
    ctx->grid.origin_x_m = grid->origin_x_m; /* the grid's corner is the frame */
    ctx->grid.origin_y_m = grid->origin_y_m;
    ctx->grid.frame_ox = ctx->grid.frame_oy = 0.0f;
}

int polyc__grid_origin_ok(const polyc_occupancy_grid *grid)
{
    return isfinite(grid->origin_x_m) && isfinite(grid->origin_y_m) &&
           isfinite(grid->origin_yaw_rad) && fabs(grid->origin_x_m) < 1e7 &&
           fabs(grid->origin_y_m) < 1e7 && fabs(grid->origin_yaw_rad) <= 100.0;
}

void polyc__figures_iteration(polyc_iteration *rep, float bic, float best_bic, float noise_m)
{
    rep->bic = (double)bic;
    rep->best_bic = (double)best_bic;
    rep->noise_m = (double)noise_m;
}

void polyc__figures_out(float bic, float err, double *bic_out, double *err_out)
{
    if (bic_out)
        *bic_out = (double)bic;
    if (err_out)
        *err_out = (double)err;
}
