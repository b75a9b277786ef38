/* polyline.c - polyline storage in the arena.
 * Takes: capacities from the limits. Gives: polylines as doubly linked lists
 * of vertices in a fixed pool (insert, remove, split and join in O(1)), and
 * the flattened form results are read in (also the optimiser's best model). */
#include "internal.h"

#include <string.h>

int32_t polyc__max_vertices(const polyc_limits *lim)
{
    uint64_t v = lim->max_vertices ? lim->max_vertices : (uint64_t)lim->max_beams + POLYC__VERTEX_SPARE;
    if (v > 0x3fffffffu)
        v = 0x3fffffffu;
    return (int32_t)v;
}

int32_t polyc__line_cap(int32_t v_cap)
{
    return v_cap / 2 + 16;
}

static int store_carve(polyc__arena *a, polyc__store *s, int32_t v_cap)
{
    memset(s, 0, sizeof *s);
    s->v_cap = v_cap;
    s->l_cap = polyc__line_cap(v_cap);
    s->v = polyc__alloc(a, (size_t)s->v_cap, sizeof(polyc__vertex));
    s->l = polyc__alloc(a, (size_t)s->l_cap, sizeof(polyc__line));
    return s->v && s->l;
}

void polyc__store_reserve(polyc__arena *a, const polyc_limits *lim)
{
    polyc__store s;
    store_carve(a, &s, polyc__max_vertices(lim));
}

int polyc__store_init(polyc__arena *a, polyc__store *s, int32_t v_cap)
{
    if (!store_carve(a, s, v_cap))
        return 0;
    s->v_free = POLYC__NONE;
    s->l_free = POLYC__NONE;
    return 1;
}

void polyc__store_clear(polyc__store *s)
{
    s->v_free = s->l_free = POLYC__NONE;
    s->v_live = s->l_live = 0;
    s->v_high = s->l_high = 0;
}

/* Free slots are recycled first; fresh ones are taken in order. */
static int32_t vertex_new(polyc__store *s, int32_t line, float x, float y)
{
    int32_t v;
    if (s->v_free != POLYC__NONE) {
        v = s->v_free;
        s->v_free = s->v[v].next;
    } else if (s->v_high < s->v_cap) {
        v = s->v_high++;
    } else {
        return POLYC__NONE;
    }
    polyc__vertex *p = &s->v[v];
    p->x = x;
    p->y = y;
    p->prev = p->next = POLYC__NONE;
    p->line = line;
    s->v_live++;
    return v;
}

static void vertex_free(polyc__store *s, int32_t v)
{
    s->v[v].line = POLYC__NONE;
    s->v[v].next = s->v_free;
    s->v_free = v;
    s->v_live--;
}

int32_t polyc__line_new(polyc__store *s)
{
    int32_t l;
    if (s->l_free != POLYC__NONE) {
        l = s->l_free;
        s->l_free = s->l[l].head;
    } else if (s->l_high < s->l_cap) {
        l = s->l_high++;
    } else {
        return POLYC__NONE;
    }
    s->l[l].head = s->l[l].tail = POLYC__NONE;
    s->l[l].count = 0;
    s->l[l].closed = 0;
    s->l[l].id = ++s->last_id;
    s->l_live++;
    return l;
}

/* Frees the polyline and every vertex still on it. */
void polyc__line_free(polyc__store *s, int32_t l)
{
    polyc__line *ln = &s->l[l];
    int32_t v = ln->head;
    for (int32_t k = 0; k < ln->count; k++) {
        int32_t nx = s->v[v].next;
        vertex_free(s, v);
        v = nx;
    }
    ln->closed = POLYC__NONE;
    ln->head = s->l_free;
    s->l_free = l;
    s->l_live--;
}

int32_t polyc__vertex_append(polyc__store *s, int32_t l, float x, float y)
{
    polyc__line *ln = &s->l[l];
    POLYC_ASSERT(!ln->closed);
    int32_t v = vertex_new(s, l, x, y);
    if (v == POLYC__NONE)
        return v;
    if (ln->count == 0) {
        ln->head = v;
    } else {
        s->v[ln->tail].next = v;
        s->v[v].prev = ln->tail;
    }
    ln->tail = v;
    ln->count++;
    return v;
}

int32_t polyc__vertex_insert_after(polyc__store *s, int32_t u, float x, float y)
{
    int32_t l = s->v[u].line;
    polyc__line *ln = &s->l[l];
    int32_t v = vertex_new(s, l, x, y);
    if (v == POLYC__NONE)
        return v;
    int32_t w = s->v[u].next;
    s->v[v].prev = u;
    s->v[v].next = w;
    s->v[u].next = v;
    if (w != POLYC__NONE)
        s->v[w].prev = v;
    if (ln->tail == u)
        ln->tail = v;
    ln->count++;
    return v;
}

void polyc__vertex_remove(polyc__store *s, int32_t v)
{
    int32_t l = s->v[v].line;
    polyc__line *ln = &s->l[l];
    int32_t p = s->v[v].prev, n = s->v[v].next;
    if (ln->count == 1) {
        ln->head = ln->tail = POLYC__NONE;
    } else {
        if (p != POLYC__NONE)
            s->v[p].next = n;
        if (n != POLYC__NONE)
            s->v[n].prev = p;
        if (ln->head == v)
            ln->head = n;
        if (ln->tail == v)
            ln->tail = p;
    }
    ln->count--;
    if (ln->closed && ln->count < 3) {
        /* a closed polyline of two points is an open segment */
        ln->closed = 0;
        if (ln->count > 0) {
            s->v[ln->head].prev = POLYC__NONE;
            s->v[ln->tail].next = POLYC__NONE;
        }
    }
    vertex_free(s, v);
}

void polyc__line_close(polyc__store *s, int32_t l)
{
    polyc__line *ln = &s->l[l];
    POLYC_ASSERT(ln->count >= 3);
    s->v[ln->tail].next = ln->head;
    s->v[ln->head].prev = ln->tail;
    ln->closed = 1;
}

void polyc__line_reverse(polyc__store *s, int32_t l)
{
    polyc__line *ln = &s->l[l];
    int32_t v = ln->head;
    for (int32_t k = 0; k < ln->count; k++) {
        int32_t nx = s->v[v].next;
        s->v[v].next = s->v[v].prev;
        s->v[v].prev = nx;
        v = nx;
    }
    int32_t h = ln->head;
    ln->head = ln->tail;
    ln->tail = h;
}

/* ---- flattened form ---- */

/* circles: one for every fourth polyline (a map of pillars alone has a
 * polyline round each, and more circles than that stay polylines) */
static uint32_t circle_cap(uint32_t cap_lines)
{
    return cap_lines / 4 + 4;
}

/* (circles: the context's result only, polyc__flat_result) */
static int flat_carve(polyc__arena *a, polyc__flat *f, uint32_t cap_lines, uint32_t cap_points,
                      int circles)
{
    memset(f, 0, sizeof *f);
    f->xy = polyc__alloc(a, (size_t)cap_points * 2, sizeof(float));
    f->start = polyc__alloc(a, (size_t)cap_lines + 1, sizeof(uint32_t));
    f->closed = polyc__alloc(a, cap_lines, 1);
    f->id = polyc__alloc(a, cap_lines, sizeof(uint32_t));
    if (circles) {
        f->circ = polyc__alloc(a, circle_cap(cap_lines), sizeof(polyc__circle));
        f->circ_cap = circle_cap(cap_lines);
        f->arc_keep = polyc__alloc(a, cap_points, 1);
        f->arc_bulge = polyc__alloc(a, cap_points, sizeof(float));
    }
    return f->xy && f->start && f->closed && f->id &&
           (!circles || (f->circ && f->arc_keep && f->arc_bulge));
}

void polyc__flat_reserve(polyc__arena *a, int32_t v_cap, int result)
{
    polyc__flat f;
    flat_carve(a, &f, (uint32_t)polyc__line_cap(v_cap), (uint32_t)v_cap, result);
}

static int flat_start(polyc__arena *a, polyc__flat *f, uint32_t cap_lines, uint32_t cap_points,
                      int circles)
{
    if (!flat_carve(a, f, cap_lines, cap_points, circles))
        return 0;
    f->cap_lines = cap_lines;
    f->cap_points = cap_points;
    f->start[0] = 0;
    return 1;
}

int polyc__flat_result(polyc__arena *a, polyc__flat *f, uint32_t cap_lines, uint32_t cap_points)
{
    return flat_start(a, f, cap_lines, cap_points, 1);
}

int polyc__flat_init(polyc__arena *a, polyc__flat *f, uint32_t cap_lines, uint32_t cap_points)
{
    return flat_start(a, f, cap_lines, cap_points, 0);
}

void polyc__flat_from_store(polyc__flat *f, const polyc__store *s)
{
    f->count = 0;
    f->points = 0;
    for (int32_t l = 0; l < s->l_high; l++) {
        const polyc__line *ln = &s->l[l];
        if (ln->closed == POLYC__NONE || ln->count == 0)
            continue;
        int32_t v = ln->head;
        for (int32_t k = 0; k < ln->count; k++) {
            f->xy[2 * f->points] = s->v[v].x;
            f->xy[2 * f->points + 1] = s->v[v].y;
            f->points++;
            v = s->v[v].next;
        }
        f->closed[f->count] = (uint8_t)(ln->closed == 1);
        f->id[f->count] = ln->id;
        f->count++;
        f->start[f->count] = f->points;
    }
}

/* The polylines keep their ids; the next new one gets an id none had. */
polyc_status polyc__store_from_flat(polyc__store *s, const polyc__flat *f)
{
    uint32_t last = s->last_id;
    polyc__store_clear(s);
    for (uint32_t i = 0; i < f->count; i++) {
        int32_t l = polyc__line_new(s);
        if (l == POLYC__NONE)
            return POLYC_ERR_NOMEM;
        s->l[l].id = f->id[i];
        s->last_id = last;
        for (uint32_t k = f->start[i]; k < f->start[i + 1]; k++)
            if (polyc__vertex_append(s, l, f->xy[2 * k], f->xy[2 * k + 1]) == POLYC__NONE)
                return POLYC_ERR_NOMEM;
        if (f->closed[i])
            polyc__line_close(s, l);
    }
    return POLYC_OK;
}

/* Cuts the link u -> next(u). A closed polyline opens there; an open one
 * becomes two (the part after u moves to a new polyline, returned; NONE
 * when the polyline was closed or no slot is free, in which case an open
 * polyline is left uncut and *ok is 0). */
int32_t polyc__line_cut(polyc__store *s, int32_t u, int *ok)
{
    int32_t l = s->v[u].line, w = s->v[u].next;
    polyc__line *ln = &s->l[l];
    *ok = 1;
    if (w == POLYC__NONE)
        return POLYC__NONE;
    if (ln->closed) {
        s->v[u].next = POLYC__NONE;
        s->v[w].prev = POLYC__NONE;
        ln->head = w;
        ln->tail = u;
        ln->closed = 0;
        return POLYC__NONE;
    }
    int32_t l2 = polyc__line_new(s);
    if (l2 == POLYC__NONE) {
        *ok = 0;
        return POLYC__NONE;
    }
    ln = &s->l[l]; /* (no reallocation, but keep the pattern obvious) */
    polyc__line *n2 = &s->l[l2];
    int32_t moved = 0;
    for (int32_t v = w; v != POLYC__NONE; v = s->v[v].next) {
        s->v[v].line = l2;
        moved++;
    }
    n2->head = w;
    n2->tail = ln->tail;
    n2->count = moved;
    n2->closed = 0;
    ln->tail = u;
    ln->count -= moved;
    s->v[u].next = POLYC__NONE;
    s->v[w].prev = POLYC__NONE;
    return l2;
}

/* Links tail (the last vertex of an open polyline) to head (the first of an
 * open polyline): the same polyline closes, two polylines become one. */
void polyc__line_join(polyc__store *s, int32_t tail, int32_t head)
{
    int32_t l1 = s->v[tail].line, l2 = s->v[head].line;
    if (l1 == l2) {
        polyc__line_close(s, l1);
        return;
    }
    polyc__line *a = &s->l[l1], *b = &s->l[l2];
    for (int32_t v = head; v != POLYC__NONE; v = s->v[v].next)
        s->v[v].line = l1;
    s->v[tail].next = head;
    s->v[head].prev = tail;
    a->tail = b->tail;
    a->count += b->count;
    b->count = 0; /* its vertices now belong to l1 */
    polyc__line_free(s, l2);
}
