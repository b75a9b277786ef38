/* scanlog.c - laser log lines in, polyc_scan records out.
 * Takes: a FILE of CARMEN FLASER / ROBOTLASER1 or polyc plain SCAN lines.
 * Gives: owned scans, line counters, the FLASER no-return threshold, or
 * one "NAME:LINE: message" error. Rules are in docs/formats.md. */
#include "scanlog.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "scanlog_noreturn.h"
#include "textesc.h"

#define PI_D 3.14159265358979323846
#define MAX_NUMBER_CHARS 64          /* longer tokens are not numbers we accept */
#define FLASER_TAIL 9                /* x y theta ox oy otheta ipc_ts host log_ts */
#define ROBOTLASER1_TAIL 14          /* laser pose, robot pose, 5 motion, 3 stamps */

/* ---- the reader ---- */

typedef struct reader {
    scanlog *log;
    const char *name;
    uint64_t line;
    double max_range_m;              /* opts->max_range_m or 0 */
    char *buf;
    size_t cap;
    int partial;                     /* the last line read ended at EOF, not '\n' */
} reader;

/* A cursor over the whitespace-separated fields of one line. */
typedef struct fields {
    char *p;
    uint32_t index;                  /* 1-based number of the last field taken */
} fields;

static int fail(reader *r, const char *fmt, ...)
{
    char msg[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (r->line > 0)
        snprintf(r->log->error, sizeof r->log->error, "%s:%llu: %s", r->name,
                 (unsigned long long)r->line, msg);
    else
        snprintf(r->log->error, sizeof r->log->error, "%s: %s", r->name, msg);
    return -1;
}

static int is_space(int c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* Up to 24 bytes of field s for a message, with "..." if longer, bytes
 * outside printable ASCII as \xNN (textesc.h). */
static const char *quote(textesc_excerpt *e, const char *s)
{
    return textesc_quote(e, s, strlen(s));
}

/* Reads one line into r->buf without its '\n' (a final line may lack it).
 * 1: a line, 0: end of file, -1: error (NUL, control byte, too long, I/O). */
static int read_line(reader *r, FILE *f, size_t *len_out)
{
    size_t len = 0;
    int c;
    r->line++;
    while ((c = getc_unlocked(f)) != EOF && c != '\n') {
        if (c == 0 || (c < 0x20 && !is_space(c)) || c == 0x7f)
            return fail(r, "binary data (byte 0x%02x at column %llu)", (unsigned)c,
                        (unsigned long long)len + 1);
        if (len + 1 >= r->cap) {
            if (r->cap >= SCANLOG_MAX_LINE_BYTES)
                return fail(r, "line longer than %u bytes", SCANLOG_MAX_LINE_BYTES);
            size_t ncap = r->cap ? r->cap * 2 : 4096;
            char *nbuf = realloc(r->buf, ncap);
            if (!nbuf)
                return fail(r, "out of memory reading a line");
            r->buf = nbuf;
            r->cap = ncap;
        }
        r->buf[len++] = (char)c;
    }
    if (ferror(f))
        return fail(r, "read error: %s", strerror(errno));
    if (c == EOF && len == 0) {
        r->line--;
        return 0;
    }
    if (!r->buf) {                   /* an empty first line */
        r->buf = malloc(4096);
        if (!r->buf)
            return fail(r, "out of memory reading a line");
        r->cap = 4096;
    }
    r->buf[len] = '\0';
    r->partial = c == EOF;
    *len_out = len;
    return 1;
}

/* Next field, NUL-terminated in place; NULL at the end of the line. */
static char *next_field(fields *fs)
{
    char *p = fs->p;
    while (*p && is_space((unsigned char)*p))
        p++;
    if (!*p) {
        fs->p = p;
        return NULL;
    }
    char *start = p;
    while (*p && !is_space((unsigned char)*p))
        p++;
    if (*p)
        *p++ = '\0';
    fs->p = p;
    fs->index++;
    return start;
}

static uint64_t count_fields(const char *p)
{
    uint64_t n = 0;
    while (*p) {
        while (*p && is_space((unsigned char)*p))
            p++;
        if (!*p)
            break;
        n++;
        while (*p && !is_space((unsigned char)*p))
            p++;
    }
    return n;
}

/* Plain decimals ([-]digits[.digits], at most 15 significant digits, as
 * laser logs write ranges) without strtod: the digits make an integer below
 * 2^53 and 10^k is exact, so one division gives the correctly rounded value,
 * the same double strtod returns. Anything else returns 0 for strtod. */
static int plain_decimal(const char *s, size_t len, double *out)
{
    static const double pow10[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7,
                                   1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
    size_t i = s[0] == '-';
    uint64_t m = 0;
    int digits = 0, frac = -1;
    for (; i < len; i++) {
        char c = s[i];
        if (c >= '0' && c <= '9') {
            m = m * 10u + (uint64_t)(c - '0');
            if (m != 0 && ++digits > 15)
                return 0;
            if (frac >= 0)
                frac++;
        } else if (c == '.' && frac < 0) {
            frac = 0;
        } else {
            return 0;
        }
    }
    /* at least one digit, and a digit on one side of the point */
    if (len == (size_t)(s[0] == '-') + (frac >= 0) || frac > 15)
        return 0;
    double v = (double)m / pow10[frac > 0 ? frac : 0];
    *out = s[0] == '-' ? -v : v;
    return 1;
}

/* A number with nothing after it; NaN and inf are numbers here (callers
 * decide). Fails on missing, non-numeric or over-long fields. */
static int take_double(reader *r, fields *fs, const char *what, double *out)
{
    char *s = next_field(fs);
    if (!s)
        return fail(r, "missing %s (field %u)", what, fs->index + 1);
    size_t len = strlen(s);
    char *end = NULL;
    if (len <= MAX_NUMBER_CHARS && plain_decimal(s, len, out))
        return 0;
    if (len <= MAX_NUMBER_CHARS)
        *out = strtod(s, &end);
    if (len > MAX_NUMBER_CHARS || end != s + len) {
        textesc_excerpt e;
        return fail(r, "%s is not a number: '%s' (field %u)", what, quote(&e, s), fs->index);
    }
    /* Overflow gives +-HUGE_VAL, underflow a tiny number (errno ERANGE):
     * the callers' range checks judge both. */
    return 0;
}

static int take_count(reader *r, fields *fs, const char *what, uint32_t max, uint32_t *out)
{
    char *s = next_field(fs);
    if (!s)
        return fail(r, "missing %s (field %u)", what, fs->index + 1);
    size_t len = strlen(s);
    unsigned long long v = 0;
    textesc_excerpt e;
    for (size_t i = 0; i < len; i++) {
        if (s[i] < '0' || s[i] > '9')
            return fail(r, "%s is not a count: '%s' (field %u)", what, quote(&e, s), fs->index);
        if (v <= max)                /* stops growing once too big: no overflow */
            v = v * 10 + (unsigned)(s[i] - '0');
    }
    if (v > max)
        return fail(r, "%s %s out of range (at most %u)", what, quote(&e, s), max);
    *out = (uint32_t)v;
    return 0;
}

static int take_pose(reader *r, fields *fs, const char *what, double *x, double *y,
                     double *theta)
{
    char name[64];
    double *v[3] = {x, y, theta};
    const char *axis[3] = {"x", "y", "theta"};
    for (int i = 0; i < 3; i++) {
        snprintf(name, sizeof name, "%s %s", what, axis[i]);
        if (take_double(r, fs, name, v[i]))
            return -1;
        double lim = i < 2 ? SCANLOG_MAX_POSE_M : SCANLOG_MAX_ANGLE_RAD;
        if (!isfinite(*v[i]))
            return fail(r, "%s is not finite", name);
        if (fabs(*v[i]) > lim)
            return fail(r, "%s %g beyond +-%g %s", name, *v[i], lim, i < 2 ? "m" : "rad");
    }
    return 0;
}

static int take_angle(reader *r, fields *fs, const char *what, double *out)
{
    if (take_double(r, fs, what, out))
        return -1;
    if (!isfinite(*out) || fabs(*out) > SCANLOG_MAX_ANGLE_RAD)
        return fail(r, "%s %g is not a finite angle within +-%g rad", what, *out,
                    SCANLOG_MAX_ANGLE_RAD);
    return 0;
}

static int grow(reader *r, void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t ncap = *cap ? *cap : 1024;
    while (ncap < need)
        ncap *= 2;
    if (ncap > SIZE_MAX / elem)
        return fail(r, "out of memory");
    void *np = realloc(*p, ncap * elem);
    if (!np)
        return fail(r, "out of memory");
    *p = np;
    *cap = ncap;
    return 0;
}

/* Appends n ranges to the pool. Bad values (NaN, inf, negative) and values
 * in [0, short_m) become NaN, which the library counts as skipped: neither
 * hit nor free space. CARMEN lasers write error codes below their minimum
 * range (Hokuyo: 0..19 mm); they mean "no reading", not "nothing there". */
static int take_ranges(reader *r, fields *fs, uint32_t n, float short_m)
{
    scanlog *log = r->log;
    if (grow(r, (void **)&log->pool, &log->pool_cap, log->pool_len + n, sizeof(float)))
        return -1;
    for (uint32_t i = 0; i < n; i++) {
        double v;
        if (take_double(r, fs, "range", &v))
            return -1;
        float f = (float)v;
        if (!isfinite(v) || v < 0 || !isfinite(f)) {
            f = NAN;
            log->bad_ranges++;
        } else if (f < short_m) {
            f = NAN;
            log->short_ranges++;
        }
        log->pool[log->pool_len + i] = f;
    }
    return 0;
}

/* Records the scan whose ranges were just appended to the pool. */
static int push_scan(reader *r, const polyc_scan *s, enum scanlog_kind kind)
{
    scanlog *log = r->log;
    if (log->count == UINT32_MAX - 1)
        return fail(r, "too many scans");
    if (log->beams + s->beam_count > UINT32_MAX)
        return fail(r, "more than %u beams in total", (unsigned)UINT32_MAX);
    if (log->count == log->cap) {
        size_t cap = log->cap ? (size_t)log->cap * 2 : 256;
        if (cap > UINT32_MAX)
            cap = UINT32_MAX;
        if (cap > SIZE_MAX / sizeof *log->scans)   /* 32-bit size_t */
            return fail(r, "out of memory");
        void *a = realloc(log->scans, cap * sizeof *log->scans);
        if (a)
            log->scans = a;
        void *b = realloc(log->line_of_scan, cap * sizeof *log->line_of_scan);
        if (b)
            log->line_of_scan = b;
        void *c = realloc(log->kind_of_scan, cap * sizeof *log->kind_of_scan);
        if (c)
            log->kind_of_scan = c;
        void *d = realloc(log->offset_of_scan, cap * sizeof *log->offset_of_scan);
        if (d)
            log->offset_of_scan = d;
        if (!a || !b || !c || !d)
            return fail(r, "out of memory");
        log->cap = (uint32_t)cap;
    }
    log->scans[log->count] = *s;
    log->scans[log->count].range_m = NULL;   /* set in finish(): the pool moves */
    log->line_of_scan[log->count] = r->line;
    log->kind_of_scan[log->count] = (uint8_t)kind;
    log->offset_of_scan[log->count] = log->pool_len;
    log->pool_len += s->beam_count;
    log->beams += s->beam_count;
    log->kind_counts[kind]++;
    log->count++;
    return 0;
}

/* Exactly n + tail fields must remain after a count of `items`. */
static int check_tail(reader *r, fields *fs, const char *type, const char *items, uint32_t n,
                      uint64_t tail)
{
    uint64_t rest = count_fields(fs->p);
    if (rest != (uint64_t)n + tail)
        return fail(r, "%s with %u %s needs %llu fields after the count, found %llu", type, n,
                    items, (unsigned long long)n + tail, (unsigned long long)rest);
    return 0;
}

/* FLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_ts host logger_ts */
static int parse_flaser(reader *r, fields *fs)
{
    polyc_scan s;
    uint32_t n;
    memset(&s, 0, sizeof s);
    if (take_count(r, fs, "beam count", SCANLOG_MAX_BEAMS_SCAN, &n) ||
        check_tail(r, fs, "FLASER", "beams", n, FLASER_TAIL) ||
        take_ranges(r, fs, n, SCANLOG_MIN_RANGE_M) ||
        take_pose(r, fs, "pose", &s.pose_x_m, &s.pose_y_m, &s.pose_theta_rad))
        return -1;
    double inc = PI_D / 180.0;                   /* CARMEN: 180/181 beams, 1 deg */
    if (n == 360 || n == 361)
        inc = PI_D / 360.0;
    else if (n != 180 && n != 181 && n > 1)     /* any other count spans 180 deg */
        inc = n % 2 ? PI_D / (n - 1) : PI_D / n;
    s.start_angle_rad = (float)(-PI_D / 2);
    s.angle_step_rad = (float)inc;
    s.min_range_m = SCANLOG_MIN_RANGE_M;
    s.max_range_m = 0;                           /* set by the no-return rule */
    s.beam_count = n;
    return push_scan(r, &s, SCANLOG_FLASER);
}

/* Beam order reversed so that the step is positive (the library's rule). */
static void reverse_last(scanlog *log, size_t n)
{
    float *a = log->pool + log->pool_len;    /* n > 1: the pool holds them */
    for (size_t i = 0; i < n / 2; i++) {
        float t = a[i];
        a[i] = a[n - 1 - i];
        a[n - 1 - i] = t;
    }
}

/* The library's rules (polyc_add_scan) on the float values it will get, so
 * that every scan read is one it accepts and a bad one is named by line. */
static int check_scan(reader *r, const polyc_scan *s)
{
    if (!(fabsf(s->start_angle_rad) <= SCANLOG_MAX_START_RAD))
        return fail(r, "start angle %g rad beyond +-%g rad", (double)s->start_angle_rad,
                    (double)SCANLOG_MAX_START_RAD);
    if (!(s->angle_step_rad > 0.0f && s->angle_step_rad <= SCANLOG_MAX_STEP_RAD))
        return fail(r, "angle step %g rad not in (0, %g]", (double)s->angle_step_rad,
                    (double)SCANLOG_MAX_STEP_RAD);
    if (!(s->max_range_m > s->min_range_m))
        return fail(r, "max range %g m not above min range %g m%s", (double)s->max_range_m,
                    (double)s->min_range_m,
                    r->max_range_m > 0 ? " (max range lowered by option)" : "");
    return 0;
}

static int check_max_range(reader *r, double max_range_m, polyc_scan *s)
{
    if (!isfinite(max_range_m) || max_range_m <= (double)SCANLOG_MIN_RANGE_M ||
        max_range_m > SCANLOG_MAX_POSE_M)
        return fail(r, "max range %g m out of (%g, %g]", max_range_m,
                    (double)SCANLOG_MIN_RANGE_M, SCANLOG_MAX_POSE_M);
    if (r->max_range_m > 0 && r->max_range_m < max_range_m)
        max_range_m = r->max_range_m;
    s->max_range_m = (float)max_range_m;
    return 0;
}

/* ROBOTLASER1 type start fov res max_range accuracy remission_mode n r1..rn
 *   m rem1..remm laser_x laser_y laser_theta robot_x .. (14 fields) */
static int parse_robotlaser1(reader *r, fields *fs)
{
    polyc_scan s;
    double type, start, fov, res, max_range, accuracy, mode;
    uint32_t n, m;
    memset(&s, 0, sizeof s);
    if (take_double(r, fs, "laser_type", &type) || take_angle(r, fs, "start_angle", &start) ||
        take_double(r, fs, "fov", &fov) || take_angle(r, fs, "angular_res", &res) ||
        take_double(r, fs, "max_range", &max_range) ||
        take_double(r, fs, "accuracy", &accuracy) ||
        take_double(r, fs, "remission_mode", &mode) ||
        take_count(r, fs, "beam count", SCANLOG_MAX_BEAMS_SCAN, &n))
        return -1;
    uint64_t rest = count_fields(fs->p);
    if (rest < (uint64_t)n + 1)
        return fail(r, "ROBOTLASER1 with %u beams has only %llu fields after the count",
                    n, (unsigned long long)rest);
    if (take_ranges(r, fs, n, SCANLOG_MIN_RANGE_M) ||
        take_count(r, fs, "remission count", SCANLOG_MAX_BEAMS_SCAN, &m) ||
        check_tail(r, fs, "ROBOTLASER1", "remissions", m, ROBOTLASER1_TAIL))
        return -1;
    for (uint32_t i = 0; i < m; i++)
        next_field(fs);
    if (take_pose(r, fs, "laser pose", &s.pose_x_m, &s.pose_y_m, &s.pose_theta_rad) ||
        check_max_range(r, max_range, &s))
        return -1;
    if (res == 0 && n > 1)
        return fail(r, "angular_res is 0 with %u beams", n);
    if (res < 0 && n > 1) {
        reverse_last(r->log, n);
        start += (n - 1) * res;
        res = -res;
    }
    s.start_angle_rad = (float)start;
    s.angle_step_rad = n > 1 ? (float)res : 1.0f;   /* one beam or none: any step */
    s.min_range_m = SCANLOG_MIN_RANGE_M;
    s.beam_count = n;
    if (check_scan(r, &s))
        return -1;
    return push_scan(r, &s, SCANLOG_ROBOTLASER1);
}

/* SCAN x y theta start step min max n r1..rn (docs/formats.md) */
static int parse_plain(reader *r, fields *fs)
{
    polyc_scan s;
    double start, step, min_r, max_r;
    uint32_t n;
    memset(&s, 0, sizeof s);
    if (take_pose(r, fs, "pose", &s.pose_x_m, &s.pose_y_m, &s.pose_theta_rad) ||
        take_angle(r, fs, "start angle", &start) || take_angle(r, fs, "angle step", &step) ||
        take_double(r, fs, "min range", &min_r) || take_double(r, fs, "max range", &max_r) ||
        take_count(r, fs, "beam count", SCANLOG_MAX_BEAMS_SCAN, &n) ||
        check_tail(r, fs, "SCAN", "beams", n, 0) || take_ranges(r, fs, n, 0.0f))
        return -1;
    if (!isfinite(min_r) || min_r < 0 || min_r >= max_r)
        return fail(r, "min range %g m must be finite, >= 0 and below max range", min_r);
    if (check_max_range(r, max_r, &s))
        return -1;
    s.start_angle_rad = (float)start;
    s.angle_step_rad = (float)step;
    s.min_range_m = (float)min_r;
    s.beam_count = n;
    if (check_scan(r, &s))
        return -1;
    return push_scan(r, &s, SCANLOG_PLAIN);
}

static void count_keyword(scanlog *log, const char *word)
{
    log->skipped_lines++;
    for (uint32_t i = 0; i < log->keyword_count; i++)
        if (strcmp(log->keywords[i].name, word) == 0) {
            log->keywords[i].count++;
            return;
        }
    if (log->keyword_count < SCANLOG_MAX_KEYWORDS) {
        scanlog_keyword *k = &log->keywords[log->keyword_count++];
        snprintf(k->name, sizeof k->name, "%s", word);
        k->count = 1;
    }
}

/* A line type we skip: letters, digits and '_' (CARMEN's message names). */
static int is_keyword(const char *s)
{
    size_t n = strlen(s);
    if (n == 0 || n >= sizeof(((scanlog_keyword *)0)->name))
        return 0;
    for (size_t i = 0; i < n; i++) {
        char c = s[i];
        if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
              c == '_'))
            return 0;
    }
    return 1;
}

static int parse_comment(reader *r, char *line)
{
    fields fs = {line + 1, 0};
    char *w = next_field(&fs);
    if (w && strcmp(w, "polyc-scans") == 0) {
        char *v = next_field(&fs);
        textesc_excerpt e;
        if (!v || strcmp(v, "1") != 0)
            return fail(r, "unsupported polyc-scans version '%s' (this reader: 1)",
                        quote(&e, v ? v : ""));
    }
    count_keyword(r->log, "#");
    return 0;
}

static int parse_line(reader *r, char *line)
{
    fields fs = {line, 0};
    char *p = line;
    while (*p && is_space((unsigned char)*p))
        p++;
    if (*p == '#')
        return parse_comment(r, p);
    char *word = next_field(&fs);
    if (!word) {
        r->log->blank_lines++;
        return 0;
    }
    if (strcmp(word, "FLASER") == 0)
        return parse_flaser(r, &fs);
    if (strcmp(word, "ROBOTLASER1") == 0)
        return parse_robotlaser1(r, &fs);
    if (strcmp(word, "SCAN") == 0)
        return parse_plain(r, &fs);
    if (!is_keyword(word)) {
        textesc_excerpt e;
        return fail(r, "not a log line: starts with '%s'", quote(&e, word));
    }
    count_keyword(r->log, word);
    return 0;
}

/* Applies the no-return rule to FLASER scans and points scans at the pool. */
static int finish(reader *r)
{
    scanlog *log = r->log;
    if (log->count == 0)
        return fail(r, "no scans found (%llu lines read; polyc reads CARMEN FLASER and"
                       " ROBOTLASER1 lines, polyc's SCAN lines, or a map_server map YAML)",
                    (unsigned long long)log->lines);
    if (log->kind_counts[SCANLOG_FLASER]) {
        scanlog_noreturn *nr = &log->noreturn;
        if (r->max_range_m > 0) {
            memset(nr, 0, sizeof *nr);
            nr->overridden = 1;
            nr->max_range_m = (float)r->max_range_m;
        } else {
            scanlog_nr_hist h;
            if (scanlog_nr_open(&h) != 0)
                return fail(r, "out of memory");
            for (uint32_t i = 0; i < log->count; i++) {
                if (log->kind_of_scan[i] != SCANLOG_FLASER || !log->scans[i].beam_count)
                    continue;         /* no ranges: the pool may be NULL */
                const float *a = log->pool + log->offset_of_scan[i];
                for (uint32_t j = 0; j < log->scans[i].beam_count; j++)
                    scanlog_nr_add(&h, a[j]);
            }
            scanlog_nr_pick(&h, nr);
            scanlog_nr_close(&h);
        }
        for (uint32_t i = 0; i < log->count; i++)
            if (log->kind_of_scan[i] == SCANLOG_FLASER)
                log->scans[i].max_range_m = nr->max_range_m;
    }
    for (uint32_t i = 0; i < log->count; i++)
        log->scans[i].range_m = log->scans[i].beam_count ? log->pool + log->offset_of_scan[i]
                                                         : NULL;
    return 0;
}

int scanlog_read(scanlog *log, FILE *f, const char *name, const scanlog_opts *opts)
{
    reader r;
    size_t len;
    int got;
    memset(log, 0, sizeof *log);
    memset(&r, 0, sizeof r);
    r.log = log;
    r.name = name;
    r.max_range_m = opts && opts->max_range_m > (double)SCANLOG_MIN_RANGE_M ? opts->max_range_m : 0;
    while ((got = read_line(&r, f, &len)) == 1) {
        log->lines++;
        size_t pool_len = log->pool_len;
        if (parse_line(&r, r.buf)) {
            log->pool_len = pool_len;
            if (r.partial) {             /* say why a last line may be cut short */
                size_t n = strlen(log->error);
                snprintf(log->error + n, sizeof log->error - n,
                         " (the file ends inside this line: truncated?)");
            }
            break;
        }
    }
    free(r.buf);
    if (got != 0)
        return -1;
    r.line = 0;
    return finish(&r);
}

void scanlog_free(scanlog *log)
{
    free(log->scans);
    free(log->line_of_scan);
    free(log->kind_of_scan);
    free(log->offset_of_scan);
    free(log->pool);
    memset(log, 0, sizeof *log);
}

/* ---- the plain format writer ---- */

static void put_float(FILE *f, double v, int digits)
{
    if (isnan(v))
        fputs(" nan", f);
    else if (isinf(v))
        fputs(v > 0 ? " inf" : " -inf", f);
    else
        fprintf(f, " %.*g", digits, v);
}

int scanlog_write_plain(FILE *f, const polyc_scan *scans, uint32_t count)
{
    fputs("# polyc-scans 1\n"
          "# SCAN x_m y_m theta_rad start_angle_rad angle_step_rad min_range_m max_range_m"
          " n range_1_m .. range_n_m\n",
          f);
    for (uint32_t i = 0; i < count; i++) {
        const polyc_scan *s = &scans[i];
        fputs("SCAN", f);
        put_float(f, s->pose_x_m, 17);
        put_float(f, s->pose_y_m, 17);
        put_float(f, s->pose_theta_rad, 17);
        put_float(f, (double)s->start_angle_rad, 9);
        put_float(f, (double)s->angle_step_rad, 9);
        put_float(f, (double)s->min_range_m, 9);
        put_float(f, (double)s->max_range_m, 9);
        fprintf(f, " %u", (unsigned)s->beam_count);
        for (uint32_t j = 0; j < s->beam_count; j++)
            put_float(f, (double)s->range_m[j], 9);
        fputc('\n', f);
    }
    return ferror(f) ? -1 : 0;
}
