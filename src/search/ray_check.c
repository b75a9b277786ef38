/* ray_check.c - one scan's beams as constraints on the map (a departure from
 * the paper, used when the map is built from a single scan).
 * Takes: the context's one scan. Gives: whether a segment would stand in
 * front of some beam's return (where the beam saw through), or behind one
 * of its own returns, by more than the tolerance along the beam. The BIC
 * only sees distances to data points: without this a removal or a merge can
 * bridge a gap that beams passed through, and those beams then meet the map
 * metres short of what they measured; and on a wall seen at a grazing angle
 * a centimetre across the wall is decimetres along the beam. */
#include "../opt_state.h"

#include <math.h>
#include <string.h>

#define TWO_PI 6.283185307179586f

void polyc__rays_init(polyc__rays *rays, const polyc_ctx *ctx)
{
    rays->on = polyc__input_kind(ctx) == POLYC__INPUT_ONE_SCAN;
    if (!rays->on)
        return;
    const polyc__scan *s = &ctx->scans[0];
    rays->x = s->x_m;
    rays->y = s->y_m;
    rays->base = (float)s->theta_rad + (float)s->start_rad;
    rays->step = (float)s->step_rad;
    rays->step_cos = polyc__cosf(rays->step);
    rays->step_sin = polyc__sinf(rays->step);
    rays->count = (int32_t)s->count;
    rays->range = &ctx->ranges[s->first];
    rays->min_m = s->min_m;
    rays->max_m = s->max_m;
    /* beams per turn: indices that far apart are the same direction */
    float per_turn = rays->step != 0.0f ? TWO_PI / fabsf(rays->step) : 0.0f;
    rays->turn = per_turn < 1e9f ? (int32_t)lroundf(per_turn) : 0;
    rays->tol_m = POLYC__RAY_TOLERANCE_M;
    rays->own_m = (float)ctx->cfg.search_radius_m;
}

/* Range along beam direction (c, s) from the origin to segment a-b, or
 * INFINITY if the beam misses it. */
static float range_to(const polyc__rays *rays, float c, float sn, float ax, float ay,
                       float bx, float by)
{
    float ex = bx - ax, ey = by - ay;
    float den = c * ey - sn * ex;
    if (den == 0.0f)
        return INFINITY;
    float qx = ax - rays->x, qy = ay - rays->y;
    float t = (qx * ey - qy * ex) / den;  /* along the beam */
    float u = (qx * sn - qy * c) / den;   /* along the segment */
    return t > 0.0f && u >= 0.0f && u <= 1.0f ? t : (float)INFINITY;
}

/* Where the beam through (px, py) crosses the line of segment a-b, in
 * metres from a along it; `projection` (p's own) if the beam runs nearly
 * parallel to the segment or crosses it far from p. */
float polyc__ray_position(const polyc__rays *rays, float ax, float ay, float bx, float by,
                          float px, float py, float projection)
{
    float ex = (float)bx - (float)ax, ey = (float)by - (float)ay, len = sqrtf(ex * ex + ey * ey);
    float cx = (float)px - rays->x, cy = (float)py - rays->y, r = sqrtf(cx * cx + cy * cy);
    if (len <= 0.0f || r <= 0.0f)
        return projection;
    ex /= len;
    ey /= len;
    float den = cx * ey - cy * ex; /* r sin(incidence) */
    if (fabsf(den) < 0.05f * r)
        return projection;
    float qx = (float)ax - rays->x, qy = (float)ay - rays->y;
    float u = (qx * cy - qy * cx) / den;
    return fabsf(u - (float)projection) <= 0.5f ? (float)u : projection;
}

int polyc__edit_segments(const polyc__opt *o, const int32_t *segs, int n, float *old_xy)
{
    const polyc__vertex *V = o->s->v;
    int k = 0;
    for (int j = 0; j < n && k < POLYC__EDIT_SEGS; j++) {
        int32_t a = segs[j];
        if (a == POLYC__NONE || V[a].next == POLYC__NONE)
            continue;
        old_xy[4 * k] = V[a].x;
        old_xy[4 * k + 1] = V[a].y;
        old_xy[4 * k + 2] = V[V[a].next].x;
        old_xy[4 * k + 3] = V[V[a].next].y;
        k++;
    }
    return k;
}

/* A segment a-b to test beams against, and a list of other segments (x0 y0
 * x1 y1 each): for blocks_beams those the edit replaces, for loses_returns
 * those that replace a-b. */
typedef struct beam_query {
    float ax, ay, bx, by;
    const float *others;
    int n_others;
} beam_query;

/* Whether one of the n segments in xy meets beam (c, sn) within the
 * tolerance of range r. */
static int met_by_any(const polyc__rays *rays, float c, float sn, float r, const float *xy, int n)
{
    for (int k = 0; k < n; k++) {
        const float *e = xy + 4 * k;
        if (fabsf(range_to(rays, c, sn, e[0], e[1], e[2], e[3]) - (float)r) <= rays->tol_m)
            return 1;
    }
    return 0;
}

/* Beam i against the query's segment: 1 if the segment stands in front of
 * its return, or behind it while the return is its own: near its line, or
 * met within the tolerance by a segment the edit replaces. Without the
 * second rule a removal on a wall seen at a grazing angle can leave a
 * return 15-20 cm off the new line, and its beam then meets the map metres
 * behind it (one such beam can make most of a scan's ray RMSE). */
static int beam_blocked(const polyc__rays *rays, int32_t i, float c, float sn,
                        const beam_query *q)
{
    float r = rays->range[i];
    if (!(r >= rays->min_m && r < rays->max_m))
        return 0; /* no return: it proves nothing about a wall */
    float ax = q->ax, ay = q->ay, bx = q->bx, by = q->by;
    float t = range_to(rays, c, sn, ax, ay, bx, by);
    if (t < (float)r - rays->tol_m)
        return 1;
    if (isfinite(t) && t > (float)r + rays->tol_m) {
        /* the return is in front of the segment: a misfit if it is near
         * enough to be the segment's own point (within the search radius
         * of its line) */
        float px = rays->x + (float)r * c - (float)ax, py = rays->y + (float)r * sn - (float)ay;
        float ex = (float)bx - (float)ax, ey = (float)by - (float)ay;
        float cr = px * ey - py * ex;
        if (cr * cr < rays->own_m * rays->own_m * (ex * ex + ey * ey))
            return 1;
        return met_by_any(rays, c, sn, r, q->others, q->n_others);
    }
    return 0;
}

/* Beam i meets segment a-b within the tolerance of its return: a return
 * the segment holds, at any range and incidence. Together with the rule on
 * the returns of replaced segments (beam_blocked) and polyc__loses_returns
 * that keeps every reflected beam on the map at no ray error. (Without
 * beam_blocked's rule, holding far or flat returns raised the ray RMSE of
 * a log with long beams by half, with ends kept decimetres off along beams
 * tens of metres long.) */
static int beam_own(const polyc__rays *rays, int32_t i, float c, float sn, const beam_query *q)
{
    float ax = q->ax, ay = q->ay, bx = q->bx, by = q->by;
    float r = rays->range[i];
    if (!(r >= rays->min_m && r < rays->max_m))
        return 0;
    return fabsf(range_to(rays, c, sn, ax, ay, bx, by) - (float)r) <= rays->tol_m;
}

/* A test of beam i, whose direction is (c, sn), against segment a-b. */
typedef int (*beam_test)(const polyc__rays *rays, int32_t i, float c, float sn,
                         const beam_query *q);

/* The direction of (x, y) in (-pi, pi], to within 2e-6 rad (polyc__turn_rad:
 * libm's atan2 would take a tenth of the ray checks' time) */
static float angle_of(float x, float y)
{
    float a = (float)polyc__turn_rad((float)y, (float)x);
    return y < 0.0f ? -a : a;
}

/* d wrapped into [-pi, pi] */
static float wrap(float d)
{
    return d - TWO_PI * floorf(d / TWO_PI + 0.5f);
}

/* Whether `test` holds for some beam whose direction crosses segment a-b.
 * The directions of a run of beams come from rotating the first by the
 * step: one cosine and sine per run, not per beam. */
static int any_beam(const polyc__rays *rays, const beam_query *q, beam_test test)
{
    float ax = q->ax, ay = q->ay, bx = q->bx, by = q->by;
    if (!rays->on || rays->step == 0.0f)
        return 0;
    float ta = angle_of((float)ax - rays->x, (float)ay - rays->y);
    float tb = angle_of((float)bx - rays->x, (float)by - rays->y);
    /* beam index space: the segment covers [ia, ib] the short way round,
     * widened by a hundredth of a beam for the angles' error (a beam that
     * does not cross the segment passes every test) */
    float ia = wrap(ta - rays->base) / rays->step;
    float span = wrap(tb - ta) / rays->step;
    float lo = span < 0.0f ? ia + span : ia, hi = span < 0.0f ? ia : ia + span;
    lo -= 0.01f;
    hi += 0.01f;
    /* lo, hi lie in [-turn, turn]: beam i is index i, i - turn or i + turn
     * (bounded by the beam count, however fine the step) */
    int32_t offsets[3] = {0, rays->turn, -rays->turn};
    for (int k = 0; k < (rays->turn > 0 ? 3 : 1); k++) {
        float from = ceilf(lo), to = (float)offsets[k] + (float)rays->count - 1.0f;
        from = from > (float)offsets[k] ? from : (float)offsets[k];
        to = hi < to ? hi : to;
        if (!(from <= to))
            continue;
        float a = rays->base + (from - (float)offsets[k]) * rays->step;
        float c, sn;
        polyc__sincosf(a, &sn, &c);
        for (float at = from; at <= to; at += 1.0f) {
            if (test(rays, (int32_t)at - offsets[k], c, sn, q))
                return 1;
            float next_c = c * rays->step_cos - sn * rays->step_sin;
            sn = sn * rays->step_cos + c * rays->step_sin;
            c = next_c;
        }
    }
    return 0;
}

int polyc__blocks_beams(const polyc__rays *rays, float ax, float ay, float bx, float by,
                        const float *old_xy, int n_old)
{
    beam_query q = {ax, ay, bx, by, old_xy, n_old};
    return any_beam(rays, &q, beam_blocked);
}

/* Beam i is blocked by the query's (new) segment and by none of the old
 * segments (the query's others): a block the edit adds. */
static int beam_newly_blocked(const polyc__rays *rays, int32_t i, float c, float sn,
                              const beam_query *q)
{
    if (!beam_blocked(rays, i, c, sn, q))
        return 0;
    for (int k = 0; k < q->n_others; k++) {
        const float *e = q->others + 4 * k;
        beam_query old = {e[0], e[1], e[2], e[3], q->others, q->n_others};
        if (beam_blocked(rays, i, c, sn, &old))
            return 0;
    }
    return 1;
}

/* Whether vertex v at (x, y) makes one of its segments block a beam that
 * its segments as they stand do not block, or loses a return they hold
 * (the store still holds v where it is). A vertex that already blocks a
 * beam (an end near the sensor, where the range noise is as large as the
 * beam spacing) may still move, but not onto other beams: with any move of
 * such a vertex allowed, one climb put a segment metres in front of a
 * return. */
int polyc__vertex_blocks(const polyc__opt *o, int32_t v, float x, float y)
{
    if (!o->rays.on)
        return 0;
    const polyc__vertex *V = o->s->v;
    int32_t p = V[v].prev, n = V[v].next;
    int32_t segs[2] = {p, v};
    float old_xy[4 * POLYC__EDIT_SEGS], new_xy[8];
    int n_old = polyc__edit_segments(o, segs, 2, old_xy), n_new = 0;
    if (p != POLYC__NONE) {
        const float e[4] = {V[p].x, V[p].y, x, y};
        memcpy(new_xy + 4 * n_new++, e, sizeof e);
    }
    if (n != POLYC__NONE) {
        const float e[4] = {x, y, V[n].x, V[n].y};
        memcpy(new_xy + 4 * n_new++, e, sizeof e);
    }
    for (int k = 0; k < n_new; k++) {
        const float *e = new_xy + 4 * k;
        beam_query q = {e[0], e[1], e[2], e[3], old_xy, n_old};
        if (any_beam(&o->rays, &q, beam_newly_blocked))
            return 1;
    }
    return polyc__loses_returns(&o->rays, old_xy, n_old, new_xy, n_new);
}

int polyc__holds_returns(const polyc__rays *rays, float ax, float ay, float bx, float by)
{
    beam_query q = {ax, ay, bx, by, NULL, 0};
    return any_beam(rays, &q, beam_own);
}

/* A return the query's (old) segment holds that none of the new segments
 * (the query's others) meets within the tolerance. */
static int beam_lost(const polyc__rays *rays, int32_t i, float c, float sn, const beam_query *q)
{
    return beam_own(rays, i, c, sn, q) &&
           !met_by_any(rays, c, sn, rays->range[i], q->others, q->n_others);
}

int polyc__loses_returns(const polyc__rays *rays, const float *old_xy, int n_old,
                         const float *new_xy, int n_new)
{
    if (!rays->on)
        return 0;
    for (int k = 0; k < n_old; k++) {
        const float *e = old_xy + 4 * k;
        beam_query q = {e[0], e[1], e[2], e[3], new_xy, n_new};
        if (any_beam(rays, &q, beam_lost))
            return 1;
    }
    return 0;
}
