/* checks.c - invariant checkers (as Lua's ltests.c), compiled in with
 * -DPOLYC_CHECKS and empty otherwise: the optimiser's books against a
 * recomputation from scratch, the spatial hash against a walk of every
 * live segment's path, the store's lists, and the arena's bounds. Each
 * returns NULL when the invariant holds, or a static message naming the
 * first violation (*at: the point, vertex, line or bucket). `make
 * test-checks` runs the unit suites on a library built with them; the
 * optimiser runs the cheap ones after every iteration there. */
#include "../cost.h"

#ifdef POLYC_CHECKS

#include <math.h>

static int seg_live(const polyc__opt *o, int32_t v)
{
    return v >= 0 && v < o->s->v_high && o->s->v[v].line != POLYC__NONE &&
           o->s->v[v].next != POLYC__NONE;
}

static int close_rel(double a, double b, double rel)
{
    return fabs(a - b) <= rel * (1.0 + fmax(fabs(a), fabs(b)));
}

const char *polyc__check_arena(const polyc__arena *a)
{
    if (((uintptr_t)a->base & 15u) != 0)
        return "arena: base not 16-byte aligned";
    if (a->used > a->size || a->peak > a->size)
        return "arena: use past the block";
    if (a->used > a->peak)
        return "arena: use above its peak";
    return NULL;
}

const char *polyc__check_store(const polyc__store *s, int32_t *at)
{
    int32_t verts = 0, lines = 0;
    for (int32_t l = 0; l < s->l_high; l++) {
        const polyc__line *ln = &s->l[l];
        if (ln->closed == POLYC__NONE)
            continue;
        *at = l;
        lines++;
        if (ln->count < 2) /* a polyline left with one vertex goes (op_remove, op_cut) */
            return "store: a polyline with fewer than 2 vertices";
        if (ln->closed && ln->count < 3)
            return "store: a closed polyline with fewer than 3 vertices";
        int32_t v = ln->head, prev = ln->closed ? ln->tail : POLYC__NONE;
        for (int32_t k = 0; k < ln->count; k++) {
            if (v < 0 || v >= s->v_high || s->v[v].line != l)
                return "store: a polyline's vertex is not on it";
            if (s->v[v].prev != prev)
                return "store: a vertex's prev is not the one before it";
            prev = v;
            v = s->v[v].next;
        }
        if (prev != ln->tail)
            return "store: a polyline does not end at its tail";
        if (v != (ln->closed ? ln->head : POLYC__NONE))
            return "store: a polyline's tail links on";
        verts += ln->count;
    }
    *at = -1;
    if (verts != s->v_live || lines != s->l_live)
        return "store: live counts differ from the polylines'";
    return NULL;
}

/* one live segment's path through the hash: each bucket it visits holds
 * it once per visit */
typedef struct path_check {
    int32_t seg, visits, wrong;
    float ax, ay, bx, by;
    int32_t bucket, count;         /* the inner walk: visits of `bucket` */
} path_check;

static void count_visits(polyc__opt *o, void *user, int32_t bucket)
{
    (void)o;
    path_check *pc = user;
    pc->count += bucket == pc->bucket;
}

static void visit_bucket(polyc__opt *o, void *user, int32_t bucket)
{
    path_check *pc = user;
    int32_t have = 0;
    for (int32_t e = o->h.seg_head[bucket]; e != POLYC__NONE; e = o->h.entries[e].next)
        have += o->h.entries[e].seg == pc->seg;
    pc->bucket = bucket;
    pc->count = 0;
    polyc__segment_buckets(o, pc->ax, pc->ay, pc->bx, pc->by, count_visits, pc);
    pc->visits++;
    pc->wrong += have != pc->count;
}

const char *polyc__check_hash(polyc__opt *o, int32_t *at)
{
    const polyc__hash *h = &o->h;
    int32_t nb = h->bx * h->by, total = 0, expect = 0;
    for (int32_t b = 0; b < nb; b++)
        for (int32_t e = h->seg_head[b]; e != POLYC__NONE; e = h->entries[e].next) {
            int32_t sg = h->entries[e].seg;
            *at = b;
            if (!seg_live(o, sg) || !o->seg_in[sg])
                return "hash: a bucket holds a segment that is not live or not marked in";
            total++;
        }
    if (total != h->entry_live)
        return "hash: entries in buckets differ from entry_live";
    for (int32_t v = 0; v < o->s->v_high; v++) {
        *at = v;
        if (!seg_live(o, v)) {
            if (o->seg_in[v])
                return "hash: a vertex without a segment is marked in the hash";
            continue;
        }
        if (!o->seg_in[v])
            return "hash: a live segment is not marked in the hash";
        const polyc__vertex *a = &o->s->v[v], *c = &o->s->v[a->next];
        path_check pc = {v, 0, 0, a->x, a->y, c->x, c->y, 0, 0};
        polyc__segment_buckets(o, a->x, a->y, c->x, c->y, visit_bucket, &pc);
        if (pc.wrong)
            return "hash: a bucket on a segment's path holds it other than once per visit";
        expect += pc.visits;
    }
    *at = -1;
    if (expect != total)
        return "hash: the paths' buckets differ from the entries held";
    return NULL;
}

/* nearest segment over every live segment, capped at w R^2 as the score is */
static double brute_nearest(const polyc__opt *o, const polyc__point *p)
{
    double best = polyc__point_cap(o, p);
    for (int32_t v = 0; v < o->s->v_high; v++)
        if (seg_live(o, v)) {
            double c = polyc__cost_seg(o, p, v);
            best = c < best ? c : best;
        }
    return best;
}

const char *polyc__check_books(const polyc__opt *o, int32_t *at)
{
    double err = 0.0, angle = 0.0;
    for (int32_t i = 0; i < o->d.np; i++) {
        const polyc__point *p = &o->d.pts[i];
        double c = brute_nearest(o, p);
        int32_t ps = o->d.pt_seg[i];
        *at = i;
        err += c;
        if (!close_rel(o->d.pt_cost[i], c, 1e-12))
            return "books: a point's cost differs from its nearest segment's from scratch";
        if (ps == POLYC__NONE) {
            if (o->d.pt_cost[i] != polyc__point_cap(o, p))
                return "books: an unassigned point's cost is below the cap";
        } else if (!seg_live(o, ps)) {
            return "books: a point is assigned to a dead segment";
        } else if (polyc__cost_seg(o, p, ps) != o->d.pt_cost[i]) {
            return "books: a point's cost is not its segment's";
        }
    }
    *at = -1;
    if (!close_rel((double)polyc__err(o), err, 1e-5))
        return "books: the error differs from its sum from scratch";
    for (int32_t v = 0; v < o->s->v_high; v++) {
        if (o->s->v[v].line == POLYC__NONE)
            continue;
        double a = polyc__vertex_angle_cost(o, v);
        *at = v;
        angle += a;
        if (!close_rel(o->acost[v], a, 1e-9))
            return "books: a vertex's angle cost differs from scratch";
    }
    *at = -1;
    if (!close_rel((double)polyc__ksum_get(&o->angle), angle, 1e-5))
        return "books: the angle term differs from its sum from scratch";
    return NULL;
}

/* the points sorted by bucket: each bucket's starts in order, each point
 * in the bucket its position gives, the last end the points' count (an
 * online update moves them in runs, online_data.c) */
const char *polyc__check_point_order(const polyc__opt *o, int32_t *at)
{
    const polyc__hash *h = &o->h;
    int32_t nb = h->bx * h->by;
    if (h->pt_start[0] != 0 || h->pt_start[nb] != (uint32_t)o->d.np)
        return "points: the buckets' starts do not span the points";
    for (int32_t b = 0; b < nb; b++) {
        *at = b;
        if (h->pt_start[b] > h->pt_start[b + 1])
            return "points: a bucket starts after the next one";
        for (uint32_t i = h->pt_start[b]; i < h->pt_start[b + 1]; i++)
            if (polyc__bucket_of(h, o->d.pts[i].x, o->d.pts[i].y) != b)
                return "points: a point lies outside its bucket";
    }
    *at = -1;
    return NULL;
}

void polyc__checks_iteration(polyc__opt *o)
{
    int32_t at;
    POLYC_ASSERT(polyc__check_arena(&o->ctx->arena) == NULL);
    POLYC_ASSERT(polyc__check_store(o->s, &at) == NULL);
    POLYC_ASSERT(polyc__check_hash(o, &at) == NULL);
    POLYC_ASSERT(polyc__check_point_order(o, &at) == NULL);
}

#else
typedef int polyc__checks_off; /* ISO C: a translation unit is not empty */
#endif
