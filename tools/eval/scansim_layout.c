/* scansim_layout.c - a scene kind's layout under construction
 * (scansim_layout.h). Takes: walls and waypoints as a kind draws them.
 * Gives: the path's poses, and furniture and people kept only where they
 * stay clear of the path, the walls and each other. */
#include "scansim_layout.h"

#include <string.h>

static double cross3(const double *o, const double *a, const double *b)
{
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

/* Distance between segments ab and cd (0 if they cross). */
static double seg_seg_dist(const double *a, const double *b, const double *c, const double *d)
{
    double d1 = cross3(a, b, c), d2 = cross3(a, b, d), d3 = cross3(c, d, a),
           d4 = cross3(c, d, b), m;
    if (((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) &&
        ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0)))
        return 0.0;
    m = scansim_point_segment_m(a[0], a[1], c, d);
    m = fmin(m, scansim_point_segment_m(b[0], b[1], c, d));
    m = fmin(m, scansim_point_segment_m(c[0], c[1], a, b));
    return fmin(m, scansim_point_segment_m(d[0], d[1], a, b));
}

static int point_in_poly(const double *xy, uint32_t n, double x, double y)
{
    uint32_t i, j;
    int in = 0;
    for (i = 0, j = n - 1u; i < n; j = i++) {
        double yi = xy[2u * i + 1u], yj = xy[2u * j + 1u];
        if ((yi > y) != (yj > y) &&
            x < xy[2u * j] + (xy[2u * i] - xy[2u * j]) * (y - yj) / (yi - yj))
            in = !in;
    }
    return in;
}

void layout_init(layout *L, scansim_scene *s, uint64_t kind_salt)
{
    memset(L, 0, sizeof *L);
    L->s = s;
    scansim_rng_seed(&L->rng, s->seed * UINT64_C(0x9E3779B97F4A7C15) ^ kind_salt);
    L->outline = UINT32_MAX;
    L->first_object = UINT32_MAX;
}

void layout_way(layout *L, double x, double y)
{
    if (L->way_count < MAX_WAY) {
        L->way[2u * L->way_count] = x;
        L->way[2u * L->way_count + 1u] = y;
        L->way_count++;
    }
}

static const double *wall_point(const scansim_scene *s, uint32_t w, uint32_t j)
{
    const scansim_wall *wall = &s->walls[w];
    return &s->wall_xy_m[2u * (wall->first_point + j % wall->point_count)];
}

/* Does the closed polygon (n points) keep PATH_CLEAR_M off the path, gap_m
 * off the structure's walls and OBJECT_GAP_M off the furniture, neither
 * inside another closed wall (the outline aside) nor round one? */
static int fits(const layout *L, const double *poly, uint32_t n, double gap_m)
{
    const scansim_scene *s = L->s;
    uint32_t i, j, w;
    for (i = 0; i < n; i++) {
        const double *a = &poly[2u * i], *b = &poly[2u * ((i + 1u) % n)];
        for (j = 0; j + 1u < L->way_count; j++)
            if (seg_seg_dist(a, b, &L->way[2u * j], &L->way[2u * j + 2u]) < PATH_CLEAR_M)
                return 0;
        for (w = 0; w < s->wall_count; w++) {
            const scansim_wall *wall = &s->walls[w];
            uint32_t nseg = wall->closed ? wall->point_count : wall->point_count - 1u;
            double need = w >= L->first_object ? OBJECT_GAP_M : gap_m;
            for (j = 0; j < nseg; j++)
                if (seg_seg_dist(a, b, wall_point(s, w, j), wall_point(s, w, j + 1u)) < need)
                    return 0;
        }
    }
    for (w = 0; w < s->wall_count; w++) {
        const double *p = wall_point(s, w, 0);
        if (point_in_poly(poly, n, p[0], p[1]))
            return 0;
        if (w != L->outline && s->walls[w].closed &&
            point_in_poly(&s->wall_xy_m[2u * s->walls[w].first_point], s->walls[w].point_count,
                          poly[0], poly[1]))
            return 0;
    }
    return 1;
}

/* Adds the polygon if `check` (the polygon itself, or a copy of it moved
 * off the wall it stands against) fits; 1 added, 0 not, -1 out of memory. */
static int try_add_checked(layout *L, const double *poly, const double *check, uint32_t n,
                           double gap_m, const uint8_t *smooth)
{
    if (L->first_object == UINT32_MAX)
        L->first_object = L->s->wall_count;
    if (!fits(L, check, n, gap_m))
        return 0;
    return scansim_add_wall_smooth(L->s, poly, n, 1, smooth) == 0 ? 1 : -1;
}

int layout_try_add(layout *L, const double *poly, uint32_t n, double gap_m)
{
    return try_add_checked(L, poly, poly, n, gap_m, NULL);
}

int layout_try_add_smooth(layout *L, const double *poly, uint32_t n, double gap_m,
                          const uint8_t *smooth)
{
    return try_add_checked(L, poly, poly, n, gap_m, smooth);
}

/* Up to `count` w x h boxes (sizes drawn per box from the ranges) at random
 * places in [x0, x1] x [y0, y1]; angle_rad < 0: any angle. -1 out of memory. */
int layout_scatter_boxes(layout *L, uint32_t count, const double *w_range,
                         const double *h_range, double angle_rad, double x0, double y0,
                         double x1, double y1, double gap_m)
{
    uint32_t placed = 0, tries;
    for (tries = 0; placed < count && tries < PLACE_TRIES; tries++) {
        double xy[8];
        double w = urange(&L->rng, w_range[0], w_range[1]);
        double h = urange(&L->rng, h_range[0], h_range[1]);
        double a = angle_rad < 0.0 ? urange(&L->rng, 0.0, PI) : angle_rad;
        double cx = urange(&L->rng, x0, x1), cy = urange(&L->rng, y0, y1);
        int rc;
        rect_xy(xy, cx, cy, w, h, a);
        rc = layout_try_add(L, xy, 4u, gap_m);
        if (rc < 0)
            return -1;
        placed += (uint32_t)rc;
    }
    return 0;
}

/* A box of w along the wall and depth d into the room, flush with one of
 * the four inner faces of the room [x0, x1] x [y0, y1] (side 0..3: south,
 * east, north, west) and 0.3 m or more from the room's corners, as
 * cupboards, beds and crates stand: no slot behind it for a beam to look
 * into. The box is checked moved FLUSH_CHECK_M off its wall, so that it may
 * touch that wall but keeps FLUSH_CHECK_M from every other one (and the
 * usual distances from the path and the furniture). 1 added, 0 not, -1 out
 * of memory. */
int layout_against_wall(layout *L, double x0, double y0, double x1, double y1, double w,
                        double d)
{
    uint32_t side = upick(&L->rng, 0u, 3u);
    double along, xy[8], check[8], off = 2.0 * FLUSH_CHECK_M;
    if (side == 0u || side == 2u) {
        double cy = side == 0u ? y0 + d / 2.0 : y1 - d / 2.0;
        if (x1 - x0 < w + 0.6)
            return 0;
        along = urange(&L->rng, x0 + 0.3 + w / 2.0, x1 - 0.3 - w / 2.0);
        rect_xy(xy, along, cy, w, d, 0.0);
        rect_xy(check, along, side == 0u ? cy + off : cy - off, w, d, 0.0);
    } else {
        double cx = side == 3u ? x0 + d / 2.0 : x1 - d / 2.0;
        if (y1 - y0 < w + 0.6)
            return 0;
        along = urange(&L->rng, y0 + 0.3 + w / 2.0, y1 - 0.3 - w / 2.0);
        rect_xy(xy, cx, along, d, w, 0.0);
        rect_xy(check, side == 3u ? cx + off : cx - off, along, d, w, 0.0);
    }
    return try_add_checked(L, xy, check, 4u, FLUSH_CHECK_M, NULL);
}

/* The smallest distance from the segment ab to any wall. */
static double seg_wall_dist(const scansim_scene *s, const double *a, const double *b)
{
    double m = HUGE_VAL;
    uint32_t w, j;
    for (w = 0; w < s->wall_count; w++) {
        uint32_t nseg = s->walls[w].closed ? s->walls[w].point_count
                                           : s->walls[w].point_count - 1u;
        for (j = 0; j < nseg; j++)
            m = fmin(m, seg_seg_dist(a, b, wall_point(s, w, j), wall_point(s, w, j + 1u)));
    }
    return m;
}

/* People near the path: `walkers` who cross the robot's view in a straight
 * line at walking pace, `standers` who stop in one place for 20-60 scans.
 * Each stays clear of every wall, is in view of the robot when it appears
 * (no wall in between) and never comes within 0.3 m of the robot. Call
 * after the path's poses are laid. -1 out of memory. */
int layout_add_people(layout *L, uint32_t walkers, uint32_t standers)
{
    scansim_scene *s = L->s;
    uint32_t person_index, tries;
    if (s->pose_count < 2u)
        return 0;
    for (person_index = 0; person_index < walkers + standers; person_index++)
        for (tries = 0; tries < PLACE_TRIES; tries++) {
            int stands = person_index >= walkers, ok = 1;
            double len = stands ? 0.0 : urange(&L->rng, 1.5, 4.0);
            /* 1.0-1.5 m/s at 10 scans a second; all of it within the scans */
            uint32_t dur = stands ? upick(&L->rng, 20u, 60u)
                                  : (uint32_t)(len / urange(&L->rng, 0.10, 0.15));
            uint32_t k = dur + 1u < s->pose_count ? upick(&L->rng, 0u, s->pose_count - 1u - dur)
                                                  : 0u, i;
            const scansim_pose *p = &s->poses[k];
            double a = urange(&L->rng, -PI, PI), r = urange(&L->rng, 1.0, 3.0);
            double from[2], to[2], heading;
            scansim_person person;
            from[0] = p->x_m + r * cos(a);
            from[1] = p->y_m + r * sin(a);
            heading = urange(&L->rng, -PI, PI);
            to[0] = from[0] + len * cos(heading);
            to[1] = from[1] + len * sin(heading);
            memset(&person, 0, sizeof person);
            person.from_x_m = from[0];
            person.from_y_m = from[1];
            person.to_x_m = to[0];
            person.to_y_m = to[1];
            person.radius_m = PERSON_RADIUS_M;
            person.first_scan = k;
            person.last_scan = k + dur < s->pose_count ? k + dur : s->pose_count - 1u;
            if (seg_wall_dist(s, from, to) < PERSON_RADIUS_M + 0.05 ||
                scansim_cast(s, p->x_m, p->y_m, a, UINT32_MAX, NULL) < r)
                continue;
            for (i = 0; i < s->wall_count && ok; i++)
                ok = i == L->outline || !s->walls[i].closed ||
                     !point_in_poly(&s->wall_xy_m[2u * s->walls[i].first_point],
                                    s->walls[i].point_count, from[0], from[1]);
            for (i = person.first_scan; i <= person.last_scan && ok; i++) {
                double f = person.last_scan > person.first_scan
                               ? (double)(i - person.first_scan) /
                                     (double)(person.last_scan - person.first_scan)
                               : 0.0;
                ok = hypot(from[0] + (to[0] - from[0]) * f - s->poses[i].x_m,
                           from[1] + (to[1] - from[1]) * f - s->poses[i].y_m) >=
                     PERSON_RADIUS_M + 0.3;
            }
            if (!ok)
                continue;
            if (scansim_add_person(s, &person) != 0)
                return -1;
            break;
        }
    return 0;
}

/* Lays the poses along the waypoints, about `target` of them (spacing kept
 * within 5-20 cm). */
int layout_path(layout *L, double target)
{
    double len = 0.0, spacing;
    uint32_t i;
    for (i = 0; i + 1u < L->way_count; i++)
        len += hypot(L->way[2u * i + 2u] - L->way[2u * i],
                     L->way[2u * i + 3u] - L->way[2u * i + 1u]);
    spacing = fmin(0.20, fmax(0.05, len / target));
    return scansim_add_path(L->s, L->way, L->way_count, spacing);
}

/* Turns the scene by a random angle and shifts it by up to 10 m. */
void layout_place_anywhere(layout *L)
{
    double a = urange(&L->rng, 0.0, 2.0 * PI);
    double dx = urange(&L->rng, -10.0, 10.0), dy = urange(&L->rng, -10.0, 10.0);
    scansim_transform(L->s, a, dx, dy);
}

int layout_finish(layout *L, int rc, uint32_t walkers, uint32_t standers)
{
    rc |= layout_add_people(L, walkers, standers);
    if (rc != 0)
        return -1;
    layout_place_anywhere(L);
    return 0;
}
