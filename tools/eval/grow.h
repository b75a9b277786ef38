/* grow.h - the evaluation's growable arrays (scansim's scenes, gtscore's
 * truth files and wall index): room for `need` elements in *items, an
 * array of *cap elements of elem_size bytes, by doubling *cap (from 16);
 * 0, or -1 (the capacity or its bytes overflow, out of memory) with
 * *items and *cap as they were. *items is malloc'd: the owner frees it.
 *
 * SPDX-License-Identifier: MIT
 */
#ifndef GROW_H
#define GROW_H

#include <stddef.h>
#include <stdint.h>

int grow_array(void **items, uint32_t *cap, uint32_t need, size_t elem_size);

#endif /* GROW_H */
