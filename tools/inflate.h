/* inflate.h - a zlib stream (RFC 1950) of DEFLATE blocks (RFC 1951)
 * unpacked into a buffer the caller sizes: the PNG reader's (mapfile_png.c)
 * image data, whose unpacked size the image header fixes. */
#ifndef POLYC_INFLATE_H
#define POLYC_INFLATE_H

#include <stddef.h>
#include <stdint.h>

/* Unpacks the zlib stream in[0..in_len) into out[0..out_len), which it must
 * fill exactly. Returns 0, or -1 with *why a static message and *at the
 * offset into `in` where the fault was found: a bad header, a preset
 * dictionary, a bad block, code or distance, more or less data than
 * out_len, an Adler-32 that does not match, bytes after the stream. */
int inflate_zlib(const uint8_t *in, size_t in_len, uint8_t *out, size_t out_len, const char **why,
                 size_t *at);

#endif /* POLYC_INFLATE_H */
