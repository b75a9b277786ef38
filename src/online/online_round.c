/* online_round.c - a round of an online update: the backlog's tiles
 * nearest the robot and oldest first, as many as the work budget allows;
 * the data refreshed from the cells' sums; their contour cells that no
 * polyline explains traced into new polylines; the search's operators run
 * on what lies in and next to those tiles (the rest of the map is only
 * looked at by the operators that scan it whole, and stays where it is
 * unless they gain). Takes: the online state (online.h). Gives: the map in
 * the store (online_update.c publishes it). */
#include "../cost.h"
#include "../online.h"

#include <math.h>
#include <string.h>

/* A contour cell this near the map is explained by it: no new polyline
 * (the operators move the map onto its data), where a polyline's side
 * allows (explained() below) */
#define EXPLAINED_M 0.10f
/* and this near always: a diagonal neighbour's centre */
#define NEAR_CELLS 1.42f
/* a side is clear when the view is at least 30 degrees off the segment
 * (sin 30 degrees) */
#define CLEAR_SIDE 0.5f
/* The work of a tile: its cells with endpoints, and this for the tile. */
#define TILE_WORK 64u
/* A tile waiting in the backlog gains this on the nearer ones per scan
 * added since it changed: nearest first, but none waits for ever. */
#define AGE_M_PER_SCAN 0.25f
/* The tile taken in a round is marked so in dirty_since until it is done. */
#define TAKEN UINT32_MAX

static float tile_key(const polyc_ctx *ctx, uint32_t d)
{
    const polyc__grid *g = &ctx->grid;
    const polyc__online *on = ctx->online;
    float tile_m = g->cell_m * (float)POLYC__TILE_SIDE;
    float ox = g->frame_ox, oy = g->frame_oy;
    float cx = ox + ((float)(d % (uint32_t)g->tiles_x) + 0.5f) * tile_m;
    float cy = oy + ((float)(d / (uint32_t)g->tiles_x) + 0.5f) * tile_m;
    float dx = cx - on->poses.last_x, dy = cy - on->poses.last_y;
    float age = (float)(on->scans + 1 - on->backlog.dirty_since[d]);
    return sqrtf(dx * dx + dy * dy) - AGE_M_PER_SCAN * age;
}

static uint32_t tile_work(const polyc_ctx *ctx, uint32_t d)
{
    const polyc__grid *g = &ctx->grid;
    if (!g->dir[d])
        return TILE_WORK;
    return TILE_WORK + ctx->online->tab.tile_cells[g->dir[d] - 1];
}

/* Moves the tiles to take to the front of the backlog (all of them, or
 * by key until `work` is spent; ties by directory index) and marks them;
 * returns how many, with the units in *units. */
static uint32_t take_tiles(polyc_ctx *ctx, uint64_t work, int all, uint64_t *units)
{
    polyc__online *on = ctx->online;
    uint32_t taken = 0;
    *units = 0;
    while (taken < on->backlog.dirty_n && (all || taken == 0 || *units < work)) {
        uint32_t best = taken;
        if (!all) {
            float best_key = tile_key(ctx, on->backlog.dirty[taken]);
            for (uint32_t i = taken + 1; i < on->backlog.dirty_n; i++) {
                float k = tile_key(ctx, on->backlog.dirty[i]);
                if (k < best_key || (k == best_key && on->backlog.dirty[i] < on->backlog.dirty[best])) {
                    best_key = k;
                    best = i;
                }
            }
        }
        uint32_t d = on->backlog.dirty[best];
        on->backlog.dirty[best] = on->backlog.dirty[taken];
        on->backlog.dirty[taken++] = d;
        *units += tile_work(ctx, d);
    }
    for (uint32_t i = 0; i < taken; i++)
        on->backlog.dirty_since[on->backlog.dirty[i]] = TAKEN;
    return taken;
}

/* Whether the map explains a contour cell at (x, y), seen along (vx, vy)
 * (its endpoints' vectors to their sensors, summed): a segment passes
 * within `near` (a diagonal neighbour) of it; or one passes within `far`
 * (10 cm), with the foot of the perpendicular at least `near` inside its
 * polyline (not at or past an open end), seen from one side only and from
 * the cell's side (or from no known side). So the band of a wall (traced,
 * it becomes a fan of lines a few cm apart) is left to the wall, and what
 * lies at or past an end (a door jamb, a thin wall's end, a corner) or
 * across the line (the other face of a thin wall) is traced. With `sides`
 * 0 (no views, or cells of 7 cm and more) `near` is all. */
static int explained(const polyc__opt *o, float x, float y, float near, float far, float vx,
                     float vy, int sides)
{
    const polyc__hash *h = &o->h;
    const polyc__store *s = o->s;
    polyc__near_segs w;
    POLYC__FOR_NEAR_SEGS(w, h, x, y, sg) {
        const polyc__vertex *a = &s->v[sg], *b = &s->v[a->next];
        float d2 = polyc__seg_dist2(x, y, a->x, a->y, b->x, b->y);
        if (d2 <= near * near)
            return 1;
        if (d2 > far * far || (sides && polyc__two_sided(o, sg)))
            continue;
        float dx = b->x - a->x, dy = b->y - a->y, len = sqrtf(dx * dx + dy * dy);
        if (!(len > 0.0f))
            continue;
        /* the foot's distance from a along the segment */
        float u = ((x - a->x) * dx + (y - a->y) * dy) / len;
        float from_a = a->prev == POLYC__NONE ? near : 0.0f;
        float from_b = b->next == POLYC__NONE ? near : 0.0f;
        if (u < from_a || u > len - from_b)
            continue;
        /* the sides along the segment's left normal (-dy, dx), each
         * taken only when seen clearly across the segment: a wall seen
         * at a grazing angle has no side to speak of (a wall seen along
         * its length got lines on both "sides", a wedge) */
        float sx = o->seg_side ? o->seg_side[2 * sg] : 0.0f;
        float sy = o->seg_side ? o->seg_side[2 * sg + 1] : 0.0f;
        float seen = -sx * dy + sy * dx, cell = -vx * dy + vy * dx;
        if (seen * cell >= 0.0f || fabsf(seen) < CLEAR_SIDE * len * sqrtf(sx * sx + sy * sy) ||
            fabsf(cell) < CLEAR_SIDE * len * sqrtf(vx * vx + vy * vy))
            return 1;
    }
    return 0;
}

/* The points of the buckets within a bucket of the taken tiles, listed in
 * o->region_pt: those that give the sides of the segments near the tiles'
 * cells (their sides there). Returns their count. (From every point in
 * every round, as the zip took them too, the sides cost each round in
 * proportion to the whole map, not to its region.) */
static int32_t taken_points(polyc_ctx *ctx, uint32_t taken)
{
    polyc__online_list_taken_buckets(ctx, taken);
    return polyc__listed_points(&ctx->online->opt);
}

/* The taken tiles' contour cells that are occupied now (or data alone now:
 * contour.c's fallback) and that no polyline explains, marked and listed
 * for the trace; returns their count.
 * `all`: every tile is taken (the sides from every point). */
static uint32_t unexplained_cells(polyc_ctx *ctx, uint32_t taken, float near, int all)
{
    polyc__online *on = ctx->online;
    polyc__grid *g = &ctx->grid;
    polyc__opt *o = &on->opt;
    /* the sides matter only where `near` is less than EXPLAINED_M */
    int sides = near < EXPLAINED_M && o->seg_side != NULL;
    if (sides) {
        const int32_t *list = NULL;
        int32_t np = 0;
        if (!all) {
            np = taken_points(ctx, taken);
            list = o->region_pt;
        }
        polyc__side_scratch sd = polyc__sides(o);
        polyc__find_sides(o, list, np, sd.left_w, sd.right_w);
    }
    float thr = ctx->cfg.contour_threshold;
    float ox = g->frame_ox, oy = g->frame_oy;
    for (uint32_t k = 0; k < g->tile_count; k++)
        memset(g->tiles[k].mark, 0, sizeof g->tiles[k].mark);
    uint32_t n = 0;
    for (uint32_t i = 0; i < taken; i++) {
        uint32_t d = on->backlog.dirty[i];
        if (!g->dir[d])
            continue;
        polyc__tile *t = &g->tiles[g->dir[d] - 1];
        int32_t tx = (int32_t)(d % (uint32_t)g->tiles_x) << POLYC__TILE_SHIFT;
        int32_t ty = (int32_t)(d / (uint32_t)g->tiles_x) << POLYC__TILE_SHIFT;
        for (int r = 0; r < POLYC__TILE_SIDE; r++)
            for (int c = 0; t->contour[r] != 0 && c < POLYC__TILE_SIDE; c++) {
                int idx = (r << POLYC__TILE_SHIFT) | c;
                if (!((t->contour[r] >> c) & 1u) || n >= polyc__online_cells_cap(on) ||
                    (!polyc__cell_occupied(t, idx, thr) &&
                     !polyc__contour_data_alone(ctx, tx + c, ty + r, 0)))
                    continue;
                float x = (float)(ox + ((float)(tx + c) + 0.5f) * (float)g->cell_m);
                float y = (float)(oy + ((float)(ty + r) + 0.5f) * (float)g->cell_m);
                float vx = 0.0f, vy = 0.0f;
                if (sides)
                    polyc__online_cell_view(ctx, tx + c, ty + r, &vx, &vy);
                if (o->s->l_live > 0 && explained(o, x, y, near, EXPLAINED_M, vx, vy, sides))
                    continue;
                t->mark[r] |= 1u << c;
                on->scr.cells[2 * n] = tx + c;
                on->scr.cells[2 * n + 1] = ty + r;
                n++;
            }
    }
    return n;
}

/* Stamps the vertices of the segments that pass through a taken tile (or
 * within the search radius of it) as edited at `since`: the operators that
 * look at what changed since a stamp take them. */
static void stamp_region(polyc_ctx *ctx, uint32_t taken, uint32_t since)
{
    polyc__online *on = ctx->online;
    polyc__opt *o = &on->opt;
    const polyc__grid *g = &ctx->grid;
    const polyc__hash *h = &o->h;
    float tile_m = g->cell_m * (float)POLYC__TILE_SIDE, pad = o->R;
    float ox = g->frame_ox, oy = g->frame_oy;
    for (uint32_t k = 0; k < taken; k++) {
        uint32_t d = on->backlog.dirty[k];
        float x0 = ox + (float)(d % (uint32_t)g->tiles_x) * tile_m - pad;
        float y0 = oy + (float)(d / (uint32_t)g->tiles_x) * tile_m - pad;
        float x1 = x0 + tile_m + 2.0f * pad, y1 = y0 + tile_m + 2.0f * pad;
        int32_t bx0, by0, bx1, by1;
        polyc__bucket_xy(h, x0, y0, &bx0, &by0);
        polyc__bucket_xy(h, x1, y1, &bx1, &by1);
        for (int32_t by = by0; by <= by1; by++)
            for (int32_t bx = bx0; bx <= bx1; bx++)
                for (int32_t e = h->seg_head[by * h->bx + bx]; e != POLYC__NONE; e = h->entries[e].next) {
                    int32_t a = h->entries[e].seg, b = o->s->v[a].next;
                    if (o->v_touch[a] == since && o->v_touch[b] == since)
                        continue;
                    const polyc__vertex *va = &o->s->v[a], *vb = &o->s->v[b];
                    if (polyc__maxf(va->x, vb->x) < x0 || polyc__minf(va->x, vb->x) > x1 ||
                        polyc__maxf(va->y, vb->y) < y0 || polyc__minf(va->y, vb->y) > y1)
                        continue;
                    o->v_touch[a] = o->v_touch[b] = since;
                    o->split_due[a] = 1;
                }
    }
}

/* Polylines of the region with no data point within the support distance
 * of any of their segments go: traced on what the grid held then (a person
 * walking by), their points left the data when the tile was made again.
 * (In a batch build every polyline starts on contour cells that hold data.)
 * Requiring the support to lie in occupied cells as well dropped the
 * people's lines in open halls but also walls drawn through bands, whose
 * cells fall under the contour threshold, and the real logs' final maps
 * came out clearly worse for it. */
static void drop_dataless(polyc__opt *o, uint8_t *has)
{
    const polyc__store *s = o->s;
    memset(has, 0, (size_t)s->v_high);
    int32_t np = polyc__region_points(o, polyc__in_region);
    float sup2 = (float)o->d.support_m * (float)o->d.support_m;
    for (int32_t j = 0; j < np; j++) {
        int32_t i = o->region_pt[j], sg = o->d.pt_seg[i];
        if (sg != POLYC__NONE && o->d.pt_cost[i] <= sup2 * (float)o->d.pts[i].w)
            has[sg] = 1;
    }
    for (int32_t l = 0; l < s->l_high; l++) {
        const polyc__line *ln = &s->l[l];
        if (ln->closed == POLYC__NONE || ln->count == 0)
            continue;
        int in = 0, data = 0;
        int32_t v = ln->head;
        for (int32_t k = 0; k < ln->count; k++, v = s->v[v].next) {
            in |= o->v_touch[v] >= o->region_since;
            data |= has[v];
        }
        if (!in || data)
            continue;
        polyc__chg_begin(o);
        while (s->l[l].closed != POLYC__NONE && s->l[l].count > 0)
            polyc__op_remove(o, s->l[l].head);
        polyc__chg_commit(o);
    }
}

/* The pieces of map that an end this round edited lies along, stamped as
 * edited; returns how many. The zip looks at edited segments only, and a
 * round's climb can bring an end along a piece outside the region that the
 * round did not edit: where two ends reach into one segment from both
 * sides, that segment is doubly covered over 20 cm and more, and no later
 * round need come near it (a large log, with sparse tiles waiting in the
 * backlog, kept such doubled walls for hundreds of scans). "Along": the
 * end within overlap_m of the piece, its segment within ALONG_COS of
 * parallel to it (an end at a T junction is not). */
#define ALONG_COS 0.866f /* cos 30 degrees */
static uint32_t stamp_near_ends(polyc__opt *o, uint32_t since)
{
    const polyc__store *s = o->s;
    const polyc__hash *h = &o->h;
    float lim2 = o->cfg->overlap_m * o->cfg->overlap_m;
    uint32_t stamp = ++o->touch_stamp, n = 0;
    for (int32_t v = 0; v < s->v_high; v++) {
        const polyc__vertex *e = &s->v[v];
        if (e->line == POLYC__NONE || o->v_touch[v] < since ||
            (e->prev != POLYC__NONE && e->next != POLYC__NONE) ||
            (e->prev == POLYC__NONE && e->next == POLYC__NONE))
            continue;
        const polyc__vertex *f = &s->v[e->prev != POLYC__NONE ? e->prev : e->next];
        float ex = f->x - e->x, ey = f->y - e->y, el = sqrtf(ex * ex + ey * ey);
        polyc__near_segs w;
        POLYC__FOR_NEAR_SEGS(w, h, e->x, e->y, sg) {
            const polyc__vertex *c = &s->v[sg], *d = &s->v[c->next];
            if (c->line == e->line || polyc__edited_since(o, sg, since) ||
                polyc__seg_dist2(e->x, e->y, c->x, c->y, d->x, d->y) > lim2)
                continue;
            float dx = d->x - c->x, dy = d->y - c->y, dl = sqrtf(dx * dx + dy * dy);
            if (fabsf(ex * dx + ey * dy) < ALONG_COS * el * dl)
                continue;
            o->v_touch[sg] = stamp;
            n++;
        }
    }
    return n;
}

/* The ends within merge reach that the operators left in the region,
 * linked (op_merge), then fused where that lowers the BIC and climbed onto
 * the data; returns how many links. The operators merge first, and their
 * split, climbs and trims leave some ends within reach again; a batch
 * build's next iteration links those, an update's next round does only if
 * its region holds them. Left, they piled up: the online maps of a log
 * held many times the batch map's pairs of ends of two polylines within
 * 15 cm, most of them two-vertex pieces of one wall. */
static int link_left_ends(polyc__opt *o)
{
    if (!o->pol.restructure)
        return 0;
    uint32_t mark = ++o->touch_stamp;
    int linked = polyc__op_merge_folds(o, POLYC__HAIRPINS_REFUSED);
    if (linked > 0) {
        polyc__op_remove_vertices(o, mark);
        polyc__op_adjust(o, POLYC__ADJUST_ROUNDS, mark);
    }
    return linked;
}

/* Whether a vertex was edited since the zip's last pass began. */
static int edited_after_zip(const polyc__opt *o)
{
    const polyc__store *s = o->s;
    for (int32_t v = 0; v < s->v_high; v++)
        if (s->v[v].line != POLYC__NONE && o->v_touch[v] >= o->zip_mark)
            return 1;
    return 0;
}

static polyc_status remap_taken_tiles(polyc_ctx *ctx, uint64_t work, int all, uint64_t *spent);

/* An update's scratch (the points made again, the contour cells, the
 * trace's walk: online.h) sits above the grid's tiles, which must stay
 * contiguous for the next scan's: it is given back whatever the round's
 * outcome. */
polyc_status polyc__online_round(polyc_ctx *ctx, uint64_t work, int all, uint64_t *spent)
{
    size_t mark = ctx->arena.used;
    ctx->flat.circ_n = ctx->flat.arc_n = 0; /* (polyc_find_curves: the map changes) */
    polyc_status st = remap_taken_tiles(ctx, work, all, spent);
    ctx->arena.used = mark;
    ctx->online->scr.cells = NULL;
    ctx->online->scr.seg_data = NULL;
    return st;
}

/* The round's sequence, on the tiles it takes from the backlog (all of
 * them with `all`, or as many as `work` allows; *spent gets their work):
 * 1. their points made again from the cells' sums (online_data.c);
 * 2. their contour cells that no polyline explains traced into new
 *    polylines, which join the optimiser's books;
 * 3. the vertices in and near the tiles stamped as edited: the region;
 * 4. the search's operators on the region (without adding vertices);
 * 5. the region's polylines that no point supports dropped, the ends the
 *    operators left within reach linked, the pieces they lie along zipped,
 *    folds and crossings repaired, the gaps at ends closed;
 * 6. the tiles out of the backlog. */
static polyc_status remap_taken_tiles(polyc_ctx *ctx, uint64_t work, int all, uint64_t *spent)
{
    polyc__online *on = ctx->online;
    polyc__opt *o = &on->opt;
    uint32_t taken = take_tiles(ctx, work, all, spent);
    polyc_status st = polyc__online_refresh_tiles(ctx, taken);
    if (st != POLYC_OK)
        return st;
    on->opt_ready = 1;
    uint32_t since = ++o->touch_stamp;
    if (!polyc__online_scratch(&ctx->arena, on, 0, POLYC__STEP_TRACE))
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the contour cells");
    uint32_t n = unexplained_cells(ctx, taken, NEAR_CELLS * ctx->grid.cell_m, all);
    if (n > 0) {
        uint32_t last_id = o->s->last_id;
        st = polyc__trace_cells(ctx, on->scr.cells, n);
        if (st == POLYC_OK)
            st = polyc__online_add_lines(ctx, last_id);
        if (st != POLYC_OK) { /* the map stays the one before */
            polyc__online_drop_lines(ctx, last_id);
            return st;
        }
    }
    /* in the trace's walk's room, given back (polyc__online_scratch) */
    if (!polyc__online_scratch(&ctx->arena, on, 0, POLYC__STEP_DATALESS))
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the round's scratch");
    stamp_region(ctx, taken, since);
    o->region_since = since;
    /* the batch iteration's operators from the table, without additions:
     * the finishing search adds vertices, and with them in every round
     * the updates took far longer for the same final map */
    polyc__op_args ops;
    memset(&ops, 0, sizeof ops);
    ops.since = ops.climb = since;
    ops.skip = POLYC__OPF_ADDS;
    ops.status = POLYC_OK;
    polyc__run_ops(o, POLYC__SEQ_ITERATION, &ops);
    drop_dataless(o, on->scr.seg_data);
    int merged = link_left_ends(o);
    /* the operators' zip came before their crossing repair and the drop of
     * dataless polylines: what those edited, and the pieces of map the ends
     * lie along, are zipped now */
    if (o->pol.restructure && (stamp_near_ends(o, since) > 0 || edited_after_zip(o)))
        polyc__op_zip(o);
    /* (the map between updates draws no wall twice, and crosses nothing
     * where the climbs after the links went) */
    if (polyc__op_unfold(o) + merged > 0)
        polyc__op_untangle(o);
    if (polyc__op_end_gaps(o) >= 1000) {
        polyc__op_untangle(o);
        polyc__op_end_gaps(o);
    }
    o->region_since = 0;
    POLYC__CHECKS_ITERATION(o);
    for (uint32_t i = 0; i < taken; i++)
        on->backlog.dirty_since[on->backlog.dirty[i]] = 0;
    on->backlog.dirty_n -= taken;
    memmove(on->backlog.dirty, on->backlog.dirty + taken, (size_t)on->backlog.dirty_n * sizeof on->backlog.dirty[0]);
    on->pending = 0;
    if (o->h.out_of_entries)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "spatial hash full (limits.max_vertices)");
    return POLYC_OK;
}

