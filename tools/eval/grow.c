/* grow.c - growable arrays by doubling (grow.h). */
#include "grow.h"

#include <stdlib.h>

int grow_array(void **items, uint32_t *cap, uint32_t need, size_t elem_size)
{
    uint32_t new_cap;
    void *p;
    if (need <= *cap)
        return 0;
    new_cap = *cap ? *cap : 16u;
    while (new_cap < need) {
        if (new_cap > UINT32_MAX / 2u)
            return -1;
        new_cap *= 2u;
    }
    if ((size_t)new_cap > SIZE_MAX / elem_size)
        return -1;
    p = realloc(*items, (size_t)new_cap * elem_size);
    if (!p)
        return -1;
    *items = p;
    *cap = new_cap;
    return 0;
}
