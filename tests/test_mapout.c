/* test_mapout.c - the map writers: exact JSON and TXT for a tiny map, JSON
 * that parses, SVG with y up, a scale bar and distinct colours. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mapout.h"

static const float open_xy[] = {0.0f, 0.0f, 1.0f, 0.0f};
static const float closed_xy[] = {0.0f, 1.0f, 1.0f, 1.0f, 0.5f, 2.0f};

static mapout_map tiny_map(polyc_polyline lines[2])
{
    mapout_map m;
    memset(&m, 0, sizeof m);
    lines[0].xy_m = open_xy;
    lines[0].point_count = 2;
    lines[0].closed = 0;
    lines[1].xy_m = closed_xy;
    lines[1].point_count = 3;
    lines[1].closed = 1;
    m.lines = lines;
    m.line_count = 2;
    return m;
}

/* Runs a writer into memory; the caller frees. */
static char *render(int (*writer)(FILE *, const mapout_map *), const mapout_map *m)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    assert_int_equal(writer(f, m), 0);
    assert_int_equal(fclose(f), 0);
    assert_int_equal(strlen(buf), len);
    return buf;
}

/* ---- a small JSON syntax checker (RFC 8259 grammar, no semantics) ---- */

static const char *json_value(const char *p);

static const char *json_ws(const char *p)
{
    while (*p == ' ' || *p == '\n' || *p == '\r' || *p == '\t')
        p++;
    return p;
}

static const char *json_string(const char *p)
{
    if (*p++ != '"')
        return NULL;
    while (*p && *p != '"') {
        if ((unsigned char)*p < 0x20)
            return NULL;
        p += *p == '\\' ? 2 : 1;
    }
    return *p == '"' ? p + 1 : NULL;
}

static const char *json_number(const char *p)
{
    const char *s = p;
    if (*p == '-')
        p++;
    if (*p == '0')
        p++;
    else if (*p >= '1' && *p <= '9')
        while (*p >= '0' && *p <= '9')
            p++;
    else
        return NULL;
    if (*p == '.') {
        if (*++p < '0' || *p > '9')
            return NULL;
        while (*p >= '0' && *p <= '9')
            p++;
    }
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-')
            p++;
        if (*p < '0' || *p > '9')
            return NULL;
        while (*p >= '0' && *p <= '9')
            p++;
    }
    return p > s ? p : NULL;
}

static const char *json_list(const char *p, char close, int object)
{
    p = json_ws(p + 1);
    if (*p == close)
        return p + 1;
    for (;;) {
        if (object) {
            if (!(p = json_string(json_ws(p))))
                return NULL;
            p = json_ws(p);
            if (*p++ != ':')
                return NULL;
        }
        if (!(p = json_value(p)))
            return NULL;
        p = json_ws(p);
        if (*p == close)
            return p + 1;
        if (*p++ != ',')
            return NULL;
    }
}

static const char *json_value(const char *p)
{
    p = json_ws(p);
    if (*p == '{')
        return json_list(p, '}', 1);
    if (*p == '[')
        return json_list(p, ']', 0);
    if (*p == '"')
        return json_string(p);
    if (strncmp(p, "true", 4) == 0 || strncmp(p, "null", 4) == 0)
        return p + 4;
    if (strncmp(p, "false", 5) == 0)
        return p + 5;
    return json_number(p);
}

static int json_valid(const char *text)
{
    const char *end = json_value(text);
    return end && *json_ws(end) == '\0';
}

/* ---- tests ---- */

static void test_json_exact(void **state)
{
    (void)state;
    polyc_polyline lines[2];
    mapout_map m = tiny_map(lines);
    char *out = render(mapout_json, &m);
    assert_string_equal(out,
                        "{\"polylines\": [\n"
                        "{\"closed\": false, \"points\": [[0.0000, 0.0000], [1.0000, 0.0000]]},\n"
                        "{\"closed\": true, \"points\": [[0.0000, 1.0000], [1.0000, 1.0000],"
                        " [0.5000, 2.0000]]}\n"
                        "], \"stats\": {}}\n");
    assert_true(json_valid(out));
    free(out);
    m.line_count = 0;
    out = render(mapout_json, &m);
    assert_string_equal(out, "{\"polylines\": [], \"stats\": {}}\n");
    assert_true(json_valid(out));
    free(out);
}

static void test_json_stats(void **state)
{
    (void)state;
    polyc_polyline lines[2];
    mapout_map m = tiny_map(lines);
    polyc_stats s;
    mapout_times t = {1.5, 2, 3, 4, 5, 6};
    memset(&s, 0, sizeof s);
    s.scans = 3;
    s.beams = 5000000000ull;
    s.bic = (double)NAN;                        /* JSON has no NaN: null */
    s.error_sq_m2 = 0.25;
    m.stats = &s;
    m.times = &t;
    char *out = render(mapout_json, &m);
    assert_true(json_valid(out));
    assert_non_null(strstr(out, "\"scans\": 3, \"beams\": 5000000000, "));
    assert_non_null(strstr(out, "\"bic\": null, \"error_sq_m2\": 0.250000"));
    assert_non_null(strstr(out, "\"time_parse_ms\": 1.500000"));
    assert_non_null(strstr(out, "\"time_optimize_ms\": 6.000000}}\n"));
    free(out);
    /* the checker itself rejects broken JSON */
    assert_false(json_valid("{\"a\": [1, 2,]}"));
    assert_false(json_valid("{\"a\": nan}"));
}

static void test_txt_exact(void **state)
{
    (void)state;
    polyc_polyline lines[2];
    mapout_map m = tiny_map(lines);
    char *out = render(mapout_txt, &m);
    assert_string_equal(out, "open 2 0.0000 0.0000 1.0000 0.0000\n"
                             "closed 3 0.0000 1.0000 1.0000 1.0000 0.5000 2.0000\n");
    free(out);
}

/* Numbers of the first path whose d starts with 'M' after `after`. */
static void first_path_points(const char *svg, const char *after, double *x0, double *y0,
                              double *x1, double *y1)
{
    const char *p = strstr(svg, after);
    assert_non_null(p);
    p = strstr(p, "d=\"M");
    assert_non_null(p);
    assert_int_equal(sscanf(p, "d=\"M%lf %lf L%lf %lf", x0, y0, x1, y1), 4);
}

static void test_svg(void **state)
{
    (void)state;
    polyc_polyline lines[2];
    mapout_map m = tiny_map(lines);
    char *out = render(mapout_svg, &m);
    assert_true(strncmp(out, "<?xml", 5) == 0);
    assert_non_null(strstr(out, "<svg xmlns=\"http://www.w3.org/2000/svg\""));
    assert_non_null(strstr(out, "</svg>\n"));
    /* scale bar: the map is 1 m wide, so a 0.2 m bar */
    assert_non_null(strstr(out, "id=\"scalebar\""));
    assert_non_null(strstr(out, ">0.2 m</text>"));
    /* x grows to the right; y up: the closed polyline (y 1 -> 1) lies above
     * the open one (y 0), so its pixel y is smaller */
    double x0, y0, x1, y1, cx0, cy0, cx1, cy1;
    first_path_points(out, "<g id=\"polylines\"", &x0, &y0, &x1, &y1);
    assert_true(x1 > x0);
    assert_true(fabs(y1 - y0) < 1e-9);
    /* one colour for the map: the closed polyline is the second path */
    assert_null(strstr(out, "<path stroke=\"#2471a3\""));
    assert_null(strstr(out, "<path stroke=\"#c0392b\""));
    const char *second = strstr(strstr(out, "<g id=\"polylines\""), "<path stroke=\"#17407a\"");
    assert_non_null(second);
    first_path_points(second + 1, "<path stroke=\"#17407a\"", &cx0, &cy0, &cx1, &cy1);
    assert_true(cy0 < y0);
    assert_non_null(strstr(out, " Z\"/>"));             /* closed: Z */
    assert_null(strstr(out, " 0 1 0 "));              /* no vertex dots unless asked */
    /* a title block, axes in metres, the origin (in view), a legend of the
     * polylines only; no time unless given */
    assert_non_null(strstr(out, "<g id=\"title\""));
    assert_non_null(strstr(out, ">polyc map</text>"));
    assert_non_null(strstr(out, ">2 polylines, 5 vertices</text>"));
    assert_null(strstr(out, "id=\"time\""));
    assert_non_null(strstr(out, "<g id=\"axes\""));
    assert_non_null(strstr(out, " m</text>"));
    assert_non_null(strstr(out, "<g id=\"origin\""));
    assert_non_null(strstr(out, ">polylines</text>"));
    assert_null(strstr(out, ">vertices</text>"));
    free(out);
    m.color_lines = 1;                                /* a colour per polyline */
    m.title = "some/dir/a<b>&\033.log";
    m.cell_m = 0.05;
    m.total_ms = 1234.0;
    out = render(mapout_svg, &m);
    assert_non_null(strstr(out, "<path stroke=\"#2471a3\""));
    assert_non_null(strstr(out, ">a?b???.log</text>"));  /* the file name, XML-safe */
    assert_non_null(strstr(out, ">2 polylines, 5 vertices, cells of 0.05 m</text>"));
    assert_non_null(strstr(out, ">made in 1.23 s</text>"));
    free(out);
    m.color_lines = 0;
    m.vertices = 1;
    out = render(mapout_svg, &m);
    assert_non_null(strstr(out, " 0 1 0 "));
    assert_non_null(strstr(out, ">vertices</text>"));
    free(out);
}

static void test_svg_points_and_empty(void **state)
{
    (void)state;
    const float ranges[4] = {1.0f, 2.0f, 100.0f, NAN};   /* two hits */
    polyc_scan scan;
    memset(&scan, 0, sizeof scan);
    scan.angle_step_rad = 0.5f;
    scan.min_range_m = 0.02f;
    scan.max_range_m = 50.0f;
    scan.beam_count = 4;
    scan.range_m = ranges;
    mapout_map m;
    memset(&m, 0, sizeof m);
    m.scans = &scan;
    m.scan_count = 1;
    char *out = render(mapout_svg, &m);
    const char *p = strstr(out, "<path id=\"points\"");
    assert_non_null(p);
    int squares = 0;
    for (const char *q = p; (q = strstr(q, "h1v1h-1z")) != NULL; q++)
        squares++;
    assert_int_equal(squares, 2);
    assert_non_null(strstr(out, ">scan endpoints</text>"));
    free(out);
    m.scans = NULL;                                      /* nothing at all */
    out = render(mapout_svg, &m);
    assert_non_null(strstr(out, "id=\"scalebar\""));
    free(out);
}

/* The grid layer from a real context: one scan of a wall at x = 2 m. */
static void test_svg_grid(void **state)
{
    (void)state;
    float ranges[181];
    for (int i = 0; i < 181; i++) {
        double a = -1.5707963267948966 + i * 0.017453292519943295;
        ranges[i] = cos(a) > 0.3 ? (float)(2.0 / cos(a)) : 10.0f;
    }
    polyc_scan scan;
    memset(&scan, 0, sizeof scan);
    scan.start_angle_rad = -1.5707963f;
    scan.angle_step_rad = 0.017453292f;
    scan.min_range_m = 0.02f;
    scan.max_range_m = 10.0f;
    scan.beam_count = 181;
    scan.range_m = ranges;
    polyc_config cfg;
    polyc_limits lim;
    polyc_ctx *ctx = NULL;
    polyc_config_default(&cfg);
    assert_int_equal(polyc_limits_for_scans(&cfg, &scan, 1, &lim), POLYC_OK);
    size_t size = polyc_memory_size(&cfg, &lim);
    assert_true(size > 0);
    void *block = malloc(size);
    assert_non_null(block);
    assert_int_equal(polyc_init(block, size, &cfg, &lim, &ctx), POLYC_OK);
    assert_int_equal(polyc_add_scan(ctx, &scan), POLYC_OK);
    assert_int_equal(polyc_extract_contour(ctx), POLYC_OK);
    mapout_map m;
    memset(&m, 0, sizeof m);
    m.grid = ctx;
    m.contour_threshold = cfg.contour_threshold;
    char *out = render(mapout_svg, &m);
    double width = 0;
    assert_int_equal(sscanf(strstr(out, "<svg"), "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%lf\"",
                            &width), 1);
    const char *layers[2] = {"<path id=\"grid\"", "<path id=\"contour\""};
    for (int k = 0; k < 2; k++) {
        const char *p = strstr(out, layers[k]);
        assert_non_null(p);
        p = strstr(p, " d=\"") + 4;
        int squares = 0;
        while (*p == 'M') {                 /* M x y h w v h h -w z */
            double x, y, w, h, w2;
            int used = 0;
            assert_int_equal(sscanf(p, "M%lf %lfh%lfv%lfh%lfz%n", &x, &y, &w, &h, &w2, &used), 5);
            assert_true(x >= 0 && x <= width && w > 0 && w <= width && h > 0 && w2 == -w);
            p += used;
            squares++;
        }
        assert_int_equal(*p, '"');
        assert_true(squares > 10);          /* the wall is 2 x 2 tan(72.5 deg) m long */
    }
    assert_non_null(strstr(out, ">occupied grid cells</text>"));
    assert_non_null(strstr(out, ">contour cells</text>"));
    /* the canvas follows the cells drawn (the wall at x = 2 m), not the
     * whole grid: the view (a tenth of the wall's length wide) is near x = 2 m */
    double x0, x1, y0, y1;
    assert_int_equal(sscanf(strstr(out, "<!-- polyc map: "), "<!-- polyc map: x %lf..%lf m, y %lf..%lf m",
                            &x0, &x1, &y0, &y1), 4);
    assert_true(x0 > 1.0 && x1 < 3.0);                 /* the grid starts at the pose, x = 0 */
    free(out);
    free(block);
}

/* The robot's path: its poses joined, the last one a circle; a fixed view
 * box is what the SVG shows (its comment on line 3), whatever is drawn. */
static void test_svg_path_and_view(void **state)
{
    (void)state;
    polyc_polyline lines[2];
    mapout_map m = tiny_map(lines);
    polyc_scan poses[3];
    memset(poses, 0, sizeof poses);
    for (int i = 0; i < 3; i++)
        poses[i].pose_x_m = 0.5 * i;
    m.path = poses;
    m.path_count = 3;
    char *out = render(mapout_svg, &m);
    const char *p = strstr(out, "<g id=\"path\"");
    assert_non_null(p);
    assert_non_null(strstr(p, " L"));
    assert_non_null(strstr(p, "<circle"));
    assert_non_null(strstr(out, "the robot's path and pose"));
    free(out);
    polyc_box view = {-10.0, -5.0, 10.0, 5.0};
    m.path = NULL;
    m.view_m = &view;
    out = render(mapout_svg, &m);
    assert_null(strstr(out, "<g id=\"path\""));
    double x0, x1, y0, y1;
    p = strstr(out, "<!-- polyc map: x ");
    assert_non_null(p);
    assert_int_equal(sscanf(p, "<!-- polyc map: x %lf..%lf m, y %lf..%lf m", &x0, &x1, &y0, &y1), 4);
    assert_true(x0 < -10.0 && x0 > -10.5 && x1 > 10.0 && x1 < 10.5);   /* 2 % of air */
    assert_true(y0 < -5.0 && y0 > -5.5 && y1 > 5.0 && y1 < 5.5);
    free(out);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_json_exact),
        cmocka_unit_test(test_json_stats),
        cmocka_unit_test(test_txt_exact),
        cmocka_unit_test(test_svg),
        cmocka_unit_test(test_svg_points_and_empty),
        cmocka_unit_test(test_svg_grid),
        cmocka_unit_test(test_svg_path_and_view),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
