/* mapscore.c - the topology and band figures of one map against one log.
 *
 *   mapscore LOG [MAP.txt]
 *
 * Takes a scan log (read by tools/scanlog, as the CLI reads it) and a map
 * in the TXT format `polyc --format txt` writes (docs/formats.md); without
 * a map, maps the log with the library's defaults (tools/eval/pipeline.h,
 * as the bench does). Gives one row: the map's size, its topology figures
 * (tools/eval/gttopo.h) and its bands (tools/eval/gtband.h) against the
 * log's scan endpoints. No ground truth needed. Exit codes: 0 ok, 1 the
 * log, the map or the library failed, 2 usage.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gtband.h"
#include "gtround.h"
#include "gttopo.h"
#include "pipeline.h"
#include "polyc.h"
#include "scanlog.h"

#define EXIT_FAILED 1
#define EXIT_USAGE 2

static const char usage_text[] =
    "usage: mapscore [--runs] LOG [MAP.txt]\n"
    "Scores MAP (as `polyc --format txt` writes it; without MAP: the log mapped\n"
    "with the library's defaults) against LOG's scan endpoints, one row:\n"
    "lines, verts, params (2 a vertex, 1 an arc, 3 a circle), arcs, circ(les);\n"
    "len = map length (m); dcov (m, and % of len), cross, uns20,\n"
    "uns10, loose (tools/eval/gttopo.h); band15 = map length drawn as a band of\n"
    "parallel lines seen from the same side (m, and % of len); end20, end10,\n"
    "end5 = share of endpoints within 20 / 10 / 5 cm of the map\n"
    "(tools/eval/gtband.h, docs/evaluation.md); libms = the library's time\n"
    "(without MAP; 0 with it), scorems = the scorers' time.\n"
    "--runs: then each run band15 counts, one a line: `run X0 Y0 X1 Y1 LEN`\n"
    "(its ends on its segment and its length, metres), to find where a map\n"
    "draws a wall as a band.\n"
    "Exit: 0 ok; 1 the log, the map or the library failed; 2 usage.\n";

/* Adds n floats of v to the growing array *a (*len of *cap). 0 or -1. */
static int push(float **a, size_t *len, size_t *cap, const float *v, size_t n)
{
    if (*len + n > *cap) {
        size_t c = *cap ? *cap : 1024;
        while (c < *len + n)
            c *= 2;
        float *q = realloc(*a, c * sizeof *q);
        if (!q)
            return -1;
        *a = q;
        *cap = c;
    }
    memcpy(*a + *len, v, n * sizeof *v);
    *len += n;
    return 0;
}

/* One line's polyline or circle, the m->count-th, into m (its points
 * from *xy_len on). 0, or -1 when the line is not one. */
static int read_item(char *p, curves_map *m, size_t *xy_len, size_t *xy_cap, size_t *b_len,
                     size_t *b_cap)
{
    char *end, word[16];
    int used = 0;
    polyc_polyline *pl = &m->lines[m->count];
    polyc_circle *cc = &m->circ[m->count];
    memset(pl, 0, sizeof *pl);
    memset(cc, 0, sizeof *cc);
    if (sscanf(p, "%15s%n", word, &used) != 1)
        return -1;
    p += used;
    if (strcmp(word, "circle") == 0) {
        if (sscanf(p, "%f %f %f", &cc->center_x_m, &cc->center_y_m, &cc->radius_m) != 3 ||
            !(cc->radius_m > 0.0f))
            return -1;
        cc->same_as = m->count;
        m->circles++;
        return 0;
    }
    unsigned long n = strtoul(p, &end, 10);
    if ((strcmp(word, "open") != 0 && strcmp(word, "closed") != 0) || end == p || n == 0 ||
        n > 100000000ul)
        return -1;
    p = end;
    for (unsigned long k = 0; k < 2u * n; k++) {
        float v = strtof(p, &end);
        if (end == p || push(&m->xy, xy_len, xy_cap, &v, 1) != 0)
            return -1;
        p = end;
    }
    pl->point_count = (uint32_t)n;
    pl->closed = strcmp(word, "closed") == 0;
    /* the bulges, one a segment (the closing one too), padded to one a point */
    unsigned long nb = 0, want = pl->closed ? n : n - 1;
    float b = 0.0f;
    while (*p == ' ')
        p++;
    if (strncmp(p, "bulges", 6) == 0)
        for (p += 6; nb < want; nb++, p = end) {
            b = strtof(p, &end);
            if (end == p || push(&m->bulge, b_len, b_cap, &b, 1) != 0)
                return -1;
            m->arcs += b != 0.0f;
        }
    for (b = 0.0f; nb < n; nb++)
        if (push(&m->bulge, b_len, b_cap, &b, 1) != 0)
            return -1;
    while (*p == ' ' || *p == '\n' || *p == '\r')
        p++;
    return *p ? -1 : 0;
}

/* A TXT map (docs/formats.md) into m: per line "open|closed N x1 y1 ...
 * xN yN [bulges b1 ...]" or "circle X Y R" (a polyline of no points whose
 * m->circ entry holds it). -1 with a message on stderr when the file is
 * not such a map (curves_free either way). */
static int read_txt_map(const char *path, curves_map *m)
{
    FILE *f = fopen(path, "r");
    char *line = NULL;
    size_t line_cap = 0, xy_len = 0, xy_cap = 0, b_len = 0, b_cap = 0;
    uint32_t cap = 0, *first = NULL;
    int rc = -1;
    memset(m, 0, sizeof *m);
    if (!f) {
        fprintf(stderr, "mapscore: %s: %s\n", path, strerror(errno));
        return -1;
    }
    while (getline(&line, &line_cap, f) > 0) {
        if (strspn(line, " \t\r\n") == strlen(line))
            continue;
        if (m->count == cap) {
            cap = cap ? 2u * cap : 64u;
            polyc_polyline *l = realloc(m->lines, cap * sizeof *l);
            if (l)
                m->lines = l;
            polyc_circle *c = realloc(m->circ, cap * sizeof *c);
            if (c)
                m->circ = c;
            uint32_t *q = realloc(first, cap * sizeof *q);
            if (q)
                first = q;
            if (!l || !c || !q)
                goto done;
        }
        first[m->count] = (uint32_t)(xy_len / 2);
        if (read_item(line, m, &xy_len, &xy_cap, &b_len, &b_cap) != 0)
            goto done;
        m->count++;
    }
    if (ferror(f))
        goto done;
    for (uint32_t i = 0; i < m->count; i++) /* (the points moved while growing) */
        m->lines[i].xy_m = m->xy ? m->xy + 2u * first[i] : NULL;
    rc = 0;
done:
    if (rc != 0)
        fprintf(stderr, "mapscore: %s: not a TXT map (polyline %u)\n", path, m->count);
    free(first);
    free(line);
    fclose(f);
    return rc;
}

/* The runs band15 counts, kept for printing after the row. */
typedef struct run_list {
    double *xy_len;                /* 5 per run: x0, y0, x1, y1, length */
    size_t n, cap;
    int failed;
} run_list;

static void keep_run(void *user, const double run_xy_m[4], double length_m)
{
    run_list *r = user;
    if (r->n == r->cap) {
        size_t cap = r->cap ? 2 * r->cap : 64;
        double *grown = realloc(r->xy_len, cap * 5 * sizeof *grown);
        if (!grown) {
            r->failed = 1;
            return;
        }
        r->xy_len = grown;
        r->cap = cap;
    }
    memcpy(&r->xy_len[5 * r->n], run_xy_m, 4 * sizeof *run_xy_m);
    r->xy_len[5 * r->n + 4] = length_m;
    r->n++;
}

int main(int argc, char **argv)
{
    scanlog log;
    pipeline p;
    gtround_map m;
    uint32_t params = 0, arcs = 0, circles = 0;
    uint32_t count = 0, verts = 0, i;
    gttopo_score topo;
    gtband_score band;
    double *xy = NULL, *from = NULL, lib_ms = 0.0, t0;
    uint64_t n = 0;
    FILE *f;
    int rc = EXIT_FAILED, from_file, want_runs = 0;
    run_list runs = {NULL, 0, 0, 0};

    if (argc == 2 && (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0)) {
        fputs(usage_text, stdout);
        return 0;
    }
    if (argc >= 2 && strcmp(argv[1], "--runs") == 0) {
        want_runs = 1;
        argv++;
        argc--;
    }
    from_file = argc == 3;
    if (argc < 2 || argc > 3 || argv[1][0] == '-' || (from_file && argv[2][0] == '-')) {
        fputs(usage_text, stderr);
        return EXIT_USAGE;
    }
    memset(&log, 0, sizeof log);
    memset(&p, 0, sizeof p);
    memset(&m, 0, sizeof m);
    f = fopen(argv[1], "r");
    if (!f) {
        fprintf(stderr, "mapscore: %s: %s\n", argv[1], strerror(errno));
        return EXIT_FAILED;
    }
    if (scanlog_read(&log, f, argv[1], NULL) != 0) {
        fprintf(stderr, "mapscore: %s\n", log.error);
        fclose(f);
        goto done;
    }
    fclose(f);
    if (from_file) {
        if (read_txt_map(argv[2], &m.map) != 0)
            goto done;
    } else {
        polyc_config config;
        double times[PIPELINE_STAGES];
        polyc_config_default(&config);
        if (pipeline_open(&p, &config, log.scans, log.count) != 0 ||
            pipeline_run(&p, log.scans, log.count, times) != 0 ||
            (p.status = gtround_from_ctx(p.ctx, &m)) != POLYC_OK) {
            fprintf(stderr, "mapscore: error in %s: %s (%s)\n",
                    p.failed_at ? p.failed_at : "pipeline_lines", polyc_status_str(p.status),
                    p.ctx ? polyc_last_error(p.ctx) : "");
            goto done;
        }
        for (i = 0; i < PIPELINE_STAGES; i++)
            lib_ms += times[i];
    }
    /* a circle or an arc is scored as itself (a fine polyline) and counted
     * as 3 numbers or 1 more */
    if (from_file) {
        if (gtround_score(&m) != 0) {
            fprintf(stderr, "mapscore: out of memory\n");
            goto done;
        }
    }
    count = m.count;
    gtround_params(&m, &verts, &params, &arcs, &circles);
    const polyc_polyline *scored = m.scored;
    t0 = pipeline_now_ms();
    if (gtband_scan_points(log.scans, log.count, &xy, &from, &n) != 0 ||
        gttopo_score_map(scored, count, xy, n, &topo) != 0 ||
        gtband_score_map_runs(scored, count, xy, from, n, &band, want_runs ? keep_run : NULL,
                              &runs) != 0 ||
        runs.failed) {
        fprintf(stderr, "mapscore: the scorers ran out of memory\n");
        goto done;
    }
    printf("%-28s %6s %7s %7s %5s %5s %9s %8s %6s %5s %5s %5s %5s %8s %6s %6s %6s %6s %8s %7s\n",
           "map", "lines", "verts", "params", "arcs", "circ", "len", "dcov", "dcov%", "cross", "uns20", "uns10", "loose",
           "band15", "band%", "end20", "end10", "end5", "libms", "scorems");
    /* parameters: 2 a vertex, 1 an arc, 3 a circle */
    printf("%-28s %6u %7u %7u %5u %5u %9.1f %8.2f %6.2f %5u %5u %5u %5u %8.2f %6.2f %6.4f %6.4f "
           "%6.4f %8.1f %7.1f\n",
           from_file ? argv[2] : "(library defaults)", count, verts, params, arcs, circles,
           topo.map_length_m,
           topo.double_cover_m,
           topo.map_length_m > 0.0 ? 100.0 * topo.double_cover_m / topo.map_length_m : 0.0,
           topo.crossings, topo.unsupported_20, topo.unsupported_10, topo.loose_ends,
           band.band_m, band.map_length_m > 0.0 ? 100.0 * band.band_m / band.map_length_m : 0.0,
           gtband_share(band.within_20, band.points), gtband_share(band.within_10, band.points),
           gtband_share(band.within_5, band.points), lib_ms, pipeline_now_ms() - t0);
    for (size_t k = 0; k < runs.n; k++) {
        const double *r = &runs.xy_len[5 * k];
        printf("run %.3f %.3f %.3f %.3f %.3f\n", r[0], r[1], r[2], r[3], r[4]);
    }
    rc = 0;
done:
    free(runs.xy_len);
    free(xy);
    free(from);
    gtround_free(&m);
    pipeline_close(&p);
    scanlog_free(&log);
    return rc;
}
