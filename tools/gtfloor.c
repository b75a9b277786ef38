/* gtfloor.c - the precision the data themselves allow: the "line-fit floor"
 * of a simulated scene (gtscore.h).
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
 * data would score about this precision.
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
            if (!gtscore_beam_reflected(sc, i))
                continue;
            double a = sc->pose_theta_rad + (double)sc->start_angle_rad +
                       (double)i * (double)sc->angle_step_rad;
            double x = sc->pose_x_m + (double)sc->range_m[i] * cos(a);
            double y = sc->pose_y_m + (double)sc->range_m[i] * sin(a);
            if (gtscore_index_distance(&truth->index, x, y, FLOOR_NEAR_M) > FLOOR_NEAR_M)
                continue;
            /* the nearest segment whose interior the endpoint projects onto */
            double best = FLOOR_NEAR_M, best_t = 0.0, best_off = 0.0;
            uint32_t best_s = UINT32_MAX;
            for (uint32_t s = 0; s < ns; s++) {
                const wall_seg *g = &segs[s];
                double px = x - g->ax, py = y - g->ay;
                double t = px * g->ux + py * g->uy, off = py * g->ux - px * g->uy;
                if (t < 0.0 || t > g->len || fabs(off) > best)
                    continue;
                best = fabs(off);
                best_t = t;
                best_off = off;
                best_s = s;
            }
            if (best_s == UINT32_MAX)
                continue;
            const wall_seg *g = &segs[best_s];
            double sx = sc->pose_x_m - g->ax, sy = sc->pose_y_m - g->ay;
            int side = sy * g->ux - sx * g->uy > 0.0;
            side_fit *f = &fits[2 * best_s + (uint32_t)side];
            f->n += 1.0;
            f->st += best_t;
            f->ss += best_off;
            f->stt += best_t * best_t;
            f->sts += best_t * best_off;
            seen[f->first_bin + (uint32_t)(best_t / FLOOR_BIN_M)] = 1;
        }
    }
    double sum = 0.0, count = 0.0;
    for (uint32_t s = 0; s < ns; s++)
        for (int side = 0; side < 2; side++) {
            const side_fit *f = &fits[2 * s + (uint32_t)side];
            if (f->n < FLOOR_MIN_POINTS)
                continue;
            double mt = f->st / f->n, ms = f->ss / f->n;
            double var = f->stt / f->n - mt * mt;
            double slope = var > 1e-12 ? (f->sts / f->n - mt * ms) / var : 0.0;
            uint32_t nb = (uint32_t)(segs[s].len / FLOOR_BIN_M) + 1;
            for (uint32_t b = 0; b < nb; b++) {
                if (!seen[f->first_bin + b])
                    continue;
                double t = ((double)b + 0.5) * FLOOR_BIN_M;
                double e = ms + slope * (t - mt);
                sum += e * e;
                count += 1.0;
            }
        }
    *floor_m = count > 0.0 ? sqrt(sum / count) : -1.0;
    free(seen);
    free(fits);
    free(segs);
    return 0;
}
