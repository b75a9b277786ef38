/* footprint.c - what polyc_memory_size() charges for each part of a map, from
 * the public API alone: bytes per scan, per beam, per vertex and per 32 x 32
 * grid tile, hence per square metre of map at a given cell size.
 * `make footprint` runs it against the host library (16-bit grid counters)
 * and the embedded build (8-bit); the README's footprint table comes from it.
 * usage: footprint [cell_m]     (default 0.025, the paper's resolution) */
#include <stdio.h>
#include <stdlib.h>

#include "polyc.h"

#define TILE_CELLS 1024.0

static polyc_config cfg;

static double size(uint32_t scans, uint32_t beams, uint32_t tiles, uint32_t vertices)
{
    polyc_limits lim = {scans, beams, tiles * 1024u, vertices, 0};
    return (double)polyc_memory_size(&cfg, &lim);
}

int main(int argc, char **argv)
{
    polyc_config_default(&cfg);
    if (argc > 1)
        cfg.cell_m = (float)atof(argv[1]);
    if (polyc_config_check(&cfg, NULL) != POLYC_OK) {
        fprintf(stderr, "footprint: bad cell size\n");
        return 2;
    }
    /* a point in the middle of the useful range; beams < grid cells, so that
     * each beam (not each cell) bounds the data points */
    const uint32_t S = 1000, B = 100000, T = 1000, V = 10000, D = 1000;
    double base = size(S, B, T, V);
    double per_scan = (size(S + D, B, T, V) - base) / D;
    double per_beam = (size(S, B + D, T, V) - base) / D;
    double per_vertex = (size(S, B, T, V + D) - base) / D;
    double per_tile = (size(S, B, T + D, V) - base) / D;
    double fixed = base - S * per_scan - B * per_beam - V * per_vertex - T * per_tile;
    double tile_m = 32.0 * (double)cfg.cell_m;
    printf("cell %.3f m: memory_size = %.0f + %.1f/scan + %.1f/beam + %.1f/vertex + %.0f/tile\n",
           (double)cfg.cell_m, fixed, per_scan, per_beam, per_vertex, per_tile);
    printf("  a tile is %.2f m x %.2f m: %.0f bytes per square metre of grid bounding box\n",
           tile_m, tile_m, per_tile / (tile_m * tile_m));
    printf("  (%.1f bytes per cell; max_vertices 0 means max_beams + 1024, i.e. %.1f/beam)\n",
           per_tile / TILE_CELLS, per_beam + per_vertex);
    return 0;
}
