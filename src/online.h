/* online.h - the state of an online context (online.c, online_round.c,
 * online_changes.c): what the scans left behind (per-cell sums, poses,
 * the backlog of changed tiles), the kept scans, the optimiser that lives
 * across updates and the published versions. */
#ifndef POLYC_ONLINE_H
#define POLYC_ONLINE_H

#include "optimize.h"

/* One grid cell's endpoints: their count, the sums of their offsets from
 * the cell's centre and of those offsets' products (metres), and of the
 * vectors from them to their sensors. A scan taken back subtracts what it
 * added. */
typedef struct polyc__cell_sums {
    float fx, fy, fxx, fxy, fyy, vx, vy;
    uint32_t n;
} polyc__cell_sums;

/* What the last publication held of a polyline: its id, a hash of its
 * points, and the version that last changed it. */
typedef struct polyc__pub {
    uint32_t id, hash;
    uint64_t version;
} polyc__pub;

typedef struct polyc__online {
    polyc_online_limits lim;
    /* per cell of the stored tiles (tile index * 1024 + cell): 1 + its
     * entry in sums, 0 for a cell without endpoints */
    uint32_t *slot;
    polyc__cell_sums *sums;
    uint32_t sums_n;
    uint32_t *pose_bits;           /* bit per directory entry: a pose lay in the tile */
    float min_step_rad;            /* smallest |angle step| seen */
    float *spacing_dist;           /* the spacing table (spacing.c), per directory entry */

    /* the backlog: per directory entry 0, or 1 + the scan count when the
     * tile changed first since it was last re-optimised; and their list */
    uint32_t *dirty_since;
    uint32_t *dirty;
    uint32_t dirty_n;
    float last_x, last_y;          /* the latest pose, frame metres */
    uint32_t scans, pending;

    /* kept scans: ctx->scans[1 + k] and their ranges after the current
     * scan's; kept_id[k], ascending, is scan k's number */
    uint32_t *kept_id;
    uint32_t kept_n, kept_beams;

    /* the angle prior and the accuracy, learned scan by scan */
    polyc__prior prior;
    polyc__acc_learn acc;

    /* an update's scratch: the contour cells to trace, the points */
    int32_t *cells;
    uint32_t cells_cap;
    polyc__point *pts_tmp;
    float *view_tmp;

    polyc__opt opt;                /* the optimiser (its arrays in the block) */
    int opt_ready;                 /* it holds the map (0 before the first update) */

    /* publication */
    uint64_t version;
    polyc__pub *pub, *pub_next;    /* sorted by id */
    uint32_t pub_n;
    polyc_change *gone;            /* removals, oldest first (a ring of gone_cap) */
    uint32_t gone_first, gone_n, gone_cap;
    uint64_t forgot_through;       /* removals of versions up to this are forgotten */
} polyc__online;

/* online.c: the context's limits for the stages, from the online limits */
void polyc__online_stage_limits(const polyc_online_limits *ol, polyc_limits *lim);
/* online_round.c */
polyc_status polyc__online_round(polyc_ctx *ctx, uint64_t work, int all, uint64_t *spent);
/* online_changes.c: publishes the store as the context's result, a new
 * version if anything changed; *changed gets the polylines that did */
polyc_status polyc__online_publish(polyc_ctx *ctx, uint32_t *changed);
void polyc__online_pub_carve(polyc__arena *a, polyc__online *on, int32_t lines);

/* points.c: the weighted points from the cells' sums (online) */
/* opt_setup.c: the optimiser of an online context, carved once; and its
 * data refreshed from the sums before an update's search */
int polyc__opt_carve_online(polyc_ctx *ctx, polyc__arena *a, polyc__opt *o);
polyc_status polyc__opt_refresh(polyc__opt *o);
/* optimize.c: the search on a set-up optimiser (the batch loop) */
polyc_status polyc__search(polyc__opt *o, polyc_progress_fn progress, void *user);

#endif
