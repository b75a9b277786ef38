/* gtscore.c - ground-truth reader and map scores (definitions in gtscore.h).
 *
 * Takes a .gt.txt file and a map of polylines or single scans; gives the
 * figures of docs/evaluation.md, "Scores": precision, completeness, compactness,
 * ray RMSE and f.
 */
#include "gtscore.h"
#include "grow.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#define TRUTH_CELL_M 0.25  /* grid of the true walls (few, long segments) */
#define MAP_CELL_M 0.10    /* grid of a learned map for 5 cm queries */

/* ---- reader --------------------------------------------------------------- */

static int fail(char *err, size_t err_size, const char *name, uint64_t line, const char *fmt,
                ...)
{
    va_list ap;
    int n;
    if (!err || err_size == 0)
        return -1;
    n = snprintf(err, err_size, "%s:%llu: ", name, (unsigned long long)line);
    if (n >= 0 && (size_t)n < err_size) {
        va_start(ap, fmt);
        vsnprintf(err + n, err_size - (size_t)n, fmt, ap);
        va_end(ap);
    }
    return -1;
}

/* Next whitespace-separated token of *p, NUL-terminated in place; NULL at
 * the end of the line. */
static char *next_token(char **p)
{
    char *s = *p, *start;
    while (*s && isspace((unsigned char)*s))
        s++;
    if (!*s)
        return NULL;
    start = s;
    while (*s && !isspace((unsigned char)*s))
        s++;
    if (*s)
        *s++ = '\0';
    *p = s;
    return start;
}

/* A finite number, the whole token. */
static int parse_number(const char *token, double *out)
{
    char *end;
    errno = 0;
    *out = strtod(token, &end);
    return end != token && *end == '\0' && errno == 0 && isfinite(*out);
}

void gtscore_truth_free(gtscore_truth *truth)
{
    if (!truth)
        return;
    free(truth->wall_xy_m);
    free(truth->walls);
    free(truth->seen_xy_m);
    gtscore_index_free(&truth->index);
    memset(truth, 0, sizeof *truth);
}

static int read_wall(gtscore_truth *truth, char *rest, const char *name, uint64_t line,
                     char *err, size_t err_size)
{
    char *token = next_token(&rest);
    uint32_t first = truth->wall_point_count, numbers = 0;
    gtscore_wall *wall;
    int closed;
    if (!token || (strcmp(token, "closed") != 0 && strcmp(token, "open") != 0))
        return fail(err, err_size, name, line, "wall: expected 'closed' or 'open'");
    closed = token[0] == 'c';
    while ((token = next_token(&rest)) != NULL) {
        double v;
        if (!parse_number(token, &v))
            return fail(err, err_size, name, line, "wall: bad number '%.40s'", token);
        if (numbers % 2u == 0 &&
            grow_array((void **)&truth->wall_xy_m, &truth->wall_point_cap,
                       truth->wall_point_count + 1u, 2u * sizeof(double)) != 0)
            return fail(err, err_size, name, line, "out of memory");
        truth->wall_xy_m[2u * first + numbers] = v;
        numbers++;
        if (numbers % 2u == 0)
            truth->wall_point_count++;
    }
    if (numbers % 2u != 0)
        return fail(err, err_size, name, line, "wall: odd number of coordinates");
    if (numbers / 2u < (closed ? 3u : 2u))
        return fail(err, err_size, name, line, "wall: %s wall needs at least %u points",
                    closed ? "a closed" : "an open", closed ? 3u : 2u);
    if (grow_array((void **)&truth->walls, &truth->wall_cap, truth->wall_count + 1u,
                   sizeof(gtscore_wall)) != 0)
        return fail(err, err_size, name, line, "out of memory");
    wall = &truth->walls[truth->wall_count++];
    wall->first_point = first;
    wall->point_count = numbers / 2u;
    wall->closed = closed ? 1u : 0u;
    return 0;
}

static int read_line(gtscore_truth *truth, char *text, const char *name, uint64_t line,
                     char *err, size_t err_size)
{
    char *rest = text, *key = next_token(&rest), *token;
    double v[2];
    if (!key || key[0] == '#')
        return 0;
    if (strcmp(key, "wall") == 0)
        return read_wall(truth, rest, name, line, err, err_size);
    if (strcmp(key, "seen") == 0) {
        char *a = next_token(&rest), *b = next_token(&rest);
        if (!a || !b || next_token(&rest) || !parse_number(a, &v[0]) || !parse_number(b, &v[1]))
            return fail(err, err_size, name, line, "seen: expected two numbers x y");
        if (grow_array((void **)&truth->seen_xy_m, &truth->seen_cap, truth->seen_count + 1u,
                       2u * sizeof(double)) != 0)
            return fail(err, err_size, name, line, "out of memory");
        truth->seen_xy_m[2u * truth->seen_count] = v[0];
        truth->seen_xy_m[2u * truth->seen_count + 1u] = v[1];
        truth->seen_count++;
        return 0;
    }
    if (strcmp(key, "ideal") == 0) {
        token = next_token(&rest);
        if (!token || next_token(&rest) || !parse_number(token, &v[0]) || v[0] < 0.0 ||
            v[0] > (double)UINT32_MAX || v[0] != floor(v[0]))
            return fail(err, err_size, name, line, "ideal: expected one whole number");
        if (truth->has_ideal)
            return fail(err, err_size, name, line, "ideal: given twice");
        truth->ideal = (uint32_t)v[0];
        truth->has_ideal = 1;
        return 0;
    }
    if (strcmp(key, "ideal_params") == 0) {
        uint32_t n[3], k;
        for (k = 0; k < 3u; k++) {
            token = next_token(&rest);
            if (!token || !parse_number(token, &v[0]) || v[0] < 0.0 ||
                v[0] > (double)UINT32_MAX || v[0] != floor(v[0]))
                return fail(err, err_size, name, line,
                            "ideal_params: expected three whole numbers P A C");
            n[k] = (uint32_t)v[0];
        }
        if (next_token(&rest))
            return fail(err, err_size, name, line, "ideal_params: expected three whole numbers P A C");
        if (truth->has_ideal_params)
            return fail(err, err_size, name, line, "ideal_params: given twice");
        truth->ideal_params = n[0];
        truth->ideal_arcs = n[1];
        truth->ideal_circles = n[2];
        truth->has_ideal_params = 1;
        return 0;
    }
    return fail(err, err_size, name, line, "unknown line type '%.40s'", key);
}

int gtscore_truth_read(gtscore_truth *truth, FILE *f, const char *name, char *err,
                       size_t err_size)
{
    char *text = NULL;
    size_t cap = 0;
    ssize_t len;
    uint64_t line = 0;
    uint32_t w;
    int rc = 0;

    memset(truth, 0, sizeof *truth);
    if (err && err_size)
        err[0] = '\0';
    if (!name)
        name = "<truth>";
    while (rc == 0 && (len = getline(&text, &cap, f)) >= 0) {
        line++;
        if ((size_t)len != strlen(text))
            rc = fail(err, err_size, name, line, "NUL byte in line");
        else
            rc = read_line(truth, text, name, line, err, err_size);
    }
    free(text);
    if (rc != 0)
        return -1;
    if (ferror(f))
        return fail(err, err_size, name, line, "read error");
    if (truth->wall_count == 0)
        return fail(err, err_size, name, line, "no walls");
    gtscore_index_init(&truth->index);
    for (w = 0; w < truth->wall_count; w++) {
        const gtscore_wall *wall = &truth->walls[w];
        if (gtscore_index_add_d(&truth->index, &truth->wall_xy_m[2u * wall->first_point],
                                wall->point_count, wall->closed != 0) != 0)
            return fail(err, err_size, name, line, "out of memory");
    }
    if (gtscore_index_build(&truth->index, TRUTH_CELL_M) != 0)
        return fail(err, err_size, name, line, "out of memory");
    return 0;
}

int gtscore_truth_load(gtscore_truth *truth, const char *path, char *err, size_t err_size)
{
    FILE *f = fopen(path, "r");
    int rc;
    if (!f) {
        memset(truth, 0, sizeof *truth);
        if (err && err_size)
            snprintf(err, err_size, "%s: %s", path, strerror(errno));
        return -1;
    }
    rc = gtscore_truth_read(truth, f, path, err, err_size);
    fclose(f);
    return rc;
}

/* ---- map scores ----------------------------------------------------------- */

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Appends the 1 cm samples' distances to the truth for segment a->b,
 * without b (the next segment or the open end adds it). */
static int sample_segment(const gtscore_truth *truth, const float *a, const float *b,
                          double **dist, size_t *count, size_t *cap)
{
    double ax = (double)a[0], ay = (double)a[1], bx = (double)b[0], by = (double)b[1];
    double len = hypot(bx - ax, by - ay);
    double pieces = ceil(len / GTSCORE_SAMPLE_M - 1e-9);
    size_t n = pieces < 1.0 ? 1u : (size_t)pieces, k;
    if (!isfinite(len) || pieces > 1e9)
        return -1;
    if (*count + n > *cap) {
        size_t new_cap = (*cap ? *cap : 1024u);
        double *p;
        while (new_cap < *count + n)
            new_cap *= 2u;
        p = realloc(*dist, new_cap * sizeof *p);
        if (!p)
            return -1;
        *dist = p;
        *cap = new_cap;
    }
    for (k = 0; k < n; k++) {
        double t = (double)k / (double)n;
        (*dist)[(*count)++] = gtscore_index_distance(&truth->index, ax + (bx - ax) * t,
                                                     ay + (by - ay) * t, HUGE_VAL);
    }
    return 0;
}

/* The distances to the truth of the map's 1 cm samples: *dist (malloc'ed,
 * NULL if none) gets *n of them. */
static int sample_distances(const gtscore_truth *truth, const polyc_polyline *lines,
                            uint32_t count, double **dist, size_t *n)
{
    size_t cap = 0;
    uint32_t l, j;
    *dist = NULL;
    *n = 0;
    for (l = 0; l < count; l++) {
        const polyc_polyline *pl = &lines[l];
        uint32_t m = pl->point_count, segs;
        if (m == 0)
            continue;
        segs = pl->closed && m > 2u ? m : m - 1u;
        for (j = 0; j < segs; j++)
            if (sample_segment(truth, &pl->xy_m[2u * j], &pl->xy_m[2u * ((j + 1u) % m)], dist,
                               n, &cap) != 0)
                goto fail;
        if (!(pl->closed && m > 2u)) { /* the open end (or a lone point) */
            const float *e = &pl->xy_m[2u * (m - 1u)];
            if (sample_segment(truth, e, e, dist, n, &cap) != 0)
                goto fail;
        }
    }
    return 0;
fail:
    free(*dist);
    *dist = NULL;
    *n = 0;
    return -1;
}

static int precision(const gtscore_truth *truth, const polyc_polyline *lines, uint32_t count,
                     gtscore_map_score *out)
{
    double *dist, sum_sq = 0.0;
    size_t n, i;
    if (sample_distances(truth, lines, count, &dist, &n) != 0)
        return -1;
    out->precision_samples = n;
    if (n > 0) {
        for (i = 0; i < n; i++)
            sum_sq += dist[i] * dist[i];
        qsort(dist, n, sizeof *dist, compare_double);
        out->precision_rms_m = sqrt(sum_sq / (double)n);
        /* nearest rank: the smallest value with >= 95% of samples at or below */
        out->precision_p95_m = dist[(size_t)ceil(0.95 * (double)n) - 1u];
        out->precision_max_m = dist[n - 1u];
    }
    free(dist);
    return 0;
}

int gtscore_core_precision(const gtscore_truth *truth, const polyc_polyline *lines,
                           uint32_t count, double core_m, double *rms_m)
{
    double *dist, sum_sq = 0.0;
    size_t n, i, kept = 0;
    uint32_t l;
    if (!rms_m)
        return -1;
    *rms_m = 0.0;
    if (!truth || (!lines && count) || !(core_m >= 0.0))
        return -1;
    for (l = 0; l < count; l++)
        if (lines[l].point_count && !lines[l].xy_m)
            return -1;
    if (sample_distances(truth, lines, count, &dist, &n) != 0)
        return -1;
    for (i = 0; i < n; i++)
        if (dist[i] <= core_m) {
            sum_sq += dist[i] * dist[i];
            kept++;
        }
    *rms_m = kept ? sqrt(sum_sq / (double)kept) : 0.0;
    free(dist);
    return 0;
}

int gtscore_score_map(const gtscore_truth *truth, const polyc_polyline *lines,
                      uint32_t count, gtscore_map_score *out)
{
    gtscore_index map;
    uint32_t i;
    memset(out, 0, sizeof *out);
    if (!truth || (!lines && count))
        return -1;
    for (i = 0; i < count; i++) {
        out->vertices += lines[i].point_count;
        if (lines[i].point_count && !lines[i].xy_m)
            return -1;
    }
    out->polylines = count;
    out->ideal = truth->has_ideal ? truth->ideal : 0u;
    out->vertex_ratio = out->ideal ? (double)out->vertices / (double)out->ideal : 0.0;
    out->params = 2u * out->vertices;
    out->arcs = out->circles = 0;
    out->ideal_params = truth->has_ideal_params ? truth->ideal_params : 0u;
    out->param_ratio = out->ideal_params ? (double)out->params / (double)out->ideal_params : 0.0;
    if (precision(truth, lines, count, out) != 0)
        return -1;

    gtscore_index_init(&map);
    if (gtscore_index_add_polylines(&map, lines, count) != 0 ||
        gtscore_index_build(&map, MAP_CELL_M) != 0) {
        gtscore_index_free(&map);
        return -1;
    }
    out->seen_count = truth->seen_count;
    for (i = 0; i < truth->seen_count; i++)
        if (gtscore_index_distance(&map, truth->seen_xy_m[2u * i], truth->seen_xy_m[2u * i + 1u],
                                   GTSCORE_COMPLETE_M) <= GTSCORE_COMPLETE_M)
            out->seen_covered++;
    out->completeness =
        out->seen_count ? (double)out->seen_covered / (double)out->seen_count : 1.0;
    gtscore_index_free(&map);
    return 0;
}

/* ---- single-scan scores --------------------------------------------------- */

int gtscore_beam_reflected(const polyc_scan *scan, uint32_t beam)
{
    float r = scan->range_m[beam];
    return isfinite(r) && r >= scan->min_range_m && r < scan->max_range_m;
}

static double beam_angle(const polyc_scan *scan, uint32_t beam)
{
    return scan->pose_theta_rad + (double)scan->start_angle_rad +
           (double)beam * (double)scan->angle_step_rad;
}

void gtscore_score_scan(const gtscore_index *map, const polyc_scan *scan,
                        gtscore_scan_score *acc)
{
    uint32_t i;
    for (i = 0; i < scan->beam_count; i++) {
        double r_map, error;
        if (!gtscore_beam_reflected(scan, i))
            continue;
        acc->reflected++;
        r_map = gtscore_index_ray(map, scan->pose_x_m, scan->pose_y_m, beam_angle(scan, i),
                                  (double)scan->max_range_m);
        if (!isfinite(r_map))
            continue;
        error = (double)scan->range_m[i] - r_map;
        acc->hits++;
        acc->sum_sq_m2 += error * error;
    }
    acc->f = acc->reflected ? (double)acc->hits / (double)acc->reflected : 0.0;
    acc->ray_rmse_m = acc->hits ? sqrt(acc->sum_sq_m2 / (double)acc->hits) : 0.0;
}

/* The endpoint (x, y) of the next reflected beam from beam *i of scan *s
 * on: 1, with *s its scan and *i the beam after it; 0 after the last.
 * Start with *s = *i = 0. */
static int next_endpoint(const polyc_scan *scans, uint32_t scan_count, uint32_t *s, uint32_t *i,
                         double *x, double *y)
{
    for (; *s < scan_count; (*s)++, *i = 0) {
        const polyc_scan *scan = &scans[*s];
        for (; *i < scan->beam_count; (*i)++) {
            if (!gtscore_beam_reflected(scan, *i))
                continue;
            double a = beam_angle(scan, *i), r = (double)scan->range_m[*i];
            *x = scan->pose_x_m + r * cos(a);
            *y = scan->pose_y_m + r * sin(a);
            (*i)++;
            return 1;
        }
    }
    return 0;
}

int gtscore_scan_endpoints(const polyc_scan *scans, uint32_t scan_count, double **xy_m,
                           double **sensors_xy_m, uint64_t *count)
{
    uint64_t n = 0, p;
    uint32_t s, i;
    double *xy, *from = NULL, x, y;
    if (!xy_m || !count || (!scans && scan_count))
        return -1;
    *xy_m = NULL;
    if (sensors_xy_m)
        *sensors_xy_m = NULL;
    *count = 0;
    for (s = 0; s < scan_count; s++)
        for (i = 0; i < scans[s].beam_count; i++)
            n += (uint64_t)gtscore_beam_reflected(&scans[s], i);
    if (n == 0)
        return 0;
    if (n > SIZE_MAX / (2u * sizeof *xy))
        return -1;
    xy = malloc((size_t)n * 2u * sizeof *xy);
    if (sensors_xy_m)
        from = malloc((size_t)n * 2u * sizeof *from);
    if (!xy || (sensors_xy_m && !from)) {
        free(xy);
        free(from);
        return -1;
    }
    s = i = 0;
    for (p = 0; next_endpoint(scans, scan_count, &s, &i, &x, &y); p++) {
        xy[2u * p] = x;
        xy[2u * p + 1u] = y;
        if (from) {
            from[2u * p] = scans[s].pose_x_m;
            from[2u * p + 1u] = scans[s].pose_y_m;
        }
    }
    *xy_m = xy;
    if (sensors_xy_m)
        *sensors_xy_m = from;
    *count = n;
    return 0;
}

void gtscore_endpoints_within(const gtscore_index *map, const polyc_scan *scans,
                              uint32_t scan_count, double d_m, uint64_t *within,
                              uint64_t *total)
{
    uint32_t s = 0, i = 0;
    double x, y;
    *within = 0;
    *total = 0;
    while (next_endpoint(scans, scan_count, &s, &i, &x, &y)) {
        (*total)++;
        if (gtscore_index_distance(map, x, y, d_m) <= d_m)
            (*within)++;
    }
}
