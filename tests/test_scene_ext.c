/* test_scene_ext.c - the glTF material extensions written in the scene
 * format (docs/scene-format.md, section 5): every extension key parses to
 * the material the glTF loader makes from the same extension JSON (the two
 * files written here, loaded, compared field by field, textures included);
 * a row of quads with clearcoat, sheen, specular colour and iridescence
 * written as scene-text triangles path traces to the same bytes as the
 * same quads as a glTF model in the same scene; out-of-range values and
 * extension keys on another bsdf are refused naming file:line:column; a
 * material without extension keys keeps the core BSDF (not `extended`);
 * a coat ignores the base's normal map; scenes/pbr-extensions.txt loads.
 */
#include "test_util.h"
#include "test_fixture.h"

#include <math.h>

#include "rt/accel/kdtree.h"
#include "rt/image/framebuffer.h"
#include "rt/io/scene_parse.h"
#include "rt/render/material_eval.h"
#include "rt/render/render.h"
#include "rt/render/render_state.h"
#include "rt/render/surface.h"
#include "rt/scene/scene.h"
#include "rt/scene/validate.h"

static char tmp_dir[256];

static int setup_tmp(void **state)
{
    (void)state;
    if (!test_make_dir(tmp_dir, sizeof tmp_dir, "scene_ext"))
        return -1;
    /* an image both formats' textures refer to, beside the written files */
    FILE *f = fopen("assets/bumps.png", "rb");
    if (!f)
        return -1;
    static char png[1 << 20];
    size_t n = fread(png, 1, sizeof png, f);
    fclose(f);
    char path[512];
    snprintf(path, sizeof path, "%s/t.png", tmp_dir);
    test_write_file(path, png, n);
    return 0;
}

static int teardown_tmp(void **state)
{
    (void)state;
    test_remove_dir(tmp_dir);
    return 0;
}

static void load_text(rt_scene *s, const char *file, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmp_dir, file);
    test_write_file(path, text, strlen(text));
    rt_scene_init(s);
    rt_error err = {0};
    if (rt_scene_parse_file(s, NULL, path, &err) != RT_OK)
        fail_msg("%s: %s", file, err.message);
}

/* One material in both formats: scene-text keys and the glTF
 * material's "extensions" object (plus pbrMetallicRoughness). */
typedef struct pair {
    const char *keys, *ext;
} pair;

/* Every extension key, each beside its glTF property. Base colour 0.5,
 * metallic 0, roughness 0.5 in both; texture t0 is t.png, texture 0 of
 * the glTF file. */
static const pair pairs[] = {
    {"clearcoat 0.7 clearcoat_roughness 0.3 clearcoat_normal_scale 0.5 clearcoat_map t0 "
     "clearcoat_roughness_map t0 clearcoat_normal_map t0",
     "\"KHR_materials_clearcoat\": {\"clearcoatFactor\": 0.7, \"clearcoatRoughnessFactor\": 0.3, "
     "\"clearcoatTexture\": {\"index\": 0}, \"clearcoatRoughnessTexture\": {\"index\": 0}, "
     "\"clearcoatNormalTexture\": {\"index\": 0, \"scale\": 0.5}}"},
    {"specular_factor 0.4 specular_color 0.5 1 2 specular_map t0 specular_color_map t0",
     "\"KHR_materials_specular\": {\"specularFactor\": 0.4, \"specularColorFactor\": [0.5, 1, 2], "
     "\"specularTexture\": {\"index\": 0}, \"specularColorTexture\": {\"index\": 0}}"},
    {"sheen_color 0.9 0.7 0.2 sheen_roughness 0.5 sheen_color_map t0 sheen_roughness_map t0",
     "\"KHR_materials_sheen\": {\"sheenColorFactor\": [0.9, 0.7, 0.2], \"sheenRoughnessFactor\": 0.5, "
     "\"sheenColorTexture\": {\"index\": 0}, \"sheenRoughnessTexture\": {\"index\": 0}}"},
    {"anisotropy_strength 0.6 anisotropy_rotation -1.25 anisotropy_map t0",
     "\"KHR_materials_anisotropy\": {\"anisotropyStrength\": 0.6, \"anisotropyRotation\": -1.25, "
     "\"anisotropyTexture\": {\"index\": 0}}"},
    {"iridescence 0.8 iridescence_ior 1.8 iridescence_thickness 150 550 iridescence_map t0 "
     "iridescence_thickness_map t0",
     "\"KHR_materials_iridescence\": {\"iridescenceFactor\": 0.8, \"iridescenceIor\": 1.8, "
     "\"iridescenceThicknessMinimum\": 150, \"iridescenceThicknessMaximum\": 550, "
     "\"iridescenceTexture\": {\"index\": 0}, \"iridescenceThicknessTexture\": {\"index\": 0}}"},
    {"transmission 1 ior 1.6 thickness 1 dispersion 0.5",
     "\"KHR_materials_transmission\": {\"transmissionFactor\": 1}, \"KHR_materials_ior\": {\"ior\": 1.6}, "
     "\"KHR_materials_volume\": {\"thicknessFactor\": 1}, \"KHR_materials_dispersion\": {\"dispersion\": 0.5}"},
    {"transmission 1 thin_walled true dispersion 0.5",
     "\"KHR_materials_transmission\": {\"transmissionFactor\": 1}, \"KHR_materials_dispersion\": {\"dispersion\": 0.5}"},
    {"diffuse_transmission 0.5 diffuse_transmission_color 0.2 0.8 0.4 diffuse_transmission_map t0 "
     "diffuse_transmission_color_map t0",
     "\"KHR_materials_diffuse_transmission\": {\"diffuseTransmissionFactor\": 0.5, "
     "\"diffuseTransmissionColorFactor\": [0.2, 0.8, 0.4], \"diffuseTransmissionTexture\": {\"index\": 0}, "
     "\"diffuseTransmissionColorTexture\": {\"index\": 0}}"},
    {"clearcoat 0 sheen_color 0 0 0 specular_factor 1", ""}, /* the defaults: the core BSDF */
};
#define NPAIRS (sizeof pairs / sizeof *pairs)

#define SAME_F(f)                                                                                                  \
    do {                                                                                                           \
        if (a->f != b->f)                                                                                          \
            fail_msg("material %zu (%s): " #f " text %g, glTF %g", i, pairs[i].keys, (double)a->f, (double)b->f);  \
    } while (0)
#define SAME_V(f)                                                                                                  \
    do {                                                                                                           \
        SAME_F(f.x);                                                                                               \
        SAME_F(f.y);                                                                                               \
        SAME_F(f.z);                                                                                               \
    } while (0)

/* The fields the glTF BSDF and its extensions read. */
static void same_material(size_t i, const rt_material *a, const rt_material *b)
{
    SAME_V(color);
    SAME_F(metallic);
    SAME_F(roughness);
    SAME_F(ior);
    SAME_F(transmission);
    SAME_F(thickness);
    if (a->transmission > 0.0f) /* a thin wall only means something to a transmitting surface */
        SAME_F(thin_walled);
    SAME_F(clearcoat);
    SAME_F(clearcoat_roughness);
    SAME_F(clearcoat_normal_scale);
    SAME_F(specular_weight);
    SAME_V(specular_color);
    SAME_V(sheen_color);
    SAME_F(sheen_roughness);
    SAME_F(anisotropy);
    SAME_F(anisotropy_rotation);
    SAME_F(iridescence);
    SAME_F(iridescence_ior);
    SAME_F(iridescence_thickness_min);
    SAME_F(iridescence_thickness_max);
    SAME_F(dispersion);
    SAME_F(diffuse_transmission);
    SAME_V(diffuse_transmission_color);
    SAME_F(extended);
    SAME_F(bsdf);
    for (int k = 0; k < RT_XTEX_COUNT; k++) {
        SAME_F(ext_tex[k].texture);
        SAME_F(ext_tex[k].texcoord);
        for (int j = 0; j < 6; j++)
            SAME_F(ext_tex[k].uv_transform[j]);
    }
}

static void test_keys_match_gltf(void **state)
{
    (void)state;
    /* the glTF file: one material a pair, texture 0 = t.png */
    static char json[16384];
    size_t o = (size_t)snprintf(json, sizeof json,
                                "{\"asset\": {\"version\": \"2.0\"}, \"images\": [{\"uri\": \"t.png\"}], "
                                "\"textures\": [{\"source\": 0}], \"materials\": [");
    for (size_t i = 0; i < NPAIRS; i++)
        o += (size_t)snprintf(json + o, sizeof json - o,
                              "%s{\"name\": \"m%zu\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, "
                              "0.5, 1], \"metallicFactor\": 0, \"roughnessFactor\": 0.5}, \"extensions\": {%s}}",
                              i ? ", " : "", i, pairs[i].ext);
    snprintf(json + o, sizeof json - o, "]}");
    char path[512];
    snprintf(path, sizeof path, "%s/m.gltf", tmp_dir);
    test_write_file(path, json, strlen(json));
    static char text[16384];
    o = (size_t)snprintf(text, sizeof text, "texture t0 image t.png\nmodel m.gltf\n");
    for (size_t i = 0; i < NPAIRS; i++)
        o += (size_t)snprintf(text + o, sizeof text - o, "material t%zu color 0.5 0.5 0.5 roughness 0.5 %s\n", i,
                              pairs[i].keys);
    rt_scene s;
    load_text(&s, "m.txt", text);
    /* texture 0 is t0 and the glTF file's texture 0 is texture 1: the same image */
    assert_int_equal(s.texture_count, 2);
    assert_int_equal(s.material_count, 2 * NPAIRS);
    for (size_t i = 0; i < NPAIRS; i++) {
        rt_material g = s.materials[i], *t = &s.materials[NPAIRS + i];
        for (int k = 0; k < RT_XTEX_COUNT; k++)
            if (g.ext_tex[k].texture == 1)
                g.ext_tex[k].texture = 0;
        same_material(i, t, &g);
    }
    for (size_t i = 0; i + 1 < NPAIRS; i++)
        assert_true(s.materials[NPAIRS + i].extended);
    assert_false(s.materials[2 * NPAIRS - 1].extended);
    assert_int_equal(s.images[s.textures[0].image].width, s.images[s.textures[1].image].width);
    rt_scene_free(&s);
}

/* Four quads (two triangles each, tilted towards the light), one material
 * each: as scene-text triangles and as a glTF model in an otherwise
 * identical scene. */
static const char *const quad_keys[4] = {
    "color 0.6 0.05 0.05 roughness 0.6 clearcoat 1 clearcoat_roughness 0.1",
    "color 0.05 0.05 0.3 roughness 0.8 sheen_color 1 0.9 0.8 sheen_roughness 0.4",
    "color 0.5 0.5 0.5 roughness 0.3 specular_factor 0.8 specular_color 0.5 1 2",
    "color 0.02 0.02 0.02 roughness 0.2 iridescence 1 iridescence_thickness 100 420",
};
static const char *const quad_ext[4] = {
    "\"KHR_materials_clearcoat\": {\"clearcoatFactor\": 1, \"clearcoatRoughnessFactor\": 0.1}",
    "\"KHR_materials_sheen\": {\"sheenColorFactor\": [1, 0.9, 0.8], \"sheenRoughnessFactor\": 0.4}",
    "\"KHR_materials_specular\": {\"specularFactor\": 0.8, \"specularColorFactor\": [0.5, 1, 2]}",
    "\"KHR_materials_iridescence\": {\"iridescenceFactor\": 1, \"iridescenceThicknessMaximum\": 420}",
};
static const float quad_color[4][3] = {{0.6f, 0.05f, 0.05f}, {0.05f, 0.05f, 0.3f}, {0.5f, 0.5f, 0.5f},
                                       {0.02f, 0.02f, 0.02f}};
static const float quad_rough[4] = {0.6f, 0.8f, 0.3f, 0.2f};

static void quad_corners(int k, float v[4][3])
{
    float x0 = -2.0f + (float)k;
    const float c[4][3] = {{x0, -0.5f, -0.5f}, {x0 + 1, -0.5f, -0.25f}, {x0 + 1, 0.5f, 0.5f}, {x0, 0.5f, 0.25f}};
    memcpy(v, c, sizeof c);
}

/* Renders scene text (resolution RW x RH) written as file. */
enum { RW = 64, RH = 24 };
static void render_scene(const char *file, const char *text, rt_framebuffer *fb)
{
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    load_text(&s, file, text);
    test_render_scene(&s, &set, 2, 0, fb);
    rt_scene_free(&s);
}

static void test_render_matches_gltf(void **state)
{
    (void)state;
    const char *head = "resolution 64 24\nsamples 16\nintegrator path\nbackground 0.3 0.35 0.45\n"
                       "camera position 0 0.3 4 look_at 0 0 0 fov 30\n"
                       "light point 1 3 3  1 1 1  30\n";
    /* the glTF model: 16 corners, 24 uint16 indices, one primitive a quad */
    unsigned char bin[16 * 12 + 24 * 2];
    size_t o = 0;
    for (int k = 0; k < 4; k++) {
        float v[4][3];
        quad_corners(k, v);
        memcpy(bin + o, v, sizeof v);
        o += sizeof v;
    }
    for (int k = 0; k < 4; k++) {
        const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
        for (int j = 0; j < 6; j++) {
            memcpy(bin + o, &idx[j], 2); /* each primitive indexes its own accessor */
            o += 2;
        }
    }
    char *b64 = test_base64(bin, sizeof bin);
    static char json[16384];
    size_t n = (size_t)snprintf(json, sizeof json,
                                "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], "
                                "\"nodes\": [{\"mesh\": 0}], "
                                "\"buffers\": [{\"byteLength\": %zu, \"uri\": \"data:application/octet-stream;base64,%s\"}], "
                                "\"bufferViews\": [{\"buffer\": 0, \"byteLength\": 192}, "
                                "{\"buffer\": 0, \"byteOffset\": 192, \"byteLength\": 48}], \"accessors\": [",
                                sizeof bin, b64);
    free(b64);
    for (int k = 0; k < 4; k++) {
        float v[4][3];
        quad_corners(k, v);
        n += (size_t)snprintf(json + n, sizeof json - n,
                              "{\"bufferView\": 0, \"byteOffset\": %d, \"componentType\": 5126, \"count\": 4, "
                              "\"type\": \"VEC3\", \"min\": [%.9g, -0.5, -0.5], \"max\": [%.9g, 0.5, 0.5]}, ",
                              48 * k, (double)v[0][0], (double)v[1][0]);
    }
    for (int k = 0; k < 4; k++)
        n += (size_t)snprintf(json + n, sizeof json - n,
                              "{\"bufferView\": 1, \"byteOffset\": %d, \"componentType\": 5123, \"count\": 6, "
                              "\"type\": \"SCALAR\"}%s",
                              12 * k, k < 3 ? ", " : "], \"meshes\": [{\"primitives\": [");
    for (int k = 0; k < 4; k++)
        n += (size_t)snprintf(json + n, sizeof json - n,
                              "{\"attributes\": {\"POSITION\": %d}, \"indices\": %d, \"material\": %d}%s", k, 4 + k,
                              k, k < 3 ? ", " : "]}], \"materials\": [");
    for (int k = 0; k < 4; k++)
        n += (size_t)snprintf(json + n, sizeof json - n,
                              "{\"pbrMetallicRoughness\": {\"baseColorFactor\": [%.9g, %.9g, %.9g, 1], "
                              "\"metallicFactor\": 0, \"roughnessFactor\": %.9g}, \"doubleSided\": true, "
                              "\"extensions\": {%s}}%s",
                              (double)quad_color[k][0], (double)quad_color[k][1], (double)quad_color[k][2],
                              (double)quad_rough[k], quad_ext[k], k < 3 ? ", " : "]}");
    char path[512];
    snprintf(path, sizeof path, "%s/quads.gltf", tmp_dir);
    test_write_file(path, json, n);

    static char text[8192];
    n = (size_t)snprintf(text, sizeof text, "%smodel quads.gltf\n", head);
    rt_framebuffer from_gltf, from_text;
    render_scene("quads-gltf.txt", text, &from_gltf);
    n = (size_t)snprintf(text, sizeof text, "%s", head);
    for (int k = 0; k < 4; k++)
        n += (size_t)snprintf(text + n, sizeof text - n, "material q%d %s\n", k, quad_keys[k]);
    for (int k = 0; k < 4; k++) {
        float v[4][3];
        quad_corners(k, v);
        static const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
        for (int t = 0; t < 2; t++) {
            n += (size_t)snprintf(text + n, sizeof text - n, "triangle");
            for (int j = 0; j < 3; j++)
                n += (size_t)snprintf(text + n, sizeof text - n, "  %.9g %.9g %.9g", (double)v[tri[t][j]][0],
                                      (double)v[tri[t][j]][1], (double)v[tri[t][j]][2]);
            n += (size_t)snprintf(text + n, sizeof text - n, " q%d\n", k);
        }
    }
    render_scene("quads.txt", text, &from_text);
    /* the picture shows something: the quads are lit, not the background alone */
    double sum = 0;
    for (int i = 0; i < RW * RH * 3; i++)
        sum += from_text.rgb[i];
    assert_true(sum > 0.5 * RW * RH);
    assert_memory_equal(from_text.rgb, from_gltf.rgb, sizeof(float) * RW * RH * 3);
    rt_framebuffer_free(&from_gltf);
    rt_framebuffer_free(&from_text);
}

/* Out-of-range values, missing words and keys on another bsdf: refused
 * with the file, line and column of the word at fault (exit status 2 in the
 * command line: rt_result codes RT_ERR_PARSE / RT_ERR_INVALID). */
static void test_bad_values(void **state)
{
    (void)state;
    static const struct {
        const char *line, *where, *part;
    } bad[] = {
        {"material m clearcoat 1.5", "2:22", "material clearcoat must be between 0 and 1"},
        {"material m clearcoat_roughness -0.1", "2:32", "between 0 and 1"},
        {"material m specular_factor 2", "2:28", "material specular_factor must be between 0 and 1"},
        {"material m specular_color 1 -1 1", "2:29", "material specular_color (green) must be >= 0"},
        {"material m sheen_color 0.5 0.5 1.5", "2:32", "material sheen_color (blue) must be between 0 and 1"},
        {"material m sheen_roughness 2", "2:28", "between 0 and 1"},
        {"material m anisotropy_strength 1.01", "2:32", "between 0 and 1"},
        {"material m anisotropy_rotation x", "2:32", "expected a number for material anisotropy_rotation"},
        {"material m iridescence_ior 0.5", "2:28", "material iridescence_ior must be >= 1"},
        {"material m iridescence_thickness -5 400", "2:34", "(minimum, nm) must be >= 0"},
        {"material m iridescence_thickness 100", "2:37", "(maximum, nm), got end of line"},
        {"material m dispersion -1", "2:23", "material dispersion must be >= 0"},
        {"material m diffuse_transmission 3", "2:33", "between 0 and 1"},
        {"material m diffuse_transmission_color 1 1 2", "2:43", "between 0 and 1"},
        {"material m clearcoat_map nope", "2:26", "undefined texture 'nope'"},
        {"material m bsdf conductor clearcoat 1", "2:27", "'clearcoat' (a glTF material extension) needs 'bsdf gltf'"},
        {"material m sheen_color 1 1 1 bsdf plastic", "2:12", "'sheen_color' (a glTF material extension) needs"},
        {"material m clearcoat 1 clearcoat 0.5", "2:24", "'clearcoat' is given twice"},
        {"material m clearcoat_roughnes 0.5", "2:12", "did you mean 'clearcoat_roughness'"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        char text[256], path[512];
        snprintf(text, sizeof text, "# a bad extension value on the next line\n%s\n", bad[i].line);
        snprintf(path, sizeof path, "%s/bad.txt", tmp_dir);
        test_write_file(path, text, strlen(text));
        rt_scene s;
        rt_scene_init(&s);
        rt_error err = {0};
        rt_result r = rt_scene_parse_file(&s, NULL, path, &err);
        char prefix[600];
        snprintf(prefix, sizeof prefix, "%s:%s: ", path, bad[i].where);
        if (r == RT_OK || strncmp(err.message, prefix, strlen(prefix)) != 0 || !strstr(err.message, bad[i].part))
            fail_msg("'%s': expected '%s...%s', got %s '%s'", bad[i].line, prefix, bad[i].part, rt_result_name(r),
                     err.message);
        assert_int_equal(s.material_count, 0); /* nothing half-made */
        rt_scene_free(&s);
    }
}

/* A material's extension keys at their defaults, or none: the core BSDF
 * (not extended), so such scenes keep today's bytes; one key is enough to
 * turn the layering on, as in the glTF loader. */
static void test_extended_flag(void **state)
{
    (void)state;
    rt_scene s;
    load_text(&s, "flag.txt",
              "material plain\n"
              "material defaults clearcoat 0 specular_factor 1 specular_color 1 1 1 sheen_color 0 0 0 "
              "iridescence_thickness 100 400 clearcoat_roughness 0.5\n"
              "material coat clearcoat 0.25\n"
              "material dispersive transmission 1 dispersion 0.3\n"
              "material not_dispersive dispersion 0.3\n");
    assert_false(s.materials[0].extended);
    assert_false(s.materials[1].extended);
    assert_true(s.materials[2].extended);
    assert_true(s.materials[3].extended);
    assert_false(s.materials[4].extended); /* dispersion needs transmission */
    /* whitted: specular_factor scales the Phong weight unless `specular` is given */
    rt_scene_free(&s);
    load_text(&s, "phong.txt",
              "material a specular_factor 0.5\n"
              "material b specular_color 2 2 2\n"
              "material c specular_factor 0.5 specular 0.3\n"
              "material d\n");
    float ks = s.materials[3].specular;
    assert_float_equal(s.materials[0].specular, 0.5f * ks, 1e-7);
    assert_float_equal(s.materials[1].specular, 2.0f * ks, 1e-7);
    assert_float_equal(s.materials[2].specular, 0.3f, 0);
    rt_scene_free(&s);
}

/* KHR_materials_clearcoat: the coat takes no texture from the material
 * below it, so a base normal map tilts the base's normal but not the
 * coat's, which keeps the interpolated normal (or follows its own map). */
static void test_coat_ignores_base_normal_map(void **state)
{
    (void)state;
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    /* a constant normal map tilting the normal by atan(0.6 / 0.4) towards +u */
    load_text(&s, "coat.txt",
              "texture tilt constant 0.8 0.5 0.7\n"
              "texture flat constant 0.5 0.5 1\n"
              "material bumpy clearcoat 1 normal_map tilt\n"
              "material both clearcoat 1 normal_map tilt clearcoat_normal_map flat\n"
              "material coat_map clearcoat 1 normal_map flat clearcoat_normal_map tilt\n"
              "quad -1 -1 0  2 0 0  0 2 0  bumpy\n"
              "quad -1 -1 1  2 0 0  0 2 0  both\n"
              "quad -1 -1 2  2 0 0  0 2 0  coat_map\n");
    rt_error err = {0};
    assert_int_equal(rt_scene_validate(&s, &err), RT_OK);
    rt_render_state rs;
    assert_int_equal(rt_render_state_prepare(&rs, &s, &set, NULL, 0, &err), RT_OK);
    rt_trace_ctx ctx;
    rt_trace_ctx_init(&ctx, &rs);
    rt_vec3 tilted = rt_normalize(rt_v3(0.6f, 0.0f, 0.4f));
    for (uint32_t q = 0; q < 3; q++) {
        rt_vec3 p = rt_v3(0.1f, 0.2f, (float)q);
        rt_vec3 dir = rt_normalize(rt_v3(0.1f, 0.05f, -1.0f));
        rt_ray r = rt_ray_make(rt_sub(p, rt_scale(dir, 3.0f)), dir, 0.0f, INFINITY);
        rt_hit h = {3.0f, 0.55f, 0.6f, q, 0}; /* quads are the only primitives: ids 0, 1, 2 */
        rt_surface sf;
        rt_surface_at(&ctx, &r, &h, &sf);
        rt_bsdf b;
        rt_bsdf_from_surface(&ctx, &sf, &b);
        assert_true((b.kind == RT_BSDF_KIND_GLTF_LAYERED) && b.clearcoat == 1.0f);
        rt_vec3 coat = rt_bsdf_to_world(&b, b.cc_n), base = b.n;
        rt_vec3 want_base = q == 2 ? rt_v3(0, 0, 1) : tilted, want_coat = q == 2 ? tilted : rt_v3(0, 0, 1);
        if (rt_length(rt_sub(base, want_base)) > 1e-5f || rt_length(rt_sub(coat, want_coat)) > 1e-5f)
            fail_msg("quad %u: base normal (%g %g %g), coat normal (%g %g %g)", q, (double)base.x, (double)base.y,
                     (double)base.z, (double)coat.x, (double)coat.y, (double)coat.z);
    }
    rt_render_state_free(&rs);
    rt_scene_free(&s);
}

/* scenes/pbr-extensions.txt, the material grid of the README: every
 * sphere but the two references (plain paint, bare velvet) and the floor
 * takes the layered path. */
static void test_shipped_scene(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    rt_error err = {0};
    assert_int_equal(rt_scene_parse_file(&s, NULL, "scenes/pbr-extensions.txt", &err), RT_OK);
    size_t extended = 0;
    for (size_t i = 0; i < s.material_count; i++)
        extended += s.materials[i].extended;
    assert_int_equal(s.spheres.count, 15);
    assert_int_equal(extended, 13);
    assert_int_equal(rt_scene_validate(&s, &err), RT_OK);
    rt_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_keys_match_gltf),
        cmocka_unit_test(test_render_matches_gltf),
        cmocka_unit_test(test_bad_values),
        cmocka_unit_test(test_extended_flag),
        cmocka_unit_test(test_coat_ignores_base_normal_map),
        cmocka_unit_test(test_shipped_scene),
    };
    return cmocka_run_group_tests_name("scene_ext", tests, setup_tmp, teardown_tmp);
}
