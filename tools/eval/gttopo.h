/* gttopo.h - topology figures of a polyline map, measured against the map
 * itself and a set of data points (no ground truth needed).
 *
 * Takes: a map as polyc_polyline records and an array of data points
 * (x, y in metres: the endpoints of a log's reflected beams, or any other
 * data such as the occupied cells of an occupancy map).
 * Samples: the map sampled as the precision of gtscore.h samples it, every
 * segment cut into ceil(length / 1 cm) equal pieces, its start point and
 * the cut points; an open polyline adds its last point. A sample stands for
 * the piece it starts (its segment's sample spacing, length / pieces); the
 * last point of an open polyline stands for no length.
 * Neighbours: two segments of one polyline that share a vertex (wrapping
 * round a closed one). A closed polyline of fewer than 3 points is open.
 * Gives:
 *   map_length_m    the sum of the segment lengths.
 *   double_cover_m  a sample is doubly covered when a segment that is
 *                   neither its own nor a neighbour of its own lies within
 *                   5 cm (<=) of it; the sum of the lengths of the runs of
 *                   consecutive doubly covered samples of one segment that
 *                   are longer than 20 cm (a run's length: its samples'
 *                   count x the segment's spacing).
 *   crossings       pairs of segments, not neighbours, that cross properly
 *                   (each has the other's ends strictly on both sides) at a
 *                   point at least 1 cm from all four segment ends.
 *   unsupported_20, unsupported_10
 *                   runs of consecutive samples with no data point within
 *                   5 cm (<=); a run continues across the vertices of its
 *                   polyline and round a closed one; runs longer than 20 cm,
 *                   and (counted separately, so including those) than 10 cm.
 *   loose_ends      ends of open polylines (of 2 or more points) whose
 *                   nearest other part of the map lies 3 cm to 15 cm (both
 *                   included) away. Other parts: the segments of other
 *                   polylines, and those of its own polyline that it
 *                   reaches only after 15 cm or more along itself from that
 *                   end (so a short end segment does not make its own
 *                   polyline's previous segment a near miss, but a polyline
 *                   that bends back to within 15 cm of its end does).
 * "Longer than" is strict, to within 1 micrometre (float vertices).
 *
 * Queries go through gtscore_index (gtindex.c), built over the map: each
 * sample looks for segments in the cells near it, each data point marks
 * the samples within 5 cm of it on the segments near it, and crossings
 * test the pairs listed in one cell, each pair once (in the cell holding
 * the crossing).
 *
 * Memory: malloc, released before return. int returns: 0 on success, -1
 * out of memory or bad input (NULL arrays with nonzero counts, non-finite
 * coordinates, more than 2^32 - 1 samples).
 *
 * SPDX-License-Identifier: MIT
 */
#ifndef GTTOPO_H
#define GTTOPO_H

#include <stdint.h>

#include "polyc.h"

#define GTTOPO_COVER_M 0.05     /* double cover and support reach */
#define GTTOPO_RUN_M 0.20       /* runs that count: longer than this */
#define GTTOPO_SHORT_RUN_M 0.10 /* the second unsupported-run threshold */
#define GTTOPO_CROSS_END_M 0.01 /* a crossing this near a segment end does not count */
#define GTTOPO_LOOSE_MIN_M 0.03 /* a loose end's gap: from */
#define GTTOPO_LOOSE_MAX_M 0.15 /* to */

typedef struct gttopo_score {
    double map_length_m;
    double double_cover_m;
    uint32_t crossings;
    uint32_t unsupported_20;
    uint32_t unsupported_10;
    uint32_t loose_ends;
} gttopo_score;

/* Scores the map `lines` (count records) against point_count data points
 * (points_xy_m: x, y interleaved; may be NULL when point_count is 0: every
 * sample is then unsupported). *out is zeroed first. */
int gttopo_score_map(const polyc_polyline *lines, uint32_t count, const double *points_xy_m,
                     uint64_t point_count, gttopo_score *out);

/* The endpoints of the reflected beams (gtscore_beam_reflected) of `scans`:
 * *xy_m gets a malloc'ed array of *count (x, y) pairs that the caller
 * frees (NULL when there are none). */
int gttopo_scan_points(const polyc_scan *scans, uint32_t scan_count, double **xy_m,
                       uint64_t *count);

#endif /* GTTOPO_H */
