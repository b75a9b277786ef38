/* polyc.c - the command-line tool: a laser log or a ROS map in, a polyline
 * map out.
 *   polyc [options] INPUT        map as SVG (default), JSON or TXT; INPUT is
 *                                a log or a map_server map YAML (by content)
 *   polyc convert INPUT          the scans in the plain format
 *   polyc grid LOG -o PREFIX     the hit/miss grid as map_saver's PREFIX.pgm
 *                                and PREFIX.yaml
 * Exit codes: 0 ok, 1 bad input or other failure, 2 usage, 3 memory budget.
 * Formats and rules: docs/formats.md. */
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "gridimage.h"
#include "mapfile.h"
#include "mapout.h"
#include "outfile.h"
#include "polyc.h"
#include "scanlog.h"
#include "textesc.h"

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
    OPT_COLOR_LINES = 1u << 20
};
static const struct {
    const char *name;
    unsigned bit;
} option_bits[] = {
    {"--format", OPT_FORMAT},       {"-o", OPT_OUTPUT},           {"--output", OPT_OUTPUT},
    {"--trace", OPT_TRACE},         {"--seed", OPT_SEED},         {"--iterations", OPT_ITERATIONS},
    {"--max-range", OPT_MAX_RANGE}, {"--memory-mb", OPT_MEMORY},  {"--cell", OPT_CELL},
    {"--threshold", OPT_THRESHOLD}, {"--alpha", OPT_ALPHA},       {"--gamma", OPT_GAMMA},
    {"--occupied-thresh", OPT_OCCUPIED}, {"--free-thresh", OPT_FREE}, {"--stats", OPT_STATS},
    {"--no-optimize", OPT_NO_OPTIMIZE}, {"--exact-points", OPT_EXACT},
    {"--grid-trace", OPT_GRID_TRACE}, {"--points", OPT_POINTS}, {"--grid", OPT_GRID},
    {"--vertices", OPT_VERTICES},     {"--color-lines", OPT_COLOR_LINES},
};
/* what applies where */
#define OPTS_LOG_ONLY (OPT_CELL | OPT_THRESHOLD | OPT_MAX_RANGE | OPT_EXACT | OPT_GRID_TRACE | OPT_POINTS)
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
    double max_range_m;        /* 0: detect */
    double memory_mb;          /* 0: no cap */
    polyc_config config;
} options;

static const char usage_text[] =
    "usage: polyc [options] INPUT       learn a polyline map from a laser log or a ROS map\n"
    "       polyc convert [-o FILE] [--max-range M] INPUT\n"
    "                                   write the scans in polyc's plain format\n"
    "       polyc grid [--cell M] [--max-range M] -o PREFIX LOG\n"
    "                                   write the log's hit/miss grid as a ROS map:\n"
    "                                   PREFIX.pgm and PREFIX.yaml, as map_saver does\n"
    "INPUT is a CARMEN log (FLASER, ROBOTLASER1) or a plain scan file (- is stdin),\n"
    "or a ROS map_server map YAML (found by its content: key: value lines naming an\n"
    "image, a PGM). A map's cells are its own: --cell, --threshold, --max-range,\n"
    "--exact-points, --grid-trace and --points act on scans and are refused for a\n"
    "map; --occupied-thresh and --free-thresh apply to maps only.\n"
    "options:\n"
    "  --format svg|json|txt   output format (default: -o's extension, else svg)\n"
    "  -o, --output FILE       write FILE instead of stdout (a file is replaced\n"
    "                          atomically, a device or FIFO written in place)\n"
    "  --stats                 counts, sizes and times per stage on stderr\n"
    "  --no-optimize           stop after tracing the initial polylines\n"
    "  --cell M                grid cell size in metres (default 0.025)\n"
    "  --threshold T           contour threshold on hits/(hits+misses) (default 0.5)\n"
    "  --max-range M           FLASER: no-return threshold in metres (default: detected);\n"
    "                          other formats: lowers their max range to M\n"
    "  --seed N                PRNG seed of the optimiser\n"
    "  --iterations N          cap on optimiser iterations\n"
    "  --alpha A               BIC weight of the error (paper 500)\n"
    "  --gamma G               weight of the angle prior (0: uniform)\n"
    "  --exact-points          keep every endpoint as a data point (slower)\n"
    "  --grid-trace            one scan: trace the grid's contour, not the beam order\n"
    "  --trace FILE            per iteration: iteration bic best_bic vertices polylines noise_m\n"
    "  --memory-mb N           fail (exit 3) if the library needs more than N MiB\n"
    "  --occupied-thresh P     map: a cell of value >= 100 P is occupied (default 0.65)\n"
    "  --free-thresh P         map: a cell of value 0..100 P is free (default 0.196)\n"
    "  --quiet                 no progress line on a terminal (shown on stderr for runs\n"
    "                          over 2 s: stage, iteration, vertices, BIC)\n"
    "  --points, --grid, --vertices\n"
    "                          SVG layers: scan endpoints, grid cells, vertex dots\n"
    "  --color-lines           SVG: a colour per polyline (default: one for the map)\n"
    "  --help, --version\n"
    "exit codes: 0 ok, 1 bad input or other failure, 2 usage, 3 memory budget too small\n";

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

/* ---- progress: one line on a terminal ---- */

/* Shown on stderr when it is a terminal (not with --quiet), once a run has
 * taken PROGRESS_AFTER_MS: the stage, and in the optimiser the iteration,
 * vertices and BIC, rewritten in place (carriage return) at each stage and
 * iteration, and blanked before anything else is written to stderr. The
 * stages without a callback (grid, contour) show when they start. */
#define PROGRESS_AFTER_MS 2000.0
#define PROGRESS_EVERY_MS 100.0

static struct progress {
    int on;
    double start_ms, last_ms;
    const char *stage;
    size_t shown;              /* characters of the line now on the terminal */
} prog;

static void progress_clear(void)
{
    if (!prog.shown)
        return;
    fputc('\r', stderr);
    for (size_t i = 0; i < prog.shown; i++)
        fputc(' ', stderr);
    fputc('\r', stderr);
    fflush(stderr);
    prog.shown = 0;
}

static void progress_show(const polyc_iteration *it)
{
    if (!prog.on || !prog.stage)
        return;
    double now = now_ms();
    if (now - prog.start_ms < PROGRESS_AFTER_MS || (it && now - prog.last_ms < PROGRESS_EVERY_MS))
        return;
    prog.last_ms = now;
    char line[160];
    int n = snprintf(line, sizeof line, "polyc: %s", prog.stage);
    if (it && n > 0 && (size_t)n < sizeof line)
        n += snprintf(line + n, sizeof line - (size_t)n, ": iteration %u, %u vertices, BIC %.1f",
                      (unsigned)it->iteration, (unsigned)it->vertices, it->best_bic);
    if (n > 0 && (size_t)n < sizeof line)
        snprintf(line + n, sizeof line - (size_t)n, " (%.1f s)", (now - prog.start_ms) / 1e3);
    size_t len = strlen(line);
    fputc('\r', stderr);
    fputs(line, stderr);
    for (size_t i = len; i < prog.shown; i++)   /* over the rest of a longer line */
        fputc(' ', stderr);
    fflush(stderr);
    prog.shown = len > prog.shown ? len : prog.shown;
}

static void progress_stage(const char *stage)
{
    prog.stage = stage;
    progress_show(NULL);
}

static int complain(int code, const char *fmt, ...)
{
    va_list ap;
    progress_clear();
    fputs("polyc: ", stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    if (code == EXIT_USAGE)
        fputs("try 'polyc --help'\n", stderr);
    return code;
}

/* ---- options ---- */

static int parse_double(const char *s, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end || errno || !(v >= lo && v <= hi))
        return -1;
    *out = v;
    return 0;
}

static int parse_u64(const char *s, uint64_t max, uint64_t *out)
{
    char *end;
    if (*s < '0' || *s > '9')
        return -1;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (*end || errno || v > max)
        return -1;
    *out = v;
    return 0;
}

/* Sets one option that takes a value; returns 0 or an exit code. */
static int set_value(options *o, const char *name, const char *val)
{
    double d;
    uint64_t u;
    if (strcmp(name, "--format") == 0) {
        if (strcmp(val, "svg") == 0)
            o->format = FORMAT_SVG;
        else if (strcmp(val, "json") == 0)
            o->format = FORMAT_JSON;
        else if (strcmp(val, "txt") == 0)
            o->format = FORMAT_TXT;
        else
            return complain(EXIT_USAGE, "--format must be svg, json or txt, not '%s'", val);
    } else if (strcmp(name, "-o") == 0 || strcmp(name, "--output") == 0) {
        o->output = val;
    } else if (strcmp(name, "--trace") == 0) {
        o->trace = val;
    } else if (strcmp(name, "--seed") == 0) {
        if (parse_u64(val, UINT64_MAX, &u))
            return complain(EXIT_USAGE, "--seed needs an unsigned integer, not '%s'", val);
        o->config.seed = u;
    } else if (strcmp(name, "--iterations") == 0) {
        if (parse_u64(val, UINT32_MAX, &u))
            return complain(EXIT_USAGE, "--iterations needs 0..%u, not '%s'", UINT32_MAX, val);
        o->config.max_iterations = (uint32_t)u;
    } else if (strcmp(name, "--max-range") == 0) {
        if (parse_double(val, 0.05, 1e6, &d))
            return complain(EXIT_USAGE, "--max-range needs metres in [0.05, 1e6], not '%s'", val);
        o->max_range_m = d;
    } else if (strcmp(name, "--memory-mb") == 0) {
        if (parse_double(val, 1e-6, 1e9, &d))
            return complain(EXIT_USAGE, "--memory-mb needs MiB from 0.000001 to 1000000000,"
                                        " not '%s'", val);
        o->memory_mb = d;
    } else {
        /* float config fields; polyc_config_check judges the values */
        float *field = strcmp(name, "--cell") == 0        ? &o->config.cell_m
                       : strcmp(name, "--threshold") == 0 ? &o->config.contour_threshold
                       : strcmp(name, "--alpha") == 0     ? &o->config.alpha
                       : strcmp(name, "--gamma") == 0     ? &o->config.gamma
                       : strcmp(name, "--occupied-thresh") == 0 ? &o->config.occupied_thresh
                       : strcmp(name, "--free-thresh") == 0     ? &o->config.free_thresh
                                                                : NULL;
        if (!field)
            return complain(EXIT_USAGE, "unknown option '%s'", name);
        if (parse_double(val, -1e30, 1e30, &d))
            return complain(EXIT_USAGE, "%s needs a number, not '%s'", name, val);
        *field = (float)d;
    }
    return 0;
}

static unsigned option_bit(const char *name)
{
    for (size_t i = 0; i < sizeof option_bits / sizeof option_bits[0]; i++)
        if (strcmp(name, option_bits[i].name) == 0)
            return option_bits[i].bit;
    return 0;
}

static int set_flag(options *o, const char *name)
{
    if (strcmp(name, "--quiet") == 0)
        o->quiet = 1;
    else if (strcmp(name, "--stats") == 0)
        o->stats = 1;
    else if (strcmp(name, "--no-optimize") == 0)
        o->no_optimize = 1;
    else if (strcmp(name, "--exact-points") == 0)
        o->config.flags |= POLYC_FLAG_EXACT_POINTS;
    else if (strcmp(name, "--grid-trace") == 0)
        o->config.flags |= POLYC_FLAG_GRID_TRACE;
    else if (strcmp(name, "--points") == 0)
        o->points = 1;
    else if (strcmp(name, "--grid") == 0)
        o->grid = 1;
    else if (strcmp(name, "--vertices") == 0)
        o->vertices = 1;
    else if (strcmp(name, "--color-lines") == 0)
        o->color_lines = 1;
    else
        return -1;
    return 0;
}

static int takes_value(const char *name)
{
    static const char *const names[] = {"--format", "-o",          "--output",    "--trace",
                                        "--seed",   "--iterations", "--max-range", "--memory-mb",
                                        "--cell",   "--threshold", "--alpha",     "--gamma",
                                        "--occupied-thresh", "--free-thresh"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(name, names[i]) == 0)
            return 1;
    return 0;
}

/* The format -o's extension names (.svg, .json, .txt), or -1. */
static int format_of_name(const char *path)
{
    static const char *const ext[] = {".svg", ".json", ".txt"};
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    for (int f = 0; dot && f < 3; f++) {
        size_t i = 0;
        while (dot[i] && ext[f][i] && tolower((unsigned char)dot[i]) == ext[f][i])
            i++;
        if (!dot[i] && !ext[f][i])
            return f;
    }
    return -1;
}

/* Refuses (usage) outputs that cannot be written as asked, before any work:
 * an empty or directory name, -o and --trace naming the same file, a
 * --format that -o's extension contradicts; else takes the format from it. */
static int check_outputs(options *o)
{
    const char *why;
    if (o->command == CMD_GRID) {
        size_t n = strlen(o->output);
        char *p = malloc(n + 6);
        if (!p)
            return complain(EXIT_INPUT, "out of memory");
        why = outfile_check(o->output);
        for (int i = 0; i < 2 && !why; i++) {
            snprintf(p, n + 6, "%s%s", o->output, i ? ".yaml" : ".pgm");
            why = outfile_check(p);
        }
        free(p);
        return why ? complain(EXIT_USAGE, "-o PREFIX '%s' %s (polyc grid writes PREFIX.pgm and"
                                          " PREFIX.yaml)", o->output, why)
                   : 0;
    }
    if ((why = outfile_check(o->output)))
        return complain(EXIT_USAGE, "-o '%s' %s: give a file name", o->output, why);
    if ((why = outfile_check(o->trace)))
        return complain(EXIT_USAGE, "--trace '%s' %s: give a file name", o->trace, why);
    if (o->trace && outfile_same(o->output, o->trace))
        return complain(EXIT_USAGE, "-o and --trace name the same file ('%s', '%s')",
                        o->output ? o->output : "-", o->trace);
    int f = o->output && o->command == CMD_MAP ? format_of_name(o->output) : -1;
    static const char *const names[] = {"svg", "json", "txt"};
    if (f >= 0 && (o->given & OPT_FORMAT) && (int)o->format != f)
        return complain(EXIT_USAGE, "--format %s contradicts -o %s (a .%s name)",
                        names[o->format], o->output, names[f]);
    if (f >= 0)
        o->format = (enum format)f;
    return 0;
}

/* polyc_config_check's message, in the options' names: "cell_m must be in
 * [0.001, 10]" is "--cell must be in [0.001, 10]". */
static int config_fail(const char *why)
{
    static const char *const names[][2] = {
        {"cell_m", "--cell"}, {"contour_threshold", "--threshold"}, {"alpha", "--alpha"},
        {"gamma", "--gamma"}, {"occupied_thresh", "--occupied-thresh"},
        {"free_thresh", "--free-thresh"}};
    char msg[200];
    size_t n = 0;
    while (*why && n + 40 < sizeof msg) {
        size_t k = 0, len = 0;
        for (; k < sizeof names / sizeof names[0]; k++) {
            len = strlen(names[k][0]);
            if (strncmp(why, names[k][0], len) == 0 && why[len] != '_' &&
                !isalnum((unsigned char)why[len]))   /* a whole name */
                break;
        }
        if (k < sizeof names / sizeof names[0]) {
            n += (size_t)sprintf(msg + n, "%s", names[k][1]);
            why += len;
        } else {
            msg[n++] = *why++;
        }
    }
    msg[n] = '\0';
    return complain(EXIT_USAGE, "bad option value: %s", msg);
}

/* 0: run; -1: --help/--version done (exit 0); else an exit code. */
static int parse_args(int argc, char **argv, options *o)
{
    const char *positional[2];
    int npos = 0, only_files = 0;
    memset(o, 0, sizeof *o);
    polyc_config_default(&o->config);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (only_files || a[0] != '-' || strcmp(a, "-") == 0) {
            if (npos == 2)
                return complain(EXIT_USAGE, "too many arguments ('%s')", a);
            positional[npos++] = a;
            continue;
        }
        if (strcmp(a, "--") == 0) {
            only_files = 1;
        } else if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage_text, stdout);
            return -1;
        } else if (strcmp(a, "--version") == 0) {
            printf("polyc %d.%d.%d\n", POLYC_VERSION_MAJOR, POLYC_VERSION_MINOR,
                   POLYC_VERSION_PATCH);   /* the tool is libpolyc's, one version */
            return -1;
        } else if (set_flag(o, a) == 0) {
            o->given |= option_bit(a);
            continue;
        } else {
            char name[32];
            const char *eq = strchr(a, '=');
            size_t n = eq && a[1] == '-' ? (size_t)(eq - a) : strlen(a);   /* --name=value */
            if (n >= sizeof name)
                return complain(EXIT_USAGE, "unknown option '%s'", a);
            memcpy(name, a, n);
            name[n] = '\0';
            if (!takes_value(name))
                return complain(EXIT_USAGE, "unknown option '%s'", a);
            if (!eq && i + 1 >= argc)
                return complain(EXIT_USAGE, "%s needs a value", a);
            int rc = set_value(o, name, eq && a[1] == '-' ? eq + 1 : argv[++i]);
            if (rc)
                return rc;
            o->given |= option_bit(name);
        }
    }
    if (npos >= 1 && (strcmp(positional[0], "convert") == 0 || strcmp(positional[0], "grid") == 0)) {
        o->command = positional[0][0] == 'c' ? CMD_CONVERT : CMD_GRID;
        positional[0] = npos == 2 ? positional[1] : NULL;
        npos--;
    }
    if (npos != 1 || !positional[0])
        return complain(EXIT_USAGE, npos == 0 ? "no input file" : "too many arguments");
    o->input = positional[0];
    if (o->command == CMD_GRID && (!o->output || strcmp(o->output, "-") == 0))
        return complain(EXIT_USAGE, "polyc grid needs -o PREFIX (it writes PREFIX.pgm and"
                                    " PREFIX.yaml)");
    int rc = check_outputs(o);
    if (rc)
        return rc;
    const char *why = NULL;
    if (polyc_config_check(&o->config, &why) != POLYC_OK)
        return config_fail(why ? why : "?");
    return 0;
}

/* A memory stream to render into before anything is written. */
typedef struct membuf {
    char *data;
    size_t len;
    FILE *f;
} membuf;

static int membuf_open(membuf *m)
{
    m->data = NULL;
    m->len = 0;
    m->f = open_memstream(&m->data, &m->len);
    return m->f ? 0 : complain(EXIT_INPUT, "out of memory");
}

/* Closes the stream; 0 if everything written to it made it. */
static int membuf_close(membuf *m, int write_failed)
{
    int bad = write_failed || ferror(m->f);
    bad = fclose(m->f) != 0 || bad;
    m->f = NULL;
    return bad ? complain(EXIT_INPUT, "out of memory rendering the output") : 0;
}

/* ---- output: all or nothing ---- */

/* Writes n rendered outputs to their paths (NULL or "-": stdout), all or
 * none where it can (outfile.h): every temporary file is written before
 * anything is renamed or written in place. 0 or EXIT_INPUT with a message. */
static int write_outputs(const char *const *paths, const membuf *const *bufs, size_t n)
{
    outfile of[2];
    outfile *ptr[2];
    const char *what = NULL;
    int err = 0;
    size_t made = 0;
    for (; made < n && made < 2 && !err; made++) {
        ptr[made] = &of[made];
        err = outfile_prepare(&of[made], paths[made], bufs[made]->data, bufs[made]->len, &what);
    }
    if (err) {
        for (size_t j = 0; j < made; j++)
            outfile_abort(&of[j]);
        const char *p = paths[made - 1];
        return what ? complain(EXIT_INPUT, "%s: %s: %s", p, what, strerror(err))
                    : complain(EXIT_INPUT, "%s: %s", p, strerror(err));
    }
    progress_clear();                     /* before stdout, which may be the terminal */
    const outfile *failed = NULL;
    if ((err = outfile_commit_all(ptr, made, &failed)) != 0)
        return failed && failed->kind != OUTFILE_STDOUT
                   ? complain(EXIT_INPUT, "%s: %s", failed->path, strerror(err))
                   : complain(EXIT_INPUT, "writing stdout: %s", strerror(err));
    return 0;
}

/* ---- the optimiser's callback: --trace and the progress line ---- */

static int on_iteration(void *user, const polyc_iteration *it)
{
    FILE *f = user;
    if (f)
        fprintf(f, "%u %.6f %.6f %u %u %.6f\n", (unsigned)it->iteration, it->bic, it->best_bic,
                (unsigned)it->vertices, (unsigned)it->polylines, it->noise_m);
    progress_show(it);
    return 0;
}

/* ---- the run's state ---- */

/* A map read from a map YAML and its image. */
typedef struct map_input {
    mapfile_yaml yaml;
    mapfile_pgm pgm;
    char *image_path;          /* as opened */
    int8_t *cells;             /* OccupancyGrid values, row 0 at the bottom */
    polyc_occupancy_grid grid;
    uint64_t occupied, free_cells, unknown;   /* under the library's thresholds */
} map_input;

typedef struct run {
    scanlog log;
    map_input *map;            /* a map instead of a log; NULL for a log */
    void *block;
    polyc_polyline *lines;
    membuf out, trace;
    gridimage image;           /* polyc grid */
    membuf pgm, yaml;
} run;

/* ---- --stats ---- */

static void print_input_stats(const scanlog *log)
{
    FILE *e = stderr;
    fprintf(e, "scans          %u (FLASER %llu, ROBOTLASER1 %llu, SCAN %llu)\n", log->count,
            (unsigned long long)log->kind_counts[SCANLOG_FLASER],
            (unsigned long long)log->kind_counts[SCANLOG_ROBOTLASER1],
            (unsigned long long)log->kind_counts[SCANLOG_PLAIN]);
    fprintf(e, "input beams    %llu (bad ranges %llu, below min range %llu)\n",
            (unsigned long long)log->beams, (unsigned long long)log->bad_ranges,
            (unsigned long long)log->short_ranges);
    fprintf(e, "lines skipped  %llu (", (unsigned long long)log->skipped_lines);
    for (uint32_t i = 0; i < log->keyword_count; i++)
        fprintf(e, "%s%s %llu", i ? ", " : "", log->keywords[i].name,
                (unsigned long long)log->keywords[i].count);
    fprintf(e, "), blank %llu\n", (unsigned long long)log->blank_lines);
    const scanlog_noreturn *nr = &log->noreturn;
    if (log->kind_counts[SCANLOG_FLASER]) {
        if (nr->overridden)
            fprintf(e, "no-return      FLASER max range %.3f m (--max-range)\n",
                    (double)nr->max_range_m);
        else if (nr->found)
            fprintf(e, "no-return      FLASER max range %.3f m: code %.2f..%.2f m, mode %.2f m,"
                       " %llu beams at or above\n",
                    (double)nr->max_range_m, nr->code_lo_m, nr->code_hi_m, nr->code_mode_m,
                    (unsigned long long)nr->code_beams);
        else
            fprintf(e, "no-return      FLASER: no code found, every range is a hit (max range"
                       " %.3f m)\n",
                    (double)nr->max_range_m);
    }
}

static void print_map_stats(const map_input *m)
{
    static const char *const modes[] = {"trinary", "scale", "raw"};
    FILE *e = stderr;
    char *shown = textesc_dup(m->image_path);   /* no raw bytes on the terminal */
    fprintf(e, "map            %u x %u cells of %g m, %s (%s, maxval %u), mode %s%s\n",
            (unsigned)m->pgm.width, (unsigned)m->pgm.height, m->yaml.resolution_m,
            shown ? shown : "?", m->pgm.plain ? "P2" : "P5", (unsigned)m->pgm.maxval,
            modes[m->yaml.mode], m->yaml.negate ? ", negate" : "");
    free(shown);
    fprintf(e, "origin         %.6f %.6f m, yaw %.6f rad\n", m->yaml.origin_x_m,
            m->yaml.origin_y_m, m->yaml.origin_yaw_rad);
    fprintf(e, "cells          occupied %llu, free %llu, unknown %llu\n",
            (unsigned long long)m->occupied, (unsigned long long)m->free_cells,
            (unsigned long long)m->unknown);
}

static void print_stats(const options *o, const run *r, const polyc_stats *s,
                        const mapout_times *t, double output_ms, double total_ms)
{
    FILE *e = stderr;
    progress_clear();
    if (r->map) {
        print_map_stats(r->map);
    } else {
        print_input_stats(&r->log);
        fprintf(e, "beams          %llu (hits %llu, skipped by the library %llu)\n",
                (unsigned long long)s->beams, (unsigned long long)s->hits,
                (unsigned long long)s->beams_skipped);
    }
    fprintf(e, "points         %llu data points, %u weighted points\n",
            (unsigned long long)s->data_points, (unsigned)s->weighted_points);
    fprintf(e, "grid           %u x %u cells of %.4f m, %u tiles, %llu bytes\n",
            (unsigned)s->grid_width, (unsigned)s->grid_height,
            r->map ? (double)r->map->grid.resolution_m : (double)o->config.cell_m,
            (unsigned)s->grid_tiles, (unsigned long long)s->grid_bytes);
    fprintf(e, "contour cells  %u\n", (unsigned)s->contour_cells);
    fprintf(e, "initial        %u polylines, %u vertices\n", (unsigned)s->initial_polylines,
            (unsigned)s->initial_vertices);
    fprintf(e, "final          %u polylines, %u vertices, %u iterations\n",
            (unsigned)s->polylines, (unsigned)s->vertices, (unsigned)s->iterations);
    fprintf(e, "BIC            %.3f (error %.6f m^2)\n", s->bic, s->error_sq_m2);
    fprintf(e, "memory         block %llu bytes, used %llu bytes\n",
            (unsigned long long)s->memory_size_bytes, (unsigned long long)s->memory_used_bytes);
    fprintf(e, "time ms        %s %.1f, add %.1f, grid %.1f, contour %.1f, trace %.1f,"
               " optimize %.1f, output %.1f, total %.1f\n",
            r->map ? "read" : "parse", t->parse_ms, t->add_ms, t->grid_ms, t->contour_ms,
            t->trace_ms, t->optimize_ms, output_ms, total_ms);
}

/* ---- the run ---- */

/* Maps a library failure to a message and an exit code. */
static int library_fail(const char *stage, polyc_status st, const polyc_ctx *ctx, size_t block)
{
    const char *msg = ctx ? polyc_last_error(ctx) : NULL;
    if (st == POLYC_ERR_NOMEM)
        return complain(EXIT_MEMORY, "memory budget too small: need more than %zu bytes (%s: %s)",
                        block, stage, msg ? msg : polyc_status_str(st));
    return complain(EXIT_INPUT, "%s failed: %s%s%s", stage, polyc_status_str(st),
                    msg && *msg ? ": " : "", msg ? msg : "");
}

/* The block needs more than --memory-mb allows: say the MiB to give. */
static int budget_fail(const options *o, size_t size)
{
    double mib = (double)size / 1048576.0;
    return complain(EXIT_MEMORY, "memory budget too small: need %zu bytes (%.1f MiB), --memory-mb"
                                 " %g allows %g MiB: give --memory-mb %.0f or more",
                    size, mib, o->memory_mb, o->memory_mb, ceil(mib));
}

static int struct_sizes_match(void)
{
    return polyc_struct_size("polyc_config") == sizeof(polyc_config) &&
           polyc_struct_size("polyc_limits") == sizeof(polyc_limits) &&
           polyc_struct_size("polyc_scan") == sizeof(polyc_scan) &&
           polyc_struct_size("polyc_polyline") == sizeof(polyc_polyline) &&
           polyc_struct_size("polyc_stats") == sizeof(polyc_stats) &&
           polyc_struct_size("polyc_iteration") == sizeof(polyc_iteration) &&
           polyc_struct_size("polyc_occupancy_grid") == sizeof(polyc_occupancy_grid);
}

static int convert(const options *o, run *r)
{
    if (membuf_open(&r->out))
        return EXIT_INPUT;
    int bad = scanlog_write_plain(r->out.f, r->log.scans, r->log.count);
    if (membuf_close(&r->out, bad))
        return EXIT_INPUT;
    if (o->stats)
        print_input_stats(&r->log);
    const char *paths[] = {o->output};
    const membuf *bufs[] = {&r->out};
    return write_outputs(paths, bufs, 1);
}
static const char *input_name(const options *o)
{
    return strcmp(o->input, "-") == 0 ? "<stdin>" : o->input;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The data are too wide for the grid. Names the scan that reaches farthest
 * from the median pose (a far-away scan or hit is the usual cause), before
 * any memory is sized. */
static int extent_fail(const options *o, const scanlog *log, const polyc_config *cfg)
{
    uint32_t n = log->count;
    double *v = malloc(2 * (size_t)n * sizeof *v);
    if (!v)
        return complain(EXIT_INPUT, "%s: the data span more than %g m", input_name(o),
                        (double)cfg->max_extent_m);
    for (uint32_t i = 0; i < n; i++) {
        v[i] = log->scans[i].pose_x_m;
        v[n + i] = log->scans[i].pose_y_m;
    }
    qsort(v, n, sizeof *v, cmp_double);
    qsort(v + n, n, sizeof *v, cmp_double);
    double mx = v[n / 2], my = v[n + n / 2], worst = -1.0;
    free(v);
    polyc_box all = {1.0, 1.0, 0.0, 0.0};
    uint32_t far = 0;
    for (uint32_t i = 0; i < n; i++) {
        polyc_box b = {1.0, 1.0, 0.0, 0.0};
        polyc_scan_extent(cfg, &log->scans[i], &b);
        polyc_scan_extent(cfg, &log->scans[i], &all);
        double d = fmax(fmax(fabs(b.min_x_m - mx), fabs(b.max_x_m - mx)),
                        fmax(fabs(b.min_y_m - my), fabs(b.max_y_m - my)));
        if (b.min_x_m <= b.max_x_m && d > worst) {
            worst = d;
            far = i;
        }
    }
    double w = all.max_x_m - all.min_x_m, h = all.max_y_m - all.min_y_m;
    double pad = 4.0 * (double)cfg->cell_m;    /* the grid's margin (polyc_limits_for_scans) */
    const polyc_scan *s = &log->scans[far];
    if (w + pad > (double)cfg->max_extent_m || h + pad > (double)cfg->max_extent_m || worst < 0)
        return complain(EXIT_INPUT,
                        "%s:%llu: this scan (pose %.2f %.2f) reaches %.0f m from the median pose"
                        " (%.2f %.2f): the data would span %.0f x %.0f m (plus the grid's margin"
                        " of %g m), more than the grid's limit of %g m",
                        input_name(o), (unsigned long long)log->line_of_scan[far], s->pose_x_m,
                        s->pose_y_m, worst, mx, my, w, h, pad, (double)cfg->max_extent_m);
    return complain(EXIT_INPUT, "%s: the data span %.1f x %.1f m: more than 2^32 grid cells of"
                                " %g m (try a larger --cell)",
                    input_name(o), w, h, (double)cfg->cell_m);
}


/* ---- a ROS map in ---- */

/* Reads a whole regular file of at most max bytes into *data (malloc'd,
 * *len bytes). 0, an errno value, READ_TOO_LARGE if it holds more than max
 * bytes, or READ_NOT_FILE if it is not a regular file (a device, a FIFO:
 * opened without waiting for a writer, and not read). */
#define READ_TOO_LARGE (-1)
#define READ_NOT_FILE (-2)
static int read_whole(const char *path, size_t max, char **data, size_t *len)
{
    *data = NULL;
    *len = 0;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY);
    if (fd < 0)
        return errno;
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        int e = S_ISDIR(st.st_mode) ? EISDIR : READ_NOT_FILE;
        close(fd);
        return e;
    }
    FILE *f = fdopen(fd, "rb");
    if (!f) {
        close(fd);
        return errno;
    }
    size_t cap = 0, n = 0;
    char *buf = NULL;
    int err = 0;
    for (;;) {
        if (n == cap) {
            size_t ncap = cap ? cap * 2 : 65536;
            if (cap > max) {
                err = READ_TOO_LARGE;
                break;
            }
            char *nb = realloc(buf, ncap);
            if (!nb) {
                err = ENOMEM;
                break;
            }
            buf = nb;
            cap = ncap;
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0) {
            if (ferror(f))
                err = errno ? errno : EIO;
            break;
        }
    }
    fclose(f);
    if (!err && n > max)
        err = READ_TOO_LARGE;
    if (err) {
        free(buf);
        return err;
    }
    *data = buf;
    *len = n;
    return 0;
}

/* Reads the map YAML o->input, its image and converts it; 0 or an exit code. */
static int load_map(const options *o, map_input *m)
{
    char *text;
    size_t len;
    int err = read_whole(o->input, MAPFILE_MAX_YAML_BYTES, &text, &len);
    if (err == READ_TOO_LARGE)
        return complain(EXIT_INPUT, "%s: larger than %u bytes: not a map YAML", o->input,
                        MAPFILE_MAX_YAML_BYTES);
    if (err == READ_NOT_FILE)
        return complain(EXIT_INPUT, "%s: not a regular file", o->input);
    if (err)
        return complain(EXIT_INPUT, "%s: %s", o->input, strerror(err));
    int bad = mapfile_yaml_parse(&m->yaml, text, len, o->input);
    free(text);
    if (bad)
        return complain(EXIT_INPUT, "%s", m->yaml.error);
    if (!(m->image_path = mapfile_image_path(o->input, m->yaml.image)))
        return complain(EXIT_INPUT, "out of memory");
    char *shown = textesc_dup(m->image_path);
    if (!shown)
        return complain(EXIT_INPUT, "out of memory");
    err = read_whole(m->image_path, MAPFILE_MAX_PGM_BYTES, &text, &len);
    if (err) {
        unsigned line = (unsigned)m->yaml.image_line;
        int rc = err == READ_TOO_LARGE
                     ? complain(EXIT_INPUT, "%s:%u: image %s: larger than %u bytes", o->input, line,
                                shown, MAPFILE_MAX_PGM_BYTES)
                 : err == READ_NOT_FILE
                     ? complain(EXIT_INPUT, "%s:%u: image %s: not a regular file (a device or a"
                                            " FIFO): give a PGM file", o->input, line, shown)
                     : complain(EXIT_INPUT, "%s:%u: image %s: %s", o->input, line, shown,
                                strerror(err));
        free(shown);
        return rc;
    }
    bad = mapfile_pgm_parse(&m->pgm, (const uint8_t *)text, len, shown);
    free(text);
    free(shown);
    if (bad)
        return complain(EXIT_INPUT, "%s", m->pgm.error);
    size_t cells = (size_t)m->pgm.width * m->pgm.height;
    if (!(m->cells = malloc(cells)))
        return complain(EXIT_MEMORY, "memory budget too small: need %zu bytes for the map's cells",
                        cells);
    mapfile_to_cells(&m->pgm, &m->yaml, m->cells);
    mapfile_pgm_free(&m->pgm);            /* the samples are not needed any more */
    polyc_occupancy_grid *g = &m->grid;
    g->width = m->pgm.width;
    g->height = m->pgm.height;
    g->resolution_m = (float)m->yaml.resolution_m;
    g->reserved = 0;
    g->origin_x_m = m->yaml.origin_x_m;
    g->origin_y_m = m->yaml.origin_y_m;
    g->origin_yaw_rad = m->yaml.origin_yaw_rad;
    g->cells = m->cells;
    double occ = 100.0 * (double)o->config.occupied_thresh;
    double fre = 100.0 * (double)o->config.free_thresh;
    for (size_t i = 0; i < cells; i++) {
        int8_t v = m->cells[i];
        if (v >= 0 && (double)v >= occ)
            m->occupied++;
        else if (v >= 0 && (double)v <= fre)
            m->free_cells++;
        else
            m->unknown++;
    }
    return 0;
}

/* The library refused the map's grid (polyc_limits_for_grid, polyc_add_grid). */
static int map_fail(const options *o, const map_input *m, polyc_status st, const polyc_ctx *ctx,
                    size_t block)
{
    const polyc_config *c = &o->config;
    if (st == POLYC_ERR_EXTENT)
        return complain(EXIT_INPUT, "%s:%u: the map spans %.1f x %.1f m (%u x %u cells of %g m):"
                                    " more than the grid's limit of %g m",
                        o->input, (unsigned)m->yaml.resolution_line,
                        m->grid.width * m->yaml.resolution_m, m->grid.height * m->yaml.resolution_m,
                        (unsigned)m->grid.width, (unsigned)m->grid.height, m->yaml.resolution_m,
                        (double)c->max_extent_m);
    return library_fail("map", st, ctx, block);
}

/* ---- the map out ---- */

/* The log's scans into the context; 0, or the exit code of the complaint
 * (a scan the library rejects names its line). */
static int add_scans(const options *o, const run *r, polyc_ctx *ctx, size_t size)
{
    progress_stage("adding scans");
    for (uint32_t i = 0; i < r->log.count; i++) {
        polyc_status st = polyc_add_scan(ctx, &r->log.scans[i]);
        if (st == POLYC_OK)
            continue;
        if (st == POLYC_ERR_SCAN)
            return complain(EXIT_INPUT, "%s:%llu: scan rejected by the library: %s",
                            input_name(o), (unsigned long long)r->log.line_of_scan[i],
                            polyc_last_error(ctx));
        return library_fail("add scan", st, ctx, size);
    }
    return 0;
}

static int make_map(const options *o, run *r, double t_start, mapout_times *t)
{
    polyc_config cfg = o->config;
    polyc_limits lim;
    polyc_ctx *ctx = NULL;
    const polyc_occupancy_grid *grid = r->map ? &r->map->grid : NULL;
    polyc_status st = grid ? polyc_limits_for_grid(&cfg, grid, &lim)
                           : polyc_limits_for_scans(&cfg, r->log.scans, r->log.count, &lim);
    double t4 = 0.0;
    if (grid && st != POLYC_OK)
        return map_fail(o, r->map, st, NULL, 0);
    if (st == POLYC_ERR_EXTENT)
        return extent_fail(o, &r->log, &cfg);
    if (st != POLYC_OK)
        return library_fail("sizing", st, NULL, 0);
    /* polyc_limits_for_scans sizes vertices and data points for a usual
     * contour; a map that needs more is run again with the worst-case bound */
    size_t size = 0;
    for (int attempt = 0;; attempt++) {
        int retry = !grid && attempt == 0 && (lim.max_vertices != 0 || lim.max_points != 0);
        size = polyc_memory_size(&cfg, &lim);
        if (size == 0)
            return complain(EXIT_MEMORY, "memory budget too small: need more than %zu bytes",
                            (size_t)SIZE_MAX);
        if (o->memory_mb > 0 && (double)size > o->memory_mb * 1048576.0)
            return budget_fail(o, size);
        free(r->block);
        r->block = malloc(size);
        if (!r->block)
            return complain(EXIT_MEMORY, "memory budget too small: need %zu bytes (malloc failed)",
                            size);
        if ((st = polyc_init(r->block, size, &cfg, &lim, &ctx)) != POLYC_OK)
            return library_fail("init", st, ctx, size);

        double t0 = now_ms();
        if (grid) {
            /* the grid and its contour come with the map */
            progress_stage("map cells");
            if ((st = polyc_add_grid(ctx, grid)) != POLYC_OK)
                return map_fail(o, r->map, st, ctx, size);
        } else {
            int rc = add_scans(o, r, ctx, size);
            if (rc != 0)
                return rc;
        }
        double t1 = now_ms();
        t->add_ms = t1 - t0;
        if (!grid) {
            progress_stage("grid");
            if ((st = polyc_build_grid(ctx)) != POLYC_OK)
                return library_fail("grid", st, ctx, size);
        }
        double t2 = now_ms();
        t->grid_ms = t2 - t1;
        /* one scan's polylines come from its beam order (polyc_build skips
         * the contour too): it is needed only to trace it or to draw it */
        int want_contour = !grid && (r->log.count != 1 || o->grid || (cfg.flags & POLYC_FLAG_GRID_TRACE));
        progress_stage("contour");
        if (want_contour && (st = polyc_extract_contour(ctx)) != POLYC_OK)
            return library_fail("contour", st, ctx, size);
        double t3 = now_ms();
        t->contour_ms = t3 - t2;
        progress_stage("trace");
        st = polyc_trace(ctx);
        if (st == POLYC_ERR_NOMEM && retry) {
            lim.max_vertices = lim.max_points = 0;
            continue;
        }
        if (st != POLYC_OK)
            return library_fail("trace", st, ctx, size);
        t4 = now_ms();
        t->trace_ms = t4 - t3;
        if (o->trace && !r->trace.f) {
            if (membuf_open(&r->trace))
                return EXIT_INPUT;
            fputs("# iteration bic best_bic vertices polylines noise_m\n", r->trace.f);
        }
        if (!o->no_optimize && cfg.max_iterations > 0) {
            progress_stage("optimize");
            st = polyc_optimize(ctx, o->trace || prog.on ? on_iteration : NULL, r->trace.f);
            if (st == POLYC_ERR_NOMEM && retry) {
                lim.max_vertices = lim.max_points = 0;
                if (r->trace.f)
                    rewind(r->trace.f); /* (the rerun writes the same lines again) */
                continue;
            }
            if (st != POLYC_OK)
                return library_fail("optimize", st, ctx, size);
        }
        break;
    }
    double t5 = now_ms();
    t->optimize_ms = t5 - t4;
    progress_stage("writing");

    polyc_stats stats;
    double bic = 0, error_sq_m2 = 0;
    int scored = (o->no_optimize || cfg.max_iterations == 0) &&   /* the initial polylines */
                 polyc_score(ctx, &bic, &error_sq_m2) == POLYC_OK;
    if ((st = polyc_get_stats(ctx, &stats)) != POLYC_OK)
        return library_fail("stats", st, ctx, size);
    if (scored) {
        stats.bic = bic;
        stats.error_sq_m2 = error_sq_m2;
    }
    uint32_t n = polyc_polyline_count(ctx);
    r->lines = calloc(n ? n : 1, sizeof *r->lines);
    if (!r->lines)
        return complain(EXIT_INPUT, "out of memory");
    for (uint32_t i = 0; i < n; i++)
        if ((st = polyc_get_polyline(ctx, i, &r->lines[i])) != POLYC_OK)
            return library_fail("get polyline", st, ctx, size);

    mapout_map map;
    memset(&map, 0, sizeof map);
    map.lines = r->lines;
    map.line_count = n;
    map.stats = &stats;
    map.times = t;
    map.scans = o->points ? r->log.scans : NULL;
    map.scan_count = r->log.count;
    map.grid = o->grid ? ctx : NULL;
    map.contour_threshold = cfg.contour_threshold;
    map.vertices = o->vertices;
    map.color_lines = o->color_lines;
    map.title = input_name(o);
    map.cell_m = r->map ? r->map->yaml.resolution_m : (double)cfg.cell_m;
    map.total_ms = now_ms() - t_start;
    if (membuf_open(&r->out))
        return EXIT_INPUT;
    int bad = o->format == FORMAT_JSON  ? mapout_json(r->out.f, &map)
              : o->format == FORMAT_TXT ? mapout_txt(r->out.f, &map)
                                        : mapout_svg(r->out.f, &map);
    if (membuf_close(&r->out, bad))
        return EXIT_INPUT;
    if (o->trace && membuf_close(&r->trace, 0))
        return EXIT_INPUT;
    /* both outputs or neither */
    const char *paths[] = {o->output, o->trace};
    const membuf *bufs[] = {&r->out, &r->trace};
    int rc = write_outputs(paths, bufs, o->trace ? 2 : 1);
    double t6 = now_ms();
    if (o->stats)
        print_stats(o, r, &stats, t, t6 - t5, t6 - t_start);
    return rc;
}

/* ---- polyc grid: the hit/miss grid as map_saver's files ---- */

static int grid_files(const options *o, run *r, double t_start)
{
    polyc_config cfg = o->config;
    polyc_limits lim;
    polyc_ctx *ctx = NULL;
    polyc_status st = polyc_limits_for_scans(&cfg, r->log.scans, r->log.count, &lim);
    if (st == POLYC_ERR_EXTENT)
        return extent_fail(o, &r->log, &cfg);
    if (st != POLYC_OK)
        return library_fail("sizing", st, NULL, 0);
    size_t size = polyc_memory_size(&cfg, &lim);
    if (size == 0)
        return complain(EXIT_MEMORY, "memory budget too small: need more than %zu bytes",
                        (size_t)SIZE_MAX);
    if (o->memory_mb > 0 && (double)size > o->memory_mb * 1048576.0)
        return budget_fail(o, size);
    if (!(r->block = malloc(size)))
        return complain(EXIT_MEMORY, "memory budget too small: need %zu bytes (malloc failed)",
                        size);
    if ((st = polyc_init(r->block, size, &cfg, &lim, &ctx)) != POLYC_OK)
        return library_fail("init", st, ctx, size);
    int added = add_scans(o, r, ctx, size);
    if (added != 0)
        return added;
    progress_stage("grid");
    if ((st = polyc_build_grid(ctx)) != POLYC_OK)
        return library_fail("grid", st, ctx, size);
    gridimage *img = &r->image;
    int made = gridimage_make(ctx, img, &st);
    if (made == GRIDIMAGE_LIBRARY)
        return library_fail("grid", st, ctx, size);
    if (made == GRIDIMAGE_TOO_LARGE)
        return complain(EXIT_INPUT, "%s: the grid is %u x %u cells of %g m: more than the %u a"
                                    " map may have (try a larger --cell)",
                        input_name(o), (unsigned)img->width, (unsigned)img->height,
                        (double)img->cell_m, MAPFILE_MAX_CELLS);
    if (made != GRIDIMAGE_OK)
        return complain(EXIT_INPUT, "out of memory for %u x %u pixels", (unsigned)img->width,
                        (unsigned)img->height);
    progress_stage("writing");
    uint32_t w = img->width, h = img->height;
    float cell = img->cell_m;
    double ox = img->origin_x_m, oy = img->origin_y_m;
    const uint64_t *counts = img->counts;
    /* PREFIX.pgm and PREFIX.yaml; the YAML names the image by its base name */
    size_t plen = strlen(o->output);
    char *pgm_path = malloc(plen + 6), *yaml_path = malloc(plen + 6);
    int rc = 0;
    if (!pgm_path || !yaml_path) {
        rc = complain(EXIT_INPUT, "out of memory");
    } else {
        snprintf(pgm_path, plen + 6, "%s.pgm", o->output);
        snprintf(yaml_path, plen + 6, "%s.yaml", o->output);
        const char *slash = strrchr(pgm_path, '/');
        const char *image = slash ? slash + 1 : pgm_path;
        for (const char *q = image; *q && !rc; q++)
            if ((unsigned char)*q < 0x20 || *q == 0x7f)
                rc = complain(EXIT_USAGE, "-o PREFIX holds a control character");
        if (!rc && (membuf_open(&r->pgm) || membuf_open(&r->yaml)))
            rc = EXIT_INPUT;
        if (!rc) {
            int bad = mapfile_write_pgm(r->pgm.f, img->pixels, w, h, (double)cell);
            rc = membuf_close(&r->pgm, bad);
        }
        if (!rc) {
            int bad = mapfile_write_yaml(r->yaml.f, image, (double)cell, ox, oy);
            rc = membuf_close(&r->yaml, bad);
        }
        /* both files or neither; the image first, so that the YAML never
         * names a missing one */
        const char *paths[] = {pgm_path, yaml_path};
        const membuf *bufs[] = {&r->pgm, &r->yaml};
        if (!rc)
            rc = write_outputs(paths, bufs, 2);
    }
    free(pgm_path);
    free(yaml_path);
    progress_clear();
    if (!rc && o->stats) {
        print_input_stats(&r->log);
        fprintf(stderr, "grid           %u x %u cells of %.4f m, origin %.6f %.6f m\n",
                (unsigned)w, (unsigned)h, (double)cell, ox, oy);
        fprintf(stderr, "pixels         occupied %llu, free %llu, unknown %llu\n",
                (unsigned long long)counts[MAPFILE_PIXEL_OCCUPIED],
                (unsigned long long)counts[MAPFILE_PIXEL_FREE],
                (unsigned long long)counts[MAPFILE_PIXEL_UNKNOWN]);
        fprintf(stderr, "time ms        total %.1f\n", now_ms() - t_start);
    }
    return rc;
}

/* ---- which input ---- */

enum input_kind { INPUT_LOG, INPUT_MAP_YAML, INPUT_IMAGE };

/* A map YAML or an image is told from a log by its first bytes. Only a
 * regular file is looked at (a pipe would lose what is read); anything
 * unreadable is left to the log reader, which reports it. */
static enum input_kind sniff(const char *path)
{
    char head[65536];
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
        return INPUT_LOG;
    FILE *f = fopen(path, "rb");
    if (!f)
        return INPUT_LOG;
    size_t n = fread(head, 1, sizeof head, f);
    fclose(f);
    if (n >= 3 && head[0] == 'P' && (head[1] == '5' || head[1] == '2') &&
        (head[2] == ' ' || head[2] == '\n' || head[2] == '\r' || head[2] == '\t' || head[2] == '#'))
        return INPUT_IMAGE;
    if (n >= 8 && memcmp(head, "\x89PNG\r\n\x1a\n", 8) == 0)
        return INPUT_IMAGE;
    return mapfile_is_yaml(head, n) ? INPUT_MAP_YAML : INPUT_LOG;
}

/* Refuses (usage) the options given that are not in `allowed`. */
static int refuse_options(const options *o, unsigned allowed, const char *why)
{
    unsigned bad = o->given & ~allowed;
    for (size_t i = 0; bad && i < sizeof option_bits / sizeof option_bits[0]; i++)
        if (bad & option_bits[i].bit)
            return complain(EXIT_USAGE, "%s does not apply to %s", option_bits[i].name, why);
    return 0;
}

int main(int argc, char **argv)
{
    options o;
    run r;
    map_input map;
    outfile_signals();
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc < 0 ? 0 : rc;
    if (!struct_sizes_match())
        return complain(EXIT_INPUT, "libpolyc's structs differ from polyc.h (rebuild)");
    memset(&r, 0, sizeof r);
    memset(&map, 0, sizeof map);
    mapout_times t = {0, 0, 0, 0, 0, 0};
    double t_start = now_ms();
    prog.on = !o.quiet && isatty(STDERR_FILENO);
    prog.start_ms = prog.last_ms = t_start;
    enum input_kind kind = strcmp(o.input, "-") == 0 ? INPUT_LOG : sniff(o.input);
    if (kind == INPUT_IMAGE) {
        rc = complain(EXIT_INPUT, "%s: an image: give the map's YAML file (map_server's"
                                  " map.yaml), which names the image", o.input);
    } else if (kind == INPUT_MAP_YAML) {
        progress_stage("reading the map");
        if (o.command != CMD_MAP)
            rc = complain(EXIT_INPUT, "%s: a map YAML: polyc %s takes a laser log", o.input,
                          o.command == CMD_CONVERT ? "convert" : "grid");
        else if (!(rc = refuse_options(&o, ~(unsigned)OPTS_LOG_ONLY,
                                       "a map YAML (it acts on laser scans; a map's cells are its own)")) &&
                 !(rc = load_map(&o, &map))) {
            r.map = &map;
            t.parse_ms = now_ms() - t_start;
            if (o.grid && map.yaml.origin_yaw_rad != 0.0)
                rc = complain(EXIT_USAGE, "--grid draws the grid unrotated: not for a map whose"
                                          " origin has a yaw");
            else
                rc = make_map(&o, &r, t_start, &t);
        }
    } else {
        rc = o.command == CMD_GRID      ? refuse_options(&o, OPTS_GRID_CMD, "polyc grid")
             : o.command == CMD_CONVERT ? refuse_options(&o, OPTS_CONVERT_CMD, "polyc convert")
                                        : refuse_options(&o, ~(unsigned)OPTS_MAP_ONLY,
                                                         "a laser log");
        FILE *in = NULL;
        if (!rc) {
            progress_stage("reading the log");
            in = strcmp(o.input, "-") == 0 ? stdin : fopen(o.input, "rb");
            struct stat st;
            if (!in)
                rc = complain(EXIT_INPUT, "%s: %s", o.input, strerror(errno));
            else if (fstat(fileno(in), &st) == 0 && S_ISDIR(st.st_mode))
                rc = complain(EXIT_INPUT, "%s: %s: give a log file", o.input, strerror(EISDIR));
            if (rc && in && in != stdin)
                fclose(in);
        }
        if (!rc) {
            scanlog_opts so = {o.max_range_m};
            int bad = scanlog_read(&r.log, in, strcmp(o.input, "-") == 0 ? "<stdin>" : o.input, &so);
            if (in != stdin)
                fclose(in);
            t.parse_ms = now_ms() - t_start;
            if (bad)
                rc = complain(EXIT_INPUT, "%s", r.log.error);
            else
                rc = o.command == CMD_CONVERT ? convert(&o, &r)
                     : o.command == CMD_GRID  ? grid_files(&o, &r, t_start)
                                              : make_map(&o, &r, t_start, &t);
        }
    }
    progress_clear();
    membuf *bufs[] = {&r.trace, &r.out, &r.pgm, &r.yaml};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; i++) {
        if (bufs[i]->f)
            fclose(bufs[i]->f);
        free(bufs[i]->data);
    }
    free(r.lines);
    free(r.block);
    gridimage_free(&r.image);
    scanlog_free(&r.log);
    mapfile_yaml_free(&map.yaml);
    mapfile_pgm_free(&map.pgm);
    free(map.image_path);
    free(map.cells);
    return rc;
}
