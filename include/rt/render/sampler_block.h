/* rt/render/sampler_block.h - a stratified sampler's values for eight
 * consecutive dimensions of one sample at once, and a path's cache of them.
 *
 *   float x[RT_SAMPLER_BLOCK], y[RT_SAMPLER_BLOCK];
 *   rt_sampler_block(RT_SAMPLER_SOBOL, key, index, spp, dim0, x, y);  // or RT_SAMPLER_CMJ
 *   // x[k], y[k] == rt_sampler_2d(kind, key, index, spp, dim0 + k), bit for bit
 *   // (Sobol: x[k] == rt_sampler_1d(RT_SAMPLER_SOBOL, key, index, spp, dim0 + k) too)
 *
 *   rt_sampler_cache c; rt_sampler_cache_clear(&c);     // a new sample (key, index)
 *   if (rt_sampler_block_usable())
 *       u = rt_sampler_cache_2d(&c, kind, key, index, spp, dim0, slot);  // slot < 8
 *
 * The path tracer reads a bounce's dimensions (bounce x (5 + lights) +
 * slot, rt/render/pathtrace.h) from one block: the first read of a bounce
 * fills it, the others read it. rt_sampler_block computes the eight
 * dimensions in the eight 32-bit lanes of AVX2 registers with the same
 * operations as sampler.h (integer ones mod 2^32; CMJ's float ones are
 * IEEE adds and divides in the same order, its quotients by the spp's grid
 * exact in doubles), so the same bits; the AVX2 code is compiled in on x86
 * with GCC or clang whatever the build's -march (a PORTABLE=1 build has it
 * too) and used when the CPU has AVX2. rt_sampler_block_scalar is the same
 * block one value at a time through sampler.h. A block costs about as much
 * as one or two values computed alone, so without AVX2
 * (rt_sampler_block_usable false) a caller should call rt_sampler_2d for
 * the values it reads instead. Values are a pure function of (kind, key,
 * index, spp, dim): the cache changes no bit of an image.
 */
#ifndef RT_SAMPLER_BLOCK_H
#define RT_SAMPLER_BLOCK_H

#include <stdbool.h>
#include <stdint.h>

#include "rt/render/sampler.h"

#define RT_SAMPLER_BLOCK 8

/* Values of dimensions dim0 .. dim0 + 7 (mod 2^32) of sample `index` (of
 * spp a pixel) of pixel key `key` for kind RT_SAMPLER_SOBOL or
 * RT_SAMPLER_CMJ: the AVX2 lanes when the CPU has them, else
 * rt_sampler_block_scalar. */
void rt_sampler_block(rt_sampler_kind kind, uint32_t key, uint32_t index, uint32_t spp, uint32_t dim0,
                      float x[RT_SAMPLER_BLOCK], float y[RT_SAMPLER_BLOCK]);
void rt_sampler_block_scalar(rt_sampler_kind kind, uint32_t key, uint32_t index, uint32_t spp, uint32_t dim0,
                             float x[RT_SAMPLER_BLOCK], float y[RT_SAMPLER_BLOCK]);
/* Whether rt_sampler_block runs in AVX2 lanes on this CPU. */
bool rt_sampler_block_simd(void);

/* One block of a path's current sample: dims dim0 .. dim0 + 7 when full. */
typedef struct rt_sampler_cache {
    float x[RT_SAMPLER_BLOCK], y[RT_SAMPLER_BLOCK];
    uint32_t dim0;
    bool full;
} rt_sampler_cache;

static inline void rt_sampler_cache_clear(rt_sampler_cache *c) { c->full = false; }

/* Worth using: blocks are computed in lanes (compile-time true in a build
 * for an AVX2 target). */
static inline bool rt_sampler_block_usable(void)
{
#if defined(__AVX2__)
    return true;
#else
    return rt_sampler_block_simd();
#endif
}

/* rt_sampler_2d(kind, key, index, spp, dim0 + slot), slot <
 * RT_SAMPLER_BLOCK, from the cache (filled first if it holds another
 * block). kind, key and index must be the same since it was cleared. */
static inline rt_vec2 rt_sampler_cache_2d(rt_sampler_cache *c, rt_sampler_kind kind, uint32_t key, uint32_t index,
                                          uint32_t spp, uint32_t dim0, uint32_t slot)
{
    if (!c->full || c->dim0 != dim0) {
        rt_sampler_block(kind, key, index, spp, dim0, c->x, c->y);
        c->dim0 = dim0;
        c->full = true;
    }
    return rt_v2(c->x[slot], c->y[slot]);
}

#endif
