/* api.c - the batch entry points on a context: sizing, context, scans,
 * stage order and results (what the online entry points share with these
 * is in context.c). Takes: the caller's block and scans. Gives: the
 * pipeline run stage by stage, each stage restartable from its arena mark. */
#include "context.h"

#include <math.h>
#include <string.h>

/* ---- sizing and context ---- */

/* the scans' poses and their ranges */
static int scans_carve(polyc__arena *a, const polyc_limits *lim, polyc__scan **scans, float **ranges)
{
    *scans = polyc__alloc(a, lim->max_scans, sizeof(polyc__scan));
    *ranges = polyc__alloc(a, lim->max_beams, sizeof(float));
    return (*scans || !lim->max_scans) && (*ranges || !lim->max_beams);
}

/* The size is the peak of a counting arena on which every stage carves what
 * it would carve under the limits, in the order of the block's layout. */
size_t polyc_memory_size(const polyc_config *config, const polyc_limits *limits)
{
    if (!config || !limits || polyc_config_check(config, NULL) != POLYC_OK)
        return 0;
    polyc__arena a;
    polyc__scan *scans;
    float *ranges;
    polyc__arena_counting(&a);
    scans_carve(&a, limits, &scans, &ranges);
    polyc__grid_reserve(&a, limits);
    /* a single scan's chains start where the contour would (need_stage) */
    size_t grid_mark = a.used;
    polyc__chains_reserve(&a, limits);
    a.used = grid_mark;
    polyc__contour_reserve(&a, limits);
    polyc__trace_reserve(&a, limits);
    polyc__flat_reserve(&a, polyc__max_vertices(limits), 1); /* the result */
    polyc__prior_reserve(&a, limits);
    polyc__optimizer_reserve(&a, config, limits);
    size_t head = polyc__bytes(1, sizeof(polyc_ctx)) + 16; /* + alignment of the block */
    size_t n = polyc__add(head, a.peak);
    return n == SIZE_MAX ? 0 : n;
}

polyc_status polyc_init(void *block, size_t size, const polyc_config *config,
                        const polyc_limits *limits, polyc_ctx **out)
{
    polyc_ctx *ctx;
    polyc_status st = polyc__init_args(block, config, limits, out);
    if (st == POLYC_OK)
        st = polyc__place_ctx(block, size, polyc_memory_size(config, limits),
                              polyc__bytes(1, sizeof(polyc_ctx)), config, &ctx);
    if (st != POLYC_OK)
        return st;
    ctx->lim = *limits;
    if (!scans_carve(&ctx->arena, limits, &ctx->scans, &ctx->ranges))
        return POLYC_ERR_NOMEM;
    ctx->scans_mark = ctx->base_mark = ctx->arena.used;
    *out = ctx;
    return POLYC_OK;
}

polyc_status polyc_reset(polyc_ctx *ctx)
{
    polyc_status cst = polyc__check_ctx(ctx);
    if (cst != POLYC_OK)
        return cst;
    if (ctx->online)
        return polyc__fail(ctx, POLYC_ERR_STATE, "an online context: use the polyc_online_* calls");
    ctx->arena.used = ctx->scans_mark = ctx->base_mark;
    ctx->scan_count = ctx->range_count = 0;
    ctx->have_frame = ctx->ext.have = 0;
    ctx->from_grid = 0;
    ctx->frame_x = ctx->frame_y = 0.0;
    ctx->frame_dir.cos = 1.0f;
    ctx->frame_dir.sin = 0.0f;
    memset(&ctx->grid, 0, sizeof ctx->grid);
    ctx->contour_count = 0;
    ctx->stage = POLYC__STAGE_SCANS;
    ctx->err.msg = NULL;
    ctx->err.scan = -1;
    ctx->flat.count = 0;
    uint64_t size = ctx->stats.memory_size_bytes;
    memset(&ctx->stats, 0, sizeof ctx->stats);
    ctx->stats.memory_size_bytes = size;
    return POLYC_OK;
}

polyc_status polyc_add_scan(polyc_ctx *ctx, const polyc_scan *s)
{
    polyc_status st = polyc__enter(ctx, s != NULL);
    if (st != POLYC_OK)
        return st;
    if (ctx->from_grid)
        return polyc__fail(ctx, POLYC_ERR_STATE,
                           "the context holds a grid: scans need a context of their own");
    if (ctx->online)
        return polyc__fail(ctx, POLYC_ERR_STATE, "an online context takes scans by polyc_online_add_scan");
    if ((st = polyc__scan_check(ctx, s, ctx->scan_count)) != POLYC_OK)
        return st;
    if (ctx->scan_count >= ctx->lim.max_scans ||
        s->beam_count > ctx->lim.max_beams - ctx->range_count)
        return polyc__fail(ctx, POLYC_ERR_LIMIT, "more scans or beams than the limits allow");
    if (!ctx->have_frame)
        polyc__frame_set(ctx, s->pose_x_m, s->pose_y_m);
    polyc__take_scan(ctx, &ctx->scans[ctx->scan_count], s, ctx->range_count);
    polyc__tally_beams(ctx, s);
    double box[4] = {ctx->ext.min_x, ctx->ext.min_y, ctx->ext.max_x, ctx->ext.max_y};
    polyc__extent_add(s, ctx->frame_x, ctx->frame_y, box, &ctx->ext.have);
    ctx->ext.min_x = box[0];
    ctx->ext.min_y = box[1];
    ctx->ext.max_x = box[2];
    ctx->ext.max_y = box[3];
    ctx->range_count += s->beam_count;
    ctx->scan_count++;
    ctx->stats.scans = ctx->scan_count;
    ctx->stage = POLYC__STAGE_SCANS;
    return POLYC_OK;
}

polyc_status polyc_add_grid(polyc_ctx *ctx, const polyc_occupancy_grid *grid)
{
    polyc_status st = polyc__enter(ctx, grid != NULL);
    if (st == POLYC_OK && ctx->online)
        st = polyc__fail(ctx, POLYC_ERR_STATE, "an online context: use the polyc_online_* calls");
    return st != POLYC_OK ? st : polyc__occ_add(ctx, grid);
}

/* ---- stages ---- */

static void note_memory(polyc_ctx *ctx)
{
    size_t head = polyc__bytes(1, sizeof(polyc_ctx));
    ctx->stats.memory_used_bytes = (uint64_t)(head + ctx->arena.peak);
}

/* Run a stage from its arena mark; on failure roll back to the stage before. */
static polyc_status run_stage(polyc_ctx *ctx, polyc__stage to, size_t mark,
                              polyc_status (*fn)(polyc_ctx *), polyc__stage before)
{
    ctx->arena.used = mark;
    polyc_status st = fn(ctx);
    note_memory(ctx);
    if (st != POLYC_OK) {
        ctx->arena.used = mark;
        ctx->stage = before;
        return st;
    }
    ctx->stage = to;
    return POLYC_OK;
}

static polyc_status stage_grid(polyc_ctx *ctx)
{
    polyc_status st = polyc__grid_build(ctx);
    ctx->grid_mark = ctx->arena.used;
    return st;
}

/* Initial polylines from a single scan's beam order (scan_chains.c) */
static int one_scan_chains(const polyc_ctx *ctx)
{
    return polyc__input_kind(ctx) == POLYC__INPUT_ONE_SCAN;
}

static polyc_status stage_contour(polyc_ctx *ctx)
{
    polyc_status st = polyc__contour_build(ctx);
    ctx->contour_mark = ctx->arena.used;
    return st;
}

static polyc_status stage_trace(polyc_ctx *ctx)
{
    polyc_status st = one_scan_chains(ctx) ? polyc__chains_build(ctx) : polyc__trace_build(ctx);
    if (st != POLYC_OK)
        return st;
    int32_t vcap = ctx->store.v_cap;
    if (!polyc__flat_result(&ctx->arena, &ctx->flat, (uint32_t)polyc__line_cap(vcap), (uint32_t)vcap))
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the result polylines");
    polyc__export_result(ctx);
    ctx->stats.initial_polylines = ctx->stats.polylines;
    ctx->stats.initial_vertices = ctx->stats.vertices;
    ctx->trace_mark = ctx->arena.used;
    return POLYC_OK;
}

static polyc_status need_stage(polyc_ctx *ctx, polyc__stage want)
{
    polyc_status st = POLYC_OK;
    if (ctx->online)
        return polyc__fail(ctx, POLYC_ERR_STATE, "an online context: use the polyc_online_* calls");
    if (ctx->from_grid && ctx->stage < POLYC__STAGE_CONTOUR)
        ctx->stage = POLYC__STAGE_CONTOUR; /* an occupancy grid's are its input */
    if (ctx->stage < POLYC__STAGE_GRID && want >= POLYC__STAGE_GRID)
        st = run_stage(ctx, POLYC__STAGE_GRID, ctx->scans_mark, stage_grid, POLYC__STAGE_SCANS);
    if (st == POLYC_OK && ctx->stage < POLYC__STAGE_CONTOUR && want > POLYC__STAGE_CONTOUR &&
        one_scan_chains(ctx)) {
        /* the chains do not need it: left empty unless asked for */
        ctx->contour_count = 0;
        ctx->contour_mark = ctx->grid_mark;
        ctx->stats.contour_cells = 0;
        ctx->stage = POLYC__STAGE_CONTOUR;
    }
    if (st == POLYC_OK && ctx->stage < POLYC__STAGE_CONTOUR && want >= POLYC__STAGE_CONTOUR)
        st = run_stage(ctx, POLYC__STAGE_CONTOUR, ctx->grid_mark, stage_contour, POLYC__STAGE_GRID);
    if (st == POLYC_OK && ctx->stage < POLYC__STAGE_TRACE && want >= POLYC__STAGE_TRACE) {
        /* a single scan's chains take the room of a contour list they do not
         * read (one asked for by polyc_extract_contour is released; the grid
         * keeps its contour bits), so that polyc_memory_size charges the
         * larger of the two, not both */
        size_t mark = ctx->contour_mark;
        if (one_scan_chains(ctx)) {
            mark = ctx->contour_mark = ctx->grid_mark;
            ctx->contour_count = 0;
        }
        st = run_stage(ctx, POLYC__STAGE_TRACE, mark, stage_trace, POLYC__STAGE_CONTOUR);
    }
    return st;
}

/* An explicit call of a stage: redone from the stage before it (`from`,
 * an occupancy grid's contour: its input), the results after it dropped,
 * then run up to `want`. */
static polyc_status redo_stage(polyc_ctx *ctx, polyc__stage from, polyc__stage want)
{
    polyc_status cst = polyc__enter(ctx, 1);
    if (cst != POLYC_OK)
        return cst;
    if (ctx->online) /* before the stage moves: the map stays readable */
        return polyc__fail(ctx, POLYC_ERR_STATE, "an online context: use the polyc_online_* calls");
    if (ctx->from_grid && from < POLYC__STAGE_CONTOUR)
        from = POLYC__STAGE_CONTOUR;
    if (ctx->stage > from || want == POLYC__STAGE_GRID)
        ctx->stage = from; /* the grid is always built again */
    return need_stage(ctx, want);
}

polyc_status polyc_build_grid(polyc_ctx *ctx)
{
    return redo_stage(ctx, POLYC__STAGE_SCANS, POLYC__STAGE_GRID);
}

polyc_status polyc_extract_contour(polyc_ctx *ctx)
{
    return redo_stage(ctx, POLYC__STAGE_GRID, POLYC__STAGE_CONTOUR);
}

polyc_status polyc_trace(polyc_ctx *ctx)
{
    return redo_stage(ctx, POLYC__STAGE_CONTOUR, POLYC__STAGE_TRACE);
}

polyc_status polyc_optimize(polyc_ctx *ctx, polyc_progress_fn progress, void *user)
{
    polyc_status cst = polyc__enter(ctx, 1);
    if (cst != POLYC_OK)
        return cst;
    polyc_status st = need_stage(ctx, POLYC__STAGE_TRACE);
    if (st != POLYC_OK)
        return st;
    ctx->arena.used = ctx->trace_mark;
    polyc__guarded g = {ctx, progress, user};
    st = polyc__optimize(ctx, progress ? polyc__guarded_progress : NULL, &g);
    note_memory(ctx);
    ctx->arena.used = ctx->trace_mark;
    if (ctx->opt_result_valid) {
        /* the best map found (after a failure mid-search too: the store
         * and the published result never disagree) */
        polyc__export_result(ctx);
        ctx->stage = POLYC__STAGE_OPTIMIZED;
    }
    return st;
}

polyc_status polyc_build(polyc_ctx *ctx, polyc_progress_fn progress, void *user)
{
    polyc_status cst = polyc__enter(ctx, 1);
    if (cst != POLYC_OK)
        return cst;
    polyc_status st = need_stage(ctx, POLYC__STAGE_TRACE);
    if (st != POLYC_OK || ctx->cfg.max_iterations == 0)
        return st;
    return polyc_optimize(ctx, progress, user);
}

polyc_status polyc_find_curves(polyc_ctx *ctx)
{
    polyc_status cst = polyc__enter(ctx, 1);
    if (cst != POLYC_OK)
        return cst;
    if (ctx->stage < POLYC__STAGE_TRACE && !ctx->online)
        return polyc__fail(ctx, POLYC_ERR_STATE, "no polylines yet: run polyc_trace first");
    if (ctx->layer && ctx->layer->live_opt) { /* its optimiser holds the map */
        polyc__circles_select(ctx->layer->live_opt(ctx));
        polyc__arcs_select(ctx->layer->live_opt(ctx));
        return POLYC_OK;
    }
    ctx->arena.used = ctx->trace_mark;
    polyc_status st = polyc__find_curves(ctx);
    note_memory(ctx);
    ctx->arena.used = ctx->trace_mark;
    return st;
}

polyc_status polyc_score(polyc_ctx *ctx, double *bic, double *err)
{
    polyc_status cst = polyc__enter(ctx, 1);
    if (cst != POLYC_OK)
        return cst;
    if (ctx->online)
        return polyc__fail(ctx, POLYC_ERR_STATE, "an online context: use the polyc_online_* calls");
    if (ctx->stage < POLYC__STAGE_TRACE)
        return polyc__fail(ctx, POLYC_ERR_STATE, "no polylines yet: run polyc_trace first");
    ctx->arena.used = ctx->trace_mark;
    polyc_status st = polyc__score(ctx, bic, err);
    note_memory(ctx);
    ctx->arena.used = ctx->trace_mark;
    return st;
}
