/* cost.h - the cost kernel (paper eq. 2): the cost of a weighted point
 * against a segment, as C99 inline functions, so that the loops that call
 * it most (trial evaluation, the books) can inline it; cost.c holds their
 * one external definition (what -Os calls). */
#ifndef POLYC_COST_H
#define POLYC_COST_H

#include "opt_state.h"

/* Sum of squared distances of a weighted point's endpoints to segment a-b,
 * all of them taken to fall in the region (interior or end) of their mean. */
inline float polyc__cost(const polyc__point *p, float ax, float ay, float bx, float by)
{
    float dx = (float)bx - (float)ax, dy = (float)by - (float)ay;
    float mx = (float)p->x - (float)ax, my = (float)p->y - (float)ay;
    float l2 = dx * dx + dy * dy;
    float trace = (float)p->cxx + (float)p->cyy;
    float t = l2 > 1e-18f ? (mx * dx + my * dy) / l2 : 0.0f;
    if (t <= 0.0f)
        return (float)p->w * (mx * mx + my * my) + trace;
    if (t >= 1.0f) {
        float ex = (float)p->x - (float)bx, ey = (float)p->y - (float)by;
        return (float)p->w * (ex * ex + ey * ey) + trace;
    }
    /* w (n.m)^2 + n'Cn with n = (-dy, dx) / |d|: one division, no root.
     * C, central moments summed in float, can be a rounding error short of
     * positive semi-definite (cxy^2 > cxx cyy): n'Cn then dips below 0 for
     * a point whose endpoints lie on a line, and a map's error could be
     * -1e-12 (found by fuzz_library). A sum of squares is never negative. */
    float cross = dx * my - dy * mx;
    float c = ((float)p->w * cross * cross + dy * dy * (float)p->cxx -
                2.0f * dx * dy * (float)p->cxy + dx * dx * (float)p->cyy) / l2;
    return c > 0.0f ? c : 0.0f;
}

/* a point's cost when no segment is within the search radius: w R^2 */
inline float polyc__point_cap(const polyc__opt *o, const polyc__point *p)
{
    return (float)p->w * (float)o->R2;
}

inline float polyc__cost_seg(const polyc__opt *o, const polyc__point *p, int32_t seg)
{
    const polyc__vertex *a = &o->s->v[seg];
    const polyc__vertex *b = &o->s->v[a->next];
    return polyc__cost(p, a->x, a->y, b->x, b->y);
}

/* cost.c: the turn at b, in [0, pi], of the path a -> b -> c */
float polyc__turn_of(float ax, float ay, float bx, float by, float cx, float cy);
/* cost.c: the angle term of a vertex b on the path a -> b -> c, 1 - p(turn
 * at b); the same at vertex v of the map (open ends: 0) */
float polyc__turn_cost(const polyc__opt *o, float ax, float ay, float bx, float by, float cx,
                        float cy);
float polyc__vertex_angle_cost(const polyc__opt *o, int32_t v);

/* The nearest segment costing less than `start`, skipping `skip` (NONE
 * and `start` if there is none). */
float polyc__nearest_below(const polyc__opt *o, int32_t pi, const int32_t *skip, int n_skip,
                            float start, int32_t *seg);

/* checks.c, with -DPOLYC_CHECKS: invariants, NULL when they hold, else
 * the first violation (*at: its point, vertex, line or bucket, -1 none) */
#ifdef POLYC_CHECKS
const char *polyc__check_arena(const polyc__arena *a);
const char *polyc__check_store(const polyc__store *s, int32_t *at);
const char *polyc__check_hash(polyc__opt *o, int32_t *at);
const char *polyc__check_books(const polyc__opt *o, int32_t *at);
const char *polyc__check_point_order(const polyc__opt *o, int32_t *at);
/* the cheap ones (arena, store, hash, the points' order), asserted after
 * each iteration */
void polyc__checks_iteration(polyc__opt *o);
#define POLYC__CHECKS_ITERATION(o) polyc__checks_iteration(o)
#else
#define POLYC__CHECKS_ITERATION(o) ((void)0)
#endif

#endif
