/* embedded_online.c - an online map (polyc_online_*) of the room of
 * embedded_room.h, built scan by scan inside a static 128 KiB block, as on
 * a Cortex-M4: the robot drives a path of eight poses through the room;
 * each scan is added and the map updated (polyc_online_update with the
 * default work budget), and the map is finished after the last.
 *
 * Choices that make it fit (also in README.md, "Footprint"):
 *   area           8 m square around the first pose, the room's middle
 *                  (every endpoint stays the 1 m inside it that
 *                  polyc_online_add_scan requires): 3 x 3 tiles of 0.1 m cells
 *   range cap      4.5 m    (scan max_range_m and config free_range_m)
 *   counters       8 bit    (library built with -DPOLYC_COUNTER_BITS=8)
 *   vertices       96       (limits.max_vertices)
 *   points         400      (limits.max_points: cells with endpoints; the
 *                            eight scans hit 380: the walls lie on cell
 *                            boundaries, and the noise spreads their
 *                            endpoints over two rows of cells)
 * polyc_online_memory_size() is then 128,240 bytes <= sizeof block; the
 * whole map is updated in it, from the first scan to the finish.
 *
 * Host:   prints the map in polyc's TXT format (tests/embedded_test.sh).
 * Target: built with -DEMBEDDED_ONLINE_TARGET, main() only runs the scans
 *         and returns the status; no stdio is linked.
 */
#include <stdint.h>

#ifndef EMBEDDED_ONLINE_TARGET
#define EMBEDDED_ROOM_HOST /* embedded_room.h's printing */
#endif
#include "embedded_room.h"
#include "polyc.h"

#ifndef EMBEDDED_ONLINE_TARGET
#include <stdio.h>
#endif

#define AREA_M 8.0
#define MAX_VERTICES 96u
#define MAX_POINTS 400u
#define BLOCK_BYTES (128u * 1024u)

static uint8_t block[BLOCK_BYTES]; /* the library's only memory */
static float ranges[BEAMS];

/* The path: x, y, heading (rad). The first pose is the area's centre. */
static const float path[][3] = {
    {2.5f, 2.0f, 3.1416f}, {1.5f, 2.2f, -2.3562f}, {0.8f, 1.2f, -0.7854f}, {1.8f, 0.7f, 0.0f},
    {3.0f, 0.8f, 0.0f},    {4.2f, 1.2f, 1.5708f},  {4.4f, 2.1f, 2.3562f},  {2.8f, 3.2f, 3.1416f},
};
#define POSES (sizeof path / sizeof path[0])

/* Adds the scans one by one, each followed by an update, then finishes;
 * *out gets the context (valid while `block` lives). */
static polyc_status run(polyc_ctx **out, size_t *need)
{
    polyc_config cfg;
    polyc_online_limits lim = {0};
    polyc_scan scan;
    polyc_status st;

    polyc_config_default(&cfg);
    cfg.cell_m = CELL_M;
    cfg.free_range_m = RANGE_CAP_M;
    lim.area_m = AREA_M;
    lim.max_grid_cells = 9u * 1024u; /* the 8 m square's 3 x 3 tiles */
    lim.max_scan_beams = BEAMS;
    lim.max_vertices = MAX_VERTICES;
    lim.max_points = MAX_POINTS;
    *need = polyc_online_memory_size(&cfg, &lim);
    if (*need == 0 || *need > sizeof block)
        return POLYC_ERR_NOMEM;
    st = polyc_online_init(block, sizeof block, &cfg, &lim, out);
    EMBEDDED_MARK("init", 0);
    if (st != POLYC_OK)
        return st;
    uint32_t seed = 12345u;
    for (unsigned i = 0; i < POSES; i++) {
        make_scan(&scan, ranges, path[i][0], path[i][1], path[i][2], &seed);
        EMBEDDED_MARK("scan", i); /* the simulated laser, not the library */
        st = polyc_online_add_scan(*out, &scan, 0, NULL);
        EMBEDDED_MARK("add", i);
        if (st != POLYC_OK)
            return st;
        st = polyc_online_update(*out, POLYC_ONLINE_WORK_DEFAULT, NULL);
        EMBEDDED_MARK("update", i);
        if (st != POLYC_OK)
            return st;
    }
    st = polyc_online_finish(*out, NULL, NULL, NULL);
    EMBEDDED_MARK("finish", 0);
    return st;
}

#ifdef EMBEDDED_ONLINE_TARGET

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
    printf("scans %u, version %lu\n", (unsigned)s.scans, (unsigned long)polyc_online_version(ctx));
    printf("polylines %u vertices %u iterations %u\n", (unsigned)s.polylines, (unsigned)s.vertices,
           (unsigned)s.iterations);
    return print_polylines(ctx);
}

#endif
