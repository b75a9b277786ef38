/* gtround.h - maps with circles and arcs for the scorers
 * (tools/eval/gtscore.h and the others take polylines): the library's map
 * with its curves (tools/curves.h), and the same with every curve a
 * polyline whose sides stray at most GTROUND_SAGITTA_M from it, so that
 * distances to it are the curve's; and the map's parameters, 2 a vertex, 1
 * an arc, 3 a circle (docs/evaluation.md).
 * Memory: malloc; gtround_free releases a map.
 * SPDX-License-Identifier: MIT
 */
#ifndef GTROUND_H
#define GTROUND_H

#include <stdint.h>

#include "curves.h"
#include "polyc.h"

#define GTROUND_SAGITTA_M 0.0001

typedef struct gtround_map {
    curves_map map;            /* the map as the library gives it */
    polyc_polyline *scored;    /* what the scorers take: the curves flattened */
    float *scored_xy;
    uint32_t count;
} gtround_map;

/* The context's current map with its curves into m; the library's status,
 * or POLYC_ERR_NOMEM; gtround_free either way. */
polyc_status gtround_from_ctx(polyc_ctx *ctx, gtround_map *m);
/* m->map set by the caller: the scored polylines. 0, or -1 out of memory. */
int gtround_score(gtround_map *m);
void gtround_free(gtround_map *m);

/* The map's vertices (of the polylines that are no circle, in their arc
 * form), parameters, arcs and circles. */
void gtround_params(const gtround_map *m, uint32_t *vertices, uint32_t *params, uint32_t *arcs,
                    uint32_t *circles);

#endif /* GTROUND_H */
