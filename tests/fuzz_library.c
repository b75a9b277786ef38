/* fuzz_library.c - fuzz target for the library: arbitrary scans through the
 * whole pipeline.
 * Takes: bytes decoded into a configuration, a memory budget and up to 64
 * scans (layout below). Checks: every call returns a known status, nothing
 * is written outside the block (guard bytes), results are finite, a stopped
 * or failed run leaves a readable context, and after polyc_reset the same
 * scans give the same map to the bit.
 * Built with libFuzzer (`make fuzz`) or with tests/fuzz_replay.c, which
 * replays tests/corpus/library/ in plain CI.
 *
 * Layout (all little-endian, missing bytes read as 0):
 *   byte 0  flags: bit 0 exact points, 1 no grazing, 2 gamma 0, 3 no free
 *           space, 4-5 cell (0.05, 0.1, 0.025, 0.2 m), 6-7 memory (0, 1:
 *           the queried size, 2: a share of it, 3: a tiny max_grid_cells)
 *   byte 1  bits 0-1 max_iterations (bit 2 unused), 3-5 stop after this many iterations
 *           (0: never), 6-7 patience - 1
 *   byte 2  memory share for mode 2 (n / 256 of the queried size)
 *   byte 3  seed
 *   then scans of 13 header bytes: x, y (int16, cm), theta, start (int8,
 *   pi/64), step (uint8, pi/512 each; 0 is a zero step), min (uint8, cm),
 *   max (uint8, 0.25 m), special (uint8, below), beam count (uint8), range
 *   encoding (uint8: even: uint8 of 5 cm each, odd: uint16 of mm each);
 *   then the ranges. Special: bit 7 clear: none (most scans stay good),
 *   else bits 0-2 pick a field (x, y, theta, start, step, min, max,
 *   reserved) and bits 3-5 a value (NaN, inf, -inf, 1e30, -1e30, 1e7, -0,
 *   1e-30). A range byte 255 (uint16 65535) is
 *   NaN, 254 (65534) is inf. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "polyc.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define MAX_SCANS 64
#define MAX_BEAMS 4096
#define MAX_BLOCK (48u << 20)       /* bytes; bigger budgets are capped */
#define GUARD 64

#define CHECK(x)                                                                     \
    do {                                                                             \
        if (!(x)) {                                                                  \
            fprintf(stderr, "fuzz_library: check failed: %s (line %d)\n", #x, __LINE__); \
            abort();                                                                 \
        }                                                                            \
    } while (0)

typedef struct input {
    const uint8_t *p;
    size_t left;
} input;

static uint8_t u8(input *in)
{
    if (!in->left)
        return 0;
    in->left--;
    return *in->p++;
}

static uint16_t u16(input *in)
{
    uint16_t lo = u8(in);
    return (uint16_t)(lo | (uint16_t)(u8(in) << 8));
}

typedef struct scene {
    polyc_config cfg;
    int memory_mode;
    uint8_t share;
    uint32_t stop_after;
    polyc_scan scans[MAX_SCANS];
    float ranges[MAX_BEAMS];
    uint32_t scan_count;
} scene;

static const double specials[8] = {(double)NAN, (double)INFINITY, -(double)INFINITY, 1e30, -1e30,
                                   1e7, -0.0, 1e-30};

static void apply_special(polyc_scan *s, uint8_t sp)
{
    double v = specials[(sp >> 3) & 7];
    switch (sp & 7) {
    case 0: s->pose_x_m = v; break;
    case 1: s->pose_y_m = v; break;
    case 2: s->pose_theta_rad = v; break;
    case 3: s->start_angle_rad = (float)v; break;
    case 4: s->angle_step_rad = (float)v; break;
    case 5: s->min_range_m = (float)v; break;
    case 6: s->max_range_m = (float)v; break;
    default: s->reserved = (uint32_t)sp; break;
    }
}

static void decode(const uint8_t *data, size_t size, scene *sc)
{
    static const float cells[4] = {0.05f, 0.1f, 0.025f, 0.2f};
    input in = {data, size};
    uint8_t flags = u8(&in), iters = u8(&in);
    polyc_config *c = &sc->cfg;
    polyc_config_default(c);
    c->cell_m = cells[(flags >> 4) & 3];
    c->max_extent_m = 300.0f;   /* int16 cm poses span 655 m: some runs exceed it */
    if (flags & 1) c->flags |= POLYC_FLAG_EXACT_POINTS;
    if (flags & 2) c->flags |= POLYC_FLAG_NO_GRAZING;
    if (flags & 4) c->gamma = 0.0f;
    if (flags & 8) c->free_range_m = 0.0f;
    c->max_iterations = iters & 3u;   /* a few iterations reach every operator */
    c->patience = 1u + (iters >> 6);
    sc->stop_after = (iters >> 3) & 7u;
    sc->memory_mode = flags >> 6;
    sc->share = u8(&in);
    c->seed = u8(&in);
    uint32_t beams = 0;
    sc->scan_count = 0;
    while (in.left > 0 && sc->scan_count < MAX_SCANS) {
        polyc_scan *s = &sc->scans[sc->scan_count];
        memset(s, 0, sizeof *s);
        s->pose_x_m = (int16_t)u16(&in) * 0.01;
        s->pose_y_m = (int16_t)u16(&in) * 0.01;
        s->pose_theta_rad = (int8_t)u8(&in) * (3.14159265358979 / 64);
        s->start_angle_rad = (float)((int8_t)u8(&in) * (3.14159265358979 / 64));
        s->angle_step_rad = (float)(u8(&in) * (3.14159265358979 / 512));
        s->min_range_m = (float)(u8(&in) * 0.01);
        s->max_range_m = (float)(u8(&in) * 0.25);
        uint8_t sp = u8(&in);
        uint32_t n = u8(&in);
        uint8_t wide = u8(&in) & 1;
        if (sp & 0x80)
            apply_special(s, sp);
        if (n > MAX_BEAMS - beams)
            n = MAX_BEAMS - beams;
        s->range_m = sc->ranges + beams;
        for (uint32_t i = 0; i < n && in.left > 0; i++) {
            uint32_t v = wide ? u16(&in) : u8(&in);
            uint32_t top = wide ? 65535u : 255u;
            float r = wide ? (float)(v * 0.001) : (float)(v * 0.05);
            sc->ranges[beams + i] = v == top ? NAN : v == top - 1 ? INFINITY : r;
            s->beam_count = i + 1;
        }
        beams += s->beam_count;
        sc->scan_count++;
    }
}

typedef struct progress {
    uint32_t stop_after, max_iterations, calls;
} progress;

/* One call per iteration, numbered from 0, never more than the cap; asks
 * to stop after stop_after calls. */
static int stop_at(void *user, const polyc_iteration *it)
{
    progress *p = user;
    CHECK(it->iteration == p->calls);
    CHECK(p->calls < p->max_iterations);
    /* the optimiser takes a new best only if it is better by 1e-6 relative
     * (optimize.c: the float total's rounding is about 1e-7 of it) */
    int worse = it->best_bic > it->bic + 1e-6 * fabs(it->best_bic);
    if (worse)
        fprintf(stderr, "fuzz_library: iteration %u: bic %.17g, best %.17g\n",
                (unsigned)it->iteration, it->bic, it->best_bic);
    CHECK(!worse);
    p->calls++;
    return p->stop_after && p->calls >= p->stop_after;
}

static int known_status(polyc_status st)
{
    return st >= POLYC_OK && st <= POLYC_ERR_STOPPED;
}

/* The map a context holds now, flattened for comparison. */
typedef struct result {
    polyc_status add, build;
    uint32_t lines, points;
    float xy[2 * 8192];
    uint32_t count[1024];
} result;

static void read_result(polyc_ctx *ctx, result *r)
{
    polyc_stats stats;
    CHECK(polyc_get_stats(ctx, &stats) == POLYC_OK);
    r->lines = polyc_polyline_count(ctx);
    r->points = 0;
    for (uint32_t i = 0; i < r->lines; i++) {
        polyc_polyline pl;
        CHECK(polyc_get_polyline(ctx, i, &pl) == POLYC_OK);
        CHECK(pl.point_count > 0 && pl.closed <= 1);
        for (uint32_t j = 0; j < 2 * pl.point_count; j++)
            CHECK(isfinite(pl.xy_m[j]));
        if (i < 1024)
            r->count[i] = pl.point_count;
        uint32_t fit = r->points < 8192 ? 8192 - r->points : 0;
        fit = pl.point_count < fit ? pl.point_count : fit;
        if (fit)
            memcpy(r->xy + 2 * r->points, pl.xy_m, 2 * sizeof(float) * fit);
        r->points += pl.point_count;
        uint32_t n = 0, closed = 9;
        CHECK(polyc_copy_polyline(ctx, i, NULL, 0, &n, &closed) == POLYC_OK);
        CHECK(n == pl.point_count && closed == pl.closed);
    }
    CHECK(polyc_get_polyline(ctx, r->lines, &(polyc_polyline){0}) != POLYC_OK);
    CHECK(r->lines == stats.polylines || r->lines == 0);
    CHECK(r->points == stats.vertices || r->lines == 0);
    CHECK(stats.memory_used_bytes <= stats.memory_size_bytes);
}

static void run(polyc_ctx *ctx, scene *sc, result *r)
{
    r->add = POLYC_OK;
    for (uint32_t i = 0; i < sc->scan_count; i++) {
        polyc_status st = polyc_add_scan(ctx, &sc->scans[i]);
        CHECK(known_status(st));
        CHECK(st == POLYC_OK || polyc_last_error(ctx)[0] != '\0');
        if (st != POLYC_OK && r->add == POLYC_OK)
            r->add = st;
    }
    progress p = {sc->stop_after, sc->cfg.max_iterations, 0};
    r->build = polyc_build(ctx, stop_at, &p);
    CHECK(known_status(r->build));
    CHECK(r->build != POLYC_ERR_NULL && r->build != POLYC_ERR_RANGE);
    /* the callback's stop is obeyed at once and reported as STOPPED */
    CHECK((r->build == POLYC_ERR_STOPPED) == (p.stop_after && p.calls >= p.stop_after));
    CHECK(p.calls <= p.stop_after || !p.stop_after);
    read_result(ctx, r);
    if (r->build == POLYC_OK || r->build == POLYC_ERR_STOPPED) {
        polyc_stats stats;
        CHECK(polyc_get_stats(ctx, &stats) == POLYC_OK);
        CHECK(stats.iterations == p.calls);
    }
    if (r->build == POLYC_OK || r->build == POLYC_ERR_STOPPED) {
        double bic = 0, err = 0;
        polyc_status st = polyc_score(ctx, &bic, &err);
        CHECK(st == POLYC_OK || st == POLYC_ERR_NOMEM);
        if (st == POLYC_OK)
            CHECK(!isnan(bic) && err >= 0.0);
        /* the round things: finite circles of polylines that exist, the
         * polylines unchanged */
        st = polyc_find_curves(ctx);
        CHECK(st == POLYC_OK || st == POLYC_ERR_NOMEM);
        uint32_t circles = 0;
        for (uint32_t i = 0; st == POLYC_OK && i < r->lines; i++) {
            polyc_circle c;
            CHECK(polyc_get_circle(ctx, i, &c) == POLYC_OK);
            CHECK(c.radius_m >= 0.0f && isfinite(c.radius_m));
            CHECK(c.same_as < r->lines);
            if (c.radius_m > 0.0f) {
                polyc_circle first;
                CHECK(polyc_get_circle(ctx, c.same_as, &first) == POLYC_OK);
                CHECK(first.same_as == c.same_as && first.radius_m == c.radius_m);
                circles += c.same_as == i;
                CHECK(isfinite(c.center_x_m) && isfinite(c.center_y_m) && c.polyline_dev_m >= 0.0f);
            }
        }
        CHECK(st != POLYC_OK || circles == polyc_circle_count(ctx));
        CHECK(polyc_polyline_count(ctx) == r->lines);
        uint32_t w = 0, h = 0;
        CHECK(polyc_grid_info(ctx, NULL, NULL, NULL, &w, &h) == POLYC_OK);
        uint32_t hits, misses, contour;
        if (w && h)
            CHECK(polyc_grid_cell(ctx, w / 2, h / 2, &hits, &misses, &contour) == POLYC_OK);
        CHECK(polyc_grid_cell(ctx, w, 0, &hits, &misses, &contour) == POLYC_ERR_RANGE);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static scene sc;
    static result first, second;
    decode(data, size, &sc);
    polyc_limits lim;
    polyc_status st = polyc_limits_for_scans(&sc.cfg, sc.scans, sc.scan_count, &lim);
    CHECK(known_status(st));
    if (st != POLYC_OK) {
        /* a far-away scan: size for the largest grid the cap allows instead */
        lim.max_scans = sc.scan_count;
        lim.max_beams = MAX_BEAMS;
        lim.max_grid_cells = 1u << 16;
    }
    if (sc.memory_mode == 3)
        lim.max_grid_cells = 1024u * (sc.share & 7u);
    size_t need = polyc_memory_size(&sc.cfg, &lim);
    if (need == 0)
        return 0;
    if (need > MAX_BLOCK) {
        /* keep the block bounded: the grid gets what is left */
        lim.max_grid_cells = 1u << 16;
        need = polyc_memory_size(&sc.cfg, &lim);
        if (need == 0 || need > MAX_BLOCK)
            return 0;
    }
    size_t size_given = sc.memory_mode == 2 ? need * sc.share / 256 : need;
    unsigned char *block = malloc(size_given + GUARD);
    CHECK(block != NULL);
    memset(block + size_given, 0xa5, GUARD);
    polyc_ctx *ctx = NULL;
    st = polyc_init(block, size_given, &sc.cfg, &lim, &ctx);
    CHECK(st == (size_given < need ? POLYC_ERR_NOMEM : POLYC_OK));
    if (st == POLYC_OK) {
        run(ctx, &sc, &first);
        /* the context stays usable: the same scans again give the same map */
        CHECK(polyc_reset(ctx) == POLYC_OK);
        CHECK(polyc_polyline_count(ctx) == 0);
        run(ctx, &sc, &second);
        CHECK(first.add == second.add && first.build == second.build);
        CHECK(first.lines == second.lines && first.points == second.points);
        uint32_t pts = first.points < 8192 ? first.points : 8192;
        CHECK(memcmp(first.xy, second.xy, 2 * sizeof(float) * pts) == 0);
        uint32_t lines = first.lines < 1024 ? first.lines : 1024;
        CHECK(memcmp(first.count, second.count, sizeof(uint32_t) * lines) == 0);
    }
    for (size_t i = 0; i < GUARD; i++)
        CHECK(block[size_given + i] == 0xa5);
    free(block);
    return 0;
}
