/* boundary.c - where the API's doubles meet the library's floats.
 * Takes: poses and origins in the caller's frame (double, polyc.h).
 * Gives: the checks of poses and grid origins, the extent of scans (the
 * sizing of polyc_limits_for_scans and the frame's box), float
 * coordinates relative to the frame (the first pose, or an occupancy
 * grid's origin), the map back in the caller's frame, and the BIC and
 * error figures as the API's doubles.
 * Everything else computes in float: on a Cortex-M4F (a single-precision
 * FPU) each double operation is a software call. The sums and
 * conversions here are binary64.c's, on the bits with integers; what
 * needs no arithmetic (the checks, the comparisons) is done on the
 * doubles' bits too, exactly as the FPU would decide it. */
#include "context.h"

#include <math.h>
#include <string.h>

#define TWO_PI 6.283185307179586
#define PI 3.141592653589793

/* ---- comparisons on the bits (IEEE 754 binary64) ---- */

#define SIGN_BIT (UINT64_C(1) << 63)

static int is_nan(double v)
{
    return (polyc__bits64(v) << 1) > (UINT64_C(0x7ff) << 53); /* exponent all ones, a fraction */
}

/* |v| as an integer that orders as |v| does (infinity and NaN above every
 * finite number): `fabs(v) < lim` is magnitude(v) < magnitude(lim) */
static uint64_t magnitude(double v)
{
    return polyc__bits64(v) & ~SIGN_BIT;
}

/* v (not NaN) as an integer that orders as v does, -0 and +0 as 0 */
static int64_t order(double v)
{
    uint64_t u = polyc__bits64(v);
    return (u & SIGN_BIT) ? -(int64_t)(u & ~SIGN_BIT) : (int64_t)u;
}

/* a < b and a <= b, false when either is NaN (as the FPU's) */
static int less(double a, double b)
{
    return !is_nan(a) && !is_nan(b) && order(a) < order(b);
}
static int less_eq(double a, double b)
{
    return !is_nan(a) && !is_nan(b) && order(a) <= order(b);
}

/* fmin and fmax: the other when one is NaN */
static double min_of(double a, double b)
{
    return is_nan(a) || less(b, a) ? b : a;
}
static double max_of(double a, double b)
{
    return is_nan(a) || less(a, b) ? b : a;
}

/* ---- the checks and the extent ---- */

int polyc__pose_ok(double x, double y, double th)
{
    /* finite, within 1e7 m, turned at most 1e4 rad */
    return magnitude(x) < magnitude(1e7) && magnitude(y) < magnitude(1e7) &&
           magnitude(th) <= magnitude(1e4);
}

int polyc__grid_origin_ok(const polyc_occupancy_grid *grid)
{
    return magnitude(grid->origin_x_m) < magnitude(1e7) && magnitude(grid->origin_y_m) < magnitude(1e7) &&
           magnitude(grid->origin_yaw_rad) <= magnitude(100.0);
}

/* Extent rule: the poses and every reflected endpoint. Free-space beams do
 * not widen it (they are clipped to it). ox, oy shift the frame.
 * The endpoints' offsets from the pose are found in float (ranges are
 * small numbers; a double per beam is a software call on the target), the
 * box in double once per scan (poses may be far from the origin). */
void polyc__extent_add(const polyc_scan *s, double ox, double oy, double *box, int *have)
{
    double px = polyc__d_sub(s->pose_x_m, ox), py = polyc__d_sub(s->pose_y_m, oy);
    float off[4] = {0.0f, 0.0f, 0.0f, 0.0f}; /* min x, min y, max x, max y */
    float theta = polyc__heading(s->pose_theta_rad);
    for (uint32_t i = 0; s->range_m && i < s->beam_count; i++) {
        float r = s->range_m[i];
        if (!(r >= s->min_range_m && r < s->max_range_m))
            continue;
        float a = theta + s->start_angle_rad + (float)i * s->angle_step_rad;
        float sn, cs;
        polyc__sincosf(a, &sn, &cs);
        float x = r * cs, y = r * sn;
        off[0] = x < off[0] ? x : off[0];
        off[1] = y < off[1] ? y : off[1];
        off[2] = x > off[2] ? x : off[2];
        off[3] = y > off[3] ? y : off[3];
    }
    double lo_x = polyc__d_add(px, polyc__f_to_d(off[0])), lo_y = polyc__d_add(py, polyc__f_to_d(off[1]));
    double hi_x = polyc__d_add(px, polyc__f_to_d(off[2])), hi_y = polyc__d_add(py, polyc__f_to_d(off[3]));
    if (!*have) {
        box[0] = lo_x;
        box[1] = lo_y;
        box[2] = hi_x;
        box[3] = hi_y;
        *have = 1;
        return;
    }
    box[0] = min_of(box[0], lo_x);
    box[1] = min_of(box[1], lo_y);
    box[2] = max_of(box[2], hi_x);
    box[3] = max_of(box[3], hi_y);
}

void polyc_scan_extent(const polyc_config *config, const polyc_scan *scan, polyc_box *box)
{
    (void)config;
    if (!scan || !box || !polyc__pose_ok(scan->pose_x_m, scan->pose_y_m, scan->pose_theta_rad))
        return;
    double b[4] = {box->min_x_m, box->min_y_m, box->max_x_m, box->max_y_m};
    int have = less_eq(b[0], b[2]) && less_eq(b[1], b[3]);
    polyc__extent_add(scan, 0.0, 0.0, b, &have);
    box->min_x_m = b[0];
    box->min_y_m = b[1];
    box->max_x_m = b[2];
    box->max_y_m = b[3];
}

int polyc__box_spans(const polyc_box *box, float *w, float *h)
{
    if (!less_eq(box->min_x_m, box->max_x_m))
        return 0;
    *w = polyc__d_to_f(polyc__d_sub(box->max_x_m, box->min_x_m));
    *h = polyc__d_to_f(polyc__d_sub(box->max_y_m, box->min_y_m));
    return 1;
}

/* ---- the frame ---- */

float polyc__narrow(double v)
{
    return polyc__d_to_f(v);
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
    while (less(PI, theta_rad))
        theta_rad = polyc__d_sub(theta_rad, TWO_PI);
    while (less(theta_rad, -PI))
        theta_rad = polyc__d_add(theta_rad, TWO_PI);
    return polyc__d_to_f(theta_rad);
}

void polyc__frame_scan(const polyc_ctx *ctx, const polyc_scan *s, polyc__scan *d)
{
    d->x_m = polyc__d_to_f(polyc__d_sub(s->pose_x_m, ctx->frame_x));
    d->y_m = polyc__d_to_f(polyc__d_sub(s->pose_y_m, ctx->frame_y));
    d->theta_rad = polyc__heading(s->pose_theta_rad);
}

void polyc__frame_grid_origin(const polyc_ctx *ctx, polyc__grid *g, float x0_m, float y0_m)
{
    g->frame_ox = x0_m;
    g->frame_oy = y0_m;
    g->origin_x_m = polyc__d_add(ctx->frame_x, polyc__f_to_d(x0_m));
    g->origin_y_m = polyc__d_add(ctx->frame_y, polyc__f_to_d(y0_m));
}

int polyc__frame_inside(const polyc_ctx *ctx, const polyc_scan *s, float half_m)
{
    double box[4] = {0.0, 0.0, 0.0, 0.0};
    int have = 0;
    polyc__extent_add(s, ctx->frame_x, ctx->frame_y, box, &have);
    double h = polyc__f_to_d(half_m), minus_h = polyc__f_to_d(-half_m);
    return !have || (less(minus_h, box[0]) && less(minus_h, box[1]) && less(box[2], h) && less(box[3], h));
}

void polyc__frame_box(const polyc_ctx *ctx, float box[4])
{
    box[0] = polyc__d_to_f(ctx->ext.min_x);
    box[1] = polyc__d_to_f(ctx->ext.min_y);
    box[2] = polyc__d_to_f(ctx->ext.max_x);
    box[3] = polyc__d_to_f(ctx->ext.max_y);
}

void polyc__frame_point_out(const polyc_ctx *ctx, float x, float y, float *out_x, float *out_y)
{
    if (ctx->from_grid) {
        /* turned in float (offsets from the grid's corner), placed in double */
        float c = ctx->frame_dir.cos, s = ctx->frame_dir.sin;
        *out_x = polyc__d_to_f(polyc__d_add(ctx->frame_x, polyc__f_to_d(c * x - s * y)));
        *out_y = polyc__d_to_f(polyc__d_add(ctx->frame_y, polyc__f_to_d(s * x + c * y)));
    } else {
        *out_x = polyc__d_to_f(polyc__d_add(polyc__f_to_d(x), ctx->frame_x));
        *out_y = polyc__d_to_f(polyc__d_add(polyc__f_to_d(y), ctx->frame_y));
    }
}

void polyc__frame_export(polyc_ctx *ctx)
{
    for (uint32_t i = 0; i < ctx->flat.points; i++)
        polyc__frame_point_out(ctx, ctx->flat.xy[2 * i], ctx->flat.xy[2 * i + 1], &ctx->flat.xy[2 * i],
                               &ctx->flat.xy[2 * i + 1]);
}

void polyc__frame_of_grid(polyc_ctx *ctx, const polyc_occupancy_grid *grid)
{
    polyc__frame_set(ctx, grid->origin_x_m, grid->origin_y_m);
    polyc__sincosf(polyc__heading(grid->origin_yaw_rad), &ctx->frame_dir.sin, &ctx->frame_dir.cos);
    ctx->grid.origin_x_m = grid->origin_x_m; /* the grid's corner is the frame */
    ctx->grid.origin_y_m = grid->origin_y_m;
    ctx->grid.frame_ox = ctx->grid.frame_oy = 0.0f;
}


void polyc__figures_iteration(polyc_iteration *rep, float bic, float best_bic, float noise_m)
{
    rep->bic = polyc__f_to_d(bic);
    rep->best_bic = polyc__f_to_d(best_bic);
    rep->noise_m = polyc__f_to_d(noise_m);
}

void polyc__figures_out(float bic, float err, double *bic_out, double *err_out)
{
    if (bic_out)
        *bic_out = polyc__f_to_d(bic);
    if (err_out)
        *err_out = polyc__f_to_d(err);
}
