/* test_validate.c - rt_scene_validate (src/scene/validate.c).
 *
 * One test per rule: a small valid scene built in code (every kind of
 * primitive, texture and light) is broken in exactly one way, and the
 * error must be RT_ERR_INVALID with a message naming the record and the
 * problem. Then every shipped scene, the built-in one, the models in
 * assets/ and (when present) a few shared models validate as loaded.
 */
#include "test_util.h"

#include <dirent.h>
#include <math.h>

#include "rt/io/scene_parse.h"
#include "rt/scene/texture.h"
#include "rt/scene/validate.h"

/* A valid scene: material 0 with a base colour texture (an image) and a
 * checker normal map, a triangle, a sphere, a quad that is an area
 * light's, a point light, an environment texture. */
static void valid_scene(rt_scene *s)
{
    rt_scene_init(s);
    rt_image img;
    memset(&img, 0, sizeof img);
    img.width = img.height = 1;
    img.rgba8 = calloc(4, 1);
    assert_non_null(img.rgba8);
    snprintf(img.name, sizeof img.name, "px");
    uint32_t im = rt_scene_add_image(s, &img);
    assert_int_not_equal(im, RT_NONE);
    rt_texture ti = rt_texture_image(im);
    rt_texture tc = rt_texture_checker(rt_v4(0.5f, 0.5f, 1, 1), rt_v4(1, 1, 1, 1), 4.0f);
    uint32_t t0 = rt_scene_add_texture(s, &ti), t1 = rt_scene_add_texture(s, &tc);
    assert_true(t0 != RT_NONE && t1 != RT_NONE);
    rt_material m;
    rt_material_default(&m, "m");
    m.base_color_tex.texture = t0;
    m.normal_tex.texture = t1;
    uint32_t mi = rt_scene_add_material(s, &m);
    assert_int_equal(mi, 0);
    uint32_t v = rt_scene_add_vertices(s, 3);
    assert_int_equal(v, 0);
    s->vertices.position[0] = rt_v3(0, 0, 0);
    s->vertices.position[1] = rt_v3(1, 0, 0);
    s->vertices.position[2] = rt_v3(0, 1, 0);
    assert_int_not_equal(rt_scene_add_triangle(s, 0, 1, 2, mi, RT_TRI_UV), RT_NONE);
    assert_int_not_equal(rt_scene_add_sphere(s, rt_v3(0, 0, -3), 1.0f, mi), RT_NONE);
    uint32_t q = rt_scene_add_quad(s, rt_v3(-1, 3, -1), rt_v3(2, 0, 0), rt_v3(0, 0, 2), mi);
    assert_int_equal(q, 0);
    rt_light l;
    memset(&l, 0, sizeof l);
    l.kind = RT_LIGHT_AREA;
    l.color = rt_v3s(1);
    l.intensity = 5.0f;
    l.position = rt_v3(-1, 3, -1);
    l.edge_u = rt_v3(2, 0, 0);
    l.edge_v = rt_v3(0, 0, 2);
    l.quad = q;
    assert_int_not_equal(rt_scene_add_light(s, &l), RT_NONE);
    memset(&l, 0, sizeof l);
    l.kind = RT_LIGHT_POINT;
    l.color = rt_v3s(1);
    l.intensity = 2.0f;
    l.position = rt_v3(0, 2, 2);
    l.quad = RT_NONE;
    assert_int_not_equal(rt_scene_add_light(s, &l), RT_NONE);
    s->environment.environment_texture = t1;
}

/* The scene must fail validation with RT_ERR_INVALID and a message
 * containing `part`; the scene is freed. */
#define expect_invalid(s, part) expect_invalid_at(s, part, __LINE__)
static void expect_invalid_at(rt_scene *s, const char *part, int line)
{
    rt_error err;
    memset(&err, 0, sizeof err);
    rt_result r = rt_scene_validate(s, &err);
    if (r != RT_ERR_INVALID || !strstr(err.message, part))
        fail_msg("line %d: expected RT_ERR_INVALID with \"%s\", got %d \"%s\"", line, part, (int)r, err.message);
    rt_scene_free(s);
}

static void test_valid_scenes_pass(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    rt_error err;
    assert_int_equal(rt_scene_validate(&s, &err), RT_OK);
    rt_scene_free(&s);
    /* an empty scene (only a background) needs no material */
    rt_scene_init(&s);
    assert_int_equal(rt_scene_validate(&s, &err), RT_OK);
    rt_scene_free(&s);
}

static void test_primitives_need_a_material(void **state)
{
    (void)state;
    rt_scene s;
    rt_scene_init(&s);
    assert_int_not_equal(rt_scene_add_sphere(&s, rt_v3(0, 0, 0), 1.0f, 0), RT_NONE);
    expect_invalid(&s, "the scene has 1 primitive but no materials");
}

static void test_triangle_vertex_index(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    s.triangles.index[1] = 7;
    expect_invalid(&s, "triangle 0: vertex index 7 is out of range (3 vertices)");
}

static void test_triangle_material(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    s.triangles.material[0] = 3;
    expect_invalid(&s, "triangle 0: material 3 is out of range (1 material)");
}

static void test_triangle_attribute_flags(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    s.triangles.flags[0] |= RT_TRI_TANGENT;
    expect_invalid(&s, "triangle 0: flagged with tangents, but the vertices have none");
    valid_scene(&s);
    s.triangles.flags[0] |= RT_TRI_COLOR;
    expect_invalid(&s, "triangle 0: flagged with colours, but the vertices have none");
}

static void test_vertex_finite(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    s.vertices.position[2].y = NAN;
    expect_invalid(&s, "vertex 2: position is not finite");
}

static void test_sphere_material_and_finite(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    s.spheres.material[0] = RT_NONE;
    expect_invalid(&s, "sphere 0: material 4294967295 is out of range (1 material)");
    valid_scene(&s);
    s.spheres.radius[0] = INFINITY;
    expect_invalid(&s, "sphere 0: centre or radius is not finite");
}

static void test_quad_material_and_finite(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    s.quads.material[0] = 1;
    expect_invalid(&s, "quad 0: material 1 is out of range (1 material)");
    valid_scene(&s);
    s.quads.vy[0] = -INFINITY;
    expect_invalid(&s, "quad 0: corner or edges are not finite");
}

static void test_material_texture_slots(void **state)
{
    (void)state;
    static const char *const names[] = {"base colour", "metallic-roughness", "normal",
                                        "occlusion",   "emissive",           "transmission"};
    for (int k = 0; k < 6; k++) {
        rt_scene s;
        valid_scene(&s);
        rt_material *m = &s.materials[0];
        rt_texture_slot *slots[] = {&m->base_color_tex, &m->metal_rough_tex, &m->normal_tex,
                                    &m->occlusion_tex,  &m->emissive_tex,    &m->transmission_tex};
        slots[k]->texture = 9;
        char want[128];
        snprintf(want, sizeof want, "material 0 ('m'): %s texture 9 is out of range (2 textures)", names[k]);
        expect_invalid(&s, want);
    }
    rt_scene s;
    valid_scene(&s);
    s.materials[0].normal_tex.texcoord = 2;
    expect_invalid(&s, "material 0 ('m'): normal texture uses UV set 2");
}

static void test_material_finite(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    s.materials[0].emission_strength = NAN;
    expect_invalid(&s, "material 0 ('m'): colour or emission is not finite");
}

static void test_texture_kind_and_image(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    s.textures[1].kind = (rt_texture_kind)7;
    expect_invalid(&s, "texture 1: unknown kind 7");
    valid_scene(&s);
    s.textures[0].image = 2;
    expect_invalid(&s, "texture 0: image 2 is out of range (1 image)");
}

static void test_image_pixels(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    free(s.images[0].rgba8);
    s.images[0].rgba8 = NULL;
    expect_invalid(&s, "image 0 ('px'): no pixels");
}

static void test_light_kind_and_finite(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    s.lights[1].kind = (rt_light_kind)9;
    expect_invalid(&s, "light 1: unknown kind 9");
    valid_scene(&s);
    s.lights[1].intensity = INFINITY;
    expect_invalid(&s, "light 1: a colour, intensity, position, direction or edge is not finite");
}

static void test_light_quads(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    s.lights[0].quad = 5;
    expect_invalid(&s, "light 0: area light's quad 5 is out of range (1 quad)");
    valid_scene(&s);
    s.lights[1].quad = 0;
    expect_invalid(&s, "light 1: only area lights have a quad (it names quad 0)");
    valid_scene(&s);
    rt_light twin = s.lights[0];
    assert_int_not_equal(rt_scene_add_light(&s, &twin), RT_NONE);
    expect_invalid(&s, "light 2: quad 0 is already another area light's quad");
}

static void test_settings(void **state)
{
    (void)state;
    rt_scene s;
    valid_scene(&s);
    s.environment.environment_texture = 2;
    expect_invalid(&s, "settings: environment texture 2 is out of range (2 textures)");
    valid_scene(&s);
    s.environment.background.x = NAN;
    expect_invalid(&s, "settings: background or environment strength is not finite");
}

/* Scene text (a file, or `model`/`mesh` statements naming one) must load
 * and validate. */
static void expect_valid_text(const char *name, const char *text, bool is_file)
{
    rt_scene s;
    rt_scene_init(&s);
    rt_error err;
    memset(&err, 0, sizeof err);
    rt_result r = is_file ? rt_scene_parse_file(&s, NULL, name, &err)
                          : rt_scene_parse_string(&s, NULL, text, strlen(text), name, ".", &err);
    if (r != RT_OK)
        fail_msg("%s: does not load: %s", name, err.message);
    if (rt_scene_validate(&s, &err) != RT_OK)
        fail_msg("%s: does not validate: %s", name, err.message);
    rt_scene_free(&s);
}

static void test_shipped_scenes_and_models_validate(void **state)
{
    (void)state;
    expect_valid_text("<built-in scene>", rt_default_scene_text, false);
    int scenes = 0;
    DIR *d = opendir("scenes");
    assert_non_null(d);
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t n = strlen(e->d_name);
        if (n < 5 || strcmp(e->d_name + n - 4, ".txt") != 0)
            continue;
        char path[512];
        snprintf(path, sizeof path, "scenes/%s", e->d_name);
        expect_valid_text(path, NULL, true);
        scenes++;
    }
    closedir(d);
    assert_true(scenes >= 5);
    static const char *const assets[] = {"mesh assets/donut.obj", "mesh assets/torus.obj", "mesh assets/vase.obj",
                                         "model assets/box.gltf"};
    for (size_t i = 0; i < sizeof assets / sizeof assets[0]; i++) {
        char text[256];
        snprintf(text, sizeof text, "%s\n", assets[i]);
        expect_valid_text(assets[i], text, false);
    }
}

/* The shared models that scenes and docs use validate too. */
static void test_shared_models_validate(void **state)
{
    (void)state;
    test_require_shared();
    static const char *const shared[] = {
        "mesh assets/meshes/stanford-bunny/stanford-bunny.obj",
        "mesh assets/meshes/igea/igea.ply",
        "model assets/gltf/DamagedHelmet/glTF-Binary/DamagedHelmet.glb",
        "model assets/gltf/AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb",
        "model assets/gltf/TransmissionTest/glTF-Binary/TransmissionTest.glb",
    };
    for (size_t i = 0; i < sizeof shared / sizeof shared[0]; i++) {
        const char *sp = strchr(shared[i], ' ');
        char text[4200];
        snprintf(text, sizeof text, "%.*s \"%s\"\n", (int)(sp - shared[i]), shared[i], test_shared_path(sp + 1));
        expect_valid_text(shared[i], text, false);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_valid_scenes_pass),
        cmocka_unit_test(test_primitives_need_a_material),
        cmocka_unit_test(test_triangle_vertex_index),
        cmocka_unit_test(test_triangle_material),
        cmocka_unit_test(test_triangle_attribute_flags),
        cmocka_unit_test(test_vertex_finite),
        cmocka_unit_test(test_sphere_material_and_finite),
        cmocka_unit_test(test_quad_material_and_finite),
        cmocka_unit_test(test_material_texture_slots),
        cmocka_unit_test(test_material_finite),
        cmocka_unit_test(test_texture_kind_and_image),
        cmocka_unit_test(test_image_pixels),
        cmocka_unit_test(test_light_kind_and_finite),
        cmocka_unit_test(test_light_quads),
        cmocka_unit_test(test_settings),
        cmocka_unit_test(test_shipped_scenes_and_models_validate),
        cmocka_unit_test(test_shared_models_validate),
    };
    return cmocka_run_group_tests_name("validate", tests, NULL, NULL);
}
