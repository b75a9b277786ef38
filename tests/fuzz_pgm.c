/* fuzz_pgm.c - fuzz target for the PGM reader (tools/mapfile.c).
 * Takes: arbitrary bytes as a PGM file. Checks: no crash, no leak, no read
 * past the input, memory only for pixels the file holds; an image that
 * parses is within the bounds (width x height <= 2^28, samples <= maxval),
 * converts to OccupancyGrid values in -1..100 in every mode, and (maxval up
 * to 255) written as map_saver's P5 reads back to the same samples; a
 * refused one has a "NAME: byte N: " message without raw bytes.
 * Built with libFuzzer (`make fuzz`) or with tests/fuzz_replay.c, which
 * replays tests/corpus/pgm/ in plain CI. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mapfile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(x)                                                                  \
    do {                                                                          \
        if (!(x)) {                                                               \
            fprintf(stderr, "fuzz_pgm: check failed: %s (line %d)\n", #x, __LINE__); \
            abort();                                                              \
        }                                                                         \
    } while (0)

static void check_convert(const mapfile_pgm *p, size_t cells)
{
    int8_t *out = malloc(cells);
    CHECK(out != NULL);
    static const double th[][2] = {{0.65, 0.196}, {1.0, 0.0}, {0.5, 0.49}};
    for (int mode = MAPFILE_TRINARY; mode <= MAPFILE_RAW; mode++)
        for (int negate = 0; negate < 2; negate++)
            for (size_t t = 0; t < sizeof th / sizeof th[0]; t++) {
                mapfile_yaml y;
                memset(&y, 0, sizeof y);
                y.mode = mode;
                y.negate = negate;
                y.occupied_thresh = th[t][0];
                y.free_thresh = th[t][1];
                mapfile_to_cells(p, &y, out);
                for (size_t i = 0; i < cells; i++) {
                    CHECK(out[i] >= -1 && out[i] <= 100);
                    if (mode == MAPFILE_TRINARY)
                        CHECK(out[i] == -1 || out[i] == 0 || out[i] == 100);
                }
            }
    free(out);
}

static void check_write_back(const mapfile_pgm *p, size_t cells)
{
    uint8_t *px = malloc(cells);
    CHECK(px != NULL);
    for (size_t i = 0; i < cells; i++)
        px[i] = (uint8_t)p->samples[i];
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    CHECK(f != NULL);
    CHECK(mapfile_write_pgm(f, px, p->width, p->height, 0.05) == 0);
    CHECK(fclose(f) == 0);
    mapfile_pgm back;
    CHECK(mapfile_pgm_parse(&back, (const uint8_t *)text, len, "back") == 0);
    CHECK(back.width == p->width && back.height == p->height && back.maxval == 255);
    CHECK(memcmp(back.samples, p->samples, cells * sizeof *p->samples) == 0);
    mapfile_pgm_free(&back);
    free(text);
    free(px);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    mapfile_pgm p;
    if (mapfile_pgm_parse(&p, data, size, "fuzz") == 0) {
        size_t cells = (size_t)p.width * p.height;
        CHECK(p.width >= 1 && p.height >= 1 && cells <= MAPFILE_MAX_CELLS);
        CHECK(p.maxval >= 1 && p.maxval <= 65535);
        /* a P5 file holds every pixel; a P2 file at least a digit each */
        CHECK(p.plain ? cells <= size / 2 + 1 : cells * (p.maxval > 255 ? 2 : 1) < size);
        for (size_t i = 0; i < cells; i++)
            CHECK(p.samples[i] <= p.maxval);
        check_convert(&p, cells);
        if (p.maxval <= 255)
            check_write_back(&p, cells);
    } else {
        CHECK(strncmp(p.error, "fuzz: byte ", 11) == 0);
        CHECK(strlen(p.error) < sizeof p.error);
        for (const char *q = p.error; *q; q++)
            CHECK((unsigned char)*q >= 0x20 && (unsigned char)*q < 0x7f);
    }
    mapfile_pgm_free(&p);
    return 0;
}
