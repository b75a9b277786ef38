/* change.c - the books of a change: an edit (or a batch of them) records
 * the segments it takes out and puts in and the vertices whose angle it
 * changes; committing rescores only the points near those segments and
 * those angles, so the model's terms stay what cost.c would compute from
 * scratch. Takes: the optimiser state. Gives: the updated terms. */
#include "../cost.h"

/* the external definition of opt_state.h's polyc__in_region (C99: one
 * copy for the callers that take its address or do not inline it) */
extern inline int polyc__in_region(const polyc__opt *o, int32_t v);

int polyc__change_carve(polyc__arena *a, polyc__change *c, int32_t V)
{
    int ok = 1;
    POLYC__CARVE_ZERO(ok, a, c->seg_dead, V);
    POLYC__CARVE_ZERO(ok, a, c->v_dirty, V);
    POLYC__CARVE(ok, a, c->dirty_list, V);
    c->dirty_cap = V;
    c->added_cap = POLYC__ADDED_CAP;
    POLYC__CARVE(ok, a, c->added, POLYC__ADDED_CAP);
    return ok;
}

/* ---- recording a change ---- */

void polyc__chg_mark_region(polyc__opt *o, int32_t seg)
{
    const polyc__vertex *a = &o->s->v[seg];
    const polyc__vertex *b = &o->s->v[a->next];
    polyc__segment_region(o, a->x, a->y, b->x, b->y);
}

void polyc__chg_begin(polyc__opt *o)
{
    o->chg.epoch++;
    o->chg.bucket_n = 0;
    o->chg.added_n = 0;
    o->chg.added_overflow = 0;
    o->chg.dirty_n = 0;
}

void polyc__chg_seg_out(polyc__opt *o, int32_t seg)
{
    if (seg == POLYC__NONE || !o->seg_in[seg])
        return;
    polyc__chg_mark_region(o, seg);
    polyc__hash_remove(o, seg);
    o->chg.seg_dead[seg] = o->chg.epoch;
}

int polyc__chg_seg_in(polyc__opt *o, int32_t seg)
{
    if (seg == POLYC__NONE || o->seg_in[seg] || o->s->v[seg].next == POLYC__NONE)
        return 1;
    int ok = polyc__hash_insert(o, seg);
    polyc__chg_mark_region(o, seg);
    if (o->chg.added_n < o->chg.added_cap)
        o->chg.added[o->chg.added_n++] = seg;
    else
        o->chg.added_overflow = 1; /* too many to compare: full queries in the region */
    return ok;
}

void polyc__chg_dirty(polyc__opt *o, int32_t v)
{
    if (v == POLYC__NONE)
        return;
    o->v_touch[v] = o->touch_stamp;
    if (o->chg.v_dirty[v] == o->chg.epoch || o->chg.dirty_n >= o->chg.dirty_cap)
        return;
    o->chg.v_dirty[v] = o->chg.epoch;
    polyc__ksum_add(&o->angle, -(o->acost[v]));
    o->acost[v] = 0.0f;
    o->chg.dirty_list[o->chg.dirty_n++] = v;
}

int32_t polyc__region_points(polyc__opt *o, polyc__seg_pred want)
{
    if (o->region_since == 0)
        return -1;
    const polyc__store *s = o->s;
    polyc__chg_begin(o); /* a new epoch for the bucket marks; no change is open */
    for (int32_t v = 0; v < s->v_high; v++)
        if (s->v[v].line != POLYC__NONE && s->v[v].next != POLYC__NONE && want(o, v))
            polyc__chg_mark_region(o, v);
    return polyc__listed_points(o);
}

int32_t polyc__listed_points(polyc__opt *o)
{
    const polyc__hash *h = &o->h;
    int32_t n = 0;
    for (int32_t k = 0; k < o->chg.bucket_n; k++) {
        int32_t b = o->chg.bucket_list[k];
        for (uint32_t i = h->pt_start[b]; i < h->pt_start[b + 1]; i++)
            o->region_pt[n++] = (int32_t)i;
    }
    o->chg.bucket_n = 0;
    return n;
}

void polyc__chg_commit(polyc__opt *o)
{
    const polyc__hash *h = &o->h;
    for (int32_t k = 0; k < o->chg.bucket_n; k++) {
        int32_t b = o->chg.bucket_list[k];
        for (uint32_t i = h->pt_start[b]; i < h->pt_start[b + 1]; i++) {
            float old = o->d.pt_cost[i], c;
            int32_t seg = o->d.pt_seg[i];
            if (o->chg.added_overflow || (seg != POLYC__NONE && o->chg.seg_dead[seg] == o->chg.epoch)) {
                c = polyc__nearest(o, (int32_t)i, NULL, 0, &seg);
            } else {
                c = old;
                for (int32_t a = 0; a < o->chg.added_n; a++) {
                    int32_t sg = o->chg.added[a];
                    if (!o->seg_in[sg])
                        continue;
                    float ca = polyc__cost_seg(o, &o->d.pts[i], sg);
                    if (ca < c) {
                        c = ca;
                        seg = sg;
                    }
                }
            }
            o->d.pt_cost[i] = c;
            polyc__split_due_pt(o, o->d.pt_seg[i], seg);
            o->d.pt_seg[i] = seg;
            polyc__ksum_add(&o->err, c - old);
        }
    }
    for (int32_t k = 0; k < o->chg.dirty_n; k++) {
        int32_t v = o->chg.dirty_list[k];
        if (o->s->v[v].line == POLYC__NONE)
            continue;
        o->acost[v] = polyc__vertex_angle_cost(o, v);
        polyc__ksum_add(&o->angle, o->acost[v]);
    }
    o->chg.bucket_n = o->chg.added_n = o->chg.dirty_n = 0;
}
