/* curves.c - a map with its circles and arcs (curves.h). */
#include "curves.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TWO_PI 6.28318530717958647692

void curves_arc(const float *a, const float *b, double bulge, double *cx, double *cy, double *r,
                double *a0, double *sweep)
{
    double ax = a[0], ay = a[1], dx = (double)b[0] - ax, dy = (double)b[1] - ay;
    double c = hypot(dx, dy), half = 2.0 * atan(fabs(bulge)), s = bulge >= 0.0 ? 1.0 : -1.0;
    *r = c / (2.0 * sin(half));
    double d = *r * cos(half);
    /* the centre: off the chord's middle, away from the arc (to the left
     * of a -> b for a counter-clockwise arc) */
    *cx = 0.5 * (ax + (double)b[0]) + s * d * (-dy / c);
    *cy = 0.5 * (ay + (double)b[1]) + s * d * (dx / c);
    *a0 = atan2(ay - *cy, ax - *cx);
    *sweep = s * 4.0 * atan(fabs(bulge));
}

/* Pieces of an arc of radius r over angle a whose chords stray at most
 * sagitta_m from it. */
static uint32_t pieces(double r, double a, double sagitta_m)
{
    double step = 2.0 * acos(fmax(-1.0, 1.0 - sagitta_m / r));
    double n = ceil(fabs(a) / step);
    return n < 1.0 ? 1u : (n > 65536.0 ? 65536u : (uint32_t)n);
}

const float *curves_bulges(const curves_map *m, uint32_t i)
{
    if (!m->bulge)
        return NULL;
    const float *b = m->bulge + (m->lines[i].xy_m - m->xy) / 2;
    for (uint32_t k = 0; k < m->lines[i].point_count; k++)
        if (b[k] != 0.0f)
            return b;
    return NULL;
}

/* Polyline i flattened into out (NULL: the count only). */
static uint32_t flat_points(const curves_map *m, uint32_t i, double sagitta_m, float *out)
{
    const polyc_polyline *l = &m->lines[i];
    uint32_t n = 0;
    if (m->circ && m->circ[i].radius_m > 0.0f) {
        if (m->circ[i].same_as != i) /* another piece of a circle: given at the first */
            return 0;
        double r = (double)m->circ[i].radius_m;
        uint32_t sides = pieces(r, TWO_PI, sagitta_m);
        sides = sides < 8u ? 8u : sides;
        for (uint32_t k = 0; out && k < sides; k++) {
            double a = TWO_PI * (double)k / (double)sides;
            out[2u * k] = (float)((double)m->circ[i].center_x_m + r * cos(a));
            out[2u * k + 1u] = (float)((double)m->circ[i].center_y_m + r * sin(a));
        }
        return sides;
    }
    const float *bulge = curves_bulges(m, i);
    for (uint32_t k = 0; k < l->point_count; k++) {
        if (out) {
            out[2u * n] = l->xy_m[2u * k];
            out[2u * n + 1u] = l->xy_m[2u * k + 1u];
        }
        n++;
        uint32_t next = k + 1u < l->point_count ? k + 1u : 0u;
        if (!bulge || bulge[k] == 0.0f || (next == 0u && !l->closed))
            continue;
        double cx, cy, r, a0, sweep;
        curves_arc(&l->xy_m[2u * k], &l->xy_m[2u * next], (double)bulge[k], &cx, &cy, &r, &a0, &sweep);
        uint32_t p = pieces(r, sweep, sagitta_m);
        for (uint32_t j = 1; j < p; j++, n++)
            if (out) {
                double a = a0 + sweep * (double)j / (double)p;
                out[2u * n] = (float)(cx + r * cos(a));
                out[2u * n + 1u] = (float)(cy + r * sin(a));
            }
    }
    return n;
}

int curves_flatten(const curves_map *m, double sagitta_m, polyc_polyline **out, float **xy)
{
    size_t total = 0, at = 0;
    *out = malloc((m->count ? m->count : 1u) * sizeof **out);
    for (uint32_t i = 0; i < m->count; i++)
        total += flat_points(m, i, sagitta_m, NULL);
    *xy = malloc((total ? total : 1u) * 2u * sizeof **xy);
    if (!*out || !*xy) {
        free(*out);
        free(*xy);
        *out = NULL;
        *xy = NULL;
        return -1;
    }
    for (uint32_t i = 0; i < m->count; i++) {
        uint32_t n = flat_points(m, i, sagitta_m, *xy + 2u * at);
        (*out)[i].xy_m = *xy + 2u * at;
        (*out)[i].point_count = n;
        (*out)[i].closed = m->circ && m->circ[i].radius_m > 0.0f ? 1u : m->lines[i].closed;
        at += n;
    }
    return 0;
}

polyc_status curves_from_ctx(polyc_ctx *ctx, int no_curves, curves_map *m)
{
    polyc_status st = no_curves ? POLYC_OK : polyc_find_curves(ctx);
    uint32_t i, total = 0, at = 0, n, closed;
    memset(m, 0, sizeof *m);
    if (st != POLYC_OK)
        return st;
    m->count = polyc_polyline_count(ctx);
    for (i = 0; i < m->count; i++) {
        if ((st = polyc_copy_arcs(ctx, i, NULL, NULL, 0, &n, NULL)) != POLYC_OK)
            return st;
        total += n;
    }
    m->lines = calloc(m->count ? m->count : 1u, sizeof *m->lines);
    m->circ = calloc(m->count ? m->count : 1u, sizeof *m->circ);
    m->xy = malloc((total ? total : 1u) * 2u * sizeof *m->xy);
    m->bulge = malloc((total ? total : 1u) * sizeof *m->bulge);
    if (!m->lines || !m->circ || !m->xy || !m->bulge)
        return POLYC_ERR_NOMEM;
    for (i = 0; i < m->count; i++) {
        if ((st = polyc_copy_arcs(ctx, i, m->xy + 2u * at, m->bulge + at, total - at, &n,
                                  &closed)) != POLYC_OK ||
            (st = polyc_get_circle(ctx, i, &m->circ[i])) != POLYC_OK)
            return st;
        m->lines[i].xy_m = m->xy + 2u * at;
        m->lines[i].point_count = n;
        m->lines[i].closed = closed;
        m->circles += m->circ[i].radius_m > 0.0f && m->circ[i].same_as == i;
        for (uint32_t k = 0; k < n; k++)
            m->arcs += m->bulge[at + k] != 0.0f;
        at += n;
    }
    return POLYC_OK;
}

void curves_free(curves_map *m)
{
    free(m->lines);
    free(m->xy);
    free(m->bulge);
    free(m->circ);
    memset(m, 0, sizeof *m);
}
