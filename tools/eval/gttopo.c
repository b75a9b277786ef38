/* gttopo.c - topology figures of a polyline map (definitions in gttopo.h).
 *
 * Takes a map and data points; gives double cover, crossings, unsupported
 * runs and loose ends. The map goes into a gtscore_index; every segment
 * keeps its samples' place in one flag array, its polyline and its
 * neighbours, so that each figure is a walk over flags or over cells.
 */
#include "gttopo.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gtscore.h"

#define MAP_CELL_M 0.10            /* the map's grid, as gtscore.c builds it for 5 cm */
#define RUN_EPS_M 1e-6             /* "longer than" and "after": to within 1 um */
#define NO_SEG UINT32_MAX
#define F_SUPPORTED 1u             /* a data point within GTTOPO_COVER_M */

typedef struct topo_seg {
    uint32_t first;                /* its first sample in topo_map.flags */
    uint32_t pieces;               /* n: samples k = 0 .. n - 1 at k / n */
    uint32_t samples;              /* n, or n + 1 with an open polyline's last point */
    uint32_t prev, next;           /* neighbour segments, NO_SEG if none */
    double length_m;
    double spacing_m;              /* length / n */
} topo_seg;

typedef struct topo_map {
    gtscore_index index;           /* segment s is index.seg_m[4 s ...] */
    topo_seg *segs;                /* index.seg_count */
    uint32_t *line_first;          /* count + 1: polyline l has segments [l], [l + 1] */
    uint8_t *flags;                /* sample_count */
    uint32_t sample_count;
} topo_map;

static void topo_free(topo_map *m)
{
    gtscore_index_free(&m->index);
    free(m->segs);
    free(m->line_first);
    free(m->flags);
    memset(m, 0, sizeof *m);
}

/* Sample k of segment s, as gtscore.c's precision places it. */
static void sample_xy(const topo_map *m, uint32_t s, uint32_t k, double *x, double *y)
{
    const double *g = &m->index.seg_m[4u * s];
    const topo_seg *t = &m->segs[s];
    if (k >= t->pieces) { /* the open polyline's last point */
        *x = g[2];
        *y = g[3];
    } else {
        double u = (double)k / (double)t->pieces;
        *x = g[0] + (g[2] - g[0]) * u;
        *y = g[1] + (g[3] - g[1]) * u;
    }
}

/* One polyline's segments, in the order gtscore_index_add_polylines adds
 * them. */
static int add_line_segments(topo_map *m, const polyc_polyline *pl, uint32_t *s,
                             uint64_t *samples)
{
    uint32_t pc = pl->point_count, segs, j, first = *s;
    int closed = pl->closed && pc > 2u;
    if (pc == 0)
        return 0;
    segs = pc == 1u ? 1u : closed ? pc : pc - 1u;
    if (first + segs > m->index.seg_count)
        return -1;
    for (j = 0; j < segs; j++) {
        const double *g = &m->index.seg_m[4u * (first + j)];
        topo_seg *t = &m->segs[first + j];
        double len = hypot(g[2] - g[0], g[3] - g[1]);
        double pieces = ceil(len / GTSCORE_SAMPLE_M - 1e-9);
        if (pieces > 1e9)
            return -1;
        t->pieces = pieces < 1.0 ? 1u : (uint32_t)pieces;
        t->samples = t->pieces + (pc > 1u && !closed && j == segs - 1u ? 1u : 0u);
        t->length_m = len;
        t->spacing_m = len / (double)t->pieces;
        t->prev = j > 0 ? first + j - 1u : closed ? first + segs - 1u : NO_SEG;
        t->next = j + 1u < segs ? first + j + 1u : closed ? first : NO_SEG;
        if (*samples + t->samples > UINT32_MAX)
            return -1;
        t->first = (uint32_t)*samples;
        *samples += t->samples;
    }
    *s = first + segs;
    return 0;
}

static int topo_build(topo_map *m, const polyc_polyline *lines, uint32_t count)
{
    uint64_t samples = 0;
    uint32_t l, s = 0;
    memset(m, 0, sizeof *m);
    gtscore_index_init(&m->index);
    for (l = 0; l < count; l++)
        if (lines[l].point_count && !lines[l].xy_m)
            return -1;
    if (gtscore_index_add_polylines(&m->index, lines, count) != 0 ||
        gtscore_index_build(&m->index, MAP_CELL_M) != 0)
        return -1;
    m->segs = malloc((m->index.seg_count ? m->index.seg_count : 1u) * sizeof *m->segs);
    m->line_first = malloc(((size_t)count + 1u) * sizeof *m->line_first);
    if (!m->segs || !m->line_first)
        return -1;
    for (l = 0; l < count; l++) {
        m->line_first[l] = s;
        if (add_line_segments(m, &lines[l], &s, &samples) != 0)
            return -1;
    }
    m->line_first[count] = s;
    if (s != m->index.seg_count)
        return -1;
    m->sample_count = (uint32_t)samples;
    m->flags = calloc(samples ? (size_t)samples : 1u, 1u);
    return m->flags ? 0 : -1;
}

/* ---- support: the samples within reach of each data point ---------------- */

/* Flags the samples of segment s within r_m of (px, py). Only the few
 * samples around the point's projection are tested, each exactly. */
static void support_segment(topo_map *m, uint32_t s, double px, double py, double r_m)
{
    const double *g = &m->index.seg_m[4u * s];
    const topo_seg *t = &m->segs[s];
    double ex = g[2] - g[0], ey = g[3] - g[1], wx = px - g[0], wy = py - g[1];
    double len2 = ex * ex + ey * ey, lo = 0.0, hi = (double)(t->samples - 1u);
    uint32_t k, k0, k1;
    if (len2 > 0.0) {
        double u = (wx * ex + wy * ey) / len2;
        double perp2 = wx * wx + wy * wy - u * u * len2;
        double h;
        if (perp2 > r_m * r_m * (1.0 + 1e-6))
            return;
        h = sqrt(fmax(r_m * r_m - perp2, 0.0) / len2);
        lo = fmax(lo, floor((u - h) * (double)t->pieces) - 1.0);
        hi = fmin(hi, ceil((u + h) * (double)t->pieces) + 1.0);
        if (lo > hi)
            return;
    }
    k0 = (uint32_t)lo;
    k1 = (uint32_t)hi;
    for (k = k0; k <= k1; k++) {
        uint8_t *f = &m->flags[t->first + k];
        double x, y;
        if (*f & F_SUPPORTED)
            continue;
        sample_xy(m, s, k, &x, &y);
        if ((x - px) * (x - px) + (y - py) * (y - py) <= r_m * r_m)
            *f |= F_SUPPORTED;
    }
}

static int mark_support(topo_map *m, const double *xy, uint64_t point_count)
{
    const gtscore_index *ix = &m->index;
    uint64_t *stamp, p;
    if (ix->seg_count == 0)
        return 0;
    stamp = calloc(ix->seg_count, sizeof *stamp); /* the last point + 1 that met it */
    if (!stamp)
        return -1;
    for (p = 0; p < point_count; p++) {
        double px = xy[2u * p], py = xy[2u * p + 1u];
        uint32_t box[4], x, y, k;
        if (!gtscore_index_box(ix, px, py, GTTOPO_COVER_M, box))
            continue;
        for (y = box[1]; y <= box[3]; y++)
            for (x = box[0]; x <= box[2]; x++) {
                size_t c = (size_t)y * ix->width + x;
                for (k = ix->cell_start[c]; k < ix->cell_start[c + 1u]; k++) {
                    uint32_t s = ix->cell_seg[k];
                    if (stamp[s] == p + 1u)
                        continue;
                    stamp[s] = p + 1u;
                    support_segment(m, s, px, py, GTTOPO_COVER_M);
                }
            }
    }
    free(stamp);
    return 0;
}

/* A run that closes: counted by its length. */
static void count_unsupported(double run_m, gttopo_score *out)
{
    if (run_m > GTTOPO_RUN_M + RUN_EPS_M)
        out->unsupported_20++;
    if (run_m > GTTOPO_SHORT_RUN_M + RUN_EPS_M)
        out->unsupported_10++;
}

/* Runs of unsupported samples along each polyline, round a closed one. */
static void unsupported_runs(const topo_map *m, const polyc_polyline *lines, uint32_t count,
                             gttopo_score *out)
{
    uint32_t l, s, k;
    for (l = 0; l < count; l++) {
        int closed = lines[l].closed && lines[l].point_count > 2u, in_first = 1;
        double run = 0.0, first_run = 0.0;
        uint32_t first = m->line_first[l], end = m->line_first[l + 1u];
        if (first == end)
            continue;
        for (s = first; s < end; s++) {
            const topo_seg *t = &m->segs[s];
            for (k = 0; k < t->samples; k++) {
                if (m->flags[t->first + k] & F_SUPPORTED) {
                    if (in_first && closed)
                        first_run = run; /* may join the last run */
                    else
                        count_unsupported(run, out);
                    in_first = 0;
                    run = 0.0;
                } else if (k < t->pieces) {
                    run += t->spacing_m;
                }
            }
        }
        if (in_first)            /* no sample supported: one run */
            count_unsupported(run, out);
        else
            count_unsupported(run + first_run, out);
    }
}

/* ---- double cover --------------------------------------------------------- */

typedef struct cover_pick {
    const topo_map *m;
    uint32_t s;
} cover_pick;

/* Any segment but s and its neighbours. */
static int cover_accepts(const void *ctx, uint32_t o)
{
    const cover_pick *p = ctx;
    const topo_seg *t = &p->m->segs[p->s];
    return o != p->s && o != t->prev && o != t->next;
}

/* Is a segment other than s and its neighbours within reach of (x, y)? */
static int covered(const topo_map *m, uint32_t s, double x, double y)
{
    cover_pick p = {m, s};
    return gtscore_index_any_near(&m->index, x, y, GTTOPO_COVER_M, cover_accepts, &p);
}

static void double_cover(const topo_map *m, gttopo_score *out)
{
    uint32_t s, k;
    for (s = 0; s < m->index.seg_count; s++) {
        const topo_seg *t = &m->segs[s];
        uint32_t run = 0;
        /* a run is at most the segment long: shorter ones cannot count */
        if (t->length_m <= GTTOPO_RUN_M + RUN_EPS_M)
            continue;
        for (k = 0; k <= t->pieces; k++) { /* k == pieces closes the last run */
            double x, y;
            if (k < t->pieces) {
                sample_xy(m, s, k, &x, &y);
                if (covered(m, s, x, y)) {
                    run++;
                    continue;
                }
            }
            if ((double)run * t->spacing_m > GTTOPO_RUN_M + RUN_EPS_M)
                out->double_cover_m += (double)run * t->spacing_m;
            run = 0;
        }
    }
}

/* ---- crossings ------------------------------------------------------------ */

static double orient(const double *a, const double *b, const double *p)
{
    return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
}

static int far_from(const double *p, const double *q)
{
    double dx = p[0] - q[0], dy = p[1] - q[1];
    return dx * dx + dy * dy >= GTTOPO_CROSS_END_M * GTTOPO_CROSS_END_M;
}

/* Do segments g and h cross properly, away from their ends? *at gets the
 * crossing. */
static int proper_crossing(const double *g, const double *h, double at[2])
{
    double d1 = orient(g, g + 2, h), d2 = orient(g, g + 2, h + 2);
    double d3 = orient(h, h + 2, g), d4 = orient(h, h + 2, g + 2), u;
    if (!((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) ||
        !((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0)))
        return 0;
    u = d3 / (d3 - d4);
    at[0] = g[0] + (g[2] - g[0]) * u;
    at[1] = g[1] + (g[3] - g[1]) * u;
    return far_from(at, g) && far_from(at, g + 2) && far_from(at, h) && far_from(at, h + 2);
}

/* The cell holding (x, y), clamped to the grid. */
static size_t cell_of(const gtscore_index *ix, double x, double y)
{
    double fx = floor((x - ix->origin_x_m) / ix->cell_m);
    double fy = floor((y - ix->origin_y_m) / ix->cell_m);
    size_t cx = fx < 0.0 ? 0u : fx >= (double)ix->width ? ix->width - 1u : (size_t)fx;
    size_t cy = fy < 0.0 ? 0u : fy >= (double)ix->height ? ix->height - 1u : (size_t)fy;
    return cy * ix->width + cx;
}

/* Every pair listed together in a cell, counted in the cell that holds its
 * crossing: each crossing pair once. */
static void crossings(const topo_map *m, gttopo_score *out)
{
    const gtscore_index *ix = &m->index;
    size_t c, n = (size_t)ix->width * ix->height;
    uint32_t i, j;
    for (c = 0; c < n; c++)
        for (i = ix->cell_start[c]; i < ix->cell_start[c + 1u]; i++) {
            uint32_t a = ix->cell_seg[i];
            for (j = i + 1u; j < ix->cell_start[c + 1u]; j++) {
                uint32_t b = ix->cell_seg[j];
                double at[2];
                if (m->segs[a].prev == b || m->segs[a].next == b)
                    continue;
                if (proper_crossing(&ix->seg_m[4u * a], &ix->seg_m[4u * b], at) &&
                    cell_of(ix, at[0], at[1]) == c)
                    out->crossings++;
            }
        }
}

/* ---- loose ends ----------------------------------------------------------- */

/* The distance from (x, y) to the map's segments outside [skip_lo,
 * skip_hi], exact up to GTTOPO_LOOSE_MAX_M (beyond: HUGE_VAL or more). */
static double distance_outside(const topo_map *m, double x, double y, uint32_t skip_lo,
                               uint32_t skip_hi)
{
    const gtscore_index *ix = &m->index;
    double best2 = HUGE_VAL;
    uint32_t box[4], cx, cy, k;
    if (!gtscore_index_box(ix, x, y, GTTOPO_LOOSE_MAX_M, box))
        return HUGE_VAL;
    for (cy = box[1]; cy <= box[3]; cy++)
        for (cx = box[0]; cx <= box[2]; cx++) {
            size_t c = (size_t)cy * ix->width + cx;
            for (k = ix->cell_start[c]; k < ix->cell_start[c + 1u]; k++) {
                uint32_t o = ix->cell_seg[k];
                double d2;
                if (o >= skip_lo && o <= skip_hi)
                    continue;
                d2 = gtscore_segment_distance2(&ix->seg_m[4u * o], x, y);
                if (d2 < best2)
                    best2 = d2;
            }
        }
    return sqrt(best2);
}

static int is_loose(double d_m)
{
    return d_m >= GTTOPO_LOOSE_MIN_M && d_m <= GTTOPO_LOOSE_MAX_M;
}

static void loose_ends(const topo_map *m, const polyc_polyline *lines, uint32_t count,
                       gttopo_score *out)
{
    uint32_t l, lo, hi;
    for (l = 0; l < count; l++) {
        const polyc_polyline *pl = &lines[l];
        uint32_t first = m->line_first[l], last = m->line_first[l + 1u] - 1u;
        double path;
        if (pl->point_count < 2u || (pl->closed && pl->point_count > 2u))
            continue;
        /* the first point: its own segments reached within 15 cm are skipped */
        for (hi = first, path = m->segs[first].length_m;
             hi < last && path <= GTTOPO_LOOSE_MAX_M + RUN_EPS_M; path += m->segs[++hi].length_m)
            ;
        out->loose_ends += (uint32_t)is_loose(distance_outside(
            m, (double)pl->xy_m[0], (double)pl->xy_m[1], first, hi));
        /* the last point, walking back */
        for (lo = last, path = m->segs[last].length_m;
             lo > first && path <= GTTOPO_LOOSE_MAX_M + RUN_EPS_M; path += m->segs[--lo].length_m)
            ;
        out->loose_ends += (uint32_t)is_loose(
            distance_outside(m, (double)pl->xy_m[2u * (pl->point_count - 1u)],
                             (double)pl->xy_m[2u * (pl->point_count - 1u) + 1u], lo, last));
    }
}

/* ---- the scores ----------------------------------------------------------- */

int gttopo_score_map(const polyc_polyline *lines, uint32_t count, const double *points_xy_m,
                     uint64_t point_count, gttopo_score *out)
{
    topo_map m;
    uint32_t s;
    if (!out)
        return -1;
    memset(out, 0, sizeof *out);
    if ((!lines && count) || (!points_xy_m && point_count))
        return -1;
    if (topo_build(&m, lines, count) != 0) {
        topo_free(&m);
        return -1;
    }
    for (s = 0; s < m.index.seg_count; s++)
        out->map_length_m += m.segs[s].length_m;
    if (mark_support(&m, points_xy_m, point_count) != 0) {
        topo_free(&m);
        return -1;
    }
    unsupported_runs(&m, lines, count, out);
    double_cover(&m, out);
    crossings(&m, out);
    loose_ends(&m, lines, count, out);
    topo_free(&m);
    return 0;
}

int gttopo_scan_points(const polyc_scan *scans, uint32_t scan_count, double **xy_m,
                       uint64_t *count)
{
    return gtscore_scan_endpoints(scans, scan_count, xy_m, NULL, count);
}
