/* test_subsurface.c - random-walk subsurface scattering
 * (rt/scene/subsurface.h, docs/media.md section 5), held to closed forms
 * and to the media it is made of:
 * - the single-scattering albedo inverts van de Hulst's albedo of a
 *   semi-infinite medium (the curve it is defined by), stays within 0.002
 *   of Christensen and Burley's fit that Cycles uses, and is 0 at 0 and 1
 *   at 1;
 * - the scene format's subsurface keys make the medium the mapping says
 *   (sigma_t = 1 / (d s(A)), the reduced scattering coefficient kept for
 *   g != 0) as the interior of a dielectric;
 * - white furnaces: a sphere of albedo-1 subsurface material under a
 *   uniform sky of 1 stays 1, behind an index-matched boundary and behind
 *   a smooth glass one of index 1.5 (internal reflection, 1 / eta^2
 *   radiance scaling);
 * - behind an index-matched dielectric the walk is the walk behind a null
 *   boundary: the same scene with the same medium under `bsdf null`
 *   renders the same means, lit by a point light over a floor;
 * - glTF: KHR_materials_volume_scatter with KHR_materials_volume becomes
 *   the extension's medium (sigma_t from the attenuation, the
 *   single-scattering albedo from multiscatterColor), the attenuation
 *   moves into it, KHR_materials_volume alone keeps its Beer-Lambert
 *   attenuation, a white scattering glTF cube stays 1 in the furnace, and
 *   out-of-range values are refused naming the file and the key.
 * Means are over 20,000 to 30,000 paths along one camera ray, within four
 * standard errors (and 0.2%).
 */
#include "test_util.h"

#include <math.h>

#include "rt/io/load.h"
#include "rt/render/volpath.h"
#include "rt/scene/subsurface.h"
#include "test_fixture.h"
#include "test_volpath_estimate.h"

static char tmp_dir[256];

static int setup(void **state)
{
    (void)state;
    return test_make_dir(tmp_dir, sizeof tmp_dir, "subsurface") ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    test_remove_dir(tmp_dir);
    return 0;
}

/* van de Hulst's albedo of a semi-infinite isotropic medium of
 * single-scattering albedo alpha. */
static double van_de_hulst(double alpha)
{
    double s = sqrt(1.0 - alpha);
    return (1.0 - s) * (1.0 - 0.139 * s) / (1.0 + 1.17 * s);
}

static void test_single_albedo(void **state)
{
    (void)state;
    for (int i = 0; i <= 100; i++) {
        double alpha = i / 100.0;
        float back = rt_subsurface_single_albedo((float)van_de_hulst(alpha));
        assert_float_equal(back, alpha, 2e-5);
    }
    assert_float_equal(rt_subsurface_single_albedo(0.0f), 0.0f, 1e-5);
    assert_true(rt_subsurface_single_albedo(1.0f) == 1.0f); /* white loses nothing */
    assert_true(rt_subsurface_single_albedo(2.0f) == 1.0f && rt_subsurface_single_albedo(-1.0f) < 1e-5f);
    float prev = -1.0f;
    for (int i = 0; i <= 1000; i++) {
        float A = i / 1000.0f, a = rt_subsurface_single_albedo(A);
        float cb = 1.0f - expf(A * (-5.09406f + A * (2.61188f - A * 4.31805f))); /* Cycles' fit */
        assert_true(fabsf(a - cb) < 0.002f);
        assert_true(a >= prev);
        prev = a;
    }
    assert_float_equal(rt_subsurface_radius_scale(0.8f), 1.1f, 1e-6);
    assert_float_equal(rt_subsurface_radius_scale(0.0f), 1.9f + 3.5f * 0.64f, 1e-6);
}

static void test_keys_make_the_medium(void **state)
{
    (void)state;
    test_fixture f;
    test_fixture_parse(&f, "material wax bsdf dielectric ior 1.4 subsurface_albedo 0.9 0.5 0.2 "
                           "subsurface_radius 1 0.5 0.25\n"
                           "material jade bsdf dielectric subsurface_albedo 0.9 0.5 0.2 subsurface_radius 1 0.5 0.25 "
                           "subsurface_g 0.5\n"
                           "material plain bsdf dielectric\n");
    assert_int_equal(f.s.medium_count, 2);
    const rt_material *wax = &f.s.materials[0], *jade = &f.s.materials[1];
    assert_true(wax->interior_medium == 0 && jade->interior_medium == 1);
    assert_int_equal(f.s.materials[2].interior_medium, RT_NONE);
    assert_true(rt_scene_has_media(&f.s));
    const float A[3] = {0.9f, 0.5f, 0.2f}, d[3] = {1.0f, 0.5f, 0.25f};
    const rt_medium_def *m0 = &f.s.media[0], *m1 = &f.s.media[1];
    const float sa0[3] = {m0->sigma_a.x, m0->sigma_a.y, m0->sigma_a.z};
    const float ss0[3] = {m0->sigma_s.x, m0->sigma_s.y, m0->sigma_s.z};
    const float sa1[3] = {m1->sigma_a.x, m1->sigma_a.y, m1->sigma_a.z};
    const float ss1[3] = {m1->sigma_s.x, m1->sigma_s.y, m1->sigma_s.z};
    for (int k = 0; k < 3; k++) {
        float s = 1.9f - A[k] + 3.5f * (A[k] - 0.8f) * (A[k] - 0.8f);
        float sigma_t = 1.0f / (d[k] * s), alpha = rt_subsurface_single_albedo(A[k]);
        assert_float_equal(sa0[k] + ss0[k], sigma_t, 1e-5f * sigma_t);
        assert_float_equal(ss0[k] / (sa0[k] + ss0[k]), alpha, 1e-5);
        /* g 0.5: the same absorption, the same reduced scattering */
        assert_float_equal(sa1[k], sa0[k], 1e-6f * sigma_t);
        assert_float_equal(ss1[k] * 0.5f, ss0[k], 1e-5f * sigma_t);
    }
    assert_true(m0->g == 0.0f && m1->g == 0.5f && m0->kind == RT_MEDIUM_HOMOGENEOUS);
    rt_scene_free(&f.s);
}

static void test_white_furnace(void **state)
{
    (void)state;
    static const char *const boundaries[] = {"ior 1", "ior 1.5"};
    for (int i = 0; i < 2; i++) {
        char text[512];
        snprintf(text, sizeof text,
                 "sampler independent\nbackground 1 1 1\n"
                 "material white bsdf dielectric %s subsurface_albedo 1 1 1 subsurface_radius 0.5 1 2 "
                 "subsurface_g 0.3\n"
                 "sphere 0 0 0 1 white\n",
                 boundaries[i]);
        test_fixture f;
        test_fixture_load(&f, text, RT_PREPARE_LIGHT_TABLE);
        char what[64];
        snprintf(what, sizeof what, "furnace, %s, through the centre", boundaries[i]);
        test_expect_near(what, test_estimate_ray(&f, rt_v3(0, 0, 4), rt_v3(0, 0, -1), 100000, 4321), rt_v3s(1.0f));
        snprintf(what, sizeof what, "furnace, %s, off centre", boundaries[i]);
        test_expect_near(what, test_estimate_ray(&f, rt_v3(0.6f, 0.3f, 4), rt_v3(0, 0, -1), 100000, 4321), rt_v3s(1.0f));
        test_fixture_free(&f);
    }
}

/* Behind an index-matched dielectric the walk is the null boundary's. */
static void test_index_matched_is_the_medium(void **state)
{
    (void)state;
    const char *lit = "sampler independent\nbackground 0.1 0.15 0.2\n"
                      "material floor color 0.7 0.7 0.7 bsdf lambert\n"
                      "quad -5 -1 -5  0 0 10  10 0 0  floor\n"
                      "light point 0.5 3 1  1 1 1  20\n";
    char sss_text[1024], null_text[1024];
    snprintf(sss_text, sizeof sss_text,
             "%smaterial skin bsdf dielectric ior 1 subsurface_albedo 0.8 0.5 0.3 subsurface_radius 0.4 0.3 0.2 "
             "subsurface_g -0.2\nsphere 0 0 0 0.8 skin\n",
             lit);
    test_fixture sss, null;
    test_fixture_load(&sss, sss_text, RT_PREPARE_LIGHT_TABLE);
    const rt_medium_def *m = &sss.s.media[0];
    snprintf(null_text, sizeof null_text,
             "%smedium same homogeneous sigma_a %.9g %.9g %.9g sigma_s %.9g %.9g %.9g g %.9g\n"
             "material box bsdf null interior same\nsphere 0 0 0 0.8 box\n",
             lit, (double)m->sigma_a.x, (double)m->sigma_a.y, (double)m->sigma_a.z, (double)m->sigma_s.x,
             (double)m->sigma_s.y, (double)m->sigma_s.z, (double)m->g);
    test_fixture_load(&null, null_text, RT_PREPARE_LIGHT_TABLE);
    const rt_vec3 org[2] = {rt_v3(0, 0, 4), rt_v3(0.4f, 0.5f, 4)};
    for (int k = 0; k < 2; k++) {
        test_estimate a = test_estimate_ray(&null, org[k], rt_v3(0, 0, -1), 30000, 4321);
        test_estimate b = test_estimate_ray(&sss, org[k], rt_v3(0, 0, -1), 30000, 4321);
        rt_vec3 se = rt_v3(hypotf(a.se.x, b.se.x), hypotf(a.se.y, b.se.y), hypotf(a.se.z, b.se.z));
        test_expect_near("subsurface behind ior 1 against the medium behind a null boundary", (test_estimate){b.mean, se},
                    a.mean);
        assert_true(rt_fminf(a.mean.x, rt_fminf(a.mean.y, a.mean.z)) > 0.02f); /* light did arrive */
    }
    test_fixture_free(&sss);
    test_fixture_free(&null);
}

/* A glTF cube [-1, 1]^3 (eight corners, twelve triangles wound outwards)
 * with one material whose extensions object is `ext`, written to
 * tmp_dir/name. */
static void write_cube_gltf(const char *name, const char *ext, char *path, size_t path_size)
{
    float pos[24];
    for (int i = 0; i < 8; i++) {
        pos[3 * i + 0] = (i & 1) ? 1.0f : -1.0f;
        pos[3 * i + 1] = (i & 2) ? 1.0f : -1.0f;
        pos[3 * i + 2] = (i & 4) ? 1.0f : -1.0f;
    }
    static const uint16_t idx[36] = {0, 2, 1, 1, 2, 3, /* -z */ 4, 5, 6, 5, 7, 6, /* +z */
                                     0, 1, 4, 1, 5, 4, /* -y */ 2, 6, 3, 3, 6, 7, /* +y */
                                     0, 4, 2, 2, 4, 6, /* -x */ 1, 3, 5, 3, 7, 5 /* +x */};
    unsigned char bin[24 * 4 + 36 * 2];
    memcpy(bin, pos, sizeof pos);
    memcpy(bin + sizeof pos, idx, sizeof idx);
    char *b64 = test_base64(bin, sizeof bin);
    char text[4096];
    snprintf(text, sizeof text,
             "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],"
             "\"nodes\": [{\"mesh\": 0}], \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0},"
             "\"indices\": 1, \"material\": 0}]}],"
             "\"materials\": [{\"name\": \"m\", \"pbrMetallicRoughness\": {\"metallicFactor\": 0,"
             "\"roughnessFactor\": 0}, \"extensions\": {%s}}],"
             "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 8, \"type\": \"VEC3\","
             "\"min\": [-1, -1, -1], \"max\": [1, 1, 1]},"
             "{\"bufferView\": 1, \"componentType\": 5123, \"count\": 36, \"type\": \"SCALAR\"}],"
             "\"bufferViews\": [{\"buffer\": 0, \"byteLength\": 96}, {\"buffer\": 0, \"byteOffset\": 96,"
             "\"byteLength\": 72}],"
             "\"buffers\": [{\"byteLength\": %zu, \"uri\": \"data:application/octet-stream;base64,%s\"}]}",
             ext, sizeof bin, b64);
    free(b64);
    snprintf(path, path_size, "%s/%s", tmp_dir, name);
    test_write_file(path, text, strlen(text));
}

static void test_gltf_volume_scatter(void **state)
{
    (void)state;
    char path[512], text[1024];
    write_cube_gltf("scatter.gltf",
                    "\"KHR_materials_transmission\": {\"transmissionFactor\": 1},"
                    "\"KHR_materials_volume\": {\"thicknessFactor\": 2, \"attenuationColor\": [0.5, 0.25, 0.8],"
                    "\"attenuationDistance\": 0.5},"
                    "\"KHR_materials_volume_scatter\": {\"multiscatterColor\": [0.9, 0.4, 0.1],"
                    "\"scatterAnisotropy\": -0.4}",
                    path, sizeof path);
    test_fixture f;
    snprintf(text, sizeof text, "model %s\n", path);
    test_fixture_parse(&f, text);
    assert_int_equal(f.s.medium_count, 1);
    const rt_material *mat = &f.s.materials[0];
    assert_int_equal(mat->interior_medium, 0);
    assert_true(isinf(mat->attenuation_distance)); /* the medium attenuates now, not Beer-Lambert besides */
    const rt_medium_def *m = &f.s.media[0];
    const float c[3] = {0.5f, 0.25f, 0.8f}, ms[3] = {0.9f, 0.4f, 0.1f};
    const float sa[3] = {m->sigma_a.x, m->sigma_a.y, m->sigma_a.z}, ss[3] = {m->sigma_s.x, m->sigma_s.y, m->sigma_s.z};
    for (int k = 0; k < 3; k++) {
        float sigma_t = -logf(c[k]) / 0.5f;
        assert_float_equal(sa[k] + ss[k], sigma_t, 1e-5f * sigma_t);
        assert_float_equal(ss[k] / sigma_t, rt_subsurface_single_albedo(ms[k]), 1e-5);
    }
    assert_float_equal(m->g, -0.4f, 1e-7);
    rt_scene_free(&f.s);

    /* KHR_materials_volume alone: Beer-Lambert attenuation, no medium */
    write_cube_gltf("volume.gltf",
                    "\"KHR_materials_transmission\": {\"transmissionFactor\": 1},"
                    "\"KHR_materials_volume\": {\"thicknessFactor\": 2, \"attenuationColor\": [0.5, 0.25, 0.8],"
                    "\"attenuationDistance\": 0.5}",
                    path, sizeof path);
    snprintf(text, sizeof text, "model %s\n", path);
    test_fixture_parse(&f, text);
    assert_true(f.s.medium_count == 0 && f.s.materials[0].interior_medium == RT_NONE);
    assert_float_equal(f.s.materials[0].attenuation_distance, 0.5f, 0);
    rt_scene_free(&f.s);

    /* thin-walled (no thickness): no volume, so nothing scatters inside */
    write_cube_gltf("thin.gltf",
                    "\"KHR_materials_volume\": {\"attenuationColor\": [0.5, 0.5, 0.5], \"attenuationDistance\": 1},"
                    "\"KHR_materials_volume_scatter\": {\"multiscatterColor\": [1, 1, 1]}",
                    path, sizeof path);
    snprintf(text, sizeof text, "model %s\n", path);
    test_fixture_parse(&f, text);
    assert_int_equal(f.s.medium_count, 0);
    rt_scene_free(&f.s);
}

/* A white scattering glTF cube, index-matched, in the furnace. */
static void test_gltf_white_furnace(void **state)
{
    (void)state;
    static const char *const boundaries[] = {"\"KHR_materials_transmission\": {\"transmissionFactor\": 1}",
                                             "\"KHR_materials_diffuse_transmission\": "
                                             "{\"diffuseTransmissionFactor\": 1}"};
    for (int i = 0; i < 2; i++) {
        char path[512], text[1024], ext[1024];
        snprintf(ext, sizeof ext,
                 "%s, \"KHR_materials_ior\": {\"ior\": %s},"
                 "\"KHR_materials_volume\": {\"thicknessFactor\": 2, \"attenuationColor\": [0.2, 0.4, 0.6],"
                 "\"attenuationDistance\": 0.5},"
                 "\"KHR_materials_volume_scatter\": {\"multiscatterColor\": [1, 1, 1], \"scatterAnisotropy\": 0.5}",
                 boundaries[i], i == 0 ? "1" : "1.5");
        write_cube_gltf("white.gltf", ext, path, sizeof path);
        snprintf(text, sizeof text, "sampler independent\nbackground 1 1 1\nmodel %s\n", path);
        test_fixture f;
        test_fixture_load(&f, text, RT_PREPARE_LIGHT_TABLE);
        assert_int_equal(f.s.medium_count, 1);
        test_expect_near(i == 0 ? "glTF furnace, transmission, ior 1" : "glTF furnace, diffuse transmission",
                    test_estimate_ray(&f, rt_v3(0.3f, 0.2f, 4), rt_v3(0, 0, -1), 100000, 4321), rt_v3s(1.0f));
        test_fixture_free(&f);
    }
}

static void test_gltf_refused(void **state)
{
    (void)state;
    static const struct {
        const char *ext, *what;
    } bad[] = {
        {"\"KHR_materials_volume_scatter\": {\"multiscatterColor\": [1.5, 0, 0]}", "multiscatterColor"},
        {"\"KHR_materials_volume_scatter\": {\"multiscatterColor\": [1, 0]}", "multiscatterColor"},
        {"\"KHR_materials_volume_scatter\": {\"scatterAnisotropy\": -1.5}", "scatterAnisotropy"},
        {"\"KHR_materials_volume_scatter\": {\"scatterAnisotropy\": \"forward\"}", "scatterAnisotropy"},
        {"\"KHR_materials_volume_scatter\": [0.5]", "expected an object"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char path[512], name[32];
        snprintf(name, sizeof name, "bad%zu.gltf", i);
        write_cube_gltf(name, bad[i].ext, path, sizeof path);
        rt_scene s;
        rt_error err;
        rt_scene_init(&s);
        memset(&err, 0, sizeof err);
        rt_load_options opt = {0};
        rt_result r = rt_load(&s, NULL, path, &opt, NULL, &err);
        if (r == RT_OK || !strstr(err.message, path) || !strstr(err.message, bad[i].what))
            fail_msg("%s: got %d '%s'", bad[i].ext, r, err.message);
        rt_scene_free(&s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_single_albedo),
        cmocka_unit_test(test_keys_make_the_medium),
        cmocka_unit_test(test_white_furnace),
        cmocka_unit_test(test_index_matched_is_the_medium),
        cmocka_unit_test(test_gltf_volume_scatter),
        cmocka_unit_test(test_gltf_white_furnace),
        cmocka_unit_test(test_gltf_refused),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
