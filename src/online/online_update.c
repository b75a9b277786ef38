/* online_update.c - the online entry points that change the map: an
 * update (the waiting corrections applied, then a round on the backlog's
 * tiles if it is due: online_round.c) and the finishing call (every tile's
 * round, then the batch search from the map), each publishing the map
 * (online_changes.c). Takes: a work budget. Gives: the map's new version
 * and a report. */
#include "../online.h"

#include <math.h>
#include <string.h>

/* An update starts a round when the backlog holds this many tiles, when a
 * tile in it has waited this many scans, when no scan came since the last
 * update, or when there is no map yet. A round's fixed costs (the passes
 * over the map's ends, the region's books) and the climbs of the vertices
 * near the robot are then paid once for several scans, not for each.
 * Twice these (8 tiles or 16 scans) took less time in all but left the
 * online map's precision further behind the batch map's on the worst
 * simulated scenes; four times these saved no time, as each round grew
 * larger. */
#define ROUND_TILES 4u
#define ROUND_WAIT_SCANS 8u
/* After a recount (pose corrections), each update puts back the records of
 * this many of the kept scans' beams (online_grid.c): a log's records come
 * back over several updates, a small part of each one's time. */
#define REDO_BEAMS 16384u
/* Corrections count against an update's budget: a unit for every two
 * beams they cast (a beam cast through the grid costs about half of what
 * a unit stands for). An update whose corrections spent its budget does
 * nothing else. */
#define CAST_BEAMS_PER_UNIT 2u

static polyc_status online_ctx(polyc_ctx *ctx)
{
    polyc_status cst = polyc__online_enter(ctx, 1);
    if (cst != POLYC_OK)
        return cst;
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
    out->version = on->pubs.version;
    out->work = work;
    out->scans = on->scans;
    out->pending_scans = on->pending;
    out->backlog_tiles = on->backlog.dirty_n;
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
         * updates (a whole log corrected at once already takes several
         * budgets' time; a round and the records' first slice on top would
         * make that one update longer still) */
        on->pending = 0;
        report(ctx, corrections, 0, out);
        return POLYC_OK;
    }
    work -= corrections;
    polyc__online_learn_due(ctx);
    polyc__online_redo_records(ctx, REDO_BEAMS);
    polyc__online_backlog_misses(ctx);
    uint32_t oldest = on->scans + 1;
    for (uint32_t i = 0; i < on->backlog.dirty_n; i++)
        oldest = on->backlog.dirty_since[on->backlog.dirty[i]] < oldest ? on->backlog.dirty_since[on->backlog.dirty[i]] : oldest;
    /* (with no scan since the last update, nothing more is coming to wait for) */
    if (on->backlog.dirty_n >= ROUND_TILES ||
        (on->backlog.dirty_n > 0 && (!on->opt_ready || on->pending == 0 || on->scans + 1 - oldest >= ROUND_WAIT_SCANS))) {
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
 * returns) keep it: a short piece standing free beside a wall, which the
 * batch map of the same scans does not have. Longer polylines stay: a
 * wall drawn through a band may have no occupied cell under it. */
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
 * With 5 cm, the noisy iterations could settle at a BIC above the map the
 * updates left, and the search then kept that worse map; from 0.0245 m
 * they go below it. Started there, the final map's BIC on the batch's data
 * came out lower on nearly every real log, and the simulated scenes' online
 * precision nearer the batch's, than from 5 cm or from one decay further
 * (0.012 m). */
#define FINISH_NOISE_SKIP 2

/* The finishing call: every tile's data made again, what no polyline
 * explains traced (explained: the finishing round's rule), then the batch
 * search from the map. With the rounds' 10 cm everywhere, the search has
 * nothing to start a thin wall's far face or a door jamb from: the online
 * maps of simulated scenes, thin walls the worst, fell further behind the
 * batch maps' precision than with the finishing rule. A second search from
 * the contour traced afresh made the finishing call much longer and gave
 * no better map on the real logs. */
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
    on->poses.spacing_now = 1;
    if (st == POLYC_OK)
        st = polyc__opt_refresh(o, &on->prior);
    on->poses.spacing_now = 0;
    if (st == POLYC_OK && ctx->cfg.max_iterations > 0) {
        polyc__guarded g = {ctx, progress, user};
        o->pol.noise_skip = FINISH_NOISE_SKIP;
        st = polyc__search(o, progress ? polyc__guarded_progress : NULL, &g);
        o->pol.noise_skip = 0;
    }
    ctx->arena.used = mark;
    on->scr.cells = NULL;
    uint32_t changed = 0;
    polyc_status pst = polyc__online_publish(ctx, &changed);
    if (st == POLYC_OK)
        st = pst;
    report(ctx, spent, changed, out);
    return st;
}
