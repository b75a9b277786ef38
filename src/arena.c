/* arena.c - bump allocation inside the caller's block.
 * Takes: the block given to polyc_init. Gives: aligned, overflow-checked
 * allocations; running out returns NULL and leaves the arena unchanged. */
#include "internal.h"

#include <string.h>

#define POLYC__ALIGN 16u

size_t polyc__bytes(size_t count, size_t elem_size)
{
    if (elem_size != 0 && count > (SIZE_MAX - POLYC__ALIGN) / elem_size)
        return 0;
    return (count * elem_size + POLYC__ALIGN - 1) & ~(size_t)(POLYC__ALIGN - 1);
}

size_t polyc__add(size_t a, size_t b)
{
    return a > SIZE_MAX - b ? SIZE_MAX : a + b;
}

void *polyc__alloc(polyc__arena *a, size_t count, size_t elem_size)
{
    size_t bytes = polyc__bytes(count, elem_size);
    if (bytes == 0 && count != 0 && elem_size != 0)
        return NULL;
    if (bytes > a->size - a->used)
        return NULL;
    void *p = a->base + a->used;
    a->used += bytes;
    if (a->used > a->peak)
        a->peak = a->used;
    return p;
}

void *polyc__alloc_zero(polyc__arena *a, size_t count, size_t elem_size)
{
    void *p = polyc__alloc(a, count, elem_size);
    if (p)
        memset(p, 0, count * elem_size);
    return p;
}
