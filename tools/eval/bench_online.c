/* bench_online.c - the bench's online section (bench.h).
 * Takes: the scenes and the main table's batch figures. Gives: per scene
 * the log replayed scan by scan through the online API (add, update at the
 * default work budget, finish) with its times, its map at checkpoints
 * against batch builds of the scans so far, and its final map beside the
 * batch map; then intel's block and ten passes of intel in it, and intel
 * with a pose drift that polyc_online_correct takes back. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "fairbic.h"
#include "gtscore.h"
#include "mapout.h"

#define CHECK_EVERY 100u  /* a checkpoint every 100 scans... */
#define CHECK_MAX 10u     /* ...at most 10 a log, evenly spread over those */
#define AREA_MARGIN_M PIPELINE_ONLINE_MARGIN_M /* the area's half-side: the
                             farthest pose or endpoint from the first pose,
                             plus this */
#define LIMIT_TRIES 3u    /* out of grid cells, vertices or data cells: again
                             with twice the limits, up to this many times in all */
#define PASSES 10u        /* the memory row: intel this many times over */
#define SETTLE_MAX 200u   /* the correction row: updates to re-converge, at most */

/* ---- a scene's data ------------------------------------------------------ */

typedef struct scene_data {
    scanlog log;
    double *xy, *from;         /* reflected endpoints and their sensors (gtband) */
    uint64_t points;
    gtscore_truth truth;
    int has_truth;
    uint32_t max_beams;        /* the most beams of one scan */
} scene_data;

static void scene_data_free(scene_data *d)
{
    scanlog_free(&d->log);
    free(d->xy);
    free(d->from);
    if (d->has_truth)
        gtscore_truth_free(&d->truth);
    memset(d, 0, sizeof *d);
}

/* The log, its endpoints and (sims) its truth; -1 with a message. */
static int scene_data_load(const scene *s, scene_data *d, const char *label)
{
    double ms;
    uint32_t i;
    memset(d, 0, sizeof *d);
    if (bench_read_log(s->log_path, &d->log, &ms) != 0) {
        printf("%-24s error: %s\n", label, d->log.error);
        scene_data_free(d);
        return -1;
    }
    for (i = 0; i < d->log.count; i++)
        if (d->log.scans[i].beam_count > d->max_beams)
            d->max_beams = d->log.scans[i].beam_count;
    if (gtband_scan_points(d->log.scans, d->log.count, &d->xy, &d->from, &d->points) != 0) {
        printf("%-24s error: out of memory for the endpoints\n", label);
        scene_data_free(d);
        return -1;
    }
    if (s->gt_path[0]) {
        char err[512] = "";
        if (gtscore_truth_load(&d->truth, s->gt_path, err, sizeof err) == 0)
            d->has_truth = 1;
        else {
            fprintf(stderr, "bench: %s: no score: %s\n", s->name, err);
            gtscore_truth_free(&d->truth);
        }
    }
    return 0;
}

/* Side of the square centred on the first pose that holds every pose and
 * endpoint of scans by the library's extent rule (polyc_scan_extent), with
 * AREA_MARGIN_M to spare: pipeline_run_online's area (the sweep's). */
static double area_for(const polyc_config *config, const polyc_scan *scans, uint32_t n,
                       double x0, double y0)
{
    polyc_box box = {HUGE_VAL, HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    uint32_t i;
    for (i = 0; i < n; i++)
        polyc_scan_extent(config, &scans[i], &box);
    return 2.0 * (fmax(fmax(x0 - box.min_x_m, box.max_x_m - x0),
                       fmax(y0 - box.min_y_m, box.max_y_m - y0)) + AREA_MARGIN_M);
}

/* ---- a map's figures ----------------------------------------------------- */

/* The current map's polylines (malloc'ed records pointing into the
 * context: valid until it changes); NULL when out of memory. */
static polyc_polyline *map_lines(const polyc_ctx *ctx, uint32_t *count)
{
    uint32_t i, n = polyc_polyline_count(ctx);
    polyc_polyline *lines = calloc(n ? n : 1u, sizeof *lines);
    *count = 0;
    if (!lines)
        return NULL;
    for (i = 0; i < n; i++)
        if (polyc_get_polyline(ctx, i, &lines[i]) != POLYC_OK) {
            free(lines);
            return NULL;
        }
    *count = n;
    return lines;
}

/* With --maps DIR: ctx's map as DIR/LABEL.online.txt (polyc's text
 * format, `/` in the label as `-`), to look at or score again
 * (build-bench/mapscore LOG MAP.txt). A map the tool's `polyc --online`
 * gives differs: the tool sizes its area from the log another way. */
static void save_map(const options *o, const polyc_ctx *ctx, const char *label)
{
    char path[1200], name[160];
    uint32_t count, k;
    polyc_polyline *lines;
    mapout_map map;
    FILE *f;
    if (!o->maps_dir)
        return;
    snprintf(name, sizeof name, "%s", label);
    for (k = 0; name[k]; k++)
        if (name[k] == '/')
            name[k] = '-';
    snprintf(path, sizeof path, "%s/%s.online.txt", o->maps_dir, name);
    if ((lines = map_lines(ctx, &count)) == NULL || (f = fopen(path, "w")) == NULL) {
        printf("%-24s --maps: cannot write %s\n", label, path);
        free(lines);
        return;
    }
    memset(&map, 0, sizeof map);
    map.lines = lines;
    map.line_count = count;
    int bad = mapout_txt(f, &map) != 0;
    if (fclose(f) != 0 || bad) /* (closed either way) */
        printf("%-24s --maps: error writing %s\n", label, path);
    free(lines);
}

/* The figures of ctx's map against d's endpoints (and truth); the times
 * are the caller's. */
static void score_map(const scene_data *d, const polyc_ctx *ctx, bench_figures *f)
{
    polyc_stats stats;
    polyc_polyline *lines;
    uint32_t count, i;
    double lib_ms = f->lib_ms;
    memset(f, 0, sizeof *f);
    f->lib_ms = lib_ms;
    f->core_m = f->completeness = -1.0;
    if (polyc_get_stats(ctx, &stats) != POLYC_OK || (lines = map_lines(ctx, &count)) == NULL)
        return;
    f->block_bytes = stats.memory_size_bytes;
    f->bic = stats.bic;
    f->lines = count;
    for (i = 0; i < count; i++)
        f->vertices += lines[i].point_count;
    f->ok = gttopo_score_map(lines, count, d->xy, d->points, &f->topo) == 0 &&
            gtband_score_map(lines, count, d->xy, d->from, d->points, &f->band) == 0;
    if (f->ok && d->has_truth) {
        gtscore_map_score sc;
        if (gtscore_score_map(&d->truth, lines, count, &sc) == 0)
            f->completeness = sc.completeness;
        if (gtscore_core_precision(&d->truth, lines, count, CORE_M, &f->core_m) != 0)
            f->core_m = -1.0;
    }
    free(lines);
}

/* Another map (an online one) to score on a batch build's data. */
typedef struct other_map {
    const polyc_polyline *lines;
    uint32_t count;
    double bic;                /* out: its BIC on the batch's data */
} other_map;

/* The batch build of scans[0..n) (one run, tools/eval/pipeline.h): its
 * BIC, with d its figures into *f, and with other that map's BIC on the
 * same data; -1 with a message if it failed. */
static int batch_build(const options *o, const scene_data *d, const polyc_scan *scans,
                       uint32_t n, double *bic, bench_figures *f, other_map *other,
                       const char *label)
{
    pipeline p;
    double times[PIPELINE_STAGES] = {0};
    polyc_stats stats;
    int k, rc = -1;
    if (bench_open_pipeline(&p, o, scans, n) == 0 && pipeline_run(&p, scans, n, times) == 0 &&
        polyc_get_stats(p.ctx, &stats) == POLYC_OK) {
        *bic = stats.bic;
        if (f) {
            for (f->lib_ms = 0.0, k = 0; k < PIPELINE_STAGES; k++)
                f->lib_ms += times[k];
            score_map(d, p.ctx, f);
        }
        rc = 0;
        /* last: it replaces the context's map */
        polyc_status st = other ? fairbic_score(p.ctx, other->lines, other->count, &other->bic)
                                : POLYC_OK;
        if (st != POLYC_OK) {
            printf("%-24s batch of %u scans: the other map not scored: %s\n", label, n,
                   polyc_status_str(st));
            rc = -1;
        }
    } else
        printf("%-24s batch of %u scans: error in %s: %s (%s)\n", label, n,
               p.failed_at ? p.failed_at : "polyc_get_stats", polyc_status_str(p.status),
               p.ctx ? polyc_last_error(p.ctx) : "");
    pipeline_close(&p);
    return rc;
}

/* ---- an online context ---------------------------------------------------- */

typedef struct online {
    polyc_online_limits limits;
    void *block;
    size_t block_size;
    polyc_ctx *ctx;
    const char *failed_at;     /* the call that failed, NULL if none */
    polyc_status status;
    uint32_t failed_scan;      /* the scan it failed on */
    char error[160];           /* polyc_last_error then */
} online;

static int online_fail(online *on, polyc_status st, const char *what, uint32_t scan)
{
    if (st == POLYC_OK)
        return 0;
    if (!on->failed_at) {
        on->status = st;
        on->failed_at = what;
        on->failed_scan = scan;
        snprintf(on->error, sizeof on->error, "%s", on->ctx ? polyc_last_error(on->ctx) : "");
    }
    return -1;
}

static void online_close(online *on)
{
    free(on->block);
    on->block = NULL;
    on->ctx = NULL;
}

/* A context for these limits on a malloc'ed block of
 * polyc_online_memory_size; 0, or -1 with failed_at. */
static int online_open(online *on, const polyc_config *config)
{
    on->ctx = NULL;
    on->failed_at = NULL;
    on->status = POLYC_OK;
    on->error[0] = '\0';
    on->block_size = polyc_online_memory_size(config, &on->limits);
    if (on->block_size == 0)
        return online_fail(on, POLYC_ERR_CONFIG, "polyc_online_memory_size", 0);
    on->block = malloc(on->block_size);
    if (!on->block)
        return online_fail(on, POLYC_ERR_NOMEM, "malloc of the block", 0);
    return online_fail(on, polyc_online_init(on->block, on->block_size, config, &on->limits,
                                             &on->ctx),
                       "polyc_online_init", 0);
}

/* The limits for scans[0..n) (and, when other is not NULL, other[0..n)
 * too: the same scans at other poses), keeping them all if keep. */
static polyc_status limits_for(const polyc_config *config, const scene_data *d,
                               const polyc_scan *other, int keep, polyc_online_limits *out)
{
    const polyc_scan *scans = d->log.scans;
    uint32_t n = d->log.count;
    double area = area_for(config, scans, n, scans[0].pose_x_m, scans[0].pose_y_m);
    polyc_status st;
    if (other)
        area = fmax(area, area_for(config, other, n, scans[0].pose_x_m, scans[0].pose_y_m));
    st = polyc_online_limits_for_area(config, area, d->max_beams, out);
    if (st == POLYC_OK && keep) {
        out->keep_scans = n;
        out->keep_beams = (uint32_t)d->log.beams;
    }
    return st;
}

/* ---- a replay ------------------------------------------------------------- */

typedef struct replay {
    uint32_t scans;            /* scans added */
    double *add_ms, *step_ms;  /* per scan: the add, the add and its update */
    double total_ms;           /* adds, updates and finish */
    double finish_ms;
    uint32_t backlog_max;      /* the most tiles an update left */
    unsigned tries;            /* limits doubled tries - 1 times */
    /* checkpoints (the scene rows) */
    uint32_t checks;
    double worst_ratio;        /* online BIC / batch BIC, the largest */
    uint32_t worst_at;         /* at this many scans */
    uint32_t cross_max;
    double dcov_max_m;
} replay;

/* Is scan count k (1-based) a checkpoint of a log of n scans? Every
 * CHECK_EVERY scans, or CHECK_MAX of those evenly spread when there are
 * more. */
static int is_checkpoint(uint32_t k, uint32_t n)
{
    uint32_t m = n / CHECK_EVERY, j;
    if (k % CHECK_EVERY != 0 || k == 0)
        return 0;
    if (m <= CHECK_MAX)
        return 1;
    for (j = 1; j <= CHECK_MAX; j++)
        if ((uint32_t)(((uint64_t)j * m + CHECK_MAX - 1u) / CHECK_MAX) * CHECK_EVERY == k)
            return 1;
    return 0;
}

/* The checkpoint at k scans: the online map's crossings and double cover
 * (against no data: those two need none), and its BIC against a batch
 * build of the same k scans, both on that build's data (fairbic.h). */
static void checkpoint(const options *o, const polyc_ctx *ctx, const polyc_scan *scans,
                       uint32_t k, replay *r, const char *label)
{
    uint32_t count;
    polyc_polyline *lines = map_lines(ctx, &count);
    gttopo_score t;
    double bic;
    other_map now = {lines, count, 0.0};
    if (!lines)
        return;
    if (gttopo_score_map(lines, count, NULL, 0, &t) == 0) {
        if (t.crossings > r->cross_max)
            r->cross_max = t.crossings;
        r->dcov_max_m = fmax(r->dcov_max_m, t.double_cover_m);
    }
    if (batch_build(o, NULL, scans, k, &bic, NULL, &now, label) == 0 && bic > 0.0) {
        r->checks++;
        if (now.bic / bic > r->worst_ratio) {
            r->worst_ratio = now.bic / bic;
            r->worst_at = k;
        }
    }
    free(lines);
}

/* scans[0..n) `passes` times over into on's context (opened here on
 * on->limits), an update after each add, then polyc_online_finish (with
 * finish). keep: keep the scans, their ids into ids[]. With checks, the
 * checkpoints of the first pass. 0, or
 * -1 with on->failed_at; the context stays open either way (online_close). */
static int replay_run(const options *o, online *on, const polyc_scan *scans, uint32_t n,
                      unsigned passes, int keep, uint32_t *ids, int checks, int finish,
                      replay *r, const char *label)
{
    polyc_config config;
    polyc_online_report rep;
    unsigned pass;
    uint32_t i;
    bench_config(o, &config);
    if (online_open(on, &config) != 0)
        return -1;
    for (pass = 0; pass < passes; pass++)
        for (i = 0; i < n; i++) {
            uint32_t id = 0;
            double t0 = pipeline_now_ms(), t1, t2;
            if (online_fail(on, polyc_online_add_scan(on->ctx, &scans[i], keep, &id),
                            "polyc_online_add_scan", r->scans))
                return -1;
            t1 = pipeline_now_ms();
            if (online_fail(on, polyc_online_update(on->ctx, POLYC_ONLINE_WORK_DEFAULT, &rep),
                            "polyc_online_update", r->scans))
                return -1;
            t2 = pipeline_now_ms();
            if (r->add_ms && pass == 0) {
                r->add_ms[i] = t1 - t0;
                r->step_ms[i] = t2 - t0;
            }
            if (ids && pass == 0)
                ids[i] = id;
            r->total_ms += t2 - t0;
            if (rep.backlog_tiles > r->backlog_max)
                r->backlog_max = rep.backlog_tiles;
            r->scans++;
            if (checks && pass == 0 && is_checkpoint(i + 1u, n))
                checkpoint(o, on->ctx, scans, i + 1u, r, label);
        }
    if (finish) {
        double t0 = pipeline_now_ms();
        if (online_fail(on, polyc_online_finish(on->ctx, NULL, NULL, &rep),
                        "polyc_online_finish", r->scans))
            return -1;
        r->finish_ms = pipeline_now_ms() - t0;
        r->total_ms += r->finish_ms;
    }
    return 0;
}

/* 2 x, at most cap */
static uint32_t twice(uint32_t a, double cap)
{
    return (uint32_t)fmin(2.0 * (double)a, cap);
}

/* replay_run, again with twice the grid cells (at most the square's),
 * vertices and data cells while it runs out of them (POLYC_ERR_NOMEM), as
 * pipeline_run_online does, LIMIT_TRIES times in all; r->tries says how
 * many runs it took. */
static int replay_grow(const options *o, online *on, const polyc_scan *scans, uint32_t n,
                       int checks, replay *r, const char *label)
{
    double *add_ms = r->add_ms, *step_ms = r->step_ms;
    polyc_config config;
    double tiles;
    unsigned tries = 0;
    int rc;
    for (;;) {
        memset(r, 0, sizeof *r);
        r->add_ms = add_ms;
        r->step_ms = step_ms;
        r->tries = ++tries;
        rc = replay_run(o, on, scans, n, 1, 0, NULL, checks, 1, r, label);
        if (rc == 0 || on->status != POLYC_ERR_NOMEM || tries >= LIMIT_TRIES)
            return rc;
        online_close(on);
        bench_config(o, &config);
        tiles = ceil(on->limits.area_m / (double)config.cell_m / 32.0);
        on->limits.max_grid_cells =
            twice(on->limits.max_grid_cells, fmin(tiles * tiles * 1024.0, 0x40000000));
        on->limits.max_vertices = twice(on->limits.max_vertices, 0x10000000);
        on->limits.max_points = twice(on->limits.max_points, 0x10000000);
    }
}

/* ---- the tables ----------------------------------------------------------- */

static int compare_double(const void *a, const void *b)
{
    return pipeline_compare_double(a, b);
}

/* The q-quantile (nearest rank) of v[0..n), sorted here. */
static double quantile(double *v, uint32_t n, double q)
{
    uint32_t rank;
    if (n == 0)
        return 0.0;
    qsort(v, n, sizeof *v, compare_double);
    rank = (uint32_t)ceil(q * (double)n);
    return v[rank ? rank - 1u : 0u];
}

static double median(double *v, uint32_t n)
{
    if (n == 0)
        return 0.0;
    qsort(v, n, sizeof *v, compare_double);
    return n % 2u ? v[n / 2u] : 0.5 * (v[n / 2u - 1u] + v[n / 2u]);
}

/* The 1-minute load average (Linux, /proc/loadavg), < 0 if unknown: the
 * times are wall-clock, and other jobs on the machine lengthen them. */
static double load_average(void)
{
    FILE *f = fopen("/proc/loadavg", "r");
    double load = -1.0;
    if (f) {
        if (fscanf(f, "%lf", &load) != 1)
            load = -1.0;
        fclose(f);
    }
    return load;
}

static void print_replay_header(const options *o, int batch_from_table)
{
    double load = load_average();
    printf("\nonline (polyc_online_*): each log replayed scan by scan, polyc_online_add_scan "
           "then\npolyc_online_update(POLYC_ONLINE_WORK_DEFAULT = %u) after each; area = "
           "the square (centred on\nthe first pose) holding every pose and endpoint with "
           "%.0f m to spare, limits from\npolyc_online_limits_for_area (x2, x4: doubled "
           "cells, vertices and points after running out).\nadd = one add, a+u = one add and its "
           "update; total = all adds, updates and polyc_online_finish;\nxbatch = total / "
           "the batch build's library time (add to optimise, %s);\ncheckpoints every %u "
           "scans, at most %u a log (evenly spread over the multiples of %u):\nthe online "
           "map's BIC / a batch build's of the scans so far (worst, at which scan), its\n"
           "crossings and double cover (worst)\n",
           (unsigned)POLYC_ONLINE_WORK_DEFAULT, AREA_MARGIN_M,
           batch_from_table ? "the main table's median" : "one run", CHECK_EVERY, CHECK_MAX,
           CHECK_EVERY);
    if (load >= 0.0)
        printf("(wall-clock times; the machine's load average at the start: %.2f)\n", load);
    (void)o;
    printf("%-24s %6s %6s %8s | %6s %6s %6s %7s | %8s %6s %7s %7s | %5s %7s %6s %6s %6s\n",
           "scene", "scans", "area", "blockMiB", "add", "a+u", "a+u", "a+u", "total", "xbatch",
           "finish", "backlog", "ckpts", "BIC/b", "@scan", "cross", "dcov");
    printf("%-24s %6s %6s %8s | %6s %6s %6s %7s | %8s %6s %7s %7s | %5s %7s %6s %6s %6s\n", "",
           "", "m", "", "median", "median", "p99", "max", "ms", "", "ms", "tiles", "", "worst",
           "", "max", "max m");
}

static void print_figures_header(void)
{
    printf("%-24s %-9s | %6s %7s %10s %10s %6s | %8s %6s %6s %8s %6s %6s | %6s %6s\n", "scene",
           "map", "lines", "verts", "BIC", "BIC@batch", "/batch", "band15", "band%", "cross", "dcov", "uns20", "end20", "core",
           "compl");
    printf("%-24s %-9s | %6s %7s %10s %10s %6s | %8s %6s %6s %8s %6s %6s | %6s %6s\n", "", "",
           "", "", "", "", "", "m", "", "", "m", "", "", "mm", "");
}

/* batch: the batch map's figures, for the online map's BIC ratio (NULL for
 * the batch row itself) */
static void print_figures(const char *label, const char *map, const bench_figures *f,
                          const bench_figures *batch)
{
    char core[16] = "-", compl[16] = "-", fair[16] = "-", ratio[16] = "-";
    if (!f->ok) {
        printf("%-24s %-9s | %6s\n", label, map, "-");
        return;
    }
    if (f->core_m >= 0.0)
        snprintf(core, sizeof core, "%.1f", 1e3 * f->core_m);
    if (f->completeness >= 0.0)
        snprintf(compl, sizeof compl, "%.4f", f->completeness);
    if (batch && f->bic_on_batch > 0.0) {
        snprintf(fair, sizeof fair, "%.1f", f->bic_on_batch);
        if (batch->ok && batch->bic > 0.0)
            snprintf(ratio, sizeof ratio, "%.4f", f->bic_on_batch / batch->bic);
    }
    printf("%-24s %-9s | %6u %7u %10.1f %10s %6s | %8.2f %6.2f %6u %8.2f %6u %6.4f | %6s %6s\n", label,
           map, f->lines, f->vertices, f->bic, fair, ratio, f->band.band_m,
           f->band.map_length_m > 0.0 ? 100.0 * f->band.band_m / f->band.map_length_m : 0.0,
           f->topo.crossings, f->topo.double_cover_m, f->topo.unsupported_20,
           gtband_share(f->band.within_20, f->band.points), core, compl);
}

static void print_failure(const char *label, const online *on)
{
    printf("%-24s error in %s at scan %u: %s (%s)\n", label, on->failed_at, on->failed_scan,
           polyc_status_str(on->status), on->error);
}

/* ---- one scene ------------------------------------------------------------ */

typedef struct scene_result {
    char label[160];
    int ok;
    bench_figures online, batch;
} scene_result;

/* The online map's BIC on the data of a batch build of the same scans
 * (one more batch build: the table's keeps no context). */
static void fair_score(const options *o, const scene_data *d, const polyc_ctx *ctx,
                       bench_figures *f, const char *label)
{
    uint32_t count;
    double bic;
    polyc_polyline *lines = map_lines(ctx, &count);
    other_map now = {lines, count, 0.0};
    if (lines && batch_build(o, NULL, d->log.scans, d->log.count, &bic, NULL, &now, label) == 0)
        f->bic_on_batch = now.bic;
    free(lines);
}

static int online_scene(const options *o, const scene *s, const bench_figures *table_batch,
                        scene_result *res)
{
    scene_data d;
    online on;
    replay r;
    polyc_config config;
    polyc_status st;
    uint32_t n;
    char tries[16] = "";
    double bic;
    int rc = -1;

    memset(&on, 0, sizeof on);
    memset(&r, 0, sizeof r);
    snprintf(res->label, sizeof res->label, "%s/%s", s->kind, s->name);
    if (scene_data_load(s, &d, res->label) != 0)
        return -1;
    n = d.log.count;
    if (n == 0) {
        printf("%-24s error: no scans\n", res->label);
        scene_data_free(&d);
        return -1;
    }
    /* the batch map: the main table's, or built here (one run) */
    if (table_batch && table_batch->ok)
        res->batch = *table_batch;
    else if (batch_build(o, &d, d.log.scans, n, &bic, &res->batch, NULL, res->label) != 0)
        memset(&res->batch, 0, sizeof res->batch);
    bench_config(o, &config);
    if ((st = limits_for(&config, &d, NULL, 0, &on.limits)) != POLYC_OK) {
        printf("%-24s error in polyc_online_limits_for_area: %s\n", res->label,
               polyc_status_str(st));
        scene_data_free(&d);
        return -1;
    }
    r.add_ms = malloc(n * sizeof *r.add_ms);
    r.step_ms = malloc(n * sizeof *r.step_ms);
    if (!r.add_ms || !r.step_ms) {
        printf("%-24s error: out of memory\n", res->label);
    } else if (replay_grow(o, &on, d.log.scans, n, 1, &r, res->label) != 0) {
        print_failure(res->label, &on);
    } else {
        double add_med = median(r.add_ms, n), step_med = median(r.step_ms, n);
        double step_p99 = quantile(r.step_ms, n, 0.99), step_max = r.step_ms[n - 1u];
        char ratio[16] = "-", worst[16] = "-", at[16] = "-";
        if (res->batch.ok && res->batch.lib_ms > 0.0)
            snprintf(ratio, sizeof ratio, "%.2f", r.total_ms / res->batch.lib_ms);
        if (r.checks) {
            snprintf(worst, sizeof worst, "%.4f", r.worst_ratio);
            snprintf(at, sizeof at, "%u", r.worst_at);
        }
        if (r.tries > 1u)
            snprintf(tries, sizeof tries, " x%u", 1u << (r.tries - 1u));
        printf("%-24s %6u %6.0f %8.2f | %6.3f %6.3f %6.2f %7.2f | %8.1f %6s %7.1f %7u | %5u "
               "%7s %6s %6u %6.2f%s\n",
               res->label, n, on.limits.area_m, bench_mib(on.block_size), add_med, step_med,
               step_p99, step_max, r.total_ms, ratio, r.finish_ms, r.backlog_max, r.checks,
               worst, at, r.cross_max, r.dcov_max_m, tries);
        res->online.lib_ms = r.total_ms;
        save_map(o, on.ctx, res->label);
        score_map(&d, on.ctx, &res->online);
        fair_score(o, &d, on.ctx, &res->online, res->label);
        res->ok = 1;
        rc = 0;
    }
    fflush(stdout);
    online_close(&on);
    free(r.add_ms);
    free(r.step_ms);
    scene_data_free(&d);
    return rc;
}

/* ---- one real log (intel, --rows-log): memory and pose corrections ---------- */

/* The memory row: intel's online block against its batch block, then intel
 * PASSES times over in the block of one pass. */
static int memory_row(const options *o, const scene *s, const scene_result *one)
{
    scene_data d;
    online on;
    replay r;
    polyc_config config;
    polyc_stats stats;
    bench_figures f;
    char status[64], batch_mib[16] = "-", used_mib[16] = "-";
    int rc;

    memset(&on, 0, sizeof on);
    memset(&r, 0, sizeof r);
    memset(&f, 0, sizeof f);
    if (scene_data_load(s, &d, one->label) != 0)
        return -1;
    bench_config(o, &config);
    if (limits_for(&config, &d, NULL, 0, &on.limits) != POLYC_OK) {
        scene_data_free(&d);
        return -1;
    }
    printf("\nonline memory: %s's online block (its area, no scans kept) against its batch "
           "block;\n%s replayed %u times over (the same scans and poses, an update after "
           "each add) in\nthe block of one pass, then polyc_online_finish; status = the "
           "first failure, or ok\n", s->name, s->name, PASSES);
    printf("%-24s %6s %9s %9s | %6s %6s %-14s %8s %8s %9s\n", "scene", "area", "onlineMiB",
           "batchMiB", "passes", "scans", "status", "usedMiB", "total", "finish");
    printf("%-24s %6s %9s %9s | %6s %6s %-14s %8s %8s %9s\n", "", "m", "", "", "", "", "", "",
           "ms", "ms");
    rc = replay_run(o, &on, d.log.scans, d.log.count, PASSES, 0, NULL, 0, 0, &r,
                    one->label);
    if (on.ctx) {
        /* finish what was added, whether all of it fitted or not */
        polyc_online_report rep;
        double t0 = pipeline_now_ms();
        polyc_status st = polyc_online_finish(on.ctx, NULL, NULL, &rep);
        r.finish_ms = pipeline_now_ms() - t0;
        r.total_ms += r.finish_ms;
        if (online_fail(&on, st, "polyc_online_finish", r.scans) == 0) {
            score_map(&d, on.ctx, &f);
            fair_score(o, &d, on.ctx, &f, one->label);
        } else
            rc = -1;
    }
    if (on.failed_at)
        snprintf(status, sizeof status, "%s", polyc_status_str(on.status));
    else
        snprintf(status, sizeof status, "ok");
    memset(&stats, 0, sizeof stats);
    if (on.ctx)
        polyc_get_stats(on.ctx, &stats);
    if (one->batch.ok)
        snprintf(batch_mib, sizeof batch_mib, "%.2f", bench_mib(one->batch.block_bytes));
    if (stats.memory_used_bytes > 0u) /* (0: the context does not say) */
        snprintf(used_mib, sizeof used_mib, "%.2f", bench_mib(stats.memory_used_bytes));
    printf("%-24s %6.0f %9.2f %9s | %6u %6u %-14s %8s %8.1f %9.1f\n", one->label,
           on.limits.area_m, bench_mib(on.block_size), batch_mib, PASSES, r.scans, status,
           used_mib, r.total_ms, r.finish_ms);
    if (on.failed_at)
        print_failure(one->label, &on);
    print_figures_header();
    if (one->ok)
        print_figures(one->label, "1 pass", &one->online, &one->batch);
    print_figures(one->label, "10 passes", &f, &one->batch);
    print_figures(one->label, "batch", &one->batch, NULL);
    fflush(stdout);
    online_close(&on);
    scene_data_free(&d);
    return rc;
}

/* scans with the correction row's drift on their poses (copies; the ranges
 * are shared): 0 at the first scan, growing linearly to a turn of drift[0]
 * about the first pose and a shift of (drift[1], drift[2]) at the last. */
static polyc_scan *drifted(const polyc_scan *scans, uint32_t n, const double *drift)
{
    polyc_scan *out = malloc(n * sizeof *out);
    double x0 = scans[0].pose_x_m, y0 = scans[0].pose_y_m;
    uint32_t i;
    if (!out)
        return NULL;
    for (i = 0; i < n; i++) {
        double s = n > 1u ? (double)i / (double)(n - 1u) : 0.0;
        double a = drift[0] * s, c = cos(a), sn = sin(a);
        double dx = scans[i].pose_x_m - x0, dy = scans[i].pose_y_m - y0;
        out[i] = scans[i];
        out[i].pose_x_m = x0 + c * dx - sn * dy + drift[1] * s;
        out[i].pose_y_m = y0 + sn * dx + c * dy + drift[2] * s;
        out[i].pose_theta_rad = scans[i].pose_theta_rad + a;
    }
    return out;
}

/* The pose-correction row: intel with a drift, all scans kept, an update
 * after each; every pose corrected, updates until the backlog is empty,
 * finish. */
static int correction_row(const options *o, const scene *s, const scene_result *one)
{
    scene_data d;
    online on;
    replay r;
    polyc_config config;
    polyc_online_report rep;
    bench_figures before, after;
    polyc_scan *bad = NULL;
    uint32_t *ids = NULL, n, i, updates = 0;
    double correct_ms = 0.0, settle_ms = 0.0, first_ms = 0.0, finish_ms = 0.0;
    int rc = -1;

    memset(&on, 0, sizeof on);
    memset(&r, 0, sizeof r);
    memset(&before, 0, sizeof before);
    memset(&after, 0, sizeof after);
    memset(&rep, 0, sizeof rep);
    if (scene_data_load(s, &d, one->label) != 0)
        return -1;
    n = d.log.count;
    printf("\nonline pose correction: %s's scans with a drift on their poses (0 at the first "
           "scan,\ngrowing linearly to a turn of %.3f rad about the first pose and a shift of "
           "(%.2f, %.2f) m\nat the last), all kept (keep_scans = all), an update after each "
           "add; then\npolyc_online_correct for every scan with its true pose (correct: all "
           "of them), updates\n(first: the first, which applies them) until the backlog is 0 (at most %u),\npolyc_online_finish; "
           "drifted = the map before\nthe corrections as the updates left it, corrected = "
           "after them and the finish (both\nscored against the true poses' endpoints)\n",
           s->name, o->drift[0], o->drift[1], o->drift[2], SETTLE_MAX);
    printf("%-24s %6s %9s | %8s | %9s %6s | %8s %7s %8s | %8s %-10s\n", "scene", "kept",
           "blockMiB", "replay", "correct", "scans", "first", "updates", "updates", "finish",
           "status");
    printf("%-24s %6s %9s | %8s | %9s %6s | %8s %7s %8s | %8s %-10s\n", "", "", "", "ms", "ms", "",
           "ms", "", "ms", "ms", "");
    bench_config(o, &config);
    bad = drifted(d.log.scans, n, o->drift);
    ids = malloc(n * sizeof *ids);
    if (!bad || !ids || limits_for(&config, &d, bad, 1, &on.limits) != POLYC_OK) {
        printf("%-24s error: out of memory or no limits\n", one->label);
        goto done;
    }
    /* tiles stay stored once a hit made them, so the grid holds the tiles
     * of both poses; the data cells hold both while the corrections go in */
    on.limits.max_grid_cells = on.limits.max_grid_cells > UINT32_MAX / 2u ? UINT32_MAX : 2u * on.limits.max_grid_cells;
    on.limits.max_points = on.limits.max_points > UINT32_MAX / 2u ? UINT32_MAX : 2u * on.limits.max_points;
    if (replay_run(o, &on, bad, n, 1, 1, ids, 0, 0, &r, one->label) != 0)
        goto failed;
    score_map(&d, on.ctx, &before);
    fair_score(o, &d, on.ctx, &before, one->label);
    {
        double t0 = pipeline_now_ms();
        for (i = 0; i < n; i++)
            if (online_fail(&on, polyc_online_correct(on.ctx, ids[i], d.log.scans[i].pose_x_m,
                                                      d.log.scans[i].pose_y_m,
                                                      d.log.scans[i].pose_theta_rad),
                            "polyc_online_correct", i))
                goto failed;
        correct_ms = pipeline_now_ms() - t0;
        t0 = pipeline_now_ms();
        do {
            if (online_fail(&on, polyc_online_update(on.ctx, POLYC_ONLINE_WORK_DEFAULT, &rep),
                            "polyc_online_update", n))
                goto failed;
            if (updates++ == 0)
                first_ms = pipeline_now_ms() - t0;
        } while ((rep.backlog_tiles > 0u || rep.pending_scans > 0u) && updates < SETTLE_MAX);
        settle_ms = pipeline_now_ms() - t0;
        t0 = pipeline_now_ms();
        if (online_fail(&on, polyc_online_finish(on.ctx, NULL, NULL, &rep),
                        "polyc_online_finish", n))
            goto failed;
        finish_ms = pipeline_now_ms() - t0;
    }
    score_map(&d, on.ctx, &after);
    /* on the data of the batch map of the true poses: the log's */
    fair_score(o, &d, on.ctx, &after, one->label);
    {
        char upd[16];
        snprintf(upd, sizeof upd, "%u%s", updates,
                 rep.backlog_tiles > 0u && updates >= SETTLE_MAX ? "+" : "");
        printf("%-24s %6u %9.2f | %8.1f | %9.2f %6u | %8.1f %7s %8.1f | %8.1f %-10s\n", one->label,
               n, bench_mib(on.block_size), r.total_ms, correct_ms, n, first_ms, upd, settle_ms,
               finish_ms, "ok");
    }
    print_figures_header();
    print_figures(one->label, "drifted", &before, &one->batch);
    print_figures(one->label, "corrected", &after, &one->batch);
    print_figures(one->label, "batch", &one->batch, NULL);
    rc = 0;
    goto done;
failed:
    print_failure(one->label, &on);
done:
    fflush(stdout);
    online_close(&on);
    free(bad);
    free(ids);
    scene_data_free(&d);
    return rc;
}

/* ---- the section ---------------------------------------------------------- */

int bench_online_section(const options *o, const scene *list, size_t count,
                         const bench_figures *batch)
{
    scene_result *res = calloc(count ? count : 1u, sizeof *res);
    double t0 = pipeline_now_ms();
    int failed = 0, from_table = batch && count && batch[0].ok;
    size_t i, intel = count;
    if (!res) {
        fprintf(stderr, "bench: out of memory\n");
        return -1;
    }
    if (count == 0) {
        free(res);
        return 0;
    }
    print_replay_header(o, from_table);
    for (i = 0; i < count; i++) {
        if (online_scene(o, &list[i], batch ? &batch[i] : NULL, &res[i]) != 0)
            failed = 1;
        if (strcmp(list[i].name, o->rows_log) == 0 && strcmp(list[i].kind, "carmen") == 0)
            intel = i;
    }
    printf("\nonline maps after polyc_online_finish beside the batch maps (%s); figures "
           "as in the\ntopology table, against the log's scan endpoints; BIC = polyc_stats.bic; "
           "sims: core\nprecision (0.5 m) and completeness\n",
           from_table ? "the main table's" : "one run each");
    print_figures_header();
    for (i = 0; i < count; i++) {
        if (res[i].ok)
            print_figures(res[i].label, "online", &res[i].online, &res[i].batch);
        print_figures(res[i].label, "batch", &res[i].batch, NULL);
    }
    if (intel < count) {
        if (memory_row(o, &list[intel], &res[intel]) != 0)
            failed = 1;
        if (correction_row(o, &list[intel], &res[intel]) != 0)
            failed = 1;
    }
    printf("\nonline section: %.0f s in all (replays, checkpoints, batch builds and scores)\n",
           (pipeline_now_ms() - t0) / 1e3);
    fflush(stdout);
    free(res);
    return failed ? -1 : 0;
}
