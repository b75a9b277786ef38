/* api.c - the public entry points: configuration, sizing, context, scans,
 * stage order and results. Takes: the caller's block and scans. Gives: the
 * pipeline run stage by stage, each stage restartable from its arena mark. */
#include "context.h"

#include <math.h>
#include <string.h>

uint32_t polyc_version(void)
{
    return POLYC_VERSION;
}

const char *polyc_status_str(polyc_status st)
{
    switch (st) {
    case POLYC_OK: return "ok";
    case POLYC_ERR_NULL: return "a required pointer was NULL";
    case POLYC_ERR_CONFIG: return "configuration or limit out of range";
    case POLYC_ERR_NOMEM: return "memory block too small";
    case POLYC_ERR_SCAN: return "malformed scan";
    case POLYC_ERR_STATE: return "call out of order";
    case POLYC_ERR_EXTENT: return "data extent too large";
    case POLYC_ERR_LIMIT: return "more scans or beams than the limits allow";
    case POLYC_ERR_RANGE: return "index out of range";
    case POLYC_ERR_STOPPED: return "stopped by the progress callback";
    case POLYC_ERR_BUSY: return "called from inside the progress callback";
    }
    return "unknown status";
}

size_t polyc_struct_size(const char *name)
{
    static const struct { const char *name; size_t size; } sizes[] = {
        {"polyc_config", sizeof(polyc_config)},   {"polyc_limits", sizeof(polyc_limits)},
        {"polyc_scan", sizeof(polyc_scan)},       {"polyc_box", sizeof(polyc_box)},
        {"polyc_polyline", sizeof(polyc_polyline)}, {"polyc_stats", sizeof(polyc_stats)},
        {"polyc_iteration", sizeof(polyc_iteration)},
        {"polyc_occupancy_grid", sizeof(polyc_occupancy_grid)},
    };
    if (!name)
        return 0;
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++)
        if (strcmp(name, sizes[i].name) == 0)
            return sizes[i].size;
    return 0;
}

void polyc_config_default(polyc_config *c)
{
    if (!c)
        return;
    memset(c, 0, sizeof *c);
    c->cell_m = 0.025f;
    c->contour_threshold = 0.5f;
    c->data_min_m = 0.2f;
    c->free_range_m = 10.0f;
    c->grazing_cells = 4.0f;
    c->max_extent_m = 2000.0f;
    c->alpha = 500.0f;
    c->gamma = 0.02f;
    c->merge_dist_m = 0.15f;
    c->split_gap_m = 0.20f;
    c->step_m = 0.01f;
    c->noise_m = 0.05f;
    c->noise_decay = 0.7f;
    c->overlap_m = 0.05f;
    c->search_radius_m = 0.15f;
    c->patience = 5;
    c->max_iterations = 100;
    c->flags = 0;
    c->seed = 1;
    c->occupied_thresh = 0.65f;
    c->free_thresh = 0.196f;
}

static int in(float v, float lo, float hi)
{
    return v >= lo && v <= hi; /* false for NaN */
}

polyc_status polyc_config_check(const polyc_config *c, const char **why)
{
    const char *w = NULL;
    if (!c) {
        if (why) *why = "config is NULL";
        return POLYC_ERR_NULL;
    }
    if (!in(c->cell_m, 0.001f, 10.0f)) w = "cell_m must be in [0.001, 10]";
    else if (!in(c->contour_threshold, 0.0f, 0.999f)) w = "contour_threshold must be in [0, 1)";
    else if (!in(c->data_min_m, 0.0f, 1.0f)) w = "data_min_m must be in [0, 1]";
    else if (!in(c->free_range_m, 0.0f, 1e4f)) w = "free_range_m must be in [0, 10000]";
    else if (!in(c->grazing_cells, 0.0f, 100.0f)) w = "grazing_cells must be in [0, 100]";
    else if (!in(c->max_extent_m, 0.01f, 1e6f)) w = "max_extent_m must be in [0.01, 1e6]";
    else if (!in(c->alpha, 1e-6f, 1e12f)) w = "alpha must be positive";
    else if (!in(c->gamma, 0.0f, 1e6f)) w = "gamma must be in [0, 1e6]";
    else if (!in(c->merge_dist_m, 0.0f, 100.0f)) w = "merge_dist_m must be in [0, 100]";
    else if (!in(c->split_gap_m, 1e-4f, 100.0f)) w = "split_gap_m must be in (0, 100]";
    else if (!in(c->step_m, 1e-5f, POLYC__STEP_MAX_M))
        w = "step_m must be in (0, 0.025]: a longer step leaves the hill climb's reach";
    else if (!in(c->noise_m, 0.0f, 10.0f)) w = "noise_m must be in [0, 10]";
    else if (!in(c->noise_decay, 1e-6f, 1.0f)) w = "noise_decay must be in (0, 1]";
    else if (!in(c->overlap_m, 0.0f, 10.0f)) w = "overlap_m must be in [0, 10]";
    else if (!in(c->search_radius_m, 1e-3f, 100.0f)) w = "search_radius_m must be in (0, 100]";
    else if (!in(c->occupied_thresh, 1e-6f, 1.0f)) w = "occupied_thresh must be in (0, 1]";
    else if (!in(c->free_thresh, 0.0f, 1.0f) || !(c->free_thresh < c->occupied_thresh))
        w = "free_thresh must be in [0, occupied_thresh)";
    else if (c->reserved != 0) w = "reserved must be 0";
    else if (c->flags & ~(POLYC_FLAG_EXACT_POINTS | POLYC_FLAG_NO_GRAZING | POLYC_FLAG_GRID_TRACE))
        w = "unknown flags";
    if (why)
        *why = w;
    return w ? POLYC_ERR_CONFIG : POLYC_OK;
}

/* ---- extent ---- */

static int pose_ok(double x, double y, double th)
{
    return isfinite(x) && isfinite(y) && isfinite(th) && fabs(x) < 1e7 && fabs(y) < 1e7;
}

/* Extent rule: the poses and every reflected endpoint. Free-space beams do
 * not widen it (they are clipped to it). ox, oy shift the frame. */
static void extent_add(const polyc_scan *s, double ox, double oy, double *box, int *have)
{
    double px = s->pose_x_m - ox, py = s->pose_y_m - oy;
#define EXT(X, Y) do { \
        if (!*have) { box[0] = box[2] = (X); box[1] = box[3] = (Y); *have = 1; } \
        else { box[0] = fmin(box[0], X); box[1] = fmin(box[1], Y); \
               box[2] = fmax(box[2], X); box[3] = fmax(box[3], Y); } } while (0)
    EXT(px, py);
    if (!s->range_m)
        return;
    for (uint32_t i = 0; i < s->beam_count; i++) {
        float r = s->range_m[i];
        if (!(r >= s->min_range_m && r < s->max_range_m))
            continue;
        double a = s->pose_theta_rad + (double)s->start_angle_rad + (double)i * (double)s->angle_step_rad;
        EXT(px + (double)r * cos(a), py + (double)r * sin(a));
    }
#undef EXT
}

void polyc_scan_extent(const polyc_config *config, const polyc_scan *scan, polyc_box *box)
{
    (void)config;
    if (!scan || !box || !pose_ok(scan->pose_x_m, scan->pose_y_m, scan->pose_theta_rad))
        return;
    double b[4] = {box->min_x_m, box->min_y_m, box->max_x_m, box->max_y_m};
    int have = b[0] <= b[2] && b[1] <= b[3];
    extent_add(scan, 0.0, 0.0, b, &have);
    box->min_x_m = b[0];
    box->min_y_m = b[1];
    box->max_x_m = b[2];
    box->max_y_m = b[3];
}

polyc_status polyc_limits_for_scans(const polyc_config *config, const polyc_scan *scans,
                                    uint32_t scan_count, polyc_limits *out)
{
    if (!config || !out || (!scans && scan_count))
        return POLYC_ERR_NULL;
    if (polyc_config_check(config, NULL) != POLYC_OK)
        return POLYC_ERR_CONFIG;
    memset(out, 0, sizeof *out);
    uint64_t beams = 0;
    polyc_box box = {1.0, 1.0, 0.0, 0.0}; /* empty */
    for (uint32_t i = 0; i < scan_count; i++) {
        beams += scans[i].beam_count;
        polyc_scan_extent(config, &scans[i], &box);
    }
    if (beams > 0xffffffffu)
        return POLYC_ERR_LIMIT;
    out->max_scans = scan_count;
    out->max_beams = (uint32_t)beams;
    if (box.min_x_m <= box.max_x_m) {
        double cell = (double)config->cell_m, ext = (double)config->max_extent_m;
        double pad = 4.0 * cell;
        double w = box.max_x_m - box.min_x_m + pad, h = box.max_y_m - box.min_y_m + pad;
        if (w > ext || h > ext)
            return POLYC_ERR_EXTENT;
        double tx = ceil(ceil(w / cell + 1.0) / POLYC__TILE_SIDE);
        double ty = ceil(ceil(h / cell + 1.0) / POLYC__TILE_SIDE);
        double cells = tx * ty * POLYC__TILE_CELLS;
        if (cells > 4294967295.0)
            return POLYC_ERR_EXTENT;
        out->max_grid_cells = (uint32_t)cells;
    }
    /* Contours and weighted points follow the map (its walls), not the
     * log's length (tunables.h) */
    uint64_t typical = beams / POLYC__LIMITS_BEAM_SHARE;
    if ((uint64_t)out->max_grid_cells / POLYC__LIMITS_CELLS_PER_WALL < typical)
        typical = (uint64_t)out->max_grid_cells / POLYC__LIMITS_CELLS_PER_WALL;
    typical += POLYC__LIMITS_SPARE;
    uint64_t points = typical * POLYC__LIMITS_POINTS_NUM / POLYC__LIMITS_POINTS_DEN;
    if (typical < beams) {
        out->max_vertices = (uint32_t)typical + POLYC__VERTEX_SPARE;
        if (!(config->flags & POLYC_FLAG_EXACT_POINTS) && points < beams)
            out->max_points = (uint32_t)points;
    }
    return POLYC_OK;
}

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
    polyc__flat_reserve(&a, polyc__max_vertices(limits)); /* the result */
    polyc__prior_reserve(&a, limits);
    polyc__optimizer_reserve(&a, config, limits);
    size_t head = polyc__bytes(1, sizeof(polyc_ctx)) + 16; /* + alignment of the block */
    size_t n = polyc__add(head, a.peak);
    return n == SIZE_MAX ? 0 : n;
}

/* While the progress callback runs, the context is lent to the optimiser:
 * its magic reads POLYC__MAGIC_BUSY and every entry point refuses it with
 * POLYC_ERR_BUSY (guarded_progress). */
#define POLYC__MAGIC_BUSY 0x62757379u /* "busy" */

static polyc_status check_ctx(const polyc_ctx *ctx)
{
    if (!ctx)
        return POLYC_ERR_NULL;
    if (ctx->magic == POLYC__MAGIC_BUSY)
        return POLYC_ERR_BUSY;
    return ctx->magic == POLYC__MAGIC ? POLYC_OK : POLYC_ERR_NULL;
}

polyc_status polyc_init(void *block, size_t size, const polyc_config *config,
                        const polyc_limits *limits, polyc_ctx **out)
{
    if (!out)
        return POLYC_ERR_NULL;
    *out = NULL;
    if (!block || !config || !limits)
        return POLYC_ERR_NULL;
    if (polyc_config_check(config, NULL) != POLYC_OK)
        return POLYC_ERR_CONFIG;
    size_t need = polyc_memory_size(config, limits);
    if (need == 0)
        return POLYC_ERR_CONFIG;
    if (size < need)
        return POLYC_ERR_NOMEM;
    uintptr_t p = ((uintptr_t)block + 15u) & ~(uintptr_t)15u;
    size_t skew = (size_t)(p - (uintptr_t)block);
    polyc_ctx *ctx = (polyc_ctx *)p;
    memset(ctx, 0, sizeof *ctx);
    ctx->magic = POLYC__MAGIC;
    ctx->cfg = *config;
    ctx->lim = *limits;
    size_t head = polyc__bytes(1, sizeof(polyc_ctx));
    ctx->arena.base = (unsigned char *)p + head;
    ctx->arena.size = size - skew - head;
    if (!scans_carve(&ctx->arena, limits, &ctx->scans, &ctx->ranges))
        return POLYC_ERR_NOMEM;
    ctx->scans_mark = ctx->base_mark = ctx->arena.used;
    ctx->frame_dir.cos = 1.0;
    ctx->stats.memory_size_bytes = size;
    ctx->err.scan = -1;
    *out = ctx;
    return POLYC_OK;
}

polyc_status polyc_reset(polyc_ctx *ctx)
{
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK)
        return cst;
    ctx->arena.used = ctx->scans_mark = ctx->base_mark;
    ctx->scan_count = ctx->range_count = 0;
    ctx->have_frame = ctx->ext.have = 0;
    ctx->from_grid = 0;
    ctx->frame_x = ctx->frame_y = 0.0;
    ctx->frame_dir.cos = 1.0;
    ctx->frame_dir.sin = 0.0;
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
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK || !s)
        return cst != POLYC_OK ? cst : POLYC_ERR_NULL;
    ctx->err.msg = NULL;
    if (ctx->from_grid)
        return polyc__fail(ctx, POLYC_ERR_STATE,
                           "the context holds a grid: scans need a context of their own");
    if (s->beam_count && !s->range_m)
        return polyc__fail(ctx, POLYC_ERR_NULL, "scan.range_m is NULL with beams");
    const char *bad = NULL;
    if (!pose_ok(s->pose_x_m, s->pose_y_m, s->pose_theta_rad))
        bad = "scan pose is not finite or beyond 1e7 m";
    else if (!isfinite(s->start_angle_rad) || !isfinite(s->angle_step_rad) ||
             fabsf(s->angle_step_rad) > 6.2832f || fabsf(s->start_angle_rad) > 100.0f)
        bad = "scan angles are not finite or out of range";
    else if (s->beam_count > 1 && s->angle_step_rad == 0.0f)
        bad = "scan angle_step_rad is 0";
    else if (!(s->min_range_m >= 0.0f) || !(s->max_range_m > s->min_range_m))
        bad = "scan range interval is empty or negative";
    else if (s->reserved != 0)
        bad = "scan.reserved must be 0";
    if (bad) {
        ctx->err.scan = (int32_t)ctx->scan_count;
        return polyc__fail(ctx, POLYC_ERR_SCAN, bad);
    }
    if (ctx->scan_count >= ctx->lim.max_scans ||
        s->beam_count > ctx->lim.max_beams - ctx->range_count)
        return polyc__fail(ctx, POLYC_ERR_LIMIT, "more scans or beams than the limits allow");
    if (!ctx->have_frame) {
        ctx->frame_x = s->pose_x_m;
        ctx->frame_y = s->pose_y_m;
        ctx->have_frame = 1;
    }
    polyc__scan *d = &ctx->scans[ctx->scan_count];
    d->x_m = (float)(s->pose_x_m - ctx->frame_x);
    d->y_m = (float)(s->pose_y_m - ctx->frame_y);
    d->theta_rad = (float)remainder(s->pose_theta_rad, 6.283185307179586);
    d->start_rad = s->start_angle_rad;
    d->step_rad = s->angle_step_rad;
    d->min_m = s->min_range_m;
    d->max_m = s->max_range_m;
    d->first = ctx->range_count;
    d->count = s->beam_count;
    for (uint32_t i = 0; i < s->beam_count; i++) {
        float r = s->range_m[i];
        if (!(r >= 0.0f)) /* NaN or negative: kept, skipped by every pass */
            ctx->stats.beams_skipped++;
        else if (r >= s->min_range_m && r < s->max_range_m)
            ctx->stats.hits++;
        ctx->ranges[ctx->range_count + i] = r;
    }
    double box[4] = {ctx->ext.min_x, ctx->ext.min_y, ctx->ext.max_x, ctx->ext.max_y};
    extent_add(s, ctx->frame_x, ctx->frame_y, box, &ctx->ext.have);
    ctx->ext.min_x = box[0];
    ctx->ext.min_y = box[1];
    ctx->ext.max_x = box[2];
    ctx->ext.max_y = box[3];
    ctx->range_count += s->beam_count;
    ctx->scan_count++;
    ctx->stats.scans = ctx->scan_count;
    ctx->stats.beams += s->beam_count;
    ctx->stage = POLYC__STAGE_SCANS;
    return POLYC_OK;
}

polyc_status polyc_add_grid(polyc_ctx *ctx, const polyc_occupancy_grid *grid)
{
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK || !grid)
        return cst != POLYC_OK ? cst : POLYC_ERR_NULL;
    ctx->err.msg = NULL;
    return polyc__occ_add(ctx, grid);
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

/* The result form, in the frame of the input poses (an occupancy grid's
 * map frame: its origin pose applied). */
static void export_result(polyc_ctx *ctx)
{
    polyc__flat_from_store(&ctx->flat, &ctx->store);
    for (uint32_t i = 0; ctx->from_grid && i < ctx->flat.points; i++) {
        double x = (double)ctx->flat.xy[2 * i], y = (double)ctx->flat.xy[2 * i + 1];
        ctx->flat.xy[2 * i] = (float)(ctx->frame_x + ctx->frame_dir.cos * x - ctx->frame_dir.sin * y);
        ctx->flat.xy[2 * i + 1] = (float)(ctx->frame_y + ctx->frame_dir.sin * x + ctx->frame_dir.cos * y);
    }
    for (uint32_t i = 0; !ctx->from_grid && i < ctx->flat.points; i++) {
        ctx->flat.xy[2 * i] = (float)((double)ctx->flat.xy[2 * i] + ctx->frame_x);
        ctx->flat.xy[2 * i + 1] = (float)((double)ctx->flat.xy[2 * i + 1] + ctx->frame_y);
    }
    ctx->stats.polylines = ctx->flat.count;
    ctx->stats.vertices = ctx->flat.points;
}

static polyc_status stage_trace(polyc_ctx *ctx)
{
    polyc_status st = one_scan_chains(ctx) ? polyc__chains_build(ctx) : polyc__trace_build(ctx);
    if (st != POLYC_OK)
        return st;
    int32_t vcap = ctx->store.v_cap;
    if (!polyc__flat_init(&ctx->arena, &ctx->flat, (uint32_t)polyc__line_cap(vcap), (uint32_t)vcap))
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the result polylines");
    export_result(ctx);
    ctx->stats.initial_polylines = ctx->stats.polylines;
    ctx->stats.initial_vertices = ctx->stats.vertices;
    ctx->trace_mark = ctx->arena.used;
    return POLYC_OK;
}

static polyc_status need_stage(polyc_ctx *ctx, polyc__stage want)
{
    polyc_status st = POLYC_OK;
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

polyc_status polyc_build_grid(polyc_ctx *ctx)
{
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK)
        return cst;
    ctx->err.msg = NULL;
    /* explicit call: rebuild (an occupancy grid's is its input: the results
     * after it are dropped) */
    ctx->stage = ctx->from_grid ? POLYC__STAGE_CONTOUR : POLYC__STAGE_SCANS;
    return need_stage(ctx, POLYC__STAGE_GRID);
}

polyc_status polyc_extract_contour(polyc_ctx *ctx)
{
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK)
        return cst;
    ctx->err.msg = NULL;
    if (ctx->stage >= POLYC__STAGE_CONTOUR)
        ctx->stage = ctx->from_grid ? POLYC__STAGE_CONTOUR : POLYC__STAGE_GRID;
    return need_stage(ctx, POLYC__STAGE_CONTOUR);
}

polyc_status polyc_trace(polyc_ctx *ctx)
{
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK)
        return cst;
    ctx->err.msg = NULL;
    if (ctx->stage >= POLYC__STAGE_TRACE)
        ctx->stage = POLYC__STAGE_CONTOUR;
    return need_stage(ctx, POLYC__STAGE_TRACE);
}

/* The caller's callback, with the context marked busy while it runs: a
 * call back into the library on it is refused (POLYC_ERR_BUSY) instead of
 * changing the model under the optimiser. */
typedef struct guarded {
    polyc_ctx *ctx;
    polyc_progress_fn progress;
    void *user;
} guarded;

static int guarded_progress(void *user, const polyc_iteration *it)
{
    guarded *g = (guarded *)user;
    g->ctx->magic = POLYC__MAGIC_BUSY;
    int stop = g->progress(g->user, it);
    g->ctx->magic = POLYC__MAGIC;
    return stop;
}

polyc_status polyc_optimize(polyc_ctx *ctx, polyc_progress_fn progress, void *user)
{
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK)
        return cst;
    ctx->err.msg = NULL;
    polyc_status st = need_stage(ctx, POLYC__STAGE_TRACE);
    if (st != POLYC_OK)
        return st;
    ctx->arena.used = ctx->trace_mark;
    guarded g = {ctx, progress, user};
    st = polyc__optimize(ctx, progress ? guarded_progress : NULL, &g);
    note_memory(ctx);
    ctx->arena.used = ctx->trace_mark;
    if (ctx->opt_result_valid) {
        /* the best map found (after a failure mid-search too: the store
         * and the published result never disagree) */
        export_result(ctx);
        ctx->stage = POLYC__STAGE_OPTIMIZED;
    }
    return st;
}

polyc_status polyc_build(polyc_ctx *ctx, polyc_progress_fn progress, void *user)
{
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK)
        return cst;
    ctx->err.msg = NULL;
    polyc_status st = need_stage(ctx, POLYC__STAGE_TRACE);
    if (st != POLYC_OK || ctx->cfg.max_iterations == 0)
        return st;
    return polyc_optimize(ctx, progress, user);
}

polyc_status polyc_score(polyc_ctx *ctx, double *bic, double *err)
{
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK)
        return cst;
    ctx->err.msg = NULL;
    if (ctx->stage < POLYC__STAGE_TRACE)
        return polyc__fail(ctx, POLYC_ERR_STATE, "no polylines yet: run polyc_trace first");
    ctx->arena.used = ctx->trace_mark;
    polyc_status st = polyc__score(ctx, bic, err);
    note_memory(ctx);
    ctx->arena.used = ctx->trace_mark;
    return st;
}

/* ---- results ---- */

uint32_t polyc_polyline_count(const polyc_ctx *ctx)
{
    if (check_ctx(ctx) != POLYC_OK || ctx->stage < POLYC__STAGE_TRACE)
        return 0;
    return ctx->flat.count;
}

polyc_status polyc_get_polyline(const polyc_ctx *ctx, uint32_t index, polyc_polyline *out)
{
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK || !out)
        return cst != POLYC_OK ? cst : POLYC_ERR_NULL;
    if (ctx->stage < POLYC__STAGE_TRACE)
        return POLYC_ERR_STATE;
    if (index >= ctx->flat.count)
        return POLYC_ERR_RANGE;
    uint32_t a = ctx->flat.start[index];
    out->xy_m = ctx->flat.xy + 2 * a;
    out->point_count = ctx->flat.start[index + 1] - a;
    out->closed = ctx->flat.closed[index];
    return POLYC_OK;
}

polyc_status polyc_copy_polyline(const polyc_ctx *ctx, uint32_t index, float *xy_m,
                                 uint32_t capacity, uint32_t *count, uint32_t *closed)
{
    polyc_polyline pl;
    polyc_status st = polyc_get_polyline(ctx, index, &pl);
    if (st != POLYC_OK)
        return st;
    if (count)
        *count = pl.point_count;
    if (closed)
        *closed = pl.closed;
    if (xy_m) {
        if (capacity < pl.point_count)
            return POLYC_ERR_NOMEM;
        memcpy(xy_m, pl.xy_m, (size_t)pl.point_count * 2 * sizeof(float));
    }
    return POLYC_OK;
}

polyc_status polyc_get_stats(const polyc_ctx *ctx, polyc_stats *out)
{
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK || !out)
        return cst != POLYC_OK ? cst : POLYC_ERR_NULL;
    *out = ctx->stats;
    return POLYC_OK;
}

polyc_status polyc_grid_info(const polyc_ctx *ctx, double *origin_x_m, double *origin_y_m,
                             float *cell_m, uint32_t *width, uint32_t *height)
{
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK)
        return cst;
    if (ctx->stage < POLYC__STAGE_GRID)
        return POLYC_ERR_STATE;
    if (origin_x_m) *origin_x_m = ctx->grid.origin_x_m;
    if (origin_y_m) *origin_y_m = ctx->grid.origin_y_m;
    if (cell_m) *cell_m = ctx->grid.cell_m;
    if (width) *width = (uint32_t)ctx->grid.width;
    if (height) *height = (uint32_t)ctx->grid.height;
    return POLYC_OK;
}

polyc_status polyc_grid_cell(const polyc_ctx *ctx, uint32_t ix, uint32_t iy, uint32_t *hits,
                             uint32_t *misses, uint32_t *contour)
{
    polyc_status cst = check_ctx(ctx);
    if (cst != POLYC_OK)
        return cst;
    if (ctx->stage < POLYC__STAGE_GRID)
        return POLYC_ERR_STATE;
    if (ix >= (uint32_t)ctx->grid.width || iy >= (uint32_t)ctx->grid.height)
        return POLYC_ERR_RANGE;
    const polyc__tile *t = polyc__grid_tile(&ctx->grid, (int32_t)ix, (int32_t)iy);
    int idx = polyc__cell_index((int32_t)ix, (int32_t)iy);
    if (hits) *hits = t ? t->hits[idx] : 0;
    if (misses) *misses = t ? t->misses[idx] : 0;
    if (contour)
        *contour = t && ctx->stage >= POLYC__STAGE_CONTOUR ? (t->contour[iy & 31] >> (ix & 31)) & 1u : 0;
    return POLYC_OK;
}

const char *polyc_last_error(const polyc_ctx *ctx)
{
    polyc_status cst = check_ctx(ctx);
    if (cst == POLYC_ERR_BUSY)
        return "called from inside the progress callback";
    if (cst != POLYC_OK)
        return "invalid context";
    return ctx->err.msg ? ctx->err.msg : "";
}
