/* mapfile_image.c - a ROS map's image, PGM or PNG, to OccupancyGrid cells
 * (mapfile.h), as the tool (load.c) and the Python binding read it.
 * Takes: the image file's bytes and the map YAML. Gives: the cells, the
 * image's size and a short description, or the reader's message. */
#include "mapfile.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int mapfile_image_read(mapfile_image *m, const uint8_t *data, size_t len, const char *name,
                       const mapfile_yaml *y)
{
    return mapfile_image_read_capped(m, data, len, name, y, 0);
}

int mapfile_image_read_capped(mapfile_image *m, const uint8_t *data, size_t len,
                              const char *name, const mapfile_yaml *y, size_t max_bytes)
{
    memset(m, 0, sizeof *m);
    if (mapfile_is_png(data, len)) {
        /* (read and converted in one go: its pixels are not kept) */
        mapfile_png p;
        if (mapfile_png_read_capped(&p, data, len, name, y, &m->cells, max_bytes)) {
            m->no_memory = p.no_memory;
            m->need_bytes = p.need_bytes;
            m->width = p.width;
            m->height = p.height;
            memcpy(m->error, p.error, sizeof m->error);
            return -1;
        }
        m->width = p.width;
        m->height = p.height;
        snprintf(m->kind, sizeof m->kind, "PNG, %u-bit %s%s%s", p.bit_depth,
                 mapfile_png_color_name(p.color_type),
                 p.alpha && p.color_type != 4 && p.color_type != 6 ? " with tRNS" : "",
                 p.interlaced ? ", interlaced" : "");
        return 0;
    }
    mapfile_pgm p;
    int bad = mapfile_pgm_parse_capped(&p, data, len, name, max_bytes);
    m->need_bytes = p.need_bytes;
    if (p.need_bytes) {
        m->width = p.width;
        m->height = p.height;
    }
    if (!bad && !(m->cells = malloc((size_t)p.width * p.height))) {
        m->no_memory = 1;
        snprintf(p.error, sizeof p.error, "%s: out of memory: %zu bytes for the map's cells", name,
                 (size_t)p.width * p.height);
    }
    if (bad || !m->cells) {
        memcpy(m->error, p.error, sizeof m->error);
        mapfile_pgm_free(&p);
        return -1;
    }
    mapfile_to_cells(&p, y, m->cells);
    m->width = p.width;
    m->height = p.height;
    snprintf(m->kind, sizeof m->kind, "%s, maxval %u", p.plain ? "P2" : "P5", (unsigned)p.maxval);
    mapfile_pgm_free(&p);
    return 0;
}
