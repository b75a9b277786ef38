/* bench.c - measure libpolyc on the shared data sets (not in the repo).
 *
 *   bench [--runs N] [--only NAMES] [--single K] [--iterations N] [--occupancy-only] DATA_DIR
 *
 * Takes DATA_DIR/sim/NAME.log (+ NAME.gt.txt ground truth) and
 * DATA_DIR/carmen/NAME.log. Prints one table: per scene the input size, the
 * median time of each stage over N runs, memory, and accuracy (scored by
 * tools/eval/gtscore), a second table of topology figures (tools/eval/gttopo), then a
 * single-scan section on the real logs, then the occupancy-map section (the
 * library and a findContours-style baseline on grids, and a speed row on a
 * 2,000 x 2,000-cell map file). Logs are read
 * with tools/scanlog, the same reader as the CLI. Exit codes: 0 ok, 1 some
 * scene failed, 2 usage or no data directory.
 */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "gridimage.h"
#include "gridtrace.h"
#include "gtband.h"
#include "gtscore.h"
#include "gttopo.h"
#include "mapfile.h"
#include "mapout.h"
#include "occmap.h"
#include "pipeline.h"
#include "polyc.h"
#include "scanlog.h"

#define EXIT_FAILED 1
#define EXIT_USAGE 2
#define MAX_RUNS 99
#define NEAR_M 0.05 /* "share of endpoints within 5 cm of the map" */
#define CORE_M 0.5 /* core precision: the map samples within 0.5 m of a true wall */
#define SCAN_BUDGET_MS 2.0 /* issue 4: one 360-beam scan within 2 ms; `over` counts the scans above */

static const char usage_text[] =
    "usage: bench [options] DATA_DIR\n"
    "Measures libpolyc on DATA_DIR/sim/*.log (scored against NAME.gt.txt) and\n"
    "DATA_DIR/carmen/*.log (see shared/data/README.md); `make bench DATA=dir`\n"
    "builds it with -O3 and runs it.\n"
    "options:\n"
    "  --runs N         runs per scene; stage times are medians (default 3)\n"
    "  --only NAMES     comma-separated scene names (intel,office), or sim / carmen\n"
    "  --single K       single-scan maps from K scans of each real log, each run N\n"
    "                   times on one block (medians; cold = the first run with its\n"
    "                   malloc). Default 10; 0: no single-scan section\n"
    "  --iterations N   optimiser iteration cap (default: the library's)\n"
    "  --alpha A, --gamma G, --cell M, --grazing C, --data-min M\n"
    "                   override polyc_config's alpha, gamma, cell_m,\n"
    "                   grazing_cells, data_min_m (default: the library's)\n"
    "  --seed N         the optimiser's PRNG seed (default: the library's)\n"
    "  --occupancy-only only the occupancy-map section\n"
    "  -h, --help       this text\n"
    "Columns: stage times in ms (parse = reading the log, add = polyc_add_scan,\n"
    "grid, contour, trace, optimise, output = JSON to /dev/null); block and used\n"
    "= the context's memory block and its high-water mark; rss = peak resident\n"
    "size of the process so far. Accuracy (shared/data/README.md): sim scenes\n"
    "precision RMS / p95 in mm, the line-fit floor (the precision straight lines\n"
    "fitted to each seen wall side's endpoints would score, tools/eval/gtfloor.c),\n"
    "the ideal fit (the precision of the ideal map, one segment per seen run of\n"
    "each wall side, fitted to that run's endpoints),\n"
    "completeness, vertices / ideal; real logs the\n"
    "share of scan endpoints within 5 cm of the map (end5). Single scans: mean\n"
    "f, pooled ray RMSE, vertices, the mean and the slowest of the scans' median\n"
    "times, and how many scans took over 2 ms (issue 4's budget for one scan);\n"
    "cross = crossings summed over the scan maps, maps = scan maps with one or\n"
    "more, uns20 = unsupported runs over 20 cm summed (each against its scan).\n"
    "Topology (second table, tools/eval/gttopo.h, against the log's scan endpoints):\n"
    "len = map length (m); dcov = doubly covered length in runs over 20 cm (m,\n"
    "and % of len); cross = pairs of segments crossing; uns20, uns10 = runs of\n"
    "map over 20 / 10 cm with no endpoint within 5 cm; loose = open ends 3-15 cm\n"
    "from another part of the map; band15 = map length drawn as a band of parallel\n"
    "lines seen from the same side, in runs over 20 cm (m, and % of len;\n"
    "tools/eval/gtband.h); end20, end10, end5 = share of scan endpoints within\n"
    "20 / 10 / 5 cm of the map; sim scenes: rms = precision RMS, core = the\n"
    "precision RMS of the samples within 0.5 m of a true wall (mm); ms = the\n"
    "topology scorers' time.\n"
    "Occupancy maps (last section, docs/evaluation.md): sim scenes but the circles\n"
    "through the log-odds mapper at 5 cm (tools/eval/occmap.h), intel, fhw and aces\n"
    "as their hit/miss grid at 5 cm written and read back as `polyc grid` writes it;\n"
    "each grid mapped by the library (libpolyc: polyc_add_grid, polyc_build) and by\n"
    "the baseline (contours: findContours + approxPolyDP at one cell,\n"
    "tools/eval/gridtrace.h). grid = occmap or hit/miss, cells = width x height,\n"
    "occ = occupied cells, gridms = time to make the grid; lines, verts, ideal,\n"
    "x = verts / ideal; core = core precision (0.5 m, mm), compl = completeness\n"
    "(sim); occ1 = share of occupied cells within one cell (5 cm) of the map;\n"
    "dcov (m), dcov%, cross against the occupied cells' centres; ms = grid to\n"
    "polylines. maze: a 2,000 x 2,000-cell maze at 5 cm written as PGM + YAML to\n"
    "a temporary folder, then read, converted to cells, mapped and written as JSON\n"
    "(to /dev/null) as `polyc map.yaml` does, each timed (target: under 1 s); it\n"
    "runs unless --only leaves out `maze`.\n"
    "Exit: 0 ok; 1 a scene failed (its row says why); 2 usage error, or\n"
    "DATA_DIR missing: 'bench: data directory DIR not found (pass DATA=path)'.\n";

/* ST_ADD..ST_OPT in the order of pipeline.h's stages: pipeline_run fills them */
enum stage { ST_PARSE, ST_ADD, ST_GRID, ST_CONTOUR, ST_TRACE, ST_OPT, ST_OUT, ST_TOTAL,
             ST_COUNT };
typedef char stage_order_check[ST_OPT - ST_ADD == PIPELINE_OPTIMIZE ? 1 : -1];

typedef struct options {
    unsigned runs;
    const char *only;          /* NULL: every scene */
    unsigned single;
    long iterations;           /* < 0: library default */
    double alpha, gamma, cell; /* <= 0 (gamma < 0): library default */
    double grazing, data_min;  /* < 0: library default */
    long seed;                 /* < 0: library default */
    int occupancy_only;        /* only the occupancy-map section */
    const char *data;
} options;

typedef struct scene {
    char name[128];            /* "office" */
    char kind[8];              /* "sim" or "carmen" */
    char log_path[1536];
    char gt_path[1536];        /* sim only */
} scene;

/* ---- small helpers -------------------------------------------------------- */


static double median(const double *v, unsigned n)
{
    double tmp[MAX_RUNS];
    memcpy(tmp, v, n * sizeof *v);
    qsort(tmp, n, sizeof *tmp, pipeline_compare_double);
    return n % 2u ? tmp[n / 2u] : 0.5 * (tmp[n / 2u - 1u] + tmp[n / 2u]);
}

static double peak_rss_mib(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0)
        return 0.0;
    return (double)ru.ru_maxrss / 1024.0; /* Linux: kilobytes */
}

static double mib(uint64_t bytes)
{
    return (double)bytes / (1024.0 * 1024.0);
}

/* Is `name` (or its kind) listed in the comma-separated `only`? */
static int selected(const options *o, const scene *s)
{
    const char *p = o->only;
    if (!p)
        return 1;
    while (*p) {
        size_t len = strcspn(p, ",");
        if ((len == strlen(s->name) && strncmp(p, s->name, len) == 0) ||
            (len == strlen(s->kind) && strncmp(p, s->kind, len) == 0))
            return 1;
        p += len;
        if (*p == ',')
            p++;
    }
    return 0;
}

static int compare_scene(const void *a, const void *b)
{
    return strcmp(((const scene *)a)->name, ((const scene *)b)->name);
}

/* Appends DATA/kind/NAME.log files to *list. Returns the new count. */
static size_t find_scenes(const options *o, const char *kind, scene **list, size_t count,
                          size_t *cap)
{
    char dir_path[1024];
    DIR *dir;
    struct dirent *e;
    size_t first = count;
    snprintf(dir_path, sizeof dir_path, "%s/%s", o->data, kind);
    dir = opendir(dir_path);
    if (!dir)
        return count;
    while ((e = readdir(dir)) != NULL) {
        size_t len = strlen(e->d_name);
        scene *s;
        if (len <= 4 || len - 4 >= sizeof s->name || strcmp(e->d_name + len - 4, ".log") != 0)
            continue;
        if (count == *cap) {
            scene *p = realloc(*list, (*cap ? 2u * *cap : 32u) * sizeof *p);
            if (!p)
                break;
            *list = p;
            *cap = *cap ? 2u * *cap : 32u;
        }
        s = &(*list)[count];
        memset(s, 0, sizeof *s);
        memcpy(s->name, e->d_name, len - 4);
        snprintf(s->kind, sizeof s->kind, "%s", kind);
        snprintf(s->log_path, sizeof s->log_path, "%s/%s", dir_path, e->d_name);
        if (strcmp(kind, "sim") == 0)
            snprintf(s->gt_path, sizeof s->gt_path, "%s/%s.gt.txt", dir_path, s->name);
        if (selected(o, s))
            count++;
    }
    closedir(dir);
    qsort(*list + first, count - first, sizeof **list, compare_scene);
    return count;
}

/* ---- reading a log (tools/scanlog) --------------------------------------- */

static int read_log(const char *path, scanlog *log, double *ms)
{
    FILE *f = fopen(path, "r");
    double t0 = pipeline_now_ms();
    int rc;
    memset(log, 0, sizeof *log);
    if (!f) {
        snprintf(log->error, sizeof log->error, "%s: %s", path, strerror(errno));
        return -1;
    }
    rc = scanlog_read(log, f, path, NULL);
    fclose(f);
    *ms = pipeline_now_ms() - t0;
    return rc;
}

/* ---- one pipeline run (tools/eval/pipeline.h) --------------------------------- */

/* The library's configuration with the options' overrides. */
static void bench_config(const options *o, polyc_config *c)
{
    polyc_config_default(c);
    if (o->iterations >= 0)
        c->max_iterations = (uint32_t)o->iterations;
    if (o->alpha > 0.0)
        c->alpha = (float)o->alpha;
    if (o->gamma >= 0.0)
        c->gamma = (float)o->gamma;
    if (o->cell > 0.0)
        c->cell_m = (float)o->cell;
    if (o->grazing >= 0.0)
        c->grazing_cells = (float)o->grazing;
    if (o->data_min >= 0.0)
        c->data_min_m = (float)o->data_min;
    if (o->seed >= 0)
        c->seed = (uint64_t)o->seed;
}

static int open_pipeline(pipeline *p, const options *o, const polyc_scan *scans, uint32_t n)
{
    polyc_config config;
    bench_config(o, &config);
    return pipeline_open(p, &config, scans, n);
}

static double write_output(const pipeline *p, const polyc_polyline *lines, uint32_t count)
{
    double t = pipeline_now_ms();
    polyc_stats stats;
    mapout_map map;
    FILE *f = fopen("/dev/null", "w");
    if (!f)
        return (double)NAN;
    memset(&map, 0, sizeof map);
    polyc_get_stats(p->ctx, &stats);
    map.lines = lines;
    map.line_count = count;
    map.stats = &stats;
    mapout_json(f, &map);
    fclose(f);
    return pipeline_now_ms() - t;
}

/* ---- the table ----------------------------------------------------------- */

static void print_header(const options *o)
{
    printf("libpolyc %u.%u.%u bench: median of %u run%s, data %s\n", polyc_version() / 10000u,
           polyc_version() / 100u % 100u, polyc_version() % 100u, o->runs,
           o->runs == 1 ? "" : "s", o->data);
    printf("%-24s %6s %8s | %7s %6s %7s %7s %7s %8s %6s %8s | %8s %8s %7s | %6s %7s %6s "
           "%5s | %6s %6s %6s %6s %6s %6s\n",
           "scene", "scans", "beams", "parse", "add", "grid", "contour", "trace", "optimise",
           "output", "total", "blockMiB", "usedMiB", "rssMiB", "lines", "verts", "ideal", "x",
           "rms", "p95", "floor", "fit", "compl", "end5");
    printf("%-24s %6s %8s | %7s %6s %7s %7s %7s %8s %6s %8s | %8s %8s %7s | %6s %7s %6s "
           "%5s | %6s %6s %6s %6s %6s %6s\n",
           "", "", "", "ms", "ms", "ms", "ms", "ms", "ms", "ms", "ms", "", "", "", "", "", "",
           "", "mm", "mm", "mm", "mm", "", "");
}

/* One row of the topology table, kept until the first table is done. */
typedef struct topo_row {
    char label[160];
    int ok;                    /* 0: the scene failed or the scorer ran out of memory */
    gttopo_score score;
    gtband_score band;         /* band15, end5 / end10 / end20 */
    double rms_m, core_m;      /* sim scenes; < 0: none */
    double ms;                 /* the scorers' time, points included */
} topo_row;

typedef struct row_accuracy {
    int has_truth;
    gtscore_map_score score;
    double end5;               /* < 0: not computed */
    double floor_m;            /* line-fit floor (sim scenes), < 0: none */
    double fit_m;              /* ideal-map fit (sim scenes), < 0: none */
    uint32_t lines, vertices;
} row_accuracy;

/* The topology figures of a whole log's map against its scan endpoints,
 * and the core precision of a simulated scene. */
static void topology(const scanlog *log, const polyc_polyline *lines, uint32_t count,
                     const gtscore_truth *truth, const row_accuracy *acc, topo_row *row)
{
    double t0 = pipeline_now_ms(), *xy = NULL, *from = NULL;
    uint64_t n = 0;
    row->rms_m = row->core_m = -1.0;
    row->ok = gtband_scan_points(log->scans, log->count, &xy, &from, &n) == 0 &&
              gttopo_score_map(lines, count, xy, n, &row->score) == 0 &&
              gtband_score_map(lines, count, xy, from, n, &row->band) == 0;
    free(xy);
    free(from);
    row->ms = pipeline_now_ms() - t0;
    if (row->ok && truth) {
        row->rms_m = acc->score.precision_rms_m;
        if (gtscore_core_precision(truth, lines, count, CORE_M, &row->core_m) != 0)
            row->core_m = -1.0;
    }
}

static void accuracy(const scene *s, const scanlog *log, const polyc_polyline *lines,
                     uint32_t count, row_accuracy *acc, topo_row *row)
{
    uint32_t i;
    memset(acc, 0, sizeof *acc);
    acc->end5 = -1.0;
    acc->floor_m = -1.0;
    acc->fit_m = -1.0;
    acc->lines = count;
    for (i = 0; i < count; i++)
        acc->vertices += lines[i].point_count;
    if (s->gt_path[0]) {
        gtscore_truth truth;
        char err[512];
        if (gtscore_truth_load(&truth, s->gt_path, err, sizeof err) == 0 &&
            gtscore_score_map(&truth, lines, count, &acc->score) == 0) {
            acc->has_truth = 1;
            if (gtscore_line_floor(&truth, log->scans, log->count, &acc->floor_m) != 0)
                acc->floor_m = -1.0;
            if (gtscore_ideal_fit(&truth, log->scans, log->count, &acc->fit_m) != 0)
                acc->fit_m = -1.0;
            topology(log, lines, count, &truth, acc, row);
        } else
            fprintf(stderr, "bench: %s: no score: %s\n", s->name, err);
        gtscore_truth_free(&truth);
    } else {
        gtscore_index map;
        uint64_t within, total;
        gtscore_index_init(&map);
        if (gtscore_index_add_polylines(&map, lines, count) == 0 &&
            gtscore_index_build(&map, 0.1) == 0) {
            gtscore_endpoints_within(&map, log->scans, log->count, NEAR_M, &within, &total);
            acc->end5 = total ? (double)within / (double)total : 0.0;
        }
        gtscore_index_free(&map);
        topology(log, lines, count, NULL, acc, row);
    }
}

static int bench_scene(const options *o, const scene *s, topo_row *row)
{
    double times[MAX_RUNS][ST_COUNT], column[MAX_RUNS], med[ST_COUNT];
    scanlog log;
    pipeline p;
    polyc_polyline *lines = NULL;
    polyc_stats stats;
    row_accuracy acc;
    uint32_t count = 0;
    unsigned r, k;
    char label[160];
    int ok = 0;

    snprintf(label, sizeof label, "%s/%s", s->kind, s->name);
    memset(row, 0, sizeof *row);
    snprintf(row->label, sizeof row->label, "%s", label);
    memset(times, 0, sizeof times);
    memset(&log, 0, sizeof log);
    for (r = 0; r < o->runs; r++) {
        scanlog_free(&log);
        if (read_log(s->log_path, &log, &times[r][ST_PARSE]) != 0) {
            printf("%-24s error: %s\n", label, log.error);
            scanlog_free(&log);
            return -1;
        }
    }
    if (open_pipeline(&p, o, log.scans, log.count) == 0) {
        for (r = 0; r < o->runs && p.failed_at == NULL; r++) {
            free(lines);
            lines = NULL;
            if (pipeline_run(&p, log.scans, log.count, &times[r][ST_ADD]) != 0)
                break;
            lines = pipeline_lines(&p, &count);
            if (!lines)
                break;
            times[r][ST_OUT] = write_output(&p, lines, count);
            for (k = 0; k < ST_TOTAL; k++)
                times[r][ST_TOTAL] += times[r][k];
        }
        ok = p.failed_at == NULL && lines != NULL;
    }
    if (!ok) {
        printf("%-24s %6u %8llu | error in %s: %s (%s)\n", label, log.count,
               (unsigned long long)log.beams, p.failed_at ? p.failed_at : "pipeline_lines",
               polyc_status_str(p.status), p.ctx ? polyc_last_error(p.ctx) : "");
        free(lines);
        pipeline_close(&p);
        scanlog_free(&log);
        return -1;
    }
    for (k = 0; k < ST_COUNT; k++) {
        for (r = 0; r < o->runs; r++)
            column[r] = times[r][k];
        med[k] = median(column, o->runs);
    }
    polyc_get_stats(p.ctx, &stats);
    accuracy(s, &log, lines, count, &acc, row);

    printf("%-24s %6u %8llu | %7.1f %6.1f %7.1f %7.1f %7.1f %8.1f %6.1f %8.1f | %8.2f %8.2f "
           "%7.1f | %6u %7u ",
           label, log.count, (unsigned long long)log.beams, med[ST_PARSE], med[ST_ADD],
           med[ST_GRID], med[ST_CONTOUR], med[ST_TRACE], med[ST_OPT], med[ST_OUT],
           med[ST_TOTAL], mib(stats.memory_size_bytes), mib(stats.memory_used_bytes),
           peak_rss_mib(), acc.lines, acc.vertices);
    if (acc.has_truth) {
        char floor_mm[16] = "-", fit_mm[16] = "-";
        if (acc.floor_m >= 0.0)
            snprintf(floor_mm, sizeof floor_mm, "%.1f", 1e3 * acc.floor_m);
        if (acc.fit_m >= 0.0)
            snprintf(fit_mm, sizeof fit_mm, "%.1f", 1e3 * acc.fit_m);
        printf("%6u %5.2f | %6.1f %6.1f %6s %6s %6.4f %6s\n", acc.score.ideal,
               acc.score.vertex_ratio, 1e3 * acc.score.precision_rms_m,
               1e3 * acc.score.precision_p95_m, floor_mm, fit_mm, acc.score.completeness, "-");
    } else if (acc.end5 >= 0.0) {
        printf("%6s %5s | %6s %6s %6s %6s %6s %6.4f\n", "-", "-", "-", "-", "-", "-", "-",
               acc.end5);
    } else {
        printf("%6s %5s | %6s %6s %6s %6s %6s %6s\n", "-", "-", "-", "-", "-", "-", "-", "-");
    }
    fflush(stdout);
    free(lines);
    pipeline_close(&p);
    scanlog_free(&log);
    return 0;
}

static void print_topology(const topo_row *rows, size_t count)
{
    size_t i;
    printf("\ntopology (tools/eval/gttopo.h) and bands (tools/eval/gtband.h): the map "
           "against its log's scan\nendpoints; rms and core (the samples within 0.5 m of a "
           "true wall) are precision RMS, sim\nscenes only\n");
    printf("%-24s %9s %8s %6s %6s %6s %6s %6s | %8s %6s %6s %6s %6s | %6s %6s | %7s\n",
           "scene", "len", "dcov", "dcov%", "cross", "uns20", "uns10", "loose", "band15",
           "band%", "end20", "end10", "end5", "rms", "core", "topo");
    printf("%-24s %9s %8s %6s %6s %6s %6s %6s | %8s %6s %6s %6s %6s | %6s %6s | %7s\n", "",
           "m", "m", "", "", "", "", "", "m", "", "", "", "", "mm", "mm", "ms");
    for (i = 0; i < count; i++) {
        const topo_row *r = &rows[i];
        const gttopo_score *t = &r->score;
        const gtband_score *b = &r->band;
        char rms[16] = "-", core[16] = "-";
        if (!r->ok) {
            if (r->label[0])
                printf("%-24s %9s\n", r->label, "-");
            continue;
        }
        if (r->rms_m >= 0.0)
            snprintf(rms, sizeof rms, "%.1f", 1e3 * r->rms_m);
        if (r->core_m >= 0.0)
            snprintf(core, sizeof core, "%.1f", 1e3 * r->core_m);
        printf("%-24s %9.1f %8.2f %6.2f %6u %6u %6u %6u | %8.2f %6.2f %6.4f %6.4f %6.4f | "
               "%6s %6s | %7.1f\n",
               r->label, t->map_length_m, t->double_cover_m,
               t->map_length_m > 0.0 ? 100.0 * t->double_cover_m / t->map_length_m : 0.0,
               t->crossings, t->unsupported_20, t->unsupported_10, t->loose_ends, b->band_m,
               b->map_length_m > 0.0 ? 100.0 * b->band_m / b->map_length_m : 0.0,
               gtband_share(b->within_20, b->points), gtband_share(b->within_10, b->points),
               gtband_share(b->within_5, b->points), rms, core, r->ms);
    }
    fflush(stdout);
}

/* ---- single scans of the real logs ---------------------------------------- */

static int single_scans(const options *o, const scene *s)
{
    scanlog log;
    double parse_ms, f_sum = 0.0, ms_sum = 0.0, ms_max = 0.0, cold_sum = 0.0, sum_sq = 0.0;
    double vertices = 0.0;
    uint64_t beams = 0;
    double stage_sum[ST_COUNT] = {0};
    uint64_t hits = 0, crossings = 0, unsupported = 0;
    unsigned k, done = 0, over = 0, crossed = 0;
    char label[160];

    snprintf(label, sizeof label, "%s/%s", s->kind, s->name);
    if (read_log(s->log_path, &log, &parse_ms) != 0) {
        printf("%-24s error: %s\n", label, log.error);
        scanlog_free(&log);
        return -1;
    }
    for (k = 0; k < o->single && k < log.count; k++) {
        /* evenly spread over the log, away from its ends */
        uint32_t idx = (uint32_t)(((uint64_t)2u * k + 1u) * log.count / (2u * o->single));
        const polyc_scan *scan = &log.scans[idx];
        double times[ST_COUNT] = {0}, run_total[MAX_RUNS], run_stage[ST_COUNT][MAX_RUNS];
        double t0 = pipeline_now_ms(), cold = 0.0;
        pipeline p;
        polyc_polyline *lines;
        uint32_t count = 0, i;
        unsigned r;
        gtscore_index map;
        gtscore_scan_score acc;
        /* A robot keeps its block: the scan runs `runs` times on one block,
         * and ms/scan is the median of those runs (init to optimised map).
         * `cold` is the first run with the block's malloc, pages first
         * touched and caches cold, as a one-off call would see it. */
        int bad = open_pipeline(&p, o, scan, 1) != 0;
        for (r = 0; r < o->runs && !bad; r++) {
            bad = pipeline_run(&p, scan, 1, &times[ST_ADD]) != 0;
            run_total[r] = 0.0;
            for (i = ST_ADD; i <= ST_OPT; i++) {
                run_total[r] += times[i];
                run_stage[i][r] = times[i];
            }
            if (r == 0)
                cold = pipeline_now_ms() - t0;
        }
        if (bad || (lines = pipeline_lines(&p, &count)) == NULL) {
            printf("%-24s scan %u: error in %s: %s (%s)\n", label, idx,
                   p.failed_at ? p.failed_at : "pipeline_lines", polyc_status_str(p.status),
                   p.ctx ? polyc_last_error(p.ctx) : "");
            pipeline_close(&p);
            continue;
        }
        double ms = median(run_total, o->runs);
        ms_sum += ms;
        if (ms > ms_max)
            ms_max = ms; /* a robot's worst case: the slowest scan */
        over += ms > SCAN_BUDGET_MS;
        cold_sum += cold; /* a scan that failed counts in neither */
        for (i = ST_GRID; i <= ST_OPT; i++)
            stage_sum[i] += median(run_stage[i], o->runs);
        for (i = 0; i < count; i++)
            vertices += lines[i].point_count;
        gtscore_index_init(&map);
        memset(&acc, 0, sizeof acc);
        if (gtscore_index_add_polylines(&map, lines, count) == 0 &&
            gtscore_index_build(&map, 0.1) == 0)
            gtscore_score_scan(&map, scan, &acc);
        gtscore_index_free(&map);
        {
            double *xy = NULL;
            uint64_t n = 0;
            gttopo_score topo;
            if (gttopo_scan_points(scan, 1, &xy, &n) == 0 &&
                gttopo_score_map(lines, count, xy, n, &topo) == 0) {
                crossings += topo.crossings;
                crossed += topo.crossings > 0;
                unsupported += topo.unsupported_20;
            }
            free(xy);
        }
        f_sum += acc.f;
        beams += scan->beam_count;
        sum_sq += acc.sum_sq_m2;
        hits += acc.hits;
        done++;
        free(lines);
        pipeline_close(&p);
    }
    if (done)
        printf("%-24s %6u %8.4f %9.1f %9.1f %9.1f %9.2f %7.2f %6u %6.2f | %6.2f %7.2f %6.2f %8.2f"
               " | %6llu %6u %6llu\n",
               label, done, f_sum / done, hits ? 1e3 * sqrt(sum_sq / (double)hits) : 0.0,
               vertices / done, beams ? 180.0 * vertices / (double)beams : 0.0, ms_sum / done,
               ms_max, over, cold_sum / done, stage_sum[ST_GRID] / done, stage_sum[ST_CONTOUR] / done,
               stage_sum[ST_TRACE] / done, stage_sum[ST_OPT] / done,
               (unsigned long long)crossings, crossed, (unsigned long long)unsupported);
    fflush(stdout);
    scanlog_free(&log);
    return done ? 0 : -1;
}

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
    if (read_log(s->log_path, &log, &ms) != 0) {
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
    if (read_log(s->log_path, &log, &ms) != 0) {
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
    memset(&g, 0, sizeof g);
    g.width = pgm.width;
    g.height = pgm.height;
    g.resolution_m = (float)y.resolution_m;
    g.origin_x_m = y.origin_x_m;
    g.origin_y_m = y.origin_y_m;
    g.origin_yaw_rad = y.origin_yaw_rad;
    g.cells = cells;
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

static int slurp(const char *path, char **text, size_t *len)
{
    FILE *f = fopen(path, "rb");
    size_t cap = 1u << 16, n = 0;
    char *buf = malloc(cap);
    if (!f || !buf) {
        if (f)
            fclose(f);
        free(buf);
        return -1;
    }
    for (;;) {
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (n < cap)
            break;
        char *b = realloc(buf, 2u * cap);
        if (!b) {
            free(buf);
            fclose(f);
            return -1;
        }
        buf = b;
        cap *= 2u;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        return -1;
    }
    *text = buf;
    *len = n;
    return 0;
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
    if (slurp(yaml_path, &text, &len) != 0 ||
        mapfile_yaml_parse(&y, text, len, yaml_path) != 0)
        goto failed;
    free(text);
    text = NULL;
    if (!(image = mapfile_image_path(yaml_path, y.image)) || slurp(image, &text, &len) != 0 ||
        mapfile_pgm_parse(&pgm, (const uint8_t *)text, len, image) != 0)
        goto failed;
    free(text);
    text = NULL;
    t[1] = pipeline_now_ms();
    if (!(cells = malloc((size_t)pgm.width * pgm.height)))
        goto failed;
    mapfile_to_cells(&pgm, &y, cells);
    polyc_occupancy_grid g;
    memset(&g, 0, sizeof g);
    g.width = pgm.width;
    g.height = pgm.height;
    g.resolution_m = (float)y.resolution_m;
    g.origin_x_m = y.origin_x_m;
    g.origin_y_m = y.origin_y_m;
    g.origin_yaw_rad = y.origin_yaw_rad;
    g.cells = cells;
    t[2] = pipeline_now_ms();
    bench_config(o, &config);
    if (pipeline_run_grid(&p, &config, &g, &lib_ms) != 0 || !(lines = pipeline_lines(&p, &count))) {
        printf("%-18s error in %s: %s (%s)\n", "maze", p.failed_at ? p.failed_at : "pipeline_lines",
               polyc_status_str(p.status), p.ctx ? polyc_last_error(p.ctx) : "");
        goto done;
    }
    t[3] = pipeline_now_ms();
    double out_ms = write_output(&p, lines, count);
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
static int occupancy_section(const options *o, const scene *list, size_t count)
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

/* ---- main ---------------------------------------------------------------- */

static int parse_count(const char *text, long min, long max, long *out)
{
    char *end;
    long v;
    errno = 0;
    v = strtol(text, &end, 10);
    if (errno || end == text || *end || v < min || v > max)
        return -1;
    *out = v;
    return 0;
}

static int parse_options(int argc, char **argv, options *o)
{
    int i;
    long v;
    memset(o, 0, sizeof *o);
    o->runs = 3;
    o->single = 10;
    o->iterations = -1;
    o->gamma = o->grazing = o->data_min = -1.0;
    o->seed = -1;
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            fputs(usage_text, stdout);
            exit(0);
        } else if (strcmp(a, "--runs") == 0 && i + 1 < argc) {
            if (parse_count(argv[++i], 1, MAX_RUNS, &v))
                return -1;
            o->runs = (unsigned)v;
        } else if (strcmp(a, "--single") == 0 && i + 1 < argc) {
            if (parse_count(argv[++i], 0, 100000, &v))
                return -1;
            o->single = (unsigned)v;
        } else if (strcmp(a, "--iterations") == 0 && i + 1 < argc) {
            if (parse_count(argv[++i], 0, 100000000, &v))
                return -1;
            o->iterations = v;
        } else if ((strcmp(a, "--alpha") == 0 || strcmp(a, "--gamma") == 0 ||
                    strcmp(a, "--cell") == 0 || strcmp(a, "--grazing") == 0 ||
                    strcmp(a, "--data-min") == 0) && i + 1 < argc) {
            char *end;
            double d = strtod(argv[++i], &end);
            if (*end || !(d >= 0.0 && d < 1e9))
                return -1;
            if (strcmp(a, "--alpha") == 0) o->alpha = d;
            else if (strcmp(a, "--gamma") == 0) o->gamma = d;
            else if (strcmp(a, "--cell") == 0) o->cell = d;
            else if (strcmp(a, "--grazing") == 0) o->grazing = d;
            else o->data_min = d;
        } else if (strcmp(a, "--seed") == 0 && i + 1 < argc) {
            if (parse_count(argv[++i], 0, 2147483647, &v))
                return -1;
            o->seed = v;
        } else if (strcmp(a, "--occupancy-only") == 0) {
            o->occupancy_only = 1;
        } else if (strcmp(a, "--only") == 0 && i + 1 < argc) {
            o->only = argv[++i];
        } else if (a[0] == '-' || o->data) {
            return -1;
        } else {
            o->data = a;
        }
    }
    return o->data ? 0 : -1;
}

int main(int argc, char **argv)
{
    options o;
    scene *list = NULL;
    topo_row *rows;
    size_t count = 0, cap = 0, i, reals = 0;
    DIR *dir;
    int failed = 0;

    if (parse_options(argc, argv, &o) != 0) {
        fputs(usage_text, stderr);
        return EXIT_USAGE;
    }
    dir = opendir(o.data);
    if (!dir) {
        fprintf(stderr, "bench: data directory %s not found (pass DATA=path)\n", o.data);
        return EXIT_USAGE;
    }
    closedir(dir);
    count = find_scenes(&o, "sim", &list, count, &cap);
    count = find_scenes(&o, "carmen", &list, count, &cap);
    if (count == 0 && !(o.only && strstr(o.only, "maze"))) {
        fprintf(stderr, "bench: no %s*.log under %s/sim or %s/carmen\n",
                o.only ? "selected " : "", o.data, o.data);
        free(list);
        return EXIT_USAGE;
    }
    rows = calloc(count ? count : 1u, sizeof *rows);
    if (!rows) {
        fprintf(stderr, "bench: out of memory\n");
        free(list);
        return EXIT_FAILED;
    }
    if (!o.occupancy_only) {
        print_header(&o);
        for (i = 0; i < count; i++) {
            if (bench_scene(&o, &list[i], &rows[i]) != 0)
                failed = 1;
            reals += strcmp(list[i].kind, "carmen") == 0;
        }
        print_topology(rows, count);
    }
    free(rows);
    if (!o.occupancy_only && o.single > 0 && reals > 0) {
        printf("\nsingle scans: a map from one scan; f = share of reflected beams whose ray "
               "meets the map,\nray RMSE = measured minus map range over those beams "
               "(tools/eval/gtscore.h)\n");
        printf("%-24s %6s %8s %9s %9s %9s %9s %7s %6s %6s | %6s %7s %6s %8s | %6s %6s %6s\n",
               "log", "scans", "mean f", "rayRMSE", "verts", "verts", "ms/scan", "slowest",
               "over", "cold", "grid", "contour", "trace", "optimise", "cross", "maps", "uns20");
        printf("%-24s %6s %8s %9s %9s %9s %9s %7s %6s %6s | %6s %7s %6s %8s | %6s %6s %6s\n",
               "", "", "", "mm", "/scan", "/180 b.", "median", "ms", "2 ms", "ms", "ms", "ms",
               "ms", "ms", "sum", "w/ any", "sum");
        for (i = 0; i < count; i++)
            if (strcmp(list[i].kind, "carmen") == 0 && single_scans(&o, &list[i]) != 0)
                failed = 1;
    }
    if (occupancy_section(&o, list, count) != 0)
        failed = 1;
    printf("\npeak RSS of the process: %.1f MiB\n", peak_rss_mib());
    free(list);
    return failed ? EXIT_FAILED : 0;
}
