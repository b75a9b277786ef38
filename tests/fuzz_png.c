/* fuzz_png.c - fuzz target for the PNG reader (tools/mapfile_png.c) and
 * its DEFLATE decoder (tools/inflate.c).
 * Takes: arbitrary bytes as a PNG file. Checks: no crash, no leak, no read
 * past the input; an image that reads is within the bounds (width x
 * height <= 2^28) with OccupancyGrid values in -1..100 in every mode (0,
 * 100 or -1 in trinary), the same pixels in every mode (an image reads in
 * one mode iff in all); a refused one has a "NAME: byte N: " message
 * without raw bytes and no cells.
 * Built with libFuzzer (`make fuzz`) or with tests/fuzz_replay.c, which
 * replays tests/corpus/png/ in plain CI. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mapfile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(x)                                                                  \
    do {                                                                          \
        if (!(x)) {                                                               \
            fprintf(stderr, "fuzz_png: check failed: %s (line %d)\n", #x, __LINE__); \
            abort();                                                              \
        }                                                                         \
    } while (0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    int first_rc = 0;
    for (int mode = MAPFILE_TRINARY; mode <= MAPFILE_RAW; mode++) {
        mapfile_yaml y;
        memset(&y, 0, sizeof y);
        y.mode = mode;
        y.negate = mode == MAPFILE_SCALE;
        y.occupied_thresh = 0.65;
        y.free_thresh = 0.196;
        mapfile_png p;
        int8_t *cells = (int8_t *)data; /* (must come back NULL on failure) */
        int rc = mapfile_png_read(&p, data, size, "fuzz", &y, &cells);
        if (mode == MAPFILE_TRINARY)
            first_rc = rc;
        CHECK(rc == first_rc);
        if (rc == 0) {
            size_t n = (size_t)p.width * p.height;
            CHECK(p.width >= 1 && p.height >= 1 && n <= MAPFILE_MAX_CELLS && cells != NULL);
            for (size_t i = 0; i < n; i++) {
                CHECK(cells[i] >= -1 && cells[i] <= 100);
                if (mode == MAPFILE_TRINARY)
                    CHECK(cells[i] == -1 || cells[i] == 0 || cells[i] == 100);
            }
            free(cells);
        } else {
            CHECK(cells == NULL);
            CHECK(strncmp(p.error, "fuzz: byte ", 11) == 0);
            CHECK(strlen(p.error) < sizeof p.error);
            for (const char *q = p.error; *q; q++)
                CHECK((unsigned char)*q >= 0x20 && (unsigned char)*q < 0x7f);
        }
    }
    return 0;
}
