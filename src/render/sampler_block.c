/* sampler_block.c - eight dimensions of a stratified sampler at once, in
 * the 32-bit lanes of AVX2 registers (rt/render/sampler_block.h).
 *
 * Lane k computes rt_sampler_2d(kind, key, index, spp, dim0 + k) with
 * sampler.h's operations in sampler.h's order.
 *
 * Sobol: all exact integer arithmetic mod 2^32 (so the lanes give the
 * scalar bits): the seed hash (a multiply-add and the murmur3 finaliser's
 * xor-shifts and multiplies, vpmulld), the nested-scramble shuffle of the
 * index and the two Owen scrambles (Burley 2020, "Practical Hash-based
 * Owen Scrambling", JCGT 9(4); the Laine-Karras style hash's operations of
 * Vegdahl 2021), the second Sobol dimension's generator matrix (Pascal's
 * triangle mod 2 as five masked xor-shifts), and the bit reversals: a byte
 * swap and two 16-entry nibble-reversal lookups per byte with vpshufb
 * (the table trick of e.g. Warren, "Hacker's Delight", 2nd ed., 7-1, done
 * in registers). The conversion to [0,1) is (x >> 8) x 2^-24 as in
 * rt_sampler_unit: x >> 8 < 2^24 converts exactly as a signed lane.
 *
 * CMJ (Kensler 2013, "Correlated Multi-Jittered Sampling", Pixar Technical
 * Memo 13-01, through sampling.h's rt_cmj_permute / rt_cmj_randfloat /
 * rt_cmj_sample): the hashes and the permutation's rounds as integer lanes,
 * its cycle-walking loop run until no lane is out of range (a lane that is
 * in range keeps its value, vpblendvb); the remainders and quotients by the
 * grid's sides (the same in every lane) in doubles: for x, l < 2^32,
 * floor(x / l) of the correctly rounded quotient is exact, as x / l is
 * either an integer or at least 1/l below the next one, a relative gap of
 * 2^-33 or more against a double's 2^-53. The point's float arithmetic is
 * the scalar's adds and divides in its order (IEEE, so the same bits;
 * the integers converted are < 2^31 and convert as the scalar's do).
 *
 * The AVX2 functions are compiled for AVX2 between target pragmas whatever
 * the build's -march (as the kd-tree's kernels, src/accel/kdtree_internal.h)
 * and chosen at run time by __builtin_cpu_supports; elsewhere the block
 * is eight calls of rt_sampler_2d.
 */
#include "rt/render/sampler_block.h"

void rt_sampler_block_scalar(rt_sampler_kind kind, uint32_t key, uint32_t index, uint32_t spp, uint32_t dim0,
                             float x[RT_SAMPLER_BLOCK], float y[RT_SAMPLER_BLOCK])
{
    for (uint32_t k = 0; k < RT_SAMPLER_BLOCK; k++) {
        rt_vec2 v = rt_sampler_2d(kind, key, index, spp, dim0 + k);
        x[k] = v.x;
        y[k] = v.y;
    }
}

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define BLOCK_HAVE_AVX2 1
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
#include <immintrin.h>

/* The constants, eight lanes each, read from memory by the instructions
 * that use them: the function gets them through a pointer it cannot see
 * through (noipa), since GCC otherwise builds each one in a register from
 * an immediate (three instructions a constant, a fifth of the block). */
#define K8(v) {v, v, v, v, v, v, v, v}
#define KB(...) {__VA_ARGS__, __VA_ARGS__} /* a 16-byte shuffle table in both halves */
typedef struct block_consts {
    uint32_t dim_hash[8];                       /* k * 0x9e3779b9 + 0x7f4a7c15: rt_sampler_hash(key, dim0 + k) */
    uint32_t mix1[8], mix2[8];                  /* the finaliser's multipliers */
    uint32_t xhash[8], yhash[8];                /* rt_sampler_hash(seed, c): c * 0x9e3779b9 + 0x7f4a7c15 */
    uint32_t lk1[8], one[8], lk2[8], lk3[8];    /* rt_sampler_lk's */
    uint8_t bswap[32], rev_lo[32], rev_hi[32];  /* byte swap; 4-bit reversal of a nibble, into the low or high nibble */
    uint32_t m1[8], m2[8], m4[8], m8[8], m16[8]; /* the generator matrix's masks; m4 also the low nibble of each byte */
    float unit[8];                              /* 2^-24 */
    /* CMJ: the permutation's multipliers, the hash-to-float's, the pattern multipliers */
    uint32_t perm[6][8], rf1[8], rf2[8], rf3[8], pat_perm[8], pat_x[8], pat_y[8], pat_jx[8], pat_jy[8];
    float top[8];                               /* 0x1.fffffep-1, the largest float below 1 */
} block_consts;

#define H(c) ((c) * 0x9e3779b9u + 0x7f4a7c15u)
static const block_consts block_k = {
    {H(0u), H(1u), H(2u), H(3u), H(4u), H(5u), H(6u), H(7u)},
    K8(0x85ebca6bu), K8(0xc2b2ae35u),
    K8(H(0x68e31da4u)), K8(H(0xb5297a4du)),
    K8(0x3d20adeau), K8(1u), K8(0x05526c56u), K8(0x53a22864u),
    KB(3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12),
    KB(0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15),
    KB(0x00, 0x80, 0x40, 0xc0, 0x20, 0xa0, 0x60, 0xe0, 0x10, 0x90, 0x50, 0xd0, 0x30, 0xb0, 0x70, 0xf0),
    K8(0x55555555u), K8(0x33333333u), K8(0x0f0f0f0fu), K8(0x00ff00ffu), K8(0x0000ffffu),
    K8(1.0f / 16777216.0f),
    {K8(0xe170893du), K8(0x0929eb3fu), K8(0x6935fa69u), K8(0x74dcb303u), K8(0x9e501cc3u), K8(0xc860a3dfu)},
    K8(0xb36534e5u), K8(0x93fc4795u), K8(0xdf6e307fu),
    K8(0x8ee9b46bu), K8(0xa511e9b3u), K8(0x63d83595u), K8(0xa399d265u), K8(0x711ad6a5u),
    K8(0x1.fffffep-1f),
};
#undef H

#define LD(f) _mm256_loadu_si256((const __m256i *)k->f)

static inline __m256i mix32(const block_consts *k, __m256i h) /* rt_sampler_hash's finaliser */
{
    h = _mm256_xor_si256(h, _mm256_srli_epi32(h, 16));
    h = _mm256_mullo_epi32(h, LD(mix1));
    h = _mm256_xor_si256(h, _mm256_srli_epi32(h, 13));
    h = _mm256_mullo_epi32(h, LD(mix2));
    return _mm256_xor_si256(h, _mm256_srli_epi32(h, 16));
}

static inline __m256i lk(const block_consts *k, __m256i x, __m256i seed) /* rt_sampler_lk */
{
    x = _mm256_xor_si256(x, _mm256_mullo_epi32(x, LD(lk1)));
    x = _mm256_add_epi32(x, seed);
    x = _mm256_mullo_epi32(x, _mm256_or_si256(_mm256_srli_epi32(seed, 16), LD(one)));
    x = _mm256_xor_si256(x, _mm256_mullo_epi32(x, LD(lk2)));
    return _mm256_xor_si256(x, _mm256_mullo_epi32(x, LD(lk3)));
}

static inline __m256i reverse(const block_consts *k, __m256i x) /* rt_sampler_reverse */
{
    x = _mm256_shuffle_epi8(x, LD(bswap));
    __m256i lo = _mm256_and_si256(x, LD(m4)), hi = _mm256_and_si256(_mm256_srli_epi16(x, 4), LD(m4));
    return _mm256_or_si256(_mm256_shuffle_epi8(LD(rev_hi), lo), _mm256_shuffle_epi8(LD(rev_lo), hi));
}

static inline __m256 unit(const block_consts *k, __m256i x) /* rt_sampler_unit */
{
    return _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srli_epi32(x, 8)), _mm256_loadu_ps(k->unit));
}

/* y ^= (y >> s) & mask */
#define XOR_SHIFT_MASKED(y, s, mask) _mm256_xor_si256(y, _mm256_and_si256(_mm256_srli_epi32(y, s), LD(mask)))

#if defined(__clang__)
#define BLOCK_OPAQUE __attribute__((noinline))
#else
#define BLOCK_OPAQUE __attribute__((noipa))
#endif

BLOCK_OPAQUE static void sobol_block_avx2(const block_consts *k, uint32_t key, uint32_t index, uint32_t spp,
                                          uint32_t dim0, float x[RT_SAMPLER_BLOCK], float y[RT_SAMPLER_BLOCK])
{
    if (spp == 0)
        spp = 1;
    uint32_t mask = spp > 1 ? 0xffffffffu >> __builtin_clz(spp - 1) : 1u;
    /* seed = rt_sampler_hash(key, dim0 + lane) */
    __m256i seed = _mm256_add_epi32(_mm256_set1_epi32((int)(dim0 * 0x9e3779b9u)), LD(dim_hash));
    seed = mix32(k, _mm256_xor_si256(_mm256_set1_epi32((int)key), seed));
    __m256i xseed = mix32(k, _mm256_xor_si256(seed, LD(xhash)));
    __m256i yseed = mix32(k, _mm256_xor_si256(seed, LD(yhash)));
    /* j = rt_sobol_shuffle(index, spp, seed): x reversed */
    __m256i s = reverse(k, lk(k, reverse(k, _mm256_set1_epi32((int)index)), seed));
    __m256i j = _mm256_or_si256(_mm256_set1_epi32((int)(index & ~mask)), _mm256_and_si256(s, _mm256_set1_epi32((int)mask)));
    /* y reversed: the generator matrix */
    __m256i yr = XOR_SHIFT_MASKED(j, 1, m1);
    yr = XOR_SHIFT_MASKED(yr, 2, m2);
    yr = XOR_SHIFT_MASKED(yr, 4, m4);
    yr = XOR_SHIFT_MASKED(yr, 8, m8);
    yr = XOR_SHIFT_MASKED(yr, 16, m16);
    _mm256_storeu_ps(x, unit(k, reverse(k, lk(k, j, xseed))));
    _mm256_storeu_ps(y, unit(k, reverse(k, lk(k, yr, yseed))));
}


/* ---- CMJ */

#define S1(c) _mm256_set1_epi32((int)(c))

static inline __m256i xor_and_shift(__m256i i, __m256i w, int s) /* i ^= (i & w) >> s */
{
    return _mm256_xor_si256(i, _mm256_srli_epi32(_mm256_and_si256(i, w), s));
}

/* floor(x / l) of four lanes in doubles, 2 <= l */
static inline __m128i quot4(__m128i x, __m256d l)
{
    __m256d d = _mm256_add_pd(_mm256_cvtepi32_pd(_mm_xor_si128(x, _mm_set1_epi32(INT32_MIN))),
                              _mm256_set1_pd(2147483648.0)); /* x as unsigned */
    return _mm256_cvttpd_epi32(_mm256_floor_pd(_mm256_div_pd(d, l)));
}

static inline __m256i quot(__m256i x, uint32_t l) /* x / l */
{
    if ((l & (l - 1)) == 0) /* a power of two (1 included): a shift */
        return _mm256_srli_epi32(x, __builtin_ctz(l));
    __m256d ld = _mm256_set1_pd((double)l);
    __m128i lo = quot4(_mm256_castsi256_si128(x), ld), hi = quot4(_mm256_extracti128_si256(x, 1), ld);
    return _mm256_inserti128_si256(_mm256_castsi128_si256(lo), hi, 1);
}

static inline __m256i rem(__m256i x, uint32_t l, __m256i q) /* x % l, given q = x / l */
{
    if ((l & (l - 1)) == 0)
        return _mm256_and_si256(x, S1(l - 1));
    return _mm256_sub_epi32(x, _mm256_mullo_epi32(q, S1(l)));
}

static inline __m256i cmj_permute(const block_consts *k, __m256i i, uint32_t l, __m256i p) /* rt_cmj_permute */
{
    uint32_t ws = l - 1;
    ws |= ws >> 1; ws |= ws >> 2; ws |= ws >> 4; ws |= ws >> 8; ws |= ws >> 16;
    __m256i w = S1(ws), lv = S1(l);
    __m256i p16 = _mm256_srli_epi32(p, 16), p8 = _mm256_srli_epi32(p, 8), p23 = _mm256_srli_epi32(p, 23);
    __m256i p27 = _mm256_or_si256(_mm256_srli_epi32(p, 27), LD(one));
    __m256i active = _mm256_set1_epi32(-1);
    do { /* every lane the first time, then the lanes still >= l */
        __m256i v = _mm256_xor_si256(i, p);
        v = _mm256_mullo_epi32(v, LD(perm[0]));
        v = _mm256_xor_si256(v, p16);
        v = xor_and_shift(v, w, 4);
        v = _mm256_xor_si256(v, p8);
        v = _mm256_mullo_epi32(v, LD(perm[1]));
        v = _mm256_xor_si256(v, p23);
        v = xor_and_shift(v, w, 1);
        v = _mm256_mullo_epi32(v, p27);
        v = _mm256_mullo_epi32(v, LD(perm[2]));
        v = xor_and_shift(v, w, 11);
        v = _mm256_mullo_epi32(v, LD(perm[3]));
        v = xor_and_shift(v, w, 2);
        v = _mm256_mullo_epi32(v, LD(perm[4]));
        v = xor_and_shift(v, w, 2);
        v = _mm256_mullo_epi32(v, LD(perm[5]));
        v = _mm256_and_si256(v, w);
        v = _mm256_xor_si256(v, _mm256_srli_epi32(v, 5));
        i = _mm256_blendv_epi8(i, v, active);
        active = _mm256_cmpeq_epi32(_mm256_max_epu32(i, lv), i); /* i >= l, unsigned */
    } while (!_mm256_testz_si256(active, active));
    __m256i x = _mm256_add_epi32(i, p);
    return rem(x, l, quot(x, l));
}

static inline __m256 cmj_randfloat(const block_consts *k, __m256i i, __m256i p) /* rt_cmj_randfloat */
{
    i = _mm256_xor_si256(i, p);
    i = _mm256_xor_si256(i, _mm256_srli_epi32(i, 17));
    i = _mm256_xor_si256(i, _mm256_srli_epi32(i, 10));
    i = _mm256_mullo_epi32(i, LD(rf1));
    i = _mm256_xor_si256(i, _mm256_srli_epi32(i, 12));
    i = _mm256_xor_si256(i, _mm256_srli_epi32(i, 21));
    i = _mm256_mullo_epi32(i, LD(rf2));
    i = _mm256_xor_si256(i, LD(rf3));
    i = _mm256_xor_si256(i, _mm256_srli_epi32(i, 17));
    i = _mm256_mullo_epi32(i, _mm256_or_si256(_mm256_srli_epi32(p, 18), LD(one)));
    return _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srli_epi32(i, 8)), _mm256_loadu_ps(k->unit));
}

BLOCK_OPAQUE static void cmj_block_avx2(const block_consts *k, uint32_t key, uint32_t index, uint32_t spp,
                                        uint32_t dim0, float x[RT_SAMPLER_BLOCK], float y[RT_SAMPLER_BLOCK])
{
    if (spp == 0)
        spp = 1;
    /* rt_cmj_padded_pattern: p = rt_sampler_hash(key, dim), then of the round */
    __m256i p = _mm256_add_epi32(_mm256_set1_epi32((int)(dim0 * 0x9e3779b9u)), LD(dim_hash));
    p = mix32(k, _mm256_xor_si256(_mm256_set1_epi32((int)key), p));
    if (index >= spp) {
        p = mix32(k, _mm256_xor_si256(p, S1((index / spp) * 0x9e3779b9u + 0x7f4a7c15u)));
        index %= spp;
    }
    __m256i s = cmj_permute(k, S1(index), spp, _mm256_mullo_epi32(p, LD(pat_perm)));
    /* rt_cmj_sample(s, spp, p) */
    uint32_t m, rows;
    rt_cmj_grid(spp, &m, &rows);
    __m256i sdm = quot(s, m), smm = rem(s, m, sdm);
    __m256i sx = cmj_permute(k, smm, m, _mm256_mullo_epi32(p, LD(pat_x)));
    __m256i sy = cmj_permute(k, sdm, rows, _mm256_mullo_epi32(p, LD(pat_y)));
    __m256 jx = cmj_randfloat(k, s, _mm256_mullo_epi32(p, LD(pat_jx)));
    __m256 jy = cmj_randfloat(k, s, _mm256_mullo_epi32(p, LD(pat_jy)));
    __m256 fm = _mm256_set1_ps((float)m), fk = _mm256_set1_ps((float)rows);
    __m256 vx = _mm256_add_ps(_mm256_cvtepi32_ps(smm), _mm256_div_ps(_mm256_add_ps(_mm256_cvtepi32_ps(sy), jx), fk));
    __m256 vy = _mm256_add_ps(_mm256_cvtepi32_ps(sdm), _mm256_div_ps(_mm256_add_ps(_mm256_cvtepi32_ps(sx), jy), fm));
    const __m256 top = _mm256_loadu_ps(k->top); /* rt_fminf: no NaN here */
    _mm256_storeu_ps(x, _mm256_min_ps(_mm256_div_ps(vx, fm), top));
    _mm256_storeu_ps(y, _mm256_min_ps(_mm256_div_ps(vy, fk), top));
}

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

bool rt_sampler_block_simd(void)
{
#if defined(__AVX2__)
    return true;
#elif defined(BLOCK_HAVE_AVX2)
    return __builtin_cpu_supports("avx2");
#else
    return false;
#endif
}

void rt_sampler_block(rt_sampler_kind kind, uint32_t key, uint32_t index, uint32_t spp, uint32_t dim0,
                      float x[RT_SAMPLER_BLOCK], float y[RT_SAMPLER_BLOCK])
{
#ifdef BLOCK_HAVE_AVX2
    if (rt_sampler_block_simd()) {
        if (kind == RT_SAMPLER_SOBOL) {
            sobol_block_avx2(&block_k, key, index, spp, dim0, x, y);
            return;
        }
        if (kind == RT_SAMPLER_CMJ) {
            cmj_block_avx2(&block_k, key, index, spp, dim0, x, y);
            return;
        }
    }
#endif
    rt_sampler_block_scalar(kind, key, index, spp, dim0, x, y);
}
