/* fuzz_mapyaml.c - fuzz target for the map YAML reader (tools/mapfile.c).
 * Takes: arbitrary bytes as a map YAML. Checks: no crash, no leak, no read
 * past the input; a YAML that parses has every field within its documented
 * bounds, and written back as map_saver writes it (mapfile_write_yaml) it
 * reads back to the same image name, resolution and origin; a refused one
 * has a "NAME:LINE: " message without raw bytes.
 * Built with libFuzzer (`make fuzz`) or with tests/fuzz_replay.c, which
 * replays tests/corpus/mapyaml/ in plain CI. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mapfile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* A failed check is a finding: abort so that libFuzzer saves the input. */
#define CHECK(x)                                                                      \
    do {                                                                              \
        if (!(x)) {                                                                   \
            fprintf(stderr, "fuzz_mapyaml: check failed: %s (line %d)\n", #x, __LINE__); \
            abort();                                                                  \
        }                                                                             \
    } while (0)

static int printable(const char *s)
{
    for (; *s; s++)
        if ((unsigned char)*s < 0x20 || (unsigned char)*s >= 0x7f)
            return 0;
    return 1;
}

static void check_fields(const mapfile_yaml *y)
{
    CHECK(y->error[0] == '\0');
    CHECK(y->image != NULL && y->image[0] != '\0');
    CHECK(strlen(y->image) <= MAPFILE_MAX_IMAGE_NAME);
    CHECK(y->resolution_m >= MAPFILE_MIN_RESOLUTION_M && y->resolution_m <= MAPFILE_MAX_RESOLUTION_M);
    CHECK(fabs(y->origin_x_m) <= MAPFILE_MAX_ORIGIN_M && fabs(y->origin_y_m) <= MAPFILE_MAX_ORIGIN_M);
    CHECK(fabs(y->origin_yaw_rad) <= MAPFILE_MAX_YAW_RAD);
    CHECK(y->negate == 0 || y->negate == 1);
    CHECK(y->free_thresh >= 0.0 && y->occupied_thresh <= 1.0);
    CHECK(y->free_thresh < y->occupied_thresh);
    CHECK(y->mode == MAPFILE_TRINARY || y->mode == MAPFILE_SCALE || y->mode == MAPFILE_RAW);
    CHECK(y->image_line >= 1 && y->image_line <= y->lines);
    CHECK(y->resolution_line >= 1 && y->resolution_line <= y->lines);
    CHECK(y->origin_line >= 1 && y->origin_line <= y->lines);
}

/* map_saver's text for these fields reads back to them (%f: 1e-6). */
static void check_write_back(const mapfile_yaml *y)
{
    /* a name with a line break or other control byte cannot be written on
     * one line; polyc grid refuses such a prefix */
    for (const char *q = y->image; *q; q++)
        if ((unsigned char)*q < 0x20 || *q == 0x7f)
            return;
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    CHECK(f != NULL);
    CHECK(mapfile_write_yaml(f, y->image, y->resolution_m, y->origin_x_m, y->origin_y_m) == 0);
    CHECK(fclose(f) == 0);
    mapfile_yaml back;
    int rc = mapfile_yaml_parse(&back, text, len, "back");
    if (rc != 0)
        fprintf(stderr, "fuzz_mapyaml: reading the written YAML back: %s\n", back.error);
    CHECK(rc == 0);
    CHECK(strcmp(back.image, y->image) == 0);
    CHECK(fabs(back.resolution_m - y->resolution_m) <= 5e-7);
    CHECK(fabs(back.origin_x_m - y->origin_x_m) <= 5e-7);
    CHECK(fabs(back.origin_y_m - y->origin_y_m) <= 5e-7);
    CHECK(back.origin_yaw_rad == 0.0 && back.negate == 0 && back.mode == MAPFILE_TRINARY);
    mapfile_yaml_free(&back);
    free(text);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    (void)mapfile_is_yaml((const char *)data, size);
    mapfile_yaml y;
    if (mapfile_yaml_parse(&y, (const char *)data, size, "fuzz") == 0) {
        check_fields(&y);
        check_write_back(&y);
    } else {
        CHECK(strncmp(y.error, "fuzz:", 5) == 0);
        CHECK(strlen(y.error) < sizeof y.error);
        CHECK(printable(y.error));
        CHECK(y.image == NULL || y.image[0] != '\0');
    }
    mapfile_yaml_free(&y);
    return 0;
}
