/* stages.h - the calls of the library's stages and helpers on the types of
 * internal.h (which includes it last): configuration and the API's
 * boundary, the grid, the contour, the polyline store, the trace, the
 * optimiser's budget. Never installed. */
#ifndef POLYC_STAGES_H
#define POLYC_STAGES_H

#include "internal.h"

/* context.c: what is wrong with a scan's geometry (a static message), or NULL */
const char *polyc__scan_problem(const polyc_scan *s);

/* boundary.c: the API's doubles in and out (the library computes in float).
 * A pose is usable (finite, within 10,000 km); the extent rule (the pose
 * and every reflected endpoint, frame shifted by ox, oy) grows box[4] = min
 * x, min y, max x, max y (have: it holds something); a box's spans in x
 * and y (0: empty) */
int polyc__pose_ok(double x, double y, double th);
void polyc__extent_add(const polyc_scan *s, double ox, double oy, double *box, int *have);
int polyc__box_spans(const polyc_box *box, float *w, float *h);
float polyc__narrow(double v); /* a double of the API (an area, a limit) as a float */
void polyc__frame_set(polyc_ctx *ctx, double x_m, double y_m);
float polyc__heading(double theta_rad); /* a pose's heading in [-pi, pi] */
void polyc__frame_scan(const polyc_ctx *ctx, const polyc_scan *s, polyc__scan *d);
void polyc__frame_grid_origin(const polyc_ctx *ctx, polyc__grid *g, float x0_m, float y0_m);
int polyc__frame_inside(const polyc_ctx *ctx, const polyc_scan *s, float half_m);
void polyc__frame_box(const polyc_ctx *ctx, float box[4]); /* the data's extent, frame metres */
void polyc__frame_export(polyc_ctx *ctx);
/* a frame point (x, y) in the caller's frame, as the result's points are */
void polyc__frame_point_out(const polyc_ctx *ctx, float x, float y, float *out_x, float *out_y);
void polyc__frame_of_grid(polyc_ctx *ctx, const polyc_occupancy_grid *grid);
int polyc__grid_origin_ok(const polyc_occupancy_grid *grid);
void polyc__figures_out(float bic, float err, double *bic_out, double *err_out);
void polyc__figures_iteration(polyc_iteration *rep, float bic, float best_bic, float noise_m);

/* grid.c */
/* entries the grid's tile directory may have under the limits */
size_t polyc__grid_dir_cap(const polyc_limits *lim);
size_t polyc__grid_budget_bytes(const polyc_limits *lim);
/* the budget, on a counting arena */
void polyc__grid_reserve(polyc__arena *a, const polyc_limits *lim);
polyc_status polyc__grid_build(polyc_ctx *ctx);
/* a grid over a square of side_m centred on the frame origin, with no
 * tile yet (online); one scan counted into it, or taken back (a pose
 * correction); with on_hits (per tile, may be NULL) the misses in cells
 * with hits tallied, with records (g->rec) the misses in the tiles not
 * stored kept there */
polyc_status polyc__grid_online_init(polyc_ctx *ctx, float side_m, uint32_t max_cells);
polyc_status polyc__grid_add_scan(polyc_ctx *ctx, const polyc__scan *s, int take_back,
                                  uint32_t *on_hits);
/* the tiles the scan's hits end in wanted (stored when a beam reaches
 * them), before any scan is counted again */
void polyc__grid_want(polyc_ctx *ctx, const polyc__scan *s);
/* one scan in as a batch counts it, its misses in tiles not stored left
 * out (the tiles wanted first) */
polyc_status polyc__grid_recount_scan(polyc_ctx *ctx, const polyc__scan *s);
/* the directory entry of the tile of cell (ix, iy), inside the grid */
static inline size_t polyc__dir_index(const polyc__grid *g, int32_t ix, int32_t iy)
{
    size_t tx = (size_t)(ix >> POLYC__TILE_SHIFT), ty = (size_t)(iy >> POLYC__TILE_SHIFT);
    return ty * (size_t)g->tiles_x + tx;
}
/* A cell's two counters saturate by halving both, which keeps m = h/(h+m). */
static inline void polyc__count_inc(polyc__count *a, polyc__count *b)
{
    if (*a == POLYC__COUNT_MAX) {
        *a = (polyc__count)(*a >> 1);
        *b = (polyc__count)(*b >> 1);
    }
    (*a)++;
}
/* A scan taken back (an online pose correction): exact unless the cell
 * saturated since, then never below 0. */
static inline void polyc__count_dec(polyc__count *a)
{
    if (*a > 0)
        (*a)--;
}
polyc__tile *polyc__grid_tile(const polyc__grid *g, int32_t ix, int32_t iy);
/* NULL for cells outside the grid or in tiles not stored (no beam ends in a
 * hit there: free space or never reached) */
inline int polyc__cell_index(int32_t ix, int32_t iy)
{
    return ((iy & (POLYC__TILE_SIDE - 1)) << POLYC__TILE_SHIFT) | (ix & (POLYC__TILE_SIDE - 1));
}
/* one scan's beams (ray_check.c): a segment may not stand in front of a
 * return, nor behind one of its own returns, by more than this along the
 * beam; scan_chains.c links hits across beams whose return is in front of
 * the link by more than this */
#define POLYC__RAY_TOLERANCE_M 0.10f

/* min and max of two floats that are not NaN: fminf and fmaxf are libm
 * calls on x86-64 (their NaN rules keep the compiler from using minss) */
static inline float polyc__minf(float a, float b)
{
    return a < b ? a : b;
}
static inline float polyc__maxf(float a, float b)
{
    return a > b ? a : b;
}
/* The angle between two directions in [0, pi] from their cross and dot
 * products, as atan2f(|cross|, dot) to within 2e-6 rad. Ours, not libm's:
 * it is about three times faster where the optimiser prices every trial
 * move's turns, and plain float arithmetic gives the same result with every
 * libm (the build does not contract it into fused multiply-adds). */
static inline float polyc__turn_rad(float cross, float dot)
{
    float ax = dot < 0.0f ? -dot : dot, ay = cross < 0.0f ? -cross : cross;
    float hi = ax > ay ? ax : ay, lo = ax > ay ? ay : ax;
    if (!(hi > 0.0f))
        return 0.0f; /* a zero-length side; NaN, too, counts as straight */
    float t = lo / hi, t2 = t * t;
    float r = t * (0.99997726f +
                   t2 * (-0.33262347f + t2 * (0.19354346f + t2 * (-0.11643287f +
                                                                 t2 * (0.05265332f + t2 * -0.01172120f)))));
    if (ay > ax)
        r = 1.57079633f - r;
    return dot < 0.0f ? 3.14159265f - r : r;
}
/* m > threshold, evaluated without division: hits > t * (hits + misses) */
int polyc__cell_occupied(const polyc__tile *t, int idx, float threshold);
/* the data rule: a cell with hits that the grid does not judge free,
 * m >= data_min (config.data_min_m: points.c's data points, contour.c's
 * fallback); inline, for points.c's passes over every cell */
static inline int polyc__cell_holds_data(const polyc__tile *t, int idx, float data_min)
{
    unsigned h = t->hits[idx], m = t->misses[idx];
    return h > 0 && (float)h >= data_min * (float)(h + m);
}
/* contour.c: whether cell (ix, iy) holds data with no occupied cell near
 * it, which the end of a reflection that met no occupied cell labels as
 * contour (`bits`: the tiles' marks hold the occupied cells, as in the
 * contour pass; else from the counts) */
int polyc__contour_data_alone(const polyc_ctx *ctx, int32_t ix, int32_t iy, int bits);
/* beam geometry shared by the grid and contour passes */
typedef struct polyc__beam {
    float sx, sy, ex, ey;          /* grid coordinates (cells) of sensor and end */
    int hit;                       /* the end is a reflection */
    float miss_end;                /* misses stop at this fraction of the beam */
} polyc__beam;
int polyc__beam_get(const polyc_ctx *ctx, const polyc__scan *s, uint32_t i, polyc__beam *b);
/* the same without miss_end (left at 1): for passes that only follow the path */
int polyc__beam_path(const polyc_ctx *ctx, const polyc__scan *s, uint32_t i, polyc__beam *b);
/* cos and sin of a scan's angular step */
typedef struct polyc__step_rot {
    float cs, sn;
} polyc__step_rot;
/* polyc__beam_get with the step's cos and sin given (a pass over a scan) */
int polyc__beam_turned(const polyc_ctx *ctx, const polyc__scan *s, uint32_t i, polyc__beam *b,
                       const polyc__step_rot *rot);
/* Exact traversal (Amanatides-Woo) of the cells from the sensor to the end;
 * visit gets each cell with the beam parameter at which the beam enters it
 * and `last` set for the end cell; a non-zero return stops the walk. */
typedef int (*polyc__cell_fn)(void *u, int32_t ix, int32_t iy, float t_enter, int last);
void polyc__traverse(const polyc__beam *b, polyc__cell_fn visit, void *u);
/* walk.h's polyc__walk_start, _key_at and _skip_tiles out of line (grid.c:
 * one copy in the library for the walks that are not the grid's count) */
void polyc__grid_walk_start(struct polyc__walk *w, const polyc__beam *b);
int64_t polyc__grid_walk_key_at(const struct polyc__walk *w, float t);
int polyc__grid_walk_skip_tiles(struct polyc__walk *w, int32_t width, int32_t height, int32_t tiles_x,
                                const uint32_t *stop);

/* occupancy.c: the grid and contour stages of an occupancy grid, at once */
polyc_status polyc__occ_add(polyc_ctx *ctx, const polyc_occupancy_grid *grid);
/* 1 if the cell at (x, y), in the optimiser's frame, is a free cell of the
 * grid; a cell outside the stored tiles reads as unknown */
int polyc__occ_free_at(const polyc_ctx *ctx, float x, float y);
/* An occupied cell faces free space if a free cell lies this many cells or
 * fewer along a row or a column, with only unknown cells between */
#define POLYC__FACE_CELLS 4

/* contour.c */
/* the contour list (limits.max_beams + 1 cells) */
int32_t *polyc__contour_list(polyc__arena *a, const polyc_limits *lim);
/* the stage's allocations under the limits, on a counting arena; and their peak */
void polyc__contour_reserve(polyc__arena *a, const polyc_limits *lim);
size_t polyc__contour_bytes(const polyc_limits *lim);
polyc_status polyc__contour_build(polyc_ctx *ctx);
/* The contour of scans[0 .. n-1] (those with their bit set in `only`, if
 * given) cast on the grid as it stands (its marks set from the counts
 * first; the contour bits cleared first if `clear`), into the tiles' bits,
 * and into the list when ctx->contour_xy is set. Its scratch on
 * ctx->arena, polyc__contour_cast_bytes of a directory of dir_n entries; 0
 * when there is no room for it. */
int polyc__contour_cast(polyc_ctx *ctx, const polyc__scan *scans, uint32_t n, int clear,
                        const uint32_t *only);
size_t polyc__contour_cast_bytes(size_t dir_n);

/* polyline.c */
/* the store's vertex capacity: limits.max_vertices, or max_beams + 1024 */
int32_t polyc__max_vertices(const polyc_limits *lim);
/* lines a store (and its flat form) of v_cap vertices holds */
int32_t polyc__line_cap(int32_t v_cap);
/* the store's allocations under the limits, on a counting arena */
void polyc__store_reserve(polyc__arena *a, const polyc_limits *lim);
/* 0: no room */
int polyc__store_init(polyc__arena *a, polyc__store *s, int32_t v_cap);
void polyc__store_clear(polyc__store *s);
int32_t polyc__line_new(polyc__store *s);
void polyc__line_free(polyc__store *s, int32_t line);
int32_t polyc__vertex_append(polyc__store *s, int32_t line, float x, float y);
int32_t polyc__vertex_insert_after(polyc__store *s, int32_t v, float x, float y);
void polyc__vertex_remove(polyc__store *s, int32_t v);
void polyc__line_close(polyc__store *s, int32_t line);
void polyc__line_reverse(polyc__store *s, int32_t line);
int32_t polyc__line_cut(polyc__store *s, int32_t u, int *ok);
void polyc__line_join(polyc__store *s, int32_t tail, int32_t head);
/* a flat form of v_cap vertices' allocations, on a counting arena */
void polyc__flat_reserve(polyc__arena *a, int32_t v_cap, int result); /* result: a context's */
/* 0: no room */
int polyc__flat_init(polyc__arena *a, polyc__flat *f, uint32_t cap_lines, uint32_t cap_points);
/* the same for a context's result, with room for its circles */
int polyc__flat_result(polyc__arena *a, polyc__flat *f, uint32_t cap_lines, uint32_t cap_points);
void polyc__flat_from_store(polyc__flat *f, const polyc__store *s);
polyc_status polyc__store_from_flat(polyc__store *s, const polyc__flat *f);

/* trace.c */
polyc_status polyc__trace_build(polyc_ctx *ctx);
/* the walks alone: the `count` cells of xy (2 a cell) that are marked in
 * their tiles (t->mark) traced into polylines added to the store (the
 * batch's: the contour list; an online round's: its unexplained cells) */
polyc_status polyc__trace_cells(polyc_ctx *ctx, const int32_t *xy, uint32_t count);
void polyc__trace_reserve(polyc__arena *a, const polyc_limits *lim);
/* scan_chains.c: a single scan's initial polylines from its beam order */
void polyc__chains_reserve(polyc__arena *a, const polyc_limits *lim);
polyc_status polyc__chains_build(polyc_ctx *ctx);

/* optimize.c */
/* what the optimiser carves after the prior, on a counting arena */
void polyc__optimizer_reserve(polyc__arena *a, const polyc_config *cfg, const polyc_limits *lim);
polyc_status polyc__optimize(polyc_ctx *ctx, polyc_progress_fn progress, void *user);
polyc_status polyc__score(polyc_ctx *ctx, double *bic, double *err);
/* the circles of the current map (circles.c) on an optimiser set up for it */
polyc_status polyc__find_curves(polyc_ctx *ctx);
/* circles.c: the polylines of o's map that go round and that a circle fits
 * at a lower BIC, into the result's circle list (none with
 * POLYC_FLAG_NO_ARCS) */
struct polyc__opt;
void polyc__circles_select(struct polyc__opt *o);
/* arcs.c: the runs of the polylines that are no circle that turn one way
 * by small angles and that an arc fits at a lower BIC, into the result's
 * arc form (none with POLYC_FLAG_NO_ARCS) */
void polyc__arcs_select(struct polyc__opt *o);

#endif
