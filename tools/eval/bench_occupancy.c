/* bench_occupancy.c - the bench's occupancy-map section (bench.h).
 * Takes: the sim scenes (their log-odds grids, tools/eval/occmap), the
 * hit/miss grids of intel, fhw and aces, and a generated maze. Gives: a
 * row per grid and method (the library, the contour baseline of
 * tools/eval/gridtrace), and the maze's timed file-to-JSON run. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"
#include "gridimage.h"
#include "gridtrace.h"
#include "gtscore.h"
#include "gttopo.h"
#include "mapfile.h"
#include "occmap.h"
#include "readfile.h"

/* ---- occupancy maps ----------------------------------------------------- */

#define OCC_CELL_M 0.05        /* the maps' resolution: the mapper's and the logs' grids */
#define OCC_MIN 65             /* an occupied cell: value >= 100 x occupied_thresh */
#define MAZE_CELLS 2000        /* the speed row's map: 2,000 x 2,000 cells */
#define MAZE_ROOM 50           /* cells per maze room (2.5 m) */
#define MAZE_WALL 2            /* wall thickness, cells */

/* The scores of one map of an occupancy grid. */
typedef struct occ_score {
    uint32_t lines, vertices, ideal;
    double core_m, completeness;   /* sim scenes; < 0: none */
    double near;               /* share of occupied cells within one cell of the map */
    gttopo_score topo;         /* against the occupied cells' centres */
    double ms;                 /* grid to polylines */
} occ_score;

/* Share of the points within d_m (<=) of the map. */
static double share_near(const polyc_polyline *lines, uint32_t count, const double *xy,
                         uint64_t n, double d_m)
{
    gtscore_index map;
    uint64_t k, within = 0;
    gtscore_index_init(&map);
    if (gtscore_index_add_polylines(&map, lines, count) != 0 ||
        gtscore_index_build(&map, 0.1) != 0) {
        gtscore_index_free(&map);
        return (double)NAN;
    }
    for (k = 0; k < n; k++)
        within += gtscore_index_distance(&map, xy[2u * k], xy[2u * k + 1u], d_m) <= d_m;
    gtscore_index_free(&map);
    return n ? (double)within / (double)n : 0.0;
}

static int occ_scores(const polyc_polyline *lines, uint32_t count, const polyc_occupancy_grid *g,
                      const double *xy, uint64_t n, const gtscore_truth *truth, occ_score *s)
{
    uint32_t i;
    s->lines = count;
    s->vertices = 0;
    for (i = 0; i < count; i++)
        s->vertices += lines[i].point_count;
    s->ideal = truth ? truth->ideal : 0;
    s->core_m = s->completeness = -1.0;
    s->near = share_near(lines, count, xy, n, (double)g->resolution_m);
    if (gttopo_score_map(lines, count, xy, n, &s->topo) != 0)
        return -1;
    if (truth) {
        gtscore_map_score sc;
        if (gtscore_score_map(truth, lines, count, &sc) != 0 ||
            gtscore_core_precision(truth, lines, count, CORE_M, &s->core_m) != 0)
            return -1;
        s->completeness = sc.completeness;
    }
    return 0;
}

static void print_occ_header(void)
{
    printf("%-18s %-8s %11s %7s %7s | %-8s %6s %6s %6s %6s | %6s %6s | %6s | %7s %6s %6s | %8s\n",
           "scene", "grid", "cells", "occ", "gridms", "method", "lines", "verts", "ideal", "x",
           "core", "compl", "occ1", "dcov", "dcov%", "cross", "ms");
    printf("%-18s %-8s %11s %7s %7s | %-8s %6s %6s %6s %6s | %6s %6s | %6s | %7s %6s %6s | %8s\n",
           "", "", "", "", "ms", "", "", "", "", "", "mm", "", "", "m", "", "", "");
}

static void print_occ_row(const char *label, const char *source, const polyc_occupancy_grid *g,
                          uint64_t occupied, double grid_ms, const char *method,
                          const occ_score *s)
{
    char cells[32], ideal[16] = "-", ratio[16] = "-", core[16] = "-", compl[16] = "-";
    snprintf(cells, sizeof cells, "%ux%u", (unsigned)g->width, (unsigned)g->height);
    if (s->ideal) {
        snprintf(ideal, sizeof ideal, "%u", s->ideal);
        snprintf(ratio, sizeof ratio, "%.2f", (double)s->vertices / (double)s->ideal);
    }
    if (s->core_m >= 0.0)
        snprintf(core, sizeof core, "%.1f", 1e3 * s->core_m);
    if (s->completeness >= 0.0)
        snprintf(compl, sizeof compl, "%.4f", s->completeness);
    printf("%-18s %-8s %11s %7llu %7.1f | %-8s %6u %6u %6s %6s | %6s %6s | %6.4f | %7.2f %6.2f "
           "%6u | %8.1f\n",
           label, source, cells, (unsigned long long)occupied, grid_ms, method, s->lines, s->vertices,
           ideal, ratio, core, compl, s->near, s->topo.double_cover_m,
           s->topo.map_length_m > 0.0 ? 100.0 * s->topo.double_cover_m / s->topo.map_length_m
                                      : 0.0,
           s->topo.crossings, s->ms);
    fflush(stdout);
}

/* The library (default configuration, the options' overrides) and the
 * baseline on one grid, a row each. */
static int map_grid(const options *o, const char *label, const char *source,
                    const polyc_occupancy_grid *g, double grid_ms, const gtscore_truth *truth)
{
    double *xy = NULL;
    uint64_t n = 0;
    polyc_config config;
    pipeline p;
    polyc_polyline *lines = NULL;
    uint32_t count = 0;
    gridtrace_map base;
    occ_score s;
    int rc = 0;
    if (occmap_cell_points(g, OCC_MIN, &xy, &n) != 0) {
        printf("%-18s error: out of memory\n", label);
        return -1;
    }
    bench_config(o, &config);
    memset(&s, 0, sizeof s);
    if (pipeline_run_grid(&p, &config, g, &s.ms) != 0 || !(lines = pipeline_lines(&p, &count))) {
        printf("%-18s %-8s error in %s: %s (%s)\n", label, source,
               p.failed_at ? p.failed_at : "pipeline_lines", polyc_status_str(p.status),
               p.ctx ? polyc_last_error(p.ctx) : "");
        rc = -1;
    } else if (occ_scores(lines, count, g, xy, n, truth, &s) != 0) {
        printf("%-18s error: scoring ran out of memory\n", label);
        rc = -1;
    } else
        print_occ_row(label, source, g, n, grid_ms, "libpolyc", &s);
    free(lines);
    pipeline_close(&p);
    memset(&s, 0, sizeof s);
    double t = pipeline_now_ms();
    if (gridtrace_run(g, OCC_MIN, (double)g->resolution_m, &base) != 0) {
        printf("%-18s error: the baseline ran out of memory\n", label);
        rc = -1;
    } else {
        s.ms = pipeline_now_ms() - t;
        if (occ_scores(base.lines, base.line_count, g, xy, n, truth, &s) != 0) {
            printf("%-18s error: scoring ran out of memory\n", label);
            rc = -1;
        } else
            print_occ_row(label, source, g, n, grid_ms, "contours", &s);
    }
    gridtrace_free(&base);
    free(xy);
    return rc;
}

/* A simulated scene: the mapper's grid at 5 cm. */
static int occupancy_sim(const options *o, const scene *s)
{
    scanlog log;
    gtscore_truth truth;
    occmap_config c;
    occmap m;
    polyc_occupancy_grid g;
    char label[160], err[512] = "", source[32];
    double ms;
    int rc;
    snprintf(label, sizeof label, "%s/%s", s->kind, s->name);
    if (bench_read_log(s->log_path, &log, &ms) != 0) {
        printf("%-18s error: %s\n", label, log.error);
        scanlog_free(&log);
        return -1;
    }
    if (gtscore_truth_load(&truth, s->gt_path, err, sizeof err) != 0) {
        printf("%-18s error: %s\n", label, err);
        gtscore_truth_free(&truth);
        scanlog_free(&log);
        return -1;
    }
    occmap_config_default(&c);
    c.resolution_m = OCC_CELL_M;
    double t = pipeline_now_ms();
    if (occmap_build(&m, &c, log.scans, log.count) != 0) {
        printf("%-18s error: the occupancy mapper failed\n", label);
        rc = -1;
    } else {
        snprintf(source, sizeof source, "occmap");
        ms = pipeline_now_ms() - t;
        occmap_grid(&m, &g);
        rc = map_grid(o, label, source, &g, ms, &truth);
    }
    occmap_free(&m);
    gtscore_truth_free(&truth);
    scanlog_free(&log);
    return rc;
}

/* A real log: the library's hit/miss grid at 5 cm as `polyc grid --cell
 * 0.05` writes it (tools/gridimage.h, map_saver's PGM and YAML), read back
 * as `polyc map.yaml` reads it (tools/mapfile.h). */
static int occupancy_log(const options *o, const scene *s)
{
    scanlog log;
    pipeline p;
    polyc_config config;
    gridimage img;
    polyc_status st = POLYC_OK;
    char label[160], *pgm_text = NULL, *yaml_text = NULL;
    size_t pgm_len = 0, yaml_len = 0;
    mapfile_yaml y;
    mapfile_pgm pgm;
    int8_t *cells = NULL;
    double ms;
    int rc = -1;
    snprintf(label, sizeof label, "%s/%s", s->kind, s->name);
    memset(&img, 0, sizeof img);
    memset(&y, 0, sizeof y);
    memset(&pgm, 0, sizeof pgm);
    memset(&p, 0, sizeof p);
    if (bench_read_log(s->log_path, &log, &ms) != 0) {
        printf("%-18s error: %s\n", label, log.error);
        scanlog_free(&log);
        return -1;
    }
    polyc_config_default(&config);
    config.cell_m = (float)OCC_CELL_M;
    double t0 = pipeline_now_ms();
    if (pipeline_open(&p, &config, log.scans, log.count) != 0 ||
        (st = polyc_init(p.block, p.block_size, &p.config, &p.limits, &p.ctx)) != POLYC_OK) {
        printf("%-18s error in %s\n", label, p.failed_at ? p.failed_at : "polyc_init");
        goto done;
    }
    for (uint32_t i = 0; i < log.count && st == POLYC_OK; i++)
        st = polyc_add_scan(p.ctx, &log.scans[i]);
    if (st == POLYC_OK)
        st = polyc_build_grid(p.ctx);
    if (st != POLYC_OK || gridimage_make(p.ctx, &img, &st) != GRIDIMAGE_OK) {
        printf("%-18s error: the hit/miss grid: %s\n", label, polyc_status_str(st));
        goto done;
    }
    FILE *fp = open_memstream(&pgm_text, &pgm_len), *fy = open_memstream(&yaml_text, &yaml_len);
    int bad = !fp || !fy;
    if (fp) {
        bad |= mapfile_write_pgm(fp, img.pixels, img.width, img.height, (double)img.cell_m);
        bad |= fclose(fp) != 0;
    }
    if (fy) {
        bad |= mapfile_write_yaml(fy, "grid.pgm", (double)img.cell_m, img.origin_x_m,
                                  img.origin_y_m);
        bad |= fclose(fy) != 0;
    }
    if (bad || mapfile_yaml_parse(&y, yaml_text, yaml_len, "grid.yaml") != 0 ||
        mapfile_pgm_parse(&pgm, (const uint8_t *)pgm_text, pgm_len, "grid.pgm") != 0 ||
        !(cells = malloc((size_t)pgm.width * pgm.height))) {
        printf("%-18s error: writing or reading the map: %s%s\n", label, y.error, pgm.error);
        goto done;
    }
    mapfile_to_cells(&pgm, &y, cells);
    ms = pipeline_now_ms() - t0;
    polyc_occupancy_grid g;
    mapfile_grid(&y, pgm.width, pgm.height, cells, &g);
    pipeline_close(&p);
    rc = map_grid(o, label, "hit/miss", &g, ms, NULL);
done:
    free(cells);
    mapfile_pgm_free(&pgm);
    mapfile_yaml_free(&y);
    free(pgm_text);
    free(yaml_text);
    gridimage_free(&img);
    pipeline_close(&p);
    scanlog_free(&log);
    return rc;
}

/* A splitmix64 step: the maze's own deterministic generator. */
static uint64_t maze_next(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* A maze of (MAZE_CELLS / MAZE_ROOM)^2 rooms (depth-first, every room
 * reached once), walls MAZE_WALL cells thick, as map_saver's trinary
 * pixels (rows top first): occupied walls, free rooms. */
static uint8_t *maze_pixels(void)
{
    enum { R = MAZE_CELLS / MAZE_ROOM };
    uint8_t *px = malloc((size_t)MAZE_CELLS * MAZE_CELLS);
    unsigned char *seen = calloc((size_t)R * R, 1), *open_e = calloc((size_t)R * R, 1),
                  *open_n = calloc((size_t)R * R, 1);
    uint32_t *stack = malloc((size_t)R * R * sizeof *stack), top = 0;
    uint64_t rng = 28;
    if (!px || !seen || !open_e || !open_n || !stack) {
        free(px);
        px = NULL;
        goto done;
    }
    stack[top++] = 0;
    seen[0] = 1;
    while (top) {
        uint32_t c = stack[top - 1], cx = c % R, cy = c / R, next[4], k = 0;
        if (cx + 1 < R && !seen[c + 1]) next[k++] = c + 1;
        if (cx > 0 && !seen[c - 1]) next[k++] = c - 1;
        if (cy + 1 < R && !seen[c + R]) next[k++] = c + R;
        if (cy > 0 && !seen[c - R]) next[k++] = c - R;
        if (!k) {
            top--;
            continue;
        }
        uint32_t d = next[maze_next(&rng) % k];
        if (d == c + 1) open_e[c] = 1;
        else if (d == c - 1) open_e[d] = 1;
        else if (d == c + R) open_n[c] = 1;
        else open_n[d] = 1;
        seen[d] = 1;
        stack[top++] = d;
    }
    for (uint32_t y = 0; y < MAZE_CELLS; y++)
        for (uint32_t x = 0; x < MAZE_CELLS; x++) {
            uint32_t rx = x / MAZE_ROOM, ry = y / MAZE_ROOM, ux = x % MAZE_ROOM,
                     uy = y % MAZE_ROOM, c = ry * R + rx;
            /* each room owns its west and south walls; the maze's east and
             * north edges get their own */
            int wall = (ux < MAZE_WALL && (rx == 0 || !open_e[c - 1])) ||
                       (uy < MAZE_WALL && (ry == 0 || !open_n[c - R])) ||
                       x >= MAZE_CELLS - MAZE_WALL || y >= MAZE_CELLS - MAZE_WALL ||
                       (ux < MAZE_WALL && uy < MAZE_WALL);
            px[(size_t)(MAZE_CELLS - 1u - y) * MAZE_CELLS + x] =
                wall ? MAPFILE_PIXEL_OCCUPIED : MAPFILE_PIXEL_FREE;
        }
done:
    free(seen);
    free(open_e);
    free(open_n);
    free(stack);
    return px;
}

/* The speed row: the maze written as PGM + YAML to a temporary folder, then
 * timed from reading the files to the JSON (to /dev/null), as `polyc
 * map.yaml` runs. */
static int occupancy_speed(const options *o)
{
    char dir[] = "/tmp/polyc-bench-XXXXXX", yaml_path[64], pgm_path[64], *text = NULL;
    uint8_t *px = maze_pixels();
    size_t len = 0;
    mapfile_yaml y;
    mapfile_pgm pgm;
    int8_t *cells = NULL;
    char *image = NULL;
    pipeline p;
    polyc_polyline *lines = NULL;
    uint32_t count = 0;
    polyc_config config;
    double t[6], lib_ms = 0.0;
    int rc = -1;
    memset(&y, 0, sizeof y);
    memset(&pgm, 0, sizeof pgm);
    memset(&p, 0, sizeof p);
    if (!px || !mkdtemp(dir)) {
        printf("%-18s error: %s\n", "maze", px ? strerror(errno) : "out of memory");
        free(px);
        return -1;
    }
    snprintf(yaml_path, sizeof yaml_path, "%s/maze.yaml", dir);
    snprintf(pgm_path, sizeof pgm_path, "%s/maze.pgm", dir);
    FILE *fp = fopen(pgm_path, "wb"), *fy = fopen(yaml_path, "w");
    int bad = !fp || !fy;
    if (fp) {
        bad |= mapfile_write_pgm(fp, px, MAZE_CELLS, MAZE_CELLS, OCC_CELL_M);
        bad |= fclose(fp) != 0;
    }
    if (fy) {
        bad |= mapfile_write_yaml(fy, "maze.pgm", OCC_CELL_M, -50.0, -50.0);
        bad |= fclose(fy) != 0;
    }
    free(px);
    if (bad) {
        printf("%-18s error: writing %s failed\n", "maze", dir);
        goto done;
    }
    t[0] = pipeline_now_ms();
    if (readfile(yaml_path, MAPFILE_MAX_YAML_BYTES, &text, &len) != 0 ||
        mapfile_yaml_parse(&y, text, len, yaml_path) != 0)
        goto failed;
    free(text);
    text = NULL;
    if (!(image = mapfile_image_path(yaml_path, y.image)) || readfile(image, MAPFILE_MAX_PGM_BYTES, &text, &len) != 0 ||
        mapfile_pgm_parse(&pgm, (const uint8_t *)text, len, image) != 0)
        goto failed;
    free(text);
    text = NULL;
    t[1] = pipeline_now_ms();
    if (!(cells = malloc((size_t)pgm.width * pgm.height)))
        goto failed;
    mapfile_to_cells(&pgm, &y, cells);
    polyc_occupancy_grid g;
    mapfile_grid(&y, pgm.width, pgm.height, cells, &g);
    t[2] = pipeline_now_ms();
    bench_config(o, &config);
    if (pipeline_run_grid(&p, &config, &g, &lib_ms) != 0 || !(lines = pipeline_lines(&p, &count))) {
        printf("%-18s error in %s: %s (%s)\n", "maze", p.failed_at ? p.failed_at : "pipeline_lines",
               polyc_status_str(p.status), p.ctx ? polyc_last_error(p.ctx) : "");
        goto done;
    }
    t[3] = pipeline_now_ms();
    double out_ms = bench_write_output(&p, lines, count);
    t[4] = pipeline_now_ms();
    uint32_t verts = 0;
    for (uint32_t i = 0; i < count; i++)
        verts += lines[i].point_count;
    uint64_t occupied = 0;
    for (size_t k = 0; k < (size_t)g.width * g.height; k++)
        occupied += cells[k] >= OCC_MIN;
    printf("%-18s %-8s %5ux%-5u %7llu %7s | read %.1f, cells %.1f, library %.1f, output %.1f ms: "
           "total %.1f ms (target < 1000); %u lines, %u vertices\n",
           "maze", "files", (unsigned)g.width, (unsigned)g.height, (unsigned long long)occupied,
           "-", t[1] - t[0], t[2] - t[1], t[3] - t[2], out_ms, t[4] - t[0], count, verts);
    fflush(stdout);
    rc = 0;
    goto done;
failed:
    printf("%-18s error: reading %s: %s%s\n", "maze", yaml_path, y.error, pgm.error);
done:
    free(lines);
    pipeline_close(&p);
    free(cells);
    free(image);
    free(text);
    mapfile_pgm_free(&pgm);
    mapfile_yaml_free(&y);
    remove(pgm_path);
    remove(yaml_path);
    rmdir(dir);
    return rc;
}

/* The section: sim scenes (but the circles, whose 720-gon walls have no
 * meaningful ideal), the hit/miss grids of intel, fhw and aces, the speed
 * row. */
int bench_occupancy_section(const options *o, const scene *list, size_t count)
{
    static const char *const logs[] = {"intel", "fhw", "aces"};
    size_t i, k;
    int failed = 0;
    printf("\noccupancy maps at %.0f cm: the library (polyc_add_grid, polyc_build) and the "
           "baseline (contours:\nfindContours + approxPolyDP at one cell, tools/eval/gridtrace.c) "
           "on one grid; sim: the\nlog-odds mapper's grid (tools/eval/occmap.c), real logs: the "
           "hit/miss grid as `polyc grid`\nwrites it\n", 100.0 * OCC_CELL_M);
    print_occ_header();
    for (i = 0; i < count; i++)
        if (strcmp(list[i].kind, "sim") == 0 && strcmp(list[i].name, "circles") != 0)
            failed |= occupancy_sim(o, &list[i]) != 0;
    for (k = 0; k < sizeof logs / sizeof logs[0]; k++)
        for (i = 0; i < count; i++)
            if (strcmp(list[i].kind, "carmen") == 0 && strcmp(list[i].name, logs[k]) == 0)
                failed |= occupancy_log(o, &list[i]) != 0;
    if (!o->only || strstr(o->only, "maze"))
        failed |= occupancy_speed(o) != 0;
    return failed ? -1 : 0;
}
