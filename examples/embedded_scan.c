/* embedded_scan.c - the whole pipeline (grid, contour, trace, optimiser) on
 * one 180-beam scan inside a static 128 KiB block, as on a Cortex-M4.
 *
 * The scan is computed here (no I/O on the target): the room of
 * embedded_room.h, a 5 m x 4 m room with a 0.6 m x 0.5 m cabinet, seen by a
 * laser at (1.2, 2.0) looking along +x, beams from -90 to +89 degrees in 1
 * degree steps, +-1 cm of noise.
 *
 * Choices that make it fit (also in README.md, "Footprint"):
 *   grid cell      0.10 m   (limits.max_grid_cells: 4 tiles = 64 x 64 cells)
 *   range cap      4.5 m    (scan max_range_m and config free_range_m)
 *   counters       8 bit    (library built with -DPOLYC_COUNTER_BITS=8)
 *   vertices       96       (limits.max_vertices; the trace gives ~40, the map ~10)
 * polyc_memory_size() is then about 80 KB <= sizeof block (the host build;
 * the spatial hash's buckets and entries follow the grid and the vertices).
 * With 16-bit counters it is 10 KB more, 91 KB: still within the block.
 *
 * Host:   prints the polylines in polyc's TXT format (tests/embedded_test.sh).
 * Target: built with -DEMBEDDED_SCAN_TARGET, main() only runs the pipeline
 *         and returns the status; no stdio is linked.
 */
#include <stdint.h>

#ifndef EMBEDDED_SCAN_TARGET
#define EMBEDDED_ROOM_HOST /* embedded_room.h's printing */
#endif
#include "embedded_room.h"
#include "polyc.h"

#ifndef EMBEDDED_SCAN_TARGET
#include <stdio.h>
#endif

#define MAX_VERTICES 96u
#define BLOCK_BYTES (128u * 1024u)

static uint8_t block[BLOCK_BYTES]; /* the library's only memory */
static float ranges[BEAMS];

#define POSE_X 1.2f
#define POSE_Y 2.0f

/* Runs the pipeline; *out gets the context (valid while `block` lives). */
static polyc_status run(polyc_ctx **out, size_t *need)
{
    polyc_config cfg;
    polyc_limits lim;
    polyc_scan scan;
    polyc_status st;

    uint32_t seed = 12345u;
    make_scan(&scan, ranges, POSE_X, POSE_Y, 0.0f, &seed);
    EMBEDDED_MARK("scan", 0); /* the simulated laser, not the library */
    polyc_config_default(&cfg);
    cfg.cell_m = CELL_M;
    cfg.free_range_m = RANGE_CAP_M;
    if ((st = polyc_limits_for_scans(&cfg, &scan, 1, &lim)) != POLYC_OK)
        return st;
    lim.max_vertices = MAX_VERTICES;
    *need = polyc_memory_size(&cfg, &lim);
    if (*need == 0 || *need > sizeof block)
        return POLYC_ERR_NOMEM;
    st = polyc_init(block, sizeof block, &cfg, &lim, out);
    EMBEDDED_MARK("init", 0);
    if (st != POLYC_OK)
        return st;
    st = polyc_add_scan(*out, &scan);
    EMBEDDED_MARK("add", 0);
    if (st != POLYC_OK)
        return st;
    st = polyc_build(*out, NULL, NULL);
    EMBEDDED_MARK("build", 0);
    return st;
}

#ifdef EMBEDDED_SCAN_TARGET

int main(void)
{
    polyc_ctx *ctx = NULL;
    size_t need = 0;
    return (int)run(&ctx, &need);
}

#else

int main(void)
{
    polyc_ctx *ctx = NULL;
    size_t need = 0;
    polyc_status st = run(&ctx, &need); /* before print_run reads ctx and need */
    polyc_stats s;
    if (print_run(st, ctx, sizeof block, need, &s))
        return 1;
    printf("grid %u x %u cells, %u tiles, %lu bytes\n", (unsigned)s.grid_width,
           (unsigned)s.grid_height, (unsigned)s.grid_tiles, (unsigned long)s.grid_bytes);
    printf("polylines %u vertices %u iterations %u (initial %u, %u)\n", (unsigned)s.polylines,
           (unsigned)s.vertices, (unsigned)s.iterations, (unsigned)s.initial_polylines,
           (unsigned)s.initial_vertices);
    return print_polylines(ctx);
}

#endif
