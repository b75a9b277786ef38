/* opt_harness.h - the optimiser's test harness (tests/opt_harness.c),
 * shared by tests/test_opt_*.c: a context built through the public API on a
 * 4 x 3 m room seen from three poses (analytic ranges), traced, with an
 * optimiser state set up by polyc__opt_setup as polyc_optimize does; data
 * points and polylines replaced by hand-made ones; and the oracles, which
 * compare the incremental books with a recomputation from scratch: the
 * library's checkers (src/search/checks.c, compiled into every test_opt_* suite). */
#ifndef OPT_HARNESS_H
#define OPT_HARNESS_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cost.h"
#include "optimize.h"

#define PI_D 3.14159265358979323846
#define BEAMS 360
#define N_POSES 3
#define ROOM_X0 (-2.0)
#define ROOM_Y0 (-1.5)
#define ROOM_X1 2.0
#define ROOM_Y1 1.5
#define MAX_PTS 1080            /* synthetic data points a test may use (raw points) */

typedef struct fixture {
    polyc_scan scans[N_POSES];
    float ranges[N_POSES][BEAMS];
    polyc_config cfg;
    void *block;
    polyc_ctx *ctx;
    polyc__opt o;
    int32_t pt_cap;             /* points the per-point arrays hold */
} fixture;

/* a growing list of synthetic points */
typedef struct ptlist {
    float xy[2 * MAX_PTS];
    int n;
} ptlist;


/* range from (px, py) along (c, s) to the walls of the room */
double room_range(double px, double py, double c, double s);

/* 360 beams over the full circle; noise_m > 0 adds a small deterministic
 * ripple (no randomness: the same ranges on every run) */
void make_scans(fixture *f, float noise_m);

void check_st(polyc_status st, const polyc_ctx *ctx, const char *what);

/* A context with the room's scans, built up to the initial polylines. */
void fx_context(fixture *f, float gamma, float noise_m, uint32_t flags);

/* The optimiser state as polyc_optimize makes it: the arena rewound to the
 * end of the trace, then polyc__opt_setup (points, hash, prior, scores). */
void fx_setup_opt(fixture *f);

void fx_open(fixture *f, float gamma, float noise_m, uint32_t flags);

/* For hand-made cases: raw points (so that the per-point arrays hold one
 * per beam, 1080), the prior as learned from the room (gamma 0 unless set). */
void fx_open_hand(fixture *f, float gamma);

void fx_close(fixture *f);

/* ---- hand-made data and polylines ---- */
/* Replaces the data points by unit points at xy (n of them), sorted by
 * bucket as points.c sorts them; the per-point arrays were sized for the
 * room's points, so the new set must not be larger (checked). Each point is
 * seen from seen_xy (its sensor's position, 2 per point), or from nowhere
 * known when seen_xy is NULL. */
void set_points_seen(fixture *f, const float *xy, const float *seen_xy, int n);

void set_points(fixture *f, const float *xy, int n);

/* points every step_m along a-b, both ends included */
void pts_line(ptlist *p, float ax, float ay, float bx, float by, float step_m);

void clear_lines(polyc__opt *o);

/* a polyline through n points of xy; returns its id */
int32_t add_line(polyc__opt *o, const float *xy, int n, int closed);

/* A hand case: points every 1 cm along a straight wall from (-1, 0) to
 * (1, 0), no polylines yet. */
void open_straight_wall(fixture *f, ptlist *p);

void rebuild(polyc__opt *o);

/* ---- inspecting the map ---- */
int live_lines(const polyc__opt *o);

/* the live polyline with an end (head or tail) at (x, y) within 1 mm, or NONE */
int32_t line_with_end(const polyc__opt *o, float x, float y);

/* distance from (x, y) to the nearest live vertex */
float nearest_vertex(const polyc__opt *o, float x, float y);

void dump_map(const polyc__opt *o, const char *title);

/* ---- from-scratch checks ---- */
int seg_live(const polyc__opt *o, int32_t v);

/* nearest segment over every live segment, capped at w R^2 as the score is */
double brute_nearest(const polyc__opt *o, const polyc__point *p, int32_t *seg);

int close_rel(double a, double b, double rel);
/* The library computes in float: two ways to one cost or BIC (incremental
 * and from scratch, moments and points) agree to float's rounding, about
 * 1e-7 of the value; 1e-5 leaves room for sums of thousands of terms. */
#define FLOAT_REL 1e-5

/* Linked lists, line ids, counts, ends, live counts. */
void check_store(const polyc__opt *o, const char *where);



/* Walks every bucket: each entry is a live segment marked in the hash; each
 * live segment is in exactly the buckets its path crosses, once per visit. */
void check_hash(polyc__opt *o, const char *where);

/* The incremental books against a recomputation from scratch: the
 * library's checkers (src/search/checks.c) where they are built in, then the
 * test's own, which say more about a failure. */
void check_books(polyc__opt *o, const char *where);

/* BIC of the current map recomputed from scratch */
double scratch_bic(polyc__opt *o);

/* ---- random edits ---- */
double urand(polyc__rng *r);

int32_t irand(polyc__rng *r, int32_t n);

/* a random live vertex (with a segment after it when want_seg), or NONE */
int32_t pick_vertex(const polyc__opt *o, polyc__rng *r, int want_seg);

/* a random open end: a tail (want_tail) or a head */
int32_t pick_end(const polyc__opt *o, polyc__rng *r, int want_tail);

/* One elementary edit inside the current change; returns its name. */
const char *basic_edit(polyc__opt *o, polyc__rng *r);

/* One random step: an edit, a batch of edits, an operator or noise. */
const char *random_step(polyc__opt *o, polyc__rng *r);

/* point at arc length t along the room's walls, counter-clockwise from
 * its lower-left corner */
void perimeter_at(double t, float *x, float *y);

/* A start map for random edits: five open polylines along the walls with a
 * vertex every 8 cm (1 cm jitter), small gaps between them, two of them
 * running clockwise; one has 88 vertices (more segments than a change
 * lists). About 170 vertices. */
void make_start_map(polyc__opt *o, polyc__rng *r);

/* Random steps from the start map, rebuilt when fewer than 40 vertices are
 * left; the books are checked after every step. */
void run_random(polyc__opt *o, uint64_t seed, int steps);

/* the polyline's vertices in order (either direction), against xy, within
 * tol metres (0: exact) */
void assert_line_near(const polyc__opt *o, int32_t l, const float *xy, int n, float tol);

void assert_line_is(const polyc__opt *o, int32_t l, const float *xy, int n);

/* the longest stretch of segment samples (every 1 cm) with no data point
 * within 5 cm, over the whole map, metres */
double longest_unsupported(const polyc__opt *o);

/* Hand-made beams on the fixture's optimiser, as a single scan would set
 * them: `count` beams from (x, y), the first at `base` rad, `step` apart. */
polyc__rays *set_rays(polyc__opt *o, float x, float y, float base, float step,
                             const float *range, int32_t count);

#endif
