/* opt_state.h - the state of the BIC optimiser (paper section IV), which
 * every file of the search shares: the model's terms, the spatial hash, the
 * books of a change, each operator group's scratch (its types in
 * opt_scratch.h, carved by its own file), and the functions of the files
 * below the search loop (optimize.h). */
#ifndef POLYC_OPT_STATE_H
#define POLYC_OPT_STATE_H

#include "opt_scratch.h"

/* A float sum with Kahan's compensation: the map's totals (the error and
 * the angle cost, over up to millions of terms, updated by each change)
 * to about float's precision of the total, without double arithmetic
 * (software calls on a single-precision FPU). */
typedef struct polyc__ksum {
    float sum, carry;
} polyc__ksum;

static inline void polyc__ksum_add(polyc__ksum *k, float x)
{
    float y = x - k->carry;
    float t = k->sum + y;
    k->carry = (t - k->sum) - y;
    k->sum = t;
}

static inline float polyc__ksum_get(const polyc__ksum *k)
{
    return k->sum - k->carry;
}

typedef struct polyc__rays {
    int on;                        /* the map comes from a single scan */
    float x, y, base, step;       /* origin, direction of beam 0, step */
    float step_cos, step_sin;     /* cos and sin of step */
    const float *range;
    float min_m, max_m;
    int32_t count, turn;           /* beams, beams per full turn */
    float tol_m;
    float own_m;                  /* a return this near a segment's line is its own */
} polyc__rays;

/* The books of one change (a batch of edits) being recorded (change.c). */
typedef struct polyc__change {
    uint32_t epoch;
    uint32_t *seg_dead;            /* per vertex: == epoch when its segment changed */
    uint32_t *v_dirty;             /* per vertex: == epoch when its angle is pending */
    int32_t *dirty_list, dirty_n;
    int32_t *added, added_n;       /* segments inserted in this change */
    int added_overflow;            /* more than added_cap: rescore the region fully */
    uint32_t *bucket_mark;         /* per bucket: == epoch when listed */
    int32_t *bucket_list, bucket_n;
    int32_t added_cap, dirty_cap;
} polyc__change;

/* The data: weighted points sorted by hash bucket (points.c), and their
 * assignment to the model (cost.c, change.c). */
typedef struct polyc__data {
    polyc__point *pts;
    float *pt_view;                /* per point: the sum of the vectors from its endpoints
                                    * to their sensors, metres (NULL: not known, grids
                                    * and single scans) */
    int32_t np;
    int32_t *pt_seg;               /* nearest segment (its start vertex) or NONE */
    float *pt_cost;               /* capped cost of the point's endpoints */
    float n, log_n;               /* BIC's n: every endpoint */
    float point_span_m;            /* side of the block a weighted point stands for */
    float support_m;               /* a point supports the map this near it: POLYC__SUPPORT_M,
                                    * or a point's span where that is wider (grids) */
} polyc__data;

/* What the search does for the kind of input (polyc__input_kind), decided
 * once in polyc__opt_setup; the loop (optimize.c) reads it. */
typedef struct polyc__policy {
    /* an occupancy grid: an iteration gains only if the BIC falls by more
     * than gain_share of it (0: by one unit) */
    float gain_share;
    /* flags (bytes: the policy rides on the optimiser's stack). A single scan's chains already join what its beam order joins: no
     * overlaps, merges, splits or zips (A, B, C), nor the polish of the
     * best map; they start with more than enough vertices: no additions
     * (G); and no noise (F, docs/algorithm.md) */
    uint8_t restructure, add_vertices, noise;
    /* a single scan's later iterations climb only what the previous one
     * edited after its first climbs, and it stops after an iteration
     * without gain */
    uint8_t climb_since_prev, stop_without_gain;
    /* an occupancy grid: noisy iterations and ones still recovering from
     * the noise do not spare the patience; a gap in the data is cut only as
     * far as the grid has free cells along it (split.c) */
    uint8_t noise_spares_patience, recover, gaps_free_only;
    /* the noise starts this many decays in (an online map the updates
     * fitted: the finishing call, online_round.c) */
    uint8_t noise_skip;
} polyc__policy;

/* The optimiser's long-lived state: the model and its terms, the spatial
 * index, the books of the current change and the stamps; each operator
 * group's working state is its own struct, carved by its file. */
typedef struct polyc__opt {
    polyc_ctx *ctx;
    const polyc_config *cfg;       /* ctx->cfg, or ctx->grid_cfg for an occupancy grid */
    polyc__store *s;
    polyc__policy pol;
    float R, R2;                   /* search radius: the cost of a point is capped at w R^2 */

    polyc__data d;
    float *seg_side;               /* 2 per vertex: what its segment is seen from (zip.c) */

    /* model terms, kept incrementally */
    polyc__ksum err;               /* sum of pt_cost */
    polyc__ksum angle;                             /* sum over vertices of (1 - p(turn | x, y)) */
    float *acost;                 /* per vertex: 1 - p */
    polyc__prior prior;
    polyc__spacing spacing;        /* expected point spacing: the split scale */
    polyc__rays rays;              /* single-scan mode: the beams' free space */

    polyc__hash h;
    uint8_t *seg_in;               /* per vertex: its segment is in the hash */
    uint8_t *split_due;            /* per vertex: its segment or its points changed
                                    * since op_split last looked at it */
    polyc__change chg;

    uint32_t *v_touch;             /* per vertex: touch_stamp of the last edit near it */
    uint32_t touch_stamp;
    uint32_t untangle_mark, zip_mark; /* touch_stamp of their last passes: a segment
                                    * edited since is looked at again */
    polyc__rng rng;
    polyc__flat best;

    polyc__eval_scratch ev;
    polyc__split_scratch split;
    polyc__size_scratch size;
    polyc__climb_scratch climb;

    /* an online update's region: only segments edited at or after this
     * stamp are split, trimmed or given vertices (0: the whole map); the
     * points those operators look at (change.c, polyc__region_points) */
    uint32_t region_since;
    int32_t *region_pt;
} polyc__opt;

#define POLYC__CAND_MAX 48

/* The zip's scratch (sides.c, zip.c): per segment, the weight of unit views across
 * it from its left and from its right (polyc__find_sides fills them,
 * polyc__two_sided reads them). A transient carve, the one place where two
 * groups share memory: the pair is vertex removal's per-segment sums
 * (polyc__size_scratch's seg_sum and seg_w, model_size.c), which the zip
 * and the removal each fill anew before they read them within one pass, and
 * no pass of the one runs inside a pass of the other. Stored nowhere, so
 * that neither the block (the embedded examples fill 128 KiB) nor
 * polyc__opt grows: polyc__sides gives it. */
typedef struct polyc__side_scratch {
    float *left_w, *right_w;
} polyc__side_scratch;
static inline polyc__side_scratch polyc__sides(const polyc__opt *o)
{
    polyc__side_scratch sd;
    sd.left_w = o->size.seg_sum;
    sd.right_w = o->size.seg_w;
    return sd;
}

/* topology.c, zip.c */
/* Does segment sg share vertex a or b (NONE: a new point)? */
inline int polyc__touches(const polyc__store *s, int32_t sg, int32_t a, int32_t b)
{
    int32_t e = s->v[sg].next;
    return (a != POLYC__NONE && (sg == a || e == a)) || (b != POLYC__NONE && (sg == b || e == b));
}
/* Whether segment v (live) was edited since the touch stamp `since`: a
 * crossing or a doubly covered stretch that is new has a new or moved
 * segment on one side, so a pass needs to look only at those. */
inline int polyc__edited_since(const polyc__opt *o, int32_t v, uint32_t since)
{
    return o->v_touch[v] >= since || o->v_touch[o->s->v[v].next] >= since;
}


/* ok &= carving count elements of *ptr from arena a (the carve functions:
 * each group's scratch is carved by its own file, on the block or on the
 * size query's counting arena) */
#define POLYC__CARVE(ok, a, ptr, count) \
    ((ok) &= ((ptr) = polyc__alloc((a), (size_t)(count), sizeof *(ptr))) != NULL)
#define POLYC__CARVE_ZERO(ok, a, ptr, count) \
    ((ok) &= ((ptr) = polyc__alloc_zero((a), (size_t)(count), sizeof *(ptr))) != NULL)
/* change.c: the books of a change for V vertices */
int polyc__change_carve(polyc__arena *a, polyc__change *c, int32_t V);
/* change.c: lists the buckets a segment's points can be in for rescoring */
void polyc__chg_mark_region(polyc__opt *o, int32_t seg);
/* Whether segment v is in the online update's region (always, without one). */
inline int polyc__in_region(const polyc__opt *o, int32_t v)
{
    return o->region_since == 0 || o->v_touch[v] >= o->region_since ||
           o->v_touch[o->s->v[v].next] >= o->region_since;
}
/* change.c: in an online update's region, lists in o->region_pt the points
 * in the buckets where the points of the segments `want` takes can be, and
 * returns their count; without a region, -1 (look at every point) */
typedef int (*polyc__seg_pred)(const polyc__opt *o, int32_t v);
int32_t polyc__region_points(polyc__opt *o, polyc__seg_pred want);
/* change.c: lists in o->region_pt the points of the buckets listed in
 * o->chg.bucket_list, empties that list; returns the count */
int32_t polyc__listed_points(polyc__opt *o);
/* trial.c: trial evaluation's scratch for P points (lsoa_cap: listed
 * points copied by field, 0 for none) */
int polyc__eval_carve(polyc__arena *a, polyc__eval_scratch *ev, int32_t P, int32_t lsoa_cap);
/* split.c: split and trim scratch; model_size.c: vertex removal's */
int polyc__split_carve(polyc__arena *a, polyc__split_scratch *sp, int32_t P, int32_t V);
int polyc__size_carve(polyc__arena *a, polyc__size_scratch *sz, int32_t V);
/* a data point supports the stretch of map within this distance of it:
 * splits and end trimming count only such points (not in the paper) */
#define POLYC__SUPPORT_M 0.05f
/* listed points copied by field for the trials (nearly every trial on a
 * real log lists fewer) */
#define POLYC__LOC_SOA 256
/* segments one edit replaces, at most (corners: a chain of 3 and its two ends) */
#define POLYC__EDIT_SEGS 6

/* points.c */
int32_t polyc__points_bound(const polyc_config *cfg, const polyc_limits *lim);
/* whether the points carry the direction they were seen from (pt_view) */
int polyc__points_viewed(const polyc_ctx *ctx);
polyc_status polyc__points_collect(polyc__opt *o);
/* the span of a weighted point and the support distance (exact: one
 * point per endpoint) */
void polyc__points_spans(polyc__opt *o, int exact);
/* a point's weight by the accuracy where it lies */
void polyc__point_weigh(const polyc__prior *prior, polyc__point *p);
/* online: the points (in o->d), carved once (their unsorted copy is the
 * update's scratch, online.h) */
int polyc__points_carve_online(polyc__arena *a, polyc__opt *o);
/* the points' allocations under the limits, on a counting arena */
void polyc__points_reserve(polyc__arena *a, const polyc_config *cfg, const polyc_limits *lim);

/* spatial_hash.c */
int32_t polyc__hash_bucket_cap(const polyc_limits *lim);
/* the bucket cap of a grid of this many tiles (its area, stored or not) */
int32_t polyc__hash_bucket_cap_tiles(size_t tiles);
/* the entries for a hash of nb buckets (the reserve: the bucket cap) */
int32_t polyc__hash_entry_cap(const polyc_limits *lim, size_t nb);
polyc_status polyc__hash_init(polyc__opt *o);
/* the buckets over the grid, at most cap of them, carved from a (no
 * clearing); 0: no room */
int polyc__hash_lay_out(polyc__opt *o, polyc__arena *a, int32_t cap);
/* the hash's allocations under the limits, on a counting arena */
void polyc__hash_reserve(polyc__arena *a, polyc__opt *o, const polyc_limits *lim);
int polyc__hash_insert(polyc__opt *o, int32_t seg);
void polyc__hash_remove(polyc__opt *o, int32_t seg);
void polyc__hash_clear(polyc__opt *o);
int32_t polyc__bucket_of(const polyc__hash *h, float x, float y);
/* the column and row of the bucket holding (x, y), clamped to the hash */
inline void polyc__bucket_xy(const polyc__hash *h, float x, float y, int32_t *ix, int32_t *iy)
{
    float fx = (x - h->origin_x) * h->inv_bucket, fy = (y - h->origin_y) * h->inv_bucket;
    *ix = fx < 0.0f ? 0 : (fx >= (float)h->bx ? h->bx - 1 : (int32_t)fx);
    *iy = fy < 0.0f ? 0 : (fy >= (float)h->by ? h->by - 1 : (int32_t)fy);
}
/* The 3 x 3 buckets around bucket (bx, by) that lie in the hash, row by
 * row, into out; returns their count (the library's bucket walk:
 * polyc__near_segs below walks their segments; only polyc__segment_region,
 * the hottest, writes the same rows out). */
inline int polyc__buckets_around(const polyc__hash *h, int32_t bx, int32_t by, int32_t out[9])
{
    int32_t x0 = bx > 0 ? bx - 1 : 0, x1 = bx + 1 < h->bx ? bx + 1 : h->bx - 1;
    int32_t y0 = by > 0 ? by - 1 : 0, y1 = by + 1 < h->by ? by + 1 : h->by - 1;
    int n = 0;
    for (int32_t y = y0; y <= y1; y++)
        for (int32_t x = x0; x <= x1; x++)
            out[n++] = y * h->bx + x;
    return n;
}
/* The segments entered in the 3 x 3 buckets around the bucket of (x, y),
 * bucket by bucket and in each in its list's order (a segment entered in
 * two of them comes twice): the walk of every query near a point (a search
 * radius is at most a bucket). Two loops, so that the walk costs what the
 * loops written out did (an iterator function, inlined or not, cost the
 * embedded online example measurably more instructions at -Os): in the
 * body, `continue` goes to the next segment, `break` only to the next
 * bucket (leave the walk with return or goto). The hash must not change
 * during the walk.
 *     polyc__near_segs w;
 *     POLYC__FOR_NEAR_SEGS(w, h, x, y, sg) { ... sg ... } */
typedef struct polyc__near_segs {
    int32_t bx, by, around[9];
    int n;
} polyc__near_segs;
#define POLYC__FOR_NEAR_SEGS(w, h, x, y, sg)                                                       \
    for (int w##_b = (polyc__bucket_xy((h), (x), (y), &(w).bx, &(w).by),                           \
                      (w).n = polyc__buckets_around((h), (w).bx, (w).by, (w).around), 0);           \
         w##_b < (w).n; w##_b++)                                                                    \
        for (int32_t w##_e = (h)->seg_head[(w).around[w##_b]], sg = POLYC__NONE;                   \
             w##_e != POLYC__NONE && ((sg) = (h)->entries[w##_e].seg, 1);                          \
             w##_e = (h)->entries[w##_e].next)
/* calls fn(o, user, bucket) for every bucket the segment a-b crosses */
typedef void (*polyc__bucket_fn)(polyc__opt *o, void *user, int32_t bucket);
void polyc__segment_buckets(polyc__opt *o, float ax, float ay, float bx, float by,
                            polyc__bucket_fn fn, void *user);
/* lists in o->bucket_list, once per epoch (o->bucket_mark), every bucket
 * within one bucket of the segment a-b: those whose points it can reach */
void polyc__segment_region(polyc__opt *o, float ax, float ay, float bx, float by);
/* whether a segment that touches neither end of segment v comes within
 * `reach` of it or crosses it, among the segments in the 3 x 3 buckets
 * around each bucket v crosses: those a query near a point of v walks
 * (polyc__near_segs); 0: no point of v is within reach of another piece
 * of map there */
int polyc__segment_near_other(const polyc__opt *o, int32_t v, float reach);

/* A segment prepared for many cost evaluations (trial.h). */
typedef struct polyc__seg_pre {
    float ax, ay, bx, by, dx, dy, inv_l2, nx, ny;
} polyc__seg_pre;

/* trial_costs.c: c[k] = min(c[k], cost of listed point k on segment q) for
 * the lsoa_n points copied by field; the values of trial.h's polyc__seg_pre_cost */
void polyc__trial_costs_min(const polyc__opt *o, const polyc__seg_pre *q, float *c);

/* cost.c: the nearest segment within reach, skipping up to n_skip segments;
 * the BIC and the error; the model's terms from scratch */
float polyc__nearest(const polyc__opt *o, int32_t pi, const int32_t *skip, int n_skip,
                      int32_t *seg);
float polyc__bic(const polyc__opt *o);
float polyc__err(const polyc__opt *o); /* the map's sum of squared distances */
polyc_status polyc__rebuild(polyc__opt *o);          /* hash and assignment from scratch */
/* change.c: recording a change: segments out before an edit, in after it */
void polyc__chg_begin(polyc__opt *o);
void polyc__chg_seg_out(polyc__opt *o, int32_t seg);
int polyc__chg_seg_in(polyc__opt *o, int32_t seg);
void polyc__chg_dirty(polyc__opt *o, int32_t v);
void polyc__chg_commit(polyc__opt *o);
/* trial.c: local evaluation of replacing `old` segments by candidate geometry */
void polyc__local_prepare(polyc__opt *o, const int32_t *old, int n_old, const float *seg_xy,
                          int n_new, float reach);
/* the same for moving the vertex at (mx, my), the shared end of the n_new
 * (1 or 2) segments, by at most `reach`: seg_xy are the `old` segments as
 * they are now; with aggregation */
void polyc__local_prepare_move(polyc__opt *o, const int32_t *old, int n_old, const float *seg_xy,
                               int n_new, float reach, float mx, float my);
float polyc__local_eval(const polyc__opt *o, const float *seg_xy, int n_new);
float polyc__local_current(const polyc__opt *o);
/* delta.c: the change of the error replacing `old` by seg_xy: exact below `limit`,
 * else some value >= limit */
float polyc__local_delta(polyc__opt *o, const int32_t *old, int n_old, const float *seg_xy,
                          int n_new, float limit);

/* edits (edits.c): each records its change; call chg_begin/commit around */
void polyc__op_move(polyc__opt *o, int32_t v, float x, float y);
void polyc__op_remove(polyc__opt *o, int32_t v);
int32_t polyc__op_insert_after(polyc__opt *o, int32_t u, float x, float y);
void polyc__op_cut(polyc__opt *o, int32_t u);                 /* cut link u -> next */
int polyc__op_link(polyc__opt *o, int32_t tail, int32_t head); /* join or close */
void polyc__op_reverse(polyc__opt *o, int32_t l);              /* reverse polyline l */
/* one edit as a change of its own (begin, edit, commit) */
void polyc__apply_remove(polyc__opt *o, int32_t v);
void polyc__apply_move(polyc__opt *o, int32_t v, float x, float y);

/* the operators (paper IV.A-G); the table that runs them: optimize.c */
/* operators.c: A (overlaps), B (merge), E (zigzags), folds */
int polyc__op_overlaps(polyc__opt *o);
int polyc__op_merge(polyc__opt *o);
/* op_merge that refuses hairpins or not: a hairpin is a link whose two
 * polylines leave it within 30 degrees of one direction; a pass with no
 * zigzag or zip after it to judge one refuses them (op_merge allows them) */
typedef enum polyc__hairpins {
    POLYC__HAIRPINS_REFUSED = 0,
    POLYC__HAIRPINS_ALLOWED = 1
} polyc__hairpins;
int polyc__op_merge_folds(polyc__opt *o, polyc__hairpins hairpins);
/* split.c: C (split) and end trimming */
int polyc__op_split(polyc__opt *o);
int polyc__op_trim_ends(polyc__opt *o);
/* adjust.c: D (vertex moves) and F (noise) */
int polyc__op_adjust(polyc__opt *o, int max_rounds, uint32_t since);
void polyc__op_noise(polyc__opt *o, float sigma_m);
int polyc__hill_climb(polyc__opt *o, int32_t v);
int polyc__op_zigzag(polyc__opt *o);
/* folds that draw a short stretch of wall twice, removed whatever the BIC */
int polyc__op_unfold(polyc__opt *o);
/* corners.c: corners (not in the paper) */
int polyc__op_corners(polyc__opt *o, uint32_t since);
/* topology.c: every crossing of two segments resolved (not in the paper) */
int polyc__op_untangle(polyc__opt *o);
/* topology.c: open ends at T-junctions stop END_GAP_M (1 mm) short of the
 * segment they meet, corners that touch a segment clear it by as much;
 * the number moved, plus 1000 for each crossing at a vertex made one that
 * polyc__op_untangle sees (run it, and this, again) */
int polyc__op_end_gaps(polyc__opt *o);
/* topology.c: whether a segment from vertex a to vertex b would cross the map */
int polyc__link_crosses(const polyc__opt *o, int32_t a, int32_t b);
/* sides.c: what each segment is seen from, into seg_side (needs it), from
 * the n points of list (NULL: every point); valid until the next edit.
 * With left and right (per vertex, or NULL), also the weight of unit views
 * across each segment from its left and from its right. */
void polyc__find_sides(polyc__opt *o, const int32_t *list, int32_t n, float *left, float *right);
/* sides.c: whether segment sg is seen from both sides, from the left and
 * right weights polyc__find_sides left in polyc__sides(o) */
int polyc__two_sided(const polyc__opt *o, int32_t sg);
/* zip.c: stretches of map along another piece of map cut out */
int polyc__op_zip(polyc__opt *o);
/* model_size.c: G (vertex removal and addition) */
int polyc__op_remove_vertices(polyc__opt *o, uint32_t since);
/* the change of the BIC if v is removed when that is below `bound`, else
 * some value >= bound (INFINITY: always exact) */
float polyc__removal_delta_below(polyc__opt *o, int32_t v, float bound);
/* Squared distance from (px, py) to segment a-b. */
inline float polyc__seg_dist2(float px, float py, float ax, float ay, float bx, float by)
{
    float dx = bx - ax, dy = by - ay, mx = px - ax, my = py - ay;
    float l2 = dx * dx + dy * dy;
    float t = l2 > 0.0f ? (mx * dx + my * dy) / l2 : 0.0f;
    t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    float ex = mx - t * dx, ey = my - t * dy;
    return ex * ex + ey * ey;
}
/* A point changes segment from `from` to `to`: both are due for op_split. */
static inline void polyc__split_due_pt(polyc__opt *o, int32_t from, int32_t to)
{
    if (from == to)
        return;
    if (from != POLYC__NONE)
        o->split_due[from] = 1;
    if (to != POLYC__NONE)
        o->split_due[to] = 1;
}
/* ray_check.c: single-scan mode (rays.on) only, else every answer is 0.
 * blocks_beams: segment a-b stands in front of a return, or behind one of
 * its own, by more than the tolerance; vertex_blocks: v at (x, y) makes one
 * of its segments do so where none of them does now, or loses a return
 * they hold; holds_returns: some beam meets a-b within the
 * tolerance of its return (the map would lose that return without it) */
void polyc__rays_init(polyc__rays *rays, const polyc_ctx *ctx);
/* old_xy: the n_old segments (x0 y0 x1 y1 each) the edit replaces; a
 * return one of them met within the tolerance is the new segment's own too,
 * however far from its line (on a wall seen at a grazing angle) */
int polyc__blocks_beams(const polyc__rays *rays, float ax, float ay, float bx, float by,
                        const float *old_xy, int n_old);
/* fills old_xy with the segments of `segs` (start vertices, NONE skipped)
 * as they are now; returns their count (at most POLYC__EDIT_SEGS) */
int polyc__edit_segments(const polyc__opt *o, const int32_t *segs, int n, float *old_xy);
/* some return one of the old segments holds (holds_returns) is met by
 * none of the new ones within the tolerance */
int polyc__loses_returns(const polyc__rays *rays, const float *old_xy, int n_old,
                         const float *new_xy, int n_new);
int polyc__vertex_blocks(const polyc__opt *o, int32_t v, float x, float y);
int polyc__holds_returns(const polyc__rays *rays, float ax, float ay, float bx, float by);
float polyc__ray_position(const polyc__rays *rays, float ax, float ay, float bx, float by,
                          float px, float py, float projection);
/* model_size.c: G, more vertices; additions that failed are tried again
 * (a new search, or data that changed) */
int polyc__op_add_vertices(polyc__opt *o, int max_tries);
void polyc__size_forget(polyc__opt *o);

#endif
