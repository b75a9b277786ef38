/* bench.h - what the bench's files share: bench.c (options, scenes, main),
 * bench_table.c (the main table and the topology table), bench_single.c
 * (single scans of the real logs), bench_occupancy.c (occupancy maps). */
#ifndef POLYC_BENCH_H
#define POLYC_BENCH_H

#include <stddef.h>
#include <stdint.h>

#include "pipeline.h"
#include "polyc.h"
#include "scanlog.h"

#define EXIT_FAILED 1
#define EXIT_USAGE 2
#define MAX_RUNS 99
#define NEAR_M 0.05 /* "share of endpoints within 5 cm of the map" */
#define CORE_M 0.5 /* core precision: the map samples within 0.5 m of a true wall */
#define SCAN_BUDGET_MS 2.0 /* issue 4: one 360-beam scan within 2 ms; `over` counts the scans above */

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


/* ---- bench.c ---- */

double bench_median(const double *v, unsigned n);
/* Peak resident size of the process so far, MiB. */
double bench_peak_rss_mib(void);
double bench_mib(uint64_t bytes);
/* The log at path (tools/scanlog); *ms gets the time. 0, or -1 with log->error. */
int bench_read_log(const char *path, scanlog *log, double *ms);
/* The library's configuration with the options' overrides. */
void bench_config(const options *o, polyc_config *c);
int bench_open_pipeline(pipeline *p, const options *o, const polyc_scan *scans, uint32_t n);
/* The map as JSON to /dev/null (as the tool renders it); its time in ms. */
double bench_write_output(const pipeline *p, const polyc_polyline *lines, uint32_t count);

/* ---- the sections: each prints its table; 0, or -1 if a scene failed ---- */

/* Every scene timed and scored, then the topology table. */
int bench_table_section(const options *o, const scene *list, size_t count);
/* Single-scan maps from o->single scans of each real log. */
int bench_single_section(const options *o, const scene *list, size_t count);
/* Occupancy grids mapped by the library and by the baseline; the maze. */
int bench_occupancy_section(const options *o, const scene *list, size_t count);

#endif /* POLYC_BENCH_H */
