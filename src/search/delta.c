/* delta.c - the change of the error a vertex removal would make, bounded:
 * exact below a limit, and as soon as the sure losses reach the limit, some
 * value at least the limit (enough to reject the removal). Takes: the
 * optimiser state and the trial's segments. Gives: the delta (model_size.c
 * ranks removal candidates by it). */
#include "../trial.h"

#include <float.h>

/* ---- bounded change of the error (removal candidates) ---- */

/* Max-heap on loc_base (the most a pending point can add) over loc_pt. */
static void pend_sift(polyc__opt *o, int32_t i, int32_t n)
{
    float key = o->ev.loc_base[i];
    int32_t pt = o->ev.loc_pt[i];
    for (;;) {
        int32_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && o->ev.loc_base[c + 1] > o->ev.loc_base[c])
            c++;
        if (o->ev.loc_base[c] <= key)
            break;
        o->ev.loc_base[i] = o->ev.loc_base[c];
        o->ev.loc_pt[i] = o->ev.loc_pt[c];
        i = c;
    }
    o->ev.loc_base[i] = key;
    o->ev.loc_pt[i] = pt;
}

/* The change of the error when the `old` segments are replaced by seg_xy,
 * exact when it is below `limit`; otherwise some value >= limit (enough to
 * reject a removal). A point whose nearest segment goes needs a nearest
 * query, unless a new segment serves it at least as well as now; the rest
 * can only lose (their new cost is at least their current one), so they are
 * queried largest possible loss first, and the queries stop as soon as the
 * sure losses reach the limit. Most vertices worth keeping are settled by
 * the few points at their corner. */
float polyc__local_delta(polyc__opt *o, const int32_t *old, int n_old, const float *seg_xy,
                          int n_new, float limit)
{
    const polyc__hash *h = &o->h;
    const polyc__old_set olds = polyc__old_set_of(old, n_old);
    polyc__seg_pre q[4];
    POLYC_ASSERT(n_new <= 4);
    for (int j = 0; j < n_new; j++)
        polyc__seg_prepare(&q[j], seg_xy + 4 * j);
    o->chg.epoch++;
    o->chg.bucket_n = 0;
    for (int k = 0; k < n_old; k++)
        if (old[k] != POLYC__NONE)
            polyc__chg_mark_region(o, old[k]);
    for (int k = 0; k < n_new; k++) {
        const float *s = seg_xy + 4 * k;
        polyc__segment_region(o, s[0], s[1], s[2], s[3]);
    }
    float sure = 0.0f; /* exact part so far; pending points add >= 0 each */
    int32_t n = 0;
    o->ev.lsoa_n = -1; /* loc_pt and loc_base are a heap here */
    for (int32_t k = 0; k < o->chg.bucket_n; k++) {
        int32_t b = o->chg.bucket_list[k];
        for (uint32_t i = h->pt_start[b]; i < h->pt_start[b + 1]; i++) {
            const polyc__point *p = &o->d.pts[i];
            float cur = o->d.pt_cost[i], c = FLT_MAX;
            for (int j = 0; j < n_new; j++) {
                float cj = polyc__seg_pre_cost(&q[j], p);
                if (cj < c)
                    c = cj;
            }
            int32_t seg = o->d.pt_seg[i];
            int hit = polyc__is_old(&olds, seg);
            if (!hit || c <= cur) {
                /* not hit: its cost without the old segments is cur; hit
                 * with c <= cur: no other segment beats c (all are >= cur) */
                sure += (c < cur ? c : cur) - cur;
                continue;
            }
            float cap = polyc__point_cap(o, p);
            o->ev.loc_pt[n] = (int32_t)i;
            o->ev.loc_base[n] = (c < cap ? c : cap) - cur;
            n++;
        }
    }
    o->chg.bucket_n = 0;
    for (int32_t i = n / 2 - 1; i >= 0; i--)
        pend_sift(o, i, n);
    while (n > 0 && sure < limit) {
        int32_t i = o->ev.loc_pt[0];
        float most = o->ev.loc_base[0];
        /* only a segment cheaper than the new one matters: a query within
         * that cost (usually the point's own bucket) */
        sure += polyc__nearest_below(o, i, old, n_old, most + o->d.pt_cost[i], NULL) - o->d.pt_cost[i];
        n--;
        if (n > 0) {
            o->ev.loc_base[0] = o->ev.loc_base[n];
            o->ev.loc_pt[0] = o->ev.loc_pt[n];
            pend_sift(o, 0, n);
        }
    }
    return sure;
}
