/* bench.h - what the bench's files share: bench.c (options, scenes, main),
 * bench_table.c (the main table and the topology table), bench_single.c
 * (single scans of the real logs), bench_occupancy.c (occupancy maps),
 * bench_online.c (the online API, scan by scan). */
#ifndef POLYC_BENCH_H
#define POLYC_BENCH_H

#include <stddef.h>
#include <stdint.h>

#include "gtband.h"
#include "gttopo.h"
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
    int online;                /* the online section (--no-online: 0) */
    int online_only;           /* only the online section */
    const char *rows_log;      /* the memory and correction rows' real log */
    const char *maps_dir;      /* --maps: the online maps written there (NULL: not) */
    double drift[3];           /* the correction row's drift at the last scan:
                                  turn (rad), shift x, y (m) */
    const char *data;
} options;

typedef struct scene {
    char name[128];            /* "office" */
    char kind[8];              /* "sim" or "carmen" */
    char log_path[1536];
    char gt_path[1536];        /* sim only */
} scene;

/* A map's figures as the online section sets them side by side: the batch
 * build's (filled by bench_table_section) and the online map's. */
typedef struct bench_figures {
    int ok;                    /* 0: no map, or not scored */
    double lib_ms;             /* the library's time (batch: add to optimise,
                                  the median over the runs) */
    uint64_t block_bytes;      /* the context's block */
    uint32_t lines, vertices;
    double bic;                /* polyc_stats.bic */
    double bic_on_batch;       /* online maps: the BIC on the batch build's
                                  data (tools/eval/fairbic.h); 0: none */
    gttopo_score topo;         /* against the log's scan endpoints */
    gtband_score band;
    double core_m;             /* sim scenes: core precision (CORE_M); < 0: none */
    double completeness;       /* sim scenes; < 0: none */
} bench_figures;

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

/* Every scene timed and scored, then the topology table. batch (NULL, or
 * count entries) gets each scene's batch figures. */
int bench_table_section(const options *o, const scene *list, size_t count, bench_figures *batch);
/* Single-scan maps from o->single scans of each real log. */
int bench_single_section(const options *o, const scene *list, size_t count);
/* Occupancy grids mapped by the library and by the baseline; the maze. */
int bench_occupancy_section(const options *o, const scene *list, size_t count);
/* Each scene replayed scan by scan through the online API beside its batch
 * build (batch: the main table's figures, count entries; NULL or an entry
 * not ok: built here, one run), then intel's memory and pose-correction
 * rows. */
int bench_online_section(const options *o, const scene *list, size_t count,
                         const bench_figures *batch);

#endif /* POLYC_BENCH_H */
