/* online_correct.c - the kept scans' pose corrections: noted when given,
 * applied by the next update, finish or add (the grid's counts and the
 * cells' sums made again, or each moved scan out and in again; then the
 * contour cast and, when every scan is kept, the prior and the accuracy
 * learned again). Takes: corrections. Gives: the state as if the scans had
 * come at their new poses. */
#include "../online.h"

#include <string.h>

/* relabel: the marks pay when the scans' beams times this reach the
 * stored cells (a beam walks some tens of cells in the tiles it does not
 * skip) */
#define RELABEL_CELLS_PER_BEAM 32u

/* Kept scan k as the caller gave it, at another pose (frame-free metres). */
static void moved_scan(const polyc_ctx *ctx, uint32_t k, double x, double y, double theta,
                       polyc_scan *out)
{
    const polyc__scan *d = &ctx->scans[1 + k];
    memset(out, 0, sizeof *out);
    out->pose_x_m = x;
    out->pose_y_m = y;
    out->pose_theta_rad = theta;
    out->start_angle_rad = d->start_rad;
    out->angle_step_rad = d->step_rad;
    out->min_range_m = d->min_m;
    out->max_range_m = d->max_m;
    out->beam_count = d->count;
    out->range_m = ctx->ranges + d->first;
}

/* ---- pose corrections ----
 * polyc_online_correct only notes the new pose; the next update, finish or
 * add applies every correction waiting, in one of two ways:
 * - when every scan is kept and at least half of them moved, the grid's
 *   counts and the cells' sums are cleared and every kept scan counted
 *   again, as a batch build counts them: the tiles of all their hits
 *   wanted first, then one cast each, over the tiles not stored in one
 *   move; the records of those the updates make again after (online_grid.c).
 *   Taking each scan out and in again costs two casts a scan, counting
 *   afresh one and a pass over the tiles, and the float sums come out
 *   exact;
 * - otherwise each moved scan's counts and sums are taken out exactly (the
 *   counters are integers; one that saturated is not taken below 0) and
 *   added back at the new pose.
 * Then the contour is cast, on the grid with every correction in it: a
 * scan cast as its correction came would meet, at its new pose, cells that
 * still held the misses of the scans not corrected yet, and see through
 * walls those scans saw: a drifted log corrected that way kept a map
 * clearly worse than the batch map; cast after all, a map as good as the
 * batch map. When every scan is kept, the
 * contour is cleared and cast from all of them: the batch's contour, with
 * the old poses' gone; otherwise the old poses' contour stays (it only
 * seeds the trace). */

polyc_status polyc_online_correct(polyc_ctx *ctx, uint32_t scan_id, double pose_x_m,
                                  double pose_y_m, double pose_theta_rad)
{
    polyc_status cst = polyc__online_enter(ctx, 1);
    if (cst != POLYC_OK)
        return cst;
    polyc__online *on = ctx->online;
    uint32_t lo = 0, hi = on->kept.n;
    while (lo < hi) { /* kept_id ascends */
        uint32_t mid = lo + (hi - lo) / 2;
        if (on->kept.id[mid] < scan_id)
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo >= on->kept.n || on->kept.id[lo] != scan_id)
        return polyc__fail(ctx, POLYC_ERR_RANGE, "the scan was not kept (polyc_online_add_scan's keep)");
    if (!polyc__pose_ok(pose_x_m, pose_y_m, pose_theta_rad))
        return polyc__fail(ctx, POLYC_ERR_SCAN, "scan pose is not finite or beyond 1e7 m");
    polyc_scan moved;
    moved_scan(ctx, lo, pose_x_m, pose_y_m, pose_theta_rad, &moved);
    if ((cst = polyc__online_inside_area(ctx, &moved)) != POLYC_OK)
        return cst;
    on->kept.new_pose[3 * (size_t)lo] = pose_x_m;
    on->kept.new_pose[3 * (size_t)lo + 1] = pose_y_m;
    on->kept.new_pose[3 * (size_t)lo + 2] = pose_theta_rad;
    if (!((on->kept.moved[lo >> 5] >> (lo & 31)) & 1u)) {
        on->kept.moved[lo >> 5] |= 1u << (lo & 31);
        on->kept.moved_n++;
    }
    on->pending++;
    return POLYC_OK;
}

static int is_moved(const polyc__online *on, uint32_t k)
{
    return (on->kept.moved[k >> 5] >> (k & 31)) & 1u;
}

/* Kept scan k at its waiting pose. */
static void take_new_pose(polyc_ctx *ctx, uint32_t k)
{
    polyc__online *on = ctx->online;
    polyc__scan *d = &ctx->scans[1 + k];
    const double *p = &on->kept.new_pose[3 * (size_t)k];
    polyc_scan moved;
    moved_scan(ctx, k, p[0], p[1], p[2], &moved);
    polyc__store_scan(ctx, d, &moved, d->first);
}

/* Every kept scan counted afresh (every scan is kept); the records after. */
static polyc_status count_afresh(polyc_ctx *ctx)
{
    polyc__online *on = ctx->online;
    polyc__grid *g = &ctx->grid;
    for (uint32_t k = 0; k < on->kept.n; k++)
        if (is_moved(on, k))
            take_new_pose(ctx, k);
    polyc__records_clear_counts(g, &on->rec);
    polyc__cells_clear(&on->tab, g->tile_count);
    memset(on->backlog.tile_new, 0, (size_t)g->tile_count * sizeof *on->backlog.tile_new);
    memset(on->backlog.tile_miss, 0, (size_t)g->tile_count * sizeof *on->backlog.tile_miss);
    for (uint32_t k = 0; k < on->kept.n; k++)
        polyc__grid_want(ctx, &ctx->scans[1 + k]);
    polyc_status st = POLYC_OK;
    for (uint32_t k = 0; k < on->kept.n && st == POLYC_OK; k++)
        st = polyc__online_accumulate(ctx, &ctx->scans[1 + k], on->kept.id[k], POLYC__SCAN_RECOUNT);
    polyc__records_redo_begin(ctx, &on->rec, on->kept.n);
    return st;
}

/* Each moved scan out at its old pose and in at its new one. */
static polyc_status move_each(polyc_ctx *ctx)
{
    polyc__online *on = ctx->online;
    polyc_status st = POLYC_OK;
    for (uint32_t k = 0; k < on->kept.n && st == POLYC_OK; k++) {
        if (!is_moved(on, k))
            continue;
        polyc__scan *d = &ctx->scans[1 + k];
        st = polyc__online_accumulate(ctx, d, on->kept.id[k], POLYC__SCAN_OUT);
        take_new_pose(ctx, k);
        if (st == POLYC_OK)
            st = polyc__online_accumulate(ctx, d, on->kept.id[k], POLYC__SCAN_MOVED); /* (the prior has its lines) */
    }
    return st;
}

/* The contour of the moved scans (all: cleared, and every kept scan's).
 * Many scans are cast as the batch casts, on the tiles' marks (contour.c),
 * which pass over the tiles without an occupied cell in one move, where
 * labelling scan by scan walks every cell of every beam. The marks cost a
 * test per stored cell, so a few scans are labelled one by one on the
 * counts; the bits are the same either way. */
static void relabel(polyc_ctx *ctx, int all)
{
    polyc__online *on = ctx->online;
    polyc__grid *g = &ctx->grid;
    const uint32_t *only = all ? NULL : on->kept.moved;
    uint64_t beams = (uint64_t)(all ? on->kept.n : on->kept.moved_n) * on->lim.max_scan_beams;
    if (beams * RELABEL_CELLS_PER_BEAM >= (uint64_t)g->tile_count * POLYC__TILE_CELLS &&
        polyc__contour_cast(ctx, &ctx->scans[1], on->kept.n, all, only))
        return;
    if (all)
        for (uint32_t t = 0; t < g->tile_count; t++)
            memset(g->tiles[t].contour, 0, sizeof g->tiles[t].contour);
    for (uint32_t k = 0; k < on->kept.n; k++)
        if (all || is_moved(on, k))
            polyc__online_label_contour(ctx, &ctx->scans[1 + k]);
}

/* The angle prior's counts and the accuracy's pairs cannot be taken out
 * one scan at a time (a pair's offset is not kept). When every scan is
 * kept, both are forgotten and learned again from all of them at their
 * poses now, and every tile joins the backlog: its points' weights change.
 * Without it the drifted scans' pairs stay, and the weights they give (a
 * band's, where the drift spread a wall) fit the corrected map loosely:
 * a drifted log corrected without it ended well above the batch map's BIC
 * on the true poses' data. The learning waits for the next round or scan
 * (polyc__online_learn_due): nothing reads the two before, and the update
 * that applies the corrections does nothing else. */
void polyc__online_learn_due(polyc_ctx *ctx)
{
    polyc__online *on = ctx->online;
    if (!on->kept.learn_due)
        return;
    on->kept.learn_due = 0;
    polyc__prior_forget(&on->prior);
    polyc__accuracy_forget(&on->acc);
    for (uint32_t k = 0; k < on->kept.n; k++) {
        size_t mark = ctx->arena.used;
        polyc__online_scratch(&ctx->arena, on, 0, POLYC__STEP_LEARN);
        polyc__prior_learn_scan(ctx, &on->prior, &ctx->scans[1 + k], on->kept.id[k], on->scr.learn_cache,
                                on->lim.max_scan_beams, &on->acc);
        ctx->arena.used = mark;
        on->scr.learn_cache = NULL;
    }
}

polyc_status polyc__online_apply_corrections(polyc_ctx *ctx, uint64_t *beams_cast)
{
    polyc__online *on = ctx->online;
    if (beams_cast)
        *beams_cast = 0;
    if (on->kept.moved_n == 0)
        return POLYC_OK;
    int all = on->kept.n == on->scans;
    float lx = on->poses.last_x, ly = on->poses.last_y;
    int afresh = all && 2u * on->kept.moved_n >= on->kept.n;
    if (beams_cast) {
        uint64_t moved_beams = 0;
        for (uint32_t k = 0; k < on->kept.n; k++)
            if (is_moved(on, k))
                moved_beams += ctx->scans[1 + k].count;
        /* counted (afresh: every kept scan once; else each moved one out
         * and in), then their contour cast */
        *beams_cast = (afresh ? on->kept.beams : 2u * moved_beams) +
                      (all ? on->kept.beams : moved_beams);
    }
    if (!afresh) /* (a scan taken out takes its misses out of the records) */
        polyc__online_redo_records(ctx, UINT32_MAX);
    polyc_status st = afresh ? count_afresh(ctx) : move_each(ctx);
    on->poses.last_x = lx; /* the robot is where the latest scan was */
    on->poses.last_y = ly;
    relabel(ctx, all);
    memset(on->kept.moved, 0, (on->lim.keep_scans / 32u + 1u) * sizeof *on->kept.moved);
    on->kept.moved_n = 0;
    if (all) {
        polyc__online_backlog_all(ctx);
        on->kept.learn_due = 1;
    }
    return st;
}

