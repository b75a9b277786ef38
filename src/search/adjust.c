/* adjust.c - vertex positions (paper IV.D and IV.F).
 * Takes: the optimiser state. Gives: hill climbing of each vertex in 8
 * directions with a fixed step while the BIC falls, evaluated on the points
 * near its two segments only; and Gaussian noise on all vertices. */
#include "../cost.h"

#include <math.h>

static const float DIR_X[8] = {1.0f, 0.70710678f, 0.0f, -0.70710678f, -1.0f, -0.70710678f, 0.0f, 0.70710678f};
static const float DIR_Y[8] = {0.0f, 0.70710678f, 1.0f, 0.70710678f, 0.0f, -0.70710678f, -1.0f, -0.70710678f};

/* The prior at the three vertices whose angles a move of v changes: its
 * neighbours stay put, v's cell is looked up again when it changes. */
typedef struct angle_places {
    polyc__prior_place prev, at, next;
} angle_places;

/* The prior at vertex u into *out: a copy of *same when u lies in its
 * cell (a prior cell is a grid tile: neighbours often share one). */
static void place_of(const polyc__opt *o, int32_t u, const polyc__prior_place *same,
                     polyc__prior_place *out)
{
    const polyc__vertex *V = o->s->v;
    if (polyc__prior_same_place(&o->prior, same, V[u].x, V[u].y))
        *out = *same;
    else
        polyc__prior_at(&o->prior, V[u].x, V[u].y, out);
}

static void places_init(const polyc__opt *o, int32_t v, angle_places *pl)
{
    const polyc__vertex *V = o->s->v;
    pl->prev.valid = pl->next.valid = 0;
    polyc__prior_at(&o->prior, V[v].x, V[v].y, &pl->at);
    if (V[v].prev != POLYC__NONE)
        place_of(o, V[v].prev, &pl->at, &pl->prev);
    if (V[v].next != POLYC__NONE)
        place_of(o, V[v].next, &pl->at, &pl->next);
}

/* Angle terms of v's neighbourhood with v at (x, y). */
static float local_angles(const polyc__opt *o, angle_places *pl, int32_t v, float x, float y)
{
    if (o->cfg->gamma <= 0.0f)
        return 0.0f;
    const polyc__vertex *V = o->s->v;
    int32_t p = V[v].prev, n = V[v].next;
    float sum = 0.0f;
    if (p != POLYC__NONE && n != POLYC__NONE) {
        if (!polyc__prior_same_place(&o->prior, &pl->at, x, y))
            polyc__prior_at(&o->prior, x, y, &pl->at);
        sum += 1.0f - (float)polyc__prior_p_at(&pl->at, polyc__turn_of(V[p].x, V[p].y, x, y, V[n].x, V[n].y));
    }
    if (p != POLYC__NONE && V[p].prev != POLYC__NONE && V[p].prev != v)
        sum += 1.0f - (float)polyc__prior_p_at(
                         &pl->prev, polyc__turn_of(V[V[p].prev].x, V[V[p].prev].y, V[p].x, V[p].y, x, y));
    if (n != POLYC__NONE && V[n].next != POLYC__NONE && V[n].next != v)
        sum += 1.0f - (float)polyc__prior_p_at(
                         &pl->next, polyc__turn_of(x, y, V[n].x, V[n].y, V[V[n].next].x, V[V[n].next].y));
    return sum;
}

static int segs_at(const polyc__opt *o, int32_t v, float x, float y, float *xy)
{
    const polyc__vertex *V = o->s->v;
    int n = 0;
    if (V[v].prev != POLYC__NONE) {
        xy[4 * n] = V[V[v].prev].x;
        xy[4 * n + 1] = V[V[v].prev].y;
        xy[4 * n + 2] = x;
        xy[4 * n + 3] = y;
        n++;
    }
    if (V[v].next != POLYC__NONE) {
        xy[4 * n] = x;
        xy[4 * n + 1] = y;
        xy[4 * n + 2] = V[V[v].next].x;
        xy[4 * n + 3] = V[V[v].next].y;
        n++;
    }
    return n;
}

/* Commits the move of v to (x, y) found by hill_climb from its local
 * evaluation: every point whose cost can change is in the prepared list or
 * aggregated on one of v's segments (those on v's segments are never
 * pruned), so nothing is rescored twice. */
static void commit_move(polyc__opt *o, int32_t v, float x, float y)
{
    polyc__vertex *V = o->s->v;
    int32_t p = V[v].prev, n = V[v].next;
    int32_t nb[3] = {p, v, n};
    for (int k = 0; k < 3; k++)
        if (nb[k] != POLYC__NONE) {
            polyc__ksum_add(&o->angle, -(o->acost[nb[k]]));
            o->v_touch[nb[k]] = o->touch_stamp;
        }
    if (p != POLYC__NONE)
        polyc__hash_remove(o, p);
    if (n != POLYC__NONE)
        polyc__hash_remove(o, v);
    V[v].x = x;
    V[v].y = y;
    int ok = 1;
    if (p != POLYC__NONE)
        ok &= polyc__hash_insert(o, p);
    if (n != POLYC__NONE)
        ok &= polyc__hash_insert(o, v);
    (void)ok; /* a full hash is reported by the search loop */
    float xy[8];
    int32_t id[2];
    int ns = segs_at(o, v, x, y, xy);
    id[0] = p != POLYC__NONE ? p : v;
    id[1] = v;
    for (int32_t k = 0; k < o->ev.loc_n; k++) {
        int32_t i = o->ev.loc_pt[k];
        float c = o->ev.loc_base[k];
        int32_t sg = o->ev.loc_seg[k];
        for (int j = 0; j < ns; j++) {
            float cj = polyc__cost(&o->d.pts[i], xy[4 * j], xy[4 * j + 1], xy[4 * j + 2], xy[4 * j + 3]);
            if (cj < c) {
                c = cj;
                sg = id[j];
            }
        }
        polyc__ksum_add(&o->err, c - o->d.pt_cost[i]);
        o->d.pt_cost[i] = c;
        polyc__split_due_pt(o, o->d.pt_seg[i], sg);
        o->d.pt_seg[i] = sg;
    }
    /* the aggregated points: on their segment, whatever the move */
    for (int j = 0; j < ns; j++)
        for (int32_t k = 0; k < o->ev.agg_n[j]; k++) {
            int32_t i = o->ev.agg_pt[j == 0 ? k : o->ev.agg_cap - 1 - k];
            float c = polyc__cost(&o->d.pts[i], xy[4 * j], xy[4 * j + 1], xy[4 * j + 2], xy[4 * j + 3]);
            polyc__ksum_add(&o->err, c - o->d.pt_cost[i]);
            o->d.pt_cost[i] = c;
            polyc__split_due_pt(o, o->d.pt_seg[i], id[j]);
            o->d.pt_seg[i] = id[j];
        }
    for (int k = 0; k < 3; k++)
        if (nb[k] != POLYC__NONE) {
            o->acost[nb[k]] = polyc__vertex_angle_cost(o, nb[k]);
            polyc__ksum_add(&o->angle, o->acost[nb[k]]);
        }
}

/* Moves v by steps of step_m while the local score (error plus gamma times
 * the angle terms) falls; the move is then committed as one change.
 * Returns 0 if v did not move, 1 if it stopped at a local optimum, 2 if it
 * moved but stopped at the reach or the step cap (worth climbing again). */
int polyc__hill_climb(polyc__opt *o, int32_t v)
{
    const polyc__vertex *V = o->s->v;
    if (V[v].line == POLYC__NONE || (V[v].prev == POLYC__NONE && V[v].next == POLYC__NONE))
        return 0;
    float step = o->cfg->step_m, gamma = o->cfg->gamma;
    float reach = POLYC__CLIMB_REACH_M - step; /* the hash buckets cover this much movement */
    float x0 = V[v].x, y0 = V[v].y, x = x0, y = y0;
    int32_t old[2] = {V[v].prev, V[v].next != POLYC__NONE ? v : POLYC__NONE};
    float xy[8];
    int ns = segs_at(o, v, x, y, xy);
    polyc__local_prepare_move(o, old, 2, xy, ns, reach + step, x, y);
    angle_places pl;
    if (gamma > 0.0f)
        places_init(o, v, &pl);
    float cur = polyc__local_current(o) + (float)gamma * local_angles(o, &pl, v, x, y);
    int moved = 0, last = -1;
    int optimum = 0, cut = 0; /* no better trial in the last round; some trial was beyond reach */
    for (int it = 0; it < POLYC__CLIMB_STEPS; it++) {
        cut = 0;
        float best = cur;
        int best_d = -1;
        /* the direction that paid last time first: if it pays again, take
         * it without trying the other seven */
        for (int k = 0; k < 9; k++) {
            int d = k == 0 ? last : k - 1;
            /* nor back where the last step came from: it cost more */
            if (d < 0 || (k > 0 && (d == last || (last >= 0 && d == (last + 4) % 8))))
                continue;
            float cx = x + step * DIR_X[d], cy = y + step * DIR_Y[d];
            if ((cx - x0) * (cx - x0) + (cy - y0) * (cy - y0) > reach * reach) {
                cut = 1;
                continue;
            }
            ns = segs_at(o, v, cx, cy, xy);
            float e = polyc__local_eval(o, xy, ns) + (float)gamma * local_angles(o, &pl, v, cx, cy);
            if (e < best - 1e-12f * (1.0f + fabsf(best))) {
                best = e;
                best_d = d;
                if (k == 0)
                    break;
            }
        }
        if (best_d < 0) {
            optimum = 1;
            break;
        }
        x += step * DIR_X[best_d];
        y += step * DIR_Y[best_d];
        cur = best;
        last = best_d;
        moved = 1;
    }
    /* a single scan: no climb may put a segment in front of a return it
     * did not stand in front of before */
    if (!moved || polyc__vertex_blocks(o, v, x, y))
        return 0;
    commit_move(o, v, x, y);
    return optimum && !cut ? 1 : 2;
}

/* Rounds of hill climbing; after the first, only vertices next to one that
 * moved in the previous round are climbed again (for a single scan, only
 * those that stopped at the reach). The first round takes the
 * vertices edited at or after touch stamp `since` (0: all). */
int polyc__op_adjust(polyc__opt *o, int max_rounds, uint32_t since)
{
    const polyc__store *s = o->s;
    int total = 0;
    uint32_t stamp = ++o->climb.work_stamp;
    for (int32_t v = 0; v < s->v_high; v++)
        if (o->v_touch[v] >= since)
            o->climb.v_work[v] = stamp;
    for (int r = 0; r < max_rounds; r++) {
        uint32_t next = ++o->climb.work_stamp;
        int moved = 0;
        for (int32_t v = 0; v < s->v_high; v++) {
            if (o->climb.v_work[v] != stamp || s->v[v].line == POLYC__NONE)
                continue;
            /* a single scan's ends are placed by end trimming (where the
             * end return's beam crosses the end segment's line), so a climb
             * could only turn the end segment about its neighbour: a large
             * share of the climbs' trials for little of their gain */
            if (o->rays.on && (s->v[v].prev == POLYC__NONE || s->v[v].next == POLYC__NONE))
                continue;
            int how = polyc__hill_climb(o, v);
            if (!how)
                continue;
            moved++;
            if (how == 2 || !o->rays.on)
                o->climb.v_work[v] = next;
            /* a single scan's neighbours are not climbed again for a move:
             * on slow scans most climbs come from the first adjustment, and
             * the re-climbs of neighbours bought well under a millimetre of
             * ray RMSE for a noticeable share of the time */
            if (o->rays.on)
                continue;
            int32_t nb[4] = {s->v[v].prev, s->v[v].next, POLYC__NONE, POLYC__NONE};
            if (nb[0] != POLYC__NONE) nb[2] = s->v[nb[0]].prev;
            if (nb[1] != POLYC__NONE) nb[3] = s->v[nb[1]].next;
            for (int k = 0; k < 4; k++)
                if (nb[k] != POLYC__NONE && o->climb.v_work[nb[k]] != stamp)
                    o->climb.v_work[nb[k]] = next;
        }
        total += moved;
        stamp = next;
        if (!moved)
            break;
    }
    return total;
}

/* Gaussian noise of std-dev sigma on every vertex; the caller rescores
 * from scratch (polyc__rebuild) before anything else. */
void polyc__op_noise(polyc__opt *o, float sigma_m)
{
    polyc__store *s = o->s;
    for (int32_t v = 0; v < s->v_high; v++) {
        if (s->v[v].line == POLYC__NONE)
            continue;
        float x = s->v[v].x + (float)(sigma_m * polyc__rng_normal(&o->rng));
        float y = s->v[v].y + (float)(sigma_m * polyc__rng_normal(&o->rng));
        if (polyc__vertex_blocks(o, v, x, y))
            continue; /* a single scan saw through there */
        s->v[v].x = x;
        s->v[v].y = y;
    }
}
