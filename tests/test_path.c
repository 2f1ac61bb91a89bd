/* test_path.c - the path integrator against closed forms and against the
 * shared Mitsuba 3 reference:
 *   - white furnace: a convex Lambertian object in a uniform environment of
 *     radiance 1 shows exactly its albedo (every path escapes after one
 *     bounce), sample by sample; a GGX metal shows its directional albedo
 *     (a 1D quadrature here), never more than 1;
 *   - inside a closed emissive Lambertian sphere (emission E, albedo a)
 *     L = E (1 + a + ... + a^k) = E (1 - a^(k+1)) / (1 - a) with max_depth
 *     k, and E / (1 - a) unlimited: Russian roulette is unbiased, and with
 *     the emitter table (light sampling + MIS) the value is the same as
 *     without (nothing counted twice);
 *   - a point light over a Lambertian floor: exactly a I cos / (pi r^2);
 *   - one-sided area lights: the front shows the radiance, the back nothing;
 *   - an emissive quad made of two triangles lights a floor like the same
 *     area light, with and without the table;
 *   - a floor lit through a smooth thin-walled pane: light sampling through
 *     it (emitters, an area light, the environment) gives the mean of BSDF
 *     sampling alone, with less noise; under an unbounded pane in a uniform
 *     sky the floor shows the closed form a t / (1 - a r);
 *   - every sample finite on a scene of every material kind, and the image
 *     identical for 1 and 3 threads;
 *   - scenes/cornell-reference.txt at 64x64 against the reference image
 *     box-averaged over 8x8 blocks: image means within 1%, RMSE bounded.
 */
#include "test_util.h"
#include "test_fixture.h"
#include "test_scenes.h"

#include <math.h>

#include "rt/render/bsdf.h"
#include "rt/render/camera.h"
#include "rt/image/framebuffer.h"
#include "rt/render/integrator.h"
#include "rt/render/light.h"
#include "rt/accel/kdtree.h"
#include "rt/render/ggx_albedo.h"
#include "rt/render/pathtrace.h"
#include "rt/render/render.h"
#include "rt/scene/scene.h"
#include "rt/io/scene_parse.h"
#include "rt/scene/texture.h"

typedef test_fixture fixture; /* test_fixture.h */

static void load(fixture *f, const char *text, bool table)
{
    test_fixture_load(f, text, table ? RT_PREPARE_LIGHT_TABLE : 0);
}

static void unload(fixture *f) { test_fixture_free(f); }

/* The path tracer's radiance (test_fixture_path_radiance) with this file's seed. */
static rt_vec3 radiance(const fixture *f, rt_vec3 org, rt_vec3 dir, uint32_t i)
{
    return test_fixture_path_radiance(f, 17, org, dir, i);
}

/* Channel c (0, 1, 2) of v. */
static double channel(rt_vec3 v, int c) { return c == 0 ? v.x : c == 1 ? v.y : v.z; }

/* The mean of channel c of the radiance along -z from n points (x, y, 5),
 * x and y uniform in [-w/2, w/2] (the test stream seeded `seed`). */
static double mean_over_square(const fixture *f, uint32_t n, uint64_t seed, float w, int c)
{
    double sum = 0.0;
    test_rng tr = {seed};
    for (uint32_t i = 0; i < n; i++) {
        float x = w * test_rng_float(&tr) - 0.5f * w, y = w * test_rng_float(&tr) - 0.5f * w;
        sum += channel(radiance(f, rt_v3(x, y, 5), rt_v3(0, 0, -1), i), c);
    }
    return sum / n;
}

/* The same from n points of [-1, 1]^2, of which only those with
 * x^2 + y^2 <= 0.98 count: a unit sphere at the origin without its
 * silhouette. *se (when not NULL): the standard error of the mean. */
static double mean_over_sphere_disk(const fixture *f, uint32_t n, uint64_t seed, int c, double *se)
{
    double sum = 0.0, sum2 = 0.0;
    test_rng tr = {seed};
    uint32_t hits = 0;
    for (uint32_t i = 0; i < n; i++) {
        float x = 2.0f * test_rng_float(&tr) - 1.0f, y = 2.0f * test_rng_float(&tr) - 1.0f;
        if (x * x + y * y > 0.98f)
            continue; /* the sphere only */
        double L = channel(radiance(f, rt_v3(x, y, 5), rt_v3(0, 0, -1), i), c);
        sum += L;
        sum2 += L * L;
        hits++;
    }
    double mean = sum / hits;
    if (se)
        *se = sqrt(fmax(0.0, sum2 / hits - mean * mean) / hits);
    return mean;
}

/* Inside a closed sphere around the origin: the mean red radiance over n
 * rays from (0.1, -0.2, 0.3) in random directions (the test stream seeded
 * `seed`), and its standard error in *sd. */
static double mean_inside_sphere(const fixture *f, uint32_t n, uint64_t seed, double *sd)
{
    double sum = 0.0, sum2 = 0.0;
    test_rng tr = {seed};
    for (uint32_t i = 0; i < n; i++) {
        rt_vec3 dir = rt_v3(test_rng_float(&tr) - 0.5f, test_rng_float(&tr) - 0.5f, test_rng_float(&tr) - 0.5f);
        if (rt_length2(dir) < 1e-6f)
            dir = rt_v3(0, 0, 1);
        double L = radiance(f, rt_v3(0.1f, -0.2f, 0.3f), dir, i).x;
        sum += L;
        sum2 += L * L;
    }
    double mean = sum / n;
    *sd = sqrt(fmax(0.0, sum2 / n - mean * mean) / n);
    return mean;
}

/* ------------------------------------------------------------- furnaces */

static void test_furnace_lambert(void **state)
{
    (void)state;
    const float albedo[][3] = {{1, 1, 1}, {0.5f, 0.8f, 0.2f}};
    for (int k = 0; k < 2; k++) {
        char text[512];
        snprintf(text, sizeof text,
                 "integrator path\nbackground 1 1 1\n"
                 "material m color %g %g %g bsdf lambert\nsphere 0 0 0 1 m\n",
                 (double)albedo[k][0], (double)albedo[k][1], (double)albedo[k][2]);
        fixture f;
        load(&f, text, false);
        test_rng tr = {5};
        for (uint32_t i = 0; i < 4000; i++) {
            /* rays from outside at random points of the disk the sphere covers */
            float x = 1.8f * test_rng_float(&tr) - 0.9f, y = 1.8f * test_rng_float(&tr) - 0.9f;
            rt_vec3 L = radiance(&f, rt_v3(x, y, 5), rt_v3(0, 0, -1), i);
            bool hit = x * x + y * y < 0.99f;
            rt_vec3 want = hit ? rt_v3(albedo[k][0], albedo[k][1], albedo[k][2]) : rt_v3s(1.0f);
            if (x * x + y * y > 0.97f && x * x + y * y < 1.01f)
                continue; /* the silhouette */
            assert_true(fabsf(L.x - want.x) < 1e-5f && fabsf(L.y - want.y) < 1e-5f && fabsf(L.z - want.z) < 1e-5f);
        }
        unload(&f);
    }
}

/* Directional albedo at normal incidence of a white GGX metal, by the 1D
 * integral over cos(theta_i) of D(h) G2 / (4 cos_i) cos_i (h = half vector). */
static double metal_albedo_normal(float alpha)
{
    const int n = 200000;
    double sum = 0.0;
    for (int i = 0; i < n; i++) {
        float ci = ((float)i + 0.5f) / (float)n;
        float s = sqrtf(1.0f - ci * ci);
        rt_vec3 wi = rt_v3(s, 0.0f, ci), wo = rt_v3(0, 0, 1);
        rt_vec3 h = rt_normalize(rt_add(wi, wo));
        sum += (double)rt_ggx_d(h, alpha) * (double)rt_ggx_g2(wo, wi, alpha) / 4.0;
    }
    return 2.0 * 3.14159265358979 * sum / n;
}

static void test_furnace_metal(void **state)
{
    (void)state;
    const float rough[] = {0.3f, 0.5f, 0.8f};
    for (int k = 0; k < 3; k++) {
        char text[512];
        snprintf(text, sizeof text,
                 "integrator path\nbackground 1 1 1\n"
                 "material m color 1 1 1 metallic 1 roughness %g\nsphere 0 0 0 1 m\n",
                 (double)rough[k]);
        fixture f;
        load(&f, text, false);
        double sum = 0.0;
        const uint32_t n = 40000;
        for (uint32_t i = 0; i < n; i++) {
            rt_vec3 L = radiance(&f, rt_v3(0, 0, 5), rt_v3(0, 0, -1), i);
            /* VNDF sampling of F = 1: each sample weighs G2 / G1 <= 1 */
            assert_true(L.x <= 1.0f + 1e-5f);
            sum += L.x;
        }
        double mean = sum / n, want = metal_albedo_normal(rough[k] * rough[k]);
        assert_true(want < 1.0 && want > 0.5);
        if (fabs(mean - want) > 0.01)
            fail_msg("roughness %g: furnace %.4f, quadrature %.4f", (double)rough[k], mean, want);
        unload(&f);
    }
}

/* A closed glass sphere (base 1, transmission 1, ior 1.5) in a uniform
 * environment of radiance 1: every path leaves sooner or later, so the
 * mean is the fraction of energy the model keeps: 1 for smooth glass, less
 * when rough. The dielectric albedo table (single-scattering rough glass,
 * tools/ggx_albedo.c) gives the expected values apart from the path tracer:
 * the energy kept at entry, E(mu, alpha, 1/1.5) averaged over the rays'
 * entry cosines, bounds the mean from above (every later interaction only
 * loses), and one entry times one interaction from inside, at the
 * hemispherical average E_avg(alpha, 1.5), is the first-order value: the
 * light reflected at entry loses less, further bounces inside lose more
 * (measured within 0.015 of it). */
static void test_furnace_glass(void **state)
{
    (void)state;
    const float rough[] = {0.0f, 0.3f, 0.6f};
    for (int k = 0; k < 3; k++) {
        char text[512];
        snprintf(text, sizeof text,
                 "integrator path\nbackground 1 1 1\n"
                 "material m color 1 1 1 transmission 1 ior 1.5 roughness %g\nsphere 0 0 0 1 m\n",
                 (double)rough[k]);
        fixture f;
        load(&f, text, false);
        double mean = mean_over_square(&f, 20000, 21, 1.4f, 0);
        float alpha = rough[k] * rough[k];
        double entry = 0.0; /* E at entry over the square's rays (all of which meet the sphere) */
        for (int i = 0; i < 200; i++)
            for (int j = 0; j < 200; j++) {
                double x = 1.4 * ((i + 0.5) / 200 - 0.5), y = 1.4 * ((j + 0.5) / 200 - 0.5);
                entry += rt_ggx_dielectric_albedo((float)sqrt(1.0 - x * x - y * y), alpha, 1.0f / 1.5f) / 40000.0;
            }
        double first_order = entry * rt_ggx_dielectric_albedo_avg(alpha, 1.5f);
        fprintf(stderr, "glass furnace, roughness %.1f: %.4f; the table: at most %.4f, first order %.4f\n",
                (double)rough[k], mean, entry, first_order);
        double tol = alpha == 0.0f ? 0.002 : 0.04; /* smooth: nothing is lost, the first order is exact */
        if (mean > entry + 0.01 || fabs(mean - first_order) > tol)
            fail_msg("roughness %.1f: glass furnace %.4f; the albedo table bounds it by %.4f, first order %.4f",
                     (double)rough[k], mean, entry, first_order);
        unload(&f);
    }
}

/* White furnace of a white rough conductor (F = 1) through the path
 * tracer: with energy_compensation on, a convex sphere under a uniform sky
 * of radiance 1 shows 1 (within 2%) at every alpha; off, it shows the
 * single-scattering albedo, which loses up to about 60% at alpha 1. */
static void test_furnace_energy_compensation(void **state)
{
    (void)state;
    const float alphas[] = {0.1f, 0.5f, 1.0f};
    for (int k = 0; k < 3; k++) {
        double mean[2];
        for (int on = 0; on < 2; on++) {
            char text[512];
            snprintf(text, sizeof text,
                     "integrator path\nbackground 1 1 1\nenergy_compensation %s\n"
                     "material m bsdf conductor eta 0 0 0 k 1 1 1 ggx_alpha %g\nsphere 0 0 0 1 m\n",
                     on ? "on" : "off", (double)alphas[k]);
            fixture f;
            load(&f, text, false);
            mean[on] = mean_over_sphere_disk(&f, 20000, 33, 1, NULL);
            unload(&f);
        }
        fprintf(stderr, "white metal furnace, alpha %.1f: %.4f single scattering, %.4f compensated\n",
                (double)alphas[k], mean[0], mean[1]);
        if (fabs(mean[1] - 1.0) > 0.02)
            fail_msg("alpha %.1f: compensated furnace %.4f", (double)alphas[k], mean[1]);
        assert_true(mean[0] < mean[1] - 0.005);
        if (k == 2)
            assert_true(mean[0] < 0.7); /* the energy single scattering loses at alpha 1 */
    }
}

/* White furnace of rough glass (bsdf dielectric, no absorption) through
 * the path tracer: a sphere under a uniform sky of radiance 1 shows 1 when
 * nothing is lost. Single scattering loses the light a microfacet sends
 * back to the side it came from, most of it inside the sphere (measured
 * 0.94 / 0.56 / 0.34 at alpha 0.1 / 0.5 / 1, index 1.5); with
 * energy_compensation on, Kulla and Conty's lobe (docs/shading.md,
 * section 14) puts it back: 1 within 2% (or 3 standard errors, when the
 * rough glass's rare heavy paths make the estimate noisier) at alpha 0.1,
 * 0.5, 1 and index 1.5 and 1.33. */
static void test_furnace_glass_compensation(void **state)
{
    (void)state;
    const float alphas[] = {0.1f, 0.5f, 1.0f}, iors[] = {1.5f, 1.33f};
    for (int e = 0; e < 2; e++) {
        for (int k = 0; k < 3; k++) {
            double mean[2], se[2];
            for (int on = 0; on < 2; on++) {
                char text[512];
                snprintf(text, sizeof text,
                         "integrator path\nbackground 1 1 1\nenergy_compensation %s\n"
                         "material g bsdf dielectric ior %g ggx_alpha %g\nsphere 0 0 0 1 g\n",
                         on ? "on" : "off", (double)iors[e], (double)alphas[k]);
                fixture f;
                load(&f, text, false);
                mean[on] = mean_over_sphere_disk(&f, on ? 400000 : 40000, 41, 1, &se[on]);
                unload(&f);
            }
            fprintf(stderr,
                    "glass furnace, ior %.2f alpha %.1f: %.4f +- %.4f single scattering, %.4f +- %.4f compensated\n",
                    (double)iors[e], (double)alphas[k], mean[0], se[0], mean[1], se[1]);
            if (fabs(mean[1] - 1.0) > fmax(0.02, 3.0 * se[1]))
                fail_msg("ior %.2f alpha %.1f: compensated glass furnace %.4f +- %.4f", (double)iors[e],
                         (double)alphas[k], mean[1], se[1]);
            assert_true(mean[0] < mean[1]);
        }
    }
}

/* A smooth gold sphere in a uniform environment of radiance 1: every
 * camera ray reflects once off the convex sphere and leaves, so a ray
 * meeting it at incidence cosine c sees exactly F_conductor(c) per
 * channel. */
static void test_smooth_conductor_sphere(void **state)
{
    (void)state;
    fixture f;
    load(&f, "integrator path\nbackground 1 1 1\nmaterial au bsdf conductor metal Au ggx_alpha 0\n"
             "sphere 0 0 0 1 au\n", false);
    for (int i = 0; i < 9; i++) {
        float x = 0.1f * (float)i;
        rt_vec3 L = radiance(&f, rt_v3(x, 0, 5), rt_v3(0, 0, -1), (uint32_t)i);
        rt_vec3 F = rt_fresnel_conductor(sqrtf(1.0f - x * x), rt_metals[1].eta, rt_metals[1].k);
        if (fabsf(L.x - F.x) > 2e-4f || fabsf(L.y - F.y) > 2e-4f || fabsf(L.z - F.z) > 2e-4f)
            fail_msg("x %.1f: L (%.5f %.5f %.5f), F (%.5f %.5f %.5f)", (double)x, (double)L.x, (double)L.y,
                     (double)L.z, (double)F.x, (double)F.y, (double)F.z);
    }
    unload(&f);
}

/* bsdf dielectric in closed forms: (1) smooth glass in a white furnace
 * keeps all energy (the 1 / eta^2 in and eta^2 out cancel); (2) an
 * index-matched absorbing ball (ior = exterior_ior: no refraction, F = 0)
 * transmits exp(-sigma 2 sqrt(1 - x^2)) along a chord at offset x;
 * (3) an emitter of radiance 1 inside a glass ball (ior 1.5, black
 * background) seen through its centre: (1 - F0) / 1.5^2 = 0.42667. */
static void test_dielectric_closed_forms(void **state)
{
    (void)state;
    fixture f;
    load(&f, "integrator path\nbackground 1 1 1\nmaterial g bsdf dielectric ior 1.5\nsphere 0 0 0 1 g\n", false);
    double mean = mean_over_square(&f, 20000, 5, 1.4f, 1);
    fprintf(stderr, "dielectric furnace: %.4f\n", mean);
    assert_true(fabs(mean - 1.0) < 0.01);
    unload(&f);

    load(&f, "integrator path\nbackground 1 1 1\n"
             "material g bsdf dielectric ior 1.2 exterior_ior 1.2 absorption 0.1 0.5 2\nsphere 0 0 0 1 g\n", false);
    for (int i = 0; i < 8; i++) {
        float x = 0.12f * (float)i;
        rt_vec3 L = radiance(&f, rt_v3(x, 0, 5), rt_v3(0, 0, -1), (uint32_t)i);
        double d = 2.0 * sqrt(1.0 - (double)x * x);
        if (fabs(L.x - exp(-0.1 * d)) > 1e-4 || fabs(L.y - exp(-0.5 * d)) > 1e-4 || fabs(L.z - exp(-2.0 * d)) > 1e-4)
            fail_msg("x %.2f: L (%.5f %.5f %.5f), want (%.5f %.5f %.5f)", (double)x, (double)L.x, (double)L.y,
                     (double)L.z, exp(-0.1 * d), exp(-0.5 * d), exp(-2.0 * d));
    }
    unload(&f);

    load(&f, "integrator path\nbackground 0 0 0\nmaterial g bsdf dielectric ior 1.5\n"
             "material e color 0 0 0 bsdf lambert emission 1 1 1\nsphere 0 0 0 1 g\nsphere 0 0 0 0.5 e\n", false);
    double sum = 0.0;
    const uint32_t n = 20000;
    for (uint32_t i = 0; i < n; i++)
        sum += radiance(&f, rt_v3(0, 0, 5), rt_v3(0, 0, -1), i).y;
    fprintf(stderr, "emitter in glass: %.4f (want 0.42667)\n", sum / n);
    assert_true(fabs(sum / n - 0.96 / 2.25) < 0.01);
    unload(&f);
}

/* Inside an emissive Lambertian sphere: L = E (1 - a^(k+1)) / (1 - a). */
static void test_closed_furnace(void **state)
{
    (void)state;
    const int depths[] = {0, 1, 3}; /* 0 = unlimited */
    for (int t = 0; t < 2; t++) {
        for (int d = 0; d < 3; d++) {
            char text[512];
            snprintf(text, sizeof text,
                     "integrator path\nmax_depth %d\n"
                     "material m color 0.6 0.6 0.6 bsdf lambert emission 1 1 1\nsphere 0 0 0 1 m\n",
                     depths[d]);
            fixture f;
            load(&f, text, t == 1);
            assert_int_equal(f.rs.light_table ? f.rs.light_table->count : 0, t == 1 ? 1 : 0);
            double a = 0.6, want = depths[d] ? (1.0 - pow(a, depths[d] + 1)) / (1.0 - a) : 1.0 / (1.0 - a);
            double sd, mean = mean_inside_sphere(&f, 40000, 9, &sd);
            if (fabs(mean - want) > 4.0 * sd + 1e-3)
                fail_msg("table %d max_depth %d: %.4f +- %.4f, want %.4f", t, depths[d], mean, sd, want);
            unload(&f);
        }
    }
}

/* Russian roulette stays unbiased whatever rr_depth: inside the closed
 * emissive sphere of albedo 0.6 every start depth, and the adaptive rule
 * (0), give E / (1 - a). */
static void test_rr_depth_unbiased(void **state)
{
    (void)state;
    const int rr[] = {0, 1, 5};
    for (int k = 0; k < 3; k++) {
        char text[512];
        snprintf(text, sizeof text,
                 "integrator path\nrr_depth %d\n"
                 "material m color 0.6 0.6 0.6 bsdf lambert emission 1 1 1\nsphere 0 0 0 1 m\n",
                 rr[k]);
        fixture f;
        load(&f, text, false);
        assert_int_equal(f.settings.rr_depth, rr[k]);
        double sd, mean = mean_inside_sphere(&f, 40000, 13, &sd);
        if (fabs(mean - 2.5) > 4.0 * sd + 1e-3)
            fail_msg("rr_depth %d: %.4f +- %.4f, want 2.5", rr[k], mean, sd);
        unload(&f);
    }
}

/* ------------------------------------------------------------- lights */

static void test_point_light_exact(void **state)
{
    (void)state;
    fixture f;
    load(&f,
         "integrator path\nmaterial m color 0.5 0.25 1 bsdf lambert\n"
         "quad -10 0 10  20 0 0  0 0 -20  m\nlight point 1 2 0  1 1 1  10\n",
         true);
    for (uint32_t i = 0; i < 200; i++) {
        float x = -3.0f + 6.0f * (float)i / 200.0f;
        rt_vec3 p = rt_v3(x, 0, 0.5f);
        rt_vec3 L = radiance(&f, rt_v3(x, 1, 1.5f), rt_sub(p, rt_v3(x, 1, 1.5f)), i);
        rt_vec3 d = rt_sub(rt_v3(1, 2, 0), p);
        float r2 = rt_length2(d), c = d.y / sqrtf(r2);
        float e = 10.0f * c / r2 * RT_INV_PI;
        assert_true(fabsf(L.x - 0.5f * e) < 1e-4f * e && fabsf(L.y - 0.25f * e) < 1e-4f * e &&
                    fabsf(L.z - e) < 1e-4f * e);
    }
    unload(&f);
}

static void test_area_light_one_sided(void **state)
{
    (void)state;
    for (int t = 0; t < 2; t++) {
        fixture f;
        load(&f, "integrator path\nlight area -1 2 -1  0 0 2  2 0 0  17 12 4  1\n", t == 1);
        /* cross((0,0,2), (2,0,0)) = (0,4,0): the front faces +y... */
        rt_vec3 above = radiance(&f, rt_v3(0.2f, 5, 0.1f), rt_v3(0, -1, 0), 1);
        rt_vec3 below = radiance(&f, rt_v3(0.2f, 0, 0.1f), rt_v3(0, 1, 0), 2);
        assert_true(above.x == 17.0f && above.y == 12.0f && above.z == 4.0f);
        assert_true(below.x == 0.0f && below.y == 0.0f && below.z == 0.0f);
        unload(&f);
    }
}

/* An emitter made of two triangles and the same rectangle as an area
 * light give the same floor brightness, with or without the table: BSDF
 * sampling alone (triangles, no table) and light sampling combined with
 * it by MIS (the table; the area light) estimate the same integral, for a
 * Lambertian, a glossy metal and a rough plastic floor, the last two seen
 * near the mirror direction of the light. */
static void test_emissive_triangles_vs_area_light(void **state)
{
    (void)state;
    const char *floors[] = {"color 0.8 0.8 0.8 bsdf lambert", "color 0.9 0.9 0.9 metallic 1 roughness 0.25",
                            "color 0.5 0.5 0.5 roughness 0.3"};
    for (int fl = 0; fl < 3; fl++) {
        char tri[1024], area[1024];
        snprintf(tri, sizeof tri,
                 "integrator path\nmaterial floor %s\n"
                 "material lamp color 0 0 0 emission 4 4 4 double_sided false bsdf lambert\n"
                 "quad -10 0 10  20 0 0  0 0 -20  floor\n"
                 "triangle -0.5 1 -0.5  0.5 1 -0.5  0.5 1 0.5  lamp\n"
                 "triangle -0.5 1 -0.5  0.5 1 0.5  -0.5 1 0.5  lamp\n",
                 floors[fl]);
        snprintf(area, sizeof area,
                 "integrator path\nmaterial floor %s\n"
                 "quad -10 0 10  20 0 0  0 0 -20  floor\n"
                 "light area -0.5 1 -0.5  1 0 0  0 0 1  4 4 4  1\n",
                 floors[fl]);
        rt_vec3 eye = fl == 0 ? rt_v3(0.3f, 0.5f, 2.0f) : rt_v3(0.05f, 1.0f, 1.0f);
        rt_vec3 at = fl == 0 ? rt_v3(0.3f, 0.0f, 0.2f) : rt_v3(0.0f, 0.0f, 0.5f);
        double mean[3], sd[3];
        for (int v = 0; v < 3; v++) {
            fixture f;
            load(&f, v == 2 ? area : tri, v == 1);
            double sum = 0.0, sum2 = 0.0;
            const uint32_t n = 20000;
            for (uint32_t i = 0; i < n; i++) {
                rt_vec3 L = radiance(&f, eye, rt_sub(at, eye), i);
                sum += L.x;
                sum2 += (double)L.x * L.x;
            }
            mean[v] = sum / n;
            sd[v] = sqrt(fmax(0.0, sum2 / n - mean[v] * mean[v]) / n);
            unload(&f);
        }
        fprintf(stderr, "floor %d: BSDF only %.4f +- %.4f, table %.4f +- %.4f, area light %.4f +- %.4f\n", fl,
                mean[0], sd[0], mean[1], sd[1], mean[2], sd[2]);
        /* on the Lambertian floor light sampling removes most of the noise */
        if (fl == 0)
            assert_true(sd[1] < 0.5 * sd[0] && sd[2] < 0.5 * sd[0]);
        /* MIS is never much worse than the better strategy: here BSDF
         * sampling, whose narrow metal lobe the big light covers (measured
         * 1.55x its noise, the price of the light samples' tails) */
        assert_true(sd[1] < 2.0 * sd[0] && sd[2] < 2.0 * sd[0]);
        for (int v = 0; v < 2; v++)
            if (fabs(mean[v] - mean[2]) > 4.0 * sqrt(sd[v] * sd[v] + sd[2] * sd[2]))
                fail_msg("floor %d variant %d: %.5f +- %.5f vs area light %.5f +- %.5f", fl, v, mean[v], sd[v],
                         mean[2], sd[2]);
        assert_true(mean[2] > 0.05);
    }
}

/* --------------------------------------------------------- environment */

static void load_env(fixture *f, const char *text, float sky, float sun, bool table)
{
    test_fixture_parse(f, text);
    test_fixture_add_env(&f->s, 64, 32, sky, sun, 40, 8);
    test_fixture_build(f, table ? RT_PREPARE_LIGHT_TABLE : 0);
}

/* -------------------------------------------------- thin-walled panes */

/* The mean and standard error of channel c of n path samples along one ray. */
static double mean_along(const fixture *f, rt_vec3 eye, rt_vec3 at, uint32_t n, int c, double *sd)
{
    double sum = 0.0, sum2 = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        double L = channel(radiance(f, eye, rt_sub(at, eye), i), c);
        sum += L;
        sum2 += L * L;
    }
    double mean = sum / n;
    *sd = sqrt(fmax(0.0, sum2 / n - mean * mean) / n);
    return mean;
}

/* Shadow rays through a smooth thin-walled pane (glTF transmission without
 * a volume) carry its straight-through weight, and a BSDF-sampled path
 * through it is weighed against the light sampling of the vertex before
 * it: the estimate must stay that of BSDF sampling alone. A Lambertian
 * floor under a tinted pane (seen from below, tilted, so both faces and
 * the Fresnel term at many angles are crossed), lit through it by an
 * emissive rectangle (by BSDF sampling alone without the table; by light
 * sampling + MIS through the pane with it), by the same rectangle as an
 * area light, and by an environment with a sun (without and with its
 * table, and with the pane turned over: a thin wall is the same from both
 * sides). Means agree within 4 standard errors (fixed seed, 40,000 samples
 * each); light sampling through the pane must cut the noise of the
 * BSDF-only estimate at least in half (measured: 0.03x emitters, 0.1x the
 * environment). */
static void test_thin_pane_light_sampling(void **state)
{
    (void)state;
    static const char *pane = "material floor color 0.8 0.8 0.8 bsdf lambert\n"
                              "material pane color 0.9 0.6 0.3 transmission 1 ior 1.5 roughness 0 thin_walled true\n"
                              "quad -10 0 10  20 0 0  0 0 -20  floor\n"
                              "quad -10 0.4 10  20 0 0  0 0.3 -20  pane\n";
    char tri[1024], area[1024];
    snprintf(tri, sizeof tri,
             "integrator path\n%smaterial lamp color 0 0 0 emission 4 4 4 double_sided false bsdf lambert\n"
             "triangle -0.5 1.5 -0.5  0.5 1.5 -0.5  0.5 1.5 0.5  lamp\n"
             "triangle -0.5 1.5 -0.5  0.5 1.5 0.5  -0.5 1.5 0.5  lamp\n",
             pane);
    snprintf(area, sizeof area, "integrator path\n%slight area -0.5 1.5 -0.5  1 0 0  0 0 1  4 4 4  1\n", pane);
    rt_vec3 eye = rt_v3(0.3f, 0.3f, 2.0f), at = rt_v3(0.3f, 0.0f, 0.2f);
    const uint32_t n = 40000;
    for (int c = 0; c < 3; c += 2) { /* red and blue: the pane's colour */
        double mean[3], sd[3];
        for (int v = 0; v < 3; v++) {
            fixture f;
            load(&f, v == 2 ? area : tri, v == 1);
            mean[v] = mean_along(&f, eye, at, n, c, &sd[v]);
            unload(&f);
        }
        fprintf(stderr, "pane, channel %d: BSDF only %.5f +- %.5f, table %.5f +- %.5f, area light %.5f +- %.5f\n", c,
                mean[0], sd[0], mean[1], sd[1], mean[2], sd[2]);
        assert_true(mean[0] > 0.01);
        for (int v = 1; v < 3; v++) {
            if (fabs(mean[v] - mean[0]) > 4.0 * sqrt(sd[v] * sd[v] + sd[0] * sd[0]))
                fail_msg("channel %d variant %d: %.5f +- %.5f vs BSDF only %.5f +- %.5f", c, v, mean[v], sd[v],
                         mean[0], sd[0]);
            assert_true(sd[v] < 0.5 * sd[0]);
        }
    }
    /* the environment: sky 0.5, a sun of 400 in 4 texels, 45 degrees up:
     * past the critical angle of ior 1.5, where a thin wall's back face
     * used to reflect everything; with the pane turned over (its front
     * down, variant 2) the floor must see the same */
    char env[1024], flipped[1024];
    snprintf(env, sizeof env, "integrator path\n%s", pane);
    snprintf(flipped, sizeof flipped, "integrator path\n%s", pane);
    char *q = strstr(flipped, "quad -10 0.4 10  20 0 0  0 0.3 -20  pane");
    assert_non_null(q);
    memcpy(q, "quad -10 0.4 10  0 0.3 -20  20 0 0  pane", strlen("quad -10 0.4 10  0 0.3 -20  20 0 0  pane"));
    double mean[3], sd[3];
    for (int v = 0; v < 3; v++) {
        fixture f;
        load_env(&f, v == 2 ? flipped : env, 0.5f, 400.0f, v >= 1);
        mean[v] = mean_along(&f, eye, at, n, 0, &sd[v]);
        unload(&f);
    }
    fprintf(stderr, "pane under an environment: BSDF only %.5f +- %.5f, table %.5f +- %.5f, turned over %.5f +- %.5f\n",
            mean[0], sd[0], mean[1], sd[1], mean[2], sd[2]);
    for (int v = 1; v < 3; v++)
        if (fabs(mean[v] - mean[0]) > 4.0 * sqrt(sd[v] * sd[v] + sd[0] * sd[0]))
            fail_msg("environment %d: %.5f +- %.5f vs BSDF only %.5f +- %.5f", v, mean[v], sd[v], mean[0], sd[0]);
    assert_true(fabs(mean[2] - mean[1]) < 4.0 * sqrt(sd[1] * sd[1] + sd[2] * sd[2]));
    assert_true(sd[1] < 0.5 * sd[0]);
}

/* A closed form through a thin pane: a Lambertian floor (albedo a) under
 * an unbounded smooth thin pane of colour c (transmission 1, ior 1.5) in a
 * uniform sky of radiance 1, light-sampled through the pane. The floor's
 * radiance is uniform, L = a (t + r L), with t = 2 int c (1 - F) cos sin
 * and r = 2 int F cos sin over the hemisphere (F the exact Fresnel
 * reflectance from air: the pane transmits the sky and mirrors the floor),
 * so L = a t / (1 - a r). Quads 4000 wide 1 apart stand in for planes (the
 * sky they leave out at the horizon is below 1e-6). Within 4 standard
 * errors at 20,000 samples, for the pane either way up. */
static void test_thin_pane_closed_form(void **state)
{
    (void)state;
    const float a = 0.8f, c = 0.7f;
    double t = 0.0, r = 0.0;
    const int steps = 20000;
    for (int k = 0; k < steps; k++) { /* midpoint rule in theta */
        double th = (k + 0.5) * (0.5 * RT_PI / steps), w = 2.0 * cos(th) * sin(th) * (0.5 * RT_PI / steps);
        double F = rt_fresnel_exact((float)cos(th), 1.0f / 1.5f);
        t += w * c * (1.0 - F);
        r += w * F;
    }
    double expect = a * t / (1.0 - a * r);
    const char *faces[] = {"2000 1 -2000  -4000 0 0  0 0 4000", "2000 1 -2000  0 0 4000  -4000 0 0"};
    for (int v = 0; v < 2; v++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "integrator path\nmax_depth 0\nmaterial floor color %g %g %g bsdf lambert\n"
                 "material pane color %g %g %g transmission 1 ior 1.5 roughness 0 thin_walled true\n"
                 "quad -2000 0 2000  4000 0 0  0 0 -4000  floor\nquad %s  pane\n",
                 a, a, a, c, c, c, faces[v]);
        fixture f;
        load_env(&f, text, 1.0f, 1.0f, true);
        double sd, mean = mean_along(&f, rt_v3(0.1f, 0.5f, 0.2f), rt_v3(0.3f, 0.0f, -0.1f), 20000, 0, &sd);
        unload(&f);
        fprintf(stderr, "pane closed form, face %d: %.5f +- %.5f, expected %.5f (t %.5f, r %.5f)\n", v, mean, sd,
                expect, t, r);
        if (fabs(mean - expect) > 4.0 * sd + 1e-4)
            fail_msg("face %d: %.5f +- %.5f, expected %.5f", v, mean, sd, expect);
    }
}

/* The environment's sampling density integrates to 1 over the sphere. */
static void test_env_pdf_normalised(void **state)
{
    (void)state;
    fixture f;
    load_env(&f, "integrator path\n", 0.1f, 1000.0f, true);
    assert_int_equal(f.rs.light_table->env_w, 64);
    assert_int_equal(f.rs.light_table->env_h, 32);
    /* midpoint rule in (u, v), 16 x 16 points per cell (the cells' edges
     * fall between points), dw = 2 pi^2 sin(theta) du dv */
    double sum = 0.0;
    const int nu = 64 * 16, nv = 32 * 16;
    for (int j = 0; j < nv; j++) {
        double v = (j + 0.5) / nv, theta = v * 3.14159265358979;
        for (int i = 0; i < nu; i++) {
            double u = (i + 0.5) / nu, phi = (u - 0.5) * 2.0 * 3.14159265358979;
            rt_vec3 d = rt_v3((float)(sin(theta) * sin(phi)), (float)cos(theta), (float)(sin(theta) * cos(phi)));
            sum += rt_light_table_env_pdf(f.rs.light_table, d) * sin(theta);
        }
    }
    double integral = sum * 2.0 * 3.14159265358979 * 3.14159265358979 / ((double)nu * nv);
    if (fabs(integral - 1.0) >= 0.01)
        fail_msg("integral of the environment pdf: %.4f", integral);
    unload(&f);
}

/* A Lambertian floor under a sky with a small bright sun: environment
 * sampling with MIS gives the same mean as BSDF sampling alone, with far
 * less noise; under a uniform sky of 1 a Lambertian sphere shows its albedo. */
static void test_env_sampling(void **state)
{
    (void)state;
    const char *text = "integrator path\nmaterial m color 0.5 0.5 0.5 bsdf lambert\nquad -10 0 10  20 0 0  0 0 -20  m\n";
    double mean[2], sd[2];
    for (int t = 0; t < 2; t++) {
        fixture f;
        load_env(&f, text, 0.1f, 1000.0f, t == 1);
        double sum = 0.0, sum2 = 0.0;
        const uint32_t n = 20000;
        for (uint32_t i = 0; i < n; i++) {
            rt_vec3 L = radiance(&f, rt_v3(0, 1, 1), rt_v3(0, -1, -1), i);
            sum += L.x;
            sum2 += (double)L.x * L.x;
        }
        mean[t] = sum / n;
        sd[t] = sqrt(fmax(0.0, sum2 / n - mean[t] * mean[t]) / n);
        unload(&f);
    }
    fprintf(stderr, "sun and sky: BSDF only %.4f +- %.4f, with environment sampling %.4f +- %.4f\n", mean[0], sd[0],
            mean[1], sd[1]);
    assert_true(sd[1] < 0.3 * sd[0]);
    assert_true(fabs(mean[0] - mean[1]) < 4.0 * sqrt(sd[0] * sd[0] + sd[1] * sd[1]));
    /* uniform sky, textured: the furnace again, now through light sampling */
    fixture f;
    load_env(&f, "integrator path\nmaterial m color 0.7 0.7 0.7 bsdf lambert\nsphere 0 0 0 1 m\n", 1.0f, 1.0f, true);
    double sum = 0.0;
    const uint32_t n = 20000;
    for (uint32_t i = 0; i < n; i++)
        sum += radiance(&f, rt_v3(0.3f, 0.2f, 5), rt_v3(0, 0, -1), i).x;
    assert_true(fabs(sum / n - 0.7) < 0.005);
    unload(&f);
}

/* ------------------------------------------------------ whole images */

static const char *every_material =
    "integrator path\nresolution 48 32\nsamples 8\nbackground 0.2 0.3 0.4\n" TEST_EVERY_MATERIAL_SCENE;

static void render_fixture(fixture *f, int threads, rt_framebuffer *fb, rt_render_stats *st)
{
    rt_error err;
    assert_int_equal(rt_framebuffer_init(fb, f->settings.width, f->settings.height, &err), RT_OK);
    rt_render_options opt;
    memset(&opt, 0, sizeof opt);
    opt.threads = threads;
    opt.tile_size = 8;
    assert_int_equal(rt_render(&f->s, &f->settings, &f->tree, &opt, fb, st, &err), RT_OK);
}

static void test_every_material_finite_and_deterministic(void **state)
{
    (void)state;
    fixture f;
    load(&f, every_material, false);
    rt_framebuffer a, b;
    rt_render_stats sa, sb;
    render_fixture(&f, 1, &a, &sa);
    render_fixture(&f, 3, &b, &sb);
    assert_true(sa.bad_samples == 0 && sb.bad_samples == 0);
    size_t n = (size_t)a.width * (size_t)a.height * 3;
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        assert_true(isfinite(a.rgb[i]) && a.rgb[i] >= 0.0f);
        sum += a.rgb[i];
    }
    assert_true(sum > 0.0);
    assert_memory_equal(a.rgb, b.rgb, n * sizeof(float));
    rt_framebuffer_free(&a);
    rt_framebuffer_free(&b);
    /* the same through the emitter table: every sample finite */
    rt_render_state rs;
    rt_error err;
    assert_int_equal(rt_render_state_prepare(&rs, &f.s, &f.settings, &f.tree, RT_PREPARE_LIGHT_TABLE, &err), RT_OK);
    assert_int_equal(rs.light_table->count, 1); /* the lamp triangle (the area light's quad is a light already) */
    rt_trace_ctx ctx;
    rt_trace_ctx_init(&ctx, &rs);
    rt_camera_frame cf;
    rt_camera_frame_init(&cf, &f.s.camera, 48, 32);
    for (uint32_t i = 0; i < 48 * 32 * 4; i++) {
        uint32_t p = i / 4;
        rt_rng rng = rt_rng_for_sample(3, p, i % 4);
        rt_ray r = rt_camera_ray(&cf, (float)(p % 48) + 0.5f, (float)(p / 48) + 0.5f, rt_v2(0.5f, 0.5f));
        rt_vec3 L = rt_radiance_path(&ctx, &r, &rng);
        assert_true(rt_finite3(L) && L.x >= 0.0f && L.y >= 0.0f && L.z >= 0.0f);
    }
    rt_render_state_free(&rs);
    unload(&f);
}

/* The Cornell-reference test (the one: test_wavefront.c checks that
 * path_scalar renders the same bytes as `path`, the wavefront, used here;
 * test_sampler.c compares samplers' errors against the same reference).
 * The shared reference: scenes/cornell-reference.txt at 64x64 (the same
 * camera, so each pixel covers an 8x8 block of the 512x512 reference) and
 * 256 samples per pixel, against the reference box-averaged over 8x8
 * blocks. The reference's own noise (RMSE 0.002 per 512x512 pixel at 8064
 * spp) averages to ~0.0003 per block, negligible. Our per-block noise: a
 * sample's standard deviation over this scene is about 0.075 (measured: the
 * 512x512 render at 64 spp has RMSE 0.0092 = 0.075 / 8), so 256 samples give
 * ~0.075 / 16 = 0.0047, plus the light's edge, which a 64x64 pixel straddles
 * with a much larger spread. Bound: 0.008. Image means: the mean over 4096
 * pixels x 256 samples has a relative noise of ~0.1%, so 1% detects any bias
 * that matters (a 4-bounce cap alone darkens by 2.5-3.4%, SCENE.md). */
static void test_cornell_reference(void **state)
{
    (void)state;
    rt_framebuffer ref;
    test_require_cornell_reference(&ref);
    rt_error err;
    assert_int_equal(ref.width, 512);
    assert_int_equal(ref.height, 512);
    fixture f;
    rt_scene_init(&f.s);
    rt_settings_default(&f.settings); /* the file's settings go here; then the size and samples below */
    if (rt_scene_parse_file(&f.s, &f.settings, "scenes/cornell-reference.txt", &err) != RT_OK)
        fail_msg("%s", err.message);
    assert_int_equal(f.s.triangles.count, 30);
    assert_int_equal(f.s.light_count, 1);
    f.settings.width = f.settings.height = 64;
    f.settings.samples = 256;
    assert_int_equal(rt_kdtree_build(&f.tree, &f.s, NULL, &err), RT_OK);
    memset(&f.rs, 0, sizeof f.rs);
    rt_framebuffer img;
    rt_render_stats st;
    render_fixture(&f, 0, &img, &st);
    assert_true(st.bad_samples == 0);
    double mine[3], theirs[3];
    double rmse = test_cornell_block_rmse(&img, &ref, mine, theirs);
    fprintf(stderr, "cornell-reference 64x64 @ 256 spp: RMSE %.5f, means (%.5f %.5f %.5f) vs (%.5f %.5f %.5f)\n", rmse,
            mine[0], mine[1], mine[2], theirs[0], theirs[1], theirs[2]);
    /* the reference's published means */
    assert_true(fabs(theirs[0] - 0.19650) < 2e-5 && fabs(theirs[1] - 0.12749) < 2e-5 && fabs(theirs[2] - 0.03642) < 2e-5);
    for (int c = 0; c < 3; c++)
        assert_true(fabs(mine[c] / theirs[c] - 1.0) < 0.01);
    assert_true(rmse < 0.008);
    rt_framebuffer_free(&img);
    rt_framebuffer_free(&ref);
    rt_kdtree_free(&f.tree);
    rt_scene_free(&f.s);
}

/* The same box with the light as two emissive triangles (one-sided, black,
 * as SCENE.md defines it), light-sampled through the emitter table and
 * combined by MIS, must converge to the same reference: 64x64, 64 spp,
 * image means within 1% (their noise is ~0.2%). */
static void test_cornell_emissive_triangles(void **state)
{
    (void)state;
    rt_framebuffer ref;
    test_require_cornell_reference(&ref);
    FILE *fp = fopen("scenes/cornell-reference.txt", "rb");
    assert_non_null(fp);
    static char text[16384];
    size_t n = fread(text, 1, sizeof text - 1, fp);
    fclose(fp);
    text[n] = 0;
    char *light = strstr(text, "\nlight area");
    assert_non_null(light);
    snprintf(light, sizeof text - (size_t)(light - text),
             "\nmaterial lamp color 0 0 0 emission 17 12 4 double_sided false bsdf lambert\n"
             "triangle 343 548.7 227  343 548.7 332  213 548.7 332  lamp\n"
             "triangle 343 548.7 227  213 548.7 332  213 548.7 227  lamp\n");
    fixture f;
    load(&f, text, true);
    assert_int_equal(f.s.light_count, 0);
    assert_int_equal(f.rs.light_table->count, 2);
    rt_camera_frame cf;
    rt_camera_frame_init(&cf, &f.s.camera, 64, 64);
    double mine[3] = {0, 0, 0}, theirs[3] = {0, 0, 0};
    const uint32_t spp = 64;
    for (uint32_t p = 0; p < 64 * 64; p++) {
        for (uint32_t k = 0; k < spp; k++) {
            rt_vec2 j = rt_cmj_sample(k, spp, p * 7919u + 1u);
            rt_ray r = rt_camera_ray(&cf, (float)(p % 64) + j.x, (float)(p / 64) + j.y, rt_v2(0.5f, 0.5f));
            rt_rng rng = rt_rng_for_sample(1, p, k);
            rt_vec3 L = rt_radiance_path(&f.ctx, &r, &rng);
            assert_true(rt_finite3(L));
            mine[0] += L.x, mine[1] += L.y, mine[2] += L.z;
        }
    }
    for (size_t i = 0; i < 512 * 512; i++)
        for (int c = 0; c < 3; c++)
            theirs[c] += ref.rgb[3 * i + (size_t)c];
    for (int c = 0; c < 3; c++) {
        mine[c] /= 64.0 * 64.0 * spp;
        theirs[c] /= 512.0 * 512.0;
    }
    fprintf(stderr, "cornell, emissive triangles via the table: means (%.5f %.5f %.5f) vs (%.5f %.5f %.5f)\n", mine[0],
            mine[1], mine[2], theirs[0], theirs[1], theirs[2]);
    for (int c = 0; c < 3; c++)
        assert_true(fabs(mine[c] / theirs[c] - 1.0) < 0.01);
    rt_framebuffer_free(&ref);
    unload(&f);
}

/* A surface close under an area light sees all of it: nothing lies in
 * between, so no light sample may be shadowed, whichever shadow walk asks
 * (the plain one of direct/whitted, the path tracer's). The shadow ray once
 * ran along wi from the offset origin and met the light's plane past the
 * sampled point, on the light's own quad: from 10 units under a 130 x 105
 * light 3925 of 4096 samples counted as shadowed, from 48.7 units 309 to
 * all of them, depending on the point. */
static void test_shadow_rays_reach_the_light(void **state)
{
    (void)state;
    const float heights[] = {48.7f, 10.0f, 1.0f};
    for (int k = 0; k < 3; k++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "material white color 0.8 0.8 0.8\n"
                 "quad 0 %g 0   0 0 559   556 0 0   white\n" /* facing up, h under the light */
                 "light area 343 548.7 227  0 0 105  -130 0 0  1 1 1  1\n",
                 (double)(548.7f - heights[k]));
        test_fixture f;
        test_fixture_load(&f, text, RT_PREPARE_LIGHT_TABLE);
        for (int px = 0; px < 4; px++) {
            rt_vec3 target = rt_v3(100.0f + 70.0f * (float)px, 548.7f - heights[k], 279.5f);
            rt_ray r = rt_ray_make(rt_add(target, rt_v3(0, 1, 0)), rt_v3(0, -1, 0), 0.0f, INFINITY);
            rt_hit hit;
            assert_true(rt_trace(&f.ctx, &r, &hit));
            rt_surface sf;
            rt_surface_at(&f.ctx, &r, &hit, &sf);
            int blocked = 0, n = 0;
            rt_rng rng = rt_rng_seed(1, (uint64_t)px);
            for (int i = 0; i < 1024; i++) {
                rt_light_sample ls;
                rt_vec2 u = rt_v2(rt_rng_float(&rng), rt_rng_float(&rng));
                if (!rt_light_sample_at(&f.ctx, &f.s.lights[0], sf.p, u, &ls))
                    continue;
                n++;
                blocked += rt_shadow_path_transmittance(&f.ctx, &sf, ls.wi, ls.dist, true).x == 0.0f;
                blocked += rt_shadow_transmittance(&f.ctx, &sf, ls.wi, ls.dist).x == 0.0f;
            }
            if (blocked)
                fail_msg("%g under the light, x %g: %d of %d light samples shadowed", (double)heights[k],
                         (double)target.x, blocked, 2 * n);
            assert_true(n > 500);
        }
        test_fixture_free(&f);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_furnace_lambert),
        cmocka_unit_test(test_furnace_metal),
        cmocka_unit_test(test_furnace_glass),
        cmocka_unit_test(test_furnace_energy_compensation),
        cmocka_unit_test(test_furnace_glass_compensation),
        cmocka_unit_test(test_smooth_conductor_sphere),
        cmocka_unit_test(test_dielectric_closed_forms),
        cmocka_unit_test(test_closed_furnace),
        cmocka_unit_test(test_rr_depth_unbiased),
        cmocka_unit_test(test_point_light_exact),
        cmocka_unit_test(test_area_light_one_sided),
        cmocka_unit_test(test_emissive_triangles_vs_area_light),
        cmocka_unit_test(test_env_pdf_normalised),
        cmocka_unit_test(test_env_sampling),
        cmocka_unit_test(test_thin_pane_light_sampling),
        cmocka_unit_test(test_thin_pane_closed_form),
        cmocka_unit_test(test_every_material_finite_and_deterministic),
        cmocka_unit_test(test_cornell_reference),
        cmocka_unit_test(test_cornell_emissive_triangles),
        cmocka_unit_test(test_shadow_rays_reach_the_light),
    };
    return cmocka_run_group_tests_name("path", tests, NULL, NULL);
}
