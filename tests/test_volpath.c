/* test_volpath.c - the volumetric path tracer (rt/render/volpath.h) against
 * closed forms, each a mean over many paths along one camera ray held to
 * within four standard errors (plus a small relative slack):
 * - Beer-Lambert: a slab of a chromatic pure absorber between two null
 *   faces, seen against a uniform white background, lets exp(-sigma_a d)
 *   through per channel (the hero channel's null-collision tracking and
 *   the spectral MIS over channels it has to average);
 * - single scattering: a slab of chromatic medium lit by a directional
 *   light from behind the camera, max_depth 1, against
 *   sigma_s p(-1) E (1 - exp(-2 sigma_t d)) / (2 sigma_t) (light sampling
 *   with the phase function, ratio tracking of the shadow rays);
 * - single scattering from a box of medium under an area light close
 *   above it, against quadrature (solid-angle light sampling, shadow rays
 *   through a null face to the light), and under the same rectangle as
 *   two emissive triangles (the light table's NEE with MIS, with a
 *   standard error like the area light's);
 * - a camera inside a null sphere of absorber starts in it (Beer-Lambert
 *   from the centre);
 * - a white furnace: a sphere of albedo-1 chromatic forward-scattering
 *   medium (g 0.7) under a uniform sky of radiance 1 stays 1;
 * - a voxel grid of constant density 0.5 with doubled coefficients renders
 *   as the homogeneous medium (majorant walk, trilinear lookups inside the
 *   grid's hull), with two dense voxels outside the sphere raising the
 *   majorant of their blocks so that paths inside take null collisions;
 * and the dispatch: rt_render uses it for a scene with media and the
 * surface path tracer's bytes for one without.
 */
#include "test_util.h"

#include <math.h>

#include "rt/render/aov.h"
#include "rt/render/phase.h"
#include "rt/render/volpath.h"
#include "test_fixture.h"
#include "test_volpath_estimate.h"

/* Two faces of a slab z in [-0.5, 0.5], wide as the world here: the front
 * (+z) faces the camera, the back faces away (cross(U, V) outwards). */
#define SLAB_FACES                                                                                                     \
    "quad -500 -500 0.5   1000 0 0   0 1000 0   box\n"                                                                 \
    "quad -500 -500 -0.5  0 1000 0   1000 0 0   box\n"

static void test_beer_lambert_slab(void **state)
{
    (void)state;
    test_fixture f;
    test_fixture_load(&f,
                      "sampler independent\nbackground 1 1 1\n"
                      "medium ink homogeneous sigma_a 0.25 1 2.5 sigma_s 0 0 0\n"
                      "material box bsdf null interior ink\n" SLAB_FACES,
                      RT_PREPARE_LIGHT_TABLE);
    test_estimate e = test_estimate_ray(&f, rt_v3(0.1f, 0.2f, 5.0f), rt_v3(0, 0, -1), 30000, 1234);
    test_expect_near("slab transmittance", e, rt_v3(expf(-0.25f), expf(-1.0f), expf(-2.5f)));
    /* at 60 degrees the path in the slab is twice as long */
    e = test_estimate_ray(&f, rt_v3(0, 0, 5.0f), rt_v3(sqrtf(3.0f), 0, -1), 30000, 1234);
    test_expect_near("slab transmittance at 60 degrees", e, rt_v3(expf(-0.5f), expf(-2.0f), expf(-5.0f)));
    test_fixture_free(&f);
}

static void test_single_scattering_slab(void **state)
{
    (void)state;
    const float g = 0.5f, E = 3.0f;
    const rt_vec3 sa = rt_v3(0.1f, 0.1f, 0.1f), ss = rt_v3(0.2f, 0.5f, 1.0f);
    test_fixture f;
    test_fixture_load(&f,
                      "sampler independent\nmax_depth 1\n"
                      "medium haze homogeneous sigma_a 0.1 0.1 0.1 sigma_s 0.2 0.5 1 g 0.5\n"
                      "material box bsdf null interior haze\n" SLAB_FACES
                      "light directional 0 0 -1  1 1 1  3\n",
                      RT_PREPARE_LIGHT_TABLE);
    /* light travelling -z scatters back (+z, cos -1) towards the camera */
    float p = rt_hg_pdf(g, -1.0f);
    const float st[3] = {sa.x + ss.x, sa.y + ss.y, sa.z + ss.z}, s_s[3] = {ss.x, ss.y, ss.z};
    float want[3];
    for (int k = 0; k < 3; k++)
        want[k] = s_s[k] * p * E * (1.0f - expf(-2.0f * st[k])) / (2.0f * st[k]);
    test_estimate e = test_estimate_ray(&f, rt_v3(0.1f, -0.3f, 4.0f), rt_v3(0, 0, -1), 40000, 1234);
    test_expect_near("single scattering", e, rt_v3(want[0], want[1], want[2]));
    test_fixture_free(&f);
}

static void test_white_furnace(void **state)
{
    (void)state;
    test_fixture f;
    test_fixture_load(&f,
                      "sampler independent\nbackground 1 1 1\n"
                      "medium cloud homogeneous sigma_a 0 0 0 sigma_s 0.5 2 4 g 0.7\n"
                      "material box bsdf null interior cloud\n"
                      "sphere 0 0 0 1 box\n",
                      RT_PREPARE_LIGHT_TABLE);
    test_estimate e = test_estimate_ray(&f, rt_v3(0, 0, 4), rt_v3(0, 0, -1), 20000, 1234);
    test_expect_near("furnace, through the centre", e, rt_v3s(1.0f));
    e = test_estimate_ray(&f, rt_v3(0.7f, 0.2f, 4), rt_v3(0, 0, -1), 20000, 1234);
    test_expect_near("furnace, off centre", e, rt_v3s(1.0f));
    test_fixture_free(&f);
}

/* The same scene with the medium as given and as a grid of density 0.5
 * and twice the coefficients, placed so that the sphere lies inside the
 * hull of the voxel centres (where trilinear lookups are exact). */
static void test_constant_grid_is_homogeneous(void **state)
{
    (void)state;
    const char *text = "sampler independent\nbackground 0.2 0.3 0.4\n"
                       "medium m homogeneous sigma_a 0.3 0.5 0.2 sigma_s 1 0.6 1.5 g -0.3\n"
                       "material box bsdf null interior m\n"
                       "material floor color 0.7 0.7 0.7\n"
                       "sphere 0 0 0 0.8 box\n"
                       "quad -5 -1 -5  0 0 10  10 0 0  floor\n"
                       "light point 0 3 1  1 1 1  20\n";
    test_fixture hom, grid;
    test_fixture_load(&hom, text, RT_PREPARE_LIGHT_TABLE);
    test_fixture_parse(&grid, text);
    rt_medium_def *m = &grid.s.media[0];
    rt_error err;
    assert_int_equal(rt_density_grid_init(&m->grid, 10, 10, 10, &err), RT_OK);
    for (size_t i = 0; i < 1000; i++)
        m->grid.density[i] = 0.5f;
    /* two dense corner voxels outside the sphere (trilinear reach: 0.2):
     * their blocks' majorant is 10 x the density inside, so paths there
     * take null collisions */
    m->grid.density[rt_density_grid_index(&m->grid, 9, 9, 9)] = 5.0f;
    m->grid.density[rt_density_grid_index(&m->grid, 0, 9, 0)] = 5.0f;
    assert_int_equal(rt_density_grid_finish(&m->grid, "test", &err), RT_OK);
    m->kind = RT_MEDIUM_GRID;
    m->sigma_a = rt_scale(m->sigma_a, 2.0f);
    m->sigma_s = rt_scale(m->sigma_s, 2.0f);
    /* index (0..10)^3 -> world (-1..1)^3: the centres' hull is +-0.9 */
    m->index_to_world = rt_mat4_mul(rt_mat4_translate(rt_v3s(-1.0f)), rt_mat4_scale(rt_v3s(0.2f)));
    m->world_to_index = rt_mat4_mul(rt_mat4_scale(rt_v3s(5.0f)), rt_mat4_translate(rt_v3s(1.0f)));
    test_fixture_build(&grid, RT_PREPARE_LIGHT_TABLE);
    const rt_vec3 org[2] = {rt_v3(0, 0, 4), rt_v3(0.3f, 0.4f, 4)};
    for (int k = 0; k < 2; k++) {
        test_estimate a = test_estimate_ray(&hom, org[k], rt_v3(0, 0, -1), 30000, 1234);
        test_estimate b = test_estimate_ray(&grid, org[k], rt_v3(0, 0, -1), 30000, 1234);
        /* two estimates: their difference's standard error */
        rt_vec3 se = rt_v3(hypotf(a.se.x, b.se.x), hypotf(a.se.y, b.se.y), hypotf(a.se.z, b.se.z));
        test_expect_near("grid of constant density against homogeneous", (test_estimate){b.mean, se}, a.mean);
        assert_true(rt_fminf(a.mean.x, rt_fminf(a.mean.y, a.mean.z)) > 0.02f); /* light did arrive */
    }
    test_fixture_free(&hom);
    test_fixture_free(&grid);
}

/* Single scattering under a light close above a box of medium, against
 * quadrature along the ray: the medium point's transmittance to each point
 * of the light (out through the top face) times the phase function and the
 * light's solid angle. The light is given by `light`: a `light area`
 * (sampled by solid angle from points near it) or the same rectangle as
 * two emissive triangles of the light table (sampled by power, then by
 * solid angle or area, with MIS against phase sampling). The shadow rays
 * cross the box's null top face on their way; sent on along their first
 * direction from the face's offset, they met the light's own plane past
 * the sampled point and counted as blocked (a third of the light). */
static test_estimate single_scattering_under(const char *light, double *expected)
{
    char text[2048];
    snprintf(text, sizeof text,
             "sampler independent\nmax_depth 1\n"
             "medium m homogeneous sigma_a 0.002 0.002 0.002 sigma_s 0.008 0.008 0.008 g 0.3\n"
             "material box bsdf null interior m\n"
             "quad 100 350 100   350 0 0   0 0 350     box\n"
             "quad 100 525 100   0 0 350   350 0 0     box\n"
             "quad 100 350 100   0 0 350   0 175 0     box\n"
             "quad 450 350 100   0 175 0   0 0 350     box\n"
             "quad 100 350 100   0 175 0   350 0 0     box\n"
             "quad 100 350 450   350 0 0   0 175 0     box\n"
             "%s",
             light);
    test_fixture f;
    test_fixture_load(&f, text, RT_PREPARE_LIGHT_TABLE);
    /* the rectangle both lights are: corner, edges, facing -y */
    const rt_vec3 pos = rt_v3(343, 548.7f, 227), eu = rt_v3(0, 0, 105), ev = rt_v3(-130, 0, 0);
    const rt_vec3 o = rt_v3(278, 480, -800), d = rt_normalize(rt_v3(0, 0.02f, 1));
    const double st = 0.01, ss = 0.008, t0 = (100 - o.z) / d.z, t1 = (450 - o.z) / d.z;
    const rt_vec3 n = rt_normalize(rt_cross(eu, ev));
    const double area = rt_length(rt_cross(eu, ev));
    double want = 0;
    const int NT = 200, NU = 40;
    for (int i = 0; i < NT; i++) { /* midpoint rule along the ray and over the light */
        double t = t0 + (i + 0.5) * (t1 - t0) / NT, ls = 0;
        rt_vec3 p = rt_madd(o, d, (float)t);
        for (int a = 0; a < NU; a++)
            for (int b = 0; b < NU; b++) {
                rt_vec3 x = rt_add(pos, rt_add(rt_scale(eu, (a + 0.5f) / NU), rt_scale(ev, (b + 0.5f) / NU)));
                rt_vec3 w = rt_sub(x, p);
                float d2 = rt_length2(w);
                w = rt_scale(w, 1.0f / sqrtf(d2));
                double inside = (525.0 - p.y) / w.y; /* leaves through the top face */
                ls += exp(-st * inside) * rt_hg_pdf(0.3f, rt_dot(d, w)) * -rt_dot(n, w) / d2 * area / (NU * NU);
            }
        want += exp(-st * (t - t0)) * ss * ls * (t1 - t0) / NT;
    }
    test_estimate e = test_estimate_ray(&f, o, d, 100000, 1234);
    test_fixture_free(&f);
    *expected = want;
    return e;
}

static void test_single_scattering_area_light(void **state)
{
    (void)state;
    double want;
    test_estimate e = single_scattering_under("light area 343 548.7 227  0 0 105  -130 0 0  1 1 1  1\n", &want);
    test_expect_near("single scattering under an area light", e, rt_v3s((float)want));
}

/* The same light as two emissive triangles: found by light sampling (NEE
 * through the light table, ratio-tracked shadow rays, MIS with the phase
 * function), the estimate is as good as the area light's; by phase
 * sampling alone (as before) its standard error was 3 times the
 * area light's for the same mean. */
static void test_single_scattering_emissive_triangles(void **state)
{
    (void)state;
    double want, want_area;
    test_estimate area = single_scattering_under("light area 343 548.7 227  0 0 105  -130 0 0  1 1 1  1\n", &want_area);
    test_estimate e = single_scattering_under("material lamp color 0 0 0 emission 1 1 1 double_sided false\n"
                                         "triangle 343 548.7 227  343 548.7 332  213 548.7 332  lamp\n"
                                         "triangle 343 548.7 227  213 548.7 332  213 548.7 227  lamp\n",
                                         &want);
    test_expect_near("single scattering under emissive triangles", e, rt_v3s((float)want));
    print_message("standard error: emissive triangles %.6f, area light %.6f\n", e.se.x, area.se.x);
    assert_true(e.se.x < 2.0f * area.se.x);
}

/* A camera inside a closed null boundary starts in its medium: from the
 * centre of a sphere of radius 1 of pure absorber, the white background
 * arrives through exp(-sigma_a) (it arrived unattenuated when every path
 * started in the scene's medium). */
static void test_camera_inside_medium(void **state)
{
    (void)state;
    test_fixture f;
    test_fixture_load(&f,
                      "sampler independent\nbackground 1 1 1\n"
                      "medium ink homogeneous sigma_a 0.5 1 2 sigma_s 0 0 0\n"
                      "material box bsdf null interior ink\n"
                      "sphere 0 0 0 1 box\n"
                      "sphere 5 0 0 1 box\n", /* another one, off to the side: outside it, no change */
                      RT_PREPARE_LIGHT_TABLE);
    test_estimate e = test_estimate_ray(&f, rt_v3(0, 0, 0), rt_v3(0.3f, 0.4f, -1), 4000, 1234);
    test_expect_near("camera inside a medium", e, rt_v3(expf(-0.5f), expf(-1.0f), expf(-2.0f)));
    /* looking through the other sphere: its diameter on top */
    e = test_estimate_ray(&f, rt_v3(0, 0, 0), rt_v3(1, 0, 0), 4000, 1234);
    test_expect_near("camera inside a medium, through another", e, rt_v3(expf(-1.5f), expf(-3.0f), expf(-6.0f)));
    test_fixture_free(&f);
}

/* The denoiser's AOVs with media: a camera ray whose first event is a
 * collision in a medium reports its single-scattering albedo and a zero
 * normal. A slab of grey medium (optical depth 0.7, albedo 0.5) between
 * null faces in front of a wall of albedo 0.9: the mean albedo is
 * (1 - T) 0.5 + T 0.9 with T = exp(-0.7), and the mean normal T times the
 * wall's; a dense chromatic ball gives its albedo (0.9, 0.8, 0.7) alone. */
static void test_aov_albedo_of_media(void **state)
{
    (void)state;
    test_fixture f;
    test_fixture_load(&f,
                      "sampler independent\nintegrator path\n"
                      "medium haze homogeneous sigma_a 0.35 0.35 0.35 sigma_s 0.35 0.35 0.35\n"
                      "medium milk homogeneous sigma_a 1 2 3 sigma_s 9 8 7\n"
                      "material box bsdf null interior haze\n"
                      "material ball bsdf null interior milk\n"
                      "material wall color 0.9 0.9 0.9 bsdf lambert\n" SLAB_FACES
                      "quad -500 -500 -2  0 1000 0   1000 0 0   wall\n"
                      "sphere 100 0 0 1 ball\n",
                      RT_PREPARE_LIGHT_TABLE);
    const int n = 20000;
    double alb = 0, nz = 0;
    for (int i = 0; i < n; i++) {
        rt_rng rng = rt_rng_for_sample(99, (uint64_t)i, 0);
        rt_aov_sample a;
        rt_aov_trace(&f.ctx, rt_ray_make(rt_v3(0.1f, 0.2f, 5), rt_v3(0, 0, -1), 0.0f, INFINITY), &rng, &a);
        alb += a.albedo.x;
        nz += a.normal.z;
    }
    const double T = exp(-0.7), want = (1 - T) * 0.5 + T * 0.9;
    /* a Bernoulli mix of 0.5 and 0.9: its standard error */
    const double se = 0.4 * sqrt(T * (1 - T) / n);
    print_message("albedo through haze %.4f (expected %.4f +- %.4f), normal z %.4f (expected %.4f)\n", alb / n, want,
                  se, nz / n, T);
    assert_true(fabs(alb / n - want) < 4 * se);
    assert_true(fabs(nz / n - T) < 4 * sqrt(T * (1 - T) / n));
    rt_rng rng = rt_rng_for_sample(99, 0, 0);
    rt_aov_sample a;
    rt_aov_trace(&f.ctx, rt_ray_make(rt_v3(100, 0, 5), rt_v3(0, 0, -1), 0.0f, INFINITY), &rng, &a);
    assert_float_equal(a.albedo.x, 0.9f, 1e-6f);
    assert_float_equal(a.albedo.y, 0.8f, 1e-6f);
    assert_float_equal(a.albedo.z, 0.7f, 1e-6f);
    assert_true(a.normal.x == 0.0f && a.normal.y == 0.0f && a.normal.z == 0.0f);
    assert_true(a.depth > 4.0f && a.depth < 4.5f); /* inside the ball, close under its surface */
    test_fixture_free(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_beer_lambert_slab),
        cmocka_unit_test(test_single_scattering_slab),
        cmocka_unit_test(test_single_scattering_area_light),
        cmocka_unit_test(test_single_scattering_emissive_triangles),
        cmocka_unit_test(test_camera_inside_medium),
        cmocka_unit_test(test_aov_albedo_of_media),
        cmocka_unit_test(test_white_furnace),
        cmocka_unit_test(test_constant_grid_is_homogeneous),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
