/* polyc.c - the command-line tool: a laser log in, a polyline map out.
 *   polyc [options] INPUT        map as SVG (default), JSON or TXT
 *   polyc convert INPUT          the scans in the plain format
 * Exit codes: 0 ok, 1 bad input or other failure, 2 usage, 3 memory budget.
 * Formats and rules: docs/formats.md. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "mapout.h"
#include "polyc.h"
#include "scanlog.h"

#define EXIT_INPUT 1
#define EXIT_USAGE 2
#define EXIT_MEMORY 3
#define TOOL_VERSION "0.1.0"

enum format { FORMAT_SVG, FORMAT_JSON, FORMAT_TXT };

typedef struct options {
    const char *input;
    const char *output;        /* NULL or "-": stdout */
    const char *trace;
    int convert;
    enum format format;
    int stats, no_optimize, points, grid, vertices;
    double max_range_m;        /* 0: detect */
    double memory_mb;          /* 0: no cap */
    polyc_config config;
} options;

static const char usage_text[] =
    "usage: polyc [options] INPUT       learn a polyline map from a laser log\n"
    "       polyc convert [-o FILE] [--max-range M] INPUT\n"
    "                                   write the scans in polyc's plain format\n"
    "INPUT is a CARMEN log (FLASER, ROBOTLASER1) or a plain scan file; - is stdin.\n"
    "options:\n"
    "  --format svg|json|txt   output format (default svg)\n"
    "  -o, --output FILE       write FILE (atomically) instead of stdout\n"
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
    "  --points, --grid, --vertices\n"
    "                          SVG layers: scan endpoints, grid cells, vertex dots\n"
    "  --help, --version\n"
    "exit codes: 0 ok, 1 bad input or other failure, 2 usage, 3 memory budget too small\n";

static int complain(int code, const char *fmt, ...)
{
    va_list ap;
    fputs("polyc: ", stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    if (code == EXIT_USAGE)
        fputs("try 'polyc --help'\n", stderr);
    return code;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
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
            return complain(EXIT_USAGE, "--memory-mb needs a positive number, not '%s'", val);
        o->memory_mb = d;
    } else {
        /* float config fields; polyc_config_check judges the values */
        float *field = strcmp(name, "--cell") == 0        ? &o->config.cell_m
                       : strcmp(name, "--threshold") == 0 ? &o->config.contour_threshold
                       : strcmp(name, "--alpha") == 0     ? &o->config.alpha
                       : strcmp(name, "--gamma") == 0     ? &o->config.gamma
                                                          : NULL;
        if (!field)
            return complain(EXIT_USAGE, "unknown option '%s'", name);
        if (parse_double(val, -1e30, 1e30, &d))
            return complain(EXIT_USAGE, "%s needs a number, not '%s'", name, val);
        *field = (float)d;
    }
    return 0;
}

static int set_flag(options *o, const char *name)
{
    if (strcmp(name, "--stats") == 0)
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
    else
        return -1;
    return 0;
}

static int takes_value(const char *name)
{
    static const char *const names[] = {"--format", "-o",          "--output",    "--trace",
                                        "--seed",   "--iterations", "--max-range", "--memory-mb",
                                        "--cell",   "--threshold", "--alpha",     "--gamma"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(name, names[i]) == 0)
            return 1;
    return 0;
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
            uint32_t v = polyc_version();
            printf("polyc %s (libpolyc %u.%u.%u)\n", TOOL_VERSION, (unsigned)(v / 10000),
                   (unsigned)(v / 100 % 100), (unsigned)(v % 100));
            return -1;
        } else if (set_flag(o, a) == 0) {
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
        }
    }
    if (npos >= 1 && strcmp(positional[0], "convert") == 0) {
        o->convert = 1;
        positional[0] = npos == 2 ? positional[1] : NULL;
        npos--;
    }
    if (npos != 1 || !positional[0])
        return complain(EXIT_USAGE, npos == 0 ? "no input file" : "too many arguments");
    o->input = positional[0];
    const char *why = NULL;
    if (polyc_config_check(&o->config, &why) != POLYC_OK)
        return complain(EXIT_USAGE, "bad option value: %s", why ? why : "?");
    return 0;
}

/* ---- output: all or nothing ---- */

/* An output written in two steps, so that a run with two outputs (the map
 * and --trace) writes both or neither: emit_prepare writes a file's bytes to
 * a temporary file in the same directory, emit_commit renames it over the
 * file (or writes stdout), emit_abort removes what is left. */
typedef struct pending {
    const char *path;          /* NULL or "-": stdout, written at commit */
    const char *data;
    size_t len;
    char *tmp;                 /* the prepared temporary file, or NULL */
} pending;

static int emit_file(const char *path, const char *data, size_t len, char **tmp_out);

static int emit_prepare(pending *p, const char *path, const char *data, size_t len)
{
    p->path = path;
    p->data = data;
    p->len = len;
    p->tmp = NULL;
    if (!path || strcmp(path, "-") == 0)
        return 0;
    return emit_file(path, data, len, &p->tmp);
}

static int emit_commit(pending *p)
{
    if (!p->path || strcmp(p->path, "-") == 0) {
        if (fwrite(p->data, 1, p->len, stdout) != p->len || fflush(stdout) != 0)
            return complain(EXIT_INPUT, "writing stdout: %s", strerror(errno));
        return 0;
    }
    int err = rename(p->tmp, p->path) != 0 ? errno : 0;
    if (err)
        unlink(p->tmp);
    free(p->tmp);
    p->tmp = NULL;
    return err ? complain(EXIT_INPUT, "%s: %s", p->path, strerror(err)) : 0;
}

static void emit_abort(pending *p)
{
    if (p->tmp) {
        unlink(p->tmp);
        free(p->tmp);
        p->tmp = NULL;
    }
}

/* Writes len bytes to stdout, or to path through a temporary file in the
 * same directory renamed over it, so that a failure never leaves a partial
 * file. Returns 0 or EXIT_INPUT with a message. */
static int emit(const char *path, const char *data, size_t len)
{
    pending p;
    int rc = emit_prepare(&p, path, data, len);
    return rc ? rc : emit_commit(&p);
}

/* The bytes in a synced temporary file next to path; *tmp_out gets its
 * name (to rename or remove). 0 or EXIT_INPUT with a message. */
static int emit_file(const char *path, const char *data, size_t len, char **tmp_out)
{
    size_t n = strlen(path);
    char *tmp = malloc(n + 16);
    if (!tmp)
        return complain(EXIT_INPUT, "out of memory");
    memcpy(tmp, path, n);
    memcpy(tmp + n, ".tmpXXXXXX", 11);
    int fd = mkstemp(tmp);
    if (fd < 0) {
        int e = errno;
        free(tmp);
        return complain(EXIT_INPUT, "%s: cannot create a temporary file: %s", path, strerror(e));
    }
    mode_t mask = umask(0);            /* mkstemp makes 0600; give the usual mode */
    umask(mask);
    int err = fchmod(fd, 0666 & ~mask) ? errno : 0;
    for (size_t done = 0; !err && done < len;) {
        ssize_t w = write(fd, data + done, len - done);
        if (w < 0 && errno != EINTR)
            err = errno;
        else if (w > 0)
            done += (size_t)w;
    }
    if (!err && fsync(fd) != 0)
        err = errno;
    if (close(fd) != 0 && !err)
        err = errno;
    if (err) {
        unlink(tmp);
        free(tmp);
        return complain(EXIT_INPUT, "%s: %s", path, strerror(err));
    }
    *tmp_out = tmp;
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

/* ---- the optimiser trace ---- */

static int on_iteration(void *user, const polyc_iteration *it)
{
    FILE *f = user;
    fprintf(f, "%u %.6f %.6f %u %u %.6f\n", (unsigned)it->iteration, it->bic, it->best_bic,
            (unsigned)it->vertices, (unsigned)it->polylines, it->noise_m);
    return 0;
}

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

static void print_stats(const options *o, const scanlog *log, const polyc_stats *s,
                        const mapout_times *t, double output_ms, double total_ms)
{
    FILE *e = stderr;
    print_input_stats(log);
    fprintf(e, "beams          %llu (hits %llu, skipped by the library %llu)\n",
            (unsigned long long)s->beams, (unsigned long long)s->hits,
            (unsigned long long)s->beams_skipped);
    fprintf(e, "points         %llu data points, %u weighted points\n",
            (unsigned long long)s->data_points, (unsigned)s->weighted_points);
    fprintf(e, "grid           %u x %u cells of %.4f m, %u tiles, %llu bytes\n",
            (unsigned)s->grid_width, (unsigned)s->grid_height, (double)o->config.cell_m,
            (unsigned)s->grid_tiles, (unsigned long long)s->grid_bytes);
    fprintf(e, "contour cells  %u\n", (unsigned)s->contour_cells);
    fprintf(e, "initial        %u polylines, %u vertices\n", (unsigned)s->initial_polylines,
            (unsigned)s->initial_vertices);
    fprintf(e, "final          %u polylines, %u vertices, %u iterations\n",
            (unsigned)s->polylines, (unsigned)s->vertices, (unsigned)s->iterations);
    fprintf(e, "BIC            %.3f (error %.6f m^2)\n", s->bic, s->error_sq_m2);
    fprintf(e, "memory         block %llu bytes, used %llu bytes\n",
            (unsigned long long)s->memory_size_bytes, (unsigned long long)s->memory_used_bytes);
    fprintf(e, "time ms        parse %.1f, add %.1f, grid %.1f, contour %.1f, trace %.1f,"
               " optimize %.1f, output %.1f, total %.1f\n",
            t->parse_ms, t->add_ms, t->grid_ms, t->contour_ms, t->trace_ms, t->optimize_ms,
            output_ms, total_ms);
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
                    msg ? ": " : "", msg ? msg : "");
}

static int struct_sizes_match(void)
{
    return polyc_struct_size("polyc_config") == sizeof(polyc_config) &&
           polyc_struct_size("polyc_limits") == sizeof(polyc_limits) &&
           polyc_struct_size("polyc_scan") == sizeof(polyc_scan) &&
           polyc_struct_size("polyc_polyline") == sizeof(polyc_polyline) &&
           polyc_struct_size("polyc_stats") == sizeof(polyc_stats) &&
           polyc_struct_size("polyc_iteration") == sizeof(polyc_iteration);
}

typedef struct run {
    scanlog log;
    void *block;
    polyc_polyline *lines;
    membuf out, trace;
} run;

static int convert(const options *o, run *r)
{
    if (membuf_open(&r->out))
        return EXIT_INPUT;
    int bad = scanlog_write_plain(r->out.f, r->log.scans, r->log.count);
    if (membuf_close(&r->out, bad))
        return EXIT_INPUT;
    if (o->stats)
        print_input_stats(&r->log);
    return emit(o->output, r->out.data, r->out.len);
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
    const polyc_scan *s = &log->scans[far];
    if (w > (double)cfg->max_extent_m || h > (double)cfg->max_extent_m || worst < 0)
        return complain(EXIT_INPUT,
                        "%s:%llu: this scan (pose %.2f %.2f) reaches %.0f m from the median pose"
                        " (%.2f %.2f): the data would span %.0f x %.0f m, more than the grid's"
                        " limit of %g m",
                        input_name(o), (unsigned long long)log->line_of_scan[far], s->pose_x_m,
                        s->pose_y_m, worst, mx, my, w, h, (double)cfg->max_extent_m);
    return complain(EXIT_INPUT, "%s: the data span %.1f x %.1f m: more than 2^32 grid cells of"
                                " %g m (try a larger --cell)",
                    input_name(o), w, h, (double)cfg->cell_m);
}

static int make_map(const options *o, run *r, double t_start, mapout_times *t)
{
    polyc_config cfg = o->config;
    polyc_limits lim;
    polyc_ctx *ctx = NULL;
    polyc_status st = polyc_limits_for_scans(&cfg, r->log.scans, r->log.count, &lim);
    double t4 = 0.0;
    if (st == POLYC_ERR_EXTENT)
        return extent_fail(o, &r->log, &cfg);
    if (st != POLYC_OK)
        return library_fail("sizing", st, NULL, 0);
    /* polyc_limits_for_scans sizes vertices and data points for a usual
     * contour; a map that needs more is run again with the worst-case bound */
    size_t size = 0;
    for (int attempt = 0;; attempt++) {
        int retry = attempt == 0 && (lim.max_vertices != 0 || lim.max_points != 0);
        size = polyc_memory_size(&cfg, &lim);
        if (size == 0)
            return complain(EXIT_MEMORY, "memory budget too small: need more than %zu bytes",
                            (size_t)SIZE_MAX);
        if (o->memory_mb > 0 && (double)size > o->memory_mb * 1048576.0)
            return complain(EXIT_MEMORY, "memory budget too small: need %zu bytes", size);
        free(r->block);
        r->block = malloc(size);
        if (!r->block)
            return complain(EXIT_MEMORY, "memory budget too small: need %zu bytes (malloc failed)",
                            size);
        if ((st = polyc_init(r->block, size, &cfg, &lim, &ctx)) != POLYC_OK)
            return library_fail("init", st, ctx, size);

        double t0 = now_ms();
        for (uint32_t i = 0; i < r->log.count; i++)
            if ((st = polyc_add_scan(ctx, &r->log.scans[i])) != POLYC_OK) {
                if (st == POLYC_ERR_SCAN)
                    return complain(EXIT_INPUT, "%s:%llu: scan rejected by the library: %s",
                                    input_name(o), (unsigned long long)r->log.line_of_scan[i],
                                    polyc_last_error(ctx));
                return library_fail("add scan", st, ctx, size);
            }
        double t1 = now_ms();
        t->add_ms = t1 - t0;
        if ((st = polyc_build_grid(ctx)) != POLYC_OK)
            return library_fail("grid", st, ctx, size);
        double t2 = now_ms();
        t->grid_ms = t2 - t1;
        /* one scan's polylines come from its beam order (polyc_build skips
         * the contour too): it is needed only to trace it or to draw it */
        int want_contour = r->log.count != 1 || o->grid || (cfg.flags & POLYC_FLAG_GRID_TRACE);
        if (want_contour && (st = polyc_extract_contour(ctx)) != POLYC_OK)
            return library_fail("contour", st, ctx, size);
        double t3 = now_ms();
        t->contour_ms = t3 - t2;
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
            st = polyc_optimize(ctx, o->trace ? on_iteration : NULL, r->trace.f);
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
    pending map_out, trace_out;
    memset(&trace_out, 0, sizeof trace_out);
    int rc = emit_prepare(&map_out, o->output, r->out.data, r->out.len);
    if (!rc && o->trace)
        rc = emit_prepare(&trace_out, o->trace, r->trace.data, r->trace.len);
    if (!rc)
        rc = emit_commit(&map_out);
    if (!rc && o->trace)
        rc = emit_commit(&trace_out);
    emit_abort(&map_out);
    emit_abort(&trace_out);
    double t6 = now_ms();
    if (o->stats)
        print_stats(o, &r->log, &stats, t, t6 - t5, t6 - t_start);
    return rc;
}

int main(int argc, char **argv)
{
    options o;
    run r;
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc < 0 ? 0 : rc;
    if (!struct_sizes_match())
        return complain(EXIT_INPUT, "libpolyc's structs differ from polyc.h (rebuild)");
    memset(&r, 0, sizeof r);
    mapout_times t = {0, 0, 0, 0, 0, 0};
    double t_start = now_ms();
    FILE *in = strcmp(o.input, "-") == 0 ? stdin : fopen(o.input, "rb");
    if (!in)
        return complain(EXIT_INPUT, "%s: %s", o.input, strerror(errno));
    scanlog_opts so = {o.max_range_m};
    int bad = scanlog_read(&r.log, in, strcmp(o.input, "-") == 0 ? "<stdin>" : o.input, &so);
    if (in != stdin)
        fclose(in);
    t.parse_ms = now_ms() - t_start;
    if (bad)
        rc = complain(EXIT_INPUT, "%s", r.log.error);
    else
        rc = o.convert ? convert(&o, &r) : make_map(&o, &r, t_start, &t);
    if (r.trace.f)
        fclose(r.trace.f);
    if (r.out.f)
        fclose(r.out.f);
    free(r.trace.data);
    free(r.out.data);
    free(r.lines);
    free(r.block);
    scanlog_free(&r.log);
    return rc;
}
