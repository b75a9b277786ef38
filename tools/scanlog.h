/* scanlog.h - read laser logs (CARMEN FLASER / ROBOTLASER1, polyc plain
 * scans) into polyc_scan records, and write the plain format back.
 * Formats and rules: docs/formats.md. All memory is owned by the scanlog. */
#ifndef POLYC_SCANLOG_H
#define POLYC_SCANLOG_H

#include <stdint.h>
#include <stdio.h>

#include "polyc.h"

/* Limits on untrusted input (docs/formats.md, "Limits"). */
#define SCANLOG_MAX_LINE_BYTES   (32u * 1024u * 1024u)
#define SCANLOG_MAX_BEAMS_SCAN   (1u << 20)
#define SCANLOG_MAX_POSE_M       1e6
#define SCANLOG_MAX_ANGLE_RAD    1e3
#define SCANLOG_MIN_RANGE_M      0.02f  /* Hokuyo error codes are 0..19 mm */
#define SCANLOG_MAX_KEYWORDS     16
/* The library's limits on a scan's angles (polyc_add_scan), checked here */
#define SCANLOG_MAX_START_RAD    100.0f
#define SCANLOG_MAX_STEP_RAD     6.2832f

enum scanlog_kind { SCANLOG_FLASER = 1, SCANLOG_ROBOTLASER1 = 2, SCANLOG_PLAIN = 3 };

typedef struct scanlog_opts {
    double max_range_m;        /* > 0.02: FLASER no-return threshold (no detection);
                                  other formats: lowers max_range_m to this;
                                  other values: ignored */
} scanlog_opts;

/* Line types that were skipped, with their counts (first SCANLOG_MAX_KEYWORDS). */
typedef struct scanlog_keyword {
    char name[24];
    uint64_t count;
} scanlog_keyword;

/* FLASER no-return detection result (docs/formats.md). */
typedef struct scanlog_noreturn {
    int found;                 /* 1: a code cluster was found */
    int overridden;            /* 1: --max-range given */
    float max_range_m;         /* threshold used for every FLASER scan */
    double code_lo_m;          /* smallest and largest value in the cluster */
    double code_hi_m;
    double code_mode_m;        /* most frequent value (1 cm bins) */
    uint64_t code_beams;       /* beams in the cluster (no return) */
    uint64_t beams;            /* FLASER beams looked at */
} scanlog_noreturn;

typedef struct scanlog {
    polyc_scan *scans;         /* count scans, valid after scanlog_read */
    uint32_t count;
    uint64_t *line_of_scan;    /* 1-based input line of each scan */
    uint8_t *kind_of_scan;     /* enum scanlog_kind */
    uint64_t lines;            /* lines read */
    uint64_t blank_lines;
    uint64_t skipped_lines;    /* comments and other line types */
    uint64_t beams;
    uint64_t bad_ranges;       /* NaN, inf, negative: passed on as NaN (skipped) */
    uint64_t short_ranges;     /* CARMEN ranges below SCANLOG_MIN_RANGE_M: NaN too */
    uint64_t kind_counts[4];   /* scans per enum scanlog_kind */
    scanlog_keyword keywords[SCANLOG_MAX_KEYWORDS];
    uint32_t keyword_count;
    scanlog_noreturn noreturn;
    char error[512];           /* "NAME:LINE: what is wrong" after a failure */
    /* private */
    float *pool;               /* every range, scan after scan */
    size_t pool_len, pool_cap;
    size_t *offset_of_scan;
    uint32_t cap;
} scanlog;

/* Reads every line of `f` (named `name` in messages). Returns 0, or -1 with
 * log->error set; either way call scanlog_free. A log without scans is an
 * error. opts may be NULL. */
int scanlog_read(scanlog *log, FILE *f, const char *name, const scanlog_opts *opts);
void scanlog_free(scanlog *log);

/* Writes scans in the plain format; 0 or -1 (stream error). Reading the
 * result back gives bit-identical polyc_scan records. */
int scanlog_write_plain(FILE *f, const polyc_scan *scans, uint32_t count);

/* The FLASER rule on its own, for tests: the threshold for a set of ranges. */
void scanlog_detect_noreturn(const float *range_m, size_t count, scanlog_noreturn *out);

#endif /* POLYC_SCANLOG_H */
