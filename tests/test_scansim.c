/* test_scansim.c - the laser simulator: determinism, geometry, noise,
 * people, dropout, its log and ground-truth files read back by scanlog and
 * gtscore, and the randomised scene kinds (layouts per seed, a path clear
 * of every wall, people in free space). */
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
#include "scanlog.h"
#include "scansim.h"

#define TEST_PI 3.14159265358979323846

/* splitmix64 from seed 0: the published first outputs. Pins the integer
 * stream on every platform. */
static void test_rng_reference(void **state)
{
    scansim_rng rng;
    (void)state;
    scansim_rng_seed(&rng, 0);
    assert_true(scansim_rng_u64(&rng) == UINT64_C(0xE220A8397B1DCDAF));
    assert_true(scansim_rng_u64(&rng) == UINT64_C(0x6E789E6AA1B965F4));
    assert_true(scansim_rng_u64(&rng) == UINT64_C(0x06C45D188009454F));
}

static void test_rng_gauss_moments(void **state)
{
    scansim_rng rng;
    double sum = 0.0, sum_sq = 0.0, mean, var;
    int i, n = 200000;
    (void)state;
    scansim_rng_seed(&rng, 42);
    for (i = 0; i < n; i++) {
        double g = scansim_rng_gauss(&rng), u = scansim_rng_uniform(&rng);
        assert_true(u >= 0.0 && u < 1.0);
        sum += g;
        sum_sq += g * g;
    }
    mean = sum / n;
    var = sum_sq / n - mean * mean;
    assert_true(fabs(mean) < 0.01);
    assert_true(fabs(var - 1.0) < 0.02);
}

static void run_builtin(scansim_scene *scene, const char *name, uint64_t seed)
{
    assert_int_equal(scansim_scene_builtin(scene, name, seed), 0);
    assert_int_equal(scansim_run(scene), 0);
    assert_true(scene->scan_count > 0);
}

static void test_same_seed_same_ranges(void **state)
{
    scansim_scene a, b, c;
    size_t n;
    (void)state;
    run_builtin(&a, "office", 7);
    run_builtin(&b, "office", 7);
    run_builtin(&c, "office", 8);
    assert_int_equal(a.scan_count, b.scan_count);
    n = (size_t)a.scan_count * a.laser.beam_count;
    assert_memory_equal(a.range_m, b.range_m, n * sizeof(float));
    assert_true(a.scans[5].pose_x_m == b.scans[5].pose_x_m);
    assert_true(memcmp(a.range_m, c.range_m, n * sizeof(float)) != 0);
    /* a second run of the same scene starts the stream afresh */
    assert_int_equal(scansim_run(&a), 0);
    assert_memory_equal(a.range_m, b.range_m, n * sizeof(float));
    scansim_scene_free(&a);
    scansim_scene_free(&b);
    scansim_scene_free(&c);
}

/* One beam at a wall 2 m away, perpendicular: the range is 2 m within the
 * noise, exactly 2 m without it. */
static void test_perpendicular_beam(void **state)
{
    static const double wall[] = {2.0, -5.0, 2.0, 5.0};
    scansim_scene s;
    double sum = 0.0;
    uint32_t i, n = 400;
    (void)state;
    scansim_scene_init(&s, "wall", 3);
    s.laser.beam_count = 1;
    s.laser.start_angle_rad = 0.0f;
    s.laser.dropout = 0.0f;
    s.pose_sigma_m = 0.0;
    s.pose_sigma_rad = 0.0;
    assert_int_equal(scansim_add_wall(&s, wall, 2, 0), 0);
    for (i = 0; i < n; i++)
        assert_int_equal(scansim_add_pose(&s, 0.0, 0.0, 0.0), 0);
    assert_int_equal(scansim_run(&s), 0);
    for (i = 0; i < n; i++) {
        double r = (double)s.range_m[i];
        assert_true(fabs(r - 2.0) < 5.0 * 0.01);
        sum += r;
    }
    assert_true(fabs(sum / n - 2.0) < 0.003); /* 4 standard errors */

    s.laser.range_sigma_m = 0.0f;
    assert_int_equal(scansim_run(&s), 0);
    assert_near(s.range_m[0], 2.0, 1e-6);
    /* the wall seen face-on: samples around the hit point, and a short
     * stretch is not worth a vertex */
    assert_true(scansim_seen_count(&s) >= 1);
    assert_int_equal(scansim_ideal_vertices(&s), 0);
    scansim_scene_free(&s);
}

/* A person stands in the beam in scan 1 only. */
static void test_person_in_one_scan(void **state)
{
    static const double wall[] = {5.0, -5.0, 5.0, 5.0};
    scansim_person p;
    scansim_scene s;
    (void)state;
    scansim_scene_init(&s, "person", 1);
    s.laser.beam_count = 1;
    s.laser.start_angle_rad = 0.0f;
    s.laser.range_sigma_m = 0.0f;
    s.laser.dropout = 0.0f;
    s.pose_sigma_m = 0.0;
    s.pose_sigma_rad = 0.0;
    assert_int_equal(scansim_add_wall(&s, wall, 2, 0), 0);
    memset(&p, 0, sizeof p);
    p.from_x_m = p.to_x_m = 2.0;
    p.radius_m = 0.2;
    p.first_scan = p.last_scan = 1;
    assert_int_equal(scansim_add_person(&s, &p), 0);
    assert_int_equal(scansim_add_pose(&s, 0, 0, 0), 0);
    assert_int_equal(scansim_add_pose(&s, 0, 0, 0), 0);
    assert_int_equal(scansim_add_pose(&s, 0, 0, 0), 0);
    assert_int_equal(scansim_run(&s), 0);
    assert_near(s.range_m[0], 5.0, 1e-6);
    assert_near(s.range_m[1], 1.8, 1e-6);
    assert_near(s.range_m[2], 5.0, 1e-6);
    scansim_scene_free(&s);
}

/* Dropped beams and walls beyond the range read exactly max_range_m. */
static void test_dropout_and_max_range(void **state)
{
    scansim_scene s;
    uint32_t i, dropped = 0, total;
    (void)state;
    run_builtin(&s, "square", 5);
    total = s.scan_count * s.laser.beam_count;
    for (i = 0; i < total; i++)
        dropped += s.range_m[i] == s.laser.max_range_m;
    /* the room is 6 x 4 m: only dropout gives no return, 0.3% of beams */
    assert_true(dropped > total / 1000u && dropped < total / 100u);

    s.laser.dropout = 0.5f;
    assert_int_equal(scansim_run(&s), 0);
    for (dropped = 0, i = 0; i < total; i++)
        dropped += s.range_m[i] == s.laser.max_range_m;
    assert_true(fabs((double)dropped / total - 0.5) < 0.03);
    scansim_scene_free(&s);
}

static void test_builtins_sane(void **state)
{
    const char *const *names = scansim_builtin_names();
    scansim_scene s;
    (void)state;
    for (; *names; names++) {
        gtscore_index walls;
        uint32_t i, w;
        /* the randomised kinds run 300-1,000 scans: every 20th of them here */
        assert_int_equal(scansim_scene_builtin(&s, *names, 11), 0);
        if (s.pose_count > 400u)
            assert_int_equal(scansim_keep_every(&s, 20u), 0);
        assert_int_equal(scansim_run(&s), 0);
        assert_true(s.scan_count > 0 && s.scan_count <= 400u);
        assert_true(scansim_seen_count(&s) > 0);
        /* every seen sample lies on a true wall */
        gtscore_index_init(&walls);
        for (w = 0; w < s.wall_count; w++)
            assert_int_equal(gtscore_index_add_d(&walls, &s.wall_xy_m[2u * s.walls[w].first_point],
                                                 s.walls[w].point_count,
                                                 (int)s.walls[w].closed),
                             0);
        assert_int_equal(gtscore_index_build(&walls, 0.25), 0);
        for (i = 0; i < s.sample_count; i++)
            assert_true(gtscore_index_distance(&walls, s.sample_xy_m[2u * i],
                                               s.sample_xy_m[2u * i + 1u], 1.0) < 1e-9);
        gtscore_index_free(&walls);
        if (strcmp(*names, "square") == 0)
            assert_int_equal(scansim_ideal_vertices(&s), 4);
        if (strcmp(*names, "circle") == 0) {
            assert_int_equal(s.scan_count, 3);
            assert_int_equal(scansim_seen_count(&s), s.sample_count); /* seen all round */
        }
        scansim_scene_free(&s);
    }
    assert_int_equal(scansim_scene_builtin(&s, "nowhere", 1), -1);
}

/* A stadium (two straight sides, two half circles of 2 m radius) seen all
 * round from its centre by a full-circle scanner: four vertices where the
 * straights meet the arcs, two arcs: 10 parameters; a circle seen all
 * round: 3; straight rooms: 2 a corner. */
static void test_ideal_params(void **state)
{
    scansim_scene s;
    double xy[2u * 2048u];
    uint8_t smooth[2048u];
    uint32_t n = 0, m, k, arcs, circles;
    (void)state;
    scansim_scene_init(&s, "stadium", 1);
    s.laser.beam_count = 2880u;
    s.laser.start_angle_rad = (float)(-TEST_PI);
    s.laser.angle_step_rad = (float)(TEST_PI / 1440.0);
    s.laser.dropout = 0.0f;
    /* east half circle from (2, -2) up to (2, 2), then west from (-2, 2) down */
    m = scansim_arc_points(&xy[2u * n], 1024u, 2.0, 0.0, 2.0, -TEST_PI / 2.0, TEST_PI / 2.0);
    for (k = 0; k < m; k++)
        smooth[n + k] = k > 0 && k + 1u < m;
    n += m;
    m = scansim_arc_points(&xy[2u * n], 1024u, -2.0, 0.0, 2.0, TEST_PI / 2.0, 1.5 * TEST_PI);
    for (k = 0; k < m; k++)
        smooth[n + k] = k > 0 && k + 1u < m;
    n += m;
    assert_true(n > 100u); /* sides of at most 0.1 mm sagitta: about 1.8 cm */
    assert_int_equal(scansim_add_wall_smooth(&s, xy, n, 1, smooth), 0);
    assert_int_equal(scansim_add_pose(&s, 0.0, 0.0, 0.0), 0);
    assert_int_equal(scansim_run(&s), 0);
    assert_int_equal(scansim_seen_count(&s), s.sample_count);
    assert_int_equal(scansim_ideal_params(&s, &arcs, &circles), 10);
    assert_int_equal(arcs, 2);
    assert_int_equal(circles, 0);
    scansim_scene_free(&s);

    run_builtin(&s, "circle", 1); /* the paper's three circles, seen all round */
    assert_int_equal(scansim_ideal_params(&s, &arcs, &circles), 9);
    assert_int_equal(circles, 3);
    assert_int_equal(arcs, 0);
    assert_int_equal(scansim_ideal_vertices(&s), 2160); /* the line-only count keeps its sides */
    scansim_scene_free(&s);

    run_builtin(&s, "square", 1);
    assert_int_equal(scansim_ideal_params(&s, &arcs, &circles), 2u * scansim_ideal_vertices(&s));
    assert_int_equal(arcs + circles, 0);
    scansim_scene_free(&s);

    /* a pillar hall: pillars seen all round are circles, those seen in
     * part arcs; without the smooth flags every point is a corner again,
     * and the parameters are twice the line-only vertices */
    run_builtin(&s, "pillars", 3);
    assert_true(scansim_ideal_params(&s, &arcs, &circles) < scansim_ideal_vertices(&s));
    assert_true(circles >= 1u);
    memset(s.sample_smooth, 0, s.sample_count);
    assert_int_equal(scansim_ideal_params(&s, &arcs, &circles), 2u * scansim_ideal_vertices(&s));
    assert_int_equal(arcs + circles, 0);
    scansim_scene_free(&s);
}

/* The ground truth written, read back by gtscore: same walls, seen
 * samples and ideal count. */
static void test_gt_round_trip(void **state)
{
    scansim_scene s;
    gtscore_truth t;
    char err[256];
    FILE *f = tmpfile();
    uint32_t w, i;
    (void)state;
    assert_non_null(f);
    run_builtin(&s, "office", 7);
    assert_int_equal(scansim_write_gt(&s, f), 0);
    rewind(f);
    assert_int_equal(gtscore_truth_read(&t, f, "office.gt.txt", err, sizeof err), 0);
    fclose(f);
    assert_int_equal(t.wall_count, s.wall_count);
    assert_int_equal(t.seen_count, scansim_seen_count(&s));
    assert_true(t.has_ideal);
    assert_int_equal(t.ideal, scansim_ideal_vertices(&s));
    assert_true(t.has_ideal_params);
    assert_int_equal(t.ideal_params, scansim_ideal_params(&s, NULL, NULL));
    for (w = 0; w < s.wall_count; w++) {
        assert_int_equal(t.walls[w].point_count, s.walls[w].point_count);
        assert_int_equal(t.walls[w].closed, s.walls[w].closed);
        for (i = 0; i < 2u * s.walls[w].point_count; i++)
            assert_true(fabs(t.wall_xy_m[2u * t.walls[w].first_point + i] -
                             s.wall_xy_m[2u * s.walls[w].first_point + i]) <= 0.5e-4 + 1e-12);
    }
    gtscore_truth_free(&t);
    scansim_scene_free(&s);
}

/* The log written, read back by the CLI's reader: same poses and ranges
 * (to the mm of the text format), same beam geometry. */
static void test_log_round_trip(void **state)
{
    scansim_scene s;
    scanlog log;
    FILE *f = tmpfile();
    uint32_t k, i;
    (void)state;
    assert_non_null(f);
    run_builtin(&s, "angled", 7);
    assert_int_equal(scansim_write_log(&s, f), 0);
    rewind(f);
    memset(&log, 0, sizeof log);
    if (scanlog_read(&log, f, "angled.log", NULL) != 0)
        fail_msg("scanlog_read: %s", log.error);
    fclose(f);
    assert_int_equal(log.count, s.scan_count);
    for (k = 0; k < s.scan_count; k++) {
        const polyc_scan *a = &s.scans[k], *b = &log.scans[k];
        assert_int_equal(b->beam_count, a->beam_count);
        assert_true(fabs(b->pose_x_m - a->pose_x_m) < 1e-6);
        assert_true(fabs(b->pose_theta_rad - a->pose_theta_rad) < 1e-6);
        assert_near(b->start_angle_rad, a->start_angle_rad, 1e-8);
        assert_near(b->angle_step_rad, a->angle_step_rad, 1e-8);
        assert_near(b->max_range_m, a->max_range_m, 1e-6);
        for (i = 0; i < a->beam_count; i++) {
            int none_a = !(a->range_m[i] < a->max_range_m);
            int none_b = !(b->range_m[i] < b->max_range_m);
            assert_int_equal(none_a, none_b);
            if (!none_a)
                assert_near(b->range_m[i], a->range_m[i], 0.0005 + 1e-6);
        }
    }
    scanlog_free(&log);
    scansim_scene_free(&s);
}

static void test_path_spacing(void **state)
{
    static const double way[] = {0.0, 0.0, 1.0, 0.0, 1.0, 1.0};
    scansim_scene s;
    uint32_t i;
    (void)state;
    scansim_scene_init(&s, "path", 1);
    assert_int_equal(scansim_add_path(&s, way, 3, 0.25), 0);
    assert_int_equal(s.pose_count, 8); /* 0 .. 1.75 m in 0.25 m steps */
    for (i = 1; i < s.pose_count; i++) {
        double d = hypot(s.poses[i].x_m - s.poses[i - 1u].x_m,
                         s.poses[i].y_m - s.poses[i - 1u].y_m);
        assert_true(d <= 0.25 + 1e-9 && d > 0.17);
    }
    assert_near(s.poses[7].theta_rad, 3.14159265358979323846 / 2, 1e-12);
    scansim_scene_free(&s);
}


static const char *const kinds[] = {"hall",      "shelves", "flat",    "curved",  "thinwalls",
                                    "drift",     "farhall", "pillars", "arcwalls", "roundmix"};
#define KIND_COUNT (sizeof kinds / sizeof kinds[0])

/* Is (x, y) inside the closed wall w? (even-odd rule) */
static int inside_wall(const scansim_scene *s, uint32_t w, double x, double y)
{
    const double *xy = &s->wall_xy_m[2u * s->walls[w].first_point];
    uint32_t i, j, n = s->walls[w].point_count;
    int in = 0;
    for (i = 0, j = n - 1u; i < n; j = i++)
        if ((xy[2u * i + 1u] > y) != (xy[2u * j + 1u] > y) &&
            x < xy[2u * j] + (xy[2u * i] - xy[2u * j]) * (y - xy[2u * j + 1u]) /
                                 (xy[2u * i + 1u] - xy[2u * j + 1u]))
            in = !in;
    return in;
}

static double cross3(const double *o, const double *a, const double *b)
{
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

/* Do segments ab and cd cross at a point inside both, each pair of ends
 * more than 1 um from the other's line on either side? (touching is not
 * crossing: the flat's wall boxes meet, furniture stands flush) */
static int segments_cross(const double *a, const double *b, const double *c, const double *d)
{
    double lab = hypot(b[0] - a[0], b[1] - a[1]), lcd = hypot(d[0] - c[0], d[1] - c[1]);
    double d1 = cross3(a, b, c) / lab, d2 = cross3(a, b, d) / lab;
    double d3 = cross3(c, d, a) / lcd, d4 = cross3(c, d, b) / lcd;
    return ((d1 > 1e-6 && d2 < -1e-6) || (d1 < -1e-6 && d2 > 1e-6)) &&
           ((d3 > 1e-6 && d4 < -1e-6) || (d3 < -1e-6 && d4 > 1e-6));
}

/* The first pair of walls that cross each other, or -1. */
static int32_t walls_crossing(const scansim_scene *s)
{
    uint32_t v, w, i, j;
    for (v = 0; v < s->wall_count; v++)
        for (w = v + 1u; w < s->wall_count; w++) {
            const scansim_wall *p = &s->walls[v], *q = &s->walls[w];
            uint32_t np = p->closed ? p->point_count : p->point_count - 1u;
            uint32_t nq = q->closed ? q->point_count : q->point_count - 1u;
            for (i = 0; i < np; i++)
                for (j = 0; j < nq; j++)
                    if (segments_cross(&s->wall_xy_m[2u * (p->first_point + i)],
                                       &s->wall_xy_m[2u * (p->first_point + (i + 1u) % p->point_count)],
                                       &s->wall_xy_m[2u * (q->first_point + j)],
                                       &s->wall_xy_m[2u * (q->first_point + (j + 1u) % q->point_count)]))
                        return (int32_t)v;
        }
    return -1;
}

/* Every kind, seeds 0-5, without simulating: a few hundred to 1,500 poses,
 * the robot never within 0.25 m of a wall nor inside a box (a closed wall
 * holds either every pose, the hall round them, or none), no wall crossing
 * another (furniture does not stand in a wall), people present,
 * some of them standing still for 20 scans or more, each clear of the walls
 * and of the robot; and each seed a different layout. */
static void test_kinds_layouts(void **state)
{
    uint32_t k, w, i;
    uint64_t seed;
    (void)state;
    for (k = 0; k < KIND_COUNT; k++) {
        uint32_t prev_points = 0;
        double prev_x = 0.0;
        for (seed = 0; seed < 6u; seed++) {
            scansim_scene s;
            uint32_t standing = 0;
            assert_int_equal(scansim_scene_builtin(&s, kinds[k], seed), 0);
            if (s.pose_count < 300u || s.pose_count > 1500u)
                fail_msg("%s seed %u: %u poses", kinds[k], (unsigned)seed, s.pose_count);
            if (scansim_path_clearance(&s) < 0.25)
                fail_msg("%s seed %u: the path comes %.3f m from a wall", kinds[k],
                         (unsigned)seed, scansim_path_clearance(&s));
            for (w = 0; w < s.wall_count; w++) {
                uint32_t in = 0;
                if (!s.walls[w].closed)
                    continue;
                for (i = 0; i < s.pose_count; i++)
                    in += (uint32_t)inside_wall(&s, w, s.poses[i].x_m, s.poses[i].y_m);
                if (in != 0 && in != s.pose_count)
                    fail_msg("%s seed %u: %u poses inside wall %u", kinds[k], (unsigned)seed, in,
                             w);
            }
            if (walls_crossing(&s) >= 0)
                fail_msg("%s seed %u: wall %d crosses another", kinds[k], (unsigned)seed,
                         (int)walls_crossing(&s));
            assert_true(s.person_count >= 2u);
            for (i = 0; i < s.person_count; i++) {
                const scansim_person *p = &s.people[i];
                uint32_t scan;
                assert_true(p->last_scan < s.pose_count);
                if (p->from_x_m == p->to_x_m && p->from_y_m == p->to_y_m &&
                    p->last_scan - p->first_scan >= 20u)
                    standing++;
                for (scan = p->first_scan; scan <= p->last_scan; scan++) {
                    double f = p->last_scan > p->first_scan
                                   ? (double)(scan - p->first_scan) /
                                         (double)(p->last_scan - p->first_scan)
                                   : 0.0;
                    double x = p->from_x_m + (p->to_x_m - p->from_x_m) * f;
                    double y = p->from_y_m + (p->to_y_m - p->from_y_m) * f;
                    assert_true(hypot(x - s.poses[scan].x_m, y - s.poses[scan].y_m) >
                                p->radius_m + 0.25);
                }
            }
            assert_true(standing >= 1u);
            /* another seed, another layout */
            if (seed > 0)
                assert_true(s.wall_point_count != prev_points || s.wall_xy_m[0] != prev_x);
            prev_points = s.wall_point_count;
            prev_x = s.wall_xy_m[0];
            scansim_scene_free(&s);
        }
    }
}

/* Every kind simulated (every 25th pose, seeds 0-2): the same seed gives the
 * same scans, walls and samples; another seed other walls; ideal and the
 * seen samples are there and most beams return. */
static void test_kinds_run(void **state)
{
    uint32_t k;
    uint64_t seed;
    (void)state;
    for (k = 0; k < KIND_COUNT; k++)
        for (seed = 0; seed < 3u; seed++) {
            scansim_scene a, b, c;
            size_t n;
            assert_int_equal(scansim_scene_builtin(&a, kinds[k], seed), 0);
            assert_int_equal(scansim_scene_builtin(&b, kinds[k], seed), 0);
            assert_int_equal(scansim_scene_builtin(&c, kinds[k], seed + 100u), 0);
            assert_int_equal(scansim_keep_every(&a, 25u), 0);
            assert_int_equal(scansim_keep_every(&b, 25u), 0);
            assert_int_equal(scansim_run(&a), 0);
            assert_int_equal(scansim_run(&b), 0);
            assert_true(a.scan_count >= 12u);
            assert_int_equal(a.wall_point_count, b.wall_point_count);
            assert_memory_equal(a.wall_xy_m, b.wall_xy_m, 2u * a.wall_point_count * sizeof(double));
            n = (size_t)a.scan_count * a.laser.beam_count;
            assert_memory_equal(a.range_m, b.range_m, n * sizeof(float));
            assert_int_equal(scansim_seen_count(&a), scansim_seen_count(&b));
            assert_true(c.wall_point_count != a.wall_point_count ||
                        memcmp(c.wall_xy_m, a.wall_xy_m,
                               2u * a.wall_point_count * sizeof(double)) != 0);
            assert_true(scansim_ideal_vertices(&a) > 0u);
            assert_true(scansim_seen_count(&a) > 0u);
            assert_true(a.hit_count > n / 2u);
            scansim_scene_free(&a);
            scansim_scene_free(&b);
            scansim_scene_free(&c);
        }
}

/* The hall's scanner: 361 beams over 180 degrees, 30 m; its 32-gon columns
 * seen all round count each corner in ideal. */
static void test_hall_scanner(void **state)
{
    scansim_scene s;
    uint32_t w, polygons = 0;
    (void)state;
    assert_int_equal(scansim_scene_builtin(&s, "hall", 4), 0);
    assert_int_equal(s.laser.beam_count, 361);
    assert_near(s.laser.max_range_m, 30.0, 1e-6);
    assert_near((double)s.laser.angle_step_rad * 360.0, 3.14159265358979323846, 1e-6);
    for (w = 0; w < s.wall_count; w++)
        polygons += s.walls[w].point_count == 32u;
    assert_true(polygons > 0u);
    scansim_scene_free(&s);
}

/* Segment k of the scene (scansim_segment_count order): x0 y0 x1 y1. */
static void segment_xy(const scansim_scene *s, uint32_t k, double *g)
{
    uint32_t w;
    for (w = 0; w < s->wall_count; w++) {
        const scansim_wall *wall = &s->walls[w];
        uint32_t n = wall->closed ? wall->point_count : wall->point_count - 1u;
        if (k < n) {
            const double *a = &s->wall_xy_m[2u * (wall->first_point + k)];
            const double *b = &s->wall_xy_m[2u * (wall->first_point + (k + 1u) % wall->point_count)];
            g[0] = a[0];
            g[1] = a[1];
            g[2] = b[0];
            g[3] = b[1];
            return;
        }
        k -= n;
    }
    fail_msg("no segment %u", (unsigned)k);
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

#define SPREAD_MIN_HITS 200u

/* The band of the endpoints around the true walls: every reflected beam
 * that the true pose sends to a wall segment puts its endpoint, as the
 * logged pose places it, at some signed distance from that segment's
 * line; per segment hit by SPREAD_MIN_HITS beams or more, the spread of
 * those distances (95th minus 5th percentile). Gives the largest spread
 * and the median over those segments. */
static void endpoint_spread(const scansim_scene *s, double *largest, double *median)
{
    uint32_t segs = scansim_segment_count(s), k, scan, i, used = 0;
    uint32_t *count = calloc(segs, sizeof *count), *fill = calloc(segs, sizeof *fill);
    double *spread = calloc(segs, sizeof *spread), **offset = calloc(segs, sizeof *offset);
    int32_t *hit = malloc((size_t)s->scan_count * s->laser.beam_count * sizeof *hit);
    assert_non_null(count);
    assert_non_null(fill);
    assert_non_null(spread);
    assert_non_null(offset);
    assert_non_null(hit);
    for (scan = 0; scan < s->scan_count; scan++) {
        const polyc_scan *sc = &s->scans[scan];
        const scansim_pose *p = &s->poses[scan];
        for (i = 0; i < sc->beam_count; i++) {
            int32_t *obj = &hit[(size_t)scan * sc->beam_count + i];
            double a = p->theta_rad + (double)sc->start_angle_rad +
                       (double)i * (double)sc->angle_step_rad;
            *obj = -1;
            if (sc->range_m[i] < sc->max_range_m)
                (void)scansim_cast(s, p->x_m, p->y_m, a, scan, obj);
            if (*obj >= 0)
                count[*obj]++;
        }
    }
    for (k = 0; k < segs; k++)
        if (count[k] >= SPREAD_MIN_HITS)
            assert_non_null(offset[k] = malloc(count[k] * sizeof(double)));
    for (scan = 0; scan < s->scan_count; scan++) {
        const polyc_scan *sc = &s->scans[scan];
        for (i = 0; i < sc->beam_count; i++) {
            int32_t obj = hit[(size_t)scan * sc->beam_count + i];
            double a = sc->pose_theta_rad + (double)sc->start_angle_rad +
                       (double)i * (double)sc->angle_step_rad, g[4] = {0.0, 0.0, 0.0, 0.0};
            double ex, ey, x, y;
            if (obj < 0 || !offset[obj])
                continue;
            segment_xy(s, (uint32_t)obj, g);
            ex = g[2] - g[0];
            ey = g[3] - g[1];
            x = sc->pose_x_m + (double)sc->range_m[i] * cos(a);
            y = sc->pose_y_m + (double)sc->range_m[i] * sin(a);
            offset[obj][fill[obj]++] = ((x - g[0]) * -ey + (y - g[1]) * ex) / hypot(ex, ey);
        }
    }
    for (k = 0; k < segs; k++) {
        if (!offset[k])
            continue;
        qsort(offset[k], count[k], sizeof(double), compare_double);
        spread[used++] = offset[k][count[k] * 95u / 100u] - offset[k][count[k] * 5u / 100u];
        free(offset[k]);
    }
    assert_true(used > 0u);
    qsort(spread, used, sizeof(double), compare_double);
    *largest = spread[used - 1u];
    *median = spread[used / 2u];
    free(count);
    free(fill);
    free(spread);
    free(offset);
    free(hit);
}

/* The drift kind (every 4th pose, seeds 1-2): the same seed gives the same
 * logged poses; the drift moves the logged poses only (the ranges and the
 * seen samples are those of the scene with the drift off); the endpoints of
 * the corridor walls, seen on three passes with different drift, spread
 * over a band: some wall over 8 cm wide and the median wall wider than
 * without the drift, which stays under 6 cm. */
static void test_drift_band(void **state)
{
    uint64_t seed;
    (void)state;
    for (seed = 1; seed <= 2u; seed++) {
        scansim_scene a, b, off;
        double largest, median, off_largest, off_median;
        size_t n;
        uint32_t i;
        assert_int_equal(scansim_scene_builtin(&a, "drift", seed), 0);
        assert_int_equal(scansim_scene_builtin(&b, "drift", seed), 0);
        assert_int_equal(scansim_scene_builtin(&off, "drift", seed), 0);
        assert_true(a.drift_m_per_m > 0.0 && a.drift_rad_per_m > 0.0 && a.drift_reset_m > 0.0);
        off.drift_m_per_m = off.drift_rad_per_m = 0.0;
        assert_int_equal(scansim_keep_every(&a, 4u), 0);
        assert_int_equal(scansim_keep_every(&b, 4u), 0);
        assert_int_equal(scansim_keep_every(&off, 4u), 0);
        assert_int_equal(scansim_run(&a), 0);
        assert_int_equal(scansim_run(&b), 0);
        assert_int_equal(scansim_run(&off), 0);
        n = (size_t)a.scan_count * a.laser.beam_count;
        assert_memory_equal(a.range_m, b.range_m, n * sizeof(float));
        assert_memory_equal(a.range_m, off.range_m, n * sizeof(float));
        assert_int_equal(scansim_seen_count(&a), scansim_seen_count(&off));
        assert_int_equal(scansim_ideal_vertices(&a), scansim_ideal_vertices(&off));
        for (i = 0; i < a.scan_count; i++) {
            assert_true(a.scans[i].pose_x_m == b.scans[i].pose_x_m);
            assert_true(a.scans[i].pose_y_m == b.scans[i].pose_y_m);
            assert_true(a.scans[i].pose_theta_rad == b.scans[i].pose_theta_rad);
        }
        assert_true(a.scans[a.scan_count - 1u].pose_x_m != off.scans[off.scan_count - 1u].pose_x_m);
        endpoint_spread(&a, &largest, &median);
        endpoint_spread(&off, &off_largest, &off_median);
        if (!(largest > 0.08 && median > off_median + 0.02 && off_largest < 0.06))
            fail_msg("drift seed %u: spread largest %.3f median %.3f, without drift %.3f %.3f",
                     (unsigned)seed, largest, median, off_largest, off_median);
        scansim_scene_free(&a);
        scansim_scene_free(&b);
        scansim_scene_free(&off);
    }
}

/* The drift model on a straight 20 m path (scansim.h): without a reset the
 * logged heading's error is a random walk and the position's error across
 * the path follows it (a turned step), so that it grows far beyond the
 * position's own walk; a reset every 2 m with keep 0 pulls every error
 * back to under one 2 m stretch's walk. The farhall kind is the hall of the
 * same seed with drift. */
static void test_drift_model(void **state)
{
    scansim_scene s, hall, far;
    static const double wall[] = {-1.0, 5.0, 21.0, 5.0};
    static const double path[] = {0.0, 0.0, 20.0, 0.0};
    double worst_heading = 0.0, worst_across = 0.0, along_sum = 0.0, across_sum = 0.0;
    uint32_t i;
    (void)state;
    scansim_scene_init(&s, "straight", 3);
    s.pose_sigma_m = s.pose_sigma_rad = 0.0;
    s.drift_rad_per_m = 0.5 * 3.14159265358979323846 / 180.0;
    assert_int_equal(scansim_add_wall(&s, wall, 2u, 0), 0);
    assert_int_equal(scansim_add_path(&s, path, 2u, 0.1), 0);
    assert_int_equal(scansim_run(&s), 0);
    for (i = 0; i < s.scan_count; i++) {
        double et = s.scans[i].pose_theta_rad - s.poses[i].theta_rad;
        /* position error across the path: the sum of the turned steps */
        assert_near(s.scans[i].pose_y_m, across_sum, 1e-5);
        assert_near(s.scans[i].pose_x_m, s.poses[i].x_m + along_sum, 1e-5);
        along_sum += 0.1 * (cos(et) - 1.0);
        across_sum += 0.1 * sin(et);
        worst_heading = fmax(worst_heading, fabs(et));
        worst_across = fmax(worst_across, fabs(s.scans[i].pose_y_m));
    }
    assert_true(worst_heading > 0.5 * 3.14159265358979323846 / 180.0);
    assert_true(worst_across > 0.03);
    s.drift_m_per_m = 0.01;
    s.drift_reset_m = 2.0;
    s.drift_keep = 0.0;
    assert_int_equal(scansim_run(&s), 0);
    for (i = 0; i < s.scan_count; i++)
        assert_true(fabs(s.scans[i].pose_theta_rad - s.poses[i].theta_rad) <
                    5.0 * 0.5 * 3.14159265358979323846 / 180.0 * sqrt(2.0));
    scansim_scene_free(&s);

    assert_int_equal(scansim_scene_builtin(&hall, "hall", 5), 0);
    assert_int_equal(scansim_scene_builtin(&far, "farhall", 5), 0);
    assert_int_equal(far.wall_point_count, hall.wall_point_count);
    assert_memory_equal(far.wall_xy_m, hall.wall_xy_m, 2u * hall.wall_point_count * sizeof(double));
    assert_int_equal(far.pose_count, hall.pose_count);
    assert_true(hall.drift_rad_per_m == 0.0 && far.drift_rad_per_m > 0.0);
    assert_near(far.laser.max_range_m, 30.0, 1e-6);
    scansim_scene_free(&hall);
    scansim_scene_free(&far);
}

/* Keeping every third pose keeps poses 0, 3, 6 and moves the people with
 * them. */
static void test_keep_every(void **state)
{
    scansim_scene s;
    scansim_person p;
    uint32_t i;
    (void)state;
    scansim_scene_init(&s, "thin", 1);
    for (i = 0; i < 8u; i++)
        assert_int_equal(scansim_add_pose(&s, (double)i, 0.0, 0.0), 0);
    memset(&p, 0, sizeof p);
    p.radius_m = 0.2;
    p.first_scan = 3u;
    p.last_scan = 7u;
    assert_int_equal(scansim_add_person(&s, &p), 0);
    assert_int_equal(scansim_keep_every(&s, 0u), -1);
    assert_int_equal(scansim_keep_every(&s, 3u), 0);
    assert_int_equal(s.pose_count, 3);
    assert_near(s.poses[1].x_m, 3.0, 0.0);
    assert_near(s.poses[2].x_m, 6.0, 0.0);
    assert_int_equal(s.people[0].first_scan, 1);
    assert_int_equal(s.people[0].last_scan, 2);
    scansim_scene_free(&s);
}

/* The clearance is the nearest approach of a pose to a wall segment. */
static void test_path_clearance(void **state)
{
    static const double wall[] = {0.0, 1.0, 4.0, 1.0};
    scansim_scene s;
    (void)state;
    scansim_scene_init(&s, "clear", 1);
    assert_true(isinf(scansim_path_clearance(&s)));
    assert_int_equal(scansim_add_wall(&s, wall, 2u, 0), 0);
    assert_int_equal(scansim_add_pose(&s, 2.0, 0.0, 0.0), 0);
    assert_int_equal(scansim_add_pose(&s, 5.0, 1.0, 0.0), 0);
    assert_int_equal(scansim_add_pose(&s, 1.0, 0.7, 0.0), 0);
    assert_near(scansim_path_clearance(&s), 0.3, 1e-12);
    scansim_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rng_reference),
        cmocka_unit_test(test_rng_gauss_moments),
        cmocka_unit_test(test_same_seed_same_ranges),
        cmocka_unit_test(test_perpendicular_beam),
        cmocka_unit_test(test_person_in_one_scan),
        cmocka_unit_test(test_dropout_and_max_range),
        cmocka_unit_test(test_builtins_sane),
        cmocka_unit_test(test_ideal_params),
        cmocka_unit_test(test_gt_round_trip),
        cmocka_unit_test(test_log_round_trip),
        cmocka_unit_test(test_path_spacing),
        cmocka_unit_test(test_kinds_layouts),
        cmocka_unit_test(test_kinds_run),
        cmocka_unit_test(test_hall_scanner),
        cmocka_unit_test(test_drift_band),
        cmocka_unit_test(test_drift_model),
        cmocka_unit_test(test_keep_every),
        cmocka_unit_test(test_path_clearance),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
