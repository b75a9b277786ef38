/* gtround.h - maps with circles, for the scorers (tools/eval/gtscore.h and
 * the others take polylines): a circle's polyline stands in for it as a
 * polygon whose sides stray at most GTROUND_SAGITTA_M from the circle, so
 * that distances to it are the circle's; and the map's parameters, 2 a
 * vertex, 1 an arc, 3 a circle (docs/evaluation.md).
 * Memory: malloc; the caller frees what *out and *xy get.
 * SPDX-License-Identifier: MIT
 */
#ifndef GTROUND_H
#define GTROUND_H

#include <stdint.h>

#include "polyc.h"

#define GTROUND_SAGITTA_M 0.0001

/* circ[i].radius_m > 0: polyline i is that circle (circ may be NULL: none).
 * *out gets count polylines, the circles' as fine polygons (their points in
 * *xy, NULL when there is none). 0, or -1 out of memory. */
int gtround_lines(const polyc_polyline *lines, const polyc_circle *circ, uint32_t count,
                  polyc_polyline **out, float **xy);

/* The map's vertices (the polylines that are no circle), parameters, arcs
 * and circles. */
void gtround_params(const polyc_polyline *lines, const polyc_circle *circ, uint32_t count,
                    uint32_t *vertices, uint32_t *params, uint32_t *arcs, uint32_t *circles);

#endif /* GTROUND_H */
