/* fairbic.h - the BIC of any map on a batch context's data.
 *
 * An online map's own BIC is on the online data (each point weighed as the
 * online accuracy learned it), so it cannot be set beside a batch map's.
 * fairbic_score puts the given polylines in place of a built batch
 * context's map and scores them on that context's points, weights and
 * prior, as polyc_score scores the batch map: the two BICs are then on the
 * same data. The context's own map is gone afterwards (its result records,
 * polyc_get_polyline, are not touched until the next build).
 * Takes: a context after polyc_build (or polyc_optimize). Gives: the BIC. */
#ifndef FAIRBIC_H
#define FAIRBIC_H

#include "polyc.h"

/* POLYC_OK and *bic; POLYC_ERR_NOMEM when the lines exceed the context's
 * vertex limit; the status of polyc_score otherwise */
polyc_status fairbic_score(polyc_ctx *ctx, const polyc_polyline *lines, uint32_t count,
                           double *bic);

#endif
