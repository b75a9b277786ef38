/* fuzz_scanlog.c - fuzz target for the log parser (tools/scanlog.c).
 * Takes: arbitrary bytes, read as a log through fmemopen. Checks: no crash,
 * no leak, no read past the input; a log that parses is written in the plain
 * format and read back to the same scans, bit for bit (docs/formats.md), and
 * every scan it gives is one the library accepts.
 * Built with libFuzzer (`make fuzz`) or with tests/fuzz_replay.c, which
 * replays tests/corpus/scanlog/ in plain CI. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "polyc.h"
#include "scanlog.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* A failed check is a finding: abort so that libFuzzer saves the input. */
#define CHECK(x)                                                                    \
    do {                                                                            \
        if (!(x)) {                                                                 \
            fprintf(stderr, "fuzz_scanlog: check failed: %s (line %d)\n", #x, __LINE__); \
            abort();                                                                \
        }                                                                           \
    } while (0)

static int same_float(float a, float b)
{
    return (isnan(a) && isnan(b)) || memcmp(&a, &b, sizeof a) == 0;
}

static int same_double(double a, double b)
{
    return (isnan(a) && isnan(b)) || memcmp(&a, &b, sizeof a) == 0;
}

static void check_scans_equal(const scanlog *a, const scanlog *b)
{
    CHECK(a->count == b->count);
    for (uint32_t i = 0; i < a->count; i++) {
        const polyc_scan *x = &a->scans[i], *y = &b->scans[i];
        CHECK(same_double(x->pose_x_m, y->pose_x_m));
        CHECK(same_double(x->pose_y_m, y->pose_y_m));
        CHECK(same_double(x->pose_theta_rad, y->pose_theta_rad));
        CHECK(same_float(x->start_angle_rad, y->start_angle_rad));
        CHECK(same_float(x->angle_step_rad, y->angle_step_rad));
        CHECK(same_float(x->min_range_m, y->min_range_m));
        CHECK(same_float(x->max_range_m, y->max_range_m));
        CHECK(x->beam_count == y->beam_count);
        for (uint32_t j = 0; j < x->beam_count; j++)
            CHECK(same_float(x->range_m[j], y->range_m[j]));
    }
}

/* Every scan the parser gives must pass the library's checks: the tool
 * promises a FILE:LINE message for a bad scan, not a refusal later on. */
static void check_library_accepts(const scanlog *log)
{
    static unsigned char block[1 << 16];
    polyc_config cfg;
    polyc_limits lim;
    polyc_ctx *ctx = NULL;
    polyc_config_default(&cfg);
    memset(&lim, 0, sizeof lim);
    lim.max_scans = 1;
    for (uint32_t i = 0; i < log->count; i++) {
        polyc_scan s = log->scans[i];
        lim.max_beams = s.beam_count;
        if (polyc_memory_size(&cfg, &lim) > sizeof block)
            continue;
        CHECK(polyc_init(block, sizeof block, &cfg, &lim, &ctx) == POLYC_OK);
        polyc_status st = polyc_add_scan(ctx, &s);
        if (st != POLYC_OK)
            fprintf(stderr, "fuzz_scanlog: line %llu: library refuses the scan: %s\n",
                    (unsigned long long)log->line_of_scan[i], polyc_last_error(ctx));
        CHECK(st == POLYC_OK);
    }
}

static void read_back(const scanlog *log, const scanlog_opts *opts)
{
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    CHECK(out != NULL);
    CHECK(scanlog_write_plain(out, log->scans, log->count) == 0);
    CHECK(fclose(out) == 0);
    FILE *in = fmemopen(text, len, "r");
    CHECK(in != NULL);
    scanlog again;
    int rc = scanlog_read(&again, in, "plain", opts);
    if (rc != 0)
        fprintf(stderr, "fuzz_scanlog: reading the plain form back: %s\n", again.error);
    CHECK(rc == 0);
    fclose(in);
    check_scans_equal(log, &again);
    scanlog_free(&again);
    free(text);
}

static void parse(const uint8_t *data, size_t size, const scanlog_opts *opts)
{
    /* fmemopen refuses a zero size; an empty log is tested via an empty stream */
    static char empty[1];
    FILE *f = size ? fmemopen((void *)(uintptr_t)data, size, "r") : fmemopen(empty, 1, "r");
    CHECK(f != NULL);
    if (!size)
        (void)getc(f);            /* now at the end: an empty input */
    scanlog log;
    int rc = scanlog_read(&log, f, "fuzz", opts);
    fclose(f);
    if (rc == 0) {
        CHECK(log.count > 0);
        CHECK(log.error[0] == '\0');
        check_library_accepts(&log);
        /* --max-range lowers max_range_m: the plain form carries it, read it
         * back without the option */
        read_back(&log, NULL);
    } else {
        CHECK(log.error[0] != '\0');
        CHECK(strlen(log.error) < sizeof log.error);
    }
    scanlog_free(&log);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    parse(data, size, NULL);
    /* the same bytes with --max-range 5 (the override path); halves speed
     * only for inputs that reach the FLASER rule or a max range */
    scanlog_opts opts = {5.0};
    parse(data, size, &opts);
    return 0;
}
