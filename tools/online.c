/* online.c - polyc --online (cli.h): a log replayed as a live stream.
 * Takes: the log read by load.c and the options. Gives: an online context
 * sized for the log's area, each scan added and the map updated within
 * --work, --frames' SVGs, the finished map written as run.c writes a batch
 * map, and --stats' latencies of an add and of an add and its update. */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "ctxblock.h"
#include "outfile.h"
#include "textesc.h"

#define ONLINE_ATTEMPTS 3          /* the usual limits, then 4 and 16 times them */
#define ONLINE_EDGE_M 1.0          /* the library refuses data this near the area's
                                      edge (docs/api.md, "Online") */
#define ONLINE_AIR_CELLS 32.0      /* and a tile of air inside that */

/* What --stats shows of the replay. */
typedef struct replay {
    double *add_ms, *step_ms;      /* per scan: the add, the add and its update */
    double area_m, finish_ms, frames_ms;
    polyc_box box;                 /* every scan's endpoints and pose: the frames' view */
    uint32_t max_backlog, frames, attempts;
    char stage[48];                /* the progress line's */
} replay;

/* The side of the square round the first pose that holds every scan's
 * endpoints and pose (*box), with a margin; *max_beams gets the largest scan. */
static double log_area(const polyc_config *cfg, const scanlog *log, polyc_box *box,
                       uint32_t *max_beams)
{
    double x0 = log->scans[0].pose_x_m, y0 = log->scans[0].pose_y_m;
    *box = (polyc_box){x0, y0, x0, y0};
    *max_beams = 0;
    for (uint32_t i = 0; i < log->count; i++) {
        polyc_scan_extent(cfg, &log->scans[i], box);
        if (log->scans[i].beam_count > *max_beams)
            *max_beams = log->scans[i].beam_count;
    }
    if (*max_beams == 0)
        *max_beams = 1;            /* scans of no beams: the library sizes for one */
    double reach = fmax(fmax(x0 - box->min_x_m, box->max_x_m - x0),
                        fmax(y0 - box->min_y_m, box->max_y_m - y0));
    return 2.0 * (reach + ONLINE_EDGE_M + ONLINE_AIR_CELLS * (double)cfg->cell_m);
}

/* The grid's tiles (32 x 32 cells), cells and 2 x 2 blocks of cells (a
 * weighted point each) that the log's returns fall in, the grid laid out
 * as the library lays an online one: a square of side area_m centred on
 * the first pose. 0, or -1 if out of memory. */
#define TILE_SIDE 32
#define TILE_BYTES (TILE_SIDE * TILE_SIDE / 8 + TILE_SIDE * TILE_SIDE / 32) /* cells, blocks */
static int count_hit_cells(const polyc_config *cfg, const scanlog *log, double area_m,
                           uint64_t *tiles_hit, uint64_t *cells_hit, uint64_t *blocks_hit)
{
    double cell = (double)cfg->cell_m, half = 0.5 * area_m;
    double x0 = log->scans[0].pose_x_m, y0 = log->scans[0].pose_y_m;
    uint64_t side = (uint64_t)ceil(area_m / cell / TILE_SIDE);
    if (side == 0 || side > 1u << 15)
        return -1;
    /* per tile: the index of its cell bitmap (0: none yet), bitmaps on demand */
    uint32_t *slot = calloc(side * side, sizeof *slot);
    uint8_t *bits = NULL;
    uint32_t used = 0, cap = 0;
    *tiles_hit = *cells_hit = *blocks_hit = 0;
    if (!slot)
        return -1;
    for (uint32_t s = 0; s < log->count; s++) {
        const polyc_scan *sc = &log->scans[s];
        for (uint32_t i = 0; i < sc->beam_count; i++) {
            float r = sc->range_m[i];
            if (!(r >= sc->min_range_m && r < sc->max_range_m))
                continue;
            double a = sc->pose_theta_rad + (double)sc->start_angle_rad + (double)i * (double)sc->angle_step_rad;
            double fx = (sc->pose_x_m + (double)r * cos(a) - x0 + half) / cell;
            double fy = (sc->pose_y_m + (double)r * sin(a) - y0 + half) / cell;
            if (!(fx >= 0.0 && fy >= 0.0 && fx < (double)(side * TILE_SIDE) &&
                  fy < (double)(side * TILE_SIDE)))
                continue;
            uint64_t ix = (uint64_t)fx, iy = (uint64_t)fy;
            uint64_t t = (iy / TILE_SIDE) * side + ix / TILE_SIDE;
            if (slot[t] == 0) {
                if (used == cap) {
                    cap = cap ? 2 * cap : 256;
                    uint8_t *more = realloc(bits, (size_t)cap * TILE_BYTES);
                    if (!more) {
                        free(bits);
                        free(slot);
                        return -1;
                    }
                    bits = more;
                }
                memset(bits + (size_t)used * TILE_BYTES, 0, TILE_BYTES);
                slot[t] = ++used;
            }
            uint8_t *b = bits + (size_t)(slot[t] - 1) * TILE_BYTES;
            unsigned c = (unsigned)((iy % TILE_SIDE) * TILE_SIDE + ix % TILE_SIDE);
            if (!(b[c >> 3] & (1u << (c & 7)))) {
                b[c >> 3] = (uint8_t)(b[c >> 3] | (1u << (c & 7)));
                (*cells_hit)++;
            }
            uint8_t *k = b + TILE_SIDE * TILE_SIDE / 8;
            unsigned q = (unsigned)((iy % TILE_SIDE) / 2 * (TILE_SIDE / 2) + (ix % TILE_SIDE) / 2);
            if (!(k[q >> 3] & (1u << (q & 7)))) {
                k[q >> 3] = (uint8_t)(k[q >> 3] | (1u << (q & 7)));
                (*blocks_hit)++;
            }
        }
    }
    *tiles_hit = used;
    free(bits);
    free(slot);
    return 0;
}

/* The area's limits raised to what the log's returns need (an eighth to
 * spare): the tiles they fall in, the cells with endpoints and twice their
 * 2 x 2 blocks (an update's points are limits.max_points / 2), which
 * polyc_online_limits_for_area can only estimate for a usual building
 * (fhw's 1,352 tiles and aces' 1,329 outgrew its 1,314 and 1,024, and the
 * whole replay ran again with four times the limits). Never lowered. */
static void fit_limits_to_log(const polyc_config *cfg, const scanlog *log, polyc_online_limits *lim)
{
    uint64_t tiles, cells, blocks;
    if (count_hit_cells(cfg, log, lim->area_m, &tiles, &cells, &blocks) != 0)
        return; /* (the estimate, and the retries) */
    double want_cells = fmin((double)(tiles + tiles / 8 + 16) * TILE_SIDE * TILE_SIDE, 0x40000000);
    uint64_t need = cells > 2 * blocks ? cells : 2 * blocks;
    double want_points = fmin((double)(need + need / 8 + 1024), 0x10000000);
    if (want_cells > (double)lim->max_grid_cells)
        lim->max_grid_cells = (uint32_t)want_cells;
    if (want_points > (double)lim->max_points) {
        lim->max_points = (uint32_t)want_points;
        /* (vertices as the library sizes them from the points) */
        double want_vertices = fmin(want_points / 16.0 + 4096.0, 0x10000000);
        if (want_vertices > (double)lim->max_vertices)
            lim->max_vertices = (uint32_t)want_vertices;
    }
}

/* a * 4, at most cap */
static uint32_t times4(uint32_t a, double cap)
{
    return (uint32_t)fmin(4.0 * a, cap);
}

/* The block for lim in r->block and an online context on it; 0 or the exit
 * code of the complaint. */
static int make_block(const options *o, run *r, const polyc_config *cfg,
                      const polyc_online_limits *lim, polyc_ctx **ctx, size_t *size)
{
    polyc_status st = POLYC_OK;
    *ctx = NULL;
    *size = polyc_online_memory_size(cfg, lim);
    int made = ctxblock_alloc(*size, o->memory_mb * 1048576.0, &r->block);
    if (made == CTXBLOCK_OK && (st = polyc_online_init(r->block, *size, cfg, lim, ctx)) != POLYC_OK)
        made = CTXBLOCK_INIT;
    return block_fail(o, made, st, *ctx, *size);
}

/* --frames: the folder, made if missing (its parent must exist). */
static int make_frames_dir(const char *dir)
{
    struct stat st;
    if (mkdir(dir, 0777) == 0 || (errno == EEXIST && stat(dir, &st) == 0 && S_ISDIR(st.st_mode)))
        return 0;
    return complain(EXIT_INPUT, "--frames %s: %s", dir, strerror(errno == EEXIST ? ENOTDIR : errno));
}

/* The width of the frames' numbers: as the last one needs, at least 5. */
static int frame_digits(uint32_t count)
{
    int digits = snprintf(NULL, 0, "%u", (unsigned)count);
    return digits > 5 ? digits : 5;
}

/* Refuses (usage) a --frames DIR in which a frame this run writes is the
 * input (DIR/frame-00050.svg a link to it, or the log itself), before the
 * replay: DIR's entries named as those frames are looked at. */
static int frames_clash(const options *o, uint32_t count)
{
    DIR *d = opendir(o->frames);
    if (!d)
        return 0;                      /* made new: nothing in it */
    int width = frame_digits(count), rc = 0;
    size_t n = strlen(o->frames) + 300;
    char *path = malloc(n);
    struct dirent *e;
    while (path && !rc && (e = readdir(d)) != NULL) {
        char *end, want[48];
        if (strncmp(e->d_name, "frame-", 6) != 0 || e->d_name[6] < '0' || e->d_name[6] > '9')
            continue;
        unsigned long k = strtoul(e->d_name + 6, &end, 10);
        if (k == 0 || k > count || k % o->every != 0)
            continue;
        snprintf(want, sizeof want, "frame-%0*lu.svg", width, k);
        if (strcmp(want, e->d_name) != 0)
            continue;
        snprintf(path, n, "%s/%s", o->frames, want);
        if (outfile_is_input(path, o->input))
            rc = complain(EXIT_USAGE, "--frames %s: %s is the input '%s' (the same file): it"
                                      " would be replaced; give another folder", o->frames,
                          want, strcmp(o->input, "-") == 0 ? "stdin" : o->input);
    }
    closedir(d);
    if (!path)
        return complain(EXIT_INPUT, "out of memory");
    free(path);
    return rc;
}

/* The map after `scans` scans as DIR/frame-NNNNN.svg (as wide as the last
 * frame's number needs, at least 5 digits), written as -o is (outfile.h). */
static int write_frame(const options *o, run *r, const polyc_config *cfg, polyc_ctx *ctx,
                       size_t size, const polyc_box *view, uint32_t scans)
{
    mapout_map map;
    int rc = map_to_draw(o, r, cfg, ctx, size, &map);
    if (rc)
        return rc;
    char title[96];
    const char *name = strrchr(input_name(o), '/');
    snprintf(title, sizeof title, "%s, %u of %u scans", name ? name + 1 : input_name(o),
             (unsigned)scans, (unsigned)r->log.count);
    map.title = title;
    map.scan_count = scans;        /* --points: the scans so far */
    map.path = r->log.scans;
    map.path_count = scans;
    map.view_m = view;             /* one view for every frame */
    size_t n = strlen(o->frames) + 32;
    char *path = malloc(n);
    if (!path)
        return complain(EXIT_INPUT, "out of memory");
    snprintf(path, n, "%s/frame-%0*u.svg", o->frames, frame_digits(r->log.count), (unsigned)scans);
    membuf m = {NULL, 0, NULL};
    rc = render_map(&m, FORMAT_SVG, &map);
    if (!rc) {
        const char *paths[] = {path};
        const membuf *bufs[] = {&m};
        rc = write_outputs(paths, bufs, 1);
    }
    free(m.data);
    free(path);
    return rc;
}

/* Each scan added and the map updated, timed into rp; frames on the way.
 * 0, an exit code, or RUN_AGAIN when the block ran out and `retry`
 * allows a larger one. */
static int add_and_update(const options *o, run *r, const polyc_config *cfg, polyc_ctx *ctx,
                          size_t size, int retry, replay *rp)
{
    polyc_online_report rep;
    rp->max_backlog = 0;
    rp->frames = 0;
    rp->frames_ms = 0;
    for (uint32_t i = 0; i < r->log.count; i++) {
        if (i % 64 == 0 && progress_on()) {
            snprintf(rp->stage, sizeof rp->stage, "online: scan %u of %u", (unsigned)i + 1,
                     (unsigned)r->log.count);
            progress_stage(rp->stage);
        }
        double t0 = now_ms();
        polyc_status st = polyc_online_add_scan(ctx, &r->log.scans[i], 0, NULL);
        double t1 = now_ms();
        if (st == POLYC_ERR_NOMEM && retry)
            return RUN_AGAIN;
        if (st != POLYC_OK)
            return add_fail(o, r, i, st, ctx, size);
        st = polyc_online_update(ctx, o->work, &rep);
        double t2 = now_ms();
        if (st == POLYC_ERR_NOMEM && retry)
            return RUN_AGAIN;
        if (st != POLYC_OK)
            return library_fail("update", st, ctx, size);
        rp->add_ms[i] = t1 - t0;
        rp->step_ms[i] = t2 - t0;
        if (rep.backlog_tiles > rp->max_backlog)
            rp->max_backlog = rep.backlog_tiles;
        if (o->frames && (i + 1) % o->every == 0) {
            int rc = write_frame(o, r, cfg, ctx, size, &rp->box, i + 1);
            if (rc)
                return rc;
            rp->frames++;
            rp->frames_ms += now_ms() - t2;
        }
    }
    return 0;
}

/* The replay on a fresh context, then polyc_online_finish; t gets the adds
 * and the updates with the finish as the optimiser's time. 0, an exit code
 * or RUN_AGAIN. */
static int run_online(const options *o, run *r, const polyc_config *cfg, polyc_ctx *ctx,
                      size_t size, int retry, replay *rp, mapout_times *t)
{
    int rc = add_and_update(o, r, cfg, ctx, size, retry, rp);
    if (rc)
        return rc;
    if (open_trace(o, r))
        return EXIT_INPUT;
    progress_stage("online: finish");
    double t0 = now_ms();
    polyc_status st = polyc_online_finish(ctx, iteration_fn(o), r->trace.f, NULL);
    rp->finish_ms = now_ms() - t0;
    if ((rc = optimiser_status(r, st, retry, "finish", ctx, size)) != 0)
        return rc;
    t->add_ms = t->optimize_ms = 0;
    for (uint32_t i = 0; i < r->log.count; i++) {
        t->add_ms += rp->add_ms[i];
        t->optimize_ms += rp->step_ms[i] - rp->add_ms[i];
    }
    t->optimize_ms += rp->finish_ms;
    t->grid_ms = t->contour_ms = t->trace_ms = 0;   /* within the adds and updates */
    return 0;
}

/* "median M, p99 P, max X" of n times (sorted in place), nearest rank. */
static void print_latency(const char *label, double *ms, uint32_t n)
{
    qsort(ms, n, sizeof *ms, cmp_double);
    size_t med = (n - 1) / 2, p99 = (size_t)ceil(0.99 * n) - 1;
    fprintf(stderr, "%-14s median %.3f, p99 %.3f, max %.3f\n", label, ms[med], ms[p99], ms[n - 1]);
}

static void print_online_stats(const options *o, const run *r, replay *rp, size_t size)
{
    uint32_t n = r->log.count;
    double total = 0;
    for (uint32_t i = 0; i < n; i++)
        total += rp->step_ms[i];
    fprintf(stderr, "online         %u scans, --work %llu, a square of %.1f m, block %zu bytes%s\n",
            (unsigned)n, (unsigned long long)o->work, rp->area_m, size,
            rp->attempts > 1 ? " (after a larger block)" : "");
    print_latency("add ms", rp->add_ms, n);
    print_latency("add+update ms", rp->step_ms, n);
    fprintf(stderr, "online ms      adds and updates %.1f in all, finish %.1f\n", total,
            rp->finish_ms);
    fprintf(stderr, "backlog        at most %u tiles\n", (unsigned)rp->max_backlog);
    if (o->frames) {
        char *shown = textesc_dup(o->frames);   /* no raw bytes on the terminal */
        fprintf(stderr, "frames         %u in %s, %.1f ms\n", (unsigned)rp->frames,
                shown ? shown : "?", rp->frames_ms);
        free(shown);
    }
}

int online_map(const options *o, run *r, double t_start, mapout_times *t)
{
    polyc_config cfg = o->config;
    polyc_online_limits lim;
    polyc_ctx *ctx = NULL;
    replay rp;
    memset(&rp, 0, sizeof rp);
    uint32_t max_beams;
    int rc;
    rp.area_m = log_area(&cfg, &r->log, &rp.box, &max_beams);
    polyc_status st = polyc_online_limits_for_area(&cfg, rp.area_m, max_beams, &lim);
    if (st == POLYC_ERR_EXTENT)
        return complain(EXIT_INPUT, "%s: the log reaches %.0f m from its first pose: an online"
                                    " map of %.0f m square is more than the grid's limit of %g m",
                        input_name(o), rp.area_m / 2, rp.area_m, (double)cfg.max_extent_m);
    if (st != POLYC_OK)
        return complain(EXIT_INPUT, "%s: an online map of %g m square for scans of up to %u"
                                    " beams: %s", input_name(o), rp.area_m, (unsigned)max_beams,
                        polyc_status_str(st));
    fit_limits_to_log(&cfg, &r->log, &lim);
    if (o->frames && (rc = frames_clash(o, r->log.count)) != 0)
        return rc;
    if (o->frames && make_frames_dir(o->frames))
        return EXIT_INPUT;
    rp.add_ms = malloc(2 * (size_t)r->log.count * sizeof *rp.add_ms);
    if (!rp.add_ms)
        return complain(EXIT_INPUT, "out of memory");
    rp.step_ms = rp.add_ms + r->log.count;
    size_t size = 0;
    for (;;) {
        rp.attempts++;
        int retry = rp.attempts < ONLINE_ATTEMPTS;
        rc = make_block(o, r, &cfg, &lim, &ctx, &size);
        if (rc == 0)
            rc = run_online(o, r, &cfg, ctx, size, retry, &rp, t);
        if (rc != RUN_AGAIN)
            break;
        /* grid cells, data cells and vertices are sized for a usual building:
         * four times as many, up to the whole square and the library's caps */
        double tiles = ceil(lim.area_m / (double)cfg.cell_m / 32.0);
        lim.max_grid_cells = times4(lim.max_grid_cells, fmin(tiles * tiles * 1024.0, 0x40000000));
        lim.max_points = times4(lim.max_points, 0x10000000);
        lim.max_vertices = times4(lim.max_vertices, 0x10000000);
    }
    if (rc == 0)
        rc = write_map(o, r, &cfg, ctx, size, t, t_start);
    if (rc == 0 && o->stats)
        print_online_stats(o, r, &rp, size);
    free(rp.add_ms);
    return rc;
}
