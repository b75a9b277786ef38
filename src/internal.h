/* internal.h - shared private types of libpolyc (never installed).
 * Everything here lives inside the caller's memory block. */
#ifndef POLYC_INTERNAL_H
#define POLYC_INTERNAL_H

#include "polyc.h"
#include "tunables.h"

#include <string.h>

#ifndef POLYC_ASSERT
#include <assert.h>
#define POLYC_ASSERT(x) assert(x)
#endif

/* Counter width of the hit/miss grid: 16 bits by default; 8 for tiny targets. */
#ifndef POLYC_COUNTER_BITS
#define POLYC_COUNTER_BITS 16
#endif
#if POLYC_COUNTER_BITS == 8
typedef uint8_t polyc__count;
#define POLYC__COUNT_MAX 255u
#else
typedef uint16_t polyc__count;
#define POLYC__COUNT_MAX 65535u
#endif

#define POLYC__NONE (-1)
/* a function the compiler must not inline (where inlining copies code) */
#if defined(__GNUC__)
#define POLYC__NOINLINE __attribute__((noinline))
#else
#define POLYC__NOINLINE
#endif

/* ---- arena.c: bump allocation inside the caller's block ---- */
typedef struct polyc__arena {
    unsigned char *base;
    size_t size;
    size_t used;
    size_t peak;
} polyc__arena;

void *polyc__alloc(polyc__arena *a, size_t count, size_t elem_size);
/* an arena that only counts (no block): what polyc_memory_size carves on */
void polyc__arena_counting(polyc__arena *a);
void *polyc__alloc_zero(polyc__arena *a, size_t count, size_t elem_size);
/* size of count * elem_size rounded up to the arena alignment; 0 on overflow */
size_t polyc__bytes(size_t count, size_t elem_size);
/* a + b, saturating at SIZE_MAX (so a size query overflows to "too big") */
size_t polyc__add(size_t a, size_t b);

/* ---- rng.c: the library's own PRNG (splitmix64), identical on every platform ---- */
typedef struct polyc__rng {
    uint64_t state;
} polyc__rng;
uint64_t polyc__rng_next(polyc__rng *r);
float polyc__rng_uniform(polyc__rng *r);   /* [0, 1) */
float polyc__rng_normal(polyc__rng *r);    /* N(0, 1) */

/* binary64.c: a + b, a - b, a double to float and a float to double,
 * rounded as IEEE 754 rounds them, with integers (no software double on
 * a single-precision FPU) */
double polyc__d_add(double a, double b);
double polyc__d_sub(double a, double b);
float polyc__d_to_f(double v);
double polyc__f_to_d(float v);
/* a double's or a float's bits, and back (memcpy: no aliasing rule broken) */
static inline uint64_t polyc__bits64(double v)
{
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    return u;
}
static inline double polyc__double_of(uint64_t u)
{
    double v;
    memcpy(&v, &u, sizeof v);
    return v;
}
static inline uint32_t polyc__bits32(float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return u;
}
static inline float polyc__float_of(uint32_t u)
{
    float v;
    memcpy(&v, &u, sizeof v);
    return v;
}

/* fmath.c: float sine, cosine, arc tangent, logarithm (libm's compute in
 * double on the target); angles within a few thousand turns, log of a
 * finite normal x > 0 */
void polyc__sincosf(float a, float *s, float *c);
float polyc__sinf(float a);
float polyc__cosf(float a);
float polyc__atan2f(float y, float x);
float polyc__logf(float x);
/* floor(x) as an integer for |x| < 2^31 (callers keep cell and bucket
 * coordinates there): a conversion and a compare, where newlib's floorf is
 * a library call of some 40 instructions on a Cortex-M */
inline int32_t polyc__floori(float x)
{
    int32_t i = (int32_t)x;
    return i - (x < (float)i);
}

/* ---- grid.c: hit/miss grid in 32 x 32 tiles ---- */
#define POLYC__TILE_SHIFT 5
#define POLYC__TILE_SIDE 32
#define POLYC__TILE_CELLS 1024
/* the record of misses in a tile not stored that an online grid keeps
 * (online_grid.c): a count per block of POLYC__PRE_SIDE x POLYC__PRE_SIDE
 * cells, POLYC__PRE_BLOCKS a tile (and half a byte per cell) */
#define POLYC__PRE_SHIFT 3
#define POLYC__PRE_SIDE 8
#define POLYC__PRE_BLOCKS 16
#define POLYC__PRE_FULL 15u

typedef struct polyc__tile {
    polyc__count hits[POLYC__TILE_CELLS];
    polyc__count misses[POLYC__TILE_CELLS];
    uint32_t contour[POLYC__TILE_SIDE]; /* bit per cell: labelled contour */
    uint32_t mark[POLYC__TILE_SIDE];    /* bit per cell: scratch (contour, tracing, data cells) */
    uint32_t mark_base;                 /* index of this tile's first marked cell */
    uint16_t mark_row[POLYC__TILE_SIDE];/* marked cells in earlier rows of the tile */
    uint32_t pad[3];                    /* size a multiple of 16 (contiguous tiles) */
} polyc__tile;

/* (the layer's records and the cell walk: online_grid.c, walk.h) */
struct polyc__records;
struct polyc__walk;

typedef struct polyc__grid {
    double origin_x_m, origin_y_m; /* lower-left corner of cell (0, 0) */
    float frame_ox, frame_oy;      /* the same, relative to the frame (first pose) */
    float cell_m, inv_cell;
    int32_t width, height;         /* cells */
    int32_t tiles_x, tiles_y;
    uint32_t *dir;                 /* tiles_x * tiles_y; 0 = not stored, else index + 1 */
    polyc__tile *tiles;            /* contiguous, tile_count used of tile_cap */
    uint32_t tile_count, tile_cap;
    int out_of_tiles;              /* set when a beam needed a tile past tile_cap */
    uint32_t *wanted;              /* bit per directory entry: a tile to store */
    polyc__tile *spill;            /* where misses in tiles not stored go */
    /* where the misses in tiles not stored are kept, when they are (a
     * layer's records, online_grid.c, walked by its hooks: polyc__layer;
     * NULL in a batch) */
    struct polyc__records *rec;
    size_t fixed_bytes;            /* directory, bits and spill tile */
} polyc__grid;

/* ---- scans as stored ---- */
typedef struct polyc__scan {
    float x_m, y_m, theta_rad;     /* pose relative to ctx->frame origin */
    float start_rad, step_rad;
    float min_m, max_m;
    uint32_t first;                /* index of the first range in ctx->ranges */
    uint32_t count;
} polyc__scan;

/* ---- polyline store (polyline.c): vertices in doubly linked lists ---- */
typedef struct polyc__vertex {
    float x, y;
    int32_t prev, next;            /* POLYC__NONE at the ends of an open polyline */
    int32_t line;                  /* owning polyline, POLYC__NONE when free */
} polyc__vertex;

typedef struct polyc__line {
    int32_t head;                  /* first vertex (any vertex when closed) */
    int32_t tail;                  /* last vertex (head->prev when closed) */
    int32_t count;
    int32_t closed;                /* POLYC__NONE when the slot is free */
    uint32_t id;                   /* stable while the polyline lives (polyc_polyline_id) */
} polyc__line;

typedef struct polyc__store {
    polyc__vertex *v;
    polyc__line *l;
    int32_t v_cap, l_cap;
    int32_t v_free, l_free;        /* free lists (through .next / .head) */
    int32_t v_live, l_live;
    int32_t v_high, l_high;        /* slots in use are among [0, high) */
    uint32_t last_id;              /* the id the newest polyline got (never reused) */
} polyc__store;

/* ---- flattened map, the form results are read in ---- */
/* A polyline the BIC prefers as a circle, or one of the pieces a circle
 * stands for (circles.c): its store id, the first piece's, the circle
 * (frame metres) and how far the polyline strays from it. */
typedef struct polyc__circle {
    uint32_t line_id, first_id;
    float cx, cy, r, dev;
} polyc__circle;

typedef struct polyc__flat {
    float *xy;                     /* 2 floats per point */
    uint32_t *start;               /* point offset of each polyline, count + 1 entries */
    uint8_t *closed;
    uint32_t *id;                  /* per polyline: its store id */
    uint32_t count, points;
    uint32_t cap_lines, cap_points;
    /* the result's circles (the search's last step; not copied with the
     * polylines: set on the context's result only) */
    polyc__circle *circ;
    uint32_t circ_n, circ_cap;
    /* and its arcs (arcs.c; arc_n 0: none, the arrays not read): per point,
     * kept in the arc form (1) or inside an arc (0), and the bulge of the
     * arc form's segment that starts at it (0: straight) */
    uint8_t *arc_keep;
    float *arc_bulge;
    uint32_t arc_n;
} polyc__flat;

/* ---- data points (points.c): one weighted point per cell, or raw points ----
 * Moments let the sum of squared distances of all points of a cell to a line
 * be computed exactly: sum (n.(p-a))^2 = w (n.(m-a))^2 + n^T C n. */
typedef struct polyc__point {
    float x, y;                    /* mean */
    float cxx, cxy, cyy;           /* central second moments (sums, not averages) */
    float w;                       /* number of endpoints */
} polyc__point;

/* ---- spatial hash (spatial_hash.c): uniform buckets over the map ---- */
typedef struct polyc__hash_entry {
    int32_t seg;                   /* segment = its start vertex */
    int32_t next;
} polyc__hash_entry;

typedef struct polyc__hash {
    float origin_x, origin_y, bucket_m, inv_bucket;
    int32_t bx, by;                /* buckets per axis */
    int32_t *seg_head;             /* bx * by lists of segment entries */
    polyc__hash_entry *entries;
    int32_t entry_cap, entry_free, entry_live;
    int32_t entry_top;             /* entries below it have been handed out */
    uint32_t *pt_start;            /* bx * by + 1: points sorted by bucket */
    int32_t *pt_order;             /* unused when points are stored sorted */
    int out_of_entries;
} polyc__hash;

/* ---- angle prior (angle_prior.c) ----
 * p(turn angle | x, y) from corners between lines fitted in single scans.
 * The prior grid is the tile grid: one cell per 32 x 32 grid cells. */
#define POLYC__ANGLE_BINS 18       /* 10 degree bins of the turn angle, 0..180 */
#define POLYC__BINS_PER_RAD 5.729577951f /* 18 / pi: 10 degree bins */
typedef struct polyc__prior {
    float origin_x, origin_y;     /* frame-relative lower-left corner */
    float cell_m, inv_cell;
    int32_t w, h;
    /* per cell (w * h): 1 + its row of counts, 0 for a cell without evidence */
    uint32_t *row_of;
    uint16_t *hist;                /* rows * POLYC__ANGLE_BINS counts, saturating */
    uint32_t *total;               /* per row: the sum of its counts */
    uint32_t rows;
    /* when the block has room to spare: per cell, 1 + its row of smoothed
     * counts (18 bins and their total, which queries would sum over 3 x 3
     * cells: the same integers), 0 where no cell of the 3 x 3 has evidence;
     * smooth NULL: queries sum them */
    uint32_t *smooth_of;
    uint32_t *smooth;
    uint32_t corners, straights;   /* observations recorded */
    /* per cell: the weight of the error term there (accuracy.c); NULL: 1 */
    float *weight;
} polyc__prior;

/* ---- the data's accuracy (accuracy.c), learned in the prior's pass ---- */
typedef struct polyc__acc_learn {
    polyc__prior *p;               /* NULL: nothing to learn (one scan) */
    void *samples, *cells;         /* scratch (online: kept) */
    uint32_t n, cap;
    uint32_t *ring_n;              /* online: per cell, the samples it has seen */
    float alpha;                   /* online: the error term's, for the weights */
} polyc__acc_learn;
/* the weights (all 1), after the prior's cells are laid out; 0: no room */
int polyc__accuracy_begin(polyc__acc_learn *L, polyc__prior *p, polyc__arena *a,
                          const polyc_limits *lim);
/* the scratch, released with the prior's; 0: no room */
int polyc__accuracy_scratch(polyc__acc_learn *L, polyc__arena *a, const polyc_limits *lim);
/* one sample of a line fitted in scan `scan`: a point on it, its unit
 * normal towards the sensor, the line's residual variance (m^2) and its
 * points per metre */
void polyc__accuracy_sample(polyc__acc_learn *L, float x, float y, float nx, float ny,
                            uint32_t scan, float res2, float density);
/* pairs the samples up and sets the weights (alpha: the error term's) */
void polyc__accuracy_finish(polyc__acc_learn *L, polyc__arena *a, float alpha);
/* online: the per-cell sums and rings, kept (after polyc__accuracy_begin);
 * samples are then paired as they come; 0: no room */
int polyc__accuracy_online(polyc__acc_learn *L, polyc__arena *a, float alpha);
/* the weights from the pairs so far */
void polyc__accuracy_weigh(polyc__acc_learn *L, float alpha);
/* online: every cell's sums, ring and weight as before any sample */
void polyc__accuracy_forget(polyc__acc_learn *L);
/* what polyc__accuracy_finish allocates at most (L->cap samples), on a
 * counting arena */
void polyc__accuracy_reserve_finish(polyc__acc_learn *L, polyc__arena *a);
/* the weight at (x, y), frame metres; 1 outside the prior or without one */
float polyc__accuracy_weight(const polyc__prior *p, float x, float y);

/* the prior's allocations under the limits, on a counting arena; and their peak */
void polyc__prior_reserve(polyc__arena *a, const polyc_limits *lim);
size_t polyc__prior_bytes(const polyc_limits *lim);
/* Learns the prior from the stored scans (needs the grid for its extent);
 * with `spare` bytes or more of the block free beyond what the later stages
 * are budgeted, also the table of smoothed counts (p->smooth). */
polyc_status polyc__prior_build(polyc_ctx *ctx, polyc__prior *p, size_t spare);
/* online: the prior and the accuracy over the whole grid, carved from a
 * (the rows' totals and the weights kept as scans come); 0: no room */
int polyc__prior_online(const polyc_ctx *ctx, polyc__prior *p, polyc__acc_learn *acc,
                        polyc__arena *a);
/* online: every count as before any scan (the rows stay handed out) */
void polyc__prior_forget(polyc__prior *p);
/* prior_learn.c: the counts from every scan, into p (laid out, rows handed
 * out as cells get evidence); cache: cache_cap beams' endpoints (NULL: none);
 * acc: the accuracy's samples (NULL: none) */
void polyc__prior_learn(const polyc_ctx *ctx, polyc__prior *p, float *cache, uint32_t cache_cap,
                        polyc__acc_learn *acc);
/* the same for one scan (its number `scan`: lines of one scan are not paired) */
void polyc__prior_learn_scan(const polyc_ctx *ctx, polyc__prior *p, const polyc__scan *s,
                             uint32_t scan, float *cache, uint32_t cache_cap, polyc__acc_learn *acc);
/* p(turn | x, y) in [0, 1]; x, y frame-relative metres; turn in [0, pi]. */
float polyc__prior_p(const polyc__prior *p, float x, float y, float turn_rad);
/* The same for many turns at one place: its cell's smoothed counts. */
typedef struct polyc__prior_place {
    int valid;                     /* 0: no evidence there, p uniform */
    int32_t cx, cy;
    uint32_t n, c[POLYC__ANGLE_BINS];
} polyc__prior_place;
void polyc__prior_at(const polyc__prior *p, float x, float y, polyc__prior_place *at);
int polyc__prior_same_place(const polyc__prior *p, const polyc__prior_place *at, float x, float y);
float polyc__prior_p_at(const polyc__prior_place *at, float turn_rad);
/* The 18 counts of prior cell (cx, cy); NULL without evidence or outside. */
const uint16_t *polyc__prior_counts(const polyc__prior *p, int32_t cx, int32_t cy);

/* ---- expected beam spacing (spacing.c) ---- */
typedef struct polyc__spacing {
    float origin_x, origin_y, tile_m, min_step_rad;
    int32_t w, h;
    float *dist;                   /* per tile: distance to the nearest pose */
    const polyc__scan *poses;      /* or, for a few poses, these (dist NULL) */
    uint32_t pose_count;
} polyc__spacing;

/* the table's allocation under the limits, on a counting arena */
void polyc__spacing_reserve(polyc__arena *a, const polyc_limits *lim);
polyc_status polyc__spacing_build(polyc_ctx *ctx, polyc__spacing *sp);
/* the distances of sp->dist made from the tiles at 0 (1e30 elsewhere) */
void polyc__spacing_chamfer(polyc__spacing *sp);
/* metres between neighbouring endpoints near (x, y), frame-relative; a lower
 * bound, since the nearest pose is taken (0 without poses) */
float polyc__spacing_at(const polyc__spacing *sp, float x, float y);


/* ---- blocks.c: the weighted points' blocks ----
 * Weighted points gather the endpoints of a block of 2 x 2 grid cells (5 cm
 * at the default grid): a quarter of the points to score, while the moments
 * keep each block's squared distances exact (docs/algorithm.md, "The
 * score", its departure "weighted points"). */
#define POLYC__BLOCK_SHIFT 1
#define POLYC__BLOCK_SIDE (1 << POLYC__BLOCK_SHIFT)
/* The blocks of tile t that hold data marked (t->mark), from the counters;
 * its marked blocks numbered from n (returns the next number). */
void polyc__block_mark_tile(const polyc_ctx *ctx, polyc__tile *t);
uint32_t polyc__block_number_tile(polyc__tile *t, uint32_t n);
/* The number of the marked block (bx, by) of tile t. */
static inline uint32_t polyc__block_number(const polyc__tile *t, int32_t bx, int32_t by)
{
    uint32_t row = t->mark[by & 31], col = (uint32_t)(bx & 31);
    uint32_t below = row & ((1u << col) - 1u);
    uint32_t c = 0;
    while (below) {
        below &= below - 1;
        c++;
    }
    return t->mark_base + t->mark_row[by & 31] + c;
}
/* every tile's blocks marked and numbered, and that many points (and
 * views, if any) zeroed; POLYC_ERR_NOMEM past cap */
polyc_status polyc__blocks_begin(polyc_ctx *ctx, polyc__point *tmp, float *view, int32_t cap,
                                 uint32_t *n);
/* means and central moments from the sums of the points of the tile at
 * directory entry d, in the numbering order of its marks (a point of
 * weight 0 left as it is); of every stored tile */
void polyc__block_finish_tile(const polyc_ctx *ctx, int32_t d, polyc__point *tmp);
void polyc__blocks_finish(polyc_ctx *ctx, polyc__point *tmp);

/* ---- what a layer above the batch stages lends them ----
 * The online mode (online*.c) reuses the batch stages on data of its own:
 * where a batch stage would compute from the stored scans, it calls these
 * hooks of ctx->layer (NULL in a batch context; the online table is in
 * online.c), and knows nothing else of the layer. */
struct polyc__opt;
/* the unsorted points a layer collects, and a tag per point that the sort
 * by bucket carries along (tag[i] to tag_out[its place]) */
typedef struct polyc__points_in {
    polyc__point *pts;
    float *view;                   /* 2 per point: towards the sensors */
    const uint32_t *tag;
    uint32_t *tag_out;
} polyc__points_in;
typedef struct polyc__layer {
    /* spacing.c: the layer's spacing table (n directory entries) into sp */
    polyc_status (*spacing)(polyc_ctx *ctx, polyc__spacing *sp, size_t n);
    /* opt_setup.c: the scratch of `collect` for this many points, carved
     * on the context's arena (0: no room; the caller gives it back) */
    int (*points_scratch)(polyc_ctx *ctx, int32_t points);
    /* points.c: the weighted points (at most cap) from the layer's data */
    polyc_status (*collect)(struct polyc__opt *o, int32_t cap, polyc__points_in *in, int32_t *n);
    /* grid.c: a walk's cells in a tile not stored (directory entry d) into
     * its record (take_back: out again); returns 1 when the walk left the
     * tile; and a tile stored now takes its record's misses */
    int (*rec_walk)(struct polyc__records *r, size_t d, struct polyc__walk *w, int64_t miss_key,
                    int take_back);
    void (*rec_take)(struct polyc__records *r, struct polyc__tile *t, size_t d);
    /* api.c: the optimiser that holds the layer's map, its points assigned
     * (polyc_find_curves) */
    struct polyc__opt *(*live_opt)(polyc_ctx *ctx);
} polyc__layer;

/* the stages' calls on these types */
#include "stages.h"

#endif
