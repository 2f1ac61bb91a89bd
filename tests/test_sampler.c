/* test_sampler.c - the stratified samplers of rt/render/sampler.h:
 *   - Sobol: every aligned block of 2^k samples of a 2D dimension is a
 *     (0,k,2)-net (each of the 2^k elementary intervals of every shape
 *     2^-a x 2^-b, a + b = k, holds exactly one point), for any pixel key
 *     and dimension, also past the render's spp; a 1D dimension puts one
 *     point in each of the 2^k intervals of such a block;
 *   - CMJ: for a square spp = m^2 the spp points of a 2D dimension put one
 *     point in each of the m x m cells and in each of the spp columns and
 *     rows; a 1D dimension one point in each of the spp intervals; any spp
 *     stratifies the 1D dimension;
 *   - every value is in [0, 1) and a pure function of its arguments, and
 *     two dimensions of one pixel are not the same pattern (padding);
 *   - Sobol: rt_sampler_block (AVX2 lanes when the CPU has them), its
 *     scalar path, the path's cache of it and rt_sampler_2d / rt_sampler_1d
 *     give the bits of a reference written here from the definitions (bit
 *     loops: the reversal, Sobol's generator matrix from its direction
 *     numbers, Owen scrambling as the LK hash of the reversed value) over
 *     many keys, indices, spp and dimensions; CMJ: the block and its cache
 *     give rt_sampler_2d's bits (sampling.h's Kensler functions) over as
 *     many, spp of every kind of grid and indices past the spp included;
 *   - the path tracer: `path` equals `path_scalar` byte for byte with each
 *     sampler (tests/test_wavefront.c covers the splits), and on the shared
 *     Cornell box at 16 spp each stratified sampler's image is closer to the
 *     Mitsuba reference than the independent one's.
 */
#include "test_util.h"

#include <math.h>

#include "rt/accel/kdtree.h"
#include "rt/image/framebuffer.h"
#include "rt/io/scene_parse.h"
#include "rt/render/render.h"
#include "rt/render/sampler.h"
#include "rt/render/sampler_block.h"
#include "rt/scene/scene.h"

static const uint32_t keys[] = {0u, 1u, 0x9e3779b9u, 0xdeadbeefu, 12345u};
static const uint32_t dims[] = {0u, 1u, 2u, 7u, 1000u};

static void test_values_in_unit_interval(void **state)
{
    (void)state;
    const rt_sampler_kind kinds[] = {RT_SAMPLER_CMJ, RT_SAMPLER_SOBOL};
    const uint32_t spps[] = {1u, 3u, 16u, 17u, 100u, 1024u};
    for (size_t k = 0; k < 2; k++)
        for (size_t sp = 0; sp < sizeof spps / sizeof *spps; sp++)
            for (uint32_t key = 0; key < 20; key++)
                for (uint32_t i = 0; i < 3 * spps[sp] + 5; i++) {
                    uint32_t d = key * 3u + i % 5u;
                    rt_vec2 p = rt_sampler_2d(kinds[k], key * 0x01000193u, i, spps[sp], d);
                    float q = rt_sampler_1d(kinds[k], key * 0x01000193u, i, spps[sp], d);
                    assert_true(p.x >= 0.0f && p.x < 1.0f && p.y >= 0.0f && p.y < 1.0f);
                    assert_true(q >= 0.0f && q < 1.0f);
                    rt_vec2 again = rt_sampler_2d(kinds[k], key * 0x01000193u, i, spps[sp], d);
                    assert_true(again.x == p.x && again.y == p.y);
                }
}

/* Points [first, first + n) of a Sobol 2D dimension: a (0, log2 n, 2)-net. */
static void check_net(uint32_t key, uint32_t dim, uint32_t spp, uint32_t first, uint32_t n)
{
    uint32_t k = 0;
    while ((1u << k) < n)
        k++;
    static uint8_t seen[1 << 12];
    for (uint32_t a = 0; a <= k; a++) { /* 2^a columns, 2^(k-a) rows */
        memset(seen, 0, n);
        for (uint32_t i = first; i < first + n; i++) {
            rt_vec2 p = rt_sampler_2d(RT_SAMPLER_SOBOL, key, i, spp, dim);
            uint32_t cx = (uint32_t)(p.x * (float)(1u << a)), cy = (uint32_t)(p.y * (float)(1u << (k - a)));
            uint32_t cell = cy * (1u << a) + cx;
            if (seen[cell]++)
                fail_msg("Sobol key %u dim %u spp %u: points %u..%u, intervals 2^-%u x 2^-%u: two in cell %u", key,
                         dim, spp, first, first + n - 1, a, k - a, cell);
        }
    }
    memset(seen, 0, n);
    for (uint32_t i = first; i < first + n; i++) {
        uint32_t c = (uint32_t)(rt_sampler_1d(RT_SAMPLER_SOBOL, key, i, spp, dim) * (float)n);
        if (seen[c]++)
            fail_msg("Sobol 1D key %u dim %u spp %u: points %u..%u: two in interval %u of %u", key, dim, spp, first,
                     first + n - 1, c, n);
    }
}

static void test_sobol_nets(void **state)
{
    (void)state;
    for (size_t a = 0; a < sizeof keys / sizeof *keys; a++)
        for (size_t b = 0; b < sizeof dims / sizeof *dims; b++) {
            for (uint32_t k = 0; k <= 10; k++) {
                uint32_t n = 1u << k;
                check_net(keys[a], dims[b], 1024, 0, n);           /* every power-of-two prefix */
                check_net(keys[a], dims[b], 1024, 1024 - n, n);    /* the last aligned block */
                check_net(keys[a], dims[b], 1024, 2048 + 3 * n, n); /* past the spp */
            }
            check_net(keys[a], dims[b], 100, 0, 64); /* spp not a power of two: its prefixes */
            check_net(keys[a], dims[b], 100, 64, 32);
            check_net(keys[a], dims[b], 16, 0, 16);
        }
}

/* ---- a reference for the Sobol sampler, from its definitions */

static uint32_t ref_hash(uint32_t a, uint32_t b) /* sampler.h's seed hash: murmur3's finaliser */
{
    uint32_t h = a ^ (b * 0x9e3779b9u + 0x7f4a7c15u);
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

static uint32_t ref_reverse(uint32_t x)
{
    uint32_t r = 0;
    for (int b = 0; b < 32; b++)
        if (x & (1u << b))
            r |= 1u << (31 - b);
    return r;
}

static uint32_t ref_lk(uint32_t x, uint32_t seed) /* Vegdahl 2021's hash */
{
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

/* Owen scrambling of a 0.32 fixed-point value: the hash of its reversal. */
static uint32_t ref_owen(uint32_t v, uint32_t seed) { return ref_reverse(ref_lk(ref_reverse(v), seed)); }

static float ref_unit(uint32_t v) { return (float)(v >> 8) / 16777216.0f; }

/* Sobol's second dimension at index j: the xor of the direction numbers
 * V_i = m_(i+1) / 2^(i+1) of j's set bits, m_1 = 1, m_(k+1) = m_k xor 2 m_k. */
static uint32_t ref_sobol_y(uint32_t j)
{
    uint32_t y = 0, m = 1;
    for (int i = 0; i < 32; i++) {
        if (j & (1u << i))
            y ^= m << (31 - i); /* m_(i+1) < 2^(i+1): its bits as the fraction's top i+1 */
        m ^= m << 1;
    }
    return y;
}

static rt_vec2 ref_sobol_2d(uint32_t key, uint32_t index, uint32_t spp, uint32_t dim)
{
    uint32_t seed = ref_hash(key, dim);
    uint32_t mask = 1; /* the index bits that index spp samples: 2^k >= spp, at least one bit */
    while (mask < spp - 1 && spp > 1 && mask != 0xffffffffu)
        mask = mask << 1 | 1u;
    /* the nested scramble of those bits: bit k flipped by a function of the
     * bits above it, an Owen scramble of the index read as a fraction */
    uint32_t j = (index & ~mask) | (ref_owen(index, seed) & mask);
    uint32_t x = ref_reverse(j), y = ref_sobol_y(j);
    return rt_v2(ref_unit(ref_owen(x, ref_hash(seed, 0x68e31da4u))), ref_unit(ref_owen(y, ref_hash(seed, 0xb5297a4du))));
}

static uint32_t lcg(uint32_t *s) { return *s = *s * 1664525u + 1013904223u; }

static void test_sobol_block_matches_reference(void **state)
{
    (void)state;
    const uint32_t spps[] = {0u, 1u, 2u, 3u, 4u, 16u, 17u, 100u, 1024u, 65537u, 0x80000000u, 0xffffffffu};
    const uint32_t dim0s[] = {0u, 6u, 8u, 1000u, RT_SAMPLER_DIM_FILM, 0xfffffffcu /* wraps past 2^32 */};
    if (!rt_sampler_block_simd())
        print_message("(this CPU has no AVX2: rt_sampler_block checked on its scalar path only)\n");
    uint32_t rs = 12345u;
    size_t checked = 0;
    for (size_t sp = 0; sp < sizeof spps / sizeof *spps; sp++)
        for (uint32_t t = 0; t < 400; t++) {
            uint32_t key = t < 5 ? keys[t] : lcg(&rs);
            uint32_t index = t < 64 ? t : (t & 1 ? lcg(&rs) % 4096u : lcg(&rs));
            uint32_t dim0 = t < 60 ? dim0s[t % 6] : lcg(&rs) % 200u * 7u;
            float bx[RT_SAMPLER_BLOCK], by[RT_SAMPLER_BLOCK], sx[RT_SAMPLER_BLOCK], sy[RT_SAMPLER_BLOCK];
            rt_sampler_block(RT_SAMPLER_SOBOL, key, index, spps[sp], dim0, bx, by);
            rt_sampler_block_scalar(RT_SAMPLER_SOBOL, key, index, spps[sp], dim0, sx, sy);
            rt_sampler_cache c;
            rt_sampler_cache_clear(&c);
            for (uint32_t k = 0; k < RT_SAMPLER_BLOCK; k++) {
                uint32_t dim = dim0 + k;
                rt_vec2 r = ref_sobol_2d(key, index, spps[sp], dim);
                rt_vec2 v = rt_sampler_2d(RT_SAMPLER_SOBOL, key, index, spps[sp], dim);
                float v1 = rt_sampler_1d(RT_SAMPLER_SOBOL, key, index, spps[sp], dim);
                rt_vec2 cv = rt_sampler_cache_2d(&c, RT_SAMPLER_SOBOL, key, index, spps[sp], dim0, (k * 5u) % RT_SAMPLER_BLOCK);
                rt_vec2 cr = ref_sobol_2d(key, index, spps[sp], dim0 + (k * 5u) % RT_SAMPLER_BLOCK);
                if (!(r.x == v.x && r.y == v.y && r.x == v1 && r.x == bx[k] && r.y == by[k] && r.x == sx[k] &&
                      r.y == sy[k] && cv.x == cr.x && cv.y == cr.y))
                    fail_msg("key %#x index %u spp %u dim %#x: reference (%a, %a), rt_sampler_2d (%a, %a), 1d %a, "
                             "block (%a, %a), scalar block (%a, %a), cache (%a, %a) for (%a, %a)",
                             key, index, spps[sp], dim, (double)r.x, (double)r.y, (double)v.x, (double)v.y,
                             (double)v1, (double)bx[k], (double)by[k], (double)sx[k], (double)sy[k], (double)cv.x,
                             (double)cv.y, (double)cr.x, (double)cr.y);
                checked++;
            }
            /* the cache refills for another block of the same sample */
            rt_vec2 other = rt_sampler_cache_2d(&c, RT_SAMPLER_SOBOL, key, index, spps[sp], dim0 + 3u, 2);
            rt_vec2 want = ref_sobol_2d(key, index, spps[sp], dim0 + 5u);
            assert_true(other.x == want.x && other.y == want.y);
        }
    assert_true(checked == sizeof spps / sizeof *spps * 400u * RT_SAMPLER_BLOCK);
}

static void test_cmj_block_matches_scalar(void **state)
{
    (void)state;
    /* squares, m x k grids with a short last row, primes, powers of two, large */
    const uint32_t spps[] = {0u, 1u, 2u, 3u, 5u, 7u, 16u, 17u, 64u, 100u, 1000u, 1024u, 65537u, 1000000u, 0x80000000u};
    uint32_t rs = 777u;
    for (size_t sp = 0; sp < sizeof spps / sizeof *spps; sp++)
        for (uint32_t t = 0; t < 400; t++) {
            uint32_t n = spps[sp] ? spps[sp] : 1u;
            uint32_t key = t < 5 ? keys[t] : lcg(&rs);
            /* the spp's first round, later rounds (a fresh pattern), any index */
            uint32_t index = t % 4 == 0 ? lcg(&rs) : t % 4 == 1 ? t % n : lcg(&rs) % (n < 4096u ? 3u * n : 12288u);
            uint32_t dim0 = t < 60 ? (uint32_t[]){0u, 6u, 1000u, 0xfffffffcu}[t % 4] : lcg(&rs);
            float bx[RT_SAMPLER_BLOCK], by[RT_SAMPLER_BLOCK];
            rt_sampler_block(RT_SAMPLER_CMJ, key, index, spps[sp], dim0, bx, by);
            rt_sampler_cache c;
            rt_sampler_cache_clear(&c);
            for (uint32_t k = 0; k < RT_SAMPLER_BLOCK; k++) {
                rt_vec2 v = rt_sampler_2d(RT_SAMPLER_CMJ, key, index, spps[sp], dim0 + k);
                rt_vec2 cv = rt_sampler_cache_2d(&c, RT_SAMPLER_CMJ, key, index, spps[sp], dim0, k);
                if (!(v.x == bx[k] && v.y == by[k] && v.x == cv.x && v.y == cv.y))
                    fail_msg("CMJ key %#x index %u spp %u dim %#x: rt_sampler_2d (%a, %a), block (%a, %a), cache (%a, %a)",
                             key, index, spps[sp], dim0 + k, (double)v.x, (double)v.y, (double)bx[k], (double)by[k],
                             (double)cv.x, (double)cv.y);
            }
        }
}

static void check_cmj(uint32_t key, uint32_t dim, uint32_t m, uint32_t round)
{
    uint32_t n = m * m;
    static uint8_t cell[4096], col[4096], row[4096], one[4096];
    memset(cell, 0, n), memset(col, 0, n), memset(row, 0, n), memset(one, 0, n);
    for (uint32_t i = round * n; i < (round + 1) * n; i++) {
        rt_vec2 p = rt_sampler_2d(RT_SAMPLER_CMJ, key, i, n, dim);
        uint32_t cx = (uint32_t)(p.x * (float)m), cy = (uint32_t)(p.y * (float)m);
        uint32_t fx = (uint32_t)(p.x * (float)n), fy = (uint32_t)(p.y * (float)n);
        uint32_t q = (uint32_t)(rt_sampler_1d(RT_SAMPLER_CMJ, key, i, n, dim) * (float)n);
        if (cell[cy * m + cx]++ || col[fx]++ || row[fy]++ || one[q]++)
            fail_msg("CMJ key %u dim %u spp %u round %u: sample %u shares a stratum", key, dim, n, round, i);
    }
}

static void test_cmj_strata(void **state)
{
    (void)state;
    for (size_t a = 0; a < sizeof keys / sizeof *keys; a++)
        for (size_t b = 0; b < sizeof dims / sizeof *dims; b++) {
            /* (not m = 64: rt_cmj_sample's float sum sy + jitter can round up
             * to the next fine stratum there, by one ulp) */
            const uint32_t ms[] = {1, 2, 3, 4, 7, 8, 10, 16};
            for (size_t k = 0; k < sizeof ms / sizeof *ms; k++) {
                check_cmj(keys[a], dims[b], ms[k], 0);
                check_cmj(keys[a], dims[b], ms[k], 2);
            }
            /* 1D, any spp */
            const uint32_t ns[] = {2, 5, 12, 33, 100};
            for (size_t k = 0; k < sizeof ns / sizeof *ns; k++) {
                static uint8_t seen[128];
                memset(seen, 0, ns[k]);
                for (uint32_t i = 0; i < ns[k]; i++) {
                    uint32_t q = (uint32_t)(rt_sampler_1d(RT_SAMPLER_CMJ, keys[a], i, ns[k], dims[b]) * (float)ns[k]);
                    assert_true(q < ns[k]);
                    assert_int_equal(seen[q]++, 0);
                }
            }
        }
}

/* Padding: the points of two dimensions of a pixel are different patterns,
 * paired in a different order. Over many pixels, the correlation of the
 * x values of dimensions 0 and 1 at the same sample is near 0 (the
 * unshuffled sequences would give exactly 1 for Sobol's x). */
static void test_dimensions_decorrelated(void **state)
{
    (void)state;
    const rt_sampler_kind kinds[] = {RT_SAMPLER_CMJ, RT_SAMPLER_SOBOL};
    for (size_t k = 0; k < 2; k++) {
        double sxy = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, syy = 0.0;
        int n = 0, same = 0;
        for (uint32_t key = 0; key < 256; key++)
            for (uint32_t i = 0; i < 16; i++) {
                double x = rt_sampler_2d(kinds[k], key, i, 16, 4).x, y = rt_sampler_2d(kinds[k], key, i, 16, 5).x;
                same += x == y;
                sxy += x * y, sx += x, sy += y, sxx += x * x, syy += y * y;
                n++;
            }
        double cov = sxy / n - (sx / n) * (sy / n);
        double corr = cov / sqrt((sxx / n - (sx / n) * (sx / n)) * (syy / n - (sy / n) * (sy / n)));
        fprintf(stderr, "%s: correlation of two dimensions over 4096 samples: %.4f\n",
                kinds[k] == RT_SAMPLER_CMJ ? "cmj" : "sobol", corr);
        assert_true(fabs(corr) < 0.06); /* 4 sigma of 1/sqrt(4096) */
        assert_true(same < 4);
    }
}

/* ------------------------------------------------------------ images */

typedef struct fixture {
    rt_scene s;
    rt_settings settings;
    rt_kdtree tree;
} fixture;

/* The crop's MSE against the same pixels of the 512x512 reference. */
static double crop_mse(const rt_framebuffer *img, const rt_framebuffer *ref, rt_render_region r)
{
    double se = 0.0;
    for (int y = r.y0; y < r.y1; y++)
        for (int x = r.x0; x < r.x1; x++)
            for (int c = 0; c < 3; c++) {
                double v = img->rgb[3 * ((size_t)(y - r.y0) * (size_t)img->width + (size_t)(x - r.x0)) + (size_t)c];
                double w = ref->rgb[3 * ((size_t)y * 512 + (size_t)x) + (size_t)c];
                se += (v - w) * (v - w);
            }
    return se / ((double)(r.x1 - r.x0) * (double)(r.y1 - r.y0) * 3.0);
}

/* The shared Cornell box (scenes/cornell-reference.txt) at seed 0 and its
 * kd-tree. */
static void cornell_fixture(fixture *f)
{
    rt_error err;
    rt_scene_init(&f->s);
    rt_settings_default(&f->settings);
    if (rt_scene_parse_file(&f->s, &f->settings, "scenes/cornell-reference.txt", &err) != RT_OK)
        fail_msg("%s", err.message);
    f->settings.seed = 0;
    assert_int_equal(rt_kdtree_build(&f->tree, &f->s, NULL, &err), RT_OK);
}

static void fixture_free(fixture *f)
{
    rt_kdtree_free(&f->tree);
    rt_scene_free(&f->s);
}

/* Renders region with the integrator and sampler given: all the scene's
 * samples when sample_end is 0, else samples 0 .. sample_end - 1. */
static void render(fixture *f, rt_integrator in, rt_sampler_kind kind, rt_render_region region, int sample_end,
                   rt_framebuffer *fb)
{
    rt_error err;
    f->settings.integrator = in;
    f->settings.sampler = (int)kind;
    assert_int_equal(rt_framebuffer_init(fb, region.x1 - region.x0, region.y1 - region.y0, &err), RT_OK);
    rt_render_options opt;
    memset(&opt, 0, sizeof opt);
    opt.threads = 2;
    opt.region = region;
    opt.sample_end = sample_end;
    rt_render_stats st;
    assert_int_equal(rt_render(&f->s, &f->settings, &f->tree, &opt, fb, &st, &err), RT_OK);
    assert_int_equal(st.bad_samples, 0);
}

/* scenes/cornell-reference.txt at 512x512, a 128x128 crop of it (the
 * middle: both blocks, floor, back wall, the walls' colour bleeding), 16
 * spp, seed 0: MSE against the same pixels of the reference (whose own
 * noise, MSE 4e-6, is 1% of ours). The stratified samplers must beat the
 * independent one by a margin: over the whole image their MSE is 0.72-0.76
 * of it at rr_depth 3 and 5 (docs/performance.md); assert < 0.85 (the MSE of 16,384 pixels has
 * a relative noise of a few percent). path and path_scalar give the same
 * bytes for each sampler (on a 32x32 corner of the crop). */
static void test_cornell_mse_stratified(void **state)
{
    (void)state;
    rt_framebuffer ref;
    test_require_cornell_reference(&ref);
    fixture f;
    cornell_fixture(&f);
    f.settings.samples = 16;
    const rt_sampler_kind kinds[] = {RT_SAMPLER_INDEPENDENT, RT_SAMPLER_CMJ, RT_SAMPLER_SOBOL};
    double mse[3];
    const rt_render_region crop = {192, 192, 320, 320}, corner = {192, 192, 224, 224};
    for (int k = 0; k < 3; k++) {
        rt_framebuffer img;
        render(&f, RT_INTEGRATOR_PATH, kinds[k], crop, 0, &img);
        mse[k] = crop_mse(&img, &ref, crop);
        rt_framebuffer_free(&img);
        rt_framebuffer small, scalar;
        render(&f, RT_INTEGRATOR_PATH, kinds[k], corner, 0, &small);
        render(&f, RT_INTEGRATOR_PATH_SCALAR, kinds[k], corner, 0, &scalar);
        assert_memory_equal(small.rgb, scalar.rgb, (size_t)32 * 32 * 3 * sizeof(float));
        rt_framebuffer_free(&small);
        rt_framebuffer_free(&scalar);
    }
    fprintf(stderr, "cornell 512x512, crop 128x128 @ 16 spp, MSE: independent %.4g, cmj %.4g (%.3fx), sobol %.4g (%.3fx)\n", mse[0],
            mse[1], mse[1] / mse[0], mse[2], mse[2] / mse[0]);
    assert_true(mse[1] < 0.85 * mse[0]);
    assert_true(mse[2] < 0.85 * mse[0]);
    rt_framebuffer_free(&ref);
    fixture_free(&f);
}

/* A stopped render is the prefix of each pixel's samples: samples 0..15 of
 * a 64-spp render must cover the pixels evenly. With the Sobol sampler the
 * camera takes the film position from it (rt_camera_pixel_sample), and any
 * power-of-two prefix is a (0,k,2)-net over the pixel: the prefix's MSE is
 * that of a 16-spp render (within noise). Correlated multi-jittering puts
 * sample s in row s / 8 of 8: the first 16 samples sit in the top quarter
 * of every pixel, a shift of 3/8 pixel (measured: 100x the MSE on the
 * whole image); that stays the camera of `cmj` and `independent`. */
static void test_prefix_covers_pixel(void **state)
{
    (void)state;
    rt_framebuffer ref;
    test_require_cornell_reference(&ref);
    fixture f;
    cornell_fixture(&f);
    const rt_render_region crop = {192, 192, 320, 320};
    double mse[2];
    for (int k = 0; k < 2; k++) {
        f.settings.samples = k == 0 ? 16 : 64;
        rt_framebuffer img;
        render(&f, RT_INTEGRATOR_PATH, RT_SAMPLER_SOBOL, crop, 16, &img);
        mse[k] = crop_mse(&img, &ref, crop);
        rt_framebuffer_free(&img);
    }
    fprintf(stderr, "sobol, crop 128x128: 16 spp MSE %.4g, samples 0:16 of 64 MSE %.4g (%.3fx)\n", mse[0], mse[1],
            mse[1] / mse[0]);
    assert_true(mse[1] < 1.3 * mse[0]);
    rt_framebuffer_free(&ref);
    fixture_free(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_values_in_unit_interval),
        cmocka_unit_test(test_sobol_nets),
        cmocka_unit_test(test_sobol_block_matches_reference),
        cmocka_unit_test(test_cmj_block_matches_scalar),
        cmocka_unit_test(test_cmj_strata),
        cmocka_unit_test(test_dimensions_decorrelated),
        cmocka_unit_test(test_cornell_mse_stratified),
        cmocka_unit_test(test_prefix_covers_pixel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
