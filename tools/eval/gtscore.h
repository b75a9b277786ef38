/* gtscore.h - score polyline maps against ground truth, as
 * docs/evaluation.md ("Scores") defines it.
 *
 * Takes: a ground-truth file (ideal, wall, seen lines; the format of
 * shared/data/sim/NAME.gt.txt) and a map as polyc_polyline records.
 * Gives:
 *   precision     the learned polylines sampled every 1 cm (every segment cut
 *                 into ceil(length / 1 cm) equal pieces, its start point and
 *                 the cut points; an open polyline adds its last point);
 *                 RMS, 95th percentile (nearest rank) and max of the
 *                 distance of those samples to the nearest true wall.
 *   completeness  share of `seen` samples within 5 cm (<=) of the map.
 *   compactness   vertices of the map (sum of point counts) against `ideal`;
 *                 parameters (2 a vertex, 1 an arc, 3 a circle) against
 *                 `ideal_params`.
 *   single scan   for one scan and a map: a reflected beam is one whose
 *                 range lies in [min_range_m, max_range_m) and is finite. It
 *                 HITS THE MAP if its ray, cast from the scan pose along the
 *                 beam direction, meets a map segment at a range r_map in
 *                 (0, max_range_m] of the scan (anywhere along the ray, not
 *                 only near the measured range). f = hits / reflected beams;
 *                 ray error = measured range - r_map of the FIRST segment
 *                 met; ray RMSE = sqrt(mean of ray error^2 over the hits).
 *   core precision the precision RMS over the samples within a given
 *                 distance of a true wall (the bench uses 0.5 m).
 *   points        share of scan endpoints (reflected beams) within D of a
 *                 map, for whole real logs without ground truth.
 *
 * All distance and ray queries go through gtscore_index, a uniform grid of
 * cells listing the segments that pass within the cell's circumscribed
 * circle, so a million points score in a fraction of a second.
 *
 * Memory: malloc in tools/; every *_free releases what its init/read made.
 * int returns: 0 on success, -1 on failure (out of memory, bad input).
 *
 * SPDX-License-Identifier: MIT
 */
#ifndef GTSCORE_H
#define GTSCORE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "polyc.h"

#define GTSCORE_SAMPLE_M 0.01      /* precision sampling step */
#define GTSCORE_COMPLETE_M 0.05    /* completeness tolerance */

/* ---- segment index ------------------------------------------------------- */

typedef struct gtscore_index {
    double *seg_m;             /* 4 per segment: x0 y0 x1 y1 */
    uint32_t seg_count, seg_cap;
    /* grid, valid after gtscore_index_build */
    double origin_x_m, origin_y_m, cell_m;
    uint32_t width, height;
    uint32_t *cell_start;      /* width * height + 1 offsets into cell_seg */
    uint32_t *cell_seg;        /* segment numbers, cell after cell */
} gtscore_index;

void gtscore_index_init(gtscore_index *index);
void gtscore_index_free(gtscore_index *index);
/* Adds the segments of one polyline (a single point adds a zero-length
 * segment so that it can still be found). */
int gtscore_index_add_f(gtscore_index *index, const float *xy_m, uint32_t point_count,
                        int closed);
int gtscore_index_add_d(gtscore_index *index, const double *xy_m, uint32_t point_count,
                        int closed);
int gtscore_index_add_polylines(gtscore_index *index, const polyc_polyline *lines,
                                uint32_t count);
/* Builds the grid; cell_m is a wish, enlarged so that the grid stays below
 * 4 M cells. Call again after adding more segments. */
int gtscore_index_build(gtscore_index *index, double cell_m);
/* Distance from (x, y) to the nearest segment. Exact when it is <= limit_m;
 * otherwise some value > limit_m (INFINITY when nothing was found).
 * limit_m = INFINITY asks for the exact distance however far. */
double gtscore_index_distance(const gtscore_index *index, double x_m, double y_m,
                              double limit_m);
/* The cells [cells[0], cells[2]] x [cells[1], cells[3]] (x, then y) that
 * meet the square of half-side r_m around (x, y): every segment within r_m
 * of the point is listed in one of them (a segment may be listed in
 * several). Returns 0, cells untouched, when the square misses the grid. */
int gtscore_index_box(const gtscore_index *index, double x_m, double y_m, double r_m,
                      uint32_t cells[4]);

/* Squared distance from (x, y) to the segment seg_m (x0 y0 x1 y1). */
double gtscore_segment_distance2(const double *seg_m, double x_m, double y_m);

/* Is a segment that `accept` takes (accept(ctx, segment index) != 0; NULL:
 * any) within r_m (squared distance <= r_m^2) of (x, y)? */
int gtscore_index_any_near(const gtscore_index *index, double x_m, double y_m, double r_m,
                           int (*accept)(const void *ctx, uint32_t seg), const void *ctx);

/* Range to the first segment met by the ray from (x, y) at angle_rad,
 * within (0, max_range_m]; INFINITY if none. */
double gtscore_index_ray(const gtscore_index *index, double x_m, double y_m, double angle_rad,
                         double max_range_m);

/* ---- ground truth --------------------------------------------------------- */

typedef struct gtscore_wall {
    uint32_t first_point;
    uint32_t point_count;
    uint32_t closed;
} gtscore_wall;

typedef struct gtscore_truth {
    double *wall_xy_m;         /* interleaved points of every wall */
    uint32_t wall_point_count, wall_point_cap;
    gtscore_wall *walls;
    uint32_t wall_count, wall_cap;
    double *seen_xy_m;
    uint32_t seen_count, seen_cap;
    uint32_t ideal;
    int has_ideal;
    /* ideal_params P A C: the perfect map's parameters with arcs and circles
     * (2 a vertex, 1 an arc, 3 a circle), its arcs and circles; absent in
     * older files (has_ideal_params 0) */
    uint32_t ideal_params, ideal_arcs, ideal_circles;
    int has_ideal_params;
    gtscore_index index;       /* the true walls, built by the reader */
} gtscore_truth;

/* Reads a .gt.txt stream. On failure returns -1 with "NAME:LINE: what"
 * in err (err_size bytes; err may be NULL); either way call
 * gtscore_truth_free. A file without walls is an error. */
int gtscore_truth_read(gtscore_truth *truth, FILE *f, const char *name, char *err,
                       size_t err_size);
int gtscore_truth_load(gtscore_truth *truth, const char *path, char *err, size_t err_size);
void gtscore_truth_free(gtscore_truth *truth);

/* ---- map scores ----------------------------------------------------------- */

typedef struct gtscore_map_score {
    double precision_rms_m;
    double precision_p95_m;
    double precision_max_m;
    uint64_t precision_samples;
    double completeness;       /* seen_covered / seen_count (1 if no samples) */
    uint32_t seen_count;
    uint32_t seen_covered;
    uint32_t vertices;         /* sum of point counts */
    uint32_t polylines;
    uint32_t ideal;            /* from the truth, 0 if absent */
    double vertex_ratio;       /* vertices / ideal (0 if no ideal) */
    /* the map's parameters: 2 a vertex, 1 an arc, 3 a circle (the
     * polylines the library gives today are straight segments only: 2 a
     * vertex, no arc, no circle) */
    uint32_t params, arcs, circles;
    uint32_t ideal_params;     /* from the truth, 0 if absent */
    double param_ratio;        /* params / ideal_params (0 if absent) */
} gtscore_map_score;

int gtscore_score_map(const gtscore_truth *truth, const polyc_polyline *lines,
                      uint32_t count, gtscore_map_score *out);

/* Core precision: the precision RMS over only the map's samples (as above)
 * that lie within core_m (<=) of a true wall, so that a map of data that
 * are no wall (a person who stood still, furniture not in the truth) does
 * not weigh on it. *rms_m = 0 when no sample is that near. */
int gtscore_core_precision(const gtscore_truth *truth, const polyc_polyline *lines,
                           uint32_t count, double core_m, double *rms_m);

/* ---- single-scan scores --------------------------------------------------- */

typedef struct gtscore_scan_score {
    uint64_t reflected;        /* beams with a return */
    uint64_t hits;             /* of those, beams whose ray meets the map */
    double sum_sq_m2;          /* sum of ray error^2 over the hits */
    double f;                  /* hits / reflected (0 if none reflected) */
    double ray_rmse_m;         /* sqrt(sum_sq_m2 / hits) (0 if no hits) */
} gtscore_scan_score;

/* Adds one scan's beams to *acc (start from a zeroed struct; several scans
 * may be accumulated) and updates acc->f and acc->ray_rmse_m. */
void gtscore_score_scan(const gtscore_index *map, const polyc_scan *scan,
                        gtscore_scan_score *acc);

/* The endpoints of the reflected beams (gtscore_beam_reflected) of `scans`,
 * in order: *xy_m gets a malloc'ed array of *count (x, y) pairs, and with
 * sensors_xy_m (may be NULL) another of each endpoint's scan pose (x, y);
 * the caller frees them (NULL when there are none). 0, or -1 for a NULL
 * argument or out of memory. */
int gtscore_scan_endpoints(const polyc_scan *scans, uint32_t scan_count, double **xy_m,
                           double **sensors_xy_m, uint64_t *count);

/* Endpoints of the reflected beams of `scans` within d_m (<=) of the map:
 * *within of *total. */
void gtscore_endpoints_within(const gtscore_index *map, const polyc_scan *scans,
                              uint32_t scan_count, double d_m, uint64_t *within,
                              uint64_t *total);

/* The line-fit floor of a simulated scene (tools/eval/gtfloor.c): the precision
 * RMS that straight lines fitted by least squares to each seen side of
 * each true wall segment would score, given these scans; *floor_m < 0 if no
 * side holds enough endpoints (the circles' 720-gons: 1 cm to 6 cm sides).
 * Returns -1 when out of memory. */
int gtscore_line_floor(const gtscore_truth *truth, const polyc_scan *scans, uint32_t scan_count,
                       double *floor_m);

/* The ideal-map fit of a simulated scene (tools/eval/gtfloor.c): the precision
 * RMS of the map `ideal` counts, one straight segment per run of seen
 * samples (>= 20 cm) on each true wall segment, each fitted by least
 * squares to the endpoints within 6 cm of its stretch, measured at the
 * run's seen samples. Unlike the line-fit floor, no line spans two runs (a
 * wall seen from two rooms is two runs, each with the pose errors of the
 * scans that saw it). *fit_m < 0 if no run qualifies (the circles).
 * Returns -1 when out of memory. */
int gtscore_ideal_fit(const gtscore_truth *truth, const polyc_scan *scans, uint32_t scan_count,
                      double *fit_m);

/* True if the beam is reflected (see the definition above). */
int gtscore_beam_reflected(const polyc_scan *scan, uint32_t beam);

#endif /* GTSCORE_H */
