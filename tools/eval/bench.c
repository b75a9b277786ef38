/* bench.c - measure libpolyc on the shared data sets (not in the repo).
 *
 *   bench [--runs N] [--only NAMES] [--single K] [--iterations N] DATA_DIR
 *
 * Takes DATA_DIR/sim/NAME.log (+ NAME.gt.txt ground truth) and
 * DATA_DIR/carmen/NAME.log. Prints one table: per scene the input size, the
 * median time of each stage over N runs, memory, and accuracy (scored by
 * tools/eval/gtscore), a second table of topology figures (tools/eval/gttopo), then a
 * single-scan section on the real logs. Logs are read
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

#include "gtscore.h"
#include "gttopo.h"
#include "mapout.h"
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
    "from another part of the map; sim scenes: rms = precision RMS, core = the\n"
    "precision RMS of the samples within 0.5 m of a true wall (mm); ms = the\n"
    "topology scorers' time.\n"
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
    double t0 = pipeline_now_ms(), *xy = NULL;
    uint64_t n = 0;
    row->rms_m = row->core_m = -1.0;
    row->ok = gttopo_scan_points(log->scans, log->count, &xy, &n) == 0 &&
              gttopo_score_map(lines, count, xy, n, &row->score) == 0;
    free(xy);
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
    printf("\ntopology (tools/eval/gttopo.h): the map against its log's scan endpoints; "
           "rms and core (the\nsamples within 0.5 m of a true wall) are precision RMS, "
           "sim scenes only\n");
    printf("%-24s %9s %8s %6s %6s %6s %6s %6s | %6s %6s | %7s\n", "scene", "len", "dcov",
           "dcov%", "cross", "uns20", "uns10", "loose", "rms", "core", "topo");
    printf("%-24s %9s %8s %6s %6s %6s %6s %6s | %6s %6s | %7s\n", "", "m", "m", "", "", "",
           "", "", "mm", "mm", "ms");
    for (i = 0; i < count; i++) {
        const topo_row *r = &rows[i];
        const gttopo_score *t = &r->score;
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
        printf("%-24s %9.1f %8.2f %6.2f %6u %6u %6u %6u | %6s %6s | %7.1f\n", r->label,
               t->map_length_m, t->double_cover_m,
               t->map_length_m > 0.0 ? 100.0 * t->double_cover_m / t->map_length_m : 0.0,
               t->crossings, t->unsupported_20, t->unsupported_10, t->loose_ends, rms, core,
               r->ms);
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
    if (count == 0) {
        fprintf(stderr, "bench: no %s*.log under %s/sim or %s/carmen\n",
                o.only ? "selected " : "", o.data, o.data);
        free(list);
        return EXIT_USAGE;
    }
    rows = calloc(count, sizeof *rows);
    if (!rows) {
        fprintf(stderr, "bench: out of memory\n");
        free(list);
        return EXIT_FAILED;
    }
    print_header(&o);
    for (i = 0; i < count; i++) {
        if (bench_scene(&o, &list[i], &rows[i]) != 0)
            failed = 1;
        reals += strcmp(list[i].kind, "carmen") == 0;
    }
    print_topology(rows, count);
    free(rows);
    if (o.single > 0 && reals > 0) {
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
    printf("\npeak RSS of the process: %.1f MiB\n", peak_rss_mib());
    free(list);
    return failed ? EXIT_FAILED : 0;
}
