/* gtband.h - bands of a polyline map: one wall drawn as several parallel
 * lines a few cm apart, all seen from the same side, as a band of scan
 * endpoints (pose error) turns into; and the share of the scan endpoints
 * near the map. No ground truth needed.
 *
 * Takes: a map as polyc_polyline records and data points, each with the
 * position of the sensor that saw it (the endpoints of a log's reflected
 * beams and their scans' poses, gtband_scan_points).
 * Segments, samples and neighbours as gttopo.h defines them: every segment
 * cut into ceil(length / 1 cm) equal pieces, its start point and the cut
 * points (a sample stands for the piece it starts); neighbours are two
 * segments of one polyline that share a vertex (round a closed one).
 * Gives:
 *   map_length_m    the sum of the segment lengths.
 *   points, within_5, within_10, within_20
 *                   the data points, and those within 5 / 10 / 20 cm (<=)
 *                   of the map: end5 = within_5 / points (as
 *                   gtscore_endpoints_within counts it), end10, end20.
 *   sided_segments  segments that have a side. A segment's side: each data
 *                   point within 10 cm (<=) of the map belongs to its
 *                   nearest segment (ties: the lowest segment number) and
 *                   votes the sign of (its sensor - the segment's start) .
 *                   the segment's left normal; the side is the sign of the
 *                   votes' sum (none when it is 0, when no point belongs to
 *                   the segment, or when the segment has no length). The
 *                   segment's facing normal: its left normal times its side
 *                   (the normal towards the sensors that saw it).
 *   band_m          band15: a sample is band-doubled when a segment that
 *                   is neither its own nor a neighbour of its own lies
 *                   within 15 cm (<=) of it, runs parallel to its own
 *                   within 20 degrees (either direction), and both have a
 *                   side with facing normals that agree (dot > 0); band_m
 *                   is the sum of the lengths of the runs of consecutive
 *                   band-doubled samples of one segment that are longer
 *                   than 20 cm (to within 1 micrometre; a run's length:
 *                   its samples' count x the segment's spacing).
 * A thin wall seen from both sides is two lines with opposite facing
 * normals, so it does not count; a door recess or a 10 cm step makes runs
 * shorter than 20 cm.
 *
 * Queries go through gtscore_index (gtindex.c), built over the map.
 * Memory: malloc, released before return. int returns: 0 on success, -1
 * out of memory or bad input (NULL arrays with nonzero counts, more than
 * 2^32 - 1 segments).
 *
 * SPDX-License-Identifier: MIT
 */
#ifndef GTBAND_H
#define GTBAND_H

#include <stdint.h>

#include "polyc.h"

#define GTBAND_SIDE_M 0.10      /* a point votes for its nearest segment this near */
#define GTBAND_REACH_M 0.15     /* another segment this near doubles a sample */
#define GTBAND_ANGLE_DEG 20.0   /* if parallel within this */
#define GTBAND_RUN_M 0.20       /* runs that count: longer than this */

typedef struct gtband_score {
    double map_length_m;
    double band_m;             /* band15 */
    uint64_t points;
    uint64_t within_5, within_10, within_20;
    uint32_t sided_segments;
} gtband_score;

/* Each run band15 counts, as gtband_score_map_runs finds it: its start and
 * end on the segment (x0, y0, x1, y1, metres) and its length. */
typedef void (*gtband_run_fn)(void *user, const double run_xy_m[4], double length_m);

/* Scores the map `lines` (count records) against point_count data points:
 * points_xy_m and sensors_xy_m hold x, y interleaved, the point and the
 * position it was seen from (both may be NULL when point_count is 0: no
 * segment has a side). *out is zeroed first. */
int gtband_score_map(const polyc_polyline *lines, uint32_t count, const double *points_xy_m,
                     const double *sensors_xy_m, uint64_t point_count, gtband_score *out);

/* The same, and each run that band15 counts to run(user, ...) (none when
 * run is NULL), segment by segment in the index's order: where a map is
 * drawn as a band, to look at. */
int gtband_score_map_runs(const polyc_polyline *lines, uint32_t count, const double *points_xy_m,
                          const double *sensors_xy_m, uint64_t point_count, gtband_score *out,
                          gtband_run_fn run, void *user);

/* The endpoints of the reflected beams (gtscore_beam_reflected) of `scans`
 * in gttopo_scan_points' order, and for each its scan's pose (x, y): two
 * malloc'ed arrays of *count (x, y) pairs that the caller frees (both NULL
 * when there are none). */
int gtband_scan_points(const polyc_scan *scans, uint32_t scan_count, double **xy_m,
                       double **sensors_xy_m, uint64_t *count);

/* The share of the data points within 5, 10, 20 cm; 0 when there is none. */
double gtband_share(uint64_t within, uint64_t points);

#endif /* GTBAND_H */
