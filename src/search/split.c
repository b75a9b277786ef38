/* split.c - operator C (paper IV.C) and end trimming: segments are split
 * where a stretch longer than the data's spacing has no data, and polyline
 * ends are pulled back to their last data. Takes: the optimiser state and
 * its split scratch (polyc__split_scratch, carved here). Gives: the cuts
 * and trims, through the edits of edits.c. */
#include "../opt_state.h"

#include <math.h>
#include <string.h>
#include <stdlib.h>

int polyc__split_carve(polyc__arena *a, polyc__split_scratch *sp, int32_t P, int32_t V)
{
    int ok = 1;
    POLYC__CARVE(ok, a, sp->split_t, P > V ? P : V);
    POLYC__CARVE(ok, a, sp->trim_head, V);
    POLYC__CARVE_ZERO(ok, a, sp->gap_head, V);
    POLYC__CARVE_ZERO(ok, a, sp->gap_tail, V);
    POLYC__CARVE(ok, a, sp->split_off, V + 1);
    /* cuts per pass (more wait for the next pass) */
    sp->cut_cap = V / POLYC__CUT_SHARE + POLYC__CUT_SPARE;
    POLYC__CARVE(ok, a, sp->cut_seg, sp->cut_cap);
    POLYC__CARVE(ok, a, sp->cut_next, sp->cut_cap);
    POLYC__CARVE(ok, a, sp->cut_t0, sp->cut_cap);
    POLYC__CARVE(ok, a, sp->cut_t1, sp->cut_cap);
    return ok;
}

/* ---- C: split ---- */

/* Sorts a[0..n) ascending (no NaN): insertion for short runs, else heap
 * sort; in place, no recursion, no callback per comparison (qsort's cost
 * in this operator). */
static void sort_floats(float *a, int32_t n)
{
    if (n <= 24) {
        for (int32_t i = 1; i < n; i++) {
            float v = a[i];
            int32_t j = i;
            for (; j > 0 && a[j - 1] > v; j--)
                a[j] = a[j - 1];
            a[j] = v;
        }
        return;
    }
    for (int32_t end = n, i = n / 2 - 1;; ) {
        /* sift a[i] down within a[0..end) */
        float v = a[i];
        int32_t k = i;
        for (;;) {
            int32_t c = 2 * k + 1;
            if (c >= end)
                break;
            if (c + 1 < end && a[c + 1] > a[c])
                c++;
            if (a[c] <= v)
                break;
            a[k] = a[c];
            k = c;
        }
        a[k] = v;
        if (i > 0) {
            i--; /* still building the heap */
        } else {
            if (--end <= 0)
                break;
            float top = a[0]; /* the largest goes to the end */
            a[0] = a[end];
            a[end] = top;
        }
    }
}

/* True if the positions t[0..n) along a segment of length len leave no
 * stretch longer than gap (the ends included) without one: every bin of
 * half the gap holds a position. Spares sorting the many segments that
 * have none; a segment of more than 1024 bins is left to the sort. */
static int no_gap_over(const float *t, int32_t n, float len, float gap)
{
    uint64_t seen[16];
    float h = 0.5f * gap;
    if (!(h > 0.0f) || len / h > 1024.0f)
        return 0;
    int32_t nb = (int32_t)ceilf(len / h);
    if (nb < 1)
        nb = 1;
    memset(seen, 0, sizeof seen);
    for (int32_t k = 0; k < n; k++) {
        int32_t b = (int32_t)(t[k] / h);
        b = b < 0 ? 0 : (b >= nb ? nb - 1 : b);
        seen[b >> 6] |= (uint64_t)1 << (b & 63);
    }
    for (int32_t b = 0; b < nb; b++)
        if (!(seen[b >> 6] >> (b & 63) & 1u))
            return 0;
    return 1;
}

/* Whether data point i lies within support_m (POLYC__SUPPORT_M, wider for
 * an occupancy grid's coarse cells) of segment sg: a
 * point farther away is nearest to it only for want of a better segment
 * (clutter, the far side of a wall band) and holds no stretch of it. */
static int supports(const polyc__opt *o, int32_t i, int32_t sg)
{
    const polyc__vertex *a = &o->s->v[sg], *b = &o->s->v[a->next];
    float lim = o->d.support_m;
    return polyc__seg_dist2(o->d.pts[i].x, o->d.pts[i].y, a->x, a->y, b->x, b->y) <= lim * lim;
}

/* How much of the stretch [g0, g0 + len_gap] of segment a-b (of length
 * len) lies in free cells of an occupancy grid: only there does the grid
 * show that no wall stands (a stretch through unknown cells is a wall seen
 * in pieces, as through a door, not a gap: when unknown stretches are cut
 * too, an office's occupancy map loses a large part of its seen walls).
 * Sampled every half cell. */
static float free_length(const polyc__opt *o, const polyc__vertex *a, const polyc__vertex *b,
                         float len, float g0, float len_gap)
{
    float step = 0.5f * o->ctx->grid.cell_m, free_m = 0.0f;
    int32_t n = (int32_t)ceilf(len_gap / step);
    for (int32_t k = 0; k < n; k++) {
        float t = (g0 + ((float)k + 0.5f) * len_gap / (float)n) / len;
        if (polyc__occ_free_at(o->ctx, a->x + t * (b->x - a->x), a->y + t * (b->y - a->y)))
            free_m += len_gap / (float)n;
    }
    return free_m;
}

/* The length a stretch without data must exceed at (x, y) to be cut.
 * Sparse data (far from every pose) have gaps of a few beam spacings
 * between neighbouring points: those are no gaps. */
#define TIP_GAP_M 0.03f /* a sharp vertex this far past its data is pulled back */

static float gap_needed(const polyc__opt *o, float x, float y)
{
    float gap_min = o->cfg->split_gap_m;
    float sparse = polyc__minf(POLYC__GAP_SPACINGS * polyc__spacing_at(&o->spacing, x, y),
                               gap_min + 0.5f * o->d.support_m);
    return polyc__maxf(gap_min, sparse) + 0.5f * o->d.point_span_m;
}

/* Takes vertex v out between the last data on its two segments: from
 * gap_tail[p] before it (p its predecessor) to gap_head[v] after it, and
 * either cuts the polyline there (cut: the tip of a spike, with no data
 * over a gap) or joins the two new vertices (a tip pulled back to the
 * data). 0 if there was no room. */
static int take_out_tip(polyc__opt *o, int32_t v, int cut)
{
    polyc__store *s = o->s;
    int32_t p = s->v[v].prev, n = s->v[v].next;
    float px = s->v[p].x, py = s->v[p].y, vx = s->v[v].x, vy = s->v[v].y;
    float nx = s->v[n].x, ny = s->v[n].y;
    float lp = sqrtf((vx - px) * (vx - px) + (vy - py) * (vy - py));
    float ln = sqrtf((nx - vx) * (nx - vx) + (ny - vy) * (ny - vy));
    float ta = lp > 0.0f ? 1.0f - o->split.gap_tail[p] / lp : 0.0f; /* along p -> v */
    float tb = ln > 0.0f ? o->split.gap_head[v] / ln : 1.0f;        /* along v -> n */
    polyc__chg_begin(o);
    int32_t a = p, b = n;
    int ok = 1;
    if (ta > 1e-3f && (a = polyc__op_insert_after(o, p, px + ta * (vx - px), py + ta * (vy - py))) == POLYC__NONE)
        ok = 0;
    if (ok && tb < 1.0f - 1e-3f &&
        (b = polyc__op_insert_after(o, v, vx + tb * (nx - vx), vy + tb * (ny - vy))) == POLYC__NONE)
        ok = 0;
    if (ok) {
        polyc__op_remove(o, v); /* a -> b */
        if (cut && s->v[a].line != POLYC__NONE && s->v[a].next == b)
            polyc__op_cut(o, a);
    }
    polyc__chg_commit(o);
    (void)b;
    return ok;
}

/* The cuts recorded by polyc__op_split, each a change of its own. */
static void apply_cuts(polyc__opt *o, int32_t n_cut)
{
    polyc__store *s = o->s;
    for (int32_t k = 0; k < n_cut; k++) {
        int32_t u = o->split.cut_seg[k];
        if (s->v[u].line == POLYC__NONE || s->v[u].next != o->split.cut_next[k])
            continue; /* changed by an earlier cut */
        const polyc__vertex *a = &s->v[u], *b = &s->v[a->next];
        float ax = a->x, ay = a->y, dx = b->x - a->x, dy = b->y - a->y;
        float t0 = o->split.cut_t0[k], t1 = o->split.cut_t1[k];
        polyc__chg_begin(o);
        int32_t c = u;
        if (t0 > 1e-3f)
            c = polyc__op_insert_after(o, u, ax + t0 * dx, ay + t0 * dy);
        if (c != POLYC__NONE && t1 < 1.0f - 1e-3f)
            if (polyc__op_insert_after(o, c, ax + t1 * dx, ay + t1 * dy) == POLYC__NONE)
                c = POLYC__NONE;
        if (c != POLYC__NONE)
            polyc__op_cut(o, c);
        else
            o->split_due[u] = 1; /* no room for a vertex: try again next pass */
        polyc__chg_commit(o);
    }
}

/* A stretch without data across a vertex: the ends of its two segments
 * (neither changed in this pass) together longer than the gap, among the
 * first nv vertices (those before the pass's cuts). Returns the tips taken
 * out. */
static int32_t cut_tips(polyc__opt *o, int32_t nv)
{
    polyc__store *s = o->s;
    const uint8_t *due = o->split_due;
    int32_t n_cut = 0;
    for (int32_t v = 0; v < nv; v++) {
        const polyc__vertex *c = &s->v[v];
        if (c->line == POLYC__NONE || c->prev == POLYC__NONE || c->next == POLYC__NONE)
            continue;
        int32_t p = c->prev;
        if (due[p] || due[v] || s->l[c->line].count < 3)
            continue;
        const polyc__vertex *a = &s->v[p], *b = &s->v[c->next];
        float ux = c->x - a->x, uy = c->y - a->y, wx = b->x - c->x, wy = b->y - c->y;
        float dot = ux * wx + uy * wy, lens = sqrtf((ux * ux + uy * uy) * (wx * wx + wy * wy));
        /* only where the polyline turns by more than 120 degrees (a
         * spike): at a corner of a wall seen from one side the data stop
         * short of the corner on the unseen face, and the corner is real */
        if (dot < -0.5f * lens && o->split.gap_tail[p] + o->split.gap_head[v] > gap_needed(o, c->x, c->y)) {
            n_cut += take_out_tip(o, v, 1);
            continue;
        }
        /* a spike past the data on both its segments, as at the end of a
         * wall seen from both sides where one face's line overshoots to
         * meet the end's: pulled back to the data, as an open end is
         * (nothing in the BIC holds it there) */
        if (dot < -0.5f * lens && o->split.gap_tail[p] >= TIP_GAP_M && o->split.gap_head[v] >= TIP_GAP_M)
            n_cut += take_out_tip(o, v, 0);
    }
    return n_cut;
}

/* A segment with a stretch longer than split_gap_m (or 2.5 beam spacings
 * where the data are sparser than that, up to split_gap_m plus half the
 * support distance: past that a stretch between two points would be
 * without data within POLYC__SUPPORT_M over more than split_gap_m), plus
 * the span of a weighted point, onto which no data point within
 * POLYC__SUPPORT_M projects is cut there: the polyline ends on either side
 * of the gap. Only the segments split_due are looked at: one
 * whose ends and points are what they were when it was last found whole
 * is whole still (the search calls this several times an iteration, and
 * between two calls most segments did not change). */
/* split looks at the segments due (in the region) */
static int split_wants(const polyc__opt *o, int32_t v)
{
    return o->split_due[v] && polyc__in_region(o, v);
}

int polyc__op_split(polyc__opt *o)
{
    polyc__store *s = o->s;
    int32_t nv = s->v_high;
    int32_t *off = o->split.split_off;
    float *t = o->split.split_t;
    const uint8_t *due = o->split_due;
    int32_t np = polyc__region_points(o, split_wants);
    const int32_t *list = np >= 0 ? o->region_pt : NULL;
    np = np >= 0 ? np : o->d.np;
    for (int32_t v = 0; v <= nv; v++)
        off[v] = 0;
    for (int32_t j = 0; j < np; j++) {
        int32_t i = list ? list[j] : j;
        int32_t sg = o->d.pt_seg[i];
        if (sg != POLYC__NONE && split_wants(o, sg) && supports(o, i, sg))
            off[sg + 1]++;
    }
    for (int32_t v = 0; v < nv; v++)
        off[v + 1] += off[v];
    /* fill: positions along the segment, metres */
    for (int32_t j = 0; j < np; j++) {
        int32_t i = list ? list[j] : j;
        int32_t sg = o->d.pt_seg[i];
        if (sg == POLYC__NONE || !split_wants(o, sg) || !supports(o, i, sg))
            continue;
        const polyc__vertex *a = &s->v[sg], *b = &s->v[a->next];
        float dx = b->x - a->x, dy = b->y - a->y;
        float len = sqrtf(dx * dx + dy * dy);
        float u = len > 0.0f ? ((o->d.pts[i].x - a->x) * dx + (o->d.pts[i].y - a->y) * dy) / len : 0.0f;
        t[off[sg]++] = u < 0.0f ? 0.0f : (u > len ? len : u);
    }
    for (int32_t v = nv; v > 0; v--)
        off[v] = off[v - 1];
    off[0] = 0;
    /* find the gaps first, then cut (cuts change the assignment) */
    int32_t n_cut = 0;
    float gap_min = o->cfg->split_gap_m;
    for (int32_t v = 0; v < nv; v++) {
        const polyc__vertex *a = &s->v[v];
        if (!due[v] || a->line == POLYC__NONE || a->next == POLYC__NONE || !polyc__in_region(o, v))
            continue;
        const polyc__vertex *b = &s->v[a->next];
        float len = sqrtf((b->x - a->x) * (b->x - a->x) + (b->y - a->y) * (b->y - a->y));
        /* looked at: due again only when it or its points change (a cut
         * changes them; one left for the next pass stays due) */
        o->split_due[v] = 0;
        int32_t lo = off[v], hi = off[v + 1];
        /* how far each end of it lies from its nearest data (for the gaps
         * across a vertex, below) */
        float t_min = len, t_max = 0.0f;
        for (int32_t k = lo; k < hi; k++) {
            t_min = polyc__minf(t_min, t[k]);
            t_max = polyc__maxf(t_max, t[k]);
        }
        o->split.gap_head[v] = t_min;
        o->split.gap_tail[v] = hi > lo ? len - t_max : len;
        if (len <= gap_min)
            continue;
        if (no_gap_over(t + lo, hi - lo, len, gap_min))
            continue;
        sort_floats(t + lo, hi - lo);
        float prev = 0.0f, best = 0.0f, g0 = 0.0f;
        for (int32_t k = lo; k <= hi; k++) {
            float cur = k < hi ? t[k] : len;
            if (cur - prev > best) {
                best = cur - prev;
                g0 = prev;
            }
            prev = cur;
        }
        float gx = a->x + (b->x - a->x) * (g0 + 0.5f * best) / len;
        float gy = a->y + (b->y - a->y) * (g0 + 0.5f * best) / len;
        float need = gap_needed(o, gx, gy);
        if (best > need && o->pol.gaps_free_only)
            best = free_length(o, a, b, len, g0, best);
        if (best > need && n_cut < o->split.cut_cap) {
            o->split.cut_seg[n_cut] = v;
            o->split.cut_next[n_cut] = a->next;
            o->split.cut_t0[n_cut] = g0 / len;
            o->split.cut_t1[n_cut] = (g0 + best) / len;
            n_cut++;
        } else if (best > need) {
            o->split_due[v] = 1; /* no room for its cut in this pass */
        }
    }
    apply_cuts(o, n_cut);
    return n_cut + cut_tips(o, nv);
}

/* ---- end trimming (part of C) ---- */

/* Whether pulling end vertex v back to (x, y) on its segment loses a
 * return the segment holds now (single scans only): on a segment that runs
 * along the beams the farthest projection of its points can fall short of
 * where the last beam crosses it (without this test, scans of several real
 * logs had an end beam that then meets the map metres behind its return). */
static int trim_loses_returns(const polyc__opt *o, int32_t v, float x, float y)
{
    const polyc__vertex *V = o->s->v;
    int32_t nb = V[v].prev != POLYC__NONE ? V[v].prev : V[v].next;
    const float old_xy[4] = {V[v].x, V[v].y, V[nb].x, V[nb].y};
    const float new_xy[4] = {x, y, V[nb].x, V[nb].y};
    return polyc__loses_returns(&o->rays, old_xy, 1, new_xy, 1);
}

/* Nothing in the BIC holds an open end where the data stop: points beyond
 * it cost the same wherever it is. Each open end is pulled back to the
 * farthest projection of the points of its segment that lie within
 * POLYC__SUPPORT_M of it (of all its points in a single scan, whose beams
 * place its ends), plus half a beam spacing (at least 1 cm). */
/* trimming looks at the end segments (in the region) */
static int trim_wants(const polyc__opt *o, int32_t v)
{
    const polyc__vertex *a = &o->s->v[v];
    return (a->prev == POLYC__NONE || o->s->v[a->next].next == POLYC__NONE) && polyc__in_region(o, v);
}

int polyc__op_trim_ends(polyc__opt *o)
{
    polyc__store *s = o->s;
    int32_t nv = s->v_high;
    int32_t np = polyc__region_points(o, trim_wants);
    const int32_t *list = np >= 0 ? o->region_pt : NULL;
    np = np >= 0 ? np : o->d.np;
    /* per end segment: farthest projection (metres from the inner vertex) */
    for (int32_t v = 0; v < nv; v++)
        o->split.split_t[v] = o->split.trim_head[v] = -1.0f;
    for (int32_t j = 0; j < np; j++) {
        int32_t i = list ? list[j] : j;
        int32_t sg = o->d.pt_seg[i];
        if (sg == POLYC__NONE || (!o->rays.on && !supports(o, i, sg)))
            continue;
        const polyc__vertex *a = &s->v[sg], *b = &s->v[a->next];
        int head_end = a->prev == POLYC__NONE, tail_end = b->next == POLYC__NONE;
        if (!head_end && !tail_end)
            continue;
        float dx = b->x - a->x, dy = b->y - a->y, len = sqrtf(dx * dx + dy * dy);
        if (len <= 0.0f)
            continue;
        float u = ((o->d.pts[i].x - a->x) * dx + (o->d.pts[i].y - a->y) * dy) / len;
        if (o->rays.on)
            u = polyc__ray_position(&o->rays, a->x, a->y, b->x, b->y, o->d.pts[i].x, o->d.pts[i].y, u);
        /* store as fraction from the tail side and from the head side */
        if (tail_end && u / len > o->split.split_t[sg])
            o->split.split_t[sg] = u / len;
        if (head_end && (1.0f - u / len) > o->split.trim_head[sg])
            o->split.trim_head[sg] = 1.0f - u / len;
    }
    int changed = 0;
    for (int32_t v = 0; v < nv; v++) {
        const polyc__vertex *a = &s->v[v];
        if (a->line == POLYC__NONE || a->next == POLYC__NONE || !polyc__in_region(o, v))
            continue;
        int32_t w = a->next;
        float ax = a->x, ay = a->y, bx = s->v[w].x, by = s->v[w].y;
        float len = sqrtf((bx - ax) * (bx - ax) + (by - ay) * (by - ay));
        /* a margin of half a beam spacing keeps the last point's own beam on the map */
        float margin = polyc__maxf(0.01f, 0.5f * polyc__spacing_at(&o->spacing, bx, by)) / len;
        float keep_tail = o->split.split_t[v] + margin, keep_head = o->split.trim_head[v] + margin;
        /* a single scan's ends also grow to its end beams */
        float most = o->rays.on ? 1.0f + 4.0f * margin : 1.0f;
        keep_tail = polyc__minf(keep_tail, most);
        keep_head = polyc__minf(keep_head, most);
        /* (there, under a millimetre is not worth a move, which would be
         * climbed again in the next iteration) */
        if (o->rays.on && fabsf(keep_tail - 1.0f) * len < 1e-3f)
            keep_tail = 1.0f;
        if (o->rays.on && fabsf(keep_head - 1.0f) * len < 1e-3f)
            keep_head = 1.0f;
        float tx = ax + keep_tail * (bx - ax), ty = ay + keep_tail * (by - ay);
        float hx = bx + keep_head * (ax - bx), hy = by + keep_head * (ay - by);
        if (s->v[w].next == POLYC__NONE && o->split.split_t[v] >= 0.0f && keep_tail != 1.0f &&
            !(keep_tail > 1.0f ? polyc__vertex_blocks(o, w, tx, ty) : trim_loses_returns(o, w, tx, ty))) {
            polyc__apply_move(o, w, tx, ty);
            changed++;
        }
        if (a->prev == POLYC__NONE && o->split.trim_head[v] >= 0.0f && keep_head != 1.0f &&
            !(keep_head > 1.0f ? polyc__vertex_blocks(o, v, hx, hy) : trim_loses_returns(o, v, hx, hy))) {
            polyc__apply_move(o, v, hx, hy);
            changed++;
        }
    }
    return changed;
}
