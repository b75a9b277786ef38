/* cost.h - the cost kernel (paper eq. 2): the cost of a weighted point
 * against a segment, as C99 inline functions, so that the loops that call
 * it most (trial evaluation, the books) can inline it; cost.c holds their
 * one external definition (what -Os calls). */
#ifndef POLYC_COST_H
#define POLYC_COST_H

#include "optimize.h"

/* Sum of squared distances of a weighted point's endpoints to segment a-b,
 * all of them taken to fall in the region (interior or end) of their mean. */
inline double polyc__cost(const polyc__point *p, float ax, float ay, float bx, float by)
{
    double dx = (double)bx - (double)ax, dy = (double)by - (double)ay;
    double mx = (double)p->x - (double)ax, my = (double)p->y - (double)ay;
    double l2 = dx * dx + dy * dy;
    double trace = (double)p->cxx + (double)p->cyy;
    double t = l2 > 1e-18 ? (mx * dx + my * dy) / l2 : 0.0;
    if (t <= 0.0)
        return (double)p->w * (mx * mx + my * my) + trace;
    if (t >= 1.0) {
        double ex = (double)p->x - (double)bx, ey = (double)p->y - (double)by;
        return (double)p->w * (ex * ex + ey * ey) + trace;
    }
    /* w (n.m)^2 + n'Cn with n = (-dy, dx) / |d|: one division, no root.
     * C, central moments summed in float, can be a rounding error short of
     * positive semi-definite (cxy^2 > cxx cyy): n'Cn then dips below 0 for
     * a point whose endpoints lie on a line, and a map's error could be
     * -1e-12 (found by fuzz_library). A sum of squares is never negative. */
    double cross = dx * my - dy * mx;
    double c = ((double)p->w * cross * cross + dy * dy * (double)p->cxx -
                2.0 * dx * dy * (double)p->cxy + dx * dx * (double)p->cyy) / l2;
    return c > 0.0 ? c : 0.0;
}

/* a point's cost when no segment is within the search radius: w R^2 */
inline double polyc__point_cap(const polyc__opt *o, const polyc__point *p)
{
    return (double)p->w * (double)o->R2;
}

inline double polyc__cost_seg(const polyc__opt *o, const polyc__point *p, int32_t seg)
{
    const polyc__vertex *a = &o->s->v[seg];
    const polyc__vertex *b = &o->s->v[a->next];
    return polyc__cost(p, a->x, a->y, b->x, b->y);
}

/* checks.c, with -DPOLYC_CHECKS: invariants, NULL when they hold, else
 * the first violation (*at: its point, vertex, line or bucket, -1 none) */
#ifdef POLYC_CHECKS
const char *polyc__check_arena(const polyc__arena *a);
const char *polyc__check_store(const polyc__store *s, int32_t *at);
const char *polyc__check_hash(polyc__opt *o, int32_t *at);
const char *polyc__check_books(const polyc__opt *o, int32_t *at);
/* the cheap ones (arena, store, hash), asserted after each iteration */
void polyc__checks_iteration(polyc__opt *o);
#define POLYC__CHECKS_ITERATION(o) polyc__checks_iteration(o)
#else
#define POLYC__CHECKS_ITERATION(o) ((void)0)
#endif

#endif
