/* optimize.c - the search (paper section IV): local search on the BIC.
 * Takes: the initial polylines, the grid and the scans. Gives: the best map
 * found by repeating the operators (overlaps, merge, split, vertex moves,
 * zigzags, noise, vertex count) until `patience` iterations bring no better
 * BIC, or the iteration cap or the caller's progress callback stops it. */
#include "optimize.h"

#include <math.h>
#include <string.h>



/* No copy for a context of one scan: its trials list fewer than 8 points
 * nine times in ten (and its block is the embedded one). An occupancy
 * grid's limits have no scans (polyc_limits_for_grid) and get the copy. */
static int32_t loc_soa_cap(const polyc_limits *lim)
{
    return lim->max_scans != 1 ? POLYC__LOC_SOA : 0;
}

/* The optimiser's own arrays for P points and V vertices, then each
 * group's scratch by its file (the points, the spatial hash and the best
 * model are carved by theirs). */
static int opt_carve(polyc__arena *a, polyc__opt *o, int32_t P, int32_t V, int viewed, int32_t lsoa_cap)
{
    int ok = 1;
    POLYC__CARVE(ok, a, o->d.pt_seg, P);
    POLYC__CARVE(ok, a, o->d.pt_cost, P);
    POLYC__CARVE(ok, a, o->acost, V);
    o->seg_side = NULL;
    if (viewed)
        POLYC__CARVE(ok, a, o->seg_side, V);
    POLYC__CARVE(ok, a, o->seg_in, V);
    POLYC__CARVE(ok, a, o->split_due, V);
    POLYC__CARVE(ok, a, o->v_work, V);
    POLYC__CARVE(ok, a, o->v_touch, V);
    return ok && polyc__change_carve(a, &o->chg, V) && polyc__eval_carve(a, &o->ev, P, lsoa_cap) &&
           polyc__split_carve(a, &o->split, P, V) && polyc__size_carve(a, &o->size, V);
}

/* What the optimiser takes from the block after the prior: the spacing
 * table, the spatial hash, the points, its own arrays and the best model,
 * each carved by the code that carves them in polyc__opt_setup. */
void polyc__optimizer_reserve(polyc__arena *a, const polyc_config *cfg, const polyc_limits *lim)
{
    polyc__opt o;
    memset(&o, 0, sizeof o);
    int32_t V = polyc__max_vertices(lim), P = polyc__points_bound(cfg, lim);
    polyc__spacing_reserve(a, lim);
    polyc__hash_reserve(a, &o, lim);
    polyc__points_reserve(a, cfg, lim);
    opt_carve(a, &o, P > 0 ? P : 1, V, lim->max_scans > 1, loc_soa_cap(lim));
    polyc__flat_reserve(a, V);
}

/* An occupancy grid's data are cell centres, not noisy endpoints
 * (docs/algorithm.md, "From an occupancy grid"): its squared distances are
 * weighed as in 5 cm cells, alpha (GRID_CELL_M / r)^2 (alpha itself at 5 cm,
 * the maps ROS users keep: the sweep's occupancy maps 23 of 48 scenes on
 * target against 20 with alpha / 4; a room at 2.5, 5, 10 or 15 cm comes out
 * with its corner count of vertices); the search radius is at least
 * GRID_RADIUS_CELLS cells (at 5 cm, 2 cells lost pillars of the turtlebot3
 * map, at 15 cm 1 cell lost a box); and there is no angle prior (gamma 0:
 * learned from the grid's edges it cost more coverage than it saved
 * vertices). */
#define GRID_CELL_M 0.05f
#define GRID_RADIUS_CELLS 3.0f
/* A grid's search: an iteration gains only if its BIC is lower by more
 * than GRID_GAIN of it, and noisy iterations count towards the patience. A
 * grid's data are exact cell centres: on the bench's 2,000 x 2,000-cell
 * maze the first iteration's map stayed the best through 12 more (its noise
 * a whole cell), and the search took 1.4 of the 1.5 s; with these rules 6
 * iterations, 0.85 s, the same map. */
#define GRID_GAIN 2e-3

static polyc__policy policy_for(polyc__input kind)
{
    polyc__policy p;
    int one = kind == POLYC__INPUT_ONE_SCAN, grid = kind == POLYC__INPUT_GRID;
    p.restructure = p.add_vertices = p.noise = !one;
    p.climb_since_prev = p.stop_without_gain = one;
    p.gain_share = grid ? GRID_GAIN : 0.0;
    p.noise_spares_patience = p.recover = !grid;
    p.gaps_free_only = grid;
    return p;
}

static const polyc_config *grid_config(polyc_ctx *ctx)
{
    polyc_config *c = &ctx->grid_cfg;
    float r = ctx->grid.cell_m, k = GRID_CELL_M / r;
    *c = ctx->cfg;
    c->alpha = ctx->cfg.alpha * k * k;
    c->gamma = 0.0f;

    if (c->search_radius_m < GRID_RADIUS_CELLS * r)
        c->search_radius_m = GRID_RADIUS_CELLS * r;
    return c;
}

/* Everything the optimiser needs, carved from the arena after the trace
 * (also the entry point of the optimiser's unit tests). */
polyc_status polyc__opt_setup(polyc_ctx *ctx, polyc__opt *o)
{
    memset(o, 0, sizeof *o);
    o->ctx = ctx;
    polyc__input kind = polyc__input_kind(ctx);
    o->pol = policy_for(kind);
    o->cfg = kind == POLYC__INPUT_GRID ? grid_config(ctx) : &ctx->cfg;
    o->s = &ctx->store;
    o->R = o->cfg->search_radius_m;
    o->R2 = o->R * o->R;
    o->rng.state = ctx->cfg.seed;
    int32_t V = o->s->v_cap;
    polyc__rays_init(&o->rays, ctx);
    /* what the optimiser will still take from the block after the prior */
    polyc__arena later;
    polyc__arena_counting(&later);
    polyc__optimizer_reserve(&later, &ctx->cfg, &ctx->lim);
    polyc_status st = polyc__prior_build(ctx, &o->prior, later.peak);
    if (st != POLYC_OK)
        return st;
    if ((st = polyc__spacing_build(ctx, &o->spacing)) != POLYC_OK)
        return st;
    if ((st = polyc__hash_init(o)) != POLYC_OK)
        return st;
    if ((st = polyc__points_collect(o)) != POLYC_OK)
        return st;
    o->d.log_n = log(o->d.n > 1.0 ? o->d.n : 1.0);
    int32_t P = o->d.np > 0 ? o->d.np : 1;
    if (!opt_carve(&ctx->arena, o, P, V, o->d.pt_view != NULL, loc_soa_cap(&ctx->lim)))
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the optimiser");
    memset(o->v_work, 0, (size_t)V * sizeof(uint32_t));
    memset(o->v_touch, 0, (size_t)V * sizeof(uint32_t));
    memset(o->seg_in, 0, (size_t)V);
    memset(o->split_due, 0, (size_t)V);
    if (!polyc__flat_init(&ctx->arena, &o->best, (uint32_t)polyc__line_cap(V), (uint32_t)V))
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the result polylines");
    return polyc__rebuild(o);
}

static void fill_stats(polyc__opt *o)
{
    polyc_stats *st = &o->ctx->stats;
    st->bic = polyc__bic(o);
    st->error_sq_m2 = o->err;
}

static int32_t live_lines(const polyc__store *s)
{
    return s->l_live;
}

/* Whether any vertex was edited since the stamp `start`: every edit goes
 * through polyc__chg_dirty or a committed move, and both stamp v_touch. */
static int edited_since(const polyc__opt *o, uint32_t start)
{
    for (int32_t v = 0; v < o->s->v_high; v++)
        if (o->v_touch[v] >= start)
            return 1;
    return 0;
}

/* After a failure mid-search the store holds the best map so far (at worst
 * the traced one), which polyc_optimize then publishes with the status. */
static polyc_status restore_best(polyc__opt *o, polyc_status st)
{
    if (polyc__store_from_flat(o->s, &o->best) != POLYC_OK)
        return POLYC_ERR_NOMEM;
    o->ctx->opt_result_valid = 1;
    return st;
}

/* The best map once more through merging and vertex removal, kept if its
 * BIC is no higher: the last edits of the search (cuts at crossings,
 * zipped stretches) can leave two ends a centimetre apart that the next
 * iteration would have joined. Then the rules the map must keep whatever
 * its BIC: every data gap split (a pass cuts one gap a segment), ends
 * trimmed, no double cover, no crossing. Returns a status (the store holds
 * the result, scored). */
static polyc_status polish(polyc__opt *o, double best)
{
    polyc_status st;
    o->untangle_mark = o->zip_mark = 0; /* the best map is a fresh store */
    polyc__op_merge(o);
    polyc__op_remove_vertices(o, 0);
    if (polyc__bic(o) > best) {
        if (polyc__store_from_flat(o->s, &o->best) != POLYC_OK)
            return polyc__fail(o->ctx, POLYC_ERR_NOMEM, "no room to restore the best map");
        if ((st = polyc__rebuild(o)) != POLYC_OK)
            return st;
        o->untangle_mark = o->zip_mark = 0;
    }
    for (int k = 0; k < POLYC__POLISH_SPLITS && polyc__op_split(o) > 0; k++)
        ;
    polyc__op_trim_ends(o);
    uint32_t mark = ++o->touch_stamp;
    if (polyc__op_zip(o) > 0) {
        /* what is left of a zipped pair moves onto the data of both */
        polyc__op_adjust(o, POLYC__ADJUST_ROUNDS, mark);
        polyc__op_trim_ends(o);
        polyc__op_zip(o);
    }
    polyc__op_untangle(o);
    return POLYC_OK;
}

polyc_status polyc__optimize(polyc_ctx *ctx, polyc_progress_fn progress, void *user)
{
    polyc__opt o;
    ctx->opt_result_valid = 0;
    polyc_status st = polyc__opt_setup(ctx, &o);
    if (st != POLYC_OK)
        return st;
    const polyc_config *cfg = o.cfg;
    polyc__flat_from_store(&o.best, o.s);
    double best = polyc__bic(&o);
    double sigma = (double)cfg->noise_m;
    uint32_t quiet = 0, it;
    polyc_status result = POLYC_OK;
    uint32_t prev_start = 0, prev_mark = 0;
    double prev_bic = best;
    for (it = 0; it < cfg->max_iterations; it++) {
        uint32_t start = ++o.touch_stamp;
        /* F: noise to leave local minima, shrinking every iteration. Below
         * half a hill-climbing step it is not applied any more: the steps
         * could not correct it. Without noise, only what changed since the
         * previous iteration is adjusted and offered for removal again. */
        double noise = it > 0 && sigma >= 0.5 * (double)cfg->step_m ? sigma : 0.0;
        if (!o.pol.noise)
            noise = 0.0;
        if (noise > 0.0) {
            polyc__op_noise(&o, noise);
            o.untangle_mark = o.zip_mark = 0; /* every segment moved */
            if ((st = polyc__rebuild(&o)) != POLYC_OK)
                return restore_best(&o, st);
        }
        uint32_t since = it == 0 || noise > 0.0 ? 0 : prev_start;
        prev_start = start;
        if (o.pol.restructure) {
            polyc__op_overlaps(&o);      /* A */
            polyc__op_merge(&o);         /* B */
            polyc__op_split(&o);         /* C */
        }
        polyc__op_remove_vertices(&o, since); /* G: fewer vertices first, so that */
        /* D moves what is left. A single scan's later iterations climb only
         * what the previous one edited after its first climbs (removals,
         * zigzags, corners, trims): the vertices those climbs left at an
         * optimum stay there (on 200 freiburg-campus scans, with ends not
         * climbed, climbing them again takes a sixth of the time and
         * lowers the BIC by 0.15 %) */
        polyc__op_adjust(&o, POLYC__ADJUST_ROUNDS, o.pol.climb_since_prev && it > 0 ? prev_mark : since);
        uint32_t mark = ++o.touch_stamp;
        prev_mark = mark;
        polyc__op_zigzag(&o);            /* E */
        polyc__op_corners(&o, since);    /* corners (not in the paper) */
        polyc__op_remove_vertices(&o, mark); /* G */
        if (o.pol.add_vertices)
            polyc__op_add_vertices(&o, POLYC__ADD_ROUNDS); /* G, more vertices */
        polyc__op_adjust(&o, POLYC__ADJUST_ROUNDS, mark);
        /* moves and additions can leave segments without data or hairpins:
         * clean them before the model is judged, so the best one is clean */
        for (int round = 0; round < POLYC__CLEAN_ROUNDS; round++) {
            mark = ++o.touch_stamp;
            if ((!o.pol.restructure ? 0 : polyc__op_split(&o)) + polyc__op_zigzag(&o) +
                    polyc__op_corners(&o, since) == 0)
                break;
            polyc__op_adjust(&o, POLYC__ADJUST_ROUNDS, mark);
        }
        polyc__op_trim_ends(&o); /* moves could push ends past the data */
        if (o.pol.restructure)
            polyc__op_zip(&o);   /* one piece of map per wall */
        polyc__op_untangle(&o);  /* last: the map judged has no crossing */
        if (o.h.out_of_entries)
            return restore_best(&o, polyc__fail(ctx, POLYC_ERR_NOMEM, "spatial hash full"));
        double bic = polyc__bic(&o);
        /* any better map is kept; a gain under one BIC unit (no evidence
         * either way) does not restart the patience: late iterations can
         * cycle between maps that differ by a vertex and a fraction of it.
         * Iterations with noise do not use it up: their maps are perturbed
         * on purpose, and a run of them all worse than iteration 0 stopped
         * infinite-corridor at iteration 5 with 5,766 vertices (3,793 when
         * the noise is allowed to decay) */
        int gained = bic < best - (o.pol.gain_share > 0.0 ? fmax(1.0, o.pol.gain_share * fabs(best)) : 1.0);
        /* Nor do iterations that are still coming down from the noise by
         * more than POLYC__RECOVER_GAIN of the BIC each (tunables.h) */
        int recovering = o.pol.recover && it > 0 && bic < prev_bic - POLYC__RECOVER_GAIN * fabs(prev_bic);
        prev_bic = bic;
        quiet = gained ? 0 : ((noise > 0.0 && o.pol.noise_spares_patience) || recovering ? quiet : quiet + 1);
        if (bic < best - 1e-9 * fabs(best)) {
            best = bic;
            polyc__flat_from_store(&o.best, o.s);
        }
        polyc_iteration rep;
        memset(&rep, 0, sizeof rep);
        rep.iteration = it;
        rep.vertices = (uint32_t)o.s->v_live;
        rep.polylines = (uint32_t)live_lines(o.s);
        rep.bic = bic;
        rep.best_bic = best;
        rep.noise_m = noise;
        if (it > 0)
            sigma *= (double)cfg->noise_decay;
        if (progress && progress(user, &rep)) {
            result = POLYC_ERR_STOPPED;
            it++;
            break;
        }
        if (quiet >= cfg->patience)
            break;
        /* Without noise now or later, an iteration is a function of the map
         * and of what the previous one edited: one that edited nothing is
         * followed by copies of itself, so the patience would run out on
         * the same best map. */
        int noisy_later = o.pol.noise && sigma >= 0.5 * (double)cfg->step_m;
        if (!noisy_later && !edited_since(&o, start))
            break;
        /* A single scan has no noise either: an iteration that gained less
         * than one BIC unit leaves so little edited that the next ones gain
         * nothing measurable (the 130 bench scans: 4 vertices more in
         * all, the same f and ray RMSE, 4 % fewer instructions) */
        if (o.pol.stop_without_gain && !gained)
            break;
    }
    ctx->stats.iterations = it < cfg->max_iterations ? it + (result == POLYC_OK) : it;
    /* the best model found is the result */
    if (polyc__store_from_flat(o.s, &o.best) != POLYC_OK)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room to restore the best map");
    ctx->opt_result_valid = 1;
    if ((st = polyc__rebuild(&o)) != POLYC_OK)
        return st;
    if (o.pol.restructure && result == POLYC_OK && (st = polish(&o, best)) != POLYC_OK)
        return st;
    fill_stats(&o);
    return result;
}

polyc_status polyc__score(polyc_ctx *ctx, double *bic, double *err)
{
    polyc__opt o;
    polyc_status st = polyc__opt_setup(ctx, &o);
    if (st != POLYC_OK)
        return st;
    fill_stats(&o);
    if (bic)
        *bic = polyc__bic(&o);
    if (err)
        *err = o.err;
    return POLYC_OK;
}
