/* test_opt_merge.c - the BIC optimiser (paper section IV): operators A (overlaps) and B (merge) on hand-made maps.
 * The harness: tests/opt_harness.h. */
#include "opt_harness.h"

/* ---- A: overlaps ---- */

static void test_overlaps_trims_overlapping_end(void **state)
{
    (void)state;
    static fixture f;
    static ptlist p;
    open_straight_wall(&f, &p);
    /* A ends along B (both vertices of its last segment within 2 cm of B);
     * B's first segment is within 5 cm of A only at its head */
    const float a[6] = {-1.0f, 0.0f, 0.1f, 0.0f, 0.3f, 0.0f};
    const float b[6] = {0.0f, 0.02f, 0.2f, 0.02f, 1.0f, 0.02f};
    int32_t la = add_line(&f.o, a, 3, 0), lb = add_line(&f.o, b, 3, 0);
    rebuild(&f.o);
    assert_int_equal(polyc__op_overlaps(&f.o), 1);
    check_books(&f.o, "overlaps");
    assert_int_equal(f.o.s->l[la].count, 2);
    const polyc__vertex *t = &f.o.s->v[f.o.s->l[la].tail];
    assert_true(t->x == 0.1f && t->y == 0.0f);
    assert_int_equal(f.o.s->l[lb].count, 3);
    /* nothing overlaps any more */
    assert_int_equal(polyc__op_overlaps(&f.o), 0);
    fx_close(&f);
}

static void test_overlaps_leaves_separate_lines(void **state)
{
    (void)state;
    static fixture f;
    fx_open_hand(&f, 0.0f);
    clear_lines(&f.o);
    /* parallel lines 10 cm apart (overlap_m is 5 cm) */
    const float a[4] = {-1.0f, 0.0f, 1.0f, 0.0f};
    const float b[4] = {-1.0f, 0.1f, 1.0f, 0.1f};
    add_line(&f.o, a, 2, 0);
    add_line(&f.o, b, 2, 0);
    rebuild(&f.o);
    assert_int_equal(polyc__op_overlaps(&f.o), 0);
    assert_int_equal(f.o.s->v_live, 4);
    fx_close(&f);
}

static void test_overlaps_leaves_a_wall_between_two_lines(void **state)
{
    (void)state;
    static fixture f;
    fx_open_hand(&f, 0.0f);
    clear_lines(&f.o);
    /* a 1 m wall whose two ends touch two other walls (corners traced as
     * separate polylines): both of its vertices lie within overlap_m of
     * other polylines, but the stretch between them does not run along
     * any; it is not an overlap */
    const float left[4] = {-0.5f, -1.0f, -0.5f, 1.0f};
    const float right[4] = {0.52f, -1.0f, 0.52f, 1.0f};
    const float wall[4] = {-0.48f, 0.3f, 0.5f, 0.3f};
    add_line(&f.o, left, 2, 0);
    add_line(&f.o, right, 2, 0);
    int32_t lw = add_line(&f.o, wall, 2, 0);
    rebuild(&f.o);
    assert_int_equal(polyc__op_overlaps(&f.o), 0);
    assert_int_equal(f.o.s->l[lw].count, 2);
    assert_int_equal(f.o.s->v_live, 6);
    /* the same wall laid along the left one is an overlap: it loses an
     * end vertex, and no segment of it is left */
    clear_lines(&f.o);
    const float along[4] = {-0.48f, -0.6f, -0.48f, 0.4f};
    add_line(&f.o, left, 2, 0);
    int32_t la = add_line(&f.o, along, 2, 0);
    rebuild(&f.o);
    assert_int_equal(polyc__op_overlaps(&f.o), 1);
    check_books(&f.o, "overlaps along");
    assert_true(f.o.s->l[la].count < 2);
    fx_close(&f);
}

/* ---- B: merge ---- */

static void merge_case(fixture *f, const float *a, const float *b, int n)
{
    static ptlist p;
    p.n = 0;
    pts_line(&p, -1.0f, 0.0f, 1.0f, 0.0f, 0.02f);
    set_points(f, p.xy, p.n);
    clear_lines(&f->o);
    add_line(&f->o, a, n, 0);
    add_line(&f->o, b, n, 0);
    rebuild(&f->o);
}

static void test_merge_joins_ends_10cm_apart(void **state)
{
    (void)state;
    static fixture f;
    fx_open_hand(&f, 0.0f);
    const float a[4] = {-1.0f, 0.0f, -0.05f, 0.0f}, b[4] = {0.05f, 0.0f, 1.0f, 0.0f};
    const float joined[8] = {-1.0f, 0.0f, -0.05f, 0.0f, 0.05f, 0.0f, 1.0f, 0.0f};
    merge_case(&f, a, b, 2);
    double before = (double)polyc__bic(&f.o);
    assert_int_equal(polyc__op_merge(&f.o), 1);
    check_books(&f.o, "merge tail-head");
    assert_int_equal(live_lines(&f.o), 1);
    assert_line_is(&f.o, line_with_end(&f.o, -1.0f, 0.0f), joined, 4);
    assert_int_equal(f.o.s->l[line_with_end(&f.o, -1.0f, 0.0f)].closed, 0);
    assert_true((double)polyc__bic(&f.o) < before); /* the gap's points are explained */
    /* head to head and tail to tail: one polyline is turned round */
    const float ar[4] = {-0.05f, 0.0f, -1.0f, 0.0f}, br[4] = {1.0f, 0.0f, 0.05f, 0.0f};
    merge_case(&f, ar, b, 2);
    assert_int_equal(polyc__op_merge(&f.o), 1);
    check_books(&f.o, "merge head-head");
    assert_int_equal(live_lines(&f.o), 1);
    assert_line_is(&f.o, line_with_end(&f.o, -1.0f, 0.0f), joined, 4);
    merge_case(&f, a, br, 2);
    assert_int_equal(polyc__op_merge(&f.o), 1);
    check_books(&f.o, "merge tail-tail");
    assert_int_equal(live_lines(&f.o), 1);
    assert_line_is(&f.o, line_with_end(&f.o, -1.0f, 0.0f), joined, 4);
    fx_close(&f);
}

static void test_merge_leaves_ends_30cm_apart(void **state)
{
    (void)state;
    static fixture f;
    fx_open_hand(&f, 0.0f);
    const float a[4] = {-1.0f, 0.0f, -0.15f, 0.0f}, b[4] = {0.15f, 0.0f, 1.0f, 0.0f};
    merge_case(&f, a, b, 2);
    assert_int_equal(polyc__op_merge(&f.o), 0);
    assert_int_equal(live_lines(&f.o), 2);
    assert_int_equal(f.o.s->v_live, 4);
    check_books(&f.o, "no merge");
    fx_close(&f);
}

static void test_merge_closes_polyline(void **state)
{
    (void)state;
    static fixture f;
    static ptlist p;
    fx_open_hand(&f, 0.0f);
    /* a square of 1 m, open at the middle of its bottom side by 10 cm */
    const float sq[12] = {0.05f, -0.5f, 0.5f, -0.5f, 0.5f, 0.5f, -0.5f, 0.5f, -0.5f, -0.5f, -0.05f, -0.5f};
    p.n = 0;
    for (int k = 0; k < 4; k++)
        pts_line(&p, sq[2 + 2 * k], sq[3 + 2 * k], sq[(4 + 2 * k) % 10], sq[(5 + 2 * k) % 10], 0.02f);
    set_points(&f, p.xy, p.n);
    clear_lines(&f.o);
    int32_t l = add_line(&f.o, sq, 6, 0);
    rebuild(&f.o);
    assert_int_equal(polyc__op_merge(&f.o), 1);
    check_books(&f.o, "merge closes");
    assert_int_equal(live_lines(&f.o), 1);
    assert_int_equal(f.o.s->l[l].closed, 1);
    assert_int_equal(f.o.s->l[l].count, 6);
    assert_int_equal(polyc__op_merge(&f.o), 0);
    fx_close(&f);
}

/* Two pieces of a band leaving nearly the same point in nearly one
 * direction (the online round's case: a link there makes a hairpin that
 * no zigzag or zip after it judges): op_merge links them, op_merge_folds
 * without folds does not, and still links a wall's two pieces end to end
 * or at a corner. */
static void test_merge_without_folds(void **state)
{
    (void)state;
    static fixture f;
    fx_open_hand(&f, 0.0f);
    /* from ends 4 cm apart, 10 degrees between the pieces */
    const float a[4] = {0.0f, 0.0f, 1.0f, 0.0f}, b[4] = {0.0f, 0.04f, 0.985f, 0.2137f};
    merge_case(&f, a, b, 2);
    assert_int_equal(polyc__op_merge_folds(&f.o, POLYC__HAIRPINS_REFUSED), 0);
    assert_int_equal(live_lines(&f.o), 2);
    assert_int_equal(polyc__op_merge(&f.o), 1);
    assert_int_equal(live_lines(&f.o), 1);
    /* end to end */
    const float c[4] = {-1.0f, 0.0f, -0.05f, 0.0f}, d[4] = {0.05f, 0.0f, 1.0f, 0.0f};
    merge_case(&f, c, d, 2);
    assert_int_equal(polyc__op_merge_folds(&f.o, POLYC__HAIRPINS_REFUSED), 1);
    check_books(&f.o, "merge without folds");
    assert_int_equal(live_lines(&f.o), 1);
    /* a corner: 90 degrees */
    const float e[4] = {-1.0f, 0.0f, -0.05f, 0.0f}, g[4] = {0.0f, 0.05f, 0.0f, 1.0f};
    merge_case(&f, e, g, 2);
    assert_int_equal(polyc__op_merge_folds(&f.o, POLYC__HAIRPINS_REFUSED), 1);
    assert_int_equal(live_lines(&f.o), 1);
    fx_close(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_overlaps_trims_overlapping_end),
        cmocka_unit_test(test_overlaps_leaves_separate_lines),
        cmocka_unit_test(test_overlaps_leaves_a_wall_between_two_lines),
        cmocka_unit_test(test_merge_joins_ends_10cm_apart),
        cmocka_unit_test(test_merge_leaves_ends_30cm_apart),
        cmocka_unit_test(test_merge_closes_polyline),
        cmocka_unit_test(test_merge_without_folds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
