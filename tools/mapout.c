/* mapout.c - the map out of the library, into a file.
 * Takes: polylines (and optionally stats, scans, the grid).
 * Gives: JSON, SVG (y up; title, axes, scale bar, legend, optional layers)
 * or TXT on a FILE. */
#include "mapout.h"

#include "curves.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Polyline i is written as a circle. */
static const polyc_circle *circle_at(const mapout_map *map, uint32_t i)
{
    return map->circles && map->circles[i].radius_m > 0.0f && map->circles[i].same_as == i
               ? &map->circles[i]
               : NULL;
}

/* Polyline i is written not at all: a piece of a circle given at its first
 * piece, or a polyline of no points. */
static int skipped(const mapout_map *map, uint32_t i)
{
    if (map->circles && map->circles[i].radius_m > 0.0f)
        return map->circles[i].same_as != i;
    return map->lines[i].point_count == 0;
}

/* The bulges of polyline i (NULL: straight segments only), and how many
 * it has: one a segment. */
static const float *bulges_at(const mapout_map *map, uint32_t i, uint32_t *n)
{
    const polyc_polyline *pl = &map->lines[i];
    *n = pl->closed ? pl->point_count : (pl->point_count ? pl->point_count - 1 : 0);
    return map->bulges ? map->bulges[i] : NULL;
}

/* ---- TXT ---- */

int mapout_txt(FILE *f, const mapout_map *map)
{
    for (uint32_t i = 0; i < map->line_count; i++) {
        const polyc_polyline *pl = &map->lines[i];
        const polyc_circle *c = circle_at(map, i);
        if (skipped(map, i))
            continue;
        if (c) {
            fprintf(f, "circle %.4f %.4f %.4f\n", (double)c->center_x_m, (double)c->center_y_m,
                    (double)c->radius_m);
            continue;
        }
        fprintf(f, "%s %u", pl->closed ? "closed" : "open", (unsigned)pl->point_count);
        for (uint32_t j = 0; j < pl->point_count; j++)
            fprintf(f, " %.4f %.4f", (double)pl->xy_m[2 * j], (double)pl->xy_m[2 * j + 1]);
        uint32_t nb;
        const float *b = bulges_at(map, i, &nb);
        if (b) {
            fputs(" bulges", f);
            for (uint32_t j = 0; j < nb; j++)
                fprintf(f, " %.6f", (double)b[j]);
        }
        fputc('\n', f);
    }
    return ferror(f) ? -1 : 0;
}

/* ---- JSON ---- */

static void json_u64(FILE *f, const char *key, uint64_t v, int *first)
{
    fprintf(f, "%s\"%s\": %llu", *first ? "" : ", ", key, (unsigned long long)v);
    *first = 0;
}

static void json_double(FILE *f, const char *key, double v, int *first)
{
    if (isfinite(v))
        fprintf(f, "%s\"%s\": %.6f", *first ? "" : ", ", key, v);
    else   /* JSON has no NaN or infinity */
        fprintf(f, "%s\"%s\": null", *first ? "" : ", ", key);
    *first = 0;
}

static void json_stats(FILE *f, const polyc_stats *s, const mapout_times *t)
{
    int first = 1;
    fputs("{", f);
    if (s) {
        json_u64(f, "scans", s->scans, &first);
        json_u64(f, "beams", s->beams, &first);
        json_u64(f, "beams_skipped", s->beams_skipped, &first);
        json_u64(f, "hits", s->hits, &first);
        json_u64(f, "data_points", s->data_points, &first);
        json_u64(f, "weighted_points", s->weighted_points, &first);
        json_u64(f, "grid_width", s->grid_width, &first);
        json_u64(f, "grid_height", s->grid_height, &first);
        json_u64(f, "grid_tiles", s->grid_tiles, &first);
        json_u64(f, "grid_bytes", s->grid_bytes, &first);
        json_u64(f, "contour_cells", s->contour_cells, &first);
        json_u64(f, "initial_polylines", s->initial_polylines, &first);
        json_u64(f, "initial_vertices", s->initial_vertices, &first);
        json_u64(f, "polylines", s->polylines, &first);
        json_u64(f, "vertices", s->vertices, &first);
        json_u64(f, "iterations", s->iterations, &first);
        json_double(f, "bic", s->bic, &first);
        json_double(f, "error_sq_m2", s->error_sq_m2, &first);
        json_u64(f, "memory_size_bytes", s->memory_size_bytes, &first);
        json_u64(f, "memory_used_bytes", s->memory_used_bytes, &first);
    }
    if (t) {
        json_double(f, "time_parse_ms", t->parse_ms, &first);
        json_double(f, "time_add_ms", t->add_ms, &first);
        json_double(f, "time_grid_ms", t->grid_ms, &first);
        json_double(f, "time_contour_ms", t->contour_ms, &first);
        json_double(f, "time_trace_ms", t->trace_ms, &first);
        json_double(f, "time_optimize_ms", t->optimize_ms, &first);
    }
    fputs("}", f);
}

int mapout_json(FILE *f, const mapout_map *map)
{
    uint32_t written = 0, circles = 0;
    fputs("{\"polylines\": [", f);
    for (uint32_t i = 0; i < map->line_count; i++) {
        const polyc_polyline *pl = &map->lines[i];
        if (circle_at(map, i))
            circles++;
        if (circle_at(map, i) || skipped(map, i))
            continue;
        fprintf(f, "%s\n{\"closed\": %s, \"points\": [", written++ ? "," : "",
                pl->closed ? "true" : "false");
        for (uint32_t j = 0; j < pl->point_count; j++)
            fprintf(f, "%s[%.4f, %.4f]", j ? ", " : "", (double)pl->xy_m[2 * j],
                    (double)pl->xy_m[2 * j + 1]);
        uint32_t nb;
        const float *b = bulges_at(map, i, &nb);
        if (b) {
            fputs("], \"bulges\": [", f);
            for (uint32_t j = 0; j < nb; j++)
                fprintf(f, "%s%.6f", j ? ", " : "", (double)b[j]);
        }
        fputs("]}", f);
    }
    fputs(written ? "\n]" : "]", f);
    if (circles) {             /* (only when there are: a map of lines is written as before) */
        uint32_t k = 0;
        fputs(", \"circles\": [", f);
        for (uint32_t i = 0; i < map->line_count; i++) {
            const polyc_circle *c = circle_at(map, i);
            if (c)
                fprintf(f, "%s\n{\"center\": [%.4f, %.4f], \"radius\": %.4f}", k++ ? "," : "",
                        (double)c->center_x_m, (double)c->center_y_m, (double)c->radius_m);
        }
        fputs("\n]", f);
    }
    fputs(", \"stats\": ", f);
    json_stats(f, map->stats, map->times);
    fputs("}\n", f);
    return ferror(f) ? -1 : 0;
}

/* ---- SVG ---- */

#define SVG_MARGIN_PX 24.0
#define SVG_PX_PER_M 40.0              /* preferred scale, clamped by: */
#define SVG_MIN_SIDE_PX 600.0
#define SVG_MAX_SIDE_PX 4000.0
#define SVG_CHAR_EM 0.6                /* a sans-serif character's width, in font sizes */
#define SVG_LINE_COLOUR "#17407a"      /* the map, unless --color-lines: dark blue */
#define SVG_INK "#404040"              /* text, axes, the origin */
#define SVG_PATH_COLOUR "#c0392b"      /* the robot's path and pose: red */
#define SVG_FONT "font-family=\"sans-serif\" fill=\"" SVG_INK "\""

/* --color-lines: distinct colours, cycled over the polylines. */
static const char *const palette[] = {"#c0392b", "#2471a3", "#229954", "#d68910", "#7d3c98",
                                      "#17a589", "#a04000", "#e74c8c", "#2e4053", "#b7950b"};
#define PALETTE_SIZE (sizeof palette / sizeof palette[0])
static const char *const grid_fill[2] = {"#bcd0ea", "#f0a04b"};   /* occupied, contour */

typedef struct view {
    double x0, y0, x1, y1;             /* metres shown */
    double scale;                      /* px per metre */
    double left, top;                  /* px: the map area's top left corner */
    double width, height;              /* px: the whole picture */
    double stroke;                     /* line width, px */
    double font, small;                /* title and label sizes, px */
    double tick_m;                     /* axis ticks, metres apart */
    double footer;                     /* px: y of the scale bar */
    char title[96], subtitle[96];
    int legend_rows;
} view;

static double px_x(const view *v, double x) { return v->left + (x - v->x0) * v->scale; }
/* SVG's y grows downwards; maps have y up. */
static double px_y(const view *v, double y) { return v->top + (v->y1 - y) * v->scale; }

static void box_add(view *v, double x, double y)
{
    if (!isfinite(x) || !isfinite(y))
        return;
    v->x0 = fmin(v->x0, x);
    v->y0 = fmin(v->y0, y);
    v->x1 = fmax(v->x1, x);
    v->y1 = fmax(v->y1, y);
}

/* Endpoint of beam j of scan s, if it is a hit (the library's rule). */
static int endpoint(const polyc_scan *s, uint32_t j, double *x, double *y)
{
    float r = s->range_m[j];
    if (!isfinite(r) || r < s->min_range_m || r >= s->max_range_m)
        return 0;
    double a = s->pose_theta_rad + (double)s->start_angle_rad + j * (double)s->angle_step_rad;
    *x = s->pose_x_m + (double)r * cos(a);
    *y = s->pose_y_m + (double)r * sin(a);
    return 1;
}

/* The --grid layer's cell (ix, iy): bit 0 occupied, bit 1 contour. */
static unsigned grid_bits(const mapout_map *map, uint32_t ix, uint32_t iy)
{
    uint32_t hits, misses, contour;
    if (polyc_grid_cell(map->grid, ix, iy, &hits, &misses, &contour) != POLYC_OK)
        return 0;
    unsigned b = 0;
    if (hits && (double)hits > (double)map->contour_threshold * ((double)hits + misses))
        b |= 1;
    if (contour)
        b |= 2;
    return b;
}

/* A round length of at most `target` metres: 1, 2 or 5 times a power of 10. */
static double nice_length(double target)
{
    double p = pow(10, floor(log10(target)));
    if (5 * p <= target)
        return 5 * p;
    if (2 * p <= target)
        return 2 * p;
    return p;
}

/* An axis label: t rounded to the tick spacing. */
static int tick_label(char *buf, size_t n, double t, double step)
{
    double r = round(t / step) * step;
    return snprintf(buf, n, "%g", fabs(r) < step * 1e-6 ? 0.0 : r);
}

/* name's last path component, at most n - 1 bytes, safe as XML text:
 * markup characters and bytes outside printable ASCII become '?'. */
static void xml_name(char *out, size_t n, const char *name)
{
    const char *slash = name ? strrchr(name, '/') : NULL;
    const char *s = slash ? slash + 1 : name ? name : "";
    size_t o = 0;
    for (; *s && o + 1 < n; s++) {
        unsigned char c = (unsigned char)*s;
        out[o++] = c < 0x20 || c >= 0x7f || c == '<' || c == '>' || c == '&' ? '?' : (char)c;
    }
    out[o] = '\0';
}

static void make_view(const mapout_map *map, view *v)
{
    v->x0 = v->y0 = HUGE_VAL;
    v->x1 = v->y1 = -HUGE_VAL;
    uint64_t vertices = 0;
    uint32_t circles = 0, arcs = 0, drawn = 0;
    for (uint32_t i = 0; i < map->line_count; i++) {
        const polyc_circle *c = circle_at(map, i);
        if (skipped(map, i))
            continue;
        if (c) {
            circles++;
            box_add(v, (double)c->center_x_m - (double)c->radius_m, (double)c->center_y_m - (double)c->radius_m);
            box_add(v, (double)c->center_x_m + (double)c->radius_m, (double)c->center_y_m + (double)c->radius_m);
            continue;
        }
        drawn++;
        vertices += map->lines[i].point_count;
        for (uint32_t j = 0; j < map->lines[i].point_count; j++)
            box_add(v, (double)map->lines[i].xy_m[2 * j], (double)map->lines[i].xy_m[2 * j + 1]);
        uint32_t nb;
        const float *b = bulges_at(map, i, &nb);
        for (uint32_t j = 0; b && j < nb; j++)
            if (b[j] != 0.0f) { /* the arc's middle */
                arcs++;
                double cx, cy, r, a0, sweep;
                const float *p = &map->lines[i].xy_m[2 * j];
                curves_arc(p, &map->lines[i].xy_m[2 * ((j + 1) % map->lines[i].point_count)],
                           (double)b[j], &cx, &cy, &r, &a0, &sweep);
                box_add(v, cx + r * cos(a0 + 0.5 * sweep), cy + r * sin(a0 + 0.5 * sweep));
            }
    }
    for (uint32_t i = 0; map->scans && i < map->scan_count; i++) {
        double x, y;
        for (uint32_t j = 0; j < map->scans[i].beam_count; j++)
            if (endpoint(&map->scans[i], j, &x, &y))
                box_add(v, x, y);
    }
    double gx, gy;
    float cell_m;
    uint32_t gw, gh;
    if (map->grid && polyc_grid_info(map->grid, &gx, &gy, &cell_m, &gw, &gh) == POLYC_OK) {
        double c = (double)cell_m;     /* the cells drawn, not the whole grid */
        for (uint32_t iy = 0; iy < gh; iy++)
            for (uint32_t ix = 0; ix < gw; ix++)
                if (grid_bits(map, ix, iy)) {
                    box_add(v, gx + ix * c, gy + iy * c);
                    box_add(v, gx + (ix + 1) * c, gy + (iy + 1) * c);
                }
    }
    for (uint32_t i = 0; map->path && i < map->path_count; i++)
        box_add(v, map->path[i].pose_x_m, map->path[i].pose_y_m);
    if (map->view_m) {
        v->x0 = map->view_m->min_x_m;
        v->y0 = map->view_m->min_y_m;
        v->x1 = map->view_m->max_x_m;
        v->y1 = map->view_m->max_y_m;
    }
    if (!(v->x0 <= v->x1)) {           /* nothing to show */
        v->x0 = v->y0 = -0.5;
        v->x1 = v->y1 = 0.5;
    }
    /* No side thinner than a tenth of the other (a single straight wall). */
    double side = fmax(fmax(v->x1 - v->x0, v->y1 - v->y0), 1e-3);
    /* and 2 % of air inside the frame */
    double padx = fmax(0, side / 10 - (v->x1 - v->x0)) / 2 + side / 50;
    double pady = fmax(0, side / 10 - (v->y1 - v->y0)) / 2 + side / 50;
    v->x0 -= padx;
    v->x1 += padx;
    v->y0 -= pady;
    v->y1 += pady;
    double long_px = fmin(fmax(side * SVG_PX_PER_M, SVG_MIN_SIDE_PX), SVG_MAX_SIDE_PX);
    v->scale = long_px / side;
    /* Big pictures are mostly viewed shrunk to a screen: thicker lines. */
    v->stroke = fmin(fmax(long_px / 800, 1.5), 3.0);
    v->font = fmin(fmax(long_px / 60, 14), 48);
    v->small = 0.75 * v->font;
    v->tick_m = nice_length(side / 4);

    /* the title block: the source, the map's size, its cells */
    char name[64];
    xml_name(name, sizeof name, map->title);
    snprintf(v->title, sizeof v->title, "%s", *name ? name : "polyc map");
    int n = snprintf(v->subtitle, sizeof v->subtitle, "%u polylines, %llu vertices",
                     (unsigned)drawn, (unsigned long long)vertices);
    if (circles && n > 0 && (size_t)n < sizeof v->subtitle)
        n += snprintf(v->subtitle + n, sizeof v->subtitle - (size_t)n, ", %u circles",
                      (unsigned)circles);
    if (arcs && n > 0 && (size_t)n < sizeof v->subtitle)
        n += snprintf(v->subtitle + n, sizeof v->subtitle - (size_t)n, ", %u arcs", (unsigned)arcs);
    if (map->cell_m > 0 && n > 0 && (size_t)n < sizeof v->subtitle)
        n += snprintf(v->subtitle + n, sizeof v->subtitle - (size_t)n, ", cells of %g m",
                      map->cell_m);
    if (map->stats && map->stats->iterations == 0 && n > 0 && (size_t)n < sizeof v->subtitle)
        snprintf(v->subtitle + n, sizeof v->subtitle - (size_t)n, ", not optimised");
    v->legend_rows = 1 + (map->vertices != 0) + (map->scans != NULL) + 2 * (map->grid != NULL) +
                     (map->path && map->path_count);

    /* room for the y axis' labels on the left */
    size_t widest = 1;
    char label[32];
    for (double t = ceil(v->y0 / v->tick_m) * v->tick_m; t <= v->y1; t += v->tick_m) {
        int k = tick_label(label, sizeof label, t, v->tick_m);
        widest = k > 0 && (size_t)k > widest ? (size_t)k : widest;
    }
    v->left = SVG_MARGIN_PX + (double)widest * SVG_CHAR_EM * v->small + 10;
    v->top = SVG_MARGIN_PX + 1.2 * v->font + 1.6 * v->small + 10;
    double map_w = (v->x1 - v->x0) * v->scale, map_h = (v->y1 - v->y0) * v->scale;
    double title_w = SVG_CHAR_EM * fmax(v->font * (double)strlen(v->title),
                                        v->small * ((double)strlen(v->subtitle) + 14));
    v->width = ceil(fmax(v->left + map_w, SVG_MARGIN_PX + title_w) + SVG_MARGIN_PX);
    v->footer = v->top + map_h + 1.6 * v->small + 10 + v->font + 6;
    v->height = ceil(v->footer + v->legend_rows * 1.6 * v->small + 10 + SVG_MARGIN_PX);
}

/* Endpoints as 1 px grey squares, at most one per pixel (file size stays
 * bounded by the picture, not by the number of beams). */
static void svg_points(FILE *f, const mapout_map *map, const view *v)
{
    size_t w = (size_t)v->width, h = (size_t)v->height;
    unsigned char *seen = calloc((w * h + 7) / 8, 1);
    if (!seen)
        return;
    fputs("<path id=\"points\" fill=\"#707070\" fill-opacity=\"0.6\" d=\"", f);
    for (uint32_t i = 0; i < map->scan_count; i++) {
        double x, y;
        for (uint32_t j = 0; j < map->scans[i].beam_count; j++) {
            if (!endpoint(&map->scans[i], j, &x, &y))
                continue;
            double fx = floor(px_x(v, x)), fy = floor(px_y(v, y));
            if (fx < 0 || fy < 0 || fx >= v->width || fy >= v->height)
                continue;
            size_t k = (size_t)fy * w + (size_t)fx;
            if (seen[k / 8] & (1u << (k % 8)))
                continue;
            seen[k / 8] = (unsigned char)(seen[k / 8] | (1u << (k % 8)));
            fprintf(f, "M%.0f %.0fh1v1h-1z", fx, fy);
        }
    }
    fputs("\"/>\n", f);
    free(seen);
}

/* Grid cells with m > threshold (light blue) and contour cells (orange),
 * merged into blocks of at least one pixel and into runs along each row. */
static void svg_grid(FILE *f, const mapout_map *map, const view *v)
{
    double gx, gy;
    float cell_m;
    uint32_t gw, gh;
    if (polyc_grid_info(map->grid, &gx, &gy, &cell_m, &gw, &gh) != POLYC_OK || !gw || !gh)
        return;
    uint32_t k = (uint32_t)ceil(1.0 / ((double)cell_m * v->scale));
    if (k < 1)
        k = 1;
    uint32_t bw = (gw + k - 1) / k, bh = (gh + k - 1) / k;
    unsigned char *block = calloc((size_t)bw * bh, 1);   /* bit 0: occupied, 1: contour */
    if (!block)
        return;
    for (uint32_t iy = 0; iy < gh; iy++)
        for (uint32_t ix = 0; ix < gw; ix++) {
            unsigned char *b = &block[(size_t)(iy / k) * bw + ix / k];
            *b = (unsigned char)(*b | grid_bits(map, ix, iy));
        }
    const char *id[2] = {"grid", "contour"};
    double bm = k * (double)cell_m;    /* block size in metres */
    for (int layer = 0; layer < 2; layer++) {
        fprintf(f, "<path id=\"%s\" fill=\"%s\" d=\"", id[layer], grid_fill[layer]);
        for (uint32_t by = 0; by < bh; by++)
            for (uint32_t bx = 0; bx < bw;) {
                if (!(block[(size_t)by * bw + bx] & (1u << layer))) {
                    bx++;
                    continue;
                }
                uint32_t run = bx;
                while (run < bw && (block[(size_t)by * bw + run] & (1u << layer)))
                    run++;
                double x = px_x(v, gx + bx * bm), y = px_y(v, gy + (by + 1) * bm);
                double w = (double)(run - bx) * bm * v->scale;
                fprintf(f, "M%.2f %.2fh%.2fv%.2fh%.2fz", x, y, w, bm * v->scale, -w);
                bx = run;
            }
        fputs("\"/>\n", f);
    }
    free(block);
}

/* The title block: the source's name, polylines, vertices, cell size, and
 * the run's time (its own element, id "time": the one part that changes
 * from run to run). */
static void svg_title(FILE *f, const mapout_map *map, const view *v)
{
    double y1 = SVG_MARGIN_PX + v->font, y2 = y1 + 1.6 * v->small;
    fprintf(f, "<g id=\"title\" " SVG_FONT ">\n"
               "<text x=\"%.2f\" y=\"%.2f\" font-size=\"%.1f\" font-weight=\"bold\">%s</text>\n"
               "<text x=\"%.2f\" y=\"%.2f\" font-size=\"%.1f\">%s</text>\n",
            SVG_MARGIN_PX, y1, v->font, v->title, SVG_MARGIN_PX, y2, v->small, v->subtitle);
    if (map->total_ms > 0)
        fprintf(f, "<text id=\"time\" x=\"%.2f\" y=\"%.2f\" font-size=\"%.1f\""
                   " text-anchor=\"end\">made in %.2f s</text>\n",
                v->width - SVG_MARGIN_PX, y2, v->small, map->total_ms / 1e3);
    fputs("</g>\n", f);
}

/* A frame round the map with ticks and labels in metres, and the origin. */
static void svg_axes(FILE *f, const view *v)
{
    double l = px_x(v, v->x0), r = px_x(v, v->x1), t = px_y(v, v->y1), b = px_y(v, v->y0);
    char label[32];
    fprintf(f, "<g id=\"axes\" " SVG_FONT " font-size=\"%.1f\">\n"
               "<path fill=\"none\" stroke=\"#b0b0b0\" stroke-width=\"1\""
               " d=\"M%.2f %.2fH%.2fV%.2fH%.2fZ",
            v->small, l, t, r, b, l);
    for (double x = ceil(v->x0 / v->tick_m) * v->tick_m; x <= v->x1; x += v->tick_m)
        fprintf(f, "M%.2f %.2fv5", px_x(v, x), b);
    for (double y = ceil(v->y0 / v->tick_m) * v->tick_m; y <= v->y1; y += v->tick_m)
        fprintf(f, "M%.2f %.2fh-5", l, px_y(v, y));
    fputs("\"/>\n", f);
    double last = -HUGE_VAL;
    for (double x = ceil(v->x0 / v->tick_m) * v->tick_m; x <= v->x1; x += v->tick_m)
        last = x;
    for (double x = ceil(v->x0 / v->tick_m) * v->tick_m; x <= v->x1; x += v->tick_m) {
        tick_label(label, sizeof label, x, v->tick_m);
        fprintf(f, "<text x=\"%.2f\" y=\"%.2f\" text-anchor=\"middle\">%s%s</text>\n",
                px_x(v, x), b + 7 + v->small, label, x == last ? " m" : "");
    }
    for (double y = ceil(v->y0 / v->tick_m) * v->tick_m; y <= v->y1; y += v->tick_m) {
        tick_label(label, sizeof label, y, v->tick_m);
        fprintf(f, "<text x=\"%.2f\" y=\"%.2f\" text-anchor=\"end\">%s</text>\n", l - 8,
                px_y(v, y) + 0.35 * v->small, label);
    }
    fputs("</g>\n", f);
    if (0 >= v->x0 && 0 <= v->x1 && 0 >= v->y0 && 0 <= v->y1) {
        double ox = px_x(v, 0), oy = px_y(v, 0), a = 2.5 * v->font / 3;
        fprintf(f, "<g id=\"origin\" stroke=\"" SVG_INK "\" stroke-width=\"1.5\" fill=\"none\">"
                   "<path d=\"M%.2f %.2fh%.2fM%.2f %.2fv%.2f\"/>"
                   "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%.2f\"/></g>\n",
                ox - a / 2, oy, a, ox, oy - a / 2, a, ox, oy, a / 4);
    }
}

/* The robot's path (its poses joined) and its last pose: a circle with a
 * stroke along its heading. */
static void svg_path(FILE *f, const mapout_map *map, const view *v)
{
    fprintf(f, "<g id=\"path\" fill=\"none\" stroke=\"" SVG_PATH_COLOUR "\" stroke-width=\"%.2f\""
               " stroke-linejoin=\"round\">\n<path stroke-opacity=\"0.6\" d=\"",
            v->stroke / 2);
    for (uint32_t i = 0; i < map->path_count; i++)
        fprintf(f, "%s%.2f %.2f", i ? " L" : "M", px_x(v, map->path[i].pose_x_m),
                px_y(v, map->path[i].pose_y_m));
    const polyc_scan *s = &map->path[map->path_count - 1];
    double x = px_x(v, s->pose_x_m), y = px_y(v, s->pose_y_m), r = 3 * v->stroke;
    fprintf(f, "\"/>\n<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%.2f\" stroke-width=\"%.2f\"/>"
               "<path stroke-width=\"%.2f\" d=\"M%.2f %.2fl%.2f %.2f\"/>\n</g>\n",
            x, y, r, v->stroke, v->stroke, x, y, 2 * r * cos(s->pose_theta_rad),
            -2 * r * sin(s->pose_theta_rad));
}

static void svg_scalebar(FILE *f, const view *v)
{
    double len_m = nice_length((v->x1 - v->x0) / 4);
    double x0 = v->left, x1 = x0 + len_m * v->scale;
    double y = v->footer;
    fprintf(f,
            "<g id=\"scalebar\"><path d=\"M%.2f %.2fv-6M%.2f %.2fH%.2fv-6\" stroke=\"black\""
            " stroke-width=\"%.2f\" fill=\"none\"/>\n"
            "<text x=\"%.2f\" y=\"%.2f\" font-family=\"sans-serif\" font-size=\"%.0f\">%g m</text>"
            "</g>\n",
            x0, y, x0, y, x1, v->stroke + 0.5, x1 + 8, y, v->font, len_m);
}

/* One row of the legend for each layer drawn, under the scale bar. */
static void svg_legend(FILE *f, const mapout_map *map, const view *v)
{
    double x = v->left, y = v->footer + 10, row = 1.6 * v->small, sw = 2 * v->small;
    double tx = x + sw + 8;
    fprintf(f, "<g id=\"legend\" " SVG_FONT " font-size=\"%.1f\">\n", v->small);
    y += row;
    double mid = y - 0.35 * v->small;
    if (map->color_lines)
        for (int k = 0; k < 3; k++)
            fprintf(f, "<path stroke=\"%s\" stroke-width=\"%.2f\" d=\"M%.2f %.2fh%.2f\"/>\n",
                    palette[k], v->stroke, x + k * sw / 3, mid, sw / 3);
    else
        fprintf(f, "<path stroke=\"" SVG_LINE_COLOUR "\" stroke-width=\"%.2f\""
                   " d=\"M%.2f %.2fh%.2f\"/>\n",
                v->stroke, x, mid, sw);
    fprintf(f, "<text x=\"%.2f\" y=\"%.2f\">polylines%s</text>\n", tx, y,
            map->color_lines ? " (a colour each)" : "");
    if (map->vertices) {
        y += row;
        fprintf(f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%.2f\" fill=\"%s\"/>\n"
                   "<text x=\"%.2f\" y=\"%.2f\">vertices</text>\n",
                x + sw / 2, y - 0.35 * v->small, 1.4 * v->stroke,
                map->color_lines ? palette[0] : SVG_LINE_COLOUR, tx, y);
    }
    if (map->scans) {
        y += row;
        fprintf(f, "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" fill=\"#707070\""
                   " fill-opacity=\"0.6\"/>\n<text x=\"%.2f\" y=\"%.2f\">scan endpoints</text>\n",
                x + sw / 2 - 2, y - 0.35 * v->small - 2, 4.0, 4.0, tx, y);
    }
    if (map->path && map->path_count) {
        y += row;
        fprintf(f, "<path stroke=\"" SVG_PATH_COLOUR "\" stroke-width=\"%.2f\" d=\"M%.2f %.2fh%.2f\"/>\n"
                   "<text x=\"%.2f\" y=\"%.2f\">the robot's path and pose</text>\n",
                v->stroke / 2, x, y - 0.35 * v->small, sw, tx, y);
    }
    if (map->grid) {
        static const char *const what[2] = {"occupied grid cells", "contour cells"};
        for (int k = 0; k < 2; k++) {
            y += row;
            fprintf(f, "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" fill=\"%s\"/>\n"
                       "<text x=\"%.2f\" y=\"%.2f\">%s</text>\n",
                    x, y - 0.8 * v->small, sw, 0.8 * v->small, grid_fill[k], tx, y, what[k]);
        }
    }
    fputs("</g>\n", f);
}

int mapout_svg(FILE *f, const mapout_map *map)
{
    view v;
    make_view(map, &v);
    fprintf(f,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\""
            " viewBox=\"0 0 %.0f %.0f\">\n"
            "<!-- polyc map: x %.4f..%.4f m, y %.4f..%.4f m (y up), %.4f px/m,"
            " x %.4f m at px %.2f, y %.4f m at px %.2f -->\n"
            "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
            v.width, v.height, v.width, v.height, v.x0, v.x1, v.y0, v.y1, v.scale, v.x0, v.left,
            v.y1, v.top);
    svg_title(f, map, &v);
    if (map->grid)
        svg_grid(f, map, &v);
    if (map->scans)
        svg_points(f, map, &v);
    svg_axes(f, &v);
    fprintf(f, "<g id=\"polylines\" fill=\"none\" stroke-width=\"%.2f\" stroke-linejoin=\"round\""
               " stroke-linecap=\"round\">\n",
            v.stroke);
    for (uint32_t i = 0; i < map->line_count; i++) {
        const polyc_polyline *pl = &map->lines[i];
        const char *colour = map->color_lines ? palette[i % PALETTE_SIZE] : SVG_LINE_COLOUR;
        const polyc_circle *c = circle_at(map, i);
        if (skipped(map, i))
            continue;
        if (c) {
            fprintf(f, "<circle stroke=\"%s\" cx=\"%.2f\" cy=\"%.2f\" r=\"%.2f\"/>\n", colour,
                    px_x(&v, (double)c->center_x_m), px_y(&v, (double)c->center_y_m),
                    (double)c->radius_m * v.scale);
            continue;
        }
        if (pl->point_count == 0)
            continue;
        fprintf(f, "<path stroke=\"%s\" d=\"", colour);
        uint32_t nb;
        const float *b = bulges_at(map, i, &nb);
        fprintf(f, "M%.2f %.2f", px_x(&v, (double)pl->xy_m[0]), px_y(&v, (double)pl->xy_m[1]));
        for (uint32_t j = 0; j < nb; j++) {
            uint32_t k = (j + 1) % pl->point_count;
            double x = px_x(&v, (double)pl->xy_m[2 * k]), y = px_y(&v, (double)pl->xy_m[2 * k + 1]);
            if (b && b[j] != 0.0f) {
                /* y is flipped: a counter-clockwise arc on the map (its
                 * angle growing, y up) is SVG's negative sweep (y down) */
                double cx, cy, r, a0, sweep;
                curves_arc(&pl->xy_m[2 * j], &pl->xy_m[2 * k], (double)b[j], &cx, &cy, &r, &a0, &sweep);
                fprintf(f, " A%.2f %.2f 0 %d %d %.2f %.2f", r * v.scale, r * v.scale,
                        fabs(sweep) > 3.14159265358979 ? 1 : 0, b[j] > 0.0f ? 0 : 1, x, y);
            } else if (j + 1 < pl->point_count || !pl->closed) {
                fprintf(f, " L%.2f %.2f", x, y);
            }
        }
        fputs(pl->closed ? " Z\"/>\n" : "\"/>\n", f);
        if (map->vertices) {
            fprintf(f, "<path stroke=\"none\" fill=\"%s\" d=\"", colour);
            double r = 1.4 * v.stroke;                       /* dot radius, px */
            for (uint32_t j = 0; j < pl->point_count; j++)
                fprintf(f, "M%.2f %.2fm%.2f 0a%.2f %.2f 0 1 0 %.2f 0a%.2f %.2f 0 1 0 %.2f 0",
                        px_x(&v, (double)pl->xy_m[2 * j]), px_y(&v, (double)pl->xy_m[2 * j + 1]),
                        -r, r, r, 2 * r, r, r, -2 * r);
            fputs("\"/>\n", f);
        }
    }
    fputs("</g>\n", f);
    if (map->path && map->path_count)
        svg_path(f, map, &v);
    svg_scalebar(f, &v);
    svg_legend(f, map, &v);
    fputs("</svg>\n", f);
    return ferror(f) ? -1 : 0;
}
