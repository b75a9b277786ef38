/* ctxblock.h - the one block the library runs in, as the tools make it:
 * polyc_memory_size for a configuration and limits, malloc, and polyc_init
 * on it. The library never allocates; this is the tools' side of "ask for
 * the size, then pass the block" (the polyc tool, and the bench and the
 * sweep through tools/eval/pipeline.c). */
#ifndef POLYC_CTXBLOCK_H
#define POLYC_CTXBLOCK_H

#include <stddef.h>

#include "polyc.h"

enum ctxblock_result {
    CTXBLOCK_OK = 0,
    CTXBLOCK_UNSIZED,     /* polyc_memory_size gave 0: the size overflows size_t */
    CTXBLOCK_OVER_CAP,    /* the size is over max_bytes: nothing allocated */
    CTXBLOCK_NOMEM,       /* malloc failed */
    CTXBLOCK_INIT         /* polyc_init failed: *init_status says why */
};

/* Sizes the block for cfg and lim into *size. Unless it is 0 or over
 * max_bytes (0: no cap), frees *block (NULL or an earlier block) and
 * mallocs a new one of *size bytes into *block (freed by the caller with
 * free()). With ctx, then runs polyc_init on it: *ctx and *init_status get
 * its results. Returns an enum ctxblock_result. */
int ctxblock_make(const polyc_config *cfg, const polyc_limits *lim, double max_bytes,
                  void **block, size_t *size, polyc_ctx **ctx, polyc_status *init_status);

/* The allocation alone, for a size from another query (an online context's,
 * polyc_online_memory_size): CTXBLOCK_UNSIZED for size 0, CTXBLOCK_OVER_CAP,
 * else *block (freed first) gets size bytes or CTXBLOCK_NOMEM. */
int ctxblock_alloc(size_t size, double max_bytes, void **block);

#endif /* POLYC_CTXBLOCK_H */
