/* polyc.c - the command-line tool: a laser log or a ROS map in, a polyline
 * map out.
 *   polyc [options] INPUT        map as SVG (default), JSON or TXT; INPUT is
 *                                a log or a map_server map YAML (by content)
 *   polyc convert INPUT          the scans in the plain format
 *   polyc grid LOG -o PREFIX     the hit/miss grid as map_saver's PREFIX.pgm
 *                                and PREFIX.yaml
 * Exit codes: 0 ok, 1 bad input or other failure, 2 usage, 3 memory budget.
 * Formats and rules: docs/formats.md.
 *
 * This file: main. The rest of the tool: options.c (the command line),
 * load.c (the input), run.c (the library's run and the outputs), online.c
 * (--online: the log replayed as a stream), cli.c
 * (messages, the progress line, writing the outputs); cli.h joins them. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "outfile.h"

static int struct_sizes_match(void)
{
    return polyc_struct_size("polyc_config") == sizeof(polyc_config) &&
           polyc_struct_size("polyc_limits") == sizeof(polyc_limits) &&
           polyc_struct_size("polyc_scan") == sizeof(polyc_scan) &&
           polyc_struct_size("polyc_polyline") == sizeof(polyc_polyline) &&
           polyc_struct_size("polyc_stats") == sizeof(polyc_stats) &&
           polyc_struct_size("polyc_iteration") == sizeof(polyc_iteration) &&
           polyc_struct_size("polyc_occupancy_grid") == sizeof(polyc_occupancy_grid) &&
           polyc_struct_size("polyc_online_limits") == sizeof(polyc_online_limits) &&
           polyc_struct_size("polyc_online_report") == sizeof(polyc_online_report);
}

int main(int argc, char **argv)
{
    options o;
    run r;
    map_input map;
    outfile_signals();
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc < 0 ? 0 : rc;
    if (!struct_sizes_match())
        return complain(EXIT_INPUT, "libpolyc's structs differ from polyc.h (rebuild)");
    memset(&r, 0, sizeof r);
    memset(&map, 0, sizeof map);
    mapout_times t = {0, 0, 0, 0, 0, 0};
    double t_start = now_ms();
    progress_start(!o.quiet && isatty(STDERR_FILENO), t_start);
    enum input_kind kind = strcmp(o.input, "-") == 0 ? INPUT_LOG : sniff(o.input);
    if (kind == INPUT_IMAGE) {
        rc = complain(EXIT_INPUT, "%s: an image: give the map's YAML file (map_server's"
                                  " map.yaml), which names the image", o.input);
    } else if (kind == INPUT_MAP_YAML) {
        progress_stage("reading the map");
        if (o.command != CMD_MAP)
            rc = complain(EXIT_INPUT, "%s: a map YAML: polyc %s takes a laser log", o.input,
                          o.command == CMD_CONVERT ? "convert" : "grid");
        else if (!(rc = refuse_options(&o, ~(unsigned)OPTS_LOG_ONLY,
                                       "a map YAML (it acts on laser scans; a map's cells are its own)")) &&
                 !(rc = load_map(&o, &map))) {
            r.map = &map;
            t.parse_ms = now_ms() - t_start;
            if (o.grid && map.yaml.origin_yaw_rad != 0.0)
                rc = complain(EXIT_USAGE, "--grid draws the grid unrotated: not for a map whose"
                                          " origin has a yaw");
            else
                rc = make_map(&o, &r, t_start, &t);
        }
    } else {
        rc = o.command == CMD_GRID      ? refuse_options(&o, OPTS_GRID_CMD, "polyc grid")
             : o.command == CMD_CONVERT ? refuse_options(&o, OPTS_CONVERT_CMD, "polyc convert")
                                        : refuse_options(&o, ~(unsigned)OPTS_MAP_ONLY,
                                                         "a laser log");
        if (!rc) {
            rc = load_log(&o, &r);
            t.parse_ms = now_ms() - t_start;
        }
        if (!rc)
            rc = o.command == CMD_CONVERT ? convert(&o, &r)
                 : o.command == CMD_GRID  ? grid_files(&o, &r, t_start)
                 : o.online               ? online_map(&o, &r, t_start, &t)
                                          : make_map(&o, &r, t_start, &t);
    }
    progress_clear();
    membuf *bufs[] = {&r.trace, &r.out, &r.pgm, &r.yaml};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; i++) {
        if (bufs[i]->f)
            fclose(bufs[i]->f);
        free(bufs[i]->data);
    }
    curves_free(&r.curves);
    free(r.flat_lines);
    free(r.flat_xy);
    free(r.bulges);
    free(r.block);
    gridimage_free(&r.image);
    scanlog_free(&r.log);
    mapfile_yaml_free(&map.yaml);
    free(map.image_path);
    free(map.cells);
    return rc;
}
