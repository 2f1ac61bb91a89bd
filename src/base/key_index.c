/* key_index.c - a hash index from 128-bit keys to ints (rt/base/key_index.h):
 * open addressing with linear probing (Knuth, TAOCP vol. 3, 6.4, algorithm
 * L) in a power-of-two table at least twice the capacity, so a probe
 * sequence is short (about 1.5 slots for a hit, 2.5 for a miss, at load
 * 1/2); the slot from the splitmix64 finalizer (Steele, Lea, Flood, "Fast
 * splittable pseudorandom number generators", 2014) of the key's halves,
 * so keys in runs (inodes, corners) spread out. */
#include "rt/base/key_index.h"

#include <stdlib.h>
#include <string.h>

#include "rt/base/alloc.h"

static uint64_t mix(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

bool rt_key_index_init(rt_key_index *ix, size_t capacity)
{
    memset(ix, 0, sizeof *ix);
    size_t slots = 16;
    while (slots < 2 * capacity && slots <= SIZE_MAX / 4)
        slots *= 2;
    if (slots < 2 * capacity)
        return false;
    ix->key = rt_alloc(slots, sizeof *ix->key);
    ix->value = rt_alloc(slots, sizeof *ix->value);
    if (!ix->key || !ix->value) {
        rt_key_index_free(ix);
        return false;
    }
    for (size_t i = 0; i < slots; i++)
        ix->value[i] = -1;
    ix->mask = slots - 1;
    ix->capacity = capacity;
    return true;
}

int rt_key_index_add(rt_key_index *ix, const uint64_t key[2], int value)
{
    size_t at = (size_t)(mix(key[0] ^ mix(key[1])) & ix->mask);
    for (;; at = (at + 1) & ix->mask) {
        ix->probes++;
        if (ix->value[at] < 0)
            break;
        if (ix->key[at][0] == key[0] && ix->key[at][1] == key[1])
            return ix->value[at];
    }
    if (ix->count >= ix->capacity)
        return -2;
    ix->key[at][0] = key[0];
    ix->key[at][1] = key[1];
    ix->value[at] = value;
    ix->count++;
    return -1;
}

void rt_key_index_free(rt_key_index *ix)
{
    free(ix->key);
    free(ix->value);
    memset(ix, 0, sizeof *ix);
}
