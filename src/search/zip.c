/* zip.c - one piece of map per wall (not in the paper): two pieces of map
 * along one wall, a stretch of a segment that runs within overlap_m of
 * another piece of the map (not its neighbours) for more than ZIP_RUN_M,
 * lose that stretch from one of the two, the one whose loss raises the BIC
 * least, until no such stretch is left. Takes: the optimiser state (and
 * the sides segments are seen from, seg_side: sides.c). Gives: the zipped
 * map. */
#include "../opt_state.h"

#include <math.h>

#define ZIP_STEP_M 0.02f    /* samples along a segment for the double-cover test */
#define ZIP_RUN_M 0.15f     /* a doubly covered stretch longer than this goes */
#define ZIP_SNAP_M 0.03f    /* a stretch this near a segment end reaches it */
#define ZIP_PASSES 3        /* passes of one zip over what the last one edited */
/* One line through a band (not in the paper): two pieces of map seen from
 * the same side, parallel within BAND_COS and within BAND_M of each other
 * along more than ZIP_RUN_M, are one wall whose points form a band (pose
 * error, far range): a laser cannot see a wall through another from the
 * same side. BAND_M: bands on the real logs are 10-30 cm wide, and two lines
 * through a 30 cm band settle 15 cm apart. */
#define BAND_M 0.20f
#define BAND_END_M 0.15f   /* past the other's end: a 10 cm recess's back is within this of
                             * the wall's ends over 11 cm only (less than ZIP_RUN_M) */
#define BAND_COS 0.9397f    /* cos 20 degrees */

/* The nearest segment to (x, y) that does not touch a or b (within the
 * 3 x 3 buckets around it: at least the search radius), or NONE; *d2 its
 * squared distance. */
static int32_t nearest_other(const polyc__opt *o, float x, float y, int32_t a, int32_t b,
                             float *d2)
{
    const polyc__hash *h = &o->h;
    const polyc__store *s = o->s;
    int32_t best = POLYC__NONE;
    *d2 = 1e30f;
    polyc__near_segs w;
    POLYC__FOR_NEAR_SEGS(w, h, x, y, sg) {
        if (polyc__touches(s, sg, a, b))
            continue;
        const polyc__vertex *c = &s->v[sg], *d = &s->v[c->next];
        float dd = polyc__seg_dist2(x, y, c->x, c->y, d->x, d->y);
        if (dd < *d2) {
            *d2 = dd;
            best = sg;
        }
    }
    return best;
}

/* Is (x, y) within sqrt(lim2) of a segment that does not touch a or b? */
static int covered(const polyc__opt *o, float x, float y, int32_t a, int32_t b, float lim2)
{
    float d2;
    return nearest_other(o, x, y, a, b, &d2) != POLYC__NONE && d2 <= lim2;
}

/* The unit normal of segment sg towards those who saw it; 0 if unknown
 * (no endpoint, or edited since the sides were found). */
static int seen_normal(const polyc__opt *o, int32_t sg, float *nx, float *ny)
{
    const polyc__vertex *a = &o->s->v[sg], *b = &o->s->v[a->next];
    float dx = b->x - a->x, dy = b->y - a->y, len = sqrtf(dx * dx + dy * dy);
    float side = -o->seg_side[2 * sg] * dy + o->seg_side[2 * sg + 1] * dx;
    if (!(len > 0.0f) || side == 0.0f || polyc__edited_since(o, sg, o->zip_mark))
        return 0;
    float sign = side > 0.0f ? 1.0f : -1.0f;
    *nx = -sign * dy / len;
    *ny = sign * dx / len;
    return 1;
}

/* Whether segment sg is seen from both sides by the sides the zip found
 * last (polyc__two_sided; not edited since). */
static int two_sided_now(const polyc__opt *o, int32_t sg)
{
    return o->seg_side && !polyc__edited_since(o, sg, o->zip_mark) && polyc__two_sided(o, sg);
}

/* Whether segments v and sg are parallel within BAND_COS. */
static int parallel(const polyc__opt *o, int32_t v, int32_t sg)
{
    const polyc__vertex *a = &o->s->v[v], *b = &o->s->v[a->next];
    const polyc__vertex *c = &o->s->v[sg], *d = &o->s->v[c->next];
    float ux = b->x - a->x, uy = b->y - a->y, wx = d->x - c->x, wy = d->y - c->y;
    float dot = ux * wx + uy * wy;
    return dot * dot >= BAND_COS * BAND_COS * (ux * ux + uy * uy) * (wx * wx + wy * wy);
}

/* The segments that may lie in a band with segment v (seen along the unit
 * normal nx, ny, or 0 if unknown): not touching it, parallel within
 * BAND_COS, seen from the same side and within BAND_M of it (the nearest
 * of the four ends to the other segment: parallel segments do not cross).
 * Or, when v is seen from both sides (`v_two`), a parallel one seen from
 * both sides too: a thin wall seen from both sides through a band of pose
 * error, its two sides' points mixed over the band's width, which the BIC
 * draws as two lines each with points of both sides (a closed loop a
 * metre long and a hand wide round a band whose returns from either side
 * lie within two centimetres of its middle). The faces of a partition seen
 * cleanly are each seen from one side. At most BAND_CANDIDATES (the first
 * found), into cand; returns how many. */
#define BAND_CANDIDATES 16
static int band_candidates(const polyc__opt *o, int32_t v, float nx, float ny, int v_two,
                           int32_t *cand)
{
    const polyc__hash *h = &o->h;
    const polyc__store *s = o->s;
    int32_t w = s->v[v].next, n = 0;
    float ax = s->v[v].x, ay = s->v[v].y, bx = s->v[w].x, by = s->v[w].y;
    int32_t ix0, iy0, ix1, iy1;
    polyc__bucket_xy(h, polyc__minf(ax, bx) - BAND_M, polyc__minf(ay, by) - BAND_M, &ix0, &iy0);
    polyc__bucket_xy(h, polyc__maxf(ax, bx) + BAND_M, polyc__maxf(ay, by) + BAND_M, &ix1, &iy1);
    for (int32_t iy = iy0; iy <= iy1; iy++)
        for (int32_t ix = ix0; ix <= ix1; ix++)
            for (int32_t e = h->seg_head[iy * h->bx + ix]; e != POLYC__NONE; e = h->entries[e].next) {
                int32_t sg = h->entries[e].seg, k;
                if (polyc__touches(s, sg, v, w))
                    continue;
                for (k = 0; k < n && cand[k] != sg; k++)
                    ;
                if (k < n)
                    continue; /* listed from another bucket */
                float mx, my;
                int same = seen_normal(o, sg, &mx, &my) && mx * nx + my * ny >= BAND_COS;
                if (!same && !(v_two && two_sided_now(o, sg) && parallel(o, v, sg)))
                    continue;
                const polyc__vertex *c = &s->v[sg], *d = &s->v[c->next];
                float d2 = polyc__minf(
                    polyc__minf(polyc__seg_dist2(ax, ay, c->x, c->y, d->x, d->y),
                                polyc__seg_dist2(bx, by, c->x, c->y, d->x, d->y)),
                    polyc__minf(polyc__seg_dist2(c->x, c->y, ax, ay, bx, by),
                                polyc__seg_dist2(d->x, d->y, ax, ay, bx, by)));
                if (d2 > BAND_M * BAND_M)
                    continue;
                cand[n++] = sg;
                if (n == BAND_CANDIDATES)
                    return n;
            }
    return n;
}

/* The first of the n candidates (band_candidates) in a band with the
 * point (x, y): more than a grid cell from its line (nearer, it is the
 * same line continued: on the sim office, 12 cm walls seen from both sides
 * lost pieces to their own continuations at 1.5 cm, none at 2.5), and
 * within BAND_M of it with its foot on the candidate, or within BAND_END_M
 * of the candidate past its end; or NONE. */
static int32_t band_other(const polyc__opt *o, float x, float y, const int32_t *cand, int n)
{
    const polyc__store *s = o->s;
    float lim2 = o->ctx->cfg.cell_m * o->ctx->cfg.cell_m;
    for (int k = 0; k < n; k++) {
        const polyc__vertex *c = &s->v[cand[k]], *d = &s->v[c->next];
        float dx = d->x - c->x, dy = d->y - c->y, l2 = dx * dx + dy * dy;
        if (!(l2 > 0.0f))
            continue;
        float u = ((x - c->x) * dx + (y - c->y) * dy) / l2;
        float off = ((x - c->x) * dy - (y - c->y) * dx);
        if (off * off <= lim2 * l2)
            continue; /* on its line */
        if ((u >= 0.0f && u <= 1.0f && off * off <= BAND_M * BAND_M * l2) ||
            polyc__seg_dist2(x, y, c->x, c->y, d->x, d->y) <= BAND_END_M * BAND_END_M)
            return cand[k];
    }
    return POLYC__NONE;
}

/* What a sample of a segment is tested for: double cover (within sqrt
 * lim2 of another piece of map) or a band (band_other, the segment's seen
 * normal nx, ny). */
typedef struct run_test {
    int band;
    float lim2;
    int32_t cand[BAND_CANDIDATES];  /* band: the segments that may hold it */
    int n_cand;
} run_test;

static int sample_in_run(const polyc__opt *o, const run_test *rt, float x, float y, int32_t a,
                         int32_t b)
{
    if (rt->band)
        return band_other(o, x, y, rt->cand, rt->n_cand) != POLYC__NONE;
    return covered(o, x, y, a, b, rt->lim2);
}

/* The longest stretch of segment v whose samples pass the test (band 0:
 * double cover; 1: a band with another piece of map seen from v's side),
 * as fractions [*t0, *t1] along it; 0 if none is longer than ZIP_RUN_M. */
static int longest_run(const polyc__opt *o, int32_t v, int band, float *t0, float *t1)
{
    const polyc__vertex *V = o->s->v;
    int32_t w = V[v].next;
    float ax = V[v].x, ay = V[v].y, dx = V[w].x - ax, dy = V[w].y - ay;
    float len = sqrtf(dx * dx + dy * dy);
    if (!(len > ZIP_RUN_M))
        return 0;
    run_test rt;
    rt.band = band;
    rt.lim2 = o->cfg->overlap_m * o->cfg->overlap_m;
    rt.n_cand = 0;
    /* none of its samples is covered when no other segment comes within
     * reach of the segment (a clean map's usual case, found without
     * sampling; a millimetre more: the samples lie on it within rounding,
     * and a covering segment's bucket is one a sample's query walks when
     * buckets are wider than twice the reach: else no shortcut) */
    if (!band && o->h.bucket_m > 2.0f * o->cfg->overlap_m + 0.01f &&
        !polyc__segment_near_other(o, v, o->cfg->overlap_m + 1e-3f))
        return 0;
    if (band) {
        float nx = 0.0f, ny = 0.0f;
        int two = two_sided_now(o, v);
        if (!o->seg_side || (!seen_normal(o, v, &nx, &ny) && !two) ||
            (rt.n_cand = band_candidates(o, v, nx, ny, two, rt.cand)) == 0)
            return 0;
    }
    int32_t n = (int32_t)ceilf(len / ZIP_STEP_M);
    int32_t run0 = -1, best0 = 0, best1 = -1;
    for (int32_t k = 0; k <= n + 1; k++) {
        int c = 0;
        if (k <= n) {
            float t = (float)k / (float)n;
            c = sample_in_run(o, &rt, ax + t * dx, ay + t * dy, v, w);
        }
        if (c && run0 < 0)
            run0 = k;
        if (!c && run0 >= 0) {
            if (k - 1 - run0 > best1 - best0) {
                best0 = run0;
                best1 = k - 1;
            }
            run0 = -1;
        }
    }
    if (best1 < 0 || (float)(best1 - best0) * len / (float)n <= ZIP_RUN_M)
        return 0;
    *t0 = (float)best0 / (float)n;
    *t1 = (float)best1 / (float)n;
    float snap = ZIP_SNAP_M / len;
    if (*t0 < snap)
        *t0 = 0.0f;
    if (*t1 > 1.0f - snap)
        *t1 = 1.0f;
    return 1;
}

/* The change of the BIC if stretch [t0, t1] of segment v goes. */
static float drop_delta(polyc__opt *o, int32_t v, float t0, float t1)
{
    const polyc__vertex *V = o->s->v;
    int32_t w = V[v].next;
    float ax = V[v].x, ay = V[v].y, dx = V[w].x - ax, dy = V[w].y - ay;
    float xy[8];
    int n_new = 0;
    float dk = 0.0f, dangle = 0.0f;
    if (t0 > 0.0f) {
        xy[4 * n_new] = ax;
        xy[4 * n_new + 1] = ay;
        xy[4 * n_new + 2] = ax + t0 * dx;
        xy[4 * n_new + 3] = ay + t0 * dy;
        n_new++;
        dk += V[w].next == POLYC__NONE && t1 >= 1.0f ? 0.0f : 1.0f;
    } else if (V[v].prev == POLYC__NONE) {
        dk -= t1 >= 1.0f ? 1.0f : 0.0f; /* the head goes, or moves to t1 */
    } else {
        dangle -= o->acost[v];        /* v becomes an end */
    }
    if (t1 < 1.0f) {
        xy[4 * n_new] = ax + t1 * dx;
        xy[4 * n_new + 1] = ay + t1 * dy;
        xy[4 * n_new + 2] = V[w].x;
        xy[4 * n_new + 3] = V[w].y;
        n_new++;
        dk += V[v].prev == POLYC__NONE && t0 <= 0.0f ? 0.0f : 1.0f;
    } else if (V[w].next == POLYC__NONE) {
        dk -= t0 <= 0.0f ? 1.0f : 0.0f;
    } else {
        dangle -= o->acost[w];
    }
    float derr = polyc__local_delta(o, &v, 1, xy, n_new, INFINITY);
    return (float)o->cfg->alpha * (derr + (float)o->cfg->gamma * dangle) + dk * o->d.log_n;
}

/* Cuts stretch [t0, t1] out of segment v; 0 if there was no room. */
static int drop_stretch(polyc__opt *o, int32_t v, float t0, float t1)
{
    polyc__store *s = o->s;
    int32_t w = s->v[v].next;
    float ax = s->v[v].x, ay = s->v[v].y, dx = s->v[w].x - ax, dy = s->v[w].y - ay;
    int head = s->v[v].prev == POLYC__NONE, tail = s->v[w].next == POLYC__NONE;
    if (t0 <= 0.0f && head && t1 < 1.0f) {
        polyc__apply_move(o, v, ax + t1 * dx, ay + t1 * dy);
        return 1;
    }
    if (t1 >= 1.0f && tail && t0 > 0.0f) {
        polyc__apply_move(o, w, ax + t0 * dx, ay + t0 * dy);
        return 1;
    }
    polyc__chg_begin(o);
    int32_t c0 = v, c1;
    int ok = 1;
    if (t0 > 0.0f && (c0 = polyc__op_insert_after(o, v, ax + t0 * dx, ay + t0 * dy)) == POLYC__NONE)
        ok = 0;
    c1 = ok ? s->v[c0].next : POLYC__NONE;
    if (ok && t1 < 1.0f &&
        (c1 = polyc__op_insert_after(o, c0, ax + t1 * dx, ay + t1 * dy)) == POLYC__NONE)
        ok = 0;
    if (ok)
        polyc__op_cut(o, c0); /* the link c0 -> c1 goes; a lone end with it */
    polyc__chg_commit(o);
    (void)c1;
    return ok;
}

/* An open end that runs on along another piece of map, parallel to it
 * (within BAND_COS) and within overlap_m of it, for at most ZIP_RUN_M past
 * where that piece begins: an end that overshoots a T junction or the start
 * of the wall's next piece. Nothing in the BIC pulls it back (the points it
 * overlaps cost the same on either piece), and band15 counts the stretch
 * with its 15 cm reach: an end a decimetre past a T junction, a few cm off
 * the other line, counts as a run of over twice that (its covered
 * stretch, just under ZIP_RUN_M, is too short for the zip's runs; one just
 * over it goes whole to the zip, which leaves the end short of the
 * junction). Only where the two are seen from the same side: a thin
 * wall's other face is not the wall's next piece. The end is pulled
 * back to where the other piece begins: the covered stretch's inner end
 * plus the cover's reach (overlap_m, or the stretch if shorter). Returns
 * the new end's fraction along segment v in *t, and which end in *tail
 * (1: v's next); 0 if none. */
static int end_overshoot(const polyc__opt *o, int32_t v, float *t, int *tail)
{
    const polyc__vertex *V = o->s->v;
    int32_t w = V[v].next;
    int head_end = V[v].prev == POLYC__NONE, tail_end = V[w].next == POLYC__NONE;
    if (!head_end && !tail_end)
        return 0;
    float ax = V[v].x, ay = V[v].y, dx = V[w].x - ax, dy = V[w].y - ay;
    float len = sqrtf(dx * dx + dy * dy), lim = o->cfg->overlap_m;
    if (!(len > ZIP_RUN_M))
        return 0;
    int32_t n = (int32_t)ceilf(len / ZIP_STEP_M);
    for (int side = 0; side < 2; side++) {
        if (!(side ? tail_end : head_end))
            continue;
        /* samples from the end inwards while they are covered */
        int32_t k = 0;
        int32_t cover = POLYC__NONE;
        for (; k <= n; k++) {
            float u = (float)k / (float)n, f = side ? 1.0f - u : u;
            float d2;
            int32_t q = nearest_other(o, ax + f * dx, ay + f * dy, v, w, &d2);
            if (q == POLYC__NONE || d2 > lim * lim)
                break;
            if (k == 0)
                cover = q;
        }
        float run = (float)(k - 1) * len / (float)n; /* from the end to the last covered sample */
        if (k == 0 || k > n || run <= ZIP_SNAP_M || run > ZIP_RUN_M + lim)
            continue;
        const polyc__vertex *c = &V[cover], *d = &V[c->next];
        float ex = d->x - c->x, ey = d->y - c->y, el = sqrtf(ex * ex + ey * ey);
        if (!(el > 0.0f) || fabsf(ex * dx + ey * dy) < BAND_COS * el * len)
            continue;
        /* and seen from the same side (where the sides are known): the
         * faces of a partition 5 cm thick run within reach of each other */
        float nx, ny, mx, my;
        if (o->seg_side && (!seen_normal(o, v, &nx, &ny) || !seen_normal(o, cover, &mx, &my) ||
                            nx * mx + ny * my <= 0.0f))
            continue;
        float back = (run - polyc__minf(lim, run)) / len;
        if (!(back * len > ZIP_SNAP_M))
            continue;
        *t = side ? 1.0f - back : back;
        *tail = side;
        return 1;
    }
    return 0;
}

/* One pass over the segments edited since `since`. */
static int zip_pass(polyc__opt *o, uint32_t since)
{
    polyc__store *s = o->s;
    int zipped = 0;
    if (o->seg_side) {
        /* in an online round, from the region's points: taken from every
         * point, the sides cost each round in proportion to the whole map */
        int32_t np = polyc__region_points(o, polyc__in_region);
        const polyc__side_scratch sd = polyc__sides(o);
        polyc__find_sides(o, np >= 0 ? o->region_pt : NULL, np, sd.left_w, sd.right_w);
    }
    for (int32_t v = 0; v < s->v_high; v++) {
        for (int k = 0; k < POLYC__FIXES_PER_SEGMENT; k++) {
            if (s->v[v].line == POLYC__NONE || s->v[v].next == POLYC__NONE ||
                (k == 0 && !polyc__edited_since(o, v, since)))
                break;
            float t0, t1;
            int band = 0;
            float te;
            int tail;
            if (end_overshoot(o, v, &te, &tail)) {
                int32_t e = tail ? s->v[v].next : v;
                const polyc__vertex *a = &s->v[v], *b = &s->v[a->next];
                polyc__apply_move(o, e, a->x + te * (b->x - a->x), a->y + te * (b->y - a->y));
                zipped++;
                continue;
            }
            if (!longest_run(o, v, 0, &t0, &t1)) {
                if (!longest_run(o, v, 1, &t0, &t1))
                    break;
                band = 1;
            }
            /* the stretch goes from this segment or from the piece of map
             * along it (its own run there), whichever costs less */
            const polyc__vertex *V = s->v;
            int32_t w = V[v].next;
            float mx = V[v].x + 0.5f * (t0 + t1) * (V[w].x - V[v].x);
            float my = V[v].y + 0.5f * (t0 + t1) * (V[w].y - V[v].y);
            int32_t q;
            if (band) {
                float nx = 0.0f, ny = 0.0f;
                int32_t cand[BAND_CANDIDATES];
                seen_normal(o, v, &nx, &ny);
                int n_cand = band_candidates(o, v, nx, ny, two_sided_now(o, v), cand);
                q = band_other(o, mx, my, cand, n_cand);
            } else {
                float qd2;
                q = nearest_other(o, mx, my, v, w, &qd2);
            }
            float u0, u1;
            float d_here = drop_delta(o, v, t0, t1);
            if (q != POLYC__NONE && longest_run(o, q, band, &u0, &u1) &&
                drop_delta(o, q, u0, u1) < d_here) {
                if (!drop_stretch(o, q, u0, u1))
                    break;
            } else if (!drop_stretch(o, v, t0, t1)) {
                break;
            }
            zipped++;
        }
    }
    return zipped;
}

int polyc__op_zip(polyc__opt *o)
{
    if (!(o->cfg->overlap_m > 0.0f))
        return 0;
    /* a cut leaves the pieces it edited without a side until the sides are
     * found again: passes over what the last one edited, a few at most */
    int zipped = 0, n = 0;
    for (int pass = 0; pass < ZIP_PASSES && (pass == 0 || n > 0); pass++) {
        uint32_t since = o->zip_mark;
        o->zip_mark = ++o->touch_stamp;
        n = zip_pass(o, since);
        zipped += n;
    }
    return zipped;
}
