/* occmap.c - log-odds occupancy mapping of aligned scans (see occmap.h):
 * takes scans, gives an int8 OccupancyGrid thresholded as map_saver does.
 */
#include "occmap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gtscore.h"

void occmap_config_default(occmap_config *c)
{
    c->resolution_m = 0.05;
    c->hit_logodds = 0.85;
    c->miss_logodds = -0.4;
    c->free_range_m = 10.0;
    c->occupied_p = 0.65;
    c->free_p = 0.196;
}

double occmap_probability(double logodds)
{
    return 1.0 - 1.0 / (1.0 + exp(logodds));
}

int8_t occmap_value(const occmap_config *c, double logodds)
{
    double p = occmap_probability(logodds);
    return p > c->occupied_p ? 100 : p < c->free_p ? 0 : -1;
}

static double beam_angle(const polyc_scan *s, uint32_t i)
{
    return s->pose_theta_rad + (double)s->start_angle_rad + (double)i * (double)s->angle_step_rad;
}

/* Grid coordinates (cells from the origin) of a point. */
static void to_grid(const occmap *m, double x, double y, double *gx, double *gy)
{
    *gx = (x - m->origin_x_m) / m->resolution_m;
    *gy = (y - m->origin_y_m) / m->resolution_m;
}

static void add(occmap *m, int64_t ix, int64_t iy, double v)
{
    size_t k = (size_t)iy * m->width + (size_t)ix;
    m->logodds[k] += (float)v;
    m->touched[k]++;
}

/* The ray from grid point (ax, ay) to (bx, by): misses in every cell it
 * crosses before the cell of b, and in that cell `end` (a hit, a miss, or
 * nothing when end is 0). Cells are visited in order (Amanatides & Woo);
 * the ray stops where it leaves the grid. */
static void trace(occmap *m, double ax, double ay, double bx, double by, double miss, double end)
{
    int64_t ix = (int64_t)floor(ax), iy = (int64_t)floor(ay);
    int64_t ex = (int64_t)floor(bx), ey = (int64_t)floor(by);
    double dx = bx - ax, dy = by - ay;
    int64_t sx = dx > 0.0 ? 1 : -1, sy = dy > 0.0 ? 1 : -1;
    /* ray parameter t in [0, 1] at the next vertical / horizontal cell edge */
    double tx = dx != 0.0 ? ((dx > 0.0 ? (double)(ix + 1) : (double)ix) - ax) / dx : HUGE_VAL;
    double ty = dy != 0.0 ? ((dy > 0.0 ? (double)(iy + 1) : (double)iy) - ay) / dy : HUGE_VAL;
    double stepx = dx != 0.0 ? fabs(1.0 / dx) : HUGE_VAL;
    double stepy = dy != 0.0 ? fabs(1.0 / dy) : HUGE_VAL;
    int64_t steps = llabs(ex - ix) + llabs(ey - iy);
    for (int64_t k = 0;; k++) {
        if (ix < 0 || iy < 0 || ix >= (int64_t)m->width || iy >= (int64_t)m->height)
            return;
        if (k == steps || (ix == ex && iy == ey)) {
            if (end != 0.0)
                add(m, ix, iy, end);
            return;
        }
        add(m, ix, iy, miss);
        if (tx < ty) {
            ix += sx;
            tx += stepx;
        } else {
            iy += sy;
            ty += stepy;
        }
    }
}

int occmap_build(occmap *m, const occmap_config *c, const polyc_scan *scans, uint32_t n)
{
    double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL, res = c->resolution_m;
    memset(m, 0, sizeof *m);
    if (n == 0 || !(res > 0.0) || !(c->free_range_m >= 0.0))
        return -1;
    for (uint32_t s = 0; s < n; s++) {
        const polyc_scan *sc = &scans[s];
        x0 = fmin(x0, sc->pose_x_m); x1 = fmax(x1, sc->pose_x_m);
        y0 = fmin(y0, sc->pose_y_m); y1 = fmax(y1, sc->pose_y_m);
        for (uint32_t i = 0; i < sc->beam_count; i++) {
            if (!gtscore_beam_reflected(sc, i))
                continue;
            double a = beam_angle(sc, i), r = (double)sc->range_m[i];
            double x = sc->pose_x_m + r * cos(a), y = sc->pose_y_m + r * sin(a);
            x0 = fmin(x0, x); x1 = fmax(x1, x);
            y0 = fmin(y0, y); y1 = fmax(y1, y);
        }
    }
    if (!isfinite(x0) || !isfinite(y0) || !isfinite(x1) || !isfinite(y1))
        return -1;
    double cx0 = floor(x0 / res) - 1.0, cy0 = floor(y0 / res) - 1.0;
    double cx1 = floor(x1 / res) + 1.0, cy1 = floor(y1 / res) + 1.0;
    double w = cx1 - cx0 + 1.0, h = cy1 - cy0 + 1.0;
    if (!(w * h <= (double)OCCMAP_MAX_CELLS))
        return -1;
    m->width = (uint32_t)w;
    m->height = (uint32_t)h;
    m->resolution_m = res;
    m->origin_x_m = cx0 * res;
    m->origin_y_m = cy0 * res;
    size_t cells = (size_t)m->width * m->height;
    m->logodds = calloc(cells, sizeof *m->logodds);
    m->touched = calloc(cells, sizeof *m->touched);
    m->cells = malloc(cells);
    if (!m->logodds || !m->touched || !m->cells) {
        occmap_free(m);
        return -1;
    }
    for (uint32_t s = 0; s < n; s++) {
        const polyc_scan *sc = &scans[s];
        double ax, ay;
        to_grid(m, sc->pose_x_m, sc->pose_y_m, &ax, &ay);
        for (uint32_t i = 0; i < sc->beam_count; i++) {
            int hit = gtscore_beam_reflected(sc, i);
            if (!hit && c->free_range_m <= 0.0)
                continue;
            double a = beam_angle(sc, i), r = hit ? (double)sc->range_m[i] : c->free_range_m;
            double bx, by;
            to_grid(m, sc->pose_x_m + r * cos(a), sc->pose_y_m + r * sin(a), &bx, &by);
            trace(m, ax, ay, bx, by, c->miss_logodds, hit ? c->hit_logodds : c->miss_logodds);
        }
    }
    for (size_t k = 0; k < cells; k++) {
        int8_t v = m->touched[k] ? occmap_value(c, (double)m->logodds[k]) : -1;
        m->cells[k] = v;
        m->occupied += v == 100;
        m->free_cells += v == 0;
        m->unknown += v == -1;
    }
    return 0;
}

void occmap_free(occmap *m)
{
    free(m->logodds);
    free(m->touched);
    free(m->cells);
    m->logodds = NULL;
    m->touched = NULL;
    m->cells = NULL;
}

void occmap_grid(const occmap *m, polyc_occupancy_grid *g)
{
    memset(g, 0, sizeof *g);
    g->width = m->width;
    g->height = m->height;
    g->resolution_m = (float)m->resolution_m;
    g->origin_x_m = m->origin_x_m;
    g->origin_y_m = m->origin_y_m;
    g->origin_yaw_rad = 0.0;
    g->cells = m->cells;
}

int occmap_cell_points(const polyc_occupancy_grid *g, int8_t min_value, double **xy_m,
                       uint64_t *count)
{
    size_t cells = (size_t)g->width * g->height, n = 0, k;
    double res = (double)g->resolution_m, c = cos(g->origin_yaw_rad), s = sin(g->origin_yaw_rad);
    *xy_m = NULL;
    *count = 0;
    for (k = 0; k < cells; k++)
        n += g->cells[k] >= min_value;
    if (n == 0)
        return 0;
    double *xy = malloc(2u * n * sizeof *xy);
    if (!xy)
        return -1;
    n = 0;
    for (uint32_t j = 0; j < g->height; j++)
        for (uint32_t i = 0; i < g->width; i++) {
            if (g->cells[(size_t)j * g->width + i] < min_value)
                continue;
            double u = ((double)i + 0.5) * res, v = ((double)j + 0.5) * res;
            xy[2u * n] = g->origin_x_m + c * u - s * v;
            xy[2u * n + 1u] = g->origin_y_m + s * u + c * v;
            n++;
        }
    *xy_m = xy;
    *count = n;
    return 0;
}
