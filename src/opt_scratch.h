/* opt_scratch.h - each operator group's working state (its scratch),
 * carved by its own file and read by no other group but as said at each:
 * trial evaluation's, split and trimming's, vertex removal's, hill
 * climbing's. The state they all share is opt_state.h's polyc__opt. */
#ifndef POLYC_OPT_SCRATCH_H
#define POLYC_OPT_SCRATCH_H

#include "context.h"

typedef struct polyc__heap_entry {
    float delta;                  /* change of the BIC if the vertex goes */
    int32_t v;
    int32_t pad;
} polyc__heap_entry;

/* Trial evaluation's scratch (trial.c; read by adjust.c and trial_costs.c). */
typedef struct polyc__eval_scratch {
    int32_t *loc_pt;               /* points near the edited segments */
    float *loc_base;              /* their cost without the edited segments */
    int32_t *loc_seg;              /* and the segment giving it */
    int32_t loc_n;
    /* the listed points again, by field (when there are 8 to lsoa_cap of
     * them), so that a trial's costs are computed several at a time
     * (trial_costs.c): lsoa_n == loc_n when they are valid */
    float *lsoa_x, *lsoa_y, *lsoa_w, *lsoa_cxx, *lsoa_cxy, *lsoa_cyy;
    float *lsoa_c;
    int32_t lsoa_n, lsoa_cap;
    float loc_fixed, loc_fixed_cur; /* pruned points: base and current sums */
    /* moving one vertex: points sure to stay in the interior of one of its
     * segments and nearest to it, whatever the move within reach, are
     * summed as second moments about the segment's fixed end (agg_m: aa,
     * ab, bb in the frame of the segment before the move: a along it, b
     * across; agg_t: its direction), so that a trial costs O(1) for them:
     * listed in agg_pt, those of segment 0 from the front (agg_n[0]), of
     * segment 1 from the back. (In x and y, the small sum across a long
     * wall is the difference of large ones: in float, a map of a log seen
     * in many passes lost it to rounding and kept far more vertices than
     * its walls need.) */
    int32_t *agg_pt, agg_cap, agg_n[2];
    /* the segments (other than the old ones) near the prepared region, for
     * the points whose own segment goes: cand_n < 0 not gathered yet,
     * POLYC__CAND_MAX + 1 too many (then the hash is queried) */
    int32_t *cand_seg, cand_n;
    int32_t cand_src;              /* the bucket whose 3 x 3 were gathered last */
    uint32_t cand_stamp;           /* epoch of the gathering (bucket and segment marks) */
    float *cand_box;               /* per candidate: min x, min y, max x, max y */
    int agg_on;                    /* 0: no aggregation prepared */
    int agg_moving_b[2];           /* the moving end is the segment's b */
    float agg_ax[2], agg_ay[2], agg_tx[2], agg_ty[2], agg_m[2][3];
} polyc__eval_scratch;

/* Split and end trimming's scratch (split.c): per segment offsets,
 * positions of its points (of the segments split_due only). */
typedef struct polyc__split_scratch {
    int32_t *split_off;
    float *split_t;
    int32_t *cut_seg, *cut_next, cut_cap;
    float *cut_t0, *cut_t1;
    float *trim_head;              /* end trimming: farthest point from the head side */
    float *gap_head, *gap_tail;    /* per segment: its ends' distance to its nearest data
                                    * (split, valid while it is not split_due) */
} polyc__split_scratch;

/* Vertex removal's scratch (model_size.c): per segment sums, farthest
 * point; the removal heap. */
typedef struct polyc__size_scratch {
    float *seg_sum, *seg_w, *seg_far_d;
    int32_t *seg_far;
    /* per segment (its first vertex): a digest of the four vertices an
     * addition on it moved or looked at when it failed (0: none since the
     * search began) */
    uint32_t *add_failed;
    polyc__heap_entry *heap;
    int32_t heap_n, heap_cap;
} polyc__size_scratch;

/* Hill climbing's scratch (adjust.c): per vertex, the round stamp at
 * which it is to be climbed. */
typedef struct polyc__climb_scratch {
    uint32_t *v_work;
    uint32_t work_stamp;
} polyc__climb_scratch;

#endif
