/* test_written_topology.c - the map as written has no crossing and no
 * touch: simulated scenes of several kinds (halls of pillars, shelves,
 * thin walls, offices, flats), mapped in batch and online, written as TXT
 * and JSON by the tool's writers (tools/mapout.c, four decimals), read back,
 * and every pair of segments that share no vertex tested exactly on the
 * printed values: no proper crossing, and no vertex on the other segment;
 * the circles (polyc_find_curves, written as circles) meet no segment and
 * no other circle, and the arcs (written as bulges; read back as polylines
 * within 0.05 mm of them) cross and touch nothing either. (Ends at T-junctions stop 1 mm short of the segment they
 * meet, corners clear it by as much: topology.c, polyc__op_end_gaps; a
 * circle keeps 1 cm off every other segment: circles.c.) */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "curves.h"
#include "mapout.h"
#include "polyc.h"
#include "scansim.h"

/* kinds and seeds: flat's seed 6 had an end 0.4 mm through a wall in the
 * batch map, written to four decimals (before the ends kept their gap) */
static const struct {
    const char *kind;
    uint32_t seeds;
} SCENES[] = {{"flat", 6},  {"office", 3},   {"thinwalls", 3}, {"shelves", 2}, {"hall", 2},
              {"pillars", 2}, {"roundmix", 2}, {"arcwalls", 2}};

typedef struct seg {
    double ax, ay, bx, by;
} seg;

typedef struct ring {
    double cx, cy, r;
} ring;

#define MAX_RINGS 256
static ring rings[MAX_RINGS];
static uint32_t ring_n;

/* The segments of a written map read back from the numbers as printed:
 * TXT lines `open|closed N x y ...`, or JSON arrays `[x, y]` within each
 * polyline's "points". */
static uint32_t read_back(FILE *f, int json, seg *out, uint32_t cap)
{
    rewind(f);
    uint32_t n = 0;
    ring_n = 0;
    char line[1 << 16];
    double xy[2 * 4096];
    static double bulge[4096];
    uint32_t nb = 0;
    while (fgets(line, sizeof line, f)) {
        uint32_t k = 0;
        int closed = 0;
        const char *p = line;
        ring g;
        if (!json && sscanf(line, "circle %lf %lf %lf", &g.cx, &g.cy, &g.r) == 3) {
            assert_true(ring_n < MAX_RINGS);
            rings[ring_n++] = g;
            continue;
        }
        if (json && sscanf(line, "{\"center\": [%lf, %lf], \"radius\": %lf}", &g.cx, &g.cy, &g.r) == 3) {
            assert_true(ring_n < MAX_RINGS);
            rings[ring_n++] = g;
            continue;
        }
        if (!json) {
            if (strncmp(line, "open ", 5) != 0 && strncmp(line, "closed ", 7) != 0)
                continue;
            closed = line[0] == 'c';
            p = strchr(line, ' ') + 1;
            strtoul(p, (char **)&p, 10);
            char *end;
            for (double v = strtod(p, &end); end != p && k < 2 * 4096; v = strtod(p, &end)) {
                xy[k++] = v;
                p = end;
            }
            const char *bl = strstr(p, " bulges");
            nb = 0;
            for (p = bl ? bl + 7 : p; bl && nb < 4096; p = end) {
                double v = strtod(p, &end);
                if (end == p)
                    break;
                bulge[nb++] = v;
            }
        } else {
            const char *pts = strstr(line, "\"points\"");
            if (!pts)
                continue;
            closed = strstr(line, "\"closed\": true") != NULL;
            const char *bl = strstr(line, "\"bulges\"");
            for (p = strchr(pts, '['); p && (p = strchr(p + 1, '[')) != NULL && k + 1 < 2 * 4096 &&
                                      (!bl || p < bl);) {
                char *end;
                xy[k++] = strtod(p + 1, &end);
                xy[k++] = strtod(strchr(end, ',') + 1, &end);
                p = end;
            }
            nb = 0;
            for (p = bl ? strchr(bl, '[') + 1 : NULL; p && nb < 4096;) {
                char *end;
                double v = strtod(p, &end);
                if (end == p)
                    break;
                bulge[nb++] = v;
                p = strchr(end, ',');
                p = p ? p + 1 : NULL;
            }
        }
        uint32_t m = k / 2;
        for (uint32_t i = 0; i + 1 < m + (closed ? 1u : 0u) && n < cap; i++) {
            uint32_t j = (i + 1) % m;
            if (i >= nb || bulge[i] == 0.0) {
                out[n++] = (seg){xy[2 * i], xy[2 * i + 1], xy[2 * j], xy[2 * j + 1]};
                continue;
            }
            /* an arc: pieces within 0.05 mm of it, its ends as printed */
            float a[2] = {(float)xy[2 * i], (float)xy[2 * i + 1]}, b[2] = {(float)xy[2 * j], (float)xy[2 * j + 1]};
            double cx, cy, r, a0, sweep;
            curves_arc(a, b, bulge[i], &cx, &cy, &r, &a0, &sweep);
            uint32_t pieces = (uint32_t)ceil(fabs(sweep) / (2.0 * acos(1.0 - 0.00005 / r)));
            pieces = pieces < 1u ? 1u : (pieces > 4096u ? 4096u : pieces);
            double px = xy[2 * i], py = xy[2 * i + 1];
            for (uint32_t q = 1; q <= pieces && n < cap; q++) {
                double ang = a0 + sweep * (double)q / (double)pieces;
                double qx = q == pieces ? xy[2 * j] : cx + r * cos(ang);
                double qy = q == pieces ? xy[2 * j + 1] : cy + r * sin(ang);
                out[n++] = (seg){px, py, qx, qy};
                px = qx;
                py = qy;
            }
        }
    }
    return n;
}

static double orient(double ax, double ay, double bx, double by, double cx, double cy)
{
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

static int within(double a, double b, double c)
{
    return (a <= c && c <= b) || (b <= c && c <= a);
}

/* c on segment a-b (exactly, as printed) */
static int on_seg(double ax, double ay, double bx, double by, double cx, double cy)
{
    return orient(ax, ay, bx, by, cx, cy) == 0.0 && within(ax, bx, cx) && within(ay, by, cy);
}

static int shares_vertex(const seg *s, const seg *t)
{
    return (s->ax == t->ax && s->ay == t->ay) || (s->ax == t->bx && s->ay == t->by) ||
           (s->bx == t->ax && s->by == t->ay) || (s->bx == t->bx && s->by == t->by);
}

/* Pairs of segments that share no vertex and cross or touch. */
static uint32_t strict_faults(const seg *s, uint32_t n, const char *what)
{
    uint32_t bad = 0;
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t j = i + 1; j < n; j++) {
            const seg *a = &s[i], *b = &s[j];
            if (fmax(a->ax, a->bx) < fmin(b->ax, b->bx) || fmax(b->ax, b->bx) < fmin(a->ax, a->bx) ||
                fmax(a->ay, a->by) < fmin(b->ay, b->by) || fmax(b->ay, b->by) < fmin(a->ay, a->by) ||
                shares_vertex(a, b))
                continue;
            double o1 = orient(a->ax, a->ay, a->bx, a->by, b->ax, b->ay);
            double o2 = orient(a->ax, a->ay, a->bx, a->by, b->bx, b->by);
            double o3 = orient(b->ax, b->ay, b->bx, b->by, a->ax, a->ay);
            double o4 = orient(b->ax, b->ay, b->bx, b->by, a->bx, a->by);
            int cross = o1 * o2 < 0.0 && o3 * o4 < 0.0;
            int touch = on_seg(a->ax, a->ay, a->bx, a->by, b->ax, b->ay) ||
                        on_seg(a->ax, a->ay, a->bx, a->by, b->bx, b->by) ||
                        on_seg(b->ax, b->ay, b->bx, b->by, a->ax, a->ay) ||
                        on_seg(b->ax, b->ay, b->bx, b->by, a->bx, a->by);
            if (cross || touch) {
                if (bad++ < 3)
                    print_error("%s: [%.4f, %.4f]-[%.4f, %.4f] %s [%.4f, %.4f]-[%.4f, %.4f]\n", what,
                                a->ax, a->ay, a->bx, a->by, cross ? "crosses" : "touches", b->ax,
                                b->ay, b->bx, b->by);
            }
        }
    return bad;
}

/* Circles read back that meet a segment (the ring's distance to it, the
 * segment's nearest and farthest points round the centre, brackets the
 * radius) or another circle. */
static uint32_t ring_faults(const seg *s, uint32_t n, const char *what)
{
    uint32_t bad = 0;
    for (uint32_t k = 0; k < ring_n; k++) {
        const ring *g = &rings[k];
        for (uint32_t i = 0; i < n; i++) {
            const seg *a = &s[i];
            double ex = a->bx - a->ax, ey = a->by - a->ay, l2 = ex * ex + ey * ey;
            double t = l2 > 0.0 ? ((g->cx - a->ax) * ex + (g->cy - a->ay) * ey) / l2 : 0.0;
            t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
            double near = hypot(a->ax + t * ex - g->cx, a->ay + t * ey - g->cy);
            double far = fmax(hypot(a->ax - g->cx, a->ay - g->cy), hypot(a->bx - g->cx, a->by - g->cy));
            if (near <= g->r && far >= g->r && bad++ < 3)
                print_error("%s: circle (%.4f, %.4f) r %.4f meets [%.4f, %.4f]-[%.4f, %.4f]\n", what,
                            g->cx, g->cy, g->r, a->ax, a->ay, a->bx, a->by);
        }
        for (uint32_t j = k + 1; j < ring_n; j++) {
            const ring *h = &rings[j];
            double d = hypot(g->cx - h->cx, g->cy - h->cy);
            if (d <= g->r + h->r && d >= fabs(g->r - h->r) && bad++ < 3)
                print_error("%s: circles (%.4f, %.4f) and (%.4f, %.4f) meet\n", what, g->cx, g->cy,
                            h->cx, h->cy);
        }
    }
    return bad;
}

/* The scene's map, batch or online, written both ways and checked. */
static uint32_t check_scene(const char *kind, uint64_t seed, int online, uint32_t *segments,
                            uint32_t *circles, uint32_t *arcs)
{
    scansim_scene sc;
    assert_int_equal(scansim_scene_builtin(&sc, kind, seed), 0);
    assert_int_equal(scansim_run(&sc), 0);
    polyc_config c;
    polyc_config_default(&c);
    void *block = NULL;
    polyc_ctx *ctx = NULL;
    if (!online) {
        polyc_limits lim;
        assert_int_equal(polyc_limits_for_scans(&c, sc.scans, sc.scan_count, &lim), POLYC_OK);
        lim.max_vertices = lim.max_points = 0; /* (the worst case: no retry) */
        size_t size = polyc_memory_size(&c, &lim);
        block = malloc(size);
        assert_non_null(block);
        assert_int_equal(polyc_init(block, size, &c, &lim, &ctx), POLYC_OK);
        for (uint32_t i = 0; i < sc.scan_count; i++)
            assert_int_equal(polyc_add_scan(ctx, &sc.scans[i]), POLYC_OK);
        assert_int_equal(polyc_build(ctx, NULL, NULL), POLYC_OK);
    } else {
        polyc_box box = {1.0, 1.0, 0.0, 0.0};
        for (uint32_t i = 0; i < sc.scan_count; i++)
            polyc_scan_extent(&c, &sc.scans[i], &box);
        double x0 = sc.scans[0].pose_x_m, y0 = sc.scans[0].pose_y_m;
        double reach = fmax(fmax(x0 - box.min_x_m, box.max_x_m - x0), fmax(y0 - box.min_y_m, box.max_y_m - y0));
        polyc_online_limits lim;
        assert_int_equal(polyc_online_limits_for_area(&c, 2.0 * reach + 6.0, sc.laser.beam_count, &lim),
                         POLYC_OK);
        lim.max_points *= 4;
        lim.max_grid_cells *= 4;
        lim.max_vertices *= 4;
        size_t size = polyc_online_memory_size(&c, &lim);
        block = malloc(size);
        assert_non_null(block);
        assert_int_equal(polyc_online_init(block, size, &c, &lim, &ctx), POLYC_OK);
        for (uint32_t i = 0; i < sc.scan_count; i++) {
            assert_int_equal(polyc_online_add_scan(ctx, &sc.scans[i], 0, NULL), POLYC_OK);
            assert_int_equal(polyc_online_update(ctx, POLYC_ONLINE_WORK_DEFAULT, NULL), POLYC_OK);
        }
        assert_int_equal(polyc_online_finish(ctx, NULL, NULL, NULL), POLYC_OK);
    }
    uint32_t n = polyc_polyline_count(ctx);
    curves_map cm;
    assert_int_equal(curves_from_ctx(ctx, 0, &cm), POLYC_OK);
    const float **bul = calloc(n ? n : 1u, sizeof *bul);
    assert_non_null(bul);
    for (uint32_t i = 0; i < n; i++)
        bul[i] = curves_bulges(&cm, i);
    *arcs += cm.arcs;
    mapout_map m;
    memset(&m, 0, sizeof m);
    m.lines = cm.lines;
    m.line_count = n;
    m.circles = cm.circ;
    m.bulges = bul;
    uint32_t bad = 0, cap = 200000;
    seg *s = malloc(cap * sizeof *s);
    assert_non_null(s);
    char what[96];
    for (int json = 0; json < 2; json++) {
        FILE *f = tmpfile();
        assert_non_null(f);
        assert_int_equal(json ? mapout_json(f, &m) : mapout_txt(f, &m), 0);
        uint32_t ns = read_back(f, json, s, cap);
        fclose(f);
        snprintf(what, sizeof what, "%s seed %u %s %s", kind, (unsigned)seed,
                 online ? "online" : "batch", json ? "JSON" : "TXT");
        bad += strict_faults(s, ns, what) + ring_faults(s, ns, what);
        *segments += ns;
        *circles += ring_n;
    }
    free(s);
    free(bul);
    curves_free(&cm);
    free(block);
    scansim_scene_free(&sc);
    return bad;
}

static void test_no_crossing_no_touch_as_written(void **state)
{
    (void)state;
    uint32_t bad = 0, segments = 0, circles = 0, arcs = 0, maps = 0;
    for (size_t k = 0; k < sizeof SCENES / sizeof SCENES[0]; k++)
        for (uint64_t seed = 1; seed <= SCENES[k].seeds; seed++)
            for (int online = 0; online < 2; online++) {
                bad += check_scene(SCENES[k].kind, seed, online, &segments, &circles, &arcs);
                maps++;
            }
    print_message("%u maps with %u arcs written as TXT and JSON, %u segments and %u circles read "
                  "back: %u crossings or touches\n", maps, arcs, segments, circles, bad);
    assert_int_equal(bad, 0);
    assert_true(circles > 0 && arcs > 0); /* (the round kinds have some) */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_no_crossing_no_touch_as_written),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
