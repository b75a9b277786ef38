/* sweep.c - the library's maps on simulated scenes of every kind and many
 * seeds, scored against each scene's own ground truth.
 *
 *   sweep [--seeds A-B] [--kinds a,b,...] [--save DIR] [--svg DIR] [--occupancy | --online]
 *         [--map-seed N] [--batch-seeds N] [--online-wider M]
 *
 * Takes nothing from disk: every scene is simulated (tools/eval/scansim.h), its
 * ground truth written to memory and read back by tools/eval/gtscore.h, its scans
 * mapped by the whole pipeline (tools/eval/pipeline.h: polyc_config_default,
 * polyc_limits_for_scans, one malloc'ed block). Gives one row per scene,
 * then per kind and over all the median and the worst of every figure, and
 * whether each scene meets the targets. --occupancy maps each scene's
 * occupancy grid (tools/eval/occmap.h) through polyc_add_grid instead.
 * --online maps each scene twice, in batch and scan by scan through an
 * online context (pipeline_run_online), scores both alike and gives the
 * online map's row with the batch map's core precision, vertices and time
 * beside it.
 * Exit codes: 0 every scene ran (met its targets or not), 1 some scene
 * failed to run, 2 usage error.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gtband.h"
#include "gtround.h"
#include "gtscore.h"
#include "gttopo.h"
#include "occmap.h"
#include "pipeline.h"
#include "polyc.h"
#include "scansim.h"

#define EXIT_FAILED 1
#define EXIT_USAGE 2
#define MAX_KINDS 16
/* the targets: precision within 25 % or 1.5 mm of the ideal fit, 98 % of
 * the seen walls mapped, at most 1.5 times the ideal vertices */
#define TARGET_FIT_FACTOR 1.25
#define TARGET_FIT_MARGIN_M 0.0015
#define TARGET_COMPLETENESS 0.98
#define TARGET_RATIO 1.5
/* and, in a scene with round things (arcs or circles in its truth), at most
 * 1.25 times the ideal parameters (2 a vertex, 1 an arc, 3 a circle) */
#define TARGET_PARAM_RATIO 1.25
/* and the topology's: double cover at most 25 cm, no crossing, no run of
 * map over 20 cm without a scan endpoint within 5 cm */
#define TARGET_DCOV_M 0.25
/* and the bands': band15 at most 1 % of the map's length */
#define TARGET_BAND 0.01
#define CORE_M 0.5                 /* core precision: map samples this near a true wall */
/* --occupancy: the scenes through the mapper at 5 cm (tools/eval/occmap.h)
 * and the library's polyc_add_grid; its targets: core precision at most
 * 12 mm, 97 % of the seen walls, 1.5 x ideal vertices, no crossing */
#define OCC_CELL_M 0.05
#define OCC_MIN 65                 /* an occupied cell: value >= 100 x occupied_thresh */
#define OCC_TARGET_CORE_M 0.012
#define OCC_TARGET_COMPLETENESS 0.97
/* --online: the target, core precision within 10 % of the batch map's */
#define ONLINE_CORE_RATIO 1.10
#define ONLINE_WORST_LISTED 5      /* scenes listed by their core ratio */

static const char usage_text[] =
    "usage: sweep [options]\n"
    "Simulates every scene kind for a range of seeds, maps each with libpolyc's\n"
    "whole pipeline and scores the map against the scene's ground truth;\n"
    "`make sweep` builds it with -O3 and runs it (SWEEP_ARGS='...').\n"
    "options:\n"
    "  --seeds A-B      seeds A to B (or one seed A); default 1-6\n"
    "  --kinds a,b,...  scene kinds; default hall,shelves,flat,curved,thinwalls,\n"
    "                   office,angled,square,drift,farhall (any of scansim's\n"
    "                   built-in names; drift and farhall: poses that drift;\n"
    "                   pillars, arcwalls and roundmix: true arcs and circles)\n"
    "  --save DIR       write DIR/KIND-sSEED.log and .gt.txt (for build/polyc)\n"
    "  --svg DIR        write DIR/KIND-sSEED.svg: true walls (grey), the robot's\n"
    "                   path (blue), people (pink), the map (black, dots on vertices;\n"
    "                   red where a segment strays over 5 cm from every true wall;\n"
    "                   with --occupancy the occupied cells, green)\n"
    "  --occupancy      map each scene's occupancy grid instead of its scans: the\n"
    "                   log-odds mapper at 5 cm (tools/eval/occmap.h), then\n"
    "                   polyc_add_grid and polyc_build; ms is that library run,\n"
    "                   dcov and uns20 are measured against the occupied cells'\n"
    "                   centres, and the targets are P core > 12 mm, C compl <\n"
    "                   0.97, V verts > 1.5 x ideal, T any crossing\n"
    "  --online         map each scene twice, in batch and scan by scan through an\n"
    "                   online context (polyc_online_limits_for_area for the square\n"
    "                   round the first pose that holds every pose and endpoint\n"
    "                   with 2 m to spare, limits doubled on POLYC_ERR_NOMEM; an\n"
    "                   update of POLYC_ONLINE_WORK_DEFAULT after each scan, then\n"
    "                   polyc_online_finish). The row, its targets and its summary\n"
    "                   are the online map's (ms: polyc_online_init to the\n"
    "                   finished map; --svg draws the online map), with six more\n"
    "                   columns: bcore (the batch map's core, mm), core/b (online\n"
    "                   core / batch core), bverts (the batch map's vertices),\n"
    "                   verts/b, bms (the batch ms), ms/b. The summary adds per\n"
    "                   kind and over all on how many scenes core/b <= 1.10 and\n"
    "                   the worst core/b and verts/b, and lists the five scenes\n"
    "                   of the worst core/b. Not with --occupancy\n"
    "  --map-seed N     the optimiser's seed (polyc_config.seed) of every map,\n"
    "                   batch and online; default the library's. Two runs that\n"
    "                   differ only in it show how far a figure moves with the\n"
    "                   search's random path alone\n"
    "  --batch-seeds N  with --online, N batch maps per scene (1 to 16; default\n"
    "                   1), with the optimiser's seeds S .. S + N - 1 (S: the\n"
    "                   --map-seed or the library's); the batch columns are\n"
    "                   the first map's, bhi the highest core precision of the\n"
    "                   N (mm), core/hi the online core against it, and the\n"
    "                   summary adds on how many scenes core/hi <= 1.10\n"
    "  --online-wider M with --online, the online square M metres wider (0 to\n"
    "                   100; default 0): its grid lies M / 2 further out, so\n"
    "                   an M that is no multiple of two cells aligns the cells\n"
    "                   another way; the online updates draw no random numbers,\n"
    "                   and their maps move with the cells' alignment instead\n"
    "  -h, --help       this text\n";

/* (in two: a C99 compiler need not take a string over 4095 characters) */
static const char usage_columns[] =
    "Columns: scans, beams (all scans), ms (the pipeline from polyc_init to the\n"
    "optimised map), verts (map vertices), ideal, ratio (verts / ideal), params\n"
    "(the map's parameters: 2 a vertex, 1 an arc, 3 a circle), iparam (the ideal\n"
    "map's with arcs and circles, scansim_ideal_params), p/i (params / iparam),\n"
    "arcs and circ (the map's arcs and circles), rms\n"
    "(precision RMS, mm), core (precision over the map samples within 0.5 m of a\n"
    "true wall, mm), fit (the ideal map's fit to the data, mm), floor (the\n"
    "line-fit floor, mm), compl (completeness), gcompl (--occupancy: the grid's\n"
    "own completeness, seen samples within 5 cm of an occupied cell's centre),\n"
    "dcov (double cover, m), cross (crossings), uns20 (runs over 20 cm without\n"
    "data within 5 cm), band% (band15: map length drawn as a band of parallel\n"
    "lines seen from the same side, in runs over 20 cm, % of the map's length;\n"
    "tools/eval/gtband.h), end20, end10 (share of scan endpoints within 20 / 10 cm\n"
    "of the map; band%, end20 and end10 need the scans: '-' with --occupancy),\n"
    "then the targets missed: P core precision > max(1.25 x\n"
    "fit, fit + 1.5 mm), C completeness < 0.98, V vertices > 1.5 x ideal, A\n"
    "(scenes with arcs or circles in their truth) params > 1.25 x iparam, T\n"
    "double cover > 0.25 m, a crossing or a run over 20 cm, B band15 > 1 % of\n"
    "the map's length ('ok': none).\n"
    "Summary rows give per kind and over all the median and the worst (highest;\n"
    "completeness: lowest) of each figure.\n"
    "Exit: 0 every scene ran; 1 a scene failed (its row says why); 2 usage error.\n";

static const char *const default_kinds[] = {"hall",   "shelves", "flat",   "curved",
                                            "thinwalls", "office", "angled", "square",
                                            "drift",  "farhall"};

typedef struct options {
    uint64_t seed_first, seed_last;
    const char *kinds[MAX_KINDS];
    unsigned kind_count;
    const char *save_dir;      /* NULL: none */
    const char *svg_dir;       /* NULL: none */
    int occupancy;             /* --occupancy */
    int online;                /* --online */
    unsigned batch_seeds;      /* --batch-seeds: batch maps per scene (--online) */
    double online_wider_m;     /* --online-wider: the online square this much wider */
    int map_seed_set;          /* --map-seed given */
    uint64_t map_seed;         /* --map-seed: polyc_config.seed of every map */
} options;

/* ---- the figures ----------------------------------------------------------- */

/* One entry per column: to add a figure, add it here, to `figures` and to
 * score_scene. The figures from FIG_BCORE on are --online's, set by
 * sweep_scene from the batch map's row and printed only with --online. */
enum figure { FIG_SCANS, FIG_BEAMS, FIG_MS, FIG_VERTS, FIG_IDEAL, FIG_RATIO, FIG_PARAMS,
              FIG_IPARAMS, FIG_PRATIO, FIG_ARCS, FIG_CIRCLES, FIG_RMS,
              FIG_CORE, FIG_FIT, FIG_FLOOR, FIG_COMPL, FIG_GCOMPL, FIG_DCOV, FIG_CROSS,
              FIG_UNS20, FIG_BAND, FIG_END20, FIG_END10,
              FIG_BCORE, FIG_CORE_RATIO, FIG_BVERTS, FIG_VERTS_RATIO, FIG_BMS, FIG_MS_RATIO,
              FIG_BCORE_HI, FIG_CORE_HI_RATIO, FIG_COUNT };

typedef struct figure_info {
    const char *name;
    int width, decimals;
    double scale;              /* printed value = figure * scale */
    int low_is_worse;          /* the worst is the lowest (else the highest) */
} figure_info;

static const figure_info figures[FIG_COUNT] = {
    {"scans", 6, 0, 1.0, 0},   {"beams", 8, 0, 1.0, 0},   {"ms", 7, 1, 1.0, 0},
    {"verts", 6, 0, 1.0, 0},   {"ideal", 6, 0, 1.0, 0},   {"ratio", 6, 2, 1.0, 0},
    {"params", 6, 0, 1.0, 0},  {"iparam", 6, 0, 1.0, 0},  {"p/i", 5, 2, 1.0, 0},
    {"arcs", 4, 0, 1.0, 0},    {"circ", 4, 0, 1.0, 0},
    {"rms", 6, 1, 1e3, 0},     {"core", 6, 1, 1e3, 0},    {"fit", 6, 1, 1e3, 0},
    {"floor", 6, 1, 1e3, 0},   {"compl", 7, 4, 1.0, 1},   {"gcompl", 7, 4, 1.0, 1},
    {"dcov", 6, 2, 1.0, 0},
    {"cross", 5, 0, 1.0, 0},   {"uns20", 5, 0, 1.0, 0},   {"band%", 6, 2, 100.0, 0},
    {"end20", 6, 4, 1.0, 1},   {"end10", 6, 4, 1.0, 1},
    {"bcore", 6, 1, 1e3, 0},   {"core/b", 6, 3, 1.0, 0},  {"bverts", 6, 0, 1.0, 0},
    {"verts/b", 7, 3, 1.0, 0}, {"bms", 7, 1, 1.0, 0},     {"ms/b", 6, 2, 1.0, 0},
    {"bhi", 6, 1, 1e3, 0},     {"core/hi", 7, 3, 1.0, 0},
};

/* The columns printed: all with --online, else up to FIG_BCORE. */
static uint32_t shown_figures(const options *o)
{
    return o->online ? (uint32_t)FIG_COUNT : (uint32_t)FIG_BCORE;
}

/* Bits of the targets a scene misses. */
enum { MISS_PRECISION = 1, MISS_COMPLETENESS = 2, MISS_VERTICES = 4, MISS_TOPOLOGY = 8,
       MISS_BAND = 16, MISS_PARAMS = 32 };

typedef struct row {
    char kind[32];
    uint64_t seed;
    double fig[FIG_COUNT];     /* NAN: not available */
    unsigned missed;           /* MISS_* bits */
    int ok;                    /* the scene ran and was scored */
    unsigned doublings;        /* --online: the limits doubled this many times */
} row;

/* ---- small helpers --------------------------------------------------------- */


/* ---- one scene -------------------------------------------------------------- */

/* A map as the scorers take it (gtround.h): the library's polylines in
 * their arc form, their circles, and the curves as fine polylines. */
typedef gtround_map map_view;

static void map_free(map_view *m)
{
    gtround_free(m);
}

/* The pipeline's map into m (freed first); 0, or -1 (the pipeline's
 * failed_at says where). */
static int map_get(pipeline *p, map_view *m)
{
    polyc_status st;
    map_free(m);
    if ((st = gtround_from_ctx(p->ctx, m)) != POLYC_OK) {
        p->status = st;
        p->failed_at = "polyc_find_curves";
        return -1;
    }
    return 0;
}

/* The scene's ground truth as gtscore reads it: written by scansim to
 * memory and read back, exactly what KIND-sSEED.gt.txt would hold. */
static int truth_of(const scansim_scene *sc, gtscore_truth *truth, char *err, size_t err_size)
{
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    int rc = -1;
    memset(truth, 0, sizeof *truth);
    if (!f) {
        snprintf(err, err_size, "open_memstream: %s", strerror(errno));
        return -1;
    }
    if (scansim_write_gt(sc, f) != 0 || fclose(f) != 0) {
        snprintf(err, err_size, "writing the ground truth failed");
        free(text);
        return -1;
    }
    f = fmemopen(text, size, "r");
    if (f) {
        rc = gtscore_truth_read(truth, f, sc->name, err, err_size);
        fclose(f);
    } else
        snprintf(err, err_size, "fmemopen: %s", strerror(errno));
    free(text);
    return rc;
}

/* --occupancy: the completeness of the grid itself, the share of the seen
 * samples within GTSCORE_COMPLETE_M of an occupied cell's centre: a wall
 * the grid does not hold, no map of the grid can hold (a bound on the map's
 * completeness). */
static double grid_completeness(const gtscore_truth *truth, const polyc_occupancy_grid *g)
{
    double c = cos(g->origin_yaw_rad), sn = sin(g->origin_yaw_rad), r = (double)g->resolution_m;
    double lim2 = GTSCORE_COMPLETE_M * GTSCORE_COMPLETE_M;
    uint32_t k, covered = 0;
    for (k = 0; k < truth->seen_count; k++) {
        double dx = truth->seen_xy_m[2 * k] - g->origin_x_m, dy = truth->seen_xy_m[2 * k + 1] - g->origin_y_m;
        double gx = (c * dx + sn * dy) / r, gy = (-sn * dx + c * dy) / r; /* in cells */
        long i0 = (long)floor(gx), j0 = (long)floor(gy), i, j;
        int hit = 0;
        for (j = j0 - 2; j <= j0 + 2 && !hit; j++)
            for (i = i0 - 2; i <= i0 + 2 && !hit; i++) {
                if (i < 0 || j < 0 || i >= (long)g->width || j >= (long)g->height ||
                    g->cells[(size_t)j * g->width + (size_t)i] < OCC_MIN)
                    continue;
                double ex = ((double)i + 0.5 - gx) * r, ey = ((double)j + 0.5 - gy) * r;
                hit = ex * ex + ey * ey <= lim2;
            }
        covered += (uint32_t)hit;
    }
    return truth->seen_count ? (double)covered / (double)truth->seen_count : 1.0;
}

/* Every figure of one map and the targets it misses: the one place that
 * scores a scene. The topology's data: the occupied cells' centres of
 * `grid` when it is given (--occupancy, whose targets then apply), else the
 * scans' endpoints. */
static int score_scene(const scansim_scene *sc, const gtscore_truth *truth, const map_view *m,
                       double pipeline_ms, const polyc_occupancy_grid *grid, row *r)
{
    const polyc_polyline *lines = m->scored;
    uint32_t count = m->count, verts, params, arcs, circles;
    gtscore_map_score score;
    gttopo_score topo;
    gtband_score band = {0};
    double fit_m, floor_m, core_m, *hits = NULL, *from = NULL;
    uint64_t hit_count = 0;
    uint32_t i;
    for (i = 0; i < FIG_COUNT; i++)
        r->fig[i] = (double)NAN;
    if (gtscore_score_map(truth, lines, count, &score) != 0 ||
        gtscore_core_precision(truth, lines, count, CORE_M, &core_m) != 0 ||
        gtscore_ideal_fit(truth, sc->scans, sc->scan_count, &fit_m) != 0 ||
        gtscore_line_floor(truth, sc->scans, sc->scan_count, &floor_m) != 0)
        return -1;
    if (grid ? occmap_cell_points(grid, OCC_MIN, &hits, &hit_count) != 0
             : gtband_scan_points(sc->scans, sc->scan_count, &hits, &from, &hit_count) != 0)
        return -1;
    /* the bands need the sensor of each point: scans only */
    int topo_rc = gttopo_score_map(lines, count, hits, hit_count, &topo) != 0 ||
                  (!grid && gtband_score_map(lines, count, hits, from, hit_count, &band) != 0);
    free(hits);
    free(from);
    if (topo_rc != 0)
        return -1;
    r->fig[FIG_CORE] = core_m;
    r->fig[FIG_DCOV] = topo.double_cover_m;
    r->fig[FIG_CROSS] = topo.crossings;
    r->fig[FIG_UNS20] = topo.unsupported_20;
    r->fig[FIG_SCANS] = sc->scan_count;
    r->fig[FIG_BEAMS] = (double)sc->scan_count * (double)sc->laser.beam_count;
    r->fig[FIG_MS] = pipeline_ms;
    /* the vertices and parameters of the map as the library gives it (a
     * circle is three numbers, not its scoring polygon) */
    gtround_params(m, &verts, &params, &arcs, &circles);
    score.vertices = verts;
    score.params = params;
    r->fig[FIG_VERTS] = verts;
    r->fig[FIG_IDEAL] = score.ideal;
    r->fig[FIG_RATIO] = score.ideal ? (double)verts / (double)score.ideal : (double)NAN;
    r->fig[FIG_PARAMS] = params;
    r->fig[FIG_IPARAMS] = score.ideal_params ? (double)score.ideal_params : (double)NAN;
    r->fig[FIG_PRATIO] = score.ideal_params ? (double)params / (double)score.ideal_params : (double)NAN;
    r->fig[FIG_ARCS] = arcs;
    r->fig[FIG_CIRCLES] = circles;
    r->fig[FIG_RMS] = score.precision_rms_m;
    r->fig[FIG_FIT] = fit_m >= 0.0 ? fit_m : (double)NAN;
    r->fig[FIG_FLOOR] = floor_m >= 0.0 ? floor_m : (double)NAN;
    r->fig[FIG_COMPL] = score.completeness;
    if (!grid) {
        r->fig[FIG_BAND] = band.map_length_m > 0.0 ? band.band_m / band.map_length_m : 0.0;
        r->fig[FIG_END20] = gtband_share(band.within_20, band.points);
        r->fig[FIG_END10] = gtband_share(band.within_10, band.points);
    }
    r->missed = 0;
    if (grid) {
        r->fig[FIG_GCOMPL] = grid_completeness(truth, grid);
        if (core_m > OCC_TARGET_CORE_M)
            r->missed |= MISS_PRECISION;
        if (topo.crossings > 0)
            r->missed |= MISS_TOPOLOGY;
        if (score.completeness < OCC_TARGET_COMPLETENESS)
            r->missed |= MISS_COMPLETENESS;
        if (score.ideal && (double)score.vertices > TARGET_RATIO * (double)score.ideal)
            r->missed |= MISS_VERTICES;
        return 0;
    }
    if (fit_m >= 0.0 && core_m > fmax(TARGET_FIT_FACTOR * fit_m, fit_m + TARGET_FIT_MARGIN_M))
        r->missed |= MISS_PRECISION;
    if (topo.double_cover_m > TARGET_DCOV_M || topo.crossings > 0 || topo.unsupported_20 > 0)
        r->missed |= MISS_TOPOLOGY;
    if (score.completeness < TARGET_COMPLETENESS)
        r->missed |= MISS_COMPLETENESS;
    if (score.ideal && (double)score.vertices > TARGET_RATIO * (double)score.ideal)
        r->missed |= MISS_VERTICES;
    if (r->fig[FIG_BAND] > TARGET_BAND)
        r->missed |= MISS_BAND;
    if ((truth->ideal_arcs || truth->ideal_circles) && score.ideal_params &&
        (double)score.params > TARGET_PARAM_RATIO * (double)score.ideal_params)
        r->missed |= MISS_PARAMS;
    return 0;
}

/* Does some point of the map segment ab lie over GTSCORE_COMPLETE_M from
 * every true wall? (sampled every GTSCORE_SAMPLE_M, as precision is) */
static int segment_off(const gtscore_truth *truth, const float *a, const float *b)
{
    double dx = (double)b[0] - (double)a[0], dy = (double)b[1] - (double)a[1];
    double n = ceil(hypot(dx, dy) / GTSCORE_SAMPLE_M), k;
    for (k = 0.0; k <= n; k += 1.0) {
        double t = n > 0.0 ? k / n : 0.0;
        if (gtscore_index_distance(&truth->index, (double)a[0] + t * dx, (double)a[1] + t * dy,
                                   GTSCORE_COMPLETE_M) > GTSCORE_COMPLETE_M)
            return 1;
    }
    return 0;
}

/* The scene's true walls, the robot's path, its people and the map (a
 * segment in red where it strays over 5 cm from every true wall). */
static int write_svg(const char *path, const scansim_scene *sc, const gtscore_truth *truth,
                     const map_view *m, const polyc_occupancy_grid *grid)
{
    const polyc_polyline *lines = m->scored;
    uint32_t count = m->count;
    double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL;
    uint32_t i, j, w;
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    for (i = 0; i < sc->wall_point_count; i++) {
        x0 = fmin(x0, sc->wall_xy_m[2u * i]);
        x1 = fmax(x1, sc->wall_xy_m[2u * i]);
        y0 = fmin(y0, sc->wall_xy_m[2u * i + 1u]);
        y1 = fmax(y1, sc->wall_xy_m[2u * i + 1u]);
    }
    x0 -= 0.5; y0 -= 0.5; x1 += 0.5; y1 += 0.5;
    /* y up: the picture's y is -y */
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"%.3f %.3f %.3f %.3f\" "
               "width=\"%.0f\" height=\"%.0f\">\n<rect x=\"%.3f\" y=\"%.3f\" width=\"%.3f\" "
               "height=\"%.3f\" fill=\"white\"/>\n",
            x0, -y1, x1 - x0, y1 - y0, 40.0 * (x1 - x0), 40.0 * (y1 - y0), x0, -y1, x1 - x0,
            y1 - y0);
    for (w = 0; w < sc->wall_count; w++) {
        const scansim_wall *wall = &sc->walls[w];
        fprintf(f, "<%s fill=\"none\" stroke=\"#bbb\" stroke-width=\"0.06\" points=\"",
                wall->closed ? "polygon" : "polyline");
        for (j = 0; j < wall->point_count; j++)
            fprintf(f, "%.3f,%.3f ", sc->wall_xy_m[2u * (wall->first_point + j)],
                    -sc->wall_xy_m[2u * (wall->first_point + j) + 1u]);
        fprintf(f, "\"/>\n");
    }
    if (grid) {                /* --occupancy: the occupied cells, under the map */
        double res = (double)grid->resolution_m;
        for (j = 0; j < grid->height; j++)
            for (i = 0; i < grid->width; i++)
                if (grid->cells[(size_t)j * grid->width + i] >= OCC_MIN)
                    fprintf(f, "<rect x=\"%.4f\" y=\"%.4f\" width=\"%.4f\" height=\"%.4f\" "
                               "fill=\"#8c8\" opacity=\"0.6\"/>\n",
                            grid->origin_x_m + res * i, -(grid->origin_y_m + res * (j + 1u)),
                            res, res);
    }
    fprintf(f, "<polyline fill=\"none\" stroke=\"#48f\" stroke-width=\"0.02\" points=\"");
    for (i = 0; i < sc->pose_count; i++)
        fprintf(f, "%.3f,%.3f ", sc->poses[i].x_m, -sc->poses[i].y_m);
    fprintf(f, "\"/>\n");
    for (i = 0; i < sc->person_count; i++) {
        const scansim_person *p = &sc->people[i];
        fprintf(f, "<line x1=\"%.3f\" y1=\"%.3f\" x2=\"%.3f\" y2=\"%.3f\" stroke=\"#f44\" "
                   "stroke-width=\"%.3f\" stroke-linecap=\"round\" opacity=\"0.5\"/>\n",
                p->from_x_m, -p->from_y_m, p->to_x_m, -p->to_y_m, 2.0 * p->radius_m);
    }
    for (i = 0; i < count; i++) {
        const polyc_polyline *l = &lines[i];
        uint32_t nseg = l->closed ? l->point_count : l->point_count - 1u;
        for (j = 0; j < nseg && l->point_count > 1u; j++) {
            const float *a = &l->xy_m[2u * j], *b = &l->xy_m[2u * ((j + 1u) % l->point_count)];
            fprintf(f, "<line x1=\"%.4f\" y1=\"%.4f\" x2=\"%.4f\" y2=\"%.4f\" stroke=\"%s\" "
                       "stroke-width=\"0.015\"/>\n",
                    (double)a[0], -(double)a[1], (double)b[0], -(double)b[1],
                    segment_off(truth, a, b) ? "#e00" : "black");
        }
        /* a dot on every vertex of the map as the library gives it (its arc
         * form; none on a circle), not on the curves' scoring points */
        const polyc_polyline *v = &m->map.lines[i];
        int circle = m->map.circ && m->map.circ[i].radius_m > 0.0f;
        for (j = 0; !circle && j < v->point_count; j++)
            fprintf(f, "<circle cx=\"%.4f\" cy=\"%.4f\" r=\"0.03\" fill=\"black\"/>\n",
                    (double)v->xy_m[2u * j], -(double)v->xy_m[2u * j + 1u]);
    }
    fprintf(f, "</svg>\n");
    {
        int bad = ferror(f);
        return fclose(f) == 0 && !bad ? 0 : -1;
    }
}

static void print_figures(const double *fig, uint32_t shown)
{
    uint32_t i;
    for (i = 0; i < shown; i++) {
        if (isnan(fig[i]))
            printf(" %*s", figures[i].width, "-");
        else
            printf(" %*.*f", figures[i].width, figures[i].decimals, fig[i] * figures[i].scale);
    }
}

static void print_missed(unsigned missed)
{
    if (!missed) {
        printf("  ok\n");
        return;
    }
    printf("  %s%s%s%s%s%s\n", missed & MISS_PRECISION ? "P" : "",
           missed & MISS_COMPLETENESS ? "C" : "", missed & MISS_VERTICES ? "V" : "",
           missed & MISS_PARAMS ? "A" : "", missed & MISS_TOPOLOGY ? "T" : "",
           missed & MISS_BAND ? "B" : "");
}

/* a / b; 1 when both are 0, NAN when only b is */
static double ratio_of(double a, double b)
{
    if (b == 0.0)
        return a == 0.0 ? 1.0 : (double)NAN;
    return a / b;
}

/* --batch-seeds: the highest core precision of the batch maps made with
 * the optimiser's seeds config->seed + 1 .. + extra, and `core`, into *hi.
 * The batch search takes a random path: how far its figures move from one
 * seed to the next bounds what a comparison of two maps can ask. */
static int batch_core_high(const scansim_scene *sc, const gtscore_truth *truth,
                           const polyc_config *config, unsigned extra, double core, double *hi,
                           const char *label)
{
    *hi = core;
    for (unsigned k = 1; k <= extra; k++) {
        polyc_config c = *config;
        pipeline p;
        map_view m = {0};
        double times[PIPELINE_STAGES];
        row r;
        int rc = -1;
        c.seed = config->seed + k;
        memset(&p, 0, sizeof p);
        if (pipeline_open(&p, &c, sc->scans, sc->scan_count) != 0 ||
            pipeline_run(&p, sc->scans, sc->scan_count, times) != 0 || map_get(&p, &m) != 0)
            printf("%s error in %s (batch seed %llu): %s\n", label,
                   p.failed_at ? p.failed_at : "pipeline_lines", (unsigned long long)c.seed,
                   polyc_status_str(p.status));
        else if (score_scene(sc, truth, &m, 0.0, NULL, &r) != 0)
            printf("%s error: scoring ran out of memory\n", label);
        else
            rc = 0;
        map_free(&m);
        pipeline_close(&p);
        if (rc != 0)
            return -1;
        if (!(r.fig[FIG_CORE] <= *hi))
            *hi = r.fig[FIG_CORE];
    }
    return 0;
}

/* --online: the scene's scans through an online context (pipeline.h), its
 * map scored into r as score_scene scores the batch map, and the batch
 * map's figures (the row `batch`) beside it. *m becomes the online map
 * (the caller frees it). */
static int online_scene(const scansim_scene *sc, const gtscore_truth *truth, const row *batch,
                        const polyc_config *config, double wider_m, pipeline *q,
                        map_view *m, row *r, const char *label)
{
    double ms;
    map_free(m);
    if (pipeline_run_online_wider(q, config, sc->scans, sc->scan_count, wider_m, &ms) != 0 ||
        map_get(q, m) != 0) {
        printf("%s error in %s (online): %s (%s)\n", label,
               q->failed_at ? q->failed_at : "pipeline_lines", polyc_status_str(q->status),
               q->ctx ? polyc_last_error(q->ctx) : "");
        return -1;
    }
    if (score_scene(sc, truth, m, ms, NULL, r) != 0) {
        printf("%s error: scoring the online map ran out of memory\n", label);
        return -1;
    }
    r->fig[FIG_BCORE] = batch->fig[FIG_CORE];
    r->fig[FIG_CORE_RATIO] = ratio_of(r->fig[FIG_CORE], batch->fig[FIG_CORE]);
    r->fig[FIG_BVERTS] = batch->fig[FIG_VERTS];
    r->fig[FIG_VERTS_RATIO] = ratio_of(r->fig[FIG_VERTS], batch->fig[FIG_VERTS]);
    r->fig[FIG_BMS] = batch->fig[FIG_MS];
    r->fig[FIG_MS_RATIO] = ratio_of(r->fig[FIG_MS], batch->fig[FIG_MS]);
    r->fig[FIG_BCORE_HI] = batch->fig[FIG_BCORE_HI];
    r->fig[FIG_CORE_HI_RATIO] = ratio_of(r->fig[FIG_CORE], batch->fig[FIG_BCORE_HI]);
    r->doublings = q->online_doublings;
    return 0;
}

/* Simulates, maps and scores one scene; prints its row. */
static int sweep_scene(const options *o, const char *kind, uint64_t seed, row *r)
{
    scansim_scene sc;
    gtscore_truth truth;
    occmap occ;
    polyc_occupancy_grid grid;
    pipeline p, q;
    polyc_config config;
    map_view m = {0};
    row batch;
    double times[PIPELINE_STAGES], ms = 0.0;
    uint32_t i;
    char err[512] = "", label[48];
    int rc = -1;

    memset(r, 0, sizeof *r);
    snprintf(r->kind, sizeof r->kind, "%s", kind);
    r->seed = seed;
    snprintf(label, sizeof label, "%-10s %4llu", kind, (unsigned long long)seed);
    memset(&truth, 0, sizeof truth);
    memset(&p, 0, sizeof p);
    memset(&q, 0, sizeof q);
    memset(&occ, 0, sizeof occ);
    if (scansim_scene_builtin(&sc, kind, seed) != 0) {
        printf("%s error: out of memory\n", label);
        return -1;
    }
    if (scansim_run(&sc) != 0) {
        printf("%s error: simulation failed\n", label);
        goto done;
    }
    if (truth_of(&sc, &truth, err, sizeof err) != 0) {
        printf("%s error: ground truth: %s\n", label, err);
        goto done;
    }
    polyc_config_default(&config);
    if (o->map_seed_set)
        config.seed = o->map_seed;
    if (o->occupancy) {
        occmap_config oc;
        occmap_config_default(&oc);
        oc.resolution_m = OCC_CELL_M;
        if (occmap_build(&occ, &oc, sc.scans, sc.scan_count) != 0) {
            printf("%s error: the occupancy mapper failed\n", label);
            goto done;
        }
        occmap_grid(&occ, &grid);
        if (pipeline_run_grid(&p, &config, &grid, &ms) != 0 || map_get(&p, &m) != 0) {
            printf("%s error in %s: %s (%s)\n", label,
                   p.failed_at ? p.failed_at : "pipeline_lines", polyc_status_str(p.status),
                   p.ctx ? polyc_last_error(p.ctx) : "");
            goto done;
        }
    } else {
        if (pipeline_open(&p, &config, sc.scans, sc.scan_count) != 0 ||
            pipeline_run(&p, sc.scans, sc.scan_count, times) != 0 || map_get(&p, &m) != 0) {
            printf("%s error in %s: %s (%s)\n", label,
                   p.failed_at ? p.failed_at : "pipeline_lines", polyc_status_str(p.status),
                   p.ctx ? polyc_last_error(p.ctx) : "");
            goto done;
        }
        for (i = 0; i < PIPELINE_STAGES; i++)
            ms += times[i];
    }
    if (score_scene(&sc, &truth, &m, ms, o->occupancy ? &grid : NULL, o->online ? &batch : r) != 0) {
        printf("%s error: scoring ran out of memory\n", label);
        goto done;
    }
    if (o->online && batch_core_high(&sc, &truth, &config, o->batch_seeds - 1u,
                                     batch.fig[FIG_CORE], &batch.fig[FIG_BCORE_HI], label) != 0)
        goto done;
    if (o->online && online_scene(&sc, &truth, &batch, &config, o->online_wider_m, &q, &m, r,
                                  label) != 0)
        goto done;
    r->ok = 1;
    printf("%s", label);
    print_figures(r->fig, shown_figures(o));
    print_missed(r->missed);
    fflush(stdout);
    if (o->save_dir || o->svg_dir) {
        char log_path[1024], gt_path[1024], svg_path[1024];
        snprintf(log_path, sizeof log_path, "%s/%s-s%llu.log", o->save_dir ? o->save_dir : "",
                 kind, (unsigned long long)seed);
        snprintf(gt_path, sizeof gt_path, "%s/%s-s%llu.gt.txt", o->save_dir ? o->save_dir : "",
                 kind, (unsigned long long)seed);
        snprintf(svg_path, sizeof svg_path, "%s/%s-s%llu.svg", o->svg_dir ? o->svg_dir : "",
                 kind, (unsigned long long)seed);
        if (o->save_dir && scansim_save(&sc, log_path, gt_path) != 0)
            fprintf(stderr, "sweep: cannot write %s: %s\n", log_path, strerror(errno));
        if (o->svg_dir && write_svg(svg_path, &sc, &truth, &m,
                                    o->occupancy ? &grid : NULL) != 0)
            fprintf(stderr, "sweep: cannot write %s: %s\n", svg_path, strerror(errno));
    }
    rc = 0;
done:
    map_free(&m);
    pipeline_close(&q);
    pipeline_close(&p);
    occmap_free(&occ);
    gtscore_truth_free(&truth);
    scansim_scene_free(&sc);
    return rc;
}

/* ---- the summary -------------------------------------------------------------- */

/* --online: over the rows of `kind` (NULL: all), on how many scenes the
 * online map's core precision is within 10 % of the batch map's, the worst
 * core ratio and the highest and lowest vertex ratio, with their scenes. */
static void summarise_online(const row *rows, size_t n, const char *kind)
{
    size_t i, worst = n, most = n, least = n;
    unsigned within = 0, within_hi = 0, scenes = 0;
    for (i = 0; i < n; i++) {
        const row *r = &rows[i];
        if (!r->ok || (kind && strcmp(r->kind, kind) != 0))
            continue;
        scenes++;
        within += r->fig[FIG_CORE_RATIO] <= ONLINE_CORE_RATIO;
        within_hi += r->fig[FIG_CORE_HI_RATIO] <= ONLINE_CORE_RATIO;
        /* a ratio that cannot be taken (batch core 0, online not) is the worst */
        if (worst == n || !(r->fig[FIG_CORE_RATIO] <= rows[worst].fig[FIG_CORE_RATIO]))
            worst = i;
        if (most == n || r->fig[FIG_VERTS_RATIO] > rows[most].fig[FIG_VERTS_RATIO])
            most = i;
        if (least == n || r->fig[FIG_VERTS_RATIO] < rows[least].fig[FIG_VERTS_RATIO])
            least = i;
    }
    printf("%-10s %4s", "", "");
    if (!scenes) {
        printf(" online/batch: no scene\n");
        return;
    }
    printf(" online/batch: core within %.0f %% on %u/%u, worst %.3f (%s %llu: %.1f mm against "
           "%.1f); verts worst %.3f (%s %llu: %.0f against %.0f), lowest %.3f (%s %llu)\n",
           100.0 * (ONLINE_CORE_RATIO - 1.0), within, scenes, rows[worst].fig[FIG_CORE_RATIO],
           rows[worst].kind, (unsigned long long)rows[worst].seed,
           1e3 * rows[worst].fig[FIG_CORE], 1e3 * rows[worst].fig[FIG_BCORE],
           rows[most].fig[FIG_VERTS_RATIO], rows[most].kind,
           (unsigned long long)rows[most].seed, rows[most].fig[FIG_VERTS],
           rows[most].fig[FIG_BVERTS], rows[least].fig[FIG_VERTS_RATIO], rows[least].kind,
           (unsigned long long)rows[least].seed);
    printf("%-10s %4s online/highest batch: core within %.0f %% on %u/%u\n", "", "",
           100.0 * (ONLINE_CORE_RATIO - 1.0), within_hi, scenes);
}

/* qsort: the rows by their core ratio, worst (highest, or none) first */
static int compare_core_ratio(const void *a, const void *b)
{
    double x = (*(const row *const *)a)->fig[FIG_CORE_RATIO];
    double y = (*(const row *const *)b)->fig[FIG_CORE_RATIO];
    if (isnan(x) || isnan(y))
        return isnan(y) - isnan(x);
    return (x < y) - (x > y);
}

/* --online: the ONLINE_WORST_LISTED scenes of the worst core ratio. */
static void list_worst_online(const row *rows, size_t n)
{
    const row **by = malloc((n ? n : 1u) * sizeof *by);
    size_t i, m = 0;
    if (!by)
        return;
    for (i = 0; i < n; i++)
        if (rows[i].ok)
            by[m++] = &rows[i];
    qsort(by, m, sizeof *by, compare_core_ratio);
    printf("\nthe worst core/b (online core against batch core):\n");
    for (i = 0; i < m && i < ONLINE_WORST_LISTED; i++)
        printf("  %-10s %4llu  %6.1f mm against %6.1f mm  core/b %.3f  verts %.0f against %.0f\n",
               by[i]->kind, (unsigned long long)by[i]->seed, 1e3 * by[i]->fig[FIG_CORE],
               1e3 * by[i]->fig[FIG_BCORE], by[i]->fig[FIG_CORE_RATIO], by[i]->fig[FIG_VERTS],
               by[i]->fig[FIG_BVERTS]);
    free(by);
}

/* Median and worst of each figure over the rows of `kind` (NULL: all). */
static void summarise(const options *o, const row *rows, size_t n, const char *kind,
                      const char *label)
{
    double median[FIG_COUNT], worst[FIG_COUNT], *v = malloc((n ? n : 1u) * sizeof *v);
    unsigned passed = 0, scenes = 0;
    uint32_t f;
    size_t i, m;
    if (!v)
        return;
    for (f = 0; f < FIG_COUNT; f++) {
        for (m = 0, i = 0; i < n; i++)
            if (rows[i].ok && (!kind || strcmp(rows[i].kind, kind) == 0) &&
                !isnan(rows[i].fig[f]))
                v[m++] = rows[i].fig[f];
        median[f] = worst[f] = (double)NAN;
        if (m) {
            qsort(v, m, sizeof *v, pipeline_compare_double);
            median[f] = m % 2u ? v[m / 2u] : 0.5 * (v[m / 2u - 1u] + v[m / 2u]);
            worst[f] = figures[f].low_is_worse ? v[0] : v[m - 1u];
        }
    }
    for (i = 0; i < n; i++)
        if (rows[i].ok && (!kind || strcmp(rows[i].kind, kind) == 0)) {
            scenes++;
            passed += rows[i].missed == 0;
        }
    free(v);
    printf("%-10s %4s", label, "med");
    print_figures(median, shown_figures(o));
    printf("  %u/%u ok\n", passed, scenes);
    printf("%-10s %4s", "", "worst");
    print_figures(worst, shown_figures(o));
    printf("\n");
    if (o->online)
        summarise_online(rows, n, kind);
}

/* ---- main ------------------------------------------------------------------- */

/* A decimal unsigned number at the start of text, no sign; *end after it.
 * -1 when there is none or it does not fit. */
static int parse_unsigned(const char *text, char **end, unsigned long long *out)
{
    errno = 0;
    *out = strtoull(text, end, 10);
    return errno || *end == text || text[0] == '-' ? -1 : 0;
}

static int parse_seeds(const char *text, options *o)
{
    char *end;
    unsigned long long a, b;
    if (parse_unsigned(text, &end, &a))
        return -1;
    b = a;
    if (*end == '-' && parse_unsigned(end + 1, &end, &b))
        return -1;
    if (*end || b < a || b - a > 100000u)
        return -1;
    o->seed_first = a;
    o->seed_last = b;
    return 0;
}

/* A comma-separated list of scansim's built-in names. */
static int parse_kinds(char *text, options *o)
{
    char *tok;
    o->kind_count = 0;
    for (tok = strtok(text, ","); tok; tok = strtok(NULL, ",")) {
        const char *const *name = scansim_builtin_names();
        while (*name && strcmp(*name, tok) != 0)
            name++;
        if (!*name) {
            fprintf(stderr, "sweep: no scene kind '%s'\n", tok);
            return -1;
        }
        if (o->kind_count == MAX_KINDS)
            return -1;
        o->kinds[o->kind_count++] = tok;
    }
    return o->kind_count ? 0 : -1;
}

static int parse_options(int argc, char **argv, options *o)
{
    int i;
    memset(o, 0, sizeof *o);
    o->seed_first = 1;
    o->seed_last = 6;
    o->batch_seeds = 1;
    for (i = 0; i < (int)(sizeof default_kinds / sizeof default_kinds[0]); i++)
        o->kinds[o->kind_count++] = default_kinds[i];
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            fputs(usage_text, stdout);
            fputs(usage_columns, stdout);
            exit(0);
        } else if (strcmp(a, "--seeds") == 0 && i + 1 < argc) {
            if (parse_seeds(argv[++i], o))
                return -1;
        } else if (strcmp(a, "--kinds") == 0 && i + 1 < argc) {
            if (parse_kinds(argv[++i], o))
                return -1;
        } else if (strcmp(a, "--save") == 0 && i + 1 < argc) {
            o->save_dir = argv[++i];
        } else if (strcmp(a, "--occupancy") == 0) {
            o->occupancy = 1;
        } else if (strcmp(a, "--online") == 0) {
            o->online = 1;
        } else if (strcmp(a, "--svg") == 0 && i + 1 < argc) {
            o->svg_dir = argv[++i];
        } else if (strcmp(a, "--online-wider") == 0 && i + 1 < argc) {
            char *end;
            double v = strtod(argv[++i], &end);
            if (end == argv[i] || *end || !(v >= 0.0 && v <= 100.0))
                return -1;
            o->online_wider_m = v;
        } else if (strcmp(a, "--batch-seeds") == 0 && i + 1 < argc) {
            char *end;
            unsigned long long v;
            if (parse_unsigned(argv[++i], &end, &v) || *end || v < 1 || v > 16)
                return -1;
            o->batch_seeds = (unsigned)v;
        } else if (strcmp(a, "--map-seed") == 0 && i + 1 < argc) {
            char *end;
            unsigned long long v;
            if (parse_unsigned(argv[++i], &end, &v) || *end)
                return -1;
            o->map_seed = v;
            o->map_seed_set = 1;
        } else
            return -1;
    }
    if (!o->online && (o->batch_seeds > 1 || o->online_wider_m > 0.0))
        return -1; /* (options of --online) */
    return o->online && o->occupancy ? -1 : 0;
}

int main(int argc, char **argv)
{
    options o;
    row *rows;
    size_t n, k = 0;
    unsigned kind, doubled = 0;
    uint64_t seed;
    double t0 = pipeline_now_ms(), pipeline_ms = 0.0, batch_ms = 0.0;
    int failed = 0;
    uint32_t f;

    if (parse_options(argc, argv, &o) != 0) {
        fputs(usage_text, stderr);
        fputs(usage_columns, stderr);
        return EXIT_USAGE;
    }
    n = (size_t)o.kind_count * (size_t)(o.seed_last - o.seed_first + 1u);
    rows = calloc(n, sizeof *rows);
    if (!rows) {
        fprintf(stderr, "sweep: out of memory\n");
        return EXIT_FAILED;
    }
    if (o.occupancy)
        printf("libpolyc %u.%u.%u sweep --occupancy: seeds %llu-%llu, each scene's log-odds map at "
               "%.0f cm through polyc_add_grid; targets: P core <= %.0f mm, C compl >= %.2f, V "
               "verts <= %.1f x ideal, T 0 cross (dcov, uns20 against the occupied cells)\n",
               polyc_version() / 10000u, polyc_version() / 100u % 100u, polyc_version() % 100u,
               (unsigned long long)o.seed_first, (unsigned long long)o.seed_last,
               100.0 * OCC_CELL_M, 1e3 * OCC_TARGET_CORE_M, OCC_TARGET_COMPLETENESS,
               TARGET_RATIO);
    else
        printf("libpolyc %u.%u.%u sweep%s: seeds %llu-%llu, targets: P core <= max(%.2f x fit, fit + "
               "%.1f mm), C compl >= %.2f, V verts <= %.1f x ideal, T dcov <= %.2f m, 0 cross, "
               "0 uns20, B band15 <= %.0f %% of the map\n",
               polyc_version() / 10000u, polyc_version() / 100u % 100u, polyc_version() % 100u,
               o.online ? " --online" : "", (unsigned long long)o.seed_first,
               (unsigned long long)o.seed_last, TARGET_FIT_FACTOR, 1e3 * TARGET_FIT_MARGIN_M, TARGET_COMPLETENESS, TARGET_RATIO,
               TARGET_DCOV_M, 100.0 * TARGET_BAND);
    if (o.online)
        printf("online: each scene's scans one by one through polyc_online_add_scan, "
               "polyc_online_update (work %u) after each, then polyc_online_finish; the rows, "
               "targets and summaries are the online map's; bcore, bverts, bms: the batch "
               "map's; core/b within %.0f %% is the target\n",
               POLYC_ONLINE_WORK_DEFAULT, 100.0 * (ONLINE_CORE_RATIO - 1.0));
    printf("%-10s %4s", "kind", "seed");
    for (f = 0; f < shown_figures(&o); f++)
        printf(" %*s", figures[f].width, figures[f].name);
    printf("  missed\n");
    for (kind = 0; kind < o.kind_count; kind++)
        for (seed = o.seed_first; seed <= o.seed_last; seed++)
            if (sweep_scene(&o, o.kinds[kind], seed, &rows[k++]) != 0)
                failed = 1;
    printf("\n");
    for (kind = 0; kind < o.kind_count; kind++)
        summarise(&o, rows, n, o.kinds[kind], o.kinds[kind]);
    summarise(&o, rows, n, NULL, "all");
    if (o.online)
        list_worst_online(rows, n);
    for (k = 0; k < n; k++) {
        pipeline_ms += rows[k].ok ? rows[k].fig[FIG_MS] : 0.0;
        batch_ms += rows[k].ok && o.online ? rows[k].fig[FIG_BMS] : 0.0;
        doubled += rows[k].ok && rows[k].doublings > 0;
    }
    if (o.online)
        printf("\n%zu scenes in %.1f s, %.1f s of it online (the ms column), %.1f s in batch "
               "(bms); the online limits were doubled on %u\n", n,
               (pipeline_now_ms() - t0) / 1e3, pipeline_ms / 1e3, batch_ms / 1e3, doubled);
    else
        printf("\n%zu scenes in %.1f s, %.1f s of it in the pipeline (the ms column)\n", n,
               (pipeline_now_ms() - t0) / 1e3, pipeline_ms / 1e3);
    free(rows);
    return failed ? EXIT_FAILED : 0;
}
