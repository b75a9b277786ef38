/* test_mappng.c - ROS map images as PNG (tools/mapfile_png.c) and their
 * DEFLATE decoder (tools/inflate.c): every colour type and bit depth,
 * interlaced or not, through every row filter, read to the values a PGM
 * of the same samples gives; map_server's rule for colour and alpha;
 * palettes and transparency; streams of fixed and dynamic Huffman codes;
 * and every refused file with its byte. The PNGs are written here, with
 * stored (uncompressed) DEFLATE blocks, or with streams zlib made. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "inflate.h"
#include "mapfile.h"

/* ---- a PNG writer ---- */

typedef struct buf {
    uint8_t *d;
    size_t n, cap;
} buf;

static void put(buf *b, const void *p, size_t n)
{
    if (b->n + n > b->cap) {
        b->cap = (b->n + n) * 2 + 64;
        b->d = realloc(b->d, b->cap);
        assert_non_null(b->d);
    }
    if (n)
        memcpy(b->d + b->n, p, n);
    b->n += n;
}

static void put_u8(buf *b, unsigned v)
{
    uint8_t c = (uint8_t)v;
    put(b, &c, 1);
}

static void put_be32(buf *b, uint32_t v)
{
    uint8_t c[4] = {(uint8_t)(v >> 24), (uint8_t)(v >> 16), (uint8_t)(v >> 8), (uint8_t)v};
    put(b, c, 4);
}

static uint32_t crc32_of(const uint8_t *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = c & 1u ? 0xedb88320u ^ (c >> 1) : c >> 1;
    }
    return c ^ 0xffffffffu;
}

static uint32_t adler32_of(const uint8_t *p, size_t n)
{
    uint32_t a = 1, b = 0;
    for (size_t i = 0; i < n; i++) {
        a = (a + p[i]) % 65521u;
        b = (b + a) % 65521u;
    }
    return b << 16 | a;
}

static void chunk(buf *b, const char *type, const void *data, size_t n)
{
    put_be32(b, (uint32_t)n);
    size_t at = b->n;
    put(b, type, 4);
    put(b, data, n);
    put_be32(b, crc32_of(b->d + at, n + 4));
}

/* zlib of stored blocks (at most 65,535 bytes each) */
static buf zlib_stored(const uint8_t *raw, size_t n)
{
    buf z = {0};
    put_u8(&z, 0x78);
    put_u8(&z, 0x01);
    size_t at = 0;
    do {
        size_t k = n - at < 65535 ? n - at : 65535;
        put_u8(&z, at + k == n ? 1 : 0);
        put_u8(&z, (unsigned)(k & 255));
        put_u8(&z, (unsigned)(k >> 8));
        put_u8(&z, (unsigned)(~k & 255));
        put_u8(&z, (unsigned)((~k >> 8) & 255));
        put(&z, raw + at, k);
        at += k;
    } while (at < n);
    put_be32(&z, adler32_of(raw, n));
    return z;
}

typedef struct image {
    uint32_t w, h;
    unsigned type, depth;
    int interlace;
    const uint16_t *samples;   /* w * h * channels, rows top first */
    const uint8_t *plte;       /* palette: plte_n RGB triples */
    unsigned plte_n;
    const uint8_t *trns;       /* the tRNS chunk's bytes, or NULL */
    size_t trns_n;
} image;

static const unsigned PX0[7] = {0, 4, 0, 2, 0, 1, 0}, PY0[7] = {0, 0, 4, 0, 2, 0, 1};
static const unsigned PDX[7] = {8, 8, 4, 4, 2, 2, 1}, PDY[7] = {8, 8, 8, 4, 4, 2, 2};

static unsigned channels(unsigned type)
{
    return type == 2 ? 3 : type == 4 ? 2 : type == 6 ? 4 : 1;
}

static int paeth(int a, int b, int c)
{
    int p = a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
    return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

/* The image's raw data: each pass's rows packed and filtered, row k of the
 * whole image with filter (k + filter0) % 5. */
static buf raw_data(const image *m, unsigned filter0)
{
    buf raw = {0};
    unsigned ch = channels(m->type), bpp = (ch * m->depth + 7) / 8, k = 0;
    for (int p = 0; p < (m->interlace ? 7 : 1); p++) {
        unsigned x0 = m->interlace ? PX0[p] : 0, y0 = m->interlace ? PY0[p] : 0;
        unsigned dx = m->interlace ? PDX[p] : 1, dy = m->interlace ? PDY[p] : 1;
        uint32_t pw = m->w > x0 ? (m->w - x0 + dx - 1) / dx : 0;
        uint32_t ph = m->h > y0 ? (m->h - y0 + dy - 1) / dy : 0;
        if (!pw || !ph)
            continue;
        size_t rb = ((size_t)pw * ch * m->depth + 7) / 8;
        uint8_t *prev = calloc(rb, 1), *row = calloc(rb, 1);
        assert_non_null(prev);
        assert_non_null(row);
        for (uint32_t j = 0; j < ph; j++, k++) {
            memset(row, 0, rb);
            for (uint32_t i = 0; i < pw; i++)
                for (unsigned c = 0; c < ch; c++) {
                    uint32_t x = x0 + i * dx, y = y0 + j * dy;
                    unsigned v = m->samples[((size_t)y * m->w + x) * ch + c];
                    size_t s = (size_t)i * ch + c;
                    if (m->depth == 16) {
                        row[2 * s] = (uint8_t)(v >> 8);
                        row[2 * s + 1] = (uint8_t)v;
                    } else if (m->depth == 8) {
                        row[s] = (uint8_t)v;
                    } else {
                        size_t bit = s * m->depth;
                        row[bit / 8] |= (uint8_t)(v << (8 - m->depth - bit % 8));
                    }
                }
            unsigned f = (k + filter0) % 5;
            put_u8(&raw, f);
            for (size_t i = 0; i < rb; i++) {
                int a = i >= bpp ? row[i - bpp] : 0, b = j ? prev[i] : 0;
                int c = j && i >= bpp ? prev[i - bpp] : 0;
                int pred = f == 1 ? a : f == 2 ? b : f == 3 ? (a + b) / 2 : f == 4 ? paeth(a, b, c) : 0;
                put_u8(&raw, (unsigned)(row[i] - pred) & 255u);
            }
            memcpy(prev, row, rb);
        }
        free(prev);
        free(row);
    }
    return raw;
}

static void put_ihdr(buf *png, const image *m)
{
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    put(png, sig, 8);
    uint8_t ih[13] = {(uint8_t)(m->w >> 24), (uint8_t)(m->w >> 16), (uint8_t)(m->w >> 8),
                      (uint8_t)m->w, (uint8_t)(m->h >> 24), (uint8_t)(m->h >> 16),
                      (uint8_t)(m->h >> 8), (uint8_t)m->h, (uint8_t)m->depth, (uint8_t)m->type,
                      0, 0, (uint8_t)m->interlace};
    chunk(png, "IHDR", ih, 13);
    if (m->plte_n)
        chunk(png, "PLTE", m->plte, 3 * (size_t)m->plte_n);
    if (m->trns)
        chunk(png, "tRNS", m->trns, m->trns_n);
}

/* The PNG of `m` with the zlib stream z split into IDAT chunks of `piece`
 * bytes (and an empty one first), an ancillary chunk before them. */
static buf png_with(const image *m, const buf *z, size_t piece)
{
    buf png = {0};
    put_ihdr(&png, m);
    chunk(&png, "tEXt", "Comment\0test", 12);
    chunk(&png, "IDAT", NULL, 0);
    for (size_t at = 0; at < z->n; at += piece)
        chunk(&png, "IDAT", z->d + at, z->n - at < piece ? z->n - at : piece);
    chunk(&png, "IEND", NULL, 0);
    return png;
}

static buf png_of(const image *m, unsigned filter0)
{
    buf raw = raw_data(m, filter0);
    buf z = zlib_stored(raw.d, raw.n);
    buf png = png_with(m, &z, 100);
    free(raw.d);
    free(z.d);
    return png;
}

static mapfile_yaml yaml_mode(int mode, int negate)
{
    mapfile_yaml y;
    memset(&y, 0, sizeof y);
    y.mode = mode;
    y.negate = negate;
    y.occupied_thresh = 0.65;
    y.free_thresh = 0.196;
    return y;
}

/* Reads png, which must succeed: its cells (the caller frees). */
static int8_t *read_ok(const buf *png, const mapfile_yaml *y, mapfile_png *p)
{
    int8_t *cells = NULL;
    if (mapfile_png_read(p, png->d, png->n, "t.png", y, &cells))
        fail_msg("%s", p->error);
    assert_non_null(cells);
    return cells;
}

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

/* ---- reading ---- */

/* Gray images of every depth (1, 2, 4, 8, 16), interlaced or not, each
 * starting on every filter: the values of a PGM of the same samples with
 * maxval 2^depth - 1 (mapfile_cell_value), cell by cell, rows bottom
 * first, in each mode. */
static void test_gray_every_depth_filter_interlace(void **state)
{
    (void)state;
    static const unsigned depths[] = {1, 2, 4, 8, 16};
    uint32_t seed = 7;
    for (size_t di = 0; di < 5; di++)
        for (int inter = 0; inter < 2; inter++)
            for (unsigned f0 = 0; f0 < 5; f0++) {
                image m = {13, 11, 0, depths[di], inter, NULL, NULL, 0, NULL, 0};
                unsigned maxv = (1u << m.depth) - 1u;
                uint16_t samples[13 * 11];
                for (size_t i = 0; i < 13 * 11; i++) {
                    uint32_t r = lcg(&seed);
                    samples[i] = (uint16_t)(r % 3 == 0 ? 0 : r % 3 == 1 ? maxv : r % (maxv + 1));
                }
                m.samples = samples;
                buf png = png_of(&m, f0);
                for (int mode = MAPFILE_TRINARY; mode <= MAPFILE_RAW; mode++) {
                    mapfile_yaml y = yaml_mode(mode, f0 & 1);
                    mapfile_png p;
                    int8_t *cells = read_ok(&png, &y, &p);
                    assert_int_equal(p.width, 13);
                    assert_int_equal(p.height, 11);
                    assert_int_equal(p.bit_depth, m.depth);
                    assert_int_equal(p.interlaced, inter);
                    assert_int_equal(p.alpha, 0);
                    for (uint32_t row = 0; row < 11; row++)
                        for (uint32_t x = 0; x < 13; x++)
                            assert_int_equal(cells[(10 - row) * 13 + x],
                                             mapfile_cell_value(samples[row * 13 + x], maxv, &y));
                    free(cells);
                }
                free(png.d);
            }
}

/* map_server's rule for colour and alpha (nav2's loadMapFromFile): the
 * shade is the mean of R, G and B, with the alpha averaged in as a fourth
 * channel in trinary mode; in scale mode a pixel with any transparency is
 * unknown; raw mode takes the mean of R, G and B. The same pixels as 8-
 * and 16-bit RGBA, interlaced or not. */
static void test_rgba_map_server_rule(void **state)
{
    (void)state;
    static const uint16_t px8[6][4] = {{205, 205, 205, 255}, {205, 205, 205, 0}, {0, 0, 0, 255},
                                       {254, 254, 254, 255}, {100, 150, 200, 255}, {30, 60, 90, 0}};
    static const int8_t want[3][6] = {{0, -1, 100, 0, -1, 100},    /* trinary */
                                      {0, -1, 100, 0, 48, -1},     /* scale */
                                      {-1, -1, 0, -1, -1, 60}};    /* raw */
    for (unsigned depth = 8; depth <= 16; depth += 8)
        for (int inter = 0; inter < 2; inter++) {
            uint16_t s[6 * 4];
            for (int i = 0; i < 24; i++)
                s[i] = (uint16_t)(px8[i / 4][i % 4] * (depth == 16 ? 257u : 1u));
            image m = {6, 1, 6, depth, inter, s, NULL, 0, NULL, 0};
            buf png = png_of(&m, 4);
            for (int mode = MAPFILE_TRINARY; mode <= MAPFILE_RAW; mode++) {
                mapfile_yaml y = yaml_mode(mode, 0);
                mapfile_png p;
                int8_t *cells = read_ok(&png, &y, &p);
                assert_int_equal(p.alpha, 1);
                assert_memory_equal(cells, want[mode], 6);
                free(cells);
            }
            free(png.d);
        }
    /* RGB without alpha: the mean of the three; gray+alpha as RGBA */
    static const uint16_t rgb[3] = {100, 150, 200}, ga[4] = {205, 255, 205, 0};
    image m = {1, 1, 2, 8, 0, rgb, NULL, 0, NULL, 0};
    buf png = png_of(&m, 0);
    mapfile_yaml y = yaml_mode(MAPFILE_SCALE, 0);
    mapfile_png p;
    int8_t *cells = read_ok(&png, &y, &p);
    assert_int_equal(cells[0], 48);
    free(cells);
    free(png.d);
    image g = {2, 1, 4, 8, 0, ga, NULL, 0, NULL, 0};
    png = png_of(&g, 1);
    y = yaml_mode(MAPFILE_TRINARY, 0);
    cells = read_ok(&png, &y, &p);
    assert_int_equal(cells[0], 0);  /* opaque 205 with its alpha averaged in: free */
    assert_int_equal(cells[1], -1); /* transparent 205 */
    free(cells);
    free(png.d);
}

/* A palette (1- to 8-bit indices) with transparency for its first colours;
 * a gray and an RGB image with a tRNS colour key: the pixels of that
 * colour are transparent, the others opaque. */
static void test_palette_and_colour_keys(void **state)
{
    (void)state;
    static const uint8_t plte[3 * 3] = {205, 205, 205, 0, 0, 0, 254, 254, 254};
    static const uint8_t trns[2] = {0, 255};
    static const uint16_t idx[6] = {0, 1, 2, 2, 1, 0};
    for (unsigned depth = 2; depth <= 8; depth *= 2) {
        image m = {3, 2, 3, depth, depth == 4, idx, plte, 3, trns, 2};
        buf png = png_of(&m, depth);
        mapfile_yaml y = yaml_mode(MAPFILE_TRINARY, 0);
        mapfile_png p;
        int8_t *cells = read_ok(&png, &y, &p);
        /* rows bottom first: {2, 1, 0} then {0, 1, 2} */
        static const int8_t want[6] = {0, 100, -1, -1, 100, 0};
        assert_memory_equal(cells, want, 6);
        free(cells);
        y = yaml_mode(MAPFILE_SCALE, 0); /* the transparent colour unknown again */
        cells = read_ok(&png, &y, &p);
        assert_memory_equal(cells, want, 6);
        free(cells);
        free(png.d);
    }
    static const uint8_t key_gray[2] = {0, 205}, key_rgb[6] = {0, 205, 0, 205, 0, 205};
    static const uint16_t gray[3] = {205, 254, 0}, rgb[9] = {205, 205, 205, 254, 254, 254, 0, 0, 0};
    image g = {3, 1, 0, 8, 0, gray, NULL, 0, key_gray, 2};
    image c = {3, 1, 2, 8, 1, rgb, NULL, 0, key_rgb, 6};
    const image *ims[2] = {&g, &c};
    for (int k = 0; k < 2; k++) {
        buf png = png_of(ims[k], 2);
        mapfile_yaml y = yaml_mode(MAPFILE_SCALE, 0);
        mapfile_png p;
        int8_t *cells = read_ok(&png, &y, &p);
        assert_int_equal(p.alpha, 1);
        static const int8_t want[3] = {-1, 0, 100};
        assert_memory_equal(cells, want, 3);
        free(cells);
        free(png.d);
    }
}

/* Image data compressed by zlib 1.2.13 (level 9): a 24 x 20 gray gradient
 * in fixed Huffman codes, and a 64 x 48 room drawn in 0, 205 and 254 with
 * some stray values, in a dynamic-code block; each unpacks to its rows
 * (filter 0) and reads as those samples. */
static const uint8_t FIXED_Z[] = {
    0x78, 0x01, 0x63, 0x60, 0xe0, 0x16, 0x53, 0xd4, 0x31, 0x77, 0xf2, 0x8d, 0x48, 0xce, 0xab,
    0x6c, 0xe9, 0x9f, 0xb5, 0x74, 0xc3, 0xee, 0x63, 0x17, 0xef, 0x3c, 0xff, 0xf4, 0x97, 0x81,
    0x74, 0x09, 0x55, 0x03, 0x6b, 0xb7, 0xc0, 0x98, 0xf4, 0xa2, 0xda, 0x8e, 0xc9, 0xf3, 0x56,
    0x6e, 0xd9, 0x7f, 0xea, 0xea, 0x83, 0xd7, 0xdf, 0x18, 0x79, 0xc4, 0x95, 0xc8, 0x90, 0xf0,
    0x0a, 0x4d, 0xc8, 0x2e, 0x6b, 0xec, 0x99, 0xbe, 0x68, 0xed, 0x8e, 0xc3, 0xe7, 0x6e, 0x3e,
    0x79, 0xff, 0x8b, 0x55, 0x40, 0x5a, 0xcd, 0xd0, 0xc6, 0x9d, 0x0c, 0x89, 0xfc, 0xaa, 0xd6,
    0x09, 0xb3, 0x97, 0x6d, 0xdc, 0x73, 0xfc, 0xd2, 0xdd, 0x17, 0x9f, 0xff, 0x71, 0x8a, 0xc8,
    0x6b, 0x99, 0x3a, 0x78, 0x87, 0x25, 0xe6, 0x90, 0x21, 0x31, 0x65, 0xfe, 0xaa, 0xad, 0x07,
    0x4e, 0x5f, 0x7b, 0xf8, 0xe6, 0x3b, 0x13, 0xaf, 0x84, 0xb2, 0x9e, 0xa5, 0x8b, 0x7f, 0x54,
    0x6a, 0x41, 0x75, 0xdb, 0x44, 0x32, 0x24, 0x76, 0x1e, 0x39, 0x7f, 0xeb, 0xe9, 0x87, 0xdf,
    0x6c, 0x82, 0x32, 0xea, 0x46, 0xb6, 0x1e, 0xc1, 0x71, 0x99, 0x25, 0xf5, 0x5d, 0x53, 0x17,
    0xac, 0xde, 0x46, 0x86, 0xc4, 0xbd, 0x97, 0x5f, 0xfe, 0x73, 0x89, 0x2a, 0x68, 0x9b, 0x39,
    0xfa, 0x84, 0x27, 0xe5, 0x56, 0x34, 0xf7, 0xcd, 0x5c, 0xb2, 0x7e, 0xd7, 0xd1, 0x0b, 0xb7,
    0x71, 0x4a, 0x00, 0x00, 0x68, 0x3a, 0xee, 0xe9};
static const uint8_t DYNAMIC_Z[] = {
    0x78, 0xda, 0x95, 0x97, 0x31, 0x28, 0x44, 0x71, 0x1c, 0xc7, 0x7f, 0x99, 0x85, 0x41, 0xb9,
    0xe5, 0x88, 0x74, 0x45, 0x91, 0x74, 0x03, 0x51, 0x0c, 0x06, 0x06, 0xa5, 0x48, 0x06, 0xc3,
    0x65, 0xb1, 0x4a, 0xa7, 0x2e, 0x9b, 0xba, 0x74, 0x83, 0x22, 0x93, 0xc4, 0x20, 0x29, 0xb3,
    0x0c, 0x32, 0x99, 0x2c, 0xfa, 0xd7, 0x0d, 0xb7, 0xd9, 0xd9, 0x2e, 0x83, 0x45, 0xe9, 0x9b,
    0xeb, 0xe5, 0x5d, 0xc7, 0xfb, 0xff, 0x3f, 0x8f, 0x7f, 0x37, 0xdc, 0xdd, 0xff, 0x7d, 0xbe,
    0xf7, 0xde, 0xa7, 0xde, 0xfb, 0xfe, 0xce, 0xcc, 0xb9, 0xc6, 0x2b, 0xb0, 0xc2, 0x3b, 0xd1,
    0xa6, 0x7d, 0x1f, 0xe2, 0x3b, 0xac, 0x87, 0xd0, 0x7c, 0x4b, 0x7e, 0x32, 0x60, 0x80, 0xd0,
    0xf5, 0xc4, 0x09, 0xb6, 0x06, 0xf4, 0x13, 0x5a, 0x0a, 0x5c, 0xa1, 0x45, 0xab, 0xdb, 0x60,
    0x55, 0x68, 0xf3, 0x33, 0x0a, 0x51, 0x60, 0x1d, 0x08, 0x56, 0x56, 0x6a, 0x5e, 0x42, 0x72,
    0xb7, 0x4c, 0xe8, 0x78, 0xfc, 0xc6, 0x1b, 0xb0, 0x45, 0xe8, 0xd4, 0xcf, 0x8f, 0xbf, 0x02,
    0x96, 0x08, 0x9d, 0xf0, 0x7d, 0xd9, 0x0c, 0x18, 0x24, 0x74, 0x28, 0xbc, 0x65, 0x6e, 0xd4,
    0x91, 0xc4, 0x0e, 0xca, 0x1d, 0x13, 0x49, 0x7c, 0x25, 0x34, 0x27, 0x92, 0x78, 0x4b, 0x68,
    0x97, 0x48, 0xe2, 0x0e, 0xa1, 0x75, 0x91, 0xc4, 0x61, 0x42, 0x1f, 0x60, 0xcf, 0x56, 0x1d,
    0x49, 0xdc, 0xa7, 0xdc, 0x49, 0x91, 0xc4, 0xd9, 0x3f, 0x8a, 0xf0, 0x04, 0xd4, 0x09, 0x7d,
    0x16, 0x49, 0x3c, 0x22, 0xf4, 0x54, 0x24, 0x31, 0x67, 0x80, 0x2e, 0x52, 0x6e, 0xd1, 0x91,
    0xc4, 0xf7, 0xf4, 0x5b, 0x23, 0x24, 0xf1, 0x90, 0xd0, 0x37, 0x91, 0xc4, 0x5e, 0x42, 0xcf,
    0x44, 0x12, 0x2f, 0x08, 0x9d, 0x16, 0x49, 0xcc, 0x38, 0x90, 0x58, 0xa5, 0xdc, 0x8a, 0x91,
    0xc4, 0x35, 0x42, 0x47, 0x44, 0x12, 0x6b, 0x84, 0x3e, 0x8a, 0x24, 0xce, 0x11, 0xba, 0x2c,
    0x92, 0x78, 0x4d, 0x68, 0x4d, 0x24, 0xd1, 0xa0, 0x17, 0xb4, 0x40, 0xb9, 0xc7, 0xd4, 0x0b,
    0xba, 0x21, 0x34, 0x43, 0xbd, 0xa0, 0x4e, 0xfe, 0x55, 0x92, 0x58, 0x20, 0xd4, 0xa8, 0x17,
    0x74, 0x45, 0xe8, 0x06, 0xf4, 0x82, 0xeb, 0xc3, 0x72, 0xbd, 0x4b, 0xb9, 0x1a, 0x90, 0xd8,
    0x46, 0xe8, 0x07, 0x96, 0x2b, 0x3e, 0x0f, 0x57, 0xb0, 0x5c, 0xb7, 0x09, 0xbd, 0xc4, 0x72,
    0x3d, 0x21, 0xf4, 0x85, 0xca, 0x35, 0x8f, 0xe5, 0x9a, 0xc5, 0x7b, 0x19, 0xcb, 0x75, 0x9e,
    0xd0, 0x2a, 0x96, 0xeb, 0x26, 0xa1, 0xed, 0x58, 0xae, 0xbb, 0xff, 0x7f, 0xa8, 0xc5, 0x63,
    0xde, 0x1e, 0xcd, 0x71, 0x05, 0xda, 0x9c, 0x31, 0xb3, 0xf0, 0x44, 0x5c, 0xa2, 0xb9, 0xb3,
    0x18, 0x1e, 0x75, 0x1b, 0xab, 0x4c, 0xe8, 0x79, 0x78, 0xd4, 0x4d, 0x43, 0xef, 0xbd, 0xa3,
    0x6e, 0x1c, 0x80, 0x27, 0xfc, 0x14, 0xfe, 0x37, 0xf0, 0x05, 0x8d, 0xc2, 0x52, 0x9d
};

static unsigned gradient(uint32_t x, uint32_t y)
{
    return (x * 11 + (y / 3) * 37) % 256;
}

static unsigned room(uint32_t x, uint32_t y)
{
    const uint32_t w = 64, h = 48;
    unsigned v = (x == 3 || y == 4 || x == w - 4 || y == h - 5) ? 0
                 : (x > 3 && x < w - 4 && y > 4 && y < h - 5) ? 254 : 205;
    return (x * 7 + y * 13) % 29 == 0 ? (x * y) % 256 : v;
}

static void check_stream(const uint8_t *z, size_t zn, uint32_t w, uint32_t h,
                         unsigned (*value)(uint32_t, uint32_t), unsigned block_type)
{
    assert_int_equal((z[2] >> 1) & 3u, block_type);
    size_t n = (size_t)h * (w + 1);
    uint8_t *raw = malloc(n);
    assert_non_null(raw);
    const char *why;
    size_t at;
    assert_int_equal(inflate_zlib(z, zn, raw, n, &why, &at), 0);
    for (uint32_t y = 0; y < h; y++) {
        assert_int_equal(raw[y * (w + 1)], 0);
        for (uint32_t x = 0; x < w; x++)
            assert_int_equal(raw[y * (w + 1) + 1 + x], value(x, y));
    }
    /* one byte of room less, or more, is refused */
    assert_int_equal(inflate_zlib(z, zn, raw, n - 1, &why, &at), -1);
    assert_string_equal(why, "more data than the image needs");
    free(raw);
    raw = malloc(n + 1);
    assert_non_null(raw);
    assert_int_equal(inflate_zlib(z, zn, raw, n + 1, &why, &at), -1);
    assert_string_equal(why, "the compressed data end before the image does");
    free(raw);
    /* and as a PNG, split over IDAT chunks of 7 bytes */
    image m = {w, h, 0, 8, 0, NULL, NULL, 0, NULL, 0};
    buf zb = {(uint8_t *)(uintptr_t)z, zn, zn};
    buf png = png_with(&m, &zb, 7);
    mapfile_yaml y = yaml_mode(MAPFILE_RAW, 0);
    mapfile_png p;
    int8_t *cells = read_ok(&png, &y, &p);
    for (uint32_t row = 0; row < h; row++)
        for (uint32_t x = 0; x < w; x++)
            assert_int_equal(cells[(h - 1 - row) * w + x], mapfile_cell_value(value(x, row), 255, &y));
    free(cells);
    free(png.d);
}

static void test_huffman_streams(void **state)
{
    (void)state;
    check_stream(FIXED_Z, sizeof FIXED_Z, 24, 20, gradient, 1);
    check_stream(DYNAMIC_Z, sizeof DYNAMIC_Z, 64, 48, room, 2);
}

/* ---- refused ---- */

static void expect_png_error(const buf *png, const char *error)
{
    mapfile_yaml y = yaml_mode(MAPFILE_TRINARY, 0);
    mapfile_png p;
    int8_t *cells = (int8_t *)png->d;
    assert_int_equal(mapfile_png_read(&p, png->d, png->n, "t.png", &y, &cells), -1);
    assert_null(cells);
    assert_string_equal(p.error, error);
}

static void expect_inflate_error(const uint8_t *z, size_t zn, size_t out_n, const char *error)
{
    uint8_t out[16];
    const char *why;
    size_t at;
    assert_int_equal(inflate_zlib(z, zn, out, out_n, &why, &at), -1);
    assert_string_equal(why, error);
    assert_true(at <= zn);
}

static const uint16_t TINY[4] = {0, 254, 205, 0};
static const image TINY_IMAGE = {2, 2, 0, 8, 0, TINY, NULL, 0, NULL, 0};

/* The tiny image's PNG with its IHDR fields changed (CRCs made again). */
static buf tiny_with_ihdr(uint32_t w, uint32_t h, unsigned depth, unsigned type, unsigned inter)
{
    image m = TINY_IMAGE;
    m.w = w;
    m.h = h;
    m.depth = depth;
    m.type = type;
    m.interlace = (int)inter;
    buf png = {0};
    put_ihdr(&png, &m);
    buf raw = raw_data(&TINY_IMAGE, 0);
    buf z = zlib_stored(raw.d, raw.n);
    chunk(&png, "IDAT", z.d, z.n);
    chunk(&png, "IEND", NULL, 0);
    free(raw.d);
    free(z.d);
    return png;
}

static void test_refused_structure(void **state)
{
    (void)state;
    buf good = png_of(&TINY_IMAGE, 0);
    /* good: signature 8, IHDR 25 (8..32), tEXt 24 (33..56), an empty IDAT
     * 12 (57..68), IDAT 12 + 17 (69..97), IEND 12 (98..109) */
    assert_int_equal(good.n, 110);
    buf b = {0};
    put(&b, "P5\n2 2\n255\n", 11);
    expect_png_error(&b, "t.png: byte 0: not a PNG image (no PNG signature)");
    b.n = 0;
    put(&b, good.d, 20);
    expect_png_error(&b, "t.png: byte 8: chunk 'IHDR' of 13 bytes runs past the end of the file"
                         " (truncated)");
    b.n = 0;
    put(&b, good.d, 98);
    expect_png_error(&b, "t.png: byte 98: the file ends before its IEND chunk (truncated)");
    b.n = 0;
    put(&b, good.d, good.n);
    b.d[80] ^= 1; /* inside the IDAT */
    expect_png_error(&b, "t.png: byte 94: chunk 'IDAT': its CRC does not match (a damaged file)");
    /* IHDR not first: the tEXt chunk moved before it */
    b.n = 0;
    put(&b, good.d, 8);
    put(&b, good.d + 33, 24);
    put(&b, good.d + 8, 25);
    put(&b, good.d + 57, good.n - 57);
    expect_png_error(&b, "t.png: byte 8: the first chunk is 'tEXt', not IHDR");
    /* an unknown critical chunk; an unknown ancillary one is skipped */
    b.n = 0;
    put(&b, good.d, 57);
    chunk(&b, "ABCD", "x", 1);
    put(&b, good.d + 57, good.n - 57);
    expect_png_error(&b, "t.png: byte 57: an unknown critical chunk 'ABCD'");
    b.n = 0;
    put(&b, good.d, 57);
    chunk(&b, "abCD", "x", 1);
    put(&b, good.d + 57, good.n - 57);
    mapfile_yaml y = yaml_mode(MAPFILE_TRINARY, 0);
    mapfile_png p;
    free(read_ok(&b, &y, &p));
    /* a chunk type that is not four letters */
    b.n = 0;
    put(&b, good.d, 57);
    chunk(&b, "a\x01" "cD", "x", 1);
    put(&b, good.d + 57, good.n - 57);
    expect_png_error(&b, "t.png: byte 61: 'a\\x01cD' is not a chunk type (four letters)");
    /* IDAT, another chunk, IDAT */
    b.n = 0;
    put(&b, good.d, 69);
    chunk(&b, "tEXt", "a\0b", 3);
    put(&b, good.d + 69, good.n - 69);
    expect_png_error(&b, "t.png: byte 84: image data (IDAT) in two runs: its chunks must follow"
                         " one another");
    /* no IDAT */
    b.n = 0;
    put(&b, good.d, 57);
    put(&b, good.d + 98, 12);
    expect_png_error(&b, "t.png: byte 57: no image data (IDAT) before IEND");
    /* what follows IEND is not read */
    b.n = 0;
    put(&b, good.d, good.n);
    put(&b, "trailing", 8);
    free(read_ok(&b, &y, &p));
    free(b.d);
    free(good.d);
}

static void test_refused_header(void **state)
{
    (void)state;
    buf b = tiny_with_ihdr(0, 2, 8, 0, 0);
    expect_png_error(&b, "t.png: byte 16: 0 x 2 pixels (each must be 1..2^31-1)");
    free(b.d);
    b = tiny_with_ihdr(65536, 65536, 8, 0, 0);
    expect_png_error(&b, "t.png: byte 16: 65536 x 65536 pixels: more than 268435456 cells");
    free(b.d);
    b = tiny_with_ihdr(2, 2, 16, 3, 0);
    expect_png_error(&b, "t.png: byte 24: colour type 3 with bit depth 16 (not a PNG combination)");
    free(b.d);
    b = tiny_with_ihdr(2, 2, 8, 5, 0);
    expect_png_error(&b, "t.png: byte 24: colour type 5 with bit depth 8 (not a PNG combination)");
    free(b.d);
    b = tiny_with_ihdr(2, 2, 8, 0, 2);
    expect_png_error(&b, "t.png: byte 28: interlace method 2 (0 or 1)");
    free(b.d);
    /* a small file that claims 16384 x 16384 RGBA at 16 bits (2 GiB
     * unpacked) is refused before anything is allocated */
    b = tiny_with_ihdr(16384, 16384, 16, 6, 0);
    expect_png_error(&b, "t.png: byte 33: the image unpacks to 2147500032 bytes, more than"
                         " 1073741824");
    free(b.d);
}

static void test_refused_palette_and_rows(void **state)
{
    (void)state;
    static const uint8_t plte[6] = {0, 0, 0, 255, 255, 255};
    static const uint16_t idx[4] = {0, 1, 2, 1};
    image m = {2, 2, 3, 8, 0, idx, plte, 2, NULL, 0};
    buf b = png_of(&m, 0);
    expect_png_error(&b, "t.png: byte 75: image data (IDAT): pixel (0, 1) has palette index 2, the"
                         " palette 2 colours");
    free(b.d);
    m.plte_n = 0;
    b = png_of(&m, 0);
    expect_png_error(&b, "t.png: byte 57: a palette image without a palette (PLTE)");
    free(b.d);
    image g = TINY_IMAGE;
    g.plte = plte;
    g.plte_n = 2;
    b = png_of(&g, 0);
    expect_png_error(&b, "t.png: byte 33: a palette (PLTE) in a gray image");
    free(b.d);
    image t = TINY_IMAGE;
    t.trns = plte;
    t.trns_n = 3;
    b = png_of(&t, 0);
    expect_png_error(&b, "t.png: byte 33: transparency (tRNS) of 3 bytes in a gray image (must be 2)");
    free(b.d);
    /* a row filter of 5 */
    buf raw = raw_data(&TINY_IMAGE, 0);
    raw.d[3] = 5;
    buf z = zlib_stored(raw.d, raw.n);
    b = png_with(&TINY_IMAGE, &z, 100);
    expect_png_error(&b, "t.png: byte 57: image data (IDAT): row 1 has filter type 5 (0..4)");
    free(b.d);
    free(z.d);
    free(raw.d);
}

/* The zlib stream's faults, each through inflate_zlib and one as a PNG. */
static void test_refused_streams(void **state)
{
    (void)state;
    static const uint8_t data[4] = {0, 1, 2, 3};
    buf z = zlib_stored(data, 4);
    uint8_t s[32];
    memcpy(s, z.d, z.n);
    expect_inflate_error(s, 1, 4, "no zlib header (cut short)");
    s[0] = 0x79;
    expect_inflate_error(s, z.n, 4, "a zlib stream whose method is not deflate (8)");
    s[0] = 0x88;
    expect_inflate_error(s, z.n, 4, "a zlib window over 32 KiB");
    s[0] = 0x78;
    s[1] = 0x02;
    expect_inflate_error(s, z.n, 4, "a zlib header whose check bits are wrong");
    s[1] = 0x20; /* FDICT set, and (0x78 << 8 | 0x20) % 31 == 0 */
    expect_inflate_error(s, z.n, 4, "a zlib stream that needs a preset dictionary");
    s[1] = 0x01;
    s[z.n - 1] ^= 1;
    expect_inflate_error(s, z.n, 4, "the unpacked data do not match the zlib stream's Adler-32");
    s[z.n - 1] ^= 1;
    expect_inflate_error(s, z.n - 2, 4, "the zlib stream's Adler-32 is missing (cut short)");
    s[z.n] = 0;
    expect_inflate_error(s, z.n + 1, 4, "bytes after the end of the zlib stream");
    expect_inflate_error(s, 9, 4, "the compressed data end inside a block (cut short)");
    s[5] ^= 1; /* NLEN */
    expect_inflate_error(s, z.n, 4, "a stored block whose length and its complement disagree");
    /* hand-made blocks: type 3; a fixed-code copy (length 3, distance 1)
     * before any byte; a dynamic block whose first code length repeats
     * the one before it */
    static const uint8_t type3[] = {0x78, 0x01, 0x07, 0, 0, 0, 0};
    expect_inflate_error(type3, sizeof type3, 4, "a block of type 3 (reserved)");
    static const uint8_t early_copy[] = {0x78, 0x01, 0x03, 0x02, 0, 0, 0, 0};
    expect_inflate_error(early_copy, sizeof early_copy, 4, "a copy from before the start of the data");
    /* BFINAL 1, BTYPE 2, HLIT 0, HDIST 0, HCLEN 0 (the code-length code's
     * first four lengths: 16 and 0 of 1 bit, 17 and 18 unused), then the
     * code of 16 (a repeat) first */
    static const uint8_t bad_repeat[] = {0x78, 0x01, 0x05, 0x00, 0x02, 0x24, 0, 0, 0, 0};
    expect_inflate_error(bad_repeat, sizeof bad_repeat, 4,
                         "a repeated code length with none before it");
    /* as a PNG: the byte is in the file, where the Adler-32 starts */
    image m = TINY_IMAGE;
    buf raw = raw_data(&m, 0);
    buf zz = zlib_stored(raw.d, raw.n);
    zz.d[zz.n - 1] ^= 1;
    buf png = png_with(&m, &zz, 100);
    expect_png_error(&png, "t.png: byte 90: image data (IDAT): the unpacked data do not match the"
                           " zlib stream's Adler-32");
    free(png.d);
    free(zz.d);
    free(raw.d);
    free(z.d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gray_every_depth_filter_interlace),
        cmocka_unit_test(test_rgba_map_server_rule),
        cmocka_unit_test(test_palette_and_colour_keys),
        cmocka_unit_test(test_huffman_streams),
        cmocka_unit_test(test_refused_structure),
        cmocka_unit_test(test_refused_header),
        cmocka_unit_test(test_refused_palette_and_rows),
        cmocka_unit_test(test_refused_streams),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
