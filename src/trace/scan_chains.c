/* scan_chains.c - initial polylines of a single scan from its beam order
 * (a departure from the paper, which traces the grid's contour).
 * Takes: the context's one scan. Gives: polylines in the store, one per
 * chain of neighbouring endpoints, simplified to within a grid cell, then
 * bottom-up while the BIC falls.
 *
 * Why: one scan leaves sparse contour cells (a beam spacing apart at range,
 * wider at grazing angles), and the grid trace cannot tell such a gap from a
 * depth jump by distance alone; the beam order can. Two consecutive
 * endpoints belong to one surface unless the second lies farther than a
 * surface seen at LAMBDA or more to the beams would put it (the adaptive
 * breakpoint rule of Borges and Aldon, 2004). Beams whose return lies in
 * front of the link between two endpoints (posts of a railing, a chair in
 * front of a wall) do not break it: several chains can be open at once, and
 * an endpoint joins the most recent one it links to. */
#include "../scan_chains.h"

#include <math.h>

/* the external definitions of scan_chains.h's inline functions (C99: used
 * where a caller does not inline them, as at -Os) */
extern inline float polyc__seg_dist2f(const float *p, const float *a, const float *b);
extern inline int polyc__chain_has_point(const chains *c, int32_t i);
extern inline int polyc__chain_member(const chains *c, int32_t i);

#define LAMBDA_RAD 0.1745f   /* 10 degrees: flatter surfaces count as jumps */
#define GRAZING_REACH 4.0f  /* ... times farther if the chain goes straight on */
#define COS2_TURN 0.9698f    /* cos^2 of 10 degrees: "straight on" */
#define MAX_SKIP_NEAR 2      /* a chain bridges one beam without return, */
#define MAX_SKIP 8           /* or seven going straight on (grazing walls) */

#define MAX_OPEN (MAX_SKIP + 1) /* chains whose last hit is that recent */


/* the scratch for a scan of n beams */
static int chains_carve(polyc__arena *a, chains *c, int32_t n)
{
    c->xy = polyc__alloc(a, (size_t)n + 1, 2 * sizeof(float));
    c->turned = polyc__alloc(a, (size_t)n + 1, sizeof(float));
    c->keep = polyc__alloc(a, (size_t)n + 1, 1);
    c->cost = polyc__alloc(a, (size_t)n + 1, sizeof(float));
    c->chain_of = polyc__alloc(a, (size_t)n + 1, 1);
    return c->xy && c->turned && c->keep && c->cost && c->chain_of;
}

void polyc__chains_reserve(polyc__arena *a, const polyc_limits *lim)
{
    chains c;
    polyc__store_reserve(a, lim);
    size_t after_store = a->used;
    chains_carve(a, &c, (int32_t)lim->max_beams);
    a->used = after_store;
}

static int is_hit(const polyc__scan *s, float r)
{
    return r == r && r >= s->min_m && r < s->max_m;
}

static float dist2(const chains *c, int32_t i, int32_t j)
{
    float dx = c->xy[2 * j] - c->xy[2 * i], dy = c->xy[2 * j + 1] - c->xy[2 * i + 1];
    return dx * dx + dy * dy;
}

/* a -> b -> c goes straight on (turns less than 10 degrees) */
static int straight(const chains *c, int32_t a, int32_t b, int32_t d)
{
    float ux = c->xy[2 * b] - c->xy[2 * a], uy = c->xy[2 * b + 1] - c->xy[2 * a + 1];
    float wx = c->xy[2 * d] - c->xy[2 * b], wy = c->xy[2 * d + 1] - c->xy[2 * b + 1];
    float dot = ux * wx + uy * wy;
    return dot > 0.0f && dot * dot >= COS2_TURN * (ux * ux + uy * uy) * (wx * wx + wy * wy);
}

static polyc_status append(chains *c, int32_t line, float x, float y)
{
    if (polyc__vertex_append(&c->ctx->store, line, x, y) == POLYC__NONE)
        return polyc__fail(c->ctx, POLYC_ERR_NOMEM, "too many vertices for limits.max_vertices");
    return POLYC_OK;
}

/* Half a beam spacing at the endpoint of beam i: an end reaches that far
 * past its hit, so that its beam meets the map and the next beam does not.
 * (A floor of half a cell would make near returns, where a cell spans
 * several beams, block the neighbouring beams that saw through, whose ray
 * errors then swamp the scan's.) */
static float half_spacing(const chains *c, int32_t i)
{
    float dx = c->xy[2 * i] - c->ox, dy = c->xy[2 * i + 1] - c->oy;
    return 0.5f * sqrtf(dx * dx + dy * dy) * c->step;
}

/* A line fitted to the hits of beams [i, j]: centroid and unit direction
 * (total least squares: the direction of the larger eigenvector). Hits
 * that all lie within two cells along and across the beams (a chair leg
 * near the sensor, where the range noise is larger than the beam spacing)
 * say nothing about the direction: their line runs across the beams. */
typedef struct fitted {
    float cx, cy, dx, dy;
} fitted;

static void fit(const chains *c, int32_t i, int32_t j, fitted *f)
{
    float sx = 0.0f, sy = 0.0f, n = 0.0f;
    for (int32_t k = i; k <= j; k++)
        if (polyc__chain_member(c, k)) {
            sx += c->xy[2 * k];
            sy += c->xy[2 * k + 1];
            n += 1.0f;
        }
    f->cx = sx / n;
    f->cy = sy / n;
    float xx = 0.0f, xy = 0.0f, yy = 0.0f;
    for (int32_t k = i; k <= j; k++)
        if (polyc__chain_member(c, k)) {
            float ex = c->xy[2 * k] - f->cx, ey = c->xy[2 * k + 1] - f->cy;
            xx += ex * ex;
            xy += ex * ey;
            yy += ey * ey;
        }
    float a = 0.5f * polyc__atan2f(2.0f * xy, xx - yy);
    f->dx = polyc__cosf(a);
    f->dy = polyc__sinf(a);
    float bx = f->cx - c->ox, by = f->cy - c->oy, r = sqrtf(bx * bx + by * by);
    if (r <= 0.0f)
        return;
    bx /= r;
    by /= r;
    float lo = INFINITY, hi = -INFINITY, across = 0.0f, span = 2.0f * c->ctx->cfg.cell_m;
    for (int32_t k = i; k <= j; k++)
        if (polyc__chain_member(c, k)) {
            float ex = c->xy[2 * k] - c->ox, ey = c->xy[2 * k + 1] - c->oy;
            float along = ex * bx + ey * by, side = fabsf(ey * bx - ex * by);
            lo = polyc__minf(lo, along);
            hi = polyc__maxf(hi, along);
            across = polyc__maxf(across, side);
        }
    if (hi - lo <= span && 2.0f * across <= span) {
        f->dx = -by;
        f->dy = bx;
    }
}

static void project(const fitted *f, const float *p, float *x, float *y)
{
    float t = (p[0] - f->cx) * f->dx + (p[1] - f->cy) * f->dy;
    *x = f->cx + t * f->dx;
    *y = f->cy + t * f->dy;
}

/* Where the two fitted lines meet; 0 if they are within 10 degrees of
 * parallel. */
static int meet(const fitted *f, const fitted *g, float *x, float *y)
{
    float den = f->dx * g->dy - f->dy * g->dx;
    if (fabsf(den) < POLYC__CORNER_SIN)
        return 0;
    float t = ((g->cx - f->cx) * g->dy - (g->cy - f->cy) * g->dx) / den;
    *x = f->cx + t * f->dx;
    *y = f->cy + t * f->dy;
    return 1;
}

/* The end of a chain on its fitted line f, at beam i's hit: where beam i
 * crosses the line, so that the beam meets the polyline (the hit's
 * projection can lie on the wrong side of the beam when the range noise is
 * as large as the beam spacing, as near the sensor). Returns 0, with the
 * projection, if the beam runs within 3 degrees of the line or crosses it
 * more than 50 cm from it: there the beam does not meet the line near its
 * hit at all. */
static int end_on_line(const chains *c, const fitted *f, int32_t i, float *x, float *y)
{
    const float *p = &c->xy[2 * i];
    project(f, p, x, y);
    float bx = p[0] - c->ox, by = p[1] - c->oy, r = sqrtf(bx * bx + by * by);
    if (r <= 0.0f)
        return 0;
    bx /= r;
    by /= r;
    float den = bx * f->dy - by * f->dx; /* sin(beam, line) */
    if (fabsf(den) < 0.05f)
        return 0;
    float t = ((f->cx - c->ox) * f->dy - (f->cy - c->oy) * f->dx) / den;
    float qx = c->ox + t * bx, qy = c->oy + t * by;
    if (t > 0.0f && (qx - *x) * (qx - *x) + (qy - *y) * (qy - *y) <= 0.25f) {
        *x = qx;
        *y = qy;
        return 1;
    }
    return 0;
}

/* (x, y) moved outwards from (ix, iy) by half a beam spacing at beam i */
static void extend(const chains *c, int32_t i, float ix, float iy, float *x, float *y)
{
    float dx = *x - ix, dy = *y - iy, len = sqrtf(dx * dx + dy * dy);
    if (len <= 0.0f)
        return;
    float m = half_spacing(c, i) / len;
    *x += dx * m;
    *y += dy * m;
}

/* The end of a chain at beam i on its fitted line f, (ix, iy) the chain's
 * side of it: appended first (head) or last (tail). Where beam i meets the
 * line near its hit, one vertex there, half a beam spacing further out.
 * Where the beam runs along the line, a stub across the beam through its
 * hit, half a spacing to each side: the line's end would stand where the
 * beam passes it by. */
static polyc_status append_end(chains *c, int32_t line, const fitted *f, int32_t i, float ix,
                               float iy, int head)
{
    float x, y;
    if (end_on_line(c, f, i, &x, &y)) {
        extend(c, i, ix, iy, &x, &y);
        return append(c, line, x, y);
    }
    const float *p = &c->xy[2 * i];
    float bx = p[0] - c->ox, by = p[1] - c->oy, r = sqrtf(bx * bx + by * by);
    float h = half_spacing(c, i) / (r > 0.0f ? r : 1.0f);
    float nx = -by * h, ny = bx * h; /* across the beam, half a spacing long */
    if ((ix - p[0]) * nx + (iy - p[1]) * ny < 0.0f) {
        nx = -nx;
        ny = -ny;
    }
    /* (p + n on the chain's side, p - n the stub's free end) */
    polyc_status st = append(c, line, head ? p[0] - nx : p[0] + nx, head ? p[1] - ny : p[1] + ny);
    if (st != POLYC_OK)
        return st;
    return append(c, line, head ? p[0] + nx : p[0] - nx, head ? p[1] + ny : p[1] - ny);
}

/* The chain of beams [a, b] (both hits) as a polyline: Douglas-Peucker
 * picks the vertices, a line is fitted to the hits between each two of
 * them, and each inner vertex goes where its two lines meet (near its hit;
 * else onto the lines), each end onto its line. The ends reach half a beam
 * spacing past the end hits, so that the end beams meet the map; a lone hit
 * becomes a segment across its beam, one beam spacing long. */
static polyc_status emit(chains *c, int32_t a, int32_t b, int32_t *out)
{
    polyc__store *s = &c->ctx->store;
    int32_t line = polyc__line_new(s);
    if (line == POLYC__NONE)
        return polyc__fail(c->ctx, POLYC_ERR_NOMEM, "too many polylines for limits.max_vertices");
    *out = line;
    if (a == b) {
        float x = c->xy[2 * a], y = c->xy[2 * a + 1], dx = x - c->ox, dy = y - c->oy;
        float len = sqrtf(dx * dx + dy * dy);
        float h = half_spacing(c, a) / (len > 0.0f ? len : 1.0f);
        polyc_status st = append(c, line, x + dy * h, y - dx * h);
        return st != POLYC_OK ? st : append(c, line, x - dy * h, y + dx * h);
    }
    polyc__chain_simplify(c, a, b);
    polyc__chain_merge_spans(c, a, b);
    fitted before, after;
    int32_t i = a, j = a + 1;
    while (!c->keep[j])
        j++;
    fit(c, i, j, &after);
    float x, y, ex, ey;
    project(&after, &c->xy[2 * j], &ex, &ey);
    polyc_status st = append_end(c, line, &after, a, ex, ey, 1);
    while (st == POLYC_OK && j < b) {
        /* inner vertex j between spans [i, j] and [j, k] */
        int32_t k = j + 1;
        while (!c->keep[k])
            k++;
        before = after;
        fit(c, j, k, &after);
        const float *p = &c->xy[2 * j];
        float far = 2.0f * c->tol;
        if (!meet(&before, &after, &x, &y) ||
            (x - p[0]) * (x - p[0]) + (y - p[1]) * (y - p[1]) > far * far) {
            float x1, y1, x2, y2;
            project(&before, p, &x1, &y1);
            project(&after, p, &x2, &y2);
            x = 0.5f * (x1 + x2);
            y = 0.5f * (y1 + y2);
        }
        st = append(c, line, x, y);
        i = j;
        j = k;
    }
    if (st != POLYC_OK)
        return st;
    project(&after, &c->xy[2 * i], &ex, &ey);
    return append_end(c, line, &after, b, ex, ey, 0);
}

/* An open chain. Its slot (1..MAX_OPEN) marks its beams in chain_of: a
 * slot is free again once its chain is emitted, and a chain that takes it
 * later starts past that chain's last beam, so a slot names one chain
 * within any chain's span. */
typedef struct open_chain {
    int32_t first, last, prev;     /* beams: first and last hit, the hit before last */
    uint8_t slot;
} open_chain;

/* Whether the hit of beam i continues chain h. The beams between them must
 * have no return or one in front of the link (an occluder); one behind it
 * saw through. Then the breakpoint rule over the angle between them (at
 * most one beam without return), or, on a wall seen at a grazing angle and
 * with no occluder between, three hits in a line within GRAZING_REACH
 * times that reach. */
static int links(const chains *c, const open_chain *h, int32_t i, int32_t n)
{
    int32_t last = h->last;
    if (i - last > MAX_SKIP)
        return 0;
    float lx = c->xy[2 * last], ly = c->xy[2 * last + 1];
    float dx = c->xy[2 * i] - lx, dy = c->xy[2 * i + 1] - ly;
    int missing = 0, occluders = 0;
    for (int32_t k = last + 1; k < i; k++) {
        if (!polyc__chain_has_point(c, k)) {
            missing++;
            continue;
        }
        occluders++;
        /* where beam k crosses the link: the return must be in front */
        float bx = c->xy[2 * k] - c->ox, by = c->xy[2 * k + 1] - c->oy;
        float qx = lx - c->ox, qy = ly - c->oy;
        float den = bx * dy - by * dx;  /* |beam| x link */
        if (den == 0.0f)
            return 0;
        float t = (qx * dy - qy * dx) / den; /* in units of the return's range */
        if (!(t > 1.0f + (float)POLYC__RAY_TOLERANCE_M / c->range[k]))
            return 0;
    }
    float dphi = c->step; /* each beam between widens the reach by a step */
    float reach = (float)(i - last) * c->range[last] * polyc__sinf(dphi) /
                      polyc__sinf(polyc__maxf(LAMBDA_RAD - dphi, 0.01f)) +
                  2.0f * c->ctx->cfg.cell_m;
    float d2 = dx * dx + dy * dy;
    if (missing < MAX_SKIP_NEAR && d2 <= reach * reach)
        return 1;
    /* (not behind occluders: hits receding along the beams behind a near
     * object, three of them in a line, are not a wall seen at a grazing
     * angle; such a link ran a metre along a beam) */
    if (occluders > 0 || d2 > GRAZING_REACH * GRAZING_REACH * reach * reach)
        return 0;
    /* a wall seen at a grazing angle: three points in a line, the chain's
     * last two or the two with the next hit */
    int32_t next = i + 1;
    while (next < n && next - i <= MAX_SKIP && !polyc__chain_has_point(c, next))
        next++;
    return (h->prev >= 0 && straight(c, h->prev, last, i)) ||
           (next < n && next - i <= MAX_SKIP && straight(c, last, i, next) &&
            dist2(c, i, next) <= GRAZING_REACH * GRAZING_REACH * reach * reach);
}

/* A scan over a full turn has no first beam: the chains start after its
 * widest gap between returns (the most beams without one, then the
 * longest jump), so that no wall is cut where the beam list wraps. The
 * beam to start at (*full: the scan is a full turn); 0 for a scan over
 * less than a turn. */
static int32_t seam(const polyc__scan *s, const float *r, int *full)
{
    int32_t n = (int32_t)s->count;
    *full = n >= 3 && (float)n * fabsf(s->step_rad) >= 6.2831853f - 0.5f * fabsf(s->step_rad);
    if (!*full)
        return 0;
    int32_t first = -1, prev = -1, best = 0;
    float best_gap = -1.0f;
    for (int32_t k = 0; k <= n; k++) {
        int32_t i = k % n;
        if (!is_hit(s, r[i]) || (k == n && first < 0))
            continue;
        if (k == n && i != first)
            break;
        if (prev >= 0) {
            int32_t beams = (i - prev + n) % n;
            float a = (float)beams * s->step_rad;
            float jump = r[i] * r[i] + r[prev] * r[prev] - 2.0f * r[i] * r[prev] * polyc__cosf(a);
            float gap = (float)beams * 1e6f + jump; /* (beams first, then the jump) */
            if (gap > best_gap) {
                best_gap = gap;
                best = i;
            }
        }
        if (first < 0)
            first = i;
        prev = i;
        if (k == n)
            break;
    }
    return best;
}

/* A full turn whose chain ran round it whole (first and last returns of
 * the turn in one chain that links across the seam) is closed: line is its
 * polyline, a and b its first and last beams. */
static void close_ring(chains *c, int32_t line, int32_t a, int32_t b, int32_t n)
{
    polyc__store *s = &c->ctx->store;
    if (a != 0 || s->l[line].count < 3 || !polyc__chain_has_point(c, n - 1) || b != n - 1)
        return;
    float reach = c->range[b] * polyc__sinf(c->step) / polyc__sinf(LAMBDA_RAD - c->step) +
                  2.0f * c->ctx->cfg.cell_m;
    if (dist2(c, b, a) > reach * reach)
        return;
    polyc__line_close(s, line);
}

polyc_status polyc__chains_build(polyc_ctx *ctx)
{
    if (!polyc__store_init(&ctx->arena, &ctx->store, polyc__max_vertices(&ctx->lim)))
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the polylines");
    if (ctx->scan_count == 0)
        return POLYC_OK;
    polyc_status st;
    size_t after_store = ctx->arena.used; /* scratch released at the end */
    const polyc__scan *s = &ctx->scans[0];
    int32_t n = (int32_t)s->count;
    chains c;
    c.ctx = ctx;
    if (!chains_carve(&ctx->arena, &c, n))
        return polyc__fail(ctx, POLYC_ERR_NOMEM, "no room for the scan's chains");
    c.ox = s->x_m;
    c.oy = s->y_m;
    c.step = fabsf(s->step_rad);
    c.tol = ctx->cfg.cell_m;
    c.cur = 0;
    const float *r = &ctx->ranges[s->first];
    int full;
    int32_t off = seam(s, r, &full);
    for (int32_t j = 0; j < n; j++)
        c.turned[j] = r[(j + off) % n];
    c.range = c.turned;
    r = c.turned;
    c.alpha = ctx->cfg.alpha;
    int32_t returns = 0;
    for (int32_t i = 0; i < n; i++)
        returns += is_hit(s, r[i]);
    c.log_n = polyc__logf(returns > 1 ? (float)returns : 1.0f);
    for (int32_t i = 0; i < n; i++) {
        float a = s->theta_rad + s->start_rad + (float)((i + off) % n) * s->step_rad;
        c.chain_of[i] = 0;
        c.xy[2 * i] = c.xy[2 * i + 1] = NAN;
        if (is_hit(s, r[i])) {
            float sn, cs;
            polyc__sincosf(a, &sn, &cs);
            c.xy[2 * i] = c.ox + r[i] * cs;
            c.xy[2 * i + 1] = c.oy + r[i] * sn;
        }
    }
    /* chains: hits linked to the last hit of an open chain */
    open_chain open[MAX_OPEN];
    int n_open = 0;
    uint32_t slots_used = 0; /* bit s - 1: slot s */
    for (int32_t i = 0; i <= n; i++) {
        /* chains that no later hit can join any more go to the store */
        for (int k = 0; k < n_open; k++)
            if (i == n || i - open[k].last > MAX_SKIP) {
                c.cur = open[k].slot;
                int32_t line;
                if ((st = emit(&c, open[k].first, open[k].last, &line)) != POLYC_OK)
                    return st;
                if (full)
                    close_ring(&c, line, open[k].first, open[k].last, n);
                slots_used &= ~(1u << (open[k].slot - 1));
                open[k--] = open[--n_open];
            }
        if (i == n || !polyc__chain_has_point(&c, i))
            continue;
        /* the open chain with the most recent last hit that i links to */
        int join = -1;
        for (int k = 0; k < n_open; k++)
            if ((join < 0 || open[k].last > open[join].last) && links(&c, &open[k], i, n))
                join = k;
        if (join < 0) {
            /* a new chain (room: at most one chain ends at each of the
             * last MAX_SKIP beams) */
            uint8_t slot = 1;
            while (slots_used & (1u << (slot - 1)))
                slot++;
            slots_used |= 1u << (slot - 1);
            open[n_open].first = open[n_open].last = i;
            open[n_open].prev = -1;
            open[n_open].slot = slot;
            join = n_open++;
        } else {
            open[join].prev = open[join].last;
            open[join].last = i;
        }
        c.chain_of[i] = open[join].slot;
    }
    ctx->arena.used = after_store;
    return POLYC_OK;
}
