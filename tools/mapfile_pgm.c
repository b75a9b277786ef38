/* mapfile_pgm.c - a ROS map's image in, and map_saver's files out
 * (mapfile.h; the YAML is read by mapfile.c).
 * Takes: a PGM file's bytes (P5 or P2), or a hit/miss grid's pixels. Gives:
 * the image's samples and their OccupancyGrid values as nav2's map_server
 * computes them, or map_saver's PGM and YAML text; one "NAME: byte N:"
 * message on failure. Rules are in docs/formats.md ("ROS maps"). */
#include "mapfile.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "textesc.h"

/* ---- the PGM ---- */

typedef struct pgm_reader {
    mapfile_pgm *p;
    const char *name;
    const uint8_t *d;
    size_t len;
    size_t pos;
} pgm_reader;

void mapfile_byte_error(char *error, size_t cap, const char *name, size_t at, const char *fmt,
                        va_list ap)
{
    char msg[400];
    vsnprintf(msg, sizeof msg, fmt, ap);
    snprintf(error, cap, "%s: byte %llu: %s", name, (unsigned long long)at, msg);
}

static int pfail(pgm_reader *r, size_t at, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    mapfile_byte_error(r->p->error, sizeof r->p->error, r->name, at, fmt, ap);
    va_end(ap);
    return -1;
}

static int pgm_space(uint8_t c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

/* Skips whitespace and '#' comments (to the end of their line). */
static void pgm_skip(pgm_reader *r)
{
    while (r->pos < r->len) {
        if (pgm_space(r->d[r->pos])) {
            r->pos++;
        } else if (r->d[r->pos] == '#') {
            while (r->pos < r->len && r->d[r->pos] != '\n' && r->d[r->pos] != '\r')
                r->pos++;
        } else {
            break;
        }
    }
}

/* A decimal number of the header or of a P2 sample, at most `max`; *at
 * gets its offset. 0 or -1. */
static int pgm_number(pgm_reader *r, const char *what, uint64_t max, uint64_t *out, size_t *at)
{
    textesc_excerpt e;
    pgm_skip(r);
    *at = r->pos;
    if (r->pos >= r->len)
        return pfail(r, r->pos, "the file ends before the %s (truncated)", what);
    uint64_t v = 0;
    size_t start = r->pos;
    while (r->pos < r->len && r->d[r->pos] >= '0' && r->d[r->pos] <= '9') {
        v = v * 10u + (uint64_t)(r->d[r->pos] - '0');
        if (v > max)
            return pfail(r, start, "%s above %llu", what, (unsigned long long)max);
        r->pos++;
    }
    if (r->pos == start || (r->pos < r->len && !pgm_space(r->d[r->pos]) && r->d[r->pos] != '#')) {
        size_t end = r->pos;
        while (end < r->len && !pgm_space(r->d[end]) && end - start < 24)
            end++;
        if (end == start)
            end++;
        return pfail(r, start, "%s is not a number: '%s'", what,
                     textesc_quote(&e, (const char *)r->d + start, end - start));
    }
    *out = v;
    return 0;
}

int mapfile_pgm_parse(mapfile_pgm *p, const uint8_t *data, size_t len, const char *name)
{
    return mapfile_pgm_parse_capped(p, data, len, name, 0);
}

int mapfile_pgm_parse_capped(mapfile_pgm *p, const uint8_t *data, size_t len, const char *name,
                             size_t max_bytes)
{
    pgm_reader r = {p, name, data, len, 0};
    textesc_excerpt e;
    memset(p, 0, sizeof *p);
    if (len >= 8 && memcmp(data, "\x89PNG\r\n\x1a\n", 8) == 0)
        return pfail(&r, 0, "a PNG image, not a PGM (mapfile_png_read reads it)");
    if (len < 2 || data[0] != 'P' || (data[1] != '5' && data[1] != '2') ||
        (len > 2 && !pgm_space(data[2]) && data[2] != '#'))
        return pfail(&r, 0, "not a PGM (P5 or P2) or PNG image: it starts with '%s'; save the"
                            " map as PGM or PNG",
                     textesc_quote(&e, (const char *)data, len < 4 ? len : 4));
    p->plain = data[1] == '2';
    r.pos = 2;
    uint64_t w, h, maxval;
    size_t at_w, at_h, at_m;
    if (pgm_number(&r, "width", MAPFILE_MAX_CELLS, &w, &at_w) ||
        pgm_number(&r, "height", MAPFILE_MAX_CELLS, &h, &at_h))
        return -1;
    if (w == 0 || h == 0)
        return pfail(&r, w == 0 ? at_w : at_h, "%s is 0", w == 0 ? "width" : "height");
    if (w * h > MAPFILE_MAX_CELLS)
        return pfail(&r, at_h, "%llu x %llu pixels: more than %u cells", (unsigned long long)w,
                     (unsigned long long)h, MAPFILE_MAX_CELLS);
    if (pgm_number(&r, "maxval", 65535, &maxval, &at_m))
        return -1;
    if (maxval == 0)
        return pfail(&r, at_m, "maxval is 0 (must be 1..65535)");
    p->width = (uint32_t)w;
    p->height = (uint32_t)h;
    p->maxval = (uint32_t)maxval;
    size_t cells = (size_t)(w * h);
    if (max_bytes && 3 * cells > max_bytes) {  /* the pixels, then the cells */
        p->need_bytes = 3 * cells;
        return pfail(&r, at_w, "%llu x %llu pixels take %zu bytes to read, more than the memory"
                               " budget of %zu", (unsigned long long)w, (unsigned long long)h,
                     3 * cells, max_bytes);
    }
    if (!p->plain) {
        if (r.pos >= len)
            return pfail(&r, r.pos, "the file ends after maxval: no pixel data (truncated)");
        if (!pgm_space(data[r.pos]))
            return pfail(&r, r.pos, "maxval must be followed by one whitespace byte");
        size_t start = r.pos + 1, bps = maxval > 255 ? 2 : 1, need = cells * bps;
        size_t have = len - start;
        if (have < need)
            return pfail(&r, len, "truncated: %zu bytes of pixel data, %llu x %llu at %zu bytes"
                                  " a pixel need %zu", have, (unsigned long long)w,
                         (unsigned long long)h, bps, need);
        if (have > need)
            return pfail(&r, start + need, "%zu bytes after the pixel data (trailing garbage,"
                                           " or the size does not match)", have - need);
        /* allocated only now: the file holds every pixel */
        if (!(p->samples = malloc(cells * sizeof *p->samples)))
            return pfail(&r, start, "out of memory for %zu pixels", cells);
        for (size_t i = 0; i < cells; i++) {
            const uint8_t *q = data + start + i * bps;
            uint32_t v = bps == 2 ? (uint32_t)q[0] << 8 | q[1] : q[0];
            if (v > maxval)
                return pfail(&r, start + i * bps, "pixel value %u above maxval %u", (unsigned)v,
                             (unsigned)maxval);
            p->samples[i] = (uint16_t)v;
        }
        return 0;
    }
    /* P2: a first pass checks every value, so that memory is taken only for
     * a file that holds them all; the second stores them */
    size_t raster = r.pos;
    for (int pass = 0; pass < 2; pass++) {
        r.pos = raster;
        if (pass == 1 && !(p->samples = malloc(cells * sizeof *p->samples)))
            return pfail(&r, raster, "out of memory for %zu pixels", cells);
        for (size_t i = 0; i < cells; i++) {
            uint64_t v;
            size_t at;
            pgm_skip(&r);
            if (r.pos >= len)
                return pfail(&r, len, "truncated: %zu of %zu pixel values (%llu x %llu)", i,
                             cells, (unsigned long long)w, (unsigned long long)h);
            if (pgm_number(&r, "pixel value", 999999, &v, &at))
                return -1;
            if (v > maxval)
                return pfail(&r, at, "pixel value %llu above maxval %u", (unsigned long long)v,
                             (unsigned)maxval);
            if (pass == 1)
                p->samples[i] = (uint16_t)v;
        }
        pgm_skip(&r);
        if (r.pos < len)
            return pfail(&r, r.pos, "more than %llu x %llu pixel values (trailing garbage, or"
                                    " the size does not match)", (unsigned long long)w,
                         (unsigned long long)h);
    }
    return 0;
}

void mapfile_pgm_free(mapfile_pgm *p)
{
    free(p->samples);
    p->samples = NULL;
}

/* ---- conversion ---- */

int8_t mapfile_cell_value(uint32_t sample, uint32_t maxval, const mapfile_yaml *y)
{
    return mapfile_shade_value((double)sample / (double)maxval, 1, y); /* (PGM has no alpha) */
}

int8_t mapfile_shade_value(double shade, int opaque, const mapfile_yaml *y)
{
    if (y->mode == MAPFILE_RAW) {
        double v = round(shade * 255.0);
        if (v >= 0.0 && v <= 100.0)
            return (int8_t)v;
        return -1;
    }
    double occ = y->negate ? shade : 1.0 - shade;
    if (y->mode == MAPFILE_SCALE && !opaque)
        return -1;
    if (y->occupied_thresh < occ)
        return 100;
    if (occ < y->free_thresh)
        return 0;
    if (y->mode == MAPFILE_TRINARY)
        return -1;
    return (int8_t)rint((occ - y->free_thresh) / (y->occupied_thresh - y->free_thresh) * 100.0);
}

void mapfile_to_cells(const mapfile_pgm *p, const mapfile_yaml *y, int8_t *cells)
{
    for (uint32_t row = 0; row < p->height; row++) {
        const uint16_t *in = p->samples + (size_t)row * p->width;
        int8_t *out = cells + (size_t)(p->height - 1 - row) * p->width;
        for (uint32_t i = 0; i < p->width; i++)
            out[i] = mapfile_cell_value(in[i], p->maxval, y);
    }
}

/* ---- writing ---- */

uint8_t mapfile_grid_pixel(uint32_t hits, uint32_t misses)
{
    if (hits == 0 && misses == 0)
        return MAPFILE_PIXEL_UNKNOWN;
    double m = (double)hits / ((double)hits + (double)misses);
    return m > MAPFILE_OCCUPIED_THRESH ? MAPFILE_PIXEL_OCCUPIED
           : m < MAPFILE_FREE_THRESH   ? MAPFILE_PIXEL_FREE
                                       : MAPFILE_PIXEL_UNKNOWN;
}

int mapfile_write_pgm(FILE *f, const uint8_t *pixels, uint32_t width, uint32_t height,
                      double resolution_m)
{
    fprintf(f, "P5\n# CREATOR: polyc grid %.3f m/pix\n%u %u\n255\n", resolution_m,
            (unsigned)width, (unsigned)height);
    fwrite(pixels, 1, (size_t)width * height, f);
    return ferror(f) ? -1 : 0;
}

/* A name that YAML reads back as written: plain if it is made of safe
 * characters, else single-quoted (quotes doubled). */
static void yaml_string(FILE *f, const char *s)
{
    int plain = *s != '\0' && *s != '-';
    for (const char *q = s; *q && plain; q++)
        plain = (*q >= 'a' && *q <= 'z') || (*q >= 'A' && *q <= 'Z') || (*q >= '0' && *q <= '9') ||
                *q == '_' || *q == '-' || *q == '.' || *q == '/' || *q == '+';
    if (plain) {
        fputs(s, f);
        return;
    }
    fputc('\'', f);
    for (; *s; s++) {
        if (*s == '\'')
            fputc('\'', f);
        fputc(*s, f);
    }
    fputc('\'', f);
}

int mapfile_write_yaml(FILE *f, const char *image_name, double resolution_m,
                       double origin_x_m, double origin_y_m)
{
    fputs("image: ", f);
    yaml_string(f, image_name);
    fprintf(f, "\nresolution: %f\norigin: [%f, %f, %f]\nnegate: 0\noccupied_thresh: %g\n"
               "free_thresh: %g\n\n",
            resolution_m, origin_x_m, origin_y_m, 0.0, MAPFILE_OCCUPIED_THRESH,
            MAPFILE_FREE_THRESH);
    return ferror(f) ? -1 : 0;
}
