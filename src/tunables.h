/* tunables.h - the numbers that decide behaviour and are not configuration:
 * each with the reason it has its value and, where a measurement chose it,
 * the measurement. A number used by one rule in two files is named here
 * once. (Constants private to one step of one file, such as the angle
 * prior's cluster breaks, stay at the top of that file, named.) */
#ifndef POLYC_TUNABLES_H
#define POLYC_TUNABLES_H

/* ---- hill climbing (adjust.c) and the spatial hash (spatial_hash.c) ---- */

/* How far a climbing vertex may go from where the climb started, metres. The
 * hash's buckets are the search radius plus this wide, so the points a moved
 * segment can reach are still in the 3 x 3 buckets around its old place. A
 * trial lies one step beyond the last accepted position, so a climb keeps
 * within POLYC__CLIMB_REACH_M - step_m; a step above half the reach could
 * never be taken, and polyc_config_check refuses it. */
#define POLYC__CLIMB_REACH_M 0.05f
/* the largest step_m a climb can take: reach - step >= step */
#define POLYC__STEP_MAX_M (0.5f * POLYC__CLIMB_REACH_M)
/* steps of one climb at most (then the vertex is offered again) */
#define POLYC__CLIMB_STEPS 64

/* ---- capacities ---- */

/* Vertices beyond the beams (or the occupied cells, or the limits'
 * typical map) that a store holds: the operators add vertices (G, corners)
 * before they remove others. */
#define POLYC__VERTEX_SPARE 1024u
/* Cuts one pass of the split operator records per vertex capacity (V / 4
 * + 64); more wait for the next pass. */
#define POLYC__CUT_SHARE 4
#define POLYC__CUT_SPARE 64
/* Candidates the vertex-removal heap holds beyond one per vertex, at most
 * (a store of fewer vertices: as many as it has, all a pass can push); a
 * candidate that finds it full is not retried. */
#define POLYC__HEAP_SPARE 1024

/* polyc_limits_for_scans: contours and weighted points follow the map (its
 * walls), not the log's length: sized for a share of the beams or a wall
 * every so many cells of the bounding box, whichever is less, with room to
 * spare; points 5/4 of that (cells with several returns' weights). */
#define POLYC__LIMITS_BEAM_SHARE 4
#define POLYC__LIMITS_CELLS_PER_WALL 64
#define POLYC__LIMITS_SPARE 4096
#define POLYC__LIMITS_POINTS_NUM 5
#define POLYC__LIMITS_POINTS_DEN 4

/* ---- geometry ---- */

/* Two lines meet at a corner only if they are more than 10 degrees from
 * parallel: the sine of 10 degrees (corners.c, scan_chains.c). Nearer to
 * parallel the intersection runs far off along both. */
#define POLYC__CORNER_SIN 0.17f
/* A gap between neighbouring points is sampling, not a gap in the wall,
 * up to this many beam spacings at the place (spacing.c): the trace links
 * chain ends across it (trace.c) and the split operator does not cut it
 * (operators.c). */
#define POLYC__GAP_SPACINGS 2.5f
/* Incidence (grid.c): a beam's neighbours describe a surface when the
 * middle endpoint lies within this much of their chord (metres plus a
 * share of the range); and the sine of the incidence is taken as at least
 * POLYC__INCIDENCE_SIN_MIN, so that a beam along a wall stops its misses at
 * most grazing_cells / 0.05 cells (and half the beam) before its end. */
#define POLYC__SURFACE_OFF_M 0.03f
#define POLYC__SURFACE_OFF_REL 0.02f
#define POLYC__INCIDENCE_SIN_MIN 0.05f

/* untangling and zipping (topology.c, zip.c): fixes per segment in one
 * pass, which bounds a pass's work */
#define POLYC__FIXES_PER_SEGMENT 16

/* ---- the search (optimize.c) ---- */

/* hill-climbing rounds after each operator that moves or adds vertices */
#define POLYC__ADJUST_ROUNDS 4
/* rounds of vertex addition an iteration */
#define POLYC__ADD_ROUNDS 4
/* vertices one addition round may add */
#define POLYC__ADDED_CAP 64
/* Cleaning rounds an iteration after its moves (splits, zigzags, corners
 * and a climb each): moves and additions can leave segments without data or
 * hairpins, and the model judged should be clean; each round is cheap and
 * the third rarely finds anything. */
#define POLYC__CLEAN_ROUNDS 3
/* Split passes over the best map when it is polished: a pass cuts one gap
 * a segment. */
#define POLYC__POLISH_SPLITS 8
/* An iteration still coming down from the noise by more than this share of
 * the BIC does not use up the patience: where a band's points weigh less
 * (accuracy.c) the climb back is slower, and a log's search stopped at
 * iteration 0's map while each iteration still gained a percent or two
 * (allowed to go on, it ends with a fifth fewer vertices). */
#define POLYC__RECOVER_GAIN 5e-3f

#endif
