/* mapfile_png.c - a ROS map's image as PNG (mapfile.h), which nav2's
 * map_saver writes for its `scale` mode.
 * Takes: a PNG file's bytes and the map YAML. Gives: each pixel's
 * OccupancyGrid value as nav2's map_server computes it from the pixel's
 * colour channels and alpha; one "NAME: byte N:" message on failure.
 * Rules are in docs/formats.md ("The image: PNG"). */
#include "mapfile.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "inflate.h"
#include "textesc.h"

typedef struct png_reader {
    mapfile_png *p;
    const char *name;
    const uint8_t *d;
    size_t len;
    uint8_t palette[256][3];
    unsigned palette_n;
    uint8_t trns[256];           /* palette alphas (255 past trns_n) */
    unsigned trns_n;
    uint16_t trns_key[3];        /* gray (one) or RGB: the colour drawn transparent */
    int has_trns;
    size_t idat_at, idat_bytes;  /* the first IDAT chunk and the image data's bytes */
    unsigned idat_chunks;
} png_reader;

static int pfail(png_reader *r, size_t at, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    mapfile_byte_error(r->p->error, sizeof r->p->error, r->name, at, fmt, ap);
    va_end(ap);
    return -1;
}

static uint32_t be32(const uint8_t *b)
{
    return (uint32_t)b[0] << 24 | (uint32_t)b[1] << 16 | (uint32_t)b[2] << 8 | b[3];
}

/* The CRC-32 table, made per file (no shared state: the Python binding
 * may read maps from several threads). */
static void crc32_table(uint32_t table[256])
{
    for (uint32_t i = 0; i < 256; i++) {
        uint32_t c = i;
        for (int k = 0; k < 8; k++)
            c = c & 1u ? 0xedb88320u ^ (c >> 1) : c >> 1;
        table[i] = c;
    }
}

static uint32_t crc32_of(const uint32_t table[256], const uint8_t *b, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++)
        c = table[(c ^ b[i]) & 0xffu] ^ (c >> 8);
    return c ^ 0xffffffffu;
}

int mapfile_is_png(const uint8_t *data, size_t len)
{
    return len >= 8 && memcmp(data, "\x89PNG\r\n\x1a\n", 8) == 0;
}

const char *mapfile_png_color_name(unsigned type)
{
    switch (type) {
    case 0: return "gray";
    case 2: return "RGB";
    case 3: return "palette";
    case 4: return "gray+alpha";
    default: return "RGBA";
    }
}

static unsigned channels_of(unsigned type)
{
    return type == 2 ? 3u : type == 4 ? 2u : type == 6 ? 4u : 1u;
}

static int ihdr(png_reader *r, size_t at, const uint8_t *c, uint32_t n)
{
    mapfile_png *p = r->p;
    if (n != 13)
        return pfail(r, at, "IHDR of %u bytes (must be 13)", (unsigned)n);
    uint32_t w = be32(c), h = be32(c + 4);
    unsigned depth = c[8], type = c[9];
    if (w == 0 || h == 0 || w > 0x7fffffffu || h > 0x7fffffffu)
        return pfail(r, at + 8, "%u x %u pixels (each must be 1..2^31-1)", (unsigned)w, (unsigned)h);
    if ((uint64_t)w * h > MAPFILE_MAX_CELLS)
        return pfail(r, at + 8, "%u x %u pixels: more than %u cells", (unsigned)w, (unsigned)h,
                     MAPFILE_MAX_CELLS);
    int ok = (type == 0 && (depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16)) ||
             (type == 3 && (depth == 1 || depth == 2 || depth == 4 || depth == 8)) ||
             ((type == 2 || type == 4 || type == 6) && (depth == 8 || depth == 16));
    if (!ok)
        return pfail(r, at + 16, "colour type %u with bit depth %u (not a PNG combination)", type,
                     depth);
    if (c[10] != 0 || c[11] != 0)
        return pfail(r, at + 18, "compression method %u, filter method %u (PNG has only 0 and 0)",
                     (unsigned)c[10], (unsigned)c[11]);
    if (c[12] > 1)
        return pfail(r, at + 20, "interlace method %u (0 or 1)", (unsigned)c[12]);
    p->width = w;
    p->height = h;
    p->bit_depth = depth;
    p->color_type = type;
    p->interlaced = c[12];
    return 0;
}

static int plte(png_reader *r, size_t at, const uint8_t *c, uint32_t n)
{
    unsigned type = r->p->color_type;
    if (type == 0 || type == 4)
        return pfail(r, at, "a palette (PLTE) in a %s image", mapfile_png_color_name(type));
    if (r->palette_n)
        return pfail(r, at, "a second palette (PLTE)");
    if (n == 0 || n % 3 != 0 || n > 768)
        return pfail(r, at, "a palette (PLTE) of %u bytes (3 a colour, 1 to 256 colours)",
                     (unsigned)n);
    unsigned entries = n / 3;
    if (type == 3 && entries > 1u << r->p->bit_depth)
        return pfail(r, at, "%u palette colours for %u-bit indices", entries, r->p->bit_depth);
    memcpy(r->palette, c, n);
    r->palette_n = entries;
    return 0;
}

static int trns(png_reader *r, size_t at, const uint8_t *c, uint32_t n)
{
    unsigned type = r->p->color_type;
    if (type == 4 || type == 6)
        return 0; /* an alpha channel already: ignored, as libpng ignores it */
    if (r->has_trns)
        return pfail(r, at, "a second transparency chunk (tRNS)");
    if (type == 3) {
        if (!r->palette_n)
            return pfail(r, at, "transparency (tRNS) before the palette (PLTE)");
        if (n > r->palette_n)
            return pfail(r, at, "transparency (tRNS) for %u colours, the palette has %u",
                         (unsigned)n, r->palette_n);
        memcpy(r->trns, c, n);
        r->trns_n = n;
    } else {
        uint32_t want = type == 0 ? 2u : 6u;
        if (n != want)
            return pfail(r, at, "transparency (tRNS) of %u bytes in a %s image (must be %u)",
                         (unsigned)n, mapfile_png_color_name(type), (unsigned)want);
        for (uint32_t k = 0; k < n / 2; k++)
            r->trns_key[k] = (uint16_t)(c[2 * k] << 8 | c[2 * k + 1]);
    }
    r->has_trns = 1;
    return 0;
}

/* The chunks, checked (CRC, order) and read; the image data's place. */
static int read_chunks(png_reader *r)
{
    size_t pos = 8;
    int seen_ihdr = 0, in_idat = 0, after_idat = 0;
    uint32_t crc_table[256];
    crc32_table(crc_table);
    for (;;) {
        if (r->len - pos < 12)
            return pfail(r, pos, "the file ends before its IEND chunk (truncated)");
        uint32_t n = be32(r->d + pos);
        const uint8_t *type = r->d + pos + 4;
        textesc_excerpt e;
        const char *tname = textesc_quote(&e, (const char *)type, 4);
        for (int k = 0; k < 4; k++)
            if (!((type[k] >= 'A' && type[k] <= 'Z') || (type[k] >= 'a' && type[k] <= 'z')))
                return pfail(r, pos + 4, "'%s' is not a chunk type (four letters)", tname);
        if (n > 0x7fffffffu)
            return pfail(r, pos, "chunk '%s' of %u bytes (at most 2^31-1)", tname, (unsigned)n);
        if (r->len - pos - 12 < n)
            return pfail(r, pos, "chunk '%s' of %u bytes runs past the end of the file (truncated)",
                         tname, (unsigned)n);
        const uint8_t *c = type + 4;
        if (crc32_of(crc_table, type, (size_t)n + 4) != be32(c + n))
            return pfail(r, pos + 8 + n, "chunk '%s': its CRC does not match (a damaged file)",
                         tname);
        if (!seen_ihdr && memcmp(type, "IHDR", 4) != 0)
            return pfail(r, pos, "the first chunk is '%s', not IHDR", tname);
        int is_idat = memcmp(type, "IDAT", 4) == 0;
        if (in_idat && !is_idat)
            after_idat = 1;
        if (memcmp(type, "IHDR", 4) == 0) {
            if (seen_ihdr)
                return pfail(r, pos, "a second IHDR");
            if (ihdr(r, pos, c, n))
                return -1;
            seen_ihdr = 1;
        } else if (memcmp(type, "PLTE", 4) == 0 || memcmp(type, "tRNS", 4) == 0) {
            if (in_idat)
                return pfail(r, pos, "chunk '%s' after the image data (IDAT)", tname);
            if ((type[0] == 'P' ? plte(r, pos, c, n) : trns(r, pos, c, n)) != 0)
                return -1;
        } else if (is_idat) {
            if (after_idat)
                return pfail(r, pos, "image data (IDAT) in two runs: its chunks must follow one"
                                     " another");
            if (r->p->color_type == 3 && !r->palette_n)
                return pfail(r, pos, "a palette image without a palette (PLTE)");
            if (!in_idat)
                r->idat_at = pos;
            in_idat = 1;
            r->idat_bytes += n;
            r->idat_chunks++;
        } else if (memcmp(type, "IEND", 4) == 0) {
            if (!in_idat)
                return pfail(r, pos, "no image data (IDAT) before IEND");
            return 0; /* (anything after IEND is not read, as libpng does) */
        } else if (!(type[0] & 0x20u)) {
            return pfail(r, pos, "an unknown critical chunk '%s'", tname);
        } /* else an ancillary chunk: skipped */
        pos += 12 + (size_t)n;
    }
}

/* The image data (the IDAT chunks' contents, one after another); the file
 * offset of byte k of them. */
static void gather_idat(const png_reader *r, uint8_t *z)
{
    size_t pos = r->idat_at;
    for (unsigned i = 0; i < r->idat_chunks; i++) {
        uint32_t n = be32(r->d + pos);
        memcpy(z, r->d + pos + 8, n);
        z += n;
        pos += 12 + (size_t)n;
    }
}

static size_t idat_file_offset(const png_reader *r, size_t k)
{
    size_t pos = r->idat_at;
    for (unsigned i = 0; i < r->idat_chunks; i++) {
        uint32_t n = be32(r->d + pos);
        if (k < n || i + 1 == r->idat_chunks)
            return pos + 8 + (k < n ? k : n);
        k -= n;
        pos += 12 + (size_t)n;
    }
    return pos;
}

/* Adam7's passes (one pass of step 1 when not interlaced). */
static const uint8_t PASS_X0[7] = {0, 4, 0, 2, 0, 1, 0}, PASS_Y0[7] = {0, 0, 4, 0, 2, 0, 1};
static const uint8_t PASS_DX[7] = {8, 8, 4, 4, 2, 2, 1}, PASS_DY[7] = {8, 8, 8, 4, 4, 2, 2};

static void pass_size(const mapfile_png *p, int k, uint32_t *w, uint32_t *h)
{
    if (!p->interlaced) {
        *w = p->width;
        *h = p->height;
        return;
    }
    *w = p->width > PASS_X0[k] ? (p->width - PASS_X0[k] + PASS_DX[k] - 1) / PASS_DX[k] : 0;
    *h = p->height > PASS_Y0[k] ? (p->height - PASS_Y0[k] + PASS_DY[k] - 1) / PASS_DY[k] : 0;
}

static size_t row_bytes(const mapfile_png *p, uint32_t w)
{
    return ((size_t)w * channels_of(p->color_type) * p->bit_depth + 7) / 8;
}

static uint8_t paeth(uint8_t a, uint8_t b, uint8_t c)
{
    int pa = abs((int)b - (int)c), pb = abs((int)a - (int)c), pc = abs((int)a + (int)b - 2 * (int)c);
    return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

/* Undoes a row's filter in place (prev: the row above, unfiltered, or NULL). */
static void unfilter(uint8_t *row, const uint8_t *prev, size_t n, size_t bpp, unsigned type)
{
    for (size_t i = 0; i < n; i++) {
        uint8_t a = i >= bpp ? row[i - bpp] : 0, b = prev ? prev[i] : 0;
        uint8_t c = prev && i >= bpp ? prev[i - bpp] : 0;
        switch (type) {
        case 1: row[i] = (uint8_t)(row[i] + a); break;
        case 2: row[i] = (uint8_t)(row[i] + b); break;
        case 3: row[i] = (uint8_t)(row[i] + ((unsigned)a + b) / 2); break;
        case 4: row[i] = (uint8_t)(row[i] + paeth(a, b, c)); break;
        default: break;
        }
    }
}

static unsigned sample_at(const uint8_t *row, uint32_t i, unsigned depth)
{
    if (depth == 16)
        return (unsigned)row[2 * (size_t)i] << 8 | row[2 * (size_t)i + 1];
    if (depth == 8)
        return row[i];
    size_t bit = (size_t)i * depth;
    return (row[bit / 8] >> (8 - depth - bit % 8)) & ((1u << depth) - 1u);
}

/* One pixel's value: its channels' mean (and, in trinary mode, with an
 * alpha, the alpha's too) as map_server's shade; opaque for `scale`. */
static int pixel_value(png_reader *r, const uint8_t *row, uint32_t i, const mapfile_yaml *y,
                       int8_t *out)
{
    const mapfile_png *p = r->p;
    unsigned depth = p->bit_depth, type = p->color_type, ch = channels_of(type);
    unsigned maxv = (1u << depth) - 1u, v[4], a;
    for (unsigned k = 0; k < ch; k++)
        v[k] = sample_at(row, i * ch + k, depth);
    if (type == 3) {
        if (v[0] >= r->palette_n)
            return -1;
        unsigned idx = v[0];
        maxv = 255;
        v[0] = r->palette[idx][0];
        v[1] = r->palette[idx][1];
        v[2] = r->palette[idx][2];
        a = idx < r->trns_n ? r->trns[idx] : 255u;
    } else if (type == 0 || type == 4) {
        a = type == 4 ? v[1] : (r->has_trns && v[0] == r->trns_key[0] ? 0u : maxv);
        v[1] = v[2] = v[0];
    } else {
        a = type == 6 ? v[3]
            : (r->has_trns && v[0] == r->trns_key[0] && v[1] == r->trns_key[1] &&
               v[2] == r->trns_key[2])
                ? 0u
                : maxv;
    }
    uint32_t sum = v[0] + v[1] + v[2], n = 3;
    if (y->mode == MAPFILE_TRINARY && p->alpha) {
        sum += a;
        n = 4;
    }
    *out = mapfile_shade_value((double)sum / ((double)n * maxv), a == maxv, y);
    return 0;
}

int mapfile_png_read(mapfile_png *p, const uint8_t *data, size_t len, const char *name,
                     const mapfile_yaml *y, int8_t **cells)
{
    return mapfile_png_read_capped(p, data, len, name, y, cells, 0);
}

int mapfile_png_read_capped(mapfile_png *p, const uint8_t *data, size_t len, const char *name,
                            const mapfile_yaml *y, int8_t **cells, size_t max_bytes)
{
    png_reader r;
    memset(&r, 0, sizeof r);
    memset(p, 0, sizeof *p);
    memset(r.trns, 255, sizeof r.trns);
    r.p = p;
    r.name = name;
    r.d = data;
    r.len = len;
    *cells = NULL;
    if (!mapfile_is_png(data, len))
        return pfail(&r, 0, "not a PNG image (no PNG signature)");
    if (read_chunks(&r))
        return -1;
    p->alpha = p->color_type == 4 || p->color_type == 6 || r.has_trns;
    /* the unpacked size: each pass's rows, a filter byte and the pixels */
    size_t raw_n = 0;
    for (int k = 0; k < (p->interlaced ? 7 : 1); k++) {
        uint32_t w, h;
        pass_size(p, k, &w, &h);
        if (w && h)
            raw_n += (size_t)h * (1 + row_bytes(p, w));
    }
    if (raw_n > MAPFILE_MAX_PGM_BYTES)
        return pfail(&r, r.idat_at, "the image unpacks to %zu bytes, more than %u", raw_n,
                     MAPFILE_MAX_PGM_BYTES);
    size_t need = r.idat_bytes + raw_n + (size_t)p->width * p->height;
    if (max_bytes && need > max_bytes) {
        p->need_bytes = need;
        return pfail(&r, r.idat_at, "%u x %u pixels take %zu bytes to decode, more than the"
                                    " memory budget of %zu", (unsigned)p->width,
                     (unsigned)p->height, need, max_bytes);
    }
    uint8_t *z = malloc(r.idat_bytes ? r.idat_bytes : 1), *raw = malloc(raw_n);
    int8_t *out = malloc((size_t)p->width * p->height);
    int rc = 0;
    if (!z || !raw || !out) {
        p->no_memory = 1;
        rc = pfail(&r, 0, "out of memory: %zu bytes for the image", r.idat_bytes + raw_n +
                                                                        (size_t)p->width * p->height);
        goto done;
    }
    gather_idat(&r, z);
    const char *why;
    size_t at;
    if (inflate_zlib(z, r.idat_bytes, raw, raw_n, &why, &at)) {
        rc = pfail(&r, idat_file_offset(&r, at), "image data (IDAT): %s", why);
        goto done;
    }
    size_t bpp = (channels_of(p->color_type) * p->bit_depth + 7) / 8, off = 0;
    for (int k = 0; k < (p->interlaced ? 7 : 1); k++) {
        uint32_t w, h;
        pass_size(p, k, &w, &h);
        if (!w || !h)
            continue;
        size_t rb = row_bytes(p, w);
        const uint8_t *prev = NULL;
        for (uint32_t j = 0; j < h; j++, off += 1 + rb) {
            uint8_t *row = raw + off + 1;
            if (raw[off] > 4) {
                rc = pfail(&r, r.idat_at, "image data (IDAT): row %u%s has filter type %u (0..4)",
                           (unsigned)j, p->interlaced ? " of an interlace pass" : "",
                           (unsigned)raw[off]);
                goto done;
            }
            unfilter(row, prev, rb, bpp, raw[off]);
            prev = row;
            uint32_t py = p->interlaced ? PASS_Y0[k] + j * PASS_DY[k] : j;
            int8_t *line = out + (size_t)(p->height - 1 - py) * p->width;
            for (uint32_t i = 0; i < w; i++) {
                uint32_t px = p->interlaced ? PASS_X0[k] + i * PASS_DX[k] : i;
                if (pixel_value(&r, row, i, y, &line[px])) {
                    rc = pfail(&r, r.idat_at, "image data (IDAT): pixel (%u, %u) has palette index"
                                              " %u, the palette %u colours",
                               (unsigned)px, (unsigned)py, sample_at(row, i, p->bit_depth),
                               r.palette_n);
                    goto done;
                }
            }
        }
    }
done:
    free(z);
    free(raw);
    if (rc)
        free(out);
    else
        *cells = out;
    return rc;
}
