/* scan_chains.h - a single scan's chains (scan_chains.c) and their
 * simplification (chain_simplify.c): the working state they share. */
#ifndef POLYC_SCAN_CHAINS_H
#define POLYC_SCAN_CHAINS_H

#include "context.h"

typedef struct chains {
    polyc_ctx *ctx;
    float *xy;                 /* every beam's endpoint; NaN without a hit */
    const float *range;        /* every beam's range (in the order the chains take them) */
    float *turned;             /* a full turn's ranges from its seam (range points here) */
    uint8_t *chain_of;         /* per beam: its chain's slot, 0 none */
    uint8_t cur;               /* the slot of the chain being emitted */
    uint8_t *keep;             /* per beam: a vertex of the simplified chain */
    float *cost;               /* per kept inner vertex: the BIC change of dropping it */
    float ox, oy;              /* the scan's origin */
    float step;                /* |angle step| */
    float tol;                 /* simplification tolerance */
    float alpha, log_n;        /* the BIC's weight of the error; log of the returns */
} chains;

inline float polyc__seg_dist2f(const float *p, const float *a, const float *b)
{
    float dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
    float t = l2 > 0.0f ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2 : 0.0f;
    t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    float ex = a[0] + t * dx - p[0], ey = a[1] + t * dy - p[1];
    return ex * ex + ey * ey;
}

inline int polyc__chain_has_point(const chains *c, int32_t i)
{
    return c->xy[2 * i] == c->xy[2 * i];
}

/* beam i has a hit of the chain being emitted */
inline int polyc__chain_member(const chains *c, int32_t i)
{
    return c->chain_of[i] == c->cur;
}

/* Douglas-Peucker over the hits of beams [a, b] into c->keep, then the
 * kept vertices removed bottom-up while the BIC falls (chain_simplify.c) */
void polyc__chain_simplify(chains *c, int32_t a, int32_t b);
void polyc__chain_merge_spans(chains *c, int32_t a, int32_t b);

#endif
