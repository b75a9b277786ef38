/* test_gttopo.c - the topology figures (tools/eval/gttopo.h) and the core
 * precision (tools/eval/gtscore.h) on hand-made maps whose values are known
 * exactly. Points lie at odd half centimetres (0.005 + 0.02 i) so that no
 * 1 cm map sample is exactly 5 cm from one. */
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
#include "near.h"

static void score(const polyc_polyline *lines, uint32_t count, const double *xy, uint64_t n,
                  gttopo_score *sc)
{
    assert_int_equal(gttopo_score_map(lines, count, xy, n, sc), 0);
}

/* Appends points every 2 cm, (x0, y0) + (0.005 + 0.02 i) (dx, dy) for i in
 * [i0, i1], to xy (room for them is the caller's). */
static uint64_t add_points(double *xy, uint64_t n, double x0, double y0, double dx, double dy,
                           int i0, int i1)
{
    int i;
    for (i = i0; i <= i1; i++) {
        double t = 0.005 + 0.02 * i;
        xy[2u * n] = x0 + t * dx;
        xy[2u * n + 1u] = y0 + t * dy;
        n++;
    }
    return n;
}

/* Two parallel 1 m polylines 3 cm apart: each one's 100 samples (0 .. 99
 * cm; the last point stands for no length) lie 3 cm from the other, so
 * each is one doubly covered run of 100 x 1 cm: 2.00 m of the 2 m map.
 * With no data points every polyline is one unsupported run of 1 m. */
static void test_parallel_lines(void **state)
{
    static const float a[] = {0.0f, 0.0f, 1.0f, 0.0f};
    static const float b[] = {0.0f, 0.03f, 1.0f, 0.03f};
    polyc_polyline lines[2] = {{a, 2, 0}, {b, 2, 0}};
    gttopo_score sc;
    (void)state;
    score(lines, 2, NULL, 0, &sc);
    assert_near(sc.map_length_m, 2.0, 1e-9);
    assert_near(sc.double_cover_m, 2.0, 1e-9);
    assert_int_equal(sc.crossings, 0);
    assert_int_equal(sc.unsupported_20, 2);
    assert_int_equal(sc.unsupported_10, 2);
}

/* 1 m segments 3 cm apart that overlap by 15 cm: a (0 .. 1 m) has its
 * samples within 4 cm before b's start (0.85 m) covered, b those within
 * 4 cm past a's end. In float coordinates the ones at exactly 4 cm (a's
 * 0.81 m, b's 1.04 m) lie 5.000002 cm away: a's 0.82 .. 0.99 m (18 x 1 cm)
 * and b's 0.85 .. 1.03 m (19) are covered; exactly, 19 and 20 would be.
 * Either way no run is over 20 cm: 0. Overlapping by 31.25 cm (b from
 * 0.6875 m), a's samples 0.65 .. 0.99 m (35) and b's 0.6875 .. 1.0375 m
 * (36) are covered: 0.71 m. */
static void test_short_overlap(void **state)
{
    static const float a[] = {0.0f, 0.0f, 1.0f, 0.0f};
    static const float b[] = {0.85f, 0.03f, 1.85f, 0.03f};
    static const float c[] = {0.6875f, 0.03f, 1.6875f, 0.03f};
    polyc_polyline lines[2] = {{a, 2, 0}, {b, 2, 0}};
    gttopo_score sc;
    (void)state;
    score(lines, 2, NULL, 0, &sc);
    assert_near(sc.double_cover_m, 0.0, 0.0);
    lines[1].xy_m = c;
    score(lines, 2, NULL, 0, &sc);
    assert_near(sc.double_cover_m, 0.71, 1e-9);
}

/* An L corner in one polyline: the two legs share a vertex, so neither
 * covers the other (0), and the same corner as two polylines meeting there
 * covers 5 cm of each leg (0: under 20 cm). Only a sharp corner shows the
 * rule: a V of 1 m legs whose ends are 6 cm apart is 0 in one polyline, but
 * as two polylines the leg along y = 0 is covered up to x = 0.05 /
 * sin(tip angle) = 0.8348 m (84 samples, 0.84 m) and the other leg from
 * 1/6 of the way from its end (samples 17 .. 100 of its 101, each 1/101 of
 * its length). A hairpin, 1 m out and 1 m back 3 cm away, is 0 -> 2 -> 3
 * -> 1 in vertex order: segments 0 and 2 are not neighbours, and each of
 * their 100 samples is covered: 2.00 m. */
static void test_corner_and_hairpin(void **state)
{
    static const float corner[] = {0.0f, 1.0f, 0.0f, 0.0f, 1.0f, 0.0f};
    static const float leg[] = {0.0f, 0.0f, 1.0f, 0.0f};
    static const float vee[] = {1.0f, 0.06f, 0.0f, 0.0f, 1.0f, 0.0f};
    static const float hairpin[] = {0.0f, 0.0f, 1.0f, 0.0f, 1.0f, 0.03f, 0.0f, 0.03f};
    polyc_polyline lines[2] = {{corner, 3, 0}, {leg, 2, 0}};
    double slant = sqrt(1.0 + (double)0.06f * (double)0.06f);
    gttopo_score sc;
    (void)state;
    score(lines, 1, NULL, 0, &sc);
    assert_near(sc.map_length_m, 2.0, 1e-9);
    assert_near(sc.double_cover_m, 0.0, 0.0);
    assert_int_equal(sc.crossings, 0);
    assert_int_equal(sc.loose_ends, 0);
    lines[0].point_count = 2; /* (0, 1) - (0, 0), and (0, 0) - (1, 0) */
    score(lines, 2, NULL, 0, &sc);
    assert_near(sc.double_cover_m, 0.0, 0.0);
    assert_int_equal(sc.loose_ends, 0);
    lines[0].xy_m = vee;
    lines[0].point_count = 3;
    score(lines, 1, NULL, 0, &sc);
    assert_near(sc.double_cover_m, 0.0, 0.0);
    lines[0].point_count = 2; /* (1, 0.06) - (0, 0), and (0, 0) - (1, 0) */
    score(lines, 2, NULL, 0, &sc);
    assert_near(sc.double_cover_m, 0.84 + 84.0 * slant / 101.0, 1e-9);
    lines[0].xy_m = hairpin;
    lines[0].point_count = 4;
    score(lines, 1, NULL, 0, &sc);
    assert_near(sc.double_cover_m, 2.0, 1e-9);
}

/* Crossings: an X of two polylines (1); a bow-tie polyline whose first and
 * third segments cross (1; its neighbours only meet at vertices); a grid of
 * 5 horizontal and 5 vertical 1 m polylines, every pair listed together in
 * several cells of the index and counted once (25); a stem through a bar
 * 0.5 cm before its end (0: within 1 cm of an end); a T touching (0). */
static void test_crossings(void **state)
{
    static const float x1[] = {-0.5f, -0.5f, 0.5f, 0.5f};
    static const float x2[] = {-0.5f, 0.5f, 0.5f, -0.5f};
    static const float bowtie[] = {0.0f, 0.0f, 1.0f, 1.0f, 1.0f, 0.0f, 0.0f, 1.0f};
    static const float bar[] = {-1.0f, 0.0f, 1.0f, 0.0f};
    static const float through[] = {0.0f, -1.0f, 0.0f, 0.005f};
    static const float touching[] = {0.0f, -1.0f, 0.0f, 0.0f};
    float comb[10][4];
    polyc_polyline lines[10] = {{x1, 2, 0}, {x2, 2, 0}};
    gttopo_score sc;
    int k;
    (void)state;
    score(lines, 2, NULL, 0, &sc);
    assert_int_equal(sc.crossings, 1);
    lines[0].xy_m = bowtie;
    lines[0].point_count = 4;
    score(lines, 1, NULL, 0, &sc);
    assert_int_equal(sc.crossings, 1);
    lines[0].closed = 1; /* the closing segment (0, 1) - (0, 0) crosses nothing */
    score(lines, 1, NULL, 0, &sc);
    assert_int_equal(sc.crossings, 1);
    for (k = 0; k < 5; k++) {
        float v = 0.1f + 0.2f * (float)k;
        comb[k][0] = 0.0f;
        comb[k][1] = v;
        comb[k][2] = 1.0f;
        comb[k][3] = v;
        comb[5 + k][0] = v;
        comb[5 + k][1] = 0.0f;
        comb[5 + k][2] = v;
        comb[5 + k][3] = 1.0f;
    }
    for (k = 0; k < 10; k++) {
        lines[k].xy_m = comb[k];
        lines[k].point_count = 2;
        lines[k].closed = 0;
    }
    score(lines, 10, NULL, 0, &sc);
    assert_int_equal(sc.crossings, 25);
    lines[0].xy_m = bar;
    lines[1].xy_m = through;
    score(lines, 2, NULL, 0, &sc);
    assert_int_equal(sc.crossings, 0);
    lines[1].xy_m = touching;
    score(lines, 2, NULL, 0, &sc);
    assert_int_equal(sc.crossings, 0);
}

/* Loose ends: a T whose stem ends 0.5 cm from the bar (not loose: under
 * 3 cm) and one whose stem ends 8 cm from it (1); the stem's far end and
 * the bar's ends are metres from anything. A 5 cm end segment is not a near
 * miss of its own polyline (0); a polyline round three sides of a 1 m
 * square and 92 cm down the fourth ends 8 cm from its start, and its start
 * 8 cm from its last segment (2). */
static void test_loose_ends(void **state)
{
    static const float bar[] = {-0.5f, 0.0f, 0.5f, 0.0f};
    static const float near_stem[] = {0.0f, 0.005f, 0.0f, 1.0f};
    static const float gap_stem[] = {0.0f, 0.08f, 0.0f, 1.0f};
    static const float short_end[] = {0.0f, 0.0f, 1.0f, 0.0f, 1.05f, 0.0f};
    static const float nearly_closed[] = {0.0f, 0.0f, 1.0f, 0.0f, 1.0f, 1.0f,
                                          0.0f, 1.0f, 0.0f, 0.08f};
    polyc_polyline lines[2] = {{bar, 2, 0}, {near_stem, 2, 0}};
    gttopo_score sc;
    (void)state;
    score(lines, 2, NULL, 0, &sc);
    assert_int_equal(sc.crossings, 0);
    assert_int_equal(sc.loose_ends, 0);
    lines[1].xy_m = gap_stem;
    score(lines, 2, NULL, 0, &sc);
    assert_int_equal(sc.crossings, 0);
    assert_int_equal(sc.loose_ends, 1);
    lines[0].xy_m = short_end;
    lines[0].point_count = 3;
    score(lines, 1, NULL, 0, &sc);
    assert_int_equal(sc.loose_ends, 0);
    lines[0].xy_m = nearly_closed;
    lines[0].point_count = 5;
    score(lines, 1, NULL, 0, &sc);
    assert_int_equal(sc.loose_ends, 2);
    lines[0].closed = 1; /* closed: no ends */
    score(lines, 1, NULL, 0, &sc);
    assert_int_equal(sc.loose_ends, 0);
}

/* A 2 m segment with points every 2 cm along it: every sample has one
 * within 1.5 cm (0 runs). Without the points from 0.805 to 1.165 m (a 40 cm
 * gap between 0.785 and 1.185 m), the samples 0.84 .. 1.13 m have none
 * within 5 cm: one run of 30 x 1 cm, over 20 cm and over 10 cm. */
static void test_unsupported_gap(void **state)
{
    static const float seg[] = {0.0f, 0.0f, 2.0f, 0.0f};
    polyc_polyline line = {seg, 2, 0};
    double xy[2 * 100];
    gttopo_score sc;
    uint64_t n;
    (void)state;
    n = add_points(xy, 0, 0.0, 0.0, 1.0, 0.0, 0, 99);
    score(&line, 1, xy, n, &sc);
    assert_int_equal(sc.unsupported_20, 0);
    assert_int_equal(sc.unsupported_10, 0);
    n = add_points(xy, 0, 0.0, 0.0, 1.0, 0.0, 0, 39);   /* .. 0.785 */
    n = add_points(xy, n, 0.0, 0.0, 1.0, 0.0, 59, 99);  /* 1.185 .. */
    score(&line, 1, xy, n, &sc);
    assert_int_equal(sc.unsupported_20, 1);
    assert_int_equal(sc.unsupported_10, 1);
}

/* Runs continue across vertices. An L (0, 0) - (1, 0) - (1, 1) with points
 * up to x = 0.825 on its first leg and from y = 0.185 on its second: 12
 * unsupported samples before the corner (0.88 .. 0.99) and 14 from it (0 ..
 * 0.13 up the second leg): one run of 26 cm (two of 12 and 14 cm if runs
 * stopped at vertices). The closed 1 m square, its points missing within
 * 18 cm of its first vertex along both sides: 13 samples at the end of its
 * last side and 14 from its first vertex, one run of 27 cm round it. */
static void test_unsupported_across_vertices(void **state)
{
    static const float ell[] = {0.0f, 0.0f, 1.0f, 0.0f, 1.0f, 1.0f};
    static const float square[] = {0.0f, 0.0f, 1.0f, 0.0f, 1.0f, 1.0f, 0.0f, 1.0f};
    polyc_polyline line = {ell, 3, 0};
    double xy[2 * 200];
    gttopo_score sc;
    uint64_t n;
    (void)state;
    n = add_points(xy, 0, 0.0, 0.0, 1.0, 0.0, 0, 41);
    n = add_points(xy, n, 1.0, 0.0, 0.0, 1.0, 9, 49);
    score(&line, 1, xy, n, &sc);
    assert_int_equal(sc.unsupported_20, 1);
    assert_int_equal(sc.unsupported_10, 1);

    line.xy_m = square;
    line.point_count = 4;
    line.closed = 1;
    n = add_points(xy, 0, 0.0, 0.0, 1.0, 0.0, 9, 49);   /* bottom from 0.185 */
    n = add_points(xy, n, 1.0, 0.0, 0.0, 1.0, 0, 49);   /* right */
    n = add_points(xy, n, 0.0, 1.0, 1.0, 0.0, 0, 49);   /* top */
    n = add_points(xy, n, 0.0, 0.0, 0.0, 1.0, 9, 49);   /* left from 0.185 */
    score(&line, 1, xy, n, &sc);
    assert_int_equal(sc.unsupported_20, 1);
    assert_int_equal(sc.unsupported_10, 1);
    line.closed = 0; /* open, without its fourth side: the 14 cm run alone */
    score(&line, 1, xy, n, &sc);
    assert_int_equal(sc.unsupported_20, 0);
    assert_int_equal(sc.unsupported_10, 1);
}

/* Reflected beams only, at pose + range along the beam. */
static void test_scan_points(void **state)
{
    static const float range[4] = {1.0f, 8.0f, 2.0f, 0.01f};
    polyc_scan scan;
    double *xy = NULL;
    uint64_t n = 0;
    (void)state;
    memset(&scan, 0, sizeof scan);
    scan.pose_x_m = 1.0;
    scan.pose_y_m = 2.0;
    scan.pose_theta_rad = 0.5;
    scan.start_angle_rad = -0.5f;
    scan.angle_step_rad = 0.25f;
    scan.min_range_m = 0.02f;
    scan.max_range_m = 8.0f;
    scan.beam_count = 4;
    scan.range_m = range;
    assert_int_equal(gttopo_scan_points(&scan, 1, &xy, &n), 0);
    assert_int_equal(n, 2); /* 8 m: no return; 1 cm: under min_range_m */
    assert_near(xy[0], 2.0, 1e-12);
    assert_near(xy[1], 2.0, 1e-12);
    assert_near(xy[2], 1.0 + 2.0 * cos(0.5), 1e-6);
    assert_near(xy[3], 2.0 + 2.0 * sin(0.5), 1e-6);
    free(xy);
    scan.beam_count = 0;
    assert_int_equal(gttopo_scan_points(&scan, 1, &xy, &n), 0);
    assert_int_equal(n, 0);
    assert_null(xy);
}

/* A map 1 cm off a wall (101 samples, 1 cm) and a lone point 0.8 m from it:
 * the precision counts all 102 samples, the core precision (0.5 m) only the
 * 101 near the wall. */
static void test_core_precision(void **state)
{
    static const float near_wall[] = {0.0f, 0.01f, 1.0f, 0.01f};
    static const float person[] = {5.0f, 0.8f};
    polyc_polyline lines[2] = {{near_wall, 2, 0}, {person, 1, 0}};
    const char *text = "wall open 0 0 10 0\n";
    FILE *f = fmemopen((void *)(uintptr_t)text, strlen(text), "r");
    gtscore_truth t;
    gtscore_map_score sc;
    char err[256];
    double core;
    (void)state;
    assert_non_null(f);
    assert_int_equal(gtscore_truth_read(&t, f, "hand.gt.txt", err, sizeof err), 0);
    fclose(f);
    assert_int_equal(gtscore_score_map(&t, lines, 2, &sc), 0);
    assert_near(sc.precision_rms_m, sqrt((101.0 * 1e-4 + 0.64) / 102.0), 1e-6);
    assert_int_equal(gtscore_core_precision(&t, lines, 2, 0.5, &core), 0);
    assert_near(core, 0.01, 1e-6);
    assert_int_equal(gtscore_core_precision(&t, lines, 2, 1.0, &core), 0);
    assert_near(core, sc.precision_rms_m, 1e-9);
    assert_int_equal(gtscore_core_precision(&t, &lines[1], 1, 0.5, &core), 0);
    assert_near(core, 0.0, 0.0); /* nothing that near */
    gtscore_truth_free(&t);
}

/* No map: zeros; bad arguments: -1. */
static void test_empty_and_bad(void **state)
{
    static const float nan_xy[] = {0.0f, 0.0f, NAN, 1.0f};
    polyc_polyline line = {nan_xy, 2, 0};
    double xy[2] = {0.0, 0.0};
    gttopo_score sc;
    (void)state;
    score(NULL, 0, xy, 1, &sc);
    assert_near(sc.map_length_m, 0.0, 0.0);
    assert_int_equal(sc.unsupported_10, 0);
    assert_int_equal(gttopo_score_map(&line, 1, xy, 1, &sc), -1);
    line.xy_m = NULL;
    assert_int_equal(gttopo_score_map(&line, 1, xy, 1, &sc), -1);
    assert_int_equal(gttopo_score_map(NULL, 0, NULL, 1, &sc), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parallel_lines),
        cmocka_unit_test(test_short_overlap),
        cmocka_unit_test(test_corner_and_hairpin),
        cmocka_unit_test(test_crossings),
        cmocka_unit_test(test_loose_ends),
        cmocka_unit_test(test_unsupported_gap),
        cmocka_unit_test(test_unsupported_across_vertices),
        cmocka_unit_test(test_scan_points),
        cmocka_unit_test(test_core_precision),
        cmocka_unit_test(test_empty_and_bad),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
