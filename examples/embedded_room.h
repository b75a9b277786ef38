/* embedded_room.h - the room of the embedded examples (embedded_scan.c,
 * embedded_online.c), computed, not read (no I/O on the target): a 5 m x
 * 4 m room with a 0.6 m x 0.5 m cabinet, seen by a laser with 180 beams
 * from -90 to +89 degrees in 1 degree steps, ranges capped at 4.5 m, +-1 cm
 * of noise. */
#ifndef EMBEDDED_ROOM_H
#define EMBEDDED_ROOM_H

#include <math.h>
#include <stdint.h>

#include "polyc.h"

#define BEAMS 180
#define CELL_M 0.10f
#define RANGE_CAP_M 4.5f

/* The end of each library call, for a harness that counts the
 * instructions between them (tools/target/target.h): nothing otherwise. */
#ifndef EMBEDDED_MARK
#define EMBEDDED_MARK(what, index) ((void)0)
#endif

/* The room: wall segments (x0, y0, x1, y1) in metres. */
static const float walls[][4] = {
    {0.0f, 0.0f, 5.0f, 0.0f}, {5.0f, 0.0f, 5.0f, 4.0f},
    {5.0f, 4.0f, 0.0f, 4.0f}, {0.0f, 4.0f, 0.0f, 0.0f},
    /* cabinet */
    {3.6f, 2.6f, 4.2f, 2.6f}, {4.2f, 2.6f, 4.2f, 3.1f},
    {4.2f, 3.1f, 3.6f, 3.1f}, {3.6f, 3.1f, 3.6f, 2.6f},
};

/* Distance along (dx, dy) from (px, py) to the nearest wall; RANGE_CAP_M if none. */
static float cast(float px, float py, float dx, float dy)
{
    float best = RANGE_CAP_M;
    for (unsigned i = 0; i < sizeof walls / sizeof walls[0]; i++) {
        float ax = walls[i][0], ay = walls[i][1];
        float ex = walls[i][2] - ax, ey = walls[i][3] - ay;
        float den = dx * ey - dy * ex;
        if (fabsf(den) < 1e-9f)
            continue;
        float t = ((ax - px) * ey - (ay - py) * ex) / den; /* along the beam */
        float u = ((ax - px) * dy - (ay - py) * dx) / den; /* along the wall */
        if (t > 0.0f && t < best && u >= 0.0f && u <= 1.0f)
            best = t;
    }
    return best;
}

/* Uniform noise in [-1, 1) from a fixed LCG: the same scan every run. */
static float noise(uint32_t *state)
{
    *state = *state * 1664525u + 1013904223u;
    return (float)(*state >> 8) / 8388608.0f - 1.0f;
}

/* The scan from pose (x, y, theta) into ranges[BEAMS], noise from *seed. */
static void make_scan(polyc_scan *scan, float *ranges, float x, float y, float theta,
                      uint32_t *seed)
{
    const float start = -1.5707963f, step = 0.017453292f; /* -90 deg, 1 deg */
    for (uint32_t i = 0; i < BEAMS; i++) {
        float a = theta + start + (float)i * step;
        ranges[i] = cast(x, y, cosf(a), sinf(a)) + 0.01f * noise(seed);
    }
    scan->pose_x_m = (double)x;
    scan->pose_y_m = (double)y;
    scan->pose_theta_rad = (double)theta;
    scan->start_angle_rad = start;
    scan->angle_step_rad = step;
    scan->min_range_m = 0.02f;
    scan->max_range_m = RANGE_CAP_M; /* a range >= the cap is free space only */
    scan->beam_count = BEAMS;
    scan->reserved = 0;
    scan->range_m = ranges;
}

#ifdef EMBEDDED_ROOM_HOST
#include <stdio.h>

/* A run's status, the block against what it needs and, when the run
 * failed, its message (host builds: the tests read these lines); 1 on
 * failure, else 0 with the context's stats in *s and its memory used
 * printed. */
static int print_run(polyc_status st, const polyc_ctx *ctx, size_t block_size, size_t need,
                     polyc_stats *s)
{
    printf("status %s\n", polyc_status_str(st));
    printf("block %u bytes, memory_size %lu bytes\n", (unsigned)block_size, (unsigned long)need);
    if (st != POLYC_OK) {
        printf("error %s\n", ctx ? polyc_last_error(ctx) : "");
        return 1;
    }
    polyc_get_stats(ctx, s);
    printf("memory_used %lu bytes\n", (unsigned long)s->memory_used_bytes);
    return 0;
}

/* The map in polyc's TXT form, a polyline a line (host builds: the tests
 * read it); 1 if a polyline could not be read, else 0. */
static int print_polylines(const polyc_ctx *ctx)
{
    for (uint32_t i = 0; i < polyc_polyline_count(ctx); i++) {
        polyc_polyline pl;
        if (polyc_get_polyline(ctx, i, &pl) != POLYC_OK)
            return 1;
        printf("%s %u", pl.closed ? "closed" : "open", (unsigned)pl.point_count);
        for (uint32_t k = 0; k < 2 * pl.point_count; k++)
            printf(" %.4f", (double)pl.xy_m[k]);
        printf("\n");
    }
    return 0;
}
#endif

#endif
