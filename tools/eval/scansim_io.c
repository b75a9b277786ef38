/* scansim_io.c - what the simulator gives out (see scansim.h): the count
 * of seen samples, the ideal vertex count, the ROBOTLASER1 log and the
 * ground-truth file.
 */
#include "scansim.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>

#define SCANSIM_MIN_STRETCH_M 0.20 /* a seen stretch shorter is not mapped */

uint32_t scansim_seen_count(const scansim_scene *scene)
{
    uint32_t i, n = 0;
    for (i = 0; i < scene->sample_count; i++)
        n += scene->sample_seen[i];
    return n;
}

/* Ideal vertices of one run of seen samples first..first+len-1 (mod count). */
static uint32_t run_vertices(const scansim_scene *scene, uint32_t w, const uint8_t *corner,
                             uint32_t first, uint32_t len)
{
    uint32_t count = scene->wall_sample_count[w], k, corners = 0;
    const double *xy = &scene->sample_xy_m[2u * scene->wall_first_sample[w]];
    double length = 0.0;
    for (k = 1; k < len; k++) {
        uint32_t a = (first + k - 1u) % count, b = (first + k) % count;
        length += hypot(xy[2u * b] - xy[2u * a], xy[2u * b + 1u] - xy[2u * a + 1u]);
        if (k + 1u < len && corner[b])
            corners++;
    }
    return length >= SCANSIM_MIN_STRETCH_M ? 2u + corners : 0u;
}

uint32_t scansim_ideal_vertices(const scansim_scene *scene)
{
    uint32_t w, ideal = 0;
    for (w = 0; w < scene->wall_count; w++) {
        const scansim_wall *wall = &scene->walls[w];
        uint32_t count = scene->wall_sample_count[w];
        const uint8_t *seen = &scene->sample_seen[scene->wall_first_sample[w]];
        const uint8_t *corner = &scene->sample_corner[scene->wall_first_sample[w]];
        uint32_t j, k, start, run = 0, run_first = 0;
        for (k = 0; k < count && seen[k]; k++)
            ;
        if (k == count) { /* corners, or two ends plus inner corners */
            ideal += wall->point_count;
            continue;
        }
        /* Start just after an unseen sample so no run is cut in two. */
        start = wall->closed ? k : 0u;
        for (j = 0; j < count; j++) {
            uint32_t idx = (start + j) % count;
            if (seen[idx]) {
                if (run++ == 0)
                    run_first = idx;
            } else if (run) {
                ideal += run_vertices(scene, w, corner, run_first, run);
                run = 0;
            }
        }
        if (run)
            ideal += run_vertices(scene, w, corner, run_first, run);
    }
    return ideal;
}

/* ---- parameters with arcs and circles ------------------------------------- */

/* The samples a..b (mod count) of wall w stray over SCANSIM_ARC_MIN_SAGITTA_M
 * from the chord a-b, and one inside runs through a smooth point. */
static int piece_is_arc(const scansim_scene *scene, uint32_t w, uint32_t a, uint32_t b)
{
    uint32_t count = scene->wall_sample_count[w], k;
    const double *xy = &scene->sample_xy_m[2u * scene->wall_first_sample[w]];
    const uint8_t *smooth = &scene->sample_smooth[scene->wall_first_sample[w]];
    int through = 0;
    double far = 0.0;
    for (k = (a + 1u) % count; k != b; k = (k + 1u) % count) {
        through |= smooth[k];
        far = fmax(far, scansim_point_segment_m(xy[2u * k], xy[2u * k + 1u], &xy[2u * a],
                                                &xy[2u * b]));
    }
    return through && far > SCANSIM_ARC_MIN_SAGITTA_M;
}

/* The vertices and arcs of the run of samples first..first+len-1 (mod
 * count) of wall w, closed_all: the wall seen all round (no ends). */
static void run_params(const scansim_scene *scene, uint32_t w, uint32_t first, uint32_t len,
                       int closed_all, uint32_t *vertices, uint32_t *arcs)
{
    uint32_t count = scene->wall_sample_count[w], k, prev = UINT32_MAX, first_v = UINT32_MAX;
    const double *xy = &scene->sample_xy_m[2u * scene->wall_first_sample[w]];
    const uint8_t *corner = &scene->sample_corner[scene->wall_first_sample[w]];
    const uint8_t *smooth = &scene->sample_smooth[scene->wall_first_sample[w]];
    double length = 0.0;
    *vertices = *arcs = 0;
    for (k = 1; k < len; k++) {
        uint32_t a = (first + k - 1u) % count, b = (first + k) % count;
        length += hypot(xy[2u * b] - xy[2u * a], xy[2u * b + 1u] - xy[2u * a + 1u]);
    }
    if (!closed_all && length < SCANSIM_MIN_STRETCH_M)
        return;
    for (k = 0; k < len; k++) {
        uint32_t i = (first + k) % count;
        int end = !closed_all && (k == 0 || k + 1u == len);
        if (!end && !(corner[i] && !smooth[i]))
            continue;
        (*vertices)++;
        if (prev != UINT32_MAX)
            *arcs += (uint32_t)piece_is_arc(scene, w, prev, i);
        else
            first_v = i;
        prev = i;
    }
    if (closed_all && prev != UINT32_MAX)
        *arcs += (uint32_t)piece_is_arc(scene, w, prev, first_v == prev ? (prev + count - 1u) % count
                                                                         : first_v);
}

uint32_t scansim_ideal_params(const scansim_scene *scene, uint32_t *arcs_out, uint32_t *circles_out)
{
    uint32_t w, params = 0, arcs = 0, circles = 0, v, a;
    for (w = 0; w < scene->wall_count; w++) {
        const scansim_wall *wall = &scene->walls[w];
        uint32_t count = scene->wall_sample_count[w];
        const uint8_t *seen = &scene->sample_seen[scene->wall_first_sample[w]];
        uint32_t j, k, start, run = 0, run_first = 0;
        for (k = 0; k < count && seen[k]; k++)
            ;
        if (k == count && wall->closed) {
            run_params(scene, w, 0, count, 1, &v, &a);
            if (v == 0) {      /* no corner: a circle */
                circles++;
                params += 3u;
            } else {
                params += 2u * v + a;
                arcs += a;
            }
            continue;
        }
        start = wall->closed && k < count ? k : 0u;
        for (j = 0; j <= count; j++) {
            uint32_t idx = (start + j) % count;
            if (j < count && seen[idx]) {
                if (run++ == 0)
                    run_first = idx;
            } else if (run) {
                run_params(scene, w, run_first, run, 0, &v, &a);
                params += 2u * v + a;
                arcs += a;
                run = 0;
            }
        }
    }
    if (arcs_out)
        *arcs_out = arcs;
    if (circles_out)
        *circles_out = circles;
    return params;
}

/* ---- output ------------------------------------------------------------- */

int scansim_write_log(const scansim_scene *scene, FILE *out)
{
    uint32_t s, i;
    const scansim_laser *laser = &scene->laser;
    fprintf(out, "# simulated scans of scene %s, seed %llu (libpolyc scansim)\n", scene->name,
            (unsigned long long)scene->seed);
    for (s = 0; s < scene->scan_count; s++) {
        const polyc_scan *scan = &scene->scans[s];
        double fov = (double)(scan->beam_count - 1u) * (double)scan->angle_step_rad;
        double time_s = 1000.0 + 0.1 * (double)s;
        fprintf(out, "ROBOTLASER1 0 %.9f %.9f %.9f %.3f %.3f 0 %u",
                (double)scan->start_angle_rad, fov, (double)scan->angle_step_rad,
                (double)laser->max_range_m, (double)laser->range_sigma_m, scan->beam_count);
        for (i = 0; i < scan->beam_count; i++)
            fprintf(out, " %.3f", (double)scan->range_m[i]);
        /* no remissions; laser pose = robot pose; tv rv safety turn_axis */
        fprintf(out, " 0 %.6f %.6f %.6f %.6f %.6f %.6f 0 0 0 0 0 %.3f sim %.3f\n",
                scan->pose_x_m, scan->pose_y_m, scan->pose_theta_rad, scan->pose_x_m,
                scan->pose_y_m, scan->pose_theta_rad, time_s, time_s);
    }
    return ferror(out) ? -1 : 0;
}

int scansim_write_gt(const scansim_scene *scene, FILE *out)
{
    uint32_t w, i;
    fprintf(out,
            "# ground truth of scene %s seed %llu: sigma_range %.3f m, %u scans, %llu points\n",
            scene->name, (unsigned long long)scene->seed, (double)scene->laser.range_sigma_m,
            scene->scan_count, (unsigned long long)scene->hit_count);
    fprintf(out, "# ideal N: vertices of a perfect map of the seen walls (every seen stretch\n"
                 "# of at least 20 cm traced: its two ends plus the true corners inside it)\n");
    fprintf(out, "ideal %u\n", scansim_ideal_vertices(scene));
    {
        uint32_t arcs, circles, params = scansim_ideal_params(scene, &arcs, &circles);
        fprintf(out, "# ideal_params P A C: parameters of a perfect map of the seen walls with\n"
                     "# arcs and circles (2 a vertex, 1 an arc, 3 a circle), its arcs, its circles\n");
        fprintf(out, "ideal_params %u %u %u\n", params, arcs, circles);
    }
    fprintf(out, "# wall closed|open x1 y1 x2 y2 ... (metres)\n");
    for (w = 0; w < scene->wall_count; w++) {
        const scansim_wall *wall = &scene->walls[w];
        fprintf(out, "wall %s", wall->closed ? "closed" : "open");
        for (i = 0; i < wall->point_count; i++)
            fprintf(out, " %.4f %.4f", scene->wall_xy_m[2u * (wall->first_point + i)],
                    scene->wall_xy_m[2u * (wall->first_point + i) + 1u]);
        fputc('\n', out);
    }
    fprintf(out, "# seen x y: true wall samples every 2 cm that the scanner observed\n");
    for (i = 0; i < scene->sample_count; i++)
        if (scene->sample_seen[i])
            fprintf(out, "seen %.4f %.4f\n", scene->sample_xy_m[2u * i],
                    scene->sample_xy_m[2u * i + 1u]);
    return ferror(out) ? -1 : 0;
}

static int save_one(const scansim_scene *scene, const char *path,
                    int (*write)(const scansim_scene *, FILE *))
{
    FILE *f = fopen(path, "w");
    int rc, saved;
    if (!f)
        return -1;
    rc = write(scene, f);
    saved = errno;
    if (fclose(f) != 0)
        rc = -1;
    else
        errno = saved;
    return rc;
}

int scansim_save(const scansim_scene *scene, const char *log_path, const char *gt_path)
{
    if (log_path && save_one(scene, log_path, scansim_write_log) != 0)
        return -1;
    if (gt_path && save_one(scene, gt_path, scansim_write_gt) != 0)
        return -1;
    return 0;
}
