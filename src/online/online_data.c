/* online_data.c - an online update's data: the weighted points of the
 * tiles it takes are made again from their cells' sums and take the place
 * of their old ones in the same arrays (the other tiles' points, and their
 * segments, stay); the polylines the update traced join the spatial hash,
 * the points near them re-assigned as after any edit. Takes: the optimiser of an online
 * context, the taken tiles. Gives: the optimiser's data and books, exact
 * for what it holds. */
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
    /* old points of the taken tiles out of the error; the kept ones counted
     * per bucket (nothing moves before the room is known) */
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
        o->d.pts[k] = on->scr.pts_tmp[j];
        o->d.pt_view[2 * k] = on->scr.view_tmp[2 * j];
        o->d.pt_view[2 * k + 1] = on->scr.view_tmp[2 * j + 1];
        o->d.pt_seg[k] = POLYC__NONE - 1; /* new: assigned below */
        on->pt_tile[k] = on->scr.fresh_tile[j];
    }
    o->d.np = kept + nf;
    for (int32_t i = 0; i < o->d.np; i++)
        if (o->d.pt_seg[i] == POLYC__NONE - 1) {
            o->d.pt_cost[i] = polyc__nearest(o, i, NULL, 0, &o->d.pt_seg[i]);
            polyc__ksum_add(&o->err, o->d.pt_cost[i]);
            if (o->d.pt_seg[i] != POLYC__NONE)
                o->split_due[o->d.pt_seg[i]] = 1;
        }
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
