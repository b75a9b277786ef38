/* score.c - the BIC (paper eqs. 2, 3, 5) and its incremental bookkeeping.
 * Takes: data points, polylines, the spatial hash, the angle prior. Gives:
 * each point's nearest segment and capped cost, the model's error and angle
 * terms, updated after an edit by rescoring only the points near the
 * segments that changed; and a read-only local evaluation for trial moves. */
#include "optimize.h"

#include <math.h>

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

/* Sum of squared distances of a weighted point's endpoints to segment a-b,
 * all of them taken to fall in the region (interior or end) of their mean. */
double polyc__cost(const polyc__point *p, float ax, float ay, float bx, float by)
{
    double dx = (double)bx - (double)ax, dy = (double)by - (double)ay;
    double mx = (double)p->x - (double)ax, my = (double)p->y - (double)ay;
    double l2 = dx * dx + dy * dy;
    double trace = (double)p->cxx + (double)p->cyy;
    double t = l2 > 1e-18 ? (mx * dx + my * dy) / l2 : 0.0;
    if (t <= 0.0)
        return (double)p->w * (mx * mx + my * my) + trace;
    if (t >= 1.0) {
        double ex = (double)p->x - (double)bx, ey = (double)p->y - (double)by;
        return (double)p->w * (ex * ex + ey * ey) + trace;
    }
    /* w (n.m)^2 + n'Cn with n = (-dy, dx) / |d|: one division, no root.
     * C, central moments summed in float, can be a rounding error short of
     * positive semi-definite (cxy^2 > cxx cyy): n'Cn then dips below 0 for
     * a point whose endpoints lie on a line, and a map's error could be
     * -1e-12 (found by fuzz_library). A sum of squares is never negative. */
    double cross = dx * my - dy * mx;
    double c = ((double)p->w * cross * cross + dy * dy * (double)p->cxx -
                2.0 * dx * dy * (double)p->cxy + dx * dx * (double)p->cyy) / l2;
    return c > 0.0 ? c : 0.0;
}

double polyc__cost_seg(const polyc__opt *o, const polyc__point *p, int32_t seg)
{
    const polyc__vertex *a = &o->s->v[seg];
    const polyc__vertex *b = &o->s->v[a->next];
    return polyc__cost(p, a->x, a->y, b->x, b->y);
}

static double cap_of(const polyc__opt *o, const polyc__point *p)
{
    return (double)p->w * (double)o->R2;
}

/* The nearest segment costing less than `start` (NONE and `start` if there
 * is none). Own bucket first, then the eight around it nearest first, each
 * only if it is nearer than the best cost so far allows: a segment is
 * entered in every bucket it crosses, so one within distance D of the point
 * crosses a bucket within D of it, and its cost is at least w D^2. */
static double nearest_below(const polyc__opt *o, int32_t pi, const int32_t *skip, int n_skip,
                            double start, int32_t *seg)
{
    static const int8_t ORDER[9][2] = {{0, 0}, {-1, 0}, {1, 0}, {0, -1}, {0, 1},
                                       {-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
    const polyc__hash *h = &o->h;
    const polyc__point *p = &o->d.pts[pi];
    double best = start, w = (double)p->w;
    int32_t best_seg = POLYC__NONE;
    int32_t bx, by;
    polyc__bucket_xy(h, p->x, p->y, &bx, &by);
    /* distances to the bucket's four sides (0 if outside that side) */
    double fx = ((double)p->x - (double)h->origin_x) - (double)bx * (double)h->bucket_m;
    double fy = ((double)p->y - (double)h->origin_y) - (double)by * (double)h->bucket_m;
    double side[2][3];
    side[0][0] = fx > 0.0 ? fx : 0.0;
    side[0][1] = 0.0;
    side[0][2] = (double)h->bucket_m - fx > 0.0 ? (double)h->bucket_m - fx : 0.0;
    side[1][0] = fy > 0.0 ? fy : 0.0;
    side[1][1] = 0.0;
    side[1][2] = (double)h->bucket_m - fy > 0.0 ? (double)h->bucket_m - fy : 0.0;
    double near = side[0][0];
    for (int k = 1; k < 4; k++) {
        double g = side[k >> 1][k & 1 ? 2 : 0];
        near = g < near ? g : near;
    }
    for (int k = 0; k < 9; k++) {
        /* the own bucket done: no neighbour is nearer than its nearest side */
        if (k == 1 && w * near * near >= best)
            break;
        double sx = side[0][ORDER[k][0] + 1], sy = side[1][ORDER[k][1] + 1];
        if (w * (sx * sx + sy * sy) >= best)
            continue;
        int32_t x = bx + ORDER[k][0], y = by + ORDER[k][1];
        if (x < 0 || x >= h->bx || y < 0 || y >= h->by)
            continue;
        for (int32_t e = h->seg_head[y * h->bx + x]; e != POLYC__NONE; e = h->entries[e].next) {
            int32_t sg = h->entries[e].seg;
            int skipped = 0;
            for (int j = 0; j < n_skip; j++)
                skipped |= skip[j] == sg;
            if (skipped)
                continue;
            double c = polyc__cost_seg(o, p, sg);
            if (c < best) {
                best = c;
                best_seg = sg;
            }
        }
    }
    if (seg)
        *seg = best_seg;
    return best;
}

double polyc__nearest(const polyc__opt *o, int32_t pi, const int32_t *skip, int n_skip,
                      int32_t *seg)
{
    return nearest_below(o, pi, skip, n_skip, cap_of(o, &o->d.pts[pi]), seg);
}

/* 1 - p(turn | x, y) at v; open ends have no angle. */
double polyc__vertex_angle_cost(const polyc__opt *o, int32_t v)
{
    if (o->cfg->gamma <= 0.0f)
        return 0.0;
    const polyc__vertex *c = &o->s->v[v];
    if (c->prev == POLYC__NONE || c->next == POLYC__NONE)
        return 0.0;
    const polyc__vertex *a = &o->s->v[c->prev], *b = &o->s->v[c->next];
    return polyc__turn_cost(o, a->x, a->y, c->x, c->y, b->x, b->y);
}

double polyc__bic(const polyc__opt *o)
{
    return (double)o->cfg->alpha * (o->err + (double)o->cfg->gamma * o->angle) +
           (double)o->s->v_live * o->d.log_n;
}

polyc_status polyc__rebuild(polyc__opt *o)
{
    polyc__store *s = o->s;
    polyc__hash_clear(o);
    o->angle = 0.0;
    for (int32_t v = 0; v < s->v_high; v++) {
        o->acost[v] = 0.0;
        if (s->v[v].line == POLYC__NONE)
            continue;
        if (s->v[v].next != POLYC__NONE && !polyc__hash_insert(o, v))
            return polyc__fail(o->ctx, POLYC_ERR_NOMEM, "spatial hash full");
        o->acost[v] = polyc__vertex_angle_cost(o, v);
        o->angle += o->acost[v];
    }
    o->err = 0.0;
    for (int32_t i = 0; i < o->d.np; i++) {
        o->d.pt_cost[i] = polyc__nearest(o, i, NULL, 0, &o->d.pt_seg[i]);
        o->err += o->d.pt_cost[i];
    }
    return POLYC_OK;
}

/* ---- recording a change ---- */

static void mark_segment_region(polyc__opt *o, int32_t seg)
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
    mark_segment_region(o, seg);
    polyc__hash_remove(o, seg);
    o->chg.seg_dead[seg] = o->chg.epoch;
}

int polyc__chg_seg_in(polyc__opt *o, int32_t seg)
{
    if (seg == POLYC__NONE || o->seg_in[seg] || o->s->v[seg].next == POLYC__NONE)
        return 1;
    int ok = polyc__hash_insert(o, seg);
    mark_segment_region(o, seg);
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
    o->angle -= o->acost[v];
    o->acost[v] = 0.0;
    o->chg.dirty_list[o->chg.dirty_n++] = v;
}

void polyc__chg_commit(polyc__opt *o)
{
    const polyc__hash *h = &o->h;
    for (int32_t k = 0; k < o->chg.bucket_n; k++) {
        int32_t b = o->chg.bucket_list[k];
        for (uint32_t i = h->pt_start[b]; i < h->pt_start[b + 1]; i++) {
            double old = o->d.pt_cost[i], c;
            int32_t seg = o->d.pt_seg[i];
            if (o->chg.added_overflow || (seg != POLYC__NONE && o->chg.seg_dead[seg] == o->chg.epoch)) {
                c = polyc__nearest(o, (int32_t)i, NULL, 0, &seg);
            } else {
                c = old;
                for (int32_t a = 0; a < o->chg.added_n; a++) {
                    int32_t sg = o->chg.added[a];
                    if (!o->seg_in[sg])
                        continue;
                    double ca = polyc__cost_seg(o, &o->d.pts[i], sg);
                    if (ca < c) {
                        c = ca;
                        seg = sg;
                    }
                }
            }
            o->d.pt_cost[i] = c;
            polyc__split_due_pt(o, o->d.pt_seg[i], seg);
            o->d.pt_seg[i] = seg;
            o->err += c - old;
        }
    }
    for (int32_t k = 0; k < o->chg.dirty_n; k++) {
        int32_t v = o->chg.dirty_list[k];
        if (o->s->v[v].line == POLYC__NONE)
            continue;
        o->acost[v] = polyc__vertex_angle_cost(o, v);
        o->angle += o->acost[v];
    }
    o->chg.bucket_n = o->chg.added_n = o->chg.dirty_n = 0;
}

/* ---- local evaluation (read-only) ---- */

static void seg_prepare(polyc__seg_pre *q, const float *xy)
{
    q->ax = (double)xy[0];
    q->ay = (double)xy[1];
    q->bx = (double)xy[2];
    q->by = (double)xy[3];
    q->dx = q->bx - q->ax;
    q->dy = q->by - q->ay;
    double l2 = q->dx * q->dx + q->dy * q->dy;
    q->inv_l2 = l2 > 1e-18 ? 1.0 / l2 : 0.0;
    double inv = l2 > 1e-18 ? 1.0 / sqrt(l2) : 0.0;
    q->nx = -q->dy * inv;
    q->ny = q->dx * inv;
}

/* Same value as polyc__cost, without the per-call divisions. */
static double seg_cost(const polyc__seg_pre *q, const polyc__point *p)
{
    double mx = (double)p->x - q->ax, my = (double)p->y - q->ay;
    double t = (mx * q->dx + my * q->dy) * q->inv_l2;
    if (t <= 0.0 || q->inv_l2 == 0.0)
        return (double)p->w * (mx * mx + my * my) + ((double)p->cxx + (double)p->cyy);
    if (t >= 1.0) {
        double ex = (double)p->x - q->bx, ey = (double)p->y - q->by;
        return (double)p->w * (ex * ex + ey * ey) + ((double)p->cxx + (double)p->cyy);
    }
    double d = q->nx * mx + q->ny * my;
    double c = (double)p->w * d * d + (q->nx * q->nx * (double)p->cxx +
                                       2.0 * q->nx * q->ny * (double)p->cxy +
                                       q->ny * q->ny * (double)p->cyy);
    return c > 0.0 ? c : 0.0; /* as polyc__cost */
}

/* A segment's start, direction and squared length, for point_seg_dist. */
typedef struct seg_span {
    double ax, ay, dx, dy, l2;
} seg_span;

static seg_span seg_span_of(const float *xy)
{
    seg_span q;
    q.ax = (double)xy[0];
    q.ay = (double)xy[1];
    q.dx = (double)xy[2] - (double)xy[0];
    q.dy = (double)xy[3] - (double)xy[1];
    q.l2 = q.dx * q.dx + q.dy * q.dy;
    return q;
}

static double point_seg_dist(const polyc__point *p, const seg_span *q)
{
    double dx = q->dx, dy = q->dy;
    double mx = (double)p->x - q->ax, my = (double)p->y - q->ay;
    double l2 = q->l2;
    double t = l2 > 1e-18 ? (mx * dx + my * dy) / l2 : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    double ex = mx - t * dx, ey = my - t * dy;
    return sqrt(ex * ex + ey * ey);
}

/* Can a move of the shared end c (by at most rho) take point p out of the
 * interior of segment a-c, or make the other moving segment beat it? If
 * not, the returned bound exceeds its cost on a-c for every trial, where
 * that cost is exactly w (n.(p-a))^2 + n'Cn; if no other segment costs less
 * than the bound either, the point can join the segment's moments. d_own
 * and d_other are the distances of p to this segment and to the other
 * moving one (1e30 if none). Returns 0 if the point may leave. */
static double stay_bound(const polyc__point *p, double ax, double ay, double cx, double cy,
                         double rho, double d_own, double d_other)
{
    double px = (double)p->x, py = (double)p->y;
    double ux = cx - ax, uy = cy - ay, pax = px - ax, pay = py - ay;
    /* projection after the end at a: (p-a).(c-a) > 0 for all |dc| <= rho */
    if (pax * ux + pay * uy - sqrt(pax * pax + pay * pay) * rho <= 0.0)
        return 0.0;
    /* before the end at c: (c-p).(c-a) >= (c0-p).(c0-a) - rho |2c0-p-a| */
    double cpx = cx - px, cpy = cy - py, sx = cpx + ux, sy = cpy + uy;
    if (cpx * ux + cpy * uy - rho * sqrt(sx * sx + sy * sy) <= 0.0)
        return 0.0;
    /* its cost here is at most w (d + rho)^2 + trace(C), the other's at
     * least w (d' - rho)^2 */
    double w = (double)p->w, up = d_own + rho, lo = d_other - rho;
    double worst = w * up * up + ((double)p->cxx + (double)p->cyy);
    return lo > 0.0 && worst < w * lo * lo ? worst : 0.0;
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
static double nearest_candidate(const polyc__opt *o, int32_t pi, double start, int32_t *seg)
{
    const polyc__point *p = &o->d.pts[pi];
    double best = start, w = (double)p->w;
    int32_t best_seg = POLYC__NONE;
    for (int32_t k = 0; k < o->ev.cand_n; k++) {
        const float *box = o->ev.cand_box + 4 * k;
        /* distance to the box, a lower bound of the segment's: differences
         * of floats are exact in double, so the bound is never too high */
        double px = (double)p->x, py = (double)p->y;
        double gx = (double)box[0] - px > px - (double)box[2] ? (double)box[0] - px : px - (double)box[2];
        double gy = (double)box[1] - py > py - (double)box[3] ? (double)box[1] - py : py - (double)box[3];
        gx = gx > 0.0 ? gx : 0.0;
        gy = gy > 0.0 ? gy : 0.0;
        if (0.999 * w * (gx * gx + gy * gy) >= best)
            continue;
        double c = polyc__cost_seg(o, p, o->ev.cand_seg[k]);
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
typedef struct old_set {
    int32_t a, b;
    const int32_t *rest;
    int n_rest;
} old_set;

static old_set old_set_of(const int32_t *old, int n_old)
{
    old_set s;
    s.a = n_old > 0 ? old[0] : POLYC__NONE;
    s.b = n_old > 1 ? old[1] : POLYC__NONE;
    s.rest = n_old > 2 ? old + 2 : old; /* never past the caller's array */
    s.n_rest = n_old > 2 ? n_old - 2 : 0;
    return s;
}

/* whether the point's segment seg (NONE: none) is one of them */
static int is_old(const old_set *s, int32_t seg)
{
    if (seg == POLYC__NONE)
        return 0;
    int hit = seg == s->a || seg == s->b;
    for (int j = 0; j < s->n_rest; j++)
        hit |= seg == s->rest[j];
    return hit;
}

/* Collects the points near the `old` segments and the candidate geometry,
 * with their cost when the old segments are gone (loc_base, loc_seg). With
 * reach > 0 the candidates stay within `reach` of seg_xy: a point not on an
 * old segment whose cost is below any cost it could get from them never
 * changes, and is summed once into loc_fixed instead of being listed. With
 * `move`, the candidates differ by the position of the shared end (mx, my)
 * only, and the points that stay on one segment are aggregated. */
static void prepare(polyc__opt *o, const int32_t *old, int n_old, const float *seg_xy, int n_new,
                    float reach, int move, float mx, float my)
{
    const polyc__hash *h = &o->h;
    const old_set olds = old_set_of(old, n_old);
    seg_span span[4];
    POLYC_ASSERT(n_new <= 4);
    for (int j = 0; j < n_new; j++)
        span[j] = seg_span_of(seg_xy + 4 * j);
    o->chg.epoch++;
    o->chg.bucket_n = 0;
    for (int k = 0; k < n_old; k++)
        if (old[k] != POLYC__NONE)
            mark_segment_region(o, old[k]);
    /* moving: the candidates start where the old segments are, and their
     * moves stay within the buckets' margin */
    for (int k = 0; k < n_new && !move; k++) {
        const float *q = seg_xy + 4 * k;
        polyc__segment_region(o, q[0], q[1], q[2], q[3]);
    }
    o->ev.cand_n = -1;
    o->ev.loc_n = 0;
    o->ev.loc_fixed = 0.0;
    o->ev.loc_fixed_cur = 0.0;
    o->ev.agg_on = move && n_new <= 2;
    o->ev.agg_n[0] = o->ev.agg_n[1] = 0;
    for (int j = 0; j < 2; j++) {
        o->ev.agg_m[j][0] = o->ev.agg_m[j][1] = o->ev.agg_m[j][2] = 0.0;
        o->ev.agg_moving_b[j] = 0;
        o->ev.agg_ax[j] = o->ev.agg_ay[j] = 0.0;
    }
    if (o->ev.agg_on)
        for (int j = 0; j < n_new; j++) {
            const float *q = seg_xy + 4 * j;
            int b = q[2] == mx && q[3] == my;
            o->ev.agg_moving_b[j] = b;
            o->ev.agg_ax[j] = (double)(b ? q[0] : q[2]);
            o->ev.agg_ay[j] = (double)(b ? q[1] : q[3]);
        }
    for (int32_t k = 0; k < o->chg.bucket_n; k++) {
        int32_t b = o->chg.bucket_list[k];
        for (uint32_t i = h->pt_start[b]; i < h->pt_start[b + 1]; i++) {
            int32_t seg = o->d.pt_seg[i];
            int hit = is_old(&olds, seg);
            int32_t base_seg = seg;
            double base = o->d.pt_cost[i];
            const polyc__point *p = &o->d.pts[i];
            double d[2] = {1e30, 1e30};
            if (reach > 0.0f) {
                double dmin = 1e30;
                for (int j = 0; j < n_new; j++) {
                    double dj = point_seg_dist(p, &span[j]);
                    if (j < 2)
                        d[j] = dj;
                    if (dj < dmin)
                        dmin = dj;
                }
                dmin -= (double)reach;
                if (!hit && dmin > 0.0 && base <= (double)p->w * dmin * dmin) {
                    o->ev.loc_fixed += base;
                    o->ev.loc_fixed_cur += o->d.pt_cost[i];
                    continue;
                }
            }
            int j = n_new == 2 && d[1] < d[0];
            double bound = o->ev.agg_on ? stay_bound(p, o->ev.agg_ax[j], o->ev.agg_ay[j], (double)mx,
                                                  (double)my, (double)reach, d[j], d[1 - j])
                                     : 0.0;
            if (hit) {
                /* without the old segments: a query within the bound is
                 * enough to tell that the point stays (most do) */
                double cap = cap_of(o, p), start = bound > 0.0 && bound < cap ? bound : cap;
                if (o->ev.cand_n < 0)
                    gather_start(o, old, n_old);
                if (o->ev.cand_n >= 0 && o->ev.cand_n <= POLYC__CAND_MAX)
                    gather_around(o, b);
                base = o->ev.cand_n >= 0 && o->ev.cand_n <= POLYC__CAND_MAX
                           ? nearest_candidate(o, (int32_t)i, start, &base_seg)
                           : nearest_below(o, (int32_t)i, old, n_old, start, &base_seg);
                if (base_seg != POLYC__NONE)
                    bound = 0.0;
                else if (bound > 0.0 && bound < cap)
                    base = cap; /* unknown but irrelevant: the point stays */
                else
                    bound = 0.0;
            } else if (bound >= base) {
                bound = 0.0;
            }
            if (bound > 0.0) {
                double dx = (double)p->x - o->ev.agg_ax[j], dy = (double)p->y - o->ev.agg_ay[j];
                double w = (double)p->w;
                o->ev.agg_m[j][0] += w * dx * dx + (double)p->cxx;
                o->ev.agg_m[j][1] += w * dx * dy + (double)p->cxy;
                o->ev.agg_m[j][2] += w * dy * dy + (double)p->cyy;
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
    o->ev.lsoa_n = -1;
    /* for a few points (most of a single scan's trials) the copy costs
     * more than it saves */
    if (o->ev.loc_n >= 8 && o->ev.loc_n <= o->ev.lsoa_cap) {
        for (int32_t k = 0; k < o->ev.loc_n; k++) {
            const polyc__point *p = &o->d.pts[o->ev.loc_pt[k]];
            o->ev.lsoa_x[k] = (double)p->x;
            o->ev.lsoa_y[k] = (double)p->y;
            o->ev.lsoa_w[k] = (double)p->w;
            o->ev.lsoa_cxx[k] = (double)p->cxx;
            o->ev.lsoa_cxy[k] = (double)p->cxy;
            o->ev.lsoa_cyy[k] = (double)p->cyy;
        }
        o->ev.lsoa_n = o->ev.loc_n;
    }
}

void polyc__local_prepare(polyc__opt *o, const int32_t *old, int n_old, const float *seg_xy,
                          int n_new, float reach)
{
    prepare(o, old, n_old, seg_xy, n_new, reach, 0, 0.0f, 0.0f);
}

void polyc__local_prepare_move(polyc__opt *o, const int32_t *old, int n_old, const float *seg_xy,
                               int n_new, float reach, float mx, float my)
{
    prepare(o, old, n_old, seg_xy, n_new, reach, 1, mx, my);
}

double polyc__local_eval(const polyc__opt *o, const float *seg_xy, int n_new)
{
    polyc__seg_pre q[4];
    POLYC_ASSERT(n_new <= 4);
    for (int j = 0; j < n_new; j++)
        seg_prepare(&q[j], seg_xy + 4 * j);
    double sum = o->ev.loc_fixed;
    if (o->ev.agg_on)
        for (int j = 0; j < n_new; j++) {
            if (o->ev.agg_n[j] == 0)
                continue;
            /* n'Mn with n the unit normal of the segment from its fixed end */
            const float *e = seg_xy + 4 * j + (o->ev.agg_moving_b[j] ? 2 : 0);
            double ux = (double)e[0] - o->ev.agg_ax[j], uy = (double)e[1] - o->ev.agg_ay[j];
            const double *m = o->ev.agg_m[j];
            sum += (m[0] * uy * uy - 2.0 * m[1] * ux * uy + m[2] * ux * ux) / (ux * ux + uy * uy);
        }
    if (o->ev.lsoa_n == o->ev.loc_n) {
        double *c = o->ev.lsoa_c;
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
        double c = o->ev.loc_base[k];
        for (int j = 0; j < n_new; j++) {
            double cj = seg_cost(&q[j], p);
            if (cj < c)
                c = cj;
        }
        sum += c;
    }
    return sum;
}

double polyc__local_current(const polyc__opt *o)
{
    double sum = o->ev.loc_fixed_cur;
    for (int32_t k = 0; k < o->ev.loc_n; k++)
        sum += o->d.pt_cost[o->ev.loc_pt[k]];
    return sum;
}

/* ---- bounded change of the error (removal candidates) ---- */

/* Max-heap on loc_base (the most a pending point can add) over loc_pt. */
static void pend_sift(polyc__opt *o, int32_t i, int32_t n)
{
    double key = o->ev.loc_base[i];
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
double polyc__local_delta(polyc__opt *o, const int32_t *old, int n_old, const float *seg_xy,
                          int n_new, double limit)
{
    const polyc__hash *h = &o->h;
    const old_set olds = old_set_of(old, n_old);
    polyc__seg_pre q[4];
    POLYC_ASSERT(n_new <= 4);
    for (int j = 0; j < n_new; j++)
        seg_prepare(&q[j], seg_xy + 4 * j);
    o->chg.epoch++;
    o->chg.bucket_n = 0;
    for (int k = 0; k < n_old; k++)
        if (old[k] != POLYC__NONE)
            mark_segment_region(o, old[k]);
    for (int k = 0; k < n_new; k++) {
        const float *s = seg_xy + 4 * k;
        polyc__segment_region(o, s[0], s[1], s[2], s[3]);
    }
    double sure = 0.0; /* exact part so far; pending points add >= 0 each */
    int32_t n = 0;
    o->ev.lsoa_n = -1; /* loc_pt and loc_base are a heap here */
    for (int32_t k = 0; k < o->chg.bucket_n; k++) {
        int32_t b = o->chg.bucket_list[k];
        for (uint32_t i = h->pt_start[b]; i < h->pt_start[b + 1]; i++) {
            const polyc__point *p = &o->d.pts[i];
            double cur = o->d.pt_cost[i], c = 1e300;
            for (int j = 0; j < n_new; j++) {
                double cj = seg_cost(&q[j], p);
                if (cj < c)
                    c = cj;
            }
            int32_t seg = o->d.pt_seg[i];
            int hit = is_old(&olds, seg);
            if (!hit || c <= cur) {
                /* not hit: its cost without the old segments is cur; hit
                 * with c <= cur: no other segment beats c (all are >= cur) */
                sure += (c < cur ? c : cur) - cur;
                continue;
            }
            double cap = cap_of(o, p);
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
        double most = o->ev.loc_base[0];
        /* only a segment cheaper than the new one matters: a query within
         * that cost (usually the point's own bucket) */
        sure += nearest_below(o, i, old, n_old, most + o->d.pt_cost[i], NULL) - o->d.pt_cost[i];
        n--;
        if (n > 0) {
            o->ev.loc_base[0] = o->ev.loc_base[n];
            o->ev.loc_pt[0] = o->ev.loc_pt[n];
            pend_sift(o, 0, n);
        }
    }
    return sure;
}
