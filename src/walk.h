/* walk.h - the cell walk of polyc__traverse (Amanatides-Woo) as inline
 * steps, for the grid and contour passes, which visit every cell of every
 * beam and cannot afford a call through a pointer per cell, and for the
 * spatial hash's segment paths.
 *
 * In integers: the beam's ends in fixed point (F fractional bits, F chosen
 * per beam so that no product exceeds 2^62), and for each axis a key that
 * orders the boundary crossings exactly, the distance to the next boundary
 * along that axis times the beam's extent along the other one. A step adds
 * a constant to a key, so a walk can cross any number of tiles in one
 * move (polyc__walk_skip_tiles) and be where its steps would have taken it. */
#ifndef POLYC_WALK_H
#define POLYC_WALK_H

#include "context.h"

#include <math.h>
#include <string.h>

typedef struct polyc__walk {
    int32_t ix, iy;                /* current cell */
    int32_t idx;                   /* its index in its tile */
    int32_t left_x, left_y;        /* steps along x / y left in this tile and the grid */
    int32_t ex, ey;                /* end cell, visited last whatever the rounding */
    int32_t stx, sty;              /* +1 or -1 */
    int32_t n;                     /* steps left before the end cell */
    int64_t kx, ky;                /* keys of the next x and y crossings (INT64_MAX: none) */
    int64_t inc_x, inc_y;          /* what a step adds to them */
    int64_t t_key;                 /* key of the step into the current cell (0: the start) */
    int64_t end_key;               /* key of the end point: no step's is larger */
    float per_key;                 /* beam parameter per key unit */
} polyc__walk;

/* floor(v * scale) of a finite v, scale a power of two: exact in float, so
 * no double arithmetic (a microcontroller's FPU has none); below 2^30 in
 * magnitude (polyc__walk_start's choice of scale), so a 32-bit conversion,
 * one instruction where a 64-bit one is a library call */
static inline int64_t polyc__fixed(float v, float scale)
{
    return (int64_t)polyc__floori(v * scale);
}

inline float polyc__max_abs(float a, float b)
{
    a = a < 0.0f ? -a : a;
    b = b < 0.0f ? -b : b;
    return a > b ? a : b;
}

static inline void polyc__walk_start(polyc__walk *w, const polyc__beam *b)
{
    w->ix = polyc__floori(b->sx);
    w->iy = polyc__floori(b->sy);
    w->ex = polyc__floori(b->ex);
    w->ey = polyc__floori(b->ey);
    /* fractional bits: coordinates (plus a tile's worth of steps past the
     * end) below 2^(30 - f) keep every key below 2^62; at f = 0 that holds
     * for any grid the configuration allows (1e6 m / 1 mm < 2^30 cells) */
    float m = polyc__max_abs(polyc__max_abs(b->sx, b->sy), polyc__max_abs(b->ex, b->ey)) + 64.0f;
    uint32_t bits;
    memcpy(&bits, &m, sizeof bits);
    int e = (int)((bits >> 23) & 0xffu) - 126; /* m < 2^e, a normal float >= 64 */
    int f = 30 - e;
    f = f < 0 ? 0 : (f > 20 ? 20 : f);
    int64_t one = (int64_t)1 << f;
    float scale = (float)one;
    int64_t sx = polyc__fixed(b->sx, scale), sy = polyc__fixed(b->sy, scale);
    int64_t ex = polyc__fixed(b->ex, scale), ey = polyc__fixed(b->ey, scale);
    w->stx = ex > sx ? 1 : -1;
    w->sty = ey > sy ? 1 : -1;
    int64_t dxa = ex > sx ? ex - sx : sx - ex, dya = ey > sy ? ey - sy : sy - ey;
    /* distance to the first boundary along each axis */
    int64_t ax = w->stx > 0 ? ((int64_t)w->ix + 1) * one - sx : sx - (int64_t)w->ix * one;
    int64_t ay = w->sty > 0 ? ((int64_t)w->iy + 1) * one - sy : sy - (int64_t)w->iy * one;
    if (dxa > 0 && dya > 0) {
        w->kx = ax * dya;
        w->ky = ay * dxa;
        w->inc_x = one * dya;
        w->inc_y = one * dxa;
        w->end_key = dxa * dya;
        w->per_key = 1.0f / ((float)(int32_t)dxa * (float)(int32_t)dya); /* (each < 2^31) */
    } else {
        /* along one axis only (or not at all): its distance is the key */
        w->kx = dxa > 0 ? ax : INT64_MAX;
        w->ky = dya > 0 ? ay : INT64_MAX;
        w->inc_x = dxa > 0 ? one : 0;
        w->inc_y = dya > 0 ? one : 0;
        w->end_key = dxa > 0 ? dxa : dya;
        w->per_key = dxa > 0 ? 1.0f / (float)(int32_t)dxa : (dya > 0 ? 1.0f / (float)(int32_t)dya : 0.0f);
    }
    /* the step count is fixed in advance, so the walk always ends */
    w->n = (w->ex > w->ix ? w->ex - w->ix : w->ix - w->ex) +
           (w->ey > w->iy ? w->ey - w->iy : w->iy - w->ey);
    w->t_key = 0;
    /* set by polyc__walk_enter; until then steps count down from far away
     * (polyc__traverse never calls it: no use of indeterminate values) */
    w->idx = 0;
    w->left_x = w->left_y = INT32_MAX;
}

/* The beam parameter where the walk entered the current cell. */
static inline float polyc__walk_t(const polyc__walk *w)
{
    return (float)w->t_key * w->per_key;
}

/* The key of beam parameter t: the steps with t_key below it are those
 * whose polyc__walk_t is below t (up to float's rounding of either). Once
 * per beam, so that the cells compare integers: a 64-bit key to float is a
 * library call per cell on the target. t in 24-bit fixed point, times
 * end_key (the key of t = 1) in two halves: below 2^62, no overflow. */
static inline int64_t polyc__walk_key_at(const polyc__walk *w, float t)
{
    if (w->end_key == 0) /* (no extent: every step is at t = 0) */
        return t > 0.0f ? INT64_MAX : 0;
    if (!(t < 1.0f)) /* (t = 1: the steps before the end point; NaN: none) */
        return t == 1.0f ? w->end_key : (t > 1.0f ? INT64_MAX : 0);
    if (t <= 0.0f)
        return 0;
    int64_t m = (int64_t)(uint32_t)(t * 16777216.0f), e = w->end_key;
    return (e >> 24) * m + (((e & 0xffffff) * m) >> 24);
}

/* To the next cell. Returns 1 when it left the tile (or the grid): then
 * polyc__walk_enter must run before idx is used again. */
inline int polyc__walk_step(polyc__walk *w)
{
    w->n--;
    if (w->kx < w->ky) {
        w->t_key = w->kx;
        w->kx += w->inc_x;
        w->ix += w->stx;
        w->idx += w->stx;
        return --w->left_x < 0;
    }
    w->t_key = w->ky;
    w->ky += w->inc_y;
    w->iy += w->sty;
    w->idx += w->sty * POLYC__TILE_SIDE;
    return --w->left_y < 0;
}

/* Sets idx and the steps left before the walk leaves the current cell's
 * tile or the width x height grid; 0 when the cell is outside the grid. */
inline int polyc__walk_enter(polyc__walk *w, int32_t width, int32_t height)
{
    if (w->ix < 0 || w->iy < 0 || w->ix >= width || w->iy >= height)
        return 0;
    const int32_t m = POLYC__TILE_SIDE - 1;
    w->idx = polyc__cell_index(w->ix, w->iy);
    w->left_x = w->stx > 0 ? ((w->ix | m) < width ? w->ix | m : width - 1) - w->ix : w->ix & m;
    w->left_y = w->sty > 0 ? ((w->iy | m) < height ? w->iy | m : height - 1) - w->iy : w->iy & m;
    return 1;
}

/* Moves the walk, from inside a tile whose counts polyc__walk_enter set,
 * into the first tile of its path whose bit is set in `stop` (a bit per
 * tile, row-major over tiles_x columns), where its steps would take it,
 * and returns 1; if its steps end first (the step into that tile would be
 * the last, or none is left), 0; if they leave the width x height grid
 * first, -1 (nothing moved in either case). Tile by tile only the keys of
 * the steps that leave each tile are compared (the same order as the
 * steps: across x when its key is below y's), so a beam's crossing of
 * many tiles without a stop costs a comparison and an addition each; the
 * step counts (a division) are worked out where it stops. No step has a
 * key past the end point's (end_key): ties there are why a walk can end a
 * cell off its end cell, and why the step counts decide. */
static inline int polyc__walk_skip_tiles(polyc__walk *w, int32_t width, int32_t height,
                                         int32_t tiles_x, const uint32_t *stop)
{
    const int32_t S = POLYC__TILE_SIDE, m = S - 1;
    int32_t tx = w->ix >> POLYC__TILE_SHIFT, ty = w->iy >> POLYC__TILE_SHIFT;
    /* keys of the steps that leave the current tile along x and along y */
    int64_t lx = w->inc_x ? w->kx + (int64_t)w->left_x * w->inc_x : INT64_MAX;
    int64_t ly = w->inc_y ? w->ky + (int64_t)w->left_y * w->inc_y : INT64_MAX;
    int64_t key;
    int across_x, outside;
    for (;;) {
        across_x = lx < ly;
        key = across_x ? lx : ly;
        if (key > w->end_key)
            return 0;
        if (across_x) {
            tx += w->stx;
            int32_t lo = tx * S;
            outside = tx < 0 || lo >= width;
            /* the columns it crosses in the new tile (the last tile may be cut by the grid) */
            int32_t cols = w->stx > 0 ? ((lo + m < width ? lo + m : width - 1) - lo + 1) : S;
            lx = key + (int64_t)cols * w->inc_x;
        } else {
            ty += w->sty;
            int32_t lo = ty * S;
            outside = ty < 0 || lo >= height;
            int32_t rows = w->sty > 0 ? ((lo + m < height ? lo + m : height - 1) - lo + 1) : S;
            ly = key + (int64_t)rows * w->inc_y;
        }
        if (outside)
            break;
        size_t d = (size_t)ty * (size_t)tiles_x + (size_t)tx;
        if ((stop[d >> 5] >> (d & 31)) & 1u)
            break;
    }
    /* the step with `key` enters the tile: along its own axis the steps
     * are the columns (rows) to the tile's edge; along the other, the steps
     * whose keys are at or below it (across x) or below it (across y) */
    int64_t sx, sy;
    if (across_x) {
        int64_t to = (int64_t)tx * S < width ? (int64_t)tx * S : width; /* (out past a cut tile) */
        sx = w->stx > 0 ? to - w->ix : (int64_t)w->ix - ((int64_t)tx * S + m);
        sy = w->ky > key ? 0 : (key - w->ky) / w->inc_y + 1;
    } else {
        int64_t to = (int64_t)ty * S < height ? (int64_t)ty * S : height;
        sy = w->sty > 0 ? to - w->iy : (int64_t)w->iy - ((int64_t)ty * S + m);
        sx = w->kx >= key ? 0 : (key - w->kx - 1) / w->inc_x + 1;
    }
    if (sx + sy >= (int64_t)w->n)
        return 0; /* that step would be the last (or past it) */
    if (outside)
        return -1;
    w->n -= (int32_t)(sx + sy);
    w->t_key = key;
    w->kx = w->inc_x ? w->kx + sx * w->inc_x : INT64_MAX;
    w->ky = w->inc_y ? w->ky + sy * w->inc_y : INT64_MAX;
    w->ix += w->stx * (int32_t)sx;
    w->iy += w->sty * (int32_t)sy;
    w->left_x = w->left_y = -1;
    return 1;
}

#endif
