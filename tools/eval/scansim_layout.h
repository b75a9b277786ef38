/* scansim_layout.h - what the simulator's randomised scene kinds share
 * (scansim_kinds.c): a layout under construction (walls, path, furniture
 * and people placed by rejection, scansim_layout.c) and small geometry. */
#ifndef SCANSIM_LAYOUT_H
#define SCANSIM_LAYOUT_H

#include <math.h>
#include <stdint.h>

#include "scansim.h"

#define PI 3.14159265358979323846
#define PATH_CLEAR_M 0.5     /* furniture keeps this far from the path */
#define OBJECT_GAP_M 0.3     /* and this far from other furniture */
#define FLUSH_CHECK_M 0.01  /* a piece flush with a wall keeps this off the others */
#define ARC_STEP_M 0.10      /* side of the polygons that stand for curves */
#define PLACE_TRIES 400u
#define MAX_WAY 256u         /* waypoints of one path */
#define PERSON_RADIUS_M 0.2

typedef struct layout {
    scansim_scene *s;
    scansim_rng rng;
    double way[2u * MAX_WAY];  /* the path's waypoints */
    uint32_t way_count;
    uint32_t outline;          /* a closed wall round everything, or UINT32_MAX */
    uint32_t first_object;     /* walls from here on are furniture */
} layout;

static inline double urange(scansim_rng *rng, double lo, double hi)
{
    return lo + (hi - lo) * scansim_rng_uniform(rng);
}

/* An integer in lo..hi. */
static inline uint32_t upick(scansim_rng *rng, uint32_t lo, uint32_t hi)
{
    return lo + (uint32_t)(scansim_rng_u64(rng) % (uint64_t)(hi - lo + 1u));
}

/* A w x h rectangle centred on (cx, cy), its w side at angle a. */
static inline void rect_xy(double *xy, double cx, double cy, double w, double h, double a)
{
    static const double sx[4] = {-0.5, 0.5, 0.5, -0.5}, sy[4] = {-0.5, -0.5, 0.5, 0.5};
    double c = cos(a), s = sin(a);
    uint32_t i;
    for (i = 0; i < 4u; i++) {
        double u = sx[i] * w, v = sy[i] * h;
        xy[2u * i] = cx + c * u - s * v;
        xy[2u * i + 1u] = cy + s * u + c * v;
    }
}

/* Points every <= ARC_STEP_M on the arc of radius r about (cx, cy) from
 * angle a0 to a1 (either way round), both ends included; returns the count
 * written to xy (at most max). */
static inline uint32_t arc_xy(double *xy, uint32_t max, double cx, double cy, double r,
                              double a0, double a1)
{
    double n = ceil(fabs(a1 - a0) * r / ARC_STEP_M);
    uint32_t count = (uint32_t)(n < 1.0 ? 1.0 : n) + 1u;
    if (count > max)
        count = max;
    scansim_arc_fill(xy, count, cx, cy, r, a0, a1);
    return count;
}

void layout_init(layout *L, scansim_scene *s, uint64_t kind_salt);
void layout_way(layout *L, double x, double y);
int layout_try_add(layout *L, const double *poly, uint32_t n, double gap_m);
/* layout_try_add with the points flagged smooth[] (scansim_add_wall_smooth) */
int layout_try_add_smooth(layout *L, const double *poly, uint32_t n, double gap_m,
                          const uint8_t *smooth);

/* Up to `count` w x h boxes (sizes drawn per box from the ranges) at random
 * places in [x0, x1] x [y0, y1]; angle_rad < 0: any angle. -1 out of memory. */
int layout_scatter_boxes(layout *L, uint32_t count, const double *w_range,
                         const double *h_range, double angle_rad, double x0, double y0,
                         double x1, double y1, double gap_m);

/* A box of w along the wall and depth d into the room, flush with one of
 * the four inner faces of the room [x0, x1] x [y0, y1] (side 0..3: south,
 * east, north, west) and 0.3 m or more from the room's corners, as
 * cupboards, beds and crates stand: no slot behind it for a beam to look
 * into. The box is checked moved FLUSH_CHECK_M off its wall, so that it may
 * touch that wall but keeps FLUSH_CHECK_M from every other one (and the
 * usual distances from the path and the furniture). 1 added, 0 not, -1 out
 * of memory. */
int layout_against_wall(layout *L, double x0, double y0, double x1, double y1, double w,
                        double d);

/* People near the path: `walkers` who cross the robot's view in a straight
 * line at walking pace, `standers` who stop in one place for 20-60 scans.
 * Each stays clear of every wall, is in view of the robot when it appears
 * (no wall in between) and never comes within 0.3 m of the robot. Call
 * after the path's poses are laid. -1 out of memory. */
int layout_add_people(layout *L, uint32_t walkers, uint32_t standers);

/* Lays the poses along the waypoints, about `target` of them (spacing kept
 * within 5-20 cm). */
int layout_path(layout *L, double target);

/* Turns the scene by a random angle and shifts it by up to 10 m. */
void layout_place_anywhere(layout *L);

/* A kind's last steps: its people (layout_add_people), then the whole scene
 * placed anywhere. 0, or -1 if rc (the kind's own result so far) or the
 * people failed (the scene is then not moved). */
int layout_finish(layout *L, int rc, uint32_t walkers, uint32_t standers);

#endif /* SCANSIM_LAYOUT_H */
