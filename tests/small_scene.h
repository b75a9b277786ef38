/* small_scene.h - a small known-good scene for the robustness tests
 * (test_api_errors.c, test_exhaustion.c): a 3 m x 2 m room seen from three
 * poses by a 91-beam laser, simulated by tools/eval/scansim. Building it must
 * give a map; the tests run it after every error to show that the context
 * still works. */
#ifndef SMALL_SCENE_H
#define SMALL_SCENE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "polyc.h"
#include "scansim.h"

/* Simulates the room; 0 or -1. Free with scansim_scene_free. */
static inline int small_scene(scansim_scene *sc)
{
    scansim_scene_init(sc, "small", 11u);
    sc->laser.beam_count = 91u;
    sc->laser.angle_step_rad = (float)(3.14159265358979 / 90.0);
    if (scansim_add_box(sc, 0.0, 0.0, 3.0, 2.0) != 0 || scansim_add_pose(sc, 0.8, 0.7, 0.3) != 0 ||
        scansim_add_pose(sc, 2.0, 1.2, 2.5) != 0 || scansim_add_pose(sc, 1.5, 0.5, -1.8) != 0)
        return -1;
    scansim_transform(sc, 0.2, 10.0, -3.0);
    return scansim_run(sc);
}

/* The configuration the tests use with it: coarse and quick. */
static inline void small_config(polyc_config *c)
{
    polyc_config_default(c);
    c->cell_m = 0.05f;
    c->max_iterations = 8;
}

/* Every point of every polyline is finite and near the data; polyline
 * count and vertex total agree with the stats. 0 or -1. */
static inline int map_is_valid(const polyc_ctx *ctx, double cx, double cy, double radius)
{
    polyc_stats st;
    uint32_t n = polyc_polyline_count(ctx), points = 0;
    if (polyc_get_stats(ctx, &st) != POLYC_OK)
        return -1;
    for (uint32_t i = 0; i < n; i++) {
        polyc_polyline pl;
        if (polyc_get_polyline(ctx, i, &pl) != POLYC_OK || pl.point_count == 0 || pl.closed > 1)
            return -1;
        for (uint32_t j = 0; j < pl.point_count; j++) {
            double x = (double)pl.xy_m[2 * j], y = (double)pl.xy_m[2 * j + 1];
            if (!isfinite(x) || !isfinite(y) || fabs(x - cx) > radius || fabs(y - cy) > radius)
                return -1;
        }
        points += pl.point_count;
    }
    return n == st.polylines && points == st.vertices ? 0 : -1;
}

/* Resets ctx and builds the scene on it: OK and a valid, non-empty map. */
static inline polyc_status small_run(polyc_ctx *ctx, const scansim_scene *sc)
{
    polyc_status st = polyc_reset(ctx);
    for (uint32_t i = 0; st == POLYC_OK && i < sc->scan_count; i++)
        st = polyc_add_scan(ctx, &sc->scans[i]);
    if (st == POLYC_OK)
        st = polyc_build(ctx, NULL, NULL);
    if (st == POLYC_OK && (polyc_polyline_count(ctx) == 0 || map_is_valid(ctx, 11.5, -2.0, 4.0)))
        st = POLYC_ERR_STATE;   /* no map, or a broken one */
    return st;
}

#endif
