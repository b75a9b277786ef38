/* bench.c - measure libpolyc on the shared data sets (not in the repo).
 *
 *   bench [--runs N] [--only NAMES] [--single K] [--iterations N] [--occupancy-only]
 *         [--no-online | --online-only] DATA_DIR
 *
 * Takes DATA_DIR/sim/NAME.log (+ NAME.gt.txt ground truth) and
 * DATA_DIR/carmen/NAME.log. Prints one table: per scene the input size, the
 * median time of each stage over N runs, memory, and accuracy (scored by
 * tools/eval/gtscore), a second table of topology figures (tools/eval/gttopo), then a
 * single-scan section on the real logs, then the occupancy-map section (the
 * library and a findContours-style baseline on grids, and a speed row on a
 * 2,000 x 2,000-cell map file), then the online section (each log replayed
 * scan by scan through the online API, beside its batch build). Logs are read
 * with tools/scanlog, the same reader as the CLI. Exit codes: 0 ok, 1 some
 * scene failed, 2 usage or no data directory.
 *
 * This file: the options, the scenes, the helpers the sections share and
 * main. The sections: bench_table.c (the first two tables), bench_single.c
 * (single scans), bench_occupancy.c (occupancy maps), bench_online.c (the
 * online API); bench.h joins them.
 */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "bench.h"
#include "mapout.h"

static const char usage_text[] =
    "usage: bench [options] DATA_DIR\n"
    "Measures libpolyc on DATA_DIR/sim/*.log (simulated logs in ROBOTLASER1 lines,\n"
    "each scored against its ground truth NAME.gt.txt, docs/evaluation.md) and\n"
    "DATA_DIR/carmen/*.log (real CARMEN FLASER logs: the Radish data set's intel,\n"
    "aces, csail, fhw, ... as GMapping corrected their poses; scored against\n"
    "their own scan endpoints). Neither is in the repository. `make bench\n"
    "DATA=dir` builds it with -O3 and runs it.\n"
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
    "  --no-online      no online section\n"
    "  --online-only    only the online section (its batch builds: one run each)\n"
    "  --rows-log NAME  the real log of the online memory and pose-correction\n"
    "                   rows (default intel; with --only, it must be among them)\n"
    "  --drift R,X,Y    the pose-correction row's drift at the last scan: a turn\n"
    "                   of R rad about the first pose and a shift of (X, Y) m\n"
    "                   (default 0.02,0.30,-0.20)\n"
    "  --maps DIR       write each scene's finished online map to DIR (which must\n"
    "                   exist) as NAME.online.txt, `/` as `-` (carmen-intel...)\n"
    "  -h, --help       this text\n";
static const char usage_columns[] =
    "Columns: stage times in ms (parse = reading the log, add = polyc_add_scan,\n"
    "grid, contour, trace, optimise, output = JSON to /dev/null); block and used\n"
    "= the context's memory block and its high-water mark; rss = peak resident\n"
    "size of the process so far. Accuracy (docs/evaluation.md): sim scenes\n"
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
    "runs unless --only leaves out `maze`.\n";
/* (two strings: C99 compilers need only take 4,095 characters in one) */
static const char usage_online[] =
    "Online (last section, docs/evaluation.md): each scene replayed scan by scan,\n"
    "polyc_online_add_scan then polyc_online_update at the default work budget:\n"
    "add = one add, a+u = one add and its update (median, p99, max, ms); total =\n"
    "all adds, updates and polyc_online_finish (ms); xbatch = total / the batch\n"
    "build's library time (add to optimise, the main table's median); finish =\n"
    "polyc_online_finish (ms); backlog = the most tiles an update left; checkpoints\n"
    "every 100 scans (at most 10 a log, evenly spread): the online map's\n"
    "crossings and double cover (worst), its BIC against a batch build of the\n"
    "scans so far (worst ratio, and at which scan). Then the final online map\n"
    "beside the batch map (lines, verts, BIC, band15, cross, dcov, uns20, end20;\n"
    "sims: core, compl), intel's block and 10 passes in the block of one, and\n"
    "intel's scans with a pose drift corrected by polyc_online_correct (another\n"
    "real log with --rows-log).\n"
    "Exit: 0 ok; 1 a scene failed (its row says why); 2 usage error, or\n"
    "DATA_DIR missing: 'bench: data directory DIR not found (pass DATA=path)'.\n";

/* ST_ADD..ST_OPT in the order of pipeline.h's stages: pipeline_run fills them */

/* ---- small helpers -------------------------------------------------------- */


double bench_median(const double *v, unsigned n)
{
    double tmp[MAX_RUNS];
    memcpy(tmp, v, n * sizeof *v);
    qsort(tmp, n, sizeof *tmp, pipeline_compare_double);
    return n % 2u ? tmp[n / 2u] : 0.5 * (tmp[n / 2u - 1u] + tmp[n / 2u]);
}

double bench_peak_rss_mib(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0)
        return 0.0;
    return (double)ru.ru_maxrss / 1024.0; /* Linux: kilobytes */
}

double bench_mib(uint64_t bytes)
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

int bench_read_log(const char *path, scanlog *log, double *ms)
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
void bench_config(const options *o, polyc_config *c)
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

int bench_open_pipeline(pipeline *p, const options *o, const polyc_scan *scans, uint32_t n)
{
    polyc_config config;
    bench_config(o, &config);
    return pipeline_open(p, &config, scans, n);
}

double bench_write_output(const pipeline *p, const polyc_polyline *lines, uint32_t count)
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
    o->online = 1;
    o->rows_log = "intel";
    o->drift[0] = 0.02;
    o->drift[1] = 0.30;
    o->drift[2] = -0.20;
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            fputs(usage_text, stdout);
            fputs(usage_columns, stdout);
            fputs(usage_online, stdout);
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
        } else if (strcmp(a, "--no-online") == 0) {
            o->online = 0;
        } else if (strcmp(a, "--online-only") == 0) {
            o->online_only = 1;
        } else if (strcmp(a, "--rows-log") == 0 && i + 1 < argc) {
            o->rows_log = argv[++i];
        } else if (strcmp(a, "--maps") == 0 && i + 1 < argc) {
            o->maps_dir = argv[++i];
        } else if (strcmp(a, "--drift") == 0 && i + 1 < argc) {
            char tail;
            if (sscanf(argv[++i], "%lf,%lf,%lf%c", &o->drift[0], &o->drift[1], &o->drift[2],
                       &tail) != 3 ||
                !(fabs(o->drift[0]) <= 1.0 && fabs(o->drift[1]) <= 10.0 && fabs(o->drift[2]) <= 10.0))
                return -1;
        } else if (strcmp(a, "--only") == 0 && i + 1 < argc) {
            o->only = argv[++i];
        } else if (a[0] == '-' || o->data) {
            return -1;
        } else {
            o->data = a;
        }
    }
    if (o->online_only && (o->occupancy_only || !o->online))
        return -1; /* --online-only with --occupancy-only or --no-online */
    return o->data ? 0 : -1;
}


int main(int argc, char **argv)
{
    options o;
    scene *list = NULL;
    size_t count = 0, cap = 0;
    bench_figures *batch;
    DIR *dir;
    int failed = 0;

    if (parse_options(argc, argv, &o) != 0) {
        fputs(usage_text, stderr);
        fputs(usage_columns, stderr);
        fputs(usage_online, stderr);
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
    /* the main table's batch figures, for the online section */
    batch = calloc(count ? count : 1u, sizeof *batch);
    if (!batch) {
        fprintf(stderr, "bench: out of memory\n");
        free(list);
        return EXIT_FAILED;
    }
    if (!o.occupancy_only && !o.online_only &&
        bench_table_section(&o, list, count, batch) != 0)
        failed = 1;
    if (!o.occupancy_only && !o.online_only && o.single > 0 &&
        bench_single_section(&o, list, count) != 0)
        failed = 1;
    if (!o.online_only && bench_occupancy_section(&o, list, count) != 0)
        failed = 1;
    if (!o.occupancy_only && o.online && bench_online_section(&o, list, count, batch) != 0)
        failed = 1;
    free(batch);
    printf("\npeak RSS of the process: %.1f MiB\n", bench_peak_rss_mib());
    free(list);
    return failed ? EXIT_FAILED : 0;
}
