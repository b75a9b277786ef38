/* load.c - the polyc tool's input (cli.h).
 * Takes: the input's path. Gives: what it is (a log, a map YAML, an
 * image), the log's scans (scanlog.h) or the map's cells as an occupancy
 * grid (mapfile.h), and the --stats lines that describe them. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "outfile.h"
#include "readfile.h"
#include "textesc.h"

/* A map YAML or an image is told from a log by its first bytes. Only a
 * regular file is looked at (a pipe would lose what is read); anything
 * unreadable is left to the log reader, which reports it. */
enum input_kind sniff(const char *path)
{
    char head[65536];
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
        return INPUT_LOG;
    FILE *f = fopen(path, "rb");
    if (!f)
        return INPUT_LOG;
    size_t n = fread(head, 1, sizeof head, f);
    fclose(f);
    if (n >= 3 && head[0] == 'P' && (head[1] == '5' || head[1] == '2') &&
        (head[2] == ' ' || head[2] == '\n' || head[2] == '\r' || head[2] == '\t' || head[2] == '#'))
        return INPUT_IMAGE;
    if (n >= 8 && memcmp(head, "\x89PNG\r\n\x1a\n", 8) == 0)
        return INPUT_IMAGE;
    return mapfile_is_yaml(head, n) ? INPUT_MAP_YAML : INPUT_LOG;
}

int load_log(const options *o, run *r)
{
    progress_stage("reading the log");
    FILE *in = strcmp(o->input, "-") == 0 ? stdin : fopen(o->input, "rb");
    struct stat st;
    if (!in)
        return complain(EXIT_INPUT, "%s: %s", o->input, strerror(errno));
    if (fstat(fileno(in), &st) == 0 && S_ISDIR(st.st_mode)) {
        int rc = complain(EXIT_INPUT, "%s: %s: give a log file", o->input, strerror(EISDIR));
        if (in != stdin)
            fclose(in);
        return rc;
    }
    scanlog_opts so = {o->max_range_m};
    int bad = scanlog_read(&r->log, in, input_name(o), &so);
    if (in != stdin)
        fclose(in);
    return bad ? complain(EXIT_INPUT, "%s", r->log.error) : 0;
}

int load_map(const options *o, map_input *m)
{
    char *text;
    size_t len;
    int err = readfile(o->input, MAPFILE_MAX_YAML_BYTES, &text, &len);
    if (err == READFILE_TOO_LARGE)
        return complain(EXIT_INPUT, "%s: larger than %u bytes: not a map YAML", o->input,
                        MAPFILE_MAX_YAML_BYTES);
    if (err == READFILE_NOT_FILE)
        return complain(EXIT_INPUT, "%s: not a regular file", o->input);
    if (err)
        return complain(EXIT_INPUT, "%s: %s", o->input, strerror(err));
    int bad = mapfile_yaml_parse(&m->yaml, text, len, o->input);
    free(text);
    if (bad)
        return complain(EXIT_INPUT, "%s", m->yaml.error);
    if (!(m->image_path = mapfile_image_path(o->input, m->yaml.image)))
        return complain(EXIT_INPUT, "out of memory");
    char *shown = textesc_dup(m->image_path);
    if (!shown)
        return complain(EXIT_INPUT, "out of memory");
    const char *const outs[] = {o->output, o->trace};   /* before the image is read */
    const char *const opts[] = {"-o", "--trace"};
    for (int i = 0; i < 2; i++)
        if ((i == 0 || o->trace) && outfile_is_input(outs[i], m->image_path)) {
            int rc = complain(EXIT_USAGE, "%s '%s' is the map's image %s (the same file, named at"
                                          " %s:%u): it would be replaced; give another name",
                              opts[i], outs[i] ? outs[i] : "-", shown, o->input,
                              (unsigned)m->yaml.image_line);
            free(shown);
            return rc;
        }
    err = readfile(m->image_path, MAPFILE_MAX_PGM_BYTES, &text, &len);
    if (err) {
        unsigned line = (unsigned)m->yaml.image_line;
        int rc = err == READFILE_TOO_LARGE
                     ? complain(EXIT_INPUT, "%s:%u: image %s: larger than %u bytes", o->input, line,
                                shown, MAPFILE_MAX_PGM_BYTES)
                 : err == READFILE_NOT_FILE
                     ? complain(EXIT_INPUT, "%s:%u: image %s: not a regular file (a device or a"
                                            " FIFO): give a PGM or PNG file", o->input, line, shown)
                     : complain(EXIT_INPUT, "%s:%u: image %s: %s", o->input, line, shown,
                                strerror(err));
        free(shown);
        return rc;
    }
    /* --memory-mb bounds the decoding too (the file, its pixels, the cells):
     * refused from the header, before the pixels are allocated */
    double cap = o->memory_mb * 1048576.0;
    size_t budget = cap <= 0 ? 0 : (double)len >= cap ? 1 : (size_t)(cap - (double)len);
    bad = mapfile_image_read_capped(&m->image, (const uint8_t *)text, len, shown, &m->yaml,
                                    budget);
    free(text);
    if (bad && m->image.need_bytes) {
        double need = (double)len + (double)m->image.need_bytes;
        int rc = complain(EXIT_MEMORY, "memory budget too small: image %s needs %.0f bytes (%.1f"
                                       " MiB) to read (%u x %u pixels), --memory-mb %g allows %g"
                                       " MiB: give --memory-mb %.0f or more", shown, need,
                          need / 1048576.0, (unsigned)m->image.width, (unsigned)m->image.height,
                          o->memory_mb, o->memory_mb, ceil(need / 1048576.0));
        free(shown);
        return rc;
    }
    free(shown);
    if (bad)
        return complain(m->image.no_memory ? EXIT_MEMORY : EXIT_INPUT, "%s", m->image.error);
    m->cells = m->image.cells;
    size_t cells = (size_t)m->image.width * m->image.height;
    mapfile_grid(&m->yaml, m->image.width, m->image.height, m->cells, &m->grid);
    double occ = 100.0 * (double)o->config.occupied_thresh;
    double fre = 100.0 * (double)o->config.free_thresh;
    for (size_t i = 0; i < cells; i++) {
        int8_t v = m->cells[i];
        if (v >= 0 && (double)v >= occ)
            m->occupied++;
        else if (v >= 0 && (double)v <= fre)
            m->free_cells++;
        else
            m->unknown++;
    }
    return 0;
}

void print_input_stats(const scanlog *log)
{
    FILE *e = stderr;
    fprintf(e, "scans          %u (FLASER %llu, ROBOTLASER1 %llu, SCAN %llu)\n", log->count,
            (unsigned long long)log->kind_counts[SCANLOG_FLASER],
            (unsigned long long)log->kind_counts[SCANLOG_ROBOTLASER1],
            (unsigned long long)log->kind_counts[SCANLOG_PLAIN]);
    fprintf(e, "input beams    %llu (bad ranges %llu, below min range %llu)\n",
            (unsigned long long)log->beams, (unsigned long long)log->bad_ranges,
            (unsigned long long)log->short_ranges);
    fprintf(e, "lines skipped  %llu (", (unsigned long long)log->skipped_lines);
    for (uint32_t i = 0; i < log->keyword_count; i++)
        fprintf(e, "%s%s %llu", i ? ", " : "", log->keywords[i].name,
                (unsigned long long)log->keywords[i].count);
    fprintf(e, "), blank %llu\n", (unsigned long long)log->blank_lines);
    const scanlog_noreturn *nr = &log->noreturn;
    if (log->kind_counts[SCANLOG_FLASER]) {
        if (nr->overridden)
            fprintf(e, "no-return      FLASER max range %.3f m (--max-range)\n",
                    (double)nr->max_range_m);
        else if (nr->found)
            fprintf(e, "no-return      FLASER max range %.3f m: code %.2f..%.2f m, mode %.2f m,"
                       " %llu beams at or above\n",
                    (double)nr->max_range_m, nr->code_lo_m, nr->code_hi_m, nr->code_mode_m,
                    (unsigned long long)nr->code_beams);
        else
            fprintf(e, "no-return      FLASER: no code found, every range is a hit (max range"
                       " %.3f m)\n",
                    (double)nr->max_range_m);
    }
}

void print_map_stats(const map_input *m)
{
    static const char *const modes[] = {"trinary", "scale", "raw"};
    FILE *e = stderr;
    char *shown = textesc_dup(m->image_path);   /* no raw bytes on the terminal */
    fprintf(e, "map            %u x %u cells of %g m, %s (%s), mode %s%s\n",
            (unsigned)m->image.width, (unsigned)m->image.height, m->yaml.resolution_m,
            shown ? shown : "?", m->image.kind,
            modes[m->yaml.mode], m->yaml.negate ? ", negate" : "");
    free(shown);
    fprintf(e, "origin         %.6f %.6f m, yaw %.6f rad\n", m->yaml.origin_x_m,
            m->yaml.origin_y_m, m->yaml.origin_yaw_rad);
    fprintf(e, "cells          occupied %llu, free %llu, unknown %llu\n",
            (unsigned long long)m->occupied, (unsigned long long)m->free_cells,
            (unsigned long long)m->unknown);
}
