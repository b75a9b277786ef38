/* test_mapfile.c - the ROS map readers and writers (tools/mapfile.c): the
 * YAML's keys, quoting, comments and lists, the image path, PGM P5 (8 and
 * 16 bits) and P2, the conversion to OccupancyGrid values in each mode, what
 * `polyc grid` writes, and every refused input with its line or byte. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mapfile.h"

/* map_saver's layout, after its image line */
#define SAVER_REST                                                                        \
    "resolution: 0.050000\norigin: [-10.000000, -10.000000, 0.000000]\nnegate: 0\n"        \
    "occupied_thresh: 0.65\nfree_thresh: 0.196\n\n"
#define SAVER_YAML "image: turtlebot3_world.pgm\n" SAVER_REST

static int parse(mapfile_yaml *y, const char *text)
{
    return mapfile_yaml_parse(y, text, strlen(text), "m.yaml");
}

static void expect_yaml_error(const char *text, const char *error)
{
    mapfile_yaml y;
    assert_int_equal(parse(&y, text), -1);
    assert_string_equal(y.error, error);
    mapfile_yaml_free(&y);
}

/* Parses text, which must succeed; the caller frees. */
static void parse_ok(mapfile_yaml *y, const char *text)
{
    int rc = parse(y, text);
    if (rc)
        fail_msg("%s", y->error);
}

static void test_yaml_map_saver_layout(void **state)
{
    (void)state;
    mapfile_yaml y;
    parse_ok(&y, SAVER_YAML);
    assert_string_equal(y.image, "turtlebot3_world.pgm");
    assert_true(y.resolution_m == 0.05);
    assert_true(y.origin_x_m == -10.0 && y.origin_y_m == -10.0 && y.origin_yaw_rad == 0.0);
    assert_int_equal(y.negate, 0);
    assert_true(y.occupied_thresh == 0.65);
    assert_true(y.free_thresh == 0.196);
    assert_int_equal(y.mode, MAPFILE_TRINARY);
    assert_int_equal(y.image_line, 1);
    assert_int_equal(y.resolution_line, 2);
    assert_int_equal(y.origin_line, 3);
    assert_int_equal(y.lines, 7);
    mapfile_yaml_free(&y);
}

static void test_yaml_each_key(void **state)
{
    (void)state;
    mapfile_yaml y;
    /* nav2's layout: mode first, numbers as yaml-cpp prints them, any order */
    parse_ok(&y, "mode: scale\nfree_thresh: 0.25\nimage: a.pgm\nresolution: 2.5e-2\n"
                 "origin: [1.5, -2, 0.7853981]\nnegate: 1\noccupied_thresh: .9\n");
    assert_int_equal(y.mode, MAPFILE_SCALE);
    assert_true(y.free_thresh == 0.25);
    assert_true(y.occupied_thresh == 0.9);
    assert_true(y.resolution_m == 0.025);
    assert_true(y.origin_x_m == 1.5 && y.origin_y_m == -2.0 && y.origin_yaw_rad == 0.7853981);
    assert_int_equal(y.negate, 1);
    mapfile_yaml_free(&y);
    parse_ok(&y, "image: a.pgm\nresolution: 1\norigin: [0, 0, 0]\nnegate: true\n"
                 "occupied_thresh: 1\nfree_thresh: 0\nmode: raw\n");
    assert_int_equal(y.mode, MAPFILE_RAW);
    assert_int_equal(y.negate, 1);
    assert_true(y.occupied_thresh == 1.0 && y.free_thresh == 0.0);
    mapfile_yaml_free(&y);
    parse_ok(&y, "image: a.pgm\nresolution: 1\norigin: [0, 0, 0]\nnegate: False\n"
                 "occupied_thresh: 0.5\nfree_thresh: 0.1\nmode: trinary\n");
    assert_int_equal(y.negate, 0);
    assert_int_equal(y.mode, MAPFILE_TRINARY);
    mapfile_yaml_free(&y);
}

static void test_yaml_quoting(void **state)
{
    (void)state;
    mapfile_yaml y;
    parse_ok(&y, "image: 'my map.pgm'\n\"resolution\": \"0.05\"\n'origin': ['1', \"2\", 3]\n"
                 "negate: '0'\noccupied_thresh: \"0.65\"\nfree_thresh: '0.196'\nmode: 'raw'\n");
    assert_string_equal(y.image, "my map.pgm");
    assert_true(y.resolution_m == 0.05);
    assert_true(y.origin_x_m == 1.0 && y.origin_y_m == 2.0 && y.origin_yaw_rad == 3.0);
    assert_int_equal(y.mode, MAPFILE_RAW);
    mapfile_yaml_free(&y);
    /* '' in single quotes; escapes in double quotes; '#' and ': ' inside quotes */
    parse_ok(&y, "image: 'it''s # here: x.pgm'\n" SAVER_REST);
    assert_string_equal(y.image, "it's # here: x.pgm");
    mapfile_yaml_free(&y);
    parse_ok(&y, "image: \"a\\\"b\\\\c\\t\\u00e9\\x41.pgm\"  # comment\n" SAVER_REST);
    assert_string_equal(y.image, "a\"b\\c\t\xc3\xa9" "A.pgm");
    mapfile_yaml_free(&y);
}

static void test_yaml_comments(void **state)
{
    (void)state;
    mapfile_yaml y;
    parse_ok(&y, "# a map\n---\n  # indented comment\nimage: a#b.pgm # the image\n"
                 "resolution: 0.1 #cell\norigin: [0, 0, 0] # pose\nnegate: 0 #comment\n"
                 "occupied_thresh: 0.65\nfree_thresh: 0.196\n...\nthis is not read\n");
    assert_string_equal(y.image, "a#b.pgm");
    assert_true(y.resolution_m == 0.1);
    mapfile_yaml_free(&y);
    /* '#' without a blank before it is part of the value */
    expect_yaml_error("negate: 0#x\n", "m.yaml:1: negate must be 0 or 1 (or true, false), not '0#x'");
    /* CRLF and a byte order mark */
    parse_ok(&y, "\xef\xbb\xbfimage: a.pgm\r\nresolution: 0.1\r\norigin: [0, 0, 0]\r\n"
                 "negate: 0\r\noccupied_thresh: 0.65\r\nfree_thresh: 0.196\r\n");
    assert_string_equal(y.image, "a.pgm");
    mapfile_yaml_free(&y);
}

static void test_yaml_lists_and_unknown_keys(void **state)
{
    (void)state;
    mapfile_yaml y;
    /* a flow list over lines, a block list, unknown keys with nested values */
    parse_ok(&y, "image: a.pgm\nsettings:\n  inner: [1, 2\n    , 3]\n  deep:\n    - x: 1\n"
                 "flow: {a: 1, b: [2, 3]}\norigin: [ -1.25 ,\n   2.5,  # y\n   0.1 ]\n"
                 "block:\n- 1\n- 2\nresolution: 0.5\nnegate: 0\noccupied_thresh: 0.65\n"
                 "free_thresh: 0.196\n");
    assert_true(y.origin_x_m == -1.25 && y.origin_y_m == 2.5 && y.origin_yaw_rad == 0.1);
    mapfile_yaml_free(&y);
    parse_ok(&y, "image: a.pgm\norigin:\n  - 4\n  - -5 # y\n  - 0.5\nresolution: 0.5\n"
                 "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n");
    assert_true(y.origin_x_m == 4.0 && y.origin_y_m == -5.0 && y.origin_yaw_rad == 0.5);
    mapfile_yaml_free(&y);
    parse_ok(&y, "image: a.pgm\norigin:\n- 4\n- 5\n- 6\nresolution:\n  0.5\n"
                 "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n");
    assert_true(y.origin_x_m == 4.0 && y.origin_yaw_rad == 6.0);
    assert_true(y.resolution_m == 0.5);
    mapfile_yaml_free(&y);
    /* keys indented alike are fine */
    parse_ok(&y, "  image: a.pgm\n  resolution: 0.5\n  origin: [0, 0, 0]\n  negate: 0\n"
                 "  occupied_thresh: 0.65\n  free_thresh: 0.196\n");
    mapfile_yaml_free(&y);
}

static void test_yaml_errors(void **state)
{
    (void)state;
    /* every required key, missing: the last line */
    static const char *const keys[] = {"image: a.pgm\n", "resolution: 0.05\n",
                                       "origin: [0, 0, 0]\n", "negate: 0\n",
                                       "occupied_thresh: 0.65\n", "free_thresh: 0.196\n"};
    static const char *const names[] = {"image", "resolution", "origin", "negate",
                                        "occupied_thresh", "free_thresh"};
    for (int skip = 0; skip < 6; skip++) {
        char text[256] = "", want[128];
        for (int k = 0; k < 6; k++)
            if (k != skip)
                strcat(text, keys[k]);
        snprintf(want, sizeof want, "m.yaml:5: no %s key (map_server needs it)", names[skip]);
        expect_yaml_error(text, want);
    }
    const char *rest = "origin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
    char text[512];
#define WITH(head) (snprintf(text, sizeof text, "%s%s", head, rest), text)
    expect_yaml_error(WITH("image: a.pgm\nresolution: 0\n"),
                      "m.yaml:2: resolution 0 must be above 0 m");
    expect_yaml_error(WITH("image: a.pgm\nresolution: -0.05\n"),
                      "m.yaml:2: resolution -0.05 must be above 0 m");
    expect_yaml_error(WITH("image: a.pgm\nresolution: 5cm\n"),
                      "m.yaml:2: resolution: '5cm' is not a number");
    expect_yaml_error(WITH("image: a.pgm\nresolution: 0x10\n"),
                      "m.yaml:2: resolution: '0x10' is not a number");
    expect_yaml_error(WITH("image: a.pgm\nresolution: .nan\n"),
                      "m.yaml:2: resolution: '.nan' is not a number");
    expect_yaml_error(WITH("image: a.pgm\nresolution: 1e999\n"),
                      "m.yaml:2: resolution: '1e999' is not a number");
    expect_yaml_error(WITH("image: a.pgm\nresolution: 500\n"),
                      "m.yaml:2: resolution 500 m is outside [0.0001, 100] m");
    expect_yaml_error(WITH("image: a.pgm\nresolution: 1e-5\n"),
                      "m.yaml:2: resolution 1e-5 m is outside [0.0001, 100] m");
    expect_yaml_error(WITH("image: a.pgm\nresolution:\n"), "m.yaml:2: resolution has no value");
    expect_yaml_error(WITH("image: ''\nresolution: 1\n"), "m.yaml:1: image is empty");
    expect_yaml_error(WITH("image: \"a\\0b\"\nresolution: 1\n"),
                      "m.yaml:1: image holds a NUL character");
    expect_yaml_error(WITH("image: a.pgm\nresolution: 1\nresolution: 2\n"),
                      "m.yaml:3: resolution given twice (first on line 2)");
    expect_yaml_error(WITH("image: a.pgm\nresolution: [1]\n"),
                      "m.yaml:2: resolution must be a single value, not a list");
    expect_yaml_error(WITH("image: a.pgm\nresolution: &r 1\n"),
                      "m.yaml:2: resolution: anchors, aliases and tags are not read");
    expect_yaml_error(WITH("image: 'a.pgm\nresolution: 1\n"), "m.yaml:1: unterminated single quote");
    expect_yaml_error(WITH("image: \"a.pgm\" b\nresolution: 1\n"),
                      "m.yaml:1: unexpected 'b' after the image");
    expect_yaml_error(WITH("image: \"\\q\"\nresolution: 1\n"),
                      "m.yaml:1: unknown escape '\\q' in a double-quoted string");
    expect_yaml_error(WITH("image: a.pgm\nresolution 1\n"),
                      "m.yaml:2: expected 'key: value', found 'resolution 1'");
    expect_yaml_error(WITH("image: a.pgm\n resolution: 1\n"),
                      "m.yaml:2: unexpected indented line after image (line 1)");
    expect_yaml_error(WITH("  image: a.pgm\n resolution: 1\n"),
                      "m.yaml:2: indented by 1, the keys above by 2");
    expect_yaml_error(WITH("image: a.pgm\n\tresolution: 1\n"),
                      "m.yaml:2: a tab in the indentation (YAML indents with spaces)");
    expect_yaml_error(WITH("image: a.pgm\nresolution: 1\x01\n"),
                      "m.yaml:2: binary data (byte 0x01 at column 14)");
    expect_yaml_error(WITH("- image: a.pgm\n"),
                      "m.yaml:1: a list where a key was expected: a map YAML is key: value lines");
    expect_yaml_error(WITH("image: a.pgm\nresolution: 1\n---\n"),
                      "m.yaml:3: a second YAML document ('---'): one map a file");
    const char *head = "image: a.pgm\nresolution: 1\n";
    char t2[512];
#define WITH2(tail) (snprintf(t2, sizeof t2, "%s%s", head, tail), t2)
    expect_yaml_error(WITH2("origin: [0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"),
                      "m.yaml:3: origin must have 3 elements [x, y, yaw], not 2");
    expect_yaml_error(WITH2("origin: [0, 0, 0, 0]\nnegate: 0\n"),
                      "m.yaml:3: origin must have 3 elements [x, y, yaw], not 4");
    expect_yaml_error(WITH2("origin: [0, x, 0]\nnegate: 0\n"), "m.yaml:3: origin: 'x' is not a number");
    expect_yaml_error(WITH2("origin: [0, 0, 0\nnegate: 0\n"),
                      "m.yaml:3: origin: the list is not closed with ']'");
    expect_yaml_error(WITH2("origin: [0 0, 0]\n"),
                      "m.yaml:3: origin: '0 0' is not a number");
    expect_yaml_error(WITH2("origin: [0, , 0]\n"), "m.yaml:3: origin: an empty element in the list");
    expect_yaml_error(WITH2("origin: [0, [1], 0]\n"),
                      "m.yaml:3: origin: elements must be numbers, not lists");
    expect_yaml_error(WITH2("origin: [0, 0, 0] x\n"), "m.yaml:3: unexpected 'x' after the list");
    expect_yaml_error(WITH2("origin: 0 0 0\n"),
                      "m.yaml:3: origin must be a list [x, y, yaw], not '0 0 0'");
    expect_yaml_error(WITH2("origin:\n  - 1\n  x: 2\n"), "m.yaml:5: origin: expected '- number', found 'x: 2'");
    expect_yaml_error(WITH2("origin: [2e6, 0, 0]\nnegate: 0\n"),
                      "m.yaml:3: origin x or y beyond +-1e+06 m");
    expect_yaml_error(WITH2("origin: [0, 0, 101]\nnegate: 0\n"),
                      "m.yaml:3: origin yaw beyond +-100 rad");
    const char *h3 = "image: a.pgm\nresolution: 1\norigin: [0, 0, 0]\n";
    char t3[512];
#define WITH3(tail) (snprintf(t3, sizeof t3, "%s%s", h3, tail), t3)
    expect_yaml_error(WITH3("negate: 2\n"), "m.yaml:4: negate must be 0 or 1 (or true, false), not '2'");
    expect_yaml_error(WITH3("negate: 0\noccupied_thresh: 1.5\n"),
                      "m.yaml:5: occupied_thresh 1.5 is outside [0, 1]");
    expect_yaml_error(WITH3("negate: 0\noccupied_thresh: 0.65\nfree_thresh: -0.1\n"),
                      "m.yaml:6: free_thresh -0.1 is outside [0, 1]");
    expect_yaml_error(WITH3("negate: 0\noccupied_thresh: 0.65\nfree_thresh: high\n"),
                      "m.yaml:6: free_thresh: 'high' is not a number");
    expect_yaml_error(WITH3("negate: 0\nfree_thresh: 0.65\noccupied_thresh: 0.65\n"),
                      "m.yaml:6: free_thresh 0.65 must be below occupied_thresh 0.65");
    expect_yaml_error(WITH3("negate: 0\noccupied_thresh: 0.2\nfree_thresh: 0.3\nmode: x\n"),
                      "m.yaml:7: mode must be trinary, scale or raw, not 'x'");
    expect_yaml_error(WITH3("negate: 0\noccupied_thresh: 0.2\nfree_thresh: 0.3\n"),
                      "m.yaml:6: free_thresh 0.3 must be below occupied_thresh 0.2");
    expect_yaml_error("", "m.yaml:1: no image key (map_server needs it)");
    /* the size limit */
    size_t n = MAPFILE_MAX_YAML_BYTES + 1;
    char *big = malloc(n);
    assert_non_null(big);
    memset(big, '#', n);
    mapfile_yaml y;
    assert_int_equal(mapfile_yaml_parse(&y, big, n, "m.yaml"), -1);
    assert_string_equal(y.error, "m.yaml: larger than 1048576 bytes: not a map YAML");
    mapfile_yaml_free(&y);
    free(big);
}

static void test_is_yaml(void **state)
{
    (void)state;
    const char *yes[] = {"image: a.pgm\n", "# map\n\n  resolution: 1\n", "---\nimage: a\n",
                         "\"image\" : x\n", "origin:\n", "free_thresh:\t0.1", "image:"};
    const char *no[] = {"FLASER 180 1 2 3\n", "# polyc-scans 1\nSCAN 0 0 0\n", "",
                        "# only a comment\n", "P5\n384 384\n255\n", "image:x\n",
                        "ROBOTLASER1 0 1: 2\n", "\"unterminated: 1\n"};
    for (size_t i = 0; i < sizeof yes / sizeof yes[0]; i++)
        if (!mapfile_is_yaml(yes[i], strlen(yes[i])))
            fail_msg("not taken for a YAML: '%s'", yes[i]);
    for (size_t i = 0; i < sizeof no / sizeof no[0]; i++)
        if (mapfile_is_yaml(no[i], strlen(no[i])))
            fail_msg("taken for a YAML: '%s'", no[i]);
}

static void test_image_path(void **state)
{
    (void)state;
    static const char *const cases[][3] = {
        {"maps/sub/m.yaml", "a.pgm", "maps/sub/a.pgm"},
        {"m.yaml", "a.pgm", "a.pgm"},
        {"../m.yaml", "img/a.pgm", "../img/a.pgm"},
        {"/abs/m.yaml", "a.pgm", "/abs/a.pgm"},
        {"/m.yaml", "a.pgm", "/a.pgm"},
        {"maps/m.yaml", "/data/a.pgm", "/data/a.pgm"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char *p = mapfile_image_path(cases[i][0], cases[i][1]);
        assert_non_null(p);
        assert_string_equal(p, cases[i][2]);
        free(p);
    }
}

/* ---- PGM ---- */

static int pgm(mapfile_pgm *p, const void *data, size_t len)
{
    return mapfile_pgm_parse(p, data, len, "m.pgm");
}

static void expect_pgm_error(const void *data, size_t len, const char *error)
{
    mapfile_pgm p;
    assert_int_equal(pgm(&p, data, len), -1);
    assert_string_equal(p.error, error);
    mapfile_pgm_free(&p);
}

#define EXPECT_PGM_ERROR(lit, error) expect_pgm_error(lit, sizeof(lit) - 1, error)

static void test_pgm_p5_8bit(void **state)
{
    (void)state;
    static const char data[] = "P5\n# CREATOR: map_saver.cpp 0.050 m/pix\n3 2\n255\n"
                               "\x00\xfe\xcd\x01\x02\xff";
    mapfile_pgm p;
    assert_int_equal(pgm(&p, data, sizeof data - 1), 0);
    assert_int_equal(p.width, 3);
    assert_int_equal(p.height, 2);
    assert_int_equal(p.maxval, 255);
    assert_int_equal(p.plain, 0);
    static const uint16_t want[] = {0, 254, 205, 1, 2, 255};
    for (int i = 0; i < 6; i++)
        assert_int_equal(p.samples[i], want[i]);
    mapfile_pgm_free(&p);
    /* comments between every header field, and a maxval below 255 */
    static const char d2[] = "P5#c\n2#w\n#h\n1 #m\n 7\t\x07\x00";
    assert_int_equal(pgm(&p, d2, sizeof d2 - 1), 0);
    assert_int_equal(p.width, 2);
    assert_int_equal(p.maxval, 7);
    assert_int_equal(p.samples[0], 7);
    assert_int_equal(p.samples[1], 0);
    mapfile_pgm_free(&p);
}

static void test_pgm_p5_16bit(void **state)
{
    (void)state;
    static const char data[] = "P5 2 2 65535\n\x00\x00\xff\xff\x01\x02\xcd\xcd";
    mapfile_pgm p;
    assert_int_equal(pgm(&p, data, sizeof data - 1), 0);
    assert_int_equal(p.maxval, 65535);
    assert_int_equal(p.samples[0], 0);
    assert_int_equal(p.samples[1], 65535);
    assert_int_equal(p.samples[2], 0x0102);   /* big-endian */
    assert_int_equal(p.samples[3], 0xcdcd);
    mapfile_pgm_free(&p);
    static const char d2[] = "P5 1 1 256\n\x01\x00";
    assert_int_equal(pgm(&p, d2, sizeof d2 - 1), 0);
    assert_int_equal(p.samples[0], 256);
    mapfile_pgm_free(&p);
}

static void test_pgm_p2(void **state)
{
    (void)state;
    static const char data[] = "P2\n# plain\n3 2\n1000\n0 1000 500\n  7\n# in the raster\n8 9\n\n";
    mapfile_pgm p;
    assert_int_equal(pgm(&p, data, sizeof data - 1), 0);
    assert_int_equal(p.plain, 1);
    assert_int_equal(p.maxval, 1000);
    static const uint16_t want[] = {0, 1000, 500, 7, 8, 9};
    for (int i = 0; i < 6; i++)
        assert_int_equal(p.samples[i], want[i]);
    mapfile_pgm_free(&p);
}

static void test_pgm_errors(void **state)
{
    (void)state;
    EXPECT_PGM_ERROR("\x89PNG\r\n\x1a\n\0\0\0\rIHDR",
                     "m.pgm: byte 0: a PNG image, not a PGM (mapfile_png_read reads it)");
    EXPECT_PGM_ERROR("P6 1 1 255\n\0\0\0",
                     "m.pgm: byte 0: not a PGM (P5 or P2) or PNG image: it starts with 'P6 1';"
                     " save the map as PGM or PNG");
    EXPECT_PGM_ERROR("", "m.pgm: byte 0: not a PGM (P5 or P2) or PNG image: it starts with '';"
                         " save the map as PGM or PNG");
    EXPECT_PGM_ERROR("P55 1 1 255\n\0",
                     "m.pgm: byte 0: not a PGM (P5 or P2) or PNG image: it starts with 'P55 ';"
                     " save the map as PGM or PNG");
    EXPECT_PGM_ERROR("P5\n3 2\n255\n\0\0\0\0\0",
                     "m.pgm: byte 16: truncated: 5 bytes of pixel data, 3 x 2 at 1 bytes a pixel"
                     " need 6");
    EXPECT_PGM_ERROR("P5\n2 1\n65535\n\0\0\0",
                     "m.pgm: byte 16: truncated: 3 bytes of pixel data, 2 x 1 at 2 bytes a pixel"
                     " need 4");
    EXPECT_PGM_ERROR("P5\n2 1\n255\n\0\0\n", "m.pgm: byte 13: 1 bytes after the pixel data"
                                             " (trailing garbage, or the size does not match)");
    EXPECT_PGM_ERROR("P5\n2 1\n255", "m.pgm: byte 10: the file ends after maxval: no pixel data"
                                     " (truncated)");
    EXPECT_PGM_ERROR("P5\n2 1\n", "m.pgm: byte 7: the file ends before the maxval (truncated)");
    EXPECT_PGM_ERROR("P5\n2 1\n0\n\0\0", "m.pgm: byte 7: maxval is 0 (must be 1..65535)");
    EXPECT_PGM_ERROR("P5\n2 1\n65536\n\0\0\0\0", "m.pgm: byte 7: maxval above 65535");
    EXPECT_PGM_ERROR("P5\n2 1\n99999999999999999999999\n", "m.pgm: byte 7: maxval above 65535");
    EXPECT_PGM_ERROR("P5\n0 1\n255\n", "m.pgm: byte 3: width is 0");
    EXPECT_PGM_ERROR("P5\n1 0\n255\n", "m.pgm: byte 5: height is 0");
    EXPECT_PGM_ERROR("P5\n16385 16384\n255\n",
                     "m.pgm: byte 9: 16385 x 16384 pixels: more than 268435456 cells");
    EXPECT_PGM_ERROR("P5\n268435457 1\n255\n", "m.pgm: byte 3: width above 268435456");
    EXPECT_PGM_ERROR("P5\n4294967297 4294967297\n255\n", "m.pgm: byte 3: width above 268435456");
    EXPECT_PGM_ERROR("P5\nx 1\n255\n", "m.pgm: byte 3: width is not a number: 'x'");
    EXPECT_PGM_ERROR("P5\n2 1x\n255\n", "m.pgm: byte 5: height is not a number: '1x'");
    EXPECT_PGM_ERROR("P5\n2 1\n255#\n\0\0", "m.pgm: byte 10: maxval must be followed by one"
                                            " whitespace byte");
    EXPECT_PGM_ERROR("P5\n2 1\n100\n\x10\x65", "m.pgm: byte 12: pixel value 101 above maxval 100");
    EXPECT_PGM_ERROR("P2\n2 2\n255\n1 2 3\n", "m.pgm: byte 17: truncated: 3 of 4 pixel values"
                                              " (2 x 2)");
    EXPECT_PGM_ERROR("P2\n2 1\n255\n1 2 3\n", "m.pgm: byte 15: more than 2 x 1 pixel values"
                                              " (trailing garbage, or the size does not match)");
    EXPECT_PGM_ERROR("P2\n2 1\n255\n1 256\n", "m.pgm: byte 13: pixel value 256 above maxval 255");
    EXPECT_PGM_ERROR("P2\n2 1\n255\n1 two\n", "m.pgm: byte 13: pixel value is not a number: 'two'");
    EXPECT_PGM_ERROR("P2\n2 1\n255\n1 -2\n", "m.pgm: byte 13: pixel value is not a number: '-2'");
}

/* ---- conversion ---- */

static mapfile_yaml yaml_with(int mode, int negate, double occ, double free_th)
{
    mapfile_yaml y;
    memset(&y, 0, sizeof y);
    y.mode = mode;
    y.negate = negate;
    y.occupied_thresh = occ;
    y.free_thresh = free_th;
    return y;
}

static void test_convert_trinary(void **state)
{
    (void)state;
    mapfile_yaml y = yaml_with(MAPFILE_TRINARY, 0, 0.65, 0.196);
    /* map_saver's three values */
    assert_int_equal(mapfile_cell_value(0, 255, &y), 100);
    assert_int_equal(mapfile_cell_value(254, 255, &y), 0);
    assert_int_equal(mapfile_cell_value(205, 255, &y), -1);
    /* p = (255 - v) / 255 against the thresholds, strictly: 89 gives
     * p = 0.6510 > 0.65, 90 gives 0.6471; 205 gives 0.19608 (not < 0.196),
     * 206 gives 0.19216 */
    assert_int_equal(mapfile_cell_value(89, 255, &y), 100);
    assert_int_equal(mapfile_cell_value(90, 255, &y), -1);
    assert_int_equal(mapfile_cell_value(206, 255, &y), 0);
    /* 16 bits: p = (65535 - v) / 65535 */
    assert_int_equal(mapfile_cell_value(0, 65535, &y), 100);
    assert_int_equal(mapfile_cell_value(65535, 65535, &y), 0);
    assert_int_equal(mapfile_cell_value(205 * 257, 65535, &y), -1);
    /* maxval 1: black and white */
    assert_int_equal(mapfile_cell_value(0, 1, &y), 100);
    assert_int_equal(mapfile_cell_value(1, 1, &y), 0);
    /* negate: p = v / 255 */
    y.negate = 1;
    assert_int_equal(mapfile_cell_value(0, 255, &y), 0);
    assert_int_equal(mapfile_cell_value(255, 255, &y), 100);
    assert_int_equal(mapfile_cell_value(128, 255, &y), -1);
}

static void test_convert_scale_and_raw(void **state)
{
    (void)state;
    mapfile_yaml y = yaml_with(MAPFILE_SCALE, 0, 0.65, 0.25);
    assert_int_equal(mapfile_cell_value(0, 255, &y), 100);
    assert_int_equal(mapfile_cell_value(255, 255, &y), 0);
    /* in between: rint((p - free) / (occ - free) * 100), p = (255 - v) / 255 */
    for (uint32_t v = 90; v <= 191; v++) {
        double p = (255.0 - v) / 255.0;
        int8_t want = (int8_t)(p > 0.65 ? 100.0 : p < 0.25 ? 0.0 : rint((p - 0.25) / 0.4 * 100.0));
        assert_int_equal(mapfile_cell_value(v, 255, &y), want);
    }
    assert_int_equal(mapfile_cell_value(128, 255, &y), 62);    /* p 0.498: 62.0 */
    assert_int_equal(mapfile_cell_value(90, 255, &y), 99);     /* p 0.647: 99.3 */
    assert_int_equal(mapfile_cell_value(191, 255, &y), 0);     /* p 0.251: 0.37 */
    y.negate = 1;
    assert_int_equal(mapfile_cell_value(128, 255, &y), 63);    /* p 0.502: 63.0 */
    /* raw: the value itself, 0..100; other values unknown; negate not applied */
    y = yaml_with(MAPFILE_RAW, 1, 0.65, 0.196);
    assert_int_equal(mapfile_cell_value(0, 255, &y), 0);
    assert_int_equal(mapfile_cell_value(37, 255, &y), 37);
    assert_int_equal(mapfile_cell_value(100, 255, &y), 100);
    assert_int_equal(mapfile_cell_value(101, 255, &y), -1);
    assert_int_equal(mapfile_cell_value(255, 255, &y), -1);
    /* other maxvals are scaled to 0..255 first */
    assert_int_equal(mapfile_cell_value(50 * 257, 65535, &y), 50);
    assert_int_equal(mapfile_cell_value(1, 1, &y), -1);
}

static void test_convert_rows(void **state)
{
    (void)state;
    /* PGM rows are top first, OccupancyGrid rows bottom first */
    static const char data[] = "P2 2 3 255  0 254  205 0  254 254";
    mapfile_pgm p;
    assert_int_equal(pgm(&p, data, sizeof data - 1), 0);
    mapfile_yaml y = yaml_with(MAPFILE_TRINARY, 0, 0.65, 0.196);
    int8_t cells[6];
    mapfile_to_cells(&p, &y, cells);
    static const int8_t want[] = {0, 0, -1, 100, 100, 0};
    for (int i = 0; i < 6; i++)
        assert_int_equal(cells[i], want[i]);
    mapfile_pgm_free(&p);
}

/* ---- what `polyc grid` writes ---- */

static void test_grid_pixel(void **state)
{
    (void)state;
    assert_int_equal(mapfile_grid_pixel(0, 0), 205);
    assert_int_equal(mapfile_grid_pixel(1, 0), 0);
    assert_int_equal(mapfile_grid_pixel(66, 34), 0);         /* 0.66 > 0.65 */
    assert_int_equal(mapfile_grid_pixel(65, 35), 205);       /* 0.65 is not above */
    assert_int_equal(mapfile_grid_pixel(1, 1), 205);
    assert_int_equal(mapfile_grid_pixel(196, 804), 205);     /* 0.196 is not below */
    assert_int_equal(mapfile_grid_pixel(195, 805), 254);
    assert_int_equal(mapfile_grid_pixel(0, 7), 254);
}

static void test_write_and_read_back(void **state)
{
    (void)state;
    static const uint8_t pixels[] = {0, 254, 205, 254, 0, 0};
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    assert_non_null(f);
    assert_int_equal(mapfile_write_pgm(f, pixels, 3, 2, 0.025), 0);
    assert_int_equal(fclose(f), 0);
    static const char head[] = "P5\n# CREATOR: polyc grid 0.025 m/pix\n3 2\n255\n";
    assert_int_equal(len, sizeof head - 1 + 6);
    assert_memory_equal(text, head, sizeof head - 1);
    mapfile_pgm p;
    assert_int_equal(pgm(&p, text, len), 0);
    assert_int_equal(p.width, 3);
    for (int i = 0; i < 6; i++)
        assert_int_equal(p.samples[i], pixels[i]);
    mapfile_pgm_free(&p);
    free(text);

    f = open_memstream(&text, &len);
    assert_non_null(f);
    assert_int_equal(mapfile_write_yaml(f, "office.pgm", 0.025f, -1.2375, 3.5), 0);
    assert_int_equal(fclose(f), 0);
    assert_string_equal(text, "image: office.pgm\nresolution: 0.025000\n"
                              "origin: [-1.237500, 3.500000, 0.000000]\nnegate: 0\n"
                              "occupied_thresh: 0.65\nfree_thresh: 0.196\n\n");
    mapfile_yaml y;
    parse_ok(&y, text);
    assert_string_equal(y.image, "office.pgm");
    assert_true(fabs(y.resolution_m - 0.025) < 1e-9);
    assert_true(y.origin_x_m == -1.2375 && y.origin_y_m == 3.5);
    mapfile_yaml_free(&y);
    free(text);
    /* a name YAML would misread is quoted */
    f = open_memstream(&text, &len);
    assert_non_null(f);
    assert_int_equal(mapfile_write_yaml(f, "my map's #1.pgm", 1.0, 0.0, 0.0), 0);
    assert_int_equal(fclose(f), 0);
    assert_non_null(strstr(text, "image: 'my map''s #1.pgm'\n"));
    parse_ok(&y, text);
    assert_string_equal(y.image, "my map's #1.pgm");
    mapfile_yaml_free(&y);
    free(text);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_yaml_map_saver_layout),
        cmocka_unit_test(test_yaml_each_key),
        cmocka_unit_test(test_yaml_quoting),
        cmocka_unit_test(test_yaml_comments),
        cmocka_unit_test(test_yaml_lists_and_unknown_keys),
        cmocka_unit_test(test_yaml_errors),
        cmocka_unit_test(test_is_yaml),
        cmocka_unit_test(test_image_path),
        cmocka_unit_test(test_pgm_p5_8bit),
        cmocka_unit_test(test_pgm_p5_16bit),
        cmocka_unit_test(test_pgm_p2),
        cmocka_unit_test(test_pgm_errors),
        cmocka_unit_test(test_convert_trinary),
        cmocka_unit_test(test_convert_scale_and_raw),
        cmocka_unit_test(test_convert_rows),
        cmocka_unit_test(test_grid_pixel),
        cmocka_unit_test(test_write_and_read_back),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
