/* test_volume.c - the building blocks of participating media against
 * closed forms and brute force (rt/render/phase.h, rt/render/volume.h,
 * rt/scene/density_grid.h):
 *   - the Henyey-Greenstein function integrates to 1 over the sphere, its
 *     sampler's cosines fall into 32 bins as the closed-form CDF says
 *     (within 4 sigma a bin), the mean cosine is g, and a sampled
 *     direction's pdf is the function at its cosine;
 *   - a homogeneous slab: delta tracking lets exp(-sigma_t L) of the rays
 *     through in each channel (binomial, 4 sigma), its collision distances
 *     follow the exponential law, and ratio tracking's mean is exp(-sigma_t L)
 *     (4 standard errors), with a direction that is not unit length;
 *   - a voxel grid placed by a scale and a translation: the trilinear
 *     lookup at voxel centres and midpoints, the majorant's pieces cover the
 *     clipped ray without gaps and bound the density everywhere inside them
 *     (random rays, points sampled in every piece), and ratio and delta
 *     tracking match exp(-optical depth) where the optical depth is
 *     integrated by brute force along the ray (a ramp with an empty gap);
 *   - bad grids are refused: a NaN, a negative or an infinite voxel (named),
 *     a size of 0, a claim over the voxel limit (before any allocation).
 */
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rt/render/phase.h"
#include "rt/render/volume.h"
#include "rt/scene/density_grid.h"

static const float g_values[] = {-0.9f, -0.3f, 0.0f, 0.0005f, 0.5f, 0.95f};
#define G_COUNT (int)(sizeof g_values / sizeof g_values[0])

/* P(cos <= c) for HG, in double (the closed form of its integral). */
static double hg_cdf(double g, double c)
{
    if (fabs(g) < 1e-3)
        return (c + 1.0) / 2.0;
    return (1.0 - g * g) / (2.0 * g) * (1.0 / sqrt(1.0 + g * g - 2.0 * g * c) - 1.0 / (1.0 + g));
}

static void test_hg_normalised(void **state)
{
    (void)state;
    for (int k = 0; k < G_COUNT; k++) {
        double sum = 0.0;
        const int n = 400000;
        for (int i = 0; i < n; i++) {
            double c = -1.0 + (i + 0.5) * (2.0 / n);
            sum += 2.0 * 3.14159265358979323846 * rt_hg_pdf(g_values[k], (float)c) * (2.0 / n);
        }
        assert_true(fabs(sum - 1.0) < 2e-3);
        assert_true(fabs(hg_cdf(g_values[k], 1.0) - 1.0) < 1e-9);
    }
}

static void test_hg_sampler_matches_pdf(void **state)
{
    (void)state;
    enum { BINS = 32, N = 200000 };
    for (int k = 0; k < G_COUNT; k++) {
        float g = g_values[k];
        int count[BINS] = {0};
        double mean = 0.0;
        rt_rng rng = rt_rng_seed(7, (uint64_t)k);
        rt_vec3 d_in = rt_normalize(rt_v3(0.3f, -0.5f, 0.8f));
        for (int i = 0; i < N; i++) {
            float u1 = rt_rng_float(&rng), u2 = rt_rng_float(&rng);
            float pdf;
            rt_vec3 d = rt_hg_sample(g, d_in, u1, u2, &pdf);
            assert_true(fabsf(rt_length(d) - 1.0f) < 1e-5f);
            float c = rt_dot(d_in, d);
            assert_true(fabsf(c - rt_hg_sample_cos(g, u1)) < 2e-4f);
            assert_true(fabsf(pdf - rt_hg_pdf(g, c)) <= 1e-6f * pdf + 1e-12f);
            int b = (int)((c + 1.0f) * 0.5f * BINS);
            b = b < 0 ? 0 : (b >= BINS ? BINS - 1 : b);
            count[b]++;
            mean += c;
        }
        for (int b = 0; b < BINS; b++) {
            double lo = -1.0 + 2.0 * b / BINS, hi = -1.0 + 2.0 * (b + 1) / BINS;
            double p = hg_cdf(g, hi) - hg_cdf(g, lo);
            double expect = p * N, sigma = sqrt(N * p * (1.0 - p)) + 1.0;
            if (fabs(count[b] - expect) > 4.0 * sigma)
                fail_msg("g %g bin %d: %d samples, expected %.1f +- %.1f", (double)g, b, count[b], expect, sigma);
        }
        /* the mean cosine of HG is g; the cosine's variance is at most 1 */
        mean /= N;
        assert_true(fabs(mean - g) < 4.0 / sqrt((double)N));
    }
}

/* 4-sigma binomial check of `hits` out of `n` against probability p. */
static void assert_binomial(int hits, int n, double p, const char *what)
{
    double sigma = sqrt(n * p * (1.0 - p)) + 1.0;
    if (fabs(hits - n * p) > 4.0 * sigma)
        fail_msg("%s: %d of %d, expected %.1f +- %.1f", what, hits, n, n * p, sigma);
}

static void assert_mean(double sum, double sum2, int n, double expect, const char *what)
{
    double mean = sum / n, var = sum2 / n - mean * mean;
    double se = sqrt(var > 0 ? var / n : 0) + 1e-4;
    if (fabs(mean - expect) > 4.0 * se)
        fail_msg("%s: mean %.5f, expected %.5f (standard error %.5f)", what, mean, expect, se);
}

static void test_homogeneous_slab(void **state)
{
    (void)state;
    rt_vec3 sa = rt_v3(0.2f, 0.5f, 1.5f), ss = rt_v3(0.3f, 0.5f, 0.5f); /* sigma_t 0.5, 1, 2 */
    rt_volume v = rt_volume_homogeneous(sa, ss, 0.0f);
    rt_vec3 o = rt_v3(1, 2, 3), d = rt_scale(rt_normalize(rt_v3(1, -2, 0.5f)), 2.0f); /* |d| = 2 */
    const float L = 1.3f, t_max = L / 2.0f;
    const float st[3] = {0.5f, 1.0f, 2.0f};
    enum { N = 100000 };
    for (int c = 0; c < 3; c++) {
        rt_rng rng = rt_rng_seed(11, (uint64_t)c);
        int pass = 0, early = 0;
        for (int i = 0; i < N; i++) {
            float t = rt_volume_delta_tracking(&v, o, d, t_max, c, &rng);
            pass += t >= t_max;
            early += t < t_max / 2.0f;
        }
        char what[64];
        snprintf(what, sizeof what, "delta tracking, channel %d, passing", c);
        assert_binomial(pass, N, exp(-st[c] * L), what);
        snprintf(what, sizeof what, "delta tracking, channel %d, first half", c);
        assert_binomial(early, N, 1.0 - exp(-st[c] * L / 2.0), what);
    }
    rt_rng rng = rt_rng_seed(12, 0);
    double sum[3] = {0}, sum2[3] = {0};
    for (int i = 0; i < N; i++) {
        rt_vec3 T = rt_volume_ratio_tracking(&v, o, d, t_max, &rng);
        const float tc[3] = {T.x, T.y, T.z};
        for (int c = 0; c < 3; c++) {
            assert_true(tc[c] >= 0.0f && tc[c] <= 1.0f);
            sum[c] += tc[c];
            sum2[c] += (double)tc[c] * tc[c];
        }
    }
    for (int c = 0; c < 3; c++)
        assert_mean(sum[c], sum2[c], N, exp(-st[c] * L), "ratio tracking, homogeneous slab");
}

/* A 20x6x5 grid: density 0.1 x (x index) except an empty gap at x 8..15,
 * placed at world = index * 0.25 + (-1, 0.5, 2). */
static void make_ramp(rt_density_grid *g, rt_mat4 *world_to_index)
{
    rt_error err = {0};
    assert_int_equal(rt_density_grid_init(g, 20, 6, 5, &err), RT_OK);
    for (int z = 0; z < 5; z++)
        for (int y = 0; y < 6; y++)
            for (int x = 0; x < 20; x++)
                g->density[rt_density_grid_index(g, x, y, z)] = (x >= 8 && x < 16) ? 0.0f : 0.1f * (float)x;
    assert_int_equal(rt_density_grid_finish(g, "ramp", &err), RT_OK);
    *world_to_index = rt_mat4_mul(rt_mat4_scale(rt_v3(4, 4, 4)), rt_mat4_translate(rt_v3(1, -0.5f, -2)));
}

static void test_grid_lookup(void **state)
{
    (void)state;
    rt_density_grid g;
    rt_mat4 w2i;
    make_ramp(&g, &w2i);
    assert_true(fabsf(rt_density_grid_lookup(&g, rt_v3(3.5f, 2.5f, 2.5f)) - 0.3f) < 1e-6f);
    assert_true(fabsf(rt_density_grid_lookup(&g, rt_v3(4.0f, 2.5f, 2.5f)) - 0.35f) < 1e-6f);
    assert_true(fabsf(rt_density_grid_lookup(&g, rt_v3(4.0f, 3.0f, 3.0f)) - 0.35f) < 1e-6f);
    /* half a voxel past the last centre the neighbour outside counts as 0 */
    assert_true(fabsf(rt_density_grid_lookup(&g, rt_v3(20.0f, 2.5f, 2.5f)) - 0.95f) < 1e-6f);
    assert_true(rt_density_grid_lookup(&g, rt_v3(20.6f, 2.5f, 2.5f)) == 0.0f);
    assert_true(rt_density_grid_lookup(&g, rt_v3(-0.6f, 2.5f, 2.5f)) == 0.0f);
    assert_true(rt_density_grid_lookup(&g, rt_v3(NAN, 2.5f, 2.5f)) == 0.0f);
    assert_true(fabsf(g.max_density - 1.9f) < 1e-6f);
    /* world placement: index (3.5, 2.5, 2.5) is world (-0.125, 1.125, 2.625) */
    rt_volume v = rt_volume_grid(rt_v3(1, 1, 1), rt_v3(0, 0, 0), 0.0f, &g, &w2i);
    assert_true(fabsf(rt_volume_density(&v, rt_v3(-0.125f, 1.125f, 2.625f)) - 0.3f) < 1e-5f);
    rt_density_grid_free(&g);
}

static void test_majorant_bounds_density(void **state)
{
    (void)state;
    rt_error err = {0};
    rt_density_grid g;
    assert_int_equal(rt_density_grid_init(&g, 19, 23, 9, &err), RT_OK);
    rt_rng rng = rt_rng_seed(21, 0);
    size_t n = (size_t)g.nx * g.ny * g.nz;
    for (size_t i = 0; i < n; i++) {
        float u = rt_rng_float(&rng);
        g.density[i] = u < 0.995f ? 0.0f : (u - 0.99f) * 300.0f; /* empty but for a few spikes a block */
    }
    assert_int_equal(rt_density_grid_finish(&g, "random", &err), RT_OK);
    rt_mat4 w2i = rt_mat4_mul(rt_mat4_scale(rt_v3(10, 10, 10)), rt_mat4_translate(rt_v3(0.2f, -0.1f, 0.3f)));
    rt_volume v = rt_volume_grid(rt_v3(0.5f, 1, 2), rt_v3(0.5f, 0, 1), 0.3f, &g, &w2i);
    int pieces = 0, checked = 0;
    for (int r = 0; r < 400; r++) {
        rt_vec3 o = rt_v3(rt_rng_float(&rng) * 3 - 1, rt_rng_float(&rng) * 3 - 1, rt_rng_float(&rng) * 3 - 1);
        /* towards a point of the grid's world box x -0.25..1.75, y 0.05..2.45, z -0.35..0.65 */
        rt_vec3 target = rt_v3(rt_rng_float(&rng) * 2.0f - 0.25f, rt_rng_float(&rng) * 2.4f + 0.05f,
                               rt_rng_float(&rng) - 0.35f);
        if (r % 7 == 0)
            target.y = o.y; /* parallel to a set of planes */
        rt_vec3 d = rt_sub(target, o);
        float t_max = 2.0f;
        rt_majorant_iter it;
        rt_majorant_iter_init(&it, &v, o, d, 0.0f, t_max);
        float t0, t1, prev = NAN;
        rt_vec3 maj;
        while (rt_majorant_next(&it, &t0, &t1, &maj)) {
            pieces++;
            assert_true(t0 <= t1);
            if (!isnan(prev))
                assert_true(t0 == prev); /* contiguous */
            prev = t1;
            for (int s = 0; s < 10; s++) {
                /* near both ends, where the neighbouring block's voxels weigh in, and inside */
                float u = s == 0 ? 1e-3f : (s == 1 ? 1.0f - 1e-3f : rt_rng_float(&rng));
                float t = t0 + (t1 - t0) * u;
                float dens = rt_volume_density(&v, rt_madd(o, d, t));
                rt_vec3 st = rt_scale(rt_volume_sigma_t(&v), rt_length(d) * dens);
                assert_true(st.x <= maj.x * 1.0001f + 1e-6f && st.y <= maj.y * 1.0001f + 1e-6f &&
                            st.z <= maj.z * 1.0001f + 1e-6f);
                checked++;
            }
        }
        /* outside every piece the density is 0: sample the ray densely */
        rt_majorant_iter_init(&it, &v, o, d, 0.0f, t_max);
        float first = INFINITY, last = -INFINITY;
        while (rt_majorant_next(&it, &t0, &t1, &maj)) {
            first = t0 < first ? t0 : first;
            last = t1 > last ? t1 : last;
        }
        for (int s = 0; s < 200; s++) {
            float t = t_max * (s + 0.5f) / 200.0f;
            if (t < first - 1e-4f || t > last + 1e-4f)
                assert_true(rt_volume_density(&v, rt_madd(o, d, t)) == 0.0f);
        }
    }
    if (!(pieces > 400 && checked > 4000))
        fail_msg("only %d pieces, %d points checked", pieces, checked);
    rt_density_grid_free(&g);
}

static void test_grid_tracking(void **state)
{
    (void)state;
    rt_density_grid g;
    rt_mat4 w2i;
    make_ramp(&g, &w2i);
    rt_vec3 sa = rt_v3(1.0f, 2.0f, 0.5f), ss = rt_v3(1.0f, 0.5f, 0.5f); /* sigma_t 2, 2.5, 1 */
    rt_volume v = rt_volume_grid(sa, ss, 0.0f, &g, &w2i);
    /* world box: x -1..4, y 0.5..2, z 2..3.25; an oblique ray across it */
    rt_vec3 o = rt_v3(-1.5f, 0.9f, 2.2f), d = rt_scale(rt_v3(6.0f, 0.6f, 0.7f), 0.5f);
    const float t_max = 2.0f;
    /* the optical depth by brute force along the ray */
    double depth = 0.0;
    const int steps = 200000;
    for (int i = 0; i < steps; i++) {
        double t = (i + 0.5) * t_max / steps;
        depth += rt_volume_density(&v, rt_madd(o, d, (float)t)) * (t_max / steps);
    }
    depth *= rt_length(d);
    const double st[3] = {2.0, 2.5, 1.0};
    assert_true(depth > 0.3 && depth < 3.0); /* the ray really crosses the ramp */
    enum { N = 100000 };
    for (int c = 0; c < 3; c++) {
        rt_rng rng = rt_rng_seed(31, (uint64_t)c);
        int pass = 0;
        for (int i = 0; i < N; i++)
            pass += rt_volume_delta_tracking(&v, o, d, t_max, c, &rng) >= t_max;
        assert_binomial(pass, N, exp(-st[c] * depth), "delta tracking through the ramp");
    }
    rt_rng rng = rt_rng_seed(32, 0);
    double sum[3] = {0}, sum2[3] = {0};
    for (int i = 0; i < N; i++) {
        rt_vec3 T = rt_volume_ratio_tracking(&v, o, d, t_max, &rng);
        const float tc[3] = {T.x, T.y, T.z};
        for (int c = 0; c < 3; c++) {
            sum[c] += tc[c];
            sum2[c] += (double)tc[c] * tc[c];
        }
    }
    for (int c = 0; c < 3; c++)
        assert_mean(sum[c], sum2[c], N, exp(-st[c] * depth), "ratio tracking through the ramp");
    rt_density_grid_free(&g);
}

static void test_bad_grids_refused(void **state)
{
    (void)state;
    rt_error err = {0};
    rt_density_grid g;
    assert_int_equal(rt_density_grid_init(&g, 0, 4, 4, &err), RT_ERR_INVALID);
    assert_int_equal(rt_density_grid_init(&g, 100000, 100000, 100000, &err), RT_ERR_LIMIT);
    assert_non_null(strstr(err.message, "100000x100000x100000"));
    const float bad[] = {NAN, -0.5f, INFINITY};
    for (int i = 0; i < 3; i++) {
        assert_int_equal(rt_density_grid_init(&g, 4, 3, 2, &err), RT_OK);
        g.density[rt_density_grid_index(&g, 2, 1, 1)] = bad[i];
        assert_int_equal(rt_density_grid_finish(&g, "cloud.nvdb", &err), RT_ERR_INVALID);
        assert_non_null(strstr(err.message, "cloud.nvdb: voxel (2, 1, 1)"));
        rt_density_grid_free(&g);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hg_normalised),
        cmocka_unit_test(test_hg_sampler_matches_pdf),
        cmocka_unit_test(test_homogeneous_slab),
        cmocka_unit_test(test_grid_lookup),
        cmocka_unit_test(test_majorant_bounds_density),
        cmocka_unit_test(test_grid_tracking),
        cmocka_unit_test(test_bad_grids_refused),
    };
    return cmocka_run_group_tests_name("volume", tests, NULL, NULL);
}
