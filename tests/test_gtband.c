/* test_gtband.c - band15 and end5 / end10 / end20 (tools/eval/gtband.h) on
 * hand-made maps whose values are known exactly. Data points lie at odd
 * half centimetres (0.005 + 0.02 i) along the lines, each seen from a
 * sensor 1 m to one side. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gtband.h"
#include "gtscore.h"
#include "near.h"

#define MAX_POINTS 512

typedef struct data {
    double xy[2 * MAX_POINTS], from[2 * MAX_POINTS];
    uint64_t n;
} data;

/* Points (x0 + t dx, y0 + t dy), t = 0.005 + 0.02 i for i in [0, last],
 * each seen from (its x, its y + sensor_dy). */
static void add_points(data *d, double x0, double y0, double dx, double dy, int last,
                       double sensor_dy)
{
    int i;
    for (i = 0; i <= last; i++) {
        double t = 0.005 + 0.02 * i;
        assert_true(d->n < MAX_POINTS);
        d->xy[2u * d->n] = x0 + t * dx;
        d->xy[2u * d->n + 1u] = y0 + t * dy;
        d->from[2u * d->n] = d->xy[2u * d->n];
        d->from[2u * d->n + 1u] = d->xy[2u * d->n + 1u] + sensor_dy;
        d->n++;
    }
}

/* Two parallel 1 m lines 8 cm apart, the cases' map. */
static const float LOWER[] = {0.0f, 0.0f, 1.0f, 0.0f};
static const float UPPER[] = {0.0f, 0.08f, 1.0f, 0.08f};

static gtband_score score(const polyc_polyline *lines, uint32_t count, const data *d)
{
    gtband_score sc;
    assert_int_equal(gtband_score_map(lines, count, d->xy, d->from, d->n, &sc), 0);
    return sc;
}

/* The score of two-line `lines` against two runs of 50 points: along
 * y = 0 from x = 0 (1 m, seen from below), and from (x_b, y_b) along
 * (dx_b, dy_b), seen from sensor_dy_b above or below. */
static gtband_score score_two_runs(const polyc_polyline *lines, double x_b, double y_b,
                                   double dx_b, double dy_b, double sensor_dy_b)
{
    static data d;
    memset(&d, 0, sizeof d);
    add_points(&d, 0.0, 0.0, 1.0, 0.0, 49, -1.0);
    add_points(&d, x_b, y_b, dx_b, dy_b, 49, sensor_dy_b);
    return score(lines, 2, &d);
}

/* Two parallel 1 m lines 8 cm apart, both seen from below (y = -1): each
 * one's 100 samples (0 .. 99 cm) lie 8 cm from the other, so each is one
 * band-doubled run of 100 x 1 cm: 2.00 m. Seen from opposite sides (the
 * upper line from y = +1, a thin wall): 0. */
static void test_parallel_same_side(void **state)
{
    polyc_polyline lines[2] = {{LOWER, 2, 0}, {UPPER, 2, 0}};
    gtband_score sc;
    (void)state;
    sc = score_two_runs(lines, 0.0, 0.08, 1.0, 0.0, -1.0);
    assert_near(sc.map_length_m, 2.0, 1e-9);
    assert_int_equal(sc.sided_segments, 2);
    assert_near(sc.band_m, 2.0, 1e-9);

    sc = score_two_runs(lines, 0.0, 0.08, 1.0, 0.0, 1.0);
    assert_int_equal(sc.sided_segments, 2);
    assert_near(sc.band_m, 0.0, 0.0);

    /* drawn in opposite directions, seen from one side: the facing
     * normals agree however the segments run */
    {
        static const float b_back[] = {1.0f, 0.08f, 0.0f, 0.08f};
        lines[1].xy_m = b_back;
        sc = score_two_runs(lines, 0.0, 0.08, 1.0, 0.0, -1.0);
        assert_near(sc.band_m, 2.0, 1e-9);
    }
}

/* The runs reported by gtband_score_map_runs: how many, their summed
 * length and the last one's ends. */
typedef struct runs_seen {
    int n;
    double sum_m;
    double last[4];
} runs_seen;

static void see_run(void *user, const double run_xy_m[4], double length_m)
{
    runs_seen *r = user;
    r->n++;
    r->sum_m += length_m;
    memcpy(r->last, run_xy_m, sizeof r->last);
}

/* The two parallel lines 8 cm apart seen from below: two runs, one on each
 * line, 1 m each (a's 0 .. 1 m on y = 0, b's on y = 0.08), summing to
 * band15; seen from opposite sides, none. */
static void test_runs_reported(void **state)
{
    polyc_polyline lines[2] = {{LOWER, 2, 0}, {UPPER, 2, 0}};
    static data d;
    gtband_score sc;
    runs_seen r;
    (void)state;
    for (int side = 0; side < 2; side++) {
        memset(&d, 0, sizeof d);
        memset(&r, 0, sizeof r);
        add_points(&d, 0.0, 0.0, 1.0, 0.0, 49, -1.0);
        add_points(&d, 0.0, 0.08, 1.0, 0.0, 49, side ? 1.0 : -1.0);
        assert_int_equal(gtband_score_map_runs(lines, 2, d.xy, d.from, d.n, &sc, see_run, &r), 0);
        assert_int_equal(r.n, side ? 0 : 2);
        assert_near(r.sum_m, sc.band_m, 1e-9);
        if (!side) {
            assert_near(r.sum_m, 2.0, 1e-9);
            assert_near(r.last[1], 0.08, 1e-6); /* b's run, on y = 0.08 (float vertices) */
            assert_near(fabs(r.last[2] - r.last[0]), 1.0, 0.011);
        }
    }
}

/* The same lines, the upper one shifted by 0.5 m (0.5 .. 1.5 m): a's
 * samples lie within 15 cm of b from x >= 0.5 - sqrt(0.15^2 - 0.08^2) =
 * 0.3731 m (0.38 .. 0.99: 62 samples), b's up to x <= 1.1269 m (0.50 ..
 * 1.12: 63 samples): 1.25 m. */
static void test_parallel_overlap(void **state)
{
    static const float a[] = {0.0f, 0.0f, 1.0f, 0.0f};
    static const float b[] = {0.5f, 0.08f, 1.5f, 0.08f};
    polyc_polyline lines[2] = {{a, 2, 0}, {b, 2, 0}};
    gtband_score sc;
    (void)state;
    sc = score_two_runs(lines, 0.5, 0.08, 1.0, 0.0, -1.0);
    assert_near(sc.band_m, 1.25, 1e-9);
}

/* A 10 cm step: two parallel 15 cm pieces 10 cm apart, joined in one
 * polyline (0, 0.1) - (0.15, 0.1) - (0.15, 0) - (0.30, 0), and as two
 * separate pieces one above the other: every run is at most 15 cm, 0. */
static void test_step(void **state)
{
    static const float step[] = {0.0f, 0.1f, 0.15f, 0.1f, 0.15f, 0.0f, 0.30f, 0.0f};
    static const float a[] = {0.0f, 0.0f, 0.15f, 0.0f};
    static const float b[] = {0.0f, 0.1f, 0.15f, 0.1f};
    polyc_polyline lines[2] = {{step, 4, 0}, {NULL, 0, 0}};
    static data d;
    gtband_score sc;
    (void)state;
    memset(&d, 0, sizeof d);
    add_points(&d, 0.0, 0.1, 1.0, 0.0, 7, -1.0);
    add_points(&d, 0.15, 0.0, 1.0, 0.0, 7, -1.0);
    sc = score(lines, 1, &d);
    assert_int_equal(sc.sided_segments, 2);
    assert_near(sc.band_m, 0.0, 0.0);

    memset(&d, 0, sizeof d);
    add_points(&d, 0.0, 0.0, 1.0, 0.0, 7, -1.0);
    add_points(&d, 0.0, 0.1, 1.0, 0.0, 7, -1.0);
    lines[0].xy_m = a;
    lines[0].point_count = 2;
    lines[1].xy_m = b;
    lines[1].point_count = 2;
    sc = score(lines, 2, &d);
    assert_int_equal(sc.sided_segments, 2);
    assert_near(sc.band_m, 0.0, 0.0);
}

/* Not a band: lines at 30 degrees (5 cm apart at their start), lines 20 cm
 * apart, and a line no point belongs to (no side). */
static void test_not_bands(void **state)
{
    static const float a[] = {0.0f, 0.0f, 1.0f, 0.0f};
    static const float far_b[] = {0.0f, 0.2f, 1.0f, 0.2f};
    static const float near_b[] = {0.0f, 0.08f, 1.0f, 0.08f};
    float slant[4];
    polyc_polyline lines[2] = {{a, 2, 0}, {slant, 2, 0}};
    double c = cos(3.14159265358979323846 / 6.0), s = sin(3.14159265358979323846 / 6.0);
    static data d;
    gtband_score sc;
    (void)state;
    slant[0] = 0.0f;
    slant[1] = 0.05f;
    slant[2] = (float)c;
    slant[3] = (float)(0.05 + s);
    sc = score_two_runs(lines, 0.0, 0.05, c, s, -1.0);
    assert_int_equal(sc.sided_segments, 2);
    assert_near(sc.band_m, 0.0, 0.0);

    lines[1].xy_m = far_b;
    sc = score_two_runs(lines, 0.0, 0.2, 1.0, 0.0, -1.0);
    assert_int_equal(sc.sided_segments, 2);
    assert_near(sc.band_m, 0.0, 0.0);

    memset(&d, 0, sizeof d);
    add_points(&d, 0.0, 0.0, 1.0, 0.0, 49, -1.0);
    lines[1].xy_m = near_b;
    sc = score(lines, 2, &d);
    assert_int_equal(sc.sided_segments, 1);
    assert_near(sc.band_m, 0.0, 0.0);
    sc = score(lines, 2, &(data){{0}, {0}, 0});
    assert_int_equal(sc.sided_segments, 0);
    assert_near(sc.band_m, 0.0, 0.0);
    assert_near(sc.map_length_m, 2.0, 1e-9);
}

/* A point votes for its nearest segment only: points on the upper line,
 * 8 cm from the lower, give the lower no side. The side is the sign of
 * the votes' sum: 30 votes from below and 20 from above make it "below". */
static void test_votes(void **state)
{
    polyc_polyline lines[2] = {{LOWER, 2, 0}, {UPPER, 2, 0}};
    static data d;
    gtband_score sc;
    (void)state;
    memset(&d, 0, sizeof d);
    add_points(&d, 0.0, 0.08, 1.0, 0.0, 49, -1.0);
    sc = score(lines, 2, &d);
    assert_int_equal(sc.sided_segments, 1);
    assert_near(sc.band_m, 0.0, 0.0);

    add_points(&d, 0.0, 0.0, 1.0, 0.0, 29, -1.0);
    add_points(&d, 0.6, 0.0, 1.0, 0.0, 19, 1.0);
    sc = score(lines, 2, &d);
    assert_int_equal(sc.sided_segments, 2);
    assert_near(sc.band_m, 2.0, 1e-9);
}

/* end5 / end10 / end20 by hand: a 1 m line and points 3, 7, 15, 25 cm
 * from it (above its middle), 12 cm past its end and 1 m away. */
static void test_end_shares(void **state)
{
    static const float a[] = {0.0f, 0.0f, 1.0f, 0.0f};
    polyc_polyline line = {a, 2, 0};
    static const double xy[] = {0.5, 0.03, 0.5, 0.07, 0.5, -0.15, 0.5, 0.25, 1.12, 0.0, 2.0, 0.0};
    static const double from[] = {0.5, 1.0, 0.5, 1.0, 0.5, -1.0, 0.5, 1.0, 2.0, 0.0, 3.0, 0.0};
    gtband_score sc;
    (void)state;
    assert_int_equal(gtband_score_map(&line, 1, xy, from, 6, &sc), 0);
    assert_int_equal(sc.points, 6);
    assert_int_equal(sc.within_5, 1);
    assert_int_equal(sc.within_10, 2);
    assert_int_equal(sc.within_20, 4);
    assert_near(gtband_share(sc.within_20, sc.points), 4.0 / 6.0, 1e-12);
    assert_near(gtband_share(0, 0), 0.0, 0.0);
}

/* On scans: the endpoints and poses of gtband_scan_points, and the counts
 * agree with gtscore_endpoints_within at 5, 10 and 20 cm. */
static void test_scan_points(void **state)
{
    float ranges[21];
    polyc_scan scan;
    static const float a[] = {-2.0f, 0.0f, 3.0f, 0.0f};
    polyc_polyline line = {a, 2, 0};
    static const double extra[] = {0.0, 0.04, 0.08, 0.15, 0.3, 0.01, 0.12};
    double *xy = NULL, *from = NULL;
    uint64_t n = 0, within, total;
    gtscore_index map;
    gtband_score sc;
    uint32_t i;
    (void)state;
    memset(&scan, 0, sizeof scan);
    scan.pose_x_m = 0.5;
    scan.pose_y_m = -1.0;
    scan.pose_theta_rad = 3.14159265358979323846 / 2.0;
    scan.start_angle_rad = -0.5f;
    scan.angle_step_rad = 0.05f;
    scan.min_range_m = 0.1f;
    scan.max_range_m = 8.0f;
    scan.beam_count = 21;
    scan.range_m = ranges;
    for (i = 0; i < 21; i++) {
        double ang = -0.5 + 0.05 * i;
        ranges[i] = (float)(1.0 / cos(ang) + extra[i % 7u]);
    }
    ranges[3] = 9.0f; /* not reflected */
    assert_int_equal(gtband_scan_points(&scan, 1, &xy, &from, &n), 0);
    assert_int_equal(n, 20);
    for (i = 0; i < n; i++) {
        assert_near(from[2u * i], 0.5, 0.0);
        assert_near(from[2u * i + 1u], -1.0, 0.0);
    }
    assert_int_equal(gtband_score_map(&line, 1, xy, from, n, &sc), 0);
    gtscore_index_init(&map);
    assert_int_equal(gtscore_index_add_polylines(&map, &line, 1), 0);
    assert_int_equal(gtscore_index_build(&map, 0.1), 0);
    gtscore_endpoints_within(&map, &scan, 1, 0.05, &within, &total);
    assert_int_equal(total, sc.points);
    assert_int_equal(within, sc.within_5);
    gtscore_endpoints_within(&map, &scan, 1, 0.10, &within, &total);
    assert_int_equal(within, sc.within_10);
    gtscore_endpoints_within(&map, &scan, 1, 0.20, &within, &total);
    assert_int_equal(within, sc.within_20);
    assert_true(sc.within_5 < sc.within_10 && sc.within_10 < sc.within_20 &&
                sc.within_20 < sc.points);
    assert_int_equal(sc.sided_segments, 1);
    gtscore_index_free(&map);
    free(xy);
    free(from);
}

static void test_empty_and_bad(void **state)
{
    static const float a[] = {0.0f, 0.0f, 1.0f, 0.0f};
    polyc_polyline line = {a, 2, 0}, bad = {NULL, 2, 0};
    static const double xy[] = {0.5, 0.0};
    gtband_score sc;
    double *p = NULL, *q = NULL;
    uint64_t n = 7;
    (void)state;
    assert_int_equal(gtband_score_map(NULL, 0, NULL, NULL, 0, &sc), 0);
    assert_near(sc.map_length_m, 0.0, 0.0);
    assert_int_equal(gtband_score_map(NULL, 0, xy, xy, 1, &sc), 0);
    assert_int_equal(sc.points, 1);
    assert_int_equal(sc.within_20, 0);
    assert_int_equal(gtband_score_map(&line, 1, xy, NULL, 1, &sc), -1);
    assert_int_equal(gtband_score_map(&bad, 1, NULL, NULL, 0, &sc), -1);
    assert_int_equal(gtband_score_map(NULL, 1, NULL, NULL, 0, &sc), -1);
    assert_int_equal(gtband_score_map(&line, 1, NULL, NULL, 0, NULL), -1);
    assert_int_equal(gtband_scan_points(NULL, 0, &p, &q, &n), 0);
    assert_null(p);
    assert_null(q);
    assert_int_equal(n, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parallel_same_side),
        cmocka_unit_test(test_runs_reported),
        cmocka_unit_test(test_parallel_overlap),
        cmocka_unit_test(test_step),
        cmocka_unit_test(test_not_bands),
        cmocka_unit_test(test_votes),
        cmocka_unit_test(test_end_shares),
        cmocka_unit_test(test_scan_points),
        cmocka_unit_test(test_empty_and_bad),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
