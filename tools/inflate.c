/* inflate.c - DEFLATE blocks (RFC 1951) in a zlib wrapper (RFC 1950),
 * unpacked into a buffer of known size (inflate.h).
 * Takes: the compressed bytes. Gives: the bytes they stand for, checked
 * against the stream's Adler-32, or a static message. Huffman codes are
 * looked up by their first FAST_BITS bits; longer ones are decoded bit by
 * bit, counting the canonical codes of each length (RFC 1951, 3.2.2). */
#include "inflate.h"

#include <string.h>

#define MAX_BITS 15    /* the longest code */
#define FAST_BITS 9    /* codes up to this long come from the table */
#define MAX_CODES 288  /* literal/length symbols of the fixed code */

typedef struct huff {
    uint16_t count[MAX_BITS + 1];  /* codes of each length (count[0]: unused symbols) */
    uint16_t symbol[MAX_CODES];    /* the symbols in canonical order */
    uint16_t fast[1u << FAST_BITS];/* by the next FAST_BITS bits: symbol << 4 | length, 0 if longer */
} huff;

typedef struct inf {
    const uint8_t *in;
    size_t len, pos;               /* the input and the next byte to load */
    uint32_t bits;                 /* loaded bits not used yet, the next one lowest; none above nbits */
    int nbits;
    uint8_t *out;
    size_t cap, n;                 /* the output's size and what is written */
    const char *why;               /* the first fault */
} inf;

static int fail(inf *s, const char *why)
{
    if (!s->why)
        s->why = why;
    return -1;
}

/* At least k bits loaded (k <= 25), as far as the input goes. */
static void fill(inf *s, int k)
{
    while (s->nbits < k && s->pos < s->len) {
        s->bits |= (uint32_t)s->in[s->pos++] << s->nbits;
        s->nbits += 8;
    }
}

static int get_bits(inf *s, int k, uint32_t *v)
{
    fill(s, k);
    if (s->nbits < k)
        return fail(s, "the compressed data end inside a block (cut short)");
    *v = s->bits & ((1u << k) - 1u);
    s->bits >>= k;
    s->nbits -= k;
    return 0;
}

/* To the next byte boundary: the bits left of the current byte are
 * dropped and the whole bytes loaded go back to the input. */
static void to_byte(inf *s)
{
    s->pos -= (size_t)(s->nbits / 8);
    s->bits = 0;
    s->nbits = 0;
}

static uint32_t reverse_bits(uint32_t code, int len)
{
    uint32_t r = 0;
    for (int i = 0; i < len; i++, code >>= 1)
        r = (r << 1) | (code & 1u);
    return r;
}

/* The canonical code of n symbols' lengths (0: unused). Refused: a set
 * that needs more codes than the lengths have room for, and an incomplete
 * one, but for a single code of length 1 and no code at all (a block of
 * literals only has no distance code), as zlib has them. */
static int build(huff *h, const uint8_t *length, int n)
{
    memset(h->count, 0, sizeof h->count);
    memset(h->fast, 0, sizeof h->fast);
    for (int sym = 0; sym < n; sym++)
        h->count[length[sym]]++;
    if (h->count[0] == n)
        return 0;
    int left = 1;
    for (int len = 1; len <= MAX_BITS; len++) {
        left = left * 2 - h->count[len];
        if (left < 0)
            return -1;
    }
    if (left > 0 && !(h->count[1] == 1 && h->count[0] == n - 1))
        return -1;
    uint16_t offs[MAX_BITS + 2];
    offs[1] = 0;
    for (int len = 1; len <= MAX_BITS; len++)
        offs[len + 1] = (uint16_t)(offs[len] + h->count[len]);
    for (int sym = 0; sym < n; sym++)
        if (length[sym])
            h->symbol[offs[length[sym]]++] = (uint16_t)sym;
    /* the table: each short code, bit-reversed (codes are sent from their
     * top bit), under every value of the bits after it */
    uint32_t code = 0;
    int index = 0;
    for (int len = 1; len <= FAST_BITS; len++) {
        for (int k = 0; k < h->count[len]; k++, code++) {
            uint16_t e = (uint16_t)(h->symbol[index + k] << 4 | len);
            for (uint32_t i = reverse_bits(code, len); i < (1u << FAST_BITS); i += 1u << len)
                h->fast[i] = e;
        }
        index += h->count[len];
        code <<= 1;
    }
    return 0;
}

static int decode(inf *s, const huff *h, int *sym)
{
    fill(s, FAST_BITS);
    uint16_t e = h->fast[s->bits & ((1u << FAST_BITS) - 1u)];
    if (e && (int)(e & 15u) <= s->nbits) {
        s->bits >>= e & 15u;
        s->nbits -= (int)(e & 15u);
        *sym = e >> 4;
        return 0;
    }
    /* a longer code (or the input's last bits): bit by bit */
    int code = 0, first = 0, index = 0;
    for (int len = 1; len <= MAX_BITS; len++) {
        uint32_t b;
        if (get_bits(s, 1, &b))
            return -1;
        code |= (int)b;
        int count = h->count[len];
        if (code - count < first) {
            *sym = h->symbol[index + (code - first)];
            return 0;
        }
        index += count;
        first = (first + count) << 1;
        code <<= 1;
    }
    return fail(s, "a Huffman code the block's code table does not hold");
}

static const uint16_t LEN_BASE[29] = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                      31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
static const uint8_t LEN_EXTRA[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                      2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
static const uint16_t DIST_BASE[30] = {1,    2,    3,    4,    5,    7,     9,     13,    17,  25,
                                       33,   49,   65,   97,   129,  193,   257,   385,   513, 769,
                                       1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
static const uint8_t DIST_EXTRA[30] = {0, 0, 0, 0, 1, 1, 2, 2,  3,  3,  4,  4,  5,  5,  6,
                                       6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};

/* A Huffman-coded block's literals and copies, up to its end code. */
static int codes(inf *s, const huff *lit, const huff *dist)
{
    for (;;) {
        int sym;
        if (decode(s, lit, &sym))
            return -1;
        if (sym < 256) {
            if (s->n >= s->cap)
                return fail(s, "more data than the image needs");
            s->out[s->n++] = (uint8_t)sym;
            continue;
        }
        if (sym == 256)
            return 0;
        sym -= 257;
        if (sym >= 29)
            return fail(s, "a length code past 285");
        uint32_t extra;
        if (get_bits(s, LEN_EXTRA[sym], &extra))
            return -1;
        size_t len = LEN_BASE[sym] + extra;
        int dsym;
        if (decode(s, dist, &dsym))
            return -1;
        if (dsym >= 30)
            return fail(s, "a distance code past 29");
        if (get_bits(s, DIST_EXTRA[dsym], &extra))
            return -1;
        size_t d = DIST_BASE[dsym] + extra;
        if (d > s->n)
            return fail(s, "a copy from before the start of the data");
        if (len > s->cap - s->n)
            return fail(s, "more data than the image needs");
        uint8_t *o = s->out + s->n;
        for (size_t i = 0; i < len; i++) /* (a copy may overlap what it writes) */
            o[i] = o[(ptrdiff_t)i - (ptrdiff_t)d];
        s->n += len;
    }
}

static int stored(inf *s)
{
    to_byte(s);
    if (s->len - s->pos < 4)
        return fail(s, "the compressed data end inside a block (cut short)");
    const uint8_t *p = s->in + s->pos;
    size_t len = (size_t)p[0] | (size_t)p[1] << 8, nlen = (size_t)p[2] | (size_t)p[3] << 8;
    if (len != (~nlen & 0xffffu))
        return fail(s, "a stored block whose length and its complement disagree");
    s->pos += 4;
    if (len > s->len - s->pos)
        return fail(s, "the compressed data end inside a block (cut short)");
    if (len > s->cap - s->n)
        return fail(s, "more data than the image needs");
    memcpy(s->out + s->n, s->in + s->pos, len);
    s->pos += len;
    s->n += len;
    return 0;
}

static int fixed(inf *s, huff *lit, huff *dist)
{
    uint8_t length[MAX_CODES];
    int sym = 0;
    for (; sym < 144; sym++) length[sym] = 8;
    for (; sym < 256; sym++) length[sym] = 9;
    for (; sym < 280; sym++) length[sym] = 7;
    for (; sym < MAX_CODES; sym++) length[sym] = 8;
    build(lit, length, MAX_CODES);
    memset(length, 5, 32); /* (30 and 31 complete the code; met, they are refused) */
    build(dist, length, 32);
    return codes(s, lit, dist);
}

static int dynamic(inf *s, huff *lit, huff *dist)
{
    static const uint8_t ORDER[19] = {16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15};
    uint32_t v;
    int nlen, ndist, ncode;
    if (get_bits(s, 5, &v))
        return -1;
    nlen = (int)v + 257;
    if (get_bits(s, 5, &v))
        return -1;
    ndist = (int)v + 1;
    if (get_bits(s, 4, &v))
        return -1;
    ncode = (int)v + 4;
    if (nlen > 286 || ndist > 30)
        return fail(s, "a block with more length or distance codes than DEFLATE has");
    uint8_t length[286 + 30];
    memset(length, 0, sizeof length);
    for (int i = 0; i < ncode; i++) {
        if (get_bits(s, 3, &v))
            return -1;
        length[ORDER[i]] = (uint8_t)v;
    }
    huff *cl = dist; /* (the code-length code, before the distance code is built) */
    if (build(cl, length, 19))
        return fail(s, "a bad code-length code");
    memset(length, 0, 19);
    for (int i = 0; i < nlen + ndist;) {
        int sym;
        if (decode(s, cl, &sym))
            return -1;
        if (sym < 16) {
            length[i++] = (uint8_t)sym;
            continue;
        }
        uint8_t val = 0;
        int rep;
        if (sym == 16) {
            if (i == 0)
                return fail(s, "a repeated code length with none before it");
            val = length[i - 1];
            if (get_bits(s, 2, &v))
                return -1;
            rep = 3 + (int)v;
        } else if (sym == 17) {
            if (get_bits(s, 3, &v))
                return -1;
            rep = 3 + (int)v;
        } else {
            if (get_bits(s, 7, &v))
                return -1;
            rep = 11 + (int)v;
        }
        if (i + rep > nlen + ndist)
            return fail(s, "code lengths past the block's count");
        while (rep-- > 0)
            length[i++] = val;
    }
    if (length[256] == 0)
        return fail(s, "a block without an end code");
    if (build(lit, length, nlen))
        return fail(s, "a bad literal/length code");
    if (build(dist, length + nlen, ndist))
        return fail(s, "a bad distance code");
    return codes(s, lit, dist);
}

static uint32_t adler32(const uint8_t *p, size_t n)
{
    uint32_t a = 1, b = 0;
    while (n > 0) {
        size_t k = n < 5552 ? n : 5552; /* (no overflow before the modulo) */
        n -= k;
        while (k-- > 0) {
            a += *p++;
            b += a;
        }
        a %= 65521u;
        b %= 65521u;
    }
    return b << 16 | a;
}

int inflate_zlib(const uint8_t *in, size_t in_len, uint8_t *out, size_t out_len, const char **why,
                 size_t *at)
{
    inf s;
    memset(&s, 0, sizeof s);
    s.in = in;
    s.len = in_len;
    s.out = out;
    s.cap = out_len;
    huff lit, dist;
    int rc = 0;
    if (in_len < 2) {
        rc = fail(&s, "no zlib header (cut short)");
    } else if ((in[0] & 15u) != 8) {
        rc = fail(&s, "a zlib stream whose method is not deflate (8)");
    } else if ((in[0] >> 4) > 7) {
        rc = fail(&s, "a zlib window over 32 KiB");
    } else if (((unsigned)in[0] << 8 | in[1]) % 31u != 0) {
        rc = fail(&s, "a zlib header whose check bits are wrong");
    } else if (in[1] & 32u) {
        rc = fail(&s, "a zlib stream that needs a preset dictionary");
    } else {
        s.pos = 2;
        uint32_t last = 0, type;
        while (rc == 0 && !last) {
            if (get_bits(&s, 1, &last) || get_bits(&s, 2, &type))
                rc = -1;
            else if (type == 0)
                rc = stored(&s);
            else if (type == 1)
                rc = fixed(&s, &lit, &dist);
            else if (type == 2)
                rc = dynamic(&s, &lit, &dist);
            else
                rc = fail(&s, "a block of type 3 (reserved)");
        }
    }
    if (rc == 0) {
        to_byte(&s);
        if (s.n != out_len)
            rc = fail(&s, "the compressed data end before the image does");
        else if (s.len - s.pos < 4)
            rc = fail(&s, "the zlib stream's Adler-32 is missing (cut short)");
        else if (adler32(out, s.n) != ((uint32_t)in[s.pos] << 24 | (uint32_t)in[s.pos + 1] << 16 |
                                       (uint32_t)in[s.pos + 2] << 8 | in[s.pos + 3]))
            rc = fail(&s, "the unpacked data do not match the zlib stream's Adler-32");
        else if ((s.pos += 4) != s.len)
            rc = fail(&s, "bytes after the end of the zlib stream");
    }
    *why = rc ? s.why : NULL;
    *at = s.pos < in_len ? s.pos : in_len;
    return rc;
}
