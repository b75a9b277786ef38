/* corners.c - corners (an operator this library adds to the paper's).
 * Takes: the optimiser state. Gives: short runs of vertices between two
 * segments (spikes, little steps where two walls meet) replaced by one
 * vertex where the lines of the two segments intersect, when that lowers
 * the BIC. Hill climbing cannot get there: every single step is uphill. */
#include "../cost.h"

#include <math.h>

#define CHAIN_MAX 3        /* vertices between the two segments, at most */
#define REACH_M 0.30f      /* the corner lies this close to the chain's ends */

/* Intersection of lines a-b and c-d; 0 if (nearly) parallel. */
static int intersect(const polyc__vertex *a, const polyc__vertex *b, const polyc__vertex *c,
                     const polyc__vertex *d, float *x, float *y)
{
    float rx = b->x - a->x, ry = b->y - a->y, sx = d->x - c->x, sy = d->y - c->y;
    float den = rx * sy - ry * sx;
    float lr = sqrtf(rx * rx + ry * ry), ls = sqrtf(sx * sx + sy * sy);
    if (fabsf(den) < POLYC__CORNER_SIN * lr * ls) /* less than 10 degrees apart */
        return 0;
    float t = ((c->x - a->x) * sy - (c->y - a->y) * sx) / den;
    *x = a->x + t * rx;
    *y = a->y + t * ry;
    return 1;
}

static float dist(float x, float y, const polyc__vertex *v)
{
    return sqrtf((x - v->x) * (x - v->x) + (y - v->y) * (y - v->y));
}

/* Tries the corner for the chain b .. c (k interior links) between segments
 * a-b and c-d; applies it when the BIC falls. */
static int try_corner(polyc__opt *o, int32_t b, int32_t c, int k)
{
    const polyc__vertex *V = o->s->v;
    int32_t a = V[b].prev, d = V[c].next;
    if (a == POLYC__NONE || d == POLYC__NONE || a == c || d == b || a == d)
        return 0;
    float x, y;
    if (!intersect(&V[a], &V[b], &V[c], &V[d], &x, &y))
        return 0;
    if (dist(x, y, &V[b]) > REACH_M || dist(x, y, &V[c]) > REACH_M)
        return 0;
    int32_t old[CHAIN_MAX + 3];
    int n_old = 0;
    old[n_old++] = a;
    for (int32_t v = b; v != d; v = V[v].next)
        old[n_old++] = v;
    float xy[8] = {V[a].x, V[a].y, x, y, x, y, V[d].x, V[d].y};
    polyc__local_prepare(o, old, n_old, xy, 2, 0.0f);
    float derr = polyc__local_eval(o, xy, 2) - polyc__local_current(o);
    float gamma = (float)o->cfg->gamma, dangle = 0.0f;
    if (gamma > 0.0f) {
        for (int32_t v = a; v != V[d].next && v != POLYC__NONE; v = V[v].next)
            dangle -= o->acost[v];
        int32_t pa = V[a].prev, nd = V[d].next;
        if (pa != POLYC__NONE && pa != d)
            dangle += polyc__turn_cost(o, V[pa].x, V[pa].y, V[a].x, V[a].y, x, y);
        dangle += polyc__turn_cost(o, V[a].x, V[a].y, x, y, V[d].x, V[d].y);
        if (nd != POLYC__NONE && nd != a)
            dangle += polyc__turn_cost(o, x, y, V[d].x, V[d].y, V[nd].x, V[nd].y);
    }
    float dbic = (float)o->cfg->alpha * (derr + gamma * dangle) - (float)k * o->d.log_n;
    if (dbic >= 0.0f)
        return 0;
    float old_xy[4 * POLYC__EDIT_SEGS];
    int n_xy = polyc__edit_segments(o, old, n_old, old_xy);
    if (polyc__blocks_beams(&o->rays, V[a].x, V[a].y, x, y, old_xy, n_xy) ||
        polyc__blocks_beams(&o->rays, x, y, V[d].x, V[d].y, old_xy, n_xy) ||
        polyc__loses_returns(&o->rays, old_xy, n_xy, xy, 2))
        return 0;
    polyc__chg_begin(o);
    polyc__op_move(o, b, x, y);
    while (o->s->v[b].next != d)
        polyc__op_remove(o, o->s->v[b].next);
    polyc__chg_commit(o);
    return 1;
}

/* Candidates: chains starting at a vertex edited at or after touch stamp
 * `since` (0: all). */
int polyc__op_corners(polyc__opt *o, uint32_t since)
{
    int changed = 0;
    for (int32_t b = 0; b < o->s->v_high; b++) {
        if (o->v_touch[b] < since)
            continue;
        for (int k = 1; k <= CHAIN_MAX; k++) { /* (k = 0 would be b itself) */
            if (o->s->v[b].line == POLYC__NONE || o->s->l[o->s->v[b].line].count < CHAIN_MAX + 4)
                break;
            int32_t c = b;
            for (int j = 0; j < k && c != POLYC__NONE; j++)
                c = o->s->v[c].next;
            if (c == POLYC__NONE)
                break;
            if (try_corner(o, b, c, k)) {
                changed++;
                break;
            }
        }
    }
    return changed;
}
