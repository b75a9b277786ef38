/* online_cells.c - an online context's cells with endpoints: their sums
 * (online.h, polyc__cell_sums), found by cell through an open-addressed
 * table of 4/3 limits.max_points slots or more, so that the memory
 * follows the cells with endpoints, not the stored tiles' cells; and per
 * stored tile the count of them. Takes: a cell key (polyc__cell_key).
 * Gives: its entry in the sums. */
#include "../online.h"

#include <string.h>

/* The table's slots, 2^bits: the next power of two at or above 4/3 of the
 * entries (three quarters full at most: a few probes a lookup). */
static uint32_t table_bits(uint32_t entries)
{
    uint32_t bits = 4;
    while (3.0f * (float)(1u << bits) < 4.0f * (float)entries)
        bits++;
    return bits;
}

int polyc__cells_carve(polyc__arena *a, polyc__cell_table *tab, uint32_t cap, uint32_t tile_cap)
{
    int ok = 1;
    tab->cap = cap;
    uint32_t bits = table_bits(tab->cap), n = 1u << bits;
    tab->cell_shift = 32 - bits;
    tab->cell_mask = n - 1;
    POLYC__CARVE(ok, a, tab->sums, tab->cap);
    POLYC__CARVE_ZERO(ok, a, tab->cell_at, n);
    POLYC__CARVE_ZERO(ok, a, tab->tile_cells, tile_cap);
    return ok;
}

/* Fibonacci hashing: the top bits of the key times 2^32 / phi (the keys of
 * neighbouring cells land far apart). */
static uint32_t home(const polyc__cell_table *tab, uint32_t key)
{
    return (key * 2654435769u) >> tab->cell_shift;
}

/* The slot holding key, or the empty one where it would go. */
static uint32_t probe(const polyc__cell_table *tab, uint32_t key)
{
    uint32_t i = home(tab, key);
    while (tab->cell_at[i] != 0 && tab->sums[tab->cell_at[i] - 1].cell != key)
        i = (i + 1) & tab->cell_mask;
    return i;
}

uint32_t polyc__cell_find(const polyc__cell_table *tab, uint32_t key)
{
    return tab->cell_at[probe(tab, key)];
}

/* Whether another cell of key's 2 x 2 block (one weighted point, points.c)
 * has sums: a tile's keys are its cells' indices, 32 a row, so the block's
 * others are key ^ 1, ^ 32 and ^ 33, in the same tile. */
static int block_has_other(const polyc__cell_table *tab, uint32_t key)
{
    return tab->cell_at[probe(tab, key ^ 1u)] != 0 || tab->cell_at[probe(tab, key ^ 32u)] != 0 ||
           tab->cell_at[probe(tab, key ^ 33u)] != 0;
}

uint32_t polyc__cell_add(polyc__cell_table *tab, uint32_t key)
{
    uint32_t i = probe(tab, key);
    if (tab->cell_at[i] != 0)
        return tab->cell_at[i];
    uint32_t e;
    if (tab->sums_free) {
        e = tab->sums_free - 1;
        tab->sums_free = tab->sums[e].n;
    } else if (tab->sums_n < tab->cap) {
        e = tab->sums_n++;
    } else {
        return 0;
    }
    memset(&tab->sums[e], 0, sizeof tab->sums[0]);
    tab->sums[e].cell = key;
    tab->blocks_n += !block_has_other(tab, key);
    tab->cell_at[i] = e + 1;
    tab->tile_cells[key / POLYC__TILE_CELLS]++;
    return e + 1;
}

/* Out of the table by shifting back the entries after it that probed past
 * its slot (no tombstones: a lookup stops at the first empty slot). */
void polyc__cell_drop(polyc__cell_table *tab, uint32_t entry)
{
    uint32_t key = tab->sums[entry - 1].cell;
    uint32_t i = probe(tab, key), j = i;
    for (;;) {
        j = (j + 1) & tab->cell_mask;
        if (tab->cell_at[j] == 0)
            break;
        uint32_t h = home(tab, tab->sums[tab->cell_at[j] - 1].cell);
        /* j's entry may move to i if its home is not in (i, j], cyclically */
        int stays = i <= j ? (i < h && h <= j) : (i < h || h <= j);
        if (!stays) {
            tab->cell_at[i] = tab->cell_at[j];
            i = j;
        }
    }
    tab->cell_at[i] = 0;
    tab->blocks_n -= !block_has_other(tab, key);
    tab->tile_cells[key / POLYC__TILE_CELLS]--;
    tab->sums[entry - 1].n = tab->sums_free;
    tab->sums_free = entry;
}

void polyc__cells_clear(polyc__cell_table *tab, uint32_t tiles)
{
    memset(tab->cell_at, 0, ((size_t)tab->cell_mask + 1u) * sizeof *tab->cell_at);
    memset(tab->tile_cells, 0, (size_t)tiles * sizeof *tab->tile_cells);
    tab->sums_n = 0;
    tab->sums_free = 0;
    tab->blocks_n = 0;
}
