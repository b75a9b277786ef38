/* run.c - the polyc tool's run of the library (cli.h).
 * Takes: the options and the input read by load.c. Gives: the block
 * (ctxblock.h), each stage run and timed, and the outputs rendered
 * (mapout.h, mapfile.h, scanlog.h) and written all or nothing; a library
 * failure as a message and an exit code. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "ctxblock.h"

int library_fail(const char *stage, polyc_status st, const polyc_ctx *ctx, size_t block)
{
    const char *msg = ctx ? polyc_last_error(ctx) : NULL;
    if (st == POLYC_ERR_NOMEM)
        return complain(EXIT_MEMORY, "memory budget too small: need more than %zu bytes (%s: %s)",
                        block, stage, msg ? msg : polyc_status_str(st));
    return complain(EXIT_INPUT, "%s failed: %s%s%s", stage, polyc_status_str(st),
                    msg && *msg ? ": " : "", msg ? msg : "");
}

/* The block needs more than --memory-mb allows: say the MiB to give. */
static int budget_fail(const options *o, size_t size)
{
    double mib = (double)size / 1048576.0;
    return complain(EXIT_MEMORY, "memory budget too small: need %zu bytes (%.1f MiB), --memory-mb"
                                 " %g allows %g MiB: give --memory-mb %.0f or more",
                    size, mib, o->memory_mb, o->memory_mb, ceil(mib));
}

/* The data are too wide for the grid. Names the scan that reaches farthest
 * from the median pose (a far-away scan or hit is the usual cause), before
 * any memory is sized. */
static int extent_fail(const options *o, const scanlog *log, const polyc_config *cfg)
{
    uint32_t n = log->count;
    double *v = malloc(2 * (size_t)n * sizeof *v);
    if (!v)
        return complain(EXIT_INPUT, "%s: the data span more than %g m", input_name(o),
                        (double)cfg->max_extent_m);
    for (uint32_t i = 0; i < n; i++) {
        v[i] = log->scans[i].pose_x_m;
        v[n + i] = log->scans[i].pose_y_m;
    }
    qsort(v, n, sizeof *v, cmp_double);
    qsort(v + n, n, sizeof *v, cmp_double);
    double mx = v[n / 2], my = v[n + n / 2], worst = -1.0;
    free(v);
    polyc_box all = {1.0, 1.0, 0.0, 0.0};
    uint32_t far = 0;
    for (uint32_t i = 0; i < n; i++) {
        polyc_box b = {1.0, 1.0, 0.0, 0.0};
        polyc_scan_extent(cfg, &log->scans[i], &b);
        polyc_scan_extent(cfg, &log->scans[i], &all);
        double d = fmax(fmax(fabs(b.min_x_m - mx), fabs(b.max_x_m - mx)),
                        fmax(fabs(b.min_y_m - my), fabs(b.max_y_m - my)));
        if (b.min_x_m <= b.max_x_m && d > worst) {
            worst = d;
            far = i;
        }
    }
    double w = all.max_x_m - all.min_x_m, h = all.max_y_m - all.min_y_m;
    double pad = 4.0 * (double)cfg->cell_m;    /* the grid's margin (polyc_limits_for_scans) */
    const polyc_scan *s = &log->scans[far];
    if (w + pad > (double)cfg->max_extent_m || h + pad > (double)cfg->max_extent_m || worst < 0)
        return complain(EXIT_INPUT,
                        "%s:%llu: this scan (pose %.2f %.2f) reaches %.0f m from the median pose"
                        " (%.2f %.2f): the data would span %.0f x %.0f m (plus the grid's margin"
                        " of %g m), more than the grid's limit of %g m",
                        input_name(o), (unsigned long long)log->line_of_scan[far], s->pose_x_m,
                        s->pose_y_m, worst, mx, my, w, h, pad, (double)cfg->max_extent_m);
    return complain(EXIT_INPUT, "%s: the data span %.1f x %.1f m: more than 2^32 grid cells of"
                                " %g m (try a larger --cell)",
                    input_name(o), w, h, (double)cfg->cell_m);
}

/* The library refused the map's grid (polyc_limits_for_grid, polyc_add_grid). */
static int map_fail(const options *o, const map_input *m, polyc_status st, const polyc_ctx *ctx,
                    size_t block)
{
    const polyc_config *c = &o->config;
    if (st == POLYC_ERR_EXTENT)
        return complain(EXIT_INPUT, "%s:%u: the map spans %.1f x %.1f m (%u x %u cells of %g m):"
                                    " more than the grid's limit of %g m",
                        o->input, (unsigned)m->yaml.resolution_line,
                        m->grid.width * m->yaml.resolution_m, m->grid.height * m->yaml.resolution_m,
                        (unsigned)m->grid.width, (unsigned)m->grid.height, m->yaml.resolution_m,
                        (double)c->max_extent_m);
    return library_fail("map", st, ctx, block);
}

int block_fail(const options *o, int made, polyc_status st, const polyc_ctx *ctx, size_t size)
{
    switch (made) {
    case CTXBLOCK_OK:
        return 0;
    case CTXBLOCK_UNSIZED:
        return complain(EXIT_MEMORY, "memory budget too small: need more than %zu bytes",
                        (size_t)SIZE_MAX);
    case CTXBLOCK_OVER_CAP:
        return budget_fail(o, size);
    case CTXBLOCK_NOMEM:
        return complain(EXIT_MEMORY, "memory budget too small: need %zu bytes (malloc failed)",
                        size);
    default:
        return library_fail("init", st, ctx, size);
    }
}

/* The library's block for cfg and lim in r->block (ctxblock.h) and a
 * context on it; 0, or the exit code of the complaint. */
static int make_block(const options *o, run *r, const polyc_config *cfg, const polyc_limits *lim,
                      polyc_ctx **ctx, size_t *size)
{
    polyc_status st = POLYC_OK;
    int made = ctxblock_make(cfg, lim, o->memory_mb * 1048576.0, &r->block, size, ctx, &st);
    return block_fail(o, made, st, *ctx, *size);
}

int add_fail(const options *o, const run *r, uint32_t i, polyc_status st, const polyc_ctx *ctx,
             size_t size)
{
    if (st == POLYC_ERR_SCAN)
        return complain(EXIT_INPUT, "%s:%llu: scan rejected by the library: %s", input_name(o),
                        (unsigned long long)r->log.line_of_scan[i], polyc_last_error(ctx));
    return library_fail("add scan", st, ctx, size);
}

/* The log's scans into the context; 0, or the exit code of the complaint
 * (a scan the library rejects names its line). */
static int add_scans(const options *o, const run *r, polyc_ctx *ctx, size_t size)
{
    progress_stage("adding scans");
    for (uint32_t i = 0; i < r->log.count; i++) {
        polyc_status st = polyc_add_scan(ctx, &r->log.scans[i]);
        if (st != POLYC_OK)
            return add_fail(o, r, i, st, ctx, size);
    }
    return 0;
}

/* ---- the optimiser's callback: --trace and the progress line ---- */

static int on_iteration(void *user, const polyc_iteration *it)
{
    FILE *f = user;
    if (f)
        fprintf(f, "%u %.6f %.6f %u %u %.6f\n", (unsigned)it->iteration, it->bic, it->best_bic,
                (unsigned)it->vertices, (unsigned)it->polylines, it->noise_m);
    progress_show(it);
    return 0;
}

static void print_stats(const options *o, const run *r, const polyc_stats *s,
                        const mapout_times *t, double output_ms, double total_ms)
{
    FILE *e = stderr;
    progress_clear();
    if (r->map) {
        print_map_stats(r->map);
    } else {
        print_input_stats(&r->log);
        fprintf(e, "beams          %llu (hits %llu, skipped by the library %llu)\n",
                (unsigned long long)s->beams, (unsigned long long)s->hits,
                (unsigned long long)s->beams_skipped);
    }
    fprintf(e, "points         %llu data points, %u weighted points\n",
            (unsigned long long)s->data_points, (unsigned)s->weighted_points);
    fprintf(e, "grid           %u x %u cells of %.4f m, %u tiles, %llu bytes\n",
            (unsigned)s->grid_width, (unsigned)s->grid_height,
            r->map ? (double)r->map->grid.resolution_m : (double)o->config.cell_m,
            (unsigned)s->grid_tiles, (unsigned long long)s->grid_bytes);
    if (!o->online) { /* an online map has no contour stage nor one initial trace */
        fprintf(e, "contour cells  %u\n", (unsigned)s->contour_cells);
        fprintf(e, "initial        %u polylines, %u vertices\n", (unsigned)s->initial_polylines,
                (unsigned)s->initial_vertices);
    }
    fprintf(e, "final          %u polylines, %u vertices, %u iterations\n",
            (unsigned)s->polylines, (unsigned)s->vertices, (unsigned)s->iterations);
    fprintf(e, "curves         %u circles, %u arcs%s\n", (unsigned)r->curves.circles,
            (unsigned)r->curves.arcs,
            o->no_arcs ? " (--no-arcs)" : o->max_chord_m > 0.0 ? " (--max-chord-error: written as polylines)" : "");
    fprintf(e, "BIC            %.3f (error %.6f m^2)\n", s->bic, s->error_sq_m2);
    fprintf(e, "memory         block %llu bytes, used %llu bytes\n",
            (unsigned long long)s->memory_size_bytes, (unsigned long long)s->memory_used_bytes);
    fprintf(e, "time ms        %s %.1f, add %.1f, grid %.1f, contour %.1f, trace %.1f,"
               " optimize %.1f, output %.1f, total %.1f\n",
            r->map ? "read" : "parse", t->parse_ms, t->add_ms, t->grid_ms, t->contour_ms,
            t->trace_ms, t->optimize_ms, output_ms, total_ms);
}

int convert(const options *o, run *r)
{
    if (membuf_open(&r->out))
        return EXIT_INPUT;
    int bad = scanlog_write_plain(r->out.f, r->log.scans, r->log.count);
    if (membuf_close(&r->out, bad))
        return EXIT_INPUT;
    if (o->stats)
        print_input_stats(&r->log);
    const char *paths[] = {o->output};
    const membuf *bufs[] = {&r->out};
    return write_outputs(paths, bufs, 1);
}

polyc_progress_fn iteration_fn(const options *o)
{
    return o->trace || progress_on() ? on_iteration : NULL;
}

/* ---- the map out ---- */

int optimiser_status(run *r, polyc_status st, int retry, const char *stage, const polyc_ctx *ctx,
                     size_t size)
{
    if (st == POLYC_ERR_NOMEM && retry) {
        if (r->trace.f)
            rewind(r->trace.f);    /* (the rerun writes the same lines again) */
        return RUN_AGAIN;
    }
    return st == POLYC_OK ? 0 : library_fail(stage, st, ctx, size);
}

int open_trace(const options *o, run *r)
{
    if (!o->trace || r->trace.f)
        return 0;
    if (membuf_open(&r->trace))
        return EXIT_INPUT;
    fputs("# iteration bic best_bic vertices polylines noise_m\n", r->trace.f);
    return 0;
}

/* The stages on a fresh context, from the data in to the optimised map,
 * each timed into t; 0, an exit code, or RUN_AGAIN if the trace or the
 * optimiser ran out of vertices or points and `retry` allows the
 * worst-case limits. */
static int run_stages(const options *o, run *r, const polyc_config *cfg, polyc_ctx *ctx,
                      size_t size, int retry, mapout_times *t)
{
    const polyc_occupancy_grid *grid = r->map ? &r->map->grid : NULL;
    polyc_status st;
    double t0 = now_ms();
    if (grid) {
        /* the grid and its contour come with the map */
        progress_stage("map cells");
        if ((st = polyc_add_grid(ctx, grid)) != POLYC_OK)
            return map_fail(o, r->map, st, ctx, size);
    } else {
        int rc = add_scans(o, r, ctx, size);
        if (rc != 0)
            return rc;
    }
    double t1 = now_ms();
    t->add_ms = t1 - t0;
    if (!grid) {
        progress_stage("grid");
        if ((st = polyc_build_grid(ctx)) != POLYC_OK)
            return library_fail("grid", st, ctx, size);
    }
    double t2 = now_ms();
    t->grid_ms = t2 - t1;
    /* one scan's polylines come from its beam order (polyc_build skips
     * the contour too): it is needed only to trace it or to draw it */
    int want_contour = !grid && (r->log.count != 1 || o->grid ||
                                 (cfg->flags & POLYC_FLAG_GRID_TRACE));
    progress_stage("contour");
    if (want_contour && (st = polyc_extract_contour(ctx)) != POLYC_OK)
        return library_fail("contour", st, ctx, size);
    double t3 = now_ms();
    t->contour_ms = t3 - t2;
    progress_stage("trace");
    st = polyc_trace(ctx);
    if (st == POLYC_ERR_NOMEM && retry)
        return RUN_AGAIN;
    if (st != POLYC_OK)
        return library_fail("trace", st, ctx, size);
    double t4 = now_ms();
    t->trace_ms = t4 - t3;
    if (open_trace(o, r))
        return EXIT_INPUT;
    if (!o->no_optimize && cfg->max_iterations > 0) {
        progress_stage("optimize");
        st = polyc_optimize(ctx, iteration_fn(o), r->trace.f);
        int rc = optimiser_status(r, st, retry, "optimize", ctx, size);
        if (rc)
            return rc;
    }
    t->optimize_ms = now_ms() - t4;
    return 0;
}

int map_to_draw(const options *o, run *r, const polyc_config *cfg, polyc_ctx *ctx, size_t size,
                mapout_map *map)
{
    /* the round things (polyc_find_curves) unless --no-arcs; the map drawn
     * before (an earlier frame) freed first */
    curves_free(&r->curves);
    polyc_status st = curves_from_ctx(ctx, o->no_arcs, &r->curves);
    if (st != POLYC_OK)
        return library_fail("find curves", st, ctx, size);
    uint32_t n = r->curves.count;
    free(r->flat_lines);
    free(r->flat_xy);
    free(r->bulges);
    r->flat_lines = NULL;
    r->flat_xy = NULL;
    r->bulges = calloc(n ? n : 1, sizeof *r->bulges);
    if (!r->bulges)
        return complain(EXIT_INPUT, "out of memory");
    const polyc_polyline *lines = r->curves.lines;
    const polyc_circle *circles = r->curves.circ;
    if (o->max_chord_m > 0.0) {  /* lines only, each curve within the error */
        if (curves_flatten(&r->curves, o->max_chord_m, &r->flat_lines, &r->flat_xy) != 0)
            return complain(EXIT_INPUT, "out of memory");
        lines = r->flat_lines;
        circles = NULL;
    } else {
        for (uint32_t i = 0; i < n; i++)
            r->bulges[i] = curves_bulges(&r->curves, i);
    }
    memset(map, 0, sizeof *map);
    map->lines = lines;
    map->line_count = n;
    map->circles = circles;
    map->bulges = o->max_chord_m > 0.0 ? NULL : r->bulges;
    map->scans = o->points ? r->log.scans : NULL;
    map->scan_count = r->log.count;
    map->grid = o->grid ? ctx : NULL;
    map->contour_threshold = cfg->contour_threshold;
    map->vertices = o->vertices;
    map->color_lines = o->color_lines;
    map->title = input_name(o);
    map->cell_m = r->map ? r->map->yaml.resolution_m : (double)cfg->cell_m;
    return 0;
}

int render_map(membuf *out, enum format format, const mapout_map *map)
{
    if (membuf_open(out))
        return EXIT_INPUT;
    int bad = format == FORMAT_JSON  ? mapout_json(out->f, map)
              : format == FORMAT_TXT ? mapout_txt(out->f, map)
                                     : mapout_svg(out->f, map);
    return membuf_close(out, bad) ? EXIT_INPUT : 0;
}

int write_map(const options *o, run *r, const polyc_config *cfg, polyc_ctx *ctx, size_t size,
              const mapout_times *t, double t_start)
{
    double t5 = now_ms();
    progress_stage("writing");
    polyc_stats stats;
    polyc_status st;
    double bic = 0, error_sq_m2 = 0;
    int scored = (o->no_optimize || cfg->max_iterations == 0) &&   /* the initial polylines */
                 polyc_score(ctx, &bic, &error_sq_m2) == POLYC_OK;
    if ((st = polyc_get_stats(ctx, &stats)) != POLYC_OK)
        return library_fail("stats", st, ctx, size);
    if (scored) {
        stats.bic = bic;
        stats.error_sq_m2 = error_sq_m2;
    }
    mapout_map map;
    int rc = map_to_draw(o, r, cfg, ctx, size, &map);
    if (rc)
        return rc;
    map.stats = &stats;
    map.times = t;
    map.total_ms = now_ms() - t_start;
    if ((rc = render_map(&r->out, o->format, &map)) != 0)
        return rc;
    if (o->trace && membuf_close(&r->trace, 0))
        return EXIT_INPUT;
    /* both outputs or neither */
    const char *paths[] = {o->output, o->trace};
    const membuf *bufs[] = {&r->out, &r->trace};
    rc = write_outputs(paths, bufs, o->trace ? 2 : 1);
    double t6 = now_ms();
    if (o->stats)
        print_stats(o, r, &stats, t, t6 - t5, t6 - t_start);
    return rc;
}

int make_map(const options *o, run *r, double t_start, mapout_times *t)
{
    polyc_config cfg = o->config;
    polyc_limits lim;
    polyc_ctx *ctx = NULL;
    const polyc_occupancy_grid *grid = r->map ? &r->map->grid : NULL;
    polyc_status st = grid ? polyc_limits_for_grid(&cfg, grid, &lim)
                           : polyc_limits_for_scans(&cfg, r->log.scans, r->log.count, &lim);
    if (grid && st != POLYC_OK)
        return map_fail(o, r->map, st, NULL, 0);
    if (st == POLYC_ERR_EXTENT)
        return extent_fail(o, &r->log, &cfg);
    if (st != POLYC_OK)
        return library_fail("sizing", st, NULL, 0);
    /* polyc_limits_for_scans sizes vertices and data points for a usual
     * contour; a map that needs more is run again with the worst-case bound */
    size_t size = 0;
    for (int attempt = 0;; attempt++) {
        int retry = !grid && attempt == 0 && (lim.max_vertices != 0 || lim.max_points != 0);
        int rc = make_block(o, r, &cfg, &lim, &ctx, &size);
        if (rc == 0)
            rc = run_stages(o, r, &cfg, ctx, size, retry, t);
        if (rc != RUN_AGAIN) {
            if (rc != 0)
                return rc;
            break;
        }
        lim.max_vertices = lim.max_points = 0;
    }
    return write_map(o, r, &cfg, ctx, size, t, t_start);
}

/* ---- polyc grid: the hit/miss grid as map_saver's files ---- */

/* PREFIX.pgm and PREFIX.yaml of img, both or neither; the YAML names the
 * image by its base name. 0 or an exit code. */
static int write_grid_files(const options *o, run *r, const gridimage *img)
{
    size_t plen = grid_prefix_len(o->output);
    char *pgm_path = malloc(plen + 6), *yaml_path = malloc(plen + 6);
    int rc = 0;
    if (!pgm_path || !yaml_path) {
        rc = complain(EXIT_INPUT, "out of memory");
    } else {
        snprintf(pgm_path, plen + 6, "%.*s.pgm", (int)plen, o->output);
        snprintf(yaml_path, plen + 6, "%.*s.yaml", (int)plen, o->output);
        const char *slash = strrchr(pgm_path, '/');
        const char *image = slash ? slash + 1 : pgm_path;
        for (const char *q = image; *q && !rc; q++)
            if ((unsigned char)*q < 0x20 || *q == 0x7f)
                rc = complain(EXIT_USAGE, "-o PREFIX holds a control character");
        if (!rc && (membuf_open(&r->pgm) || membuf_open(&r->yaml)))
            rc = EXIT_INPUT;
        if (!rc) {
            int bad = mapfile_write_pgm(r->pgm.f, img->pixels, img->width, img->height,
                                        (double)img->cell_m);
            rc = membuf_close(&r->pgm, bad);
        }
        if (!rc) {
            int bad = mapfile_write_yaml(r->yaml.f, image, (double)img->cell_m, img->origin_x_m,
                                         img->origin_y_m);
            rc = membuf_close(&r->yaml, bad);
        }
        /* both files or neither; the image first, so that the YAML never
         * names a missing one */
        const char *paths[] = {pgm_path, yaml_path};
        const membuf *bufs[] = {&r->pgm, &r->yaml};
        if (!rc)
            rc = write_outputs(paths, bufs, 2);
    }
    free(pgm_path);
    free(yaml_path);
    return rc;
}

int grid_files(const options *o, run *r, double t_start)
{
    polyc_config cfg = o->config;
    polyc_limits lim;
    polyc_ctx *ctx = NULL;
    size_t size = 0;
    polyc_status st = polyc_limits_for_scans(&cfg, r->log.scans, r->log.count, &lim);
    if (st == POLYC_ERR_EXTENT)
        return extent_fail(o, &r->log, &cfg);
    if (st != POLYC_OK)
        return library_fail("sizing", st, NULL, 0);
    int rc = make_block(o, r, &cfg, &lim, &ctx, &size);
    if (rc == 0)
        rc = add_scans(o, r, ctx, size);
    if (rc != 0)
        return rc;
    progress_stage("grid");
    if ((st = polyc_build_grid(ctx)) != POLYC_OK)
        return library_fail("grid", st, ctx, size);
    gridimage *img = &r->image;
    int made = gridimage_make(ctx, img, &st);
    if (made == GRIDIMAGE_LIBRARY)
        return library_fail("grid", st, ctx, size);
    if (made == GRIDIMAGE_TOO_LARGE)
        return complain(EXIT_INPUT, "%s: the grid is %u x %u cells of %g m: more than the %u a"
                                    " map may have (try a larger --cell)",
                        input_name(o), (unsigned)img->width, (unsigned)img->height,
                        (double)img->cell_m, MAPFILE_MAX_CELLS);
    if (made != GRIDIMAGE_OK)
        return complain(EXIT_INPUT, "out of memory for %u x %u pixels", (unsigned)img->width,
                        (unsigned)img->height);
    progress_stage("writing");
    rc = write_grid_files(o, r, img);
    progress_clear();
    if (!rc && o->stats) {
        const uint64_t *counts = img->counts;
        print_input_stats(&r->log);
        fprintf(stderr, "grid           %u x %u cells of %.4f m, origin %.6f %.6f m\n",
                (unsigned)img->width, (unsigned)img->height, (double)img->cell_m,
                img->origin_x_m, img->origin_y_m);
        fprintf(stderr, "pixels         occupied %llu, free %llu, unknown %llu\n",
                (unsigned long long)counts[MAPFILE_PIXEL_OCCUPIED],
                (unsigned long long)counts[MAPFILE_PIXEL_FREE],
                (unsigned long long)counts[MAPFILE_PIXEL_UNKNOWN]);
        fprintf(stderr, "time ms        total %.1f\n", now_ms() - t_start);
    }
    return rc;
}
