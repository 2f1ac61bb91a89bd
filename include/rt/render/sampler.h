/* rt/render/sampler.h - stratified values for every dimension of a path.
 *
 * A sample's value in dimension `dim` is a pure function of (the pixel's
 * key, the sample's global index, the render's samples per pixel, dim), so
 * an image is the same for any thread count, tile size, pass split, part
 * of the samples and tracer (wavefront or scalar). The key and index travel
 * in the sample's rt_rng (rt_rng_for_sample sets them; sampling.h):
 *
 *   rt_rng rng = rt_rng_for_sample(seed, pixel, s);       // key and index of sample s
 *   rt_vec2 u = rt_sample_2d(RT_SAMPLER_SOBOL, spp, &rng, dim);
 *   float   v = rt_sample_1d(RT_SAMPLER_SOBOL, spp, &rng, dim + 1);
 *
 * RT_SAMPLER_INDEPENDENT draws from the rng's PCG stream instead, in call
 * order (rt's sampler before this file: the image bytes of that time).
 * Every dimension (a 1D value or a 2D pair) has its own randomisation and
 * its own order of the samples, so the dimensions of one sample are
 * independent of each other ("padding"), and the samples of one pixel are
 * stratified in each:
 *
 *   RT_SAMPLER_CMJ    correlated multi-jittering (Kensler 2013) over the
 *                     render's spp: a pattern per (pixel, dim) and a hashed
 *                     permutation of the sample index per (pixel, dim). The
 *                     spp points of a pixel are a jittered m x k grid with
 *                     stratified 1D projections, for any spp; a prefix of
 *                     them (a --time-limit stop) is unbiased but not
 *                     stratified. Indices >= spp start fresh patterns.
 *   RT_SAMPLER_SOBOL  the first two dimensions of Sobol's sequence, Owen
 *                     scrambled per (pixel, dim), the index shuffled by a
 *                     nested scramble per (pixel, dim) (Burley 2020). Each
 *                     aligned block of 2^k samples is a (0,k,2)-net: every
 *                     elementary interval of area 2^-k holds one point, so
 *                     a power-of-two prefix is stratified like the whole.
 *
 * rt_sampler_1d / rt_sampler_2d are the stratified values themselves (no
 * rng), for tests and callers with their own keys. All inline: a path takes
 * three or four values a bounce, and a call costs a tenth of the work.
 * The path tracer (and the camera, for Sobol) read them through
 * rt/render/sampler_block.h when the CPU has AVX2: eight dimensions of a
 * sample at once in vector lanes, the same bits as these functions.
 *
 * Padding: pbrt-v4 (Pharr, Jakob, Humphreys, 4th ed.), section 8.5; Kollig
 * and Keller 2002, "Efficient Multidimensional Sampling". CMJ: Kensler
 * 2013, Pixar Technical Memo 13-01, through rt_cmj_sample / rt_cmj_permute
 * (sampling.h): sample s of dimension d is rt_cmj_sample(perm_d(s), spp,
 * p_d); 1D: (perm_d(s) + jitter) / spp. Sobol: Sobol' 1967; its first two
 * dimensions as a (0,2)-sequence in base 2: x = the radical inverse of the
 * index, y = the index bits times the generator matrix whose column k (from
 * 1) is m_k / 2^k, m_1 = 1, m_{k+1} = m_k xor 2 m_k (the polynomial x + 1:
 * Pascal's triangle mod 2, so by Lucas's theorem bit r of the reversed y is
 * the xor of the index bits c with c a superset of r, a 5-step transform).
 * Randomised as Burley 2020, "Practical Hash-based Owen Scrambling" (JCGT
 * 9(4)): Owen scrambling (a bit flipped by a random function of the bits
 * above it) is a Laine-Karras style hash of the bit-reversed value (any mix
 * of x += c, x *= odd, x ^= x * even: bit k depends on bits <= k only);
 * the hash's operations are those of Vegdahl 2021 ("Building a Better LK
 * Hash", psychopath.io), which fix the bias of the paper's first one.
 */
#ifndef RT_SAMPLER_H
#define RT_SAMPLER_H

#include <stdint.h>

#include "rt/render/sampling.h"

/* Where a path's random numbers come from (rt/render/sampler.h); the
 * values are the words of the `sampler` setting, in order. */
typedef enum rt_sampler_kind {
    RT_SAMPLER_INDEPENDENT = 0, /* a PCG stream per sample (pixel and lens stratified only) */
    RT_SAMPLER_CMJ,             /* padded correlated multi-jittering over the spp */
    RT_SAMPLER_SOBOL,           /* padded Owen-scrambled Sobol */
} rt_sampler_kind;

/* The camera's dimensions (rt_camera_pixel_sample), apart from the path's
 * (bounce x (5 + lights) + slot): the film position and the lens point. */
#define RT_SAMPLER_DIM_FILM 0xfffffff0u
#define RT_SAMPLER_DIM_LENS 0xfffffff1u

static inline uint32_t rt_sampler_hash(uint32_t a, uint32_t b)
{
    uint32_t h = a ^ (b * 0x9e3779b9u + 0x7f4a7c15u);
    h ^= h >> 16; h *= 0x85ebca6bu; h ^= h >> 13; h *= 0xc2b2ae35u; h ^= h >> 16;
    return h;
}

static inline uint32_t rt_sampler_reverse(uint32_t x)
{
    x = __builtin_bswap32(x);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    return ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
}

/* A random bijection of 32-bit words in which bit k of the result is bit k
 * of x flipped by a function of the seed and the bits below k. */
static inline uint32_t rt_sampler_lk(uint32_t x, uint32_t seed)
{
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

static inline float rt_sampler_unit(uint32_t x)
{
    return (float)(x >> 8) * (1.0f / 16777216.0f);
}

/* Owen scrambling of the value whose bit reversal is xr. */
static inline float rt_sampler_owen(uint32_t xr, uint32_t seed)
{
    return rt_sampler_unit(rt_sampler_reverse(rt_sampler_lk(xr, seed)));
}

/* Owen scrambling of two values given bit-reversed, with one 64-bit reversal. */
static inline rt_vec2 rt_sampler_owen2(uint32_t xr, uint32_t xseed, uint32_t yr, uint32_t yseed)
{
    uint64_t v = ((uint64_t)rt_sampler_lk(yr, yseed) << 32) | rt_sampler_lk(xr, xseed);
    v = __builtin_bswap64(v);
    v = ((v >> 4) & 0x0f0f0f0f0f0f0f0full) | ((v & 0x0f0f0f0f0f0f0f0full) << 4);
    v = ((v >> 2) & 0x3333333333333333ull) | ((v & 0x3333333333333333ull) << 2);
    v = ((v >> 1) & 0x5555555555555555ull) | ((v & 0x5555555555555555ull) << 1);
    return rt_v2(rt_sampler_unit((uint32_t)(v >> 32)), rt_sampler_unit((uint32_t)v));
}

/* The index shuffled by a nested scramble of its bits that index spp
 * samples (bit k flipped by a function of the bits above it), so that
 * aligned blocks of 2^k indices map onto aligned blocks. */
static inline uint32_t rt_sobol_shuffle(uint32_t index, uint32_t spp, uint32_t seed)
{
    uint32_t mask = spp > 1 ? 0xffffffffu >> __builtin_clz(spp - 1) : 1u;
    uint32_t s = rt_sampler_reverse(rt_sampler_lk(rt_sampler_reverse(index), seed));
    return (index & ~mask) | (s & mask);
}

/* CMJ: the pattern of dimension dim and of the round of spp samples the
 * index falls in (indices past spp start fresh patterns). */
static inline uint32_t rt_cmj_padded_pattern(uint32_t key, uint32_t *index, uint32_t spp, uint32_t dim)
{
    uint32_t p = rt_sampler_hash(key, dim);
    if (*index >= spp) {
        p = rt_sampler_hash(p, *index / spp);
        *index %= spp;
    }
    return p;
}

/* Value `dim` of sample `index` (of spp a pixel) for pixel key `key`; in [0,1). */
static inline float rt_sampler_1d(rt_sampler_kind kind, uint32_t key, uint32_t index, uint32_t spp, uint32_t dim)
{
    if (spp == 0)
        spp = 1;
    if (kind == RT_SAMPLER_CMJ) {
        uint32_t p = rt_cmj_padded_pattern(key, &index, spp, dim);
        uint32_t s = rt_cmj_permute(index, spp, p * 0x8ee9b46bu);
        float x = ((float)s + rt_cmj_randfloat(index, p * 0x2a6f7e53u)) / (float)spp;
        return rt_fminf(x, 0x1.fffffep-1f);
    }
    uint32_t seed = rt_sampler_hash(key, dim); /* the shuffle's; the scramble's is hashed apart from it */
    return rt_sampler_owen(rt_sobol_shuffle(index, spp, seed), rt_sampler_hash(seed, 0x68e31da4u));
}

static inline rt_vec2 rt_sampler_2d(rt_sampler_kind kind, uint32_t key, uint32_t index, uint32_t spp, uint32_t dim)
{
    if (spp == 0)
        spp = 1;
    if (kind == RT_SAMPLER_CMJ) {
        uint32_t p = rt_cmj_padded_pattern(key, &index, spp, dim);
        return rt_cmj_sample(rt_cmj_permute(index, spp, p * 0x8ee9b46bu), spp, p);
    }
    uint32_t seed = rt_sampler_hash(key, dim);
    uint32_t j = rt_sobol_shuffle(index, spp, seed); /* x reversed: the radical inverse of j is reverse(j) */
    uint32_t y = j;                                  /* y reversed: bit r = xor of j's bits c, c superset of r */
    y ^= (y >> 1) & 0x55555555u;
    y ^= (y >> 2) & 0x33333333u;
    y ^= (y >> 4) & 0x0f0f0f0fu;
    y ^= (y >> 8) & 0x00ff00ffu;
    y ^= (y >> 16) & 0x0000ffffu;
    /* three independent seeds: the LK hash's low output bits (the top bits
     * of a value) depend on the seed's low bits only, so seeds that differ
     * by a multiply-add would scramble x and y alike */
    return rt_sampler_owen2(j, rt_sampler_hash(seed, 0x68e31da4u), y, rt_sampler_hash(seed, 0xb5297a4du));
}

/* The path's value in dimension dim: the sampler's, or the next PCG draws. */
static inline float rt_sample_1d(rt_sampler_kind kind, uint32_t spp, rt_rng *rng, uint32_t dim)
{
    if (kind == RT_SAMPLER_INDEPENDENT)
        return rt_rng_float(rng);
    return rt_sampler_1d(kind, rng->key, rng->index, spp, dim);
}

static inline rt_vec2 rt_sample_2d(rt_sampler_kind kind, uint32_t spp, rt_rng *rng, uint32_t dim)
{
    if (kind == RT_SAMPLER_INDEPENDENT) {
        float y = rt_rng_float(rng); /* gcc's order for rt_v2(rt_rng_float(), rt_rng_float()) */
        float x = rt_rng_float(rng);
        return rt_v2(x, y);
    }
    return rt_sampler_2d(kind, rng->key, rng->index, spp, dim);
}

#endif
