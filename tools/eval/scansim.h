/* scansim.h - a small deterministic 2D laser simulator for tests, examples
 * and benchmarks.
 *
 * Takes: a scene (walls as polylines, a trajectory of true poses, a laser,
 * noise settings, people walking through). Gives: polyc_scan records as a
 * laser would report them, a CARMEN ROBOTLASER1 log and a ground-truth file
 * in the format of shared/data/sim/NAME.gt.txt (ideal, wall, seen).
 *
 * Deterministic: one seed gives the same scans. The random stream is
 * splitmix64 (exact integer arithmetic on every platform); Gaussian noise is
 * Box-Muller on top of it (log, sqrt, cos from libm, so bitwise identity of
 * the float ranges needs a libm that rounds the same; the mm-rounded log text
 * is the same on every glibc/musl/macOS we know of).
 *
 * Memory: a scene owns malloc'ed arrays; scansim_scene_free() releases them.
 * Functions returning int give 0 on success, -1 on bad arguments or when
 * malloc fails (the scene stays valid, nothing half-added).
 *
 * SPDX-License-Identifier: MIT
 */
#ifndef SCANSIM_H
#define SCANSIM_H

#include <stdint.h>
#include <stdio.h>

#include "polyc.h"

/* ---- random numbers ---------------------------------------------------- */

typedef struct scansim_rng {
    uint64_t state;
    double spare;     /* second Box-Muller value, valid if has_spare */
    int has_spare;
} scansim_rng;

void scansim_rng_seed(scansim_rng *rng, uint64_t seed);
uint64_t scansim_rng_u64(scansim_rng *rng);
/* Uniform in [0, 1), 53 bits. */
double scansim_rng_uniform(scansim_rng *rng);
/* Standard normal (mean 0, std-dev 1). */
double scansim_rng_gauss(scansim_rng *rng);

/* ---- scene ------------------------------------------------------------- */

/* Beam i points at pose_theta + start_angle_rad + i * angle_step_rad. */
typedef struct scansim_laser {
    uint32_t beam_count;
    float start_angle_rad;
    float angle_step_rad;
    float min_range_m;        /* reported in polyc_scan; hits closer are kept */
    float max_range_m;        /* a wall farther away gives no return */
    float range_sigma_m;      /* Gaussian range noise */
    float dropout;            /* share of beams that return nothing, [0, 1] */
} scansim_laser;

typedef struct scansim_pose {
    double x_m;
    double y_m;
    double theta_rad;
} scansim_pose;

/* A disc that walks in a straight line from `from` to `to` during scans
 * first_scan..last_scan (inclusive) and is absent from every other scan. */
typedef struct scansim_person {
    double from_x_m, from_y_m;
    double to_x_m, to_y_m;
    double radius_m;
    uint32_t first_scan;
    uint32_t last_scan;
} scansim_person;

/* A wall: points wall_xy_m[2*first_point ..] of the scene, point_count of
 * them; closed: the last point connects to the first. */
typedef struct scansim_wall {
    uint32_t first_point;
    uint32_t point_count;
    uint32_t closed;
} scansim_wall;

typedef struct scansim_scene {
    char name[32];
    uint64_t seed;
    scansim_laser laser;
    double pose_sigma_m;       /* alignment noise of the logged pose */
    double pose_sigma_rad;
    /* Drift of the logged pose (off while both rates are 0), on top of the
     * alignment noise: an error (x, y, heading) that starts at 0 and, over
     * each step between two poses of d metres, grows as dead reckoning's
     * does: the step is turned by the heading error, the position error
     * takes a Gaussian of std-dev drift_m_per_m x sqrt(d) per axis, the
     * heading error one of drift_rad_per_m x sqrt(d). Every drift_reset_m
     * metres travelled (0: never) the error is scaled by drift_keep, as a
     * scan matcher pulls it back towards zero. A stream of its own (from
     * the seed), so that the other draws are those of a scene without
     * drift. The ground truth (seen samples, ideal) follows the true
     * poses. */
    double drift_m_per_m;
    double drift_rad_per_m;
    double drift_reset_m;
    double drift_keep;

    double *wall_xy_m;         /* interleaved x, y */
    uint8_t *wall_smooth;      /* per wall point: 1 where the wall runs through it
                                  on a curve (an arc's or a circle's sample, not
                                  a corner), as scansim_add_wall_smooth gives */
    uint32_t wall_point_count, wall_point_cap;
    scansim_wall *walls;
    uint32_t wall_count, wall_cap;
    scansim_pose *poses;       /* true laser poses, one scan each */
    uint32_t pose_count, pose_cap;
    scansim_person *people;
    uint32_t person_count, person_cap;

    /* Filled by scansim_run (freed and refilled by each run). */
    polyc_scan *scans;         /* scan_count scans; pose = logged (noisy) pose */
    float *range_m;            /* scan_count * beam_count ranges; a beam with
                                  no return reads exactly max_range_m */
    uint32_t scan_count;
    uint64_t hit_count;        /* beams that returned a wall or a person */
    double *sample_xy_m;       /* wall samples every <= 2 cm, along each wall */
    uint8_t *sample_seen;      /* 1: some beam observed this sample */
    uint8_t *sample_corner;    /* 1: this sample is a corner of its wall */
    uint8_t *sample_smooth;    /* 1: this sample is a smooth point of its wall */
    uint32_t *wall_first_sample; /* per wall, index of its first sample */
    double *wall_box;          /* per wall: x0 y0 x1 y1 round its points (a ray
                                  that misses it skips the wall's segments) */
    uint32_t *wall_sample_count;
    uint32_t sample_count;
} scansim_scene;

/* An empty scene with the defaults: 181 beams over 180 degrees, 8 m range,
 * 1 cm range noise, 0.3% dropout, 1 cm / 0.2 degree pose noise. */
void scansim_scene_init(scansim_scene *scene, const char *name, uint64_t seed);
void scansim_scene_free(scansim_scene *scene);

int scansim_add_wall(scansim_scene *scene, const double *xy_m, uint32_t point_count,
                     int closed);
/* A wall whose points flagged in smooth[] (point_count of them; NULL: none)
 * lie on a curve that runs through them: samples of an arc or a circle,
 * not corners. The truth's parameters count the curve between two corners
 * as one arc (scansim_ideal_params); the scans see the polygon, so its
 * sides must be short enough to stand for the curve (scansim_arc_points). */
int scansim_add_wall_smooth(scansim_scene *scene, const double *xy_m, uint32_t point_count,
                            int closed, const uint8_t *smooth);
/* Points on the arc of radius r about (cx, cy) from angle a0 to a1 (either
 * way round), both ends included, spaced so that a side strays at most
 * SCANSIM_ARC_SAGITTA_M from the arc; returns the count written to xy (at
 * most max; fewer points when max is too small). */
#define SCANSIM_ARC_SAGITTA_M 0.0001
uint32_t scansim_arc_points(double *xy, uint32_t max, double cx, double cy, double r, double a0,
                            double a1);
/* count >= 2 points evenly spaced on that arc, both ends included */
void scansim_arc_fill(double *xy, uint32_t count, double cx, double cy, double r, double a0,
                      double a1);
/* A closed regular polygon of `sides` points approximating a circle (its
 * points smooth: the truth holds a circle). */
int scansim_add_circle(scansim_scene *scene, double cx_m, double cy_m, double radius_m,
                       uint32_t sides);
/* A closed rectangle, axis-aligned in the scene's frame (for thick walls). */
int scansim_add_box(scansim_scene *scene, double x0_m, double y0_m, double x1_m,
                    double y1_m);
int scansim_add_pose(scansim_scene *scene, double x_m, double y_m, double theta_rad);
/* Poses every spacing_m along the waypoint polyline (first waypoint
 * included), each facing the direction of travel. */
int scansim_add_path(scansim_scene *scene, const double *xy_m, uint32_t waypoint_count,
                     double spacing_m);
int scansim_add_person(scansim_scene *scene, const scansim_person *person);
/* Rotates the whole scene (walls, poses, people) by angle_rad about the
 * origin, then shifts it: used to put walls off the grid axes. */
void scansim_transform(scansim_scene *scene, double angle_rad, double dx_m, double dy_m);

/* Built-in scenes: "square", "office", "angled", "circle" (fixed layouts;
 * the seed drives the noise only) and the randomised kinds "hall",
 * "shelves", "flat", "curved", "thinwalls", with drifting poses "drift",
 * "farhall", and with round things "pillars", "arcwalls", "roundmix" (the
 * seed also draws the layout, furniture, people, rotation and shift). -1
 * if unknown. */
int scansim_scene_builtin(scansim_scene *scene, const char *name, uint64_t seed);
/* NULL-terminated list of the built-in names. */
const char *const *scansim_builtin_names(void);

/* The randomised kinds (tools/eval/scansim_kinds.c), as scansim_scene_builtin
 * calls them: each fills a scene fresh from scansim_scene_init from its
 * scene->seed. 0, or -1 when out of memory. */
int scansim_kind_hall(scansim_scene *scene);
int scansim_kind_shelves(scansim_scene *scene);
int scansim_kind_flat(scansim_scene *scene);
int scansim_kind_curved(scansim_scene *scene);
int scansim_kind_thinwalls(scansim_scene *scene);
int scansim_kind_drift(scansim_scene *scene);
int scansim_kind_farhall(scansim_scene *scene);
/* with round things (tools/eval/scansim_round.c): true arcs and circles */
int scansim_kind_pillars(scansim_scene *scene);
int scansim_kind_arcwalls(scansim_scene *scene);
int scansim_kind_roundmix(scansim_scene *scene);

/* Keeps every step-th pose (0, step, 2 step, ...) and moves the people's
 * scan intervals with them: a smaller scene of the same layout, for tests.
 * Call before scansim_run. -1 if step is 0. */
int scansim_keep_every(scansim_scene *scene, uint32_t step);
/* The smallest distance from any true pose to any wall segment (INFINITY
 * without poses or walls): how close the robot comes to a wall. */
double scansim_path_clearance(const scansim_scene *scene);

/* Distance in metres from (px, py) to the segment from a to b (x, y). */
double scansim_point_segment_m(double px, double py, const double *a, const double *b);

/* ---- simulation -------------------------------------------------------- */

/* First intersection of the ray from (x, y) at angle_rad with the walls and
 * with the people present in scan `scan_index` (UINT32_MAX: no people).
 * Returns the range, or INFINITY if nothing is hit; *object (may be NULL)
 * gets the wall segment index (see scansim_segment_count order), -2 for a
 * person, -1 for nothing. */
double scansim_cast(const scansim_scene *scene, double x_m, double y_m, double angle_rad,
                    uint32_t scan_index, int32_t *object);
/* Number of wall segments (a closed wall of n points has n, an open one n-1). */
uint32_t scansim_segment_count(const scansim_scene *scene);

/* Simulates one scan per pose: fills scans, range_m, sample_seen. */
int scansim_run(scansim_scene *scene);

/* Vertices of a perfect map of the seen walls (after scansim_run): every
 * stretch seen over >= 20 cm counts its two ends and its corners; a closed
 * wall seen all round counts its corners. */
uint32_t scansim_ideal_vertices(const scansim_scene *scene);
/* Parameters of a perfect map of the seen walls with arcs and circles
 * (after scansim_run): 2 per vertex (the ends of every stretch seen over
 * >= 20 cm and the corners inside it), 1 per arc (a piece between two of
 * those vertices that runs through a smooth point and strays over
 * SCANSIM_ARC_MIN_SAGITTA_M from its chord: less, and a line fits it as
 * well as the scores can tell), 3 per circle (a closed wall of smooth
 * points seen all round). *arcs and *circles (may be NULL) get their
 * counts. */
#define SCANSIM_ARC_MIN_SAGITTA_M 0.001
uint32_t scansim_ideal_params(const scansim_scene *scene, uint32_t *arcs, uint32_t *circles);
/* Number of seen samples (after scansim_run). */
uint32_t scansim_seen_count(const scansim_scene *scene);

/* ROBOTLASER1 lines, one per scan, ranges in mm precision. 0 or -1 (I/O). */
int scansim_write_log(const scansim_scene *scene, FILE *out);
/* The ground truth (ideal, wall, seen). 0 or -1 (I/O). */
int scansim_write_gt(const scansim_scene *scene, FILE *out);
/* Both, to files; 0 or -1 with errno set. */
int scansim_save(const scansim_scene *scene, const char *log_path, const char *gt_path);

#endif /* SCANSIM_H */
