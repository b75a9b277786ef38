/* walk.h - the cell walk of polyc__traverse (Amanatides-Woo in float) as
 * inline steps, for the grid and contour passes, which visit every cell of
 * every beam and cannot afford a call through a pointer per cell. */
#ifndef POLYC_WALK_H
#define POLYC_WALK_H

#include "internal.h"

#include <math.h>

typedef struct polyc__walk {
    int32_t ix, iy;                /* current cell */
    int32_t idx;                   /* its index in its tile */
    int32_t left_x, left_y;        /* steps along x / y left in this tile and the grid */
    int32_t ex, ey;                /* end cell, visited last whatever the rounding */
    int32_t stx, sty;              /* +1 or -1 */
    int32_t n;                     /* steps left before the end cell */
    float t;                       /* beam parameter where the walk entered the cell */
    float tmx, tmy;                /* parameter of the next x and y cell boundary */
    float tdx, tdy;                /* parameter per cell along x and y */
} polyc__walk;

static inline void polyc__walk_start(polyc__walk *w, const polyc__beam *b)
{
    w->ix = (int32_t)floorf(b->sx);
    w->iy = (int32_t)floorf(b->sy);
    w->ex = (int32_t)floorf(b->ex);
    w->ey = (int32_t)floorf(b->ey);
    float dx = b->ex - b->sx, dy = b->ey - b->sy;
    w->stx = dx > 0.0f ? 1 : -1;
    w->sty = dy > 0.0f ? 1 : -1;
    w->tdx = dx != 0.0f ? fabsf(1.0f / dx) : 1e30f;
    w->tdy = dy != 0.0f ? fabsf(1.0f / dy) : 1e30f;
    w->tmx = dx > 0.0f ? ((float)w->ix + 1.0f - b->sx) * w->tdx : (b->sx - (float)w->ix) * w->tdx;
    w->tmy = dy > 0.0f ? ((float)w->iy + 1.0f - b->sy) * w->tdy : (b->sy - (float)w->iy) * w->tdy;
    if (dx == 0.0f) w->tmx = 1e30f;
    if (dy == 0.0f) w->tmy = 1e30f;
    /* the step count is fixed in advance, so the walk always ends */
    w->n = (w->ex > w->ix ? w->ex - w->ix : w->ix - w->ex) +
           (w->ey > w->iy ? w->ey - w->iy : w->iy - w->ey);
    w->t = 0.0f;
    /* set by polyc__walk_enter; until then steps count down from far away
     * (polyc__traverse never calls it: no use of indeterminate values) */
    w->idx = 0;
    w->left_x = w->left_y = INT32_MAX;
}

/* To the next cell. Returns 1 when it left the tile (or the grid): then
 * polyc__walk_enter must run before idx is used again. */
static inline int polyc__walk_step(polyc__walk *w)
{
    w->n--;
    if (w->tmx < w->tmy) {
        w->t = w->tmx;
        w->tmx += w->tdx;
        w->ix += w->stx;
        w->idx += w->stx;
        return --w->left_x < 0;
    }
    w->t = w->tmy;
    w->tmy += w->tdy;
    w->iy += w->sty;
    w->idx += w->sty * POLYC__TILE_SIDE;
    return --w->left_y < 0;
}

/* Sets idx and the steps left before the walk leaves the current cell's
 * tile or the width x height grid; 0 when the cell is outside the grid. */
static inline int polyc__walk_enter(polyc__walk *w, int32_t width, int32_t height)
{
    if (w->ix < 0 || w->iy < 0 || w->ix >= width || w->iy >= height)
        return 0;
    const int32_t m = POLYC__TILE_SIDE - 1;
    w->idx = polyc__cell_index(w->ix, w->iy);
    w->left_x = w->stx > 0 ? ((w->ix | m) < width ? w->ix | m : width - 1) - w->ix : w->ix & m;
    w->left_y = w->sty > 0 ? ((w->iy | m) < height ? w->iy | m : height - 1) - w->iy : w->iy & m;
    return 1;
}

#endif
