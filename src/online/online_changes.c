/* online_changes.c - what an online map's versions changed: each update
 * publishes the store as the result and compares it, polyline by polyline
 * (by id, with a hash of its points), with the last publication; a changed
 * map is a new version. Removals are remembered in a ring, so that a caller
 * can ask what changed since any version it holds while the ring reaches
 * back that far. Takes: the store. Gives: the result, versions, changes. */
#include "../online.h"

#include <string.h>

void polyc__online_pub_carve(polyc__arena *a, polyc__online *on, int32_t lines)
{
    on->pubs.pub = polyc__alloc(a, (size_t)lines, sizeof(polyc__pub));
    on->pubs.pub_next = polyc__alloc(a, (size_t)lines, sizeof(polyc__pub));
    on->pubs.gone_cap = (uint32_t)lines;
    on->pubs.gone = polyc__alloc(a, on->pubs.gone_cap, sizeof(polyc__pub));
}

/* FNV-1a over the polyline's coordinates and whether it is closed. */
static uint32_t hash_of(const polyc__flat *f, uint32_t i)
{
    uint32_t h = 2166136261u;
    const unsigned char *b = (const unsigned char *)(f->xy + 2 * (size_t)f->start[i]);
    size_t n = (size_t)(f->start[i + 1] - f->start[i]) * 2 * sizeof(float);
    for (size_t k = 0; k < n; k++)
        h = (h ^ b[k]) * 16777619u;
    return (h ^ f->closed[i]) * 16777619u;
}

/* Sorts by id (ids are unique), in place: a heap sort. The store hands
 * out slots in order but a new polyline takes a freed slot with a fresh
 * id, so on a large map the ids come far out of order: an insertion sort
 * (quadratic then) took most of the publication's time on a map of
 * thousands of polylines. */
static void sift_down(polyc__pub *p, uint32_t root, uint32_t n)
{
    polyc__pub x = p[root];
    for (;;) {
        uint32_t c = 2 * root + 1;
        if (c >= n)
            break;
        if (c + 1 < n && p[c + 1].id > p[c].id)
            c++;
        if (p[c].id <= x.id)
            break;
        p[root] = p[c];
        root = c;
    }
    p[root] = x;
}

static void sort_by_id(polyc__pub *p, uint32_t n)
{
    for (uint32_t i = n / 2; i-- > 0;)
        sift_down(p, i, n);
    for (uint32_t end = n; end > 1; end--) {
        polyc__pub t = p[0];
        p[0] = p[end - 1];
        p[end - 1] = t;
        sift_down(p, 0, end - 1);
    }
}

static void remember_removal(polyc__online *on, const polyc__pub *p, uint64_t version)
{
    if (on->pubs.gone_n == on->pubs.gone_cap) { /* the oldest is forgotten */
        on->pubs.forgot_through = on->pubs.gone[on->pubs.gone_first].version;
        on->pubs.gone_first = (on->pubs.gone_first + 1) % on->pubs.gone_cap;
        on->pubs.gone_n--;
    }
    polyc__pub *c = &on->pubs.gone[(on->pubs.gone_first + on->pubs.gone_n) % on->pubs.gone_cap];
    *c = *p;
    c->version = version;
    on->pubs.gone_n++;
}

polyc_status polyc__online_publish(polyc_ctx *ctx, uint32_t *changed)
{
    polyc__online *on = ctx->online;
    polyc__export_result(ctx);
    ctx->opt_result_valid = 1;
    ctx->stats.memory_used_bytes = (uint64_t)(polyc__bytes(1, sizeof(polyc__online_head)) + ctx->arena.peak);
    ctx->stage = POLYC__STAGE_OPTIMIZED; /* the results are readable */
    const polyc__flat *f = &ctx->flat;
    uint64_t v = on->pubs.version + 1;
    polyc__pub *next = on->pubs.pub_next;
    for (uint32_t i = 0; i < f->count; i++) {
        next[i].id = f->id[i];
        next[i].hash = hash_of(f, i);
        next[i].born = next[i].version = v;
    }
    sort_by_id(next, f->count);
    /* both sorted by id: a merge */
    uint32_t a = 0, b = 0, n = 0;
    while (a < on->pubs.pub_n || b < f->count) {
        if (b >= f->count || (a < on->pubs.pub_n && on->pubs.pub[a].id < next[b].id)) {
            remember_removal(on, &on->pubs.pub[a], v);
            a++;
            n++;
        } else if (a >= on->pubs.pub_n || next[b].id < on->pubs.pub[a].id) {
            b++; /* added */
            n++;
        } else {
            next[b].born = on->pubs.pub[a].born;
            if (next[b].hash == on->pubs.pub[a].hash)
                next[b].version = on->pubs.pub[a].version;
            else
                n++;
            a++;
            b++;
        }
    }
    on->pubs.pub_next = on->pubs.pub;
    on->pubs.pub = next;
    on->pubs.pub_n = f->count;
    if (n > 0) /* else every entry kept its version */
        on->pubs.version = v;
    *changed = n;
    return POLYC_OK;
}

polyc_status polyc_online_changes(const polyc_ctx *ctx, uint64_t since, polyc_change *out,
                                  uint32_t cap, uint32_t *count)
{
    polyc_status cst = polyc__check_ctx(ctx);
    if (cst != POLYC_OK || !count)
        return cst != POLYC_OK ? cst : POLYC_ERR_NULL;
    *count = 0;
    const polyc__online *on = ctx->online;
    if (!on)
        return POLYC_ERR_STATE;
    if (since < on->pubs.forgot_through)
        return POLYC_ERR_RANGE;
    uint32_t n = 0;
    for (uint32_t i = 0; i < on->pubs.pub_n; i++)
        n += on->pubs.pub[i].version > since;
    /* a removal since `since` of a polyline born after it: never seen there */
    for (uint32_t k = 0; k < on->pubs.gone_n; k++) {
        const polyc__pub *g = &on->pubs.gone[(on->pubs.gone_first + k) % on->pubs.gone_cap];
        n += g->version > since && g->born <= since;
    }
    *count = n;
    if (!out || cap < n)
        return POLYC_OK;
    /* the live ones are sorted by id; the removed ones merged in by id */
    uint32_t m = 0;
    for (uint32_t i = 0; i < on->pubs.pub_n; i++) {
        const polyc__pub *p = &on->pubs.pub[i];
        if (p->version <= since)
            continue;
        out[m].id = p->id;
        out[m].kind = p->born > since ? POLYC_CHANGE_ADDED : POLYC_CHANGE_MODIFIED;
        out[m].version = p->version;
        m++;
    }
    for (uint32_t k = 0; k < on->pubs.gone_n; k++) {
        const polyc__pub *g = &on->pubs.gone[(on->pubs.gone_first + k) % on->pubs.gone_cap];
        if (g->version <= since || g->born > since)
            continue;
        uint32_t j = m++;
        for (; j > 0 && out[j - 1].id > g->id; j--)
            out[j] = out[j - 1];
        out[j].id = g->id;
        out[j].kind = POLYC_CHANGE_REMOVED;
        out[j].version = g->version;
    }
    return POLYC_OK;
}

polyc_status polyc_polyline_id(const polyc_ctx *ctx, uint32_t index, uint32_t *id)
{
    polyc_status cst = polyc__check_ctx(ctx);
    if (cst != POLYC_OK || !id)
        return cst != POLYC_OK ? cst : POLYC_ERR_NULL;
    if (index >= ctx->flat.count)
        return POLYC_ERR_RANGE;
    *id = ctx->flat.id[index];
    return POLYC_OK;
}
