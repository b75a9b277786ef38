/* cli.h - what the polyc tool's files share (polyc.c: main; options.c:
 * the command line; load.c: the input; run.c: the library's run and the
 * outputs; cli.c: messages, the progress line and writing the outputs). */
#ifndef POLYC_CLI_H
#define POLYC_CLI_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "gridimage.h"
#include "mapfile.h"
#include "mapout.h"
#include "curves.h"
#include "polyc.h"
#include "scanlog.h"

#define EXIT_INPUT 1
#define EXIT_USAGE 2
#define EXIT_MEMORY 3

enum format { FORMAT_SVG, FORMAT_JSON, FORMAT_TXT };
enum command { CMD_MAP, CMD_CONVERT, CMD_GRID };

/* The options that apply to some inputs only, as bits of options.given. */
enum {
    OPT_FORMAT = 1u << 0, OPT_OUTPUT = 1u << 1, OPT_TRACE = 1u << 2, OPT_SEED = 1u << 3,
    OPT_ITERATIONS = 1u << 4, OPT_MAX_RANGE = 1u << 5, OPT_MEMORY = 1u << 6, OPT_CELL = 1u << 7,
    OPT_THRESHOLD = 1u << 8, OPT_ALPHA = 1u << 9, OPT_GAMMA = 1u << 10, OPT_OCCUPIED = 1u << 11,
    OPT_FREE = 1u << 12, OPT_STATS = 1u << 13, OPT_NO_OPTIMIZE = 1u << 14, OPT_EXACT = 1u << 15,
    OPT_GRID_TRACE = 1u << 16, OPT_POINTS = 1u << 17, OPT_GRID = 1u << 18, OPT_VERTICES = 1u << 19,
    OPT_COLOR_LINES = 1u << 20, OPT_ONLINE = 1u << 21, OPT_WORK = 1u << 22, OPT_FRAMES = 1u << 23,
    OPT_EVERY = 1u << 24, OPT_NO_ARCS = 1u << 25, OPT_CHORD = 1u << 26
};
/* what applies where */
#define OPTS_LOG_ONLY (OPT_CELL | OPT_THRESHOLD | OPT_MAX_RANGE | OPT_EXACT | OPT_GRID_TRACE | \
                       OPT_POINTS | OPT_ONLINE)
#define OPTS_ONLINE (OPT_WORK | OPT_FRAMES | OPT_EVERY)   /* with --online only */
#define OPTS_MAP_ONLY (OPT_OCCUPIED | OPT_FREE)
#define OPTS_GRID_CMD (OPT_OUTPUT | OPT_CELL | OPT_MAX_RANGE | OPT_MEMORY | OPT_STATS)
#define OPTS_CONVERT_CMD (OPT_OUTPUT | OPT_MAX_RANGE | OPT_STATS)

typedef struct options {
    const char *input;
    const char *output;        /* NULL or "-": stdout */
    const char *trace;
    enum command command;
    enum format format;
    unsigned given;            /* OPT_* bits of the options on the command line */
    int stats, no_optimize, points, grid, vertices, color_lines, quiet;
    int online;                /* --online: the log replayed as a stream (online.c) */
    int no_arcs;               /* --no-arcs: polylines only (POLYC_FLAG_NO_ARCS) */
    double max_chord_m;        /* --max-chord-error: circles written as polygons
                                  within this (0: as circles) */
    uint64_t work;             /* --work: an update's budget */
    const char *frames;        /* --frames DIR: an SVG every `every` scans; NULL: none */
    uint32_t every;
    double max_range_m;        /* 0: detect */
    double memory_mb;          /* 0: no cap */
    polyc_config config;
} options;

/* A memory stream to render into before anything is written. */
typedef struct membuf {
    char *data;
    size_t len;
    FILE *f;
} membuf;

/* A map read from a map YAML and its image. */
typedef struct map_input {
    mapfile_yaml yaml;
    mapfile_image image;       /* its size and kind (its cells are `cells`) */
    char *image_path;          /* as opened */
    int8_t *cells;             /* OccupancyGrid values, row 0 at the bottom */
    polyc_occupancy_grid grid;
    uint64_t occupied, free_cells, unknown;   /* under the library's thresholds */
} map_input;

typedef struct run {
    scanlog log;
    map_input *map;            /* a map instead of a log; NULL for a log */
    void *block;
    curves_map curves;         /* the map with its circles and arcs (curves.h) */
    polyc_polyline *flat_lines; /* --max-chord-error: the curves as polylines */
    float *flat_xy;
    const float **bulges;      /* per polyline: its bulges, NULL: no arc */
    membuf out, trace;
    gridimage image;           /* polyc grid */
    membuf pgm, yaml;
} run;

/* ---- cli.c ---- */

double now_ms(void);
/* qsort's comparison of doubles, ascending. */
int cmp_double(const void *a, const void *b);
/* The progress line on stderr: shown if `on` (stderr a terminal, no
 * --quiet), timed from t_start_ms. */
void progress_start(int on, double t_start_ms);
int progress_on(void);
void progress_clear(void);
void progress_show(const polyc_iteration *it);
void progress_stage(const char *stage);
/* "polyc: message" on stderr (and a pointer to --help for EXIT_USAGE);
 * returns code. */
int complain(int code, const char *fmt, ...);
/* The input as messages name it ("<stdin>" for -). */
const char *input_name(const options *o);
/* 0, or EXIT_INPUT with a message; membuf_close: 0 if all of it was
 * written to the stream. */
int membuf_open(membuf *m);
int membuf_close(membuf *m, int write_failed);
/* The rendered outputs to their paths, all or none (outfile.h); 0 or
 * EXIT_INPUT with a message. */
int write_outputs(const char *const *paths, const membuf *const *bufs, size_t n);

/* ---- options.c ---- */

/* 0: run; -1: --help/--version done (exit 0); else an exit code. */
int parse_args(int argc, char **argv, options *o);
/* Refuses (usage) the options given that are not in `allowed`. */
int refuse_options(const options *o, unsigned allowed, const char *why);
/* polyc grid's PREFIX: the length of -o's value without a .pgm or .yaml
 * extension (-o office.yaml writes office.pgm and office.yaml). */
size_t grid_prefix_len(const char *output);

/* ---- load.c ---- */

enum input_kind { INPUT_LOG, INPUT_MAP_YAML, INPUT_IMAGE };
enum input_kind sniff(const char *path);
/* The log o->input (or stdin) into r->log; 0 or an exit code. */
int load_log(const options *o, run *r);
/* The map YAML o->input, its image, converted; 0 or an exit code. */
int load_map(const options *o, map_input *m);
void print_input_stats(const scanlog *log);
void print_map_stats(const map_input *m);

/* ---- run.c ---- */

/* polyc [options] INPUT: the map out; t gets the stage times. */
int make_map(const options *o, run *r, double t_start, mapout_times *t);
/* Maps a library failure in `stage` to a message and an exit code (3 for
 * POLYC_ERR_NOMEM, else 1); ctx may be NULL. */
int library_fail(const char *stage, polyc_status st, const polyc_ctx *ctx, size_t block);
/* Scan i of the log refused by the library (st): its line and the library's
 * message for a bad scan, else library_fail's. Returns the exit code. */
int add_fail(const options *o, const run *r, uint32_t i, polyc_status st, const polyc_ctx *ctx,
             size_t size);
/* ctxblock_make's result `made` (enum ctxblock_result) as 0 or the exit
 * code of its complaint (--memory-mb's cap, malloc, init's status st). */
int block_fail(const options *o, int made, polyc_status st, const polyc_ctx *ctx, size_t size);
/* The optimiser's callback for the options, or NULL: --trace's line (its
 * user pointer: r->trace.f) and the progress line. */
polyc_progress_fn iteration_fn(const options *o);
/* A run that ran out of memory and may try again with larger limits. */
#define RUN_AGAIN (-1)
/* After an optimiser call in `stage`: 0 if st is POLYC_OK, RUN_AGAIN (the
 * trace rewound, as the rerun writes its lines again) for POLYC_ERR_NOMEM
 * if `retry`, else library_fail's exit code. */
int optimiser_status(run *r, polyc_status st, int retry, const char *stage, const polyc_ctx *ctx,
                     size_t size);
/* With --trace, opens r->trace and writes its header (once); 0 or an exit code. */
int open_trace(const options *o, run *r);
/* The context's current map as the options draw it: its polylines into
 * r->lines (any earlier array freed; they point into the context), the
 * layers, the title. stats, times and total_ms are left 0. 0 or an exit code. */
int map_to_draw(const options *o, run *r, const polyc_config *cfg, polyc_ctx *ctx, size_t size,
                mapout_map *map);
/* map rendered in `format` into out (opened and closed here); 0 or an exit code. */
int render_map(membuf *out, enum format format, const mapout_map *map);
/* The map rendered (SVG, JSON or TXT) and written with the trace, both or
 * neither; --stats after. 0 or an exit code. */
int write_map(const options *o, run *r, const polyc_config *cfg, polyc_ctx *ctx, size_t size,
              const mapout_times *t, double t_start);

/* ---- online.c ---- */

/* polyc --online LOG: the scans added and the map updated one by one
 * (--frames: an SVG every --every scans), finished, and written as
 * make_map writes it; --stats adds the latencies. */
int online_map(const options *o, run *r, double t_start, mapout_times *t);
/* polyc grid: the hit/miss grid as map_saver's PREFIX.pgm and PREFIX.yaml. */
int grid_files(const options *o, run *r, double t_start);
/* polyc convert: the scans in the plain format. */
int convert(const options *o, run *r);

#endif /* POLYC_CLI_H */
