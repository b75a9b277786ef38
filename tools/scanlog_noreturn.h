/* scanlog_noreturn.h - the FLASER no-return rule's histogram, for the log
 * reader (scanlog.c), which pools the ranges of many scans; one array of
 * ranges goes through scanlog_detect_noreturn (scanlog.h). */
#ifndef POLYC_SCANLOG_NORETURN_H
#define POLYC_SCANLOG_NORETURN_H

#include <stdint.h>

#include "scanlog.h"

typedef struct scanlog_nr_hist {
    uint32_t *bin;                   /* beams per 1 cm bin, 0 .. 1000 m */
    uint64_t total;                  /* valid ranges seen, beyond included */
    uint64_t beyond;                 /* >= 1000 m */
    uint64_t *prefix;                /* scratch of scanlog_nr_pick */
} scanlog_nr_hist;

/* An empty histogram (malloc'ed bins): 0, or -1 if out of memory (then
 * nothing to close). */
int scanlog_nr_open(scanlog_nr_hist *h);
/* Counts one range (below SCANLOG_MIN_RANGE_M or not finite: ignored). */
void scanlog_nr_add(scanlog_nr_hist *h, float range_m);
/* The no-return threshold for the ranges counted so far. */
void scanlog_nr_pick(scanlog_nr_hist *h, scanlog_noreturn *out);
void scanlog_nr_close(scanlog_nr_hist *h);

#endif /* POLYC_SCANLOG_NORETURN_H */
