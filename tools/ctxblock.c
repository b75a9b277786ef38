/* ctxblock.c - size, malloc and init of the library's block (ctxblock.h).
 * Takes: a configuration and limits. Gives: a block and a context on it. */
#include "ctxblock.h"

#include <stdlib.h>

int ctxblock_alloc(size_t size, double max_bytes, void **block)
{
    if (size == 0)
        return CTXBLOCK_UNSIZED;
    if (max_bytes > 0 && (double)size > max_bytes)
        return CTXBLOCK_OVER_CAP;
    free(*block);
    return (*block = malloc(size)) ? CTXBLOCK_OK : CTXBLOCK_NOMEM;
}

int ctxblock_make(const polyc_config *cfg, const polyc_limits *lim, double max_bytes,
                  void **block, size_t *size, polyc_ctx **ctx, polyc_status *init_status)
{
    *size = polyc_memory_size(cfg, lim);
    int made = ctxblock_alloc(*size, max_bytes, block);
    if (made != CTXBLOCK_OK || !ctx)
        return made;
    *init_status = polyc_init(*block, *size, cfg, lim, ctx);
    return *init_status == POLYC_OK ? CTXBLOCK_OK : CTXBLOCK_INIT;
}
