/* arena.c - bump allocation inside the caller's block.
 * Takes: the block given to polyc_init. Gives: aligned, overflow-checked
 * allocations; running out returns NULL and leaves the arena unchanged.
 * A counting arena (polyc__arena_counting: no block) hands out no memory:
 * each allocation only advances `used` and `peak` and returns a pointer that
 * must not be dereferenced. polyc_memory_size runs every stage's carve on one,
 * so the size query is the allocating code itself, not a second formula. */
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

void polyc__arena_counting(polyc__arena *a)
{
    a->base = NULL;
    a->size = SIZE_MAX;
    a->used = a->peak = 0;
}

void *polyc__alloc(polyc__arena *a, size_t count, size_t elem_size)
{
    size_t bytes = polyc__bytes(count, elem_size);
    if (bytes == 0 && count != 0 && elem_size != 0)
        return NULL;
    if (!a->base) {
        a->used = polyc__add(a->used, bytes);
        if (a->used > a->peak)
            a->peak = a->used;
        return a; /* not NULL; never read or written */
    }
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
    if (p && a->base)
        memset(p, 0, count * elem_size);
    return p;
}
