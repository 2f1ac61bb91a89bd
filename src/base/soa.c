/* soa.c - growing the parallel arrays of a structure-of-arrays table together
 * (rt/base/soa.h): one capacity, doubled from 64, for every array. */
#include "rt/base/soa.h"

#include <stdint.h>

#include "rt/base/error.h"

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
