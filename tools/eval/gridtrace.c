/* gridtrace.c - border following and Douglas-Peucker on an occupancy grid
 * (see gridtrace.h): takes a grid, gives the findContours + approxPolyDP
 * baseline's polylines.
 */
#include "gridtrace.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Neighbour directions, clockwise with rows growing "down" (Suzuki & Abe's
 * image frame; the grid's rows grow up, which mirrors the picture and
 * leaves the borders the same): E, SE, S, SW, W, NW, N, NE. */
static const int dir_di[8] = {0, 1, 1, 1, 0, -1, -1, -1};
static const int dir_dj[8] = {1, 1, 0, -1, -1, -1, 0, 1};

typedef struct buf {
    double *xy;                /* border points, grid coordinates (column, row) */
    size_t count, cap;
} buf;

/* p, an array with room for *cap items of `size` bytes, with room for
 * `need`: as it is, or reallocated to the first of `first`, 2 `first`,
 * 4 `first`, ... that holds them (*cap updated); NULL when out of memory
 * (p still valid, *cap unchanged). */
static void *reserve(void *p, size_t *cap, size_t need, size_t first, size_t size)
{
    size_t c = *cap;
    if (p && need <= c)
        return p;
    if (c == 0)
        c = first;
    while (c < need)
        c *= 2u;
    p = realloc(p, c * size);
    if (p)
        *cap = c;
    return p;
}

static int push(buf *b, double x, double y)
{
    double *p = reserve(b->xy, &b->cap, b->count + 1u, 256u, 2u * sizeof *p);
    if (!p)
        return -1;
    b->xy = p;
    b->xy[2u * b->count] = x;
    b->xy[2u * b->count + 1u] = y;
    b->count++;
    return 0;
}

/* Direction from (i, j) to its neighbour (ni, nj). */
static int direction(long i, long j, long ni, long nj)
{
    for (int d = 0; d < 8; d++)
        if (dir_di[d] == ni - i && dir_dj[d] == nj - j)
            return d;
    return 0;
}

/* Follows the border that starts at (i, j), whose 0-neighbour (i2, j2)
 * tells the side (Suzuki & Abe, steps 3.1 to 3.5): labels f with nbd and
 * appends the border cells to b. f has a frame of zeros, `stride` wide. */
static int follow(int32_t *f, long stride, long i, long j, long i2, long j2, int32_t nbd, buf *b)
{
#define F(a, c) f[(a) * stride + (c)]
    long i1 = 0, j1 = 0, i3, j3;
    int d0 = direction(i, j, i2, j2), k, found = 0;
    if (push(b, (double)(j - 1), (double)(i - 1)))
        return -1;
    for (k = 0; k < 8; k++) {              /* 3.1: clockwise from (i2, j2) */
        int d = (d0 + k) % 8;
        if (F(i + dir_di[d], j + dir_dj[d]) != 0) {
            i1 = i + dir_di[d];
            j1 = j + dir_dj[d];
            found = 1;
            break;
        }
    }
    if (!found) {                           /* a lone cell */
        F(i, j) = -nbd;
        return 0;
    }
    i2 = i1; j2 = j1; i3 = i; j3 = j;       /* 3.2 */
    for (;;) {
        /* 3.3: counterclockwise round (i3, j3), from the one after (i2, j2) */
        int d2 = direction(i3, j3, i2, j2), east_zero = 0;
        long i4 = i3, j4 = j3;
        for (k = 1; k <= 8; k++) {
            int d = ((d2 - k) % 8 + 8) % 8;
            long ni = i3 + dir_di[d], nj = j3 + dir_dj[d];
            if (F(ni, nj) != 0) {
                i4 = ni;
                j4 = nj;
                break;
            }
            if (d == 0)
                east_zero = 1;
        }
        /* 3.4 */
        if (east_zero)
            F(i3, j3) = -nbd;
        else if (F(i3, j3) == 1)
            F(i3, j3) = nbd;
        /* 3.5 */
        if (i4 == i && j4 == j && i3 == i1 && j3 == j1)
            return 0;
        if (push(b, (double)(j4 - 1), (double)(i4 - 1)))
            return -1;
        i2 = i3; j2 = j3; i3 = i4; j3 = j4;
    }
#undef F
}

static double seg_dist2(const double *p, const double *a, const double *b)
{
    double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy, t = 0.0;
    if (l2 > 0.0) {
        t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2;
        t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    }
    double ex = a[0] + t * dx - p[0], ey = a[1] + t * dy - p[1];
    return ex * ex + ey * ey;
}

/* Douglas-Peucker on the chain p[a..b] (indices modulo n): marks keep[]
 * for the points kept inside it. stack: room for 2 * n indices. */
static void douglas_peucker(const double *xy, size_t n, size_t a, size_t b, double eps2,
                            unsigned char *keep, size_t *stack)
{
    size_t top = 0;
    stack[top++] = a;
    stack[top++] = b;
    while (top) {
        size_t hi = stack[--top], lo = stack[--top], best = lo, k;
        double worst = -1.0;
        const double *pa = &xy[2u * (lo % n)], *pb = &xy[2u * (hi % n)];
        for (k = lo + 1u; k < hi; k++) {
            double d = seg_dist2(&xy[2u * (k % n)], pa, pb);
            if (d > worst) {
                worst = d;
                best = k;
            }
        }
        if (best != lo && worst > eps2) {
            keep[best % n] = 1;
            stack[top++] = lo;
            stack[top++] = best;
            stack[top++] = best;
            stack[top++] = hi;
        }
    }
}

typedef struct out_buf {
    float *xy;
    uint64_t count;
    size_t cap;
    polyc_polyline *lines;
    uint64_t *first;           /* each line's first point in xy */
    uint32_t line_count;
    size_t line_cap, first_cap;
} out_buf;

static int add_line(out_buf *o, const double *xy, size_t n, const unsigned char *keep,
                    const polyc_occupancy_grid *g)
{
    double res = (double)g->resolution_m, c = cos(g->origin_yaw_rad), s = sin(g->origin_yaw_rad);
    size_t k, kept = 0;
    for (k = 0; k < n; k++)
        kept += keep[k];
    polyc_polyline *l = reserve(o->lines, &o->line_cap, o->line_count + 1u, 64u, sizeof *l);
    if (!l)
        return -1;
    o->lines = l;
    uint64_t *fp = reserve(o->first, &o->first_cap, o->line_count + 1u, 64u, sizeof *fp);
    if (!fp)
        return -1;
    o->first = fp;
    float *p = reserve(o->xy, &o->cap, (size_t)o->count + kept, 1024u, 2u * sizeof *p);
    if (!p)
        return -1;
    o->xy = p;
    l = &o->lines[o->line_count];
    o->first[o->line_count++] = o->count;
    l->point_count = (uint32_t)kept;
    l->closed = kept >= 3u;
    for (k = 0; k < n; k++) {
        if (!keep[k])
            continue;
        double u = (xy[2u * k] + 0.5) * res, v = (xy[2u * k + 1u] + 0.5) * res;
        o->xy[2u * o->count] = (float)(g->origin_x_m + c * u - s * v);
        o->xy[2u * o->count + 1u] = (float)(g->origin_y_m + s * u + c * v);
        o->count++;
    }
    return 0;
}

/* approxPolyDP of one closed border into o. */
static int simplify(const buf *b, double eps_cells, const polyc_occupancy_grid *g, out_buf *o,
                    unsigned char **keep, size_t **stack, size_t *room)
{
    size_t n = b->count, k, far = 0;
    double best = -1.0;
    if (n > *room) {
        unsigned char *kp = realloc(*keep, n);
        size_t *sp = realloc(*stack, 4u * n * sizeof *sp);
        if (kp)
            *keep = kp;
        if (sp)
            *stack = sp;
        if (!kp || !sp)
            return -1;
        *room = n;
    }
    memset(*keep, 0, n);
    (*keep)[0] = 1;
    for (k = 1; k < n; k++) {
        double dx = b->xy[2u * k] - b->xy[0], dy = b->xy[2u * k + 1u] - b->xy[1];
        if (dx * dx + dy * dy > best) {
            best = dx * dx + dy * dy;
            far = k;
        }
    }
    if (n > 1u) {
        (*keep)[far] = 1;
        douglas_peucker(b->xy, n, 0, far, eps_cells * eps_cells, *keep, *stack);
        douglas_peucker(b->xy, n, far, n, eps_cells * eps_cells, *keep, *stack);
    }
    return add_line(o, b->xy, n, *keep, g);
}

int gridtrace_run(const polyc_occupancy_grid *g, int8_t occupied_min, double epsilon_m,
                  gridtrace_map *out)
{
    long w = (long)g->width, h = (long)g->height, stride = w + 2, i, j;
    int32_t nbd = 1, *f;
    buf b;
    out_buf o;
    unsigned char *keep = NULL;
    size_t *stack = NULL, room = 0;
    int rc = -1;
    memset(out, 0, sizeof *out);
    memset(&b, 0, sizeof b);
    memset(&o, 0, sizeof o);
    if ((uint64_t)g->width * g->height > (1u << 28) || !(epsilon_m >= 0.0) ||
        !(g->resolution_m > 0.0f))
        return -1;
    f = calloc((size_t)stride * (size_t)(h + 2), sizeof *f);
    if (!f)
        return -1;
    for (i = 0; i < h; i++)
        for (j = 0; j < w; j++)
            f[(i + 1) * stride + j + 1] = g->cells[(size_t)i * g->width + (size_t)j] >= occupied_min;
    double eps_cells = epsilon_m / (double)g->resolution_m;
    for (i = 1; i <= h; i++)
        for (j = 1; j <= w; j++) {
            int32_t v = f[i * stride + j];
            long i2, j2;
            if (v == 1 && f[i * stride + j - 1] == 0) {
                i2 = i; j2 = j - 1;               /* an outer border */
            } else if (v >= 1 && f[i * stride + j + 1] == 0) {
                i2 = i; j2 = j + 1;               /* a hole border */
            } else
                continue;
            if (nbd == INT32_MAX)
                goto done;
            nbd++;
            b.count = 0;
            if (follow(f, stride, i, j, i2, j2, nbd, &b) != 0)
                goto done;
            out->border_cells += b.count;
            if (simplify(&b, eps_cells, g, &o, &keep, &stack, &room) != 0)
                goto done;
        }
    for (uint32_t k = 0; k < o.line_count; k++)
        o.lines[k].xy_m = o.xy + 2u * o.first[k];
    out->lines = o.lines;
    out->line_count = o.line_count;
    out->xy_m = o.xy;
    out->vertices = o.count;
    o.lines = NULL;
    o.xy = NULL;
    rc = 0;
done:
    free(o.lines);
    free(o.xy);
    free(o.first);
    free(f);
    free(b.xy);
    free(keep);
    free(stack);
    return rc;
}

void gridtrace_free(gridtrace_map *m)
{
    free(m->lines);
    free(m->xy_m);
    memset(m, 0, sizeof *m);
}
