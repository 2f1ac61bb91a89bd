/* test_gltf_ext.c - the glTF PBR-next material extensions end to end:
 * parsed into the material table (factors, textures, defaults), refused
 * with the file and byte when out of range, loaded without warnings and
 * path traced (tiny renders of the sphere rows tools/gen_ext_assets.py
 * writes to assets/ext/, checked for what each extension must do to the
 * picture), and the shared Khronos sample models that use them, when
 * ../shared has them; KHR_materials_variants through rt_load_options. */
#include "test_util.h"
#include "test_fixture.h"

#include <fcntl.h>
#include <math.h>
#include <unistd.h>

#include "rt/accel/kdtree.h"
#include "rt/image/framebuffer.h"
#include "rt/io/gltf.h"
#include "rt/io/load.h"
#include "rt/render/render.h"
#include "rt/scene/scene.h"
#include "rt/scene/validate.h"

static char tmp_dir[256];

static int setup_tmp(void **state)
{
    (void)state;
    return test_make_dir(tmp_dir, sizeof tmp_dir, "gltf_ext") ? 0 : -1;
}

static int teardown_tmp(void **state)
{
    (void)state;
    test_remove_dir(tmp_dir);
    return 0;
}

/* Loads path into a fresh scene (for rendering: with the first camera and
 * the default sky) with stderr captured; *warned is true when
 * anything was written to it (a warning). */
static rt_result load_quiet(const char *path, rt_scene *s, rt_error *err, bool *warned, bool for_render)
{
    char log[512];
    snprintf(log, sizeof log, "%s/stderr.txt", tmp_dir);
    fflush(stderr);
    int saved = dup(2);
    int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    assert_true(saved >= 0 && fd >= 0);
    dup2(fd, 2);
    close(fd);
    rt_scene_init(s);
    memset(err, 0, sizeof *err);
    rt_load_options opt = {.for_render = for_render};
    rt_result r = rt_load(s, NULL, path, &opt, NULL, err);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    FILE *f = fopen(log, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    *warned = ftell(f) > 0;
    if (*warned) {
        char buf[512] = {0};
        fseek(f, 0, SEEK_SET);
        size_t n = fread(buf, 1, sizeof buf - 1, f);
        buf[n] = 0;
        fprintf(stderr, "%s warned: %s", path, buf);
    }
    fclose(f);
    return r;
}

static const rt_material *find_material(const rt_scene *s, const char *name)
{
    for (size_t i = 0; i < s->material_count; i++)
        if (strcmp(s->materials[i].name, name) == 0)
            return &s->materials[i];
    fail_msg("no material named '%s'", name);
    return NULL;
}

static void test_parse_generated(void **state)
{
    (void)state;
    rt_scene s;
    rt_error err;
    bool warned;
    assert_int_equal(load_quiet("assets/ext/clearcoat.gltf", &s, &err, &warned, false), RT_OK);
    assert_false(warned);
    const rt_material *m = find_material(&s, "coat 0.3");
    assert_true(m->clearcoat == 1.0f && fabsf(m->clearcoat_roughness - 0.3f) < 1e-7f);
    m = find_material(&s, "no coat");
    assert_true(m->clearcoat == 0.0f && m->specular_weight == 1.0f && m->iridescence == 0.0f);
    rt_scene_free(&s);

    assert_int_equal(load_quiet("assets/ext/specular.gltf", &s, &err, &warned, false), RT_OK);
    assert_false(warned);
    m = find_material(&s, "blue F0");
    assert_true(m->specular_color.x == 0.5f && m->specular_color.z == 2.0f && m->specular_weight == 1.0f);
    assert_true(find_material(&s, "specular 0")->specular_weight == 0.0f);
    rt_scene_free(&s);

    assert_int_equal(load_quiet("assets/ext/sheen.gltf", &s, &err, &warned, false), RT_OK);
    m = find_material(&s, "gold sheen 0.5");
    assert_true(m->sheen_color.y == 0.7f && m->sheen_roughness == 0.5f);
    rt_scene_free(&s);

    assert_int_equal(load_quiet("assets/ext/anisotropy.gltf", &s, &err, &warned, false), RT_OK);
    m = find_material(&s, "strength 1, rotated");
    assert_true(m->anisotropy == 1.0f && fabsf(m->anisotropy_rotation - 1.5707963f) < 1e-6f);
    rt_scene_free(&s);

    assert_int_equal(load_quiet("assets/ext/iridescence.gltf", &s, &err, &warned, false), RT_OK);
    m = find_material(&s, "200 nm");
    assert_true(m->iridescence == 1.0f && m->iridescence_ior == 1.3f && m->iridescence_thickness_min == 100.0f &&
                m->iridescence_thickness_max == 200.0f);
    assert_true(find_material(&s, "metal 400 nm")->iridescence_ior == 1.8f);
    rt_scene_free(&s);

    assert_int_equal(load_quiet("assets/ext/transmission.gltf", &s, &err, &warned, false), RT_OK);
    assert_false(warned);
    m = find_material(&s, "half diffuse transmission");
    assert_true(m->diffuse_transmission == 0.5f && m->diffuse_transmission_color.y == 0.8f);
    assert_true(find_material(&s, "dispersive glass")->dispersion == 0.5f);
    rt_scene_free(&s);
}

/* Out-of-range factors are refused naming the file, the byte and the key. */
static void test_refused(void **state)
{
    (void)state;
    static const struct {
        const char *ext, *what;
    } bad[] = {
        {"\"KHR_materials_clearcoat\": {\"clearcoatFactor\": 1.5}", "clearcoatFactor"},
        {"\"KHR_materials_clearcoat\": {\"clearcoatRoughnessFactor\": -0.1}", "clearcoatRoughnessFactor"},
        {"\"KHR_materials_specular\": {\"specularFactor\": 2}", "specularFactor"},
        {"\"KHR_materials_specular\": {\"specularColorFactor\": [1, -1, 1]}", "specularColorFactor"},
        {"\"KHR_materials_sheen\": {\"sheenColorFactor\": [1, 1]}", "sheenColorFactor"},
        {"\"KHR_materials_sheen\": {\"sheenRoughnessFactor\": \"rough\"}", "sheenRoughnessFactor"},
        {"\"KHR_materials_anisotropy\": {\"anisotropyStrength\": 1.01}", "anisotropyStrength"},
        {"\"KHR_materials_iridescence\": {\"iridescenceIor\": 0.5}", "iridescenceIor"},
        {"\"KHR_materials_iridescence\": {\"iridescenceThicknessMinimum\": -5}", "iridescenceThicknessMinimum"},
        {"\"KHR_materials_dispersion\": {\"dispersion\": -1}", "dispersion"},
        {"\"KHR_materials_diffuse_transmission\": {\"diffuseTransmissionFactor\": 3}", "diffuseTransmissionFactor"},
        {"\"KHR_materials_clearcoat\": {\"clearcoatTexture\": {\"index\": 7}}", "texture 7 is out of range"},
        {"\"KHR_materials_sheen\": []", "expected an object"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char text[1024], path[512];
        snprintf(text, sizeof text,
                 "{\"asset\": {\"version\": \"2.0\"}, \"materials\": [{\"name\": \"m\", \"extensions\": {%s}}]}",
                 bad[i].ext);
        snprintf(path, sizeof path, "%s/bad%zu.gltf", tmp_dir, i);
        test_write_file(path, text, strlen(text));
        rt_scene s;
        rt_error err;
        bool warned;
        rt_result r = load_quiet(path, &s, &err, &warned, false);
        if (r == RT_OK || !strstr(err.message, path) || !strstr(err.message, bad[i].what) ||
            (!strstr(err.message, "byte") && !strstr(bad[i].what, "out of range")))
            fail_msg("%s: got %s \"%s\"", bad[i].ext, rt_result_name(r), err.message);
        assert_int_equal(s.material_count, 0); /* all or nothing */
        rt_scene_free(&s);
    }
}

/* Issue 25, class 6: every number the loader reads from a material, a
 * texture info or a punctual light is held to its JSON schema's range
 * (KHR_materials_ior: 0 or at least 1; emissiveStrength at least 0; ...),
 * and the error names the file, the byte and the field. */
static void test_schema_ranges(void **state)
{
    (void)state;
    static const struct {
        const char *members, *what;
    } bad[] = {
        {"\"materials\": [{\"extensions\": {\"KHR_materials_ior\": {\"ior\": -1.5}}}]",
         "materials[0].extensions.KHR_materials_ior.ior -1.5 is outside"},
        {"\"materials\": [{\"extensions\": {\"KHR_materials_ior\": {\"ior\": 0.5}}}]",
         "materials[0].extensions.KHR_materials_ior.ior 0.5 is neither 0 nor at least 1"},
        {"\"materials\": [{\"extensions\": {\"KHR_materials_emissive_strength\": {\"emissiveStrength\": -2}}}]",
         "KHR_materials_emissive_strength.emissiveStrength -2 is outside"},
        {"\"materials\": [{\"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 1.5}}}]",
         "KHR_materials_transmission.transmissionFactor 1.5 is outside [0, 1]"},
        {"\"materials\": [{\"extensions\": {\"KHR_materials_volume\": {\"thicknessFactor\": -1}}}]",
         "KHR_materials_volume.thicknessFactor -1 is outside"},
        {"\"materials\": [{\"extensions\": {\"KHR_materials_volume\": {\"attenuationColor\": [1, 2, 1]}}}]",
         "KHR_materials_volume.attenuationColor component 1 (2) is outside [0, 1]"},
        {"\"materials\": [{\"pbrMetallicRoughness\": {\"baseColorFactor\": [1, 1, 1, -0.5]}}]",
         "pbrMetallicRoughness.baseColorFactor component 3 (-0.5) is outside [0, 1]"},
        {"\"materials\": [{\"pbrMetallicRoughness\": {\"metallicFactor\": 2}}]",
         "pbrMetallicRoughness.metallicFactor 2 is outside [0, 1]"},
        {"\"materials\": [{\"pbrMetallicRoughness\": {\"roughnessFactor\": -1}}]",
         "pbrMetallicRoughness.roughnessFactor -1 is outside [0, 1]"},
        {"\"materials\": [{\"emissiveFactor\": [0, 0, 3]}]", "materials[0].emissiveFactor component 2 (3)"},
        {"\"materials\": [{\"alphaCutoff\": -0.5}]", "materials[0].alphaCutoff -0.5 is outside"},
        {"\"materials\": [{\"occlusionTexture\": {\"index\": 0, \"strength\": 1.5}}]",
         "materials[0].occlusionTexture.strength 1.5 is outside [0, 1]"},
        {"\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"point\", \"intensity\": -3}]}}",
         "KHR_lights_punctual.lights[0].intensity -3 is outside"},
        {"\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"point\", \"color\": [1, 1, 7]}]}}",
         "KHR_lights_punctual.lights[0].color component 2 (7) is outside [0, 1]"},
        {"\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"spot\", "
         "\"spot\": {\"outerConeAngle\": 2}}]}}",
         "KHR_lights_punctual.lights[0].spot.outerConeAngle 2 is outside"},
        {"\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"spot\", "
         "\"spot\": {\"innerConeAngle\": -0.1}}]}}",
         "KHR_lights_punctual.lights[0].spot.innerConeAngle -0.1 is outside"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char text[1024], path[512];
        snprintf(text, sizeof text, "{\"asset\": {\"version\": \"2.0\"}, %s}", bad[i].members);
        snprintf(path, sizeof path, "%s/range%zu.gltf", tmp_dir, i);
        test_write_file(path, text, strlen(text));
        rt_scene s;
        rt_error err;
        bool warned;
        rt_result r = load_quiet(path, &s, &err, &warned, false);
        if (r != RT_ERR_INVALID || !strstr(err.message, path) || !strstr(err.message, ": byte ") ||
            !strstr(err.message, bad[i].what))
            fail_msg("%s: got %s \"%s\", wanted \"%s\"", bad[i].members, rt_result_name(r), err.message, bad[i].what);
        rt_scene_free(&s);
    }
    /* the edges the schemas allow load */
    static const char *const good[] = {
        "\"materials\": [{\"extensions\": {\"KHR_materials_ior\": {\"ior\": 0}}}]",
        "\"materials\": [{\"extensions\": {\"KHR_materials_ior\": {\"ior\": 1}}}]",
        "\"materials\": [{\"extensions\": {\"KHR_materials_emissive_strength\": {\"emissiveStrength\": 0}}}]",
        "\"materials\": [{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0, 1, 0, 1]}, \"alphaCutoff\": 0}]",
        "\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"spot\", \"intensity\": 0, "
        "\"spot\": {\"innerConeAngle\": 0, \"outerConeAngle\": 1.5707963267948966}}]}}",
    };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        char text[1024], path[512];
        snprintf(text, sizeof text, "{\"asset\": {\"version\": \"2.0\"}, %s}", good[i]);
        snprintf(path, sizeof path, "%s/edge%zu.gltf", tmp_dir, i);
        test_write_file(path, text, strlen(text));
        rt_scene s;
        rt_error err;
        bool warned;
        rt_result r = load_quiet(path, &s, &err, &warned, false);
        if (r != RT_OK)
            fail_msg("%s: %s", good[i], err.message);
        rt_scene_free(&s);
    }
}

/* Issue 25, class 6, the audit: the rest of every extension's (and the
 * core's extension-like objects') schema ranges. Loads `members` into a
 * minimal document; a refusal must name the file, a byte and `what`. */
static void expect_range_refused(const char *members, const char *what, int i)
{
    char text[1024], path[512];
    snprintf(text, sizeof text, "{\"asset\": {\"version\": \"2.0\"}, %s}", members);
    snprintf(path, sizeof path, "%s/audit%d.gltf", tmp_dir, i);
    test_write_file(path, text, strlen(text));
    rt_scene s;
    rt_error err;
    bool warned;
    rt_result r = load_quiet(path, &s, &err, &warned, false);
    if (what && (r != RT_ERR_INVALID || !strstr(err.message, path) || !strstr(err.message, ": byte ") ||
                 !strstr(err.message, what)))
        fail_msg("%s: got %s \"%s\", wanted \"%s\"", members, rt_result_name(r), err.message, what);
    if (!what && r != RT_OK)
        fail_msg("%s: %s", members, err.message);
    rt_scene_free(&s);
}

static void test_schema_ranges_audit(void **state)
{
    (void)state;
#define LIGHT(x) "\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"point\", " x "}]}}"
#define CAMERA(x) "\"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 1, " x "}}]"
#define MATERIAL(ext, x) "\"materials\": [{\"extensions\": {\"" ext "\": {" x "}}}]"
    static const struct {
        const char *members, *what;
    } cases[] = {
        /* KHR_lights_punctual: range exclusiveMinimum 0 */
        {LIGHT("\"range\": 0"), "KHR_lights_punctual.lights[0].range must be greater than 0"},
        {LIGHT("\"range\": 0.001"), NULL},
        /* camera.perspective: aspectRatio, znear, zfar exclusiveMinimum 0; zfar > znear */
        {CAMERA("\"znear\": 0"), "cameras[0].perspective.znear 0 must be greater than 0"},
        {CAMERA("\"znear\": 0.1, \"aspectRatio\": -1.5"), "cameras[0].perspective.aspectRatio -1.5 must be greater"},
        {CAMERA("\"znear\": 0.1, \"zfar\": 0.05"), "cameras[0].perspective.zfar 0.05 must be greater than znear 0.1"},
        {CAMERA("\"znear\": 0.1, \"zfar\": 100, \"aspectRatio\": 1.5"), NULL},
        /* sampler.minFilter: the six values of the enum */
        {"\"samplers\": [{\"minFilter\": 1234}]", "samplers[0]: minFilter 1234 is not"},
        {"\"samplers\": [{\"minFilter\": 9987, \"magFilter\": 9728}]", NULL},
        /* the PBR-next extensions */
        {MATERIAL("KHR_materials_clearcoat", "\"clearcoatFactor\": 1.5"), "clearcoatFactor 1.5 is outside [0, 1]"},
        {MATERIAL("KHR_materials_specular", "\"specularColorFactor\": [1, -1, 1]"),
         "specularColorFactor component 1 (-1) is outside"},
        {MATERIAL("KHR_materials_specular", "\"specularColorFactor\": [2, 3, 4]"), NULL}, /* minimum 0, no maximum */
        {MATERIAL("KHR_materials_sheen", "\"sheenRoughnessFactor\": -0.5"), "sheenRoughnessFactor -0.5 is outside"},
        {MATERIAL("KHR_materials_anisotropy", "\"anisotropyStrength\": 2"), "anisotropyStrength 2 is outside"},
        {MATERIAL("KHR_materials_iridescence", "\"iridescenceIor\": 0.9"), "iridescenceIor 0.9 is outside"},
        {MATERIAL("KHR_materials_iridescence", "\"iridescenceThicknessMinimum\": -1"),
         "iridescenceThicknessMinimum -1 is outside"},
        {MATERIAL("KHR_materials_dispersion", "\"dispersion\": -0.1"), "dispersion -0.1 is outside"},
        {MATERIAL("KHR_materials_diffuse_transmission", "\"diffuseTransmissionColorFactor\": [1, 1, 1.5]"),
         "diffuseTransmissionColorFactor component 2 (1.5) is outside [0, 1]"},
        {MATERIAL("KHR_materials_volume", "\"attenuationDistance\": 0"), "attenuationDistance must be positive"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        expect_range_refused(cases[i].members, cases[i].what, (int)i);
#undef LIGHT
#undef CAMERA
#undef MATERIAL
}

/* Renders a generated file at W x H with the path tracer. */
enum { W = 96, H = 48 };
static void render_file(const char *path, rt_framebuffer *fb)
{
    rt_scene s;
    rt_settings set;
    rt_settings_default(&set);
    rt_error err;
    bool warned;
    assert_int_equal(load_quiet(path, &s, &err, &warned, true), RT_OK);
    assert_false(warned);
    set.width = W;
    set.height = H;
    set.samples = 64;
    set.integrator = RT_INTEGRATOR_PATH;
    test_render_scene(&s, &set, 2, 0, fb);
    for (int i = 0; i < W * H * 3; i++)
        assert_true(isfinite(fb->rgb[i]) && fb->rgb[i] >= 0.0f);
    rt_scene_free(&s);
}

/* Mean radiance over a disc at the centre of sphere k of n (the generator's
 * layout: spheres 1 apart along x, camera yfov 0.5, aspect 2, at
 * n / (4 tan 0.25) + 1.2). */
static rt_vec3 sphere_mean(const rt_framebuffer *fb, int k, int n)
{
    double dist = (n > 2 ? n : 2) / (4.0 * tan(0.25)) + 1.2;
    double x = (k - (n - 1) / 2.0) / dist; /* tan of the angle */
    double r = 0.4 / dist * 0.6;           /* inside the silhouette */
    double scale = (H / 2.0) / tan(0.25);  /* pixels per unit tangent */
    double cx = W / 2.0 + x * scale, cy = H / 2.0;
    double sum[3] = {0, 0, 0};
    int cnt = 0;
    for (int py = 0; py < H; py++)
        for (int px = 0; px < W; px++) {
            double dx = (px + 0.5 - cx) / scale, dy = (py + 0.5 - cy) / scale;
            if (dx * dx + dy * dy > r * r)
                continue;
            for (int c = 0; c < 3; c++)
                sum[c] += fb->rgb[(py * W + px) * 3 + c];
            cnt++;
        }
    assert_true(cnt > 4);
    return rt_v3((float)(sum[0] / cnt), (float)(sum[1] / cnt), (float)(sum[2] / cnt));
}

/* The spread of sphere k of n's brightness (luminance-weighted standard
 * deviation of the pixel position, in pixels) across (*sx) and up (*sy)
 * the image, over the same disc as sphere_mean: the shape of a highlight. */
static void sphere_spread(const rt_framebuffer *fb, int k, int n, double *sx, double *sy)
{
    double dist = (n > 2 ? n : 2) / (4.0 * tan(0.25)) + 1.2;
    double x = (k - (n - 1) / 2.0) / dist, r = 0.4 / dist * 0.9, scale = (H / 2.0) / tan(0.25);
    double cx = W / 2.0 + x * scale, cy = H / 2.0;
    double w = 0, mx = 0, my = 0, mxx = 0, myy = 0;
    for (int py = 0; py < H; py++)
        for (int px = 0; px < W; px++) {
            double dx = (px + 0.5 - cx) / scale, dy = (py + 0.5 - cy) / scale;
            if (dx * dx + dy * dy > r * r)
                continue;
            const float *c = fb->rgb + (py * W + px) * 3;
            double l = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
            w += l, mx += l * px, my += l * py, mxx += l * px * px, myy += l * py * py;
        }
    assert_true(w > 0);
    mx /= w, my /= w;
    *sx = sqrt(mxx / w - mx * mx);
    *sy = sqrt(myy / w - my * my);
}

static void test_render_generated(void **state)
{
    (void)state;
    rt_framebuffer fb;
    /* a coat reflects the bluish sky over the red base: more blue */
    render_file("assets/ext/clearcoat.gltf", &fb);
    rt_vec3 bare = sphere_mean(&fb, 0, 5), coat = sphere_mean(&fb, 1, 5);
    assert_true(coat.z > bare.z * 1.2f);
    rt_framebuffer_free(&fb);
    /* a white sheen brightens the dark blue cloth */
    render_file("assets/ext/sheen.gltf", &fb);
    bare = sphere_mean(&fb, 0, 4);
    rt_vec3 sheen = sphere_mean(&fb, 2, 4);
    assert_true(sheen.x + sheen.y + sheen.z > 1.1f * (bare.x + bare.y + bare.z));
    rt_framebuffer_free(&fb);
    /* specularColorFactor (0.5, 1, 2): a bluer highlight than the plain one */
    render_file("assets/ext/specular.gltf", &fb);
    rt_vec3 plain = sphere_mean(&fb, 2, 5), blue = sphere_mean(&fb, 3, 5);
    assert_true(blue.z / blue.x > plain.z / plain.x);
    rt_framebuffer_free(&fb);
    /* diffuse transmission 0, 0.5, 1: the lit side the camera sees passes
     * light into the sphere instead of reflecting it, so it darkens with the
     * factor (the diffuse reflection scales by 1 - factor; what is left is
     * the specular lobe and light coming back through; measured green
     * 0.96, 0.66, 0.39) */
    render_file("assets/ext/transmission.gltf", &fb);
    rt_vec3 opaque = sphere_mean(&fb, 0, 4), half = sphere_mean(&fb, 1, 4), full = sphere_mean(&fb, 2, 4);
    if (!(half.y < 0.85f * opaque.y && full.y < 0.75f * half.y))
        fail_msg("diffuse transmission 0, 0.5, 1: green %g, %g, %g: not darkening with the factor", opaque.y, half.y,
                 full.y);
    rt_framebuffer_free(&fb);
    /* anisotropy strength 0, 0.5, 1 and 1 rotated by 90 degrees on white
     * metal: the highlight stretches along the tangent (across the image)
     * with the strength, and up the image when rotated: the ratio of its
     * spreads across and up grows with the strength and falls below the
     * isotropic one when rotated (measured 0.91, 0.99, 1.13; 0.75) */
    render_file("assets/ext/anisotropy.gltf", &fb);
    double ratio[4];
    for (int k = 0; k < 4; k++) {
        double sx, sy;
        sphere_spread(&fb, k, 4, &sx, &sy);
        ratio[k] = sx / sy;
    }
    if (!(ratio[1] > ratio[0] + 0.03 && ratio[2] > ratio[1] + 0.03 && ratio[3] < ratio[0] - 0.05))
        fail_msg("anisotropy: highlight spread ratios %g (isotropic), %g (0.5), %g (1), %g (1, rotated)", ratio[0],
                 ratio[1], ratio[2], ratio[3]);
    rt_framebuffer_free(&fb);
    render_file("assets/ext/iridescence.gltf", &fb);
    rt_vec3 thin = sphere_mean(&fb, 0, 4), thick = sphere_mean(&fb, 2, 4);
    assert_true(fabsf(thin.x / (thin.z + 1e-6f) - thick.x / (thick.z + 1e-6f)) > 0.01f); /* the film's colour changes */
    rt_framebuffer_free(&fb);
}

/* Names of the materials of the first and last triangle (sphere 0 and the last sphere). */
static void first_last_material(const rt_scene *s, const char **first, const char **last)
{
    assert_true(s->triangles.count > 0);
    *first = s->materials[s->triangles.material[0]].name;
    *last = s->materials[s->triangles.material[s->triangles.count - 1]].name;
}

/* KHR_materials_variants (rt --variant NAME): each primitive takes the
 * material its mapping gives for the variant; others keep theirs. */
static void test_variants(void **state)
{
    (void)state;
    static const struct {
        const char *variant, *first, *last;
    } want[] = {{NULL, "grey", "grey"}, {"red", "grey", "red"}, {"blue", "blue", "grey"}};
    for (size_t i = 0; i < 3; i++) {
        rt_scene s;
        rt_scene_init(&s);
        rt_error err = {0};
        rt_load_options opt = {.variant = want[i].variant};
        assert_int_equal(rt_load(&s, NULL, "assets/ext/variants.gltf", &opt, NULL, &err), RT_OK);
        const char *first, *last;
        first_last_material(&s, &first, &last);
        if (strcmp(first, want[i].first) != 0 || strcmp(last, want[i].last) != 0)
            fail_msg("variant %s: spheres have '%s' and '%s'", want[i].variant ? want[i].variant : "(none)", first,
                     last);
        rt_scene_free(&s);
    }
    /* an unknown name lists the file's variants; a scene file refuses the flag */
    rt_scene s;
    rt_scene_init(&s);
    rt_error err = {0};
    rt_load_options opt = {.variant = "green"};
    assert_int_equal(rt_load(&s, NULL, "assets/ext/variants.gltf", &opt, NULL, &err), RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "variants.gltf"));
    assert_non_null(strstr(err.message, "'green'"));
    assert_non_null(strstr(err.message, "'red', 'blue'"));
    assert_int_equal(s.material_count, 0);
    assert_int_equal(rt_load(&s, NULL, "scenes/cornell.txt", &opt, NULL, &err), RT_ERR_INVALID);
    rt_scene_free(&s);
    /* a mapping to a material or a variant that does not exist */
    static const char *const bad[] = {
        "[{\"material\": 5, \"variants\": [0]}]",
        "[{\"material\": 0, \"variants\": [3]}]",
        "[{\"variants\": [0]}]",
    };
    for (size_t i = 0; i < 3; i++) {
        char text[2048], path[512];
        snprintf(text, sizeof text,
                 "{\"asset\": {\"version\": \"2.0\"}, \"extensions\": {\"KHR_materials_variants\": "
                 "{\"variants\": [{\"name\": \"a\"}]}}, \"materials\": [{}], \"buffers\": [{\"byteLength\": 36, "
                 "\"uri\": \"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}], "
                 "\"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}], \"accessors\": [{\"bufferView\": 0, "
                 "\"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}], "
                 "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"material\": 0, "
                 "\"extensions\": {\"KHR_materials_variants\": {\"mappings\": %s}}}]}], "
                 "\"nodes\": [{\"mesh\": 0}], \"scenes\": [{\"nodes\": [0]}]}",
                 bad[i]);
        snprintf(path, sizeof path, "%s/variants%zu.gltf", tmp_dir, i);
        test_write_file(path, text, strlen(text));
        rt_scene_init(&s);
        rt_result r = rt_load(&s, NULL, path, NULL, NULL, &err);
        if (r != RT_ERR_INVALID || !strstr(err.message, path) || !strstr(err.message, "byte"))
            fail_msg("mapping %s: got %s \"%s\"", bad[i], rt_result_name(r), err.message);
        rt_scene_free(&s);
    }
}

/* The Khronos sample models in the shared assets that use material
 * extensions (emissive strength, transmission, ior, volume, texture
 * transform): each must load
 * without a warning and render (16x16, 1 sample a pixel, the path tracer)
 * with no bad sample. (The extension test models, ClearCoatTest and the
 * like, are not in the shared assets: assets/ext's generated files above
 * cover those extensions.) */
static void test_shared_models(void **state)
{
    (void)state;
    test_require_shared();
    static const char *const models[] = {"EmissiveStrengthTest", "TransmissionTest", "TransmissionRoughnessTest",
                                         "TextureTransformTest"};
    int found = 0;
    for (size_t i = 0; i < sizeof models / sizeof models[0]; i++) {
        char rel[256], path[4200];
        const char *kinds[] = {"glTF-Binary/%s.glb", "glTF/%s.gltf", "%s.glb", "%s.gltf"};
        bool have = false;
        for (size_t k = 0; k < 4 && !have; k++) {
            char name[200];
            snprintf(name, sizeof name, kinds[k], models[i]);
            snprintf(rel, sizeof rel, "assets/gltf/%s/%s", models[i], name);
            snprintf(path, sizeof path, "%s", test_shared_path(rel));
            have = access(path, R_OK) == 0;
        }
        if (!have)
            fail_msg("%s is not in %s", models[i], test_shared_path("assets/gltf"));
        found++;
        rt_scene s;
        rt_settings set;
        rt_settings_default(&set);
        rt_error err;
        bool warned;
        assert_int_equal(load_quiet(path, &s, &err, &warned, true), RT_OK);
        assert_false(warned);
        set.width = set.height = 16;
        set.samples = 1;
        set.integrator = RT_INTEGRATOR_PATH;
        rt_framebuffer fb;
        test_render_scene(&s, &set, 2, 0, &fb);
        rt_framebuffer_free(&fb);
        rt_scene_free(&s);
    }
    assert_int_equal(found, sizeof models / sizeof models[0]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse_generated),
        cmocka_unit_test(test_refused),
        cmocka_unit_test(test_schema_ranges),
        cmocka_unit_test(test_schema_ranges_audit),
        cmocka_unit_test(test_render_generated),
        cmocka_unit_test(test_variants),
        cmocka_unit_test(test_shared_models),
    };
    return cmocka_run_group_tests_name("gltf_ext", tests, setup_tmp, teardown_tmp);
}
