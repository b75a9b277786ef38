/* trial.c - trial evaluation, read-only: the points near the segments an
 * edit would change are listed once with their cost without those segments
 * (list_near_points), and each trial prices only them (trial_costs.c in
 * batches). Takes: the optimiser state. Gives: the error a trial geometry
 * would make near the edit. */
#include "../trial.h"

#include <math.h>

/* the external definitions of trial.h's inline functions (C99: used
 * where a caller does not inline them, as at -Os) */
extern inline void polyc__seg_prepare(polyc__seg_pre *q, const float *xy);
extern inline float polyc__seg_pre_cost(const polyc__seg_pre *q, const polyc__point *p);
extern inline polyc__old_set polyc__old_set_of(const int32_t *old, int n_old);
extern inline int polyc__is_old(const polyc__old_set *s, int32_t seg);

int polyc__eval_carve(polyc__arena *a, polyc__eval_scratch *ev, int32_t P, int32_t lsoa_cap)
{
    int ok = 1;
    POLYC__CARVE(ok, a, ev->loc_pt, P);
    POLYC__CARVE(ok, a, ev->loc_base, P);
    POLYC__CARVE(ok, a, ev->loc_seg, P);
    POLYC__CARVE(ok, a, ev->agg_pt, P);
    ev->agg_cap = P;
    POLYC__CARVE(ok, a, ev->cand_seg, POLYC__CAND_MAX);
    POLYC__CARVE(ok, a, ev->cand_box, 4 * POLYC__CAND_MAX);
    ev->lsoa_cap = lsoa_cap;
    ev->lsoa_n = -1;
    if (lsoa_cap > 0) {
        POLYC__CARVE(ok, a, ev->lsoa_x, lsoa_cap);
        POLYC__CARVE(ok, a, ev->lsoa_y, lsoa_cap);
        POLYC__CARVE(ok, a, ev->lsoa_w, lsoa_cap);
        POLYC__CARVE(ok, a, ev->lsoa_cxx, lsoa_cap);
        POLYC__CARVE(ok, a, ev->lsoa_cxy, lsoa_cap);
        POLYC__CARVE(ok, a, ev->lsoa_cyy, lsoa_cap);
        POLYC__CARVE(ok, a, ev->lsoa_c, lsoa_cap);
    }
    return ok;
}

/* ---- local evaluation (read-only) ---- */

/* A segment's start, direction and squared length, for point_seg_dist. */
typedef struct seg_span {
    float ax, ay, dx, dy, l2;
} seg_span;

static seg_span seg_span_of(const float *xy)
{
    seg_span q;
    q.ax = (float)xy[0];
    q.ay = (float)xy[1];
    q.dx = (float)xy[2] - (float)xy[0];
    q.dy = (float)xy[3] - (float)xy[1];
    q.l2 = q.dx * q.dx + q.dy * q.dy;
    return q;
}

static float point_seg_dist(const polyc__point *p, const seg_span *q)
{
    float dx = q->dx, dy = q->dy;
    float mx = (float)p->x - q->ax, my = (float)p->y - q->ay;
    float l2 = q->l2;
    float t = l2 > 1e-18f ? (mx * dx + my * dy) / l2 : 0.0f;
    t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    float ex = mx - t * dx, ey = my - t * dy;
    return sqrtf(ex * ex + ey * ey);
}

/* Can a move of the shared end c (by at most rho) take point p out of the
 * interior of segment a-c, or make the other moving segment beat it? If
 * not, the returned bound exceeds its cost on a-c for every trial, where
 * that cost is exactly w (n.(p-a))^2 + n'Cn; if no other segment costs less
 * than the bound either, the point can join the segment's moments. d_own
 * and d_other are the distances of p to this segment and to the other
 * moving one (1e30 if none). Returns 0 if the point may leave. */
static float stay_bound(const polyc__point *p, float ax, float ay, float cx, float cy,
                         float rho, float d_own, float d_other)
{
    float px = (float)p->x, py = (float)p->y;
    float ux = cx - ax, uy = cy - ay, pax = px - ax, pay = py - ay;
    /* projection after the end at a: (p-a).(c-a) > 0 for all |dc| <= rho */
    if (pax * ux + pay * uy - sqrtf(pax * pax + pay * pay) * rho <= 0.0f)
        return 0.0f;
    /* before the end at c: (c-p).(c-a) >= (c0-p).(c0-a) - rho |2c0-p-a| */
    float cpx = cx - px, cpy = cy - py, sx = cpx + ux, sy = cpy + uy;
    if (cpx * ux + cpy * uy - rho * sqrtf(sx * sx + sy * sy) <= 0.0f)
        return 0.0f;
    /* its cost here is at most w (d + rho)^2 + trace(C), the other's at
     * least w (d' - rho)^2 */
    float w = (float)p->w, up = d_own + rho, lo = d_other - rho;
    float worst = w * up * up + ((float)p->cxx + (float)p->cyy);
    return lo > 0.0f && worst < w * lo * lo ? worst : 0.0f;
}

/* The candidates of the points whose own segment goes: the segments other
 * than `old` that a nearest query from such a point could meet, the ones in
 * the 3 x 3 buckets around its bucket. They are gathered for a bucket the
 * first time one of its points asks (most of the region's buckets hold no
 * point of the old segments). */
static void gather_start(polyc__opt *o, const int32_t *old, int n_old)
{
    /* a new epoch: the region's bucket marks are not needed any more (the
     * region is listed), and seg_dead (compared with the epoch of a change,
     * which starts a new one) marks the segments met */
    o->ev.cand_stamp = ++o->chg.epoch;
    o->ev.cand_src = POLYC__NONE;
    o->ev.cand_n = 0;
    for (int j = 0; j < n_old; j++)
        if (old[j] != POLYC__NONE)
            o->chg.seg_dead[old[j]] = o->ev.cand_stamp;
}

static void gather_around(polyc__opt *o, int32_t b)
{
    const polyc__hash *h = &o->h;
    const uint32_t stamp = o->ev.cand_stamp;
    if (b == o->ev.cand_src)
        return; /* the points come bucket by bucket */
    o->ev.cand_src = b;
    int32_t around[9];
    int n = polyc__buckets_around(h, b % h->bx, b / h->bx, around);
    for (int i = 0; i < n; i++) {
        int32_t nb = around[i];
        if (o->chg.bucket_mark[nb] == stamp)
            continue;
        o->chg.bucket_mark[nb] = stamp;
        for (int32_t e = h->seg_head[nb]; e != POLYC__NONE; e = h->entries[e].next) {
            int32_t sg = h->entries[e].seg;
            if (o->chg.seg_dead[sg] == stamp)
                continue;
            o->chg.seg_dead[sg] = stamp;
            if (o->ev.cand_n == POLYC__CAND_MAX) {
                o->ev.cand_n = POLYC__CAND_MAX + 1; /* too many: the hash is queried */
                return;
            }
            const polyc__vertex *a = &o->s->v[sg], *c = &o->s->v[a->next];
            float *box = o->ev.cand_box + 4 * o->ev.cand_n;
            box[0] = polyc__minf(a->x, c->x);
            box[1] = polyc__minf(a->y, c->y);
            box[2] = polyc__maxf(a->x, c->x);
            box[3] = polyc__maxf(a->y, c->y);
            o->ev.cand_seg[o->ev.cand_n++] = sg;
        }
    }
}

/* nearest_below over the gathered candidates: the same segments it would
 * look at, and a box test instead of the bucket walk. */
static float nearest_candidate(const polyc__opt *o, int32_t pi, float start, int32_t *seg)
{
    const polyc__point *p = &o->d.pts[pi];
    float best = start, w = (float)p->w;
    int32_t best_seg = POLYC__NONE;
    for (int32_t k = 0; k < o->ev.cand_n; k++) {
        const float *box = o->ev.cand_box + 4 * k;
        /* distance to the box, a lower bound of the segment's: differences
         * of floats are exact in double, so the bound is never too high */
        float px = (float)p->x, py = (float)p->y;
        float gx = (float)box[0] - px > px - (float)box[2] ? (float)box[0] - px : px - (float)box[2];
        float gy = (float)box[1] - py > py - (float)box[3] ? (float)box[1] - py : py - (float)box[3];
        gx = gx > 0.0f ? gx : 0.0f;
        gy = gy > 0.0f ? gy : 0.0f;
        if (0.999f * w * (gx * gx + gy * gy) >= best)
            continue;
        float c = polyc__cost_seg(o, p, o->ev.cand_seg[k]);
        if (c < best) {
            best = c;
            best_seg = o->ev.cand_seg[k];
        }
    }
    *seg = best_seg;
    return best;
}

/* The old segments of an edit, for the test every listed point makes: the
 * first two compared directly (a climb has two), the rest in a loop. */
/* The aggregation of a move (list_near_points): on when moving the shared end of at
 * most two segments; each segment's fixed end. */
static void agg_begin(polyc__eval_scratch *ev, int move, const float *seg_xy, int n_new, float mx,
                      float my)
{
    ev->agg_on = move && n_new <= 2;
    ev->agg_n[0] = ev->agg_n[1] = 0;
    for (int j = 0; j < 2; j++) {
        ev->agg_m[j][0] = ev->agg_m[j][1] = ev->agg_m[j][2] = 0.0f;
        ev->agg_moving_b[j] = 0;
        ev->agg_ax[j] = ev->agg_ay[j] = 0.0f;
        ev->agg_tx[j] = 1.0f;
        ev->agg_ty[j] = 0.0f;
    }
    if (ev->agg_on)
        for (int j = 0; j < n_new; j++) {
            const float *q = seg_xy + 4 * j;
            int b = q[2] == mx && q[3] == my;
            ev->agg_moving_b[j] = b;
            ev->agg_ax[j] = (float)(b ? q[0] : q[2]);
            ev->agg_ay[j] = (float)(b ? q[1] : q[3]);
            float tx = (b ? q[2] : q[0]) - ev->agg_ax[j], ty = (b ? q[3] : q[1]) - ev->agg_ay[j];
            float len = sqrtf(tx * tx + ty * ty);
            ev->agg_tx[j] = len > 0.0f ? tx / len : 1.0f;
            ev->agg_ty[j] = len > 0.0f ? ty / len : 0.0f;
        }
}

/* The listed points again, by field (trial_costs.c) */
static void copy_listed(polyc__opt *o)
{
    o->ev.lsoa_n = -1;
    /* for a few points (most of a single scan's trials) the copy costs
     * more than it saves */
    if (o->ev.loc_n >= 8 && o->ev.loc_n <= o->ev.lsoa_cap) {
        for (int32_t k = 0; k < o->ev.loc_n; k++) {
            const polyc__point *p = &o->d.pts[o->ev.loc_pt[k]];
            o->ev.lsoa_x[k] = (float)p->x;
            o->ev.lsoa_y[k] = (float)p->y;
            o->ev.lsoa_w[k] = (float)p->w;
            o->ev.lsoa_cxx[k] = (float)p->cxx;
            o->ev.lsoa_cxy[k] = (float)p->cxy;
            o->ev.lsoa_cyy[k] = (float)p->cyy;
        }
        o->ev.lsoa_n = o->ev.loc_n;
    }
}

/* A trial edit as the listing sees it: the `old` segments it replaces, the
 * candidate geometry (n_new segments, x0 y0 x1 y1 each), how far the
 * candidates stray from it (0: unknown), and for a move the shared end
 * (mx, my) that alone differs between candidates. */
typedef struct trial_edit {
    const int32_t *old;
    int n_old;
    const float *seg_xy;
    int n_new;
    float reach;
    int move;
    float mx, my;
} trial_edit;

/* Lists the points near the `old` segments and the candidate geometry,
 * with their cost when the old segments are gone (loc_base, loc_seg). With
 * reach > 0 the candidates stay within `reach` of seg_xy: a point not on an
 * old segment whose cost is below any cost it could get from them never
 * changes, and is summed once into loc_fixed instead of being listed. With
 * `move`, the candidates differ by the position of the shared end (mx, my)
 * only, and the points that stay on one segment are aggregated. */
static void list_near_points(polyc__opt *o, const trial_edit *ed)
{
    const polyc__hash *h = &o->h;
    const int32_t *old = ed->old;
    const float *seg_xy = ed->seg_xy;
    const int n_old = ed->n_old, n_new = ed->n_new, move = ed->move;
    const float reach = ed->reach, mx = ed->mx, my = ed->my;
    const polyc__old_set olds = polyc__old_set_of(old, n_old);
    seg_span span[4];
    POLYC_ASSERT(n_new <= 4);
    for (int j = 0; j < n_new; j++)
        span[j] = seg_span_of(seg_xy + 4 * j);
    o->chg.epoch++;
    o->chg.bucket_n = 0;
    for (int k = 0; k < n_old; k++)
        if (old[k] != POLYC__NONE)
            polyc__chg_mark_region(o, old[k]);
    /* moving: the candidates start where the old segments are, and their
     * moves stay within the buckets' margin */
    for (int k = 0; k < n_new && !move; k++) {
        const float *q = seg_xy + 4 * k;
        polyc__segment_region(o, q[0], q[1], q[2], q[3]);
    }
    o->ev.cand_n = -1;
    o->ev.loc_n = 0;
    o->ev.loc_fixed = 0.0f;
    o->ev.loc_fixed_cur = 0.0f;
    agg_begin(&o->ev, move, seg_xy, n_new, mx, my);
    for (int32_t k = 0; k < o->chg.bucket_n; k++) {
        int32_t b = o->chg.bucket_list[k];
        for (uint32_t i = h->pt_start[b]; i < h->pt_start[b + 1]; i++) {
            int32_t seg = o->d.pt_seg[i];
            int hit = polyc__is_old(&olds, seg);
            int32_t base_seg = seg;
            float base = o->d.pt_cost[i];
            const polyc__point *p = &o->d.pts[i];
            float d[2] = {1e30f, 1e30f};
            if (reach > 0.0f) {
                float dmin = 1e30f;
                for (int j = 0; j < n_new; j++) {
                    float dj = point_seg_dist(p, &span[j]);
                    if (j < 2)
                        d[j] = dj;
                    if (dj < dmin)
                        dmin = dj;
                }
                dmin -= (float)reach;
                if (!hit && dmin > 0.0f && base <= (float)p->w * dmin * dmin) {
                    o->ev.loc_fixed += base;
                    o->ev.loc_fixed_cur += o->d.pt_cost[i];
                    continue;
                }
            }
            int j = n_new == 2 && d[1] < d[0];
            float bound = o->ev.agg_on ? stay_bound(p, o->ev.agg_ax[j], o->ev.agg_ay[j], (float)mx,
                                                  (float)my, (float)reach, d[j], d[1 - j])
                                     : 0.0f;
            if (hit) {
                /* without the old segments: a query within the bound is
                 * enough to tell that the point stays (most do) */
                float cap = polyc__point_cap(o, p), start = bound > 0.0f && bound < cap ? bound : cap;
                if (o->ev.cand_n < 0)
                    gather_start(o, old, n_old);
                if (o->ev.cand_n >= 0 && o->ev.cand_n <= POLYC__CAND_MAX)
                    gather_around(o, b);
                base = o->ev.cand_n >= 0 && o->ev.cand_n <= POLYC__CAND_MAX
                           ? nearest_candidate(o, (int32_t)i, start, &base_seg)
                           : polyc__nearest_below(o, (int32_t)i, old, n_old, start, &base_seg);
                if (base_seg != POLYC__NONE)
                    bound = 0.0f;
                else if (bound > 0.0f && bound < cap)
                    base = cap; /* unknown but irrelevant: the point stays */
                else
                    bound = 0.0f;
            } else if (bound >= base) {
                bound = 0.0f;
            }
            if (bound > 0.0f) {
                /* in the segment's frame: a along, b across (its C turned too) */
                float tx = o->ev.agg_tx[j], ty = o->ev.agg_ty[j];
                float dx = p->x - o->ev.agg_ax[j], dy = p->y - o->ev.agg_ay[j];
                float a = dx * tx + dy * ty, bn = dy * tx - dx * ty, w = p->w;
                float txy = tx * ty, c2 = tx * tx - ty * ty;
                float caa = tx * tx * p->cxx + 2.0f * txy * p->cxy + ty * ty * p->cyy;
                float cab = txy * (p->cyy - p->cxx) + c2 * p->cxy;
                float cbb = ty * ty * p->cxx - 2.0f * txy * p->cxy + tx * tx * p->cyy;
                o->ev.agg_m[j][0] += w * a * a + caa;
                o->ev.agg_m[j][1] += w * a * bn + cab;
                o->ev.agg_m[j][2] += w * bn * bn + cbb;
                int32_t slot = j == 0 ? o->ev.agg_n[0] : o->ev.agg_cap - 1 - o->ev.agg_n[1];
                o->ev.agg_pt[slot] = (int32_t)i;
                o->ev.agg_n[j]++;
                o->ev.loc_fixed_cur += o->d.pt_cost[i];
                continue;
            }
            o->ev.loc_pt[o->ev.loc_n] = (int32_t)i;
            o->ev.loc_base[o->ev.loc_n] = base;
            o->ev.loc_seg[o->ev.loc_n] = base_seg;
            o->ev.loc_n++;
        }
    }
    o->chg.bucket_n = 0;
    copy_listed(o);
}

void polyc__local_prepare(polyc__opt *o, const int32_t *old, int n_old, const float *seg_xy,
                          int n_new, float reach)
{
    const trial_edit ed = {old, n_old, seg_xy, n_new, reach, 0, 0.0f, 0.0f};
    list_near_points(o, &ed);
}

void polyc__local_prepare_move(polyc__opt *o, const int32_t *old, int n_old, const float *seg_xy,
                               int n_new, float reach, float mx, float my)
{
    const trial_edit ed = {old, n_old, seg_xy, n_new, reach, 1, mx, my};
    list_near_points(o, &ed);
}

float polyc__local_eval(const polyc__opt *o, const float *seg_xy, int n_new)
{
    polyc__seg_pre q[4];
    POLYC_ASSERT(n_new <= 4);
    for (int j = 0; j < n_new; j++)
        polyc__seg_prepare(&q[j], seg_xy + 4 * j);
    float sum = o->ev.loc_fixed;
    if (o->ev.agg_on)
        for (int j = 0; j < n_new; j++) {
            if (o->ev.agg_n[j] == 0)
                continue;
            /* n'Mn with n the unit normal of the segment from its fixed end */
            const float *e = seg_xy + 4 * j + (o->ev.agg_moving_b[j] ? 2 : 0);
            float dx = e[0] - o->ev.agg_ax[j], dy = e[1] - o->ev.agg_ay[j];
            float tx = o->ev.agg_tx[j], ty = o->ev.agg_ty[j];
            float ux = dx * tx + dy * ty, uy = dy * tx - dx * ty; /* (the moments' frame) */
            const float *m = o->ev.agg_m[j];
            sum += (m[0] * uy * uy - 2.0f * m[1] * ux * uy + m[2] * ux * ux) / (ux * ux + uy * uy);
        }
    if (o->ev.lsoa_n == o->ev.loc_n) {
        float *c = o->ev.lsoa_c;
        for (int32_t k = 0; k < o->ev.loc_n; k++)
            c[k] = o->ev.loc_base[k];
        for (int j = 0; j < n_new; j++)
            polyc__trial_costs_min(o, &q[j], c);
        /* summed in the order of the scalar loop below: the same bits */
        for (int32_t k = 0; k < o->ev.loc_n; k++)
            sum += c[k];
        return sum;
    }
    for (int32_t k = 0; k < o->ev.loc_n; k++) {
        const polyc__point *p = &o->d.pts[o->ev.loc_pt[k]];
        float c = o->ev.loc_base[k];
        for (int j = 0; j < n_new; j++) {
            float cj = polyc__seg_pre_cost(&q[j], p);
            if (cj < c)
                c = cj;
        }
        sum += c;
    }
    return sum;
}

float polyc__local_current(const polyc__opt *o)
{
    float sum = o->ev.loc_fixed_cur;
    for (int32_t k = 0; k < o->ev.loc_n; k++)
        sum += o->d.pt_cost[o->ev.loc_pt[k]];
    return sum;
}
