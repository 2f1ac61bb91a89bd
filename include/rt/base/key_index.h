/* rt/base/key_index.h - a hash index from 128-bit keys (two uint64s: a
 * file's device and inode, a region's corners) to the first int stored
 * under each, so that finding the earlier entry with the same key among n
 * is O(1) expected and n entries cost O(n), not the n^2/2 comparisons of a
 * pairwise check. Open addressing with linear probing in a table at least
 * twice the capacity; `probes` counts the slots looked at, so a test can
 * hold the work to a bound.
 *
 *   rt_key_index ix;
 *   if (!rt_key_index_init(&ix, n)) ... out of memory ...
 *   for (int i = 0; i < n; i++) {
 *       uint64_t key[2] = {st.st_dev, st.st_ino};
 *       int first = rt_key_index_add(&ix, key, i);   // -1: new; else the value stored first
 *       if (first >= 0) ... entry i is entry first again ...
 *   }
 *   rt_key_index_free(&ix);
 */
#ifndef RT_KEY_INDEX_H
#define RT_KEY_INDEX_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct rt_key_index {
    uint64_t (*key)[2];
    int *value;        /* -1: an empty slot */
    size_t mask;       /* slots - 1 (a power of two) */
    size_t count, capacity;
    size_t probes;     /* slots looked at by every add so far */
} rt_key_index;

/* Room for `capacity` keys; false when out of memory (ix is then empty). */
bool rt_key_index_init(rt_key_index *ix, size_t capacity);
/* The value stored first under key, or (when there is none) -1 after
 * storing value (>= 0) under it. -2 when the index already holds its
 * capacity of keys. */
int rt_key_index_add(rt_key_index *ix, const uint64_t key[2], int value);
void rt_key_index_free(rt_key_index *ix);

#endif
