/* mapout.h - write a polyline map as JSON, SVG or plain text.
 * Formats: docs/formats.md. The writers only read what they are given. */
#ifndef POLYC_MAPOUT_H
#define POLYC_MAPOUT_H

#include <stdint.h>
#include <stdio.h>

#include "polyc.h"

/* Wall-clock time of each stage in milliseconds (negative: not run). */
typedef struct mapout_times {
    double parse_ms, add_ms, grid_ms, contour_ms, trace_ms, optimize_ms;
} mapout_times;

typedef struct mapout_map {
    const polyc_polyline *lines;   /* line_count polylines (metres, pose frame) */
    uint32_t line_count;
    const polyc_circle *circles;   /* per polyline: radius_m > 0, written as that
                                      circle (JSON "circles", TXT `circle`, SVG
                                      <circle>); NULL: none */
    const float *const *bulges;    /* per polyline: its bulges (one a point, the
                                      segment from it), NULL: straight (JSON
                                      "bulges", TXT `bulges`, SVG arcs); NULL:
                                      none */
    const polyc_stats *stats;      /* JSON "stats"; NULL: written as {} */
    const mapout_times *times;     /* JSON time_*_ms; NULL: left out */
    /* SVG only */
    const polyc_scan *scans;       /* --points: draw these scans' endpoints; NULL: off */
    uint32_t scan_count;
    const polyc_ctx *grid;         /* --grid: draw this context's grid; NULL: off */
    float contour_threshold;       /* a grid cell is drawn if hits/(hits+misses) > this */
    const polyc_scan *path;        /* the robot's path: these scans' poses joined, the
                                      last one drawn as the robot; NULL: off */
    uint32_t path_count;
    const polyc_box *view_m;       /* the part of the plane shown (metres); NULL: what
                                      is drawn */
    int vertices;                  /* --vertices: a dot on every vertex */
    int color_lines;               /* --color-lines: a colour per polyline (else one) */
    const char *title;             /* the title: this path's file name; NULL: "polyc map" */
    double cell_m;                 /* shown in the title if > 0 */
    double total_ms;               /* the run's time, shown if > 0 (element id "time") */
} mapout_map;

/* Each returns 0, or -1 if the stream reported an error. */
int mapout_json(FILE *f, const mapout_map *map);
int mapout_svg(FILE *f, const mapout_map *map);
int mapout_txt(FILE *f, const mapout_map *map);

#endif /* POLYC_MAPOUT_H */
