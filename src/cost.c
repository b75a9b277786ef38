/* cost.c - the BIC (paper eqs. 2, 3, 5) from scratch: the cost of a point
 * against a segment, the angle term of a vertex, the BIC of the model, and
 * the model's terms rebuilt (every point assigned its nearest segment).
 * Takes: data points, polylines, the spatial hash, the angle prior. Gives:
 * the model's error and angle terms. */
#include "cost.h"

#include <math.h>

/* the external definitions of cost.h's inline functions (C99: used
 * where a caller does not inline them, as at -Os) */
extern inline float polyc__cost(const polyc__point *p, float ax, float ay, float bx, float by);
extern inline float polyc__point_cap(const polyc__opt *o, const polyc__point *p);
extern inline float polyc__cost_seg(const polyc__opt *o, const polyc__point *p, int32_t seg);

/* 1 - p(turn | x, y) at v; open ends have no angle. */
float polyc__vertex_angle_cost(const polyc__opt *o, int32_t v)
{
    if (o->cfg->gamma <= 0.0f)
        return 0.0f;
    const polyc__vertex *c = &o->s->v[v];
    if (c->prev == POLYC__NONE || c->next == POLYC__NONE)
        return 0.0f;
    const polyc__vertex *a = &o->s->v[c->prev], *b = &o->s->v[c->next];
    return polyc__turn_cost(o, a->x, a->y, c->x, c->y, b->x, b->y);
}

float polyc__bic(const polyc__opt *o)
{
    return o->cfg->alpha * (polyc__ksum_get(&o->err) + o->cfg->gamma * polyc__ksum_get(&o->angle)) +
           (float)o->s->v_live * o->d.log_n;
}

float polyc__err(const polyc__opt *o)
{
    return polyc__ksum_get(&o->err);
}

polyc_status polyc__rebuild(polyc__opt *o)
{
    polyc__store *s = o->s;
    polyc__hash_clear(o);
    o->angle = (polyc__ksum){0.0f, 0.0f};
    for (int32_t v = 0; v < s->v_high; v++) {
        o->acost[v] = 0.0f;
        if (s->v[v].line == POLYC__NONE)
            continue;
        if (s->v[v].next != POLYC__NONE && !polyc__hash_insert(o, v))
            return polyc__fail(o->ctx, POLYC_ERR_NOMEM, "spatial hash full");
        o->acost[v] = polyc__vertex_angle_cost(o, v);
        polyc__ksum_add(&o->angle, o->acost[v]);
    }
    o->err = (polyc__ksum){0.0f, 0.0f};
    for (int32_t i = 0; i < o->d.np; i++) {
        o->d.pt_cost[i] = polyc__nearest(o, i, NULL, 0, &o->d.pt_seg[i]);
        polyc__ksum_add(&o->err, o->d.pt_cost[i]);
    }
    return POLYC_OK;
}
