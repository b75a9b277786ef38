/* prior_learn.c - learning the angle prior (angle_prior.c) from the scans:
 * each scan's endpoints are clustered by the gaps between them, split and
 * merged into fitted lines, and each pair of neighbouring lines records
 * its turn (a corner) or their straight run into the prior's cell; the
 * lines' residuals are the accuracy's samples (accuracy.c). Takes: the
 * context's scans and a prior laid out on the grid. Gives: its counts. */
#include "../context.h"

#include <math.h>
#include <string.h>

#define BINS POLYC__ANGLE_BINS
#define BINS_PER_RAD POLYC__BINS_PER_RAD

#define GAP_M 0.15f                 /* cluster break: fixed part */
#define GAP_STEPS 3.0f              /* cluster break: beam spacings at range r */
#define TOL_M 0.03f                 /* split tolerance: fixed part */
#define TOL_REL 0.01f               /* split tolerance: share of the range */
#define MIN_POINTS 4u               /* a line needs this many endpoints */
#define MIN_LEN_M 0.10f             /* and a chord this long */
#define STRAIGHT_M 0.25f            /* one straight observation per this length */
#define MAX_DEPTH 16                /* split depth bound (no recursion) */
#define CORNER_COUNT 8u             /* a corner counts as 2 m of straight evidence */

typedef struct fit_line {
    uint32_t a, b;                 /* first and last beam */
    float mx, my;                  /* centroid (frame metres) */
    float dx, dy;                  /* unit direction, in beam order */
    float t0, t1;                  /* extent along d from the centroid */
    float res2;                    /* residual variance across the line, m^2 */
    int ok;
} fit_line;

typedef struct prior_pass {
    polyc__prior *p;
    const polyc_ctx *ctx;
    const polyc__scan *s;
    float ox, oy;                  /* prior origin (frame metres) */
    float *cache;                  /* x, y, range per beam of the scan, or NULL */
    uint32_t cache_cap;
    int cached;                    /* the cache holds this scan */
    fit_line last, pend;           /* last emitted line, line pending a merge */
    int have_last, have_pend;
    polyc__acc_learn *acc;         /* the accuracy's samples (accuracy.c) */
    uint32_t scan;                 /* index of s */
} prior_pass;

static int is_hit(const polyc__scan *s, float r)
{
    return r >= s->min_m && r < s->max_m; /* false for NaN */
}

/* endpoint of beam i of the scan (frame metres), the beam angle as grid.c has it */
static void endpoint(const prior_pass *q, uint32_t i, float *x, float *y, float *r)
{
    if (q->cached) {
        const float *c = q->cache + 3 * (size_t)i;
        *x = c[0];
        *y = c[1];
        *r = c[2];
        return;
    }
    const polyc__scan *s = q->s;
    float rr = q->ctx->ranges[s->first + i];
    float a = s->theta_rad + s->start_rad + (float)i * s->step_rad;
    float sn, cs;
    polyc__sincosf(a, &sn, &cs);
    *x = s->x_m + rr * cs;
    *y = s->y_m + rr * sn;
    *r = rr;
}

/* Adds `inc` to bin `bin` of the cell at (x, y); 0 when outside the grid. A
 * counter that would pass 65535 halves its cell's counters first. */
static int record(prior_pass *q, float x, float y, int bin, uint32_t inc)
{
    polyc__prior *p = q->p;
    float fx = (x - q->ox) * p->inv_cell, fy = (y - q->oy) * p->inv_cell;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < (float)p->w && fy < (float)p->h))
        return 0;
    int32_t ix = (int32_t)fx, iy = (int32_t)fy;
    if (ix >= p->w || iy >= p->h)
        return 0;
    uint32_t *row = &p->row_of[(size_t)iy * (size_t)p->w + (size_t)ix];
    if (*row == 0) { /* the block holds a row for every cell */
        *row = ++p->rows;
        memset(p->hist + (size_t)(*row - 1) * BINS, 0, BINS * sizeof(uint16_t));
        if (p->total) /* online: the totals are kept as counts come */
            p->total[*row - 1] = 0;
    }
    uint16_t *c = p->hist + (size_t)(*row - 1) * BINS;
    if (c[bin] > UINT16_MAX - inc) {
        uint32_t n = 0;
        for (int k = 0; k < BINS; k++) {
            c[k] = (uint16_t)(c[k] >> 1);
            n += c[k];
        }
        if (p->total)
            p->total[*row - 1] = n;
    }
    c[bin] = (uint16_t)(c[bin] + inc);
    if (p->total)
        p->total[*row - 1] += inc;
    return 1;
}

/* Farthest endpoint strictly between a and b from the chord a-b; returns
 * non-zero when it is off by more than the tolerance (*k gets it). */
static int off_chord(const prior_pass *q, uint32_t a, uint32_t b, uint32_t *k)
{
    float ax, ay, bx, by, r;
    endpoint(q, a, &ax, &ay, &r);
    endpoint(q, b, &bx, &by, &r);
    float tx = bx - ax, ty = by - ay;
    float len = sqrtf(tx * tx + ty * ty);
    float ux = 1.0f, uy = 0.0f;
    int chord = len > 1e-6f;
    if (chord) {
        ux = tx / len;
        uy = ty / len;
    }
    float best = -1.0f, best_tol = 0.0f;
    *k = a;
    for (uint32_t i = a + 1; i < b; i++) {
        float x, y;
        endpoint(q, i, &x, &y, &r);
        float vx = x - ax, vy = y - ay;
        float dist = chord ? fabsf(ux * vy - uy * vx) : sqrtf(vx * vx + vy * vy);
        if (dist > best) {
            best = dist;
            best_tol = TOL_M + TOL_REL * r;
            *k = i;
        }
    }
    return best > best_tol;
}

/* Principal-axis fit of the endpoints a..b (two passes: mean, then moments). */
static void fit(const prior_pass *q, uint32_t a, uint32_t b, fit_line *l)
{
    float ax, ay, bx, by, r;
    endpoint(q, a, &ax, &ay, &r);
    endpoint(q, b, &bx, &by, &r);
    float n = (float)(b - a + 1);
    float sx = 0.0f, sy = 0.0f;
    for (uint32_t i = a; i <= b; i++) {
        float x, y;
        endpoint(q, i, &x, &y, &r);
        sx += x - ax;
        sy += y - ay;
    }
    float mx = sx / n, my = sy / n; /* relative to endpoint a */
    float cxx = 0.0f, cxy = 0.0f, cyy = 0.0f;
    for (uint32_t i = a; i <= b; i++) {
        float x, y;
        endpoint(q, i, &x, &y, &r);
        float vx = x - ax - mx, vy = y - ay - my;
        cxx += vx * vx;
        cxy += vx * vy;
        cyy += vy * vy;
    }
    /* major eigenvector of [[cxx, cxy], [cxy, cyy]] */
    float half = 0.5f * (cxx - cyy);
    float root = sqrtf(half * half + cxy * cxy);
    float lam = 0.5f * (cxx + cyy) + root;
    float lam2 = 0.5f * (cxx + cyy) - root;
    float v1x = lam - cyy, v1y = cxy, v2x = cxy, v2y = lam - cxx;
    float n1 = v1x * v1x + v1y * v1y, n2 = v2x * v2x + v2y * v2y;
    float dx = n1 >= n2 ? v1x : v2x, dy = n1 >= n2 ? v1y : v2y;
    float nn = sqrtf(dx * dx + dy * dy);
    float cx = bx - ax, cy = by - ay;
    if (!(nn > 1e-12f)) { /* degenerate: the chord's direction */
        dx = cx;
        dy = cy;
        nn = sqrtf(dx * dx + dy * dy);
        if (!(nn > 1e-12f)) {
            dx = 1.0f;
            dy = 0.0f;
            nn = 1.0f;
        }
    }
    dx /= nn;
    dy /= nn;
    if (dx * cx + dy * cy < 0.0f) {
        dx = -dx;
        dy = -dy;
    }
    l->a = a;
    l->b = b;
    l->mx = ax + mx;
    l->my = ay + my;
    l->dx = dx;
    l->dy = dy;
    l->t0 = -(mx * dx + my * dy);
    l->t1 = (cx - mx) * dx + (cy - my) * dy;
    l->res2 = lam2 > 0.0f ? lam2 / n : 0.0f;
    l->ok = b - a + 1 >= MIN_POINTS && sqrtf(cx * cx + cy * cy) >= MIN_LEN_M;
}

/* A final line: the corner with the line before it, straight evidence along it. */
static void emit(prior_pass *q, const fit_line *l)
{
    polyc__prior *p = q->p;
    if (q->have_last && q->last.b == l->a) {
        float dot = q->last.dx * l->dx + q->last.dy * l->dy;
        float cr = q->last.dx * l->dy - q->last.dy * l->dx;
        float turn = polyc__turn_rad(cr, dot);
        int bin = (int)(turn * BINS_PER_RAD + 0.5f);
        if (bin > BINS - 1)
            bin = BINS - 1;
        float x, y, r;
        endpoint(q, l->a, &x, &y, &r);
        if (record(q, x, y, bin, CORNER_COUNT) && p->corners < UINT32_MAX)
            p->corners++;
    }
    float len = l->t1 - l->t0;
    uint32_t n = len > STRAIGHT_M ? (uint32_t)(len / STRAIGHT_M) : 1u;
    float step = len / (float)n;
    /* the normal towards the sensor, and points per metre: the accuracy's */
    float nx = -l->dy, ny = l->dx;
    if (nx * (q->s->x_m - l->mx) + ny * (q->s->y_m - l->my) < 0.0f) {
        nx = -nx;
        ny = -ny;
    }
    float density = len > 0.0f ? (float)(l->b - l->a + 1) / len : 0.0f;
    for (uint32_t j = 0; j < n; j++) {
        float t = l->t0 + ((float)j + 0.5f) * step;
        float x = l->mx + t * l->dx, y = l->my + t * l->dy;
        if (record(q, x, y, 0, 1u) && p->straights < UINT32_MAX)
            p->straights++;
        if (q->acc && len >= 0.5f)
            polyc__accuracy_sample(q->acc, x, y, nx, ny, q->scan, l->res2, density);
    }
    q->last = *l;
    q->have_last = 1;
}

static void flush(prior_pass *q)
{
    if (q->have_pend)
        emit(q, &q->pend);
    q->have_pend = 0;
}

/* One leaf of the end-point fit, in beam order: merge it into the pending line
 * when their union passes the chord test (short leaves too), else emit the
 * pending line and make the leaf pending if it is a line itself. */
static void leaf(prior_pass *q, uint32_t a, uint32_t b, int fits)
{
    uint32_t k;
    if (fits && q->have_pend && q->pend.b == a && !off_chord(q, q->pend.a, b, &k)) {
        fit(q, q->pend.a, b, &q->pend);
        return;
    }
    fit_line l;
    l.ok = 0;
    if (fits && b - a + 1 >= MIN_POINTS)
        fit(q, a, b, &l);
    flush(q);
    if (!l.ok) {
        q->have_last = 0; /* the chain of lines breaks here */
        return;
    }
    q->pend = l;
    q->have_pend = 1;
}

/* Split-and-merge of the cluster of beams i0..i1 (all hits). */
static void cluster(prior_pass *q, uint32_t i0, uint32_t i1)
{
    struct { uint32_t a, b, depth; } st[MAX_DEPTH + 2];
    int top = 0;
    if (i1 - i0 + 1 < MIN_POINTS)
        return;
    q->have_last = q->have_pend = 0;
    st[top].a = i0;
    st[top].b = i1;
    st[top].depth = 0;
    top++;
    while (top > 0) {
        top--;
        uint32_t a = st[top].a, b = st[top].b, depth = st[top].depth, k;
        if (!off_chord(q, a, b, &k)) {
            leaf(q, a, b, 1);
            continue;
        }
        if (b - a + 1 < MIN_POINTS || depth >= MAX_DEPTH) {
            leaf(q, a, b, 0); /* too short to hold a line, or too deep */
            continue;
        }
        /* right half below the left: leaves come out in beam order; the stack
         * holds at most one pending right half per level */
        POLYC_ASSERT(top + 2 <= MAX_DEPTH + 2);
        st[top].a = k;
        st[top].b = b;
        st[top].depth = depth + 1;
        top++;
        st[top].a = a;
        st[top].b = k;
        st[top].depth = depth + 1;
        top++;
    }
    flush(q);
}

static void learn_scan(prior_pass *q)
{
    const polyc__scan *s = q->s;
    const float *rr = q->ctx->ranges + s->first;
    float gap_per_m = GAP_STEPS * fabsf(s->step_rad);
    uint32_t start = 0;
    int open = 0;
    float px = 0.0f, py = 0.0f, pr = 0.0f;
    q->cached = 0;
    if (q->cache && s->count <= q->cache_cap) {
        for (uint32_t i = 0; i < s->count; i++)
            endpoint(q, i, &q->cache[3 * i], &q->cache[3 * i + 1], &q->cache[3 * i + 2]);
        q->cached = 1;
    }
    for (uint32_t i = 0; i < s->count; i++) {
        if (!is_hit(s, rr[i])) {
            if (open)
                cluster(q, start, i - 1);
            open = 0;
            continue;
        }
        float x, y, r;
        endpoint(q, i, &x, &y, &r);
        if (open) {
            float dx = x - px, dy = y - py, rm = r > pr ? r : pr;
            float gap = GAP_M + gap_per_m * rm;
            if (dx * dx + dy * dy > gap * gap) {
                cluster(q, start, i - 1);
                open = 0;
            }
        }
        if (!open) {
            start = i;
            open = 1;
        }
        px = x;
        py = y;
        pr = r;
    }
    if (open)
        cluster(q, start, s->count - 1);
}

void polyc__prior_learn(const polyc_ctx *ctx, polyc__prior *p, float *cache, uint32_t cache_cap,
                        polyc__acc_learn *acc)
{
    for (uint32_t si = 0; si < ctx->scan_count; si++)
        polyc__prior_learn_scan(ctx, p, &ctx->scans[si], si, cache, cache_cap, acc);
}

void polyc__prior_learn_scan(const polyc_ctx *ctx, polyc__prior *p, const polyc__scan *s,
                             uint32_t scan, float *cache, uint32_t cache_cap, polyc__acc_learn *acc)
{
    prior_pass q;
    memset(&q, 0, sizeof q);
    q.p = p;
    q.ctx = ctx;
    q.ox = (float)p->origin_x;
    q.oy = (float)p->origin_y;
    q.cache_cap = cache_cap;
    q.cache = cache;
    q.acc = acc;
    q.s = s;
    q.scan = scan;
    learn_scan(&q);
}
