/* opt_harness.c - the optimiser's test harness: the scene, the fixture,
 * hand-made data and maps, from-scratch checks and random edits
 * (tests/opt_harness.h). */
#include "opt_harness.h"

/* ---- scene: the room seen from three poses, the first at the origin ---- */

static const double POSE[N_POSES][3] = {{0.0, 0.0, 0.0}, {1.1, 0.6, 0.4}, {-1.2, -0.7, -0.3}};

/* range from (px, py) along (c, s) to the walls of the room */
double room_range(double px, double py, double c, double s)
{
    double t = 1e30;
    if (c > 1e-12) t = fmin(t, (ROOM_X1 - px) / c);
    if (c < -1e-12) t = fmin(t, (ROOM_X0 - px) / c);
    if (s > 1e-12) t = fmin(t, (ROOM_Y1 - py) / s);
    if (s < -1e-12) t = fmin(t, (ROOM_Y0 - py) / s);
    return t;
}

/* 360 beams over the full circle; noise_m > 0 adds a small deterministic
 * ripple (no randomness: the same ranges on every run) */
void make_scans(fixture *f, float noise_m)
{
    for (int k = 0; k < N_POSES; k++) {
        polyc_scan *s = &f->scans[k];
        memset(s, 0, sizeof *s);
        s->pose_x_m = POSE[k][0];
        s->pose_y_m = POSE[k][1];
        s->pose_theta_rad = POSE[k][2];
        s->start_angle_rad = (float)-PI_D;
        s->angle_step_rad = (float)(2.0 * PI_D / BEAMS);
        s->min_range_m = 0.05f;
        s->max_range_m = 30.0f;
        s->beam_count = BEAMS;
        for (int i = 0; i < BEAMS; i++) {
            double a = POSE[k][2] + (double)s->start_angle_rad + (double)i * (double)s->angle_step_rad;
            double r = room_range(POSE[k][0], POSE[k][1], cos(a), sin(a));
            r += (double)noise_m * sin(0.7 * (double)i + 1.3 * (double)k);
            f->ranges[k][i] = (float)r;
        }
        s->range_m = f->ranges[k];
    }
}

void check_st(polyc_status st, const polyc_ctx *ctx, const char *what)
{
    if (st != POLYC_OK)
        fail_msg("%s: %s (%s)", what, polyc_status_str(st), ctx ? polyc_last_error(ctx) : "");
}

/* A context with the room's scans, built up to the initial polylines. */
void fx_context(fixture *f, float gamma, float noise_m, uint32_t flags)
{
    polyc_limits lim;
    memset(f, 0, sizeof *f);
    polyc_config_default(&f->cfg);
    f->cfg.gamma = gamma;
    f->cfg.flags = flags;
    make_scans(f, noise_m);
    check_st(polyc_limits_for_scans(&f->cfg, f->scans, N_POSES, &lim), NULL, "limits");
    size_t size = polyc_memory_size(&f->cfg, &lim);
    assert_true(size > 0);
    f->block = malloc(size);
    assert_non_null(f->block);
    check_st(polyc_init(f->block, size, &f->cfg, &lim, &f->ctx), NULL, "init");
    for (int k = 0; k < N_POSES; k++)
        check_st(polyc_add_scan(f->ctx, &f->scans[k]), f->ctx, "add_scan");
    check_st(polyc_trace(f->ctx), f->ctx, "trace");
}

/* The optimiser state as polyc_optimize makes it: the arena rewound to the
 * end of the trace, then polyc__opt_setup (points, hash, prior, scores). */
void fx_setup_opt(fixture *f)
{
    f->ctx->arena.used = f->ctx->trace_mark;
    check_st(polyc__opt_setup(f->ctx, &f->o), f->ctx, "setup");
}

void fx_open(fixture *f, float gamma, float noise_m, uint32_t flags)
{
    fx_context(f, gamma, noise_m, flags);
    fx_setup_opt(f);
    f->pt_cap = f->o.d.np;
}

/* For hand-made cases: raw points (so that the per-point arrays hold one
 * per beam, 1080), the prior as learned from the room (gamma 0 unless set). */
void fx_open_hand(fixture *f, float gamma)
{
    fx_open(f, gamma, 0.0f, POLYC_FLAG_EXACT_POINTS);
}

void fx_close(fixture *f)
{
    free(f->block);
    f->block = NULL;
}

/* ---- hand-made data and polylines ---- */

/* Replaces the data points by unit points at xy (n of them), sorted by
 * bucket as points.c sorts them; the per-point arrays were sized for the
 * room's points, so the new set must not be larger (checked). Each point is
 * seen from seen_xy (its sensor's position, 2 per point), or from nowhere
 * known when seen_xy is NULL. */
void set_points_seen(fixture *f, const float *xy, const float *seen_xy, int n)
{
    polyc__opt *o = &f->o;
    polyc__hash *h = &o->h;
    int32_t nb = h->bx * h->by;
    assert_true(n <= f->pt_cap);
    memset(h->pt_start, 0, ((size_t)nb + 1) * sizeof(uint32_t));
    for (int i = 0; i < n; i++)
        h->pt_start[polyc__bucket_of(h, xy[2 * i], xy[2 * i + 1]) + 1]++;
    for (int32_t b = 0; b < nb; b++)
        h->pt_start[b + 1] += h->pt_start[b];
    for (int i = 0; i < n; i++) {
        int32_t b = polyc__bucket_of(h, xy[2 * i], xy[2 * i + 1]);
        uint32_t at = h->pt_start[b]++;
        polyc__point *p = &o->d.pts[at];
        memset(p, 0, sizeof *p);
        p->x = xy[2 * i];
        p->y = xy[2 * i + 1];
        p->w = 1.0f;
        if (o->d.pt_view) {
            o->d.pt_view[2 * at] = seen_xy ? seen_xy[2 * i] - p->x : 0.0f;
            o->d.pt_view[2 * at + 1] = seen_xy ? seen_xy[2 * i + 1] - p->y : 0.0f;
        }
    }
    for (int32_t b = nb; b > 0; b--)
        h->pt_start[b] = h->pt_start[b - 1];
    h->pt_start[0] = 0;
    o->d.np = n;
    o->d.n = (float)n;
    o->d.log_n = logf(o->d.n > 1.0f ? o->d.n : 1.0f);
}

void set_points(fixture *f, const float *xy, int n)
{
    set_points_seen(f, xy, NULL, n);
}

/* points every step_m along a-b, both ends included */
void pts_line(ptlist *p, float ax, float ay, float bx, float by, float step_m)
{
    float len = sqrtf((bx - ax) * (bx - ax) + (by - ay) * (by - ay));
    int k = (int)floorf(len / step_m + 0.5f);
    for (int i = 0; i <= k; i++) {
        assert_true(p->n < MAX_PTS);
        float t = k > 0 ? (float)i / (float)k : 0.0f;
        p->xy[2 * p->n] = ax + t * (bx - ax);
        p->xy[2 * p->n + 1] = ay + t * (by - ay);
        p->n++;
    }
}

void clear_lines(polyc__opt *o)
{
    polyc__store_clear(o->s);
}

/* a polyline through n points of xy; returns its id */
int32_t add_line(polyc__opt *o, const float *xy, int n, int closed)
{
    int32_t l = polyc__line_new(o->s);
    assert_true(l != POLYC__NONE);
    for (int i = 0; i < n; i++)
        assert_true(polyc__vertex_append(o->s, l, xy[2 * i], xy[2 * i + 1]) != POLYC__NONE);
    if (closed)
        polyc__line_close(o->s, l);
    return l;
}

/* A hand case: points every 1 cm along a straight wall from (-1, 0) to
 * (1, 0), no polylines yet. */
void open_straight_wall(fixture *f, ptlist *p)
{
    fx_open_hand(f, 0.0f);
    p->n = 0;
    pts_line(p, -1.0f, 0.0f, 1.0f, 0.0f, 0.01f);
    set_points(f, p->xy, p->n);
    clear_lines(&f->o);
}

void rebuild(polyc__opt *o)
{
    check_st(polyc__rebuild(o), o->ctx, "rebuild");
}

/* ---- inspecting the map ---- */

int live_lines(const polyc__opt *o)
{
    int n = 0;
    for (int32_t l = 0; l < o->s->l_high; l++)
        if (o->s->l[l].closed != POLYC__NONE)
            n++;
    return n;
}

/* the live polyline with an end (head or tail) at (x, y) within 1 mm, or NONE */
int32_t line_with_end(const polyc__opt *o, float x, float y)
{
    for (int32_t l = 0; l < o->s->l_high; l++) {
        const polyc__line *ln = &o->s->l[l];
        if (ln->closed == POLYC__NONE || ln->count == 0)
            continue;
        const polyc__vertex *h = &o->s->v[ln->head], *t = &o->s->v[ln->tail];
        if (fabsf(h->x - x) < 1e-3f && fabsf(h->y - y) < 1e-3f)
            return l;
        if (fabsf(t->x - x) < 1e-3f && fabsf(t->y - y) < 1e-3f)
            return l;
    }
    return POLYC__NONE;
}

/* distance from (x, y) to the nearest live vertex */
float nearest_vertex(const polyc__opt *o, float x, float y)
{
    float best = 1e30f;
    for (int32_t v = 0; v < o->s->v_high; v++) {
        const polyc__vertex *p = &o->s->v[v];
        if (p->line == POLYC__NONE)
            continue;
        float d = sqrtf((p->x - x) * (p->x - x) + (p->y - y) * (p->y - y));
        if (d < best)
            best = d;
    }
    return best;
}

void dump_map(const polyc__opt *o, const char *title)
{
    printf("# %s: %d vertices, %d polylines, bic %.6f err %.9f\n", title, o->s->v_live,
           live_lines(o), (double)polyc__bic(o), (double)polyc__err(o));
    for (int32_t l = 0; l < o->s->l_high; l++) {
        const polyc__line *ln = &o->s->l[l];
        if (ln->closed == POLYC__NONE)
            continue;
        printf("#  line %d (%s, %d):", l, ln->closed ? "closed" : "open", ln->count);
        int32_t v = ln->head;
        for (int32_t k = 0; k < ln->count; k++) {
            printf(" (%.3f %.3f)", (double)o->s->v[v].x, (double)o->s->v[v].y);
            v = o->s->v[v].next;
        }
        printf("\n");
    }
}

/* ---- from-scratch checks ---- */

int seg_live(const polyc__opt *o, int32_t v)
{
    return v >= 0 && v < o->s->v_high && o->s->v[v].line != POLYC__NONE &&
           o->s->v[v].next != POLYC__NONE;
}

/* nearest segment over every live segment, capped at w R^2 as the score is */
double brute_nearest(const polyc__opt *o, const polyc__point *p, int32_t *seg)
{
    double best = (double)p->w * (double)o->R2;
    int32_t best_seg = POLYC__NONE;
    for (int32_t v = 0; v < o->s->v_high; v++) {
        if (!seg_live(o, v))
            continue;
        double c = polyc__cost_seg(o, p, v);
        if (c < best) {
            best = c;
            best_seg = v;
        }
    }
    if (seg)
        *seg = best_seg;
    return best;
}

int close_rel(double a, double b, double rel)
{
    return fabs(a - b) <= rel * (1.0 + fmax(fabs(a), fabs(b)));
}

/* The oracles: the library's invariant checkers (src/search/checks.c, linked into
 * every tests/test_opt_* suite with POLYC_CHECKS), failing the test with
 * the first violation. */
static void fail_if(const char *why, int32_t at, const char *where)
{
    if (why)
        fail_msg("%s: %s (at %d)", where, why, at);
}

/* Linked lists, line ids, counts, ends, live counts. */
void check_store(const polyc__opt *o, const char *where)
{
    int32_t at = -1;
    fail_if(polyc__check_store(o->s, &at), at, where);
}

/* Every entry is a live segment marked in the hash; each live segment is in
 * exactly the buckets its path crosses, once per visit. */
void check_hash(polyc__opt *o, const char *where)
{
    int32_t at = -1;
    fail_if(polyc__check_hash(o, &at), at, where);
}

/* The incremental books against a recomputation from scratch, with the
 * store, the hash and the arena. */
void check_books(polyc__opt *o, const char *where)
{
    int32_t at = -1;
    fail_if(polyc__check_arena(&o->ctx->arena), -1, where);
    check_store(o, where);
    check_hash(o, where);
    fail_if(polyc__check_books(o, &at), at, where);
}

/* BIC of the current map recomputed from scratch */
double scratch_bic(polyc__opt *o)
{
    double err = 0.0, angle = 0.0;
    for (int32_t i = 0; i < o->d.np; i++)
        err += brute_nearest(o, &o->d.pts[i], NULL);
    for (int32_t v = 0; v < o->s->v_high; v++)
        if (o->s->v[v].line != POLYC__NONE)
            angle += (double)polyc__vertex_angle_cost(o, v);
    return (double)o->cfg->alpha * (err + (double)o->cfg->gamma * angle) +
           (double)o->s->v_live * (double)o->d.log_n;
}

/* ---- random edits ---- */

double urand(polyc__rng *r)
{
    return polyc__rng_uniform(r);
}

int32_t irand(polyc__rng *r, int32_t n)
{
    return (int32_t)(urand(r) * (double)n);
}

/* a random live vertex (with a segment after it when want_seg), or NONE */
int32_t pick_vertex(const polyc__opt *o, polyc__rng *r, int want_seg)
{
    for (int tries = 0; tries < 200; tries++) {
        int32_t v = irand(r, o->s->v_high);
        if (o->s->v[v].line == POLYC__NONE)
            continue;
        if (want_seg && o->s->v[v].next == POLYC__NONE)
            continue;
        return v;
    }
    return POLYC__NONE;
}

/* a random open end: a tail (want_tail) or a head */
int32_t pick_end(const polyc__opt *o, polyc__rng *r, int want_tail)
{
    for (int tries = 0; tries < 400; tries++) {
        int32_t v = irand(r, o->s->v_high);
        const polyc__vertex *p = &o->s->v[v];
        if (p->line == POLYC__NONE || o->s->l[p->line].count < 2)
            continue;
        if (want_tail ? p->next == POLYC__NONE : p->prev == POLYC__NONE)
            return v;
    }
    return POLYC__NONE;
}

/* One elementary edit inside the current change; returns its name. */
const char *basic_edit(polyc__opt *o, polyc__rng *r)
{
    int32_t v;
    switch (irand(r, 5)) {
    case 0:
        if ((v = pick_vertex(o, r, 0)) == POLYC__NONE)
            return "none";
        polyc__op_move(o, v, o->s->v[v].x + 0.04f * polyc__rng_normal(r),
                       o->s->v[v].y + 0.04f * polyc__rng_normal(r));
        return "move";
    case 1: {
        if ((v = pick_vertex(o, r, 1)) == POLYC__NONE)
            return "none";
        const polyc__vertex *a = &o->s->v[v], *b = &o->s->v[a->next];
        float t = (float)urand(r);
        polyc__op_insert_after(o, v, a->x + t * (b->x - a->x) + 0.02f * polyc__rng_normal(r),
                               a->y + t * (b->y - a->y) + 0.02f * polyc__rng_normal(r));
        return "insert";
    }
    case 2:
        if (o->s->v_live < 30 || (v = pick_vertex(o, r, 0)) == POLYC__NONE)
            return "none";
        polyc__op_remove(o, v);
        return "remove";
    case 3:
        if ((v = pick_vertex(o, r, 1)) == POLYC__NONE)
            return "none";
        polyc__op_cut(o, v);
        return "cut";
    default: {
        int32_t t = pick_end(o, r, 1), h = pick_end(o, r, 0);
        if (t == POLYC__NONE || h == POLYC__NONE)
            return "none";
        polyc__op_link(o, t, h);
        return "link";
    }
    }
}

/* One random step: an edit, a batch of edits, an operator or noise. */
const char *random_step(polyc__opt *o, polyc__rng *r)
{
    int32_t v;
    const char *what;
    int k = irand(r, 21);
    if (k < 8) {
        polyc__chg_begin(o);
        what = basic_edit(o, r);
        polyc__chg_commit(o);
        return what;
    }
    if (k < 10) {
        polyc__chg_begin(o);
        int n = 2 + irand(r, 3);
        for (int i = 0; i < n; i++)
            basic_edit(o, r);
        polyc__chg_commit(o);
        return "batch";
    }
    switch (k) {
    case 10: polyc__op_overlaps(o); return "overlaps";
    case 11: polyc__op_merge(o); return "merge";
    case 12: polyc__op_split(o); return "split";
    case 13: polyc__op_zigzag(o); return "zigzag";
    case 14: polyc__op_corners(o, 0); return "corners";
    case 15: polyc__op_remove_vertices(o, 0); return "remove_vertices";
    case 16: polyc__op_add_vertices(o, 1); return "add_vertices";
    case 17: polyc__op_adjust(o, 2, irand(r, 2) ? o->touch_stamp : 0); return "adjust";
    case 18:
        if ((v = pick_vertex(o, r, 0)) != POLYC__NONE)
            polyc__hill_climb(o, v);
        return "hill_climb";
    case 19: polyc__op_trim_ends(o); return "trim_ends";
    default:
        polyc__op_noise(o, 0.02f);
        rebuild(o);
        return "noise";
    }
}

/* point at arc length t along the room's walls, counter-clockwise from
 * its lower-left corner */
void perimeter_at(double t, float *x, float *y)
{
    const double w = ROOM_X1 - ROOM_X0, h = ROOM_Y1 - ROOM_Y0;
    t = fmod(t, 2.0 * (w + h));
    if (t < w) {
        *x = (float)(ROOM_X0 + t);
        *y = (float)ROOM_Y0;
    } else if (t < w + h) {
        *x = (float)ROOM_X1;
        *y = (float)(ROOM_Y0 + t - w);
    } else if (t < 2.0 * w + h) {
        *x = (float)(ROOM_X1 - (t - w - h));
        *y = (float)ROOM_Y1;
    } else {
        *x = (float)ROOM_X0;
        *y = (float)(ROOM_Y1 - (t - 2.0 * w - h));
    }
}

/* A start map for random edits: five open polylines along the walls with a
 * vertex every 8 cm (1 cm jitter), small gaps between them, two of them
 * running clockwise; one has 88 vertices (more segments than a change
 * lists). About 170 vertices. */
void make_start_map(polyc__opt *o, polyc__rng *r)
{
    static const double piece[5][3] = {
        {0.10, 2.00, 0}, {2.12, 3.95, 1}, {4.05, 11.0, 1}, {11.1, 12.6, 0}, {12.7, 13.9, 0}};
    clear_lines(o);
    for (int k = 0; k < 5; k++) {
        int32_t l = polyc__line_new(o->s);
        assert_true(l != POLYC__NONE);
        int n = (int)((piece[k][1] - piece[k][0]) / 0.08) + 1;
        for (int i = 0; i < n; i++) {
            double t = piece[k][2] > 0.0 ? piece[k][1] - 0.08 * i : piece[k][0] + 0.08 * i;
            float x, y;
            perimeter_at(t, &x, &y);
            x += 0.01f * polyc__rng_normal(r);
            y += 0.01f * polyc__rng_normal(r);
            assert_true(polyc__vertex_append(o->s, l, x, y) != POLYC__NONE);
        }
    }
    rebuild(o);
}

/* Random steps from the start map, rebuilt when fewer than 40 vertices are
 * left; the books are checked after every step. */
void run_random(polyc__opt *o, uint64_t seed, int steps)
{
    polyc__rng r = {seed};
    char where[128];
    make_start_map(o, &r);
    check_books(o, "start map");
    for (int i = 0; i < steps; i++) {
        if (o->s->v_live < 40)
            make_start_map(o, &r);
        const char *what = random_step(o, &r);
        snprintf(where, sizeof where, "seed %llu step %d (%s)", (unsigned long long)seed, i, what);
        check_books(o, where);
    }
}

/* ---- bookkeeping ---- */

/* the polyline's vertices in order (either direction), against xy, within
 * tol metres (0: exact) */
void assert_line_near(const polyc__opt *o, int32_t l, const float *xy, int n, float tol)
{
    const polyc__line *ln = &o->s->l[l];
    int32_t v = ln->head;
    int fwd = 1, bwd = 1;
    if (ln->count != n)
        fail_msg("line %d has %d vertices, expected %d", l, ln->count, n);
    for (int k = 0; k < n; k++) {
        const polyc__vertex *p = &o->s->v[v];
        fwd &= fabsf(p->x - xy[2 * k]) <= tol && fabsf(p->y - xy[2 * k + 1]) <= tol;
        bwd &= fabsf(p->x - xy[2 * (n - 1 - k)]) <= tol && fabsf(p->y - xy[2 * (n - 1 - k) + 1]) <= tol;
        v = p->next;
    }
    if (!fwd && !bwd) {
        dump_map(o, "unexpected polyline");
        fail_msg("line %d is not the expected polyline", l);
    }
}

void assert_line_is(const polyc__opt *o, int32_t l, const float *xy, int n)
{
    assert_line_near(o, l, xy, n, 0.0f);
}

/* the longest stretch of segment samples (every 1 cm) with no data point
 * within 5 cm, over the whole map, metres */
double longest_unsupported(const polyc__opt *o)
{
    const polyc__vertex *V = o->s->v;
    double worst = 0.0;
    for (int32_t a = 0; a < o->s->v_high; a++) {
        if (!seg_live(o, a))
            continue;
        const polyc__vertex *b = &V[V[a].next];
        double dx = (double)(b->x - V[a].x), dy = (double)(b->y - V[a].y);
        double len = sqrt(dx * dx + dy * dy);
        int n = (int)ceil(len / 0.01);
        double run = 0.0;
        for (int k = 0; k <= n; k++) {
            double x = (double)V[a].x + dx * k / n, y = (double)V[a].y + dy * k / n;
            int near = 0;
            for (int32_t i = 0; i < o->d.np && !near; i++) {
                double ex = (double)o->d.pts[i].x - x, ey = (double)o->d.pts[i].y - y;
                near = ex * ex + ey * ey <= 0.0025;
            }
            run = near ? 0.0 : run + len / n;
            if (run > worst)
                worst = run;
        }
    }
    return worst;
}

/* Hand-made beams on the fixture's optimiser, as a single scan would set
 * them: `count` beams from (x, y), the first at `base` rad, `step` apart. */
polyc__rays *set_rays(polyc__opt *o, float x, float y, float base, float step,
                             const float *range, int32_t count)
{
    polyc__rays *r = &o->rays;
    memset(r, 0, sizeof *r);
    r->on = 1;
    r->x = x;
    r->y = y;
    r->base = base;
    r->step = step;
    r->step_cos = cosf(step);
    r->step_sin = sinf(step);
    r->count = count;
    r->turn = (int32_t)lround(2.0 * PI_D / (double)step);
    r->range = range;
    r->min_m = 0.05f;
    r->max_m = 30.0f;
    r->tol_m = POLYC__RAY_TOLERANCE_M;
    r->own_m = 0.15f;
    return r;
}
