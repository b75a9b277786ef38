/* operators.c - the structural operators A, B and E (paper IV.A, B, E).
 * Takes: the optimiser state. Gives: overlapping polyline ends zipped,
 * close ends merged (or a polyline closed), hairpin zigzags removed; all
 * through the edits of edits.c. (C, splitting and trimming, is split.c.) */
#include "../cost.h"

#include <float.h>
#include <math.h>

/* ---- geometry helpers ---- */


/* Is segment `seg` within `hops` links of vertex v on the same polyline? */
static int near_on_line(const polyc__opt *o, int32_t v, int32_t seg, int hops)
{
    if (o->s->v[v].line != o->s->v[seg].line)
        return 0;
    int32_t a = v, b = v;
    for (int k = 0; k <= hops; k++) {
        if (a == seg || b == seg)
            return 1;
        if (a != POLYC__NONE) a = o->s->v[a].prev;
        if (b != POLYC__NONE) b = o->s->v[b].next;
    }
    return 0;
}

/* Squared distance from (x, y) to the nearest segment not near vertex v on
 * its own polyline (searched within the hash's reach). */
static float other_dist2(const polyc__opt *o, float x, float y, int32_t v)
{
    const polyc__hash *h = &o->h;
    float best = 1e30f;
    polyc__near_segs w;
    POLYC__FOR_NEAR_SEGS(w, h, x, y, sg) {
        if (near_on_line(o, v, sg, 3))
            continue;
        const polyc__vertex *a = &o->s->v[sg], *c = &o->s->v[a->next];
        float d = polyc__seg_dist2(x, y, a->x, a->y, c->x, c->y);
        if (d < best)
            best = d;
    }
    return best;
}

/* Whether an end is looked at: always, but in an online round only when
 * it or its neighbour was edited since the region's stamp. An end outside
 * the region lies where nothing changed: what could overlap it or merge
 * with it there is itself in the region, and is looked at from that side
 * (merge) or by the zip (an edited segment along it). */
static int in_region(const polyc__opt *o, int32_t e)
{
    if (o->region_since == 0)
        return 1;
    const polyc__vertex *v = &o->s->v[e];
    int32_t n = v->next != POLYC__NONE ? v->next : v->prev;
    return o->v_touch[e] >= o->region_since || (n != POLYC__NONE && o->v_touch[n] >= o->region_since);
}

/* ---- A: overlaps ---- */

/* Whether the segment from vertex e to its neighbour e2 runs along other
 * segments: its two vertices and points along it, at most overlap_m apart,
 * all lie within overlap_m of segments of other polylines (or of its own,
 * away from it). The ends alone are not enough: a wall between two corners
 * traced as separate polylines has both ends within reach of them. On a
 * real log that test takes segments a metre or more long, bridging two
 * other polylines, for overlaps, and zipping them away raises the BIC each
 * iteration by much more than the rest of the iteration wins back. */
static int runs_along(const polyc__opt *o, int32_t e, int32_t e2, float lim)
{
    const polyc__vertex *a = &o->s->v[e], *b = &o->s->v[e2];
    float lim2 = lim * lim;
    if (other_dist2(o, a->x, a->y, e) > lim2 || other_dist2(o, b->x, b->y, e2) > lim2)
        return 0;
    float dx = b->x - a->x, dy = b->y - a->y;
    int n = (int)ceilf(sqrtf(dx * dx + dy * dy) / lim);
    for (int k = 1; k < n; k++) {
        float t = (float)k / (float)n;
        if (other_dist2(o, a->x + t * dx, a->y + t * dy, e2) > lim2)
            return 0;
    }
    return 1;
}

/* An open polyline whose end segment runs along another polyline (every
 * point of it within overlap_m of one, runs_along) loses that end vertex,
 * repeatedly: the duplicate stretch is zipped away and the ends are left
 * for merging. */
int polyc__op_overlaps(polyc__opt *o)
{
    polyc__store *s = o->s;
    float lim2 = o->cfg->overlap_m * o->cfg->overlap_m;
    int changed = 0;
    if (lim2 <= 0.0f)
        return 0;
    for (int32_t l = 0; l < s->l_high; l++) {
        for (int side = 0; side < 2; side++) {
            for (;;) {
                const polyc__line *ln = &s->l[l];
                if (ln->closed != 0 || ln->count < 2)
                    break;
                int32_t e = side ? ln->tail : ln->head;
                int32_t e2 = side ? s->v[e].prev : s->v[e].next;
                if (!in_region(o, e) || !runs_along(o, e, e2, o->cfg->overlap_m))
                    break;
                polyc__apply_remove(o, e);
                changed++;
            }
        }
    }
    return changed;
}

/* ---- B: merge ---- */

/* The nearest open end (head or tail of another polyline, or the other end
 * of its own when that would close a polyline of 3 or more) within reach. */
static int32_t nearest_end(const polyc__opt *o, int32_t e, float lim2)
{
    const polyc__hash *h = &o->h;
    const polyc__store *s = o->s;
    int32_t best_v = POLYC__NONE;
    float best = lim2;
    float x = s->v[e].x, y = s->v[e].y;
    polyc__near_segs w;
    POLYC__FOR_NEAR_SEGS(w, h, x, y, sg) {
        int32_t cand[2] = {sg, s->v[sg].next};
        for (int k = 0; k < 2; k++) {
            int32_t f = cand[k];
            const polyc__vertex *fv = &s->v[f];
            if (f == e || (fv->prev != POLYC__NONE && fv->next != POLYC__NONE))
                continue; /* not an open end */
            if (fv->line == s->v[e].line && s->l[fv->line].count < 3)
                continue;
            float dx = fv->x - x, dy = fv->y - y, d = dx * dx + dy * dy;
            if (d < best) {
                best = d;
                best_v = f;
            }
        }
    }
    return best_v;
}

static int is_head(const polyc__opt *o, int32_t v)
{
    return o->s->v[v].prev == POLYC__NONE;
}

/* Whether the polylines of ends e and f leave them within 30 degrees of
 * one direction: linked, they would make a hairpin. */
static int would_fold(const polyc__opt *o, int32_t e, int32_t f)
{
    const polyc__vertex *V = o->s->v;
    int32_t en = V[e].prev != POLYC__NONE ? V[e].prev : V[e].next;
    int32_t fn = V[f].prev != POLYC__NONE ? V[f].prev : V[f].next;
    float ax = V[en].x - V[e].x, ay = V[en].y - V[e].y;
    float bx = V[fn].x - V[f].x, by = V[fn].y - V[f].y;
    float la = sqrtf(ax * ax + ay * ay), lb = sqrtf(bx * bx + by * by);
    return ax * bx + ay * by > 0.866f * la * lb;
}

/* The change of the BIC if ends e and f are linked by a segment: the
 * error it explains (the points between them) and the turn costs of the
 * two ends that become corners; the vertex count stays. */
static float link_delta(polyc__opt *o, int32_t e, int32_t f)
{
    const polyc__vertex *E = &o->s->v[e], *F = &o->s->v[f];
    const float xy[4] = {E->x, E->y, F->x, F->y};
    float derr = polyc__local_delta(o, NULL, 0, xy, 1, 0.0f);
    if (derr >= 0.0f)
        return derr; /* (nothing explained: no gain whatever the turns) */
    int32_t pe = E->prev != POLYC__NONE ? E->prev : E->next;
    int32_t pf = F->prev != POLYC__NONE ? F->prev : F->next;
    float dangle = 0.0f;
    if (pe != POLYC__NONE)
        dangle += polyc__turn_cost(o, o->s->v[pe].x, o->s->v[pe].y, E->x, E->y, F->x, F->y);
    if (pf != POLYC__NONE)
        dangle += polyc__turn_cost(o, E->x, E->y, F->x, F->y, o->s->v[pf].x, o->s->v[pf].y);
    return o->cfg->alpha * (derr + o->cfg->gamma * dangle);
}

/* Ends closer than merge_dist_m are linked by a segment; the vertex
 * removal operator later fuses the two ends when that lowers the BIC.
 * Ends up to twice that apart are linked when the link lowers the BIC
 * (data between them that the link explains): a ring whose ends the
 * search has pulled 18 cm apart on a circle stays open otherwise. */
int polyc__op_merge(polyc__opt *o)
{
    return polyc__op_merge_folds(o, POLYC__HAIRPINS_ALLOWED);
}

int polyc__op_merge_folds(polyc__opt *o, polyc__hairpins hairpins)
{
    polyc__store *s = o->s;
    float lim2 = o->cfg->merge_dist_m * o->cfg->merge_dist_m, bridge2 = 4.0f * lim2;
    int changed = 0;
    for (int32_t l = 0; l < s->l_high; l++) {
        for (int side = 0; side < 2; side++) {
            const polyc__line *ln = &s->l[l];
            if (ln->closed != 0 || ln->count < 2)
                continue;
            int32_t e = side ? ln->tail : ln->head;
            if (!in_region(o, e))
                continue;
            int32_t f = nearest_end(o, e, lim2);
            int bridge = f == POLYC__NONE;
            if (bridge)
                f = nearest_end(o, e, bridge2);
            if (f == POLYC__NONE || polyc__link_crosses(o, e, f) ||
                (hairpins == POLYC__HAIRPINS_REFUSED && would_fold(o, e, f)))
                continue; /* (a link through a wall would be cut again) */
            if (bridge && link_delta(o, e, f) >= 0.0f)
                continue;
            polyc__chg_begin(o);
            int32_t le = s->v[e].line, lf = s->v[f].line;
            if (le == lf) {
                int32_t t = is_head(o, e) ? f : e;
                polyc__op_link(o, t, t == e ? f : e);
            } else {
                /* orient so that e ends its polyline and f starts its own */
                if (is_head(o, e) && !is_head(o, f)) {
                    int32_t t = e;
                    e = f;
                    f = t;
                } else if (is_head(o, e)) {
                    polyc__op_reverse(o, le);
                } else if (!is_head(o, f)) {
                    polyc__op_reverse(o, lf);
                }
                polyc__op_link(o, e, f);
            }
            polyc__chg_commit(o);
            changed++;
        }
    }
    return changed;
}

/* ---- E: zigzags ---- */

/* A vertex where the polyline folds back on itself (turn above 150 degrees)
 * is a zigzag left by vertex moves: it goes, unless that raises the BIC (a
 * fold can be real: removing every fold unconditionally lost whole walls).
 * A spike (turn above 120 degrees on two legs shorter than 30 cm, as moves
 * leave at corners) goes even if the BIC rises by up to one vertex's worth. */
int polyc__op_zigzag(polyc__opt *o)
{
    polyc__store *s = o->s;
    int changed = 0;
    for (int32_t v = 0; v < s->v_high; v++) {
        const polyc__vertex *c = &s->v[v];
        if (c->line == POLYC__NONE || c->prev == POLYC__NONE || c->next == POLYC__NONE)
            continue;
        const polyc__vertex *a = &s->v[c->prev], *b = &s->v[c->next];
        float ux = c->x - a->x, uy = c->y - a->y, wx = b->x - c->x, wy = b->y - c->y;
        float lu = sqrtf(ux * ux + uy * uy), lw = sqrtf(wx * wx + wy * wy);
        float dot = ux * wx + uy * wy;
        /* (a zero-length segment counts: its vertex is a duplicate) */
        int fold = lu * lw <= 0.0f || dot < -0.866f * lu * lw;
        int spike = lu < 0.3f && lw < 0.3f && dot < -0.5f * lu * lw;
        if (!fold && !spike)
            continue;
        float bound = spike ? o->d.log_n : 0.0f;
        if (polyc__removal_delta_below(o, v, bound) >= bound)
            continue;
        polyc__apply_remove(o, v);
        changed++;
    }
    return changed;
}

/* A fold whose shorter leg ends within overlap_m of the longer leg draws
 * that stretch of wall twice: it goes whatever the BIC, as crossings and
 * double cover do (a wall that runs a hand's breadth past its corner and
 * comes back at under a degree; a short end folded back at a sharp angle;
 * two legs of a few decimetres turning through two vertices a few cm
 * apart). Such folds escaped band15 and double cover alike when short,
 * and the zigzag's BIC test kept them. A
 * thin wall's end drawn round has its faces farther apart and stays. Run
 * on the map the search keeps (and after each online round), not in its
 * iterations, whose folds the next moves often undo: removing them there
 * too moved the search's path, and the simulated scenes' batch maps came
 * out no better, fewer of them on target. */
static int is_fold(const polyc__vertex *a, const polyc__vertex *c, const polyc__vertex *b)
{
    float ux = c->x - a->x, uy = c->y - a->y, wx = b->x - c->x, wy = b->y - c->y;
    float lu = sqrtf(ux * ux + uy * uy), lw = sqrtf(wx * wx + wy * wy);
    return lu * lw > 0.0f && ux * wx + uy * wy < -0.866f * lu * lw; /* (as op_zigzag) */
}

/* The fold at vertex v that doubles its shorter leg: the other end of that
 * leg (NONE: no such fold at v). */
static int32_t doubled_leg_end(const polyc__opt *o, int32_t v)
{
    const polyc__store *s = o->s;
    const polyc__vertex *c = &s->v[v];
    if (c->line == POLYC__NONE || c->prev == POLYC__NONE || c->next == POLYC__NONE)
        return POLYC__NONE;
    const polyc__vertex *a = &s->v[c->prev], *b = &s->v[c->next];
    if (!is_fold(a, c, b))
        return POLYC__NONE;
    float lu = sqrtf((c->x - a->x) * (c->x - a->x) + (c->y - a->y) * (c->y - a->y));
    float lw = sqrtf((b->x - c->x) * (b->x - c->x) + (b->y - c->y) * (b->y - c->y));
    float tol2 = o->cfg->overlap_m * o->cfg->overlap_m;
    /* the shorter leg's far end, and its distance from the longer leg */
    int32_t f = lu <= lw ? c->prev : c->next;
    const polyc__vertex *e = &s->v[f], *l0 = lu <= lw ? c : a, *l1 = lu <= lw ? b : c;
    return polyc__seg_dist2(e->x, e->y, l0->x, l0->y, l1->x, l1->y) <= tol2 ? f : POLYC__NONE;
}

/* A fold that turns through two vertices, v and the next, at most
 * overlap_m apart: the segment before v and the one after its next turn
 * by over 150 degrees, and the shorter of them ends within overlap_m of
 * the longer. One of the two vertices goes (the one whose removal costs
 * less), leaving the fold at the other; returns that one (NONE: no such
 * fold at v). */
static int32_t close_cap(polyc__opt *o, int32_t v)
{
    const polyc__store *s = o->s;
    const polyc__vertex *b = &s->v[v];
    if (b->line == POLYC__NONE || b->prev == POLYC__NONE || b->next == POLYC__NONE)
        return POLYC__NONE;
    int32_t w = b->next;
    const polyc__vertex *a = &s->v[b->prev], *c = &s->v[w];
    if (c->next == POLYC__NONE || c->next == b->prev)
        return POLYC__NONE;
    const polyc__vertex *d = &s->v[c->next];
    float cap2 = (c->x - b->x) * (c->x - b->x) + (c->y - b->y) * (c->y - b->y);
    float tol2 = o->cfg->overlap_m * o->cfg->overlap_m;
    float ux = b->x - a->x, uy = b->y - a->y, wx = d->x - c->x, wy = d->y - c->y;
    float lu = sqrtf(ux * ux + uy * uy), lw = sqrtf(wx * wx + wy * wy);
    if (cap2 > tol2 || !(lu * lw > 0.0f) || ux * wx + uy * wy >= -0.866f * lu * lw)
        return POLYC__NONE;
    /* the shorter leg's far end against the longer leg */
    const polyc__vertex *e = lu <= lw ? a : d, *l0 = lu <= lw ? c : a, *l1 = lu <= lw ? d : b;
    if (polyc__seg_dist2(e->x, e->y, l0->x, l0->y, l1->x, l1->y) > tol2)
        return POLYC__NONE;
    float db = polyc__removal_delta_below(o, v, FLT_MAX);
    float dc = polyc__removal_delta_below(o, w, FLT_MAX);
    if ((db < dc ? db : dc) >= FLT_MAX)
        return POLYC__NONE; /* (a single scan's return stays on the map: INFINITY) */
    polyc__apply_remove(o, db < dc ? v : w);
    return db < dc ? w : v;
}

/* Removing f, the doubled leg's far end, leaves no fold at v (f an end of
 * its polyline: the leg goes with it). */
static int unfolds(const polyc__opt *o, int32_t v, int32_t f)
{
    const polyc__store *s = o->s;
    const polyc__vertex *c = &s->v[v];
    int32_t g = f == c->prev ? s->v[f].prev : s->v[f].next;
    if (g == POLYC__NONE)
        return 1;
    if (g == (f == c->prev ? c->next : c->prev))
        return 0; /* (a closed triangle) */
    if (f == c->prev)
        return !is_fold(&s->v[g], c, &s->v[c->next]);
    return !is_fold(&s->v[c->prev], c, &s->v[g]);
}

int polyc__op_unfold(polyc__opt *o)
{
    polyc__store *s = o->s;
    int changed = 0;
    for (int32_t u = 0; u < s->v_high; u++) {
        int32_t v = close_cap(o, u);
        if (v != POLYC__NONE)
            changed++;
        else
            v = u;
        int32_t f = doubled_leg_end(o, v);
        if (f == POLYC__NONE)
            continue;
        /* the fold's vertex, or the leg's far end where that keeps the map
         * nearer its data (a corner's vertex at the fold: a short end
         * folded back past the corner) */
        float dv = polyc__removal_delta_below(o, v, FLT_MAX);
        float df = unfolds(o, v, f) ? polyc__removal_delta_below(o, f, FLT_MAX) : HUGE_VALF;
        int32_t go = df < dv ? f : v;
        if ((df < dv ? df : dv) >= FLT_MAX)
            continue; /* (a single scan's return stays on the map: INFINITY) */
        polyc__apply_remove(o, go);
        changed++;
    }
    return changed;
}
