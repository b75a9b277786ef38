/* accuracy.c - how accurate the data are where they lie (not in the paper).
 * Takes: the lines the angle prior fits in single scans (angle_prior.c hands
 * over a sample of each every STRAIGHT_M). Gives: per prior cell, the weight
 * of the BIC's error term there, in (0, 1].
 *
 * The paper's alpha "depends on the accuracy of the underlying sensor". Where
 * the poses are off (a loop closed late, far range), one wall seen from many
 * poses leaves a band of points 10-30 cm wide, each scan's points a thin line
 * somewhere in it. Scored as independent points, such a band pays for a line
 * per pass (a fan) or a zigzag across it: every extra vertex explains
 * thousands of points by a few centimetres. But the points of one scan share
 * its pose error; they are one observation of where the wall is, not many.
 *
 * Learning. Lines of different scans are compared where they describe the
 * same stretch of wall: two samples in one cell, parallel within PAIR_COS,
 * seen from the same side, less than PAIR_ALONG_M apart along the wall and
 * less than PAIR_ACROSS_M across it. Their offset across the wall, delta,
 * gives the spread of the scans' lines there: b^2 = mean(delta^2) / 2. The
 * lines' own residuals give the spread within a scan, r^2, and their point
 * densities the number m of one scan's points along CORRELATION_M of wall
 * (the reach of one vertex's decisions).
 *
 * Weight. The error term with alpha assumes independent Gaussian errors of
 * variance s0^2 = 1 / (2 alpha) (3.2 cm at the paper's 500). Spread beyond
 * that is shared by the m points of a scan, so the m points carry the
 * information of one point of variance r^2 + s0^2 + m (b^2 - s0^2) (the
 * design effect of clustered samples): each point's weight is
 *   w = (r^2 + s0^2) / (r^2 + s0^2 + m max(0, b^2 - s0^2)),
 * 1 where the scans agree to within s0. Cells with fewer than MIN_PAIRS pairs
 * keep 1.
 *
 * Memory: the weights (a float per prior cell) stay; the samples (at most
 * one per SAMPLE_BEAMS beams of the limits; past that none are taken) and the
 * per-cell sums are scratch, given back with the prior's. */
#include "../internal.h"

#include <math.h>
#include <string.h>

#define PAIR_COS 0.985f        /* cos 10 degrees: parallel */
#define PAIR_ALONG_M 0.125f    /* half the sample spacing: the same place along the wall */
#define PAIR_ACROSS_M 0.30f    /* wider than any band seen on the real logs */
#define PAIR_TRIES 16          /* other samples of the cell each sample is compared with */
#define MIN_PAIRS 8            /* fewer pairs say nothing */
#define CORRELATION_M 0.5f     /* one scan's points along this much wall share an error */
/* the sample budget: one per SAMPLE_BEAMS beams of the limits (room to
 * spare: the real logs take one per several beams) */
#define SAMPLE_BEAMS 2

typedef struct acc_sample {
    float x, y;                    /* on the line, frame metres */
    float nx, ny;                  /* unit normal towards the scan's sensor */
    uint32_t scan;
    uint32_t cell;
} acc_sample;

typedef struct acc_cell {
    float res2, density;           /* sums over the cell's samples */
    float delta2;                  /* sum over its pairs */
    uint32_t samples, pairs;
} acc_cell;

int polyc__accuracy_begin(polyc__acc_learn *L, polyc__prior *p, polyc__arena *a,
                          const polyc_limits *lim)
{
    memset(L, 0, sizeof *L);
    p->weight = NULL;
    if (lim->max_scans <= 1)
        return 1;
    size_t cells = (size_t)p->w * (size_t)p->h;
    p->weight = polyc__alloc(a, cells, sizeof(float));
    if (!p->weight)
        return 0;
    for (size_t c = 0; a->base && c < cells; c++) /* (a counting arena: no block) */
        p->weight[c] = 1.0f;
    L->p = p;
    return 1;
}

/* The scratch comes after the prior's own (released with it). */
int polyc__accuracy_scratch(polyc__acc_learn *L, polyc__arena *a, const polyc_limits *lim)
{
    if (!L->p)
        return 1;
    size_t cells = (size_t)L->p->w * (size_t)L->p->h;
    L->cap = lim->max_beams / SAMPLE_BEAMS + 1;
    L->samples = polyc__alloc(a, L->cap, sizeof(acc_sample));
    L->cells = polyc__alloc_zero(a, cells, sizeof(acc_cell));
    return L->samples && L->cells;
}

/* Online, the samples are paired as they come: each cell keeps PAIR_TRIES
 * of its samples, a uniform choice among all it has seen (a reservoir: the
 * n-th takes a place with chance PAIR_TRIES / n), and a new sample is
 * compared with them, so that, as in the batch's pairing, the scans
 * compared are spread over the whole run and not only the last few (whose
 * poses share their error). The cell's sums stay. */
int polyc__accuracy_online(polyc__acc_learn *L, polyc__arena *a, float alpha)
{
    L->alpha = alpha;
    if (!L->p)
        return 1;
    size_t cells = (size_t)L->p->w * (size_t)L->p->h;
    L->cells = polyc__alloc_zero(a, cells, sizeof(acc_cell));
    L->samples = polyc__alloc(a, cells * PAIR_TRIES, sizeof(acc_sample));
    L->ring_n = polyc__alloc_zero(a, cells, sizeof(uint32_t));
    return L->cells && L->samples && L->ring_n;
}

void polyc__accuracy_forget(polyc__acc_learn *L)
{
    const polyc__prior *p = L->p;
    if (!p || !L->cells || !L->ring_n)
        return;
    size_t cells = (size_t)p->w * (size_t)p->h;
    memset(L->cells, 0, cells * sizeof(acc_cell));
    memset(L->ring_n, 0, cells * sizeof(uint32_t));
    for (size_t c = 0; p->weight && c < cells; c++)
        p->weight[c] = 1.0f;
}

/* The prior cell holding (x, y) (frame metres); 0 outside the prior. */
static int cell_at(const polyc__prior *p, float x, float y, uint32_t *cell)
{
    float fx = (x - (float)p->origin_x) * p->inv_cell, fy = (y - (float)p->origin_y) * p->inv_cell;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < (float)p->w && fy < (float)p->h))
        return 0;
    *cell = (uint32_t)((int32_t)fy * p->w + (int32_t)fx);
    return 1;
}

/* The weight of a cell's points from its sums (s0_2: the variance alpha
 * assumes). */
static float cell_weight(const acc_cell *c, float s0_2)
{
    if (c->pairs < MIN_PAIRS || c->samples == 0)
        return 1.0f;
    float b2 = 0.5f * c->delta2 / (float)c->pairs;
    float r2 = c->res2 / (float)c->samples;
    float m = CORRELATION_M * c->density / (float)c->samples;
    float excess = b2 - s0_2;
    return excess > 0.0f && m > 1.0f ? (r2 + s0_2) / (r2 + s0_2 + m * excess) : 1.0f;
}

/* Adds the offset across the wall between a and b to the cell's pairs
 * when they describe the same stretch of wall from different scans. */
static void pair(acc_cell *c, const acc_sample *a, const acc_sample *b)
{
    if (b->scan == a->scan || a->nx * b->nx + a->ny * b->ny < PAIR_COS)
        return;
    float dx = b->x - a->x, dy = b->y - a->y;
    float along = dx * a->ny - dy * a->nx, across = dx * a->nx + dy * a->ny;
    if (fabsf(along) > PAIR_ALONG_M || fabsf(across) > PAIR_ACROSS_M)
        return;
    c->delta2 += across * across;
    c->pairs++;
}

void polyc__accuracy_sample(polyc__acc_learn *L, float x, float y, float nx, float ny,
                            uint32_t scan, float res2, float density)
{
    const polyc__prior *p = L->p;
    if (!p || !L->samples || (!L->ring_n && L->n >= L->cap))
        return;
    uint32_t cell;
    if (!cell_at(p, x, y, &cell))
        return;
    acc_sample tmp, *s = &tmp;
    if (!L->ring_n)
        s = &((acc_sample *)L->samples)[L->n++];
    s->x = x;
    s->y = y;
    s->nx = nx;
    s->ny = ny;
    s->scan = scan;
    s->cell = cell;
    acc_cell *c = &((acc_cell *)L->cells)[cell];
    c->res2 += res2;
    c->density += density;
    c->samples++;
    if (L->ring_n) {
        acc_sample *ring = (acc_sample *)L->samples + (size_t)cell * PAIR_TRIES;
        uint32_t n = L->ring_n[cell];
        for (uint32_t k = 0; k < n && k < PAIR_TRIES; k++)
            pair(c, s, &ring[k]);
        uint32_t at = n;
        if (n >= PAIR_TRIES) { /* a hash of (cell, n): the same choices on every run */
            uint32_t h = (cell * 2654435761u) ^ (n * 2246822519u);
            h ^= h >> 15;
            h *= 2654435761u;
            h ^= h >> 13;
            at = h % (n + 1);
        }
        if (at < PAIR_TRIES)
            ring[at] = *s;
        L->ring_n[cell] = n + 1;
        p->weight[cell] = cell_weight(c, L->alpha > 0.0f ? 0.5f / L->alpha : 0.0f);
    }
}

/* Offsets across the wall between samples of one cell, each sample against
 * up to PAIR_TRIES others spread over the cell's list. */
static void pair_up(acc_cell *cells, const acc_sample *smp, const uint32_t *order,
                    const uint32_t *start, size_t n_cells)
{
    for (size_t c = 0; c < n_cells; c++) {
        uint32_t lo = start[c], n = start[c + 1] - lo;
        if (n < 2)
            continue;
        uint32_t step = n > PAIR_TRIES ? n / PAIR_TRIES : 1;
        for (uint32_t i = 0; i < n; i++) {
            const acc_sample *a = &smp[order[lo + i]];
            for (uint32_t k = 1; k <= PAIR_TRIES && k * step < n; k++) {
                pair(&cells[c], a, &smp[order[lo + (i + k * step) % n]]);
            }
        }
    }
}

/* the pairing's index: the samples in cell order */
static int index_carve(polyc__arena *a, size_t cells, uint32_t n, uint32_t **start, uint32_t **order)
{
    *start = polyc__alloc_zero(a, cells + 1, sizeof(uint32_t));
    *order = polyc__alloc(a, n, sizeof(uint32_t));
    return *start && *order;
}

void polyc__accuracy_reserve_finish(polyc__acc_learn *L, polyc__arena *a)
{
    uint32_t *start, *order;
    if (L->p)
        index_carve(a, (size_t)L->p->w * (size_t)L->p->h, L->cap, &start, &order);
}

void polyc__accuracy_finish(polyc__acc_learn *L, polyc__arena *a, float alpha)
{
    polyc__prior *p = L->p;
    if (!p || !L->samples || !L->cells || L->n == 0)
        return;
    size_t cells = (size_t)p->w * (size_t)p->h;
    const acc_sample *smp = L->samples;
    acc_cell *cell = L->cells;
    uint32_t *start, *order;
    if (!index_carve(a, cells, L->n, &start, &order))
        return; /* cannot happen: budgeted; the weights stay 1 */
    for (uint32_t i = 0; i < L->n; i++)
        start[smp[i].cell + 1]++;
    for (size_t c = 0; c < cells; c++)
        start[c + 1] += start[c];
    for (uint32_t i = 0; i < L->n; i++)
        order[start[smp[i].cell]++] = i;
    for (size_t c = cells; c > 0; c--)
        start[c] = start[c - 1];
    start[0] = 0;
    pair_up(cell, smp, order, start, cells);
    polyc__accuracy_weigh(L, alpha);
}

void polyc__accuracy_weigh(polyc__acc_learn *L, float alpha)
{
    polyc__prior *p = L->p;
    if (!p || !L->cells)
        return;
    size_t cells = (size_t)p->w * (size_t)p->h;
    const acc_cell *cell = L->cells;
    float s0_2 = alpha > 0.0f ? 0.5f / alpha : 0.0f;
    for (size_t c = 0; c < cells; c++)
        p->weight[c] = cell_weight(&cell[c], s0_2);
}

float polyc__accuracy_weight(const polyc__prior *p, float x, float y)
{
    uint32_t cell;
    return p->weight && cell_at(p, x, y, &cell) ? p->weight[cell] : 1.0f;
}
