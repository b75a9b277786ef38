/* curves.h - a map with its round things as the library gives them
 * (polyc_find_curves): each polyline in its arc form (the vertices that
 * bound a straight segment or an arc, and per segment its bulge) or as a
 * circle; and the same map flattened, every curve as a polyline whose sides
 * stray at most a given distance from it (for writers and readers that take
 * lines only, and for the scorers).
 * Memory: malloc; curves_free releases a map.
 * SPDX-License-Identifier: MIT
 */
#ifndef POLYC_CURVES_H
#define POLYC_CURVES_H

#include <stdint.h>

#include "polyc.h"

typedef struct curves_map {
    uint32_t count;
    polyc_polyline *lines;     /* per polyline its arc form (polyc_copy_arcs) */
    float *xy;                 /* their points */
    float *bulge;              /* per point: the bulge of the segment from it (NULL: none) */
    polyc_circle *circ;        /* per polyline: radius_m > 0, it is that circle (NULL: none) */
    uint32_t arcs, circles;
} curves_map;

/* The context's map with its curves (polyc_find_curves, unless no_curves:
 * its polylines as they are) into m (which holds nothing yet: zeroed, or
 * curves_free'd); the library's status, or POLYC_ERR_NOMEM when malloc
 * fails. curves_free either way. */
polyc_status curves_from_ctx(polyc_ctx *ctx, int no_curves, curves_map *m);
void curves_free(curves_map *m);

/* The bulges of polyline i, NULL when it has no arc. */
const float *curves_bulges(const curves_map *m, uint32_t i);

/* m's polylines with every circle and arc as a polyline whose sides stray
 * at most sagitta_m from it (a circle: 8 sides or more, at its first piece;
 * its other pieces get no point): *out gets count polylines, their points
 * in *xy (the caller frees both). 0, or -1 out of memory. */
int curves_flatten(const curves_map *m, double sagitta_m, polyc_polyline **out, float **xy);

/* The arc from a to b of bulge b as its centre, radius, start angle and
 * signed sweep (radians; > 0 counter-clockwise). */
void curves_arc(const float *a, const float *b, double bulge, double *cx, double *cy, double *r,
                double *a0, double *sweep);

#endif /* POLYC_CURVES_H */
