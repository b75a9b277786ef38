/* test_online.c - the online context (polyc_online_*) on simulated scenes
 * through the public API: updates stay within their work budget and carry
 * what does not fit; the same scans and budgets give the same map; the
 * changes since a version rebuild a client's copy of the map; the map
 * between updates has no crossing and no doubled wall; the finished map
 * scores like the batch map of the same scans; ten passes fit the block
 * sized for one; corrected poses give the map of the true poses; misuse
 * gives clear statuses; and too small a block fails cleanly. Scenes come
 * from the simulator (tools/eval/scansim), deterministic by seed; scores
 * from tools/eval/gtscore and gttopo. Needs nothing outside the repository.
 * What the tests found is marked FIXME(name) where an assertion waits for
 * the library: changes-since-0-lists-unseen-removals,
 * online-keeps-transient-polylines, online-stats-memory-used, stage-calls-hide-online-map,
 * nan-points-after-sums-run-out. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gtscore.h"
#include "gttopo.h"
#include "polyc.h"
#include "scansim.h"
#include "small_scene.h"

#define PI 3.14159265358979
#define SCENE_SEED 7u
/* a tile's work at most (online_round.c: 64 for the tile, one per cell
 * with endpoints, 1024 cells) */
#define TILE_WORK_MAX (64u + 1024u)

/* ---- scenes and contexts -------------------------------------------------- */

typedef struct scene {
    scansim_scene sim;
    gtscore_truth truth;
    double area_m;             /* a square round the first pose that holds the walls */
    uint32_t beams;
} scene;

static void check_status(polyc_status st, const polyc_ctx *ctx, const char *what)
{
    if (st != POLYC_OK)
        fail_msg("%s: %s (%s)", what, polyc_status_str(st), ctx ? polyc_last_error(ctx) : "");
}

static void scene_make(scene *s, const char *name, uint64_t seed)
{
    char err[256];
    FILE *gt = tmpfile();
    memset(s, 0, sizeof *s);
    assert_int_equal(scansim_scene_builtin(&s->sim, name, seed), 0);
    assert_int_equal(scansim_run(&s->sim), 0);
    assert_non_null(gt);
    assert_int_equal(scansim_write_gt(&s->sim, gt), 0);
    rewind(gt);
    if (gtscore_truth_read(&s->truth, gt, name, err, sizeof err) != 0)
        fail_msg("truth: %s", err);
    fclose(gt);
    /* twice the farthest wall point from the first pose, and 4 m more */
    const polyc_scan *first = &s->sim.scans[0];
    double far = 0.0;
    for (uint32_t i = 0; i < s->sim.wall_point_count; i++)
        far = fmax(far, fmax(fabs(s->sim.wall_xy_m[2 * i] - first->pose_x_m),
                             fabs(s->sim.wall_xy_m[2 * i + 1] - first->pose_y_m)));
    s->area_m = 2.0 * far + 4.0;
    s->beams = s->sim.laser.beam_count;
}

static void scene_free(scene *s)
{
    gtscore_truth_free(&s->truth);
    scansim_scene_free(&s->sim);
}

/* added to the optimiser's seed of every configuration (0: the default) */
static uint32_t seed_shift;

static void config_of(polyc_config *c)
{
    polyc_config_default(c);
    c->seed += seed_shift;
    if (c->max_iterations == 0 || c->max_iterations > 1000)
        c->max_iterations = 1000;
}

typedef struct online {
    polyc_config config;
    polyc_online_limits limits;
    size_t size;
    void *block;
    polyc_ctx *ctx;
} online;

/* An online context for the scene's area, keeping keep_scans scans. */
static void online_open(online *o, const scene *s, uint32_t keep_scans)
{
    memset(o, 0, sizeof *o);
    config_of(&o->config);
    check_status(polyc_online_limits_for_area(&o->config, s->area_m, s->beams, &o->limits), NULL,
                 "polyc_online_limits_for_area");
    o->limits.keep_scans = keep_scans;
    o->limits.keep_beams = keep_scans * s->beams;
    o->size = polyc_online_memory_size(&o->config, &o->limits);
    assert_true(o->size > 0);
    o->block = malloc(o->size);
    assert_non_null(o->block);
    check_status(polyc_online_init(o->block, o->size, &o->config, &o->limits, &o->ctx), NULL,
                 "polyc_online_init");
}

static void online_close(online *o)
{
    free(o->block);
    o->block = NULL;
    o->ctx = NULL;
}

/* ---- maps: copies, scores, checks ----------------------------------------- */

typedef struct map_copy {
    uint32_t n;
    uint32_t *id, *count, *closed;
    float **xy;
} map_copy;

static void map_free(map_copy *m)
{
    for (uint32_t i = 0; i < m->n; i++)
        free(m->xy[i]);
    free(m->id);
    free(m->count);
    free(m->closed);
    free(m->xy);
    memset(m, 0, sizeof *m);
}

static void map_take(map_copy *m, const polyc_ctx *ctx)
{
    memset(m, 0, sizeof *m);
    m->n = polyc_polyline_count(ctx);
    size_t n = m->n ? m->n : 1u;
    m->id = calloc(n, sizeof *m->id);
    m->count = calloc(n, sizeof *m->count);
    m->closed = calloc(n, sizeof *m->closed);
    m->xy = calloc(n, sizeof *m->xy);
    assert_true(m->id && m->count && m->closed && m->xy);
    for (uint32_t i = 0; i < m->n; i++) {
        polyc_polyline pl;
        check_status(polyc_get_polyline(ctx, i, &pl), ctx, "polyc_get_polyline");
        check_status(polyc_polyline_id(ctx, i, &m->id[i]), ctx, "polyc_polyline_id");
        m->count[i] = pl.point_count;
        m->closed[i] = pl.closed;
        m->xy[i] = malloc(2u * pl.point_count * sizeof(float) + 1u);
        assert_non_null(m->xy[i]);
        memcpy(m->xy[i], pl.xy_m, 2u * pl.point_count * sizeof(float));
    }
}

/* The index of polyline `id` in m, or -1. */
static int64_t map_find(const map_copy *m, uint32_t id)
{
    for (uint32_t i = 0; i < m->n; i++)
        if (m->id[i] == id)
            return i;
    return -1;
}

static int same_line(const map_copy *a, uint32_t i, const map_copy *b, uint32_t j)
{
    return a->count[i] == b->count[j] && a->closed[i] == b->closed[j] &&
           memcmp(a->xy[i], b->xy[j], 2u * a->count[i] * sizeof(float)) == 0;
}

/* Same polylines in the same order, to the bit. */
static void assert_maps_equal(const map_copy *a, const map_copy *b)
{
    assert_int_equal(a->n, b->n);
    for (uint32_t i = 0; i < a->n; i++) {
        assert_int_equal(a->id[i], b->id[i]);
        assert_int_equal(a->count[i], b->count[i]);
        assert_int_equal(a->closed[i], b->closed[i]);
        assert_memory_equal(a->xy[i], b->xy[i], 2u * a->count[i] * sizeof(float));
    }
}

static void score_ctx(const polyc_ctx *ctx, const scene *s, gtscore_map_score *out)
{
    uint32_t n = polyc_polyline_count(ctx);
    polyc_polyline *lines = calloc(n ? n : 1u, sizeof *lines);
    assert_non_null(lines);
    for (uint32_t i = 0; i < n; i++)
        check_status(polyc_get_polyline(ctx, i, &lines[i]), ctx, "polyc_get_polyline");
    assert_int_equal(gtscore_score_map(&s->truth, lines, n, out), 0);
    free(lines);
}

static void print_score(const char *what, const gtscore_map_score *sc)
{
    print_message("%-26s %3u polylines, %4u vertices (ideal %u), RMS %5.2f mm, "
                  "completeness %.4f\n",
                  what, sc->polylines, sc->vertices, sc->ideal, 1e3 * sc->precision_rms_m,
                  sc->completeness);
}

/* A crossing this near a segment end is a junction, not a crossing: the
 * library's own rule (src/search/topology.c, CROSS_END_M), under which the batch
 * map has none either. */
#define JUNCTION_M 0.002

/* Whether segments ab and cd cross properly: each has the other's ends
 * strictly on both sides, the crossing at least JUNCTION_M from all four
 * ends (segments that share a vertex never count). *near_end: they cross
 * but within JUNCTION_M of an end. */
static int cross_properly(const double *a, const double *b, const double *c, const double *d,
                          int *near_end)
{
    double d1 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    double d2 = (b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0]);
    double d3 = (d[0] - c[0]) * (a[1] - c[1]) - (d[1] - c[1]) * (a[0] - c[0]);
    double d4 = (d[0] - c[0]) * (b[1] - c[1]) - (d[1] - c[1]) * (b[0] - c[0]);
    *near_end = 0;
    if (!(((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) &&
          ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))))
        return 0;
    double t = d3 / (d3 - d4), u = d1 / (d1 - d2); /* along ab, along cd */
    double lab = hypot(b[0] - a[0], b[1] - a[1]), lcd = hypot(d[0] - c[0], d[1] - c[1]);
    if (t * lab < JUNCTION_M || (1.0 - t) * lab < JUNCTION_M || u * lcd < JUNCTION_M ||
        (1.0 - u) * lcd < JUNCTION_M) {
        *near_end = 1;
        return 0;
    }
    return 1;
}

/* The map's segments: 4 doubles each (x0 y0 x1 y1), and for each its
 * polyline and index there. */
typedef struct segs {
    double *xy;
    uint32_t *line, *at;
    uint32_t n;
} segs;

static void segs_of(const polyc_ctx *ctx, segs *s)
{
    uint32_t count = polyc_polyline_count(ctx), total = 0;
    for (uint32_t i = 0; i < count; i++) {
        polyc_polyline pl;
        check_status(polyc_get_polyline(ctx, i, &pl), ctx, "polyc_get_polyline");
        total += pl.point_count;
    }
    s->xy = malloc(4u * (total + 1u) * sizeof *s->xy);
    s->line = malloc((total + 1u) * sizeof *s->line);
    s->at = malloc((total + 1u) * sizeof *s->at);
    assert_true(s->xy && s->line && s->at);
    s->n = 0;
    for (uint32_t i = 0; i < count; i++) {
        polyc_polyline pl;
        check_status(polyc_get_polyline(ctx, i, &pl), ctx, "polyc_get_polyline");
        uint32_t m = pl.closed && pl.point_count > 2 ? pl.point_count : pl.point_count - 1;
        for (uint32_t j = 0; pl.point_count > 1 && j < m; j++) {
            uint32_t k = (j + 1) % pl.point_count;
            double *q = &s->xy[4u * s->n];
            q[0] = (double)pl.xy_m[2 * j];
            q[1] = (double)pl.xy_m[2 * j + 1];
            q[2] = (double)pl.xy_m[2 * k];
            q[3] = (double)pl.xy_m[2 * k + 1];
            s->line[s->n] = i;
            s->at[s->n] = j;
            s->n++;
        }
    }
}

static void segs_free(segs *s)
{
    free(s->xy);
    free(s->line);
    free(s->at);
}

/* Proper crossings between any two segments of the map (its own check,
 * O(n^2); *junctions: those within JUNCTION_M of an end), and the doubled
 * walls as gttopo measures them (double_cover_m:
 * runs over 20 cm of a segment within 5 cm of another that is not its
 * neighbour). */
static void map_validity(const polyc_ctx *ctx, uint32_t *crossings, uint32_t *junctions,
                         double *double_cover_m)
{
    segs s;
    segs_of(ctx, &s);
    *crossings = *junctions = 0;
    for (uint32_t i = 0; i < s.n; i++)
        for (uint32_t j = i + 1; j < s.n; j++) {
            const double *p = &s.xy[4u * i], *q = &s.xy[4u * j];
            if (fmax(p[0], p[2]) < fmin(q[0], q[2]) || fmax(q[0], q[2]) < fmin(p[0], p[2]) ||
                fmax(p[1], p[3]) < fmin(q[1], q[3]) || fmax(q[1], q[3]) < fmin(p[1], p[3]))
                continue;
            int near_end;
            if (cross_properly(p, p + 2, q, q + 2, &near_end)) {
                if (*crossings < 5)
                    print_message("crossing: polyline %u segment %u (%.3f %.3f - %.3f %.3f) and "
                                  "polyline %u segment %u (%.3f %.3f - %.3f %.3f)\n",
                                  s.line[i], s.at[i], p[0], p[1], p[2], p[3], s.line[j], s.at[j],
                                  q[0], q[1], q[2], q[3]);
                (*crossings)++;
            }
            *junctions += (uint32_t)near_end;
        }
    segs_free(&s);
    uint32_t n = polyc_polyline_count(ctx);
    polyc_polyline *lines = calloc(n ? n : 1u, sizeof *lines);
    assert_non_null(lines);
    for (uint32_t i = 0; i < n; i++)
        check_status(polyc_get_polyline(ctx, i, &lines[i]), ctx, "polyc_get_polyline");
    gttopo_score topo;
    assert_int_equal(gttopo_score_map(lines, n, NULL, 0, &topo), 0);
    *double_cover_m = topo.double_cover_m;
    free(lines);
}

/* Pairs of open ends of two polylines within merge reach (the default
 * merge_dist_m, 15 cm) that the polylines leave in directions more than 30
 * degrees apart: ends the merge would link, as it links them in a batch
 * build's every iteration (a link that would fold back is the zigzag's). */
#define MERGE_REACH_M 0.15
static uint32_t linkable_ends(const polyc_ctx *ctx)
{
    uint32_t n = polyc_polyline_count(ctx), pairs = 0;
    double *e = malloc(8u * (n + 1u) * sizeof *e); /* per end: x y, away dx dy */
    assert_non_null(e);
    uint32_t k = 0;
    for (uint32_t i = 0; i < n; i++) {
        polyc_polyline pl;
        check_status(polyc_get_polyline(ctx, i, &pl), ctx, "polyc_get_polyline");
        if (pl.closed || pl.point_count < 2)
            continue;
        const float *xy = pl.xy_m;
        uint32_t last = pl.point_count - 1;
        double *h = &e[8u * k++];
        h[0] = xy[0], h[1] = xy[1], h[2] = xy[2] - xy[0], h[3] = xy[3] - xy[1];
        h[4] = xy[2 * last], h[5] = xy[2 * last + 1];
        h[6] = xy[2 * last - 2] - xy[2 * last], h[7] = xy[2 * last - 1] - xy[2 * last + 1];
    }
    for (uint32_t i = 0; i < k; i++)
        for (uint32_t j = i + 1; j < k; j++)
            for (int a = 0; a < 2; a++)
                for (int b = 0; b < 2; b++) {
                    const double *p = &e[8u * i + 4u * (uint32_t)a];
                    const double *q = &e[8u * j + 4u * (uint32_t)b];
                    double cosang = (p[2] * q[2] + p[3] * q[3]) /
                                    (hypot(p[2], p[3]) * hypot(q[2], q[3]) + 1e-30);
                    if (hypot(p[0] - q[0], p[1] - q[1]) < MERGE_REACH_M && cosang < 0.866)
                        pairs++;
                }
    free(e);
    return pairs;
}

/* Adds scan i (keep: for corrections), failing the test on an error. */
static void add(const online *o, const polyc_scan *scan, int keep)
{
    check_status(polyc_online_add_scan(o->ctx, scan, keep, NULL), o->ctx, "polyc_online_add_scan");
}

static void update(const online *o, uint64_t work, polyc_online_report *r)
{
    check_status(polyc_online_update(o->ctx, work, r), o->ctx, "polyc_online_update");
}

static void finish(const online *o, polyc_online_report *r)
{
    check_status(polyc_online_finish(o->ctx, NULL, NULL, r), o->ctx, "polyc_online_finish");
}

/* Scans from .. to - 1 of s, each added (not kept) and followed by an
 * update at the default budget. */
static void add_and_update(const online *o, const scene *s, uint32_t from, uint32_t to,
                           polyc_online_report *r)
{
    for (uint32_t i = from; i < to; i++) {
        add(o, &s->sim.scans[i], 0);
        update(o, POLYC_ONLINE_WORK_DEFAULT, r);
    }
}

/* The batch map of n of these scans, scored. */
/* A search's progress: the noise of its first iteration with noise (0:
 * none yet). */
typedef struct first_noise {
    double noise_m;
} first_noise;

static int note_first_noise(void *user, const polyc_iteration *it)
{
    first_noise *f = user;
    if (f->noise_m == 0.0 && it->noise_m > 0.0)
        f->noise_m = it->noise_m;
    return 0;
}

/* The batch map of scans[0 .. n-1], scored; its search's first noise into
 * *noise if not NULL. */
static void batch_score_n(const scene *s, const polyc_scan *scans, uint32_t n,
                          gtscore_map_score *out, first_noise *noise)
{
    polyc_config c;
    polyc_limits lim;
    polyc_ctx *ctx;
    config_of(&c);
    check_status(polyc_limits_for_scans(&c, scans, n, &lim), NULL, "polyc_limits_for_scans");
    size_t size = polyc_memory_size(&c, &lim);
    assert_true(size > 0);
    void *block = malloc(size);
    assert_non_null(block);
    check_status(polyc_init(block, size, &c, &lim, &ctx), NULL, "polyc_init");
    for (uint32_t i = 0; i < n; i++)
        check_status(polyc_add_scan(ctx, &scans[i]), ctx, "polyc_add_scan");
    check_status(polyc_build(ctx, noise ? note_first_noise : NULL, noise), ctx, "polyc_build");
    score_ctx(ctx, s, out);
    free(block);
}

static void batch_score(const scene *s, const polyc_scan *scans, gtscore_map_score *out)
{
    batch_score_n(s, scans, s->sim.scan_count, out, NULL);
}

/* ---- 1. updates within their budget, the backlog, determinism ------------- */

/* The scene scan by scan, an update of `work` after each; then updates of
 * `work` until the backlog is empty (at most `drain` of them). Every
 * update's work stays within one tile of its budget, and one that leaves a
 * backlog has spent its budget. The map is copied into *m. */
typedef struct budget_run {
    uint32_t max_backlog;      /* the largest backlog an update left */
    uint32_t drained_in;       /* updates after the last scan */
    uint64_t max_over;         /* the most an update spent over its budget */
} budget_run;

static void replay_budget(const scene *s, uint64_t work, uint32_t drain, map_copy *m,
                          budget_run *b)
{
    online o;
    polyc_online_report r;
    online_open(&o, s, 0);
    memset(b, 0, sizeof *b);
    for (uint32_t i = 0; i < s->sim.scan_count; i++) {
        add(&o, &s->sim.scans[i], 0);
        update(&o, work, &r);
        if (r.work > work + TILE_WORK_MAX)
            fail_msg("update %u: work %llu over the budget %llu by more than a tile", i,
                     (unsigned long long)r.work, (unsigned long long)work);
        /* an update that worked and left a backlog spent its budget (one
         * may also wait for more tiles: work 0) */
        if (r.backlog_tiles > 0 && r.work > 0)
            assert_true(r.work >= work);
        if (r.work > work && r.work - work > b->max_over)
            b->max_over = r.work - work;
        assert_int_equal(r.scans, i + 1);
        assert_int_equal(r.pending_scans, 0);
        if (r.backlog_tiles > b->max_backlog)
            b->max_backlog = r.backlog_tiles;
    }
    uint32_t k = 0;
    for (; r.backlog_tiles > 0 && k < drain; k++) {
        uint32_t before = r.backlog_tiles;
        update(&o, work, &r);
        assert_true(r.work > 0 && r.work <= work + TILE_WORK_MAX);
        assert_true(r.backlog_tiles < before); /* no scan came: it shrinks */
    }
    b->drained_in = k;
    assert_int_equal(r.backlog_tiles, 0);
    /* nothing left: an update does nothing */
    update(&o, work, &r);
    assert_int_equal(r.work, 0);
    assert_int_equal(r.changed, 0);
    map_take(m, o.ctx);
    online_close(&o);
}

/* Measured (office, seed 7): budget 1 leaves up to 88 tiles waiting,
 * drained in 76 updates after the last scan; budget 300 up to 34 and the
 * default budget up to 3, both drained by the updates of the scans. */
#define DRAIN_UPDATES 200

static void test_update_within_budget(void **state)
{
    (void)state;
    scene s;
    scene_make(&s, "office", SCENE_SEED);
    static const uint64_t budgets[3] = {1u, 300u, POLYC_ONLINE_WORK_DEFAULT};
    for (int k = 0; k < 3; k++) {
        map_copy a, c;
        budget_run ra, rc;
        replay_budget(&s, budgets[k], DRAIN_UPDATES, &a, &ra);
        print_message("budget %4llu: backlog up to %2u tiles, drained in %2u updates, at most "
                      "%4llu units over, %u polylines\n",
                      (unsigned long long)budgets[k], ra.max_backlog, ra.drained_in,
                      (unsigned long long)ra.max_over, a.n);
        assert_true(a.n > 0);
        if (budgets[k] == 1u)
            assert_true(ra.max_backlog > 0); /* the tiny budget carries a backlog */
        /* the same scans and budgets: the same map, to the bit */
        replay_budget(&s, budgets[k], DRAIN_UPDATES, &c, &rc);
        assert_memory_equal(&ra, &rc, sizeof ra);
        assert_maps_equal(&a, &c);
        map_free(&a);
        map_free(&c);
    }
    scene_free(&s);
}

/* ---- 2. changes since a version ---------------------------------------- */

/* Every entry of the changes since `since`, checked for order and range;
 * *n gets their count. The caller frees the array. */
static polyc_change *changes_since(const polyc_ctx *ctx, uint64_t since, uint32_t *n)
{
    uint32_t count = UINT32_MAX;
    check_status(polyc_online_changes(ctx, since, NULL, 0, &count), ctx, "polyc_online_changes");
    assert_true(count != UINT32_MAX);
    polyc_change *out = calloc((size_t)count + 1u, sizeof *out);
    assert_non_null(out);
    if (count > 0) {
        /* one short: only the count, out untouched */
        memset(out, 0xee, ((size_t)count + 1u) * sizeof *out);
        uint32_t again = 0;
        check_status(polyc_online_changes(ctx, since, out, count - 1u, &again), ctx,
                     "polyc_online_changes");
        assert_int_equal(again, count);
        for (size_t b = 0; b < ((size_t)count + 1u) * sizeof *out; b++)
            assert_int_equal(((const unsigned char *)out)[b], 0xee);
    }
    uint32_t got = 0;
    check_status(polyc_online_changes(ctx, since, out, count, &got), ctx, "polyc_online_changes");
    assert_int_equal(got, count);
    uint64_t now = polyc_online_version(ctx);
    for (uint32_t i = 0; i < count; i++) {
        if (i > 0 && out[i].id <= out[i - 1].id)
            fail_msg("changes since %llu: ids not ascending at %u (%u after %u)",
                     (unsigned long long)since, i, out[i].id, out[i - 1].id);
        assert_true(out[i].kind >= POLYC_CHANGE_ADDED && out[i].kind <= POLYC_CHANGE_REMOVED);
        assert_true(out[i].version > since && out[i].version <= now);
    }
    *n = count;
    return out;
}

/* Applies the changes since the client copy's version to it: it then holds
 * the ids of the current map, and every polyline the changes do not name
 * is the same to the bit in both. */
static void check_changes_apply(const polyc_ctx *ctx, const map_copy *client, uint64_t since,
                                uint32_t *added, uint32_t *modified, uint32_t *removed,
                                uint32_t *unseen)
{
    map_copy now;
    map_take(&now, ctx);
    uint32_t n;
    polyc_change *ch = changes_since(ctx, since, &n);
    uint8_t *named = calloc((size_t)client->n + 1u, 1);
    assert_non_null(named);
    uint32_t live = client->n;
    for (uint32_t i = 0; i < n; i++) {
        int64_t was = map_find(client, ch[i].id), is = map_find(&now, ch[i].id);
        switch (ch[i].kind) {
        case POLYC_CHANGE_ADDED:
            if (was >= 0 || is < 0)
                fail_msg("id %u ADDED since %llu: in the client copy %d, in the map %d", ch[i].id,
                         (unsigned long long)since, was >= 0, is >= 0);
            live++;
            (*added)++;
            break;
        case POLYC_CHANGE_MODIFIED:
            if (was < 0 || is < 0)
                fail_msg("id %u MODIFIED since %llu: in the client copy %d, in the map %d",
                         ch[i].id, (unsigned long long)since, was >= 0, is >= 0);
            named[was] = 1;
            (*modified)++;
            break;
        default:
            /* a polyline added and removed again since: not in the copy
             * (see FIXME(changes-since-0-lists-unseen-removals)) */
            if (is >= 0)
                fail_msg("id %u REMOVED since %llu but in the map", ch[i].id,
                         (unsigned long long)since);
            if (was < 0) {
                (*unseen)++;
                break;
            }
            named[was] = 1;
            live--;
            (*removed)++;
            break;
        }
    }
    /* the ids: those of the copy less the removed, with the added */
    assert_int_equal(live, now.n);
    for (uint32_t j = 0; j < now.n; j++) {
        int64_t was = map_find(client, now.id[j]);
        if (was < 0) {
            int listed = 0;
            for (uint32_t i = 0; i < n; i++)
                listed |= ch[i].id == now.id[j] && ch[i].kind == POLYC_CHANGE_ADDED;
            if (!listed)
                fail_msg("id %u is new since %llu but not listed as added", now.id[j],
                         (unsigned long long)since);
        } else if (!named[was] && !same_line(client, (uint32_t)was, &now, j)) {
            fail_msg("id %u changed since %llu but is not in the changes", now.id[j],
                     (unsigned long long)since);
        }
    }
    free(named);
    free(ch);
    map_free(&now);
}

#define CHECKPOINTS 12

static void test_changes_since_version(void **state)
{
    (void)state;
    scene s;
    scene_make(&s, "office", SCENE_SEED);
    online o;
    polyc_online_report r;
    online_open(&o, &s, 0);
    assert_int_equal(polyc_online_version(o.ctx), 0);
    map_copy copy[CHECKPOINTS];
    uint64_t at[CHECKPOINTS];
    uint32_t taken = 0, added = 0, modified = 0, removed = 0, spurious_removals = 0,
             unseen_removals = 0;
    uint64_t last_version = 0;
    for (uint32_t i = 0; i < s.sim.scan_count; i++) {
        add(&o, &s.sim.scans[i], 0);
        update(&o, POLYC_ONLINE_WORK_DEFAULT, &r);
        assert_true(r.version >= last_version);
        assert_int_equal(r.version, polyc_online_version(o.ctx));
        /* a version moves when the map does */
        if (r.version == last_version)
            assert_int_equal(r.changed, 0);
        else
            assert_true(r.changed > 0);
        last_version = r.version;
        if (i % 16 != 15 || taken >= CHECKPOINTS)
            continue;
        /* since 0: every polyline of the map once, as added, ids ascending
         * (changes_since checks the order) */
        uint32_t n, n_added = 0;
        polyc_change *ch = changes_since(o.ctx, 0, &n);
        for (uint32_t k = 0; k < n; k++) {
            if (ch[k].kind == POLYC_CHANGE_ADDED) {
                n_added++;
                continue;
            }
            /* the rest: removals of polylines born after version 0 (a
             * client at version 0 never had them) */
            assert_int_equal(ch[k].kind, POLYC_CHANGE_REMOVED);
            for (uint32_t q = 0; q < r.polylines; q++) {
                uint32_t id;
                check_status(polyc_polyline_id(o.ctx, q, &id), o.ctx, "polyc_polyline_id");
                assert_true(id != ch[k].id);
            }
            spurious_removals++;
        }
        /* since 0: the current map and nothing else (a polyline added and
         * removed again after version 0 is not named) */
        assert_int_equal(n, polyc_polyline_count(o.ctx));
        assert_int_equal(n_added, polyc_polyline_count(o.ctx));
        assert_int_equal(n_added, r.polylines);
        for (uint32_t k = 0; k < r.polylines; k++) {
            uint32_t id;
            check_status(polyc_polyline_id(o.ctx, k, &id), o.ctx, "polyc_polyline_id");
            assert_true(id >= 1);
            int found = 0;
            for (uint32_t q = 0; q < n; q++)
                found += ch[q].id == id && ch[q].kind == POLYC_CHANGE_ADDED;
            assert_int_equal(found, 1);
        }
        free(ch);
        /* since now: nothing */
        uint32_t none = 99;
        check_status(polyc_online_changes(o.ctx, r.version, NULL, 0, &none), o.ctx,
                     "polyc_online_changes");
        assert_int_equal(none, 0);
        /* the earlier copies brought up to date */
        for (uint32_t k = 0; k < taken; k++)
            check_changes_apply(o.ctx, &copy[k], at[k], &added, &modified, &removed,
                                &unseen_removals);
        map_take(&copy[taken], o.ctx);
        at[taken++] = r.version;
    }
    finish(&o, &r);
    for (uint32_t k = 0; k < taken; k++)
        check_changes_apply(o.ctx, &copy[k], at[k], &added, &modified, &removed,
                                &unseen_removals);
    print_message("office: %u checkpoints up to version %llu; changes applied: %u added, "
                  "%u modified, %u removed, %u removals of unseen ids; since 0: %u removals "
                  "of unseen ids\n",
                  taken, (unsigned long long)r.version, added, modified, removed,
                  unseen_removals, spurious_removals);
    /* the replay exercises every kind */
    assert_true(taken >= 8 && added > 0 && modified > 0 && removed > 0);
    for (uint32_t k = 0; k < taken; k++)
        map_free(&copy[k]);
    online_close(&o);
    scene_free(&s);
}

/* With few vertices (128: a ring of 80 removals) the thin walls' removals
 * outrun the ring: a copy too old gets POLYC_ERR_RANGE (and reads the map
 * again), a recent one still rebuilds exactly. */
static void test_changes_forgotten(void **state)
{
    (void)state;
    scene s;
    scene_make(&s, "thinwalls", SCENE_SEED);
    online o;
    memset(&o, 0, sizeof o);
    config_of(&o.config);
    check_status(polyc_online_limits_for_area(&o.config, s.area_m, s.beams, &o.limits), NULL,
                 "limits");
    o.limits.max_vertices = 128;
    o.size = polyc_online_memory_size(&o.config, &o.limits);
    assert_true(o.size > 0);
    o.block = malloc(o.size);
    assert_non_null(o.block);
    check_status(polyc_online_init(o.block, o.size, &o.config, &o.limits, &o.ctx), NULL, "init");
    map_copy client, prev;
    map_take(&client, o.ctx);
    map_take(&prev, o.ctx);
    uint64_t client_at = 0, prev_at = 0;
    uint32_t refused = 0, applied = 0, a = 0, m = 0, rm = 0, unseen = 0;
    polyc_online_report r;
    /* passes until the removals have gone round the ring (thin walls: their
     * faces' pieces come and go while both are seen, 80 or so removals in
     * two passes; the office's walls, whose pieces the updates link before
     * they are published, made 68 removals in four passes); at most six */
    for (uint32_t i = 0; i < 6 * s.sim.scan_count && !(refused > 0 && i % s.sim.scan_count == 0);
         i++) {
        add(&o, &s.sim.scans[i % s.sim.scan_count], 0);
        update(&o, POLYC_ONLINE_WORK_DEFAULT, &r);
        /* the copy of the update before: never forgotten here */
        check_changes_apply(o.ctx, &prev, prev_at, &a, &m, &rm, &unseen);
        map_free(&prev);
        map_take(&prev, o.ctx);
        prev_at = r.version;
        /* the copy of version 0, or the last re-read */
        uint32_t n;
        polyc_status st = polyc_online_changes(o.ctx, client_at, NULL, 0, &n);
        if (st == POLYC_ERR_RANGE) {
            refused++;
            map_free(&client);
            map_take(&client, o.ctx); /* the caller reads the whole map */
            client_at = r.version;
            continue;
        }
        check_status(st, o.ctx, "polyc_online_changes");
        if (i % 8 == 7) {
            check_changes_apply(o.ctx, &client, client_at, &a, &m, &rm, &unseen);
            applied++;
        }
    }
    print_message("thinwalls, 128 vertices: %u refusals (POLYC_ERR_RANGE) of an old copy, %u "
                  "applied; %u added, %u modified, %u removed\n",
                  refused, applied, a, m, rm);
    assert_true(refused > 0);
    assert_int_equal(polyc_online_changes(o.ctx, 0, NULL, 0, &a), POLYC_ERR_RANGE);
    map_free(&client);
    map_free(&prev);
    online_close(&o);
    scene_free(&s);
}

/* ---- 3. a valid map between updates -------------------------------------- */

/* The scene scan by scan, an update after each (of `work`, or with work 0
 * of 500 and the default in turn), the map checked after every `every`
 * updates and after finish: no crossing, nothing doubly covered. */
static void check_valid_replay(const char *name, uint64_t work, uint32_t every)
{
    scene s;
    scene_make(&s, name, SCENE_SEED);
    online o;
    polyc_online_report r;
    online_open(&o, &s, 0);
    uint32_t checks = 0, junctions_seen = 0, bad = 0, linkable_sum = 0, linkable_max = 0;
    for (uint32_t i = 0; i < s.sim.scan_count; i++) {
        add(&o, &s.sim.scans[i], 0);
        update(&o, work ? work : i % 3 == 0 ? 500u : POLYC_ONLINE_WORK_DEFAULT, &r);
        if (i % every != every - 1 && i + 1 != s.sim.scan_count)
            continue;
        uint32_t crossings, junctions;
        double cover;
        map_validity(o.ctx, &crossings, &junctions, &cover);
        uint32_t linkable = linkable_ends(o.ctx);
        linkable_sum += linkable;
        linkable_max = linkable > linkable_max ? linkable : linkable_max;
        checks++;
        junctions_seen += junctions;
        if (crossings > 0 || cover > 0.0) {
            print_error("%s after scan %u (version %llu): %u crossings, %.3f m doubly covered\n",
                        name, i, (unsigned long long)r.version, crossings, cover);
            bad++;
        }
    }
    finish(&o, &r);
    uint32_t crossings, junctions;
    double cover;
    map_validity(o.ctx, &crossings, &junctions, &cover);
    print_message("%s (work %llu%s): %u maps checked, %u junction touches (within %.0f mm of "
                  "an end), linkable pairs of ends %u in all, %u at most; finished: %u crossings, "
                  "%.3f m doubly covered\n",
                  name, (unsigned long long)work, work ? "" : ": 500 and the default in turn",
                  checks, junctions_seen, 1e3 * JUNCTION_M, linkable_sum, linkable_max, crossings,
                  cover);
    assert_int_equal(crossings, 0);
    assert_true(cover == 0.0);
    assert_int_equal(bad, 0);
    /* the ends a round's operators leave within merge reach are linked
     * before the update returns (online_round.c, link_left_ends). Without
     * that: office 138, 109 and 271 pairs over its three replays (up to 10
     * in one map), angled 32 and 6, square 7; with it 3, 5, 2, 0, 0, 0 (the
     * rest: a link that would cross, or ends the zip or the crossing repair
     * after it made) */
    assert_true(linkable_max <= 1u);
    assert_true(linkable_sum <= checks / 10u);
    online_close(&o);
    scene_free(&s);
}

static void test_valid_between_updates(void **state)
{
    (void)state;
    check_valid_replay("office", POLYC_ONLINE_WORK_DEFAULT, 1);
    check_valid_replay("office", 0, 3);
    check_valid_replay("office", 1, 3);
    check_valid_replay("angled", POLYC_ONLINE_WORK_DEFAULT, 1);
    check_valid_replay("angled", 0, 3);
    check_valid_replay("square", POLYC_ONLINE_WORK_DEFAULT, 1);
}

/* Vertices of the map farther than d_m from every true wall. */
static uint32_t stray_vertices(const polyc_ctx *ctx, const scene *s, double d_m)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < polyc_polyline_count(ctx); i++) {
        polyc_polyline pl;
        check_status(polyc_get_polyline(ctx, i, &pl), ctx, "polyc_get_polyline");
        for (uint32_t j = 0; j < pl.point_count; j++)
            n += gtscore_index_distance(&s->truth.index, (double)pl.xy_m[2 * j],
                                        (double)pl.xy_m[2 * j + 1], d_m) > d_m;
    }
    return n;
}

/* A walker crosses the angled hall during scans 50-110; the robot's later
 * scans see the floor there free. Once the backlog has drained, the map
 * between updates should not keep the walker's trail (the batch map of the
 * same scans has no vertex 0.3 m from a wall); after finish it does not. */
static void test_walker_trail(void **state)
{
    (void)state;
    scene s;
    scene_make(&s, "angled", SCENE_SEED);
    online o;
    polyc_online_report r;
    online_open(&o, &s, 0);
    uint32_t mid = 0;
    for (uint32_t i = 0; i < s.sim.scan_count; i++) {
        add(&o, &s.sim.scans[i], 0);
        update(&o, POLYC_ONLINE_WORK_DEFAULT, &r);
        if (i >= 50 && i <= 110) {
            uint32_t n = stray_vertices(o.ctx, &s, 0.3);
            mid = n > mid ? n : mid;
        }
    }
    uint32_t k = 0;
    for (; r.backlog_tiles > 0 && k < 100; k++)
        update(&o, POLYC_ONLINE_WORK_DEFAULT, &r);
    assert_int_equal(r.backlog_tiles, 0);
    uint32_t drained = stray_vertices(o.ctx, &s, 0.3);
    finish(&o, &r);
    uint32_t finished = stray_vertices(o.ctx, &s, 0.3);
    print_message("angled: vertices 0.3 m or more from a wall: at most %u during scans 50-110 "
                  "(the walker there), %u after the last update, %u after finish\n",
                  mid, drained, finished);
    /* the walker was mapped while there (where it stood in cells the
     * robot had seen through before, their misses hold it off: 2-4
     * vertices at scans 63-100) */
    assert_true(mid > 0);
    assert_int_equal(finished, 0);
    /* the walker's polylines go once beams cross its cells again (a tile
     * whose cells with hits are crossed as often as it held endpoints joins
     * the backlog, and polylines left without data go) */
    assert_int_equal(drained, 0);
    online_close(&o);
    scene_free(&s);
}

/* ---- 4. finish against batch --------------------------------------------- */

static double core_rms(const polyc_ctx *ctx, const scene *s);

/* The scene's scans through an online context, an update after each, then
 * the finishing call: its map's score (and core RMS, when core is not
 * NULL; the first noise through the progress callback, when noise is not
 * NULL). */
static void online_finished_score(const scene *s, const polyc_scan *scans, gtscore_map_score *out,
                                  double *core, first_noise *noise)
{
    online o;
    polyc_online_report r;
    online_open(&o, s, 0);
    for (uint32_t i = 0; i < s->sim.scan_count; i++) {
        add(&o, &scans[i], 0);
        update(&o, POLYC_ONLINE_WORK_DEFAULT, &r);
    }
    check_status(polyc_online_finish(o.ctx, noise ? note_first_noise : NULL, noise, &r), o.ctx,
                 "polyc_online_finish");
    score_ctx(o.ctx, s, out);
    if (core)
        *core = core_rms(o.ctx, s);
    online_close(&o);
}

/* Measured (seed 7, default configuration, updates of the default budget):
 *   square  batch  4 vertices, RMS 2.90 mm, completeness 1.0000
 *           online 4 vertices, RMS 3.50 mm, completeness 1.0000
 *   office  batch 63 vertices, RMS 4.88 mm, completeness 0.9961
 *           online 60 vertices, RMS 5.05 mm, completeness 0.9986
 *   angled  batch 16 vertices, RMS 2.55 mm, completeness 1.0000
 *           online 13 vertices, RMS 2.60 mm, completeness 1.0000
 * (square +0.60 mm, office +0.17 mm, angled +0.05 mm: the online search
 * settles in another optimum, 3 vertices fewer on angled's walls; over the
 * sweep's 60 scenes the spread is in docs/performance.md). The tolerances
 * hold that gap and little more: a map that keeps a stray polyline, loses a
 * wall or doubles one breaks them. */
#define FINISH_RMS_M 0.0008        /* online RMS at most the batch's + this */
#define FINISH_COMPLETENESS 0.010  /* online completeness at least the batch's - this */
#define FINISH_VERTICES 0.25       /* vertices within this share of the batch's */

static void assert_scores_like(const char *what, const gtscore_map_score *got,
                               const gtscore_map_score *want, double rms_m, double completeness,
                               double vertices)
{
    int bad = 0;
    if (got->precision_rms_m > want->precision_rms_m + rms_m) {
        print_error("%s: RMS %.2f mm > %.2f mm + %.2f mm\n", what, 1e3 * got->precision_rms_m,
                    1e3 * want->precision_rms_m, 1e3 * rms_m);
        bad = 1;
    }
    if (got->completeness < want->completeness - completeness) {
        print_error("%s: completeness %.4f < %.4f - %.4f\n", what, got->completeness,
                    want->completeness, completeness);
        bad = 1;
    }
    if (fabs((double)got->vertices - (double)want->vertices) > vertices * (double)want->vertices) {
        print_error("%s: %u vertices, not within %.0f %% of %u\n", what, got->vertices,
                    1e2 * vertices, want->vertices);
        bad = 1;
    }
    if (bad)
        fail_msg("%s does not score like its reference", what);
}

static void compare_finish(const char *name)
{
    scene s;
    scene_make(&s, name, SCENE_SEED);
    gtscore_map_score b, f;
    first_noise bn = {0.0}, fn = {0.0};
    batch_score_n(&s, s.sim.scans, s.sim.scan_count, &b, &bn);
    online_finished_score(&s, s.sim.scans, &f, NULL, &fn);
    print_message("%s (first noise: batch %.4f m, finish %.4f m):\n", name, bn.noise_m, fn.noise_m);
    print_score("  batch", &b);
    print_score("  online finished", &f);
    assert_scores_like(name, &f, &b, FINISH_RMS_M, FINISH_COMPLETENESS, FINISH_VERTICES);
    /* the finishing search's noise starts two decays in (online_round.c,
     * FINISH_NOISE_SKIP): the updates fitted the map already */
    polyc_config c;
    config_of(&c);
    assert_true(fabs(bn.noise_m - (double)c.noise_m) < 1e-6);
    double cooler = (double)c.noise_m * (double)c.noise_decay * (double)c.noise_decay;
    assert_true(fabs(fn.noise_m - cooler) < 1e-6);
    /* and the project's targets (test_e2e.c) */
    assert_true(f.precision_rms_m <= 0.010);
    assert_true(f.completeness >= 0.98);
    scene_free(&s);
}

static void test_finish_against_batch(void **state)
{
    (void)state;
    compare_finish("square");
    compare_finish("office");
    compare_finish("angled");
}

/* Scans may be added after finish: the office's first half, finish, the
 * second half with updates, finish again. The map stays valid throughout,
 * the changes since the first finish rebuild its copy, and the end scores
 * like the batch map (measured: 58 vertices, RMS 5.24 mm, completeness
 * 0.9957 against the batch's 63, 4.88 mm, 0.9961). */
static void test_finish_then_more(void **state)
{
    (void)state;
    scene s;
    scene_make(&s, "office", SCENE_SEED);
    gtscore_map_score b, f;
    batch_score(&s, s.sim.scans, &b);
    online o;
    polyc_online_report r;
    online_open(&o, &s, 0);
    uint32_t half = s.sim.scan_count / 2, crossings, junctions;
    double cover;
    add_and_update(&o, &s, 0, half, &r);
    finish(&o, &r);
    assert_int_equal(r.backlog_tiles, 0);
    assert_int_equal(r.pending_scans, 0);
    map_copy mid;
    map_take(&mid, o.ctx);
    uint64_t mid_at = r.version;
    for (uint32_t i = half; i < s.sim.scan_count; i++) {
        add(&o, &s.sim.scans[i], 0);
        update(&o, POLYC_ONLINE_WORK_DEFAULT, &r);
        map_validity(o.ctx, &crossings, &junctions, &cover);
        assert_int_equal(crossings, 0);
        assert_true(cover == 0.0);
    }
    finish(&o, &r);
    uint32_t a = 0, m = 0, rm = 0, unseen = 0;
    check_changes_apply(o.ctx, &mid, mid_at, &a, &m, &rm, &unseen);
    score_ctx(o.ctx, &s, &f);
    print_message("office, finished half-way and at the end:\n");
    print_score("  batch", &b);
    print_score("  online", &f);
    assert_scores_like("finished twice", &f, &b, FINISH_RMS_M, FINISH_COMPLETENESS,
                       FINISH_VERTICES);
    map_free(&mid);
    online_close(&o);
    scene_free(&s);
}

/* finish's progress callback: called back with the context busy, and
 * asking to stop keeps a valid map (POLYC_ERR_STOPPED); updates go on. */
typedef struct stopper {
    polyc_ctx *ctx;
    uint32_t calls, stop_at;
    polyc_status busy;
} stopper;

static int stop_early(void *user, const polyc_iteration *it)
{
    stopper *st = user;
    (void)it;
    st->calls++;
    st->busy = polyc_online_update(st->ctx, POLYC_ONLINE_WORK_DEFAULT, NULL);
    return st->calls >= st->stop_at;
}

static void test_finish_stopped(void **state)
{
    (void)state;
    scene s;
    scene_make(&s, "office", SCENE_SEED);
    online o;
    polyc_online_report r;
    online_open(&o, &s, 0);
    add_and_update(&o, &s, 0, s.sim.scan_count / 2, &r);
    stopper st = {o.ctx, 0, 2, POLYC_OK};
    assert_int_equal(polyc_online_finish(o.ctx, stop_early, &st, &r), POLYC_ERR_STOPPED);
    assert_int_equal(st.calls, 2);
    assert_int_equal(st.busy, POLYC_ERR_BUSY);
    assert_true(polyc_polyline_count(o.ctx) > 0);
    assert_int_equal(r.polylines, polyc_polyline_count(o.ctx));
    uint32_t crossings, junctions;
    double cover;
    map_validity(o.ctx, &crossings, &junctions, &cover);
    assert_int_equal(crossings, 0);
    add_and_update(&o, &s, s.sim.scan_count / 2, s.sim.scan_count, &r);
    finish(&o, &r);
    assert_true(polyc_polyline_count(o.ctx) > 0);
    online_close(&o);
    scene_free(&s);
}

/* ---- 5. ten passes in the block for one ---------------------------------- */

/* What the requirement asks: ten passes run in the block sized for one,
 * every call OK, and the map scores like the batch map of the same ten
 * passes: measured (office, seed 7) ten passes online 60 vertices, RMS
 * 4.84 mm, completeness 0.9982; the batch map of the ten passes 69
 * vertices, 5.29 mm, 0.9990. */

static void test_ten_passes(void **state)
{
    (void)state;
    scene s;
    scene_make(&s, "office", SCENE_SEED);
    gtscore_map_score one, ten, batch_ten;
    online_finished_score(&s, s.sim.scans, &one, NULL, NULL);
    uint32_t n = s.sim.scan_count;
    polyc_scan *all = malloc(10u * n * sizeof *all);
    assert_non_null(all);
    for (uint32_t k = 0; k < 10u * n; k++)
        all[k] = s.sim.scans[k % n];
    batch_score_n(&s, all, 10u * n, &batch_ten, NULL);
    free(all);
    online o;
    polyc_online_report r;
    online_open(&o, &s, 0); /* limits_for_area and memory_size: for one pass */
    for (uint32_t pass = 0; pass < 10; pass++)
        for (uint32_t i = 0; i < s.sim.scan_count; i++) {
            polyc_status st = polyc_online_add_scan(o.ctx, &s.sim.scans[i], 0, NULL);
            if (st != POLYC_OK)
                fail_msg("pass %u scan %u: add: %s (%s)", pass, i, polyc_status_str(st),
                         polyc_last_error(o.ctx));
            st = polyc_online_update(o.ctx, POLYC_ONLINE_WORK_DEFAULT, &r);
            if (st != POLYC_OK)
                fail_msg("pass %u scan %u: update: %s (%s)", pass, i, polyc_status_str(st),
                         polyc_last_error(o.ctx));
        }
    assert_int_equal(r.scans, 10u * s.sim.scan_count);
    finish(&o, &r);
    score_ctx(o.ctx, &s, &ten);
    polyc_stats st;
    check_status(polyc_get_stats(o.ctx, &st), o.ctx, "polyc_get_stats");
    print_message("office, block of %zu bytes (stats: %llu used, %llu size):\n", o.size,
                  (unsigned long long)st.memory_used_bytes, (unsigned long long)st.memory_size_bytes);
    print_score("  online, one pass", &one);
    print_score("  batch, ten passes", &batch_ten);
    print_score("  online, ten passes", &ten);
    /* Ten passes carry the information of one: the online map of ten is
     * held to the online map of one. The batch map of ten is no vertex
     * reference: to the BIC, k copies of a log are k-fold certainty about
     * the same noise, and its search ends anywhere between 65 and 120
     * vertices (office.log repeated 2, 3, 5, 10 times: 96, 65-100, 109,
     * 68-120 over builds and seeds); its RMS and completeness still bound
     * the online map's. */
    assert_scores_like("ten passes", &ten, &one, FINISH_RMS_M, FINISH_COMPLETENESS,
                       FINISH_VERTICES);
    assert_true(ten.precision_rms_m <= batch_ten.precision_rms_m + FINISH_RMS_M);
    assert_true(ten.completeness >= batch_ten.completeness - FINISH_COMPLETENESS);
    assert_true(st.memory_size_bytes == o.size);
    assert_true(st.memory_used_bytes > 0 && st.memory_used_bytes <= o.size);
    online_close(&o);
    scene_free(&s);
}

/* ---- 6. pose corrections --------------------------------------------------- */

/* The scans with a growing pose error: per 100 scans 1 degree of heading
 * and 5 cm along x and y. A copy; the ranges are the scene's. */
static polyc_scan *drifted(const scene *s)
{
    polyc_scan *d = malloc(s->sim.scan_count * sizeof *d);
    assert_non_null(d);
    for (uint32_t i = 0; i < s->sim.scan_count; i++) {
        double e = (double)i / 100.0;
        d[i] = s->sim.scans[i];
        d[i].pose_theta_rad += e * PI / 180.0;
        d[i].pose_x_m += 0.05 * e;
        d[i].pose_y_m += 0.05 * e;
    }
    return d;
}

/* The precision RMS over the map's samples within 0.5 m of a true wall
 * (gtscore_core_precision, as the bench measures it). */
static double core_rms(const polyc_ctx *ctx, const scene *s)
{
    uint32_t n = polyc_polyline_count(ctx);
    polyc_polyline *lines = calloc(n ? n : 1u, sizeof *lines);
    assert_non_null(lines);
    for (uint32_t i = 0; i < n; i++)
        check_status(polyc_get_polyline(ctx, i, &lines[i]), ctx, "polyc_get_polyline");
    double rms = 0.0;
    assert_int_equal(gtscore_core_precision(&s->truth, lines, n, 0.5, &rms), 0);
    free(lines);
    return rms;
}

/* Measured (seed 7; RMS, completeness, vertices):
 *           batch, true poses      online drifted (updated / finished)
 *   square  2.90 mm, 1.0000, 4 v   32.34 / 34.68 mm, 0.8540 / 0.8530
 *   office  5.09 mm, 0.9963, 64 v  53.15 / 53.92 mm, 0.8141 / 0.8153
 *           online corrected       online, true poses
 *   square  3.70 mm, 1.0000, 4 v   3.53 mm, 1.0000, 4 v
 *   office  5.22 mm, 0.9978, 58 v  4.98 mm, 0.9978, 60 v
 * the backlog drained in 2 and 4 updates (the first applies the
 * corrections and does nothing else). */
#define CORRECT_DRAIN_UPDATES 20   /* updates the backlog drains in after corrections */
/* core RMS at most this above the online map of the true poses (no
 * drift, no corrections; measured: office +0.24 mm, square +0.17 mm; with
 * the drifted poses' accuracy pairs kept instead of learned again, office
 * +0.52 mm against the batch map). The reference is the online pipeline
 * itself: how far an online map may lie from the batch map is
 * compare_finish's question (FINISH_RMS_M). Against the batch map the
 * corrected square is 0.7988 mm above (the online map of the true poses
 * 0.63 mm, another optimum of 1 cm steps on four corners), so a bound
 * there would hold by a micrometre and test nothing about corrections. */
#define CORRECT_RMS_M 0.0005

static void check_correction(const char *name)
{
    scene s;
    scene_make(&s, name, SCENE_SEED);
    polyc_scan *bad = drifted(&s);
    gtscore_map_score batch, drift_fin, before, after;
    double batch_core;
    {
        polyc_config c;
        polyc_limits lim;
        polyc_ctx *ctx;
        config_of(&c);
        check_status(polyc_limits_for_scans(&c, s.sim.scans, s.sim.scan_count, &lim), NULL,
                     "polyc_limits_for_scans");
        size_t size = polyc_memory_size(&c, &lim);
        void *block = malloc(size);
        assert_non_null(block);
        check_status(polyc_init(block, size, &c, &lim, &ctx), NULL, "polyc_init");
        for (uint32_t i = 0; i < s.sim.scan_count; i++)
            check_status(polyc_add_scan(ctx, &s.sim.scans[i]), ctx, "polyc_add_scan");
        check_status(polyc_build(ctx, NULL, NULL), ctx, "polyc_build");
        score_ctx(ctx, &s, &batch);
        batch_core = core_rms(ctx, &s);
        free(block);
    }
    online_finished_score(&s, bad, &drift_fin, NULL, NULL);
    /* the reference: the worst of three optimiser seeds' online maps of
     * the true poses (the search's own spread: square 2.98, 3.53 mm ...) */
    gtscore_map_score truth_fin;
    double truth_core = 0.0, seed_core[3];
    for (uint32_t k = 0; k < 3; k++) {
        gtscore_map_score sc;
        seed_shift = k;
        online_finished_score(&s, s.sim.scans, &sc, &seed_core[k], NULL);
        if (k == 0 || seed_core[k] > truth_core) {
            truth_core = seed_core[k];
            truth_fin = sc;
        }
    }
    seed_shift = 0;
    print_message("  online true poses, core RMS at optimiser seeds +0, +1, +2: %.2f, %.2f, "
                  "%.2f mm\n", 1e3 * seed_core[0], 1e3 * seed_core[1], 1e3 * seed_core[2]);
    online o;
    polyc_online_report r;
    online_open(&o, &s, s.sim.scan_count);
    for (uint32_t i = 0; i < s.sim.scan_count; i++) {
        uint32_t id = UINT32_MAX;
        check_status(polyc_online_add_scan(o.ctx, &bad[i], 1, &id), o.ctx, "polyc_online_add_scan");
        assert_int_equal(id, i);
        update(&o, POLYC_ONLINE_WORK_DEFAULT, &r);
    }
    score_ctx(o.ctx, &s, &before);
    for (uint32_t i = 0; i < s.sim.scan_count; i++) {
        const polyc_scan *t = &s.sim.scans[i];
        check_status(polyc_online_correct(o.ctx, i, t->pose_x_m, t->pose_y_m, t->pose_theta_rad),
                     o.ctx, "polyc_online_correct");
    }
    /* the first update applies the corrections and does nothing else: they
     * spent its budget (a unit per two beams cast), the map is as it was,
     * every tile is in the backlog */
    uint64_t was = polyc_online_version(o.ctx);
    update(&o, POLYC_ONLINE_WORK_DEFAULT, &r);
    assert_true(r.work >= POLYC_ONLINE_WORK_DEFAULT);
    assert_int_equal(r.version, was);
    assert_true(r.backlog_tiles > 0);
    uint32_t updates = 1;
    do {
        update(&o, POLYC_ONLINE_WORK_DEFAULT, &r);
        updates++;
    } while (r.backlog_tiles > 0 && updates < 1000);
    assert_int_equal(r.pending_scans, 0);
    finish(&o, &r);
    score_ctx(o.ctx, &s, &after);
    double after_core = core_rms(o.ctx, &s);
    print_message("%s: corrections; the backlog drained in %u updates\n", name, updates);
    print_score("  batch, true poses", &batch);
    print_score("  online drifted, updated", &before);
    print_score("  online drifted, finished", &drift_fin);
    print_score("  online corrected", &after);
    print_score("  online true poses, finished", &truth_fin);
    print_message("  core RMS (within 0.5 m of a wall): batch %.2f mm, online true poses %.2f mm, "
                  "corrected %.2f mm\n",
                  1e3 * batch_core, 1e3 * truth_core, 1e3 * after_core);
    assert_true(updates <= CORRECT_DRAIN_UPDATES);
    /* like the batch map of the true poses */
    assert_true(after.completeness >= batch.completeness - FINISH_COMPLETENESS);
    assert_true(fabs((double)after.vertices - (double)batch.vertices) <=
                FINISH_VERTICES * (double)batch.vertices);
    assert_true(after_core <= truth_core + CORRECT_RMS_M);
    /* the whole map too: a 2 cm polyline on a walker's trail, traced before
     * the corrections (its cell 13 hits against 50 misses, m 0.21), went
     * only when the finishing call learned to drop short polylines under
     * which no cell is occupied (17.12 mm before) */
    assert_true(after.precision_rms_m <= batch.precision_rms_m + FINISH_RMS_M);
    /* and clearly better than the drifted map, updated or finished */
    assert_true(after.precision_rms_m < 0.5 * before.precision_rms_m);
    assert_true(after.precision_rms_m < 0.5 * drift_fin.precision_rms_m);
    assert_true(after.completeness > before.completeness + 0.1);
    assert_true(after.completeness > drift_fin.completeness + 0.1);
    online_close(&o);
    free(bad);
    scene_free(&s);
}

static void test_pose_correction(void **state)
{
    (void)state;
    check_correction("square");
    check_correction("office");
}

/* ---- 7. bad use ----------------------------------------------------------- */

/* The small scene (tests/small_scene.h) on an online context: a 12 m
 * square round its first pose, its 91 beams, keeping keep_scans scans of
 * keep_beams beams. */
#define SMALL_AREA_M 12.0

static void small_online(online *o, uint32_t keep_scans, uint32_t keep_beams)
{
    memset(o, 0, sizeof *o);
    small_config(&o->config);
    check_status(polyc_online_limits_for_area(&o->config, SMALL_AREA_M, 91u, &o->limits), NULL,
                 "polyc_online_limits_for_area");
    o->limits.keep_scans = keep_scans;
    o->limits.keep_beams = keep_beams;
    o->size = polyc_online_memory_size(&o->config, &o->limits);
    assert_true(o->size > 0);
    o->block = malloc(o->size);
    assert_non_null(o->block);
    check_status(polyc_online_init(o->block, o->size, &o->config, &o->limits, &o->ctx), NULL,
                 "polyc_online_init");
}

/* The status was `want` and the context says why. */
#define assert_fails(call, want, ctx)                                                          \
    do {                                                                                       \
        polyc_status st_ = (call);                                                             \
        if (st_ != (want))                                                                     \
            fail_msg("%s: %s, not %s", #call, polyc_status_str(st_), polyc_status_str(want));  \
        if (strlen(polyc_last_error(ctx)) == 0)                                                \
            fail_msg("%s: %s without a message", #call, polyc_status_str(st_));                \
    } while (0)

/* The map and its version as they were. */
static void assert_unchanged(const polyc_ctx *ctx, const map_copy *was, uint64_t version,
                             const char *after)
{
    map_copy now;
    map_take(&now, ctx);
    if (now.n != was->n || polyc_online_version(ctx) != version)
        fail_msg("after %s: %u polylines at version %llu, were %u at %llu", after, now.n,
                 (unsigned long long)polyc_online_version(ctx), was->n,
                 (unsigned long long)version);
    assert_maps_equal(&now, was);
    map_free(&now);
}

static void test_bad_use(void **state)
{
    (void)state;
    scansim_scene sc;
    assert_int_equal(small_scene(&sc), 0);
    polyc_config c;
    small_config(&c);
    polyc_online_limits lim, bad;
    online o;
    uint32_t id = 0, count = 0;

    /* limits, sizes, init */
    assert_int_equal(polyc_online_limits_for_area(NULL, SMALL_AREA_M, 91u, &lim), POLYC_ERR_NULL);
    assert_int_equal(polyc_online_limits_for_area(&c, SMALL_AREA_M, 91u, NULL), POLYC_ERR_NULL);
    assert_int_equal(polyc_online_limits_for_area(&c, 0.5, 91u, &lim), POLYC_ERR_CONFIG);
    assert_int_equal(polyc_online_limits_for_area(&c, NAN, 91u, &lim), POLYC_ERR_CONFIG);
    assert_int_equal(polyc_online_limits_for_area(&c, SMALL_AREA_M, 0u, &lim), POLYC_ERR_CONFIG);
    check_status(polyc_online_limits_for_area(&c, SMALL_AREA_M, 91u, &lim), NULL, "limits");
    assert_true(polyc_online_memory_size(&c, &lim) > 0);
    assert_int_equal(polyc_online_memory_size(NULL, &lim), 0);
    assert_int_equal(polyc_online_memory_size(&c, NULL), 0);
    bad = lim, bad.reserved = 1;
    assert_int_equal(polyc_online_memory_size(&c, &bad), 0);
    bad = lim, bad.area_m = 0.0;
    assert_int_equal(polyc_online_memory_size(&c, &bad), 0);
    bad = lim, bad.area_m = NAN;
    assert_int_equal(polyc_online_memory_size(&c, &bad), 0);
    bad = lim, bad.max_scan_beams = 0;
    assert_int_equal(polyc_online_memory_size(&c, &bad), 0);
    bad = lim, bad.max_grid_cells = 0;
    assert_int_equal(polyc_online_memory_size(&c, &bad), 0);
    bad = lim, bad.max_vertices = 0;
    assert_int_equal(polyc_online_memory_size(&c, &bad), 0);
    bad = lim, bad.max_points = 0;
    assert_int_equal(polyc_online_memory_size(&c, &bad), 0);
    bad = lim, bad.keep_scans = UINT32_MAX;
    assert_int_equal(polyc_online_memory_size(&c, &bad), 0);
    {
        polyc_config bc = c;
        bc.cell_m = 0.0f;
        assert_int_equal(polyc_online_memory_size(&bc, &lim), 0);
    }
    small_online(&o, 2u, 2u * 91u);
    polyc_ctx *out = (polyc_ctx *)&o; /* not NULL: init must clear it */
    assert_int_equal(polyc_online_init(o.block, o.size, &c, &lim, NULL), POLYC_ERR_NULL);
    assert_int_equal(polyc_online_init(NULL, o.size, &c, &lim, &out), POLYC_ERR_NULL);
    assert_null(out);
    assert_int_equal(polyc_online_init(o.block, o.size, NULL, &lim, &out), POLYC_ERR_NULL);
    assert_int_equal(polyc_online_init(o.block, o.size, &c, NULL, &out), POLYC_ERR_NULL);
    bad = o.limits, bad.reserved = 1;
    assert_int_equal(polyc_online_init(o.block, o.size, &c, &bad, &out), POLYC_ERR_CONFIG);
    out = (polyc_ctx *)&o;
    assert_int_equal(polyc_online_init(o.block, o.size - 1u, &c, &o.limits, &out), POLYC_ERR_NOMEM);
    assert_null(out);
    check_status(polyc_online_init(o.block, o.size, &o.config, &o.limits, &o.ctx), NULL, "init");
    polyc_ctx *ctx = o.ctx;

    /* before any scan */
    assert_fails(polyc_online_update(ctx, POLYC_ONLINE_WORK_DEFAULT, NULL), POLYC_ERR_STATE, ctx);
    assert_fails(polyc_online_finish(ctx, NULL, NULL, NULL), POLYC_ERR_STATE, ctx);
    assert_int_equal(polyc_online_version(ctx), 0);
    assert_int_equal(polyc_polyline_count(ctx), 0);
    assert_int_equal(polyc_online_changes(ctx, 0, NULL, 0, &count), POLYC_OK);
    assert_int_equal(count, 0);

    /* NULLs */
    assert_int_equal(polyc_online_add_scan(NULL, &sc.scans[0], 0, &id), POLYC_ERR_NULL);
    assert_int_equal(polyc_online_add_scan(ctx, NULL, 0, &id), POLYC_ERR_NULL);
    {
        polyc_scan s = sc.scans[0];
        s.range_m = NULL;
        assert_fails(polyc_online_add_scan(ctx, &s, 0, &id), POLYC_ERR_NULL, ctx);
    }
    assert_int_equal(polyc_online_update(NULL, POLYC_ONLINE_WORK_DEFAULT, NULL), POLYC_ERR_NULL);
    assert_int_equal(polyc_online_finish(NULL, NULL, NULL, NULL), POLYC_ERR_NULL);
    assert_int_equal(polyc_online_correct(NULL, 0, 0.0, 0.0, 0.0), POLYC_ERR_NULL);
    assert_int_equal(polyc_online_changes(NULL, 0, NULL, 0, &count), POLYC_ERR_NULL);
    assert_int_equal(polyc_online_changes(ctx, 0, NULL, 0, NULL), POLYC_ERR_NULL);
    assert_int_equal(polyc_polyline_id(NULL, 0, &id), POLYC_ERR_NULL);
    assert_int_equal(polyc_polyline_id(ctx, 0, NULL), POLYC_ERR_NULL);
    assert_int_equal(polyc_online_version(NULL), 0);
    assert_true(strlen(polyc_last_error(NULL)) > 0);
    /* a malformed scan */
    {
        polyc_scan s = sc.scans[0];
        s.pose_x_m = NAN;
        assert_fails(polyc_online_add_scan(ctx, &s, 0, &id), POLYC_ERR_SCAN, ctx);
    }

    /* keeping: scans 0 and 1 kept, the third refused and not added */
    check_status(polyc_online_add_scan(ctx, &sc.scans[0], 1, &id), ctx, "add 0");
    assert_int_equal(id, 0);
    check_status(polyc_online_add_scan(ctx, &sc.scans[1], 1, &id), ctx, "add 1");
    assert_int_equal(id, 1);
    assert_fails(polyc_online_add_scan(ctx, &sc.scans[2], 1, &id), POLYC_ERR_LIMIT, ctx);
    polyc_stats stats;
    check_status(polyc_get_stats(ctx, &stats), ctx, "stats");
    assert_int_equal(stats.scans, 2);
    check_status(polyc_online_add_scan(ctx, &sc.scans[2], 0, &id), ctx, "add 2");
    assert_int_equal(id, 2);

    /* budgets */
    assert_fails(polyc_online_update(ctx, 0, NULL), POLYC_ERR_CONFIG, ctx);
    polyc_online_report r;
    check_status(polyc_online_update(ctx, POLYC_ONLINE_WORK_DEFAULT, &r), ctx, "update");
    assert_true(polyc_polyline_count(ctx) > 0);
    assert_true(r.version > 0);
    assert_int_equal(polyc_online_changes(ctx, r.version + 5u, NULL, 0, &count), POLYC_OK);
    assert_int_equal(count, 0);
    map_copy was;
    map_take(&was, ctx);
    assert_int_equal(polyc_polyline_id(ctx, was.n, &id), POLYC_ERR_RANGE);

    /* corrections: an unkept scan, an unknown one, a bad pose, a pose
     * that takes the scan out of the area */
    assert_fails(polyc_online_correct(ctx, 2, 10.0, -2.0, 0.0), POLYC_ERR_RANGE, ctx);
    assert_fails(polyc_online_correct(ctx, 99, 10.0, -2.0, 0.0), POLYC_ERR_RANGE, ctx);
    assert_fails(polyc_online_correct(ctx, 0, NAN, -2.0, 0.0), POLYC_ERR_SCAN, ctx);
    assert_fails(polyc_online_correct(ctx, 0, sc.scans[0].pose_x_m + 50.0, sc.scans[0].pose_y_m,
                                      sc.scans[0].pose_theta_rad),
                 POLYC_ERR_EXTENT, ctx);

    /* too many beams; too many kept beams (a second context) */
    {
        float ranges[92];
        polyc_scan s = sc.scans[0];
        for (uint32_t i = 0; i < 92u; i++)
            ranges[i] = 1.0f;
        s.beam_count = 92u;
        s.range_m = ranges;
        assert_fails(polyc_online_add_scan(ctx, &s, 0, &id), POLYC_ERR_LIMIT, ctx);
        online k;
        small_online(&k, 3u, 91u + 45u);
        check_status(polyc_online_add_scan(k.ctx, &sc.scans[0], 1, &id), k.ctx, "keep 0");
        assert_fails(polyc_online_add_scan(k.ctx, &sc.scans[1], 1, &id), POLYC_ERR_LIMIT, k.ctx);
        s = sc.scans[1];
        s.beam_count = 45u;
        check_status(polyc_online_add_scan(k.ctx, &s, 1, &id), k.ctx, "keep 45 beams");
        online_close(&k);
    }

    /* outside the area: the pose, or one endpoint; nothing added */
    {
        polyc_scan s = sc.scans[1];
        s.pose_x_m += 20.0;
        assert_fails(polyc_online_add_scan(ctx, &s, 0, &id), POLYC_ERR_EXTENT, ctx);
        float ranges[91];
        memcpy(ranges, sc.scans[1].range_m, sizeof ranges);
        ranges[45] = 9.0f;
        s = sc.scans[1];
        s.max_range_m = 30.0f;
        s.range_m = ranges;
        assert_fails(polyc_online_add_scan(ctx, &s, 0, &id), POLYC_ERR_EXTENT, ctx);
    }
    check_status(polyc_get_stats(ctx, &stats), ctx, "stats");
    assert_int_equal(stats.scans, 3);
    assert_unchanged(ctx, &was, r.version, "the refused scans");

    /* the batch calls */
    {
        polyc_occupancy_grid g;
        int8_t cells[4] = {0, 100, 0, 0};
        memset(&g, 0, sizeof g);
        g.width = g.height = 2;
        g.resolution_m = 0.05f;
        g.cells = cells;
        double bic, err;
        assert_fails(polyc_add_scan(ctx, &sc.scans[0]), POLYC_ERR_STATE, ctx);
        assert_unchanged(ctx, &was, r.version, "polyc_add_scan");
        assert_fails(polyc_add_grid(ctx, &g), POLYC_ERR_STATE, ctx);
        assert_unchanged(ctx, &was, r.version, "polyc_add_grid");
        assert_fails(polyc_reset(ctx), POLYC_ERR_STATE, ctx);
        assert_unchanged(ctx, &was, r.version, "polyc_reset");
        assert_fails(polyc_optimize(ctx, NULL, NULL), POLYC_ERR_STATE, ctx);
        assert_unchanged(ctx, &was, r.version, "polyc_optimize");
        assert_fails(polyc_build(ctx, NULL, NULL), POLYC_ERR_STATE, ctx);
        assert_unchanged(ctx, &was, r.version, "polyc_build");
        assert_fails(polyc_score(ctx, &bic, &err), POLYC_ERR_STATE, ctx);
        assert_unchanged(ctx, &was, r.version, "polyc_score");
        assert_fails(polyc_build_grid(ctx), POLYC_ERR_STATE, ctx);
        assert_fails(polyc_extract_contour(ctx), POLYC_ERR_STATE, ctx);
        assert_fails(polyc_trace(ctx), POLYC_ERR_STATE, ctx);
        assert_unchanged(ctx, &was, r.version, "the stage calls");
        /* the online calls still work (and an update publishes the map again) */
        check_status(polyc_online_add_scan(ctx, &sc.scans[2], 0, &id), ctx, "add");
        check_status(polyc_online_update(ctx, POLYC_ONLINE_WORK_DEFAULT, &r), ctx, "update");
    }

    /* the online calls on a batch context */
    {
        polyc_limits bl;
        check_status(polyc_limits_for_scans(&c, sc.scans, sc.scan_count, &bl), NULL, "limits");
        size_t bs = polyc_memory_size(&c, &bl);
        void *bb = malloc(bs);
        assert_non_null(bb);
        polyc_ctx *batch;
        check_status(polyc_init(bb, bs, &c, &bl, &batch), NULL, "polyc_init");
        assert_fails(polyc_online_add_scan(batch, &sc.scans[0], 0, &id), POLYC_ERR_STATE, batch);
        for (uint32_t i = 0; i < sc.scan_count; i++)
            check_status(polyc_add_scan(batch, &sc.scans[i]), batch, "polyc_add_scan");
        check_status(polyc_build(batch, NULL, NULL), batch, "polyc_build");
        assert_fails(polyc_online_update(batch, POLYC_ONLINE_WORK_DEFAULT, NULL), POLYC_ERR_STATE,
                     batch);
        assert_fails(polyc_online_finish(batch, NULL, NULL, NULL), POLYC_ERR_STATE, batch);
        assert_fails(polyc_online_correct(batch, 0, 10.0, -2.0, 0.0), POLYC_ERR_STATE, batch);
        assert_int_equal(polyc_online_changes(batch, 0, NULL, 0, &count), POLYC_ERR_STATE);
        assert_int_equal(polyc_online_version(batch), 0);
        /* ids on a batch map too: from 1, distinct */
        uint32_t n = polyc_polyline_count(batch), prev = 0;
        assert_true(n > 0);
        for (uint32_t i = 0; i < n; i++) {
            check_status(polyc_polyline_id(batch, i, &id), batch, "polyc_polyline_id");
            assert_true(id >= 1 && id != prev);
            prev = id;
        }
        free(bb);
    }
    map_free(&was);
    online_close(&o);
    scansim_scene_free(&sc);
}

/* An update that runs out of room (vertices) leaves the context as valid as
 * before: later scans still get grid tiles (the update's scratch sat above
 * the tiles and was not given back). An 8 m x 5 m room, scans all round. */
static float room_cast(double x, double y, double a)
{
    double dx = cos(a), dy = sin(a), best = 30.0, t;
    if (dx > 1e-12 && (t = (8.0 - x) / dx) < best) best = t;
    if (dx < -1e-12 && (t = -x / dx) < best) best = t;
    if (dy > 1e-12 && (t = (5.0 - y) / dy) < best) best = t;
    if (dy < -1e-12 && (t = -y / dy) < best) best = t;
    return (float)best;
}

static void test_nomem_update_then_scans(void **state)
{
    (void)state;
    polyc_config cfg;
    polyc_config_default(&cfg);
    cfg.cell_m = 0.05f;
    polyc_online_limits lim;
    check_status(polyc_online_limits_for_area(&cfg, 16.0, 361, &lim), NULL, "limits");
    lim.max_vertices = 64;
    size_t n = polyc_online_memory_size(&cfg, &lim);
    assert_true(n > 0);
    void *block = malloc(n);
    assert_non_null(block);
    polyc_ctx *ctx;
    check_status(polyc_online_init(block, n, &cfg, &lim, &ctx), NULL, "init");
    float r[361];
    int nomem = 0;
    uint32_t seed = 12345; /* +-1 cm of noise: more vertices than 64 */
    for (int k = 0; k < 5; k++) {
        double x = 1.5 + 0.4348 * k, y = 1.8, th = 0.1 * k;
        polyc_scan s = {x, y, th, (float)-3.14159265, (float)(2 * 3.14159265 / 360), 0.02f, 30.0f, 361, 0, r};
        for (int i = 0; i < 361; i++) {
            seed = seed * 1664525u + 1013904223u;
            r[i] = room_cast(x, y, th + (double)s.start_angle_rad + (double)i * (double)s.angle_step_rad) +
                   0.02f * ((float)(seed >> 8) / 16777216.0f - 0.5f);
        }
        check_status(polyc_online_add_scan(ctx, &s, 0, NULL), ctx, "add");
        if (k == 1) {
            polyc_status st = polyc_online_update(ctx, POLYC_ONLINE_WORK_DEFAULT, NULL);
            nomem = st == POLYC_ERR_NOMEM;
            assert_true(st == POLYC_OK || st == POLYC_ERR_NOMEM);
        }
    }
    assert_true(nomem); /* the case this test is for */
    free(block);
}

/* Data cells too few for the office (limits.max_points 1,500 and 2,000):
 * an add whose endpoints would outgrow them, or the weighted points an
 * update collects from them, is refused with POLYC_ERR_NOMEM and leaves
 * nothing behind; every update after an accepted add runs, and so does the
 * finish. (Before: every add succeeded, and from scan 10 or 25 on every
 * update and the finish failed with POLYC_ERR_NOMEM, for good.) */
static void test_points_never_wedge(void **state)
{
    (void)state;
    scene s;
    scene_make(&s, "office", SCENE_SEED);
    const uint32_t points[2] = {1500, 2000};
    for (int k = 0; k < 2; k++) {
        online o;
        memset(&o, 0, sizeof o);
        config_of(&o.config);
        check_status(polyc_online_limits_for_area(&o.config, s.area_m, s.beams, &o.limits), NULL,
                     "limits");
        o.limits.max_points = points[k];
        o.size = polyc_online_memory_size(&o.config, &o.limits);
        o.block = malloc(o.size);
        assert_non_null(o.block);
        check_status(polyc_online_init(o.block, o.size, &o.config, &o.limits, &o.ctx), NULL, "init");
        uint32_t refused = 0, accepted = 0;
        for (uint32_t i = 0; i < s.sim.scan_count; i++) {
            polyc_stats before, after;
            check_status(polyc_get_stats(o.ctx, &before), o.ctx, "stats");
            polyc_status st = polyc_online_add_scan(o.ctx, &s.sim.scans[i], 0, NULL);
            check_status(polyc_get_stats(o.ctx, &after), o.ctx, "stats");
            if (st == POLYC_ERR_NOMEM) {
                refused++;
                assert_true(after.scans == before.scans && after.hits == before.hits);
                assert_non_null(strstr(polyc_last_error(o.ctx), "max_points"));
            } else {
                check_status(st, o.ctx, "add");
                accepted++;
            }
            st = polyc_online_update(o.ctx, POLYC_ONLINE_WORK_DEFAULT, NULL);
            if (st != POLYC_OK)
                fail_msg("max_points %u, scan %u: update: %s (%s)", points[k], i,
                         polyc_status_str(st), polyc_last_error(o.ctx));
        }
        polyc_online_report r;
        check_status(polyc_online_finish(o.ctx, NULL, NULL, &r), o.ctx, "finish");
        uint32_t crossings, junctions;
        double cover;
        map_validity(o.ctx, &crossings, &junctions, &cover);
        print_message("office, max_points %u: %u scans accepted, %u refused; finished: %u "
                      "polylines, %u vertices, %u crossings\n",
                      points[k], accepted, refused, r.polylines, r.vertices, crossings);
        assert_true(accepted > 0 && refused > 0 && r.polylines > 0 && crossings == 0);
        online_close(&o);
    }
    scene_free(&s);
}

/* ---- 8. exhaustion ---------------------------------------------------------- */

#define GUARD 64
#define GUARD_BYTE 0xa5

/* A block of `size` bytes at offset `skew` of a buffer with guard bytes
 * on both sides. */
static unsigned char *guarded(size_t size, size_t skew)
{
    unsigned char *raw = malloc(size + skew + 2 * GUARD);
    assert_non_null(raw);
    memset(raw, GUARD_BYTE, size + skew + 2 * GUARD);
    return raw;
}

static void guard_check(const unsigned char *raw, size_t size, size_t skew)
{
    for (size_t i = 0; i < GUARD + skew; i++)
        if (raw[i] != GUARD_BYTE)
            fail_msg("block of %zu bytes (skew %zu): byte %zu before it written", size, skew,
                     GUARD + skew - i);
    for (size_t i = 0; i < GUARD; i++)
        if (raw[GUARD + skew + size + i] != GUARD_BYTE)
            fail_msg("block of %zu bytes (skew %zu): byte %zu after it written", size, skew, i);
}

/* The scans through an online context in the block: adds, updates (a
 * small budget, then the default) and finish all OK, a valid map. */
static void run_through(polyc_ctx *ctx, const polyc_scan *scans, uint32_t n)
{
    polyc_online_report r;
    for (uint32_t i = 0; i < n; i++) {
        check_status(polyc_online_add_scan(ctx, &scans[i], 0, NULL), ctx, "polyc_online_add_scan");
        check_status(polyc_online_update(ctx, i % 2 ? 1u : POLYC_ONLINE_WORK_DEFAULT, &r), ctx,
                     "polyc_online_update");
    }
    check_status(polyc_online_finish(ctx, NULL, NULL, &r), ctx, "polyc_online_finish");
    assert_true(polyc_polyline_count(ctx) > 0);
    assert_int_equal(r.polylines, polyc_polyline_count(ctx));
}

static void test_exhaustion(void **state)
{
    (void)state;
    scansim_scene sc;
    assert_int_equal(small_scene(&sc), 0);
    polyc_config c;
    polyc_online_limits lim;
    small_config(&c);
    check_status(polyc_online_limits_for_area(&c, SMALL_AREA_M, 91u, &lim), NULL, "limits");
    lim.keep_scans = 3;
    lim.keep_beams = 3 * 91;
    size_t size = polyc_online_memory_size(&c, &lim);
    assert_true(size > 0);
    size_t from = size > 65536u ? size - 65536u : 0;
    uint32_t tried = 0;
    /* below the size: every 512 bytes from 64 KiB under it, and the last
     * 64 byte by byte; NOMEM, no context, nothing written outside */
    for (size_t b = from; b < size; b += (size - b > 64u ? 512u : 1u)) {
        for (size_t skew = 0; skew < 16; skew += 5) {
            unsigned char *raw = guarded(b, skew);
            polyc_ctx *ctx = (polyc_ctx *)(void *)raw;
            polyc_status st = polyc_online_init(raw + GUARD + skew, b, &c, &lim, &ctx);
            if (st != POLYC_ERR_NOMEM)
                fail_msg("block of %zu bytes (size %zu): %s", b, size, polyc_status_str(st));
            assert_null(ctx);
            guard_check(raw, b, skew);
            free(raw);
            tried++;
        }
    }
    /* at the size, at every alignment: the scene runs through, keeping
     * its scans and correcting one, inside the block */
    for (size_t skew = 0; skew < 16; skew++) {
        unsigned char *raw = guarded(size, skew);
        polyc_ctx *ctx = NULL;
        check_status(polyc_online_init(raw + GUARD + skew, size, &c, &lim, &ctx), NULL,
                     "polyc_online_init at the size");
        for (uint32_t i = 0; i < sc.scan_count; i++)
            check_status(polyc_online_add_scan(ctx, &sc.scans[i], 1, NULL), ctx, "keep");
        check_status(polyc_online_update(ctx, POLYC_ONLINE_WORK_DEFAULT, NULL), ctx, "update");
        check_status(polyc_online_correct(ctx, 1, sc.scans[1].pose_x_m + 0.02,
                                          sc.scans[1].pose_y_m, sc.scans[1].pose_theta_rad),
                     ctx, "polyc_online_correct");
        run_through(ctx, sc.scans, sc.scan_count);
        assert_int_equal(map_is_valid(ctx, 11.5, -2.0, 4.0), 0);
        guard_check(raw, size, skew);
        free(raw);
    }
    print_message("online block of %zu bytes: %u smaller blocks refused\n", size, tried);
    /* a larger scene at its size, in a guarded block */
    scene s;
    scene_make(&s, "office", SCENE_SEED);
    polyc_online_limits ol;
    polyc_config oc;
    config_of(&oc);
    oc.max_iterations = 50;
    check_status(polyc_online_limits_for_area(&oc, s.area_m, s.beams, &ol), NULL, "limits");
    size_t os = polyc_online_memory_size(&oc, &ol);
    unsigned char *raw = guarded(os, 3);
    polyc_ctx *ctx = NULL;
    check_status(polyc_online_init(raw + GUARD + 3, os, &oc, &ol, &ctx), NULL, "init");
    run_through(ctx, s.sim.scans, s.sim.scan_count);
    guard_check(raw, os, 3);
    free(raw);
    scene_free(&s);
    scansim_scene_free(&sc);
}

/* Each of max_points, max_vertices and max_grid_cells swept from the least
 * valid value up to enough: every call returns OK or POLYC_ERR_NOMEM (with
 * a message), and the context stays readable and its map valid. */
static void sweep_limit(const scansim_scene *sc, uint32_t which, uint32_t lo, uint32_t hi,
                        uint32_t step, uint32_t *nomem)
{
    polyc_config c;
    small_config(&c);
    for (uint32_t v = lo; v <= hi; v += step) {
        polyc_online_limits lim;
        check_status(polyc_online_limits_for_area(&c, SMALL_AREA_M, 91u, &lim), NULL, "limits");
        if (which == 0)
            lim.max_points = v;
        else if (which == 1)
            lim.max_vertices = v;
        else
            lim.max_grid_cells = v;
        size_t size = polyc_online_memory_size(&c, &lim);
        assert_true(size > 0);
        unsigned char *raw = guarded(size, 0);
        polyc_ctx *ctx = NULL;
        check_status(polyc_online_init(raw + GUARD, size, &c, &lim, &ctx), NULL, "init");
        polyc_status st;
        for (uint32_t pass = 0; pass < 2; pass++)
            for (uint32_t i = 0; i < sc->scan_count; i++) {
                st = polyc_online_add_scan(ctx, &sc->scans[i], 0, NULL);
                /* an add that would run out of max_points is refused and
                 * the updates go on */
                if (st == POLYC_OK)
                    st = polyc_online_update(ctx, i % 2 ? 1u : POLYC_ONLINE_WORK_DEFAULT, NULL);
                if (st != POLYC_OK && st != POLYC_ERR_NOMEM)
                    fail_msg("limit %u = %u: %s (%s)", which, v, polyc_status_str(st),
                             polyc_last_error(ctx));
                if (st != POLYC_OK) {
                    assert_true(strlen(polyc_last_error(ctx)) > 0);
                    (*nomem)++;
                }
                assert_int_equal(map_is_valid(ctx, 11.5, -2.0, 4.0), 0);
            }
        st = polyc_online_finish(ctx, NULL, NULL, NULL);
        polyc_stats stats;
        check_status(polyc_get_stats(ctx, &stats), ctx, "stats");
        /* (with max_points too small for any scan's endpoints, every add is
         * refused: then there is nothing to finish) */
        int none = st == POLYC_ERR_STATE && stats.scans == 0;
        if (st != POLYC_OK && st != POLYC_ERR_NOMEM && !none)
            fail_msg("limit %u = %u: finish: %s (%s)", which, v, polyc_status_str(st),
                     polyc_last_error(ctx));
        (*nomem) += st != POLYC_OK;
        assert_int_equal(map_is_valid(ctx, 11.5, -2.0, 4.0), 0);
        guard_check(raw, size, 0);
        free(raw);
    }
}

static void test_exhaustion_limits(void **state)
{
    (void)state;
    scansim_scene sc;
    assert_int_equal(small_scene(&sc), 0);
    uint32_t points = 0, vertices = 0, cells = 0;
    sweep_limit(&sc, 0, 16u, 400u, 8u, &points);
    sweep_limit(&sc, 1, 16u, 80u, 2u, &vertices);
    sweep_limit(&sc, 2, 1024u, 40u * 1024u, 1024u, &cells);
    print_message("limits swept: %u, %u and %u calls ran out of points, vertices and grid cells\n",
                  points, vertices, cells);
    /* the sweeps reach the limits */
    assert_true(points > 0 && cells > 0);
    scansim_scene_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_update_within_budget),
        cmocka_unit_test(test_changes_since_version),
        cmocka_unit_test(test_changes_forgotten),
        cmocka_unit_test(test_valid_between_updates),
        cmocka_unit_test(test_walker_trail),
        cmocka_unit_test(test_finish_against_batch),
        cmocka_unit_test(test_finish_then_more),
        cmocka_unit_test(test_finish_stopped),
        cmocka_unit_test(test_ten_passes),
        cmocka_unit_test(test_pose_correction),
        cmocka_unit_test(test_bad_use),
        cmocka_unit_test(test_nomem_update_then_scans),
        cmocka_unit_test(test_points_never_wedge),
        cmocka_unit_test(test_exhaustion),
        cmocka_unit_test(test_exhaustion_limits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
