/* mapfile.h - ROS map_server maps: the map YAML and its image (PGM, PNG) in,
 * nav_msgs/OccupancyGrid cell values out (converted as nav2's map_server
 * does), and a hit/miss grid out as map_saver writes a map.
 * Rules: docs/formats.md ("ROS maps"). All memory is owned by the structs. */
#ifndef POLYC_MAPFILE_H
#define POLYC_MAPFILE_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "polyc.h"

/* Limits on untrusted input (docs/security.md). */
#define MAPFILE_MAX_YAML_BYTES  (1u << 20)    /* the map YAML */
#define MAPFILE_MAX_PGM_BYTES   (1u << 30)    /* the image file */
#define MAPFILE_MAX_CELLS       (1u << 28)    /* width x height */
#define MAPFILE_MAX_IMAGE_NAME  4096u         /* bytes of the `image` value */
#define MAPFILE_MAX_ORIGIN_M    1e6           /* |origin x|, |origin y| */
#define MAPFILE_MAX_YAW_RAD     100.0         /* |origin yaw| (the library's bound) */
#define MAPFILE_MIN_RESOLUTION_M 1e-4         /* the library's bounds */
#define MAPFILE_MAX_RESOLUTION_M 100.0

/* map_saver's pixel values and thresholds (what `polyc grid` writes). */
#define MAPFILE_PIXEL_OCCUPIED  0
#define MAPFILE_PIXEL_FREE      254
#define MAPFILE_PIXEL_UNKNOWN   205
#define MAPFILE_OCCUPIED_THRESH 0.65
#define MAPFILE_FREE_THRESH     0.196

enum mapfile_mode { MAPFILE_TRINARY = 0, MAPFILE_SCALE = 1, MAPFILE_RAW = 2 };

/* What the YAML says. Line numbers are 1-based, 0 for a key not given. */
typedef struct mapfile_yaml {
    char *image;               /* the `image` value as written (unquoted), owned */
    double resolution_m;       /* metres per cell, > 0 */
    double origin_x_m;         /* pose of the lower-left cell's outer corner */
    double origin_y_m;
    double origin_yaw_rad;
    int negate;                /* 0 or 1 */
    double occupied_thresh;    /* in [0, 1], above free_thresh */
    double free_thresh;
    int mode;                  /* enum mapfile_mode; trinary if `mode` is absent */
    uint32_t image_line;       /* where `image`, `resolution` and `origin` are, */
    uint32_t resolution_line;  /* for messages about what they give */
    uint32_t origin_line;
    uint32_t lines;            /* lines read */
    char error[512];           /* "NAME:LINE: what is wrong" after a failure */
} mapfile_yaml;

/* Does this look like a map YAML rather than a laser log: is its first line
 * that is neither blank nor a comment a `key:` line (or `---`)? `head` is
 * the start of the file (any length; a line cut off at the end counts as
 * far as it goes). */
int mapfile_is_yaml(const char *head, size_t len);

/* Parses a map YAML of len bytes (named `name` in messages). Returns 0, or
 * -1 with y->error set; either way call mapfile_yaml_free. */
int mapfile_yaml_parse(mapfile_yaml *y, const char *text, size_t len, const char *name);
void mapfile_yaml_free(mapfile_yaml *y);

/* The image's path: `image` itself if absolute, else `image` in the folder
 * of yaml_path (map_server's rule). malloc'd; NULL if out of memory. */
char *mapfile_image_path(const char *yaml_path, const char *image);

/* A PGM image, rows top first as stored. */
typedef struct mapfile_pgm {
    uint32_t width, height;
    uint32_t maxval;           /* 1..65535 */
    int plain;                 /* 1: P2 (ASCII), 0: P5 (binary) */
    uint16_t *samples;         /* width * height values in 0..maxval, owned */
    size_t need_bytes;         /* over the budget: pixels and cells' bytes; else 0 */
    char error[512];           /* "NAME: byte N: what is wrong" after a failure */
} mapfile_pgm;

/* Parses a whole PGM file of len bytes (P5 or P2). Returns 0, or -1 with
 * p->error set (byte N is a 0-based offset into the file); either way call
 * mapfile_pgm_free. */
int mapfile_pgm_parse(mapfile_pgm *p, const uint8_t *data, size_t len, const char *name);
/* The same with a memory budget: a PGM whose pixels (2 bytes each) and
 * cells (1 byte each) would take more than max_bytes (0: no budget) is
 * refused before its pixels are allocated, with p->need_bytes set. */
int mapfile_pgm_parse_capped(mapfile_pgm *p, const uint8_t *data, size_t len, const char *name,
                             size_t max_bytes);
void mapfile_pgm_free(mapfile_pgm *p);

/* One pixel's OccupancyGrid value (-1 unknown, 0..100) under the YAML's
 * mode, negate and thresholds: nav2 map_server's rule (docs/formats.md),
 * from a gray sample, or from the pixel's shade (0 black .. 1 white) and
 * whether it is opaque (a pixel with any transparency is -1 in `scale`). */
int8_t mapfile_cell_value(uint32_t sample, uint32_t maxval, const mapfile_yaml *y);
int8_t mapfile_shade_value(double shade, int opaque, const mapfile_yaml *y);

/* "NAME: byte N: " and the message, into error[cap]: the image readers'
 * failures (mapfile_pgm.c). */
void mapfile_byte_error(char *error, size_t cap, const char *name, size_t at, const char *fmt,
                        va_list ap);

/* A PNG image's header (mapfile_png.c). */
typedef struct mapfile_png {
    uint32_t width, height;
    unsigned bit_depth;        /* 1, 2, 4, 8 or 16 */
    unsigned color_type;       /* 0 gray, 2 RGB, 3 palette, 4 gray+alpha, 6 RGBA */
    int interlaced;            /* 1: Adam7 */
    int alpha;                 /* an alpha channel or a tRNS chunk (map_server's "matte") */
    int no_memory;             /* the failure was an allocation's */
    size_t need_bytes;         /* over the budget: the bytes decoding needs; else 0 */
    char error[512];           /* "NAME: byte N: what is wrong" after a failure */
} mapfile_png;

/* Whether the bytes start with PNG's signature; a colour type's name
 * ("gray", "RGB", "palette", "gray+alpha", "RGBA"). */
int mapfile_is_png(const uint8_t *data, size_t len);
const char *mapfile_png_color_name(unsigned type);

/* Reads a whole PNG file of len bytes and converts every pixel under the
 * YAML (docs/formats.md, "The image: PNG"): *cells, malloc'd, width *
 * height values in the order of mapfile_to_cells. Returns 0, or -1 with
 * p->error set (byte N a 0-based offset into the file; out of memory
 * too) and *cells NULL. */
int mapfile_png_read(mapfile_png *p, const uint8_t *data, size_t len, const char *name,
                     const mapfile_yaml *y, int8_t **cells);
/* The same with a memory budget: an image whose decoding (its compressed
 * data, the unpacked rows and the cells) would take more than max_bytes
 * (0: no budget) is refused before anything is allocated, with
 * p->need_bytes set. */
int mapfile_png_read_capped(mapfile_png *p, const uint8_t *data, size_t len, const char *name,
                            const mapfile_yaml *y, int8_t **cells, size_t max_bytes);

/* The image, PGM or PNG (told by its first bytes), converted under the
 * YAML (mapfile_image.c): cells malloc'd (the caller frees them), its size
 * and a description for --stats ("P5, maxval 255", "PNG, 8-bit RGBA").
 * Returns 0, or -1 with error set ("NAME: byte N: ...") and cells NULL. */
typedef struct mapfile_image {
    uint32_t width, height;
    int8_t *cells;
    char kind[64];
    int no_memory;             /* the failure was an allocation's */
    size_t need_bytes;         /* over the budget: the bytes decoding needs; else 0 */
    char error[512];
} mapfile_image;
int mapfile_image_read(mapfile_image *m, const uint8_t *data, size_t len, const char *name,
                       const mapfile_yaml *y);
/* The same within max_bytes for the decoding (0: no budget): over it, -1
 * with need_bytes set (the bytes it would take) and nothing allocated. */
int mapfile_image_read_capped(mapfile_image *m, const uint8_t *data, size_t len,
                              const char *name, const mapfile_yaml *y, size_t max_bytes);

/* The library's grid of a map as `polyc map.yaml` reads it: the image's
 * size, the YAML's resolution and origin pose, and cells (OccupancyGrid
 * order, as mapfile_to_cells gives them; only pointed to). */
void mapfile_grid(const mapfile_yaml *y, uint32_t width, uint32_t height, const int8_t *cells,
                  polyc_occupancy_grid *g);

/* Every pixel converted: cells[(height - 1 - row) * width + column], i.e.
 * OccupancyGrid order with row 0 at the bottom. cells: width * height. */
void mapfile_to_cells(const mapfile_pgm *p, const mapfile_yaml *y, int8_t *cells);

/* map_saver's trinary pixel for one hit/miss cell: occupied if
 * hits/(hits+misses) > 0.65, free if < 0.196, unknown otherwise (and
 * without counts). */
uint8_t mapfile_grid_pixel(uint32_t hits, uint32_t misses);

/* map_saver's files for a width x height image of `pixels` (rows top
 * first): the P5 header and bytes, and the YAML naming `image_name`, with
 * origin (x, y, 0). Each returns 0, or -1 if the stream reported an error. */
int mapfile_write_pgm(FILE *f, const uint8_t *pixels, uint32_t width, uint32_t height,
                      double resolution_m);
int mapfile_write_yaml(FILE *f, const char *image_name, double resolution_m,
                       double origin_x_m, double origin_y_m);

#endif /* POLYC_MAPFILE_H */
