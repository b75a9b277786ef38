/* round.h - what the round things share (circles.c, arcs.c): the buckets
 * round a box of the map and their points, and a point's cost across a
 * circle. */
#ifndef POLYC_ROUND_H
#define POLYC_ROUND_H

#include "../cost.h"

#include <math.h>

/* The buckets that hold the points of a piece of map inside a box: the
 * box, the search radius R wider. */
typedef struct polyc__bucket_box {
    int32_t x0, y0, x1, y1;
} polyc__bucket_box;

static inline polyc__bucket_box polyc__box_buckets(const polyc__opt *o, float lo_x, float lo_y,
                                                   float hi_x, float hi_y)
{
    polyc__bucket_box bb;
    polyc__bucket_xy(&o->h, lo_x - o->R, lo_y - o->R, &bb.x0, &bb.y0);
    polyc__bucket_xy(&o->h, hi_x + o->R, hi_y + o->R, &bb.x1, &bb.y1);
    return bb;
}

/* Every point i in the buckets of bb (points are stored sorted by bucket). */
#define POLYC__FOR_BOX_POINTS(o, bb, i)                                                          \
    for (int32_t i##_y = (bb).y0; i##_y <= (bb).y1; i##_y++)                                      \
        for (int32_t i##_x = (bb).x0; i##_x <= (bb).x1; i##_x++)                                  \
            for (uint32_t i = (o)->h.pt_start[i##_y * (o)->h.bx + i##_x];                         \
                 i < (o)->h.pt_start[i##_y * (o)->h.bx + i##_x + 1]; i++)

/* A point's cost against the circle of radius r about (cx, cy): its
 * endpoints' squared distances across the circle at their mean (the
 * tangent there stands for the curve over a cell), not capped. */
static inline float polyc__ring_cost(const polyc__point *p, float cx, float cy, float r)
{
    float dx = p->x - cx, dy = p->y - cy, d = sqrtf(dx * dx + dy * dy), c;
    if (d < 1e-9f) {
        c = p->w * r * r + p->cxx + p->cyy;
    } else {
        float nx = dx / d, ny = dy / d, e = d - r;
        c = p->w * e * e + nx * nx * p->cxx + 2.0f * nx * ny * p->cxy + ny * ny * p->cyy;
    }
    return c > 0.0f ? c : 0.0f;
}

#endif /* POLYC_ROUND_H */
