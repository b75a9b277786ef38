/* opt_setup.c - the optimiser's setup: what it carves from the block after
 * the trace (and, on a counting arena, what the size query charges for
 * it), the policy for the kind of input, an occupancy grid's weights, the
 * prior, the spacing, the spatial hash, the points and the model's terms.
 * Takes: the context after the trace. Gives: a polyc__opt ready to search
 * (optimize.c) or to score. */
#include "../optimize.h"

#include <math.h>
#include <string.h>

/* No copy for a context of one scan: its trials list fewer than 8 points
 * nine times in ten (and its block is the embedded one). Nor for limits of
 * at most POLYC__LOC_SOA points, a room's map: its block is an embedded
 * one too, where the copy's 56 bytes a point count for more than the
 * trials' speed (the costs are the same values either way, trial_costs.c).
 * An occupancy grid's limits have no scans (polyc_limits_for_grid) and get
 * the copy. */
static int32_t loc_soa_cap(const polyc_config *cfg, const polyc_limits *lim)
{
    return lim->max_scans != 1 && polyc__points_bound(cfg, lim) > POLYC__LOC_SOA ? POLYC__LOC_SOA : 0;
}

/* The optimiser's own arrays for P points and V vertices, then each
 * group's scratch by its file (the points, the spatial hash and the best
 * model are carved by theirs). */
static int opt_carve(polyc__arena *a, polyc__opt *o, int32_t P, int32_t V, int viewed, int32_t lsoa_cap,
                     int online)
{
    int ok = 1;
    POLYC__CARVE(ok, a, o->d.pt_seg, P);
    POLYC__CARVE(ok, a, o->d.pt_cost, P);
    POLYC__CARVE(ok, a, o->acost, V);
    o->seg_side = NULL;
    if (viewed)
        POLYC__CARVE(ok, a, o->seg_side, 2 * (size_t)V);
    POLYC__CARVE(ok, a, o->seg_in, V);
    o->region_pt = NULL;
    if (online)
        POLYC__CARVE(ok, a, o->region_pt, P);
    POLYC__CARVE(ok, a, o->split_due, V);
    POLYC__CARVE(ok, a, o->climb.v_work, V);
    POLYC__CARVE(ok, a, o->v_touch, V);
    /* (the zip's scratch is the size scratch's pair: polyc__sides) */
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
    opt_carve(a, &o, P > 0 ? P : 1, V, lim->max_scans > 1, loc_soa_cap(cfg, lim), 0);
    polyc__flat_reserve(a, V, 0);
}

/* An occupancy grid's data are cell centres, not noisy endpoints
 * (docs/algorithm.md, "From an occupancy grid"): its squared distances are
 * weighed as in 5 cm cells, alpha (GRID_CELL_M / r)^2 (alpha itself at 5 cm,
 * the maps ROS users keep: with alpha / 4 fewer of the simulated scenes'
 * occupancy maps came out on target; a room at 2.5, 5, 10 or 15 cm comes out
 * with its corner count of vertices); the search radius is at least
 * GRID_RADIUS_CELLS cells (at 5 cm, 2 cells lost pillars of the turtlebot3
 * map, at 15 cm 1 cell lost a box); and there is no angle prior (gamma 0:
 * learned from the grid's edges it cost more coverage than it saved
 * vertices). */
#define GRID_CELL_M 0.05f
#define GRID_RADIUS_CELLS 3.0f
/* A grid's search: an iteration gains only if its BIC is lower by more
 * than GRID_GAIN of it, and noisy iterations count towards the patience. A
 * grid's data are exact cell centres: on a large maze grid the first
 * iteration's map stayed the best through a dozen more (its noise a whole
 * cell), which took most of the search's time; with these rules the
 * search stops after half as many iterations, with the same map. */
#define GRID_GAIN 2e-3f

static polyc__policy policy_for(polyc__input kind)
{
    polyc__policy p;
    uint8_t one = kind == POLYC__INPUT_ONE_SCAN, grid = kind == POLYC__INPUT_GRID;
    p.restructure = p.add_vertices = p.noise = !one;
    p.climb_since_prev = p.stop_without_gain = one;
    p.gain_share = grid ? GRID_GAIN : 0.0f;
    p.noise_spares_patience = p.recover = !grid;
    p.gaps_free_only = grid;
    p.noise_skip = 0;
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

/* The fields set before anything is carved or computed. */
static void opt_begin(polyc_ctx *ctx, polyc__opt *o)
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
}

/* An optimiser that lives across calls (an online context's), its arrays
 * carved once for the limits (on the block, or on the size query's
 * counting arena): the spatial hash over the whole grid, the points, its
 * own arrays, the best map. The prior and the spacing are the caller's. */
int polyc__opt_carve_lasting(polyc_ctx *ctx, polyc__arena *a, polyc__opt *o, int32_t bucket_cap)
{
    opt_begin(ctx, o);
    int32_t V = polyc__max_vertices(&ctx->lim), P = polyc__points_bound(o->cfg, &ctx->lim);
    polyc__rays_init(&o->rays, ctx);
    int ok = polyc__hash_lay_out(o, a, bucket_cap) && polyc__points_carve_online(a, o) &&
             opt_carve(a, o, P > 0 ? P : 1, V, 1, loc_soa_cap(o->cfg, &ctx->lim), 1);
    if (!a->base) { /* a counting arena: nothing is written */
        polyc__flat_reserve(a, V, 0);
        return ok;
    }
    if (!ok || !polyc__flat_init(a, &o->best, (uint32_t)polyc__line_cap(V), (uint32_t)V))
        return 0;
    polyc__hash_clear(o);
    polyc__points_spans(o, 0);
    /* no points yet: every bucket empty */
    memset(o->h.pt_start, 0, ((size_t)o->h.bx * (size_t)o->h.by + 1) * sizeof(uint32_t));
    memset(o->acost, 0, (size_t)V * sizeof(float));
    memset(o->climb.v_work, 0, (size_t)V * sizeof(uint32_t));
    memset(o->v_touch, 0, (size_t)V * sizeof(uint32_t));
    memset(o->seg_in, 0, (size_t)V);
    memset(o->split_due, 0, (size_t)V);
    return 1;
}

/* Before an update's search: the prior's totals and weights, the spacing,
 * the points from the cells' sums, the hash and every point's segment. */
polyc_status polyc__opt_refresh(polyc__opt *o, const polyc__prior *prior)
{
    polyc_ctx *ctx = o->ctx;
    o->prior = *prior; /* (an online context keeps its totals and weights as scans come) */
    polyc_status st = polyc__spacing_build(ctx, &o->spacing);
    if (st != POLYC_OK)
        return st;
    polyc__hash_clear(o);
    size_t mark = ctx->arena.used; /* the points' scratch, given back below */
    if (!ctx->layer->points_scratch(ctx, polyc__points_bound(o->cfg, &ctx->lim)))
        st = polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the data points");
    else
        st = polyc__points_collect(o);
    ctx->arena.used = mark;
    if (st != POLYC_OK)
        return st;
    o->d.log_n = polyc__logf(o->d.n > 1.0f ? o->d.n : 1.0f);
    return polyc__rebuild(o);
}

/* Everything the optimiser needs, carved from the arena after the trace
 * (also the entry point of the optimiser's unit tests). */
polyc_status polyc__opt_setup(polyc_ctx *ctx, polyc__opt *o)
{
    opt_begin(ctx, o);
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
    o->d.log_n = polyc__logf(o->d.n > 1.0f ? o->d.n : 1.0f);
    int32_t P = o->d.np > 0 ? o->d.np : 1;
    if (!opt_carve(&ctx->arena, o, P, V, o->d.pt_view != NULL, loc_soa_cap(o->cfg, &ctx->lim), 0))
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the optimiser");
    memset(o->climb.v_work, 0, (size_t)V * sizeof(uint32_t));
    memset(o->v_touch, 0, (size_t)V * sizeof(uint32_t));
    memset(o->seg_in, 0, (size_t)V);
    memset(o->split_due, 0, (size_t)V);
    if (!polyc__flat_init(&ctx->arena, &o->best, (uint32_t)polyc__line_cap(V), (uint32_t)V))
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the result polylines");
    return polyc__rebuild(o);
}
