/* rt/render/sobol_block.h - the Sobol sampler's values for eight
 * consecutive dimensions of one sample at once, and a path's cache of them.
 *
 *   float x[RT_SOBOL_BLOCK], y[RT_SOBOL_BLOCK];
 *   rt_sobol_block(key, index, spp, dim0, x, y);
 *   // x[k], y[k] == rt_sampler_2d(RT_SAMPLER_SOBOL, key, index, spp, dim0 + k), bit for bit
 *   //        x[k] == rt_sampler_1d(RT_SAMPLER_SOBOL, key, index, spp, dim0 + k)
 *
 *   rt_sobol_cache c; rt_sobol_cache_clear(&c);        // a new sample (key, index)
 *   if (rt_sobol_cache_usable()) u = rt_sobol_cache_2d(&c, key, index, spp, dim0, slot);  // slot < 8
 *
 * The path tracer reads a bounce's dimensions (bounce x (5 + lights) +
 * slot, rt/render/pathtrace.h) from one block: the first read of a bounce
 * fills it, the others read it. rt_sobol_block computes the eight
 * dimensions in the eight 32-bit lanes of AVX2 registers (the hashes, the
 * bit reversals by byte shuffles, the generator matrix and the scrambles
 * are the same integer operations as sampler.h's, so the same bits); the
 * AVX2 code is compiled in on x86 with GCC or clang whatever the build's
 * -march (a PORTABLE=1 build has it too) and used when the CPU has AVX2.
 * rt_sobol_block_scalar is the same block one value at a time through
 * sampler.h. A block costs about as much as one value computed alone, so
 * without AVX2 (rt_sobol_cache_usable false) a caller should call
 * rt_sampler_2d for the values it reads instead. Values are a pure
 * function of (key, index, spp, dim): the cache changes no bit of an image.
 */
#ifndef RT_SOBOL_BLOCK_H
#define RT_SOBOL_BLOCK_H

#include <stdbool.h>
#include <stdint.h>

#include "rt/render/sampler.h"

#define RT_SOBOL_BLOCK 8

/* Sobol values of dimensions dim0 .. dim0 + 7 (mod 2^32) of sample `index`
 * (of spp a pixel) of pixel key `key`: the AVX2 lanes when the CPU has
 * them, else rt_sobol_block_scalar. */
void rt_sobol_block(uint32_t key, uint32_t index, uint32_t spp, uint32_t dim0, float x[RT_SOBOL_BLOCK],
                    float y[RT_SOBOL_BLOCK]);
void rt_sobol_block_scalar(uint32_t key, uint32_t index, uint32_t spp, uint32_t dim0, float x[RT_SOBOL_BLOCK],
                           float y[RT_SOBOL_BLOCK]);
/* Whether rt_sobol_block runs in AVX2 lanes on this CPU. */
bool rt_sobol_block_simd(void);

/* One block of a path's current sample: dims dim0 .. dim0 + 7 when full. */
typedef struct rt_sobol_cache {
    float x[RT_SOBOL_BLOCK], y[RT_SOBOL_BLOCK];
    uint32_t dim0;
    bool full;
} rt_sobol_cache;

static inline void rt_sobol_cache_clear(rt_sobol_cache *c) { c->full = false; }

/* Worth using: the block is computed in lanes (compile-time true in a
 * build for an AVX2 target). */
static inline bool rt_sobol_cache_usable(void)
{
#if defined(__AVX2__)
    return true;
#else
    return rt_sobol_block_simd();
#endif
}

/* rt_sampler_2d(RT_SAMPLER_SOBOL, key, index, spp, dim0 + slot), slot <
 * RT_SOBOL_BLOCK, from the cache (filled first if it holds another block).
 * key and index must be the cache's sample's since it was cleared. */
static inline rt_vec2 rt_sobol_cache_2d(rt_sobol_cache *c, uint32_t key, uint32_t index, uint32_t spp, uint32_t dim0,
                                        uint32_t slot)
{
    if (!c->full || c->dim0 != dim0) {
        rt_sobol_block(key, index, spp, dim0, c->x, c->y);
        c->dim0 = dim0;
        c->full = true;
    }
    return rt_v2(c->x[slot], c->y[slot]);
}

#endif
