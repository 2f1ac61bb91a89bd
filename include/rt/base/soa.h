/* rt/base/soa.h - growing the parallel arrays of a structure-of-arrays table
 * together.
 *
 * A table such as the scene's spheres (cx, cy, cz, radius, material) or a
 * mesh buffer's vertices keeps one capacity for all of its arrays. To make
 * room, list the addresses of the array pointers and their element sizes:
 *
 *   void **arrays[] = {(void **)&sp->cx, (void **)&sp->cy, (void **)&sp->material};
 *   const size_t sizes[] = {sizeof *sp->cx, sizeof *sp->cy, sizeof *sp->material};
 *   if (!rt_soa_reserve(arrays, sizes, 3, &sp->cap, sp->count + 1))
 *       return RT_NONE;   // out of memory
 *
 * Capacities start at 64 and double. Arrays that are NULL are allocated.
 */
#ifndef RT_SOA_H
#define RT_SOA_H

#include <stdbool.h>
#include <stddef.h>

/* Makes room for `need` elements in each of the n arrays (*arrays[i], of
 * sizes[i] bytes an element) and updates *cap. false when out of memory or
 * the size overflows; the arrays grown before the failure keep their new
 * size and *cap its old value, so the table stays consistent. */
bool rt_soa_reserve(void **const arrays[], const size_t sizes[], int n, size_t *cap, size_t need);

#endif
