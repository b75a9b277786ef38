/* textesc.c - input bytes as printable ASCII for messages (textesc.h).
 * Takes: bytes. Gives: the same text with each byte outside 0x20..0x7e as \xNN. */
#include "textesc.h"

#include <stdlib.h>
#include <string.h>

size_t textesc(char *out, const char *s, size_t len)
{
    static const char hex[] = "0123456789abcdef";
    size_t o = 0;
    for (size_t i = 0; i < len; i++) {
        unsigned char c = (unsigned char)s[i];
        if (c >= 0x20 && c < 0x7f) {
            out[o++] = (char)c;
        } else {
            out[o++] = '\\';
            out[o++] = 'x';
            out[o++] = hex[c >> 4];
            out[o++] = hex[c & 15];
        }
    }
    out[o] = '\0';
    return o;
}

const char *textesc_quote(textesc_excerpt *e, const char *s, size_t len)
{
    size_t n = len < TEXTESC_EXCERPT_BYTES ? len : TEXTESC_EXCERPT_BYTES;
    size_t o = textesc(e->text, s, n);
    if (n < len)
        memcpy(e->text + o, "...", 4);
    return e->text;
}

char *textesc_dup(const char *s)
{
    size_t n = strlen(s);
    char *out = malloc(4 * n + 1);
    if (out)
        textesc(out, s, n);
    return out;
}
