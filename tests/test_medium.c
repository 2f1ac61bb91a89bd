/* test_medium.c - nested dielectrics (rt/render/medium.h) by their rules and
 * through the path tracer against closed forms:
 *   - the stack's rules one by one: the current medium by priority (ties:
 *     the last entered), false intersections entering a lower-priority
 *     medium or leaving a non-current one, the index beyond an interface,
 *     overflow (the oldest entry dropped) and underflow (leaving a medium
 *     the stack does not hold: a true exit, nothing removed);
 *   - a water ball (ior 1.333) inside a glass ball (ior 1.5, index-matched
 *     to the outside so its own surface is invisible) with absorbing water:
 *     a camera ray at offset x meets the water at incidence sin = x and
 *     sees exactly the exact Fresnel reflectance between 1.5 and 1.333,
 *     from normal incidence to past the critical angle (F = 1), not the
 *     water-air value; with the water's priority below the glass's, the
 *     water's surface is a false intersection and the ray passes;
 *   - absorption only where each medium is: a coloured liquid ball inside
 *     an absorbing glass ball, and a liquid overlapping a clear glass of
 *     higher priority (the overlap is glass), along straight
 *     (index-matched) chords, against exp(-sum sigma_i d_i);
 *   - ten nested absorbing shells (more than the stack holds) along a
 *     diameter: overflow and underflow together still give the exact
 *     transmittance;
 *   - `whitted` under the same rules: the water ball in the glass ball
 *     reflects exactly the Fresnel reflectance between 1.5 and 1.333 (its
 *     refracted light is cut by a black transmission colour, so the image
 *     is that reflectance, deterministically), and with the water's
 *     priority below the glass's the ray passes untouched.
 */
#include "test_util.h"
#include "test_fixture.h"

#include <math.h>

#include "rt/accel/kdtree.h"
#include "rt/io/scene_parse.h"
#include "rt/render/bsdf.h"
#include "rt/render/medium.h"
#include "rt/render/pathtrace.h"
#include "rt/render/whitted.h"
#include "rt/scene/scene.h"

typedef test_fixture fixture; /* test_fixture.h */

static void load(fixture *f, const char *text) { test_fixture_load(f, text, 0); }

static void unload(fixture *f) { test_fixture_free(f); }

/* The path tracer's radiance (test_fixture_path_radiance) with this file's seed. */
static rt_vec3 radiance(const fixture *f, rt_vec3 org, rt_vec3 dir, uint32_t i)
{
    return test_fixture_path_radiance(f, 29, org, dir, i);
}

/* Exact unpolarised Fresnel reflectance in double precision, n1 -> n2. */
static double fresnel_d(double cos_i, double n1, double n2)
{
    double eta = n1 / n2, s2 = eta * eta * (1.0 - cos_i * cos_i);
    if (s2 >= 1.0)
        return 1.0;
    double ct = sqrt(1.0 - s2);
    double rs = (n1 * cos_i - n2 * ct) / (n1 * cos_i + n2 * ct);
    double rp = (n1 * ct - n2 * cos_i) / (n1 * ct + n2 * cos_i);
    return 0.5 * (rs * rs + rp * rp);
}

/* ------------------------------------------------------------ the rules */

static void test_stack_rules(void **state)
{
    (void)state;
    rt_material mats[7];
    const float ior[] = {1.5f, 1.333f, 1.31f, 1.2f, 1.4f, 1.6f, 1.0f};
    const int prio[] = {2, 1, 3, 1, 0, 0, 0};
    for (int i = 0; i < 7; i++) {
        rt_material_default(&mats[i], "m");
        mats[i].bsdf = i == 6 ? RT_BSDF_LAMBERT : RT_BSDF_DIELECTRIC;
        mats[i].ior = ior[i];
        mats[i].priority = prio[i];
    }
    enum { GLASS, WATER, ICE, B, C, D, PAINT };
    rt_medium_stack st;
    rt_medium_stack_init(&st);
    assert_int_equal(rt_medium_current(&st, mats), RT_NONE);
    /* outside: every object's own exterior index; nothing is false */
    assert_false(rt_medium_false_hit(&st, mats, WATER, true));
    assert_true(rt_medium_outside_ior(&st, mats, GLASS, true) == 1.0f);
    /* the glass, then the water inside its wall: a false hit */
    rt_medium_cross(&st, mats, GLASS, true);
    assert_int_equal(rt_medium_current(&st, mats), GLASS);
    assert_true(rt_medium_false_hit(&st, mats, WATER, true));
    rt_medium_cross(&st, mats, WATER, true);
    assert_int_equal(rt_medium_current(&st, mats), GLASS);
    /* leaving the glass into the water: true, the water's index beyond */
    assert_false(rt_medium_false_hit(&st, mats, GLASS, false));
    assert_true(rt_medium_outside_ior(&st, mats, GLASS, false) == 1.333f);
    rt_medium_cross(&st, mats, GLASS, false);
    assert_int_equal(rt_medium_current(&st, mats), WATER);
    /* ice (higher priority) in the water: true, water's index outside it */
    assert_false(rt_medium_false_hit(&st, mats, ICE, true));
    assert_true(rt_medium_outside_ior(&st, mats, ICE, true) == 1.333f);
    rt_medium_cross(&st, mats, ICE, true);
    assert_int_equal(rt_medium_current(&st, mats), ICE);
    /* leaving the water while in the ice: false; leaving the ice: true */
    assert_true(rt_medium_false_hit(&st, mats, WATER, false));
    assert_false(rt_medium_false_hit(&st, mats, ICE, false));
    assert_true(rt_medium_outside_ior(&st, mats, ICE, false) == 1.333f);
    /* equal priorities: the last entered is current, leaving the other is false */
    rt_medium_stack_init(&st);
    rt_medium_cross(&st, mats, C, true);
    assert_false(rt_medium_false_hit(&st, mats, D, true));
    assert_true(rt_medium_outside_ior(&st, mats, D, true) == 1.4f);
    rt_medium_cross(&st, mats, D, true);
    assert_int_equal(rt_medium_current(&st, mats), D);
    assert_true(rt_medium_false_hit(&st, mats, C, false));
    assert_false(rt_medium_false_hit(&st, mats, D, false));
    /* a non-medium is never false and never recorded */
    assert_false(rt_medium_false_hit(&st, mats, PAINT, true));
    rt_medium_cross(&st, mats, PAINT, true);
    assert_int_equal(st.depth, 2);
    /* underflow: leaving what is not on the stack is a true exit, the
     * segment ran inside it, nothing is removed */
    assert_false(rt_medium_false_hit(&st, mats, GLASS, false));
    assert_int_equal(rt_medium_of_segment(&st, mats, GLASS, false), GLASS);
    assert_true(rt_medium_outside_ior(&st, mats, GLASS, false) == 1.6f);
    rt_medium_cross(&st, mats, GLASS, false);
    assert_int_equal(st.depth, 2);
    rt_medium_stack_init(&st);
    rt_medium_cross(&st, mats, GLASS, false);
    assert_int_equal(st.depth, 0);
    /* overflow: the oldest entry goes, the newest are kept in order */
    enum { N = RT_MEDIUM_STACK_MAX + 3 };
    const uint32_t kinds[] = {GLASS, WATER, B, C, D, ICE};
    uint32_t seq[N];
    for (int i = 0; i < N; i++) {
        seq[i] = kinds[i % 6];
        rt_medium_cross(&st, mats, seq[i], true);
    }
    assert_int_equal(st.depth, RT_MEDIUM_STACK_MAX);
    for (int i = 0; i < RT_MEDIUM_STACK_MAX; i++)
        assert_int_equal(st.material[i], seq[N - RT_MEDIUM_STACK_MAX + i]);
    assert_int_equal(rt_medium_current(&st, mats), ICE);
}

/* ------------------------------------------------- through the integrator */

/* Reflectance at a water ball inside glass: the only light reaching the
 * camera is what the water surface reflects (the water swallows the rest;
 * the glass is index-matched to the outside, so its surface does nothing). */
static void test_glass_of_water_fresnel(void **state)
{
    (void)state;
    fixture f;
    load(&f, "integrator path\nrr_depth 64\nbackground 1 1 1\n"
             "material glass bsdf dielectric ior 1.5 exterior_ior 1.5 priority 1\n"
             "material water bsdf dielectric ior 1.333 priority 2 absorption 1e4 1e4 1e4\n"
             "sphere 0 0 0 2 glass\nsphere 0 0 0 1 water\n");
    const float sines[] = {0.0f, 0.5f, 0.8f, 0.87f, 0.95f};
    for (int k = 0; k < 5; k++) {
        double c = sqrt(1.0 - (double)sines[k] * sines[k]);
        double want = fresnel_d(c, 1.5, 1.333), air = fresnel_d(c, 1.0, 1.333);
        const uint32_t n = 20000;
        double sum = 0.0;
        for (uint32_t i = 0; i < n; i++)
            sum += radiance(&f, rt_v3(sines[k], 0, 5), rt_v3(0, 0, -1), i).y;
        double mean = sum / n, sigma = sqrt(fmax(want * (1.0 - want), 1e-8) / n);
        fprintf(stderr, "water in glass, sin %.2f: %.5f, Fresnel 1.5/1.333 %.5f (water in air %.5f)\n",
                (double)sines[k], mean, want, air);
        if (fabs(mean - want) > 5.0 * sigma + 1e-4)
            fail_msg("sin %.2f: reflectance %.5f, want %.5f", (double)sines[k], mean, want);
        /* not the water-air interface: nearer the glass-water value (at sin
         * 0.8 the two are 9.2 sigma apart, so "10 sigma from air" failed
         * for an exact mean and passed only by the noise) */
        assert_true(k == 4 || fabs(mean - air) > 0.5 * fabs(want - air));
    }
    unload(&f);
    /* the water's priority below the glass's: its surface is false, the
     * glass (clear) fills the ball and the ray passes untouched */
    load(&f, "integrator path\nrr_depth 64\nbackground 1 1 1\n"
             "material glass bsdf dielectric ior 1.5 exterior_ior 1.5 priority 2\n"
             "material water bsdf dielectric ior 1.333 priority 1 absorption 1e4 1e4 1e4\n"
             "sphere 0 0 0 2 glass\nsphere 0 0 0 1 water\n");
    for (uint32_t i = 0; i < 16; i++) {
        rt_vec3 L = radiance(&f, rt_v3(0.06f * (float)i, 0.01f, 5), rt_v3(0, 0, -1), i);
        assert_true(fabsf(L.x - 1.0f) < 1e-5f && fabsf(L.z - 1.0f) < 1e-5f);
    }
    unload(&f);
}

static void check_transmittance(const fixture *f, float x, const double want[3])
{
    rt_vec3 L = radiance(f, rt_v3(x, 0, 5), rt_v3(0, 0, -1), 1);
    const float *l = &L.x;
    for (int c = 0; c < 3; c++)
        if (fabs(l[c] - want[c]) > 2e-4 * fmax(want[c], 0.05))
            fail_msg("x %.2f channel %d: transmittance %.6f, want %.6f", (double)x, c, (double)l[c], want[c]);
}

static void test_absorption_where_each_medium_is(void **state)
{
    (void)state;
    const double sl[3] = {0.1, 0.6, 1.5}, sg[3] = {0.2, 0.05, 0.0};
    fixture f;
    /* a liquid ball (higher priority) inside an absorbing glass ball */
    load(&f, "integrator path\nrr_depth 64\nbackground 1 1 1\n"
             "material glass bsdf dielectric ior 1.5 exterior_ior 1.5 priority 1 absorption 0.2 0.05 0\n"
             "material tea bsdf dielectric ior 1.5 priority 2 absorption 0.1 0.6 1.5\n"
             "sphere 0 0 0 2 glass\nsphere 0 0 0 1 tea\n");
    for (int i = 0; i < 10; i++) {
        double x = 0.19 * i, hl = x < 1.0 ? sqrt(1.0 - x * x) : 0.0, hg = sqrt(4.0 - x * x);
        double want[3];
        for (int c = 0; c < 3; c++)
            want[c] = exp(-sg[c] * (2.0 * hg - 2.0 * hl) - sl[c] * 2.0 * hl);
        check_transmittance(&f, (float)x, want);
    }
    unload(&f);
    /* a liquid overlapping a clear glass of higher priority: only the part
     * outside the glass absorbs */
    load(&f, "integrator path\nrr_depth 64\nbackground 1 1 1\n"
             "material glass bsdf dielectric ior 1.5 exterior_ior 1.5 priority 2\n"
             "material tea bsdf dielectric ior 1.5 exterior_ior 1.5 priority 1 absorption 0.1 0.6 1.5\n"
             "sphere 0 0 0 1 glass\nsphere 0 0 -1.5 1 tea\n");
    for (int i = 0; i < 8; i++) {
        double x = 0.12 * i, h = sqrt(1.0 - x * x), d = 2.0 * h - fmax(0.0, 2.0 * h - 1.5);
        double want[3];
        for (int c = 0; c < 3; c++)
            want[c] = exp(-sl[c] * d);
        check_transmittance(&f, (float)x, want);
    }
    unload(&f);
}

/* Ten concentric absorbing balls, priorities rising inwards: the stack
 * overflows on the way in and underflows on the way out, and the
 * transmittance along a diameter is still exp(-2 sum sigma_i (R_i - R_{i-1})). */
static void test_overflow_underflow_exact(void **state)
{
    (void)state;
    char text[4096] = "integrator path\nrr_depth 64\nbackground 1 1 1\n";
    double want = 0.0;
    for (int i = 1; i <= 10; i++) {
        double sigma = 0.02 * i;
        char line[256];
        snprintf(line, sizeof line,
                 "material m%d bsdf dielectric ior 1.5 exterior_ior 1.5 priority %d absorption %g %g %g\n"
                 "sphere 0 0 0 %d m%d\n",
                 i, 20 - i, sigma, sigma, sigma, i, i);
        strcat(text, line);
        want += 2.0 * sigma;
    }
    fixture f;
    load(&f, text);
    rt_vec3 L = radiance(&f, rt_v3(0, 0, 15), rt_v3(0, 0, -1), 3);
    fprintf(stderr, "ten nested shells: %.6f, want %.6f\n", (double)L.y, exp(-want));
    assert_true(fabs(L.y - exp(-want)) < 1e-4);
    unload(&f);
}

/* The glass of water for `whitted`: every transmissive material is a
 * medium of its stack, under the path tracer's priority rules. */
static void test_whitted_glass_of_water(void **state)
{
    (void)state;
    fixture f;
    load(&f, "integrator whitted\nmax_bounce 8\nbackground 1 1 1\n"
             "material glass bsdf dielectric ior 1.5 exterior_ior 1.5 priority 1\n"
             "material water bsdf dielectric ior 1.333 priority 2 transmission_color 0 0 0\n"
             "sphere 0 0 0 2 glass\nsphere 0 0 0 1 water\n");
    const float sines[] = {0.0f, 0.5f, 0.8f, 0.87f, 0.95f};
    for (int k = 0; k < 5; k++) {
        double c = sqrt(1.0 - (double)sines[k] * sines[k]);
        double want = fresnel_d(c, 1.5, 1.333), air = fresnel_d(c, 1.0, 1.333);
        rt_rng rng = rt_rng_for_sample(29, (uint32_t)k, 0);
        rt_ray r = rt_ray_make(rt_v3(sines[k], 0, 5), rt_v3(0, 0, -1), 0.0f, INFINITY);
        rt_vec3 L = rt_radiance_whitted(&f.ctx, &r, &rng);
        fprintf(stderr, "whitted, water in glass, sin %.2f: %.5f, Fresnel 1.5/1.333 %.5f (water in air %.5f)\n",
                (double)sines[k], (double)L.y, want, air);
        if (fabs(L.y - want) > 2e-4 || fabs(L.x - L.y) > 1e-6 || fabs(L.z - L.y) > 1e-6)
            fail_msg("sin %.2f: reflectance %.5f, want %.5f", (double)sines[k], (double)L.y, want);
        assert_true(k == 4 || fabs(L.y - air) > 0.01); /* not the water-air interface */
    }
    unload(&f);
    /* the water's priority below the glass's: its surface is false, the
     * clear glass fills the ball and the ray passes untouched */
    load(&f, "integrator whitted\nmax_bounce 8\nbackground 1 1 1\n"
             "material glass bsdf dielectric ior 1.5 exterior_ior 1.5 priority 2\n"
             "material water bsdf dielectric ior 1.333 priority 1 transmission_color 0 0 0\n"
             "sphere 0 0 0 2 glass\nsphere 0 0 0 1 water\n");
    for (uint32_t i = 0; i < 16; i++) {
        rt_rng rng = rt_rng_for_sample(29, i, 0);
        rt_ray r = rt_ray_make(rt_v3(0.06f * (float)i, 0.01f, 5), rt_v3(0, 0, -1), 0.0f, INFINITY);
        rt_vec3 L = rt_radiance_whitted(&f.ctx, &r, &rng);
        if (fabsf(L.x - 1.0f) > 1e-5f || fabsf(L.y - 1.0f) > 1e-5f || fabsf(L.z - 1.0f) > 1e-5f)
            fail_msg("x %.2f: %.6f %.6f %.6f, want the background 1 untouched", 0.06 * i, (double)L.x,
                     (double)L.y, (double)L.z);
    }
    unload(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stack_rules),
        cmocka_unit_test(test_glass_of_water_fresnel),
        cmocka_unit_test(test_absorption_where_each_medium_is),
        cmocka_unit_test(test_overflow_underflow_exact),
        cmocka_unit_test(test_whitted_glass_of_water),
    };
    return cmocka_run_group_tests_name("medium", tests, NULL, NULL);
}
