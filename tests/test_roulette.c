/* test_roulette.c - Russian roulette of the path tracer weighs the
 * throughput by eta_scale, the squared index ratios of the refractions a
 * path took (issue 30; pbrt-v4's etaScale, Mitsuba 3's max(throughput) eta^2):
 *   - unit level: a path that refracted into a dense dielectric (index 2.4)
 *     has eta_scale 2.4^2 and continues with probability 0.95 (rr_depth N)
 *     or 1 (adaptive), where max channel of beta alone (1 / 2.4^2) would
 *     have killed 83% of such paths; leaving again brings eta_scale back to
 *     1, and a reflected path keeps exactly 1;
 *   - along random walks through nested dielectrics (priorities, false
 *     intersections, a rough glass with energy compensation) eta_scale is
 *     always the square of the current medium's index, and through
 *     thin-walled and glTF transmission (which do not scale radiance)
 *     exactly 1;
 *   - white furnaces of smooth and rough glass stay unbiased for every
 *     rr_depth (the means agree with the closed form or with no roulette);
 *   - variance, fixed seeds: the smooth glass furnace (exactly 1 without
 *     roulette) and a lit glass sphere on a floor, against the same scene
 *     without roulette, below stated bounds the old rule failed.
 */
#include "test_util.h"
#include "test_fixture.h"
#include "test_scenes.h"

#include <math.h>

#include "rt/render/pathtrace.h"
#include "rt/render/medium.h"
#include "rt/render/surface.h"

typedef test_fixture fixture; /* test_fixture.h */

/* One path of f from org along dir, stepped as rt_radiance_path steps it
 * but without light sampling (only the BSDF's and the roulette's numbers
 * are drawn): *ps after vertex `stop` (1 = the first) has been sampled, or
 * earlier when the path ended; returns the vertices sampled. */
static int walk(const fixture *f, rt_vec3 org, rt_vec3 dir, uint32_t i, int stop, rt_path_state *ps)
{
    rt_rng rng = rt_rng_for_sample(3, i, 0);
    rt_ray r = rt_ray_make(org, rt_normalize(dir), 0.0f, INFINITY);
    assert_true(rt_path_start(&f->ctx, &r, ps));
    int done = 0;
    while (done < stop) {
        int layers = RT_PATH_LAYERS;
        rt_surface sf;
        float coverage;
        if (rt_trace_surface(&f->ctx, &ps->r, &layers, &rng, &sf, &coverage) != RT_WALK_SURFACE)
            break;
        rt_bsdf b;
        rt_vec3 wo;
        rt_path_vertex v = rt_path_vertex_begin(&f->ctx, ps, &sf, &b, &wo);
        if (v == RT_VERTEX_PASS)
            continue;
        if (v == RT_VERTEX_STOP)
            break;
        done++;
        if (!rt_path_vertex_end(&f->ctx, ps, &sf, &b, wo, &rng))
            break;
    }
    return done;
}

/* ------------------------------------------------------------- unit level */

/* A smooth ball of index 2.4 (diamond) hit head-on: the transmitted
 * weight is (1 / 2.4)^2 = 0.174 and eta_scale 2.4^2 = 5.76, so the
 * roulette weighs 1 and keeps the path with probability 0.95 from
 * rr_depth 1 on, and always under the adaptive rule; max channel of beta
 * alone would keep it with probability 0.174. */
static void test_probability_inside_dense_dielectric(void **state)
{
    (void)state;
    fixture f;
    test_fixture_load(&f, "integrator path\nrr_depth 3\nmaterial g bsdf dielectric ior 2.4\nsphere 0 0 0 1 g\n", 0);
    int inside = 0, reflected = 0, out = 0;
    for (uint32_t i = 0; i < 64; i++) {
        rt_path_state ps;
        if (walk(&f, rt_v3(0, 0, 5), rt_v3(0, 0, -1), i, 1, &ps) != 1)
            continue;
        if (ps.r.dir.z > 0.0f) { /* reflected: nothing refracted, eta_scale exactly 1 */
            assert_true(ps.eta_scale == 1.0f);
            reflected++;
            continue;
        }
        inside++;
        float beta = rt_max3(ps.beta);
        if (fabsf(ps.eta_scale - 5.76f) > 1e-4f || fabsf(beta - 1.0f / 5.76f) > 1e-4f)
            fail_msg("inside: eta_scale %.6f (want 5.76), max beta %.6f (want 0.17361)", (double)ps.eta_scale,
                     (double)beta);
        assert_int_equal(ps.bounces, 1);
        /* rr_depth 1: min(beta x eta_scale, 0.95); before issue 30, 0.174 */
        assert_true(rt_path_rr_probability(&ps, 1) == 0.95f);
        assert_true(rt_path_rr_probability(&ps, 0) == 1.0f); /* adaptive: weighs 1, no roulette */
        assert_true(rt_path_rr_probability(&ps, 2) == 1.0f); /* before the start depth: none */
        /* a dimmer path inside (beta halved) weighs half as much */
        rt_path_state dim = ps;
        dim.beta = rt_scale(ps.beta, 0.5f);
        float w = rt_max3(dim.beta) * dim.eta_scale;
        assert_true(fabsf(w - 0.5f) < 1e-4f);
        assert_true(rt_path_rr_probability(&dim, 1) == w && rt_path_rr_probability(&dim, 0) == w);
        /* out through the back, head-on again: eta_scale returns to 1 */
        if (walk(&f, rt_v3(0, 0, 5), rt_v3(0, 0, -1), i, 2, &ps) == 2 && ps.r.dir.z < 0.0f &&
            ps.r.org.z < -0.5f) {
            if (fabsf(ps.eta_scale - 1.0f) > 1e-5f)
                fail_msg("left the ball: eta_scale %.7f, want 1", (double)ps.eta_scale);
            out++;
        }
    }
    fprintf(stderr, "index 2.4 head-on, 64 paths: %d refracted in (%d out again), %d reflected\n", inside, out,
            reflected);
    assert_true(inside > 40 && reflected > 3 && out > 20); /* F = 0.17 at each interface */
    test_fixture_free(&f);
}

/* Random walks through nested media: an outer rough glass ball (index 1.5,
 * priority 1, energy compensation on) holding water (1.33, priority 2, a
 * higher priority: it fills its ball), overlapped by a dense ball (2.0,
 * priority 0: its surface inside the glass is a false intersection). At
 * every vertex eta_scale is (index of the current medium)^2, 1 outside. */
static void test_eta_scale_follows_media(void **state)
{
    (void)state;
    fixture f;
    test_fixture_load(&f,
                      "integrator path\nrr_depth 1024\nmax_depth 64\nenergy_compensation on\n"
                      "material glass bsdf dielectric ior 1.5 ggx_alpha 0.3 priority 1\n"
                      "material water bsdf dielectric ior 1.33 priority 2\n"
                      "material dense bsdf dielectric ior 2.0 priority 0\n"
                      "sphere 0 0 0 1 glass\nsphere 0 0 0 0.5 water\nsphere 0.9 0 0 0.5 dense\n",
                      0);
    int checked = 0, in_water = 0, in_dense = 0;
    test_rng tr = {41};
    for (uint32_t i = 0; i < 400; i++) {
        rt_vec3 org = rt_v3(4.0f * test_rng_float(&tr) - 2.0f, 2.0f * test_rng_float(&tr) - 1.0f, 5.0f);
        for (int stop = 1; stop <= 12; stop++) {
            rt_path_state ps;
            if (walk(&f, org, rt_sub(rt_v3(0.3f, 0, 0), org), i, stop, &ps) != stop)
                break;
            uint32_t m = rt_medium_current(&ps.media, f.s.materials);
            float n = m == RT_NONE ? 1.0f : f.s.materials[m].ior;
            in_water += n == 1.33f;
            in_dense += n == 2.0f;
            if (fabsf(ps.eta_scale - n * n) > 1e-4f * n * n)
                fail_msg("path %u vertex %d: eta_scale %.6f in a medium of index %.2f", i, stop,
                         (double)ps.eta_scale, (double)n);
            checked++;
        }
    }
    fprintf(stderr, "nested media: %d vertices (%d in water, %d in the dense ball)\n", checked, in_water, in_dense);
    assert_true(checked > 1000 && in_water > 20 && in_dense > 20);
    test_fixture_free(&f);

    /* thin-walled and glTF transmission do not scale radiance: eta_scale stays exactly 1 */
    test_fixture_load(&f,
                      "integrator path\nrr_depth 1024\nmax_depth 32\n"
                      "material thin color 1 1 1 transmission 1 ior 1.5 roughness 0.2 thin_walled true\n"
                      "material solid color 1 1 1 transmission 1 ior 1.5 roughness 0\n"
                      "sphere -0.6 0 0 0.5 thin\nsphere 0.6 0 0 0.5 solid\n",
                      0);
    for (uint32_t i = 0; i < 200; i++) {
        rt_vec3 org = rt_v3(-1.2f + 0.012f * (float)i, 0.1f, 5.0f);
        for (int stop = 1; stop <= 8; stop++) {
            rt_path_state ps;
            if (walk(&f, org, rt_v3(0, 0, -1), i, stop, &ps) != stop)
                break;
            if (ps.eta_scale != 1.0f)
                fail_msg("glTF transmission, path %u vertex %d: eta_scale %.7f", i, stop, (double)ps.eta_scale);
        }
    }
    test_fixture_free(&f);
}

/* ------------------------------------------------------------- furnaces */

/* Mean and its standard error of the green radiance along -z from n
 * points of the disk of radius 0.95 x r around (cx, cy) (the test stream
 * seeded `seed`), pixel i the ray's index. */
static double mean_over_disk(const fixture *f, float cx, float cy, float r, uint32_t n, uint64_t seed, double *se,
                             double *var)
{
    double sum = 0.0, sum2 = 0.0;
    test_rng tr = {seed};
    uint32_t hits = 0;
    for (uint32_t i = 0; i < n; i++) {
        float x = 2.0f * test_rng_float(&tr) - 1.0f, y = 2.0f * test_rng_float(&tr) - 1.0f;
        if (x * x + y * y > 0.9f)
            continue;
        double L = test_fixture_path_radiance(f, 5, rt_v3(cx + r * x, cy + r * y, 5), rt_v3(0, 0, -1), i).y;
        sum += L;
        sum2 += L * L;
        hits++;
    }
    double mean = sum / hits, v = fmax(0.0, sum2 / hits - mean * mean);
    if (se)
        *se = sqrt(v / hits);
    if (var)
        *var = v;
    return mean;
}

/* Glass spheres in a white furnace (radiance 1 all round, no absorption):
 * smooth glass returns exactly 1 for every rr_depth; rough dense glass
 * (index 2.4, alpha 0.5, single scattering loses energy) gives the same
 * mean with the roulette as without it (rr_depth 1024), within 4 standard
 * errors. */
static void test_glass_furnace_unbiased(void **state)
{
    (void)state;
    const int rr[] = {0, 1, 3, 5};
    for (int k = 0; k < 4; k++) {
        char text[256];
        snprintf(text, sizeof text,
                 "integrator path\nbackground 1 1 1\nrr_depth %d\nmaterial g bsdf dielectric ior 1.5\n"
                 "sphere 0 0 0 1 g\n",
                 rr[k]);
        fixture f;
        test_fixture_load(&f, text, 0);
        double se, mean = mean_over_disk(&f, 0, 0, 1, 20000, 11, &se, NULL);
        if (fabs(mean - 1.0) > 4.0 * se + 1e-3)
            fail_msg("smooth glass furnace, rr_depth %d: %.5f +- %.5f, want 1", rr[k], mean, se);
        test_fixture_free(&f);
    }
    double se0, mean0 = 0.0;
    for (int k = -1; k < 4; k++) {
        char text[256];
        snprintf(text, sizeof text,
                 "integrator path\nbackground 1 1 1\nrr_depth %d\nmaterial g bsdf dielectric ior 2.4 ggx_alpha 0.5\n"
                 "sphere 0 0 0 1 g\n",
                 k < 0 ? 1024 : rr[k]);
        fixture f;
        test_fixture_load(&f, text, 0);
        double se, mean = mean_over_disk(&f, 0, 0, 1, 80000, 12 + (uint64_t)k, &se, NULL);
        fprintf(stderr, "rough dense glass furnace, rr_depth %d: %.5f +- %.5f\n", k < 0 ? 1024 : rr[k], mean, se);
        if (k < 0) {
            mean0 = mean;
            se0 = se;
        } else if (fabs(mean - mean0) > 4.0 * sqrt(se * se + se0 * se0) + 1e-3) {
            fail_msg("rough glass furnace, rr_depth %d: %.5f +- %.5f, without roulette %.5f +- %.5f", rr[k], mean,
                     se, mean0, se0);
        }
        test_fixture_free(&f);
    }
}

/* ------------------------------------------------------------- variance */

/* Per-sample variance, fixed seeds (measured before issue 30 -> after):
 *   - the smooth glass furnace returns exactly 1 on every path without
 *     roulette; with it, rr_depth 0 (adaptive): 1.17 -> 0 (the weight never
 *     falls below 1), rr_depth 1: 1.29 -> 0.108 (only the 0.95 cap plays);
 *   - a smooth glass ball (index 1.5) on a white Lambertian floor before a
 *     wall, under an area light, rays at the ball: the variance over the
 *     same scene without roulette (0.737), rr_depth 5: 1.75x -> 1.17x,
 *     adaptive: 1.71x -> 1.21x.
 * The bounds (0.3, 1.4x) sit between the two. */
static void test_glass_variance_falls(void **state)
{
    (void)state;
    const int rr_furnace[] = {0, 1};
    const double bound_furnace[] = {1e-6, 0.3};
    for (int k = 0; k < 2; k++) {
        char text[256];
        snprintf(text, sizeof text,
                 "integrator path\nbackground 1 1 1\nrr_depth %d\nmaterial g bsdf dielectric ior 1.5\n"
                 "sphere 0 1 0 1 g\n",
                 rr_furnace[k]);
        fixture f;
        test_fixture_load(&f, text, 0);
        double var;
        mean_over_disk(&f, 0, 1, 1, 20000, 77, NULL, &var);
        fprintf(stderr, "smooth glass furnace, rr_depth %d: variance %.6f (bound %g)\n", rr_furnace[k], var,
                bound_furnace[k]);
        if (!(var < bound_furnace[k]))
            fail_msg("smooth glass furnace, rr_depth %d: variance %.6f, bound %g", rr_furnace[k], var,
                     bound_furnace[k]);
        test_fixture_free(&f);
    }
    const int rr[] = {1024, 5, 0};
    const double bound[] = {0.0, 1.4, 1.4}; /* of the variance without roulette */
    double var0 = 0.0;
    for (int k = 0; k < 3; k++) {
        char text[512];
        snprintf(text, sizeof text,
                 "integrator path\nbackground 0 0 0\nrr_depth %d\nmaterial g bsdf dielectric ior 1.5\n"
                 "material w color 0.8 0.8 0.8 bsdf lambert\n"
                 "quad -5 0 -5  0 0 10  10 0 0  w\nquad -5 0 -3  10 0 0  0 8 0  w\n"
                 "sphere 0 1 0 1 g\nlight area -0.5 3.5 -0.5  1 0 0  0 0 1  1 1 1 20\n",
                 rr[k]);
        fixture f;
        test_fixture_load(&f, text, RT_PREPARE_LIGHT_TABLE);
        double var;
        mean_over_disk(&f, 0, 1, 1, 40000, 77, NULL, &var);
        if (k == 0)
            var0 = var;
        fprintf(stderr, "glass ball on a floor, rr_depth %d: variance %.5f (%.3fx no roulette)\n", rr[k], var,
                var / var0);
        if (k > 0 && !(var < bound[k] * var0))
            fail_msg("glass ball, rr_depth %d: variance %.5f, %.3fx no roulette's %.5f, bound %.2fx", rr[k], var,
                     var / var0, var0, bound[k]);
        test_fixture_free(&f);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_probability_inside_dense_dielectric),
        cmocka_unit_test(test_eta_scale_follows_media),
        cmocka_unit_test(test_glass_furnace_unbiased),
        cmocka_unit_test(test_glass_variance_falls),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
