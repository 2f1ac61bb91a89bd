/* alloc.c - checked allocation, doubling arrays and structure-of-arrays
 * tables grown together (rt/base/alloc.h). */
#include "rt/base/alloc.h"

#include <stdint.h>
#include <stdlib.h>

void *rt_alloc(size_t count, size_t size)
{
    if (count == 0 || size == 0)
        return calloc(1, 1);
    if (count > SIZE_MAX / size)
        return NULL;
    return calloc(count, size);
}

void *rt_realloc_array(void *p, size_t count, size_t size)
{
    if (size && count > SIZE_MAX / size)
        return NULL;
    size_t bytes = count * size;
    return realloc(p, bytes ? bytes : 1);
}

int rt_grow(void **p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap)
        return 1;
    size_t c = *cap ? *cap : 16;
    while (c < need) {
        if (c > SIZE_MAX / 2)
            return 0;
        c *= 2;
    }
    void *q = rt_realloc_array(*p, c, size);
    if (!q)
        return 0;
    *p = q;
    *cap = c;
    return 1;
}

bool rt_soa_reserve(void **const arrays[], const size_t sizes[], int n, size_t *cap, size_t need)
{
    if (need <= *cap)
        return true;
    size_t c = *cap ? *cap : 64;
    while (c < need) {
        if (c > (SIZE_MAX >> 2))
            return false;
        c *= 2;
    }
    for (int i = 0; i < n; i++) {
        void *q = rt_realloc_array(*arrays[i], c, sizes[i]);
        if (!q)
            return false; /* arrays already grown keep their new size; cap stays: still consistent */
        *arrays[i] = q;
    }
    *cap = c;
    return true;
}
