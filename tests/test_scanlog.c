/* test_scanlog.c - the log parser: FLASER geometry and no-return rule,
 * ROBOTLASER1, the plain format round trip, and hostile input. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scanlog.h"

#define PI_D 3.14159265358979323846

static int parse_len(scanlog *log, const char *text, size_t len, double max_range_m)
{
    scanlog_opts o = {max_range_m};
    FILE *f = tmpfile();
    assert_non_null(f);
    assert_int_equal(fwrite(text, 1, len, f), len);
    rewind(f);
    int rc = scanlog_read(log, f, "t.log", &o);
    fclose(f);
    return rc;
}

static int parse(scanlog *log, const char *text)
{
    return parse_len(log, text, strlen(text), 0);
}

/* Parses text, expecting exactly this error. */
static void expect_error(const char *text, size_t len, const char *error)
{
    scanlog log;
    assert_int_equal(parse_len(&log, text, len, 0), -1);
    assert_string_equal(log.error, error);
    scanlog_free(&log);
}

/* For string literals, which may hold NUL bytes. */
#define EXPECT_ERROR(text, error) expect_error(text, sizeof(text) - 1, error)

static void near(double a, double b, double eps)
{
    if (!(fabs(a - b) <= eps))
        fail_msg("%.9g is not within %g of %.9g", a, eps, b);
}

/* A FLASER line of n beams, ranges from range_fn. */
static void flaser_line(FILE *f, uint32_t n, double x, double y, double th,
                        double (*range_fn)(uint32_t, uint32_t), uint32_t scan)
{
    fprintf(f, "FLASER %u", (unsigned)n);
    for (uint32_t i = 0; i < n; i++)
        fprintf(f, " %.2f", range_fn(scan, i));
    fprintf(f, " %.6f %.6f %.6f %.6f %.6f %.6f 1.5 host 1.6\n", x, y, th, x, y, th);
}

/* Deterministic "room" ranges in [1, 9] m. */
static double room_range(uint32_t scan, uint32_t i)
{
    uint32_t h = (scan * 2654435761u) ^ (i * 40503u + 977u);
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return 1.0 + 8.0 * (h % 10000u) / 10000.0;
}

/* Every 10th beam is the SICK code 81.91. */
static double sick_range(uint32_t scan, uint32_t i)
{
    return i % 10 == 3 ? 81.91 : room_range(scan, i);
}

/* Two codes, as in acapulco: 50.0 and 51.15 (and stray 51.1). */
static double two_code_range(uint32_t scan, uint32_t i)
{
    if (i % 20 == 1)
        return 50.0;
    if (i % 10 == 2)
        return i % 3 ? 51.15 : 51.1;
    return room_range(scan, i);
}

static char *make_log(uint32_t scans, uint32_t n, double (*range_fn)(uint32_t, uint32_t),
                      size_t *len)
{
    char *buf = NULL;
    FILE *f = open_memstream(&buf, len);
    assert_non_null(f);
    fputs("# a test log\nPARAM robot_x 0\n", f);
    for (uint32_t s = 0; s < scans; s++) {
        fprintf(f, "ODOM 0 0 0 0 0 0 1.0 host 1.0\n");
        flaser_line(f, n, 0.1 * s, -0.2 * s, 0.01 * s, range_fn, s);
        fprintf(f, "NEFF 15\n");
    }
    fclose(f);
    return buf;
}

/* ---- FLASER ---- */

static void test_flaser_angles(void **state)
{
    (void)state;
    const uint32_t counts[] = {180, 181, 360, 361, 90, 91, 1};
    const double steps_deg[] = {1, 1, 0.5, 0.5, 2, 2, 1};
    for (size_t k = 0; k < sizeof counts / sizeof counts[0]; k++) {
        size_t len;
        char *text = make_log(1, counts[k], room_range, &len);
        scanlog log;
        assert_int_equal(parse_len(&log, text, len, 0), 0);
        assert_int_equal(log.count, 1);
        const polyc_scan *s = &log.scans[0];
        assert_int_equal(s->beam_count, counts[k]);
        near((double)s->start_angle_rad, -PI_D / 2, 1e-6);
        near((double)s->angle_step_rad, steps_deg[k] * PI_D / 180, 1e-7);
        near((double)s->min_range_m, 0.02, 1e-7);
        assert_int_equal(s->reserved, 0);
        scanlog_free(&log);
        free(text);
    }
}

static void test_flaser_fields(void **state)
{
    (void)state;
    scanlog log;
    assert_int_equal(parse(&log, "FLASER 3 1.5 2.5 3.5 10 -20 0.5 0 0 0 0 h 0\n"), 0);
    assert_int_equal(log.count, 1);
    const polyc_scan *s = &log.scans[0];
    near(s->pose_x_m, 10, 0);
    near(s->pose_y_m, -20, 0);
    near(s->pose_theta_rad, 0.5, 0);
    near((double)s->range_m[0], 1.5, 0);
    near((double)s->range_m[2], 3.5, 0);
    near((double)s->angle_step_rad, PI_D / 2, 1e-7);   /* 3 beams span 180 deg */
    assert_int_equal(log.line_of_scan[0], 1);
    scanlog_free(&log);
}

/* Numbers the parser reads without strtod must be the very doubles strtod
 * gives: fixed cases at the fast path's edges, then pseudo-random decimals. */
static void expect_pose_x(const char *number)
{
    char text[160];
    snprintf(text, sizeof text, "FLASER 3 1 2 3 %s 0 0 0 0 0 0 h 0\n", number);
    scanlog log;
    if (parse(&log, text) != 0)
        fail_msg("'%s': %s", number, log.error);
    double want = strtod(number, NULL);
    if (memcmp(&log.scans[0].pose_x_m, &want, sizeof want) != 0)
        fail_msg("'%s' read as %.17g, strtod gives %.17g", number, log.scans[0].pose_x_m, want);
    scanlog_free(&log);
}

static void test_numbers_as_strtod(void **state)
{
    (void)state;
    static const char *const fixed[] = {
        "0", "-0", "5.", ".5", "-.5", "0.1", "-17.3073", "00000.1250", "81.83",
        "123456.789012345", "123456.7890123456", "900719.9254740993", "0.000000000000001",
        "0.0000000000000001", "1.0000000000000000", "99999.99999999999", "1e3", "+2.5",
        "-0.000", "3.141592653589793"};
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++)
        expect_pose_x(fixed[i]);
    uint64_t state64 = 12345;
    for (int i = 0; i < 2000; i++) {
        state64 = state64 * 6364136223846793005ull + 1442695040888963407ull;
        double v = (double)(state64 >> 11) / 9007199254740992.0 * 2000.0 - 1000.0;
        char number[64];
        snprintf(number, sizeof number, "%.*f", (int)(state64 >> 60) % 14, v);
        expect_pose_x(number);
    }
}

static void test_noreturn_sick(void **state)
{
    (void)state;
    size_t len;
    char *text = make_log(40, 180, sick_range, &len);
    scanlog log;
    assert_int_equal(parse_len(&log, text, len, 0), 0);
    assert_int_equal(log.count, 40);
    assert_true(log.noreturn.found);
    near((double)log.noreturn.max_range_m, 81.905, 1e-4);
    near(log.noreturn.code_mode_m, 81.91, 1e-9);
    assert_int_equal(log.noreturn.code_beams, 40 * 18);
    for (uint32_t i = 0; i < log.count; i++) {
        const polyc_scan *s = &log.scans[i];
        assert_true(s->max_range_m == log.noreturn.max_range_m);
        assert_true(s->range_m[3] >= s->max_range_m);     /* the code: no return */
        assert_true(s->range_m[4] < s->max_range_m);      /* a wall: a hit */
    }
    scanlog_free(&log);
    /* --max-range overrides the rule */
    assert_int_equal(parse_len(&log, text, len, 5.0), 0);
    assert_true(log.noreturn.overridden);
    assert_true(log.scans[0].max_range_m == 5.0f);
    scanlog_free(&log);
    free(text);
}

static void test_noreturn_two_codes(void **state)
{
    (void)state;
    size_t len;
    char *text = make_log(40, 180, two_code_range, &len);
    scanlog log;
    assert_int_equal(parse_len(&log, text, len, 0), 0);
    assert_true(log.noreturn.found);
    near((double)log.noreturn.max_range_m, 49.995, 1e-4);
    near(log.noreturn.code_hi_m, 51.15, 1e-9);
    scanlog_free(&log);
    free(text);
}

static void test_noreturn_none(void **state)
{
    (void)state;
    size_t len;
    char *text = make_log(40, 180, room_range, &len);
    scanlog log;
    assert_int_equal(parse_len(&log, text, len, 0), 0);
    assert_false(log.noreturn.found);
    for (uint32_t i = 0; i < log.count; i++)               /* every range a hit */
        for (uint32_t j = 0; j < log.scans[i].beam_count; j++)
            assert_true(log.scans[i].range_m[j] < log.scans[i].max_range_m);
    scanlog_free(&log);
    free(text);
}

static void test_noreturn_direct(void **state)
{
    (void)state;
    enum { N = 5000 };
    float *r = malloc(N * sizeof *r);
    assert_non_null(r);
    for (uint32_t i = 0; i < N; i++)   /* 32.767 with jitter, as orebro */
        r[i] = i % 25 == 0 ? (i % 2 ? 32.767f : 32.763f) : (float)room_range(7, i);
    r[17] = 1e30f;                     /* junk above: still no return */
    r[18] = NAN;
    scanlog_noreturn nr;
    scanlog_detect_noreturn(r, N, &nr);
    assert_true(nr.found);
    near((double)nr.max_range_m, 32.755, 1e-4);
    free(r);
}

/* ---- ROBOTLASER1 ---- */

static void test_robotlaser1(void **state)
{
    (void)state;
    scanlog log;
    const char *text =
        "ROBOTLASER1 0 -1.5 3.0 0.5 8.0 0.01 0 4 1.0 2.0 8.0 3.0 2 7 7 "
        "1.0 2.0 0.25 1.1 2.1 0.3 0 0 0 0 0 5.0 host 5.0\n"
        "ROBOTLASER1 0 1.5 3.0 -0.5 8.0 0.01 0 3 1.0 2.0 3.0 0 "
        "1.0 2.0 0.25 1.1 2.1 0.3 0 0 0 0 0 5.0 host 5.0\n";
    assert_int_equal(parse(&log, text), 0);
    assert_int_equal(log.count, 2);
    const polyc_scan *s = &log.scans[0];
    near(s->pose_x_m, 1.0, 0);                     /* the laser pose */
    near(s->pose_theta_rad, 0.25, 0);
    near((double)s->start_angle_rad, -1.5, 1e-7);
    near((double)s->angle_step_rad, 0.5, 1e-7);
    assert_true(s->max_range_m == 8.0f);
    assert_true(s->range_m[2] >= s->max_range_m);  /* 8.0 is no return */
    s = &log.scans[1];                             /* negative step: reversed */
    near((double)s->start_angle_rad, 0.5, 1e-7);
    near((double)s->angle_step_rad, 0.5, 1e-7);
    near((double)s->range_m[0], 3.0, 0);
    near((double)s->range_m[2], 1.0, 0);
    assert_int_equal(log.kind_counts[SCANLOG_ROBOTLASER1], 2);
    scanlog_free(&log);
    EXPECT_ERROR("ROBOTLASER1 0 -1.5 3.0 0.5 8.0 0.01 0 2 1.0 2.0 0 1 2 3\n",
                 "t.log:1: ROBOTLASER1 with 0 remissions needs 14 fields after the count,"
                 " found 3");
}

/* ---- plain format ---- */

static void assert_same_scans(const scanlog *a, const scanlog *b)
{
    assert_int_equal(a->count, b->count);
    for (uint32_t i = 0; i < a->count; i++) {
        const polyc_scan *s = &a->scans[i], *t = &b->scans[i];
        assert_memory_equal(&s->pose_x_m, &t->pose_x_m, sizeof(double));
        assert_memory_equal(&s->pose_y_m, &t->pose_y_m, sizeof(double));
        assert_memory_equal(&s->pose_theta_rad, &t->pose_theta_rad, sizeof(double));
        assert_memory_equal(&s->start_angle_rad, &t->start_angle_rad, sizeof(float));
        assert_memory_equal(&s->angle_step_rad, &t->angle_step_rad, sizeof(float));
        assert_memory_equal(&s->min_range_m, &t->min_range_m, sizeof(float));
        assert_memory_equal(&s->max_range_m, &t->max_range_m, sizeof(float));
        assert_int_equal(s->beam_count, t->beam_count);
        for (uint32_t j = 0; j < s->beam_count; j++)
            if (isnan(s->range_m[j]))
                assert_true(isnan(t->range_m[j]));
            else
                assert_memory_equal(&s->range_m[j], &t->range_m[j], sizeof(float));
    }
}

static void round_trip(const char *text, size_t len)
{
    scanlog a, b;
    char *buf = NULL;
    size_t blen = 0;
    assert_int_equal(parse_len(&a, text, len, 0), 0);
    FILE *f = open_memstream(&buf, &blen);
    assert_non_null(f);
    assert_int_equal(scanlog_write_plain(f, a.scans, a.count), 0);
    fclose(f);
    assert_true(strncmp(buf, "# polyc-scans 1\n", 16) == 0);
    assert_int_equal(parse_len(&b, buf, blen, 0), 0);
    assert_int_equal(b.kind_counts[SCANLOG_PLAIN], a.count);
    assert_same_scans(&a, &b);
    assert_int_equal(a.bad_ranges + a.short_ranges, b.bad_ranges);   /* all NaN now */
    scanlog_free(&a);
    scanlog_free(&b);
    free(buf);
}

static void test_plain_round_trip(void **state)
{
    (void)state;
    size_t len;
    char *text = make_log(30, 361, sick_range, &len);
    round_trip(text, len);
    free(text);
    const char *odd = "FLASER 4 nan -1 inf 1e-3 0.1234567891234 -7.000000001 3.14159 0 0 0 0 h 0\n"
                      "ROBOTLASER1 0 -1.5 3.0 -0.5 8.0 0.01 0 3 1.0 2.0 3.0 0 "
                      "1.0 2.0 0.25 1.1 2.1 0.3 0 0 0 0 0 5.0 host 5.0\n";
    round_trip(odd, strlen(odd));
}

static void test_plain_fields(void **state)
{
    (void)state;
    scanlog log;
    assert_int_equal(parse(&log, "# polyc-scans 1\nSCAN 1 2 0.5 -1 0.25 0.1 4 3 1 2 5\n"), 0);
    const polyc_scan *s = &log.scans[0];
    near((double)s->start_angle_rad, -1, 0);
    near((double)s->angle_step_rad, 0.25, 0);
    near((double)s->min_range_m, 0.1, 1e-7);
    near((double)s->max_range_m, 4, 0);
    assert_int_equal(s->beam_count, 3);
    scanlog_free(&log);
    EXPECT_ERROR("# polyc-scans 2\nSCAN 1 2 0.5 -1 0.25 0.1 4 0\n",
                 "t.log:1: unsupported polyc-scans version '2' (this reader: 1)");
    EXPECT_ERROR("SCAN 1 2 0.5 -1 0 0.1 4 0\n", "t.log:1: angle step 0 rad not in (0, 6.2832]");
}

/* ---- line handling ---- */

static void test_crlf_and_last_line(void **state)
{
    (void)state;
    scanlog log;
    const char *text = "ODOM 1 2 3\r\nFLASER 2 1 2 0 0 0 0 0 0 0 h 0\r\n"
                       "FLASER 2 1 2 5 6 0 0 0 0 0 h 0";   /* no final newline */
    assert_int_equal(parse(&log, text), 0);
    assert_int_equal(log.count, 2);
    assert_int_equal(log.lines, 3);
    near(log.scans[1].pose_y_m, 6, 0);
    near((double)log.scans[0].range_m[1], 2, 0);
    scanlog_free(&log);
}

static void test_skipped_counted(void **state)
{
    (void)state;
    scanlog log;
    const char *text = "# comment\n  # indented comment\nPARAM a b\n\nODOM 1 2 3\nODOM 1\n"
                       "NEFF 15\nRLASER 1 2\nFLASER 1 1 0 0 0 0 0 0 0 h 0\n";
    assert_int_equal(parse(&log, text), 0);
    assert_int_equal(log.count, 1);
    assert_int_equal(log.lines, 9);
    assert_int_equal(log.blank_lines, 1);
    assert_int_equal(log.skipped_lines, 7);
    assert_int_equal(log.keyword_count, 5);
    assert_string_equal(log.keywords[0].name, "#");
    assert_int_equal(log.keywords[0].count, 2);
    assert_string_equal(log.keywords[2].name, "ODOM");
    assert_int_equal(log.keywords[2].count, 2);
    scanlog_free(&log);
}

static void test_bad_ranges_counted(void **state)
{
    (void)state;
    scanlog log;
    assert_int_equal(parse(&log, "FLASER 7 nan -0.5 inf 1e999 0 0.019 2 0 0 0 0 0 0 0 h 0\n"), 0);
    assert_int_equal(log.bad_ranges, 4);
    assert_int_equal(log.short_ranges, 2);      /* error codes below 2 cm */
    for (int i = 0; i < 6; i++)
        assert_true(isnan(log.scans[0].range_m[i]));
    near((double)log.scans[0].range_m[6], 2, 0);
    scanlog_free(&log);
    /* the plain format passes short ranges on: its min range says what they are */
    assert_int_equal(parse(&log, "SCAN 0 0 0 0 0.1 0.05 4 2 0.01 -1\n"), 0);
    near((double)log.scans[0].range_m[0], 0.01, 1e-9);
    assert_true(isnan(log.scans[0].range_m[1]));
    assert_int_equal(log.short_ranges, 0);
    scanlog_free(&log);
}

static void test_errors(void **state)
{
    (void)state;
    EXPECT_ERROR("ODOM 0\nFLASER 3 1 2 0 0 0 0 0 0 0 h 0\n",
                 "t.log:2: FLASER with 3 beams needs 12 fields after the count, found 11");
    EXPECT_ERROR("FLASER 2147483648 1 2\n",
                 "t.log:1: beam count 2147483648 out of range (at most 1048576)");
    EXPECT_ERROR("FLASER -3 1 2\n", "t.log:1: beam count is not a count: '-3' (field 2)");
    EXPECT_ERROR("FLASER 2 1 x2 0 0 0 0 0 0 0 h 0\n",
                 "t.log:1: range is not a number: 'x2' (field 4)");
    EXPECT_ERROR("FLASER 2 1 2 nan 0 0 0 0 0 0 h 0\n", "t.log:1: pose x is not finite");
    EXPECT_ERROR("FLASER 2 1 2 0 -inf 0 0 0 0 0 h 0\n", "t.log:1: pose y is not finite");
    EXPECT_ERROR("FLASER 2 1 2 0 2e6 0 0 0 0 0 h 0\n",
                 "t.log:1: pose y 2e+06 beyond +-1e+06 m");
    EXPECT_ERROR("FLASER 2 1 2 0 0 0x 0 0 0 0 h 0\n",
                 "t.log:1: pose theta is not a number: '0x' (field 7)");
    EXPECT_ERROR("ODOM 1\nFL\001ASER 1 2\n", "t.log:2: binary data (byte 0x01 at column 3)");
    EXPECT_ERROR("ODOM 1\nFLASER\0 1 2\n", "t.log:2: binary data (byte 0x00 at column 7)");
    EXPECT_ERROR("\x89PNG\r\n", "t.log:1: not a log line: starts with '\\x89PNG'");
    EXPECT_ERROR("", "t.log: no scans found (0"
                     " lines read; polyc reads CARMEN FLASER and ROBOTLASER1 lines, polyc's SCAN lines, or a map_server map YAML)");
    EXPECT_ERROR("# only\nODOM 1\n", "t.log: no scans found (2"
                     " lines read; polyc reads CARMEN FLASER and ROBOTLASER1 lines, polyc's SCAN lines, or a map_server map YAML)");
}

/* Every scan read is one the library accepts (fuzz_scanlog findings): the
 * library's angle and range rules are checked by line, on the float values. */
static void test_library_rules(void **state)
{
    (void)state;
    scanlog log;
    /* ROBOTLASER1 without beams and a negative step: nothing to reverse */
    assert_int_equal(parse(&log, "ROBOTLASER1 0 1.57 3.14 -0.5 8 0.01 0 0 0 0.5 0.25 0.1 0.5 "
                                 "0.25 0.1 0 0 0.5 0.5 0 1.0 host 1.0\n"),
                     0);
    near((double)log.scans[0].start_angle_rad, 1.57, 1e-6);
    assert_true(log.scans[0].angle_step_rad > 0.0f);
    scanlog_free(&log);
    /* a FLASER log of zero-beam scans: no ranges, no pool */
    assert_int_equal(parse(&log, "FLASER 0 0 0 0 0 0 0 0 h 0\n"), 0);
    assert_int_equal(log.count, 1);
    scanlog_free(&log);
    EXPECT_ERROR("SCAN 0 0 0 150 0.1 0.05 4 1 1\n",
                 "t.log:1: start angle 150 rad beyond +-100 rad");
    EXPECT_ERROR("SCAN 0 0 0 0 7 0.05 4 1 1\n", "t.log:1: angle step 7 rad not in (0, 6.2832]");
    EXPECT_ERROR("SCAN 0 0 0 0 1e-50 0.05 4 2 1 1\n",
                 "t.log:1: angle step 0 rad not in (0, 6.2832]");
    EXPECT_ERROR("ROBOTLASER1 0 -1 3 0.5 8 0.01 0 300 0 0\n",
                 "t.log:1: ROBOTLASER1 with 300 beams has only 2 fields after the count");
    /* min and max equal as floats */
    EXPECT_ERROR("SCAN 0 0 0 0 0.1 0.99999999999 1 1 1\n",
                 "t.log:1: max range 1 m not above min range 1 m");
    /* --max-range below a SCAN line's min range */
    assert_int_equal(parse_len(&log, "SCAN 0 0 0 0 0.1 6 8 1 7\n", 25, 5.0), -1);
    assert_string_equal(log.error, "t.log:1: max range 5 m not above min range 6 m"
                                   " (max range lowered by option)");
    scanlog_free(&log);
    /* a no-return code at 2 cm: the threshold stays above the min range */
    scanlog_noreturn nr;
    float r[40];
    for (int i = 0; i < 40; i++)
        r[i] = 0.02f;
    scanlog_detect_noreturn(r, 40, &nr);
    assert_true(nr.max_range_m > SCANLOG_MIN_RANGE_M);
    /* a field quoted in a message carries no raw bytes */
    EXPECT_ERROR("SCAN 0 0 0 0 0.1 0.05 4 1 \x9b[2J\n",
                 "t.log:1: range is not a number: '\\x9b[2J' (field 10)");
    /* a last line cut short says so */
    EXPECT_ERROR("SCAN 0 0 0 0 0.1 0.05 4 3 1 1",
                 "t.log:1: SCAN with 3 beams needs 3 fields after the count, found 2"
                 " (the file ends inside this line: truncated?)");
    EXPECT_ERROR("FLASER 99999999999999999999999 1\n",
                 "t.log:1: beam count 99999999999999999999999 out of range (at most 1048576)");
}

static void test_long_lines(void **state)
{
    (void)state;
    /* 10 MB of ranges after a wrong count: an error, no crash */
    size_t n = 10u * 1024u * 1024u;
    char *text = malloc(n + 1);
    assert_non_null(text);
    memcpy(text, "FLASER 5", 8);
    for (size_t i = 8; i + 1 < n; i += 2)
        memcpy(text + i, " 1", 2);
    text[n - 1] = '\n';
    expect_error(text, n, "t.log:1: FLASER with 5 beams needs 14 fields after the count,"
                          " found 5242875");
    free(text);
    /* a line past the limit */
    n = SCANLOG_MAX_LINE_BYTES + 10u;
    text = malloc(n);
    assert_non_null(text);
    memset(text, 'A', n);
    expect_error(text, n, "t.log:1: line longer than 33554432 bytes");
    free(text);
    /* a very long number */
    char num[200];
    memset(num, 0, sizeof num);
    memcpy(num, "FLASER 1 ", 9);
    memset(num + 9, '1', 100);
    memcpy(num + 109, " 0 0 0 0 0 0 0 h 0\n", 19);
    expect_error(num, strlen(num),
                 "t.log:1: range is not a number: '111111111111111111111111...' (field 3)");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_flaser_angles),
        cmocka_unit_test(test_flaser_fields),
        cmocka_unit_test(test_numbers_as_strtod),
        cmocka_unit_test(test_noreturn_sick),
        cmocka_unit_test(test_noreturn_two_codes),
        cmocka_unit_test(test_noreturn_none),
        cmocka_unit_test(test_noreturn_direct),
        cmocka_unit_test(test_robotlaser1),
        cmocka_unit_test(test_plain_round_trip),
        cmocka_unit_test(test_plain_fields),
        cmocka_unit_test(test_crlf_and_last_line),
        cmocka_unit_test(test_skipped_counted),
        cmocka_unit_test(test_bad_ranges_counted),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_long_lines),
        cmocka_unit_test(test_library_rules),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
