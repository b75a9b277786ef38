/* edits.c - the primitive edits of the map the operators are made of: move,
 * remove and insert a vertex, cut a link, join two ends, reverse a polyline.
 * Takes: the optimiser state. Gives: the edit, with the segments it takes
 * out and puts in recorded in the current change, so the score stays exact. */
#include "../opt_state.h"

/* ---- edits ---- */

static int32_t prev_of(const polyc__opt *o, int32_t v)
{
    return o->s->v[v].prev;
}

static int32_t next_of(const polyc__opt *o, int32_t v)
{
    return o->s->v[v].next;
}

/* Every segment and vertex angle of a polyline out of the score (in 0),
 * or back in (in 1). */
static void line_books(polyc__opt *o, int32_t l, int in)
{
    const polyc__line *ln = &o->s->l[l];
    int32_t v = ln->head;
    for (int32_t k = 0; k < ln->count; k++) {
        if (in)
            polyc__chg_seg_in(o, v);
        else
            polyc__chg_seg_out(o, v);
        polyc__chg_dirty(o, v);
        v = next_of(o, v);
    }
}

/* The two segments at v out of the score, the angles at v and its
 * neighbours p and n pending: before v moves or goes. */
static void around_out(polyc__opt *o, int32_t p, int32_t v, int32_t n)
{
    polyc__chg_seg_out(o, p);
    polyc__chg_seg_out(o, v);
    polyc__chg_dirty(o, p);
    polyc__chg_dirty(o, v);
    polyc__chg_dirty(o, n);
}

void polyc__op_move(polyc__opt *o, int32_t v, float x, float y)
{
    int32_t p = prev_of(o, v), n = next_of(o, v);
    around_out(o, p, v, n);
    o->s->v[v].x = x;
    o->s->v[v].y = y;
    polyc__chg_seg_in(o, p);
    polyc__chg_seg_in(o, v);
}

/* Removes v; a polyline left with one vertex goes too (it explains nothing). */
void polyc__op_remove(polyc__opt *o, int32_t v)
{
    polyc__store *s = o->s;
    int32_t l = s->v[v].line;
    if (s->l[l].closed && s->l[l].count <= 3) {
        line_books(o, l, 0); /* the polyline opens: every link may change */
        polyc__vertex_remove(s, v);
        line_books(o, l, 1);
        return;
    }
    int32_t p = prev_of(o, v), n = next_of(o, v);
    around_out(o, p, v, n);
    polyc__vertex_remove(s, v);
    if (s->l[l].count == 1) {
        int32_t last = s->l[l].head;
        polyc__chg_dirty(o, last);
        polyc__line_free(s, l);
        return;
    }
    if (s->l[l].count == 0) {
        polyc__line_free(s, l);
        return;
    }
    polyc__chg_seg_in(o, p);
}

int32_t polyc__op_insert_after(polyc__opt *o, int32_t u, float x, float y)
{
    int32_t w = next_of(o, u);
    polyc__chg_seg_out(o, u);
    polyc__chg_dirty(o, u);
    polyc__chg_dirty(o, w);
    int32_t v = polyc__vertex_insert_after(o->s, u, x, y);
    if (v == POLYC__NONE) {
        polyc__chg_seg_in(o, u);
        return v;
    }
    /* a fresh slot holds no angle; a slot freed and reused within this same
     * change was already taken out of the angle sum when it was freed */
    if (o->chg.v_dirty[v] != o->chg.epoch)
        o->acost[v] = 0.0f;
    o->seg_in[v] = 0;
    polyc__chg_dirty(o, v);
    polyc__chg_seg_in(o, u);
    polyc__chg_seg_in(o, v);
    return v;
}

/* A piece of one vertex left by a cut explains nothing: it goes. */
static void drop_if_single(polyc__opt *o, int32_t l)
{
    if (l != POLYC__NONE && o->s->l[l].closed != POLYC__NONE && o->s->l[l].count == 1)
        polyc__op_remove(o, o->s->l[l].head);
}

void polyc__op_cut(polyc__opt *o, int32_t u)
{
    int32_t w = next_of(o, u);
    if (w == POLYC__NONE)
        return;
    int32_t l = o->s->v[u].line;
    polyc__chg_seg_out(o, u);
    polyc__chg_dirty(o, u);
    polyc__chg_dirty(o, w);
    int ok;
    int32_t l2 = polyc__line_cut(o->s, u, &ok);
    if (!ok) {
        polyc__chg_seg_in(o, u);
        return;
    }
    drop_if_single(o, l);
    drop_if_single(o, l2);
}

void polyc__op_reverse(polyc__opt *o, int32_t l)
{
    line_books(o, l, 0);
    polyc__line_reverse(o->s, l);
    line_books(o, l, 1);
}

/* Links two open ends: tail of one polyline to head of another (or closes). */
int polyc__op_link(polyc__opt *o, int32_t tail, int32_t head)
{
    polyc__store *s = o->s;
    if (s->v[tail].line == s->v[head].line && s->l[s->v[tail].line].count < 3)
        return 0;
    polyc__chg_dirty(o, tail);
    polyc__chg_dirty(o, head);
    polyc__line_join(s, tail, head);
    polyc__chg_seg_in(o, tail);
    return 1;
}

/* One edit as a change of its own. */
void polyc__apply_remove(polyc__opt *o, int32_t v)
{
    polyc__chg_begin(o);
    polyc__op_remove(o, v);
    polyc__chg_commit(o);
}

void polyc__apply_move(polyc__opt *o, int32_t v, float x, float y)
{
    polyc__chg_begin(o);
    polyc__op_move(o, v, x, y);
    polyc__chg_commit(o);
}
