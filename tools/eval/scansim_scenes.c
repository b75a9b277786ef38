/* scansim_scenes.c - the simulator's built-in scenes (see scansim.h).
 *
 * Takes a name and a seed; gives a scene ready for scansim_run. Each scene
 * is drawn in a convenient local frame, then rotated and shifted off the
 * grid axes, as shared/data/sim does. Sizes are kept small so that tests
 * stay fast: at most about 200 scans of 181 beams. The randomised kinds
 * (300-1,000 scans) are in scansim_kinds.c.
 */
#include "scansim.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846
#define WALL_M 0.12 /* wall thickness of the office */

/* One rectangular room (a thin closed wall), driven round once. */
static int make_square(scansim_scene *s)
{
    static const double room[] = {0.0, 0.0, 6.0, 0.0, 6.0, 4.0, 0.0, 4.0};
    static const double path[] = {1.0, 1.0, 5.0, 1.0, 5.0, 3.0, 1.0, 3.0, 1.0, 1.2};
    if (scansim_add_wall(s, room, 4u, 1) != 0 || scansim_add_path(s, path, 5u, 0.1) != 0)
        return -1;
    scansim_transform(s, 0.25, 1.3, 0.7);
    return 0;
}

/* A 16 m x 2 m corridor with 12 cm thick walls, four rooms on the north
 * side and two on the south seen only through doors, some furniture, two
 * people walking by. The robot drives down the corridor and back. */
static int make_office(scansim_scene *s)
{
    const double t = WALL_M;
    /* corridor walls, as (x0, x1) pieces between the doors */
    static const double north[] = {0.0, 1.5, 2.4, 5.5, 6.4, 9.5, 10.4, 13.5, 14.4, 16.0};
    static const double south[] = {0.0, 3.0, 3.9, 11.0, 11.9, 16.0};
    static const double path[] = {0.8, 0.8, 15.2, 0.8, 15.2, 1.2, 0.8, 1.2};
    scansim_person walker;
    uint32_t i;
    int rc = 0;

    for (i = 0; i < 10u; i += 2u)
        rc |= scansim_add_box(s, north[i], 2.0, north[i + 1u], 2.0 + t);
    for (i = 0; i < 6u; i += 2u)
        rc |= scansim_add_box(s, south[i], -t, south[i + 1u], 0.0);
    /* outer walls: west and east full height, north and south back walls */
    rc |= scansim_add_box(s, -t, -4.0 - 2.0 * t, 0.0, 6.0 + 2.0 * t);
    rc |= scansim_add_box(s, 16.0, -4.0 - 2.0 * t, 16.0 + t, 6.0 + 2.0 * t);
    rc |= scansim_add_box(s, 0.0, 6.0 + t, 16.0, 6.0 + 2.0 * t);
    rc |= scansim_add_box(s, 0.0, -4.0 - 2.0 * t, 16.0, -4.0 - t);
    /* room dividers */
    for (i = 1; i < 4u; i++)
        rc |= scansim_add_box(s, 4.0 * i - t / 2.0, 2.0 + t, 4.0 * i + t / 2.0, 6.0 + t);
    rc |= scansim_add_box(s, 8.0 - t / 2.0, -4.0 - t, 8.0 + t / 2.0, -t);
    /* furniture: a table in view of a north door, a cabinet in the south */
    rc |= scansim_add_box(s, 9.0, 4.0, 10.2, 4.6);
    rc |= scansim_add_box(s, 5.0, -3.0, 6.0, -2.4);
    rc |= scansim_add_path(s, path, 4u, 0.15);

    memset(&walker, 0, sizeof walker);
    walker.radius_m = 0.2;
    walker.from_x_m = 14.0; walker.from_y_m = 0.5;
    walker.to_x_m = 3.0;    walker.to_y_m = 1.5;
    walker.first_scan = 20u; walker.last_scan = 80u;
    rc |= scansim_add_person(s, &walker);
    walker.from_x_m = 2.0;  walker.from_y_m = 1.6;
    walker.to_x_m = 12.0;   walker.to_y_m = 0.4;
    walker.first_scan = 110u; walker.last_scan = 170u;
    rc |= scansim_add_person(s, &walker);
    if (rc != 0)
        return -1;
    scansim_transform(s, 0.3217, -3.2, 5.1);
    return 0;
}

/* A hexagonal hall (walls at 30, 90 and 150 degrees) with a triangular
 * island (0, 60, 120 degrees) and a square pillar turned by 45 degrees;
 * the robot drives one loop round the island. */
static int make_angled(scansim_scene *s)
{
    double hall[12], island[6], pillar[8], path[26];
    scansim_person walker;
    uint32_t i;
    int rc;
    for (i = 0; i < 6u; i++) {
        double a = PI / 6.0 + (double)i * PI / 3.0;
        hall[2u * i] = 7.0 * cos(a);
        hall[2u * i + 1u] = 7.0 * sin(a);
    }
    for (i = 0; i < 3u; i++) { /* equilateral, side 2.4 m */
        double a = -PI / 2.0 + (double)i * 2.0 * PI / 3.0;
        island[2u * i] = -1.2 + 2.4 / sqrt(3.0) * cos(a);
        island[2u * i + 1u] = 1.0 + 2.4 / sqrt(3.0) * sin(a);
    }
    for (i = 0; i < 4u; i++) { /* a 0.6 m square standing on a corner */
        double a = (double)i * PI / 2.0;
        pillar[2u * i] = 2.0 + 0.6 / sqrt(2.0) * cos(a);
        pillar[2u * i + 1u] = -1.6 + 0.6 / sqrt(2.0) * sin(a);
    }
    for (i = 0; i <= 12u; i++) {
        double a = (double)i * PI / 6.0;
        path[2u * i] = 4.6 * cos(a);
        path[2u * i + 1u] = 4.6 * sin(a);
    }
    rc = scansim_add_wall(s, hall, 6u, 1);
    rc |= scansim_add_wall(s, island, 3u, 1);
    rc |= scansim_add_wall(s, pillar, 4u, 1);
    rc |= scansim_add_path(s, path, 13u, 0.15);
    memset(&walker, 0, sizeof walker);
    walker.radius_m = 0.2;
    walker.from_x_m = -4.0; walker.from_y_m = -2.0;
    walker.to_x_m = 1.0;    walker.to_y_m = -4.0;
    walker.first_scan = 50u; walker.last_scan = 110u;
    rc |= scansim_add_person(s, &walker);
    if (rc != 0)
        return -1;
    scansim_transform(s, 0.1, 2.3, -1.1);
    return 0;
}

/* The paper's Fig. 11: circles of radius 1, 3 and 7 m (720-gons), each
 * seen by one noise-free-pose 360-beam scan from its centre. */
static int make_circle(scansim_scene *s)
{
    static const double radius[3] = {1.0, 3.0, 7.0};
    static const double centre_x[3] = {0.0, 12.0, 30.0};
    uint32_t i;
    s->laser.beam_count = 360u;
    s->laser.start_angle_rad = (float)-PI;
    s->laser.angle_step_rad = (float)(2.0 * PI / 360.0);
    s->laser.dropout = 0.0f;
    s->pose_sigma_m = 0.0;
    s->pose_sigma_rad = 0.0;
    for (i = 0; i < 3u; i++) {
        if (scansim_add_circle(s, centre_x[i], 0.0, radius[i], 720u) != 0 ||
            scansim_add_pose(s, centre_x[i], 0.0, 0.0) != 0)
            return -1;
    }
    return 0;
}

typedef struct builtin {
    const char *name;
    int (*make)(scansim_scene *s);
} builtin;

static const builtin builtins[] = {
    {"square", make_square},
    {"office", make_office},
    {"angled", make_angled},
    {"circle", make_circle},
    {"hall", scansim_kind_hall},
    {"shelves", scansim_kind_shelves},
    {"flat", scansim_kind_flat},
    {"curved", scansim_kind_curved},
    {"thinwalls", scansim_kind_thinwalls},
    {"drift", scansim_kind_drift},
    {"farhall", scansim_kind_farhall},
    {"pillars", scansim_kind_pillars},
    {"arcwalls", scansim_kind_arcwalls},
    {"roundmix", scansim_kind_roundmix},
};

static const char *const builtin_names[] = {"square", "office",  "angled", "circle",
                                            "hall",   "shelves", "flat",   "curved",
                                            "thinwalls", "drift", "farhall", "pillars",
                                            "arcwalls", "roundmix", NULL};

const char *const *scansim_builtin_names(void)
{
    return builtin_names;
}

int scansim_scene_builtin(scansim_scene *scene, const char *name, uint64_t seed)
{
    size_t i;
    if (!scene || !name)
        return -1;
    for (i = 0; i < sizeof builtins / sizeof builtins[0]; i++) {
        if (strcmp(name, builtins[i].name) == 0) {
            scansim_scene_init(scene, name, seed);
            if (builtins[i].make(scene) != 0) {
                scansim_scene_free(scene);
                return -1;
            }
            return 0;
        }
    }
    return -1;
}
