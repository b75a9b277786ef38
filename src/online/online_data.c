/* online_data.c - an online update's data: the weighted points of the
 * tiles it takes are made again from their cells' sums and take the place
 * of their old ones in the same arrays, in the buckets over those tiles
 * (the other tiles' points, and their segments, stay; they and the bucket
 * starts move as whole runs); the polylines the update traced join the
 * spatial hash, the points near them re-assigned as after any edit.
 * Takes: the optimiser of an online context, the taken tiles. Gives: the
 * optimiser's data and books, exact for what it holds. */
#include "../online.h"

#include <math.h>
#include <string.h>

/* Point i moved to position k (k <= i, or k >= i walking down): its
 * arrays, in place. */
static void move_point(polyc__opt *o, polyc__online *on, uint32_t i, uint32_t k)
{
    o->d.pts[k] = o->d.pts[i];
    o->d.pt_view[2 * k] = o->d.pt_view[2 * i];
    o->d.pt_view[2 * k + 1] = o->d.pt_view[2 * i + 1];
    o->d.pt_seg[k] = o->d.pt_seg[i];
    o->d.pt_cost[k] = o->d.pt_cost[i];
    on->pt_tile[k] = on->pt_tile[i];
}

/* The taken tiles are marked TAKEN in dirty_since (online_round.c). */
static int taken(const polyc__online *on, uint32_t d)
{
    return on->backlog.dirty_since[d] == UINT32_MAX;
}

/* The weighted points of the tiles at directory entries dirs (nd of
 * them), unsorted, into out, view and tile (its directory entry), at most
 * cap; returns their count (-1: more than cap); tile_raw (by tile storage
 * index) gets each tile's endpoints. */
static int32_t points_of_tiles(polyc__opt *o, const uint32_t *dirs, uint32_t nd, polyc__point *out,
                               float *view, uint32_t *tile, int32_t cap, float *tile_raw)
{
    polyc_ctx *ctx = o->ctx;
    polyc__grid *g = &ctx->grid;
    uint32_t n = 0;
    for (uint32_t j = 0; j < nd; j++)
        if (g->dir[dirs[j]]) {
            polyc__tile *t = &g->tiles[g->dir[dirs[j]] - 1];
            polyc__block_mark_tile(ctx, t);
            uint32_t next = polyc__block_number_tile(t, n);
            if (next > (uint32_t)cap)
                return -1;
            for (uint32_t i = n; i < next; i++)
                tile[i] = dirs[j];
            n = next;
        }
    memset(out, 0, (size_t)n * sizeof *out);
    memset(view, 0, (size_t)n * 2 * sizeof *view);
    for (uint32_t j = 0; j < nd; j++)
        if (g->dir[dirs[j]]) {
            tile_raw[g->dir[dirs[j]] - 1] = polyc__online_sum_tile(ctx, (int32_t)dirs[j], out, view);
            polyc__block_finish_tile(ctx, (int32_t)dirs[j], out);
        }
    n = polyc__online_drop_empty(out, view, tile, n);
    for (uint32_t i = 0; i < n; i++)
        polyc__point_weigh(&o->prior, &out[i]);
    return (int32_t)n;
}


/* New point j of the scratch into slot k; its segment is found once all
 * are in (assign_range). */
static void put(polyc__opt *o, polyc__online *on, int32_t j, uint32_t k)
{
    o->d.pts[k] = on->scr.pts_tmp[j];
    o->d.pt_view[2 * k] = on->scr.view_tmp[2 * j];
    o->d.pt_view[2 * k + 1] = on->scr.view_tmp[2 * j + 1];
    o->d.pt_seg[k] = POLYC__NONE - 1;
    on->pt_tile[k] = on->scr.fresh_tile[j];
}

/* the new points among slots i0..i1 - 1 to their nearest segments, into
 * the error */
static void assign_range(polyc__opt *o, uint32_t i0, uint32_t i1)
{
    for (uint32_t i = i0; i < i1; i++)
        if (o->d.pt_seg[i] == POLYC__NONE - 1) {
            o->d.pt_cost[i] = polyc__nearest(o, (int32_t)i, NULL, 0, &o->d.pt_seg[i]);
            polyc__ksum_add(&o->err, o->d.pt_cost[i]);
            if (o->d.pt_seg[i] != POLYC__NONE)
                o->split_due[o->d.pt_seg[i]] = 1;
        }
}

/* Above this many buckets an update's points are all laid out again. */
#define LOCAL_BUCKETS_MAX 4096

void polyc__online_list_taken_buckets(polyc_ctx *ctx, uint32_t taken)
{
    polyc__online *on = ctx->online;
    polyc__opt *o = &on->opt;
    const polyc__grid *g = &ctx->grid;
    const polyc__hash *h = &o->h;
    float tile_m = g->cell_m * (float)POLYC__TILE_SIDE;
    float ox = g->frame_ox, oy = g->frame_oy;
    polyc__chg_begin(o); /* a new epoch for the bucket marks */
    for (uint32_t k = 0; k < taken; k++) {
        uint32_t d = on->backlog.dirty[k];
        float x0 = ox + (float)(d % (uint32_t)g->tiles_x) * tile_m;
        float y0 = oy + (float)(d / (uint32_t)g->tiles_x) * tile_m;
        int32_t bx0, by0, bx1, by1;
        polyc__bucket_xy(h, x0, y0, &bx0, &by0);
        polyc__bucket_xy(h, x0 + tile_m, y0 + tile_m, &bx1, &by1);
        bx0 = bx0 > 0 ? bx0 - 1 : 0;
        by0 = by0 > 0 ? by0 - 1 : 0;
        bx1 = bx1 + 1 < h->bx ? bx1 + 1 : h->bx - 1;
        by1 = by1 + 1 < h->by ? by1 + 1 : h->by - 1;
        for (int32_t by = by0; by <= by1; by++)
            for (int32_t bx = bx0; bx <= bx1; bx++) {
                int32_t b = by * h->bx + bx;
                if (o->chg.bucket_mark[b] == o->chg.epoch)
                    continue;
                o->chg.bucket_mark[b] = o->chg.epoch;
                o->chg.bucket_list[o->chg.bucket_n++] = b;
            }
    }
}

/* the n bucket numbers in place, ascending (Shell's sort: n is small) */
static void sort_buckets(int32_t *b, int32_t n)
{
    static const int32_t gaps[] = {701, 301, 132, 57, 23, 10, 4, 1};
    for (size_t g = 0; g < sizeof gaps / sizeof gaps[0]; g++)
        for (int32_t i = gaps[g]; i < n; i++) {
            int32_t v = b[i], j = i;
            for (; j >= gaps[g] && b[j - gaps[g]] > v; j -= gaps[g])
                b[j] = b[j - gaps[g]];
            b[j] = v;
        }
}

/* n bucket starts moved by d (none goes below 0): half of an update's
 * buckets on average, eight at a time (which a compiler makes two vector
 * adds at -O2) */
static void add_to_starts(uint32_t *start, size_t n, int64_t d)
{
    const uint32_t add = (uint32_t)(d & 0xffffffff); /* (modulo 2^32: d < 0 too) */
    size_t i = 0;
    for (; i + 8 <= n; i += 8)
        for (int k = 0; k < 8; k++)
            start[i + (size_t)k] += add;
    for (; i < n; i++)
        start[i] += add;
}

/* slots [i0, i1) moved by d (a block of every array) */
static void shift_slots(polyc__opt *o, polyc__online *on, uint32_t i0, uint32_t i1, int64_t d)
{
    if (i1 <= i0 || d == 0)
        return;
    size_t n = i1 - i0, to = (size_t)((int64_t)i0 + d);
    memmove(&o->d.pts[to], &o->d.pts[i0], n * sizeof *o->d.pts);
    memmove(&o->d.pt_view[2 * to], &o->d.pt_view[2 * (size_t)i0], 2 * n * sizeof *o->d.pt_view);
    memmove(&o->d.pt_seg[to], &o->d.pt_seg[i0], n * sizeof *o->d.pt_seg);
    memmove(&o->d.pt_cost[to], &o->d.pt_cost[i0], n * sizeof *o->d.pt_cost);
    memmove(&on->pt_tile[to], &on->pt_tile[i0], n * sizeof *on->pt_tile);
}

/* The listed buckets (o->chg.bucket_list, those within a bucket of the
 * taken tiles) made again in place: every point in them out of the error,
 * those of tiles not taken back into the scratch after the nf new ones
 * (found their segment again with them); the other buckets' points, in
 * runs between listed buckets, moved by what the listed ones below them
 * grew (runs that move down lowest first, then those that move up highest
 * first: none overwrites one not yet moved), their starts by the same; the
 * scratch's points into the listed buckets. */
static polyc_status replace_local(polyc_ctx *ctx, int32_t nf, int32_t cap)
{
    polyc__online *on = ctx->online;
    polyc__opt *o = &on->opt;
    polyc__hash *h = &o->h;
    const int32_t nb = h->bx * h->by, na = o->chg.bucket_n;
    int32_t *aff = o->chg.bucket_list;
    uint32_t *fill = on->bucket_fill;
    sort_buckets(aff, na);
    /* the total first: nothing changes when there is no room */
    int64_t total = (int64_t)h->pt_start[nb] + nf;
    for (int32_t k = 0; k < na; k++)
        for (uint32_t i = h->pt_start[aff[k]]; i < h->pt_start[aff[k] + 1]; i++)
            total -= taken(on, on->pt_tile[i]) ? 1 : 0;
    if (total > cap)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "more weighted data points than limits.max_points");
    int32_t n = nf;
    for (int32_t k = 0; k < na; k++) {
        for (uint32_t i = h->pt_start[aff[k]]; i < h->pt_start[aff[k] + 1]; i++) {
            polyc__ksum_add(&o->err, -(o->d.pt_cost[i]));
            if (o->d.pt_seg[i] != POLYC__NONE)
                o->split_due[o->d.pt_seg[i]] = 1;
            if (taken(on, on->pt_tile[i]))
                continue;
            on->scr.pts_tmp[n] = o->d.pts[i];
            on->scr.view_tmp[2 * n] = o->d.pt_view[2 * i];
            on->scr.view_tmp[2 * n + 1] = o->d.pt_view[2 * i + 1];
            on->scr.fresh_tile[n] = on->pt_tile[i];
            n++;
        }
        fill[aff[k]] = 0;
    }
    for (int32_t j = 0; j < n; j++) {
        int32_t b = polyc__bucket_of(h, on->scr.pts_tmp[j].x, on->scr.pts_tmp[j].y);
        POLYC_ASSERT(o->chg.bucket_mark[b] == o->chg.epoch); /* inside a taken tile */
        on->scr.fresh_bucket[j] = b;
        fill[b]++;
    }
    /* run k lies between listed buckets k - 1 and k (run na above the
     * last): its points [start[aff[k - 1] + 1], start[aff[k]]) move by d,
     * what the listed buckets below it grew */
    int64_t d = 0;
    for (int32_t k = 0; k <= na; k++) {
        uint32_t i0 = k > 0 ? h->pt_start[aff[k - 1] + 1] : 0, i1 = h->pt_start[k < na ? aff[k] : nb];
        if (d < 0)
            shift_slots(o, on, i0, i1, d);
        if (k < na)
            d += (int64_t)fill[aff[k]] - (int64_t)(h->pt_start[aff[k] + 1] - h->pt_start[aff[k]]);
    }
    for (int32_t k = na; k >= 0; k--) {
        if (k < na)
            d -= (int64_t)fill[aff[k]] - (int64_t)(h->pt_start[aff[k] + 1] - h->pt_start[aff[k]]);
        uint32_t i0 = k > 0 ? h->pt_start[aff[k - 1] + 1] : 0, i1 = h->pt_start[k < na ? aff[k] : nb];
        if (d > 0)
            shift_slots(o, on, i0, i1, d);
    }
    /* the starts: bucket b in (aff[k - 1], aff[k]] by run k's d; then each
     * listed bucket's fill is where its points go */
    for (int32_t k = 0; k <= na; k++) {
        int32_t b0 = k > 0 ? aff[k - 1] + 1 : 0, b1 = k < na ? aff[k] : nb;
        uint32_t grow = k < na ? fill[aff[k]] : 0, was = k < na ? h->pt_start[aff[k] + 1] - h->pt_start[aff[k]] : 0;
        if (d != 0)
            add_to_starts(h->pt_start + b0, (size_t)(b1 - b0) + 1, d);
        if (k < na) {
            fill[aff[k]] = h->pt_start[aff[k]];
            d += (int64_t)grow - (int64_t)was;
        }
    }
    for (int32_t j = 0; j < n; j++)
        put(o, on, j, fill[on->scr.fresh_bucket[j]]++);
    o->d.np = (int32_t)total;
    for (int32_t k = 0; k < na; k++)
        assign_range(o, h->pt_start[aff[k]], h->pt_start[aff[k] + 1]);
    return POLYC_OK;
}

/* Every bucket laid out again: the old points of the taken tiles out of
 * the error, the kept ones moved in place, the nf new ones put after them. */
static polyc_status replace_all(polyc_ctx *ctx, int32_t nf, int32_t cap)
{
    /* old points of the taken tiles out of the error; the kept ones counted
     * per bucket (nothing moves before the room is known) */
    polyc__online *on = ctx->online;
    polyc__opt *o = &on->opt;
    polyc__hash *h = &o->h;
    int32_t nb = h->bx * h->by;
    uint32_t *kept_in = on->bucket_fill;
    int32_t kept = 0;
    for (int32_t b = 0; b < nb; b++) {
        kept_in[b] = 0;
        for (uint32_t i = h->pt_start[b]; i < h->pt_start[b + 1]; i++) {
            if (!taken(on, on->pt_tile[i])) {
                kept_in[b]++;
                kept++;
                continue;
            }
            polyc__ksum_add(&o->err, -(o->d.pt_cost[i]));
            if (o->d.pt_seg[i] != POLYC__NONE)
                o->split_due[o->d.pt_seg[i]] = 1;
        }
    }
    if (kept + nf > cap)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "more weighted data points than limits.max_points");
    /* in place, bucket by bucket: the kept points, then the new. First the
     * kept ones down to the front, in order; then the buckets' new starts;
     * then, last bucket first, each bucket's kept points up to its start
     * (never past a lower bucket's, which start no later than they end
     * up), the new points after them */
    uint32_t w = 0;
    for (uint32_t i = 0; i < h->pt_start[nb]; i++)
        if (!taken(on, on->pt_tile[i]))
            move_point(o, on, i, w++);
    memset(h->pt_start, 0, ((size_t)nb + 1) * sizeof(uint32_t));
    for (int32_t j = 0; j < nf; j++) {
        on->scr.fresh_bucket[j] = polyc__bucket_of(h, on->scr.pts_tmp[j].x, on->scr.pts_tmp[j].y);
        h->pt_start[on->scr.fresh_bucket[j] + 1]++;
    }
    for (int32_t b = 0; b < nb; b++)
        h->pt_start[b + 1] += h->pt_start[b] + kept_in[b];
    for (int32_t b = nb - 1; b >= 0; b--) {
        uint32_t n_b = kept_in[b];
        w -= n_b;
        for (uint32_t k = n_b; k-- > 0;)
            move_point(o, on, w + k, h->pt_start[b] + k);
        kept_in[b] = h->pt_start[b] + n_b; /* where its new points go */
    }
    for (int32_t j = 0; j < nf; j++) {
        uint32_t k = kept_in[on->scr.fresh_bucket[j]]++;
        put(o, on, j, k);
    }
    o->d.np = kept + nf;
    assign_range(o, 0, (uint32_t)o->d.np);
    return POLYC_OK;
}

static polyc_status refresh(polyc_ctx *ctx, uint32_t n_taken);

/* The new points' scratch, above the tiles, given back whatever the outcome. */
polyc_status polyc__online_refresh_tiles(polyc_ctx *ctx, uint32_t n_taken)
{
    polyc__online *on = ctx->online;
    size_t mark = ctx->arena.used;
    polyc_status st;
    if (!polyc__online_scratch(&ctx->arena, on, polyc__points_bound(&ctx->cfg, &ctx->lim), POLYC__STEP_POINTS))
        st = polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the data points");
    else
        st = refresh(ctx, n_taken);
    ctx->arena.used = mark;
    on->scr.pts_tmp = NULL;
    on->scr.view_tmp = NULL;
    on->scr.fresh_tile = NULL;
    on->scr.fresh_bucket = NULL;
    return st;
}

static polyc_status refresh(polyc_ctx *ctx, uint32_t n_taken)
{
    polyc__online *on = ctx->online;
    polyc__opt *o = &on->opt;
    polyc__hash *h = &o->h;
    o->prior = on->prior; /* its totals and weights are kept as scans come */
    polyc_status st = polyc__spacing_build(ctx, &o->spacing);
    if (st != POLYC_OK)
        return st;
    /* the new points of the taken tiles, unsorted; the endpoints the BIC
     * counts, the taken tiles' as they are now */
    int32_t cap = polyc__points_bound(o->cfg, &ctx->lim);
    const polyc__grid *g = &ctx->grid;
    for (uint32_t j = 0; j < n_taken; j++)
        if (g->dir[on->backlog.dirty[j]]) {
            o->d.n -= on->backlog.tile_raw[g->dir[on->backlog.dirty[j]] - 1];
            on->backlog.tile_new[g->dir[on->backlog.dirty[j]] - 1] = 0;
            on->backlog.tile_miss[g->dir[on->backlog.dirty[j]] - 1] = 0;
        }
    int32_t nf = points_of_tiles(o, on->backlog.dirty, n_taken, on->scr.pts_tmp, on->scr.view_tmp, on->scr.fresh_tile,
                                 cap, on->backlog.tile_raw);
    if (nf < 0)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "more weighted data points than limits.max_points");
    for (uint32_t j = 0; j < n_taken; j++)
        if (g->dir[on->backlog.dirty[j]])
            o->d.n += on->backlog.tile_raw[g->dir[on->backlog.dirty[j]] - 1];
    /* the buckets that can hold the taken tiles' points: an update's few
     * are replaced where they are, the others' points and starts moved as
     * whole blocks; many (a finish, a correction) are all laid out again */
    polyc__online_list_taken_buckets(ctx, n_taken);
    int32_t nb = h->bx * h->by;
    st = o->chg.bucket_n <= LOCAL_BUCKETS_MAX && o->chg.bucket_n <= nb / 8 ? replace_local(ctx, nf, cap)
                                                                             : replace_all(ctx, nf, cap);
    o->chg.bucket_n = 0;
    if (st != POLYC_OK)
        return st;
    o->d.log_n = polyc__logf(o->d.n > 1.0f ? o->d.n : 1.0f);
    ctx->stats.weighted_points = (uint32_t)o->d.np;
    ctx->stats.data_points = (uint32_t)o->d.n; /* (a count of returns, < 2^32) */
    return POLYC_OK;
}

void polyc__online_drop_lines(polyc_ctx *ctx, uint32_t after_id)
{
    polyc__opt *o = &ctx->online->opt;
    polyc__store *s = o->s;
    for (int32_t l = 0; l < s->l_high; l++) {
        if (s->l[l].closed == POLYC__NONE || s->l[l].id <= after_id)
            continue;
        polyc__chg_begin(o);
        int32_t v = s->l[l].head;
        for (int32_t k = 0; k < s->l[l].count; k++, v = s->v[v].next)
            if (o->chg.v_dirty[v] != o->chg.epoch && !o->seg_in[v])
                o->acost[v] = 0.0f; /* never counted: nothing to take out */
        while (s->l[l].closed != POLYC__NONE && s->l[l].count > 1)
            polyc__op_remove(o, s->l[l].head);
        if (s->l[l].closed != POLYC__NONE) /* one vertex left (a trace cut short) */
            polyc__line_free(s, l);
        polyc__chg_commit(o);
    }
}

polyc_status polyc__online_add_lines(polyc_ctx *ctx, uint32_t after_id)
{
    polyc__opt *o = &ctx->online->opt;
    const polyc__store *s = o->s;
    for (int32_t l = 0; l < s->l_high; l++) {
        const polyc__line *ln = &s->l[l];
        if (ln->closed == POLYC__NONE || ln->count == 0 || ln->id <= after_id)
            continue;
        /* a polyline at a time: its vertices' angles fit the change's books */
        polyc__chg_begin(o);
        int32_t v = ln->head;
        for (int32_t k = 0; k < ln->count; k++) {
            if (!polyc__chg_seg_in(o, v))
                return polyc__fail(ctx, POLYC_ERR_NOMEM, "spatial hash full (limits.max_vertices)");
            o->acost[v] = 0.0f; /* a new vertex: no angle counted yet */
            polyc__chg_dirty(o, v);
            o->split_due[v] = 1;
            v = s->v[v].next;
        }
        polyc__chg_commit(o);
    }
    return POLYC_OK;
}
