/* gtindex.c - a uniform grid over line segments for the scorer (gtscore.h).
 *
 * Takes segments; gives nearest-segment distances and first hits along
 * rays. Each cell lists every segment that passes within the cell's
 * circumscribed circle, so a cell's list holds all segments touching it.
 * Distance queries walk square rings of cells outwards and stop once a
 * ring cannot hold anything nearer; ray queries walk the cells the ray
 * crosses (Amanatides-Woo) and stop at the first cell that settles it.
 */
#include "gtscore.h"
#include "grow.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define GTINDEX_MAX_CELLS 4000000.0

void gtscore_index_init(gtscore_index *index)
{
    memset(index, 0, sizeof *index);
}

void gtscore_index_free(gtscore_index *index)
{
    if (!index)
        return;
    free(index->seg_m);
    free(index->cell_start);
    free(index->cell_seg);
    memset(index, 0, sizeof *index);
}

static int add_segment(gtscore_index *index, double x0, double y0, double x1, double y1)
{
    double *s;
    if (grow_array((void **)&index->seg_m, &index->seg_cap, index->seg_count + 1u,
                   4u * sizeof(double)) != 0)
        return -1;
    s = &index->seg_m[4u * index->seg_count++];
    s[0] = x0;
    s[1] = y0;
    s[2] = x1;
    s[3] = y1;
    return 0;
}

/* Coordinate k of a polyline's points, given as doubles (xy_d) or as
 * floats (xy_f, when xy_d is NULL). */
static double coord(const double *xy_d, const float *xy_f, uint32_t k)
{
    return xy_d ? xy_d[k] : (double)xy_f[k];
}

/* gtscore_index_add_d and _f: the points as doubles or as floats. */
static int add_points(gtscore_index *index, const double *xy_d, const float *xy_f,
                      uint32_t point_count, int closed)
{
    uint32_t i, n;
    if (!index || (!xy_d && !xy_f && point_count))
        return -1;
    if (point_count == 1u)
        return add_segment(index, coord(xy_d, xy_f, 0), coord(xy_d, xy_f, 1u),
                           coord(xy_d, xy_f, 0), coord(xy_d, xy_f, 1u));
    n = closed && point_count > 2u ? point_count : point_count - 1u;
    for (i = 0; point_count > 1u && i < n; i++) {
        uint32_t j = (i + 1u) % point_count;
        if (add_segment(index, coord(xy_d, xy_f, 2u * i), coord(xy_d, xy_f, 2u * i + 1u),
                        coord(xy_d, xy_f, 2u * j), coord(xy_d, xy_f, 2u * j + 1u)) != 0)
            return -1;
    }
    return 0;
}

int gtscore_index_add_d(gtscore_index *index, const double *xy_m, uint32_t point_count,
                        int closed)
{
    return add_points(index, xy_m, NULL, point_count, closed);
}

int gtscore_index_add_f(gtscore_index *index, const float *xy_m, uint32_t point_count,
                        int closed)
{
    return add_points(index, NULL, xy_m, point_count, closed);
}

int gtscore_index_add_polylines(gtscore_index *index, const polyc_polyline *lines,
                                uint32_t count)
{
    uint32_t i;
    for (i = 0; i < count; i++)
        if (gtscore_index_add_f(index, lines[i].xy_m, lines[i].point_count,
                                lines[i].closed != 0) != 0)
            return -1;
    return 0;
}

double gtscore_segment_distance2(const double *s, double px, double py)
{
    double ex = s[2] - s[0], ey = s[3] - s[1];
    double wx = px - s[0], wy = py - s[1];
    double len2 = ex * ex + ey * ey;
    double t = len2 > 0.0 ? (wx * ex + wy * ey) / len2 : 0.0;
    if (t < 0.0)
        t = 0.0;
    else if (t > 1.0)
        t = 1.0;
    wx -= t * ex;
    wy -= t * ey;
    return wx * wx + wy * wy;
}

/* Cell range [lo, hi] of coordinate interval [a, b] on one axis. */
static void cell_span(double a, double b, double origin, double cell, uint32_t n, uint32_t *lo,
                      uint32_t *hi)
{
    double fa = floor((a - origin) / cell), fb = floor((b - origin) / cell);
    if (fa < 0.0)
        fa = 0.0;
    if (fb > (double)(n - 1u))
        fb = (double)(n - 1u);
    *lo = (uint32_t)fa;
    *hi = fb < fa ? *lo : (uint32_t)fb;
}

/* Visits the cells segment `s` passes near: counts (fill == 0) or fills. */
static void bin_segment(gtscore_index *index, uint32_t s, uint32_t *cursor, int fill)
{
    const double *g = &index->seg_m[4u * s];
    double cell = index->cell_m, reach = 0.5 * cell * sqrt(2.0) * (1.0 + 1e-9);
    uint32_t x0, x1, y0, y1, x, y;
    cell_span(fmin(g[0], g[2]), fmax(g[0], g[2]), index->origin_x_m, cell, index->width, &x0,
              &x1);
    cell_span(fmin(g[1], g[3]), fmax(g[1], g[3]), index->origin_y_m, cell, index->height, &y0,
              &y1);
    for (y = y0; y <= y1; y++) {
        for (x = x0; x <= x1; x++) {
            size_t c = (size_t)y * index->width + x;
            double cx = index->origin_x_m + ((double)x + 0.5) * cell;
            double cy = index->origin_y_m + ((double)y + 0.5) * cell;
            if (gtscore_segment_distance2(g, cx, cy) > reach * reach)
                continue;
            if (fill)
                index->cell_seg[cursor[c]++] = s;
            else
                cursor[c]++;
        }
    }
}

int gtscore_index_build(gtscore_index *index, double cell_m)
{
    double min_x = HUGE_VAL, min_y = HUGE_VAL, max_x = -HUGE_VAL, max_y = -HUGE_VAL;
    double span_x, span_y, cells;
    uint32_t s, *cursor = NULL;
    size_t c, n, total;

    free(index->cell_start);
    free(index->cell_seg);
    index->cell_start = NULL;
    index->cell_seg = NULL;
    index->width = index->height = 0;
    if (!(cell_m > 0.0))
        return -1;
    if (index->seg_count == 0)
        return 0;
    for (s = 0; s < index->seg_count; s++) {
        const double *g = &index->seg_m[4u * s];
        if (!isfinite(g[0]) || !isfinite(g[1]) || !isfinite(g[2]) || !isfinite(g[3]))
            return -1;
        min_x = fmin(min_x, fmin(g[0], g[2]));
        max_x = fmax(max_x, fmax(g[0], g[2]));
        min_y = fmin(min_y, fmin(g[1], g[3]));
        max_y = fmax(max_y, fmax(g[1], g[3]));
    }
    span_x = max_x - min_x;
    span_y = max_y - min_y;
    cells = (span_x / cell_m + 1.0) * (span_y / cell_m + 1.0);
    if (cells > GTINDEX_MAX_CELLS)
        cell_m *= sqrt(cells / GTINDEX_MAX_CELLS) * 1.01;
    index->cell_m = cell_m;
    index->origin_x_m = min_x - 0.5 * cell_m;
    index->origin_y_m = min_y - 0.5 * cell_m;
    index->width = (uint32_t)(span_x / cell_m) + 2u;
    index->height = (uint32_t)(span_y / cell_m) + 2u;
    n = (size_t)index->width * index->height;

    cursor = calloc(n + 1u, sizeof *cursor);
    index->cell_start = malloc((n + 1u) * sizeof *index->cell_start);
    if (!cursor || !index->cell_start)
        goto fail;
    for (s = 0; s < index->seg_count; s++)
        bin_segment(index, s, cursor, 0);
    for (total = 0, c = 0; c < n; c++) {
        uint32_t k = cursor[c];
        if (total + k > UINT32_MAX)
            goto fail;
        index->cell_start[c] = (uint32_t)total;
        cursor[c] = (uint32_t)total;
        total += k;
    }
    index->cell_start[n] = (uint32_t)total;
    index->cell_seg = malloc((total ? total : 1u) * sizeof *index->cell_seg);
    if (!index->cell_seg)
        goto fail;
    for (s = 0; s < index->seg_count; s++)
        bin_segment(index, s, cursor, 1);
    free(cursor);
    return 0;
fail:
    free(cursor);
    free(index->cell_start);
    free(index->cell_seg);
    index->cell_start = NULL;
    index->cell_seg = NULL;
    index->width = index->height = 0;
    return -1;
}

/* The smaller of best2 and the squared distances to cell (x, y)'s segments. */
static double cell_distance2(const gtscore_index *index, int64_t x, int64_t y, double px,
                             double py, double best2)
{
    size_t c = (size_t)y * index->width + (size_t)x;
    uint32_t k;
    for (k = index->cell_start[c]; k < index->cell_start[c + 1u]; k++) {
        double d2 = gtscore_segment_distance2(&index->seg_m[4u * index->cell_seg[k]], px, py);
        if (d2 < best2)
            best2 = d2;
    }
    return best2;
}

int gtscore_index_box(const gtscore_index *index, double x_m, double y_m, double r_m,
                      uint32_t cells[4])
{
    double fx0, fx1, fy0, fy1;
    if (!index->cell_start || !isfinite(x_m) || !isfinite(y_m) || !(r_m >= 0.0))
        return 0;
    fx0 = floor((x_m - r_m - index->origin_x_m) / index->cell_m);
    fx1 = floor((x_m + r_m - index->origin_x_m) / index->cell_m);
    fy0 = floor((y_m - r_m - index->origin_y_m) / index->cell_m);
    fy1 = floor((y_m + r_m - index->origin_y_m) / index->cell_m);
    if (fx1 < 0.0 || fy1 < 0.0 || fx0 >= (double)index->width || fy0 >= (double)index->height)
        return 0;
    cells[0] = fx0 < 0.0 ? 0u : (uint32_t)fx0;
    cells[1] = fy0 < 0.0 ? 0u : (uint32_t)fy0;
    cells[2] = fx1 >= (double)index->width ? index->width - 1u : (uint32_t)fx1;
    cells[3] = fy1 >= (double)index->height ? index->height - 1u : (uint32_t)fy1;
    return 1;
}

int gtscore_index_any_near(const gtscore_index *index, double x_m, double y_m, double r_m,
                           int (*accept)(const void *ctx, uint32_t seg), const void *ctx)
{
    double r2 = r_m * r_m;
    uint32_t box[4], cx, cy, k;
    if (!gtscore_index_box(index, x_m, y_m, r_m, box))
        return 0;
    for (cy = box[1]; cy <= box[3]; cy++)
        for (cx = box[0]; cx <= box[2]; cx++) {
            size_t c = (size_t)cy * index->width + cx;
            for (k = index->cell_start[c]; k < index->cell_start[c + 1u]; k++) {
                uint32_t o = index->cell_seg[k];
                if (accept && !accept(ctx, o))
                    continue;
                if (gtscore_segment_distance2(&index->seg_m[4u * o], x_m, y_m) <= r2)
                    return 1;
            }
        }
    return 0;
}

/* A short-limit query: only the cells that meet the square of half-side
 * limit_m around the point can hold a segment that near. */
static double box_distance(const gtscore_index *index, double x_m, double y_m, double limit_m)
{
    double best2 = HUGE_VAL;
    uint32_t box[4], x, y;
    if (!gtscore_index_box(index, x_m, y_m, limit_m, box))
        return HUGE_VAL;
    for (y = box[1]; y <= box[3]; y++)
        for (x = box[0]; x <= box[2]; x++)
            best2 = cell_distance2(index, x, y, x_m, y_m, best2);
    return sqrt(best2);
}

static int64_t max64(int64_t a, int64_t b)
{
    return a > b ? a : b;
}

double gtscore_index_distance(const gtscore_index *index, double x_m, double y_m,
                              double limit_m)
{
    double best2 = HUGE_VAL, fx, fy;
    int64_t cx, cy, w, h, k, k_first, k_last;
    if (!index->cell_start || !isfinite(x_m) || !isfinite(y_m))
        return HUGE_VAL;
    if (limit_m <= 2.0 * index->cell_m)
        return box_distance(index, x_m, y_m, limit_m);
    w = (int64_t)index->width;
    h = (int64_t)index->height;
    fx = floor((x_m - index->origin_x_m) / index->cell_m);
    fy = floor((y_m - index->origin_y_m) / index->cell_m);
    if (fabs(fx) > 1e15 || fabs(fy) > 1e15)
        return HUGE_VAL;
    cx = (int64_t)fx;
    cy = (int64_t)fy;
    /* rings that intersect the grid: Chebyshev distance to it, and to its
     * farthest corner */
    k_first = max64(max64(-cx, cx - (w - 1)), max64(max64(-cy, cy - (h - 1)), 0));
    k_last = max64(max64(cx, w - 1 - cx), max64(cy, h - 1 - cy));
    for (k = k_first; k <= k_last; k++) {
        int64_t x, y, y_lo = max64(cy - k, 0), y_hi = cy + k < h - 1 ? cy + k : h - 1;
        /* every cell of ring k is at least (k - 1) cells away */
        double lower = k > 0 ? (double)(k - 1) * index->cell_m : 0.0;
        if (lower * lower > best2 || lower > limit_m)
            break;
        for (y = y_lo; y <= y_hi; y++) {
            if (y == cy - k || y == cy + k) {
                int64_t x_lo = max64(cx - k, 0), x_hi = cx + k < w - 1 ? cx + k : w - 1;
                for (x = x_lo; x <= x_hi; x++)
                    best2 = cell_distance2(index, x, y, x_m, y_m, best2);
            } else {
                if (cx - k >= 0 && cx - k < w)
                    best2 = cell_distance2(index, cx - k, y, x_m, y_m, best2);
                if (k > 0 && cx + k >= 0 && cx + k < w)
                    best2 = cell_distance2(index, cx + k, y, x_m, y_m, best2);
            }
        }
    }
    return sqrt(best2);
}

/* Range along the unit ray (ox, oy) + t (dx, dy) to segment s, or INFINITY. */
static double ray_segment(const double *s, double ox, double oy, double dx, double dy)
{
    double ex = s[2] - s[0], ey = s[3] - s[1];
    double wx = s[0] - ox, wy = s[1] - oy;
    double denom = dx * ey - dy * ex;
    double t, u;
    if (fabs(denom) < 1e-15)
        return HUGE_VAL; /* parallel, or a point: the ray grazes it */
    t = (wx * ey - wy * ex) / denom;
    u = (wx * dy - wy * dx) / denom;
    if (t <= 1e-12 || u < -1e-12 || u > 1.0 + 1e-12)
        return HUGE_VAL;
    return t;
}

/* One slab of the ray p + t d (one axis) against [lo, hi): narrows
 * [*t_in, *t_out] to the t inside it; 0 when the ray runs parallel to the
 * slab outside it. */
static int clip_slab(double p, double d, double lo, double hi, double *t_in, double *t_out)
{
    if (d != 0.0) {
        double t0 = (lo - p) / d, t1 = (hi - p) / d;
        *t_in = fmax(*t_in, fmin(t0, t1));
        *t_out = fmin(*t_out, fmax(t0, t1));
        return 1;
    }
    return !(p < lo || p >= hi);
}

double gtscore_index_ray(const gtscore_index *index, double x_m, double y_m, double angle_rad,
                         double max_range_m)
{
    double dx = cos(angle_rad), dy = sin(angle_rad);
    double x_lo = index->origin_x_m, y_lo = index->origin_y_m;
    double x_hi = x_lo + index->cell_m * index->width;
    double y_hi = y_lo + index->cell_m * index->height;
    double t_in = 0.0, t_out = max_range_m, best = HUGE_VAL;
    double t_next_x, t_next_y, t_step_x, t_step_y, px, py;
    int64_t cx, cy, step_x, step_y;

    if (!index->cell_start || !isfinite(x_m) || !isfinite(y_m) || !(max_range_m > 0.0))
        return HUGE_VAL;
    /* clip the ray to the grid box (slabs) */
    if (!clip_slab(x_m, dx, x_lo, x_hi, &t_in, &t_out) ||
        !clip_slab(y_m, dy, y_lo, y_hi, &t_in, &t_out))
        return HUGE_VAL;
    if (t_in > t_out)
        return HUGE_VAL;

    px = x_m + t_in * dx;
    py = y_m + t_in * dy;
    cx = (int64_t)floor((px - x_lo) / index->cell_m);
    cy = (int64_t)floor((py - y_lo) / index->cell_m);
    if (cx < 0) cx = 0;
    if (cx >= (int64_t)index->width) cx = (int64_t)index->width - 1;
    if (cy < 0) cy = 0;
    if (cy >= (int64_t)index->height) cy = (int64_t)index->height - 1;
    step_x = dx > 0.0 ? 1 : -1;
    step_y = dy > 0.0 ? 1 : -1;
    t_step_x = dx != 0.0 ? index->cell_m / fabs(dx) : (double)INFINITY;
    t_step_y = dy != 0.0 ? index->cell_m / fabs(dy) : (double)INFINITY;
    t_next_x = dx != 0.0
                   ? ((x_lo + (double)(cx + (step_x > 0 ? 1 : 0)) * index->cell_m) - x_m) / dx
                   : (double)INFINITY;
    t_next_y = dy != 0.0
                   ? ((y_lo + (double)(cy + (step_y > 0 ? 1 : 0)) * index->cell_m) - y_m) / dy
                   : (double)INFINITY;

    for (;;) {
        size_t c = (size_t)cy * index->width + (size_t)cx;
        double t_exit = fmin(t_next_x, t_next_y);
        uint32_t k;
        for (k = index->cell_start[c]; k < index->cell_start[c + 1u]; k++) {
            double t = ray_segment(&index->seg_m[4u * index->cell_seg[k]], x_m, y_m, dx, dy);
            if (t < best)
                best = t;
        }
        /* a hit found in this cell may lie in a later cell: only stop once
         * the ray has passed it */
        if (best <= t_exit || t_exit > t_out)
            break;
        if (t_next_x < t_next_y) {
            cx += step_x;
            t_next_x += t_step_x;
        } else {
            cy += step_y;
            t_next_y += t_step_y;
        }
        if (cx < 0 || cy < 0 || cx >= (int64_t)index->width || cy >= (int64_t)index->height)
            break;
    }
    return best <= max_range_m ? best : (double)INFINITY;
}
