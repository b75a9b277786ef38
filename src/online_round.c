/* online_round.c - an update of an online map: the backlog's tiles nearest
 * the robot and oldest first, as many as the work budget allows; their
 * contour cells that no polyline explains traced into new polylines; the
 * data refreshed from the cells' sums; the search's operators run on what
 * lies in and next to those tiles (the rest of the map is only looked at
 * by the operators that scan it whole, and stays where it is unless they
 * gain); and the finishing call, which runs the batch search from the map.
 * Takes: the online state (online.h). Gives: the map in the store. */
#include "cost.h"
#include "online.h"

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
/* An update starts a round when the backlog holds this many tiles, when a
 * tile in it has waited this many scans, when no scan came since the last
 * update, or when there is no map yet. A round's fixed costs (the passes
 * over the map's ends, the region's books) and the climbs of the vertices
 * near the robot are then paid once for several scans, not for each. On
 * intel, 4 tiles or 8 scans made 666 rounds and 1.06 s of updates; 8 or 16
 * made 371 rounds and 0.70 s, but the sweep's worst row (online against
 * batch core precision) went from 2.73 to 3.13 times; 16 or 32, 180 rounds
 * and 1.05 s (the rounds grew), a p99 of 8 ms. */
#define ROUND_TILES 4u
#define ROUND_WAIT_SCANS 8u
/* The tile taken in a round is marked so in dirty_since until it is done. */
#define TAKEN UINT32_MAX
/* After a recount (pose corrections), each update puts back the records of
 * this many of the kept scans' beams (online.c): intel's 910 scans in 10
 * updates, some 4 ms each. */
#define REDO_BEAMS 16384u
/* Corrections count against an update's budget: a unit for every two
 * beams they cast (a beam through the grid costs about half a tile cell's
 * unit: intel's recount, 163,800 beams in 47 ms). An update whose
 * corrections spent its budget does nothing else. */
#define CAST_BEAMS_PER_UNIT 2u

static float tile_key(const polyc_ctx *ctx, uint32_t d)
{
    const polyc__grid *g = &ctx->grid;
    const polyc__online *on = ctx->online;
    float tile_m = g->cell_m * (float)POLYC__TILE_SIDE;
    float ox = g->frame_ox, oy = g->frame_oy;
    float cx = ox + ((float)(d % (uint32_t)g->tiles_x) + 0.5f) * tile_m;
    float cy = oy + ((float)(d / (uint32_t)g->tiles_x) + 0.5f) * tile_m;
    float dx = cx - on->last_x, dy = cy - on->last_y;
    float age = (float)(on->scans + 1 - on->dirty_since[d]);
    return sqrtf(dx * dx + dy * dy) - AGE_M_PER_SCAN * age;
}

static uint32_t tile_work(const polyc_ctx *ctx, uint32_t d)
{
    const polyc__grid *g = &ctx->grid;
    if (!g->dir[d])
        return TILE_WORK;
    return TILE_WORK + ctx->online->tile_cells[g->dir[d] - 1];
}

/* Moves the tiles to take to the front of the backlog (all of them, or
 * by key until `work` is spent; ties by directory index) and marks them;
 * returns how many, with the units in *units. */
static uint32_t take_tiles(polyc_ctx *ctx, uint64_t work, int all, uint64_t *units)
{
    polyc__online *on = ctx->online;
    uint32_t taken = 0;
    *units = 0;
    while (taken < on->dirty_n && (all || taken == 0 || *units < work)) {
        uint32_t best = taken;
        if (!all) {
            float best_key = tile_key(ctx, on->dirty[taken]);
            for (uint32_t i = taken + 1; i < on->dirty_n; i++) {
                float k = tile_key(ctx, on->dirty[i]);
                if (k < best_key || (k == best_key && on->dirty[i] < on->dirty[best])) {
                    best_key = k;
                    best = i;
                }
            }
        }
        uint32_t d = on->dirty[best];
        on->dirty[best] = on->dirty[taken];
        on->dirty[taken++] = d;
        *units += tile_work(ctx, d);
    }
    for (uint32_t i = 0; i < taken; i++)
        on->dirty_since[on->dirty[i]] = TAKEN;
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
    int32_t bx, by, around[9];
    polyc__bucket_xy(h, x, y, &bx, &by);
    int n = polyc__buckets_around(h, bx, by, around);
    for (int k = 0; k < n; k++)
        for (int32_t e = h->seg_head[around[k]]; e != POLYC__NONE; e = h->entries[e].next) {
            int32_t sg = h->entries[e].seg;
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
             * at a grazing angle has no side to speak of (on fhw, a wall
             * seen along its length got lines on both "sides", a wedge) */
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
 * every round, as the zip took them too, the sides were a tenth of
 * freiburg-campus's update time.) */
static int32_t taken_points(polyc_ctx *ctx, uint32_t taken)
{
    polyc__online *on = ctx->online;
    polyc__opt *o = &on->opt;
    const polyc__grid *g = &ctx->grid;
    const polyc__hash *h = &o->h;
    float tile_m = g->cell_m * (float)POLYC__TILE_SIDE;
    float ox = g->frame_ox, oy = g->frame_oy;
    polyc__chg_begin(o); /* a new epoch for the bucket marks */
    for (uint32_t k = 0; k < taken; k++) {
        uint32_t d = on->dirty[k];
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
    return polyc__listed_points(o);
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
        polyc__find_sides(o, list, np, o->size.seg_sum, o->size.seg_w);
    }
    float thr = ctx->cfg.contour_threshold;
    float ox = g->frame_ox, oy = g->frame_oy;
    for (uint32_t k = 0; k < g->tile_count; k++)
        memset(g->tiles[k].mark, 0, sizeof g->tiles[k].mark);
    uint32_t n = 0;
    for (uint32_t i = 0; i < taken; i++) {
        uint32_t d = on->dirty[i];
        if (!g->dir[d])
            continue;
        polyc__tile *t = &g->tiles[g->dir[d] - 1];
        int32_t tx = (int32_t)(d % (uint32_t)g->tiles_x) << POLYC__TILE_SHIFT;
        int32_t ty = (int32_t)(d / (uint32_t)g->tiles_x) << POLYC__TILE_SHIFT;
        for (int r = 0; r < POLYC__TILE_SIDE; r++)
            for (int c = 0; t->contour[r] != 0 && c < POLYC__TILE_SIDE; c++) {
                int idx = (r << POLYC__TILE_SHIFT) | c;
                if (!((t->contour[r] >> c) & 1u) || n >= on->cells_cap ||
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
                on->cells[2 * n] = tx + c;
                on->cells[2 * n + 1] = ty + r;
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
        uint32_t d = on->dirty[k];
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
 * people's lines on the sweep's halls (full-map RMS median 22.6 to 9.3 mm)
 * but also walls drawn through bands, whose cells fall under the contour
 * threshold: intel's final BIC 67,795 to 76,137, orebro's 45,582 to 47,449. */
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
 * round need come near it (acapulco, scans 250 to 800, with sparse tiles in
 * the backlog). "Along": the end within overlap_m of the piece, its segment
 * within ALONG_COS of parallel to it (an end at a T junction is not). */
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
        int32_t bx, by, around[9];
        polyc__bucket_xy(h, e->x, e->y, &bx, &by);
        int nb = polyc__buckets_around(h, bx, by, around);
        for (int i = 0; i < nb; i++)
            for (int32_t en = h->seg_head[around[i]]; en != POLYC__NONE; en = h->entries[en].next) {
                int32_t sg = h->entries[en].seg;
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
 * its region holds them. Left, they piled up: edmonton's maps after 200
 * and 300 scans had 169 and 194 pairs of ends of two polylines within
 * 15 cm (most of them two-vertex pieces of one wall), the batch map 8;
 * with the links 30 and 36. */
static int link_left_ends(polyc__opt *o)
{
    if (!o->pol.restructure)
        return 0;
    uint32_t mark = ++o->touch_stamp;
    int linked = polyc__op_merge_folds(o, 0);
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

static polyc_status round_in(polyc_ctx *ctx, uint64_t work, int all, uint64_t *spent);

/* An update's scratch (the points made again, the contour cells, the
 * trace's walk: online.h) sits above the grid's tiles, which must stay
 * contiguous for the next scan's: it is given back whatever the round's
 * outcome. */
polyc_status polyc__online_round(polyc_ctx *ctx, uint64_t work, int all, uint64_t *spent)
{
    size_t mark = ctx->arena.used;
    polyc_status st = round_in(ctx, work, all, spent);
    ctx->arena.used = mark;
    ctx->online->cells = NULL;
    ctx->online->seg_data = NULL;
    return st;
}

static polyc_status round_in(polyc_ctx *ctx, uint64_t work, int all, uint64_t *spent)
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
        st = polyc__trace_cells(ctx, on->cells, n);
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
    uint8_t add = o->pol.add_vertices;
    o->pol.add_vertices = 0;
    polyc__operators(o, since, since);
    drop_dataless(o, on->seg_data);
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
    o->pol.add_vertices = add;
    o->region_since = 0;
    POLYC__CHECKS_ITERATION(o);
    for (uint32_t i = 0; i < taken; i++)
        on->dirty_since[on->dirty[i]] = 0;
    on->dirty_n -= taken;
    memmove(on->dirty, on->dirty + taken, (size_t)on->dirty_n * sizeof on->dirty[0]);
    on->pending = 0;
    if (o->h.out_of_entries)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "spatial hash full (limits.max_vertices)");
    return POLYC_OK;
}

static polyc_status online_ctx(polyc_ctx *ctx)
{
    polyc_status cst = polyc__enter(ctx, 1);
    if (cst != POLYC_OK)
        return cst;
    if (!ctx->online)
        return polyc__fail(ctx, POLYC_ERR_STATE, "not an online context (polyc_online_init)");
    if (ctx->online->scans == 0)
        return polyc__fail(ctx, POLYC_ERR_STATE, "no scan added yet");
    return POLYC_OK;
}

static void report(polyc_ctx *ctx, uint64_t work, uint32_t changed, polyc_online_report *out)
{
    polyc__online *on = ctx->online;
    polyc__figures_out(on->opt_ready ? polyc__bic(&on->opt) : 0.0f,
                       on->opt_ready ? polyc__err(&on->opt) : 0.0f, &ctx->stats.bic,
                       &ctx->stats.error_sq_m2);
    if (!out)
        return;
    memset(out, 0, sizeof *out);
    out->version = on->version;
    out->work = work;
    out->scans = on->scans;
    out->pending_scans = on->pending;
    out->backlog_tiles = on->dirty_n;
    out->changed = changed;
    out->polylines = ctx->flat.count;
    out->vertices = ctx->flat.points;
    out->bic = ctx->stats.bic;
}

polyc_status polyc_online_update(polyc_ctx *ctx, uint64_t work, polyc_online_report *out)
{
    polyc_status st = online_ctx(ctx);
    if (st != POLYC_OK)
        return st;
    if (work == 0)
        return polyc__fail(ctx, POLYC_ERR_CONFIG, "a work budget of 0 (POLYC_ONLINE_WORK_DEFAULT is the default)");
    polyc__online *on = ctx->online;
    uint64_t spent = 0, cast = 0;
    uint32_t changed = 0;
    if ((st = polyc__online_apply_corrections(ctx, &cast)) != POLYC_OK)
        return st;
    uint64_t corrections = cast / CAST_BEAMS_PER_UNIT; /* their units */
    if (corrections >= work) {
        /* the corrections spent the budget: the rounds come in the next
         * updates (intel's 910 at once: some 90 ms; a round and the
         * records' first slice after them took another 16) */
        on->pending = 0;
        report(ctx, corrections, 0, out);
        return POLYC_OK;
    }
    work -= corrections;
    polyc__online_learn_due(ctx);
    polyc__online_redo_records(ctx, REDO_BEAMS);
    polyc__online_backlog_misses(ctx);
    uint32_t oldest = on->scans + 1;
    for (uint32_t i = 0; i < on->dirty_n; i++)
        oldest = on->dirty_since[on->dirty[i]] < oldest ? on->dirty_since[on->dirty[i]] : oldest;
    /* (with no scan since the last update, nothing more is coming to wait for) */
    if (on->dirty_n >= ROUND_TILES ||
        (on->dirty_n > 0 && (!on->opt_ready || on->pending == 0 || on->scans + 1 - oldest >= ROUND_WAIT_SCANS))) {
        st = polyc__online_round(ctx, work, 0, &spent);
        polyc_status pst = polyc__online_publish(ctx, &changed);
        if (st == POLYC_OK)
            st = pst;
    }
    on->pending = 0;
    report(ctx, spent + corrections, changed, out);
    return st;
}

/* A polyline this short under which no cell is occupied now goes before
 * the finishing search: the batch traces only cells occupied at the end,
 * and could not have drawn it. The updates traced it when its cells were
 * occupied, a person standing or walking by, and its points (the person's
 * returns) keep it (the sweep's thinwalls seed 3: a 12 cm piece 0.3 m from
 * a wall, core precision 12.0 mm against the batch's 4.5). Longer polylines
 * stay: a wall drawn through a band may have no occupied cell under it. */
#define UNOCCUPIED_MAX_M 0.5f

/* Whether a cell within one of (x, y) is occupied now. */
static int occupied_near(const polyc_ctx *ctx, float x, float y)
{
    const polyc__grid *g = &ctx->grid;
    float ox = g->frame_ox, oy = g->frame_oy;
    int32_t cx = (int32_t)floorf((x - ox) * g->inv_cell), cy = (int32_t)floorf((y - oy) * g->inv_cell);
    for (int32_t dy = -1; dy <= 1; dy++)
        for (int32_t dx = -1; dx <= 1; dx++) {
            const polyc__tile *t = polyc__grid_tile(g, cx + dx, cy + dy);
            if (t && polyc__cell_occupied(t, polyc__cell_index(cx + dx, cy + dy), ctx->cfg.contour_threshold))
                return 1;
        }
    return 0;
}

/* The polylines of at most UNOCCUPIED_MAX_M with no occupied cell within
 * one of them (sampled every half cell) go. */
static void drop_unoccupied(polyc_ctx *ctx)
{
    polyc__opt *o = &ctx->online->opt;
    const polyc__store *s = o->s;
    float step = 0.5f * ctx->grid.cell_m;
    for (int32_t l = 0; l < s->l_high; l++) {
        const polyc__line *ln = &s->l[l];
        if (ln->closed == POLYC__NONE || ln->count == 0)
            continue;
        float len = 0.0f;
        int32_t v = ln->head;
        for (int32_t k = 0; k + 1 < ln->count; k++, v = s->v[v].next) {
            const polyc__vertex *a = &s->v[v], *b = &s->v[a->next];
            len += sqrtf((b->x - a->x) * (b->x - a->x) + (b->y - a->y) * (b->y - a->y));
        }
        if (len > UNOCCUPIED_MAX_M)
            continue;
        int occ = 0;
        v = ln->head;
        for (int32_t k = 0; k < ln->count && !occ; k++, v = s->v[v].next) {
            const polyc__vertex *a = &s->v[v];
            if (a->next == POLYC__NONE) {
                occ = occupied_near(ctx, a->x, a->y);
                break;
            }
            const polyc__vertex *b = &s->v[a->next];
            float dl = sqrtf((b->x - a->x) * (b->x - a->x) + (b->y - a->y) * (b->y - a->y));
            int32_t n = (int32_t)(dl / step) + 1;
            for (int32_t j = 0; j <= n && !occ; j++) {
                float t = (float)j / (float)n;
                occ = occupied_near(ctx, a->x + t * (b->x - a->x), a->y + t * (b->y - a->y));
            }
        }
        if (occ)
            continue;
        polyc__chg_begin(o);
        while (s->l[l].closed != POLYC__NONE && s->l[l].count > 0)
            polyc__op_remove(o, s->l[l].head);
        polyc__chg_commit(o);
    }
}

/* The finishing search's noise starts two decays in (0.0245 m at the
 * defaults): the updates have fitted every piece of the map to its data,
 * and the batch's 5 cm, meant to shake a traced contour out of its cells,
 * undoes that fit faster than the search's patience lets it come back.
 * With 5 cm, fhw's noisy iterations settled at a BIC 0.8-1.3 % above the
 * map the updates left, which the search then kept (1.037 times the batch
 * map's on the batch's data); from 0.0245 m they went below it. On twelve
 * real logs the final BIC on the batch's data fell on eleven (fhw 1.037 ->
 * 1.021, acapulco 1.020 -> 1.000, infinite-corridor 1.010 -> 0.991,
 * seattle 1.017 -> 1.014) and rose on orebro (0.965 -> 0.973); from
 * 0.012 m it fell on ten. The sweep's online core precision came within
 * 10 % of the batch's on 88 of 120 scenes, against 85 (its worst row in
 * those runs, hall seed 12, 1.77 -> 2.08 times). */
#define FINISH_NOISE_SKIP 2

/* The finishing call: every tile's data made again, what no polyline
 * explains traced (explained: the finishing round's rule), then the batch
 * search from the map. With the rounds' 10 cm everywhere, the search has
 * nothing to start a thin wall's far face or a door jamb from: the sweep's
 * online core precision within 10 % of batch on 40 of 60 scenes (worst
 * 4.45 times, thin walls) against 43 (3.03) with the finishing rule. A
 * second search from the contour traced afresh doubled the finishing time
 * and won on no real log. */
polyc_status polyc_online_finish(polyc_ctx *ctx, polyc_progress_fn progress, void *user,
                                 polyc_online_report *out)
{
    polyc_status st = online_ctx(ctx);
    if (st != POLYC_OK)
        return st;
    if ((st = polyc__online_apply_corrections(ctx, NULL)) != POLYC_OK)
        return st;
    polyc__online_learn_due(ctx);
    polyc__online_redo_records(ctx, UINT32_MAX);
    polyc__online *on = ctx->online;
    polyc__opt *o = &on->opt;
    uint64_t spent = 0;
    size_t mark = ctx->arena.used; /* the traces' scratch, given back below */
    /* every tile: what no polyline explains anywhere is traced */
    polyc__online_backlog_all(ctx);
    st = polyc__online_round(ctx, UINT64_MAX, 1, &spent);
    if (st == POLYC_OK)
        drop_unoccupied(ctx);
    /* the data exact for the search: every point weighed as the accuracy
     * stands now, the books from scratch */
    on->spacing_now = 1;
    if (st == POLYC_OK)
        st = polyc__opt_refresh(o);
    on->spacing_now = 0;
    if (st == POLYC_OK && ctx->cfg.max_iterations > 0) {
        polyc__guarded g = {ctx, progress, user};
        o->pol.noise_skip = FINISH_NOISE_SKIP;
        st = polyc__search(o, progress ? polyc__guarded_progress : NULL, &g);
        o->pol.noise_skip = 0;
    }
    ctx->arena.used = mark;
    on->cells = NULL;
    uint32_t changed = 0;
    polyc_status pst = polyc__online_publish(ctx, &changed);
    if (st == POLYC_OK)
        st = pst;
    report(ctx, spent, changed, out);
    return st;
}
