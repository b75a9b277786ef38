/* polyc.h - learn compact polyline maps from aligned 2D laser scans.
 *
 * libpolyc implements Veeck & Burgard, "Learning Polyline Maps from Range
 * Scan Data Acquired with Mobile Robots" (IROS 2004): a hit/miss grid built
 * by ray casting, a contour of first-hit cells, traced into initial
 * polylines, then optimised by local search on a BIC score.
 *
 * Memory: the caller owns everything. polyc_memory_size() says how many
 * bytes a context needs for given limits; polyc_init() places the context
 * inside that caller block. The library never allocates, never does I/O and
 * keeps no global state: two contexts may be used from two threads.
 *
 * Units: metres, radians, counter-clockwise angles, in the frame of the poses.
 * Errors: every call returns a polyc_status; POLYC_OK is 0. After an error
 * the context stays valid; polyc_last_error() gives a static message.
 *
 * SPDX-License-Identifier: MIT
 */
#ifndef POLYC_H
#define POLYC_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define POLYC_VERSION_MAJOR 0
#define POLYC_VERSION_MINOR 2
#define POLYC_VERSION_PATCH 0
/* One number, comparable: major * 10000 + minor * 100 + patch. */
#define POLYC_VERSION (POLYC_VERSION_MAJOR * 10000 + POLYC_VERSION_MINOR * 100 + POLYC_VERSION_PATCH)

#if defined(POLYC_BUILD_SHARED) && defined(__GNUC__)
#define POLYC_API __attribute__((visibility("default")))
#else
#define POLYC_API
#endif

/* Status codes. Append-only: values never change meaning. */
typedef enum polyc_status {
    POLYC_OK = 0,
    POLYC_ERR_NULL = 1,      /* a required pointer was NULL */
    POLYC_ERR_CONFIG = 2,    /* a configuration or limit is out of range */
    POLYC_ERR_NOMEM = 3,     /* the memory block is too small for this work */
    POLYC_ERR_SCAN = 4,      /* a scan is malformed (see polyc_last_error) */
    POLYC_ERR_STATE = 5,     /* call out of order (e.g. results before build) */
    POLYC_ERR_EXTENT = 6,    /* the data span more than config.max_extent_m */
    POLYC_ERR_LIMIT = 7,     /* more scans or beams than the limits allow */
    POLYC_ERR_RANGE = 8,     /* an index argument is out of range */
    POLYC_ERR_STOPPED = 9,   /* the progress callback asked to stop (result kept) */
    POLYC_ERR_BUSY = 10      /* called on a context from inside its progress callback */
} polyc_status;

/* Flags of polyc_config.flags. */
#define POLYC_FLAG_EXACT_POINTS  0x1u /* keep every scan endpoint as its own data
                                         point instead of one weighted point per
                                         grid cell (slower, more memory) */
#define POLYC_FLAG_NO_GRAZING    0x2u /* count misses all the way to the hit, as
                                         the paper does (see docs/algorithm.md) */
#define POLYC_FLAG_GRID_TRACE    0x4u /* trace the grid's contour even for a
                                         single scan (by default one scan's
                                         initial polylines follow its beam order) */
#define POLYC_FLAG_NO_ARCS       0x8u /* no circles: every polyline stays
                                         polylines only (polyc_get_circle) */

typedef struct polyc_config {
    /* Grid (paper section III) */
    float cell_m;              /* grid resolution; paper 0.025 */
    float contour_threshold;   /* a cell is contour if m > this; paper 0.5 */
    float data_min_m;          /* an endpoint is a data point only if its cell
                                  has m >= this (rejects people, spurious hits) */
    float free_range_m;        /* a beam with no return marks free space up to
                                  this range (0: such beams are ignored) */
    float grazing_cells;       /* skip misses in the last grazing_cells/sin(incidence)
                                  cells before a hit (0 = off) */
    float max_extent_m;        /* refuse data spanning more than this, either axis;
                                  at most 10,000 (coordinates are floats relative
                                  to the first pose: their step stays below 1 mm) */
    /* Optimiser (paper section IV) */
    float alpha;               /* BIC weight of the error; paper 500 */
    float gamma;               /* weight of the angle prior; 0 = uniform prior */
    float merge_dist_m;        /* join polyline ends closer than this; paper 0.15 */
    float split_gap_m;         /* split segments with a data gap longer; paper 0.20 */
    float step_m;              /* hill-climbing step; paper 0.01; at most 0.025 */
    float noise_m;             /* initial std-dev of the vertex noise; paper 0.05 */
    float noise_decay;         /* noise std-dev factor per iteration, (0, 1] */
    float overlap_m;           /* polyline ends this close to another polyline are
                                  zipped onto it */
    float search_radius_m;     /* data farther than this from every segment costs
                                  as if at this distance (bounds the search) */
    uint32_t patience;         /* stop after this many iterations without a
                                  better BIC; paper 5 */
    uint32_t max_iterations;   /* hard cap on iterations (0 = no optimisation) */
    uint32_t flags;            /* POLYC_FLAG_* */
    uint32_t reserved;         /* must be 0 */
    uint64_t seed;             /* PRNG seed: same input and seed, same map */
    /* Occupancy grids (polyc_add_grid) */
    float occupied_thresh;     /* an occupancy-grid cell with value >= 100 * this is
                                  occupied; default 0.65 (map_server's) */
    float free_thresh;         /* a cell with 0 <= value <= 100 * this is free;
                                  default 0.196 (map_server's); must be < occupied_thresh */
} polyc_config;

/* Upper bounds that size the memory block. */
typedef struct polyc_limits {
    uint32_t max_scans;        /* scans that may be added */
    uint32_t max_beams;        /* beams, summed over all scans */
    uint32_t max_grid_cells;   /* grid cells the map may touch (allocated in
                                  tiles of 32 x 32 cells as beams reach them) */
    uint32_t max_vertices;     /* polyline vertices (0: max_beams + 1024, enough
                                  for any contour) */
    uint32_t max_points;       /* weighted data points (0: max_beams, enough
                                  for any input) */
} polyc_limits;

/* One scan, as the laser saw it. Beam i points at
 * pose_theta_rad + start_angle_rad + i * angle_step_rad. A range outside
 * [min_range_m, max_range_m) is a beam with no return (free space only). */
typedef struct polyc_scan {
    double pose_x_m;
    double pose_y_m;
    double pose_theta_rad;
    float start_angle_rad;
    float angle_step_rad;
    float min_range_m;
    float max_range_m;
    uint32_t beam_count;
    uint32_t reserved;         /* must be 0 */
    const float *range_m;      /* beam_count ranges; copied by polyc_add_scan */
} polyc_scan;

/* Axis-aligned box in metres. */
typedef struct polyc_box {
    double min_x_m, min_y_m, max_x_m, max_y_m;
} polyc_box;

/* An occupancy grid shaped like ROS nav_msgs/OccupancyGrid: cell (column i,
 * row j) is cells[j * width + i]; row 0 is at the origin, columns run along
 * the origin's x axis (yaw origin_yaw_rad), rows along its y axis. The
 * origin pose is that of cell (0, 0)'s outer corner, as in map_server.
 * Values: -1 unknown, 0..100 occupancy (others are refused). `cells` is only
 * read during the call that takes it. */
typedef struct polyc_occupancy_grid {
    uint32_t width;            /* cells along x */
    uint32_t height;           /* cells along y */
    float resolution_m;        /* metres per cell, > 0 */
    uint32_t reserved;         /* must be 0 */
    double origin_x_m;         /* pose of cell (0, 0)'s corner */
    double origin_y_m;
    double origin_yaw_rad;
    const int8_t *cells;       /* width * height values, row-major */
} polyc_occupancy_grid;

/* One polyline of the result; points belong to the context and stay valid
 * until the next call that changes the map (build, optimise, reset). */
typedef struct polyc_polyline {
    const float *xy_m;         /* point_count (x, y) pairs, interleaved */
    uint32_t point_count;
    uint32_t closed;           /* 1: the last point connects to the first */
} polyc_polyline;

/* A polyline of the result that the BIC prefers as a circle
 * (polyc_get_circle): its centre and radius, and how far the polyline
 * itself (what polyc_get_polyline gives) strays from the circle at most. */
typedef struct polyc_circle {
    float center_x_m, center_y_m;
    float radius_m;            /* 0: the polyline is no circle */
    float polyline_dev_m;
    uint32_t same_as;          /* the polyline given as the circle: this one's
                                  index, or for a ring the search left in
                                  pieces one piece's, the same for all */
} polyc_circle;

typedef struct polyc_stats {
    uint64_t beams;            /* beams added */
    uint64_t beams_skipped;    /* beams dropped: NaN/inf range (counted, not data) */
    uint64_t hits;             /* beams that returned inside the valid interval */
    uint64_t data_points;      /* endpoints kept as data (hits in non-free cells) */
    uint64_t memory_used_bytes;/* high-water mark of the block */
    uint64_t memory_size_bytes;/* size of the block */
    uint64_t grid_bytes;       /* memory the grid took (directory and tiles) */
    double bic;                /* BIC of the current map (after optimise) */
    double error_sq_m2;        /* sum of squared point distances (current map) */
    uint32_t scans;
    uint32_t grid_width;       /* grid size in cells */
    uint32_t grid_height;
    uint32_t grid_tiles;       /* tiles stored (those where some beam ends in a hit) */
    uint32_t contour_cells;
    uint32_t initial_polylines;
    uint32_t initial_vertices;
    uint32_t polylines;        /* current map */
    uint32_t vertices;
    uint32_t weighted_points;  /* data points as stored (cells or raw) */
    uint32_t iterations;       /* optimiser iterations run */
    uint32_t reserved;
} polyc_stats;

/* What the optimiser reports after each iteration (the paper's Fig. 10). */
typedef struct polyc_iteration {
    uint32_t iteration;
    uint32_t vertices;
    uint32_t polylines;
    uint32_t reserved;
    double bic;                /* BIC of the model at the end of this iteration */
    double best_bic;           /* best BIC so far */
    double noise_m;            /* vertex noise used in this iteration */
} polyc_iteration;

/* Called after each optimiser iteration; return non-zero to stop (the best
 * map so far is kept and polyc_optimize returns POLYC_ERR_STOPPED). This is
 * how a caller imposes a deadline: the library has no clock. While it runs,
 * every call on the same context returns POLYC_ERR_BUSY and changes nothing
 * (polyc_polyline_count returns 0); other contexts may be used. */
typedef int (*polyc_progress_fn)(void *user, const polyc_iteration *it);

typedef struct polyc_ctx polyc_ctx;

/* Version of the library actually linked (POLYC_VERSION format). */
POLYC_API uint32_t polyc_version(void);
/* Static, never NULL. */
POLYC_API const char *polyc_status_str(polyc_status status);
/* sizeof of the public struct named by `name` ("polyc_config", "polyc_limits",
 * "polyc_scan", "polyc_box", "polyc_polyline", "polyc_stats",
 * "polyc_iteration", "polyc_occupancy_grid", "polyc_online_limits",
 * "polyc_online_report", "polyc_change"), 0 if unknown: lets bindings
 * detect ABI drift. */
POLYC_API size_t polyc_struct_size(const char *name);

/* The paper's parameters and this library's defaults. */
POLYC_API void polyc_config_default(polyc_config *config);
/* POLYC_OK or POLYC_ERR_CONFIG; *why (if not NULL) names the bad field. */
POLYC_API polyc_status polyc_config_check(const polyc_config *config, const char **why);

/* Limits for a known set of scans: counts and a grid bound from the extent
 * of their endpoints (the same rule the grid uses). Pure; no memory.
 * Vertices and weighted points are sized for a usual contour: the lesser of
 * a quarter of the beams and one cell in 64 of the bounding box, plus 4096
 * (1.25 times that for the points; small inputs are covered whole). A map
 * that needs more fails with POLYC_ERR_NOMEM in polyc_trace or
 * polyc_optimize: retry with max_vertices and max_points 0 (worst case). */
POLYC_API polyc_status polyc_limits_for_scans(const polyc_config *config,
                                              const polyc_scan *scans, uint32_t scan_count,
                                              polyc_limits *out);
/* Extends *box by the endpoints and pose of one scan (the extent rule). */
POLYC_API void polyc_scan_extent(const polyc_config *config, const polyc_scan *scan,
                                 polyc_box *box);

/* Limits for mapping one occupancy grid (counts its occupied cells). Pure. */
POLYC_API polyc_status polyc_limits_for_grid(const polyc_config *config,
                                             const polyc_occupancy_grid *grid,
                                             polyc_limits *out);

/* Bytes needed for a context with these limits; 0 if config or limits are
 * invalid or the size would overflow size_t. */
POLYC_API size_t polyc_memory_size(const polyc_config *config, const polyc_limits *limits);

/* Places a context in `block` (any alignment; `size` bytes, owned by the
 * caller and untouched outside). The block must stay alive while the
 * context is used; there is nothing to free. Copies config and limits. */
POLYC_API polyc_status polyc_init(void *block, size_t size, const polyc_config *config,
                                  const polyc_limits *limits, polyc_ctx **out);
/* Forget scans and results; keep config, limits and block. */
POLYC_API polyc_status polyc_reset(polyc_ctx *ctx);

/* Copies one scan in. POLYC_ERR_SCAN for bad geometry (NaN pose, angles
 * not finite, |angle_step_rad| > 6.2832 or |start_angle_rad| > 100, a zero
 * step with more than one beam, an empty range interval). A negative step is
 * a clockwise scan and is taken as it is. beam_count 0 is allowed and adds
 * nothing; NaN/inf ranges are counted in stats.beams_skipped. */
POLYC_API polyc_status polyc_add_scan(polyc_ctx *ctx, const polyc_scan *scan);

/* Takes the grid's occupied and free cells as the map's evidence; then
 * polyc_build (or trace + optimize) works as for scans. One grid per context;
 * a context that holds scans refuses a grid and the other way round
 * (POLYC_ERR_STATE). POLYC_ERR_CONFIG for a bad resolution, size or value,
 * POLYC_ERR_NOMEM / POLYC_ERR_LIMIT if the block or limits are too small. */
POLYC_API polyc_status polyc_add_grid(polyc_ctx *ctx, const polyc_occupancy_grid *grid);
/* Grids, in detail. polyc_limits_for_grid gives max_scans 0, max_beams,
 * max_points the occupied cells (each is one data point and at most one
 * contour cell), max_vertices that + 1024, max_grid_cells the 32 x 32-cell
 * tiles that hold an occupied cell (at least a quarter of all the grid's
 * tiles, for their directory). More occupied cells than max_beams is
 * POLYC_ERR_LIMIT, more tiles than max_grid_cells POLYC_ERR_NOMEM; cells
 * NULL is POLYC_ERR_NULL; a grid wider or taller than config.max_extent_m is
 * POLYC_ERR_EXTENT. The polylines come in the map frame (the origin pose
 * applied); polyc_grid_info gives the origin corner and the resolution,
 * polyc_grid_cell hits 1 for an occupied cell, misses 1 for a free one (in
 * tiles within four cells of an occupied cell), contour 1 for an occupied
 * cell that faces free space (a free cell at most four cells away along a
 * row or a column, only unknown cells between). The optimiser's data are those cells' centres; it
 * weighs a grid's squared distances by alpha (0.05 / resolution_m)^2, splits
 * only where a gap lies in free cells, searches at least 3 cells and has no
 * angle prior (gamma unused): docs/algorithm.md, "From an occupancy grid". */

/* Stage by stage (each runs the earlier ones if needed), or all at once. */
POLYC_API polyc_status polyc_build_grid(polyc_ctx *ctx);   /* hit/miss grid */
POLYC_API polyc_status polyc_extract_contour(polyc_ctx *ctx);
POLYC_API polyc_status polyc_trace(polyc_ctx *ctx);        /* initial polylines */
/* Optimise the current polylines; progress may be NULL. If it fails once
 * the search has started (POLYC_ERR_NOMEM), the best map found so far is
 * the result, as after POLYC_ERR_STOPPED. */
POLYC_API polyc_status polyc_optimize(polyc_ctx *ctx, polyc_progress_fn progress, void *user);
/* build_grid + extract_contour + trace + optimize (if max_iterations > 0). */
POLYC_API polyc_status polyc_build(polyc_ctx *ctx, polyc_progress_fn progress, void *user);

/* Results: the current map. */
POLYC_API uint32_t polyc_polyline_count(const polyc_ctx *ctx);
POLYC_API polyc_status polyc_get_polyline(const polyc_ctx *ctx, uint32_t index,
                                          polyc_polyline *out);
/* Copies polyline `index` into xy_m (2 * capacity floats); *count gets its
 * point count. xy_m may be NULL to ask for the count only. */
POLYC_API polyc_status polyc_copy_polyline(const polyc_ctx *ctx, uint32_t index, float *xy_m,
                                           uint32_t capacity, uint32_t *count,
                                           uint32_t *closed);
/* Round things: which polylines of the current map are circles, and which
 * runs of their segments are arcs. A polyline that goes round (closed, or
 * its ends nearer than split_gap_m) becomes a circle where its own points,
 * held all round with no stretch over split_gap_m without one, fit a
 * circle at a lower BIC than the polyline's (3 numbers against 2 a
 * vertex); in the others, a run of segments that turn one way by small
 * angles becomes one arc between its end vertices where its points fit the
 * arc at a lower BIC (1 number, the bulge, against the vertices inside the
 * run; docs/algorithm.md, "Circles and arcs"). Call after polyc_build or
 * polyc_optimize (an online context: after any update or the finish); a
 * call that changes the map forgets them. None with POLYC_FLAG_NO_ARCS.
 * POLYC_ERR_STATE before polyc_trace; POLYC_ERR_NOMEM if the block cannot
 * hold the optimiser again. */
POLYC_API polyc_status polyc_find_curves(polyc_ctx *ctx);
/* Whether polyline `index` is a circle (polyc_find_curves): out->radius_m
 * > 0 and its centre, or radius_m 0. polyc_get_polyline still gives the
 * polyline, which strays at most out->polyline_dev_m from the circle. A
 * circle may stand for several polylines (the pieces of a ring): each gets
 * it, with out->same_as the same piece's index for all. polyc_circle_count: how
 * many circles there are (each once). */
POLYC_API polyc_status polyc_get_circle(const polyc_ctx *ctx, uint32_t index, polyc_circle *out);
POLYC_API uint32_t polyc_circle_count(const polyc_ctx *ctx);
/* Polyline `index` with its arcs (polyc_find_curves): its vertices that
 * bound a straight segment or an arc into xy_m (2 * capacity floats), and
 * per segment its bulge into bulges (capacity floats): tan of a quarter of
 * the arc's angle, > 0 when the arc runs counter-clockwise from the
 * segment's first vertex to its second (y up), 0 for a straight segment, as
 * DXF's LWPOLYLINE stores it; *count gets the vertices (count - 1 bulges for
 * an open polyline, count for a closed one, the last then 0: its closing
 * segment is straight). A polyline without arcs comes out as
 * polyc_copy_polyline gives it, every bulge 0. xy_m and bulges may be NULL
 * to ask for the count only; POLYC_ERR_NOMEM if capacity is too small.
 * polyc_arc_count: the arcs of the whole map. */
POLYC_API polyc_status polyc_copy_arcs(const polyc_ctx *ctx, uint32_t index, float *xy_m,
                                       float *bulges, uint32_t capacity, uint32_t *count,
                                       uint32_t *closed);
POLYC_API uint32_t polyc_arc_count(const polyc_ctx *ctx);
POLYC_API polyc_status polyc_get_stats(const polyc_ctx *ctx, polyc_stats *out);
/* Current BIC of the map and its parts, recomputed from scratch. */
POLYC_API polyc_status polyc_score(polyc_ctx *ctx, double *bic, double *error_sq_m2);

/* The grid (after polyc_build_grid): origin of cell (0, 0)'s lower-left
 * corner, size, and one cell's counters. Only tiles of 32 x 32 cells where
 * some beam ends in a hit are stored: elsewhere (and in cells never reached)
 * hits and misses read 0. */
POLYC_API polyc_status polyc_grid_info(const polyc_ctx *ctx, double *origin_x_m,
                                       double *origin_y_m, float *cell_m, uint32_t *width,
                                       uint32_t *height);
POLYC_API polyc_status polyc_grid_cell(const polyc_ctx *ctx, uint32_t ix, uint32_t iy,
                                       uint32_t *hits, uint32_t *misses, uint32_t *contour);

/* ---- Online mapping: the map kept up to date as scans arrive ----
 *
 * An online context accumulates each scan into its grid, its data and its
 * angle prior as the scan is added, and keeps the map between calls: an
 * update re-optimises, within a work budget, the regions the new scans
 * changed (nearest the latest pose and oldest first) and leaves the rest.
 * Between updates the map is a valid map of the scans so far (no crossing,
 * no doubled wall). Memory grows with the mapped area, not with the number
 * of scans: the block is sized from an area (a square centred on the first
 * scan's pose) and from bounds on cells, vertices and data cells. The
 * results (polyc_polyline_count, polyc_get_polyline, polyc_get_stats) read
 * the map as the last update or finish left it. docs/api.md, "Online". */
typedef struct polyc_online_limits {
    double area_m;             /* side of the square the map may span, centred
                                  on the first scan's pose; at most twice
                                  config.max_extent_m */
    uint32_t max_grid_cells;   /* grid cells stored (tiles of 32 x 32 cells where
                                  some beam ended in a hit) */
    uint32_t max_vertices;     /* polyline vertices of the map */
    uint32_t max_points;       /* grid cells holding endpoints (each keeps their
                                  sums); the weighted data points (a 2 x 2 block
                                  of cells each) are bounded by half of it */
    uint32_t max_scan_beams;   /* beams in one scan */
    uint32_t keep_scans;       /* scans kept for pose corrections (0: none) */
    uint32_t keep_beams;       /* beams of the kept scans, in all */
    uint32_t reserved;         /* must be 0 */
} polyc_online_limits;

/* What an update or finish did and where the map stands. */
typedef struct polyc_online_report {
    uint64_t version;          /* the map's version (0: no update yet); every
                                  update that changes the map adds one */
    uint64_t work;             /* work units this call spent */
    uint32_t scans;            /* scans added so far */
    uint32_t pending_scans;    /* scans added since the last update */
    uint32_t backlog_tiles;    /* changed regions (tiles) not yet re-optimised */
    uint32_t changed;          /* polylines this call added, modified or removed */
    uint32_t polylines;
    uint32_t vertices;
    double bic;                /* BIC of the map against the data so far */
} polyc_online_report;

/* One entry of polyc_online_changes. */
typedef struct polyc_change {
    uint32_t id;               /* the polyline's id (polyc_polyline_id) */
    uint32_t kind;             /* POLYC_CHANGE_* */
    uint64_t version;          /* the version that made this change */
} polyc_change;
#define POLYC_CHANGE_ADDED 1u
#define POLYC_CHANGE_MODIFIED 2u
#define POLYC_CHANGE_REMOVED 3u

/* The default work budget of an update, in units: an update with a long
 * backlog uses it up; most updates need far less. A unit is one weighted
 * data point taken into a re-optimised region (docs/api.md). What a unit
 * costs in time depends on the machine: measure it, or see the times at
 * this default in docs/performance.md, "Online". */
#define POLYC_ONLINE_WORK_DEFAULT 8000u

/* Limits for an area of side area_m (metres) and scans of up to
 * max_scan_beams beams, keeping no scans: grid cells, data cells and
 * vertices for a usual building in that square (docs/api.md, "Online").
 * Pure. POLYC_ERR_EXTENT for a side over twice config.max_extent_m. */
POLYC_API polyc_status polyc_online_limits_for_area(const polyc_config *config, double area_m,
                                                    uint32_t max_scan_beams,
                                                    polyc_online_limits *out);
/* Bytes needed for an online context; 0 if config or limits are invalid. */
POLYC_API size_t polyc_online_memory_size(const polyc_config *config,
                                          const polyc_online_limits *limits);
/* Places an online context in `block`, as polyc_init does. The batch calls
 * (polyc_add_scan, polyc_build, ...) refuse it with POLYC_ERR_STATE. */
POLYC_API polyc_status polyc_online_init(void *block, size_t size, const polyc_config *config,
                                         const polyc_online_limits *limits, polyc_ctx **out);
/* Adds one scan to the grid, the data and the prior (a cast of its beams,
 * no search: docs/performance.md, "Online", gives the time an add takes);
 * the map changes only at the next update.
 * The scan's pose and endpoints must lie more than 1 m inside the area's
 * square (vertices may wander past the data).
 * keep != 0 keeps the scan for polyc_online_correct (POLYC_ERR_LIMIT when
 * keep_scans or keep_beams are used up; the scan is then not added).
 * *scan_id (may be NULL) gets its number: 0 for the first scan added.
 * POLYC_ERR_EXTENT when an endpoint or the pose lies outside the area
 * (nothing is added), POLYC_ERR_LIMIT when the scan has more than
 * max_scan_beams beams, POLYC_ERR_NOMEM when the grid cells are used up
 * (the scan is added up to the beam that ran out) or when its endpoints
 * would outgrow the data cells or the points an update makes of them
 * (limits.max_points: nothing of it is added, and the updates still run). */
POLYC_API polyc_status polyc_online_add_scan(polyc_ctx *ctx, const polyc_scan *scan, int keep,
                                             uint32_t *scan_id);
/* Re-optimises what the scans added or corrected since the last update
 * changed, spending at most about `work` units (POLYC_ONLINE_WORK_DEFAULT;
 * 0 is POLYC_ERR_CONFIG); what does not fit stays in the backlog for the
 * next update. Waiting pose corrections count against the budget (a unit
 * per two beams they cast); an update they spent it in does nothing else
 * (its report: their units, the version unchanged). The same scans and
 * budgets give the same map. Before any scan: POLYC_ERR_STATE. out may be
 * NULL. */
POLYC_API polyc_status polyc_online_update(polyc_ctx *ctx, uint64_t work,
                                           polyc_online_report *out);
/* Converges the map as a batch build would: the backlog, then the full
 * search (noise, patience) from the current map, its noise starting two
 * decays in (docs/api.md). Scans may be added after it; progress as for
 * polyc_optimize. */
POLYC_API polyc_status polyc_online_finish(polyc_ctx *ctx, polyc_progress_fn progress, void *user,
                                           polyc_online_report *out);
/* Gives kept scan `scan_id` a new pose (after a loop closure). The pose
 * waits; the next update, finish or add applies every waiting correction:
 * the scans' hits, misses and data leave the grid exactly and come back at
 * their new poses (with every scan kept and at least half of them moved,
 * every kept scan is counted afresh), their contour is cast, and the
 * regions both poses saw are re-optimised by the updates. An error there
 * (POLYC_ERR_NOMEM: the new poses' tiles) is that call's.
 * POLYC_ERR_RANGE for a scan that is not kept (or unknown). */
POLYC_API polyc_status polyc_online_correct(polyc_ctx *ctx, uint32_t scan_id, double pose_x_m,
                                            double pose_y_m, double pose_theta_rad);
/* The polylines added, modified or removed by the versions after `since`,
 * one entry per polyline (its latest change), ids ascending: up to `cap`
 * into out (may be NULL with cap 0), the number there are into *count.
 * POLYC_ERR_RANGE when removals that old are no longer remembered (the
 * caller then reads the whole map again). */
POLYC_API polyc_status polyc_online_changes(const polyc_ctx *ctx, uint64_t since,
                                            polyc_change *out, uint32_t cap, uint32_t *count);
/* The id of polyline `index` of the current map: it stays the same while
 * that polyline lives (moves, added or removed vertices), on online and
 * batch contexts alike; a polyline split or merged keeps its id on one
 * part. Ids start at 1 and are not reused. */
POLYC_API polyc_status polyc_polyline_id(const polyc_ctx *ctx, uint32_t index, uint32_t *id);
/* The online context's map version (0 for a batch context). */
POLYC_API uint64_t polyc_online_version(const polyc_ctx *ctx);

/* The static message of the first error of the last failed call ("" if the
 * last call succeeded); for a rejected scan it says what was wrong with it,
 * and the scan is the one that polyc_add_scan was given. */
POLYC_API const char *polyc_last_error(const polyc_ctx *ctx);

#ifdef __cplusplus
}
#endif
#endif /* POLYC_H */
