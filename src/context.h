/* context.h - the context: the state that lives from polyc_init to the
 * block's release (configuration, limits, arena, scans, grid, contour,
 * polylines, result, statistics, first error). api.c runs the stages on it;
 * a stage reads the parts it needs and leaves its working state in its own
 * structs (the optimiser's in polyc__opt, optimize.h). */
#ifndef POLYC_CONTEXT_H
#define POLYC_CONTEXT_H

#include "internal.h"

typedef enum polyc__stage {
    POLYC__STAGE_SCANS = 0,
    POLYC__STAGE_GRID,
    POLYC__STAGE_CONTOUR,
    POLYC__STAGE_TRACE,
    POLYC__STAGE_OPTIMIZED
} polyc__stage;

/* the first error of an operation: its static message and, for one met in
 * a scan, that scan's index (-1: none) */
typedef struct polyc__error {
    const char *msg;
    int32_t scan;
} polyc__error;

/* a direction, as its cosine and sine */
typedef struct polyc__turn {
    float cos, sin;
} polyc__turn;

/* a box, with whether it holds anything yet */
typedef struct polyc__extent {
    double min_x, min_y, max_x, max_y;
    int have;
} polyc__extent;

struct polyc_ctx {
    uint32_t magic;
    polyc_config cfg;
    polyc_limits lim;
    polyc__arena arena;
    size_t scans_mark;             /* arena use after the fixed scan storage */
    polyc__stage stage;
    polyc__error err;

    double frame_x, frame_y;       /* first pose: stored floats are relative to it */
    int have_frame;
    /* an occupancy grid (occupancy.c) instead of scans: stored floats are in
     * its frame, whose corner is frame_x, frame_y and whose x axis points
     * along frame_dir; its grid and contour are input, kept
     * below scans_mark */
    int from_grid;
    polyc__turn frame_dir;
    size_t base_mark;              /* arena use after polyc_init's scan storage */
    polyc_config grid_cfg;         /* the optimiser's weights for it (optimize.c);
                                      here, not on the optimiser's stack */
    polyc__scan *scans;
    float *ranges;
    uint32_t scan_count, range_count;
    polyc__extent ext;             /* frame-relative extent of the scans */

    polyc__grid grid;
    int32_t *contour_xy;           /* 2 per contour cell */
    uint32_t contour_count;
    size_t grid_mark;              /* arena use after the grid */
    size_t contour_mark;           /* arena use after the contour */

    polyc__store store;
    polyc__flat flat;
    int opt_result_valid;          /* the store holds a map to publish */
    size_t trace_mark;             /* arena use after the initial polylines */


    polyc_stats stats;
    struct polyc__online *online;  /* online.h; NULL for a batch context */
    const polyc__layer *layer;     /* its hooks into the batch stages (NULL: none) */
};

#define POLYC__MAGIC 0x706f6c79u   /* "poly" */
/* While the progress callback runs, the context is lent to the optimiser:
 * its magic reads POLYC__MAGIC_BUSY and every entry point refuses it with
 * POLYC_ERR_BUSY (context.c, guarded_progress). */
#define POLYC__MAGIC_BUSY 0x62757379u /* "busy" */
/* context.c: what every entry point, batch (api.c) or online (online*.c),
 * does on a context. */
/* an init's preamble: *out cleared (out not NULL), POLYC_ERR_NULL for a
 * missing argument, POLYC_ERR_CONFIG for an invalid config */
polyc_status polyc__init_args(const void *block, const polyc_config *config, const void *limits,
                              polyc_ctx **out);
/* Places a context at block's first 16-byte boundary: the first `head`
 * bytes zeroed (the context's header and what follows it), the arena after
 * them; POLYC_ERR_CONFIG when `need` (the size query's) is 0, NOMEM when
 * size is under it */
polyc_status polyc__place_ctx(void *block, size_t size, size_t need, size_t head,
                              const polyc_config *config, polyc_ctx **out);
/* POLYC_OK for a context an entry point may use */
polyc_status polyc__check_ctx(const polyc_ctx *ctx);
/* an entry point's preamble: the context checked, POLYC_ERR_NULL unless
 * args_ok (its pointer arguments), the last call's error cleared */
polyc_status polyc__enter(polyc_ctx *ctx, int args_ok);
/* a scan's ranges and geometry checked (POLYC_ERR_NULL, POLYC_ERR_SCAN
 * with err.scan = number) */
polyc_status polyc__scan_check(polyc_ctx *ctx, const polyc_scan *s, uint32_t number);
/* the stored form of a scan in d (pose relative to the frame), its ranges
 * at ctx->ranges + first; take: with its ranges copied there */
void polyc__store_scan(polyc_ctx *ctx, polyc__scan *d, const polyc_scan *s, uint32_t first);
void polyc__take_scan(polyc_ctx *ctx, polyc__scan *d, const polyc_scan *s, uint32_t first);
/* its beams into the statistics (beams, hits, skipped) */
void polyc__tally_beams(polyc_ctx *ctx, const polyc_scan *s);
/* the caller's progress callback, called with the context lent */
typedef struct polyc__guarded {
    polyc_ctx *ctx;
    polyc_progress_fn progress;
    void *user;
} polyc__guarded;
int polyc__guarded_progress(void *user, const polyc_iteration *it);
/* the store as the published result, in the input's frame */
void polyc__export_result(polyc_ctx *ctx);

/* The kind of input, decided here once: an occupancy grid, a single scan
 * (mapped from its beam order, scan_chains.c, and checked against its
 * beams, ray_check.c; unless POLYC_FLAG_GRID_TRACE asks for the grid's
 * trace) or scans. */
typedef enum polyc__input {
    POLYC__INPUT_SCANS = 0,
    POLYC__INPUT_ONE_SCAN,
    POLYC__INPUT_GRID
} polyc__input;
static inline polyc__input polyc__input_kind(const polyc_ctx *ctx)
{
    if (ctx->from_grid)
        return POLYC__INPUT_GRID;
    if (ctx->online)
        return POLYC__INPUT_SCANS;
    return ctx->scan_count == 1 && !(ctx->cfg.flags & POLYC_FLAG_GRID_TRACE) ? POLYC__INPUT_ONE_SCAN
                                                                              : POLYC__INPUT_SCANS;
}

/* errors: keep the first message of an operation (C99 inline: its external
 * definition is in context.c) */
inline polyc_status polyc__fail(polyc_ctx *ctx, polyc_status st, const char *msg)
{
    if (ctx && !ctx->err.msg)
        ctx->err.msg = msg;
    return st;
}

#endif
