/* gridimage.h - the library's hit/miss grid as map_saver's trinary image:
 * what `polyc grid` writes, shared with the benchmark.
 *
 * Takes a context after polyc_build_grid; gives one pixel per cell
 * (mapfile_grid_pixel: occupied 0, free 254, unknown 205), rows top first as
 * the PGM stores them, with the grid's origin corner and cell size.
 *
 * Memory: gridimage_make mallocs pixels; gridimage_free releases them.
 *
 * SPDX-License-Identifier: MIT
 */
#ifndef POLYC_GRIDIMAGE_H
#define POLYC_GRIDIMAGE_H

#include <stdint.h>

#include "polyc.h"

typedef struct gridimage {
    uint8_t *pixels;           /* width * height, row 0 the top (the grid's last row) */
    uint32_t width, height;
    float cell_m;
    double origin_x_m, origin_y_m;  /* the grid's cell (0, 0) lower-left corner */
    uint64_t counts[256];      /* pixels of each value */
} gridimage;

enum { GRIDIMAGE_OK = 0, GRIDIMAGE_LIBRARY = -1, GRIDIMAGE_TOO_LARGE = -2,
       GRIDIMAGE_NOMEM = -3 };

/* Fills *img from the context's grid. Returns GRIDIMAGE_OK;
 * GRIDIMAGE_LIBRARY with *status set if polyc_grid_info or polyc_grid_cell
 * failed; GRIDIMAGE_TOO_LARGE (width, height, cell_m set) if the grid is
 * empty or holds more than MAPFILE_MAX_CELLS cells; GRIDIMAGE_NOMEM. On
 * failure img->pixels is NULL. */
int gridimage_make(const polyc_ctx *ctx, gridimage *img, polyc_status *status);
void gridimage_free(gridimage *img);

#endif /* POLYC_GRIDIMAGE_H */
