/* topology.c - walls do not pass through each other (not in the paper).
 * Takes: the optimiser state. Gives: a map in which no two segments that
 * do not share a vertex cross. The paper's error term measures only how
 * far the data lie from the map, so nothing in the BIC keeps a hairpin
 * that explains clutter from passing through a wall, or an end from
 * overshooting the wall it meets. Each crossing is resolved by the edit
 * that raises the BIC least among those that remove it and create none:
 * one of the four vertices of the two segments removed, or one segment cut
 * short just before the crossing, the arm beyond it gone (at an open end
 * that is a trim; inside a polyline it splits it there). (Two pieces of
 * map along one wall are zip.c's.) */
#include "../opt_state.h"

#include <math.h>

/* the external definitions of optimize.h's inline functions (C99: used
 * where a caller does not inline them, as at -Os) */
extern inline int polyc__touches(const polyc__store *s, int32_t sg, int32_t a, int32_t b);
extern inline int polyc__edited_since(const polyc__opt *o, int32_t v, uint32_t since);

#define CROSS_END_M 0.002f  /* a crossing this near a segment end is a junction */
#define CUT_BACK_M 0.002f   /* a cut arm ends this short of the other segment */
#define LOSES_RETURNS 1e6f   /* single scans: an edit that loses returns comes last */
#define END_GAP_M 0.001f     /* an end that meets a segment stops this short of it */

/* Whether segments p0-p1 and q0-q1 cross with the crossing at least
 * CROSS_END_M from all four ends; *t and *u: its position along each. */
static int proper_cross(float p0x, float p0y, float p1x, float p1y, float q0x, float q0y,
                        float q1x, float q1y, float *t, float *u)
{
    float rx = (float)p1x - (float)p0x, ry = (float)p1y - (float)p0y;
    float sx = (float)q1x - (float)q0x, sy = (float)q1y - (float)q0y;
    float den = rx * sy - ry * sx;
    if (den == 0.0f)
        return 0;
    float wx = (float)q0x - (float)p0x, wy = (float)q0y - (float)p0y;
    float tt = (wx * sy - wy * sx) / den, uu = (wx * ry - wy * rx) / den;
    float lp = sqrtf(rx * rx + ry * ry), lq = sqrtf(sx * sx + sy * sy);
    float e = (float)CROSS_END_M;
    if (tt * lp < e || (1.0f - tt) * lp < e || uu * lq < e || (1.0f - uu) * lq < e)
        return 0;
    *t = (float)tt;
    *u = (float)uu;
    return 1;
}


/* The first segment of the map that crosses x0-x1 (ends a and b as vertex
 * numbers, NONE for a point that is no vertex; segments touching them do
 * not count), or NONE. Every segment is in each bucket its path crosses, so
 * two crossing segments share the bucket of the crossing, and that bucket
 * lies in x0-x1's bounding box of buckets. */
static int32_t first_crossing(const polyc__opt *o, const float *xy, int32_t a, int32_t b,
                              float *t, float *u)
{
    const polyc__hash *h = &o->h;
    const polyc__store *s = o->s;
    int32_t ix0, iy0, ix1, iy1;
    polyc__bucket_xy(h, polyc__minf(xy[0], xy[2]), polyc__minf(xy[1], xy[3]), &ix0, &iy0);
    polyc__bucket_xy(h, polyc__maxf(xy[0], xy[2]), polyc__maxf(xy[1], xy[3]), &ix1, &iy1);
    for (int32_t iy = iy0; iy <= iy1; iy++)
        for (int32_t ix = ix0; ix <= ix1; ix++)
            for (int32_t e = h->seg_head[iy * h->bx + ix]; e != POLYC__NONE; e = h->entries[e].next) {
                int32_t sg = h->entries[e].seg;
                if (polyc__touches(s, sg, a, b))
                    continue;
                const polyc__vertex *c = &s->v[sg], *d = &s->v[c->next];
                if (proper_cross(xy[0], xy[1], xy[2], xy[3], c->x, c->y, d->x, d->y, t, u))
                    return sg;
            }
    return POLYC__NONE;
}

int polyc__link_crosses(const polyc__opt *o, int32_t a, int32_t b)
{
    const polyc__vertex *V = o->s->v;
    const float xy[4] = {V[a].x, V[a].y, V[b].x, V[b].y};
    float t, u;
    return first_crossing(o, xy, a, b, &t, &u) != POLYC__NONE;
}

/* One way to remove a crossing. */
typedef struct fix {
    int kind;          /* 0 none, 1 remove vertex v, 2 keep v's side of segment seg up to (x, y) */
    int32_t v, seg;
    float x, y;
    float delta;      /* change of the BIC */
} fix;

static void consider(fix *best, const fix *f)
{
    if (f->kind != 0 && (best->kind == 0 || f->delta < best->delta))
        *best = *f;
}

/* Removing vertex v, if the segment that replaces its two crosses nothing. */
static void try_remove(polyc__opt *o, int32_t v, fix *best)
{
    const polyc__vertex *V = o->s->v;
    int32_t p = V[v].prev, n = V[v].next;
    if (p != POLYC__NONE && n != POLYC__NONE && p != n) {
        const float xy[4] = {V[p].x, V[p].y, V[n].x, V[n].y};
        float t, u;
        if (first_crossing(o, xy, p, n, &t, &u) != POLYC__NONE)
            return;
    }
    /* only a removal cheaper than the best fix so far matters: its change is
     * exact below that bound (INFINITY: a single scan's return would go) */
    float bound = best->kind != 0 ? best->delta : (float)INFINITY;
    float d = polyc__removal_delta_below(o, v, bound);
    if (isinf(d) || (best->kind != 0 && d >= bound))
        return;
    fix f = {1, v, POLYC__NONE, 0.0f, 0.0f, d};
    consider(best, &f);
}

/* Cutting segment seg (a -> b) at position t, keeping the side of `keep`
 * (a or b): the kept piece ends CUT_BACK_M short of the crossing. */
static void try_cut(polyc__opt *o, int32_t seg, float t, int32_t keep, fix *best)
{
    const polyc__vertex *V = o->s->v;
    int32_t a = seg, b = V[seg].next;
    float dx = V[b].x - V[a].x, dy = V[b].y - V[a].y;
    float len = sqrtf(dx * dx + dy * dy);
    if (!(len > 0.0f))
        return;
    float back = CUT_BACK_M / len;
    float tc = keep == a ? t - back : t + back;
    if (tc <= 0.0f || tc >= 1.0f)
        return;
    float x = V[a].x + tc * dx, y = V[a].y + tc * dy;
    int32_t gone = keep == a ? b : a; /* the vertex on the far side */
    const float old_xy[4] = {V[a].x, V[a].y, V[b].x, V[b].y};
    float new_xy[4] = {V[keep].x, V[keep].y, x, y};
    float dk = 0.0f, dangle = 0.0f;
    int end = keep == a ? V[b].next == POLYC__NONE : V[a].prev == POLYC__NONE;
    if (!end) {
        dk = 1.0f;                  /* the cut adds the vertex at the cut */
        dangle = -o->acost[gone];  /* and the far vertex becomes an end */
    }
    float alpha = (float)o->cfg->alpha, fixed = alpha * (float)o->cfg->gamma * dangle + dk * o->d.log_n;
    /* a cut only takes map away, so its error change is >= 0: it matters
     * only below the best fix so far, and is exact below that */
    float limit = best->kind != 0 ? (best->delta - fixed) / alpha : (float)INFINITY;
    if (limit <= 0.0f)
        return;
    float derr = polyc__local_delta(o, &seg, 1, new_xy, 1, limit);
    if (derr >= limit)
        return;
    float d = alpha * derr + fixed;
    if (o->rays.on && polyc__loses_returns(&o->rays, old_xy, 1, new_xy, 1))
        d += LOSES_RETURNS;
    fix f = {2, keep, seg, x, y, d};
    consider(best, &f);
}

/* Applies a fix; 0 if there was no room for it. */
static int apply(polyc__opt *o, const fix *f)
{
    polyc__store *s = o->s;
    if (f->kind == 1) {
        polyc__apply_remove(o, f->v);
        return 1;
    }
    int32_t a = f->seg, b = s->v[a].next, keep = f->v;
    int32_t gone = keep == a ? b : a;
    int end = keep == a ? s->v[b].next == POLYC__NONE : s->v[a].prev == POLYC__NONE;
    if (end) {
        polyc__apply_move(o, gone, f->x, f->y); /* the open end is pulled back */
        return 1;
    }
    polyc__chg_begin(o);
    int32_t c = polyc__op_insert_after(o, a, f->x, f->y);
    if (c != POLYC__NONE)
        polyc__op_cut(o, keep == a ? c : a); /* the link on the far side goes */
    polyc__chg_commit(o);
    return c != POLYC__NONE;
}


int polyc__op_untangle(polyc__opt *o)
{
    polyc__store *s = o->s;
    int fixed = 0;
    uint32_t since = o->untangle_mark;
    o->untangle_mark = ++o->touch_stamp;
    for (int32_t v = 0; v < s->v_high; v++) {
        for (int k = 0; k < POLYC__FIXES_PER_SEGMENT; k++) {
            if (s->v[v].line == POLYC__NONE || s->v[v].next == POLYC__NONE ||
                (k == 0 && !polyc__edited_since(o, v, since)))
                break;
            int32_t w = s->v[v].next;
            const float xy[4] = {s->v[v].x, s->v[v].y, s->v[w].x, s->v[w].y};
            float t, u;
            int32_t other = first_crossing(o, xy, v, w, &t, &u);
            if (other == POLYC__NONE)
                break;
            int32_t ends[4] = {v, w, other, s->v[other].next};
            fix best = {0, POLYC__NONE, POLYC__NONE, 0.0f, 0.0f, 0.0f};
            /* cuts first: an overshooting end is the usual crossing, and its
             * trim bounds the rest */
            try_cut(o, v, t, v, &best);
            try_cut(o, v, t, w, &best);
            try_cut(o, other, u, ends[2], &best);
            try_cut(o, other, u, ends[3], &best);
            for (int e = 0; e < 4; e++)
                try_remove(o, ends[e], &best);
            if (best.kind == 0 || !apply(o, &best))
                break;
            fixed++;
        }
    }
    return fixed;
}

/* Vertex v, within CROSS_END_M of segment c-d (its projection on it),
 * cleared of it by END_GAP_M on the side of its neighbours p and q (q
 * NONE: v is an open end). A T-junction's end, or a corner that touches a
 * wall, lies on the other segment up to float's rounding, a tenth of a
 * millimetre through it or short of it, which the crossings' end rule lets
 * pass; printed to 0.1 mm a strict test finds a crossing or a touch
 * (shapely's validity on real logs' maps). An end moves back along its
 * segment, a corner across the line. With p and q on two sides the
 * polyline crosses c-d at v: v goes 1.5 CROSS_END_M further its own way,
 * so that the crossing is one untangle sees. 0: unmoved, 1: cleared, 2:
 * pushed through. */
static int clear_vertex(polyc__opt *o, int32_t v, int32_t p, int32_t q, int32_t sg)
{
    const polyc__vertex *V = o->s->v, *c = &V[sg], *d = &V[c->next];
    float sx = d->x - c->x, sy = d->y - c->y, ls = sqrtf(sx * sx + sy * sy);
    if (ls <= 4.0f * END_GAP_M)
        return 0;
    float nx = -sy / ls, ny = sx / ls; /* unit normal of c-d */
    float dv = (V[v].x - c->x) * nx + (V[v].y - c->y) * ny;
    float dp = (V[p].x - c->x) * nx + (V[p].y - c->y) * ny;
    float dq = q != POLYC__NONE ? (V[q].x - c->x) * nx + (V[q].y - c->y) * ny : dp;
    float along = ((V[v].x - c->x) * sx + (V[v].y - c->y) * sy) / (ls * ls);
    if (along < 0.0f || along > 1.0f || fabsf(dv) >= CROSS_END_M || fabsf(dp) <= END_GAP_M ||
        fabsf(dq) <= END_GAP_M)
        return 0;
    if ((dp > 0.0f) != (dq > 0.0f)) {
        float push = (dv >= 0.0f ? 1.5f : -1.5f) * CROSS_END_M;
        polyc__apply_move(o, v, V[v].x + push * nx, V[v].y + push * ny);
        return 2;
    }
    float to = dp > 0.0f ? END_GAP_M : -END_GAP_M;
    if ((dv > 0.0f) == (dp > 0.0f) && fabsf(dv) >= END_GAP_M)
        return 0; /* (clear of it on its neighbours' side) */
    if (q == POLYC__NONE) { /* along p-v to where it is `to` from the line */
        float f = (dp - to) / (dp - dv);
        polyc__apply_move(o, v, V[p].x + f * (V[v].x - V[p].x), V[p].y + f * (V[v].y - V[p].y));
    } else {
        polyc__apply_move(o, v, V[v].x + (to - dv) * nx, V[v].y + (to - dv) * ny);
    }
    return 1;
}

int polyc__op_end_gaps(polyc__opt *o)
{
    const polyc__store *s = o->s;
    const polyc__hash *h = &o->h;
    int moved = 0;
    for (int32_t v = 0; v < s->v_high; v++) {
        const polyc__vertex *e = &s->v[v];
        if (e->line == POLYC__NONE || (e->prev == POLYC__NONE && e->next == POLYC__NONE))
            continue; /* (a polyline of one vertex) */
        int inner = e->prev != POLYC__NONE && e->next != POLYC__NONE;
        int32_t n = e->prev != POLYC__NONE ? e->prev : e->next;
        int32_t m = inner ? e->next : POLYC__NONE;
        polyc__near_segs w;
        POLYC__FOR_NEAR_SEGS(w, h, e->x, e->y, sg) {
            if (polyc__touches(s, sg, v, inner ? POLYC__NONE : n))
                continue;
            int how = clear_vertex(o, v, n, m, sg);
            if (how) {
                moved += how == 2 ? 1000 : 1; /* (thousands: crossings made proper) */
                goto next; /* (its hash entries moved with it) */
            }
        }
    next:;
    }
    return moved;
}
