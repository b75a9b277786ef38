/* scanlog_noreturn.c - the FLASER no-return rule (scanlog.h,
 * docs/formats.md): which range is the scanner's code for "no return".
 * Takes: ranges, into a histogram of 1 cm bins. Gives: the threshold at or
 * above which a range is no return, and the code cluster it was found from. */
#include "scanlog_noreturn.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NR_BIN_M 0.01
#define NR_BINS 100000u              /* 0 .. 1000 m; beyond counts as no return */
#define NR_WINDOW 50u                /* the cluster lies within 0.5 m */
#define NR_SHOULDER 200u             /* compared with the 2 m just below it */

typedef scanlog_nr_hist nr_hist;

static void nr_add(nr_hist *h, float range_m)
{
    if (!(range_m >= SCANLOG_MIN_RANGE_M) || !isfinite(range_m))
        return;
    h->total++;
    /* + 0.002: 51.05f is 51.0499992, which belongs to the 51.05 bin */
    double k = floor((double)range_m / NR_BIN_M + 0.002);
    if (k >= (double)NR_BINS)
        h->beyond++;
    else
        h->bin[(uint32_t)k]++;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Median beams per bin over bins [lo, hi): the background density of real
 * returns, blind to a second code's spike (acapulco's 50.0 below 51.15). */
static double nr_median(const nr_hist *h, uint32_t lo, uint32_t hi)
{
    uint32_t tmp[NR_SHOULDER];
    uint32_t n = hi - lo;
    if (n == 0)
        return 0;
    memcpy(tmp, h->bin + lo, n * sizeof tmp[0]);
    qsort(tmp, n, sizeof tmp[0], cmp_u32);
    return n % 2 ? tmp[n / 2] : 0.5 * ((double)tmp[n / 2 - 1] + tmp[n / 2]);
}

/* Is [b-0.5 m, b] a code cluster: at least 3 beams and 0.05% of all, half
 * of them in one 1 cm bin (a code repeats one value; real returns spread),
 * and at least 16x the background density of the 2 m below it (median beams
 * per bin)? If so, *bottom is its lowest bin holding more than 1 + 4x that
 * median, so that stray real returns in the window stay hits. */
static int nr_cluster(const nr_hist *h, const uint64_t *prefix, uint32_t b, uint32_t *bottom)
{
    uint32_t lo = b >= NR_WINDOW ? b - NR_WINDOW : 0;
    uint32_t slo = lo >= NR_SHOULDER ? lo - NR_SHOULDER : 0;
    uint64_t t = prefix[b + 1] - prefix[lo];
    if (!h->bin[b] || t < 3 || t * 2000u < h->total)
        return 0;
    uint32_t peak = 0;
    for (uint32_t k = lo; k <= b; k++)
        peak = h->bin[k] > peak ? h->bin[k] : peak;
    if (2u * (uint64_t)peak < t)
        return 0;
    double median = nr_median(h, slo, lo);
    if ((double)t < 16.0 * median * (b - lo + 1))
        return 0;
    double dense = 1.0 + 4.0 * median;
    uint32_t k = lo;
    while (k < b && (double)h->bin[k] <= dense)
        k++;
    *bottom = k;
    return 1;
}

/* Walks down from the largest range to the first cluster that also holds at
 * least as many beams as everything above it: the main no-return code. Then
 * looks for more codes (acapulco has 50.0 besides 51.15) in the 10% of range
 * below, again and again. The threshold goes half a bin below the lowest
 * code. Without a cluster every range is a hit. prefix: NR_BINS + 1. */
static void nr_pick(const nr_hist *h, uint64_t *prefix, scanlog_noreturn *out)
{
    uint32_t top = 0, b, bottom = 0, next;
    int any = 0;
    prefix[0] = 0;
    for (b = 0; b < NR_BINS; b++) {
        prefix[b + 1] = prefix[b] + h->bin[b];
        if (h->bin[b]) {
            top = b;
            any = 1;
        }
    }
    memset(out, 0, sizeof *out);
    out->beams = h->total;
    out->max_range_m = any ? (float)((top + 1) * NR_BIN_M) : (float)(NR_BINS * NR_BIN_M);
    for (b = top + 1; any && b-- > 0;) {
        uint64_t above = prefix[top + 1] - prefix[b + 1] + h->beyond;
        if (nr_cluster(h, prefix, b, &bottom) && above <= prefix[b + 1] - prefix[bottom]) {
            out->found = 1;
            break;
        }
    }
    if (!out->found)
        return;
    out->code_hi_m = b * NR_BIN_M;
    for (int more = 1; more;) {
        more = 0;
        uint32_t limit = bottom - bottom / 10;
        for (b = bottom; b-- > limit;)
            if (nr_cluster(h, prefix, b, &next)) {
                bottom = next;
                more = 1;
                break;
            }
    }
    uint32_t mode = top;
    for (b = bottom; b <= top; b++)
        if (h->bin[b] > h->bin[mode])
            mode = b;
    out->max_range_m = (float)((bottom - 0.5) * NR_BIN_M);
    if (out->max_range_m <= SCANLOG_MIN_RANGE_M)   /* a code at 2 cm: keep max > min */
        out->max_range_m = SCANLOG_MIN_RANGE_M + (float)(NR_BIN_M / 2);
    out->code_lo_m = bottom * NR_BIN_M;
    out->code_mode_m = mode * NR_BIN_M;
    out->code_beams = prefix[top + 1] - prefix[bottom] + h->beyond;
}

int scanlog_nr_open(scanlog_nr_hist *h)
{
    h->bin = calloc(NR_BINS, sizeof(uint32_t));
    h->prefix = malloc((NR_BINS + 1) * sizeof *h->prefix);
    h->total = h->beyond = 0;
    if (h->bin && h->prefix)
        return 0;
    scanlog_nr_close(h);
    return -1;
}

void scanlog_nr_add(scanlog_nr_hist *h, float range_m)
{
    nr_add(h, range_m);
}

void scanlog_nr_pick(scanlog_nr_hist *h, scanlog_noreturn *out)
{
    nr_pick(h, h->prefix, out);
}

void scanlog_nr_close(scanlog_nr_hist *h)
{
    free(h->bin);
    free(h->prefix);
    h->bin = NULL;
    h->prefix = NULL;
}

void scanlog_detect_noreturn(const float *range_m, size_t count, scanlog_noreturn *out)
{
    scanlog_nr_hist h;
    memset(out, 0, sizeof *out);
    if (scanlog_nr_open(&h) != 0)
        return;
    for (size_t i = 0; i < count; i++)
        nr_add(&h, range_m[i]);
    nr_pick(&h, h.prefix, out);
    scanlog_nr_close(&h);
}
