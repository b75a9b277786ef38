/* bench_single.c - the bench's single-scan section (bench.h).
 * Takes: the real logs. Gives: per log, maps of single scans spread over
 * it, each run on one block: ray accuracy (tools/eval/gtscore), vertices,
 * the median and slowest times, crossings and unsupported runs. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "gtscore.h"
#include "gttopo.h"

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
    if (bench_read_log(s->log_path, &log, &parse_ms) != 0) {
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
        int bad = bench_open_pipeline(&p, o, scan, 1) != 0;
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
        double ms = bench_median(run_total, o->runs);
        ms_sum += ms;
        if (ms > ms_max)
            ms_max = ms; /* a robot's worst case: the slowest scan */
        over += ms > SCAN_BUDGET_MS;
        cold_sum += cold; /* a scan that failed counts in neither */
        for (i = ST_GRID; i <= ST_OPT; i++)
            stage_sum[i] += bench_median(run_stage[i], o->runs);
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

int bench_single_section(const options *o, const scene *list, size_t count)
{
    size_t reals = 0;
    int failed = 0;
    for (size_t i = 0; i < count; i++)
        reals += strcmp(list[i].kind, "carmen") == 0;
    if (reals == 0)
        return 0;
    printf("\nsingle scans: a map from one scan; f = share of reflected beams whose ray "
           "meets the map,\nray RMSE = measured minus map range over those beams "
           "(tools/eval/gtscore.h)\n");
    printf("%-24s %6s %8s %9s %9s %9s %9s %7s %6s %6s | %6s %7s %6s %8s | %6s %6s %6s\n",
           "log", "scans", "mean f", "rayRMSE", "verts", "verts", "ms/scan", "slowest",
           "over", "cold", "grid", "contour", "trace", "optimise", "cross", "maps", "uns20");
    printf("%-24s %6s %8s %9s %9s %9s %9s %7s %6s %6s | %6s %7s %6s %8s | %6s %6s %6s\n",
           "", "", "", "mm", "/scan", "/180 b.", "median", "ms", "2 ms", "ms", "ms", "ms",
           "ms", "ms", "sum", "w/ any", "sum");
    for (size_t i = 0; i < count; i++)
        if (strcmp(list[i].kind, "carmen") == 0 && single_scans(o, &list[i]) != 0)
            failed = 1;
    return failed ? -1 : 0;
}
