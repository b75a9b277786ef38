/* gridimage.c - the library's hit/miss grid as map_saver's trinary image
 * (see gridimage.h): takes a context's grid, gives one pixel per cell.
 */
#include "gridimage.h"

#include <stdlib.h>
#include <string.h>

#include "mapfile.h"

int gridimage_make(const polyc_ctx *ctx, gridimage *img, polyc_status *status)
{
    polyc_status st;
    memset(img, 0, sizeof *img);
    *status = POLYC_OK;
    st = polyc_grid_info(ctx, &img->origin_x_m, &img->origin_y_m, &img->cell_m, &img->width,
                         &img->height);
    if (st != POLYC_OK) {
        *status = st;
        return GRIDIMAGE_LIBRARY;
    }
    if ((uint64_t)img->width * img->height > MAPFILE_MAX_CELLS || img->width == 0 ||
        img->height == 0)
        return GRIDIMAGE_TOO_LARGE;
    img->pixels = malloc((size_t)img->width * img->height);
    if (!img->pixels)
        return GRIDIMAGE_NOMEM;
    for (uint32_t row = 0; row < img->height; row++) {   /* the PGM's first row is the top */
        uint32_t iy = img->height - 1u - row;
        for (uint32_t ix = 0; ix < img->width; ix++) {
            uint32_t hits = 0, misses = 0;
            if ((st = polyc_grid_cell(ctx, ix, iy, &hits, &misses, NULL)) != POLYC_OK) {
                *status = st;
                gridimage_free(img);
                return GRIDIMAGE_LIBRARY;
            }
            uint8_t px = mapfile_grid_pixel(hits, misses);
            img->pixels[(size_t)row * img->width + ix] = px;
            img->counts[px]++;
        }
    }
    return GRIDIMAGE_OK;
}

void gridimage_free(gridimage *img)
{
    free(img->pixels);
    img->pixels = NULL;
}
