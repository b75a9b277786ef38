/* gtround.c - maps with circles and arcs for the scorers (gtround.h). */
#include "gtround.h"

#include <stdlib.h>
#include <string.h>

int gtround_score(gtround_map *m)
{
    free(m->scored);
    free(m->scored_xy);
    m->count = m->map.count;
    return curves_flatten(&m->map, GTROUND_SAGITTA_M, &m->scored, &m->scored_xy);
}

polyc_status gtround_from_ctx(polyc_ctx *ctx, gtround_map *m)
{
    memset(m, 0, sizeof *m);
    polyc_status st = curves_from_ctx(ctx, 0, &m->map);
    if (st != POLYC_OK)
        return st;
    return gtround_score(m) == 0 ? POLYC_OK : POLYC_ERR_NOMEM;
}

void gtround_free(gtround_map *m)
{
    curves_free(&m->map);
    free(m->scored);
    free(m->scored_xy);
    memset(m, 0, sizeof *m);
}

void gtround_params(const gtround_map *m, uint32_t *vertices, uint32_t *params, uint32_t *arcs,
                    uint32_t *circles)
{
    const curves_map *c = &m->map;
    *vertices = *params = *arcs = *circles = 0;
    for (uint32_t i = 0; i < c->count; i++) {
        if (c->circ && c->circ[i].radius_m > 0.0f) {
            if (c->circ[i].same_as == i) { /* (once for the pieces of a ring) */
                (*circles)++;
                *params += 3u;
            }
            continue;
        }
        const float *b = curves_bulges(c, i);
        *vertices += c->lines[i].point_count;
        *params += 2u * c->lines[i].point_count;
        for (uint32_t k = 0; b && k < c->lines[i].point_count; k++)
            if (b[k] != 0.0f) {
                (*arcs)++;
                (*params)++;
            }
    }
}
