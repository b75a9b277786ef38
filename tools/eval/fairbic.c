/* fairbic.c - the BIC of any map on a batch context's data (fairbic.h).
 * The one evaluation module that reaches into the library's internals (as
 * the unit tests do): a map is put into the polyline store directly, in the
 * store's frame (relative to the first pose). */
#include "fairbic.h"

#include "../../src/context.h"
#include "../../src/internal.h"

polyc_status fairbic_score(polyc_ctx *ctx, const polyc_polyline *lines, uint32_t count,
                           double *bic)
{
    if (!ctx || ctx->online || ctx->from_grid || ctx->stage < POLYC__STAGE_TRACE)
        return POLYC_ERR_STATE;
    polyc__store *s = &ctx->store;
    polyc__store_clear(s);
    for (uint32_t i = 0; i < count; i++) {
        int32_t line = polyc__line_new(s);
        if (line < 0)
            return POLYC_ERR_NOMEM;
        for (uint32_t j = 0; j < lines[i].point_count; j++) {
            double x = (double)lines[i].xy_m[2 * j] - ctx->frame_x;
            double y = (double)lines[i].xy_m[2 * j + 1] - ctx->frame_y;
            if (polyc__vertex_append(s, line, (float)x, (float)y) < 0)
                return POLYC_ERR_NOMEM;
        }
        if (lines[i].closed)
            polyc__line_close(s, line);
    }
    return polyc_score(ctx, bic, NULL);
}
