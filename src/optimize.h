/* optimize.h - the search's entry points (optimize.c): setting the
 * optimiser up, the search loop, and the table of operators that its
 * sequences (an iteration, the polish, an online round) read. The state
 * every file of the search shares is in opt_state.h. */
#ifndef POLYC_OPTIMIZE_H
#define POLYC_OPTIMIZE_H

#include "opt_state.h"

/* ---- the operator table (optimize.c) ----
 * One table (POLYC__OP_TABLE) lists every step of the search's operator
 * sequences, in the order they run; each row says which sequences it is a step of (bits
 * POLYC__SEQ_*) and when it is skipped (POLYC__OPF_*). A sequence runs the
 * rows that carry its bit, top to bottom. */
enum {
    POLYC__SEQ_ITERATION = 1, /* one iteration of the search, after the noise */
    POLYC__SEQ_POLISH = 2,    /* the best map once more, after the search */
    POLYC__SEQ_CLEAN = 4      /* an iteration's cleaning round, repeated while it edits */
};
enum {
    POLYC__OPF_RESTRUCTURE = 1, /* only where the policy restructures (pol.restructure) */
    POLYC__OPF_ADDS = 2         /* only where the policy adds vertices (pol.add_vertices) */
};
/* What the steps of one run of a sequence share. */
typedef struct polyc__op_args {
    uint32_t since;    /* the stamp after which edits are looked at again (0: all) */
    uint32_t climb;    /* the first climb's (climbs only what was edited after it) */
    uint32_t mark;     /* the stamp a "stamp" step took last */
    uint32_t first;    /* the stamp the first "stamp" step took (0: none yet) */
    unsigned skip;     /* POLYC__OPF_* flags whose rows this run skips */
    float best;        /* the polish: the best map's BIC (o->best holds it) */
    polyc_status status; /* a step that fails sets it, and the run stops */
} polyc__op_args;
/* A row of the table (optimize.c) as the runs read it: the sequences it is
 * a step of and its flags (its name and its call stand in the table's
 * source; the names cost the firmware 250 bytes and nothing reads them). A
 * step returns how much it edited (what the cleaning round sums). */
typedef struct polyc__op {
    uint8_t seq;   /* POLYC__SEQ_* bits: the sequences it is a step of */
    uint8_t flags; /* POLYC__OPF_*: skipped unless the policy allows */
} polyc__op;
/* Runs the table's rows of sequence `seq` (one POLYC__SEQ_* bit) in order,
 * with the shared arguments a; returns the sum of the steps' results (a
 * step that sets a->status ends the run). */
int polyc__run_ops(polyc__opt *o, unsigned seq, polyc__op_args *a);
/* optimize.c: one iteration's operators after the noise (the ITERATION
 * sequence); `since`: the stamp after which edits are looked at again (0:
 * all), `climb`: the first climb's; returns the stamp taken after the first
 * climb */
uint32_t polyc__operators(polyc__opt *o, uint32_t since, uint32_t climb);
/* opt_setup.c: carves the state from the arena after the trace, scores it */
polyc_status polyc__opt_setup(polyc_ctx *ctx, polyc__opt *o);
/* opt_setup.c: an optimiser that lasts across calls (an online context's),
 * carved once for the limits; and its data made again (the points through
 * ctx->layer's collect, with the prior given) before a search; at most
 * bucket_cap buckets */
int polyc__opt_carve_lasting(polyc_ctx *ctx, polyc__arena *a, polyc__opt *o, int32_t bucket_cap);
polyc_status polyc__opt_refresh(polyc__opt *o, const polyc__prior *prior);

/* optimize.c: the search on a set-up optimiser (the batch loop) */
polyc_status polyc__search(polyc__opt *o, polyc_progress_fn progress, void *user);


#endif
