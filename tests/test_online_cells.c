/* test_online_cells.c - an online context's cells with endpoints
 * (src/online/online_cells.c): the open-addressed table finds every cell added and
 * no other, through random adds and drops that fill it to its limit
 * (backward-shift deletion, wrap-around at the table's end); the entries
 * run out at limits.max_points and come back when dropped; and each tile's
 * count of cells is exact. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <string.h>

#include "online.h"

#define TILES 6u
#define KEYS (TILES * POLYC__TILE_CELLS)

static unsigned char mem[1u << 16];
static uint32_t ref[KEYS]; /* 1 + entry, as the table should answer */

static void open_cells(polyc__online *on, uint32_t max_points)
{
    memset(on, 0, sizeof *on);
    on->lim.max_points = max_points;
    polyc__arena a = {mem, sizeof mem, 0, 0};
    assert_true(polyc__cells_carve(&a, &on->tab, max_points, TILES));
    memset(ref, 0, sizeof ref);
}

static void check_all(const polyc__online *on)
{
    uint32_t count[TILES] = {0};
    for (uint32_t k = 0; k < KEYS; k++) {
        assert_int_equal(polyc__cell_find(&on->tab, k), ref[k]);
        count[k / POLYC__TILE_CELLS] += ref[k] != 0;
    }
    for (uint32_t t = 0; t < TILES; t++)
        assert_int_equal(on->tab.tile_cells[t], count[t]);
}

static uint32_t next(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static void test_random_adds_and_drops(void **state)
{
    (void)state;
    static const uint32_t caps[] = {16, 100, 384, 1000};
    for (unsigned c = 0; c < sizeof caps / sizeof caps[0]; c++) {
        polyc__online on;
        open_cells(&on, caps[c]);
        uint32_t seed = 7u + c, live = 0;
        for (int step = 0; step < 20000; step++) {
            uint32_t key = next(&seed) % KEYS;
            if (next(&seed) % 3 != 0) {
                uint32_t e = polyc__cell_add(&on.tab, key);
                if (ref[key]) {
                    assert_int_equal(e, ref[key]); /* there already: the same entry */
                } else if (live < caps[c]) {
                    assert_true(e != 0);
                    assert_int_equal(on.tab.sums[e - 1].cell, key);
                    assert_true(on.tab.sums[e - 1].n == 0 && on.tab.sums[e - 1].fx == 0.0f);
                    ref[key] = e;
                    live++;
                } else {
                    assert_int_equal(e, 0); /* limits.max_points reached */
                }
            } else if (ref[key]) {
                polyc__cell_drop(&on.tab, ref[key]);
                ref[key] = 0;
                live--;
            }
            if (step % 1000 == 0)
                check_all(&on);
        }
        check_all(&on);
    }
}

/* A full table: every entry taken, then all dropped in another order, then
 * taken again from the free list. */
static void test_fill_drop_refill(void **state)
{
    (void)state;
    polyc__online on;
    open_cells(&on, 300);
    for (uint32_t i = 0; i < 300; i++)
        ref[i * 17] = polyc__cell_add(&on.tab, i * 17);
    assert_int_equal(polyc__cell_add(&on.tab, 1), 0);
    check_all(&on);
    for (uint32_t i = 0; i < 300; i += 2) {
        polyc__cell_drop(&on.tab, ref[i * 17]);
        ref[i * 17] = 0;
    }
    check_all(&on);
    for (uint32_t i = 1; i < 300; i += 2) {
        polyc__cell_drop(&on.tab, ref[i * 17]);
        ref[i * 17] = 0;
    }
    check_all(&on);
    assert_int_equal(on.tab.sums_n, 300); /* entries are reused, not handed out anew */
    for (uint32_t i = 0; i < 300; i++)
        assert_true((ref[i * 5] = polyc__cell_add(&on.tab, i * 5)) != 0);
    assert_int_equal(on.tab.sums_n, 300);
    check_all(&on);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_adds_and_drops),
        cmocka_unit_test(test_fill_drop_refill),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
