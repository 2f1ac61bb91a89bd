/* rt/sampling.h - deterministic random numbers and sample patterns.
 *
 * Every random number a render uses is a pure function of (seed, pixel,
 * sample index, draw order), so an image is bit-identical whatever the
 * number of threads or the order tiles are rendered in, and a crop equals
 * the same pixels of the full image.
 *
 *   rt_rng rng = rt_rng_for_sample(seed, pixel_index, sample_index);
 *   (rng.key, rng.index: the sample, for the stratified samplers of rt/render/sampler.h)
 *   float u = rt_rng_float(&rng);
 *   rt_vec2 p = rt_cmj_sample(sample_index, samples, pattern);  // stratified 2D point
 *
 * Generator: PCG32 (O'Neill 2014, "PCG: A Family of Simple Fast
 * Space-Efficient Statistically Good Algorithms for Random Number
 * Generation"), seeded through the splitmix64 finaliser.
 * Pixel samples: correlated multi-jittered sampling (Kensler 2013,
 * "Correlated Multi-Jittered Sampling", Pixar Technical Memo 13-01), which
 * stratifies any sample count in 2D and in each 1D projection.
 */
#ifndef RT_SAMPLING_H
#define RT_SAMPLING_H

#include <stdint.h>

#include "rt/base/vec.h"

/* A PCG stream, and the sample it belongs to for the stratified samplers
 * (rt/render/sampler.h): key = a hash of (seed, pixel), index = the
 * sample's global index in its pixel (both 0 for rt_rng_seed streams). */
typedef struct rt_rng {
    uint64_t state, inc;
    uint32_t key, index;
} rt_rng;

static inline uint64_t rt_mix64(uint64_t z)
{
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static inline uint32_t rt_rng_u32(rt_rng *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ull + r->inc;
    uint32_t xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

/* Uniform in [0, 1): 24 random bits, so never rounds up to 1. */
static inline float rt_rng_float(rt_rng *r) { return (float)(rt_rng_u32(r) >> 8) * (1.0f / 16777216.0f); }

static inline rt_rng rt_rng_seed(uint64_t a, uint64_t b)
{
    rt_rng r;
    r.state = rt_mix64(a);
    r.inc = (rt_mix64(b ^ 0x5851f42d4c957f2dull) << 1u) | 1u;
    r.key = r.index = 0;
    rt_rng_u32(&r);
    return r;
}

static inline rt_rng rt_rng_for_sample(uint32_t seed, uint64_t pixel, uint32_t sample)
{
    rt_rng r = rt_rng_seed(pixel * 0x9e3779b97f4a7c15ull ^ seed, ((uint64_t)seed << 32) | sample);
    r.key = (uint32_t)rt_mix64(pixel ^ ((uint64_t)seed << 40) ^ 0x2545f4914f6cdd1dull);
    r.index = sample;
    return r;
}

/* Kensler's hash-based permutation of [0, l) indexed by i, for pattern p. */
static inline uint32_t rt_cmj_permute(uint32_t i, uint32_t l, uint32_t p)
{
    uint32_t w = l - 1;
    w |= w >> 1; w |= w >> 2; w |= w >> 4; w |= w >> 8; w |= w >> 16;
    do {
        i ^= p; i *= 0xe170893du; i ^= p >> 16;
        i ^= (i & w) >> 4; i ^= p >> 8; i *= 0x0929eb3fu;
        i ^= p >> 23; i ^= (i & w) >> 1; i *= 1u | p >> 27;
        i *= 0x6935fa69u; i ^= (i & w) >> 11; i *= 0x74dcb303u;
        i ^= (i & w) >> 2; i *= 0x9e501cc3u; i ^= (i & w) >> 2;
        i *= 0xc860a3dfu; i &= w; i ^= i >> 5;
    } while (i >= l);
    return (i + p) % l;
}

static inline float rt_cmj_randfloat(uint32_t i, uint32_t p)
{
    i ^= p; i ^= i >> 17; i ^= i >> 10; i *= 0xb36534e5u; i ^= i >> 12;
    i ^= i >> 21; i *= 0x93fc4795u; i ^= 0xdf6e307fu; i ^= i >> 17;
    i *= 1u | p >> 18;
    return (float)(i >> 8) * (1.0f / 16777216.0f);
}

/* The grid of n samples: m columns, k rows, m*k >= n. */
static inline void rt_cmj_grid(uint32_t n, uint32_t *m_out, uint32_t *k_out)
{
    uint32_t m = (uint32_t)sqrtf((float)n);
    if (m == 0) m = 1;
    while (m * m > n) m--;
    *m_out = m;
    *k_out = (n + m - 1) / m;
}

/* Sample s of n (any n >= 1) of pattern p: a point in [0,1)^2. */
static inline rt_vec2 rt_cmj_sample(uint32_t s, uint32_t n, uint32_t p)
{
    uint32_t m, k;
    rt_cmj_grid(n, &m, &k);
    uint32_t sx = rt_cmj_permute(s % m, m, p * 0xa511e9b3u);
    uint32_t sy = rt_cmj_permute(s / m, k, p * 0x63d83595u);
    float jx = rt_cmj_randfloat(s, p * 0xa399d265u);
    float jy = rt_cmj_randfloat(s, p * 0x711ad6a5u);
    float x = ((float)(s % m) + ((float)sy + jx) / (float)k) / (float)m;
    float y = ((float)(s / m) + ((float)sx + jy) / (float)m) / (float)k;
    return rt_v2(rt_fminf(x, 0x1.fffffep-1f), rt_fminf(y, 0x1.fffffep-1f));
}

/* Cosine-weighted direction about +z from a point in [0,1)^2 (Malley's
 * method: uniform disk by concentric mapping, lifted to the hemisphere). */
static inline rt_vec3 rt_sample_cosine_hemisphere(rt_vec2 u)
{
    float a = 2.0f * u.x - 1.0f, b = 2.0f * u.y - 1.0f;
    float r, phi;
    if (a == 0.0f && b == 0.0f) {
        r = 0.0f; phi = 0.0f;
    } else if (fabsf(a) > fabsf(b)) {
        r = a; phi = (RT_PI / 4.0f) * (b / a);
    } else {
        r = b; phi = (RT_PI / 2.0f) - (RT_PI / 4.0f) * (a / b);
    }
    float sn, cs;
    rt_sincosf(phi, &sn, &cs);
    float x = r * cs, y = r * sn;
    float z = sqrtf(rt_fmaxf(0.0f, 1.0f - x * x - y * y));
    return rt_v3(x, y, z);
}

/* Uniform point on a disk of radius 1 (concentric mapping). */
static inline rt_vec2 rt_sample_disk(rt_vec2 u)
{
    rt_vec3 h = rt_sample_cosine_hemisphere(u);
    return rt_v2(h.x, h.y);
}

#endif
