/* trial.h - what the trial evaluation (trial.c) and the bounded removal
 * delta (delta.c) share: a segment prepared for many
 * cost queries (the same value as polyc__cost without its divisions) and the
 * set of segments an edit takes out. */
#ifndef POLYC_TRIAL_H
#define POLYC_TRIAL_H

#include "cost.h"

#include <math.h>

inline void polyc__seg_prepare(polyc__seg_pre *q, const float *xy)
{
    q->ax = (float)xy[0];
    q->ay = (float)xy[1];
    q->bx = (float)xy[2];
    q->by = (float)xy[3];
    q->dx = q->bx - q->ax;
    q->dy = q->by - q->ay;
    float l2 = q->dx * q->dx + q->dy * q->dy;
    q->inv_l2 = l2 > 1e-18f ? 1.0f / l2 : 0.0f;
    float inv = l2 > 1e-18f ? 1.0f / sqrtf(l2) : 0.0f;
    q->nx = -q->dy * inv;
    q->ny = q->dx * inv;
}

/* Same value as polyc__cost, without the per-call divisions. */
inline float polyc__seg_pre_cost(const polyc__seg_pre *q, const polyc__point *p)
{
    float mx = (float)p->x - q->ax, my = (float)p->y - q->ay;
    float t = (mx * q->dx + my * q->dy) * q->inv_l2;
    if (t <= 0.0f || q->inv_l2 == 0.0f)
        return (float)p->w * (mx * mx + my * my) + ((float)p->cxx + (float)p->cyy);
    if (t >= 1.0f) {
        float ex = (float)p->x - q->bx, ey = (float)p->y - q->by;
        return (float)p->w * (ex * ex + ey * ey) + ((float)p->cxx + (float)p->cyy);
    }
    float d = q->nx * mx + q->ny * my;
    float c = (float)p->w * d * d + (q->nx * q->nx * (float)p->cxx +
                                       2.0f * q->nx * q->ny * (float)p->cxy +
                                       q->ny * q->ny * (float)p->cyy);
    return c > 0.0f ? c : 0.0f; /* as polyc__cost */
}


typedef struct polyc__old_set {
    int32_t a, b;
    const int32_t *rest;
    int n_rest;
} polyc__old_set;

inline polyc__old_set polyc__old_set_of(const int32_t *old, int n_old)
{
    polyc__old_set s;
    s.a = n_old > 0 ? old[0] : POLYC__NONE;
    s.b = n_old > 1 ? old[1] : POLYC__NONE;
    s.rest = n_old > 2 ? old + 2 : old; /* never past the caller's array */
    s.n_rest = n_old > 2 ? n_old - 2 : 0;
    return s;
}

/* whether the point's segment seg (NONE: none) is one of them */
inline int polyc__is_old(const polyc__old_set *s, int32_t seg)
{
    if (seg == POLYC__NONE)
        return 0;
    int hit = seg == s->a || seg == s->b;
    for (int j = 0; j < s->n_rest; j++)
        hit |= seg == s->rest[j];
    return hit;
}

#endif
