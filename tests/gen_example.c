/* gen_example.c - writes the bundled example: the simulator's "office"
 * scene as a ROBOTLASER1 log and its ground truth.
 *   gen_example LOG GT [SCENE [SEED]]     (`make examples` runs it)
 * The output depends only on the scene and the seed (default office, 7).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scansim.h"

int main(int argc, char **argv)
{
    const char *name = argc > 3 ? argv[3] : "office";
    uint64_t seed = argc > 4 ? (uint64_t)strtoull(argv[4], NULL, 10) : 7u;
    scansim_scene scene;
    if (argc < 3 || argc > 5) {
        fprintf(stderr, "usage: gen_example LOG GT [SCENE [SEED]]\n");
        return 2;
    }
    if (scansim_scene_builtin(&scene, name, seed) != 0) {
        fprintf(stderr, "gen_example: unknown scene '%s'\n", name);
        return 2;
    }
    if (scansim_run(&scene) != 0 || scansim_save(&scene, argv[1], argv[2]) != 0) {
        fprintf(stderr, "gen_example: %s\n", errno ? strerror(errno) : "out of memory");
        scansim_scene_free(&scene);
        return 1;
    }
    printf("%s: %u scans, %llu returns; %s: ideal %u vertices, %u seen samples\n", argv[1],
           scene.scan_count, (unsigned long long)scene.hit_count, argv[2],
           scansim_ideal_vertices(&scene), scansim_seen_count(&scene));
    scansim_scene_free(&scene);
    return 0;
}
