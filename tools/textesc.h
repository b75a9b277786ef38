/* textesc.h - input bytes made safe for a message: every byte outside
 * printable ASCII (0x20..0x7e) written as \xNN, so that a message never
 * carries raw input (terminal escapes, broken UTF-8). Used by the log
 * reader, the map readers and the tool. No allocation but textesc_dup's. */
#ifndef POLYC_TEXTESC_H
#define POLYC_TEXTESC_H

#include <stddef.h>

/* Writes the len bytes of s escaped to out, which must hold 4 * len + 1
 * bytes, NUL-terminated; returns the characters written (without the NUL). */
size_t textesc(char *out, const char *s, size_t len);

/* Up to TEXTESC_EXCERPT_BYTES bytes of s escaped, "..." after them if s
 * has more: a field quoted in an error message. */
#define TEXTESC_EXCERPT_BYTES 24
typedef struct textesc_excerpt {
    char text[TEXTESC_EXCERPT_BYTES * 4 + 4];
} textesc_excerpt;
const char *textesc_quote(textesc_excerpt *e, const char *s, size_t len);

/* The NUL-terminated s escaped, malloc'd; NULL if out of memory. */
char *textesc_dup(const char *s);

#endif /* POLYC_TEXTESC_H */
