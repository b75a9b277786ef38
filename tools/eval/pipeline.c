/* pipeline.c - the library's whole pipeline on a set of scans (see
 * pipeline.h): takes scans and a configuration, gives the optimised map
 * and each stage's time.
 */
#include "pipeline.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "ctxblock.h"

double pipeline_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

int pipeline_compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static int step(pipeline *p, polyc_status st, const char *what)
{
    if (st == POLYC_OK)
        return 0;
    p->status = st;
    p->failed_at = what;
    return -1;
}

/* The block for p's config and limits (ctxblock.h), and with init a
 * context on it; 0 or -1 with the step that failed. */
static int make_block(pipeline *p, int init)
{
    polyc_status st = POLYC_OK;
    switch (ctxblock_make(&p->config, &p->limits, 0, &p->block, &p->block_size,
                          init ? &p->ctx : NULL, &st)) {
    case CTXBLOCK_OK:
        return 0;
    case CTXBLOCK_UNSIZED:
        return step(p, POLYC_ERR_CONFIG, "polyc_memory_size");
    case CTXBLOCK_INIT:
        return step(p, st, "polyc_init");
    default:
        return step(p, POLYC_ERR_NOMEM, "malloc of the block");
    }
}

int pipeline_open(pipeline *p, const polyc_config *config, const polyc_scan *scans, uint32_t n)
{
    memset(p, 0, sizeof *p);
    p->config = *config;
    if (step(p, polyc_limits_for_scans(&p->config, scans, n, &p->limits),
             "polyc_limits_for_scans"))
        return -1;
    return make_block(p, 0);
}

void pipeline_close(pipeline *p)
{
    free(p->block);
    p->block = NULL;
}

/* polyc_limits_for_scans sizes vertices and points for a usual map; as
 * the polyc tool does, a map that needs more runs again with the worst case. */
static int pipeline_grow(pipeline *p)
{
    if (p->status != POLYC_ERR_NOMEM || (!p->limits.max_vertices && !p->limits.max_points))
        return -1;
    p->limits.max_vertices = p->limits.max_points = 0;
    if (ctxblock_make(&p->config, &p->limits, 0, &p->block, &p->block_size, NULL, NULL) !=
        CTXBLOCK_OK)
        return -1;
    p->failed_at = NULL;
    p->status = POLYC_OK;
    return 0;
}

int pipeline_run(pipeline *p, const polyc_scan *scans, uint32_t n, double *times)
{
    double t = pipeline_now_ms(), t1;
    uint32_t i;
    if (step(p, polyc_init(p->block, p->block_size, &p->config, &p->limits, &p->ctx),
             "polyc_init"))
        return -1;
    for (i = 0; i < n; i++)
        if (step(p, polyc_add_scan(p->ctx, &scans[i]), "polyc_add_scan"))
            return -1;
    t1 = pipeline_now_ms(); times[PIPELINE_ADD] = t1 - t; t = t1;
    if (step(p, polyc_build_grid(p->ctx), "polyc_build_grid"))
        return -1;
    t1 = pipeline_now_ms(); times[PIPELINE_GRID] = t1 - t; t = t1;
    /* (a single scan's polylines come from its beam order: polyc_build
     * skips the contour, and so does this) */
    if (n > 1 && step(p, polyc_extract_contour(p->ctx), "polyc_extract_contour"))
        return -1;
    t1 = pipeline_now_ms(); times[PIPELINE_CONTOUR] = t1 - t; t = t1;
    if (step(p, polyc_trace(p->ctx), "polyc_trace"))
        return pipeline_grow(p) ? -1 : pipeline_run(p, scans, n, times);
    t1 = pipeline_now_ms(); times[PIPELINE_TRACE] = t1 - t; t = t1;
    if (p->config.max_iterations > 0 &&
        step(p, polyc_optimize(p->ctx, NULL, NULL), "polyc_optimize"))
        return pipeline_grow(p) ? -1 : pipeline_run(p, scans, n, times);
    times[PIPELINE_OPTIMIZE] = pipeline_now_ms() - t;
    return 0;
}

int pipeline_run_grid(pipeline *p, const polyc_config *config, const polyc_occupancy_grid *grid,
                      double *ms)
{
    double t = pipeline_now_ms();
    memset(p, 0, sizeof *p);
    p->config = *config;
    *ms = 0.0;
    if (step(p, polyc_limits_for_grid(&p->config, grid, &p->limits), "polyc_limits_for_grid"))
        return -1;
    if (make_block(p, 1) ||
        step(p, polyc_add_grid(p->ctx, grid), "polyc_add_grid") ||
        step(p, polyc_build(p->ctx, NULL, NULL), "polyc_build"))
        return -1;
    *ms = pipeline_now_ms() - t;
    return 0;
}

/* One attempt of pipeline_run_online on p->online_limits: 0, -1 with
 * failed_at, or -2 when the block's malloc failed (no use doubling). */
static int online_once(pipeline *p, const polyc_scan *scans, uint32_t n, double *ms)
{
    double t;
    uint32_t i;
    free(p->block);
    p->block = NULL;
    p->ctx = NULL;
    p->block_size = polyc_online_memory_size(&p->config, &p->online_limits);
    if (p->block_size == 0)
        return step(p, POLYC_ERR_CONFIG, "polyc_online_memory_size");
    if ((p->block = malloc(p->block_size)) == NULL)
        return step(p, POLYC_ERR_NOMEM, "malloc of the block") - 1;
    t = pipeline_now_ms();
    if (step(p, polyc_online_init(p->block, p->block_size, &p->config, &p->online_limits,
                                  &p->ctx),
             "polyc_online_init"))
        return -1;
    for (i = 0; i < n; i++)
        if (step(p, polyc_online_add_scan(p->ctx, &scans[i], 0, NULL), "polyc_online_add_scan") ||
            step(p, polyc_online_update(p->ctx, POLYC_ONLINE_WORK_DEFAULT, NULL),
                 "polyc_online_update"))
            return -1;
    if (step(p, polyc_online_finish(p->ctx, NULL, NULL, NULL), "polyc_online_finish"))
        return -1;
    *ms = pipeline_now_ms() - t;
    return 0;
}

/* 2 x, at most cap */
static uint32_t twice(uint32_t a, double cap)
{
    return (uint32_t)fmin(2.0 * (double)a, cap);
}

int pipeline_run_online(pipeline *p, const polyc_config *config, const polyc_scan *scans,
                        uint32_t n, double *ms)
{
    return pipeline_run_online_wider(p, config, scans, n, 0.0, ms);
}

int pipeline_run_online_wider(pipeline *p, const polyc_config *config, const polyc_scan *scans,
                              uint32_t n, double wider_m, double *ms)
{
    polyc_box box = {HUGE_VAL, HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    double x0, y0, reach, tiles;
    uint32_t i, beams = 0;
    int rc;
    memset(p, 0, sizeof *p);
    p->config = *config;
    *ms = 0.0;
    if (n == 0)
        return step(p, POLYC_ERR_STATE, "no scans");
    x0 = scans[0].pose_x_m;
    y0 = scans[0].pose_y_m;
    for (i = 0; i < n; i++) {
        polyc_scan_extent(&p->config, &scans[i], &box);
        if (scans[i].beam_count > beams)
            beams = scans[i].beam_count;
    }
    reach = fmax(fmax(x0 - box.min_x_m, box.max_x_m - x0),
                 fmax(y0 - box.min_y_m, box.max_y_m - y0));
    if (step(p, polyc_online_limits_for_area(&p->config, 2.0 * (reach + PIPELINE_ONLINE_MARGIN_M) + wider_m,
                                             beams, &p->online_limits),
             "polyc_online_limits_for_area"))
        return -1;
    /* the grid cells of the whole square at most (32 x 32-cell tiles) */
    tiles = ceil(p->online_limits.area_m / (double)p->config.cell_m / 32.0);
    while ((rc = online_once(p, scans, n, ms)) != 0) {
        if (rc == -2 || p->status != POLYC_ERR_NOMEM ||
            p->online_doublings == PIPELINE_ONLINE_DOUBLINGS)
            return -1;
        p->online_limits.max_grid_cells =
            twice(p->online_limits.max_grid_cells, fmin(tiles * tiles * 1024.0, 0x40000000));
        p->online_limits.max_vertices = twice(p->online_limits.max_vertices, 0x10000000);
        p->online_limits.max_points = twice(p->online_limits.max_points, 0x10000000);
        p->online_doublings++;
        p->failed_at = NULL;
        p->status = POLYC_OK;
    }
    return 0;
}

polyc_polyline *pipeline_lines(pipeline *p, uint32_t *count)
{
    uint32_t i, n = polyc_polyline_count(p->ctx);
    polyc_polyline *lines = calloc(n ? n : 1u, sizeof *lines);
    *count = 0;
    if (!lines)
        return NULL;
    for (i = 0; i < n; i++)
        if (step(p, polyc_get_polyline(p->ctx, i, &lines[i]), "polyc_get_polyline")) {
            free(lines);
            return NULL;
        }
    *count = n;
    return lines;
}
