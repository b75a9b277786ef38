/* test_opt_moves.c - the BIC optimiser (paper section IV): vertex moves (D), zigzags (E), noise (F), vertex removal and addition
 * (G), corners, and one scan's beams as constraints.
 * The harness: tests/opt_harness.h. */
#include "opt_harness.h"

/* ---- D: hill climbing ---- */

/* L-shaped walls meeting at the origin, 1 cm point spacing */
static void corner_points(fixture *f, int with_corner)
{
    static ptlist p;
    p.n = 0;
    pts_line(&p, -1.0f, 0.0f, with_corner ? 0.0f : -0.01f, 0.0f, 0.01f);
    pts_line(&p, 0.0f, with_corner ? 0.0f : 0.01f, 0.0f, 1.0f, 0.01f);
    set_points(f, p.xy, p.n);
}

static void test_hill_climb_returns_to_corner(void **state)
{
    (void)state;
    static fixture f;
    static const float start[3][2] = {{0.03f, 0.0f}, {0.0212f, -0.0212f}, {-0.03f, 0.0f}};
    fx_open_hand(&f, 0.0f);
    for (int c = 0; c < 3; c++) {
        corner_points(&f, 1);
        clear_lines(&f.o);
        const float xy[6] = {-1.0f, 0.0f, start[c][0], start[c][1], 0.0f, 1.0f};
        add_line(&f.o, xy, 3, 0);
        rebuild(&f.o);
        double bic = (double)polyc__bic(&f.o);
        for (int round = 0; round < 20; round++) {
            int moved = 0;
            for (int32_t v = 0; v < 3; v++) {
                moved += polyc__hill_climb(&f.o, v);
                double now = (double)polyc__bic(&f.o);
                if (now > bic + FLOAT_REL * fabs(bic))
                    fail_msg("start %d: the BIC rose from %.9f to %.9f", c, bic, now);
                bic = now;
            }
            check_books(&f.o, "hill climbing");
            if (!moved)
                break;
        }
        const polyc__vertex *m = &f.o.s->v[1];
        float d = sqrtf(m->x * m->x + m->y * m->y);
        if (d > 0.01f)
            fail_msg("start %d: the corner vertex stopped at (%.4f, %.4f), %.1f mm away", c,
                     (double)m->x, (double)m->y, 1e3 * (double)d);
    }
    fx_close(&f);
}

static void test_adjust_never_raises_bic(void **state)
{
    (void)state;
    static fixture f;
    fx_open(&f, 0.02f, 0.002f, 0);
    polyc__rng r = {5};
    make_start_map(&f.o, &r);
    for (int k = 0; k < 3; k++) {
        polyc__op_noise(&f.o, 0.02f);
        rebuild(&f.o);
        double before = (double)polyc__bic(&f.o);
        for (int round = 0; round < 6; round++) {
            polyc__op_adjust(&f.o, 1, 0);
            double now = (double)polyc__bic(&f.o);
            if (now > before + FLOAT_REL * fabs(before))
                fail_msg("adjust raised the BIC from %.9f to %.9f", before, now);
            before = now;
        }
        check_books(&f.o, "adjust");
        assert_true(close_rel((double)polyc__bic(&f.o), scratch_bic(&f.o), FLOAT_REL));
    }
    fx_close(&f);
}

/* The operators that check the BIC before they change the map (D, E, G,
 * corners) never raise it; checked on noisy random maps, both gammas. */
static void test_bic_checked_operators_never_raise_bic(void **state)
{
    (void)state;
    static fixture f;
    static const char *const names[5] = {"adjust", "zigzag", "corners", "remove_vertices",
                                         "add_vertices"};
    for (int run = 0; run < 4; run++) {
        fx_open(&f, run % 2 ? 0.5f : 0.0f, 0.002f, 0);
        polyc__rng r = {(uint64_t)(100 + run)};
        make_start_map(&f.o, &r);
        polyc__op_noise(&f.o, 0.03f);
        rebuild(&f.o);
        for (int round = 0; round < 4; round++) {
            for (int op = 0; op < 5; op++) {
                double before = (double)polyc__bic(&f.o);
                switch (op) {
                case 0: polyc__op_adjust(&f.o, 3, 0); break;
                case 1: polyc__op_zigzag(&f.o); break;
                case 2: polyc__op_corners(&f.o, 0); break;
                case 3: polyc__op_remove_vertices(&f.o, 0); break;
                default: polyc__op_add_vertices(&f.o, 2); break;
                }
                double after = (double)polyc__bic(&f.o);
                if (after > before + FLOAT_REL * fabs(before))
                    fail_msg("run %d round %d: %s raised the BIC from %.9f to %.9f", run, round,
                             names[op], before, after);
            }
            check_books(&f.o, "BIC-checked operators");
        }
        fx_close(&f);
    }
}

/* ---- E: zigzag ---- */

static void test_zigzag_removes_hairpin(void **state)
{
    (void)state;
    static fixture f;
    static ptlist p;
    open_straight_wall(&f, &p);
    /* a spike 40 cm out of a straight wall: its tip turns by 177 degrees */
    const float xy[10] = {-1.0f, 0.0f, 0.0f, 0.0f, 0.02f, 0.4f, 0.04f, 0.0f, 1.0f, 0.0f};
    const float after[8] = {-1.0f, 0.0f, 0.0f, 0.0f, 0.04f, 0.0f, 1.0f, 0.0f};
    int32_t l = add_line(&f.o, xy, 5, 0);
    rebuild(&f.o);
    assert_int_equal(polyc__op_zigzag(&f.o), 1);
    check_books(&f.o, "zigzag");
    assert_line_is(&f.o, l, after, 4);
    assert_int_equal(polyc__op_zigzag(&f.o), 0);
    fx_close(&f);
}

/* A hand-made case: data along the two walls (x0, y0, x1, y1 each) and
 * the polyline xy of n points over them, scored; returns its line. */
static int32_t two_walls_case(fixture *f, ptlist *p, const float *walls, const float *xy, int n)
{
    fx_open_hand(f, 0.0f);
    p->n = 0;
    pts_line(p, walls[0], walls[1], walls[2], walls[3], 0.01f);
    pts_line(p, walls[4], walls[5], walls[6], walls[7], 0.01f);
    set_points(f, p->xy, p->n);
    clear_lines(&f->o);
    int32_t l = add_line(&f->o, xy, n, 0);
    rebuild(&f->o);
    return l;
}

static void test_zigzag_keeps_sharp_corner_with_data(void **state)
{
    (void)state;
    static fixture f;
    static ptlist p;
    /* two walls meeting at 15 degrees: the tip turns by 165 degrees */
    const float xy[6] = {-1.0f, 0.1317f, 0.0f, 0.0f, -1.0f, -0.1317f};
    const float walls[8] = {xy[0], xy[1], xy[2], xy[3], xy[2], xy[3], xy[4], xy[5]};
    int32_t l = two_walls_case(&f, &p, walls, xy, 3);
    assert_int_equal(polyc__op_zigzag(&f.o), 0);
    assert_line_is(&f.o, l, xy, 3);
    fx_close(&f);
}

/* A wall drawn 14 cm past its corner and back (acapulco's batch map): a
 * fold whose short leg lies on the long one. The data along the overshoot
 * keep it through zigzag's BIC test; op_unfold takes it out whatever the
 * BIC, leaving a corner and no fold. */
static void test_unfold_corner_overshoot(void **state)
{
    (void)state;
    static fixture f;
    static ptlist p;
    /* the data along its first and last segments */
    const float xy[8] = {0.0f, 0.0f, 0.0f, 2.14f, 0.0f, 2.0f, 2.0f, 2.0f};
    int32_t l = two_walls_case(&f, &p, xy, xy, 4);
    assert_int_equal(polyc__op_zigzag(&f.o), 0); /* the BIC keeps it */
    assert_int_equal(polyc__op_unfold(&f.o), 1);
    check_books(&f.o, "unfold");
    const polyc__store *s = f.o.s;
    assert_int_equal(s->l[l].count, 3);
    int32_t a = s->l[l].head, c = s->v[a].next, b = s->v[c].next;
    float ux = s->v[c].x - s->v[a].x, uy = s->v[c].y - s->v[a].y;
    float wx = s->v[b].x - s->v[c].x, wy = s->v[b].y - s->v[c].y;
    assert_true(fabsf(ux * wx + uy * wy) < 0.2f * sqrtf((ux * ux + uy * uy) * (wx * wx + wy * wy)));
    assert_int_equal(polyc__op_unfold(&f.o), 0);
    fx_close(&f);
}

/* A band's two faces drawn as one polyline that turns back through two
 * vertices 3 cm apart (an online map of freiburg-079: legs of 37 and 46 cm
 * within 5 cm of each other, counted as double cover): op_unfold takes one
 * of the two vertices and then the fold, whatever the BIC, and leaves no
 * stretch drawn twice. */
static void test_unfold_two_vertex_hairpin(void **state)
{
    (void)state;
    static fixture f;
    static ptlist p;
    const float xy[8] = {0.0f, 0.0f, 0.46f, 0.0f, 0.46f, 0.03f, 0.09f, 0.03f};
    int32_t l = two_walls_case(&f, &p, xy, xy, 4); /* (the two faces' data) */
    assert_true(polyc__op_unfold(&f.o) >= 2); /* (zigzag: no single vertex folds) */
    check_books(&f.o, "unfold two-vertex hairpin");
    assert_int_equal(f.o.s->l[l].count, 2);
    assert_int_equal(polyc__op_unfold(&f.o), 0);
    fx_close(&f);
}

/* A thin wall's end drawn round (two 1 m faces 6 cm apart) folds on two
 * long legs: it is a wall's two faces, not one face twice, and stays. */
static void test_unfold_keeps_thin_wall_end(void **state)
{
    (void)state;
    static fixture f;
    static ptlist p;
    const float walls[8] = {0.0f, 0.0f, 1.0f, 0.0f, 1.0f, 0.06f, 0.0f, 0.06f};
    const float xy[6] = {0.0f, 0.0f, 1.0f, 0.03f, 0.0f, 0.06f};
    int32_t l = two_walls_case(&f, &p, walls, xy, 3);
    assert_int_equal(polyc__op_unfold(&f.o), 0);
    assert_line_is(&f.o, l, xy, 3);
    fx_close(&f);
}

/* ---- F: noise ---- */

static void test_noise_deterministic_and_sized(void **state)
{
    (void)state;
    static fixture f;
    static float x0[2 * 400], x1[2 * 400];
    fx_open(&f, 0.0f, 0.002f, 0);
    polyc__rng r = {9};
    make_start_map(&f.o, &r);
    polyc__flat_from_store(&f.o.best, f.o.s);
    int32_t n = f.o.s->v_high;
    assert_true(n <= 400 && f.o.s->v_live == n);
    for (int32_t v = 0; v < n; v++) {
        x0[2 * v] = f.o.s->v[v].x;
        x0[2 * v + 1] = f.o.s->v[v].y;
    }
    const double sigma = 0.05;
    for (int run = 0; run < 3; run++) {
        check_st(polyc__store_from_flat(f.o.s, &f.o.best), f.ctx, "restore");
        f.o.rng.state = run < 2 ? 77 : 78;
        polyc__op_noise(&f.o, (float)sigma);
        double sx = 0.0, sxx = 0.0;
        int same = 1;
        for (int32_t v = 0; v < n; v++) {
            double dx = (double)f.o.s->v[v].x - (double)x0[2 * v];
            double dy = (double)f.o.s->v[v].y - (double)x0[2 * v + 1];
            sx += dx + dy;
            sxx += dx * dx + dy * dy;
            if (run == 1)
                same &= f.o.s->v[v].x == x1[2 * v] && f.o.s->v[v].y == x1[2 * v + 1];
            if (run == 2)
                same &= f.o.s->v[v].x == x1[2 * v] && f.o.s->v[v].y == x1[2 * v + 1];
            if (run == 0) {
                x1[2 * v] = f.o.s->v[v].x;
                x1[2 * v + 1] = f.o.s->v[v].y;
            }
        }
        double mean = sx / (2.0 * n), rms = sqrt(sxx / (2.0 * n));
        /* 2n ~ 340 normal samples: the std-dev within 15 %, the mean near 0 */
        if (fabs(rms - sigma) > 0.15 * sigma || fabs(mean) > 0.2 * sigma)
            fail_msg("run %d: displacement rms %.4f mean %.4f for sigma %.3f", run, rms, mean, sigma);
        if (run == 1)
            assert_true(same);  /* same seed, same map */
        if (run == 2)
            assert_false(same); /* another seed, another map */
        rebuild(&f.o);          /* the caller rebuilds after noise */
        check_books(&f.o, "noise + rebuild");
    }
    fx_close(&f);
}

/* ---- G: model size ---- */

static void test_remove_collinear_vertex(void **state)
{
    (void)state;
    static fixture f;
    static ptlist p;
    open_straight_wall(&f, &p);
    const float xy[6] = {-1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f}, after[4] = {-1.0f, 0.0f, 1.0f, 0.0f};
    int32_t l = add_line(&f.o, xy, 3, 0);
    rebuild(&f.o);
    double d = (double)polyc__removal_delta_below(&f.o, 1, INFINITY);
    assert_true(fabs(d + (double)f.o.d.log_n) < FLOAT_REL * (double)f.o.d.log_n); /* no error change, one vertex less */
    assert_int_equal(polyc__op_remove_vertices(&f.o, 0), 1);
    check_books(&f.o, "remove");
    assert_line_is(&f.o, l, after, 2);
    fx_close(&f);
}

/* The corner's points (corner_points) mapped by the exact L through them:
 * (-1, 0), (0, 0), (0, 1); returns its line. */
static const float L_CORNER[6] = {-1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f};
static int32_t open_exact_corner(fixture *f)
{
    fx_open_hand(f, 0.0f);
    corner_points(f, 1);
    clear_lines(&f->o);
    int32_t l = add_line(&f->o, L_CORNER, 3, 0);
    rebuild(&f->o);
    return l;
}

static void test_remove_keeps_true_corner(void **state)
{
    (void)state;
    static fixture f;
    int32_t l = open_exact_corner(&f);
    assert_true(polyc__removal_delta_below(&f.o, 1, INFINITY) > 0.0f);
    assert_int_equal(polyc__op_remove_vertices(&f.o, 0), 0);
    assert_line_is(&f.o, l, L_CORNER, 3);
    fx_close(&f);
}

static void test_add_vertex_at_cut_corner(void **state)
{
    (void)state;
    static fixture f;
    fx_open_hand(&f, 0.0f);
    corner_points(&f, 1);
    clear_lines(&f.o);
    /* a chamfer 20 cm from the corner along each wall: the corner is 14 cm
     * from it, the farthest point of the worst segment */
    const float xy[8] = {-1.0f, 0.0f, -0.2f, 0.0f, 0.0f, 0.2f, 0.0f, 1.0f};
    add_line(&f.o, xy, 4, 0);
    rebuild(&f.o);
    double before = (double)polyc__bic(&f.o);
    assert_true(polyc__op_add_vertices(&f.o, 1) >= 1);
    check_books(&f.o, "add");
    assert_true((double)polyc__bic(&f.o) < before);
    assert_int_equal(f.o.s->v_live, 5);
    float d = nearest_vertex(&f.o, 0.0f, 0.0f);
    if (d > 0.01f)
        fail_msg("no vertex within 1 cm of the corner (nearest %.1f mm)", 1e3 * (double)d);
    /* and then the chamfer's ends are collinear: removal leaves the L */
    polyc__op_remove_vertices(&f.o, 0);
    check_books(&f.o, "add + remove");
    assert_int_equal(f.o.s->v_live, 3);
    assert_true(nearest_vertex(&f.o, 0.0f, 0.0f) <= 0.01f);
    fx_close(&f);
}

/* An addition that failed is not tried again while the four vertices it
 * depends on stay where they are: a second pass over an unchanged map
 * makes no trial, so it edits (stamps) nothing. Two trials on an L, whose
 * undos stamped each other's vertices, were both made again. */
static void test_failed_addition_not_tried_again(void **state)
{
    (void)state;
    static fixture f;
    int32_t l = open_exact_corner(&f);
    assert_int_equal(polyc__op_add_vertices(&f.o, 1), 0);
    assert_line_is(&f.o, l, L_CORNER, 3);
    uint32_t touch[3];
    for (int32_t v = 0; v < 3; v++)
        touch[v] = f.o.v_touch[v];
    assert_int_equal(polyc__op_add_vertices(&f.o, 1), 0);
    for (int32_t v = 0; v < 3; v++)
        if (f.o.v_touch[v] != touch[v])
            fail_msg("vertex %d stamped again (%u -> %u): a failed addition was tried again",
                     (int)v, (unsigned)touch[v], (unsigned)f.o.v_touch[v]);
    /* a moved end is a new neighbourhood: its addition is tried again */
    polyc__apply_move(&f.o, 0, -1.0f, 0.01f);
    uint32_t before = f.o.v_touch[1];
    f.o.touch_stamp++;
    polyc__op_add_vertices(&f.o, 1);
    assert_true(f.o.v_touch[1] > before);
    check_books(&f.o, "additions");
    fx_close(&f);
}

/* ---- corners ---- */

static void test_corner_replaces_spike(void **state)
{
    (void)state;
    static fixture f;
    fx_open_hand(&f, 0.0f);
    corner_points(&f, 1);
    clear_lines(&f.o);
    /* a spike out of the corner between the two walls; the segment into the
     * spike's tip runs parallel to the first wall, so the only corner the
     * operator can find replaces the whole chain */
    const float xy[14] = {-1.0f, 0.0f, -0.5f, 0.0f, -0.08f, 0.0f, 0.1f, 0.08f,
                          0.0f, 0.08f, 0.0f, 0.5f, 0.0f, 1.0f};
    const float after[10] = {-1.0f, 0.0f, -0.5f, 0.0f, 0.0f, 0.0f, 0.0f, 0.5f, 0.0f, 1.0f};
    int32_t l = add_line(&f.o, xy, 7, 0);
    rebuild(&f.o);
    double before = (double)polyc__bic(&f.o);
    int changed = polyc__op_corners(&f.o, 0);
    check_books(&f.o, "corner");
    assert_line_near(&f.o, l, after, 5, 1e-6f);
    assert_int_equal(changed, 1);
    assert_true((double)polyc__bic(&f.o) < before);
    fx_close(&f);
}

/* A map whose every vertex is a real corner (a staircase of 25 cm steps,
 * data along it) has no corner to put in: nothing changes, and nothing is
 * reported as changed (the search loop adjusts again when it is). */
static void test_corners_leave_clean_map(void **state)
{
    (void)state;
    static fixture f;
    static ptlist p;
    fx_open_hand(&f, 0.0f);
    const float xy[16] = {-1.0f, 0.0f, -0.5f, 0.0f, -0.5f, 0.25f, -0.25f, 0.25f,
                          -0.25f, 0.5f, 0.0f, 0.5f, 0.0f, 0.75f, 0.25f, 0.75f};
    p.n = 0;
    for (int k = 0; k < 7; k++)
        pts_line(&p, xy[2 * k], xy[2 * k + 1], xy[2 * k + 2], xy[2 * k + 3], 0.01f);
    set_points(&f, p.xy, p.n);
    clear_lines(&f.o);
    int32_t l = add_line(&f.o, xy, 8, 0);
    rebuild(&f.o);
    int changed = polyc__op_corners(&f.o, 0);
    assert_line_is(&f.o, l, xy, 8);
    assert_int_equal(changed, 0);
    fx_close(&f);
}

/* A vertex whose segment already stands in front of a return (12 cm in
 * front of beam 1's, as ends near the sensor do within the range noise)
 * may move along it, but not across another beam that saw through: a
 * check that lets any move of such a vertex pass let one csail climb put a
 * segment 5.3 m in front of a return. */
static void test_vertex_blocks_only_new_beams(void **state)
{
    (void)state;
    static fixture f;
    static float range[3] = {2.0f, 1.0f, 5.0f};
    fx_open_hand(&f, 0.0f);
    clear_lines(&f.o);
    const float xy[4] = {0.88f, -0.05f, 0.88f, 0.05f};
    int32_t l = add_line(&f.o, xy, 2, 0);
    rebuild(&f.o);
    /* three beams from the origin, at -0.2, 0 and 0.2 rad */
    polyc__rays *r = set_rays(&f.o, 0.0f, 0.0f, -0.2f, 0.2f, range, 3);
    int32_t v = f.o.s->l[l].tail;
    const polyc__vertex *t = &f.o.s->v[v];
    assert_true(polyc__blocks_beams(r, f.o.s->v[f.o.s->l[l].head].x, f.o.s->v[f.o.s->l[l].head].y,
                                    t->x, t->y, NULL, 0));
    /* along beam 1's block: nothing new */
    assert_false(polyc__vertex_blocks(&f.o, v, 0.89f, 0.06f));
    /* across beam 2, 4.1 m in front of its return */
    if (!polyc__vertex_blocks(&f.o, v, 0.88f, 0.25f))
        fail_msg("the tail at (0.88, 0.25) stands 4.1 m in front of beam 2's return, and passed");
    fx_close(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hill_climb_returns_to_corner),
        cmocka_unit_test(test_adjust_never_raises_bic),
        cmocka_unit_test(test_bic_checked_operators_never_raise_bic),
        cmocka_unit_test(test_zigzag_removes_hairpin),
        cmocka_unit_test(test_zigzag_keeps_sharp_corner_with_data),
        cmocka_unit_test(test_unfold_corner_overshoot),
        cmocka_unit_test(test_unfold_two_vertex_hairpin),
        cmocka_unit_test(test_unfold_keeps_thin_wall_end),
        cmocka_unit_test(test_noise_deterministic_and_sized),
        cmocka_unit_test(test_remove_collinear_vertex),
        cmocka_unit_test(test_remove_keeps_true_corner),
        cmocka_unit_test(test_add_vertex_at_cut_corner),
        cmocka_unit_test(test_failed_addition_not_tried_again),
        cmocka_unit_test(test_corner_replaces_spike),
        cmocka_unit_test(test_corners_leave_clean_map),
        cmocka_unit_test(test_vertex_blocks_only_new_beams),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
