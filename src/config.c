/* config.c - the entry points that need no context: version, status
 * strings, struct sizes, the default configuration and its check, and the
 * limits for a set of scans (their extent: boundary.c). Takes: the
 * caller's config and scans. Gives: what polyc_memory_size and polyc_init
 * are then called with. */
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
        {"polyc_online_limits", sizeof(polyc_online_limits)},
        {"polyc_online_report", sizeof(polyc_online_report)},
        {"polyc_change", sizeof(polyc_change)},   {"polyc_circle", sizeof(polyc_circle)},
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
    else if (!in(c->max_extent_m, 0.01f, 1e4f)) /* float's step within 1e4 m: < 1 mm */
        w = "max_extent_m must be in [0.01, 10000]";
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
    else if (c->flags & ~(POLYC_FLAG_EXACT_POINTS | POLYC_FLAG_NO_GRAZING | POLYC_FLAG_GRID_TRACE |
                          POLYC_FLAG_NO_ARCS))
        w = "unknown flags";
    if (why)
        *why = w;
    return w ? POLYC_ERR_CONFIG : POLYC_OK;
}

/* ---- limits ---- */

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
    float span_x, span_y;
    if (polyc__box_spans(&box, &span_x, &span_y)) {
        /* in float once the spans are known (the grid lays itself out in
         * float too, with 4 cells less of padding than allowed here) */
        float cell = config->cell_m, ext = config->max_extent_m;
        float pad = 4.0f * cell;
        float w = span_x + pad, h = span_y + pad;
        if (w > ext || h > ext)
            return POLYC_ERR_EXTENT;
        float tx = ceilf(ceilf(w / cell + 1.0f) / POLYC__TILE_SIDE);
        float ty = ceilf(ceilf(h / cell + 1.0f) / POLYC__TILE_SIDE);
        float cells = tx * ty * POLYC__TILE_CELLS;
        if (cells > 4294967040.0f) /* (the largest float below 2^32) */
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
