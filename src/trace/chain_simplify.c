/* chain_simplify.c - a single scan's chain simplified: Douglas-Peucker to
 * within the tolerance (a grid cell), then kept vertices dropped bottom-up,
 * cheapest first, while the BIC falls. Takes: a chain of the scan's hits
 * (scan_chains.c). Gives: its vertices, marked in c->keep. */
#include "../scan_chains.h"

#include <math.h>

/* Douglas-Peucker over the hits of beams [a, b], both hits: marks vertices
 * in c->keep. Without a stack (fixed memory): each pass splits every span
 * whose farthest point is beyond the tolerance, until none is. */
void polyc__chain_simplify(chains *c, int32_t a, int32_t b)
{
    for (int32_t i = a; i <= b; i++)
        c->keep[i] = 0;
    c->keep[a] = c->keep[b] = 1;
    float tol2 = c->tol * c->tol;
    int split = 1;
    while (split) {
        split = 0;
        int32_t i = a;
        while (i < b) {
            int32_t j = i + 1, far = -1;
            float worst = tol2;
            while (!c->keep[j])
                j++;
            for (int32_t k = i + 1; k < j; k++) {
                if (!polyc__chain_member(c, k))
                    continue;
                float d = polyc__seg_dist2f(&c->xy[2 * k], &c->xy[2 * i], &c->xy[2 * j]);
                if (d > worst) {
                    worst = d;
                    far = k;
                }
            }
            if (far >= 0) {
                c->keep[far] = 1;
                split = 1;
            }
            i = j;
        }
    }
}

/* The line fitted (total least squares) to the hits of beams [i, j]: the
 * sum of their squared distances to it is the scatter's smaller eigenvalue,
 * from one pass of sums taken about the first hit. */
typedef struct span_fit {
    float x0, y0, n, sx, sy, xx, xy, yy; /* xx, xy, yy: central */
} span_fit;

static float span_error(const chains *c, int32_t i, int32_t j, span_fit *f)
{
    f->x0 = (float)c->xy[2 * i];
    f->y0 = (float)c->xy[2 * i + 1];
    float n = 0.0f, sx = 0.0f, sy = 0.0f, sxx = 0.0f, sxy = 0.0f, syy = 0.0f;
    for (int32_t k = i; k <= j; k++)
        if (polyc__chain_member(c, k)) {
            float x = (float)c->xy[2 * k] - f->x0, y = (float)c->xy[2 * k + 1] - f->y0;
            n += 1.0f;
            sx += x;
            sy += y;
            sxx += x * x;
            sxy += x * y;
            syy += y * y;
        }
    f->n = n;
    f->sx = sx;
    f->sy = sy;
    f->xx = sxx - sx * sx / n;
    f->xy = sxy - sx * sy / n;
    f->yy = syy - sy * sy / n;
    float half = 0.5f * (f->xx - f->yy), r = sqrtf(half * half + f->xy * f->xy);
    float e = 0.5f * (f->xx + f->yy) - r;
    return e > 0.0f ? e : 0.0f;
}

/* The largest distance of a hit of beams [i, j] to their fitted line f
 * along its own beam, squared: a segment on that line stands that far in
 * front of or behind the return (at most 20 times its distance across). */
static float along_worst2(const chains *c, int32_t i, int32_t j, const span_fit *f)
{
    float a = 0.5f * polyc__atan2f(2.0f * f->xy, f->xx - f->yy), nx = -polyc__sinf(a), ny = polyc__cosf(a);
    float cx = f->x0 + f->sx / f->n, cy = f->y0 + f->sy / f->n, worst = 0.0f;
    for (int32_t k = i; k <= j; k++)
        if (polyc__chain_member(c, k)) {
            float x = (float)c->xy[2 * k], y = (float)c->xy[2 * k + 1];
            float d = (x - cx) * nx + (y - cy) * ny;
            float bx = x - (float)c->ox, by = y - (float)c->oy, b2 = bx * bx + by * by;
            float cosb = bx * nx + by * ny; /* times the range */
            float e = d * d * b2 / (cosb * cosb > 0.0025f * b2 ? cosb * cosb : 0.0025f * b2);
            worst = e > worst ? e : worst;
        }
    return worst;
}

static int32_t kept_after(const chains *c, int32_t j)
{
    do
        j++;
    while (!c->keep[j]);
    return j;
}

static int32_t kept_before(const chains *c, int32_t j)
{
    do
        j--;
    while (!c->keep[j]);
    return j;
}

/* The BIC change of dropping kept vertex j, whose kept neighbours are i and
 * k: alpha times the error the line over [i, k] adds to the lines over
 * [i, j] and [j, k], less the log n a vertex costs; +inf if that line
 * would stand more than the ray tolerance from a return along its beam. */
static float drop_cost(const chains *c, int32_t i, int32_t j, int32_t k)
{
    span_fit merged, part;
    float gain = span_error(c, i, k, &merged) - span_error(c, i, j, &part) -
                  span_error(c, j, k, &part);
    gain = (float)c->alpha * gain - (float)c->log_n;
    float limit = POLYC__RAY_TOLERANCE_M;
    if (gain < 0.0f && along_worst2(c, i, k, &merged) > limit * limit)
        return INFINITY;
    return (float)gain;
}

/* Bottom-up over the vertices Douglas-Peucker kept on beams [a, b]: drops
 * the one whose line pair the BIC pays least for, while dropping lowers
 * the BIC and the merged line keeps every return within the ray tolerance
 * along its beam. Douglas-Peucker alone keeps a vertex wherever the range
 * noise puts a return a cell off the chord, and the search's removals (one
 * vertex at a time, the chord of its neighbours, the beams as constraints)
 * leave many of them: from this start single scans end with a lower BIC,
 * fewer vertices, and in less time. */
void polyc__chain_merge_spans(chains *c, int32_t a, int32_t b)
{
    int32_t inner = 0;
    for (int32_t j = kept_after(c, a); j < b; j = kept_after(c, j)) {
        c->cost[j] = drop_cost(c, kept_before(c, j), j, kept_after(c, j));
        inner++;
    }
    while (inner > 0) {
        int32_t best = -1;
        for (int32_t j = kept_after(c, a); j < b; j = kept_after(c, j))
            if (best < 0 || c->cost[j] < c->cost[best])
                best = j;
        if (!(c->cost[best] < 0.0f))
            break;
        int32_t i = kept_before(c, best), k = kept_after(c, best);
        c->keep[best] = 0;
        inner--;
        if (i > a)
            c->cost[i] = drop_cost(c, kept_before(c, i), i, k);
        if (k < b)
            c->cost[k] = drop_cost(c, i, k, kept_after(c, k));
    }
}

