/* polyc_io.c - the polyc tool's readers for the Python binding: a laser log
 * (tools/scanlog.c) into polyc_scan records, a map_server map YAML and its
 * PGM or PNG (tools/mapfile*.c) into a polyc_occupancy_grid, read as `polyc` reads
 * them; and a context's hit/miss grid as the image `polyc grid` writes
 * (tools/gridimage.c). Built into the binding's libpolyc.so with the
 * library; the library itself (src/) stays without allocation and I/O.
 *
 * Memory: each reader mallocs a handle that owns everything it points to;
 * the matching *_free releases it. Errors: -1 with the reader's message
 * ("NAME:LINE: what is wrong", as the tool prints it) in error[error_size];
 * the file named not opened (missing, not allowed, a directory): its errno
 * value (> 0), and the message too.
 *
 * SPDX-License-Identifier: MIT
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "gridimage.h"
#include "mapfile.h"
#include "polyc.h"
#include "readfile.h"
#include "scanlog.h"

#if defined(__GNUC__)
#define POLYC_IO_API __attribute__((visibility("default")))
#else
#define POLYC_IO_API
#endif

/* Bumped when a function below changes; the binding checks it. */
#define POLYC_IO_VERSION 2

POLYC_IO_API int polyc_io_version(void);
POLYC_IO_API size_t polyc_io_struct_size(const char *name);
POLYC_IO_API int polyc_io_read_log(const char *path, double max_range_m, scanlog **out,
                                   char *error, size_t error_size);
POLYC_IO_API uint32_t polyc_io_log_count(const scanlog *log);
POLYC_IO_API const polyc_scan *polyc_io_log_scans(const scanlog *log);
POLYC_IO_API void polyc_io_log_free(scanlog *log);

typedef struct polyc_io_map {
    polyc_occupancy_grid grid;     /* cells owned by the handle */
    char *image_path;              /* the image (PGM or PNG) as opened */
    double occupied_thresh;        /* the YAML's, as it converted the pixels */
    double free_thresh;
    int mode;                      /* enum mapfile_mode */
    int negate;
} polyc_io_map;

POLYC_IO_API int polyc_io_read_map(const char *path, polyc_io_map **out, char *error,
                                   size_t error_size);
POLYC_IO_API void polyc_io_map_free(polyc_io_map *map);
POLYC_IO_API int polyc_io_grid_image(const polyc_ctx *ctx, gridimage **out,
                                     polyc_status *status);
POLYC_IO_API void polyc_io_grid_image_free(gridimage *img);

int polyc_io_version(void)
{
    return POLYC_IO_VERSION;
}

/* sizeof of the structs the binding reads ("polyc_io_map", "gridimage"), 0
 * if unknown. */
size_t polyc_io_struct_size(const char *name)
{
    if (name && strcmp(name, "polyc_io_map") == 0)
        return sizeof(polyc_io_map);
    if (name && strcmp(name, "gridimage") == 0)
        return sizeof(gridimage);
    return 0;
}

static int fail(char *error, size_t error_size, const char *fmt, const char *a, const char *b)
{
    if (error && error_size)
        snprintf(error, error_size, fmt, a, b);
    return -1;
}

/* ---- logs ---- */

/* Reads the log at path as `polyc LOG` does (`--max-range` is max_range_m;
 * 0: none). 0 and *out; -1 and the message; the errno value if path is not
 * opened (EISDIR for a directory). */
int polyc_io_read_log(const char *path, double max_range_m, scanlog **out, char *error,
                      size_t error_size)
{
    if (!path || !out)
        return fail(error, error_size, "%s%s", "no path given", "");
    *out = NULL;
    scanlog *log = calloc(1, sizeof *log);
    if (!log)
        return fail(error, error_size, "%s%s", "out of memory", "");
    errno = 0;
    FILE *f = fopen(path, "rb");
    struct stat st;
    int err = 0;
    if (!f || fstat(fileno(f), &st) != 0)
        err = errno ? errno : EIO;
    else if (S_ISDIR(st.st_mode))
        err = EISDIR;
    if (err) {
        if (f)
            fclose(f);
        free(log);
        fail(error, error_size, "%s: %s", path, strerror(err));
        return err;
    }
    scanlog_opts opts = {max_range_m};
    int bad = scanlog_read(log, f, path, &opts);
    fclose(f);
    if (bad) {
        fail(error, error_size, "%s%s", log->error, "");
        polyc_io_log_free(log);
        return -1;
    }
    *out = log;
    return 0;
}

uint32_t polyc_io_log_count(const scanlog *log)
{
    return log ? log->count : 0;
}

const polyc_scan *polyc_io_log_scans(const scanlog *log)
{
    return log ? log->scans : NULL;
}

void polyc_io_log_free(scanlog *log)
{
    if (!log)
        return;
    scanlog_free(log);
    free(log);
}

/* ---- maps ---- */

/* Reads a map YAML, its image (map_server's rule for where it is) and
 * converts its pixels as `polyc map.yaml` does. 0 and *out; -1 and the
 * message; the errno value if the YAML is not opened (its image not
 * opened is -1: a bad map). */
int polyc_io_read_map(const char *path, polyc_io_map **out, char *error, size_t error_size)
{
    if (!path || !out)
        return fail(error, error_size, "%s%s", "no path given", "");
    *out = NULL;
    char *text = NULL;
    size_t len = 0;
    int err = readfile(path, MAPFILE_MAX_YAML_BYTES, &text, &len);
    if (err == READFILE_TOO_LARGE)
        return fail(error, error_size, "%s: %s", path, "too large to be a map YAML");
    if (err == READFILE_NOT_FILE)
        return fail(error, error_size, "%s: %s", path, "not a regular file");
    if (err) {
        fail(error, error_size, "%s: %s", path, strerror(err));
        return err;
    }
    mapfile_yaml yaml;
    memset(&yaml, 0, sizeof yaml);
    int bad = mapfile_yaml_parse(&yaml, text, len, path);
    free(text);
    if (bad) {
        fail(error, error_size, "%s%s", yaml.error, "");
        mapfile_yaml_free(&yaml);
        return -1;
    }
    polyc_io_map *m = calloc(1, sizeof *m);
    char *image = mapfile_image_path(path, yaml.image);
    if (!m || !image) {
        free(m);
        free(image);
        mapfile_yaml_free(&yaml);
        return fail(error, error_size, "%s%s", "out of memory", "");
    }
    m->image_path = image;
    err = readfile(image, MAPFILE_MAX_PGM_BYTES, &text, &len);
    if (err) {
        if (error && error_size)
            snprintf(error, error_size, "%s:%u: image %s: %s", path, (unsigned)yaml.image_line,
                     image, err == READFILE_TOO_LARGE ? "too large"
                            : err == READFILE_NOT_FILE ? "not a regular file"
                                                       : strerror(err));
        mapfile_yaml_free(&yaml);
        polyc_io_map_free(m);
        return -1;
    }
    mapfile_image img;
    bad = mapfile_image_read(&img, (const uint8_t *)text, len, image, &yaml);
    free(text);
    if (bad) {
        fail(error, error_size, "%s%s", img.error, "");
        mapfile_yaml_free(&yaml);
        polyc_io_map_free(m);
        return -1;
    }
    int8_t *cells = img.cells;
    m->grid.width = img.width;
    m->grid.height = img.height;
    m->grid.resolution_m = (float)yaml.resolution_m;
    m->grid.origin_x_m = yaml.origin_x_m;
    m->grid.origin_y_m = yaml.origin_y_m;
    m->grid.origin_yaw_rad = yaml.origin_yaw_rad;
    m->grid.cells = cells;
    m->occupied_thresh = yaml.occupied_thresh;
    m->free_thresh = yaml.free_thresh;
    m->mode = yaml.mode;
    m->negate = yaml.negate;
    mapfile_yaml_free(&yaml);
    *out = m;
    return 0;
}

void polyc_io_map_free(polyc_io_map *m)
{
    if (!m)
        return;
    free((void *)m->grid.cells);
    free(m->image_path);
    free(m);
}

/* ---- the grid as an image ---- */

/* The context's hit/miss grid (after polyc_build_grid) as map_saver's
 * trinary image, as `polyc grid` writes it: GRIDIMAGE_OK and *out, or a
 * GRIDIMAGE_* code (GRIDIMAGE_LIBRARY with *status, GRIDIMAGE_TOO_LARGE
 * with the size in *out, which is then freed by polyc_io_grid_image_free
 * too). */
int polyc_io_grid_image(const polyc_ctx *ctx, gridimage **out, polyc_status *status)
{
    *out = calloc(1, sizeof **out);
    if (!*out)
        return GRIDIMAGE_NOMEM;
    *status = POLYC_OK;
    return gridimage_make(ctx, *out, status);
}

void polyc_io_grid_image_free(gridimage *img)
{
    if (!img)
        return;
    gridimage_free(img);
    free(img);
}
