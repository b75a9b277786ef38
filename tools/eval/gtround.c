/* gtround.c - maps with circles for the scorers (gtround.h). */
#include "gtround.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TWO_PI 6.28318530717958647692

/* Sides of the polygon that stands for a circle of radius r. */
static uint32_t circle_sides(double r)
{
    double step = 2.0 * acos(fmax(-1.0, 1.0 - GTROUND_SAGITTA_M / r));
    double n = ceil(TWO_PI / step);
    return n < 8.0 ? 8u : (n > 100000.0 ? 100000u : (uint32_t)n);
}

int gtround_lines(const polyc_polyline *lines, const polyc_circle *circ, uint32_t count,
                  polyc_polyline **out, float **xy)
{
    size_t points = 0, at = 0;
    uint32_t i, k;
    *out = NULL;
    *xy = NULL;
    for (i = 0; circ && i < count; i++)
        if (circ[i].radius_m > 0.0f)
            points += circle_sides((double)circ[i].radius_m);
    *out = malloc((count ? count : 1u) * sizeof **out);
    if (points)
        *xy = malloc(2u * points * sizeof **xy);
    if (!*out || (points && !*xy)) {
        free(*out);
        free(*xy);
        *out = NULL;
        *xy = NULL;
        return -1;
    }
    for (i = 0; i < count; i++) {
        (*out)[i] = lines[i];
        if (!circ || !(circ[i].radius_m > 0.0f))
            continue;
        uint32_t n = circle_sides((double)circ[i].radius_m);
        float *p = *xy + 2u * at;
        for (k = 0; k < n; k++) {
            double a = TWO_PI * (double)k / (double)n;
            double r = (double)circ[i].radius_m;
            p[2u * k] = (float)((double)circ[i].center_x_m + r * cos(a));
            p[2u * k + 1u] = (float)((double)circ[i].center_y_m + r * sin(a));
        }
        (*out)[i].xy_m = p;
        (*out)[i].point_count = n;
        (*out)[i].closed = 1;
        at += n;
    }
    return 0;
}

void gtround_params(const polyc_polyline *lines, const polyc_circle *circ, uint32_t count,
                    uint32_t *vertices, uint32_t *params, uint32_t *arcs, uint32_t *circles)
{
    uint32_t i;
    *vertices = *params = *arcs = *circles = 0;
    for (i = 0; i < count; i++) {
        if (circ && circ[i].radius_m > 0.0f) {
            (*circles)++;
            *params += 3u;
        } else {
            *vertices += lines[i].point_count;
            *params += 2u * lines[i].point_count;
        }
    }
}
