/* spatial_hash.c - uniform buckets for nearest-segment queries.
 * Takes: the grid extent and the polyline segments. Gives: per bucket the
 * segments passing through it (a segment is entered in every bucket its
 * path crosses) and the data points lying in it. With buckets at least as
 * wide as the search radius, every segment within reach of a point passes
 * through the 3 x 3 buckets around it. */
#include "../opt_state.h"
#include "../walk.h"

/* the external definitions of optimize.h's inline functions (C99: used
 * where a caller does not inline them, as at -Os) */
extern inline int polyc__buckets_around(const polyc__hash *h, int32_t bx, int32_t by, int32_t out[9]);
extern inline void polyc__bucket_xy(const polyc__hash *h, float x, float y, int32_t *ix, int32_t *iy);
extern inline float polyc__seg_dist2(float px, float py, float ax, float ay, float bx, float by);

#include <math.h>
#include <string.h>

#define HASH_MARGIN_M 2.0f /* vertices may wander a little outside the grid */
#define HASH_BUCKETS_PER_BEAM 16

int32_t polyc__hash_bucket_cap_tiles(size_t tiles)
{
    size_t cap = 4 * (tiles * 4 + 64) + 1024; /* wider buckets when the map is larger */
    return tiles > 0x1000000 || cap > 0x3fffffff ? 0x3fffffff : (int32_t)cap;
}

int32_t polyc__hash_bucket_cap(const polyc_limits *lim)
{
    size_t tiles = ((size_t)lim->max_grid_cells + POLYC__TILE_CELLS - 1) / POLYC__TILE_CELLS;
    size_t cap = (size_t)polyc__hash_bucket_cap_tiles(tiles);
    /* and wider when the data are few for the area (one scan's 361 returns
     * over 80 m x 80 m): clearing and counting 160,000 buckets took more
     * than the queries saved (at 16 buckets a beam single scans take fewer
     * instructions for the same maps) */
    size_t by_beams = (size_t)lim->max_beams * HASH_BUCKETS_PER_BEAM + 4096;
    if (by_beams < cap)
        cap = by_beams;
    return cap > 0x3fffffff ? 0x3fffffff : (int32_t)cap;
}

/* A segment takes an entry in each bucket its path crosses: three for a
 * short one, and the long ones more, one per bucket they pass. Beyond three
 * a vertex, the entries are room for the long segments to pass every bucket
 * once (a wall through each bucket), at most HASH_LONG_ENTRIES: a small
 * area's hash needs no more than its buckets. */
#define HASH_LONG_ENTRIES 4096

int32_t polyc__hash_entry_cap(const polyc_limits *lim, size_t nb)
{
    int64_t v = polyc__max_vertices(lim);
    int64_t cap = 3 * v + (nb < HASH_LONG_ENTRIES ? (int64_t)nb : HASH_LONG_ENTRIES);
    return cap > 0x3fffffff ? 0x3fffffff : (int32_t)cap;
}

/* nb buckets' lists, marks and point ranges, and the entries */
static int hash_carve(polyc__arena *a, polyc__opt *o, size_t nb, int32_t entry_cap)
{
    polyc__hash *h = &o->h;
    h->seg_head = polyc__alloc(a, nb, sizeof(int32_t));
    h->pt_start = polyc__alloc(a, nb + 1, sizeof(uint32_t));
    h->entry_cap = entry_cap;
    h->entries = polyc__alloc(a, (size_t)h->entry_cap, sizeof(polyc__hash_entry));
    o->chg.bucket_mark = polyc__alloc_zero(a, nb, sizeof(uint32_t));
    o->chg.bucket_list = polyc__alloc(a, nb, sizeof(int32_t));
    return h->seg_head && h->pt_start && h->entries && o->chg.bucket_mark && o->chg.bucket_list;
}

void polyc__hash_reserve(polyc__arena *a, polyc__opt *o, const polyc_limits *lim)
{
    size_t nb = (size_t)polyc__hash_bucket_cap(lim);
    hash_carve(a, o, nb, polyc__hash_entry_cap(lim, nb));
}

polyc_status polyc__hash_init(polyc__opt *o)
{
    if (!polyc__hash_lay_out(o, &o->ctx->arena, polyc__hash_bucket_cap(&o->ctx->lim)))
        return polyc__fail(o->ctx, POLYC_ERR_NOMEM, "no room for the spatial hash");
    polyc__hash_clear(o);
    return POLYC_OK;
}

int polyc__hash_lay_out(polyc__opt *o, polyc__arena *a, int32_t cap)
{
    polyc_ctx *ctx = o->ctx;
    polyc__hash *h = &o->h;
    const polyc__grid *g = &ctx->grid;
    memset(h, 0, sizeof *h);
    float w_m = (float)g->width * g->cell_m + 2.0f * HASH_MARGIN_M;
    float h_m = (float)g->height * g->cell_m + 2.0f * HASH_MARGIN_M;
    /* at least the search radius plus the reach of one hill-climbing round */
    float b = o->R + POLYC__CLIMB_REACH_M;
    while ((float)ceilf(w_m / b) * (float)ceilf(h_m / b) > (float)cap)
        b *= 1.25f;
    h->bucket_m = b;
    h->inv_bucket = 1.0f / b;
    h->bx = (int32_t)ceilf(w_m / b);
    h->by = (int32_t)ceilf(h_m / b);
    h->origin_x = g->frame_ox - HASH_MARGIN_M;
    h->origin_y = g->frame_oy - HASH_MARGIN_M;
    size_t nb = (size_t)h->bx * (size_t)h->by;
    return hash_carve(a, o, nb, polyc__hash_entry_cap(&ctx->lim, nb));
}

void polyc__hash_clear(polyc__opt *o)
{
    polyc__hash *h = &o->h;
    for (int32_t i = 0; i < h->bx * h->by; i++)
        h->seg_head[i] = POLYC__NONE;
    /* entries come from the freed ones first, then from the top: nothing
     * to initialise for the (limit-sized) rest */
    h->entry_free = POLYC__NONE;
    h->entry_top = 0;
    h->entry_live = 0;
    h->out_of_entries = 0;
    if (o->seg_in)
        memset(o->seg_in, 0, (size_t)o->s->v_cap);
}

static int32_t clampi(int32_t v, int32_t hi)
{
    return v < 0 ? 0 : (v > hi ? hi : v);
}

int32_t polyc__bucket_of(const polyc__hash *h, float x, float y)
{
    int32_t ix, iy;
    polyc__bucket_xy(h, x, y, &ix, &iy);
    return iy * h->bx + ix;
}

/* Clips segment (ax, ay)-(bx, by), in bucket units, to [0, w] x [0, h]
 * (Liang-Barsky); 0 if nothing is left. Parts outside the area are farther
 * than its margin from every data point, so they matter to no query. */
static int clip(float *ax, float *ay, float *bx, float *by, float w, float h)
{
    float dx = *bx - *ax, dy = *by - *ay, t0 = 0.0f, t1 = 1.0f;
    float p[4] = {-dx, dx, -dy, dy}, q[4] = {*ax, w - *ax, *ay, h - *ay};
    for (int i = 0; i < 4; i++) {
        if (p[i] == 0.0f) {
            if (q[i] < 0.0f)
                return 0;
            continue;
        }
        float r = q[i] / p[i];
        if (p[i] < 0.0f) {
            if (r > t1) return 0;
            if (r > t0) t0 = r;
        } else {
            if (r < t0) return 0;
            if (r < t1) t1 = r;
        }
    }
    float x0 = *ax + t0 * dx, y0 = *ay + t0 * dy;
    *bx = *ax + t1 * dx;
    *by = *ay + t1 * dy;
    *ax = x0;
    *ay = y0;
    return 1;
}

/* The walk of polyc__traverse, inline, over the buckets the segment's path
 * crosses (clipped to the hash), in order, the end bucket last. */
typedef struct path_walk {
    polyc__walk w;
    int done;
} path_walk;

/* 0 if the path misses the hash. */
static int path_begin(const polyc__hash *h, float ax, float ay, float bx, float by, path_walk *p)
{
    float wx = (float)h->bx - 0.001f, wy = (float)h->by - 0.001f;
    polyc__beam b;
    b.sx = (ax - h->origin_x) * h->inv_bucket;
    b.sy = (ay - h->origin_y) * h->inv_bucket;
    b.ex = (bx - h->origin_x) * h->inv_bucket;
    b.ey = (by - h->origin_y) * h->inv_bucket;
    if (!clip(&b.sx, &b.sy, &b.ex, &b.ey, wx, wy))
        return 0;
    b.hit = 1;
    b.miss_end = 1.0f;
    polyc__walk_start(&p->w, &b);
    p->done = 0;
    return 1;
}

static int path_next(path_walk *p, int32_t *ix, int32_t *iy)
{
    if (p->done)
        return 0;
    if (p->w.n <= 0) {
        *ix = p->w.ex;
        *iy = p->w.ey;
        p->done = 1;
        return 1;
    }
    *ix = p->w.ix;
    *iy = p->w.iy;
    polyc__walk_step(&p->w);
    return 1;
}

void polyc__segment_buckets(polyc__opt *o, float ax, float ay, float bx, float by,
                            polyc__bucket_fn fn, void *user)
{
    const polyc__hash *h = &o->h;
    path_walk p;
    int32_t ix, iy;
    if (!path_begin(h, ax, ay, bx, by, &p))
        return;
    while (path_next(&p, &ix, &iy))
        fn(o, user, clampi(iy, h->by - 1) * h->bx + clampi(ix, h->bx - 1));
}

void polyc__segment_region(polyc__opt *o, float ax, float ay, float bx, float by)
{
    const polyc__hash *h = &o->h;
    const uint32_t epoch = o->chg.epoch;
    path_walk p;
    int32_t ix, iy;
    if (!path_begin(h, ax, ay, bx, by, &p))
        return;
    while (path_next(&p, &ix, &iy)) {
        /* the 3 x 3 around it in polyc__buckets_around's order, written
         * out (this is the hottest bucket walk) */
        int32_t x0 = ix > 0 ? ix - 1 : 0, x1 = ix + 1 < h->bx ? ix + 1 : h->bx - 1;
        int32_t y0 = iy > 0 ? iy - 1 : 0, y1 = iy + 1 < h->by ? iy + 1 : h->by - 1;
        for (int32_t y = y0; y <= y1; y++)
            for (int32_t k = y * h->bx + x0; k <= y * h->bx + x1; k++) {
                if (o->chg.bucket_mark[k] == epoch)
                    continue;
                o->chg.bucket_mark[k] = epoch;
                o->chg.bucket_list[o->chg.bucket_n++] = k;
            }
    }
}

/* the side of p that line q-r leaves it on (twice the signed area) */
static float orient(const polyc__vertex *q, const polyc__vertex *r, const polyc__vertex *p)
{
    return (r->x - q->x) * (p->y - q->y) - (r->y - q->y) * (p->x - q->x);
}

/* Whether the segments of vertices p and q come within sqrt(lim2) of each
 * other, or cross (or lie on one line). */
POLYC__NOINLINE static int segments_near(const polyc__store *s, int32_t p, int32_t q, float lim2)
{
    const polyc__vertex *e[4] = {&s->v[p], &s->v[s->v[p].next], &s->v[q], &s->v[s->v[q].next]};
    for (int k = 0; k < 4; k++) { /* each end against the other segment */
        const polyc__vertex *c = e[k], *a = e[k < 2 ? 2 : 0], *b = e[k < 2 ? 3 : 1];
        if (polyc__seg_dist2(c->x, c->y, a->x, a->y, b->x, b->y) <= lim2)
            return 1;
    }
    return orient(e[0], e[1], e[2]) * orient(e[0], e[1], e[3]) <= 0.0f &&
           orient(e[2], e[3], e[0]) * orient(e[2], e[3], e[1]) <= 0.0f;
}

int polyc__segment_near_other(const polyc__opt *o, int32_t v, float reach)
{
    const polyc__hash *h = &o->h;
    const polyc__vertex *a = &o->s->v[v], *b = &o->s->v[a->next];
    path_walk p;
    int32_t ix, iy, around[9];
    if (!path_begin(h, a->x, a->y, b->x, b->y, &p))
        return 0;
    while (path_next(&p, &ix, &iy)) {
        int n = polyc__buckets_around(h, ix, iy, around);
        for (int i = 0; i < n; i++)
            for (int32_t e = h->seg_head[around[i]]; e != POLYC__NONE; e = h->entries[e].next) {
                int32_t sg = h->entries[e].seg;
                if (!polyc__touches(o->s, sg, v, a->next) && segments_near(o->s, v, sg, reach * reach))
                    return 1;
            }
    }
    return 0;
}

/* The bucket callbacks get the segment id as their user pointer. */
static void insert_in_bucket(polyc__opt *o, void *user, int32_t bucket)
{
    polyc__hash *h = &o->h;
    int32_t e = h->entry_free;
    if (e != POLYC__NONE) {
        h->entry_free = h->entries[e].next;
    } else if (h->entry_top < h->entry_cap) {
        e = h->entry_top++;
    } else {
        h->out_of_entries = 1;
        return;
    }
    h->entries[e].seg = *(const int32_t *)user;
    h->entries[e].next = h->seg_head[bucket];
    h->seg_head[bucket] = e;
    h->entry_live++;
}

static void remove_from_bucket(polyc__opt *o, void *user, int32_t bucket)
{
    polyc__hash *h = &o->h;
    const int32_t seg = *(const int32_t *)user;
    int32_t *link = &h->seg_head[bucket];
    while (*link != POLYC__NONE) {
        int32_t e = *link;
        if (h->entries[e].seg == seg) {
            *link = h->entries[e].next;
            h->entries[e].next = h->entry_free;
            h->entry_free = e;
            h->entry_live--;
            return;
        }
        link = &h->entries[e].next;
    }
}

int polyc__hash_insert(polyc__opt *o, int32_t seg)
{
    const polyc__vertex *a = &o->s->v[seg];
    const polyc__vertex *b = &o->s->v[a->next];
    polyc__segment_buckets(o, a->x, a->y, b->x, b->y, insert_in_bucket, &seg);
    o->seg_in[seg] = 1;
    o->split_due[seg] = 1; /* every new or moved segment comes in here */
    return !o->h.out_of_entries;
}

void polyc__hash_remove(polyc__opt *o, int32_t seg)
{
    const polyc__vertex *a = &o->s->v[seg];
    const polyc__vertex *b = &o->s->v[a->next];
    polyc__segment_buckets(o, a->x, a->y, b->x, b->y, remove_from_bucket, &seg);
    o->seg_in[seg] = 0;
}
