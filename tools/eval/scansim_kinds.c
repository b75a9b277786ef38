/* scansim_kinds.c - the simulator's randomised scene kinds (see scansim.h):
 * hall, shelves, flat, curved, thinwalls.
 *
 * Takes a scene fresh from scansim_scene_init; gives walls, a path and
 * people drawn from scene->seed (a splitmix64 stream of its own, apart from
 * the noise stream of scansim_run). Each kind fixes its structure (outline,
 * rows, rooms, partitions) with random sizes and places, lays the robot's
 * path through it, then places furniture and people by rejection: a piece
 * is kept only if it stays PATH_CLEAR_M off the path and clear of every
 * wall, a person only if they stay in free space, in view of the robot and
 * away from it. The whole scene is then turned by a random angle and
 * shifted, as the fixed scenes are. (Random draws are never two arguments
 * of one call: C leaves their order to the compiler.) The placing by
 * rejection and the path are scansim_layout.c's (scansim_layout.h).
 */
#include "scansim.h"

#include <math.h>
#include <string.h>

#include "scansim_layout.h"

/* ---- hall -------------------------------------------------------------------- */

/* A 25-40 m hall with a bay in its south wall, seen by a 30 m, 361-beam
 * scanner. Square pillars and round columns (32-gons) stand on a jittered
 * grid wherever the path leaves room; display cases lie at random angles.
 * The robot drives either a loop or a lawnmower. */
int scansim_kind_hall(scansim_scene *s)
{
    layout L;
    double w, h, bx, bw, bd, grid, ox, oy, gx, gy, outline[16];
    int rc = 0;
    layout_init(&L, s, UINT64_C(0x68616c6c));
    s->laser.beam_count = 361u;
    s->laser.angle_step_rad = (float)(PI / 360.0);
    s->laser.max_range_m = 30.0f;
    w = urange(&L.rng, 25.0, 40.0);
    h = urange(&L.rng, 25.0, 40.0);
    bw = urange(&L.rng, 3.0, 6.0);
    bd = urange(&L.rng, 1.0, 2.0);
    bx = urange(&L.rng, 3.0, w - 3.0 - bw);
    {
        const double pts[16] = {0.0, 0.0, bx, 0.0, bx, -bd, bx + bw, -bd,
                                bx + bw, 0.0, w, 0.0, w, h, 0.0, h};
        memcpy(outline, pts, sizeof outline);
    }
    L.outline = s->wall_count;
    rc |= scansim_add_wall(s, outline, 8u, 1);
    if (scansim_rng_uniform(&L.rng) < 0.5) {
        double i = urange(&L.rng, 3.0, 5.0);
        layout_way(&L, i, i);
        layout_way(&L, w - i, i);
        layout_way(&L, w - i, h - i);
        layout_way(&L, i, h - i);
        layout_way(&L, i, i + 0.2);
    } else {
        double m = urange(&L.rng, 2.5, 4.0), lane = urange(&L.rng, 6.0, 9.0), y;
        uint32_t k = 0;
        for (y = m; y <= h - m + 1e-9; y += lane, k++) {
            layout_way(&L, k % 2u ? w - m : m, y);
            layout_way(&L, k % 2u ? m : w - m, y);
        }
    }
    rc |= layout_path(&L, 800.0);
    /* pillars and columns on a grid of 6-9 m, each node jittered by 0.3 m */
    grid = urange(&L.rng, 6.0, 9.0);
    ox = urange(&L.rng, 2.0, 2.0 + grid);
    oy = urange(&L.rng, 2.0, 2.0 + grid);
    L.first_object = s->wall_count;
    for (gx = ox; gx < w - 1.5 && rc == 0; gx += grid)
        for (gy = oy; gy < h - 1.5 && rc == 0; gy += grid) {
            double xy[64], cx = gx + urange(&L.rng, -0.3, 0.3);
            double cy = gy + urange(&L.rng, -0.3, 0.3);
            uint32_t n = 4u, k;
            if (scansim_rng_uniform(&L.rng) < 0.5) {
                double side = urange(&L.rng, 0.4, 0.8);
                rect_xy(xy, cx, cy, side, side, scansim_rng_uniform(&L.rng) < 0.5 ? 0.0
                                                       : urange(&L.rng, 0.0, PI / 2.0));
            } else {
                double r = urange(&L.rng, 0.2, 0.5);
                for (n = 32u, k = 0; k < n; k++) {
                    xy[2u * k] = cx + r * cos(2.0 * PI * (double)k / (double)n);
                    xy[2u * k + 1u] = cy + r * sin(2.0 * PI * (double)k / (double)n);
                }
            }
            rc |= layout_try_add(&L, xy, n, 1.0) < 0;
        }
    {
        static const double case_w[2] = {0.8, 2.5}, case_h[2] = {0.4, 1.2};
        rc |= layout_scatter_boxes(&L, upick(&L.rng, 4u, 10u), case_w, case_h, -1.0, 1.0, 1.0,
                                   w - 1.0, h - 1.0, 1.0);
    }
    return layout_finish(&L, rc, 3u, 2u);
}

/* ---- shelves ------------------------------------------------------------------- */

/* 4-7 rows of shelves, 6-10 m long and 0.5-1 m deep, some rows split by a
 * cross passage, aisles of 1.5-2.4 m, cross aisles of 2.2-3.2 m at both
 * ends, a few crates; the robot drives a serpentine through every aisle. */
int scansim_kind_shelves(scansim_scene *s)
{
    layout L;
    double start_w = 0.0, cross_w, cross_e, y = 0.0, x_end = 0.0, room[8];
    double row_y0[8], row_y1[8], row_x0[8], row_x1[8], aisle_c[9];
    uint32_t rows, i;
    int rc = 0;
    layout_init(&L, s, UINT64_C(0x7368656c));
    rows = upick(&L.rng, 4u, 7u);
    cross_w = urange(&L.rng, 2.2, 3.2);
    cross_e = urange(&L.rng, 2.2, 3.2);
    for (i = 0; i < rows; i++) {
        double aisle = urange(&L.rng, 1.5, 2.4), depth = urange(&L.rng, 0.5, 1.0);
        aisle_c[i] = y + aisle / 2.0;
        row_y0[i] = y + aisle;
        row_y1[i] = row_y0[i] + depth;
        y = row_y1[i];
        row_x0[i] = cross_w + urange(&L.rng, 0.0, 0.5);
        row_x1[i] = row_x0[i] + urange(&L.rng, 6.0, 10.0);
        x_end = fmax(x_end, row_x1[i]);
    }
    aisle_c[rows] = y + urange(&L.rng, 1.5, 2.4) / 2.0;
    y = 2.0 * aisle_c[rows] - y; /* the room's north wall */
    x_end += cross_e;
    rect_xy(room, x_end / 2.0, y / 2.0, x_end, y, 0.0);
    L.outline = s->wall_count;
    rc |= scansim_add_wall(s, room, 4u, 1);
    for (i = 0; i < rows; i++) {
        double xy[8];
        if (row_x1[i] - row_x0[i] > 8.0 && scansim_rng_uniform(&L.rng) < 0.4) {
            double gap = urange(&L.rng, 1.2, 1.6);
            double cut = urange(&L.rng, row_x0[i] + 3.0, row_x1[i] - 3.0 - gap);
            rect_xy(xy, (row_x0[i] + cut) / 2.0, (row_y0[i] + row_y1[i]) / 2.0, cut - row_x0[i],
                    row_y1[i] - row_y0[i], 0.0);
            rc |= scansim_add_wall(s, xy, 4u, 1);
            start_w = cut + gap;
        } else
            start_w = row_x0[i];
        rect_xy(xy, (start_w + row_x1[i]) / 2.0, (row_y0[i] + row_y1[i]) / 2.0,
                row_x1[i] - start_w, row_y1[i] - row_y0[i], 0.0);
        rc |= scansim_add_wall(s, xy, 4u, 1);
    }
    for (i = 0; i <= rows; i++) {
        layout_way(&L, i % 2u ? x_end - cross_e / 2.0 : cross_w / 2.0, aisle_c[i]);
        layout_way(&L, i % 2u ? cross_w / 2.0 : x_end - cross_e / 2.0, aisle_c[i]);
    }
    rc |= layout_path(&L, 900.0);
    {
        uint32_t crates = upick(&L.rng, 1u, 4u), placed = 0, tries;
        L.first_object = s->wall_count;
        for (tries = 0; placed < crates && tries < PLACE_TRIES && rc == 0; tries++) {
            double along = urange(&L.rng, 0.6, 1.2), depth = urange(&L.rng, 0.4, 0.8);
            int got = layout_against_wall(&L, 0.0, 0.0, x_end, y, along, depth);
            if (got < 0)
                rc = -1;
            else
                placed += (uint32_t)got;
        }
    }
    return layout_finish(&L, rc, 2u, 2u);
}

/* ---- flat ------------------------------------------------------------------- */

#define FLAT_T 0.10 /* wall thickness */

/* Splits [0, total] into n rooms of at least min_w: the n - 1 inner
 * boundaries go to cut[]. */
static void split_widths(scansim_rng *rng, double total, uint32_t n, double min_w, double *cut)
{
    double weight[4], sum = 0.0, x = 0.0;
    uint32_t i;
    for (i = 0; i < n; i++)
        sum += weight[i] = urange(rng, 1.0, 2.0);
    for (i = 0; i + 1u < n; i++) {
        x += min_w + (total - (double)n * min_w) * weight[i] / sum;
        cut[i] = x;
    }
}

typedef struct flat_room {
    double x0, x1, y0, y1;   /* inner faces */
    double door_c;           /* door centre x */
    int north;
} flat_room;

/* A flat of 10 cm walls: a 1.2-1.6 m hallway with 2-3 rooms (2.8-4 m deep)
 * on either side, each behind a door of 0.8-0.9 m at a random place, with
 * a bed, a cupboard or a table or two. The robot drives down the hallway
 * and into each room through its door, to the middle and back out. */
int scansim_kind_flat(scansim_scene *s)
{
    const double t = FLAT_T;
    layout L;
    flat_room room[6];
    double hw, dn, ds, total, cut_n[3], cut_s[3], top, bottom;
    uint32_t nn, ns, nr = 0, i, j, order[6];
    int rc = 0;
    layout_init(&L, s, UINT64_C(0x666c6174));
    hw = urange(&L.rng, 1.2, 1.6);
    dn = urange(&L.rng, 2.8, 4.0);
    ds = urange(&L.rng, 2.8, 4.0);
    nn = upick(&L.rng, 2u, 3u);
    ns = upick(&L.rng, 2u, 3u);
    total = urange(&L.rng, 2.9, 3.8) * (double)(nn > ns ? nn : ns);
    split_widths(&L.rng, total, nn, 2.6, cut_n);
    split_widths(&L.rng, total, ns, 2.6, cut_s);
    top = hw + t + dn;
    bottom = -t - ds;
    for (i = 0; i < nn + ns; i++) {
        int north = i < nn;
        uint32_t k = north ? i : i - nn, n = north ? nn : ns;
        const double *cut = north ? cut_n : cut_s;
        flat_room *r = &room[nr++];
        double dw = urange(&L.rng, 0.8, 0.9);
        r->north = north;
        r->x0 = k == 0 ? 0.0 : cut[k - 1u] + t / 2.0;
        r->x1 = k + 1u == n ? total : cut[k] - t / 2.0;
        r->y0 = north ? hw + t : bottom;
        r->y1 = north ? top : -t;
        r->door_c = urange(&L.rng, r->x0 + 0.3 + dw / 2.0, r->x1 - 0.3 - dw / 2.0);
        /* the hallway wall on this room's side, left and right of the door */
        if (north) {
            rc |= scansim_add_box(s, r->x0 - (k ? t / 2.0 : 0.0), hw, r->door_c - dw / 2.0, hw + t);
            rc |= scansim_add_box(s, r->door_c + dw / 2.0, hw, r->x1 + (k + 1u < n ? t / 2.0 : 0.0),
                                  hw + t);
        } else {
            rc |= scansim_add_box(s, r->x0 - (k ? t / 2.0 : 0.0), -t, r->door_c - dw / 2.0, 0.0);
            rc |= scansim_add_box(s, r->door_c + dw / 2.0, -t, r->x1 + (k + 1u < n ? t / 2.0 : 0.0),
                                  0.0);
        }
        if (k + 1u < n)
            rc |= scansim_add_box(s, cut[k] - t / 2.0, north ? hw + t : bottom, cut[k] + t / 2.0,
                                  north ? top : -t);
    }
    /* outer walls */
    rc |= scansim_add_box(s, -t, bottom - t, 0.0, top + t);
    rc |= scansim_add_box(s, total, bottom - t, total + t, top + t);
    rc |= scansim_add_box(s, 0.0, top, total, top + t);
    rc |= scansim_add_box(s, 0.0, bottom - t, total, bottom);
    /* the path: down the hallway, into each room in the order of its door */
    for (i = 0; i < nr; i++)
        order[i] = i;
    for (i = 1; i < nr; i++)
        for (j = i; j > 0 && room[order[j]].door_c < room[order[j - 1u]].door_c; j--) {
            uint32_t tmp = order[j];
            order[j] = order[j - 1u];
            order[j - 1u] = tmp;
        }
    layout_way(&L, 0.6, hw / 2.0);
    for (i = 0; i < nr; i++) {
        const flat_room *r = &room[order[i]];
        double inside = r->north ? r->y0 + 0.7 : r->y1 - 0.7;
        double mx = urange(&L.rng, r->x0 + 0.9, r->x1 - 0.9);
        double my = r->y0 + (r->y1 - r->y0) * urange(&L.rng, 0.4, 0.6);
        layout_way(&L, r->door_c, hw / 2.0);
        layout_way(&L, r->door_c, inside);
        layout_way(&L, mx, my);
        layout_way(&L, r->door_c, inside);
        layout_way(&L, r->door_c, hw / 2.0);
    }
    layout_way(&L, total - 0.6, hw / 2.0);
    rc |= layout_path(&L, 600.0);
    /* furniture: a bed or a cupboard against a wall, and a table */
    L.first_object = s->wall_count;
    for (i = 0; i < nr && rc == 0; i++) {
        const flat_room *r = &room[i];
        uint32_t tries, pieces = upick(&L.rng, 1u, 3u), placed = 0;
        for (tries = 0; placed < pieces && tries < 60u; tries++) {
            double kind = scansim_rng_uniform(&L.rng);
            int got;
            if (kind < 0.7) { /* a bed or a cupboard */
                double along = kind < 0.35 ? urange(&L.rng, 1.9, 2.1) : urange(&L.rng, 0.8, 2.0);
                double depth = kind < 0.35 ? urange(&L.rng, 0.9, 1.6) : urange(&L.rng, 0.5, 0.65);
                got = layout_against_wall(&L, r->x0, r->y0, r->x1, r->y1, along, depth);
            } else {
                double xy[8], tx = urange(&L.rng, r->x0 + 0.5, r->x1 - 0.5);
                double ty = urange(&L.rng, r->y0 + 0.5, r->y1 - 0.5);
                double tw = urange(&L.rng, 1.0, 1.8), th = urange(&L.rng, 0.7, 0.9);
                rect_xy(xy, tx, ty, tw, th, urange(&L.rng, -0.3, 0.3));
                got = layout_try_add(&L, xy, 4u, 0.3); /* table */
            }
            if (got < 0)
                rc = -1;
            else
                placed += (uint32_t)got;
        }
    }
    return layout_finish(&L, rc, 1u, 2u);
}

/* ---- curved --------------------------------------------------------------------- */

/* An 8-12 m x 6-9 m room whose north wall has an apse, an arc of 2-4 m
 * radius bulging out, and often a south-east corner rounded with a radius
 * of 1.5-3 m, both as polygons of 10 cm sides; a round column and some
 * furniture. The robot drives a loop that reaches into the apse. */
int scansim_kind_curved(scansim_scene *s)
{
    layout L;
    double w, h, r, c2, d, cx, inset, outline[2u * 400u];
    uint32_t n = 0;
    int rc = 0;
    layout_init(&L, s, UINT64_C(0x63757276));
    r = urange(&L.rng, 2.0, 4.0);
    c2 = r * urange(&L.rng, 0.75, 1.0);
    d = sqrt(fmax(0.0, r * r - c2 * c2));
    w = fmax(urange(&L.rng, 8.0, 12.0), 2.0 * c2 + 3.0);
    h = urange(&L.rng, 6.0, 9.0);
    cx = urange(&L.rng, c2 + 1.5, w - c2 - 1.5);
    inset = urange(&L.rng, 1.4, 1.8);
    outline[n++] = 0.0;
    outline[n++] = 0.0;
    if (scansim_rng_uniform(&L.rng) < 0.6) {
        double rc_m = urange(&L.rng, 1.5, 3.0);
        n += 2u * arc_xy(&outline[n], 150u, w - rc_m, rc_m, rc_m, -PI / 2.0, 0.0);
    } else {
        outline[n++] = w;
        outline[n++] = 0.0;
    }
    outline[n++] = w;
    outline[n++] = h;
    n += 2u * arc_xy(&outline[n], 200u, cx, h - d, r, atan2(d, c2), PI - atan2(d, c2));
    outline[n++] = 0.0;
    outline[n++] = h;
    L.outline = s->wall_count;
    rc |= scansim_add_wall(s, outline, n / 2u, 1);
    layout_way(&L, inset, inset);
    layout_way(&L, w - inset, inset);
    layout_way(&L, w - inset, h - inset);
    layout_way(&L, cx + 0.6, h - inset);
    layout_way(&L, cx, h - d + r - 1.0);
    layout_way(&L, cx - 0.6, h - inset);
    layout_way(&L, inset, h - inset);
    layout_way(&L, inset, inset + 0.2);
    rc |= layout_path(&L, 450.0);
    L.first_object = s->wall_count;
    {
        static const double fw[2] = {0.6, 1.8}, fh[2] = {0.5, 0.9};
        double column[2u * 40u], cr = urange(&L.rng, 0.25, 0.5);
        uint32_t k, tries;
        for (tries = 0; tries < 100u; tries++) {
            double ccx = urange(&L.rng, 1.0, w - 1.0), ccy = urange(&L.rng, 1.0, h - 1.0);
            int got;
            for (k = 0; k < 40u; k++) {
                column[2u * k] = ccx + cr * cos(2.0 * PI * (double)k / 40.0);
                column[2u * k + 1u] = ccy + cr * sin(2.0 * PI * (double)k / 40.0);
            }
            got = layout_try_add(&L, column, 40u, 0.5);
            if (got != 0) {
                rc |= got < 0;
                break;
            }
        }
        rc |= layout_scatter_boxes(&L, upick(&L.rng, 2u, 4u), fw, fh, -1.0, 0.5, 0.5, w - 0.5,
                                   h - 0.5, 0.3);
    }
    return layout_finish(&L, rc, 1u, 1u);
}

/* ---- thinwalls ------------------------------------------------------------------ */

/* 3-5 free-standing partitions, 2.5-4 m long and 5-12 cm thick, each
 * tilted up to 20 degrees, in a row 2.8-3.8 m apart in a room of line
 * walls; the robot weaves between them (up before each, down after it), so
 * that it sees both faces of every partition. */
int scansim_kind_thinwalls(scansim_scene *s)
{
    layout L;
    double cx[5], cy[5], half[5], tilt[5], x = 0.0, y_lo = HUGE_VAL, y_hi = -HUGE_VAL, room[8];
    double w, h, shift;
    uint32_t k, n;
    int rc = 0;
    layout_init(&L, s, UINT64_C(0x7468696e));
    n = upick(&L.rng, 3u, 5u);
    for (k = 0; k < n; k++) {
        x += k == 0 ? 2.5 : urange(&L.rng, 2.8, 3.8);
        cx[k] = x;
        cy[k] = urange(&L.rng, -0.5, 0.5);
        half[k] = urange(&L.rng, 2.5, 4.0) / 2.0;
        tilt[k] = urange(&L.rng, -0.35, 0.35);
        y_lo = fmin(y_lo, cy[k] - half[k] * cos(tilt[k]));
        y_hi = fmax(y_hi, cy[k] + half[k] * cos(tilt[k]));
    }
    /* 0.9 m past the partitions' ends lies the path, 1.1 m further the wall */
    shift = 2.0 - y_lo;
    w = x + 2.5;
    h = y_hi + shift + 2.0;
    rect_xy(room, w / 2.0, h / 2.0, w, h, 0.0);
    L.outline = s->wall_count;
    rc |= scansim_add_wall(s, room, 4u, 1);
    for (k = 0; k < n; k++) {
        double xy[8];
        cy[k] += shift;
        rect_xy(xy, cx[k], cy[k], urange(&L.rng, 0.05, 0.12), 2.0 * half[k], -tilt[k]);
        rc |= scansim_add_wall(s, xy, 4u, 1);
    }
    for (k = 0; k <= n; k++) {
        /* the leg between partitions k - 1 and k, through their ends' and
         * centres' midpoints */
        double bx, tx, mx, my;
        if (k == 0) {
            bx = cx[0] - half[0] * sin(tilt[0]) - 1.2;
            tx = cx[0] + half[0] * sin(tilt[0]) - 1.2;
            mx = cx[0] - 1.2;
            my = cy[0];
        } else if (k == n) {
            bx = cx[n - 1u] - half[n - 1u] * sin(tilt[n - 1u]) + 1.2;
            tx = cx[n - 1u] + half[n - 1u] * sin(tilt[n - 1u]) + 1.2;
            mx = cx[n - 1u] + 1.2;
            my = cy[n - 1u];
        } else {
            bx = 0.5 * (cx[k - 1u] - half[k - 1u] * sin(tilt[k - 1u]) + cx[k] -
                        half[k] * sin(tilt[k]));
            tx = 0.5 * (cx[k - 1u] + half[k - 1u] * sin(tilt[k - 1u]) + cx[k] +
                        half[k] * sin(tilt[k]));
            mx = 0.5 * (cx[k - 1u] + cx[k]);
            my = 0.5 * (cy[k - 1u] + cy[k]);
        }
        if (k % 2u == 0) {
            layout_way(&L, bx, 1.1); layout_way(&L, mx, my); layout_way(&L, tx, h - 1.1);
        } else {
            layout_way(&L, tx, h - 1.1); layout_way(&L, mx, my); layout_way(&L, bx, 1.1);
        }
    }
    rc |= layout_path(&L, 600.0);
    L.first_object = s->wall_count;
    {
        static const double fw[2] = {0.6, 1.2}, fh[2] = {0.4, 0.8};
        rc |= layout_scatter_boxes(&L, upick(&L.rng, 0u, 2u), fw, fh, -1.0, 0.5, 0.5, w - 0.5,
                                   h - 0.5, 0.3);
    }
    return layout_finish(&L, rc, 1u, 1u);
}

/* ---- drift and farhall: poses that drift --------------------------------------- */

#define DRIFT_T 0.12         /* the drift building's wall thickness */
#define DRIFT_DOOR_M 0.9

/* The drift of the logged poses (scansim.h): m_per_m and deg_per_m per
 * sqrt(metre) travelled, pulled back to keep x the error every reset_m
 * metres. */
static void set_drift(scansim_scene *s, double m_per_m, double deg_per_m, double reset_m,
                      double keep)
{
    s->drift_m_per_m = m_per_m;
    s->drift_rad_per_m = deg_per_m * PI / 180.0;
    s->drift_reset_m = reset_m;
    s->drift_keep = keep;
}

/* A wall DRIFT_T thick along one axis from a to b (x if horizontal, else
 * y), across it from c to c + DRIFT_T, with a DRIFT_DOOR_M gap at each
 * door start (ascending, within (a, b)). */
static int wall_with_doors(scansim_scene *s, int horizontal, double a, double b, double c,
                           const double *door, uint32_t doors)
{
    double from = a;
    uint32_t k;
    int rc = 0;
    for (k = 0; k <= doors; k++) {
        double to = k < doors ? door[k] : b;
        if (to > from)
            rc |= horizontal ? scansim_add_box(s, from, c, to, c + DRIFT_T)
                             : scansim_add_box(s, c, from, c + DRIFT_T, to);
        if (k < doors)
            from = door[k] + DRIFT_DOOR_M;
    }
    return rc;
}

/* One row of offices between the outline and the corridor ring: the row
 * runs along one axis over [a, b], its corridor wall at c (across), the
 * outline at `back`; partitions every 3-4.5 m within the corridor's span
 * [lo, hi], one door per office where it faces the corridor. */
static int office_row(layout *L, int horizontal, double a, double b, double lo, double hi,
                      double c, double back)
{
    scansim_scene *s = L->s;
    /* the partitions, across: from the corridor wall's office face to the
     * outline */
    double cut[16], door[17], x, q0 = back < c ? back : c + DRIFT_T, q1 = back < c ? c : back;
    uint32_t n = 0, k, doors = 0;
    int rc = 0;
    for (x = lo + urange(&L->rng, 3.0, 4.5); x < hi - 2.5 && n < 16u;
         x += urange(&L->rng, 3.0, 4.5))
        cut[n++] = x;
    for (k = 0; k <= n; k++) {
        double o0 = fmax(k ? cut[k - 1u] + DRIFT_T / 2.0 : a, lo) + 0.3;
        double o1 = fmin(k < n ? cut[k] - DRIFT_T / 2.0 : b, hi) - 0.3 - DRIFT_DOOR_M;
        if (o1 > o0)
            door[doors++] = urange(&L->rng, o0, o1);
    }
    rc |= wall_with_doors(s, horizontal, a, b, c, door, doors);
    for (k = 0; k < n; k++)
        rc |= horizontal ? scansim_add_box(s, cut[k] - DRIFT_T / 2.0, q0, cut[k] + DRIFT_T / 2.0, q1)
                         : scansim_add_box(s, q0, cut[k] - DRIFT_T / 2.0, q1, cut[k] + DRIFT_T / 2.0);
    return rc;
}

/* An office floor of 24-32 m x 16-22 m: offices 3-4 m deep along the
 * outside, each behind a door on a corridor 1.8-2.4 m wide that runs round
 * a central block. The robot drives round the corridor three times, so
 * that every wall is seen on three passes, each with the drift of its own
 * stretch: 1 cm and 0.15 degrees per sqrt(m), halved every 5-10 m, on top
 * of 5 mm / 0.1 degree of alignment noise per scan. The endpoints of one
 * corridor wall then spread over a band of about 10 cm (5th to 95th
 * percentile across it), up to 30 cm, as on the real logs. */
int scansim_kind_drift(scansim_scene *s)
{
    layout L;
    double w, h, o, c, m, outline[8];
    uint32_t loop;
    int rc = 0;
    layout_init(&L, s, UINT64_C(0x6472696674));
    set_drift(s, 0.01, 0.15, urange(&L.rng, 5.0, 10.0), 0.5);
    s->pose_sigma_m = 0.005;
    s->pose_sigma_rad = 0.1 * PI / 180.0;
    w = urange(&L.rng, 24.0, 32.0);
    h = urange(&L.rng, 16.0, 22.0);
    o = urange(&L.rng, 3.0, 4.0);
    c = urange(&L.rng, 1.8, 2.4);
    outline[0] = 0.0; outline[1] = 0.0; outline[2] = w; outline[3] = 0.0;
    outline[4] = w; outline[5] = h; outline[6] = 0.0; outline[7] = h;
    L.outline = s->wall_count;
    rc |= scansim_add_wall(s, outline, 4u, 1);
    /* south and north rows span the width (their corridor walls close the
     * corner offices), west and east rows lie between them */
    rc |= office_row(&L, 1, 0.0, w, o, w - o, o - DRIFT_T, 0.0);
    rc |= office_row(&L, 1, 0.0, w, o, w - o, h - o, h);
    rc |= office_row(&L, 0, o, h - o, o, h - o, o - DRIFT_T, 0.0);
    rc |= office_row(&L, 0, o, h - o, o, h - o, w - o, w);
    rc |= scansim_add_box(s, o + c, o + c, w - o - c, h - o - c);
    m = o + c / 2.0;
    for (loop = 0; loop < 3u; loop++) {
        layout_way(&L, m, m);
        layout_way(&L, w - m, m);
        layout_way(&L, w - m, h - m);
        layout_way(&L, m, h - m);
    }
    layout_way(&L, m, m + 0.2);
    rc |= layout_path(&L, 1000.0);
    return layout_finish(&L, rc, 2u, 1u);
}

/* The hall (the same layout, path and people for a seed) with drift: its
 * 30 m scanner sees the far walls at 20-30 m, where 0.1 degree of heading
 * is 4-5 cm. 3 mm and 0.05 degrees per sqrt(m), reset to a third every
 * 8 m. */
int scansim_kind_farhall(scansim_scene *s)
{
    if (scansim_kind_hall(s) != 0)
        return -1;
    set_drift(s, 0.003, 0.05, 8.0, 1.0 / 3.0);
    return 0;
}
