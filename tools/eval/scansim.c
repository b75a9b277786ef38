/* scansim.c - deterministic 2D laser simulator (see scansim.h).
 *
 * Takes a scene (walls, poses, laser, noise, people); gives noisy scans and
 * the wall samples the laser observed (the files are written by
 * scansim_io.c, the built-in scenes live in scansim_scenes.c). Ray casting
 * is brute force over all wall segments: the scenes are small (hundreds of
 * segments, a few hundred scans).
 */
#include "scansim.h"
#include "grow.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SCANSIM_PI 3.14159265358979323846
#define SCANSIM_SAMPLE_M 0.02      /* spacing of the ground-truth samples */
#define SCANSIM_JOIN_M 0.30        /* two neighbouring beams on one wall whose
                                      hits are closer than this saw the wall
                                      between them too */

/* ---- random numbers ---------------------------------------------------- */

void scansim_rng_seed(scansim_rng *rng, uint64_t seed)
{
    rng->state = seed;
    rng->spare = 0.0;
    rng->has_spare = 0;
}

/* splitmix64: a 64-bit counter passed through a bijective mixer. */
uint64_t scansim_rng_u64(scansim_rng *rng)
{
    uint64_t z;
    rng->state += UINT64_C(0x9E3779B97F4A7C15);
    z = rng->state;
    z = (z ^ (z >> 30)) * UINT64_C(0xBF58476D1CE4E5B9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94D049BB133111EB);
    return z ^ (z >> 31);
}

double scansim_rng_uniform(scansim_rng *rng)
{
    return (double)(scansim_rng_u64(rng) >> 11) * (1.0 / 9007199254740992.0);
}

double scansim_rng_gauss(scansim_rng *rng)
{
    double u1, u2, r;
    if (rng->has_spare) {
        rng->has_spare = 0;
        return rng->spare;
    }
    u1 = 1.0 - scansim_rng_uniform(rng); /* (0, 1]: log is finite */
    u2 = scansim_rng_uniform(rng);
    r = sqrt(-2.0 * log(u1));
    rng->spare = r * sin(2.0 * SCANSIM_PI * u2);
    rng->has_spare = 1;
    return r * cos(2.0 * SCANSIM_PI * u2);
}

/* ---- scene building ----------------------------------------------------- */

void scansim_scene_init(scansim_scene *scene, const char *name, uint64_t seed)
{
    memset(scene, 0, sizeof *scene);
    if (name) {
        strncpy(scene->name, name, sizeof scene->name - 1u);
        scene->name[sizeof scene->name - 1u] = '\0';
    }
    scene->seed = seed;
    scene->laser.beam_count = 181u;
    scene->laser.start_angle_rad = (float)(-SCANSIM_PI / 2.0);
    scene->laser.angle_step_rad = (float)(SCANSIM_PI / 180.0);
    scene->laser.min_range_m = 0.02f;
    scene->laser.max_range_m = 8.0f;
    scene->laser.range_sigma_m = 0.01f;
    scene->laser.dropout = 0.003f;
    scene->pose_sigma_m = 0.01;
    scene->pose_sigma_rad = 0.2 * SCANSIM_PI / 180.0;
}

static void free_results(scansim_scene *scene)
{
    free(scene->scans);
    free(scene->range_m);
    free(scene->sample_xy_m);
    free(scene->sample_seen);
    free(scene->sample_corner);
    free(scene->sample_smooth);
    free(scene->wall_box);
    free(scene->wall_first_sample);
    free(scene->wall_sample_count);
    scene->scans = NULL;
    scene->range_m = NULL;
    scene->sample_xy_m = NULL;
    scene->sample_seen = NULL;
    scene->sample_corner = NULL;
    scene->sample_smooth = NULL;
    scene->wall_box = NULL;
    scene->wall_first_sample = NULL;
    scene->wall_sample_count = NULL;
    scene->scan_count = 0;
    scene->sample_count = 0;
    scene->hit_count = 0;
}

void scansim_scene_free(scansim_scene *scene)
{
    if (!scene)
        return;
    free_results(scene);
    free(scene->wall_xy_m);
    free(scene->wall_smooth);
    free(scene->walls);
    free(scene->poses);
    free(scene->people);
    memset(scene, 0, sizeof *scene);
}

int scansim_add_wall_smooth(scansim_scene *scene, const double *xy_m, uint32_t point_count,
                            int closed, const uint8_t *smooth)
{
    uint32_t i, cap;
    scansim_wall *w;
    if (!scene || !xy_m || point_count < 2u || (closed && point_count < 3u))
        return -1;
    if (point_count > UINT32_MAX - scene->wall_point_count)
        return -1;
    cap = scene->wall_point_cap;
    if (grow_array((void **)&scene->wall_xy_m, &cap, scene->wall_point_count + point_count,
                   2u * sizeof(double)) != 0)
        return -1;
    /* (the flags grow with the points, to the same capacity) */
    cap = scene->wall_point_cap;
    if (grow_array((void **)&scene->wall_smooth, &cap, scene->wall_point_count + point_count,
                   1u) != 0)
        return -1;
    scene->wall_point_cap = cap;
    if (grow_array((void **)&scene->walls, &scene->wall_cap, scene->wall_count + 1u,
                   sizeof(scansim_wall)) != 0)
        return -1;
    for (i = 0; i < 2u * point_count; i++)
        scene->wall_xy_m[2u * scene->wall_point_count + i] = xy_m[i];
    for (i = 0; i < point_count; i++)
        scene->wall_smooth[scene->wall_point_count + i] = smooth && smooth[i] ? 1u : 0u;
    free(scene->wall_box); /* (made again by the next run) */
    scene->wall_box = NULL;
    w = &scene->walls[scene->wall_count++];
    w->first_point = scene->wall_point_count;
    w->point_count = point_count;
    w->closed = closed ? 1u : 0u;
    scene->wall_point_count += point_count;
    return 0;
}

int scansim_add_wall(scansim_scene *scene, const double *xy_m, uint32_t point_count,
                     int closed)
{
    return scansim_add_wall_smooth(scene, xy_m, point_count, closed, NULL);
}

uint32_t scansim_arc_points(double *xy, uint32_t max, double cx, double cy, double r, double a0,
                            double a1)
{
    /* a side of angle d strays r (1 - cos(d / 2)) from the arc */
    double d = 2.0 * acos(fmax(-1.0, 1.0 - SCANSIM_ARC_SAGITTA_M / r));
    double n = ceil(fabs(a1 - a0) / d);
    uint32_t count = (uint32_t)(n < 1.0 ? 1.0 : n) + 1u;
    if (max < 2u)
        return 0;
    if (count > max)
        count = max;
    scansim_arc_fill(xy, count, cx, cy, r, a0, a1);
    return count;
}

void scansim_arc_fill(double *xy, uint32_t count, double cx, double cy, double r, double a0,
                      double a1)
{
    uint32_t k;
    for (k = 0; k < count; k++) {
        double a = a0 + (a1 - a0) * (double)k / (double)(count - 1u);
        xy[2u * k] = cx + r * cos(a);
        xy[2u * k + 1u] = cy + r * sin(a);
    }
}

int scansim_add_circle(scansim_scene *scene, double cx_m, double cy_m, double radius_m,
                       uint32_t sides)
{
    double *xy;
    uint32_t i;
    int rc;
    if (sides < 3u || !(radius_m > 0.0))
        return -1;
    xy = malloc(2u * (size_t)sides * sizeof *xy);
    if (!xy)
        return -1;
    for (i = 0; i < sides; i++) {
        double a = 2.0 * SCANSIM_PI * (double)i / (double)sides;
        xy[2u * i] = cx_m + radius_m * cos(a);
        xy[2u * i + 1u] = cy_m + radius_m * sin(a);
    }
    {
        uint8_t *smooth = malloc(sides);
        if (!smooth) {
            free(xy);
            return -1;
        }
        memset(smooth, 1, sides);
        rc = scansim_add_wall_smooth(scene, xy, sides, 1, smooth);
        free(smooth);
    }
    free(xy);
    return rc;
}

int scansim_add_box(scansim_scene *scene, double x0_m, double y0_m, double x1_m,
                    double y1_m)
{
    double xy[8];
    xy[0] = x0_m; xy[1] = y0_m;
    xy[2] = x1_m; xy[3] = y0_m;
    xy[4] = x1_m; xy[5] = y1_m;
    xy[6] = x0_m; xy[7] = y1_m;
    return scansim_add_wall(scene, xy, 4u, 1);
}

int scansim_add_pose(scansim_scene *scene, double x_m, double y_m, double theta_rad)
{
    scansim_pose *p;
    if (!scene || scene->pose_count == UINT32_MAX)
        return -1;
    if (grow_array((void **)&scene->poses, &scene->pose_cap, scene->pose_count + 1u,
                   sizeof(scansim_pose)) != 0)
        return -1;
    p = &scene->poses[scene->pose_count++];
    p->x_m = x_m;
    p->y_m = y_m;
    p->theta_rad = theta_rad;
    return 0;
}

int scansim_add_path(scansim_scene *scene, const double *xy_m, uint32_t waypoint_count,
                     double spacing_m)
{
    double carry = 0.0; /* distance into the current leg of the next pose */
    uint32_t i;
    if (!scene || !xy_m || waypoint_count < 2u || !(spacing_m > 0.0))
        return -1;
    for (i = 0; i + 1u < waypoint_count; i++) {
        double x0 = xy_m[2u * i], y0 = xy_m[2u * i + 1u];
        double dx = xy_m[2u * i + 2u] - x0, dy = xy_m[2u * i + 3u] - y0;
        double len = sqrt(dx * dx + dy * dy);
        double heading = atan2(dy, dx);
        double s;
        if (len <= 0.0)
            continue;
        for (s = carry; s < len; s += spacing_m) {
            if (scansim_add_pose(scene, x0 + dx * s / len, y0 + dy * s / len, heading) != 0)
                return -1;
        }
        carry = s - len;
    }
    return 0;
}

int scansim_add_person(scansim_scene *scene, const scansim_person *person)
{
    if (!scene || !person || !(person->radius_m > 0.0) ||
        person->last_scan < person->first_scan)
        return -1;
    if (grow_array((void **)&scene->people, &scene->person_cap, scene->person_count + 1u,
                   sizeof(scansim_person)) != 0)
        return -1;
    scene->people[scene->person_count++] = *person;
    return 0;
}

static void rotate_shift(double *x, double *y, double c, double s, double dx, double dy)
{
    double nx = c * *x - s * *y + dx;
    double ny = s * *x + c * *y + dy;
    *x = nx;
    *y = ny;
}

void scansim_transform(scansim_scene *scene, double angle_rad, double dx_m, double dy_m)
{
    double c = cos(angle_rad), s = sin(angle_rad);
    uint32_t i;
    free(scene->wall_box);
    scene->wall_box = NULL;
    for (i = 0; i < scene->wall_point_count; i++)
        rotate_shift(&scene->wall_xy_m[2u * i], &scene->wall_xy_m[2u * i + 1u], c, s, dx_m,
                     dy_m);
    for (i = 0; i < scene->pose_count; i++) {
        rotate_shift(&scene->poses[i].x_m, &scene->poses[i].y_m, c, s, dx_m, dy_m);
        scene->poses[i].theta_rad += angle_rad;
    }
    for (i = 0; i < scene->person_count; i++) {
        scansim_person *p = &scene->people[i];
        rotate_shift(&p->from_x_m, &p->from_y_m, c, s, dx_m, dy_m);
        rotate_shift(&p->to_x_m, &p->to_y_m, c, s, dx_m, dy_m);
    }
}

int scansim_keep_every(scansim_scene *scene, uint32_t step)
{
    uint32_t i, n = 0;
    if (!scene || step == 0)
        return -1;
    for (i = 0; i < scene->pose_count; i += step)
        scene->poses[n++] = scene->poses[i];
    scene->pose_count = n;
    for (i = 0; i < scene->person_count; i++) {
        scene->people[i].first_scan /= step;
        scene->people[i].last_scan /= step;
    }
    return 0;
}

double scansim_point_segment_m(double px, double py, const double *a, const double *b)
{
    double ex = b[0] - a[0], ey = b[1] - a[1], len2 = ex * ex + ey * ey, t = 0.0;
    if (len2 > 0.0) {
        t = ((px - a[0]) * ex + (py - a[1]) * ey) / len2;
        t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    }
    return hypot(px - a[0] - t * ex, py - a[1] - t * ey);
}

double scansim_path_clearance(const scansim_scene *scene)
{
    double best = HUGE_VAL;
    uint32_t p, w, j;
    for (p = 0; p < scene->pose_count; p++)
        for (w = 0; w < scene->wall_count; w++) {
            const scansim_wall *wall = &scene->walls[w];
            uint32_t nseg = wall->closed ? wall->point_count : wall->point_count - 1u;
            for (j = 0; j < nseg; j++) {
                const double *a = &scene->wall_xy_m[2u * (wall->first_point + j)];
                const double *b =
                    &scene->wall_xy_m[2u * (wall->first_point + (j + 1u) % wall->point_count)];
                double d =
                    scansim_point_segment_m(scene->poses[p].x_m, scene->poses[p].y_m, a, b);
                if (d < best)
                    best = d;
            }
        }
    return best;
}

/* ---- ray casting -------------------------------------------------------- */

uint32_t scansim_segment_count(const scansim_scene *scene)
{
    uint32_t n = 0, w;
    for (w = 0; w < scene->wall_count; w++)
        n += scene->walls[w].closed ? scene->walls[w].point_count
                                    : scene->walls[w].point_count - 1u;
    return n;
}

/* Where person p stands during scan `scan`; 0 if absent. */
static int person_at(const scansim_person *p, uint32_t scan, double *x, double *y)
{
    double f;
    if (scan < p->first_scan || scan > p->last_scan)
        return 0;
    f = p->last_scan > p->first_scan
            ? (double)(scan - p->first_scan) / (double)(p->last_scan - p->first_scan)
            : 0.0;
    *x = p->from_x_m + (p->to_x_m - p->from_x_m) * f;
    *y = p->from_y_m + (p->to_y_m - p->from_y_m) * f;
    return 1;
}

/* The nearest hit along the ray; *segment gets the segment index (-2 person,
 * -1 nothing) and *along the hit's parameter in [0, 1] on that segment. */
/* The boxes round the walls (wall_box); 0, or -1 out of memory. */
static int make_boxes(scansim_scene *scene)
{
    uint32_t w, j;
    free(scene->wall_box);
    scene->wall_box = malloc(4u * (size_t)(scene->wall_count ? scene->wall_count : 1u) * sizeof(double));
    if (!scene->wall_box)
        return -1;
    for (w = 0; w < scene->wall_count; w++) {
        const scansim_wall *wall = &scene->walls[w];
        double *b = &scene->wall_box[4u * w];
        b[0] = b[1] = HUGE_VAL;
        b[2] = b[3] = -HUGE_VAL;
        for (j = 0; j < wall->point_count; j++) {
            const double *p = &scene->wall_xy_m[2u * (wall->first_point + j)];
            b[0] = fmin(b[0], p[0]);
            b[1] = fmin(b[1], p[1]);
            b[2] = fmax(b[2], p[0]);
            b[3] = fmax(b[3], p[1]);
        }
    }
    return 0;
}

/* Can the ray from (ox, oy) along (dx, dy) meet the box b (with a margin
 * far above rounding)? */
static int ray_meets_box(const double *b, double ox, double oy, double dx, double dy)
{
    const double m = 1e-6;
    double lo = 0.0, hi = HUGE_VAL, o[2] = {ox, oy}, d[2] = {dx, dy};
    int k;
    for (k = 0; k < 2; k++) {
        double a0 = b[k] - m, a1 = b[k + 2] + m;
        if (fabs(d[k]) < 1e-15) {
            if (o[k] < a0 || o[k] > a1)
                return 0;
            continue;
        }
        double t0 = (a0 - o[k]) / d[k], t1 = (a1 - o[k]) / d[k];
        if (t0 > t1) {
            double t = t0;
            t0 = t1;
            t1 = t;
        }
        lo = fmax(lo, t0);
        hi = fmin(hi, t1);
        if (lo > hi)
            return 0;
    }
    return 1;
}

static double cast_ray(const scansim_scene *scene, double ox, double oy, double angle,
                       uint32_t scan, int32_t *segment, double *along)
{
    double dx = cos(angle), dy = sin(angle);
    double best = HUGE_VAL;
    int32_t best_seg = -1;
    double best_u = 0.0;
    uint32_t w, j, seg = 0;
    for (w = 0; w < scene->wall_count; w++) {
        const scansim_wall *wall = &scene->walls[w];
        uint32_t nseg = wall->closed ? wall->point_count : wall->point_count - 1u;
        if (scene->wall_box && !ray_meets_box(&scene->wall_box[4u * w], ox, oy, dx, dy)) {
            seg += nseg;
            continue;
        }
        for (j = 0; j < nseg; j++, seg++) {
            const double *a = &scene->wall_xy_m[2u * (wall->first_point + j)];
            const double *b =
                &scene->wall_xy_m[2u * (wall->first_point + (j + 1u) % wall->point_count)];
            double ex = b[0] - a[0], ey = b[1] - a[1];
            double wx = a[0] - ox, wy = a[1] - oy;
            double denom = dx * ey - dy * ex;
            double t, u;
            if (fabs(denom) < 1e-15)
                continue; /* parallel: a grazing ray sees nothing */
            t = (wx * ey - wy * ex) / denom;
            u = (wx * dy - wy * dx) / denom;
            if (t > 1e-9 && t < best && u >= 0.0 && u <= 1.0) {
                best = t;
                best_seg = (int32_t)seg;
                best_u = u;
            }
        }
    }
    if (scan != UINT32_MAX) {
        for (w = 0; w < scene->person_count; w++) {
            double cx, cy, b, c, disc, t;
            const scansim_person *p = &scene->people[w];
            if (!person_at(p, scan, &cx, &cy))
                continue;
            b = dx * (ox - cx) + dy * (oy - cy);
            c = (ox - cx) * (ox - cx) + (oy - cy) * (oy - cy) - p->radius_m * p->radius_m;
            disc = b * b - c;
            if (disc < 0.0)
                continue;
            t = -b - sqrt(disc);
            if (t <= 1e-9)
                t = -b + sqrt(disc);
            if (t > 1e-9 && t < best) {
                best = t;
                best_seg = -2;
            }
        }
    }
    if (segment)
        *segment = best_seg;
    if (along)
        *along = best_u;
    return best;
}

double scansim_cast(const scansim_scene *scene, double x_m, double y_m, double angle_rad,
                    uint32_t scan_index, int32_t *object)
{
    return cast_ray(scene, x_m, y_m, angle_rad, scan_index, object, NULL);
}

/* ---- ground-truth samples ----------------------------------------------- */

/* Per segment: its wall and where its samples start (relative to the wall's
 * first sample) and how many intervals it is cut into. */
typedef struct seg_info {
    uint32_t wall;
    uint32_t base;      /* sample of the segment's first point, wall-relative */
    uint32_t intervals; /* samples at t = k / intervals, k = 0..intervals */
    int corner;         /* the segment's first point is a corner of its wall */
} seg_info;

static uint32_t segment_intervals(const double *a, const double *b)
{
    double len = hypot(b[0] - a[0], b[1] - a[1]);
    double n = ceil(len / SCANSIM_SAMPLE_M - 1e-9);
    return n < 1.0 ? 1u : (uint32_t)n;
}

/* Lays the samples along every wall; fills seg (one per segment). */
static int make_samples(scansim_scene *scene, seg_info *seg)
{
    uint32_t w, j, k, total = 0, s = 0;
    for (w = 0; w < scene->wall_count; w++) {
        const scansim_wall *wall = &scene->walls[w];
        uint32_t nseg = wall->closed ? wall->point_count : wall->point_count - 1u;
        uint32_t count = 0;
        for (j = 0; j < nseg; j++, s++) {
            const double *a = &scene->wall_xy_m[2u * (wall->first_point + j)];
            const double *b =
                &scene->wall_xy_m[2u * (wall->first_point + (j + 1u) % wall->point_count)];
            seg[s].wall = w;
            seg[s].base = count;
            seg[s].corner = wall->closed || j > 0;
            seg[s].intervals = segment_intervals(a, b);
            count += seg[s].intervals;
        }
        if (!wall->closed)
            count++; /* the open wall's last point */
        scene->wall_first_sample[w] = total;
        scene->wall_sample_count[w] = count;
        total += count;
    }
    scene->sample_count = total;
    scene->sample_xy_m = malloc(2u * (size_t)total * sizeof(double));
    scene->sample_seen = calloc(total ? total : 1u, 1u);
    scene->sample_corner = calloc(total ? total : 1u, 1u);
    scene->sample_smooth = calloc(total ? total : 1u, 1u);
    if (!scene->sample_xy_m || !scene->sample_seen || !scene->sample_corner ||
        !scene->sample_smooth)
        return -1;
    for (s = 0, w = 0; w < scene->wall_count; w++) {
        const scansim_wall *wall = &scene->walls[w];
        uint32_t nseg = wall->closed ? wall->point_count : wall->point_count - 1u;
        double *out = &scene->sample_xy_m[2u * scene->wall_first_sample[w]];
        for (j = 0; j < nseg; j++, s++) {
            const double *a = &scene->wall_xy_m[2u * (wall->first_point + j)];
            const double *b =
                &scene->wall_xy_m[2u * (wall->first_point + (j + 1u) % wall->point_count)];
            scene->sample_corner[scene->wall_first_sample[w] + seg[s].base] =
                seg[s].corner ? 1u : 0u;
            scene->sample_smooth[scene->wall_first_sample[w] + seg[s].base] =
                scene->wall_smooth[wall->first_point + j];
            for (k = 0; k < seg[s].intervals; k++) {
                double t = (double)k / (double)seg[s].intervals;
                *out++ = a[0] + (b[0] - a[0]) * t;
                *out++ = a[1] + (b[1] - a[1]) * t;
            }
        }
        if (!wall->closed) {
            const double *last = &scene->wall_xy_m[2u * (wall->first_point + nseg)];
            *out++ = last[0];
            *out++ = last[1];
        }
    }
    return 0;
}

/* Marks wall-relative sample position u (rounded) of wall w. */
static void mark_sample(scansim_scene *scene, uint32_t w, double u)
{
    uint32_t count = scene->wall_sample_count[w];
    double r = floor(u + 0.5);
    uint32_t k;
    if (r < 0.0)
        r = 0.0;
    k = (uint32_t)r;
    if (k >= count)
        k = scene->walls[w].closed ? k % count : count - 1u;
    scene->sample_seen[scene->wall_first_sample[w] + k] = 1u;
}

/* Marks every sample between wall-relative positions u1 and u2 of wall w
 * (the short way round a closed wall). */
static void mark_stretch(scansim_scene *scene, uint32_t w, double u1, double u2)
{
    uint32_t count = scene->wall_sample_count[w];
    double lo = u1 < u2 ? u1 : u2, hi = u1 < u2 ? u2 : u1, u;
    if (scene->walls[w].closed && hi - lo > 0.5 * (double)count) {
        lo += (double)count; /* wrap: go from hi up to lo + count */
        u = lo;
        lo = hi;
        hi = u;
    }
    mark_sample(scene, w, lo);
    mark_sample(scene, w, hi);
    for (u = ceil(lo); u <= hi; u += 1.0) {
        uint32_t k = (uint32_t)u;
        if (k >= count) {
            if (!scene->walls[w].closed)
                break;
            k %= count;
        }
        scene->sample_seen[scene->wall_first_sample[w] + k] = 1u;
    }
}

/* Two hits at wall-relative sample positions u1, u2 of one wall are close
 * along the wall (the short way round a closed wall): then the wall between
 * them faced the laser too. */
static int close_along_wall(const scansim_scene *scene, uint32_t w, double u1, double u2)
{
    double gap = fabs(u1 - u2), count = (double)scene->wall_sample_count[w];
    if (scene->walls[w].closed && gap > 0.5 * count)
        gap = count - gap;
    return gap <= SCANSIM_JOIN_M / SCANSIM_SAMPLE_M;
}

/* ---- simulation --------------------------------------------------------- */

/* A beam that hit a wall: segment, wall, wall-relative sample position and
 * the true hit point. seg < 0: no wall hit. */
typedef struct wall_hit {
    int32_t seg;
    uint32_t wall;
    double u, x, y;
} wall_hit;

/* Marks what beam `cur` observed; `prev` is its neighbouring beam. */
static void observe(scansim_scene *scene, const wall_hit *prev, const wall_hit *cur)
{
    if (prev->seg >= 0 && prev->wall == cur->wall &&
        close_along_wall(scene, cur->wall, prev->u, cur->u) &&
        hypot(cur->x - prev->x, cur->y - prev->y) < SCANSIM_JOIN_M)
        mark_stretch(scene, cur->wall, prev->u, cur->u);
    else
        mark_sample(scene, cur->wall, cur->u);
}

/* v rounded to the nearest multiple of 1 / per_unit (what "%.3f" or "%.6f"
 * prints for per_unit 1e3 or 1e6). */
static double round_to(double v, double per_unit)
{
    return floor(v * per_unit + 0.5) / per_unit;
}

/* The drift of each pose (scansim.h): err gets x, y, heading per pose. */
static void make_drift(const scansim_scene *scene, double *err)
{
    scansim_rng rng;
    double ex = 0.0, ey = 0.0, et = 0.0, since = 0.0;
    uint32_t s;
    scansim_rng_seed(&rng, scene->seed ^ UINT64_C(0x6472696674)); /* "drift" */
    for (s = 0; s < scene->pose_count; s++) {
        if (s > 0) {
            const scansim_pose *a = &scene->poses[s - 1u], *b = &scene->poses[s];
            double dx = b->x_m - a->x_m, dy = b->y_m - a->y_m, d = hypot(dx, dy);
            double c = cos(et), sn = sin(et), root = sqrt(d);
            double gx = scansim_rng_gauss(&rng), gy = scansim_rng_gauss(&rng);
            double gt = scansim_rng_gauss(&rng);
            ex += c * dx - sn * dy - dx + scene->drift_m_per_m * root * gx;
            ey += sn * dx + c * dy - dy + scene->drift_m_per_m * root * gy;
            et += scene->drift_rad_per_m * root * gt;
            since += d;
            if (scene->drift_reset_m > 0.0 && since >= scene->drift_reset_m) {
                ex *= scene->drift_keep;
                ey *= scene->drift_keep;
                et *= scene->drift_keep;
                since = 0.0;
            }
        }
        err[3u * s] = ex;
        err[3u * s + 1u] = ey;
        err[3u * s + 2u] = et;
    }
}

int scansim_run(scansim_scene *scene)
{
    const scansim_laser *laser = &scene->laser;
    uint32_t nseg, n = laser->beam_count, s, i;
    seg_info *seg = NULL;
    double *drift = NULL;
    scansim_rng rng;
    int rc = -1, full_circle;

    if (!scene || scene->wall_count == 0 || n == 0)
        return -1;
    free_results(scene);
    nseg = scansim_segment_count(scene);
    seg = malloc((size_t)nseg * sizeof *seg);
    scene->wall_first_sample = malloc((size_t)scene->wall_count * sizeof(uint32_t));
    scene->wall_sample_count = malloc((size_t)scene->wall_count * sizeof(uint32_t));
    scene->scans = calloc(scene->pose_count ? scene->pose_count : 1u, sizeof(polyc_scan));
    scene->range_m = malloc(((size_t)scene->pose_count * n + 1u) * sizeof(float));
    if (!seg || !scene->wall_first_sample || !scene->wall_sample_count || !scene->scans ||
        !scene->range_m || make_samples(scene, seg) != 0 || make_boxes(scene) != 0)
        goto done;
    if (scene->drift_m_per_m > 0.0 || scene->drift_rad_per_m > 0.0) {
        drift = malloc(((size_t)scene->pose_count * 3u + 1u) * sizeof *drift);
        if (!drift)
            goto done;
        make_drift(scene, drift);
    }

    scansim_rng_seed(&rng, scene->seed);
    full_circle = (double)n * fabs((double)laser->angle_step_rad) >= 2.0 * SCANSIM_PI - 1e-4;
    for (s = 0; s < scene->pose_count; s++) {
        const scansim_pose *truth = &scene->poses[s];
        polyc_scan *scan = &scene->scans[s];
        float *range = &scene->range_m[(size_t)s * n];
        wall_hit first, prev, cur;

        /* logged pose: truth plus alignment noise (and drift), in the log's
         * precision */
        scan->pose_x_m = truth->x_m + scene->pose_sigma_m * scansim_rng_gauss(&rng);
        scan->pose_y_m = truth->y_m + scene->pose_sigma_m * scansim_rng_gauss(&rng);
        scan->pose_theta_rad = truth->theta_rad + scene->pose_sigma_rad * scansim_rng_gauss(&rng);
        if (drift) {
            scan->pose_x_m += drift[3u * s];
            scan->pose_y_m += drift[3u * s + 1u];
            scan->pose_theta_rad += drift[3u * s + 2u];
        }
        scan->pose_x_m = round_to(scan->pose_x_m, 1e6);
        scan->pose_y_m = round_to(scan->pose_y_m, 1e6);
        scan->pose_theta_rad = round_to(scan->pose_theta_rad, 1e6);
        scan->start_angle_rad = laser->start_angle_rad;
        scan->angle_step_rad = laser->angle_step_rad;
        scan->min_range_m = laser->min_range_m;
        scan->max_range_m = laser->max_range_m;
        scan->beam_count = n;
        scan->reserved = 0;
        scan->range_m = range;

        first.seg = prev.seg = -1;
        for (i = 0; i < n; i++) {
            /* The same float angle the library will use for this beam. */
            double angle = truth->theta_rad + (double)laser->start_angle_rad +
                           (double)i * (double)laser->angle_step_rad;
            double u, r, measured;
            double drop = scansim_rng_uniform(&rng);
            double noise = scansim_rng_gauss(&rng); /* drawn always: a fixed stream */
            r = cast_ray(scene, truth->x_m, truth->y_m, angle, s, &cur.seg, &u);
            /* the log keeps mm: round here so that scans and log agree, and
             * a reading that rounds to max_range_m is no return in both */
            measured = round_to(r + (double)laser->range_sigma_m * noise, 1e3);
            if (!(r < (double)laser->max_range_m) || drop < (double)laser->dropout ||
                !(measured < (double)laser->max_range_m)) {
                range[i] = laser->max_range_m;
                prev.seg = -1;
                continue;
            }
            range[i] = (float)(measured > 0.0 ? measured : 0.0);
            scene->hit_count++;
            if (cur.seg >= 0) {
                cur.wall = seg[cur.seg].wall;
                cur.u = (double)seg[cur.seg].base + u * (double)seg[cur.seg].intervals;
                cur.x = truth->x_m + r * cos(angle);
                cur.y = truth->y_m + r * sin(angle);
                observe(scene, &prev, &cur);
                if (i == 0)
                    first = cur;
            }
            prev = cur;
        }
        if (full_circle && first.seg >= 0 && prev.seg >= 0)
            observe(scene, &prev, &first); /* the last beam neighbours the first */
    }
    scene->scan_count = scene->pose_count;
    rc = 0;
done:
    free(seg);
    free(drift);
    if (rc != 0)
        free_results(scene);
    return rc;
}
