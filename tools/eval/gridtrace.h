/* gridtrace.h - the baseline the benchmark compares the library with: what
 * users do with OpenCV today, findContours + approxPolyDP at one cell,
 * written in C.
 *
 * Takes: an occupancy grid (polyc_occupancy_grid; a cell is occupied when
 * its value >= occupied_min). Gives: one closed polyline per border of the
 * 8-connected occupied regions, through the centres of the border cells,
 * each simplified by Douglas-Peucker.
 * Borders: Suzuki & Abe's border following (1985; OpenCV's findContours),
 * outer borders and hole borders alike (findContours' RETR_LIST: a room's
 * wall ring gives the ring's outside and its inside), each traced once as
 * the sequence of its cells' centres (a one-cell-wide wall is walked out
 * and back). A lone cell is a polyline of one point, a border of two cells
 * an open one of two.
 * Simplification (approxPolyDP on a closed curve): split at the border's
 * first cell and the cell farthest from it; Douglas-Peucker on each half
 * keeps a point whose distance to the segment between its chain's kept
 * ends is over epsilon_m.
 *
 * Memory: gridtrace_run mallocs; gridtrace_free releases. int returns: 0,
 * or -1 (out of memory, a grid over 2^28 cells, epsilon_m < 0).
 *
 * SPDX-License-Identifier: MIT
 */
#ifndef GRIDTRACE_H
#define GRIDTRACE_H

#include <stdint.h>

#include "polyc.h"

typedef struct gridtrace_map {
    polyc_polyline *lines;     /* line_count polylines, points in xy_m */
    uint32_t line_count;
    float *xy_m;               /* every vertex, polyline after polyline */
    uint64_t vertices;         /* sum of the point counts */
    uint64_t border_cells;     /* border points traced, before simplification */
} gridtrace_map;

int gridtrace_run(const polyc_occupancy_grid *g, int8_t occupied_min, double epsilon_m,
                  gridtrace_map *out);
void gridtrace_free(gridtrace_map *m);

#endif /* GRIDTRACE_H */
