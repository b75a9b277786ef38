/* optimize.c - the search (paper section IV): local search on the BIC.
 * Takes: the initial polylines, the grid and the scans. Gives: the best map
 * found by repeating the operators (overlaps, merge, split, vertex moves,
 * zigzags, noise, vertex count) until `patience` iterations bring no better
 * BIC, or the iteration cap or the caller's progress callback stops it. */
#include "cost.h"
#include "optimize.h"

#include <math.h>
#include <string.h>

static void fill_stats(polyc__opt *o)
{
    polyc_stats *st = &o->ctx->stats;
    polyc__figures_out(polyc__bic(o), polyc__err(o), &st->bic, &st->error_sq_m2);
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
 * trimmed, no double cover, no fold doubling a wall (op_unfold), no
 * crossing. Returns a status (the store holds
 * the result, scored). */
static polyc_status polish(polyc__opt *o, float best)
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
    polyc__op_unfold(o);
    polyc__op_untangle(o);
    /* the map as written: no vertex on another segment */
    if (polyc__op_end_gaps(o) >= 1000) {
        polyc__op_untangle(o);
        polyc__op_end_gaps(o);
    }
    return POLYC_OK;
}

/* One iteration's operators after the noise, in their order; `since`: the
 * stamp after which edits are looked at again (0: all), `climb`: the
 * first climb's. Returns the stamp taken after the first climb. */
uint32_t polyc__operators(polyc__opt *o, uint32_t since, uint32_t climb)
{
    if (o->pol.restructure) {
        polyc__op_overlaps(o);      /* A */
        polyc__op_merge(o);         /* B */
        polyc__op_split(o);         /* C */
    }
    polyc__op_remove_vertices(o, since); /* G: fewer vertices first, so that */
    /* D moves what is left. A single scan's later iterations climb only
     * what the previous one edited after its first climbs (removals,
     * zigzags, corners, trims): the vertices those climbs left at an
     * optimum stay there (on 200 freiburg-campus scans, with ends not
     * climbed, climbing them again takes a sixth of the time and lowers
     * the BIC by 0.15 %) */
    polyc__op_adjust(o, POLYC__ADJUST_ROUNDS, climb);
    uint32_t first = ++o->touch_stamp, mark = first;
    polyc__op_zigzag(o);            /* E */
    polyc__op_corners(o, since);    /* corners (not in the paper) */
    polyc__op_remove_vertices(o, mark); /* G */
    if (o->pol.add_vertices)
        polyc__op_add_vertices(o, POLYC__ADD_ROUNDS); /* G, more vertices */
    polyc__op_adjust(o, POLYC__ADJUST_ROUNDS, mark);
    /* moves and additions can leave segments without data or hairpins:
     * clean them before the model is judged, so the best one is clean */
    for (int round = 0; round < POLYC__CLEAN_ROUNDS; round++) {
        mark = ++o->touch_stamp;
        if ((!o->pol.restructure ? 0 : polyc__op_split(o)) + polyc__op_zigzag(o) +
                polyc__op_corners(o, since) == 0)
            break;
        polyc__op_adjust(o, POLYC__ADJUST_ROUNDS, mark);
    }
    polyc__op_trim_ends(o); /* moves could push ends past the data */
    if (o->pol.restructure)
        polyc__op_zip(o);   /* one piece of map per wall */
    polyc__op_untangle(o);  /* last: the map judged has no crossing */
    return first;
}

polyc_status polyc__optimize(polyc_ctx *ctx, polyc_progress_fn progress, void *user)
{
    polyc__opt o;
    ctx->opt_result_valid = 0;
    polyc_status st = polyc__opt_setup(ctx, &o);
    if (st != POLYC_OK)
        return st;
    return polyc__search(&o, progress, user);
}

/* The search from the map in the store (the batch's trace, or an online
 * context's map), on an optimiser set up and scored. */
polyc_status polyc__search(polyc__opt *o, polyc_progress_fn progress, void *user)
{
    polyc_ctx *ctx = o->ctx;
    polyc_status st;
    const polyc_config *cfg = o->cfg;
    polyc__flat_from_store(&o->best, o->s);
    polyc__size_forget(o);
    float best = polyc__bic(o);
    float sigma = (float)cfg->noise_m;
    for (uint8_t k = 0; k < o->pol.noise_skip; k++)
        sigma *= (float)cfg->noise_decay;
    uint32_t quiet = 0, it;
    polyc_status result = POLYC_OK;
    uint32_t prev_start = 0, prev_mark = 0;
    float prev_bic = best;
    for (it = 0; it < cfg->max_iterations; it++) {
        uint32_t start = ++o->touch_stamp;
        /* F: noise to leave local minima, shrinking every iteration. Below
         * half a hill-climbing step it is not applied any more: the steps
         * could not correct it. Without noise, only what changed since the
         * previous iteration is adjusted and offered for removal again. */
        float noise = it > 0 && sigma >= 0.5f * (float)cfg->step_m ? sigma : 0.0f;
        if (!o->pol.noise)
            noise = 0.0f;
        if (noise > 0.0f) {
            polyc__op_noise(o, noise);
            polyc__size_forget(o); /* (the noise moves vertices without touching them) */
            o->untangle_mark = o->zip_mark = 0; /* every segment moved */
            if ((st = polyc__rebuild(o)) != POLYC_OK)
                return restore_best(o, st);
        }
        uint32_t since = it == 0 || noise > 0.0f ? 0 : prev_start;
        prev_start = start;
        prev_mark = polyc__operators(o, since, o->pol.climb_since_prev && it > 0 ? prev_mark : since);
        if (o->h.out_of_entries)
            return restore_best(o, polyc__fail(ctx, POLYC_ERR_NOMEM, "spatial hash full"));
        POLYC__CHECKS_ITERATION(o);
        float bic = polyc__bic(o);
        /* any better map is kept; a gain under one BIC unit (no evidence
         * either way) does not restart the patience: late iterations can
         * cycle between maps that differ by a vertex and a fraction of it.
         * Iterations with noise do not use it up: their maps are perturbed
         * on purpose, and a run of them all worse than iteration 0 stopped
         * infinite-corridor at iteration 5 with 5,766 vertices (3,793 when
         * the noise is allowed to decay) */
        int gained = bic < best - (o->pol.gain_share > 0.0f ? fmaxf(1.0f, o->pol.gain_share * fabsf(best)) : 1.0f);
        /* Nor do iterations that are still coming down from the noise by
         * more than POLYC__RECOVER_GAIN of the BIC each (tunables.h) */
        int recovering = o->pol.recover && it > 0 && bic < prev_bic - POLYC__RECOVER_GAIN * fabsf(prev_bic);
        prev_bic = bic;
        quiet = gained ? 0 : ((noise > 0.0f && o->pol.noise_spares_patience) || recovering ? quiet : quiet + 1);
        /* (better by more than the float total's rounding: its terms are
         * summed with compensation, to about 1e-7 of it) */
        if (bic < best - 1e-6f * fabsf(best)) {
            best = bic;
            polyc__flat_from_store(&o->best, o->s);
        }
        polyc_iteration rep;
        memset(&rep, 0, sizeof rep);
        rep.iteration = it;
        rep.vertices = (uint32_t)o->s->v_live;
        rep.polylines = (uint32_t)live_lines(o->s);
        polyc__figures_iteration(&rep, bic, best, noise);
        if (it > 0)
            sigma *= (float)cfg->noise_decay;
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
        int noisy_later = o->pol.noise && sigma >= 0.5f * (float)cfg->step_m;
        if (!noisy_later && !edited_since(o, start))
            break;
        /* A single scan has no noise either: an iteration that gained less
         * than one BIC unit leaves so little edited that the next ones gain
         * nothing measurable (the 130 bench scans: 4 vertices more in
         * all, the same f and ray RMSE, 4 % fewer instructions) */
        if (o->pol.stop_without_gain && !gained)
            break;
    }
    ctx->stats.iterations = it < cfg->max_iterations ? it + (result == POLYC_OK) : it;
    /* the best model found is the result */
    if (polyc__store_from_flat(o->s, &o->best) != POLYC_OK)
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room to restore the best map");
    ctx->opt_result_valid = 1;
    if ((st = polyc__rebuild(o)) != POLYC_OK)
        return st;
    if (o->pol.restructure && result == POLYC_OK && (st = polish(o, best)) != POLYC_OK)
        return st;
    fill_stats(o);
    return result;
}

polyc_status polyc__score(polyc_ctx *ctx, double *bic, double *err)
{
    polyc__opt o;
    polyc_status st = polyc__opt_setup(ctx, &o);
    if (st != POLYC_OK)
        return st;
    fill_stats(&o);
    polyc__figures_out(polyc__bic(&o), polyc__err(&o), bic, err);
    return POLYC_OK;
}
