/* mapfile.c - ROS map_server maps in: the map YAML (mapfile.h; the image
 * and map_saver's files out are in mapfile_pgm.c).
 * Takes: a map YAML's bytes. Gives: its fields, whether a file's head looks
 * like one, the image's path; one "NAME:LINE:" message on failure. Rules
 * are in docs/formats.md ("ROS maps"). */
#include "mapfile.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "textesc.h"

/* ---- the YAML ---- */

enum key { K_IMAGE, K_RESOLUTION, K_ORIGIN, K_NEGATE, K_OCCUPIED, K_FREE, K_MODE, K_COUNT,
           K_UNKNOWN = K_COUNT, K_NONE };
static const char *const key_names[K_COUNT] = {"image",           "resolution",  "origin", "negate",
                                               "occupied_thresh", "free_thresh", "mode"};

/* the state of the current key's value */
enum value_state { V_DONE, V_PENDING, V_FLOW, V_BLOCK_SEQ };

typedef struct yparser {
    mapfile_yaml *y;
    const char *name;
    uint32_t line;
    int key_indent;            /* indent of top-level keys; -1 before the first */
    int key;                   /* enum key of the current value */
    uint32_t key_line;
    int state;                 /* enum value_state */
    int flow_expect_item;      /* V_FLOW: 1 before an item, 0 before ',' or ']' */
    double origin[3];
    uint32_t origin_n;         /* elements seen (may exceed 3, for the message) */
    uint32_t seen[K_COUNT];    /* line of each key, 0: not yet */
    char *scratch;             /* one unquoted scalar, len + 1 bytes */
} yparser;

static int yfail(yparser *p, uint32_t line, const char *fmt, ...)
{
    char msg[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    snprintf(p->y->error, sizeof p->y->error, "%s:%u: %s", p->name, (unsigned)line, msg);
    return -1;
}

static int is_blank(char c) { return c == ' ' || c == '\t'; }

/* UTF-8 of code point u into out (at least 4 bytes); bytes written. */
static size_t put_utf8(char *out, uint32_t u)
{
    if (u < 0x80) {
        out[0] = (char)u;
        return 1;
    }
    if (u < 0x800) {
        out[0] = (char)(0xc0 | (u >> 6));
        out[1] = (char)(0x80 | (u & 0x3f));
        return 2;
    }
    if (u < 0x10000) {
        out[0] = (char)(0xe0 | (u >> 12));
        out[1] = (char)(0x80 | ((u >> 6) & 0x3f));
        out[2] = (char)(0x80 | (u & 0x3f));
        return 3;
    }
    out[0] = (char)(0xf0 | (u >> 18));
    out[1] = (char)(0x80 | ((u >> 12) & 0x3f));
    out[2] = (char)(0x80 | ((u >> 6) & 0x3f));
    out[3] = (char)(0x80 | (u & 0x3f));
    return 4;
}

static int hex_value(char c)
{
    return c >= '0' && c <= '9' ? c - '0'
           : c >= 'a' && c <= 'f' ? c - 'a' + 10
           : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                  : -1;
}

/* Reads one scalar of s[0..n) from *pos into p->scratch (*out_len bytes,
 * NUL-terminated; a NUL from an escape makes *has_nul 1). In a flow list a
 * plain scalar ends at ',' or ']'; everywhere at " #" or the end. Leaves
 * *pos after the scalar (and after a closing quote). 0, or -1 with the
 * message set. */
static int read_scalar(yparser *p, const char *s, size_t n, size_t *pos, int in_flow,
                       size_t *out_len, int *has_nul)
{
    size_t i = *pos, o = 0;
    char *out = p->scratch;
    textesc_excerpt e;
    *has_nul = 0;
    if (i < n && s[i] == '\'') {
        for (i++;; i++) {
            if (i >= n)
                return yfail(p, p->line, "unterminated single quote");
            if (s[i] == '\'') {
                if (i + 1 < n && s[i + 1] == '\'') {
                    out[o++] = '\'';
                    i++;
                    continue;
                }
                i++;
                break;
            }
            out[o++] = s[i];
        }
    } else if (i < n && s[i] == '"') {
        for (i++;; i++) {
            if (i >= n)
                return yfail(p, p->line, "unterminated double quote");
            char c = s[i];
            if (c == '"') {
                i++;
                break;
            }
            if (c != '\\') {
                out[o++] = c;
                continue;
            }
            if (++i >= n)
                return yfail(p, p->line, "unterminated double quote");
            static const char from[] = "0abtnvfre \"/\\";
            static const char to[] = "\0\a\b\t\n\v\f\r\033 \"/\\";
            const char *k = strchr(from, s[i]);
            if (k && s[i] && (size_t)(k - from) < sizeof to - 1) {
                out[o++] = to[k - from];
                *has_nul |= to[k - from] == '\0';
                continue;
            }
            int digits = s[i] == 'x' ? 2 : s[i] == 'u' ? 4 : s[i] == 'U' ? 8 : 0;
            if (!digits)
                return yfail(p, p->line, "unknown escape '\\%s' in a double-quoted string",
                             textesc_quote(&e, s + i, 1));
            uint32_t u = 0;
            for (int d = 0; d < digits; d++) {
                int h = i + 1 + (size_t)d < n ? hex_value(s[i + 1 + (size_t)d]) : -1;
                if (h < 0)
                    return yfail(p, p->line, "escape '\\%c' needs %d hex digits", s[i], digits);
                u = u * 16u + (uint32_t)h;
            }
            if (u > 0x10ffff || (u >= 0xd800 && u <= 0xdfff))
                return yfail(p, p->line, "escape '\\%c' is not a character", s[i]);
            i += (size_t)digits;
            *has_nul |= u == 0;
            o += put_utf8(out + o, u);
        }
    } else {
        size_t start = i, end = i;
        for (; i < n; i++) {
            if (in_flow && (s[i] == ',' || s[i] == ']' || s[i] == '[' || s[i] == '{' ||
                            s[i] == '}'))
                break;
            if (s[i] == '#' && i > start && is_blank(s[i - 1]))
                break;
            if (!is_blank(s[i]))
                end = i + 1;
        }
        o = end - start;
        memcpy(out, s + start, o);
        i = end;
    }
    out[o] = '\0';
    *out_len = o;
    *pos = i;
    return 0;
}

/* After a scalar in block context: only blanks and a comment may follow. */
static int expect_line_end(yparser *p, const char *s, size_t n, size_t i, const char *what)
{
    textesc_excerpt e;
    size_t j = i;
    while (j < n && is_blank(s[j]))
        j++;
    if (j < n && !(s[j] == '#' && j > i))
        return yfail(p, p->line, "unexpected '%s' after the %s", textesc_quote(&e, s + j, n - j),
                     what);
    return 0;
}

/* A YAML float as map_server takes it: [-+](digits[.digits]|.digits)[e[-+]digits],
 * finite. 0 or -1. */
static int parse_number(const char *s, double *out)
{
    const char *q = s;
    int mant = 0;
    if (*q == '-' || *q == '+')
        q++;
    while (*q >= '0' && *q <= '9') {
        q++;
        mant++;
    }
    if (*q == '.') {
        q++;
        while (*q >= '0' && *q <= '9') {
            q++;
            mant++;
        }
    }
    if (!mant)
        return -1;
    if (*q == 'e' || *q == 'E') {
        q++;
        if (*q == '-' || *q == '+')
            q++;
        if (!(*q >= '0' && *q <= '9'))
            return -1;
        while (*q >= '0' && *q <= '9')
            q++;
    }
    if (*q || q - s > 64)
        return -1;
    errno = 0;
    double v = strtod(s, NULL);
    if (!isfinite(v))
        return -1;
    *out = v;
    return 0;
}

/* One number of the origin list. */
static int origin_item(yparser *p, const char *s, size_t len)
{
    textesc_excerpt e;
    double v;
    if (parse_number(s, &v))
        return yfail(p, p->line, "origin: '%s' is not a number", textesc_quote(&e, s, len));
    if (p->origin_n < 3)
        p->origin[p->origin_n] = v;
    p->origin_n++;
    return 0;
}

static int is_bool(const char *s, int *out)
{
    static const char *const yes[] = {"true", "True", "TRUE", "yes", "Yes", "YES", "on", "On", "ON"};
    static const char *const no[] = {"false", "False", "FALSE", "no", "No", "NO", "off", "Off", "OFF"};
    for (size_t i = 0; i < sizeof yes / sizeof yes[0]; i++) {
        if (strcmp(s, yes[i]) == 0) {
            *out = 1;
            return 1;
        }
        if (strcmp(s, no[i]) == 0) {
            *out = 0;
            return 1;
        }
    }
    return 0;
}

/* The scalar value of a known key other than origin. */
static int set_scalar(yparser *p, const char *s, size_t len, int has_nul)
{
    mapfile_yaml *y = p->y;
    textesc_excerpt e;
    double v;
    const char *k = key_names[p->key];
    switch (p->key) {
    case K_IMAGE:
        if (len == 0)
            return yfail(p, p->line, "image is empty");
        if (has_nul)
            return yfail(p, p->line, "image holds a NUL character");
        if (len > MAPFILE_MAX_IMAGE_NAME)
            return yfail(p, p->line, "image name longer than %u bytes", MAPFILE_MAX_IMAGE_NAME);
        free(y->image);
        if (!(y->image = malloc(len + 1)))
            return yfail(p, p->line, "out of memory");
        memcpy(y->image, s, len + 1);
        y->image_line = p->line;
        return 0;
    case K_RESOLUTION:
        if (parse_number(s, &v))
            return yfail(p, p->line, "resolution: '%s' is not a number", textesc_quote(&e, s, len));
        if (!(v > 0))
            return yfail(p, p->line, "resolution %s must be above 0 m", textesc_quote(&e, s, len));
        if (v < MAPFILE_MIN_RESOLUTION_M || v > MAPFILE_MAX_RESOLUTION_M)
            return yfail(p, p->line, "resolution %s m is outside [%g, %g] m",
                         textesc_quote(&e, s, len), MAPFILE_MIN_RESOLUTION_M,
                         MAPFILE_MAX_RESOLUTION_M);
        y->resolution_m = v;
        return 0;
    case K_NEGATE:
        if (strcmp(s, "0") == 0 || strcmp(s, "1") == 0)
            y->negate = s[0] == '1';
        else if (!is_bool(s, &y->negate))
            return yfail(p, p->line, "negate must be 0 or 1 (or true, false), not '%s'",
                         textesc_quote(&e, s, len));
        return 0;
    case K_OCCUPIED:
    case K_FREE:
        if (parse_number(s, &v))
            return yfail(p, p->line, "%s: '%s' is not a number", k, textesc_quote(&e, s, len));
        if (!(v >= 0.0 && v <= 1.0))
            return yfail(p, p->line, "%s %s is outside [0, 1]", k, textesc_quote(&e, s, len));
        *(p->key == K_FREE ? &y->free_thresh : &y->occupied_thresh) = v;
        return 0;
    case K_MODE:
        if (strcmp(s, "trinary") == 0)
            y->mode = MAPFILE_TRINARY;
        else if (strcmp(s, "scale") == 0)
            y->mode = MAPFILE_SCALE;
        else if (strcmp(s, "raw") == 0)
            y->mode = MAPFILE_RAW;
        else
            return yfail(p, p->line, "mode must be trinary, scale or raw, not '%s'",
                         textesc_quote(&e, s, len));
        return 0;
    default:
        return 0;
    }
}

/* Feeds part of a flow list [x, y, yaw] (of origin) from s[i..n). */
static int flow_feed(yparser *p, const char *s, size_t n, size_t i)
{
    textesc_excerpt e;
    while (i < n) {
        if (is_blank(s[i])) {
            i++;
            continue;
        }
        if (s[i] == '#' && (i == 0 || is_blank(s[i - 1])))
            return 0;                          /* a comment: the list goes on */
        if (p->state == V_DONE)
            return yfail(p, p->line, "unexpected '%s' after the list",
                         textesc_quote(&e, s + i, n - i));
        if (s[i] == ']') {
            p->state = V_DONE;
            i++;
            continue;
        }
        if (p->flow_expect_item) {
            if (s[i] == ',')
                return yfail(p, p->line, "origin: an empty element in the list");
            if (s[i] == '[' || s[i] == '{')
                return yfail(p, p->line, "origin: elements must be numbers, not lists");
            size_t len;
            int nul;
            if (read_scalar(p, s, n, &i, 1, &len, &nul) || origin_item(p, p->scratch, len))
                return -1;
            p->flow_expect_item = 0;
        } else if (s[i] == ',') {
            p->flow_expect_item = 1;
            i++;
        } else {
            return yfail(p, p->line, "origin: expected ',' or ']', found '%s'",
                         textesc_quote(&e, s + i, n - i));
        }
    }
    return 0;
}

/* The value of a known key starts at s[i..n) (non-empty, not a comment). */
static int value_start(yparser *p, const char *s, size_t n, size_t i)
{
    textesc_excerpt e;
    const char *k = key_names[p->key];
    char c = s[i];
    if (c == '&' || c == '*' || c == '!')
        return yfail(p, p->line, "%s: anchors, aliases and tags are not read", k);
    if (c == '|' || c == '>')
        return yfail(p, p->line, "%s: block scalars (| and >) are not read", k);
    if (p->key == K_ORIGIN) {
        if (c != '[')
            return yfail(p, p->line, "origin must be a list [x, y, yaw], not '%s'",
                         textesc_quote(&e, s + i, n - i));
        p->state = V_FLOW;
        p->flow_expect_item = 1;
        p->origin_n = 0;
        return flow_feed(p, s, n, i + 1);
    }
    if (c == '[' || c == '{')
        return yfail(p, p->line, "%s must be a single value, not a %s", k,
                     c == '[' ? "list" : "map");
    size_t len;
    int nul;
    if (read_scalar(p, s, n, &i, 0, &len, &nul) || expect_line_end(p, s, n, i, k))
        return -1;
    p->state = V_DONE;
    return set_scalar(p, p->scratch, len, nul);
}

/* The current key's value is complete (a new key or the end follows). */
static int key_end(yparser *p)
{
    if (p->key >= K_COUNT)
        return 0;
    const char *k = key_names[p->key];
    if (p->state == V_PENDING)
        return yfail(p, p->key_line, "%s has no value", k);
    if (p->state == V_FLOW)
        return yfail(p, p->key_line, "origin: the list is not closed with ']'");
    if (p->key == K_ORIGIN) {
        if (p->origin_n != 3)
            return yfail(p, p->key_line, "origin must have 3 elements [x, y, yaw], not %u",
                         (unsigned)p->origin_n);
        if (fabs(p->origin[0]) > MAPFILE_MAX_ORIGIN_M || fabs(p->origin[1]) > MAPFILE_MAX_ORIGIN_M)
            return yfail(p, p->key_line, "origin x or y beyond +-%g m", MAPFILE_MAX_ORIGIN_M);
        if (fabs(p->origin[2]) > MAPFILE_MAX_YAW_RAD)
            return yfail(p, p->key_line, "origin yaw beyond +-%g rad", MAPFILE_MAX_YAW_RAD);
        p->y->origin_x_m = p->origin[0];
        p->y->origin_y_m = p->origin[1];
        p->y->origin_yaw_rad = p->origin[2];
    }
    return 0;
}

static int is_seq_item(const char *s, size_t n)
{
    return n >= 1 && s[0] == '-' && (n == 1 || is_blank(s[1]));
}

/* An indented line (or a list item under an empty value) that belongs to
 * the current key. */
static int continuation(yparser *p, const char *s, size_t n)
{
    textesc_excerpt e;
    if (p->key == K_UNKNOWN)
        return 0;
    if (p->key == K_NONE)
        return yfail(p, p->line, "indented line before the first key");
    const char *k = key_names[p->key];
    if (p->state == V_FLOW)
        return flow_feed(p, s, n, 0);
    if (p->state == V_PENDING && !is_seq_item(s, n))
        return value_start(p, s, n, 0);
    if ((p->state == V_PENDING || p->state == V_BLOCK_SEQ) && is_seq_item(s, n)) {
        if (p->key != K_ORIGIN)
            return yfail(p, p->line, "%s must be a single value, not a list", k);
        if (p->state == V_PENDING)
            p->origin_n = 0;
        p->state = V_BLOCK_SEQ;
        size_t i = 1, len;
        int nul;
        while (i < n && is_blank(s[i]))
            i++;
        if (i == n || s[i] == '#')
            return yfail(p, p->line, "origin: an empty element in the list");
        if (s[i] == '[' || s[i] == '{' || is_seq_item(s + i, n - i))
            return yfail(p, p->line, "origin: elements must be numbers, not lists");
        if (read_scalar(p, s, n, &i, 0, &len, &nul) || expect_line_end(p, s, n, i, "number"))
            return -1;
        return origin_item(p, p->scratch, len);
    }
    if (p->state == V_BLOCK_SEQ)
        return yfail(p, p->line, "origin: expected '- number', found '%s'",
                     textesc_quote(&e, s, n));
    return yfail(p, p->line, "unexpected indented line after %s (line %u)", k,
                 (unsigned)p->key_line);
}

/* A top-level `key: value` line (s is the line without its indent). */
static int key_line(yparser *p, const char *s, size_t n)
{
    textesc_excerpt e;
    size_t i = 0, klen;
    const char *kname;
    if (key_end(p))
        return -1;
    if (is_seq_item(s, n))
        return yfail(p, p->line, "a list where a key was expected: a map YAML is key: value lines");
    if (s[0] == '{' || s[0] == '[')
        return yfail(p, p->line, "a flow %s where a key was expected: write one key: value a line",
                     s[0] == '{' ? "map" : "list");
    if (s[0] == '"' || s[0] == '\'') {
        int nul;
        if (read_scalar(p, s, n, &i, 0, &klen, &nul))
            return -1;
        while (i < n && is_blank(s[i]))
            i++;
        if (i >= n || s[i] != ':')
            return yfail(p, p->line, "expected ':' after the quoted key");
        kname = p->scratch;
    } else {
        for (; i < n; i++) {
            if (s[i] == ':' && (i + 1 == n || is_blank(s[i + 1])))
                break;
            if (s[i] == '#' && i > 0 && is_blank(s[i - 1]))
                i = n;
        }
        if (i >= n)
            return yfail(p, p->line, "expected 'key: value', found '%s'", textesc_quote(&e, s, n));
        klen = i;
        while (klen > 0 && is_blank(s[klen - 1]))
            klen--;
        kname = s;
    }
    i++;                                       /* the ':' */
    p->key = K_UNKNOWN;
    for (int k = 0; k < K_COUNT; k++)
        if (strlen(key_names[k]) == klen && memcmp(key_names[k], kname, klen) == 0)
            p->key = k;
    p->key_line = p->line;
    p->state = V_DONE;
    if (p->key == K_UNKNOWN)
        return 0;                              /* ignored, with what is indented below */
    if (p->seen[p->key])
        return yfail(p, p->line, "%s given twice (first on line %u)", key_names[p->key],
                     (unsigned)p->seen[p->key]);
    p->seen[p->key] = p->line;
    while (i < n && is_blank(s[i]))
        i++;
    if (i == n || s[i] == '#') {
        p->state = V_PENDING;
        return 0;
    }
    return value_start(p, s, n, i);
}

/* One line without its end of line. */
static int yaml_line(yparser *p, const char *s, size_t n)
{
    size_t indent = 0;
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)s[i];
        if ((c < 0x20 && c != '\t') || c == 0x7f)
            return yfail(p, p->line, "binary data (byte 0x%02x at column %u)", (unsigned)c,
                         (unsigned)i + 1);
    }
    while (n > 0 && is_blank(s[n - 1]))
        n--;
    while (indent < n && s[indent] == ' ')
        indent++;
    if (indent == n || s[indent] == '#')
        return 0;                              /* blank or a comment */
    if (s[indent] == '\t')
        return yfail(p, p->line, "a tab in the indentation (YAML indents with spaces)");
    s += indent;
    n -= indent;
    int doc_start = n >= 3 && memcmp(s, "---", 3) == 0 && (n == 3 || is_blank(s[3]));
    if (p->key_indent < 0 && indent == 0 && (doc_start || s[0] == '%')) {
        if (doc_start && expect_line_end(p, s, n, 3, "'---'"))
            return -1;
        return 0;                              /* document start, directives */
    }
    if (indent == 0 && doc_start)
        return yfail(p, p->line, "a second YAML document ('---'): one map a file");
    if (p->key_indent >= 0 &&
        ((int)indent > p->key_indent ||
         ((int)indent == p->key_indent && is_seq_item(s, n) &&
          (p->state == V_PENDING || p->state == V_BLOCK_SEQ || p->key == K_UNKNOWN))))
        return continuation(p, s, n);
    if (p->key_indent >= 0 && (int)indent != p->key_indent)
        return yfail(p, p->line, "indented by %u, the keys above by %d", (unsigned)indent,
                     p->key_indent);
    p->key_indent = (int)indent;
    return key_line(p, s, n);
}

int mapfile_yaml_parse(mapfile_yaml *y, const char *text, size_t len, const char *name)
{
    yparser p;
    memset(y, 0, sizeof *y);
    memset(&p, 0, sizeof p);
    p.y = y;
    p.name = name;
    p.key_indent = -1;
    p.key = K_NONE;
    if (len > MAPFILE_MAX_YAML_BYTES) {
        snprintf(y->error, sizeof y->error, "%s: larger than %u bytes: not a map YAML", name,
                 MAPFILE_MAX_YAML_BYTES);
        return -1;
    }
    if (!(p.scratch = malloc(len + 1))) {
        snprintf(y->error, sizeof y->error, "%s: out of memory", name);
        return -1;
    }
    size_t pos = 0;
    if (len >= 3 && memcmp(text, "\xef\xbb\xbf", 3) == 0)
        pos = 3;                               /* a UTF-8 byte order mark */
    int rc = 0;
    while (rc == 0 && pos < len) {
        const char *nl = memchr(text + pos, '\n', len - pos);
        size_t end = nl ? (size_t)(nl - text) : len, n = end - pos;
        p.line++;
        if (n > 0 && text[pos + n - 1] == '\r')
            n--;
        if (n == 3 && memcmp(text + pos, "...", 3) == 0) {
            pos = len;                         /* document end: the rest is not read */
            break;
        }
        rc = yaml_line(&p, text + pos, n);
        pos = end + 1;
    }
    y->lines = p.line;
    y->resolution_line = p.seen[K_RESOLUTION];
    y->origin_line = p.seen[K_ORIGIN];
    if (rc == 0)
        rc = key_end(&p);
    for (int k = 0; rc == 0 && k < K_COUNT; k++)
        if (!p.seen[k] && k != K_MODE)
            rc = yfail(&p, p.line ? p.line : 1, "no %s key (map_server needs it)", key_names[k]);
    if (rc == 0 && !(y->free_thresh < y->occupied_thresh)) {
        uint32_t line = p.seen[K_FREE] > p.seen[K_OCCUPIED] ? p.seen[K_FREE] : p.seen[K_OCCUPIED];
        rc = yfail(&p, line, "free_thresh %g must be below occupied_thresh %g", y->free_thresh,
                   y->occupied_thresh);
    }
    free(p.scratch);
    return rc;
}

void mapfile_yaml_free(mapfile_yaml *y)
{
    free(y->image);
    y->image = NULL;
}

int mapfile_is_yaml(const char *head, size_t len)
{
    size_t i = len >= 3 && memcmp(head, "\xef\xbb\xbf", 3) == 0 ? 3 : 0;
    while (i < len) {
        while (i < len && (is_blank(head[i]) || head[i] == '\r'))
            i++;
        if (i < len && head[i] != '\n' && head[i] != '#')
            break;
        while (i < len && head[i] != '\n')     /* blank or a comment: next line */
            i++;
        i++;
    }
    if (i >= len)
        return 0;
    const char *s = head + i;
    size_t n = len - i, k = 0;
    if (n >= 3 && memcmp(s, "---", 3) == 0 && (n == 3 || is_blank(s[3]) || s[3] == '\r' ||
                                               s[3] == '\n'))
        return 1;
    if (s[0] == '"' || s[0] == '\'') {
        for (k = 1; k < n && s[k] != s[0] && s[k] != '\n'; k++)
            ;
        if (k >= n || s[k] != s[0])
            return 0;
        k++;
    } else {
        while (k < n && ((s[k] >= 'a' && s[k] <= 'z') || (s[k] >= 'A' && s[k] <= 'Z') ||
                         (s[k] >= '0' && s[k] <= '9') || s[k] == '_' || s[k] == '-' ||
                         s[k] == '.'))
            k++;
        if (k == 0)
            return 0;
    }
    while (k < n && is_blank(s[k]))
        k++;
    return k < n && s[k] == ':' &&
           (k + 1 == n || is_blank(s[k + 1]) || s[k + 1] == '\r' || s[k + 1] == '\n');
}

char *mapfile_image_path(const char *yaml_path, const char *image)
{
    const char *slash = strrchr(yaml_path, '/');
    size_t dir = image[0] == '/' || !slash ? 0 : (size_t)(slash - yaml_path) + 1;
    size_t n = strlen(image);
    char *out = malloc(dir + n + 1);
    if (out) {
        memcpy(out, yaml_path, dir);
        memcpy(out + dir, image, n + 1);
    }
    return out;
}

void mapfile_grid(const mapfile_yaml *y, uint32_t width, uint32_t height, const int8_t *cells,
                  polyc_occupancy_grid *g)
{
    memset(g, 0, sizeof *g);
    g->width = width;
    g->height = height;
    g->resolution_m = (float)y->resolution_m;
    g->origin_x_m = y->origin_x_m;
    g->origin_y_m = y->origin_y_m;
    g->origin_yaw_rad = y->origin_yaw_rad;
    g->cells = cells;
}
