/* bench_table.c - the bench's main table and its topology table (bench.h).
 * Takes: the scenes. Gives: per scene the median stage times over the
 * runs, memory and accuracy (tools/eval/gtscore), then a row of topology
 * and band figures (tools/eval/gttopo, gtband) per scene. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "gtband.h"
#include "gtscore.h"
#include "gttopo.h"

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

static int bench_scene(const options *o, const scene *s, topo_row *row, bench_figures *batch)
{
    double times[MAX_RUNS][ST_COUNT], column[MAX_RUNS], med[ST_COUNT], lib[MAX_RUNS];
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
        if (bench_read_log(s->log_path, &log, &times[r][ST_PARSE]) != 0) {
            printf("%-24s error: %s\n", label, log.error);
            scanlog_free(&log);
            return -1;
        }
    }
    if (bench_open_pipeline(&p, o, log.scans, log.count) == 0) {
        for (r = 0; r < o->runs && p.failed_at == NULL; r++) {
            free(lines);
            lines = NULL;
            if (pipeline_run(&p, log.scans, log.count, &times[r][ST_ADD]) != 0)
                break;
            lines = pipeline_lines(&p, &count);
            if (!lines)
                break;
            times[r][ST_OUT] = bench_write_output(&p, lines, count);
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
        med[k] = bench_median(column, o->runs);
    }
    polyc_get_stats(p.ctx, &stats);
    accuracy(s, &log, lines, count, &acc, row);
    if (batch) {
        /* the online section's comparison: the library's time, add to optimise */
        for (r = 0; r < o->runs; r++)
            for (lib[r] = 0.0, k = ST_ADD; k <= ST_OPT; k++)
                lib[r] += times[r][k];
        batch->ok = row->ok;
        batch->lib_ms = bench_median(lib, o->runs);
        batch->block_bytes = stats.memory_size_bytes;
        batch->lines = acc.lines;
        batch->vertices = acc.vertices;
        batch->bic = stats.bic;
        batch->topo = row->score;
        batch->band = row->band;
        batch->core_m = row->core_m;
        batch->completeness = acc.has_truth ? acc.score.completeness : -1.0;
    }

    printf("%-24s %6u %8llu | %7.1f %6.1f %7.1f %7.1f %7.1f %8.1f %6.1f %8.1f | %8.2f %8.2f "
           "%7.1f | %6u %7u ",
           label, log.count, (unsigned long long)log.beams, med[ST_PARSE], med[ST_ADD],
           med[ST_GRID], med[ST_CONTOUR], med[ST_TRACE], med[ST_OPT], med[ST_OUT],
           med[ST_TOTAL], bench_mib(stats.memory_size_bytes), bench_mib(stats.memory_used_bytes),
           bench_peak_rss_mib(), acc.lines, acc.vertices);
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

int bench_table_section(const options *o, const scene *list, size_t count, bench_figures *batch)
{
    topo_row *rows = calloc(count ? count : 1u, sizeof *rows);
    int failed = 0;
    if (!rows) {
        fprintf(stderr, "bench: out of memory\n");
        return -1;
    }
    print_header(o);
    for (size_t i = 0; i < count; i++)
        if (bench_scene(o, &list[i], &rows[i], batch ? &batch[i] : NULL) != 0)
            failed = 1;
    print_topology(rows, count);
    free(rows);
    return failed ? -1 : 0;
}
