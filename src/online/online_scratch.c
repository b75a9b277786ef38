/* online_scratch.c - the online steps' scratch: one region above the
 * grid's tiles that each step carves for itself and gives back (the
 * block holds the largest step's, online.c). Takes: the step. Gives: its
 * arrays in on->scr. */
#include "../online.h"

/* A step's scratch lives only while the step runs, so the steps share one
 * region above the tiles: the block holds the largest, not their sum. */
int polyc__online_scratch(polyc__arena *a, polyc__online *on, int32_t points, polyc__online_step step)
{
    int ok = 1;
    size_t P = (size_t)points;
    switch (step) {
    case POLYC__STEP_TRACE:
        POLYC__CARVE(ok, a, on->scr.cells, 2 * (size_t)polyc__online_cells_cap(on));
        break;
    case POLYC__STEP_POINTS:
        POLYC__CARVE(ok, a, on->scr.pts_tmp, P);
        POLYC__CARVE(ok, a, on->scr.view_tmp, 2 * P);
        POLYC__CARVE(ok, a, on->scr.fresh_tile, P);
        POLYC__CARVE(ok, a, on->scr.fresh_bucket, P);
        break;
    case POLYC__STEP_LEARN:
        POLYC__CARVE(ok, a, on->scr.learn_cache, 3 * (size_t)on->lim.max_scan_beams);
        break;
    case POLYC__STEP_DATALESS:
        POLYC__CARVE(ok, a, on->scr.seg_data, (size_t)on->opt.s->v_cap);
        break;
    }
    return ok;
}

/* The layer's points' scratch (polyc__layer, for polyc__opt_refresh). */
int polyc__online_points_scratch(polyc_ctx *ctx, int32_t points)
{
    return polyc__online_scratch(&ctx->arena, ctx->online, points, POLYC__STEP_POINTS);
}
