/* scansim_round.c - the simulator's kinds with round things (scansim.h):
 * pillars, arcwalls, roundmix. Their curves are true arcs and circles,
 * drawn as polygons whose sides stray at most SCANSIM_ARC_SAGITTA_M (0.1
 * mm) from them and whose points are smooth (scansim_add_wall_smooth), so
 * that the ground truth counts an arc as one piece and a circle as one
 * circle (scansim_ideal_params). Sizes and places are drawn from the seed:
 * the radii over the ranges round things have in buildings. */
#include "scansim_layout.h"

#include <stdlib.h>
#include <string.h>

#define MAX_RING 4096u       /* points of one wall */

/* A closed circle of radius r about (cx, cy), its points smooth, if it
 * fits the layout (layout_try_add's rule, gap_m from the structure);
 * 1 added, 0 not, -1 out of memory. */
static int try_add_circle(layout *L, double cx, double cy, double r, double gap_m)
{
    double *xy = malloc(2u * MAX_RING * sizeof *xy);
    uint8_t *smooth = malloc(MAX_RING);
    uint32_t n;
    int rc;
    if (!xy || !smooth) {
        free(xy);
        free(smooth);
        return -1;
    }
    /* the closing point would repeat the first */
    n = scansim_arc_points(xy, MAX_RING, cx, cy, r, 0.0, 2.0 * PI) - 1u;
    memset(smooth, 1, n);
    rc = layout_try_add_smooth(L, xy, n, gap_m, smooth);
    free(xy);
    free(smooth);
    return rc;
}

/* The outline of a w x h room whose sides (south, east, north, west) in
 * `arc_sides` (bit k: side k) are arcs of radius radius[k] through the two
 * corners, bulging out (bulge[k] > 0) or in; corners are corners, the
 * arcs' inner points smooth. Returns the number of points written. */
static uint32_t room_outline(double *xy, uint8_t *smooth, uint32_t max, double w, double h,
                             unsigned arc_sides, const double *radius, const double *bulge)
{
    const double corner[8] = {0.0, 0.0, w, 0.0, w, h, 0.0, h};
    uint32_t n = 0, k;
    for (k = 0; k < 4u; k++) {
        const double *a = &corner[2u * k], *b = &corner[2u * ((k + 1u) % 4u)];
        if (n + 1u > max)
            break;
        xy[2u * n] = a[0];
        xy[2u * n + 1u] = a[1];
        smooth[n++] = 0;
        if (!((arc_sides >> k) & 1u))
            continue;
        {
            /* the arc's centre lies on the side's normal, on the side away
             * from the bulge; the room's inside is to the left of a -> b */
            double mx = 0.5 * (a[0] + b[0]), my = 0.5 * (a[1] + b[1]);
            double len = hypot(b[0] - a[0], b[1] - a[1]), r = radius[k];
            double nx = -(b[1] - a[1]) / len, ny = (b[0] - a[0]) / len; /* inward */
            double off = sqrt(fmax(0.0, r * r - 0.25 * len * len)), sign = bulge[k] > 0.0 ? 1.0 : -1.0;
            double cx = mx + sign * nx * off, cy = my + sign * ny * off;
            double a0 = atan2(a[1] - cy, a[0] - cx), a1 = atan2(b[1] - cy, b[0] - cx);
            double pts[2u * 1024u];
            uint32_t m, j;
            /* the short way round from a to b */
            while (a1 - a0 > PI)
                a1 -= 2.0 * PI;
            while (a0 - a1 > PI)
                a1 += 2.0 * PI;
            m = scansim_arc_points(pts, 1024u, cx, cy, r, a0, a1);
            for (j = 1; j + 1u < m && n < max; j++) {
                xy[2u * n] = pts[2u * j];
                xy[2u * n + 1u] = pts[2u * j + 1u];
                smooth[n++] = 1;
            }
        }
    }
    return n;
}

/* The sagitta of an arc of radius r over a chord of len. */
static double sagitta(double r, double len)
{
    return r - sqrt(fmax(0.0, r * r - 0.25 * len * len));
}

/* A room of w x h whose sides in arc_sides are arcs of radius 2-20 m (or
 * more when the side is longer than the smallest arc's chord), bulging out,
 * or in by at most max_in metres; the robot's loop keeps `inset` from the
 * sides plus what an inward arc takes. Adds the outline and the loop. */
static int arc_room(layout *L, double w, double h, unsigned arc_sides, double max_in,
                    double inset, double target_poses)
{
    double radius[4], bulge[4], in[4] = {0.0, 0.0, 0.0, 0.0};
    double *xy = malloc(2u * MAX_RING * sizeof *xy);
    uint8_t *smooth = malloc(MAX_RING);
    uint32_t k, n;
    int rc = 0;
    if (!xy || !smooth) {
        free(xy);
        free(smooth);
        return -1;
    }
    for (k = 0; k < 4u; k++) {
        double len = k % 2u ? h : w;
        radius[k] = fmax(urange(&L->rng, 2.0, 20.0), 0.5 * len + 0.5);
        bulge[k] = scansim_rng_uniform(&L->rng) < 0.6 ? 1.0 : -1.0;
        if (bulge[k] < 0.0 && sagitta(radius[k], len) > max_in)
            bulge[k] = 1.0;
        if (((arc_sides >> k) & 1u) && bulge[k] < 0.0)
            in[k] = sagitta(radius[k], len);
    }
    n = room_outline(xy, smooth, MAX_RING, w, h, arc_sides, radius, bulge);
    L->outline = L->s->wall_count;
    rc |= scansim_add_wall_smooth(L->s, xy, n, 1, smooth);
    layout_way(L, inset + in[3], inset + in[0]);
    layout_way(L, w - inset - in[1], inset + in[0]);
    layout_way(L, w - inset - in[1], h - inset - in[2]);
    layout_way(L, inset + in[3], h - inset - in[2]);
    layout_way(L, inset + in[3], inset + in[0] + 0.2);
    rc |= layout_path(L, target_poses);
    free(xy);
    free(smooth);
    return rc;
}

/* Round pillars of radius r_lo-r_hi at random places in the room's inner
 * [x0, x1] x [y0, y1], up to `count`. */
static int scatter_pillars(layout *L, uint32_t count, double r_lo, double r_hi, double x0,
                           double y0, double x1, double y1)
{
    uint32_t placed = 0, tries;
    if (L->first_object == UINT32_MAX)
        L->first_object = L->s->wall_count;
    for (tries = 0; placed < count && tries < PLACE_TRIES; tries++) {
        double r = urange(&L->rng, r_lo, r_hi);
        int got = try_add_circle(L, urange(&L->rng, x0 + r, x1 - r), urange(&L->rng, y0 + r, y1 - r),
                                 r, 0.8);
        if (got < 0)
            return -1;
        placed += (uint32_t)got;
    }
    return 0;
}

static void round_laser(scansim_scene *s, float range_m)
{
    s->laser.beam_count = 361u;
    s->laser.angle_step_rad = (float)(PI / 360.0);
    s->laser.max_range_m = range_m;
}

/* ---- pillars ------------------------------------------------------------------- */

/* A 14-28 m x 10-20 m hall of straight walls with 5-12 round pillars of
 * 10-60 cm radius wherever the robot's loop leaves room, seen by a 20 m,
 * 361-beam scanner; a few people. */
int scansim_kind_pillars(scansim_scene *s)
{
    layout L;
    double w, h, inset;
    int rc;
    layout_init(&L, s, UINT64_C(0x70696c6c));
    round_laser(s, 20.0f);
    w = urange(&L.rng, 14.0, 28.0);
    h = urange(&L.rng, 10.0, 20.0);
    inset = urange(&L.rng, 2.5, 4.0);
    rc = arc_room(&L, w, h, 0u, 0.0, inset, 600.0);
    rc |= scatter_pillars(&L, upick(&L.rng, 5u, 12u), 0.10, 0.60, 1.0, 1.0, w - 1.0, h - 1.0);
    return layout_finish(&L, rc, 2u, 1u);
}

/* ---- arcwalls ------------------------------------------------------------------ */

/* A 8-16 m x 6-12 m room, one to four of whose sides are arcs of 2-20 m
 * radius (bulging out, or in by up to 1.2 m), seen by a 15 m scanner;
 * sometimes a round column, a few boxes. */
int scansim_kind_arcwalls(scansim_scene *s)
{
    layout L;
    double w, h;
    unsigned sides = 0;
    int rc;
    layout_init(&L, s, UINT64_C(0x61726377));
    round_laser(s, 15.0f);
    w = urange(&L.rng, 8.0, 16.0);
    h = urange(&L.rng, 6.0, 12.0);
    while (sides == 0)
        sides = (unsigned)upick(&L.rng, 0u, 15u);
    rc = arc_room(&L, w, h, sides, 1.2, 1.6, 450.0);
    if (scansim_rng_uniform(&L.rng) < 0.5)
        rc |= scatter_pillars(&L, 1u, 0.15, 0.5, 1.0, 1.0, w - 1.0, h - 1.0);
    {
        static const double fw[2] = {0.6, 1.8}, fh[2] = {0.5, 0.9};
        rc |= layout_scatter_boxes(&L, upick(&L.rng, 1u, 3u), fw, fh, -1.0, 0.5, 0.5, w - 0.5,
                                   h - 0.5, 0.3);
    }
    return layout_finish(&L, rc, 1u, 1u);
}

/* ---- roundmix ------------------------------------------------------------------ */

/* A 12-22 m x 8-16 m room, one of whose sides is an arc of 2-20 m radius,
 * with 2-5 round pillars of 10-60 cm radius among 3-7 boxes and cupboards:
 * round things among straight ones. */
int scansim_kind_roundmix(scansim_scene *s)
{
    layout L;
    double w, h;
    int rc;
    layout_init(&L, s, UINT64_C(0x726d6978));
    round_laser(s, 20.0f);
    w = urange(&L.rng, 12.0, 22.0);
    h = urange(&L.rng, 8.0, 16.0);
    rc = arc_room(&L, w, h, 1u << upick(&L.rng, 0u, 3u), 1.0, urange(&L.rng, 2.0, 3.0), 550.0);
    rc |= scatter_pillars(&L, upick(&L.rng, 2u, 5u), 0.10, 0.60, 1.0, 1.0, w - 1.0, h - 1.0);
    {
        static const double fw[2] = {0.6, 2.0}, fh[2] = {0.4, 1.0};
        uint32_t k, n = upick(&L.rng, 1u, 3u);
        rc |= layout_scatter_boxes(&L, upick(&L.rng, 2u, 4u), fw, fh, -1.0, 0.5, 0.5, w - 0.5,
                                   h - 0.5, 0.3);
        for (k = 0; k < n && rc == 0; k++)
            rc |= layout_against_wall(&L, 0.0, 0.0, w, h, urange(&L.rng, 0.8, 2.0),
                                      urange(&L.rng, 0.4, 0.7)) < 0;
    }
    return layout_finish(&L, rc, 1u, 1u);
}
