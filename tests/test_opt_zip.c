/* test_opt_zip.c - the BIC optimiser (paper section IV): the topology operators: crossings untangled, double cover zipped, a
 * spike past a corner removed.
 * The harness: tests/opt_harness.h. */
#include "opt_harness.h"

/* ---- topology (topology.c, and the support rule of split) ---- */

/* crossings of live segments that share no vertex, more than 1 cm from
 * their ends, brute force */
static int brute_crossings(const polyc__opt *o)
{
    const polyc__vertex *V = o->s->v;
    int n = 0;
    for (int32_t a = 0; a < o->s->v_high; a++) {
        if (!seg_live(o, a))
            continue;
        for (int32_t b = a + 1; b < o->s->v_high; b++) {
            if (!seg_live(o, b))
                continue;
            int32_t an = V[a].next, bn = V[b].next;
            if (a == bn || an == b || an == bn)
                continue;
            double rx = (double)(V[an].x - V[a].x), ry = (double)(V[an].y - V[a].y);
            double sx = (double)(V[bn].x - V[b].x), sy = (double)(V[bn].y - V[b].y);
            double den = rx * sy - ry * sx;
            if (den == 0.0)
                continue;
            double wx = (double)(V[b].x - V[a].x), wy = (double)(V[b].y - V[a].y);
            double t = (wx * sy - wy * sx) / den, u = (wx * ry - wy * rx) / den;
            double lr = sqrt(rx * rx + ry * ry), ls = sqrt(sx * sx + sy * sy);
            if (t * lr > 0.01 && (1 - t) * lr > 0.01 && u * ls > 0.01 && (1 - u) * ls > 0.01)
                n++;
        }
    }
    return n;
}

/* The hand case's data (n points, each seen from its seen_xy) and two
 * polylines, a (na points) and b (nb), in place of the room's. */
static void two_lines_case(fixture *f, const float *xy, const float *seen, int n, const float *a,
                           int na, const float *b, int nb)
{
    set_points_seen(f, xy, seen, n);
    clear_lines(&f->o);
    add_line(&f->o, a, na, 0);
    add_line(&f->o, b, nb, 0);
    rebuild(&f->o);
}

/* Two polylines along y = 0 and y = gap with their data; the points of the
 * second are seen from above (y = 2) and those of the first from below
 * (y = -2); with `sides` SAME_SIDE from above too; with MIXED 3 in 5 of
 * each line's points as said and 2 in 5 from the other side. */
enum { OWN_SIDES, SAME_SIDE, MIXED };
static void parallel_case(fixture *f, float gap, int sides)
{
    static ptlist p;
    static float seen[2 * MAX_PTS];
    p.n = 0;
    pts_line(&p, -1.0f, 0.0f, 1.0f, 0.0f, 0.02f);
    int first = p.n;
    pts_line(&p, -1.0f, gap, 1.0f, gap, 0.02f);
    for (int i = 0; i < p.n; i++) {
        int k = i < first ? i : i - first;
        int below = i < first && sides != SAME_SIDE;
        if (sides == MIXED && k % 5 >= 3)
            below = !below;
        seen[2 * i] = p.xy[2 * i];
        seen[2 * i + 1] = below ? -2.0f : 2.0f;
    }
    const float a[4] = {-1.0f, 0.0f, 1.0f, 0.0f}, b[4] = {-1.0f, gap, 1.0f, gap};
    two_lines_case(f, p.xy, seen, p.n, a, 2, b, 2);
}

/* The parallel case zips to one line, left whole, and a second zip finds
 * nothing. */
static void check_zipped_to_one(float gap, int sides, const char *what)
{
    static fixture f;
    fx_open_hand(&f, 0.0f);
    parallel_case(&f, gap, sides);
    assert_true(polyc__op_zip(&f.o) >= 1);
    check_books(&f.o, what);
    assert_int_equal(live_lines(&f.o), 1);
    assert_int_equal(f.o.s->v_live, 2);
    assert_int_equal(polyc__op_zip(&f.o), 0);
    fx_close(&f);
}

/* Two polylines 3 cm apart along one wall (its data a band between them):
 * one of them goes, the other is left whole. */
static void test_zip_parallel_lines_become_one(void **state)
{
    (void)state;
    check_zipped_to_one(0.03f, OWN_SIDES, "zip");
}

/* The two faces of a wall 10 cm thick, each seen from its own side, are two
 * lines: nothing is zipped. */
/* The parallel case is left as it is: two lines, nothing zipped. */
static void check_left_as_two(float gap, int sides)
{
    static fixture f;
    fx_open_hand(&f, 0.0f);
    parallel_case(&f, gap, sides);
    assert_int_equal(polyc__op_zip(&f.o), 0);
    assert_int_equal(live_lines(&f.o), 2);
    fx_close(&f);
}

static void test_zip_leaves_walls_10cm_apart(void **state)
{
    (void)state;
    check_left_as_two(0.10f, OWN_SIDES);
}

/* Two lines 10 and 18 cm apart, both seen from the same side, are one wall
 * seen as a band (a laser does not see a wall through another): one goes,
 * the other is left whole. 25 cm apart they are two. */
static void test_zip_same_side_band(void **state)
{
    (void)state;
    const float gaps[2] = {0.10f, 0.18f};
    for (int k = 0; k < 2; k++)
        check_zipped_to_one(gaps[k], SAME_SIDE, "band zip");
    check_left_as_two(0.25f, SAME_SIDE);
}

/* Two polylines 8 cm apart along one thin wall seen from both sides
 * through a band of pose error (its two sides' returns mixed over the
 * band): the lower line's points are seen 3 in 5 from below and 2 in 5 from
 * above, the upper line's the other way round. Their sides are opposite,
 * as two faces' would be, but both are seen from both sides: one goes.
 * (test_zip_leaves_walls_10cm_apart: each face seen only from its own side
 * stays.) */
static void test_zip_two_sided_band(void **state)
{
    (void)state;
    check_zipped_to_one(0.08f, MIXED, "two-sided band zip");
}

/* A T junction: polyline B runs up a stem to (0, 0) and on along the wall
 * y = 0; polyline A comes along the wall from the left and runs `over` past
 * the junction, along B. Wall points are seen from below (y = -2), the
 * stem's from its right; A is seen from above (y = +2) when a_above (then
 * it is the other face of a partition 4.5 cm thick: a_y = 0.045). */
static void t_case(fixture *f, float over, float a_y, int a_above)
{
    static ptlist p;
    static float seen[2 * MAX_PTS];
    p.n = 0;
    pts_line(&p, -1.0f, 0.0f, 1.0f, 0.0f, 0.02f);
    int wall = p.n;
    pts_line(&p, 0.0f, -1.0f, 0.0f, -0.04f, 0.02f);
    int stem = p.n;
    if (a_above)
        pts_line(&p, -1.0f, a_y, 0.0f, a_y, 0.02f);
    for (int i = 0; i < p.n; i++) {
        seen[2 * i] = i < wall ? p.xy[2 * i] : i < stem ? 2.0f : p.xy[2 * i];
        seen[2 * i + 1] = i < wall ? -2.0f : i < stem ? p.xy[2 * i + 1] : 2.0f;
    }
    const float a[4] = {-1.0f, a_y, over, a_y}, b[6] = {0.0f, -1.0f, 0.0f, 0.0f, 1.0f, 0.0f};
    two_lines_case(f, p.xy, seen, p.n, a, 2, b, 3);
}

/* An end 11 cm past a T junction, along the other polyline and seen from
 * the same side (too short a stretch for the zip's runs) is pulled back to
 * the junction; the other polyline is left as it was. One that ends at the
 * junction stays. */
static void test_zip_end_past_t_junction(void **state)
{
    (void)state;
    static fixture f;
    const float overs[2] = {0.11f, 0.0f};
    for (int k = 0; k < 2; k++) {
        fx_open_hand(&f, 0.0f);
        t_case(&f, overs[k], 0.0f, 0);
        polyc__op_zip(&f.o);
        check_books(&f.o, "end past a T junction");
        assert_int_equal(live_lines(&f.o), 2);
        assert_int_equal(f.o.s->v_live, 5);
        assert_true(line_with_end(&f.o, -1.0f, 0.0f) != POLYC__NONE);
        assert_true(nearest_vertex(&f.o, 1.0f, 0.0f) < 1e-4f);
        assert_true(nearest_vertex(&f.o, 0.0f, 0.0f) < 1e-4f);
        /* A's other end: at the junction, within a centimetre */
        const polyc__line *ln = &f.o.s->l[line_with_end(&f.o, -1.0f, 0.0f)];
        int32_t e = f.o.s->v[ln->head].x < -0.5f ? ln->tail : ln->head;
        assert_true(fabsf(f.o.s->v[e].x) <= 0.01f);
        assert_true(fabsf(f.o.s->v[e].y) <= 1e-4f);
        fx_close(&f);
    }
    /* the other face of a partition 4.5 cm thick, seen from above: stays */
    fx_open_hand(&f, 0.0f);
    t_case(&f, 0.11f, 0.045f, 1);
    polyc__op_zip(&f.o);
    assert_int_equal(live_lines(&f.o), 2);
    assert_true(nearest_vertex(&f.o, 0.11f, 0.045f) < 1e-4f);
    fx_close(&f);
}

/* An X of two polylines, each wall seen on both sides of the crossing
 * except the second below the first: the second's overshoot goes, the
 * first is left whole, no crossing remains. */
static void test_untangle_resolves_x(void **state)
{
    (void)state;
    static fixture f;
    static ptlist p;
    fx_open_hand(&f, 0.0f);
    p.n = 0;
    pts_line(&p, -1.0f, 0.0f, 1.0f, 0.0f, 0.02f);
    pts_line(&p, 0.0f, 0.02f, 0.0f, 1.0f, 0.02f);
    set_points(&f, p.xy, p.n);
    clear_lines(&f.o);
    const float a[4] = {-1.0f, 0.0f, 1.0f, 0.0f}, b[4] = {0.0f, -0.4f, 0.0f, 1.0f};
    int32_t la = add_line(&f.o, a, 2, 0);
    add_line(&f.o, b, 2, 0);
    rebuild(&f.o);
    assert_int_equal(brute_crossings(&f.o), 1);
    assert_int_equal(polyc__op_untangle(&f.o), 1);
    check_books(&f.o, "untangle");
    assert_int_equal(brute_crossings(&f.o), 0);
    assert_line_is(&f.o, la, a, 2);
    /* the second wall now ends just short of the first */
    assert_true(nearest_vertex(&f.o, 0.0f, 0.0f) < 0.01f);
    assert_int_equal(f.o.s->v_live, 4);
    assert_int_equal(polyc__op_untangle(&f.o), 0);
    fx_close(&f);
}

/* A hairpin that explains scattered points passes through a wall: the
 * cheapest way out is found and no crossing remains; a merge does not
 * link two ends through a wall. */
static void test_untangle_hairpin_through_wall(void **state)
{
    (void)state;
    static fixture f;
    static ptlist p;
    fx_open_hand(&f, 0.0f);
    p.n = 0;
    pts_line(&p, -1.0f, 0.0f, 1.0f, 0.0f, 0.02f);  /* the wall */
    pts_line(&p, -1.0f, 0.5f, 0.0f, 0.5f, 0.02f);  /* a wall above it */
    pts_line(&p, 0.3f, -0.3f, 0.35f, -0.3f, 0.02f); /* clutter below */
    set_points(&f, p.xy, p.n);
    clear_lines(&f.o);
    const float wall[4] = {-1.0f, 0.0f, 1.0f, 0.0f};
    const float hair[8] = {-1.0f, 0.5f, 0.0f, 0.5f, 0.32f, -0.3f, 0.1f, 0.45f};
    add_line(&f.o, wall, 2, 0);
    add_line(&f.o, hair, 4, 0);
    rebuild(&f.o);
    assert_true(brute_crossings(&f.o) >= 2);
    assert_true(polyc__op_untangle(&f.o) >= 1);
    check_books(&f.o, "untangle hairpin");
    assert_int_equal(brute_crossings(&f.o), 0);
    /* two ends on either side of the wall are not linked across it */
    clear_lines(&f.o);
    const float up[4] = {0.5f, 0.6f, 0.5f, 0.04f}, down[4] = {0.52f, -0.04f, 0.52f, -0.6f};
    add_line(&f.o, wall, 2, 0);
    add_line(&f.o, up, 2, 0);
    add_line(&f.o, down, 2, 0);
    rebuild(&f.o);
    polyc__op_merge(&f.o);
    check_books(&f.o, "merge");
    assert_int_equal(brute_crossings(&f.o), 0);
    assert_int_equal(live_lines(&f.o), 3);
    fx_close(&f);
}

/* A spike 28 cm past an L corner (as vertex moves leave it): the map ends
 * up on the data, no stretch of it without data over 10 cm. */
static void test_spike_past_corner_removed(void **state)
{
    (void)state;
    static fixture f;
    static ptlist p;
    fx_open_hand(&f, 0.0f);
    p.n = 0;
    pts_line(&p, -1.0f, 0.0f, 0.0f, 0.0f, 0.01f);
    pts_line(&p, 0.0f, 0.01f, 0.0f, 1.0f, 0.01f);
    set_points(&f, p.xy, p.n);
    clear_lines(&f.o);
    const float xy[8] = {-1.0f, 0.0f, 0.28f, -0.01f, 0.0f, 0.05f, 0.0f, 1.0f};
    add_line(&f.o, xy, 4, 0);
    rebuild(&f.o);
    assert_true(longest_unsupported(&f.o) > 0.2);
    for (int round = 0; round < 3; round++) {
        polyc__op_split(&f.o);
        polyc__op_zigzag(&f.o);
        polyc__op_corners(&f.o, 0);
        polyc__op_adjust(&f.o, 4, 0);
        polyc__op_trim_ends(&f.o);
        polyc__op_merge(&f.o);
        polyc__op_remove_vertices(&f.o, 0);
    }
    check_books(&f.o, "spike");
    assert_true(longest_unsupported(&f.o) < 0.1);
    assert_true(nearest_vertex(&f.o, 0.0f, 0.0f) < 0.03f);
    assert_int_equal(brute_crossings(&f.o), 0);
    fx_close(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_zip_parallel_lines_become_one),
        cmocka_unit_test(test_zip_leaves_walls_10cm_apart),
        cmocka_unit_test(test_zip_same_side_band),
        cmocka_unit_test(test_zip_end_past_t_junction),
        cmocka_unit_test(test_zip_two_sided_band),
        cmocka_unit_test(test_untangle_resolves_x),
        cmocka_unit_test(test_untangle_hairpin_through_wall),
        cmocka_unit_test(test_spike_past_corner_removed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
