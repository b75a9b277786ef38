/* cost.c - the BIC (paper eqs. 2, 3, 5) from scratch: the cost of a point
 * against a segment, the angle term of a vertex, the BIC of the model, and
 * the model's terms rebuilt (every point assigned its nearest segment).
 * Takes: data points, polylines, the spatial hash, the angle prior. Gives:
 * the model's error and angle terms. */
#include "../cost.h"

#include <math.h>

/* the external definitions of cost.h's inline functions (C99: used
 * where a caller does not inline them, as at -Os) */
extern inline float polyc__cost(const polyc__point *p, float ax, float ay, float bx, float by);
extern inline float polyc__point_cap(const polyc__opt *o, const polyc__point *p);
extern inline float polyc__cost_seg(const polyc__opt *o, const polyc__point *p, int32_t seg);

float polyc__turn_of(float ax, float ay, float bx, float by, float cx, float cy)
{
    float ux = bx - ax, uy = by - ay, wx = cx - bx, wy = cy - by;
    return polyc__turn_rad(ux * wy - uy * wx, ux * wx + uy * wy);
}

/* 1 - p(turn at b) for the path a -> b -> c */
float polyc__turn_cost(const polyc__opt *o, float ax, float ay, float bx, float by, float cx, float cy)
{
    return 1.0f - (float)polyc__prior_p(&o->prior, bx, by, polyc__turn_of(ax, ay, bx, by, cx, cy));
}

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

/* The nearest segment costing less than `start` (NONE and `start` if there
 * is none). Own bucket first, then the eight around it nearest first, each
 * only if it is nearer than the best cost so far allows: a segment is
 * entered in every bucket it crosses, so one within distance D of the point
 * crosses a bucket within D of it, and its cost is at least w D^2. */
float polyc__nearest_below(const polyc__opt *o, int32_t pi, const int32_t *skip, int n_skip,
                            float start, int32_t *seg)
{
    static const int8_t ORDER[9][2] = {{0, 0}, {-1, 0}, {1, 0}, {0, -1}, {0, 1},
                                       {-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
    const polyc__hash *h = &o->h;
    const polyc__point *p = &o->d.pts[pi];
    float best = start, w = (float)p->w;
    int32_t best_seg = POLYC__NONE;
    int32_t bx, by;
    polyc__bucket_xy(h, p->x, p->y, &bx, &by);
    /* distances to the bucket's four sides (0 if outside that side) */
    float fx = ((float)p->x - (float)h->origin_x) - (float)bx * (float)h->bucket_m;
    float fy = ((float)p->y - (float)h->origin_y) - (float)by * (float)h->bucket_m;
    float side[2][3];
    side[0][0] = fx > 0.0f ? fx : 0.0f;
    side[0][1] = 0.0f;
    side[0][2] = (float)h->bucket_m - fx > 0.0f ? (float)h->bucket_m - fx : 0.0f;
    side[1][0] = fy > 0.0f ? fy : 0.0f;
    side[1][1] = 0.0f;
    side[1][2] = (float)h->bucket_m - fy > 0.0f ? (float)h->bucket_m - fy : 0.0f;
    float near = side[0][0];
    for (int k = 1; k < 4; k++) {
        float g = side[k >> 1][k & 1 ? 2 : 0];
        near = g < near ? g : near;
    }
    for (int k = 0; k < 9; k++) {
        /* the own bucket done: no neighbour is nearer than its nearest side */
        if (k == 1 && w * near * near >= best)
            break;
        float sx = side[0][ORDER[k][0] + 1], sy = side[1][ORDER[k][1] + 1];
        if (w * (sx * sx + sy * sy) >= best)
            continue;
        int32_t x = bx + ORDER[k][0], y = by + ORDER[k][1];
        if (x < 0 || x >= h->bx || y < 0 || y >= h->by)
            continue;
        for (int32_t e = h->seg_head[y * h->bx + x]; e != POLYC__NONE; e = h->entries[e].next) {
            int32_t sg = h->entries[e].seg;
            int skipped = 0;
            for (int j = 0; j < n_skip; j++)
                skipped |= skip[j] == sg;
            if (skipped)
                continue;
            float c = polyc__cost_seg(o, p, sg);
            if (c < best) {
                best = c;
                best_seg = sg;
            }
        }
    }
    if (seg)
        *seg = best_seg;
    return best;
}

float polyc__nearest(const polyc__opt *o, int32_t pi, const int32_t *skip, int n_skip,
                      int32_t *seg)
{
    return polyc__nearest_below(o, pi, skip, n_skip, polyc__point_cap(o, &o->d.pts[pi]), seg);
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
