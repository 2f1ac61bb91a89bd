/* rt/base/alloc.h - checked allocation and growing arrays.
 *
 * Every helper returns NULL (or false) on failure and on size overflow, and
 * callers turn that into RT_ERR_NOMEM with a located message:
 *
 *   float *px = rt_alloc((size_t)w * h, 3 * sizeof *px);        // zeroed
 *   if (!rt_grow((void **)&list, &cap, count + 1, sizeof *list)) ...
 *
 * A structure-of-arrays table (the scene's spheres: cx, cy, cz, radius,
 * material) keeps one capacity for all of its arrays and grows them together:
 *
 *   void **arrays[] = {(void **)&sp->cx, (void **)&sp->cy, (void **)&sp->material};
 *   const size_t sizes[] = {sizeof *sp->cx, sizeof *sp->cy, sizeof *sp->material};
 *   if (!rt_soa_reserve(arrays, sizes, 3, &sp->cap, sp->count + 1))
 *       return RT_NONE;   // out of memory
 */
#ifndef RT_ALLOC_H
#define RT_ALLOC_H

#include <stdbool.h>
#include <stddef.h>

void *rt_alloc(size_t count, size_t size); /* zeroed; count or size 0 gives a 1-byte block */
void *rt_realloc_array(void *p, size_t count, size_t size);
/* Makes room for `need` elements of `size` bytes in *p, doubling *cap from
 * 16. Returns 0 when out of memory (then *p and *cap are unchanged). */
int rt_grow(void **p, size_t *cap, size_t need, size_t size);
/* Makes room for `need` elements in each of the n arrays (*arrays[i], of
 * sizes[i] bytes an element), doubling *cap from 64. false when out of
 * memory or the size overflows; the arrays grown before the failure keep
 * their new size and *cap its old value, so the table stays consistent. */
bool rt_soa_reserve(void **const arrays[], const size_t sizes[], int n, size_t *cap, size_t need);

#endif
