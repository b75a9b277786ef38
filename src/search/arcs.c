/* arcs.c - curved walls as arcs: after the search, a run of a polyline's
 * segments that turn one way by small angles (a curve drawn as chords)
 * becomes one circular arc between its two end vertices where the points
 * the run holds fit the arc at a lower BIC: one number, the bulge, for the
 * vertices inside the run. Takes: the optimiser at its final map. Gives:
 * the result's arc form (ctx->flat: per point, kept or not, and the bulge
 * of the arc that starts there). */
#include "../optimize.h"
#include "round.h"

/* an arc is the bulge, half a vertex in the BIC's units (one log n a
 * vertex, two numbers) */
#define ARC_K 0.5f
#define ARC_MAX_SEGS 16            /* segments one arc may replace */
/* and at least this many: two turns the same way make a curve; one is a
 * bend, which the search keeps as a vertex (one turn as an arc put lines
 * bent by the poses' noise on straight walls) */
#define ARC_MIN_SEGS 3
#define ARC_MAX_TURN 0.8f          /* rad: a sharper turn is a corner, not a curve */
#define ARC_BULGE_MAX 0.9f         /* arcs of less than about 170 degrees */
#define FIT_ITERATIONS 28          /* golden-section steps on the bulge */
#define CLEAR_M 0.01f              /* other segments keep this far from an arc */
#define END_SKIP_M 0.02f           /* near its ends an arc meets its neighbours */

/* An arc from a to b with bulge b (tan of a quarter of its angle; > 0:
 * counter-clockwise), as its circle and the sense it turns. */
typedef struct arc {
    float ax, ay, bx, by, bulge;
    float cx, cy, r, sense;        /* sense: +1 counter-clockwise, -1 clockwise */
} arc;

static void arc_make(arc *g, float ax, float ay, float bx, float by, float bulge)
{
    float dx = bx - ax, dy = by - ay, c = sqrtf(dx * dx + dy * dy);
    float b = fabsf(bulge), half = 2.0f * polyc__atan2f(b, 1.0f); /* half the included angle */
    g->ax = ax;
    g->ay = ay;
    g->bx = bx;
    g->by = by;
    g->bulge = bulge;
    g->sense = bulge >= 0.0f ? 1.0f : -1.0f;
    g->r = c / (2.0f * polyc__sinf(half));
    /* the centre lies off the chord's middle on the side away from the
     * arc: to the left of a -> b for a counter-clockwise arc */
    float d = g->r * polyc__cosf(half), nx = -dy / c, ny = dx / c;
    g->cx = 0.5f * (ax + bx) + g->sense * d * nx;
    g->cy = 0.5f * (ay + by) + g->sense * d * ny;
}

/* Whether the direction (vx, vy) from the centre lies within the arc. */
static int arc_spans(const arc *g, float vx, float vy)
{
    float ux = g->ax - g->cx, uy = g->ay - g->cy, wx = g->bx - g->cx, wy = g->by - g->cy;
    return g->sense * (ux * vy - uy * vx) >= 0.0f && g->sense * (vx * wy - vy * wx) >= 0.0f;
}

/* A point's cost against the arc (across the circle where the arc spans
 * it, else to the nearer end), capped as a segment's. */
static float arc_cost(const polyc__opt *o, const polyc__point *p, const arc *g)
{
    float c;
    if (arc_spans(g, p->x - g->cx, p->y - g->cy)) {
        c = polyc__ring_cost(p, g->cx, g->cy, g->r);
    } else {
        float ex = p->x - g->ax, ey = p->y - g->ay, fx = p->x - g->bx, fy = p->y - g->by;
        c = p->w * fminf(ex * ex + ey * ey, fx * fx + fy * fy) + p->cxx + p->cyy;
    }
    float cap = polyc__point_cap(o, p);
    return c < cap ? c : cap;
}

/* A run of a polyline: the vertices v[0..k] (k segments). */
typedef struct run {
    int32_t v[ARC_MAX_SEGS + 1];
    int32_t k;
    polyc__bucket_box bb;
} run;

static int in_run(const run *ru, int32_t seg)
{
    for (int32_t i = 0; i < ru->k; i++)
        if (ru->v[i] == seg)
            return 1;
    return 0;
}

/* Every point i whose nearest segment is one of the run's. */
#define FOR_RUN_POINTS(o, ru, i)                                                                 \
    POLYC__FOR_BOX_POINTS(o, (ru)->bb, i)                                                         \
    if ((o)->d.pt_seg[i] != POLYC__NONE && in_run(ru, (o)->d.pt_seg[i]))

static float run_arc_error(const polyc__opt *o, const run *ru, const arc *g)
{
    float e = 0.0f;
    FOR_RUN_POINTS(o, ru, i) e += arc_cost(o, &o->d.pts[i], g);
    return e;
}

/* The bulge of the run's arc: golden section about the bulge its inner
 * vertices suggest (their largest offset from the chord). */
static float fit_bulge(const polyc__opt *o, const run *ru, arc *g)
{
    const polyc__vertex *a = &o->s->v[ru->v[0]], *b = &o->s->v[ru->v[ru->k]];
    float dx = b->x - a->x, dy = b->y - a->y, c = sqrtf(dx * dx + dy * dy), off = 0.0f;
    for (int32_t i = 1; i < ru->k; i++) {
        const polyc__vertex *u = &o->s->v[ru->v[i]];
        /* to the right of a -> b: a counter-clockwise arc's side */
        float s = ((u->x - a->x) * dy - (u->y - a->y) * dx) / c;
        off = fabsf(s) > fabsf(off) ? s : off;
    }
    float b0 = 2.0f * off / c, span = fmaxf(0.5f * fabsf(b0), 0.02f);
    float lo = fmaxf(b0 - span, -ARC_BULGE_MAX), hi = fminf(b0 + span, ARC_BULGE_MAX);
    const float phi = 0.6180340f;
    float x1 = hi - phi * (hi - lo), x2 = lo + phi * (hi - lo), f1, f2;
    arc_make(g, a->x, a->y, b->x, b->y, x1);
    f1 = run_arc_error(o, ru, g);
    arc_make(g, a->x, a->y, b->x, b->y, x2);
    f2 = run_arc_error(o, ru, g);
    for (int it = 0; it < FIT_ITERATIONS; it++) {
        if (f1 < f2) {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - phi * (hi - lo);
            arc_make(g, a->x, a->y, b->x, b->y, x1);
            f1 = run_arc_error(o, ru, g);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + phi * (hi - lo);
            arc_make(g, a->x, a->y, b->x, b->y, x2);
            f2 = run_arc_error(o, ru, g);
        }
    }
    float best = f1 < f2 ? x1 : x2;
    arc_make(g, a->x, a->y, b->x, b->y, best);
    return f1 < f2 ? f1 : f2;
}

/* The point of the arc at fraction t of its angle. */
static void arc_at(const arc *g, float t, float *x, float *y)
{
    float a0 = polyc__atan2f(g->ay - g->cy, g->ax - g->cx);
    float sweep = g->sense * 4.0f * polyc__atan2f(fabsf(g->bulge), 1.0f);
    float s, c;
    polyc__sincosf(a0 + t * sweep, &s, &c);
    *x = g->cx + g->r * c;
    *y = g->cy + g->r * s;
}

/* Do the run's points near the arc (within support_m) hold it with no
 * stretch longer than the split gap without one? */
static int arc_covered(const polyc__opt *o, const run *ru, const arc *g)
{
    enum { BINS = 256 };
    uint8_t hit[BINS] = {0};
    float len = g->r * 4.0f * polyc__atan2f(fabsf(g->bulge), 1.0f), gap = o->cfg->split_gap_m;
    int32_t n = (int32_t)ceilf(len / (0.5f * gap));
    n = n < 4 ? 4 : (n > BINS ? BINS : n);
    float a0 = polyc__atan2f(g->ay - g->cy, g->ax - g->cx), sweep = len / g->r;
    FOR_RUN_POINTS(o, ru, i) {
        const polyc__point *p = &o->d.pts[i];
        float dx = p->x - g->cx, dy = p->y - g->cy;
        if (fabsf(sqrtf(dx * dx + dy * dy) - g->r) > o->d.support_m)
            continue; /* (a point holds the arc only near it) */
        float a = polyc__atan2f(dy, dx) - a0;
        a = g->sense > 0.0f ? a : -a;
        while (a < 0.0f)
            a += 6.2831853f;
        if (a <= sweep) {
            int32_t k = (int32_t)(a / sweep * (float)n);
            hit[k >= n ? n - 1 : k] = 1;
        }
    }
    int32_t run_len = 0, longest = 0;
    for (int32_t k = 0; k < n; k++) {
        run_len = hit[k] ? 0 : run_len + 1;
        longest = run_len > longest ? run_len : longest;
    }
    return (float)longest * len / (float)n <= gap;
}

/* Does every segment outside the run keep CLEAR_M off the arc (away from
 * its two ends, where it meets its neighbours)? The arc sampled every
 * centimetre against the segments of the buckets round each sample. */
static int arc_clear(const polyc__opt *o, const run *ru, const arc *g)
{
    float len = g->r * 4.0f * polyc__atan2f(fabsf(g->bulge), 1.0f);
    int32_t n = (int32_t)ceilf(len / 0.01f);
    for (int32_t k = 0; k <= n; k++) {
        float t = (float)k / (float)n, x, y;
        if (t * len < END_SKIP_M || (1.0f - t) * len < END_SKIP_M)
            continue;
        arc_at(g, t, &x, &y);
        polyc__near_segs w;
        POLYC__FOR_NEAR_SEGS(w, &o->h, x, y, sg) {
            if (in_run(ru, sg))
                continue;
            const polyc__vertex *a = &o->s->v[sg], *b = &o->s->v[a->next];
            float ex = b->x - a->x, ey = b->y - a->y, l2 = ex * ex + ey * ey;
            float u = l2 > 0.0f ? ((x - a->x) * ex + (y - a->y) * ey) / l2 : 0.0f;
            u = u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
            float fx = a->x + u * ex - x, fy = a->y + u * ey - y;
            if (fx * fx + fy * fy < CLEAR_M * CLEAR_M)
                return 0;
        }
    }
    return 1;
}

/* The turn at vertex u of the path t -> u -> w, signed (+ left). */
static float signed_turn(const polyc__opt *o, int32_t t, int32_t u, int32_t w)
{
    const polyc__vertex *a = &o->s->v[t], *b = &o->s->v[u], *c = &o->s->v[w];
    float ux = b->x - a->x, uy = b->y - a->y, vx = c->x - b->x, vy = c->y - b->y;
    return polyc__atan2f(ux * vy - uy * vx, ux * vx + uy * vy);
}

/* The BIC's change if the run's k segments become its arc (< 0: the arc is
 * better), *g the arc; 1e30 when the arc is not allowed. */
static float run_delta(const polyc__opt *o, run *ru, arc *g)
{
    float lo_x = INFINITY, lo_y = INFINITY, hi_x = -INFINITY, hi_y = -INFINITY, angle = 0.0f;
    for (int32_t i = 0; i <= ru->k; i++) {
        const polyc__vertex *u = &o->s->v[ru->v[i]];
        lo_x = fminf(lo_x, u->x);
        lo_y = fminf(lo_y, u->y);
        hi_x = fmaxf(hi_x, u->x);
        hi_y = fmaxf(hi_y, u->y);
        if (i > 0 && i < ru->k)
            angle += o->acost[ru->v[i]];
    }
    ru->bb = polyc__box_buckets(o, lo_x, lo_y, hi_x, hi_y);
    float err_lines = 0.0f;
    FOR_RUN_POINTS(o, ru, i) err_lines += o->d.pt_cost[i];
    float err_arc = fit_bulge(o, ru, g);
    float delta = o->cfg->alpha * (err_arc - err_lines - o->cfg->gamma * angle) +
                  (ARC_K - (float)(ru->k - 1)) * o->d.log_n;
    if (!(delta < 0.0f) || !arc_covered(o, ru, g) || !arc_clear(o, ru, g))
        return 1e30f;
    return delta;
}

/* Line l's arcs, greedily from its head: at each vertex the best arc over
 * the runs of 2 to ARC_MAX_SEGS segments that turn one way by less than
 * ARC_MAX_TURN at every inner vertex; its points' keep and bulge into the
 * result from `at` (the line's first point there). */
static uint32_t line_arcs(const polyc__opt *o, int32_t l, polyc__flat *res, uint32_t at)
{
    const polyc__line *ln = &o->s->l[l];
    uint32_t arcs = 0;
    int32_t v = ln->head;
    /* (no run crosses a closed line's head: its last segment stays) */
    for (int32_t i = 0; i + ARC_MIN_SEGS <= ln->count - 1;) {
        run ru, best_run = {{0}, 0, {0, 0, 0, 0}};
        arc g, best_arc = {0};
        float best = 0.0f, sense = 0.0f;
        ru.v[0] = v;
        ru.k = 0;
        int32_t u = v;
        while (ru.k < ARC_MAX_SEGS && i + ru.k + 1 <= ln->count - 1) {
            int32_t w = o->s->v[u].next;
            if (ru.k >= 1) {
                float t = signed_turn(o, ru.v[ru.k - 1], u, w);
                if (fabsf(t) > ARC_MAX_TURN || (sense != 0.0f && t * sense < 0.0f))
                    break;
                sense = t >= 0.0f ? 1.0f : -1.0f;
            }
            ru.v[++ru.k] = w;
            u = w;
            if (ru.k >= ARC_MIN_SEGS) {
                float d = run_delta(o, &ru, &g);
                if (d < best) {
                    best = d;
                    best_run = ru;
                    best_arc = g;
                }
            }
        }
        if (best < 0.0f) {
            res->arc_bulge[at + (uint32_t)i] = best_arc.bulge;
            for (int32_t k = 1; k < best_run.k; k++)
                res->arc_keep[at + (uint32_t)(i + k)] = 0;
            arcs++;
            i += best_run.k;
            v = best_run.v[best_run.k];
        } else {
            i++;
            v = o->s->v[v].next;
        }
    }
    return arcs;
}

/* Every polyline that is no circle: its arcs (the result's polylines are
 * the store's live slots, lowest first: polyc__flat_from_store). */
void polyc__arcs_select(polyc__opt *o)
{
    polyc__flat *res = &o->ctx->flat;
    const polyc__store *s = o->s;
    res->arc_n = 0;
    if (!res->arc_keep)
        return;
    for (uint32_t k = 0; k < res->points; k++) {
        res->arc_keep[k] = 1;
        res->arc_bulge[k] = 0.0f;
    }
    if (o->cfg->flags & POLYC_FLAG_NO_ARCS)
        return;
    uint32_t index = 0;
    for (int32_t l = 0; l < s->l_high; l++) {
        const polyc__line *ln = &s->l[l];
        if (ln->closed == POLYC__NONE || ln->count == 0)
            continue;
        int circle = 0;
        for (uint32_t c = 0; c < res->circ_n; c++)
            circle |= res->circ[c].line_id == ln->id;
        if (!circle && index < res->count && ln->count >= 3)
            res->arc_n += line_arcs(o, l, res, res->start[index]);
        index++;
    }
}
