/* pipeline.h - the library's whole pipeline on a set of scans, as the
 * benchmark and the sweep run it: polyc_limits_for_scans, one malloc'ed
 * block of polyc_memory_size, init, add, grid, contour, trace, optimise;
 * or the same scans through an online context (the sweep's --online).
 *
 * Memory: pipeline_open mallocs the block, pipeline_close frees it; the
 * scans must outlive the runs. int returns: 0, or -1 with failed_at (the
 * call that failed) and status set.
 *
 * SPDX-License-Identifier: MIT
 */
#ifndef POLYC_PIPELINE_H
#define POLYC_PIPELINE_H

#include <stddef.h>
#include <stdint.h>

#include "polyc.h"

/* Indices of the stage times pipeline_run fills (milliseconds). */
enum pipeline_stage {
    PIPELINE_ADD, PIPELINE_GRID, PIPELINE_CONTOUR, PIPELINE_TRACE, PIPELINE_OPTIMIZE,
    PIPELINE_STAGES
};

typedef struct pipeline {
    polyc_config config;
    polyc_limits limits;
    void *block;
    size_t block_size;
    polyc_ctx *ctx;
    const char *failed_at;     /* the call that failed, NULL if none */
    polyc_status status;
    /* pipeline_run_online: the limits of the last attempt, and how many
       times they were doubled */
    polyc_online_limits online_limits;
    unsigned online_doublings;
} pipeline;

/* Limits for these scans and a block for them, under `config` (copied). */
int pipeline_open(pipeline *p, const polyc_config *config, const polyc_scan *scans, uint32_t n);
void pipeline_close(pipeline *p);
/* One run from polyc_init to the optimised map on the block (a single scan
 * skips the contour, as polyc_build does); times[PIPELINE_STAGES] gets each
 * stage. A map that needs more vertices or points than the usual limits
 * runs again with the worst-case limits, as the polyc tool does. */
int pipeline_run(pipeline *p, const polyc_scan *scans, uint32_t n, double *times);
/* The library on an occupancy grid, as `polyc map.yaml` runs it: limits
 * (polyc_limits_for_grid), one malloc'ed block, init, polyc_add_grid,
 * polyc_build. *ms gets the time of it all. Call pipeline_close after,
 * whatever the result. */
int pipeline_run_grid(pipeline *p, const polyc_config *config, const polyc_occupancy_grid *grid,
                      double *ms);
/* The scans through an online context, as a robot would feed them: limits
 * (polyc_online_limits_for_area) for the square centred on the first pose
 * that holds every pose and endpoint (polyc_scan_extent) with
 * PIPELINE_ONLINE_MARGIN_M to spare and scans of the most beams, one
 * malloc'ed block, init, each scan added (not kept) and an update of
 * POLYC_ONLINE_WORK_DEFAULT after it, then polyc_online_finish. On
 * POLYC_ERR_NOMEM the grid cells, vertices and data cells are doubled and
 * the run starts again (up to PIPELINE_ONLINE_DOUBLINGS times). *ms gets the
 * last attempt's time from polyc_online_init to the finished map. Call
 * pipeline_close after, whatever the result. */
#define PIPELINE_ONLINE_MARGIN_M 2.0
#define PIPELINE_ONLINE_DOUBLINGS 4u
int pipeline_run_online(pipeline *p, const polyc_config *config, const polyc_scan *scans,
                        uint32_t n, double *ms);
/* The same with the square's side `wider_m` longer: its grid's cells lie
 * wider_m / 2 further out (the online grid is laid out from the corner of
 * the square), so a wider_m that is no multiple of two cells aligns them
 * another way. */
int pipeline_run_online_wider(pipeline *p, const polyc_config *config, const polyc_scan *scans,
                              uint32_t n, double wider_m, double *ms);
/* The current map as an array of polylines (malloc'ed; NULL on failure). */
polyc_polyline *pipeline_lines(pipeline *p, uint32_t *count);

/* A monotonic clock in milliseconds, and a qsort comparison of doubles
 * (the bench's and the sweep's medians). */
double pipeline_now_ms(void);
int pipeline_compare_double(const void *a, const void *b);

#endif /* POLYC_PIPELINE_H */
