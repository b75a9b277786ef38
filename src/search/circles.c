/* circles.c - round things as circles (the paper's "more features than line
 * segments"): after the search, a polyline that goes round (or the pieces
 * of a ring the search left apart) whose own points a circle fits at a
 * lower BIC becomes a circle, three numbers against two a vertex. Takes:
 * the optimiser at its final map (points assigned to their nearest
 * segments, angle terms per vertex). Gives: the result's circle list
 * (ctx->flat.circ), an entry for each polyline a circle stands for, with
 * the circle's centre and radius, its first piece and how far that
 * polyline strays from it. The polylines stay as they are (what a caller
 * that knows only vertices reads), and so do the BIC and error the
 * statistics give: those of the polylines. */
#include "../optimize.h"
#include "round.h"

#include <math.h>

/* a circle is three numbers and a vertex two: in the BIC's units (log n a
 * vertex) a circle costs 1.5 */
#define CIRCLE_K 1.5f
#define FIT_ITERATIONS 16
#define FIT_STEP_DONE_M 1e-5f      /* a Gauss-Newton step this small ends the fit */

/* The sums a fit needs over one polyline's points. */
typedef struct circle_fit {
    float ox, oy;                  /* the points' weighted mean: the fit's origin */
    float cx, cy, r;               /* the circle, relative to the origin */
    float err_lines;               /* the points' cost against their segments */
    float err_circle;              /* their cost against the circle */
    float w;                       /* their endpoints */
} circle_fit;

/* The polylines one circle stands for: one that goes round, or the pieces
 * of a ring the search left apart; and the buckets that hold their points
 * (their vertices' box). */
#define MAX_PIECES 12
typedef struct pieces {
    int32_t line[MAX_PIECES];
    int32_t n;
    polyc__bucket_box bb;
} pieces;

static int in_pieces(const pieces *ps, int32_t l)
{
    for (int32_t k = 0; k < ps->n; k++)
        if (ps->line[k] == l)
            return 1;
    return 0;
}

static void pieces_box(const polyc__opt *o, pieces *ps)
{
    float lo_x = INFINITY, lo_y = INFINITY, hi_x = -INFINITY, hi_y = -INFINITY;
    for (int32_t m = 0; m < ps->n; m++) {
        const polyc__line *ln = &o->s->l[ps->line[m]];
        int32_t v = ln->head;
        for (int32_t k = 0; k < ln->count; k++, v = o->s->v[v].next) {
            lo_x = fminf(lo_x, o->s->v[v].x);
            lo_y = fminf(lo_y, o->s->v[v].y);
            hi_x = fmaxf(hi_x, o->s->v[v].x);
            hi_y = fmaxf(hi_y, o->s->v[v].y);
        }
    }
    ps->bb = polyc__box_buckets(o, lo_x, lo_y, hi_x, hi_y);
}

/* Every point i of the pieces' buckets whose nearest segment is one of
 * theirs. */
#define FOR_PIECE_POINTS(o, ps, i)                                                               \
    POLYC__FOR_BOX_POINTS(o, (ps)->bb, i)                                                         \
    if ((o)->d.pt_seg[i] != POLYC__NONE && in_pieces(ps, (o)->s->v[(o)->d.pt_seg[i]].line))

/* A point's cost against the fitted circle, capped as a segment's. */
static float circle_cost(const polyc__opt *o, const polyc__point *p, const circle_fit *f)
{
    float c = polyc__ring_cost(p, f->ox + f->cx, f->oy + f->cy, f->r);
    float cap = polyc__point_cap(o, p);
    return c < cap ? c : cap;
}

/* Solves the 3 x 3 system a x = b (Gaussian elimination with pivoting);
 * 0 when it is singular. */
static int solve3(float a[3][3], float b[3], float x[3])
{
    for (int c = 0; c < 3; c++) {
        int piv = c;
        for (int r = c + 1; r < 3; r++)
            if (fabsf(a[r][c]) > fabsf(a[piv][c]))
                piv = r;
        if (fabsf(a[piv][c]) < 1e-20f)
            return 0;
        for (int k = 0; k < 3; k++) {
            float t = a[c][k];
            a[c][k] = a[piv][k];
            a[piv][k] = t;
        }
        float t = b[c];
        b[c] = b[piv];
        b[piv] = t;
        for (int r = c + 1; r < 3; r++) {
            float m = a[r][c] / a[c][c];
            for (int k = c; k < 3; k++)
                a[r][k] -= m * a[c][k];
            b[r] -= m * b[c];
        }
    }
    for (int c = 2; c >= 0; c--) {
        float s = b[c];
        for (int k = c + 1; k < 3; k++)
            s -= a[c][k] * x[k];
        x[c] = s / a[c][c];
    }
    return 1;
}

/* Do the pieces' points near the circle (within support_m, as a point
 * supports a segment) hold it all round, no stretch of it longer than the
 * split gap without one (a circle drawn over a pillar's unseen
 * back would be a run without data)? Bins of at most half the gap round the
 * circle; the longest run of empty ones decides. */
#define COVER_BINS 1024
static int covered_round(const polyc__opt *o, const pieces *ps, const circle_fit *f)
{
    uint8_t hit[COVER_BINS] = {0};
    float gap = o->cfg->split_gap_m, need = 2.0f * 3.14159265f * f->r / (0.5f * gap);
    int32_t n = need > (float)COVER_BINS ? COVER_BINS : (need < 16.0f ? 16 : (int32_t)ceilf(need));
    float per_rad = (float)n / (2.0f * 3.14159265f), bin_m = 2.0f * 3.14159265f * f->r / (float)n;
    FOR_PIECE_POINTS(o, ps, i) {
        const polyc__point *p = &o->d.pts[i];
        float dx = (p->x - f->ox) - f->cx, dy = (p->y - f->oy) - f->cy;
        if (fabsf(sqrtf(dx * dx + dy * dy) - f->r) > o->d.support_m)
            continue; /* (a point holds the circle only near it, as a segment) */
        float a = polyc__atan2f(dy, dx) + 3.14159265f;
        int32_t k = (int32_t)(a * per_rad);
        hit[k < 0 ? 0 : (k >= n ? n - 1 : k)] = 1;
    }
    int32_t run = 0, longest = 0;
    for (int32_t k = 0; k < 2 * n; k++) { /* twice round: a run across bin 0 */
        run = hit[k % n] ? 0 : run + 1;
        longest = run > longest ? run : longest;
    }
    return longest < n && (float)longest * bin_m <= gap;
}

/* The circle of the pieces' points: an algebraic (Kasa) fit about their
 * mean to start, then Gauss-Newton on the true distances, which decide (the
 * algebraic fit leans inwards on short, noisy arcs). 0 when the points do
 * not make a circle. */
static int fit_circle(const polyc__opt *o, const pieces *ps, circle_fit *f)
{
    /* the mean about the first point, so that float keeps its resolution */
    float sw = 0.0f, sx = 0.0f, sy = 0.0f, x0 = 0.0f, y0 = 0.0f;
    int first = 1;
    f->err_lines = 0.0f;
    FOR_PIECE_POINTS(o, ps, i) {
        const polyc__point *p = &o->d.pts[i];
        if (first) {
            x0 = p->x;
            y0 = p->y;
            first = 0;
        }
        sw += p->w;
        sx += p->w * (p->x - x0);
        sy += p->w * (p->y - y0);
        f->err_lines += o->d.pt_cost[i];
    }
    if (!(sw > 0.0f))
        return 0;
    f->w = sw;
    f->ox = x0 + sx / sw;
    f->oy = y0 + sy / sw;
    /* Kasa: u^2 + v^2 + D u + E v + F = 0, about the mean (sums of u, v vanish) */
    float a[3][3] = {{0}}, b[3] = {0}, x[3];
    FOR_PIECE_POINTS(o, ps, i) {
        const polyc__point *p = &o->d.pts[i];
        float u = p->x - f->ox, v = p->y - f->oy, z = u * u + v * v;
        a[0][0] += p->w * u * u;
        a[0][1] += p->w * u * v;
        a[1][1] += p->w * v * v;
        b[0] -= p->w * u * z;
        b[1] -= p->w * v * z;
        b[2] -= p->w * z;
    }
    a[1][0] = a[0][1];
    a[2][2] = f->w;
    if (!solve3(a, b, x))
        return 0;
    f->cx = -0.5f * x[0];
    f->cy = -0.5f * x[1];
    float r2 = f->cx * f->cx + f->cy * f->cy - x[2];
    if (!(r2 > 0.0f))
        return 0;
    f->r = sqrtf(r2);
    for (int it = 0; it < FIT_ITERATIONS; it++) {
        float m[3][3] = {{0}}, g[3] = {0}, step[3];
        FOR_PIECE_POINTS(o, ps, i) {
            const polyc__point *p = &o->d.pts[i];
            float dx = (p->x - f->ox) - f->cx, dy = (p->y - f->oy) - f->cy;
            float d = sqrtf(dx * dx + dy * dy);
            if (d < 1e-9f)
                continue;
            float j[3] = {-dx / d, -dy / d, -1.0f}, e = d - f->r;
            for (int r = 0; r < 3; r++) {
                g[r] -= p->w * j[r] * e;
                for (int c = 0; c < 3; c++)
                    m[r][c] += p->w * j[r] * j[c];
            }
        }
        if (!solve3(m, g, step))
            return 0;
        f->cx += step[0];
        f->cy += step[1];
        f->r += step[2];
        if (!(f->r > 0.0f) || !isfinite(f->cx) || !isfinite(f->cy))
            return 0;
        if (fabsf(step[0]) + fabsf(step[1]) + fabsf(step[2]) < FIT_STEP_DONE_M)
            break;
    }
    f->err_circle = 0.0f;
    FOR_PIECE_POINTS(o, ps, i) f->err_circle += circle_cost(o, &o->d.pts[i], f);
    return 1;
}

/* How far line l strays from the circle: the largest gap between its
 * segments (ends and the point nearest the centre) and the circle. */
static float polygon_dev(const polyc__opt *o, int32_t l, const circle_fit *f)
{
    const polyc__line *ln = &o->s->l[l];
    int32_t segs = ln->closed == 1 ? ln->count : ln->count - 1, a = ln->head;
    float dev = 0.0f;
    for (int32_t k = 0; k < ln->count; k++) {
        float ax = o->s->v[a].x - f->ox - f->cx, ay = o->s->v[a].y - f->oy - f->cy;
        dev = fmaxf(dev, fabsf(sqrtf(ax * ax + ay * ay) - f->r));
        int32_t b = o->s->v[a].next;
        if (k < segs) {
            float bx = o->s->v[b].x - f->ox - f->cx, by = o->s->v[b].y - f->oy - f->cy;
            float ex = bx - ax, ey = by - ay, l2 = ex * ex + ey * ey;
            float t = l2 > 0.0f ? -(ax * ex + ay * ey) / l2 : 0.0f;
            t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
            float fx = ax + t * ex, fy = ay + t * ey;
            dev = fmaxf(dev, fabsf(sqrtf(fx * fx + fy * fy) - f->r));
        }
        a = b;
    }
    return dev;
}

/* Does every other polyline's segment keep CLEAR_M off the circle (no
 * crossing, no touch: what the polyline kept off them, the circle must)?
 * The segments in the buckets round the circle, R wider. */
#define CLEAR_M 0.01f
static int clear_of_others(const polyc__opt *o, const pieces *ps, const circle_fit *f)
{
    float cx = f->ox + f->cx, cy = f->oy + f->cy, reach = f->r + CLEAR_M;
    polyc__bucket_box bb;
    polyc__bucket_xy(&o->h, cx - reach - o->R, cy - reach - o->R, &bb.x0, &bb.y0);
    polyc__bucket_xy(&o->h, cx + reach + o->R, cy + reach + o->R, &bb.x1, &bb.y1);
    for (int32_t by = bb.y0; by <= bb.y1; by++)
        for (int32_t bx = bb.x0; bx <= bb.x1; bx++)
            for (int32_t e = o->h.seg_head[by * o->h.bx + bx]; e != POLYC__NONE; e = o->h.entries[e].next) {
                int32_t sg = o->h.entries[e].seg;
                const polyc__vertex *a = &o->s->v[sg], *b = &o->s->v[a->next];
                if (in_pieces(ps, a->line))
                    continue;
                float ax = a->x - cx, ay = a->y - cy, ex = b->x - a->x, ey = b->y - a->y;
                float l2 = ex * ex + ey * ey;
                float t = l2 > 0.0f ? -(ax * ex + ay * ey) / l2 : 0.0f;
                t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
                float nx = ax + t * ex, ny = ay + t * ey, bx2 = b->x - cx, by2 = b->y - cy;
                float near = sqrtf(nx * nx + ny * ny);
                float far = fmaxf(sqrtf(ax * ax + ay * ay), sqrtf(bx2 * bx2 + by2 * by2));
                if (near <= f->r + CLEAR_M && far >= f->r - CLEAR_M)
                    return 0;
            }
    return 1;
}

/* A polyline that may be a circle: closed, or open with its ends nearer
 * than the split gap (a ring whose ends the data do not hold apart), of
 * three vertices or more. */
static int goes_round(const polyc__opt *o, const polyc__line *ln)
{
    if (ln->closed == POLYC__NONE || ln->count < 3)
        return 0;
    if (ln->closed == 1)
        return 1;
    const polyc__vertex *a = &o->s->v[ln->head], *b = &o->s->v[ln->tail];
    float dx = a->x - b->x, dy = a->y - b->y;
    return dx * dx + dy * dy < o->cfg->split_gap_m * o->cfg->split_gap_m;
}

/* The BIC's change if the pieces become their circle f (< 0: the circle is
 * better); 1e30 when it is not allowed (its points leave a stretch of it
 * empty, or another segment comes near). */
static float pieces_delta(const polyc__opt *o, const pieces *ps, const circle_fit *f)
{
    float angle = 0.0f, vertices = 0.0f;
    for (int32_t m = 0; m < ps->n; m++) {
        const polyc__line *ln = &o->s->l[ps->line[m]];
        int32_t v = ln->head;
        for (int32_t k = 0; k < ln->count; k++, v = o->s->v[v].next)
            angle += o->acost[v];
        vertices += (float)ln->count;
    }
    float delta = o->cfg->alpha * (f->err_circle - f->err_lines - o->cfg->gamma * angle) +
                  (CIRCLE_K - vertices) * o->d.log_n;
    if (!(delta < 0.0f) || !covered_round(o, ps, f) || !clear_of_others(o, ps, f))
        return 1e30f;
    return delta;
}

/* The circle into the result, once for each of its pieces (the first of
 * them written as the circle, polyc_get_circle's same_as). 0 when the list
 * is full. */
static int keep_circle(const polyc__opt *o, polyc__flat *res, const pieces *ps, const circle_fit *f)
{
    if (res->circ_n + (uint32_t)ps->n > res->circ_cap)
        return 0;
    for (int32_t m = 0; m < ps->n; m++) {
        polyc__circle *c = &res->circ[res->circ_n++];
        c->line_id = o->s->l[ps->line[m]].id;
        c->first_id = o->s->l[ps->line[0]].id;
        c->cx = f->ox + f->cx;
        c->cy = f->oy + f->cy;
        c->r = f->r;
        c->dev = polygon_dev(o, ps->line[m], f);
    }
    return 1;
}

static int is_circle(const polyc__flat *res, uint32_t id)
{
    for (uint32_t c = 0; c < res->circ_n; c++)
        if (res->circ[c].line_id == id)
            return 1;
    return 0;
}

/* A ring the search left in pieces (a large circle's chords, whose ends
 * stayed more than the merge distance apart): from an open polyline whose
 * points a circle of at most RING_MAX_R fits, the other open polylines
 * whose every vertex lies within RING_NEAR_M of that circle join it. */
#define RING_MAX_R 12.0f
#define RING_NEAR_M 0.10f
static int ring_pieces(const polyc__opt *o, const polyc__flat *res, int32_t l, const circle_fit *f,
                       pieces *ps)
{
    float cx = f->ox + f->cx, cy = f->oy + f->cy;
    ps->line[0] = l;
    ps->n = 1;
    polyc__bucket_box bb = polyc__box_buckets(o, cx - f->r, cy - f->r, cx + f->r, cy + f->r);
    for (int32_t by = bb.y0; by <= bb.y1; by++)
        for (int32_t bx = bb.x0; bx <= bb.x1; bx++)
            for (int32_t e = o->h.seg_head[by * o->h.bx + bx]; e != POLYC__NONE; e = o->h.entries[e].next) {
                int32_t m = o->s->v[o->h.entries[e].seg].line;
                const polyc__line *ln = &o->s->l[m];
                if (in_pieces(ps, m) || ln->closed != 0 || is_circle(res, ln->id) || ps->n >= MAX_PIECES)
                    continue;
                int on = 1;
                int32_t v = ln->head;
                for (int32_t k = 0; k < ln->count && on; k++, v = o->s->v[v].next) {
                    float dx = o->s->v[v].x - cx, dy = o->s->v[v].y - cy;
                    on = fabsf(sqrtf(dx * dx + dy * dy) - f->r) < RING_NEAR_M;
                }
                if (on)
                    ps->line[ps->n++] = m;
            }
    if (ps->n < 2)
        return 0;
    pieces_box(o, ps);
    return 1;
}

void polyc__circles_select(polyc__opt *o)
{
    polyc__flat *res = &o->ctx->flat;
    const polyc__store *s = o->s;
    res->circ_n = 0;
    if ((o->cfg->flags & POLYC_FLAG_NO_ARCS) || !res->circ)
        return;
    /* a polyline that goes round */
    for (int32_t l = 0; l < s->l_high; l++) {
        pieces ps = {{l}, 1, {0, 0, 0, 0}};
        circle_fit f;
        if (!goes_round(o, &s->l[l]))
            continue;
        pieces_box(o, &ps);
        if (fit_circle(o, &ps, &f) && pieces_delta(o, &ps, &f) < 0.0f && !keep_circle(o, res, &ps, &f))
            return;
    }
    /* the pieces of a ring */
    for (int32_t l = 0; l < s->l_high; l++) {
        const polyc__line *ln = &s->l[l];
        pieces one = {{l}, 1, {0, 0, 0, 0}}, ps;
        circle_fit f;
        if (ln->closed != 0 || ln->count < 2 || is_circle(res, ln->id))
            continue;
        pieces_box(o, &one);
        if (!fit_circle(o, &one, &f) || !(f.r <= RING_MAX_R) || !ring_pieces(o, res, l, &f, &ps) ||
            !fit_circle(o, &ps, &f) || !(pieces_delta(o, &ps, &f) < 0.0f))
            continue;
        if (!keep_circle(o, res, &ps, &f))
            return;
    }
}
