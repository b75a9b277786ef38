/* online.h - the state of an online context and the online layer's
 * routines (src/online/, a layer above the batch stages: no batch file
 * includes this header, make test-batch-alone). Each part of the state has one file
 * that owns it: the cell table (online_cells.c), the poses and the backlog
 * (online_scan.c; the rounds take tiles out: online_round.c), the kept
 * scans and their corrections (online_correct.c), the grid's records
 * (online_grid.c), the scratch (online_scratch.c), the optimiser's data
 * (online_data.c; its points made by online_points.c), the publications
 * (online_changes.c). */
#ifndef POLYC_ONLINE_H
#define POLYC_ONLINE_H

#include "optimize.h"

/* One grid cell's endpoints: their count, the sums of their offsets from
 * the cell's centre and of those offsets' products (metres), and of the
 * vectors from them to their sensors; and the cell (polyc__cell_key). A
 * scan taken back subtracts what it added. */
typedef struct polyc__cell_sums {
    float fx, fy, fxx, fxy, fyy, vx, vy;
    uint32_t n;                    /* a free entry: 1 + the next free one, 0: none */
    uint32_t cell;
} polyc__cell_sums;

/* What the last publication held of a polyline: its id, a hash of its
 * points, and the version that last changed it. */
typedef struct polyc__pub {
    uint32_t id, hash;
    uint64_t born, version;        /* the versions that added it and last changed it */
} polyc__pub;

/* The misses in tiles not stored (online_grid.c): a pool of pre_cap
 * records, and the redo of the kept scans' misses after a recount. */
typedef struct polyc__records {
    uint32_t *pre_of;              /* per directory entry: its record + 1, or 0 */
    uint16_t *pre_miss;            /* per record: per block, its cells' misses */
    uint8_t *pre_cells;            /* per record: each cell's, half a byte, up to POLYC__PRE_FULL */
    uint32_t *pre_free;            /* records given back */
    uint32_t pre_cap, pre_high, pre_nfree;
    /* bit per directory entry: the tile was not stored when the counts were
     * made again without their records (polyc__grid_recount_scan) */
    uint32_t *redo_need;
    /* the kept scans redo_next .. redo_end - 1 still to put their misses
     * back (polyc__online_redo_records) */
    uint32_t redo_next, redo_end;
} polyc__records;

/* The cells with endpoints (online_cells.c): their sums, and a table of
 * 1 + their entries (0: an empty slot) by the hash of their key; per
 * stored tile, how many of its cells have sums. */
typedef struct polyc__cell_table {
    polyc__cell_sums *sums;        /* cap entries */
    uint32_t *cell_at;             /* cell_mask + 1 slots */
    uint32_t *tile_cells;
    uint32_t cap;                  /* limits.max_points */
    uint32_t sums_n;
    uint32_t sums_free;            /* 1 + a free entry (a list through their n), 0: none */
    uint32_t blocks_n;             /* 2 x 2 blocks of cells with sums: weighted points */
    uint32_t cell_mask, cell_shift;
} polyc__cell_table;

/* Where the scans were (online_scan.c): the tiles that held a pose, and the
 * spacing table made from them (the layer's, for spacing.c). */
typedef struct polyc__poses {
    uint32_t *pose_bits;           /* bit per directory entry: a pose lay in the tile */
    float *spacing_dist;           /* the spacing table, per directory entry */
    float min_step_rad;            /* smallest |angle step| seen */
    float last_x, last_y;          /* the latest pose, frame metres */
    int spacing_stale;             /* a pose fell in a new tile since it was made */
    uint32_t spacing_scans;        /* the scan count when it was made */
    int spacing_now;               /* make it again now if stale (the finishing call) */
} polyc__poses;

/* The backlog of changed tiles: joined as scans come (online_scan.c),
 * taken by the rounds (online_round.c). Per directory entry 0, or 1 + the
 * scan count when the tile changed first since it was last re-optimised
 * (TAKEN while a round holds it), and their list; per stored tile, the
 * endpoints its points hold (online_data.c), the endpoints in or out since
 * its refresh, and the misses counted in its cells with hits. */
typedef struct polyc__backlog {
    uint32_t *dirty_since;
    uint32_t *dirty;
    float *tile_raw;
    uint32_t *tile_new;
    uint32_t *tile_miss;
    uint32_t dirty_n;
} polyc__backlog;

/* The kept scans and their corrections (online_correct.c): ctx->scans[1 +
 * k] and their ranges after the current scan's; id[k], ascending, is scan
 * k's number. */
typedef struct polyc__kept {
    uint32_t *id;
    uint32_t *moved;               /* bit per kept scan: a correction waits */
    double *new_pose;              /* per kept scan: the waiting pose (x, y, theta) */
    uint32_t n, beams;
    uint32_t moved_n;
    /* corrections of every kept scan were applied: the prior and the
     * accuracy are learned again before the next round or scan */
    uint32_t learn_due;
} polyc__kept;

/* Scratch, carved above the tiles by the step that needs it and given back
 * after it (polyc__online_scratch, online_scratch.c): a round's contour
 * cells and, after the trace, its flags; the points made again and their
 * tiles and buckets; the prior's endpoint cache for one scan. NULL while
 * not carved. */
typedef struct polyc__online_scratch_area {
    int32_t *cells;
    polyc__point *pts_tmp;
    float *view_tmp;
    uint32_t *fresh_tile;          /* per new point: its tile's directory entry */
    int32_t *fresh_bucket;         /* per new point: its bucket */
    float *learn_cache;
    uint8_t *seg_data;             /* per segment: a point supports it (drop_dataless) */
} polyc__online_scratch_area;

/* The published versions (online_changes.c). */
typedef struct polyc__publication {
    uint64_t version;
    uint64_t forgot_through;       /* removals of versions up to this are forgotten */
    polyc__pub *pub, *pub_next;    /* sorted by id */
    polyc__pub *gone;              /* removals (version: the removal's), oldest
                                    * first, a ring of gone_cap */
    uint32_t pub_n;
    uint32_t gone_first, gone_n, gone_cap;
} polyc__publication;

/* An online context's state, each part with the file that owns it. */
typedef struct polyc__online {
    polyc_online_limits lim;
    polyc__cell_table tab;
    polyc__poses poses;
    polyc__backlog backlog;
    polyc__kept kept;
    polyc__records rec;            /* the grid's records (online_grid.c) */
    /* the angle prior and the accuracy, learned scan by scan
     * (online_scan.c; again from the kept scans: online_correct.c) */
    polyc__prior prior;
    polyc__acc_learn acc;
    polyc__online_scratch_area scr;
    /* the optimiser (its arrays in the block) and its data's books
     * (online_data.c): per point, its tile's directory entry; per bucket a
     * count or fill position */
    polyc__opt opt;
    uint32_t *pt_tile, *bucket_fill;
    polyc__publication pubs;
    uint32_t scans, pending;       /* scans added; since the last update */
    int refused;                   /* the last add's scan went out again (no room) */
    int opt_ready;                 /* the optimiser holds the map (0 before the first update) */
} polyc__online;

/* ---- online.c: sizes, the block's layout, the layer table ---- */
/* The head of an online context's block: the context, then its online
 * state (one struct, so that they pad as one). */
typedef struct polyc__online_head {
    polyc_ctx ctx;
    polyc__online on;
} polyc__online_head;
/* the contour cells a round may list (limits.max_points + 1) */
static inline uint32_t polyc__online_cells_cap(const polyc__online *on)
{
    return on->lim.max_points + 1;
}
/* the context's limits for the stages, from the online limits */
void polyc__online_stage_limits(const polyc_online_limits *ol, polyc_limits *lim);
/* online_scratch.c: the scratch of one step (scr), carved from a (the
 * context's arena above the tiles; the caller gives it back); 0: no room */
typedef enum polyc__online_step {
    POLYC__STEP_TRACE,             /* cells (and the trace's own walk) */
    POLYC__STEP_POINTS,            /* pts_tmp, view_tmp, fresh_tile, fresh_bucket */
    POLYC__STEP_LEARN,             /* learn_cache */
    /* seg_data: after the trace, in its walk's room (so counted in
     * POLYC__STEP_TRACE's) */
    POLYC__STEP_DATALESS
} polyc__online_step;
int polyc__online_scratch(polyc__arena *a, polyc__online *on, int32_t points, polyc__online_step step);
/* the layer's points' scratch (polyc__layer, for polyc__opt_refresh) */
int polyc__online_points_scratch(polyc_ctx *ctx, int32_t points);

/* ---- online_scan.c: one scan in (or out) ---- */
/* how a scan goes into the grid, the sums and the rest */
enum {
    POLYC__SCAN_NEW,      /* a new scan: its contour and its lines too */
    POLYC__SCAN_MOVED,    /* a corrected scan, in again at its new pose */
    POLYC__SCAN_OUT,      /* its counts and sums out again */
    POLYC__SCAN_RECOUNT   /* in again on cleared counts, as a batch counts it
                           * (its records later: polyc__online_redo_records);
                           * the misses on hit cells, which put a tile in the
                           * backlog, are not tallied (every tile joins it:
                           * polyc__online_apply_corrections) */
};
/* The scan's beams into the grid and its endpoints into the sums; a new
 * scan's first occupied cells into the contour and its lines into the
 * prior (`number`: its scan number). POLYC__SCAN_OUT takes its counts and
 * sums out again. */
polyc_status polyc__online_accumulate(polyc_ctx *ctx, const polyc__scan *s, uint32_t number, int how);
/* the first occupied cell along each of the scan's beams labelled contour */
void polyc__online_label_contour(polyc_ctx *ctx, const polyc__scan *s);
/* POLYC_OK if the scan at its pose lies inside the area (frame metres),
 * else POLYC_ERR_EXTENT, reported */
polyc_status polyc__online_inside_area(polyc_ctx *ctx, const polyc_scan *s);
/* polyc__enter, and POLYC_ERR_STATE (reported) unless ctx is an online
 * context: the online entry points' preamble */
polyc_status polyc__online_enter(polyc_ctx *ctx, int args_ok);
/* the layer's spacing table (polyc__layer): made again from the tiles
 * that held a pose when stale */
polyc_status polyc__online_spacing(polyc_ctx *ctx, polyc__spacing *sp, size_t n);
/* the tiles whose cells with hits beams have crossed often into the
 * backlog (every few scans); every stored tile (the finishing call) */
void polyc__online_backlog_misses(polyc_ctx *ctx);
void polyc__online_backlog_all(polyc_ctx *ctx);
/* the sum of the view vectors of a cell's endpoints (0, 0: none) */
void polyc__online_cell_view(const polyc_ctx *ctx, int32_t ix, int32_t iy, float *vx, float *vy);

/* ---- online_correct.c: pose corrections ---- */
/* the corrections given since the last update (or add) into the grid, the
 * sums and the contour; when every scan is kept, every tile into the
 * backlog and the prior and the accuracy due to be learned again; the
 * beams that cast into *beams_cast (0 when none waited; may be NULL) */
polyc_status polyc__online_apply_corrections(polyc_ctx *ctx, uint64_t *beams_cast);
/* the prior and the accuracy learned again from the kept scans, if due */
void polyc__online_learn_due(polyc_ctx *ctx);

/* ---- online_grid.c: the grid's records of misses in tiles not stored ---- */
/* the records carved for a grid of tile_cap tiles and dir_n directory
 * entries (0: no room) */
int polyc__records_carve(polyc__arena *a, polyc__records *r, uint32_t tile_cap, size_t dir_n);
/* the layer's hooks for the grid's count (polyc__layer) */
int polyc__records_walk(polyc__records *rec, size_t d, struct polyc__walk *w, int64_t miss_key,
                        int take_back);
void polyc__records_take(polyc__records *rec, polyc__tile *t, size_t d);
/* every count to 0, in the stored tiles and in the records, which go back
 * to the pool; the tiles stay stored (their contour bits too: the caller
 * casts the contour again) */
void polyc__records_clear_counts(polyc__grid *g, polyc__records *r);
/* after every kept scan was counted again without the records: the tiles
 * not stored now noted, and the kept_n kept scans' misses in them due */
void polyc__records_redo_begin(polyc_ctx *ctx, polyc__records *r, uint32_t kept_n);
/* the records' misses of the next kept scans put back (in the tiles
 * stored since, into their counts, misses on cells with hits tallied in
 * tile_miss), until `beams` (> 0) of their beams are done (UINT32_MAX: all) */
void polyc__online_redo_records(polyc_ctx *ctx, uint32_t beams);

/* ---- online_points.c: the weighted points from the cells' sums ---- */
/* the layer's collect (polyc__layer): every stored tile's points from the
 * cells' sums, into the points' scratch */
polyc_status polyc__online_collect(polyc__opt *o, int32_t cap, polyc__points_in *in, int32_t *n_out);
/* the sums of the cells of the tile at directory entry d into its marked
 * blocks' points (tmp, view); returns the endpoints taken */
float polyc__online_sum_tile(const polyc_ctx *ctx, int32_t d, polyc__point *tmp, float *view);
/* the points of weight 0 (cells with hits but no sums) out, the others
 * (and their views and tiles) moved up; returns how many are left */
uint32_t polyc__online_drop_empty(polyc__point *pts, float *view, uint32_t *tile, uint32_t n);

/* ---- online_data.c: the optimiser's data and books ---- */
/* the buckets within a bucket of the first `taken` tiles of the backlog,
 * in o->chg.bucket_list (a new epoch) */
void polyc__online_list_taken_buckets(polyc_ctx *ctx, uint32_t taken);
/* the points of the n taken tiles (the first n of the backlog, marked)
 * made again from the sums */
polyc_status polyc__online_refresh_tiles(polyc_ctx *ctx, uint32_t n);
/* the polylines with ids above after_id (traced by this update) into the
 * hash and the books */
polyc_status polyc__online_add_lines(polyc_ctx *ctx, uint32_t after_id);
/* and out again (a trace or an insertion that ran out of room) */
void polyc__online_drop_lines(polyc_ctx *ctx, uint32_t after_id);

/* ---- online_round.c: a round on the backlog's tiles (all: every tile) ---- */
polyc_status polyc__online_round(polyc_ctx *ctx, uint64_t work, int all, uint64_t *spent);

/* ---- online_changes.c: the published versions ---- */
/* publishes the store as the context's result, a new version if anything
 * changed; *changed gets the polylines that did */
polyc_status polyc__online_publish(polyc_ctx *ctx, uint32_t *changed);
void polyc__online_pub_carve(polyc__arena *a, polyc__online *on, int32_t lines);

/* ---- online_cells.c: the cells with endpoints ---- */
/* a cell's key, from its tile's storage index and its index in the tile */
static inline uint32_t polyc__cell_key(uint32_t tile, int idx)
{
    return tile * POLYC__TILE_CELLS + (uint32_t)idx;
}
/* the sums (cap entries), the table and the tiles' counts, carved (a
 * zeroed table) */
int polyc__cells_carve(polyc__arena *a, polyc__cell_table *tab, uint32_t cap, uint32_t tile_cap);
/* 1 + the entry of the cell's sums, 0 for a cell without endpoints */
uint32_t polyc__cell_find(const polyc__cell_table *tab, uint32_t key);
/* the same, the cell added with zero sums if it has none; 0 when the
 * entries (limits.max_points) are used up */
uint32_t polyc__cell_add(polyc__cell_table *tab, uint32_t key);
/* entry (1 + its index) out: its cell has no endpoints left */
void polyc__cell_drop(polyc__cell_table *tab, uint32_t entry);
/* every entry out: the table empty (tiles: the grid's stored tiles) */
void polyc__cells_clear(polyc__cell_table *tab, uint32_t tiles);

#endif
