/* gtfloor.c - the precision the data themselves allow: the "line-fit floor"
 * and the "ideal fit" of a simulated scene (gtscore.h).
 *
 * The scenes' poses carry small alignment errors that persist over runs of
 * scans, so the endpoints along a wall can sit a centimetre or two off the
 * true wall, all on the same side. No map fitted to those endpoints can be
 * closer to the truth than they are. The floor measures that: every
 * endpoint within FLOOR_NEAR_M of the interior of a true wall segment is
 * given to that segment and to the side its sensor was on; a straight line
 * is fitted by least squares to each side's endpoints (offset across the
 * wall as a linear function of the position along it); the floor is the RMS,
 * over the 2 cm stretches of wall that hold endpoints, of that line's
 * distance to the true wall. A perfect map of straight walls fitted to the
 * data would score about this precision, if it knew that the stretches of a
 * wall seen from different rooms lie on one line.
 *
 * The ideal fit does not assume that: the map `ideal` counts, one segment
 * per run of seen samples on each wall side, each fitted by least squares to
 * its own run's endpoints and measured at the run's seen samples. Where
 * each room's scans carry their own pose errors (office), it is the higher.
 *
 * SPDX-License-Identifier: MIT
 */
#include "gtscore.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FLOOR_NEAR_M 0.06   /* endpoints this close to a wall are its own */
#define FLOOR_BIN_M 0.02    /* stretches of wall, as the `seen` samples */
#define FLOOR_MIN_POINTS 20 /* a side seen by fewer endpoints is left out */

typedef struct side_fit {
    double n, st, ss, stt, sts; /* sums of 1, t, offset, t^2, t * offset */
    uint32_t first_bin;         /* into the bin bitmap */
} side_fit;

typedef struct wall_seg {
    double ax, ay, ux, uy, len; /* start, unit direction, length */
} wall_seg;

static uint32_t collect_segments(const gtscore_truth *truth, wall_seg *out)
{
    uint32_t n = 0;
    for (uint32_t w = 0; w < truth->wall_count; w++) {
        const gtscore_wall *wall = &truth->walls[w];
        uint32_t k = wall->point_count, m = wall->closed ? k : (k ? k - 1 : 0);
        for (uint32_t i = 0; i < m && k >= 2; i++) {
            const double *a = truth->wall_xy_m + 2 * (wall->first_point + i);
            const double *b = truth->wall_xy_m + 2 * (wall->first_point + (i + 1) % k);
            double dx = b[0] - a[0], dy = b[1] - a[1], len = sqrt(dx * dx + dy * dy);
            if (!(len > 0.0))
                continue;
            if (out) {
                out[n].ax = a[0];
                out[n].ay = a[1];
                out[n].ux = dx / len;
                out[n].uy = dy / len;
                out[n].len = len;
            }
            n++;
        }
    }
    return n;
}

/* The endpoint of a reflected beam; 0 for a beam without return. */
static int endpoint_xy(const polyc_scan *sc, uint32_t i, double *x, double *y)
{
    if (!gtscore_beam_reflected(sc, i))
        return 0;
    double a = sc->pose_theta_rad + (double)sc->start_angle_rad +
               (double)i * (double)sc->angle_step_rad;
    *x = sc->pose_x_m + (double)sc->range_m[i] * cos(a);
    *y = sc->pose_y_m + (double)sc->range_m[i] * sin(a);
    return 1;
}

/* The nearest wall segment within near_m whose interior (x, y) projects
 * onto, with the position along it and the signed offset across it;
 * UINT32_MAX if none. */
static uint32_t face_of(const gtscore_truth *truth, const wall_seg *segs, uint32_t ns, double x,
                        double y, double near_m, double *t_out, double *off_out)
{
    if (gtscore_index_distance(&truth->index, x, y, near_m) > near_m)
        return UINT32_MAX;
    double best = near_m;
    uint32_t best_s = UINT32_MAX;
    for (uint32_t s = 0; s < ns; s++) {
        const wall_seg *g = &segs[s];
        double px = x - g->ax, py = y - g->ay;
        double t = px * g->ux + py * g->uy, off = py * g->ux - px * g->uy;
        if (t < 0.0 || t > g->len || fabs(off) > best)
            continue;
        best = fabs(off);
        *t_out = t;
        *off_out = off;
        best_s = s;
    }
    return best_s;
}

/* face_of for the endpoint of scan sc's beam i at FLOOR_NEAR_M; UINT32_MAX
 * for a beam without return too. */
static uint32_t beam_face(const gtscore_truth *truth, const wall_seg *segs, uint32_t ns,
                          const polyc_scan *sc, uint32_t i, double *t_out, double *off_out)
{
    double x, y;
    if (!endpoint_xy(sc, i, &x, &y))
        return UINT32_MAX;
    return face_of(truth, segs, ns, x, y, FLOOR_NEAR_M, t_out, off_out);
}

static void fit_add(side_fit *f, double t, double off)
{
    f->n += 1.0;
    f->st += t;
    f->ss += off;
    f->stt += t * t;
    f->sts += t * off;
}

/* The least-squares line's offset at position t (its mean offset when the
 * positions do not spread). */
static double fitted_offset(const side_fit *f, double t)
{
    double mt = f->st / f->n, ms = f->ss / f->n;
    double var = f->stt / f->n - mt * mt;
    double slope = var > 1e-12 ? (f->sts / f->n - mt * ms) / var : 0.0;
    return ms + slope * (t - mt);
}

/* The RMS of fitted lines' offsets from the true wall (0 at the wall) at
 * the positions added; -1 when none was. */
typedef struct rms_sum {
    double sum, count;
} rms_sum;

static void rms_add(rms_sum *r, const side_fit *f, double t)
{
    double e = fitted_offset(f, t);
    r->sum += e * e;
    r->count += 1.0;
}

static double rms_of(const rms_sum *r)
{
    return r->count > 0.0 ? sqrt(r->sum / r->count) : -1.0;
}

int gtscore_line_floor(const gtscore_truth *truth, const polyc_scan *scans, uint32_t scan_count,
                       double *floor_m)
{
    uint32_t ns = collect_segments(truth, NULL);
    *floor_m = -1.0;
    if (ns == 0)
        return 0;
    wall_seg *segs = calloc(ns, sizeof *segs);
    side_fit *fits = calloc(2 * (size_t)ns, sizeof *fits);
    if (!segs || !fits) {
        free(segs);
        free(fits);
        return -1;
    }
    collect_segments(truth, segs);
    size_t bins = 0;
    for (uint32_t s = 0; s < ns; s++)
        for (int side = 0; side < 2; side++) {
            fits[2 * s + (uint32_t)side].first_bin = (uint32_t)bins;
            bins += (size_t)(segs[s].len / FLOOR_BIN_M) + 1;
        }
    unsigned char *seen = calloc(bins, 1);
    if (!seen) {
        free(segs);
        free(fits);
        return -1;
    }
    for (uint32_t k = 0; k < scan_count; k++) {
        const polyc_scan *sc = &scans[k];
        for (uint32_t i = 0; i < sc->beam_count; i++) {
            double best_t = 0.0, best_off = 0.0;
            uint32_t best_s = beam_face(truth, segs, ns, sc, i, &best_t, &best_off);
            if (best_s == UINT32_MAX)
                continue;
            const wall_seg *g = &segs[best_s];
            double sx = sc->pose_x_m - g->ax, sy = sc->pose_y_m - g->ay;
            int side = sy * g->ux - sx * g->uy > 0.0;
            side_fit *f = &fits[2 * best_s + (uint32_t)side];
            fit_add(f, best_t, best_off);
            seen[f->first_bin + (uint32_t)(best_t / FLOOR_BIN_M)] = 1;
        }
    }
    rms_sum rms = {0.0, 0.0};
    for (uint32_t s = 0; s < ns; s++)
        for (int side = 0; side < 2; side++) {
            const side_fit *f = &fits[2 * s + (uint32_t)side];
            if (f->n < FLOOR_MIN_POINTS)
                continue;
            uint32_t nb = (uint32_t)(segs[s].len / FLOOR_BIN_M) + 1;
            for (uint32_t b = 0; b < nb; b++)
                if (seen[f->first_bin + b])
                    rms_add(&rms, f, ((double)b + 0.5) * FLOOR_BIN_M);
        }
    *floor_m = rms_of(&rms);
    free(seen);
    free(fits);
    free(segs);
    return 0;
}

/* ---- the ideal map fitted to the data ------------------------------------ */

#define IDEAL_ON_M 0.005   /* a seen sample lies on the wall it was taken from */
#define IDEAL_GAP_M 0.03   /* seen samples are <= 2 cm apart within a run */
#define IDEAL_RUN_M 0.20   /* shorter runs are not in `ideal` (scansim_io.c) */
#define IDEAL_SLACK_M 0.01 /* endpoints this far past a run's ends are its own */

typedef struct seen_on_face {
    uint32_t face;
    double t;
} seen_on_face;

typedef struct seen_run {
    uint32_t face, first, count; /* samples first..first+count-1 of the sorted list */
    double t0, t1;
    side_fit fit;
} seen_run;

static int by_face_then_t(const void *pa, const void *pb)
{
    const seen_on_face *a = pa, *b = pb;
    if (a->face != b->face)
        return a->face < b->face ? -1 : 1;
    return (a->t > b->t) - (a->t < b->t);
}

/* The run of face `face` (runs sorted by face, then position) that holds
 * position t, or NULL. */
static seen_run *run_at(seen_run *runs, uint32_t nr, uint32_t face, double t)
{
    uint32_t lo = 0, hi = nr;
    while (lo < hi) { /* the first run of this face */
        uint32_t mid = lo + (hi - lo) / 2;
        if (runs[mid].face < face)
            lo = mid + 1;
        else
            hi = mid;
    }
    for (uint32_t r = lo; r < nr && runs[r].face == face; r++)
        if (t >= runs[r].t0 - IDEAL_SLACK_M && t <= runs[r].t1 + IDEAL_SLACK_M)
            return &runs[r];
    return NULL;
}

int gtscore_ideal_fit(const gtscore_truth *truth, const polyc_scan *scans, uint32_t scan_count,
                      double *fit_m)
{
    uint32_t ns = collect_segments(truth, NULL), n = 0, nr = 0;
    *fit_m = -1.0;
    if (ns == 0 || truth->seen_count == 0)
        return 0;
    wall_seg *segs = calloc(ns, sizeof *segs);
    seen_on_face *on = calloc(truth->seen_count, sizeof *on);
    seen_run *runs = calloc(truth->seen_count, sizeof *runs);
    if (!segs || !on || !runs) {
        free(segs);
        free(on);
        free(runs);
        return -1;
    }
    collect_segments(truth, segs);
    for (uint32_t i = 0; i < truth->seen_count; i++) {
        double off = 0.0;
        on[n].face = face_of(truth, segs, ns, truth->seen_xy_m[2u * i],
                             truth->seen_xy_m[2u * i + 1u], IDEAL_ON_M, &on[n].t, &off);
        if (on[n].face != UINT32_MAX)
            n++;
    }
    qsort(on, n, sizeof *on, by_face_then_t);
    for (uint32_t i = 0; i < n; i++) {
        seen_run *r = nr ? &runs[nr - 1] : NULL;
        if (r && r->face == on[i].face && on[i].t - r->t1 <= IDEAL_GAP_M) {
            r->t1 = on[i].t;
            r->count++;
            continue;
        }
        r = &runs[nr++];
        r->face = on[i].face;
        r->first = i;
        r->count = 1;
        r->t0 = r->t1 = on[i].t;
    }
    for (uint32_t k = 0; k < scan_count; k++) {
        const polyc_scan *sc = &scans[k];
        for (uint32_t i = 0; i < sc->beam_count; i++) {
            double t = 0.0, off = 0.0;
            uint32_t s = beam_face(truth, segs, ns, sc, i, &t, &off);
            seen_run *r = s == UINT32_MAX ? NULL : run_at(runs, nr, s, t);
            if (r)
                fit_add(&r->fit, t, off);
        }
    }
    rms_sum rms = {0.0, 0.0};
    for (uint32_t r = 0; r < nr; r++) {
        if (runs[r].t1 - runs[r].t0 < IDEAL_RUN_M || runs[r].fit.n < 1.0)
            continue;
        for (uint32_t i = runs[r].first; i < runs[r].first + runs[r].count; i++)
            rms_add(&rms, &runs[r].fit, on[i].t);
    }
    *fit_m = rms_of(&rms);
    free(segs);
    free(on);
    free(runs);
    return 0;
}
