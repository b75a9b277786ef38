/* optimize.c - the search (paper section IV): local search on the BIC.
 * Takes: the initial polylines, the grid and the scans. Gives: the best map
 * found by repeating the operators (overlaps, merge, split, vertex moves,
 * zigzags, noise, vertex count) until `patience` iterations bring no better
 * BIC, or the iteration cap or the caller's progress callback stops it. */
#include "../cost.h"
#include "../optimize.h"

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

/* ---- the steps that are no one operator ---- */

/* every data gap split: a pass cuts one gap a segment */
static int split_gaps(polyc__opt *o)
{
    for (int k = 0; k < POLYC__POLISH_SPLITS && polyc__op_split(o) > 0; k++)
        ;
    return 0;
}
/* a new touch stamp: the steps after it look at what is edited from here */
static int stamp(polyc__opt *o, polyc__op_args *a)
{
    a->mark = ++o->touch_stamp;
    if (a->first == 0)
        a->first = a->mark;
    return 0;
}
/* moves and additions can leave segments without data or hairpins: the
 * CLEAN rows clean them, and a climb follows, before the model is judged,
 * so that the best one is clean */
static int clean(polyc__opt *o, polyc__op_args *a)
{
    for (int round = 0; round < POLYC__CLEAN_ROUNDS; round++) {
        stamp(o, a);
        if (polyc__run_ops(o, POLYC__SEQ_CLEAN, a) == 0)
            break;
        polyc__op_adjust(o, POLYC__ADJUST_ROUNDS, a->mark);
    }
    return 0;
}
/* the zip; what is left of a zipped pair then moves onto the data of both */
static int zip_settled(polyc__opt *o, polyc__op_args *a)
{
    int n = polyc__op_zip(o);
    if (n > 0) {
        polyc__op_adjust(o, POLYC__ADJUST_ROUNDS, a->mark);
        polyc__op_trim_ends(o);
        polyc__op_zip(o);
    }
    return n;
}
/* the map as written: no vertex on another segment (a crossing that the
 * gaps made proper is untangled, and the gaps looked at again) */
static int end_gaps(polyc__opt *o)
{
    int n = polyc__op_end_gaps(o);
    if (n >= 1000) {
        polyc__op_untangle(o);
        polyc__op_end_gaps(o);
    }
    return n;
}
/* The polish's merge and removal can make the best map worse: then the best
 * map comes back, scored afresh. */
static int keep_best(polyc__opt *o, polyc__op_args *a)
{
    if (polyc__bic(o) <= a->best)
        return 0;
    if (polyc__store_from_flat(o->s, &o->best) != POLYC_OK) {
        a->status = polyc__fail(o->ctx, POLYC_ERR_NOMEM, "no room to restore the best map");
        return 0;
    }
    if ((a->status = polyc__rebuild(o)) != POLYC_OK)
        return 0;
    o->untangle_mark = o->zip_mark = 0;
    return 0;
}

/* THE OPERATOR TABLE: every step of the search's sequences, in the order
 * they run (letters: paper IV; ours: not in the paper). ITER: one
 * iteration after the noise (F, in polyc__search); POLISH: the best map
 * once more through merging and vertex removal, kept if its BIC is no
 * higher (the last edits of the search, cuts at crossings and zipped
 * stretches, can leave two ends a centimetre apart that the next iteration
 * would have joined), then the rules the map must keep whatever its BIC:
 * every data gap split, ends trimmed, no double cover, no fold doubling a
 * wall, no crossing, no vertex on a segment; CLEAN: the cleaning round
 * (clean) repeats these while they edit. A single scan's later iterations
 * climb only what the previous one edited after its first climbs (`climb`;
 * removals, zigzags, corners, trims): the vertices those climbs left at an
 * optimum stay there (climbing them again costs a good share of the time
 * and lowers the BIC by a fraction of a percent).
 * A NEW OPERATOR goes here, once: a row at the place in the order where it
 * runs, with its name, its call (o: the optimiser, a: the run's
 * polyc__op_args), the sequences it is a step of and its flags; its
 * function is declared in opt_state.h. A step that runs in two sequences at
 * different places, or with other arguments, has a row for each. (Rows,
 * not function pointers: each step is a direct call, which -Os inlines or
 * not as it likes, and the stack analysis of `make cross` follows.) */
#define POLYC__OP_TABLE(X)                                                                       \
    /* id           name               the call                                 sequences  flags */ \
    X(OVERLAPS,     "overlaps",        polyc__op_overlaps(o),                   I,        R)  /* A */ \
    X(MERGE,        "merge",           polyc__op_merge(o),                      I | P,    R)  /* B */ \
    X(SPLIT,        "split",           polyc__op_split(o),                      I | C,    R)  /* C */ \
    X(REMOVE,       "remove vertices", polyc__op_remove_vertices(o, a->since),  I | P,    0)  /* G */ \
    X(KEEP_BEST,    "keep the best",   keep_best(o, a),                         P,        0)          \
    X(SPLIT_GAPS,   "split every gap", split_gaps(o),                           P,        0)          \
    X(CLIMB,        "climb",           polyc__op_adjust(o, ADJUST, a->climb),   I,        0)  /* D */ \
    X(STAMP,        "stamp",           stamp(o, a),                             I,        0)          \
    X(ZIGZAG,       "zigzags",         polyc__op_zigzag(o),                     I | C,    0)  /* E */ \
    X(CORNERS,      "corners",         polyc__op_corners(o, a->since),          I | C,    0)  /* ours */ \
    X(REMOVE_MARK,  "remove vertices", polyc__op_remove_vertices(o, a->mark),   I,        0)  /* G */ \
    X(ADD,          "add vertices",    polyc__op_add_vertices(o, ADD),          I,        A)  /* G */ \
    X(CLIMB_MARK,   "climb",           polyc__op_adjust(o, ADJUST, a->mark),    I,        0)  /* D */ \
    X(CLEAN,        "clean",           clean(o, a),                             I,        0)          \
    X(TRIM,         "trim ends",       polyc__op_trim_ends(o),                  I | P,    0)  /* ours */ \
    X(STAMP_POLISH, "stamp",           stamp(o, a),                             P,        0)          \
    X(ZIP,          "zip",             polyc__op_zip(o),                        I,        R)  /* ours */ \
    X(ZIP_CLIMB,    "zip and climb",   zip_settled(o, a),                       P,        0)  /* ours */ \
    X(UNFOLD,       "unfold",          polyc__op_unfold(o),                     P,        0)  /* ours */ \
    X(UNTANGLE,     "untangle",        polyc__op_untangle(o),                   I | P,    0)  /* ours */ \
    X(END_GAPS,     "end gaps",        end_gaps(o),                             P,        0)  /* ours */

#define I POLYC__SEQ_ITERATION
#define P POLYC__SEQ_POLISH
#define C POLYC__SEQ_CLEAN
#define R POLYC__OPF_RESTRUCTURE
#define A POLYC__OPF_ADDS
#define ADJUST POLYC__ADJUST_ROUNDS
#define ADD POLYC__ADD_ROUNDS
#define OP_ID(id, name, call, seq, flags) OP_##id,
enum { POLYC__OP_TABLE(OP_ID) OP_COUNT };
#define OP_ROW(id, name, call, seq, flags) {seq, flags},
static const polyc__op OPS[OP_COUNT] = {POLYC__OP_TABLE(OP_ROW)};

/* The step of row i, with the run's arguments a (not inlined into the
 * loop: each case is then one tail call, where -Os otherwise copies the
 * loop's tail into all of them). */
POLYC__NOINLINE static int run_step(polyc__opt *o, polyc__op_args *a, int i)
{
#define OP_CASE(id, name, call, seq, flags) \
    case OP_##id:                           \
        return call;
    switch (i) {
        POLYC__OP_TABLE(OP_CASE)
    }
    return 0;
}

int polyc__run_ops(polyc__opt *o, unsigned seq, polyc__op_args *a)
{
    unsigned allowed = (o->pol.restructure ? POLYC__OPF_RESTRUCTURE : 0u) |
                       (o->pol.add_vertices ? POLYC__OPF_ADDS : 0u);
    allowed &= ~a->skip;
    int sum = 0;
    for (size_t i = 0; i < sizeof OPS / sizeof OPS[0] && a->status == POLYC_OK; i++)
        if ((OPS[i].seq & seq) && (OPS[i].flags & ~allowed) == 0)
            sum += run_step(o, a, (int)i);
    return sum;
}

#undef I
#undef P
#undef C
#undef R
#undef A
#undef ADJUST
#undef ADD
#undef OP_ID
#undef OP_ROW
#undef OP_CASE

/* The best map after the search, polished (POLISH); returns a status (the
 * store holds the result, scored). */
static polyc_status polish(polyc__opt *o, float best)
{
    polyc__op_args a;
    memset(&a, 0, sizeof a);
    a.best = best;
    a.status = POLYC_OK;
    o->untangle_mark = o->zip_mark = 0; /* the best map is a fresh store */
    polyc__run_ops(o, POLYC__SEQ_POLISH, &a);
    return a.status;
}

uint32_t polyc__operators(polyc__opt *o, uint32_t since, uint32_t climb)
{
    polyc__op_args a;
    memset(&a, 0, sizeof a);
    a.since = since;
    a.climb = climb;
    a.status = POLYC_OK;
    polyc__run_ops(o, POLYC__SEQ_ITERATION, &a);
    return a.first;
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
    ctx->flat.circ_n = ctx->flat.arc_n = 0; /* (the map changes under them) */
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
         * a long log's search early, with half as many vertices again as
         * when the noise is allowed to decay */
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
         * nothing measurable (over many scans a few vertices more in all,
         * the same f and ray RMSE, for less work) */
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

polyc_status polyc__find_curves(polyc_ctx *ctx)
{
    polyc__opt o;
    polyc_status st = polyc__opt_setup(ctx, &o);
    if (st == POLYC_OK) {
        polyc__circles_select(&o);
        polyc__arcs_select(&o);
    }
    return st;
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
