/* test_gtscore.c - the scorer on hand cases with known answers, its
 * segment index against brute force, and its reader's error messages. */
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
#include "near.h"
#include "scansim.h"

/* Reads truth from text; fails the test on error. */
static void truth_from_text(gtscore_truth *t, const char *text)
{
    char err[256];
    FILE *f = fmemopen((void *)(uintptr_t)text, strlen(text), "r");
    assert_non_null(f);
    if (gtscore_truth_read(t, f, "hand.gt.txt", err, sizeof err) != 0)
        fail_msg("truth: %s", err);
    fclose(f);
}

/* The error message of a truth text that must fail. */
static void truth_error(const char *text, char *err, size_t err_size)
{
    gtscore_truth t;
    FILE *f = fmemopen((void *)(uintptr_t)text, strlen(text), "r");
    assert_non_null(f);
    assert_int_equal(gtscore_truth_read(&t, f, "bad.gt.txt", err, err_size), -1);
    gtscore_truth_free(&t);
    fclose(f);
}

/* A 4 m x 3 m room with its seen samples every 2 cm all round. */
static char *room_text(void)
{
    size_t cap = 1u << 20, len = 0;
    char *text = malloc(cap);
    int k;
    assert_non_null(text);
    len += (size_t)snprintf(text + len, cap - len,
                            "# a room\nideal 4\n\nwall closed 0 0 4 0 4 3 0 3\n");
    for (k = 0; k < 200; k++) /* bottom, y = 0, and top, y = 3 */
        len += (size_t)snprintf(text + len, cap - len, "seen %.2f 0\nseen %.2f 3\n",
                                0.02 * k, 4.0 - 0.02 * k);
    for (k = 0; k < 150; k++) /* right, x = 4, and left, x = 0 */
        len += (size_t)snprintf(text + len, cap - len, "seen 4 %.2f\nseen 0 %.2f\n",
                                0.02 * k, 3.0 - 0.02 * k);
    return text;
}

static void test_truth_as_map(void **state)
{
    static const float room[] = {0, 0, 4, 0, 4, 3, 0, 3};
    polyc_polyline line = {room, 4, 1};
    gtscore_truth t;
    gtscore_map_score sc;
    char *text = room_text();
    (void)state;
    truth_from_text(&t, text);
    assert_int_equal(t.wall_count, 1);
    assert_int_equal(t.seen_count, 700);
    assert_int_equal(t.ideal, 4);
    assert_int_equal(gtscore_score_map(&t, &line, 1, &sc), 0);
    assert_near(sc.precision_rms_m, 0.0, 1e-9);
    assert_near(sc.precision_max_m, 0.0, 1e-9);
    assert_int_equal(sc.precision_samples, 1400); /* 14 m every 1 cm */
    assert_near(sc.completeness, 1.0, 0.0);
    assert_int_equal(sc.vertices, 4);
    assert_near(sc.vertex_ratio, 1.0, 0.0);
    assert_int_equal(sc.params, 8); /* 2 a vertex, no arc, no circle */
    assert_int_equal(sc.arcs + sc.circles, 0);
    assert_int_equal(sc.ideal_params, 0); /* no ideal_params line: ratio 0 */
    assert_near(sc.param_ratio, 0.0, 0.0);
    gtscore_truth_free(&t);
    free(text);
}

/* ideal_params P A C: read, and refused when malformed or given twice. */
static void test_ideal_params_line(void **state)
{
    static const float room[] = {0, 0, 4, 0, 4, 3, 0, 3};
    polyc_polyline line = {room, 4, 1};
    static const char *const bad[] = {"ideal_params 7 1\nwall open 0 0 1 0\n",
                                      "ideal_params 7 1 0 2\nwall open 0 0 1 0\n",
                                      "ideal_params 7 1.5 0\nwall open 0 0 1 0\n",
                                      "ideal_params 7 1 0\nideal_params 7 1 0\nwall open 0 0 1 0\n"};
    gtscore_truth t;
    gtscore_map_score sc;
    char err[256];
    size_t k;
    (void)state;
    truth_from_text(&t, "ideal 4\nideal_params 10 2 0\nwall closed 0 0 4 0 4 3 0 3\n");
    assert_true(t.has_ideal_params);
    assert_int_equal(t.ideal_params, 10);
    assert_int_equal(t.ideal_arcs, 2);
    assert_int_equal(t.ideal_circles, 0);
    assert_int_equal(gtscore_score_map(&t, &line, 1, &sc), 0);
    assert_int_equal(sc.params, 8);
    assert_int_equal(sc.ideal_params, 10);
    assert_near(sc.param_ratio, 0.8, 1e-12);
    gtscore_truth_free(&t);
    for (k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        FILE *f = fmemopen((void *)bad[k], strlen(bad[k]), "r");
        assert_non_null(f);
        assert_int_equal(gtscore_truth_read(&t, f, "bad.gt.txt", err, sizeof err), -1);
        assert_non_null(strstr(err, "ideal_params"));
        fclose(f);
        gtscore_truth_free(&t);
    }
}

/* A map 1 cm beside a straight wall: every sample is 1 cm off. */
static void test_shifted_map(void **state)
{
    static const float map[] = {0.0f, 0.01f, 10.0f, 0.01f};
    polyc_polyline line = {map, 2, 0};
    gtscore_truth t;
    gtscore_map_score sc;
    (void)state;
    truth_from_text(&t, "wall open 0 0 10 0\nseen 5 0\nseen 5.02 0\n");
    assert_int_equal(gtscore_score_map(&t, &line, 1, &sc), 0);
    assert_int_equal(sc.precision_samples, 1001);
    assert_near(sc.precision_rms_m, 0.01, 1e-6);
    assert_near(sc.precision_p95_m, 0.01, 1e-6);
    assert_near(sc.precision_max_m, 0.01, 1e-6);
    assert_near(sc.completeness, 1.0, 0.0);
    assert_int_equal(sc.ideal, 0); /* no ideal line: ratio 0 */
    assert_near(sc.vertex_ratio, 0.0, 0.0);
    gtscore_truth_free(&t);
}

/* The map lacks the top wall: the top samples farther than 5 cm from the
 * side walls' ends are missed. */
static void test_missing_wall(void **state)
{
    static const float three_sides[] = {0, 3, 0, 0, 4, 0, 4, 3};
    polyc_polyline line = {three_sides, 4, 0};
    gtscore_truth t;
    gtscore_map_score sc;
    char *text = room_text();
    uint32_t k, missed = 0;
    (void)state;
    truth_from_text(&t, text);
    for (k = 0; k < 200; k++) { /* top samples at x = 4 - 0.02 k */
        double x = 4.0 - 0.02 * k;
        if (x > 0.05 + 1e-9 && x < 4.0 - 0.05 - 1e-9)
            missed++;
    }
    assert_int_equal(missed, 200 - 3 - 2); /* x = 4, 3.98, 3.96 and 0.02, 0.04 */
    assert_int_equal(gtscore_score_map(&t, &line, 1, &sc), 0);
    assert_int_equal(sc.seen_covered, 700 - missed);
    assert_near(sc.completeness, (700.0 - missed) / 700.0, 1e-12);
    assert_near(sc.precision_rms_m, 0.0, 1e-9);
    gtscore_truth_free(&t);
    free(text);
}

/* p95 by nearest rank, and a map sample far from every wall. */
static void test_percentile_and_far(void **state)
{
    static const float far[] = {0.0f, 3.0f};
    static const float on[] = {0.0f, 0.0f, 1.0f, 0.0f};
    polyc_polyline lines[2] = {{on, 2, 0}, {far, 1, 0}};
    gtscore_truth t;
    gtscore_map_score sc;
    (void)state;
    truth_from_text(&t, "wall open 0 0 1 0\n");
    assert_int_equal(gtscore_score_map(&t, lines, 2, &sc), 0);
    /* 101 samples on the wall (0 .. 1 m) and one 3 m away */
    assert_int_equal(sc.precision_samples, 102);
    assert_near(sc.precision_max_m, 3.0, 1e-6);
    assert_near(sc.precision_p95_m, 0.0, 1e-9);
    assert_near(sc.precision_rms_m, sqrt(9.0 / 102.0), 1e-6);
    assert_int_equal(sc.vertices, 3);
    assert_int_equal(sc.polylines, 2);
    assert_near(sc.completeness, 1.0, 0.0); /* no seen samples */
    gtscore_truth_free(&t);
}

/* Five beams at a wall x = 2, |y| <= 1: two hit it with known errors, two
 * pass beside it, one returns nothing. */
static void test_single_scan(void **state)
{
    static const float wall[] = {2.0f, -1.0f, 2.0f, 1.0f};
    float range[5];
    polyc_scan scan;
    gtscore_index map;
    gtscore_scan_score acc;
    uint64_t within, total;
    (void)state;
    range[0] = 2.3f;                              /* -0.5 rad: beside the wall */
    range[1] = (float)(2.0 / cos(0.25) + 0.03);   /* hits, error +3 cm */
    range[2] = 1.96f;                             /* hits, error -4 cm */
    range[3] = 8.0f;                              /* no return */
    range[4] = 2.5f;                              /* beside the wall */
    memset(&scan, 0, sizeof scan);
    scan.start_angle_rad = -0.5f;
    scan.angle_step_rad = 0.25f;
    scan.min_range_m = 0.02f;
    scan.max_range_m = 8.0f;
    scan.beam_count = 5;
    scan.range_m = range;
    gtscore_index_init(&map);
    assert_int_equal(gtscore_index_add_f(&map, wall, 2, 0), 0);
    assert_int_equal(gtscore_index_build(&map, 0.1), 0);

    memset(&acc, 0, sizeof acc);
    gtscore_score_scan(&map, &scan, &acc);
    assert_int_equal(acc.reflected, 4);
    assert_int_equal(acc.hits, 2);
    assert_near(acc.f, 0.5, 0.0);
    assert_near(acc.ray_rmse_m, sqrt((0.03 * 0.03 + 0.04 * 0.04) / 2.0), 2e-6);

    /* the same scene moved and turned: the same scores */
    {
        const double c = cos(1.0), s = sin(1.0);
        float moved[4];
        gtscore_scan_score acc2;
        int k;
        for (k = 0; k < 2; k++) {
            moved[2 * k] = (float)(5.0 + c * (double)wall[2 * k] - s * (double)wall[2 * k + 1]);
            moved[2 * k + 1] = (float)(-3.0 + s * (double)wall[2 * k] + c * (double)wall[2 * k + 1]);
        }
        gtscore_index_free(&map);
        gtscore_index_init(&map);
        assert_int_equal(gtscore_index_add_f(&map, moved, 2, 0), 0);
        assert_int_equal(gtscore_index_build(&map, 0.1), 0);
        scan.pose_x_m = 5.0;
        scan.pose_y_m = -3.0;
        scan.pose_theta_rad = 1.0;
        memset(&acc2, 0, sizeof acc2);
        gtscore_score_scan(&map, &scan, &acc2);
        assert_int_equal(acc2.hits, 2);
        assert_near(acc2.ray_rmse_m, acc.ray_rmse_m, 2e-5);
    }

    /* endpoints within 5 cm: beams 1 (3 cm) and 2 (4 cm) */
    gtscore_endpoints_within(&map, &scan, 1, 0.05, &within, &total);
    assert_int_equal(total, 4);
    assert_int_equal(within, 2);
    gtscore_endpoints_within(&map, &scan, 1, 0.035, &within, &total);
    assert_int_equal(within, 1);
    gtscore_index_free(&map);
}

/* The line-fit floor: endpoints on a wall seen from one side, offset by a
 * known line (1 cm at one end, 3 cm at the other), give that line's RMS
 * over the stretches they cover; endpoints on the wall give 0; a wall seen
 * by too few endpoints gives none. */
static void test_line_floor(void **state)
{
    (void)state;
    gtscore_truth t;
    truth_from_text(&t, "ideal 2\nwall open 0 2 4 2\n");
    /* a sensor at (2, 0) looking up; beam i ends on y = 2 - off(x) */
    enum { N = 181 };
    float range[N];
    polyc_scan scan;
    memset(&scan, 0, sizeof scan);
    scan.pose_x_m = 2.0;
    scan.start_angle_rad = (float)(0.25 * 3.14159265358979);
    scan.angle_step_rad = (float)(0.5 * 3.14159265358979 / (N - 1));
    scan.min_range_m = 0.02f;
    scan.max_range_m = 8.0f;
    scan.beam_count = N;
    scan.range_m = range;
    for (int pass = 0; pass < 2; pass++) {
        for (int i = 0; i < N; i++) {
            double a = (double)scan.start_angle_rad + i * (double)scan.angle_step_rad;
            /* off(x) = a0 + a1 x: solve (2 - off(x)) = r sin a, x = 2 + r cos a */
            double a0 = pass ? 0.01 : 0.0, a1 = pass ? 0.005 : 0.0;
            double r = (2.0 - a0 - a1 * 2.0) / (sin(a) + a1 * cos(a));
            range[i] = (float)r;
        }
        double floor_m = -2.0;
        assert_int_equal(gtscore_line_floor(&t, &scan, 1, &floor_m), 0);
        if (pass == 0) {
            assert_near(floor_m, 0.0, 1e-6);
            continue;
        }
        /* the beams cover x in [0, 4] (45 to 135 degrees): the RMS of
         * 0.01 + 0.005 x over 2 cm stretches of [0, 4] */
        double sum = 0.0;
        int n = 0;
        for (int b = 0; b < 200; b++) {
            double x = (b + 0.5) * 0.02, e = 0.01 + 0.005 * x;
            sum += e * e;
            n++;
        }
        /* beams 1 degree apart leave some 2 cm stretches without an
         * endpoint near the ends: a few percent either way */
        assert_near(floor_m, sqrt(sum / n), 0.001);
    }
    scan.beam_count = 10; /* 10 endpoints: too few for a fit */
    double none = 0.0;
    assert_int_equal(gtscore_line_floor(&t, &scan, 1, &none), 0);
    assert_true(none < 0.0);
    gtscore_truth_free(&t);
}

/* The ideal-map fit: one wall seen in two runs whose endpoints sit 1 cm and
 * 3 cm off it (as two rooms' pose errors would put them) gives the RMS of
 * those offsets over the runs' seen samples; a run under 20 cm and
 * endpoints beside every run do not count; without seen samples, none. */
static void test_ideal_fit(void **state)
{
    (void)state;
    char text[8192];
    size_t len = (size_t)snprintf(text, sizeof text, "ideal 4\nwall open 0 2 4 2\n");
    int seen_a = 0, seen_b = 0;
    for (int i = 0; i <= 50; i++, seen_a++) /* run A: x 0.5 .. 1.5 */
        len += (size_t)snprintf(text + len, sizeof text - len, "seen %.2f 2\n", 0.5 + 0.02 * i);
    for (int i = 0; i <= 50; i++, seen_b++) /* run B: x 2.5 .. 3.5 */
        len += (size_t)snprintf(text + len, sizeof text - len, "seen %.2f 2\n", 2.5 + 0.02 * i);
    for (int i = 0; i <= 5; i++) /* run C: 10 cm, too short */
        len += (size_t)snprintf(text + len, sizeof text - len, "seen %.2f 2\n", 3.8 + 0.02 * i);
    assert_true(len < sizeof text);
    gtscore_truth t;
    truth_from_text(&t, text);
    /* one beam a scan, straight up from (x, 0): A at 1 cm, B at 3 cm, C and
     * the unseen stretch between A and B at 5 cm */
    enum { N = 64 };
    polyc_scan scans[N];
    float range[N];
    int n = 0;
    for (int i = 0; i <= 20; i++, n++) {
        memset(&scans[n], 0, sizeof scans[n]);
        scans[n].pose_x_m = i < 11 ? 0.5 + 0.1 * i : 2.5 + 0.1 * (i - 11);
        range[n] = i < 11 ? 1.99f : 1.97f;
    }
    double extra_x[] = {2.0, 2.2, 3.85, 3.9};
    for (int i = 0; i < 4; i++, n++) {
        memset(&scans[n], 0, sizeof scans[n]);
        scans[n].pose_x_m = extra_x[i];
        range[n] = 1.95f;
    }
    for (int i = 0; i < n; i++) {
        scans[i].start_angle_rad = (float)(0.5 * 3.14159265358979);
        scans[i].min_range_m = 0.02f;
        scans[i].max_range_m = 8.0f;
        scans[i].beam_count = 1;
        scans[i].range_m = &range[i];
    }
    double fit_m = -2.0;
    assert_int_equal(gtscore_ideal_fit(&t, scans, (uint32_t)n, &fit_m), 0);
    double want = sqrt((seen_a * 1e-4 + seen_b * 9e-4) / (seen_a + seen_b));
    assert_near(fit_m, want, 1e-5);
    gtscore_truth_free(&t);

    truth_from_text(&t, "ideal 2\nwall open 0 2 4 2\n");
    assert_int_equal(gtscore_ideal_fit(&t, scans, (uint32_t)n, &fit_m), 0);
    assert_true(fit_m < 0.0);
    gtscore_truth_free(&t);
}

/* The grid index against brute force on random segments, points (some far
 * outside the grid) and rays. */
static void test_index_vs_brute_force(void **state)
{
    enum { SEGS = 300, QUERIES = 3000 };
    double seg[4 * SEGS];
    gtscore_index index;
    scansim_rng rng;
    int i, k;
    (void)state;
    scansim_rng_seed(&rng, 99);
    gtscore_index_init(&index);
    for (i = 0; i < SEGS; i++) {
        double x = 20.0 * scansim_rng_uniform(&rng) - 10.0;
        double y = 10.0 * scansim_rng_uniform(&rng);
        double a = 6.283 * scansim_rng_uniform(&rng), len = 3.0 * scansim_rng_uniform(&rng);
        seg[4 * i] = x;
        seg[4 * i + 1] = y;
        seg[4 * i + 2] = x + len * cos(a);
        seg[4 * i + 3] = y + len * sin(a);
        assert_int_equal(gtscore_index_add_d(&index, &seg[4 * i], 2, 0), 0);
    }
    assert_int_equal(gtscore_index_build(&index, 0.3), 0);
    for (k = 0; k < QUERIES; k++) {
        double x = 40.0 * scansim_rng_uniform(&rng) - 20.0;
        double y = 30.0 * scansim_rng_uniform(&rng) - 10.0;
        double a = 6.283 * scansim_rng_uniform(&rng);
        double best_d = HUGE_VAL, best_t = HUGE_VAL, d, t;
        for (i = 0; i < SEGS; i++) {
            const double *g = &seg[4 * i];
            double ex = g[2] - g[0], ey = g[3] - g[1], wx = x - g[0], wy = y - g[1];
            double u = (wx * ex + wy * ey) / (ex * ex + ey * ey);
            double dx = cos(a), dy = sin(a), den = dx * ey - dy * ex;
            u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
            d = hypot(wx - u * ex, wy - u * ey);
            if (d < best_d)
                best_d = d;
            if (fabs(den) > 1e-15) {
                double tt = (-wx * ey + wy * ex) / den, uu = (-wx * dy + wy * dx) / den;
                if (tt > 1e-12 && tt <= 15.0 && uu >= 0.0 && uu <= 1.0 && tt < best_t)
                    best_t = tt;
            }
        }
        d = gtscore_index_distance(&index, x, y, HUGE_VAL);
        assert_near(d, best_d, 1e-9);
        d = gtscore_index_distance(&index, x, y, 0.2);
        if (best_d <= 0.2)
            assert_near(d, best_d, 1e-9);
        else
            assert_true(d > 0.2);
        t = gtscore_index_ray(&index, x, y, a, 15.0);
        if (isinf(best_t))
            assert_true(isinf(t));
        else
            assert_near(t, best_t, 1e-9);
    }
    gtscore_index_free(&index);
}

static void test_reader_errors(void **state)
{
    char err[256];
    gtscore_truth t;
    (void)state;
    truth_error("wall closed 0 0 1 1\n", err, sizeof err);
    assert_string_equal(err, "bad.gt.txt:1: wall: a closed wall needs at least 3 points");
    truth_error("# c\nwall open 0 0 1 1\nwall open 0 x 1 1\n", err, sizeof err);
    assert_string_equal(err, "bad.gt.txt:3: wall: bad number 'x'");
    truth_error("wall open 0 0 1\n", err, sizeof err);
    assert_string_equal(err, "bad.gt.txt:1: wall: odd number of coordinates");
    truth_error("wall sideways 0 0 1 1\n", err, sizeof err);
    assert_string_equal(err, "bad.gt.txt:1: wall: expected 'closed' or 'open'");
    truth_error("wall open 0 0 1 1\nseen 1\n", err, sizeof err);
    assert_string_equal(err, "bad.gt.txt:2: seen: expected two numbers x y");
    truth_error("ideal 3\nideal 4\n", err, sizeof err);
    assert_string_equal(err, "bad.gt.txt:2: ideal: given twice");
    truth_error("ideal -1\n", err, sizeof err);
    assert_string_equal(err, "bad.gt.txt:1: ideal: expected one whole number");
    truth_error("wall open 0 0 1 1\nfloor 3\n", err, sizeof err);
    assert_string_equal(err, "bad.gt.txt:2: unknown line type 'floor'");
    truth_error("seen 1 1\n", err, sizeof err);
    assert_string_equal(err, "bad.gt.txt:1: no walls");
    truth_error("wall open 0 0 1 inf\n", err, sizeof err);
    assert_string_equal(err, "bad.gt.txt:1: wall: bad number 'inf'");
    assert_int_equal(gtscore_truth_load(&t, "/nonexistent/x.gt.txt", err, sizeof err), -1);
    assert_non_null(strstr(err, "/nonexistent/x.gt.txt: "));
    gtscore_truth_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_truth_as_map),
        cmocka_unit_test(test_ideal_params_line),
        cmocka_unit_test(test_shifted_map),
        cmocka_unit_test(test_missing_wall),
        cmocka_unit_test(test_percentile_and_far),
        cmocka_unit_test(test_single_scan),
        cmocka_unit_test(test_index_vs_brute_force),
        cmocka_unit_test(test_line_floor),
        cmocka_unit_test(test_ideal_fit),
        cmocka_unit_test(test_reader_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
