/* test_gridtrace.c - the findContours + approxPolyDP baseline
 * (tools/eval/gridtrace.h) on hand-made grids of 10 cm cells with their
 * origin at (0, 0): a cell (i, j)'s centre is (0.1 i + 0.05, 0.1 j + 0.05). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "gridtrace.h"

#define W 12
#define H 10
#define RES 0.1

static int8_t cells[W * H];

static polyc_occupancy_grid grid(void)
{
    polyc_occupancy_grid g;
    memset(&g, 0, sizeof g);
    g.width = W;
    g.height = H;
    g.resolution_m = (float)RES;
    g.cells = cells;
    return g;
}

static void fill(int i0, int j0, int i1, int j1, int8_t v)
{
    for (int j = j0; j <= j1; j++)
        for (int i = i0; i <= i1; i++)
            cells[j * W + i] = v;
}

/* Does the polyline hold the centre of cell (i, j)? How often? */
static int holds(const polyc_polyline *l, int i, int j)
{
    int n = 0;
    for (uint32_t k = 0; k < l->point_count; k++)
        n += fabs((double)l->xy_m[2u * k] - (RES * i + 0.05)) < 1e-5 &&
             fabs((double)l->xy_m[2u * k + 1u] - (RES * j + 0.05)) < 1e-5;
    return n;
}

static void test_rectangle(void **state)
{
    polyc_occupancy_grid g = grid();
    gridtrace_map m;
    (void)state;
    fill(0, 0, W - 1, H - 1, 0);
    fill(2, 2, 6, 4, 100);                 /* 5 x 3 cells */
    fill(9, 7, 10, 7, -1);                 /* unknown is not occupied */
    assert_int_equal(gridtrace_run(&g, 65, (double)g.resolution_m, &m), 0);
    assert_int_equal(m.line_count, 1);
    assert_int_equal(m.border_cells, 12);  /* the ring of border cells */
    assert_int_equal(m.vertices, 4);
    assert_int_equal(m.lines[0].point_count, 4);
    assert_int_equal(m.lines[0].closed, 1);
    assert_int_equal(holds(&m.lines[0], 2, 2), 1);
    assert_int_equal(holds(&m.lines[0], 6, 2), 1);
    assert_int_equal(holds(&m.lines[0], 6, 4), 1);
    assert_int_equal(holds(&m.lines[0], 2, 4), 1);
    gridtrace_free(&m);
    /* epsilon 0 still drops the cells in line with their neighbours */
    assert_int_equal(gridtrace_run(&g, 65, 0.0, &m), 0);
    assert_int_equal(m.vertices, 4);
    gridtrace_free(&m);
    /* a notch (a cell taken out of the bottom side) is kept at epsilon 0
     * and smoothed away at one cell (it lies one cell off the side) */
    cells[2 * W + 4] = 0;
    assert_int_equal(gridtrace_run(&g, 65, 0.0, &m), 0);
    assert_int_equal(m.border_cells, 12);   /* the border steps over it diagonally */
    assert_true(holds(&m.lines[0], 4, 3) == 1);
    gridtrace_free(&m);
    assert_int_equal(gridtrace_run(&g, 65, (double)g.resolution_m, &m), 0);
    assert_int_equal(holds(&m.lines[0], 4, 3), 0);
    gridtrace_free(&m);
}

/* A one-cell-wide L, its arms 6 and 5 cells long: walked out and back
 * (the border steps diagonally from one arm to the other, past the
 * corner cell), simplified to the corner, the two ends and the cell next to
 * the corner where the walk turns back. */
static void test_l_shape(void **state)
{
    polyc_occupancy_grid g = grid();
    gridtrace_map m;
    (void)state;
    fill(0, 0, W - 1, H - 1, -1);
    fill(1, 1, 6, 1, 100);
    fill(1, 1, 1, 5, 100);
    assert_int_equal(gridtrace_run(&g, 65, (double)g.resolution_m, &m), 0);
    assert_int_equal(m.line_count, 1);
    assert_int_equal(m.border_cells, 1u + 5u + 4u + 4u + 3u);
    assert_int_equal(m.lines[0].point_count, 4);
    assert_int_equal(holds(&m.lines[0], 1, 1), 1);
    assert_int_equal(holds(&m.lines[0], 6, 1), 1);
    assert_int_equal(holds(&m.lines[0], 1, 5), 1);
    assert_int_equal(holds(&m.lines[0], 2, 1), 1);
    gridtrace_free(&m);
}

/* A room's wall ring: its outside and its inside (a hole border), four
 * corners each; a lone cell and a diagonal pair, 8-connected. */
static void test_ring_and_small(void **state)
{
    polyc_occupancy_grid g = grid();
    gridtrace_map m;
    (void)state;
    fill(0, 0, W - 1, H - 1, 0);
    fill(1, 1, 7, 6, 100);
    fill(2, 2, 6, 5, 0);
    cells[8 * W + 10] = 100;               /* lone */
    cells[1 * W + 9] = 100;                /* diagonal pair */
    cells[2 * W + 10] = 100;
    assert_int_equal(gridtrace_run(&g, 65, (double)g.resolution_m, &m), 0);
    assert_int_equal(m.line_count, 4);
    int outer = -1, inner = -1, lone = -1, pair = -1;
    for (uint32_t k = 0; k < m.line_count; k++) {
        if (holds(&m.lines[k], 1, 1))
            outer = (int)k;
        else if (holds(&m.lines[k], 10, 8))
            lone = (int)k;
        else if (holds(&m.lines[k], 9, 1))
            pair = (int)k;
        else
            inner = (int)k;
    }
    assert_true(outer >= 0 && inner >= 0 && lone >= 0 && pair >= 0);
    /* the outer border keeps the ring's corner cells; the inner one runs
     * through the cells that touch the room by a side, so it cuts each
     * corner (from the room's first border cell (1, 2) to the one farthest
     * from it, (7, 5)) */
    assert_int_equal(m.lines[outer].point_count, 4);
    assert_int_equal(holds(&m.lines[outer], 7, 6), 1);
    assert_int_equal(holds(&m.lines[outer], 7, 1), 1);
    assert_int_equal(m.lines[inner].point_count, 4);
    assert_int_equal(m.lines[inner].closed, 1);
    assert_int_equal(holds(&m.lines[inner], 1, 2), 1);
    assert_int_equal(holds(&m.lines[inner], 7, 5), 1);
    assert_int_equal(holds(&m.lines[inner], 7, 6), 0);
    assert_int_equal(m.border_cells, 22u + 18u + 1u + 2u);
    assert_int_equal(m.lines[lone].point_count, 1);
    assert_int_equal(m.lines[lone].closed, 0);
    assert_int_equal(m.lines[pair].point_count, 2);
    assert_int_equal(m.lines[pair].closed, 0);
    assert_int_equal(holds(&m.lines[pair], 10, 2), 1);
    gridtrace_free(&m);

    /* nothing occupied, nothing traced; a bad epsilon */
    fill(0, 0, W - 1, H - 1, 0);
    assert_int_equal(gridtrace_run(&g, 65, (double)g.resolution_m, &m), 0);
    assert_int_equal(m.line_count, 0);
    gridtrace_free(&m);
    assert_int_equal(gridtrace_run(&g, 65, -1.0, &m), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rectangle),
        cmocka_unit_test(test_l_shape),
        cmocka_unit_test(test_ring_and_small),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
