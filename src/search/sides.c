/* sides.c - what each segment of the map is seen from (not in the paper):
 * the views of the endpoints nearest to it, summed, and the weight of those
 * views across it from its left and from its right. Takes: the points with
 * their views (pt_view) and their assignment. Gives: seg_side, and the
 * zip's scratch (polyc__sides), which the zip (a band is seen from one
 * side) and the online round (what a segment explains) read. */
#include "../opt_state.h"

#include <math.h>

#define SIDE_REACH_M 0.10f  /* endpoints this near a segment tell its side */

/* What each segment is seen from, into seg_side (x, y per vertex): the sum
 * of the vectors to their sensors of the endpoints within SIDE_REACH_M
 * whose nearest segment it is (a point's own cost says how near: its mean
 * squared distance). Along the segment's left normal it gives its side
 * (> 0: seen from the left; as docs/evaluation.md's band15 gives a segment
 * its side). Valid for the segments not edited since zip_mark. */
void polyc__find_sides(polyc__opt *o, const int32_t *list, int32_t n, float *left, float *right)
{
    const polyc__store *s = o->s;
    float *side = o->seg_side;
    const float reach2 = (float)SIDE_REACH_M * (float)SIDE_REACH_M;
    for (int32_t v = 0; v < s->v_high; v++) {
        side[2 * v] = side[2 * v + 1] = 0.0f;
        if (left)
            left[v] = right[v] = 0.0f;
    }
    if (!list)
        n = o->d.np;
    for (int32_t j = 0; j < n; j++) {
        int32_t i = list ? list[j] : j;
        int32_t sg = o->d.pt_seg[i];
        if (sg == POLYC__NONE || o->d.pt_cost[i] > reach2 * (float)o->d.pts[i].w)
            continue;
        float vx = o->d.pt_view[2 * i], vy = o->d.pt_view[2 * i + 1];
        side[2 * sg] += vx;
        side[2 * sg + 1] += vy;
        if (!left)
            continue;
        const polyc__vertex *a = &s->v[sg], *b = &s->v[a->next];
        float dx = b->x - a->x, dy = b->y - a->y, len = sqrtf(dx * dx + dy * dy);
        float vl = sqrtf(vx * vx + vy * vy);
        if (!(len > 0.0f) || !(vl > 0.0f))
            continue;
        float across = o->d.pts[i].w * (-vx * dy + vy * dx) / (len * vl);
        if (across > 0.0f)
            left[sg] += across;
        else
            right[sg] -= across;
    }
}

/* A segment is seen from both sides when the endpoints within 10 cm of
 * it whose nearest it is were seen from its left and from its right in at
 * least this ratio (their unit views across it, by weight): a line drawn
 * between the two faces of a thin wall, each face 3 cm off it. Its summed
 * view nearly cancels, and the side rule of explained() left both faces to
 * it: on simulated thin walls the online map kept one line between the
 * faces for most of a wall's length, several times the batch map's error;
 * with the rule it is as precise as the batch map.
 * (online_round.c's explained(); and zip.c's band rule) */
#define TWO_SIDED_RATIO 0.25f
/* Only segments this long: on short ones (furniture, chair legs seen from
 * all round) the rule traced bits of clutter, a cluttered log's finished
 * map a fifth more polylines, many of them under 10 cm long. */
#define TWO_SIDED_MIN_M 0.5f

/* Whether segment sg is seen from both sides, from the weights of views
 * across it that polyc__find_sides left in the zip's scratch (from its left
 * and from its right). */
int polyc__two_sided(const polyc__opt *o, int32_t sg)
{
    const polyc__vertex *a = &o->s->v[sg], *b = &o->s->v[a->next];
    float dx = b->x - a->x, dy = b->y - a->y;
    const polyc__side_scratch sd = polyc__sides(o);
    float l = sd.left_w[sg], r = sd.right_w[sg];
    return dx * dx + dy * dy >= TWO_SIDED_MIN_M * TWO_SIDED_MIN_M && l > 0.0f && r > 0.0f &&
           polyc__minf(l, r) >= TWO_SIDED_RATIO * polyc__maxf(l, r);
}
