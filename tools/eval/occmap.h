/* occmap.h - an occupancy mapper for the evaluation: scans in, a
 * map_server-style OccupancyGrid out, as a SLAM front end with a known
 * pose would build it.
 *
 * Takes: aligned scans (polyc_scan) and a configuration. Gives: an int8
 * OccupancyGrid (row 0 at the bottom, origin yaw 0) ready for
 * polyc_add_grid, and the log-odds behind it.
 * Rule: per beam, every cell its ray crosses before its end (exact cell
 * traversal, Amanatides & Woo 1987, from the scan pose) adds miss_logodds
 * (-0.4); the cell of a reflected beam's endpoint adds hit_logodds (+0.85)
 * and no miss. A beam without return (gtscore_beam_reflected false, range
 * finite or not) adds misses up to free_range_m (10 m, as the library's
 * free_range_m), its last cell included; free_range_m 0 skips such beams.
 * No clamping. A cell's probability is p = 1 - 1 / (1 + exp(L)); then
 * nav2 map_saver's trinary: p > occupied_p (0.65) is 100, p < free_p
 * (0.196) is 0, anything else (and a cell no beam reached) -1.
 * Extent: the box of the scan poses and the reflected endpoints, widened
 * by one cell and snapped to whole cells from (0, 0); rays are cut where
 * they leave it (a no-return beam may reach beyond the data, as in the
 * library, whose no-return misses stay inside the data's extent).
 *
 * Memory: occmap_build mallocs; occmap_free releases. int returns: 0, or -1
 * (out of memory, no scans, a grid over OCCMAP_MAX_CELLS cells, bad
 * configuration).
 *
 * SPDX-License-Identifier: MIT
 */
#ifndef OCCMAP_H
#define OCCMAP_H

#include <stdint.h>

#include "polyc.h"

#define OCCMAP_MAX_CELLS (1u << 28)

typedef struct occmap_config {
    double resolution_m;       /* cell size; default 0.05 */
    double hit_logodds;        /* default +0.85 */
    double miss_logodds;       /* default -0.4 */
    double free_range_m;       /* no-return beams: misses this far; 0: skipped */
    double occupied_p;         /* p above this: 100 (default 0.65) */
    double free_p;             /* p below this: 0 (default 0.196) */
} occmap_config;

typedef struct occmap {
    uint32_t width, height;
    double resolution_m;
    double origin_x_m, origin_y_m;  /* cell (0, 0)'s lower-left corner */
    float *logodds;            /* width * height, row-major, row 0 at the bottom */
    int8_t *cells;             /* the trinary values, same order */
    uint32_t *touched;         /* beams that reached each cell (hit or miss) */
    uint64_t occupied, free_cells, unknown;
} occmap;

void occmap_config_default(occmap_config *c);
int occmap_build(occmap *m, const occmap_config *c, const polyc_scan *scans, uint32_t n);
void occmap_free(occmap *m);

/* The map as the library takes it (cells stay owned by m). */
void occmap_grid(const occmap *m, polyc_occupancy_grid *g);

/* p = 1 - 1 / (1 + exp(L)), and the trinary value of L under c. */
double occmap_probability(double logodds);
int8_t occmap_value(const occmap_config *c, double logodds);

/* The centres of a grid's cells with value >= min_value (x, y pairs in the
 * map frame, the origin's yaw applied): *xy_m malloc'ed (NULL when none),
 * *count of them. Returns -1 if out of memory. */
int occmap_cell_points(const polyc_occupancy_grid *g, int8_t min_value, double **xy_m,
                       uint64_t *count);

#endif /* OCCMAP_H */
