/* gtband.c - bands of a polyline map and endpoints near it (definitions in
 * gtband.h).
 *
 * Takes a map and data points with the sensor positions that saw them;
 * gives end5 / end10 / end20 counts, each segment's side and band15. The
 * map goes into a gtscore_index; one pass over the points finds each
 * point's nearest segment within 20 cm (the counts, and the side votes of
 * those within 10 cm), then each sample of each sided segment looks for a
 * parallel, same-facing segment within 15 cm.
 */
#include "gtband.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gtscore.h"

#define MAP_CELL_M 0.10            /* the map's grid, as gttopo.c builds it */
#define FAR_M 0.20                 /* the farthest count: end20 */
#define RUN_EPS_M 1e-6             /* "longer than": to within 1 um */
#define NO_SEG UINT32_MAX

typedef struct band_seg {
    uint32_t prev, next;           /* neighbour segments, NO_SEG if none */
    uint32_t pieces;               /* samples k = 0 .. pieces - 1 at k / pieces */
    double length_m;
    double ux, uy;                 /* unit direction (0, 0 without length) */
    double fx, fy;                 /* facing normal: side x left normal */
    int64_t votes;                 /* sum of the side votes */
    int side;                      /* -1, 0 (none), +1 */
} band_seg;

/* Segment numbers, neighbours and sampling of every polyline, in the order
 * gtscore_index_add_polylines adds them. */
static int build_segments(const gtscore_index *ix, const polyc_polyline *lines, uint32_t count,
                          band_seg *segs)
{
    uint32_t l, j, s = 0;
    for (l = 0; l < count; l++) {
        uint32_t pc = lines[l].point_count, n, first = s;
        int closed = lines[l].closed && pc > 2u;
        if (pc == 0)
            continue;
        n = pc == 1u ? 1u : closed ? pc : pc - 1u;
        if (first + n > ix->seg_count)
            return -1;
        for (j = 0; j < n; j++) {
            const double *g = &ix->seg_m[4u * (first + j)];
            band_seg *t = &segs[first + j];
            double len = hypot(g[2] - g[0], g[3] - g[1]);
            double pieces = ceil(len / GTSCORE_SAMPLE_M - 1e-9);
            if (pieces > 1e9)
                return -1;
            memset(t, 0, sizeof *t);
            t->pieces = pieces < 1.0 ? 1u : (uint32_t)pieces;
            t->length_m = len;
            if (len > 0.0) {
                t->ux = (g[2] - g[0]) / len;
                t->uy = (g[3] - g[1]) / len;
            }
            t->prev = j > 0 ? first + j - 1u : closed ? first + n - 1u : NO_SEG;
            t->next = j + 1u < n ? first + j + 1u : closed ? first : NO_SEG;
        }
        s = first + n;
    }
    return s == ix->seg_count ? 0 : -1;
}

/* The nearest segment to (x, y) within FAR_M (ties: the lowest number) and
 * its squared distance; NO_SEG if none. */
static uint32_t nearest(const gtscore_index *ix, double x, double y, double *d2_out)
{
    uint32_t box[4], cx, cy, k, best = NO_SEG;
    double best2 = FAR_M * FAR_M;
    if (!gtscore_index_box(ix, x, y, FAR_M, box))
        return NO_SEG;
    for (cy = box[1]; cy <= box[3]; cy++)
        for (cx = box[0]; cx <= box[2]; cx++) {
            size_t c = (size_t)cy * ix->width + cx;
            for (k = ix->cell_start[c]; k < ix->cell_start[c + 1u]; k++) {
                uint32_t o = ix->cell_seg[k];
                double d2 = gtscore_segment_distance2(&ix->seg_m[4u * o], x, y);
                if (d2 < best2 || (d2 == best2 && o < best)) {
                    best2 = d2;
                    best = o;
                }
            }
        }
    *d2_out = best2;
    return best;
}

/* Counts the points near the map and lets those within GTBAND_SIDE_M vote
 * for their nearest segment's side. */
static void vote(const gtscore_index *ix, band_seg *segs, const double *xy, const double *from,
                 uint64_t point_count, gtband_score *out)
{
    uint64_t p;
    out->points = point_count;
    for (p = 0; p < point_count; p++) {
        double x = xy[2u * p], y = xy[2u * p + 1u], d2 = 0.0;
        uint32_t s = nearest(ix, x, y, &d2);
        const double *g;
        double dot;
        if (s == NO_SEG)
            continue;
        out->within_20++;
        out->within_10 += d2 <= 0.10 * 0.10;
        out->within_5 += d2 <= 0.05 * 0.05;
        if (d2 > GTBAND_SIDE_M * GTBAND_SIDE_M || !from)
            continue;
        g = &ix->seg_m[4u * s];
        /* (sensor - start) . left normal (-uy, ux) */
        dot = -(from[2u * p] - g[0]) * segs[s].uy + (from[2u * p + 1u] - g[1]) * segs[s].ux;
        segs[s].votes += dot > 0.0 ? 1 : dot < 0.0 ? -1 : 0;
    }
}

/* The segments that may band-double segment s: not s or its neighbours,
 * with a side, near parallel (sine of the angle <= sin_max) and facing the
 * same way. */
typedef struct band_pick {
    const band_seg *segs;
    uint32_t s;
    double sin_max;
} band_pick;

static int band_accepts(const void *ctx, uint32_t o)
{
    const band_pick *p = ctx;
    const band_seg *t = &p->segs[p->s], *u = &p->segs[o];
    if (o == p->s || o == t->prev || o == t->next || u->side == 0)
        return 0;
    return !(fabs(t->ux * u->uy - t->uy * u->ux) > p->sin_max ||
             t->fx * u->fx + t->fy * u->fy <= 0.0);
}

/* Is sample (x, y) of segment s band-doubled? */
static int doubled(const gtscore_index *ix, const band_seg *segs, uint32_t s, double sin_max,
                   double x, double y)
{
    band_pick p = {segs, s, sin_max};
    return gtscore_index_any_near(ix, x, y, GTBAND_REACH_M, band_accepts, &p);
}

static void band(const gtscore_index *ix, const band_seg *segs, gtband_score *out,
                 gtband_run_fn report, void *user)
{
    /* parallel within the angle: |sin| of the angle between them (to 1e-12) */
    double sin_max = sin(GTBAND_ANGLE_DEG * 3.14159265358979323846 / 180.0) + 1e-12;
    uint32_t s, k;
    for (s = 0; s < ix->seg_count; s++) {
        const band_seg *t = &segs[s];
        const double *g = &ix->seg_m[4u * s];
        double spacing = t->length_m / (double)t->pieces;
        uint32_t run = 0;
        /* a run is at most the segment long: shorter ones cannot count */
        if (t->side == 0 || t->length_m <= GTBAND_RUN_M + RUN_EPS_M)
            continue;
        for (k = 0; k <= t->pieces; k++) { /* k == pieces closes the last run */
            if (k < t->pieces) {
                double u = (double)k / (double)t->pieces;
                if (doubled(ix, segs, s, sin_max, g[0] + (g[2] - g[0]) * u,
                            g[1] + (g[3] - g[1]) * u)) {
                    run++;
                    continue;
                }
            }
            if ((double)run * spacing > GTBAND_RUN_M + RUN_EPS_M) {
                out->band_m += (double)run * spacing;
                if (report) {
                    double u0 = (double)(k - run) / (double)t->pieces;
                    double u1 = (double)k / (double)t->pieces;
                    const double xy[4] = {g[0] + (g[2] - g[0]) * u0, g[1] + (g[3] - g[1]) * u0,
                                          g[0] + (g[2] - g[0]) * u1, g[1] + (g[3] - g[1]) * u1};
                    report(user, xy, (double)run * spacing);
                }
            }
            run = 0;
        }
    }
}

int gtband_score_map(const polyc_polyline *lines, uint32_t count, const double *points_xy_m,
                     const double *sensors_xy_m, uint64_t point_count, gtband_score *out)
{
    return gtband_score_map_runs(lines, count, points_xy_m, sensors_xy_m, point_count, out, NULL,
                                 NULL);
}

int gtband_score_map_runs(const polyc_polyline *lines, uint32_t count, const double *points_xy_m,
                          const double *sensors_xy_m, uint64_t point_count, gtband_score *out,
                          gtband_run_fn run, void *user)
{
    gtscore_index ix;
    band_seg *segs = NULL;
    uint32_t l, s;
    int rc = -1;
    if (!out)
        return -1;
    memset(out, 0, sizeof *out);
    if ((!lines && count) || (point_count && (!points_xy_m || !sensors_xy_m)))
        return -1;
    for (l = 0; l < count; l++)
        if (lines[l].point_count && !lines[l].xy_m)
            return -1;
    gtscore_index_init(&ix);
    if (gtscore_index_add_polylines(&ix, lines, count) != 0 ||
        gtscore_index_build(&ix, MAP_CELL_M) != 0)
        goto done;
    out->points = point_count;
    if (ix.seg_count == 0) {
        rc = 0;
        goto done;
    }
    segs = malloc((size_t)ix.seg_count * sizeof *segs);
    if (!segs || build_segments(&ix, lines, count, segs) != 0)
        goto done;
    for (s = 0; s < ix.seg_count; s++)
        out->map_length_m += segs[s].length_m;
    vote(&ix, segs, points_xy_m, sensors_xy_m, point_count, out);
    for (s = 0; s < ix.seg_count; s++) {
        band_seg *t = &segs[s];
        t->side = t->length_m > 0.0 && t->votes != 0 ? (t->votes > 0 ? 1 : -1) : 0;
        t->fx = -t->uy * (double)t->side;
        t->fy = t->ux * (double)t->side;
        out->sided_segments += t->side != 0;
    }
    band(&ix, segs, out, run, user);
    rc = 0;
done:
    free(segs);
    gtscore_index_free(&ix);
    return rc;
}

int gtband_scan_points(const polyc_scan *scans, uint32_t scan_count, double **xy_m,
                       double **sensors_xy_m, uint64_t *count)
{
    if (!sensors_xy_m)
        return -1;
    return gtscore_scan_endpoints(scans, scan_count, xy_m, sensors_xy_m, count);
}

double gtband_share(uint64_t within, uint64_t points)
{
    return points ? (double)within / (double)points : 0.0;
}
