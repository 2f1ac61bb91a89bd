/* test_gltf_animation.c - posing animated glTF (docs/gltf.md, "Animation"):
 * keyframe curves against closed forms, and small files written here (a
 * triangle translated, rotated, skinned and morphed) whose posed vertices
 * are known exactly; broken animation data refused with a clear message;
 * the shared Fox (skinned, 3 animations) posed at two times; scene-file
 * `model` lines posed by the frame time and their own time, time_offset
 * and animation options. */
#include "test_util.h"

#include <math.h>

#include "rt/base/file.h"
#include "rt/io/gltf.h"
#include "rt/io/gltf_animation.h"
#include "rt/io/load.h"
#include "rt/io/scene_parse.h"
#include "rt/scene/scene.h"

#define PI_F 3.14159265358979f

static void test_curves(void **state)
{
    (void)state;
    float out[4];
    const float t2[2] = {1.0f, 3.0f};
    const float lin[2] = {10.0f, 20.0f};
    rt_anim_sample(RT_INTERP_LINEAR, t2, 2, lin, 1, false, 2.5f, out);
    assert_float_equal(out[0], 17.5f, 1e-6);
    rt_anim_sample(RT_INTERP_LINEAR, t2, 2, lin, 1, false, 0.0f, out); /* clamped before the first key */
    assert_float_equal(out[0], 10.0f, 0);
    rt_anim_sample(RT_INTERP_LINEAR, t2, 2, lin, 1, false, 9.0f, out); /* and after the last */
    assert_float_equal(out[0], 20.0f, 0);
    rt_anim_sample(RT_INTERP_STEP, t2, 2, lin, 1, false, 2.99f, out);
    assert_float_equal(out[0], 10.0f, 0);
    rt_anim_sample(RT_INTERP_STEP, t2, 2, lin, 1, false, 3.0f, out);
    assert_float_equal(out[0], 20.0f, 0);
    /* CUBICSPLINE: in-tangent, value, out-tangent per key. Hermite with
     * v0 = 0, v1 = 1, b0 = 2, a1 = -1 over an interval of 2 at u = 0.25:
     * h00 v0 + h10 td b0 + h01 v1 + h11 td a1 */
    const float cubic[6] = {0, 0, 2, -1, 1, 0};
    rt_anim_sample(RT_INTERP_CUBICSPLINE, t2, 2, cubic, 1, false, 1.5f, out);
    float u = 0.25f, u2 = u * u, u3 = u2 * u;
    float want = (u3 - 2 * u2 + u) * 2 * 2 + (-2 * u3 + 3 * u2) * 1 + (u3 - u2) * 2 * -1;
    assert_float_equal(out[0], want, 1e-6);
    /* slerp: 0 -> 90 degrees about z; halfway is 45 degrees */
    float s45 = sinf(PI_F / 8), c45 = cosf(PI_F / 8);
    const float q[8] = {0, 0, 0, 1, 0, 0, sinf(PI_F / 4), cosf(PI_F / 4)};
    rt_anim_sample(RT_INTERP_LINEAR, t2, 2, q, 4, true, 2.0f, out);
    assert_float_equal(out[2], s45, 1e-6);
    assert_float_equal(out[3], c45, 1e-6);
    /* the shorter arc: -q2 is the same rotation */
    const float qn[8] = {0, 0, 0, 1, 0, 0, -sinf(PI_F / 4), -cosf(PI_F / 4)};
    rt_anim_sample(RT_INTERP_LINEAR, t2, 2, qn, 4, true, 2.0f, out);
    assert_float_equal(fabsf(out[2]), s45, 1e-6);
    assert_float_equal(fabsf(out[3]), c45, 1e-6);
}

/* ------------------------------------------------------ written files */

/* One buffer of floats: the triangle (0,0,0) (1,0,0) (0,1,0) at 0, then
 * `extra` floats. Views and accessors are written by the caller. */
static char dir[64];

static const char *path_of(const char *name)
{
    static char buf[128];
    snprintf(buf, sizeof buf, "%s/%s", dir, name);
    return buf;
}

static void write_gltf(const char *name, const float *data, size_t nfloats, const char *body)
{
    char *enc = test_base64(data, nfloats * sizeof(float));
    size_t cap = strlen(enc) + strlen(body) + 512;
    char *json = malloc(cap);
    snprintf(json, cap,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,"
             "\"uri\":\"data:application/octet-stream;base64,%s\"}],%s}",
             nfloats * sizeof(float), enc, body);
    test_write_file(path_of(name), json, strlen(json));
    free(enc);
    free(json);
}

static rt_result load_at(const char *name, bool posed, float t, int anim, rt_scene *s, rt_error *err)
{
    rt_scene_init(s);
    memset(err, 0, sizeof *err);
    rt_gltf_options o = {.use_time = posed, .time = t, .animation = anim};
    return rt_gltf_load(s, path_of(name), &o, NULL, err);
}

static void expect_vertex(const rt_scene *s, size_t i, float x, float y, float z)
{
    rt_vec3 p = s->vertices.position[i];
    if (fabsf(p.x - x) > 1e-5f || fabsf(p.y - y) > 1e-5f || fabsf(p.z - z) > 1e-5f)
        fprintf(stderr, "vertex %zu: (%g %g %g), expected (%g %g %g)\n", i, p.x, p.y, p.z, x, y, z);
    assert_float_equal(p.x, x, 1e-5);
    assert_float_equal(p.y, y, 1e-5);
    assert_float_equal(p.z, z, 1e-5);
}

/* floats 0..8: the triangle; 9..10: key times 0, 2; then per test */
#define TRI 0, 0, 0, 1, 0, 0, 0, 1, 0
#define TRI_VIEWS "{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":8}"
#define TRI_ACCESSORS                                                                                             \
    "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},"   \
    "{\"bufferView\":1,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"}"

static void test_node_animation(void **state)
{
    (void)state;
    assert_true(test_make_dir(dir, sizeof dir, "anim"));
    rt_scene s;
    rt_error err;
    /* translation 0 -> (2,0,0) over [0, 2], LINEAR and STEP */
    static const char *const interps[2] = {"LINEAR", "STEP"};
    for (int k = 0; k < 2; k++) {
        const float data[] = {TRI, 0, 2, 0, 0, 0, 2, 0, 0};
        char body[2048];
        snprintf(body, sizeof body,
                 "\"bufferViews\":[" TRI_VIEWS ",{\"buffer\":0,\"byteOffset\":44,\"byteLength\":24}],"
                 "\"accessors\":[" TRI_ACCESSORS ",{\"bufferView\":2,\"componentType\":5126,\"count\":2,"
                 "\"type\":\"VEC3\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                 "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],"
                 "\"animations\":[{\"samplers\":[{\"input\":1,\"output\":2,\"interpolation\":\"%s\"}],"
                 "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}]}]",
                 interps[k]);
        write_gltf("move.gltf", data, sizeof data / sizeof *data, body);
        assert_int_equal(load_at("move.gltf", true, 0.5f, 0, &s, &err), RT_OK);
        expect_vertex(&s, 1, k == 0 ? 1.5f : 1.0f, 0, 0);
        rt_scene_free(&s);
        assert_int_equal(load_at("move.gltf", false, 0, 0, &s, &err), RT_OK); /* unposed: the static pose */
        expect_vertex(&s, 1, 1, 0, 0);
        rt_scene_free(&s);
    }
    /* rotation 0 -> 90 degrees about z: at t = 1, 45 degrees */
    {
        float h = sqrtf(0.5f);
        const float data[] = {TRI, 0, 2, 0, 0, 0, 1, 0, 0, h, h};
        write_gltf("turn.gltf", data, sizeof data / sizeof *data,
                   "\"bufferViews\":[" TRI_VIEWS ",{\"buffer\":0,\"byteOffset\":44,\"byteLength\":32}],"
                   "\"accessors\":[" TRI_ACCESSORS ",{\"bufferView\":2,\"componentType\":5126,\"count\":2,"
                   "\"type\":\"VEC4\"}],"
                   "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                   "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],"
                   "\"animations\":[{\"samplers\":[{\"input\":1,\"output\":2}],"
                   "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"rotation\"}}]}]");
        assert_int_equal(load_at("turn.gltf", true, 1.0f, 0, &s, &err), RT_OK);
        expect_vertex(&s, 1, cosf(PI_F / 4), sinf(PI_F / 4), 0);
        rt_scene_free(&s);
        assert_int_equal(load_at("turn.gltf", true, 5.0f, 0, &s, &err), RT_OK); /* after the last key */
        expect_vertex(&s, 1, 0, 1, 0);
        rt_scene_free(&s);
        /* an animation that does not exist */
        assert_int_equal(load_at("turn.gltf", true, 1.0f, 3, &s, &err), RT_ERR_INVALID);
        assert_non_null(strstr(err.message, "animation 3 requested, the file has 1"));
        rt_scene_free(&s);
    }
    test_remove_dir(dir);
}

/* The skin tests' buffer views, accessors, mesh and two-joint skin: the
 * triangle, JOINTS_0 as unsigned bytes, WEIGHTS_0 as floats. */
#define SKIN_MESH                                                                                                      \
    "\"bufferViews\":[" TRI_VIEWS ",{\"buffer\":0,\"byteOffset\":44,\"byteLength\":12},"                               \
    "{\"buffer\":0,\"byteOffset\":56,\"byteLength\":48}],"                                                             \
    "\"accessors\":[" TRI_ACCESSORS ",{\"bufferView\":2,\"componentType\":5121,\"count\":3,"                           \
    "\"type\":\"VEC4\"},{\"bufferView\":3,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"}],"                     \
    "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"JOINTS_0\":2,\"WEIGHTS_0\":3}}]}],"                \
    "\"skins\":[{\"joints\":[1,2]}],"

/* Two joints at the origin; vertex 1 follows joint 1, rotated 90 degrees
 * about z (its rest rotation), vertex 2 half joint 0 and half joint 1. */
static void test_skin(void **state)
{
    (void)state;
    assert_true(test_make_dir(dir, sizeof dir, "skin"));
    /* JOINTS_0 as floats is not allowed: write them as unsigned bytes in
     * a float-sized slot (4 bytes a vertex), WEIGHTS_0 as floats */
    float data[9 + 2 + 3 + 12];
    const float tri[9] = {TRI};
    memcpy(data, tri, sizeof tri);
    data[9] = 0;
    data[10] = 2;
    uint8_t joints[12] = {0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0};
    memcpy(&data[11], joints, 12);
    const float weights[12] = {1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0};
    memcpy(&data[14], weights, sizeof weights);
    write_gltf("skin.gltf", data, sizeof data / sizeof *data,
               SKIN_MESH
               "\"nodes\":[{\"mesh\":0,\"skin\":0,\"translation\":[100,0,0]},{},"
               "{\"rotation\":[0,0,0.70710678,0.70710678]}],"
               "\"scenes\":[{\"nodes\":[0,1,2]}]");
    rt_scene s;
    rt_error err;
    rt_result r = load_at("skin.gltf", true, 0.0f, 0, &s, &err);
    if (r != RT_OK)
        fprintf(stderr, "%s\n", err.message);
    assert_int_equal(r, RT_OK);
    expect_vertex(&s, 0, 0, 0, 0);      /* joint 0: identity (the mesh node's translation does not apply) */
    expect_vertex(&s, 1, 0, 1, 0);      /* joint 1: (1,0,0) turned 90 degrees */
    expect_vertex(&s, 2, -0.5f, 0.5f, 0); /* (0,1,0): half of itself, half of (-1,0,0) */
    rt_scene_free(&s);
    /* a joint index past the skin's joints */
    joints[4] = 7;
    memcpy(&data[11], joints, 12);
    write_gltf("badjoint.gltf", data, sizeof data / sizeof *data,
               SKIN_MESH
               "\"nodes\":[{\"mesh\":0,\"skin\":0},{},{}],\"scenes\":[{\"nodes\":[0,1,2]}]");
    assert_int_equal(load_at("badjoint.gltf", true, 0.0f, 0, &s, &err), RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "badjoint.gltf"));
    assert_non_null(strstr(err.message, "names joint 7 of 2"));
    rt_scene_free(&s);
    test_remove_dir(dir);
}

/* One morph target moving vertex 0 by (0,0,1); the mesh's weight 0.25,
 * then an animation of the weight to 1 at t = 2. */
static void test_morph(void **state)
{
    (void)state;
    assert_true(test_make_dir(dir, sizeof dir, "morph"));
    const float data[] = {TRI, 0, 2, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0.25f, 1};
    write_gltf("morph.gltf", data, sizeof data / sizeof *data,
               "\"bufferViews\":[" TRI_VIEWS ",{\"buffer\":0,\"byteOffset\":44,\"byteLength\":36},"
               "{\"buffer\":0,\"byteOffset\":80,\"byteLength\":8}],"
               "\"accessors\":[" TRI_ACCESSORS ",{\"bufferView\":2,\"componentType\":5126,\"count\":3,"
               "\"type\":\"VEC3\"},{\"bufferView\":3,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"}],"
               "\"meshes\":[{\"weights\":[0.25],\"primitives\":[{\"attributes\":{\"POSITION\":0},"
               "\"targets\":[{\"POSITION\":2}]}]}],"
               "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],"
               "\"animations\":[{\"samplers\":[{\"input\":1,\"output\":3}],"
               "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"weights\"}}]}]");
    rt_scene s;
    rt_error err;
    assert_int_equal(load_at("morph.gltf", false, 0, 0, &s, &err), RT_OK); /* unposed: no morphing */
    expect_vertex(&s, 0, 0, 0, 0);
    rt_scene_free(&s);
    assert_int_equal(load_at("morph.gltf", true, 0.0f, 0, &s, &err), RT_OK); /* animated weight 0.25 at t = 0 */
    expect_vertex(&s, 0, 0, 0, 0.25f);
    rt_scene_free(&s);
    assert_int_equal(load_at("morph.gltf", true, 1.0f, 0, &s, &err), RT_OK); /* 0.625 halfway */
    expect_vertex(&s, 0, 0, 0, 0.625f);
    expect_vertex(&s, 1, 1, 0, 0);
    rt_scene_free(&s);
    test_remove_dir(dir);
}

/* Loads name (posed at t = 1 when posed) and expects RT_ERR_INVALID with a
 * message naming the file, the byte where `at` starts in the file and what. */
static void expect_bad_at(const char *name, bool posed, const char *at, const char *what)
{
    char *text;
    size_t size;
    rt_error err;
    assert_int_equal(rt_read_file(path_of(name), 0, &text, &size, &err), RT_OK);
    const char *hit = strstr(text, at);
    assert_non_null(hit);
    char want[256];
    snprintf(want, sizeof want, "%s: byte %zu: %s", path_of(name), (size_t)(hit - text), what);
    free(text);
    rt_scene s;
    rt_result r = load_at(name, posed, 1.0f, 0, &s, &err);
    test_expect_failure(r, &err, RT_ERR_INVALID, name, want);
    assert_int_equal(s.triangles.count, 0);
    rt_scene_free(&s);
}

/* Issue 25, class 1: every primitive of a mesh has the same number of
 * morph targets (a second primitive with more once over-read the weights
 * sized for the first), and every weights array has one per target. */
static void test_morph_counts_checked(void **state)
{
    (void)state;
    assert_true(test_make_dir(dir, sizeof dir, "morphcount"));
    const float data[] = {TRI, 0, 2, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0.25f, 1, 0.5f};
    static const char head[] =
        "\"bufferViews\":[" TRI_VIEWS ",{\"buffer\":0,\"byteOffset\":44,\"byteLength\":36},"
        "{\"buffer\":0,\"byteOffset\":80,\"byteLength\":12}],"
        "\"accessors\":[" TRI_ACCESSORS ",{\"bufferView\":2,\"componentType\":5126,\"count\":3,"
        "\"type\":\"VEC3\"},{\"bufferView\":3,\"componentType\":5126,\"count\":%d,\"type\":\"SCALAR\"}],"
        "\"scenes\":[{\"nodes\":[0]}],";
    static const char anim[] = "\"animations\":[{\"samplers\":[{\"input\":1,\"output\":3}],"
                               "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"weights\"}}]}]";
    static const char p1[] = "{\"attributes\":{\"POSITION\":0},\"targets\":[{\"POSITION\":2}]}";
    static const char p2[] = "{\"attributes\":{\"POSITION\":0},\"targets\":[{\"POSITION\":2},{\"POSITION\":2}]}";
    char body[4096], h[2048];
    /* primitives of one mesh with 1 and 2 targets: refused posed or not */
    snprintf(h, sizeof h, head, 2);
    snprintf(body, sizeof body, "%s\"meshes\":[{\"primitives\":[%s,%s]}],\"nodes\":[{\"mesh\":0}],%s", h, p1, p2,
             anim);
    write_gltf("prims.gltf", data, sizeof data / sizeof *data, body);
    expect_bad_at("prims.gltf", true, p2, "meshes[0].primitives[1]: has 2 morph targets, primitives[0] 1");
    expect_bad_at("prims.gltf", false, p2, "meshes[0].primitives[1]: has 2 morph targets, primitives[0] 1");
    /* mesh.weights with 2 weights for 1 target */
    snprintf(body, sizeof body, "%s\"meshes\":[{\"weights\":[0.5,0.5],\"primitives\":[%s,%s]}],"
             "\"nodes\":[{\"mesh\":0}]", h, p1, p1);
    write_gltf("meshw.gltf", data, sizeof data / sizeof *data, body);
    expect_bad_at("meshw.gltf", false, "[0.5,0.5]", "meshes[0].weights: expected an array of 1 numbers");
    /* node.weights with 3 weights for 1 target, and on a node without a mesh */
    snprintf(body, sizeof body, "%s\"meshes\":[{\"primitives\":[%s]}],\"nodes\":[{\"mesh\":0,\"weights\":[1,2,3]}]",
             h, p1);
    write_gltf("nodew.gltf", data, sizeof data / sizeof *data, body);
    expect_bad_at("nodew.gltf", true, "[1,2,3]", "nodes[0].weights: expected an array of 1 numbers");
    snprintf(body, sizeof body, "%s\"meshes\":[{\"primitives\":[%s]}],\"nodes\":[{\"mesh\":0},{\"weights\":[1]}]",
             h, p1);
    write_gltf("nodew2.gltf", data, sizeof data / sizeof *data, body);
    expect_bad_at("nodew2.gltf", false, "[1]}", "nodes[1].weights: the node has no mesh");
    /* animated weights: 3 outputs for 2 keys of 1 target */
    snprintf(h, sizeof h, head, 3);
    snprintf(body, sizeof body, "%s\"meshes\":[{\"primitives\":[%s]}],\"nodes\":[{\"mesh\":0}],%s", h, p1, anim);
    write_gltf("animw.gltf", data, sizeof data / sizeof *data, body);
    expect_bad_at("animw.gltf", true, "{\"bufferView\":3", "accessors[3] (output of animations[0].channels[0]): has 3 "
                  "elements, expected 2");
    test_remove_dir(dir);
}

static void test_broken_animation(void **state)
{
    (void)state;
    assert_true(test_make_dir(dir, sizeof dir, "badanim"));
    rt_scene s;
    rt_error err;
    /* key times that go back */
    const float data[] = {TRI, 2, 0, 0, 0, 0, 2, 0, 0};
    const char *body = "\"bufferViews\":[" TRI_VIEWS ",{\"buffer\":0,\"byteOffset\":44,\"byteLength\":24}],"
                       "\"accessors\":[" TRI_ACCESSORS ",{\"bufferView\":2,\"componentType\":5126,\"count\":2,"
                       "\"type\":\"VEC3\"}],"
                       "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                       "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],"
                       "\"animations\":[{\"samplers\":[{\"input\":1,\"output\":2}],"
                       "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}]}]";
    write_gltf("back.gltf", data, sizeof data / sizeof *data, body);
    assert_int_equal(load_at("back.gltf", true, 1.0f, 0, &s, &err), RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "back.gltf"));
    assert_non_null(strstr(err.message, "key times must increase"));
    rt_scene_free(&s);
    /* an output with the wrong count: rotation (VEC4) read from the VEC3 accessor */
    const float ok[] = {TRI, 0, 2, 0, 0, 0, 2, 0, 0};
    char body2[2048];
    snprintf(body2, sizeof body2, "%s", body);
    char *path = strstr(body2, "\"translation\"");
    memcpy(path, "\"rotation\"   ", 13);
    write_gltf("wrongtype.gltf", ok, sizeof ok / sizeof *ok, body2);
    assert_int_equal(load_at("wrongtype.gltf", true, 1.0f, 0, &s, &err), RT_ERR_INVALID);
    assert_non_null(strstr(err.message, "wrongtype.gltf"));
    assert_non_null(strstr(err.message, "output of animations[0].channels[0]"));
    rt_scene_free(&s);
    test_remove_dir(dir);
}

/* The shared Fox: skinned, three animations; posed at two times of its
 * run cycle the bounds differ, and both stay near the rest pose's size. */
static void test_fox(void **state)
{
    (void)state;
    test_require_shared();
    const char *fox = test_shared_path("assets/gltf/Fox/glTF-Binary/Fox.glb");
    rt_gltf_stats a, b, rest;
    rt_scene s;
    rt_error err;
    rt_gltf_options o = {.use_time = true, .time = 0.2f, .animation = 2};
    rt_scene_init(&s);
    assert_int_equal(rt_gltf_load(&s, fox, &o, &a, &err), RT_OK);
    rt_scene_free(&s);
    o.time = 0.5f;
    rt_scene_init(&s);
    assert_int_equal(rt_gltf_load(&s, fox, &o, &b, &err), RT_OK);
    rt_scene_free(&s);
    rt_scene_init(&s);
    assert_int_equal(rt_gltf_load(&s, fox, NULL, &rest, &err), RT_OK);
    rt_scene_free(&s);
    assert_int_equal(a.triangles, rest.triangles);
    assert_true(memcmp(&a.bounds, &b.bounds, sizeof a.bounds) != 0);
    float hr = rest.bounds.hi.y - rest.bounds.lo.y, ha = a.bounds.hi.y - a.bounds.lo.y;
    assert_true(ha > 0.7f * hr && ha < 1.3f * hr);
}

/* Vertex 1 of the scene text `text` (one model line) parsed with the
 * frame time t (posed = false: none) and the driver's animation anim;
 * returns the parse result. */
static rt_result scene_vertex(const char *text, bool posed, float t, int anim, float *x, rt_error *err)
{
    rt_scene s;
    rt_scene_init(&s);
    memset(err, 0, sizeof *err);
    rt_scene_parse_options o = {.use_time = posed, .time = t, .animation = anim};
    char name[128];
    snprintf(name, sizeof name, "%s/scene.txt", dir);
    rt_result r = rt_scene_parse_string_with(&s, NULL, text, strlen(text), name, NULL, &o, err);
    *x = r == RT_OK && s.vertices.count > 1 ? s.vertices.position[1].x : -99.0f;
    rt_scene_free(&s);
    return r;
}

/* `model` lines of a scene file: the frame time poses them; `time` fixes a
 * line's pose, `time_offset` shifts it, `animation` picks by name or index;
 * no frame time and no option = the static pose, as before. Two animations
 * of the triangle's translation over [0, 2]: "slide" to x + 2, "back" to x - 2. */
static void test_scene_model_lines(void **state)
{
    (void)state;
    assert_true(test_make_dir(dir, sizeof dir, "anim"));
    const float data[] = {TRI, 0, 2, 0, 0, 0, 2, 0, 0, 0, 0, 0, -2, 0, 0};
    write_gltf("two.gltf", data, sizeof data / sizeof *data,
               "\"bufferViews\":[" TRI_VIEWS ",{\"buffer\":0,\"byteOffset\":44,\"byteLength\":24},"
               "{\"buffer\":0,\"byteOffset\":68,\"byteLength\":24}],"
               "\"accessors\":[" TRI_ACCESSORS ",{\"bufferView\":2,\"componentType\":5126,\"count\":2,"
               "\"type\":\"VEC3\"},{\"bufferView\":3,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
               "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],"
               "\"animations\":[{\"name\":\"slide\",\"samplers\":[{\"input\":1,\"output\":2}],"
               "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}]},"
               "{\"name\":\"back\",\"samplers\":[{\"input\":1,\"output\":3}],"
               "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}]}]");
    const float still[] = {TRI};
    write_gltf("still.gltf", still, 9,
               "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
               "\"min\":[0,0,0],\"max\":[1,1,0]}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
               "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]");
    rt_error err;
    float x;
    /* each line's pose of vertex 1 (x = 1 at rest): the line, whether a
     * frame time is given and which (the driver's --frame-time), the
     * driver's animation, the x it lands at and the tolerance */
    static const struct {
        const char *text;
        bool posed;
        float t;
        int anim;
        float x;
        double tol;
    } poses[] = {
        /* the frame time (and the driver's animation) pose a plain line */
        {"model two.gltf\n", false, 0, 0, 1.0f, 0}, /* no frame time: the static pose */
        {"model two.gltf\n", true, 0.5f, 0, 1.5f, 1e-6},
        {"model two.gltf\n", true, 0.5f, 1, 0.5f, 1e-6},
        /* time fixes the pose whatever the frame; time_offset adds to it (frame time 0 without one) */
        {"model two.gltf time 1\n", true, 0.5f, 0, 2.0f, 1e-6},
        {"model two.gltf time 1\n", false, 0, 0, 2.0f, 1e-6},
        {"model two.gltf time_offset 0.25\n", true, 0.5f, 0, 1.75f, 1e-6},
        {"model two.gltf time_offset 0.25\n", false, 0, 0, 1.25f, 1e-6},
        /* animation by name or index, over the driver's */
        {"model two.gltf animation back\n", true, 0.5f, 0, 0.5f, 1e-6},
        {"model two.gltf animation 0 translate 1 0 0\n", true, 0.5f, 1, 2.5f, 1e-6},
        {"model two.gltf animation \"slide\" time 2\n", false, 0, 1, 3.0f, 1e-6},
        /* the driver's animation index passes over a model without animations */
        {"model still.gltf\n", true, 0.5f, 1, 1.0f, 0},
    };
    for (size_t i = 0; i < sizeof poses / sizeof poses[0]; i++) {
        rt_result r = scene_vertex(poses[i].text, poses[i].posed, poses[i].t, poses[i].anim, &x, &err);
        if (r != RT_OK)
            print_error("%s%s\n", poses[i].text, err.message);
        assert_int_equal(r, RT_OK);
        assert_float_equal(x, poses[i].x, poses[i].tol);
    }
    /* errors name the scene file, line and column: the line, as above, the
     * code and up to two parts of the message (NULL: not checked) */
    static const struct {
        const char *text;
        bool posed;
        float t;
        int anim;
        rt_result code;
        const char *part1, *part2;
    } bad[] = {
        {"\nmodel two.gltf animation run\n", true, 0.5f, 0, RT_ERR_INVALID, "scene.txt:2:7: ",
         "no animation named 'run' (the file has 'slide', 'back')"},
        {"model two.gltf animation 2\n", true, 0.5f, 0, RT_ERR_INVALID, "animation 2 requested, the file has 2", NULL},
        {"model still.gltf animation 1\n", false, 0, 0, RT_ERR_INVALID, "the file has none", NULL},
        {"model two.gltf time 1 time_offset 2\n", true, 0, 0, RT_ERR_INVALID, "scene.txt:1:23: give 'time'", NULL},
        {"model two.gltf time soon\n", true, 0, 0, RT_ERR_PARSE,
         "scene.txt:1:21: expected a number for the model's animation time", NULL},
        {"model two.gltf animation -1\n", true, 0, 0, RT_ERR_INVALID, NULL, NULL},
        {"model two.gltf time_offset 1 time_offset 1\n", true, 0, 0, RT_ERR_INVALID, "'time_offset' is given twice",
         NULL},
        {"model two.gltf animation\n", true, 0, 0, RT_ERR_PARSE, NULL, NULL},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(scene_vertex(bad[i].text, bad[i].posed, bad[i].t, bad[i].anim, &x, &err), bad[i].code);
        if (bad[i].part1)
            assert_non_null(strstr(err.message, bad[i].part1));
        if (bad[i].part2)
            assert_non_null(strstr(err.message, bad[i].part2));
    }
    /* rt_load passes its time to a scene file's model lines */
    char path[128];
    snprintf(path, sizeof path, "%s/scene.txt", dir);
    test_write_file(path, "model two.gltf\n", 15);
    rt_scene s;
    rt_scene_init(&s);
    rt_load_options lo = {.use_time = true, .time = 1.0f};
    assert_int_equal(rt_load(&s, NULL, path, &lo, NULL, &err), RT_OK);
    assert_float_equal(s.vertices.position[1].x, 2.0f, 1e-6);
    rt_scene_free(&s);
    test_remove_dir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_curves), cmocka_unit_test(test_node_animation), cmocka_unit_test(test_skin),
        cmocka_unit_test(test_morph),  cmocka_unit_test(test_morph_counts_checked),
        cmocka_unit_test(test_broken_animation), cmocka_unit_test(test_fox),
        cmocka_unit_test(test_scene_model_lines),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
