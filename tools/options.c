/* options.c - the polyc tool's command line (cli.h).
 * Takes: argv. Gives: the options, the command and the input, each value
 * checked (the configuration by polyc_config_check), or a usage message. */
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "outfile.h"

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
    {"--vertices", OPT_VERTICES},     {"--color-lines", OPT_COLOR_LINES}, {"--online", OPT_ONLINE},
    {"--work", OPT_WORK},             {"--frames", OPT_FRAMES},     {"--every", OPT_EVERY},
    {"--no-arcs", OPT_NO_ARCS},       {"--max-chord-error", OPT_CHORD},
};

static const char usage_text[] =
    "usage: polyc [options] INPUT       learn a polyline map from a laser log or a ROS map\n"
    "       polyc convert [-o FILE] [--max-range M] INPUT\n"
    "                                   write the scans in polyc's plain format\n"
    "       polyc grid [--cell M] [--max-range M] -o PREFIX LOG\n"
    "                                   write the log's hit/miss grid as a ROS map:\n"
    "                                   PREFIX.pgm and PREFIX.yaml, as map_saver does\n"
    "                                   (-o office, office.pgm or office.yaml)\n"
    "INPUT is a CARMEN log (FLASER, ROBOTLASER1) or a plain scan file (- is stdin),\n"
    "or a ROS map_server map YAML (found by its content: key: value lines naming an\n"
    "image, a PGM or PNG). A map's cells are its own: --cell, --threshold,\n"
    "--max-range, --exact-points, --grid-trace and --points act on scans and are\n"
    "refused for a map; --occupied-thresh and --free-thresh apply to maps only.\n"
    "options:\n"
    "  --format svg|json|txt   output format (default: -o's extension, else svg)\n"
    "  -o, --output FILE       write FILE instead of stdout: .svg, .json or .txt (a\n"
    "                          file is replaced atomically, a device or FIFO written\n"
    "                          in place; an input, or a link another user left in\n"
    "                          /tmp, is refused)\n"
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
    "  --no-arcs               polylines only: no round thing drawn as a circle\n"
    "  --max-chord-error E     write each circle as a closed polyline within E metres\n"
    "                          of it, for readers that take lines only\n"
    "  --online                replay the log as a live stream: add each scan, update the\n"
    "                          map within a work budget, finish, then write it as above\n"
    "  --work N                --online: an update's budget in work units (default %u)\n"
    "  --frames DIR            --online: the map as SVG every --every scans into DIR\n"
    "                          (made if missing): DIR/frame-00050.svg, ...\n"
    "  --every N               --frames: scans between frames (default 50)\n"
    "  --help, --version\n"
    "exit codes: 0 ok, 1 bad input or other failure, 2 usage, 3 memory budget too small\n";

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
    } else if (strcmp(name, "--work") == 0) {
        if (parse_u64(val, UINT64_MAX, &u) || u == 0)
            return complain(EXIT_USAGE, "--work needs a budget of 1 or more work units, not"
                                        " '%s' (an update with no budget does nothing)", val);
        o->work = u;
    } else if (strcmp(name, "--every") == 0) {
        if (parse_u64(val, UINT32_MAX, &u) || u == 0)
            return complain(EXIT_USAGE, "--every needs 1..%u scans, not '%s'", UINT32_MAX, val);
        o->every = (uint32_t)u;
    } else if (strcmp(name, "--frames") == 0) {
        o->frames = val;
    } else if (strcmp(name, "--max-chord-error") == 0) {
        if (parse_double(val, 1e-4, 1.0, &d))
            return complain(EXIT_USAGE, "--max-chord-error needs metres in [0.0001, 1], not '%s'",
                            val);
        o->max_chord_m = d;
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
    else if (strcmp(name, "--online") == 0)
        o->online = 1;
    else if (strcmp(name, "--no-arcs") == 0) {
        o->no_arcs = 1;
        o->config.flags |= POLYC_FLAG_NO_ARCS;
    } else
        return -1;
    return 0;
}

static int takes_value(const char *name)
{
    static const char *const names[] = {"--format", "-o",          "--output",    "--trace",
                                        "--seed",   "--iterations", "--max-range", "--memory-mb",
                                        "--cell",   "--threshold", "--alpha",     "--gamma",
                                        "--occupied-thresh", "--free-thresh", "--work",
                                        "--frames", "--every", "--max-chord-error"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(name, names[i]) == 0)
            return 1;
    return 0;
}

/* The extension of path's last component (after its last '.', not a
 * leading one), or NULL. */
static const char *extension(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    return dot && dot != base && dot[1] ? dot + 1 : NULL;
}

/* 1 if path ends with ext, in any case. */
static int ends_with(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    if (n < e)
        return 0;
    for (size_t i = 0; i < e; i++)
        if (tolower((unsigned char)path[n - e + i]) != ext[i])
            return 0;
    return 1;
}

/* The format -o's extension names (.svg, .json, .txt, in any case), or -1. */
static int format_of_name(const char *path)
{
    static const char *const ext[] = {".svg", ".json", ".txt"};
    const char *x = extension(path);
    for (int f = 0; x && f < 3; f++)
        if (ends_with(path, ext[f]) && strlen(x) + 1 == strlen(ext[f]))
            return f;
    return -1;
}

/* 1 if path has an extension that names a format of its own, which polyc
 * does not write: letters and digits after the dot, at least one a letter
 * (map.png, map.pdf; not run.2 nor a name such as /dev/null). A device,
 * FIFO or descriptor name is never refused. */
static int other_extension(const char *path)
{
    const char *x = extension(path);
    struct stat st;
    int letter = 0;
    if (!x || format_of_name(path) >= 0 || strlen(x) > 8 ||
        (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) || strncmp(path, "/dev/", 5) == 0 ||
        strncmp(path, "/proc/", 6) == 0)
        return 0;
    for (; *x; x++) {
        if (!isalnum((unsigned char)*x))
            return 0;
        letter |= isalpha((unsigned char)*x) != 0;
    }
    return letter;
}

size_t grid_prefix_len(const char *output)
{
    static const char *const ext[] = {".pgm", ".yaml"};
    size_t n = strlen(output);
    for (int k = 0; k < 2; k++) {
        size_t e = strlen(ext[k]);
        if (n > e && output[n - e - 1] != '/' && ends_with(output, ext[k]))
            return n - e;
    }
    return n;
}

/* Refuses (usage) an output that is an input, before any work: the same
 * regular file (device and inode, through links; stdout and stdin too). */
static int check_not_input(const char *what, const char *path, const char *input)
{
    if (!outfile_is_input(path, input))
        return 0;
    const char *in = strcmp(input, "-") == 0 ? "stdin" : input;
    return path && strcmp(path, "-") != 0
               ? complain(EXIT_USAGE, "%s '%s' is the input '%s' (the same file): it would be"
                                      " replaced; give another name", what, path, in)
               : complain(EXIT_USAGE, "stdout is the input '%s' (the same file): give -o another"
                                      " name", in);
}

/* Refuses (usage) outputs that cannot be written as asked, before any work:
 * an empty or directory name, a name in a missing or unwritable folder, a
 * symlink not to follow, -o and --trace naming the same file, an output
 * that is the input, an extension polyc does not write, a --format that
 * -o's extension contradicts; else takes the format from it. */
static int check_outputs(options *o)
{
    const char *why;
    int rc;
    if (o->command == CMD_GRID) {
        size_t n = grid_prefix_len(o->output);
        char *p = malloc(n + 6);
        if (!p)
            return complain(EXIT_INPUT, "out of memory");
        snprintf(p, n + 6, "%.*s", (int)n, o->output);
        rc = 0;
        why = n == 0 ? "is empty" : outfile_check(o->output);
        if (!why && (format_of_name(p) >= 0 || other_extension(p)))
            rc = complain(EXIT_USAGE, "-o PREFIX '%s': polyc grid writes PREFIX.pgm and"
                                      " PREFIX.yaml (-o office, office.pgm or office.yaml), not"
                                      " a .%s file", o->output, extension(p));
        for (int i = 0; i < 2 && !why && !rc; i++) {
            snprintf(p, n + 6, "%.*s%s", (int)n, o->output, i ? ".yaml" : ".pgm");
            if (!(why = outfile_check(p)))
                rc = check_not_input("-o", p, o->input);
        }
        free(p);
        return why ? complain(EXIT_USAGE, "-o PREFIX '%s' %s (polyc grid writes PREFIX.pgm and"
                                          " PREFIX.yaml)", o->output, why)
                   : rc;
    }
    if ((why = outfile_check(o->output)))
        return complain(EXIT_USAGE, "-o '%s' %s", o->output, why);
    if ((why = outfile_check(o->trace)))
        return complain(EXIT_USAGE, "--trace '%s' %s", o->trace, why);
    if (o->trace && outfile_same(o->output, o->trace))
        return complain(EXIT_USAGE, "-o and --trace name the same file ('%s', '%s')",
                        o->output ? o->output : "-", o->trace);
    if ((rc = check_not_input("-o", o->output, o->input)) != 0 ||
        (o->trace && (rc = check_not_input("--trace", o->trace, o->input)) != 0))
        return rc;
    if (o->command != CMD_MAP || !o->output)
        return 0;
    int f = format_of_name(o->output);
    static const char *const names[] = {"svg", "json", "txt"};
    if (f < 0 && !(o->given & OPT_FORMAT) && other_extension(o->output))
        return complain(EXIT_USAGE, "-o '%s': polyc writes .svg, .json or .txt, not .%s (or"
                                    " give --format to write that name)", o->output,
                        extension(o->output));
    if (f >= 0 && (o->given & OPT_FORMAT) && (int)o->format != f)
        return complain(EXIT_USAGE, "--format %s contradicts -o %s (a .%s name)",
                        names[o->format], o->output, names[f]);
    if (f >= 0)
        o->format = (enum format)f;
    return 0;
}

/* --work, --frames and --every with --online only, --every with --frames;
 * --frames naming a folder (or a new name). Before any work. */
static int check_online(const options *o)
{
    struct stat st;
    if (!o->online)
        return refuse_options(o, ~(unsigned)OPTS_ONLINE, "a batch run (give --online)");
    if ((o->given & OPT_EVERY) && !o->frames)
        return complain(EXIT_USAGE, "--every needs --frames DIR");
    if (o->no_optimize)
        return complain(EXIT_USAGE, "--no-optimize does not apply to --online (its map is"
                                    " always optimised)");
    if (o->frames && !*o->frames)
        return complain(EXIT_USAGE, "--frames '' is empty: give a folder");
    if (o->frames && stat(o->frames, &st) == 0 && !S_ISDIR(st.st_mode))
        return complain(EXIT_USAGE, "--frames '%s' is not a folder", o->frames);
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

int parse_args(int argc, char **argv, options *o)
{
    const char *positional[2];
    int npos = 0, only_files = 0;
    memset(o, 0, sizeof *o);
    polyc_config_default(&o->config);
    o->work = POLYC_ONLINE_WORK_DEFAULT;
    o->every = 50;
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
            printf(usage_text, (unsigned)POLYC_ONLINE_WORK_DEFAULT);
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
    if (!rc)
        rc = check_online(o);
    if (rc)
        return rc;
    const char *why = NULL;
    if (polyc_config_check(&o->config, &why) != POLYC_OK)
        return config_fail(why ? why : "?");
    return 0;
}

int refuse_options(const options *o, unsigned allowed, const char *why)
{
    unsigned bad = o->given & ~allowed;
    for (size_t i = 0; bad && i < sizeof option_bits / sizeof option_bits[0]; i++)
        if (bad & option_bits[i].bit)
            return complain(EXIT_USAGE, "%s does not apply to %s", option_bits[i].name, why);
    return 0;
}
