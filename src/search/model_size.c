/* model_size.c - the number of vertices (paper IV.G).
 * Takes: the optimiser state. Gives: vertices removed best-first while a
 * removal lowers the BIC (a lazy priority queue: every candidate is
 * re-evaluated before it is applied), and vertices added on the segments
 * with the largest mean squared distance when that lowers the BIC. */
#include "../cost.h"

#include <math.h>
#include <string.h>

int polyc__size_carve(polyc__arena *a, polyc__size_scratch *sz, int32_t V)
{
    int ok = 1;
    POLYC__CARVE(ok, a, sz->seg_sum, V);
    POLYC__CARVE(ok, a, sz->seg_w, V);
    POLYC__CARVE(ok, a, sz->seg_far_d, V);
    POLYC__CARVE(ok, a, sz->seg_far, V);
    POLYC__CARVE_ZERO(ok, a, sz->add_failed, V);
    /* A pass pushes each live vertex once, and each removal pops one
     * candidate and pushes at most its two neighbours: the heap never holds
     * more than twice the vertices, so a small store's spare is V. A
     * candidate that finds it full is not retried. */
    sz->heap_cap = V + (V < POLYC__HEAP_SPARE ? V : POLYC__HEAP_SPARE);
    POLYC__CARVE(ok, a, sz->heap, sz->heap_cap);
    return ok;
}


static void heap_push(polyc__opt *o, float delta, int32_t v)
{
    if (o->size.heap_n >= o->size.heap_cap)
        return; /* full: the candidate is simply not retried */
    polyc__heap_entry *h = o->size.heap;
    int32_t i = o->size.heap_n++;
    while (i > 0) {
        int32_t p = (i - 1) / 2;
        if (h[p].delta <= delta)
            break;
        h[i] = h[p];
        i = p;
    }
    h[i].delta = delta;
    h[i].v = v;
    h[i].pad = 0;
}

static polyc__heap_entry heap_pop(polyc__opt *o)
{
    polyc__heap_entry *h = o->size.heap;
    polyc__heap_entry top = h[0], last = h[--o->size.heap_n];
    int32_t i = 0;
    for (;;) {
        int32_t c = 2 * i + 1;
        if (c >= o->size.heap_n)
            break;
        if (c + 1 < o->size.heap_n && h[c + 1].delta < h[c].delta)
            c++;
        if (last.delta <= h[c].delta)
            break;
        h[i] = h[c];
        i = c;
    }
    h[i] = last;
    return top;
}

/* Change of the BIC if v is removed (see polyc__op_remove for the cases),
 * exact if it is below `bound`, else some value >= bound: proving that a
 * removal does not pay needs fewer nearest-segment queries than its value. */
float polyc__removal_delta_below(polyc__opt *o, int32_t v, float bound)
{
    const polyc__store *s = o->s;
    const polyc__vertex *V = s->v;
    const polyc__line *ln = &s->l[V[v].line];
    int32_t p = V[v].prev, n = V[v].next;
    float gamma = (float)o->cfg->gamma;
    int32_t old[3];
    int n_old = 0;
    float xy[4];
    int n_new = 0;
    float dk, dangle;
    if (!ln->closed && ln->count == 2) {
        if (o->rays.on)
            return INFINITY; /* a single scan's return stays on the map */
        old[n_old++] = p != POLYC__NONE ? p : v;
        dk = -2.0f;
        dangle = 0.0f;
    } else if (p == POLYC__NONE || n == POLYC__NONE) {
        int32_t nb = p == POLYC__NONE ? n : p;
        if (o->rays.on && polyc__holds_returns(&o->rays, V[v].x, V[v].y, V[nb].x, V[nb].y))
            return INFINITY; /* a single scan's end return stays on the map */
        old[n_old++] = p == POLYC__NONE ? v : p;
        dk = -1.0f;
        dangle = -o->acost[nb]; /* the neighbour becomes an end: no angle */
    } else {
        old[n_old++] = p;
        old[n_old++] = v;
        if (ln->closed && ln->count == 3)
            old[n_old++] = n; /* the triangle opens into one segment */
        xy[0] = V[p].x;
        xy[1] = V[p].y;
        xy[2] = V[n].x;
        xy[3] = V[n].y;
        if (o->rays.on) {
            float old_xy[4 * POLYC__EDIT_SEGS];
            int n_xy = polyc__edit_segments(o, old, n_old, old_xy);
            if (polyc__blocks_beams(&o->rays, xy[0], xy[1], xy[2], xy[3], old_xy, n_xy) ||
                polyc__loses_returns(&o->rays, old_xy, n_xy, xy, 1))
                return INFINITY; /* a single scan saw through there, or a return would go */
        }
        n_new = 1;
        dk = -1.0f;
        dangle = -o->acost[p] - o->acost[v] - o->acost[n];
        if (!(ln->closed && ln->count == 3) && gamma > 0.0f) {
            /* new angles at p and n with v gone */
            int32_t pp = V[p].prev, nn = V[n].next;
            if (pp != POLYC__NONE && pp != n)
                dangle += polyc__turn_cost(o, V[pp].x, V[pp].y, V[p].x, V[p].y, V[n].x, V[n].y);
            if (nn != POLYC__NONE && nn != p)
                dangle += polyc__turn_cost(o, V[p].x, V[p].y, V[n].x, V[n].y, V[nn].x, V[nn].y);
        }
    }
    float alpha = (float)o->cfg->alpha;
    /* delta < bound  <=>  derr < limit */
    float limit = isinf(bound) ? bound : (bound - dk * o->d.log_n) / alpha - gamma * dangle;
    float derr = polyc__local_delta(o, old, n_old, xy, n_new, limit);
    return alpha * (derr + gamma * dangle) + dk * o->d.log_n;
}

/* Candidates: the vertices edited at or after touch stamp `since` (0: all);
 * a removal that did not pay before pays later only if something near it
 * changed. */
int polyc__op_remove_vertices(polyc__opt *o, uint32_t since)
{
    polyc__store *s = o->s;
    o->size.heap_n = 0;
    for (int32_t v = 0; v < s->v_high; v++) {
        if (s->v[v].line == POLYC__NONE || o->v_touch[v] < since)
            continue;
        float d = polyc__removal_delta_below(o, v, 0.0f);
        if (d < 0.0f)
            heap_push(o, d, v);
    }
    int removed = 0;
    while (o->size.heap_n > 0) {
        polyc__heap_entry e = heap_pop(o);
        if (s->v[e.v].line == POLYC__NONE)
            continue;
        float d = polyc__removal_delta_below(o, e.v, 0.0f);
        if (d >= 0.0f)
            continue;
        if (o->size.heap_n > 0 && d > o->size.heap[0].delta + 1e-9f) {
            heap_push(o, d, e.v); /* no longer the best: back in line */
            continue;
        }
        int32_t p = s->v[e.v].prev, n = s->v[e.v].next;
        polyc__apply_remove(o, e.v);
        removed++;
        /* the neighbours' removals changed: offer them again */
        int32_t nb[2] = {p, n};
        for (int k = 0; k < 2; k++) {
            if (nb[k] == POLYC__NONE || s->v[nb[k]].line == POLYC__NONE)
                continue;
            float dn = polyc__removal_delta_below(o, nb[k], 0.0f);
            if (dn < 0.0f)
                heap_push(o, dn, nb[k]);
        }
    }
    return removed;
}

/* Per segment (in the region): summed cost and weight of its points, and
 * its farthest point. */
static void segment_stats(polyc__opt *o)
{
    for (int32_t v = 0; v < o->s->v_high; v++) {
        o->size.seg_sum[v] = 0.0f;
        o->size.seg_w[v] = 0.0f;
        o->size.seg_far[v] = POLYC__NONE;
        o->size.seg_far_d[v] = -1.0f;
    }
    int32_t np = polyc__region_points(o, polyc__in_region);
    const int32_t *list = np >= 0 ? o->region_pt : NULL;
    np = np >= 0 ? np : o->d.np;
    for (int32_t j = 0; j < np; j++) {
        int32_t i = list ? list[j] : j;
        int32_t sg = o->d.pt_seg[i];
        if (sg == POLYC__NONE || !polyc__in_region(o, sg))
            continue;
        float w = o->d.pts[i].w, c = (float)o->d.pt_cost[i];
        o->size.seg_sum[sg] += c;
        o->size.seg_w[sg] += w;
        if (c / w > o->size.seg_far_d[sg]) {
            o->size.seg_far_d[sg] = c / w;
            o->size.seg_far[sg] = i;
        }
    }
}

#define ADD_CANDIDATES 8

void polyc__size_forget(polyc__opt *o)
{
    for (int32_t v = 0; v < o->s->v_high; v++)
        o->size.add_failed[v] = 0;
}

/* The four vertices an addition on segment u-w depends on: its ends and
 * their neighbours (the trial climbs u, w and the new vertex; without
 * noise it is a function of them and of the data, which stay put during a
 * search). */
static void addition_near(const polyc__opt *o, int32_t u, int32_t w, int32_t near[4])
{
    const polyc__vertex *V = o->s->v;
    near[0] = V[u].prev;
    near[1] = u;
    near[2] = w;
    near[3] = V[w].next;
}

/* A digest of those vertices' ids and positions (never 0). */
static uint32_t addition_digest(const polyc__opt *o, const int32_t near[4])
{
    uint32_t h = 2166136261u;
    for (int k = 0; k < 4; k++) {
        uint32_t word[3] = {(uint32_t)near[k], 0u, 0u};
        if (near[k] != POLYC__NONE) {
            memcpy(&word[1], &o->s->v[near[k]].x, sizeof word[1]);
            memcpy(&word[2], &o->s->v[near[k]].y, sizeof word[2]);
        }
        for (int j = 0; j < 3; j++)
            h = (h ^ word[j]) * 16777619u;
    }
    return h != 0u ? h : 1u;
}

/* Whether the addition on segment u-w failed before with its four vertices
 * where they are now: the same trial would fail the same way. */
static int failed_before(const polyc__opt *o, int32_t u, int32_t w)
{
    int32_t near[4];
    addition_near(o, u, w, near);
    return o->size.add_failed[u] != 0 && o->size.add_failed[u] == addition_digest(o, near);
}

/* Tries a vertex at the farthest point of the worst segments (largest mean
 * squared distance); each is adjusted with its neighbours and kept only if
 * the BIC falls. */
int polyc__op_add_vertices(polyc__opt *o, int max_tries)
{
    polyc__store *s = o->s;
    int added = 0;
    for (int round = 0; round < max_tries; round++) {
        segment_stats(o);
        int32_t cand[ADD_CANDIDATES];
        float score[ADD_CANDIDATES];
        int nc = 0;
        for (int32_t v = 0; v < s->v_high; v++) {
            if (s->v[v].line == POLYC__NONE || s->v[v].next == POLYC__NONE || o->size.seg_w[v] < 4.0f ||
                o->size.seg_far[v] == POLYC__NONE)
                continue;
            float m = (float)(o->size.seg_sum[v] / o->size.seg_w[v]);
            if (nc == ADD_CANDIDATES && m <= score[nc - 1])
                continue;
            int k = nc < ADD_CANDIDATES ? nc++ : nc - 1;
            while (k > 0 && score[k - 1] < m) {
                score[k] = score[k - 1];
                cand[k] = cand[k - 1];
                k--;
            }
            score[k] = m;
            cand[k] = v;
        }
        int any = 0;
        for (int c = 0; c < nc; c++) {
            int32_t u = cand[c];
            if (s->v[u].line == POLYC__NONE || s->v[u].next == POLYC__NONE)
                continue;
            int32_t w = s->v[u].next;
            int32_t far = o->size.seg_far[u];
            if (o->d.pt_seg[far] != u)
                continue; /* stale after an earlier addition */
            if (failed_before(o, u, w))
                continue; /* (the same trial would fail the same way) */
            float old_xy[4 * POLYC__EDIT_SEGS];
            int n_xy = o->rays.on ? polyc__edit_segments(o, &u, 1, old_xy) : 0;
            if (o->rays.on &&
                (polyc__blocks_beams(&o->rays, s->v[u].x, s->v[u].y, o->d.pts[far].x, o->d.pts[far].y,
                                     old_xy, n_xy) ||
                 polyc__blocks_beams(&o->rays, o->d.pts[far].x, o->d.pts[far].y, s->v[w].x, s->v[w].y,
                                     old_xy, n_xy)))
                continue;
            float before = polyc__bic(o);
            float ux = s->v[u].x, uy = s->v[u].y, wx = s->v[w].x, wy = s->v[w].y;
            polyc__chg_begin(o);
            int32_t v = polyc__op_insert_after(o, u, o->d.pts[far].x, o->d.pts[far].y);
            polyc__chg_commit(o);
            if (v == POLYC__NONE)
                return added;
            for (int k = 0; k < 2; k++) {
                polyc__hill_climb(o, v);
                polyc__hill_climb(o, u);
                polyc__hill_climb(o, w);
            }
            if (polyc__bic(o) < before - 1e-6f * fabsf(before)) { /* (as optimize.c) */
                added++;
                any = 1;
                continue;
            }
            /* not better: undo */
            polyc__chg_begin(o);
            polyc__op_remove(o, v);
            polyc__op_move(o, u, ux, uy);
            polyc__op_move(o, w, wx, wy);
            polyc__chg_commit(o);
            int32_t near[4];
            addition_near(o, u, w, near);
            o->size.add_failed[u] = addition_digest(o, near);
        }
        if (!any)
            break;
    }
    return added;
}
