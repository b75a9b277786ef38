/* online_cells.c - an online context's cells with endpoints: their sums
 * (online.h, polyc__cell_sums), found by cell through an open-addressed
 * table of 4/3 limits.max_points slots or more, so that the memory
 * follows the cells with endpoints, not the stored tiles' cells; and per
 * stored tile the count of them. Takes: a cell key (polyc__cell_key).
 * Gives: its entry in the sums. */
#include "online.h"

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

int polyc__cells_carve(polyc__arena *a, polyc__online *on, uint32_t tile_cap)
{
    int ok = 1;
    uint32_t bits = table_bits(on->lim.max_points), n = 1u << bits;
    on->cell_shift = 32 - bits;
    on->cell_mask = n - 1;
    POLYC__CARVE(ok, a, on->sums, on->lim.max_points);
    POLYC__CARVE_ZERO(ok, a, on->cell_at, n);
    POLYC__CARVE_ZERO(ok, a, on->tile_cells, tile_cap);
    return ok;
}

/* Fibonacci hashing: the top bits of the key times 2^32 / phi (the keys of
 * neighbouring cells land far apart). */
static uint32_t home(const polyc__online *on, uint32_t key)
{
    return (key * 2654435769u) >> on->cell_shift;
}

/* The slot holding key, or the empty one where it would go. */
static uint32_t probe(const polyc__online *on, uint32_t key)
{
    uint32_t i = home(on, key);
    while (on->cell_at[i] != 0 && on->sums[on->cell_at[i] - 1].cell != key)
        i = (i + 1) & on->cell_mask;
    return i;
}

uint32_t polyc__cell_find(const polyc__online *on, uint32_t key)
{
    return on->cell_at[probe(on, key)];
}

/* Whether another cell of key's 2 x 2 block (one weighted point, points.c)
 * has sums: a tile's keys are its cells' indices, 32 a row, so the block's
 * others are key ^ 1, ^ 32 and ^ 33, in the same tile. */
static int block_has_other(const polyc__online *on, uint32_t key)
{
    return on->cell_at[probe(on, key ^ 1u)] != 0 || on->cell_at[probe(on, key ^ 32u)] != 0 ||
           on->cell_at[probe(on, key ^ 33u)] != 0;
}

uint32_t polyc__cell_add(polyc__online *on, uint32_t key)
{
    uint32_t i = probe(on, key);
    if (on->cell_at[i] != 0)
        return on->cell_at[i];
    uint32_t e;
    if (on->sums_free) {
        e = on->sums_free - 1;
        on->sums_free = on->sums[e].n;
    } else if (on->sums_n < on->lim.max_points) {
        e = on->sums_n++;
    } else {
        return 0;
    }
    memset(&on->sums[e], 0, sizeof on->sums[0]);
    on->sums[e].cell = key;
    on->blocks_n += !block_has_other(on, key);
    on->cell_at[i] = e + 1;
    on->tile_cells[key / POLYC__TILE_CELLS]++;
    return e + 1;
}

/* Out of the table by shifting back the entries after it that probed past
 * its slot (no tombstones: a lookup stops at the first empty slot). */
void polyc__cell_drop(polyc__online *on, uint32_t entry)
{
    uint32_t key = on->sums[entry - 1].cell;
    uint32_t i = probe(on, key), j = i;
    for (;;) {
        j = (j + 1) & on->cell_mask;
        if (on->cell_at[j] == 0)
            break;
        uint32_t h = home(on, on->sums[on->cell_at[j] - 1].cell);
        /* j's entry may move to i if its home is not in (i, j], cyclically */
        int stays = i <= j ? (i < h && h <= j) : (i < h || h <= j);
        if (!stays) {
            on->cell_at[i] = on->cell_at[j];
            i = j;
        }
    }
    on->cell_at[i] = 0;
    on->blocks_n -= !block_has_other(on, key);
    on->tile_cells[key / POLYC__TILE_CELLS]--;
    on->sums[entry - 1].n = on->sums_free;
    on->sums_free = entry;
}

void polyc__cells_clear(polyc__online *on, uint32_t tiles)
{
    memset(on->cell_at, 0, ((size_t)on->cell_mask + 1u) * sizeof *on->cell_at);
    memset(on->tile_cells, 0, (size_t)tiles * sizeof *on->tile_cells);
    on->sums_n = 0;
    on->sums_free = 0;
    on->blocks_n = 0;
}
